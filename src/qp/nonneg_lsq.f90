!> Non-negative least squares, min |G x - e| over x >= 0, with G given by its columns (a
!! contact force's generator each, a few nonzeros in the rigid rows of the bodies it
!! touches). Two methods decide the same residual:
!! - Lawson and Hanson's active set method with a dense QR of the passive columns that is
!!   updated, not redone (exact and finite; about r^3 for r rows, since about r columns
!!   enter one by one and each update costs r^2);
!! - a primal-dual interior point method (Mehrotra's predictor and corrector) whose every
!!   step is one sparse Cholesky factor of I + G D G' (D diagonal, CHOLMOD): a number of
!!   steps that does not grow with the problem, each linear in it for the chains and
!!   stacks that groups of floating bodies form (G G' has a body's rows coupled to those
!!   of the bodies it touches).
!! NNLS_AUTO takes the first up to NNLS_DENSE_MAX rows, the second beyond.
module nonneg_lsq
  use kinds, only: wp, ip
  use cholesky, only: chol_t, FACT_CHOLMOD, ORD_AMD
  use errors, only: error_t
  use sorting, only: sort_ints
  implicit none (type, external)
  private

  public :: nnls

  integer, parameter, public :: NNLS_AUTO = 0         !< by size (NNLS_DENSE_MAX)
  integer, parameter, public :: NNLS_ACTIVE_SET = 1   !< Lawson and Hanson, dense QR updates
  integer, parameter, public :: NNLS_INTERIOR = 2     !< interior point, sparse Cholesky per step

  !> NNLS_AUTO: the active set method up to this many rows (its r^3 is 0.02 s at 256)
  integer, parameter, public :: NNLS_DENSE_MAX = 256

  !> Interior point: the scaled problem's bound on x (columns of unit norm, |e| = 1). A set
  !! of columns that sums to zero (a body squeezed between two others: opposite normals)
  !! leaves x unbounded along it, and the barrier would drive the iterates there; a bound
  !! far beyond any force that balances |e| keeps them finite and changes no residual.
  real(wp), parameter :: XMAX = 1.0e8_wp
  !> Interior point: a residual below this (relative to |e|) is taken as zero (x >= 0 holds
  !! at every step, so |G x - e| is a true upper bound of the minimum)
  real(wp), parameter :: ZERO_RES = 1.0e-11_wp
  !> Interior point: when complementarity reaches rounding, a residual below this (relative
  !! to |e|) is returned as it is (a true upper bound of the minimum, ten times below the
  !! 1e-8 at which every caller decides); above it the active set method decides
  real(wp), parameter :: SMALL_RES = 1.0e-9_wp
  integer, parameter :: MAX_STEPS = 200

  !> A matrix stored by columns (1-based: column j's rows row(ptr(j):ptr(j+1)-1)).
  type, public :: sparse_cols_t
    integer :: nrow = 0
    integer :: ncol = 0
    integer, allocatable :: ptr(:)
    integer, allocatable :: row(:)
    real(wp), allocatable :: val(:)
  contains
    procedure :: init => sc_init
    procedure :: push => sc_push
    procedure :: from_dense => sc_from_dense
    procedure :: from_triplets => sc_from_triplets
    procedure :: times => sc_times
    procedure :: ttimes => sc_ttimes
  end type sparse_cols_t

  !> B + G D G' for a sparse G, a diagonal D and a block-diagonal B (blocks of consecutive
  !! rows), as a sparse Cholesky factor: the pattern is built once (`build`), the values
  !! and the factor at each `factor`. The blocks are in the pattern whatever G's nonzeros.
  type, public :: gram_t
    integer :: n = 0                     !< order (G's rows)
    integer, allocatable :: bstart(:)    !< (nb + 1) block k: rows bstart(k)..bstart(k+1)-1
    integer(ip), allocatable :: cptr0(:), rind0(:)   !< full symmetric CSC, 0-based, rows sorted
    integer, allocatable :: pbase(:)     !< (ncol + 1) column j's products start at pos(pbase(j)+1)
    integer, allocatable :: pos(:)       !< place in val of column j's product of entries a, b
    integer, allocatable :: bpos(:)      !< place in val of each block entry (blocks in order, by columns)
    real(wp), allocatable :: val(:)
    type(chol_t) :: chol
    logical :: not_posdef = .false.      !< the last factor failed: B + G D G' is not positive definite
  contains
    procedure :: build => gram_build
    procedure :: factor => gram_factor
    procedure :: free => gram_free
  end type gram_t

contains

  !> An empty matrix of nrow rows (columns follow by push).
  subroutine sc_init(self, nrow, capacity)
    class(sparse_cols_t), intent(inout) :: self
    integer, intent(in) :: nrow
    integer, intent(in), optional :: capacity   !< nonzeros to reserve
    integer :: cap
    cap = 64
    if (present(capacity)) cap = max(capacity, 1)
    self%nrow = nrow
    self%ncol = 0
    if (allocated(self%ptr)) deallocate (self%ptr, self%row, self%val)
    allocate (self%ptr(1), self%row(cap), self%val(cap))
    self%ptr(1) = 1
  end subroutine sc_init

  !> Append a column: vals at rows (zeros dropped; a row may not repeat).
  subroutine sc_push(self, rows, vals)
    class(sparse_cols_t), intent(inout) :: self
    integer, intent(in) :: rows(:)
    real(wp), intent(in) :: vals(:)
    integer, allocatable :: ptr(:), row(:)
    real(wp), allocatable :: val(:)
    integer :: k, n
    n = self%ptr(self%ncol + 1) - 1
    if (n + size(rows) > size(self%row)) then
      allocate (row(max(2*size(self%row), n + size(rows))), val(max(2*size(self%row), n + size(rows))))
      row(1:n) = self%row(1:n)
      val(1:n) = self%val(1:n)
      call move_alloc(row, self%row)
      call move_alloc(val, self%val)
    end if
    do k = 1, size(rows)
      if (vals(k) == 0.0_wp) cycle
      n = n + 1
      self%row(n) = rows(k)
      self%val(n) = vals(k)
    end do
    if (self%ncol + 2 > size(self%ptr)) then
      allocate (ptr(2*size(self%ptr) + 1))
      ptr(1:self%ncol + 1) = self%ptr(1:self%ncol + 1)
      call move_alloc(ptr, self%ptr)
    end if
    self%ncol = self%ncol + 1
    self%ptr(self%ncol + 1) = n + 1
  end subroutine sc_push

  !> The nonzeros of a dense matrix.
  subroutine sc_from_dense(self, a)
    class(sparse_cols_t), intent(inout) :: self
    real(wp), intent(in) :: a(:, :)
    integer :: j, i
    call self%init(size(a, 1), max(1, count(a /= 0.0_wp)))
    do j = 1, size(a, 2)
      call self%push([(i, i=1, size(a, 1))], a(:, j))
    end do
  end subroutine sc_from_dense

  !> Entries (ti(k), tj(k), tv(k)) of a nrow x ncol matrix, each place at most once; a
  !! column's entries in the order given.
  subroutine sc_from_triplets(self, nrow, ncol, ti, tj, tv)
    class(sparse_cols_t), intent(inout) :: self
    integer, intent(in) :: nrow, ncol
    integer, intent(in) :: ti(:), tj(:)
    real(wp), intent(in) :: tv(:)
    integer, allocatable :: fill(:)
    integer :: k, j
    self%nrow = nrow
    self%ncol = ncol
    if (allocated(self%ptr)) deallocate (self%ptr, self%row, self%val)
    allocate (self%ptr(ncol + 1), self%row(max(1, size(ti))), self%val(max(1, size(ti))), fill(ncol))
    self%ptr = 0
    do k = 1, size(tj)
      self%ptr(tj(k) + 1) = self%ptr(tj(k) + 1) + 1
    end do
    self%ptr(1) = 1
    do j = 1, ncol
      self%ptr(j + 1) = self%ptr(j + 1) + self%ptr(j)
    end do
    fill = self%ptr(1:ncol)
    do k = 1, size(tj)
      self%row(fill(tj(k))) = ti(k)
      self%val(fill(tj(k))) = tv(k)
      fill(tj(k)) = fill(tj(k)) + 1
    end do
  end subroutine sc_from_triplets

  !> G x.
  function sc_times(self, x) result(y)
    class(sparse_cols_t), intent(in) :: self
    real(wp), intent(in) :: x(:)
    real(wp) :: y(self%nrow)
    integer :: j, l
    y = 0.0_wp
    do j = 1, self%ncol
      do l = self%ptr(j), self%ptr(j + 1) - 1
        y(self%row(l)) = y(self%row(l)) + self%val(l)*x(j)
      end do
    end do
  end function sc_times

  !> G' y.
  function sc_ttimes(self, y) result(x)
    class(sparse_cols_t), intent(in) :: self
    real(wp), intent(in) :: y(:)
    real(wp) :: x(self%ncol)
    integer :: j, l
    do j = 1, self%ncol
      x(j) = 0.0_wp
      do l = self%ptr(j), self%ptr(j + 1) - 1
        x(j) = x(j) + self%val(l)*y(self%row(l))
      end do
    end do
  end function sc_ttimes

  !> min |G x - e| over x >= 0; res: |G x - e| at the returned x. method: NNLS_AUTO
  !! (default: by G's rows; a caller whose rows are mostly bound rows chooses by its own
  !! count), NNLS_ACTIVE_SET or NNLS_INTERIOR. The interior point method falls back to the
  !! active set one when it has no certificate of its answer (module doc).
  subroutine nnls(g, e, x, res, method)
    type(sparse_cols_t), intent(in) :: g   !< (r, m)
    real(wp), intent(in) :: e(:)           !< (r)
    real(wp), intent(out) :: x(:)          !< (m)
    real(wp), intent(out) :: res
    integer, intent(in), optional :: method
    integer :: meth
    logical :: ok
    meth = NNLS_AUTO
    if (present(method)) meth = method
    if (meth == NNLS_AUTO) meth = merge(NNLS_ACTIVE_SET, NNLS_INTERIOR, g%nrow <= NNLS_DENSE_MAX)
    if (meth == NNLS_INTERIOR) then
      call interior_point(g, e, x, res, ok)
      if (ok) return
    end if
    call lawson_hanson(g, e, x, res)
  end subroutine nnls

  !> Lawson and Hanson's active set method (at most r columns are ever passive). The least
  !! squares problem of the passive columns is kept as a QR factorization that is updated,
  !! not redone, when a column enters (one Householder reflection, O(r^2)) or leaves
  !! (Givens rotations, O(r np)).
  subroutine lawson_hanson(g, e, x, res)
    type(sparse_cols_t), intent(in) :: g
    real(wp), intent(in) :: e(:)
    real(wp), intent(out) :: x(:)
    real(wp), intent(out) :: res
    real(wp), allocatable :: w(:), z(:), q(:, :), rr(:, :), v(:), qe(:), resv(:), rhs(:)
    logical, allocatable :: passive(:)
    integer, allocatable :: cols(:)     ! the passive columns, in the order of rr's columns
    integer :: r, m, j, np, it, inner, k, i
    real(wp) :: tol, alpha, t, rdiag_min, gmax

    r = g%nrow
    m = g%ncol
    allocate (w(m), z(m), passive(m), q(r, r), rr(r, min(r, m)), v(r), cols(min(r, m)), qe(r), rhs(r))
    gmax = 0.0_wp
    if (g%ptr(m + 1) > 1) gmax = maxval(abs(g%val(1:g%ptr(m + 1) - 1)))
    x = 0.0_wp
    passive = .false.
    np = 0
    q = 0.0_wp
    do i = 1, r
      q(i, i) = 1.0_wp
    end do
    rr = 0.0_wp
    tol = 1.0e-12_wp*max(gmax*norm2(e), tiny(1.0_wp))
    rdiag_min = 1.0e-13_wp*max(gmax, tiny(1.0_wp))
    do it = 1, 3*m + 10
      call gradient()
      j = 0
      t = tol
      do k = 1, m
        if (.not. passive(k) .and. w(k) > t) then
          t = w(k)
          j = k
        end if
      end do
      if (j == 0 .or. np >= min(r, m)) exit
      if (.not. append_column(j)) exit     ! in the span of the passive ones to rounding
      passive(j) = .true.
      do inner = 1, 3*m + 10
        call passive_solution()
        if (all(z(cols(1:np)) > 0.0_wp)) exit
        alpha = 1.0_wp
        do k = 1, np
          j = cols(k)
          if (z(j) <= 0.0_wp) alpha = min(alpha, x(j)/max(x(j) - z(j), tiny(1.0_wp)))
        end do
        x = x + alpha*(z - x)
        ! the passive columns at zero leave, the last first (positions stay valid)
        do k = np, 1, -1
          j = cols(k)
          if (x(j) <= 1.0e-14_wp*maxval(abs(x))) then
            passive(j) = .false.
            call delete_column(k)
          end if
        end do
        where (.not. passive) x = 0.0_wp
        if (np == 0) exit
      end do
      x = z
      where (.not. passive) x = 0.0_wp
    end do
    res = norm2(g%times(x) - e)

  contains

    !> w = g'(e - g x), by g's nonzeros (x is zero off the passive columns).
    subroutine gradient()
      integer :: c, l
      resv = e
      do c = 1, np
        do l = g%ptr(cols(c)), g%ptr(cols(c) + 1) - 1
          resv(g%row(l)) = resv(g%row(l)) - g%val(l)*x(cols(c))
        end do
      end do
      w = g%ttimes(resv)
    end subroutine gradient

    !> Column j of g as column np + 1 of the factorization: v = Q'g_j, a Householder
    !! reflection zeroes v(np+2:r), applied to Q's columns np+1..r. False (nothing
    !! changed) when the column has no part outside the passive columns' span.
    logical function append_column(jc) result(ok)
      integer, intent(in) :: jc
      real(wp) :: nrm, beta, v1
      real(wp), allocatable :: hv(:), qh(:)
      integer :: n0
      ok = .false.
      n0 = np + 1
      ! v = Q' g_j by the column's nonzeros
      v = 0.0_wp
      do k = g%ptr(jc), g%ptr(jc + 1) - 1
        v = v + g%val(k)*q(g%row(k), :)
      end do
      nrm = norm2(v(n0:r))
      if (.not. nrm > rdiag_min) return
      ! H = I - beta u u', u = v(n0:r) + sign(v(n0)) |v(n0:r)| e_1: H v(n0:r) = -sign nrm e_1
      allocate (hv(r - n0 + 1))
      hv = v(n0:r)
      v1 = sign(nrm, hv(1))
      hv(1) = hv(1) + v1
      beta = 1.0_wp/(v1*hv(1))
      ! Q(:, n0:r) <- Q(:, n0:r) H
      qh = matmul(q(:, n0:r), hv)
      do k = 1, size(hv)
        q(:, n0 + k - 1) = q(:, n0 + k - 1) - beta*qh*hv(k)
      end do
      rr(1:np, n0) = v(1:np)
      rr(n0, n0) = -v1
      rr(n0 + 1:, n0) = 0.0_wp
      ! (Q'e) of the new column (the earlier columns of Q are unchanged)
      qe(n0) = dot_product(q(:, n0), e)
      np = n0
      cols(np) = jc
      ok = .true.
    end function append_column

    !> Remove the passive column at position kc: shift the later columns left and restore
    !! the triangle by Givens rotations of rows kc..np-1 (applied to Q's columns as well).
    subroutine delete_column(kc)
      integer, intent(in) :: kc
      integer :: c, l
      real(wp) :: a, b, cs, sn, hyp, t1, t2
      do c = kc, np - 1
        rr(:, c) = rr(:, c + 1)
        cols(c) = cols(c + 1)
      end do
      rr(:, np) = 0.0_wp
      np = np - 1
      do c = kc, np
        a = rr(c, c)
        b = rr(c + 1, c)
        if (b == 0.0_wp) cycle
        hyp = hypot(a, b)
        cs = a/hyp
        sn = b/hyp
        do l = c, np
          t1 = rr(c, l)
          t2 = rr(c + 1, l)
          rr(c, l) = cs*t1 + sn*t2
          rr(c + 1, l) = -sn*t1 + cs*t2
        end do
        rr(c + 1, c) = 0.0_wp
        do l = 1, r
          t1 = q(l, c)
          t2 = q(l, c + 1)
          q(l, c) = cs*t1 + sn*t2
          q(l, c + 1) = -sn*t1 + cs*t2
        end do
        t1 = qe(c)
        t2 = qe(c + 1)
        qe(c) = cs*t1 + sn*t2
        qe(c + 1) = -sn*t1 + cs*t2
      end do
    end subroutine delete_column

    !> z on the passive columns: R z_P = (Q'e)(1:np) (kept up to date by append_column and
    !! delete_column), by back substitution over R's columns (contiguous); 0 elsewhere.
    subroutine passive_solution()
      integer :: a
      real(wp) :: zc
      z = 0.0_wp
      if (np == 0) return
      rhs(1:np) = qe(1:np)
      do a = np, 1, -1
        zc = rhs(a)/rr(a, a)
        z(cols(a)) = zc
        rhs(1:a - 1) = rhs(1:a - 1) - rr(1:a - 1, a)*zc
      end do
    end subroutine passive_solution

  end subroutine lawson_hanson

  !> The interior point method on the scaled problem (columns of unit norm, |e| = 1, the
  !! bound x <= XMAX): min 1/2 |s|^2 with G x + s = e, 0 <= x <= XMAX; y = s is the
  !! multiplier of the equality, z >= 0 and u >= 0 those of the bounds, w = XMAX - x. A
  !! Newton step for the perturbed conditions x z = w u = sigma duality reduces, with
  !! D = z/x + u/w, to (I + G D^-1 G') dy = rhs: one sparse factor per step, two solves
  !! (predictor and corrector). Stops when |G x - e| (a true upper bound of the minimum,
  !! x >= 0 at every step) is below ZERO_RES, or when the duality gap is below 1e-10 of
  !! its square (then it is the minimum to 5e-11 relative), or when complementarity reaches
  !! rounding with the residual below SMALL_RES. ok = .false. (the caller falls back to the
  !! active set method) when a factorization failed, or when no certificate came:
  !! complementarity at rounding with a larger residual left (a balance on the edge of
  !! feasibility, where the iterates stall), or MAX_STEPS steps.
  subroutine interior_point(g, e, x, res, ok)
    type(sparse_cols_t), intent(in) :: g
    real(wp), intent(in) :: e(:)
    real(wp), intent(out) :: x(:)
    real(wp), intent(out) :: res
    logical, intent(out) :: ok
    type(sparse_cols_t) :: gs
    type(gram_t) :: mm
    type(error_t) :: err
    real(wp), allocatable :: cn(:), e1(:), xs(:), w(:), z(:), u(:), y(:), dinv(:)
    real(wp), allocatable :: rp(:), rd(:), ru(:), rc1(:), rc2(:), dx(:), dy(:), dz(:), dw(:), du(:), q(:)
    integer, allocatable :: live(:)
    real(wp) :: es, duality, duality_aff, sigma, alpha, resid
    integer :: r, m, n, j, l, step

    ok = .true.
    r = g%nrow
    m = g%ncol
    x = 0.0_wp
    es = norm2(e)
    res = es
    if (es == 0.0_wp .or. r == 0) then
      res = 0.0_wp
      return
    end if
    ! the live columns, scaled to unit norm
    allocate (cn(m))
    do j = 1, m
      cn(j) = norm2(g%val(g%ptr(j):g%ptr(j + 1) - 1))
    end do
    live = pack([(j, j=1, m)], cn > 0.0_wp)
    n = size(live)
    if (n == 0) return
    call gs%init(r, g%ptr(m + 1))
    do j = 1, n
      l = live(j)
      call gs%push(g%row(g%ptr(l):g%ptr(l + 1) - 1), g%val(g%ptr(l):g%ptr(l + 1) - 1)/cn(l))
    end do
    e1 = e/es
    call mm%build(gs, [(j, j=1, r + 1)])

    allocate (xs(n), w(n), z(n), u(n), dinv(n), q(n))
    xs = 1.0_wp
    w = XMAX - xs
    z = 1.0_wp
    u = 1.0_wp/w
    y = e1 - gs%times(xs)
    do step = 1, MAX_STEPS
      rp = e1 - gs%times(xs)
      resid = norm2(rp)
      if (resid <= ZERO_RES) exit
      rp = rp - y
      rd = -gs%ttimes(y) - z + u
      ru = XMAX - xs - w
      duality = (dot_product(xs, z) + dot_product(w, u))/real(2*n, wp)
      if (2*n*duality <= 1.0e-10_wp*resid**2 .and. norm2(rp) <= 1.0e-12_wp .and. maxval(abs(rd)) <= 1.0e-12_wp) exit
      ! complementarity at rounding with the primal residual left (a balance on the edge of
      ! feasibility, x pressed against its bound): an upper bound below SMALL_RES stands,
      ! above it nothing is certified and the active set method decides
      if (duality <= 1.0e-18_wp) then
        ok = resid <= SMALL_RES
        exit
      end if
      dinv = 1.0_wp/(z/xs + u/w)
      call mm%factor(gs, dinv, spread(1.0_wp, 1, r), err)
      ok = .not. err%failed()
      if (.not. ok) exit
      ! predictor (affine scaling)
      rc1 = -xs*z
      rc2 = -w*u
      call direction()
      if (.not. ok) exit
      alpha = max_step()
      duality_aff = (dot_product(xs + alpha*dx, z + alpha*dz) + dot_product(w + alpha*dw, u + alpha*du))/real(2*n, wp)
      sigma = min(1.0_wp, (duality_aff/duality)**3)
      ! corrector
      rc1 = sigma*duality - xs*z - dx*dz
      rc2 = sigma*duality - w*u - dw*du
      call direction()
      if (.not. ok) exit
      alpha = min(1.0_wp, 0.995_wp*max_step())
      xs = xs + alpha*dx
      w = w + alpha*dw
      z = z + alpha*dz
      u = u + alpha*du
      y = y + alpha*dy
    end do
    ! without a certificate (the residual below ZERO_RES, or the duality gap closed) after
    ! MAX_STEPS steps, the caller's active set method decides
    if (step > MAX_STEPS) ok = .false.
    call mm%free()
    if (.not. ok) return
    x(live) = es*xs/cn(live)
    res = norm2(g%times(x) - e)

  contains

    !> The Newton direction for the complementarity right-hand sides rc1 (x z) and rc2 (w u).
    subroutine direction()
      q = rc1/xs - (rc2 - u*ru)/w
      dy = rp - gs%times(dinv*(q - rd))
      call mm%chol%solve(dy, err)
      if (err%failed()) then
        ok = .false.
        return
      end if
      dx = dinv*(gs%ttimes(dy) + q - rd)
      dz = (rc1 - z*dx)/xs
      dw = ru - dx
      du = (rc2 - u*dw)/w
    end subroutine direction

    !> The longest step in (0, 1] that keeps x, w, z, u positive.
    real(wp) function max_step() result(a)
      a = 1.0_wp
      a = min(a, bound(xs, dx), bound(w, dw), bound(z, dz), bound(u, du))
    end function max_step

    pure real(wp) function bound(v, dv) result(a)
      real(wp), intent(in) :: v(:), dv(:)
      integer :: i
      a = 1.0_wp
      do i = 1, size(v)
        if (dv(i) < 0.0_wp) a = min(a, -v(i)/dv(i))
      end do
    end function bound

  end subroutine interior_point

  !> The pattern of B + G G' (G: the columns to come; block k of B: rows
  !! bstart(k)..bstart(k+1)-1) in full symmetric CSC with sorted rows, and the places of
  !! every column's products and every block entry in it.
  subroutine gram_build(self, g, bstart)
    class(gram_t), intent(inout) :: self
    type(sparse_cols_t), intent(in) :: g
    integer, intent(in) :: bstart(:)
    integer, allocatable :: rptr(:), rcol(:), rloc(:), list(:), mark(:), fill(:), place(:), blk(:), mrow(:), t(:)
    integer :: a, b, c, k, kj, nl, ia, ib, nnz, j, l, r, n, nb, nbv
    r = g%nrow
    n = g%ncol
    nb = size(bstart) - 1
    self%n = r
    self%bstart = bstart
    allocate (blk(r))
    nbv = 0
    do k = 1, nb
      blk(bstart(k):bstart(k + 1) - 1) = k
      nbv = nbv + (bstart(k + 1) - bstart(k))**2
    end do
    ! G's rows: the columns in each and the entry's place within its column
    allocate (rptr(r + 1), fill(r))
    rptr = 0
    do l = 1, g%ptr(n + 1) - 1
      rptr(g%row(l) + 1) = rptr(g%row(l) + 1) + 1
    end do
    rptr(1) = 1
    do a = 1, r
      rptr(a + 1) = rptr(a + 1) + rptr(a)
    end do
    allocate (rcol(max(1, g%ptr(n + 1) - 1)), rloc(max(1, g%ptr(n + 1) - 1)))
    fill = rptr(1:r)
    do j = 1, n
      do l = g%ptr(j), g%ptr(j + 1) - 1
        a = g%row(l)
        rcol(fill(a)) = j
        rloc(fill(a)) = l - g%ptr(j) + 1
        fill(a) = fill(a) + 1
      end do
    end do
    if (allocated(self%pbase)) deallocate (self%pbase, self%pos, self%bpos)
    allocate (self%pbase(n + 1))
    self%pbase(1) = 0
    do j = 1, n
      kj = g%ptr(j + 1) - g%ptr(j)
      self%pbase(j + 1) = self%pbase(j) + kj*kj
    end do
    allocate (self%pos(max(1, self%pbase(n + 1))), self%bpos(max(1, nbv)), mark(r), place(r), list(r))
    allocate (mrow(max(16, self%pbase(n + 1) + nbv)))
    allocate (self%cptr0(r + 1))
    mark = 0
    self%cptr0(1) = 0
    nnz = 0
    do a = 1, r
      ! the rows of column a: its block's rows and every row of a column that has row a
      nl = 0
      do b = bstart(blk(a)), bstart(blk(a) + 1) - 1
        nl = nl + 1
        list(nl) = b
        mark(b) = a
      end do
      do k = rptr(a), rptr(a + 1) - 1
        j = rcol(k)
        do l = g%ptr(j), g%ptr(j + 1) - 1
          b = g%row(l)
          if (mark(b) /= a) then
            mark(b) = a
            nl = nl + 1
            list(nl) = b
          end if
        end do
      end do
      if (nl > 64) then     ! a long column (a row that every column has): by the marks, in order
        nl = 0
        do b = 1, r
          if (mark(b) == a) then
            nl = nl + 1
            list(nl) = b
          end if
        end do
      else
        call sort_ints(list(1:nl))
      end if
      if (nnz + nl > size(mrow)) then
        allocate (t(max(nnz + nl, 2*size(mrow))))
        t(1:nnz) = mrow(1:nnz)
        call move_alloc(t, mrow)
      end if
      do c = 1, nl
        mrow(nnz + c) = list(c)
        place(list(c)) = nnz + c
      end do
      ! column j's product of its entries ib (row b) and ia (row a) lands at (b, a)
      do k = rptr(a), rptr(a + 1) - 1
        j = rcol(k)
        ia = rloc(k)
        kj = g%ptr(j + 1) - g%ptr(j)
        do ib = 1, kj
          self%pos(self%pbase(j) + (ia - 1)*kj + ib) = place(g%row(g%ptr(j) + ib - 1))
        end do
      end do
      nnz = nnz + nl
      self%cptr0(a + 1) = int(nnz, ip)
    end do
    ! the block entries, block by block, each by columns
    l = 0
    do k = 1, nb
      do a = bstart(k), bstart(k + 1) - 1
        do b = bstart(k), bstart(k + 1) - 1
          l = l + 1
          ! row b of column a: search the column's sorted rows
          do c = self%cptr0(a) + 1, self%cptr0(a + 1)
            if (mrow(c) == b) exit
          end do
          self%bpos(l) = c
        end do
      end do
    end do
    self%rind0 = int(mrow(1:nnz) - 1, ip)
    if (allocated(self%val)) deallocate (self%val)
    allocate (self%val(nnz))
  end subroutine gram_build

  !> Factor B + G diag(d) G' (bvals: B's blocks in order, each by columns). err: the
  !! factorization's failure; not_posdef says whether it was that the matrix is not
  !! positive definite.
  subroutine gram_factor(self, g, d, bvals, err)
    class(gram_t), intent(inout) :: self
    type(sparse_cols_t), intent(in) :: g
    real(wp), intent(in) :: d(:), bvals(:)
    type(error_t), intent(out) :: err
    integer :: j, kj, ia, ib, p0, l
    self%val = 0.0_wp
    do l = 1, size(bvals)
      self%val(self%bpos(l)) = self%val(self%bpos(l)) + bvals(l)
    end do
    do j = 1, g%ncol
      kj = g%ptr(j + 1) - g%ptr(j)
      p0 = g%ptr(j) - 1
      do ia = 1, kj
        do ib = 1, kj
          l = self%pos(self%pbase(j) + (ia - 1)*kj + ib)
          self%val(l) = self%val(l) + d(j)*g%val(p0 + ia)*g%val(p0 + ib)
        end do
      end do
    end do
    call self%chol%factor(self%n, self%cptr0, self%rind0, self%val, FACT_CHOLMOD, ORD_AMD, err)
    self%not_posdef = self%chol%not_posdef
  end subroutine gram_factor

  subroutine gram_free(self)
    class(gram_t), intent(inout) :: self
    call self%chol%free()
  end subroutine gram_free

end module nonneg_lsq
