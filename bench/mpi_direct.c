/*
 * mpi_direct.c -- the direct MPI baseline for SILC's MPI server: the same
 * PETSc solves (hypre CG, GMRES + block Jacobi, MUMPS LU) called directly by
 * a small MPI program at the same number of ranks, with no SILC in between,
 * so the server bench can report what SILC's layer costs on top of them.
 *
 *     mpirun -np P mpi_direct [-n N] [-method cg-hypre|gmres-bjacobi|mumps|dmumps|all]
 *                             [-steps S] [-dt DT] [-oneshot 0|1] [-amf 0|1]
 *                             [-header 0|1] [any PETSc option]
 *         defaults: N = 500, method mumps, S = 0, DT = 2e-4, one-shot on,
 *         AMF ordering on (MUMPS ICNTL(7) = 2), header on
 *
 * The matrix is the 2-D 5-point Laplacian on an N x N interior grid with
 * Dirichlet boundaries, unknown k = i*N + j (i the row, j the column).  Every
 * rank assembles only its own contiguous block of rows (PETSc's default
 * layout: MatSetSizes(PETSC_DECIDE, PETSC_DECIDE, N^2, N^2) and
 * MatGetOwnershipRange) into an MPIAIJ matrix preallocated with 5 entries per
 * row.  Scaling:
 *
 *   one-shot  A = stencil (4 on the diagonal, -1 for each neighbour), i.e.
 *             h^2 times the positive Laplacian K; b = A * ones, so the exact
 *             solution is all ones and the error printed is ||x - 1||_inf.
 *   loop      K = the same stencil / h^2 with h = 1/(N+1) (unit square),
 *             A = I + dt/2 K, B = I - dt/2 K (Crank-Nicolson for u_t = -K u,
 *             the same as examples/diffusion2d's A = I - dt/2 L with L = -K);
 *             u0 = 1 on (0.4, 0.6)^2, 0 elsewhere; S steps of u = A \ (B u)
 *             with one KSP set up (or factored) once and reused.  The row
 *             reports heat = h^2 sum(u), comparable with diffusion2d's.
 *
 * Methods: cg-hypre = KSPCG + PCHYPRE BoomerAMG; gmres-bjacobi = KSPGMRES +
 * PCBJACOBI with ILU(0) on each block; mumps = KSPPREONLY + PCLU with
 * MatSolverType mumps.  The iterative ones use rtol 1e-10 (abstol 0); all of
 * these can still be overridden by PETSc options on the command line, which
 * are applied last.  A method PETSc was built without is reported and skipped.
 *
 * dmumps (one-shot only) is MUMPS called directly, no PETSc: dmumps_c with
 * the ICNTLs SILC's mumps backend uses for a distributed SPD solve (output
 * off, AMF ordering ICNTL(7)=2, LDL' SYM=1 on the lower triangle,
 * distributed assembled triplets ICNTL(18)=3, distributed right-hand side
 * ICNTL(20)=10 and solution ICNTL(21)=1), each rank passing its own rows.
 * setup_s is JOB=-1 and JOB=4 (analysis + factorization), solve_s JOB=3;
 * the error is read where MUMPS leaves the solution (SILC also moves it to
 * the row blocks, which this baseline does not: SILC's ratio against it is
 * an upper bound).
 *
 * Times are MPI_Wtime between barriers, max over ranks by construction:
 *   asm_s    assembling A and b (one-shot)
 *   setup_s  KSPSetUp + KSPSetUpOnBlocks (AMG hierarchy, block ILU(0), or
 *            MUMPS analysis + factorisation)
 *   solve_s  KSPSolve
 *   oneshot_s = setup_s + solve_s
 *   lsetup_s  assembling A and B and KSPSetUp for the loop
 *   step_s    mean seconds per time step (MatMult with B plus KSPSolve)
 *   cpu_s, faults, sys_s  the CPU seconds, page faults and the system
 *            part of the CPU seconds of the one-shot's setup and solve,
 *            summed over the ranks (bench/proc_usage.h): what the work
 *            cost whatever else the machine ran
 * its is the one-shot iteration count (the mean per step for the loop in
 * litis); ord is the ordering MUMPS actually used, INFOG(7) (2 = AMF,
 * 4 = PORD, 5 = METIS, 3 = SCOTCH, 0 = AMD, 6 = QAMD; - for other methods).
 */
