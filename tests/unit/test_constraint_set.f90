!> Unit tests of the constraint set (module constraint_set) as the box lb <= x <= ub:
!! every method against its formula written out here on random points with variables free,
!! at either bound, fixed and unbounded (projection, move, free set, free / chopped /
!! projected / reduced gradients and MPRGP's split of the gradient, projected step, the three step lengths and the blocker, binding and leaving
!! tests, landing on a bound), the refusal of bad boxes, and MPRGP through `solve_in` with a
!! box set against `solve` with lb, ub (the same iterates, bit for bit).
!! One line per check: PASS/FAIL. Exits with status 1 if any check failed.
program test_constraint_set
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use kinds, only: wp
  use errors, only: error_t, ERR_INPUT, ERR_NUMERICAL
  use linop, only: dense_op_t, dense_op_init
  use constraint_set, only: box_set_t, box_set
  use mprgp, only: mprgp_t, MPRGP_CONVERGED
  use testing, only: report, test_summary, set_seed, urand, random_spd
  implicit none (type, external)

  real(wp), parameter :: big = huge(1.0_wp)
  integer, parameter :: n = 40

  call set_seed(20261128)
  call test_pointwise()
  call test_steps()
  call test_newton_tests()
  call test_validate()
  call test_solve_in()
  call test_summary()

