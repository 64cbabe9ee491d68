/* cholmod_shim.c: thin C layer over CHOLMOD for module cholmod_iface.
 *
 * One opaque handle per factor, each with its own cholmod_common (so two
 * OpenMP threads can factorize two matrices at once).  Only the int API
 * (cholmod_*) is used.  Every CHOLMOD status is translated into a CHSH_* code
 * and one sentence; CHOLMOD_NOT_POSDEF, which CHOLMOD reports as a warning,
 * is a failure here.
 *
 * Interface-last ordering: the DOFs in `last` are placed at the end of the
 * permutation, in the order given, after a fill-reducing ordering of the
 * other ("interior") DOFs:
 *   METIS   - cholmod_metis (postordered) of the interior submatrix
 *             (serialized across threads, see metis_lock);
 *   AMD     - cholmod_camd on the whole matrix with constraint sets
 *             0 = interior, 1 = interface, interface entries then re-listed
 *             in the given order;
 *   NATURAL - interior in increasing index order;
 *   GIVEN   - interior in the caller's order (e.g. geometric nested
 *             dissection, or METIS on a solid body's node graph through
 *             chsh_metis_order; checked to be a permutation of the interior).
 * The permutation is handed to cholmod_analyze_p as CHOLMOD_GIVEN with the
 * etree postorder switched off (a postorder could move interior columns
 * behind interface ones).  After the analysis the tail of L->Perm is
 * compared with `last`; the result is reported in chsh_stats.last_ok.
 * AUTO (no DOFs last) is CHOLMOD's own analysis with its default strategy
 * (nmethods = 0: AMD, and METIS too when AMD's fill is high; the better kept).
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <pthread.h>

#include "cholmod.h"
#include "cholmod_shim.h"
#include "blas_tiles.h"

#ifndef TRUE
#define TRUE 1
#endif
#ifndef FALSE
#define FALSE 0
#endif

/* OpenBLAS: parallelism is over the bodies (OpenMP), so BLAS uses 1 thread. */
extern void openblas_set_num_threads(int num_threads);

struct chsh_factor {
    cholmod_common c;       /* private to this handle */
    cholmod_factor *L;      /* symbolic or numeric factor, or NULL */
    cholmod_dense *X, *Y, *E;   /* solve workspace (cholmod_solve2) */
    int factored;           /* 1 once L holds a valid numeric factor */
    chsh_stats st;
};

static pthread_once_t blas_once = PTHREAD_ONCE_INIT;

/* METIS 5.1 (GKlib) draws its random numbers from the C library's global
 * rand()/srand() state, so two METIS orderings running at once in two threads
 * interfere (different, non-reproducible orderings; a data race).  Every call
 * that may run METIS holds this lock; the rest of CHOLMOD runs unlocked. */
static pthread_mutex_t metis_lock = PTHREAD_MUTEX_INITIALIZER;
/* OpenBLAS (the pthreads build) starts its pool of threads when it is loaded, and they spin
 * in sched_yield for a while before they sleep: on the cores the bodies' OpenMP threads need
 * in the first phase. With BLAS held to one thread they are never used: stop them (a build
 * without the pool has no such function). */
extern int blas_thread_shutdown_(void) __attribute__((weak));
static void blas_one_thread(void)
{
    openblas_set_num_threads(1);
    if (blas_thread_shutdown_) blas_thread_shutdown_();
}

void chsh_init(void)
{
    pthread_once(&blas_once, blas_one_thread);
    bt_init();
}

void chsh_codes(int *codes, int ncodes)
{
    static const int all[] = {CHSH_OK, CHSH_NOT_POSDEF, CHSH_OUT_OF_MEMORY, CHSH_FAILURE,
                              CHSH_ORD_METIS, CHSH_ORD_AMD, CHSH_ORD_NATURAL, CHSH_ORD_GIVEN,
                              CHSH_ORD_AUTO};
    int k;
    for (k = 0; k < ncodes; k++)
        codes[k] = k < (int) (sizeof all / sizeof all[0]) ? all[k] : -1;
}