#if BENCH_HAVE_DMUMPS
#include <dmumps_c.h>
#endif
#include <petscksp.h>
#include <string.h>

#include "proc_usage.h"

typedef struct {
    const char *name;
    double asm_s, setup_s, solve_s, lsetup_s, step_s, err, heat, litis;
    bench_usage used; /* the one-shot's setup + solve, summed over the ranks */
    PetscInt its;
    PetscInt ord;
    PetscBool did_oneshot, did_loop;
} Result;

/* This rank's usage so far; summed_since: the usage since u0 summed over
 * the ranks (every rank gets it). */
static bench_usage usage_now(void)
{
    bench_usage u;
    bench_proc_usage(0, &u);
    return u;
}

static PetscErrorCode summed_since(const bench_usage *u0, bench_usage *sum)
{
    bench_usage u1 = usage_now(), d = bench_usage_since(u0, &u1);
    double mine[3] = {d.cpu_s, d.sys_s, (double)d.faults}, all[3];

    PetscFunctionBeginUser;
    PetscCallMPI(MPI_Allreduce(mine, all, 3, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD));
    sum->cpu_s = all[0];
    sum->sys_s = all[1];
    sum->faults = (long long)all[2];
    PetscFunctionReturn(0);
}

/* The 5-point stencil with diagonal d and off-diagonal o, rows owned here. */
static PetscErrorCode assemble(PetscInt n, PetscScalar d, PetscScalar o, Mat *out)
{
    Mat A;
    PetscInt N = n * n, rstart, rend;

    PetscFunctionBeginUser;
    PetscCall(MatCreate(PETSC_COMM_WORLD, &A));
    PetscCall(MatSetSizes(A, PETSC_DECIDE, PETSC_DECIDE, N, N));
    PetscCall(MatSetType(A, MATMPIAIJ));
    PetscCall(MatSetFromOptions(A));
    PetscCall(MatMPIAIJSetPreallocation(A, 5, NULL, 5, NULL));
    PetscCall(MatSeqAIJSetPreallocation(A, 5, NULL)); /* if -mat_type seqaij */
    PetscCall(MatGetOwnershipRange(A, &rstart, &rend));
    for (PetscInt row = rstart; row < rend; row++) {
        PetscInt i = row / n, j = row % n, cols[5], nc = 0;
        PetscScalar vals[5];
        if (i > 0) { cols[nc] = row - n; vals[nc++] = o; }
        if (j > 0) { cols[nc] = row - 1; vals[nc++] = o; }
        cols[nc] = row; vals[nc++] = d;
        if (j < n - 1) { cols[nc] = row + 1; vals[nc++] = o; }
        if (i < n - 1) { cols[nc] = row + n; vals[nc++] = o; }
        PetscCall(MatSetValues(A, 1, &row, nc, cols, vals, INSERT_VALUES));
    }
    PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
    *out = A;
    PetscFunctionReturn(0);
}

/* Is the method available in this PETSc build?  Prints why not on rank 0. */
static PetscErrorCode available(const char *method, Mat A, PetscBool *ok)
{
    PetscFunctionBeginUser;
    *ok = PETSC_TRUE;
    if (!strcmp(method, "cg-hypre")) {
        PetscCall(PetscHasExternalPackage("hypre", ok));
        if (!*ok)
            PetscCall(PetscPrintf(PETSC_COMM_WORLD,
                                  "mpi_direct: skipping cg-hypre: this PETSc has no hypre (PCHYPRE)\n"));
    } else if (!strcmp(method, "mumps")) {
        PetscCall(MatGetFactorAvailable(A, MATSOLVERMUMPS, MAT_FACTOR_LU, ok));
        if (!*ok)
            PetscCall(PetscPrintf(PETSC_COMM_WORLD,
                                  "mpi_direct: skipping mumps: this PETSc has no MatSolverType mumps\n"));
    }
    PetscFunctionReturn(0);
}

