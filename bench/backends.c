/*
 * backends.c -- the direct-solver backends through SILC against the same
 * libraries called directly, SciPy and GNU Octave.
 *
 *     backends [--scipy] [--octave] [--install] [--reps R] [--loop N] [--grid K] [--only NAME]
 *              [--mumps-rows]
 *
 * --install installs what --scipy and --octave need (Debian's python3-scipy,
 * octave) with apt-get when it is missing; needs root.  Without it the bench
 * never installs anything, and a missing tool's rows say "failed".
 *
 * Problems: the 2-D 5-point Laplacian on a K x K grid (K = 500: 250000
 * unknowns, SPD) and the shared matrices bcsstk16 (SPD), memplus
 * (unsymmetric), bayer10 (near-singular).  Right-hand side b = A x0 with
 * x0_i = 1 + (i mod 10)/10, the same in every tool.
 *
 * One solve: for every backend, `x = solve(A, b, "backend = NAME")` on a
 * freshly put A (so nothing is reused), best of R runs (default 3 for the
 * Laplacian, 10 for the shared matrices), wall time of the whole
 * silc_exec (dispatch, analysis, factorization, solve, and in the rows that
 * make them the condition estimate and the core's backward error) and the
 * backward error ||b - A x||inf / (||A||inf ||x||inf + ||b||inf).  The row
 * "default" is plain `x = A \ b`; each library with a direct call also gets
 * rows with less of the accuracy report, "condest off" and "bare" (no
 * estimate, backward error on request: SILC's own cost; compare_one), and
 * "bare + put A" adds the silc_put of A that preceded it (copy, checks,
 * shape), which a direct caller holding its arrays in the library's format
 * does not pay.
 * "direct" is the same library called here with the same settings as the
 * plugin (UMFPACK, KLU on the CSR arrays as A' and the transposed solve, as
 * the plugin does; CHOLMOD supernodal on the upper triangle; MUMPS with AMF
 * ordering, SYM=1 for SPD), its input already in the library's own format
 * (what a direct user holds), timed from analysis to solution.  overhead =
 * SILC / direct.
 * SciPy: scipy.sparse.linalg.spsolve (SuperLU, COLAMD) via /usr/bin/python3;
 * Octave: A\b via octave-cli; both read the matrix from a file this program
 * writes, and time only the solve.
 *
 * Factor reuse: N solves `x = A \ b` with the same A (one factorization, N
 * triangular solves) through SILC, directly (factor once, N solves), with
 * SciPy's splu + N solves, and Octave's loop of A\b (which factors every time).
 *
 * The diffusion loop (--only diffusion): the main example's Crank-Nicolson
 * loop, u = A \ (B u) with A = I + s L, B = I - s L, L the 5-point
 * Laplacian on a K x K grid (K = 200 unless --grid says), s = dt / (2 h^2),
 * dt = 1e-3, N steps (--loop, default 100) from the example's initial block:
 * SILC with the default config, SILC with `tune on N` and tune.accuracy =
 * 1e-8 (a fresh session and wisdom file: the first run's whole cost), SciPy
 * with splu(A) once and N solves, Octave's loop of A \ (B*u), and the
 * baseline: CHOLMOD called directly (analysis and factorization once, then
 * per step a CSR product and cholmod_l_solve2 reusing its work space; the
 * factorization's CPU seconds in the per-step lines).  Rows are the best of
 * R runs by CPU seconds (SciPy's too; Octave's runs once).  Each row
 * prints sum(u) at the end (the tools agree to about 1e-10 relative) and
 * the last step's backward error.  --mumps-rows adds the loop with MUMPS
 * forced: double, single alone and single refined to 1e-8, each with
 * MUMPS's amalgamation and with mumps.amalgamation = 12 (the per-step floor
 * of the mixed-precision route, docs/backends.md).
 *
 * Set OPENBLAS_NUM_THREADS=1 (done here if unset) for a single-thread
 * comparison: every tool then runs its BLAS on one thread.
 */
#define _POSIX_C_SOURCE 200809L
#include "progress.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cholmod.h>
#include <dmumps_c.h>
#include <klu.h>
#include <umfpack.h>

#include "diffusion_common.h"
#include "silc.h"
#include "testlib.h"

typedef struct problem {
    const char *name;
    const char *file;       /* NULL: the generated Laplacian */
    int spd;
    silc_envelope_t A;      /* CSR */
    double *b, *x0;
} problem;

typedef struct opts {
    int scipy, octave, install, reps, loop, mumps_rows;
    int64_t grid, grid_given;
    const char *only;
    char tmpdir[256];
} opts;

/* ---- direct calls ------------------------------------------------------------ */

/* Each runs analysis + factorization + `nsolve` solves; returns seconds (< 0 on
 * failure) and leaves the last solution in x. */

static double direct_umfpack(const problem *P, int nsolve, double *x)
{
    const silc_envelope_t *A = &P->A;
    double control[UMFPACK_CONTROL], info[UMFPACK_INFO], t0 = tl_now(), t;
    void *sym = NULL, *num = NULL;
    int k, st;
    umfpack_dl_defaults(control);
    /* CSR of A = CSC of A': factor A', solve with its transpose. */
    st = (int)umfpack_dl_symbolic(A->n, A->m, A->rowptr, A->colind, A->values, &sym, control, info);
    if (st == UMFPACK_OK)
        st = (int)umfpack_dl_numeric(A->rowptr, A->colind, A->values, sym, &num, control, info);
    for (k = 0; k < nsolve && (st == UMFPACK_OK || st == UMFPACK_WARNING_singular_matrix); k++)
        st = (int)umfpack_dl_solve(UMFPACK_At, A->rowptr, A->colind, A->values, x, P->b, num,
                                   control, info);
    t = tl_now() - t0;
    umfpack_dl_free_symbolic(&sym);
    umfpack_dl_free_numeric(&num);
    return st == UMFPACK_OK || st == UMFPACK_WARNING_singular_matrix ? t : -1;
}

