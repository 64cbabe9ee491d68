/* blas_tiles.c: the dense kernels of a body's sparse factorization on the threads the bodies
 * leave idle, with results that do not depend on how many there are.
 *
 * CHOLMOD's supernodal factorization spends its time in four BLAS/LAPACK calls: dsyrk and
 * dgemm (a descendant's update of a supernode), dpotrf (its diagonal block) and dtrsm (the
 * rows below it). A threaded OpenBLAS would run them on more cores, but it splits a call
 * into pieces that depend on its thread count, so every count rounds differently (measured:
 * a 360,000-DOF factor solved to a different last bit at 1, 2, 3, 4 and 8 threads). Here a
 * large call is cut into tiles whose sizes depend only on the call's dimensions (TILE rows
 * and columns of the result; dpotrf by blocks of TILE columns, right-looking), each tile is
 * one single-threaded call of the real routine, and the tiles are OpenMP tasks. Whichever
 * thread runs a tile, it computes the same numbers: the factor is bitwise the same for any
 * number of threads, and no thread is added to the team the user gave (OMP_NUM_THREADS).
 *
 * The routines below replace dgemm_, dsyrk_, dtrsm_ and dpotrf_ for the whole program (the
 * executable's definitions come first in the dynamic linker's search, so CHOLMOD's calls
 * reach them); the real ones are found with dlsym(RTLD_NEXT). A call is tiled only between
 * bt_begin() and bt_end() on the calling thread (the shim's numeric factorization); every
 * other call (our own LAPACK use, MUMPS, CHOLMOD's solves) goes straight to the real
 * routine, unchanged. Tiles run wherever the OpenMP team has an idle thread: a body loop
 * of `parallel do` over fewer bodies than threads leaves threads at its barrier, where they
 * take the tasks; inside no parallel region the tiles run one after the other.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <stddef.h>
#include "blas_tiles.h"

/* the tile: rows and columns of a result block, and dpotrf's block size; a call is cut
 * when it has more than TILE rows or columns and at least MIN_FLOPS multiply-adds */
#ifndef TILE
#define TILE 256
#endif
#ifndef MIN_FLOPS
#define MIN_FLOPS 4.0e6
#endif

typedef void gemm_fn(const char *, const char *, const int *, const int *, const int *, const double *,
                     const double *, const int *, const double *, const int *, const double *, double *,
                     const int *, size_t, size_t);
typedef void syrk_fn(const char *, const char *, const int *, const int *, const double *, const double *,
                     const int *, const double *, double *, const int *, size_t, size_t);
typedef void trsm_fn(const char *, const char *, const char *, const char *, const int *, const int *,
                     const double *, const double *, const int *, double *, const int *, size_t, size_t,
                     size_t, size_t);
typedef void potrf_fn(const char *, const int *, double *, const int *, int *, size_t);

static gemm_fn *real_gemm;
static syrk_fn *real_syrk;
static trsm_fn *real_trsm;
static potrf_fn *real_potrf;
static pthread_once_t found_once = PTHREAD_ONCE_INIT;

static _Thread_local int tiles_on;       /* this thread is in a factorization */
static _Thread_local long tiles_run;     /* tiles this thread's calls made since bt_begin */

static void *next_symbol(const char *name)
{
    void *f = dlsym(RTLD_NEXT, name);
    if (f == NULL) {   /* a BLAS linked statically into the program would leave nothing to call */
        fprintf(stderr, "robin_contact: internal error: the BLAS/LAPACK routine %s was not found "
                        "in the shared libraries (%s)\n", name, dlerror());
        abort();
    }
    return f;
}

static void find_real(void)
{
    real_gemm = (gemm_fn *) next_symbol("dgemm_");
    real_syrk = (syrk_fn *) next_symbol("dsyrk_");
    real_trsm = (trsm_fn *) next_symbol("dtrsm_");
    real_potrf = (potrf_fn *) next_symbol("dpotrf_");
}

static void found(void)
{
    pthread_once(&found_once, find_real);
}

void bt_init(void)
{
    found();
}

void bt_begin(void)
{
    found();
    tiles_on = 1;
    tiles_run = 0;
}