/* A KSP configured for the method, PETSc options applied last. */
static PetscErrorCode make_ksp(const char *method, Mat A, KSP *out)
{
    KSP ksp;
    PC pc;

    PetscFunctionBeginUser;
    PetscCall(KSPCreate(PETSC_COMM_WORLD, &ksp));
    PetscCall(KSPSetOperators(ksp, A, A));
    PetscCall(KSPGetPC(ksp, &pc));
    if (!strcmp(method, "cg-hypre")) {
        PetscCall(KSPSetType(ksp, KSPCG));
        PetscCall(PCSetType(pc, PCHYPRE));
        PetscCall(PCHYPRESetType(pc, "boomeramg"));
        PetscCall(KSPSetTolerances(ksp, 1e-10, 0.0, PETSC_DEFAULT, 10000));
    } else if (!strcmp(method, "gmres-bjacobi")) {
        PetscCall(KSPSetType(ksp, KSPGMRES));
        PetscCall(PCSetType(pc, PCBJACOBI)); /* sub PC defaults to ILU(0) */
        PetscCall(KSPSetTolerances(ksp, 1e-10, 0.0, PETSC_DEFAULT, 100000));
    } else { /* mumps */
        PetscCall(KSPSetType(ksp, KSPPREONLY));
        PetscCall(PCSetType(pc, PCLU));
        PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
    }
    PetscCall(KSPSetFromOptions(ksp));
    *out = ksp;
    PetscFunctionReturn(0);
}

/* The ordering MUMPS used (INFOG(7)), or -1 when not a MUMPS factorisation. */
static PetscErrorCode mumps_ordering(const char *method, KSP ksp, PetscInt *ord)
{
    PC pc;
    Mat F;

    PetscFunctionBeginUser;
    *ord = -1;
    if (strcmp(method, "mumps")) PetscFunctionReturn(0);
    PetscCall(KSPGetPC(ksp, &pc));
    PetscCall(PCFactorGetMatrix(pc, &F));
    PetscCall(MatMumpsGetInfog(F, 7, ord));
    PetscFunctionReturn(0);
}

/* Where a KSP failed to converge, say so (the row is still printed). */
static PetscErrorCode check_reason(KSP ksp, const char *what)
{
    KSPConvergedReason reason;

    PetscFunctionBeginUser;
    PetscCall(KSPGetConvergedReason(ksp, &reason));
    if (reason < 0)
        PetscCall(PetscPrintf(PETSC_COMM_WORLD, "mpi_direct: %s did not converge: %s\n", what,
                              KSPConvergedReasons[reason]));
    PetscFunctionReturn(0);
}

/* The dmumps method (see the top): this rank's rows of the stencil's lower
 * triangle as 1-based triplets, b = A * ones by rows, one JOB=4 and one
 * JOB=3 with the right-hand side and solution distributed. */
