/*
 * diffusion2d_mpi.c -- diffusion2d as an MPI program: the same Crank-Nicolson
 * run for the heat equation on the unit square, with the matrices and the
 * field split by rows over the ranks and SILC running on every rank (SPMD
 * mode, silc_mpi.h).
 *
 *     mpirun -n P diffusion2d_mpi [-n N] [-s steps] [-dt dt] [-o out.pgm]
 *         defaults as diffusion2d: N = 100, 50 steps, dt = 2e-4, output
 *         diffusion2d_mpi.pgm
 *
 * No rank ever holds a whole matrix.  Each rank assembles only its block of
 * rows of A = I - dt/2 L and B = I + dt/2 L (diff_shifted_laplacian_rows) and
 * of the initial field, split as PETSc splits N^2 rows (the first N^2 % P
 * ranks get one row more), and the loop is the seeds' one on the rank's
 * context, every call collective:
 *
 *     silc_open_mpi(&ctx, MPI_COMM_WORLD, NULL);
 *     silc_put_rows(ctx, "A", r0, &A); ... "B" ... "u";
 *     for each step: silc_exec(ctx, "u = A \\ (B * u)");
 *     silc_get_rows(ctx, &u, &first, "u");
 *
 * The heat total is reduced over the ranks with MPI_Allreduce; rank 0 prints
 * the summary lines of diffusion2d (the sums may differ from its in the last
 * digits, being added in another order) and writes the picture after
 * gathering the field with MPI_Gatherv -- the only place the whole field is
 * in one process, and only for the picture.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#include "diffusion_common.h"
#include "silc.h"
#include "silc_mpi.h"

static const char prog[] = "diffusion2d_mpi";
static const char usage[] =
    "usage: mpirun -n P diffusion2d_mpi [-n N] [-s steps] [-dt dt] [-o out.pgm]\n"
    "  -n N       interior points per side (default 100, N^2 unknowns)\n"
    "  -s steps   Crank-Nicolson steps (default 50)\n"
    "  -dt dt     time step (default 2e-4)\n"
    "  -o FILE    output image, binary PGM, written by rank 0 (default diffusion2d_mpi.pgm)\n";

/* Rank 0 reads the options (so that a bad one is reported once, not once per
 * rank) into opt[] = {status, N, steps, dt}; status 0 = run, 1 = stop with
 * exit 0 (help), 2 = stop with exit 2 (bad option). */
static void parse_options(int argc, char **argv, double opt[4], const char **out)
{
    opt[0] = 0, opt[1] = 100, opt[2] = 50, opt[3] = 2e-4;
    for (int a = 1; a < argc; a += 2) { /* every option takes a value */
        const char *o = argv[a], *arg = a + 1 < argc ? argv[a + 1] : NULL;
        int bad;
        if (!strcmp(o, "-h") || !strcmp(o, "--help")) {
            fputs(usage, stdout);
            opt[0] = 1;
            return;
        } else if (!strcmp(o, "-n")) {
            /* N <= 20000 keeps N^2 within an int, which MPI_Gatherv counts in. */
            bad = diff_parse_num(prog, o, arg, 1, 20000, 1, &opt[1]);
        } else if (!strcmp(o, "-s")) {
            bad = diff_parse_num(prog, o, arg, 0, 1e9, 1, &opt[2]);
        } else if (!strcmp(o, "-dt")) {
            bad = diff_parse_num(prog, o, arg, 0, 1e6, 0, &opt[3]);
        } else if (!strcmp(o, "-o") && arg) {
            *out = arg, bad = 0;
        } else {
            fprintf(stderr, "%s: unknown or incomplete option '%s'\n%s", prog, o, usage);
            bad = 1;
        }
        if (bad) {
            opt[0] = 2;
            return;
        }
    }
}

/* Rank `rank` of `size` gets rows [*r0, *r1) of `rows`: an even split, the
 * first rows % size ranks one row more (PETSc's PETSC_DECIDE). */
static void row_block(int64_t rows, int size, int rank, int64_t *r0, int64_t *r1)
{
    int64_t base = rows / size, extra = rows % size;
    *r0 = rank * base + (rank < extra ? rank : extra);
    *r1 = *r0 + base + (rank < extra ? 1 : 0);
}

/* Whether any rank failed locally (non-zero rc).  Work that only this rank
 * does (allocation, assembly) can fail on one rank alone; the ranks must
 * agree before the next collective call or the others would wait for it.
 * SILC's own calls need no such step: they fail on every rank together. */
static int any_failed(int rc)
{
    int mine = rc != 0, any = 1;
    MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return any;
}

