/*
 * test_mpi.c -- distributed SILC checked against the sequential engine.
 *
 *     mpirun -np P test_mpi spmd      an MPI program: silc_open_mpi, each rank
 *                                     its own rows (silc_put_rows/get_rows,
 *                                     silc_get_rows_complex)
 *     test_mpi server                 a plain client of SILC_SERVER, which is
 *                                     `mpirun -np P silcd --mpi` (tests/mpi.cmake)
 *
 * Both modes run the same checks:
 *   - solves of shared matrices (SPD and unsymmetric) by the distributed
 *     backends -- petsc CG + BoomerAMG, GMRES + block Jacobi, LU through
 *     MUMPS; mumps -- agree with the sequential engine's solve within
 *     max(1, cond2) * tol (cond2 from the matrices' README);
 *   - the backward error `info` shows for a loose GMRES solve of the
 *     unsymmetric orsirr_1 equals the one computed here from the whole A,
 *     b and x to its three digits;
 *   - the 2-D diffusion loop `u = A \ (B * u)` gives the embedded engine's
 *     sum(u) to 1e-12 relative, and from the second step on `info u` says
 *     no matrix moved;
 *   - complex values (young1c, 2 doubles an entry): split, stored, gathered
 *     (silc_get_complex), a CSR and a dense product, sum, dot and the norms
 *     agree with the embedded engine's to rounding; `x = A \ b` runs on
 *     MPI MUMPS (zmumps) with the right-hand side and solution distributed
 *     (ICNTL(20)=10, ICNTL(21)=1), equals the embedded complex solve to
 *     rounding and x_true to cond x eps; each rank's rows of x come back
 *     complex (silc_get_rows_complex: its own block in SPMD mode, the whole
 *     value from a server), equal to those rows of the embedded solve and of
 *     x_true within n eps cond2, while silc_get_rows refuses them, naming
 *     the complex call; PETSc (a real build) declines it and the chain moves
 *     on;
 *   - the bytes a solve moves: nothing gathered, only the solution's
 *     entries MUMPS leaves off their row block (the count its report gives),
 *     16 bytes each for a complex column, 8 for a real one;
 *   - SPMD only: ranks EXECing different texts get an error naming the rank,
 *     a bad block on one rank is an error on every rank naming it, and the
 *     context works afterwards (nobody hangs: ctest's timeout bounds it).
 * The reference solves run in an ordinary embedded context of this process.
 */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "diffusion_common.h"
#include "testlib.h"

#ifdef SILC_TEST_SPMD
#include <mpi.h>

#include "silc_mpi.h"
#endif

static int rank = 0, nranks = 1, spmd = 0;
static int engine_ranks = 1; /* the ranks the engine runs on: ours (SPMD) or the server's */

/* The same verdict on every rank (a check failed anywhere fails everywhere). */
static int all_ok(int ok)
{
#ifdef SILC_TEST_SPMD
    if (spmd) MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
#endif
    return ok;
}

