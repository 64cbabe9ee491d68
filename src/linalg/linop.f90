!> Linear operators y = A x behind one abstract type, so that an iterative solver
!! (MPRGP) does not know whether it multiplies by a dense matrix, a sparse one or
!! a sequence of Cholesky solves.
!!
!! Thread safety: `apply` of the types below touches only the operator itself and
!! its arguments (no module state). Two threads may apply two different operators
!! concurrently; one operator must not be applied by two threads at once (the
!! binding takes `intent(inout)` so that extensions may keep work space).
module linop
  use kinds, only: wp
  use lapack, only: dsymv
  use errors, only: error_t, ERR_INPUT
  use strings, only: i2s
  implicit none (type, external)
  private

  public :: linop_t, dense_op_t, csc_op_t, dense_op_init, dense_op_take, csc_op_init, symmetrize

  !> An abstract symmetric linear operator of size `n`.
  type, abstract :: linop_t
    integer :: n = 0  !< number of rows = number of columns
  contains
    procedure(linop_apply_iface), deferred :: apply  !< y = A x
  end type linop_t

  abstract interface
    !> Compute y = A x. `x` and `y` have size `self%n` and must not alias.
    subroutine linop_apply_iface(self, x, y)
      import :: linop_t, wp
      class(linop_t), intent(inout) :: self  !< the operator
      real(wp), intent(in) :: x(:)           !< input vector (size n)
      real(wp), intent(out) :: y(:)          !< output vector A x (size n)
    end subroutine linop_apply_iface
  end interface

  !> Dense symmetric n x n matrix in full storage; applied by BLAS dsymv
  !! (upper triangle used, so the operator is exactly symmetric even if the
  !! stored matrix is symmetric only up to rounding).
  type, extends(linop_t) :: dense_op_t
    real(wp), allocatable :: a(:,:)  !< the matrix (n x n, both triangles stored)
  contains
    procedure :: apply => dense_apply
  end type dense_op_t

  public :: csc_symv

  !> Sparse symmetric matrix in compressed sparse column form, both triangles
  !! stored, 0-based indices (CHOLMOD/SciPy convention).
  type, extends(linop_t) :: csc_op_t
    integer, allocatable :: colptr(:)  !< column starts, size n+1, 0-based
    integer, allocatable :: rowind(:)  !< row indices, size nnz, 0-based
    real(wp), allocatable :: val(:)    !< values, size nnz
  contains
    procedure :: apply => csc_apply
  end type csc_op_t

