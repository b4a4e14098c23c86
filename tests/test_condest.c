/*
 * test_condest.c -- the 1-norm estimators the host lends to plugins
 * (silc_plugin.h: inv_norm1_est, ABI 1.1, and the block form
 * inv_norm1_est_block / inv_norm1_start, ABI 1.3), on operators whose
 * 1-norm is known exactly.
 *
 * The estimators only apply an operator B and its transpose (for a plugin,
 * B = A^{-1} through its factors), so B is given here directly, as a dense
 * matrix whose 1-norm is its largest column sum:
 *   - the inverse of a bidiagonal matrix with -c below the diagonal
 *     (B_ij = c^(i-j)), whose norm is the first column's: the estimate must
 *     be exact;
 *   - 40 pseudo-random 100 x 100 matrices of each of three kinds (uniform in
 *     [-1, 1], one heavy column, rank one plus noise), for the one-column
 *     form and the block form with t = 2 and 4 and two or five steps: every
 *     estimate a lower bound (up to rounding), none under a third of the
 *     norm, and the block form's mean ratio at least the one-column form's
 *     minus a margin;
 *   - the block form given Y0 = B X0 (the first block folded into a solve
 *     the caller makes anyway) returns what it returns when it applies X0
 *     itself, with one application of B fewer;
 *   - a failing apply gives -1, a non-finite one a non-finite estimate,
 *     n = 1 and t > n work;
 *   - ties in the gradient (B = 2 I: every unit vector as promising) pick
 *     the first indices, as a stable sort would, and the estimate is exact.
 */
#include "check.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "dispatch.h"
#include "engine.h"
#include "silc.h"
#include "silc_plugin.h"

typedef struct op {
    int64_t n;
    double *B;     /* column-major n x n */
    int applies;   /* applications of B (trans = 0) */
    int fail_at;   /* apply number that fails (0 = never) */
    int poison;    /* put an Inf into the result */
    double *seen;  /* when set: receives the block of the second application of B */
} op;

static int apply_block(void *ctx, double *X, int t, int trans)
{
    op *o = ctx;
    int64_t n = o->n, i, j, k;
    double *y = malloc((size_t)n * sizeof *y);
    if (!y) return -1;
    if (!trans && ++o->applies == o->fail_at) {
        free(y);
        return -1;
    }
    if (!trans && o->applies == 2 && o->seen) memcpy(o->seen, X, (size_t)(n * t) * sizeof *X);
    for (k = 0; k < t; k++) {
        double *x = X + k * n;
        for (i = 0; i < n; i++) {
            double s = 0;
            for (j = 0; j < n; j++) s += (trans ? o->B[j + i * n] : o->B[i + j * n]) * x[j];
            y[i] = s;
        }
        memcpy(x, y, (size_t)n * sizeof *y);
        if (o->poison) x[0] = INFINITY;
    }
    free(y);
    return 0;
}

/* The one-column callback of ABI 1.1 on the same operator. */
static int apply_one(void *ctx, double *x, int trans, double *work)
{
    (void)work;
    return apply_block(ctx, x, 1, trans);
}

static double norm1(const op *o)
{
    double best = 0;
    int64_t i, j;
    for (j = 0; j < o->n; j++) {
        double s = 0;
        for (i = 0; i < o->n; i++) s += fabs(o->B[i + j * o->n]);
        if (s > best) best = s;
    }
    return best;
}

static uint64_t rng = 0x2545F4914F6CDD1Du;
static double uniform(void) /* in [-1, 1] */
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0 * 2 - 1;
}

static void fill(op *o, int kind)
{
    int64_t n = o->n, i, j;
    double *u = malloc((size_t)n * sizeof *u), *v = malloc((size_t)n * sizeof *v);
    for (i = 0; i < n; i++) u[i] = uniform(), v[i] = uniform();
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) {
            double x = uniform();
            if (kind == 1 && j == (int64_t)(fabs(u[0]) * (double)(n - 1))) x *= 20; /* one heavy column */
            if (kind == 2) x = 10 * u[i] * v[j] + 0.01 * x;                          /* rank one + noise */
            o->B[i + j * n] = x;
        }
    free(u);
    free(v);
}

static void test_bidiagonal_inverse(const silc_host_api *h)
{
    const int64_t n = 30;
    const double c = 0.9;
    op o = {n, calloc((size_t)(n * n), sizeof(double)), 0, 0, 0, NULL};
    double exact, est;
    int64_t i, j;
    for (j = 0; j < n; j++)
        for (i = j; i < n; i++) o.B[i + j * n] = pow(c, (double)(i - j));
    exact = norm1(&o);
    est = h->inv_norm1_est(n, apply_one, &o, NULL);
    CHECK(fabs(est - exact) <= 1e-12 * exact, "bidiagonal inverse, one column: %.17g, exact %.17g", est, exact);
    est = h->inv_norm1_est_block(n, 2, 2, apply_block, &o, NULL);
    CHECK(fabs(est - exact) <= 1e-12 * exact, "bidiagonal inverse, t = 2: %.17g, exact %.17g", est, exact);
    free(o.B);
}

