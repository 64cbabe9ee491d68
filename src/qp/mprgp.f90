!> MPRGP: modified proportioning with reduced gradient projection, for the
!! bound-constrained convex quadratic program
!!
!!     minimise 1/2 x'Ax - b'x   subject to   l <= x <= u
!!
!! with A symmetric positive definite, given as a `class(linop_t)` (dense, sparse or
!! implicit). Z. Dostal and J. Schoberl, "Minimizing quadratic functions subject to
!! bound constraints with the rate of convergence and finite termination",
!! Comput. Optim. Appl. 30 (2005) 23-43; for the box, Z. Dostal, "Optimal Quadratic
!! Programming Algorithms", Springer 2009, ch. 5.
!!
!! Notation (g = Ax - b, projection P(x) = min(max(x, l), u), free set
!! F = {i : l_i < x_i < u_i}, active set its complement):
!!   free gradient        phi_i  = g_i on F, 0 else
!!   chopped gradient     beta_i = min(g_i, 0) at x_i = l_i, max(g_i, 0) at x_i = u_i,
!!                                 0 on F and where l_i = u_i (a fixed variable)
!!   projected gradient   gP     = phi + beta            (stopping criterion)
!!   reduced free grad.   phit_i = min((x_i - l_i)/alpha_bar, phi_i) on F where phi_i > 0,
!!                                 max((x_i - u_i)/alpha_bar, phi_i) on F where phi_i < 0
!! x is *proportional* when |beta|^2 <= Gamma^2 phit'phi. Then a conjugate gradient
!! step along p is tried; if it stays feasible it is taken (CG step), otherwise the
!! feasible part of it (cut at either bound) is taken and followed by the projected step
!! P(x - alpha_bar phi) - x, after which CG restarts (expansion step). A non-proportional
!! x gets an exact line search along -beta (proportioning step), which releases variables
!! from their bounds; in a box it is cut where a released variable reaches its other bound.
!!
!! The solver reaches its constraints only through one `class(constraint_set_t)` (module
!! constraint_set: the projection, the free set, the chopped, projected and reduced
!! gradients, the feasible step): `solve_in` takes any such set, `solve` the box
!! lb <= x <= ub as a `box_set_t`. A lower bound -huge(1.0_wp) or an upper bound
!! +huge(1.0_wp) means "no bound"; the upper bounds are optional (absent: none). All other
!! bounds must be finite, and l <= u. The upper-bound branches are never taken when
!! u = +huge, so a solve without upper bounds executes the same floating-point operations,
!! iterate for iterate, with or without ub.
!!
!! A set whose faces are curved (`linear` false: the discs of 3D friction, module
!! tangent_discs) makes this MPGP (Dostal and Kozubek): its proportioning step is projected
!! and the gradient computed again; QP_NEWTON on it is module disc_newton's method along the
!! circles, QP_AUTO (and the Newton-first and polished variants, which keep box factors)
!! MPGP within 'auto''s budget and then that method.
!!
!! Thread safety: no module variables, no SAVE, work arrays are local to each call.
!! Two threads may solve concurrently with two different operators.
module mprgp
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp
  use linop, only: linop_t, dense_op_t
  use qp_newton, only: newton_work_t, newton_step, newton_begin, NEWTON_FULL, NEWTON_STILL, NEWTON_NOT_SPD
  use strings, only: i2s
  use errors, only: error_t, ERR_NUMERICAL
  use mprgp_options, only: mprgp_opts_t, mprgp_stats_t, mprgp_status_name, check_options, MPRGP_CONVERGED, &
                           MPRGP_MAX_IT, MPRGP_NONFINITE, MPRGP_NOT_SPD, MPRGP_BAD_ARG, MPRGP_STOPPED, &
                           QP_AUTO, QP_MPRGP, QP_NEWTON, QP_NEWTON_FIRST, QP_POLISH
  use mprgp_support, only: lambda_max_estimate, power_iteration, line_search, recycled_subspace, store_direction
  use constraint_set, only: constraint_set_t, box_set_t, box_set, chopped
  use tangent_discs, only: disc_set_t
  use disc_newton, only: disc_newton_step, disc_held, DN_STILL, DN_NOT_SPD, disc_factor_t
  implicit none (type, external)
  private

  public :: lambda_max_estimate, mprgp_status_name, chopped
  public :: mprgp_t, mprgp_opts_t, mprgp_stats_t, constraint_set_t, box_set_t, box_set
  public :: MPRGP_CONVERGED, MPRGP_MAX_IT, MPRGP_NONFINITE, MPRGP_NOT_SPD, MPRGP_BAD_ARG, MPRGP_STOPPED
  public :: QP_AUTO, QP_MPRGP, QP_NEWTON, QP_NEWTON_FIRST, QP_POLISH

  !> Safety factor: default alpha_bar = ALPHA_FACTOR / lambda_max (theory: (0, 2/|A|]).
  real(wp), parameter :: ALPHA_FACTOR = 1.9_wp
  !> At most this many retries of one expansion step with a reduced alpha_bar.
  integer, parameter :: MAX_RETRY = 60
  !> The Newton method is used up to this size on a dense A (its factor: n^2 reals, 512 MiB
  !! at n = 8192, beside A that the problem holds anyway) and up to NEWTON_MAX_N_BUILT on
  !! any other operator (whose dense matrix it must first build by n products: 2 n^2 reals);
  !! larger problems are solved by MPRGP whatever opts%method says.
  integer, parameter :: NEWTON_MAX_N = 8192
  integer, parameter :: NEWTON_MAX_N_BUILT = 4096
  !> QP_AUTO's budget of MPRGP steps: max(AUTO_BUDGET_MIN, n/AUTO_BUDGET_DIV), about three
  !! factorizations of a free block of n/2 unknowns
  integer, parameter :: AUTO_BUDGET_MIN = 100
  integer, parameter :: AUTO_BUDGET_DIV = 16
  !> Working precision of a Newton solve: |gP| <= NEWTON_FLOOR n eps lambda_max |x|.
  real(wp), parameter :: NEWTON_FLOOR = 10.0_wp

  !> An MPRGP solver: its options, what its last solve did, and the vectors a sequence of
  !! solves with one operator hands on from one solve to the next. One solver per thread.
  type :: mprgp_t
    type(mprgp_opts_t) :: opts             !< options
    type(mprgp_stats_t) :: stats           !< outcome of the last solve
    real(wp), allocatable :: g(:)          !< A x - b at the returned x (units of b)
    !> in (opts%use_ax): A x at the warm start; out: A x at the returned x, the start of the
    !! next solve from it
    real(wp), allocatable :: ax(:)
    real(wp), allocatable :: s(:)          !< direction of a first line search (next solve only; needs as)
    real(wp), allocatable :: as(:)         !< A s
    real(wp), allocatable :: eq_g(:, :)    !< (r, n) equality rows (SMALBE; with eq_e, opts%eq_m)
    real(wp), allocatable :: eq_e(:)       !< (r) their right-hand side
    !> the Newton method's dense copy of an operator that is not a dense_op_t, kept for the
    !! next solves of this solver (it is taken to be the same A: a caller whose A changes
    !! deallocates it)
    real(wp), allocatable :: dense(:, :)
    !> the caller's Newton work kept from one solve to the next (its free block's factor is
    !! taken again while the free set recurs); `keep_same_a`: A is the one of its last solve
    type(newton_work_t), pointer :: keep => null()
    logical :: keep_same_a = .false.
    !> the caller's factor of the Newton method on the discs, carried from one solve to the
    !! next with the same A (the caller drops it when A changes): a solve takes it only as
    !! a new factorization would make it (disc_factor_t%carried)
    type(disc_factor_t), pointer :: keep_disc => null()
    !> the Newton method on the discs starts from the face of x: every variable on its bound
    !! and every disc on its circle held (a warm start from the last solve's answer: its
    !! face, whose factor keep_disc may hold), releasing only at the face's minimiser; else
    !! from the binding ones (on the boundary with the gradient pointing out)
    logical :: hold_boundary = .false.
    ! the iteration's state
    integer, private :: n = 0              ! unknowns
    integer, private :: it = 0             ! steps taken
    logical, private :: fresh = .false.    ! g was computed as A x - b, not by recurrence
    logical, private :: zero_tol = .false. ! no tolerance given: stop at the rounding floor
    real(wp), private :: tol = 0.0_wp      ! max(rtol |b|, atol)
    real(wp), private :: ab = 0.0_wp       ! alpha_bar in use (0: not yet needed)
    real(wp), private :: lam_lo = 0.0_wp   ! largest known lower bound of lambda_max
    real(wp), private :: xscale0 = 0.0_wp  ! |x| of the projected start
    real(wp), allocatable, private :: p(:), ap(:), w(:), v(:), av(:)
    logical, allocatable, private :: free(:)  ! the free set of the iterate, where it was last taken
  contains
    procedure :: solve => mprgp_solve
    procedure :: solve_in => mprgp_solve_in
  end type mprgp_t

  !> What the stopping test asks the main loop to do.
  integer, parameter :: GO_ON = 0, DONE = 1, RETEST = 2

