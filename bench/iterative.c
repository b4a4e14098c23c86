/*
 * iterative.c -- the iterative solvers' speed/accuracy trade.
 *
 *     iterative [--docs DIR] [--grid K]
 *
 * Part 1, kernel: the CSR SpMV of plugin-lis-style (its own lis_kernels.c,
 * compiled into this program) on the 5-point Laplacian of a K x K grid
 * (default 500, 250000 unknowns, 1.25M nonzeros), in GFLOP/s and in GB/s of
 * the minimal traffic (values and column indices 16 bytes per nonzero, row
 * pointers, x read once, y written once), next to the STREAM triad bandwidth
 * a[i] = b[i] + s c[i] measured in the same run with the same threads (24
 * bytes per entry, arrays of 20M doubles).  The target is SpMV at >= 70% of
 * the triad bandwidth; a figure above 100% means the matrix stayed in cache.
 * The 1000 x 1000 Laplacian (5M nonzeros, ~100 MB) is timed too, as the
 * out-of-cache check.
 *
 * Part 2, through SILC: x = A \ b for the K x K Laplacian with b = A * ones,
 * by lis-style CG + IC(0), CG + SA-AMG and BiCGSTAB + ILU(0) at -tol 1e-4,
 * 1e-8, 1e-12,
 * next to the direct sparse Cholesky of the reference plugin and CHOLMOD, and
 * PETSc CG + hypre BoomerAMG and CG + GAMG when the "petsc" plugin is loaded
 * (rows that fail are skipped with the reason), with `set tune.threads` to
 * the OpenMP thread count of part 1.  A is PUT afresh before every
 * run, so every time includes building the preconditioner or the factors
 * (each row is the best of two runs);
 * the backward error is the core's ||b - A x|| / (||A|| ||x|| + ||b||) from
 * `info x`.  Prints a table and writes DIR/iterative.svg (time against
 * achieved backward error, log-log) and DIR/iterative.md (the table); DIR
 * defaults to the source tree's docs/.  Both files name the command that made
 * them.  Not run by the test suite.
 */
#define _POSIX_C_SOURCE 200809L
#include "progress.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "lis_kernels.h"
#include "silc.h"

#ifndef SILC_SOURCE_DIR
#define SILC_SOURCE_DIR "."
#endif

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* 5-point Laplacian of a k x k grid, CSR. */
typedef struct csr {
    int64_t n, *rp, *ci;
    double *v;
} csr;

static int laplacian(csr *A, int64_t k)
{
    int64_t n = k * k, nz = 0;
    A->n = n;
    A->rp = malloc((size_t)(n + 1) * sizeof *A->rp);
    A->ci = malloc((size_t)(5 * n) * sizeof *A->ci);
    A->v = malloc((size_t)(5 * n) * sizeof *A->v);
    if (!A->rp || !A->ci || !A->v) return -1;
    for (int64_t r = 0; r < n; r++) {
        int64_t i = r / k, j = r % k;
        A->rp[r] = nz;
        if (i > 0) A->ci[nz] = r - k, A->v[nz++] = -1;
        if (j > 0) A->ci[nz] = r - 1, A->v[nz++] = -1;
        A->ci[nz] = r, A->v[nz++] = 4;
        if (j < k - 1) A->ci[nz] = r + 1, A->v[nz++] = -1;
        if (i < k - 1) A->ci[nz] = r + k, A->v[nz++] = -1;
    }
    A->rp[n] = nz;
    return 0;
}

static void csr_free(csr *A)
{
    free(A->rp);
    free(A->ci);
    free(A->v);
}

/* ---- part 1: SpMV against STREAM triad -------------------------------------------- */

static double stream_triad(int64_t n, int reps)
{
    double *a = malloc((size_t)n * sizeof *a), *b = malloc((size_t)n * sizeof *b),
           *c = malloc((size_t)n * sizeof *c), best = 1e30, s = 3.0;
    int64_t i;
    if (!a || !b || !c) {
        free(a), free(b), free(c);
        return -1;
    }
#pragma omp parallel for schedule(static)
    for (i = 0; i < n; i++) a[i] = 0, b[i] = 1, c[i] = 2; /* first touch by the same threads */
    for (int r = 0; r < reps; r++) {
        double t = now();
#pragma omp parallel for schedule(static)
        for (i = 0; i < n; i++) a[i] = b[i] + s * c[i];
        t = now() - t;
        if (t < best) best = t;
    }
    if (a[n / 2] != 7.0) fprintf(stderr, "stream: wrong result\n");
    free(a), free(b), free(c);
    return 24.0 * (double)n / best / 1e9;
}

