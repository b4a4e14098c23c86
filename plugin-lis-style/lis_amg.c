/*
 * lis_amg.c -- the smoothed-aggregation algebraic multigrid preconditioner
 * (-p saamg): one V-cycle per application.
 *
 * Setup, level by level until at most AMG_COARSEST unknowns remain (Vanek,
 * Mandel & Brezina, Computing 56, 1996):
 *   strength   j is a strong neighbour of i when |a_ij| >= theta sqrt(|a_ii a_jj|)
 *              (-saamg_theta, default 0.05);
 *   aggregates the usual three passes: a node whose strong neighbours are all
 *              free starts an aggregate with them; a free node joins the
 *              aggregate of a strong neighbour from the first pass; what is
 *              left makes new aggregates with its free strong neighbours;
 *   prolongator P = (I - w D^-1 A) P0, P0 the aggregates' indicator columns
 *              scaled to unit norm (the constant near-null space), w = 4/(3 r)
 *              with r >= rho(D^-1 A) the Gershgorin bound;
 *   coarse     A_c = R A P with R = P' (two sparse products), and a dense LU
 *              with partial pivoting on the last level.
 * The V-cycle smooths with one forward Gauss-Seidel sweep before the coarse
 * correction and one backward sweep after it, so for a symmetric A the
 * preconditioner is symmetric (and positive definite for an SPD A): CG and
 * MINRES may use it, and its transpose is itself.
 *
 * -saamg_unsym true lets the driver use the same construction on an
 * unsymmetric A (still Galerkin, R = P'); the V-cycle is then not symmetric
 * and has no transposed application here, so the driver keeps it from the
 * methods that need M^-T.  A Petrov-Galerkin restriction smoothed with A'
 * (R = ((I - w D^-1 A') P0)') was tried and dropped: on the convection-
 * diffusion grid of the tests (beta 0.4) GMRES then stalled from 64 x 64 on,
 * where R = P' converges in 8-9 iterations at 32..128.
 */
#include "lis.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { AMG_MAXLEVELS = 25, AMG_COARSEST = 50 };

typedef struct amg_level {
    lk_csr A;                   /* level 0: the caller's (borrowed); else Ac */
    lis_matrix *own;            /* A of levels > 0 */
    lis_matrix *P, *R;          /* to and from the next level (R = P') */
    double *x, *b, *r;          /* this level's vectors during a cycle */
} amg_level;

struct lis_amg {
    int nlev;
    amg_level L[AMG_MAXLEVELS];
    double *lu;                 /* the coarsest A, LU-factored in place */
    int64_t *piv;
};

void lis_amg_free(lis_amg *G)
{
    int l;
    if (!G) return;
    for (l = 0; l < G->nlev; l++) {
        lis_matrix_free(G->L[l].own);
        lis_matrix_free(G->L[l].P);
        lis_matrix_free(G->L[l].R);
        lis_host->free(G->L[l].x);
        lis_host->free(G->L[l].b);
        lis_host->free(G->L[l].r);
    }
    lis_host->free(G->lu);
    lis_host->free(G->piv);
    lis_host->free(G);
}

/* ---- setup -------------------------------------------------------------------------- */

static int by_index(const void *x, const void *y)
{
    int64_t a = *(const int64_t *)x, b = *(const int64_t *)y;
    return (a > b) - (a < b);
}

/* C = A B (Gustavson: row i of C accumulates a_ik times row k of B, columns
 * collected through a marker array, then sorted).  NULL when out of memory. */
