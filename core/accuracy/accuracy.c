/*
 * accuracy.c -- residuals and the backward error of a solve, computed here
 * for every backend alike (so backends are judged by one yardstick), and the
 * deferral of that number for back-substitutions that reuse a factorization
 * (accuracy.h says why that is safe).  refine.c forms its residuals with the
 * same kernel.
 */
#include "accuracy.h"
#include "dist.h"
#include "util.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* (r[i] + l[i]) -= a * x.  l NULL: plain r[i] -= a x.  Otherwise the product
 * is split exactly (a x = p + e by fma) and added with TwoSum, so r + l
 * carries the sum to about twice the working precision. */
static void sub_product(double *r, double *l, int64_t i, double a, double x)
{
    double p = a * x, s, bb, err, e;
    if (!l) {
        r[i] -= p;
        return;
    }
    e = fma(a, x, -p);
    s = r[i] - p;
    bb = s - r[i];
    err = (r[i] - (s - bb)) + (-p - bb);
    r[i] = s;
    l[i] += err - e;
}

void acc_residual(const silc_value *A, const double *B, const double *X, int64_t k, int extended,
                  double *R, double *lo)
{
    silc_view a;
    int64_t i, j, c, p;
    val_view(A, &a);
    memcpy(R, B, (size_t)(a.m * k) * sizeof *R);
    if (extended) memset(lo, 0, (size_t)(a.m * k) * sizeof *lo);
    for (c = 0; c < k; c++) {
        double *r = R + c * a.m, *l = extended ? lo + c * a.m : NULL;
        const double *x = X + c * a.n;
        if (a.format == SILC_FMT_CSR) {
            for (i = 0; i < a.m; i++)
                for (p = a.rowptr[i]; p < a.rowptr[i + 1]; p++)
                    sub_product(r, l, i, a.val[p], x[a.colind[p]]);
        } else if (a.format == SILC_FMT_BAND) {
            for (j = 0; j < a.n; j++) {
                int64_t lo_i = j - a.ku > 0 ? j - a.ku : 0;
                int64_t hi_i = j + a.kl + 1 < a.m ? j + a.kl + 1 : a.m;
                for (i = lo_i; i < hi_i; i++)
                    sub_product(r, l, i, a.val[(a.ku + i - j) + j * a.ld], x[j]);
            }
        } else if (!l) {
            /* The plain residual of a dense A, column by column: an inner
             * loop of a multiply and a subtract, which keeps up with the
             * memory, where a call of sub_product an entry did not (the
             * residual cost 2.4 % of bench/limit's samples at n = 2000, now
             * 0.7 %).  The same operations in the same order: every r[i]
             * gets the same roundings. */
            for (j = 0; j < a.n; j++) {
                const double *restrict col = a.val + j * a.m;
                double *restrict rr = r;
                const double xj = x[j];
                for (i = 0; i < a.m; i++) rr[i] -= col[i] * xj;
            }
        } else {
            for (j = 0; j < a.n; j++)
                for (i = 0; i < a.m; i++) sub_product(r, l, i, a.val[i + j * a.m], x[j]);
        }
        if (l)
            for (i = 0; i < a.m; i++) r[i] += l[i];
    }
}

/* The larger of best and s, where a NaN wins and stays. */
static double max_nan(double best, double s)
{
    return s > best || s != s ? s : best;
}

double acc_norm_inf(const double *x, int64_t m, int64_t k)
{
    double best = 0;
    int64_t i, c;
    for (i = 0; i < m; i++) {
        double s = 0;
        for (c = 0; c < k; c++) s += fabs(x[i + c * m]);
        best = max_nan(best, s);
        if (isnan(best)) break;
    }
    return best;
}

double *acc_dense_copy(const silc_value *v)
{
    double *x = malloc((size_t)(v->m * v->n > 0 ? v->m * v->n : 1) * sizeof *x);
    int64_t i, j;
    if (!x) return NULL;
    if (v->format == SILC_FMT_DENSE) {
        if (v->m * v->n > 0) memcpy(x, v->val, (size_t)(v->m * v->n) * sizeof *x);
        return x;
    }
    for (j = 0; j < v->n; j++)
        for (i = 0; i < v->m; i++) x[i + j * v->m] = val_get(v, i, j);
    return x;
}

