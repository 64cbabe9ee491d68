!> Unit tests of the active-set Newton method (module qp_newton, run through mprgp_t with
!! opts%method = QP_NEWTON or QP_AUTO) on bound-constrained QPs l <= x <= u:
!!  - small random SPD problems (condition 1 to 1e6, every kind of bound, cold and far warm
!!    starts) against the enumeration of all active sets;
!!  - random SPD problems of 40 to 200 unknowns with condition numbers 1e2 to 1e12 against
!!    the KKT conditions, computed here: x in the box, and the projected gradient within the
!!    rounding level of A x (n eps lambda_max |x|: the work must not depend on the
!!    conditioning, and no tolerance below that level is asked); the objective no larger
!!    than MPRGP's where MPRGP converges;
!!  - QP_AUTO: MPRGP's answer where MPRGP is cheap (no switch, the same iterates), the Newton
!!    method's where it is not (switched, KKT as above, far fewer products);
!!  - QP_NEWTON_FIRST: from a warm start on the solution's face one Newton step ends the solve;
!!    from a cold start its budget runs out and 'auto' finishes from there, to the solution
!!    of the Newton method alone (and an ill-conditioned problem still switches back to the
!!    Newton method rather than running MPRGP to its limit);
!!  - QP_POLISH: MPRGP to a loose tolerance, then the Newton method: the Newton method's
!!    solution at a fraction of MPRGP's work on an ill-conditioned problem; with a budget that
!!    runs out, 'auto' finishes from there, to the same solution;
!!  - SMALBE with an equality row, with the Newton method inside, against the enumeration;
!!  - an indefinite matrix is reported as not SPD, never as converged.
!! One line per check: PASS/FAIL, the measured value and its tolerance. Exit 1 on a failure.
program test_qp_newton
  use kinds, only: wp
  use linop, only: dense_op_t, dense_op_init
  use mprgp, only: mprgp_t, mprgp_opts_t, mprgp_stats_t, mprgp_status_name, MPRGP_CONVERGED, MPRGP_NOT_SPD, &
                   QP_AUTO, QP_MPRGP, QP_NEWTON, QP_NEWTON_FIRST, QP_POLISH
  use smalbe, only: smalbe_solve, smalbe_stats_t
  use qp_newton, only: newton_work_t, chol_delete, chol_append
  use lapack, only: dgesv, dpotrf
  use strings, only: i2s
  use testing, only: report, test_summary, set_seed, urand, random_spd, random_bounds, enumerate_box, box_projected
  implicit none (type, external)

  real(wp), parameter :: eps = epsilon(1.0_wp)

  call set_seed(20261128)
  call test_enumeration()
  call test_conditioning()
  call test_auto()
  call test_newton_first()
  call test_polish()
  call test_kept_factor()
  call test_smalbe()
  call test_indefinite()
  call test_summary()

