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
 * Rows (each the median of R runs, a fresh A each time so nothing is
 * reused; every row runs once per round and the rounds alternate them all,
 * since the machine drifts more over the minutes of a run (15-20 %,
 * measured) than the differences this bench is for, each round starting
 * one row further on, so that with R a multiple of the rows every row
 * follows every other once; a row's ratio is the median of its
 * round-by-round ratios to the first row):
 *   UMFPACK direct    umfpack_zl_symbolic + numeric + solve (UMFPACK_A),
 *                     default control (strategy auto, row scaling by sums,
 *                     up to two refinement steps, as SILC's backend asks
 *                     too): what the library needs and nothing more, the
 *                     baseline of the ratios;
 *   UMFPACK direct    the same with Octave's control: its sparse `\`
 *                     (liboctave CSparse.cc, fsolve) keeps the defaults and
 *                     sets UMFPACK_IRSTEP = 1;
 *   UMFPACK direct    the first row's call with SuiteSparse_config's hooks
 *                     set to the large allocator SILC's plugin gives
 *                     UMFPACK (core/util/largealloc.c: blocks of 4 MiB and
 *                     more on transparent huge pages) for the row, then put
 *                     back: SILC's default against the library called the
 *                     same way (the other direct rows keep libc's malloc);
 *   SILC  x = A \ b   default dispatch (whatever backend the dispatcher
 *                     picks, named in the row), each run in a new context
 *                     (nothing reused: checked with info), PUT not timed;
 *                     the report's own work that the statement leaves for
 *                     later (a deferred condition estimate) is what the
 *                     first `info x` costs, in a column of its own;
 *                     again with accuracy.condest = now (the estimate at
 *                     solve time) and off (no estimate at all), and with
 *                     suitesparse.huge_pages = off (libc's malloc);
 *   SciPy spsolve     /usr/bin/python3, scipy.sparse.linalg.spsolve (SuperLU);
 *   Octave A\b        octave-cli, skipped when absent.
 * SciPy and Octave run in a process of their own each round (started and
 * fed untimed, then one untimed solve of a 2 x 2 system so that nothing
 * is loaded on first use inside the timing).
 * Times are CPU seconds of the process that solves (every solver runs
 * single-threaded here: OPENBLAS_NUM_THREADS=1), so the other jobs of a
 * shared machine do not count; each row also shows the page faults of the
 * timed part (minor faults: the kernel hands the solver a fresh zeroed page
 * on first touch; UMFPACK's ~500 MB of work space here is mostly fresh
 * pages, and their faults are a fifth of the time on this machine) and the
 * relative residual ||b - A x||_1 / ||b||_1.  Ratios are to the first row
 * and, in a second column, to the huge-page direct row.
 */
#define _POSIX_C_SOURCE 200809L
#include <complex.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <umfpack.h>

#include "helmholtz.h"
#include "silc.h"
#include "timing.h"
#include "util.h" /* util_large_*: the allocator the plugin hands UMFPACK */

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

/* Minor page faults of this process so far. */
static double minor_faults(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)u.ru_minflt;
}

/* One timed run of one row: CPU seconds, the first `info x` (SILC; -1 for
 * a solver with no report), page faults, residual. */
typedef struct run_result {
    double s, report, faults, resid;
} run_result;

/* One run in a context of its own, so no factorization or analysis of an
 * earlier run is reused (the store would hand an identical PUT the value
 * it already has); the PUTs are not timed.  condest: accuracy.condest's
 * value; how: the backend as info names it, and the mode. */
static int run_silc(const csr *A, const double complex *b, const char *condest, const char *huge,
                    run_result *out, char *how, size_t hlen)
{
    silc_envelope_t EA, Eb, Ex;
    silc_context *c = NULL;
    char set[128], info[2048] = "", name[64], reused[16];
    double complex *x = malloc((size_t)A->n * sizeof *x);
    double t0, f0;
    int ok = 0;
    snprintf(set, sizeof set, "set accuracy.condest = %s; set suitesparse.huge_pages = %s", condest, huge);
    if (!x || silc_envelope_csr_complex(&EA, A->n, A->n, A->rowptr, A->colind, (const double *)A->val) ||
        silc_envelope_dense_complex(&Eb, A->n, 1, (const double *)b))
        goto done;
    if (silc_open(&c, NULL) || silc_put(c, "A", &EA) || silc_put(c, "b", &Eb) || silc_exec(c, set)) goto done;
    f0 = minor_faults();
    t0 = cpu_now();
    if (silc_exec(c, "x = A \\ b;")) goto done;
    out->s = cpu_now() - t0;
    out->faults = minor_faults() - f0;
    silc_set_output(c, collect, info);
    t0 = cpu_now();
    if (silc_exec(c, "info x")) goto done;
    out->report = cpu_now() - t0;
    info_field(info, "reused factorization: ", reused, sizeof reused);
    if (strcmp(reused, "no") != 0) {
        fprintf(stderr, "complex_helmholtz: a run reused a factorization (info: '%s')\n", reused);
        goto done;
    }
    if (silc_get_complex(c, &Ex, "x") || silc_envelope_to_dense(&Ex, (double *)x)) goto done;
    silc_envelope_free(&Ex);
    out->resid = residual(A, x, b);
    info_field(info, "backend: ", name, sizeof name);
    snprintf(how, hlen, "%s, accuracy.condest = %s%s%s", name, condest,
             strstr(info, "computed when the report was first read") ? " (estimate deferred)" : "",
             strcmp(huge, "auto") ? ", suitesparse.huge_pages = off" : "");
    ok = 1;
done:
    if (!ok) {
        fprintf(stderr, "complex_helmholtz: SILC failed: %s\n", c ? silc_context_errmsg(c) : silc_errmsg());
        snprintf(how, hlen, "failed (message on stderr)");
    }
    if (c) silc_close(&c);
    silc_envelope_free(&EA);
    silc_envelope_free(&Eb);
    free(x);
    return ok ? 0 : -1;
}

/* ---- UMFPACK directly -------------------------------------------------------------- */

/* UMFPACK's default control but for irstep (its refinement steps); huge:
 * with SILC's large allocator in SuiteSparse_config for the call. */
static int run_umfpack(const csr *A, const double complex *b, double irstep, int huge, run_result *out)
{
    struct SuiteSparse_config_struct saved = SuiteSparse_config;
    double control[UMFPACK_CONTROL], info[UMFPACK_INFO], t0, f0;
    double complex *x = malloc((size_t)A->n * sizeof *x);
    void *sym = NULL, *num = NULL;
    int st;
    if (!x) return -1;
    umfpack_zl_defaults(control);
    control[UMFPACK_IRSTEP] = irstep;
    if (huge) {
        SuiteSparse_config.malloc_func = util_large_malloc;
        SuiteSparse_config.calloc_func = util_large_calloc;
        SuiteSparse_config.realloc_func = util_large_realloc;
        SuiteSparse_config.free_func = util_large_free;
    }
    f0 = minor_faults();
    t0 = cpu_now();
    /* A = A.': its CSR arrays are its own compressed columns */
    st = (int)umfpack_zl_symbolic(A->n, A->n, A->rowptr, A->colind, (const double *)A->val, NULL, &sym, control,
                                  info);
    if (!st)
        st = (int)umfpack_zl_numeric(A->rowptr, A->colind, (const double *)A->val, NULL, sym, &num, control, info);
    if (!st)
        st = (int)umfpack_zl_solve(UMFPACK_A, A->rowptr, A->colind, (const double *)A->val, NULL, (double *)x,
                                   NULL, (const double *)b, NULL, num, control, info);
    out->s = cpu_now() - t0;
    out->faults = minor_faults() - f0;
    umfpack_zl_free_symbolic(&sym);
    umfpack_zl_free_numeric(&num);
    SuiteSparse_config = saved;
    if (st) fprintf(stderr, "complex_helmholtz: UMFPACK failed (status %d)\n", st);
    else out->resid = residual(A, x, b);
    free(x);
    return st ? -1 : 0;
}

/* ---- SciPy and Octave, from a file ------------------------------------------------ */

/* Each prints "seconds residual faults" for one solve, after one untimed
 * solve of a 2 x 2 complex system (whatever the library loads or sets up on
 * first use is not timed; the direct and SILC rows are warm after the first
 * round too). */
static const char scipy_script[] =
    "import sys, time, resource, numpy as np, scipy.sparse as sp, scipy.sparse.linalg as sla\n"
    "f, n, nnz = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])\n"
    "sla.spsolve(sp.csc_matrix(np.array([[2, 1j], [1j, 3]])), np.array([1, 1j]))\n"
    "raw = open(f, 'rb').read()\n"
    "rp = np.frombuffer(raw, np.int64, n + 1, 0)\n"
    "ci = np.frombuffer(raw, np.int64, nnz, 8 * (n + 1))\n"
    "v = np.frombuffer(raw, np.complex128, nnz, 8 * (n + 1 + nnz))\n"
    "b = np.frombuffer(raw, np.complex128, n, 8 * (n + 1 + nnz) + 16 * nnz)\n"
    "A = sp.csr_matrix((v, ci, rp), shape=(n, n)).tocsc()\n"
    "f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt\n"
    "t0 = time.process_time(); x = sla.spsolve(A, b); t = time.process_time() - t0\n"
    "f1 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt\n"
    "print(t, np.abs(b - A @ x).sum() / np.abs(b).sum(), f1 - f0)\n";

static const char octave_script[] =
    "a = argv(); f = a{1}; n = str2num(a{2}); nz = str2num(a{3});\n"
    "w = sparse([2 1i; 1i 3]) \\ [1; 1i];\n"
    "fid = fopen(f, 'r'); rp = fread(fid, n + 1, 'int64'); ci = fread(fid, nz, 'int64');\n"
    "v = fread(fid, 2 * nz, 'double'); bb = fread(fid, 2 * n, 'double'); fclose(fid);\n"
    "v = v(1:2:end) + 1i * v(2:2:end); b = bb(1:2:end) + 1i * bb(2:2:end);\n"
    "r = repelem((1:n)', diff(rp)); A = sparse(r, ci + 1, v, n, n);\n"
    "u0 = getrusage(); t0 = cputime; x = A \\ b; t = cputime - t0; u1 = getrusage();\n"
    "printf('%.17g %.17g %d\\n', t, sum(abs(b - A * x)) / sum(abs(b)), u1.minflt - u0.minflt);\n";

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

static int write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    int ok;
    if (!f) return -1;
    ok = fputs(text, f) >= 0;
    return fclose(f) == 0 && ok ? 0 : -1;
}

