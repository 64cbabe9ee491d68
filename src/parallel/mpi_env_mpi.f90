!> The parallel environment of bin/robin_contact_mpi: MPI_COMM_WORLD, its split into one
!! group per body, and the few collectives the driver needs on interface-sized data
!! (broadcasts of small arrays, agreement on a status). The serial binary compiles
!! mpi_env_serial.f90 instead, with the same API.
module mpi_env
  use kinds, only: wp
  use errors, only: error_t, exit_code
  use mpi
  implicit none (type, external)
  private

  logical, parameter, public :: par_built = .true.    !< .true. only in bin/robin_contact_mpi

  public :: par_init, par_finalize, par_rank, par_size, par_split, par_bcast_reals, par_bcast_ints, &
            par_bcast_str, par_agree, par_any, par_abort, par_comm_world, par_max_real, par_sum_real, par_node_sum

contains

  !> Start MPI (once). MPI's own failures are fatal (MPI_ERRORS_ARE_FATAL on the world, which
  !! the groups split from it inherit): a failed collective aborts every rank, which is all a
  !! translation into an error_t could do midway through one; so the `ierr` of the calls
  !! here is never other than MPI_SUCCESS when they return.
  subroutine par_init()
    integer :: ierr
    logical :: up
    call MPI_Initialized(up, ierr)
    if (.not. up) call MPI_Init(ierr)
    call MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_ARE_FATAL, ierr)
  end subroutine par_init

  !> End MPI (every rank calls it, collectively).
  subroutine par_finalize()
    integer :: ierr
    logical :: up, down
    call MPI_Initialized(up, ierr)
    call MPI_Finalized(down, ierr)
    if (up .and. .not. down) call MPI_Finalize(ierr)
  end subroutine par_finalize

  !> This rank in MPI_COMM_WORLD.
  integer function par_rank()
    integer :: ierr
    call MPI_Comm_rank(MPI_COMM_WORLD, par_rank, ierr)
  end function par_rank

  !> Ranks in MPI_COMM_WORLD.
  integer function par_size()
    integer :: ierr
    call MPI_Comm_size(MPI_COMM_WORLD, par_size, ierr)
  end function par_size

  !> MPI_COMM_WORLD (the handle MUMPS takes).
  integer function par_comm_world()
    par_comm_world = MPI_COMM_WORLD
  end function par_comm_world

  !> Split MPI_COMM_WORLD by color (MPI_Comm_split, ranks keep their world order).
  subroutine par_split(color, comm)
    integer, intent(in) :: color     !< group of this rank
    integer, intent(out) :: comm     !< the group's communicator
    integer :: ierr
    call MPI_Comm_split(MPI_COMM_WORLD, color, par_rank(), comm, ierr)
  end subroutine par_split

  !> Broadcast n reals from world rank root.
  subroutine par_bcast_reals(x, n, root)
    integer, intent(in) :: n, root
    real(wp), intent(inout) :: x(*)
    integer :: ierr
    if (n > 0) call MPI_Bcast(x, n, MPI_DOUBLE_PRECISION, root, MPI_COMM_WORLD, ierr)
  end subroutine par_bcast_reals

  !> Broadcast n integers from world rank root.
  subroutine par_bcast_ints(x, n, root)
    integer, intent(in) :: n, root
    integer, intent(inout) :: x(*)
    integer :: ierr
    if (n > 0) call MPI_Bcast(x, n, MPI_INTEGER, root, MPI_COMM_WORLD, ierr)
  end subroutine par_bcast_ints

  !> Broadcast a string from world rank root.
  subroutine par_bcast_str(s, root)
    character(len=*), intent(inout) :: s
    integer, intent(in) :: root
    integer :: ierr
    call MPI_Bcast(s, len(s), MPI_CHARACTER, root, MPI_COMM_WORLD, ierr)
  end subroutine par_bcast_str

  !> Agree on an error: every rank ends with the error of the lowest rank whose error has the
  !! largest exit code (none when no rank failed; collective over the world).
  subroutine par_agree(err)
    type(error_t), intent(inout) :: err   !< in: this rank's error; out: the world's (see above)
    integer :: pair(2), best(2), head(2), ierr
    character(len=:), allocatable :: text
    pair = [exit_code(err), par_rank()]
    call MPI_Allreduce(pair, best, 1, MPI_2INTEGER, MPI_MAXLOC, MPI_COMM_WORLD, ierr)
    if (best(1) == 0) return
    ! the chosen rank's category and message, whatever this rank held
    head = 0
    if (par_rank() == best(2)) head = [err%category, len(err%text())]
    call MPI_Bcast(head, 2, MPI_INTEGER, best(2), MPI_COMM_WORLD, ierr)
    allocate (character(len=head(2)) :: text)
    if (par_rank() == best(2)) text = err%text()
    call MPI_Bcast(text, head(2), MPI_CHARACTER, best(2), MPI_COMM_WORLD, ierr)
    call err%set(head(1), text)
  end subroutine par_agree

  !> The largest x over the ranks and the lowest world rank that has it (collective).
  subroutine par_max_real(x, xmax, where)
    real(wp), intent(in) :: x          !< this rank's value
    real(wp), intent(out) :: xmax      !< the largest over the world
    integer, intent(out) :: where      !< a world rank that has it
    real(wp) :: pair(2), best(2)
    integer :: ierr
    pair = [x, real(par_rank(), wp)]
    call MPI_Allreduce(pair, best, 1, MPI_2DOUBLE_PRECISION, MPI_MAXLOC, MPI_COMM_WORLD, ierr)
    xmax = best(1)
    where = nint(best(2))
  end subroutine par_max_real

  !> The sum of x over the ranks (collective).
  real(wp) function par_sum_real(x)
    real(wp), intent(in) :: x
    integer :: ierr
    call MPI_Allreduce(x, par_sum_real, 1, MPI_DOUBLE_PRECISION, MPI_SUM, MPI_COMM_WORLD, ierr)
  end function par_sum_real

  !> The sum of x over the ranks of this node (MPI_COMM_TYPE_SHARED) and their number.
  subroutine par_node_sum(x, total, count)
    real(wp), intent(in) :: x          !< this rank's value
    real(wp), intent(out) :: total     !< the sum over the node's ranks
    integer, intent(out) :: count      !< ranks on this node
    integer :: node, ierr
    call MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, par_rank(), MPI_INFO_NULL, node, ierr)
    call MPI_Allreduce(x, total, 1, MPI_DOUBLE_PRECISION, MPI_SUM, node, ierr)
    call MPI_Comm_size(node, count, ierr)
    call MPI_Comm_free(node, ierr)
  end subroutine par_node_sum

  !> Whether flag is true on any rank (collective).
  logical function par_any(flag)
    logical, intent(in) :: flag
    integer :: ierr
    call MPI_Allreduce(flag, par_any, 1, MPI_LOGICAL, MPI_LOR, MPI_COMM_WORLD, ierr)
  end function par_any

  !> Stop every rank with code (MPI_Abort): only for a failure that one rank meets alone.
  subroutine par_abort(code)
    integer, intent(in) :: code
    integer :: ierr
    call MPI_Abort(MPI_COMM_WORLD, code, ierr)
  end subroutine par_abort

end module mpi_env
