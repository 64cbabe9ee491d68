!> Process information from the C library: peak resident memory (getrusage).
module sysinfo
  use kinds, only: wp
  use, intrinsic :: iso_c_binding, only: c_int, c_long
  implicit none (type, external)
  private

  !> struct rusage on Linux/x86_64: two struct timeval, then 14 longs.
  type, bind(c) :: rusage_t
    integer(c_long) :: utime(2), stime(2)
    integer(c_long) :: fields(14)
  end type rusage_t

  interface
    integer(c_int) function c_getrusage(who, usage) bind(c, name='getrusage')
      import :: c_int, rusage_t
      integer(c_int), value :: who
      type(rusage_t), intent(out) :: usage
    end function c_getrusage
  end interface

  public :: peak_rss_mb

contains

  !> Peak resident set size of this process so far [MiB] (ru_maxrss is in KiB on Linux).
  real(wp) function peak_rss_mb()
    type(rusage_t) :: ru
    peak_rss_mb = 0.0_wp
    if (c_getrusage(0_c_int, ru) == 0) peak_rss_mb = real(ru%fields(1), wp)/1024.0_wp
  end function peak_rss_mb

end module sysinfo
