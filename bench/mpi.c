/*
 * mpi.c -- SILC over MPI against the same solves called directly: one
 * program that runs the 2-D Laplacian one-shot and the Crank-Nicolson loop
 * through SILC in three ways, so bench/mpi.sh can set its rows next to
 * bench/mpi_direct's (the same PETSc/MUMPS solves without SILC) at the same
 * number of ranks.
 *
 *     mpirun -np P mpi spmd  [options]   SPMD: every rank assembles and PUTs
 *                                        its rows (silc_open_mpi, silc_put_rows)
 *     mpi client -server URL [options]   a client of `mpirun -np P silcd --mpi`
 *                                        (PUTs whole values; the server splits them)
 *     mpi embedded [options]             sequential embedded SILC
 *     options: -n N (500) -steps S (0: one-shot, else the loop) -dt DT (2e-4)
 *              -methods m1,m2,...  (mumps, petsc-mumps, petsc-cg-hypre, default)
 *
 * The problems are mpi_direct's, entry for entry (docs/distributed.md):
 *   one-shot  A = the 5-point stencil (4, -1), b = A * ones computed by SILC
 *             (untimed), timed: x = A \ b; err = ||x - 1||_inf.
 *   loop      A = I - dt/2 L, B = I + dt/2 L from examples/diffusion_common.c
 *             (diff_shifted_laplacian_rows, diff2d_initial_rows), S steps of
 *             u = A \ (B * u) as examples/diffusion2d runs them.  The first
 *             step (it factors or sets up) is timed apart from the mean of the
 *             others, which is what mpi_direct's step_s measures.
 * Each method is a per-call option string of solve(); "default" is plain
 * `A \ b` (the configured dispatch: CHOLMOD for this SPD matrix).  Every
 * method gets freshly PUT matrices, so no factorization carries over.
 *
 * Per method rank 0 prints one line "RESULT key=value ..." for the script:
 * put_s (the PUTs), time_s (one-shot solve; loop: first step + the rest),
 * first_s, step_s, err, heat, and from `info` of the result (captured with
 * silc_set_output) the statement's wall time on the engine and the bytes
 * moved between ranks by the first and by the last timed statement
 * (mbytes/vbytes: matrices/vectors), and for the one-shot solve the CPU
 * seconds, their system part and the page faults of every process that
 * worked on it (cpu_s, sys_s, faults: SPMD, the ranks summed; client,
 * itself and the server's ranks, whose pids SILC_BENCH_SERVER_PIDS lists,
 * as bench/mpi.sh sets it; a machine shared with other work changes them
 * far less than the times).  status=gathered flags a solve whose
 * backend was not collective, so its matrix was gathered to every rank
 * (matrix bytes moved by the solve).  Times are wall clock between barriers
 * (SPMD) or around the calls (client, embedded).
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mpi.h>

#include "diffusion_common.h"
#include "proc_usage.h"
#include "silc.h"
#include "silc_mpi.h"

typedef struct method {
    const char *name, *opts; /* opts NULL: plain `\`, the configured dispatch */
} method;

/* The direct program estimates no condition number, so neither do these
 * (SILC's estimate costs MUMPS two extra solve phases, PETSc's direct
 * preconditioners a few MatSolves: README, "Accuracy report"). */
static const method methods[] = {
    {"default", NULL},
    {"mumps", "backend = mumps; mumps.condest = false"},
    {"petsc-mumps", "backend = petsc; petsc.condest = false; petsc.options = -ksp_type preonly -pc_type lu "
                    "-pc_factor_mat_solver_type mumps"},
    {"petsc-cg-hypre", "backend = petsc; petsc.options = -ksp_type cg -pc_type hypre -ksp_rtol 1e-10"},
};
enum { N_METHODS = sizeof methods / sizeof methods[0] };

enum { SPMD, CLIENT, EMBEDDED };
static const char *const mode_names[] = {"spmd", "client", "embedded"};

