/*
 * test_api.c -- the public C API without the language: envelopes of every
 * kind through SILC_PUT/SILC_GET, conversion to dense against hand-written
 * matrices, CSR validation, Matrix Market reading (small files written here,
 * checked against hand-computed matrices, and every shared test matrix against
 * the sizes its README lists), writing and reading back bit-exact, name
 * checks, "did you mean" and calls out of order.  One SILC_EXEC checks the
 * plumbing to the language; nothing else depends on it.
 */
#define _POSIX_C_SOURCE 200809L
#include <silc.h>

#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "check.h"

#ifndef SILC_SHARED_MATRICES
#define SILC_SHARED_MATRICES "../shared/matrices"
#endif

static int contains(const char *s, const char *part)
{
    return s && strstr(s, part) != NULL;
}

/* Same format, shape and bit-identical arrays. */
static int same_envelope(const silc_envelope_t *a, const silc_envelope_t *b)
{
    int64_t nv;
    if (a->format != b->format || a->m != b->m || a->n != b->n || a->nnz != b->nnz) return 0;
    nv = a->format == SILC_CSR ? a->rowptr[a->m] : a->nnz;
    if (nv > 0 && memcmp(a->values, b->values, (size_t)nv * sizeof(double)) != 0) return 0;
    if (a->format == SILC_CSR) {
        if (memcmp(a->rowptr, b->rowptr, (size_t)(a->m + 1) * sizeof(int64_t)) != 0) return 0;
        if (nv > 0 && memcmp(a->colind, b->colind, (size_t)nv * sizeof(int64_t)) != 0) return 0;
    }
    if (a->format == SILC_BAND && (a->kl != b->kl || a->ku != b->ku)) return 0;
    return 1;
}

static int same_doubles(const double *a, const double *b, size_t n)
{
    return memcmp(a, b, n * sizeof(double)) == 0;
}

/* Checks the dense form of e against a row-major hand-written matrix. */
static void check_dense_rowmajor(const silc_envelope_t *e, int64_t m, int64_t n, const double *rows,
                                 const char *what)
{
    double *d;
    int64_t i, j, bad = 0;
    CHECK(e->m == m && e->n == n, "%s: shape %lldx%lld, want %lldx%lld", what, (long long)e->m,
          (long long)e->n, (long long)m, (long long)n);
    if (e->m != m || e->n != n) return;
    d = malloc((size_t)(m * n > 0 ? m * n : 1) * sizeof *d);
    CHECK(silc_envelope_to_dense(e, d) == 0, "%s: to_dense: %s", what, silc_errmsg());
    for (i = 0; i < m; i++)
        for (j = 0; j < n; j++)
            if (d[i + j * m] != rows[i * n + j]) bad++;
    CHECK(bad == 0, "%s: %lld entries differ from the hand-written matrix", what, (long long)bad);
    free(d);
}

static void test_before_init(void)
{
    silc_envelope_t e, g;
    silc_envelope_scalar(&e, 1.0);
    CHECK(silc_default_context() == NULL, "default context exists before SILC_INIT");
    CHECK(SILC_PUT("a", &e) != 0, "SILC_PUT before SILC_INIT succeeded");
    CHECK(strcmp(silc_errmsg(), "SILC_INIT has not been called") == 0, "message: %s", silc_errmsg());
    CHECK(SILC_GET(&g, "a") != 0 && g.values == NULL, "SILC_GET before SILC_INIT");
    CHECK(SILC_EXEC("a = 1") != 0, "SILC_EXEC before SILC_INIT succeeded");
    CHECK(contains(silc_errmsg(), "SILC_INIT has not been called"), "message: %s", silc_errmsg());
    CHECK(SILC_FINALIZE() != 0, "SILC_FINALIZE before SILC_INIT succeeded");
    silc_envelope_free(&e);
}

