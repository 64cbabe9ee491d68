!> Unit tests of MPRGP and SMALBE with lower and upper bounds l <= x <= u: diagonal
!! problems (solution clip(b/a, l, u)), random SPD problems against an enumeration of all
!! active sets (each variable free, at its lower or at its upper bound), fixed variables
!! (l = u), upper bounds only, warm starts outside the box, the line search and the
!! recycled-subspace step at upper bounds, recycling over a sequence of box solves, SMALBE
!! with an equality row and a box, and a lower-bound solve that must not change when an
!! upper bound +huge or an inactive finite one is given.
!! One line per check: PASS/FAIL, the measured value and its tolerance.
!! Exits with status 1 if any check failed.
program test_mprgp_box
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use kinds, only: wp
  use linop, only: dense_op_t, dense_op_init
  use mprgp, only: mprgp_t, mprgp_opts_t, mprgp_stats_t, mprgp_status_name, MPRGP_CONVERGED, MPRGP_BAD_ARG, &
                   MPRGP_NONFINITE
  use mprgp_support, only: line_search, recycled_subspace
  use constraint_set, only: box_set
  use smalbe, only: smalbe_solve, smalbe_stats_t
  use lapack, only: dgesv
  use strings, only: i2s
  use testing, only: report, test_summary, set_seed, urand, random_spd, random_bounds, enumerate_box, box_projected
  implicit none (type, external)

  real(wp), parameter :: big = huge(1.0_wp)
  real(wp), parameter :: eps = epsilon(1.0_wp)
  integer :: calls = 0      ! polls of the stop hook
  integer :: stop_at = 0    ! the hook stops the solve at this poll

  call set_seed(20261125)
  call test_diagonal()
  call test_enumeration()
  call test_upper_only()
  call test_fixed()
  call test_recurrence()
  call test_line_search()
  call test_recycled_subspace()
  call test_warm_direction()
  call test_recycle_sequence()
  call test_lower_path_unchanged()
  call test_smalbe_box()
  call test_bad_upper()

  call test_summary()

