!> Step 1 of the Robin iteration: each body's contact problem against its obstacles on all
!! its contact rows, min 1/2 l'(F_a + Pi_a) l - l'(b_a - G_a + Pi_a lam_o), l >= 0 (MPRGP;
!! SMALBE-M with the body's equilibrium as an equality when it is held only by contact), the
!! bodies on the threads (largest first), warm-started from the last contact forces
!! (doc/method.md, "Method as implemented"). Each body takes its own vectors out of the
!! side-layout state (`gather`) and puts them back (`scatter`). The Hessians and their
!! bounds are built once, before the outer loop.
module robin_subproblems
  use kinds, only: wp
  use lapack, only: tiles_begin, tiles_end
  use iso_c_binding, only: c_long
  use config, only: solver_cfg_t, ACCEL_NONE, INNER_MPRGP, INNER_ACTIVE_SET, INNER_AUTO
  use linop, only: dense_op_t, dense_op_init
  use mprgp, only: mprgp_t, mprgp_stats_t, MPRGP_CONVERGED, MPRGP_MAX_IT, mprgp_status_name, QP_AUTO, QP_MPRGP, &
                   QP_NEWTON, QP_NEWTON_FIRST, QP_POLISH
  use smalbe, only: smalbe_solve, smalbe_solve_in, smalbe_stats_t
  use constraint_set, only: constraint_set_t
  use tangent_discs, only: friction_set
  use qp_newton, only: newton_work_t, newton_factor, newton_forget, newton_holds
  use disc_newton, only: disc_factor_t
  use condense, only: body_condensed_t
  use contact_types, only: contact_result_t, robin_state_t, STATUS_FAILED, recycle_size, BOUND_UPPER, BOUND_LOWER
  use contact_common, only: gather, scatter, body_threads, partner_slots
  use sorting, only: largest_first
  use equality_rows, only: equality_t, equality_init, equality_add_penalty
  use robin_operators, only: robin_operator_t
  use contact_interface, only: interface_t, slot_row, slot_side, disc_positions
  implicit none (type, external)
  private

  real(wp), parameter :: SMOOTH_RATE_TOL = 0.1_wp   !< rate change below which the outer iteration counts as smooth
  real(wp), parameter :: FEAS_RTOL_MIN = 1.0e-15_wp !< equilibrium of a floating body: max(inner tolerance, rounding, this) |e|
  !> the most Newton steps a solve of inner_solver 'auto' tries before MPRGP when the body's
  !! last solve suggests starting with the Newton method
  integer, parameter :: NEWTON_FIRST_MAX = 64
  !> a Newton step on an updated factor, in products: one product and two triangular solves
  real(wp), parameter :: UPDATED_STEP_COST = 2.0_wp
  !> QP_POLISH: the tolerance of its MPRGP phase, relative to the body's contact displacement
  real(wp), parameter :: POLISH_RTOL = 1.0e-4_wp

  !> The bodies' subproblems as the outer loop solves them (one entry per body).
  type, public :: subproblems_t
    type(dense_op_t), allocatable :: flexibility(:)   !< F_a
    type(dense_op_t), allocatable :: hessian(:)       !< F_a + Pi_a (+ rho G_a'G_a for a floating body)
    type(dense_op_t), allocatable :: proximal(:)      !< Pi_a (n = 0 when F_a is nonsingular)
    type(equality_t), allocatable :: equality(:)      !< equilibrium rows of a floating body (r = 0: none)
    real(wp), allocatable :: lmax_body(:)             !< bounds of lambda_max(F_a) [length/force]
    real(wp), allocatable :: lmax_hessian(:)          !< bounds of lambda_max of the Hessians [length/force]
    integer, allocatable :: order(:)                  !< the bodies, largest first (the threads' order)
    !> with friction: the bounds of the forces on every row (row_bounds), set by the outer
    !! loop (Coulomb: from the last iterate); not allocated: l >= 0 on every row
    real(wp), allocatable :: lb(:), ub(:)
    !> each body's Newton work from one solve to the next (a body held by its supports: its
    !! Hessian does not change, and a free set that recurs keeps its factor)
    type(newton_work_t), allocatable :: newton_work(:)
    !> friction in space: each body's discs (its rows' positions of a node's two tangential
    !! forces, contact_interface's disc_positions); none in the plane
    type(disc_list_t), allocatable :: discs(:)
    !> friction in space: each body's Hessian on the rows its last Newton solve left free to
    !! move (not held at 0 by a disc of radius 0: Coulomb on a node without normal force)
    type(reduced_t), allocatable :: reduced(:)
    !> friction in space: each body's factor of the Newton method on its discs, carried from
    !! one solve to the next while its Hessian (reduced) stays; a solve takes it only as a
    !! new factorization would make it (disc_newton's disc_factor_t%carried), so the solves
    !! do bit for bit what they would without it, and a resumed run, which has none yet, too
    type(disc_factor_t), allocatable :: disc_work(:)
  end type subproblems_t

  !> A body's Hessian on some of its rows.
  type :: reduced_t
    integer, allocatable :: rows(:)       !< the rows (increasing); not allocated: none yet
    type(dense_op_t) :: op                !< the Hessian on them
  end type reduced_t

  !> The discs of one body's rows.
  type :: disc_list_t
    integer, allocatable :: pos(:, :)     !< (2, discs) positions in the body's rows
  end type disc_list_t

  !> A vector per body.
  type :: vec_t
    real(wp), allocatable :: v(:)
  end type vec_t

  public :: subproblems_init, solve_subproblems

contains

  !> Each body's F_a, its bound of lambda_max (robin_op%body_lambda_max; its products are
  !! counted in state%inner unless the run resumes), and the subproblem Hessian: F_a + Pi_a,
  !! Pi_a = 0 unless F_a is singular (module condense: a mortar master coarser than the
  !! slave), then the proximal term 1/2 (l - lam_o)' Pi_a (l - lam_o), lam_o the partners'
  !! last contact forces on the same rows, fixes the part of lam_a that body a's own problem leaves
  !! undetermined; the fixed point stays the monolithic solution for every Pi_a >= 0
  !! (doc/method.md, "Non-matching and curved contact surfaces: dual mortar"). A floating
  !! body's Hessian carries the penalty of its equilibrium rows.
  subroutine subproblems_init(subproblems, contact_line, bodies, robin_op, state, resumed)
    type(subproblems_t), intent(out) :: subproblems     !< the subproblems
    type(interface_t), intent(in) :: contact_line       !< contact rows of all pairs
    type(body_condensed_t), intent(in) :: bodies(:)     !< condensed bodies
    class(robin_operator_t), intent(in) :: robin_op     !< the Robin operator
    type(robin_state_t), intent(inout) :: state         !< outer state (inner count)
    logical, intent(in) :: resumed                      !< the run resumes from a checkpoint
    real(wp), allocatable :: p(:, :)
    integer, allocatable :: nmv(:)
    integer :: a, k, n, m
    integer(c_long) :: ntiles
    n = size(bodies)
    allocate (subproblems%flexibility(n), subproblems%hessian(n), subproblems%proximal(n), subproblems%equality(n))
    allocate (subproblems%lmax_body(n), subproblems%lmax_hessian(n), nmv(n), subproblems%newton_work(n))
    allocate (subproblems%discs(n), subproblems%reduced(n), subproblems%disc_work(n))
    do a = 1, n
      subproblems%discs(a)%pos = disc_positions(contact_line, slot_row(bodies(a)%slots, contact_line%m))
    end do
    subproblems%lmax_body = 0.0_wp
    ! largest first: the dynamic schedule then balances the threads
    subproblems%order = largest_first([(bodies(a)%m, a=1, size(bodies))])
    nmv = 0
    ! every body's part on the threads: F_a, its bound, its Hessian (a copy of F_a, the
    ! proximal term, the penalty of its equilibrium rows)
    !$omp parallel do num_threads(body_threads()) schedule(dynamic, 1) private(a, m, p, ntiles) if (contact_line%m > 64)
    do k = 1, n
      a = subproblems%order(k)
      m = bodies(a)%m
      call dense_op_init(subproblems%flexibility(a), bodies(a)%flex)
      if (m > 0) subproblems%lmax_body(a) = robin_op%body_lambda_max(subproblems%flexibility(a), bodies(a)%flex, &
                                                                     nmv(a))
      subproblems%lmax_hessian(a) = subproblems%lmax_body(a)
      subproblems%hessian(a) = subproblems%flexibility(a)
      subproblems%proximal(a)%n = 0
      if (bodies(a)%prox > 0.0_wp) then
        allocate (p(m, m))
        ! as tiles: a body without one (its copies done) lends its thread
        call tiles_begin()
        call robin_op%proximal_term(contact_line, bodies, a, p)
        ntiles = tiles_end()
        call dense_op_init(subproblems%proximal(a), p)
        subproblems%hessian(a)%a = subproblems%hessian(a)%a + p
        ! lambda_max(F_a + Pi_a) <= lambda_max(F_a) + |Pi_a|_inf
        subproblems%lmax_hessian(a) = subproblems%lmax_body(a) + maxval(sum(abs(p), dim=1))
        deallocate (p)
      end if
      if (bodies(a)%nrig > 0 .and. m > 0) then
        call equality_init(subproblems%equality(a), bodies(a)%rg, bodies(a)%re, subproblems%lmax_hessian(a))
        call equality_add_penalty(subproblems%equality(a), subproblems%hessian(a), subproblems%lmax_hessian(a))
      end if
    end do
    !$omp end parallel do
    if (.not. resumed) state%inner = sum(nmv)
  end subroutine subproblems_init

  !> Every body's subproblem at outer iteration `it` to the inner tolerance rtol_in. On
  !! return state%lam holds the forces, w = B u of each side (side layout), and res%status
  !! is STATUS_FAILED if an inner solve broke down.
  subroutine solve_subproblems(subproblems, solver, bodies, rtol_in, it, state, w, res)
    type(subproblems_t), intent(inout) :: subproblems   !< the subproblems
    type(solver_cfg_t), intent(in) :: solver            !< solver settings
    type(body_condensed_t), intent(in) :: bodies(:)     !< condensed bodies
    real(wp), intent(in) :: rtol_in                     !< inner tolerance
    integer, intent(in) :: it                           !< outer iteration
    type(robin_state_t), intent(inout) :: state         !< outer state
    real(wp), intent(out) :: w(:, :)                    !< (m, 2) B u of each side
    type(contact_result_t), intent(inout) :: res        !< status, counts
    type(mprgp_stats_t), allocatable :: inner(:)
    integer, allocatable :: updates(:)
    type(vec_t), allocatable :: rhs(:), grad(:)
    real(wp), allocatable :: lam_last(:, :), flam(:)
    integer :: a, k, n, m
    logical :: search
    m = size(w, 1)
    n = size(bodies)
    allocate (rhs(n), grad(n), inner(n), updates(n))
    lam_last = state%lam   ! the partners' last forces, for a proximal term
    ! A first line search along the last change of lam_a only while the outer iteration
    ! contracts at a steady rate (then the changes of lam_a are nearly parallel from one
    ! iteration to the next); not in the transient, where the outcome of the outer iteration
    ! depends on the inner iterates (doc/method.md, "Method as implemented").
    search = state%nsrch == 1 .and. smooth_outer(res, it)
    !$omp parallel do num_threads(body_threads()) schedule(dynamic, 1) private(a) if (m > 64)
    do k = 1, n
      a = subproblems%order(k)
      allocate (rhs(a)%v(bodies(a)%m), grad(a)%v(bodies(a)%m))
      call solve_body(subproblems, solver, bodies(a), a, rtol_in, search, &
                      gather(lam_last, partner_slots(bodies(a)%slots, m)), state, rhs(a)%v, grad(a)%v, inner(a), &
                      updates(a))
    end do
    !$omp end parallel do
    if (m == 0) return
    do a = 1, n
      state%inner = state%inner + inner(a)%n_matvec
      res%eq_updates = res%eq_updates + updates(a)
      if (bodies(a)%m == 0) cycle
      if (inner(a)%status == MPRGP_MAX_IT) then
        res%inner_maxit_hits = res%inner_maxit_hits + 1
      else if (inner(a)%status /= MPRGP_CONVERGED) then
        res%status = STATUS_FAILED
        write (res%message, '(a,i0,a,i0,a)') 'MPRGP failed on body ', a, ' at outer iteration ', it, &
          ': '//trim(mprgp_status_name(inner(a)%status))//': '//trim(inner(a)%message)
        return
      end if
    end do
    do a = 1, n
      if (bodies(a)%m == 0) cycle
      ! B_a u_a = b_a - F_a lam_a = G_a - grad_a (with a proximal term: F_a lam_a is the
      ! Hessian's image grad_a + rhs_a less the proximal part)
      if (subproblems%proximal(a)%n > 0) then
        allocate (flam(bodies(a)%m))
        call subproblems%proximal(a)%apply(gather(state%lam, bodies(a)%slots), flam)
        flam = grad(a)%v + rhs(a)%v - flam
        call scatter(bodies(a)%b - flam, bodies(a)%slots, w)
        state%flam(a) = norm2(flam)
        deallocate (flam)
      else
        call scatter(gather(state%G, bodies(a)%slots) - grad(a)%v, bodies(a)%slots, w)
        state%flam(a) = norm2(grad(a)%v + rhs(a)%v)
      end if
    end do
    state%nsrch = state%reuse
    state%reuse = 1
  end subroutine solve_subproblems

  !> Body a's subproblem: MPRGP (SMALBE-M for a floating body), warm-started from its
  !! last force with its known product F_a lam_a, optionally a first line search along the
  !! last change of lam_a, and the Krylov recycling of its stored directions; its vectors
  !! are taken out of the side-layout state and put back.
  subroutine solve_body(subproblems, solver, cbody, a, rtol_in, search, lam_other, state, rhs, grad, inner, updates)
    type(subproblems_t), target, intent(inout) :: subproblems
    type(solver_cfg_t), intent(in) :: solver
    type(body_condensed_t), intent(in) :: cbody
    integer, intent(in) :: a
    real(wp), intent(in) :: rtol_in
    logical, intent(in) :: search                 !< line search along the last change of lam_a first
    real(wp), intent(in) :: lam_other(:)          !< the partners' last forces on the same rows (proximal term)
    type(robin_state_t), intent(inout) :: state
    real(wp), intent(out) :: rhs(:)               !< b_a - G_a (+ Pi_a lam_o)
    real(wp), intent(out) :: grad(:)              !< the Hessian's gradient at the solution
    type(mprgp_stats_t), intent(out) :: inner     !< the inner solve's outcome
    integer, intent(out) :: updates               !< SMALBE multiplier updates
    type(mprgp_t) :: inner_solver
    type(smalbe_stats_t) :: smalbe_stats
    class(constraint_set_t), allocatable :: set
    real(wp), allocatable :: lb(:), ub(:), lam(:), lam0(:), flam0(:), rw(:, :), raw(:, :)
    integer :: m, k, ka, r, mm, nfree, changed, i, steps
    integer, allocatable :: last(:)
    logical :: moved, definite
    real(wp) :: cost, flops
    m = size(rhs)
    mm = size(state%G, 1)
    updates = 0
    if (m == 0) return
    if (allocated(subproblems%lb)) then
      lb = subproblems%lb(slot_row(cbody%slots, mm))
      ub = subproblems%ub(slot_row(cbody%slots, mm))
    else
      allocate (lb(m), ub(0))
      lb = 0.0_wp
    end if
    ! the box of the forces, with a disc on each node's tangential pair in space
    if (size(ub) > 0) then
      set = friction_set(lb, ub, subproblems%discs(a)%pos)
    else
      set = friction_set(lb, [(huge(1.0_wp), i=1, m)], subproblems%discs(a)%pos)
    end if
    rhs = cbody%b - gather(state%G, cbody%slots)
    if (subproblems%proximal(a)%n > 0) then
      ! a singular body is pinned to its partners' last forces
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
    inner_solver%opts%method = inner_method(solver%inner_solver, state%newton(a))
    ! friction in space under 'auto', a body held by its supports: the Newton method on the
    ! discs once the body has forces, on the rows not held at 0 (solve_reduced). From a warm
    ! start its steps move a few discs at a time on row updates of one factor a solve, where
    ! MPGP's expansions along the circles took hundreds of products a solve while the stick
    ! and slip sets still moved (doc/performance.md, the 3D Hertz pair with friction). The
    ! first solve (no forces yet; Coulomb's first bounds are unbounded, every row free) by
    ! 'auto' as before.
    if (solver%inner_solver == INNER_AUTO .and. size(subproblems%discs(a)%pos) > 0 .and. &
        subproblems%equality(a)%r == 0) then
      if (any(gather(state%lam, cbody%slots) /= 0.0_wp)) inner_solver%opts%method = QP_NEWTON
    end if
    inner_solver%opts%newton_budget = max(1, state%newton(a) - 1, -state%newton(a))
    inner_solver%opts%polish_scale = max(1.0_wp, POLISH_RTOL/max(rtol_in, tiny(1.0_wp)))
    inner_solver%opts%lambda_max = subproblems%lmax_hessian(a)
    ! F_a is the same in every iteration and the warm start is the last solution: its
    ! gradient comes from F_a lam_a of the last solve (no initial product)
    inner_solver%opts%use_ax = state%reuse == 1
    inner_solver%ax = gather(state%flam_v, cbody%slots)
    lam0 = gather(state%lam, cbody%slots)
    lam = lam0
    flam0 = inner_solver%ax
    ! Coulomb: the box moved with the normal forces; a warm start outside it is projected
    ! and its product is no longer known
    moved = .false.
    if (size(ub) > 0) then
      ! in space, a disc whose force was on its last circle starts on its new one (Coulomb's
      ! radius moved with lam_n): the face it slid on stays its face, and the active-set
      ! method need not find its slipping discs again one per step
      ! (and a tangential force alone on its node, a box, on its last bound starts on its new
      ! one: a node on a plane of symmetry)
      if (size(subproblems%discs(a)%pos) > 0) then
        last = last_bound(state%row_state, cbody%slots, mm)
        call onto_new_circles(subproblems%discs(a)%pos, last == BOUND_UPPER, ub, lam)
        call onto_new_bounds(subproblems%discs(a)%pos, last, lb, ub, lam)
      end if
      call set%project(lam)
      moved = any(lam /= lam0)
      if (moved) inner_solver%opts%use_ax = .false.
    end if
    ! Krylov recycling, not with Aitken or Anderson acceleration, whose updates difference
    ! past iterates and so amplify the (smaller but differently placed) inner errors
    inner_solver%opts%recycle = solver%acceleration == ACCEL_NONE
    if (search .and. .not. moved) then
      inner_solver%s = gather(state%srch, cbody%slots)
      inner_solver%as = gather(state%fsrch, cbody%slots)
    end if
    ! the body's stored directions: column j on its side-1 rows, k + j on its side-2 rows;
    ! none without recycling (they are only stored then, never used: a quarter of the time)
    k = size(state%rw, 2)/2
    ka = min(k, recycle_size(m))
    if (.not. inner_solver%opts%recycle) ka = 0
    allocate (rw(m, ka), raw(m, ka))
    call directions_out(state%rw, rw)
    call directions_out(state%raw, raw)
    r = subproblems%equality(a)%r
    if (r > 0) then
      ! a floating body: its equilibrium to the accuracy asked of its forces, down to the
      ! rounding of G lam
      associate (eq => subproblems%equality(a))
        inner_solver%opts%eq_m = eq%m0
        inner_solver%opts%eq_feas = max(rtol_in, 10.0_wp*sqrt(real(m, wp))*epsilon(1.0_wp), FEAS_RTOL_MIN)*norm2(eq%e)
        inner_solver%opts%eq_feas_x = merge(max(rtol_in, 10.0_wp*sqrt(real(m, wp))*epsilon(1.0_wp), FEAS_RTOL_MIN)* &
                                            sqrt(eq%gg), 0.0_wp, all(eq%e == 0.0_wp))
        call smalbe_solve_in(inner_solver, subproblems%hessian(a), rhs, eq%g, eq%e, eq%rho, set, lam, state%eq_mult(1:r, a), &
                             smalbe_stats, rw, raw, state%nrw(:, a))
      end associate
      inner = smalbe_stats%inner
      inner%n_matvec = smalbe_stats%n_matvec
      inner%switched = smalbe_stats%switched
      updates = smalbe_stats%updates
    else
      ! the active-set method's factor from the body's last solve (frictionless: the free
      ! rows are those of the last forces); a resumed run makes it again, not counted
      inner_solver%keep => subproblems%newton_work(a)
      inner_solver%keep_same_a = .true.
      if (state%kept(a) == 1 .and. subproblems%newton_work(a)%fac_nf < 0 .and. size(ub) == 0) then
        flops = 0.0_wp
        call newton_factor(subproblems%hessian(a)%a, pack([(i, i=1, m)], lam0 > lb), subproblems%newton_work(a), &
                           definite, flops)
      end if
      if (inner_solver%opts%method == QP_NEWTON .and. size(subproblems%discs(a)%pos) > 0 .and. size(ub) > 0) then
        call solve_reduced()
      else
        call inner_solver%solve_in(subproblems%hessian(a), rhs, set, lam, rw, raw, state%nrw(:, a))
      end if
      inner = inner_solver%stats
    end if
    ! the factor is carried into the next solve when it is the one LAPACK makes of the free
    ! block of these forces (what a resumed run can make again), else dropped
    if (r == 0) then
      state%kept(a) = 0
      if (size(ub) == 0) then
        if (newton_holds(subproblems%newton_work(a), pack([(i, i=1, m)], lam > lb))) state%kept(a) = 1
      end if
      if (state%kept(a) == 0) call newton_forget(subproblems%newton_work(a))
    end if
    ! F_a does not change: a body whose QP needed the Newton method polishes its later solves
    ! (a frictionless body held by its supports, under 'auto': MPRGP to a loose tolerance, then
    ! the Newton method, the active-set method first once its set settles) or starts with the
    ! Newton method from now on (any other)
    if (inner%switched) state%newton(a) = merge(-NEWTON_FIRST_MAX, 1, r == 0 .and. size(ub) == 0 .and. &
                                                solver%inner_solver == INNER_AUTO)
    ! 'auto' on a body held by its supports: when a solve that MPRGP finished cost more than
    ! two steps of the Newton method with a new factor, the next solve takes the Newton method
    ! within half that solve's work: first (from the warm start: one step while the set stays,
    ! steps on an updated factor while it moves a little) when the solve changed at most a
    ! twelfth of the body's free rows between free and bound, else after MPRGP to a loose
    ! tolerance (QP_POLISH: MPRGP finds where the set moved, the Newton method ends on it);
    ! then 'auto' from where it stopped. A solve that had to fall back returns the body to
    ! MPRGP first; a polished solve that did not goes on with the Newton method first once
    ! its set settles
    if (solver%inner_solver == INNER_AUTO .and. r == 0 .and. state%newton(a) /= 1 .and. &
        inner%status == MPRGP_CONVERGED .and. (state%newton(a) <= 0 .or. inner%fell_back)) then
      if (size(ub) > 0) then
        nfree = count(lam > lb .and. lam < ub)
        changed = count((lam > lb) .neqv. (lam0 > lb)) + count((lam < ub) .neqv. (lam0 < ub))
      else
        nfree = count(lam > lb)
        changed = count((lam > lb) .neqv. (lam0 > lb))
      end if
      if (state%newton(a) < 0 .and. .not. inner%fell_back) then
        if (12*changed <= nfree) state%newton(a) = 1 - state%newton(a)
      else
        state%newton(a) = 0
        cost = newton_step_cost(m, nfree)
        if (.not. inner%fell_back .and. real(inner%n_matvec, wp) > 2.0_wp*cost) then
          steps = max(2, min(NEWTON_FIRST_MAX, 1 + int((0.5_wp*real(inner%n_matvec, wp) - cost)/UPDATED_STEP_COST)))
          state%newton(a) = merge(1 + steps, -steps, 12*changed <= nfree)
        end if
      end if
    end if
    grad = inner_solver%g
    call scatter(lam, cbody%slots, state%lam)
    call scatter(inner_solver%ax, cbody%slots, state%flam_v)
    call scatter(lam - lam0, cbody%slots, state%srch)
    call scatter(inner_solver%ax - flam0, cbody%slots, state%fsrch)
    call directions_in(rw, state%rw)
    call directions_in(raw, state%raw)

  contains

    !> The Newton method on the discs without the rows a disc of radius 0 holds at 0 (both
    !! its forces; Coulomb on a node without normal force: most of a large candidate
    !! surface), whose columns add nothing to a product and whose rows need no gradient
    !! until the end: on p of the m rows a product costs (p/m)^2 of one on all, and so does
    !! every step's work outside the face's factor. The reduced Hessian is kept while the
    !! rows stay (a copy of F_a's entries: the same values on a resumed run). A x on every
    !! row at the end from the columns of the nonzero forces. inner%n_matvec counts
    !! products on all m rows. The solve starts from the face of the warm start (the last
    !! answer, its forces on their new circles and bounds: hold_boundary), whose factor the
    !! last solve left (disc_work): once the stick and slip sets settle, a solve is one
    !! Newton step on a factor it does not make.
    subroutine solve_reduced()
      integer, allocatable :: idx(:), map(:), pr(:, :)
      real(wp), allocatable :: xr(:), axf(:)
      class(constraint_set_t), allocatable :: rset
      integer :: p, j, q
      idx = pack([(i, i=1, m)], .not. (lb == 0.0_wp .and. ub == 0.0_wp))
      p = size(idx)
      ! hardly any row held at 0: all rows (a factor carried from a reduced solve has another
      ! size, and the solve drops it)
      inner_solver%keep_disc => subproblems%disc_work(a)
      inner_solver%hold_boundary = .true.
      if (16*p > 15*m) then
        call inner_solver%solve_in(subproblems%hessian(a), rhs, set, lam, rw, raw, state%nrw(:, a))
        return
      end if
      associate (red => subproblems%reduced(a))
        if (allocated(red%rows)) then
          if (size(red%rows) /= p) deallocate (red%rows)
        end if
        if (allocated(red%rows)) then
          if (any(red%rows /= idx)) deallocate (red%rows)
        end if
        if (.not. allocated(red%rows)) then
          red%rows = idx
          call dense_op_init(red%op, subproblems%hessian(a)%a(idx, idx))
          ! another Hessian: the carried factor's positions mean other rows
          subproblems%disc_work(a)%valid = .false.
        end if
      end associate
      allocate (map(m), source=0)
      map(idx) = [(j, j=1, p)]
      ! a disc's two rows share their bound: kept or left out together
      associate (pos => subproblems%discs(a)%pos)
        pr = reshape([(map(pos(:, q)), q=1, size(pos, 2))], [2, size(pos, 2)])
        pr = pr(:, pack([(q, q=1, size(pos, 2))], pr(1, :) > 0))
      end associate
      rset = friction_set(lb(idx), ub(idx), pr)
      xr = lam(idx)
      if (inner_solver%opts%use_ax) inner_solver%ax = inner_solver%ax(idx)
      if (allocated(inner_solver%s)) then
        if (all(inner_solver%s(pack([(i, i=1, m)], map == 0)) == 0.0_wp)) then
          inner_solver%s = inner_solver%s(idx)
          inner_solver%as = inner_solver%as(idx)
        else
          deallocate (inner_solver%s, inner_solver%as)
        end if
      end if
      call inner_solver%solve_in(subproblems%reduced(a)%op, rhs(idx), rset, xr)
      lam = 0.0_wp
      lam(idx) = xr
      allocate (axf(m), source=0.0_wp)
      do j = 1, p
        if (xr(j) /= 0.0_wp) axf = axf + subproblems%hessian(a)%a(:, idx(j))*xr(j)
      end do
      inner_solver%ax = axf
      inner_solver%g = axf - rhs
      inner_solver%stats%n_matvec = nint(real(inner_solver%stats%n_matvec, wp)*(real(p, wp)/real(m, wp))**2 + &
                                         real(count(xr /= 0.0_wp), wp)/real(m, wp))
    end subroutine solve_reduced

    !> The body's directions out of the side layout (column by column: each a contiguous
    !! column of `all` read at the body's rows).
    subroutine directions_out(all, mine)
      real(wp), intent(in) :: all(:, :)
      real(wp), intent(out) :: mine(:, :)
      integer :: i, j, row(m), off(m)
      row = slot_row(cbody%slots, mm)
      off = (slot_side(cbody%slots, mm) - 1)*k
      do j = 1, ka
        do i = 1, m
          mine(i, j) = all(row(i), off(i) + j)
        end do
      end do
    end subroutine directions_out

    !> The body's directions back into the side layout.
    subroutine directions_in(mine, all)
      real(wp), intent(in) :: mine(:, :)
      real(wp), intent(inout) :: all(:, :)
      integer :: i, j, row(m), off(m)
      row = slot_row(cbody%slots, mm)
      off = (slot_side(cbody%slots, mm) - 1)*k
      do j = 1, ka
        do i = 1, m
          all(row(i), off(i) + j) = mine(i, j)
        end do
      end do
    end subroutine directions_in

  end subroutine solve_body

  !> Each contact row's bound state in the last iterate on the body's side (BOUND_*; 0: not
  !! known yet; in space BOUND_UPPER for a disc's force on its circle), from the rows' states
  !! (robin_state_t%row_state, checkpointed: a resumed run decides alike).
  pure function last_bound(row_state, slots, m) result(code)
    integer, intent(in) :: row_state(:)       !< (m) side 1's state + 4 x side 2's (-1: none yet)
    integer, intent(in) :: slots(:)           !< the body's slots
    integer, intent(in) :: m                  !< contact rows of all pairs
    integer :: code(size(slots))
    integer :: i, c
    do i = 1, size(slots)
      c = row_state(slot_row(slots(i), m))
      if (c < 0) then
        code(i) = 0
      else if (slot_side(slots(i), m) == 1) then
        code(i) = mod(c, 4)
      else
        code(i) = c/4
      end if
    end do
  end function last_bound

  !> Each bounded row outside the discs (pos) whose force was on a nonzero bound in the last
  !! iterate (code, and the force's sign) is put on that bound now (Coulomb's bound moved
  !! with lam_n).
  pure subroutine onto_new_bounds(pos, code, lb, ub, lam)
    integer, intent(in) :: pos(:, :)          !< (2, discs) the discs' variables
    integer, intent(in) :: code(:)            !< per variable: BOUND_* of the last iterate (0: not known)
    real(wp), intent(in) :: lb(:), ub(:)      !< the bounds now
    real(wp), intent(inout) :: lam(:)
    logical :: in_disc(size(lam))
    integer :: i
    in_disc = .false.
    in_disc(pack(pos, .true.)) = .true.
    do i = 1, size(lam)
      if (in_disc(i) .or. .not. (ub(i) < huge(1.0_wp) .and. lb(i) > -huge(1.0_wp))) cycle
      ! (a zero force counts as on its bound where the bound was 0: no side to keep)
      if (code(i) == BOUND_UPPER .and. lam(i) > 0.0_wp) then
        lam(i) = ub(i)
      else if (code(i) == BOUND_LOWER .and. lam(i) < 0.0_wp) then
        lam(i) = lb(i)
      end if
    end do
  end subroutine onto_new_bounds

  !> Each disc k (its variables pos(:, k)) whose force was on its circle in the last iterate
  !! (was_on) is scaled onto its circle of radius r now: the same direction.
  pure subroutine onto_new_circles(pos, was_on, r, lam)
    integer, intent(in) :: pos(:, :)          !< (2, discs) the discs' variables
    logical, intent(in) :: was_on(:)          !< per variable
    real(wp), intent(in) :: r(:)              !< the radii now, per variable
    real(wp), intent(inout) :: lam(:)
    integer :: k
    real(wp) :: s
    do k = 1, size(pos, 2)
      s = norm2(lam(pos(:, k)))
      if (s > 0.0_wp .and. was_on(pos(1, k)) .and. r(pos(1, k)) < huge(1.0_wp)) lam(pos(:, k)) = lam(pos(:, k))*(r(pos(1, k))/s)
    end do
  end subroutine onto_new_circles

  !> The QP method of a body's solve: the deck's inner_solver, 'auto' resolved by what the
  !! body's earlier solves needed (newton = 1: the Newton method at once; k >= 2: the Newton
  !! method within k - 1 steps, then MPRGP; k <= -1: MPRGP to a loose tolerance, then the
  !! Newton method within -k steps, then MPRGP).
  pure integer function inner_method(choice, newton) result(method)
    integer, intent(in) :: choice    !< INNER_*
    integer, intent(in) :: newton    !< robin_state_t%newton of the body
    select case (choice)
    case (INNER_MPRGP)
      method = QP_MPRGP
    case (INNER_ACTIVE_SET)
      method = QP_NEWTON
    case default
      select case (newton)
      case (1)
        method = QP_NEWTON
      case (2:)
        method = QP_NEWTON_FIRST
      case (:-1)
        method = QP_POLISH
      case default
        method = QP_AUTO
      end select
    end select
  end function inner_method

  !> One step of the active-set Newton method on n unknowns with nf free, in products with
  !! the n x n Hessian (2 n^2 flops each): the free block's factor (nf^3/3) and solves
  !! (2 nf^2), the step's product and the product that confirms the gradient.
  pure real(wp) function newton_step_cost(n, nf) result(c)
    integer, intent(in) :: n, nf
    c = (real(nf, wp)**3/3.0_wp + 2.0_wp*real(nf, wp)**2)/(2.0_wp*real(max(n, 1), wp)**2) + 2.0_wp
  end function newton_step_cost

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
