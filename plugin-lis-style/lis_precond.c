/*
 * lis_precond.c -- the preconditioners: Jacobi, ILU(k), IC(0), SSOR, ILUT,
 * and SA-AMG through lis_amg.c.
 *
 * The incomplete factorizations share one form, M = (I + L)(D + U) with L
 * strictly lower (multipliers), U strictly upper and D diagonal, kept in CSR
 * with 1/D, so one pair of triangular solves (and its transpose, for BiCG)
 * serves them all:
 *   ILU(k)  row-wise IKJ elimination keeping fill of level <= k (level of a
 *           fill entry = lev(i,k) + lev(k,j) + 1, original entries level 0);
 *   IC(0)   the ILU(0) elimination of a symmetric A, with U replaced by D L'
 *           so that M = (I + L) D (I + L)' is exactly symmetric, and every
 *           pivot required positive (an incomplete LDL');
 *   ILUT    Saad's dual threshold: entries below drop * ||a_i||_2 are
 *           dropped, and each row of L and of U keeps at most
 *           ceil(rate * nnz(a_i) / 2) of the largest.
 * An incomplete factorization can meet a zero or (IC) non-positive pivot on
 * a matrix that is nonsingular (or SPD); then it is recomputed for
 * A + alpha diag(|A|) with alpha = 1e-3, 1e-2, 1e-1, 1 (Manteuffel's shift)
 * and the shift used is reported.  SSOR and Jacobi use A's diagonal and need
 * it nonzero.  Triangular solves are sequential by nature.
 */
#include "lis.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void *lis_array(size_t count, size_t size)
{
    if (count == 0) count = 1;
    if (count > SIZE_MAX / size) return NULL;
    return lis_host->alloc(count * size);
}

static void xfree(void *p)
{
    if (p) lis_host->free(p);
}

void lis_pc_free(void *p)
{
    lis_pc *P = p;
    if (!P) return;
    xfree(P->dinv);
    xfree(P->lp);
    xfree(P->li);
    xfree(P->lx);
    xfree(P->up);
    xfree(P->ui);
    xfree(P->ux);
    lis_amg_free(P->amg);
    xfree(P);
}

/* ---- growing CSR rows ---------------------------------------------------------- */

typedef struct rows {
    int64_t *p, *i;
    double *x;
    int *lev;                   /* ILU(k): level of each entry (U only) */
    int64_t nnz, cap;
} rows;

static int rows_init(rows *R, int64_t n, int64_t cap, int levels)
{
    memset(R, 0, sizeof *R);
    R->cap = cap > 16 ? cap : 16;
    R->p = lis_array((size_t)n + 1, sizeof(int64_t));
    R->i = lis_array((size_t)R->cap, sizeof(int64_t));
    R->x = lis_array((size_t)R->cap, sizeof(double));
    R->lev = levels ? lis_array((size_t)R->cap, sizeof(int)) : NULL;
    if (!R->p || !R->i || !R->x || (levels && !R->lev)) return -1;
    R->p[0] = 0;
    return 0;
}

static void rows_free(rows *R)
{
    xfree(R->p);
    xfree(R->i);
    xfree(R->x);
    xfree(R->lev);
    memset(R, 0, sizeof *R);
}

static int rows_push(rows *R, int64_t j, double x, int lev)
{
    if (R->nnz == R->cap) {
        int64_t cap = R->cap * 2;
        int64_t *ni = lis_host->realloc(R->i, (size_t)cap * sizeof(int64_t));
        double *nx;
        int *nl;
        if (!ni) return -1;
        R->i = ni;
        nx = lis_host->realloc(R->x, (size_t)cap * sizeof(double));
        if (!nx) return -1;
        R->x = nx;
        if (R->lev) {
            nl = lis_host->realloc(R->lev, (size_t)cap * sizeof(int));
            if (!nl) return -1;
            R->lev = nl;
        }
        R->cap = cap;
    }
    R->i[R->nnz] = j;
    R->x[R->nnz] = x;
    if (R->lev) R->lev[R->nnz] = lev;
    R->nnz++;
    return 0;
}

/* ---- the incomplete factorizations ---------------------------------------------- */

