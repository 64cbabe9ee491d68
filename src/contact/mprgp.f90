!> MPRGP: modified proportioning with reduced gradient projection, for the
!! bound-constrained convex quadratic program
!!
!!     minimise 1/2 x'Ax - b'x   subject to   x >= l
!!
!! with A symmetric positive definite, given as a `class(linop_t)` (dense, sparse or
!! implicit). Z. Dostal and J. Schoberl, "Minimizing quadratic functions subject to
!! bound constraints with the rate of convergence and finite termination",
!! Comput. Optim. Appl. 30 (2005) 23-43.
!!
!! Notation (g = Ax - b, free set F = {i : x_i > l_i}, active set its complement):
!!   free gradient        phi_i  = g_i on F, 0 else
!!   chopped gradient     beta_i = min(g_i, 0) off F, 0 else
!!   projected gradient   gP     = phi + beta            (stopping criterion)
!!   reduced free grad.   phit_i = min((x_i - l_i)/alpha_bar, phi_i) on F, 0 else
!! x is *proportional* when |beta|^2 <= Gamma^2 phit'phi. Then a conjugate gradient
!! step along p is tried; if it stays feasible it is taken (CG step), otherwise the
!! feasible part of it is taken and followed by a projected step of length alpha_bar
!! along the free gradient, after which CG restarts (expansion step). A
!! non-proportional x gets an exact line search along -beta (proportioning step),
!! which releases variables from their bounds.
!!
!! Bounds equal to -huge(1.0_wp) mean "no bound". All other bounds must be finite.
!!
!! Thread safety: no module variables, no SAVE, work arrays are local to each call.
!! Two threads may solve concurrently with two different operators.
module mprgp
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp
  use linop, only: linop_t
  use strings, only: itoa, rtoa
  implicit none (type, external)
  private

  public :: mprgp_solve, lambda_max_estimate, mprgp_status_name
  public :: mprgp_opts_t, mprgp_stats_t
  public :: MPRGP_CONVERGED, MPRGP_MAX_IT, MPRGP_NONFINITE, MPRGP_NOT_SPD, MPRGP_BAD_ARG, MPRGP_STOPPED

  integer, parameter :: MPRGP_CONVERGED = 0  !< |gP| <= max(rtol |b|, atol) at the true gradient
  integer, parameter :: MPRGP_MAX_IT = 1     !< max_it steps done without convergence
  integer, parameter :: MPRGP_NONFINITE = 2  !< NaN/Inf in the input or during the iteration
  integer, parameter :: MPRGP_NOT_SPD = 3    !< a direction with p'Ap <= 0 was met (A not SPD)
  integer, parameter :: MPRGP_BAD_ARG = 4    !< inconsistent sizes or invalid options
  integer, parameter :: MPRGP_STOPPED = 5    !< opts%stop turned true (a signal): x is the current iterate

  abstract interface
    !> True when the solve must stop now (polled once per step).
    logical function mprgp_stop_iface()
    end function mprgp_stop_iface
  end interface

  !> Safety factor: default alpha_bar = ALPHA_FACTOR / lambda_max (theory: (0, 2/|A|]).
  real(wp), parameter :: ALPHA_FACTOR = 1.9_wp
  !> At most this many retries of one expansion step with a reduced alpha_bar.
  integer, parameter :: MAX_RETRY = 60

  !> Options of `mprgp_solve`. Tolerances are in the units of b (for contact: a displacement).
  type :: mprgp_opts_t
    real(wp) :: rtol = 1.0e-8_wp     !< stop when |gP| <= max(rtol*|b|, atol)
    real(wp) :: atol = 0.0_wp        !< absolute floor of the stopping test (units of b)
    integer :: max_it = 10000        !< maximum number of CG + expansion + proportioning steps
    real(wp) :: gamma = 1.0_wp       !< proportioning constant Gamma > 0
    real(wp) :: alpha_bar = 0.0_wp   !< expansion step length; <= 0: 1.9/lambda_max (units 1/[A])
    real(wp) :: lambda_max = 0.0_wp  !< > 0: use this largest eigenvalue of A instead of estimating
    integer :: power_its = 20        !< power iterations for the lambda_max estimate
    logical :: use_ax = .false.      !< the argument `ax` holds A x at the warm start: no initial product
    logical :: recycle = .false.     !< start with exact line searches along the stored directions `rw` (no product)
    !> With equality rows (arguments eq_g, eq_e: SMALBE's inner solve) a projected gradient
    !! below the tolerance stops only when it is also below eq_m |eq_g x - eq_e| or the
    !! equality already holds to eq_feas (Dostal's SMALBE-M precision control)
    real(wp) :: eq_m = 0.0_wp        !< M of SMALBE-M (units of b per unit of eq_e)
    real(wp) :: eq_feas = 0.0_wp     !< |eq_g x - eq_e| that counts as feasible (units of eq_e)
    procedure(mprgp_stop_iface), pointer, nopass :: stop => null()  !< polled every step: stop when true
  end type mprgp_opts_t

  !> What `mprgp_solve` did.
  type :: mprgp_stats_t
    integer :: status = MPRGP_BAD_ARG  !< one of the MPRGP_* codes
    integer :: n_cg = 0                !< conjugate gradient steps
    integer :: n_exp = 0               !< expansion steps
    integer :: n_prop = 0              !< proportioning steps
    integer :: n_matvec = 0            !< products with A, power iterations included
    integer :: n_recycled = 0          !< line searches along s and the stored directions that moved x (no product)
    real(wp) :: gp_norm = 0.0_wp       !< |gP| at the returned x (units of b)
    real(wp) :: b_norm = 0.0_wp        !< |b|
    real(wp) :: lambda_max = 0.0_wp    !< lambda_max used (largest of estimate and observed Rayleigh quotients); 0: not needed
    real(wp) :: alpha_bar = 0.0_wp     !< final expansion step length; 0: not needed
    character(len=160) :: message = '' !< one sentence on the outcome
  end type mprgp_stats_t

contains

  !> Name of a status code: 'converged', 'max_it', 'non-finite', 'not SPD', 'bad argument'.
  function mprgp_status_name(status) result(name)
    integer, intent(in) :: status  !< an MPRGP_* code
    character(len=:), allocatable :: name
    select case (status)
    case (MPRGP_CONVERGED)
      name = 'converged'
    case (MPRGP_MAX_IT)
      name = 'max_it'
    case (MPRGP_NONFINITE)
      name = 'non-finite'
    case (MPRGP_NOT_SPD)
      name = 'not SPD'
    case (MPRGP_BAD_ARG)
      name = 'bad argument'
    case (MPRGP_STOPPED)
      name = 'stopped'
    case default
      name = 'unknown status'
    end select
  end function mprgp_status_name

  !> Estimate of the largest eigenvalue of the SPD operator A by `its` power
  !! iterations from a fixed pseudo-random start vector (deterministic).
  !! Returns max_k |A v_k| with |v_k| = 1: a lower bound of lambda_max (for symmetric
  !! A), usually within a few percent after 20 iterations. Returns 0 when n = 0 or
  !! A v = 0; a non-finite value if A produced one. its < 1 is treated as 1.
  function lambda_max_estimate(A, its, nmv) result(lam)
    class(linop_t), intent(inout) :: A      !< the operator
    integer, intent(in) :: its              !< number of power iterations (products with A)
    integer, intent(out), optional :: nmv   !< products with A performed
    real(wp) :: lam
    real(wp), allocatable :: v(:), w(:)
    integer :: k
    allocate (v(max(A%n, 0)), w(max(A%n, 0)))
    call power_iteration(A, its, v, w, lam, k)
    if (present(nmv)) nmv = k
  end function lambda_max_estimate

  !> Power iteration with caller-provided work vectors v, w (size n).
  subroutine power_iteration(A, its, v, w, lam, nmv)
    class(linop_t), intent(inout) :: A
    integer, intent(in) :: its
    real(wp), intent(inout) :: v(:), w(:)
    real(wp), intent(out) :: lam
    integer, intent(out) :: nmv
    integer :: i, k, n
    integer, parameter :: i8k = selected_int_kind(18)
    integer(i8k) :: s
    real(wp) :: nw
    n = A%n
    lam = 0.0_wp
    nmv = 0
    if (n <= 0) return
    ! Park-Miller minimal standard generator: deterministic, local state, no overflow.
    s = 12345_i8k
    do i = 1, n
      s = mod(16807_i8k * s, 2147483647_i8k)
      v(i) = real(s, wp) / 2147483647.0_wp - 0.5_wp
    end do
    v(1:n) = v(1:n) / norm2(v(1:n))
    do k = 1, max(its, 1)
      call A%apply(v(1:n), w(1:n))
      nmv = nmv + 1
      nw = norm2(w(1:n))
      if (.not. ieee_is_finite(nw)) then
        lam = nw
        return
      end if
      lam = max(lam, nw)
      if (nw <= 0.0_wp) return
      v(1:n) = w(1:n) / nw
    end do
  end subroutine power_iteration

  !> Solve min 1/2 x'Ax - b'x subject to x >= lb by MPRGP.
  !!
  !! x is a warm start on entry (projected onto the bounds first) and the solution
  !! on exit (the last iterate on failure). The run stops when |gP| <= max(rtol |b|,
  !! atol); if both are zero (b = 0 and atol = 0), at the rounding-level floor
  !! 10 sqrt(n) eps lambda_max max(|x|, |x_0|), x_0 the projected start.
  !! Convergence is always confirmed on a freshly computed gradient Ax - b (one extra
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
  !! Cost per step: one product with A (two for an expansion) and O(n) work; the
  !! only allocations are four work vectors per call.
  !!
  !! Reuse across a sequence of solves with the same A (the outer contact iteration):
  !! with opts%use_ax, `ax` holds A x at the warm start and the initial product is
  !! skipped; on exit `ax` holds A x at the returned x (the confirming product, so the
  !! next solve, warm-started from x, starts from it). With a direction s and as = A s
  !! (e.g. the change of x in the previous solve and of A x), the iteration starts with
  !! an exact line search along s, cut at the bounds, which costs no product.
  !! Krylov recycling: with rw, raw, nrw (a ring of A-normalised directions and their
  !! images, filled by every conjugate gradient step of the solves that share it) and
  !! opts%recycle, the iteration starts from the minimum over x plus the span of s and of
  !! the stored directions that vanish where x is at its bound (A-orthogonalised; a
  !! direction with less than 1% of its A-norm left is dropped, so the recurrence gradient
  !! stays accurate), taken only if the whole step is feasible and leaves a proportional
  !! iterate with a smaller projected gradient: again no product.
  !! A warm start whose projected gradient (from opts%use_ax) already meets the tolerance
  !! is returned without a search or a product.
  subroutine mprgp_solve(A, b, lb, x, opts, stats, g, ax, s, as, rw, raw, nrw, eq_g, eq_e)
    class(linop_t), intent(inout) :: A          !< SPD operator (size A%n)
    real(wp), intent(in) :: b(:)                !< linear term (size n)
    real(wp), intent(in) :: lb(:)               !< lower bounds (size n); -huge(1.0_wp): none
    real(wp), intent(inout) :: x(:)             !< in: warm start; out: solution
    type(mprgp_opts_t), intent(in) :: opts      !< options
    type(mprgp_stats_t), intent(out) :: stats   !< status, counts, message
    real(wp), intent(out), optional :: g(:)     !< Ax - b at the returned x (size n; unset if bad input)
    real(wp), intent(inout), optional :: ax(:)  !< in (opts%use_ax): A x at the warm start; out: A x at the returned x
    real(wp), intent(in), optional :: s(:)      !< direction of a first line search (size n; needs as)
    real(wp), intent(in), optional :: as(:)     !< A s (size n)
    real(wp), intent(inout), optional :: rw(:, :)   !< (n, k) stored directions, A-normalised (needs raw, nrw)
    real(wp), intent(inout), optional :: raw(:, :)  !< (n, k) A rw
    integer, intent(inout), optional :: nrw(2)      !< directions held in rw, next slot to fill (ring)
    real(wp), intent(in), optional :: eq_g(:, :)    !< (r, n) equality rows (SMALBE; with eq_e, opts%eq_m)
    real(wp), intent(in), optional :: eq_e(:)       !< (r) their right-hand side

    real(wp), allocatable :: gr(:), p(:), ap(:), w(:), v(:), av(:)
    real(wp), parameter :: big = huge(1.0_wp)
    integer :: n, i, it, blk, retry, nmv_pow
    logical :: fresh, proportional, zero_tol
    real(wp) :: tol, tol_now, ab, lam_lo, bnorm, xscale0, feas, floor_eq
    real(wp) :: phiphi, phitphi, betabeta, gp2, phi, phit, beta, slack
    real(wp) :: pap, pp, gtp, acg, af, gam, num, df, dd, dad, ab_prev, lam_pow
    character(len=24) :: s1, s2

    stats = mprgp_stats_t()
    n = A%n

    ! ---- arguments ---------------------------------------------------------------
    if (n < 0) then
      call fail(MPRGP_BAD_ARG, 'operator size A%n is negative')
      return
    end if
    if (size(b) /= n .or. size(lb) /= n .or. size(x) /= n) then
      write (stats%message, '(a,i0,a,i0,a,i0,a,i0)') 'size mismatch: A%n = ', n, &
        ', size(b) = ', size(b), ', size(lb) = ', size(lb), ', size(x) = ', size(x)
      stats%status = MPRGP_BAD_ARG
      return
    end if
    if (present(ax)) then
      if (size(ax) /= n) then
        call fail(MPRGP_BAD_ARG, 'size mismatch: size(ax) /= A%n')
        return
      end if
    else if (opts%use_ax) then
      call fail(MPRGP_BAD_ARG, 'opts%use_ax without ax')
      return
    end if
    if (present(s) .neqv. present(as)) then
      call fail(MPRGP_BAD_ARG, 's and as must be given together')
      return
    end if
    if (present(s)) then
      if (size(s) /= n .or. size(as) /= n) then
        call fail(MPRGP_BAD_ARG, 'size mismatch: size(s) or size(as) /= A%n')
        return
      end if
    end if
    if ((present(rw) .neqv. present(raw)) .or. (present(rw) .neqv. present(nrw))) then
      call fail(MPRGP_BAD_ARG, 'rw, raw and nrw must be given together')
      return
    end if
    if (present(rw)) then
      if (size(rw, 1) /= n .or. size(raw, 1) /= n .or. size(raw, 2) /= size(rw, 2)) then
        call fail(MPRGP_BAD_ARG, 'size mismatch: rw or raw is not (A%n, k)')
        return
      end if
      if (nrw(1) < 0 .or. nrw(1) > size(rw, 2) .or. nrw(2) < 1 .or. nrw(2) > max(1, size(rw, 2))) then
        call fail(MPRGP_BAD_ARG, 'nrw out of range')
        return
      end if
    end if
    if (present(g)) then
      if (size(g) /= n) then
        write (stats%message, '(a,i0,a,i0)') 'size mismatch: A%n = ', n, ', size(g) = ', size(g)
        stats%status = MPRGP_BAD_ARG
        return
      end if
    end if
    if (.not. ieee_is_finite(opts%rtol)) then
      call fail(MPRGP_BAD_ARG, 'opts%rtol is not finite')
      return
    else if (opts%rtol < 0.0_wp) then
      call fail(MPRGP_BAD_ARG, 'opts%rtol is negative: '//trim(rtoa(opts%rtol)))
      return
    end if
    if (.not. ieee_is_finite(opts%atol)) then
      call fail(MPRGP_BAD_ARG, 'opts%atol is not finite')
      return
    else if (opts%atol < 0.0_wp) then
      call fail(MPRGP_BAD_ARG, 'opts%atol is negative: '//trim(rtoa(opts%atol)))
      return
    end if
    if (opts%max_it < 0) then
      call fail(MPRGP_BAD_ARG, 'opts%max_it is negative')
      return
    end if
    if (.not. ieee_is_finite(opts%gamma)) then
      call fail(MPRGP_BAD_ARG, 'opts%gamma is not finite')
      return
    else if (opts%gamma <= 0.0_wp) then
      call fail(MPRGP_BAD_ARG, 'opts%gamma must be positive: '//trim(rtoa(opts%gamma)))
      return
    end if
    if (.not. (ieee_is_finite(opts%alpha_bar) .and. ieee_is_finite(opts%lambda_max))) then
      call fail(MPRGP_BAD_ARG, 'opts%alpha_bar or opts%lambda_max is not finite')
      return
    end if
    if (opts%alpha_bar <= 0.0_wp .and. opts%lambda_max <= 0.0_wp .and. opts%power_its < 1) then
      call fail(MPRGP_BAD_ARG, 'opts%power_its must be >= 1 when neither alpha_bar nor lambda_max is given')
      return
    end if
    do i = 1, n
      if (.not. ieee_is_finite(b(i))) then
        call fail(MPRGP_NONFINITE, 'b('//trim(itoa(i))//') is not finite')
        return
      end if
      if (.not. ieee_is_finite(lb(i))) then
        call fail(MPRGP_NONFINITE, 'lb('//trim(itoa(i))//') is not finite (use -huge(1.0_wp) for no bound)')
        return
      end if
      if (.not. ieee_is_finite(x(i))) then
        call fail(MPRGP_NONFINITE, 'initial x('//trim(itoa(i))//') is not finite')
        return
      end if
    end do

    bnorm = norm2(b)
    stats%b_norm = bnorm
    if (n == 0) then
      stats%status = MPRGP_CONVERGED
      stats%message = 'converged: empty problem'
      return
    end if
    tol = max(opts%rtol * bnorm, opts%atol)
    zero_tol = (tol <= 0.0_wp)

    allocate (gr(n), p(n), ap(n), w(n), v(n), av(n))
    ab = 0.0_wp       ! alpha_bar in use (0: not yet needed)
    lam_lo = 0.0_wp   ! largest known lower bound of lambda_max
    if (opts%lambda_max > 0.0_wp) lam_lo = opts%lambda_max

    ! ---- start: project, gradient ------------------------------------------------------
    x = max(x, lb)
    xscale0 = norm2(x)
    if (opts%use_ax) then
      gr = ax - b
    else
      call A%apply(x, gr)
      stats%n_matvec = 1
      if (present(ax)) ax = gr
      gr = gr - b
    end if
    fresh = .true.
    ! a warm start that already meets the tolerance is returned as it is (no product)
    if (zero_tol .or. proj_grad_norm() > tol) then
      if (present(rw) .and. opts%recycle) then
        call recycled_subspace()
      else if (present(s)) then
        call line_search(s, as, .false.)
      end if
    end if
    call set_p_to_phi()
    it = 0

    main: do
      ! Split the gradient (one pass).
      phiphi = 0.0_wp
      phitphi = 0.0_wp
      betabeta = 0.0_wp
      do i = 1, n
        if (x(i) > lb(i)) then
          phi = gr(i)
          phiphi = phiphi + phi * phi
          phit = phi
          if (ab > 0.0_wp .and. lb(i) > -big) then
            slack = x(i) - lb(i)
            if (slack < ab * phi) phit = slack / ab
          end if
          phitphi = phitphi + phit * phi
        else
          beta = min(gr(i), 0.0_wp)
          betabeta = betabeta + beta * beta
        end if
      end do
      gp2 = phiphi + betabeta
      stats%gp_norm = sqrt(gp2)
      if (.not. ieee_is_finite(gp2)) then
        call fail(MPRGP_NONFINITE, 'the projected gradient became non-finite after '// &
                  trim(itoa(it))//' steps')
        exit main
      end if

      ! Stopping test, confirmed on the true gradient.
      tol_now = tol
      if (zero_tol .and. gp2 > 0.0_wp) then
        if (.not. ensure_alpha()) exit main
        tol_now = 10.0_wp * sqrt(real(n, wp)) * epsilon(1.0_wp) * max(lam_lo, ALPHA_FACTOR / ab) * &
                  max(norm2(x), xscale0)
      end if
      if (present(eq_g) .and. stats%gp_norm <= tol_now .and. opts%eq_m > 0.0_wp) then
        ! SMALBE-M: solve more precisely while the equality is far from holding
        feas = norm2(matmul(eq_g, x) - eq_e)
        if (feas > opts%eq_feas) then
          floor_eq = 10.0_wp*sqrt(real(n, wp))*epsilon(1.0_wp)*lam_lo*max(norm2(x), xscale0)
          tol_now = max(min(tol_now, opts%eq_m*feas), floor_eq)
        end if
      end if
      if (stats%gp_norm <= tol_now) then
        if (fresh) then
          stats%status = MPRGP_CONVERGED
          write (s1, '(es10.3)') stats%gp_norm
          write (s2, '(es10.3)') tol_now
          stats%message = 'converged: |gP| = '//trim(adjustl(s1))//' <= '//trim(adjustl(s2))// &
                          ' after '//trim(itoa(it))//' steps, '//trim(itoa(stats%n_matvec))//' products with A'
          exit main
        end if
        call true_gradient()
        call set_p_to_phi()
        cycle main
      end if
      if (it >= opts%max_it) then
        stats%status = MPRGP_MAX_IT
        write (s1, '(es10.3)') stats%gp_norm
        write (s2, '(es10.3)') tol_now
        stats%message = 'not converged: |gP| = '//trim(adjustl(s1))//' > '//trim(adjustl(s2))// &
                        ' after max_it = '//trim(itoa(opts%max_it))//' steps'
        exit main
      end if
      if (associated(opts%stop)) then
        if (opts%stop()) then
          stats%status = MPRGP_STOPPED
          stats%message = 'stopped on request after '//trim(itoa(it))//' steps'
          exit main
        end if
      end if
      it = it + 1

      ! Proportionality test (alpha_bar is needed only when some bound is active).
      if (betabeta > 0.0_wp .and. ab <= 0.0_wp) then
        if (.not. ensure_alpha()) exit main
        phitphi = 0.0_wp
        do i = 1, n
          if (x(i) > lb(i)) then
            phi = gr(i)
            phit = phi
            if (lb(i) > -big) then
              slack = x(i) - lb(i)
              if (slack < ab * phi) phit = slack / ab
            end if
            phitphi = phitphi + phit * phi
          end if
        end do
      end if
      proportional = (betabeta <= opts%gamma**2 * phitphi)

      if (proportional) then
        ! ---- trial conjugate gradient step along -p ----
        call A%apply(p, ap)
        stats%n_matvec = stats%n_matvec + 1
        pap = 0.0_wp
        pp = 0.0_wp
        gtp = 0.0_wp
        do i = 1, n
          pap = pap + p(i) * ap(i)
          pp = pp + p(i) * p(i)
          gtp = gtp + gr(i) * p(i)
        end do
        if (.not. check_curvature(pap, pp, 'conjugate gradient direction')) exit main
        if (present(rw)) call store_direction(p, ap)
        acg = gtp / pap
        ! Largest feasible step along -p, capped at acg (no division can overflow).
        af = acg
        blk = 0
        do i = 1, n
          if (p(i) > 0.0_wp .and. lb(i) > -big) then
            slack = x(i) - lb(i)
            if (slack < af * p(i)) then
              af = slack / p(i)
              blk = i
            end if
          end if
        end do

        if (blk == 0) then
          ! CG step.
          num = 0.0_wp
          do i = 1, n
            x(i) = max(x(i) - acg * p(i), lb(i))
            gr(i) = gr(i) - acg * ap(i)
            if (x(i) > lb(i)) num = num + gr(i) * ap(i)
          end do
          gam = num / pap
          do i = 1, n
            if (x(i) > lb(i)) then
              p(i) = gr(i) - gam * p(i)
            else
              p(i) = -gam * p(i)
            end if
          end do
          stats%n_cg = stats%n_cg + 1
          fresh = .false.
        else
          ! Expansion step: feasible half step, then projected step of length alpha_bar.
          af = max(af, 0.0_wp)
          do i = 1, n
            x(i) = max(x(i) - af * p(i), lb(i))
            gr(i) = gr(i) - af * ap(i)
          end do
          x(blk) = lb(blk)
          if (.not. ensure_alpha()) exit main
          retry = 0
          expand: do
            ! Candidate step d = P(x - ab*phi) - x = -ab*phit, stored in p (reset afterwards).
            dd = 0.0_wp
            do i = 1, n
              if (x(i) > lb(i)) then
                p(i) = max(lb(i) - x(i), -ab * gr(i))
              else
                p(i) = 0.0_wp
              end if
              dd = dd + p(i) * p(i)
            end do
            if (dd <= 0.0_wp) exit expand
            call A%apply(p, ap)
            stats%n_matvec = stats%n_matvec + 1
            dad = 0.0_wp
            df = 0.0_wp
            do i = 1, n
              dad = dad + p(i) * ap(i)
              df = df + gr(i) * p(i)
            end do
            df = df + 0.5_wp * dad
            ab_prev = ab
            if (.not. check_curvature(dad, dd, 'expansion step')) exit main
            if (df > 0.0_wp .and. ab < ab_prev .and. retry < MAX_RETRY) then
              ! The step increased the cost: alpha_bar exceeded 2/lambda_max. Cut and retry.
              retry = retry + 1
              cycle expand
            end if
            do i = 1, n
              x(i) = max(x(i) + p(i), lb(i))
              gr(i) = gr(i) + ap(i)
            end do
            exit expand
          end do expand
          call set_p_to_phi()
          stats%n_exp = stats%n_exp + 1
          fresh = .false.
        end if
      else
        ! ---- proportioning step along -beta ----
        do i = 1, n
          if (x(i) > lb(i)) then
            p(i) = 0.0_wp
          else
            p(i) = min(gr(i), 0.0_wp)
          end if
        end do
        call A%apply(p, ap)
        stats%n_matvec = stats%n_matvec + 1
        pap = 0.0_wp
        pp = 0.0_wp
        do i = 1, n
          pap = pap + p(i) * ap(i)
          pp = pp + p(i) * p(i)
        end do
        if (.not. check_curvature(pap, pp, 'proportioning direction')) exit main
        acg = betabeta / pap
        do i = 1, n
          x(i) = max(x(i) - acg * p(i), lb(i))
          gr(i) = gr(i) - acg * ap(i)
        end do
        call set_p_to_phi()
        stats%n_prop = stats%n_prop + 1
        fresh = .false.
      end if
    end do main

    stats%lambda_max = lam_lo
    stats%alpha_bar = ab
    ! Report the true gradient (and |gP| from it) unless the iteration broke down.
    if (.not. fresh .and. (stats%status == MPRGP_MAX_IT .or. stats%status == MPRGP_NOT_SPD)) then
      call true_gradient()
      stats%gp_norm = proj_grad_norm()
    end if
    if (present(g)) g = gr
    if (present(ax) .and. .not. fresh) ax = gr + b

  contains


    !> Exact line search along d (A d is given: no product), cut at the bounds; with
    !! `whole`, only the whole step, and only if it helps (see below).
    subroutine line_search(d, ad, whole)
      real(wp), intent(in) :: d(:), ad(:)
      logical, intent(in) :: whole
      integer :: j
      real(wp) :: dad_, t, vj, gp_before, gp_after, bb_after
      dad_ = dot_product(d, ad)
      if (.not. (dad_ > 0.0_wp .and. ieee_is_finite(dad_))) return
      t = -dot_product(gr, d) / dad_
      if (.not. ieee_is_finite(t)) return
      do j = 1, n
        vj = t * d(j)
        if (vj < 0.0_wp .and. lb(j) > -big) then
          if (x(j) + vj < lb(j)) then
            if (whole) return
            t = t * max(0.0_wp, (x(j) - lb(j)) / (-vj))
          end if
        end if
      end do
      if (t == 0.0_wp) return
      if (whole) then
        ! p and ap are free here: the candidate is kept only if its projected gradient is
        ! smaller and it is proportional (|chopped|^2 <= Gamma^2 |free|^2); otherwise MPRGP
        ! would first release bounds and redo what the step did (delta = 1 cycles)
        gp_before = proj_grad_norm()
        do j = 1, n
          p(j) = max(x(j) + t * d(j), lb(j))
          ap(j) = gr(j) + t * ad(j)
        end do
        gp_after = 0.0_wp
        bb_after = 0.0_wp
        do j = 1, n
          if (p(j) > lb(j)) then
            gp_after = gp_after + ap(j)**2
          else
            bb_after = bb_after + min(ap(j), 0.0_wp)**2
          end if
        end do
        if (.not. (sqrt(gp_after + bb_after) < gp_before .and. bb_after <= opts%gamma**2 * gp_after)) return
        x = p
        gr = ap
      else
        do j = 1, n
          x(j) = max(x(j) + t * d(j), lb(j))
          gr(j) = gr(j) + t * ad(j)
        end do
      end if
      stats%n_recycled = stats%n_recycled + 1
      fresh = .false.
    end subroutine line_search

    !> The minimum over the warm start plus the span of s and of the stored directions
    !! that vanish where x is at its bound (no product: all the images under A are known),
    !! taken only if the whole Galerkin step is feasible (a step cut at a bound would fix
    !! variables that belong to the free set). A direction keeps its place only if at
    !! least 1e-4 of its A-norm squared is left after the A-orthogonalisation: the rounding
    !! of its image then stays within 100 times that of a product.
    subroutine recycled_subspace()
      real(wp), allocatable :: q(:, :), aq(:, :)
      integer :: j, l, k, pass
      real(wp) :: c, d0, dn
      allocate (q(n, nrw(1) + 1), aq(n, nrw(1) + 1))
      k = 0
      do j = 0, nrw(1)
        if (j == 0) then
          if (.not. present(s)) cycle
          v = s
          av = as
        else
          v = rw(:, j)
          av = raw(:, j)
        end if
        if (any(v /= 0.0_wp .and. x <= lb)) cycle
        d0 = dot_product(v, av)
        if (.not. (d0 > 0.0_wp .and. ieee_is_finite(d0))) cycle
        do pass = 1, 2
          do l = 1, k
            c = dot_product(aq(:, l), v)
            v = v - c * q(:, l)
            av = av - c * aq(:, l)
          end do
        end do
        dn = dot_product(v, av)
        if (.not. (dn > 1.0e-4_wp * d0 .and. ieee_is_finite(dn))) cycle
        k = k + 1
        q(:, k) = v / sqrt(dn)
        aq(:, k) = av / sqrt(dn)
      end do
      if (k == 0) return
      v = 0.0_wp
      av = 0.0_wp
      do l = 1, k
        c = -dot_product(gr, q(:, l))
        v = v + c * q(:, l)
        av = av + c * aq(:, l)
      end do
      call line_search(v, av, .true.)
    end subroutine recycled_subspace

    !> Keep the direction d (with A d), A-normalised, in the ring rw, raw (the oldest
    !! makes room when it is full).
    subroutine store_direction(d, ad)
      real(wp), intent(in) :: d(:), ad(:)
      integer :: k
      real(wp) :: d0
      k = size(rw, 2)
      if (k == 0) return
      d0 = dot_product(d, ad)
      if (.not. (d0 > 0.0_wp .and. ieee_is_finite(d0))) return
      d0 = 1.0_wp / sqrt(d0)
      rw(:, nrw(2)) = d0 * d
      raw(:, nrw(2)) = d0 * ad
      nrw(1) = min(nrw(1) + 1, k)
      nrw(2) = mod(nrw(2), k) + 1
    end subroutine store_direction

    !> Record a failure.
    subroutine fail(code, msg)
      integer, intent(in) :: code
      character(len=*), intent(in) :: msg
      stats%status = code
      stats%message = msg
    end subroutine fail

    !> p = phi(x).
    subroutine set_p_to_phi()
      integer :: j
      do j = 1, n
        if (x(j) > lb(j)) then
          p(j) = gr(j)
        else
          p(j) = 0.0_wp
        end if
      end do
    end subroutine set_p_to_phi

    !> |gP| for the current x and gr.
    real(wp) function proj_grad_norm() result(r)
      integer :: j
      r = 0.0_wp
      do j = 1, n
        if (x(j) > lb(j)) then
          r = r + gr(j)**2
        else
          r = r + min(gr(j), 0.0_wp)**2
        end if
      end do
      r = sqrt(r)
    end function proj_grad_norm

    !> gr = A x - b computed directly.
    subroutine true_gradient()
      call A%apply(x, gr)
      stats%n_matvec = stats%n_matvec + 1
      if (present(ax)) ax = gr
      gr = gr - b
      fresh = .true.
    end subroutine true_gradient

    !> Make alpha_bar available (power iteration on first need). False on failure.
    logical function ensure_alpha() result(ok)
      ok = .true.
      if (ab > 0.0_wp) return
      if (opts%alpha_bar > 0.0_wp) then
        ab = opts%alpha_bar
        if (lam_lo * ab > 2.0_wp) ab = ALPHA_FACTOR / lam_lo
        return
      end if
      if (opts%lambda_max <= 0.0_wp) then
        ! ap and w are free whenever this is called.
        call power_iteration(A, opts%power_its, ap, w, lam_pow, nmv_pow)
        stats%n_matvec = stats%n_matvec + nmv_pow
        if (.not. ieee_is_finite(lam_pow)) then
          call fail(MPRGP_NONFINITE, 'A produced a non-finite value in the power iteration')
          ok = .false.
          return
        end if
        if (lam_pow <= 0.0_wp) then
          call fail(MPRGP_NOT_SPD, 'A v = 0 for the power-iteration vector: A is not SPD')
          ok = .false.
          return
        end if
        lam_lo = max(lam_lo, lam_pow)
      end if
      ab = ALPHA_FACTOR / lam_lo
    end function ensure_alpha

    !> Check d'Ad > 0 and finite; update the lambda_max bound and the alpha_bar guard.
    logical function check_curvature(dad_, dd_, what) result(ok)
      real(wp), intent(in) :: dad_, dd_
      character(len=*), intent(in) :: what
      real(wp) :: rq_
      ok = .false.
      if (.not. (ieee_is_finite(dad_) .and. ieee_is_finite(dd_))) then
        call fail(MPRGP_NONFINITE, 'non-finite curvature along the '//what//' after '// &
                  trim(itoa(it))//' steps')
        return
      end if
      if (dad_ <= 0.0_wp .and. dd_ <= tiny(1.0_wp)) then
        ! the direction has vanished (underflowed): the iterate is exact to working
        ! precision and a tolerance below that cannot be reached; not a curvature failure
        stats%status = MPRGP_CONVERGED
        write (s1, '(es10.3)') stats%gp_norm
        stats%message = 'converged to working precision: |gP| = '//trim(adjustl(s1))// &
                        ' (the tolerance asked for is below what double precision resolves)'
        return
      end if
      if (dad_ <= 0.0_wp) then
        write (s1, '(es10.3)') dad_
        call fail(MPRGP_NOT_SPD, 'p''Ap = '//trim(adjustl(s1))//' <= 0 along the '//what// &
                  ' at step '//trim(itoa(it))//': A is not SPD')
        return
      end if
      ok = .true.
      rq_ = dad_ / dd_
      if (rq_ > lam_lo) lam_lo = rq_
      if (ab > 0.0_wp .and. ab * lam_lo > 2.0_wp) ab = ALPHA_FACTOR / lam_lo
    end function check_curvature

  end subroutine mprgp_solve

end module mprgp
