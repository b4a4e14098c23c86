/*
 * test_fastpath.c -- what cuts a statement's fixed cost (issue 30) never
 * serves something stale.  A repeated EXEC text reuses its parse (eval.c),
 * its backend list (dispatch.c: kept per class chain until a setting
 * changes) and maybe a memo entry (memo.c: keyed by operand ids); each
 * must follow what the names hold and what the settings say now:
 *
 *   - the same text `y = A * x` with A rebound to CSR, then dense, then a
 *     scalar, and x rebound to new entries of the same shape, gives each
 *     time the product of what the names hold (worked out by hand);
 *   - the same text `x = D \ b` after `set dispatch.solve.dense.spd`, after
 *     a per-call `backend = ...` and after setting it back runs the
 *     backend the settings name at that moment (`info` says which), and
 *     solves exactly (x = [1; 2; 3]);
 *   - `info` keeps a statement's wall time, also for the second statement
 *     of a text (the first starts at the EXEC's own clock read).
 *
 * Skips the settings part (with a message) when plugin-lapack is not built.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "testlib.h"

/* y, fetched, against the 3-vector want (exact: small integers). */
static void check_y(silc_context *c, const char *what, const double want[3])
{
    double *y = tl_get_dense_checked(c, "y", 3, 1);
    if (!y) return;
    CHECK(y[0] == want[0] && y[1] == want[1] && y[2] == want[2], "%s: y = [%g; %g; %g], want [%g; %g; %g]", what,
          y[0], y[1], y[2], want[0], want[1], want[2]);
    free(y);
}

static void run(silc_context *c, const char *text)
{
    CHECK(silc_exec(c, text) == 0, "%s: %s", text, silc_context_errmsg(c));
}

static void test_rebound_names(silc_context *c)
{
    /* S = [4 1 0; 1 4 1; 0 1 4] as CSR; M = [1 2 3; 4 5 6; 7 8 10] dense */
    static const int64_t rp[4] = {0, 2, 5, 7}, ci[7] = {0, 1, 0, 1, 2, 1, 2};
    static const double sv[7] = {4, 1, 1, 4, 1, 1, 4}, m[9] = {1, 4, 7, 2, 5, 8, 3, 6, 10};
    static const double x1[3] = {1, 2, 3}, x2[3] = {-1, 0, 2};
    static const double s_x1[3] = {6, 12, 14}, m_x1[3] = {14, 32, 53}, m_x2[3] = {5, 8, 13}, two_x2[3] = {-2, 0, 4};
    silc_envelope_t S = {0};
    CHECK(silc_envelope_csr(&S, 3, 3, rp, ci, sv) == 0, "CSR envelope");
    tl_put_checked(c, "A", &S);
    silc_envelope_free(&S);
    CHECK(tl_put_vector(c, "x", 3, x1) == 0, "PUT x: %s", silc_context_errmsg(c));
    run(c, "y = A * x");
    check_y(c, "CSR A", s_x1);
    run(c, "y = A * x"); /* the same operands again: the memo may hand out its value */
    check_y(c, "CSR A again", s_x1);
    tl_put_dense_checked(c, "A", 3, 3, m);
    run(c, "y = A * x");
    check_y(c, "A rebound to a dense matrix", m_x1);
    CHECK(tl_put_vector(c, "x", 3, x2) == 0, "PUT x: %s", silc_context_errmsg(c));
    run(c, "y = A * x");
    check_y(c, "x rebound to other entries", m_x2);
    run(c, "A = 2");
    run(c, "y = A * x");
    check_y(c, "A rebound to a scalar", two_x2);
    run(c, "A = x'; y = [A * x; 0; 0]"); /* A a row: a 1x1 product, then stacked */
    {
        static const double dot[3] = {5, 0, 0};
        check_y(c, "A rebound to a row", dot);
    }
}

/* x = D \ b ran on the backend named by want ("lapack", "reference"). */
static void check_solved_by(silc_context *c, const char *text, const char *want)
{
    static const double exact[3] = {1, 2, 3};
    char label[64];
    const char *in;
    double *x;
    run(c, text);
    in = tl_out_info(c, "x");
    snprintf(label, sizeof label, "backend: %s", want);
    CHECK(strstr(in, label) != NULL, "%s: want %s:\n%s", text, label, in);
    if ((x = tl_get_dense_checked(c, "x", 3, 1))) {
        CHECK(tl_diff_inf(x, exact, 3) <= 1e-14, "%s: x off by %g", text, tl_diff_inf(x, exact, 3));
        free(x);
    }
}

static void test_settings_between_statements(silc_context *c)
{
    static const double d[9] = {4, 1, 0, 1, 4, 1, 0, 1, 4}, b[3] = {6, 12, 14};
    if (silc_exec(c, "x0 = solve(1, 1, \"backend = lapack\")") != 0 &&
        tl_contains(silc_context_errmsg(c), "not installed")) {
        printf("  skipped: plugin-lapack is not built (%s)\n", silc_context_errmsg(c));
        return;
    }
    tl_put_dense_checked(c, "D", 3, 3, d);
    CHECK(tl_put_vector(c, "b", 3, b) == 0, "PUT b: %s", silc_context_errmsg(c));
    check_solved_by(c, "x = D \\ b", "lapack"); /* solve.dense.spd's built-in list starts with it */
    run(c, "set dispatch.solve.dense.spd = reference");
    check_solved_by(c, "x = D \\ b", "reference");
    check_solved_by(c, "x = solve(D, b, \"backend = lapack\")", "lapack");
    check_solved_by(c, "x = D \\ b", "reference"); /* the per-call option is gone */
    run(c, "set dispatch.solve.dense.spd = lapack");
    check_solved_by(c, "x = D \\ b", "lapack");
}

static void test_wall_time(silc_context *c)
{
    double t;
    run(c, "p = 1; q = [1; 2] + [3; 4]");
    t = tl_out_number(tl_out_info(c, "q"), "wall time: ");
    CHECK(t >= 0 && t < 60, "the second statement's wall time: %g s:\n%s", t, tl_out());
    run(c, "q = [1; 2] - [3; 4]");
    t = tl_out_number(tl_out_info(c, "q"), "wall time: ");
    CHECK(t >= 0 && t < 60, "a first statement's wall time: %g s:\n%s", t, tl_out());
}

int main(void)
{
    silc_context *c = NULL;
    if (silc_open(&c, NULL)) {
        fprintf(stderr, "silc_open: %s\n", c ? silc_context_errmsg(c) : silc_errmsg());
        return 1;
    }
    silc_set_output(c, tl_out_fn, NULL);
    test_rebound_names(c);
    test_settings_between_statements(c);
    test_wall_time(c);
    silc_close(&c);
    return check_done();
}
