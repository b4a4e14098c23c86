/*
 * consumer_mpi.c -- a user's MPI program against an installed SILC, built
 * with SILC::silc_mpi (find_package) and with pkg-config's silc_mpi: each
 * rank puts its rows of a tridiagonal system, the ranks solve it together,
 * and each checks its rows of the answer against the exact solution (all
 * ones: b is A times ones).  test_install.sh runs it under mpirun.
 */
#include <math.h>
#include <stdio.h>

#include <silc_mpi.h>

#define N 8

int main(int argc, char **argv)
{
    int64_t rp[N + 1], ci[3 * N], first, nz = 0, mine, i, r;
    double v[3 * N], b[N], x[N], err = 0;
    silc_envelope_t A, B, X;
    silc_context *ctx = NULL;
    int rank, size, rc = 1;
    MPI_Init(&argc, &argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    first = (int64_t)N * rank / size;
    mine = (int64_t)N * (rank + 1) / size - first;
    rp[0] = 0;
    for (r = 0; r < mine; r++) { /* rows first .. first+mine-1 of tridiag(-1, 4, -1) */
        int64_t row = first + r;
        b[r] = 4 - (row > 0) - (row < N - 1);
        if (row > 0) ci[nz] = row - 1, v[nz++] = -1;
        ci[nz] = row, v[nz++] = 4;
        if (row < N - 1) ci[nz] = row + 1, v[nz++] = -1;
        rp[r + 1] = nz;
    }
    /* each rank's block: mine rows of N columns, global column indices */
    if (silc_open_mpi(&ctx, MPI_COMM_WORLD, NULL) || silc_envelope_csr(&A, mine, N, rp, ci, v) ||
        silc_envelope_dense(&B, mine, 1, b) || silc_put_rows(ctx, "A", first, &A) ||
        silc_put_rows(ctx, "b", first, &B) || silc_exec(ctx, "x = A \\ b") ||
        silc_get_rows(ctx, &X, &i, "x") || silc_envelope_to_dense(&X, x)) {
        fprintf(stderr, "consumer_mpi: rank %d: %s\n", rank, ctx ? silc_context_errmsg(ctx) : silc_errmsg());
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    for (r = 0; r < X.m; r++) err = fmax(err, fabs(x[r] - 1));
    if (i != first || X.m != mine) fprintf(stderr, "consumer_mpi: rank %d got rows from %lld\n", rank, (long long)i);
    else if (err < 1e-14) rc = 0;
    printf("consumer_mpi: rank %d of %d: rows %lld..%lld of x = A \\ b off by %.1e\n", rank, size,
           (long long)first, (long long)(first + mine - 1), err);
    silc_envelope_free(&A);
    silc_envelope_free(&B);
    silc_envelope_free(&X);
    silc_close(&ctx);
    MPI_Finalize();
    return rc;
}