typedef struct spmv_rate {
    double seconds, gflops, gbytes;
} spmv_rate;

static spmv_rate spmv(const csr *M, int reps)
{
    lk_csr A = {M->n, M->n, M->rp, M->ci, M->v};
    double *x = malloc((size_t)M->n * sizeof *x), *y = malloc((size_t)M->n * sizeof *y), best = 1e30;
    int64_t nnz = M->rp[M->n];
    spmv_rate r = {0, 0, 0};
    if (!x || !y) {
        free(x), free(y);
        return r;
    }
    lk_zero(M->n, y);
    for (int64_t i = 0; i < M->n; i++) x[i] = 1.0;
    lk_spmv(&A, x, y); /* warm-up, first touch of y */
    for (int k = 0; k < reps; k++) {
        double t = now();
        lk_spmv(&A, x, y);
        t = now() - t;
        if (t < best) best = t;
    }
    r.seconds = best;
    r.gflops = 2.0 * (double)nnz / best / 1e9;
    r.gbytes = (16.0 * (double)nnz + 8.0 * (double)(M->n + 1) + 16.0 * (double)M->n) / best / 1e9;
    free(x), free(y);
    return r;
}

/* ---- part 2: through SILC ---------------------------------------------------------------- */

typedef struct row {
    char series[64];            /* one line of the plot */
    char config[160];
    double tol;                 /* 0 for direct */
    double seconds, backward_error, iterations;
    int ok;
    char why[200];
} row;

static char info_buf[8192];

static void capture(void *user, const char *text)
{
    size_t have = strlen(info_buf);
    (void)user;
    snprintf(info_buf + have, sizeof info_buf - have, "%s", text);
}

static double info_number(const char *label)
{
    const char *p = strstr(info_buf, label);
    return p ? atof(p + strlen(label)) : -1;
}

/* Best of two runs: this machine is shared, and one descheduled OpenMP
 * thread can stretch a run of barrier-heavy iterations many times over. */
static progress bar; /* on stderr while the bench runs, when it is a terminal */

static void run(silc_context *c, const silc_envelope_t *A, row *r)
{
    char cmd[320];
    progress_show(&bar, "iterative: %s", r->config);
    r->ok = 0;
    snprintf(cmd, sizeof cmd, "x = solve(A, b, \"%s\")", r->config);
    for (int rep = 0; rep < 2; rep++) {
        double t;
        /* cleared first: a PUT of what A holds would keep it, preconditioner and all */
        if (silc_exec(c, "clear A") || silc_put(c, "A", A) || silc_exec(c, "b = A * ones(rows(A), 1)")) {
            snprintf(r->why, sizeof r->why, "%s", silc_context_errmsg(c));
            progress_done(&bar);
            return;
        }
        t = now();
        if (silc_exec(c, cmd)) {
            snprintf(r->why, sizeof r->why, "%s", silc_context_errmsg(c));
            progress_done(&bar);
            return;
        }
        t = now() - t;
        if (!r->ok || t < r->seconds) r->seconds = t;
        info_buf[0] = '\0';
        silc_exec(c, "info x");
        r->backward_error = info_number("backward error: ");
        r->iterations = info_number("iterations: ");
        r->ok = 1;
    }
    progress_done(&bar);
}

/* ---- the plot ------------------------------------------------------------------------------ */

/* s with XML's special characters escaped. */
static void xml_puts(FILE *f, const char *s)
{
    for (; *s; s++) {
        if (*s == '&') fputs("&amp;", f);
        else if (*s == '<') fputs("&lt;", f);
        else if (*s == '>') fputs("&gt;", f);
        else if (*s == '"') fputs("&quot;", f);
        else fputc(*s, f);
    }
}