long bt_end(void)
{
    tiles_on = 0;
    return tiles_run;
}

int bt_pause(void)
{
    int was = tiles_on;
    tiles_on = 0;
    return was;
}

void bt_resume(int was)
{
    tiles_on = was;
}

static int is_n(const char *t)
{
    return *t == 'N' || *t == 'n';
}

static int nblocks(int n)
{
    return (n + TILE - 1) / TILE;
}

static int tile_len(int n, int b)
{
    int rest = n - b * TILE;
    return rest < TILE ? rest : TILE;
}

static int worth_cutting(int rows, int cols, int inner)
{
    return (rows > TILE || cols > TILE) && (double) rows * (double) cols * (double) inner >= MIN_FLOPS;
}

/* ---- the tiled kernels (each tile a task; a taskwait ends each call) ---- */

static void tiled_gemm(const char *ta, const char *tb, int m, int n, int k, double alpha, const double *a,
                       int lda, const double *b, int ldb, double beta, double *c, int ldc)
{
    int bi, bj, nbi = nblocks(m), nbj = nblocks(n);
    tiles_run += (long) nbi * nbj;
    for (bj = 0; bj < nbj; bj++)
        for (bi = 0; bi < nbi; bi++) {
#pragma omp task firstprivate(bi, bj) default(shared)
            {
                int i0 = bi * TILE, j0 = bj * TILE, mi = tile_len(m, bi), nj = tile_len(n, bj);
                const double *ai = is_n(ta) ? a + i0 : a + (size_t) i0 * lda;
                const double *bj0 = is_n(tb) ? b + (size_t) j0 * ldb : b + j0;
                real_gemm(ta, tb, &mi, &nj, &k, &alpha, ai, &lda, bj0, &ldb, &beta, c + i0 + (size_t) j0 * ldc,
                          &ldc, 1, 1);
            }
        }
#pragma omp taskwait
}

/* C = alpha op(A) op(A)' + beta C on the uplo triangle: diagonal tiles by dsyrk, the others by
 * dgemm (trans 'N': A is n x k; otherwise k x n) */
static void tiled_syrk(const char *uplo, const char *trans, int n, int k, double alpha, const double *a,
                       int lda, double beta, double *c, int ldc)
{
    int bi, bj, nb = nblocks(n), lower = (*uplo == 'L' || *uplo == 'l');
    tiles_run += (long) nb * (nb + 1) / 2;
    for (bj = 0; bj < nb; bj++)
        for (bi = lower ? bj : 0; lower ? bi < nb : bi <= bj; bi++) {
#pragma omp task firstprivate(bi, bj) default(shared)
            {
                int i0 = bi * TILE, j0 = bj * TILE, mi = tile_len(n, bi), nj = tile_len(n, bj);
                double *cij = c + i0 + (size_t) j0 * ldc;
                if (bi == bj) {
                    const double *aj = is_n(trans) ? a + j0 : a + (size_t) j0 * lda;
                    real_syrk(uplo, trans, &nj, &k, &alpha, aj, &lda, &beta, cij, &ldc, 1, 1);
                } else if (is_n(trans)) {
                    real_gemm("N", "T", &mi, &nj, &k, &alpha, a + i0, &lda, a + j0, &lda, &beta, cij, &ldc, 1, 1);
                } else {
                    real_gemm("T", "N", &mi, &nj, &k, &alpha, a + (size_t) i0 * lda, &lda, a + (size_t) j0 * lda,
                              &lda, &beta, cij, &ldc, 1, 1);
                }
            }
        }
#pragma omp taskwait
}

/* B = alpha op(A)^-1 B (side L: the columns of B are independent) or alpha B op(A)^-1
 * (side R: its rows are) */