static void set_msg(char *msg, int msglen, const char *fmt, ...)
{
    va_list ap;
    if (msg == NULL || msglen <= 0) return;
    va_start(ap, fmt);
    vsnprintf(msg, (size_t) msglen, fmt, ap);
    va_end(ap);
}

/* Translate Common->status after a call named `what`. */
static int translate(const cholmod_common *c, const char *what,
                     char *msg, int msglen)
{
    switch (c->status) {
    case CHOLMOD_OK:
    case CHOLMOD_DSMALL:        /* warning only: tiny diagonal (LDL'), accept */
        return CHSH_OK;
    case CHOLMOD_NOT_POSDEF:
        set_msg(msg, msglen, "CHOLMOD %s: matrix is not positive definite.", what);
        return CHSH_NOT_POSDEF;
    case CHOLMOD_OUT_OF_MEMORY:
        set_msg(msg, msglen, "CHOLMOD %s: out of memory.", what);
        return CHSH_OUT_OF_MEMORY;
    case CHOLMOD_TOO_LARGE:
        set_msg(msg, msglen, "CHOLMOD %s: problem too large for 32-bit integer CHOLMOD.", what);
        return CHSH_OUT_OF_MEMORY;
    case CHOLMOD_NOT_INSTALLED:
        set_msg(msg, msglen, "CHOLMOD %s: required CHOLMOD module not installed.", what);
        return CHSH_FAILURE;
    case CHOLMOD_INVALID:
        set_msg(msg, msglen, "CHOLMOD %s: invalid input.", what);
        return CHSH_FAILURE;
    default:
        if (c->status > 0) return CHSH_OK;     /* other warnings: accept */
        set_msg(msg, msglen, "CHOLMOD %s: failed with status %d.", what, c->status);
        return CHSH_FAILURE;
    }
}

static void release_factor(chsh_factor *h)
{
    chsh_release_workspace(h);
    if (h->L != NULL) cholmod_free_factor(&h->L, &h->c);
    h->factored = 0;
}

void chsh_release_workspace(chsh_factor *h)
{
    if (h == NULL) return;
    if (h->X != NULL) cholmod_free_dense(&h->X, &h->c);
    if (h->Y != NULL) cholmod_free_dense(&h->Y, &h->c);
    if (h->E != NULL) cholmod_free_dense(&h->E, &h->c);
}

int chsh_create(chsh_factor **h, char *msg, int msglen)
{
    chsh_factor *f;
    set_msg(msg, msglen, "%s", "");
    if (h == NULL) {
        set_msg(msg, msglen, "chsh_create: NULL handle pointer.");
        return CHSH_FAILURE;
    }
    *h = NULL;
    chsh_init();
    f = (chsh_factor *) calloc(1, sizeof(chsh_factor));
    if (f == NULL) {
        set_msg(msg, msglen, "chsh_create: out of memory for the handle.");
        return CHSH_OUT_OF_MEMORY;
    }
    if (!cholmod_start(&f->c)) {
        int code = translate(&f->c, "start", msg, msglen);
        free(f);
        return code == CHSH_OK ? CHSH_FAILURE : code;
    }
    f->c.print = 0;                         /* we translate every status */
    f->c.supernodal = CHOLMOD_SUPERNODAL;   /* trailing block read from supernodes */
    f->c.final_asis = FALSE;
    f->c.final_super = TRUE;
    f->c.final_ll = TRUE;
    f->c.final_pack = TRUE;
    f->c.final_monotonic = TRUE;
    f->c.quick_return_if_not_posdef = TRUE;
    *h = f;
    return CHSH_OK;
}