static double max_all(double x)
{
#ifdef SILC_TEST_SPMD
    if (spmd) MPI_Allreduce(MPI_IN_PLACE, &x, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
#endif
    return x;
}

/* This rank's rows of an m-row value: PETSc's even split. */
static void my_rows(int64_t m, int64_t *first, int64_t *count)
{
    *count = m / nranks + (rank < m % nranks);
    *first = rank * (m / nranks) + (rank < m % nranks ? rank : m % nranks);
}

/* Rows [first, first + count) of a CSR envelope as a new envelope. */
static int csr_rows(silc_envelope_t *out, const silc_envelope_t *A, int64_t first, int64_t count)
{
    int64_t lo = A->rowptr[first], i, rc;
    int64_t *rp = malloc((size_t)(count + 1) * sizeof *rp);
    if (!rp) return -1;
    for (i = 0; i <= count; i++) rp[i] = A->rowptr[first + i] - lo;
    rc = silc_envelope_is_complex(A) ? silc_envelope_csr_complex(out, count, A->n, rp, A->colind + lo, A->values + 2 * lo)
                                     : silc_envelope_csr(out, count, A->n, rp, A->colind + lo, A->values + lo);
    free(rp);
    return (int)rc;
}

/* Puts a whole envelope: each rank its rows in SPMD mode, whole to a server. */
static int put_dist(silc_context *c, const char *name, const silc_envelope_t *e)
{
    silc_envelope_t blk;
    int64_t first, count;
    int rc;
    if (!spmd) return silc_put(c, name, e);
    my_rows(e->m, &first, &count);
    memset(&blk, 0, sizeof blk);
    if ((e->format & ~SILC_COMPLEX) == SILC_CSR) {
        if (csr_rows(&blk, e, first, count)) return -1;
    } else { /* dense, column-major: each column's rows [first, first + count) */
        int w = silc_envelope_is_complex(e) ? 2 : 1;
        double *v = malloc((size_t)(count * e->n * w + 1) * sizeof *v);
        int64_t j;
        if (!v) return -1;
        for (j = 0; j < e->n; j++)
            memcpy(v + j * count * w, e->values + (first + j * e->m) * w, (size_t)(count * w) * sizeof *v);
        rc = w == 2 ? silc_envelope_dense_complex(&blk, count, e->n, v) : silc_envelope_dense(&blk, count, e->n, v);
        free(v);
        if (rc) return -1;
    }
    rc = silc_put_rows(c, name, first, &blk);
    silc_envelope_free(&blk);
    return rc;
}

/* The whole vector `name` (n entries) in x: gathered by the caller's rows. */
static int get_whole(silc_context *c, const char *name, double *x, int64_t n)
{
    silc_envelope_t e;
    int64_t first = 0;
    int rc;
    memset(&e, 0, sizeof e);
    if (!spmd) return tl_get_vec(c, name, x, n);
    if (silc_get_rows(c, &e, &first, name)) return -1;
    memset(x, 0, (size_t)n * sizeof *x);
    rc = e.m + first <= n ? silc_envelope_to_dense(&e, x + first) : -1;
    silc_envelope_free(&e);
#ifdef SILC_TEST_SPMD
    MPI_Allreduce(MPI_IN_PLACE, x, (int)n, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
#endif
    return rc;
}

/* The whole complex value `name` (m x n) in z, 2 m n doubles: gathered to
 * every rank in SPMD mode (silc_get_complex), to the client from a server. */
static int get_complex(silc_context *c, const char *name, double *z, int64_t m, int64_t n)
{
    silc_envelope_t e;
    int rc;
    memset(&e, 0, sizeof e);
    if (silc_get_complex(c, &e, name)) return -1;
    rc = e.m == m && e.n == n && silc_envelope_is_complex(&e) && e.format == (SILC_DENSE | SILC_COMPLEX) ? 0 : -1;
    if (!rc) memcpy(z, e.values, (size_t)(2 * m * n) * sizeof *z);
    silc_envelope_free(&e);
    return rc;
}

/* The real scalar `name`. */
static int get_scalar(silc_context *c, const char *name, double *v)
{
    silc_envelope_t e;
    int rc;
    memset(&e, 0, sizeof e);
    if (silc_get(c, &e, name)) return -1;
    rc = e.m == 1 && e.n == 1 ? silc_envelope_to_dense(&e, v) : -1;
    silc_envelope_free(&e);
    return rc;
}

/* max |x - y| / max |y| over n complex entries. */
static double complex_rel_diff(const double *x, const double *y, int64_t n)
{
    double d = 0, s = 0;
    int64_t i;
    for (i = 0; i < n; i++) {
        d = fmax(d, hypot(x[2 * i] - y[2 * i], x[2 * i + 1] - y[2 * i + 1]));
        s = fmax(s, hypot(y[2 * i], y[2 * i + 1]));
    }
    return s > 0 ? d / s : d;
}

/* The count MUMPS's report gives of the solution entries that changed rank
 * ("..., K entries of each column moved to their row blocks"), -1 if none. */
static long long mumps_moved_entries(silc_context *c, tl_capture *cap, const char *name)
{
    const char *t = tl_info(c, cap, name), *p = strstr(t, "entries of each column moved");
    if (!p) return -1;
    while (p > t && p[-1] == ' ') p--;
    while (p > t && p[-1] >= '0' && p[-1] <= '9') p--;
    return atoll(p);
}

typedef struct solve_case {
    const char *file;
    double cond2;           /* from the matrices' README */
    const char *options;    /* per-call options of solve() */
    double tol;             /* relative agreement per unit of condition */
} solve_case;

/* Bytes of matrices the statement that bound `name` moved, from `info`
 * ("... moved between ranks by the statement: M bytes of matrices, V bytes
 * of vectors"); the vectors' count in *vectors when asked. */
static long long moved_bytes(silc_context *c, tl_capture *cap, const char *name, long long *vectors)
{
    const char *t = tl_info(c, cap, name), *p = strstr(t, "moved between ranks by the statement: "), *q;
    if (vectors) *vectors = -1;
    if (!p) return -1;
    p += strlen("moved between ranks by the statement: ");
    q = strstr(p, "matrices, ");
    if (vectors && q) *vectors = atoll(q + strlen("matrices, "));
    return atoll(p);
}

static long long matrix_bytes(silc_context *c, tl_capture *cap, const char *name)
{
    return moved_bytes(c, cap, name, NULL);
}

/* The backward error `info` shows for a distributed solve against the one
 * computed here from the whole A, b and x, ||b - A x||_inf / (||A||_inf
 * ||x||_inf + ||b||_inf).  A loose GMRES tolerance keeps the residual far
 * above rounding, so the two agree to the three digits shown.  orsirr_1 is
 * not symmetric: its ||A||_1 is 6 % above its ||A||_inf, which the core
 * takes from the residual's own pass over the row blocks (dist.c). */
static void check_backward_error(silc_context *c, tl_capture *cap)
{
    char path[1024], err[256], stmt[512];
    silc_envelope_t A;
    double *x = NULL, shown = -1, nR = 0, nA = 0, nX = 0, nB = 0, be;
    const char *t, *p;
    int64_t n, i, k;
    int ok;
    snprintf(path, sizeof path, "%s/orsirr_1.mtx", SILC_SHARED_MATRICES);
    memset(&A, 0, sizeof A);
    ok = tl_read_mtx(&A, path, err, sizeof err) == 0;
    CHECK(all_ok(ok), "orsirr_1: %s", err);
    if (!ok) return;
    n = A.m;
    x = calloc((size_t)n, sizeof *x);
    snprintf(stmt, sizeof stmt, "b = A * ones(%lld, 1); xl = solve(A, b, \"backend = petsc; petsc.options = "
             "-ksp_type gmres -pc_type bjacobi -ksp_rtol 1e-6\")", (long long)n);
    ok = x && put_dist(c, "A", &A) == 0 && silc_exec(c, stmt) == 0;
    CHECK(all_ok(ok), "orsirr_1, loose GMRES: %s", silc_context_errmsg(c));
    t = ok ? tl_info(c, cap, "xl") : "";
    p = strstr(t, "backward error: ");
    if (p) shown = atof(p + strlen("backward error: "));
    ok = ok && get_whole(c, "xl", x, n) == 0;
    if (all_ok(ok)) {
        for (i = 0; i < n; i++) {
            double r = 0, a = 0, bi = 0; /* b_i = sum_k a_ik (b = A * ones) */
            for (k = A.rowptr[i]; k < A.rowptr[i + 1]; k++) {
                r += A.values[k] * (1 - x[A.colind[k]]);
                a += fabs(A.values[k]);
                bi += A.values[k];
            }
            nR = fmax(nR, fabs(r));
            nA = fmax(nA, a);
            nB = fmax(nB, fabs(bi));
            nX = fmax(nX, fabs(x[i]));
        }
        be = nR / (nA * nX + nB);
        CHECK(all_ok(be > 1e-12 && fabs(shown - be) <= 0.01 * be),
              "orsirr_1 on %d ranks, loose GMRES: info shows backward error %.3g, computed here %.4g:\n%s",
              engine_ranks, shown, be, t);
        if (rank == 0) printf("  orsirr_1 loose GMRES: backward error %.3g shown, %.4g computed here\n", shown, be);
    }
    free(x);
    silc_envelope_free(&A);
}

static void check_solve(silc_context *c, silc_context *ref, tl_capture *cap, const solve_case *k)
{
    char path[1024], err[256], stmt[512];
    silc_envelope_t A;
    double *x = NULL, *xr = NULL, d = 0, s = 0, bound;
    int64_t n, i;
    int ok;
    snprintf(path, sizeof path, "%s/%s", SILC_SHARED_MATRICES, k->file);
    memset(&A, 0, sizeof A);
    ok = tl_read_mtx(&A, path, err, sizeof err) == 0;
    CHECK(all_ok(ok), "%s: %s", k->file, err);
    if (!ok) return;
    n = A.m;
    x = calloc((size_t)n, sizeof *x);
    xr = calloc((size_t)n, sizeof *xr);
    /* b = A * ones: the product runs distributed too. */
    snprintf(stmt, sizeof stmt, "b = A * ones(%lld, 1); x = solve(A, b, \"%s\")", (long long)n, k->options);
    ok = put_dist(c, "A", &A) == 0 && silc_exec(c, stmt) == 0;
    CHECK(all_ok(ok), "%s [%s]: %s", k->file, k->options, silc_context_errmsg(c));
    if (ok) {
        /* Solved where the blocks lie: the matrix was not gathered.  In SPMD
         * mode the first statement to ask whether A is symmetric exchanges
         * the entries whose mirror another rank owns (once per value, far
         * less than A); a second solve with the same A moves nothing. */
        long long first = matrix_bytes(c, cap, "x"), again, whole = (long long)A.nnz * 16;
        CHECK(all_ok(first >= 0 && first < whole / 4), "%s [%s]: the solve moved %lld bytes of matrices "
              "(A holds %lld):\n%s", k->file, k->options, first, whole, tl_capture_text(cap));
        snprintf(stmt, sizeof stmt, "x = solve(A, b, \"%s\")", k->options);
        ok = silc_exec(c, stmt) == 0;
        CHECK(all_ok(ok), "%s [%s] again: %s", k->file, k->options, silc_context_errmsg(c));
        again = ok ? matrix_bytes(c, cap, "x") : -1;
        CHECK(all_ok(again == 0), "%s [%s]: the second solve moved %lld bytes of matrices:\n%s", k->file,
              k->options, again, tl_capture_text(cap));
        ok = ok && get_whole(c, "x", x, n) == 0;
    }
    snprintf(stmt, sizeof stmt, "b = A * ones(%lld, 1); x = A \\ b", (long long)n);
    CHECK(silc_put(ref, "A", &A) == 0 && silc_exec(ref, stmt) == 0 && tl_get_vec(ref, "x", xr, n) == 0,
          "reference %s: %s", k->file, silc_context_errmsg(ref));
    if (ok) {
        for (i = 0; i < n; i++) {
            d = fmax(d, fabs(x[i] - xr[i]));
            s = fmax(s, fabs(xr[i]));
        }
        d = max_all(d / s);
        bound = fmax(1, k->cond2) * k->tol;
        CHECK(d <= bound, "%s [%s] on %d ranks: relative difference to the sequential solve %.3g > %.3g",
              k->file, k->options, nranks, d, bound);
        if (rank == 0)
            printf("  %-14s %-72.72s %.2g (bound %.2g)\n", k->file, k->options, d, bound);
    }
    free(x);
    free(xr);
    silc_envelope_free(&A);
}

/* The 2-D diffusion loop of examples/diffusion2d, distributed and embedded. */
static void check_diffusion(silc_context *c, silc_context *ref, tl_capture *cap)
{
    const int64_t k = 30, n = k * k;
    const double dt = 2e-4, h = 1.0 / (double)(k + 1);
    silc_envelope_t A, B, u;
    double *u0 = calloc((size_t)n, sizeof *u0), *ud = calloc((size_t)n, sizeof *ud);
    double *ur = calloc((size_t)n, sizeof *ur), sd = 0, sr = 0;
    long long moved_first = -1, moved_later = 0, mb, vb, vec_later = -1, sol;
    /* A step's product B * u receives only the ghosts: one grid row of u
     * from each neighbouring block, k values per block boundary each way. */
    const long long halo = 2 * 8 * k * (engine_ranks - 1);
    int step, ok;
    memset(&A, 0, sizeof A), memset(&B, 0, sizeof B), memset(&u, 0, sizeof u);
    ok = u0 && ud && ur && diff_shifted_laplacian_rows(2, k, h, -dt / 2, 0, n, &A) == 0 &&
         diff_shifted_laplacian_rows(2, k, h, dt / 2, 0, n, &B) == 0;
    if (ok) diff2d_initial_rows(k, 0, n, u0);
    ok = ok && silc_envelope_dense(&u, n, 1, u0) == 0;
    CHECK(all_ok(ok), "building the diffusion system");
    if (!ok) goto out;
    ok = put_dist(c, "A", &A) == 0 && put_dist(c, "B", &B) == 0 && put_dist(c, "u", &u) == 0;
    CHECK(all_ok(ok), "diffusion put: %s", silc_context_errmsg(c));
    CHECK(silc_put(ref, "A", &A) == 0 && silc_put(ref, "B", &B) == 0 && silc_put(ref, "u", &u) == 0,
          "reference put: %s", silc_context_errmsg(ref));
    /* No configuration: the built-in list for distributed operands starts
     * with MUMPS, which factors once and solves on the row blocks. */
    for (step = 0; ok && step < 10; step++) {
        ok = silc_exec(c, "u = A \\ (B * u)") == 0;
        CHECK(all_ok(ok), "diffusion step %d: %s", step, silc_context_errmsg(c));
        CHECK(silc_exec(ref, "u = A \\ (B * u)") == 0, "reference step: %s", silc_context_errmsg(ref));
        if (ok) {
            mb = moved_bytes(c, cap, "u", &vb);
            /* the solution's entries that MUMPS left off their row block, 8 bytes each */
            sol = mumps_moved_entries(c, cap, "u");
            if (step == 0) moved_first = mb;
            else if (mb != 0) moved_later = mb;
            if (step > 0 && (sol < 0 || vb != halo + 8 * sol)) vec_later = vb;
        }
    }
    if (ok) {
        ok = get_whole(c, "u", ud, n) == 0;
        CHECK(all_ok(ok), "diffusion get: %s", silc_context_errmsg(c));
        CHECK(tl_get_vec(ref, "u", ur, n) == 0, "reference get");
        for (step = 0; step < n; step++) sd += ud[step], sr += ur[step];
        CHECK(fabs(sd - sr) <= 1e-12 * fabs(sr), "sum(u) %.17g, embedded %.17g: relative %.3g > 1e-12", sd,
              sr, fabs(sd - sr) / fabs(sr));
        /* Server: the PUT moved the matrices, not a step; SPMD: they never move. */
        CHECK(moved_first >= 0, "info u shows no byte count:\n%s", tl_capture_text(cap));
        CHECK(moved_later == 0, "a later step moved %lld bytes of matrices", moved_later);
        CHECK(vec_later < 0, "a later step moved %lld bytes of vectors, predicted the halo %lld and 8 bytes per "
              "solution entry MUMPS moved:\n%s", vec_later, halo, tl_capture_text(cap));
        if (rank == 0)
            printf("  diffusion %lldx%lld, 10 steps: sum(u) %.17g (embedded %.17g), matrix bytes per "
                   "step after the first: %lld, vector bytes %lld (the halo) + 8 x %lld (the solution's "
                   "entries MUMPS moved)\n", (long long)k, (long long)k, sd, sr, moved_later, halo, sol);
    }
out:
    silc_envelope_free(&A), silc_envelope_free(&B), silc_envelope_free(&u);
    free(u0), free(ud), free(ur);
}

/* This rank's rows of the complex solution x (n entries) through
 * silc_get_rows_complex: in SPMD mode the block of A's rows (x = A \ b
 * keeps b's rows, b = A * xt A's, and A was put split evenly), from a
 * server the whole value.  The rows must be those of the embedded solve
 * x_emb (to rounding, as the gathered x) and of x_true within n eps cond2
 * (young1c's cond2 4.2e2, from the matrices' README).  The real-only
 * silc_get_rows refuses the complex value, naming it. */
static void check_complex_rows(silc_context *c, const double *x_emb, const double *x_true, int64_t n)
{
    const double cond2 = 4.2e2, bound = (double)n * DBL_EPSILON * cond2;
    silc_envelope_t blk;
    int64_t first = -1, want_first = 0, want_rows = n, i;
    double d_emb = 0, d_true = 0, s = 0;
    int ok, rc;
    memset(&blk, 0, sizeof blk);
    if (spmd) my_rows(n, &want_first, &want_rows);
    ok = silc_get_rows_complex(c, &blk, &first, "x") == 0;
    CHECK(all_ok(ok), "silc_get_rows_complex x: %s", silc_context_errmsg(c));
    ok = ok && first == want_first && blk.m == want_rows && blk.n == 1 && blk.format == (SILC_DENSE | SILC_COMPLEX);
    CHECK(all_ok(ok), "rank %d's complex rows of x: first %lld, %lldx%lld, format %d; want first %lld, %lld rows, "
          "complex dense", rank, (long long)first, (long long)blk.m, (long long)blk.n, (int)blk.format,
          (long long)want_first, (long long)want_rows);
    if (all_ok(ok)) {
        for (i = 0; i < n; i++) s = fmax(s, hypot(x_true[2 * i], x_true[2 * i + 1]));
        for (i = 0; i < blk.m; i++) {
            const double *got = blk.values + 2 * i, *e = x_emb + 2 * (first + i), *t = x_true + 2 * (first + i);
            d_emb = fmax(d_emb, hypot(got[0] - e[0], got[1] - e[1]));
            d_true = fmax(d_true, hypot(got[0] - t[0], got[1] - t[1]));
        }
        d_emb = max_all(d_emb / s);
        d_true = max_all(d_true / s);
        CHECK(d_emb <= 1e-12, "complex rows of x on %d ranks: %.3g from the embedded solve > 1e-12", engine_ranks,
              d_emb);
        CHECK(d_true <= bound, "complex rows of x on %d ranks: error to x_true %.3g > n eps cond2 = %.3g",
              engine_ranks, d_true, bound);
        if (rank == 0)
            printf("  young1c complex rows: rank 0 got rows %lld..%lld, %.2g from the embedded solve, error "
                   "%.2g (bound n eps cond2 %.2g)\n", (long long)first, (long long)(first + blk.m - 1), d_emb,
                   d_true, bound);
    }
    silc_envelope_free(&blk);
    rc = silc_get_rows(c, &blk, &first, "x");
    CHECK(all_ok(rc != 0 && blk.values == NULL && strstr(silc_context_errmsg(c), "'x' is complex") &&
                 strstr(silc_context_errmsg(c), "silc_get_rows_complex")),
          "silc_get_rows of a complex value: rc %d, '%s'", rc, silc_context_errmsg(c));
    silc_envelope_free(&blk);
}

/* Complex values distributed by rows (young1c, 841 x 841 complex general):
 * put, products, reductions and a solve against the embedded engine, and
 * x_true.  The server splits what it is PUT (test_mpi_server.sh's
 * --dist-min-rows 100); SPMD ranks put their rows. */
static void check_complex(silc_context *c, silc_context *ref, tl_capture *cap)
{
    char path[1024], err[256];
    silc_envelope_t A, xt, M;
    double *z = NULL, *zr = NULL, *x_true = NULL, *mv = NULL, d;
    int64_t n, i, j;
    long long moved, vec = -1, entries;
    int ok;
    const char *ops = "b = A * xt; Y = M * [1+2i; -1i; 0.5]; s = sum(xt); q = dot(xt, b); "
                      "n2 = norm(xt); n1 = norm(xt, 1); ni = norm(xt, inf); nf = norm(M, \"fro\"); "
                      "na = norm(A, 1); t = abs(xt) .* xt + conj(xt)";
    snprintf(path, sizeof path, "%s/young1c.mtx", SILC_SHARED_MATRICES);
    memset(&A, 0, sizeof A), memset(&xt, 0, sizeof xt), memset(&M, 0, sizeof M);
    ok = tl_read_mtx(&A, path, err, sizeof err) == 0 && silc_envelope_is_complex(&A);
    CHECK(all_ok(ok), "young1c: %s", err);
    if (!ok) return;
    n = A.m;
    z = calloc((size_t)(6 * n), sizeof *z);
    zr = calloc((size_t)(6 * n), sizeof *zr);
    x_true = malloc((size_t)(2 * n) * sizeof *x_true);
    mv = malloc((size_t)(6 * n) * sizeof *mv);
    ok = z && zr && x_true && mv;
    for (i = 0; ok && i < n; i++) { /* x_true_i = (1 + i/n) + (i mod 7 - 3) i */
        x_true[2 * i] = 1 + (double)i / (double)n;
        x_true[2 * i + 1] = (double)(i % 7) - 3;
        for (j = 0; j < 3; j++) { /* a dense complex n x 3, column-major */
            mv[2 * (i + j * n)] = cos((double)(i * (j + 1)));
            mv[2 * (i + j * n) + 1] = sin((double)(i + j));
        }
    }
    ok = ok && silc_envelope_dense_complex(&xt, n, 1, x_true) == 0 &&
         silc_envelope_dense_complex(&M, n, 3, mv) == 0;
    CHECK(all_ok(ok), "building the complex operands");
    if (!ok) goto out;
    ok = put_dist(c, "A", &A) == 0 && put_dist(c, "xt", &xt) == 0 && put_dist(c, "M", &M) == 0 &&
         silc_exec(c, ops) == 0;
    CHECK(all_ok(ok), "complex operations on distributed values: %s", silc_context_errmsg(c));
    CHECK(silc_put(ref, "A", &A) == 0 && silc_put(ref, "xt", &xt) == 0 && silc_put(ref, "M", &M) == 0 &&
              silc_exec(ref, ops) == 0,
          "reference complex operations: %s", silc_context_errmsg(ref));
    if (ok) {
        static const struct { const char *name; int64_t m, n; double tol; } r[] = {
            {"b", 841, 1, 1e-15}, {"Y", 841, 1, 0}, {"t", 841, 1, 0}, {"s", 1, 1, 1e-14}, {"q", 1, 1, 1e-14},
        };
        static const char *const norms[] = {"n2", "n1", "ni", "nf", "na"};
        size_t k;
        for (k = 0; k < sizeof r / sizeof r[0]; k++) {
            /* Elementwise maps and a dense block's product are the same
             * arithmetic in the same order: equal bit for bit; A * xt sums
             * each row's ghost columns after its own (the halo's
             * renumbering), and sums and dots combine the ranks' parts:
             * equal to rounding. */
            ok = get_complex(c, r[k].name, z, r[k].m, r[k].n) == 0 && get_complex(ref, r[k].name, zr, r[k].m, r[k].n) == 0;
            CHECK(all_ok(ok), "get_complex %s: %s", r[k].name, silc_context_errmsg(c));
            d = ok ? complex_rel_diff(z, zr, r[k].m * r[k].n) : 1;
            CHECK(all_ok(d <= r[k].tol), "complex %s on %d ranks: relative difference %.3g to the embedded > %.3g",
                  r[k].name, engine_ranks, d, r[k].tol);
        }
        for (k = 0; k < sizeof norms / sizeof norms[0]; k++) {
            double v = -1, vr = -2;
            CHECK(all_ok(get_scalar(c, norms[k], &v) == 0 && get_scalar(ref, norms[k], &vr) == 0 &&
                         fabs(v - vr) <= 1e-14 * fabs(vr)),
                  "%s on %d ranks: %.17g, embedded %.17g", norms[k], engine_ranks, v, vr);
        }
    }
    /* The solve: the built-in list for distributed operands starts with
     * mumps (zmumps on the blocks); PETSc, a real build, declines first
     * where it is listed first. */
    ok = ok && silc_exec(c, "x = A \\ b; e = norm(x - xt, inf) / norm(xt, inf)") == 0;
    CHECK(all_ok(ok), "complex distributed solve: %s", silc_context_errmsg(c));
    CHECK(silc_exec(ref, "x = A \\ b") == 0, "reference complex solve: %s", silc_context_errmsg(ref));
    if (ok) {
        const char *t = tl_info(c, cap, "x");
        double e = 1;
        CHECK(all_ok(strstr(t, "mumps") && strstr(t, "ICNTL(20)=10") && strstr(t, "complex")),
              "the complex solve did not run on MUMPS's distributed path:\n%s", t);
        ok = get_complex(c, "x", z, n, 1) == 0 && get_complex(ref, "x", zr, n, 1) == 0;
        d = ok ? complex_rel_diff(z, zr, n) : 1;
        /* The same MUMPS factorization order is not guaranteed across rank
         * counts: agreement to rounding times young1c's modest condition. */
        CHECK(all_ok(d <= 1e-12), "complex solve on %d ranks: relative difference %.3g to the embedded > 1e-12",
              engine_ranks, d);
        CHECK(all_ok(get_scalar(c, "e", &e) == 0 && e <= 1e-10), "complex solve: error to x_true %.3g > 1e-10", e);
        if (all_ok(ok)) check_complex_rows(c, zr, x_true, n);
        /* Again with the same A: no matrix byte moves, and the vectors are
         * exactly the solution entries MUMPS left off their row block. */
        ok = silc_exec(c, "x = A \\ b") == 0;
        moved = ok ? moved_bytes(c, cap, "x", &vec) : -1;
        entries = ok ? mumps_moved_entries(c, cap, "x") : -1;
        CHECK(all_ok(moved == 0 && entries >= 0 && entries <= n && vec == entries * 16 &&
                     (engine_ranks > 1 || entries == 0)),
              "second complex solve: %lld bytes of matrices, %lld of vectors, %lld entries moved (predicted "
              "16 bytes each):\n%s", moved, vec, entries, tl_capture_text(cap));
        if (rank == 0)
            printf("  young1c complex: x = A \\ b on %d ranks, %.2g from the embedded solve, error %.2g; "
                   "solution entries moved %lld (%lld bytes)\n", engine_ranks, d, e, entries, vec);
    }
    /* PETSc here is a real build: listed first, it is passed over (it
     * takes no complex values) and mumps solves; named alone, the solve
     * fails saying why. */
    tl_capture_reset(cap);
    ok = silc_exec(c, "explain x2 = solve(A, b, \"dispatch.solve.sparse = petsc, mumps\")") == 0;
    CHECK(all_ok(ok && strstr(tl_capture_text(cap), "petsc: does not take complex values") &&
                 strstr(tl_capture_text(cap), "mumps -> would run (collective")),
          "explain, petsc listed first on a complex system: %s\n%s", silc_context_errmsg(c), tl_capture_text(cap));
    ok = silc_exec(c, "x2 = solve(A, b, \"dispatch.solve.sparse = petsc, mumps\")") == 0;
    CHECK(all_ok(ok && strstr(tl_info(c, cap, "x2"), "backend: mumps")), "petsc, mumps on a complex system: %s\n%s",
          silc_context_errmsg(c), tl_capture_text(cap));
    ok = silc_exec(c, "x3 = solve(A, b, \"backend = petsc\")") != 0;
    CHECK(all_ok(ok && strstr(silc_context_errmsg(c), "petsc does not take complex values")),
          "backend = petsc on a complex system: '%s'", silc_context_errmsg(c));
out:
    silc_envelope_free(&A), silc_envelope_free(&xt), silc_envelope_free(&M);
    free(z), free(zr), free(x_true), free(mv);
}

/* SPMD: collective calls that do not match, and a bad block on one rank. */
static void check_faults(silc_context *c)
{
    silc_envelope_t blk;
    int64_t rp[3] = {0, 2, 3}, ci[3] = {1, 0, 0};
    double v[3] = {1, 2, 3};
    char text[32];
    int rc;
    if (!spmd || nranks < 2) return;
    snprintf(text, sizeof text, "m = %d", rank == 0 ? 1 : 2);
    rc = silc_exec(c, text);
    CHECK(all_ok(rc != 0 && strstr(silc_context_errmsg(c), "mismatched collective calls") &&
                 strstr(silc_context_errmsg(c), "rank 1")),
          "different EXEC texts: rc %d, '%s'", rc, silc_context_errmsg(c));
    rc = rank == 0 ? silc_exec(c, "m = 1") : silc_put(c, "m", &(silc_envelope_t){0});
    CHECK(all_ok(rc != 0 && strstr(silc_context_errmsg(c), "mismatched")), "EXEC against PUT: '%s'",
          silc_context_errmsg(c));
    /* Rank 1's block has columns out of order: every rank hears of rank 1. */
    memset(&blk, 0, sizeof blk);
    if (silc_envelope_csr(&blk, 2, 2, rp, ci, v) == 0 && rank == 1) {
        blk.colind[0] = 1, blk.colind[1] = 0; /* hand-filled, unsorted */
    }
    rc = silc_put_rows(c, "bad", 2 * rank, &blk);
    CHECK(all_ok(rc != 0 && strstr(silc_context_errmsg(c), "rank 1")), "bad block on rank 1: rc %d '%s'",
          rc, silc_context_errmsg(c));
    silc_envelope_free(&blk);
    /* Rank 1's block complex, rank 0's real: refused on every rank, naming the field. */
    {
        double z[4] = {1, 2, 3, 4};
        memset(&blk, 0, sizeof blk);
        rc = rank == 1 ? silc_envelope_dense_complex(&blk, 2, 1, z) : silc_envelope_dense(&blk, 2, 1, z);
        if (rc == 0) rc = silc_put_rows(c, "mixed", 2 * rank, &blk);
        CHECK(all_ok(rc != 0 && strstr(silc_context_errmsg(c), "rank 1's block is complex") &&
                     strstr(silc_context_errmsg(c), "field")),
              "a complex block among real ones: rc %d '%s'", rc, silc_context_errmsg(c));
        silc_envelope_free(&blk);
    }
    /* Blocks that overlap (every rank's row 0): the same verdict everywhere. */
    memset(&blk, 0, sizeof blk);
    silc_envelope_scalar(&blk, 1.0);
    rc = silc_put_rows(c, "overlap", 0, &blk);
    silc_envelope_free(&blk);
    CHECK(all_ok(rc != 0 && strstr(silc_context_errmsg(c), "tile")), "overlapping blocks: rc %d '%s'", rc,
          silc_context_errmsg(c));
    CHECK(all_ok(silc_exec(c, "m = 3") == 0), "the context after the faults: %s", silc_context_errmsg(c));
}

int main(int argc, char **argv)
{
    static const solve_case cases[] = {
        {"gr_30_30.mtx", 195, "backend = mumps", 1e-13},
        {"gr_30_30.mtx", 195, "backend = petsc; petsc.options = -ksp_type cg -pc_type hypre -ksp_rtol 1e-12", 1e-10},
        {"gr_30_30.mtx", 195, "backend = petsc; petsc.options = -pc_type lu -pc_factor_mat_solver_type mumps",
         1e-13},
        {"1138_bus.mtx", 8.6e6, "backend = mumps", 1e-14},
        {"1138_bus.mtx", 8.6e6, "backend = petsc; petsc.options = -pc_type lu -pc_factor_mat_solver_type mumps",
         1e-14},
        {"orsirr_1.mtx", 7.7e4, "backend = mumps", 1e-14},
        {"orsirr_1.mtx", 7.7e4,
         "backend = petsc; petsc.options = -ksp_type gmres -pc_type bjacobi -ksp_rtol 1e-13 -ksp_max_it 20000 "
         "-ksp_gmres_restart 100", 1e-10},
        {"orsirr_1.mtx", 7.7e4, "backend = petsc; petsc.options = -pc_type lu -pc_factor_mat_solver_type mumps",
         1e-14},
        {"olm1000.mtx", 1.5e6, "backend = mumps", 1e-14},
    };
    silc_context *c = NULL, *ref = NULL;
    tl_capture cap;
    size_t i;
    const char *server = getenv("SILC_SERVER");
    memset(&cap, 0, sizeof cap);
    spmd = argc > 1 && !strcmp(argv[1], "spmd");
    if (spmd) {
#ifdef SILC_TEST_SPMD
        MPI_Init(&argc, &argv);
        MPI_Comm_rank(MPI_COMM_WORLD, &rank);
        MPI_Comm_size(MPI_COMM_WORLD, &nranks);
        if (silc_open_mpi(&c, MPI_COMM_WORLD, NULL)) {
            fprintf(stderr, "silc_open_mpi: %s\n", silc_errmsg());
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
#else
        fprintf(stderr, "test_mpi: built without MPI\n");
        return 2;
#endif
    } else {
        if (!server || !*server) {
            fprintf(stderr, "test_mpi server: SILC_SERVER is not set\n");
            return 2;
        }
        if (silc_open(&c, NULL)) {
            fprintf(stderr, "silc_open: %s\n", silc_errmsg());
            return 1;
        }
        unsetenv("SILC_SERVER"); /* the reference is embedded */
    }
    if (silc_open(&ref, NULL)) {
        fprintf(stderr, "reference context: %s\n", silc_errmsg());
        return 1;
    }
    tl_capture_attach(c, &cap);
    if (!spmd) { /* the server's ranks, as `info` tells them */
        const char *t, *p;
        CHECK(silc_exec(c, "probe = 1") == 0, "probe: %s", silc_context_errmsg(c));
        t = tl_info(c, &cap, "probe");
        p = strstr(t, "ranks: ");
        CHECK(p != NULL, "the server's info names no ranks (not silcd --mpi?):\n%s", t);
        if (p) printf("server ranks: %d\n", engine_ranks = atoi(p + 7));
    }
    if (spmd) engine_ranks = nranks;
    if (rank == 0) printf("test_mpi %s on %d rank(s)\n", spmd ? "spmd" : "server", nranks);
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) check_solve(c, ref, &cap, &cases[i]);
    check_backward_error(c, &cap);
    check_diffusion(c, ref, &cap);
    check_complex(c, ref, &cap);
    check_faults(c);
    silc_close(&c);
    silc_close(&ref);
    tl_capture_free(&cap);
#ifdef SILC_TEST_SPMD
    if (spmd) {
        int failed = check_failed_;
        MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
        check_failed_ = failed;
        MPI_Finalize();
        if (rank != 0) return check_failed_ ? 1 : 0;
    }
#endif
    return check_done();
}
