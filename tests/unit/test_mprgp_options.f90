!> Unit tests of module mprgp, its options, failures and state: bad arguments, non-finite
!! input and indefinite matrices reported; the step length guard against a wrong
!! lambda_max or alpha_bar; the stop hook; Krylov recycling over a sequence of solves; one
!! solver reused for problems of different sizes (test_mprgp: the solutions).
!! One line per check: PASS/FAIL, the measured value and its tolerance.
!! Exits with status 1 if any check failed.
program test_mprgp_options
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use kinds, only: wp
  use linop, only: linop_t, dense_op_t, csc_op_t, dense_op_init
  use mprgp, only: mprgp_t, lambda_max_estimate, mprgp_status_name, mprgp_opts_t, mprgp_stats_t, &
                   MPRGP_CONVERGED, MPRGP_MAX_IT, MPRGP_NONFINITE, MPRGP_NOT_SPD, MPRGP_BAD_ARG, &
                   MPRGP_STOPPED
  use strings, only: i2s, fixed
  use testing, only: report, test_summary, obstacle_problem, set_seed, urand, random_spd, spd_from_eigs, &
                     solve_once
  implicit none (type, external)

  real(wp), parameter :: nobound = -huge(1.0_wp)
  integer :: calls = 0   ! polls of the stop hook

  call set_seed(20240611)
  call test_bad_arguments()
  call test_alpha_guard()
  call test_stop_hook()
  call test_recycle()
  call test_solver_reuse()

  call test_summary()

