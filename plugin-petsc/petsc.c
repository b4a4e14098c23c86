/*
 * petsc.c -- the "petsc" backend: sparse solves with PETSc's KSP and PC,
 * sequential on whole operands, collective on row-distributed ones.
 *
 * One operation, SILC_OP_SOLVE, under "solve.sparse" and "solve.sparse.spd".
 * The user drives PETSc with its own option syntax through the typed option
 * petsc.options ("-ksp_type cg -pc_type hypre"); the direct packages of this
 * PETSc build are reachable the PETSc way (-pc_type lu
 * -pc_factor_mat_solver_type mumps|superlu_dist|umfpack|klu|superlu|cholmod).
 * Defaults are PETSc's own -- GMRES(30) with ILU(0), or ICC(0) when PETSc
 * knows A is symmetric (the plugin tells it when the host found it so), block
 * Jacobi with ILU(0) blocks on several ranks, rtol 1e-5, atol 1e-50, dtol
 * 1e4, max_it 10000 -- except that the ".spd" class starts from CG and a
 * MUMPS factorization from the AMF ordering (petsc_options.c says why).
 * `info` shows the tolerances in force.
 *
 * Whole operands (host->comm gives NULL) are solved on PETSC_COMM_SELF with a
 * MATSEQAIJ, even in an MPI process.  Operands distributed by row blocks (ABI
 * 1.5: the backend declares SOLVE in collective_ops) are solved on the host's
 * communicator: every rank runs solve_run at once, wraps its rows of A
 * (global column indices) in a MATMPIAIJ and its rows of b and x in MPI
 * vectors, and PETSc does the rest collectively.  The two are one code path
 * with the communicator as a parameter (psc_ranks); what differs is the
 * matrix and vector type and that a distributed solve has no condition
 * estimate on more than one rank.  A failure found on one rank only (an
 * allocation, a size check) is first agreed over the communicator (agree():
 * the lowest failing rank's message on every rank), so that no rank is left
 * waiting inside a collective PETSc call; PETSc's collective calls fail on
 * every rank together and need no agreement.
 *
 * The matrix, its KSP (with the preconditioner or factorization PETSc built)
 * and the options database live in one attachment of A per class, so the
 * next solve with the same A and the same options only runs KSPSolve.  On
 * distributed operands the attachment is per rank, and the ranks agree on
 * reusing it, since destroying a KSP (MUMPS's JOB=-2, hypre) is collective.
 * Every solve reports the iterations, the true relative residual ||b - A x||
 * / ||b|| (computed here, collectively: PETSc's convergence test may watch a
 * preconditioned norm), and KSP's converged reason; a negative reason is an
 * error naming it (SILC_ENOTCONV for iteration limits, SILC_EBREAKDOWN for
 * breakdowns, SILC_ESINGULAR for a zero pivot in a factorization,
 * SILC_ENOTSPD under the ".spd" class when CG or a Cholesky factorization
 * finds A indefinite, so the dispatcher retries under "solve.sparse").  With
 * a direct preconditioner (lu, cholesky) on one process the host's
 * Hager-Higham estimator gives a 1-norm condition estimate from a few extra
 * triangular solves: the block form (ABI 1.3, MatMatSolve) for MUMPS's
 * factors, the one-column form for the others.
 *
 * PETSc and MPI start on the first solve, not at load: MPI_Init only if
 * nobody initialised MPI (a host or an MPI server may own it), PetscInitialize
 * only if PETSc is not running, with -no_signal_handler; when that first solve
 * is collective, PETSC_COMM_WORLD becomes (a duplicate of) the host's
 * communicator first, since PetscInitialize is collective over it.  Each is
 * finalized at shutdown (process exit) only if this plugin started it and MPI
 * is still running (an MPI program finalizes MPI before exit).  OpenMPI's
 * singleton MPI_Init works as root here without OMPI_ALLOW_RUN_AS_ROOT (only
 * mpirun wants it).  Around every stretch of PETSc calls
 * PetscReturnErrorHandler is pushed, so errors come back as codes and PETSc
 * never prints or aborts.
 */
#include "petsc_plugin.h"

#include "common/blas_threads.h"

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STR_(x) #x
#define STR(x) STR_(x)
#define PETSC_VERSION_TEXT                                                                         \
    STR(PETSC_VERSION_MAJOR) "." STR(PETSC_VERSION_MINOR) "." STR(PETSC_VERSION_SUBMINOR)

const silc_host_api *psc_host;
#define host psc_host

/* The host has ABI 1.5's comm, layout and dist_dense_new: only then does the
 * plugin declare its collective SOLVE and ask for the call's communicator. */
static int host_dist;

/* ---- starting and stopping PETSc ------------------------------------------------ */

static enum { START_NONE, START_OK, START_FAILED } start_state;
static char start_error[256];
static int began_mpi, began_petsc, finished;
static MPI_Comm petsc_world = MPI_COMM_NULL; /* our duplicate, when PETSC_COMM_WORLD is it */

/* PetscInitialize keeps pointers to its arguments for the life of the process. */
static char arg0[] = "silc", arg1[] = "-no_signal_handler";
static char *petsc_argv[] = {arg0, arg1, NULL};
static int petsc_argc = 2;

static int mpi_down(void)
{
    int down = 0;
    MPI_Finalized(&down);
    return down;
}

/* comm: the host's communicator when the first solve is collective (every
 * rank of it is here at once), else NULL. */
static int petsc_start(silc_call *call, const MPI_Comm *comm)
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
        /* A communicator from the host means the program started MPI. */
        if (comm) {
            snprintf(start_error, sizeof start_error,
                     "petsc: the host gave a communicator but MPI is not initialized");
            return host->error(call, SILC_EINTERNAL, "%s", start_error);
        }
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
        /* PetscInitialize is collective over PETSC_COMM_WORLD, which would
         * otherwise be MPI_COMM_WORLD: the host's ranks may be fewer.  A
         * duplicate of our own, because the host frees its communicator when
         * its context closes and PETSc needs its world until PetscFinalize. */
        if (comm) {
            rc = MPI_Comm_dup(*comm, &petsc_world);
            if (rc != MPI_SUCCESS) {
                snprintf(start_error, sizeof start_error, "MPI_Comm_dup of the host's communicator "
                         "failed (MPI error %d)", rc);
                return host->error(call, SILC_ELIB, "%s", start_error);
            }
            PETSC_COMM_WORLD = petsc_world;
        }
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

