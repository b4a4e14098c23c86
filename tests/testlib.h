/*
 * testlib.h -- helpers shared by the test programs, beside check.h.
 *
 * Building the 2-D Laplacian as CSR, loading a Matrix Market file and putting
 * it under a name, fetching a result as a plain array, capturing the text of
 * `info`/`explain` (silc_set_output) in a buffer and reading numbers back out
 * of it, and norm helpers.  Header-only with static inline functions, so each
 * test stays one self-contained program and unused helpers cost nothing.
 * Every helper returns 0 on success and non-zero on failure, with the reason
 * in the caller's err buffer where there is one.
 */
#ifndef SILC_TESTLIB_H
#define SILC_TESTLIB_H

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "silc.h"

#ifndef SILC_SHARED_MATRICES
#define SILC_SHARED_MATRICES "../shared/matrices"
#endif

/* ---- matrices ---------------------------------------------------------------- */

/* The 5-point operator on a k x k grid (n = k*k, Dirichlet boundary), as CSR:
 * diag on the diagonal, -1 to the north and south neighbours, -1 - beta west
 * and -1 + beta east (beta = 0, diag = 4: the Laplacian; beta > 0: an
 * upwinded convection; diag < 4: shifted towards indefinite). */
static inline int tl_grid2d(silc_envelope_t *e, int64_t k, double beta, double diag)
{
    int64_t n = k * k, nz = 0, i, j;
    int64_t *rp = malloc((size_t)(n + 1) * sizeof *rp);
    int64_t *ci = malloc((size_t)(5 * n) * sizeof *ci);
    double *v = malloc((size_t)(5 * n) * sizeof *v);
    int rc = -1;
    if (rp && ci && v) {
        rp[0] = 0;
        for (j = 0; j < k; j++)
            for (i = 0; i < k; i++) {
                int64_t r = j * k + i;
                if (j > 0) ci[nz] = r - k, v[nz++] = -1;
                if (i > 0) ci[nz] = r - 1, v[nz++] = -1 - beta;
                ci[nz] = r, v[nz++] = diag;
                if (i < k - 1) ci[nz] = r + 1, v[nz++] = -1 + beta;
                if (j < k - 1) ci[nz] = r + k, v[nz++] = -1;
                rp[r + 1] = nz;
            }
        rc = silc_envelope_csr(e, n, n, rp, ci, v);
    }
    free(rp);
    free(ci);
    free(v);
    return rc;
}

/* The 5-point Laplacian on a k x k grid: SPD, condition number ~ 0.4 k^2. */
static inline int tl_laplacian2d(silc_envelope_t *e, int64_t k)
{
    return tl_grid2d(e, k, 0, 4);
}

/* An exactly singular SPD-looking matrix: the 5-point Laplacian on a k x k
 * grid whose last two unknowns are cut off into the block [1 1; 1 1].
 * Symmetric with a positive diagonal, so Cholesky is tried first and meets
 * the zero pivot, then LU meets it too. */
static inline int tl_singular_block_laplacian(silc_envelope_t *e, int64_t k)
{
    int64_t n = k * k, nz = 0, r, q;
    int64_t *rp = malloc((size_t)(n + 1) * sizeof *rp), *ci = malloc((size_t)(5 * n) * sizeof *ci);
    double *v = malloc((size_t)(5 * n) * sizeof *v);
    int rc = -1;
    if (rp && ci && v) {
        for (r = 0; r < n; r++) {
            int64_t i = r / k, j = r % k, cols[5], m = 0;
            rp[r] = nz;
            if (r >= n - 2) {
                ci[nz] = n - 2, v[nz++] = 1;
                ci[nz] = n - 1, v[nz++] = 1;
                continue;
            }
            if (i > 0) cols[m++] = r - k;
            if (j > 0) cols[m++] = r - 1;
            cols[m++] = r;
            if (j < k - 1) cols[m++] = r + 1;
            if (i < k - 1) cols[m++] = r + k;
            for (q = 0; q < m; q++)
                if (cols[q] < n - 2) ci[nz] = cols[q], v[nz++] = cols[q] == r ? 4 : -1;
        }
        rp[n] = nz;
        rc = silc_envelope_csr(e, n, n, rp, ci, v);
    }
    free(rp);
    free(ci);
    free(v);
    return rc;
}

