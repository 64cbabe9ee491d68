!> Unit tests of module mprgp, its solutions: exact solutions of random QPs by active-set
!! enumeration, KKT, equivalence with CG without bounds, the obstacle problem, b = 0, SI
!! scaling, concurrent solves (test_mprgp_options: its options, failures and state).
!! One line per check: PASS/FAIL, the measured value and its tolerance.
!! Exits with status 1 if any check failed.
program test_mprgp
  use kinds, only: wp
  use linop, only: dense_op_t, csc_op_t, dense_op_init
  use mprgp, only: mprgp_opts_t, mprgp_stats_t, MPRGP_CONVERGED, MPRGP_MAX_IT
  use lapack, only: dposv
  use strings, only: i2s
  use testing, only: report, test_summary, obstacle_problem, set_seed, urand, random_spd, solve_once
  implicit none (type, external)

  real(wp), parameter :: eps = epsilon(1.0_wp)
  real(wp), parameter :: nobound = -huge(1.0_wp)

  call set_seed(20240611)
  call test_enumeration()
  call test_plain_cg()
  call test_obstacle()
  call test_zero_rhs()
  call test_scaling()
  call test_threads()

  call test_summary()

contains

  ! ------------------------------------------------------------------ helpers

  !> Exact solution by enumeration of all active sets of the bounded indices.
  subroutine enumerate_qp(n, a, b, l, xs, ok)
    integer, intent(in) :: n
    real(wp), intent(in) :: a(n, n), b(n), l(n)
    real(wp), intent(out) :: xs(n)
    logical, intent(out) :: ok
    integer :: bnd(n), nb, mask, i, j, nf, info, fr(n)
    logical :: act(n)
    real(wp) :: aff(n, n), rhs(n, 1), x(n), g(n), viol, best, xsc, gsc
    nb = 0
    do i = 1, n
      if (l(i) > nobound) then
        nb = nb + 1
        bnd(nb) = i
      end if
    end do
    best = huge(1.0_wp)
    ok = .false.
    xs = 0.0_wp
    do mask = 0, 2**nb - 1
      act = .false.
      do j = 1, nb
        if (btest(mask, j - 1)) act(bnd(j)) = .true.
      end do
      nf = 0
      do i = 1, n
        if (.not. act(i)) then
          nf = nf + 1
          fr(nf) = i
        end if
      end do
      x = 0.0_wp
      where (act) x = l
      if (nf > 0) then
        aff(1:nf, 1:nf) = a(fr(1:nf), fr(1:nf))
        rhs(1:nf, 1) = b(fr(1:nf)) - matmul(a(fr(1:nf), :), x)
        call dposv('L', nf, 1, aff, n, rhs, n, info)
        if (info /= 0) cycle
        x(fr(1:nf)) = rhs(1:nf, 1)
      end if
      g = matmul(a, x) - b
      xsc = maxval(abs(x)) + 1.0_wp
      gsc = maxval(abs(b)) + maxval(abs(a)) * maxval(abs(x))
      viol = 0.0_wp
      do i = 1, n
        if (act(i)) then
          viol = max(viol, -g(i) / gsc)
        else if (l(i) > nobound) then
          viol = max(viol, (l(i) - x(i)) / xsc)
        end if
      end do
      if (viol < best) then
        best = viol
        xs = x
      end if
    end do
    ok = (best <= 1.0e-10_wp)
  end subroutine enumerate_qp

  !> KKT residuals of x for gradient g: returns the worst violation relative to tolg
  !! (<= 1 means satisfied): feasibility, g >= 0 on the active set, g = 0 on the free
  !! set, complementarity |g_i| (x_i - l_i) <= tolg * max(x - l).
  real(wp) function kkt_ratio(n, x, l, g, tolg) result(r)
    integer, intent(in) :: n
    real(wp), intent(in) :: x(n), l(n), g(n), tolg
    integer :: i
    real(wp) :: smax
    r = 0.0_wp
    smax = 0.0_wp
    do i = 1, n
      if (l(i) > nobound) smax = max(smax, x(i) - l(i))
    end do
    do i = 1, n
      if (x(i) < l(i)) r = huge(1.0_wp)                  ! infeasible: fail outright
      if (x(i) > l(i)) then
        r = max(r, abs(g(i)) / tolg)                      ! free: g = 0
        if (l(i) > nobound .and. smax > 0.0_wp) &
          r = max(r, abs(g(i)) * (x(i) - l(i)) / (tolg * smax))   ! complementarity
      else
        r = max(r, -g(i) / tolg)                          ! active: g >= 0
      end if
    end do
  end function kkt_ratio

  !> Tridiagonal product written independently of linop (for KKT checks).
  subroutine tridiag_mul(n, c, x, y)
    integer, intent(in) :: n
    real(wp), intent(in) :: c, x(n)
    real(wp), intent(out) :: y(n)
    integer :: i
    do i = 1, n
      y(i) = 2.0_wp * x(i)
      if (i > 1) y(i) = y(i) - x(i - 1)
      if (i < n) y(i) = y(i) - x(i + 1)
    end do
    y = c * y
  end subroutine tridiag_mul

  real(wp) function obstacle_exact(t) result(u)
    real(wp), intent(in) :: t
    real(wp) :: a, s
    a = sqrt(2.0_wp / 15.0_wp)
    s = min(t, 1.0_wp - t)
    if (s < a) then
      u = 7.5_wp * s * s - 15.0_wp * a * s
    else
      u = -1.0_wp
    end if
  end function obstacle_exact

  ! ------------------------------------------------------------------ tests

  !> 200 random SPD problems n <= 10 against enumeration of all active sets.
  subroutine test_enumeration()
    integer, parameter :: nprob = 200
    integer :: ip, n, i, nact_tot, nconv, nfound, nkkt, nerr, nmax_it
    real(wp), allocatable :: a(:,:), b(:), l(:), x(:), xs(:), xu(:), g(:), gt(:)
    real(wp) :: lmin, lmax, cexp, err, tolx, worst_err, worst_kkt, tolg, rk, anorm, gerr, worst_g
    type(dense_op_t) :: op
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    logical :: ok
    nact_tot = 0; nconv = 0; nfound = 0; nkkt = 0; nerr = 0; nmax_it = 0
    worst_err = 0.0_wp; worst_kkt = 0.0_wp; worst_g = 0.0_wp
    opts%rtol = 1.0e-10_wp
    do ip = 1, nprob
      n = 1 + mod(ip - 1, 10)
      cexp = urand(0.0_wp, 3.0_wp)
      if (allocated(a)) deallocate (a, b, l, x, xs, xu, g, gt)
      allocate (a(n, n), b(n), l(n), x(n), xs(n), xu(n), g(n), gt(n))
      call random_spd(n, cexp, a, lmin, lmax)
      do i = 1, n
        b(i) = urand(-1.0_wp, 1.0_wp)
      end do
      ! unconstrained solution, then bounds around it so that some are active
      xu = b
      call solve_spd(n, a, xu)
      do i = 1, n
        if (urand(0.0_wp, 1.0_wp) < 0.2_wp) then
          l(i) = nobound
        else
          l(i) = xu(i) + urand(-1.0_wp, 1.0_wp) * norm2(xu) / sqrt(real(n, wp))
        end if
      end do
      call enumerate_qp(n, a, b, l, xs, ok)
      if (ok) nfound = nfound + 1
      do i = 1, n
        if (l(i) > nobound .and. xs(i) <= l(i)) nact_tot = nact_tot + 1
      end do
      ! warm start: half of the problems from 0, half from a random point
      x = 0.0_wp
      if (mod(ip, 2) == 0) then
        do i = 1, n
          x(i) = urand(-2.0_wp, 2.0_wp) * norm2(xs) / sqrt(real(n, wp))
        end do
      end if
      call dense_op_init(op, a)
      call solve_once(op, b, l, x, opts, st, g)
      if (st%status == MPRGP_CONVERGED) nconv = nconv + 1
      if (st%status == MPRGP_MAX_IT) nmax_it = nmax_it + 1
      ! error bound: |x - x*| <= |gP| / lambda_min up to a modest constant
      anorm = lmax
      err = norm2(x - xs)
      tolx = 10.0_wp * (st%gp_norm + 10.0_wp * n * eps * anorm * norm2(xs)) / lmin
      if (err > tolx) nerr = nerr + 1
      worst_err = max(worst_err, err / tolx)
      ! KKT with an independently computed gradient
      gt = matmul(a, x) - b
      tolg = max(opts%rtol * norm2(b), opts%atol) + 10.0_wp * n * eps * (anorm * norm2(x) + norm2(b))
      rk = kkt_ratio(n, x, l, gt, tolg)
      if (rk > 1.0_wp) nkkt = nkkt + 1
      worst_kkt = max(worst_kkt, rk)
      gerr = norm2(g - gt) / (n * eps * (anorm * norm2(x) + norm2(b)))
      worst_g = max(worst_g, gerr)
    end do
    call report(nfound == nprob, 'enumeration: KKT active set found for every problem', real(nfound, wp))
    call report(nact_tot > nprob, 'enumeration: active bounds at the solutions (total count)', real(nact_tot, wp))
    call report(nconv == nprob, 'enumeration: all 200 random problems converged', real(nconv, wp))
    call report(nerr == 0, 'enumeration: |x - x*| <= 10 (|gP| + 10 n eps |A||x*|)/lambda_min, worst ratio', &
               worst_err, 1.0_wp)
    call report(nkkt == 0, 'enumeration: KKT (feasible, g>=0 active, g=0 free, compl.), worst ratio', &
               worst_kkt, 1.0_wp)
    call report(worst_g <= 10.0_wp, 'enumeration: returned g = Ax - b, worst |dg|/(n eps (|A||x|+|b|))', &
               worst_g, 10.0_wp)
  end subroutine test_enumeration

  subroutine solve_spd(n, a, x)
    integer, intent(in) :: n
    real(wp), intent(in) :: a(n, n)
    real(wp), intent(inout) :: x(n)
    real(wp) :: af(n, n), r(n, 1)
    integer :: info
    af = a
    r(:, 1) = x
    call dposv('L', n, 1, af, n, r, n, info)
    if (info /= 0) error stop 'dposv failed in test'
    x = r(:, 1)
  end subroutine solve_spd

  !> Without bounds MPRGP is plain CG: same iterates, same count, no other steps.
  subroutine test_plain_cg()
    integer, parameter :: n = 200
    real(wp) :: a(n, n), b(n), l(n), x(n), xc(n), r(n), p(n), ap(n), lmin, lmax
    real(wp) :: rr, rrn, alpha, tol, diff, worst
    real(wp), allocatable :: xhist(:,:)
    integer :: i, k, kcg, nbadcount
    type(dense_op_t) :: op
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    ! condition number 10: finite-precision CG is then reproducible to rounding
    ! (with cond 1e3 two correct CG codes part ways after ~20 steps).
    call random_spd(n, 1.0_wp, a, lmin, lmax)
    do i = 1, n
      b(i) = urand(-1.0_wp, 1.0_wp)
    end do
    l = nobound
    opts%rtol = 1.0e-10_wp
    ! plain CG (Hestenes-Stiefel), from x = 0
    allocate (xhist(n, 0:5 * n))
    xc = 0.0_wp
    r = b
    p = r
    rr = dot_product(r, r)
    tol = opts%rtol * norm2(b)
    kcg = 0
    xhist(:, 0) = xc
    do while (sqrt(rr) > tol .and. kcg < 5 * n)
      ap = matmul(a, p)
      alpha = rr / dot_product(p, ap)
      xc = xc + alpha * p
      r = r - alpha * ap
      rrn = dot_product(r, r)
      p = r + (rrn / rr) * p
      rr = rrn
      kcg = kcg + 1
      xhist(:, kcg) = xc
    end do
    call dense_op_init(op, a)
    ! iterates: stop MPRGP after k steps
    worst = 0.0_wp
    nbadcount = 0
    do k = 1, kcg - 1
      opts%max_it = k
      x = 0.0_wp
      call solve_once(op, b, l, x, opts, st)
      diff = norm2(x - xhist(:, k)) / norm2(xhist(:, kcg))
      worst = max(worst, diff)
      if (st%status /= MPRGP_MAX_IT .or. st%n_cg /= k .or. st%n_exp /= 0 .or. st%n_prop /= 0 .or. st%n_matvec /= k + 2) &
        nbadcount = nbadcount + 1
    end do
    call report(worst <= 1.0e-12_wp, 'plain CG (n = 200, cond 10): all iterates equal, max |x_k - x_k^CG|/|x|', &
               worst, 1.0e-12_wp)
    call report(nbadcount == 0, 'plain CG: after k < k_CG steps max_it, n_cg = k, n_exp = n_prop = 0, '// &
               'n_matvec = k+2 (initial + final true gradient, no power its)')
    opts%max_it = 10000
    x = 0.0_wp
    call solve_once(op, b, l, x, opts, st)
    call report(st%status == MPRGP_CONVERGED .and. st%n_cg == kcg, &
               'plain CG: converged with the same step count as CG ('//i2s(kcg)//')', real(st%n_cg, wp))
    call report(st%n_exp == 0 .and. st%n_prop == 0 .and. st%n_matvec == st%n_cg + 2, &
               'plain CG: n_exp = n_prop = 0, n_matvec = n_cg + 2 (initial + confirming product)', &
               real(st%n_matvec, wp))
  end subroutine test_plain_cg

  !> 1D obstacle problem, n = 100, 1000, 5000.
  subroutine test_obstacle()
    integer :: ns(3) = [100, 1000, 5000], k, n, i, ncontact
    type(csc_op_t) :: op
    real(wp), allocatable :: b(:), l(:), x(:), g(:), gt(:)
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    real(wp) :: c, tolg, rk, err, h, anorm
    character(len=160) :: line
    do k = 1, size(ns)
      n = ns(k)
      call obstacle_problem(n, op, b, l, 1.0_wp)
      allocate (x(n), g(n), gt(n))
      x = 0.0_wp
      opts%rtol = 1.0e-8_wp
      opts%max_it = 500000
      call solve_once(op, b, l, x, opts, st, g)
      write (line, '(a,i0,a,i0,a,i0,a,i0,a,i0,a,es9.2)') 'obstacle n = ', n, ': ', st%n_matvec, &
        ' products (cg ', st%n_cg, ', exp ', st%n_exp, ', prop ', st%n_prop, '), |gP|/|b| = ', &
        st%gp_norm / st%b_norm
      call report(st%status == MPRGP_CONVERGED, trim(line))
      c = real(n + 1, wp)**2
      call tridiag_mul(n, c, x, gt)
      gt = gt - b
      anorm = 4.0_wp * c
      tolg = opts%rtol * norm2(b) + 10.0_wp * n * eps * (anorm * norm2(x) + norm2(b))
      rk = kkt_ratio(n, x, l, gt, tolg)
      call report(rk <= 1.0_wp, 'obstacle n = '//i2s(n)//': KKT residual / tolerance', rk, 1.0_wp)
      ncontact = count(x <= l)
      h = 1.0_wp / (n + 1)
      err = 0.0_wp
      do i = 1, n
        err = max(err, abs(x(i) - obstacle_exact(i * h)))
      end do
      call report(err <= 2.0_wp * h .and. ncontact > n / 5, 'obstacle n = '//i2s(n)// &
                 ': max |u - u_exact| <= 2h (contact nodes '//i2s(ncontact)//')', err, 2.0_wp * h)
      deallocate (x, g, gt)
    end do
  end subroutine test_obstacle

  !> b = 0: the relative tolerance is void; no division by zero, a sensible answer.
  subroutine test_zero_rhs()
    integer, parameter :: n = 10
    real(wp) :: a(n, n), b(n), l(n), x(n), xs(n), lmin, lmax, gt(n), tolg
    type(dense_op_t) :: op
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    logical :: ok
    integer :: i
    call random_spd(n, 2.0_wp, a, lmin, lmax)
    call dense_op_init(op, a)
    b = 0.0_wp
    l = -1.0_wp
    x = 0.3_wp
    call solve_once(op, b, l, x, opts, st)
    call report(st%status == MPRGP_CONVERGED .and. maxval(abs(x)) <= 1.0e3_wp * eps, &
               'b = 0, l < 0: converged to x = 0 ('//trim(st%message)//')', maxval(abs(x)))
    do i = 1, n
      l(i) = merge(0.5_wp, nobound, mod(i, 2) == 0)
    end do
    x = 0.0_wp
    call solve_once(op, b, l, x, opts, st)
    call enumerate_qp(n, a, b, l, xs, ok)
    gt = matmul(a, x) - b
    tolg = 100.0_wp * n * eps * lmax * norm2(x)
    call report(st%status == MPRGP_CONVERGED .and. kkt_ratio(n, x, l, gt, tolg) <= 1.0_wp .and. &
               norm2(x - xs) <= 1.0e-10_wp * lmax / lmin * norm2(xs), &
               'b = 0, some l > 0, rtol = atol = 0 floor: converged, KKT, = enumeration', &
               norm2(x - xs) / norm2(xs))
    opts%atol = 1.0e-6_wp
    x = 0.0_wp
    call solve_once(op, b, l, x, opts, st)
    call report(st%status == MPRGP_CONVERGED .and. st%gp_norm <= 1.0e-6_wp, &
               'b = 0 with atol = 1e-6: converged on the absolute floor', st%gp_norm, 1.0e-6_wp)
  end subroutine test_zero_rhs

  !> SI magnitudes: A*1e11, b*1e6 (x scales by 1e-5, so do the bounds).
  subroutine test_scaling()
    integer, parameter :: nr = 10
    type(csc_op_t) :: op0, op1
    type(dense_op_t) :: dop0, dop1
    real(wp), allocatable :: b(:), l(:), x0(:), x1(:)
    real(wp) :: a(nr, nr), br(nr), lr(nr), xr0(nr), xr1(nr), lmin, lmax, tolx, d
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st0, st1
    integer :: n, i
    n = 100
    call obstacle_problem(n, op0, b, l, 1.0_wp)
    call obstacle_problem(n, op1, b, l, 1.0e11_wp)
    allocate (x0(n), x1(n))
    opts%rtol = 1.0e-8_wp
    opts%max_it = 100000
    x0 = 0.0_wp
    call solve_once(op0, b, l, x0, opts, st0)
    x1 = 0.0_wp
    call solve_once(op1, 1.0e6_wp * b, 1.0e-5_wp * l, x1, opts, st1)
    tolx = 10.0_wp * opts%rtol * norm2(b) / (acos(-1.0_wp)**2)
    d = norm2(1.0e5_wp * x1 - x0)
    call report(st0%status == MPRGP_CONVERGED .and. st1%status == MPRGP_CONVERGED .and. d <= tolx, &
               'scaling (obstacle n=100): 1e5 x(1e11 A, 1e6 b) = x(A, b)', d, tolx)
    call report(abs(st1%n_matvec - st0%n_matvec) <= 0.1_wp * st0%n_matvec + 5, &
               'scaling (obstacle n=100): products '//i2s(st1%n_matvec)//' vs '//i2s(st0%n_matvec))
    call random_spd(nr, 2.0_wp, a, lmin, lmax)
    do i = 1, nr
      br(i) = urand(-1.0_wp, 1.0_wp)
      lr(i) = merge(urand(-0.5_wp, 0.5_wp), nobound, mod(i, 4) /= 0)
    end do
    call dense_op_init(dop0, a)
    call dense_op_init(dop1, 1.0e11_wp * a)
    xr0 = 0.0_wp
    call solve_once(dop0, br, lr, xr0, opts, st0)
    xr1 = 0.0_wp
    call solve_once(dop1, 1.0e6_wp * br, 1.0e-5_wp * lr, xr1, opts, st1)
    tolx = 10.0_wp * opts%rtol * norm2(br) / lmin
    d = norm2(1.0e5_wp * xr1 - xr0)
    call report(st0%status == MPRGP_CONVERGED .and. st1%status == MPRGP_CONVERGED .and. d <= tolx .and. &
               abs(st1%n_matvec - st0%n_matvec) <= 0.1_wp * st0%n_matvec + 3, &
               'scaling (random n=10): same x, products '//i2s(st1%n_matvec)//' vs '//i2s(st0%n_matvec), &
               d, tolx)
  end subroutine test_scaling

  !> Two OpenMP threads solve different problems at once: same results as serially.
  subroutine test_threads()
    integer, parameter :: n = 60
    real(wp) :: a1(n, n), a2(n, n), b1(n), b2(n), l1(n), l2(n), lmin, lmax
    real(wp) :: xs1(n), xs2(n), xp1(n), xp2(n), d
    type(dense_op_t) :: op1, op2
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: s1, s2, t1, t2
    integer :: i, rep
    logical :: ok
    call random_spd(n, 2.0_wp, a1, lmin, lmax)
    call random_spd(n, 3.0_wp, a2, lmin, lmax)
    do i = 1, n
      b1(i) = urand(-1.0_wp, 1.0_wp)
      b2(i) = urand(-1.0_wp, 1.0_wp)
      l1(i) = urand(-0.3_wp, 0.3_wp)
      l2(i) = merge(urand(-0.3_wp, 0.3_wp), nobound, mod(i, 3) /= 0)
    end do
    call dense_op_init(op1, a1)
    call dense_op_init(op2, a2)
    opts%rtol = 1.0e-10_wp
    xs1 = 0.0_wp
    xs2 = 0.0_wp
    call solve_once(op1, b1, l1, xs1, opts, s1)
    call solve_once(op2, b2, l2, xs2, opts, s2)
    ok = .true.
    d = 0.0_wp
    do rep = 1, 20
      xp1 = 0.0_wp
      xp2 = 0.0_wp
      !$omp parallel sections num_threads(2)
      !$omp section
      call solve_once(op1, b1, l1, xp1, opts, t1)
      !$omp section
      call solve_once(op2, b2, l2, xp2, opts, t2)
      !$omp end parallel sections
      d = max(d, norm2(xp1 - xs1) / norm2(xs1), norm2(xp2 - xs2) / norm2(xs2))
      ok = ok .and. t1%status == MPRGP_CONVERGED .and. t2%status == MPRGP_CONVERGED .and. &
           t1%n_matvec == s1%n_matvec .and. t2%n_matvec == s2%n_matvec
    end do
    call report(ok .and. d <= 1.0e-12_wp, 'threads: 2 concurrent solves x 20 = serial results', d, 1.0e-12_wp)
  end subroutine test_threads

end program test_mprgp