static void test_roundtrip(void)
{
    static const double dense[6] = {1.5, -2.0, 0.1, 1e-300, -0.0, 1e300}; /* 3x2 column-major */
    static const int64_t rp[4] = {0, 2, 2, 5};
    static const int64_t ci[5] = {2, 0, 3, 1, 0}; /* rows unsorted on purpose */
    static const double cv[5] = {3.0, 1.0, 7.0, 0.0, -4.0};
    static const int32_t rp32[4] = {0, 2, 2, 5};
    static const int32_t ci32[5] = {2, 0, 3, 1, 0};
    static const double band[12] = {0, 1, 2, 0, 3, 4, 5, 6, 0, 7, 8, 0}; /* 4x3, kl 1, ku 1 */
    silc_envelope_t in[6], out;
    const char *names[6] = {"D", "s", "v", "C", "C32", "B"};
    int k, i;

    CHECK(silc_envelope_dense(&in[0], 3, 2, dense) == 0, "dense: %s", silc_errmsg());
    CHECK(silc_envelope_scalar(&in[1], 3.25) == 0, "scalar");
    CHECK(silc_envelope_vector(&in[2], 3, dense) == 0, "vector");
    CHECK(silc_envelope_csr(&in[3], 3, 4, rp, ci, cv) == 0, "csr: %s", silc_errmsg());
    CHECK(silc_envelope_csr32(&in[4], 3, 4, rp32, ci32, cv) == 0, "csr32: %s", silc_errmsg());
    CHECK(silc_envelope_band(&in[5], 4, 3, 1, 1, band) == 0, "band: %s", silc_errmsg());

    /* The constructors sorted row 0 and row 2 and kept the explicit zero. */
    {
        static const int64_t want_ci[5] = {0, 2, 0, 1, 3};
        static const double want_v[5] = {1.0, 3.0, -4.0, 0.0, 7.0};
        for (k = 3; k <= 4; k++) {
            CHECK(in[k].nnz == 5 && memcmp(in[k].colind, want_ci, sizeof want_ci) == 0 &&
                      same_doubles(in[k].values, want_v, 5),
                  "%s: columns not sorted with their values", names[k]);
        }
    }
    CHECK(in[1].m == 1 && in[1].n == 1 && in[1].values[0] == 3.25, "scalar envelope");
    CHECK(in[2].m == 3 && in[2].n == 1, "vector envelope shape");
    CHECK(silc_envelope_rows(&in[5]) == 4 && silc_envelope_cols(&in[5]) == 3, "rows/cols");

    for (k = 0; k < 6; k++) {
        CHECK(SILC_PUT(names[k], &in[k]) == 0, "SILC_PUT %s: %s", names[k], silc_errmsg());
        CHECK(SILC_GET(&out, names[k]) == 0, "SILC_GET %s: %s", names[k], silc_errmsg());
        CHECK(same_envelope(&in[k], &out), "%s changed in a PUT/GET round trip", names[k]);
        /* The store holds a copy: changing the program's array changes nothing. */
        if (k == 0) {
            silc_envelope_t again;
            in[0].values[0] = 99.0;
            SILC_GET(&again, "D");
            CHECK(again.values[0] == 1.5, "store aliases the caller's array");
            silc_envelope_free(&again);
            in[0].values[0] = 1.5;
        }
        silc_envelope_free(&out);
    }
    /* Re-putting a name replaces its value. */
    CHECK(SILC_PUT("s", &in[2]) == 0 && SILC_GET(&out, "s") == 0 && out.m == 3, "rebinding 's'");
    silc_envelope_free(&out);

    for (i = 0; i < 6; i++) silc_envelope_free(&in[i]);
    CHECK(in[0].values == NULL && in[0].m == 0, "silc_envelope_free zeroes the envelope");
    silc_envelope_free(&in[0]); /* twice is fine */
    silc_envelope_free(NULL);
}

static void test_to_dense(void)
{
    /* CSR of
     *   [ 1 0 2 0 ]
     *   [ 0 0 0 0 ]
     *   [ 3 4 0 5 ]   */
    static const int64_t rp[4] = {0, 2, 2, 5};
    static const int64_t ci[5] = {0, 2, 0, 1, 3};
    static const double v[5] = {1, 2, 3, 4, 5};
    static const double csr_truth[12] = {1, 0, 2, 0, 0, 0, 0, 0, 3, 4, 0, 5};
    /* Band kl = 1, ku = 2 of
     *   [ 1  2  3  0 ]
     *   [ 4  5  6  7 ]
     *   [ 0  8  9 10 ]
     *   [ 0  0 11 12 ]
     * columns of the LAPACK array (ld 4), 99 in the unused corners. */
    static const double band[16] = {99, 99, 1, 4, 99, 2, 5, 8, 3, 6, 9, 11, 7, 10, 12, 99};
    static const double band_truth[16] = {1, 2, 3, 0, 4, 5, 6, 7, 0, 8, 9, 10, 0, 0, 11, 12};
    /* A wide band: 2x4, kl 0, ku 1: [1 2 0 0; 0 3 4 0] */
    static const double wide[8] = {99, 1, 2, 3, 4, 99, 99, 99};
    static const double wide_truth[8] = {1, 2, 0, 0, 0, 3, 4, 0};
    static const double dtruth[6] = {1, 2, 3, 4, 5, 6};
    static const double dcol[6] = {1, 4, 2, 5, 3, 6};
    silc_envelope_t e;

    silc_envelope_csr(&e, 3, 4, rp, ci, v);
    check_dense_rowmajor(&e, 3, 4, csr_truth, "csr to_dense");
    silc_envelope_free(&e);
    silc_envelope_band(&e, 4, 4, 1, 2, band);
    check_dense_rowmajor(&e, 4, 4, band_truth, "band to_dense");
    silc_envelope_free(&e);
    silc_envelope_band(&e, 2, 4, 0, 1, wide);
    check_dense_rowmajor(&e, 2, 4, wide_truth, "wide band to_dense");
    silc_envelope_free(&e);
    silc_envelope_dense(&e, 2, 3, dcol);
    check_dense_rowmajor(&e, 2, 3, dtruth, "dense to_dense");
    silc_envelope_free(&e);
    CHECK(silc_envelope_to_dense(NULL, NULL) != 0, "to_dense(NULL)");
}