static double direct_klu(const problem *P, int nsolve, double *x)
{
    const silc_envelope_t *A = &P->A;
    klu_l_common c;
    klu_l_symbolic *S;
    klu_l_numeric *N = NULL;
    double t0 = tl_now(), t;
    int k, ok = 1;
    klu_l_defaults(&c);
    S = klu_l_analyze(A->n, A->rowptr, A->colind, &c);
    if (S) N = klu_l_factor(A->rowptr, A->colind, A->values, S, &c);
    for (k = 0; k < nsolve && N && ok; k++) {
        memcpy(x, P->b, (size_t)A->n * sizeof *x);
        ok = (int)klu_l_tsolve(S, N, A->n, 1, x, &c);
    }
    t = S && N && ok ? tl_now() - t0 : -1;
    klu_l_free_numeric(&N, &c);
    klu_l_free_symbolic(&S, &c);
    return t;
}

static double direct_cholmod(const problem *P, int nsolve, double *x)
{
    const silc_envelope_t *A = &P->A;
    cholmod_common cc;
    cholmod_sparse S;
    cholmod_dense B, *X = NULL;
    cholmod_factor *L = NULL;
    double t0, t;
    int k, ok;
    cholmod_l_start(&cc);
    memset(&S, 0, sizeof S);
    S.nrow = (size_t)A->n;
    S.ncol = (size_t)A->n;
    S.nzmax = (size_t)A->nnz;
    S.p = A->rowptr;
    S.i = A->colind;
    S.x = A->values;
    S.stype = 1; /* symmetric, upper triangle used: CSR of A is CSC of A' = A */
    S.itype = CHOLMOD_LONG;
    S.xtype = CHOLMOD_REAL;
    S.dtype = CHOLMOD_DOUBLE;
    S.sorted = 1;
    S.packed = 1;
    memset(&B, 0, sizeof B);
    B.nrow = B.d = (size_t)A->n;
    B.ncol = 1;
    B.nzmax = (size_t)A->n;
    B.x = P->b;
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    t0 = tl_now();
    L = cholmod_l_analyze(&S, &cc);
    ok = L && cholmod_l_factorize(&S, L, &cc) && cc.status == CHOLMOD_OK;
    for (k = 0; k < nsolve && ok; k++) {
        cholmod_l_free_dense(&X, &cc);
        X = cholmod_l_solve(CHOLMOD_A, L, &B, &cc);
        ok = X != NULL;
    }
    t = tl_now() - t0;
    if (ok) memcpy(x, X->x, (size_t)A->n * sizeof *x);
    cholmod_l_free_dense(&X, &cc);
    cholmod_l_free_factor(&L, &cc);
    cholmod_l_finish(&cc);
    return ok ? t : -1;
}

static double direct_mumps(const problem *P, int nsolve, double *x)
{
    const silc_envelope_t *A = &P->A;
    DMUMPS_STRUC_C id;
    MUMPS_INT *irn = malloc((size_t)A->nnz * sizeof *irn), *jcn = malloc((size_t)A->nnz * sizeof *jcn);
    double *a = malloc((size_t)A->nnz * sizeof *a), t0, t = -1;
    int64_t i, k, nz = 0;
    int s, ok;
    if (!irn || !jcn || !a) goto out;
    /* Triplets, 1-based; SYM=1 takes one triangle. */
    for (i = 0; i < A->m; i++)
        for (k = A->rowptr[i]; k < A->rowptr[i + 1]; k++)
            if (!P->spd || A->colind[k] >= i) {
                irn[nz] = (MUMPS_INT)(i + 1);
                jcn[nz] = (MUMPS_INT)(A->colind[k] + 1);
                a[nz++] = A->values[k];
            }
    memset(&id, 0, sizeof id);
    id.comm_fortran = -987654; /* USE_COMM_WORLD of the sequential stub */
    id.par = 1;
    id.sym = P->spd ? 1 : 0;
    id.job = -1;
    t0 = tl_now(); /* from the instance set-up (JOB=-1), which the plugin makes per factorization too */
    dmumps_c(&id);
    id.icntl[0] = id.icntl[1] = id.icntl[2] = -1;
    id.icntl[3] = 0;
    id.icntl[6] = 2; /* ICNTL(7) = AMF, the plugin's default */
    id.n = (MUMPS_INT)A->n;
    id.nnz = nz;
    id.irn = irn;
    id.jcn = jcn;
    id.a = a;
    id.job = 4; /* analysis + factorization */
    dmumps_c(&id);
    ok = id.infog[0] >= 0;
    for (s = 0; s < nsolve && ok; s++) {
        memcpy(x, P->b, (size_t)A->n * sizeof *x);
        id.rhs = x;
        id.job = 3;
        dmumps_c(&id);
        ok = id.infog[0] >= 0;
    }
    if (ok) t = tl_now() - t0;
    id.job = -2;
    dmumps_c(&id);
out:
    free(irn);
    free(jcn);
    free(a);
    return t;
}

static const struct {
    const char *backend;
    double (*run)(const problem *, int, double *);
} directs[] = {{"suitesparse.umfpack", direct_umfpack},
               {"suitesparse.klu", direct_klu},
               {"suitesparse.cholmod", direct_cholmod},
               {"mumps", direct_mumps}};

static double (*direct_for(const char *backend))(const problem *, int, double *)
{
    size_t i;
    for (i = 0; i < sizeof directs / sizeof directs[0]; i++)
        if (!strcmp(directs[i].backend, backend)) return directs[i].run;
    return NULL;
}

/* ---- through SILC ------------------------------------------------------------- */

/* SuiteSparse keeps the last symbolic analysis per library and hands it to
 * a new value of the same pattern; a solve with the small SPD system Z puts
 * another pattern there, so that every timed run starts from scratch, as the
 * direct calls do. */
static void flush_pattern_caches(silc_context *c)
{
    static const int64_t rp[] = {0, 2, 5, 7}, ci[] = {0, 1, 0, 1, 2, 1, 2};
    static const double v[] = {4, 1, 1, 4, 1, 1, 4}, zb[] = {1, 1, 1};
    silc_envelope_t Z;
    if (silc_envelope_csr(&Z, 3, 3, rp, ci, v) == 0) silc_put(c, "Z", &Z);
    silc_envelope_free(&Z);
    tl_put_vector(c, "zb", 3, zb);
    silc_exec(c, "z = solve(Z, zb, \"backend = suitesparse.umfpack\")");
    silc_exec(c, "z = solve(Z, zb, \"backend = suitesparse.klu\")");
    silc_exec(c, "z = solve(Z, zb, \"backend = suitesparse.cholmod\")");
    silc_exec(c, "z = solve(Z, zb, \"backend = mumps\")");
}

