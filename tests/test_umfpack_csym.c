/*
 * test_umfpack_csym.c -- suitesparse.umfpack solves a complex symmetric
 * A (A = A.') as UMFPACK_A, not UMFPACK_Aat (plugin-suitesparse
 * ss_complex.c, umz_system): the same system, but UMFPACK refines the
 * row-scaled system it factored instead of the unscaled transpose, which
 * takes one refinement solve less on the bench's Helmholtz matrix.
 *
 * Checked against UMFPACK called here directly on the very arrays SILC
 * stores (fetched back with silc_get), on complex symmetric matrices that
 * stress scaling and refinement: the Helmholtz operator of
 * examples/helmholtz, the same scaled as D A D with D spanning 1e-6..1e6,
 * and shared real symmetric matrices given a complex diagonal shift
 * (bcsstk13, entries 7e-24..1e12; hangGlider_2, indefinite; sherman1):
 *   - SILC's x is the direct UMFPACK_A solve's x (the path it takes);
 *   - its backward error ||b - A x||_1 / (||A||_1 ||x||_1 + ||b||_1) is no
 *     worse than the old path's (UMFPACK_Aat, same control) beyond a factor
 *     of 2: both are 1e-19..1e-16 here, rounding level, where either path
 *     wins by a few per cent (hangGlider_2: 8.1e-19 against 7.6e-19); a
 *     lost refinement step on a badly scaled matrix costs orders of
 *     magnitude, not a factor of 2;
 * and that a complex A that is not symmetric (young1c) still takes
 * UMFPACK_Aat: SILC's x is the direct UMFPACK_Aat solve's x, and solves
 * A x = b (backward error at rounding level).
 */
#define _POSIX_C_SOURCE 200809L
#include <complex.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <umfpack.h>

#include "helmholtz.h"
#include "silc.h"

static int failures, passes;

#define CHECK(cond, ...)                                                                                              \
    do {                                                                                                              \
        if (cond) {                                                                                                   \
            passes++;                                                                                                 \
        } else {                                                                                                      \
            failures++;                                                                                               \
            fprintf(stderr, "%s:%d: FAIL: ", __FILE__, __LINE__);                                                     \
            fprintf(stderr, __VA_ARGS__);                                                                             \
            fprintf(stderr, "\n");                                                                                    \
        }                                                                                                             \
    } while (0)

/* ||b - A x||_1 / (||A||_1 ||x||_1 + ||b||_1), moduli of complex entries. */
static double backward_error(const silc_envelope_t *A, const double complex *x, const double complex *b)
{
    const double complex *v = (const double complex *)A->values;
    double r = 0, nx = 0, nb = 0, na = 0;
    double *colsum = calloc((size_t)A->n, sizeof *colsum);
    if (!colsum) return INFINITY;
    for (int64_t i = 0; i < A->m; i++) {
        double complex s = b[i];
        for (int64_t p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) {
            s -= v[p] * x[A->colind[p]];
            colsum[A->colind[p]] += cabs(v[p]);
        }
        r += cabs(s);
        nb += cabs(b[i]);
    }
    for (int64_t j = 0; j < A->n; j++) {
        nx += cabs(x[j]);
        if (colsum[j] > na) na = colsum[j];
    }
    free(colsum);
    return r / (na * nx + nb);
}

/* UMFPACK's solve of sys with A's CSR arrays as the compressed columns of
 * M = A.' (as the plugin hands them), default control: what the plugin did
 * before (UMFPACK_Aat) and does now for A = A.' (UMFPACK_A). */
static int umfpack_direct(const silc_envelope_t *A, const double complex *b, long sys, double complex *x)
{
    double control[UMFPACK_CONTROL], info[UMFPACK_INFO];
    void *sym = NULL, *num = NULL;
    int st;
    umfpack_zl_defaults(control);
    st = (int)umfpack_zl_symbolic(A->n, A->n, A->rowptr, A->colind, A->values, NULL, &sym, control, info);
    if (!st) st = (int)umfpack_zl_numeric(A->rowptr, A->colind, A->values, NULL, sym, &num, control, info);
    if (!st)
        st = (int)umfpack_zl_solve(sys, A->rowptr, A->colind, A->values, NULL, (double *)x, NULL,
                                   (const double *)b, NULL, num, control, info);
    umfpack_zl_free_symbolic(&sym);
    umfpack_zl_free_numeric(&num);
    return st;
}