#if BENCH_HAVE_DMUMPS
static PetscErrorCode oneshot_dmumps(PetscInt n, Result *r)
{
    DMUMPS_STRUC_C id;
    PetscInt N = n * n, first, rows, k;
    MUMPS_INT *irn, *jcn, *irhs, *isol;
    double *a, *rhs, *sol, t0, t1, t2, t3, err = 0;
    bench_usage u0;
    int64_t nz = 0;
    PetscMPIInt rank, size;

    PetscFunctionBeginUser;
    PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
    rows = N / size + (rank < N % size); /* PETSC_DECIDE's split, as SILC's */
    first = rank * (N / size) + (rank < N % size ? rank : N % size);
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    t0 = MPI_Wtime();
    PetscCall(PetscMalloc4(3 * rows + 1, &irn, 3 * rows + 1, &jcn, 3 * rows + 1, &a, rows + 1, &rhs));
    PetscCall(PetscMalloc1(rows + 1, &irhs));
    for (k = first; k < first + rows; k++) {
        PetscInt i = k / n, j = k % n;
        double s = 4;
        /* lower triangle: the neighbours above and to the left, then the diagonal */
        if (i > 0) irn[nz] = (MUMPS_INT)(k + 1), jcn[nz] = (MUMPS_INT)(k - n + 1), a[nz++] = -1, s -= 1;
        if (j > 0) irn[nz] = (MUMPS_INT)(k + 1), jcn[nz] = (MUMPS_INT)(k), a[nz++] = -1, s -= 1;
        irn[nz] = (MUMPS_INT)(k + 1), jcn[nz] = (MUMPS_INT)(k + 1), a[nz++] = 4;
        if (j < n - 1) s -= 1;
        if (i < n - 1) s -= 1;
        rhs[k - first] = s; /* (A * ones)_k */
        irhs[k - first] = (MUMPS_INT)(k + 1);
    }
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    u0 = usage_now();
    t1 = MPI_Wtime();
    memset(&id, 0, sizeof id);
    id.comm_fortran = (MUMPS_INT)MPI_Comm_c2f(PETSC_COMM_WORLD);
    id.par = 1;
    id.sym = 1;
    id.job = -1;
    dmumps_c(&id);
    PetscCheck(id.infog[0] >= 0, PETSC_COMM_WORLD, PETSC_ERR_LIB, "dmumps_c JOB=-1: INFOG(1)=%d", (int)id.infog[0]);
    id.icntl[0] = id.icntl[1] = id.icntl[2] = -1, id.icntl[3] = 0; /* silent */
    id.icntl[6] = 2;                                                 /* AMF */
    id.icntl[17] = 3;                                                /* distributed triplets */
    id.n = (MUMPS_INT)N;
    id.nnz_loc = nz;
    id.irn_loc = irn, id.jcn_loc = jcn, id.a_loc = a;
    id.job = 4;
    dmumps_c(&id);
    PetscCheck(id.infog[0] >= 0, PETSC_COMM_WORLD, PETSC_ERR_LIB, "dmumps_c JOB=4: INFOG(1)=%d", (int)id.infog[0]);
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    t2 = MPI_Wtime();
    PetscCall(PetscMalloc2(id.info[22] + 1, &isol, id.info[22] + 1, &sol));
    id.icntl[19] = 10, id.icntl[20] = 1; /* distributed right-hand side and solution */
    id.nrhs = 1;
    id.nloc_rhs = (MUMPS_INT)rows, id.lrhs_loc = (MUMPS_INT)(rows ? rows : 1);
    id.irhs_loc = irhs, id.rhs_loc = rhs;
    id.lsol_loc = id.info[22], id.isol_loc = isol, id.sol_loc = sol;
    id.job = 3;
    dmumps_c(&id);
    PetscCheck(id.infog[0] >= 0, PETSC_COMM_WORLD, PETSC_ERR_LIB, "dmumps_c JOB=3: INFOG(1)=%d", (int)id.infog[0]);
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    t3 = MPI_Wtime();
    PetscCall(summed_since(&u0, &r->used));
    for (k = 0; k < id.info[22]; k++) err = PetscMax(err, PetscAbsReal(sol[k] - 1));
    PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &err, 1, MPI_DOUBLE, MPI_MAX, PETSC_COMM_WORLD));
    r->ord = id.infog[6];
    id.job = -2;
    dmumps_c(&id);
    r->asm_s = t1 - t0;
    r->setup_s = t2 - t1;
    r->solve_s = t3 - t2;
    r->err = err;
    r->its = 0;
    r->did_oneshot = PETSC_TRUE;
    PetscCall(PetscFree2(isol, sol));
    PetscCall(PetscFree(irhs));
    PetscCall(PetscFree4(irn, jcn, a, rhs));
    PetscFunctionReturn(0);
}
#else
static PetscErrorCode oneshot_dmumps(PetscInt n, Result *r)
{
    PetscFunctionBeginUser;
    (void)n, (void)r;
    PetscCall(PetscPrintf(PETSC_COMM_WORLD, "mpi_direct: skipping dmumps: built without MPI MUMPS's dmumps_c.h\n"));
    PetscFunctionReturn(0);
}
#endif

static PetscErrorCode oneshot(const char *method, PetscInt n, Result *r)
{
    Mat A;
    Vec x, b;
    KSP ksp;
    PetscReal err;
    double t0, t1, t2, t3;
    bench_usage u0;
    PetscBool ok;

    PetscFunctionBeginUser;
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    t0 = MPI_Wtime();
    PetscCall(assemble(n, 4.0, -1.0, &A));
    PetscCall(MatCreateVecs(A, &x, &b));
    PetscCall(VecSet(x, 1.0));
    PetscCall(MatMult(A, x, b));
    PetscCall(VecSet(x, 0.0));
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    t1 = MPI_Wtime();

    PetscCall(available(method, A, &ok));
    if (ok) {
        PetscCall(make_ksp(method, A, &ksp));
        PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
        u0 = usage_now();
        t1 = MPI_Wtime();
        PetscCall(KSPSetUp(ksp));
        PetscCall(KSPSetUpOnBlocks(ksp)); /* block Jacobi's ILU, else in KSPSolve */
        PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
        t2 = MPI_Wtime();
        PetscCall(KSPSolve(ksp, b, x));
        PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
        t3 = MPI_Wtime();
        PetscCall(summed_since(&u0, &r->used));
        PetscCall(check_reason(ksp, "one-shot solve"));
        PetscCall(KSPGetIterationNumber(ksp, &r->its));
        PetscCall(mumps_ordering(method, ksp, &r->ord));
        PetscCall(VecShift(x, -1.0));
        PetscCall(VecNorm(x, NORM_INFINITY, &err));
        r->asm_s = t1 - t0;
        r->setup_s = t2 - t1;
        r->solve_s = t3 - t2;
        r->err = (double)err;
        r->did_oneshot = PETSC_TRUE;
        PetscCall(KSPDestroy(&ksp));
    }
    PetscCall(VecDestroy(&x));
    PetscCall(VecDestroy(&b));
    PetscCall(MatDestroy(&A));
    PetscFunctionReturn(0);
}

