!> Two-body contact on the condensed interface (README, "Method as implemented"):
!! `solve_robin`: the Robin domain-decomposition iteration (each body's contact
!! problem against an obstacle by MPRGP, obstacles relaxed until the bodies agree);
!! `solve_monolithic`: the same discrete problem in one piece, the reference.
!! Everything here is interface-sized: O(m^2) per Hessian product.
module contact
  use kinds, only: wp
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use config, only: solver_cfg_t, ROBIN_CONSTANT, ROBIN_HARMONIC, STOP_RESIDUAL, ACCEL_NONE, ACCEL_AITKEN, ACCEL_ANDERSON
  use linop, only: linop_t, dense_op_t, dense_op_init
  use clock, only: wtime
  use lapack, only: dsymv, dgemm, dpotrf, dpotrs, dposv, dgels, dsyev, dgesv
  use mprgp, only: mprgp_opts_t, mprgp_stats_t, mprgp_solve, lambda_max_estimate, &
                   MPRGP_CONVERGED, MPRGP_MAX_IT, MPRGP_STOPPED, mprgp_status_name
  use smalbe, only: smalbe_solve, smalbe_stats_t
  use strings, only: itoa
  use condense, only: interface_t, body_condensed_t
  use contact_types, only: contact_result_t, robin_state_t, checkpointer_t, stop_iface, ANDERSON_DEPTH, &
                           state_init, alloc_result, grow_history, STATUS_CONVERGED, &
                           STATUS_MAX_OUTER, STATUS_DIVERGED, STATUS_FAILED, STATUS_INTERRUPTED
  implicit none (type, external)
  private

  integer, parameter :: STALL_LIMIT = 25              !< iterations of small increment / large residual before 'diverged'
  real(wp), parameter :: SMOOTH_RATE_TOL = 0.1_wp   !< rate change below which the outer iteration counts as smooth
  integer, parameter :: POWER_ITS = 10               !< power iterations for each body's lambda_max (harmonic operator only)
  integer, parameter :: HISTORY_CHUNK = 256          !< initial history entries (grown by doubling)
  integer, parameter :: FLAT_LIMIT = 50               !< iterations without a 1% better residual before 'diverged' (stop='residual')

  real(wp), parameter :: RHO_FACTOR = 10.0_wp     !< SMALBE penalty rho = RHO_FACTOR lambda_max(H) / |G G'|
  real(wp), parameter :: FEAS_RTOL = 1.0e-12_wp     !< equilibrium of a floating body: |G lam - e| <= FEAS_RTOL |e| (monolithic)
  real(wp), parameter :: FEAS_RTOL_MIN = 1.0e-15_wp !< Robin subproblems: max(inner tolerance, rounding, this) |e|

  !> The equality rows of a QP with floating bodies (module floating): G lam = e, and the
  !! SMALBE settings that go with the Hessian H they are added to (A = H + rho G'G).
  type :: eq_t
    integer :: r = 0                          !< rows (0: no equality, plain MPRGP)
    real(wp), allocatable :: g(:, :)          !< (r, m) G [-]
    real(wp), allocatable :: e(:)             !< (r) e [force]
    real(wp) :: rho = 0.0_wp                  !< penalty [length/force]
    real(wp) :: gg = 0.0_wp                   !< lambda_max(G G') [-]
    real(wp) :: m0 = 0.0_wp                   !< SMALBE's initial M [length/force]
    real(wp) :: feas = 0.0_wp                 !< |G lam - e| that counts as equilibrium [force]
  end type eq_t

  !> y = alpha x ./ w: the constant Robin operator alpha M^-1 (M: tributary lengths).
  type, extends(linop_t) :: inv_diag_op_t
    real(wp) :: alpha = 0.0_wp               !< Robin parameter [length/stress]
    real(wp), allocatable :: w(:)            !< (m) tributary lengths [length]
  contains
    procedure :: apply => inv_diag_apply
  end type inv_diag_op_t

  !> The Robin correction of the obstacles, chosen before the outer loop: body 1's obstacle
  !! moves by S_1 d, body 2's by -S_2 d (d = lam_1 - lam_2). When S_1 and S_2 are one
  !! operator, one product serves both.
  type :: robin_correction_t
    class(linop_t), pointer :: s1 => null()   !< S_1 (body 1's obstacle)
    class(linop_t), pointer :: s2 => null()   !< S_2 (body 2's obstacle)
    class(linop_t), pointer :: own => null()  !< the operator, when not a body's flexibility
    integer :: cost = 0                       !< Hessian-sized products per application (IT_inner)
  contains
    procedure :: apply => correction_apply
    procedure :: free => correction_free
  end type robin_correction_t

  public :: solve_robin, solve_monolithic, interface_residual
  public :: error_bound

contains

  !> The monolithic reference: min 1/2 lam'(F1+F2)lam - lam'(b1+b2-g0), lam >= 0.
  subroutine solve_monolithic(s, itf, bc, res, stop_requested)
    type(solver_cfg_t), intent(in) :: s                !< solver settings
    type(interface_t), intent(in) :: itf               !< contact line
    type(body_condensed_t), intent(in) :: bc(2)        !< condensed bodies
    type(contact_result_t), intent(out) :: res         !< solution and status
    procedure(stop_iface), optional :: stop_requested  !< true when the run must stop (signal)
    type(dense_op_t) :: op
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    type(smalbe_stats_t) :: sst
    type(eq_t) :: eq
    real(wp), allocatable :: c(:), lb(:), g(:), lam(:), gs(:, :), es(:), mu(:)
    integer :: m, a, r1
    real(wp) :: t0

    m = itf%m
    t0 = wtime()
    res%method = 'monolithic'
    call alloc_result(res, m, 1)
    allocate (c(m), lb(m), g(m), lam(m))
    call dense_op_init(op, bc(1)%flex + bc(2)%flex)
    c = bc(1)%b + bc(2)%b - itf%g0
    lb = 0.0_wp
    lam = 0.0_wp
    opts%rtol = s%monolithic_rtol
    opts%max_it = s%inner_max_it
    if (present(stop_requested)) opts%stop => stop_requested
    ! floating bodies: both bodies' equilibrium rows, stacked
    r1 = bc(1)%nrig
    if (r1 + bc(2)%nrig > 0 .and. m > 0) then
      allocate (gs(r1 + bc(2)%nrig, m), es(r1 + bc(2)%nrig), mu(r1 + bc(2)%nrig))
      if (r1 > 0) gs(1:r1, :) = bc(1)%rg
      if (r1 > 0) es(1:r1) = bc(1)%re
      if (bc(2)%nrig > 0) gs(r1 + 1:, :) = bc(2)%rg
      if (bc(2)%nrig > 0) es(r1 + 1:) = bc(2)%re
      opts%lambda_max = maxval(sum(abs(op%a), dim=1))
      call eq_init(eq, gs, es, opts%lambda_max)
      call eq_add(eq, op, opts%lambda_max)
      mu = 0.0_wp
    end if
    if (m > 0) then
      if (eq%r > 0) then
        call smalbe_solve(op, c, eq%g, eq%e, eq%rho, lb, lam, mu, opts, eq%m0, eq%feas, sst, g)
        st = sst%inner
        st%n_matvec = sst%n_matvec
        res%eq_updates = sst%updates
        if (r1 > 0) res%rigid(1:r1, 1) = -mu(1:r1)
        if (bc(2)%nrig > 0) res%rigid(1:bc(2)%nrig, 2) = -mu(r1 + 1:)
      else
        call mprgp_solve(op, c, lb, lam, opts, st, g)
      end if
      res%inner = st%n_matvec
      if (st%status == MPRGP_STOPPED) then
        res%status = STATUS_INTERRUPTED
        res%message = 'monolithic MPRGP stopped by a signal after '//trim(itoa(st%n_cg + st%n_exp + st%n_prop))// &
                      ' steps (no checkpoint: the monolithic solve is one step)'
      else if (st%status /= MPRGP_CONVERGED) then
        res%status = merge(STATUS_MAX_OUTER, STATUS_FAILED, st%status == MPRGP_MAX_IT)
        res%message = 'monolithic MPRGP: '//trim(mprgp_status_name(st%status))//': '//trim(st%message)
      else
        res%status = STATUS_CONVERGED
      end if
    else
      res%status = STATUS_CONVERGED
    end if
    res%outer = 1
    res%lam = lam
    do a = 1, 2
      res%lam_body(:, a) = lam
      ! B_a u_a with the rigid part B_a R_a alpha_a = G_a' alpha_a of a floating body
      res%w(:, a) = bc(a)%b - matmul(bc(a)%flex, lam)
      if (bc(a)%nrig > 0) res%w(:, a) = res%w(:, a) + matmul(res%rigid(1:bc(a)%nrig, a), bc(a)%rg)
      res%obstacle(:, a) = 0.0_wp
    end do
    call interface_residual(itf, bc, res)
    res%criterion = res%residual
    res%nhist = 1
    res%h_criterion(1) = res%criterion
    res%h_residual(1) = res%residual
    res%h_inner(1) = res%inner
    res%h_active(1) = res%active
    res%h_wall(1) = wtime() - t0
    if (res%status == STATUS_CONVERGED .and. .not. all_finite(lam)) then
      res%status = STATUS_FAILED
      res%message = 'monolithic solution has non-finite values'
    end if
  end subroutine solve_monolithic

  !> The Robin iteration (README, "Method as implemented"): each body's contact problem
  !! against its obstacle (MPRGP, in parallel), the force imbalance d = lam_1 - lam_2, its
  !! Robin correction S d, and the relaxed (or accelerated) update of the obstacles.
  !! The Robin operator is chosen once, before the loop (`robin_correction_init`).
  !! With `state` the iteration resumes from a checkpoint; `ckpt%save` is called
  !! every ckpt%every iterations and when `stop_requested` turns true.
  subroutine solve_robin(s, itf, bc, res, progress_unit, progress_lines, state, ckpt, stop_requested)
    type(solver_cfg_t), intent(in) :: s                !< solver settings
    type(interface_t), intent(in) :: itf               !< contact line
    type(body_condensed_t), intent(in) :: bc(2)        !< condensed bodies
    type(contact_result_t), intent(inout) :: res       !< solution, status and history (in: history of a restart)
    integer, intent(in), optional :: progress_unit     !< unit for progress lines (none if absent)
    integer, intent(in), optional :: progress_lines    !< at most about this many progress lines (default 30)
    type(robin_state_t), intent(inout), optional :: state   !< in: state to resume from (state%it > 0)
    class(checkpointer_t), intent(inout), optional :: ckpt  !< saves checkpoints of (state, res)
    procedure(stop_iface), optional :: stop_requested       !< true when the run must stop (signal)
    type(robin_state_t) :: st_
    type(dense_op_t), target :: op(2), opsub(2), pin(2), opc(2)
    type(robin_correction_t) :: corr_op
    type(eq_t) :: eq(2)
    real(wp), allocatable :: Gnew(:, :), w(:, :), dlam(:), corr(:, :)
    real(wp) :: rtol_in, t0, lmax(2), lsub(2), uref
    integer :: m, it, every, maxout, info, a
    logical :: printed, resumed

    m = itf%m
    t0 = wtime()
    maxout = s%max_outer
    resumed = .false.
    if (present(state)) resumed = state%it > 0
    if (resumed) then
      st_ = state
      t0 = t0 - st_%wall
    else
      ! the history grows as the run goes (max_outer may be huge)
      call alloc_result(res, m, min(maxout, HISTORY_CHUNK))
      call state_init(st_, m, itf%g0)
    end if
    res%method = 'robin'
    allocate (Gnew(m, 2), w(m, 2), dlam(m), corr(m, 2))
    uref = max(maxabs(bc(1)%b), maxabs(bc(2)%b), maxabs(itf%g0), tiny(1.0_wp))

    call body_operators(bc, op, lmax, st_, resumed, s%robin_operator == ROBIN_HARMONIC)
    call subproblem_operators(bc, op, lmax, s%robin_operator == ROBIN_HARMONIC, opsub, pin, lsub)
    ! a floating body's subproblem has its equilibrium as an equality (SMALBE-M)
    do a = 1, 2
      if (bc(a)%nrig == 0 .or. m == 0) cycle
      call eq_init(eq(a), bc(a)%rg, bc(a)%re, lsub(a))
      call eq_add(eq(a), opsub(a), lsub(a))
    end do
    ! a floating body's correction uses its flexibility on self-equilibrated forces only
    ! (projected_flex): F_a = B_a K_a^+ B_a' depends on the fixing DOFs along G_a'
    do a = 1, 2
      opc(a)%n = 0
      if (bc(a)%nrig > 0 .and. m > 0) call dense_op_init(opc(a), projected_flex(bc(a)))
    end do
    call robin_correction_init(corr_op, s, itf, bc, op, opc, info)
    if (info /= 0 .and. bc(1)%nrig + bc(2)%nrig > 0 .and. (bc(1)%rank < m .or. bc(2)%rank < m)) then
      res%status = STATUS_FAILED
      res%message = 'harmonic operator: a body held only by contact is a mortar master coarser than the '// &
                    'slave (singular F): make it the slave (&contact slave), or use steklov or monolithic'
      call corr_op%free()
      return
    else if (info /= 0) then
      res%status = STATUS_FAILED
      write (res%message, '(a,i0)') 'harmonic Robin operator: F_1 + F_2 is not positive definite, info = ', info
      call corr_op%free()
      return
    end if
    every = 30
    if (present(progress_lines)) every = progress_lines
    every = max(1, maxout/max(1, every))
    res%status = STATUS_MAX_OUTER
    printed = .false.
    if (resumed .and. st_%it >= maxout) then
      call restore_iterate(itf, bc, op, st_, res)
      if (present(progress_unit)) write (progress_unit, '(a,i0,a)') 'the checkpoint is at outer iteration ', &
        st_%it, ' = max_outer: nothing left to do, its result is written again (raise max_outer to go on)'
    end if
    if (present(progress_unit)) then
      if (resumed) write (progress_unit, '(a,i0)') 'resuming after outer iteration ', st_%it
      write (progress_unit, '(a)') '  outer   criterion    residual  active       inner'
    end if

    do it = st_%it + 1, maxout
      ! 1. each body against its obstacle, in parallel
      rtol_in = inner_tolerance(s, it, m, st_%progress, lmax)
      call solve_subproblems(s, bc, opsub, pin, eq, lsub, rtol_in, it, st_, w, res)
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
      dlam = st_%lam(:, 1) - st_%lam(:, 2)
      call corr_op%apply(dlam, corr, st_%inner)
      ! 3. the fixed-point map T(G) and the relaxed or accelerated update
      Gnew(:, 1) = itf%g0 - w(:, 2) + corr(:, 1)
      Gnew(:, 2) = itf%g0 - w(:, 1) - corr(:, 2)
      call accelerate(s%acceleration, s%delta, st_, Gnew)
      ! a non-finite iterate is not kept: the result holds the last finite one
      if (.not. (all_finite(Gnew) .and. all_finite(st_%lam) .and. all_finite(w))) then
        res%status = STATUS_DIVERGED
        write (res%message, '(a,i0)') 'non-finite values in the outer iteration at iteration ', it
        exit
      end if
      call record_iteration(s, itf, bc, it, Gnew, w, t0, st_, res)
      printed = .false.
      if (present(progress_unit) .and. (it <= 5 .or. mod(it, every) == 0)) then
        write (progress_unit, '(i7,2es12.3,i8,i12)') it, st_%crit, res%residual, res%active, st_%inner
        printed = .true.
      end if
      if (check_termination(s, it, uref, st_, res)) exit
      if (present(stop_requested)) then
        if (stop_requested()) then
          res%status = STATUS_INTERRUPTED
          write (res%message, '(a,i0)') 'stopped by a signal after outer iteration ', it
          if (present(ckpt)) call ckpt%save(st_, res)
          exit
        end if
      end if
      if (present(ckpt)) then
        if (ckpt%every > 0) then
          if (mod(it, ckpt%every) == 0) call ckpt%save(st_, res)
        end if
      end if
    end do
    if (present(progress_unit) .and. res%outer > 0 .and. .not. printed) &
      write (progress_unit, '(i7,2es12.3,i8,i12)') res%outer, res%criterion, res%residual, res%active, res%inner
    if (res%status == STATUS_MAX_OUTER) write (res%message, '(a,i0,a,es10.3)') 'max_outer = ', maxout, &
      ' reached; last criterion ', res%criterion
    call corr_op%free()
    if (present(state)) state = st_
  end subroutine solve_robin

  !> A run resumed from a checkpoint taken at max_outer has nothing left to do: its
  !! result is the checkpointed iterate (contact forces, obstacles, history), with the
  !! normal displacements B_a u_a = b_a - F_a lam_a and the residuals recomputed.
  subroutine restore_iterate(itf, bc, op, st, res)
    type(interface_t), intent(in) :: itf
    type(body_condensed_t), intent(in) :: bc(2)
    type(dense_op_t), intent(inout) :: op(2)
    type(robin_state_t), intent(in) :: st
    type(contact_result_t), intent(inout) :: res
    real(wp), allocatable :: flam(:)
    integer :: a
    allocate (flam(itf%m))
    res%lam_body = st%lam
    do a = 1, 2
      if (itf%m > 0) call op(a)%apply(st%lam(:, a), flam)
      res%w(:, a) = bc(a)%b - flam
      if (bc(a)%nrig > 0) res%w(:, a) = res%w(:, a) - matmul(st%mu(1:bc(a)%nrig, a), bc(a)%rg)
    end do
    res%rigid = -st%mu
    call interface_residual(itf, bc, res)
    res%obstacle = st%G
    res%outer = st%it
    res%inner = st%inner
    res%criterion = st%crit
    res%nhist = st%it
  end subroutine restore_iterate

  !> Each body's Hessian F_a as an operator and a bound of its largest eigenvalue for
  !! MPRGP's expansion step length. Default: the row-sum norm |F_a|_inf, an upper bound of
  !! lambda_max for a symmetric matrix (so alpha_bar = 1.9/|F_a|_inf is admissible without
  !! MPRGP's guard): one pass over F_a (m^2 flops, the cost of one product, but no product:
  !! not counted in IT_inner). With `power` (the harmonic operator, whose inner tolerance
  !! uses the ratio of the two estimates): POWER_ITS power iterations, counted in IT_inner
  !! unless the run resumes.
  subroutine body_operators(bc, op, lmax, st, resumed, power)
    type(body_condensed_t), intent(in) :: bc(2)
    type(dense_op_t), intent(out) :: op(2)
    real(wp), intent(out) :: lmax(2)
    type(robin_state_t), intent(inout) :: st
    logical, intent(in) :: resumed, power
    integer :: a, nmv(2), m
    m = bc(1)%m
    nmv = 0
    lmax = 0.0_wp
    !$omp parallel do num_threads(body_threads()) schedule(static, 1) if (m > 64)
    do a = 1, 2
      call dense_op_init(op(a), bc(a)%flex)
      if (m > 0) then
        if (power) then
          lmax(a) = lambda_max_estimate(op(a), POWER_ITS, nmv(a))
        else
          lmax(a) = maxval(sum(abs(bc(a)%flex), dim=1))
        end if
      end if
    end do
    !$omp end parallel do
    if (.not. resumed) st%inner = sum(nmv)
  end subroutine body_operators

  !> The Hessian of each body's subproblem, F_a + Pi_a, and a bound of its largest
  !! eigenvalue. Pi_a = 0 unless F_a is singular (module condense: a mortar master coarser
  !! than the slave has fewer normal DOFs than the slave has rows); then the proximal term
  !! 1/2 (l - lam_o)' Pi_a (l - lam_o), lam_o the other body's last contact force, fixes the
  !! part of lam_a that body a's own problem leaves undetermined (ker F_a = ker B_a').
  !!
  !! Fixed point. The master's KKT reads G_m - B_m u_m - Pi_m d = g_m >= 0 (d = lam_s - lam_m,
  !! lam_o = lam_s at a fixed point): an extra Robin term on its obstacle. With the two
  !! obstacle updates (slave: G_s = g0 - B_m u_m + S_s d, master: G_m = g0 - B_s u_s - S_m d)
  !! and gap = B_s u_s + B_m u_m - g0: S_s d - gap = g_s, -(S_m + Pi_m) d - gap = g_m, so
  !! (S_s + S_m + Pi_m) d = g_s - g_m, and d'(g_s - g_m) = -lam_s'g_m - lam_m'g_s <= 0
  !! (complementarity), so d'(S_s + S_m + Pi_m) d <= 0 and d = 0 whenever
  !! S_s + S_m + Pi_m is definite: the fixed point is the monolithic solution, active set
  !! included, for every Pi_m >= 0.
  !!
  !! Rate (linearised outer map, all nodes active, slave s, singular master m, e_a the error
  !! of G_a): dlam_s = -F_s^-1 e_s, dlam_m = -H_m^-1 e_m + H_m^-1 Pi_m dlam_s_prev with
  !! H_m = F_m + Pi_m. 'steklov' (S_s = F_m on the slave's obstacle, S_m = F_s on the
  !! master's): e_s -> F_m dlam_s = -F_m F_s^-1 e_s, whatever the master does, and
  !! e_m -> -F_s H_m^-1 e_m + (terms in e_s): block triangular, eigenvalues of the relaxed map
  !! 1 - delta (1 + mu), mu in eig(F_m F_s^-1) (zero on F_s ker F_m: rate 1 - delta) and in
  !! eig(F_s H_m^-1). The former Pi_m = prox I, prox = 1e-2 max diag F_m, puts F_s / prox
  !! (~ 100) in the second set: divergence. Pi_m on the kernel only (Z (Z'F_sZ) Z', Z a basis
  !! of ker F_m) gives mu = 1 there but keeps the range part, where F_s exceeds the master's
  !! mortar flexibility on the near-kernel modes (paper scene 24/36: mu up to 1.44, so
  !! delta = 0.95 diverges). Pi_m = F_s gives mu in eig(F_s (F_m + F_s)^-1), inside (0, 1):
  !! that block converges for every delta < 1 and the rate is the slave's, as on matching
  !! meshes ('constant' likewise: measured, not triangular). The term is then a Robin
  !! condition with the slave's Steklov-Poincare operator on the master's side.
  !! 'harmonic' (`kernel_only`): S = 2 F_s (F_s+F_m)^-1 F_m annihilates ker F_m, so only
  !! the kernel needs pinning and Pi_m = Z (Z'F_sZ) Z' leaves the master exact on
  !! range F_m (Pi_m = F_s would cost it its contrast independence). Without a kernel
  !! basis (dsyev failed) it falls back to F_s as well.
  subroutine subproblem_operators(bc, op, lmax, kernel_only, opsub, pin, lsub)
    type(body_condensed_t), intent(in) :: bc(2)
    type(dense_op_t), intent(in) :: op(2)
    real(wp), intent(in) :: lmax(2)              !< bounds of lambda_max(F_a)
    logical, intent(in) :: kernel_only           !< Pi_a on ker F_a only (harmonic operator)
    type(dense_op_t), intent(out) :: opsub(2)    !< F_a + Pi_a
    type(dense_op_t), intent(out) :: pin(2)      !< Pi_a (n = 0 when F_a is nonsingular)
    real(wp), intent(out) :: lsub(2)             !< bounds of lambda_max(F_a + Pi_a)
    real(wp), allocatable :: zf(:, :), zr(:, :), r(:, :), p(:, :)
    real(wp) :: floor
    integer :: a, i, k, m
    m = bc(1)%m
    lsub = lmax
    do a = 1, 2
      opsub(a) = op(a)
      pin(a)%n = 0
      if (.not. bc(a)%prox > 0.0_wp) cycle
      allocate (p(m, m))
      if (kernel_only .and. allocated(bc(a)%kern)) then
        k = size(bc(a)%kern, 2)
        allocate (zf(k, m), zr(m, k), r(k, k))
        ! R = Z' F_o Z (k x k), floored so that F_a + Pi_a is definite even if F_o is
        ! nearly singular on ker F_a; Pi_a = Z R Z'
        call dgemm('T', 'N', k, m, m, 1.0_wp, bc(a)%kern, m, bc(3 - a)%flex, m, 0.0_wp, zf, k)
        call dgemm('N', 'N', k, k, m, 1.0_wp, zf, k, bc(a)%kern, m, 0.0_wp, r, k)
        r = 0.5_wp*(r + transpose(r))
        floor = 0.0_wp
        do i = 1, m
          floor = max(floor, 1.0e-10_wp*bc(3 - a)%flex(i, i))
        end do
        do i = 1, k
          r(i, i) = r(i, i) + floor
        end do
        call dgemm('N', 'N', m, k, k, 1.0_wp, bc(a)%kern, m, r, k, 0.0_wp, zr, m)
        call dgemm('N', 'T', m, m, k, 1.0_wp, zr, m, bc(a)%kern, m, 0.0_wp, p, m)
        p = 0.5_wp*(p + transpose(p))
        deallocate (zf, zr, r)
      else
        ! F_a + F_o is definite (the monolithic Hessian)
        p = bc(3 - a)%flex
      end if
      call dense_op_init(pin(a), p)
      opsub(a)%a = opsub(a)%a + p
      ! lambda_max(F_a + Pi_a) <= lambda_max(F_a) + |Pi_a|_inf
      lsub(a) = lmax(a) + maxval(sum(abs(p), dim=1))
      deallocate (p)
    end do
  end subroutine subproblem_operators

  !> The Robin correction S_a of the obstacles: 'steklov' (the paper's: F_2 for body 1's
  !! obstacle, F_1 for body 2's, the bodies' own operators), 'constant' (alpha M^-1, a
  !! diagonal operator) and 'harmonic' (S = 2 F_1 (F_1+F_2)^-1 F_2 for both, a dense
  !! operator, which makes the linearised iteration independent of the contrast of the
  !! bodies: see the README). info /= 0 if F_1 + F_2 is not positive definite.
  subroutine robin_correction_init(c, s, itf, bc, op, opc, info)
    type(robin_correction_t), intent(out) :: c
    type(solver_cfg_t), intent(in) :: s
    type(interface_t), intent(in) :: itf
    type(body_condensed_t), intent(in) :: bc(2)
    type(dense_op_t), target, intent(in) :: op(2)
    type(dense_op_t), target, intent(in) :: opc(2)   !< floating bodies: P_a F_a P_a (n = 0: use op)
    integer, intent(out) :: info
    real(wp), allocatable :: S_h(:, :)
    info = 0
    select case (s%robin_operator)
    case (ROBIN_CONSTANT)
      allocate (inv_diag_op_t :: c%own)
      select type (o => c%own)
      type is (inv_diag_op_t)
        o%n = itf%m
        o%alpha = s%alpha
        o%w = itf%trib
      end select
      c%s1 => c%own
      c%s2 => c%own
      c%cost = 0
    case (ROBIN_HARMONIC)
      allocate (dense_op_t :: c%own)
      if (itf%m > 0) then
        if (bc(1)%nrig + bc(2)%nrig > 0) then
          call harmonic_floating(bc, S_h, info)
        else
          call harmonic_operator(bc(1)%flex, bc(2)%flex, S_h, info)
        end if
        if (info /= 0) return
        select type (o => c%own)
        type is (dense_op_t)
          call dense_op_init(o, S_h)
        end select
      end if
      c%s1 => c%own
      c%s2 => c%own
      c%cost = 1
    case default
      c%s1 => op(2)
      if (opc(2)%n > 0) c%s1 => opc(2)
      c%s2 => op(1)
      if (opc(1)%n > 0) c%s2 => opc(1)
      c%cost = 2
    end select
  end subroutine robin_correction_init

  !> The harmonic operator with a floating body: S = 2 (Sigma_1 + Sigma_2)^-1 with
  !! Sigma_a = F_a^-1 for a supported body (then S = 2 F_1 (F_1+F_2)^-1 F_2, the supported
  !! formula) and, for a floating one, its interface stiffness on balanced forces, the
  !! projected inverse Q_a = F_a^-1 - F_a^-1 G_a' (G_a F_a^-1 G_a')^-1 G_a F_a^-1
  !! (independent of the fixing DOFs; zero on the rigid normal displacements G_a'). The
  !! linearised outer map is then nilpotent at delta = 0.5 as for supported bodies
  !! (README, "Bodies held only by contact"). One floating body f, the other o supported:
  !! S = 2 (I + F_o Q_f)^-1 F_o, which needs no inverse of F_o (singular when a mortar row
  !! has none of body o's free DOFs). Both floating: S = 2 (Q_1 + Q_2)^-1 (definite unless
  !! the pair is free together, which module floating refuses). info /= 0: a
  !! factorization failed (a floating body's F_a must be definite).
  subroutine harmonic_floating(bc, S, info)
    type(body_condensed_t), intent(in) :: bc(2)
    real(wp), allocatable, intent(out) :: S(:, :)
    integer, intent(out) :: info
    real(wp), allocatable :: q(:, :, :), a(:, :)
    integer, allocatable :: ipiv(:)
    integer :: m, f, o, i
    m = bc(1)%m
    allocate (q(m, m, 2), S(m, m), a(m, m), ipiv(m))
    do f = 1, 2
      if (bc(f)%nrig == 0) cycle
      call projected_inverse(bc(f), q(:, :, f), info)
      if (info /= 0) return
    end do
    if (bc(1)%nrig > 0 .and. bc(2)%nrig > 0) then
      a = q(:, :, 1) + q(:, :, 2)
      a = 0.5_wp*(a + transpose(a))
      S = 0.0_wp
      do i = 1, m
        S(i, i) = 2.0_wp
      end do
      call dposv('U', m, m, a, m, S, m, info)
    else
      f = merge(1, 2, bc(1)%nrig > 0)
      o = 3 - f
      ! (I + F_o Q_f) X = F_o, S = 2 X
      a = matmul(bc(o)%flex, q(:, :, f))
      do i = 1, m
        a(i, i) = a(i, i) + 1.0_wp
      end do
      S = 2.0_wp*bc(o)%flex
      call dgesv(m, m, a, m, ipiv, S, m, info)
    end if
    S = 0.5_wp*(S + transpose(S))
  end subroutine harmonic_floating

  !> The projected inverse Q = F^-1 - F^-1 G' (G F^-1 G')^-1 G F^-1 of a floating body.
  subroutine projected_inverse(bc, q, info)
    type(body_condensed_t), intent(in) :: bc
    real(wp), intent(out) :: q(:, :)
    integer, intent(out) :: info
    real(wp), allocatable :: h(:, :), y(:, :), gg(:, :), t(:, :)
    integer :: m, r, i
    m = bc%m
    r = bc%nrig
    allocate (h(m, m), y(m, r), gg(r, r), t(r, m))
    h = bc%flex
    q = 0.0_wp
    do i = 1, m
      q(i, i) = 1.0_wp
    end do
    call dposv('U', m, m, h, m, q, m, info)
    if (info /= 0) return
    ! y = F^-1 G', gg = G F^-1 G': q -= y gg^-1 y'
    y = matmul(q, transpose(bc%rg))
    gg = matmul(bc%rg, y)
    t = transpose(y)
    call dposv('U', r, m, gg, r, t, r, info)
    if (info /= 0) return
    q = q - matmul(y, t)
    q = 0.5_wp*(q + transpose(q))
  end subroutine projected_inverse

  !> P F_a P with P = I - G_a'(G_a G_a')^-1 G_a, the orthogonal projector on the forces
  !! that G_a sees as balanced: a floating body's F_a = B_a K_a^+ B_a' depends on its fixing
  !! DOFs by terms in G_a' (rigid motions), and its response to a self-equilibrated force
  !! does not (P F_a P is the pseudo-inverse of the projected inverse Q_a, harmonic_floating).
  !! The 'steklov' correction of the other body's obstacle uses P F_a P: it vanishes on the
  !! rigid part, which the floating body's own equality settles, and S_1 + S_2 stays definite
  !! (the other body's part is), so the fixed point is still the monolithic solution. Its
  !! rate is not the supported case's: a floating body is far more flexible on balanced
  !! loads (a free-free block bends; README: the largest eigenvalue of P F_a P F_o^-1 is 14 on
  !! a 24x8 roller scene), and its measured rates depend on the fixing DOFs through the
  !! loosely solved first subproblems (README, the operator table).
  function projected_flex(bc) result(pf)
    type(body_condensed_t), intent(in) :: bc
    real(wp), allocatable :: pf(:, :), q(:, :), gg(:, :), y(:, :)
    integer :: m, r, info
    m = bc%m
    r = bc%nrig
    allocate (pf(m, m), q(r, m), gg(r, r), y(m, m))
    ! q = (G G')^-1 G, so that P x = x - G' (q x)
    gg = matmul(bc%rg, transpose(bc%rg))
    q = bc%rg
    call dposv('U', r, m, gg, r, q, r, info)
    ! y = P F = F - G' (q F);  pf = y P = y - (y q') G
    y = bc%flex - matmul(transpose(bc%rg), matmul(q, bc%flex))
    pf = y - matmul(matmul(y, transpose(q)), bc%rg)
    pf = 0.5_wp*(pf + transpose(pf))
  end function projected_flex

  !> corr(:, 1) = S_1 d (body 1's obstacle), corr(:, 2) = S_2 d (body 2's); `count` grows
  !! by the Hessian-sized products it took.
  subroutine correction_apply(self, d, corr, count)
    class(robin_correction_t), intent(inout) :: self
    real(wp), intent(in) :: d(:)
    real(wp), intent(out) :: corr(:, :)
    integer, intent(inout) :: count
    call self%s1%apply(d, corr(:, 1))
    if (associated(self%s2, self%s1)) then
      corr(:, 2) = corr(:, 1)
    else
      call self%s2%apply(d, corr(:, 2))
    end if
    count = count + self%cost
  end subroutine correction_apply

  !> Release an operator owned by the correction.
  subroutine correction_free(self)
    class(robin_correction_t), intent(inout) :: self
    nullify (self%s1, self%s2)
    if (associated(self%own)) deallocate (self%own)
  end subroutine correction_free

  !> y = alpha x ./ w (the constant Robin operator alpha M^-1, M the tributary lengths).
  subroutine inv_diag_apply(self, x, y)
    class(inv_diag_op_t), intent(inout) :: self
    real(wp), intent(in) :: x(:)
    real(wp), intent(out) :: y(:)
    y = self%alpha*x/self%w
  end subroutine inv_diag_apply

  !> The inner tolerance of outer iteration `it`. The harmonic operator makes the
  !! linearised outer map nilpotent at delta = 0.5: the outer iteration is as exact as its
  !! subproblems, so they are solved tightly (scaled by the contrast of the bodies: the
  !! stiff body's obstacle is built from the soft body's displacement, whose error the
  !! contrast amplifies), down to what rounding lets the projected gradient reach (a
  !! product with an m x m matrix carries ~ sqrt(m) eps of relative error: asking for less
  !! only spins MPRGP up to inner_max_it). The other operators follow the outer progress,
  !! min(increment, residual) of the previous iteration, times inner_factor, clamped.
  real(wp) function inner_tolerance(s, it, m, progress, lmax) result(rtol_in)
    type(solver_cfg_t), intent(in) :: s
    integer, intent(in) :: it, m
    real(wp), intent(in) :: progress, lmax(2)
    if (s%robin_operator == ROBIN_HARMONIC) then
      rtol_in = max(sqrt(real(max(m, 1), wp))*epsilon(1.0_wp), &
                    s%inner_factor*s%tol*minval(lmax)/max(maxval(lmax), tiny(1.0_wp)))
    else if (it == 1) then
      rtol_in = s%inner_rtol_max
    else
      rtol_in = min(s%inner_rtol_max, max(s%inner_rtol_min, s%inner_factor*progress))
    end if
  end function inner_tolerance

  !> Step 1: each body's contact problem against its obstacle (MPRGP, one thread per
  !! body), warm-started from the last contact forces. On return st%lam holds the forces,
  !! w(:, a) = B_a u_a, and res%status is 'failed' if an inner solve broke down.
  subroutine solve_subproblems(s, bc, op, pin, eq, lmax, rtol_in, it, st, w, res)
    type(solver_cfg_t), intent(in) :: s
    type(body_condensed_t), intent(in) :: bc(2)
    type(dense_op_t), intent(inout) :: op(2)      !< the subproblem Hessians F_a + Pi_a (+ rho G_a'G_a)
    type(dense_op_t), intent(inout) :: pin(2)     !< Pi_a (subproblem_operators; n = 0: none)
    type(eq_t), intent(in) :: eq(2)               !< equilibrium rows of floating bodies (r = 0: none)
    real(wp), intent(in) :: lmax(2), rtol_in
    integer, intent(in) :: it
    type(robin_state_t), intent(inout) :: st
    real(wp), intent(out) :: w(:, :)
    type(contact_result_t), intent(inout) :: res
    type(mprgp_opts_t) :: opts(2)
    type(mprgp_stats_t) :: ms(2)
    type(smalbe_stats_t) :: ss(2)
    real(wp), allocatable :: rhs(:, :), grad(:, :), lb(:), lam0(:, :), flam0(:, :), lprev(:, :)
    real(wp) :: feas
    integer :: a, m, k, r
    logical :: search
    m = size(w, 1)
    allocate (rhs(m, 2), grad(m, 2), lb(m), lam0(m, 2), flam0(m, 2))
    lb = 0.0_wp
    lprev = st%lam   ! the other body's last force, for a proximal term (subproblem_operators)
    ! A first line search along the last change of lam_a (its image under F_a is a
    ! difference of known products: no product) only while the outer iteration contracts
    ! at a steady rate: then the changes of lam_a are nearly parallel from one iteration to
    ! the next (linearised outer map), and the search puts the warm start close to the
    ! solution. In the transient (active set settling, delta = 1 oscillating) it is not
    ! used: there the outcome of the outer iteration depends on the inner iterates.
    ! Krylov recycling (README, Method): the last RECYCLE_DEPTH conjugate gradient
    ! directions of each body's solves are kept with their images under F_a, and each solve
    ! starts from the minimum over the warm start plus their span (and the last change of
    ! lam_a while `search`), no product; the step is taken only when it is feasible as a
    ! whole and leaves a proportional iterate with a smaller projected gradient. Not with
    ! Aitken or Anderson acceleration, whose updates difference past iterates and so
    ! amplify the (smaller but differently placed) inner errors.
    search = st%nsrch == 1 .and. smooth_outer(res, it)
    !$omp parallel do num_threads(body_threads()) schedule(static, 1) if (m > 64) private(k, r, feas)
    do a = 1, 2
      rhs(:, a) = bc(a)%b - st%G(:, a)
      if (pin(a)%n > 0) then
        ! a singular body is pinned to the other body's last force (subproblem_operators)
        call pin(a)%apply(lprev(:, 3 - a), grad(:, a))
        rhs(:, a) = rhs(:, a) + grad(:, a)
      end if
      ! The tolerance is measured against the body's own contact displacement
      ! |F_a lam_a| (previous iterate), not against |b_a - G_a|: with a large
      ! material contrast the stiff body's b_a - G_a is a small difference of the
      ! soft body's large displacements, and a tolerance relative to it would leave
      ! the stiff body's force inaccurate by the contrast ratio.
      if (st%flam(a) > 0.0_wp) then
        opts(a)%rtol = 0.0_wp
        opts(a)%atol = max(rtol_in*st%flam(a), 4.0_wp*epsilon(1.0_wp)*norm2(rhs(:, a)))
      else
        opts(a)%rtol = rtol_in
        opts(a)%atol = 0.0_wp
      end if
      opts(a)%max_it = s%inner_max_it
      opts(a)%lambda_max = lmax(a)
      ! F_a is the same in every iteration and the warm start is the last solution:
      ! its gradient comes from F_a lam_a of the last solve (no initial product)
      opts(a)%use_ax = st%reuse == 1
      lam0(:, a) = st%lam(:, a)
      flam0(:, a) = st%flam_v(:, a)
      opts(a)%recycle = s%acceleration == ACCEL_NONE
      k = size(st%rw, 2)/2
      r = eq(a)%r
      ss(a)%updates = 0
      if (m > 0 .and. r > 0) then
        ! a floating body: its equilibrium G_a lam = e_a as an equality (SMALBE-M)
        ! the body's equilibrium to the accuracy asked of its forces (the harmonic operator's
        ! contrast-scaled tolerance: a soft floating body's rigid motion enters the stiff body's
        ! obstacle), down to the rounding of G lam
        feas = max(rtol_in, 10.0_wp*sqrt(real(m, wp))*epsilon(1.0_wp), FEAS_RTOL_MIN)*norm2(eq(a)%e)
        if (search) then
          call smalbe_solve(op(a), rhs(:, a), eq(a)%g, eq(a)%e, eq(a)%rho, lb, st%lam(:, a), st%mu(1:r, a), &
                            opts(a), eq(a)%m0, feas, ss(a), grad(:, a), st%flam_v(:, a), &
                            st%srch(:, a), st%fsrch(:, a), st%rw(:, (a - 1)*k + 1:a*k), &
                            st%raw(:, (a - 1)*k + 1:a*k), st%nrw(:, a))
        else
          call smalbe_solve(op(a), rhs(:, a), eq(a)%g, eq(a)%e, eq(a)%rho, lb, st%lam(:, a), st%mu(1:r, a), &
                            opts(a), eq(a)%m0, feas, ss(a), grad(:, a), st%flam_v(:, a), &
                            rw=st%rw(:, (a - 1)*k + 1:a*k), raw=st%raw(:, (a - 1)*k + 1:a*k), nrw=st%nrw(:, a))
        end if
        ms(a) = ss(a)%inner
        ms(a)%n_matvec = ss(a)%n_matvec
      else if (m > 0 .and. search) then
        call mprgp_solve(op(a), rhs(:, a), lb, st%lam(:, a), opts(a), ms(a), grad(:, a), st%flam_v(:, a), &
                         st%srch(:, a), st%fsrch(:, a), st%rw(:, (a - 1)*k + 1:a*k), st%raw(:, (a - 1)*k + 1:a*k), &
                         st%nrw(:, a))
      else if (m > 0) then
        call mprgp_solve(op(a), rhs(:, a), lb, st%lam(:, a), opts(a), ms(a), grad(:, a), st%flam_v(:, a), &
                         rw=st%rw(:, (a - 1)*k + 1:a*k), raw=st%raw(:, (a - 1)*k + 1:a*k), nrw=st%nrw(:, a))
      end if
      st%srch(:, a) = st%lam(:, a) - lam0(:, a)
      st%fsrch(:, a) = st%flam_v(:, a) - flam0(:, a)
    end do
    !$omp end parallel do
    if (m == 0) return
    do a = 1, 2
      st%inner = st%inner + ms(a)%n_matvec
      res%eq_updates = res%eq_updates + ss(a)%updates
      if (ms(a)%status == MPRGP_MAX_IT) then
        res%inner_maxit_hits = res%inner_maxit_hits + 1
      else if (ms(a)%status /= MPRGP_CONVERGED) then
        res%status = STATUS_FAILED
        write (res%message, '(a,i0,a,i0,a)') 'MPRGP failed on body ', a, ' at outer iteration ', it, &
          ': '//trim(mprgp_status_name(ms(a)%status))//': '//trim(ms(a)%message)
        return
      end if
      ! B_a u_a = b_a - F_a lam_a = G_a - grad_a (with a proximal term: F_a lam_a is the
      ! Hessian's image grad_a + rhs_a less the proximal part)
      if (pin(a)%n > 0) then
        call pin(a)%apply(st%lam(:, a), flam0(:, a))
        flam0(:, a) = grad(:, a) + rhs(:, a) - flam0(:, a)
        w(:, a) = bc(a)%b - flam0(:, a)
        st%flam(a) = norm2(flam0(:, a))
      else
        w(:, a) = st%G(:, a) - grad(:, a)
        st%flam(a) = norm2(grad(:, a) + rhs(:, a))
      end if
    end do
    st%nsrch = st%reuse
    st%reuse = 1
  end subroutine solve_subproblems

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

  !> The true residual of the iterate, the increment of the obstacles (the paper's
  !! criterion), the stopping criterion, the new state and one history entry.
  subroutine record_iteration(s, itf, bc, it, Gnew, w, t0, st, res)
    type(solver_cfg_t), intent(in) :: s
    type(interface_t), intent(in) :: itf
    type(body_condensed_t), intent(in) :: bc(2)
    integer, intent(in) :: it
    real(wp), intent(in) :: Gnew(:, :), w(:, :), t0
    type(robin_state_t), intent(inout) :: st
    type(contact_result_t), intent(inout) :: res
    real(wp) :: denom(2), ref, incr
    integer :: a
    res%lam_body = st%lam
    res%w = w
    res%rigid = -st%mu
    call interface_residual(itf, bc, res)
    ref = tiny(1.0_wp) + 1.0e-14_wp*(maxabs(bc(1)%b) + maxabs(bc(2)%b) + maxabs(itf%g0))
    do a = 1, 2
      denom(a) = max(norm2(Gnew(:, a)), ref)
    end do
    incr = norm2(Gnew(:, 1) - st%G(:, 1))/denom(1) + norm2(Gnew(:, 2) - st%G(:, 2))/denom(2)
    if (s%stop == STOP_RESIDUAL) then
      st%crit = res%residual
    else
      st%crit = incr
    end if
    ! the inner tolerance follows the outer progress: both the increment and the
    ! residual must shrink before the subproblems are solved tightly (a tolerance
    ! tied to the residual alone can freeze the obstacles and stall the iteration)
    st%progress = min(incr, res%residual)
    st%G = Gnew
    st%it = it
    st%wall = wtime() - t0
    res%obstacle = st%G
    res%outer = it
    res%inner = st%inner
    res%criterion = st%crit
    if (it > size(res%h_criterion)) call grow_history(res, min(s%max_outer, 2*size(res%h_criterion) + HISTORY_CHUNK))
    res%nhist = it
    res%h_criterion(it) = st%crit
    res%h_residual(it) = res%residual
    res%h_inner(it) = st%inner
    res%h_active(it) = res%active
    res%h_wall(it) = st%wall
  end subroutine record_iteration

  !> True when the iteration ends after iteration `it`: converged, or diverged (a
  !! non-finite or exploding criterion, obstacles beyond 1e6 times the load displacement
  !! scale `uref`, a residual stop that stagnates, a small increment with a large residual
  !! for too long). Sets res%status and res%message.
  logical function check_termination(s, it, uref, st, res) result(done)
    type(solver_cfg_t), intent(in) :: s
    integer, intent(in) :: it
    real(wp), intent(in) :: uref
    type(robin_state_t), intent(inout) :: st
    type(contact_result_t), intent(inout) :: res
    done = .true.
    if (.not. ieee_is_finite(st%crit)) then
      res%status = STATUS_DIVERGED
      write (res%message, '(a,i0)') 'non-finite criterion at iteration ', it
      return
    end if
    st%best = min(st%best, st%crit)
    if (it > 10 .and. st%crit > 1.0e4_wp*st%best .and. st%crit > 1.0_wp) then
      res%status = STATUS_DIVERGED
      write (res%message, '(a,es10.3,a,es10.3)') 'criterion grew to ', st%crit, ' from its best ', st%best
      return
    end if
    ! a relative increment stays bounded while the iterates blow up geometrically:
    ! watch the size of the obstacles against the displacements the loads cause
    if (maxval(abs(st%G)) > 1.0e6_wp*uref) then
      res%status = STATUS_DIVERGED
      write (res%message, '(a,es10.3,a,es10.3,a)') 'obstacles grew to ', maxval(abs(st%G)), &
        ' (1e6 times the load displacement scale ', uref, ')'
      return
    end if
    ! the residual stop: a residual that has not improved by 1% in FLAT_LIMIT iterations
    ! has reached the floor that rounding and conditioning allow; tol is out of reach
    if (res%residual < 0.99_wp*st%res_best) then
      st%res_best = res%residual
      st%it_best = it
    end if
    if (s%stop == STOP_RESIDUAL .and. st%crit > s%tol .and. it - st%it_best >= FLAT_LIMIT) then
      res%status = STATUS_DIVERGED
      write (res%message, '(a,es10.3,a,i0,a,es10.3,a)') 'stagnated: the residual has stayed near ', &
        st%res_best, ' for ', FLAT_LIMIT, ' iterations; tol = ', s%tol, ' is out of reach'
      return
    end if
    if (st%crit <= s%tol) then
      if (s%stop /= STOP_RESIDUAL .and. res%residual > 1.0e2_wp*s%tol) then
        ! the obstacles stopped moving but the bodies do not agree yet: a small
        ! increment is not a small error. Go on (the inner tolerance follows the
        ! smaller increment); if it persists, the iteration has stagnated.
        st%stalled = st%stalled + 1
        if (st%stalled >= STALL_LIMIT) then
          res%status = STATUS_DIVERGED
          write (res%message, '(a,es10.3,a,es10.3,a,i0,a)') 'stagnated: increment ', st%crit, &
            ' below tol but residual ', res%residual, ' above 100 tol for ', STALL_LIMIT, &
            ' iterations (the bodies do not agree)'
          return
        end if
      else
        res%status = STATUS_CONVERGED
        return
      end if
    else
      st%stalled = 0
    end if
    done = .false.
  end function check_termination

  !> z = the Euclidean projection of y on {l >= 0, G l = e} (G, e: both bodies'
  !! equilibrium rows, stacked): z = max(0, y - G'nu) with nu the minimiser of the convex,
  !! piecewise quadratic phi(nu) = 1/2 |max(0, y - G'nu)|^2 + e'nu (r <= 6 unknowns), by Newton
  !! steps on the current positive set (Hessian G_P G_P', a small ridge when it is singular)
  !! with a backtracking line search on phi: exact once the positive set is right, whatever
  !! the conditioning of G on it. perr bounds |z - exact projection| by the equilibrium
  !! left, |G z - e| / sqrt(lambda_min(G_P G_P')).
  subroutine project_feasible(bc, y, z, perr)
    type(body_condensed_t), intent(in) :: bc(2)
    real(wp), intent(in) :: y(:)
    real(wp), allocatable, intent(out) :: z(:)
    real(wp), intent(out) :: perr
    real(wp), allocatable :: gs(:, :), es(:), nu(:), f(:), h(:, :), d(:), nt(:), gp(:, :)
    real(wp) :: phi, phit, t, ridge, lmin
    integer :: m, r1, r, it, k, info
    m = size(y)
    r1 = bc(1)%nrig
    r = r1 + bc(2)%nrig
    allocate (gs(r, m), es(r), nu(r), f(r), h(r, r), d(r), nt(r))
    if (r1 > 0) gs(1:r1, :) = bc(1)%rg
    if (r1 > 0) es(1:r1) = bc(1)%re
    if (bc(2)%nrig > 0) gs(r1 + 1:, :) = bc(2)%rg
    if (bc(2)%nrig > 0) es(r1 + 1:) = bc(2)%re
    nu = 0.0_wp
    z = max(y - matmul(nu, gs), 0.0_wp)
    phi = 0.5_wp*sum(z**2) + dot_product(es, nu)
    ridge = 1.0e-14_wp*maxval(sum(gs**2, dim=2))
    do it = 1, 200
      f = matmul(gs, z) - es           ! = -grad phi
      if (norm2(f) <= 1.0e-15_wp*max(norm2(es), tiny(1.0_wp))) exit
      gp = gs(:, pack([(k, k=1, m)], z > 0.0_wp))
      h = matmul(gp, transpose(gp))
      do k = 1, r
        h(k, k) = h(k, k) + ridge
      end do
      d = f
      call dposv('U', r, 1, h, r, d, r, info)
      if (info /= 0) exit
      ! Newton direction for phi is +d (phi's Hessian G_P G_P', gradient -f); backtrack
      t = 1.0_wp
      do k = 1, 60
        nt = nu + t*d
        phit = 0.5_wp*sum(max(y - matmul(nt, gs), 0.0_wp)**2) + dot_product(es, nt)
        if (phit <= phi - 1.0e-4_wp*t*dot_product(f, d)) exit
        t = 0.5_wp*t
      end do
      if (k > 60) exit
      nu = nt
      phi = phit
      z = max(y - matmul(nu, gs), 0.0_wp)
    end do
    f = matmul(gs, z) - es
    gp = gs(:, pack([(k, k=1, m)], z > 0.0_wp))
    lmin = 0.0_wp
    if (size(gp, 2) > 0) lmin = minval(gram_eigenvalues(gp))
    perr = norm2(f)/sqrt(max(lmin, tiny(1.0_wp)))
    if (.not. lmin > 0.0_wp) perr = merge(0.0_wp, huge(1.0_wp), norm2(f) == 0.0_wp)
  end subroutine project_feasible

  !> The eigenvalues of G G' (r <= 6 rows), ascending; if LAPACK fails, 0 and, last, the
  !! row-sum bound of the largest (what eq_init's penalty and project_feasible's error bound
  !! can still use safely).
  function gram_eigenvalues(gs) result(ev)
    real(wp), intent(in) :: gs(:, :)
    real(wp) :: ev(size(gs, 1))
    real(wp) :: work(64), gg(size(gs, 1), size(gs, 1))
    integer :: r, info
    r = size(gs, 1)
    gg = matmul(gs, transpose(gs))
    call dsyev('N', 'U', r, gg, r, ev, work, size(work), info)
    if (info /= 0) then
      gg = matmul(gs, transpose(gs))
      ev = 0.0_wp
      ev(r) = maxval(sum(abs(gg), dim=1))
    end if
  end function gram_eigenvalues

  !> The equality rows G lam = e of floating bodies for a QP whose Hessian H has its
  !! largest eigenvalue below lmax: the penalty rho = RHO_FACTOR lmax / lambda_max(G G')
  !! (A = H + rho G'G stays within (1 + RHO_FACTOR) lmax, and a multiplier update
  !! reduces |G lam - e| by about 1 / (1 + RHO_FACTOR)), SMALBE's initial
  !! M = lmax / sqrt(lambda_max(G G')) (a gradient per unit of force imbalance), and the
  !! equilibrium tolerance FEAS_RTOL |e|.
  subroutine eq_init(q, g, e, lmax)
    type(eq_t), intent(out) :: q
    real(wp), intent(in) :: g(:, :), e(:), lmax
    q%r = size(g, 1)
    q%g = g
    q%e = e
    q%gg = max(maxval(gram_eigenvalues(g)), tiny(1.0_wp))
    q%rho = RHO_FACTOR*lmax/q%gg
    q%m0 = lmax/sqrt(q%gg)
    q%feas = FEAS_RTOL*max(norm2(e), tiny(1.0_wp))
  end subroutine eq_init

  !> Add the penalty rho G'G to the dense Hessian and its bound to lmax.
  subroutine eq_add(q, op, lmax)
    type(eq_t), intent(in) :: q
    type(dense_op_t), intent(inout) :: op
    real(wp), intent(inout) :: lmax
    integer :: m
    m = size(q%g, 2)
    call dgemm('T', 'N', m, m, q%r, q%rho, q%g, q%r, q%g, q%r, 1.0_wp, op%a, m)
    lmax = lmax + q%rho*q%gg
  end subroutine eq_add

  !> A posteriori bound of the error of res%lam against the monolithic solution lam*
  !! of the same discrete problem: for the strongly convex QP min 1/2 l'Hl - c'l, l >= 0
  !! (H = F_1 + F_2, c = b_1 + b_2 - g0) and the natural residual
  !! r = l - max(0, l - (Hl - c)/L), |l - lam*| <= 2 (L/mu) |r| with L, mu the extreme
  !! eigenvalues of H (estimated by power and inverse iteration, kappa enlarged by 10%).
  !! Sets res%error_bound (relative to |lam|) and res%kappa.
  subroutine error_bound(itf, bc, res)
    type(interface_t), intent(in) :: itf               !< contact line
    type(body_condensed_t), intent(in) :: bc(2)        !< condensed bodies
    type(contact_result_t), intent(inout) :: res       !< lam in; error_bound, kappa out
    real(wp), allocatable :: H(:, :), A(:, :), g(:), r(:), x(:), y(:)
    real(wp) :: lmax, lmin, nl, perr
    integer :: m, i, k, info
    m = itf%m
    res%error_bound = 0.0_wp
    res%kappa = 1.0_wp
    if (m == 0) return
    allocate (H(m, m), A(m, m), g(m), r(m), x(m), y(m))
    H = bc(1)%flex + bc(2)%flex
    ! largest eigenvalue: power iteration (a lower estimate, enlarged below)
    do i = 1, m
      x(i) = 1.0_wp + 0.5_wp*sin(real(i, wp))
    end do
    x = x/norm2(x)
    lmax = 0.0_wp
    do k = 1, 60
      call dsymv('U', m, 1.0_wp, H, m, x, 1, 0.0_wp, y, 1)
      lmax = norm2(y)
      if (.not. lmax > 0.0_wp) exit
      x = y/lmax
    end do
    ! smallest eigenvalue: inverse iteration on the Cholesky factor of H
    A = H
    call dpotrf('U', m, A, m, info)
    if (info /= 0 .or. .not. lmax > 0.0_wp) then
      res%error_bound = huge(1.0_wp)
      res%kappa = huge(1.0_wp)
      return
    end if
    do i = 1, m
      x(i) = 1.0_wp + 0.5_wp*cos(real(3*i, wp))
    end do
    x = x/norm2(x)
    do k = 1, 60
      y = x
      call dpotrs('U', m, 1, A, m, y, m, info)
      x = y/norm2(y)
    end do
    call dsymv('U', m, 1.0_wp, H, m, x, 1, 0.0_wp, y, 1)
    lmin = dot_product(x, y)
    res%kappa = 1.1_wp*lmax/max(lmin, tiny(1.0_wp))
    if (.not. (ieee_is_finite(res%kappa) .and. ieee_is_finite(lmax) .and. lmax > 0.0_wp)) then
      ! out of the range of double precision: no bound can be given
      res%kappa = huge(1.0_wp)
      res%error_bound = huge(1.0_wp)
      return
    end if
    ! natural residual of the mean contact force
    call dsymv('U', m, 1.0_wp, H, m, res%lam, 1, 0.0_wp, g, 1)
    g = g - (bc(1)%b + bc(2)%b - itf%g0)
    if (bc(1)%nrig + bc(2)%nrig > 0) then
      ! floating bodies: the feasible set is {l >= 0, G l = e}, and the bound holds with
      ! the projection on it (the proof only uses the projection's variational inequality
      ! and the strong convexity of the objective on R^m), computed by SMALBE-M; its own
      ! inaccuracy (projected gradient and equilibrium of the projection) is added
      call project_feasible(bc, res%lam - g/lmax, y, perr)
      r = res%lam - y
    else
      r = res%lam - max(0.0_wp, res%lam - g/lmax)
      perr = 0.0_wp
    end if
    nl = norm2(res%lam)
    ! the residual itself is computed in floating point: add its rounding level
    if (.not. perr < 0.01_wp*huge(1.0_wp)) then
      ! the projection on the feasible set is not known to any accuracy: no bound
      res%error_bound = huge(1.0_wp)
    else if (nl > 0.0_wp) then
      res%error_bound = 2.0_wp*res%kappa*((norm2(r) + perr)/nl + 10.0_wp*real(m, wp)*epsilon(1.0_wp))
    else
      res%error_bound = merge(0.0_wp, huge(1.0_wp), norm2(r) == 0.0_wp)
    end if
  end subroutine error_bound


  !> Relaxed or accelerated fixed-point update: on entry Gnew = T(G), on exit the
  !! next obstacles. The residual of the fixed point is r = T(G) - G.
  subroutine accelerate(kind, delta, st, Gnew)
    integer, intent(in) :: kind                  !< ACCEL_*
    real(wp), intent(in) :: delta
    type(robin_state_t), intent(inout) :: st
    real(wp), intent(inout) :: Gnew(:, :)
    real(wp), allocatable :: x(:), r(:), dr(:), gam(:), qr(:, :), rhs(:), work(:)
    integer :: n2, k, j, info, lwork
    real(wp) :: den
    n2 = 2*size(Gnew, 1)
    allocate (x(n2), r(n2))
    x = reshape(st%G, [n2])
    r = reshape(Gnew, [n2]) - x
    select case (kind)
    case (ACCEL_AITKEN)
      ! Irons-Tuck dynamic relaxation: omega_k = -omega_{k-1} r_{k-1}'(r_k - r_{k-1}) / |r_k - r_{k-1}|^2
      if (st%nacc == 0) then
        st%omega = delta
      else
        allocate (dr(n2))
        dr = r - st%r_prev
        den = dot_product(dr, dr)
        if (den > 0.0_wp) then
          st%omega = -st%omega*dot_product(st%r_prev, dr)/den
          ! keep the relaxation in a safe band
          st%omega = max(-2.0_wp, min(2.0_wp, st%omega))
          if (abs(st%omega) < 1.0e-3_wp) st%omega = sign(1.0e-3_wp, st%omega)
        end if
      end if
      st%r_prev = r
      st%nacc = st%nacc + 1
      x = x + st%omega*r
    case (ACCEL_ANDERSON)
      ! Anderson mixing of depth ANDERSON_DEPTH with mixing parameter delta:
      ! x+ = x + delta r - (dX + delta dR) gamma, gamma = argmin |r - dR gamma|
      if (st%nacc > 0) then
        j = mod(st%nacc - 1, ANDERSON_DEPTH) + 1
        st%dX(:, j) = x - st%x_prev
        st%dR(:, j) = r - st%r_prev
      end if
      st%x_prev = x
      st%r_prev = r
      k = min(st%nacc, ANDERSON_DEPTH)
      st%nacc = st%nacc + 1
      if (k > 0) then
        allocate (qr(n2, k), rhs(n2), gam(k))
        qr = st%dR(:, 1:k)
        rhs = r
        lwork = -1
        allocate (work(1))
        call dgels('N', n2, k, 1, qr, n2, rhs, n2, work, lwork, info)
        lwork = max(1, int(work(1)))
        deallocate (work)
        allocate (work(lwork))
        call dgels('N', n2, k, 1, qr, n2, rhs, n2, work, lwork, info)
        if (info == 0 .and. all_finite(rhs(1:k))) then
          gam = rhs(1:k)
          x = x + delta*r - matmul(st%dX(:, 1:k) + delta*st%dR(:, 1:k), gam)
        else
          x = x + delta*r
        end if
      else
        x = x + delta*r
      end if
    case default
      x = x + delta*r
    end select
    Gnew = reshape(x, shape(Gnew))
  end subroutine accelerate

  !> S = 2 F_1 (F_1 + F_2)^-1 F_2 = 2 (F_1^-1 + F_2^-1)^-1 (symmetric positive definite).
  subroutine harmonic_operator(F1, F2, S, info)
    real(wp), intent(in) :: F1(:, :), F2(:, :)
    real(wp), allocatable, intent(out) :: S(:, :)
    integer, intent(out) :: info
    real(wp), allocatable :: A(:, :), X(:, :)
    integer :: m
    m = size(F1, 1)
    allocate (A(m, m), X(m, m), S(m, m))
    A = F1 + F2
    X = F2
    call dposv('U', m, m, A, m, X, m, info)
    if (info /= 0) return
    call dgemm('N', 'N', m, m, m, 2.0_wp, F1, m, X, m, 0.0_wp, S, m)
    S = 0.5_wp*(S + transpose(S))
  end subroutine harmonic_operator


  !> Gap, imbalance, penetration and complementarity of res%lam_body, res%w.
  subroutine interface_residual(itf, bc, res)
    type(interface_t), intent(in) :: itf               !< contact line
    type(body_condensed_t), intent(in) :: bc(2)        !< condensed bodies (scales)
    type(contact_result_t), intent(inout) :: res       !< lam_body, w in; residuals out
    real(wp) :: uscale, lnorm, lmax
    integer :: i
    if (itf%m == 0) then
      res%residual = 0.0_wp
      return
    end if
    res%lam = 0.5_wp*(res%lam_body(:, 1) + res%lam_body(:, 2))
    res%gap = res%w(:, 1) + res%w(:, 2) - itf%g0
    uscale = max(maxabs(bc(1)%b), maxabs(bc(2)%b), maxabs(itf%g0), maxabs(res%w(:, 1)), &
                 maxabs(res%w(:, 2)), tiny(1.0_wp))
    lnorm = norm2(res%lam)
    lmax = maxval(res%lam)
    if (lnorm > 0.0_wp) then
      res%imbalance = norm2(res%lam_body(:, 1) - res%lam_body(:, 2))/lnorm
    else
      res%imbalance = 0.0_wp
    end if
    res%penetration = max(maxval(res%gap), 0.0_wp)/uscale
    res%complementarity = 0.0_wp
    if (lmax > 0.0_wp) then
      do i = 1, itf%m
        res%complementarity = max(res%complementarity, max(res%lam(i), 0.0_wp)*abs(res%gap(i)))
      end do
      res%complementarity = res%complementarity/(lmax*uscale)
    end if
    ! a floating body's equilibrium (its load against its own contact force): an inner
    ! solve that stopped on inner_max_it may leave it unmet, and then no run converges
    res%equilibrium = 0.0_wp
    do i = 1, 2
      if (bc(i)%nrig == 0) cycle
      res%equilibrium = max(res%equilibrium, norm2(matmul(bc(i)%rg, res%lam_body(:, i)) - bc(i)%re)/ &
                            max(norm2(bc(i)%re), tiny(1.0_wp)))
    end do
    res%residual = max(res%imbalance, res%penetration, res%complementarity, res%equilibrium)
    res%active = count(res%lam > 0.0_wp)
  end subroutine interface_residual


  real(wp) function maxabs(x)
    real(wp), intent(in) :: x(:)
    maxabs = 0.0_wp
    if (size(x) > 0) maxabs = maxval(abs(x))
  end function maxabs

  logical function all_finite(x)
    real(wp), intent(in) :: x(..)
    select rank (x)
    rank (1)
      all_finite = all(ieee_is_finite(x))
    rank (2)
      all_finite = all(ieee_is_finite(x))
    rank default
      all_finite = .false.
    end select
  end function all_finite

  !> Threads for the two bodies: min(2, OMP max threads).
  integer function body_threads()
    use omp_lib, only: omp_get_max_threads
    body_threads = max(1, min(2, omp_get_max_threads()))
  end function body_threads

end module contact
