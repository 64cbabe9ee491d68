!> The Robin domain-decomposition iteration (doc/method.md, "Method as implemented",
!! "Several bodies and contact pairs"): each body's contact problem against its obstacles
!! on all its contact rows (module robin_subproblems), the force imbalance of every row
!! d = lam_side1 - lam_side2, its Robin correction (module robin_operators), and the relaxed
!! or accelerated update of the obstacles (module acceleration), until the bodies agree.
!! Everything here is interface-sized: O(m_a^2) per body and Hessian product.
module robin_iteration
  use kinds, only: wp
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use config, only: solver_cfg_t, STOP_RESIDUAL, ACCEL_NONE, ROBIN_HARMONIC, METHOD_ROBIN
  use clock, only: wtime
  use contact_interface, only: interface_t, has_friction, row_bounds, disc_rows, DIR_NORMAL
  use condense, only: body_condensed_t
  use signals, only: stop_iface
  use contact_types, only: contact_result_t, robin_state_t, checkpointer_t, state_init, alloc_result, &
                           grow_history, STATUS_CONVERGED, STATUS_MAX_OUTER, STATUS_DIVERGED, STATUS_FAILED, &
                           STATUS_INTERRUPTED, BOUND_LOWER, BOUND_UPPER, BOUND_INSIDE
  use contact_common, only: interface_residual, maxabs, all_finite, gather, scatter
  use errors, only: error_t
  use robin_operators, only: robin_operator_t, new_robin_operator, progress_rtol
  use robin_subproblems, only: subproblems_t, subproblems_init, solve_subproblems
  use acceleration, only: accelerate
  implicit none (type, external)
  private

  integer, parameter :: STALL_LIMIT = 25      !< iterations of small increment / large residual before 'diverged'
  integer, parameter :: HISTORY_CHUNK = 256   !< initial history entries (grown by doubling)
  integer, parameter :: FLAT_LIMIT = 50       !< iterations without a 1% better residual (stop='residual'), or
                                              !! without a 1% better criterion and residual than in the
                                              !! as many before (a cycle), before 'diverged'

  real(wp), parameter :: FLOOR_FACTOR = 1.0_wp    !< rounding_floor's safety factor
  !> a rounding level above this is not called converged: such a residual says too little
  real(wp), parameter :: FLOOR_MAX = 1.0e-4_wp

  public :: solve_robin

