/*
 * ref_cond.c -- Hager's 1-norm estimator with Higham's refinements (the
 * algorithm of LAPACK dlacon), applied to the inverse of a factored matrix.
 *
 * Every direct solver of the reference plugin reports cond_1(A) ~ ||A||_1 *
 * est(||A^{-1}||_1).  The estimate needs only solves with A and A', which the
 * factorization provides, so it costs a handful of triangular solves.  It is a
 * lower bound that is almost always within a factor 3 of the truth.
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

double ref_inv_norm1_est(int64_t n, int (*apply)(void *ctx, double *x, int trans, double *work),
                         void *ctx, double *work)
{
    if (n <= 0) return 0.0;
    double *x = ref_alloc((size_t)n, sizeof(double));
    double *xi = ref_alloc((size_t)n, sizeof(double));
    double est = -1.0;
    if (!x || !xi) goto done;
    for (int64_t i = 0; i < n; i++) x[i] = 1.0 / (double)n;
    if (apply(ctx, x, 0, work)) goto done;
    est = sum_abs(n, x);
    if (n == 1 || !isfinite(est)) goto done;
    for (int64_t i = 0; i < n; i++) xi[i] = x[i] >= 0 ? 1.0 : -1.0;
    memcpy(x, xi, (size_t)n * sizeof(double));
    if (apply(ctx, x, 1, work)) goto done;
    int64_t j = 0;
    for (int iter = 0; iter < 5; iter++) {
        int64_t jnew = 0;
        for (int64_t i = 1; i < n; i++)
            if (fabs(x[i]) > fabs(x[jnew])) jnew = i;
        if (iter > 0 && (jnew == j || fabs(x[jnew]) == fabs(x[j]))) break;
        j = jnew;
        memset(x, 0, (size_t)n * sizeof(double));
        x[j] = 1.0;
        if (apply(ctx, x, 0, work)) goto done;
        double old = est;
        est = sum_abs(n, x);
        if (!isfinite(est)) goto done;
        int same = 1;
        for (int64_t i = 0; i < n; i++)
            if ((x[i] >= 0 ? 1.0 : -1.0) != xi[i]) same = 0;
        if (same || est <= old) {
            est = est > old ? est : old;
            break;
        }
        for (int64_t i = 0; i < n; i++) xi[i] = x[i] >= 0 ? 1.0 : -1.0;
        memcpy(x, xi, (size_t)n * sizeof(double));
        if (apply(ctx, x, 1, work)) goto done;
    }
    /* Higham's alternating vector guards against the rare cases where the
     * power-method steps above stall on a poor local maximum. */
    for (int64_t i = 0; i < n; i++) x[i] = (i % 2 ? -1.0 : 1.0) * (1.0 + (double)i / (double)(n - 1));
    if (apply(ctx, x, 0, work)) goto done;
    {
        double alt = 2.0 * sum_abs(n, x) / (3.0 * (double)n);
        if (alt > est || !isfinite(alt)) est = alt;
    }
done:
    ref_free(x);
    ref_free(xi);
    return est;
}

double ref_cond_from(double anorm, double inv_est)
{
    if (inv_est < 0) return -1.0;
    if (!isfinite(inv_est) || !isfinite(anorm)) return INFINITY;
    if (anorm == 0.0 || inv_est == 0.0) return anorm == 0.0 ? INFINITY : 0.0;
    return anorm * inv_est;
}