/* Runs cmd, which prints "seconds residual faults". */
static int run_tool(const char *cmd, run_result *out)
{
    FILE *p = popen(cmd, "r");
    int ok;
    if (!p) return -1;
    ok = fscanf(p, "%lf %lf %lf", &out->s, &out->resid, &out->faults) == 3;
    if (pclose(p) != 0) ok = 0;
    return ok ? 0 : -1;
}

/* ---- the rounds ----------------------------------------------------------------- */

/* The 1-minute load average (/proc/loadavg), -1 where there is none: the
 * rounds print it, since a shared machine's load says how far to trust
 * a few per cent. */
static double load_average(void)
{
    FILE *f = fopen("/proc/loadavg", "r");
    double l = -1;
    if (f) {
        if (fscanf(f, "%lf", &l) != 1) l = -1;
        fclose(f);
    }
    return l;
}

enum {
    ROW_DIRECT,
    ROW_DIRECT_OCTAVE,
    ROW_DIRECT_HUGE,
    ROW_SILC_AUTO,
    ROW_SILC_NOW,
    ROW_SILC_OFF,
    ROW_SILC_NOHUGE,
    ROW_SCIPY,
    ROW_OCTAVE,
    ROWS
};

typedef struct bench_row {
    const char *name;
    char how[300];
    int on;                            /* runs at all */
    double *s, *ratio, *ratio_huge, *report, *faults; /* one per round */
    double resid;
    int failed;
} bench_row;

