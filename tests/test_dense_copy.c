/*
 * test_dense_copy.c -- a bare dense solve's shape pass that also copies A
 * for the backend (dispatch.c's prepare_dense_copy, value.c's
 * val_shape_into, host->take_dense_copy), against a brute-force scan of the
 * same matrix and against the solve without the copy.
 *
 * For dense matrices with the edge cases of the dispatcher's classification
 * (zero corners, NaN in a corner, Inf in the middle, triangular with one
 * entry across the diagonal in the middle, banded, symmetric with a
 * positive diagonal, symmetric indefinite, all-zero, 1x1, rectangular,
 * general):
 *   - val_shape_into gives the shape and the scan a brute-force scan of the
 *     entries gives, and a copy equal to the entries bit for bit; it does
 *     nothing to a value whose shape is known, nor to a CSR value;
 *   - `x = A \ b` in the bare mode (accuracy.condest = off,
 *     solve.backward_error = on_request: the copy is made when A's corners
 *     are nonzero) gives the same backend, method and bits of x, or the same
 *     error, as the default mode on a fresh copy of A (whose norms' pass
 *     makes no copy), and the bare A's shape asked afterwards is the
 *     brute-force one;
 *   - the copy is made exactly when the corners say so and the backend
 *     takes it: an array pool counting the n x n arrays sees the first one
 *     allocated before A's shape is known (the dispatcher's), and no second;
 *   - the pass's kernel, which reads eight entries a step and then a tail,
 *     gives brute force's answers with a special entry (the largest
 *     magnitude, -0.0, a signed NaN with a payload, Inf, Inf and NaN in one
 *     column, a lone subnormal) at every row of a 13-row column;
 *   - a NaN deep inside a general 300 x 300 A, and with b NaN as well, is
 *     refused naming A and its position, the message the default mode gives.
 */
#include "check.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "client.h"
#include "engine.h"
#include "context.h"
#include "store.h"
#include "util.h"

static silc_engine *E;
static char err[1024];

/* ---- the array pool's view of a solve ---------------------------------------- */

static const silc_value *watched;  /* the A of the solve being watched */
static size_t watched_bytes;       /* its n x n array's size */
static int square_arrays, early_square_arrays;

/* Counts the arrays of A's size, and those taken before A's shape was
 * known: only the dispatcher's copy is made then (the backend's own copy
 * comes after the classification). */
static void *count_take(size_t bytes)
{
    if (watched && bytes == watched_bytes) {
        square_arrays++;
        early_square_arrays += !(watched->props_have & SILC_PROPS_SHAPE);
    }
    return NULL; /* then malloc, as without a pool */
}

static int give_none(void *p)
{
    (void)p;
    return 0;
}

/* ---- matrices ---------------------------------------------------------------- */

typedef struct shape {
    int diagonal, lower, upper, pos_diag, has_nonfinite;
    int64_t kl, ku, nnz;
    uint64_t maxbits;
} shape;

/* The shape by its definitions, entry by entry. */
static shape brute(const double *a, int64_t m, int64_t n)
{
    shape s;
    int64_t pos = 0;
    memset(&s, 0, sizeof s);
    s.diagonal = s.lower = s.upper = 1;
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < m; i++) {
            double x = a[i + j * m];
            uint64_t bits;
            memcpy(&bits, &x, sizeof bits);
            bits &= 0x7fffffffffffffffULL;
            if (bits > s.maxbits) s.maxbits = bits;
            if (!isfinite(x)) s.has_nonfinite = 1;
            if (i == j && x > 0) pos++;
            if (x == 0) continue;
            s.nnz++;
            if (i != j) s.diagonal = 0;
            if (j > i) s.lower = 0, s.ku = j - i > s.ku ? j - i : s.ku;
            if (i > j) s.upper = 0, s.kl = i - j > s.kl ? i - j : s.kl;
        }
    s.pos_diag = m == n && n > 0 && pos == n;
    return s;
}

static void check_props(const char *what, const silc_value *v, const shape *t)
{
    const silc_props *p = &v->props;
    CHECK((v->props_have & SILC_PROPS_SHAPE) && p->nnz == t->nnz && p->diagonal == t->diagonal &&
              p->lower == t->lower && p->upper == t->upper && p->kl == t->kl && p->ku == t->ku &&
              p->pos_diag == t->pos_diag && p->has_nonfinite == t->has_nonfinite,
          "%s: shape (parts %d) nnz %lld/%lld diag %d/%d lower %d/%d upper %d/%d kl %lld/%lld ku %lld/%lld "
          "posdiag %d/%d nonfinite %d/%d",
          what, v->props_have, (long long)p->nnz, (long long)t->nnz, p->diagonal, t->diagonal, p->lower,
          t->lower, p->upper, t->upper, (long long)p->kl, (long long)t->kl, (long long)p->ku, (long long)t->ku,
          p->pos_diag, t->pos_diag, p->has_nonfinite, t->has_nonfinite);
}

