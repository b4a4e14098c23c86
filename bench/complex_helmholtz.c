/*
 * complex_helmholtz.c -- a complex sparse solve through SILC against the
 * library called directly, SciPy and Octave, in one run (issue 31).
 *
 *   complex_helmholtz [--n N] [--k K] [--reps R] [--no-scipy] [--no-octave]
 *
 * The system is examples/helmholtz's (helmholtz.h): the 2-D Helmholtz
 * equation -Lap u - k^2 u = f on the unit square with the absorbing
 * boundary du/dn = i k u, 5-point stencil on an N x N grid of vertices
 * (default N = 500, 250000 unknowns, k = 50), a Gaussian source at the
 * centre; A is complex symmetric (A = A.'), not Hermitian.  The bench links
 * the example's assembly (silc_helmholtz), so both solve the same matrix.
 *
 * Rows (each the median of R runs, a fresh A each time so nothing is reused;
 * the library and the three SILC rows run in alternating rounds, and a SILC
 * row's ratio is the median of its round-by-round ratios to the library,
 * since the machine drifts more over the minutes of a run (15-20 %, measured)
 * than the differences this bench is for):
 *   UMFPACK direct    umfpack_zl_symbolic + numeric + solve, default
 *                     control (two refinement steps, as SILC's backend
 *                     asks too): what the library needs and nothing more,
 *                     the baseline of the ratios;
 *   SILC  x = A \ b   default dispatch (whatever backend the dispatcher
 *                     picks, named in the row), each run in a new context
 *                     (nothing reused: checked with info), PUT not timed;
 *                     the report's own work that the statement leaves for
 *                     later (a deferred condition estimate) is what the
 *                     first `info x` costs, in a column of its own;
 *                     again with accuracy.condest = now (the estimate at
 *                     solve time) and off (no estimate at all);
 *   SciPy spsolve     /usr/bin/python3, scipy.sparse.linalg.spsolve (SuperLU);
 *   Octave A\b        octave-cli, skipped when absent.
 * Times are CPU seconds of the process that solves (every solver runs
 * single-threaded here: OPENBLAS_NUM_THREADS=1), so the other jobs of a
 * shared machine do not count; each row also shows the relative residual
 * ||b - A x||_1 / ||b||_1.
 */
#define _POSIX_C_SOURCE 200809L
#include <complex.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <umfpack.h>

#include "helmholtz.h"
#include "silc.h"
#include "timing.h"

typedef struct csr {
    int64_t n, nnz;
    int64_t *rowptr, *colind;
    double complex *val;
} csr;

/* The Helmholtz matrix and source of examples/helmholtz on N x N vertices
 * (its n = N - 1 intervals), viewed as a csr (the envelope keeps the arrays). */
static int helmholtz(int64_t N, double k, silc_envelope_t *E, csr *A, double complex **b)
{
    char err[256];
    *b = malloc((size_t)(N * N) * sizeof **b);
    if (!*b || helmholtz_assemble((int)N - 1, k, HELMHOLTZ_SOURCE, E, (double *)*b, err, sizeof err)) {
        fprintf(stderr, "complex_helmholtz: %s\n", *b ? err : "out of memory");
        return -1;
    }
    A->n = E->m, A->nnz = E->nnz, A->rowptr = E->rowptr, A->colind = E->colind;
    A->val = (double complex *)E->values;
    return 0;
}

/* ||b - A x||_1 / ||b||_1 */
static double residual(const csr *A, const double complex *x, const double complex *b)
{
    double r = 0, nb = 0;
    for (int64_t i = 0; i < A->n; i++) {
        double complex s = b[i];
        for (int64_t p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) s -= A->val[p] * x[A->colind[p]];
        r += cabs(s);
        nb += cabs(b[i]);
    }
    return r / nb;
}

/* ---- SILC ---------------------------------------------------------------------- */