/* Row j's run of one round. */
static int run_row(int j, const csr *A, const double complex *b, const char *cmd_scipy, const char *cmd_octave,
                   run_result *out, char *how, size_t hlen)
{
    out->report = -1;
    switch (j) {
    case ROW_DIRECT: return run_umfpack(A, b, 2, 0, out);
    case ROW_DIRECT_OCTAVE: return run_umfpack(A, b, 1, 0, out);
    case ROW_DIRECT_HUGE: return run_umfpack(A, b, 2, 1, out);
    case ROW_SILC_AUTO: return run_silc(A, b, "auto", "auto", out, how, hlen);
    case ROW_SILC_NOW: return run_silc(A, b, "now", "auto", out, how, hlen);
    case ROW_SILC_OFF: return run_silc(A, b, "off", "auto", out, how, hlen);
    case ROW_SILC_NOHUGE: return run_silc(A, b, "auto", "off", out, how, hlen);
    case ROW_SCIPY: return run_tool(cmd_scipy, out);
    default: return run_tool(cmd_octave, out);
    }
}

static void print_row(const bench_row *r, int reps)
{
    char rep[32] = "--";
    double report;
    if (!r->on) return;
    if (r->failed) {
        printf("| %-18s | %-76s | %9s | %9s | %9s | %11s | %9s | %9s |\n", r->name, r->how, "n/a", "", "", "", "",
               "");
        return;
    }
    report = bench_median(r->report, reps);
    if (report >= 0) snprintf(rep, sizeof rep, "%.3f", report);
    printf("| %-18s | %-76s | %9.3f | %9.3f | %9.3f | %11s | %9.0f | %9.1e |\n", r->name, r->how,
           bench_median(r->s, reps), bench_median(r->ratio, reps), bench_median(r->ratio_huge, reps), rep,
           bench_median(r->faults, reps), r->resid);
}

