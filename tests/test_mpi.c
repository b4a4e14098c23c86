/*
 * test_mpi.c -- distributed SILC checked against the sequential engine.
 *
 *     mpirun -np P test_mpi spmd      an MPI program: silc_open_mpi, each rank
 *                                     its own rows (silc_put_rows/get_rows)
 *     test_mpi server                 a plain client of SILC_SERVER, which is
 *                                     `mpirun -np P silcd --mpi` (tests/mpi.cmake)
 *
 * Both modes run the same checks:
 *   - solves of shared matrices (SPD and unsymmetric) by the distributed
 *     backends -- petsc CG + BoomerAMG, GMRES + block Jacobi, LU through
 *     MUMPS; mumps -- agree with the sequential engine's solve within
 *     max(1, cond2) * tol (cond2 from the matrices' README);
 *   - the 2-D diffusion loop `u = A \ (B * u)` gives the embedded engine's
 *     sum(u) to 1e-12 relative, and from the second step on `info u` says
 *     no matrix moved;
 *   - SPMD only: ranks EXECing different texts get an error naming the rank,
 *     a bad block on one rank is an error on every rank naming it, and the
 *     context works afterwards (nobody hangs: ctest's timeout bounds it).
 * The reference solves run in an ordinary embedded context of this process.
 */
#define _POSIX_C_SOURCE 200809L
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
    rc = silc_envelope_csr(out, count, A->n, rp, A->colind + lo, A->values + lo);
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
    if (e->format == SILC_CSR) {
        if (csr_rows(&blk, e, first, count)) return -1;
    } else {
        if (silc_envelope_dense(&blk, count, 1, e->values + first)) return -1;
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
    long long moved_first = -1, moved_later = 0, mb, vb, vec_later = -1;
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
            if (step == 0) moved_first = mb;
            else if (mb != 0) moved_later = mb;
            if (step > 0 && vb != halo) vec_later = vb;
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
        CHECK(vec_later < 0, "a later step moved %lld bytes of vectors, the halo is %lld:\n%s", vec_later, halo,
              tl_capture_text(cap));
        if (rank == 0)
            printf("  diffusion %lldx%lld, 10 steps: sum(u) %.17g (embedded %.17g), matrix bytes per "
                   "step after the first: %lld, vector bytes %lld (the halo)\n", (long long)k, (long long)k, sd,
                   sr, moved_later, halo);
    }
out:
    silc_envelope_free(&A), silc_envelope_free(&B), silc_envelope_free(&u);
    free(u0), free(ud), free(ur);
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
    check_diffusion(c, ref, &cap);
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