static silc_value *dense_of(const double *a, int64_t m, int64_t n)
{
    silc_value *v = val_dense_new(m, n);
    CHECK(v != NULL, "val_dense_new(%lld, %lld)", (long long)m, (long long)n);
    if (v && m * n > 0) memcpy(v->val, a, (size_t)(m * n) * sizeof *a);
    return v;
}

/* val_shape_into against brute force, and the copy against the entries. */
static void check_store(const char *what, const double *a, int64_t m, int64_t n, const shape *t)
{
    silc_value *v = dense_of(a, m, n);
    double *copy = malloc((size_t)(m * n > 0 ? m * n : 1) * sizeof *copy);
    if (!v || !copy) goto out;
    CHECK(val_shape_into(v, copy) == 0, "%s: val_shape_into refused a fresh dense value", what);
    check_props(what, v, t);
    CHECK(m * n == 0 || memcmp(copy, a, (size_t)(m * n) * sizeof *a) == 0, "%s: the copy differs", what);
    {
        double want;
        memcpy(&want, &t->maxbits, sizeof want);
        /* a NaN anywhere makes the max NaN; else it is the largest |a_ij|, Inf included */
        CHECK(val_has_nonfinite(v) == t->has_nonfinite &&
                  (isnan(want) ? isnan(val_max_abs(v)) : val_max_abs(v) == want),
              "%s: scan max %.17g nonfinite %d, truth %.17g %d", what, val_max_abs(v), val_has_nonfinite(v), want,
              t->has_nonfinite);
    }
    CHECK(val_shape_into(v, copy) == -1, "%s: val_shape_into ran again on a known shape", what);
out:
    val_release(v);
    free(copy);
}

static const char *const bare = "set accuracy.condest = off; set solve.backward_error = on_request";
static const char *const full = "set accuracy.condest = auto; set solve.backward_error = deferred";

/* Runs `x = A \ b` with A a new value of a under mode; returns the
 * statement's status, with `info x`'s backend and method lines in info
 * (or the error), and x's entries in x (n of them) on success. */
static void out_to(void *user, const char *text)
{
    sb_printf(user, "%s", text);
}

static int solve_with(const char *mode, const double *a, int64_t m, int64_t n, const double *b, double *x,
                      char *info, size_t infolen, silc_value **Aout)
{
    silc_value *A = dense_of(a, m, n), *B = dense_of(b, m, 1);
    const silc_value *X;
    strbuf out;
    int rc;
    info[0] = '\0';
    if (!A || !B || api_bind(E, "A", A, err, sizeof err) || api_bind(E, "b", B, err, sizeof err) ||
        api_exec(E, mode, err, sizeof err)) {
        CHECK(0, "setting up: %s", err);
        val_release(A), val_release(B);
        return -1;
    }
    val_release(A);
    val_release(B);
    /* borrowed: the store holds it (a 1x1 one as the store's own scalar)
     * until "A" is bound again */
    *Aout = (silc_value *)api_lookup(E, "A", err, sizeof err);
    watched = *Aout;
    watched_bytes = (size_t)(m * n) * sizeof(double);
    square_arrays = early_square_arrays = 0;
    rc = api_exec(E, "x = A \\ b", err, sizeof err);
    watched = NULL;
    if (rc) {
        snprintf(info, infolen, "error: %s", err);
        return rc;
    }
    X = api_lookup(E, "x", err, sizeof err);
    if (X && X->format == SILC_FMT_DENSE) memcpy(x, X->val, (size_t)n * sizeof *x);
    sb_init(&out);
    E->output = out_to;
    E->output_user = &out;
    if (api_exec(E, "info x", err, sizeof err) == 0) {
        const char *s = strstr(sb_str(&out), "  solve: "), *be = strstr(sb_str(&out), "  backend: ");
        snprintf(info, infolen, "%.*s | %.*s", s ? (int)strcspn(s, "\n") : 0, s ? s : "",
                 be ? (int)strcspn(be, "\n") : 0, be ? be : "");
    }
    E->output = NULL;
    E->output_user = NULL;
    sb_free(&out);
    return 0;
}

/* The bare solve (with the copy where the corners allow it) against the
 * default one (norms' pass, no copy), and the bare A's shape afterwards. */