static progress bar; /* on stderr while the bench runs, when it is a terminal */

/* One run on a fresh A: nsolve solves with it, timed together; be, the
 * backend that ran and the time of silc_put(A) (copy, checks and shape,
 * which the direct calls do not pay) are filled.  compare() takes the best
 * of several. */
static double silc_time(silc_context *c, tl_capture *cap, const problem *P, const char *backend,
                        int nsolve, double *be, char *ran, size_t ranlen, double *tput)
{
    char stmt[160];
    double t0, t;
    int k, put_failed;
    if (!strcmp(backend, "default")) snprintf(stmt, sizeof stmt, "x = A \\ b");
    else snprintf(stmt, sizeof stmt, "x = solve(%s, b, \"backend = %s\")",
                  strcmp(backend, "lapack") ? "A" : "Ad", backend);
    progress_show(&bar, "backends: %s, %s", P->name, backend);
    flush_pattern_caches(c);
    /* A PUT of exactly what A holds keeps the value, factorization and all
     * (silc_put): clear it first, so this run starts from nothing. */
    silc_exec(c, "clear A");
    t0 = tl_now();
    put_failed = silc_put(c, "A", &P->A);
    *tput = tl_now() - t0;
    if (put_failed || (!strcmp(backend, "lapack") && silc_exec(c, "Ad = dense(A)"))) {
        fprintf(stderr, "backends: %s: %s\n", P->name, silc_context_errmsg(c));
        return -1;
    }
    t0 = tl_now();
    for (k = 0; k < nsolve; k++)
        if (silc_exec(c, stmt)) {
            const char *e = silc_context_errmsg(c);
            snprintf(ran, ranlen, "%s", tl_contains(e, "not installed") ? "not built" : "error");
            if (!tl_contains(e, "not installed")) fprintf(stderr, "  %s %s: %s\n", P->name, backend, e);
            return -1;
        }
    t = tl_now() - t0;
    {
        const char *info = tl_info(c, cap, "x");
        const char *p = strstr(info, "  backend: ");
        *be = tl_field(info, "backward error");
        if (p) sscanf(p + 11, "%63s", ran);
    }
    silc_exec(c, "clear Ad");
    progress_done(&bar);
    return t;
}

/* ---- SciPy and Octave ------------------------------------------------------------ */

static const char scipy_script[] =
    "import sys, time, numpy as np, scipy.io, scipy.sparse as sp, scipy.sparse.linalg as sl\n"
    "src, reps, nloop = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])\n"
    "if src.startswith('laplace:'):\n"
    "    k = int(src[8:]); T = sp.diags([-1, 2, -1], [-1, 0, 1], shape=(k, k)); I = sp.identity(k)\n"
    "    A = (sp.kron(I, T) + sp.kron(T, I)).tocsc()\n"
    "else:\n"
    "    A = scipy.io.mmread(src).tocsc()\n"
    "n = A.shape[0]; x0 = 1 + (np.arange(n) % 10) / 10.0; b = A @ x0\n"
    "nA = abs(A).sum(axis=1).max()\n"
    "def be(x): return np.abs(b - A @ x).max() / (nA * np.abs(x).max() + np.abs(b).max())\n"
    "best = None\n"
    "for r in range(reps):\n"
    "    t = time.perf_counter(); x = sl.spsolve(A, b); t = time.perf_counter() - t\n"
    "    best = t if best is None or t < best else best\n"
    "print('solve %.6g %.3g' % (best, be(x)))\n"
    "t = time.perf_counter(); f = sl.splu(A)\n"
    "for i in range(nloop): x = f.solve(b)\n"
    "t = time.perf_counter() - t\n"
    "print('loop %.6g %.3g' % (t, be(x)))\n";

static const char octave_script[] =
    "args = argv(); T = load(args{1}); reps = str2num(args{2}); nloop = str2num(args{3});\n"
    "A = spconvert(T); n = rows(A); x0 = 1 + mod((0:n-1)', 10) / 10; b = A * x0;\n"
    "nA = norm(A, inf); best = inf;\n"
    "for r = 1:reps, tic; x = A \\ b; best = min(best, toc); end\n"
    "printf('solve %.6g %.3g\\n', best, norm(b - A*x, inf) / (nA*norm(x, inf) + norm(b, inf)));\n"
    "tic; for i = 1:nloop, x = A \\ b; end; t = toc;\n"
    "printf('loop %.6g %.3g\\n', t, norm(b - A*x, inf) / (nA*norm(x, inf) + norm(b, inf)));\n";

/* Writes text to dir/name; returns the path in out. */
static int write_file(const char *dir, const char *name, const char *text, char *out, size_t len)
{
    FILE *f;
    snprintf(out, len, "%s/%s", dir, name);
    if (!(f = fopen(out, "w"))) return -1;
    fputs(text, f);
    return fclose(f);
}

/* Triplets "i j v" (1-based), with "m n 0" last so spconvert gets the size. */
static int write_triplets(const problem *P, const char *path)
{
    FILE *f = fopen(path, "w");
    int64_t i, k;
    if (!f) return -1;
    for (i = 0; i < P->A.m; i++)
        for (k = P->A.rowptr[i]; k < P->A.rowptr[i + 1]; k++)
            fprintf(f, "%lld %lld %.17g\n", (long long)i + 1, (long long)P->A.colind[k] + 1,
                    P->A.values[k]);
    fprintf(f, "%lld %lld 0\n", (long long)P->A.m, (long long)P->A.n);
    return fclose(f);
}

/* Runs a tool's script; fills solve and loop (time, backward error). */
static int run_tool(const char *cmd, double st[2], double lt[2])
{
    char line[256];
    FILE *p = popen(cmd, "r");
    int got = 0;
    if (!p) return -1;
    while (fgets(line, sizeof line, p)) {
        if (sscanf(line, "solve %lf %lf", &st[0], &st[1]) == 2) got |= 1;
        if (sscanf(line, "loop %lf %lf", &lt[0], &lt[1]) == 2) got |= 2;
    }
    return pclose(p) == 0 && got == 3 ? 0 : -1;
}

/* ---- the table -------------------------------------------------------------------- */