static void test_csr_errors(void)
{
    static const double v[4] = {1, 2, 3, 4};
    static const int64_t ci_ok[4] = {0, 1, 0, 1};
    static const int64_t rp_bad0[3] = {1, 2, 4};
    static const int64_t rp_dec[3] = {0, 3, 2};
    static const int64_t rp_ok[3] = {0, 2, 4};
    static const int64_t ci_range[4] = {0, 2, 0, 1};
    static const int64_t ci_neg[4] = {0, -1, 0, 1};
    static const int64_t ci_dup[4] = {0, 1, 1, 1};
    static const int32_t rp32_dec[3] = {0, 3, 2};
    silc_envelope_t e;

    CHECK(silc_envelope_csr(&e, 2, 2, rp_bad0, ci_ok, v) != 0, "rowptr[0] = 1 accepted");
    CHECK(contains(silc_errmsg(), "rowptr[0]"), "message: %s", silc_errmsg());
    CHECK(e.values == NULL && e.rowptr == NULL, "failed constructor left arrays behind");
    /* SILC_PUT of that envelope (the README's sequence without its checks)
     * is an error naming why, and binds nothing, not a 0x0 value. */
    CHECK(SILC_PUT("failed_env", &e) != 0, "SILC_PUT of a failed constructor's envelope succeeded");
    CHECK(contains(silc_errmsg(), "envelope 'failed_env' was not constructed: silc_envelope_csr: rowptr[0]"),
          "message: %s", silc_errmsg());
    CHECK(silc_get(silc_default_context(), &e, "failed_env") != 0,
          "failed_env is bound after the refused SILC_PUT");
    CHECK(silc_envelope_csr(&e, 2, 2, rp_dec, ci_ok, v) != 0, "decreasing rowptr accepted");
    CHECK(contains(silc_errmsg(), "rowptr decreases at row 1"), "message: %s", silc_errmsg());
    CHECK(silc_envelope_csr32(&e, 2, 2, rp32_dec, (const int32_t *)NULL, v) != 0, "csr32 bad rowptr");
    CHECK(silc_envelope_csr(&e, 2, 2, rp_ok, ci_range, v) != 0, "column 2 of a 2-column matrix accepted");
    CHECK(contains(silc_errmsg(), "column index 2 out of range [0, 2) in row 0"), "message: %s",
          silc_errmsg());
    CHECK(silc_envelope_csr(&e, 2, 2, rp_ok, ci_neg, v) != 0, "negative column accepted");
    CHECK(silc_envelope_csr(&e, 2, 2, rp_ok, ci_dup, v) != 0, "duplicate accepted");
    CHECK(contains(silc_errmsg(), "duplicate entry at row 1, column 1"), "message: %s", silc_errmsg());
    CHECK(silc_envelope_csr(&e, 2, 2, NULL, ci_ok, v) != 0, "NULL rowptr accepted");
    CHECK(silc_envelope_csr(&e, -1, 2, rp_ok, ci_ok, v) != 0, "negative size accepted");
    CHECK(silc_envelope_dense(&e, -3, 2, NULL) != 0, "negative dense size accepted");
    CHECK(silc_envelope_band(&e, 3, 3, -1, 0, NULL) != 0, "negative kl accepted");
    CHECK(silc_envelope_dense(NULL, 1, 1, NULL) != 0, "NULL envelope accepted");

    /* A hand-filled envelope that breaks the invariants is refused by PUT. */
    {
        int64_t rp[2] = {0, 2}, ci[2] = {1, 0};
        double x[2] = {1, 2};
        silc_envelope_t h;
        memset(&h, 0, sizeof h);
        h.m = 1;
        h.n = 2;
        h.format = SILC_CSR;
        h.rowptr = rp;
        h.colind = ci;
        h.values = x;
        h.nnz = 2;
        CHECK(SILC_PUT("h", &h) != 0, "unsorted hand-made CSR accepted");
        CHECK(contains(silc_errmsg(), "not sorted"), "message: %s", silc_errmsg());
        /* PUT checks as it copies (val_csr_fill_checked); each failure, in
         * any row, is named as env_check names it, and the name keeps its
         * old value. */
        {
            int64_t rp3[4] = {0, 1, 2, 5}, ci3[5] = {0, 1, 0, 1, 2};
            double x3[5] = {1, 2, 3, 4, 5};
            silc_envelope_t g = h, out;
            static const struct {
                int at;
                int64_t col;
                const char *msg;
            } bad[] = {{3, 0, "columns of row 2 are duplicated"},
                       {4, 3, "column index 3 out of range [0, 3) in row 2"},
                       {2, -1, "column index -1 out of range [0, 3) in row 2"},
                       {0, 5, "column index 5 out of range [0, 3) in row 0"},
                       {4, 0, "columns of row 2 are not sorted"}};
            size_t b;
            g.m = g.n = 3, g.rowptr = rp3, g.colind = ci3, g.values = x3, g.nnz = 5;
            CHECK(SILC_PUT("g", &g) == 0, "good 3x3 CSR refused: %s", silc_errmsg());
            for (b = 0; b < sizeof bad / sizeof bad[0]; b++) {
                int64_t keep = ci3[bad[b].at];
                ci3[bad[b].at] = bad[b].col;
                CHECK(SILC_PUT("g", &g) != 0 && contains(silc_errmsg(), bad[b].msg), "%s: %s", bad[b].msg,
                      silc_errmsg());
                ci3[bad[b].at] = keep;
            }
            rp3[2] = 0;
            CHECK(SILC_PUT("g", &g) != 0 && contains(silc_errmsg(), "rowptr decreases at row 1"),
                  "decreasing rowptr: %s", silc_errmsg());
            rp3[2] = 2;
            CHECK(SILC_GET(&out, "g") == 0 && out.format == SILC_CSR && out.rowptr[3] == 5 &&
                      out.colind[4] == 2 && out.values[4] == 5,
                  "g changed by refused PUTs: %s", silc_errmsg());
            silc_envelope_free(&out);
            SILC_EXEC("clear g");
        }
        h.format = (silc_format_t)7;
        CHECK(SILC_PUT("h", &h) != 0 && contains(silc_errmsg(), "unknown envelope format 7"),
              "unknown format: %s", silc_errmsg());
    }
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        CHECK(0, "cannot write %s", path);
        return;
    }
    fputs(text, f);
    fclose(f);
}