contains

  !> A box with every kind of variable and a point with variables free, at lb, at ub.
  subroutine random_box(l, u, x)
    real(wp), intent(out) :: l(n), u(n), x(n)
    integer :: i
    do i = 1, n
      l(i) = urand(0.0_wp, 1.0_wp) - 1.0_wp
      u(i) = l(i) + urand(0.0_wp, 1.0_wp) + 0.1_wp
      select case (mod(i, 5))
      case (0)
        l(i) = -big                       ! no lower bound
      case (1)
        u(i) = big                        ! no upper bound
      case (2)
        u(i) = l(i)                       ! fixed
      end select
      select case (mod(i, 3))
      case (0)
        x(i) = l(i)
      case (1)
        x(i) = u(i)
      case default
        x(i) = 0.5_wp*(max(l(i), -2.0_wp) + min(u(i), 2.0_wp))
      end select
      if (x(i) <= -big) x(i) = u(i) - 0.5_wp
      if (x(i) >= big) x(i) = l(i) + 0.5_wp
    end do
  end subroutine random_box

  !> Projection, free set, chopped, projected and reduced gradients, projected step.
  subroutine test_pointwise()
    real(wp) :: l(n), u(n), x(n), g(n), y(n), v(n), ref(n), alpha, s1, s2, s3
    logical :: free(n), freeref(n)
    type(box_set_t) :: box
    integer :: i
    call random_box(l, u, x)
    box = box_set(l, u)
    do i = 1, n
      g(i) = 2.0_wp*urand(0.0_wp, 1.0_wp) - 1.0_wp
      y(i) = 4.0_wp*urand(0.0_wp, 1.0_wp) - 2.0_wp
    end do
    ! projection: the nearest point of the box
    ref = y
    where (ref < l) ref = l
    where (ref > u) ref = u
    v = y
    call box%project(v)
    call report(all(v == ref), 'box: project(y) = min(max(y, l), u)')
    call box%project(v)
    call report(all(v == ref), 'box: projection is idempotent')
    ! free set
    freeref = x > l .and. x < u
    call box%free_mask(x, free)
    call report(all(free .eqv. freeref), 'box: free set = {l < x < u}')
    call report(count(free) > 0 .and. count(.not. free) > 0, 'box: the test point has free and bound variables')
    ! chopped gradient: 0 on F, min(g,0) at l, max(g,0) at u, 0 when fixed
    do i = 1, n
      if (freeref(i) .or. l(i) == u(i)) then
        ref(i) = 0.0_wp
      else if (x(i) <= l(i)) then
        ref(i) = min(g(i), 0.0_wp)
      else
        ref(i) = max(g(i), 0.0_wp)
      end if
    end do
    call box%chopped_gradient(x, g, v)
    call report(all(v == ref), 'box: chopped gradient beta')
    ! the split of MPRGP: |phi|^2, phit'phi (alpha unknown: phit = phi) and |beta|^2
    call box%split_gradient(x, g, 0.0_wp, s1, s2, s3)
    call report(abs(s1 - sum(g**2, mask=freeref)) <= 4.0_wp*epsilon(1.0_wp)*s1 .and. s2 == s1 .and. &
                abs(s3 - sum(ref**2)) <= 4.0_wp*epsilon(1.0_wp)*s3, 'box: split_gradient = |phi|^2, phi''phi, |beta|^2')
    ! free gradient
    call box%free_gradient(x, g, v)
    call report(all(v == merge(g, 0.0_wp, freeref)), 'box: free gradient phi')
    ! projected gradient = phi + beta
    where (freeref) ref = g
    call box%projected_gradient(x, g, v)
    call report(all(v == ref), 'box: projected gradient gP = phi + beta')
    call report(abs(box%projected_gradient_norm(x, g) - norm2(ref)) <= 4.0_wp*epsilon(1.0_wp)*norm2(ref), &
                'box: |gP|')
    ! reduced free gradient: x - alpha phit stays in the box, phit = phi where it can
    alpha = 3.0_wp
    call box%reduced_gradient(x, g, alpha, v)
    do i = 1, n
      if (.not. freeref(i)) then
        ref(i) = 0.0_wp
      else
        ref(i) = min(max(g(i), (x(i) - u(i))/alpha), (x(i) - l(i))/alpha)
      end if
    end do
    call report(maxval(abs(v - ref)) <= 4.0_wp*epsilon(1.0_wp)*maxval(abs(g)), 'box: reduced free gradient phit')
    call report(all(x - alpha*v >= l - 1.0e-15_wp .and. x - alpha*v <= u + 1.0e-15_wp), &
                'box: x - alpha phit stays in the box')
    call box%split_gradient(x, g, alpha, s1, s2, s3)
    call report(abs(s2 - sum(ref*g, mask=freeref)) <= 8.0_wp*epsilon(1.0_wp)*sum(abs(ref*g)), &
                'box: split_gradient''s phit''phi = the reduced gradient''s')
    call box%reduced_gradient(x, g, 0.0_wp, v)
    call report(all(merge(g, 0.0_wp, freeref) == v), 'box: phit = phi while alpha is not known')
    ! projected step: x + d = P(x - alpha phi)
    call box%projected_step(x, g, alpha, v)
    ref = x - alpha*merge(g, 0.0_wp, freeref)
    call box%project(ref)
    call report(maxval(abs(x + v - ref)) <= 8.0_wp*epsilon(1.0_wp)*(1.0_wp + maxval(abs(ref))), &
                'box: projected step d = P(x - alpha phi) - x')
    ! move: x = P(x + t d) and the free set there
    v = x
    call box%move(v, y, 0.7_wp, free)
    ref = x + 0.7_wp*y
    where (ref < l) ref = l
    where (ref > u) ref = u
    call report(all(v == ref) .and. all(free .eqv. (ref > l .and. ref < u)), 'box: move = P(x + t d), free set there')
  end subroutine test_pointwise

  !> The three step lengths against the least ratio, the blocker and pin.
  subroutine test_steps()
    real(wp) :: l(n), u(n), x(n), d(n), t, tref, tb, tc, z(n), ti
    type(box_set_t) :: box
    integer :: i, blk, iref
    logical :: cut
    call random_box(l, u, x)
    box = box_set(l, u)
    do i = 1, n
      d(i) = 2.0_wp*urand(0.0_wp, 1.0_wp) - 1.0_wp
    end do
    ! the least ratio over the variables moving towards a finite bound
    tref = 10.0_wp
    iref = 0
    do i = 1, n
      ti = big
      if (d(i) < 0.0_wp .and. l(i) > -big) ti = (x(i) - l(i))/(-d(i))
      if (d(i) > 0.0_wp .and. u(i) < big) ti = (u(i) - x(i))/d(i)
      if (ti < tref) then
        tref = ti
        iref = i
      end if
    end do
    call box%max_step(x, d, 10.0_wp, t, blk)
    call report(abs(t - tref) <= 4.0_wp*epsilon(1.0_wp)*max(1.0_wp, tref) .and. blk > 0, &
                'box: max_step = least ratio, with a blocker', t, tref)
    call report(blk == iref .or. abs(t - tref) <= 4.0_wp*epsilon(1.0_wp), 'box: the blocker is the least ratio''s variable')
    tb = box%step_bound(x, d, 10.0_wp)
    call report(abs(tb - max(tref, 0.0_wp)) <= 4.0_wp*epsilon(1.0_wp)*max(1.0_wp, tref), 'box: step_bound = least ratio')
    tc = 10.0_wp
    cut = box%cut_step(x, d, tc, .false.)
    call report(cut .and. abs(tc - tref) <= 16.0_wp*epsilon(1.0_wp)*max(1.0_wp, tref), 'box: cut_step = least ratio')
    tc = 10.0_wp
    cut = box%cut_step(x, d, tc, .true.)
    call report(cut .and. tc == 10.0_wp, 'box: cut_step with whole: refused, t unchanged')
    ! a step short of every bound: no blocker, no cut
    call box%max_step(x, d, 0.0_wp, t, blk)
    call report(blk == 0 .and. t == 0.0_wp, 'box: a zero step has no blocker')
    ! pin: the blocker lands on the bound d points to
    z = x + t*d
    call box%max_step(x, d, 10.0_wp, t, blk)
    z = x + t*d
    call box%project(z)
    call box%pin(z, d, blk)
    call report(z(blk) == merge(u(blk), l(blk), d(blk) > 0.0_wp), 'box: pin puts the blocker on its bound')
    ! a made-up direction into the box's interior on every variable: free to go 10
    d = 0.0_wp
    call box%max_step(x, d, 10.0_wp, t, blk)
    call report(blk == 0 .and. t == 10.0_wp, 'box: d = 0 is never blocked')
  end subroutine test_steps

  !> binding, leaving and settle (the Newton method's working set).
  subroutine test_newton_tests()
    real(wp) :: l(n), u(n), x(n), g(n), d(n), z(n)
    logical :: held(n), ref(n)
    type(box_set_t) :: box
    integer :: i, idx(n)
    call random_box(l, u, x)
    box = box_set(l, u)
    do i = 1, n
      g(i) = 2.0_wp*urand(0.0_wp, 1.0_wp) - 1.0_wp
    end do
    call box%binding(x, g, held)
    do i = 1, n
      ref(i) = (x(i) == l(i) .and. (g(i) >= 0.0_wp .or. l(i) == u(i))) .or. (x(i) == u(i) .and. g(i) <= 0.0_wp)
    end do
    call report(all(held .eqv. ref), 'box: binding = at l with g >= 0, at u with g <= 0, or fixed')
    call report(count(held) > 0 .and. count(.not. held .and. x == l) > 0, 'box: the test has held and released bounds')
    call box%leaving(x, g, held)
    ref = (x == l .and. g < 0.0_wp) .or. (x == u .and. g > 0.0_wp)
    call report(all(held .eqv. ref), 'box: leaving = at l moving down, at u moving up')
    ! settle: a step that lands within rounding of a bound puts the variable on it
    x = 0.0_wp
    l = -1.0_wp
    u = 1.0_wp
    box = box_set(l, u)
    d = 0.0_wp
    d(1) = -1.0_wp + epsilon(1.0_wp)   ! lands just short of l
    d(2) = 1.0_wp                      ! lands on u
    d(3) = 0.5_wp                      ! stays inside
    held = .false.
    idx = [(i, i=1, n)]
    z = x
    call box%settle(z, d, 1.0_wp, idx(1:3), held)
    call report(z(1) == -1.0_wp .and. held(1), 'box: settle puts a variable within rounding of l on l')
    call report(z(2) == 1.0_wp .and. held(2), 'box: settle holds a variable that reaches u')
    call report(z(3) == 0.5_wp .and. .not. held(3), 'box: settle leaves an interior variable free')
  end subroutine test_newton_tests

  !> Wrong sizes, NaN and an empty box are refused, a valid box accepted.
  subroutine test_validate()
    type(box_set_t) :: box
    type(error_t) :: verr
    real(wp) :: nan
    box = box_set([0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp])
    call box%validate(2, verr)
    call report(.not. verr%failed() .and. len(verr%text()) == 0, 'box: a valid box is accepted')
    call box%validate(3, verr)
    call report(verr%category == ERR_INPUT, 'box: wrong size refused ('//verr%text()//')')
    box = box_set([0.0_wp, 0.0_wp], [1.0_wp, -1.0_wp])
    call box%validate(2, verr)
    call report(verr%category == ERR_INPUT .and. index(verr%text(), 'empty') > 0, 'box: ub < lb refused ('//verr%text()//')')
    nan = ieee_value(1.0_wp, ieee_quiet_nan)
    box = box_set([0.0_wp, nan])
    call box%validate(2, verr)
    call report(verr%category == ERR_NUMERICAL, 'box: NaN bound refused ('//verr%text()//')')
    box = box_set([0.0_wp, 0.0_wp])
    call report(all(box%ub == big), 'box: without ub, ub = +huge')
  end subroutine test_validate

  !> solve_in(box_set(l, u)) and solve(l, ub=u) take the same iterates.
  subroutine test_solve_in()
    real(wp) :: a(n, n), b(n), l(n), u(n), x1(n), x2(n), x0(n), lmin, lmax
    type(dense_op_t) :: op
    type(mprgp_t) :: s1, s2
    integer :: i
    call random_spd(n, 3.0_wp, a, lmin, lmax)
    call dense_op_init(op, a)
    call random_box(l, u, x0)
    do i = 1, n
      b(i) = 4.0_wp*urand(0.0_wp, 1.0_wp) - 2.0_wp
    end do
    s1%opts%rtol = 1.0e-12_wp
    s2%opts = s1%opts
    x1 = x0
    x2 = x0
    call s1%solve(op, b, l, x1, ub=u)
    call s2%solve_in(op, b, box_set(l, u), x2)
    call report(s1%stats%status == MPRGP_CONVERGED, 'solve with lb, ub converges ('//trim(s1%stats%message)//')')
    call report(all(x1 == x2) .and. s1%stats%n_matvec == s2%stats%n_matvec, &
                'solve_in(box_set(l, u)) = solve(l, ub=u), bit for bit')
    call report(all(x1 >= l .and. x1 <= u), 'the solution is in the box')
  end subroutine test_solve_in

end program test_constraint_set