static void check_solve(const char *what, const double *a, int64_t m, int64_t n, const shape *t)
{
    double *b = malloc((size_t)m * sizeof *b), *x1 = calloc((size_t)n + 1, sizeof *x1),
           *x2 = calloc((size_t)n + 1, sizeof *x2);
    char i1[1200], i2[1200];
    silc_value *A1 = NULL, *A2 = NULL;
    int rc1, rc2, expect_copy, scaled;
    double mx;
    if (!b || !x1 || !x2) goto out;
    for (int64_t i = 0; i < m; i++) b[i] = 1 + (double)(i % 5);
    rc1 = solve_with(bare, a, m, n, b, x1, i1, sizeof i1, &A1);
    expect_copy = m == n && n >= 2 && a[n - 1] != 0 && a[(n - 1) * m] != 0;
    memcpy(&mx, &t->maxbits, sizeof mx);
    scaled = mx > 0x1p60 || (mx > 0 && mx < 0x1p-60); /* scale.c's 2^+-64 */
    /* (a 1-column A's size is b's and x's) */
    CHECK(n < 2 || early_square_arrays == expect_copy, "%s: %d array(s) of A's size before its shape was known, "
          "a copy was %sexpected", what, early_square_arrays, expect_copy ? "" : "not ");
    /* lapack's factorization took it: no array of its own */
    CHECK(!expect_copy || rc1 || scaled || square_arrays == 1,
          "%s: %d arrays of A's size in a solve that had the copy (%s)", what, square_arrays, i1);
    if (A1 && A1->props_have & SILC_PROPS_SHAPE) check_props(what, A1, t);
    rc2 = solve_with(full, a, m, n, b, x2, i2, sizeof i2, &A2);
    CHECK(rc1 == rc2 && !strcmp(i1, i2), "%s: bare solve '%s', default '%s'", what, i1, i2);
    CHECK(rc1 || memcmp(x1, x2, (size_t)n * sizeof *x1) == 0, "%s: x differs between the bare and default solves",
          what);
    CHECK(!expect_copy || !rc1 || t->has_nonfinite, "%s: a general matrix failed: %s", what, i1);
out:
    free(b), free(x1), free(x2);
}

static void check_dense(const char *what, const double *a, int64_t m, int64_t n)
{
    shape t = brute(a, m, n);
    check_store(what, a, m, n, &t);
    check_solve(what, a, m, n, &t);
}

/* An n x n matrix: entry (i, j) from f. */
static double *make(int64_t n, double (*f)(int64_t i, int64_t j, int64_t n))
{
    double *a = malloc((size_t)(n * n) * sizeof *a);
    CHECK(a != NULL, "out of memory");
    for (int64_t j = 0; a && j < n; j++)
        for (int64_t i = 0; i < n; i++) a[i + j * n] = f(i, j, n);
    return a;
}

/* General: a dominant diagonal, every entry nonzero, not symmetric. */
static double general(int64_t i, int64_t j, int64_t n)
{
    return i == j ? (double)n + 2 : 1.0 / (double)(1 + i + 2 * j);
}
static double symmetric_pos(int64_t i, int64_t j, int64_t n)
{
    return i == j ? (double)n + 2 : 1.0 / (double)(1 + i + j);
}
static double symmetric_indef(int64_t i, int64_t j, int64_t n)
{
    return i == j ? (i % 2 ? -1.0 : 1.0) * ((double)n + 2) : 1.0 / (double)(1 + i + j);
}
static double lower(int64_t i, int64_t j, int64_t n)
{
    return i >= j ? general(i, j, n) : 0;
}
static double band(int64_t i, int64_t j, int64_t n)
{
    return i - j <= 1 && j - i <= 2 ? general(i, j, n) : 0;
}

static void edge_cases(void)
{
    enum { N = 8 };
    double *a;
    if ((a = make(N, general))) {
        check_dense("general", a, N, N);
        a[N - 1] = 0; /* A(n,1) = 0: no copy, the full pass decides */
        check_dense("general, A(n,1) = 0", a, N, N);
        a[N - 1] = 1, a[(N - 1) * N] = 0;
        check_dense("general, A(1,n) = 0", a, N, N);
        a[(N - 1) * N] = NAN;
        check_dense("general, NaN in the corner A(1,n)", a, N, N);
        a[(N - 1) * N] = 1, a[3 + 4 * N] = INFINITY;
        check_dense("general, Inf in the middle", a, N, N);
        a[3 + 4 * N] = -1e300, a[4 + 3 * N] = 1e-300;
        check_dense("general, entries near 1e+-300 (scaled solve)", a, N, N);
        for (int64_t k = 0; k < N * N; k++) a[k] = 0;
        check_dense("all zero", a, N, N);
        free(a);
    }
    if ((a = make(N, symmetric_pos))) {
        check_dense("symmetric, positive diagonal", a, N, N);
        free(a);
    }
    if ((a = make(N, symmetric_indef))) {
        check_dense("symmetric indefinite", a, N, N);
        free(a);
    }
    if ((a = make(N, lower))) {
        check_dense("lower triangular", a, N, N);
        a[3 + 5 * N] = 0.25; /* one entry above the diagonal, in the middle */
        check_dense("lower triangular but one entry", a, N, N);
        free(a);
    }
    if ((a = make(N, band))) {
        check_dense("banded (kl 1, ku 2)", a, N, N);
        free(a);
    }
    {
        double one = 3, rect[6] = {1, 2, 3, 4, 5, 6};
        check_dense("1x1", &one, 1, 1);
        check_dense("rectangular 3x2", rect, 3, 2);
    }
}