/* y = A x for A in CSR. */
static inline void tl_csr_matvec(const silc_envelope_t *A, const double *x, double *y)
{
    int64_t i, p;
    for (i = 0; i < A->m; i++) {
        double s = 0;
        for (p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) s += A->values[p] * x[A->colind[p]];
        y[i] = s;
    }
}

/* Normwise backward error ||b - A x||_inf / (||A||_inf ||x||_inf + ||b||_inf),
 * A in CSR. */
static inline double tl_backward_error(const silc_envelope_t *A, const double *x, const double *b)
{
    double r = 0, an = 0, xn = 0, bn = 0;
    int64_t i, j, p;
    for (i = 0; i < A->m; i++) {
        double s = b[i], rs = 0;
        for (p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) {
            s -= A->values[p] * x[A->colind[p]];
            rs += fabs(A->values[p]);
        }
        r = fmax(r, fabs(s));
        an = fmax(an, rs);
        bn = fmax(bn, fabs(b[i]));
    }
    for (j = 0; j < A->n; j++) xn = fmax(xn, fabs(x[j]));
    return r / (an * xn + bn);
}

/* Reads a Matrix Market file into e (caller frees). */
static inline int tl_read_mtx(silc_envelope_t *e, const char *path, char *err, size_t errlen)
{
    memset(e, 0, sizeof *e);
    return silc_mm_read(e, path, err, errlen);
}

/* Reads SILC_SHARED_MATRICES/file and binds it to name; m, n (may be NULL)
 * receive its shape. */
static inline int tl_put_shared(silc_context *c, const char *name, const char *file, int64_t *m,
                                int64_t *n, char *err, size_t errlen)
{
    char path[1024];
    silc_envelope_t e;
    int rc;
    snprintf(path, sizeof path, "%s/%s", SILC_SHARED_MATRICES, file);
    if (tl_read_mtx(&e, path, err, errlen)) return -1;
    if (m) *m = e.m;
    if (n) *n = e.n;
    rc = silc_put(c, name, &e);
    if (rc) snprintf(err, errlen, "put %s: %s", name, silc_context_errmsg(c));
    silc_envelope_free(&e);
    return rc;
}

/* Puts a dense column vector. */
static inline int tl_put_vector(silc_context *c, const char *name, int64_t n, const double *x)
{
    silc_envelope_t e;
    int rc;
    if (silc_envelope_vector(&e, n, x)) return -1;
    rc = silc_put(c, name, &e);
    silc_envelope_free(&e);
    return rc;
}

/* Fetches name as a malloc'd column-major array of m*n entries. */
static inline double *tl_get_dense(silc_context *c, const char *name, int64_t *m, int64_t *n)
{
    silc_envelope_t e;
    double *x = NULL;
    memset(&e, 0, sizeof e);
    if (silc_get(c, &e, name)) return NULL;
    x = malloc((size_t)(e.m * e.n > 0 ? e.m * e.n : 1) * sizeof *x);
    if (x && silc_envelope_to_dense(&e, x)) {
        free(x);
        x = NULL;
    }
    if (m) *m = e.m;
    if (n) *n = e.n;
    silc_envelope_free(&e);
    return x;
}

/* Puts A as "A" and b = A x (b: caller's array of A->m) as "b". */
static inline int tl_put_system(silc_context *c, const silc_envelope_t *A, const double *x, double *b)
{
    tl_csr_matvec(A, x, b);
    if (silc_put(c, "A", A)) return -1;
    return tl_put_vector(c, "b", A->m, b);
}

/* Fetches the n-vector name into x; an error if it is not n x 1. */
static inline int tl_get_vec(silc_context *c, const char *name, double *x, int64_t n)
{
    silc_envelope_t e;
    int rc;
    if (silc_get(c, &e, name)) return -1;
    rc = (e.m == n && e.n == 1) ? silc_envelope_to_dense(&e, x) : -1;
    silc_envelope_free(&e);
    return rc;
}

/* ---- output capture ---------------------------------------------------------- */

/* Text printed by `info`, `who` and `explain`, appended; grows as needed. */
typedef struct tl_capture {
    char *text;
    size_t len, cap;
} tl_capture;

static inline void tl_capture_fn(void *user, const char *text)
{
    tl_capture *c = user;
    size_t add = strlen(text);
    if (c->len + add + 1 > c->cap) {
        size_t cap = c->cap ? c->cap : 4096;
        char *t;
        while (cap < c->len + add + 1) cap *= 2;
        if (!(t = realloc(c->text, cap))) return;
        c->text = t;
        c->cap = cap;
    }
    memcpy(c->text + c->len, text, add + 1);
    c->len += add;
}

