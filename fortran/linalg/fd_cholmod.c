/* A minimal interface to SuiteSparse's CHOLMOD (its LGPL Core and Cholesky modules only:
 * analyse, factorize, solve; never the GPL Modify module) for fd_sparse.f90: one handle per
 * symmetric positive definite matrix of a fixed pattern, its upper triangle in compressed
 * columns (0-based), factored as a simplicial L L'. Nothing prints (Common->print = 0); errors come back as status codes.
 *
 * The solve is this file's own substitution over the factor's columns, in a work vector the
 * handle keeps: a solve allocates nothing.
 *
 * Built without CHOLMOD (FD_HAVE_CHOLMOD undefined), every call returns FD_CHOL_UNAVAILABLE. */
#include <stdlib.h>
#include <string.h>

#define FD_CHOL_OK 0
#define FD_CHOL_UNAVAILABLE 1
#define FD_CHOL_NO_MEMORY 2
#define FD_CHOL_NOT_POSDEF 3
#define FD_CHOL_FAILED 4

#ifdef FD_HAVE_CHOLMOD
#if defined(__has_include)
#if __has_include(<suitesparse/cholmod.h>)
#include <suitesparse/cholmod.h>
#else
#include <cholmod.h>
#endif
#else
#include <cholmod.h>
#endif

typedef struct {
    cholmod_common c;
    cholmod_sparse *a;     /* upper triangle, stype 1, values set by fd_chol_factor */
    cholmod_factor *l;
    double *w;             /* n: the permuted right-hand side of a solve */
    int n, nrhs_max;
} fd_chol;

int fd_chol_available(void) { return 1; }

static void release(fd_chol *h) {
    free(h->w);
    if (h->l) cholmod_free_factor(&h->l, &h->c);
    if (h->a) cholmod_free_sparse(&h->a, &h->c);
    cholmod_finish(&h->c);
    free(h);
}

/* Analyse the pattern (colptr: n + 1, rowind: colptr[n] entries, rows <= column, sorted):
 * the fill-reducing ordering and the symbolic factor. lnz: entries of the factor; flops:
 * of a factorization. */
int fd_chol_create(int n, const int *colptr, const int *rowind, int nrhs_max, void **handle, double *lnz,
                   double *flops) {
    fd_chol *h;
    int nz;
    *handle = NULL;
    if (n < 1 || nrhs_max < 1) return FD_CHOL_FAILED;
    h = calloc(1, sizeof(fd_chol));
    if (!h) return FD_CHOL_NO_MEMORY;
    cholmod_start(&h->c);
    h->c.print = 0;
    h->c.error_handler = NULL;
    /* simplicial LL': its solve is two loops over the factor's columns, faster than the
     * supernodal solve's BLAS calls on the fronts of a frame (a few tens of columns wide)
     * (bench/matrix_scale.py); LL' so that a pivot <= 0 is reported (not positive definite) */
    h->c.supernodal = CHOLMOD_SIMPLICIAL;
    h->c.final_ll = 1;
    h->n = n;
    h->nrhs_max = nrhs_max;
    h->w = malloc(sizeof(double) * (size_t)n);
    if (!h->w) {
        release(h);
        return FD_CHOL_NO_MEMORY;
    }
    nz = colptr[n];
    h->a = cholmod_allocate_sparse((size_t)n, (size_t)n, (size_t)nz, 1, 1, 1, CHOLMOD_REAL, &h->c);
    if (!h->a) {
        release(h);
        return FD_CHOL_NO_MEMORY;
    }
    memcpy(h->a->p, colptr, sizeof(int) * (size_t)(n + 1));
    memcpy(h->a->i, rowind, sizeof(int) * (size_t)nz);
    memset(h->a->x, 0, sizeof(double) * (size_t)nz);
    h->l = cholmod_analyze(h->a, &h->c);
    if (!h->l || h->c.status < CHOLMOD_OK) {
        int st = h->c.status == CHOLMOD_OUT_OF_MEMORY ? FD_CHOL_NO_MEMORY : FD_CHOL_FAILED;
        release(h);
        return st;
    }
    *lnz = h->c.lnz;
    *flops = h->c.fl;
    *handle = h;
    return FD_CHOL_OK;
}

/* Solve A x = b for one column b (n values), overwritten by x, with the simplicial L L' of
 * A (Perm, Perm): w = b (Perm), L L' w = w by forward and back substitution over L's columns
 * (each its diagonal first), x (Perm) = w. Written here rather than through cholmod_solve2,
 * which reallocates its workspace in a solve (CHOLMOD 5.12, seen under the sanitizer): a
 * step's solve allocates nothing. */