/* Reads text as a Matrix Market file and checks it against a row-major matrix. */
static void check_mm(const char *text, int64_t m, int64_t n, const double *rows, int want_format,
                     int64_t want_nnz, const char *what)
{
    const char *path = "/tmp/silc_test_api.mtx";
    char err[512];
    silc_envelope_t e;
    write_file(path, text);
    if (silc_mm_read(&e, path, err, sizeof err)) {
        CHECK(0, "%s: %s", what, err);
        return;
    }
    CHECK((int)e.format == want_format, "%s: format %d", what, (int)e.format);
    CHECK(e.nnz == want_nnz, "%s: %lld stored entries, want %lld", what, (long long)e.nnz,
          (long long)want_nnz);
    check_dense_rowmajor(&e, m, n, rows, what);
    silc_envelope_free(&e);
}

static void check_mm_error(const char *text, const char *want, const char *what)
{
    const char *path = "/tmp/silc_test_api.mtx";
    char err[512];
    silc_envelope_t e;
    write_file(path, text);
    CHECK(silc_mm_read(&e, path, err, sizeof err) != 0, "%s: accepted", what);
    CHECK(contains(err, want), "%s: message '%s', want '%s'", what, err, want);
    CHECK(strcmp(err, silc_errmsg()) == 0, "%s: silc_errmsg differs: %s", what, silc_errmsg());
    CHECK(e.values == NULL, "%s: failed read left arrays", what);
}