/* Wrap the caller's CSC arrays (no copy); stype = +1: upper part is read. */
static void wrap_sparse(cholmod_sparse *A, int n, const int *colptr,
                        const int *rowind, const double *val)
{
    memset(A, 0, sizeof(*A));
    A->nrow = (size_t) n;
    A->ncol = (size_t) n;
    A->nzmax = (size_t) (colptr[n] > 0 ? colptr[n] : 1);
    A->p = (void *) colptr;
    A->i = (void *) rowind;
    A->nz = NULL;
    A->x = (void *) val;
    A->z = NULL;
    A->stype = 1;
    A->itype = CHOLMOD_INT;
    A->xtype = (val != NULL) ? CHOLMOD_REAL : CHOLMOD_PATTERN;
    A->dtype = CHOLMOD_DOUBLE;
    A->sorted = TRUE;
    A->packed = TRUE;
}

/* Build the interface-last permutation perm[n] (see the file header). */
static int build_last_perm(chsh_factor *h, cholmod_sparse *A, int n,
                           const int *colptr, const int *rowind, int ordering,
                           int nlast, const int *last, const int *interior,
                           int *perm, char *msg, int msglen)
{
    cholmod_common *c = &h->c;
    int ni = n - nlast, k, j, p, code = CHSH_OK;
    int *is_last = (int *) calloc((size_t) n, sizeof(int));
    int *inter = (int *) malloc((size_t) (ni > 0 ? ni : 1) * sizeof(int));
    int *work = NULL, *newidx = NULL;
    cholmod_sparse *S = NULL;

    if (is_last == NULL || inter == NULL) {
        set_msg(msg, msglen, "CHOLMOD ordering: out of memory for the interface-last permutation.");
        code = CHSH_OUT_OF_MEMORY;
        goto done;
    }
    for (k = 0; k < nlast; k++) is_last[last[k]] = 1;
    for (j = 0, k = 0; j < n; j++)
        if (!is_last[j]) inter[k++] = j;

    if (ni > 0 && ordering == CHSH_ORD_NATURAL) {
        for (k = 0; k < ni; k++) perm[k] = inter[k];
    } else if (ni > 0 && ordering == CHSH_ORD_GIVEN) {
        /* the caller's interior order: in range, not in `last`, no repeats
         * (is_last marks `last` with 1, the given entries seen so far with 2) */
        for (k = 0; k < ni; k++) {
            j = interior[k];
            if (j < 0 || j >= n || is_last[j]) {
                set_msg(msg, msglen,
                        "CHOLMOD ordering: given interior DOF %d (entry %d) is out of range, an interface DOF or repeated.",
                        j + 1, k + 1);
                code = CHSH_FAILURE;
                goto done;
            }
            is_last[j] = 2;
            perm[k] = j;
        }
    } else if (ni > 0 && ordering == CHSH_ORD_METIS) {
        /* interior submatrix, upper triangle, pattern only */
        size_t nz = 0;
        int *Sp, *Si;
        newidx = (int *) malloc((size_t) n * sizeof(int));
        work = (int *) malloc((size_t) ni * sizeof(int));
        if (newidx == NULL || work == NULL) {
            set_msg(msg, msglen, "CHOLMOD ordering: out of memory for the interior submatrix.");
            code = CHSH_OUT_OF_MEMORY;
            goto done;
        }
        for (j = 0, k = 0; j < n; j++) newidx[j] = is_last[j] ? -1 : k++;
        for (k = 0; k < ni; k++) {
            j = inter[k];
            for (p = colptr[j]; p < colptr[j + 1]; p++)
                if (!is_last[rowind[p]] && rowind[p] <= j) nz++;
        }
        S = cholmod_allocate_sparse((size_t) ni, (size_t) ni, nz > 0 ? nz : 1,
                                    TRUE, TRUE, 1, CHOLMOD_PATTERN, c);
        if (S == NULL) {
            code = translate(c, "allocate interior submatrix", msg, msglen);
            if (code == CHSH_OK) code = CHSH_FAILURE;
            goto done;
        }
        Sp = (int *) S->p;
        Si = (int *) S->i;
        nz = 0;
        for (k = 0; k < ni; k++) {
            j = inter[k];
            Sp[k] = (int) nz;
            for (p = colptr[j]; p < colptr[j + 1]; p++) {
                int i = rowind[p];
                if (!is_last[i] && i <= j) Si[nz++] = newidx[i];
            }
        }
        Sp[ni] = (int) nz;
        pthread_mutex_lock(&metis_lock);
        k = cholmod_metis(S, NULL, 0, TRUE, work, c);
        pthread_mutex_unlock(&metis_lock);
        if (!k || c->status < CHOLMOD_OK) {
            code = translate(c, "METIS ordering of the interior", msg, msglen);
            if (code == CHSH_OK) code = CHSH_FAILURE;
            goto done;
        }
        for (k = 0; k < ni; k++) perm[k] = inter[work[k]];
    } else if (ni > 0 && ordering == CHSH_ORD_AMD) {
        /* constrained AMD on the whole matrix: interior (set 0) first */
        work = (int *) malloc((size_t) n * sizeof(int));
        if (work == NULL) {
            set_msg(msg, msglen, "CHOLMOD ordering: out of memory for CAMD.");
            code = CHSH_OUT_OF_MEMORY;
            goto done;
        }
        if (!cholmod_camd(A, NULL, 0, is_last, work, c) || c->status < CHOLMOD_OK) {
            code = translate(c, "CAMD ordering", msg, msglen);
            if (code == CHSH_OK) code = CHSH_FAILURE;
            goto done;
        }
        for (j = 0, k = 0; j < n; j++)
            if (!is_last[work[j]]) perm[k++] = work[j];
        if (k != ni) {
            set_msg(msg, msglen, "CAMD returned an invalid permutation.");
            code = CHSH_FAILURE;
            goto done;
        }
    }
    for (k = 0; k < nlast; k++) perm[ni + k] = last[k];

done:
    if (S != NULL) cholmod_free_sparse(&S, c);
    free(work);
    free(newidx);
    free(inter);
    free(is_last);
    return code;
}

