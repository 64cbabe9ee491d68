!> Process information from the C library (src/base/sysinfo_shim.c): peak resident
!! memory (getrusage) and the memory a run may use.
module sysinfo
  use, intrinsic :: iso_c_binding, only: c_double, c_int, c_char
  use, intrinsic :: iso_fortran_env, only: output_unit
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
    !> Memory the process may use [MiB], 0 if unknown (which: 0 all limits, 1 the node's,
    !! 2 the process's own).
    function rc_memory_limit_mb(which) bind(c, name='rc_memory_limit_mb') result(mb)
      import :: c_double, c_int
      implicit none
      integer(c_int), value :: which
      real(c_double) :: mb
    end function rc_memory_limit_mb
    !> write(2) to standard output; 0 or errno.
    function rc_stdout_write(buf, n) bind(c, name='rc_stdout_write') result(err)
      import :: c_int, c_char
      implicit none
      character(kind=c_char), intent(in) :: buf(*)
      integer(c_int), value :: n
      integer(c_int) :: err
    end function rc_stdout_write
  end interface

  public :: peak_rss_mb, memory_limit_mb, node_memory_limit_mb, process_memory_limit_mb, write_stdout_checked

contains

  !> Peak resident set size of this process so far [MiB].
  real(wp) function peak_rss_mb()
    peak_rss_mb = real(rc_peak_rss_mb(), wp)
  end function peak_rss_mb

  !> Memory this process may use [MiB]: the least of MemAvailable, the cgroup limit,
  !! ulimit -v and ROBIN_MEMORY_LIMIT_MB; 0 if none is known.
  real(wp) function memory_limit_mb()
    memory_limit_mb = declared_limit(real(rc_memory_limit_mb(0_c_int), wp))
  end function memory_limit_mb

  !> Memory the processes of this node (or of the job's cgroup on it) may use together
  !! [MiB]: the least of MemAvailable, the cgroup limit and ROBIN_MEMORY_LIMIT_MB; 0 if none.
  real(wp) function node_memory_limit_mb()
    node_memory_limit_mb = declared_limit(real(rc_memory_limit_mb(1_c_int), wp))
  end function node_memory_limit_mb

  !> Memory each process may use by itself [MiB]: ulimit -v (RLIMIT_AS); 0 if unlimited.
  real(wp) function process_memory_limit_mb()
    process_memory_limit_mb = real(rc_memory_limit_mb(2_c_int), wp)
  end function process_memory_limit_mb

  !> lim lowered to ROBIN_MEMORY_LIMIT_MB when that is set (a job declares the memory of
  !! its node, or a test makes the limit small); the variable can only lower the limit.
  real(wp) function declared_limit(lim)
    real(wp), intent(in) :: lim
    character(len=32) :: env
    real(wp) :: v
    integer :: st
    declared_limit = lim
    call get_environment_variable('ROBIN_MEMORY_LIMIT_MB', env, status=st)
    if (st /= 0) return
    read (env, *, iostat=st) v
    if (st == 0 .and. v > 0.0_wp .and. (lim <= 0.0_wp .or. v < lim)) declared_limit = v
  end function declared_limit

  !> Write one line to standard output and report whether it got there (gfortran's unit 6
  !! silently drops write errors, e.g. on a full disk or /dev/full). Fortran output written
  !! before is flushed first, so the order is kept. err = 0 on success, else errno.
  subroutine write_stdout_checked(line, err)
    character(len=*), intent(in) :: line   !< the line, without its newline
    integer, intent(out) :: err            !< 0, or the errno of the failed write
    flush (output_unit)
    err = int(rc_stdout_write(line//achar(10), int(len(line) + 1, c_int)))
  end subroutine write_stdout_checked

end module sysinfo
