/*
 * test_condest_auto.c -- no warning is lost, and none changes, when the
 * condition estimate is deferred (accuracy.condest = auto, the default;
 * docs/accuracy.md "When the estimate is made").
 *
 * Over every square shared matrix (../shared/matrices/index.tsv, the
 * singular and near-singular ones and the complex ones included) and every
 * backend that defers its estimate and takes the matrix (reference up to
 * AU_REF_MAX unknowns, for the test's time; UMFPACK, KLU, MUMPS; CHOLMOD
 * on the spd and hpd classes), the
 * same system b = A * ones is solved twice, each time with a fresh copy of
 * A (nothing reused):
 *
 *   auto: the warnings of the solve statement, then those of `info x`
 *         (which makes an owed estimate), and the report `info` prints;
 *   now:  the warnings of the solve statement, and its report.
 *
 * The estimator and the factorization are the same, so the reports agree
 * to rounding, and:
 *   (1) the condition warnings ("... condition estimate ...") of auto, at
 *       solve time and with `info` together, are now's, text for text,
 *       but for those given early: an urgent estimate whose warning a
 *       rigorous lower bound already settles is made when the report is
 *       read, and its warning at solve time says "cond_1 >= L so far"
 *       (docs/accuracy.md); `info` then gives now's text;
 *   (2) every condition warning now gives at solve time auto gives at
 *       solve time too, the same kind of warning where it came early (one
 *       that comes only with `info` is a lost warning: a program that
 *       never reads its reports would not hear it), and an early one's
 *       bound is at most the estimate;
 *   (3) the estimate and the forward-error bound `info` prints are equal
 *       within AU_REL (both from the same estimate and the same residual);
 *   (4) a solve that fails under one mode fails under the other.
 * The same runs over complex Hilbert matrices H (1 + 1i) of order 9-11
 * (cond_1 1.1e12 to 1.2e15): A^-1 e cancels on them, so the lower bound
 * from e/n alone is 4e5 to 1e7 times below cond_1 and their warnings came
 * only with `info` under UMFPACK and KLU (the loss (2) catches), until the
 * complex start block took the alternating vector too, as the real one
 * does (plugin-suitesparse/ss_complex.c).
 * The table printed (matrix, backend, where auto made its estimate, the
 * warnings) is the evidence docs/accuracy.md cites for the rule that
 * decides when an owed estimate is made at once.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "testlib.h"

#define AU_REF_MAX 2100     /* the reference's dense/band/sparse LU beyond this takes seconds */
#define AU_REL 1e-10        /* estimates and bounds: equal but for rounding */
#define AU_WARN 2048

typedef struct deferring {
    const char *name;
    int spd_only;           /* Cholesky: the spd class only */
    int64_t max_n;          /* largest n it runs here */
} deferring;

static const deferring backends[] = {
    {"reference", 0, AU_REF_MAX},      {"suitesparse.umfpack", 0, INT64_MAX}, {"suitesparse.klu", 0, INT64_MAX},
    {"suitesparse.cholmod", 1, INT64_MAX}, {"mumps", 0, INT64_MAX},
};
#define NBACKENDS (sizeof backends / sizeof backends[0])

static int installed(silc_context *c, const char *name)
{
    char stmt[160];
    snprintf(stmt, sizeof stmt, "x0 = solve(1, 1, \"backend = %s\")", name);
    return silc_exec(c, stmt) == 0 || !tl_contains(silc_context_errmsg(c), "not installed");
}

/* The condition warnings of the last statement, one a line, appended to out. */
static void condition_warnings(silc_context *c, char *out, size_t len)
{
    const char *w = silc_context_warnings(c), *end;
    char line[AU_WARN];
    for (; w && *w; w = *end ? end + 1 : end) {
        size_t have = strlen(out);
        end = strchr(w, '\n');
        if (!end) end = w + strlen(w);
        snprintf(line, sizeof line, "%.*s\n", (int)(end - w), w);
        if (tl_contains(line, "condition estimate") && have + strlen(line) < len) strcat(out, line);
    }
}

/* What one mode gave: the solve's status, its condition warnings at solve
 * time and with `info`, the estimate and bound `info` printed (-1: none),
 * and whether `info` made the estimate. */
typedef struct outcome {
    int failed;
    char at_solve[AU_WARN], at_info[AU_WARN];
    double estimate, bound;
    int read;
} outcome;

/* Solves b with a fresh copy of A (put under a new name) under mode; when
 * reused, with the factorization of a solve under accuracy.condest = off
 * before it (no estimate made, none owed): the estimate's cost is then
 * weighed against no factorization, and only the lower bound can make it
 * at once. */
