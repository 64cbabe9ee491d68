!> The parallel environment of the serial binary: one rank, no MPI. The same API as
!! mpi_env_mpi.f90 (the Makefile compiles one of the two as module mpi_env), so the driver
!! calls one set of routines whichever binary it is.
module mpi_env
  use kinds, only: wp
  use errors, only: error_t
  implicit none (type, external)
  private

  logical, parameter, public :: par_built = .false.   !< .true. only in bin/robin_contact_mpi

  public :: par_init, par_finalize, par_rank, par_size, par_split, par_bcast_reals, par_bcast_ints, &
            par_bcast_str, par_agree, par_any, par_abort, par_comm_world, par_max_real, par_sum_real, par_node_sum

contains

  !> Start the parallel environment (nothing to do).
  subroutine par_init()
  end subroutine par_init

  !> End the parallel environment (nothing to do).
  subroutine par_finalize()
  end subroutine par_finalize

  !> This rank in the world (always 0).
  integer function par_rank()
    par_rank = 0
  end function par_rank

  !> Ranks in the world (always 1).
  integer function par_size()
    par_size = 1
  end function par_size

  !> The world communicator (0: none).
  integer function par_comm_world()
    par_comm_world = 0
  end function par_comm_world

  !> Split the world by color (one group: the world).
  subroutine par_split(color, comm)
    integer, intent(in) :: color     !< group of this rank
    integer, intent(out) :: comm     !< the group's communicator
    comm = 0 * color
  end subroutine par_split

  !> Broadcast n reals from world rank root (no-op).
  subroutine par_bcast_reals(x, n, root)
    integer, intent(in) :: n, root
    real(wp), intent(inout) :: x(*)
    if (n < 0 .or. root < 0) x(1) = x(1)
  end subroutine par_bcast_reals

  !> Broadcast n integers from world rank root (no-op).
  subroutine par_bcast_ints(x, n, root)
    integer, intent(in) :: n, root
    integer, intent(inout) :: x(*)
    if (n < 0 .or. root < 0) x(1) = x(1)
  end subroutine par_bcast_ints

  !> Broadcast a string from world rank root (no-op).
  subroutine par_bcast_str(s, root)
    character(len=*), intent(inout) :: s
    integer, intent(in) :: root
    if (root < 0) s = s
  end subroutine par_bcast_str

  !> Agree on an error across ranks (one rank: unchanged).
  subroutine par_agree(err)
    type(error_t), intent(inout) :: err   !< this rank's error, which is the world's
    if (.false.) call err%clear()
  end subroutine par_agree

  !> The largest x over the ranks and the rank that has it (one rank: x, 0).
  subroutine par_max_real(x, xmax, where)
    real(wp), intent(in) :: x
    real(wp), intent(out) :: xmax
    integer, intent(out) :: where
    xmax = x
    where = 0
  end subroutine par_max_real

  !> The sum of x over the ranks (one rank: x).
  real(wp) function par_sum_real(x)
    real(wp), intent(in) :: x
    par_sum_real = x
  end function par_sum_real

  !> The sum of x over the ranks of this node and their number (one rank: x, 1).
  subroutine par_node_sum(x, total, count)
    real(wp), intent(in) :: x
    real(wp), intent(out) :: total
    integer, intent(out) :: count
    total = x
    count = 1
  end subroutine par_node_sum

  !> Whether flag is true on any rank (one rank: flag).
  logical function par_any(flag)
    logical, intent(in) :: flag
    par_any = flag
  end function par_any

  !> Stop every rank with code (one rank: stop).
  subroutine par_abort(code)
    integer, intent(in) :: code
    error stop code, quiet=.true.
  end subroutine par_abort

end module mpi_env