static void test_mm_read(void)
{
    static const double general[9] = {1, 0, 2, 0, 0, 0, 3, 4, 0};
    static const double sym[9] = {4, 1, 0, 1, 5, 2, 0, 2, 6};
    static const double pat[6] = {1, 0, 1, 0, 1, 1};
    static const double skew[9] = {0, -2, 3, 2, 0, 5, -3, -5, 0};
    static const double arr[6] = {1, 2, 3, 4, 5, 6};
    static const double arr_sym[9] = {1, 2, 3, 2, 4, 5, 3, 5, 6};
    char err[256];
    silc_envelope_t e;

    /* 3x3 general with an explicit zero at (2,2) kept as an entry. */
    check_mm("%%MatrixMarket matrix coordinate real general\n% comment\n\n3 3 5\n"
             "3 2 4\n1 1 1\n3 1 3\n1 3 2.0\n2 2 0\n",
             3, 3, general, SILC_CSR, 5, "general");
    check_mm("%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 4\n2 1 1\n2 2 5\n3 2 2\n3 3 6\n",
             3, 3, sym, SILC_CSR, 7, "symmetric");
    check_mm("%%MatrixMarket matrix coordinate integer symmetric\n3 3 5\n1 1 4\n2 1 1\n2 2 5\n3 2 2\n3 3 6\n",
             3, 3, sym, SILC_CSR, 7, "integer symmetric");
    check_mm("%%MatrixMarket matrix coordinate pattern general\n2 3 4\n1 1\n2 2\n1 3\n2 3\n", 2, 3, pat,
             SILC_CSR, 4, "pattern");
    check_mm("%%MatrixMarket matrix coordinate real skew-symmetric\n3 3 3\n2 1 2\n3 1 -3\n3 2 -5\n", 3, 3,
             skew, SILC_CSR, 6, "skew-symmetric");
    check_mm("%%MatrixMarket matrix array real general\n2 3\n1\n4\n2\n5\n3\n6\n", 2, 3, arr, SILC_DENSE, 6,
             "array");
    check_mm("%%MatrixMarket matrix array real symmetric\n3 3\n1\n2\n3\n4\n5\n6\n", 3, 3, arr_sym,
             SILC_DENSE, 9, "array symmetric");
    check_mm("%%MatrixMarket matrix coordinate real general\n0 0 0\n", 0, 0, NULL, SILC_CSR, 0, "empty");

    check_mm_error("%%MatrixMarket matrix coordinate real general\n2 2 3\n1 1 1\n2 2 2\n1 1 3\n",
                   "silc_test_api.mtx:5: duplicate entry (1, 1)", "duplicate");
    check_mm_error("%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n2 1 1\n2 1 3\n",
                   "duplicate entry", "duplicate in a symmetric file");
    check_mm_error("%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n2 1 1\n1 2 3\n",
                   ":4:1: entry (1, 2) is above the diagonal: a symmetric file stores the lower triangle only",
                   "above the diagonal of a symmetric file");
    check_mm_error("%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1\n",
                   "expected a value", "complex entry without its imaginary part");
    check_mm_error("%%MatrixMarket matrix coordinate real general\n2 2 3\n1 1 1\n2 2 2\n",
                   "file ends after 2 of 3 entries", "short file");
    check_mm_error("%%MatrixMarket matrix coordinate real general\n2 2 1\n1 3 1\n",
                   "silc_test_api.mtx:3:1: entry (1, 3) is outside the 2x2 matrix", "out of range");
    check_mm_error("%%MatrixMarket matrix coordinate real general\n2 2 1\n1 x 1\n",
                   ":3:3: column index 'x' is not an integer", "garbage");
    check_mm_error("%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 1\n2 2 2\n",
                   ":4: more entries", "too many");
    check_mm_error("hello\n", ":1: not a Matrix Market file", "no banner");
    check_mm_error("%%MatrixMarket matrix coordinate real symmetric\n2 3 1\n1 1 1\n", "must be square",
                   "non-square symmetric");
    /* no line may make the reader allocate without bound: 64 KiB at most,
     * wherever the line is (an entry, the last line, a comment) */
    {
        static const char *const heads[3] = {
            "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 ",
            "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 1\n",
            "%%MatrixMarket matrix coordinate real general\n%"};
        static const char *const where[3] = {":3: line longer than 65536 bytes",
                                             ":4: line longer than 65536 bytes",
                                             ":2: line longer than 65536 bytes"};
        size_t h, len = 70000;
        for (h = 0; h < 3; h++) {
            char *text = malloc(strlen(heads[h]) + len + 2);
            if (!text) continue;
            strcpy(text, heads[h]);
            memset(text + strlen(heads[h]), '1', len);
            strcpy(text + strlen(heads[h]) + len, "\n");
            check_mm_error(text, where[h], "long line");
            free(text);
        }
    }
    CHECK(silc_mm_read(&e, "/nonexistent/x.mtx", err, sizeof err) != 0 &&
              contains(err, "/nonexistent/x.mtx: cannot open"),
          "missing file: %s", err);
    CHECK(silc_mm_read(NULL, "/tmp/x", NULL, 0) != 0, "NULL envelope accepted");
}

/* Writes e, reads it back and compares bit for bit. */
static void check_mm_write_read(const silc_envelope_t *e, const silc_envelope_t *want, const char *what)
{
    const char *path = "/tmp/silc_test_api_w.mtx";
    char err[256];
    silc_envelope_t r;
    FILE *f = fopen(path, "w");
    CHECK(f && silc_mm_write(e, f) == 0, "%s: write", what);
    if (f) fclose(f);
    if (silc_mm_read(&r, path, err, sizeof err)) {
        CHECK(0, "%s: read back: %s", what, err);
        return;
    }
    CHECK(same_envelope(want, &r), "%s: not bit-exact after write and read", what);
    silc_envelope_free(&r);
}

