!> Unit test of module cholesky (CHOLMOD + banded factorizations, interface flexibility).
!! Test matrices are built here, independently of the FE code: a shifted 2D 5-point
!! Laplacian, a 2D bar-and-diagonal spring lattice (2 DOF per node, clamped on one
!! side: an elasticity-like SPD matrix), and a random diagonally dominant SPD matrix.
!! Every result is checked against dense LAPACK. One line per check; exits non-zero
!! if any check fails.
program test_cholesky
  use, intrinsic :: iso_fortran_env, only: output_unit
  use omp_lib, only: omp_get_max_threads, omp_get_num_threads, omp_set_max_active_levels
  use kinds, only: wp
  use cholesky, only: chol_t, FACT_CHOLMOD, FACT_BANDED, ORD_METIS, ORD_AMD, ORD_NATURAL
  use banded, only: rcm_order, band_width
  use lapack, only: dpotrf, dpotrf_tiles, dpotri, dposv, dpocon
  use clock, only: wtime
  use testing, only: report, report_le, test_summary, error_parts
  use errors, only: error_t, ERR_NUMERICAL
  implicit none (type, external)

  !> A sparse symmetric matrix in full 0-based CSC.
  type :: csc_t
    integer :: n = 0
    integer, allocatable :: colptr(:), rowind(:)
    real(wp), allocatable :: val(:)
  end type csc_t

  real(wp), parameter :: eps = epsilon(1.0_wp)
  real(wp), parameter :: RES_TOL = 10.0_wp     ! scaled residual threshold
  integer :: seed_size
  integer, allocatable :: seed(:)
  type(csc_t) :: A
  integer, allocatable :: iface(:)
  integer :: k, nx

  call random_seed(size=seed_size)
  allocate (seed(seed_size))
  seed = 20240611
  call random_seed(put=seed)
  write (output_unit, '(a,i0)') 'test_cholesky: OpenMP threads available = ', omp_get_max_threads()

  ! ---- 1. shifted 2D Laplacian, interface = last grid row ----
  k = 14
  call laplace2d(k, 1.0_wp, A)
  iface = [(k * (k - 1) + nx, nx = 1, k)]
  call check_matrix('laplace14', A, iface)

  ! ---- 2. 2D spring lattice (2 DOF/node), interface = y-DOFs of the bottom edge ----
  nx = 9
  call lattice2d(nx, 8, A)
  iface = [(2 * (nx - 1 - k) + 2, k = 0, nx - 1)]      ! bottom edge, given right to left
  call check_matrix('lattice9x8', A, iface)

  ! ---- 3. random sparse SPD (diagonally dominant), interface = random unsorted subset ----
  call random_spd(180, 5, A)
  iface = random_subset(180, 23)
  call check_matrix('random180', A, iface)

  ! ---- 4. RCM on a randomly numbered grid ----
  call check_rcm()

  ! ---- 5. not positive definite ----
  call check_not_posdef()

  ! ---- 6. bad input ----
  call check_bad_input()

  ! ---- 7. two factorizations at once (OpenMP sections) ----
  call check_concurrent(ORD_METIS)
  call check_concurrent(ORD_AMD)

  call check_row_flexibility()

  ! ---- 8. the factorization's dense kernels as tiles: the same bits at any thread count ----
  call check_tiles()
  call check_potrf_tiles()

  ! ---- 9. larger problem: timings ----
  call timing_run()

  call test_summary()