static lis_matrix *spgemm(const lk_csr *A, const lk_csr *B)
{
    int64_t *mark = lis_array((size_t)B->n, sizeof(int64_t)), *cols = lis_array((size_t)B->n, sizeof(int64_t));
    double *acc = lis_array((size_t)B->n, sizeof(double));
    int64_t i, j, k, q, nnz = 0, cap;
    lis_matrix *C = NULL;
    if (!mark || !cols || !acc) goto out;
    for (j = 0; j < B->n; j++) mark[j] = -1;
    /* Pass 1: the size of each row, to allocate C once. */
    for (i = 0; i < A->m; i++) {
        int64_t len = 0;
        for (k = A->rp[i]; k < A->rp[i + 1]; k++)
            for (q = B->rp[A->ci[k]]; q < B->rp[A->ci[k] + 1]; q++)
                if (mark[B->ci[q]] != i) mark[B->ci[q]] = i, len++;
        nnz += len;
    }
    cap = nnz;
    if (!(C = lis_matrix_alloc(A->m, B->n, cap))) goto out;
    for (j = 0; j < B->n; j++) mark[j] = -1;
    nnz = 0;
    for (i = 0; i < A->m; i++) {
        int64_t len = 0, t;
        for (k = A->rp[i]; k < A->rp[i + 1]; k++)
            for (q = B->rp[A->ci[k]]; q < B->rp[A->ci[k] + 1]; q++) {
                j = B->ci[q];
                if (mark[j] != i) mark[j] = i, acc[j] = 0, cols[len++] = j;
                acc[j] += A->v[k] * B->v[q];
            }
        if (len > 32) /* insertion sort for the usual short rows */
            qsort(cols, (size_t)len, sizeof *cols, by_index);
        else
            for (t = 1; t < len; t++)
                for (q = t; q > 0 && cols[q - 1] > cols[q]; q--) j = cols[q], cols[q] = cols[q - 1], cols[q - 1] = j;
        for (t = 0; t < len; t++) C->ci[nnz] = cols[t], C->v[nnz++] = acc[cols[t]];
        C->rp[i + 1] = nnz;
    }
out:
    lis_host->free(mark);
    lis_host->free(cols);
    lis_host->free(acc);
    return C;
}

/* The aggregate of every node (agg[i] in 0..*nagg-1). */
static int aggregate(const lk_csr *A, const double *diag, double theta, int64_t *agg, int64_t *nagg)
{
    int64_t n = A->m, i, k, count = 0;
    int64_t *first = lis_array((size_t)n, sizeof(int64_t));
    if (!first) return -1;
#define STRONG(i, k)                                                                             \
    (A->ci[k] != (i) && fabs(A->v[k]) >= theta * sqrt(fabs(diag[i] * diag[A->ci[k]])) && A->v[k] != 0)
    for (i = 0; i < n; i++) agg[i] = -1;
    for (i = 0; i < n; i++) { /* pass 1: a node and all its (free) strong neighbours */
        int free = 1;
        for (k = A->rp[i]; k < A->rp[i + 1] && free; k++)
            if (STRONG(i, k) && agg[A->ci[k]] >= 0) free = 0;
        if (!free || agg[i] >= 0) continue;
        agg[i] = count;
        for (k = A->rp[i]; k < A->rp[i + 1]; k++)
            if (STRONG(i, k)) agg[A->ci[k]] = count;
        count++;
    }
    for (i = 0; i < n; i++) first[i] = agg[i];
    for (i = 0; i < n; i++) { /* pass 2: join a first-pass neighbour */
        if (agg[i] >= 0) continue;
        for (k = A->rp[i]; k < A->rp[i + 1]; k++)
            if (STRONG(i, k) && first[A->ci[k]] >= 0) {
                agg[i] = first[A->ci[k]];
                break;
            }
    }
    for (i = 0; i < n; i++) { /* pass 3: the rest, with their free strong neighbours */
        if (agg[i] >= 0) continue;
        agg[i] = count;
        for (k = A->rp[i]; k < A->rp[i + 1]; k++)
            if (STRONG(i, k) && agg[A->ci[k]] < 0) agg[A->ci[k]] = count;
        count++;
    }
#undef STRONG
    lis_host->free(first);
    *nagg = count;
    return 0;
}

