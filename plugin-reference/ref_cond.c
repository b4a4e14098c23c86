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
 *
 * For a complex matrix, ref_inv_norm1_est_complex is the one-column method
 * of LAPACK's zlacn2 (Higham, "FORTRAN codes for estimating the one-norm of
 * a real or complex matrix", ACM TOMS 14, 1988, Algorithm 4.1).  It is kept
 * apart from the block form rather than folded into it because the two
 * differ in more than arithmetic: the complex "sign" of y is y/|y| (a point
 * on the unit circle, not +-1), so the real form's test that a sign vector
 * repeats an earlier one (all_parallel) has no counterpart and zlacn2 stops
 * instead when the gradient's largest entry stops moving; and the block
 * form's column bookkeeping (t > 1) serves no complex caller.  What is the
 * same, the alternating start vector and the final check with it, is shared.
 */
#include "ref.h"

#include <complex.h>
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

/* Inserts i into top[0..*len) (at most t entries), kept in the order of a
 * stable sort by decreasing h: an index goes after those with equal h, so
 * the list is what t passes of "largest remaining, first among equals"
 * would pick. */
static void top_insert(int64_t *top, int *len, int t, const double *h, int64_t i)
{
    int p = *len;
    if (p == t && !(h[i] > h[top[t - 1]])) return;
    if (p == t) p--;
    while (p > 0 && h[i] > h[top[p - 1]]) {
        top[p] = top[p - 1];
        p--;
    }
    top[p] = i;
    if (*len < t) (*len)++;
}

/* One pass over h (n entries): the t largest entries (top, *ntop; top[0]
 * is the largest) and the t largest not yet used (fresh, *nfresh).  Most
 * entries fail the first compare with the smallest kept, so the pass costs
 * about what one "largest" pass did. */
static void select_top(int64_t n, int t, const double *h, const unsigned char *used, int64_t *top, int *ntop,
                       int64_t *fresh, int *nfresh)
{
    *ntop = *nfresh = 0;
    for (int64_t i = 0; i < n; i++) {
        if (*ntop < t || h[i] > h[top[t - 1]]) top_insert(top, ntop, t, h, i);
        if (!used[i] && (*nfresh < t || h[i] > h[fresh[t - 1]])) top_insert(fresh, nfresh, t, h, i);
    }
}

/* The bookkeeping between solves is a few O(n t) passes (the column sums,
 * the signs, h and one selection pass) and one allocation: on a very sparse
 * matrix a solve costs little more than a pass over its factors, so passes
 * here count next to the solves (KLU on 494_bus: the estimator's own work
 * was a third of a refactorization with one "largest" pass per pick). */
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
    /* X, S, Sold (n x t each), h (n), then the used flags (n bytes) */
    double *X = ref_alloc(3 * nt + (size_t)n + ((size_t)n + sizeof(double) - 1) / sizeof(double), sizeof(double));
    double *S = X + nt, *Sold = S + nt, *h = Sold + nt;
    unsigned char *used = (unsigned char *)(h + n);
    int64_t ind[64], top[64], ind_best = -1;
    double est = -1.0;
    if (!X) return -1.0;
    memset(used, 0, (size_t)n);
    if (Y0) {
        memcpy(X, Y0, nt * sizeof(double));
    } else {
        ref_inv_norm1_start(n, t, X);
        if (apply(ctx, X, t, 0)) goto fail;
    }
    for (int k = 1;; k++) {
        /* X holds Y = M^{-1} X_k: its largest column 1-norm is a lower bound. */
        double cur = -1.0;
        int jbest = 0, ntop, nfresh, any_fresh = 0;
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
        if (t == 1) /* the one-column form (SuiteSparse, dlacon's): no inner loop; a NaN gives 0 as below */
            for (int64_t i = 0; i < n; i++) h[i] = fabs(X[i]) > 0.0 ? fabs(X[i]) : 0.0;
        else
            for (int64_t i = 0; i < n; i++) {
                double m = 0.0;
                for (int j = 0; j < t; j++)
                    if (fabs(X[i + (size_t)j * n]) > m) m = fabs(X[i + (size_t)j * n]);
                h[i] = m;
            }
        select_top(n, t, h, used, top, &ntop, ind, &nfresh);
        /* The gradient points at the unit vector already best: converged. */
        if (ind_best >= 0 && h[top[0]] == h[ind_best]) break;
        /* The t most promising unit vectors; if all were tried, converged. */
        for (int j = 0; j < ntop; j++) any_fresh |= !used[top[j]];
        if (!any_fresh) break;
        t = nfresh; /* fewer than t untried left (at least one: see above) */
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
    return ref_inv_norm1_est_from(n, apply, ctx, work, NULL);
}

