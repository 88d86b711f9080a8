/* A minimal interface to SuiteSparse's CHOLMOD (its LGPL Core and Cholesky modules only:
 * analyse, factorize, solve; never the GPL Modify module) for fd_sparse.f90: one handle per
 * symmetric positive definite matrix of a fixed pattern, its upper triangle in compressed
 * columns (0-based), factored as a simplicial L L'. Nothing prints (Common->print = 0); errors come back as status codes.
 *
 * The solve goes through cholmod_solve2 with its solution and workspace kept in the handle,
 * one column at a time, so that after the first solve (made by fd_chol_factor) a solve
 * allocates nothing; the handle counts the solves that had to (re)allocate them
 * (fd_chol_allocations).
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
    cholmod_dense *x, *y, *e;
    int n, nrhs_max;
    long allocations;      /* solves whose solution or workspace was (re)allocated */
} fd_chol;

int fd_chol_available(void) { return 1; }

static void release(fd_chol *h) {
    if (h->x) cholmod_free_dense(&h->x, &h->c);
    if (h->y) cholmod_free_dense(&h->y, &h->c);
    if (h->e) cholmod_free_dense(&h->e, &h->c);
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

/* Solve A x = b for one column b (n values), overwritten by x, with the handle's solution
 * and workspace; a solve that had to (re)allocate them is counted: by their addresses, and
 * by their shapes (cholmod_ensure_dense reallocates on a change of shape, and the C library
 * may hand back a freed block at the same address). */
static int solve_column(fd_chol *h, double *b) {
    cholmod_dense bd, *x0 = h->x, *y0 = h->y, *e0 = h->e;
    size_t xc0 = x0 ? x0->ncol : 0, yr0 = y0 ? y0->nrow : 0, yc0 = y0 ? y0->ncol : 0;
    memset(&bd, 0, sizeof bd);
    bd.nrow = (size_t)h->n;
    bd.ncol = 1;
    bd.nzmax = bd.nrow;
    bd.d = bd.nrow;
    bd.x = b;
    bd.xtype = CHOLMOD_REAL;
    bd.dtype = CHOLMOD_DOUBLE;
    if (!cholmod_solve2(CHOLMOD_A, h->l, &bd, NULL, &h->x, NULL, &h->y, &h->e, &h->c)) {
        return h->c.status == CHOLMOD_OUT_OF_MEMORY ? FD_CHOL_NO_MEMORY : FD_CHOL_FAILED;
    }
    if (x0 && (h->x != x0 || h->y != y0 || h->e != e0 || h->x->ncol != xc0 || (h->y && (h->y->nrow != yr0 ||
                                                                                   h->y->ncol != yc0))))
        h->allocations++;
    memcpy(b, h->x->x, sizeof(double) * (size_t)h->n);
    return FD_CHOL_OK;
}

/* Factor the matrix of values x (colptr[n] of them, the pattern's order). Not positive
 * definite: FD_CHOL_NOT_POSDEF and column, the 1-based original DOF where it failed. */
int fd_chol_factor(void *handle, const double *x, int *column) {
    fd_chol *h = handle;
    double *b;
    int i, st;
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
    /* the first solve allocates the solution and the workspace (one column: every solve is
     * of one column, so that cholmod_solve2 finds them of the right size and keeps them) */
    if (!h->x) {
        b = calloc((size_t)h->n, sizeof(double));
        if (!b) return FD_CHOL_NO_MEMORY;
        for (i = 0; i < h->n; i++) b[i] = 1.0;
        st = solve_column(h, b);
        free(b);
        if (st != FD_CHOL_OK) return st;
    }
    return FD_CHOL_OK;
}

/* Solve A X = B for nrhs columns of b (leading dimension n), overwritten by X: column by
 * column, since cholmod_solve2 frees and reallocates its solution when the number of
 * columns changes (cholmod_ensure_dense), which a step's solve must not do. */
int fd_chol_solve(void *handle, int nrhs, double *b) {
    fd_chol *h = handle;
    int j, st;
    if (nrhs < 1 || nrhs > h->nrhs_max) return FD_CHOL_FAILED;
    for (j = 0; j < nrhs; j++) {
        st = solve_column(h, b + (size_t)j * (size_t)h->n);
        if (st != FD_CHOL_OK) return st;
    }
    return FD_CHOL_OK;
}

long fd_chol_allocations(void *handle) { return handle ? ((fd_chol *)handle)->allocations : 0; }

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

long fd_chol_allocations(void *handle) { (void)handle; return 0; }

double fd_chol_factor_bytes(void *handle) { (void)handle; return 0.0; }

void fd_chol_free(void *handle) { (void)handle; }

#endif