int chsh_metis_order(int n, const int *colptr, const int *rowind, int *perm,
                     char *msg, int msglen)
{
    cholmod_common c;
    cholmod_sparse A;
    int ok, code = CHSH_OK, k;

    set_msg(msg, msglen, "%s", "");
    if (n < 0 || colptr == NULL || perm == NULL || (n > 0 && colptr[n] > 0 && rowind == NULL)) {
        set_msg(msg, msglen, "chsh_metis_order: invalid graph (n = %d or NULL arrays).", n);
        return CHSH_FAILURE;
    }
    if (n <= 1) {            /* nothing to order (METIS wants an edge) */
        if (n == 1) perm[0] = 0;
        return CHSH_OK;
    }
    if (!cholmod_start(&c)) {
        code = translate(&c, "start", msg, msglen);
        return code == CHSH_OK ? CHSH_FAILURE : code;
    }
    c.print = 0;
    wrap_sparse(&A, n, colptr, rowind, NULL);
    pthread_mutex_lock(&metis_lock);
    ok = cholmod_metis(&A, NULL, 0, TRUE, perm, &c);
    pthread_mutex_unlock(&metis_lock);
    if (!ok || c.status < CHOLMOD_OK) {
        code = translate(&c, "METIS ordering of the node graph", msg, msglen);
        if (code == CHSH_OK) code = CHSH_FAILURE;
    }
    if (!cholmod_finish(&c) && code == CHSH_OK) {
        code = translate(&c, "finish", msg, msglen);
        if (code == CHSH_OK) code = CHSH_FAILURE;
    }
    if (code == CHSH_OK) {   /* a permutation of 0..n-1, or a failure */
        char *seen = (char *) calloc((size_t) n, 1);
        if (seen == NULL) {
            set_msg(msg, msglen, "chsh_metis_order: out of memory for the check of the permutation.");
            return CHSH_OUT_OF_MEMORY;
        }
        for (k = 0; k < n; k++) {
            if (perm[k] < 0 || perm[k] >= n || seen[perm[k]]) {
                set_msg(msg, msglen, "METIS ordering of the node graph: entry %d (%d) is not a permutation's.",
                        k + 1, perm[k] + 1);
                code = CHSH_FAILURE;
                break;
            }
            seen[perm[k]] = 1;
        }
        free(seen);
    }
    return code;
}