static void solve_under(silc_context *c, const silc_envelope_t *A, const char *backend, const char *mode,
                        int reused, outcome *o)
{
    static int serial;
    char name[16], stmt[256];
    const char *in;
    memset(o, 0, sizeof *o);
    snprintf(name, sizeof name, "A%d", ++serial);
    tl_put_checked(c, name, A);
    snprintf(stmt, sizeof stmt, "b = %s * ones(rows(%s), 1)", name, name);
    CHECK(silc_exec(c, stmt) == 0, "%s: %s", stmt, silc_context_errmsg(c));
    snprintf(stmt, sizeof stmt, "set accuracy.condest = off; x = solve(%s, b, \"backend = %s\")", name, backend);
    if (reused && silc_exec(c, stmt)) {
        o->failed = 1;
        snprintf(stmt, sizeof stmt, "clear %s", name);
        silc_exec(c, stmt);
        return;
    }
    snprintf(stmt, sizeof stmt, "set accuracy.condest = %s; x = solve(%s, b, \"backend = %s\")", mode, name,
             backend);
    if (silc_exec(c, stmt)) {
        o->failed = 1;
        snprintf(stmt, sizeof stmt, "clear %s", name);
        silc_exec(c, stmt);
        return;
    }
    condition_warnings(c, o->at_solve, sizeof o->at_solve);
    in = tl_out_info(c, "x");
    condition_warnings(c, o->at_info, sizeof o->at_info);
    o->read = tl_contains(in, "computed when the report was first read");
    o->estimate = tl_contains(in, "condition estimate: not estimated") ? -1 : tl_out_number(in, "condition estimate: ");
    o->bound = tl_out_number(in, "forward error bound (estimate: est ||A^-1||_1 ||b - A x||_1 / ||x||_1): ");
    snprintf(stmt, sizeof stmt, "clear %s x", name); /* the factorizations go with A */
    CHECK(silc_exec(c, stmt) == 0, "%s: %s", stmt, silc_context_errmsg(c));
}

static int close_to(double a, double b)
{
    return a == b || fabs(a - b) <= AU_REL * fmax(fabs(a), fabs(b));
}

/* A warning given before its estimate was made, on a lower bound. */
#define AU_EARLY " so far, a rigorous lower bound"

/* Every line of sub is a line of whole, or an early warning of whole of
 * the same kind (the text before " (") whose bound is at most estimate. */
static int lines_within(const char *sub, const char *whole, double estimate)
{
    char line[AU_WARN], kind[AU_WARN];
    for (const char *p = sub, *end; *p; p = end + 1) {
        const char *at, *paren;
        end = strchr(p, '\n');
        if (!end) return 1;
        snprintf(line, sizeof line, "%.*s", (int)(end - p + 1), p);
        if (strstr(whole, line)) continue;
        if (!(paren = strstr(line, " ("))) return 0;
        snprintf(kind, sizeof kind, "%.*s (cond_1 >= ", (int)(paren - line), line);
        if (!(at = strstr(whole, kind)) || strtod(at + strlen(kind), NULL) > estimate * (1 + 1e-12)) return 0;
    }
    return 1;
}

/* Moves the early warnings of w (lines with AU_EARLY) to early. */
static void split_early(char *w, char *early, size_t len)
{
    char *p = w, *end, *keep = w;
    early[0] = 0;
    for (; *p; p = end + 1) {
        size_t n;
        if (!(end = strchr(p, '\n'))) break;
        n = (size_t)(end - p + 1);
        if (strstr(p, AU_EARLY) && strstr(p, AU_EARLY) < end) {
            if (strlen(early) + n < len) strncat(early, p, n);
        } else {
            memmove(keep, p, n);
            keep += n;
        }
    }
    *keep = 0;
}

/* Both modes on A (named label; spd: Hermitian positive definite, for
 * CHOLMOD) with every backend that takes it; reused: solve_under's. */
