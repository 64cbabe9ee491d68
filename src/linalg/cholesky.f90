!> Sparse Cholesky factorization of one symmetric positive definite matrix, behind one
!! type: CHOLMOD (supernodal, through cholmod_iface) or a banded LAPACK factorization
!! (module banded). Also forms the interface flexibility F = E (K^-1)_GG E.
!!
!! With FACT_CHOLMOD and the interface DOFs G ordered last, P K P' = L L' has a
!! trailing block L_G with L_G L_G' = S (Schur complement of K on G), so
!! (K^-1)_GG = S^-1 comes from one LAPACK `dpotri` on L_G (chol_flexibility), and
!! B S^-1 B' for sparse rows B from triangular solves with L_G without forming S^-1
!! (chol_row_flexibility): the condensation costs about one factorization instead of m
!! solves. Otherwise F is formed by blocked solves with unit right-hand sides.
!!
!! One chol_t owns one factorization; two chol_t may be used from two threads at
!! once, one chol_t must not. Do not copy a chol_t (it owns a C handle): pass it
!! by reference and release it with `free`.
module cholesky
  use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_int
  use kinds, only: wp, ip, i8
  use cholmod_iface, only: cm_stats_t, cm_init, cm_create, cm_factorize, cm_solve, cm_trailing_block, &
                           cm_get_stats, cm_release_workspace, cm_free, ORD_METIS, ORD_AMD, ORD_NATURAL, &
                           ORD_GIVEN, ORD_NODES, ORD_AUTO
  use banded, only: band_t
  use lapack, only: dpotri, dtrsm, dsyrk, dgemm
  use ordering, only: node_dissection
  use clock, only: wtime
  use errors, only: error_t, ERR_NUMERICAL, ERR_MEMORY
  implicit none (type, external)
  private

  integer, parameter, public :: FACT_CHOLMOD = 1   !< CHOLMOD supernodal LL'
  integer, parameter, public :: FACT_BANDED = 2    !< RCM + LAPACK band Cholesky

  ! the fill-reducing orderings (FACT_CHOLMOD), defined in cholmod_iface and handed on
  public :: ORD_METIS, ORD_AMD, ORD_NATURAL, ORD_GIVEN, ORD_NODES, ORD_AUTO

  !> One factorization of one symmetric positive definite matrix K (n x n).
  type, public :: chol_t
    integer :: method = 0                 !< FACT_CHOLMOD, FACT_BANDED, or 0 when empty/failed
    integer :: ordering = 0               !< ORD_* requested (FACT_CHOLMOD)
    integer :: n = 0                      !< matrix order
    integer :: m_last = 0                 !< number of DOFs ordered last (interface)
    integer, allocatable :: last(:)       !< those DOFs, 1-based, in the order given
    real(wp) :: t_analyze = 0.0_wp        !< ordering + symbolic analysis wall time [s]
    !> the ordering's part of t_analyze (CHOLMOD with DOFs last or ORD_NODES: the permutation of
    !! the interior; 0 where CHOLMOD's analysis orders, without DOFs last) [s]
    real(wp) :: t_order = 0.0_wp
    real(wp) :: t_factor = 0.0_wp         !< numeric factorization wall time [s]
    integer(i8) :: nnz_factor = 0         !< nonzeros in L (CHOLMOD: without supernodal padding)
    integer(i8) :: nnz_stored = 0         !< CHOLMOD: entries stored in the supernodal L (with padding)
    !> CHOLMOD: the ordering its analysis kept, in CHOLMOD's codes (1 given, 2 AMD, 3 METIS; what
    !! ORD_AUTO chose), -1 if none
    integer :: ordering_used = -1
    real(wp) :: flops = 0.0_wp            !< factorization flop count
    !> CHOLMOD: the dense-kernel tiles its numeric factorization ran as tasks (blas_tiles.c;
    !! 0 when every kernel was small enough to run whole)
    integer(i8) :: tiles = 0
    integer(i8) :: mem_bytes = 0          !< peak memory of the factorization [bytes]
    integer :: bandwidth = -1             !< half-bandwidth (FACT_BANDED), else -1
    logical :: interface_last_ok = .false.  !< true if L's permutation ends with `last`, in order
    logical :: not_posdef = .false.       !< CHOLMOD: the last factor failed on a pivot <= 0 (K not positive definite)
    type(c_ptr), private :: handle = c_null_ptr
    type(band_t), private :: band
  contains
    procedure :: factor => chol_factor
    procedure, private :: chol_solve_vec
    procedure, private :: chol_solve_mat
    generic :: solve => chol_solve_vec, chol_solve_mat
    procedure :: flexibility => chol_flexibility
    procedure :: row_flexibility => chol_row_flexibility
    procedure :: holds_block => chol_holds_block
    procedure :: summary => chol_summary
    procedure :: free => chol_free
  end type chol_t