int chsh_factorize(chsh_factor *h, int n, const int *colptr, const int *rowind,
                   const double *val, int ordering, int nlast, const int *last,
                   const int *interior, char *msg, int msglen)
{
    cholmod_common *c;
    cholmod_sparse A;
    int *perm = NULL, code, k;
    double t0;

    set_msg(msg, msglen, "%s", "");
    if (h == NULL) {
        set_msg(msg, msglen, "chsh_factorize: NULL handle.");
        return CHSH_FAILURE;
    }
    c = &h->c;
    release_factor(h);
    memset(&h->st, 0, sizeof(h->st));
    if (n <= 0 || colptr == NULL || rowind == NULL || val == NULL) {
        set_msg(msg, msglen, "chsh_factorize: invalid matrix (n = %d or NULL arrays).", n);
        return CHSH_FAILURE;
    }
    if (ordering != CHSH_ORD_METIS && ordering != CHSH_ORD_AMD
        && ordering != CHSH_ORD_NATURAL && ordering != CHSH_ORD_GIVEN
        && ordering != CHSH_ORD_AUTO) {
        set_msg(msg, msglen, "chsh_factorize: unknown ordering code %d.", ordering);
        return CHSH_FAILURE;
    }
    if (ordering == CHSH_ORD_AUTO && nlast > 0) {
        set_msg(msg, msglen, "chsh_factorize: CHOLMOD's own ordering cannot put %d DOFs last.", nlast);
        return CHSH_FAILURE;
    }
    if (nlast < 0 || nlast > n || (nlast > 0 && last == NULL)) {
        set_msg(msg, msglen, "chsh_factorize: invalid interface size %d for n = %d.", nlast, n);
        return CHSH_FAILURE;
    }
    if (ordering == CHSH_ORD_GIVEN && nlast < n && interior == NULL) {
        set_msg(msg, msglen, "chsh_factorize: ordering GIVEN needs the interior order.");
        return CHSH_FAILURE;
    }
    h->st.n = n;
    h->st.nlast = nlast;
    h->st.ordering_used = -1;
    wrap_sparse(&A, n, colptr, rowind, val);

    /* ---- analysis ---- */
    t0 = SuiteSparse_time();
    c->nmethods = 1;
    if (nlast > 0 || ordering == CHSH_ORD_GIVEN) {
        /* validate the interface list: in range, no repeats */
        char *seen = (char *) calloc((size_t) n, 1);
        perm = (int *) malloc((size_t) n * sizeof(int));
        if (seen == NULL || perm == NULL) {
            free(seen);
            free(perm);
            set_msg(msg, msglen, "chsh_factorize: out of memory for the permutation.");
            return CHSH_OUT_OF_MEMORY;
        }
        for (k = 0; k < nlast; k++) {
            if (last[k] < 0 || last[k] >= n || seen[last[k]]) {
                set_msg(msg, msglen, "chsh_factorize: interface DOF %d (entry %d) is out of range or repeated.",
                        last[k] + 1, k + 1);
                free(seen);
                free(perm);
                return CHSH_FAILURE;
            }
            seen[last[k]] = 1;
        }
        free(seen);
        h->st.t_order = SuiteSparse_time();
        code = build_last_perm(h, &A, n, colptr, rowind, ordering, nlast, last,
                               interior, perm, msg, msglen);
        h->st.t_order = SuiteSparse_time() - h->st.t_order;
        if (code != CHSH_OK) {
            free(perm);
            return code;
        }
        c->method[0].ordering = CHOLMOD_GIVEN;
        c->postorder = FALSE;
        h->L = cholmod_analyze_p(&A, perm, NULL, 0, c);
        free(perm);
    } else {
        int may_run_metis = (ordering == CHSH_ORD_METIS || ordering == CHSH_ORD_AUTO);
        if (ordering == CHSH_ORD_AUTO) {
            c->nmethods = 0;     /* CHOLMOD's default strategy: AMD, METIS if AMD fills much */
        } else {
            c->method[0].ordering = (ordering == CHSH_ORD_METIS) ? CHOLMOD_METIS
                                  : (ordering == CHSH_ORD_AMD) ? CHOLMOD_AMD
                                  : CHOLMOD_NATURAL;
        }
        c->postorder = (ordering != CHSH_ORD_NATURAL);
        if (may_run_metis) pthread_mutex_lock(&metis_lock);
        h->L = cholmod_analyze(&A, c);
        if (may_run_metis) pthread_mutex_unlock(&metis_lock);
    }
    h->st.t_analyze = SuiteSparse_time() - t0;
    if (h->L == NULL || c->status < CHOLMOD_OK) {
        code = translate(c, "analyze", msg, msglen);
        release_factor(h);
        return code == CHSH_OK ? CHSH_FAILURE : code;
    }
    h->st.lnz = c->lnz;
    h->st.flops = c->fl;
    if (c->selected >= 0 && c->selected < CHOLMOD_MAXMETHODS)
        h->st.ordering_used = c->method[c->selected].ordering;

    /* does L->Perm end with the interface DOFs, in the given order? */
    if (nlast > 0) {
        const int *Lperm = (const int *) h->L->Perm;
        h->st.last_ok = 1;
        for (k = 0; k < nlast; k++)
            if (Lperm == NULL || Lperm[n - nlast + k] != last[k]) {
                h->st.last_ok = 0;
                break;
            }
    }

    /* ---- numeric factorization ---- */
    t0 = SuiteSparse_time();
    bt_begin();   /* its large dense kernels as tiles on the team's idle threads */
    cholmod_factorize(&A, h->L, c);
    h->st.tiles = (double) bt_end();
    h->st.t_factor = SuiteSparse_time() - t0;
    h->st.mem_peak = (double) c->memory_usage;
    h->st.mem_inuse = (double) c->memory_inuse;
    if (c->status == CHOLMOD_NOT_POSDEF) {
        int minor = (int) h->L->minor;
        const int *Lperm = (const int *) h->L->Perm;
        if (minor >= 0 && minor < n && Lperm != NULL)
            set_msg(msg, msglen,
                    "CHOLMOD factorize: matrix is not positive definite (pivot failed at column %d of %d of the permuted matrix, DOF %d).",
                    minor + 1, n, Lperm[minor] + 1);
        else
            set_msg(msg, msglen, "CHOLMOD factorize: matrix is not positive definite.");
        release_factor(h);
        return CHSH_NOT_POSDEF;
    }
    code = translate(c, "factorize", msg, msglen);
    if (code != CHSH_OK) {
        release_factor(h);
        return code;
    }
    h->st.is_super = h->L->is_super ? 1 : 0;
    h->st.lsize = h->L->is_super ? (double) h->L->xsize : (double) h->L->nzmax;
    h->factored = 1;
    return CHSH_OK;
}

