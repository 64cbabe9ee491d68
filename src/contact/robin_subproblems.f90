!> Step 1 of the Robin iteration: each body's contact problem against its obstacle,
!! min 1/2 l'(F_a + Pi_a) l - l'(b_a - G_a + Pi_a lam_o), l >= 0 (MPRGP; SMALBE-M with the
!! body's equilibrium as an equality when it is held only by contact), the two bodies on
!! two threads, warm-started from the last contact forces (doc/method.md, "Method as
!! implemented"). The Hessians and their bounds are built once, before the outer loop.
module robin_subproblems
  use kinds, only: wp
  use config, only: solver_cfg_t, ACCEL_NONE
  use linop, only: dense_op_t, dense_op_init
  use mprgp, only: mprgp_t, mprgp_stats_t, MPRGP_CONVERGED, MPRGP_MAX_IT, mprgp_status_name
  use smalbe, only: smalbe_solve, smalbe_stats_t
  use condense, only: body_condensed_t
  use contact_types, only: contact_result_t, robin_state_t, STATUS_FAILED
  use contact_common, only: other_body, body_threads
  use equality_rows, only: equality_t, equality_init, equality_add_penalty
  use robin_operators, only: robin_operator_t
  implicit none (type, external)
  private

  real(wp), parameter :: SMOOTH_RATE_TOL = 0.1_wp   !< rate change below which the outer iteration counts as smooth
  real(wp), parameter :: FEAS_RTOL_MIN = 1.0e-15_wp !< equilibrium of a floating body: max(inner tolerance, rounding, this) |e|

  !> The two bodies' subproblems as the outer loop solves them.
  type, public :: subproblems_t
    type(dense_op_t) :: flexibility(2)       !< F_a
    type(dense_op_t) :: hessian(2)           !< F_a + Pi_a (+ rho G_a'G_a for a floating body)
    type(dense_op_t) :: proximal(2)          !< Pi_a (n = 0 when F_a is nonsingular)
    type(equality_t) :: equality(2)          !< equilibrium rows of a floating body (r = 0: none)
    real(wp) :: lmax_body(2) = 0.0_wp        !< bounds of lambda_max(F_a) [length/force]
    real(wp) :: lmax_hessian(2) = 0.0_wp     !< bounds of lambda_max of the Hessians [length/force]
  end type subproblems_t

  public :: subproblems_init, solve_subproblems

contains

  !> Each body's F_a, its bound of lambda_max (robin_op%body_lambda_max; its products are
  !! counted in state%inner unless the run resumes), and the subproblem Hessian: F_a + Pi_a,
  !! Pi_a = 0 unless F_a is singular (module condense: a mortar master coarser than the
  !! slave), then the proximal term 1/2 (l - lam_o)' Pi_a (l - lam_o), lam_o the other body's
  !! last contact force, fixes the part of lam_a that body a's own problem leaves
  !! undetermined; the fixed point stays the monolithic solution for every Pi_a >= 0
  !! (doc/method.md, "Non-matching and curved contact surfaces: dual mortar"). A floating
  !! body's Hessian carries the penalty of its equilibrium rows.
  subroutine subproblems_init(subproblems, bodies, robin_op, state, resumed)
    type(subproblems_t), intent(out) :: subproblems     !< the subproblems
    type(body_condensed_t), intent(in) :: bodies(2)     !< condensed bodies
    class(robin_operator_t), intent(in) :: robin_op     !< the Robin operator
    type(robin_state_t), intent(inout) :: state         !< outer state (inner count)
    logical, intent(in) :: resumed                      !< the run resumes from a checkpoint
    real(wp), allocatable :: p(:, :)
    integer :: a, nmv(2), m
    m = bodies(1)%m
    nmv = 0
    !$omp parallel do num_threads(body_threads()) schedule(static, 1) if (m > 64)
    do a = 1, 2
      call dense_op_init(subproblems%flexibility(a), bodies(a)%flex)
      if (m > 0) subproblems%lmax_body(a) = robin_op%body_lambda_max(subproblems%flexibility(a), bodies(a)%flex, nmv(a))
    end do
    !$omp end parallel do
    if (.not. resumed) state%inner = sum(nmv)
    subproblems%lmax_hessian = subproblems%lmax_body
    do a = 1, 2
      subproblems%hessian(a) = subproblems%flexibility(a)
      subproblems%proximal(a)%n = 0
      if (.not. bodies(a)%prox > 0.0_wp) cycle
      allocate (p(m, m))
      call robin_op%proximal_term(bodies, a, p)
      call dense_op_init(subproblems%proximal(a), p)
      subproblems%hessian(a)%a = subproblems%hessian(a)%a + p
      ! lambda_max(F_a + Pi_a) <= lambda_max(F_a) + |Pi_a|_inf
      subproblems%lmax_hessian(a) = subproblems%lmax_body(a) + maxval(sum(abs(p), dim=1))
      deallocate (p)
    end do
    do a = 1, 2
      if (bodies(a)%nrig == 0 .or. m == 0) cycle
      call equality_init(subproblems%equality(a), bodies(a)%rg, bodies(a)%re, subproblems%lmax_hessian(a))
      call equality_add_penalty(subproblems%equality(a), subproblems%hessian(a), subproblems%lmax_hessian(a))
    end do
  end subroutine subproblems_init

  !> Both bodies' subproblems at outer iteration `it` to the inner tolerance rtol_in. On
  !! return state%lam holds the forces, w(:, a) = B_a u_a, and res%status is STATUS_FAILED if
  !! an inner solve broke down.
  subroutine solve_subproblems(subproblems, solver, bodies, rtol_in, it, state, w, res)
    type(subproblems_t), intent(inout) :: subproblems   !< the subproblems
    type(solver_cfg_t), intent(in) :: solver            !< solver settings
    type(body_condensed_t), intent(in) :: bodies(2)     !< condensed bodies
    real(wp), intent(in) :: rtol_in                     !< inner tolerance
    integer, intent(in) :: it                           !< outer iteration
    type(robin_state_t), intent(inout) :: state         !< outer state
    real(wp), intent(out) :: w(:, :)                    !< (m, 2) B_a u_a
    type(contact_result_t), intent(inout) :: res        !< status, counts
    type(mprgp_stats_t) :: inner(2)
    integer :: updates(2)
    real(wp), allocatable :: rhs(:, :), grad(:, :), lam_last(:, :), flam(:, :)
    integer :: a, m
    logical :: search
    m = size(w, 1)
    allocate (rhs(m, 2), grad(m, 2), flam(m, 2))
    lam_last = state%lam   ! the other body's last force, for a proximal term
    ! A first line search along the last change of lam_a only while the outer iteration
    ! contracts at a steady rate (then the changes of lam_a are nearly parallel from one
    ! iteration to the next); not in the transient, where the outcome of the outer iteration
    ! depends on the inner iterates (doc/method.md, "Method as implemented").
    search = state%nsrch == 1 .and. smooth_outer(res, it)
    !$omp parallel do num_threads(body_threads()) schedule(static, 1) if (m > 64)
    do a = 1, 2
      call solve_body(subproblems, solver, bodies(a), a, rtol_in, search, lam_last(:, other_body(a)), state, &
                      rhs(:, a), grad(:, a), inner(a), updates(a))
    end do
    !$omp end parallel do
    if (m == 0) return
    do a = 1, 2
      state%inner = state%inner + inner(a)%n_matvec
      res%eq_updates = res%eq_updates + updates(a)
      if (inner(a)%status == MPRGP_MAX_IT) then
        res%inner_maxit_hits = res%inner_maxit_hits + 1
      else if (inner(a)%status /= MPRGP_CONVERGED) then
        res%status = STATUS_FAILED
        write (res%message, '(a,i0,a,i0,a)') 'MPRGP failed on body ', a, ' at outer iteration ', it, &
          ': '//trim(mprgp_status_name(inner(a)%status))//': '//trim(inner(a)%message)
        return
      end if
      ! B_a u_a = b_a - F_a lam_a = G_a - grad_a (with a proximal term: F_a lam_a is the
      ! Hessian's image grad_a + rhs_a less the proximal part)
      if (subproblems%proximal(a)%n > 0) then
        call subproblems%proximal(a)%apply(state%lam(:, a), flam(:, a))
        flam(:, a) = grad(:, a) + rhs(:, a) - flam(:, a)
        w(:, a) = bodies(a)%b - flam(:, a)
        state%flam(a) = norm2(flam(:, a))
      else
        w(:, a) = state%G(:, a) - grad(:, a)
        state%flam(a) = norm2(grad(:, a) + rhs(:, a))
      end if
    end do
    state%nsrch = state%reuse
    state%reuse = 1
  end subroutine solve_subproblems

  !> Body a's subproblem: MPRGP (SMALBE-M for a floating body), warm-started from
  !! state%lam(:, a) with its known product F_a lam_a, optionally a first line search along
  !! the last change of lam_a, and the Krylov recycling of its stored directions.
  subroutine solve_body(subproblems, solver, body, a, rtol_in, search, lam_other, state, rhs, grad, inner, updates)
    type(subproblems_t), intent(inout) :: subproblems
    type(solver_cfg_t), intent(in) :: solver
    type(body_condensed_t), intent(in) :: body
    integer, intent(in) :: a
    real(wp), intent(in) :: rtol_in
    logical, intent(in) :: search                 !< line search along state%srch(:, a) first
    real(wp), intent(in) :: lam_other(:)          !< the other body's last force (proximal term)
    type(robin_state_t), intent(inout) :: state
    real(wp), intent(out) :: rhs(:)               !< b_a - G_a (+ Pi_a lam_o)
    real(wp), intent(out) :: grad(:)              !< the Hessian's gradient at the solution
    type(mprgp_stats_t), intent(out) :: inner     !< the inner solve's outcome
    integer, intent(out) :: updates               !< SMALBE multiplier updates
    type(mprgp_t) :: inner_solver
    type(smalbe_stats_t) :: smalbe_stats
    real(wp), allocatable :: lb(:), lam0(:), flam0(:)
    integer :: m, k, r, first, last
    m = size(rhs)
    allocate (lb(m))
    lb = 0.0_wp
    rhs = body%b - state%G(:, a)
    if (subproblems%proximal(a)%n > 0) then
      ! a singular body is pinned to the other body's last force
      call subproblems%proximal(a)%apply(lam_other, grad)
      rhs = rhs + grad
    end if
    ! The tolerance is measured against the body's own contact displacement |F_a lam_a|
    ! (previous iterate), not against |b_a - G_a|: with a large material contrast the stiff
    ! body's b_a - G_a is a small difference of the soft body's large displacements.
    if (state%flam(a) > 0.0_wp) then
      inner_solver%opts%rtol = 0.0_wp
      inner_solver%opts%atol = max(rtol_in*state%flam(a), 4.0_wp*epsilon(1.0_wp)*norm2(rhs))
    else
      inner_solver%opts%rtol = rtol_in
      inner_solver%opts%atol = 0.0_wp
    end if
    inner_solver%opts%max_it = solver%inner_max_it
    inner_solver%opts%lambda_max = subproblems%lmax_hessian(a)
    ! F_a is the same in every iteration and the warm start is the last solution: its
    ! gradient comes from F_a lam_a of the last solve (no initial product)
    inner_solver%opts%use_ax = state%reuse == 1
    inner_solver%ax = state%flam_v(:, a)
    lam0 = state%lam(:, a)
    flam0 = state%flam_v(:, a)
    ! Krylov recycling, not with Aitken or Anderson acceleration, whose updates difference
    ! past iterates and so amplify the (smaller but differently placed) inner errors
    inner_solver%opts%recycle = solver%acceleration == ACCEL_NONE
    if (search) then
      inner_solver%s = state%srch(:, a)
      inner_solver%as = state%fsrch(:, a)
    end if
    ! body a's columns of the stored directions
    k = size(state%rw, 2)/2
    first = (a - 1)*k + 1
    last = a*k
    r = subproblems%equality(a)%r
    updates = 0
    if (m > 0 .and. r > 0) then
      ! a floating body: its equilibrium to the accuracy asked of its forces, down to the
      ! rounding of G lam
      associate (eq => subproblems%equality(a))
        inner_solver%opts%eq_m = eq%m0
        inner_solver%opts%eq_feas = max(rtol_in, 10.0_wp*sqrt(real(m, wp))*epsilon(1.0_wp), FEAS_RTOL_MIN)*norm2(eq%e)
        inner_solver%opts%eq_feas_x = merge(max(rtol_in, 10.0_wp*sqrt(real(m, wp))*epsilon(1.0_wp), FEAS_RTOL_MIN)*sqrt(eq%gg), &
                                            0.0_wp, all(eq%e == 0.0_wp))
        call smalbe_solve(inner_solver, subproblems%hessian(a), rhs, eq%g, eq%e, eq%rho, lb, state%lam(:, a), state%mu(1:r, a), &
                          smalbe_stats, state%rw(:, first:last), state%raw(:, first:last), state%nrw(:, a))
      end associate
      inner = smalbe_stats%inner
      inner%n_matvec = smalbe_stats%n_matvec
      updates = smalbe_stats%updates
    else if (m > 0) then
      call inner_solver%solve(subproblems%hessian(a), rhs, lb, state%lam(:, a), state%rw(:, first:last), &
                       state%raw(:, first:last), state%nrw(:, a))
      inner = inner_solver%stats
    end if
    if (m > 0) then
      grad = inner_solver%g
      state%flam_v(:, a) = inner_solver%ax
    end if
    state%srch(:, a) = state%lam(:, a) - lam0
    state%fsrch(:, a) = state%flam_v(:, a) - flam0
  end subroutine solve_body

  !> True when the outer criterion decreased over the last three iterations at a steady
  !! rate (the two last ratios differ by at most SMOOTH_RATE_TOL).
  logical function smooth_outer(res, it) result(ok)
    type(contact_result_t), intent(in) :: res
    integer, intent(in) :: it
    real(wp) :: c1, c2, c3
    ok = .false.
    if (it <= 3 .or. res%nhist < it - 1) return
    c1 = res%h_criterion(it - 1)
    c2 = res%h_criterion(it - 2)
    c3 = res%h_criterion(it - 3)
    if (.not. (c1 < c2 .and. c2 < c3)) return
    ok = abs(c1/c2 - c2/c3) <= SMOOTH_RATE_TOL
  end function smooth_outer

end module robin_subproblems
