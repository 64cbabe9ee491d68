!> SMALBE-M: semi-monotonic augmented Lagrangian for bound and equality constraints,
!!
!!     minimise 1/2 x'Hx - c'x   subject to   l <= x <= u,   G x = e      (G: r x n, r small)
!!
!! with MPRGP (module mprgp) as its inner solver. Z. Dostal, "Optimal Quadratic
!! Programming Algorithms", Springer 2009, ch. 9; the form used here (doc/method.md,
!! "Bodies held only by contact"): for a fixed penalty rho and multipliers mult,
!!
!!     L(x, mult, rho) = 1/2 x'Hx - c'x + mult'(Gx - e) + rho/2 |Gx - e|^2
!!
!! is minimised over the box l <= x <= u by MPRGP with the Hessian A = H + rho G'G (the
!! caller passes A: its products are the only ones, and since A does not change from one
!! solve to the next MPRGP's stored directions stay valid) and the linear term
!! c - G'mult + rho G'e, to a projected gradient below min(M |Gx - e|, eta); then
!! mult <- mult + rho (Gx - e), and M <- beta M when L did not grow by at least
!! rho/2 |Gx - e|^2. It stops when the projected gradient is below eta and |Gx - e| below
!! feas. The upper bounds are optional (absent or +huge(1.0_wp): none); the bounds go to
!! MPRGP as one `box_set_t` (module constraint_set), or `smalbe_solve_in` takes any
!! constraint set (the discs of friction in space).
!!
!! On return g = Hx - c + G'mult (the gradient of the Lagrangian at the final multipliers,
!! which is MPRGP's last gradient), so for contact `G_a - g` is still B_a u_a with the
!! rigid part of u_a = R_a alpha_a, alpha_a = -mu_a. At the solution g holds the bound
!! multipliers: g_i >= 0 where x_i = l_i, g_i <= 0 where x_i = u_i, g_i = 0 in between.
module smalbe
  use kinds, only: wp
  use linop, only: linop_t
  use lapack, only: dposv
  use mprgp, only: mprgp_t, mprgp_opts_t, mprgp_stats_t, MPRGP_CONVERGED, MPRGP_MAX_IT, QP_NEWTON
  use constraint_set, only: constraint_set_t, box_set
  implicit none (type, external)
  private

  public :: smalbe_solve, smalbe_solve_in, smalbe_stats_t, SMALBE_MAX_UPDATES

  integer, parameter :: SMALBE_MAX_UPDATES = 200   !< multiplier updates before giving up
  real(wp), parameter :: BETA = 0.2_wp              !< M <- BETA M when L did not grow enough

  !> What smalbe_solve did.
  type :: smalbe_stats_t
    type(mprgp_stats_t) :: inner        !< the last MPRGP solve (status: MPRGP_*, converged or not)
    integer :: n_matvec = 0             !< products with A over all MPRGP solves
    integer :: updates = 0              !< multiplier updates (SMALBE outer iterations)
    !> an inner solve of QP_AUTO switched to the Newton method (the later ones then used it alone)
    logical :: switched = .false.
    real(wp) :: feas = 0.0_wp           !< |Gx - e| at the returned x
    real(wp) :: m_final = 0.0_wp        !< M at the end
  end type smalbe_stats_t