static PetscErrorCode loop(const char *method, PetscInt n, PetscInt steps, PetscReal dt, Result *r)
{
    Mat A, B;
    Vec u, rhs;
    KSP ksp;
    PetscInt rstart, rend, total_its = 0;
    PetscReal h = 1.0 / (PetscReal)(n + 1), rr = dt / (2.0 * h * h), sum;
    double t0, t1, t2;
    PetscBool ok;

    PetscFunctionBeginUser;
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    t0 = MPI_Wtime();
    PetscCall(assemble(n, 1.0 + 4.0 * rr, -rr, &A));
    PetscCall(available(method, A, &ok));
    if (!ok) {
        PetscCall(MatDestroy(&A));
        PetscFunctionReturn(0);
    }
    PetscCall(assemble(n, 1.0 - 4.0 * rr, rr, &B));
    PetscCall(MatCreateVecs(A, &u, &rhs));
    PetscCall(VecGetOwnershipRange(u, &rstart, &rend));
    for (PetscInt row = rstart; row < rend; row++) {
        PetscReal x = (PetscReal)(row % n + 1) * h, y = (PetscReal)(row / n + 1) * h;
        PetscScalar v = (x > 0.4 && x < 0.6 && y > 0.4 && y < 0.6) ? 1.0 : 0.0;
        PetscCall(VecSetValue(u, row, v, INSERT_VALUES));
    }
    PetscCall(VecAssemblyBegin(u));
    PetscCall(VecAssemblyEnd(u));
    PetscCall(make_ksp(method, A, &ksp));
    PetscCall(KSPSetUp(ksp));
    PetscCall(KSPSetUpOnBlocks(ksp));
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    t1 = MPI_Wtime();
    for (PetscInt s = 0; s < steps; s++) {
        PetscInt its;
        PetscCall(MatMult(B, u, rhs));
        PetscCall(KSPSolve(ksp, rhs, u));
        PetscCall(KSPGetIterationNumber(ksp, &its));
        total_its += its;
    }
    PetscCallMPI(MPI_Barrier(PETSC_COMM_WORLD));
    t2 = MPI_Wtime();
    PetscCall(check_reason(ksp, "last time step"));
    if (!r->did_oneshot) PetscCall(mumps_ordering(method, ksp, &r->ord));
    PetscCall(VecSum(u, &sum));
    r->lsetup_s = t1 - t0;
    r->step_s = (t2 - t1) / (double)steps;
    r->litis = (double)total_its / (double)steps;
    r->heat = (double)PetscRealPart(sum) * (double)(h * h);
    r->did_loop = PETSC_TRUE;
    PetscCall(KSPDestroy(&ksp));
    PetscCall(VecDestroy(&u));
    PetscCall(VecDestroy(&rhs));
    PetscCall(MatDestroy(&A));
    PetscCall(MatDestroy(&B));
    PetscFunctionReturn(0);
}

