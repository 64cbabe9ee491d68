/* cholmod_shim.h: a thin C layer over CHOLMOD (int API, supernodal LL').
 *
 * One opaque handle per matrix/factor.  Each handle owns its own
 * cholmod_common, so two threads may work on two different handles at the
 * same time; one handle must not be used by two threads at once.
 *
 * Every function returns one of the CHSH_* codes and, on failure, writes one
 * NUL-terminated sentence into msg (at most msglen bytes, msglen >= 1).
 * All index arrays are 0-based C int; dense arrays are column-major.
 */
#ifndef CHOLMOD_SHIM_H
#define CHOLMOD_SHIM_H

#ifdef __cplusplus
extern "C" {
#endif

/* status codes (module cholmod_iface turns them into an error_t) */
#define CHSH_OK             0
#define CHSH_NOT_POSDEF     1
#define CHSH_OUT_OF_MEMORY  2
#define CHSH_FAILURE        3

/* fill-reducing orderings: module cholmod_iface's ORD_* values (its cm_create checks
 * them and the status codes against its own through chsh_codes) */
#define CHSH_ORD_METIS      1
#define CHSH_ORD_AMD        2
#define CHSH_ORD_NATURAL    3
#define CHSH_ORD_GIVEN      4   /* interior order given by the caller */
/* (5 is module cholmod_iface's ORD_NODES: module cholesky computes the interior order
 * itself, METIS on the node graph through chsh_metis_order, and hands it over as
 * CHSH_ORD_GIVEN) */
#define CHSH_ORD_AUTO       6   /* CHOLMOD's own choice (nmethods = 0); no DOFs last */

typedef struct chsh_factor chsh_factor;   /* opaque */

/* The codes above, in the order CHSH_OK, CHSH_NOT_POSDEF, CHSH_OUT_OF_MEMORY, CHSH_FAILURE,
 * CHSH_ORD_METIS, CHSH_ORD_AMD, CHSH_ORD_NATURAL, CHSH_ORD_GIVEN, CHSH_ORD_AUTO, into
 * codes[0 .. ncodes-1] (at most those nine; the rest is set to -1): module cholmod_iface
 * compares them with its own constants, the one place where the two are checked equal. */
void chsh_codes(int *codes, int ncodes);

/* Statistics of the last analysis/factorization of a handle. */
typedef struct chsh_stats {
    double t_analyze;     /* wall time of ordering + symbolic analysis [s] */
    double t_factor;      /* wall time of numeric factorization [s] */
    double lnz;           /* nnz(L), fundamental (no supernodal padding) */
    double lsize;         /* entries stored in the supernodal L (with padding) */
    double flops;         /* LL' flop count (Common->fl) */
    double mem_peak;      /* peak CHOLMOD memory of this handle [bytes] */
    double mem_inuse;     /* CHOLMOD memory in use now [bytes] */
    double tiles;         /* dense-kernel tiles the numeric factorization ran (blas_tiles.h) */
    double t_order;       /* wall time of the interface-last permutation, part of t_analyze
                             (METIS or CAMD of the interior, the check of a given order) [s] */
    int    n;             /* matrix order */
    int    nlast;         /* number of DOFs requested last */
    int    last_ok;       /* 1 if L->Perm ends with exactly those DOFs, in order */
    int    is_super;      /* 1 if L is supernodal */
    int    ordering_used; /* the CHOLMOD ordering the analysis kept (CHOLMOD_GIVEN 1,
                             CHOLMOD_AMD 2, CHOLMOD_METIS 3, ...), -1 before one */
} chsh_stats;

/* Hold OpenBLAS to one thread (done once per process; parallelism is over
 * the bodies with OpenMP).  Called by chsh_create; call it before any other
 * BLAS/LAPACK work that may run in two threads at once. */
void chsh_init(void);

/* Create an empty handle (calls chsh_init). */
int chsh_create(chsh_factor **h, char *msg, int msglen);

/* Analyze + factorize a symmetric positive definite matrix given in full
 * symmetric CSC (both triangles; only the upper triangle is read).
 * colptr[n+1], rowind[colptr[n]], val[colptr[n]]; rows sorted per column.
 * ordering: CHSH_ORD_* (CHSH_ORD_AUTO only with nlast == 0).  last[nlast]
 * (may be NULL when nlast == 0): DOFs to be ordered last, in this order (the
 * interface).  interior[n - nlast]: with CHSH_ORD_GIVEN, the order of all the
 * other DOFs (a permutation of the DOFs not in `last`), followed by `last`;
 * ignored (may be NULL) otherwise.  A previous factor in the handle is
 * released first. */
int chsh_factorize(chsh_factor *h, int n, const int *colptr, const int *rowind,
                   const double *val, int ordering, int nlast, const int *last,
                   const int *interior, char *msg, int msglen);

/* METIS nested dissection of the graph of a symmetric pattern (n x n CSC, 0-based,
 * rows sorted in each column; only the strictly upper triangle is read, the diagonal
 * may be there or not): perm[k] is the vertex placed k-th, postordered by the
 * elimination tree (cholmod_metis).  A graph partitioner's ordering of a body's node
 * graph; serialized with every other METIS call of the process (METIS draws from libc's
 * global rand()).  Needs no handle. */
int chsh_metis_order(int n, const int *colptr, const int *rowind, int *perm,
                     char *msg, int msglen);

/* Solve K X = B in place: b is n x nrhs with leading dimension ldb >= n. */
int chsh_solve(chsh_factor *h, int nrhs, double *b, int ldb,
               char *msg, int msglen);

/* Release the solve workspace kept between solves (it is kept to make
 * repeated solves with the same nrhs cheap). */
void chsh_release_workspace(chsh_factor *h);

/* Copy the trailing m x m diagonal block of L (lower triangle, zeros above)
 * into lg (column-major, leading dimension ldlg >= m).  Row/column i of the
 * block is DOF last[i] when stats.last_ok is 1. */
int chsh_trailing_block(chsh_factor *h, int m, double *lg, int ldlg,
                        char *msg, int msglen);

/* Fill *st with the statistics of the handle. */
int chsh_get_stats(const chsh_factor *h, chsh_stats *st);

/* Free everything owned by the handle and set *h to NULL (NULL is fine). */
void chsh_free(chsh_factor **h);

#ifdef __cplusplus
}
#endif
#endif /* CHOLMOD_SHIM_H */