/* ||B - A X||_inf for CSR A and dense B, X in one pass, nothing allocated:
 * the common case, whose cost is one sparse product.  With norm_a, also
 * ||A||_inf, summed unscaled while the entries pass by (the properties'
 * norms would cost a pass of their own); +Inf when that sum overflowed, and
 * not complete when the residual is NaN.  With col1 (k entries, zeroed by
 * the caller), also each column's ||b_j - A x_j||_1, for the forward-error
 * bound: one more add per row. */
static double residual_norm_csr(const silc_value *A, const double *B, const double *X, int64_t k,
                                double *norm_a, double *col1)
{
    silc_view a;
    double best = 0, best_a = 0;
    int64_t i, c, p;
    val_view(A, &a);
    for (i = 0; i < a.m; i++) {
        double s = 0;
        for (c = 0; c < k; c++) {
            const double *x = X + c * a.n;
            double r = B[i + c * a.m], row_a = 0;
            /* row_a costs an add beside each gather: not worth a second loop */
            for (p = a.rowptr[i]; p < a.rowptr[i + 1]; p++) {
                r -= a.val[p] * x[a.colind[p]];
                row_a += fabs(a.val[p]);
            }
            if (c == 0) best_a = row_a > best_a ? row_a : best_a;
            s += fabs(r);
            if (col1) col1[c] += fabs(r);
        }
        best = max_nan(best, s);
        if (isnan(best)) break;
    }
    if (norm_a) *norm_a = best_a;
    return best;
}

/* The largest over the k columns of ||r_j||_1 / ||x_j||_1 (r, x n x k; r1
 * holds the residual's column norms when r is NULL): what multiplies
 * ||A^-1||_1 in the forward-error bound.  0 for a zero residual, +Inf for a
 * zero column of X with a nonzero residual. */
static double residual_over_solution(const double *r1, const double *r, const double *x, int64_t n, int64_t k)
{
    double worst = 0;
    int64_t i, c;
    for (c = 0; c < k; c++) {
        double rn = 0, xn = 0;
        if (r1) rn = r1[c];
        else
            for (i = 0; i < n; i++) rn += fabs(r[i + c * n]);
        for (i = 0; i < n; i++) xn += fabs(x[i + c * n]);
        worst = max_nan(worst, rn == 0 ? 0 : rn / xn);
    }
    return worst;
}

/* G = A' R (A m x n, R m x k, G n x k zeroed by the caller). */
static void transpose_times(const silc_value *A, const double *R, int64_t k, double *G)
{
    silc_view a;
    int64_t i, j, c, p;
    val_view(A, &a);
    for (c = 0; c < k; c++) {
        const double *r = R + c * a.m;
        double *g = G + c * a.n;
        if (a.format == SILC_FMT_CSR) {
            for (i = 0; i < a.m; i++)
                for (p = a.rowptr[i]; p < a.rowptr[i + 1]; p++) g[a.colind[p]] += a.val[p] * r[i];
        } else if (a.format == SILC_FMT_BAND) {
            for (j = 0; j < a.n; j++) {
                int64_t lo_i = j - a.ku > 0 ? j - a.ku : 0;
                int64_t hi_i = j + a.kl + 1 < a.m ? j + a.kl + 1 : a.m;
                for (i = lo_i; i < hi_i; i++) g[j] += a.val[(a.ku + i - j) + j * a.ld] * r[i];
            }
        } else {
            for (j = 0; j < a.n; j++)
                for (i = 0; i < a.m; i++) g[j] += a.val[i + j * a.m] * r[i];
        }
    }
}

/*
 * Normwise backward error of X as a solution of A X = B, in the infinity norm:
 *
 *   square A:        ||B - A X|| / (||A|| ||X|| + ||B||)
 *   rectangular A:   ||A'(B - A X)|| / (||A|| (||A|| ||X|| + ||B||))
 *
 * The first is the Rigal-Gaches backward error of a linear system.  A least
 * squares solution does not make B - A X small, only orthogonal to the range
 * of A, so the second measures the normal equations' residual A'R, scaled so
 * that it is invariant under scaling A and B, as the first is.
 */
