!> Banded Cholesky factorization of a sparse symmetric positive definite matrix:
!! reverse Cuthill-McKee (RCM) ordering, LAPACK band storage, `dpbtrf`/`dpbtrs`.
!! A simple, dependency-free alternative to CHOLMOD for small problems and checks.
module banded
  use kinds, only: wp, i8
  use clock, only: wtime
  use sorting, only: sort_by_key
  use lapack, only: dpbtrf, dpbtrs
  use errors, only: error_t, ERR_NUMERICAL, ERR_MEMORY
  implicit none (type, external)
  private

  !> One banded Cholesky factorization P K P' = L L' (P from RCM).
  type, public :: band_t
    integer :: n = 0                       !< matrix order
    integer :: kd = -1                     !< half-bandwidth of P K P' (sub-diagonals)
    integer, allocatable :: perm(:)        !< perm(k) = original DOF (1-based) at position k
    real(wp), allocatable :: ab(:, :)      !< L in LAPACK lower band storage, (kd+1) x n
    logical :: factored = .false.          !< true once `ab` holds a valid factor
    real(wp) :: t_order = 0.0_wp           !< RCM ordering + assembly time [s]
    real(wp) :: t_factor = 0.0_wp          !< dpbtrf time [s]
  contains
    procedure :: factor => band_factor
    procedure :: solve => band_solve
    procedure :: free => band_free
  end type band_t

  public :: rcm_order, band_width