static inline void tl_capture_reset(tl_capture *c)
{
    c->len = 0;
    if (c->text) c->text[0] = '\0';
}

static inline const char *tl_capture_text(const tl_capture *c)
{
    return c->text ? c->text : "";
}

static inline void tl_capture_free(tl_capture *c)
{
    free(c->text);
    memset(c, 0, sizeof *c);
}

/* Sends ctx's output into c (c must outlive the context or be detached). */
static inline void tl_capture_attach(silc_context *ctx, tl_capture *c)
{
    silc_set_output(ctx, tl_capture_fn, c);
}

/* Runs `info name` and returns the captured text (valid until the next
 * capture on c). */
static inline const char *tl_info(silc_context *ctx, tl_capture *c, const char *name)
{
    char cmd[160];
    tl_capture_reset(c);
    snprintf(cmd, sizeof cmd, "info %s", name);
    if (silc_exec(ctx, cmd)) return "";
    return tl_capture_text(c);
}

/* ---- one output buffer ------------------------------------------------------- */

/* The plugin tests send every context's output into one fixed buffer (the
 * last statement's text, reset by tl_out_exec), which failure messages print. */
#define TL_OUT_SIZE 32768

static inline char *tl_out(void)
{
    static char buf[TL_OUT_SIZE];
    return buf;
}

/* silc_set_output callback appending to tl_out(), truncating when full. */
static inline void tl_out_fn(void *user, const char *text)
{
    char *out = tl_out();
    size_t have = strlen(out);
    (void)user;
    snprintf(out + have, TL_OUT_SIZE - have, "%s", text);
}

/* Runs stmt and returns what it printed, or "error: <message>". */
static inline const char *tl_out_exec(silc_context *c, const char *stmt)
{
    char *out = tl_out();
    out[0] = '\0';
    if (silc_exec(c, stmt)) snprintf(out, TL_OUT_SIZE, "error: %s", silc_context_errmsg(c));
    return out;
}

/* Runs `info name` and returns its text, or "info failed: <message>". */
static inline const char *tl_out_info(silc_context *c, const char *name)
{
    char cmd[160], *out = tl_out();
    out[0] = '\0';
    snprintf(cmd, sizeof cmd, "info %s", name);
    if (silc_exec(c, cmd)) snprintf(out, TL_OUT_SIZE, "info failed: %s", silc_context_errmsg(c));
    return out;
}

/* The number right after label in text (label includes its ": "), -1 when
 * the label is missing. */
static inline double tl_out_number(const char *text, const char *label)
{
    const char *p = strstr(text, label);
    return p ? strtod(p + strlen(label), NULL) : -1;
}

/* ---- text ---------------------------------------------------------------------- */

/* Case-insensitive substring test; NULL haystack contains nothing. */
static inline int tl_contains(const char *hay, const char *needle)
{
    size_t n = strlen(needle);
    for (; hay && *hay; hay++) {
        size_t i = 0;
        while (i < n && hay[i] &&
               tolower((unsigned char)hay[i]) == tolower((unsigned char)needle[i]))
            i++;
        if (i == n) return 1;
    }
    return 0;
}

/* The number after "label:" in text (e.g. "backward error" in `info` output);
 * NAN when the label is missing. */
static inline double tl_field(const char *text, const char *label)
{
    char key[128];
    const char *p;
    snprintf(key, sizeof key, "%s:", label);
    p = text ? strstr(text, key) : NULL;
    if (!p) return NAN;
    return strtod(p + strlen(key), NULL);
}

/* ---- numbers ------------------------------------------------------------------- */

static inline double tl_norm_inf(const double *x, int64_t n)
{
    double s = 0;
    int64_t i;
    for (i = 0; i < n; i++)
        if (fabs(x[i]) > s || isnan(x[i])) s = isnan(x[i]) ? NAN : fabs(x[i]);
    return s;
}

static inline double tl_diff_inf(const double *x, const double *y, int64_t n)
{
    double s = 0;
    int64_t i;
    for (i = 0; i < n; i++) {
        double d = fabs(x[i] - y[i]);
        if (d > s || isnan(d)) s = isnan(d) ? NAN : d;
    }
    return s;
}

/* ||x - y||_inf / ||y||_inf (absolute when y = 0). */
static inline double tl_rel_diff(const double *x, const double *y, int64_t n)
{
    double ny = tl_norm_inf(y, n), d = tl_diff_inf(x, y, n);
    return ny > 0 ? d / ny : d;
}