/* The time loop on this rank's rows: u (r1 - r0 entries) in and out. */
static int run(silc_context *ctx, int rank, int64_t n, int steps, double dt, int64_t r0,
               int64_t r1, double *u)
{
    double h = diff2d_h(n);
    silc_envelope_t A = {0}, B = {0}, U = {0};
    int rc = diff_shifted_laplacian_rows(2, n, h, -dt / 2, r0, r1, &A)
          || diff_shifted_laplacian_rows(2, n, h, dt / 2, r0, r1, &B)
          || silc_envelope_vector(&U, r1 - r0, u);
    if (rc) fprintf(stderr, "%s: rank %d: assembling its rows: %s\n", prog, rank, silc_errmsg());
    if (any_failed(rc)) {
        silc_envelope_free(&A), silc_envelope_free(&B), silc_envelope_free(&U);
        return 1;
    }
    rc = silc_put_rows(ctx, "A", r0, &A) || silc_put_rows(ctx, "B", r0, &B)
      || silc_put_rows(ctx, "u", r0, &U);
    for (int s = 0; s < steps && !rc; s++)
        rc = silc_exec(ctx, "u = A \\ (B * u)");
    silc_envelope_free(&U);
    int64_t first = -1;
    if (!rc) rc = silc_get_rows(ctx, &U, &first, "u");
    if (rc) {
        if (rank == 0) fprintf(stderr, "%s: %s\n", prog, silc_context_errmsg(ctx));
    } else if (first != r0 || silc_envelope_rows(&U) != r1 - r0 || silc_envelope_cols(&U) != 1) {
        /* u was computed from the distributed A, B and u, so it keeps their rows. */
        fprintf(stderr,
                "%s: rank %d: 'u' came back as rows %lld.. (%lldx%lld), expected %lld.. (%lldx1)\n",
                prog, rank, (long long)first, (long long)silc_envelope_rows(&U),
                (long long)silc_envelope_cols(&U), (long long)r0, (long long)(r1 - r0));
        rc = 1;
    } else {
        rc = silc_envelope_to_dense(&U, u);
    }
    silc_envelope_free(&A), silc_envelope_free(&B), silc_envelope_free(&U);
    return any_failed(rc);
}

int main(int argc, char **argv)
{
    int rank, size, rc = 0;
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);

    double opt[4] = {0};
    const char *out = "diffusion2d_mpi.pgm";
    if (rank == 0) parse_options(argc, argv, opt, &out);
    MPI_Bcast(opt, 4, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    if (opt[0] != 0) {
        MPI_Finalize();
        return opt[0] == 1 ? 0 : 2;
    }
    int64_t n = (int64_t)opt[1], rows = n * n, r0, r1;
    int steps = (int)opt[2];
    double dt = opt[3];
    row_block(rows, size, rank, &r0, &r1);

    /* This rank's rows of u; on rank 0 also the whole field, for the picture. */
    double *u = malloc((size_t)(r1 - r0 + 1) * sizeof *u);
    double *whole = rank == 0 ? malloc((size_t)rows * sizeof *whole) : NULL;
    int *counts = rank == 0 ? malloc(2 * (size_t)size * sizeof *counts) : NULL;
    if (!u || (rank == 0 && (!whole || !counts)))
        fprintf(stderr, "%s: rank %d: out of memory for N = %lld\n", prog, rank, (long long)n);
    if (any_failed(!u || (rank == 0 && (!whole || !counts)))) {
        free(u), free(whole), free(counts);
        MPI_Finalize();
        return 1;
    }

    silc_context *ctx = NULL;
    rc = silc_open_mpi(&ctx, MPI_COMM_WORLD, NULL);
    if (rc) {
        if (rank == 0)
            fprintf(stderr, "%s: silc_open_mpi failed: %s\n", prog,
                    ctx ? silc_context_errmsg(ctx) : silc_errmsg());
        silc_close(&ctx);
        free(u), free(whole), free(counts);
        MPI_Finalize();
        return 1;
    }

    diff2d_initial_rows(n, r0, r1, u);
    double h = diff2d_h(n), local = 0, heat0 = 0;
    for (int64_t k = 0; k < r1 - r0; k++) local += u[k];
    MPI_Allreduce(&local, &heat0, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    heat0 *= h * h;

    MPI_Barrier(MPI_COMM_WORLD);
    double t0 = MPI_Wtime();
    rc = run(ctx, rank, n, steps, dt, r0, r1, u);
    MPI_Barrier(MPI_COMM_WORLD); /* the time of the slowest rank */
    double secs = MPI_Wtime() - t0;

    if (!rc) {
        /* The totals over the ranks: sum (and so the heat) and the peak. */
        double mine[2] = {0, -INFINITY}, all[2];
        for (int64_t k = 0; k < r1 - r0; k++) {
            mine[0] += u[k];
            if (u[k] > mine[1]) mine[1] = u[k];
        }
        MPI_Allreduce(&mine[0], &all[0], 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
        MPI_Allreduce(&mine[1], &all[1], 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
        double sum = all[0], umax = all[1];

        /* The picture: the field's blocks in rank order make the whole field.
         * N <= 20000, so every count and displacement fits an int. */
        if (rank == 0)
            for (int r = 0; r < size; r++) {
                int64_t a, b;
                row_block(rows, size, r, &a, &b);
                counts[r] = (int)(b - a), counts[size + r] = (int)a;
            }
        MPI_Gatherv(u, (int)(r1 - r0), MPI_DOUBLE, whole, counts, counts ? counts + size : NULL,
                    MPI_DOUBLE, 0, MPI_COMM_WORLD);
        if (rank == 0) {
            printf("steps=%d N=%lld unknowns=%lld time=%.2fs max=%.6g sum=%.6g\n", steps,
                   (long long)n, (long long)rows, secs, umax, sum);
            printf("heat=%.10g (initially %.10g, t=%g)\n", sum * h * h, heat0, steps * dt);
            rc = diff2d_write_pgm(prog, out, n, whole, umax);
            if (!rc) printf("wrote %s (%lldx%lld PGM)\n", out, (long long)n, (long long)n);
        }
        /* Every rank exits with rank 0's status. */
        MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD);
    }

    silc_close(&ctx);
    free(u), free(whole), free(counts);
    MPI_Finalize();
    return rc ? 1 : 0;
}
