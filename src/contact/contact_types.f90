!> The types the contact solvers produce and carry, apart from the solvers so that output
!! and checkpoint modules can read and write them without importing a solver:
!! the result of a contact solve with its outer history, the outer state of the Robin
!! iteration (what a checkpoint holds), and the abstract checkpointer that the Robin
!! iteration calls.
module contact_types
  use kinds, only: wp
  use space, only: NRIGID
  implicit none (type, external)
  private

  !> A contact row's force against its bound (robin_state_t%row_state: side 1's + 4 x side 2's):
  !! at the lower bound (a normal row's zero force included), at the upper bound (in space: a
  !! disc's force on its circle), or strictly inside
  integer, parameter, public :: BOUND_LOWER = 1, BOUND_UPPER = 2, BOUND_INSIDE = 3
  !> How a contact solve ended (contact_result_t%status); `status_name` gives the word the
  !! results file and the `result:` line print.
  integer, parameter, public :: STATUS_NONE = 0         !< not solved (yet)
  integer, parameter, public :: STATUS_CONVERGED = 1    !< the stopping criterion was met
  integer, parameter, public :: STATUS_MAX_OUTER = 2    !< max_outer iterations without convergence
  integer, parameter, public :: STATUS_DIVERGED = 3     !< diverged or stagnated (the message says which)
  integer, parameter, public :: STATUS_FAILED = 4       !< a numerical failure (factorization, inner solve)
  integer, parameter, public :: STATUS_INTERRUPTED = 5  !< stopped by a signal
  !> a load history ended at a step whose loads the contact cannot hold (the steps before kept)
  integer, parameter, public :: STATUS_NO_EQUILIBRIUM = 6

  !> Outcome of a contact solve, with the outer history.
  type, public :: contact_result_t
    integer :: status = STATUS_NONE            !< STATUS_*
    integer :: method = 0                      !< METHOD_ROBIN or METHOD_MONOLITHIC (config); 0: none yet
    character(len=256) :: message = ''         !< why it failed, if it did
    integer :: outer = 0                       !< outer iterations (1 for monolithic)
    integer :: inner = 0                       !< Hessian multiplications, all subproblems (IT_inner)
    integer :: inner_maxit_hits = 0            !< subproblems that stopped on inner_max_it
    !! The contact vectors are over the rows of all pairs (m), in the side layout (m, 2):
    !! column s holds, for each row, the value of the body on side s of the row's pair
    !! (contact_interface); a body's own vector is x(slots) (body_condensed_t%slots).
    real(wp), allocatable :: lam(:)            !< (m) normal contact force, mean of the two sides' [force]
    real(wp), allocatable :: lam_body(:, :)    !< (m,2) each side's contact force [force]
    real(wp), allocatable :: w(:, :)           !< (m,2) B u of each side, normal interface displacement [length]
    real(wp), allocatable :: gap(:)            !< (m) w(:, 1) + w(:, 2) - g0 [length]
    real(wp), allocatable :: obstacle(:, :)    !< (m,2) final obstacles of each side [length]
    real(wp) :: criterion = 0.0_wp             !< last value of the stopping criterion
    real(wp) :: residual = 0.0_wp              !< max(imbalance, penetration, complementarity, equilibrium)
    real(wp) :: imbalance = 0.0_wp             !< |lam_1 - lam_2| / |lam|
    real(wp) :: penetration = 0.0_wp           !< max(gap, 0) / displacement scale
    real(wp) :: complementarity = 0.0_wp       !< max lam_i |gap_i| / (max lam * displacement scale)
    real(wp) :: equilibrium = 0.0_wp           !< floating bodies: max_a |G_a lam_a - e_a| / |e_a| (0: none)
    real(wp) :: error_bound = 0.0_wp           !< a posteriori bound of |lam - lam_mono| / |lam| (see error_bound)
    real(wp) :: kappa = 0.0_wp                 !< condition number estimate of the monolithic Hessian
    !> the natural residual |lam - P(lam - (H lam - c)/L)| / |lam| of the mean force (zero at
    !! the monolithic solution; the bound is 2 kappa times it); -1: not computed
    real(wp) :: natural = -1.0_wp
    !> why no bound is given, when the bound is not computed for a reason other than its size
    character(len=200) :: no_bound_reason = ''
    integer :: active = 0                      !< nodes with lam > 0
    !> bodies held only by contact: the amplitudes alpha_a of their rigid motions R_a
    !! (u_a = K_a^+ (f_a - B_a' lam) + R_a alpha_a; alpha_a = -mu_a, the equality multipliers)
    real(wp), allocatable :: rigid(:, :)       !< (NRIGID, bodies) [length] (R_a's columns are dimensionless)
    integer :: eq_updates = 0                  !< SMALBE multiplier updates, all solves
    integer :: nhist = 0                       !< entries in the history
    real(wp), allocatable :: h_criterion(:)    !< per outer iteration
    real(wp), allocatable :: h_residual(:)     !< per outer iteration
    real(wp), allocatable :: h_wall(:)         !< wall time since the start of the iteration [s]
    integer, allocatable :: h_inner(:)         !< cumulative inner multiplications
    integer, allocatable :: h_active(:)        !< active contact nodes
  end type contact_result_t

  integer, parameter, public :: ANDERSON_DEPTH = 5   !< history depth of Anderson acceleration, two bodies
  integer, parameter :: ANDERSON_DEPTH_MAX = 64      !< the largest depth (several pairs: anderson_history)
  integer, parameter, public :: RECYCLE_DEPTH = 32   !< directions (with their images under F_a) kept per body

  !> Everything the outer iteration carries from one iteration to the next: with it a
  !! run resumes bitwise identically from a checkpoint.
  type, public :: robin_state_t
    integer :: it = 0                          !< completed outer iterations
    integer :: inner = 0                       !< cumulative Hessian multiplications
    integer :: nacc = 0                        !< acceleration steps taken
    integer :: stalled = 0                     !< consecutive iterations with a small increment but a large residual
    integer :: it_best = 0                     !< iteration of the last 1% improvement of the residual
    real(wp) :: res_best = huge(1.0_wp)        !< residual at it_best
    real(wp) :: crit = huge(1.0_wp)            !< last criterion
    real(wp) :: progress = huge(1.0_wp)        !< min(increment, residual) of the last iteration
    real(wp) :: best = huge(1.0_wp)            !< best criterion so far
    real(wp) :: omega = 0.0_wp                 !< Aitken relaxation
    real(wp) :: wall = 0.0_wp                  !< wall time spent in the iteration so far [s]
    !! Per body: (bodies) and (3, bodies); on the contact rows: the side layout (m, 2) of
    !! contact_result_t.
    real(wp), allocatable :: flam(:)           !< (bodies) |F_a lam_a| of the last iterate [length]
    real(wp), allocatable :: eq_mult(:, :)     !< (NRIGID, bodies) equality multipliers of floating bodies (SMALBE warm start) [length]
    real(wp), allocatable :: G(:, :)           !< (m,2) obstacles [length]
    real(wp), allocatable :: lam(:, :)         !< (m,2) contact forces, warm starts [force]
    integer :: reuse = 0                       !< 1: flam_v holds F_a lam_a (0: not known, e.g. an older checkpoint)
    real(wp), allocatable :: flam_v(:, :)      !< (m,2) F_a lam_a, the last product of the body's solve [length]
    integer :: nsrch = 0                       !< 1: srch, fsrch hold the last change of lam_a and F_a times it
    real(wp), allocatable :: srch(:, :)        !< (m,2) lam_a after its last solve minus before it [force]
    real(wp), allocatable :: fsrch(:, :)       !< (m,2) F_a srch (difference of the two products F_a lam_a) [length]
    integer, allocatable :: nrw(:, :)          !< (2, bodies) per body: directions held in rw, next slot to fill
    !> (bodies, inner_solver 'auto') 1: the body's QP needed the active-set Newton method, so its
    !! later solves use it alone; k >= 2: its last MPRGP solve cost more than two Newton steps,
    !! so its next solve starts with the Newton method, within k - 1 steps; k <= -1: its next
    !! solve is polished (MPRGP to a loose tolerance, then the Newton method within -k steps);
    !! 0: MPRGP first
    integer, allocatable :: newton(:)
    !> (bodies) 1: the body's active-set method holds the factor LAPACK makes of the free block
    !! of its last forces (the rows strictly inside their bounds), which its next solve may
    !! take as it is; a resumed run makes it again first (module robin_subproblems)
    integer, allocatable :: kept(:)
    !> (m, 2 k) per body up to k F_a-orthonormal directions of its solves, in the side layout:
    !! direction j of a body is in column j on its side-1 rows and k + j on its side-2 rows
    real(wp), allocatable :: rw(:, :)          !< [1/sqrt(length force)]
    real(wp), allocatable :: raw(:, :)         !< (m, 2 k) F_a rw, the same layout
    real(wp), allocatable :: r_prev(:)         !< (2m) previous fixed-point residual
    real(wp), allocatable :: x_prev(:)         !< (2m) previous obstacles (Anderson)
    real(wp), allocatable :: dX(:, :), dR(:, :) !< (2m, depth) Anderson differences
    !> friction: per row the bound state of both sides' forces in the last iterate
    !! (robin_iteration's row_bound_state; -1: not known)
    integer, allocatable :: row_state(:)
    integer :: settled = 0                     !< 1: row_state did not change in the last iteration
  end type robin_state_t

  !> Where the Robin iteration saves its state: `save` is called every `every` outer
  !! iterations (0: never) and when the run is stopped by a signal. A failed save must not
  !! stop the iteration; the implementation records it and the driver reports it.
  type, abstract, public :: checkpointer_t
    integer :: every = 0     !< outer iterations between checkpoints (0: only on a signal)
  contains
    procedure(checkpointer_save_iface), deferred :: save   !< write (state, history)
  end type checkpointer_t

  abstract interface
    !> Save the outer state after iteration st%it and the history so far.
    subroutine checkpointer_save_iface(self, st, res)
      import :: checkpointer_t, robin_state_t, contact_result_t
      class(checkpointer_t), intent(inout) :: self
      type(robin_state_t), intent(in) :: st
      type(contact_result_t), intent(in) :: res
    end subroutine checkpointer_save_iface
  end interface

  public :: state_init, alloc_result, grow_history, recycle_size, status_name, anderson_history

contains

  !> The word for a STATUS_* code: 'none', 'converged', 'max_outer', 'diverged', 'failed',
  !! 'interrupted', 'no_equilibrium' (what the results file and the `result:` line hold).
  function status_name(status) result(name)
    integer, intent(in) :: status   !< a STATUS_* code
    character(len=:), allocatable :: name
    select case (status)
    case (STATUS_NONE)
      name = 'none'
    case (STATUS_CONVERGED)
      name = 'converged'
    case (STATUS_MAX_OUTER)
      name = 'max_outer'
    case (STATUS_DIVERGED)
      name = 'diverged'
    case (STATUS_FAILED)
      name = 'failed'
    case (STATUS_INTERRUPTED)
      name = 'interrupted'
    case (STATUS_NO_EQUILIBRIUM)
      name = 'no_equilibrium'
    case default
      name = 'unknown'
    end select
  end function status_name

  !> Fresh outer state: obstacles at the initial gap, no contact force.
  subroutine state_init(st, m, g0, nbody, npair)
    type(robin_state_t), intent(out) :: st   !< state to initialise
    integer, intent(in) :: m                 !< contact rows of all pairs
    real(wp), intent(in) :: g0(:)            !< initial gap
    integer, intent(in) :: nbody             !< bodies
    integer, intent(in) :: npair             !< pairs
    allocate (st%flam(nbody), st%eq_mult(NRIGID, nbody), st%nrw(2, nbody))
    allocate (st%newton(nbody), st%kept(nbody), source=0)
    st%flam = 0.0_wp
    st%eq_mult = 0.0_wp
    st%nrw(1, :) = 0
    st%nrw(2, :) = 1
    allocate (st%G(m, 2), st%lam(m, 2), st%r_prev(2*m), st%x_prev(2*m))
    allocate (st%dX(2*m, anderson_history(nbody, npair)), st%dR(2*m, anderson_history(nbody, npair)))
    allocate (st%flam_v(m, 2), st%srch(m, 2), st%fsrch(m, 2), st%row_state(m))
    st%row_state = -1
    allocate (st%rw(m, 2*recycle_size(m)), st%raw(m, 2*recycle_size(m)))
    st%rw = 0.0_wp
    st%raw = 0.0_wp
    st%srch = 0.0_wp
    st%fsrch = 0.0_wp
    st%flam_v = 0.0_wp   ! F_a 0 with lam = 0: exact
    st%reuse = 1
    st%G(:, 1) = g0
    st%G(:, 2) = g0
    st%lam = 0.0_wp
    st%r_prev = 0.0_wp
    st%x_prev = 0.0_wp
    st%dX = 0.0_wp
    st%dR = 0.0_wp
  end subroutine state_init

  !> The history depth of Anderson acceleration: ANDERSON_DEPTH for two bodies in one pair;
  !! for several pairs the number of bodies, between ANDERSON_DEPTH and ANDERSON_DEPTH_MAX (in a chain
  !! of N bodies the slow modes of the outer map are about N: a stack of 32 blocks took 383
  !! outer iterations at depth 5, 96 at 20 and 39 at 40).
  pure integer function anderson_history(nbody, npair) result(k)
    integer, intent(in) :: nbody, npair
    if (npair <= 1) then
      k = ANDERSON_DEPTH
    else
      k = min(ANDERSON_DEPTH_MAX, max(ANDERSON_DEPTH, nbody))
    end if
  end function anderson_history

  !> Directions kept per body for m contact nodes: RECYCLE_DEPTH, at most m.
  pure integer function recycle_size(m)
    integer, intent(in) :: m   !< interface size
    recycle_size = max(0, min(RECYCLE_DEPTH, m))
  end function recycle_size

  !> Allocate the result for m contact rows, nbody bodies and a history of nh entries, all zero.
  subroutine alloc_result(res, m, nh, nbody)
    type(contact_result_t), intent(inout) :: res
    integer, intent(in) :: m, nh, nbody
    if (allocated(res%rigid)) deallocate (res%rigid)
    allocate (res%rigid(NRIGID, nbody))
    res%rigid = 0.0_wp
    if (allocated(res%lam)) deallocate (res%lam, res%lam_body, res%w, res%gap, res%obstacle)
    if (allocated(res%h_criterion)) deallocate (res%h_criterion, res%h_residual, res%h_wall, res%h_inner, res%h_active)
    allocate (res%lam(m), res%lam_body(m, 2), res%w(m, 2), res%gap(m), res%obstacle(m, 2))
    allocate (res%h_criterion(nh), res%h_residual(nh), res%h_wall(nh), res%h_inner(nh), res%h_active(nh))
    res%lam = 0.0_wp; res%lam_body = 0.0_wp; res%w = 0.0_wp; res%gap = 0.0_wp; res%obstacle = 0.0_wp
    res%h_criterion = 0.0_wp; res%h_residual = 0.0_wp; res%h_wall = 0.0_wp; res%h_inner = 0; res%h_active = 0
  end subroutine alloc_result

  !> Grow the history arrays to nh entries, keeping the first res%nhist.
  subroutine grow_history(res, nh)
    type(contact_result_t), intent(inout) :: res
    integer, intent(in) :: nh
    real(wp), allocatable :: r(:)
    integer, allocatable :: i(:)
    integer :: n
    n = min(res%nhist, size(res%h_criterion), nh)
    allocate (r(nh)); r = 0.0_wp; r(1:n) = res%h_criterion(1:n); call move_alloc(r, res%h_criterion)
    allocate (r(nh)); r = 0.0_wp; r(1:n) = res%h_residual(1:n); call move_alloc(r, res%h_residual)
    allocate (r(nh)); r = 0.0_wp; r(1:n) = res%h_wall(1:n); call move_alloc(r, res%h_wall)
    allocate (i(nh)); i = 0; i(1:n) = res%h_inner(1:n); call move_alloc(i, res%h_inner)
    allocate (i(nh)); i = 0; i(1:n) = res%h_active(1:n); call move_alloc(i, res%h_active)
  end subroutine grow_history

end module contact_types