static double max_diff(int64_t n, const double complex *x, const double complex *y)
{
    double d = 0;
    for (int64_t i = 0; i < n; i++)
        if (cabs(x[i] - y[i]) > d) d = cabs(x[i] - y[i]);
    return d;
}

/* Solves A x = b through SILC (suitesparse.umfpack only) and checks it
 * against the direct calls; A (complex CSR, owned) is replaced by the
 * value SILC stores. */
static void check(const char *name, silc_envelope_t *A, int symmetric)
{
    int64_t n = A->n;
    silc_context *c = NULL;
    silc_envelope_t Eb, Ex, As;
    double complex *b = malloc((size_t)n * sizeof *b), *xt = malloc((size_t)n * sizeof *xt),
                   *x = malloc((size_t)n * sizeof *x), *xa = malloc((size_t)n * sizeof *xa),
                   *xat = malloc((size_t)n * sizeof *xat);
    double be, be_a, be_at, scale = 0;
    if (!b || !xt || !x || !xa || !xat) {
        CHECK(0, "%s: out of memory", name);
        goto out;
    }
    /* x_true with entries of modulus ~1, b = A x_true */
    for (int64_t i = 0; i < n; i++) xt[i] = cos(0.37 * (double)i) + I * sin(1.3 * (double)i + 0.2);
    for (int64_t i = 0; i < n; i++) {
        b[i] = 0;
        for (int64_t p = A->rowptr[i]; p < A->rowptr[i + 1]; p++)
            b[i] += ((const double complex *)A->values)[p] * xt[A->colind[p]];
    }
    if (silc_envelope_dense_complex(&Eb, n, 1, (const double *)b) || silc_open(&c, NULL) || silc_put(c, "A", A) ||
        silc_put(c, "b", &Eb) || silc_exec(c, "set dispatch.solve.sparse = suitesparse.umfpack") ||
        silc_exec(c, "x = A \\ b;") || silc_get_complex(c, &Ex, "x") || silc_envelope_to_dense(&Ex, (double *)x) ||
        silc_get_complex(c, &As, "A")) {
        CHECK(0, "%s: SILC: %s", name, c ? silc_context_errmsg(c) : silc_errmsg());
        if (c) silc_close(&c);
        silc_envelope_free(&Eb);
        goto out;
    }
    silc_envelope_free(&Ex);
    silc_envelope_free(&Eb);
    silc_close(&c);
    silc_envelope_free(A);
    *A = As;
    CHECK(umfpack_direct(A, b, UMFPACK_A, xa) == UMFPACK_OK, "%s: umfpack_zl UMFPACK_A failed", name);
    CHECK(umfpack_direct(A, b, UMFPACK_Aat, xat) == UMFPACK_OK, "%s: umfpack_zl UMFPACK_Aat failed", name);
    for (int64_t i = 0; i < n; i++)
        if (cabs(x[i]) > scale) scale = cabs(x[i]);
    be = backward_error(A, x, b);
    be_a = backward_error(A, xa, b);
    be_at = backward_error(A, xat, b);
    printf("%-28s n %6lld  backward error: SILC %.2e, UMFPACK_A %.2e, UMFPACK_Aat %.2e; "
           "|x - x_A| %.1e, |x - x_Aat| %.1e (|x| %.1e)\n",
           name, (long long)n, be, be_a, be_at, max_diff(n, x, xa), max_diff(n, x, xat), scale);
    if (symmetric) {
        CHECK(max_diff(n, x, xa) == 0, "%s: SILC's x is not UMFPACK_A's (differs by %.2e)", name,
              max_diff(n, x, xa));
        CHECK(be <= 2 * be_at, "%s: backward error %.3e worse than the old path's %.3e", name, be, be_at);
    } else {
        CHECK(max_diff(n, x, xat) == 0, "%s: SILC's x is not UMFPACK_Aat's (differs by %.2e)", name,
              max_diff(n, x, xat));
        CHECK(be <= 1e-15, "%s: backward error %.3e: A x = b not solved", name, be);
    }
out:
    free(b);
    free(xt);
    free(x);
    free(xa);
    free(xat);
}