/* P = (I - w D^-1 A) P0 for the aggregates agg (nagg columns). */
static lis_matrix *prolongator(const lk_csr *A, const double *diag, const int64_t *agg, int64_t nagg)
{
    int64_t n = A->m, i, k;
    double *scale = lis_array((size_t)nagg, sizeof(double)), rho = 0, w;
    lis_matrix *P0 = lis_matrix_alloc(n, nagg, n), *AP0 = NULL, *P = NULL;
    if (!scale || !P0) goto out;
    for (i = 0; i < nagg; i++) scale[i] = 0;
    for (i = 0; i < n; i++) scale[agg[i]] += 1;
    for (i = 0; i < n; i++) {
        double s = 0;
        P0->ci[i] = agg[i], P0->v[i] = 1 / sqrt(scale[agg[i]]), P0->rp[i + 1] = i + 1;
        for (k = A->rp[i]; k < A->rp[i + 1]; k++) s += fabs(A->v[k]);
        if (s / fabs(diag[i]) > rho) rho = s / fabs(diag[i]);
    }
    w = 4.0 / (3.0 * rho);
    if (!(AP0 = spgemm(A, &P0->A))) goto out;
    /* P0's pattern is inside A P0's (a_ii != 0), so P is A P0's pattern. */
    for (i = 0; i < n; i++)
        for (k = AP0->rp[i]; k < AP0->rp[i + 1]; k++)
            AP0->v[k] = (AP0->ci[k] == agg[i] ? P0->v[i] : 0) - w / diag[i] * AP0->v[k];
    P = AP0, AP0 = NULL;
out:
    lis_host->free(scale);
    lis_matrix_free(P0);
    lis_matrix_free(AP0);
    return P;
}

/* Dense LU with partial pivoting of the coarsest A, column-major n x n. */
static int coarse_lu(lis_amg *G, const lk_csr *A, char *err, size_t errlen)
{
    int64_t n = A->m, i, j, k;
    double *a = lis_array((size_t)(n * n), sizeof(double));
    G->lu = a, G->piv = lis_array((size_t)n, sizeof(int64_t));
    if (!a || !G->piv) return snprintf(err, errlen, "lis-style SA-AMG: out of memory"), SILC_ENOMEM;
    memset(a, 0, (size_t)(n * n) * sizeof(double));
    for (i = 0; i < n; i++)
        for (k = A->rp[i]; k < A->rp[i + 1]; k++) a[i + A->ci[k] * n] = A->v[k];
    for (k = 0; k < n; k++) {
        int64_t p = k;
        for (i = k + 1; i < n; i++)
            if (fabs(a[i + k * n]) > fabs(a[p + k * n])) p = i;
        G->piv[k] = p;
        if (a[p + k * n] == 0)
            return snprintf(err, errlen, "lis-style SA-AMG: the coarsest matrix (%lld unknowns) is singular",
                            (long long)n), SILC_EBREAKDOWN;
        if (p != k)
            for (j = 0; j < n; j++) {
                double t = a[k + j * n];
                a[k + j * n] = a[p + j * n], a[p + j * n] = t;
            }
        for (i = k + 1; i < n; i++) a[i + k * n] /= a[k + k * n];
        for (j = k + 1; j < n; j++)
            for (i = k + 1; i < n; i++) a[i + j * n] -= a[i + k * n] * a[k + j * n];
    }
    return SILC_OK;
}

/* What coarsen() returns when aggregation would not reduce the level: it is
 * then the coarsest. */
enum { AMG_LAST = -1 };

/* Level l's P and R = P', and the next level's A = R A P.  SILC_OK,
 * AMG_LAST, or SILC_ENOMEM / SILC_EBREAKDOWN (zero diagonal) with err. */
static int coarsen(amg_level *L, amg_level *next, double theta, int l, char *err, size_t errlen)
{
    int64_t n = L->A.m, nagg;
    double *diag = lis_array((size_t)n, sizeof(double));
    int64_t *agg = lis_array((size_t)n, sizeof(int64_t));
    lis_matrix *AP = NULL;
    char what[32];
    int rc = SILC_ENOMEM;
    snprintf(what, sizeof what, "SA-AMG level %d", l);
    if (!diag || !agg) goto out;
    if (lis_diagonal(&L->A, diag, what, err, errlen)) {
        rc = SILC_EBREAKDOWN;
        goto out;
    }
    if (aggregate(&L->A, diag, theta, agg, &nagg)) goto out;
    if (nagg >= n) {
        rc = AMG_LAST;
        goto out;
    }
    if (!(L->P = prolongator(&L->A, diag, agg, nagg)) || !(L->R = lis_matrix_transpose(&L->P->A)) ||
        !(AP = spgemm(&L->A, &L->P->A)) || !(next->own = spgemm(&L->R->A, &AP->A)))
        goto out;
    next->A = next->own->A;
    rc = SILC_OK;
out:
    lis_host->free(diag);
    lis_host->free(agg);
    lis_matrix_free(AP);
    return rc;
}