static void write_svg(const char *path, const row *rows, int nrows, const char *title,
                      const char *command)
{
    static const char *const colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e",
                                          "#8c564b", "#17becf"};
    const double W = 760, H = 480, L = 80, R = 230, T = 50, B = 70;
    double emin = 1e-18, emax = 1e-2, tmin = 1e30, tmax = 0;
    char series[8][64];
    int ns = 0, i, s;
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "iterative: cannot write %s\n", path);
        return;
    }
    for (i = 0; i < nrows; i++) {
        if (!rows[i].ok) continue;
        if (rows[i].seconds < tmin) tmin = rows[i].seconds;
        if (rows[i].seconds > tmax) tmax = rows[i].seconds;
        for (s = 0; s < ns && strcmp(series[s], rows[i].series); s++) {}
        if (s == ns && ns < 8) memcpy(series[ns++], rows[i].series, sizeof series[0]);
    }
    if (tmax <= 0) tmin = 1e-3, tmax = 1;
    tmin = pow(10, floor(log10(tmin)));
    tmax = pow(10, ceil(log10(tmax)));
    if (tmax <= tmin) tmax = tmin * 10;
#define PX(e) (L + (log10(e) - log10(emin)) / (log10(emax) - log10(emin)) * (W - L - R))
#define PY(t) (H - B - (log10(t) - log10(tmin)) / (log10(tmax) - log10(tmin)) * (H - T - B))
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%g\" height=\"%g\" "
               "font-family=\"sans-serif\" font-size=\"12\">\n", W, H);
    fputs("<desc>made by: ", f);
    xml_puts(f, command);
    fputs("</desc>\n", f);
    fprintf(f, "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n");
    fprintf(f, "<text x=\"%g\" y=\"24\" font-size=\"15\">", L);
    xml_puts(f, title);
    fputs("</text>\n", f);
    for (double e = emin; e <= emax * 1.01; e *= 100) {
        fprintf(f, "<line x1=\"%.1f\" y1=\"%g\" x2=\"%.1f\" y2=\"%g\" stroke=\"#ddd\"/>\n", PX(e), T, PX(e), H - B);
        fprintf(f, "<text x=\"%.1f\" y=\"%g\" text-anchor=\"middle\">1e%d</text>\n", PX(e), H - B + 16,
                (int)lround(log10(e)));
    }
    for (double t = tmin; t <= tmax * 1.01; t *= 10) {
        fprintf(f, "<line x1=\"%g\" y1=\"%.1f\" x2=\"%g\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", L, PY(t), W - R, PY(t));
        fprintf(f, "<text x=\"%g\" y=\"%.1f\" text-anchor=\"end\">%g s</text>\n", L - 6, PY(t) + 4, t);
    }
    fprintf(f, "<rect x=\"%g\" y=\"%g\" width=\"%g\" height=\"%g\" fill=\"none\" stroke=\"black\"/>\n", L, T,
            W - L - R, H - T - B);
    fprintf(f, "<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">achieved backward error "
               "||b - Ax|| / (||A|| ||x|| + ||b||)</text>\n", (L + W - R) / 2, H - B + 36);
    fprintf(f, "<text x=\"18\" y=\"%g\" transform=\"rotate(-90 18 %g)\" text-anchor=\"middle\">wall time "
               "(s, includes setup)</text>\n", (T + H - B) / 2, (T + H - B) / 2);
    for (s = 0; s < ns; s++) {
        const char *col = colours[s % 7];
        int first = 1;
        fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\" points=\"", col);
        for (i = 0; i < nrows; i++)
            if (rows[i].ok && !strcmp(rows[i].series, series[s]) && rows[i].backward_error > 0) {
                double e = rows[i].backward_error < emin ? emin : rows[i].backward_error;
                fprintf(f, "%s%.1f,%.1f", first ? "" : " ", PX(e), PY(rows[i].seconds));
                first = 0;
            }
        fprintf(f, "\"/>\n");
        for (i = 0; i < nrows; i++)
            if (rows[i].ok && !strcmp(rows[i].series, series[s]) && rows[i].backward_error > 0) {
                double e = rows[i].backward_error < emin ? emin : rows[i].backward_error;
                fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4\" fill=\"%s\"><title>", PX(e),
                        PY(rows[i].seconds), col);
                xml_puts(f, rows[i].config);
                fprintf(f, ": %.3g s, backward error %.2g</title></circle>\n", rows[i].seconds,
                        rows[i].backward_error);
                if (rows[i].tol > 0)
                    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" fill=\"%s\">tol %g</text>\n",
                            PX(e) + 6, PY(rows[i].seconds) - 6, col, rows[i].tol);
            }
        fprintf(f, "<circle cx=\"%g\" cy=\"%d\" r=\"4\" fill=\"%s\"/><text x=\"%g\" y=\"%d\">",
                W - R + 16, (int)T + 10 + 20 * s, col, W - R + 26, (int)T + 14 + 20 * s);
        xml_puts(f, series[s]);
        fputs("</text>\n", f);
    }
    fprintf(f, "<text x=\"%g\" y=\"%g\" font-size=\"10\" fill=\"#555\">made by: ", L, H - 12);
    xml_puts(f, command);
    fputs("</text>\n", f);
    fprintf(f, "</svg>\n");