double ref_inv_norm1_est_from(int64_t n, int (*apply)(void *ctx, double *x, int trans, double *work),
                              void *ctx, double *work, const double *Y)
{
    one_column c = {apply, ctx, work};
    double est = ref_inv_norm1_est_block(n, 1, 5, apply_one, &c, Y), alt;
    double *x;
    if (est < 0 || n < 2 || !isfinite(est)) return est;
    if (Y) { /* the alternating vector was solved with the start */
        alt = sum_abs(n, Y + n);
        return alt > est || !isfinite(alt) ? alt : est;
    }
    if (!(x = ref_alloc((size_t)n, sizeof(double)))) return -1.0;
    alternating(n, x);
    if (apply(ctx, x, 0, work)) est = -1.0;
    else if ((alt = sum_abs(n, x)) > est || !isfinite(alt)) est = alt;
    ref_free(x);
    return est;
}

/* sum |x_i| over n complex entries (LAPACK dzsum1). */
static double sum_mod(int64_t n, const double complex *x)
{
    double s = 0.0;
    for (int64_t i = 0; i < n; i++) s += cabs(x[i]);
    return s;
}

/* The first index of the largest modulus (LAPACK izmax1). */
static int64_t max_mod_index(int64_t n, const double complex *x)
{
    int64_t j = 0;
    double big = -1.0;
    for (int64_t i = 0; i < n; i++)
        if (cabs(x[i]) > big) big = cabs(x[i]), j = i;
    return j;
}

double ref_inv_norm1_est_complex(int64_t n, int (*apply)(void *ctx, double *x, int trans, double *work),
                                 void *ctx, double *work)
{
    enum { ITMAX = 5 };
    if (n <= 0) return 0.0;
    double complex *x = ref_alloc((size_t)n, sizeof(double complex));
    double est = -1.0, estold;
    if (!x) return -1.0;
    for (int64_t i = 0; i < n; i++) x[i] = 1.0 / (double)n;
    if (apply(ctx, (double *)x, 0, work)) goto fail;
    est = sum_mod(n, x);
    if (n == 1 || !isfinite(est)) goto done;
    int64_t j = 0;
    for (int iter = 1;; iter++) {
        /* x = A^{-H} sign(A^{-1} x): the gradient; its largest entry names
         * the unit vector to try next */
        for (int64_t i = 0; i < n; i++) x[i] = cabs(x[i]) > 0 ? x[i] / cabs(x[i]) : 1.0;
        if (apply(ctx, (double *)x, 1, work)) goto fail;
        int64_t jlast = j;
        j = max_mod_index(n, x);
        if (iter >= 2 && (cabs(x[jlast]) == cabs(x[j]) || iter >= ITMAX)) break;
        memset(x, 0, (size_t)n * sizeof *x);
        x[j] = 1.0;
        if (apply(ctx, (double *)x, 0, work)) goto fail;
        estold = est;
        est = sum_mod(n, x);
        if (!isfinite(est)) goto done;
        if (est <= estold) { /* no progress: keep the better bound (zlacn2 drops it) */
            est = estold;
            break;
        }
    }
    /* Higham's alternating vector, as the real estimator's last step: the
     * real values are written into the first n doubles and spread to the
     * real parts from the last entry down, so no entry is read after its
     * slot is overwritten. */
    alternating(n, (double *)x);
    for (int64_t i = n - 1; i >= 0; i--) x[i] = ((double *)x)[i];
    if (apply(ctx, (double *)x, 0, work)) goto fail;
    double alt = sum_mod(n, x);
    if (alt > est || !isfinite(alt)) est = alt;
    goto done;
fail:
    est = -1.0;
done:
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
