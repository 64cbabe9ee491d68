!> The serial back-end: every body in this process, the bodies on the OpenMP threads
!! (dynamic schedule, largest first), factorized by CHOLMOD or the banded Cholesky
!! (condense::factor_body, each body's factorization%factor_t).
module serial_backend
  use kinds, only: wp
  use errors, only: error_t
  use fatal_errors, only: terminate, fail_on
  use config, only: deck_t
  use assembly, only: expand
  use condense, only: factor_body, condense_body, recover_displacement
  use contact_common, only: gather
  use sorting, only: largest_first
  use sysinfo, only: memory_limit_mb
  use budget, only: check_budget
  use mpi_env, only: par_finalize
  use run_state, only: run_t
  use run_backend, only: backend_t
  use load_history, only: step_interface_load
  use strings, only: i2s
  implicit none (type, external)
  private

  !> Every body here, the bodies on the threads.
  type, extends(backend_t), public :: serial_backend_t
  contains
    procedure :: check_memory, factor, condense, condense_load, record_factor_memory, share_contact_forces, recover, &
                 agree_code, report_ranks, finish
  end type serial_backend_t

  abstract interface
    !> One body's share of a phase; a failure in err.
    subroutine body_work_i(run, a, err)
      import :: run_t, error_t
      type(run_t), intent(inout) :: run   !< the run (body a's parts only are touched)
      integer, intent(in) :: a            !< the body
      type(error_t), intent(out) :: err   !< its failure, if any
    end subroutine body_work_i
  end interface

contains

  !> The whole run against this process's memory (exit 1, nothing allocated yet).
  subroutine check_memory(self, run, the_deck)
    class(serial_backend_t), intent(inout) :: self
    type(run_t), intent(in) :: run          !< the run
    type(deck_t), intent(in) :: the_deck    !< the deck to size
    type(error_t) :: err
    call check_budget(the_deck, memory_limit_mb(), err)
    call fail_on(err, 'deck '//trim(the_deck%source))
  end subroutine check_memory

  !> Order and factorize every body, the largest first. The team has all the run's threads
  !! even with fewer bodies: a thread without a body waits at the loop's barrier, where it
  !! runs tiles of the others' factorizations (blas_tiles.c).
  subroutine factor(self, run)
    class(serial_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its systems factorized into its bodies
    call each_body(run, factor_one, 'factorization failed')
  end subroutine factor

  !> Every body's interface flexibility F_a and b_a, the largest first.
  subroutine condense(self, run)
    class(serial_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its bodies condensed
    call each_body(run, condense_one, 'condensation failed')
  end subroutine condense

  !> Every body's b_a for the current step's loads (one solve each), the largest first.
  subroutine condense_load(self, run)
    class(serial_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its bodies' interface loads
    call each_body(run, load_one, 'load step condensation failed')
  end subroutine condense_load

  !> The factors' memory [MiB].
  subroutine record_factor_memory(self, run)
    class(serial_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its timing
    integer :: a
    run%timing%factor_mb = 0.0_wp
    run%timing%factor_tiles = sum([(run%bodies(a)%fac%stats%tiles, a=1, run%nbody)])
    do a = 1, run%nbody
      run%timing%factor_mb = run%timing%factor_mb + run%bodies(a)%fac%stats%mem_bytes/1048576.0_wp
    end do
  end subroutine record_factor_memory

  !> The contact forces are here already.
  subroutine share_contact_forces(self, run)
    class(serial_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run
  end subroutine share_contact_forces

  !> Every body's displacement under its own contact forces, the largest first.
  subroutine recover(self, run)
    class(serial_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its displacements
    call each_body(run, recover_one, 'displacement recovery failed')
  end subroutine recover

  !> One process decides its exit code alone.
  subroutine agree_code(self, run)
    class(serial_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run
  end subroutine agree_code

  !> No ranks to report.
  subroutine report_ranks(self, run)
    class(serial_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run
  end subroutine report_ranks

  !> End the run with its code.
  subroutine finish(self, run)
    class(serial_backend_t), intent(inout) :: self
    type(run_t), intent(inout) :: run   !< the run: its exit code
    call par_finalize()
    call terminate(run%code)
  end subroutine finish

  ! ---- the bodies on the threads ------------------------------------------------------

  !> work(run, a, err(a)) for every body on the run's threads (dynamic schedule, the largest
  !! body first), then the first failure as the fatal error 'body <a>: <what>: <reason>'.
  !! The team has all the run's threads even with fewer bodies: a thread without a body
  !! waits at the loop's barrier, where it runs the tasks the others make (the tiles of a
  !! factorization, the condensation's panels).
  subroutine each_body(run, work, what)
    type(run_t), intent(inout) :: run
    procedure(body_work_i) :: work
    character(len=*), intent(in) :: what    !< what failed, for the message
    type(error_t), allocatable :: err(:)
    integer, allocatable :: order(:)
    integer :: a, k
    allocate (err(run%nbody))
    order = largest_first([(run%systems(a)%n, a=1, run%nbody)])
    !$omp parallel do num_threads(run%threads) schedule(dynamic, 1) private(a)
    do k = 1, run%nbody
      a = order(k)
      call work(run, a, err(a))
    end do
    !$omp end parallel do
    do a = 1, run%nbody
      call fail_on(err(a), 'body '//i2s(a)//': '//what)
    end do
  end subroutine each_body

  !> Order and factorize body a.
  subroutine factor_one(run, a, err)
    type(run_t), intent(inout) :: run
    integer, intent(in) :: a
    type(error_t), intent(out) :: err
    call factor_body(run%deck%solver%factor, run%contact_line, a, run%meshes(a), run%systems(a), run%bodies(a), err)
  end subroutine factor_one

  !> Body a's interface flexibility F_a and b_a.
  subroutine condense_one(run, a, err)
    type(run_t), intent(inout) :: run
    integer, intent(in) :: a
    type(error_t), intent(out) :: err
    call condense_body(run%systems(a), run%bodies(a), err)
  end subroutine condense_one

  !> Body a's b_a for the current step's loads (one solve).
  subroutine load_one(run, a, err)
    type(run_t), intent(inout) :: run
    integer, intent(in) :: a
    type(error_t), intent(out) :: err
    call step_interface_load(run%contact_line, a, run%systems(a), run%bodies(a), err)
  end subroutine load_one

  !> Body a's displacement under its own contact forces.
  subroutine recover_one(run, a, err)
    type(run_t), intent(inout) :: run
    integer, intent(in) :: a
    type(error_t), intent(out) :: err
    real(wp), allocatable :: ufree(:)
    allocate (ufree(run%systems(a)%n))
    call recover_displacement(run%systems(a), run%bodies(a), gather(run%result%lam_body, run%bodies(a)%slots), ufree, err)
    if (.not. err%failed()) call expand(run%systems(a), ufree, run%displacement(1:run%systems(a)%ndof, a))
  end subroutine recover_one

end module serial_backend