static double backward_error_whole(const silc_value *A, const silc_value *B, const silc_value *X,
                                   double *rx1)
{
    /* A one-column B's infinity norm is its largest entry: the scan the
     * solve already made of it (val_max_abs), not a properties pass.  A's
     * comes from its properties when they hold it, else from the residual's
     * pass over A. */
    double nA = (A->props_have & SILC_PROPS_NORMS) ? A->props.norminf : -1;
    double nB = B->n == 1 ? val_max_abs(B) : val_props(B)->norminf;
    double nX, nR, be = -1;
    const double *b = B->format == SILC_FMT_DENSE ? B->val : NULL;
    const double *x = X->format == SILC_FMT_DENSE ? X->val : NULL;
    double *bc = NULL, *xc = NULL, *R = NULL, *G = NULL, *col1 = NULL;
    int64_t k = X->n;
    if (rx1) *rx1 = -1;
    if (!b) b = bc = acc_dense_copy(B);
    if (!x) x = xc = acc_dense_copy(X);
    if (!b || !x) goto out;
    nX = acc_norm_inf(x, X->m, k);
    if (A->m == A->n && A->format == SILC_FMT_CSR) {
        if (rx1 && !(col1 = calloc((size_t)(k > 0 ? k : 1), sizeof *col1))) goto out;
        nR = residual_norm_csr(A, b, x, k, nA < 0 ? &nA : NULL, col1);
        if (!isfinite(nA)) nA = -1; /* overflowed: the scaled sums below */
        if (rx1) *rx1 = residual_over_solution(col1, NULL, x, A->n, k);
    } else {
        R = malloc((size_t)(A->m * k > 0 ? A->m * k : 1) * sizeof *R);
        if (!R) goto out;
        acc_residual(A, b, x, k, 0, R, NULL);
        if (A->m == A->n) {
            nR = acc_norm_inf(R, A->m, k);
            if (rx1) *rx1 = residual_over_solution(NULL, R, x, A->n, k);
        } else {
            G = calloc((size_t)(A->n * k > 0 ? A->n * k : 1), sizeof *G);
            if (!G) goto out;
            transpose_times(A, R, k, G);
            nR = acc_norm_inf(G, A->n, k);
        }
    }
    if (nA < 0) nA = val_props(A)->norminf;
    if (isnan(nR) || isnan(nX)) be = NAN;
    else if (nR == 0) be = 0; /* also 0/0: X = 0 solves B = 0 exactly */
    else if (A->m == A->n) be = nR / (nA * nX + nB);
    else be = nR / (nA * (nA * nX + nB));
out:
    free(bc);
    free(xc);
    free(R);
    free(G);
    free(col1);
    return be;
}

/* v as a dense complex m x n column-major array (malloc'd), any field. */
static double complex *complex_dense_copy(const silc_value *v)
{
    double complex *z = malloc((size_t)(v->m * v->n > 0 ? v->m * v->n : 1) * sizeof *z);
    if (!z) return NULL;
    for (int64_t j = 0; j < v->n; j++)
        for (int64_t i = 0; i < v->m; i++) z[i + j * v->m] = val_get_complex(v, i, j);
    return z;
}

/* ||z||_inf of an m x k complex array (moduli). */
static double complex_norm_inf(const double complex *z, int64_t m, int64_t k)
{
    double best = 0;
    for (int64_t i = 0; i < m; i++) {
        double s = 0;
        for (int64_t c = 0; c < k; c++) s += cabs(z[i + c * m]);
        best = max_nan(best, s);
    }
    return best;
}

typedef struct complex_residual {
    const silc_value *A;
    const double complex *x;  /* one column */
    double complex *r;        /* one column of B, becoming B - A X */
    double complex *g;        /* NULL, or A^H r accumulated (second pass) */
} complex_residual;

/* R = B - A X for a complex system (A of either field), entry by entry
 * through val_get_complex's positions: the complex systems' yardstick,
 * without the real kernel's extended residual. */
static void complex_residual_entry(int64_t i, int64_t j, double complex a, complex_residual *c)
{
    if (c->g) c->g[j] += conj(a) * c->r[i];
    else c->r[i] -= a * c->x[j];
}

