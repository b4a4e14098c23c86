/*
 * petsc.c -- the "petsc" backend: sparse solves with PETSc's KSP and PC.
 *
 * One operation, SILC_OP_SOLVE, under "solve.sparse" and "solve.sparse.spd",
 * sequential (PETSC_COMM_SELF).  The user drives PETSc with its own option
 * syntax through the typed option petsc.options ("-ksp_type cg -pc_type
 * hypre"); the direct packages of this PETSc build are reachable the PETSc way
 * (-pc_type lu -pc_factor_mat_solver_type mumps|umfpack|klu|superlu|cholmod).
 * Defaults are PETSc's own -- GMRES(30) with ILU(0), or ICC(0) when PETSc
 * knows A is symmetric (the plugin tells it when the host found it so), rtol
 * 1e-5, atol 1e-50, dtol 1e4, max_it 10000 -- except that the ".spd" class
 * starts from CG and a MUMPS factorization from the AMF ordering
 * (petsc_options.c says why).  `info` shows the tolerances in force.
 *
 * The matrix, its KSP (with the preconditioner or factorization PETSc built)
 * and the options database live in one attachment of A per class, so the
 * next solve with the same A and the same options only runs KSPSolve.  Every
 * solve reports the iterations, the true relative residual ||b - A x|| / ||b||
 * (computed here: PETSc's convergence test may watch a preconditioned norm),
 * and KSP's converged reason; a negative reason is an error naming it
 * (SILC_ENOTCONV for iteration limits, SILC_EBREAKDOWN for breakdowns,
 * SILC_ESINGULAR for a zero pivot in a factorization, SILC_ENOTSPD under the
 * ".spd" class when CG or a Cholesky factorization finds A indefinite, so the
 * dispatcher retries under "solve.sparse").  With a direct preconditioner
 * (lu, cholesky) the host's Hager-Higham estimator gives a 1-norm condition
 * estimate from a few extra triangular solves: the block form (ABI 1.3,
 * MatMatSolve) for MUMPS's factors, the one-column form for the others.
 *
 * PETSc and MPI start on the first solve, not at load: MPI_Init only if
 * nobody initialised MPI (a host or an MPI server may own it), PetscInitialize
 * only if PETSc is not running, with -no_signal_handler.  Each is finalized at
 * shutdown (process exit) only if this plugin started it.  OpenMPI's singleton
 * MPI_Init works as root here without OMPI_ALLOW_RUN_AS_ROOT (only mpirun
 * wants it).  Around every stretch of PETSc calls PetscReturnErrorHandler is
 * pushed, so errors come back as codes and PETSc never prints or aborts.
 */
#include "petsc_plugin.h"

#include "common/blas_threads.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STR_(x) #x
#define STR(x) STR_(x)
#define PETSC_VERSION_TEXT                                                                         \
    STR(PETSC_VERSION_MAJOR) "." STR(PETSC_VERSION_MINOR) "." STR(PETSC_VERSION_SUBMINOR)

const silc_host_api *psc_host;
#define host psc_host

/* ---- starting and stopping PETSc ------------------------------------------------ */

static enum { START_NONE, START_OK, START_FAILED } start_state;
static char start_error[256];
static int began_mpi, began_petsc, finished;

/* PetscInitialize keeps pointers to its arguments for the life of the process. */
static char arg0[] = "silc", arg1[] = "-no_signal_handler";
static char *petsc_argv[] = {arg0, arg1, NULL};
static int petsc_argc = 2;

