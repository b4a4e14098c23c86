/*
 * diffusion_common.c -- assembly, initial fields and time loops shared by the
 * diffusion examples and their test (see diffusion_common.h).  Written only
 * against the public API: the matrices are assembled in plain C, as a user's
 * program would, and handed to SILC as CSR envelopes.
 */
#include "diffusion_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static const double pi = 3.14159265358979323846;

int diff_shifted_laplacian(int dim, int64_t n, double h, double c, silc_envelope_t *out)
{
    int64_t rows = (dim == 1 || dim == 2) && n >= 1 ? (dim == 1 ? n : n * n) : 0;
    return diff_shifted_laplacian_rows(dim, n, h, c, 0, rows, out);
}

int diff_shifted_laplacian_rows(int dim, int64_t n, double h, double c, int64_t r0, int64_t r1,
                                silc_envelope_t *out)
{
    if ((dim != 1 && dim != 2) || n < 1 || !(h > 0)) {
        fprintf(stderr, "diff_shifted_laplacian: need dim 1 or 2, n >= 1, h > 0\n");
        return 1;
    }
    int64_t rows = dim == 1 ? n : n * n;
    if (r0 < 0 || r1 < r0 || r1 > rows) {
        fprintf(stderr, "diff_shifted_laplacian: rows [%lld, %lld) are not within [0, %lld)\n",
                (long long)r0, (long long)r1, (long long)rows);
        return 1;
    }
    int64_t m = r1 - r0;
    /* At least one entry each, so that an empty block (a rank with no rows)
     * is not mistaken for a failed allocation. */
    int64_t cap = m * (2 * dim + 1) + 1;
    int64_t *rowptr = malloc((size_t)(m + 1) * sizeof *rowptr);
    int64_t *colind = malloc((size_t)cap * sizeof *colind);
    double *val = malloc((size_t)cap * sizeof *val);
    if (!rowptr || !colind || !val) {
        free(rowptr), free(colind), free(val);
        fprintf(stderr, "diff_shifted_laplacian: out of memory for %lld rows\n", (long long)m);
        return 1;
    }
    /* Neighbours in increasing column order, so every CSR row comes out sorted:
     * (i, j-1), (i-1, j), (i, j), (i+1, j), (i, j+1).  Column indices are
     * global (a block of rows of the whole matrix). */
    double off = c / (h * h), diag = 1.0 - 2.0 * dim * off;
    int64_t nz = 0;
    for (int64_t k = r0; k < r1; k++) {
        int64_t i = k % n, j = k / n;
        rowptr[k - r0] = nz;
        if (dim == 2 && j > 0) colind[nz] = k - n, val[nz++] = off;
        if (i > 0) colind[nz] = k - 1, val[nz++] = off;
        colind[nz] = k, val[nz++] = diag;
        if (i < n - 1) colind[nz] = k + 1, val[nz++] = off;
        if (dim == 2 && j < n - 1) colind[nz] = k + n, val[nz++] = off;
    }
    rowptr[m] = nz;
    int rc = silc_envelope_csr(out, m, rows, rowptr, colind, val);
    free(rowptr), free(colind), free(val);
    return rc;
}