static void test_mm_write(void)
{
    double d[6] = {0.1, 1.0 / 3.0, -1e-300, 6.02214076e23, -0.0, 4.9e-324};
    static const int64_t rp[3] = {0, 2, 3};
    static const int64_t ci[3] = {0, 2, 1};
    static const double cv[3] = {2.0 / 3.0, 0.0, -1e308};
    silc_envelope_t e, want;
    silc_envelope_dense(&e, 3, 2, d);
    check_mm_write_read(&e, &e, "dense");
    silc_envelope_free(&e);
    silc_envelope_csr(&e, 2, 3, rp, ci, cv);
    check_mm_write_read(&e, &e, "csr with explicit zero");
    silc_envelope_free(&e);
    /* Band 3x3 kl 1 ku 0 of [0.0 0 0; 1.1 2.2 0; 0 3.3 4.4]: the zero (1,1) of the
     * band is not written, so the read-back CSR has four entries. */
    {
        static const double bd[6] = {0.0, 1.1, 2.2, 3.3, 4.4, 0};
        static const int64_t wrp[4] = {0, 0, 2, 4};
        static const int64_t wci[4] = {0, 1, 1, 2};
        static const double wv[4] = {1.1, 2.2, 3.3, 4.4};
        silc_envelope_band(&e, 3, 3, 1, 0, bd);
        silc_envelope_csr(&want, 3, 3, wrp, wci, wv);
        check_mm_write_read(&e, &want, "band");
        silc_envelope_free(&e);
        silc_envelope_free(&want);
    }
}

/* Every file of the shared collection: sizes and full entry counts from the
 * summary table of its README; complex ones read as complex CSR. */
static void test_shared_matrices(void)
{
    char line[1024], path[1024], err[1024];
    FILE *readme;
    int files = 0;
    snprintf(path, sizeof path, "%s/README.md", SILC_SHARED_MATRICES);
    readme = fopen(path, "r");
    CHECK(readme != NULL, "cannot open %s", path);
    if (!readme) return;
    while (fgets(line, sizeof line, readme)) {
        char name[256], field[64], sym[64];
        long long m, n, stored, full;
        silc_envelope_t e;
        if (sscanf(line, "| %255s | %lld | %lld | %lld | %lld | %63s | %63s |", name, &m, &n, &stored,
                   &full, field, sym) != 7)
            continue;
        files++;
        snprintf(path, sizeof path, "%s/%s", SILC_SHARED_MATRICES, name);
        if (strcmp(field, "complex") == 0) { /* read as complex CSR (test_complex_core checks values) */
            CHECK(silc_mm_read(&e, path, err, sizeof err) == 0, "%s: %s", name, err);
            CHECK(e.format == SILC_CSR_COMPLEX && e.m == m && e.n == n && e.nnz == full,
                  "%s: %lldx%lld complex csr of %lld entries, README says %lld", name, (long long)e.m,
                  (long long)e.n, (long long)e.nnz, full);
            silc_envelope_free(&e);
            continue;
        }
        if (silc_mm_read(&e, path, err, sizeof err)) {
            CHECK(0, "%s: %s", name, err);
            continue;
        }
        CHECK(e.format == SILC_CSR && e.m == m && e.n == n, "%s: %lldx%lld", name, (long long)e.m,
              (long long)e.n);
        CHECK(e.nnz == full, "%s: %lld entries, README says %lld", name, (long long)e.nnz, full);
        if (strcmp(sym, "symmetric") == 0 && e.format == SILC_CSR) {
            /* every (i, j) has its mirror with the same value */
            int64_t i, k, bad = 0;
            for (i = 0; i < e.m; i++)
                for (k = e.rowptr[i]; k < e.rowptr[i + 1]; k++) {
                    int64_t j = e.colind[k], q;
                    int found = 0;
                    for (q = e.rowptr[j]; q < e.rowptr[j + 1]; q++)
                        if (e.colind[q] == i) found = e.values[q] == e.values[k];
                    bad += !found;
                }
            CHECK(bad == 0, "%s: %lld entries without an equal mirror", name, (long long)bad);
        }
        if (strcmp(name, "bcsstk16.mtx") == 0 || strcmp(name, "ash219.mtx") == 0) {
            silc_envelope_t back;
            CHECK(SILC_PUT("M", &e) == 0 && SILC_GET(&back, "M") == 0 && same_envelope(&e, &back),
                  "%s: PUT/GET round trip", name);
            if (strcmp(name, "ash219.mtx") == 0) {
                int64_t k, ones = 0;
                for (k = 0; k < e.nnz; k++) ones += e.values[k] == 1.0;
                CHECK(ones == e.nnz, "ash219: pattern entries are not all 1");
            }
            silc_envelope_free(&back);
        }
        silc_envelope_free(&e);
    }
    fclose(readme);
    CHECK(files >= 28, "only %d matrices listed in the README table", files);
}