contains

  !> min 1/2 x'Ax - b'x by a fresh solver with the given options, bounds l <= x <= u.
  subroutine solve(a, b, l, u, x, opts, st)
    real(wp), intent(in) :: a(:, :), b(:), l(:), u(:)
    real(wp), intent(inout) :: x(:)
    type(mprgp_opts_t), intent(in) :: opts
    type(mprgp_stats_t), intent(out) :: st
    type(dense_op_t) :: op
    type(mprgp_t) :: solver
    call dense_op_init(op, a)
    solver%opts = opts
    call solver%solve(op, b, l, x, ub=u)
    st = solver%stats
  end subroutine solve

  !> The unconstrained minimiser A^-1 b (a scale for the bounds).
  function unconstrained(a, b) result(x)
    real(wp), intent(in) :: a(:, :), b(:)
    real(wp) :: x(size(b)), af(size(b), size(b))
    integer :: ipiv(size(b)), info
    af = a
    x = b
    call dgesv(size(b), 1, af, size(b), ipiv, x, size(b), info)
  end function unconstrained

  !> b uniform in [-1, 1] and bounds of every kind (lower, box; module testing's
  !! random_bounds) around the unconstrained minimiser A^-1 b.
  subroutine random_problem(a, b, l, u)
    real(wp), intent(in) :: a(:, :)
    real(wp), intent(out) :: b(:), l(:), u(:)
    real(wp) :: xu(size(b))
    integer :: i
    do i = 1, size(b)
      b(i) = urand(-1.0_wp, 1.0_wp)
    end do
    xu = unconstrained(a, b)
    do i = 1, size(b)
      call random_bounds(merge(1, 3, mod(i, 2) == 0), xu(i), norm2(xu)/sqrt(real(size(b), wp)), l(i), u(i))
    end do
  end subroutine random_problem

  !> |gP| at x over its rounding level n eps lambda_max max(|x|, |x_0|) (+ this product's own).
  real(wp) function kkt_ratio(a, b, l, u, x, x0, lmax) result(r)
    real(wp), intent(in) :: a(:, :), b(:), l(:), u(:), x(:), x0(:), lmax
    real(wp) :: g(size(b)), n
    n = real(size(b), wp)
    g = matmul(a, x) - b
    r = norm2(box_projected(g, x, l, u))/(20.0_wp*n*eps*(lmax*max(norm2(x), norm2(x0)) + norm2(b)))
  end function kkt_ratio

  !> Small problems (n = 1..8, condition 1 to 1e6) against the enumeration of active sets.
  subroutine test_enumeration()
    integer, parameter :: nprob = 400
    real(wp), allocatable :: a(:, :), b(:), l(:), u(:), x(:), xs(:), xu(:), g(:), x0(:)
    real(wp) :: lmin, lmax, err, worst, worst_kkt, mu(0), gm(0, 8), e(0)
    integer :: ip, n, i, nfound, nconv, nsteps
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    logical :: ok
    nfound = 0
    nconv = 0
    nsteps = 0
    worst = 0.0_wp
    worst_kkt = 0.0_wp
    opts%method = QP_NEWTON
    opts%rtol = 0.0_wp
    do ip = 1, nprob
      n = 1 + mod(ip - 1, 8)
      if (allocated(a)) deallocate (a, b, l, u, x, xs, xu, g, x0)
      allocate (a(n, n), b(n), l(n), u(n), x(n), xs(n), xu(n), g(n), x0(n))
      call random_spd(n, urand(0.0_wp, 6.0_wp), a, lmin, lmax)
      do i = 1, n
        b(i) = urand(-1.0_wp, 1.0_wp)
      end do
      xu = unconstrained(a, b)
      do i = 1, n
        call random_bounds(int(urand(0.0_wp, 5.0_wp)), xu(i), norm2(xu)/sqrt(real(n, wp)), l(i), u(i))
      end do
      call enumerate_box(a, b, gm(:, 1:n), e, l, u, xs, mu, g, ok)
      if (.not. ok) cycle
      nfound = nfound + 1
      x = 0.0_wp
      if (mod(ip, 2) == 0) then
        do i = 1, n
          x(i) = urand(-20.0_wp, 20.0_wp)*(maxval(abs(xs)) + 1.0_wp)
        end do
      end if
      x0 = min(max(x, l), u)
      call solve(a, b, l, u, x, opts, st)
      if (st%status == MPRGP_CONVERGED .and. all(x >= l) .and. all(x <= u)) nconv = nconv + 1
      nsteps = max(nsteps, st%n_newton)
      ! the enumeration solves with the same conditioning: compare at its accuracy
      err = maxval(abs(x - xs))/(maxval(abs(xs)) + 1.0e-300_wp)/(1.0e-12_wp*lmax/lmin)
      worst = max(worst, err)
      worst_kkt = max(worst_kkt, kkt_ratio(a, b, l, u, x, x0, lmax))
    end do
    call report(nfound >= nprob*9/10, 'enumeration: the reference found for '//i2s(nfound)//' of '//i2s(nprob)// &
                ' problems', real(nfound, wp))
    call report(nconv == nfound, 'enumeration: converged and feasible in every problem ('//i2s(nconv)//' of '// &
                i2s(nfound)//'; at most '//i2s(nsteps)//' Newton steps)', real(nconv, wp))
    call report(worst <= 1.0_wp, 'enumeration: |x - x_enum| / |x_enum| <= 1e-12 cond(A), every problem', worst, 1.0_wp)
    call report(worst_kkt <= 1.0_wp, 'enumeration: |gP| within 20 n eps (lambda_max |x| + |b|)', worst_kkt, 1.0_wp)
  end subroutine test_enumeration

  !> n = 40..200, condition 1e2 to 1e12, lower bounds, boxes and fixed variables: the KKT
  !! conditions to the rounding level, in a number of steps that does not grow with the
  !! condition number; MPRGP's objective is not lower where MPRGP converges.
  subroutine test_conditioning()
    integer, parameter :: sizes(3) = [40, 100, 200]
    real(wp), allocatable :: a(:, :), b(:), l(:), u(:), x(:), y(:), xu(:), x0(:)
    real(wp) :: lmin, lmax, r, worst(6), fx, fy, fworst
    integer :: ic, is, n, i, steps(6), nmv(6), k, nsteps_max
    type(mprgp_opts_t) :: opts, mopts
    type(mprgp_stats_t) :: st, sm
    logical :: conv
    worst = 0.0_wp
    steps = 0
    nmv = 0
    fworst = -huge(1.0_wp)
    conv = .true.
    opts%method = QP_NEWTON
    opts%rtol = 1.0e-14_wp
    mopts%method = QP_MPRGP
    mopts%rtol = 1.0e-10_wp
    mopts%max_it = 20000
    do ic = 1, 6
      do is = 1, size(sizes)
        n = sizes(is)
        if (allocated(a)) deallocate (a, b, l, u, x, y, xu, x0)
        allocate (a(n, n), b(n), l(n), u(n), x(n), y(n), xu(n), x0(n))
        call random_spd(n, 2.0_wp*ic, a, lmin, lmax)
        do i = 1, n
          b(i) = urand(-1.0_wp, 1.0_wp)
        end do
        xu = unconstrained(a, b)
        do i = 1, n
          k = merge(1, 3, mod(i, 3) /= 0)     ! lower bounds and boxes
          if (mod(i, 17) == 0) k = 4          ! and a few fixed variables
          call random_bounds(k, xu(i), norm2(xu)/sqrt(real(n, wp)), l(i), u(i))
        end do
        x = 0.0_wp
        x0 = min(max(x, l), u)
        call solve(a, b, l, u, x, opts, st)
        conv = conv .and. st%status == MPRGP_CONVERGED .and. all(x >= l) .and. all(x <= u)
        r = kkt_ratio(a, b, l, u, x, x0, lmax)
        worst(ic) = max(worst(ic), r)
        steps(ic) = max(steps(ic), st%n_newton)
        nmv(ic) = max(nmv(ic), st%n_matvec)
        if (ic <= 2) then
          ! where MPRGP converges, its objective is not lower (x is the minimiser)
          y = 0.0_wp
          call solve(a, b, l, u, y, mopts, sm)
          if (sm%status == MPRGP_CONVERGED) then
            fx = 0.5_wp*dot_product(x, matmul(a, x)) - dot_product(b, x)
            fy = 0.5_wp*dot_product(y, matmul(a, y)) - dot_product(b, y)
            fworst = max(fworst, (fx - fy)/(abs(fy) + tiny(1.0_wp))/(100.0_wp*n*eps*lmax/lmin))
          end if
        end if
      end do
    end do
    call report(conv, 'conditioning 1e2..1e12, n = 40..200: converged and feasible every time')
    do ic = 1, 6
      call report(worst(ic) <= 1.0_wp, 'cond 1e'//i2s(2*ic)//': |gP| within 20 n eps (lambda_max |x| + |b|) (at most '// &
                  i2s(steps(ic))//' steps, '//i2s(nmv(ic))//' product equivalents)', worst(ic), 1.0_wp)
    end do
    nsteps_max = maxval(steps)
    call report(nsteps_max <= 4*maxval(steps(1:2)) + 10, 'the steps do not grow with the conditioning: at most '// &
                i2s(maxval(steps(1:2)))//' at 1e2-1e4, '//i2s(nsteps_max)//' at any', real(nsteps_max, wp))
    call report(fworst <= 1.0_wp, 'f(x) <= f(x_MPRGP) + 100 n eps cond |f| where MPRGP converged', fworst, 1.0_wp)
  end subroutine test_conditioning

  !> QP_AUTO: a well-conditioned problem is MPRGP's alone (bitwise the MPRGP solve); an
  !! ill-conditioned one switches and meets the KKT conditions with far fewer products.
  subroutine test_auto()
    integer, parameter :: n = 120
    real(wp) :: a(n, n), b(n), l(n), u(n), x(n), y(n), x0(n), xu(n), lmin, lmax, r
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st, sm
    integer :: i
    call random_spd(n, 1.0_wp, a, lmin, lmax)
    call random_problem(a, b, l, u)
    opts%rtol = 1.0e-10_wp
    opts%method = QP_AUTO
    x = 0.0_wp
    call solve(a, b, l, u, x, opts, st)
    opts%method = QP_MPRGP
    y = 0.0_wp
    call solve(a, b, l, u, y, opts, sm)
    call report(st%status == MPRGP_CONVERGED .and. .not. st%switched .and. all(x == y) .and. &
                st%n_matvec == sm%n_matvec, 'auto, cond 10: MPRGP alone, bitwise its solve ('//i2s(st%n_matvec)// &
                ' products)', real(st%n_matvec, wp))
    call random_spd(n, 10.0_wp, a, lmin, lmax)
    xu = unconstrained(a, b)
    do i = 1, n
      call random_bounds(merge(1, 3, mod(i, 2) == 0), xu(i), norm2(xu)/sqrt(real(n, wp)), l(i), u(i))
    end do
    opts%rtol = 1.0e-12_wp
    opts%method = QP_AUTO
    x = 0.0_wp
    x0 = min(max(x, l), u)
    call solve(a, b, l, u, x, opts, st)
    r = kkt_ratio(a, b, l, u, x, x0, lmax)
    call report(st%status == MPRGP_CONVERGED .and. st%switched .and. r <= 1.0_wp, 'auto, cond 1e10: switched to '// &
                'the Newton method after its budget, KKT to the rounding level ('//i2s(st%n_matvec)//' products, '// &
                i2s(st%n_newton)//' Newton steps; '//trim(mprgp_status_name(st%status))//')', r, 1.0_wp)
    opts%method = QP_MPRGP
    opts%max_it = 5*st%n_matvec
    y = 0.0_wp
    call solve(a, b, l, u, y, opts, sm)
    call report(sm%status /= MPRGP_CONVERGED, 'auto, cond 1e10: MPRGP alone does not converge in five times '// &
                'that work ('//trim(mprgp_status_name(sm%status))//')')
  end subroutine test_auto

  !> QP_NEWTON_FIRST: one step from the solution's face; from a cold start with a budget of
  !! one step, the fall back to 'auto' reaches the Newton method's own solution, also on an
  !! ill-conditioned problem (MPRGP's budget there, then the Newton method again).
  subroutine test_newton_first()
    integer, parameter :: n = 150
    real(wp) :: a(n, n), b(n), l(n), u(n), x(n), y(n), z(n), x0(n), lmin, lmax, r, cond
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st, sn
    integer :: i, k
    do k = 1, 2
      cond = merge(1.0e2_wp, 1.0e10_wp, k == 1)
      call random_spd(n, log10(cond), a, lmin, lmax)
      call random_problem(a, b, l, u)
      opts = mprgp_opts_t()
      opts%rtol = 1.0e-12_wp
      opts%method = QP_NEWTON
      y = 0.0_wp
      call solve(a, b, l, u, y, opts, sn)
      ! cold: the budget of one step runs out, 'auto' finishes
      opts%method = QP_NEWTON_FIRST
      opts%newton_budget = 1
      x = 0.0_wp
      x0 = min(max(x, l), u)
      call solve(a, b, l, u, x, opts, st)
      r = kkt_ratio(a, b, l, u, x, x0, lmax)
      call report(st%status == MPRGP_CONVERGED .and. st%fell_back .and. r <= 1.0_wp .and. &
                  (k == 1 .or. st%switched), 'Newton first, cond '//trim(i2s(nint(log10(cond))))//' decades, cold '// &
                  'start, budget 1: fell back to auto'//trim(merge(' and switched back', '                  ', k == 2))// &
                  ', KKT to the rounding level ('//i2s(st%n_matvec)//' products)', r, 1.0_wp)
      call report(maxval(abs(x - y)) <= 1.0e3_wp*cond*eps*maxval(abs(y)), '  ... the Newton method''s solution: '// &
                  'max |x - x_Newton| / max |x_Newton| within 1e3 cond eps', &
                  maxval(abs(x - y))/maxval(abs(y)), 1.0e3_wp*cond*eps)
      ! warm: from the solution's face (the Newton solution nudged inside its face), one step
      z = y
      do i = 1, n
        if (z(i) > l(i) .and. z(i) < u(i)) z(i) = z(i) + 1.0e-3_wp*urand(-1.0_wp, 1.0_wp)*abs(z(i))
      end do
      z = min(max(z, l), u)
      opts%newton_budget = 4
      x0 = z
      call solve(a, b, l, u, z, opts, st)
      r = kkt_ratio(a, b, l, u, z, x0, lmax)
      ! (cond 1e10: a tolerance below the rounding level takes the two confirming steps of
      ! module mprgp's newton_loop, once more after the fresh gradient)
      call report(st%status == MPRGP_CONVERGED .and. .not. st%fell_back .and. st%n_newton <= merge(2, 4, k == 1) &
                  .and. r <= 1.0_wp, 'Newton first, cond '//trim(i2s(nint(log10(cond))))//' decades, warm start on '// &
                  'the solution''s face: '//i2s(st%n_newton)//' Newton step(s) (at most '//i2s(merge(2, 4, k == 1))// &
                  '), KKT to the rounding level', r, 1.0_wp)
    end do
  end subroutine test_newton_first

  !> QP_POLISH on 150 unknowns at condition 1e6, rtol 1e-12: MPRGP to 1e-4 (polish_scale 1e8)
  !! and the Newton method from there reach the Newton method's own solution, in fewer products
  !! than MPRGP alone (its MPRGP phase unbounded); MPRGP stopped at once (polish_scale 1e12)
  !! with a budget of one Newton step falls back to 'auto' and still ends at that solution.
  subroutine test_polish()
    integer, parameter :: n = 150
    real(wp) :: a(n, n), b(n), l(n), u(n), x(n), y(n), z(n), x0(n), lmin, lmax, r, cond
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st, sn, sm
    cond = 1.0e6_wp
    call random_spd(n, log10(cond), a, lmin, lmax)
    call random_problem(a, b, l, u)
    opts = mprgp_opts_t()
    opts%rtol = 1.0e-12_wp
    opts%max_it = 100000
    opts%method = QP_NEWTON
    y = 0.0_wp
    call solve(a, b, l, u, y, opts, sn)
    ! MPRGP alone, within 20,000 steps (it needs more)
    opts%method = QP_MPRGP
    opts%max_it = 20000
    z = 0.0_wp
    call solve(a, b, l, u, z, opts, sm)
    opts%max_it = 100000
    opts%method = QP_POLISH
    opts%polish_scale = 1.0e8_wp
    opts%newton_budget = 20
    opts%auto_budget = 100000      ! MPRGP's phase to its loose tolerance, whatever it takes
    x = 0.0_wp
    x0 = min(max(x, l), u)
    call solve(a, b, l, u, x, opts, st)
    r = kkt_ratio(a, b, l, u, x, x0, lmax)
    call report(st%status == MPRGP_CONVERGED .and. .not. st%fell_back .and. st%n_newton >= 1 .and. r <= 1.0_wp, &
                'polish, cond 1e6: MPRGP to 1e-4, then '//i2s(st%n_newton)//' Newton step(s), KKT to the rounding '// &
                'level', r, 1.0_wp)
    call report(maxval(abs(x - y)) <= 1.0e3_wp*cond*eps*maxval(abs(y)), '  ... the Newton method''s solution: '// &
                'max |x - x_Newton| / max |x_Newton| within 1e3 cond eps', maxval(abs(x - y))/maxval(abs(y)), &
                1.0e3_wp*cond*eps)
    call report(10*st%n_matvec < sm%n_matvec, '  ... in '//i2s(st%n_matvec)//' products, under a tenth of '// &
                'MPRGP alone: '//i2s(sm%n_matvec)//' ('//mprgp_status_name(sm%status)//')')
    opts%polish_scale = 1.0e12_wp
    opts%newton_budget = 1
    opts%auto_budget = 0
    x = 0.0_wp
    call solve(a, b, l, u, x, opts, st)
    r = kkt_ratio(a, b, l, u, x, x0, lmax)
    call report(st%status == MPRGP_CONVERGED .and. st%fell_back .and. r <= 1.0_wp .and. &
                maxval(abs(x - y)) <= 1.0e3_wp*cond*eps*maxval(abs(y)), 'polish, budget 1 from MPRGP''s first '// &
                'iterates: fell back to auto, the Newton method''s solution, KKT to the rounding level', r, 1.0_wp)
  end subroutine test_polish

  !> Newton work kept between solves (mprgp_t%keep): a solve from the solution's face makes
  !! one factorization (the face's), and the next solve from there takes it as it is (no
  !! factorization) to the bits of a solve with fresh work; told that A changed, it factors
  !! again. A factor that was updated is not carried into the next solve.
  subroutine test_kept_factor()
    integer, parameter :: n = 80
    real(wp) :: a(n, n), b(n), l(n), u(n), x(n), y(n), z(n), w(n), lmin, lmax
    type(dense_op_t) :: op
    type(mprgp_t) :: s1, s2, s3
    type(newton_work_t), target :: kept
    integer :: i, nf2
    call random_spd(n, 4.0_wp, a, lmin, lmax)
    call random_problem(a, b, l, u)
    call dense_op_init(op, a)
    s1%opts%rtol = 1.0e-12_wp
    s1%opts%method = QP_NEWTON
    s1%keep => kept
    x = 0.0_wp
    call s1%solve(op, b, l, x, ub=u)
    call report(s1%stats%status == MPRGP_CONVERGED .and. s1%stats%n_factor >= 1 .and. &
                s1%stats%n_factor < s1%stats%n_newton, 'kept work, cold start: converged, '// &
                i2s(s1%stats%n_factor)//' factorization(s) in '//i2s(s1%stats%n_newton)//' steps (the others updated)')
    ! the solution nudged inside its face: twice with the kept work, once with fresh work
    do i = 1, n
      w(i) = x(i)
      if (x(i) > l(i) .and. x(i) < u(i)) w(i) = x(i) + 1.0e-3_wp*urand(-1.0_wp, 1.0_wp)*abs(x(i))
    end do
    w = min(max(w, l), u)
    s2%opts = s1%opts
    s2%keep => kept
    s2%keep_same_a = .true.
    y = w
    call s2%solve(op, b, l, y, ub=u)
    nf2 = s2%stats%n_factor
    y = w
    call s2%solve(op, b, l, y, ub=u)
    s3%opts = s1%opts
    z = w
    call s3%solve(op, b, l, z, ub=u)
    call report(s2%stats%status == MPRGP_CONVERGED .and. nf2 <= 1 .and. s2%stats%n_factor == 0 .and. &
                s3%stats%n_factor >= 1, 'warm start on the solution''s face: '//i2s(nf2)//' factorization, '// &
                'then the kept factor taken ('//i2s(s2%stats%n_factor)//'; fresh work '//i2s(s3%stats%n_factor)//')')
    call report(all(y == z), 'the kept factor gives the bits of a fresh one')
    ! told that A changed: a new factor
    s2%keep_same_a = .false.
    y = w
    call s2%solve(op, b, l, y, ub=u)
    call report(s2%stats%n_factor >= 1 .and. all(y == z), 'keep_same_a = .false.: factored again ('// &
                i2s(s2%stats%n_factor)//'), the same bits')
    call test_updated_factor()
  end subroutine test_kept_factor

  !> Updated factors. chol_delete and chol_append against dpotrf of the reduced and the
  !! bordered matrix (to 1e-12 relative, a random SPD matrix of condition 1e3); then solves
  !! whose steps update the factor of the step before (fewer factorizations than steps):
  !! a cold one, and one whose right-hand side moved (what the Robin iteration does) from
  !! the last solution; both at the rounding level of the KKT conditions (a wrong update gives
  !! a wrong direction, a step that misses its face's minimiser and, in the end, a stall).
  subroutine test_updated_factor()
    integer, parameter :: n = 240, p = 40
    real(wp) :: a(n, n), b(n), l(n), u(n), x(n), x0(n), lmin, lmax, r
    real(wp) :: h(p, p), ref(p, p), piv, e1, e2
    type(dense_op_t) :: op
    type(mprgp_t) :: s1
    integer :: i, j, k, info, idx(p)
    ! the update routines alone
    call random_spd(n, 3.0_wp, a, lmin, lmax)
    k = 17
    h = a(1:p, 1:p)
    call dpotrf('L', p, h, p, info)
    call chol_delete(h, p, k)
    idx(1:p - 1) = [(i, i=1, k - 1), (i, i=k + 1, p)]
    ref(1:p - 1, 1:p - 1) = a(idx(1:p - 1), idx(1:p - 1))
    call dpotrf('L', p - 1, ref, p, info)
    e1 = 0.0_wp
    do j = 1, p - 1
      e1 = max(e1, maxval(abs(h(j:p - 1, j) - ref(j:p - 1, j))))
    end do
    e1 = e1/maxval(abs(ref(1:p - 1, 1:p - 1)))
    idx(p) = p + 5
    call chol_append(a, idx(1:p - 1), idx(p), h, piv)
    ref = a(idx, idx)
    call dpotrf('L', p, ref, p, info)
    e2 = 0.0_wp
    do j = 1, p
      e2 = max(e2, maxval(abs(h(j:p, j) - ref(j:p, j))))
    end do
    e2 = e2/maxval(abs(ref))
    call report(info == 0 .and. e1 <= 1.0e-12_wp .and. piv > 0.0_wp .and. e2 <= 1.0e-12_wp, &
                'chol_delete (row 17 of 40) and chol_append: the factors of the reduced and bordered matrix', &
                max(e1, e2), 1.0e-12_wp)
    ! solves
    call random_problem(a, b, l, u)
    call dense_op_init(op, a)
    s1%opts%rtol = 1.0e-12_wp
    s1%opts%method = QP_NEWTON
    x = 0.0_wp
    x0 = x
    call s1%solve(op, b, l, x, ub=u)
    r = kkt_ratio(a, b, l, u, x, x0, lmax)
    call report(s1%stats%status == MPRGP_CONVERGED .and. s1%stats%n_factor < s1%stats%n_newton .and. r <= 1.0_wp, &
                'updated factors, cold start: converged with '//i2s(s1%stats%n_factor)//' factorizations in '// &
                i2s(s1%stats%n_newton)//' steps, KKT to the rounding level', r, 1.0_wp)
    do i = 1, n
      b(i) = b(i) + 1.0e-2_wp*urand(-1.0_wp, 1.0_wp)*maxval(abs(b))
    end do
    x0 = x
    call s1%solve(op, b, l, x, ub=u)
    r = kkt_ratio(a, b, l, u, x, x0, lmax)
    call report(s1%stats%status == MPRGP_CONVERGED .and. s1%stats%n_factor < s1%stats%n_newton .and. r <= 1.0_wp, &
                'updated factors, the right-hand side moved: converged with '//i2s(s1%stats%n_factor)// &
                ' factorization(s) in '//i2s(s1%stats%n_newton)//' steps, KKT to the rounding level', r, 1.0_wp)
  end subroutine test_updated_factor

  !> SMALBE (an equality row) with the Newton method inside, against the enumeration.
  subroutine test_smalbe()
    integer, parameter :: n = 7
    real(wp) :: h(n, n), c(n), l(n), u(n), x(n), xs(n), g(n), gm(1, n), e(1), mu(1), mus(1), lmin, lmax, rho, err
    real(wp), allocatable :: aug(:, :)
    type(dense_op_t) :: op
    type(mprgp_t) :: solver
    type(smalbe_stats_t) :: st
    logical :: ok
    integer :: i
    call random_spd(n, 5.0_wp, h, lmin, lmax)
    do i = 1, n
      c(i) = urand(-1.0_wp, 1.0_wp)
      gm(1, i) = urand(0.5_wp, 1.0_wp)
      l(i) = 0.0_wp
      u(i) = merge(huge(1.0_wp), 0.3_wp, mod(i, 2) == 0)
    end do
    e = 0.5_wp
    call enumerate_box(h, c, gm, e, l, u, xs, mus, g, ok)
    rho = lmax
    aug = h + rho*matmul(transpose(gm), gm)
    call dense_op_init(op, aug)
    solver%opts%method = QP_NEWTON
    solver%opts%rtol = 1.0e-12_wp
    solver%opts%lambda_max = maxval(sum(abs(aug), dim=1))
    solver%opts%eq_m = 100.0_wp*lmax
    solver%opts%eq_feas = 1.0e-11_wp
    x = 0.0_wp
    mu = 0.0_wp
    call smalbe_solve(solver, op, c, gm, e, rho, l, x, mu, st, ub=u)
    err = maxval(abs(x - xs))/maxval(abs(xs))
    call report(ok .and. st%inner%status == MPRGP_CONVERGED .and. err <= 1.0e-6_wp, 'SMALBE with the Newton '// &
                'method, cond 1e5, an equality row and boxes: x = the enumeration''s ('//i2s(st%updates)// &
                ' multiplier updates, '//i2s(st%n_matvec)//' products)', err, 1.0e-6_wp)
  end subroutine test_smalbe

  !> An indefinite A: not SPD, never converged.
  subroutine test_indefinite()
    integer, parameter :: n = 6
    real(wp) :: a(n, n), b(n), l(n), u(n), x(n)
    type(mprgp_opts_t) :: opts
    type(mprgp_stats_t) :: st
    integer :: i
    a = 0.0_wp
    do i = 1, n
      a(i, i) = 1.0_wp
    end do
    a(1, 2) = 3.0_wp
    a(2, 1) = 3.0_wp
    b = 1.0_wp
    l = -10.0_wp
    u = 10.0_wp
    x = 0.0_wp
    opts%method = QP_NEWTON
    call solve(a, b, l, u, x, opts, st)
    call report(st%status == MPRGP_NOT_SPD, 'an indefinite A (eigenvalue -2) is reported not SPD ('// &
                trim(mprgp_status_name(st%status))//': '//trim(st%message)//')')
  end subroutine test_indefinite

end program test_qp_newton
