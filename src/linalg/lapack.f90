!> Explicit interfaces for every BLAS and LAPACK routine robin_contact calls (reference
!! BLAS/LAPACK signatures, 32-bit integers, double precision), so that a wrong argument
!! is a compile-time error instead of a crash. Linked against OpenBLAS and LAPACK.
!!
!! Thread safety: the routines keep no state; module cholmod_iface (`cm_init`) holds
!! OpenBLAS to one thread so that two OpenMP threads may call them at once.
module lapack
  use kinds, only: wp
  use iso_c_binding, only: c_long, c_int
  implicit none (type, external)
  private

  public :: dsymv, dgemm, dgemv, dsyrk, dtrsm, dtrsv
  public :: dpotrf, dpotrf_tiles, dpotrs, dpotri, dposv, dpocon, dpstrf, dsyev, dsyevd, dsyevr
  public :: dpbtrf, dpbtrs, dpbsv
  public :: dgels, dgesv, dsygv, dgesvd, dgeqrf, dorgqr, dsytrf
  public :: tiles_begin, tiles_end, tiles_pause, tiles_resume

  interface

    ! ---- BLAS ----

    !> y := alpha A x + beta y, A symmetric n x n (triangle `uplo` referenced).
    subroutine dsymv(uplo, n, alpha, a, lda, x, incx, beta, y, incy)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo  !< 'U' or 'L': the stored triangle of A
      integer, intent(in) :: n              !< order of A
      integer, intent(in) :: lda            !< leading dimension of a, >= max(1, n)
      integer, intent(in) :: incx           !< stride of x
      integer, intent(in) :: incy           !< stride of y
      real(wp), intent(in) :: alpha         !< scale of A x
      real(wp), intent(in) :: a(lda, *)     !< the matrix
      real(wp), intent(in) :: x(*)          !< input vector
      real(wp), intent(in) :: beta          !< scale of y on entry
      real(wp), intent(inout) :: y(*)       !< output vector
    end subroutine dsymv

    !> C := alpha op(A) op(B) + beta C; op(A) is m x k, op(B) is k x n.
    subroutine dgemm(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc)
      import :: wp
      implicit none
      character(len=1), intent(in) :: transa  !< 'N' or 'T': op(A) = A or A'
      character(len=1), intent(in) :: transb  !< 'N' or 'T': op(B) = B or B'
      integer, intent(in) :: m                !< rows of op(A) and C
      integer, intent(in) :: n                !< columns of op(B) and C
      integer, intent(in) :: k                !< columns of op(A), rows of op(B)
      integer, intent(in) :: lda              !< leading dimension of a
      integer, intent(in) :: ldb              !< leading dimension of b
      integer, intent(in) :: ldc              !< leading dimension of c, >= max(1, m)
      real(wp), intent(in) :: alpha           !< scale of op(A) op(B)
      real(wp), intent(in) :: a(lda, *)       !< matrix A
      real(wp), intent(in) :: b(ldb, *)       !< matrix B
      real(wp), intent(in) :: beta            !< scale of C on entry
      real(wp), intent(inout) :: c(ldc, *)    !< matrix C, m x n
    end subroutine dgemm

    !> y := alpha op(A) x + beta y; A is m x n.
    subroutine dgemv(trans, m, n, alpha, a, lda, x, incx, beta, y, incy)
      import :: wp
      implicit none
      character(len=1), intent(in) :: trans   !< 'N' or 'T': op(A) = A or A'
      integer, intent(in) :: m, n             !< rows and columns of A
      integer, intent(in) :: lda              !< leading dimension of a
      integer, intent(in) :: incx, incy       !< strides of x and y
      real(wp), intent(in) :: alpha, beta     !< scales
      real(wp), intent(in) :: a(lda, *)       !< matrix A
      real(wp), intent(in) :: x(*)            !< vector x
      real(wp), intent(inout) :: y(*)         !< vector y
    end subroutine dgemv

    !> C := alpha A A' + beta C (trans 'N'), the uplo triangle of the n x n C; A is n x k.
    subroutine dsyrk(uplo, trans, n, k, alpha, a, lda, beta, c, ldc)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo    !< 'U' or 'L': the triangle of C referenced
      character(len=1), intent(in) :: trans   !< 'N': A A'; 'T': A' A
      integer, intent(in) :: n, k             !< order of C, the other dimension of A
      integer, intent(in) :: lda, ldc         !< leading dimensions
      real(wp), intent(in) :: alpha, beta     !< scales
      real(wp), intent(in) :: a(lda, *)       !< matrix A
      real(wp), intent(inout) :: c(ldc, *)    !< matrix C
    end subroutine dsyrk

    !> B := alpha op(A)^-1 B (side 'L'), A triangular m x m, B m x n.
    subroutine dtrsm(side, uplo, transa, diag, m, n, alpha, a, lda, b, ldb)
      import :: wp
      implicit none
      character(len=1), intent(in) :: side, uplo, transa, diag   !< 'L'/'R', 'U'/'L', 'N'/'T', 'N'/'U'
      integer, intent(in) :: m, n             !< rows and columns of B
      integer, intent(in) :: lda, ldb         !< leading dimensions
      real(wp), intent(in) :: alpha           !< scale
      real(wp), intent(in) :: a(lda, *)       !< the triangular matrix
      real(wp), intent(inout) :: b(ldb, *)    !< right-hand sides in, solutions out
    end subroutine dtrsm

    !> x := op(A)^-1 x, A triangular n x n.
    subroutine dtrsv(uplo, trans, diag, n, a, lda, x, incx)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo, trans, diag   !< 'U'/'L', 'N'/'T', 'N'/'U'
      integer, intent(in) :: n, lda, incx     !< order, leading dimension, stride
      real(wp), intent(in) :: a(lda, *)       !< the triangular matrix
      real(wp), intent(inout) :: x(*)         !< right-hand side in, solution out
    end subroutine dtrsv

    ! ---- LAPACK: symmetric positive definite, full storage ----

    !> Cholesky factorization A = U'U or L L' in place.
    !! info: 0 ok; < 0 argument -info illegal; > 0 leading minor info not positive definite.
    subroutine dpotrf(uplo, n, a, lda, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo  !< 'U' or 'L': the triangle stored and factorized
      integer, intent(in) :: n              !< order of A
      integer, intent(in) :: lda            !< leading dimension of a, >= max(1, n)
      integer, intent(out) :: info          !< status (see above)
      real(wp), intent(inout) :: a(lda, *)  !< A on entry, its Cholesky factor on exit
    end subroutine dpotrf

    !> From here on the calling thread's large dgemm, dsyrk, dtrsm and dpotrf (lower) calls
    !! run as tiles, OpenMP tasks of the real routine that idle threads of the team take
    !! (src/linalg/blas_tiles.c): the results are the same for any thread count (and round
    !! differently from the routines' own blocking). Until tiles_end.
    subroutine tiles_begin() bind(c, name='bt_begin')
    end subroutine tiles_begin

    !> Back to plain calls on the calling thread; the tiles its calls made since tiles_begin.
    function tiles_end() result(n) bind(c, name='bt_end')
      import :: c_long
      integer(c_long) :: n
    end function tiles_end

    !> The calling thread's calls plain until tiles_resume (an OpenMP task's body: the thread
    !! that runs it may be inside a tiled call, taking the task at its wait, and the task's
    !! numbers must not depend on that); the state before.
    function tiles_pause() result(was) bind(c, name='bt_pause')
      import :: c_int
      integer(c_int) :: was
    end function tiles_pause

    !> The state tiles_pause returned, back.
    subroutine tiles_resume(was) bind(c, name='bt_resume')
      import :: c_int
      integer(c_int), value :: was
    end subroutine tiles_resume

    !> dpotrf whose lower factor of an order above two tiles is made as OpenMP tasks of the
    !! real routine (src/linalg/blas_tiles.c): idle threads of the team help, and the factor is
    !! the same for any thread count (it rounds differently from dpotrf's own blocking).
    subroutine dpotrf_tiles(uplo, n, a, lda, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo  !< 'U' or 'L' (only 'L' is tiled)
      integer, intent(in) :: n              !< order of A
      integer, intent(in) :: lda            !< leading dimension of a, >= max(1, n)
      integer, intent(out) :: info          !< as dpotrf's
      real(wp), intent(inout) :: a(lda, *)  !< A on entry, its Cholesky factor on exit
    end subroutine dpotrf_tiles

    !> Cholesky factorization with complete pivoting of a symmetric positive semidefinite A:
    !! P' A P = L L', its numerical rank in `rank` (pivots below tol stop it). info = 1 when
    !! A is rank deficient (rank < n), < 0 for a bad argument.
    subroutine dpstrf(uplo, n, a, lda, piv, rank, tol, work, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo  !< 'U' or 'L'
      integer, intent(in) :: n              !< order of A
      integer, intent(in) :: lda            !< leading dimension of a
      real(wp), intent(inout) :: a(lda, *)  !< A on entry, the factor on exit
      integer, intent(out) :: piv(*)        !< (n) the permutation
      integer, intent(out) :: rank          !< numerical rank
      real(wp), intent(in) :: tol           !< pivot tolerance (< 0: n eps max|A_kk|)
      real(wp), intent(out) :: work(*)      !< (2n) workspace
      integer, intent(out) :: info          !< status
    end subroutine dpstrf

    !> Singular values (descending) of a general A and, as asked, its left (U) and right (VT)
    !! singular vectors. lwork = -1: workspace query. info > 0: no convergence.
    subroutine dgesvd(jobu, jobvt, m, n, a, lda, s, u, ldu, vt, ldvt, work, lwork, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: jobu   !< 'N': no U, 'A': all of U
      character(len=1), intent(in) :: jobvt  !< 'N': no VT, 'A': all of VT
      integer, intent(in) :: m, n            !< rows and columns of A
      integer, intent(in) :: lda, ldu, ldvt  !< leading dimensions
      real(wp), intent(inout) :: a(lda, *)   !< A on entry, destroyed
      real(wp), intent(out) :: s(*)          !< (min(m, n)) singular values, descending
      real(wp), intent(out) :: u(ldu, *)     !< left singular vectors (jobu = 'A')
      real(wp), intent(out) :: vt(ldvt, *)   !< right singular vectors as rows (jobvt = 'A')
      real(wp), intent(out) :: work(*)       !< (lwork) workspace
      integer, intent(in) :: lwork           !< size of work (-1: query)
      integer, intent(out) :: info           !< status
    end subroutine dgesvd

    !> Eigenvalues (ascending) and, with jobz = 'V', orthonormal eigenvectors of a symmetric A.
    !! lwork = -1: workspace query (the optimal size in work(1)). info > 0: no convergence.
    subroutine dsyev(jobz, uplo, n, a, lda, w, work, lwork, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: jobz  !< 'N' eigenvalues only, 'V' also eigenvectors
      character(len=1), intent(in) :: uplo  !< 'U' or 'L'
      integer, intent(in) :: n              !< order of A
      integer, intent(in) :: lda            !< leading dimension of a
      real(wp), intent(inout) :: a(lda, *)  !< A on entry, the eigenvectors (jobz = 'V') on exit
      real(wp), intent(out) :: w(*)         !< (n) eigenvalues, ascending
      real(wp), intent(out) :: work(*)      !< (lwork) workspace
      integer, intent(in) :: lwork          !< size of work (-1: query)
      integer, intent(out) :: info          !< status
    end subroutine dsyev

    !> Eigenvalues (ascending) and, with jobz = 'V', orthonormal eigenvectors of a symmetric A
    !! by divide and conquer (several times faster than dsyev for all eigenvectors).
    !! lwork = liwork = -1: workspace query (sizes in work(1), iwork(1)). info > 0: failure.
    subroutine dsyevd(jobz, uplo, n, a, lda, w, work, lwork, iwork, liwork, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: jobz  !< 'N' eigenvalues only, 'V' also eigenvectors
      character(len=1), intent(in) :: uplo  !< 'U' or 'L'
      integer, intent(in) :: n              !< order of A
      integer, intent(in) :: lda            !< leading dimension of a
      real(wp), intent(inout) :: a(lda, *)  !< A on entry, the eigenvectors (jobz = 'V') on exit
      real(wp), intent(out) :: w(*)         !< (n) eigenvalues, ascending
      real(wp), intent(out) :: work(*)      !< (lwork) workspace
      integer, intent(in) :: lwork          !< size of work (-1: query)
      integer, intent(out) :: iwork(*)      !< (liwork) workspace
      integer, intent(in) :: liwork         !< size of iwork (-1: query)
      integer, intent(out) :: info          !< status
    end subroutine dsyevd

    !> Selected eigenvalues (ascending) and eigenvectors of a symmetric A: with range = 'I'
    !! those of indices il..iu (bisection and inverse iteration on the tridiagonal form for a
    !! subset, the relatively robust representations for all), O(n^3) for the reduction only
    !! (a few of n eigenvectors cost a small part of dsyev's).
    !! lwork = liwork = -1: workspace query (sizes in work(1), iwork(1)). info > 0: failure.
    subroutine dsyevr(jobz, range, uplo, n, a, lda, vl, vu, il, iu, abstol, m, w, z, ldz, isuppz, &
                      work, lwork, iwork, liwork, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: jobz   !< 'N' eigenvalues only, 'V' also eigenvectors
      character(len=1), intent(in) :: range  !< 'A' all, 'V' in (vl, vu], 'I' indices il..iu
      character(len=1), intent(in) :: uplo   !< 'U' or 'L'
      integer, intent(in) :: n               !< order of A
      integer, intent(in) :: lda             !< leading dimension of a
      real(wp), intent(inout) :: a(lda, *)   !< A on entry, destroyed on exit
      real(wp), intent(in) :: vl, vu         !< the interval (range = 'V')
      integer, intent(in) :: il, iu          !< the indices (range = 'I'), 1 <= il <= iu <= n
      real(wp), intent(in) :: abstol         !< absolute tolerance (0: LAPACK's default)
      integer, intent(out) :: m              !< eigenvalues found
      real(wp), intent(out) :: w(*)          !< (n) the eigenvalues found, ascending, in w(1:m)
      integer, intent(in) :: ldz             !< leading dimension of z
      real(wp), intent(out) :: z(ldz, *)     !< (n, m) orthonormal eigenvectors (jobz = 'V')
      integer, intent(out) :: isuppz(*)      !< (2 max(1, m)) support of the eigenvectors
      real(wp), intent(out) :: work(*)       !< (lwork) workspace
      integer, intent(in) :: lwork           !< size of work (-1: query)
      integer, intent(out) :: iwork(*)       !< (liwork) workspace
      integer, intent(in) :: liwork          !< size of iwork (-1: query)
      integer, intent(out) :: info           !< status
    end subroutine dsyevr

    !> A = L D L' (uplo 'L') of a symmetric matrix by Bunch-Kaufman pivoting: D block diagonal
    !! with 1x1 and 2x2 blocks (ipiv(k) > 0: a 1x1 block at k; ipiv(k) = ipiv(k+1) < 0: a 2x2
    !! block at k, k+1). lwork = -1: workspace query. info > 0: D(info, info) is exactly zero.
    subroutine dsytrf(uplo, n, a, lda, ipiv, work, lwork, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo   !< 'U' or 'L'
      integer, intent(in) :: n               !< order of A
      integer, intent(in) :: lda             !< leading dimension of a
      real(wp), intent(inout) :: a(lda, *)   !< A on entry; D and the multipliers on exit
      integer, intent(out) :: ipiv(*)        !< (n) the pivots and block structure
      real(wp), intent(inout) :: work(*)     !< (lwork) workspace
      integer, intent(in) :: lwork           !< size of work (-1: query)
      integer, intent(out) :: info           !< status
    end subroutine dsytrf

    !> QR factorization A = Q R of an m x n matrix (Householder): R in the upper triangle,
    !! Q as reflectors below it and in tau (dorgqr forms it).
    !! lwork = -1: workspace query (size in work(1)). info < 0: a bad argument.
    subroutine dgeqrf(m, n, a, lda, tau, work, lwork, info)
      import :: wp
      implicit none
      integer, intent(in) :: m               !< rows of A
      integer, intent(in) :: n               !< columns of A
      integer, intent(in) :: lda             !< leading dimension of a, >= max(1, m)
      real(wp), intent(inout) :: a(lda, *)   !< A on entry; R and the reflectors on exit
      real(wp), intent(out) :: tau(*)        !< (min(m, n)) the reflectors' scales
      real(wp), intent(inout) :: work(*)     !< (lwork) workspace
      integer, intent(in) :: lwork           !< size of work (-1: query)
      integer, intent(out) :: info           !< status
    end subroutine dgeqrf

    !> The m x n matrix Q with orthonormal columns from dgeqrf's k reflectors (n <= m).
    !! lwork = -1: workspace query (size in work(1)). info < 0: a bad argument.
    subroutine dorgqr(m, n, k, a, lda, tau, work, lwork, info)
      import :: wp
      implicit none
      integer, intent(in) :: m               !< rows of Q
      integer, intent(in) :: n               !< columns of Q, <= m
      integer, intent(in) :: k               !< reflectors, <= n
      integer, intent(in) :: lda             !< leading dimension of a, >= max(1, m)
      real(wp), intent(inout) :: a(lda, *)   !< dgeqrf's reflectors on entry; Q on exit
      real(wp), intent(in) :: tau(*)         !< (k) dgeqrf's scales
      real(wp), intent(inout) :: work(*)     !< (lwork) workspace
      integer, intent(in) :: lwork           !< size of work (-1: query)
      integer, intent(out) :: info           !< status
    end subroutine dorgqr

    !> Solve A X = B with the Cholesky factor from dpotrf.
    subroutine dpotrs(uplo, n, nrhs, a, lda, b, ldb, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo  !< 'U' or 'L', as given to dpotrf
      integer, intent(in) :: n              !< order of A
      integer, intent(in) :: nrhs           !< number of right-hand sides
      integer, intent(in) :: lda            !< leading dimension of a
      integer, intent(in) :: ldb            !< leading dimension of b, >= max(1, n)
      integer, intent(out) :: info          !< 0 ok; < 0 argument -info illegal
      real(wp), intent(in) :: a(lda, *)     !< the Cholesky factor
      real(wp), intent(inout) :: b(ldb, *)  !< right-hand sides in, solutions out (n x nrhs)
    end subroutine dpotrs

    !> Inverse of A from its Cholesky factor (dpotrf), in place (triangle `uplo`).
    subroutine dpotri(uplo, n, a, lda, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo  !< 'U' or 'L', as given to dpotrf
      integer, intent(in) :: n              !< order of A
      integer, intent(in) :: lda            !< leading dimension of a, >= max(1, n)
      integer, intent(out) :: info          !< 0 ok; < 0 argument -info illegal; > 0 singular factor
      real(wp), intent(inout) :: a(lda, *)  !< the factor on entry, the triangle of A^-1 on exit
    end subroutine dpotri

    !> Solve A X = B, A symmetric positive definite (dpotrf + dpotrs).
    subroutine dposv(uplo, n, nrhs, a, lda, b, ldb, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo  !< 'U' or 'L': the triangle of A referenced
      integer, intent(in) :: n              !< order of A
      integer, intent(in) :: nrhs           !< number of right-hand sides
      integer, intent(in) :: lda            !< leading dimension of a, >= max(1, n)
      integer, intent(in) :: ldb            !< leading dimension of b, >= max(1, n)
      integer, intent(out) :: info          !< 0 ok; < 0 argument illegal; > 0 not positive definite
      real(wp), intent(inout) :: a(lda, *)  !< A on entry, its Cholesky factor on exit
      real(wp), intent(inout) :: b(ldb, *)  !< right-hand sides in, solutions out (n x nrhs)
    end subroutine dposv

    !> Estimate of the reciprocal 1-norm condition number from the Cholesky factor.
    subroutine dpocon(uplo, n, a, lda, anorm, rcond, work, iwork, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo  !< 'U' or 'L', as given to dpotrf
      integer, intent(in) :: n              !< order of A
      integer, intent(in) :: lda            !< leading dimension of a
      integer, intent(out) :: iwork(*)      !< workspace, size n
      integer, intent(out) :: info          !< 0 ok; < 0 argument -info illegal
      real(wp), intent(in) :: a(lda, *)     !< the Cholesky factor
      real(wp), intent(in) :: anorm         !< 1-norm of the original A
      real(wp), intent(out) :: rcond        !< 1 / (|A|_1 |A^-1|_1), estimated
      real(wp), intent(out) :: work(*)      !< workspace, size 3 n
    end subroutine dpocon

    ! ---- LAPACK: symmetric positive definite, band storage ----

    !> Cholesky factorization of a band matrix in place (kd sub- or super-diagonals).
    !! info: 0 ok; < 0 argument -info illegal; > 0 leading minor info not positive definite.
    subroutine dpbtrf(uplo, n, kd, ab, ldab, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo    !< 'U' or 'L': the triangle stored
      integer, intent(in) :: n                !< order of A
      integer, intent(in) :: kd               !< half-bandwidth
      integer, intent(in) :: ldab             !< leading dimension of ab, >= kd + 1
      integer, intent(out) :: info            !< status (see above)
      real(wp), intent(inout) :: ab(ldab, *)  !< A in band storage on entry, its factor on exit
    end subroutine dpbtrf

    !> Solve A X = B with the band Cholesky factor from dpbtrf.
    subroutine dpbtrs(uplo, n, kd, nrhs, ab, ldab, b, ldb, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo  !< 'U' or 'L', as given to dpbtrf
      integer, intent(in) :: n              !< order of A
      integer, intent(in) :: kd             !< half-bandwidth
      integer, intent(in) :: nrhs           !< number of right-hand sides
      integer, intent(in) :: ldab           !< leading dimension of ab, >= kd + 1
      integer, intent(in) :: ldb            !< leading dimension of b, >= max(1, n)
      integer, intent(out) :: info          !< 0 ok; < 0 argument -info illegal
      real(wp), intent(in) :: ab(ldab, *)   !< the band Cholesky factor
      real(wp), intent(inout) :: b(ldb, *)  !< right-hand sides in, solutions out (n x nrhs)
    end subroutine dpbtrs

    !> Solve A X = B, A symmetric positive definite in band storage (dpbtrf + dpbtrs).
    subroutine dpbsv(uplo, n, kd, nrhs, ab, ldab, b, ldb, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: uplo    !< 'U' or 'L': the triangle stored
      integer, intent(in) :: n                !< order of A
      integer, intent(in) :: kd               !< half-bandwidth
      integer, intent(in) :: nrhs             !< number of right-hand sides
      integer, intent(in) :: ldab             !< leading dimension of ab, >= kd + 1
      integer, intent(in) :: ldb              !< leading dimension of b, >= max(1, n)
      integer, intent(out) :: info            !< 0 ok; < 0 argument illegal; > 0 not positive definite
      real(wp), intent(inout) :: ab(ldab, *)  !< A in band storage on entry, its factor on exit
      real(wp), intent(inout) :: b(ldb, *)    !< right-hand sides in, solutions out (n x nrhs)
    end subroutine dpbsv

    !> Generalized symmetric-definite eigenproblem A x = lambda B x (itype 1), B positive
    !! definite; eigenvalues ascending in w, B-orthonormal eigenvectors in a (jobz 'V').
    subroutine dsygv(itype, jobz, uplo, n, a, lda, b, ldb, w, work, lwork, info)
      import :: wp
      implicit none
      integer, intent(in) :: itype, n, lda, ldb, lwork
      character(len=1), intent(in) :: jobz, uplo
      real(wp), intent(inout) :: a(lda, *), b(ldb, *)
      real(wp), intent(out) :: w(*), work(*)
      integer, intent(out) :: info
    end subroutine dsygv

    !> A X = B for a general square A by LU with partial pivoting.
    subroutine dgesv(n, nrhs, a, lda, ipiv, b, ldb, info)
      import :: wp
      implicit none
      integer, intent(in) :: n                !< order of A
      integer, intent(in) :: nrhs             !< number of right-hand sides
      integer, intent(in) :: lda              !< leading dimension of a, >= max(1, n)
      integer, intent(in) :: ldb              !< leading dimension of b, >= max(1, n)
      integer, intent(out) :: ipiv(*)         !< pivot indices (n)
      integer, intent(out) :: info            !< 0 ok; < 0 argument illegal; > 0 A singular
      real(wp), intent(inout) :: a(lda, *)    !< A on entry, its LU factors on exit
      real(wp), intent(inout) :: b(ldb, *)    !< right-hand sides in, solutions out (n x nrhs)
    end subroutine dgesv

    ! ---- LAPACK: least squares ----

    !> Least squares min |B - op(A) X| (or minimum norm) by QR/LQ of a full-rank A.
    !! lwork = -1: workspace query, the optimal lwork is returned in work(1).
    subroutine dgels(trans, m, n, nrhs, a, lda, b, ldb, work, lwork, info)
      import :: wp
      implicit none
      character(len=1), intent(in) :: trans  !< 'N': op(A) = A; 'T': op(A) = A'
      integer, intent(in) :: m               !< rows of A
      integer, intent(in) :: n               !< columns of A
      integer, intent(in) :: nrhs            !< number of right-hand sides
      integer, intent(in) :: lda             !< leading dimension of a, >= max(1, m)
      integer, intent(in) :: ldb             !< leading dimension of b, >= max(1, m, n)
      integer, intent(in) :: lwork           !< size of work, or -1 for a workspace query
      integer, intent(out) :: info           !< 0 ok; < 0 argument illegal; > 0 A rank deficient
      real(wp), intent(inout) :: a(lda, *)   !< A on entry, its QR or LQ factors on exit
      real(wp), intent(inout) :: b(ldb, *)   !< right-hand sides in, solutions out
      real(wp), intent(out) :: work(*)       !< workspace; work(1) = optimal lwork on exit
    end subroutine dgels

  end interface

end module lapack