int lis_amg_build(const lk_csr *A, double theta, lis_amg **out, int64_t *nnz_out, char *err, size_t errlen)
{
    lis_amg *G = lis_host->calloc(1, sizeof *G);
    int64_t nnz = 0;
    int rc = SILC_ENOMEM, l;
    *out = NULL;
    if (!G) return snprintf(err, errlen, "lis-style SA-AMG: out of memory"), SILC_ENOMEM;
    G->L[0].A = *A;
    for (l = 0;; l++) {
        amg_level *L = &G->L[l];
        int64_t n = L->A.m;
        G->nlev = l + 1;
        nnz += L->A.rp[n];
        L->x = lis_array((size_t)n, sizeof(double));
        L->b = lis_array((size_t)n, sizeof(double));
        L->r = lis_array((size_t)n, sizeof(double));
        if (!L->x || !L->b || !L->r) goto fail;
        if (n <= AMG_COARSEST || l == AMG_MAXLEVELS - 1) break;
        rc = coarsen(L, &G->L[l + 1], theta, l, err, errlen);
        if (rc == AMG_LAST) break;
        if (rc) goto fail;
    }
    if (G->L[G->nlev - 1].A.m > 2000) {
        snprintf(err, errlen, "lis-style SA-AMG: coarsening stalled at %lld unknowns on level %d "
                 "(try a smaller -saamg_theta)", (long long)G->L[G->nlev - 1].A.m, G->nlev - 1);
        rc = SILC_EBREAKDOWN;
        goto fail;
    }
    if ((rc = coarse_lu(G, &G->L[G->nlev - 1].A, err, errlen))) goto fail;
    *out = G;
    *nnz_out = nnz;
    return SILC_OK;
fail:
    if (rc == SILC_ENOMEM) snprintf(err, errlen, "lis-style SA-AMG: out of memory");
    lis_amg_free(G);
    return rc;
}

int lis_amg_levels(const lis_amg *G)
{
    return G->nlev;
}

/* ---- one V-cycle ---------------------------------------------------------------------- */

/* One Gauss-Seidel sweep on A x = b, forward or backward. */
static void gauss_seidel(const lk_csr *A, const double *b, double *x, int forward)
{
    int64_t n = A->m, s, i, k;
    for (s = 0; s < n; s++) {
        double sum, d = 0;
        i = forward ? s : n - 1 - s;
        sum = b[i];
        for (k = A->rp[i]; k < A->rp[i + 1]; k++)
            if (A->ci[k] == i) d = A->v[k];
            else sum -= A->v[k] * x[A->ci[k]];
        x[i] = sum / d;
    }
}

static void cycle(const lis_amg *G, int l)
{
    const amg_level *L = &G->L[l];
    int64_t n = L->A.m, i, k;
    if (l == G->nlev - 1) {
        const double *a = G->lu;
        /* The row interchanges first (the factorization swapped whole rows,
         * so L is that of the permuted matrix), then L and U. */
        for (i = 0; i < n; i++) L->x[i] = L->b[i];
        for (k = 0; k < n; k++) {
            double t = L->x[G->piv[k]];
            L->x[G->piv[k]] = L->x[k], L->x[k] = t;
        }
        for (k = 0; k < n; k++)
            for (i = k + 1; i < n; i++) L->x[i] -= a[i + k * n] * L->x[k];
        for (k = n - 1; k >= 0; k--) {
            L->x[k] /= a[k + k * n];
            for (i = 0; i < k; i++) L->x[i] -= a[i + k * n] * L->x[k];
        }
        return;
    }
    for (i = 0; i < n; i++) L->x[i] = 0;
    gauss_seidel(&L->A, L->b, L->x, 1);
    lk_residual(&L->A, L->b, L->x, L->r);
    lk_spmv(&L->R->A, L->r, G->L[l + 1].b);
    cycle(G, l + 1);
    lk_spmv(&L->P->A, G->L[l + 1].x, L->r);
    for (i = 0; i < n; i++) L->x[i] += L->r[i];
    gauss_seidel(&L->A, L->b, L->x, 0);
}

void lis_amg_apply(const lis_amg *G, const double *x, double *y)
{
    const amg_level *L = &G->L[0];
    memcpy(L->b, x, (size_t)L->A.m * sizeof(double));
    cycle(G, 0);
    memcpy(y, L->x, (size_t)L->A.m * sizeof(double));
}