contains

  !> Bad arguments, non-finite input, indefinite matrices: a status and a message.
  subroutine test_bad_arguments()
    integer, parameter :: n = 20
    real(wp) :: a(n, n), b(n), l(n), x(n), lmin, lmax, d(n), xs(n - 1), axsmall(n - 1)
    type(dense_op_t) :: op
    type(mprgp_opts_t) :: opts, bad
    type(mprgp_stats_t) :: st
    integer :: i
    call random_spd(n, 1.0_wp, a, lmin, lmax)
    call dense_op_init(op, a)
    do i = 1, n
      b(i) = urand(-1.0_wp, 1.0_wp)
    end do
    l = 0.0_wp
    x = 0.0_wp
    xs = 0.0_wp
    call solve_once(op, b, l, xs, opts, st)
    call report(st%status == MPRGP_BAD_ARG .and. len_trim(st%message) > 0, &
               'bad args: size(x) /= n -> bad argument: "'//trim(st%message)//'"')
    call solve_once(op, b(1:n - 1), l, x, opts, st)
    call report(st%status == MPRGP_BAD_ARG .and. len_trim(st%message) > 0, &
               'bad args: size(b) /= n -> bad argument')
    bad = opts
    bad%use_ax = .true.
    call solve_once(op, b, l, x, bad, st)
    call report(st%status == MPRGP_BAD_ARG .and. len_trim(st%message) > 0, &
               'bad args: use_ax without ax -> bad argument: "'//trim(st%message)//'"')
    call solve_once(op, b, l, x, bad, st, ax=axsmall)
    call report(st%status == MPRGP_BAD_ARG .and. len_trim(st%message) > 0, &
               'bad args: size(ax) /= n -> bad argument: "'//trim(st%message)//'"')
    bad = opts
    bad%rtol = -1.0e-6_wp
    call solve_once(op, b, l, x, bad, st)
    call report(st%status == MPRGP_BAD_ARG .and. len_trim(st%message) > 0, &
               'bad args: rtol < 0 -> bad argument: "'//trim(st%message)//'"')
    bad = opts
    bad%max_it = -3
    call solve_once(op, b, l, x, bad, st)
    call report(st%status == MPRGP_BAD_ARG, 'bad args: max_it < 0 -> bad argument')
    bad = opts
    bad%gamma = 0.0_wp
    call solve_once(op, b, l, x, bad, st)
    call report(st%status == MPRGP_BAD_ARG, 'bad args: gamma = 0 -> bad argument')
    bad = opts
    bad%polish_scale = 0.5_wp
    call solve_once(op, b, l, x, bad, st)
    call report(st%status == MPRGP_BAD_ARG .and. index(st%message, 'polish_scale') > 0, &
               'bad args: polish_scale < 1 -> bad argument: "'//trim(st%message)//'"')
    call report(mprgp_status_name(MPRGP_BAD_ARG) == 'bad argument' .and. &
               mprgp_status_name(MPRGP_NOT_SPD) == 'not SPD' .and. &
               mprgp_status_name(MPRGP_NONFINITE) == 'non-finite' .and. &
               mprgp_status_name(MPRGP_MAX_IT) == 'max_it' .and. &
               mprgp_status_name(MPRGP_CONVERGED) == 'converged', 'status names')
    ! NaN in b, NaN in lb
    b(3) = ieee_value(1.0_wp, ieee_quiet_nan)
    call solve_once(op, b, l, x, opts, st)
    call report(st%status == MPRGP_NONFINITE .and. len_trim(st%message) > 0, &
               'NaN in b -> non-finite: "'//trim(st%message)//'"')
    b(3) = 0.5_wp
    l(5) = ieee_value(1.0_wp, ieee_quiet_nan)
    call solve_once(op, b, l, x, opts, st)
    call report(st%status == MPRGP_NONFINITE, 'NaN in lb -> non-finite')
    l(5) = 0.0_wp
    ! max_it reached is reported, not silent
    bad = opts
    bad%max_it = 2
    x = 0.0_wp
    call solve_once(op, b, -b * 0.0_wp - 1.0_wp, x, bad, st)
    call report(st%status == MPRGP_MAX_IT .and. len_trim(st%message) > 0, &
               'max_it = 2 -> max_it: "'//trim(st%message)//'"')
    ! indefinite matrix (eigenvalues of both signs), no bounds, generic b
    do i = 1, n
      d(i) = merge(-1.0_wp, 1.0_wp, mod(i, 3) == 0) * (1.0_wp + i)
    end do
    call spd_from_eigs(n, d, a)
    call dense_op_init(op, a)
    l = nobound
    x = 0.0_wp
    call solve_once(op, b, l, x, opts, st)
    call report(st%status == MPRGP_NOT_SPD, 'indefinite A, no bounds -> not SPD: "'//trim(st%message)//'"')
    ! negative definite with bounds: every direction has p'Ap < 0
    call spd_from_eigs(n, -abs(d), a)
    call dense_op_init(op, a)
    l = -1.0_wp
    x = 0.0_wp
    call solve_once(op, b, l, x, opts, st)
    call report(st%status /= MPRGP_CONVERGED .and. st%status /= MPRGP_BAD_ARG, &
               'negative definite A with bounds -> not converged ('//mprgp_status_name(st%status)//')')
    ! zero matrix
    a = 0.0_wp
    call dense_op_init(op, a)
    x = 0.0_wp
    call solve_once(op, b, l, x, opts, st)
    call report(st%status == MPRGP_NOT_SPD, 'zero A -> not SPD ('//mprgp_status_name(st%status)//')')
    ! empty problem
    call dense_op_init(op, a(1:0, 1:0))
    call solve_once(op, b(1:0), l(1:0), x(1:0), opts, st)
    call report(st%status == MPRGP_CONVERGED, 'n = 0 -> converged')
  end subroutine test_bad_arguments

  !> alpha_bar guard: a lambda_max 10x too small or an alpha_bar 20x too large must
  !! not break convergence: same solution, alpha_bar cut so that alpha_bar times the
  !! largest Rayleigh quotient met stays <= 2. On the obstacle problem (few
  !! expansions) and on a dense random problem with many expansions.
  subroutine test_alpha_guard()
    integer, parameter :: nd = 150
    type(csc_op_t) :: cop
    type(dense_op_t) :: dop
    real(wp), allocatable :: b(:), l(:)
    real(wp) :: a(nd, nd), lmin, lmax, lam_true, est
    integer :: n, nmv, i
    n = 200
    call obstacle_problem(n, cop, b, l, 1.0_wp)
    lam_true = 4.0_wp * real(n + 1, wp)**2 * sin(real(n, wp) * acos(-1.0_wp) / (2.0_wp * (n + 1)))**2
    est = lambda_max_estimate(cop, 20, nmv)
    call report(est <= lam_true * (1.0_wp + 1.0e-12_wp) .and. est >= 0.95_wp * lam_true .and. nmv == 20, &
               'lambda_max_estimate: 20 power its within [0.95, 1] lambda_max (obstacle n = 200)', est / lam_true)
    call guard_case(cop, b, l, lam_true, acos(-1.0_wp)**2, 'obstacle n = 200')
    call random_spd(nd, 3.0_wp, a, lmin, lmax)
    call dense_op_init(dop, a)
    deallocate (b, l)
    allocate (b(nd), l(nd))
    do i = 1, nd
      b(i) = urand(-1.0_wp, 1.0_wp)
      l(i) = urand(-0.005_wp, 0.005_wp)
    end do
    est = lambda_max_estimate(dop, 20, nmv)
    call report(est <= lmax * (1.0_wp + 1.0e-12_wp) .and. est >= 0.9_wp * lmax, &
               'lambda_max_estimate: within [0.9, 1] lambda_max (dense n = 150, cond 1e3)', est / lmax)
    call guard_case(dop, b, l, lmax, lmin, 'dense n = 150')
  end subroutine test_alpha_guard

  subroutine guard_case(op, b, l, lam_true, lam_min, name)
    class(linop_t), intent(inout) :: op
    real(wp), intent(in) :: b(:), l(:), lam_true, lam_min
    character(len=*), intent(in) :: name
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st0, st1, st2
    real(wp) :: x0(size(b)), x1(size(b)), x2(size(b)), d, tolx
    opts%rtol = 1.0e-8_wp
    opts%max_it = 100000
    x0 = 0.0_wp
    call solve_once(op, b, l, x0, opts, st0)
    opts%lambda_max = 0.1_wp * lam_true
    x1 = 0.0_wp
    call solve_once(op, b, l, x1, opts, st1)
    opts%lambda_max = 0.0_wp
    opts%alpha_bar = 20.0_wp / lam_true
    x2 = 0.0_wp
    call solve_once(op, b, l, x2, opts, st2)
    tolx = 10.0_wp * opts%rtol * norm2(b) / lam_min
    d = max(norm2(x1 - x0), norm2(x2 - x0))
    call report(st0%status == MPRGP_CONVERGED .and. st1%status == MPRGP_CONVERGED .and. &
               st2%status == MPRGP_CONVERGED .and. d <= tolx, 'alpha guard ('//name// &
               '): default, lambda_max/10, alpha_bar = 20/lambda_max converge to the same x', d, tolx)
    call report(st0%alpha_bar * lam_true <= 2.0_wp .and. st0%alpha_bar * lam_true >= 1.8_wp, &
               'alpha guard ('//name//'): default alpha_bar*lambda_max in [1.8, 2] ('// &
               i2s(st0%n_exp)//' expansions)', st0%alpha_bar * lam_true, 2.0_wp)
    call report(st1%alpha_bar < 19.0_wp / lam_true .and. st2%alpha_bar < 20.0_wp / lam_true .and. &
               st1%alpha_bar * st1%lambda_max <= 2.0_wp .and. st2%alpha_bar * st2%lambda_max <= 2.0_wp, &
               'alpha guard ('//name//'): bad alpha_bar cut to alpha_bar*lambda_max = '// &
               fixed(st1%alpha_bar * lam_true, '(f0.3)')//', '// &
               fixed(st2%alpha_bar * lam_true, '(f0.3)')//'; products '// &
               i2s(st1%n_matvec)//', '//i2s(st2%n_matvec)//' vs '//i2s(st0%n_matvec))
  end subroutine guard_case

  !> The stop hook: a solve asked to stop returns MPRGP_STOPPED at once with a feasible
  !! iterate, after fewer steps than it needs to converge.
  subroutine test_stop_hook()
    type(csc_op_t) :: op
    real(wp), allocatable :: b(:), l(:), x(:)
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    integer :: n
    n = 200
    call obstacle_problem(n, op, b, l, 1.0_wp)
    allocate (x(n))
    x = 0.0_wp
    opts%rtol = 1.0e-10_wp
    opts%stop => stop_after_five
    calls = 0
    call solve_once(op, b, l, x, opts, st)
    call report(st%status == MPRGP_STOPPED .and. st%n_cg + st%n_exp + st%n_prop == 5 .and. all(x >= l), &
                'stop hook: stops after the step it turned true at (5 steps), iterate feasible', &
                real(st%n_cg + st%n_exp + st%n_prop, wp))
  end subroutine test_stop_hook

  !> A sequence of bound-constrained solves with one operator and right-hand sides that
  !! converge geometrically (as in the outer contact iteration), warm-started from the last
  !! solution and its stored product: with the stored directions of the earlier solves
  !! (opts%recycle) every solve still meets its tolerance on a true gradient; the ring is
  !! deeper than the free set (kr = 48, 35 free variables; a body of at most RECYCLE_DEPTH
  !! contact unknowns keeps them all), so once the active set has settled the stored
  !! directions that vanish on it span the face, the recycled step is the face's minimum and
  !! a solve costs only its confirming product, which recycling guarantees (a ring of 16, the
  !! tail of a 44-step solve, saved nothing there, and the totals differed by rounding: 816
  !! against 834 products, at -O0 840 against 835); the stored images are A times the stored
  !! directions, A-normalised; a warm start that meets the tolerance costs no product;
  !! inconsistent arguments are refused.
  subroutine test_recycle()
    integer, parameter :: n = 60, kr = 48, nsolve = 14
    real(wp) :: a(n, n), b0(n), db(n), b(n), l(n), lmin, lmax, tol
    real(wp) :: x(n, 2), ax(n, 2), g(n), rw(n, kr), raw(n, kr), err, worst_gp
    integer :: nrw(2), i, k, v, nmv(2), nbad, nlate
    type(dense_op_t) :: op
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    call random_spd(n, 3.0_wp, a, lmin, lmax)
    call dense_op_init(op, a)
    do i = 1, n
      b0(i) = urand(-1.0_wp, 1.0_wp)
      db(i) = urand(-1.0_wp, 1.0_wp)
    end do
    l = 0.0_wp
    x = 0.0_wp
    ax = 0.0_wp
    rw = 0.0_wp
    raw = 0.0_wp
    nrw = [0, 1]
    nmv = 0
    nbad = 0
    nlate = 0
    worst_gp = 0.0_wp
    opts%lambda_max = lmax
    opts%use_ax = .true.
    opts%rtol = 0.0_wp
    do k = 1, nsolve
      b = b0 + (-0.4_wp)**k * db
      tol = 1.0e-3_wp * 0.4_wp**k * norm2(b0)
      opts%atol = tol
      do v = 1, 2
        opts%recycle = v == 1
        if (v == 1) then
          call solve_once(op, b, l, x(:, v), opts, st, g, ax(:, v), rw=rw, raw=raw, nrw=nrw)
        else
          call solve_once(op, b, l, x(:, v), opts, st, g, ax(:, v))
        end if
        nmv(v) = nmv(v) + st%n_matvec
        if (v == 1 .and. k > nsolve / 2 .and. st%n_matvec == 1) nlate = nlate + 1
        ! the stopping test on the true gradient A x - b
        g = matmul(a, x(:, v)) - b
        where (x(:, v) <= l) g = min(g, 0.0_wp)
        worst_gp = max(worst_gp, norm2(g) / tol)
        if (st%status /= MPRGP_CONVERGED .or. any(x(:, v) < l)) nbad = nbad + 1
      end do
    end do
    call report(nbad == 0 .and. worst_gp <= 1.0_wp + 1.0e-6_wp, 'recycle: '//i2s(nsolve)// &
                ' solves converged, feasible, true |gP| / tol', worst_gp, 1.0_wp)
    call report(nlate == nsolve - nsolve / 2, 'recycle: the last '//i2s(nsolve - nsolve / 2)//' solves (the '// &
                'active set settled) cost one product each with stored directions, '//i2s(nlate)//' did')
    call report(nmv(1) < nmv(2), 'recycle: products with stored directions ('//i2s(nmv(1))// &
                ') fewer than without ('//i2s(nmv(2))//')', real(nmv(1), wp), real(nmv(2), wp))
    err = 0.0_wp
    do k = 1, nrw(1)
      err = max(err, maxval(abs(matmul(a, rw(:, k)) - raw(:, k))) / (lmax * maxval(abs(rw(:, k)))), &
                abs(dot_product(rw(:, k), raw(:, k)) - 1.0_wp))
    end do
    call report(nrw(1) == kr .and. err <= 1.0e-12_wp, 'recycle: ring full ('//i2s(nrw(1))// &
                '), raw = A rw and rw''A rw = 1 to rounding', err, 1.0e-12_wp)
    ! the same problem again: the warm start meets the tolerance, no product
    call solve_once(op, b, l, x(:, 1), opts, st, g, ax(:, 1), rw=rw, raw=raw, nrw=nrw)
    call report(st%status == MPRGP_CONVERGED .and. st%n_matvec == 0, &
                'recycle: a warm start that meets the tolerance costs no product', real(st%n_matvec, wp), 0.0_wp)
    call solve_once(op, b, l, x(:, 1), opts, st, g, ax(:, 1), rw=rw, nrw=nrw)
    call report(st%status == MPRGP_BAD_ARG, 'recycle: rw without raw refused ('// &
                mprgp_status_name(st%status)//')')
    nrw = [kr + 1, 1]
    call solve_once(op, b, l, x(:, 1), opts, st, g, ax(:, 1), rw=rw, raw=raw, nrw=nrw)
    call report(st%status == MPRGP_BAD_ARG, 'recycle: nrw out of range refused ('// &
                mprgp_status_name(st%status)//')')
  end subroutine test_recycle

  logical function stop_after_five()
    calls = calls + 1
    stop_after_five = calls > 5
  end function stop_after_five

  !> One solver for a sequence of solves of different sizes returns what a fresh solver
  !! returns, bit for bit, with g = A x - b and ax = A x at the returned x (to rounding);
  !! its search direction serves one solve only.
  subroutine test_solver_reuse()
    integer, parameter :: n1 = 30, n2 = 17
    real(wp) :: a1(n1, n1), a2(n2, n2), b1(n1), b2(n2), l1(n1), l2(n2), lmin, lmax
    real(wp) :: x1(n1), x2(n2), y1(n1), y2(n2), err
    type(dense_op_t) :: op1, op2
    type(mprgp_t) :: reused, fresh1, fresh2
    integer :: i
    call random_spd(n1, 2.0_wp, a1, lmin, lmax)
    call random_spd(n2, 2.0_wp, a2, lmin, lmax)
    call dense_op_init(op1, a1)
    call dense_op_init(op2, a2)
    do i = 1, n1
      b1(i) = urand(-1.0_wp, 1.0_wp)
    end do
    do i = 1, n2
      b2(i) = urand(-1.0_wp, 1.0_wp)
    end do
    l1 = 0.0_wp
    l2 = 0.0_wp
    reused%opts%rtol = 1.0e-10_wp
    fresh1%opts = reused%opts
    fresh2%opts = reused%opts
    x1 = 0.0_wp
    y1 = 0.0_wp
    call reused%solve(op1, b1, l1, x1)
    call fresh1%solve(op1, b1, l1, y1)
    err = maxval(abs(reused%g - (matmul(a1, x1) - b1))) + maxval(abs(reused%ax - matmul(a1, x1)))
    call report(reused%stats%status == MPRGP_CONVERGED .and. err <= 1.0e-12_wp*lmax*maxval(abs(x1)), &
                'solver: g = A x - b and ax = A x at the returned x', err)
    x2 = 0.0_wp
    y2 = 0.0_wp
    reused%s = b2
    reused%as = matmul(a2, b2)
    fresh2%s = reused%s
    fresh2%as = reused%as
    call reused%solve(op2, b2, l2, x2)
    call fresh2%solve(op2, b2, l2, y2)
    call report(all(x1 == y1) .and. all(x2 == y2) .and. reused%stats%n_matvec == fresh2%stats%n_matvec .and. &
                reused%stats%n_recycled == fresh2%stats%n_recycled, &
                'solver: a reused solver (sizes 30, 17) returns a fresh one''s iterates bit for bit')
    call report(.not. (allocated(reused%s) .or. allocated(reused%as)), 'solver: a search direction serves one solve')
  end subroutine test_solver_reuse

end program test_mprgp_options