int main(int argc, char **argv)
{
    int64_t N = 500;
    double k = 50;
    int reps = 3, scipy = 1, octave = 1, rc = 0;
    char dir[] = "/tmp/silc-helmholtz-XXXXXX", path[600], py[600], m[600], cmd_scipy[2000] = "",
         cmd_octave[2000] = "";
    csr A;
    silc_envelope_t E;
    double complex *b;
    bench_row rows[ROWS] = {
        {.name = "UMFPACK direct",
         .how = "umfpack_zl, default control (IRSTEP 2, SCALE SUM, STRATEGY AUTO), UMFPACK_A",
         .on = 1},
        {.name = "UMFPACK direct",
         .how = "umfpack_zl, Octave's control (the defaults but IRSTEP 1), UMFPACK_A",
         .on = 1},
        {.name = "UMFPACK direct",
         .how = "umfpack_zl, default control, SILC's large allocator (huge pages) in SuiteSparse_config",
         .on = 1},
        {.name = "SILC x = A \\ b", .how = "", .on = 1},
        {.name = "SILC x = A \\ b", .how = "", .on = 1},
        {.name = "SILC x = A \\ b", .how = "", .on = 1},
        {.name = "SILC x = A \\ b", .how = "", .on = 1},
        {.name = "SciPy spsolve", .how = "scipy.sparse.linalg (SuperLU)", .on = 1},
        {.name = "Octave A\\b", .how = "octave-cli (UMFPACK)", .on = 1},
    };
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
    if (octave && access("/usr/bin/octave-cli", X_OK) != 0) {
        snprintf(rows[ROW_OCTAVE].how, sizeof rows[ROW_OCTAVE].how, "octave-cli not installed");
        rows[ROW_OCTAVE].failed = 1;
        octave = 0;
    }
    if (!(scipy || octave) || !mkdtemp(dir)) {
        dir[0] = 0;
        scipy = octave = 0;
    }
    if (dir[0]) {
        snprintf(path, sizeof path, "%s/A.bin", dir);
        snprintf(py, sizeof py, "%s/bench.py", dir);
        snprintf(m, sizeof m, "%s/bench.m", dir);
        if (write_matrix(path, &A, b) || write_text(py, scipy_script) || write_text(m, octave_script)) {
            fprintf(stderr, "complex_helmholtz: cannot write the matrix for SciPy and Octave in %s\n", dir);
            scipy = octave = 0;
        }
        snprintf(cmd_scipy, sizeof cmd_scipy, "/usr/bin/python3 %s %s %lld %lld", py, path, (long long)A.n,
                 (long long)A.nnz);
        snprintf(cmd_octave, sizeof cmd_octave, "octave-cli -q %s %s %lld %lld 2>/dev/null", m, path,
                 (long long)A.n, (long long)A.nnz);
    }
    rows[ROW_SCIPY].on = scipy;
    rows[ROW_OCTAVE].on = octave || rows[ROW_OCTAVE].failed;
    for (int j = 0; j < ROWS; j++) {
        bench_row *r = &rows[j];
        r->s = calloc((size_t)reps, sizeof(double));
        r->ratio = calloc((size_t)reps, sizeof(double));
        r->ratio_huge = calloc((size_t)reps, sizeof(double));
        r->report = calloc((size_t)reps, sizeof(double));
        r->faults = calloc((size_t)reps, sizeof(double));
        if (!r->s || !r->ratio || !r->ratio_huge || !r->report || !r->faults) {
            fprintf(stderr, "complex_helmholtz: out of memory\n");
            return 1;
        }
    }
    printf("2-D Helmholtz, %lld x %lld grid (%lld unknowns, %lld entries), k = %g, absorbing boundary; "
           "median of %d rounds\n\n",
           (long long)N, (long long)N, (long long)A.n, (long long)A.nnz, k, reps);
    for (int round = 0; round < reps; round++) {
        fprintf(stderr, "round %d of %d (load average %.2f), from row %d:", round + 1, reps, load_average(),
                round % ROWS + 1);
        /* Round r starts at row r (mod ROWS): the memory a solve frees is
         * cheaper for the next solve to touch again than memory it has not
         * had for a while (this VM's balloon hands free pages back to the
         * host after a few seconds, and a page the host took back faults
         * there again), so a fixed order favoured the row after a large one;
         * over ROWS rounds every row has every place once. */
        for (int jj = 0; jj < ROWS; jj++) {
            int j = (jj + round) % ROWS;
            bench_row *r = &rows[j];
            run_result out = {-1, -1, 0, 0};
            if (!r->on || r->failed) continue;
            if (run_row(j, &A, b, cmd_scipy, cmd_octave, &out, r->how, sizeof r->how)) {
                r->failed = 1;
                if (j == ROW_DIRECT) rc = 1;
                if (j == ROW_SCIPY || j == ROW_OCTAVE) fprintf(stderr, " (%s failed)", r->name);
                continue;
            }
            r->s[round] = out.s;
            r->report[round] = out.report;
            r->faults[round] = out.faults;
            r->resid = out.resid;
        }
        for (int j = 0; j < ROWS; j++) /* in the table's order */
            if (rows[j].on && !rows[j].failed) fprintf(stderr, " %.2f", rows[j].s[round]);
        fprintf(stderr, "\n");
        for (int j = 0; j < ROWS; j++) { /* once the round has every row */
            bench_row *r = &rows[j];
            r->ratio[round] = rows[ROW_DIRECT].failed ? 0 : r->s[round] / rows[ROW_DIRECT].s[round];
            r->ratio_huge[round] = rows[ROW_DIRECT_HUGE].failed ? 0 : r->s[round] / rows[ROW_DIRECT_HUGE].s[round];
        }
    }
    if (dir[0]) {
        unlink(path);
        unlink(py);
        unlink(m);
        rmdir(dir);
    }
    printf("| %-18s | %-76s | %9s | %9s | %9s | %11s | %9s | %9s |\n", "solver", "how", "CPU s", "/ UMFPACK",
           "/ huge", "info x [s]", "faults", "residual");
    printf("| %-18s | %-76s | %9s | %9s | %9s | %11s | %9s | %9s |\n", "---", "---", "---:", "---:", "---:", "---:",
           "---:", "---:");
    for (int j = 0; j < ROWS; j++) print_row(&rows[j], reps);
    printf("\nRatios are medians of round-by-round ratios to the first row (/ UMFPACK) and to the direct row\n"
           "on huge pages (/ huge); each round runs every row once; faults: minor page faults of the timed\n"
           "part (median).\n");
    for (int j = 0; j < ROWS; j++) {
        free(rows[j].s);
        free(rows[j].ratio);
        free(rows[j].ratio_huge);
        free(rows[j].report);
        free(rows[j].faults);
    }
    silc_envelope_free(&E);
    free(b);
    return rc || rows[ROW_SILC_AUTO].failed;
}
