!> Fortran side of the CHOLMOD shim (src/linalg/cholmod_shim.c, include/cholmod_shim.h):
!! `bind(c)` interfaces and thin typed wrappers around an opaque handle.
!! One handle holds one factorization with its own CHOLMOD workspace, so two
!! threads may use two different handles at once (never one handle from two
!! threads). Nothing of CHOLMOD's own types is visible here; the shim's status
!! becomes an `error_t` here (out of memory or too large: ERR_MEMORY, else
!! ERR_NUMERICAL, with the shim's sentence).
!!
!! The fill-reducing orderings `ORD_*` are defined here, once, for every module that
!! factorizes (module cholesky hands them on): the shim takes the same numbers
!! (`CHSH_ORD_*`), which `cm_create` checks.
module cholmod_iface
  use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_associated, c_int, &
                                         c_double, c_char, c_null_char
  use kinds, only: wp
  use errors, only: error_t, ERR_NUMERICAL, ERR_MEMORY
  implicit none (type, external)
  private

  ! the shim's status codes (CHSH_*), turned into an error_t here
  integer, parameter :: CM_OK = 0             ! success
  integer, parameter :: CM_NOT_POSDEF = 1     ! matrix not positive definite
  integer, parameter :: CM_OUT_OF_MEMORY = 2  ! out of memory / too large
  integer, parameter :: CM_FAILURE = 3        ! any other failure

  integer, parameter, public :: ORD_METIS = 1      !< METIS nested dissection (CHOLMOD)
  integer, parameter, public :: ORD_AMD = 2        !< AMD, or CAMD when an interface is given
  integer, parameter, public :: ORD_NATURAL = 3    !< natural order (interface last if given)
  integer, parameter, public :: ORD_GIVEN = 4      !< caller's interior order (interior_perm), interface last
  !> METIS on the node graph (ordering%node_dissection: a solid body's nodes, from the pattern),
  !! interface last; module cholesky computes that order and hands it to the shim as ORD_GIVEN
  integer, parameter, public :: ORD_NODES = 5
  !> CHOLMOD's own analysis (its default strategy: AMD, and METIS too when AMD fills much; the
  !! better kept), nothing last: a reference for benchmarks
  integer, parameter, public :: ORD_AUTO = 6

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

  !> the number of codes chsh_codes gives
  integer, parameter :: NCODES = 9

  interface
    subroutine chsh_codes(codes, ncodes) bind(c, name='chsh_codes')
      import :: c_int
      integer(c_int), intent(out) :: codes(*)
      integer(c_int), value :: ncodes
    end subroutine chsh_codes

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

  !> The error for a shim status that is not CM_OK: the shim's sentence (NUL-terminated in
  !! buf) with ERR_MEMORY for out of memory (or too large), else ERR_NUMERICAL. Copies into a
  !! fixed-length text (no deferred-length function result: two threads call this at once).
  subroutine set_error(code, buf, err)
    integer, intent(in) :: code                      !< CM_* status, not CM_OK
    character(kind=c_char), intent(in) :: buf(:)     !< the shim's sentence
    type(error_t), intent(inout) :: err              !< receives the error
    character(len=MSG_LEN) :: text
    integer :: k
    text = ''
    do k = 1, min(size(buf), MSG_LEN)
      if (buf(k) == c_null_char) exit
      text(k:k) = buf(k)
    end do
    if (code == CM_OUT_OF_MEMORY) then
      call err%set(ERR_MEMORY, text)
    else
      call err%set(ERR_NUMERICAL, text)
    end if
  end subroutine set_error

  !> Hold OpenBLAS to one thread (once per process; safe to call repeatedly and
  !! from several threads). Parallelism is over the bodies, with OpenMP.
  subroutine cm_init()
    call chsh_init()
  end subroutine cm_init

  !> Create an empty handle (idempotent: an existing handle is kept). First checks that the
  !! shim's status and ordering codes are this module's (the one place they are compared).
  !! err: ERR_MEMORY, or ERR_NUMERICAL (CHOLMOD's failure, or codes that differ).
  subroutine cm_create(h, err)
    type(c_ptr), intent(inout) :: h          !< handle (c_null_ptr on entry for a new one)
    type(error_t), intent(out) :: err        !< the failure, if any
    character(kind=c_char) :: buf(MSG_LEN)
    integer(c_int) :: codes(NCODES)
    integer :: code
    call chsh_codes(codes, int(NCODES, c_int))
    if (any(codes /= [CM_OK, CM_NOT_POSDEF, CM_OUT_OF_MEMORY, CM_FAILURE, &
                      ORD_METIS, ORD_AMD, ORD_NATURAL, ORD_GIVEN, ORD_AUTO])) then
      call err%set(ERR_NUMERICAL, 'CHOLMOD shim: its status or ordering codes (include/cholmod_shim.h) '// &
                   'differ from module cholmod_iface''s.')
      return
    end if
    if (c_associated(h)) return
    code = chsh_create(h, buf, MSG_LEN)
    if (code /= CM_OK) call set_error(code, buf, err)
  end subroutine cm_create

  !> Analyze and factorize a symmetric positive definite matrix (full symmetric CSC,
  !! 0-based, rows sorted). `last0` (0-based, may be empty) lists DOFs to order last.
  !! With ORD_GIVEN, `interior0` (0-based, size n - size(last0)) is the order of
  !! all the other DOFs; it is required then and ignored otherwise (ORD_NODES is module
  !! cholesky's: it hands its node order over as ORD_GIVEN). Module cholesky
  !! checks the arguments (with the user-facing messages); the shim checks again that
  !! the interior order is given and is a permutation of the other DOFs.
  !! err: ERR_NUMERICAL (not positive definite, bad arguments, CHOLMOD failure) or ERR_MEMORY.
  subroutine cm_factorize(h, n, colptr, rowind, val, ordering, last0, err, interior0, not_posdef)
    type(c_ptr), intent(in) :: h                  !< handle from cm_create
    integer, intent(in) :: n                      !< matrix order
    integer(c_int), intent(in) :: colptr(:)       !< column pointers, size n+1, 0-based
    integer(c_int), intent(in) :: rowind(:)       !< row indices, 0-based
    real(wp), intent(in) :: val(:)                !< values
    integer, intent(in) :: ordering               !< ORD_METIS, ORD_AMD, ORD_NATURAL, ORD_GIVEN or ORD_AUTO
    integer(c_int), intent(in) :: last0(:)        !< DOFs to order last, 0-based, in order
    type(error_t), intent(out) :: err             !< the failure, if any
    integer(c_int), intent(in), optional :: interior0(:)  !< interior order, 0-based (ORD_GIVEN)
    !> true when the failure is a pivot <= 0 (the matrix is not positive definite)
    logical, intent(out), optional :: not_posdef
    character(kind=c_char) :: buf(MSG_LEN)
    integer :: code
    if (ordering == ORD_GIVEN) then
      code = chsh_factorize(h, int(n, c_int), colptr, rowind, val, int(ordering, c_int), &
                            int(size(last0), c_int), last0, interior0, buf, MSG_LEN)
    else
      code = chsh_factorize(h, int(n, c_int), colptr, rowind, val, int(ordering, c_int), &
                            int(size(last0), c_int), last0, msg=buf, msglen=MSG_LEN)
    end if
    if (present(not_posdef)) not_posdef = code == CM_NOT_POSDEF
    if (code /= CM_OK) call set_error(code, buf, err)
  end subroutine cm_factorize

  !> METIS nested dissection (postordered) of the graph of a symmetric pattern: n vertices,
  !! CSC 0-based with rows sorted in each column, the strictly upper triangle read; perm0(k)
  !! is the vertex (0-based) placed k-th, checked to be a permutation. Serialized with every
  !! other METIS call of the process; needs no handle. err: ERR_MEMORY or ERR_NUMERICAL.
  subroutine cm_metis_order(n, colptr, rowind, perm0, err)
    integer, intent(in) :: n                      !< vertices
    integer(c_int), intent(in) :: colptr(:)       !< column pointers, size n+1, 0-based
    integer(c_int), intent(in) :: rowind(:)       !< row indices, 0-based (size >= 1)
    integer(c_int), intent(out) :: perm0(:)       !< (n) the order, 0-based
    type(error_t), intent(out) :: err             !< the failure, if any
    character(kind=c_char) :: buf(MSG_LEN)
    integer :: code
    if (size(colptr) < n + 1 .or. size(perm0) < n .or. size(rowind) < 1) then
      call err%set(ERR_NUMERICAL, 'cm_metis_order: the graph''s arrays are shorter than its size.')
      return
    end if
    code = chsh_metis_order(int(n, c_int), colptr, rowind, perm0, buf, MSG_LEN)
    if (code /= CM_OK) call set_error(code, buf, err)
  end subroutine cm_metis_order

  !> Solve K X = B in place for the columns of `b` (n x nrhs). err: ERR_MEMORY or ERR_NUMERICAL.
  subroutine cm_solve(h, b, err)
    type(c_ptr), intent(in) :: h                        !< factorized handle
    real(wp), contiguous, intent(inout) :: b(:, :)      !< right-hand sides in, solutions out
    type(error_t), intent(out) :: err                   !< the failure, if any
    character(kind=c_char) :: buf(MSG_LEN)
    integer :: code
    code = chsh_solve(h, int(size(b, 2), c_int), b, int(max(1, size(b, 1)), c_int), buf, MSG_LEN)
    if (code /= CM_OK) call set_error(code, buf, err)
  end subroutine cm_solve

  !> Copy the trailing m x m diagonal block of the Cholesky factor L (lower triangle).
  !! err: ERR_MEMORY or ERR_NUMERICAL.
  subroutine cm_trailing_block(h, lg, err)
    type(c_ptr), intent(in) :: h                        !< factorized handle
    real(wp), contiguous, intent(out) :: lg(:, :)       !< m x m block, zeros above the diagonal
    type(error_t), intent(out) :: err                   !< the failure, if any
    character(kind=c_char) :: buf(MSG_LEN)
    integer :: code
    if (size(lg, 1) /= size(lg, 2)) then
      call err%set(ERR_NUMERICAL, 'cm_trailing_block: the output block is not square.')
      return
    end if
    code = chsh_trailing_block(h, int(size(lg, 1), c_int), lg, int(max(1, size(lg, 1)), c_int), &
                               buf, MSG_LEN)
    if (code /= CM_OK) call set_error(code, buf, err)
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
