!> The numerical rank of a body's flexibility F_a = B X B' (condense `flex_from_x`): the
!! rank the pivoted Cholesky factor (LAPACK dpstrf, pivots below 1e-10 max diag) finds on the
!! same F_a, whichever way flex_from_x decides it, and the kernel basis of a singular F_a.
!! Rows of two entries each (not a selection of DOFs), X symmetric positive definite:
!! full rank; two equal rows (rank m - 1); a pair of rows that differ by 1e-4 (F_a's smallest
!! eigenvalue near 1e-8 of its largest: full rank for the pivoted factor, but too close
!! for a condition estimate to tell) and 1e-7 (near 1e-14: rank m - 1); a row on no free
!! DOF (F_a's row and column zero). The near-kernel of a singular F_a: a row on no free DOF
!! and two rows 1e-4 apart (an eigenvalue near 1e-8 of the largest, below NEAR_KERNEL = 1e-6):
!! the kernel basis takes that direction too (rank m - 2, one more than the pivoted factor's
!! m - 1), |F z| <= 1e-6 |F| on it; the same pair without the empty row keeps full rank and no
!! kernel (a nonsingular F_a gets none, however small its smallest eigenvalue).
!! Rows of many entries (a solid master's: F_a by Y = X B' and B Y): F_a = B X B' formed
!! densely, to 1e-13. Rows over at most half as many DOFs (a coarse master: the rank from
!! the QR of B and a k x k eigenproblem): rank(B) (B of full column rank, and with one
!! column a combination of two others), the range basis orthonormal and F_a = Q Q' F_a Q Q',
!! no kernel basis; the proximal term built on that range basis (robin_operators
!! `range_proximal`) is Z (Z' F_o Z + floor I) Z' with Z the kernel from a dense symmetric
!! eigensolver (LAPACK dsyev), to 1e-12.
program test_flex_rank
  use kinds, only: wp
  use condense, only: body_condensed_t, flex_from_x, smallest_eigenvectors, SUBSPACE_MIN
  use robin_operators, only: range_proximal
  use lapack, only: dpstrf, dsyev, dsyevd
  use testing, only: report, report_le, test_summary, identity, set_seed, urand
  implicit none (type, external)
  integer, parameter :: M = 60

  call case('full rank', 0.0_wp, .false., .false., M)
  call case('two equal rows', 0.0_wp, .true., .false., M - 1)
  call case('two rows 1e-4 apart', 1.0e-4_wp, .true., .false., M)
  call case('two rows 1e-7 apart', 1.0e-7_wp, .true., .false., M - 1)
  call case('a row on no free DOF', 0.0_wp, .false., .true., M - 1)
  call case('a row on no free DOF, two rows 1e-4 apart', 1.0e-4_wp, .true., .true., M - 2, near=1)
  call dense_rows(30, 20)
  call coarse_rows(40, 12, .false.)
  call coarse_rows(40, 12, .true.)
  call large_kernel(1600, 30)
  call tall_rows(1600, 1590)
  call test_summary()

contains

  subroutine case(what, eps, twin, empty, expected, near)
    character(len=*), intent(in) :: what
    integer, intent(in) :: expected     !< the rank by construction
    integer, intent(in), optional :: near   !< near-kernel directions pinned besides the kernel
    real(wp), intent(in) :: eps         !< the twin row's second coefficient differs by eps
    logical, intent(in) :: twin         !< rows 10 and 11 on the same DOFs
    logical, intent(in) :: empty        !< row 20 has zero coefficients
    type(body_condensed_t) :: cbody
    real(wp) :: x(M, M), g(M, M), f(M, M), work(2*M), r(M)
    integer :: i, e, piv(M), rank_ref, info
    ! X = G G' + I, G with entries in [-1/2, 1/2] from a fixed seed
    call random_seed(put=[(7919*i, i=1, 64)])
    call random_number(g)
    g = g - 0.5_wp
    x = matmul(g, transpose(g))
    do i = 1, M
      x(i, i) = x(i, i) + 1.0_wp
    end do
    cbody%m = M
    allocate (cbody%idx(M), cbody%bptr(M + 1), cbody%bpos(2*M), cbody%bval(2*M))
    cbody%idx = [(i, i=1, M)]
    e = 0
    do i = 1, M
      cbody%bptr(i) = e + 1
      cbody%bpos(e + 1) = i
      cbody%bpos(e + 2) = modulo(i, M) + 1
      cbody%bval(e + 1) = 1.0_wp
      cbody%bval(e + 2) = 0.25_wp
      e = e + 2
    end do
    cbody%bptr(M + 1) = e + 1
    if (twin) then   ! row 11 on row 10's DOFs
      cbody%bpos(21:22) = cbody%bpos(19:20)
      cbody%bval(22) = cbody%bval(20) + eps
    end if
    if (empty) cbody%bval(39:40) = 0.0_wp
    call flex_from_x(cbody, x)
    f = cbody%flex
    call dpstrf('L', M, f, M, piv, rank_ref, 1.0e-10_wp*maxval([(cbody%flex(i, i), i=1, M)]), work, info)
    if (present(near)) rank_ref = rank_ref - near
    call report(info >= 0 .and. cbody%rank == rank_ref, what//': the rank of the pivoted Cholesky factor'// &
                trim(merge(' less the near-kernel', '                     ', present(near))), &
                real(cbody%rank, wp), real(rank_ref, wp))
    call report(cbody%rank == expected, what//': the expected rank', real(cbody%rank, wp), real(expected, wp))
    if (cbody%rank < M) then
      call report(allocated(cbody%kern) .and. cbody%prox > 0.0_wp, what//': a kernel basis and a proximal weight')
      if (allocated(cbody%kern)) then
        r = matmul(cbody%flex, cbody%kern(:, 1))
        call report_le(norm2(r)/maxval(abs(cbody%flex)), 1.0e-10_wp, what//': F_a z = 0 on the kernel')
        if (present(near)) then
          r = matmul(cbody%flex, cbody%kern(:, size(cbody%kern, 2)))
          call report_le(norm2(r)/maxval(abs(cbody%flex)), 1.0e-6_wp, what//': |F_a z| <= 1e-6 |F_a| on the near-kernel')
          call report(size(cbody%kern, 2) == M - expected, what//': the basis spans kernel and near-kernel')
        end if
        call report_le(abs(norm2(cbody%kern(:, 1)) - 1.0_wp), 1.0e-12_wp, what//': |z| = 1')
      end if
    else
      call report(.not. allocated(cbody%kern) .and. cbody%prox == 0.0_wp, what//': no kernel, no proximal weight')
    end if
  end subroutine case

  !> m rows over all k DOFs (nnz = m k > 4 (k + m)): F_a against B X B' formed densely.
  subroutine dense_rows(m, k)
    integer, intent(in) :: m, k
    type(body_condensed_t) :: cbody
    real(wp) :: x(k, k), b(m, k), ref(m, m)
    call fill(m, k, .false., cbody, x, b)
    call flex_from_x(cbody, x)
    ref = matmul(b, matmul(x, transpose(b)))
    call report_le(maxval(abs(cbody%flex - ref))/maxval(abs(ref)), 1.0e-13_wp, &
                   'rows of many entries: F_a = B X B'' (formed densely)')
    call report(cbody%rank == min(m, k) .or. (k < m .and. cbody%rank == k), 'rows of many entries: rank min(m, k)', &
                real(cbody%rank, wp), real(min(m, k), wp))
  end subroutine dense_rows

  !> m rows over k <= m/2 DOFs: rank(B), the range basis, and the proximal term on it.
  subroutine coarse_rows(m, k, dependent)
    integer, intent(in) :: m, k
    logical, intent(in) :: dependent     !< B's last column the sum of its first two
    type(body_condensed_t) :: cbody
    real(wp) :: x(k, k), b(m, k), qq(m, m), fo(m, m), p(m, m), pref(m, m), z(m, m), ev(m), work(4*m*m)
    real(wp) :: floor
    integer :: i, r, info, nk
    character(len=40) :: what
    what = merge('coarse rows, a dependent column', 'coarse rows                    ', dependent)
    call fill(m, k, dependent, cbody, x, b)
    call flex_from_x(cbody, x)
    r = merge(k - 1, k, dependent)
    call report(cbody%rank == r, trim(what)//': the rank of B', real(cbody%rank, wp), real(r, wp))
    call report(allocated(cbody%rng) .and. .not. allocated(cbody%kern) .and. cbody%prox > 0.0_wp, &
                trim(what)//': a range basis, no kernel basis, a proximal weight')
    if (.not. allocated(cbody%rng)) return
    call report(size(cbody%rng, 2) == r, trim(what)//': the range basis has rank columns')
    qq = matmul(cbody%rng, transpose(cbody%rng))
    call report_le(maxval(abs(matmul(transpose(cbody%rng), cbody%rng) - identity(r))), 1.0e-12_wp, &
                   trim(what)//': Q''Q = I')
    call report_le(maxval(abs(matmul(qq, matmul(cbody%flex, qq)) - cbody%flex))/maxval(abs(cbody%flex)), 1.0e-12_wp, &
                   trim(what)//': F_a = QQ'' F_a QQ''')
    ! the partner's flexibility: any SPD matrix; the reference kernel: the eigenvectors of
    ! F_a's m - r smallest eigenvalues (dsyev, all of them)
    call random_number(fo)
    fo = matmul(fo, transpose(fo)) + identity(m)
    z = cbody%flex
    call dsyev('V', 'L', m, z, m, ev, work, size(work), info)
    nk = m - r
    floor = 1.0e-10_wp*maxval([(fo(i, i), i=1, m)])
    pref = matmul(z(:, 1:nk), matmul(matmul(transpose(z(:, 1:nk)), matmul(fo, z(:, 1:nk))) + floor*identity(nk), &
                                     transpose(z(:, 1:nk))))
    call range_proximal(cbody%rng, fo, p)
    call report(info == 0, trim(what)//': dsyev of the reference')
    call report_le(maxval(abs(p - pref))/maxval(abs(pref)), 1.0e-12_wp, &
                   trim(what)//': range_proximal = Z (Z''F_o Z + floor I) Z''')
  end subroutine coarse_rows

  !> Rows over k DOFs, each on every DOF (coefficients in [-1/2, 1/2] plus 1 on DOF i mod k),
  !! X = G G' + I; b the dense B.
  subroutine fill(m, k, dependent, cbody, x, b)
    integer, intent(in) :: m, k
    logical, intent(in) :: dependent
    type(body_condensed_t), intent(out) :: cbody
    real(wp), intent(out) :: x(k, k), b(m, k)
    real(wp) :: g(k, k)
    integer :: i, j, e
    call random_seed(put=[(104729*i, i=1, 64)])
    call random_number(g)
    g = g - 0.5_wp
    x = matmul(g, transpose(g)) + identity(k)
    call random_number(b)
    b = b - 0.5_wp
    do i = 1, m
      b(i, modulo(i - 1, k) + 1) = b(i, modulo(i - 1, k) + 1) + 1.0_wp
    end do
    if (dependent) b(:, k) = b(:, 1) + b(:, 2)
    cbody%m = m
    allocate (cbody%idx(k), cbody%bptr(m + 1), cbody%bpos(m*k), cbody%bval(m*k))
    cbody%idx = [(i, i=1, k)]
    e = 0
    do i = 1, m
      cbody%bptr(i) = e + 1
      do j = 1, k
        e = e + 1
        cbody%bpos(e) = j
        cbody%bval(e) = b(i, j)
      end do
    end do
    cbody%bptr(m + 1) = e + 1
  end subroutine fill


  !> An F_a of order m >= SUBSPACE_MIN gets its kernel and near-kernel basis by subspace
  !! iteration (condense `smallest_eigenvectors`): F = Q D Q' with Q three Householder
  !! reflections and D 10 zeros, 20 eigenvalues from 1e-12 to 1e-7 and the rest between
  !! 1e-5 and 1 (a gap of 100 after the 30th): the 30 vectors found, orthonormal (1e-12),
  !! spanning Q's first 30 columns (|Z - Q30 Q30' Z| <= 1e-6, the residual over the gap).
  subroutine large_kernel(m, k)
    integer, intent(in) :: m, k
    real(wp), allocatable :: f(:, :), d(:), v(:, :), z(:, :), q(:, :), w(:), c(:, :)
    real(wp) :: vv, vav
    integer :: i, j, r
    logical :: converged
    call set_seed(20261129)
    allocate (f(m, m), d(m), v(m, 3), q(m, k), w(m))
    d(1:10) = 0.0_wp
    do i = 11, 30
      d(i) = 10.0_wp**(-12.0_wp + 5.0_wp*real(i - 11, wp)/19.0_wp)
    end do
    do i = 31, m
      d(i) = 10.0_wp**(-5.0_wp + 5.0_wp*urand(0.0_wp, 1.0_wp))
    end do
    d(m) = 1.0_wp
    do r = 1, 3
      do i = 1, m
        v(i, r) = urand(-1.0_wp, 1.0_wp)
      end do
    end do
    ! F = H3 H2 H1 D H1 H2 H3, Q = H3 H2 H1 (H = I - 2 v v'/v'v)
    f = 0.0_wp
    q = 0.0_wp
    do i = 1, m
      f(i, i) = d(i)
    end do
    do i = 1, k
      q(i, i) = 1.0_wp
    end do
    do r = 1, 3
      vv = dot_product(v(:, r), v(:, r))
      w = matmul(f, v(:, r))
      vav = dot_product(v(:, r), w)
      do j = 1, m
        f(:, j) = f(:, j) - (2.0_wp/vv)*(v(:, r)*w(j) + w*v(j, r)) + (4.0_wp*vav/vv**2)*v(:, r)*v(j, r)
      end do
      do j = 1, k
        q(:, j) = q(:, j) - (2.0_wp*dot_product(v(:, r), q(:, j))/vv)*v(:, r)
      end do
    end do
    f = 0.5_wp*(f + transpose(f))
    call report(m >= SUBSPACE_MIN, 'large F_a: order 1600 takes the subspace iteration')
    call smallest_eigenvectors(f, k, maxval([(f(i, i), i=1, m)]), z, converged)
    call report(converged, 'large F_a: the subspace iteration converged')
    if (.not. converged) return
    c = matmul(transpose(z), z)
    do i = 1, k
      c(i, i) = c(i, i) - 1.0_wp
    end do
    call report_le(maxval(abs(c)), 1.0e-12_wp, 'large F_a: the basis orthonormal')
    call report_le(norm2(z - matmul(q, matmul(transpose(q), z))), 1.0e-6_wp, &
                   'large F_a: the basis spans the 30 smallest eigenvectors')
  end subroutine large_kernel

  !> More rows than DOFs at order m >= SUBSPACE_MIN (a 3D frictional master): F_a = B B'
  !! (X = I), row i on DOFs mod(i - 1, k) + 1 (coefficient 1) and mod(7 i, k) + 1 (1/2),
  !! singular by its shape; flex_from_x decides its kernel without a factor: the rank is m
  !! minus the eigenvalues below NEAR_KERNEL = 1e-6 of the largest diagonal entry that a
  !! dense symmetric eigensolver (LAPACK dsyevd) counts on the same F_a, the kernel basis
  !! orthonormal and |F_a z| <= 1e-6 max diag on each vector.
  subroutine tall_rows(m, k)
    integer, intent(in) :: m, k
    type(body_condensed_t) :: cbody
    real(wp), allocatable :: x(:, :), f(:, :), ev(:), work(:), c(:, :)
    integer, allocatable :: iwork(:)
    integer :: i, info, nref
    real(wp) :: dmax
    allocate (x(k, k), source=0.0_wp)
    do i = 1, k
      x(i, i) = 1.0_wp
    end do
    cbody%m = m
    allocate (cbody%idx(k), cbody%bptr(m + 1), cbody%bpos(2*m), cbody%bval(2*m))
    cbody%idx = [(i, i=1, k)]
    do i = 1, m
      cbody%bptr(i) = 2*i - 1
      cbody%bpos(2*i - 1:2*i) = [modulo(i - 1, k) + 1, modulo(7*i, k) + 1]
      cbody%bval(2*i - 1:2*i) = [1.0_wp, 0.5_wp]
    end do
    cbody%bptr(m + 1) = 2*m + 1
    call flex_from_x(cbody, x)
    f = cbody%flex
    dmax = maxval([(f(i, i), i=1, m)])
    allocate (ev(m), work(1 + 6*m + 2*m*m), iwork(3 + 5*m))
    call dsyevd('N', 'L', m, f, m, ev, work, size(work), iwork, size(iwork), info)
    nref = count(ev <= 1.0e-6_wp*dmax)
    call report(info == 0 .and. nref >= m - k, 'more rows than DOFs, order 1600: the reference eigenvalues')
    call report(cbody%rank == m - nref, 'more rows than DOFs: the rank is m less the eigenvalues below 1e-6 max diag', &
                real(cbody%rank, wp), real(m - nref, wp))
    call report(allocated(cbody%kern) .and. cbody%prox > 0.0_wp, 'more rows than DOFs: a kernel basis, a proximal weight')
    if (.not. allocated(cbody%kern)) return
    call report(size(cbody%kern, 2) == nref, 'more rows than DOFs: the basis has m - rank vectors')
    c = matmul(transpose(cbody%kern), cbody%kern)
    do i = 1, size(c, 1)
      c(i, i) = c(i, i) - 1.0_wp
    end do
    call report_le(maxval(abs(c)), 1.0e-12_wp, 'more rows than DOFs: the basis orthonormal')
    call report_le(maxval(norm2(matmul(cbody%flex, cbody%kern), dim=1))/dmax, 1.0e-6_wp, &
                   'more rows than DOFs: |F_a z| <= 1e-6 max diag on the basis')
  end subroutine tall_rows

end program test_flex_rank