static void test_random(const silc_host_api *h)
{
    static const struct {
        int t, itmax;
    } forms[] = {{1, 5}, {2, 2}, {2, 5}, {4, 2}};
    const int64_t n = 100;
    const int trials = 40;
    op o = {n, malloc((size_t)(n * n) * sizeof(double)), 0, 0, 0, NULL};
    double sum[4] = {0}, worst[4] = {1, 1, 1, 1};
    int kind, trial, f;
    for (kind = 0; kind < 3; kind++)
        for (trial = 0; trial < trials; trial++) {
            double exact;
            fill(&o, kind);
            exact = norm1(&o);
            for (f = 0; f < 4; f++) {
                double est = forms[f].t == 1 ? h->inv_norm1_est(n, apply_one, &o, NULL)
                                             : h->inv_norm1_est_block(n, forms[f].t, forms[f].itmax,
                                                                      apply_block, &o, NULL);
                double r = est / exact;
                CHECK(r <= 1 + 1e-12, "kind %d trial %d t %d: estimate %.17g above the norm %.17g", kind,
                      trial, forms[f].t, est, exact);
                CHECK(r >= 1.0 / 3, "kind %d trial %d t %d itmax %d: estimate %g, norm %g", kind, trial,
                      forms[f].t, forms[f].itmax, est, exact);
                sum[f] += r;
                if (r < worst[f]) worst[f] = r;
            }
        }
    for (f = 0; f < 4; f++)
        printf("t = %d, itmax = %d: mean ratio %.4f, worst %.4f over %d operators\n", forms[f].t,
               forms[f].itmax, sum[f] / (3 * trials), worst[f], 3 * trials);
    CHECK(sum[1] >= sum[0] - 0.02 * 3 * trials, "t = 2 (mean %.4f) is not worse than t = 1 (mean %.4f)",
          sum[1] / (3 * trials), sum[0] / (3 * trials));
    free(o.B);
}

static void test_folded_start(const silc_host_api *h)
{
    const int64_t n = 60;
    const int t = 2;
    op o = {n, malloc((size_t)(n * n) * sizeof(double)), 0, 0, 0, NULL};
    double *Y0 = malloc((size_t)(n * t) * sizeof *Y0), a, b;
    int applies;
    fill(&o, 0);
    a = h->inv_norm1_est_block(n, t, 2, apply_block, &o, NULL);
    applies = o.applies;
    h->inv_norm1_start(n, t, Y0);
    {
        int alternates = 1;
        for (int64_t i = 0; i + 1 < n; i++) alternates &= Y0[n + i] * Y0[n + i + 1] < 0;
        CHECK(fabs(Y0[0] - 1.0 / n) < 1e-18 && alternates, "starting block: e/n, then the alternating vector");
    }
    apply_block(&o, Y0, t, 0);
    o.applies = 0;
    b = h->inv_norm1_est_block(n, t, 2, apply_block, &o, Y0);
    CHECK(a == b, "folded start: %.17g, applied start: %.17g", b, a);
    CHECK(o.applies == applies - 1, "folded start saves one application of B (%d against %d)", o.applies,
          applies);
    free(Y0);
    free(o.B);
}

static void test_edges(const silc_host_api *h)
{
    const int64_t n = 20;
    op o = {n, malloc((size_t)(n * n) * sizeof(double)), 0, 0, 0, NULL};
    double one[1] = {-4}, est;
    op single = {1, one, 0, 0, 0, NULL};
    fill(&o, 0);
    o.fail_at = 2;
    CHECK(h->inv_norm1_est_block(n, 2, 2, apply_block, &o, NULL) == -1, "a failing apply gives -1 (block)");
    o.applies = 0;
    CHECK(h->inv_norm1_est(n, apply_one, &o, NULL) == -1, "a failing apply gives -1 (one column)");
    o.fail_at = 0;
    o.poison = 1;
    est = h->inv_norm1_est_block(n, 2, 2, apply_block, &o, NULL);
    CHECK(!isfinite(est), "an Inf in a solve gives a non-finite estimate, got %g", est);
    o.poison = 0;
    CHECK(h->inv_norm1_est_block(1, 1, 2, apply_block, &single, NULL) == 4, "n = 1, t = 1");
    CHECK(h->inv_norm1_est_block(1, 3, 2, apply_block, &single, NULL) == 4, "n = 1, t = 3 (t > n)");
    CHECK(h->inv_norm1_est(1, apply_one, &single, NULL) == 4, "n = 1, one column");
    est = h->inv_norm1_est_block(n, 70, 2, apply_block, &o, NULL); /* t > n and > 64: clamped */
    CHECK(fabs(est - norm1(&o)) <= 1e-12 * norm1(&o), "t >= n probes every unit vector: %g against %g", est,
          norm1(&o));
    free(o.B);
}

static void test_tied_gradient(const silc_host_api *h)
{
    const int64_t n = 6;
    const int t = 2;
    op o = {n, calloc((size_t)(n * n), sizeof(double)), 0, 0, 0, NULL};
    double seen[12], est;
    int64_t i;
    for (i = 0; i < n; i++) o.B[i + i * n] = 2;
    o.seen = seen;
    est = h->inv_norm1_est_block(n, t, 5, apply_block, &o, NULL);
    CHECK(est == 2, "B = 2 I: estimate %.17g, exact 2", est);
    CHECK(o.applies == 2, "B = 2 I: the start and one unit-vector step (%d applications)", o.applies);
    for (i = 0; i < n * t; i++)
        CHECK(seen[i] == (i == 0 || i == n + 1 ? 1.0 : 0.0),
              "tied gradient: unit vectors e_1 and e_2 are tried first (entry %lld is %g)", (long long)i, seen[i]);
    free(o.B);
}

int main(void)
{
    const silc_host_api *h = host_api();
    silc_context *c = NULL;
    int rc;
    /* The estimators live in the built-in reference plugin, started by the first open. */
    CHECK(silc_open(&c, NULL) == 0, "open: %s", c ? silc_context_errmsg(c) : silc_errmsg());
    CHECK(h->abi_minor >= 3 && h->inv_norm1_est_block && h->inv_norm1_start, "host table has ABI 1.3");
    test_bidiagonal_inverse(h);
    test_random(h);
    test_folded_start(h);
    test_edges(h);
    test_tied_gradient(h);
    rc = check_done();
    silc_close(&c);
    return rc;
}