static void run_matrix(silc_context *c, const char *label, int spd, const silc_envelope_t *A, int reused,
                       const int *have)
{
    for (size_t k = 0; k < NBACKENDS; k++) {
        const deferring *be = &backends[k];
        outcome au, now;
        char both[2 * AU_WARN], early[AU_WARN], late[AU_WARN];
        if (!have[k] || (be->spd_only && !spd) || A->n > be->max_n) continue;
        solve_under(c, A, be->name, "auto", reused, &au);
        solve_under(c, A, be->name, "now", reused, &now);
        CHECK(au.failed == now.failed, "%s, %s: the solve %s under auto, %s under now", label, be->name,
              au.failed ? "failed" : "succeeded", now.failed ? "failed" : "succeeded");
        if (au.failed || now.failed) {
            printf("  %-18s %-20s failed under both modes\n", label, be->name);
            continue;
        }
        snprintf(late, sizeof late, "%s", au.at_solve);
        split_early(late, early, sizeof early);
        snprintf(both, sizeof both, "%s%s", late, au.at_info);
        /* (1) */
        CHECK(!strcmp(both, now.at_solve), "%s, %s: condition warnings under auto (solve, then info, early "
              "ones aside):\n%sunder now:\n%s", label, be->name, both, now.at_solve);
        CHECK(!early[0] || au.read, "%s, %s: an early warning, but the estimate was made at solve time:\n%s",
              label, be->name, early);
        /* (2) */
        CHECK(lines_within(now.at_solve, au.at_solve, au.estimate), "%s, %s: a warning lost at solve time "
              "under auto:\nnow:\n%sauto at solve time:\n%s", label, be->name, now.at_solve, au.at_solve);
        /* (3) */
        CHECK(au.estimate > 0 && close_to(au.estimate, now.estimate),
              "%s, %s: estimate under auto %.17g, under now %.17g", label, be->name, au.estimate,
              now.estimate);
        CHECK(close_to(au.bound, now.bound), "%s, %s: forward error bound under auto %.17g, under now %.17g",
              label, be->name, au.bound, now.bound);
        printf("  %-18s %-20s estimate %-9.3g made %-5s %s%s", label, be->name, au.estimate,
               early[0] ? "read, warned early" : au.read ? "read" : "solve", early[0] ? "\n" : "",
               now.at_solve[0] ? now.at_solve : "(no condition warning)\n");
    }
}

static void run_shared(silc_context *c, const tl_index_row *row, const int *have)
{
    silc_envelope_t A;
    if (tl_read_shared(row->file, &A)) return;
    run_matrix(c, row->file, !strcmp(row->cls, "spd") || !strcmp(row->cls, "hpd"), &A, 0, have);
    silc_envelope_free(&A);
}

/* The Hilbert matrix of order n times 1 + 1i, as complex CSR (every entry
 * stored: the sparse backends take CSR only).  Complex symmetric, not
 * Hermitian: CHOLMOD is not asked.  Fresh, where whether the estimate is
 * made at once also depends on its timed cost, and with a reused
 * factorization, where only the lower bound can make it so. */
static void run_complex_hilbert(silc_context *c, int n, const int *have)
{
    int64_t *rp = malloc((size_t)(n + 1) * sizeof *rp), *ci = malloc((size_t)(n * n) * sizeof *ci);
    double *v = malloc((size_t)(2 * n * n) * sizeof *v);
    silc_envelope_t A;
    char label[40];
    int ok = rp && ci && v;
    memset(&A, 0, sizeof A);
    for (int i = 0; ok && i < n; i++) {
        rp[i + 1] = (int64_t)(i + 1) * n;
        for (int j = 0; j < n; j++) {
            ci[i * n + j] = j;
            v[2 * (i * n + j)] = v[2 * (i * n + j) + 1] = 1.0 / (double)(i + j + 1);
        }
    }
    if (ok) rp[0] = 0;
    ok = ok && silc_envelope_csr_complex(&A, n, n, rp, ci, v) == 0;
    CHECK(ok, "building the complex Hilbert matrix of order %d", n);
    snprintf(label, sizeof label, "hilbert%d*(1+1i)", n);
    if (ok) run_matrix(c, label, 0, &A, 0, have);
    snprintf(label, sizeof label, "hilbert%d*(1+1i) reused", n);
    if (ok) run_matrix(c, label, 0, &A, 1, have);
    silc_envelope_free(&A);
    free(rp), free(ci), free(v);
}

int main(void)
{
    silc_context *c = tl_open_printing();
    char path[1024];
    tl_index_row row;
    int have[NBACKENDS];
    FILE *f;
    if (!c) return check_done();
    for (size_t k = 0; k < NBACKENDS; k++) {
        have[k] = installed(c, backends[k].name);
        if (!have[k]) printf("test_condest_auto: %s is not installed: skipped\n", backends[k].name);
    }
    if (!(f = tl_index_open(NULL, path, sizeof path))) {
        silc_close(&c);
        return check_done();
    }
    while (tl_index_next(f, &row))
        if (row.rows == row.cols && strcmp(row.field, "pattern"))
            run_shared(c, &row, have);
    fclose(f);
    for (int n = 9; n <= 11; n++) run_complex_hilbert(c, n, have);
    silc_close(&c);
    return check_done();
}