static void complex_residual_pass(complex_residual *c)
{
    silc_view a;
    int64_t i, j, p;
    int w = val_width(c->A);
    val_view(c->A, &a);
#define ENTRY(k) (w == 2 ? util_cmplx(a.val[2 * (k)], a.val[2 * (k) + 1]) : a.val[k])
    if (a.format == SILC_FMT_CSR) {
        for (i = 0; i < a.m; i++)
            for (p = a.rowptr[i]; p < a.rowptr[i + 1]; p++) complex_residual_entry(i, a.colind[p], ENTRY(p), c);
    } else if (a.format == SILC_FMT_BAND) {
        for (j = 0; j < a.n; j++) {
            int64_t lo_i = j - a.ku > 0 ? j - a.ku : 0, hi_i = j + a.kl + 1 < a.m ? j + a.kl + 1 : a.m;
            for (i = lo_i; i < hi_i; i++) complex_residual_entry(i, j, ENTRY((a.ku + i - j) + j * a.ld), c);
        }
    } else {
        for (j = 0; j < a.n; j++)
            for (i = 0; i < a.m; i++) complex_residual_entry(i, j, ENTRY(i + j * a.m), c);
    }
#undef ENTRY
}

/* The backward error of a complex solve, as backward_error_whole's
 * formulas with moduli (the complex infinity norm): square A
 * ||B - AX|| / (||A|| ||X|| + ||B||), rectangular ||A^H R|| / (||A|| (...)). */
static double backward_error_complex(const silc_value *A, const silc_value *B, const silc_value *X, double *rx1)
{
    double complex *b = complex_dense_copy(B), *x = complex_dense_copy(X), *g = NULL;
    double nA = val_props_part(A, SILC_PROPS_NORMS)->norminf, nB, nX, nR, be = -1;
    int64_t k = X->n, c, i;
    if (rx1) *rx1 = -1;
    if (!b || !x || (A->m != A->n && !(g = calloc((size_t)(A->n * k > 0 ? A->n * k : 1), sizeof *g))))
        goto out;
    nB = complex_norm_inf(b, B->m, k);
    nX = complex_norm_inf(x, X->m, k);
    for (c = 0; c < k; c++) {
        complex_residual cr = {A, x + c * A->n, b + c * A->m, NULL};
        complex_residual_pass(&cr); /* b becomes the residual */
        if (g) {
            cr.g = g + c * A->n;
            complex_residual_pass(&cr);
        }
    }
    nR = g ? complex_norm_inf(g, A->n, k) : complex_norm_inf(b, A->m, k);
    if (rx1 && !g) {
        double worst = 0;
        for (c = 0; c < k; c++) {
            double rn = 0, xn = 0;
            for (i = 0; i < A->m; i++) rn += cabs(b[i + c * A->m]);
            for (i = 0; i < A->n; i++) xn += cabs(x[i + c * A->n]);
            worst = max_nan(worst, rn == 0 ? 0 : rn / xn);
        }
        *rx1 = worst;
    }
    if (isnan(nR) || isnan(nX)) be = NAN;
    else if (nR == 0) be = 0;
    else if (A->m == A->n) be = nR / (nA * nX + nB);
    else be = nR / (nA * (nA * nX + nB));
out:
    free(b);
    free(x);
    free(g);
    return be;
}

/* The complex residual's pieces for refine.c (accuracy.h): the same kernels
 * as the complex backward error, so refinement and the report measure alike. */
double complex *acc_dense_copy_complex(const silc_value *v)
{
    return complex_dense_copy(v);
}

double acc_norm_inf_complex(const double complex *z, int64_t m, int64_t k)
{
    return complex_norm_inf(z, m, k);
}

void acc_residual_complex(const silc_value *A, const double complex *B, const double complex *X, int64_t k,
                          double complex *R)
{
    memcpy(R, B, (size_t)(A->m * k) * sizeof *R);
    for (int64_t c = 0; c < k; c++) {
        complex_residual cr = {A, X + c * A->n, R + c * A->m, NULL};
        complex_residual_pass(&cr);
    }
}

/* 1 when a solve's operands or result are complex. */
static int complex_system(const silc_value *A, const silc_value *B, const silc_value *X)
{
    return A->field == SILC_FIELD_COMPLEX || B->field == SILC_FIELD_COMPLEX || X->field == SILC_FIELD_COMPLEX;
}

double acc_backward_error(const silc_value *A, const silc_value *B, const silc_value *X)
{
    if (A->dist || B->dist || X->dist) return dist_backward_error(A, B, X);
    if (complex_system(A, B, X)) return backward_error_complex(A, B, X, NULL);
    return backward_error_whole(A, B, X, NULL);
}

/* The backward error, and r->forward_bound from the residual of the same
 * pass when r holds a condition estimate of a square system (a distributed
 * one gets no bound: its residual lives on the ranks). */