static void row(const char *who, const char *ran, double t, double be, double ratio)
{
    char tb[32], bb[32], rb[32];
    if (t < 0) snprintf(tb, sizeof tb, "%s", "-");
    else snprintf(tb, sizeof tb, "%.4f", t);
    if (isnan(be) || t < 0) snprintf(bb, sizeof bb, "-");
    else snprintf(bb, sizeof bb, "%.1e", be);
    if (ratio > 0) snprintf(rb, sizeof rb, "%.3f", ratio);
    else snprintf(rb, sizeof rb, "-");
    printf("  %-30s %-22s %10s %10s %9s\n", who, ran, tb, bb, rb);
}

static int load_problem(problem *P, const opts *o)
{
    char err[512], path[1024];
    int64_t i;
    if (P->file) {
        snprintf(path, sizeof path, "%s/%s", SILC_SHARED_MATRICES, P->file);
        if (tl_read_mtx(&P->A, path, err, sizeof err)) {
            fprintf(stderr, "backends: %s\n", err);
            return -1;
        }
    } else if (tl_laplacian2d(&P->A, o->grid)) {
        fprintf(stderr, "backends: out of memory building the Laplacian\n");
        return -1;
    }
    P->x0 = malloc((size_t)P->A.n * sizeof *P->x0);
    P->b = malloc((size_t)P->A.m * sizeof *P->b);
    if (!P->x0 || !P->b) return -1;
    for (i = 0; i < P->A.n; i++) P->x0[i] = 1 + (double)(i % 10) / 10;
    tl_csr_matvec(&P->A, P->x0, P->b);
    return 0;
}

/* Best of how many: --reps R, else 3 for the Laplacian (seconds per run) and
 * 10 for the shared matrices (milliseconds per run, where a single burst of
 * load on this shared VM moved a best-of-3 cell by 5-10%). */
static int reps_for(const problem *P, const opts *o)
{
    return o->reps > 0 ? o->reps : P->file ? 10 : 3;
}

/* Sets the condest option of backend b's plugin ("suitesparse" of
 * "suitesparse.klu", "mumps" of "mumps") for the session. */
static void set_condest(silc_context *c, const char *b, const char *value)
{
    char stmt[96];
    snprintf(stmt, sizeof stmt, "set %.*s.condest = %s", (int)strcspn(b, "."), b, value);
    silc_exec(c, stmt);
}

/* How much of the accuracy report a SILC row makes. */
enum report_mode {
    REPORT_FULL,        /* as configured: backward error and condition estimate */
    REPORT_NO_CONDEST,  /* the plugin's condest option false: the Hager-Higham
                           estimate, the one part of the report that is not
                           O(nnz), is not made */
    REPORT_BARE         /* also solve.backward_error = on_request: the library's
                           work and SILC's dispatch, classification and NaN/Inf
                           checks, the backward error computed after the clock
                           stops (by the info this bench reads) */
};

/* One SILC row and, where the library can be called directly, the direct row
 * and the ratio, for nsolve solves with one A.  The two alternate, best of
 * reps each, so that a burst of load on the machine hits both alike.  The
 * rows with less of the report are compared with the same direct call, which
 * computes neither a backward error nor an estimate: REPORT_BARE against it
 * is SILC's own cost, the others add the report's price. */
static void compare_one(silc_context *c, tl_capture *cap, const problem *P, const opts *o,
                        const char *b, enum report_mode mode, int nsolve, double *x)
{
    static const char *const mode_names[] = {"forced", "condest off", "bare (no report)"};
    double (*direct)(const problem *, int, double *) = direct_for(b);
    double be = NAN, t = -1, td = -1, tput, with_put = -1;
    char ran[64], who[64];
    int r, condest_off = mode != REPORT_FULL;
    snprintf(ran, sizeof ran, "%s", b);
    if (condest_off) set_condest(c, b, "false");
    if (mode == REPORT_BARE) silc_exec(c, "set solve.backward_error = on_request");
    for (r = 0; r < reps_for(P, o); r++) {
        double ts = silc_time(c, cap, P, b, nsolve, &be, ran, sizeof ran, &tput), d;
        if (ts < 0) break;
        if (t < 0 || ts < t) t = ts;
        if (with_put < 0 || ts + tput < with_put) with_put = ts + tput;
        if (direct && (d = direct(P, nsolve, x)) >= 0 && (td < 0 || d < td)) td = d;
    }
    /* Back to the defaults (mumps.c, suitesparse.c and config.c declare them). */
    if (condest_off) set_condest(c, b, !strcmp(b, "mumps") ? "true" : "auto");
    if (mode == REPORT_BARE) silc_exec(c, "set solve.backward_error = deferred");
    snprintf(who, sizeof who, "SILC  %s%s", nsolve > 1 ? "loop, " : "",
             !strcmp(b, "default") ? "default" : mode_names[mode]);
    /* Rows with less of the report get a ratio against the same direct call. */
    row(who, ran, t, be, condest_off && td > 0 && t > 0 ? t / td : -1);
    /* The whole price from the user's arrays: the direct call is handed
     * them in its own format, SILC copies them in first. */
    if (mode == REPORT_BARE) row("SILC  bare + put A", ran, with_put, be, td > 0 && t > 0 ? with_put / td : -1);
    if (direct && !condest_off) {
        snprintf(who, sizeof who, "direct %s%s", strchr(b, '.') ? strchr(b, '.') + 1 : b,
                 nsolve > 1 ? ", factor once" : "");
        row(who, b, td, td >= 0 ? tl_backward_error(&P->A, x, P->b) : NAN, td > 0 && t > 0 ? t / td : -1);
    }
    fflush(stdout);
}

/* Backend b's rows: SILC as configured against the direct call, then, where
 * there is a direct call, SILC with less of the report against it (bare only
 * for one solve: in a loop every solve but the first defers its backward
 * error anyway). */
static void compare(silc_context *c, tl_capture *cap, const problem *P, const opts *o,
                    const char *b, int nsolve, double *x)
{
    if (!strcmp(b, "suitesparse.cholmod") && !P->spd) return;
    compare_one(c, cap, P, o, b, REPORT_FULL, nsolve, x);
    if (!direct_for(b)) return;
    compare_one(c, cap, P, o, b, REPORT_NO_CONDEST, nsolve, x);
    if (nsolve == 1) compare_one(c, cap, P, o, b, REPORT_BARE, nsolve, x);
}