contains

  !> Reverse Cuthill-McKee ordering of a symmetric sparsity pattern.
  !! Each connected component is numbered by a breadth-first search from a
  !! pseudo-peripheral node (George-Liu), neighbours taken by increasing degree;
  !! the whole order is then reversed.
  subroutine rcm_order(n, colptr, rowind, perm)
    integer, intent(in) :: n              !< matrix order
    integer, intent(in) :: colptr(:)      !< column pointers, size n+1, 0-based
    integer, intent(in) :: rowind(:)      !< row indices (both triangles), 0-based
    integer, intent(out) :: perm(:)       !< perm(k) = original node (1-based) at position k
    integer, allocatable :: deg(:), bydeg(:), cnt(:), mark(:), lev(:)
    logical, allocatable :: done(:)
    integer :: i, j, p, k, nnum, head, tail, ptr, root, cand, ecc, ecc_new, maxdeg, stamp
    integer :: first_new, v, x

    allocate (deg(n), done(n), mark(n), lev(n))
    do j = 1, n
      deg(j) = 0
      do p = colptr(j) + 1, colptr(j + 1)
        if (rowind(p) + 1 /= j) deg(j) = deg(j) + 1
      end do
    end do
    ! nodes sorted by degree (counting sort): start candidates for each component
    maxdeg = maxval(deg)
    allocate (cnt(0:maxdeg + 1), bydeg(n))
    cnt = 0
    do j = 1, n
      cnt(deg(j) + 1) = cnt(deg(j) + 1) + 1
    end do
    do k = 1, maxdeg + 1
      cnt(k) = cnt(k) + cnt(k - 1)
    end do
    do j = 1, n
      cnt(deg(j)) = cnt(deg(j)) + 1
      bydeg(cnt(deg(j))) = j
    end do

    done = .false.
    mark = 0
    stamp = 0
    nnum = 0
    ptr = 1
    do while (nnum < n)
      do while (done(bydeg(ptr)))
        ptr = ptr + 1
      end do
      root = bydeg(ptr)
      ! pseudo-peripheral node: repeat BFS from the min-degree node of the last level
      call level_bfs(root, ecc, cand)
      do
        call level_bfs(cand, ecc_new, x)
        if (ecc_new <= ecc) exit
        root = cand
        ecc = ecc_new
        cand = x
      end do
      ! Cuthill-McKee BFS from root, numbering into perm(nnum+1:)
      head = nnum + 1
      tail = nnum + 1
      perm(tail) = root
      done(root) = .true.
      do while (head <= tail)
        v = perm(head)
        head = head + 1
        first_new = tail + 1
        do p = colptr(v) + 1, colptr(v + 1)
          i = rowind(p) + 1
          if (.not. done(i)) then
            done(i) = .true.
            tail = tail + 1
            perm(tail) = i
          end if
        end do
        ! insertion sort of the new nodes by degree
        call sort_by_key(perm(first_new:tail), deg)
      end do
      nnum = tail
    end do
    perm(1:n) = perm(n:1:-1)

  contains

    !> BFS level structure from s inside its component (nodes not yet numbered):
    !! returns the eccentricity and the minimum-degree node of the last level.
    subroutine level_bfs(s, ecc_out, last_min)
      integer, intent(in) :: s
      integer, intent(out) :: ecc_out, last_min
      integer :: h, tl, vv, q, ii, lstart, lend, l
      stamp = stamp + 1
      lev(1) = s
      mark(s) = stamp
      h = 1
      tl = 1
      l = 0
      lstart = 1
      lend = 1
      do
        do h = lstart, lend
          vv = lev(h)
          do q = colptr(vv) + 1, colptr(vv + 1)
            ii = rowind(q) + 1
            if (mark(ii) /= stamp .and. .not. done(ii)) then
              mark(ii) = stamp
              tl = tl + 1
              lev(tl) = ii
            end if
          end do
        end do
        if (tl == lend) exit
        l = l + 1
        lstart = lend + 1
        lend = tl
      end do
      ecc_out = l
      last_min = lev(lstart)
      do h = lstart + 1, lend
        if (deg(lev(h)) < deg(last_min)) last_min = lev(h)
      end do
    end subroutine level_bfs

  end subroutine rcm_order

  !> Half-bandwidth max |iperm(i) - iperm(j)| of the pattern under the ordering perm.
  function band_width(n, colptr, rowind, perm) result(kd)
    integer, intent(in) :: n             !< matrix order
    integer, intent(in) :: colptr(:)     !< column pointers, size n+1, 0-based
    integer, intent(in) :: rowind(:)     !< row indices, 0-based
    integer, intent(in) :: perm(:)       !< perm(k) = original node (1-based) at position k
    integer :: kd
    integer, allocatable :: iperm(:)
    integer :: j, p
    allocate (iperm(n))
    do j = 1, n
      iperm(perm(j)) = j
    end do
    kd = 0
    do j = 1, n
      do p = colptr(j) + 1, colptr(j + 1)
        kd = max(kd, abs(iperm(rowind(p) + 1) - iperm(j)))
      end do
    end do
  end function band_width

  !> RCM-order, store in band form and factorize with `dpbtrf`.
  !! err: ERR_NUMERICAL (not positive definite, LAPACK failure) or ERR_MEMORY.
  subroutine band_factor(self, n, colptr, rowind, val, err)
    class(band_t), intent(inout) :: self
    integer, intent(in) :: n              !< matrix order
    integer, intent(in) :: colptr(:)      !< column pointers, size n+1, 0-based (full symmetric)
    integer, intent(in) :: rowind(:)      !< row indices, 0-based
    real(wp), intent(in) :: val(:)        !< values
    type(error_t), intent(out) :: err     !< the failure, if any
    integer, allocatable :: iperm(:)
    integer :: j, p, ni, nj, st, lapinfo
    real(wp) :: t0
    character(len=160) :: emsg

    call self%free()
    t0 = wtime()
    self%n = n
    allocate (self%perm(n), iperm(n), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'banded Cholesky: out of memory for the RCM permutation.')
      return
    end if
    call rcm_order(n, colptr, rowind, self%perm)
    do j = 1, n
      iperm(self%perm(j)) = j
    end do
    self%kd = band_width(n, colptr, rowind, self%perm)
    if (int(self%kd + 1, i8) * int(n, i8) > int(huge(1), i8)) then
      write (emsg, '(a,i0,a,i0,a)') 'banded Cholesky: band storage (', self%kd + 1, ' x ', n, &
        ') is too large for 32-bit LAPACK indexing.'
      call err%set(ERR_MEMORY, emsg)
      return
    end if
    allocate (self%ab(self%kd + 1, n), stat=st)
    if (st /= 0) then
      write (emsg, '(a,i0,a,i0,a)') 'banded Cholesky: out of memory for band storage (', &
        self%kd + 1, ' x ', n, ').'
      call err%set(ERR_MEMORY, emsg)
      return
    end if
    self%ab = 0.0_wp
    do j = 1, n
      nj = iperm(j)
      do p = colptr(j) + 1, colptr(j + 1)
        ni = iperm(rowind(p) + 1)
        if (ni >= nj) self%ab(1 + ni - nj, nj) = val(p)
      end do
    end do
    self%t_order = wtime() - t0

    t0 = wtime()
    call dpbtrf('L', n, self%kd, self%ab, self%kd + 1, lapinfo)
    self%t_factor = wtime() - t0
    if (lapinfo > 0) then
      write (emsg, '(a,i0,a,i0,a)') 'banded Cholesky: matrix is not positive definite (leading minor ', &
        lapinfo, ', DOF ', self%perm(lapinfo), ').'
      call err%set(ERR_NUMERICAL, emsg)
      deallocate (self%ab)
      return
    else if (lapinfo < 0) then
      write (emsg, '(a,i0,a)') 'banded Cholesky: dpbtrf rejected argument ', -lapinfo, '.'
      call err%set(ERR_NUMERICAL, emsg)
      deallocate (self%ab)
      return
    end if
    self%factored = .true.
  end subroutine band_factor

  !> Solve K X = B in place (b is n x nrhs). err: ERR_MEMORY or ERR_NUMERICAL.
  subroutine band_solve(self, b, err)
    class(band_t), intent(in) :: self
    real(wp), intent(inout) :: b(:, :)    !< right-hand sides in, solutions out
    type(error_t), intent(out) :: err     !< the failure, if any
    real(wp), allocatable :: w(:, :)
    integer :: k, st, lapinfo
    if (.not. self%factored) then
      call err%set(ERR_NUMERICAL, 'banded Cholesky: solve called without a valid factorization.')
      return
    end if
    if (size(b, 1) /= self%n) then
      call err%set(ERR_NUMERICAL, 'banded Cholesky: right-hand side length differs from the matrix order.')
      return
    end if
    if (size(b, 2) == 0) return
    allocate (w(self%n, size(b, 2)), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'banded Cholesky: out of memory for the solve workspace.')
      return
    end if
    do k = 1, self%n
      w(k, :) = b(self%perm(k), :)
    end do
    call dpbtrs('L', self%n, self%kd, size(b, 2), self%ab, self%kd + 1, w, self%n, lapinfo)
    if (lapinfo /= 0) then
      call err%set(ERR_NUMERICAL, 'banded Cholesky: dpbtrs failed.')
      return
    end if
    do k = 1, self%n
      b(self%perm(k), :) = w(k, :)
    end do
  end subroutine band_solve

  !> Release the factor.
  subroutine band_free(self)
    class(band_t), intent(inout) :: self
    if (allocated(self%perm)) deallocate (self%perm)
    if (allocated(self%ab)) deallocate (self%ab)
    self%n = 0
    self%kd = -1
    self%factored = .false.
  end subroutine band_free

end module banded
