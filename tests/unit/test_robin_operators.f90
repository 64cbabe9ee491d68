!> Unit tests of the Robin operators (module robin_operators) and of the bodies' subproblems
!! (module robin_subproblems), on small dense problems built here (flexibilities F_a = Q D Q'
!! of chosen spectra, contact rows and side layouts written out by hand), each against the
!! formula of doc/method.md written out in the test and evaluated by LAPACK inverses:
!!  - the factory: each ROBIN_* code gives its operator's type;
!!  - 'constant': corr_1 = corr_2 = alpha d / M (tributary lengths), no product counted;
!!  - 'steklov': two bodies corr_1 = F_2 d, corr_2 = F_1 d; three bodies in a stack, each
!!    body's F_b on its own imbalance (+d on its side-1 rows, -d on its side-2 rows) moves
!!    its partners' obstacles by -y_b; a floating body applies P F P, P = I - G'(GG')^-1 G;
!!  - 'harmonic', two bodies: S = 2 (F_1^-1 + F_2^-1)^-1 (contrast 1 and 1e6), from the
!!    factors until outer iteration max(8, m/16) + 1, formed from then on; S symmetric
!!    positive definite, S <= 2 F_a (Loewner order), S F_1^-1 + S F_2^-1 = 2 I; with friction
!!    S block diagonal by row kind; a floating body: S = 2 (F_o^-1 + Q_f)^-1 with the
!!    projected inverse Q_f; three bodies in a stack: S = 2 K^-1, K = sum E'D Sigma D E;
!!    F_1 + F_2 not positive definite refused (ERR_NUMERICAL);
!!  - the fixed point the method relies on: the outer iteration of doc/method.md written out
!!    here with every row active (each subproblem solved exactly by LAPACK) converges at
!!    delta = 0.5 under 'harmonic' in two updates to the monolithic solution (two bodies at
!!    contrast 1e4, three bodies), and under 'steklov' to the same solution (relaxed);
!!  - the inner tolerances (progress_rtol's clamp, the harmonic contrast rule), the bounds
!!    of lambda_max (the row-sum norm, 10 power iterations: below lambda_max from dsyev);
!!  - the proximal term of a singular F_a: the partners' F on its rows (pair by pair), and
!!    the harmonic Z (Z'F_o Z + floor I) Z' from a kernel basis or from a range basis
!!    (range_proximal), F_a + Pi_a then definite;
!!  - the subproblems: the Hessians F_a + Pi_a and a bound of their lambda_max; one outer
!!    iteration's solves against the minimiser of each body's QP found by active-set
!!    enumeration (testing's enumerate_box), B_a u_a = b_a - F_a lam_a.
!! One line per check: PASS/FAIL. Exits with status 1 if any check failed.
program test_robin_operators
  use kinds, only: wp
  use space, only: set_dimension
  use config, only: solver_cfg_t, ROBIN_STEKLOV, ROBIN_CONSTANT, ROBIN_HARMONIC, FRICTION_NONE
  use linop, only: dense_op_t, dense_op_init
  use lapack, only: dgesv, dsyev
  use contact_interface, only: interface_t, body_slots, slot_row
  use condense, only: body_condensed_t
  use contact_types, only: robin_state_t, contact_result_t, state_init, alloc_result
  use robin_operators, only: robin_operator_t, steklov_operator_t, constant_operator_t, harmonic_operator_t, &
                             new_robin_operator, progress_rtol, range_proximal
  use robin_subproblems, only: subproblems_t, subproblems_init, solve_subproblems
  use errors, only: error_t, ERR_NUMERICAL
  use testing, only: report, report_le, test_summary, set_seed, urand, spd_from_eigs, identity, enumerate_box
  implicit none (type, external)

  real(wp), parameter :: eps = epsilon(1.0_wp)

  call set_dimension(2)
  call set_seed(20261129)
  call test_factory()
  call test_constant()
  call test_steklov()
  call test_harmonic_two()
  call test_harmonic_kinds()
  call test_harmonic_floating()
  call test_three_bodies()
  call test_fixed_point_two()
  call test_not_definite()
  call test_tolerances()
  call test_lambda_max()
  call test_proximal()
  call test_subproblems()
  call test_summary()

contains

  ! ---- scenes ---------------------------------------------------------------------------

  !> One pair of two bodies on m frictionless rows (dir: the rows' directions, default all
  !! normal): body 1 side 1, body 2 side 2; tributary lengths 0.1, 0.2, ...; gap g0.
  subroutine pair_interface(m, itf, dir)
    integer, intent(in) :: m
    type(interface_t), intent(out) :: itf
    integer, intent(in), optional :: dir(:)
    integer :: k
    itf%m = m
    itf%npair = 1
    itf%pair_ptr = [1, m + 1]
    itf%pair_body = reshape([1, 2], [2, 1])
    itf%pair_slave = [1]
    itf%pair_friction = [FRICTION_NONE]
    itf%pair_mu = [0.0_wp]
    itf%pair_slip = [0.0_wp]
    itf%pair_of = [(1, k=1, m)]
    itf%nrow = [(k, k=1, m)]
    itf%dir = [(0, k=1, m)]
    if (present(dir)) itf%dir = dir
    itf%trib = [(0.1_wp*k, k=1, m)]
    itf%g0 = [(1.0e-3_wp*(-1.0_wp)**k, k=1, m)]
  end subroutine pair_interface

  !> A stack of three bodies: pair 1 (rows 1..3) body 1 on side 1 over body 2 on side 2,
  !! pair 2 (rows 4..6) body 2 on side 1 over body 3 on side 2.
  subroutine stack_interface(itf)
    type(interface_t), intent(out) :: itf
    integer :: k
    itf%m = 6
    itf%npair = 2
    itf%pair_ptr = [1, 4, 7]
    itf%pair_body = reshape([1, 2, 2, 3], [2, 2])
    itf%pair_slave = [1, 1]
    itf%pair_friction = [FRICTION_NONE, FRICTION_NONE]
    itf%pair_mu = [0.0_wp, 0.0_wp]
    itf%pair_slip = [0.0_wp, 0.0_wp]
    itf%pair_of = [1, 1, 1, 2, 2, 2]
    itf%nrow = [(k, k=1, 6)]
    itf%dir = [(0, k=1, 6)]
    itf%trib = [(0.1_wp*k, k=1, 6)]
    itf%g0 = [(2.0e-3_wp*(-1.0_wp)**k, k=1, 6)]
  end subroutine stack_interface

  !> Body a of interface itf condensed to the flexibility f (supported: nrig = 0, no
  !! equilibrium rows, rank m).
  subroutine condensed(itf, a, f, cbody)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: a
    real(wp), intent(in) :: f(:, :)
    type(body_condensed_t), intent(out) :: cbody
    cbody%slots = body_slots(itf, a)
    cbody%m = size(cbody%slots)
    cbody%flex = f
    cbody%rank = cbody%m
    cbody%nrig = 0
    allocate (cbody%rg(0, cbody%m), cbody%re(0))   ! as floating's rigid_rows leaves a supported body
    allocate (cbody%b(cbody%m))
    cbody%b = 0.0_wp
  end subroutine condensed

  !> The operators of the bodies' flexibilities (what the subproblems hand the Robin operator).
  subroutine flex_ops(bodies, ops)
    type(body_condensed_t), intent(in) :: bodies(:)
    type(dense_op_t), allocatable, intent(out) :: ops(:)
    integer :: a
    allocate (ops(size(bodies)))
    do a = 1, size(bodies)
      call dense_op_init(ops(a), bodies(a)%flex)
    end do
  end subroutine flex_ops

  !> A random symmetric positive definite m x m matrix scale Q diag(d) Q', d log-uniform in
  !! [1, 10**cexp].
  function random_flex(m, cexp, scale) result(f)
    integer, intent(in) :: m
    real(wp), intent(in) :: cexp, scale
    real(wp) :: f(m, m), d(m)
    integer :: i
    do i = 1, m
      d(i) = 10.0_wp**(cexp*urand(0.0_wp, 1.0_wp))
    end do
    call spd_from_eigs(m, d, f)
    f = scale*f
  end function random_flex

  ! ---- dense linear algebra of the references (LAPACK, not the code under test) ------------

  !> A^-1 by LU (dgesv on the identity).
  function inv(a) result(x)
    real(wp), intent(in) :: a(:, :)
    real(wp) :: x(size(a, 1), size(a, 1)), c(size(a, 1), size(a, 1))
    integer :: ipiv(size(a, 1)), info, n
    n = size(a, 1)
    c = a
    x = identity(n)
    call dgesv(n, n, c, n, ipiv, x, n, info)
    if (info /= 0) error stop 'inv: singular matrix'
  end function inv

  !> The eigenvalues of the symmetric part of a, ascending.
  function eigs(a) result(w)
    real(wp), intent(in) :: a(:, :)
    real(wp) :: w(size(a, 1)), c(size(a, 1), size(a, 1)), work(64*size(a, 1) + 64)
    integer :: info, n
    n = size(a, 1)
    c = 0.5_wp*(a + transpose(a))
    call dsyev('N', 'U', n, c, n, w, work, size(work), info)
    if (info /= 0) error stop 'eigs: dsyev failed'
  end function eigs

  !> max |a - b| / max |b|.
  real(wp) function relerr(a, b)
    real(wp), intent(in) :: a(:, :), b(:, :)
    relerr = maxval(abs(a - b))/max(maxval(abs(b)), tiny(1.0_wp))
  end function relerr

  !> The m x m matrix of an operator's side-s correction: column j is corr(:, s) for d = e_j;
  !! both sides' matrices, and the products counted for the m applications.
  subroutine operator_matrix(op, m, it, s1, s2, count)
    class(robin_operator_t), intent(inout) :: op
    integer, intent(in) :: m, it
    real(wp), intent(out) :: s1(m, m), s2(m, m)
    integer, intent(out) :: count
    real(wp) :: corr(m, 2), d(m)
    integer :: j
    count = 0
    do j = 1, m
      d = 0.0_wp
      d(j) = 1.0_wp
      call op%apply(d, corr, count, it)
      s1(:, j) = corr(:, 1)
      s2(:, j) = corr(:, 2)
    end do
  end subroutine operator_matrix

  ! ---- the factory ------------------------------------------------------------------------

  subroutine test_factory()
    class(robin_operator_t), allocatable :: op
    logical :: ok(3)
    op = new_robin_operator(ROBIN_STEKLOV)
    select type (op)
    type is (steklov_operator_t)
      ok(1) = .true.
    class default
      ok(1) = .false.
    end select
    deallocate (op)
    op = new_robin_operator(ROBIN_CONSTANT)
    select type (op)
    type is (constant_operator_t)
      ok(2) = .true.
    class default
      ok(2) = .false.
    end select
    deallocate (op)
    op = new_robin_operator(ROBIN_HARMONIC)
    select type (op)
    type is (harmonic_operator_t)
      ok(3) = .true.
    class default
      ok(3) = .false.
    end select
    call report(all(ok), 'new_robin_operator: steklov, constant, harmonic give their types')
  end subroutine test_factory

  ! ---- 'constant' -------------------------------------------------------------------------

  subroutine test_constant()
    type(interface_t) :: itf
    type(body_condensed_t) :: bodies(2)
    type(dense_op_t), allocatable :: ops(:)
    type(constant_operator_t) :: op
    type(solver_cfg_t) :: solver
    type(error_t) :: err
    real(wp) :: d(5), corr(5, 2), want(5)
    integer :: count, i
    call pair_interface(5, itf)
    call condensed(itf, 1, random_flex(5, 1.0_wp, 1.0_wp), bodies(1))
    call condensed(itf, 2, random_flex(5, 1.0_wp, 1.0_wp), bodies(2))
    call flex_ops(bodies, ops)
    solver%alpha = 2.5e-3_wp
    call op%setup(solver, itf, bodies, ops, err)
    d = [1.0_wp, -2.0_wp, 0.5_wp, 3.0_wp, -0.25_wp]
    want = [(2.5e-3_wp*d(i)/(0.1_wp*i), i=1, 5)]
    count = 7
    call op%apply(d, corr, count, 1)
    call report(.not. err%failed() .and. maxval(abs(corr(:, 1) - want)/abs(want)) <= 2.0_wp*eps .and. &
                all(corr(:, 2) == corr(:, 1)), 'constant: corr_1 = corr_2 = alpha d / M (tributary lengths)')
    call report(count == 7, 'constant: no Hessian-sized product counted')
  end subroutine test_constant

  ! ---- 'steklov' --------------------------------------------------------------------------

  subroutine test_steklov()
    type(interface_t) :: itf
    type(body_condensed_t) :: bodies(2), stack(3)
    type(dense_op_t), allocatable :: ops(:)
    type(steklov_operator_t) :: op, op3, opf
    type(solver_cfg_t) :: solver
    type(error_t) :: err
    real(wp) :: f1(6, 6), f2(6, 6), s1(6, 6), s2(6, 6), g(1, 6), p(6, 6), d(6), corr(6, 2), want(6, 2), y(6)
    real(wp) :: f(6, 6, 3)
    integer :: count, k, b, sl
    ! two bodies
    call pair_interface(6, itf)
    f1 = random_flex(6, 2.0_wp, 1.0e-9_wp)
    f2 = random_flex(6, 2.0_wp, 3.0e-9_wp)
    call condensed(itf, 1, f1, bodies(1))
    call condensed(itf, 2, f2, bodies(2))
    call flex_ops(bodies, ops)
    call op%setup(solver, itf, bodies, ops, err)
    call operator_matrix(op, 6, 1, s1, s2, count)
    call report_le(max(relerr(s1, f2), relerr(s2, f1)), 8.0_wp*eps, 'steklov, two bodies: corr_1 = F_2 d, corr_2 = F_1 d')
    call report(count == 12, 'steklov: one product per body and application')

    ! a floating body 2 (one equilibrium row G): its product on self-equilibrated forces only,
    ! P F_2 P with P = I - G'(GG')^-1 G
    g(1, :) = [1.0_wp, 1.0_wp, 1.0_wp, 0.5_wp, 0.5_wp, 2.0_wp]
    bodies(2)%nrig = 1
    bodies(2)%rg = g
    call opf%setup(solver, itf, bodies, ops, err)
    call operator_matrix(opf, 6, 1, s1, s2, count)
    p = identity(6) - matmul(transpose(g), g)/sum(g**2)
    call report_le(max(relerr(s1, matmul(p, matmul(f2, p))), relerr(s2, f1)), 16.0_wp*eps, &
                   'steklov, floating body 2: corr_1 = P F_2 P d (P = I - G''(GG'')^-1 G), corr_2 = F_1 d')

    ! three bodies: body b's y_b = F_b d_b, d_b = +d on its side-1 rows and -d on its side-2 rows,
    ! moves each partner's obstacle by -y_b (doc/method.md, "steklov for N bodies")
    call stack_interface(itf)
    f(1:3, 1:3, 1) = random_flex(3, 1.0_wp, 1.0_wp)
    f(:, :, 2) = random_flex(6, 1.0_wp, 2.0_wp)
    f(1:3, 1:3, 3) = random_flex(3, 1.0_wp, 0.5_wp)
    call condensed(itf, 1, f(1:3, 1:3, 1), stack(1))
    call condensed(itf, 2, f(:, :, 2), stack(2))
    call condensed(itf, 3, f(1:3, 1:3, 3), stack(3))
    call flex_ops(stack, ops)
    call op3%setup(solver, itf, stack, ops, err)
    d = [1.0_wp, -0.5_wp, 2.0_wp, 0.25_wp, -1.5_wp, 0.75_wp]
    want = 0.0_wp
    do b = 1, 3
      associate (sl_b => stack(b)%slots, m_b => stack(b)%m)
        y(1:m_b) = matmul(f(1:m_b, 1:m_b, b), [(merge(d(slot_row(sl_b(k), 6)), -d(slot_row(sl_b(k), 6)), sl_b(k) <= 6), &
                                                 k=1, m_b)])
        do k = 1, m_b
          sl = sl_b(k)
          if (sl > 6) then
            want(sl - 6, 1) = -y(k)     ! body b on side 2: the side-1 partner's obstacle
          else
            want(sl, 2) = y(k)          ! body b on side 1: the side-2 partner's, corrected by -corr_2
          end if
        end do
      end associate
    end do
    count = 0
    call op3%apply(d, corr, count, 1)
    call report_le(relerr(corr, want), 8.0_wp*eps, 'steklov, three bodies: each body''s F on its own imbalance '// &
                   'corrects its partners'' obstacles')
  end subroutine test_steklov

  ! ---- 'harmonic', two bodies ---------------------------------------------------------------

  subroutine test_harmonic_two()
    real(wp) :: c
    integer :: k
    do k = 1, 2
      c = merge(1.0_wp, 1.0e-6_wp, k == 1)
      call harmonic_pair(c)
    end do
  end subroutine test_harmonic_two

  !> Two bodies of 7 rows, F_2 about c times F_1: S against 2 (F_1^-1 + F_2^-1)^-1.
  subroutine harmonic_pair(c)
    real(wp), intent(in) :: c                     !< contrast: F_2 / F_1 about c
    integer, parameter :: m = 7
    type(interface_t) :: itf
    type(body_condensed_t) :: bodies(2)
    type(dense_op_t), allocatable :: ops(:)
    type(harmonic_operator_t) :: op
    type(solver_cfg_t) :: solver
    type(error_t) :: err
    real(wp) :: f1(m, m), f2(m, m), s1(m, m), s2(m, m), sref(m, m), sf(m, m), sf2(m, m), tol, kappa
    integer :: count, form_at
    character(len=32) :: tag
    write (tag, '(a,es8.1,a)') ' (contrast ', 1.0_wp/c, ')'
    call pair_interface(m, itf)
    f1 = random_flex(m, 2.0_wp, 1.0e-9_wp)
    f2 = random_flex(m, 2.0_wp, c*1.0e-9_wp)
    call condensed(itf, 1, f1, bodies(1))
    call condensed(itf, 2, f2, bodies(2))
    call flex_ops(bodies, ops)
    call op%setup(solver, itf, bodies, ops, err)
    call report(.not. err%failed(), 'harmonic: set up'//trim(tag))
    sref = 2.0_wp*inv(inv(f1) + inv(f2))
    kappa = 1.0e2_wp
    tol = 10.0_wp*m*kappa*eps
    ! from its factors first
    call operator_matrix(op, m, 1, s1, s2, count)
    call report_le(relerr(s1, sref), tol, 'harmonic: S = 2 (F_1^-1 + F_2^-1)^-1 applied from its factors'//trim(tag))
    call report(all(s1 == s2), 'harmonic: corr_1 = corr_2 (the same S on both sides)')
    call report_le(relerr(s1, transpose(s1)), tol, 'harmonic: S symmetric'//trim(tag))
    call report(minval(eigs(s1)) > 0.0_wp .and. minval(eigs(2.0_wp*f1 - s1)) >= -tol*maxval(abs(f1)) .and. &
                minval(eigs(2.0_wp*f2 - s1)) >= -tol*maxval(abs(f2)), &
                'harmonic: S positive definite, S <= 2 F_1 and S <= 2 F_2'//trim(tag))
    call report_le(maxval(abs(matmul(s1, inv(f1)) + matmul(s1, inv(f2)) - 2.0_wp*identity(m))), 10.0_wp*tol, &
                   'harmonic: S F_1^-1 + S F_2^-1 = 2 I (the nilpotent error map)'//trim(tag))
    ! formed at outer iteration max(8, m/16) + 1, not before
    form_at = max(8, itf%m/16) + 1
    call operator_matrix(op, m, form_at - 1, sf, sf2, count)
    call report(allocated(op%fac(1)%l) .and. op%s(1)%n == 0, 'harmonic: S not yet formed at outer iteration '// &
                'max(8, m/16) = 8')
    call operator_matrix(op, m, form_at, sf, sf2, count)
    call report(.not. allocated(op%fac(1)%l) .and. op%s(1)%n == m .and. count == m, &
                'harmonic: S formed at outer iteration max(8, m/16) + 1 = 9, one product per application')
    call report_le(relerr(sf, sref), tol, 'harmonic: the formed S = 2 (F_1^-1 + F_2^-1)^-1'//trim(tag))
    call report(all(sf == transpose(sf)) .and. all(sf == sf2), 'harmonic: the formed S exactly symmetric, on both sides')
  end subroutine harmonic_pair

  !> With friction: S of the normal rows and S of the tangential rows apart (S block diagonal
  !! by row kind, each block the harmonic formula of the blocks of F_1 and F_2).
  subroutine test_harmonic_kinds()
    integer, parameter :: m = 6
    type(interface_t) :: itf
    type(body_condensed_t) :: bodies(2)
    type(dense_op_t), allocatable :: ops(:)
    type(harmonic_operator_t) :: op
    type(solver_cfg_t) :: solver
    type(error_t) :: err
    real(wp) :: f1(m, m), f2(m, m), s1(m, m), s2(m, m), want(m, m)
    integer :: count
    integer, parameter :: nr(3) = [1, 3, 5], tr(3) = [2, 4, 6]
    call pair_interface(m, itf, dir=[0, 1, 0, 1, 0, 1])
    f1 = random_flex(m, 1.5_wp, 1.0_wp)
    f2 = random_flex(m, 1.5_wp, 4.0_wp)
    call condensed(itf, 1, f1, bodies(1))
    call condensed(itf, 2, f2, bodies(2))
    call flex_ops(bodies, ops)
    call op%setup(solver, itf, bodies, ops, err)
    call operator_matrix(op, m, 1, s1, s2, count)
    want = 0.0_wp
    want(nr, nr) = 2.0_wp*inv(inv(f1(nr, nr)) + inv(f2(nr, nr)))
    want(tr, tr) = 2.0_wp*inv(inv(f1(tr, tr)) + inv(f2(tr, tr)))
    call report(.not. err%failed() .and. all(s1(nr, tr) == 0.0_wp) .and. all(s1(tr, nr) == 0.0_wp), &
                'harmonic with friction: no coupling between normal and tangential rows')
    call report_le(relerr(s1, want), 1.0e3_wp*eps, 'harmonic with friction: each kind''s block = '// &
                   '2 (F_1^-1 + F_2^-1)^-1 of its rows'' blocks')
  end subroutine test_harmonic_kinds

  !> A floating body 2 (one equilibrium row G): S = 2 (F_1^-1 + Q_2)^-1 with Q_2 its projected
  !! inverse F_2^-1 - F_2^-1 G' (G F_2^-1 G')^-1 G F_2^-1 (doc/method.md, "Bodies held only by
  !! contact").
  subroutine test_harmonic_floating()
    integer, parameter :: m = 6
    type(interface_t) :: itf
    type(body_condensed_t) :: bodies(2)
    type(dense_op_t), allocatable :: ops(:)
    type(harmonic_operator_t) :: op
    type(solver_cfg_t) :: solver
    type(error_t) :: err
    real(wp) :: f1(m, m), f2(m, m), s1(m, m), s2(m, m), g(1, m), q2(m, m), fi(m, m), y(m, 1)
    integer :: count
    call pair_interface(m, itf)
    f1 = random_flex(m, 1.5_wp, 1.0_wp)
    f2 = random_flex(m, 1.5_wp, 2.0_wp)
    g(1, :) = [0.5_wp, 1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp, 0.5_wp]
    call condensed(itf, 1, f1, bodies(1))
    call condensed(itf, 2, f2, bodies(2))
    bodies(2)%nrig = 1
    bodies(2)%rg = g
    call flex_ops(bodies, ops)
    call op%setup(solver, itf, bodies, ops, err)
    call operator_matrix(op, m, 1, s1, s2, count)
    fi = inv(f2)
    y = matmul(fi, transpose(g))
    q2 = fi - matmul(y, transpose(y))/sum(matmul(g, y))
    call report(.not. err%failed() .and. all(s1 == s2), 'harmonic, floating body: set up, corr_1 = corr_2')
    call report_le(relerr(s1, 2.0_wp*inv(inv(f1) + q2)), 1.0e3_wp*eps, &
                   'harmonic, floating body: S = 2 (F_1^-1 + Q_2)^-1, Q_2 the projected inverse')
  end subroutine test_harmonic_floating

  ! ---- three bodies: the group operator and the fixed point ----------------------------------

  !> A stack of three bodies (body 2 in both pairs): S = 2 K^-1 with K = sum_a E_a' D_a F_a^-1
  !! D_a E_a, D_a = +1 on side-1 rows, -1 on side-2 rows; then the outer iteration with every
  !! row active reaches the monolithic solution in two updates at delta = 0.5.
  subroutine test_three_bodies()
    type(interface_t) :: itf
    type(body_condensed_t) :: stack(3)
    type(dense_op_t), allocatable :: ops(:)
    type(harmonic_operator_t) :: op
    type(solver_cfg_t) :: solver
    type(error_t) :: err
    real(wp) :: f(6, 6, 3), s1(6, 6), s2(6, 6), kk(6, 6), sg(6), sig(6, 6), errs(4)
    integer :: count, a, i, j, ma
    integer :: rows(6)
    call stack_interface(itf)
    f(1:3, 1:3, 1) = random_flex(3, 1.0_wp, 1.0_wp)
    f(:, :, 2) = random_flex(6, 1.0_wp, 1.0e-3_wp)
    f(1:3, 1:3, 3) = random_flex(3, 1.0_wp, 10.0_wp)
    call condensed(itf, 1, f(1:3, 1:3, 1), stack(1))
    call condensed(itf, 2, f(:, :, 2), stack(2))
    call condensed(itf, 3, f(1:3, 1:3, 3), stack(3))
    call flex_ops(stack, ops)
    call op%setup(solver, itf, stack, ops, err)
    call operator_matrix(op, 6, 1, s1, s2, count)
    kk = 0.0_wp
    do a = 1, 3
      ma = stack(a)%m
      rows(1:ma) = slot_row(stack(a)%slots, 6)
      sg(1:ma) = merge(1.0_wp, -1.0_wp, stack(a)%slots <= 6)
      sig(1:ma, 1:ma) = inv(f(1:ma, 1:ma, a))
      do j = 1, ma
        do i = 1, ma
          kk(rows(i), rows(j)) = kk(rows(i), rows(j)) + sg(i)*sg(j)*sig(i, j)
        end do
      end do
    end do
    call report(.not. err%failed() .and. size(op%group) == 1 .and. all(s1 == s2), &
                'harmonic, three bodies: one group of both pairs, corr_1 = corr_2')
    call report_le(relerr(s1, 2.0_wp*inv(kk)), 1.0e4_wp*eps, 'harmonic, three bodies: S = 2 K^-1, '// &
                   'K = sum E''D Sigma D E assembled by hand')
    ! rounding: the solves' errors amplified by the contrast (1e4)
    call outer_iteration(itf, stack, op, 0.5_wp, 4, errs)
    call report(errs(2) > 1.0e-3_wp .and. errs(3) <= 1.0e3_wp*1.0e4_wp*eps .and. errs(4) <= 1.0e3_wp*1.0e4_wp*eps, &
                'harmonic, three bodies (contrast 1e4), every row active, delta 0.5: the third solve is the '// &
                'monolithic solution', errs(3), 1.0e3_wp*1.0e4_wp*eps)
  end subroutine test_three_bodies

  !> The outer iteration of doc/method.md ("Method as implemented" 2, "Several bodies and
  !! contact pairs") with every row active, written out here: each body solves F_a lam_a =
  !! b_a - G_a exactly (LAPACK), w_a = b_a - F_a lam_a; with d = lam_side1 - lam_side2, side
  !! 1's obstacle becomes g0 - w_side2 + corr_1 and side 2's g0 - w_side1 - corr_2, relaxed
  !! by delta. errs(k): max over both sides of |lam - lam*| / |lam*| after solve k, lam* the
  !! monolithic solution H lam = sum_a E_a' b_a - g0, H = sum_a E_a' F_a E_a.
  subroutine outer_iteration(itf, bodies, op, delta, nit, errs)
    type(interface_t), intent(in) :: itf
    type(body_condensed_t), intent(inout) :: bodies(:)
    class(robin_operator_t), intent(inout) :: op
    real(wp), intent(in) :: delta
    integer, intent(in) :: nit
    real(wp), intent(out) :: errs(nit)
    real(wp) :: h(itf%m, itf%m), c(itf%m), lstar(itf%m), g(itf%m, 2), lam(itf%m, 2), w(itf%m, 2), d(itf%m)
    real(wp) :: corr(itf%m, 2), gnew(itf%m, 2)
    real(wp), allocatable :: la(:), ga(:)
    integer :: a, k, it, m, count, ma
    integer, allocatable :: rows(:), sides(:)
    m = itf%m
    ! loads b_a = F_a (1.1, 1.2, ...) on its rows; the monolithic forces solve H lam = c
    h = 0.0_wp
    c = -itf%g0
    do a = 1, size(bodies)
      ma = bodies(a)%m
      rows = slot_row(bodies(a)%slots, m)
      bodies(a)%b = matmul(bodies(a)%flex, [(1.0_wp + 0.1_wp*k, k=1, ma)])
      h(rows, rows) = h(rows, rows) + bodies(a)%flex
      c(rows) = c(rows) + bodies(a)%b
    end do
    lstar = matmul(inv(h), c)
    g(:, 1) = itf%g0
    g(:, 2) = itf%g0
    count = 0
    do it = 1, nit
      do a = 1, size(bodies)
        rows = slot_row(bodies(a)%slots, m)
        sides = (bodies(a)%slots - 1)/m + 1
        ga = [(g(rows(k), sides(k)), k=1, bodies(a)%m)]
        la = matmul(inv(bodies(a)%flex), bodies(a)%b - ga)
        do k = 1, bodies(a)%m
          lam(rows(k), sides(k)) = la(k)
          w(rows(k), sides(k)) = bodies(a)%b(k) - dot_product(bodies(a)%flex(k, :), la)
        end do
      end do
      errs(it) = maxval(abs(lam - spread(lstar, 2, 2)))/maxval(abs(lstar))
      d = lam(:, 1) - lam(:, 2)
      call op%apply(d, corr, count, it)
      gnew(:, 1) = itf%g0 - w(:, 2) + corr(:, 1)
      gnew(:, 2) = itf%g0 - w(:, 1) - corr(:, 2)
      g = (1.0_wp - delta)*g + delta*gnew
    end do
  end subroutine outer_iteration

  !> Two bodies at contrast 1e4: 'harmonic' at delta 0.5 is exact after two updates; 'steklov'
  !! (F_2 F_1^-1 of spectrum within [0.5, 2], so delta = 0.5 contracts) reaches the same
  !! fixed point, the monolithic solution.
  subroutine test_fixed_point_two()
    integer, parameter :: m = 8
    type(interface_t) :: itf
    type(body_condensed_t) :: bodies(2)
    type(dense_op_t), allocatable :: ops(:)
    type(harmonic_operator_t) :: hop
    type(steklov_operator_t) :: sop
    type(solver_cfg_t) :: solver
    type(error_t) :: err
    real(wp) :: f1(m, m), errs(4), errs_s(80), d(m)
    integer :: i
    call pair_interface(m, itf)
    f1 = random_flex(m, 1.0_wp, 1.0_wp)
    call condensed(itf, 1, f1, bodies(1))
    call condensed(itf, 2, 1.0e-4_wp*random_flex(m, 1.0_wp, 1.0_wp), bodies(2))
    call flex_ops(bodies, ops)
    call hop%setup(solver, itf, bodies, ops, err)
    call outer_iteration(itf, bodies, hop, 0.5_wp, 4, errs)
    call report(errs(2) > 1.0e-3_wp .and. errs(3) <= 1.0e3_wp*1.0e4_wp*eps .and. errs(4) <= 1.0e3_wp*1.0e4_wp*eps, &
                'harmonic, two bodies (contrast 1e4), every row active, delta 0.5: the third solve is the '// &
                'monolithic solution', errs(3), 1.0e3_wp*1.0e4_wp*eps)
    ! steklov: F_2 = F_1 (I + E) with a small symmetric E, then relaxation by 0.5 contracts
    do i = 1, m
      d(i) = 1.0_wp + 0.5_wp*urand(-1.0_wp, 1.0_wp)
    end do
    bodies(2)%flex = f1
    do i = 1, m
      bodies(2)%flex(i, i) = bodies(2)%flex(i, i)*d(i)
    end do
    call flex_ops(bodies, ops)
    call sop%setup(solver, itf, bodies, ops, err)
    call outer_iteration(itf, bodies, sop, 0.5_wp, 80, errs_s)
    call report(errs_s(2) > 1.0e-6_wp .and. errs_s(80) <= 1.0e-11_wp, 'steklov, delta 0.5: its fixed point is the '// &
                'monolithic solution too', errs_s(80), 1.0e-11_wp)
  end subroutine test_fixed_point_two

  !> F_1 + F_2 not positive definite: the harmonic operator cannot be built (ERR_NUMERICAL).
  subroutine test_not_definite()
    type(interface_t) :: itf
    type(body_condensed_t) :: bodies(2)
    type(dense_op_t), allocatable :: ops(:)
    type(harmonic_operator_t) :: op
    type(solver_cfg_t) :: solver
    type(error_t) :: err
    call pair_interface(3, itf)
    call condensed(itf, 1, -identity(3), bodies(1))
    call condensed(itf, 2, 0.5_wp*identity(3), bodies(2))
    call flex_ops(bodies, ops)
    call op%setup(solver, itf, bodies, ops, err)
    call report(err%category == ERR_NUMERICAL .and. index(err%text(), 'not positive definite') > 0, &
                'harmonic: F_1 + F_2 not positive definite is refused: '//err%text())
  end subroutine test_not_definite

  ! ---- inner tolerances and lambda_max ------------------------------------------------------

  subroutine test_tolerances()
    type(solver_cfg_t) :: solver
    type(steklov_operator_t) :: sop
    type(harmonic_operator_t) :: hop
    real(wp) :: r(5)
    solver%inner_rtol_min = 1.0e-10_wp
    solver%inner_rtol_max = 1.0e-2_wp
    solver%inner_factor = 0.1_wp
    solver%tol = 1.0e-8_wp
    r(1) = progress_rtol(solver, 1, 1.0e-6_wp)
    r(2) = progress_rtol(solver, 2, 1.0e-6_wp)
    r(3) = progress_rtol(solver, 2, 1.0e-15_wp)
    r(4) = progress_rtol(solver, 2, 10.0_wp)
    r(5) = sop%inner_tolerance(solver, 5, 40, 1.0e-6_wp, [1.0_wp, 2.0_wp])
    call report(r(1) == 1.0e-2_wp .and. r(2) == 0.1_wp*1.0e-6_wp .and. r(3) == 1.0e-10_wp .and. r(4) == 1.0e-2_wp &
                .and. r(5) == r(2), 'inner tolerance: inner_rtol_max first, then inner_factor x progress '// &
                'clamped to [inner_rtol_min, inner_rtol_max]')
    r(1) = hop%inner_tolerance(solver, 5, 100, 1.0_wp, [2.0e-9_wp, 4.0e-6_wp])
    r(2) = hop%inner_tolerance(solver, 1, 100, 1.0_wp, [1.0e-9_wp, 1.0e-1_wp])
    call report(abs(r(1) - 0.1_wp*1.0e-8_wp*(2.0e-9_wp/4.0e-6_wp)) <= 4.0_wp*eps*r(1) .and. &
                r(2) == 10.0_wp*eps, 'harmonic inner tolerance: inner_factor tol lmax_min/lmax_max, '// &
                'at least sqrt(m) eps')
  end subroutine test_tolerances

  subroutine test_lambda_max()
    integer, parameter :: m = 9
    type(steklov_operator_t) :: sop
    type(harmonic_operator_t) :: hop
    type(dense_op_t) :: fop
    real(wp) :: f(m, m), dd(m), lmax, est
    integer :: nmv, i
    dd = [(1.0_wp + 0.1_wp*i, i=1, m)]
    dd(m) = 20.0_wp
    call spd_from_eigs(m, dd, f)
    call dense_op_init(fop, f)
    lmax = maxval(eigs(f))
    est = sop%body_lambda_max(fop, f, nmv)
    call report(est == maxval(sum(abs(f), dim=1)) .and. est >= lmax .and. nmv == 0, &
                'lambda_max bound (steklov, constant): the row-sum norm, >= lambda_max, no product')
    est = hop%body_lambda_max(fop, f, nmv)
    call report(est <= lmax*(1.0_wp + 8.0_wp*eps) .and. est >= 0.999_wp*lmax .and. nmv == 10, &
                'lambda_max estimate (harmonic): 10 power iterations, below lambda_max and within 0.1%', &
                (lmax - est)/lmax)
  end subroutine test_lambda_max

  ! ---- the proximal term ---------------------------------------------------------------------

  subroutine test_proximal()
    integer, parameter :: m = 6, k = 2
    type(interface_t) :: itf
    type(body_condensed_t) :: bodies(2), stack(3)
    type(steklov_operator_t) :: sop
    type(harmonic_operator_t) :: hop
    real(wp) :: f1(m, m), fo(m, m), dd(m), p(m, m), z(m, k), q(m, m - k), zz(m, m), want(m, m), floor
    real(wp) :: qmat(m, m), f3(3, 3), f2(6, 6)
    integer :: i
    ! a singular F_1 = Q diag(dd) Q' with dd = 0 on k columns: its kernel Z, its range Q_r
    call pair_interface(m, itf)
    dd = [0.0_wp, 0.0_wp, 1.0_wp, 2.0_wp, 3.0_wp, 5.0_wp]
    call spd_from_eigs(m, [(real(i, wp), i=1, m)], qmat)
    qmat = orthonormal_basis(qmat)
    f1 = matmul(qmat, matmul(diag(dd), transpose(qmat)))
    z = qmat(:, 1:k)
    q = qmat(:, k + 1:m)
    fo = random_flex(m, 1.0_wp, 2.0_wp)
    call condensed(itf, 1, f1, bodies(1))
    call condensed(itf, 2, fo, bodies(2))
    bodies(1)%rank = m - k
    bodies(1)%prox = 1.0e-2_wp*maxval([(f1(i, i), i=1, m)])
    ! the default (steklov, constant): the partner's F on the body's rows
    call sop%proximal_term(itf, bodies, 1, p)
    call report(all(p == fo), 'proximal term (steklov): the partner''s F on the body''s rows')
    ! harmonic, from a kernel basis: Z (Z' F_o Z + floor I) Z', floor = 1e-10 max diag F_o
    floor = 1.0e-10_wp*maxval([(fo(i, i), i=1, m)])
    bodies(1)%kern = z
    call hop%proximal_term(itf, bodies, 1, p)
    want = matmul(z, matmul(matmul(matmul(transpose(z), fo), z) + floor*identity(k), transpose(z)))
    call report_le(relerr(p, want), 64.0_wp*eps, 'proximal term (harmonic, kernel basis Z): Z (Z''F_o Z + floor I) Z''')
    call report(minval(eigs(f1 + p)) > 1.0e-3_wp*maxval(eigs(f1)), 'proximal term (harmonic): F_a + Pi_a definite', &
                minval(eigs(f1 + p))/maxval(eigs(f1)))
    ! from the range basis instead (range_proximal): the same Z Z' = I - Q Q'
    deallocate (bodies(1)%kern)
    bodies(1)%rng = q
    call hop%proximal_term(itf, bodies, 1, p)
    zz = identity(m) - matmul(q, transpose(q))
    want = matmul(zz, matmul(fo, zz)) + floor*zz
    call report_le(relerr(p, want), 64.0_wp*eps, 'proximal term (harmonic, range basis Q): (I - QQ'') F_o '// &
                   '(I - QQ'') + floor (I - QQ'')')
    call report_le(maxval(abs(matmul(p, q)))/maxval(abs(p)), 64.0_wp*eps, 'proximal term: zero on the range of F_a')
    call range_proximal(q, fo, want)
    call report(all(want == p), 'range_proximal: the harmonic operator''s term from the range basis')
    ! harmonic without either basis: the partner's F
    deallocate (bodies(1)%rng)
    call hop%proximal_term(itf, bodies, 1, p)
    call report(all(p == fo), 'proximal term (harmonic, no basis): the partner''s F')
    ! three bodies: the middle body's partners' F, pair by pair in its positions, 0 between
    call stack_interface(itf)
    f3 = random_flex(3, 1.0_wp, 1.0_wp)
    f2 = random_flex(6, 1.0_wp, 1.0_wp)
    call condensed(itf, 1, f3, stack(1))
    call condensed(itf, 2, f2, stack(2))
    call condensed(itf, 3, 2.0_wp*f3, stack(3))
    call sop%proximal_term(itf, stack, 2, p)
    want = 0.0_wp
    want(1:3, 1:3) = f3
    want(4:6, 4:6) = 2.0_wp*f3
    call report(all(p == want), 'proximal term, body in two pairs: each pair''s partner F in its positions, 0 between')
  end subroutine test_proximal

  !> diag(d).
  pure function diag(d) result(a)
    real(wp), intent(in) :: d(:)
    real(wp) :: a(size(d), size(d))
    integer :: i
    a = 0.0_wp
    do i = 1, size(d)
      a(i, i) = d(i)
    end do
  end function diag

  !> The eigenvectors of a symmetric a (an orthonormal basis, by dsyev).
  function orthonormal_basis(a) result(v)
    real(wp), intent(in) :: a(:, :)
    real(wp) :: v(size(a, 1), size(a, 1)), w(size(a, 1)), work(64*size(a, 1) + 64)
    integer :: info, n
    n = size(a, 1)
    v = a
    call dsyev('V', 'U', n, v, n, w, work, size(work), info)
    if (info /= 0) error stop 'orthonormal_basis: dsyev failed'
  end function orthonormal_basis

  ! ---- the subproblems -----------------------------------------------------------------------

  !> Two bodies of 5 rows, body 2 singular (a kernel of one vector) with a proximal term:
  !! the Hessians, their lambda_max bounds, and one outer iteration's solves against active-set
  !! enumeration of min 1/2 l'H_a l - l'(b_a - G_a + Pi_a lam_o), l >= 0.
  subroutine test_subproblems()
    integer, parameter :: m = 5
    type(interface_t) :: itf
    type(body_condensed_t) :: bodies(2)
    type(harmonic_operator_t) :: hop
    type(steklov_operator_t) :: sop
    type(subproblems_t) :: sp
    type(robin_state_t) :: st
    type(contact_result_t) :: res
    type(solver_cfg_t) :: solver
    real(wp) :: f1(m, m), f2(m, m), qmat(m, m), pi2(m, m), h(m, m), x(m), mu(0), e0(0), gg(m), w(m, 2), lo(m), hi(m)
    real(wp) :: lam_o(m), rhs(m), e1, e2, ew, lmx(2)
    integer :: i
    logical :: ok
    call pair_interface(m, itf)
    f1 = random_flex(m, 1.0_wp, 1.0_wp)
    call spd_from_eigs(m, [(real(i, wp), i=1, m)], qmat)
    qmat = orthonormal_basis(qmat)
    f2 = matmul(qmat, matmul(diag([0.0_wp, 0.5_wp, 1.0_wp, 2.0_wp, 3.0_wp]), transpose(qmat)))
    call condensed(itf, 1, f1, bodies(1))
    call condensed(itf, 2, f2, bodies(2))
    bodies(2)%rank = m - 1
    bodies(2)%prox = 3.0e-2_wp
    bodies(2)%kern = qmat(:, 1:1)
    bodies(1)%b = [0.3_wp, -0.2_wp, 0.5_wp, 0.1_wp, -0.4_wp]
    bodies(2)%b = [0.2_wp, 0.4_wp, -0.3_wp, 0.6_wp, 0.1_wp]
    call state_init(st, m, itf%g0, 2, 1)
    call alloc_result(res, m, 10, 2)
    ! last forces (the partners' for the proximal term, the warm starts), not yet multiplied
    st%lam(:, 1) = [0.1_wp, 0.0_wp, 0.2_wp, 0.3_wp, 0.0_wp]
    st%lam(:, 2) = [0.2_wp, 0.1_wp, 0.0_wp, 0.1_wp, 0.4_wp]
    st%reuse = 0
    ! the steklov operator: the row-sum bound of lambda_max(F_a), no product; body 2's proximal
    ! term the partner's F
    call subproblems_init(sp, itf, bodies, sop, st, .false.)
    lmx = [maxval(eigs(f1)), maxval(eigs(f2 + f1))]
    call report(all(sp%hessian(1)%a == f1) .and. sp%proximal(1)%n == 0 .and. all(sp%hessian(2)%a == f2 + f1) .and. &
                all(sp%lmax_hessian >= lmx) .and. st%inner == 0, 'subproblems (steklov): Hessians F_1 and F_2 + F_1, '// &
                'their lambda_max bounded from above, no product')
    ! the harmonic operator: Pi_2 on body 2's kernel only, 10 power products per body counted
    call subproblems_init(sp, itf, bodies, hop, st, .false.)
    call hop%proximal_term(itf, bodies, 2, pi2)
    call report(all(sp%hessian(1)%a == f1) .and. sp%proximal(1)%n == 0 .and. all(sp%hessian(2)%a == f2 + pi2) .and. &
                sp%proximal(2)%n == m .and. st%inner == 20, 'subproblems (harmonic): Hessians F_1 and F_2 + Pi_2, '// &
                '10 power products per body counted')
    solver%inner_max_it = 10000
    call solve_subproblems(sp, solver, bodies, 1.0e-13_wp, 1, st, w, res)
    lo = 0.0_wp
    hi = huge(1.0_wp)
    ! body 1: min 1/2 l'F_1 l - l'(b_1 - G_1)
    rhs = bodies(1)%b - st%G(:, 1)
    call enumerate_box(f1, rhs, reshape([real(wp) ::], [0, m]), e0, lo, hi, x, mu, gg, ok)
    e1 = norm2(st%lam(:, 1) - x)/norm2(x)
    ew = maxval(abs(w(:, 1) - (bodies(1)%b - matmul(f1, st%lam(:, 1)))))
    ! body 2: min 1/2 l'(F_2 + Pi_2) l - l'(b_2 - G_2 + Pi_2 lam_o), lam_o body 1's last forces
    lam_o = [0.1_wp, 0.0_wp, 0.2_wp, 0.3_wp, 0.0_wp]
    h = f2 + pi2
    rhs = bodies(2)%b - st%G(:, 2) + matmul(pi2, lam_o)
    call enumerate_box(h, rhs, reshape([real(wp) ::], [0, m]), e0, lo, hi, x, mu, gg, ok)
    e2 = norm2(st%lam(:, 2) - x)/norm2(x)
    ew = max(ew, maxval(abs(w(:, 2) - (bodies(2)%b - matmul(f2, st%lam(:, 2))))))
    call report(ok .and. count(st%lam(:, 1) == 0.0_wp) > 0 .and. count(st%lam(:, 1) > 0.0_wp) > 0, &
                'subproblems: the enumerated minimiser has active and inactive rows (the test bites)')
    call report_le(e1, 1.0e-10_wp, 'subproblems: body 1''s forces = the minimiser of its QP (active-set enumeration)')
    call report_le(e2, 1.0e-10_wp, 'subproblems: body 2''s forces = the minimiser of its QP with the proximal term '// &
                   'pinned to body 1''s last forces')
    call report_le(ew, 1.0e-12_wp, 'subproblems: B_a u_a = b_a - F_a lam_a on each side')
  end subroutine test_subproblems

end program test_robin_operators