static PetscErrorCode print_row(const Result *r, PetscInt n, int np)
{
    char a[32] = "-", s[32] = "-", v[32] = "-", o[32] = "-", e[32] = "-", it[32] = "-",
         ls[32] = "-", st[32] = "-", li[32] = "-", h[32] = "-", ord[32] = "-", cpu[32] = "-",
         flt[32] = "-", sys[32] = "-";

    PetscFunctionBeginUser;
    if (r->did_oneshot) {
        snprintf(a, sizeof a, "%.4f", r->asm_s);
        snprintf(s, sizeof s, "%.4f", r->setup_s);
        snprintf(v, sizeof v, "%.4f", r->solve_s);
        snprintf(o, sizeof o, "%.4f", r->setup_s + r->solve_s);
        snprintf(e, sizeof e, "%.2e", r->err);
        snprintf(it, sizeof it, "%" PetscInt_FMT, r->its);
        snprintf(cpu, sizeof cpu, "%.2f", r->used.cpu_s);
        snprintf(flt, sizeof flt, "%lld", r->used.faults);
        snprintf(sys, sizeof sys, "%.2f", r->used.sys_s);
    }
    if (r->did_loop) {
        snprintf(ls, sizeof ls, "%.4f", r->lsetup_s);
        snprintf(st, sizeof st, "%.5f", r->step_s);
        snprintf(li, sizeof li, "%.1f", r->litis);
        snprintf(h, sizeof h, "%.10g", r->heat);
    }
    if (r->ord >= 0) snprintf(ord, sizeof ord, "%" PetscInt_FMT, r->ord);
    PetscCall(PetscPrintf(PETSC_COMM_WORLD,
                          "%-14s %5" PetscInt_FMT " %3d %9s %9s %9s %9s %9s %9s %4s %9s %6s %16s %3s %6s %8s %6s\n",
                          r->name, n, np, o, st, e, a, s, v, it, ls, li, h, ord, cpu, flt, sys));
    PetscFunctionReturn(0);
}

int main(int argc, char **argv)
{
    static const char *all[] = {"cg-hypre", "gmres-bjacobi", "mumps", "dmumps"};
    char method[64] = "mumps";
    PetscInt n = 500, steps = 0;
    PetscReal dt = 2e-4;
    PetscBool do_oneshot = PETSC_TRUE, amf = PETSC_TRUE, header = PETSC_TRUE, has;
    int np;

    PetscCall(PetscInitialize(&argc, &argv, NULL,
                              "mpi_direct: PETSc/MUMPS/hypre solves of the 2-D Laplacian, no SILC\n"));
    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &np));
    PetscCall(PetscOptionsGetInt(NULL, NULL, "-n", &n, NULL));
    PetscCall(PetscOptionsGetInt(NULL, NULL, "-steps", &steps, NULL));
    PetscCall(PetscOptionsGetReal(NULL, NULL, "-dt", &dt, NULL));
    PetscCall(PetscOptionsGetString(NULL, NULL, "-method", method, sizeof method, NULL));
    PetscCall(PetscOptionsGetBool(NULL, NULL, "-oneshot", &do_oneshot, NULL));
    PetscCall(PetscOptionsGetBool(NULL, NULL, "-amf", &amf, NULL));
    PetscCall(PetscOptionsGetBool(NULL, NULL, "-header", &header, NULL));
    PetscCheck(n >= 2, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE, "-n must be at least 2");
    PetscCheck(steps >= 0, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE, "-steps must be >= 0");

    /* AMF ordering (MUMPS ICNTL(7) = 2), exactly as if -mat_mumps_icntl_7 2
     * had been given; an explicit -mat_mumps_icntl_7 wins. */
    PetscCall(PetscOptionsHasName(NULL, NULL, "-mat_mumps_icntl_7", &has));
    if (amf && !has) PetscCall(PetscOptionsSetValue(NULL, "-mat_mumps_icntl_7", "2"));

    int first = 0, last = 3;
    if (strcmp(method, "all")) {
        for (first = 0; first < 4 && strcmp(method, all[first]); first++) {}
        PetscCheck(first < 4, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG,
                   "-method %s: expected cg-hypre, gmres-bjacobi, mumps, dmumps or all", method);
        last = first;
    }
    if (header)
        PetscCall(PetscPrintf(PETSC_COMM_WORLD,
                              "%-14s %5s %3s %9s %9s %9s %9s %9s %9s %4s %9s %6s %16s %3s %6s %8s %6s\n",
                              "method", "n", "np", "oneshot_s", "step_s", "err_inf", "asm_s",
                              "setup_s", "solve_s", "its", "lsetup_s", "litis", "heat", "ord",
                              "cpu_s", "faults", "sys_s"));
    for (int m = first; m <= last; m++) {
        Result r;
        memset(&r, 0, sizeof r);
        r.name = all[m];
        r.ord = -1;
        if (do_oneshot) PetscCall(strcmp(all[m], "dmumps") ? oneshot(all[m], n, &r) : oneshot_dmumps(n, &r));
        if (steps > 0 && strcmp(all[m], "dmumps")) PetscCall(loop(all[m], n, steps, dt, &r)); /* one-shot only */
        if (r.did_oneshot || r.did_loop) PetscCall(print_row(&r, n, np));
    }
    PetscCall(PetscFinalize());
    return 0;
}