/* The shape pass's kernel (value.c's max_abs_bits) reads a column eight
 * entries a step in register pairs, then one by one: in 13-row columns one
 * special entry is put at every row (every lane of the step, and the tail)
 * of a middle column and of the last one, alone or with a second one three
 * rows on, and the shape and the scan are compared with brute force. */
static void kernel_lanes(void)
{
    enum { N = 13 };
    const uint64_t nan_payload_bits = 0xfff0000000000123ULL; /* negative, quiet bit clear */
    double nan_payload, *a = make(N, general);
    memcpy(&nan_payload, &nan_payload_bits, sizeof nan_payload);
    const struct {
        const char *what;
        double first, second; /* second 0: none */
    } cases[] = {
        {"largest magnitude, negative", -1e6, 0},
        {"-0.0", -0.0, 0},
        {"NaN with a payload and the sign", nan_payload, 0},
        {"Inf", -INFINITY, 0},
        {"Inf, then NaN", INFINITY, NAN},
        {"NaN, then Inf", NAN, -INFINITY},
        {"largest magnitude, then Inf", 1e300, INFINITY},
    };
    if (!a) return;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++)
        for (int64_t j = 6; j < N; j += N - 1 - 6)
            for (int64_t i = 0; i < N; i++) {
                char what[160];
                double *col = a + j * N, keep = col[i], keep2 = col[(i + 3) % N];
                col[i] = cases[c].first;
                if (cases[c].second != 0) col[(i + 3) % N] = cases[c].second;
                snprintf(what, sizeof what, "%s at (%lld, %lld)", cases[c].what, (long long)i + 1,
                         (long long)j + 1);
                shape t = brute(a, N, N);
                check_store(what, a, N, N, &t);
                col[i] = keep, col[(i + 3) % N] = keep2;
            }
    /* a column of zeros but one subnormal, in every row: a nonzero, and the max when alone */
    for (int64_t k = 0; k < N * N; k++) a[k] = 0;
    for (int64_t i = 0; i < N; i++) {
        char what[160];
        a[i + 6 * N] = -0x1p-1074;
        snprintf(what, sizeof what, "the only nonzero, subnormal, at (%lld, 7)", (long long)i + 1);
        shape t = brute(a, N, N);
        check_store(what, a, N, N, &t);
        a[i + 6 * N] = 0;
    }
    free(a);
}

/* A NaN deep inside a general 300 x 300 A: the message names A and the
 * entry, whether or not the copy's pass found it, and comes before b's. */
static void nan_inside(void)
{
    enum { N = 300 };
    double *a = make(N, general), *b = malloc(N * sizeof *b);
    char i1[1200], i2[1200];
    silc_value *A;
    if (!a || !b) goto out;
    for (int k = 0; k < N; k++) b[k] = 1;
    a[199 + 149 * N] = NAN;
    solve_with(bare, a, N, N, b, b, i1, sizeof i1, &A);
    CHECK(strstr(i1, "'A' has NaN at (200, 150): a solve needs finite entries") != NULL, "NaN inside, bare: %s",
          i1);
    solve_with(full, a, N, N, b, b, i2, sizeof i2, &A);
    CHECK(!strcmp(i1, i2), "NaN inside: bare '%s', default '%s'", i1, i2);
    b[7] = NAN;
    solve_with(bare, a, N, N, b, b, i1, sizeof i1, &A);
    CHECK(strstr(i1, "'A' has NaN at (200, 150)") != NULL, "NaN inside A and in b, bare: %s", i1);
    a[199 + 149 * N] = 1;
    solve_with(bare, a, N, N, b, b, i1, sizeof i1, &A);
    CHECK(strstr(i1, "'b' has NaN at (8, 1)") != NULL, "NaN in b only, bare: %s", i1);
out:
    free(a), free(b);
}

int main(void)
{
    if (eng_create(&E, "/dev/null", err, sizeof err)) {
        CHECK(0, "eng_create: %s", err);
        return check_done();
    }
    val_set_array_pool(count_take, give_none);
    edge_cases();
    kernel_lanes();
    nan_inside();
    val_set_array_pool(NULL, NULL);
    eng_destroy(&E);
    return check_done();
}