static void test_names(void)
{
    silc_envelope_t e, g;
    static const char *const bad[] = {"1x", "", "a-b", "a b", "x.y", "é"};
    size_t k;
    silc_envelope_scalar(&e, 2.0);
    for (k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char want[64];
        snprintf(want, sizeof want, "invalid name '%s'", bad[k]);
        CHECK(SILC_PUT(bad[k], &e) != 0, "name '%s' accepted", bad[k]);
        CHECK(contains(silc_errmsg(), want), "message: %s", silc_errmsg());
    }
    SILC_PUT("1x", &e);
    CHECK(strncmp(silc_errmsg(), "invalid name '1x': names start with a letter or '_'", 50) == 0,
          "message: %s", silc_errmsg());
    CHECK(SILC_PUT("_x1", &e) == 0 && SILC_PUT("alpha", &e) == 0, "valid names refused: %s", silc_errmsg());

    CHECK(SILC_GET(&g, "alphx") != 0, "undefined name fetched");
    CHECK(strcmp(silc_errmsg(), "undefined name 'alphx' (did you mean 'alpha'?)") == 0, "message: %s",
          silc_errmsg());
    CHECK(g.values == NULL, "failed SILC_GET left arrays");
    CHECK(SILC_GET(&g, "zzzzzzzz") != 0 && strcmp(silc_errmsg(), "undefined name 'zzzzzzzz'") == 0,
          "message: %s", silc_errmsg());

    /* NULL arguments fail cleanly. */
    CHECK(SILC_PUT(NULL, &e) != 0 && contains(silc_errmsg(), "NULL name"), "NULL name: %s", silc_errmsg());
    CHECK(SILC_PUT("a", NULL) != 0 && contains(silc_errmsg(), "NULL envelope"), "NULL envelope");
    CHECK(SILC_GET(NULL, "a") != 0, "SILC_GET(NULL)");
    CHECK(SILC_GET(&g, NULL) != 0, "SILC_GET name NULL");
    CHECK(SILC_EXEC(NULL) != 0, "SILC_EXEC(NULL)");
    CHECK(silc_put(NULL, "a", &e) != 0 && silc_get(NULL, &g, "a") != 0 && silc_exec(NULL, "a") != 0,
          "NULL context accepted");
    CHECK(silc_open(NULL, NULL) != 0, "silc_open(NULL)");
    silc_close(NULL);

    /* The most recent failure wins: an envelope error, then a context one. */
    silc_envelope_dense(&g, -1, 1, NULL);
    CHECK(contains(silc_errmsg(), "silc_envelope_dense"), "envelope message not shown: %s", silc_errmsg());
    SILC_GET(&g, "nope");
    CHECK(contains(silc_errmsg(), "undefined name 'nope'"), "context message not shown: %s", silc_errmsg());
    silc_envelope_free(&e);
}

static void test_contexts(void)
{
    silc_context *a = NULL, *b = NULL;
    silc_envelope_t e, g;
    CHECK(silc_open(&a, NULL) == 0 && silc_open(&b, NULL) == 0, "silc_open: %s", silc_errmsg());
    if (!a || !b) return;
    silc_envelope_scalar(&e, 5.0);
    CHECK(silc_put(a, "only_a", &e) == 0, "silc_put");
    CHECK(silc_get(b, &g, "only_a") != 0, "names leak between contexts");
    CHECK(contains(silc_context_errmsg(b), "undefined name 'only_a'"), "message: %s", silc_context_errmsg(b));
    CHECK(silc_get(a, &g, "only_a") == 0 && g.values[0] == 5.0, "silc_get");
    CHECK(strcmp(silc_context_warnings(a), "") == 0, "warnings before any exec");
    silc_envelope_free(&g);
    silc_envelope_free(&e);
    silc_close(&a);
    silc_close(&b);
    CHECK(a == NULL && b == NULL, "silc_close clears the handle");
}

static void test_exec_plumbing(void)
{
    static const double x[3] = {1.0, 2.5, -3.0};
    silc_envelope_t e, y;
    silc_envelope_vector(&e, 3, x);
    SILC_PUT("x", &e);
    CHECK(SILC_EXEC("y = x") == 0, "SILC_EXEC: %s", silc_errmsg());
    CHECK(SILC_GET(&y, "y") == 0 && y.m == 3 && y.n == 1 && y.values && same_doubles(y.values, x, 3),
          "y = x did not copy x: %s", silc_errmsg());
    silc_envelope_free(&y);
    silc_envelope_free(&e);
}

/* Large arrays recycle through the process's pool (core/client/pool.c): one
 * asked for zeroed must be zero even when it last held other numbers, and
 * one about to be overwritten must hold exactly what was written. */