/* Reproducible values in [0.5, 1.5): a right-hand side or exact solution that
 * is not special to any ordering or scaling. */
static inline void tl_fill(double *x, int64_t n, uint64_t seed)
{
    int64_t i;
    for (i = 0; i < n; i++) {
        seed = seed * 6364136223846793005ull + 1442695040888963407ull;
        x[i] = 0.5 + (double)(seed >> 11) / 9007199254740992.0;
    }
}

static inline double tl_now(void)
{
    struct timespec t;
    timespec_get(&t, TIME_UTC);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* ---- with check.h: helpers that record their own failures -------------------- */

#ifdef SILC_CHECK_H

/* Reads SILC_SHARED_MATRICES/file into *A; a failure is a failed check. */
static inline int tl_read_shared(const char *file, silc_envelope_t *A)
{
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/%s", SILC_SHARED_MATRICES, file);
    if (tl_read_mtx(A, path, err, sizeof err) == 0) return 0;
    CHECK(0, "%s: %s", path, err);
    return -1;
}

/* One matrix of index.tsv: file rows cols nnz field symmetry class source. */
typedef struct tl_index_row {
    char file[256], field[32], symmetry[32], cls[32];
    long long rows, cols, nnz;
} tl_index_row;

/* dir/index.tsv (dir NULL: SILC_SHARED_MATRICES), or NULL with a failed check. */
static inline FILE *tl_index_open(const char *dir, char *path, size_t pathlen)
{
    FILE *f;
    snprintf(path, pathlen, "%s/index.tsv", dir ? dir : SILC_SHARED_MATRICES);
    f = fopen(path, "r");
    CHECK(f != NULL, "cannot open %s", path);
    return f;
}

/* The next matrix of the index: 1, or 0 at its end.  The header, comments
 * and blank lines are skipped; a row that does not parse is a failed check,
 * and skipped too. */
static inline int tl_index_next(FILE *f, tl_index_row *r)
{
    char line[1024];
    while (fgets(line, sizeof line, f)) {
        if (!strncmp(line, "file\t", 5) || line[0] == '#' || line[0] == '\n') continue;
        if (sscanf(line, "%255s %lld %lld %lld %31s %31s %31s", r->file, &r->rows, &r->cols, &r->nnz,
                   r->field, r->symmetry, r->cls) == 7)
            return 1;
        CHECK(0, "index.tsv: cannot parse '%s'", line);
    }
    return 0;
}

/* A context with the default config, printing into tl_out(); NULL with a
 * failed check. */
static inline silc_context *tl_open_printing(void)
{
    silc_context *c = NULL;
    if (silc_open(&c, NULL)) {
        CHECK(0, "silc_open: %s", c ? silc_context_errmsg(c) : silc_errmsg());
        silc_close(&c);
        return NULL;
    }
    silc_set_output(c, tl_out_fn, NULL);
    return c;
}

/* A context printing into tl_out() whose sparse solve classes (solve.sparse
 * and solve.sparse.spd) are forced to backend; NULL with a failed check. */
static inline silc_context *tl_open_forced(const char *backend)
{
    silc_context *c = tl_open_printing();
    char stmt[160];
    if (!c) return NULL;
    snprintf(stmt, sizeof stmt, "set dispatch.solve.sparse = %s; set dispatch.solve.sparse.spd = %s",
             backend, backend);
    CHECK(silc_exec(c, stmt) == 0, "%s: %s", stmt, silc_context_errmsg(c));
    return c;
}

/* Puts e under name; a failed check names it. */
static inline void tl_put_checked(silc_context *c, const char *name, const silc_envelope_t *e)
{
    CHECK(silc_put(c, name, e) == 0, "put %s: %s", name, silc_context_errmsg(c));
}

/* Puts the column-major m x n array x under name. */
static inline void tl_put_dense_checked(silc_context *c, const char *name, int64_t m, int64_t n,
                                        const double *x)
{
    silc_envelope_t e;
    CHECK(silc_envelope_dense(&e, m, n, x) == 0, "envelope %s", name);
    tl_put_checked(c, name, &e);
    silc_envelope_free(&e);
}

/* The m x n value name as a new column-major array, or NULL with a failed
 * check (missing, or another shape). */
static inline double *tl_get_dense_checked(silc_context *c, const char *name, int64_t m, int64_t n)
{
    silc_envelope_t e;
    double *x;
    memset(&e, 0, sizeof e);
    if (silc_get(c, &e, name)) {
        CHECK(0, "get %s: %s", name, silc_context_errmsg(c));
        return NULL;
    }
    if (e.m != m || e.n != n) {
        CHECK(0, "%s is %lldx%lld, want %lldx%lld", name, (long long)e.m, (long long)e.n,
              (long long)m, (long long)n);
        silc_envelope_free(&e);
        return NULL;
    }
    x = malloc((size_t)(m * n > 0 ? m * n : 1) * sizeof *x);
    if (x) silc_envelope_to_dense(&e, x);
    silc_envelope_free(&e);
    return x;
}

/* The shared SPD matrices an iterative solver must handle (issue 4). */
static const char *const tl_spd_files[] = {"bcsstk01", "bcsstk02", "LFAT5", "494_bus", "gr_30_30",
                                           "1138_bus", "bcsstk13", "bcsstk16", NULL};

/* Every SPD shared matrix, b = A * ones, solved in c by stmt (which assigns
 * x, e.g. a solve() with the solver's options) and judged against the
 * reference direct solve in ref: a converged answer must report a relative
 * residual <= tol and lie within tol * cond of the reference (2-norm relative
 * error); a failure must say "not converged" (or name a breakdown or
 * divergence) and leave x unchanged.  label names the solver in messages. */
static inline void tl_spd_sweep(silc_context *c, silc_context *ref, const char *label,
                                const char *stmt, double tol)
{
    for (int f = 0; tl_spd_files[f]; f++) {
        char file[256];
        silc_envelope_t A;
        double *ones, *b, *xref, *x, cond, t, d = 0, s = 0;
        int64_t n;
        int rc;
        snprintf(file, sizeof file, "%s.mtx", tl_spd_files[f]);
        if (tl_read_shared(file, &A)) continue;
        n = A.n;
        ones = malloc((size_t)n * sizeof *ones);
        b = malloc((size_t)n * sizeof *b);
        for (int64_t i = 0; i < n; i++) ones[i] = 1;
        tl_csr_matvec(&A, ones, b);
        tl_put_checked(c, "A", &A);
        tl_put_dense_checked(c, "b", n, 1, b);
        tl_put_checked(ref, "A", &A);
        tl_put_dense_checked(ref, "b", n, 1, b);
        CHECK(silc_exec(ref, "xr = A \\ b") == 0, "%s reference: %s", tl_spd_files[f], silc_context_errmsg(ref));
        cond = tl_out_number(tl_out_info(ref, "xr"), "condition estimate: ");
        xref = tl_get_dense_checked(ref, "xr", n, 1);
        CHECK(silc_exec(c, "x = 7") == 0, "x = 7");
        t = tl_now();
        rc = silc_exec(c, stmt);
        t = tl_now() - t;
        if (rc) {
            const char *msg = silc_context_errmsg(c);
            CHECK(tl_contains(msg, "not converged") || tl_contains(msg, "breakdown") ||
                      tl_contains(msg, "diverged") || tl_contains(msg, "DIVERGED"),
                  "%s %s failed without an honest message: %s", tl_spd_files[f], label, msg);
            x = tl_get_dense_checked(c, "x", 1, 1);
            CHECK(x && x[0] == 7, "%s: a failed solve changed x", tl_spd_files[f]);
            printf("  %-9s n=%-5lld %-12s %.3f s  not converged: %s\n", tl_spd_files[f], (long long)n,
                   label, t, msg);
            free(x);
        } else if (xref && (x = tl_get_dense_checked(c, "x", n, 1)) != NULL) {
            const char *in = tl_out_info(c, "x");
            double it = tl_out_number(in, "iterations: "), res = tl_out_number(in, "final relative residual: ");
            CHECK(res >= 0 && res <= tol, "%s %s: reported converged with residual %g", tl_spd_files[f],
                  label, res);
            for (int64_t i = 0; i < n; i++) {
                d += (x[i] - xref[i]) * (x[i] - xref[i]);
                s += xref[i] * xref[i];
            }
            d = s > 0 ? sqrt(d / s) : sqrt(d);
            CHECK(d <= tol * (cond > 1 ? cond : 1), "%s %s: error %.3g vs reference > %g * cond %.3g",
                  tl_spd_files[f], label, d, tol, cond);
            printf("  %-9s n=%-5lld %-12s %.3f s  %6g iterations, residual %.2g, error vs reference %.2g "
                   "(cond %.2g)\n", tl_spd_files[f], (long long)n, label, t, it, res, d, cond);
            free(x);
        }
        free(xref);
        free(ones);
        free(b);
        silc_envelope_free(&A);
    }
}

/* Warm starts in a time loop (solve.initial_guess, issue 18).  With A and
 * b = A * ones PUT in c and stmt a solve that assigns x with an iterative
 * method: stmt run again after b grows by 0.1 % starts from the previous x
 * (info says so), takes fewer iterations than from zero and still solves
 * (x = 1.001 * ones to tol); under solve.initial_guess = zero it starts from
 * zero again; a different statement assigning x does not start from it
 * (auto), unless solve.initial_guess = previous.  label names the solver. */
static inline void tl_check_warm_start(silc_context *c, const char *stmt, int64_t n, double tol,
                                       const char *label)
{
    double it0, it1, it2, scale = 1, *x, d = 0;
    char other[512];
    const char *in;
    snprintf(other, sizeof other, "x = 1 * %s", strchr(stmt, '=') + 1);
    if (silc_exec(c, stmt)) {
        CHECK(0, "%s: %s: %s", label, stmt, silc_context_errmsg(c));
        return;
    }
    in = tl_out_info(c, "x");
    it0 = tl_out_number(in, "iterations: ");
    CHECK(!strstr(in, "initial guess"), "%s: the first solve has no guess:\n%s", label, in);
    CHECK(silc_exec(c, "b = 1.001 * b") == 0 && silc_exec(c, stmt) == 0, "%s: second step: %s", label,
          silc_context_errmsg(c));
    scale *= 1.001;
    in = tl_out_info(c, "x");
    it1 = tl_out_number(in, "iterations: ");
    CHECK(strstr(in, "initial guess: the previous value of x (warm start)") != NULL,
          "%s: the repeated statement starts from the previous x:\n%s", label, in);
    CHECK(it1 >= 0 && it1 < it0, "%s: %g iterations from the previous x, %g from zero", label, it1, it0);
    if ((x = tl_get_dense_checked(c, "x", n, 1))) {
        for (int64_t i = 0; i < n; i++) d = fmax(d, fabs(x[i] - scale));
        CHECK(d <= tol, "%s: the warm-started x is off by %g", label, d);
        free(x);
    }
    CHECK(silc_exec(c, "set solve.initial_guess = zero; b = 1.001 * b") == 0 && silc_exec(c, stmt) == 0,
          "%s: zero: %s", label, silc_context_errmsg(c));
    in = tl_out_info(c, "x");
    it2 = tl_out_number(in, "iterations: ");
    CHECK(!strstr(in, "initial guess") && it2 > it1, "%s: solve.initial_guess = zero starts from 0 (%g "
          "iterations):\n%s", label, it2, in);
    CHECK(silc_exec(c, "set solve.initial_guess = auto") == 0 && silc_exec(c, other) == 0, "%s: %s: %s", label,
          other, silc_context_errmsg(c));
    CHECK(!strstr(tl_out_info(c, "x"), "initial guess"), "%s: another statement does not start from x", label);
    CHECK(silc_exec(c, "set solve.initial_guess = previous") == 0 && silc_exec(c, stmt) == 0, "%s: %s", label,
          silc_context_errmsg(c));
    CHECK(strstr(tl_out_info(c, "x"), "initial guess: the previous value") != NULL,
          "%s: solve.initial_guess = previous starts from any previous x:\n%s", label, tl_out());
    /* A guess worse than zero (b turned round) is dropped, and x is right. */
    CHECK(silc_exec(c, "b = -1000 * b") == 0 && silc_exec(c, stmt) == 0, "%s: turned: %s", label,
          silc_context_errmsg(c));
    scale *= -1000 * 1.001;
    CHECK(!strstr(tl_out_info(c, "x"), "initial guess: the previous"), "%s: a guess worse than 0 is dropped:\n%s",
          label, tl_out());
    if ((x = tl_get_dense_checked(c, "x", n, 1))) {
        d = 0;
        for (int64_t i = 0; i < n; i++) d = fmax(d, fabs(x[i] / scale - 1));
        CHECK(d <= tol, "%s: x after the dropped guess is off by %g", label, d);
        free(x);
    }
    CHECK(silc_exec(c, "set solve.initial_guess = auto") == 0, "restore");
}
#endif

#endif