/* A real symmetric shared matrix plus i * shift * |a_ii| on the diagonal:
 * complex symmetric, not Hermitian.  Returns 0 if the file is missing. */
static int shifted(const char *file, double shift, silc_envelope_t *A)
{
    char path[1024], err[512];
    silc_envelope_t R;
    double complex *v;
    int rc;
    snprintf(path, sizeof path, "%s/%s", SILC_SHARED_MATRICES, file);
    if (silc_mm_read(&R, path, err, sizeof err)) {
        CHECK(0, "%s: %s", file, err);
        return 0;
    }
    v = malloc((size_t)(R.nnz ? R.nnz : 1) * sizeof *v);
    if (!v) {
        silc_envelope_free(&R);
        return 0;
    }
    for (int64_t i = 0; i < R.m; i++)
        for (int64_t p = R.rowptr[i]; p < R.rowptr[i + 1]; p++)
            v[p] = R.values[p] + (R.colind[p] == i ? I * shift * fabs(R.values[p]) : 0);
    rc = silc_envelope_csr_complex(A, R.m, R.n, R.rowptr, R.colind, (const double *)v) == 0;
    silc_envelope_free(&R);
    free(v);
    return rc;
}

int main(void)
{
    silc_envelope_t A;
    char err[256];
    double *src = malloc(80 * 80 * 2 * sizeof(double));
    if (!src || SILC_INIT()) {
        fprintf(stderr, "test_umfpack_csym: cannot start: %s\n", silc_errmsg());
        return 1;
    }
    /* examples/helmholtz's operator on 80 x 80 vertices, k = 50 */
    if (helmholtz_assemble(79, 50, HELMHOLTZ_SOURCE, &A, src, err, sizeof err) == 0) {
        /* D A D, D_i = 10^((i mod 13) - 6): still complex symmetric, its
         * entries spread over 24 orders of magnitude */
        silc_envelope_t S;
        const double complex *v = (const double complex *)A.values;
        double complex *w = malloc((size_t)A.nnz * sizeof *w);
        int scaled = 0;
        if (w) {
            for (int64_t i = 0; i < A.m; i++)
                for (int64_t p = A.rowptr[i]; p < A.rowptr[i + 1]; p++)
                    /* d_i d_j first: the mirror's product rounds the same */
                    w[p] = v[p] * (pow(10, (double)(i % 13) - 6) * pow(10, (double)(A.colind[p] % 13) - 6));
            scaled = silc_envelope_csr_complex(&S, A.m, A.n, A.rowptr, A.colind, (const double *)w) == 0;
            free(w);
        }
        check("Helmholtz 80^2, k = 50", &A, 1);
        silc_envelope_free(&A);
        CHECK(scaled, "scaled Helmholtz: %s", silc_errmsg());
        if (scaled) check("D Helmholtz D, D 1e-6..1e6", &S, 1), silc_envelope_free(&S);
    } else {
        CHECK(0, "helmholtz_assemble: %s", err);
    }
    free(src);
    if (shifted("bcsstk13.mtx", 1e-2, &A)) check("bcsstk13 + 0.01i |diag|", &A, 1), silc_envelope_free(&A);
    if (shifted("hangGlider_2.mtx", 1e-2, &A)) check("hangGlider_2 + 0.01i |diag|", &A, 1), silc_envelope_free(&A);
    if (shifted("sherman1.mtx", 1e-2, &A)) check("sherman1 + 0.01i |diag|", &A, 1), silc_envelope_free(&A);
    {
        char path[1024];
        snprintf(path, sizeof path, "%s/young1c.mtx", SILC_SHARED_MATRICES);
        if (silc_mm_read(&A, path, err, sizeof err) == 0) check("young1c (not symmetric)", &A, 0), silc_envelope_free(&A);
        else CHECK(0, "young1c: %s", err);
    }
    printf("%d passed, %d failed\n", passes, failures);
    SILC_FINALIZE();
    return failures ? 1 : 0;
}
