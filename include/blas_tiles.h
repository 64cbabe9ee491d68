/* blas_tiles.h: the dense kernels of a sparse factorization as tiles on the OpenMP team's
 * idle threads, bitwise the same for any thread count (src/linalg/blas_tiles.c). */
#ifndef BLAS_TILES_H
#define BLAS_TILES_H

/* Find the real BLAS/LAPACK routines (once per process; aborts naming a missing one). */
void bt_init(void);
/* From here on this thread's large dgemm/dsyrk/dtrsm/dpotrf calls run as tiles. */
void bt_begin(void);
/* Back to plain calls; returns the tiles this thread's calls made since bt_begin. */
long bt_end(void);
/* A task's body on this thread with plain calls (the thread may be inside a tiled call,
 * taking the task at its taskwait): the state before, for bt_resume. */
int bt_pause(void);
void bt_resume(int was);
/* dpotrf as tiles (lower, n > 2 TILE) wherever it is called, the caller's state unchanged
 * (Fortran: lapack's dpotrf_tiles). */
void dpotrf_tiles_(const char *uplo, const int *n, double *a, const int *lda, int *info);

#endif