/* Collects what `info x` prints. */
static void collect(void *user, const char *text)
{
    size_t len = strlen(user);
    snprintf((char *)user + len, 2048 - len, "%s", text);
}

/* The value after "key: " in info's text, up to the line's end. */
static void info_field(const char *info, const char *key, char *out, size_t len)
{
    const char *p = strstr(info, key);
    size_t n = 0;
    out[0] = 0;
    if (!p) return;
    p += strlen(key);
    while (p[n] && p[n] != '\n') n++;
    snprintf(out, len, "%.*s", (int)n, p);
}

/* CPU seconds of this process (the solvers run single-threaded). */
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Each run in a context of its own, so no factorization or analysis of an
 * earlier run is reused (the store would hand an identical PUT the value
 * it already has); the PUTs are not timed.  condest: accuracy.condest's
 * value; *report: the median time of the first `info x` (the work the
 * statement left for the report). */
static double run_silc(const csr *A, const double complex *b, int reps, const char *condest, double *resid,
                       char *backend, size_t blen, double *report)
{
    silc_envelope_t EA, Eb, Ex;
    silc_context *c = NULL;
    double *t = calloc((size_t)reps, sizeof *t), *ti = calloc((size_t)reps, sizeof *ti), med;
    char set[64];
    double complex *x = malloc((size_t)A->n * sizeof *x);
    char info[2048] = "", name[64], reused[16];
    if (!t || !ti || !x) return -1;
    snprintf(set, sizeof set, "set accuracy.condest = %s", condest);
    if (silc_envelope_csr_complex(&EA, A->n, A->n, A->rowptr, A->colind, (const double *)A->val) ||
        silc_envelope_dense_complex(&Eb, A->n, 1, (const double *)b))
        goto fail;
    for (int r = 0; r < reps; r++) {
        double t0;
        if (silc_open(&c, NULL) || silc_put(c, "A", &EA) || silc_put(c, "b", &Eb) || silc_exec(c, set))
            goto fail;
        t0 = cpu_now();
        if (silc_exec(c, "x = A \\ b;")) goto fail;
        t[r] = cpu_now() - t0;
        info[0] = 0;
        silc_set_output(c, collect, info);
        t0 = cpu_now();
        if (silc_exec(c, "info x")) goto fail;
        ti[r] = cpu_now() - t0;
        info_field(info, "reused factorization: ", reused, sizeof reused);
        if (strcmp(reused, "no") != 0) {
            fprintf(stderr, "complex_helmholtz: run %d reused a factorization (info: '%s')\n", r, reused);
            goto fail;
        }
        if (r == reps - 1 && (silc_get_complex(c, &Ex, "x") || silc_envelope_to_dense(&Ex, (double *)x))) goto fail;
        if (r < reps - 1) silc_close(&c);
    }
    *resid = residual(A, x, b);
    info_field(info, "backend: ", name, sizeof name);
    snprintf(backend, blen, "%s, accuracy.condest = %s%s", name, condest,
             strstr(info, "computed when the report was first read") ? " (estimate deferred)" : "");
    silc_envelope_free(&Ex);
    silc_close(&c);
    silc_envelope_free(&EA);
    silc_envelope_free(&Eb);
    med = bench_median(t, reps);
    *report = bench_median(ti, reps);
    free(t);
    free(ti);
    free(x);
    return med;
fail:
    fprintf(stderr, "complex_helmholtz: SILC failed: %s\n", c ? silc_context_errmsg(c) : silc_errmsg());
    snprintf(backend, blen, "failed (message on stderr)");
    if (c) silc_close(&c);
    free(t);
    free(ti);
    free(x);
    return -1;
}

/* ---- UMFPACK directly -------------------------------------------------------------- */