static int petsc_start(silc_call *call)
{
    int flag = 0, rc;
    PetscBool running = PETSC_FALSE;
    PetscErrorCode ierr;
    char **argv = petsc_argv;
    if (start_state == START_OK) return SILC_OK;
    if (start_state == START_FAILED) return host->error(call, SILC_ELIB, "%s", start_error);
    start_state = START_FAILED;
    rc = MPI_Initialized(&flag);
    if (rc == MPI_SUCCESS && !flag) {
        rc = MPI_Init(NULL, NULL);
        if (rc != MPI_SUCCESS) {
            char text[MPI_MAX_ERROR_STRING] = "";
            int len = 0;
            MPI_Error_string(rc, text, &len);
            snprintf(start_error, sizeof start_error, "MPI_Init: %.200s (MPI error %d)", text, rc);
            return host->error(call, SILC_ELIB, "%s", start_error);
        }
        began_mpi = 1;
    }
    if ((ierr = PetscInitialized(&running)) == 0 && !running) {
        ierr = PetscInitialize(&petsc_argc, &argv, NULL, NULL);
        if (ierr) {
            snprintf(start_error, sizeof start_error, "PetscInitialize failed (PETSc error %d)",
                     (int)ierr);
            return host->error(call, SILC_ELIB, "%s", start_error);
        }
        began_petsc = 1;
    }
    start_state = START_OK;
    return SILC_OK;
}

/* Errors return as codes while the plugin is inside PETSc; a host program
 * that runs PETSc itself keeps its own handler outside. */
static void enter(void)
{
    PetscPushErrorHandler(PetscReturnErrorHandler, NULL);
}

static void leave(void)
{
    PetscPopErrorHandler();
}

static void petsc_shutdown(void)
{
    if (start_state != START_OK || finished) return;
    finished = 1;
    if (began_petsc) PetscFinalize();
    if (began_mpi) {
        int done = 0;
        MPI_Finalized(&done);
        if (!done) MPI_Finalize();
    }
}

/* ---- errors ------------------------------------------------------------------- */

int psc_fail(silc_call *call, const char *what, PetscErrorCode ierr)
{
    const char *generic = NULL;
    char *specific = NULL, msg[512] = "", gen[160] = "";
    int status = SILC_ELIB;
    PetscErrorMessage((int)ierr, &generic, &specific);
    if (specific) snprintf(msg, sizeof msg, "%s", specific);
    if (generic) snprintf(gen, sizeof gen, ": %s", generic);
    /* PETSc's texts continue with "\nsee https://..." lines. */
    msg[strcspn(msg, "\n")] = '\0';
    gen[strcspn(gen, "\n")] = '\0';
    switch (ierr) {
    case PETSC_ERR_MEM: status = SILC_ENOMEM; break;
    case PETSC_ERR_MAT_LU_ZRPVT:
    case PETSC_ERR_MAT_CH_ZRPVT: status = SILC_ESINGULAR; break;
    case PETSC_ERR_ARG_UNKNOWN_TYPE:
    case PETSC_ERR_ARG_OUTOFRANGE:
    case PETSC_ERR_ARG_WRONG: status = SILC_EARG; break;
    case PETSC_ERR_MISSING_FACTOR: status = SILC_EUNSUP; break;
    default: break;
    }
    return host->error(call, status, "%s: %s (PETSc error %d%s)", what,
                       msg[0] ? msg : "failed", (int)ierr, gen);
}

/* ---- the solver attachment ---------------------------------------------------- */

typedef struct psc_solver {
    Mat A;
    KSP ksp;
    PetscOptions opts;   /* pushed as PETSc's default around every use of ksp */
    char *text;          /* the user's option string it was configured from */
    int spd;             /* built under the ".spd" class */
    int checked;         /* the unused-option check passed */
    int direct;          /* the PC is a complete factorization (lu, cholesky) */
    int condest;         /* a condition estimate was asked for */
    double setup_seconds, cond_est;
    int cond_block;      /* cond_est came from the block estimator */
    char method[64];
} psc_solver;

static void solver_free(void *p)
{
    psc_solver *S = p;
    if (!S) return;
    /* After PetscFinalize (values freed late at exit) PETSc objects are gone with it. */
    if (!finished && start_state == START_OK) {
        enter();
        KSPDestroy(&S->ksp);
        MatDestroy(&S->A);
        PetscOptionsDestroy(&S->opts);
        leave();
    }
    host->free(S->text);
    host->free(S);
}

#define TRY(expr, what)                                                                            \
    do {                                                                                           \
        PetscErrorCode e_ = (expr);                                                                \
        if (e_) {                                                                                  \
            rc = psc_fail(call, what, e_);                                                         \
            goto done;                                                                             \
        }                                                                                          \
    } while (0)

