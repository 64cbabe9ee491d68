!> Process information from the C library (src/base/sysinfo_shim.c): peak resident
!! memory (getrusage).
module sysinfo
  use, intrinsic :: iso_c_binding, only: c_double
  use kinds, only: wp
  implicit none (type, external)
  private

  interface
    !> Peak resident set size [MiB], 0 if getrusage failed.
    function rc_peak_rss_mb() bind(c, name='rc_peak_rss_mb') result(mb)
      import :: c_double
      implicit none
      real(c_double) :: mb
    end function rc_peak_rss_mb
  end interface

  public :: peak_rss_mb

contains

  !> Peak resident set size of this process so far [MiB].
  real(wp) function peak_rss_mb()
    peak_rss_mb = real(rc_peak_rss_mb(), wp)
  end function peak_rss_mb

end module sysinfo