static double run_umfpack(const csr *A, const double complex *b, int reps, double *resid)
{
    double *t = calloc((size_t)reps, sizeof *t), control[UMFPACK_CONTROL], info[UMFPACK_INFO], med;
    double complex *x = malloc((size_t)A->n * sizeof *x);
    int st = 0;
    if (!t || !x) return -1;
    umfpack_zl_defaults(control);
    for (int r = 0; r < reps && st == 0; r++) {
        void *sym = NULL, *num = NULL;
        double t0 = cpu_now();
        /* A = A.': its CSR arrays are its own compressed columns */
        st = (int)umfpack_zl_symbolic(A->n, A->n, A->rowptr, A->colind, (const double *)A->val, NULL, &sym,
                                      control, info);
        if (!st)
            st = (int)umfpack_zl_numeric(A->rowptr, A->colind, (const double *)A->val, NULL, sym, &num, control,
                                         info);
        if (!st)
            st = (int)umfpack_zl_solve(UMFPACK_A, A->rowptr, A->colind, (const double *)A->val, NULL,
                                       (double *)x, NULL, (const double *)b, NULL, num, control, info);
        t[r] = cpu_now() - t0;
        umfpack_zl_free_symbolic(&sym);
        umfpack_zl_free_numeric(&num);
    }
    if (st) {
        fprintf(stderr, "complex_helmholtz: UMFPACK failed (status %d)\n", st);
        free(t);
        free(x);
        return -1;
    }
    *resid = residual(A, x, b);
    med = bench_median(t, reps);
    free(t);
    free(x);
    return med;
}

/* ---- SciPy and Octave, from a file ------------------------------------------------ */

static const char scipy_script[] =
    "import sys, time, numpy as np, scipy.sparse as sp, scipy.sparse.linalg as sla\n"
    "f, n, nnz, reps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])\n"
    "raw = open(f, 'rb').read()\n"
    "rp = np.frombuffer(raw, np.int64, n + 1, 0)\n"
    "ci = np.frombuffer(raw, np.int64, nnz, 8 * (n + 1))\n"
    "v = np.frombuffer(raw, np.complex128, nnz, 8 * (n + 1 + nnz))\n"
    "b = np.frombuffer(raw, np.complex128, n, 8 * (n + 1 + nnz) + 16 * nnz)\n"
    "A = sp.csr_matrix((v, ci, rp), shape=(n, n)).tocsc()\n"
    "ts = []\n"
    "for r in range(reps):\n"
    "    t0 = time.process_time(); x = sla.spsolve(A, b); ts.append(time.process_time() - t0)\n"
    "print(sorted(ts)[len(ts) // 2], np.abs(b - A @ x).sum() / np.abs(b).sum())\n";

static const char octave_script[] =
    "a = argv(); f = a{1}; n = str2num(a{2}); nnz = str2num(a{3}); reps = str2num(a{4});\n"
    "fid = fopen(f, 'r'); rp = fread(fid, n + 1, 'int64'); ci = fread(fid, nnz, 'int64');\n"
    "v = fread(fid, 2 * nnz, 'double'); bb = fread(fid, 2 * n, 'double'); fclose(fid);\n"
    "v = v(1:2:end) + 1i * v(2:2:end); b = bb(1:2:end) + 1i * bb(2:2:end);\n"
    "r = repelem((1:n)', diff(rp)); A = sparse(r, ci + 1, v, n, n);\n"
    "ts = zeros(reps, 1);\n"
    "for k = 1:reps, t0 = cputime; x = A \\ b; ts(k) = cputime - t0; end\n"
    "printf('%.17g %.17g\\n', median(ts), sum(abs(b - A * x)) / sum(abs(b)));\n";

static int write_matrix(const char *path, const csr *A, const double complex *b)
{
    FILE *f = fopen(path, "wb");
    int ok;
    if (!f) return -1;
    ok = fwrite(A->rowptr, sizeof(int64_t), (size_t)A->n + 1, f) == (size_t)A->n + 1 &&
         fwrite(A->colind, sizeof(int64_t), (size_t)A->nnz, f) == (size_t)A->nnz &&
         fwrite(A->val, sizeof(double complex), (size_t)A->nnz, f) == (size_t)A->nnz &&
         fwrite(b, sizeof(double complex), (size_t)A->n, f) == (size_t)A->n;
    return fclose(f) == 0 && ok ? 0 : -1;
}

