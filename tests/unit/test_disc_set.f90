!> Unit tests of the friction set of 3D contact (module tangent_discs: l_n >= 0 on a node's normal
!! force, |(l_t1, l_t2)| <= r on its two tangential ones) and of MPRGP on it (MPGP):
!!  - each method against its formula written out here: projection (a point outside its
!!    disc lands on the circle along its own direction), free set, chopped gradient (zero
!!    exactly at a KKT point g = -s nu, the tangential part along the circle otherwise),
!!    projected step and reduced gradient (x - alpha phit = P(x - alpha g)), the feasible
!!    step (x + t d on the circle, from inside, for either sign of x.d), the cut of a step,
!!    a disc of radius 0 (a fixed point);
!!  - the refusal of bad sets (a negative or NaN radius, a pair out of range, a variable in
!!    two pairs);
!!  - friction_set: a box when there are no pairs (the plane: a tangential force in
!!    [-t, t]), discs of radius ub(pair(1, k)) otherwise; a disc of radius huge (Coulomb's
!!    first solve) never binds, and a step towards it is not cut;
!!  - MPGP: with A = I the minimiser is the projection of b (exact); isotropy, the same
!!    2 x 2 problem with b turned by 0, 15, 30 and 45 degrees in the plane gives the force on
!!    the circle along b every time (a box fails this by up to 41%); 30 nodes with a random
!!    SPD A (condition 1e2): the KKT conditions checked from A x - b, and the minimiser
!!    against an independent method written here (projected gradient with Nesterov's
!!    momentum, FISTA, 20000 steps);
!!  - the Newton method along the circles (module disc_newton): the same minimiser as MPGP's
!!    on that problem, and at condition 1e6 (40 nodes) the KKT conditions to 1e-10 |b|
!!    within 200 steps; 'auto' (MPGP within its budget, then that method) at condition 1e3:
!!    switched, MPGP's minimiser at fewer products;
!!  - a sequence of nearby problems (the same A, b and radii moved a little each time, as the
!!    Robin iteration's solves of a body), each from the last answer: started from its face
!!    with the factor carried from solve to solve, bit for bit the answers of the same
!!    starts with a new factor each solve, with fewer factorizations, and the minimisers of
!!    the default start (the binding set) to 1e-9 with the KKT conditions to 1e-10 |b|.
!! One line per check: PASS/FAIL. Exits with status 1 if any check failed.
program test_disc_set
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use kinds, only: wp
  use errors, only: error_t, ERR_INPUT, ERR_NUMERICAL
  use linop, only: dense_op_t, dense_op_init
  use tangent_discs, only: disc_set_t, disc_set, friction_set
  use constraint_set, only: constraint_set_t
  use mprgp, only: mprgp_t, MPRGP_CONVERGED, QP_NEWTON, QP_MPRGP, QP_AUTO
  use lapack, only: dposv
  use disc_newton, only: disc_factor_t, face_solve
  use strings, only: i2s
  use testing, only: report, report_le, test_summary, set_seed, urand, random_spd
  implicit none (type, external)

  real(wp), parameter :: big = huge(1.0_wp), eps = epsilon(1.0_wp), pi = acos(-1.0_wp)

  call set_seed(20261129)
  call test_pointwise()
  call test_steps()
  call test_validate()
  call test_friction_set()
  call test_identity()
  call test_isotropy()
  call test_random_qp()
  call test_newton_hard()
  call test_auto()
  call test_carried_factor()
  call test_warm_sequence()
  call test_summary()

contains

  !> friction_set: a box, or discs on the pairs with the radius from ub.
  subroutine test_friction_set()
    class(constraint_set_t), allocatable :: box, disc, open
    real(wp) :: x(3), t
    integer :: blocker
    ! no pairs: the box [lb, ub]; (3, 4) lands on (2, 2) componentwise
    box = friction_set([0.0_wp, -2.0_wp, -2.0_wp], [big, 2.0_wp, 2.0_wp], reshape([integer ::], [2, 0]))
    x = [1.0_wp, 3.0_wp, 4.0_wp]
    call box%project(x)
    call report(box%linear() .and. all(x == [1.0_wp, 2.0_wp, 2.0_wp]), 'friction_set without pairs: the box', x(3))
    ! a pair: the disc of radius 2; (3, 4) lands on 2 (3, 4) / 5
    disc = friction_set([0.0_wp, -2.0_wp, -2.0_wp], [big, 2.0_wp, 2.0_wp], reshape([2, 3], [2, 1]))
    x = [1.0_wp, 3.0_wp, 4.0_wp]
    call disc%project(x)
    call report_le(maxval(abs(x - [1.0_wp, 1.2_wp, 1.6_wp])), 2.0_wp*eps, 'friction_set with a pair: its disc')
    call report(.not. disc%linear(), 'friction_set with a pair: not linear', 0.0_wp)
    ! radius huge: nothing binds, no step is cut, no overflow (the checked build traps it)
    open = friction_set([0.0_wp, -big, -big], [big, big, big], reshape([2, 3], [2, 1]))
    x = [1.0_wp, 1.0e300_wp, 1.0e300_wp]
    call open%project(x)
    call open%max_step(x, [0.0_wp, 1.0e300_wp, 1.0e300_wp], 1.0_wp, t, blocker)
    call report(all(x == [1.0_wp, 1.0e300_wp, 1.0e300_wp]) .and. t == 1.0_wp .and. blocker == 0, &
                'friction_set, radius huge: no projection, no cut', t)
  end subroutine test_friction_set

  !> K nodes: variable 3k-2 the normal force (>= 0), 3k-1 and 3k its disc of radius r(k).
  function node_set(r) result(set)
    real(wp), intent(in) :: r(:)
    type(disc_set_t) :: set
    integer :: k, nk
    real(wp), allocatable :: lb(:)
    nk = size(r)
    allocate (lb(3*nk), source=-big)
    lb(1:3*nk:3) = 0.0_wp
    set = disc_set(lb, reshape([(3*k - 1, 3*k, k=1, nk)], [2, nk]), r)
  end function node_set

  !> Projection, free set, chopped and projected gradients, on four nodes: inside, outside,
  !! on the circle, and a disc of radius 0.
  subroutine test_pointwise()
    type(disc_set_t) :: set
    real(wp) :: x(12), y(12), g(12), v(12), w(12), nu(2), tg(2)
    logical :: free(12)
    set = node_set([1.0_wp, 2.0_wp, 0.5_wp, 0.0_wp])
    x = [0.3_wp, 0.2_wp, -0.4_wp, -0.1_wp, 3.0_wp, 4.0_wp, 0.0_wp, 0.3_wp, -0.4_wp, 0.2_wp, 0.1_wp, 0.1_wp]
    y = x
    call set%project(y)
    call report(all(y(1:3) == x(1:3)) .and. y(4) == 0.0_wp .and. y(7) == 0.0_wp, &
                'project: a point inside its disc and a normal force >= 0 stay; a negative normal force goes to 0')
    call report_le(abs(hypot(y(5), y(6)) - 2.0_wp) + abs(y(5)*x(6) - y(6)*x(5)), 4.0_wp*eps, &
                   'project: (3, 4) onto the circle of radius 2 along its own direction')
    call report(y(8) == x(8) .and. y(9) == x(9) .and. all(y(11:12) == 0.0_wp), &
                'project: a point on its circle stays; a disc of radius 0 is the origin')
    call set%free_mask(y, free)
    call report(free(1) .and. free(2) .and. free(3) .and. .not. any(free(5:6)) .and. .not. any(free(8:9)) .and. &
                .not. any(free(11:12)) .and. .not. free(4) .and. .not. free(7), &
                'free set: inside free, on a circle (both variables) or at 0 not')
    ! on the circle of node 3 (radius 0.5, point (0.3, -0.4)): nu = (0.6, -0.8), tangent (0.8, 0.6)
    nu = [0.6_wp, -0.8_wp]
    tg = [0.8_wp, 0.6_wp]
    g = 1.0_wp
    g(8:9) = -2.5_wp*nu
    call set%chopped_gradient(y, g, v)
    call set%projected_gradient(y, g, w)
    call report(all(v(8:9) == 0.0_wp) .and. all(w(8:9) == 0.0_wp), 'KKT on a circle (g = -s nu, s > 0): beta = gP = 0')
    g(8:9) = -2.5_wp*nu + 0.7_wp*tg
    call set%chopped_gradient(y, g, v)
    call report_le(maxval(abs(v(8:9) - 0.7_wp*tg)), 4.0_wp*eps, 'chopped on a circle: the part along it (g = -s nu + c t)')
    g(8:9) = 1.5_wp*nu + 0.7_wp*tg
    call set%chopped_gradient(y, g, v)
    call report_le(maxval(abs(v(8:9) - g(8:9))), 4.0_wp*eps, 'chopped on a circle: all of g when -g points inside')
    call set%free_gradient(y, g, v)
    call report(all(v(1:3) == g(1:3)) .and. all(v(5:6) == 0.0_wp) .and. all(v(8:9) == 0.0_wp) .and. &
                all(v(11:12) == 0.0_wp), 'free gradient: g inside, 0 on circles and at radius 0')
    g(11:12) = [3.0_wp, -1.0_wp]
    call set%projected_gradient(y, g, w)
    call report(all(w(11:12) == 0.0_wp) .and. all(w(1:3) == g(1:3)) .and. w(4) == min(g(4), 0.0_wp), &
                'projected gradient: 0 on a disc of radius 0, g inside, the box''s on a normal force')
    call set%reduced_gradient(y, g, 0.0_wp, v)
    call report(all(v(2:3) == g(2:3)), 'reduced gradient without a step length: phi')
  end subroutine test_pointwise

  !> The feasible step from inside a disc, for x.d of either sign, the blocker and `pin`,
  !! the cut of a step, the step bound, and the projected step against its definition.
  subroutine test_steps()
    type(disc_set_t) :: set
    real(wp) :: x(6), d(6), v(6), phit(6), y(6), g(6), t, t2, s
    integer :: blk, trial
    logical :: free(6), cut
    set = node_set([1.0_wp, 2.0_wp])
    do trial = 1, 2
      x = [0.5_wp, 0.6_wp, 0.7_wp, 0.1_wp, 0.0_wp, 0.0_wp]
      d = 0.0_wp
      ! outward (x.d > 0) and inward first (x.d < 0): the root on the far side
      d(2:3) = merge([1.0_wp, 0.5_wp], [-1.0_wp, -0.5_wp], trial == 1)
      call set%max_step(x, d, 10.0_wp, t, blk)
      y = x + t*d
      call report_le(abs(hypot(y(2), y(3)) - 1.0_wp), 4.0_wp*eps, &
                     'max step: x + t d on the circle (x.d '//merge('> 0', '< 0', trial == 1)//')')
      call report(blk == 2 .and. t > 0.0_wp, 'max step: the blocker is the disc''s first variable')
      call set%pin(y, d, blk)
      call set%free_mask(y, free)
      call report(.not. free(2) .and. .not. free(3) .and. abs(hypot(y(2), y(3)) - 1.0_wp) <= 2.0_wp*eps, &
                  'pin: the blocking disc on its circle, not free')
      t2 = set%step_bound(x, d, 10.0_wp)
      call report_le(abs(t2 - t), 4.0_wp*eps*t, 'step bound: the same root')
      t2 = 10.0_wp
      cut = set%cut_step(x, d, t2, .false.)
      call report(cut .and. abs(t2 - t) <= 4.0_wp*eps*t, 'cut step: cut to the root')
      t2 = 0.5_wp*t
      cut = set%cut_step(x, d, t2, .false.)
      call report(.not. cut .and. t2 == 0.5_wp*t, 'cut step: a step inside is not cut')
    end do
    ! from a point on the circle along its tangent: no feasible step
    x = [0.0_wp, 0.6_wp, 0.8_wp, 0.0_wp, 0.0_wp, 0.0_wp]
    d = [0.0_wp, 0.8_wp, -0.6_wp, 0.0_wp, 0.0_wp, 0.0_wp]
    call set%max_step(x, d, 1.0_wp, t, blk)
    call report(t <= 4.0_wp*eps .and. blk == 2, 'max step: 0 along the tangent of a point on the circle')
    ! the projected step and the reduced gradient: x + d = P(x - alpha phi), x - alpha phit = the same
    x = [0.5_wp, 0.3_wp, 0.1_wp, 0.2_wp, 1.0_wp, -1.0_wp]
    g = [1.0_wp, -4.0_wp, 2.0_wp, -0.3_wp, 3.0_wp, 3.0_wp]
    call set%projected_step(x, g, 0.5_wp, v)
    call set%reduced_gradient(x, g, 0.5_wp, phit)
    y = x - 0.5_wp*g
    call set%project(y)
    call report_le(maxval(abs(x + v - y)), 4.0_wp*eps, 'projected step: x + d = P(x - alpha g) on the free set')
    call report_le(maxval(abs(x - 0.5_wp*phit - y)), 4.0_wp*eps, 'reduced gradient: x - alpha phit = P(x - alpha g)')
    call set%move(x, g, -0.5_wp, free)
    call report_le(maxval(abs(x - y)), 4.0_wp*eps, 'move: P(x + t d)')
    s = hypot(x(2), x(3))
    call report(.not. free(2) .and. .not. free(3) .and. abs(s - 1.0_wp) <= 2.0_wp*eps, 'move: lands on the circle, not free')
  end subroutine test_steps

  !> Bad sets are refused with their reason.
  subroutine test_validate()
    type(disc_set_t) :: set
    type(error_t) :: verr
    real(wp) :: nan
    set = node_set([1.0_wp, 2.0_wp])
    call set%validate(6, verr)
    call report(.not. verr%failed() .and. verr%text() == '', 'validate: a good set')
    set = node_set([1.0_wp, -2.0_wp])
    call set%validate(6, verr)
    call report(verr%category == ERR_INPUT .and. index(verr%text(), 'r(2)') > 0, 'validate: a negative radius: '//verr%text())
    nan = ieee_value(1.0_wp, ieee_quiet_nan)
    set = node_set([nan, 2.0_wp])
    call set%validate(6, verr)
    call report(verr%category == ERR_NUMERICAL .and. index(verr%text(), 'r(1)') > 0, 'validate: a NaN radius: '//verr%text())
    set = disc_set([0.0_wp, 0.0_wp, 0.0_wp], reshape([2, 4], [2, 1]), [1.0_wp])
    call set%validate(3, verr)
    call report(verr%category == ERR_INPUT .and. index(verr%text(), 'outside') > 0, 'validate: a pair out of range: '//verr%text())
    set = disc_set([0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], reshape([1, 2, 2, 3], [2, 2]), [1.0_wp, 1.0_wp])
    call set%validate(4, verr)
    call report(verr%category == ERR_INPUT .and. index(verr%text(), 'variable 2') > 0, 'validate: a variable in two pairs: '//verr%text())
  end subroutine test_validate

  !> A = I: the minimiser of 1/2|x|^2 - b'x over the set is P(b).
  subroutine test_identity()
    integer, parameter :: nk = 20, n = 3*nk
    type(disc_set_t) :: set
    type(dense_op_t) :: A
    type(mprgp_t) :: solver
    real(wp) :: a0(n, n), b(n), x(n), p(n), r(nk)
    integer :: i
    do i = 1, nk
      r(i) = urand(0.1_wp, 1.0_wp)
    end do
    set = node_set(r)
    a0 = 0.0_wp
    do i = 1, n
      a0(i, i) = 1.0_wp
      b(i) = urand(-2.0_wp, 2.0_wp)
    end do
    call dense_op_init(A, a0)
    p = b
    call set%project(p)
    x = 0.0_wp
    solver%opts%rtol = 1.0e-14_wp
    call solver%solve_in(A, b, set, x)
    call report(solver%stats%status == MPRGP_CONVERGED, 'A = I: converged: '//trim(solver%stats%message))
    call report_le(maxval(abs(x - p)), 1.0e-14_wp, 'A = I: the minimiser is P(b)')
    call report(count(hypot(p(2:n:3), p(3:n:3)) >= r - 1.0e-12_wp) > 0 .and. count(p(1:n:3) == 0.0_wp) > 0, &
                'A = I: discs on their circles and normal forces at 0 among them')
  end subroutine test_identity

  !> One node, A = 3 I on its tangential pair and its normal force free: b = 6 (cos q, sin q)
  !! pulls it beyond its circle of radius 1, for q = 0, 15, 30, 45 degrees: x on the circle
  !! along b each time (a box |x_i| <= 1 would give |x| = sqrt(2) at 45 degrees).
  subroutine test_isotropy()
    type(disc_set_t) :: set
    type(dense_op_t) :: A
    type(mprgp_t) :: solver
    real(wp) :: a0(3, 3), b(3), x(3), q, worst
    integer :: j
    a0 = 0.0_wp
    a0(1, 1) = 2.0_wp
    a0(2, 2) = 3.0_wp
    a0(3, 3) = 3.0_wp
    call dense_op_init(A, a0)
    set = node_set([1.0_wp])
    worst = 0.0_wp
    do j = 0, 3
      q = real(15*j, wp)*pi/180.0_wp
      b = [1.0_wp, 6.0_wp*cos(q), 6.0_wp*sin(q)]
      x = 0.0_wp
      solver%opts%rtol = 1.0e-14_wp
      call solver%solve_in(A, b, set, x)
      worst = max(worst, abs(x(1) - 0.5_wp), abs(x(2) - cos(q)), abs(x(3) - sin(q)))
      if (solver%stats%status /= MPRGP_CONVERGED) worst = big
    end do
    call report_le(worst, 1.0e-13_wp, 'isotropy: b turned by 0, 15, 30, 45 degrees: x = (cos q, sin q) on the circle')
  end subroutine test_isotropy

  !> 30 nodes, random SPD A (condition 1e2), b with normal parts of both signs, radii 0.3 to
  !! 1.5 times the tangential forces of the unconstrained minimiser (some discs end on their
  !! circles, some inside); rtol 1e-10: MPGP's x against the KKT conditions and
  !! against FISTA's; the Newton method asked for, MPGP used (no Newton step, the same x).
  subroutine test_random_qp()
    integer, parameter :: nk = 30, n = 3*nk
    type(disc_set_t) :: set
    type(dense_op_t) :: A
    type(mprgp_t) :: solver
    real(wp) :: a0(n, n), b(n), x(n), x2(n), xf(n), y(n), xold(n), r(nk), lmax, tk, tk1, kkt
    integer :: it, onc
    call random_friction_qp(nk, 2.0_wp, a0, b, r, lmax)
    set = node_set(r)
    call dense_op_init(A, a0)
    x = 0.0_wp
    solver%opts%rtol = 1.0e-10_wp
    solver%opts%max_it = 100000
    call solver%solve_in(A, b, set, x)
    call report(solver%stats%status == MPRGP_CONVERGED, 'random QP: converged: '//trim(solver%stats%message))
    call kkt_of(a0, b, x, r, kkt, onc)
    call report(onc >= 3 .and. onc <= nk - 3, 'random QP: some discs on their circles, some inside')
    call report_le(kkt/norm2(b), 1.0e-10_wp, 'random QP: KKT (x_n >= 0, g_n >= 0, x_n g_n = 0; g_t = 0 inside a '// &
                   'disc, g_t = -c nu, c >= 0, on its circle)')
    ! FISTA with step 1/lmax (lmax is A's largest eigenvalue)
    xf = 0.0_wp
    y = xf
    tk = 1.0_wp
    do it = 1, 20000
      xold = xf
      xf = y - (matmul(a0, y) - b)/lmax
      call set%project(xf)
      tk1 = 0.5_wp*(1.0_wp + sqrt(1.0_wp + 4.0_wp*tk*tk))
      y = xf + ((tk - 1.0_wp)/tk1)*(xf - xold)
      tk = tk1
    end do
    call report_le(norm2(x - xf)/norm2(xf), 1.0e-9_wp, 'random QP: MPGP''s minimiser against FISTA''s (20000 steps)')
    ! the Newton method along the circles (module disc_newton): the same minimiser
    x2 = 0.0_wp
    solver%opts%method = QP_NEWTON
    call solver%solve_in(A, b, set, x2)
    call report(solver%stats%status == MPRGP_CONVERGED .and. solver%stats%n_newton > 0 .and. &
                solver%stats%n_factor > 0 .and. solver%stats%n_factor <= solver%stats%n_newton, &
                'random QP: the Newton method on the discs converged (a factor per step at most): '// &
                trim(solver%stats%message))
    call report_le(norm2(x2 - x)/norm2(x), 1.0e-9_wp, 'random QP: the Newton method''s minimiser against MPGP''s')
    solver%opts%method = QP_MPRGP
  end subroutine test_random_qp

  !> The same kind of problem at condition 1e6 (beyond what MPGP's sliding along the circles
  !! reaches in a test's time): the Newton method on the discs, from 0, within 200 steps, to
  !! rtol 1e-10, with the KKT conditions checked as above (1e-10 |b|).
  subroutine test_newton_hard()
    integer, parameter :: nk = 40, n = 3*nk
    type(disc_set_t) :: set
    type(dense_op_t) :: A
    type(mprgp_t) :: solver
    real(wp) :: a0(n, n), b(n), x(n), r(nk), lmax, kkt
    integer :: onc
    call random_friction_qp(nk, 6.0_wp, a0, b, r, lmax)
    set = node_set(r)
    call dense_op_init(A, a0)
    x = 0.0_wp
    solver%opts%method = QP_NEWTON
    solver%opts%rtol = 1.0e-10_wp
    solver%opts%max_it = 200
    call solver%solve_in(A, b, set, x)
    call report(solver%stats%status == MPRGP_CONVERGED, 'condition 1e6: the Newton method on the discs: '// &
                trim(solver%stats%message))
    call kkt_of(a0, b, x, r, kkt, onc)
    call report(onc >= 3 .and. onc <= nk - 3, 'condition 1e6: some discs on their circles, some inside')
    call report_le(kkt/norm2(b), 1.0e-10_wp, 'condition 1e6: the KKT conditions (normal forces and discs)')
  end subroutine test_newton_hard

  !> 'auto' on a disc set, condition 1e3 (30 nodes, rtol 1e-10): MPGP within its budget, then
  !! the Newton method on the discs: converged, switched, the same minimiser as MPGP's alone
  !! (1e-9) at fewer products.
  subroutine test_auto()
    integer, parameter :: nk = 30, n = 3*nk
    type(disc_set_t) :: set
    type(dense_op_t) :: A
    type(mprgp_t) :: solver
    real(wp) :: a0(n, n), b(n), x(n), x2(n), r(nk), lmax
    integer :: nmv
    character(len=64) :: msg
    call random_friction_qp(nk, 3.0_wp, a0, b, r, lmax)
    set = node_set(r)
    call dense_op_init(A, a0)
    x = 0.0_wp
    solver%opts%method = QP_MPRGP
    solver%opts%rtol = 1.0e-10_wp
    solver%opts%max_it = 100000
    call solver%solve_in(A, b, set, x)
    nmv = solver%stats%n_matvec
    x2 = 0.0_wp
    solver%opts%method = QP_AUTO
    call solver%solve_in(A, b, set, x2)
    write (msg, '(i0,a,i0,a)') solver%stats%n_matvec, ' products against ', nmv, ' of MPGP alone'
    call report(solver%stats%status == MPRGP_CONVERGED .and. solver%stats%switched .and. solver%stats%n_matvec < nmv, &
                'auto on discs, condition 1e3: switched to the Newton method, '//trim(msg))
    call report_le(norm2(x2 - x)/norm2(x), 1.0e-9_wp, 'auto on discs: the minimiser of MPGP alone')
  end subroutine test_auto

  !> Eight nearby problems (30 nodes, condition 1e2; b and the radii moved by up to 1% and 2%
  !! each time), each from the last answer projected onto its set, solved three ways by the
  !! Newton method on the discs: (a) from the binding set (the default); (b) from the face of
  !! the start (hold_boundary) with the factor carried (keep_disc); (c) as (b) with a new
  !! factor each solve. (b) = (c) bit for bit with fewer factorizations; (b) = (a) to 1e-9
  !! and the KKT conditions to 1e-10 |b|.
  subroutine test_warm_sequence()
    integer, parameter :: nk = 30, n = 3*nk, nseq = 8
    type(disc_set_t) :: set
    type(dense_op_t) :: A
    type(mprgp_t) :: sa, sb, sc
    type(disc_factor_t), target :: carried
    real(wp) :: a0(n, n), b0(n), b(n), r0(nk), r(nk), rprev(nk), lmax, xa(n), xb(n), xc(n), kkt, worst_a, worst_k
    integer :: k, j, fb, fc
    logical :: same
    call random_friction_qp(nk, 2.0_wp, a0, b0, r0, lmax)
    call dense_op_init(A, a0)
    xa = 0.0_wp
    xb = 0.0_wp
    xc = 0.0_wp
    same = .true.
    fb = 0
    fc = 0
    worst_a = 0.0_wp
    worst_k = 0.0_wp
    do k = 1, nseq
      do j = 1, n
        b(j) = b0(j)*(1.0_wp + 1.0e-4_wp*sin(real(7*j + 3*k, wp)))
      end do
      do j = 1, nk
        r(j) = r0(j)*(1.0_wp + 2.0e-4_wp*cos(real(5*j + k, wp)))
      end do
      set = node_set(r)
      ! a force on its last circle onto its new one (as the Robin iteration does)
      if (k > 1) then
        call onto_circles(xa, rprev, r)
        call onto_circles(xb, rprev, r)
        call onto_circles(xc, rprev, r)
      end if
      call set%project(xa)
      call set%project(xb)
      call set%project(xc)
      rprev = r
      call warm_solve(sa, A, b, set, xa, .false., .false., carried)
      call warm_solve(sb, A, b, set, xb, .true., .true., carried)
      fb = fb + sb%stats%n_factor
      call warm_solve(sc, A, b, set, xc, .true., .false., carried)
      fc = fc + sc%stats%n_factor
      same = same .and. all(xb == xc) .and. sb%stats%status == MPRGP_CONVERGED .and. sc%stats%status == MPRGP_CONVERGED
      worst_a = max(worst_a, norm2(xb - xa)/norm2(xa))
      call kkt_of(a0, b, xb, r, kkt, j)
      worst_k = max(worst_k, kkt/norm2(b))
    end do
    call report(same, 'warm sequence: the factor carried from solve to solve = a new one each solve, bit for bit')
    call report(fb < fc, 'warm sequence: carried, '//i2s(fb)//' factorizations against '//i2s(fc))
    call report_le(worst_a, 1.0e-9_wp, 'warm sequence: started from the face = from the binding set')
    call report_le(worst_k, 1.0e-10_wp, 'warm sequence: KKT conditions of every answer')

  end subroutine test_warm_sequence

  !> Each node's tangential force on its circle of radius rprev (but for rounding) put on its
  !! circle of radius r, the same direction (as the Robin iteration does between solves).
  subroutine onto_circles(x, rprev, r)
    real(wp), intent(inout) :: x(:)
    real(wp), intent(in) :: rprev(:), r(:)
    integer :: q
    real(wp) :: h
    do q = 1, size(r)
      h = hypot(x(3*q - 1), x(3*q))
      if (h > 0.0_wp .and. h >= rprev(q)*(1.0_wp - 1.0e-14_wp)) x(3*q - 1:3*q) = x(3*q - 1:3*q)*(r(q)/h)
    end do
  end subroutine onto_circles

  !> One solve of test_warm_sequence by the Newton method on the discs, from the face of x
  !! (face) or the binding set, with the factor `carried` from the last solve (carry).
  subroutine warm_solve(s, A, b, set, x, face, carry, carried)
    type(mprgp_t), intent(inout) :: s
    type(dense_op_t), intent(inout) :: A
    real(wp), intent(in) :: b(:)
    type(disc_set_t), intent(in) :: set
    real(wp), intent(inout) :: x(:)
    logical, intent(in) :: face, carry
    type(disc_factor_t), target, intent(inout) :: carried
    s%opts%method = QP_NEWTON
    s%opts%rtol = 1.0e-11_wp
    s%opts%max_it = 1000
    s%hold_boundary = face
    if (carry) s%keep_disc => carried
    call s%solve_in(A, b, set, x)
  end subroutine warm_solve

  !> A random friction QP of nk nodes: A SPD of condition 10^cexp, b with normal parts of
  !! both signs, radii 0.3 to 1.5 times the tangential forces of the unconstrained minimiser
  !! (some discs end on their circles, some inside).
  subroutine random_friction_qp(nk, cexp, a0, b, r, lmax)
    integer, intent(in) :: nk
    real(wp), intent(in) :: cexp
    real(wp), intent(out) :: a0(3*nk, 3*nk), b(3*nk), r(nk), lmax
    real(wp) :: xu(3*nk), y2(3*nk, 3*nk), lmin
    integer :: k, info
    call random_spd(3*nk, cexp, a0, lmin, lmax)
    do k = 1, nk
      b(3*k - 2) = urand(-1.0_wp, 2.0_wp)*lmax
      b(3*k - 1) = urand(-1.0_wp, 1.0_wp)*lmax
      b(3*k) = urand(-1.0_wp, 1.0_wp)*lmax
    end do
    xu = b
    y2 = a0
    call dposv('L', 3*nk, 1, y2, 3*nk, xu, 3*nk, info)
    if (info /= 0) error stop 'random_friction_qp: dposv failed'
    do k = 1, nk
      r(k) = urand(0.3_wp, 1.5_wp)*hypot(xu(3*k - 1), xu(3*k))
    end do
  end subroutine random_friction_qp

  !> The KKT conditions of x for the node set of radii r, from g = A x - b: max over the
  !! nodes of |g_n| where x_n > 0, -g_n where x_n = 0 (huge where x_n < 0), |g_t| inside a
  !! disc, and on a circle g_t's part along it and its outward part (g_t = -c nu, c >= 0);
  !! onc: the discs on their circles.
  subroutine kkt_of(a0, b, x, r, kkt, onc)
    real(wp), intent(in) :: a0(:, :), b(:), x(:), r(:)
    real(wp), intent(out) :: kkt
    integer, intent(out) :: onc
    real(wp) :: g(size(x)), s, nu(2)
    integer :: i, k
    g = matmul(a0, x) - b
    kkt = 0.0_wp
    onc = 0
    do k = 1, size(r)
      i = 3*k - 2
      if (x(i) > 0.0_wp) then
        kkt = max(kkt, abs(g(i)))
      else
        kkt = max(kkt, -g(i), merge(big, 0.0_wp, x(i) < 0.0_wp))
      end if
      s = hypot(x(i + 1), x(i + 2))
      if (s >= r(k)*(1.0_wp - 1.0e-12_wp)) then
        onc = onc + 1
        nu = x(i + 1:i + 2)/s
        kkt = max(kkt, abs(g(i + 1)*nu(2) - g(i + 2)*nu(1)), max(dot_product(g(i + 1:i + 2), nu), 0.0_wp))
      else
        kkt = max(kkt, maxval(abs(g(i + 1:i + 2))))
      end if
    end do
  end subroutine kkt_of

  !> The factor the Newton steps carry (module disc_newton: deleted, inserted and appended
  !! rows, the Schur complement on the held discs' tangents) against the face's matrix
  !! Z'AZ + C written out and solved by LAPACK, along 300 faces each a few variables from
  !! the last (120 variables, 40 nodes, condition 1e4): a variable freed or held, a disc
  !! held or released, tangents and curvatures new each time; every 25 faces a jump far
  !! away (a new factor). The direction to 1e-10 relative on every face, and updates made.
  subroutine test_carried_factor()
    integer, parameter :: nk = 40, n = 3*nk
    type(disc_set_t) :: set
    type(disc_factor_t) :: fac
    real(wp) :: a0(n, n), g(n), r(nk), lmin, lmax, flops, worst, th
    logical :: freev(n), heldd(nk), definite
    integer, allocatable :: free(:), dk(:)
    real(wp), allocatable :: tau(:, :), curv(:), d(:), h(:, :), e(:)
    integer :: step, k, i, q, info, factored, nfresh
    call random_spd(n, 4.0_wp, a0, lmin, lmax)
    r = 1.0_wp
    set = node_set(r)
    ! a start: normal forces free, a third of the discs held, the rest free
    freev = .true.
    heldd = .false.
    do k = 1, nk, 3
      heldd(k) = .true.
    end do
    worst = 0.0_wp
    factored = 0
    do step = 1, 300
      if (mod(step, 25) == 0) then
        do k = 1, nk
          heldd(k) = urand(0.0_wp, 1.0_wp) < 0.4_wp
          freev(3*k - 2) = urand(0.0_wp, 1.0_wp) < 0.8_wp
        end do
      else if (step > 1) then
        k = 1 + int(urand(0.0_wp, real(nk, wp) - 1.0e-9_wp))
        select case (mod(step, 3))
        case (0)
          freev(3*k - 2) = .not. freev(3*k - 2)
        case default
          heldd(k) = .not. heldd(k)
        end select
      end if
      do k = 1, nk
        freev(3*k - 1:3*k) = .not. heldd(k)
      end do
      free = pack([(i, i=1, n)], freev)
      dk = pack([(k, k=1, nk)], heldd)
      allocate (tau(2, size(dk)), curv(size(dk)), d(size(free) + size(dk)))
      do q = 1, size(dk)
        th = urand(0.0_wp, 2.0_wp*pi)
        tau(:, q) = [cos(th), sin(th)]
        curv(q) = urand(0.0_wp, 1.0_wp)
      end do
      do i = 1, n
        g(i) = urand(-1.0_wp, 1.0_wp)
      end do
      flops = 0.0_wp
      call face_solve(a0, set, free, dk, tau, curv, g, fac, d, definite, flops, factored)
      ! the face's matrix written out
      call face_matrix(a0, set, free, dk, tau, curv, g, h, e)
      call dposv('L', size(e), 1, h, size(e), e, size(e), info)
      worst = max(worst, norm2(d - e)/norm2(e))
      if (.not. definite) worst = huge(1.0_wp)
      deallocate (tau, curv, d, h, e)
    end do
    nfresh = factored
    call report_le(worst, 1.0e-10_wp, 'carried face factor: the Newton direction on 300 faces against LAPACK on Z''AZ + C')
    call report(nfresh < 100, 'carried face factor: most faces by updates ('//i2s(nfresh)//' factors for 300 faces)')

  end subroutine test_carried_factor

  !> The Newton face's matrix Z'AZ + C and right-hand side -Z'g written out (module
  !! disc_newton's header): the free variables, then the held discs' tangents.
  subroutine face_matrix(a0, set, free, dk, tau, curv, g, h, e)
    real(wp), intent(in) :: a0(:, :), tau(:, :), curv(:), g(:)
    type(disc_set_t), intent(in) :: set
    integer, intent(in) :: free(:), dk(:)
    real(wp), allocatable, intent(out) :: h(:, :), e(:)
    integer :: nf, nd, i, j, q
    nf = size(free)
    nd = size(dk)
    allocate (h(nf + nd, nf + nd), e(nf + nd))
    do j = 1, nf
      do i = 1, nf
        h(i, j) = a0(free(i), free(j))
      end do
      e(j) = -g(free(j))
    end do
    do q = 1, nd
      associate (p => set%pair(:, dk(q)))
        do j = 1, nf
          h(nf + q, j) = tau(1, q)*a0(p(1), free(j)) + tau(2, q)*a0(p(2), free(j))
          h(j, nf + q) = h(nf + q, j)
        end do
        do i = 1, nd
          associate (s => set%pair(:, dk(i)))
            h(nf + i, nf + q) = dot_product(tau(:, i), matmul(a0(s, p), tau(:, q)))
          end associate
        end do
        h(nf + q, nf + q) = h(nf + q, nf + q) + curv(q)
        e(nf + q) = -dot_product(tau(:, q), g(p))
      end associate
    end do
  end subroutine face_matrix

end program test_disc_set