/* At process exit.  An MPI program has called MPI_Finalize by then, after
 * which neither PETSc nor MPI may be called: PETSc is then left as it is. */
static void petsc_shutdown(void)
{
    if (start_state != START_OK || finished) return;
    finished = 1;
    if (mpi_down()) return;
    if (began_petsc) PetscFinalize();
    if (petsc_world != MPI_COMM_NULL) MPI_Comm_free(&petsc_world);
    if (began_mpi) MPI_Finalize();
}

/* ---- errors ------------------------------------------------------------------- */

/* A message held back during a rank-local phase (psc_error, agree). */
static struct {
    int on, status;
    char msg[1024];
} pending;

int psc_error(silc_call *call, int status, const char *fmt, ...)
{
    char text[sizeof pending.msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    if (!pending.on) return host->error(call, status, "%s", text);
    if (!pending.status) {
        pending.status = status;
        memcpy(pending.msg, text, sizeof text);
    }
    return status;
}

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
    return psc_error(call, status, "%s: %s (PETSc error %d%s)", what, msg[0] ? msg : "failed",
                     (int)ierr, gen);
}

/* ---- the ranks of a call ---------------------------------------------------------- */

/* Who takes part in a solve.  dist: A and B are distributed by rows over comm
 * (a collective call), layout is A's.  Otherwise the operands are whole and
 * comm is PETSC_COMM_SELF, size 1. */
typedef struct psc_ranks {
    int dist;
    MPI_Comm comm;
    int rank, size;
    silc_layout layout;
} psc_ranks;

static void ranks_open(silc_call *call, psc_ranks *R)
{
    const void *comm = NULL;
    memset(R, 0, sizeof *R);
    R->size = 1;
    if (host_dist) comm = host->comm(call, &R->rank, &R->size);
    if (comm) {
        R->dist = 1;
        R->comm = *(const MPI_Comm *)comm;
    } else {
        R->comm = PETSC_COMM_SELF;
        R->rank = 0;
        R->size = 1;
    }
}

/* From here to agree(), psc_error keeps a distributed solve's failure back. */
static void local_begin(const psc_ranks *R)
{
    pending.on = R->dist;
    pending.status = 0;
    pending.msg[0] = '\0';
}

/* Every rank passes its local status (0, or psc_error's); all return the
 * same: the lowest failing rank's status and message, naming that rank.  On
 * whole operands the failure was reported already and rc comes back. */
static int agree(silc_call *call, const psc_ranks *R, int rc)
{
    struct {
        int rank, status;
    } in, out;
    pending.on = 0;
    if (!R->dist) return rc;
    if (rc && !pending.status) snprintf(pending.msg, sizeof pending.msg, "petsc: failed (status %d)", rc);
    in.rank = rc ? R->rank : INT_MAX;
    in.status = rc;
    /* MINLOC on MPI_2INT keeps the status that goes with the lowest rank. */
    if (MPI_Allreduce(&in, &out, 1, MPI_2INT, MPI_MINLOC, R->comm) != MPI_SUCCESS)
        return host->error(call, SILC_ELIB, "petsc: MPI_Allreduce failed agreeing on a status");
    if (out.rank == INT_MAX) return SILC_OK;
    if (MPI_Bcast(pending.msg, (int)sizeof pending.msg, MPI_CHAR, out.rank, R->comm) != MPI_SUCCESS)
        return host->error(call, out.status, "petsc: failed on rank %d of %d", out.rank, R->size);
    pending.msg[sizeof pending.msg - 1] = '\0';
    return host->error(call, out.status, "%s (on rank %d of %d)", pending.msg, out.rank, R->size);
}

/* 1 if flag is non-zero on every rank. */
static int all_ranks(const psc_ranks *R, int flag)
{
    int all = flag != 0;
    if (R->dist) MPI_Allreduce(MPI_IN_PLACE, &all, 1, MPI_INT, MPI_LAND, R->comm);
    return all;
}

/* ---- the solver attachment ---------------------------------------------------- */

/* The arrays A's Mat is built on, which PETSc does not copy
 * (MatCreateSeqAIJWithArrays, MatCreateMPIAIJWithSplitArrays): they belong
 * to the solver and are freed after its Mat.  On one process, this rank's
 * rows of A with PetscInt indices (PetscInt is 32-bit in this build;
 * solve_accepts and check_local saw that the counts fit) and va NULL: the
 * values are A's own, borrowed, which is safe because the solver is an
 * attachment of A (freed before A's arrays, val_release) and A is never
 * changed in place while it has one (update_in_place); options that would
 * make PETSc write into the Mat's values get a copy (csr_borrows).  On more,
 * the rows split into the block of this rank's own columns (ia, ja local,
 * va) and the rest (oi, oj global, oa), which PETSc's MATMPIAIJ keeps apart
 * and whose oj it rewrites.  Before, MatSeqAIJSetPreallocationCSR and
 * MatMPIAIJSetPreallocationCSR copied A entry by entry through
 * MatSetValues: 66 ms of a 0.56 s one-shot CG + BoomerAMG solve at 500^2
 * (docs/distributed.md). */
typedef struct psc_csr {
    void *block; /* the arrays below, one allocation (csr_build) */
    PetscInt *ia, *ja, *oi, *oj;
    double *va, *oa;
} psc_csr;

/* The arrays' block comes from the host's large-block allocator where it has
 * one (silc_large_alloc_of): filling it then takes a few page faults instead
 * of one per 4 KiB (2,100 of them per rank at 500^2 on two ranks).  Not
 * counted against the value size limit, as PETSc's own copy was not. */