enum { FACT_OK = 0, FACT_NOMEM = -1, FACT_PIVOT = 1 };

typedef struct work {
    double *w;                  /* the row being eliminated, dense */
    int *lev;
    int64_t *next, *mark;       /* sorted linked list of the row's columns */
    int64_t *cand;              /* ILUT: candidates for keeping */
} work;

/* The diagonal shift of row i: alpha times |a_ii|, or the largest |a_ij| if
 * the diagonal is zero, in the direction of a_ii's sign. */
static double shift_of(const lk_csr *A, int64_t i, double aii, double alpha)
{
    double s = aii < 0 ? -aii : aii;
    if (alpha == 0) return 0;
    if (s == 0)
        for (int64_t k = A->rp[i]; k < A->rp[i + 1]; k++) {
            double a = A->v[k] < 0 ? -A->v[k] : A->v[k];
            if (a > s) s = a;
        }
    return aii < 0 ? -alpha * s : alpha * s;
}

/* Inserts column j after position `from` in the sorted list (j > from). */
static void list_insert(work *W, int64_t from, int64_t j)
{
    int64_t p = from;
    while (W->next[p] != -1 && W->next[p] < j) p = W->next[p];
    W->next[j] = W->next[p];
    W->next[p] = j;
}

typedef struct cand {
    int64_t j;
    double x;
} cand;

static int by_size(const void *a, const void *b)
{
    double x = ((const cand *)a)->x, y = ((const cand *)b)->x;
    x = x < 0 ? -x : x;
    y = y < 0 ? -y : y;
    return (x < y) - (x > y);
}

static int by_column(const void *a, const void *b)
{
    int64_t x = ((const cand *)a)->j, y = ((const cand *)b)->j;
    return (x > y) - (x < y);
}

/* Keeps at most p of the c candidates (largest first), in column order. */
static int64_t keep_largest(cand *c, int64_t count, int64_t p)
{
    if (count > p) {
        qsort(c, (size_t)count, sizeof *c, by_size);
        count = p;
    }
    qsort(c, (size_t)count, sizeof *c, by_column);
    return count;
}

/* One incomplete factorization with diagonal shift alpha.  kind is ILU (with
 * fill level `fill`), IC (ILU(0) + positive pivots) or ILUT.  On a bad pivot
 * returns FACT_PIVOT with its row in *bad_row. */
