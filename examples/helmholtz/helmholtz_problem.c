/*
 * helmholtz_problem.c -- assembly and solve of the complex Helmholtz
 * problem (helmholtz.h says which problem and how it is discretized).
 */
#include "helmholtz.h"

#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The plane wave's boundary datum g = du/dn - i k u at (x, y) on the side
 * with outward normal (nx, ny): du/dx = i k u, du/dy = 0. */
static double complex plane_wave_g(double k, double x, double nx)
{
    double complex u = cexp(I * k * x);
    return I * k * u * nx - I * k * u;
}

/* The Gaussian source of HELMHOLTZ_SOURCE, centred, width 0.03. */
static double source_f(double x, double y)
{
    double r2 = (x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5);
    return 100.0 * exp(-r2 / (2 * 0.03 * 0.03));
}

int helmholtz_assemble(int n, double k, int problem, silc_envelope_t *A, double *b, char *err, size_t errlen)
{
    if (n < 2 || n > 4000 || !(k >= 0) || !isfinite(k)) {
        snprintf(err, errlen, "helmholtz: need 2 <= n <= 4000 and a finite k >= 0 (got n = %d, k = %g)", n, k);
        return -1;
    }
    int64_t N = n + 1, rows = N * N, cap = 5 * rows;
    double h = 1.0 / n;
    int64_t *rp = malloc((size_t)(rows + 1) * sizeof *rp), *ci = malloc((size_t)cap * sizeof *ci);
    double complex *v = malloc((size_t)cap * sizeof *v), *rhs = (double complex *)b;
    if (!rp || !ci || !v) {
        free(rp);
        free(ci);
        free(v);
        snprintf(err, errlen, "helmholtz: out of memory for n = %d", n);
        return -1;
    }
    int64_t nz = 0;
    rp[0] = 0;
    for (int64_t j = 0; j < N; j++)
        for (int64_t i = 0; i < N; i++) {
            int xb = i == 0 || i == n, yb = j == 0 || j == n; /* on an x side, a y side */
            double s = (xb ? 0.5 : 1.0) * (yb ? 0.5 : 1.0), x = (double)i * h, y = (double)j * h;
            double complex diag = s * (4.0 / (h * h) - k * k) - (double)(xb + yb) * s * 2.0 * I * k / h;
            double complex f = problem == HELMHOLTZ_SOURCE ? source_f(x, y) : 0.0, g = 0.0;
            if (problem == HELMHOLTZ_PLANE_WAVE) { /* sum of g over the ghost sides */
                if (i == 0) g += plane_wave_g(k, x, -1.0);
                if (i == n) g += plane_wave_g(k, x, 1.0);
                if (j == 0 || j == n) g += plane_wave_g(k, x, 0.0);
            }
            rhs[i + j * N] = s * f + s * (2.0 / h) * g;
            /* the neighbours in column order: (i, j-1), (i-1, j), (i, j), (i+1, j), (i, j+1);
             * a neighbour whose mirror is a ghost point counts twice */
            if (j > 0) ci[nz] = i + (j - 1) * N, v[nz++] = -s / (h * h) * (j == n ? 2.0 : 1.0);
            if (i > 0) ci[nz] = i - 1 + j * N, v[nz++] = -s / (h * h) * (i == n ? 2.0 : 1.0);
            ci[nz] = i + j * N, v[nz++] = diag;
            if (i < n) ci[nz] = i + 1 + j * N, v[nz++] = -s / (h * h) * (i == 0 ? 2.0 : 1.0);
            if (j < n) ci[nz] = i + (j + 1) * N, v[nz++] = -s / (h * h) * (j == 0 ? 2.0 : 1.0);
            rp[i + j * N + 1] = nz;
        }
    int rc = silc_envelope_csr_complex(A, rows, rows, rp, ci, (const double *)v);
    if (rc) snprintf(err, errlen, "helmholtz: %s", silc_errmsg());
    free(rp);
    free(ci);
    free(v);
    return rc ? -1 : 0;
}

int helmholtz_solve(silc_context *c, int n, double k, int problem, double *u, char *err, size_t errlen)
{
    int64_t rows = (int64_t)(n + 1) * (n + 1);
    silc_envelope_t A, be, ue;
    double *b = malloc((size_t)(2 * rows) * sizeof *b);
    int rc = -1;
    if (!b) {
        snprintf(err, errlen, "helmholtz: out of memory for n = %d", n);
        return -1;
    }
    if (helmholtz_assemble(n, k, problem, &A, b, err, errlen)) {
        free(b);
        return -1;
    }
    if (silc_envelope_dense_complex(&be, rows, 1, b)) {
        snprintf(err, errlen, "helmholtz: %s", silc_errmsg());
        silc_envelope_free(&A);
        free(b);
        return -1;
    }
    /* The core's check of a complex solution's backward error is being made
     * complex-aware on the complex-core branch (issue 31); until then it is
     * switched off here and the program checks the error itself. */
    if (silc_put(c, "A", &A) || silc_put(c, "b", &be) || silc_exec(c, "set solve.verify = off; u = A \\ b") ||
        silc_get_complex(c, &ue, "u")) {
        snprintf(err, errlen, "helmholtz: %s", silc_context_errmsg(c));
    } else {
        if (silc_envelope_is_complex(&ue) && ue.m == rows && ue.n == 1) {
            memcpy(u, ue.values, (size_t)(2 * rows) * sizeof *u);
            rc = 0;
        } else {
            snprintf(err, errlen, "helmholtz: u came back %lldx%lld, %s", (long long)ue.m, (long long)ue.n,
                     silc_envelope_is_complex(&ue) ? "complex" : "real");
        }
        silc_envelope_free(&ue);
    }
    silc_envelope_free(&A);
    silc_envelope_free(&be);
    free(b);
    return rc;
}

double helmholtz_plane_wave_error(int n, double k, const double *u)
{
    int64_t N = n + 1;
    const double complex *z = (const double complex *)u;
    double e = 0.0;
    for (int64_t j = 0; j < N; j++)
        for (int64_t i = 0; i < N; i++) e = fmax(e, cabs(z[i + j * N] - cexp(I * k * (double)i / n)));
    return e;
}