contains

  !> The Robin iteration. With `state` the iteration resumes from a checkpoint; `ckpt%save`
  !! is called every ckpt%every iterations and when `stop_requested` turns true.
  subroutine solve_robin(solver, contact_line, bodies, res, progress_unit, progress_lines, state, ckpt, stop_requested, &
                         warm_obstacle, warm_lam)
    type(solver_cfg_t), intent(in) :: solver                !< solver settings
    type(interface_t), intent(in) :: contact_line           !< contact rows of all pairs
    type(body_condensed_t), intent(in) :: bodies(:)         !< condensed bodies
    type(contact_result_t), intent(inout) :: res            !< solution, status and history (in: history of a restart)
    integer, intent(in), optional :: progress_unit          !< unit for progress lines (none if absent)
    integer, intent(in), optional :: progress_lines         !< at most about this many progress lines (default 30)
    type(robin_state_t), intent(inout), optional :: state   !< in: state to resume from (state%it > 0)
    class(checkpointer_t), intent(inout), optional :: ckpt  !< saves checkpoints of (state, res)
    procedure(stop_iface), optional :: stop_requested       !< true when the run must stop (signal)
    !> (m,2) a fresh start's first obstacles and forces (a load step: the step before's)
    real(wp), intent(in), optional :: warm_obstacle(:, :), warm_lam(:, :)
    type(robin_state_t) :: own
    ! the caller's state is iterated in place: a copy in and out would be a serial copy of
    ! the Anderson history and the recycled directions (megabytes at many bodies)
    if (present(state)) then
      call robin_run(solver, contact_line, bodies, res, progress_unit, progress_lines, state, state%it > 0, ckpt, &
                     stop_requested, warm_obstacle, warm_lam)
    else
      call robin_run(solver, contact_line, bodies, res, progress_unit, progress_lines, own, .false., ckpt, &
                     stop_requested, warm_obstacle, warm_lam)
    end if
  end subroutine solve_robin

  !> solve_robin on run_state, a fresh start unless `resumed`.
  subroutine robin_run(solver, contact_line, bodies, res, progress_unit, progress_lines, run_state, resumed, ckpt, &
                       stop_requested, warm_obstacle, warm_lam)
    type(solver_cfg_t), intent(in) :: solver
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    type(contact_result_t), intent(inout) :: res
    integer, intent(in), optional :: progress_unit
    integer, intent(in), optional :: progress_lines
    type(robin_state_t), intent(inout) :: run_state   !< the outer state, iterated in place
    logical, intent(in) :: resumed                    !< run_state holds a checkpoint's state
    class(checkpointer_t), intent(inout), optional :: ckpt
    procedure(stop_iface), optional :: stop_requested
    real(wp), intent(in), optional :: warm_obstacle(:, :), warm_lam(:, :)
    type(subproblems_t), target :: subproblems
    class(robin_operator_t), allocatable :: robin_op
    real(wp) :: t0
    integer :: m, every
    type(error_t) :: err

    m = contact_line%m
    t0 = wtime()
    if (resumed) then
      t0 = t0 - run_state%wall
    else
      ! the history grows as the run goes (max_outer may be huge)
      call alloc_result(res, m, min(solver%max_outer, HISTORY_CHUNK), size(bodies))
      call state_init(run_state, m, contact_line%g0, size(bodies), contact_line%npair)
      if (present(warm_obstacle) .and. present(warm_lam)) then
        run_state%G = warm_obstacle
        run_state%lam = warm_lam
        run_state%reuse = 0   ! F_a lam_a is not known for these forces
      end if
    end if
    res%method = METHOD_ROBIN

    robin_op = new_robin_operator(solver%robin_operator)
    call subproblems_init(subproblems, contact_line, bodies, robin_op, run_state, resumed)
    call robin_op%setup(solver, contact_line, bodies, subproblems%flexibility, err)
    if (err%failed()) then
      res%message = err%text()
      res%status = STATUS_FAILED
      return
    end if
    every = 30
    if (present(progress_lines)) every = progress_lines
    every = max(1, solver%max_outer/max(1, every))
    res%status = STATUS_MAX_OUTER
    if (resumed .and. run_state%it >= solver%max_outer) then
      call restore_iterate(contact_line, bodies, subproblems, run_state, res)
      if (present(progress_unit)) write (progress_unit, '(a,i0,a)') 'the checkpoint is at outer iteration ', &
        run_state%it, ' = max_outer: nothing left to do, its result is written again (raise max_outer to go on)'
    end if
    if (present(progress_unit)) then
      if (resumed) write (progress_unit, '(a,i0)') 'resuming after outer iteration ', run_state%it
      write (progress_unit, '(a)') '  outer   criterion    residual  active       inner'
    end if
    call outer_loop(solver, contact_line, bodies, subproblems, robin_op, t0, every, run_state, res, &
                    progress_unit, ckpt, stop_requested)
  end subroutine robin_run

  !> The outer iterations from run_state%it + 1 to max_outer: subproblems, correction,
  !! update, record, termination test, progress line, checkpoint.
  subroutine outer_loop(solver, contact_line, bodies, subproblems, robin_op, t0, every, run_state, res, &
                        progress_unit, ckpt, stop_requested)
    type(solver_cfg_t), intent(in) :: solver
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    type(subproblems_t), target, intent(inout) :: subproblems     !< (the Robin operator may refer to its F_a)
    class(robin_operator_t), intent(inout) :: robin_op
    real(wp), intent(in) :: t0                              !< wall time the iteration started at
    integer, intent(in) :: every                            !< a progress line every this many iterations
    type(robin_state_t), intent(inout) :: run_state
    type(contact_result_t), intent(inout) :: res
    integer, intent(in), optional :: progress_unit
    class(checkpointer_t), intent(inout), optional :: ckpt
    procedure(stop_iface), optional :: stop_requested
    real(wp), allocatable :: g_new(:, :), w(:, :), dlam(:), corr(:, :), g_full(:, :)
    real(wp) :: rtol_in, uref
    integer :: m, it, a
    logical :: printed, first

    m = contact_line%m
    allocate (g_new(m, 2), w(m, 2), dlam(m), corr(m, 2))
    uref = max(maxabs(contact_line%g0), tiny(1.0_wp))
    do a = 1, size(bodies)
      uref = max(uref, maxabs(bodies(a)%b))
    end do
    printed = .false.
    first = .true.
    res%message = ''
    do it = run_state%it + 1, solver%max_outer
      ! 1. each body against its obstacle, in parallel
      rtol_in = robin_op%inner_tolerance(solver, it, m, run_state%progress, subproblems%lmax_body)
      ! friction: while the rows still change between stick, slip and open, the boxes
      ! (Coulomb: and their bounds) are provisional, and solving against them more tightly
      ! than the outer progress is wasted; once they settle, the operator's own tolerance
      if (has_friction(contact_line) .and. run_state%settled == 0) &
        rtol_in = max(rtol_in, progress_rtol(solver, it, run_state%progress))
      ! the obstacles stopped moving but the bodies do not agree: the subproblems' own error
      ! is what is left, so each such iteration solves them ten times tighter, down to rounding
      if (run_state%stalled > 0) rtol_in = max(sqrt(real(m, wp))*epsilon(1.0_wp), &
                                               rtol_in*0.1_wp**min(run_state%stalled, 12))
      ! friction: the bounds of the tangential forces (Coulomb: mu times the mean normal
      ! force of the last iterate, the same box for both sides of a row)
      if (has_friction(contact_line)) then
        if (.not. allocated(subproblems%lb)) allocate (subproblems%lb(m), subproblems%ub(m))
        call row_bounds(contact_line, 0.5_wp*(run_state%lam(:, 1) + run_state%lam(:, 2)), subproblems%lb, subproblems%ub, &
                        start=all(run_state%lam == 0.0_wp))
      end if
      call solve_subproblems(subproblems, solver, bodies, rtol_in, it, run_state, w, res)
      ! the displacement scale also counts what the first forces would do to each body (its
      ! own flexibility F_a, not a Robin term's, times the largest force): a soft body loaded only through a stiff one has b_a = 0, and the stiff one's
      ! b_a is its own small displacement (a punch at contrast 1e8: 1.5e-11 against 1e-3);
      ! once only, so that forces growing with a diverging iteration do not raise it
      if (first) then
        do a = 1, size(bodies)
          if (bodies(a)%m > 0) uref = max(uref, maxval(sum(abs(bodies(a)%flex), dim=1))*maxval(abs(run_state%lam)))
        end do
        first = .false.
      end if
      if (has_friction(contact_line)) call update_row_states(contact_line, subproblems%lb, subproblems%ub, run_state)
      if (m == 0) then
        res%status = STATUS_CONVERGED
        res%outer = it
        exit
      end if
      if (res%status == STATUS_FAILED) then
        res%outer = it
        exit
      end if
      ! 2. force imbalance and its Robin correction
      dlam = run_state%lam(:, 1) - run_state%lam(:, 2)
      call robin_op%apply(dlam, corr, run_state%inner, it)
      if (robin_op%failure%failed()) then
        res%status = STATUS_FAILED
        res%outer = it
        res%message = robin_op%failure%text()
        exit
      end if
      ! 3. the fixed-point map T(G) and the relaxed or accelerated update
      g_new(:, 1) = contact_line%g0 - w(:, 2) + corr(:, 1)
      g_new(:, 2) = contact_line%g0 - w(:, 1) - corr(:, 2)
      if (has_friction(contact_line) .and. solver%acceleration == ACCEL_NONE .and. &
          solver%robin_operator == ROBIN_HARMONIC) then
        g_full = g_new
        call accelerate(solver%acceleration, solver%delta, run_state, g_new)
        call full_step_at_bounds(contact_line, run_state%row_state, g_full, g_new)
      else
        call accelerate(solver%acceleration, solver%delta, run_state, g_new)
      end if
      ! a non-finite iterate is not kept: the result holds the last finite one
      if (.not. (all_finite(g_new) .and. all_finite(run_state%lam) .and. all_finite(w))) then
        res%status = STATUS_DIVERGED
        write (res%message, '(a,i0)') 'non-finite values in the outer iteration at iteration ', it
        exit
      end if
      call record_iteration(solver, contact_line, bodies, it, g_new, w, t0, run_state, res)
      printed = .false.
      if (present(progress_unit) .and. (it <= 5 .or. mod(it, every) == 0)) then
        write (progress_unit, '(i7,2es12.3,i8,i12)') it, run_state%crit, res%residual, res%active, run_state%inner
        printed = .true.
      end if
      if (check_termination(solver, it, uref, rounding_floor(contact_line, bodies, w, run_state), run_state, res)) exit
      if (present(stop_requested)) then
        if (stop_requested()) then
          res%status = STATUS_INTERRUPTED
          write (res%message, '(a,i0)') 'stopped by a signal after outer iteration ', it
          if (present(ckpt)) call ckpt%save(run_state, res)
          exit
        end if
      end if
      if (present(ckpt)) then
        if (ckpt%every > 0) then
          if (mod(it, ckpt%every) == 0) call ckpt%save(run_state, res)
        end if
      end if
    end do
    if (present(progress_unit) .and. res%outer > 0 .and. .not. printed) &
      write (progress_unit, '(i7,2es12.3,i8,i12)') res%outer, res%criterion, res%residual, res%active, res%inner
    if (res%status == STATUS_MAX_OUTER) write (res%message, '(a,i0,a,es10.3)') 'max_outer = ', solver%max_outer, &
      ' reached; last criterion ', res%criterion
  end subroutine outer_loop

  !> The bound state of a force against its box: at the lower bound (a normal row's zero
  !! force included), at the upper bound, or strictly inside.
  elemental integer function bound_state(lam, lb, ub) result(code)
    real(wp), intent(in) :: lam, lb, ub
    if (lam <= lb) then
      code = BOUND_LOWER
    else if (lam >= ub) then
      code = BOUND_UPPER
    else
      code = BOUND_INSIDE
    end if
  end function bound_state

  !> Friction: the rows' bound states of this iterate (both sides of a row: side 1's + 4 x
  !! side 2's), and whether any changed since the last iterate. In space both rows of a disc
  !! have the disc's state: on its circle (BOUND_UPPER) or inside.
  subroutine update_row_states(itf, lb, ub, run_state)
    type(interface_t), intent(in) :: itf
    real(wp), intent(in) :: lb(:), ub(:)               !< (m) this iteration's boxes (a disc's radius in ub)
    type(robin_state_t), intent(inout) :: run_state
    integer, allocatable :: now(:), pr(:, :)
    integer :: k, s, code(2)
    allocate (now(size(lb)))
    now = bound_state(run_state%lam(:, 1), lb, ub) + 4*bound_state(run_state%lam(:, 2), lb, ub)
    pr = disc_rows(itf)
    do k = 1, size(pr, 2)
      do s = 1, 2
        ! on its circle to the rounding of a projection
        code(s) = merge(BOUND_UPPER, BOUND_INSIDE, norm2(run_state%lam(pr(:, k), s)) >= (1.0_wp - 1.0e-12_wp)*ub(pr(1, k)))
      end do
      now(pr(:, k)) = code(1) + 4*code(2)
    end do
    run_state%settled = merge(1, 0, all(now == run_state%row_state))
    run_state%row_state = now
  end subroutine update_row_states

  !> `harmonic`: relaxation leaves the obstacles of a tangential row whose force sits at the
  !! same bound on both sides at their unrelaxed value T(G): while a row is at its bound its
  !! obstacle enters neither body's solution, and relaxing it only slows its way to the
  !! fixed point (at a fixed point G = T(G), so the fixed point is the same). Not for
  !! `steklov`, whose map needs the relaxation on every row (doc/method.md, "Friction"), and
  !! not for a disc in space, whose force on its circle turns with the obstacles.
  subroutine full_step_at_bounds(itf, row_state, g_full, g_new)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: row_state(:)                !< (m) update_row_states
    real(wp), intent(in) :: g_full(:, :)               !< (m, 2) T(G)
    real(wp), intent(inout) :: g_new(:, :)             !< (m, 2) relaxed obstacles
    integer :: k
    if (size(disc_rows(itf), 2) > 0) return
    do k = 1, itf%m
      if (itf%dir(k) == DIR_NORMAL) cycle
      if (row_state(k) == BOUND_LOWER*5 .or. row_state(k) == BOUND_UPPER*5) g_new(k, :) = g_full(k, :)
    end do
  end subroutine full_step_at_bounds

  !> A run resumed from a checkpoint taken at max_outer has nothing left to do: its result
  !! is the checkpointed iterate (contact forces, obstacles, history), with the normal
  !! displacements B_a u_a = b_a - F_a lam_a and the residuals recomputed.
  subroutine restore_iterate(contact_line, bodies, subproblems, run_state, res)
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    type(subproblems_t), intent(inout) :: subproblems
    type(robin_state_t), intent(in) :: run_state
    type(contact_result_t), intent(inout) :: res
    real(wp), allocatable :: flam(:), wa(:)
    integer :: a
    res%lam_body = run_state%lam
    do a = 1, size(bodies)
      if (bodies(a)%m == 0) cycle
      allocate (flam(bodies(a)%m))
      call subproblems%flexibility(a)%apply(gather(run_state%lam, bodies(a)%slots), flam)
      wa = bodies(a)%b - flam
      if (bodies(a)%nrig > 0) wa = wa - matmul(run_state%eq_mult(1:bodies(a)%nrig, a), bodies(a)%rg)
      call scatter(wa, bodies(a)%slots, res%w)
      deallocate (flam)
    end do
    res%rigid = -run_state%eq_mult
    call interface_residual(contact_line, bodies, res)
    res%obstacle = run_state%G
    res%outer = run_state%it
    res%inner = run_state%inner
    res%criterion = run_state%crit
    res%nhist = run_state%it
  end subroutine restore_iterate

  !> The true residual of the iterate, the increment of the obstacles (the paper's
  !! criterion), the stopping criterion, the new state and one history entry.
  subroutine record_iteration(solver, contact_line, bodies, it, g_new, w, t0, run_state, res)
    type(solver_cfg_t), intent(in) :: solver
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    integer, intent(in) :: it
    real(wp), intent(in) :: g_new(:, :), w(:, :), t0
    type(robin_state_t), intent(inout) :: run_state
    type(contact_result_t), intent(inout) :: res
    real(wp) :: denom(2), ref, incr, bsum
    integer :: a
    res%lam_body = run_state%lam
    res%w = w
    res%rigid = -run_state%eq_mult
    call interface_residual(contact_line, bodies, res)
    bsum = 0.0_wp
    do a = 1, size(bodies)
      bsum = bsum + maxabs(bodies(a)%b)
    end do
    ref = tiny(1.0_wp) + 1.0e-14_wp*(bsum + maxabs(contact_line%g0))
    do a = 1, 2
      denom(a) = max(norm2(g_new(:, a)), ref)
    end do
    incr = norm2(g_new(:, 1) - run_state%G(:, 1))/denom(1) + norm2(g_new(:, 2) - run_state%G(:, 2))/denom(2)
    if (solver%stop == STOP_RESIDUAL) then
      run_state%crit = res%residual
    else
      run_state%crit = incr
    end if
    ! the inner tolerance follows the outer progress: both the increment and the residual
    ! must shrink before the subproblems are solved tightly (a tolerance tied to the
    ! residual alone can freeze the obstacles and stall the iteration)
    run_state%progress = min(incr, res%residual)
    run_state%G = g_new
    run_state%it = it
    run_state%wall = wtime() - t0
    res%obstacle = run_state%G
    res%outer = it
    res%inner = run_state%inner
    res%criterion = run_state%crit
    if (it > size(res%h_criterion)) call grow_history(res, min(solver%max_outer, 2*size(res%h_criterion) + HISTORY_CHUNK))
    res%nhist = it
    res%h_criterion(it) = run_state%crit
    res%h_residual(it) = res%residual
    res%h_inner(it) = run_state%inner
    res%h_active(it) = res%active
    res%h_wall(it) = run_state%wall
  end subroutine record_iteration

  !> The level below which rounding keeps the residual: a body's force comes from the
  !! difference of its obstacles and its load displacement, b_a - G_a, which carries an
  !! absolute rounding of eps |w_a| (w_a its normal displacement, as large as its obstacles)
  !! against its own contact displacement |F_a lam_a|, a relative error of its force lam_a
  !! that counts in the residual as much as lam_a counts among the forces. So
  !! FLOOR_FACTOR sqrt(m) eps max_a min(|w_a|, W) / |F_a lam_a| |lam_a| / max_b |lam_b|
  !! (2-norms; a body without force has no rounding of it to speak of), with W = sum_b
  !! |F_b lam_b| + max_b |b_b| + |g0| the largest displacement the forces and loads can give
  !! any body at a fixed point (a body floating on others moves by their deformations): a
  !! diverging iteration's large obstacles do not raise it. About 1e-13 where the bodies'
  !! displacements are their own deformations; 3.9e-8 for a stack of 16 blocks, steel and a
  !! material 1e6 times softer in turn (a steel block 3.4 m from where it started).
  real(wp) function rounding_floor(contact_line, bodies, w, run_state) result(floor)
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    real(wp), intent(in) :: w(:, :)                  !< (m, 2) the bodies' normal displacements
    type(robin_state_t), intent(in) :: run_state
    real(wp), allocatable :: wn(:), on(:)
    real(wp), allocatable :: wa(:), own(:)
    real(wp) :: cap, lmax
    integer :: a
    allocate (wn(size(bodies)), on(size(bodies)))
    wn = 0.0_wp
    on = 0.0_wp
    cap = norm2(contact_line%g0)
    do a = 1, size(bodies)
      if (bodies(a)%m == 0) cycle
      ! the body's own contact displacement F_a lam_a = b_a - w_a - (its rigid motion)
      wa = gather(w, bodies(a)%slots)
      own = bodies(a)%b - wa
      if (bodies(a)%nrig > 0) own = own - matmul(run_state%eq_mult(1:bodies(a)%nrig, a), bodies(a)%rg)
      wn(a) = norm2(wa)
      on(a) = norm2(own)
      cap = cap + on(a)
    end do
    cap = cap + maxval([0.0_wp, (norm2(bodies(a)%b), a=1, size(bodies))])
    floor = 0.0_wp
    lmax = 0.0_wp
    do a = 1, size(bodies)
      if (bodies(a)%m > 0) lmax = max(lmax, norm2(gather(run_state%lam, bodies(a)%slots)))
    end do
    if (.not. lmax > 0.0_wp) return
    do a = 1, size(bodies)
      if (bodies(a)%m == 0 .or. .not. on(a) > 0.0_wp) cycle
      floor = max(floor, min(wn(a), cap)/on(a)*norm2(gather(run_state%lam, bodies(a)%slots))/lmax)
    end do
    floor = FLOOR_FACTOR*sqrt(real(size(w, 1), wp))*epsilon(1.0_wp)*floor
  end function rounding_floor

  !> True when the iteration ends after iteration `it`: converged, or diverged (a
  !! non-finite or exploding criterion, obstacles beyond 1e6 times the load displacement
  !! scale `uref`, a residual stop that stagnates, a small increment with a large residual
  !! for too long). Sets res%status and res%message.
  logical function check_termination(solver, it, uref, floor, run_state, res) result(done)
    type(solver_cfg_t), intent(in) :: solver
    integer, intent(in) :: it
    real(wp), intent(in) :: uref
    real(wp), intent(in) :: floor        !< the residual's rounding level (`rounding_floor`)
    type(robin_state_t), intent(inout) :: run_state
    type(contact_result_t), intent(inout) :: res
    done = .true.
    if (.not. ieee_is_finite(run_state%crit)) then
      res%status = STATUS_DIVERGED
      write (res%message, '(a,i0)') 'non-finite criterion at iteration ', it
      return
    end if
    run_state%best = min(run_state%best, run_state%crit)
    if (it > 10 .and. run_state%crit > 1.0e4_wp*run_state%best .and. run_state%crit > 1.0_wp) then
      res%status = STATUS_DIVERGED
      write (res%message, '(a,es10.3,a,es10.3)') 'criterion grew to ', run_state%crit, ' from its best ', run_state%best
      return
    end if
    ! a relative increment stays bounded while the iterates blow up geometrically: watch
    ! the size of the obstacles against the displacements the loads cause
    if (maxval(abs(run_state%G)) > 1.0e6_wp*uref) then
      res%status = STATUS_DIVERGED
      write (res%message, '(a,es10.3,a,es10.3,a)') 'obstacles grew to ', maxval(abs(run_state%G)), &
        ' (1e6 times the load displacement scale ', uref, ')'
      return
    end if
    ! the residual stop: a residual that has not improved by 1% in FLAT_LIMIT iterations
    ! has reached the floor that rounding and conditioning allow; tol is out of reach
    if (res%residual < 0.99_wp*run_state%res_best) then
      run_state%res_best = res%residual
      run_state%it_best = it
    end if
    if (solver%stop == STOP_RESIDUAL .and. run_state%crit > solver%tol .and. it - run_state%it_best >= FLAT_LIMIT) then
      res%status = STATUS_DIVERGED
      write (res%message, '(a,es10.3,a,i0,a,es10.3,a)') 'stagnated: the residual has stayed near ', &
        run_state%res_best, ' for ', FLAT_LIMIT, ' iterations; tol = ', solver%tol, ' is out of reach'
      return
    end if
    if (solver%stop /= STOP_RESIDUAL .and. run_state%crit > solver%tol .and. cycling(it)) then
      res%status = STATUS_DIVERGED
      write (res%message, '(a,i0,a,es10.3,a,es10.3,a,i0,a)') 'stagnated: in ', FLAT_LIMIT, &
        ' iterations neither the increment (best ', minval(res%h_criterion(it - FLAT_LIMIT + 1:it)), &
        ') nor the residual (best ', minval(res%h_residual(it - FLAT_LIMIT + 1:it)), &
        ') has come 1% below its best of the ', FLAT_LIMIT, ' before: the iteration cycles or stalls'
      return
    end if
    ! tol below what rounding allows: a residual at that level is as converged as this
    ! scene can be (a stack of stiff bodies on soft ones: each stiff body's force is a small
    ! difference of its obstacles, which the soft bodies' displacements make large)
    if (run_state%crit > solver%tol .and. res%residual > solver%tol .and. res%residual <= floor .and. &
        floor <= FLOOR_MAX) then
      res%status = STATUS_CONVERGED
      write (res%message, '(a,es10.3,a,es10.3,a,es10.3,a)') 'converged to working precision: residual ', &
        res%residual, ' is within the rounding level ', floor, ' of this scene (tol = ', solver%tol, ' is below it)'
      return
    end if
    if (run_state%crit <= solver%tol) then
      if (solver%stop /= STOP_RESIDUAL .and. res%residual > 1.0e2_wp*solver%tol) then
        ! the obstacles stopped moving but the bodies do not agree yet: a small increment
        ! is not a small error. Go on (the inner tolerance follows the smaller increment);
        ! if it persists, the iteration has stagnated.
        run_state%stalled = run_state%stalled + 1
        if (run_state%stalled >= STALL_LIMIT) then
          res%status = STATUS_DIVERGED
          write (res%message, '(a,es10.3,a,es10.3,a,i0,a)') 'stagnated: increment ', run_state%crit, &
            ' below tol but residual ', res%residual, ' above 100 tol for ', STALL_LIMIT, &
            ' iterations (the bodies do not agree)'
          return
        end if
      else
        res%status = STATUS_CONVERGED
        return
      end if
    else
      run_state%stalled = 0
    end if
    done = .false.
  contains
    !> Neither the criterion nor the residual of the last FLAT_LIMIT iterations came 1% below
    !! their best in the FLAT_LIMIT iterations before them, and the residual is far above tol:
    !! a cycle (friction under a weakly damped operator oscillates between two states, for
    !! instance) or a stall, which more iterations do not break. Windows, not the best since
    !! the start: a load step's first iterations may be good by luck before slow, steady
    !! progress. The history holds every iteration, also after a restart.
    logical function cycling(it)
      integer, intent(in) :: it
      integer :: k
      cycling = .false.
      if (it < 2*FLAT_LIMIT .or. res%nhist < it) return
      if (res%residual <= 1.0e2_wp*solver%tol) return
      k = it - FLAT_LIMIT
      cycling = minval(res%h_criterion(k + 1:it)) >= 0.99_wp*minval(res%h_criterion(k - FLAT_LIMIT + 1:k)) .and. &
                minval(res%h_residual(k + 1:it)) >= 0.99_wp*minval(res%h_residual(k - FLAT_LIMIT + 1:k))
    end function cycling
  end function check_termination

end module robin_iteration