static void solve_column(fd_chol *h, double *b) {
    const cholmod_factor *l = h->l;
    const int *lp = l->p, *li = l->i, *lnz = l->nz;
    const int *perm = l->ordering == CHOLMOD_NATURAL ? NULL : l->Perm;
    const double *lx = l->x;
    double *w = h->w, t;
    int j, p, n = h->n;
    for (j = 0; j < n; j++) w[j] = b[perm ? perm[j] : j];
    for (j = 0; j < n; j++) {
        t = w[j] / lx[lp[j]];
        w[j] = t;
        for (p = lp[j] + 1; p < lp[j] + lnz[j]; p++) w[li[p]] -= lx[p] * t;
    }
    for (j = n - 1; j >= 0; j--) {
        t = w[j];
        for (p = lp[j] + 1; p < lp[j] + lnz[j]; p++) t -= lx[p] * w[li[p]];
        w[j] = t / lx[lp[j]];
    }
    for (j = 0; j < n; j++) b[perm ? perm[j] : j] = w[j];
}

/* Factor the matrix of values x (colptr[n] of them, the pattern's order). Not positive
 * definite: FD_CHOL_NOT_POSDEF and column, the 1-based original DOF where it failed. */
int fd_chol_factor(void *handle, const double *x, int *column) {
    fd_chol *h = handle;
    *column = 0;
    memcpy(h->a->x, x, sizeof(double) * (size_t)((int *)h->a->p)[h->n]);
    if (!cholmod_factorize(h->a, h->l, &h->c)) {
        return h->c.status == CHOLMOD_OUT_OF_MEMORY ? FD_CHOL_NO_MEMORY : FD_CHOL_FAILED;
    }
    if (h->c.status == CHOLMOD_NOT_POSDEF || h->l->minor < (size_t)h->n) {
        size_t k = h->l->minor < (size_t)h->n ? h->l->minor : 0;
        *column = (h->l->Perm ? ((int *)h->l->Perm)[k] : (int)k) + 1;
        return FD_CHOL_NOT_POSDEF;
    }
    if (h->c.status < CHOLMOD_OK) return FD_CHOL_FAILED;
    /* solve_column reads a simplicial L L' (Common: simplicial, final_ll) */
    if (h->l->is_super || !h->l->is_ll || h->l->xtype != CHOLMOD_REAL) return FD_CHOL_FAILED;
    return FD_CHOL_OK;
}

/* Solve A X = B for nrhs columns of b (leading dimension n), overwritten by X. */
int fd_chol_solve(void *handle, int nrhs, double *b) {
    fd_chol *h = handle;
    int j;
    if (nrhs < 1 || nrhs > h->nrhs_max) return FD_CHOL_FAILED;
    for (j = 0; j < nrhs; j++) solve_column(h, b + (size_t)j * (size_t)h->n);
    return FD_CHOL_OK;
}

/* Bytes held by the factor (its values and indices). */
double fd_chol_factor_bytes(void *handle) {
    fd_chol *h = handle;
    cholmod_factor *l;
    if (!h) return 0.0;
    l = h->l;
    if (l->is_super) return 8.0 * (double)l->xsize + 4.0 * (double)l->ssize;
    return 12.0 * (double)l->nzmax;
}

void fd_chol_free(void *handle) {
    if (handle) release(handle);
}

#else

int fd_chol_available(void) { return 0; }

int fd_chol_create(int n, const int *colptr, const int *rowind, int nrhs_max, void **handle, double *lnz,
                   double *flops) {
    (void)n; (void)colptr; (void)rowind; (void)nrhs_max;
    *handle = NULL;
    *lnz = 0.0;
    *flops = 0.0;
    return FD_CHOL_UNAVAILABLE;
}

int fd_chol_factor(void *handle, const double *x, int *column) {
    (void)handle; (void)x;
    *column = 0;
    return FD_CHOL_UNAVAILABLE;
}

int fd_chol_solve(void *handle, int nrhs, double *b) {
    (void)handle; (void)nrhs; (void)b;
    return FD_CHOL_UNAVAILABLE;
}


double fd_chol_factor_bytes(void *handle) { (void)handle; return 0.0; }

void fd_chol_free(void *handle) { (void)handle; }

#endif