contains

  !> Factorize K, given in full symmetric CSC (both triangles, 0-based, rows sorted
  !! increasingly in each column, K symmetric).
  !! With ORD_GIVEN (CHOLMOD), interior_perm is the elimination order of every DOF not in
  !! `last` (e.g. module ordering's nested dissection), followed by `last`; ORD_NODES computes
  !! it (ordering%node_dissection, its time part of t_analyze); ORD_AUTO takes no `last`.
  !! err: ERR_NUMERICAL (not positive definite, bad arguments, CHOLMOD failure) or ERR_MEMORY.
  subroutine chol_factor(self, n, colptr, rowind, val, method, ordering, err, last, interior_perm)
    class(chol_t), intent(inout) :: self
    integer, intent(in) :: n                    !< matrix order
    integer(ip), intent(in) :: colptr(:)        !< column pointers, size n+1, 0-based
    integer(ip), intent(in) :: rowind(:)        !< row indices, 0-based, size >= colptr(n+1)
    real(wp), intent(in) :: val(:)              !< values, size >= colptr(n+1)
    integer, intent(in) :: method               !< FACT_CHOLMOD or FACT_BANDED
    integer, intent(in) :: ordering             !< ORD_* (CHOLMOD)
    type(error_t), intent(out) :: err           !< the failure, if any
    integer, intent(in), optional :: last(:)    !< 1-based DOFs to order last (interface), CHOLMOD
    integer, intent(in), optional :: interior_perm(:)  !< ORD_GIVEN: 1-based order of the DOFs not in `last`
    integer :: j, p, nnz, k
    logical, allocatable :: seen(:)
    integer(c_int), allocatable :: last0(:), inter0(:)
    integer, allocatable :: node_perm(:)
    real(wp) :: t_order
    type(cm_stats_t) :: st
    character(len=200) :: emsg
    logical :: not_posdef

    call self%free()

    ! ---- check arguments ----
    if (n < 1) then
      write (emsg, '(a,i0,a)') 'Cholesky: matrix order n = ', n, ' must be positive.'
      call err%set(ERR_NUMERICAL, emsg)
      return
    end if
    if (size(colptr) < n + 1) then
      call err%set(ERR_NUMERICAL, 'Cholesky: colptr is shorter than n+1.')
      return
    end if
    if (colptr(1) /= 0) then
      call err%set(ERR_NUMERICAL, 'Cholesky: colptr(1) must be 0 (0-based CSC).')
      return
    end if
    nnz = colptr(n + 1)
    if (size(rowind) < nnz .or. size(val) < nnz) then
      call err%set(ERR_NUMERICAL, 'Cholesky: rowind or val is shorter than colptr(n+1).')
      return
    end if
    do j = 1, n
      if (colptr(j + 1) < colptr(j)) then
        write (emsg, '(a,i0,a)') 'Cholesky: colptr decreases at column ', j, '.'
        call err%set(ERR_NUMERICAL, emsg)
        return
      end if
      do p = colptr(j) + 1, colptr(j + 1)
        if (rowind(p) < 0 .or. rowind(p) >= n) then
          write (emsg, '(a,i0,a,i0,a)') 'Cholesky: row index ', rowind(p), ' out of range in column ', j, '.'
          call err%set(ERR_NUMERICAL, emsg)
          return
        end if
        if (p > colptr(j) + 1) then
          if (rowind(p) <= rowind(p - 1)) then
            write (emsg, '(a,i0,a)') 'Cholesky: row indices not strictly increasing in column ', j, '.'
            call err%set(ERR_NUMERICAL, emsg)
            return
          end if
        end if
      end do
    end do
    if (method /= FACT_CHOLMOD .and. method /= FACT_BANDED) then
      write (emsg, '(a,i0,a)') 'Cholesky: unknown factorization method ', method, '.'
      call err%set(ERR_NUMERICAL, emsg)
      return
    end if
    if (method == FACT_CHOLMOD .and. (ordering < ORD_METIS .or. ordering > ORD_AUTO)) then
      write (emsg, '(a,i0,a)') 'Cholesky: unknown ordering ', ordering, '.'
      call err%set(ERR_NUMERICAL, emsg)
      return
    end if
    allocate (seen(n))
    seen = .false.
    if (present(last)) then
      do k = 1, size(last)
        if (last(k) < 1 .or. last(k) > n) then
          write (emsg, '(a,i0,a,i0,a)') 'Cholesky: interface DOF ', last(k), ' (entry ', k, ') is out of range.'
          call err%set(ERR_NUMERICAL, emsg)
          return
        end if
        if (seen(last(k))) then
          write (emsg, '(a,i0,a,i0,a)') 'Cholesky: interface DOF ', last(k), ' (entry ', k, ') is repeated.'
          call err%set(ERR_NUMERICAL, emsg)
          return
        end if
        seen(last(k)) = .true.
      end do
      self%last = last
    else
      allocate (self%last(0))
    end if
    if (method == FACT_CHOLMOD .and. ordering == ORD_GIVEN) then
      ! interior_perm: every DOF not in `last`, once (seen marks `last` so far)
      if (.not. present(interior_perm)) then
        call err%set(ERR_NUMERICAL, 'Cholesky: ordering GIVEN needs interior_perm.')
        return
      end if
      if (size(interior_perm) /= n - size(self%last)) then
        write (emsg, '(a,i0,a,i0,a)') 'Cholesky: interior_perm has ', size(interior_perm), &
          ' entries, expected n - size(last) = ', n - size(self%last), '.'
        call err%set(ERR_NUMERICAL, emsg)
        return
      end if
      do k = 1, size(interior_perm)
        if (interior_perm(k) < 1 .or. interior_perm(k) > n) then
          write (emsg, '(a,i0,a,i0,a)') 'Cholesky: interior_perm entry ', k, ' = ', interior_perm(k), &
            ' is out of range.'
          call err%set(ERR_NUMERICAL, emsg)
          return
        end if
        if (seen(interior_perm(k))) then
          write (emsg, '(a,i0,a,i0,a)') 'Cholesky: interior_perm entry ', k, ' = ', interior_perm(k), &
            ' is repeated or an interface DOF.'
          call err%set(ERR_NUMERICAL, emsg)
          return
        end if
        seen(interior_perm(k)) = .true.
      end do
    end if
    deallocate (seen)
    if (method == FACT_CHOLMOD .and. ordering == ORD_AUTO .and. size(self%last) > 0) then
      call err%set(ERR_NUMERICAL, 'Cholesky: ordering AUTO (CHOLMOD''s own choice) cannot put DOFs last.')
      return
    end if
    t_order = 0.0_wp
    if (method == FACT_CHOLMOD .and. ordering == ORD_NODES) then
      t_order = wtime()
      call node_dissection(colptr(1:n + 1), rowind(1:nnz), self%last, node_perm, err)
      t_order = wtime() - t_order
      if (err%failed()) return
    end if
    self%m_last = size(self%last)
    self%n = n
    self%ordering = ordering

    ! ---- factorize ----
    call cm_init()    ! BLAS single-threaded, for the banded path too
    select case (method)
    case (FACT_CHOLMOD)
      call cm_create(self%handle, err)
      if (err%failed()) return
      allocate (last0(self%m_last))
      last0 = int(self%last - 1, c_int)
      if (ordering == ORD_GIVEN .or. ordering == ORD_NODES) then
        if (ordering == ORD_NODES) then
          allocate (inter0(size(node_perm)))
          inter0 = int(node_perm - 1, c_int)
          deallocate (node_perm)
        else
          allocate (inter0(size(interior_perm)))
          inter0 = int(interior_perm - 1, c_int)
        end if
        call cm_factorize(self%handle, n, colptr, rowind, val, ORD_GIVEN, last0, err, interior0=inter0, &
                          not_posdef=not_posdef)
        deallocate (inter0)
      else
        call cm_factorize(self%handle, n, colptr, rowind, val, ordering, last0, err, not_posdef=not_posdef)
      end if
      st = cm_get_stats(self%handle)
      self%t_analyze = st%t_analyze + t_order
      self%t_order = st%t_order + t_order
      self%t_factor = st%t_factor
      self%nnz_factor = int(st%lnz, i8)
      self%nnz_stored = int(st%lsize, i8)
      self%ordering_used = st%ordering_used
      self%flops = st%flops
      self%tiles = int(st%tiles, i8)
      self%mem_bytes = int(st%mem_peak, i8)
      self%interface_last_ok = (st%last_ok == 1 .and. self%m_last > 0)
      if (err%failed()) then
        self%not_posdef = not_posdef
        call cm_free(self%handle)
        return
      end if
    case (FACT_BANDED)
      call self%band%factor(n, colptr, rowind, val, err)
      self%t_analyze = self%band%t_order
      self%t_factor = self%band%t_factor
      self%bandwidth = self%band%kd
      if (err%failed()) return
      self%nnz_factor = int(n, i8) * int(self%band%kd + 1, i8) &
                        - int(self%band%kd, i8) * int(self%band%kd + 1, i8) / 2
      self%flops = real(n, wp) * real(self%band%kd, wp) * real(self%band%kd + 3, wp)
      self%mem_bytes = int(size(self%band%ab, kind=i8) * 8_i8, i8)
    end select
    self%method = method

  end subroutine chol_factor

  !> Solve K x = b in place (one right-hand side). err: ERR_MEMORY or ERR_NUMERICAL.
  subroutine chol_solve_vec(self, b, err)
    class(chol_t), intent(in) :: self
    real(wp), intent(inout), target, contiguous :: b(:)   !< right-hand side in, solution out
    type(error_t), intent(out) :: err                     !< the failure, if any
    real(wp), pointer, contiguous :: b2(:, :)
    b2(1:size(b), 1:1) => b
    call chol_solve_mat(self, b2, err)
  end subroutine chol_solve_vec

  !> Solve K X = B in place (columns of b). err: ERR_MEMORY or ERR_NUMERICAL.
  subroutine chol_solve_mat(self, b, err)
    class(chol_t), intent(in) :: self
    real(wp), intent(inout), contiguous :: b(:, :)   !< right-hand sides in, solutions out (n x nrhs)
    type(error_t), intent(out) :: err                !< the failure, if any
    character(len=512) :: emsg
    if (self%method == 0) then
      call err%set(ERR_NUMERICAL, 'Cholesky: solve called without a valid factorization.')
    else if (size(b, 1) /= self%n) then
      write (emsg, '(a,i0,a,i0,a)') 'Cholesky: right-hand side length ', size(b, 1), &
        ' differs from the matrix order ', self%n, '.'
      call err%set(ERR_NUMERICAL, emsg)
    else if (self%method == FACT_CHOLMOD) then
      call cm_solve(self%handle, b, err)
    else
      call self%band%solve(b, err)
    end if
  end subroutine chol_solve_mat

  !> Interface flexibility F(i,j) = sgn(i) sgn(j) (K^-1)(idx(i), idx(j)), m = size(idx),
  !! symmetric, full storage. Uses the trailing block of L when the factorization
  !! is CHOLMOD with every idx(i) among the DOFs ordered last and the ordering check
  !! passed; otherwise blocked solves with unit right-hand sides.
  !! err: ERR_NUMERICAL (Schur complement not positive definite, failure) or ERR_MEMORY.
  subroutine chol_flexibility(self, idx, sgn, F, err, use_solves, used_block)
    class(chol_t), intent(in) :: self
    integer, intent(in) :: idx(:)                 !< 1-based DOFs of the interface rows
    real(wp), intent(in) :: sgn(:)                !< row scaling (the +-1 signs of E), size(idx)
    real(wp), intent(out) :: F(:, :)              !< m x m flexibility [K^-1 units]
    type(error_t), intent(out) :: err             !< the failure, if any
    logical, intent(in), optional :: use_solves   !< force the solve-based path (default false)
    logical, intent(out), optional :: used_block  !< true if the trailing-block path was used
    integer :: m, i, j, st
    integer, allocatable :: pos(:)
    logical :: try_block
    character(len=200) :: emsg

    if (present(used_block)) used_block = .false.
    m = size(idx)
    if (self%method == 0) then
      call err%set(ERR_NUMERICAL, 'Cholesky: flexibility requested without a valid factorization.')
      return
    end if
    if (size(sgn) /= m .or. size(F, 1) /= m .or. size(F, 2) /= m) then
      write (emsg, '(a,i0,a)') 'Cholesky: flexibility needs sgn(', m, ') and F(m,m) for m = size(idx).'
      call err%set(ERR_NUMERICAL, emsg)
      return
    end if
    if (m == 0) return
    do i = 1, m
      if (idx(i) < 1 .or. idx(i) > self%n) then
        write (emsg, '(a,i0,a,i0,a)') 'Cholesky: interface DOF ', idx(i), ' (entry ', i, ') is out of range.'
        call err%set(ERR_NUMERICAL, emsg)
        return
      end if
    end do

    try_block = .true.
    if (present(use_solves)) try_block = .not. use_solves
    if (try_block) try_block = block_holds(self, idx, pos)

    if (try_block) then
      call flex_block()
      if (present(used_block)) used_block = .not. err%failed()
    else
      call flex_solves()
    end if

  contains

    !> F from the trailing block L_G: (K^-1)_GG = (L_G L_G')^-1 via dpotri.
    subroutine flex_block()
      real(wp), allocatable :: lg(:, :)
      integer :: ml, lapinfo, a, b
      ml = self%m_last
      call trailing_block(self, lg, err)
      if (err%failed()) return
      call dpotri('L', ml, lg, ml, lapinfo)
      if (lapinfo > 0) then
        write (emsg, '(a,i0,a)') 'Cholesky: trailing block of L is singular (dpotri info ', lapinfo, ').'
        call err%set(ERR_NUMERICAL, emsg)
        return
      else if (lapinfo < 0) then
        call err%set(ERR_NUMERICAL, 'Cholesky: dpotri rejected its arguments.')
        return
      end if
      do j = 1, m
        do i = 1, m
          a = max(pos(idx(i)), pos(idx(j)))
          b = min(pos(idx(i)), pos(idx(j)))
          F(i, j) = sgn(i) * sgn(j) * lg(a, b)
        end do
      end do
    end subroutine flex_block

    !> F from blocked solves with unit right-hand sides (at most 64 columns at once,
    !! fewer for large n to bound the workspace), then symmetrized.
    subroutine flex_solves()
      real(wp), allocatable :: w(:, :)
      integer :: nb, j0, nc, jj
      nb = int(max(1_i8, min(64_i8, 2_i8**24 / int(self%n, i8))))
      nb = min(nb, m)
      allocate (w(self%n, nb), stat=st)
      if (st /= 0) then
        call err%set(ERR_MEMORY, 'Cholesky: out of memory for the flexibility solve block.')
        return
      end if
      do j0 = 1, m, nb
        nc = min(nb, m - j0 + 1)
        w(:, 1:nc) = 0.0_wp
        do jj = 1, nc
          w(idx(j0 + jj - 1), jj) = 1.0_wp
        end do
        call chol_solve_mat(self, w(:, 1:nc), err)
        if (err%failed()) exit
        do jj = 1, nc
          j = j0 + jj - 1
          do i = 1, m
            F(i, j) = sgn(i) * sgn(j) * w(idx(i), jj)
          end do
        end do
      end do
      if (self%method == FACT_CHOLMOD) call cm_release_workspace(self%handle)
      if (err%failed()) return
      do j = 1, m
        do i = j + 1, m
          F(i, j) = 0.5_wp * (F(i, j) + F(j, i))
          F(j, i) = F(i, j)
        end do
      end do
    end subroutine flex_solves

  end subroutine chol_flexibility

  !> F = B (K^-1)(idx, idx) B' for sparse rows B (row i: the entries bval(e) at columns
  !! bpos(e) of idx, e = bptr(i) .. bptr(i+1)-1), from the trailing block L_G of a CHOLMOD factor
  !! whose DOFs ordered last hold every idx: with W = L_G^-1 B', F = W' W. Row i of W' is zero
  !! before the first position p_i in G of its DOFs, so the rows are sorted by p_i and taken
  !! in panels of ROW_PANEL: each panel's triangular solve (dtrsm) and each pair of panels'
  !! product (dsyrk, dgemm) starts at the later panel's first position. That costs about a
  !! third of the dense k^2 m + m^2 k on contact rows (their DOFs first appear in row order),
  !! 3-5 times fewer than inverting L_G (dpotri, 2/3 k^3) when k is three times m, about the
  !! same when k = m. The panels are OpenMP tasks, one BLAS call each: a body loop's idle
  !! threads take them at its barrier, and F is bitwise the same for any number of threads.
  !! used_block false (F untouched, no error): not this factor's case; the caller falls back.
  !! err: ERR_MEMORY, or CHOLMOD's failure to give L_G.
  subroutine chol_row_flexibility(self, idx, bptr, bpos, bval, F, err, used_block)
    class(chol_t), intent(in) :: self
    integer, intent(in) :: idx(:)                 !< 1-based DOFs of the columns of B
    integer, intent(in) :: bptr(:)                !< (m+1) row starts in bpos, bval
    integer, intent(in) :: bpos(:)                !< columns of B's entries (into idx)
    real(wp), intent(in) :: bval(:)               !< B's entries
    real(wp), intent(out) :: F(:, :)              !< (m,m) B (K^-1)(idx, idx) B'
    type(error_t), intent(out) :: err             !< the failure, if any
    logical, intent(out) :: used_block            !< true if F was formed here
    integer, parameter :: ROW_PANEL = 128
    real(wp), allocatable :: lg(:, :), wt(:, :), fs(:, :)
    integer, allocatable :: pos(:), first(:), order(:), cnt(:), pstart(:), r0(:)
    integer :: m, ml, i, e, q, np, a, b, nr, na, nb, nc, st

    used_block = .false.
    m = size(bptr) - 1
    if (m <= 0) return
    if (.not. block_holds(self, idx, pos)) return
    ml = self%m_last
    used_block = .true.
    allocate (wt(m, ml), fs(m, m), first(m), order(m), cnt(0:ml + 1), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'Cholesky: out of memory for the rows on the trailing block of L.')
      return
    end if
    call trailing_block(self, lg, err)
    if (err%failed()) return
    ! the rows in the order of their first position in G (stable counting sort; a row on
    ! no DOF goes last, its W row stays zero)
    do i = 1, m
      first(i) = ml + 1
      do e = bptr(i), bptr(i + 1) - 1
        first(i) = min(first(i), pos(idx(bpos(e))))
      end do
    end do
    cnt = 0
    do i = 1, m
      cnt(first(i)) = cnt(first(i)) + 1
    end do
    do q = 1, ml + 1
      cnt(q) = cnt(q) + cnt(q - 1)
    end do
    do i = m, 1, -1
      order(cnt(first(i))) = i
      cnt(first(i)) = cnt(first(i)) - 1
    end do
    wt = 0.0_wp
    do a = 1, m
      i = order(a)
      do e = bptr(i), bptr(i + 1) - 1
        q = pos(idx(bpos(e)))
        wt(a, q) = wt(a, q) + bval(e)
      end do
    end do
    ! panels of sorted rows: pstart(p) .. pstart(p+1)-1, nonzero in W' from r0(p)
    np = (m + ROW_PANEL - 1)/ROW_PANEL
    allocate (pstart(np + 1), r0(np))
    do q = 1, np
      pstart(q) = 1 + (q - 1)*ROW_PANEL
      r0(q) = first(order(pstart(q)))
    end do
    pstart(np + 1) = m + 1
    ! W' = B L_G^-T, panel by panel
    !$omp taskgroup
    do q = 1, np
      if (r0(q) > ml) cycle
      !$omp task default(shared) firstprivate(q) private(na, nr)
      na = pstart(q + 1) - pstart(q)
      nr = ml - r0(q) + 1
      call dtrsm('R', 'L', 'T', 'N', na, nr, 1.0_wp, lg(r0(q), r0(q)), ml, wt(pstart(q), r0(q)), m)
      !$omp end task
    end do
    !$omp end taskgroup
    ! F = W' W on the lower triangle of panel pairs (a >= b), from the later panel's start
    fs = 0.0_wp
    !$omp taskgroup
    do b = 1, np
      do a = b, np
        if (r0(a) > ml) cycle
        !$omp task default(shared) firstprivate(a, b) private(na, nb, nc)
        na = pstart(a + 1) - pstart(a)
        nb = pstart(b + 1) - pstart(b)
        nc = ml - r0(a) + 1
        if (a == b) then
          call dsyrk('L', 'N', na, nc, 1.0_wp, wt(pstart(a), r0(a)), m, 0.0_wp, fs(pstart(a), pstart(a)), m)
        else
          call dgemm('N', 'T', na, nb, nc, 1.0_wp, wt(pstart(a), r0(a)), m, wt(pstart(b), r0(a)), m, 0.0_wp, &
                     fs(pstart(a), pstart(b)), m)
        end if
        !$omp end task
      end do
    end do
    !$omp end taskgroup
    deallocate (lg, wt)
    do b = 1, m
      do a = b, m
        F(order(a), order(b)) = fs(a, b)
        F(order(b), order(a)) = fs(a, b)
      end do
    end do
  end subroutine chol_row_flexibility

  !> True when row_flexibility on the DOFs idx forms F from the trailing block of L, reading
  !! the factor and nothing a solve uses: a CHOLMOD factor that ordered every idx last
  !! (block_holds). A solve of the same factor may then run beside it on another thread (it
  !! keeps its workspace and CHOLMOD's Common in the handle, which the block's copy does not
  !! touch).
  logical function chol_holds_block(self, idx) result(yes)
    class(chol_t), intent(in) :: self
    integer, intent(in) :: idx(:)                 !< 1-based DOFs
    integer, allocatable :: pos(:)
    yes = block_holds(self, idx, pos)
  end function chol_holds_block

  !> True when the trailing block of this factor holds (K^-1) on idx: a CHOLMOD factor that
  !! ordered its `last` DOFs last, every idx among them (and in range); pos(j) is then the
  !! position of DOF j among them (0: not among them). False also when pos cannot be allocated.
  logical function block_holds(self, idx, pos) result(ok)
    class(chol_t), intent(in) :: self
    integer, intent(in) :: idx(:)                 !< 1-based DOFs
    integer, allocatable, intent(out) :: pos(:)   !< (n) position of each DOF in `last`
    integer :: q, st
    ok = .false.
    if (self%method /= FACT_CHOLMOD .or. .not. self%interface_last_ok .or. self%m_last <= 0) return
    if (any(idx < 1 .or. idx > self%n)) return
    allocate (pos(self%n), stat=st)
    if (st /= 0) return
    pos = 0
    do q = 1, self%m_last
      pos(self%last(q)) = q
    end do
    ok = all(pos(idx) > 0)
  end function block_holds

  !> The trailing block L_G (m_last x m_last, lower triangle) of a CHOLMOD factor whose
  !! interface DOFs were ordered last. err: ERR_MEMORY, or CHOLMOD's failure.
  subroutine trailing_block(self, lg, err)
    type(chol_t), intent(in) :: self
    real(wp), allocatable, intent(out) :: lg(:, :)
    type(error_t), intent(inout) :: err
    integer :: st
    allocate (lg(self%m_last, self%m_last), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'Cholesky: out of memory for the trailing block of L.')
      return
    end if
    call cm_trailing_block(self%handle, lg, err)
  end subroutine trailing_block

  !> One line describing the factorization (method, sizes, times, memory).
  function chol_summary(self) result(line)
    class(chol_t), intent(in) :: self
    character(len=:), allocatable :: line
    character(len=400) :: buf
    character(len=*), parameter :: ordname(6) = [character(len=7) :: 'metis', 'amd', 'natural', 'given', 'nodes', 'auto']
    select case (self%method)
    case (FACT_CHOLMOD)
      write (buf, '(a,a,a,i0,a,i0,a,es10.3,a,es10.3,a,i0,a,f0.3,a,f0.3,a,f0.1,a,l1)') &
        'cholmod/', trim(ordname(self%ordering)), ' n=', self%n, ' m_last=', self%m_last, &
        ' nnz(L)=', real(self%nnz_factor, wp), ' flops=', self%flops, ' tiles=', self%tiles, &
        ' t_analyze=', self%t_analyze, 's t_factor=', self%t_factor, 's mem=', &
        real(self%mem_bytes, wp) / 2.0_wp**20, 'MiB interface_last=', self%interface_last_ok
    case (FACT_BANDED)
      write (buf, '(a,i0,a,i0,a,es10.3,a,es10.3,a,f0.3,a,f0.3,a,f0.1,a)') &
        'banded n=', self%n, ' bandwidth=', self%bandwidth, ' nnz(L)=', real(self%nnz_factor, wp), &
        ' flops=', self%flops, ' t_order=', self%t_analyze, 's t_factor=', self%t_factor, &
        's mem=', real(self%mem_bytes, wp) / 2.0_wp**20, 'MiB'
    case default
      buf = 'no factorization'
    end select
    line = trim(buf)
  end function chol_summary

  !> Release the factorization and reset the statistics.
  subroutine chol_free(self)
    class(chol_t), intent(inout) :: self
    call cm_free(self%handle)
    call self%band%free()
    if (allocated(self%last)) deallocate (self%last)
    self%method = 0
    self%ordering = 0
    self%n = 0
    self%m_last = 0
    self%t_analyze = 0.0_wp
    self%t_order = 0.0_wp
    self%t_factor = 0.0_wp
    self%nnz_factor = 0
    self%nnz_stored = 0
    self%ordering_used = -1
    self%tiles = 0
    self%flops = 0.0_wp
    self%mem_bytes = 0
    self%bandwidth = -1
    self%interface_last_ok = .false.
    self%not_posdef = .false.
  end subroutine chol_free

end module cholesky