int diff_run(int dim, int64_t n, int steps, double dt, double *u0)
{
    /* The seeds' loop: the matrices go in once, u lives inside SILC between
     * steps, and only the final field comes back.  A keeps its id, so it is
     * factored on the first step and the factorization is reused after.  The
     * 1-D step is written as two statements to show several per EXEC; it
     * computes the same thing. */
    const char *step = dim == 1 ? "b = B * u; u = A \\ b" : "u = A \\ (B * u)";
    double h = dim == 1 ? diff1d_h(n) : diff2d_h(n);
    int64_t len = dim == 1 ? n : n * n;
    silc_envelope_t A = {0}, B = {0}, u = {0};
    int rc = diff_shifted_laplacian(dim, n, h, -dt / 2, &A)
          || diff_shifted_laplacian(dim, n, h, dt / 2, &B)
          || silc_envelope_vector(&u, len, u0);

    if (!rc) rc = SILC_PUT("A", &A) || SILC_PUT("B", &B) || SILC_PUT("u", &u);
    for (int s = 0; s < steps && !rc; s++)
        rc = SILC_EXEC(step);
    silc_envelope_free(&u);
    if (!rc) rc = SILC_GET(&u, "u");
    if (!rc && (silc_envelope_rows(&u) != len || silc_envelope_cols(&u) != 1)) {
        fprintf(stderr, "diff_run: 'u' came back %lldx%lld, expected %lldx1\n",
                (long long)silc_envelope_rows(&u), (long long)silc_envelope_cols(&u),
                (long long)len);
        rc = 1;
    }
    if (!rc) rc = silc_envelope_to_dense(&u, u0);
    silc_envelope_free(&A), silc_envelope_free(&B), silc_envelope_free(&u);
    return rc;
}

double diff1d_h(int64_t n)
{
    return pi / (double)(n + 1);
}

void diff1d_initial(int64_t n, double *u)
{
    double h = diff1d_h(n);
    for (int64_t i = 0; i < n; i++) u[i] = sin((double)(i + 1) * h);
}

double diff1d_max_error(int64_t n, double t, const double *u)
{
    double h = diff1d_h(n), decay = exp(-t), err = 0;
    for (int64_t i = 0; i < n; i++) {
        double e = fabs(u[i] - decay * sin((double)(i + 1) * h));
        if (e > err || e != e) err = e; /* a NaN must not hide behind the max */
    }
    return err;
}

double diff2d_h(int64_t n)
{
    return 1.0 / (double)(n + 1);
}

void diff2d_initial(int64_t n, double *u)
{
    diff2d_initial_rows(n, 0, n * n, u);
}

void diff2d_initial_rows(int64_t n, int64_t r0, int64_t r1, double *u)
{
    double h = diff2d_h(n);
    for (int64_t k = r0; k < r1; k++) {
        int64_t i = k % n, j = k / n;
        double x = (double)(i + 1) * h, y = (double)(j + 1) * h;
        u[k - r0] = (x > 0.4 && x < 0.6 && y > 0.4 && y < 0.6) ? 1.0 : 0.0;
    }
}

double diff2d_heat(int64_t n, const double *u)
{
    double h = diff2d_h(n), s = 0;
    for (int64_t k = 0; k < n * n; k++) s += u[k];
    return s * h * h;
}

int diff_parse_num(const char *prog, const char *opt, const char *s, double lo, double hi,
                   int integer, double *out)
{
    char *end;
    double v = s ? strtod(s, &end) : 0;
    if (!s || end == s || *end || !(v >= lo && v <= hi) || (integer && v != floor(v))) {
        fprintf(stderr, "%s: %s needs %s in [%g, %g], got '%s'\n", prog, opt,
                integer ? "an integer" : "a number", lo, hi, s ? s : "");
        return 1;
    }
    *out = v;
    return 0;
}

int diff2d_write_pgm(const char *prog, const char *path, int64_t n, const double *u, double umax)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        fprintf(stderr, "%s: cannot write '%s'\n", prog, path);
        return 1;
    }
    unsigned char *row = malloc((size_t)n);
    int rc = !row || fprintf(f, "P5\n%lld %lld\n255\n", (long long)n, (long long)n) < 0;
    for (int64_t j = n - 1; j >= 0 && !rc; j--) {
        for (int64_t i = 0; i < n; i++) {
            double v = umax > 0 ? u[i + j * n] / umax : 0;
            row[i] = (unsigned char)lround(255.0 * (v < 0 ? 0 : v > 1 ? 1 : v));
        }
        rc = fwrite(row, 1, (size_t)n, f) != (size_t)n;
    }
    free(row);
    if (fclose(f) || rc) {
        fprintf(stderr, "%s: error writing '%s'\n", prog, path);
        return 1;
    }
    return 0;
}