static void bench_problem(silc_context *c, tl_capture *cap, problem *P, const opts *o)
{
    static const char *const silc_backends[] = {"default", "suitesparse.umfpack", "suitesparse.klu",
                                                "suitesparse.cholmod", "mumps", "lapack", "reference"};
    char src[1100], cmd[2400], script[512];
    double *x = malloc((size_t)P->A.n * sizeof *x), st[2], lt[2], scipy_lt[2];
    int have_scipy = 0, have_octave = 0;
    size_t i;
    if (!x) return;
    tl_put_vector(c, "b", P->A.n, P->b);
    printf("\n%s: n = %lld, nnz = %lld%s\n", P->name, (long long)P->A.n, (long long)P->A.nnz,
           P->spd ? ", SPD" : "");
    printf("  %-30s %-22s %10s %10s %9s\n", "one solve", "backend", "seconds", "bwd err",
           "SILC/dir");
    for (i = 0; i < sizeof silc_backends / sizeof silc_backends[0]; i++) {
        if (!strcmp(silc_backends[i], "lapack") && P->A.n > 5000) continue;
        compare(c, cap, P, o, silc_backends[i], 1, x);
    }
    if (P->file) snprintf(src, sizeof src, "%s/%s", SILC_SHARED_MATRICES, P->file);
    else snprintf(src, sizeof src, "laplace:%lld", (long long)o->grid);
    if (o->scipy) {
        write_file(o->tmpdir, "bench.py", scipy_script, script, sizeof script);
        snprintf(cmd, sizeof cmd, "/usr/bin/python3 %s %s %d %d", script, src, reps_for(P, o), o->loop);
        have_scipy = run_tool(cmd, st, scipy_lt) == 0;
        if (have_scipy) row("SciPy spsolve", "SuperLU (COLAMD)", st[0], st[1], -1);
        else row("SciPy spsolve", "failed", -1, NAN, -1);
    }
    if (o->octave) {
        char trip[512];
        write_file(o->tmpdir, "bench.m", octave_script, script, sizeof script);
        snprintf(trip, sizeof trip, "%s/A.txt", o->tmpdir);
        if (write_triplets(P, trip) == 0) {
            snprintf(cmd, sizeof cmd, "octave-cli -q %s %s %d %d 2>/dev/null", script, trip, reps_for(P, o),
                     o->loop);
            have_octave = run_tool(cmd, st, lt) == 0;
            if (have_octave) row("Octave A\\b", "Octave", st[0], st[1], -1);
            else row("Octave A\\b", "failed", -1, NAN, -1);
        }
    }

    printf("  %-30s %-22s %10s %10s %9s\n", "", "", "", "", "");
    printf("  %d solves, same A (factor reuse)\n", o->loop);
    for (i = 0; i < sizeof silc_backends / sizeof silc_backends[0]; i++)
        if (strcmp(silc_backends[i], "lapack") != 0 && strcmp(silc_backends[i], "reference") != 0)
            compare(c, cap, P, o, silc_backends[i], o->loop, x);
    if (have_scipy) row("SciPy splu + solve loop", "SuperLU (COLAMD)", scipy_lt[0], scipy_lt[1], -1);
    if (have_octave) row("Octave loop of A\\b", "Octave", lt[0], lt[1], -1);
    silc_exec(c, "clear A b x");
    free(x);
}

/* ---- the diffusion loop -------------------------------------------------------- */

#define DIFF_DT 1e-3

static const char scipy_diffusion[] =
    "import sys, time, numpy as np, scipy.sparse as sp, scipy.sparse.linalg as sl\n"
    "k, nloop, dt = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])\n"
    "h = 1.0 / (k + 1); s = dt / (2 * h * h)\n"
    "T = sp.diags([-1, 2, -1], [-1, 0, 1], shape=(k, k)); I = sp.identity(k)\n"
    "L = sp.kron(I, T) + sp.kron(T, I); E = sp.identity(k * k)\n"
    "A = (E + s * L).tocsc(); B = (E - s * L).tocsr()\n"
    "g = (np.arange(1, k + 1) * h); blk = ((g > 0.4) & (g < 0.6)).astype(float)\n"
    "u = np.kron(blk, blk)\n"
    "t = time.perf_counter(); c = time.process_time(); f = sl.splu(A)\n"
    "for i in range(nloop): v = B @ u; u = f.solve(v)\n"
    "t = time.perf_counter() - t; c = time.process_time() - c\n"
    "nA = abs(A).sum(axis=1).max()\n"
    "be = np.abs(v - A @ u).max() / (nA * np.abs(u).max() + np.abs(v).max())\n"
    "print('diffusion %.6g %.3g %.12g %.6g' % (t, be, u.sum(), c))\n";

static const char octave_diffusion[] =
    "args = argv(); k = str2num(args{1}); nloop = str2num(args{2}); dt = str2num(args{3});\n"
    "h = 1 / (k + 1); s = dt / (2 * h * h); e = ones(k, 1);\n"
    "T = spdiags([-e, 2 * e, -e], -1:1, k, k); I = speye(k); L = kron(I, T) + kron(T, I);\n"
    "A = speye(k * k) + s * L; B = speye(k * k) - s * L;\n"
    "g = (1:k)' * h; blk = double(g > 0.4 & g < 0.6); u = kron(blk, blk);\n"
    "c = cputime; tic; for i = 1:nloop, v = B * u; u = A \\ v; end; t = toc; c = cputime - c;\n"
    "be = norm(v - A * u, inf) / (norm(A, inf) * norm(u, inf) + norm(v, inf));\n"
    "printf('diffusion %.6g %.3g %.12g %.6g\\n', t, be, sum(u), c);\n";

/* A diffusion row: wall seconds, backward error, sum(u), CPU seconds of the
 * process (on this shared 2-core VM the wall clock also counts other jobs'
 * time slices; every tool here computes on one thread). */
enum { D_WALL, D_BE, D_SUM, D_CPU, D_FIRST, D_N }; /* D_FIRST: CPU s of the first step (SILC), the
                                                  factorization's (direct CHOLMOD) */

/* Runs a tool's diffusion script: its row. */
static int run_diffusion_tool(const char *cmd, double out[D_N])
{
    char line[256];
    FILE *p = popen(cmd, "r");
    int got = 0;
    if (!p) return -1;
    while (fgets(line, sizeof line, p))
        if (sscanf(line, "diffusion %lf %lf %lf %lf", &out[D_WALL], &out[D_BE], &out[D_SUM], &out[D_CPU]) == 4)
            got = 1;
    return pclose(p) == 0 && got ? 0 : -1;
}

