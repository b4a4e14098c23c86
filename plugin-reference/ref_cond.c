/*
 * ref_cond.c -- estimates of ||M^{-1}||_1 for a factored matrix M: Higham and
 * Tisseur's block 1-norm estimator (SIAM J. Matrix Anal. Appl. 21, 2000,
 * Algorithm 2.4, the method of MATLAB's normest1).  Its one-column form is
 * Hager's method with Higham's refinements (LAPACK dlacon), which every
 * direct solver of the reference plugin uses for cond_1(M) ~ ||M||_1 *
 * est(||M^{-1}||_1); the core lends both forms to plugins (silc_plugin.h).
 *
 * The estimate needs only solves with M and M', which the factorization
 * provides: a handful of triangular solves.  It is a lower bound that is
 * almost always within a factor 3 of the truth.  The block form applies t
 * columns per solve; a library whose solve phase costs the same for a few
 * columns as for one (MUMPS) gets a better estimate from fewer solve phases,
 * and can fold the first block into the user's own solve (Y0).
 */
#include "ref.h"

#include <math.h>
#include <string.h>

static double sum_abs(int64_t n, const double *x)
{
    double s = 0.0;
    for (int64_t i = 0; i < n; i++) s += fabs(x[i]);
    return s;
}

/* Higham's alternating vector x_i = (-1)^i (1 + i/(n-1)), scaled to 1-norm
 * 1: it guards against the rare matrices on which the power steps stall on a
 * poor local maximum. */
static void alternating(int64_t n, double *x)
{
    if (n == 1) {
        x[0] = 1.0;
        return;
    }
    for (int64_t i = 0; i < n; i++)
        x[i] = (i % 2 ? -1.0 : 1.0) * (1.0 + (double)i / (double)(n - 1)) / (1.5 * (double)n);
}

void ref_inv_norm1_start(int64_t n, int t, double *X)
{
    uint64_t r = 0x9E3779B97F4A7C15u; /* fixed: estimates are reproducible */
    for (int64_t i = 0; i < n; i++) X[i] = 1.0 / (double)n;
    if (t >= 2) alternating(n, X + n);
    for (int j = 2; j < t; j++)
        for (int64_t i = 0; i < n; i++) {
            r ^= r << 13, r ^= r >> 7, r ^= r << 17;
            X[i + j * n] = (r >> 63 ? -1.0 : 1.0) / (double)n;
        }
}

/* Every column of S (n x t) equals plus or minus some column of P. */
static int all_parallel(int64_t n, int t, const double *S, const double *P)
{
    for (int j = 0; j < t; j++) {
        int found = 0;
        for (int q = 0; q < t && !found; q++) {
            double d = 0.0;
            for (int64_t i = 0; i < n; i++) d += S[i + j * n] * P[i + q * n];
            found = fabs(d) == (double)n;
        }
        if (!found) return 0;
    }
    return 1;
}

/* The index of the largest h[i] with skip[i] == 0 (taken[] excluded too), or -1. */
static int64_t largest(int64_t n, const double *h, const unsigned char *skip, const unsigned char *taken)
{
    int64_t best = -1;
    for (int64_t i = 0; i < n; i++)
        if (!(skip && skip[i]) && !taken[i] && (best < 0 || h[i] > h[best])) best = i;
    return best;
}