/* A as a MATSEQAIJ (PETSc copies the arrays; PetscInt is 32-bit in this build). */
static int build_matrix(silc_call *call, const silc_view *a, int spd, Mat *out)
{
    PetscInt *ia = host->alloc((size_t)(a->n + 1) * sizeof *ia);
    PetscInt *ja = host->alloc((size_t)(a->nnz > 0 ? a->nnz : 1) * sizeof *ja);
    Mat M = NULL;
    int64_t k;
    int rc = SILC_OK;
    *out = NULL;
    if (!ia || !ja) {
        rc = host->error(call, SILC_ENOMEM, "out of memory for %lld PetscInt indices",
                         (long long)(a->nnz + a->n + 1));
        goto done;
    }
    for (k = 0; k <= a->n; k++) ia[k] = (PetscInt)a->rowptr[k];
    for (k = 0; k < a->nnz; k++) ja[k] = (PetscInt)a->colind[k];
    TRY(MatCreate(PETSC_COMM_SELF, &M), "MatCreate");
    TRY(MatSetSizes(M, (PetscInt)a->n, (PetscInt)a->n, (PetscInt)a->n, (PetscInt)a->n), "MatSetSizes");
    TRY(MatSetType(M, MATSEQAIJ), "MatSetType");
    TRY(MatSeqAIJSetPreallocationCSR(M, ia, ja, a->val), "MatSeqAIJSetPreallocationCSR");
    /* What the host knows about A helps GAMG (CG eigenvalue estimates), MUMPS (SYM) and others. */
    if (silc_props_of(host, call->in[0], SILC_PROPS_SYMMETRY)->symmetric) {
        TRY(MatSetOption(M, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption(MAT_SYMMETRIC)");
        TRY(MatSetOption(M, MAT_SYMMETRY_ETERNAL, PETSC_TRUE), "MatSetOption(MAT_SYMMETRY_ETERNAL)");
    }
    if (spd) TRY(MatSetOption(M, MAT_SPD, PETSC_TRUE), "MatSetOption(MAT_SPD)");
    *out = M;
    M = NULL;
done:
    MatDestroy(&M);
    host->free(ia);
    host->free(ja);
    return rc;
}

static int pc_is(PC pc, const char *type)
{
    PetscBool same = PETSC_FALSE;
    PetscObjectTypeCompare((PetscObject)pc, type, &same);
    return same == PETSC_TRUE;
}

static int pc_is_factor(PC pc)
{
    return pc_is(pc, PCLU) || pc_is(pc, PCCHOLESKY) || pc_is(pc, PCILU) || pc_is(pc, PCICC);
}

/* "KSP cg + PC hypre (boomeramg)", "KSP preonly + PC lu (mumps)". */
static void describe(psc_solver *S)
{
    KSPType kt = NULL;
    PCType pt = NULL;
    const char *detail = NULL;
    PC pc = NULL;
    KSPGetType(S->ksp, &kt);
    KSPGetPC(S->ksp, &pc);
    PCGetType(pc, &pt);
    if (pc_is_factor(pc)) {
        MatSolverType st = NULL;
        PCFactorGetMatSolverType(pc, &st);
        detail = st;
    }
#if defined(PETSC_HAVE_HYPRE)
    if (pc_is(pc, PCHYPRE)) PCHYPREGetType(pc, &detail);
#endif
    snprintf(S->method, sizeof S->method, "KSP %s + PC %s%s%s%s", kt ? kt : "?", pt ? pt : "?",
             detail ? " (" : "", detail ? detail : "", detail ? ")" : "");
}

/* A failed preconditioner: a zero pivot is a singular matrix, or under the
 * ".spd" class a matrix that is not positive definite. */
static int pc_failed(silc_call *call, psc_solver *S, const char *where)
{
    PC pc = NULL;
    PCFailedReason fr = PC_NOERROR;
    int status = SILC_ELIB;
    KSPGetPC(S->ksp, &pc);
    PCGetFailedReason(pc, &fr);
    if (fr == PC_FACTOR_STRUCT_ZEROPIVOT || fr == PC_FACTOR_NUMERIC_ZEROPIVOT)
        status = S->spd ? SILC_ENOTSPD : SILC_ESINGULAR;
    else if (fr == PC_FACTOR_OUTMEMORY)
        status = SILC_ENOMEM;
    return host->error(call, status, "%s: preconditioner failed: PC_%s (%s)%s", where,
                       fr >= PC_SETUP_ERROR && fr <= PC_SUBPC_ERROR ? PCFailedReasons[fr] : "?",
                       S->method,
                       status == SILC_ESINGULAR ? ": the matrix is singular"
                       : status == SILC_ENOTSPD ? ": the matrix is not positive definite"
                                                : "");
}

/* ---- condition estimate through the factorization ------------------------------ */

typedef struct cond_ctx {
    Mat F;
    Vec in, out;
    int symmetric;
    PetscInt n;
    double *block;       /* n x COND_COLS scratch of cond_apply_block */
} cond_ctx;

/* The block estimate's shape (the MUMPS plugin's): MUMPS's solve phase is
 * per-front overhead, about the same for two columns as for one. */
#define COND_COLS 2
#define COND_STEPS 2

/* x <- A^-1 x (trans: A^-T x) with the factors PETSc computed. */
static int cond_apply(void *ctx, double *x, int trans, double *work)
{
    cond_ctx *c = ctx;
    PetscErrorCode ierr;
    if (VecPlaceArray(c->in, x) || VecPlaceArray(c->out, work)) return -1;
    ierr = trans && !c->symmetric ? MatSolveTranspose(c->F, c->in, c->out) : MatSolve(c->F, c->in, c->out);
    VecResetArray(c->in);
    VecResetArray(c->out);
    if (ierr) return -1;
    memcpy(x, work, (size_t)c->n * sizeof *x);
    return 0;
}

/* X <- A^-1 X for the n x t column-major block X (trans: A^-T X) in one
 * MatMatSolve: one MUMPS solve phase for the block. */
static int cond_apply_block(void *ctx, double *X, int t, int trans)
{
    cond_ctx *c = ctx;
    Mat B = NULL, Y = NULL;
    PetscErrorCode ierr = MatCreateSeqDense(PETSC_COMM_SELF, c->n, t, X, &B);
    if (!ierr) ierr = MatCreateSeqDense(PETSC_COMM_SELF, c->n, t, c->block, &Y);
    if (!ierr)
        ierr = trans && !c->symmetric ? MatMatSolveTranspose(c->F, B, Y) : MatMatSolve(c->F, B, Y);
    MatDestroy(&B);
    MatDestroy(&Y);
    if (ierr) return -1;
    memcpy(X, c->block, (size_t)c->n * (size_t)t * sizeof *X);
    return 0;
}

/* A block of right-hand sides costs MUMPS one solve phase, dominated by
 * per-front overhead, so its factors get the block estimate: at most three
 * block solves where the one-column form makes four to ten single ones
 * (memplus, -pc_type lu with MUMPS: 82 -> 67 ms, 43 without an estimate;
 * bcsstk16 40 -> 37, 33).
 * Every other package solves a block column by column, where the
 * one-column estimate needs fewer solves. */
static int block_estimate_pays(Mat F, int symmetric)
{
    MatSolverType type = NULL;
    PetscBool mat_solve = PETSC_FALSE, mat_solve_t = PETSC_FALSE;
    if (MatFactorGetSolverType(F, &type) || !type || strcmp(type, MATSOLVERMUMPS) != 0) return 0;
    if (MatHasOperation(F, MATOP_MAT_SOLVE, &mat_solve) ||
        MatHasOperation(F, MATOP_MAT_SOLVE_TRANSPOSE, &mat_solve_t))
        return 0;
    return mat_solve && (symmetric || mat_solve_t);
}

static double condition_estimate(psc_solver *S, int64_t n, double norm1)
{
    cond_ctx c = {NULL, NULL, NULL, 0, (PetscInt)n, NULL};
    PC pc = NULL;
    double *work = NULL, est = -1;
    KSPGetPC(S->ksp, &pc);
    c.symmetric = pc_is(pc, PCCHOLESKY);
    S->cond_block = 0;
    if (PCFactorGetMatrix(pc, &c.F) || !c.F) return -1;
    if (block_estimate_pays(c.F, c.symmetric) &&
        (c.block = host->alloc((size_t)n * COND_COLS * sizeof *c.block))) {
        est = host->inv_norm1_est_block(n, COND_COLS, COND_STEPS, cond_apply_block, &c, NULL);
        host->free(c.block);
        S->cond_block = est >= 0;
    }
    if (!S->cond_block && (work = host->alloc((size_t)n * sizeof *work))) {
        if (!VecCreateSeqWithArray(PETSC_COMM_SELF, 1, (PetscInt)n, NULL, &c.in) &&
            !VecCreateSeqWithArray(PETSC_COMM_SELF, 1, (PetscInt)n, NULL, &c.out))
            est = host->inv_norm1_est(n, cond_apply, &c, work);
        VecDestroy(&c.in);
        VecDestroy(&c.out);
        host->free(work);
    }
    return est >= 0 && isfinite(est) ? norm1 * est : -1;
}

/* Builds matrix, options and KSP, and sets the preconditioner up (PETSc's options
 * database pushed by the caller). */
static int solver_setup(silc_call *call, psc_solver *S, const silc_view *a)
{
    PC pc = NULL;
    PCFailedReason fr = PC_NOERROR;
    double t0 = host->now();
    int rc = SILC_OK;
    if ((rc = build_matrix(call, a, S->spd, &S->A))) return rc;
    TRY(KSPCreate(PETSC_COMM_SELF, &S->ksp), "KSPCreate");
    TRY(PetscObjectSetOptions((PetscObject)S->ksp, S->opts), "PetscObjectSetOptions");
    TRY(KSPSetOperators(S->ksp, S->A, S->A), "KSPSetOperators");
    TRY(KSPSetFromOptions(S->ksp), "KSPSetFromOptions");
    TRY(KSPSetUp(S->ksp), "KSPSetUp");
    describe(S);
    TRY(KSPGetPC(S->ksp, &pc), "KSPGetPC");
    TRY(PCGetFailedReason(pc, &fr), "PCGetFailedReason");
    if (pc_is_factor(pc) && fr == PC_NOERROR) {
        Mat F = NULL;
        MatFactorError fe = MAT_FACTOR_NOERROR;
        if (!PCFactorGetMatrix(pc, &F) && F && !MatFactorGetError(F, &fe) && fe != MAT_FACTOR_NOERROR)
            PCSetFailedReason(pc, (PCFailedReason)fe);
        PCGetFailedReason(pc, &fr);
    }
    if (fr != PC_NOERROR) return pc_failed(call, S, "KSPSetUp");
    S->direct = pc_is(pc, PCLU) || pc_is(pc, PCCHOLESKY);
    if (S->direct && S->condest)
        S->cond_est = condition_estimate(S, a->n, silc_props_of(host, call->in[0], SILC_PROPS_NORMS)->norm1);
    S->setup_seconds = host->now() - t0;
done:
    return rc;
}

/* ---- the solve ------------------------------------------------------------------ */

static int ends_with_spd(const char *cls)
{
    size_t n = cls ? strlen(cls) : 0;
    return n >= 4 && strcmp(cls + n - 4, ".spd") == 0;
}

static int solve_accepts(const silc_call *call, const char **why)
{
    silc_view a;
    if (call->nin < 2) {
        *why = "needs a right-hand side";
        return 0;
    }
    if (!call->op_class || strncmp(call->op_class, "solve.sparse", 12) != 0 ||
        (call->op_class[12] && strcmp(call->op_class + 12, ".spd") != 0)) {
        *why = "PETSc KSP here serves solve.sparse and solve.sparse.spd only (dense and band "
               "systems are better left to LAPACK)";
        return 0;
    }
    host->view(call->in[0], &a);
    if (a.format != SILC_FMT_CSR) {
        *why = "needs a sparse (CSR) matrix";
        return 0;
    }
    if (a.m != a.n) {
        *why = "needs a square matrix";
        return 0;
    }
    if (a.n >= PETSC_MAX_INT || a.nnz >= PETSC_MAX_INT) {
        *why = "matrix too large for this PETSc's 32-bit PetscInt";
        return 0;
    }
    if (ends_with_spd(call->op_class) && !silc_props_of(host, call->in[0], SILC_PROPS_SYMMETRY)->symmetric) {
        *why = "CG needs a symmetric matrix";
        return 0;
    }
    return 1;
}

/* Entry (i, j) of a dense or band view, 0 outside the band. */
static double full_get(const silc_view *v, int64_t i, int64_t j)
{
    if (v->format == SILC_FMT_DENSE) return v->val[i + j * v->m];
    if (i - j > v->kl || j - i > v->ku) return 0.0;
    return v->val[(v->ku + i - j) + j * v->ld];
}

/* B (any format) as a dense column-major copy: KSPSolve may scale b in place. */
static void dense_copy(const silc_view *b, double *x)
{
    int64_t i, j, k;
    if (b->format == SILC_FMT_DENSE) {
        memcpy(x, b->val, (size_t)(b->m * b->n) * sizeof(double));
    } else if (b->format == SILC_FMT_CSR) {
        memset(x, 0, (size_t)(b->m * b->n) * sizeof(double));
        for (i = 0; i < b->m; i++)
            for (k = b->rowptr[i]; k < b->rowptr[i + 1]; k++) x[i + b->colind[k] * b->m] += b->val[k];
    } else {
        for (j = 0; j < b->n; j++)
            for (i = 0; i < b->m; i++) x[i + j * b->m] = full_get(b, i, j);
    }
}

static const char *reason_name(KSPConvergedReason r)
{
    return r >= KSP_DIVERGED_PC_FAILED && r <= KSP_CONVERGED_ATOL_NORMAL ? KSPConvergedReasons[r] : "UNKNOWN";
}

/* The error of a negative converged reason. */
static int diverged(silc_call *call, psc_solver *S, KSPConvergedReason reason, PetscInt its,
                    double resid, int64_t column, int64_t ncols)
{
    int status = SILC_EBREAKDOWN;
    char where[48] = "";
    if (reason == KSP_DIVERGED_PC_FAILED) return pc_failed(call, S, "KSPSolve");
    if (reason == KSP_DIVERGED_ITS || reason == KSP_DIVERGED_DTOL) status = SILC_ENOTCONV;
    if (S->spd && (reason == KSP_DIVERGED_INDEFINITE_PC || reason == KSP_DIVERGED_INDEFINITE_MAT))
        status = SILC_ENOTSPD;
    if (ncols > 1) snprintf(where, sizeof where, " on right-hand side %lld", (long long)column + 1);
    return host->error(call, status,
                       "KSPSolve: diverged (KSP_%s) after %lld iteration%s%s, relative "
                       "residual %.3g (%s)",
                       reason_name(reason), (long long)its, its == 1 ? "" : "s", where, resid,
                       S->method);
}

/* Solves column by column; fills X and the report. */
static int run_solves(silc_call *call, psc_solver *S, double *B, double *X, int64_t n, int64_t ncols)
{
    silc_report *r = call->report;
    Vec b = NULL, x = NULL, res = NULL;
    KSPConvergedReason reason = KSP_CONVERGED_ITERATING, first = KSP_CONVERGED_ITERATING;
    PetscInt its = 0;
    PetscReal nb, nr, rtol = 0, atol = 0, dtol = 0;
    PetscInt maxit = 0;
    double worst = 0;
    int64_t j, max_its = 0;
    int rc = SILC_OK, len;
    TRY(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, (PetscInt)n, NULL, &b), "VecCreateSeqWithArray");
    TRY(VecCreateSeqWithArray(PETSC_COMM_SELF, 1, (PetscInt)n, NULL, &x), "VecCreateSeqWithArray");
    TRY(VecCreateSeq(PETSC_COMM_SELF, (PetscInt)n, &res), "VecCreateSeq");
    for (j = 0; j < ncols; j++) {
        double rel;
        TRY(VecPlaceArray(b, B + j * n), "VecPlaceArray");
        TRY(VecPlaceArray(x, X + j * n), "VecPlaceArray");
        TRY(KSPSolve(S->ksp, b, x), "KSPSolve");
        TRY(KSPGetConvergedReason(S->ksp, &reason), "KSPGetConvergedReason");
        TRY(KSPGetIterationNumber(S->ksp, &its), "KSPGetIterationNumber");
        /* The true residual b - A x, whatever norm the convergence test watched. */
        TRY(MatMult(S->A, x, res), "MatMult");
        TRY(VecAYPX(res, -1.0, b), "VecAYPX");
        TRY(VecNorm(res, NORM_2, &nr), "VecNorm");
        TRY(VecNorm(b, NORM_2, &nb), "VecNorm");
        VecResetArray(b);
        VecResetArray(x);
        rel = nb > 0 ? (double)(nr / nb) : (double)nr;
        if (reason < 0) {
            rc = diverged(call, S, reason, its, rel, j, ncols);
            goto done;
        }
        if (!isfinite(rel)) {
            rc = host->error(call, S->direct ? SILC_ESINGULAR : SILC_EBREAKDOWN,
                             "KSPSolve: the solution has NaN or Inf entries after %lld "
                             "iteration%s (KSP_%s, %s)%s",
                             (long long)its, its == 1 ? "" : "s", reason_name(reason), S->method,
                             S->direct ? ": the matrix is singular" : "");
            goto done;
        }
        if (j == 0) first = reason;
        if (its > max_its) max_its = its;
        if (rel > worst) worst = rel;
    }
    KSPGetTolerances(S->ksp, &rtol, &atol, &dtol, &maxit);
    r->iterations = max_its;
    r->resid = worst;
    len = snprintf(r->note, sizeof r->note, "KSP_%s; rtol %g, atol %g, dtol %g, max_it %lld",
                   reason_name(first), (double)rtol, (double)atol, (double)dtol, (long long)maxit);
    if (ncols > 1 && len < (int)sizeof r->note)
        snprintf(r->note + len, sizeof r->note - (size_t)len,
                 "; %lld right-hand sides (iterations and residual: the worst)", (long long)ncols);
done:
    if (rc) {
        VecResetArray(b);
        VecResetArray(x);
    }
    VecDestroy(&b);
    VecDestroy(&x);
    VecDestroy(&res);
    return rc;
}

static int solve_run(silc_call *call)
{
    silc_view a, bv, o;
    silc_report *r = call->report;
    psc_solver *S = NULL;
    silc_value *X = NULL;
    double *B = NULL, t0;
    const char *why = NULL, *text;
    int spd = ends_with_spd(call->op_class), rc, pushed = 0, fresh = 0;
    PetscErrorCode ierr;
    const char *key = spd ? "petsc.ksp.spd" : "petsc.ksp";
    int64_t condest = 1;
    if (!solve_accepts(call, &why)) return host->error(call, SILC_EDECLINE, "%s", why);
    text = host->option_string(call, "options", "");
    if (!text) text = "";
    if ((rc = host->option_int(call, "condest", 1, &condest))) return rc;
    host->view(call->in[0], &a);
    host->view(call->in[1], &bv);
    if (bv.m != a.n)
        return host->error(call, SILC_EARG, "right-hand side has %lld rows, A has %lld",
                           (long long)bv.m, (long long)a.n);
    if ((rc = petsc_start(call))) return rc;
    X = host->dense_new(bv.m, bv.n);
    if (!X) return host->error(call, SILC_ENOMEM, "cannot allocate the %lldx%lld solution",
                               (long long)bv.m, (long long)bv.n);
    if (a.n == 0 || bv.n == 0) {
        call->out = X;
        return SILC_OK;
    }
    host->view(X, &o);
    enter();
    B = host->alloc((size_t)(bv.m * bv.n) * sizeof *B);
    if (!B) {
        rc = host->error(call, SILC_ENOMEM, "out of memory for the right-hand side");
        goto done;
    }
    dense_copy(&bv, B);
    S = host->attach_get(call->in[0], key);
    if (S && strcmp(S->text, text) == 0 && S->condest == (condest != 0)) {
        r->reused_factor = 1;
    } else {
        size_t len = strlen(text) + 1;
        fresh = 1;
        S = host->calloc(1, sizeof *S);
        if (!S || !(S->text = host->alloc(len))) {
            rc = host->error(call, SILC_ENOMEM, "out of memory");
            goto done;
        }
        memcpy(S->text, text, len);
        S->spd = spd;
        S->condest = condest != 0;
        S->cond_est = -1;
        if ((rc = psc_options_create(call, text, spd, &S->opts))) goto done;
    }
    if ((ierr = PetscOptionsPush(S->opts))) {
        rc = psc_fail(call, "PetscOptionsPush", ierr);
        goto done;
    }
    pushed = 1;
    if (fresh) {
        if ((rc = solver_setup(call, S, &a))) goto done;
        r->factor_seconds = S->setup_seconds;
    }
    t0 = host->now();
    if ((rc = run_solves(call, S, B, o.val, a.n, bv.n))) goto done;
    r->solve_seconds = host->now() - t0;
    if (!S->checked) {
        if ((rc = psc_options_check_used(call, S->opts, text, spd, S->A))) goto done;
        S->checked = 1;
    }
    snprintf(r->method, sizeof r->method, "%s", S->method);
    r->cond_est = S->cond_est;
    if (S->cond_est >= 0) {
        size_t len = strlen(r->note);
        if (S->cond_block)
            snprintf(r->note + len, sizeof r->note - len,
                     "; 1-norm condition estimate: block Hager-Higham (%d columns, %d steps; MatMatSolve)",
                     COND_COLS, COND_STEPS);
        else
            snprintf(r->note + len, sizeof r->note - len,
                     "; 1-norm condition estimate: Hager-Higham (MatSolve)");
    }
    if (fresh) {
        if (pushed) PetscOptionsPop();
        pushed = 0;
        /* attach_set destroys the solver of other options it replaces. */
        if (host->attach_set(call->in[0], key, S, solver_free)) {
            rc = host->error(call, SILC_ENOMEM, "cannot attach the solver");
            goto done;
        }
        fresh = 0;
    }
done:
    if (pushed) PetscOptionsPop();
    if (fresh) solver_free(S);
    leave();
    host->free(B);
    if (rc) {
        host->release(X);
        return rc;
    }
    call->out = X;
    return SILC_OK;
}

/* ---- tables ----------------------------------------------------------------------- */

static const silc_op_entry petsc_ops[SILC_OP_COUNT] = {
    [SILC_OP_SOLVE] = {solve_run, solve_accepts},
};

static const silc_backend petsc_backends[] = {
    {NULL, "PETSc " PETSC_VERSION_TEXT " KSP/PC, sequential (options: -ksp_type, -pc_type, ...)",
     SILC_OP_COUNT, petsc_ops},
};

static const silc_option_spec petsc_options[] = {
    {"options", SILC_OPT_STRING, "",
     "PETSc options for the KSP and PC, e.g. -ksp_type cg -pc_type hypre -ksp_rtol 1e-10; empty = "
     "PETSc's defaults: GMRES(30) + ILU(0) (ICC(0) for a symmetric A), rtol 1e-5, atol 1e-50, "
     "max_it 10000, CG under solve.sparse.spd; options PETSc does not read are errors "
     "(-options_left no: warnings)"},
    {"condest", SILC_OPT_BOOL, "true",
     "estimate the 1-norm condition number when the PC is a direct factorization (lu, cholesky): "
     "2-10 extra triangular solves per factorization"},
};

static silc_plugin petsc_plugin = {
    SILC_ABI_MAJOR, SILC_ABI_MINOR, sizeof(silc_plugin), (int)sizeof(silc_index),
    "petsc", "1.0 PETSc " PETSC_VERSION_TEXT,
    1, petsc_backends,
    (int)(sizeof petsc_options / sizeof petsc_options[0]), petsc_options,
    NULL, /* set_threads: blas_threads_attach fills it when OpenBLAS is found */
    petsc_shutdown,
};

SILC_PLUGIN_EXPORT int silc_plugin_init(const silc_host_api *h, const silc_plugin **out,
                                        const char **errmsg)
{
    if (silc_host_check(h, SILC_HOST_NEEDS(inv_norm1_est_block), errmsg) || !out) return 1;
    host = h;
    blas_threads_attach(&petsc_plugin); /* threaded only through its BLAS */
    *out = &petsc_plugin;
    return 0;
}