/* Runs cmd, which prints "seconds residual"; -1 if it fails. */
static double run_tool(const char *cmd, double *resid)
{
    FILE *p = popen(cmd, "r");
    double s = -1;
    if (!p) return -1;
    if (fscanf(p, "%lf %lf", &s, resid) != 2) s = -1;
    if (pclose(p) != 0) s = -1;
    return s;
}

/* One row; report < 0: the solver has no report to read; ratio < 0: s /
 * base, else the ratio measured round by round. */
static void row_ratio(const char *name, const char *how, double s, double report, double resid, double base,
                      double ratio)
{
    char rep[32] = "--";
    if (s < 0) {
        printf("| %-18s | %-58s | %9s | %9s | %11s | %9s |\n", name, how, "n/a", "", "", "");
        return;
    }
    if (report >= 0) snprintf(rep, sizeof rep, "%.3f", report);
    if (ratio < 0) ratio = base > 0 ? s / base : 0;
    printf("| %-18s | %-58s | %9.3f | %9.3f | %11s | %9.1e |\n", name, how, s, ratio, rep, resid);
}

static void row(const char *name, const char *how, double s, double report, double resid, double base)
{
    row_ratio(name, how, s, report, resid, base, -1);
}

/* The library and SILC under the three accuracy.condest modes, one run each
 * per round, rounds alternating: t[0] the library's median, t[1..3] SILC's
 * (auto, now, off), q[1..3] their medians of round-by-round ratios, and
 * each SILC row's median first-info time, residual and backend. */
static const char *const condest_modes[3] = {"auto", "now", "off"};

static int run_rounds(const csr *A, const double complex *b, int reps, double t[4], double q[4], double info[4],
                      double resid[4], char backend[3][300])
{
    double *rt[4], *rq[4], *ri[4];
    int ok = 1;
    for (int j = 0; j < 4; j++) {
        rt[j] = calloc((size_t)reps, sizeof(double));
        rq[j] = calloc((size_t)reps, sizeof(double));
        ri[j] = calloc((size_t)reps, sizeof(double));
        ok = ok && rt[j] && rq[j] && ri[j];
    }
    for (int r = 0; ok && r < reps; r++) {
        rt[0][r] = run_umfpack(A, b, 1, &resid[0]);
        ok = rt[0][r] > 0;
        for (int j = 1; ok && j < 4; j++) {
            rt[j][r] = run_silc(A, b, 1, condest_modes[j - 1], &resid[j], backend[j - 1], 300, &ri[j][r]);
            ok = rt[j][r] > 0;
            rq[j][r] = rt[j][r] / rt[0][r];
        }
    }
    for (int j = 0; j < 4; j++) {
        if (ok) {
            t[j] = bench_median(rt[j], reps);
            q[j] = j ? bench_median(rq[j], reps) : 1;
            info[j] = j ? bench_median(ri[j], reps) : -1;
        }
        free(rt[j]);
        free(rq[j]);
        free(ri[j]);
    }
    return ok ? 0 : -1;
}