static int factor(const lk_csr *A, int kind, int fill, double drop, double rate, double alpha,
                  lis_pc *P, int64_t *bad_row)
{
    int64_t n = A->m, i;
    rows L, U;
    work W;
    cand *cs = NULL;
    int rc = FACT_NOMEM, levels = kind == LIS_PC_ILU && fill > 0;
    double *dinv = lis_array((size_t)n, sizeof(double));
    memset(&W, 0, sizeof W);
    W.w = lis_array((size_t)n, sizeof(double));
    W.lev = lis_array((size_t)n, sizeof(int));
    W.next = lis_array((size_t)n + 1, sizeof(int64_t));
    W.mark = lis_array((size_t)n, sizeof(int64_t));
    cs = lis_array((size_t)n, sizeof(cand));
    if (rows_init(&L, n, A->rp[n] / 2 + n, 0) || rows_init(&U, n, A->rp[n] / 2 + n, levels) ||
        !dinv || !W.w || !W.lev || !W.next || !W.mark || !cs)
        goto done;
    for (i = 0; i < n; i++) W.mark[i] = -1;
    for (i = 0; i < n; i++) {
        /* The list head is the sentinel slot n; columns are 0..n-1. */
        const int64_t head = n;
        int64_t tail = head, k, nrow = A->rp[i + 1] - A->rp[i], count;
        double rownorm = 0, rowmax = 0, tau, d;
        int have_diag = 0;
        W.next[head] = -1;
        for (k = A->rp[i]; k < A->rp[i + 1]; k++) {
            int64_t j = A->ci[k];
            double a = A->v[k];
            if (W.mark[j] == i) { W.w[j] += a; continue; } /* duplicate entry */
            W.mark[j] = i;
            W.w[j] = a;
            W.lev[j] = 0;
            W.next[j] = -1;
            W.next[tail] = j;
            tail = j;
            if (j == i) have_diag = 1;
            rownorm += a * a;
            if ((a < 0 ? -a : a) > rowmax) rowmax = a < 0 ? -a : a;
        }
        if (!have_diag) {
            W.mark[i] = i;
            W.w[i] = 0;
            W.lev[i] = 0;
            list_insert(&W, head, i);
        }
        W.w[i] += shift_of(A, i, W.w[i], alpha);
        tau = drop * sqrt(rownorm);
        /* Eliminate with the rows above, in increasing column order; fill
         * entries are inserted after the current position, so they are
         * eliminated in turn. */
        for (k = W.next[head]; k != -1 && k < i; k = W.next[k]) {
            double lik = W.w[k] * dinv[k];
            W.w[k] = lik;
            if (kind == LIS_PC_ILUT && (lik < 0 ? -lik : lik) < tau) {
                W.w[k] = 0;
                continue;
            }
            for (int64_t q = U.p[k]; q < U.p[k + 1]; q++) {
                int64_t j = U.i[q];
                int lev = W.lev[k] + (levels ? U.lev[q] : 0) + 1;
                if (W.mark[j] == i) {
                    W.w[j] -= lik * U.x[q];
                    if (lev < W.lev[j]) W.lev[j] = lev;
                } else if (kind == LIS_PC_ILUT || lev <= fill) {
                    W.mark[j] = i;
                    W.w[j] = -lik * U.x[q];
                    W.lev[j] = lev;
                    list_insert(&W, k, j);
                }
            }
        }
        /* Gather L, the pivot and U. */
        d = W.w[i];
        count = 0;
        for (k = W.next[head]; k != -1 && k < i; k = W.next[k]) {
            if (kind == LIS_PC_ILUT) {
                if (W.w[k] != 0) cs[count].j = k, cs[count++].x = W.w[k];
            } else if (rows_push(&L, k, W.w[k], 0)) {
                goto done;
            }
        }
        if (kind == LIS_PC_ILUT) {
            int64_t p = (int64_t)ceil(rate * (double)nrow / 2), c;
            if (p < 1) p = 1;
            count = keep_largest(cs, count, p);
            for (c = 0; c < count; c++)
                if (rows_push(&L, cs[c].j, cs[c].x, 0)) goto done;
            count = 0;
            for (; k != -1; k = W.next[k])
                if (k > i && (W.w[k] < 0 ? -W.w[k] : W.w[k]) >= tau)
                    cs[count].j = k, cs[count++].x = W.w[k];
            count = keep_largest(cs, count, p);
            for (c = 0; c < count; c++)
                if (rows_push(&U, cs[c].j, cs[c].x, 0)) goto done;
        } else {
            for (; k != -1; k = W.next[k])
                if (k > i && rows_push(&U, k, W.w[k], W.lev[k])) goto done;
        }
        L.p[i + 1] = L.nnz;
        U.p[i + 1] = U.nnz;
        if (!isfinite(d) || (kind == LIS_PC_IC ? !(d > 1e-14 * rowmax)
                                               : !((d < 0 ? -d : d) > 1e-14 * rowmax))) {
            *bad_row = i;
            rc = FACT_PIVOT;
            goto done;
        }
        dinv[i] = 1.0 / d;
    }
    if (kind == LIS_PC_IC) {
        /* U = D L': the transpose of L by counting, scaled by the pivots. */
        int64_t *cnt = lis_array((size_t)n + 1, sizeof(int64_t));
        if (!cnt) goto done;
        U.nnz = L.nnz;
        if (U.cap < L.nnz) {
            int64_t *ni = lis_host->realloc(U.i, (size_t)L.nnz * sizeof(int64_t));
            double *nx = ni ? lis_host->realloc(U.x, (size_t)L.nnz * sizeof(double)) : NULL;
            if (ni) U.i = ni;
            if (nx) U.x = nx;
            if (!ni || !nx) {
                xfree(cnt);
                goto done;
            }
            U.cap = L.nnz;
        }
        memset(cnt, 0, ((size_t)n + 1) * sizeof(int64_t));
        for (i = 0; i < L.nnz; i++) cnt[L.i[i] + 1]++;
        for (i = 0; i < n; i++) cnt[i + 1] += cnt[i];
        memcpy(U.p, cnt, ((size_t)n + 1) * sizeof(int64_t));
        for (i = 0; i < n; i++)
            for (int64_t q = L.p[i]; q < L.p[i + 1]; q++) {
                int64_t j = L.i[q], at = cnt[j]++;
                U.i[at] = i;
                U.x[at] = L.x[q] / dinv[j];
            }
        xfree(cnt);
    }
    P->lp = L.p, P->li = L.i, P->lx = L.x;
    P->up = U.p, P->ui = U.i, P->ux = U.x;
    xfree(U.lev);
    P->dinv = dinv;
    P->nnz = L.nnz + U.nnz + n;
    dinv = NULL;
    memset(&L, 0, sizeof L);
    memset(&U, 0, sizeof U);
    rc = FACT_OK;
done:
    rows_free(&L);
    rows_free(&U);
    xfree(dinv);
    xfree(W.w);
    xfree(W.lev);
    xfree(W.next);
    xfree(W.mark);
    xfree(cs);
    return rc;
}