int chsh_solve(chsh_factor *h, int nrhs, double *b, int ldb, char *msg, int msglen)
{
    cholmod_dense B;
    int n, j, i;
    const double *xs;

    set_msg(msg, msglen, "%s", "");
    if (h == NULL || !h->factored) {
        set_msg(msg, msglen, "chsh_solve: no valid factorization in this handle.");
        return CHSH_FAILURE;
    }
    n = h->st.n;
    if (nrhs < 0 || ldb < n || (nrhs > 0 && b == NULL)) {
        set_msg(msg, msglen, "chsh_solve: invalid right-hand side (nrhs = %d, ldb = %d, n = %d).",
                nrhs, ldb, n);
        return CHSH_FAILURE;
    }
    if (nrhs == 0) return CHSH_OK;
    memset(&B, 0, sizeof(B));
    B.nrow = (size_t) n;
    B.ncol = (size_t) nrhs;
    B.nzmax = (size_t) ldb * (size_t) nrhs;
    B.d = (size_t) ldb;
    B.x = b;
    B.z = NULL;
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    if (!cholmod_solve2(CHOLMOD_A, h->L, &B, NULL, &h->X, NULL, &h->Y, &h->E, &h->c)
        || h->c.status < CHOLMOD_OK || h->X == NULL) {
        int code = translate(&h->c, "solve", msg, msglen);
        return code == CHSH_OK ? CHSH_FAILURE : code;
    }
    xs = (const double *) h->X->x;
    for (j = 0; j < nrhs; j++)
        for (i = 0; i < n; i++)
            b[(size_t) j * ldb + i] = xs[(size_t) j * h->X->d + i];
    return CHSH_OK;
}