contains

  ! ======================================================================
  ! reporting
  ! ======================================================================




  ! ======================================================================
  ! matrix builders
  ! ======================================================================

  !> Full symmetric CSC from triplets (duplicates summed, rows sorted).
  subroutine csc_from_triplets(n, ti, tj, tv, nt, M)
    integer, intent(in) :: n, nt
    integer, intent(in) :: ti(:), tj(:)       ! 1-based
    real(wp), intent(in) :: tv(:)
    type(csc_t), intent(out) :: M
    integer, allocatable :: cnt(:), ri(:), pos(:)
    real(wp), allocatable :: rv(:)
    integer :: t, j, p, q, i, nnz, pstart
    real(wp) :: v
    allocate (cnt(n + 1), pos(n))
    cnt = 0
    do t = 1, nt
      cnt(tj(t) + 1) = cnt(tj(t) + 1) + 1
    end do
    cnt(1) = 0
    do j = 1, n
      cnt(j + 1) = cnt(j + 1) + cnt(j)
    end do
    allocate (ri(nt), rv(nt))
    pos = cnt(1:n)
    do t = 1, nt
      pos(tj(t)) = pos(tj(t)) + 1
      ri(pos(tj(t))) = ti(t)
      rv(pos(tj(t))) = tv(t)
    end do
    ! sort each column (insertion sort) and merge duplicates
    M%n = n
    allocate (M%colptr(n + 1), M%rowind(nt), M%val(nt))
    nnz = 0
    M%colptr(1) = 0
    do j = 1, n
      do p = cnt(j) + 2, cnt(j + 1)
        i = ri(p)
        v = rv(p)
        q = p - 1
        do while (q > cnt(j))
          if (ri(q) <= i) exit
          ri(q + 1) = ri(q)
          rv(q + 1) = rv(q)
          q = q - 1
        end do
        ri(q + 1) = i
        rv(q + 1) = v
      end do
      pstart = nnz
      do p = cnt(j) + 1, cnt(j + 1)
        if (nnz > pstart) then
          if (M%rowind(nnz) == ri(p) - 1) then
            M%val(nnz) = M%val(nnz) + rv(p)
            cycle
          end if
        end if
        nnz = nnz + 1
        M%rowind(nnz) = ri(p) - 1
        M%val(nnz) = rv(p)
      end do
      M%colptr(j + 1) = nnz
    end do
    M%rowind = M%rowind(1:nnz)
    M%val = M%val(1:nnz)
  end subroutine csc_from_triplets

  !> 5-point Laplacian on a k x k grid (Dirichlet boundary) plus shift*I.
  subroutine laplace2d(k, shift, M)
    integer, intent(in) :: k
    real(wp), intent(in) :: shift
    type(csc_t), intent(out) :: M
    integer, allocatable :: ti(:), tj(:)
    real(wp), allocatable :: tv(:)
    integer :: i, j, nt, id
    allocate (ti(5 * k * k), tj(5 * k * k), tv(5 * k * k))
    nt = 0
    do j = 1, k
      do i = 1, k
        id = (j - 1) * k + i
        call add_trip(ti, tj, tv, nt, id, id, 4.0_wp + shift)
        if (i > 1) call add_trip(ti, tj, tv, nt, id, id - 1, -1.0_wp)
        if (i < k) call add_trip(ti, tj, tv, nt, id, id + 1, -1.0_wp)
        if (j > 1) call add_trip(ti, tj, tv, nt, id, id - k, -1.0_wp)
        if (j < k) call add_trip(ti, tj, tv, nt, id, id + k, -1.0_wp)
      end do
    end do
    call csc_from_triplets(k * k, ti, tj, tv, nt, M)
  end subroutine laplace2d

  subroutine add_trip(ti, tj, tv, nt, a, b, v)
    integer, intent(inout) :: ti(:), tj(:), nt
    real(wp), intent(inout) :: tv(:)
    integer, intent(in) :: a, b
    real(wp), intent(in) :: v
    nt = nt + 1
    ti(nt) = a
    tj(nt) = b
    tv(nt) = v
  end subroutine add_trip

  !> Spring lattice on nx x ny cells, nodes (i,j), i = 0..nx, j = 0..ny, bars along
  !! the edges and both diagonals of every cell (axial stiffness EA/L with EA = 1),
  !! nodes i = 0 clamped. Free node (i,j) has DOFs 2*((j*nx)+i-1)+1 (x) and +2 (y).
  subroutine lattice2d(nx, ny, M)
    integer, intent(in) :: nx, ny
    type(csc_t), intent(out) :: M
    integer, allocatable :: ti(:), tj(:)
    real(wp), allocatable :: tv(:)
    integer :: i, j, nt, cap
    cap = 4 * 16 * (nx + 1) * (ny + 1)
    allocate (ti(cap), tj(cap), tv(cap))
    nt = 0
    do j = 0, ny
      do i = 0, nx
        if (i < nx) call lattice_bar(nx, ti, tj, tv, nt, i, j, i + 1, j)
        if (j < ny) call lattice_bar(nx, ti, tj, tv, nt, i, j, i, j + 1)
        if (i < nx .and. j < ny) then
          call lattice_bar(nx, ti, tj, tv, nt, i, j, i + 1, j + 1)
          call lattice_bar(nx, ti, tj, tv, nt, i + 1, j, i, j + 1)
        end if
      end do
    end do
    call csc_from_triplets(2 * nx * (ny + 1), ti, tj, tv, nt, M)
  end subroutine lattice2d

  !> Add one bar (axial stiffness 1/length) between lattice nodes (i1,j1) and (i2,j2).
  subroutine lattice_bar(nx, ti, tj, tv, nt, i1, j1, i2, j2)
      integer, intent(in) :: nx
      integer, intent(inout) :: ti(:), tj(:), nt
      real(wp), intent(inout) :: tv(:)
      integer, intent(in) :: i1, j1, i2, j2
      real(wp) :: d(2), len, ke
      integer :: a, b, da(4)
      real(wp) :: s(4)
      d = [real(i2 - i1, wp), real(j2 - j1, wp)]
      len = norm2(d)
      d = d / len
      ke = 1.0_wp / len
      da = [lattice_dof(nx, i1, j1, 1), lattice_dof(nx, i1, j1, 2), &
            lattice_dof(nx, i2, j2, 1), lattice_dof(nx, i2, j2, 2)]
      s = [d(1), d(2), -d(1), -d(2)]
      do b = 1, 4
        do a = 1, 4
          if (da(a) > 0 .and. da(b) > 0) call add_trip(ti, tj, tv, nt, da(a), da(b), ke * s(a) * s(b))
        end do
      end do
  end subroutine lattice_bar

  !> DOF number of component c of lattice node (i,j); 0 for clamped nodes (i = 0).
  integer function lattice_dof(nx, i, j, c)
    integer, intent(in) :: nx, i, j, c
    if (i == 0) then
      lattice_dof = 0
    else
      lattice_dof = 2 * (j * nx + i - 1) + c
    end if
  end function lattice_dof

  !> Random symmetric pattern with about nb off-diagonals per column, values in
  !! [-1,1], diagonal = sum of |off-diagonals| + 1 (strictly diagonally dominant).
  subroutine random_spd(n, nb, M)
    integer, intent(in) :: n, nb
    type(csc_t), intent(out) :: M
    integer, allocatable :: ti(:), tj(:)
    real(wp), allocatable :: tv(:), dsum(:)
    integer :: j, q, i, nt
    real(wp) :: r, v
    allocate (ti(2 * n * nb + n), tj(2 * n * nb + n), tv(2 * n * nb + n), dsum(n))
    dsum = 0.0_wp
    nt = 0
    do j = 1, n
      do q = 1, nb / 2 + 1
        call random_number(r)
        i = 1 + int(r * n)
        i = min(max(i, 1), n)
        if (i == j) cycle
        call random_number(v)
        v = 2.0_wp * v - 1.0_wp
        nt = nt + 1; ti(nt) = i; tj(nt) = j; tv(nt) = v
        nt = nt + 1; ti(nt) = j; tj(nt) = i; tv(nt) = v
        dsum(i) = dsum(i) + abs(v)
        dsum(j) = dsum(j) + abs(v)
      end do
    end do
    do j = 1, n
      nt = nt + 1; ti(nt) = j; tj(nt) = j; tv(nt) = dsum(j) + 1.0_wp
    end do
    call csc_from_triplets(n, ti, tj, tv, nt, M)
  end subroutine random_spd

  !> m distinct random indices in 1..n, in random order.
  function random_subset(n, m) result(s)
    integer, intent(in) :: n, m
    integer :: s(m)
    integer :: p(n), i, j, t
    real(wp) :: r
    p = [(i, i = 1, n)]
    do i = n, 2, -1
      call random_number(r)
      j = 1 + int(r * i)
      j = min(j, i)
      t = p(i); p(i) = p(j); p(j) = t
    end do
    s = p(1:m)
  end function random_subset

  subroutine to_dense(M, D)
    type(csc_t), intent(in) :: M
    real(wp), allocatable, intent(out) :: D(:, :)
    integer :: j, p
    allocate (D(M%n, M%n))
    D = 0.0_wp
    do j = 1, M%n
      do p = M%colptr(j) + 1, M%colptr(j + 1)
        D(M%rowind(p) + 1, j) = M%val(p)
      end do
    end do
  end subroutine to_dense

  !> y = K x with K in CSC.
  function csc_matvec(M, x) result(y)
    type(csc_t), intent(in) :: M
    real(wp), intent(in) :: x(:)
    real(wp) :: y(M%n)
    integer :: j, p
    y = 0.0_wp
    do j = 1, M%n
      do p = M%colptr(j) + 1, M%colptr(j + 1)
        y(M%rowind(p) + 1) = y(M%rowind(p) + 1) + M%val(p) * x(j)
      end do
    end do
  end function csc_matvec

  !> Infinity norm of K (= 1-norm, symmetric).
  function csc_norm_inf(M) result(a)
    type(csc_t), intent(in) :: M
    real(wp) :: a
    real(wp) :: rs(M%n)
    integer :: j, p
    rs = 0.0_wp
    do j = 1, M%n
      do p = M%colptr(j) + 1, M%colptr(j + 1)
        rs(M%rowind(p) + 1) = rs(M%rowind(p) + 1) + abs(M%val(p))
      end do
    end do
    a = maxval(rs)
  end function csc_norm_inf

  !> Scaled residual |K u - f|_inf / (n |K|_inf |u|_inf eps).
  function scaled_residual(M, u, f) result(r)
    type(csc_t), intent(in) :: M
    real(wp), intent(in) :: u(:), f(:)
    real(wp) :: r
    r = maxval(abs(csc_matvec(M, u) - f)) / (real(M%n, wp) * csc_norm_inf(M) * maxval(abs(u)) * eps)
  end function scaled_residual

  function rel_diff(a, b) result(r)
    real(wp), intent(in) :: a(:), b(:)
    real(wp) :: r
    r = norm2(a - b) / max(norm2(b), tiny(1.0_wp))
  end function rel_diff

  function rel_diff2(a, b) result(r)
    real(wp), intent(in) :: a(:, :), b(:, :)
    real(wp) :: r
    r = norm2(a - b) / max(norm2(b), tiny(1.0_wp))
  end function rel_diff2

  ! ======================================================================
  ! checks
  ! ======================================================================

  !> All solvers against dense LAPACK on one matrix; flexibility on `iface`.
  subroutine check_matrix(name, M, iface)
    character(len=*), intent(in) :: name
    type(csc_t), intent(in) :: M
    integer, intent(in) :: iface(:)
    real(wp), allocatable :: D(:, :), Dc(:, :), f(:), ud(:), u(:), F3(:, :), U3(:, :), sgn(:)
    real(wp), allocatable :: Fd(:, :), Fb(:, :), Fs(:, :), work(:), Fsub(:, :)
    integer, allocatable :: sub(:)
    integer :: ms
    integer, allocatable :: iwork(:)
    real(wp) :: anorm, rcond, kappa, tol_sol, tol_flex, t
    integer :: n, mi, info, i, j, o, meth
    type(error_t) :: err
    logical :: used
    character(len=256) :: msg
    character(len=80) :: tag
    type(chol_t) :: ch
    character(len=*), parameter :: onames(3) = [character(len=7) :: 'metis', 'amd', 'natural']

    n = M%n
    mi = size(iface)
    call to_dense(M, D)
    allocate (f(n), sgn(mi))
    call random_number(f)
    f = f - 0.5_wp
    do i = 1, mi
      sgn(i) = merge(1.0_wp, -1.0_wp, mod(i, 3) /= 0)
    end do

    ! dense reference: solution, condition number, inverse block
    Dc = D
    anorm = maxval(sum(abs(D), dim=1))
    call dpotrf('L', n, Dc, n, info)
    call report(info == 0, name//': dense LAPACK dpotrf succeeds')
    allocate (work(3 * n), iwork(n))
    call dpocon('L', n, Dc, n, anorm, rcond, work, iwork, info)
    kappa = 1.0_wp / rcond
    write (output_unit, '(a,i0,a,i0,a,es9.2)') '      '//name//': n = ', n, ', nnz = ', M%colptr(n + 1), &
      ', kappa_1 estimate = ', kappa
    call dpotri('L', n, Dc, n, info)
    allocate (Fd(mi, mi))
    do j = 1, mi
      do i = 1, mi
        Fd(i, j) = sgn(i) * sgn(j) * Dc(max(iface(i), iface(j)), min(iface(i), iface(j)))
      end do
    end do
    Dc = D
    ud = f
    call dposv('L', n, 1, Dc, n, ud, n, info)
    call report_le(scaled_residual(M, ud, f), RES_TOL, name//': dense dposv scaled residual')

    ! solution differences are bounded by ~ kappa * eps (times a modest constant)
    tol_sol = 100.0_wp * kappa * eps
    tol_flex = max(1.0e-12_wp, 100.0_wp * kappa * eps)
    allocate (Fb(mi, mi), Fs(mi, mi))

    do meth = 1, 4
      if (meth <= 3) then
        o = meth
        tag = name//' cholmod/'//trim(onames(o))
        t = wtime()
        call ch%factor(n, M%colptr, M%rowind, M%val, FACT_CHOLMOD, o, err, last=iface)
        call error_parts(err, info, msg)
      else
        tag = name//' banded'
        call ch%factor(n, M%colptr, M%rowind, M%val, FACT_BANDED, ORD_NATURAL, err)
        call error_parts(err, info, msg)
      end if
      call report(info == 0, trim(tag)//': factor info = 0 '//trim(msg))
      if (info /= 0) cycle
      write (output_unit, '(a)') '      '//ch%summary()
      if (meth <= 3) call report(ch%interface_last_ok, trim(tag)//': interface DOFs ordered last, in the given order')
      u = f
      call ch%solve(u, err)
      call error_parts(err, info, msg)
      call report(info == 0, trim(tag)//': solve info = 0')
      call report_le(scaled_residual(M, u, f), RES_TOL, trim(tag)//': scaled residual |Ku-f|/(n|K||u|eps)')
      call report_le(rel_diff(u, ud), tol_sol, trim(tag)//': |u - u_dposv|/|u_dposv|')

      ! several right-hand sides at once = one at a time
      allocate (F3(n, 3), U3(n, 3))
      call random_number(F3)
      U3 = F3
      call ch%solve(U3, err)
      call error_parts(err, info, msg)
      do j = 1, 3
        u = F3(:, j)
        call ch%solve(u, err)
        call error_parts(err, info, msg)
        F3(:, j) = u
      end do
      call report_le(rel_diff2(U3, F3), tol_sol, trim(tag)//': 3 right-hand sides at once = one by one')
      deallocate (F3, U3)

      ! flexibility
      if (meth <= 3) then
        call ch%flexibility(iface, sgn, Fb, err, used_block=used)
        call error_parts(err, info, msg)
        call report(info == 0 .and. used, trim(tag)//': flexibility via trailing block of L used')
        call report_le(rel_diff2(Fb, Fd), tol_flex, trim(tag)//': F (trailing block) vs dense inverse block')
        call ch%flexibility(iface, sgn, Fs, err, use_solves=.true., used_block=used)
        call error_parts(err, info, msg)
        call report(info == 0 .and. .not. used, trim(tag)//': flexibility via solves ran')
        call report_le(rel_diff2(Fs, Fd), tol_flex, trim(tag)//': F (solves) vs dense inverse block')
        call report_le(rel_diff2(Fb, Fs), tol_flex, trim(tag)//': F (trailing block) vs F (solves)')
        call report(all(Fb == transpose(Fb)), trim(tag)//': F symmetric in full storage')
        ! a subset of the interface, in another order, still uses the block
        ms = max(1, mi / 2)
        sub = [(mi + 1 - 2 * i, i = 1, ms)]          ! positions mi-1, mi-3, ... (reversed)
        if (allocated(Fsub)) deallocate (Fsub)
        allocate (Fsub(ms, ms))
        call ch%flexibility(iface(sub), sgn(sub), Fsub, err, used_block=used)
        call error_parts(err, info, msg)
        call report(info == 0 .and. used .and. rel_diff2(Fsub, Fd(sub, sub)) <= tol_flex, &
                    trim(tag)//': F of a reordered interface subset (trailing block)')
      else
        call ch%flexibility(iface, sgn, Fs, err, used_block=used)
        call error_parts(err, info, msg)
        call report(info == 0 .and. .not. used, trim(tag)//': flexibility via solves ran')
        call report_le(rel_diff2(Fs, Fd), tol_flex, trim(tag)//': F (solves) vs dense inverse block')
      end if
      call ch%free()
    end do
  end subroutine check_matrix

  !> RCM gives a permutation and a small bandwidth on a randomly numbered grid.
  subroutine check_rcm()
    type(csc_t) :: M, P
    integer, allocatable :: perm(:), q(:), ti(:), tj(:)
    real(wp), allocatable :: tv(:)
    integer :: k, n, j, p2, nt, kd_rand, kd_rcm
    logical, allocatable :: seen(:)
    k = 30
    call laplace2d(k, 0.0_wp, M)
    n = M%n
    q = random_subset(n, n)               ! random renumbering old -> new
    allocate (ti(M%colptr(n + 1)), tj(M%colptr(n + 1)), tv(M%colptr(n + 1)))
    nt = 0
    do j = 1, n
      do p2 = M%colptr(j) + 1, M%colptr(j + 1)
        nt = nt + 1
        ti(nt) = q(M%rowind(p2) + 1)
        tj(nt) = q(j)
        tv(nt) = M%val(p2)
      end do
    end do
    call csc_from_triplets(n, ti, tj, tv, nt, P)
    allocate (perm(n), seen(n))
    kd_rand = band_width(n, P%colptr, P%rowind, [(j, j = 1, n)])
    call rcm_order(n, P%colptr, P%rowind, perm)
    seen = .false.
    seen(perm) = .true.
    call report(all(seen) .and. minval(perm) >= 1 .and. maxval(perm) <= n, 'RCM returns a permutation')
    kd_rcm = band_width(n, P%colptr, P%rowind, perm)
    write (output_unit, '(a,i0,a,i0,a,i0)') '      RCM on a randomly numbered ', k, '^2 grid: bandwidth ', &
      kd_rand, ' -> ', kd_rcm
    call report_le(real(kd_rcm, wp), real(2 * k, wp), 'RCM bandwidth of a k x k grid <= 2k')
  end subroutine check_rcm

  !> Indefinite matrices give ERR_NUMERICAL and a message, for every method; no crash after.
  subroutine check_not_posdef()
    type(csc_t) :: M
    type(chol_t) :: ch
    real(wp) :: lmin, u(144), F(3, 3)
    integer :: info, o, j, p
    type(error_t) :: err
    character(len=256) :: msg
    character(len=*), parameter :: onames(3) = [character(len=7) :: 'metis', 'amd', 'natural']
    ! (a) one diagonal entry made strongly negative
    call laplace2d(12, 0.0_wp, M)
    do j = 1, M%n
      do p = M%colptr(j) + 1, M%colptr(j + 1)
        if (j == 50 .and. M%rowind(p) == 49) M%val(p) = -10.0_wp
      end do
    end do
    do o = 1, 3
      call ch%factor(M%n, M%colptr, M%rowind, M%val, FACT_CHOLMOD, o, err, last=[1, 2, 3])
      call error_parts(err, info, msg)
      call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, &
                  'negative diagonal: cholmod/'//trim(onames(o))//' ERR_NUMERICAL: '//trim(msg))
    end do
    call ch%factor(M%n, M%colptr, M%rowind, M%val, FACT_BANDED, ORD_NATURAL, err)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, 'negative diagonal: banded ERR_NUMERICAL: '//trim(msg))
    ! (b) shift just below the smallest eigenvalue: one slightly negative eigenvalue
    lmin = 8.0_wp * sin(acos(-1.0_wp) / 26.0_wp)**2
    call laplace2d(12, -1.05_wp * lmin, M)
    do o = 1, 3
      call ch%factor(M%n, M%colptr, M%rowind, M%val, FACT_CHOLMOD, o, err)
      call error_parts(err, info, msg)
      call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, &
                  'lambda_min = -0.05 lambda_1: cholmod/'//trim(onames(o))//' ERR_NUMERICAL: '//trim(msg))
    end do
    call ch%factor(M%n, M%colptr, M%rowind, M%val, FACT_BANDED, ORD_NATURAL, err)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, &
                'lambda_min = -0.05 lambda_1: banded ERR_NUMERICAL: '//trim(msg))
    ! using the failed factorization is an error, not a crash
    u = 1.0_wp
    call ch%solve(u, err)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL, 'solve after a failed factorization returns ERR_NUMERICAL')
    call ch%flexibility([1, 2, 3], [1.0_wp, 1.0_wp, 1.0_wp], F, err)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL, 'flexibility after a failed factorization returns ERR_NUMERICAL')
    ! and the same object factorizes a good matrix afterwards
    call laplace2d(12, 1.0_wp, M)
    call ch%factor(M%n, M%colptr, M%rowind, M%val, FACT_CHOLMOD, ORD_AMD, err)
    call error_parts(err, info, msg)
    u = 1.0_wp
    call ch%solve(u, err)
    call error_parts(err, info, msg)
    call report(info == 0 .and. scaled_residual(M, u, [(1.0_wp, j = 1, 144)]) <= RES_TOL, &
                'the same chol_t is reusable after a failure')
    call ch%free()
  end subroutine check_not_posdef

  !> Invalid arguments give ERR_NUMERICAL with a message.
  subroutine check_bad_input()
    type(csc_t) :: M
    type(chol_t) :: ch
    integer :: info, tmp
    type(error_t) :: err
    character(len=256) :: msg
    call laplace2d(6, 1.0_wp, M)
    call ch%factor(M%n, M%colptr, M%rowind, M%val, FACT_CHOLMOD, ORD_METIS, err, last=[3, 5, 3])
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, 'repeated interface DOF: ERR_NUMERICAL: '//trim(msg))
    call ch%factor(M%n, M%colptr, M%rowind, M%val, FACT_CHOLMOD, ORD_METIS, err, last=[0])
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, 'interface DOF 0: ERR_NUMERICAL: '//trim(msg))
    tmp = M%rowind(1)
    M%rowind(1) = M%rowind(2)
    M%rowind(2) = tmp
    call ch%factor(M%n, M%colptr, M%rowind, M%val, FACT_BANDED, ORD_METIS, err)
    call error_parts(err, info, msg)
    call report(info == ERR_NUMERICAL .and. len_trim(msg) > 0, 'unsorted row indices: ERR_NUMERICAL: '//trim(msg))
    call ch%free()
  end subroutine check_bad_input

  !> F = B (K^-1)_GG B' for sparse rows B from the trailing block (chol_row_flexibility)
  !! against the dense inverse: 300 rows in random order (three panels), 1-6 entries each on
  !! 200 interface DOFs, one empty row; bitwise the same whether its panel tasks run on one
  !! thread or on a team of two; not taken (used false) for a banded factor.
  subroutine check_row_flexibility()
    type(csc_t) :: M
    type(chol_t) :: ch
    type(error_t) :: err
    integer, parameter :: K = 40, MI = 200, MR = 300
    integer, allocatable :: g(:), bptr(:), bpos(:), pick(:)
    real(wp), allocatable :: bval(:), D(:, :), X(:, :), B(:, :), Fr(:, :), F1(:, :), F2(:, :), u1(:), u2(:)
    real(wp) :: r, anorm, rcond, tol
    type(error_t) :: err2
    real(wp), allocatable :: work(:)
    integer, allocatable :: iwork(:)
    integer :: i, j, e, ne, nr, info, n
    logical :: used, used2
    character(len=256) :: msg
    call laplace2d(K, 0.01_wp, M)
    n = M%n
    g = random_subset(n, MI)
    allocate (bptr(MR + 1), bpos(6*MR), bval(6*MR), B(MR, MI))
    B = 0.0_wp
    ne = 0
    bptr(1) = 1
    do i = 1, MR
      call random_number(r)
      nr = 1 + int(6.0_wp*r)
      if (i == MR/2) nr = 0
      pick = random_subset(MI, nr)
      do e = 1, nr
        ne = ne + 1
        bpos(ne) = pick(e)
        call random_number(r)
        bval(ne) = r - 0.5_wp
        B(i, pick(e)) = B(i, pick(e)) + bval(ne)
      end do
      bptr(i + 1) = ne + 1
    end do
    ! dense reference
    call to_dense(M, D)
    anorm = maxval(sum(abs(D), dim=1))
    call dpotrf('L', n, D, n, info)
    allocate (work(3*n), iwork(n))
    call dpocon('L', n, D, n, anorm, rcond, work, iwork, info)
    call dpotri('L', n, D, n, info)
    allocate (X(MI, MI))
    do j = 1, MI
      do i = 1, MI
        X(i, j) = D(max(g(i), g(j)), min(g(i), g(j)))
      end do
    end do
    Fr = matmul(B, matmul(X, transpose(B)))
    tol = max(1.0e-12_wp, 100.0_wp*eps/rcond)
    allocate (F1(MR, MR), F2(MR, MR))
    call ch%factor(n, M%colptr, M%rowind, M%val, FACT_CHOLMOD, ORD_METIS, err, last=g)
    call error_parts(err, info, msg)
    call report(info == 0 .and. ch%interface_last_ok, 'row flexibility: CHOLMOD factor, interface last '//trim(msg))
    call ch%row_flexibility(g, bptr, bpos(1:ne), bval(1:ne), F1, err, used)
    call error_parts(err, info, msg)
    call report(info == 0 .and. used, 'row flexibility: formed from the trailing block '//trim(msg))
    call report_le(rel_diff2(F1, Fr), tol, 'row flexibility: B (K^-1)_GG B'' vs the dense inverse')
    call report(all(F1 == transpose(F1)), 'row flexibility: symmetric to the last bit')
    call report(all(F1(MR/2, :) == 0.0_wp), 'row flexibility: a row on no DOF gives a zero row')
    !$omp parallel num_threads(2) default(shared)
    !$omp single
    call ch%row_flexibility(g, bptr, bpos(1:ne), bval(1:ne), F2, err, used2)
    !$omp end single
    !$omp end parallel
    call report(used2 .and. all(F2 == F1), 'row flexibility: its panel tasks on two threads give the same bits')
    ! a solve of the same factor as a task beside it (what condense does): the same bits, both
    allocate (u1(n))
    u1 = [(cos(0.3_wp*i), i = 1, n)]
    u2 = u1
    call ch%solve(u1, err)
    call report(ch%holds_block(g) .and. .not. ch%holds_block([g, pack([(i, i = 1, n)], [(all(g /= i), i = 1, n)])]), &
                'row flexibility: the block holds the interface DOFs, not one DOF more')
    F2 = 0.0_wp
    !$omp parallel num_threads(2) default(shared)
    !$omp single
    !$omp task default(shared)
    call ch%solve(u2, err2)
    !$omp end task
    call ch%row_flexibility(g, bptr, bpos(1:ne), bval(1:ne), F2, err, used2)
    !$omp taskwait
    !$omp end single
    !$omp end parallel
    call report(used2 .and. all(F2 == F1) .and. all(u2 == u1) .and. .not. err2%failed(), &
                'row flexibility: a solve beside it on another thread, both the same bits')
    call ch%free()
    call ch%factor(n, M%colptr, M%rowind, M%val, FACT_BANDED, ORD_NATURAL, err)
    call ch%row_flexibility(g, bptr, bpos(1:ne), bval(1:ne), F2, err, used)
    call report(.not. used .and. .not. err%failed() .and. .not. ch%holds_block(g), &
                'row flexibility: a banded factor leaves it to the caller')
    call ch%free()
  end subroutine check_row_flexibility

  !> Two factorizations + flexibilities + solves inside `omp parallel sections`
  !! equal the same computed sequentially.
  subroutine check_concurrent(ord)
    integer, intent(in) :: ord
    type(csc_t) :: M1, M2
    type(chol_t) :: c1, c2
    integer, allocatable :: g1(:), g2(:)
    real(wp), allocatable :: F1(:, :), F2(:, :), P1(:, :), P2(:, :), u1(:), u2(:), v1(:), v2(:)
    real(wp), allocatable :: s1(:), s2(:)
    integer :: i1, i2, j1, j2, i
    character(len=256) :: m1s, m2s, tmsg
    character(len=16) :: oname
    real(wp) :: d
    oname = merge('metis', 'amd  ', ord == ORD_METIS)
    call lattice2d(40, 30, M1)
    call laplace2d(70, 0.5_wp, M2)
    g1 = [(2 * i, i = 1, 40)]
    g2 = [(70 * 69 + i, i = 1, 70)]
    s1 = [(merge(1.0_wp, -1.0_wp, mod(i, 2) == 0), i = 1, size(g1))]
    s2 = [(1.0_wp, i = 1, size(g2))]
    allocate (F1(size(g1), size(g1)), F2(size(g2), size(g2)), P1(size(g1), size(g1)), P2(size(g2), size(g2)))
    allocate (u1(M1%n), u2(M2%n), v1(M1%n), v2(M2%n))
    ! sequential reference
    call conc_work(ord, c1, M1, g1, s1, P1, v1, i1, m1s)
    call conc_work(ord, c2, M2, g2, s2, P2, v2, i2, m2s)
    call report(i1 == 0 .and. i2 == 0, 'sequential reference runs ('//trim(oname)//')')
    ! concurrent
    !$omp parallel sections default(shared)
    !$omp section
    call conc_work(ord, c1, M1, g1, s1, F1, u1, j1, m1s)
    !$omp section
    call conc_work(ord, c2, M2, g2, s2, F2, u2, j2, m2s)
    !$omp end parallel sections
    d = max(rel_diff2(F1, P1), rel_diff2(F2, P2), rel_diff(u1, v1), rel_diff(u2, v2))
    write (tmsg, '(a)') 'two chol_t in omp parallel sections = sequential ('//trim(oname)//')'
    call report(j1 == 0 .and. j2 == 0 .and. d <= 4.0_wp * eps, trim(tmsg), d, 4.0_wp * eps)
    call c1%free()
    call c2%free()
  end subroutine check_concurrent

  !> Factor, flexibility and one solve for check_concurrent.
  subroutine conc_work(ord, c, M, g, s, F, u, info, msg)
      integer, intent(in) :: ord
      type(chol_t), intent(inout) :: c
      type(csc_t), intent(in) :: M
      integer, intent(in) :: g(:)
      real(wp), intent(in) :: s(:)
      real(wp), intent(out) :: F(:, :)
      real(wp), intent(out), contiguous :: u(:)
      integer, intent(out) :: info
      type(error_t) :: err
      character(len=*), intent(out) :: msg
      call c%factor(M%n, M%colptr, M%rowind, M%val, FACT_CHOLMOD, ord, err, last=g)
      call error_parts(err, info, msg)
      if (info /= 0) return
      call c%flexibility(g, s, F, err)
      call error_parts(err, info, msg)
      if (info /= 0) return
      u = 1.0_wp
      call c%solve(u, err)
      call error_parts(err, info, msg)
  end subroutine conc_work

  !> A lattice whose last supernode (its top separator and an interface of 2 x 220 DOFs
  !! ordered last) is large enough for the factorization's dense kernels to run as tiles
  !! (blas_tiles.c): factorized and solved by one thread of a team of 1, 2, 3, 4 and 8
  !! threads (the others take the tiles at the team's barrier); the tiles ran, the solution is
  !! accurate and the same to the last bit for every team. Then a negative pivot in the last
  !! tile of the tiled dpotrf is reported at its own column (the tile's offset added).
  subroutine check_tiles()
    type(csc_t) :: M
    type(chol_t) :: ch
    integer, allocatable :: g(:)
    real(wp), allocatable :: f(:), u(:), u1(:)
    integer(kind=8) :: tiles1, tiles
    integer :: info, i, t, nt, team, p
    type(error_t) :: err
    character(len=256) :: msg
    character(len=8) :: tname
    integer, parameter :: teams(5) = [1, 2, 3, 4, 8]
    call lattice2d(220, 160, M)
    g = [(2 * i - 1, i = 1, 220), (2 * i, i = 1, 220)]
    allocate (f(M%n), u(M%n))
    f = [(sin(0.37_wp * i), i = 1, M%n)]
    tiles1 = -1
    do t = 1, size(teams)
      nt = teams(t)
      write (tname, '(i0)') nt
      team = 0
      ! as the program does (run_phases choose_threads): no region below the team's is active
      call omp_set_max_active_levels(merge(0, 1, nt == 1))
      !$omp parallel num_threads(nt) default(shared)
      !$omp single
      team = omp_get_num_threads()
      call ch%factor(M%n, M%colptr, M%rowind, M%val, FACT_CHOLMOD, ORD_METIS, err, last=g)
      call error_parts(err, info, msg)
      if (info == 0) then
        u = f
        call ch%solve(u, err)
        call error_parts(err, info, msg)
      end if
      !$omp end single
      !$omp end parallel
      tiles = ch%tiles
      write (output_unit, '(a)') '      team of '//trim(tname)//': '//ch%summary()
      if (t == 1) then
        call report(info == 0 .and. tiles > 0, 'tiled factorization ran tiles (team of 1): '//trim(msg))
        call report_le(scaled_residual(M, u, f), RES_TOL, 'tiled factorization: scaled residual (team of 1)')
        u1 = u
        tiles1 = tiles
      else
        call report(info == 0 .and. team == nt .and. tiles == tiles1 .and. all(u == u1), &
                    'team of '//trim(tname)//': the same tiles and the same solution to the last bit')
      end if
    end do
    ! a negative pivot on the last DOF (ordered last: in the last tile of the last supernode)
    do p = M%colptr(g(size(g))) + 1, M%colptr(g(size(g)) + 1)
      if (M%rowind(p) + 1 == g(size(g))) M%val(p) = -M%val(p)
    end do
    call omp_set_max_active_levels(1)
    !$omp parallel num_threads(2) default(shared)
    !$omp single
    call ch%factor(M%n, M%colptr, M%rowind, M%val, FACT_CHOLMOD, ORD_METIS, err, last=g)
    !$omp end single
    !$omp end parallel
    call error_parts(err, info, msg)
    write (tname, '(i0)') M%n
    call report(info == ERR_NUMERICAL .and. index(msg, 'column '//trim(tname)//' of '//trim(tname)) > 0, &
                'tiled dpotrf: a negative last pivot is reported at its column: '//trim(msg))
    call ch%free()
  end subroutine check_tiles

  !> dpotrf_tiles, a dense Cholesky factor as tiles outside a factorization (the rank test of
  !! a flexibility, the Newton method's free block): an SPD matrix of order 700 (three tile
  !! columns) factorized by one thread of a team of 1, 2 and 4 gives the same bits every
  !! time, L L' = A to rounding and L within rounding of LAPACK's dpotrf; a matrix whose
  !! leading minor of order 600 is not positive definite reports info = 600, as dpotrf does;
  !! an upper factor, or one of two tiles or less, is LAPACK's own to the last bit.
  subroutine check_potrf_tiles()
    integer, parameter :: N = 700
    real(wp), allocatable :: a(:, :), l(:, :), l1(:, :), lref(:, :), r(:, :)
    integer :: t, info, info1, i, j
    integer, parameter :: teams(3) = [1, 2, 4]
    character(len=8) :: tname
    allocate (a(N, N))
    call random_number(a)
    a = matmul(transpose(a), a)/real(N, wp)
    do i = 1, N
      a(i, i) = a(i, i) + 1.0_wp
    end do
    lref = a
    call dpotrf('L', N, lref, N, info)
    do t = 1, size(teams)
      write (tname, '(i0)') teams(t)
      l = a
      call omp_set_max_active_levels(merge(0, 1, teams(t) == 1))
      !$omp parallel num_threads(teams(t)) default(shared)
      !$omp single
      call dpotrf_tiles('L', N, l, N, info1)
      !$omp end single
      !$omp end parallel
      do j = 1, N
        l(1:j - 1, j) = 0.0_wp
      end do
      if (t == 1) then
        l1 = l
        r = matmul(l, transpose(l)) - a
        call report(info1 == 0 .and. info == 0, 'dpotrf_tiles: an SPD matrix of order 700 factorized')
        call report_le(maxval(abs(r))/maxval(abs(a)), 100.0_wp*eps, 'dpotrf_tiles: |L L'' - A| / |A|')
        do j = 1, N
          lref(1:j - 1, j) = 0.0_wp
        end do
        call report_le(maxval(abs(l - lref))/maxval(abs(lref)), 100.0_wp*eps, 'dpotrf_tiles: L against LAPACK''s dpotrf')
      else
        call report(info1 == 0 .and. all(l == l1), 'dpotrf_tiles: a team of '//trim(tname)//' gives the same bits')
      end if
    end do
    call omp_set_max_active_levels(1)
    ! a minor that is not positive definite: info names its order
    l = a
    l(600, 600) = -1.0_wp
    lref = l
    call dpotrf_tiles('L', N, l, N, info1)
    call dpotrf('L', N, lref, N, info)
    call report(info1 == 600 .and. info == 600, 'dpotrf_tiles: a leading minor of order 600 not positive definite')
    ! upper, and small: LAPACK's own
    l = a
    lref = a
    call dpotrf_tiles('U', N, l, N, info1)
    call dpotrf('U', N, lref, N, info)
    call report(info1 == 0 .and. all(l == lref), 'dpotrf_tiles: an upper factor is dpotrf''s, bit for bit')
    l = a(1:500, 1:500)
    lref = l
    call dpotrf_tiles('L', 500, l, 500, info1)
    call dpotrf('L', 500, lref, 500, info)
    call report(info1 == 0 .and. all(l == lref), 'dpotrf_tiles: order 500 (two tiles) is dpotrf''s, bit for bit')
  end subroutine check_potrf_tiles

  !> A larger lattice (200 x 200 cells, ~80k DOFs, 200 interface DOFs): print timings.
  subroutine timing_run()
    type(csc_t) :: M
    type(chol_t) :: ch
    integer, allocatable :: g(:)
    real(wp), allocatable :: Fb(:, :), Fs(:, :), s(:), u(:), f(:)
    integer :: info, o, i, nc
    type(error_t) :: err
    real(wp) :: t0, tb, ts
    logical :: used
    character(len=256) :: msg
    character(len=*), parameter :: onames(3) = [character(len=7) :: 'metis', 'amd', 'natural']
    nc = 200
    t0 = wtime()
    call lattice2d(nc, nc, M)
    write (output_unit, '(a,i0,a,i0,a,i0,a,f0.3,a)') '      timing problem: lattice ', nc, 'x', nc, ', n = ', M%n, &
      ' (assembled in ', wtime() - t0, ' s)'
    g = [(2 * i, i = 1, nc)]
    s = [(1.0_wp, i = 1, nc)]
    allocate (Fb(nc, nc), Fs(nc, nc), f(M%n))
    call random_number(f)
    do o = 1, 2
      call ch%factor(M%n, M%colptr, M%rowind, M%val, FACT_CHOLMOD, o, err, last=g)
      call error_parts(err, info, msg)
      call report(info == 0 .and. ch%interface_last_ok, &
                  'timing lattice cholmod/'//trim(onames(o))//': factor ok, interface last')
      if (info /= 0) cycle
      write (output_unit, '(a)') '      '//ch%summary()
      t0 = wtime()
      call ch%flexibility(g, s, Fb, err, used_block=used)
      call error_parts(err, info, msg)
      tb = wtime() - t0
      t0 = wtime()
      call ch%flexibility(g, s, Fs, err, use_solves=.true.)
      call error_parts(err, info, msg)
      ts = wtime() - t0
      write (output_unit, '(a,f0.4,a,f0.4,a)') '      flexibility (m = 200): trailing block + dpotri ', tb, &
        ' s, blocked solves ', ts, ' s'
      call report_le(rel_diff2(Fb, Fs), 1.0e-10_wp, 'timing lattice cholmod/'//trim(onames(o))// &
                     ': F (trailing block) vs F (solves)')
      u = f
      call ch%solve(u, err)
      call error_parts(err, info, msg)
      call report_le(scaled_residual(M, u, f), RES_TOL, 'timing lattice cholmod/'//trim(onames(o))// &
                     ': scaled residual')
    end do
    call ch%free()
  end subroutine timing_run

end program test_cholesky