/* ---- building ---------------------------------------------------------------------- */

int lis_diagonal(const lk_csr *A, double *d, const char *what, char *err, size_t errlen)
{
    for (int64_t i = 0; i < A->m; i++) {
        d[i] = 0;
        for (int64_t k = A->rp[i]; k < A->rp[i + 1]; k++)
            if (A->ci[k] == i) d[i] += A->v[k];
        if (d[i] == 0 || !isfinite(d[i])) {
            snprintf(err, errlen, "lis-style %s: zero diagonal entry in row %lld", what,
                     (long long)i + 1);
            return -1;
        }
    }
    return 0;
}

int lis_pc_build(const lk_csr *A, const lis_options *o, lis_pc **out, char *err, size_t errlen)
{
    static const double shifts[] = {0, 1e-3, 1e-2, 1e-1, 1};
    double t0 = lis_host->now();
    lis_pc *P = lis_host->calloc(1, sizeof *P);
    char label[48];
    *out = NULL;
    lis_precon_label(o, label, sizeof label);
    if (!P) return snprintf(err, errlen, "lis-style: out of memory for the preconditioner"), SILC_ENOMEM;
    P->kind = o->precon;
    P->n = A->m;
    if (o->precon == LIS_PC_SAAMG) {
        int rc = lis_amg_build(A, o->saamg_theta, &P->amg, &P->nnz, err, errlen);
        if (rc) {
            lis_pc_free(P);
            return rc;
        }
    } else if (o->precon == LIS_PC_JACOBI || o->precon == LIS_PC_SSOR) {
        P->dinv = lis_array((size_t)A->m, sizeof(double));
        if (!P->dinv) {
            lis_pc_free(P);
            return snprintf(err, errlen, "lis-style: out of memory for the preconditioner"), SILC_ENOMEM;
        }
        if (lis_diagonal(A, P->dinv, label, err, errlen)) {
            lis_pc_free(P);
            return SILC_EBREAKDOWN;
        }
        for (int64_t i = 0; i < A->m; i++) P->dinv[i] = 1.0 / P->dinv[i];
        P->A = *A;
        P->omega = o->ssor_omega;
        P->nnz = o->precon == LIS_PC_SSOR ? A->rp[A->m] : A->m;
    } else {
        size_t s;
        int64_t bad = -1;
        int rc = FACT_PIVOT;
        for (s = 0; s < sizeof shifts / sizeof *shifts && rc == FACT_PIVOT; s++) {
            int fill = o->precon == LIS_PC_IC ? 0 : o->ilu_fill;
            rc = factor(A, o->precon, fill, o->ilut_drop, o->ilut_rate, shifts[s], P, &bad);
            P->shift = shifts[s];
        }
        if (rc == FACT_NOMEM) {
            lis_pc_free(P);
            return snprintf(err, errlen, "lis-style %s: out of memory", label), SILC_ENOMEM;
        }
        if (rc == FACT_PIVOT) {
            snprintf(err, errlen, "lis-style %s: %s pivot in row %lld even with diagonal shift %g",
                     label, o->precon == LIS_PC_IC ? "non-positive" : "zero", (long long)bad + 1,
                     shifts[sizeof shifts / sizeof *shifts - 1]);
            lis_pc_free(P);
            return SILC_EBREAKDOWN;
        }
    }
    P->seconds = lis_host->now() - t0;
    *out = P;
    return SILC_OK;
}