/* One SILC run of the loop in a fresh session (setup: statements run
 * before it, e.g. the tuner's), with the example's matrices and initial
 * field (diffusion_common.h); time of the loop, last step's backward error
 * and sum(u) into out, what ran the last solve into ran[64]. */
static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int silc_diffusion(int64_t k, int steps, const char *setup, double out[D_N], char ran[64])
{
    double h = diff2d_h(k), t0, c0, *u, *sum;
    silc_envelope_t A = {0}, B = {0}, U = {0};
    silc_context *c = NULL;
    tl_capture cap = {0};
    int64_t m, n;
    int step, rc = -1;
    if (!(u = malloc((size_t)(k * k) * sizeof *u))) return -1;
    diff2d_initial(k, u);
    if (diff_shifted_laplacian(2, k, h, -DIFF_DT / 2, &A) || diff_shifted_laplacian(2, k, h, DIFF_DT / 2, &B) ||
        silc_envelope_dense(&U, k * k, 1, u) || silc_open(&c, NULL)) {
        free(u);
        silc_envelope_free(&A);
        silc_envelope_free(&B);
        silc_envelope_free(&U);
        return -1;
    }
    free(u);
    tl_capture_attach(c, &cap);
    if (silc_put(c, "A", &A) || silc_put(c, "B", &B) || silc_put(c, "u", &U) || (setup && silc_exec(c, setup)))
        goto done;
    t0 = tl_now();
    c0 = cpu_now();
    for (step = 0; step < steps; step++) {
        if (silc_exec(c, "u = A \\ (B * u)")) goto done;
        if (step == 0) out[D_FIRST] = cpu_now() - c0;
    }
    out[D_WALL] = tl_now() - t0;
    out[D_CPU] = cpu_now() - c0;
    {
        const char *info = tl_info(c, &cap, "u");
        const char *p = strstr(info, "  backend: ");
        out[D_BE] = tl_field(info, "backward error");
        if (p) sscanf(p + 11, "%63s", ran);
    }
    if (silc_exec(c, "s = sum(u)") || !(sum = tl_get_dense(c, "s", &m, &n))) goto done;
    out[D_SUM] = sum[0];
    free(sum);
    rc = 0;
done:
    if (rc) fprintf(stderr, "backends: diffusion: %s\n", silc_context_errmsg(c));
    silc_close(&c);
    tl_capture_free(&cap);
    silc_envelope_free(&A);
    silc_envelope_free(&B);
    silc_envelope_free(&U);
    return rc;
}

/* The same loop with CHOLMOD called directly, what a C programmer holding
 * CSR arrays would write: the plugin's settings (upper triangle of the
 * symmetric CSR arrays, final_ll, CHOLMOD's ordering and supernodal rule),
 * cholmod_l_analyze and cholmod_l_factorize once, then per step v = B u
 * (a plain CSR loop) and cholmod_l_solve2 reusing its X, Y and E.  Timed
 * from the analysis to the last step, as SILC's rows (which also start
 * without a factorization); the factorization's own CPU seconds go to
 * out[D_FIRST].  The baseline that tells SILC's cost from CHOLMOD's. */
static int direct_cholmod_diffusion(int64_t k, int steps, double out[D_N])
{
    double h = diff2d_h(k), t0, c0, *u = NULL, *v = NULL, num = 0, den_a = 0, den_u = 0, den_v = 0;
    silc_envelope_t A = {0}, B = {0};
    cholmod_common cc;
    cholmod_sparse S;
    cholmod_dense V, *X = NULL, *Y = NULL, *E = NULL;
    cholmod_factor *L = NULL;
    int64_t n = k * k, i, p;
    int step, rc = -1;
    cholmod_l_start(&cc);
    cc.final_ll = 1; /* as the plugin (ss_start) */
    if (diff_shifted_laplacian(2, k, h, -DIFF_DT / 2, &A) || diff_shifted_laplacian(2, k, h, DIFF_DT / 2, &B) ||
        !(u = malloc((size_t)n * sizeof *u)) || !(v = malloc((size_t)n * sizeof *v)))
        goto done;
    diff2d_initial(k, u);
    memset(&S, 0, sizeof S);
    S.nrow = S.ncol = (size_t)n;
    S.nzmax = (size_t)A.nnz;
    S.p = A.rowptr;
    S.i = A.colind;
    S.x = A.values;
    S.stype = 1;
    S.itype = CHOLMOD_LONG;
    S.xtype = CHOLMOD_REAL;
    S.dtype = CHOLMOD_DOUBLE;
    S.sorted = S.packed = 1;
    memset(&V, 0, sizeof V);
    V.nrow = V.d = V.nzmax = (size_t)n;
    V.ncol = 1;
    V.x = v;
    V.xtype = CHOLMOD_REAL;
    V.dtype = CHOLMOD_DOUBLE;
    t0 = tl_now();
    c0 = cpu_now();
    if (!(L = cholmod_l_analyze(&S, &cc)) || !cholmod_l_factorize(&S, L, &cc) || cc.status != CHOLMOD_OK) goto done;
    out[D_FIRST] = cpu_now() - c0;
    for (step = 0; step < steps; step++) {
        for (i = 0; i < n; i++) {
            double t = 0;
            for (p = B.rowptr[i]; p < B.rowptr[i + 1]; p++) t += B.values[p] * u[B.colind[p]];
            v[i] = t;
        }
        if (!cholmod_l_solve2(CHOLMOD_A, L, &V, NULL, &X, NULL, &Y, &E, &cc)) goto done;
        memcpy(u, X->x, (size_t)n * sizeof *u);
    }
    out[D_WALL] = tl_now() - t0;
    out[D_CPU] = cpu_now() - c0;
    /* the last step's backward error, inf-norms, as the other tools' */
    for (i = 0; i < n; i++) {
        double t = 0, ra = 0;
        for (p = A.rowptr[i]; p < A.rowptr[i + 1]; p++) t += A.values[p] * u[A.colind[p]], ra += fabs(A.values[p]);
        num = fmax(num, fabs(v[i] - t));
        den_a = fmax(den_a, ra);
        den_u = fmax(den_u, fabs(u[i]));
        den_v = fmax(den_v, fabs(v[i]));
    }
    out[D_BE] = num / (den_a * den_u + den_v);
    out[D_SUM] = 0;
    for (i = 0; i < n; i++) out[D_SUM] += u[i];
    rc = 0;
done:
    if (rc) fprintf(stderr, "backends: direct CHOLMOD diffusion failed (status %d)\n", cc.status);
    cholmod_l_free_dense(&X, &cc);
    cholmod_l_free_dense(&Y, &cc);
    cholmod_l_free_dense(&E, &cc);
    cholmod_l_free_factor(&L, &cc);
    cholmod_l_finish(&cc);
    free(u);
    free(v);
    silc_envelope_free(&A);
    silc_envelope_free(&B);
    return rc;
}