static void csr_free(psc_csr *c)
{
    if (c->block) silc_large_free_of(host, c->block);
    memset(c, 0, sizeof *c);
}

typedef struct psc_solver {
    Mat A;
    psc_csr csr;         /* the arrays A is built on (freed after A) */
    KSP ksp;             /* NULL once cleared (solver_clear): not reusable */
    PetscOptions opts;   /* pushed as PETSc's default around every use of ksp */
    char *text;          /* the user's option string it was configured from */
    int spd;             /* built under the ".spd" class */
    int checked;         /* the unused-option check passed */
    int direct;          /* the PC is a complete factorization (lu, cholesky) */
    int condest;         /* a condition estimate was asked for */
    double setup_seconds, cond_est;
    int cond_block;      /* cond_est came from the block estimator */
    char method[64];
    silc_call *call;     /* the call solving with ksp now, for host->cancelled(); else NULL */
    int stopped;         /* the convergence test ended that solve on request */
} psc_solver;

/* Destroys the PETSc objects (collective over the solver's communicator),
 * keeping the rest.  After PetscFinalize or MPI_Finalize (values freed late
 * at exit) they are gone with PETSc, or can no longer be destroyed. */
static void solver_clear(psc_solver *S)
{
    if (!finished && start_state == START_OK && !mpi_down()) {
        enter();
        KSPDestroy(&S->ksp);
        MatDestroy(&S->A);
        PetscOptionsDestroy(&S->opts);
        leave();
    }
    S->ksp = NULL;
    S->A = NULL;
    S->opts = NULL;
    csr_free(&S->csr); /* gone with A, or never to be used again */
}