double ref_inv_norm1_est_block(int64_t n, int t, int itmax,
                               int (*apply)(void *ctx, double *X, int t, int trans), void *ctx,
                               const double *Y0)
{
    if (n <= 0) return 0.0;
    if (t > n) t = (int)n;
    if (t < 1) t = 1;
    if (t > 64) t = 64;
    if (itmax < 2) itmax = 2;
    size_t nt = (size_t)n * (size_t)t;
    double *X = ref_alloc(nt, sizeof(double)), *S = ref_alloc(nt, sizeof(double));
    double *Sold = ref_alloc(nt, sizeof(double)), *h = ref_alloc((size_t)n, sizeof(double));
    unsigned char *used = ref_alloc((size_t)n, 1), *taken = ref_alloc((size_t)n, 1);
    int64_t ind[64], ind_best = -1;
    double est = -1.0;
    if (!X || !S || !Sold || !h || !used || !taken) goto done;
    memset(used, 0, (size_t)n);
    memset(taken, 0, (size_t)n);
    if (Y0) {
        memcpy(X, Y0, nt * sizeof(double));
    } else {
        ref_inv_norm1_start(n, t, X);
        if (apply(ctx, X, t, 0)) goto fail;
    }
    for (int k = 1;; k++) {
        /* X holds Y = M^{-1} X_k: its largest column 1-norm is a lower bound. */
        double cur = -1.0;
        int jbest = 0;
        for (int j = 0; j < t; j++) {
            double s = sum_abs(n, X + (size_t)j * n);
            if (!isfinite(s)) {
                est = s;
                goto done;
            }
            if (s > cur) cur = s, jbest = j;
        }
        if (k >= 2 && cur <= est) break;
        est = cur;
        if (k >= 2) ind_best = ind[jbest];
        if (k >= itmax || n == 1) break;
        for (size_t q = 0; q < nt; q++) S[q] = X[q] >= 0 ? 1.0 : -1.0;
        /* Signs seen before: the next step would repeat an earlier one. */
        if (k >= 2 && all_parallel(n, t, S, Sold)) break;
        memcpy(X, S, nt * sizeof(double));
        if (apply(ctx, X, t, 1)) goto fail;
        for (int64_t i = 0; i < n; i++) {
            double m = 0.0;
            for (int j = 0; j < t; j++)
                if (fabs(X[i + (size_t)j * n]) > m) m = fabs(X[i + (size_t)j * n]);
            h[i] = m;
        }
        /* The gradient points at the unit vector already best: converged. */
        if (ind_best >= 0 && h[largest(n, h, NULL, taken)] == h[ind_best]) break;
        /* The t most promising unit vectors; if all were tried, converged. */
        {
            int fresh = 0;
            int64_t top[64];
            for (int j = 0; j < t; j++) {
                top[j] = largest(n, h, NULL, taken);
                taken[top[j]] = 1;
                fresh |= !used[top[j]];
            }
            for (int j = 0; j < t; j++) taken[top[j]] = 0; /* t marks, not an O(n) clear */
            if (!fresh) break;
        }
        for (int j = 0; j < t; j++) {
            int64_t i = largest(n, h, used, taken);
            if (i < 0) { /* fewer than t untried left (at least one: see above) */
                t = j;
                break;
            }
            taken[i] = 1;
            ind[j] = i;
        }
        for (int j = 0; j < t; j++) taken[ind[j]] = 0;
        memcpy(Sold, S, nt * sizeof(double));
        nt = (size_t)n * (size_t)t;
        memset(X, 0, nt * sizeof(double));
        for (int j = 0; j < t; j++) {
            X[ind[j] + (size_t)j * n] = 1.0;
            used[ind[j]] = 1;
        }
        if (apply(ctx, X, t, 0)) goto fail;
    }
    goto done;
fail:
    est = -1.0;
done:
    ref_free(X);
    ref_free(S);
    ref_free(Sold);
    ref_free(h);
    ref_free(used);
    ref_free(taken);
    return est;
}

/* The one-column form on a one-vector solve callback. */
typedef struct one_column {
    int (*apply)(void *ctx, double *x, int trans, double *work);
    void *ctx;
    double *work;
} one_column;

static int apply_one(void *ctx, double *X, int t, int trans)
{
    const one_column *c = ctx;
    (void)t; /* always 1 here */
    return c->apply(c->ctx, X, trans, c->work);
}

double ref_inv_norm1_est(int64_t n, int (*apply)(void *ctx, double *x, int trans, double *work),
                         void *ctx, double *work)
{
    one_column c = {apply, ctx, work};
    double est = ref_inv_norm1_est_block(n, 1, 5, apply_one, &c, NULL), alt;
    double *x;
    if (est < 0 || n < 2 || !isfinite(est)) return est;
    if (!(x = ref_alloc((size_t)n, sizeof(double)))) return -1.0;
    alternating(n, x);
    if (apply(ctx, x, 0, work)) est = -1.0;
    else if ((alt = sum_abs(n, x)) > est || !isfinite(alt)) est = alt;
    ref_free(x);
    return est;
}

double ref_cond_from(double anorm, double inv_est)
{
    if (inv_est < 0) return -1.0;
    if (!isfinite(inv_est) || !isfinite(anorm)) return INFINITY;
    if (anorm == 0.0 || inv_est == 0.0) return anorm == 0.0 ? INFINITY : 0.0;
    return anorm * inv_est;
}