typedef struct run {
    int mode, rank, size;
    silc_context *ctx;
    int64_t n, r0, r1; /* grid side, this rank's rows [r0, r1) */
    int steps;
    double dt;
} run;

/* What one `info` said: the statement's wall time and bytes moved. */
typedef struct info_line {
    double wall;
    int ranks; /* from the "ranks:" line; 1 when there is none (one process) */
    unsigned long long mbytes, vbytes;
    char solve[160];
} info_line;

/* `info` output, collected by the output callback. */
static char captured[8192];
static void capture(void *user, const char *text)
{
    (void)user;
    size_t have = strlen(captured);
    snprintf(captured + have, sizeof captured - have, "%s", text);
}

static double now(const run *R)
{
    if (R->mode == SPMD) return MPI_Wtime();
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* SPMD: times are those of the slowest rank, as in mpi_direct. */
static void barrier(const run *R)
{
    if (R->mode == SPMD) MPI_Barrier(MPI_COMM_WORLD);
}

/* Work a rank does alone (assembly) can fail on it alone; the ranks must
 * agree before the next collective call. */
static int any_failed(const run *R, int rc)
{
    int mine = rc != 0, any = mine;
    if (R->mode == SPMD) MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return any;
}

/* The usage so far of the processes that run this mode's statements: this
 * one (SPMD: summed over the ranks, on rank 0) and, for a client, the
 * server's ranks listed in SILC_BENCH_SERVER_PIDS.  A pid that cannot be
 * read counts nothing (the table then shows less, never more). */
static bench_usage usage_now(const run *R)
{
    bench_usage u, one;
    const char *pids = getenv("SILC_BENCH_SERVER_PIDS");
    bench_proc_usage(0, &u);
    if (R->mode == CLIENT && pids) {
        char *end;
        for (long pid = strtol(pids, &end, 10); end != pids; pid = strtol(pids, &end, 10)) {
            pids = end;
            if (pid > 0 && !bench_proc_usage(pid, &one))
                u.cpu_s += one.cpu_s, u.sys_s += one.sys_s, u.faults += one.faults;
        }
    }
    if (R->mode == SPMD) {
        double mine[3] = {u.cpu_s, u.sys_s, (double)u.faults}, sum[3];
        MPI_Reduce(mine, sum, 3, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
        u.cpu_s = sum[0], u.sys_s = sum[1], u.faults = (long long)sum[2];
    }
    return u;
}

/* PETSc's PETSC_DECIDE split of rows over ranks, as mpi_direct's matrices. */
static void row_block(int64_t rows, int size, int rank, int64_t *r0, int64_t *r1)
{
    int64_t base = rows / size, extra = rows % size;
    *r0 = rank * base + (rank < extra ? rank : extra);
    *r1 = *r0 + base + (rank < extra ? 1 : 0);
}

/* This rank's block (or the whole value) under name. */
static int put(const run *R, const char *name, const silc_envelope_t *e)
{
    return R->mode == SPMD ? silc_put_rows(R->ctx, name, R->r0, e) : silc_put(R->ctx, name, e);
}

/* Runs `info name` and reads what the result line says. */
static int info_of(const run *R, const char *name, info_line *out)
{
    char stmt[64];
    const char *p;
    memset(out, 0, sizeof *out);
    out->wall = -1;
    out->ranks = 1;
    captured[0] = '\0';
    snprintf(stmt, sizeof stmt, "info %s", name);
    if (silc_exec(R->ctx, stmt)) return 1;
    if ((p = strstr(captured, "wall time: "))) out->wall = strtod(p + 11, NULL);
    if ((p = strstr(captured, "  ranks: "))) out->ranks = atoi(p + 9);
    if ((p = strstr(captured, "moved between ranks by the statement: ")))
        sscanf(p, "moved between ranks by the statement: %llu bytes of matrices, %llu", &out->mbytes,
               &out->vbytes);
    if ((p = strstr(captured, "  solve: "))) {
        size_t k = 0;
        for (p += 9; *p && *p != '\n' && k + 1 < sizeof out->solve; p++)
            out->solve[k++] = *p == '"' ? '\'' : *p; /* the script splits on '"' */
        out->solve[k] = '\0';
    }
    return 0;
}

/* Whether the solve gathered its matrix to every rank (a backend that is not
 * collective).  A collective solve moves matrix entries too, but only
 * O(n) of them (the checks of symmetry look across the block boundary); a
 * gathered 5-point matrix is at least 5 n^2 / 2 entries of 8 bytes. */
static int gathered(const run *R, const info_line *in)
{
    return in->mbytes > 8ULL * (unsigned long long)(R->n * R->n);
}

/* The scalar `expr` evaluated into name and fetched (whole on every rank). */
static int scalar(const run *R, const char *name, const char *expr, double *out)
{
    char stmt[128];
    silc_envelope_t e = {0};
    snprintf(stmt, sizeof stmt, "%s = %s", name, expr);
    int rc = silc_exec(R->ctx, stmt) || silc_get(R->ctx, &e, name) || silc_envelope_to_dense(&e, out);
    silc_envelope_free(&e);
    return rc;
}

/* The solve statement of method m: x = solve(A, rhs, "opts") or x = A \ rhs. */
static void statement(char *buf, size_t len, const char *x, const char *rhs, const method *m)
{
    if (m->opts) snprintf(buf, len, "%s = solve(A, %s, \"%s\")", x, rhs, m->opts);
    else snprintf(buf, len, "%s = A \\ %s", x, rhs);
}

static void report_failure(const run *R, const char *kind, const method *m, const char *msg)
{
    if (R->rank != 0) return;
    printf("RESULT mode=%s kind=%s method=%s n=%lld np=%d status=fail msg=\"", mode_names[R->mode],
           kind, m->name, (long long)R->n, R->size);
    for (; *msg; msg++) putchar(*msg == '"' || *msg == '\n' ? ' ' : *msg);
    printf("\"\n");
    fflush(stdout);
}

/* One-shot: PUT A and ones, b = A * ones, time x = A \ b. */
static int oneshot(const run *R, const method *m)
{
    silc_envelope_t A = {0}, e = {0};
    int64_t rows = R->r1 - R->r0, k, j;
    double *ones = malloc((size_t)(rows + 1) * sizeof *ones), t0, t1, t2, err = NAN;
    char stmt[256];
    info_line in;
    bench_usage u0, used;
    /* diffusion_common's I + c L with h = 1, c = -1 is the stencil plus I
     * (diagonal 5, neighbours -1); taking the 1 off the diagonal gives
     * mpi_direct's A (4, -1) from the shared row assembly. */
    int rc = !ones || diff_shifted_laplacian_rows(2, R->n, 1.0, -1.0, R->r0, R->r1, &A);
    for (k = 0; !rc && k < rows; k++) {
        ones[k] = 1.0;
        for (j = A.rowptr[k]; j < A.rowptr[k + 1]; j++)
            if (A.colind[j] == R->r0 + k) A.values[j] -= 1.0;
    }
    if (!rc) rc = silc_envelope_vector(&e, rows, ones);
    free(ones);
    if (any_failed(R, rc)) {
        report_failure(R, "oneshot", m, "assembling this rank's rows failed");
        silc_envelope_free(&A), silc_envelope_free(&e);
        return 1;
    }
    barrier(R);
    t0 = now(R);
    rc = put(R, "A", &A) || put(R, "e", &e);
    barrier(R);
    t1 = now(R);
    silc_envelope_free(&A), silc_envelope_free(&e);
    statement(stmt, sizeof stmt, "x", "b", m);
    rc = rc || silc_exec(R->ctx, "b = A * e");
    if (!rc) {
        barrier(R);
        u0 = usage_now(R);
        t2 = now(R);
        rc = silc_exec(R->ctx, stmt);
        barrier(R);
        t2 = now(R) - t2;
        {
            bench_usage u1 = usage_now(R);
            used = bench_usage_since(&u0, &u1);
        }
        rc = rc || scalar(R, "err", "norm(x - e, inf)", &err) || info_of(R, "x", &in);
        if (!rc && R->rank == 0) {
            printf("RESULT mode=%s kind=oneshot method=%s n=%lld np=%d status=%s put_s=%.4f "
                   "time_s=%.4f err=%.3e wall_s=%.4f mbytes=%llu vbytes=%llu cpu_s=%.2f sys_s=%.2f faults=%lld "
                   "solve=\"%s\"\n",
                   mode_names[R->mode], m->name, (long long)R->n, in.ranks,
                   gathered(R, &in) ? "gathered" : "ok", t1 - t0, t2, err, in.wall, in.mbytes,
                   in.vbytes, used.cpu_s, used.sys_s, used.faults, in.solve);
            fflush(stdout);
        }
    }
    if (rc) report_failure(R, "oneshot", m, silc_context_errmsg(R->ctx));
    /* Frees the factorization (collectively) before the next method. */
    silc_exec(R->ctx, "clear A e b x err");
    return rc;
}

/* The loop: PUT A, B, u; S steps of u = A \ (B * u). */
static int loop(const run *R, const method *m)
{
    silc_envelope_t A = {0}, B = {0}, U = {0};
    int64_t rows = R->r1 - R->r0;
    double h = diff2d_h(R->n), *u = malloc((size_t)(rows + 1) * sizeof *u), t0, t1, first,
           rest = 0, sum = NAN;
    char stmt[256];
    info_line in1, in;
    int rc = !u || diff_shifted_laplacian_rows(2, R->n, h, -R->dt / 2, R->r0, R->r1, &A)
          || diff_shifted_laplacian_rows(2, R->n, h, R->dt / 2, R->r0, R->r1, &B);
    if (!rc) {
        diff2d_initial_rows(R->n, R->r0, R->r1, u);
        rc = silc_envelope_vector(&U, rows, u);
    }
    free(u);
    if (any_failed(R, rc)) {
        report_failure(R, "loop", m, "assembling this rank's rows failed");
        silc_envelope_free(&A), silc_envelope_free(&B), silc_envelope_free(&U);
        return 1;
    }
    statement(stmt, sizeof stmt, "u", "(B * u)", m);
    barrier(R);
    t0 = now(R);
    rc = put(R, "A", &A) || put(R, "B", &B) || put(R, "u", &U);
    barrier(R);
    t1 = now(R);
    silc_envelope_free(&A), silc_envelope_free(&B), silc_envelope_free(&U);
    double put_s = t1 - t0;
    rc = rc || silc_exec(R->ctx, stmt);
    barrier(R);
    first = now(R) - t1;
    /* Untimed: what the first step moved (a gathered matrix shows here only,
     * being gathered once per value). */
    rc = rc || info_of(R, "u", &in1);
    if (!rc && R->steps > 1) {
        barrier(R);
        t0 = now(R);
        for (int s = 1; s < R->steps && !rc; s++) rc = silc_exec(R->ctx, stmt);
        barrier(R);
        rest = now(R) - t0;
    }
    rc = rc || scalar(R, "heat", "sum(u)", &sum) || info_of(R, "u", &in);
    if (!rc && R->rank == 0) {
        printf("RESULT mode=%s kind=loop method=%s n=%lld np=%d status=%s put_s=%.4f time_s=%.4f "
               "first_s=%.4f step_s=%.5f heat=%.10g wall_s=%.5f mbytes1=%llu vbytes1=%llu "
               "mbytes=%llu vbytes=%llu steps=%d solve=\"%s\"\n",
               mode_names[R->mode], m->name, (long long)R->n, in1.ranks,
               gathered(R, &in1) ? "gathered" : "ok", put_s, first + rest, first,
               R->steps > 1 ? rest / (R->steps - 1) : first, sum * h * h, in.wall, in1.mbytes,
               in1.vbytes, in.mbytes, in.vbytes, R->steps, in1.solve);
        fflush(stdout);
    }
    if (rc) report_failure(R, "loop", m, silc_context_errmsg(R->ctx));
    silc_exec(R->ctx, "clear A B u heat");
    return rc;
}

static int usage(void)
{
    fprintf(stderr, "usage: [mpirun -np P] mpi spmd|client|embedded [-server URL] [-n N] [-steps S] "
                    "[-dt DT] [-methods mumps,petsc-mumps,petsc-cg-hypre,default]\n");
    return 2;
}

int main(int argc, char **argv)
{
    run R = {0};
    const char *server = getenv("SILC_SERVER"), *list = "mumps,petsc-mumps,petsc-cg-hypre";
    int a, rc = 0;
    R.n = 500, R.dt = 2e-4, R.size = 1;
    if (argc < 2) return usage();
    for (R.mode = 0; R.mode < 3 && strcmp(argv[1], mode_names[R.mode]); R.mode++) {}
    if (R.mode == 3) return usage();
    for (a = 2; a + 1 < argc; a += 2) {
        if (!strcmp(argv[a], "-n")) R.n = atoll(argv[a + 1]);
        else if (!strcmp(argv[a], "-steps")) R.steps = atoi(argv[a + 1]);
        else if (!strcmp(argv[a], "-dt")) R.dt = atof(argv[a + 1]);
        else if (!strcmp(argv[a], "-methods")) list = argv[a + 1];
        else if (!strcmp(argv[a], "-server")) server = argv[a + 1];
        else return usage();
    }
    if (a != argc || R.n < 2 || R.steps < 0) return usage();

    if (R.mode == SPMD) {
        MPI_Init(&argc, &argv);
        MPI_Comm_rank(MPI_COMM_WORLD, &R.rank);
        MPI_Comm_size(MPI_COMM_WORLD, &R.size);
        rc = silc_open_mpi(&R.ctx, MPI_COMM_WORLD, NULL);
    } else if (R.mode == CLIENT) {
        if (!server) {
            fprintf(stderr, "mpi client: give -server URL or set SILC_SERVER\n");
            return 2;
        }
        rc = silc_open_remote(&R.ctx, server);
    } else {
        unsetenv("SILC_SERVER"); /* embedded means in this process */
        rc = silc_open(&R.ctx, NULL);
    }
    if (rc) {
        fprintf(stderr, "mpi %s: opening SILC failed: %s\n", mode_names[R.mode],
                R.ctx ? silc_context_errmsg(R.ctx) : silc_errmsg());
        silc_close(&R.ctx);
        if (R.mode == SPMD) MPI_Finalize();
        return 1;
    }
    silc_set_output(R.ctx, capture, NULL);
    if (R.mode == SPMD) row_block(R.n * R.n, R.size, R.rank, &R.r0, &R.r1);
    else R.r0 = 0, R.r1 = R.n * R.n;

    /* Methods in the order given; an unknown name is skipped with a message. */
    for (const char *p = list; *p;) {
        size_t len = strcspn(p, ",");
        int k;
        for (k = 0; k < N_METHODS; k++)
            if (strlen(methods[k].name) == len && !strncmp(methods[k].name, p, len)) break;
        if (k == N_METHODS) {
            if (R.rank == 0) fprintf(stderr, "mpi: unknown method '%.*s'\n", (int)len, p);
            rc = 1;
        } else {
            rc |= R.steps > 0 ? loop(&R, &methods[k]) : oneshot(&R, &methods[k]);
        }
        p += len + (p[len] == ',');
    }
    silc_close(&R.ctx);
    if (R.mode == SPMD) MPI_Finalize();
    return rc ? 1 : 0;
}