contains

  ! ------------------------------------------------------------------ helpers

  !> One box solve by a fresh solver.
  subroutine solve_box(op, b, l, u, x, opts, st)
    type(dense_op_t), intent(inout) :: op
    real(wp), intent(in) :: b(:), l(:), u(:)
    real(wp), intent(inout) :: x(:)
    type(mprgp_opts_t), intent(in) :: opts
    type(mprgp_stats_t), intent(out) :: st
    type(mprgp_t) :: solver
    solver%opts = opts
    call solver%solve(op, b, l, x, ub=u)
    st = solver%stats
  end subroutine solve_box

  ! ------------------------------------------------------------------ tests

  !> A diagonal: the solution is clip(b/a, l, u); the bound variables exactly at their bound.
  subroutine test_diagonal()
    integer, parameter :: n = 50
    real(wp) :: a(n, n), b(n), l(n), u(n), x(n), xs(n), d(n), err
    type(dense_op_t) :: op
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    integer :: i, nlow, nup, nfree, nexact
    a = 0.0_wp
    do i = 1, n
      d(i) = urand(1.0_wp, 100.0_wp)
      a(i, i) = d(i)
      b(i) = urand(-10.0_wp, 10.0_wp)
      call random_bounds(mod(i, 5), b(i) / d(i), 0.2_wp, l(i), u(i))
    end do
    xs = min(max(b / d, l), u)
    call dense_op_init(op, a)
    opts%rtol = 1.0e-14_wp
    x = 0.0_wp
    call solve_box(op, b, l, u, x, opts, st)
    err = maxval(abs(x - xs)) / maxval(abs(xs))
    call report(st%status == MPRGP_CONVERGED .and. err <= 1.0e-13_wp, &
                'diagonal: x = clip(b/a, l, u) ('//trim(st%message)//')', err, 1.0e-13_wp)
    nlow = 0
    nup = 0
    nfree = 0
    nexact = 0
    do i = 1, n
      if (xs(i) == l(i)) then
        nlow = nlow + 1
        if (x(i) == l(i)) nexact = nexact + 1
      else if (xs(i) == u(i)) then
        nup = nup + 1
        if (x(i) == u(i)) nexact = nexact + 1
      else
        nfree = nfree + 1
      end if
    end do
    call report(nlow > 0 .and. nup > 0 .and. nfree > 0 .and. nexact == nlow + nup, &
                'diagonal: '//i2s(nlow)//' at l, '//i2s(nup)//' at u, '//i2s(nfree)// &
                ' free; the bound ones exactly at their bound', real(nexact, wp), real(nlow + nup, wp))
  end subroutine test_diagonal

  !> Random SPD problems n <= 8 with every kind of bound, against the enumeration; half of
  !! them from a warm start far outside the box.
  subroutine test_enumeration()
    integer, parameter :: nprob = 300
    real(wp), allocatable :: a(:, :), b(:), l(:), u(:), x(:), xs(:), xu(:), g(:), mu(:), gm(:, :), e(:)
    real(wp) :: lmin, lmax, err, worst, worst_kkt, tolg, gp
    integer :: ip, n, i, info, nfound, nconv, nat(3)
    integer, allocatable :: ipiv(:)
    type(dense_op_t) :: op
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    logical :: ok
    nfound = 0
    nconv = 0
    nat = 0
    worst = 0.0_wp
    worst_kkt = 0.0_wp
    opts%rtol = 0.0_wp    ! to the rounding floor
    allocate (gm(0, 8), e(0), mu(0))
    do ip = 1, nprob
      n = 1 + mod(ip - 1, 8)
      if (allocated(a)) deallocate (a, b, l, u, x, xs, xu, g, ipiv)
      allocate (a(n, n), b(n), l(n), u(n), x(n), xs(n), xu(n), g(n), ipiv(n))
      call random_spd(n, urand(0.0_wp, 2.0_wp), a, lmin, lmax)
      do i = 1, n
        b(i) = urand(-1.0_wp, 1.0_wp)
      end do
      xu = b
      block
        real(wp) :: af(n, n)
        af = a
        call dgesv(n, 1, af, n, ipiv, xu, n, info)
      end block
      do i = 1, n
        call random_bounds(int(urand(0.0_wp, 5.0_wp)), xu(i), norm2(xu) / sqrt(real(n, wp)), l(i), u(i))
      end do
      call enumerate_box(a, b, gm(:, 1:n), e, l, u, xs, mu, g, ok)
      if (ok) nfound = nfound + 1
      x = 0.0_wp
      if (mod(ip, 2) == 0) then
        do i = 1, n
          x(i) = urand(-20.0_wp, 20.0_wp) * (maxval(abs(xs)) + 1.0_wp)
        end do
      end if
      xu = min(max(x, l), u)   ! the projected start: its size sets the rounding floor
      call dense_op_init(op, a)
      call solve_box(op, b, l, u, x, opts, st)
      if (st%status == MPRGP_CONVERGED .and. all(x >= l) .and. all(x <= u)) nconv = nconv + 1
      err = maxval(abs(x - xs)) / (maxval(abs(xs)) + 1.0e-300_wp)
      worst = max(worst, err)
      ! KKT with the gradient computed here: the projected gradient at the solver's rounding
      ! floor 10 sqrt(n) eps lambda_max max(|x|, |x_0|) (rtol = 0), plus this product's rounding
      g = matmul(a, x) - b
      tolg = 20.0_wp * sqrt(real(n, wp)) * eps * lmax * max(norm2(x), norm2(xu)) + &
             10.0_wp * n * eps * (lmax * norm2(x) + norm2(b))
      gp = norm2(box_projected(g, x, l, u))
      worst_kkt = max(worst_kkt, gp / tolg)
      do i = 1, n
        if (l(i) == u(i)) cycle
        if (xs(i) == l(i)) nat(1) = nat(1) + 1
        if (xs(i) == u(i)) nat(2) = nat(2) + 1
        if (xs(i) > l(i) .and. xs(i) < u(i)) nat(3) = nat(3) + 1
      end do
    end do
    call report(nfound == nprob, 'box enumeration: reference found for '//i2s(nfound)//' of '//i2s(nprob))
    call report(nconv == nprob, 'box: '//i2s(nconv)//' of '//i2s(nprob)//' converged inside the box')
    call report(worst <= 1.0e-10_wp, 'box: max |x - x_ref| / |x_ref| ('//i2s(nat(1))//' at l, '// &
                i2s(nat(2))//' at u, '//i2s(nat(3))//' free)', worst, 1.0e-10_wp)
    call report(minval(nat) > 0, 'box: the references have variables at l, at u and free')
    call report(worst_kkt <= 1.0_wp, 'box: projected gradient A x - b to rounding', worst_kkt, 1.0_wp)
  end subroutine test_enumeration

  !> Upper bounds only (lb = -huge): against the enumeration and against the mirrored
  !! lower-bound problem min 1/2 y'Ay + b'y, y >= -u (x = -y).
  subroutine test_upper_only()
    integer, parameter :: n = 8
    real(wp) :: a(n, n), b(n), l(n), u(n), x(n), y(n), xs(n), g(n), mu(0), gm(0, n), e(0), lmin, lmax, err, err2
    type(dense_op_t) :: op
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st, st2
    type(mprgp_t) :: solver
    logical :: ok
    integer :: i
    call random_spd(n, 1.5_wp, a, lmin, lmax)
    do i = 1, n
      b(i) = urand(-1.0_wp, 1.0_wp)
      u(i) = urand(-0.5_wp, 0.5_wp)
    end do
    l = -big
    call enumerate_box(a, b, gm, e, l, u, xs, mu, g, ok)
    call dense_op_init(op, a)
    opts%rtol = 1.0e-14_wp
    x = 0.0_wp
    call solve_box(op, b, l, u, x, opts, st)
    err = maxval(abs(x - xs)) / maxval(abs(xs))
    call report(ok .and. st%status == MPRGP_CONVERGED .and. err <= 1.0e-10_wp .and. count(x == u) > 0 .and. &
                count(x < u) > 0, 'upper only: '//i2s(count(x == u))//' at u, against the enumeration', err, 1.0e-10_wp)
    solver%opts = opts
    y = 0.0_wp
    call solver%solve(op, -b, -u, y)
    st2 = solver%stats
    err2 = maxval(abs(x + y)) / maxval(abs(xs))
    call report(st2%status == MPRGP_CONVERGED .and. err2 <= 1.0e-12_wp .and. all((x == u) .eqv. (-y == u)), &
                'upper only: the mirror of the lower-bound problem, same active set', err2, 1.0e-12_wp)
    call mirror_steps()
  end subroutine test_upper_only

  !> The upper-bound iteration is the mirror image of the lower-bound one (negation is
  !! exact): on a larger problem the same steps of each kind, x = -y bit for bit.
  subroutine mirror_steps()
    integer, parameter :: n = 60
    real(wp) :: a(n, n), b(n), u(n), nb(n), x(n), y(n), lmin, lmax
    type(dense_op_t) :: op
    type(mprgp_t) :: up, low
    integer :: i
    call random_spd(n, 3.0_wp, a, lmin, lmax)
    do i = 1, n
      b(i) = urand(-1.0_wp, 1.0_wp)
      u(i) = urand(-1.0e-3_wp, 1.0e-3_wp)
    end do
    nb = -big
    call dense_op_init(op, a)
    up%opts%rtol = 1.0e-12_wp
    low%opts = up%opts
    x = 0.0_wp
    y = 0.0_wp
    call up%solve(op, b, nb, x, ub=u)
    call low%solve(op, -b, -u, y)
    call report(up%stats%status == MPRGP_CONVERGED .and. all(x == -y) .and. up%stats%n_exp > 0 .and. &
                up%stats%n_prop > 0 .and. up%stats%n_cg == low%stats%n_cg .and. &
                up%stats%n_exp == low%stats%n_exp .and. up%stats%n_prop == low%stats%n_prop, &
                'upper only: the mirror image of the lower-bound iteration ('//i2s(up%stats%n_cg)//' CG, '// &
                i2s(up%stats%n_exp)//' expansion, '//i2s(up%stats%n_prop)//' proportioning steps), x = -y exactly')
  end subroutine mirror_steps

  !> Fixed variables (l = u) stay exactly at their value; the others solve the reduced
  !! problem (reference: the enumeration of the reduced box problem).
  subroutine test_fixed()
    integer, parameter :: n = 8, nfix = 3
    real(wp) :: a(n, n), b(n), l(n), u(n), x(n), xs(n), g(n), mu(0), gm(0, n), e(0), lmin, lmax, err
    type(dense_op_t) :: op
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    logical :: ok
    integer :: i
    call random_spd(n, 1.0_wp, a, lmin, lmax)
    do i = 1, n
      b(i) = urand(-1.0_wp, 1.0_wp)
      l(i) = urand(-0.3_wp, 0.0_wp)
      u(i) = urand(0.0_wp, 0.3_wp)
    end do
    l(1:nfix) = [0.7_wp, -0.4_wp, 0.0_wp]
    u(1:nfix) = l(1:nfix)
    call enumerate_box(a, b, gm, e, l, u, xs, mu, g, ok)
    call dense_op_init(op, a)
    opts%rtol = 1.0e-14_wp
    x = 5.0_wp
    call solve_box(op, b, l, u, x, opts, st)
    err = maxval(abs(x - xs)) / maxval(abs(xs))
    call report(ok .and. st%status == MPRGP_CONVERGED .and. all(x(1:nfix) == l(1:nfix)) .and. err <= 1.0e-10_wp, &
                'fixed: l = u variables exactly at their value, the rest against the enumeration', err, 1.0e-10_wp)
  end subroutine test_fixed

  logical function stop_now()
    calls = calls + 1
    stop_now = calls >= stop_at
  end function stop_now

  !> The gradient carried by the recurrences stays A x - b in a box: a solve stopped after
  !! k = 1, 2, ... steps returns the recurrence gradient, compared with A x - b here. First a
  !! proportioning step that releases x1 from l and would carry it past u (cut at u), then
  !! random narrow boxes started from l.
  subroutine test_recurrence()
    integer, parameter :: n = 30
    real(wp) :: a(n, n), b(n), l(n), u(n), x(n), lmin, lmax, err, worst
    real(wp) :: a2(2, 2), x2(2)
    type(dense_op_t) :: op
    type(mprgp_t) :: solver
    integer :: i, k, nbad
    a2 = reshape([1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], [2, 2])
    call dense_op_init(op, a2)
    solver%opts%stop => stop_now
    calls = 0
    stop_at = 2
    x2 = 0.0_wp
    call solver%solve(op, [10.0_wp, 0.5_wp], [0.0_wp, 0.0_wp], x2, ub=[1.0_wp, 1.0_wp])
    err = maxval(abs(solver%g - (x2 - [10.0_wp, 0.5_wp])))
    call report(solver%stats%n_prop == 1 .and. x2(1) == 1.0_wp .and. abs(x2(2) - 0.05_wp) <= 4.0_wp * eps .and. &
                err <= 16.0_wp * eps, 'proportioning step cut at u: x = (1, 0.05), g = A x - b', err, 16.0_wp * eps)
    call random_spd(n, 2.0_wp, a, lmin, lmax)
    call dense_op_init(op, a)
    do i = 1, n
      b(i) = urand(-1.0_wp, 1.0_wp)
      l(i) = urand(-0.02_wp, 0.0_wp)
      u(i) = l(i) + urand(0.0_wp, 0.02_wp)
    end do
    worst = 0.0_wp
    nbad = 0
    do k = 1, 40
      calls = 0
      stop_at = k + 1
      x = l
      call solver%solve(op, b, l, x, ub=u)
      if (any(x < l) .or. any(x > u)) nbad = nbad + 1
      err = maxval(abs(solver%g - (matmul(a, x) - b))) / (lmax * maxval(abs(x)) + maxval(abs(b)))
      worst = max(worst, err)
    end do
    call report(nbad == 0 .and. worst <= 1.0e-13_wp, 'recurrence gradient = A x - b after 1..40 box steps', &
                worst, 1.0e-13_wp)
  end subroutine test_recurrence

  !> The exact line search of mprgp_support cut at an upper bound (A = I).
  subroutine test_line_search()
    real(wp) :: x(2), g(2), l(2), u(2), d(2), p(2), ap(2)
    logical :: moved
    l = -1.0_wp
    u = 1.0_wp
    d = [1.0_wp, 0.0_wp]
    x = 0.0_wp
    g = [-10.0_wp, 0.0_wp]
    moved = line_search(x, g, box_set(l, u), d, d, .false., 1.0_wp, p, ap)
    call report(moved .and. x(1) == 1.0_wp .and. x(2) == 0.0_wp .and. g(1) == -9.0_wp, &
                'line search: cut at the upper bound (x = u exactly, g updated)')
    x = 0.0_wp
    g = [-10.0_wp, 0.0_wp]
    moved = line_search(x, g, box_set(l, u), d, d, .true., 1.0_wp, p, ap)
    call report(.not. moved .and. all(x == 0.0_wp) .and. g(1) == -10.0_wp, &
                'line search: a whole step through the upper bound is refused')
    x = 0.0_wp
    g = [10.0_wp, 0.0_wp]
    moved = line_search(x, g, box_set(l, u), d, d, .false., 1.0_wp, p, ap)
    call report(moved .and. x(1) == -1.0_wp .and. g(1) == 9.0_wp, 'line search: cut at the lower bound')
    x = [1.0_wp, 0.0_wp]
    g = [-3.0_wp, 0.0_wp]
    moved = line_search(x, g, box_set(l, u), d, d, .false., 1.0_wp, p, ap)
    call report(.not. moved .and. x(1) == 1.0_wp, 'line search: no move out of an active upper bound')
  end subroutine test_line_search

  !> The recycled-subspace step skips a stored direction that moves a variable at its upper
  !! bound, and takes one that moves only free variables.
  subroutine test_recycled_subspace()
    real(wp) :: x(2), g(2), l(2), u(2), rw(2, 1), raw(2, 1), v(2), av(2), p(2), ap(2)
    logical :: moved
    l = -1.0_wp
    u = 1.0_wp
    x = [1.0_wp, 0.0_wp]
    g = [-1.0_wp, -0.5_wp]
    rw(:, 1) = [1.0_wp, 0.0_wp]
    raw = rw
    moved = recycled_subspace(x, g, box_set(l, u), rw, raw, 1, 1.0_wp, v, av, p, ap)
    call report(.not. moved .and. all(x == [1.0_wp, 0.0_wp]), 'recycled subspace: a direction moving a variable at u is skipped')
    rw(:, 1) = [0.0_wp, 1.0_wp]
    raw = rw
    moved = recycled_subspace(x, g, box_set(l, u), rw, raw, 1, 1.0_wp, v, av, p, ap)
    call report(moved .and. x(1) == 1.0_wp .and. abs(x(2) - 0.5_wp) <= 4.0_wp * eps .and. abs(g(2)) <= 4.0_wp * eps, &
                'recycled subspace: a direction of the free variables is taken (x2 = 0.5)')
  end subroutine test_recycled_subspace

  !> A warm-start direction s towards the unconstrained minimiser, outside the box: the
  !! first line search is cut at the bounds, and the solve ends at the solution in the box.
  subroutine test_warm_direction()
    integer, parameter :: n = 8
    real(wp) :: a(n, n), af(n, n), b(n), l(n), u(n), x(n), xs(n), xu(n), g(n), mu(0), gm(0, n), e(0)
    real(wp) :: lmin, lmax, err
    type(dense_op_t) :: op
    type(mprgp_t) :: solver
    logical :: ok
    integer :: i, ipiv(n), info
    call random_spd(n, 1.0_wp, a, lmin, lmax)
    do i = 1, n
      b(i) = urand(-1.0_wp, 1.0_wp)
      l(i) = urand(-0.2_wp, -0.1_wp)
      u(i) = urand(0.1_wp, 0.2_wp)
    end do
    call enumerate_box(a, b, gm, e, l, u, xs, mu, g, ok)
    call dense_op_init(op, a)
    solver%opts%rtol = 1.0e-14_wp
    x = 0.0_wp
    xu = b
    af = a
    call dgesv(n, 1, af, n, ipiv, xu, n, info)
    solver%s = xu
    solver%as = matmul(a, solver%s)
    call solver%solve(op, b, l, x, ub=u)
    err = maxval(abs(x - xs)) / maxval(abs(xs))
    call report(ok .and. info == 0 .and. any(xu < l .or. xu > u) .and. &
                solver%stats%status == MPRGP_CONVERGED .and. solver%stats%n_recycled == 1 .and. &
                all(x >= l) .and. all(x <= u) .and. err <= 1.0e-10_wp, &
                'warm direction: line search along s cut at the box, then the solution', err, 1.0e-10_wp)
  end subroutine test_warm_direction

  !> Krylov recycling across a sequence of box solves: converged, inside the box, the true
  !! projected gradient below the tolerance, fewer products than without the ring.
  subroutine test_recycle_sequence()
    integer, parameter :: n = 60, kr = 16, nsolve = 14
    real(wp) :: a(n, n), b0(n), db(n), b(n), l(n), u(n), lmin, lmax, tol
    real(wp) :: x(n, 2), ax(n, 2), g(n), rw(n, kr), raw(n, kr), worst_gp, diff
    integer :: nrw(2), i, k, v, nmv(2), nbad, nup
    type(dense_op_t) :: op
    type(mprgp_t) :: solver
    call random_spd(n, 3.0_wp, a, lmin, lmax)
    call dense_op_init(op, a)
    do i = 1, n
      b0(i) = urand(-1.0_wp, 1.0_wp)
      db(i) = urand(-1.0_wp, 1.0_wp)
      call random_bounds(1 + mod(i, 3), 0.0_wp, 1.0e-3_wp, l(i), u(i))
    end do
    x = 0.0_wp
    ax = 0.0_wp
    rw = 0.0_wp
    raw = 0.0_wp
    nrw = [0, 1]
    nmv = 0
    nbad = 0
    nup = 0
    worst_gp = 0.0_wp
    diff = 0.0_wp
    solver%opts%lambda_max = lmax
    solver%opts%use_ax = .true.
    solver%opts%rtol = 0.0_wp
    do k = 1, nsolve
      b = b0 + (-0.4_wp)**k * db
      tol = 1.0e-4_wp * 0.4_wp**k * norm2(b0)
      solver%opts%atol = tol
      do v = 1, 2
        solver%opts%recycle = v == 1
        solver%ax = ax(:, v)
        if (v == 1) then
          call solver%solve(op, b, l, x(:, v), rw, raw, nrw, ub=u)
        else
          call solver%solve(op, b, l, x(:, v), ub=u)
        end if
        ax(:, v) = solver%ax
        nmv(v) = nmv(v) + solver%stats%n_matvec
        g = matmul(a, x(:, v)) - b
        worst_gp = max(worst_gp, norm2(box_projected(g, x(:, v), l, u)) / tol)
        if (solver%stats%status /= MPRGP_CONVERGED .or. any(x(:, v) < l) .or. any(x(:, v) > u)) nbad = nbad + 1
      end do
      nup = max(nup, count(x(:, 1) == u))
      diff = max(diff, norm2(x(:, 1) - x(:, 2)) / norm2(x(:, 2)))
    end do
    call report(nbad == 0 .and. nup > 0 .and. worst_gp <= 1.0_wp + 1.0e-6_wp, 'box recycle: '//i2s(nsolve)// &
                ' solves converged in the box (up to '//i2s(nup)//' at u), true |gP| / tol', worst_gp, 1.0_wp)
    call report(nmv(1) < nmv(2), 'box recycle: products with stored directions ('//i2s(nmv(1))// &
                ') fewer than without ('//i2s(nmv(2))//')', real(nmv(1), wp), real(nmv(2), wp))
    call report(diff <= 1.0e-3_wp, 'box recycle: the same solutions with and without the ring', diff, 1.0e-3_wp)
  end subroutine test_recycle_sequence

  !> A lower-bound problem solved three times, ub absent, ub = +huge and ub finite but never
  !! reached: the same iterates bit for bit (x, g, A x and every count), over a sequence of
  !! solves with use_ax, a warm direction and recycling, and for SMALBE.
  subroutine test_lower_path_unchanged()
    integer, parameter :: n = 40, kr = 8, nsolve = 6
    real(wp) :: a(n, n), b0(n), db(n), b(n), l(n), ub(n, 2:3), lmin, lmax
    real(wp) :: x(n, 3), xprev(n, 3), rw(n, kr, 3), raw(n, kr, 3), gm(1, n), e(1), mu(1, 3), rho
    integer :: nrw(2, 3), i, k, v, nbad, nsame, counts(6, 3)
    type(dense_op_t) :: op, opp
    type(mprgp_t) :: solver(3), sm(3)
    type(smalbe_stats_t) :: sst(3)
    call random_spd(n, 2.0_wp, a, lmin, lmax)
    call dense_op_init(op, a)
    do i = 1, n
      b0(i) = urand(-1.0_wp, 1.0_wp)
      db(i) = urand(-1.0_wp, 1.0_wp)
      l(i) = urand(-0.05_wp, 0.0_wp)
      if (mod(i, 4) == 0) l(i) = -big
    end do
    ub(:, 2) = big
    ub(:, 3) = 1.0e30_wp
    x = 0.0_wp
    rw = 0.0_wp
    raw = 0.0_wp
    nrw = 1
    nrw(1, :) = 0
    nbad = 0
    nsame = 0
    do k = 1, nsolve
      b = b0 + (-0.5_wp)**k * db
      do v = 1, 3
        solver(v)%opts%rtol = 1.0e-10_wp
        solver(v)%opts%recycle = .true.
        solver(v)%opts%use_ax = .false.
        if (k > 1) then
          solver(v)%opts%use_ax = .true.
          if (mod(k, 2) == 0) then
            solver(v)%s = x(:, v) - xprev(:, v)
            solver(v)%as = matmul(a, solver(v)%s)
          end if
        end if
        xprev(:, v) = x(:, v)
        if (v == 1) then
          call solver(v)%solve(op, b, l, x(:, v), rw(:, :, v), raw(:, :, v), nrw(:, v))
        else
          call solver(v)%solve(op, b, l, x(:, v), rw(:, :, v), raw(:, :, v), nrw(:, v), ub=ub(:, v))
        end if
        associate (s => solver(v)%stats)
          counts(:, v) = [s%n_cg, s%n_exp, s%n_prop, s%n_matvec, s%n_recycled, s%status]
        end associate
      end do
      if (solver(1)%stats%status /= MPRGP_CONVERGED .or. count(x(:, 1) == l) == 0) nbad = nbad + 1
      if (all(x(:, 2) == x(:, 1)) .and. all(x(:, 3) == x(:, 1)) .and. all(solver(2)%g == solver(1)%g) .and. &
          all(solver(3)%g == solver(1)%g) .and. all(solver(2)%ax == solver(1)%ax) .and. &
          all(solver(3)%ax == solver(1)%ax) .and. all(counts(:, 2) == counts(:, 1)) .and. &
          all(counts(:, 3) == counts(:, 1)) .and. all(rw(:, :, 2) == rw(:, :, 1)) .and. &
          all(rw(:, :, 3) == rw(:, :, 1))) nsame = nsame + 1
    end do
    call report(nbad == 0, 'lower path: '//i2s(nsolve)//' lower-bound solves converged with active bounds')
    call report(nsame == nsolve, 'lower path: ub absent, +huge, 1e30: the same x, g, A x, ring and counts, '// &
                i2s(nsame)//' of '//i2s(nsolve)//' solves bit for bit')
    ! SMALBE: one equality row
    do i = 1, n
      gm(1, i) = urand(0.2_wp, 1.0_wp)
    end do
    e(1) = 0.3_wp * sum(gm)
    rho = 10.0_wp * lmax / sum(gm**2)
    call dense_op_init(opp, a + rho * matmul(transpose(gm), gm))
    do v = 1, 3
      sm(v)%opts%rtol = 1.0e-12_wp
      sm(v)%opts%lambda_max = lmax + rho * sum(gm**2)
      sm(v)%opts%eq_m = lmax / sqrt(sum(gm**2))
      sm(v)%opts%eq_feas = 1.0e-12_wp * norm2(e)
      x(:, v) = max(l, 0.0_wp)
      mu(:, v) = 0.0_wp
      if (v == 1) then
        call smalbe_solve(sm(v), opp, b0, gm, e, rho, l, x(:, v), mu(:, v), sst(v))
      else
        call smalbe_solve(sm(v), opp, b0, gm, e, rho, l, x(:, v), mu(:, v), sst(v), ub=ub(:, v))
      end if
    end do
    call report(sst(1)%inner%status == MPRGP_CONVERGED .and. all(x(:, 2) == x(:, 1)) .and. &
                all(x(:, 3) == x(:, 1)) .and. all(mu(:, 2) == mu(:, 1)) .and. all(mu(:, 3) == mu(:, 1)) .and. &
                sst(2)%n_matvec == sst(1)%n_matvec .and. sst(3)%n_matvec == sst(1)%n_matvec .and. &
                sst(2)%updates == sst(1)%updates .and. sst(3)%updates == sst(1)%updates, &
                'lower path: SMALBE with ub absent, +huge, 1e30 bit for bit ('//i2s(sst(1)%updates)// &
                ' updates, '//i2s(sst(1)%n_matvec)//' products)')
  end subroutine test_lower_path_unchanged

  !> SMALBE with one equality row and a box against the enumeration of the equality- and
  !! box-constrained QP: x to 1e-8, G x = e to 1e-10, the bound multipliers' signs
  !! (g >= 0 at l, g <= 0 at u, g = 0 free; g = Hx - c + G'mu).
  subroutine test_smalbe_box()
    integer, parameter :: n = 7, nprob = 20
    real(wp) :: h(n, n), c(n), gm(1, n), e(1), l(n), u(n), x(n), xs(n), gs(n), mus(1), mu(1), g(n)
    real(wp) :: lmin, lmax, rho, err, feas, sgn, tolg, werr, wfeas, wsgn
    integer :: ip, i, nok, nat(3)
    type(dense_op_t) :: op
    type(smalbe_stats_t) :: st
    logical :: ok
    nok = 0
    nat = 0
    werr = 0.0_wp
    wfeas = 0.0_wp
    wsgn = 0.0_wp
    do ip = 1, nprob
      call random_spd(n, 1.0_wp, h, lmin, lmax)
      do i = 1, n
        c(i) = urand(-1.0_wp, 1.0_wp)
        gm(1, i) = urand(0.2_wp, 1.0_wp)
        l(i) = urand(-0.3_wp, 0.0_wp)
        u(i) = urand(0.0_wp, 0.3_wp)
      end do
      l(1) = -big
      u(2) = big
      e(1) = dot_product(gm(1, :), 0.5_wp * (max(l, -0.3_wp) + min(u, 0.3_wp))) + urand(-0.1_wp, 0.1_wp)
      call enumerate_box(h, c, gm, e, l, u, xs, mus, gs, ok)
      rho = 10.0_wp * lmax / sum(gm**2)
      call dense_op_init(op, h + rho * matmul(transpose(gm), gm))
      x = 0.0_wp
      mu = 0.0_wp
      block
        type(mprgp_t) :: solver
        solver%opts%rtol = 1.0e-14_wp
        solver%opts%lambda_max = lmax + rho * sum(gm**2)
        solver%opts%eq_m = lmax / sqrt(sum(gm**2))
        solver%opts%eq_feas = 1.0e-14_wp * norm2(e)
        ! G x - e is computed to about eps sum |G_i x_i| <= eps |G| |x|, which exceeds 1e-14 |e|
        ! where |e| << |G| |x| (one of these problems: 1.3e-16 against 8e-17): feasible down to
        ! that rounding, or SMALBE spins to its update limit on rounding alone
        solver%opts%eq_feas_x = 10.0_wp * sqrt(real(n, wp)) * epsilon(1.0_wp) * norm2(gm)
        call smalbe_solve(solver, op, c, gm, e, rho, l, x, mu, st, ub=u)
      end block
      g = matmul(h, x) - c + mu(1) * gm(1, :)
      err = maxval(abs(x - xs)) / maxval(abs(xs))
      feas = abs(dot_product(gm(1, :), x) - e(1)) / (sum(abs(gm)) * maxval(abs(x)))
      tolg = 1.0e-8_wp * (maxval(abs(c)) + lmax * maxval(abs(x)))
      sgn = 0.0_wp
      do i = 1, n
        if (x(i) == l(i)) then
          sgn = max(sgn, -g(i) / tolg)
        else if (x(i) == u(i)) then
          sgn = max(sgn, g(i) / tolg)
        else
          sgn = max(sgn, abs(g(i)) / tolg)
        end if
        if (xs(i) == l(i)) nat(1) = nat(1) + 1
        if (xs(i) == u(i)) nat(2) = nat(2) + 1
        if (xs(i) > l(i) .and. xs(i) < u(i)) nat(3) = nat(3) + 1
      end do
      werr = max(werr, err)
      wfeas = max(wfeas, feas)
      wsgn = max(wsgn, sgn)
      if (ok .and. st%inner%status == MPRGP_CONVERGED .and. all(x >= l) .and. all(x <= u)) nok = nok + 1
    end do
    call report(nok == nprob, 'SMALBE box: '//i2s(nok)//' of '//i2s(nprob)//' converged in the box, reference found')
    call report(werr <= 1.0e-8_wp, 'SMALBE box: max |x - x_ref| / |x_ref| ('//i2s(nat(1))//' at l, '// &
                i2s(nat(2))//' at u, '//i2s(nat(3))//' free)', werr, 1.0e-8_wp)
    call report(minval(nat) > 0, 'SMALBE box: the references have variables at l, at u and free')
    call report(wfeas <= 1.0e-10_wp, 'SMALBE box: |G x - e| relative', wfeas, 1.0e-10_wp)
    call report(wsgn <= 1.0_wp, 'SMALBE box: KKT, g >= 0 at l, g <= 0 at u, g = 0 free (ratio to tol)', wsgn, 1.0_wp)
  end subroutine test_smalbe_box

  !> An empty box, a wrong size and a non-finite upper bound are refused.
  subroutine test_bad_upper()
    real(wp) :: a(2, 2), b(2), l(2), x(2)
    type(dense_op_t) :: op
    type(mprgp_t) :: solver
    a = reshape([2.0_wp, 0.0_wp, 0.0_wp, 2.0_wp], [2, 2])
    call dense_op_init(op, a)
    b = 1.0_wp
    l = 0.0_wp
    x = 0.0_wp
    call solver%solve(op, b, l, x, ub=[1.0_wp, -1.0_wp])
    call report(solver%stats%status == MPRGP_BAD_ARG, 'bad ub: ub < lb refused ('//trim(solver%stats%message)//')')
    call solver%solve(op, b, l, x, ub=[1.0_wp])
    call report(solver%stats%status == MPRGP_BAD_ARG, 'bad ub: size refused ('//trim(solver%stats%message)//')')
    call solver%solve(op, b, l, x, ub=[1.0_wp, ieee_value(1.0_wp, ieee_quiet_nan)])
    call report(solver%stats%status == MPRGP_NONFINITE .or. solver%stats%status == MPRGP_BAD_ARG, &
                'bad ub: non-finite refused ('//mprgp_status_name(solver%stats%status)//')')
  end subroutine test_bad_upper

end program test_mprgp_box