int chsh_trailing_block(chsh_factor *h, int m, double *lg, int ldlg,
                        char *msg, int msglen)
{
    const cholmod_factor *L;
    const int *super, *pi, *px, *ls;
    const double *lx;
    int n, n0, s, j, ii;
    size_t col;

    set_msg(msg, msglen, "%s", "");
    if (h == NULL || !h->factored) {
        set_msg(msg, msglen, "chsh_trailing_block: no valid factorization in this handle.");
        return CHSH_FAILURE;
    }
    L = h->L;
    n = h->st.n;
    if (!L->is_super || L->xtype != CHOLMOD_REAL) {
        set_msg(msg, msglen, "chsh_trailing_block: the factor is not a real supernodal LL' factor.");
        return CHSH_FAILURE;
    }
    if (m < 0 || m > n || ldlg < m || (m > 0 && lg == NULL)) {
        set_msg(msg, msglen, "chsh_trailing_block: invalid block size %d (n = %d, ld = %d).",
                m, n, ldlg);
        return CHSH_FAILURE;
    }
    for (j = 0; j < m; j++)
        memset(lg + (size_t) j * ldlg, 0, (size_t) m * sizeof(double));
    n0 = n - m;
    super = (const int *) L->super;
    pi = (const int *) L->pi;
    px = (const int *) L->px;
    ls = (const int *) L->s;
    lx = (const double *) L->x;
    for (s = 0; s < (int) L->nsuper; s++) {
        int k1 = super[s], k2 = super[s + 1];
        int psi = pi[s], nsrow = pi[s + 1] - pi[s];
        int psx = px[s];
        if (k2 <= n0) continue;
        for (j = (k1 > n0 ? k1 : n0); j < k2; j++) {
            int jj = j - k1;
            col = (size_t) (j - n0) * (size_t) ldlg;
            /* rows jj..nsrow-1 of column jj (the lower part); rows >= j >= n0 */
            for (ii = jj; ii < nsrow; ii++) {
                int row = ls[psi + ii];
                lg[col + (size_t) (row - n0)] = lx[(size_t) psx + (size_t) ii + (size_t) jj * (size_t) nsrow];
            }
        }
    }
    return CHSH_OK;
}

int chsh_get_stats(const chsh_factor *h, chsh_stats *st)
{
    if (h == NULL || st == NULL) return CHSH_FAILURE;
    *st = h->st;
    st->mem_peak = (double) h->c.memory_usage;
    st->mem_inuse = (double) h->c.memory_inuse;
    return CHSH_OK;
}

void chsh_free(chsh_factor **h)
{
    if (h == NULL || *h == NULL) return;
    release_factor(*h);
    cholmod_finish(&(*h)->c);
    free(*h);
    *h = NULL;
}