contains

  !> Solve the bound- and equality-constrained QP (module header) with the MPRGP solver
  !! `solver` for every inner solve: its options give eta (rtol/atol), max_it, lambda_max of
  !! A, use_ax (its ax: A x at the warm start, first solve only), recycle, and SMALBE's
  !! initial M (opts%eq_m > 0) and the |Gx - e| that counts as feasible (opts%eq_feas); its
  !! search direction s, as (if any) serves the first solve. On return solver%g holds
  !! Hx - c + G'mult and solver%ax A x. mult holds the warm start of the multipliers and returns
  !! them. stats%inner%status is MPRGP_CONVERGED only when both the projected gradient and
  !! |Gx - e| met their tolerances.
  subroutine smalbe_solve(solver, A, c, gm, e, rho, lb, x, mult, stats, rw, raw, nrw, ub)
    type(mprgp_t), intent(inout) :: solver      !< inner solver (options; ax, g as above)
    class(linop_t), intent(inout) :: A          !< H + rho G'G
    real(wp), intent(in) :: c(:)                !< (n) linear term
    real(wp), intent(in) :: gm(:, :)            !< (r, n) equality rows G
    real(wp), intent(in) :: e(:)                !< (r) right-hand side
    real(wp), intent(in) :: rho                 !< the penalty folded into A
    real(wp), intent(in) :: lb(:)               !< (n) lower bounds
    real(wp), intent(inout) :: x(:)             !< in: warm start; out: solution
    real(wp), intent(inout) :: mult(:)            !< (r) in: warm start; out: multipliers
    type(smalbe_stats_t), intent(out) :: stats
    real(wp), intent(inout), optional :: rw(:, :), raw(:, :)  !< stored directions (mprgp_t%solve)
    integer, intent(inout), optional :: nrw(2)
    real(wp), intent(in), optional :: ub(:)     !< (n) upper bounds (>= lb); +huge(1.0_wp): none
    call smalbe_solve_in(solver, A, c, gm, e, rho, box_set(lb, ub), x, mult, stats, rw, raw, nrw)
  end subroutine smalbe_solve

  !> `smalbe_solve` on any constraint set (a box, or discs: module tangent_discs).
  subroutine smalbe_solve_in(solver, A, c, gm, e, rho, set, x, mult, stats, rw, raw, nrw)
    type(mprgp_t), intent(inout) :: solver      !< inner solver (options; ax, g as above)
    class(linop_t), intent(inout) :: A          !< H + rho G'G
    real(wp), intent(in) :: c(:)                !< (n) linear term
    real(wp), intent(in) :: gm(:, :)            !< (r, n) equality rows G
    real(wp), intent(in) :: e(:)                !< (r) right-hand side
    real(wp), intent(in) :: rho                 !< the penalty folded into A
    class(constraint_set_t), intent(in) :: set  !< the feasible set
    real(wp), intent(inout) :: x(:)             !< in: warm start; out: solution
    real(wp), intent(inout) :: mult(:)            !< (r) in: warm start; out: multipliers
    type(smalbe_stats_t), intent(out) :: stats
    real(wp), intent(inout), optional :: rw(:, :), raw(:, :)  !< stored directions (mprgp_t%solve)
    integer, intent(inout), optional :: nrw(2)
    type(mprgp_opts_t) :: opts
    real(wp), allocatable :: rhs(:), r(:)
    real(wp) :: lag_old, lag_new, rr, m_control, feas
    integer :: n, k
    logical :: have_ax

    n = size(x)
    allocate (rhs(n), r(size(e)))
    opts = solver%opts
    feas = opts%eq_feas
    m_control = opts%eq_m
    have_ax = opts%use_ax .and. allocated(solver%ax)
    if (have_ax) call multiplier_estimate(gm, e, rho, set, x, c, solver%ax, mult)
    solver%eq_g = gm
    solver%eq_e = e
    lag_old = -huge(1.0_wp)
    stats%updates = 0
    do k = 1, SMALBE_MAX_UPDATES
      solver%opts = opts
      solver%opts%eq_m = m_control
      solver%opts%use_ax = have_ax
      ! a projected gradient below the rounding of a product with A cannot be reached (A
      ! holds rho G'G, about RHO_FACTOR times the Hessian's own scale): floor the tolerance
      ! there, sqrt(n) eps lambda_max(A) |x|, instead of spinning MPRGP up to max_it (measured:
      ! a floating body under the harmonic tolerance, 1.2 M products for m = 25 without it; a
      ! floor 10 times higher costs a soft floating body's contrast case its last digits)
      if (opts%lambda_max > 0.0_wp) &
        solver%opts%atol = max(opts%atol, sqrt(real(n, wp))*epsilon(1.0_wp)*opts%lambda_max*norm2(x))
      ! linear term of L(., mult, rho) with the penalty's part: c - G'mult + rho G'e
      rhs = c - matmul(mult - rho*e, gm)
      feas = max(opts%eq_feas, opts%eq_feas_x*norm2(x))
      solver%opts%eq_feas = feas
      call solver%solve_in(A, rhs, set, x, rw, raw, nrw)
      stats%inner = solver%stats
      if (solver%stats%switched) then
        ! the penalized Hessian needs the Newton method: the next solves start with it
        stats%switched = .true.
        opts%method = QP_NEWTON
      end if
      have_ax = .true.
      stats%n_matvec = stats%n_matvec + stats%inner%n_matvec
      r = matmul(gm, x) - e
      rr = norm2(r)
      stats%feas = rr
      ! the new multipliers; MPRGP's gradient is the Lagrangian's gradient at them (also after
      ! an inner solve that stopped on max_it: g and mult must agree, the caller's B u uses both)
      mult = mult + rho*r
      if (stats%inner%status /= MPRGP_CONVERGED) exit
      ! L(x, mu_new, rho) = 1/2 x'Ax - x'rhs(mu_old) + mu_old'(Gx - e)... written out:
      ! 1/2 x'Hx - c'x + mu_new'(Gx - e) + rho/2 |Gx - e|^2, with x'Hx = x'Ax - rho |Gx|^2
      lag_new = 0.5_wp*(dot_product(x, solver%ax) - rho*sum(matmul(gm, x)**2)) - dot_product(c, x) + &
                dot_product(mult, r) + 0.5_wp*rho*rr*rr
      stats%updates = k
      feas = max(opts%eq_feas, opts%eq_feas_x*norm2(x))
      if (rr <= feas) exit
      if (lag_new < lag_old + 0.5_wp*rho*rr*rr) m_control = BETA*m_control
      lag_old = lag_new
    end do
    stats%m_final = m_control
    if (stats%inner%status == MPRGP_CONVERGED .and. stats%feas > feas) then
      stats%inner%status = MPRGP_MAX_IT
      write (stats%inner%message, '(a,i0,a,es10.3,a,es10.3)') 'SMALBE: ', SMALBE_MAX_UPDATES, &
        ' multiplier updates without |Gx - e| = ', stats%feas, ' <= ', feas
    end if
    solver%opts = opts
    deallocate (solver%eq_g, solver%eq_e)
  end subroutine smalbe_solve_in

  !> A better start for the multipliers when the warm start mult is far off: the least-squares
  !! multipliers of the free set, mu_ls = argmin |g0_F + G_F' mult| (g0 = H x - c, no product:
  !! H x = A x - rho G'G x), over every variable when x has no free one (a floating body that
  !! lost contact: mu_ls is then the rigid shift that brings it back to its obstacle on
  !! average, where the warm start would need of order |shift| / (rho |e|) updates to get).
  !! mu_ls replaces mult when the Lagrangian's projected gradient at x is smaller with it.
  subroutine multiplier_estimate(gm, e, rho, set, x, c, ax, mult)
    real(wp), intent(in) :: gm(:, :), e(:), rho, x(:), c(:), ax(:)
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(inout) :: mult(:)
    real(wp), allocatable :: g0(:), gf(:, :), a(:, :), b(:), mls(:)
    logical, allocatable :: free(:)
    integer :: r, i, info
    r = size(e)
    g0 = ax - rho*matmul(matmul(gm, x), gm) - c
    allocate (free(size(x)))
    call set%free_mask(x, free)
    if (count(free) < r) free = .true.
    allocate (a(r, r), b(r))
    gf = gm(:, pack([(i, i=1, size(x))], free))
    a = matmul(gf, transpose(gf))
    b = -matmul(gf, pack(g0, free))
    call dposv('U', r, 1, a, r, b, r, info)
    if (info /= 0) return
    mls = b
    if (proj_norm(set, g0 + matmul(mls, gm), x) < proj_norm(set, g0 + matmul(mult, gm), x)) mult = mls
  end subroutine multiplier_estimate

  !> Norm of the projected gradient of g at x (norm2 of the vector gP).
  real(wp) function proj_norm(set, g, x) result(v)
    class(constraint_set_t), intent(in) :: set
    real(wp), intent(in) :: g(:), x(:)
    real(wp), allocatable :: gp(:)
    allocate (gp(size(x)))
    call set%projected_gradient(x, g, gp)
    v = norm2(gp)
  end function proj_norm


end module smalbe