static void solver_free(void *p)
{
    psc_solver *S = p;
    if (!S) return;
    solver_clear(S);
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

/* Whether A's Mat may borrow A's values on one process: not when an option
 * (the user's, PETSC_OPTIONS' or SILC's own, all in opts) asks PETSc to
 * write into the operator -- a factorization in place (-pc_factor_in_place,
 * also under a sub-solver's prefix) or a diagonal scaling of the system
 * (-ksp_diagonal_scale) -- which would change the user's A. */
static int csr_borrows(PetscOptions opts)
{
    char *all = NULL;
    int borrow;
    if (PetscOptionsGetAll(opts, &all)) return 0;
    borrow = all && !strstr(all, "in_place") && !strstr(all, "diagonal_scale");
    PetscFree(all);
    return borrow;
}

/* The arrays of this rank's rows of A for build_matrix (psc_csr).
 * Rank-local. */
static int csr_build(silc_call *call, const psc_ranks *R, const silc_view *a, int borrow, psc_csr *c)
{
    int64_t i, k, nd = 0, no, first = R->size > 1 ? R->layout.first_row : 0, last = first + a->m;
    int split = R->size > 1;
    size_t doubles, ints, bytes;
    memset(c, 0, sizeof *c);
    if (split)
        for (k = 0; k < a->nnz; k++) nd += a->colind[k] >= first && a->colind[k] < last;
    else
        nd = a->nnz;
    no = a->nnz - nd;
    /* The doubles first, so that every array is aligned for its type. */
    doubles = (size_t)(split || !borrow ? nd : 0) + (size_t)(split ? no : 0);
    ints = (size_t)(a->m + 1) + (size_t)nd + (split ? (size_t)(a->m + 1) + (size_t)no : 0);
    bytes = doubles * sizeof(double) + ints * sizeof(PetscInt);
    c->block = silc_large_alloc_of(host, bytes);
    if (!c->block)
        return psc_error(call, SILC_ENOMEM, "out of memory for PETSc's copy of %lld rows (%lld entries)",
                         (long long)a->m, (long long)a->nnz);
    {
        double *d = c->block;
        PetscInt *p;
        if (split || !borrow) c->va = d, d += nd;
        if (split) c->oa = d, d += no;
        p = (PetscInt *)d;
        c->ia = p, p += a->m + 1;
        c->ja = p, p += nd;
        if (split) c->oi = p, p += a->m + 1, c->oj = p;
    }
    if (!split) {
        for (i = 0; i <= a->m; i++) c->ia[i] = (PetscInt)a->rowptr[i];
        for (k = 0; k < a->nnz; k++) c->ja[k] = (PetscInt)a->colind[k];
        if (c->va) memcpy(c->va, a->val, (size_t)a->nnz * sizeof *c->va);
        return SILC_OK;
    }
    c->ia[0] = c->oi[0] = 0;
    for (i = 0, nd = no = 0; i < a->m; i++) {
        for (k = a->rowptr[i]; k < a->rowptr[i + 1]; k++) {
            int64_t col = a->colind[k];
            if (col >= first && col < last) {
                c->ja[nd] = (PetscInt)(col - first);
                c->va[nd++] = a->val[k];
            } else {
                c->oj[no] = (PetscInt)col;
                c->oa[no++] = a->val[k];
            }
        }
        c->ia[i + 1] = (PetscInt)nd;
        c->oi[i + 1] = (PetscInt)no;
    }
    return SILC_OK;
}

/* A on R's communicator over c's arrays, which PETSc does not copy: a
 * MATSEQAIJ on one process, else a MATMPIAIJ of which this rank holds the
 * rows of a (the diagonal block is square, as PETSc's vectors are split like
 * the rows).  Collective. */
static int build_matrix(silc_call *call, const psc_ranks *R, const silc_view *a, psc_csr *c, int spd,
                        Mat *out)
{
    Mat M = NULL;
    int rc = SILC_OK;
    PetscInt m = (PetscInt)a->m, n = (PetscInt)a->n;
    *out = NULL;
    if (R->size > 1)
        TRY(MatCreateMPIAIJWithSplitArrays(R->comm, m, m, n, n, c->ia, c->ja, c->va, c->oi, c->oj, c->oa, &M),
            "MatCreateMPIAIJWithSplitArrays");
    else
        TRY(MatCreateSeqAIJWithArrays(R->comm, m, n, c->ia, c->ja, c->va ? c->va : (double *)a->val, &M),
            "MatCreateSeqAIJWithArrays");
    /* What the host knows about A helps GAMG (CG eigenvalue estimates), MUMPS
     * (SYM) and others.  The properties are global (the host computes those
     * of a distributed A collectively). */
    if (silc_props_of(host, call->in[0], SILC_PROPS_SYMMETRY)->symmetric) {
        TRY(MatSetOption(M, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption(MAT_SYMMETRIC)");
        TRY(MatSetOption(M, MAT_SYMMETRY_ETERNAL, PETSC_TRUE), "MatSetOption(MAT_SYMMETRY_ETERNAL)");
    }
    if (spd) TRY(MatSetOption(M, MAT_SPD, PETSC_TRUE), "MatSetOption(MAT_SPD)");
    *out = M;
    M = NULL;
done:
    MatDestroy(&M);
    return rc;
}

/* A vector over this rank's m of the n rows, its array placed later
 * (VecPlaceArray): sequential on one process, else MPI.  Collective. */
static PetscErrorCode vec_wrap(const psc_ranks *R, int64_t m, int64_t n, Vec *v)
{
    if (R->size > 1) return VecCreateMPIWithArray(R->comm, 1, (PetscInt)m, (PetscInt)n, NULL, v);
    return VecCreateSeqWithArray(R->comm, 1, (PetscInt)n, NULL, v);
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

/* The preconditioner's failed reason, a factorization's error counting as
 * one, agreed over the ranks: a sub-block's ILU may fail on one rank only,
 * and every rank must take the same branch.  The largest reason wins, any
 * failure over PC_NOERROR. */
static PCFailedReason pc_reason(const psc_ranks *R, psc_solver *S)
{
    PC pc = NULL;
    PCFailedReason fr = PC_NOERROR;
    int code;
    KSPGetPC(S->ksp, &pc);
    PCGetFailedReason(pc, &fr);
    if (pc_is_factor(pc) && fr == PC_NOERROR) {
        Mat F = NULL;
        MatFactorError fe = MAT_FACTOR_NOERROR;
        if (!PCFactorGetMatrix(pc, &F) && F && !MatFactorGetError(F, &fe) && fe != MAT_FACTOR_NOERROR)
            PCSetFailedReason(pc, (PCFailedReason)fe);
        PCGetFailedReason(pc, &fr);
    }
    if (!R->dist) return fr;
    /* PC_SETUP_ERROR is -1, below PC_NOERROR: no error counts as -2 here. */
    code = fr == PC_NOERROR ? -2 : (int)fr;
    MPI_Allreduce(MPI_IN_PLACE, &code, 1, MPI_INT, MPI_MAX, R->comm);
    return code == -2 ? PC_NOERROR : (PCFailedReason)code;
}

/* A failed preconditioner (fr, from pc_reason): a zero pivot is a singular
 * matrix, or under the ".spd" class a matrix that is not positive definite. */
static int pc_failed(silc_call *call, psc_solver *S, PCFailedReason fr, const char *where)
{
    int status = SILC_ELIB;
    if (fr == PC_FACTOR_STRUCT_ZEROPIVOT || fr == PC_FACTOR_NUMERIC_ZEROPIVOT)
        status = S->spd ? SILC_ENOTSPD : SILC_ESINGULAR;
    else if (fr == PC_FACTOR_OUTMEMORY)
        status = SILC_ENOMEM;
    return psc_error(call, status, "%s: preconditioner failed: PC_%s (%s)%s", where,
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
    MPI_Comm comm;       /* of one process: PETSC_COMM_SELF or a 1-rank host comm */
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
    PetscErrorCode ierr = MatCreateSeqDense(c->comm, c->n, t, X, &B);
    if (!ierr) ierr = MatCreateSeqDense(c->comm, c->n, t, c->block, &Y);
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

/* Only on one process (R->size 1): the host's estimators work on whole
 * vectors. */
static double condition_estimate(const psc_ranks *R, psc_solver *S, int64_t n, double norm1)
{
    cond_ctx c = {NULL, NULL, NULL, 0, (PetscInt)n, R->comm, NULL};
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
        if (!VecCreateSeqWithArray(R->comm, 1, (PetscInt)n, NULL, &c.in) &&
            !VecCreateSeqWithArray(R->comm, 1, (PetscInt)n, NULL, &c.out))
            est = host->inv_norm1_est(n, cond_apply, &c, work);
        VecDestroy(&c.in);
        VecDestroy(&c.out);
        host->free(work);
    }
    return est >= 0 && isfinite(est) ? norm1 * est : -1;
}

/* ---- stopping on request, -log_view ------------------------------------------------ */

/* The KSP's own convergence test (PETSc's default or what the options
 * chose), wrapped: after it, between iterations, the wrapper asks
 * host->cancelled() -- an interrupt (Ctrl-C, silc_cancel, a CANCEL frame)
 * or silcd's request limit; a clock read -- and ends the solve with a
 * negative reason, which run_solves reports as "stopped on request". */
typedef struct psc_stop {
    PetscErrorCode (*test)(KSP, PetscInt, PetscReal, KSPConvergedReason *, void *);
    void *ctx;
    PetscErrorCode (*destroy)(void *);
    psc_solver *S;
} psc_stop;

static PetscErrorCode stop_test(KSP ksp, PetscInt it, PetscReal rnorm, KSPConvergedReason *reason,
                                void *p)
{
    psc_stop *w = p;
    PetscErrorCode ierr = w->test ? w->test(ksp, it, rnorm, reason, w->ctx) : 0;
    if (ierr) return ierr;
    if (*reason == KSP_CONVERGED_ITERATING && w->S->call && host->cancelled(w->S->call)) {
        w->S->stopped = 1;
        *reason = KSP_DIVERGED_ITS; /* PETSc 3.18 has no reason of its own for it */
    }
    return 0;
}

static PetscErrorCode stop_destroy(void *p)
{
    psc_stop *w = p;
    PetscErrorCode ierr = w->destroy ? w->destroy(w->ctx) : 0;
    PetscFree(w);
    return ierr;
}

/* Puts the wrapper around S's convergence test (a host older than ABI 1.7
 * cannot be asked: the test stays as it is). */
static PetscErrorCode stop_install(psc_solver *S)
{
    psc_stop *w = NULL;
    PetscErrorCode ierr;
    if (host->struct_size < SILC_HOST_NEEDS(cancelled)) return 0;
    if ((ierr = PetscNew(&w))) return ierr;
    w->S = S;
    if ((ierr = KSPGetAndClearConvergenceTest(S->ksp, &w->test, &w->ctx, &w->destroy)) ||
        (ierr = KSPSetConvergenceTest(S->ksp, stop_test, w, stop_destroy))) {
        if (w->destroy) w->destroy(w->ctx);
        PetscFree(w);
    }
    return ierr;
}

/* -log_view in the user's string starts PETSc's default logging (once per
 * process: PETSc then counts every later call, whatever asked for it). */
static int log_begin(silc_call *call, const char *text)
{
    static int began;
    PetscErrorCode ierr;
    if (began || !psc_find_option(text, "log_view", NULL, 0)) return SILC_OK;
    if ((ierr = PetscLogDefaultBegin())) return psc_fail(call, "PetscLogDefaultBegin", ierr);
    began = 1;
    return SILC_OK;
}

/* After a solve whose options hold -log_view[:file[:format]]: PETSc's
 * performance table (KSPSolve, PCApply, MatMult, ... since logging began),
 * printed as PETSc prints it at PetscFinalize -- to standard output, or to
 * the file the option names -- since a session may never finalize PETSc.
 * PETSc parses the option itself (PetscOptionsGetViewer), which also marks
 * it read.  Collective over R's communicator, as PetscLogView is. */
static int log_view(silc_call *call, const psc_ranks *R, psc_solver *S)
{
    PetscViewer v = NULL;
    PetscViewerFormat format = PETSC_VIEWER_DEFAULT;
    PetscBool set = PETSC_FALSE;
    PetscErrorCode ierr = PetscOptionsGetViewer(R->comm, S->opts, NULL, "-log_view", &v, &format, &set);
    if (ierr) return psc_fail(call, "-log_view", ierr);
    if (!set || !v) return SILC_OK;
    if (!(ierr = PetscViewerPushFormat(v, format))) {
        ierr = PetscLogView(v);
        PetscViewerPopFormat(v);
    }
    PetscViewerDestroy(&v);
    fflush(stdout);
    return ierr ? psc_fail(call, "PetscLogView", ierr) : SILC_OK;
}

/* Builds the matrix and the KSP on R's communicator, and sets the
 * preconditioner up (PETSc's options database pushed by the caller).
 * Collective. */
static int solver_setup(silc_call *call, const psc_ranks *R, psc_solver *S, const silc_view *a,
                        psc_csr *csr)
{
    PC pc = NULL;
    PCFailedReason fr = PC_NOERROR;
    double t0 = host->now();
    int rc = SILC_OK;
    if ((rc = build_matrix(call, R, a, csr, S->spd, &S->A))) return rc;
    S->csr = *csr; /* A's arrays now live as long as A */
    memset(csr, 0, sizeof *csr);
    TRY(KSPCreate(R->comm, &S->ksp), "KSPCreate");
    TRY(PetscObjectSetOptions((PetscObject)S->ksp, S->opts), "PetscObjectSetOptions");
    TRY(KSPSetOperators(S->ksp, S->A, S->A), "KSPSetOperators");
    TRY(KSPSetFromOptions(S->ksp), "KSPSetFromOptions");
    TRY(KSPSetUp(S->ksp), "KSPSetUp");
    TRY(stop_install(S), "KSPSetConvergenceTest");
    describe(S);
    TRY(KSPGetPC(S->ksp, &pc), "KSPGetPC");
    if ((fr = pc_reason(R, S)) != PC_NOERROR) return pc_failed(call, S, fr, "KSPSetUp");
    S->direct = pc_is(pc, PCLU) || pc_is(pc, PCCHOLESKY);
    /* The properties' norms are asked for on every rank or none (R->size
     * is the same everywhere). */
    if (S->direct && S->condest && R->size == 1)
        S->cond_est = condition_estimate(R, S, a->n, silc_props_of(host, call->in[0], SILC_PROPS_NORMS)->norm1);
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

static int distributed(const silc_value *v, silc_layout *L)
{
    return host_dist && host->layout(v, L);
}

/* Rows of A: the view of a distributed A shows this rank's rows only. */
static int64_t global_rows(const silc_value *v, const silc_view *view)
{
    silc_layout L;
    return distributed(v, &L) ? L.m_global : view->m;
}

/* Every rank of a collective call gets the same answer: it looks at global
 * shapes and properties only (the host computes a distributed A's
 * collectively); the local entry count is check_local's. */
/* Complex values: this plugin passes SILC's arrays to PETSc as PetscScalar,
 * which Debian's default PETSc (petsc-real) makes a double.  A PETSc built
 * with complex scalars would take SILC's interleaved complex arrays as they
 * are (PetscScalar = double complex), but it is another library with the
 * same symbols, so it would be another build of this plugin, not a switch;
 * see plugin-petsc/README.md. */
#if defined(PETSC_USE_COMPLEX)
#error "plugin-petsc is written for real PetscScalar: build it against the real PETSc (README.md)"
#endif
#define PETSC_SCALAR_WHY "this PETSc is built with real scalars (PetscScalar is double): no complex values"

static int solve_accepts(const silc_call *call, const char **why)
{
    silc_view a;
    silc_layout L;
    if (call->nin < 2) {
        *why = "needs a right-hand side";
        return 0;
    }
    /* The host hands complex values only to backends listing the op in
     * complex_ops, which this plugin leaves out on a real PETSc; the test
     * here says why to a host (or a caller) that asks anyway. */
    if (host->struct_size >= SILC_HOST_NEEDS(field) &&
        (host->field(call->in[0]) == SILC_FIELD_COMPLEX || host->field(call->in[1]) == SILC_FIELD_COMPLEX)) {
        *why = PETSC_SCALAR_WHY;
        return 0;
    }
    if (!call->op_class || strncmp(call->op_class, "solve.sparse", 12) != 0 ||
        (call->op_class[12] && !ends_with_spd(call->op_class))) { /* also solve.sparse.mmatrix.spd */
        *why = "PETSc KSP here serves solve.sparse and solve.sparse.spd only (dense and band "
               "systems are better left to LAPACK)";
        return 0;
    }
    host->view(call->in[0], &a);
    if (a.format != SILC_FMT_CSR) {
        *why = "needs a sparse (CSR) matrix";
        return 0;
    }
    if (global_rows(call->in[0], &a) != a.n) {
        *why = "needs a square matrix";
        return 0;
    }
    if (a.n >= PETSC_MAX_INT || (!distributed(call->in[0], &L) && a.nnz >= PETSC_MAX_INT)) {
        *why = "matrix too large for this PETSc's 32-bit PetscInt";
        return 0;
    }
    if (ends_with_spd(call->op_class) && !silc_props_of(host, call->in[0], SILC_PROPS_SYMMETRY)->symmetric) {
        *why = "CG needs a symmetric matrix";
        return 0;
    }
    return 1;
}

/* A collective call's operands, checked on this rank (rank-local: the caller
 * agrees): A's rows as its layout says, with an entry count PetscInt holds,
 * and B dense, distributed like A's rows. */
static int check_local(silc_call *call, psc_ranks *R, const silc_view *a, const silc_view *b)
{
    silc_layout Lb;
    if (!host->layout(call->in[0], &R->layout))
        return psc_error(call, SILC_EARG, "petsc: a collective solve needs A distributed by rows");
    if (a->m != R->layout.m_local)
        return psc_error(call, SILC_EARG, "petsc: A's block has %lld rows, its layout %lld",
                         (long long)a->m, (long long)R->layout.m_local);
    if (a->nnz >= PETSC_MAX_INT)
        return psc_error(call, SILC_EDECLINE, "matrix too large for this PETSc's 32-bit PetscInt "
                         "(%lld entries in this rank's rows)", (long long)a->nnz);
    if (!host->layout(call->in[1], &Lb) || Lb.first_row != R->layout.first_row ||
        Lb.m_local != R->layout.m_local || Lb.m_global != R->layout.m_global)
        return psc_error(call, SILC_EARG, "petsc: the right-hand side is not distributed like A's rows");
    if (b->format != SILC_FMT_DENSE || b->m != Lb.m_local)
        return psc_error(call, SILC_EARG, "petsc: a distributed right-hand side must be dense");
    return SILC_OK;
}

/* Entry (i, j) of a dense or band view, 0 outside the band. */
static double full_get(const silc_view *v, int64_t i, int64_t j)
{
    if (v->format == SILC_FMT_DENSE) return v->val[i + j * v->m];
    if (i - j > v->kl || j - i > v->ku) return 0.0;
    return v->val[(v->ku + i - j) + j * v->ld];
}

/* B (any format; a distributed one: this rank's rows) as a dense
 * column-major copy: KSPSolve may scale b in place. */
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

/* The error of a negative converged reason (the same on every rank: PETSc
 * decides it from global norms). */
static int diverged(silc_call *call, const psc_ranks *R, psc_solver *S, KSPConvergedReason reason,
                    PetscInt its, double resid, int64_t column, int64_t ncols)
{
    int status = SILC_EBREAKDOWN;
    char where[48] = "";
    if (reason == KSP_DIVERGED_PC_FAILED) return pc_failed(call, S, pc_reason(R, S), "KSPSolve");
    if (reason == KSP_DIVERGED_ITS || reason == KSP_DIVERGED_DTOL) status = SILC_ENOTCONV;
    if (S->spd && (reason == KSP_DIVERGED_INDEFINITE_PC || reason == KSP_DIVERGED_INDEFINITE_MAT))
        status = SILC_ENOTSPD;
    if (ncols > 1) snprintf(where, sizeof where, " on right-hand side %lld", (long long)column + 1);
    return psc_error(call, status,
                     "KSPSolve: diverged (KSP_%s) after %lld iteration%s%s, relative "
                     "residual %.3g (%s)",
                     reason_name(reason), (long long)its, its == 1 ? "" : "s", where, resid,
                     S->method);
}

/* Solves column by column; fills X and the report.  B and X hold this
 * rank's m of the n rows, column-major.  *guess: in, X holds an initial
 * guess; out, how many columns started from it (a guess no better than
 * zero is dropped: it would only trip the divergence test).  Collective. */
static int run_solves(silc_call *call, const psc_ranks *R, psc_solver *S, double *B, double *X,
                      int64_t m, int64_t n, int64_t ncols, int *guess)
{
    int given = *guess;
    silc_report *r = call->report;
    Vec b = NULL, x = NULL, res = NULL;
    KSPConvergedReason reason = KSP_CONVERGED_ITERATING, first = KSP_CONVERGED_ITERATING;
    PetscInt its = 0;
    PetscReal nb, nr, rtol = 0, atol = 0, dtol = 0;
    PetscInt maxit = 0;
    double worst = 0;
    int64_t j, max_its = 0;
    int rc = SILC_OK, len;
    PetscErrorCode ierr;
    TRY(vec_wrap(R, m, n, &b), R->size > 1 ? "VecCreateMPIWithArray" : "VecCreateSeqWithArray");
    TRY(vec_wrap(R, m, n, &x), R->size > 1 ? "VecCreateMPIWithArray" : "VecCreateSeqWithArray");
    TRY(VecDuplicate(b, &res), "VecDuplicate");
    *guess = 0;
    for (j = 0; j < ncols; j++) {
        double rel;
        TRY(VecPlaceArray(b, B + j * m), "VecPlaceArray");
        TRY(VecPlaceArray(x, X + j * m), "VecPlaceArray");
        if (given) {
            TRY(MatMult(S->A, x, res), "MatMult");
            TRY(VecAYPX(res, -1.0, b), "VecAYPX");
            TRY(VecNorm(res, NORM_2, &nr), "VecNorm");
            TRY(VecNorm(b, NORM_2, &nb), "VecNorm");
            if (nr < nb) (*guess)++;
            else TRY(VecSet(x, 0.0), "VecSet");
        }
        S->stopped = 0;
        ierr = KSPSolve(S->ksp, b, x);
        if (S->stopped) { /* before ierr: -ksp_error_if_not_converged makes it an error */
            KSPGetIterationNumber(S->ksp, &its);
            rc = psc_error(call, SILC_ELIB, "stopped on request (KSPSolve, after %lld iteration%s)",
                           (long long)its, its == 1 ? "" : "s");
            goto done;
        }
        TRY(ierr, "KSPSolve");
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
            rc = diverged(call, R, S, reason, its, rel, j, ncols);
            goto done;
        }
        if (!isfinite(rel)) {
            rc = psc_error(call, S->direct ? SILC_ESINGULAR : SILC_EBREAKDOWN,
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
    if (!S->direct && host->abi_minor >= 6) r->tol = (double)rtol; /* the host verifies against it */
    r->iterations = max_its;
    r->resid = worst;
    len = snprintf(r->note, sizeof r->note, "KSP_%s; rtol %g, atol %g, dtol %g, max_it %lld",
                   reason_name(first), (double)rtol, (double)atol, (double)dtol, (long long)maxit);
    if (ncols > 1 && len < (int)sizeof r->note)
        snprintf(r->note + len, sizeof r->note - (size_t)len,
                 "; %lld right-hand sides (iterations and residual: the worst)", (long long)ncols);
done:
    if (rc) {
        if (b) VecResetArray(b);
        if (x) VecResetArray(x);
    }
    VecDestroy(&b);
    VecDestroy(&x);
    VecDestroy(&res);
    return rc;
}

/* Fills the report's method and condition estimate once the solves passed. */
static void report_method(silc_report *r, const psc_solver *S)
{
    /* How many ranks ran a collective solve the host adds (dispatch.c). */
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
}

/* x = A \ b.  Whole operands: on this process alone.  Distributed ones: on
 * every rank of the host's communicator at once, in three phases -- a
 * rank-local one (checks, allocations, the options database, A's indices)
 * that ends in agree(); the collective PETSc work (matrix, KSP set-up,
 * solves, the unused-option check), whose failures every rank sees; and
 * attaching the solver to A, agreed again. */
static int solve_run(silc_call *call)
{
    silc_view a, bv, o;
    silc_report *r = call->report;
    psc_ranks R;
    psc_csr csr = {NULL, NULL, NULL, NULL, NULL, NULL, NULL};
    psc_solver *S = NULL;
    silc_value *X = NULL;
    double *B = NULL, t0;
    const char *why = NULL, *text;
    int spd = ends_with_spd(call->op_class), rc, pushed = 0, fresh = 0, entered = 0, reuse;
    PetscErrorCode ierr;
    const char *key = spd ? "petsc.ksp.spd" : "petsc.ksp";
    int64_t condest = 1;
    if (!solve_accepts(call, &why)) return host->error(call, SILC_EDECLINE, "%s", why);
    text = host->option_string(call, "options", "");
    if (!text) text = "";
    if ((rc = host->option_int(call, "condest", 1, &condest))) return rc;
    if (host->abi_minor >= 7 && call->report->condest_off) condest = 0; /* accuracy.condest = off */
    ranks_open(call, &R);
    host->view(call->in[0], &a);
    host->view(call->in[1], &bv);
    if (!R.dist && bv.m != a.n)
        return host->error(call, SILC_EARG, "right-hand side has %lld rows, A has %lld",
                           (long long)bv.m, (long long)a.n);
    if ((rc = petsc_start(call, R.dist ? &R.comm : NULL))) return rc;
    if ((rc = log_begin(call, text))) return rc;
    /* Reusing A's solver is decided first, by every rank, before a rank-local
     * failure could make one rank skip this collective step. */
    S = host->attach_get(call->in[0], key);
    reuse = all_ranks(&R, S && S->ksp && strcmp(S->text, text) == 0 && S->condest == (condest != 0));

    /* Rank-local phase. */
    local_begin(&R);
    if (R.dist && (rc = check_local(call, &R, &a, &bv))) goto agreed;
    X = R.dist ? host->dist_dense_new(call->in[1], bv.n) : host->dense_new(bv.m, bv.n);
    if (!X) {
        rc = psc_error(call, SILC_ENOMEM, "cannot allocate the %lldx%lld solution",
                       (long long)global_rows(call->in[1], &bv), (long long)bv.n);
        goto agreed;
    }
    if (a.n == 0 || bv.n == 0) goto agreed; /* nothing to solve: the same on every rank */
    host->view(X, &o);
    enter();
    entered = 1;
    /* At least one element: a rank may hold no rows. */
    B = host->alloc((size_t)(bv.m * bv.n > 0 ? bv.m * bv.n : 1) * sizeof *B);
    if (!B) {
        rc = psc_error(call, SILC_ENOMEM, "out of memory for the right-hand side");
        goto agreed;
    }
    dense_copy(&bv, B);
    if (reuse) {
        r->reused_factor = 1;
    } else {
        size_t len = strlen(text) + 1;
        fresh = 1;
        S = host->calloc(1, sizeof *S);
        if (!S || !(S->text = host->alloc(len))) {
            rc = psc_error(call, SILC_ENOMEM, "out of memory");
            goto agreed;
        }
        memcpy(S->text, text, len);
        S->spd = spd;
        S->condest = condest != 0;
        S->cond_est = -1;
        if ((rc = psc_options_create(call, text, spd, &S->opts))) goto agreed;
        if ((rc = csr_build(call, &R, &a, csr_borrows(S->opts), &csr))) goto agreed;
    }
agreed:
    if ((rc = agree(call, &R, rc))) goto done;
    if (a.n == 0 || bv.n == 0) goto done;

    /* Collective phase. */
    if ((ierr = PetscOptionsPush(S->opts))) {
        rc = psc_fail(call, "PetscOptionsPush", ierr);
        goto done;
    }
    pushed = 1;
    if (fresh) {
        rc = solver_setup(call, &R, S, &a, &csr);
        csr_free(&csr);
        if (rc) goto done;
        r->factor_seconds = S->setup_seconds;
    }
    {
        /* A warm start (ABI 1.6: the host's initial guess in in[2]) for a
         * Krylov method, as KSPSetInitialGuessNonzero; a direct PC gains
         * nothing from it.  PETSc's default test is relative to ||b||, so a
         * good guess stops early.  The flag is set every solve: the KSP is
         * reused across calls with and without a guess. */
        silc_view g;
        int guess = host->abi_minor >= 6 && call->nin >= 3 && call->in[2] && !R.dist && !S->direct;
        if (guess) {
            host->view(call->in[2], &g);
            guess = g.format == SILC_FMT_DENSE && g.m == a.n && g.n == bv.n;
        }
        if (guess) memcpy(o.val, g.val, (size_t)(g.m * g.n) * sizeof(double));
        if ((ierr = KSPSetInitialGuessNonzero(S->ksp, guess ? PETSC_TRUE : PETSC_FALSE))) {
            rc = psc_fail(call, "KSPSetInitialGuessNonzero", ierr);
            goto done;
        }
        t0 = host->now();
        S->call = call;
        rc = run_solves(call, &R, S, B, o.val, bv.m, a.n, bv.n, &guess);
        S->call = NULL;
        if (rc) goto done;
        r->initial_guess = guess > 0;
    }
    r->solve_seconds = host->now() - t0;
    if ((rc = log_view(call, &R, S))) goto done;
    if (fresh && psc_find_option(text, "help", NULL, 0) &&
        (rc = psc_options_print_help(call, R.comm, text, spd, S->A)))
        goto done;
    if (!S->checked) {
        if ((rc = psc_options_check_used(call, R.comm, S->opts, text, spd, S->A))) goto done;
        S->checked = 1;
    }
    report_method(r, S);

    /* Attaching: rank-local, agreed. */
    if (fresh) {
        psc_solver *old = host->attach_get(call->in[0], key);
        int attach_rc;
        if (pushed) PetscOptionsPop();
        pushed = 0;
        /* attach_set destroys the solver of other options it replaces; on
         * distributed operands that destruction is collective, so it is done
         * here, on every rank at once (the attachments are alike on every
         * rank), and attach_set only frees memory. */
        if (R.dist && old) solver_clear(old);
        local_begin(&R);
        attach_rc = host->attach_set(call->in[0], key, S, solver_free)
                        ? psc_error(call, SILC_ENOMEM, "cannot attach the solver")
                        : SILC_OK;
        if ((rc = agree(call, &R, attach_rc))) {
            /* Attached here but not elsewhere: its PETSc objects end now, with
             * the other ranks' (solver_free below), and A keeps the shell. */
            if (!attach_rc) {
                solver_clear(S);
                fresh = 0;
            }
            goto done;
        }
        fresh = 0;
    }
done:
    pending.on = 0;
    if (pushed) PetscOptionsPop();
    if (fresh) solver_free(S);
    csr_free(&csr);
    if (entered) leave();
    host->free(B);
    if (rc) {
        if (X) host->release(X);
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
    {NULL,
     "PETSc " PETSC_VERSION_TEXT " KSP/PC, sequential, or collective (MPIAIJ) on row-distributed "
     "operands (options: -ksp_type, -pc_type, ...)",
     SILC_OP_COUNT, petsc_ops},
};

/* SOLVE runs collectively on distributed operands (ABI 1.5), declared only
 * to a host that has comm, layout and dist_dense_new. */
static const uint32_t petsc_collective[] = {SILC_COLLECTIVE(SILC_OP_SOLVE)};

static const silc_option_spec petsc_options[] = {
    {"options", SILC_OPT_STRING, "",
     "PETSc options for the KSP and PC, e.g. -ksp_type cg -pc_type hypre -ksp_rtol 1e-10; empty = "
     "PETSc's defaults: GMRES(30) + ILU(0) (ICC(0) for a symmetric A; block Jacobi + ILU(0) on "
     "several ranks), rtol 1e-5, atol 1e-50, max_it 10000, CG under solve.sparse.spd; options "
     "PETSc does not read are errors (-options_left no: warnings)"},
    {"condest", SILC_OPT_BOOL, "true",
     "estimate the 1-norm condition number when the PC is a direct factorization (lu, cholesky) "
     "on one process: 2-10 extra triangular solves per factorization"},
};

static silc_plugin petsc_plugin = {
    SILC_ABI_MAJOR, SILC_ABI_MINOR, sizeof(silc_plugin), (int)sizeof(silc_index),
    "petsc", "1.0 PETSc " PETSC_VERSION_TEXT,
    1, petsc_backends,
    (int)(sizeof petsc_options / sizeof petsc_options[0]), petsc_options,
    NULL, /* set_threads: blas_threads_attach fills it when OpenBLAS is found */
    petsc_shutdown,
    NULL, /* collective_ops: silc_plugin_init sets it on a 1.5 host */
    NULL, /* complex_ops: none, PetscScalar is real here (PETSC_SCALAR_WHY) */
};

SILC_PLUGIN_EXPORT int silc_plugin_init(const silc_host_api *h, const silc_plugin **out,
                                        const char **errmsg)
{
    if (silc_host_check(h, SILC_HOST_NEEDS(inv_norm1_est_block), errmsg) || !out) return 1;
    host = h;
    /* An older host never hands over distributed operands: sequential only. */
    host_dist = h->struct_size >= SILC_HOST_NEEDS(dist_dense_new);
    petsc_plugin.collective_ops = host_dist ? petsc_collective : NULL;
    blas_threads_attach(&petsc_plugin); /* threaded only through its BLAS */
    *out = &petsc_plugin;
    return 0;
}