static void tiled_trsm(const char *side, const char *uplo, const char *ta, const char *diag, int m, int n,
                       double alpha, const double *a, int lda, double *b, int ldb)
{
    int left = (*side == 'L' || *side == 'l');
    int t, nt = nblocks(left ? n : m);
    tiles_run += nt;
    for (t = 0; t < nt; t++) {
#pragma omp task firstprivate(t) default(shared)
        {
            int len = tile_len(left ? n : m, t);
            if (left)
                real_trsm(side, uplo, ta, diag, &m, &len, &alpha, a, &lda, b + (size_t) t * TILE * ldb, &ldb,
                          1, 1, 1, 1);
            else
                real_trsm(side, uplo, ta, diag, &len, &n, &alpha, a, &lda, b + (size_t) t * TILE, &ldb,
                          1, 1, 1, 1);
        }
    }
#pragma omp taskwait
}

/* A = L L' (lower), right-looking by blocks of TILE columns: the diagonal block by the real
 * dpotrf, the panel below by tiled dtrsm, the trailing matrix by tiled dsyrk */
static void tiled_potrf_lower(int n, double *a, int lda, int *info)
{
    int j0, jb, rest;
    const double one = 1.0, minus_one = -1.0;
    *info = 0;
    for (j0 = 0; j0 < n; j0 += TILE) {
        double *ajj = a + j0 + (size_t) j0 * lda;
        jb = n - j0 < TILE ? n - j0 : TILE;
        real_potrf("L", &jb, ajj, &lda, info, 1);
        tiles_run++;
        if (*info != 0) {
            if (*info > 0) *info += j0;
            return;
        }
        rest = n - j0 - jb;
        if (rest == 0) break;
        tiled_trsm("R", "L", "T", "N", rest, jb, one, ajj, lda, ajj + jb, lda);
        tiled_syrk("L", "N", rest, jb, minus_one, ajj + jb, lda, one, ajj + jb + (size_t) jb * lda, lda);
    }
}

/* ---- the replacements (Fortran calling convention; trailing string lengths ignored) ---- */

void dgemm_(const char *ta, const char *tb, const int *m, const int *n, const int *k, const double *alpha,
            const double *a, const int *lda, const double *b, const int *ldb, const double *beta, double *c,
            const int *ldc)
{
    found();
    if (tiles_on && worth_cutting(*m, *n, *k))
        tiled_gemm(ta, tb, *m, *n, *k, *alpha, a, *lda, b, *ldb, *beta, c, *ldc);
    else
        real_gemm(ta, tb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc, 1, 1);
}

void dsyrk_(const char *uplo, const char *trans, const int *n, const int *k, const double *alpha,
            const double *a, const int *lda, const double *beta, double *c, const int *ldc)
{
    found();
    if (tiles_on && worth_cutting(*n, *n, *k))
        tiled_syrk(uplo, trans, *n, *k, *alpha, a, *lda, *beta, c, *ldc);
    else
        real_syrk(uplo, trans, n, k, alpha, a, lda, beta, c, ldc, 1, 1);
}

void dtrsm_(const char *side, const char *uplo, const char *ta, const char *diag, const int *m, const int *n,
            const double *alpha, const double *a, const int *lda, double *b, const int *ldb)
{
    int left = (*side == 'L' || *side == 'l');
    found();
    if (tiles_on && worth_cutting(*m, *n, left ? *m : *n))
        tiled_trsm(side, uplo, ta, diag, *m, *n, *alpha, a, *lda, b, *ldb);
    else
        real_trsm(side, uplo, ta, diag, m, n, alpha, a, lda, b, ldb, 1, 1, 1, 1);
}

void dpotrf_(const char *uplo, const int *n, double *a, const int *lda, int *info)
{
    found();
    if (tiles_on && (*uplo == 'L' || *uplo == 'l') && *n > 2 * TILE && *lda >= *n)
        tiled_potrf_lower(*n, a, *lda, info);
    else
        real_potrf(uplo, n, a, lda, info, 1);
}

/* A = L L' of one dense matrix outside a factorization, as tiles on the team's idle threads
 * (the same numbers for any thread count); a small or upper one goes to the real dpotrf. The
 * calling thread's state (inside a factorization or not, its tile count) is left as it was. */
void dpotrf_tiles_(const char *uplo, const int *n, double *a, const int *lda, int *info)
{
    int was = tiles_on;
    long run = tiles_run;
    found();
    tiles_on = 1;
    dpotrf_(uplo, n, a, lda, info);
    tiles_on = was;
    if (!was) tiles_run = run;
}