contains

  !> Make `op` a dense operator holding a copy of the square matrix `a`.
  !! `err` (optional): a matrix that is not square (op%n is then 0).
  subroutine dense_op_init(op, a, err)
    type(dense_op_t), intent(out) :: op      !< the operator to set up
    real(wp), intent(in) :: a(:,:)           !< symmetric matrix, full storage
    type(error_t), intent(out), optional :: err   !< a matrix that is not square
    if (size(a, 1) /= size(a, 2)) then
      if (present(err)) call err%set(ERR_INPUT, 'dense operator: the matrix is '//i2s(size(a, 1))//' x '// &
                                     i2s(size(a, 2))//', not square')
      op%n = 0
      allocate (op%a(0, 0))
      return
    end if
    op%n = size(a, 1)
    allocate (op%a(op%n, op%n), source=a)
  end subroutine dense_op_init

  !> a = (a + a')/2 in place, block by block (a large matrix's transpose in one sweep
  !! reads it a row at a time across memory): every entry the number 0.5 (a + a') gives.
  subroutine symmetrize(a)
    real(wp), intent(inout) :: a(:, :)      !< square
    integer, parameter :: BLK = 64
    integer :: n, ib, jb, i, j
    real(wp) :: v
    n = size(a, 1)
    do jb = 1, n, BLK
      do ib = jb, n, BLK
        do j = jb, min(jb + BLK - 1, n)
          do i = max(ib, j + 1), min(ib + BLK - 1, n)
            v = 0.5_wp*(a(i, j) + a(j, i))
            a(i, j) = v
            a(j, i) = v
          end do
        end do
      end do
    end do
  end subroutine symmetrize

  !> Make `op` a dense operator of the square matrix `a`, taking its storage (no copy;
  !! `a` is deallocated on return).
  subroutine dense_op_take(op, a)
    type(dense_op_t), intent(out) :: op          !< the operator to set up
    real(wp), allocatable, intent(inout) :: a(:, :) !< symmetric square matrix, full storage
    if (.not. allocated(a)) allocate (a(0, 0))
    op%n = size(a, 1)
    call move_alloc(a, op%a)
  end subroutine dense_op_take

  !> y = A x for a dense operator (BLAS dsymv).
  subroutine dense_apply(self, x, y)
    class(dense_op_t), intent(inout) :: self  !< the operator
    real(wp), intent(in) :: x(:)              !< input vector (size n)
    real(wp), intent(out) :: y(:)             !< output A x (size n)
    if (self%n == 0) return
    call dsymv('U', self%n, 1.0_wp, self%a, self%n, x, 1, 0.0_wp, y, 1)
  end subroutine dense_apply

  !> Make `op` a CSC operator holding copies of the arrays (0-based indices).
  !! `err` (optional): bad n or colptr, or a row index out of range (op%n is then 0 and the
  !! operator is empty).
  subroutine csc_op_init(op, n, colptr, rowind, val, err)
    type(csc_op_t), intent(out) :: op       !< the operator to set up
    integer, intent(in) :: n                !< matrix size
    integer, intent(in) :: colptr(:)        !< size n+1, 0-based, nondecreasing
    integer, intent(in) :: rowind(:)        !< 0-based row indices
    real(wp), intent(in) :: val(:)          !< values
    type(error_t), intent(out), optional :: err   !< a bad structure or an index out of range
    integer :: j, nnz, ierr
    ierr = 0
    if (n < 0 .or. size(colptr) /= n + 1) then
      ierr = 1
    else if (colptr(1) /= 0) then
      ierr = 1
    else
      nnz = colptr(n + 1)
      if (size(rowind) < nnz .or. size(val) < nnz) ierr = 1
      do j = 1, n
        if (colptr(j + 1) < colptr(j)) ierr = 1
      end do
      if (ierr == 0) then
        if (nnz > 0) then
          if (minval(rowind(1:nnz)) < 0 .or. maxval(rowind(1:nnz)) >= n) ierr = 2
        end if
      end if
    end if
    if (ierr /= 0) then
      if (present(err)) then
        if (ierr == 1) then
          call err%set(ERR_INPUT, 'sparse operator: bad n or column pointers')
        else
          call err%set(ERR_INPUT, 'sparse operator: a row index out of range')
        end if
      end if
      op%n = 0
      allocate (op%colptr(1), op%rowind(0), op%val(0))
      op%colptr = 0
      return
    end if
    op%n = n
    allocate (op%colptr(n + 1), source=colptr)
    allocate (op%rowind(nnz), source=rowind(1:nnz))
    allocate (op%val(nnz), source=val(1:nnz))
  end subroutine csc_op_init

  !> y = A x for a CSC operator (both triangles stored).
  subroutine csc_apply(self, x, y)
    class(csc_op_t), intent(inout) :: self  !< the operator
    real(wp), intent(in) :: x(:)            !< input vector (size n)
    real(wp), intent(out) :: y(:)           !< output A x (size n)
    call csc_symv(self%n, self%colptr, self%rowind, self%val, x, y)
  end subroutine csc_apply

  !> y = A x for a symmetric n x n matrix in compressed sparse columns, both triangles
  !! stored, 0-based indices: y(j) is column j (= row j) dotted with x, summed in the
  !! stored row order. The one sparse product of the code (csc_op_t, assembly's
  !! csc_matvec). For a matrix that is not symmetric this is A^T x.
  pure subroutine csc_symv(n, colptr, rowind, val, x, y)
    integer, intent(in) :: n              !< matrix size
    integer, intent(in) :: colptr(:)      !< (n+1) column starts, 0-based
    integer, intent(in) :: rowind(:)      !< (nnz) row indices, 0-based
    real(wp), intent(in) :: val(:)        !< (nnz) values
    real(wp), intent(in) :: x(:)          !< (n) input vector
    real(wp), intent(out) :: y(:)         !< (n) output A x
    integer :: j, p
    real(wp) :: acc
    do j = 1, n
      acc = 0.0_wp
      do p = colptr(j) + 1, colptr(j + 1)
        acc = acc + val(p)*x(rowind(p) + 1)
      end do
      y(j) = acc
    end do
  end subroutine csc_symv

end module linop