int main(int argc, char **argv)
{
    int64_t N = 500;
    double k = 50, r_sp = 0, r_oct = 0;
    int reps = 3, scipy = 1, octave = 1;
    char backend[3][300], dir[] = "/tmp/silc-helmholtz-XXXXXX", path[600], script[600], cmd[1600];
    csr A;
    silc_envelope_t E;
    double complex *b;
    double t[4] = {-1, -1, -1, -1}, q[4], info[4], resid[4], t_sp = -1, t_oct = -1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--n") && i + 1 < argc) N = atoll(argv[++i]);
        else if (!strcmp(argv[i], "--k") && i + 1 < argc) k = atof(argv[++i]);
        else if (!strcmp(argv[i], "--reps") && i + 1 < argc) reps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--no-scipy")) scipy = 0;
        else if (!strcmp(argv[i], "--no-octave")) octave = 0;
        else {
            fprintf(stderr, "usage: %s [--n N] [--k K] [--reps R] [--no-scipy] [--no-octave]\n", argv[0]);
            return 2;
        }
    }
    if (N < 3 || N > 4000 || reps < 1 || reps > 50) {
        fprintf(stderr, "complex_helmholtz: --n must be 3..4000 and --reps 1..50\n");
        return 2;
    }
    if (helmholtz(N, k, &E, &A, &b)) return 1;
    printf("2-D Helmholtz, %lld x %lld grid (%lld unknowns, %lld entries), k = %g, absorbing boundary; "
           "median of %d\n\n",
           (long long)N, (long long)N, (long long)A.n, (long long)A.nnz, k, reps);
    if (run_rounds(&A, b, reps, t, q, info, resid, backend)) fprintf(stderr, "complex_helmholtz: a run failed\n");
    if ((scipy || octave) && mkdtemp(dir)) {
        snprintf(path, sizeof path, "%s/A.bin", dir);
        if (write_matrix(path, &A, b) == 0) {
            if (scipy) {
                FILE *f;
                snprintf(script, sizeof script, "%s/bench.py", dir);
                if ((f = fopen(script, "w"))) {
                    fputs(scipy_script, f);
                    fclose(f);
                    snprintf(cmd, sizeof cmd, "/usr/bin/python3 %s %s %lld %lld %d", script, path, (long long)A.n,
                             (long long)A.nnz, reps);
                    t_sp = run_tool(cmd, &r_sp);
                }
            }
            if (octave && access("/usr/bin/octave-cli", X_OK) == 0) {
                FILE *f;
                snprintf(script, sizeof script, "%s/bench.m", dir);
                if ((f = fopen(script, "w"))) {
                    fputs(octave_script, f);
                    fclose(f);
                    snprintf(cmd, sizeof cmd, "octave-cli -q %s %s %lld %lld %d 2>/dev/null", script, path,
                             (long long)A.n, (long long)A.nnz, reps);
                    t_oct = run_tool(cmd, &r_oct);
                }
            }
            unlink(path);
        }
        snprintf(script, sizeof script, "%s/bench.py", dir);
        unlink(script);
        snprintf(script, sizeof script, "%s/bench.m", dir);
        unlink(script);
        rmdir(dir);
    }
    printf("| %-18s | %-58s | %9s | %9s | %11s | %9s |\n", "solver", "how", "CPU s", "/ UMFPACK",
           "info x [s]", "residual");
    printf("| %-18s | %-58s | %9s | %9s | %11s | %9s |\n", "---", "---", "---:", "---:", "---:", "---:");
    row("UMFPACK direct", "umfpack_zl symbolic+numeric+solve", t[0], -1, resid[0], t[0]);
    for (int j = 1; j < 4; j++) row_ratio("SILC x = A \\ b", backend[j - 1], t[j], info[j], resid[j], t[0], q[j]);
    if (scipy) row("SciPy spsolve", "scipy.sparse.linalg (SuperLU)", t_sp, -1, r_sp, t[0]);
    if (octave) row("Octave A\\b", access("/usr/bin/octave-cli", X_OK) ? "octave-cli not installed" : "octave-cli",
                    t_oct, -1, r_oct, t[0]);
    printf("\nSILC's ratios are medians of round-by-round ratios (the rounds alternate the library and SILC);\n"
           "SciPy's and Octave's are their medians over the library's.\n");
    silc_envelope_free(&E);
    free(b);
    return t[0] < 0 || t[1] < 0;
}