/* res is a better run than best (none yet: best[D_WALL] < 0): less CPU time,
 * the figure of merit on this shared machine, where wall time also counts
 * other jobs' time slices. */
static int better(const double res[D_N], const double best[D_N])
{
    return best[D_WALL] < 0 || res[D_CPU] < best[D_CPU];
}

static void diffusion_row(const char *who, const char *ran, const double r[D_N], const double silc[D_N])
{
    printf("  %-40s %-22s %9.4f %9.4f %9.1e %17.12g %8.2f %8.2f\n", who, ran, r[D_WALL], r[D_CPU], r[D_BE],
           r[D_SUM], silc[D_WALL] > 0 ? r[D_WALL] / silc[D_WALL] : NAN,
           silc[D_CPU] > 0 ? r[D_CPU] / silc[D_CPU] : NAN);
}

static void bench_diffusion(const opts *o)
{
    /* MUMPS forced, for the per-step floor of the mixed-precision route
     * (docs/backends.md): the double solve phase, the single one alone
     * (solve.refine = 0: its backward error is what one single solve
     * gives), and single refined to tune.accuracy = 1e-8 (refine.c stops
     * there), with MUMPS's amalgamation and with fronts of >= 12 pivots. */
    static const struct {
        const char *who, *setup;
    } forced[] = {
        {"SILC, mumps (double)", "set dispatch.solve.sparse.spd = mumps"},
        {"SILC, mumps, amalgamation 12", "set dispatch.solve.sparse.spd = mumps; set mumps.amalgamation = 12"},
        {"SILC, mumps single, no refinement",
         "set dispatch.solve.sparse.spd = mumps; set mumps.precision = single; set solve.refine = 0"},
        {"SILC, mumps single, refined to 1e-8",
         "set dispatch.solve.sparse.spd = mumps; set mumps.precision = single; set tune.accuracy = 1e-8"},
        {"SILC, mumps single, amalg. 12, no ref.",
         "set dispatch.solve.sparse.spd = mumps; set mumps.precision = single; set mumps.amalgamation = 12; "
         "set solve.refine = 0"},
        {"SILC, mumps single, amalg. 12, to 1e-8",
         "set dispatch.solve.sparse.spd = mumps; set mumps.precision = single; set mumps.amalgamation = 12; "
         "set tune.accuracy = 1e-8"},
    };
    enum { NFORCED = sizeof forced / sizeof forced[0] };
    int64_t k = o->grid_given ? o->grid : 200;
    int r, f, reps = o->reps > 0 ? o->reps : 3;
    char setup[320], cmd[1024], script[512], wisdom[64], ran[2 + NFORCED][64] = {""};
    double best[2 + NFORCED][D_N], res[D_N], direct[D_N] = {-1, 0, 0, 0, 0};
    for (f = 0; f < 2 + NFORCED; f++) memset(best[f], 0, sizeof best[f]), best[f][D_WALL] = -1;
    printf("\ndiffusion loop: %lld x %lld grid (%lld unknowns), Crank-Nicolson, dt = %g, %d steps\n",
           (long long)k, (long long)k, (long long)(k * k), DIFF_DT, o->loop);
    printf("  %-40s %-22s %9s %9s %9s %17s %8s %8s\n", "", "last solve by", "wall s", "CPU s", "bwd err", "sum(u)",
           "/ SILC", "CPU / S.");
    snprintf(wisdom, sizeof wisdom, "/tmp/silc-bench-diffusion-wisdom-%ld", (long)getpid());
    /* Best of reps; the tuned run starts from no wisdom every time. */
    for (r = 0; r < reps; r++) {
        char rn[64] = "";
        remove(wisdom);
        snprintf(setup, sizeof setup,
                 "set tune.wisdom = %s; set tune.threads = auto; set tune.accuracy = 1e-8; tune on %d", wisdom,
                 o->loop);
        if (silc_diffusion(k, o->loop, NULL, res, rn) == 0 && better(res, best[0]))
            memcpy(best[0], res, sizeof res), snprintf(ran[0], sizeof ran[0], "%s", rn);
        if (silc_diffusion(k, o->loop, setup, res, rn) == 0 && better(res, best[1]))
            memcpy(best[1], res, sizeof res), snprintf(ran[1], sizeof ran[1], "%s", rn);
        if (direct_cholmod_diffusion(k, o->loop, res) == 0 && better(res, direct))
            memcpy(direct, res, sizeof res);
        for (f = 0; o->mumps_rows && f < NFORCED; f++)
            if (silc_diffusion(k, o->loop, forced[f].setup, res, rn) == 0 &&
                better(res, best[2 + f]))
                memcpy(best[2 + f], res, sizeof res), snprintf(ran[2 + f], sizeof ran[2 + f], "%s", rn);
    }
    remove(wisdom);
    diffusion_row("SILC, default config", ran[0], best[0], best[0]);
    diffusion_row("SILC, tune on, tune.accuracy = 1e-8", ran[1], best[1], best[0]);
    if (direct[0] >= 0) diffusion_row("direct CHOLMOD (analyze+factor, solve2)", "CHOLMOD", direct, best[0]);
    for (f = 0; o->mumps_rows && f < NFORCED; f++) diffusion_row(forced[f].who, ran[2 + f], best[2 + f], best[0]);
    if (o->scipy) {
        write_file(o->tmpdir, "diffusion.py", scipy_diffusion, script, sizeof script);
        snprintf(cmd, sizeof cmd, "/usr/bin/python3 %s %lld %d %g", script, (long long)k, o->loop, DIFF_DT);
        double sp[D_N] = {-1, 0, 0, 0, 0};
        for (r = 0; r < reps; r++) /* best of reps, as SILC's rows */
            if (run_diffusion_tool(cmd, res) == 0 && better(res, sp)) memcpy(sp, res, sizeof res);
        if (sp[D_WALL] >= 0) diffusion_row("SciPy splu once + loop", "SuperLU (COLAMD)", sp, best[0]);
        else printf("  SciPy: failed\n");
    }
    if (o->octave) {
        write_file(o->tmpdir, "diffusion.m", octave_diffusion, script, sizeof script);
        snprintf(cmd, sizeof cmd, "octave-cli -q %s %lld %d %g 2>/dev/null", script, (long long)k, o->loop, DIFF_DT);
        if (run_diffusion_tool(cmd, res) == 0) diffusion_row("Octave loop of A \\ (B*u)", "Octave", res, best[0]);
        else printf("  Octave: failed\n");
    }
    printf("  (last columns: wall and CPU seconds / SILC default's; below 1 is faster than SILC; best of the runs by CPU;\n   Octave runs once)\n");
    /* Where the time goes: the first step (SILC: an AMG solve or the
     * factorization, with the condition estimate; direct: analysis and
     * factorization) and the mean of the others. */
    printf("  CPU per step: first, then each of the %d others (ms)\n", o->loop - 1);
    for (f = 0; f < 2; f++)
        if (best[f][D_WALL] >= 0)
            printf("    %-38s %8.1f  %7.2f\n", f ? "SILC, tune on" : "SILC, default", 1e3 * best[f][D_FIRST],
                   o->loop > 1 ? 1e3 * (best[f][D_CPU] - best[f][D_FIRST]) / (o->loop - 1) : 0);
    if (direct[0] >= 0)
        printf("    %-38s %8.1f  %7.2f   (first = analysis + factorization; then B*u + cholmod_l_solve2)\n",
               "direct CHOLMOD", 1e3 * direct[D_FIRST], 1e3 * (direct[D_CPU] - direct[D_FIRST]) / o->loop);
}