contains

  !> Solve min 1/2 x'Ax - b'x subject to lb <= x <= ub by MPRGP (without ub: x >= lb).
  !!
  !! x is a warm start on entry (projected onto the bounds first) and the solution
  !! on exit (the last iterate on failure); self%g holds A x - b and self%ax A x there.
  !! The run stops when |gP| <= max(rtol |b|, atol); if both are zero (b = 0 and atol = 0),
  !! at the rounding-level floor 10 sqrt(n) eps lambda_max max(|x|, |x_0|), x_0 the projected
  !! start. Convergence is always confirmed on a freshly computed gradient Ax - b (one extra
  !! product); if the recurrence drifted, the iteration continues from the true one.
  !!
  !! Guard on alpha_bar. The power iteration underestimates lambda_max, so
  !! 1.9/estimate may exceed the admissible 2/lambda_max. Every product with A made
  !! by the iteration (CG direction, proportioning direction, expansion step) yields
  !! a Rayleigh quotient d'Ad/d'd <= lambda_max; the largest one raises the
  !! lambda_max used, and whenever alpha_bar * (that value) > 2, alpha_bar is cut to
  !! 1.9/(that value). In an expansion step the projected step d costs
  !! g'd + 1/2 d'Ad; since g'd <= -|d|^2/alpha_bar, it can only increase the cost if
  !! d'Ad/d'd > 2/alpha_bar, i.e. exactly when the cut above happens: the step is then
  !! recomputed from the half step with the reduced alpha_bar (at most 60 times, each
  !! one product). A cost increase without such a curvature (rounding) is accepted.
  !! A user-given alpha_bar is subject to the same guard.
  !!
  !! Cost per step: one product with A (two for an expansion) and O(n) work.
  !!
  !! Reuse across a sequence of solves with the same A (the outer contact iteration):
  !! with opts%use_ax, self%ax holds A x at the warm start and the initial product is
  !! skipped; on exit it holds A x at the returned x (the confirming product, so the next
  !! solve, warm-started from x, starts from it). With a direction self%s and self%as = A s
  !! (e.g. the change of x in the previous solve and of A x), the iteration starts with an
  !! exact line search along s, cut at both bounds, which costs no product; the solve
  !! consumes s and as.
  !! Krylov recycling: with rw, raw, nrw (a ring of A-normalised directions and their
  !! images, filled by every conjugate gradient step of the solves that share it) and
  !! opts%recycle, the iteration starts from the minimum over x plus the span of s and of
  !! the stored directions that vanish where x is at a bound (A-orthogonalised; a
  !! direction with less than 1% of its A-norm left is dropped, so the recurrence gradient
  !! stays accurate), taken only if the whole step is feasible and leaves a proportional
  !! iterate with a smaller projected gradient: again no product.
  !! A warm start whose projected gradient (from opts%use_ax) already meets the tolerance
  !! is returned without a search or a product.
  subroutine mprgp_solve(self, A, b, lb, x, rw, raw, nrw, ub)
    class(mprgp_t), intent(inout) :: self           !< the solver (options in, outcome out)
    class(linop_t), intent(inout) :: A              !< SPD operator (size A%n)
    real(wp), intent(in) :: b(:)                    !< linear term (size n)
    real(wp), intent(in) :: lb(:)                   !< lower bounds (size n); -huge(1.0_wp): none
    real(wp), intent(inout) :: x(:)                 !< in: warm start; out: solution
    real(wp), intent(inout), optional :: rw(:, :)   !< (n, k) stored directions, A-normalised (needs raw, nrw)
    real(wp), intent(inout), optional :: raw(:, :)  !< (n, k) A rw
    integer, intent(inout), optional :: nrw(2)      !< directions held in rw, next slot to fill (ring)
    real(wp), intent(in), optional :: ub(:)         !< upper bounds (size n, >= lb); +huge(1.0_wp): none
    call mprgp_solve_in(self, A, b, box_set(lb, ub), x, rw, raw, nrw)
  end subroutine mprgp_solve

  !> Solve min 1/2 x'Ax - b'x subject to x in `set` by MPRGP: `solve` for any constraint
  !! set (the warm start x is projected onto the set first).
  subroutine mprgp_solve_in(self, A, b, set, x, rw, raw, nrw)
    class(mprgp_t), intent(inout) :: self           !< the solver (options in, outcome out)
    class(linop_t), intent(inout) :: A              !< SPD operator (size A%n)
    real(wp), intent(in) :: b(:)                    !< linear term (size n)
    class(constraint_set_t), intent(in) :: set      !< the feasible set
    real(wp), intent(inout) :: x(:)                 !< in: warm start; out: solution
    real(wp), intent(inout), optional :: rw(:, :)   !< (n, k) stored directions, A-normalised (needs raw, nrw)
    real(wp), intent(inout), optional :: raw(:, :)  !< (n, k) A rw
    integer, intent(inout), optional :: nrw(2)      !< directions held in rw, next slot to fill (ring)
    integer :: method, max_it, budget
    real(wp) :: tol

    self%stats = mprgp_stats_t()
    if (.not. valid_arguments(self, A%n, b, set, x, rw, raw, nrw)) then
      call consume_search(self)
      return
    end if
    self%stats%b_norm = norm2(b)
    if (self%n == 0) then
      self%stats%status = MPRGP_CONVERGED
      self%stats%message = 'converged: empty problem'
      call consume_search(self)
      return
    end if
    call start(self, A, b, set, x, rw, raw, nrw)
    method = self%opts%method
    ! a set with curved faces (discs): MPGP, the Newton method along its circles (module
    ! disc_newton), or 'auto' between them (its Newton-first and polished variants keep box
    ! factors: 'auto' there)
    if (.not. set%linear() .and. method /= QP_NEWTON .and. method /= QP_MPRGP) method = QP_AUTO
    if (method /= QP_MPRGP) then
      select type (A)
      type is (dense_op_t)
        if (self%n > NEWTON_MAX_N) method = QP_MPRGP
      class default
        if (self%n > NEWTON_MAX_N_BUILT) method = QP_MPRGP
      end select
    end if
    select case (method)
    case (QP_NEWTON)
      if (set%linear()) then
        call newton_loop(self, A, b, set, x)
      else
        call disc_newton_loop(self, A, b, set, x, rw, raw, nrw)
      end if
    case (QP_AUTO)
      call auto_steps()
    case (QP_NEWTON_FIRST)
      ! the Newton method within its budget (a warm start on the solution's face ends in one
      ! step); 'auto' from where it stopped when the active set moved more than that
      call newton_then_auto(self%opts%newton_budget)
    case (QP_POLISH)
      ! MPRGP at the looser tolerance within 'auto''s budget; from there the Newton method
      ! within its budget; what is left by 'auto' at the real tolerance
      tol = self%tol
      self%tol = tol*self%opts%polish_scale
      max_it = self%opts%max_it
      budget = self%opts%auto_budget
      if (budget == 0) budget = max(AUTO_BUDGET_MIN, self%n/AUTO_BUDGET_DIV)
      self%opts%max_it = min(max_it, budget)
      call mprgp_loop(self, A, b, set, x, rw, raw, nrw)
      self%opts%max_it = max_it
      self%tol = tol
      if (self%stats%status == MPRGP_CONVERGED .or. (self%stats%status == MPRGP_MAX_IT .and. budget < max_it)) then
        if (.not. self%fresh) call true_gradient(self, A, b, x)
        call newton_then_auto(self%it + self%opts%newton_budget)
      end if
    case default
      call mprgp_loop(self, A, b, set, x, rw, raw, nrw)
    end select
    self%stats%lambda_max = self%lam_lo
    self%stats%alpha_bar = self%ab
    ! Report the true gradient (and |gP| from it) unless the iteration broke down.
    if (.not. self%fresh .and. (self%stats%status == MPRGP_MAX_IT .or. self%stats%status == MPRGP_NOT_SPD)) then
      call true_gradient(self, A, b, x)
      self%stats%gp_norm = set%projected_gradient_norm(x, self%g)
    end if
    if (.not. self%fresh) self%ax = self%g + b
    call consume_search(self)

  contains

    !> The Newton method up to step `limit`; if it stops there unconverged, 'auto' from where
    !! it stopped (fell_back).
    subroutine newton_then_auto(limit)
      integer, intent(in) :: limit
      max_it = self%opts%max_it
      self%opts%max_it = min(max_it, limit)
      call newton_loop(self, A, b, set, x)
      self%opts%max_it = max_it
      if (self%stats%status == MPRGP_MAX_IT .and. self%it < max_it) then
        self%stats%fell_back = .true.
        if (.not. self%fresh) call true_gradient(self, A, b, x)
        call set_p_to_phi(self, set, x)
        call auto_steps()
      end if
    end subroutine newton_then_auto

    !> MPRGP within a budget of about three factorizations of a free block of half the
    !! unknowns (counted on from the steps already taken); the Newton method from where it
    !! stopped (a conditioning MPRGP pays for, the Newton method does not).
    subroutine auto_steps()
      max_it = self%opts%max_it
      budget = self%opts%auto_budget
      if (budget == 0) budget = max(AUTO_BUDGET_MIN, self%n/AUTO_BUDGET_DIV)
      budget = self%it + budget
      self%opts%max_it = min(max_it, budget)
      call mprgp_loop(self, A, b, set, x, rw, raw, nrw)
      self%opts%max_it = max_it
      if (self%stats%status == MPRGP_MAX_IT .and. budget < max_it) then
        self%stats%switched = .true.
        if (.not. self%fresh) call true_gradient(self, A, b, x)
        if (set%linear()) then
          call newton_loop(self, A, b, set, x)
        else
          call disc_newton_loop(self, A, b, set, x, rw, raw, nrw)
        end if
      end if
    end subroutine auto_steps

  end subroutine mprgp_solve_in

  !> MPRGP's steps until the stopping test ends the solve.
  subroutine mprgp_loop(self, A, b, set, x, rw, raw, nrw)
    type(mprgp_t), intent(inout) :: self
    class(linop_t), intent(inout) :: A
    real(wp), intent(in) :: b(:)
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(inout) :: x(:)
    real(wp), intent(inout), optional :: rw(:, :), raw(:, :)
    integer, intent(inout), optional :: nrw(2)
    real(wp) :: betabeta, phitphi
    logical :: ok
    main: do
      select case (stopping_test(self, A, b, set, x, betabeta, phitphi))
      case (DONE)
        exit main
      case (RETEST)
        cycle main
      end select
      self%it = self%it + 1
      if (proportional(self, A, set, x, betabeta, phitphi, ok)) then
        if (ok) ok = cg_or_expansion_step(self, A, set, x, rw, raw, nrw)
      else if (ok) then
        ok = proportioning_step(self, A, b, set, x, betabeta)
      end if
      if (.not. ok) exit main
    end do main
  end subroutine mprgp_loop

  !> The active-set Newton method's steps (module qp_newton) until the stopping test ends
  !! the solve, on the dense matrix of A (A itself when it is a dense_op_t, else built by n
  !! products once and kept in self%dense for the solver's next solves). Two whole steps in a row on the same face leave x at that face's minimiser
  !! to working precision: if the projected gradient is still above the tolerance then, the
  !! tolerance is below what double precision resolves for this A, and the solve ends as
  !! converged to working precision when |gP| is within NEWTON_FLOOR n eps lambda_max |x|
  !! (a Cholesky solve's backward error), as failed (max_it) above it.
  subroutine newton_loop(self, A, b, set, x)
    type(mprgp_t), intent(inout) :: self
    class(linop_t), intent(inout) :: A
    real(wp), intent(in) :: b(:)
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(inout) :: x(:)
    type(newton_work_t), target :: own
    type(newton_work_t), pointer :: work
    real(wp) :: betabeta, phitphi, flops
    integer :: outcome, j, n
    n = self%n
    if (associated(self%keep)) then
      work => self%keep
      call newton_begin(work, self%keep_same_a)
      self%keep_same_a = .true.     ! a second Newton phase of this solve: the same A
    else
      work => own
    end if
    select type (A)
    type is (dense_op_t)
      call newton_steps(A%a)
    class default
      if (allocated(self%dense)) then
        if (size(self%dense, 1) /= n) deallocate (self%dense)
      end if
      if (.not. allocated(self%dense)) then
        allocate (self%dense(n, n))
        do j = 1, n
          self%v = 0.0_wp
          self%v(j) = 1.0_wp
          call A%apply(self%v, self%dense(:, j))
        end do
        self%stats%n_matvec = self%stats%n_matvec + n
      end if
      call newton_steps(self%dense)
    end select

  contains

    subroutine newton_steps(am)
      real(wp), intent(in) :: am(:, :)
      logical :: refined
      integer :: nfac
      refined = .false.
      main: do
        select case (stopping_test(self, A, b, set, x, betabeta, phitphi))
        case (DONE)
          exit main
        case (RETEST)
          cycle main
        end select
        self%it = self%it + 1
        nfac = work%factored
        call newton_step(am, set, x, self%g, self%ax, work, outcome, flops)
        self%fresh = .false.
        self%stats%n_newton = self%stats%n_newton + 1
        self%stats%n_factor = self%stats%n_factor + work%factored - nfac
        self%stats%n_matvec = self%stats%n_matvec + max(1, nint(flops/(2.0_wp*real(n, wp)**2)))
        if (outcome == NEWTON_NOT_SPD) then
          call fail(self, MPRGP_NOT_SPD, 'the active-set Newton method met a curvature <= 0 at step '// &
                    i2s(self%it)//': A is not SPD')
          exit main
        end if
        if (.not. (outcome == NEWTON_STILL .or. (outcome == NEWTON_FULL .and. work%same_face))) then
          refined = .false.
          cycle main
        end if
        ! x solves its face (twice in a row): the gradient afresh, and one more step from it
        ! when that is not enough; a second time, the rounding level of A is reached
        call true_gradient(self, A, b, x)
        self%stats%gp_norm = set%projected_gradient_norm(x, self%g)
        if ((self%stats%gp_norm <= self%tol .and. .not. self%zero_tol) .or. .not. refined) then
          refined = .true.
          cycle main
        end if
        call newton_verdict(self, am, x, ' Newton steps (x solves its face exactly; the tolerance asked for is '// &
                            'below what double precision resolves)', 'the Newton method', &
                            ', above the rounding level of A (A nearly singular on the free set)')
        exit main
      end do main
    end subroutine newton_steps

  end subroutine newton_loop

  !> The Newton method on a set with curved faces (module disc_newton), until the stopping
  !! test ends the solve: each step on a dense A computes the gradient afresh. Two steps in a
  !! row that find x at its face's minimiser with nothing to release end it: converged to
  !! working precision when |gP| is within NEWTON_FLOOR n eps lambda_max |x|, else as failed
  !! (max_it). An A that is not a dense_op_t, or a set that is not the friction set, is MPGP's.
  subroutine disc_newton_loop(self, A, b, set, x, rw, raw, nrw)
    type(mprgp_t), intent(inout) :: self
    class(linop_t), intent(inout) :: A
    real(wp), intent(in) :: b(:)
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(inout) :: x(:)
    real(wp), intent(inout), optional :: rw(:, :), raw(:, :)
    integer, intent(inout), optional :: nrw(2)
    logical, allocatable :: held(:)
    logical :: at_min
    real(wp) :: betabeta, phitphi, flops
    integer :: outcome, still
    type(disc_factor_t), target :: own
    type(disc_factor_t), pointer :: fac
    fac => own
    if (associated(self%keep_disc)) then
      fac => self%keep_disc
      fac%carried = .true.
    end if
    select type (set)
    type is (disc_set_t)
      select type (A)
      type is (dense_op_t)
        if (.not. self%fresh) call true_gradient(self, A, b, x)
        allocate (held(self%n))
        if (self%hold_boundary) then
          call set%free_mask(x, held)
          held = .not. held
        else
          call disc_held(set, x, self%g, held)
        end if
        at_min = .false.
        still = 0
        main: do
          select case (stopping_test(self, A, b, set, x, betabeta, phitphi))
          case (DONE)
            exit main
          case (RETEST)
            cycle main
          end select
          self%it = self%it + 1
          flops = 0.0_wp
          call disc_newton_step(A%a, b, set, x, self%g, self%ax, held, at_min, outcome, flops, self%stats%n_factor, fac)
          self%fresh = .true.
          self%stats%n_newton = self%stats%n_newton + 1
          self%stats%n_matvec = self%stats%n_matvec + max(1, nint(flops/(2.0_wp*real(self%n, wp)**2)))
          if (outcome == DN_NOT_SPD) then
            call fail(self, MPRGP_NOT_SPD, 'the Newton method on the discs met a face matrix that is not '// &
                      'positive definite at step '//i2s(self%it)//': A is not SPD')
            exit main
          end if
          still = merge(still + 1, 0, outcome == DN_STILL)
          if (still < 2) cycle main
          self%stats%gp_norm = set%projected_gradient_norm(x, self%g)
          call newton_verdict(self, A%a, x, ' Newton steps on the discs', 'the Newton method on the discs', '')
          exit main
        end do main
        return
      end select
    end select
    call mprgp_loop(self, A, b, set, x, rw, raw, nrw)
  end subroutine disc_newton_loop

  !> The end of a Newton method whose x solves its face but whose |gP| (in stats) stays above
  !! the tolerance: converged to working precision when |gP| is within NEWTON_FLOOR n eps
  !! lambda_max |x| (a Cholesky solve's backward error), else failed (max_it); the messages
  !! name the method (`who`) and add `done` after its step count or `why` after |gP|.
  subroutine newton_verdict(self, am, x, done, who, why)
    type(mprgp_t), intent(inout) :: self
    real(wp), intent(in) :: am(:, :)           !< A, dense
    real(wp), intent(in) :: x(:)
    character(len=*), intent(in) :: done, who, why
    real(wp) :: floor
    character(len=24) :: s1
    if (self%lam_lo <= 0.0_wp) self%lam_lo = maxval(sum(abs(am), dim=1))
    floor = NEWTON_FLOOR*real(self%n, wp)*epsilon(1.0_wp)*self%lam_lo*max(norm2(x), self%xscale0)
    write (s1, '(es10.3)') self%stats%gp_norm
    if (self%stats%gp_norm <= floor) then
      self%stats%status = MPRGP_CONVERGED
      self%stats%message = 'converged to working precision: |gP| = '//trim(adjustl(s1))// &
        ' after '//i2s(self%stats%n_newton)//done
    else
      self%stats%status = MPRGP_MAX_IT
      self%stats%message = 'not converged: '//who//' stalls at |gP| = '//trim(adjustl(s1))//why
    end if
  end subroutine newton_verdict

  !> A solve uses its search direction once.
  subroutine consume_search(self)
    type(mprgp_t), intent(inout) :: self
    if (allocated(self%s)) deallocate (self%s)
    if (allocated(self%as)) deallocate (self%as)
  end subroutine consume_search

  !> Check sizes, options and finiteness before any work; sets self%n, allocates the
  !! solver's vectors. False (with the status and message) when the solve cannot start.
  logical function valid_arguments(self, n, b, set, x, rw, raw, nrw) result(ok)
    type(mprgp_t), intent(inout) :: self
    integer, intent(in) :: n
    real(wp), intent(in) :: b(:), x(:)
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(in), optional :: rw(:, :), raw(:, :)
    integer, intent(in), optional :: nrw(2)
    integer :: i
    type(error_t) :: verr
    ok = .false.
    self%n = n
    if (n < 0) then
      call fail(self, MPRGP_BAD_ARG, 'operator size A%n is negative')
      return
    end if
    if (allocated(self%g)) then
      if (size(self%g) /= n) deallocate (self%g)
    end if
    if (.not. allocated(self%g)) allocate (self%g(n))
    if (size(b) /= n .or. size(x) /= n) then
      write (self%stats%message, '(a,i0,a,i0,a,i0)') 'size mismatch: A%n = ', n, &
        ', size(b) = ', size(b), ', size(x) = ', size(x)
      self%stats%status = MPRGP_BAD_ARG
      return
    end if
    call set%validate(n, verr)
    if (verr%failed()) then
      call fail(self, merge(MPRGP_NONFINITE, MPRGP_BAD_ARG, verr%category == ERR_NUMERICAL), verr%message)
      return
    end if
    if (self%opts%use_ax) then
      if (.not. allocated(self%ax)) then
        call fail(self, MPRGP_BAD_ARG, 'opts%use_ax without ax')
        return
      else if (size(self%ax) /= n) then
        call fail(self, MPRGP_BAD_ARG, 'size mismatch: size(ax) /= A%n')
        return
      end if
    end if
    if (allocated(self%s) .neqv. allocated(self%as)) then
      call fail(self, MPRGP_BAD_ARG, 's and as must be given together')
      return
    end if
    if (allocated(self%s)) then
      if (size(self%s) /= n .or. size(self%as) /= n) then
        call fail(self, MPRGP_BAD_ARG, 'size mismatch: size(s) or size(as) /= A%n')
        return
      end if
    end if
    if ((present(rw) .neqv. present(raw)) .or. (present(rw) .neqv. present(nrw))) then
      call fail(self, MPRGP_BAD_ARG, 'rw, raw and nrw must be given together')
      return
    end if
    if (present(rw)) then
      if (size(rw, 1) /= n .or. size(raw, 1) /= n .or. size(raw, 2) /= size(rw, 2)) then
        call fail(self, MPRGP_BAD_ARG, 'size mismatch: rw or raw is not (A%n, k)')
        return
      end if
      if (nrw(1) < 0 .or. nrw(1) > size(rw, 2) .or. nrw(2) < 1 .or. nrw(2) > max(1, size(rw, 2))) then
        call fail(self, MPRGP_BAD_ARG, 'nrw out of range')
        return
      end if
    end if
    if (allocated(self%eq_g) .neqv. allocated(self%eq_e)) then
      call fail(self, MPRGP_BAD_ARG, 'eq_g and eq_e must be given together')
      return
    end if
    if (allocated(self%eq_g)) then
      if (size(self%eq_g, 2) /= n .or. size(self%eq_g, 1) /= size(self%eq_e)) then
        call fail(self, MPRGP_BAD_ARG, 'size mismatch: eq_g is not (size(eq_e), A%n)')
        return
      end if
    end if
    if (.not. valid_options(self)) return
    do i = 1, n
      if (.not. ieee_is_finite(b(i))) then
        call fail(self, MPRGP_NONFINITE, 'b('//i2s(i)//') is not finite')
        return
      end if
      if (.not. ieee_is_finite(x(i))) then
        call fail(self, MPRGP_NONFINITE, 'initial x('//i2s(i)//') is not finite')
        return
      end if
    end do
    if (allocated(self%ax)) then
      if (size(self%ax) /= n) deallocate (self%ax)
    end if
    if (.not. allocated(self%ax)) allocate (self%ax(n))
    ok = .true.
  end function valid_arguments

  !> The options are finite and in range (else a bad-argument failure).
  logical function valid_options(self) result(ok)
    type(mprgp_t), intent(inout) :: self
    type(error_t) :: err
    call check_options(self%opts, err)
    ok = .not. err%failed()
    if (.not. ok) call fail(self, MPRGP_BAD_ARG, err%message)
  end function valid_options

  !> Project the warm start, take its gradient (from ax with opts%use_ax), and unless it
  !! already meets the tolerance, the recycled subspace step or the first line search.
  subroutine start(self, A, b, set, x, rw, raw, nrw)
    type(mprgp_t), intent(inout) :: self
    class(linop_t), intent(inout) :: A
    real(wp), intent(in) :: b(:)
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(inout) :: x(:)
    real(wp), intent(inout), optional :: rw(:, :), raw(:, :)
    integer, intent(inout), optional :: nrw(2)
    integer :: n
    logical :: moved
    n = self%n
    moved = .false.
    self%tol = max(self%opts%rtol * self%stats%b_norm, self%opts%atol)
    self%zero_tol = (self%tol <= 0.0_wp)
    if (allocated(self%p)) then
      if (size(self%p) /= n) deallocate (self%p, self%ap, self%w, self%v, self%av, self%free)
    end if
    if (.not. allocated(self%p)) allocate (self%p(n), self%ap(n), self%w(n), self%v(n), self%av(n), self%free(n))
    self%ab = 0.0_wp
    self%lam_lo = 0.0_wp
    if (self%opts%lambda_max > 0.0_wp) self%lam_lo = self%opts%lambda_max
    call set%project(x)
    self%xscale0 = norm2(x)
    if (self%opts%use_ax) then
      self%g = self%ax - b
    else
      call A%apply(x, self%g)
      self%stats%n_matvec = 1
      self%ax = self%g
      self%g = self%g - b
    end if
    self%fresh = .true.
    ! a warm start that already meets the tolerance is returned as it is (no product)
    if (self%zero_tol .or. set%projected_gradient_norm(x, self%g) > self%tol) then
      if (present(rw) .and. self%opts%recycle) then
        if (allocated(self%s)) then
          moved = recycled_subspace(x, self%g, set, rw, raw, nrw(1), self%opts%gamma, self%v, self%av, &
                                    self%p, self%ap, self%s, self%as)
        else
          moved = recycled_subspace(x, self%g, set, rw, raw, nrw(1), self%opts%gamma, self%v, self%av, &
                                    self%p, self%ap)
        end if
      else if (allocated(self%s)) then
        moved = line_search(x, self%g, set, self%s, self%as, .false., self%opts%gamma, self%p, self%ap)
      end if
      if (moved) then
        self%stats%n_recycled = self%stats%n_recycled + 1
        self%fresh = .false.
      end if
    end if
    call set_p_to_phi(self, set, x)
    self%it = 0
  end subroutine start

  !> Split the gradient, test convergence (confirmed on the true gradient), max_it and the
  !! stop hook. DONE: the solve ends; RETEST: the true gradient was taken, test again;
  !! GO_ON: take a step (betabeta = |chopped gradient|^2, phitphi = phit'phi).
  integer function stopping_test(self, A, b, set, x, betabeta, phitphi) result(action)
    type(mprgp_t), intent(inout) :: self
    class(linop_t), intent(inout) :: A
    real(wp), intent(in) :: b(:), x(:)
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(out) :: betabeta, phitphi
    real(wp) :: phiphi, gp2, tol_now, feas, floor_eq
    character(len=24) :: s1, s2
    integer :: n
    n = self%n
    action = DONE
    ! Split the gradient (one pass).
    call set%split_gradient(x, self%g, self%ab, phiphi, phitphi, betabeta)
    gp2 = phiphi + betabeta
    self%stats%gp_norm = sqrt(gp2)
    if (.not. ieee_is_finite(gp2)) then
      call fail(self, MPRGP_NONFINITE, 'the projected gradient became non-finite after '// &
                i2s(self%it)//' steps')
      return
    end if

    ! Stopping test, confirmed on the true gradient.
    tol_now = self%tol
    if (self%zero_tol .and. gp2 > 0.0_wp) then
      if (.not. ensure_alpha(self, A)) return
      tol_now = 10.0_wp * sqrt(real(n, wp)) * epsilon(1.0_wp) * max(self%lam_lo, ALPHA_FACTOR / self%ab) * &
                max(norm2(x), self%xscale0)
    end if
    if (allocated(self%eq_g) .and. self%stats%gp_norm <= tol_now .and. self%opts%eq_m > 0.0_wp) then
      ! SMALBE-M: solve more precisely while the equality is far from holding
      feas = norm2(matmul(self%eq_g, x) - self%eq_e)
      if (feas > self%opts%eq_feas) then
        floor_eq = 10.0_wp*sqrt(real(n, wp))*epsilon(1.0_wp)*self%lam_lo*max(norm2(x), self%xscale0)
        tol_now = max(min(tol_now, self%opts%eq_m*feas), floor_eq)
      end if
    end if
    if (self%stats%gp_norm <= tol_now) then
      if (self%fresh) then
        self%stats%status = MPRGP_CONVERGED
        write (s1, '(es10.3)') self%stats%gp_norm
        write (s2, '(es10.3)') tol_now
        self%stats%message = 'converged: |gP| = '//trim(adjustl(s1))//' <= '//trim(adjustl(s2))// &
                             ' after '//i2s(self%it)//' steps, '//i2s(self%stats%n_matvec)// &
                             ' products with A'
        return
      end if
      call true_gradient(self, A, b, x)
      call set_p_to_phi(self, set, x)
      action = RETEST
      return
    end if
    if (self%it >= self%opts%max_it) then
      if (self%opts%rounding_floor .and. self%lam_lo > 0.0_wp) then
        ! the tolerance was out of reach: within the rounding level of A x it is met
        if (.not. self%fresh) then
          call true_gradient(self, A, b, x)
          self%stats%gp_norm = set%projected_gradient_norm(x, self%g)
        end if
        write (s1, '(es10.3)') self%stats%gp_norm
        if (self%stats%gp_norm <= 10.0_wp*sqrt(real(n, wp))*epsilon(1.0_wp)*self%lam_lo*max(norm2(x), self%xscale0)) then
          self%stats%status = MPRGP_CONVERGED
          self%stats%message = 'converged to working precision: |gP| = '//trim(adjustl(s1))//' after '// &
            i2s(self%it)//' steps (the tolerance asked for is below what double precision resolves)'
          return
        end if
      end if
      self%stats%status = MPRGP_MAX_IT
      write (s1, '(es10.3)') self%stats%gp_norm
      write (s2, '(es10.3)') tol_now
      self%stats%message = 'not converged: |gP| = '//trim(adjustl(s1))//' > '//trim(adjustl(s2))// &
                           ' after max_it = '//i2s(self%opts%max_it)//' steps'
      return
    end if
    if (associated(self%opts%stop)) then
      if (self%opts%stop()) then
        self%stats%status = MPRGP_STOPPED
        self%stats%message = 'stopped on request after '//i2s(self%it)//' steps'
        return
      end if
    end if
    action = GO_ON
  end function stopping_test

  !> The proportionality test |beta|^2 <= Gamma^2 phit'phi (alpha_bar is needed only when
  !! some bound is active). ok = .false. when alpha_bar could not be had.
  logical function proportional(self, A, set, x, betabeta, phitphi, ok) result(prop)
    type(mprgp_t), intent(inout) :: self
    class(linop_t), intent(inout) :: A
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(in) :: x(:), betabeta
    real(wp), intent(inout) :: phitphi       !< phit'phi (recomputed once alpha_bar is known)
    logical, intent(out) :: ok
    real(wp) :: phiphi, betabeta_now
    prop = .false.
    ok = .true.
    if (betabeta > 0.0_wp .and. self%ab <= 0.0_wp) then
      ok = ensure_alpha(self, A)
      if (.not. ok) return
      call set%split_gradient(x, self%g, self%ab, phiphi, phitphi, betabeta_now)
    end if
    prop = (betabeta <= self%opts%gamma**2 * phitphi)
  end function proportional

  !> Trial conjugate gradient step along -p: taken when it stays feasible (CG step),
  !! otherwise its feasible part followed by an expansion step. False on a breakdown.
  logical function cg_or_expansion_step(self, A, set, x, rw, raw, nrw) result(ok)
    type(mprgp_t), intent(inout) :: self
    class(linop_t), intent(inout) :: A
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(inout) :: x(:)
    real(wp), intent(inout), optional :: rw(:, :), raw(:, :)
    integer, intent(inout), optional :: nrw(2)
    real(wp) :: pap, pp, gtp, acg, af, num, gam
    integer :: i, n, blk
    n = self%n
    associate (p => self%p, ap => self%ap, gr => self%g, d => self%w, free => self%free)
      call A%apply(p, ap)
      self%stats%n_matvec = self%stats%n_matvec + 1
      pap = 0.0_wp
      pp = 0.0_wp
      gtp = 0.0_wp
      do i = 1, n
        pap = pap + p(i) * ap(i)
        pp = pp + p(i) * p(i)
        gtp = gtp + gr(i) * p(i)
      end do
      ok = check_curvature(self, pap, pp, 'conjugate gradient direction')
      if (.not. ok) return
      if (present(rw)) call store_direction(p, ap, rw, raw, nrw)
      acg = gtp / pap
      ! Largest feasible step along d = -p, capped at acg; blk is the variable that blocks it.
      d = -p
      call set%max_step(x, d, acg, af, blk)
      if (blk == 0) then
        ! CG step.
        call set%move(x, d, acg, free)
        num = 0.0_wp
        do i = 1, n
          gr(i) = gr(i) - acg * ap(i)
          if (free(i)) num = num + gr(i) * ap(i)
        end do
        gam = num / pap
        do i = 1, n
          if (free(i)) then
            p(i) = gr(i) - gam * p(i)
          else
            p(i) = -gam * p(i)
          end if
        end do
        self%stats%n_cg = self%stats%n_cg + 1
        self%fresh = .false.
        return
      end if
      ! the feasible half step
      af = max(af, 0.0_wp)
      call set%move(x, d, af, free)
      do i = 1, n
        gr(i) = gr(i) - af * ap(i)
      end do
      call set%pin(x, d, blk)
    end associate
    ok = expansion_step(self, A, set, x)
  end function cg_or_expansion_step

  !> Projected step of length alpha_bar along the free gradient, recomputed with a cut
  !! alpha_bar while it increases the cost (the guard above); then CG restarts.
  logical function expansion_step(self, A, set, x) result(ok)
    type(mprgp_t), intent(inout) :: self
    class(linop_t), intent(inout) :: A
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(inout) :: x(:)
    real(wp) :: dd, dad, df, ab_prev
    integer :: i, n, retry
    n = self%n
    ok = ensure_alpha(self, A)
    if (.not. ok) return
    retry = 0
    associate (p => self%p, ap => self%ap, gr => self%g)
      expand: do
        ! Candidate step d = P(x - ab*phi) - x = -ab*phit, stored in p (reset afterwards).
        call set%projected_step(x, gr, self%ab, p)
        dd = 0.0_wp
        do i = 1, n
          dd = dd + p(i) * p(i)
        end do
        if (dd <= 0.0_wp) exit expand
        call A%apply(p, ap)
        self%stats%n_matvec = self%stats%n_matvec + 1
        dad = 0.0_wp
        df = 0.0_wp
        do i = 1, n
          dad = dad + p(i) * ap(i)
          df = df + gr(i) * p(i)
        end do
        df = df + 0.5_wp * dad
        ab_prev = self%ab
        ok = check_curvature(self, dad, dd, 'expansion step')
        if (.not. ok) return
        if (df > 0.0_wp .and. self%ab < ab_prev .and. retry < MAX_RETRY) then
          ! The step increased the cost: alpha_bar exceeded 2/lambda_max. Cut and retry.
          retry = retry + 1
          cycle expand
        end if
        call set%move(x, p, 1.0_wp, self%free)
        do i = 1, n
          gr(i) = gr(i) + ap(i)
        end do
        exit expand
      end do expand
    end associate
    call set_p_to_phi(self, set, x)
    self%stats%n_exp = self%stats%n_exp + 1
    self%fresh = .false.
  end function expansion_step

  !> Exact line search along -beta (the chopped gradient), which releases variables from
  !! the boundary, cut where a released variable reaches the boundary again (in a box: its
  !! opposite bound); on a set with curved faces, the projected step (projected_proportioning).
  !! False on a breakdown.
  logical function proportioning_step(self, A, b, set, x, betabeta) result(ok)
    type(mprgp_t), intent(inout) :: self
    class(linop_t), intent(inout) :: A
    real(wp), intent(in) :: b(:)
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(in) :: betabeta
    real(wp), intent(inout) :: x(:)
    real(wp) :: pap, pp, acg
    integer :: i, n, blk
    n = self%n
    step: associate (p => self%p, ap => self%ap, gr => self%g, d => self%w, free => self%free)
      call set%chopped_gradient(x, gr, p)
      call A%apply(p, ap)
      self%stats%n_matvec = self%stats%n_matvec + 1
      pap = 0.0_wp
      pp = 0.0_wp
      do i = 1, n
        pap = pap + p(i) * ap(i)
        pp = pp + p(i) * p(i)
      end do
      ok = check_curvature(self, pap, pp, 'proportioning direction')
      if (.not. ok) return
      d = -p
      if (.not. set%linear()) exit step
      ! A variable released from the boundary may reach it again (in a box, one released
      ! from l may reach u first): the step is cut there, so that the recurrence gradient
      ! stays that of x. With lower bounds only, p <= 0 and no upper bound is finite: no
      ! step is cut.
      call set%max_step(x, d, betabeta / pap, acg, blk)
      call set%move(x, d, acg, free)
      do i = 1, n
        gr(i) = gr(i) - acg * ap(i)
      end do
      call set%pin(x, d, blk)
    end associate step
    if (.not. set%linear()) call projected_proportioning(self, A, b, set, x, &
                                                        betabeta / (pap + set%boundary_curvature(x, self%g, self%w)))
    call set_p_to_phi(self, set, x)
    self%stats%n_prop = self%stats%n_prop + 1
    self%fresh = self%fresh .and. .not. set%linear()
  end function proportioning_step

  !> The proportioning step on a set with curved faces (MPGP): along d = -beta (in self%w)
  !! the point slides along a disc's circle and leaves the set to second order, so the step
  !! is projected, x = P(x + t d), and the gradient computed again. t0 is the exact line
  !! search of the cost plus the faces' curvature term (the force that presses a point on
  !! its circle, over the radius: constraint_set%boundary_curvature), the minimiser of the
  !! second-order model of the cost along the circle; t is halved while the projected step
  !! does not decrease the cost (f(x') - f(x) = (g + g')'(x' - x) / 2 for a quadratic),
  !! which a short enough step does (the decrease is first order in t).
  subroutine projected_proportioning(self, A, b, set, x, t0)
    type(mprgp_t), intent(inout) :: self
    class(linop_t), intent(inout) :: A
    real(wp), intent(in) :: b(:)
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(inout) :: x(:)
    real(wp), intent(in) :: t0              !< the exact line search's step along d
    real(wp), allocatable :: x0(:), g0(:)
    real(wp) :: t, df, noise
    integer :: retry
    allocate (x0, source=x)
    allocate (g0, source=self%g)
    t = t0
    do retry = 0, MAX_RETRY
      x = x0
      call set%move(x, self%w, t, self%free)
      call true_gradient(self, A, b, x)
      ! an increase below its rounding counts as none: that of the two gradients (|A x| +
      ! |b| each) over the step, and that of the projected point (eps |x|, on a circle of
      ! radius r against a pressing force s: s r eps, more than the decrease near the end)
      df = 0.5_wp*dot_product(g0 + self%g, x - x0)
      noise = 8.0_wp*epsilon(1.0_wp)*(dot_product(abs(self%ax) + abs(b), abs(x - x0)) + &
                                      dot_product(abs(g0) + abs(self%g), abs(x)))
      if (df <= noise) exit
      t = 0.5_wp*t
    end do
  end subroutine projected_proportioning

  !> Record a failure.
  subroutine fail(self, code, msg)
    type(mprgp_t), intent(inout) :: self
    integer, intent(in) :: code
    character(len=*), intent(in) :: msg
    self%stats%status = code
    self%stats%message = msg
  end subroutine fail

  !> p = phi(x), the free gradient.
  subroutine set_p_to_phi(self, set, x)
    type(mprgp_t), intent(inout) :: self
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(in) :: x(:)
    call set%free_gradient(x, self%g, self%p)
  end subroutine set_p_to_phi

  !> g = A x - b computed directly.
  subroutine true_gradient(self, A, b, x)
    type(mprgp_t), intent(inout) :: self
    class(linop_t), intent(inout) :: A
    real(wp), intent(in) :: b(:), x(:)
    call A%apply(x, self%g)
    self%stats%n_matvec = self%stats%n_matvec + 1
    self%ax = self%g
    self%g = self%g - b
    self%fresh = .true.
  end subroutine true_gradient

  !> Make alpha_bar available (power iteration on first need). False on failure.
  logical function ensure_alpha(self, A) result(ok)
    type(mprgp_t), intent(inout) :: self
    class(linop_t), intent(inout) :: A
    real(wp) :: lam_pow
    integer :: nmv_pow
    ok = .true.
    if (self%ab > 0.0_wp) return
    if (self%opts%alpha_bar > 0.0_wp) then
      self%ab = self%opts%alpha_bar
      if (self%lam_lo * self%ab > 2.0_wp) self%ab = ALPHA_FACTOR / self%lam_lo
      return
    end if
    if (self%opts%lambda_max <= 0.0_wp) then
      ! ap and w are free whenever this is called.
      call power_iteration(A, self%opts%power_its, self%ap, self%w, lam_pow, nmv_pow)
      self%stats%n_matvec = self%stats%n_matvec + nmv_pow
      if (.not. ieee_is_finite(lam_pow)) then
        call fail(self, MPRGP_NONFINITE, 'A produced a non-finite value in the power iteration')
        ok = .false.
        return
      end if
      if (lam_pow <= 0.0_wp) then
        call fail(self, MPRGP_NOT_SPD, 'A v = 0 for the power-iteration vector: A is not SPD')
        ok = .false.
        return
      end if
      self%lam_lo = max(self%lam_lo, lam_pow)
    end if
    self%ab = ALPHA_FACTOR / self%lam_lo
  end function ensure_alpha

  !> Check d'Ad > 0 and finite; update the lambda_max bound and the alpha_bar guard.
  logical function check_curvature(self, dad_, dd_, what) result(ok)
    type(mprgp_t), intent(inout) :: self
    real(wp), intent(in) :: dad_, dd_
    character(len=*), intent(in) :: what
    real(wp) :: rq_
    character(len=24) :: s1
    ok = .false.
    if (.not. (ieee_is_finite(dad_) .and. ieee_is_finite(dd_))) then
      call fail(self, MPRGP_NONFINITE, 'non-finite curvature along the '//what//' after '// &
                i2s(self%it)//' steps')
      return
    end if
    if (dad_ <= 0.0_wp .and. dd_ <= tiny(1.0_wp)) then
      ! the direction has vanished (underflowed): the iterate is exact to working
      ! precision and a tolerance below that cannot be reached; not a curvature failure
      self%stats%status = MPRGP_CONVERGED
      write (s1, '(es10.3)') self%stats%gp_norm
      self%stats%message = 'converged to working precision: |gP| = '//trim(adjustl(s1))// &
                           ' (the tolerance asked for is below what double precision resolves)'
      return
    end if
    if (dad_ <= 0.0_wp) then
      write (s1, '(es10.3)') dad_
      call fail(self, MPRGP_NOT_SPD, 'p''Ap = '//trim(adjustl(s1))//' <= 0 along the '//what// &
                ' at step '//i2s(self%it)//': A is not SPD')
      return
    end if
    ok = .true.
    rq_ = dad_ / dd_
    if (rq_ > self%lam_lo) self%lam_lo = rq_
    if (self%ab > 0.0_wp .and. self%ab * self%lam_lo > 2.0_wp) self%ab = ALPHA_FACTOR / self%lam_lo
  end function check_curvature

end module mprgp