static double backward_error_and_bound(const silc_value *A, const silc_value *B, const silc_value *X,
                                       silc_report *r)
{
    double rx1 = -1, be, nA1;
    r->forward_bound = -1;
    if (A->dist || B->dist || X->dist) return dist_backward_error(A, B, X);
    if (complex_system(A, B, X)) {
        be = backward_error_complex(A, B, X, r->cond_est >= 0 && A->m == A->n ? &rx1 : NULL);
    } else {
        if (!(r->cond_est >= 0) || A->m != A->n) return backward_error_whole(A, B, X, NULL);
        be = backward_error_whole(A, B, X, &rx1);
    }
    /* ||A^-1||_1 is estimated as cond_est / ||A||_1, as the plugin made it */
    nA1 = val_props_part(A, SILC_PROPS_NORMS)->norm1;
    if (rx1 >= 0 && nA1 > 0) r->forward_bound = isinf(r->cond_est) ? INFINITY : r->cond_est / nA1 * rx1;
    return be;
}

/* ---- when -------------------------------------------------------------------- */

static void warn_if_unsolved(silc_engine *E, const char *backend, double be)
{
    /* A result that does not solve the system is never returned silently,
     * whatever the backend claimed. */
    if (be > 1e-3)
        eng_warn(E, "'\\': the result of %s has backward error %.2g: it does not solve the system",
                 backend, be);
}

double acc_verify_limit(const char *v, const silc_report *r)
{
    double direct = 1e-6, iter;
    char *end;
    if (v && !strcmp(v, "off")) return INFINITY;
    if (v && strcmp(v, "auto")) {
        double x = strtod(v, &end);
        if (end != v && !*end && x > 0) direct = x;
    }
    if (r->iterations <= 0) return direct;
    /* The backward error is at most ||r|| / ||b|| (infinity norms), which an
     * iterative method bounded in its own norm: the factor absorbs the norms'
     * difference, not a missed tolerance. */
    iter = r->tol > 0 ? ACC_VERIFY_FACTOR * r->tol : 1e-3;
    return iter > direct ? iter : direct;
}

void acc_report(silc_engine *E, silc_call *call, int may_defer, const char *when)
{
    silc_report *r = call->report;
    if (may_defer && r->iterations == 0 && r->backward_error_unrefined < 0) {
        int defer;
        if (when && strcmp(when, "on_request") == 0) defer = 1;
        else defer = r->reused_factor && !(when && strcmp(when, "always") == 0);
        if (defer) {
            r->backward_error = ACC_DEFERRED;
            r->forward_bound = -1; /* with the backward error, when info asks */
            return;
        }
    }
    r->backward_error = backward_error_and_bound(call->in[0], call->in[1], call->out, r);
    warn_if_unsolved(E, r->backend, r->backward_error);
}

double acc_cond_lower_bound(const silc_value *A, const silc_value *B, const silc_value *X)
{
    double best = -1, nA1;
    int64_t i, j;
    int w = X->field == SILC_FIELD_COMPLEX ? 2 : 1; /* doubles per entry; complex: by modulus */
    if (A->m != A->n || A->dist || B->dist || X->dist || B->format != SILC_FMT_DENSE ||
        X->format != SILC_FMT_DENSE || B->m != X->m || B->n != X->n ||
        (B->field == SILC_FIELD_COMPLEX) != (w == 2))
        return -1;
    for (j = 0; j < X->n; j++) {
        const double *b = B->val + j * B->m * w, *x = X->val + j * X->m * w;
        double sb = 0, sx = 0;
        for (i = 0; i < X->m; i++) {
            sb += w == 2 ? hypot(b[2 * i], b[2 * i + 1]) : fabs(b[i]);
            sx += w == 2 ? hypot(x[2 * i], x[2 * i + 1]) : fabs(x[i]);
        }
        if (sb > 0 && sx / sb > best) best = sx / sb; /* NaN compares false: skipped */
    }
    if (best < 0) return -1;
    nA1 = val_props_part(A, SILC_PROPS_NORMS)->norm1;
    return nA1 * best;
}

void acc_pending_resolve(silc_engine *E, eng_pending *p, silc_report *r)
{
    r->backward_error = p->A && p->B && p->X ? backward_error_and_bound(p->A, p->B, p->X, r) : -1;
    warn_if_unsolved(E, r->backend, r->backward_error);
    eng_pending_release(p);
}