static void test_recycled_arrays(void)
{
    enum { N = 1 << 18 }; /* 2 MiB of doubles: above the pool's 1 MiB floor */
    silc_envelope_t e, z, back;
    double *sevens = malloc(N * sizeof *sevens);
    int64_t i, bad = 0;
    if (!sevens) return;
    for (i = 0; i < N; i++) sevens[i] = 7.0 + (double)i;
    for (int round = 0; round < 3; round++) {
        CHECK(silc_envelope_vector(&e, N, sevens) == 0 && SILC_PUT("big", &e) == 0, "put: %s",
              silc_errmsg());
        silc_envelope_free(&e); /* the envelope's array goes to the pool */
        CHECK(SILC_EXEC("clear big; z = zeros(262144, 1); w = z + 1") == 0, "zeros: %s", silc_errmsg());
        CHECK(silc_envelope_dense(&z, N, 1, NULL) == 0, "zeroed envelope: %s", silc_errmsg());
        for (i = 0; i < N; i++) bad += z.values[i] != 0;
        silc_envelope_free(&z);
        CHECK(SILC_GET(&back, "z") == 0 && back.m == N, "get z: %s", silc_errmsg());
        for (i = 0; i < N && back.values; i++) bad += back.values[i] != 0;
        silc_envelope_free(&back);
        CHECK(SILC_GET(&back, "w") == 0 && back.m == N, "get w: %s", silc_errmsg());
        for (i = 0; i < N && back.values; i++) bad += back.values[i] != 1;
        silc_envelope_free(&back);
    }
    CHECK(bad == 0, "%lld entries of recycled arrays were not what was asked for", (long long)bad);
    CHECK(SILC_EXEC("clear z w") == 0, "clear: %s", silc_errmsg());
    free(sevens);
}

static void capture_text(void *user, const char *text)
{
    size_t have = strlen((char *)user), add = strlen(text);
    if (have + add < 8192) memcpy((char *)user + have, text, add + 1);
}

/* `tune status`'s integer after "key = ", or -1. */
static int tune_status_int(silc_context *c, char *out, const char *key)
{
    char pat[64];
    const char *at;
    out[0] = 0;
    if (silc_exec(c, "tune status")) return -1;
    snprintf(pat, sizeof pat, "\n%s = ", key);
    at = strstr(out, pat);
    return at ? atoi(at + strlen(pat)) : -1;
}

/* The tuner finds the steps wherever they repeat (issue 18): a program's
 * EXEC loop, and a `while` loop inside one EXEC (a `silc run` script); the
 * same embedded and through silcd (test_api_remote). */
static void test_tuning_loops(void)
{
    static char out[8192];
    char setup[256];
    silc_context *c = NULL;
    int k;
    /* through silcd the wisdom file is the operator's (a server setting):
     * `tune forget` makes the session tune without it */
    if (getenv("SILC_SERVER"))
        snprintf(setup, sizeof setup, "tune forget; tune on 100000; n = 40; "
                                      "A = sparse(4 * eye(n) + 0.5 * ones(n, n)); b = ones(n, 1)");
    else
        snprintf(setup, sizeof setup,
                 "set tune.wisdom = /tmp/silc-test-api-wisdom-%ld; tune forget; tune on 100000; n = 40; "
                 "A = sparse(4 * eye(n) + 0.5 * ones(n, n)); b = ones(n, 1)", (long)getpid());
    for (k = 0; k < 2; k++) {
        CHECK(silc_open(&c, NULL) == 0, "silc_open: %s", silc_errmsg());
        if (!c) return;
        silc_set_output(c, capture_text, out);
        CHECK(silc_exec(c, setup) == 0, "setup: %s", silc_context_errmsg(c));
        if (k == 0) {
            int i;
            for (i = 0; i < 30; i++) CHECK(silc_exec(c, "x = A \\ b") == 0, "solve: %s", silc_context_errmsg(c));
            CHECK(tune_status_int(c, out, "steps") >= 20 && strstr(out, "period = 1 EXEC"),
                  "an EXEC loop is found: %s", out);
        } else {
            CHECK(silc_exec(c, "i = 0; while (i < 40) { y = A \\ b; i = i + 1 }") == 0, "loop: %s",
                  silc_context_errmsg(c));
            CHECK(tune_status_int(c, out, "steps") == 40, "every iteration of the loop is a step: %s", out);
            CHECK(strstr(out, "sampled steps = ") != NULL, "the loop's steps were sampled: %s", out);
        }
        CHECK(silc_exec(c, "tune forget") == 0, "tune forget: %s", silc_context_errmsg(c));
        silc_close(&c);
    }
}

int main(void)
{
    test_before_init();
    CHECK(SILC_INIT() == 0, "SILC_INIT: %s", silc_errmsg());
    CHECK(silc_default_context() != NULL, "no default context after SILC_INIT");
    CHECK(SILC_INIT() != 0 && strcmp(silc_errmsg(), "SILC_INIT: already initialised") == 0,
          "second SILC_INIT: %s", silc_errmsg());
    test_roundtrip();
    test_to_dense();
    test_csr_errors();
    test_mm_read();
    test_mm_write();
    test_shared_matrices();
    test_names();
    test_contexts();
    test_exec_plumbing();
    test_recycled_arrays();
    test_tuning_loops();
    CHECK(SILC_FINALIZE() == 0, "SILC_FINALIZE");
    CHECK(silc_default_context() == NULL, "default context survives SILC_FINALIZE");
    CHECK(SILC_FINALIZE() != 0, "second SILC_FINALIZE succeeded");
    return check_done();
}