#undef PX
#undef PY
    fclose(f);
}

int main(int argc, char **argv)
{
    const char *docs = SILC_SOURCE_DIR "/docs";
    int64_t k = 500;
    char command[1024], cwd[512], path[1024], title[160], part1[1024];
    csr M, Mbig;
    silc_context *c = NULL;
    silc_envelope_t A;
    row rows[32];
    int nrows = 0, i, nthreads = lk_threads();
    size_t u;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--docs") && i + 1 < argc) docs = argv[++i];
        else if (!strcmp(argv[i], "--grid") && i + 1 < argc) k = atoll(argv[++i]);
        else {
            fprintf(stderr, "usage: %s [--docs DIR] [--grid K]\n", argv[0]);
            return 2;
        }
    }
    if (!getcwd(cwd, sizeof cwd)) snprintf(cwd, sizeof cwd, ".");
    u = (size_t)snprintf(command, sizeof command, "(cd %s && %s", cwd, argv[0]);
    for (i = 1; i < argc && u < sizeof command; i++)
        u += (size_t)snprintf(command + u, sizeof command - u, " %s", argv[i]);
    if (u < sizeof command) snprintf(command + u, sizeof command - u, ")");
    printf("command: %s\n\n", command);

    /* Part 1. */
    if (laplacian(&M, k) || laplacian(&Mbig, 1000)) {
        fprintf(stderr, "iterative: out of memory\n");
        return 1;
    }
    {
        double bw = stream_triad(20 * 1000 * 1000, 30);
        spmv_rate r = spmv(&M, 50), rb = spmv(&Mbig, 20);
        snprintf(part1, sizeof part1,
                 "SpMV of plugin-lis-style's kernel, %d thread(s): STREAM triad %.2f GB/s; "
                 "%lldx%lld Laplacian (%lld nnz) %.3f ms, %.2f GFLOP/s, %.2f GB/s = %.0f%% of triad; "
                 "1000x1000 Laplacian (%lld nnz, ~100 MB) %.3f ms, %.2f GFLOP/s, %.2f GB/s = %.0f%% of triad.",
                 lk_threads(), bw, (long long)k, (long long)k, (long long)M.rp[M.n], r.seconds * 1e3,
                 r.gflops, r.gbytes, 100 * r.gbytes / bw, (long long)Mbig.rp[Mbig.n], rb.seconds * 1e3,
                 rb.gflops, rb.gbytes, 100 * rb.gbytes / bw);
        printf("Part 1: SpMV (plugin-lis-style kernel) vs STREAM triad, %d thread(s)\n", lk_threads());
        printf("  STREAM triad bandwidth:                %7.2f GB/s\n", bw);
        printf("  SpMV %4lldx%-4lld Laplacian (%lld nnz): %7.3f ms  %6.2f GFLOP/s  %6.2f GB/s  = %3.0f%% of triad\n",
               (long long)k, (long long)k, (long long)M.rp[M.n], r.seconds * 1e3, r.gflops, r.gbytes,
               100 * r.gbytes / bw);
        printf("  SpMV 1000x1000 Laplacian (%lld nnz):   %7.3f ms  %6.2f GFLOP/s  %6.2f GB/s  = %3.0f%% of triad\n\n",
               (long long)Mbig.rp[Mbig.n], rb.seconds * 1e3, rb.gflops, rb.gbytes, 100 * rb.gbytes / bw);
    }
    csr_free(&Mbig);

    /* Part 2. */
    if (silc_open(&c, NULL)) {
        fprintf(stderr, "silc_open: %s\n", c ? silc_context_errmsg(c) : silc_errmsg());
        return 1;
    }
    silc_set_output(c, capture, NULL);
    /* The same threads as part 1 (the engine's default budget may be smaller). */
    snprintf(path, sizeof path, "set tune.threads = %d", nthreads);
    if (silc_exec(c, path)) fprintf(stderr, "%s: %s\n", path, silc_context_errmsg(c));
    if (silc_envelope_csr(&A, M.n, M.n, M.rp, M.ci, M.v)) return 1;
    csr_free(&M);
    {
        static const double tols[] = {1e-4, 1e-8, 1e-12};
        static const struct {
            const char *series, *fmt;
        } it[] = {
            {"lis-style CG + IC(0)", "backend = lis-style; lis-style.options = -i cg -p ic -tol %g -maxiter 100000"},
            {"lis-style CG + SA-AMG", "backend = lis-style; lis-style.options = -i cg -p saamg -tol %g -maxiter 100000"},
            {"lis-style BiCGSTAB + ILU(0)", "backend = lis-style; lis-style.options = -i bicgstab -p ilu -tol %g -maxiter 100000"},
            {"PETSc CG + hypre", "backend = petsc; petsc.options = -ksp_type cg -pc_type hypre -ksp_rtol %g -ksp_max_it 100000"},
            {"PETSc CG + GAMG", "backend = petsc; petsc.options = -ksp_type cg -pc_type gamg -ksp_rtol %g -ksp_max_it 100000"},
        };
        static const struct {
            const char *series, *config;
        } direct[] = {
            {"reference sparse Cholesky", "backend = reference"},
            {"CHOLMOD (suitesparse)", "backend = suitesparse.cholmod"},
        };
        for (size_t d = 0; d < sizeof direct / sizeof *direct; d++) {
            row *r = &rows[nrows++];
            memset(r, 0, sizeof *r);
            snprintf(r->series, sizeof r->series, "%s", direct[d].series);
            snprintf(r->config, sizeof r->config, "%s", direct[d].config);
            run(c, &A, r);
        }
        for (size_t s = 0; s < sizeof it / sizeof *it; s++)
            for (size_t t = 0; t < 3; t++) {
                row *r = &rows[nrows++];
                memset(r, 0, sizeof *r);
                snprintf(r->series, sizeof r->series, "%s", it[s].series);
                snprintf(r->config, sizeof r->config, it[s].fmt, tols[t]);
                r->tol = tols[t];
                run(c, &A, r);
            }
    }
    snprintf(title, sizeof title, "x = A \\ b, 2-D Laplacian %lldx%lld (%lld unknowns), %d thread(s)",
             (long long)k, (long long)k, (long long)A.m, lk_threads());
    printf("Part 2: %s\n", title);
    printf("  %-30s %-8s %10s %12s %10s\n", "method", "tol", "time (s)", "backward err", "iterations");
    for (i = 0; i < nrows; i++) {
        const row *r = &rows[i];
        char tol[16] = "direct";
        if (r->tol > 0) snprintf(tol, sizeof tol, "%g", r->tol);
        if (r->ok)
            printf("  %-30s %-8s %10.3f %12.2e %10.0f\n", r->series, tol, r->seconds, r->backward_error,
                   r->iterations);
        else
            printf("  %-30s %-8s skipped: %.120s\n", r->series, tol, r->why);
    }
    snprintf(path, sizeof path, "%s/iterative.svg", docs);
    write_svg(path, rows, nrows, title, command);
    printf("\nwrote %s\n", path);
    snprintf(path, sizeof path, "%s/iterative.md", docs);
    {
        FILE *f = fopen(path, "w");
        if (f) {
            fprintf(f, "# Iterative solvers: speed against accuracy\n\n");
            fprintf(f, "Made by `bench/iterative` (bench/iterative.c): `%s`.\n\n", command);
            fprintf(f, "%s\n\n", part1);
            fprintf(f, "%s; b = A * ones; A is PUT afresh before each run (best of two), so times include the "
                       "preconditioner or factorization. Backward error is SILC's "
                       "||b - Ax|| / (||A|| ||x|| + ||b||). Plot: [iterative.svg](iterative.svg).\n\n", title);
            fprintf(f, "| method | tol | time (s) | backward error | iterations |\n|---|---|---|---|---|\n");
            for (i = 0; i < nrows; i++) {
                const row *r = &rows[i];
                char tol[16] = "direct";
                if (r->tol > 0) snprintf(tol, sizeof tol, "%g", r->tol);
                if (r->ok)
                    fprintf(f, "| %s | %s | %.3f | %.2e | %.0f |\n", r->series, tol, r->seconds,
                            r->backward_error, r->iterations);
                else
                    fprintf(f, "| %s | %s | skipped: %.100s | | |\n", r->series, tol, r->why);
            }
            fclose(f);
            printf("wrote %s\n", path);
        }
    }
    silc_envelope_free(&A);
    silc_close(&c);
    return 0;
}