static int usage(void)
{
    fprintf(stderr, "usage: backends [--scipy] [--octave] [--install] [--reps R] [--loop N] [--grid K] "
                    "[--only NAME] [--mumps-rows]\n");
    return 2;
}

/* --install: runs apt-get for package when the probe command fails. */
static void install_if_missing(const char *probe, const char *package)
{
    char cmd[256];
    if (system(probe) == 0) return;
    printf("installing %s (apt-get; --install)\n", package);
    fflush(stdout);
    snprintf(cmd, sizeof cmd, "DEBIAN_FRONTEND=noninteractive apt-get install -y -q %s > /dev/null", package);
    if (system(cmd) != 0) fprintf(stderr, "backends: '%s' failed; its rows will say failed\n", cmd);
}

int main(int argc, char **argv)
{
    problem probs[] = {{"laplace2d", NULL, 1, {0}, NULL, NULL},
                       {"bcsstk16", "bcsstk16.mtx", 1, {0}, NULL, NULL},
                       {"memplus", "memplus.mtx", 0, {0}, NULL, NULL},
                       {"bayer10", "bayer10.mtx", 0, {0}, NULL, NULL}};
    opts o;
    silc_context *c = NULL;
    tl_capture cap = {0};
    size_t i;
    int a;
    memset(&o, 0, sizeof o);
    o.reps = 0; /* reps_for */
    o.loop = 100;
    o.grid = 500;
    for (a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--scipy")) o.scipy = 1;
        else if (!strcmp(argv[a], "--octave")) o.octave = 1;
        else if (!strcmp(argv[a], "--install")) o.install = 1;
        else if (!strcmp(argv[a], "--reps") && a + 1 < argc) o.reps = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--loop") && a + 1 < argc) o.loop = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--grid") && a + 1 < argc) o.grid = atoll(argv[++a]), o.grid_given = 1;
        else if (!strcmp(argv[a], "--only") && a + 1 < argc) o.only = argv[++a];
        else if (!strcmp(argv[a], "--mumps-rows")) o.mumps_rows = 1;
        else return usage();
    }
    if (o.reps < 0 || o.loop < 1 || o.grid < 2) return usage();
    if (o.install && o.scipy)
        install_if_missing("/usr/bin/python3 -c 'import scipy' > /dev/null 2>&1", "python3-scipy");
    if (o.install && o.octave) install_if_missing("command -v octave-cli > /dev/null 2>&1", "octave");
    /* Before any BLAS is loaded: one thread everywhere, including the tools. */
    setenv("OPENBLAS_NUM_THREADS", "1", 0);
    setenv("OMP_NUM_THREADS", "1", 0);
    snprintf(o.tmpdir, sizeof o.tmpdir, "/tmp/silc-bench-XXXXXX");
    if ((o.scipy || o.octave) && !mkdtemp(o.tmpdir)) {
        perror("backends: mkdtemp");
        return 1;
    }
    if (silc_open(&c, NULL)) {
        fprintf(stderr, "backends: %s\n", c ? silc_context_errmsg(c) : silc_errmsg());
        return 1;
    }
    tl_capture_attach(c, &cap);
    {
        char best[64];
        int lap = reps_for(&probs[0], &o), shared = reps_for(&probs[1], &o);
        if (lap == shared) snprintf(best, sizeof best, "%d", lap);
        else snprintf(best, sizeof best, "%d (laplace2d) or %d (shared matrices)", lap, shared);
        printf("SILC direct-solver backends; OPENBLAS_NUM_THREADS=%s; best of %s; seconds are wall time\n",
               getenv("OPENBLAS_NUM_THREADS"), best);
    }
    for (i = 0; i < sizeof probs / sizeof probs[0]; i++) {
        problem *P = &probs[i];
        if (o.only && strcmp(o.only, P->name)) continue;
        if (load_problem(P, &o) == 0) bench_problem(c, &cap, P, &o);
        silc_envelope_free(&P->A);
        free(P->b);
        free(P->x0);
    }
    if (!o.only || !strcmp(o.only, "diffusion")) bench_diffusion(&o);
    silc_close(&c);
    tl_capture_free(&cap);
    if (o.scipy || o.octave) {
        char path[512];
        const char *const files[] = {"bench.py", "bench.m", "A.txt", "diffusion.py", "diffusion.m"};
        for (i = 0; i < sizeof files / sizeof files[0]; i++) {
            snprintf(path, sizeof path, "%s/%s", o.tmpdir, files[i]);
            remove(path);
        }
        rmdir(o.tmpdir);
    }
    return 0;
}