/* ---- applying ----------------------------------------------------------------------- */

void lis_pc_apply(const lis_pc *P, const double *x, double *y)
{
    int64_t n = P->n, i, k;
    if (P->kind == LIS_PC_JACOBI) {
        for (i = 0; i < n; i++) y[i] = x[i] * P->dinv[i];
    } else if (P->kind == LIS_PC_SAAMG) {
        lis_amg_apply(P->amg, x, y);
    } else if (P->kind == LIS_PC_SSOR) {
        /* M = (D + wL) D^-1 (D + wU) / (w (2 - w)). */
        const lk_csr *A = &P->A;
        double w = P->omega, c = w * (2 - w);
        for (i = 0; i < n; i++) {
            double s = c * x[i];
            for (k = A->rp[i]; k < A->rp[i + 1] && A->ci[k] < i; k++) s -= w * A->v[k] * y[A->ci[k]];
            y[i] = s * P->dinv[i];
        }
        for (i = 0; i < n; i++) y[i] /= P->dinv[i];
        for (i = n - 1; i >= 0; i--) {
            double s = y[i];
            for (k = A->rp[i + 1] - 1; k >= A->rp[i] && A->ci[k] > i; k--) s -= w * A->v[k] * y[A->ci[k]];
            y[i] = s * P->dinv[i];
        }
    } else {
        /* (I + L) t = x, then (D + U) y = t. */
        for (i = 0; i < n; i++) {
            double s = x[i];
            for (k = P->lp[i]; k < P->lp[i + 1]; k++) s -= P->lx[k] * y[P->li[k]];
            y[i] = s;
        }
        for (i = n - 1; i >= 0; i--) {
            double s = y[i];
            for (k = P->up[i]; k < P->up[i + 1]; k++) s -= P->ux[k] * y[P->ui[k]];
            y[i] = s * P->dinv[i];
        }
    }
}

void lis_pc_apply_t(const lis_pc *P, const double *x, double *y)
{
    int64_t n = P->n, i, k;
    if (P->kind == LIS_PC_JACOBI || P->kind == LIS_PC_SAAMG) { /* symmetric M */
        lis_pc_apply(P, x, y);
    } else if (P->kind == LIS_PC_SSOR) {
        /* M' = (D + wU') D^-1 (D + wL') / (w (2 - w)): column sweeps over the rows. */
        const lk_csr *A = &P->A;
        double w = P->omega, c = w * (2 - w);
        for (i = 0; i < n; i++) y[i] = c * x[i];
        for (i = 0; i < n; i++) {
            y[i] *= P->dinv[i];
            for (k = A->rp[i + 1] - 1; k >= A->rp[i] && A->ci[k] > i; k--) y[A->ci[k]] -= w * A->v[k] * y[i];
        }
        for (i = 0; i < n; i++) y[i] /= P->dinv[i];
        for (i = n - 1; i >= 0; i--) {
            y[i] *= P->dinv[i];
            for (k = A->rp[i]; k < A->rp[i + 1] && A->ci[k] < i; k++) y[A->ci[k]] -= w * A->v[k] * y[i];
        }
    } else {
        /* M' = (D + U')(I + L'): (D + U') t = x forward, (I + L') y = t backward. */
        for (i = 0; i < n; i++) y[i] = x[i];
        for (i = 0; i < n; i++) {
            y[i] *= P->dinv[i];
            for (k = P->up[i]; k < P->up[i + 1]; k++) y[P->ui[k]] -= P->ux[k] * y[i];
        }
        for (i = n - 1; i >= 0; i--)
            for (k = P->lp[i]; k < P->lp[i + 1]; k++) y[P->li[k]] -= P->lx[k] * y[i];
    }
}
