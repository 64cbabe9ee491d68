!> Fortran side of the CHOLMOD shim (src/linalg/cholmod_shim.c, include/cholmod_shim.h):
!! `bind(c)` interfaces and thin typed wrappers around an opaque handle.
!! One handle holds one factorization with its own CHOLMOD workspace, so two
!! threads may use two different handles at once (never one handle from two
!! threads). Nothing of CHOLMOD's own types is visible here.
module cholmod_iface
  use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_associated, c_int, &
                                         c_double, c_char, c_null_char
  use kinds, only: wp
  implicit none (type, external)
  private

  integer, parameter, public :: CM_OK = 0             !< success
  integer, parameter, public :: CM_NOT_POSDEF = 1     !< matrix not positive definite
  integer, parameter, public :: CM_OUT_OF_MEMORY = 2  !< out of memory / too large
  integer, parameter, public :: CM_FAILURE = 3        !< any other failure

  integer, parameter, public :: CM_ORD_METIS = 1      !< METIS nested dissection
  integer, parameter, public :: CM_ORD_AMD = 2        !< (constrained) approximate minimum degree
  integer, parameter, public :: CM_ORD_NATURAL = 3    !< natural order (interface last if given)
  integer, parameter, public :: CM_ORD_GIVEN = 4      !< interior order given by the caller, interface last
  integer, parameter, public :: CM_ORD_AUTO = 6       !< CHOLMOD's own choice (AMD, METIS if AMD fills much), nothing last

  integer, parameter :: MSG_LEN = 512

  !> Statistics of one factorization (mirror of `chsh_stats`, not of any CHOLMOD type).
  type, bind(c), public :: cm_stats_t
    real(c_double) :: t_analyze = 0   !< ordering + symbolic analysis wall time [s]
    real(c_double) :: t_factor = 0    !< numeric factorization wall time [s]
    real(c_double) :: lnz = 0         !< nnz(L) without supernodal padding
    real(c_double) :: lsize = 0       !< entries stored in the supernodal L
    real(c_double) :: flops = 0       !< LL' flop count
    real(c_double) :: mem_peak = 0    !< peak CHOLMOD memory of the handle [bytes]
    real(c_double) :: mem_inuse = 0   !< CHOLMOD memory in use [bytes]
    real(c_double) :: tiles = 0       !< dense-kernel tiles of the numeric factorization (blas_tiles.c)
    real(c_double) :: t_order = 0     !< wall time of the interface-last permutation, part of t_analyze [s]
    integer(c_int) :: n = 0           !< matrix order
    integer(c_int) :: nlast = 0       !< number of DOFs requested last
    integer(c_int) :: last_ok = 0     !< 1 if the factor's permutation ends with them, in order
    integer(c_int) :: is_super = 0    !< 1 if the factor is supernodal
    !> the CHOLMOD ordering its analysis kept (CHOLMOD's codes: 1 given, 2 AMD, 3 METIS), -1 before one
    integer(c_int) :: ordering_used = -1
  end type cm_stats_t

  public :: cm_init, cm_create, cm_factorize, cm_solve, cm_trailing_block, cm_get_stats, &
            cm_release_workspace, cm_free, cm_metis_order

  interface
    function chsh_create(h, msg, msglen) bind(c, name='chsh_create') result(code)
      import :: c_ptr, c_int, c_char
      type(c_ptr), intent(out) :: h
      character(kind=c_char), intent(out) :: msg(*)
      integer(c_int), value :: msglen
      integer(c_int) :: code
    end function chsh_create

    function chsh_factorize(h, n, colptr, rowind, val, ordering, nlast, last, interior, msg, msglen) &
        bind(c, name='chsh_factorize') result(code)
      import :: c_ptr, c_int, c_double, c_char
      type(c_ptr), value :: h
      integer(c_int), value :: n
      integer(c_int), intent(in) :: colptr(*), rowind(*)
      real(c_double), intent(in) :: val(*)
      integer(c_int), value :: ordering, nlast
      integer(c_int), intent(in) :: last(*)
      integer(c_int), intent(in), optional :: interior(*)   ! absent: NULL
      character(kind=c_char), intent(out) :: msg(*)
      integer(c_int), value :: msglen
      integer(c_int) :: code
    end function chsh_factorize

    function chsh_metis_order(n, colptr, rowind, perm, msg, msglen) bind(c, name='chsh_metis_order') result(code)
      import :: c_int, c_char
      integer(c_int), value :: n
      integer(c_int), intent(in) :: colptr(*), rowind(*)
      integer(c_int), intent(out) :: perm(*)
      character(kind=c_char), intent(out) :: msg(*)
      integer(c_int), value :: msglen
      integer(c_int) :: code
    end function chsh_metis_order

    function chsh_solve(h, nrhs, b, ldb, msg, msglen) bind(c, name='chsh_solve') result(code)
      import :: c_ptr, c_int, c_double, c_char
      type(c_ptr), value :: h
      integer(c_int), value :: nrhs
      real(c_double), intent(inout) :: b(*)
      integer(c_int), value :: ldb
      character(kind=c_char), intent(out) :: msg(*)
      integer(c_int), value :: msglen
      integer(c_int) :: code
    end function chsh_solve

    subroutine chsh_release_workspace(h) bind(c, name='chsh_release_workspace')
      import :: c_ptr
      type(c_ptr), value :: h
    end subroutine chsh_release_workspace

    function chsh_trailing_block(h, m, lg, ldlg, msg, msglen) &
        bind(c, name='chsh_trailing_block') result(code)
      import :: c_ptr, c_int, c_double, c_char
      type(c_ptr), value :: h
      integer(c_int), value :: m
      real(c_double), intent(out) :: lg(*)
      integer(c_int), value :: ldlg
      character(kind=c_char), intent(out) :: msg(*)
      integer(c_int), value :: msglen
      integer(c_int) :: code
    end function chsh_trailing_block

    function chsh_get_stats(h, st) bind(c, name='chsh_get_stats') result(code)
      import :: c_ptr, c_int, cm_stats_t
      type(c_ptr), value :: h
      type(cm_stats_t), intent(out) :: st
      integer(c_int) :: code
    end function chsh_get_stats

    subroutine chsh_init() bind(c, name='chsh_init')
    end subroutine chsh_init

    subroutine chsh_free(h) bind(c, name='chsh_free')
      import :: c_ptr
      type(c_ptr), intent(inout) :: h
    end subroutine chsh_free
  end interface

contains

  !> Convert a NUL-terminated C buffer into a Fortran string.
  pure function c_to_f(buf) result(s)
    character(kind=c_char), intent(in) :: buf(:)
    character(len=:), allocatable :: s
    integer :: k, l
    l = 0
    do k = 1, size(buf)
      if (buf(k) == c_null_char) exit
      l = k
    end do
    allocate (character(len=l) :: s)
    do k = 1, l
      s(k:k) = buf(k)
    end do
  end function c_to_f

  !> Hold OpenBLAS to one thread (once per process; safe to call repeatedly and
  !! from several threads). Parallelism is over the bodies, with OpenMP.
  subroutine cm_init()
    call chsh_init()
  end subroutine cm_init

  !> Create an empty handle (idempotent: an existing handle is kept).
  subroutine cm_create(h, info, msg)
    type(c_ptr), intent(inout) :: h          !< handle (c_null_ptr on entry for a new one)
    integer, intent(out) :: info             !< CM_* code
    character(len=*), intent(out) :: msg     !< one sentence on failure, else blank
    character(kind=c_char) :: buf(MSG_LEN)
    msg = ''
    info = CM_OK
    if (c_associated(h)) return
    info = chsh_create(h, buf, MSG_LEN)
    if (info /= CM_OK) msg = c_to_f(buf)
  end subroutine cm_create

  !> Analyze and factorize a symmetric positive definite matrix (full symmetric CSC,
  !! 0-based, rows sorted). `last0` (0-based, may be empty) lists DOFs to order last.
  !! With CM_ORD_GIVEN, `interior0` (0-based, size n - size(last0)) is the order of
  !! all the other DOFs; it is required then and ignored otherwise. Module cholesky
  !! checks the arguments (with the user-facing messages); the shim checks again that
  !! the interior order is given and is a permutation of the other DOFs.
  subroutine cm_factorize(h, n, colptr, rowind, val, ordering, last0, info, msg, interior0)
    type(c_ptr), intent(in) :: h                  !< handle from cm_create
    integer, intent(in) :: n                      !< matrix order
    integer(c_int), intent(in) :: colptr(:)       !< column pointers, size n+1, 0-based
    integer(c_int), intent(in) :: rowind(:)       !< row indices, 0-based
    real(wp), intent(in) :: val(:)                !< values
    integer, intent(in) :: ordering               !< CM_ORD_*
    integer(c_int), intent(in) :: last0(:)        !< DOFs to order last, 0-based, in order
    integer, intent(out) :: info                  !< CM_* code
    character(len=*), intent(out) :: msg          !< one sentence on failure, else blank
    integer(c_int), intent(in), optional :: interior0(:)  !< interior order, 0-based (CM_ORD_GIVEN)
    character(kind=c_char) :: buf(MSG_LEN)
    msg = ''
    if (ordering == CM_ORD_GIVEN) then
      info = chsh_factorize(h, int(n, c_int), colptr, rowind, val, int(ordering, c_int), &
                            int(size(last0), c_int), last0, interior0, buf, MSG_LEN)
    else
      info = chsh_factorize(h, int(n, c_int), colptr, rowind, val, int(ordering, c_int), &
                            int(size(last0), c_int), last0, msg=buf, msglen=MSG_LEN)
    end if
    if (info /= CM_OK) msg = c_to_f(buf)
  end subroutine cm_factorize

  !> METIS nested dissection (postordered) of the graph of a symmetric pattern: n vertices,
  !! CSC 0-based with rows sorted in each column, the strictly upper triangle read; perm0(k)
  !! is the vertex (0-based) placed k-th, checked to be a permutation. Serialized with every
  !! other METIS call of the process; needs no handle.
  subroutine cm_metis_order(n, colptr, rowind, perm0, info, msg)
    integer, intent(in) :: n                      !< vertices
    integer(c_int), intent(in) :: colptr(:)       !< column pointers, size n+1, 0-based
    integer(c_int), intent(in) :: rowind(:)       !< row indices, 0-based (size >= 1)
    integer(c_int), intent(out) :: perm0(:)       !< (n) the order, 0-based
    integer, intent(out) :: info                  !< CM_* code
    character(len=*), intent(out) :: msg          !< one sentence on failure, else blank
    character(kind=c_char) :: buf(MSG_LEN)
    msg = ''
    if (size(colptr) < n + 1 .or. size(perm0) < n .or. size(rowind) < 1) then
      info = CM_FAILURE
      msg = 'cm_metis_order: the graph''s arrays are shorter than its size.'
      return
    end if
    info = chsh_metis_order(int(n, c_int), colptr, rowind, perm0, buf, MSG_LEN)
    if (info /= CM_OK) msg = c_to_f(buf)
  end subroutine cm_metis_order

  !> Solve K X = B in place for the columns of `b` (n x nrhs).
  subroutine cm_solve(h, b, info, msg)
    type(c_ptr), intent(in) :: h                        !< factorized handle
    real(wp), contiguous, intent(inout) :: b(:, :)      !< right-hand sides in, solutions out
    integer, intent(out) :: info                        !< CM_* code
    character(len=*), intent(out) :: msg                !< one sentence on failure
    character(kind=c_char) :: buf(MSG_LEN)
    msg = ''
    info = chsh_solve(h, int(size(b, 2), c_int), b, int(max(1, size(b, 1)), c_int), buf, MSG_LEN)
    if (info /= CM_OK) msg = c_to_f(buf)
  end subroutine cm_solve

  !> Copy the trailing m x m diagonal block of the Cholesky factor L (lower triangle).
  subroutine cm_trailing_block(h, lg, info, msg)
    type(c_ptr), intent(in) :: h                        !< factorized handle
    real(wp), contiguous, intent(out) :: lg(:, :)       !< m x m block, zeros above the diagonal
    integer, intent(out) :: info                        !< CM_* code
    character(len=*), intent(out) :: msg                !< one sentence on failure
    character(kind=c_char) :: buf(MSG_LEN)
    msg = ''
    if (size(lg, 1) /= size(lg, 2)) then
      info = CM_FAILURE
      msg = 'cm_trailing_block: the output block is not square.'
      return
    end if
    info = chsh_trailing_block(h, int(size(lg, 1), c_int), lg, int(max(1, size(lg, 1)), c_int), &
                               buf, MSG_LEN)
    if (info /= CM_OK) msg = c_to_f(buf)
  end subroutine cm_trailing_block

  !> Statistics of the handle's last factorization (zeros for a null handle).
  function cm_get_stats(h) result(st)
    type(c_ptr), intent(in) :: h   !< handle
    type(cm_stats_t) :: st
    integer(c_int) :: code
    if (.not. c_associated(h)) return
    code = chsh_get_stats(h, st)
  end function cm_get_stats

  !> Release the solve workspace kept between solves.
  subroutine cm_release_workspace(h)
    type(c_ptr), intent(in) :: h   !< handle
    if (c_associated(h)) call chsh_release_workspace(h)
  end subroutine cm_release_workspace

  !> Free the handle and everything it owns; `h` becomes c_null_ptr.
  subroutine cm_free(h)
    type(c_ptr), intent(inout) :: h   !< handle
    if (c_associated(h)) call chsh_free(h)
    h = c_null_ptr
  end subroutine cm_free

end module cholmod_iface
