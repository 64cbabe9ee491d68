!> Process information from the C library (src/base/sysinfo_shim.c): peak resident
!! memory (getrusage) and the memory a run may use.
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
    !> Memory the process may use [MiB], 0 if unknown.
    function rc_memory_limit_mb() bind(c, name='rc_memory_limit_mb') result(mb)
      import :: c_double
      implicit none
      real(c_double) :: mb
    end function rc_memory_limit_mb
  end interface

  public :: peak_rss_mb, memory_limit_mb

contains

  !> Peak resident set size of this process so far [MiB].
  real(wp) function peak_rss_mb()
    peak_rss_mb = real(rc_peak_rss_mb(), wp)
  end function peak_rss_mb

  !> Memory this process may use [MiB]: the least of MemAvailable, the cgroup limit and
  !! ulimit -v; 0 if none is known.
  real(wp) function memory_limit_mb()
    memory_limit_mb = real(rc_memory_limit_mb(), wp)
  end function memory_limit_mb

end module sysinfo
