/*
 * mumps.c -- the "mumps" backend: sparse direct solves with sequential MUMPS.
 *
 * One operation, SILC_OP_SOLVE, under "solve.sparse" (unsymmetric LU, SYM=0)
 * and "solve.sparse.spd" (LDL' without pivoting, SYM=1, on the lower
 * triangle; a zero or negative pivot returns SILC_ENOTSPD so the dispatcher
 * falls back to LU).  The matrix goes to MUMPS assembled and centralized
 * (ICNTL(5)=0, ICNTL(18)=0) as 1-based triplets built once.  Analysis and
 * factorization (JOB=4) happen once per matrix value: the MUMPS instance, its
 * triplets and a 1-norm condition estimate are kept as an attachment of A, so
 * later solves only run JOB=3; the attachment is destroyed with JOB=-2.
 *
 * Every ICNTL(1..40) and CNTL(1..15) is a typed option (mumps.icntl_7 = 5).
 * Defaults differ from MUMPS's in two ways: output is silenced, and the
 * ordering is AMF (ICNTL(7)=2; SCOTCH and PORD were 1.5-3x slower on 2-D
 * grids here).  MUMPS's own error analysis stays off as in MUMPS (ICNTL(11)=0):
 * the engine computes every solve's backward error anyway, and the analysis
 * doubled the solve phase on bcsstk16 (1.48 against 0.73 ms, 4% of a whole
 * one-shot solve).  Asked for (mumps.icntl_11 = 2: its backward errors; 1 adds
 * condition numbers), it runs once per factorization, on the first
 * one-column solve, and `info` shows it from then on.
 *
 * A solve phase (JOB=3) costs MUMPS a fixed amount per front of the
 * elimination tree, and MUMPS's amalgamation (KEEP(1) = 5 pivots) leaves
 * many: 26 208 fronts for the 40 000 unknowns of the 200^2 diffusion matrix
 * (AMF), where the pair of triangular solves proper is ~2 ms and JOB=3
 * costs 15-17 ms called directly (bench/mumps_solve), 4x CHOLMOD's
 * supernodal solve.  mumps.amalgamation = k (KEEP(1), set between JOB=-1
 * and the analysis) merges fronts below k pivots: k = 12 gives 5776 fronts
 * and halves the solve phase there (factorization 0.8x, 1.6x the entries),
 * but costs bcsstk16 and memplus 1.6-3x in the factorization, so MUMPS's
 * default stays (docs/backends.md has the table).
 *
 * A 1-norm condition estimate is made once per factorization for the
 * engine's report and its "fewer than 4 correct digits" warning: the host's
 * block estimator with two columns and two steps (estimate_cond below), whose
 * first block rides along with the first solve, so it costs two more solve
 * phases.  mumps.condest = false turns it off.  Workspace errors (the -9
 * class) double ICNTL(14) and retry up to four times.
 *
 * mumps.precision = single factors with smumps_c instead (mixed precision):
 * the entries are scaled by a power of two so the largest is near 1 and
 * converted to float once (kept in the attachment), every solve scales each
 * right-hand-side column the same way, solves in single and scales back, and
 * the report sets single_factor, so the core's refine.c refines in double
 * (up to 10 steps unless solve.refine says otherwise).  Each step then gains
 * about -log10(cond * eps_single) digits, cond of the matrix as MUMPS scales
 * it; once that reaches 1 / eps_single (1.7e7) it gains none and the core
 * warns.  When the entries span more than
 * single precision's range, or the single LU is numerically singular, the
 * matrix is factored in double and the note says why.
 *
 * The file is built twice (CMakeLists.txt).  The sequential module links
 * MUMPS's static archives with -Wl,--exclude-libs,ALL and -Bsymbolic:
 * Debian's sequential MUMPS carries a stub MPI and the same dmumps_c symbol
 * as the MPI MUMPS inside PETSc, and neither may leak out of this plugin or
 * bind to the other's.  The MPI module (-DSILC_MUMPS_MPI=1, Debian's MPI
 * MUMPS on Open MPI, shared) has the same file and backend name in
 * plugins/mpi/, which the core loads instead in MPI mode only.  There a
 * whole-operand call runs as above on MPI_COMM_SELF, and SOLVE is also a
 * collective op: with A and B distributed by row blocks, every rank calls
 * MUMPS on the call's communicator (PAR=1) with its own rows as distributed
 * assembled triplets (ICNTL(18)=3, global indices), hands MUMPS its own rows
 * of B (distributed right-hand side, ICNTL(20)=10) and gets back the part of
 * X that MUMPS's mapping leaves on it (distributed solution, ICNTL(21)=1),
 * which one MPI_Alltoallv moves into the ranks' row blocks: nothing is
 * gathered on rank 0 (B was, and X scattered, before; that path remains for
 * MUMPS's error analysis and iterative refinement, which need a centralized
 * solution).  The instance is cached on A per rank as above; its
 * JOB=-2 is collective (an allreduce and MPI_Comm_free), so a distributed A
 * must die on all ranks together.  MUMPS's INFOG is the same on every rank,
 * so its failures give every rank the same status; local failures
 * (allocations) are agreed over the communicator before the next collective
 * step (agree below).  Distributed operands get neither the condition
 * estimate (the estimator's control flow would run on rank 0 alone) nor
 * mumps.precision = single (EUNSUP: the core's refinement is whole-operand).
 *
 * Complex values (ABI 1.8) go to zmumps_c (libzmumps_seq linked the same
 * static way in the sequential module, libzmumps in the MPI one): the
 * triplets' values are SILC's interleaved entries, which is
 * mumps_double_complex.  MUMPS's SYM=2 means complex symmetric (A = A.'),
 * not Hermitian, and MUMPS has no Hermitian LDL^H: so a complex A that is
 * symmetric (A = A.') is factored with SYM=2 on its lower triangle, any
 * other complex A (Hermitian ones included) with SYM=0, and the .spd
 * classes decline complex operands, leaving a Hermitian positive definite
 * matrix to CHOLMOD or LAPACK, or to this LU under the general class.  The
 * condition estimate is the host's complex Hager-Higham
 * (inv_norm1_est_complex): A^{-H} x by the transposed solve (ICNTL(9)=2
 * solves A.' y = b for complex A, unconjugated) around conjugations.
 * mumps.precision = single is real only (cmumps is not linked): a complex
 * matrix is factored in double and the note says so.  The distributed path
 * moves 2 doubles per entry.
 */
#include "common/blas_threads.h"
#include "silc_plugin.h"

#include <float.h>
#include <stddef.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <complex.h>
#include <dmumps_c.h>
#include <smumps_c.h>
#include <zmumps_c.h>
#if SILC_MUMPS_MPI
#include <mpi.h>
#endif

#define MUMPS_JOB_INIT (-1)
#define MUMPS_JOB_END (-2)
#define MUMPS_JOB_FACTOR 2
#define MUMPS_JOB_SOLVE 3
#define MUMPS_JOB_ANALYSE_FACTOR 4
#define MUMPS_USE_COMM_WORLD (-987654) /* the sequential library's only communicator */
#define MUMPS_DISTRIBUTED_INPUT 3      /* ICNTL(18): each rank passes its own triplets */
#define MUMPS_RETRIES 4                /* ICNTL(14) doublings on workspace errors */
#define N_ICNTL 40
#define N_CNTL 15

/* Fortran's 1-based ICNTL(i), INFOG(i) of a factorization F as C lvalues
 * (the integer arrays are alike in both arithmetics). */
#define ICNTL(F, i) ((F)->icntl[(i)-1])
#define INFOG(F, i) ((F)->infog[(i)-1])

static const silc_host_api *host;

/* ---- options ----------------------------------------------------------------- */

#define IC(k, def, help) {"icntl_" #k, SILC_OPT_INT, def, "ICNTL(" #k "): " help}
#define C(k, help) {"cntl_" #k, SILC_OPT_DOUBLE, "", "CNTL(" #k "): " help}
/* The list order matters: icntl_k is entry k-1, cntl_k is entry N_ICNTL+k-1.
 * An empty default means "MUMPS's own default". */
static const silc_option_spec mumps_options[N_ICNTL + N_CNTL + 3] = {
    IC(1, "-1", "output stream for error messages (<= 0: none)"),
    IC(2, "-1", "output stream for diagnostics (<= 0: none)"),
    IC(3, "-1", "output stream for global information (<= 0: none)"),
    IC(4, "0", "print level (0: nothing .. 4: everything)"),
    IC(5, "0", "matrix input format (the plugin passes assembled triplets: 0)"),
    IC(6, "", "permutation / scaling to a zero-free diagonal (0-7)"),
    IC(7, "2", "ordering: 0 AMD, 2 AMF, 3 SCOTCH, 4 PORD, 5 METIS, 6 QAMD, 7 automatic"),
    IC(8, "", "scaling strategy (77: automatic)"),
    IC(9, "1", "1 solves A x = b (the only value '\\' can use)"),
    IC(10, "", "iterative refinement steps (0: none)"),
    IC(11, "0", "error analysis on the first one-column solve of a factorization: 0 none (the core "
                "computes every solve's backward error), 1 full (condition numbers), 2 backward errors"),
    IC(12, "", "ordering strategy for symmetric matrices (SYM=2)"),
    IC(13, "", "root front: ScaLAPACK use (parallel only)"),
    IC(14, "", "percentage increase of the estimated workspace"),
    IC(15, "", "dense-row detection / compression in analysis"),
    IC(16, "", "number of OpenMP threads (0: as the environment says)"),
    IC(17, "", "reserved"),
    IC(18, "0", "matrix distribution (the plugin chooses: 0 centralized, 3 for distributed operands)"),
    IC(19, "0", "Schur complement (not supported: 0)"),
    IC(20, "0", "right-hand side format (the plugin chooses: dense 0, distributed 10 for distributed operands)"),
    IC(21, "0", "solution distribution (the plugin chooses: centralized 0, distributed 1 for distributed operands)"),
    IC(22, "", "out-of-core factorization (1: factors on disk)"),
    IC(23, "", "maximum working memory per process in MB (0: no limit)"),
    IC(24, "", "null pivot detection (1: on)"),
    IC(25, "0", "null-space basis computation (not supported: 0)"),
    IC(26, "0", "Schur reduction / expansion (not supported: 0)"),
    IC(27, "", "blocking size for multiple right-hand sides"),
    IC(28, "", "sequential (1) or parallel (2) analysis"),
    IC(29, "", "parallel ordering tool"),
    IC(30, "0", "entries of the inverse (not supported: 0)"),
    IC(31, "0", "factors discarded after factorization (not supported: 0)"),
    IC(32, "0", "forward elimination during factorization (not supported: 0)"),
    IC(33, "", "determinant computation (1: on)"),
    IC(34, "", "out-of-core file deletion"),
    IC(35, "", "block low-rank factorization (0: off)"),
    IC(36, "", "block low-rank variant"),
    IC(37, "", "block low-rank compression of contribution blocks"),
    IC(38, "", "estimated compression rate of LU factors (per mille)"),
    IC(39, "", "estimated compression rate of contribution blocks (per mille)"),
    IC(40, "", "reserved"),
    C(1, "relative threshold for numerical pivoting"),
    C(2, "stopping criterion of iterative refinement"),
    C(3, "absolute threshold for null pivot detection"),
    C(4, "threshold for static pivoting (< 0: off)"),
    C(5, "fixation value for null pivots"),
    C(6, "reserved"),
    C(7, "block low-rank dropping parameter"),
    C(8, "reserved"),
    C(9, "reserved"),
    C(10, "reserved"),
    C(11, "reserved"),
    C(12, "reserved"),
    C(13, "reserved"),
    C(14, "reserved"),
    C(15, "reserved"),
    {"condest", SILC_OPT_BOOL, "true",
     "estimate the 1-norm condition number (block Hager-Higham: 2 extra two-column solves per "
     "factorization, the first block rides with the first solve)"},
    {"precision", SILC_OPT_STRING, "double",
     "factorization precision: double, or single (smumps factor, refined in double by the core)"},
    {"amalgamation", SILC_OPT_INT, "",
     "fewest pivots a front of the elimination tree keeps before it is merged into its parent "
     "(MUMPS's KEEP(1), NEMIN; empty: MUMPS's own 5)"},
};
#undef IC
#undef C

/* ICNTL entries whose value the plugin's data layout fixes. */
static const struct {
    int k, value;
    const char *why;
} fixed_icntl[] = {
    {5, 0, "the plugin passes the matrix assembled"},
    {9, 1, "'\\' solves A x = b"},
    {18, 0, "the plugin chooses (centralized, or distributed for distributed operands)"},
    {19, 0, "no Schur complement is returned"},
    {20, 0, "the plugin chooses (dense, or distributed for distributed operands)"},
    {21, 0, "the plugin chooses (centralized, or distributed for distributed operands)"},
    {25, 0, "no null-space basis is returned"},
    {26, 0, "no Schur complement is returned"},
    {30, 0, "'\\' computes a solution, not entries of the inverse"},
    {31, 0, "the factors must be kept for the solves"},
    {32, 0, "the right-hand side is not known at factorization"},
};

/* The options of one call.  "Unset" entries keep MUMPS's defaults. */
#define ICNTL_UNSET INT64_MIN
typedef struct settings {
    int64_t icntl[N_ICNTL];
    double cntl[N_CNTL];
    int cntl_set[N_CNTL];
    int64_t condest;
    int single;                 /* mumps.precision = single */
    int64_t amalgamation;       /* KEEP(1), or ICNTL_UNSET */
} settings;

static int read_settings(silc_call *call, settings *s)
{
    int k, rc;
    memset(s, 0, sizeof *s);
    for (k = 1; k <= N_ICNTL; k++) {
        const char *d = mumps_options[k - 1].default_value;
        int64_t def = d[0] ? (int64_t)strtol(d, NULL, 10) : ICNTL_UNSET;
        if ((rc = host->option_int(call, mumps_options[k - 1].key, def, &s->icntl[k - 1]))) return rc;
    }
    for (k = 1; k <= N_CNTL; k++) {
        double v;
        if ((rc = host->option_double(call, mumps_options[N_ICNTL + k - 1].key, NAN, &v))) return rc;
        s->cntl_set[k - 1] = !isnan(v);
        s->cntl[k - 1] = s->cntl_set[k - 1] ? v : 0.0;
    }
    if ((rc = host->option_int(call, "condest", 1, &s->condest))) return rc;
    if ((rc = host->option_int(call, "amalgamation", ICNTL_UNSET, &s->amalgamation))) return rc;
    if (s->amalgamation != ICNTL_UNSET && (s->amalgamation < 1 || s->amalgamation > 100000))
        return host->error(call, SILC_EARG, "option 'mumps.amalgamation' expects 1 to 100000 pivots, got %lld",
                           (long long)s->amalgamation);
    {
        const char *prec = host->option_string(call, "precision", "double");
        if (!prec) return SILC_EARG; /* the host has set the message */
        if (strcmp(prec, "single") != 0 && strcmp(prec, "double") != 0)
            return host->error(call, SILC_EARG,
                               "option 'mumps.precision' expects double or single, got '%s'", prec);
        s->single = strcmp(prec, "single") == 0;
    }
    for (k = 0; k < (int)(sizeof fixed_icntl / sizeof fixed_icntl[0]); k++) {
        int64_t v = s->icntl[fixed_icntl[k].k - 1];
        if (v != fixed_icntl[k].value)
            return host->error(call, SILC_EARG,
                               "mumps.icntl_%d = %lld is not supported: %s (ICNTL(%d) must be %d)",
                               fixed_icntl[k].k, (long long)v, fixed_icntl[k].why, fixed_icntl[k].k,
                               fixed_icntl[k].value);
    }
    for (k = 1; k <= N_ICNTL; k++)
        if (s->icntl[k - 1] != ICNTL_UNSET &&
            (s->icntl[k - 1] < INT_MIN || s->icntl[k - 1] > INT_MAX))
            return host->error(call, SILC_EARG, "mumps.icntl_%d = %lld is out of range", k,
                               (long long)s->icntl[k - 1]);
    return SILC_OK;
}

static int same_settings(const settings *a, const settings *b)
{
    int k;
    for (k = 0; k < N_ICNTL; k++)
        if (a->icntl[k] != b->icntl[k]) return 0;
    for (k = 0; k < N_CNTL; k++)
        if (a->cntl_set[k] != b->cntl_set[k] || a->cntl[k] != b->cntl[k]) return 0;
    return a->condest == b->condest && a->single == b->single && a->amalgamation == b->amalgamation;
}

/* ---- error meanings -------------------------------------------------------------- */

/* The common INFO(1)/INFOG(1) codes of the MUMPS 5.5 users' guide. */
static const char *mumps_meaning(int code)
{
    switch (code) {
    case -1: return "error on another process";
    case -2: return "number of entries NNZ out of range";
    case -3: return "invalid JOB for the current state";
    case -4: return "error in the user-supplied permutation PERM_IN";
    case -5: return "out of memory: real workspace allocation failed during analysis";
    case -6: return "structurally singular matrix";
    case -7: return "out of memory: integer workspace allocation failed during analysis";
    case -8: return "internal integer workspace too small for factorization";
    case -9: return "internal real workspace too small for factorization";
    case -10: return "numerically singular matrix";
    case -11: return "internal real workspace too small for the solution";
    case -12: return "internal real workspace too small for iterative refinement";
    case -13: return "out of memory: workspace allocation failed during factorization or solution";
    case -14: return "internal integer workspace too small for the solution";
    case -15: return "integer workspace too small for iterative refinement or error analysis";
    case -16: return "N out of range";
    case -17: return "internal send buffer too small";
    case -18: return "blocking size for multiple right-hand sides too large";
    case -19: return "working memory limit ICNTL(23) too small";
    case -20: return "internal reception buffer too small";
    case -21: return "PAR=0 needs more than one process";
    case -22: return "a pointer array is missing or has the wrong size";
    case -23: return "MPI was not initialized";
    case -24: return "NELT out of range";
    case -26: return "LRHS out of range";
    case -27: return "NZ_RHS and IRHS_PTR do not match";
    case -32: return "incompatible NRHS and ICNTL(25)";
    case -38: return "parallel analysis not possible with these settings";
    case -40: return "matrix declared positive definite (SYM=1) but a negative or zero pivot was met";
    case -44: return "the factors were discarded (ICNTL(31)=1)";
    case -45: return "NRHS <= 0";
    case -52: return "the ordering library needs 64-bit integers";
    case -53: return "internal error: inconsistent input between two consecutive calls";
    case -90: return "error in out-of-core management";
    default: return "see the MUMPS users' guide";
    }
}

/* Errors that more workspace (a larger ICNTL(14)) can cure. */
static int workspace_error(int code)
{
    return code == -8 || code == -9 || code == -14 || code == -15 || code == -17 || code == -20;
}

/* ---- the ranks of a call ----------------------------------------------------------- */

/* Who takes part in a call.  dist: A and B are distributed by rows over comm
 * (a collective call; MPI build only), and layout is A's.  Otherwise the
 * operands are whole and MUMPS runs on this process alone: on the sequential
 * library's one communicator, or on MPI_COMM_SELF in the MPI build. */
typedef struct solve_ctx {
    int dist;
    int rank, size;
    MUMPS_INT comm_f;           /* MUMPS's comm_fortran */
#if SILC_MUMPS_MPI
    MPI_Comm comm;
#endif
    silc_layout layout;
    int status;                 /* local_error's status and message, for agree */
    char msg[256];
} solve_ctx;

/* A failure found on this rank alone: kept for agree(), which every rank
 * reaches, instead of being returned straight away while the other ranks go
 * on into a collective step. */
static int local_error(solve_ctx *c, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static int local_error(solve_ctx *c, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->msg, sizeof c->msg, fmt, ap);
    va_end(ap);
    return c->status = status;
}

#if SILC_MUMPS_MPI
/* The communicator of the call: the host's for distributed operands, else
 * MPI_COMM_SELF.  This build is only loaded in MPI mode, so MPI must be up. */
static int ctx_open(silc_call *call, solve_ctx *c)
{
    int up = 0, down = 0;
    const void *comm;
    memset(c, 0, sizeof *c);
    comm = host->comm(call, &c->rank, &c->size);
    MPI_Initialized(&up);
    MPI_Finalized(&down);
    if (!up || down)
        return host->error(call, SILC_ELIB,
                           "mumps (MPI build): MPI is %s; this build runs only in MPI mode "
                           "(the sequential libsilc_plugin_mumps.so serves the others)",
                           down ? "already finalized" : "not initialized");
    if (comm) {
        c->dist = 1;
        c->comm = *(const MPI_Comm *)comm;
        if (!host->layout(call->in[0], &c->layout))
            return host->error(call, SILC_EARG, "mumps: a collective solve needs A distributed by rows");
    } else {
        c->comm = MPI_COMM_SELF;
        c->rank = 0;
        c->size = 1;
    }
    c->comm_f = (MUMPS_INT)MPI_Comm_c2f(c->comm);
    return SILC_OK;
}

/* Every rank passes its local status (0, or local_error's); all return the
 * same: the lowest failing rank's status and message, naming that rank. */
static int agree(silc_call *call, solve_ctx *c, int rc)
{
    struct {
        int rank, status;
    } in, out;
    if (!c->dist) return rc ? host->error(call, c->status, "%s", c->msg) : SILC_OK;
    in.rank = rc ? c->rank : INT_MAX;
    in.status = rc ? c->status : SILC_OK;
    /* MINLOC on MPI_2INT keeps the status that goes with the lowest rank. */
    if (MPI_Allreduce(&in, &out, 1, MPI_2INT, MPI_MINLOC, c->comm) != MPI_SUCCESS)
        return host->error(call, SILC_ELIB, "mumps: MPI_Allreduce failed agreeing on a status");
    if (out.rank == INT_MAX) return SILC_OK;
    if (MPI_Bcast(c->msg, (int)sizeof c->msg, MPI_CHAR, out.rank, c->comm) != MPI_SUCCESS)
        return host->error(call, out.status, "mumps: failed on rank %d of %d", out.rank, c->size);
    c->msg[sizeof c->msg - 1] = '\0';
    return host->error(call, out.status, "%s (on rank %d of %d)", c->msg, out.rank, c->size);
}

/* 1 if flag is non-zero on every rank. */
static int all_ranks(const solve_ctx *c, int flag)
{
    int all = flag != 0;
    if (c->dist) MPI_Allreduce(MPI_IN_PLACE, &all, 1, MPI_INT, MPI_LAND, c->comm);
    return all;
}

static int64_t sum_ranks(const solve_ctx *c, int64_t x)
{
    if (c->dist) MPI_Allreduce(MPI_IN_PLACE, &x, 1, MPI_INT64_T, MPI_SUM, c->comm);
    return x;
}

/* A value destroyed after MPI_Finalize cannot run JOB=-2 (MPI calls). */
static int mpi_alive(void)
{
    int down = 0;
    MPI_Finalized(&down);
    return !down;
}
#else
static int ctx_open(silc_call *call, solve_ctx *c)
{
    (void)call;
    memset(c, 0, sizeof *c);
    c->size = 1;
    c->comm_f = MUMPS_USE_COMM_WORLD;
    return SILC_OK;
}

static int agree(silc_call *call, solve_ctx *c, int rc)
{
    return rc ? host->error(call, c->status, "%s", c->msg) : SILC_OK;
}

static int all_ranks(const solve_ctx *c, int flag)
{
    (void)c;
    return flag != 0;
}

static int64_t sum_ranks(const solve_ctx *c, int64_t x)
{
    (void)c;
    return x;
}

static int mpi_alive(void)
{
    return 1;
}
#endif

/* ---- the factorization attachment ------------------------------------------------ */

typedef struct mumps_factor {
    union {
        DMUMPS_STRUC_C d;
        SMUMPS_STRUC_C s;
        ZMUMPS_STRUC_C z;
    } id;                       /* id.s when single, id.z when cplx, else id.d */
    int single;                 /* factored by smumps_c from af */
    int cplx;                   /* complex A: zmumps_c, a holds 2 doubles per entry */
    int dist;                   /* irn/jcn/a are this rank's rows (ICNTL(18)=3), rhs is on rank 0 */
    MUMPS_INT comm_f;           /* the communicator it runs on */
    MUMPS_INT *icntl, *infog;   /* the arrays of the instance in use */
    int live;                   /* JOB=-1 succeeded: JOB=-2 must run */
    MUMPS_INT *irn, *jcn;       /* 1-based triplets; MUMPS reads them again for */
    double *a;                  /* error analysis and iterative refinement */
    float *af;                  /* single: 2^scale_a * a in float, a is then freed */
    float *yf;                  /* single: the right-hand sides in float, kept for the next solve */
    int64_t yf_cap;             /* floats yf holds */
    int scale_a;
    const char *fallback;       /* why mumps.precision = single factored in double */
    settings opts;              /* the options it was computed with */
    double cond_est;            /* 1-norm condition estimate, -1 = not computed */
    double *est_y0;             /* A^-1 X0, the estimator's start block solved with the first
                                   solve of an owed estimate (real, n x EST_COLS), which the
                                   estimate goes on from when made: NULL when none is kept */
    double est_lower;           /* the lower bound of cond_1 est_y0 gave (start_bound) */
    int analysed;               /* the error analysis ran (on the first 1-column solve) */
    double rinfog[11];          /* its RINFOG(1..11) */
    double factor_seconds;
    int retries;                /* ICNTL(14) doublings that were needed */
    /* Distributed right-hand side and solution (ICNTL(20)=10, ICNTL(21)=1;
     * MPI build, distributed operands: solve_dist_loc). */
    MUMPS_INT *irhs_loc;        /* this rank's rows of b, 1-based global (Nloc_RHS of them) */
    MUMPS_INT *isol_loc;        /* the rows of x MUMPS leaves on this rank (INFO(23)), set by JOB=3 */
    MUMPS_INT *isol_plan;       /* isol_loc as the redistribution plan was made for */
    double *sol_loc;            /* INFO(23) x nrhs entries */
    int64_t lsol_loc, sol_cap;  /* INFO(23); entries sol_loc holds */
    int *send_n, *recv_n;       /* entries of x to / from each rank, per column */
    int64_t *send_at;           /* positions in sol_loc, grouped by destination rank */
    int64_t *recv_row;          /* local rows of what arrives, grouped by source rank */
    int64_t plan_moved;         /* entries per column received from another rank, summed over ranks */
    int loc_solved;             /* the last solve ran with them (for the report) */
} mumps_factor;

/* One MUMPS call (JOB=job) in the arithmetic F was set up for. */
static void mumps_job(mumps_factor *F, int job)
{
    if (F->single) {
        F->id.s.job = job;
        smumps_c(&F->id.s);
    } else if (F->cplx) {
        F->id.z.job = job;
        zmumps_c(&F->id.z);
    } else {
        F->id.d.job = job;
        dmumps_c(&F->id.d);
    }
}

/* Sets an integer or index-array member of whichever instance F uses. */
#define ID_SET(F, member, value)                                                                   \
    ((F)->single ? (void)((F)->id.s.member = (value))                                                \
     : (F)->cplx ? (void)((F)->id.z.member = (value))                                                \
                 : (void)((F)->id.d.member = (value)))
#define ID_N(F) ((F)->single ? (F)->id.s.n : (F)->cplx ? (F)->id.z.n : (F)->id.d.n)
#define ID_SYM(F) ((F)->single ? (F)->id.s.sym : (F)->cplx ? (F)->id.z.sym : (F)->id.d.sym)
/* MUMPS's internal KEEP(i) of F's instance (read-only here but for KEEP(1)). */
#define ID_KEEP(F, i) ((F)->single ? (F)->id.s.keep[(i)-1] : (F)->cplx ? (F)->id.z.keep[(i)-1] : (F)->id.d.keep[(i)-1])
/* The library entry point of F's arithmetic, for messages. */
#define ID_FN(F) ((F)->single ? "smumps_c" : (F)->cplx ? "zmumps_c" : "dmumps_c")
/* Doubles per entry of F's values and right-hand sides. */
#define ID_W(F) ((F)->cplx ? 2 : 1)

/* Ends the MUMPS instance (collective over its communicator) and frees the
 * triplets; F stays, no longer live, so it is never reused. */
static void factor_end(mumps_factor *F)
{
    if (F->live && mpi_alive()) mumps_job(F, MUMPS_JOB_END);
    F->live = 0;
    silc_large_free_of(host, F->irn);
    silc_large_free_of(host, F->jcn);
    silc_large_free_of(host, F->a);
    silc_large_free_of(host, F->af);
    host->free(F->yf);
    host->free(F->est_y0);
    F->irn = F->jcn = NULL;
    F->a = NULL;
    F->af = NULL;
    F->yf = NULL;
    F->yf_cap = 0;
    F->est_y0 = NULL;
    host->free(F->irhs_loc);
    host->free(F->isol_loc);
    host->free(F->isol_plan);
    host->free(F->sol_loc);
    host->free(F->send_n);
    host->free(F->send_at);
    host->free(F->recv_row);
    F->irhs_loc = F->isol_loc = F->isol_plan = NULL;
    F->sol_loc = NULL;
    F->send_n = F->recv_n = NULL;
    F->send_at = F->recv_row = NULL;
    F->sol_cap = 0;
}

static void factor_free(void *p)
{
    mumps_factor *F = p;
    if (!F) return;
    factor_end(F);
    host->free(F);
}

/* Entry (i, j) of a dense or band view, 0 outside the band (w = 2: the
 * complex entry, read as double complex). */
static double complex full_get(const silc_view *v, int64_t i, int64_t j, int w)
{
    int64_t p;
    if (v->format == SILC_FMT_DENSE) p = i + j * v->m;
    else if (i - j > v->kl || j - i > v->ku) return 0.0;
    else p = (v->ku + i - j) + j * v->ld;
    return w == 2 ? ((const double complex *)v->val)[p] : v->val[p];
}

/* 1-based triplets of A (SYM=1: the lower triangle only).  CSR keeps explicit
 * zeros (they are part of the pattern); dense and band skip zeros.  A
 * distributed A is CSR, v its rows from global row row0 on (else row0 = 0):
 * the triplets carry global row numbers. */
static int build_triplets(const silc_view *v, int64_t row0, int lower, mumps_factor *F,
                          int64_t *nnz_out)
{
    int64_t n = v->n, cap, nz = 0, i, j, k;
    int w = ID_W(F);
    cap = v->format == SILC_FMT_CSR ? v->nnz : v->format == SILC_FMT_BAND ? v->ld * n : n * n;
    if (cap < 1) cap = 1;
    /* 16 bytes an entry, kept as long as the factorization: 12 MB a rank
     * at a million unknowns on two, whose first-touch page faults were
     * half of this function (docs/distributed.md). */
    F->irn = silc_large_alloc_of(host, (size_t)cap * sizeof(MUMPS_INT));
    F->jcn = silc_large_alloc_of(host, (size_t)cap * sizeof(MUMPS_INT));
    F->a = silc_large_alloc_of(host, (size_t)cap * (size_t)w * sizeof(double));
    if (!F->irn || !F->jcn || !F->a) return SILC_ENOMEM;
    if (v->format == SILC_FMT_CSR) {
        for (i = 0; i < v->m; i++)
            for (k = v->rowptr[i]; k < v->rowptr[i + 1]; k++) {
                if (lower && v->colind[k] > row0 + i) break; /* columns are sorted */
                F->irn[nz] = (MUMPS_INT)(row0 + i + 1);
                F->jcn[nz] = (MUMPS_INT)(v->colind[k] + 1);
                memcpy(F->a + nz++ * w, v->val + k * w, (size_t)w * sizeof(double));
            }
    } else {
        for (j = 0; j < n; j++) {
            int64_t lo = lower ? j : 0, hi = n;
            if (v->format == SILC_FMT_BAND) {
                if (j - v->ku > lo) lo = j - v->ku;
                if (j + v->kl + 1 < hi) hi = j + v->kl + 1;
            }
            for (i = lo; i < hi; i++) {
                double complex x = full_get(v, i, j, w);
                if (x == 0.0) continue;
                F->irn[nz] = (MUMPS_INT)(i + 1);
                F->jcn[nz] = (MUMPS_INT)(j + 1);
                F->a[nz * w] = creal(x);
                if (w == 2) F->a[nz * w + 1] = cimag(x);
                nz++;
            }
        }
    }
    *nnz_out = nz;
    return SILC_OK;
}

/* The "dmumps_c (JOB=k): meaning (INFOG(1)=c, INFOG(2)=d)" message. */
static int mumps_fail(silc_call *call, int status, const mumps_factor *F, int job)
{
    return host->error(call, status, "%s (JOB=%d): %s (INFOG(1)=%d, INFOG(2)=%d)",
                       ID_FN(F), job, mumps_meaning((int)INFOG(F, 1)),
                       (int)INFOG(F, 1), (int)INFOG(F, 2));
}

/* Status of a failed factorization: singular and not-positive-definite are
 * numerical outcomes, the rest are library failures. */
static int factor_status(int code, int sym)
{
    if (sym == 1 && (code == -10 || code == -40)) return SILC_ENOTSPD;
    if (code == -6 || code == -10) return SILC_ESINGULAR;
    if (code == -5 || code == -7 || code == -13) return SILC_ENOMEM;
    return SILC_ELIB;
}

/* run_solve's "refactored with more workspace: refill the right-hand side and
 * call again".  Bounded: every retry spends one of MUMPS_RETRIES. */
#define SOLVE_AGAIN (-1)

/* Power-of-two exponent that brings the largest |x[i]| (i < n) into [0.5, 1),
 * so values fit single precision without changing a bit of their mantissas. */
static int scale_exponent(const double *x, int64_t n)
{
    double mx = 0;
    int e = 0;
    int64_t i;
    for (i = 0; i < n; i++)
        if (fabs(x[i]) > mx) mx = fabs(x[i]);
    if (mx > 0 && isfinite(mx)) frexp(mx, &e);
    return -e;
}

/* 2^e when that is a normal double, else 0.  Scaling by a multiplication
 * with it rounds exactly as ldexp (both are exact or correctly rounded to a
 * subnormal) at a fraction of ldexp's cost per entry (2-3 % of a single-
 * precision solve on the 200^2 diffusion matrix); the caller falls back to
 * ldexp when it is 0. */
static double pow2_or_zero(int e)
{
    return e >= DBL_MIN_EXP - 1 && e <= DBL_MAX_EXP - 1 ? ldexp(1.0, e) : 0.0;
}

/* Single precision: each column of rhs scaled by its own power of two, solved
 * by smumps_c, scaled back (x = 2^(scale_a - q) y for (2^scale_a A) y = 2^q b).
 * The float copy of the right-hand sides stays with F for the next solve. */
static int solve_single(mumps_factor *F, double *rhs, int64_t nrhs)
{
    int64_t n = F->id.s.n, i, c;
    int *q = host->alloc((size_t)nrhs * sizeof *q);
    if (!q) return SILC_ENOMEM;
    if (n * nrhs > F->yf_cap) {
        host->free(F->yf);
        F->yf_cap = 0;
        if (!(F->yf = host->alloc((size_t)(n * nrhs) * sizeof *F->yf))) {
            host->free(q);
            return SILC_ENOMEM;
        }
        F->yf_cap = n * nrhs;
    }
    for (c = 0; c < nrhs; c++) {
        const double *x = rhs + c * n;
        float *y = F->yf + c * n;
        double in = pow2_or_zero(q[c] = scale_exponent(x, n));
        for (i = 0; i < n; i++) y[i] = (float)(in != 0 ? x[i] * in : ldexp(x[i], q[c]));
    }
    F->id.s.rhs = F->yf;
    mumps_job(F, MUMPS_JOB_SOLVE);
    if (INFOG(F, 1) >= 0)
        for (c = 0; c < nrhs; c++) {
            double *x = rhs + c * n, out = pow2_or_zero(F->scale_a - q[c]);
            const float *y = F->yf + c * n;
            for (i = 0; i < n; i++) x[i] = out != 0 ? (double)y[i] * out : ldexp((double)y[i], F->scale_a - q[c]);
        }
    F->id.s.rhs = NULL;
    host->free(q);
    return SILC_OK;
}

/* JOB=3 on nrhs columns of rhs, overwritten by the solution.  When the solve
 * runs out of workspace, refactors with twice ICNTL(14) and asks the caller to
 * refill rhs (the failed solve may have overwritten it). */
static int run_solve(silc_call *call, mumps_factor *F, double *rhs, int64_t nrhs)
{
    ID_SET(F, nrhs, (MUMPS_INT)nrhs);
    ID_SET(F, lrhs, ID_N(F));
    if (F->single) {
        if (solve_single(F, rhs, nrhs))
            return host->error(call, SILC_ENOMEM, "mumps: out of memory for the single-precision solve");
    } else if (F->cplx) {
        F->id.z.rhs = (ZMUMPS_COMPLEX *)rhs;
        mumps_job(F, MUMPS_JOB_SOLVE);
    } else {
        F->id.d.rhs = rhs;
        mumps_job(F, MUMPS_JOB_SOLVE);
    }
    if (INFOG(F, 1) >= 0) return SILC_OK;
    if (!workspace_error((int)INFOG(F, 1)) || F->retries >= MUMPS_RETRIES)
        return mumps_fail(call, factor_status((int)INFOG(F, 1), 0), F, MUMPS_JOB_SOLVE);
    ICNTL(F, 14) = ICNTL(F, 14) > 0 ? 2 * ICNTL(F, 14) : 40;
    F->retries++;
    mumps_job(F, MUMPS_JOB_FACTOR);
    if (INFOG(F, 1) < 0)
        return mumps_fail(call, factor_status((int)INFOG(F, 1), (int)ID_SYM(F)), F, MUMPS_JOB_FACTOR);
    return SOLVE_AGAIN;
}

/* The condition estimate is the host's block estimator (ABI 1.3) with two
 * columns and two steps: MUMPS's solve phase costs about the same for two
 * columns as for one (6.2 against 6.0 ms on memplus, where the work proper
 * is a tenth of that), so the block costs no more than a single vector, and
 * its first block rides along with the user's first solve.  Two steps (start,
 * gradient, improvement) are what Hager's method settles on almost always;
 * test_plugin_mumps compares the estimates with the exact cond_1. */
#define EST_COLS 2
#define EST_STEPS 2

typedef struct est_ctx {
    silc_call *call;
    mumps_factor *F;
    double *keep;               /* the block, for a solve that must be redone */
    int rc;                     /* a failed solve's status (its message is set) */
} est_ctx;

/* A block that is mostly zeros (the estimator's unit vectors) goes to MUMPS
 * as sparse right-hand sides (ICNTL(20)=1): MUMPS then prunes the forward
 * elimination to the fronts on the paths from those unknowns to the root,
 * which halved the solve phase for two unit vectors on memplus (2.9 against
 * 5.9 ms), bayer10 (1.7 / 2.9) and bcsstk16 (0.75 / 1.1).  Double precision
 * only: the single-precision path converts dense right-hand sides.  Returns
 * 1 with F set up (and *arrays to free), or 0 for a dense solve. */
static int sparse_block(mumps_factor *F, const double *X, int t, void *arrays[3])
{
    int64_t n = ID_N(F), i, nz = 0;
    MUMPS_INT *ptr, *idx;
    double *val;
    int j;
    if (F->cplx) return 0; /* the sparse right-hand sides are real arrays here */
    for (i = 0; i < n * t; i++) nz += X[i] != 0;
    if (F->single || nz == 0 || nz * 8 > n * t) return 0; /* an all-zero block: nothing to prune */
    arrays[0] = ptr = host->alloc((size_t)(t + 1) * sizeof *ptr);
    arrays[1] = idx = host->alloc((size_t)nz * sizeof *idx);
    arrays[2] = val = host->alloc((size_t)nz * sizeof *val);
    if (!ptr || !idx || !val) {
        for (j = 0; j < 3; j++) host->free(arrays[j]);
        return 0; /* the dense solve needs no more memory */
    }
    for (nz = 0, j = 0; j < t; j++) {
        ptr[j] = (MUMPS_INT)(nz + 1);
        for (i = 0; i < n; i++)
            if (X[i + j * n] != 0) {
                idx[nz] = (MUMPS_INT)(i + 1);
                val[nz++] = X[i + j * n];
            }
    }
    ptr[t] = (MUMPS_INT)(nz + 1);
    F->id.d.irhs_ptr = ptr;
    F->id.d.irhs_sparse = idx;
    F->id.d.rhs_sparse = val;
    F->id.d.nz_rhs = (MUMPS_INT)nz;
    ICNTL(F, 20) = 1;
    return 1;
}

static int apply_block(void *ctx, double *X, int t, int trans)
{
    est_ctx *c = ctx;
    size_t bytes = (size_t)ID_N(c->F) * (size_t)t * sizeof *X;
    void *arrays[3];
    int rc, sparse, j;
    memcpy(c->keep, X, bytes);
    do {
        memcpy(X, c->keep, bytes);
        sparse = !trans && sparse_block(c->F, X, t, arrays);
        ICNTL(c->F, 9) = trans ? 2 : 1;
        rc = run_solve(c->call, c->F, X, t);
        ICNTL(c->F, 9) = 1;
        if (sparse) {
            ICNTL(c->F, 20) = 0;
            c->F->id.d.irhs_ptr = c->F->id.d.irhs_sparse = NULL;
            c->F->id.d.rhs_sparse = NULL;
            for (j = 0; j < 3; j++) host->free(arrays[j]);
        }
    } while (rc == SOLVE_AGAIN);
    return c->rc = rc;
}

/* F->cond_est from the block estimator; Y0 = A^{-1} X0 if the first block
 * was folded into a solve, else NULL.  The caller has the error analysis
 * switched off (it would run on every one of these solves). */
static int estimate_cond(silc_call *call, mumps_factor *F, const double *Y0)
{
    double inv;
    est_ctx c = {call, F, host->alloc((size_t)ID_N(F) * EST_COLS * sizeof(double)), 0};
    if (!c.keep) return host->error(call, SILC_ENOMEM, "mumps: out of memory for the condition estimate");
    /* an owed estimate goes on from the start block its solve kept: one
     * solve phase less, and the same estimate as one made at solve time */
    inv = host->inv_norm1_est_block(ID_N(F), EST_COLS, EST_STEPS, apply_block, &c, Y0 ? Y0 : F->est_y0);
    host->free(c.keep);
    host->free(F->est_y0);
    F->est_y0 = NULL;
    if (inv < 0)
        return c.rc ? c.rc : host->error(call, SILC_ENOMEM, "mumps: out of memory for the condition estimate");
    F->cond_est = silc_props_of(host, call->in[0], SILC_PROPS_NORMS)->norm1 * inv;
    return SILC_OK;
}

/* The complex estimate's solve: x (n complex entries) := A^{-1} x, or
 * A^{-H} x = conj(A.'^{-1} conj(x)) when trans is set (ICNTL(9)=2 solves
 * with A.' for complex A). */
static int apply_complex(void *ctx, double *x, int trans, double *work)
{
    est_ctx *c = ctx;
    int64_t n = ID_N(c->F), i;
    size_t bytes = (size_t)n * 2 * sizeof *x;
    int rc;
    (void)work;
    if (trans)
        for (i = 0; i < n; i++) x[2 * i + 1] = -x[2 * i + 1];
    memcpy(c->keep, x, bytes);
    do {
        memcpy(x, c->keep, bytes);
        ICNTL(c->F, 9) = trans ? 2 : 1;
        rc = run_solve(c->call, c->F, x, 1);
        ICNTL(c->F, 9) = 1;
    } while (rc == SOLVE_AGAIN);
    if (trans)
        for (i = 0; i < n; i++) x[2 * i + 1] = -x[2 * i + 1];
    return c->rc = rc;
}

/* F->cond_est of a complex F, by the host's complex estimator (ABI 1.8);
 * nothing on a host without it (the report then says "not estimated"). */
static int estimate_cond_complex(silc_call *call, mumps_factor *F)
{
    double inv;
    est_ctx c = {call, F, NULL, 0};
    if (host->struct_size < SILC_HOST_NEEDS(inv_norm1_est_complex) || !host->inv_norm1_est_complex)
        return SILC_OK;
    if (!(c.keep = host->alloc((size_t)ID_N(F) * 2 * sizeof(double))))
        return host->error(call, SILC_ENOMEM, "mumps: out of memory for the condition estimate");
    inv = host->inv_norm1_est_complex(ID_N(F), apply_complex, &c, NULL);
    host->free(c.keep);
    if (inv < 0)
        return c.rc ? c.rc : host->error(call, SILC_ENOMEM, "mumps: out of memory for the condition estimate");
    F->cond_est = silc_props_of(host, call->in[0], SILC_PROPS_NORMS)->norm1 * inv;
    return SILC_OK;
}

/* The estimate made when the report is read (ABI 1.8, docs/accuracy.md):
 * condest_later asks to leave out an estimate (it costs EST_PHASES solve
 * phases unfolded, where MUMPS's fixed cost per phase is 20-40 % of a
 * factorization of the shared matrices) and say it is owed; condest_only
 * asks for it alone with the attached factorization (condest_only_run). */
#define EST_PHASES 3
static int condest_later(const silc_call *call)
{
    return host->abi_minor >= 8 && call->report->condest_later;
}

/* The 1-norms of the n x EST_COLS block X of w doubles per entry (into
 * sums; w = 2: complex, by modulus). */
static void column_sums(int64_t n, int w, const double *X, double sums[EST_COLS])
{
    for (int j = 0; j < EST_COLS; j++) {
        const double *x = X + j * n * w;
        sums[j] = 0;
        for (int64_t i = 0; i < n; i++) sums[j] += w == 2 ? hypot(x[2 * i], x[2 * i + 1]) : fabs(x[i]);
    }
}

/* The estimator's start block (e/n and the alternating vector, the host's)
 * into X, n x EST_COLS entries of w doubles (complex: imaginary parts 0). */
static void start_block(int64_t n, int w, double *X)
{
    host->inv_norm1_start(n, EST_COLS, X);
    if (w == 2)
        for (int64_t i = n * EST_COLS - 1; i >= 0; i--) X[2 * i] = X[i], X[2 * i + 1] = 0;
}

/* ||A||_1 max_j ||Y_j||_1 / ||X0_j||_1 for the start block X0 (column sums
 * x0) solved into Y: a lower bound of cond_1(A) (condest_lower). */
static double start_bound(silc_call *call, int64_t n, int w, const double *Y, const double x0[EST_COLS])
{
    double y[EST_COLS], best = 0;
    column_sums(n, w, Y, y);
    for (int j = 0; j < EST_COLS; j++)
        if (x0[j] > 0 && y[j] / x0[j] > best) best = y[j] / x0[j];
    return best * silc_props_of(host, call->in[0], SILC_PROPS_NORMS)->norm1;
}

static int condest_wanted(const silc_call *call, const settings *s, const mumps_factor *F)
{
    return s->condest && F->cond_est < 0 && !(host->abi_minor >= 7 && call->report->condest_off);
}

/* mumps.precision = single: af = 2^scale_a a in float, the largest entry near
 * 1.  Returns why that cannot be done, or NULL. */
static const char *to_single(mumps_factor *F, int64_t nnz)
{
    int64_t k;
    F->scale_a = scale_exponent(F->a, nnz);
    for (k = 0; k < nnz; k++) {
        double x = ldexp(F->a[k], F->scale_a);
        if (x != 0 && fabs(x) < FLT_MIN) return "its entries span more than single precision's range";
    }
    F->af = silc_large_alloc_of(host, (size_t)nnz * sizeof *F->af);
    if (!F->af) return "no memory for a single-precision copy";
    for (k = 0; k < nnz; k++) F->af[k] = (float)ldexp(F->a[k], F->scale_a);
    return NULL;
}

/* JOB=-1, then JOB=4, then JOB=2 again with twice the workspace while it runs
 * short, in F's arithmetic.  nnz: the triplets of this rank when F->dist.
 * Returns INFOG(1) and the last JOB in *job. */
static int analyse_factor(mumps_factor *F, int n, int64_t nnz, int sym, const settings *s, int *job)
{
    int k;
    F->icntl = F->single ? F->id.s.icntl : F->cplx ? F->id.z.icntl : F->id.d.icntl;
    F->infog = F->single ? F->id.s.infog : F->cplx ? F->id.z.infog : F->id.d.infog;
    ID_SET(F, par, 1); /* rank 0 (the host) works too */
    ID_SET(F, sym, sym);
    ID_SET(F, comm_fortran, F->comm_f);
    mumps_job(F, *job = MUMPS_JOB_INIT);
    if (INFOG(F, 1) < 0) return (int)INFOG(F, 1);
    F->live = 1;
    for (k = 1; k <= N_ICNTL; k++)
        if (s->icntl[k - 1] != ICNTL_UNSET) ICNTL(F, k) = (MUMPS_INT)s->icntl[k - 1];
    if (s->amalgamation != ICNTL_UNSET) /* read by the analysis (JOB=4) */
        ID_SET(F, keep[0], (MUMPS_INT)s->amalgamation);
    for (k = 1; k <= N_CNTL; k++)
        if (s->cntl_set[k - 1]) {
            if (F->single)
                F->id.s.cntl[k - 1] = (float)s->cntl[k - 1];
            else if (F->cplx)
                F->id.z.cntl[k - 1] = s->cntl[k - 1];
            else
                F->id.d.cntl[k - 1] = s->cntl[k - 1];
        }
    ID_SET(F, n, (MUMPS_INT)n);
    if (F->dist) { /* the single-precision path is not offered here */
        ICNTL(F, 18) = MUMPS_DISTRIBUTED_INPUT;
        ID_SET(F, nnz_loc, nnz);
        ID_SET(F, nz_loc, nnz <= INT_MAX ? (MUMPS_INT)nnz : 0);
        ID_SET(F, irn_loc, F->irn);
        ID_SET(F, jcn_loc, F->jcn);
        if (F->cplx)
            F->id.z.a_loc = (ZMUMPS_COMPLEX *)F->a;
        else
            F->id.d.a_loc = F->a;
    } else {
        ID_SET(F, nnz, nnz);
        ID_SET(F, nz, nnz <= INT_MAX ? (MUMPS_INT)nnz : 0);
        ID_SET(F, irn, F->irn);
        ID_SET(F, jcn, F->jcn);
        if (F->single)
            F->id.s.a = F->af;
        else if (F->cplx)
            F->id.z.a = (ZMUMPS_COMPLEX *)F->a;
        else
            F->id.d.a = F->a;
    }
    mumps_job(F, *job = MUMPS_JOB_ANALYSE_FACTOR);
    /* Workspace errors come from the factorization phase, after a complete
     * analysis: only the factorization (JOB=2) is repeated. */
    while (INFOG(F, 1) < 0 && workspace_error((int)INFOG(F, 1)) && F->retries < MUMPS_RETRIES) {
        ICNTL(F, 14) = ICNTL(F, 14) > 0 ? 2 * ICNTL(F, 14) : 40;
        F->retries++;
        mumps_job(F, *job = MUMPS_JOB_FACTOR);
    }
    return (int)INFOG(F, 1);
}

/* Initializes MUMPS for A (v: this rank's rows when c->dist), analyses and
 * factors it, in single precision when the settings ask and the entries
 * allow.  Collective: every rank returns the same status. */
static int factor_new(silc_call *call, solve_ctx *c, const silc_view *v, int sym, int cplx,
                      const settings *s, mumps_factor **out)
{
    mumps_factor *F = host->calloc(1, sizeof *F);
    int64_t nnz = 0;
    int rc = SILC_OK, code, job;
    double t0 = host->now();
    *out = NULL;
    if (!F) {
        rc = local_error(c, SILC_ENOMEM, "mumps: out of memory");
    } else {
        F->cond_est = -1;
        F->opts = *s;
        F->dist = c->dist;
        F->comm_f = c->comm_f;
        F->cplx = cplx;
        if (build_triplets(v, c->dist ? c->layout.first_row : 0, sym != 0, F, &nnz))
            rc = local_error(c, SILC_ENOMEM, "mumps: out of memory for %lld triplets",
                             (long long)v->nnz);
    }
    if ((rc = agree(call, c, rc))) {
        factor_free(F); /* not live yet: nothing collective */
        return rc;
    }
    if (sum_ranks(c, nnz) == 0) { /* MUMPS would answer "NNZ out of range" (INFOG(1)=-2) */
        factor_free(F);
        return host->error(call, SILC_ESINGULAR, "mumps: singular matrix (no nonzero entries)");
    }
    if (s->single && cplx) {
        F->fallback = "single precision is real only here (cmumps is not linked)";
    } else if (s->single) {
        F->fallback = to_single(F, nnz);
        F->single = F->fallback == NULL;
    }
    code = analyse_factor(F, (int)v->n, nnz, sym, s, &job);
    if (code == -10 && F->single && sym == 0) {
        /* Singular in single precision may still be regular in double. */
        mumps_job(F, MUMPS_JOB_END);
        memset(&F->id, 0, sizeof F->id);
        F->live = F->single = F->retries = 0;
        silc_large_free_of(host, F->af);
        F->af = NULL;
        F->fallback = "the single-precision LU was numerically singular";
        code = analyse_factor(F, (int)v->n, nnz, sym, s, &job);
    }
    if (code < 0) {
        rc = mumps_fail(call, job == MUMPS_JOB_INIT ? SILC_ELIB : factor_status(code, sym), F, job);
        factor_free(F);
        return rc;
    }
    if (F->single) { /* MUMPS reads af from now on */
        silc_large_free_of(host, F->a);
        F->a = NULL;
    }
    /* LDL' of an SPD matrix has only positive pivots; INFOG(12) counts the negative ones. */
    if (sym == 1 && INFOG(F, 12) > 0) {
        rc = host->error(call, SILC_ENOTSPD,
                         "%s (JOB=4): matrix is not positive definite (INFOG(12)=%d negative pivots)",
                         ID_FN(F), (int)INFOG(F, 12));
        factor_free(F);
        return rc;
    }
    F->factor_seconds = host->now() - t0;
    *out = F;
    return SILC_OK;
}

/* ---- the solve ------------------------------------------------------------------- */

static const char *ordering_name(int k)
{
    static const char *names[] = {"AMD", "user", "AMF", "SCOTCH", "PORD", "METIS", "QAMD", "auto"};
    return k >= 0 && k < 8 ? names[k] : "unknown";
}

/* Copies B (any format) into the dense n x nrhs array x; w doubles per
 * entry (2: complex). */
static void dense_copy(const silc_view *b, double *x, int w)
{
    int64_t i, j, k;
    if (b->format == SILC_FMT_DENSE) {
        if (b->m > 0 && b->n > 0) memcpy(x, b->val, (size_t)(b->m * b->n * w) * sizeof(double));
    } else if (b->format == SILC_FMT_CSR) {
        memset(x, 0, (size_t)(b->m * b->n * w) * sizeof(double));
        for (i = 0; i < b->m; i++)
            for (k = b->rowptr[i]; k < b->rowptr[i + 1]; k++)
                for (int p = 0; p < w; p++) x[(i + b->colind[k] * b->m) * w + p] += b->val[k * w + p];
    } else {
        for (j = 0; j < b->n; j++)
            for (i = 0; i < b->m; i++) {
                double complex e = full_get(b, i, j, w);
                x[(i + j * b->m) * w] = creal(e);
                if (w == 2) x[(i + j * b->m) * w + 1] = cimag(e);
            }
    }
}

/* Appends "; text" (or text) to the report's note, truncating. */
static void note_add(silc_report *r, const char *fmt, ...)
{
    size_t len = strlen(r->note);
    va_list ap;
    if (len + 3 >= sizeof r->note) return;
    if (len) {
        memcpy(r->note + len, "; ", 3);
        len += 2;
    }
    va_start(ap, fmt);
    vsnprintf(r->note + len, sizeof r->note - len, fmt, ap);
    va_end(ap);
}

/* How F's estimate was made, in r's note (nothing when it has none). */
static void note_estimate(silc_report *r, const mumps_factor *F)
{
    if (F->cond_est >= 0 && F->cplx)
        note_add(r, "1-norm condition estimate: complex Hager-Higham (zmumps_c solves)");
    else if (F->cond_est >= 0)
        note_add(r, "1-norm condition estimate: block Hager-Higham (%d columns, %d steps)", EST_COLS, EST_STEPS);
}

static void fill_report(silc_report *r, const mumps_factor *F, const solve_ctx *c)
{
    int sym = (int)ID_SYM(F);
    /* SYM=2: complex symmetric, A = A.' (method is 64 bytes: kept short) */
    const char *fact = sym == 1 ? "LDL' Cholesky" : sym == 2 ? "LDL' (A = A.')" : F->cplx ? "complex LU" : "LU";
    if (F->single)
        snprintf(r->method, sizeof r->method, "%s (MUMPS single precision) + refinement",
                 sym == 1 ? "LDL'" : "LU");
    else
        snprintf(r->method, sizeof r->method, "%s (MUMPS multifrontal, SYM=%d, %s order)", fact, sym,
                 ordering_name((int)INFOG(F, 7)));
    r->cond_est = F->cond_est;
    r->rcond = -1;
    r->iterations = 0;
    r->note[0] = '\0';
    if (c->dist && F->loc_solved) /* test_mpi reads the count */
        note_add(r, "MUMPS on %d ranks: distributed assembled matrix (ICNTL(18)=3), right-hand side and "
                    "solution distributed (ICNTL(20)=10, ICNTL(21)=1), %lld entries of each column moved "
                    "to their row blocks, no condition estimate", c->size, (long long)F->plan_moved);
    else if (c->dist)
        note_add(r, "MUMPS on %d ranks: distributed assembled matrix (ICNTL(18)=3), right-hand side "
                    "and solution centralized on rank 0 (for ICNTL(10)/ICNTL(11)), no condition estimate",
                 c->size);
    if (F->single) {
        if (host->abi_minor >= 2) r->single_factor = 1;
        note_add(r, "SYM=%d, %s order", sym, ordering_name((int)INFOG(F, 7)));
    } else if (F->fallback) {
        note_add(r, "mumps.precision = single: factored in double, %s", F->fallback);
    }
    /* RINFOG(7), (8): backward errors omega1, omega2; (9): forward error
     * bound; (10), (11): condition numbers cond1, cond2 (ICNTL(11)=1 only). */
    if (F->analysed)
        note_add(r, "MUMPS error analysis (first solve): omega1 %.2g, omega2 %.2g", F->rinfog[6],
                 F->rinfog[7]);
    if (F->analysed && ICNTL(F, 11) == 1)
        note_add(r, "cond1 %.2g, cond2 %.2g, forward error bound %.2g", F->rinfog[9], F->rinfog[10],
                 F->rinfog[8]);
    note_estimate(r, F);
    if (F->opts.amalgamation != ICNTL_UNSET) /* KEEP(28): the fronts the solve phase visits */
        note_add(r, "mumps.amalgamation = %d: %d fronts", (int)F->opts.amalgamation, (int)ID_KEEP(F, 28));
    if (F->retries)
        note_add(r, "workspace raised to ICNTL(14)=%d after %d retr%s", (int)ICNTL(F, 14),
                 F->retries, F->retries == 1 ? "y" : "ies");
    if (INFOG(F, 1) > 0) note_add(r, "MUMPS warning INFOG(1)=%d", (int)INFOG(F, 1));
}

static int ends_with_spd(const char *cls)
{
    size_t n = cls ? strlen(cls) : 0;
    return n >= 4 && strcmp(cls + n - 4, ".spd") == 0;
}

/* Rows of A: the view of a distributed A shows this rank's rows only. */
static int64_t global_rows(const silc_value *v, const silc_view *view)
{
    silc_layout L;
    if (host->struct_size >= SILC_HOST_NEEDS(layout) && host->layout(v, &L)) return L.m_global;
    return view->m;
}

/* 1 when v is a complex value (0 on a host older than ABI 1.8). */
static int is_complex(const silc_value *v)
{
    return host->struct_size >= SILC_HOST_NEEDS(field) && host->field(v) == SILC_FIELD_COMPLEX;
}

/* Every rank gets the same answer: the shapes are global, and props_part
 * computes the symmetry collectively for a distributed A. */
static int solve_accepts(const silc_call *call, const char **why)
{
    silc_view a;
    if (call->nin < 2) {
        *why = "needs a right-hand side";
        return 0;
    }
    host->view(call->in[0], &a);
    if (global_rows(call->in[0], &a) != a.n) {
        *why = "needs a square matrix";
        return 0;
    }
    if (a.n > INT_MAX) {
        *why = "matrix too large for MUMPS's 32-bit indices";
        return 0;
    }
    if (is_complex(call->in[0]) && ends_with_spd(call->op_class)) {
        *why = "MUMPS has no Hermitian Cholesky (SYM=2 is complex symmetric): complex values take the general class";
        return 0;
    }
    if (is_complex(call->in[0]) && a.n > INT_MAX / 2) {
        *why = "complex matrix too large for MUMPS's 32-bit indices (2 doubles per entry)";
        return 0;
    }
    if (ends_with_spd(call->op_class) && !silc_props_of(host, call->in[0], SILC_PROPS_SYMMETRY)->symmetric) {
        *why = "SYM=1 needs a symmetric matrix";
        return 0;
    }
    return 1;
}

/* The error analysis (ICNTL(11) > 0) runs once per factorization, on its
 * first one-column solve (see the top of the file); RINFOG is kept for the
 * report. */
static int analysis_due(const mumps_factor *F, int64_t nrhs)
{
    return !F->analysed && nrhs == 1 && ICNTL(F, 11) > 0;
}

static void keep_analysis(mumps_factor *F)
{
    int k;
    F->analysed = 1;
    for (k = 0; k < 11; k++) F->rinfog[k] = F->single ? F->id.s.rinfog[k] : F->id.d.rinfog[k];
}

/* x = A \ b on whole operands, into a new X; with the condition estimate. */
static int solve_whole(silc_call *call, mumps_factor *F, const settings *s, const silc_view *b,
                       silc_value **out)
{
    silc_view o;
    silc_report *r = call->report;
    silc_value *X;
    int64_t n = b->m;
    int rc, icntl11, analyse, estimate, fold, w = ID_W(F);
    double t0, *rhs, lower = 0, x0[EST_COLS] = {0};
    *out = NULL;
    /* dense_copy, or the copy after a folded solve, writes every entry. */
    X = F->cplx ? host->dense_new_complex(b->m, b->n) : host->dense_new_uninit(b->m, b->n);
    if (!X) return host->error(call, SILC_ENOMEM, "mumps: cannot allocate the %lldx%lld solution",
                               (long long)b->m, (long long)b->n);
    host->view(X, &o);
    t0 = host->now();
    icntl11 = (int)ICNTL(F, 11);
    analyse = analysis_due(F, b->n);
    /* The first solve of a factorization carries the estimator's first block
     * along (MUMPS analyses one column only, so not with the analysis). */
    estimate = condest_wanted(call, s, F) && !condest_later(call);
    /* Owed (condest_later), the start block still rides along: a solve phase
     * costs about the same for a few more columns, A^-1 X0 gives the host a
     * lower bound of cond_1 that tells whether the estimate is urgent, and a
     * real estimate made later goes on from it (est_y0).  The complex
     * estimator takes no block: its start rides along only for the bound.
     * Once est_y0 is kept, the block is not solved again: the start block is
     * always the same, so A^-1 X0 and its bound are too, and a loop of
     * solves with one factorization would pay EST_COLS more columns in
     * every solve phase (about 1.3x the one-column solve phase on the 200^2
     * diffusion matrix, in a noisy measurement). */
    fold = condest_wanted(call, s, F) && !analyse && (!F->cplx || !estimate) && !F->est_y0 &&
           !(condest_later(call) && r->condest_later == 2); /* on_request wants no bound */
    rhs = o.val;
    if (fold && !(rhs = host->alloc((size_t)n * (size_t)(b->n + EST_COLS) * (size_t)w * sizeof *rhs))) {
        host->release(X);
        return host->error(call, SILC_ENOMEM, "mumps: out of memory for the condition estimate");
    }
    if (!analyse) ICNTL(F, 11) = 0; /* restored below, after the estimate */
    do {
        dense_copy(b, rhs, w);
        if (fold) start_block(n, w, rhs + n * b->n * w);
        if (fold) column_sums(n, w, rhs + n * b->n * w, x0); /* the solve overwrites the block */
    } while ((rc = run_solve(call, F, rhs, b->n + (fold ? EST_COLS : 0))) == SOLVE_AGAIN);
    if (!rc && analyse) keep_analysis(F);
    if (!rc && fold) memcpy(o.val, rhs, (size_t)(n * b->n * w) * sizeof *rhs);
    r->solve_seconds = host->now() - t0;
    ICNTL(F, 11) = 0; /* the estimate's solves, if any, without it */
    if (!rc && estimate)
        rc = F->cplx ? estimate_cond_complex(call, F) : estimate_cond(call, F, fold ? rhs + n * b->n : NULL);
    ICNTL(F, 11) = icntl11;
    if (!rc && fold && !estimate) {
        lower = start_bound(call, n, w, rhs + n * b->n * w, x0);
        host->free(F->est_y0);
        F->est_y0 = NULL;
        if (!F->cplx && (F->est_y0 = host->alloc((size_t)n * EST_COLS * sizeof *rhs)))
            memcpy(F->est_y0, rhs + n * b->n, (size_t)n * EST_COLS * sizeof *rhs); /* else solved again */
        F->est_lower = lower;
    } else if (!rc && !estimate && F->est_y0 && condest_wanted(call, s, F)) {
        lower = F->est_lower;
    }
    if (rhs != o.val) host->free(rhs);
    if (rc) {
        host->release(X);
        return rc;
    }
    if (condest_wanted(call, s, F) && condest_later(call)) {
        r->condest_deferred = 1;
        /* a solve phase costs about the same for 1 or 2 columns; a kept
         * start block saves one */
        r->condest_solves = EST_PHASES - (F->est_y0 ? 1 : 0);
    }
    if (!estimate && condest_wanted(call, s, F) && (fold || F->est_y0)) r->condest_lower = lower;
    *out = X;
    return SILC_OK;
}

#if SILC_MUMPS_MPI
/* x = A \ b on distributed operands, collectively, with a centralized
 * right-hand side and solution: b's blocks are gathered onto rank 0, MUMPS's
 * host (ICNTL(20)=0), all ranks take part in the solve, and the solution,
 * centralized on rank 0 (ICNTL(21)=0), is scattered back into this rank's
 * block of a new X.  One MPI_Gatherv / MPI_Scatterv per column: the blocks
 * are column-major.  Only for what MUMPS does on a centralized solution
 * alone: its error analysis (ICNTL(11)) and iterative refinement
 * (ICNTL(10)); solve_dist_loc serves every other solve. */
static int solve_dist_central(silc_call *call, solve_ctx *c, mumps_factor *F, const silc_view *b,
                              silc_value **out)
{
    /* A complex entry travels as 2 MPI_DOUBLEs: n, m, counts and offsets are in doubles. */
    int64_t w = ID_W(F), n = c->layout.m_global * w, m = c->layout.m_local * w, j;
    int *counts = NULL, *displs = NULL, rc = SILC_OK, r, icntl11 = (int)ICNTL(F, 11), analyse;
    double *rhs = NULL, t0;
    silc_value *X = host->dist_dense_new(call->in[1], b->n);
    silc_view o;
    *out = NULL;
    if (!X) {
        rc = local_error(c, SILC_ENOMEM, "mumps: cannot allocate this rank's %lldx%lld block of the solution",
                         (long long)c->layout.m_local, (long long)b->n);
    } else if (F->cplx && !is_complex(X)) {
        /* ABI 1.8 makes a distributed result of like's field (silc_plugin.h) */
        rc = local_error(c, SILC_EUNSUP, "mumps: the host made a real distributed result for a complex solve");
    } else if (c->rank == 0) {
        rhs = host->alloc((size_t)n * (size_t)b->n * sizeof *rhs);
        counts = host->alloc((size_t)c->size * sizeof *counts);
        displs = host->alloc((size_t)c->size * sizeof *displs);
        if (!rhs || !counts || !displs)
            rc = local_error(c, SILC_ENOMEM, "mumps: out of memory for the %lldx%lld right-hand side on rank 0",
                             (long long)c->layout.m_global, (long long)b->n);
        else
            for (r = 0; r < c->size; r++) { /* w n <= INT_MAX (solve_accepts) */
                counts[r] = (int)((c->layout.starts[r + 1] - c->layout.starts[r]) * w);
                displs[r] = (int)(c->layout.starts[r] * w);
            }
    }
    if ((rc = agree(call, c, rc))) goto done;
    host->view(X, &o);
    t0 = host->now();
    analyse = analysis_due(F, b->n);
    if (!analyse) ICNTL(F, 11) = 0;
    do {
        rc = SILC_OK; /* SOLVE_AGAIN: refill */
        for (j = 0; j < b->n && !rc; j++)
            if (MPI_Gatherv(m ? b->val + j * m : b->val, (int)m, MPI_DOUBLE, rhs ? rhs + j * n : NULL,
                            counts, displs, MPI_DOUBLE, 0, c->comm) != MPI_SUCCESS)
                rc = local_error(c, SILC_ELIB, "mumps: MPI_Gatherv of the right-hand side failed");
        if ((rc = agree(call, c, rc))) break;
    } while ((rc = run_solve(call, F, rhs, b->n)) == SOLVE_AGAIN);
    ICNTL(F, 11) = icntl11;
    if (rc) goto done;
    if (analyse) keep_analysis(F);
    for (j = 0; j < b->n && !rc; j++)
        if (MPI_Scatterv(rhs ? rhs + j * n : NULL, counts, displs, MPI_DOUBLE, m ? o.val + j * m : o.val,
                         (int)m, MPI_DOUBLE, 0, c->comm) != MPI_SUCCESS)
            rc = local_error(c, SILC_ELIB, "mumps: MPI_Scatterv of the solution failed");
    rc = agree(call, c, rc);
    call->report->solve_seconds = host->now() - t0;
done:
    host->free(rhs);
    host->free(counts);
    host->free(displs);
    if (rc && X) host->release(X);
    if (!rc) *out = X;
    return rc;
}

/* The rank whose row block holds global row g (the starts are sorted). */
static int row_owner(const solve_ctx *c, int64_t g)
{
    int lo = 0, hi = c->size - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (c->layout.starts[mid] <= g) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

/* The plan that moves the solution from MUMPS's mapping (isol_loc, which
 * the factorization fixes) to the row blocks: what this rank sends to each
 * rank (positions in sol_loc) and, from one MPI_Alltoallv of the indices,
 * which local row each arriving entry is.  Collective; made again only
 * when some rank's isol_loc changed (a refactorization).  Returns the
 * bytes of indices it moved, summed over the ranks, or -1 (local). */
static int64_t plan_solution(solve_ctx *c, mumps_factor *F)
{
    int size = c->size, r, *sd = NULL, *rd = NULL, *fill = NULL;
    int64_t i, nsend = 0, nrecv = 0, moved[2] = {0, 0};
    MUMPS_INT *gsend = NULL, *grecv = NULL;
    int failed = 0;
    host->free(F->send_n), host->free(F->send_at), host->free(F->recv_row);
    F->send_n = F->recv_n = NULL;
    F->send_at = F->recv_row = NULL;
    F->send_n = host->calloc((size_t)size * 2, sizeof *F->send_n);
    sd = host->calloc((size_t)size * 3, sizeof *sd);
    if (!F->send_n || !sd) failed = 1;
    else {
        F->recv_n = F->send_n + size;
        rd = sd + size;
        fill = rd + size;
        for (i = 0; i < F->lsol_loc; i++) F->send_n[row_owner(c, F->isol_loc[i] - 1)]++;
    }
    if (!all_ranks(c, !failed)) goto fail;
    if (MPI_Alltoall(F->send_n, 1, MPI_INT, F->recv_n, 1, MPI_INT, c->comm) != MPI_SUCCESS) goto fail;
    for (r = 0; r < size; r++) {
        sd[r] = (int)nsend, rd[r] = (int)nrecv;
        nsend += F->send_n[r], nrecv += F->recv_n[r];
        if (r != c->rank) moved[0] += F->recv_n[r];
    }
    F->send_at = host->alloc((size_t)(nsend ? nsend : 1) * sizeof *F->send_at);
    F->recv_row = host->alloc((size_t)(nrecv ? nrecv : 1) * sizeof *F->recv_row);
    gsend = host->alloc((size_t)(nsend ? nsend : 1) * sizeof *gsend);
    grecv = host->alloc((size_t)(nrecv ? nrecv : 1) * sizeof *grecv);
    if (!all_ranks(c, F->send_at && F->recv_row && gsend && grecv)) goto fail;
    for (i = 0; i < F->lsol_loc; i++) {
        r = row_owner(c, F->isol_loc[i] - 1);
        F->send_at[sd[r] + fill[r]] = i;
        gsend[sd[r] + fill[r]++] = F->isol_loc[i];
    }
    if (MPI_Alltoallv(gsend, F->send_n, sd, MPI_INT, grecv, F->recv_n, rd, MPI_INT, c->comm) != MPI_SUCCESS)
        goto fail;
    for (i = 0; i < nrecv; i++) F->recv_row[i] = grecv[i] - 1 - c->layout.first_row;
    moved[1] = moved[0] * (int64_t)sizeof(MUMPS_INT);
    if (MPI_Allreduce(MPI_IN_PLACE, moved, 2, MPI_INT64_T, MPI_SUM, c->comm) != MPI_SUCCESS) goto fail;
    F->plan_moved = moved[0];
    host->free(gsend), host->free(grecv), host->free(sd);
    return moved[1];
fail:
    host->free(gsend), host->free(grecv), host->free(sd);
    host->free(F->send_n), host->free(F->send_at), host->free(F->recv_row);
    F->send_n = F->recv_n = NULL;
    F->send_at = F->recv_row = NULL;
    return -1;
}

/* Room for INFO(23) x nrhs entries of the distributed solution and its
 * indices, and this rank's rows of b as 1-based indices; 0 or -1 (local). */
static int loc_arrays(solve_ctx *c, mumps_factor *F, int64_t nrhs)
{
    int64_t lsol = F->cplx ? F->id.z.info[22] : F->id.d.info[22], w = ID_W(F), i, m = c->layout.m_local;
    if (!F->irhs_loc) {
        if (!(F->irhs_loc = host->alloc((size_t)(m ? m : 1) * sizeof *F->irhs_loc))) return -1;
        for (i = 0; i < m; i++) F->irhs_loc[i] = (MUMPS_INT)(c->layout.first_row + i + 1);
    }
    if (lsol != F->lsol_loc || !F->isol_loc) {
        host->free(F->isol_loc);
        host->free(F->isol_plan);
        F->isol_plan = NULL; /* a plan for another size is no plan */
        F->lsol_loc = lsol;
        F->isol_loc = host->calloc((size_t)(lsol ? lsol : 1), sizeof *F->isol_loc);
        if (!F->isol_loc) return -1;
    }
    if (lsol * nrhs * w > F->sol_cap) {
        host->free(F->sol_loc);
        F->sol_cap = 0;
        if (!(F->sol_loc = host->alloc((size_t)(lsol * nrhs * w > 0 ? lsol * nrhs * w : 1) * sizeof *F->sol_loc)))
            return -1;
        F->sol_cap = lsol * nrhs * w;
    }
    return 0;
}

/* x = A \ b on distributed operands, collectively, nothing gathered: each
 * rank hands MUMPS its own rows of b (ICNTL(20)=10: IRHS_loc, RHS_loc,
 * Nloc_RHS, LRHS_loc) and gets back the part of x that MUMPS's own mapping
 * leaves on it (ICNTL(21)=1: ISOL_loc, SOL_loc, LSOL_loc = INFO(23)), which
 * one MPI_Alltoallv of all columns moves into this rank's rows of a new X
 * (plan_solution).  The entries that change rank are counted
 * (host->dist_moved); MUMPS's own messages are not. */
static int solve_dist_loc(silc_call *call, solve_ctx *c, mumps_factor *F, const silc_view *b,
                          silc_value **out)
{
    int64_t w = ID_W(F), m = c->layout.m_local, nrhs = b->n, i, j, k, t, at, nsend = 0, nrecv = 0, moved = 0;
    int rc = SILC_OK, r, size = c->size, *sc = NULL, *sd = NULL, *rcv = NULL, *rd = NULL, changed;
    double *rhs = NULL, *send = NULL, *recv = NULL, t0;
    silc_value *X = host->dist_dense_new(call->in[1], nrhs);
    silc_view o;
    *out = NULL;
    if (!X) {
        rc = local_error(c, SILC_ENOMEM, "mumps: cannot allocate this rank's %lldx%lld block of the solution",
                         (long long)m, (long long)nrhs);
    } else if (F->cplx && !is_complex(X)) {
        /* ABI 1.8 makes a distributed result of like's field (silc_plugin.h) */
        rc = local_error(c, SILC_EUNSUP, "mumps: the host made a real distributed result for a complex solve");
    } else if (!(rhs = host->alloc((size_t)(m * nrhs * w > 0 ? m * nrhs * w : 1) * sizeof *rhs))) {
        rc = local_error(c, SILC_ENOMEM, "mumps: out of memory for this rank's %lld rows of the right-hand side",
                         (long long)m);
    }
    if ((rc = agree(call, c, rc))) goto done;
    host->view(X, &o);
    t0 = host->now();
    ICNTL(F, 20) = 10; /* distributed dense right-hand side */
    ICNTL(F, 21) = 1;  /* distributed solution */
    do { /* b's rows and the solution's room, again after a refactorization (SOLVE_AGAIN) */
        rc = SILC_OK;
        if (loc_arrays(c, F, nrhs))
            rc = local_error(c, SILC_ENOMEM, "mumps: out of memory for this rank's part of the solution");
        else if ((F->lsol_loc + m) * nrhs * w > INT_MAX)
            rc = local_error(c, SILC_EARG, "mumps: %lld right-hand sides of %lld local rows exceed MPI's int "
                                           "counts", (long long)nrhs, (long long)m);
        if ((rc = agree(call, c, rc))) break;
        ID_SET(F, nloc_rhs, (MUMPS_INT)m);
        ID_SET(F, lrhs_loc, (MUMPS_INT)(m ? m : 1));
        ID_SET(F, irhs_loc, F->irhs_loc);
        ID_SET(F, isol_loc, F->isol_loc);
        ID_SET(F, lsol_loc, (MUMPS_INT)F->lsol_loc);
        if (F->cplx) {
            F->id.z.rhs_loc = (ZMUMPS_COMPLEX *)rhs;
            F->id.z.sol_loc = (ZMUMPS_COMPLEX *)F->sol_loc;
        } else {
            F->id.d.rhs_loc = rhs;
            F->id.d.sol_loc = F->sol_loc;
        }
        memcpy(rhs, b->val, (size_t)(m * nrhs * w) * sizeof *rhs);
    } while ((rc = run_solve(call, F, NULL, nrhs)) == SOLVE_AGAIN);
    ICNTL(F, 20) = 0;
    ICNTL(F, 21) = 0;
    if (rc) goto done;
    /* The plan, made once per factorization: every rank asks whether any
     * rank's isol_loc differs from the one its plan was made for. */
    changed = !F->isol_plan || memcmp(F->isol_plan, F->isol_loc, (size_t)F->lsol_loc * sizeof *F->isol_loc);
    if (!all_ranks(c, !changed)) {
        int64_t idx = plan_solution(c, F);
        host->free(F->isol_plan);
        F->isol_plan = idx < 0 ? NULL : host->alloc((size_t)(F->lsol_loc ? F->lsol_loc : 1) * sizeof *F->isol_plan);
        if (F->isol_plan) memcpy(F->isol_plan, F->isol_loc, (size_t)F->lsol_loc * sizeof *F->isol_loc);
        rc = idx < 0 || !F->isol_plan ? local_error(c, SILC_ENOMEM, "mumps: out of memory planning the solution's "
                                                                    "redistribution")
                                      : SILC_OK;
        if ((rc = agree(call, c, rc))) goto done;
        moved += idx;
    }
    /* All columns in one MPI_Alltoallv: to each rank its entries, column by column. */
    sc = host->alloc((size_t)size * 4 * sizeof *sc);
    if (sc) {
        sd = sc + size, rcv = sd + size, rd = rcv + size;
        for (r = 0; r < size; r++) {
            sc[r] = (int)(F->send_n[r] * nrhs * w), rcv[r] = (int)(F->recv_n[r] * nrhs * w);
            sd[r] = (int)nsend, rd[r] = (int)nrecv;
            nsend += sc[r], nrecv += rcv[r];
        }
        send = host->alloc((size_t)(nsend ? nsend : 1) * sizeof *send);
        recv = host->alloc((size_t)(nrecv ? nrecv : 1) * sizeof *recv);
    }
    if ((rc = agree(call, c, sc && send && recv ? SILC_OK
                                                 : local_error(c, SILC_ENOMEM, "mumps: out of memory moving the solution"))))
        goto done;
    /* send_at and recv_row are grouped by rank as the counts; at: the rank's first */
    for (k = 0, at = 0, r = 0; r < size; at += F->send_n[r++])
        for (j = 0; j < nrhs; j++)
            for (i = 0; i < F->send_n[r]; i++)
                for (t = 0; t < w; t++) send[k++] = F->sol_loc[(F->send_at[at + i] + j * F->lsol_loc) * w + t];
    if (MPI_Alltoallv(send, sc, sd, MPI_DOUBLE, recv, rcv, rd, MPI_DOUBLE, c->comm) != MPI_SUCCESS)
        rc = local_error(c, SILC_ELIB, "mumps: MPI_Alltoallv of the solution failed");
    if ((rc = agree(call, c, rc))) goto done;
    for (k = 0, at = 0, r = 0; r < size; at += F->recv_n[r++])
        for (j = 0; j < nrhs; j++)
            for (i = 0; i < F->recv_n[r]; i++)
                for (t = 0; t < w; t++) o.val[(F->recv_row[at + i] + j * m) * w + t] = recv[k++];
    moved += F->plan_moved * nrhs * w * (int64_t)sizeof(double);
    F->loc_solved = 1;
    if (host->struct_size >= SILC_HOST_NEEDS(dist_moved)) host->dist_moved(call, 0, (uint64_t)moved);
    call->report->solve_seconds = host->now() - t0;
done:
    if (F->cplx) F->id.z.rhs_loc = NULL, F->id.z.sol_loc = NULL;
    else F->id.d.rhs_loc = NULL, F->id.d.sol_loc = NULL;
    host->free(rhs);
    host->free(send);
    host->free(recv);
    host->free(sc);
    if (rc && X) host->release(X);
    if (!rc) *out = X;
    return rc;
}

/* The distributed solve: right-hand side and solution distributed
 * (solve_dist_loc), unless the options ask for what MUMPS does only on a
 * centralized solution (solve_dist_central).  Every rank decides alike:
 * the options and the factorization's state are the same on all. */
static int solve_dist(silc_call *call, solve_ctx *c, mumps_factor *F, const silc_view *b,
                      silc_value **out)
{
    F->loc_solved = 0;
    if (analysis_due(F, b->n) || ICNTL(F, 10) > 0) return solve_dist_central(call, c, F, b, out);
    return solve_dist_loc(call, c, F, b, out);
}
#endif

/* A collective call's operands as solve_dist expects them, checked on this
 * rank (the answers could differ between ranks only if the host erred, but a
 * rank must not stop alone): A in CSR rows matching its layout, B dense with
 * the same row blocks. */
static int check_dist(silc_call *call, solve_ctx *c, const silc_view *a, const silc_view *b)
{
    silc_layout Lb;
    int rc = SILC_OK;
    if (a->format != SILC_FMT_CSR || a->m != c->layout.m_local)
        rc = local_error(c, SILC_EARG, "mumps: a distributed A must be CSR rows (%lld local rows, layout %lld)",
                         (long long)a->m, (long long)c->layout.m_local);
    else if (!host->layout(call->in[1], &Lb) || Lb.first_row != c->layout.first_row ||
             Lb.m_local != c->layout.m_local || Lb.m_global != c->layout.m_global)
        rc = local_error(c, SILC_EARG, "mumps: the right-hand side is not distributed like A's rows");
    else if (b->format != SILC_FMT_DENSE || b->m != Lb.m_local)
        rc = local_error(c, SILC_EARG, "mumps: a distributed right-hand side must be dense");
    return agree(call, c, rc);
}

static int solve_run(silc_call *call)
{
    silc_view a, b;
    silc_report *r = call->report;
    settings s;
    solve_ctx c;
    mumps_factor *F;
    silc_value *X = NULL;
    int sym = ends_with_spd(call->op_class) ? 1 : 0, rc, attach_rc, cplx = is_complex(call->in[0]);
    const char *key;
    const char *why = NULL;
    if ((rc = ctx_open(call, &c))) return rc;
    if (!solve_accepts(call, &why)) return host->error(call, SILC_EDECLINE, "%s", why);
    if ((rc = read_settings(call, &s))) return rc;
    if (c.dist && s.single)
        return host->error(call, SILC_EUNSUP,
                           "mumps: mumps.precision = single is not supported on distributed operands");
    if (cplx != is_complex(call->in[1]))
        return host->error(call, SILC_EARG, "mumps: A and b of different fields (real and complex)");
    /* SYM=2: complex symmetric (A = A.'), on the lower triangle. */
    if (cplx && silc_props_of(host, call->in[0], SILC_PROPS_SYMMETRY)->symmetric) sym = 2;
    /* Both precisions' factorizations can live on A at once. */
    key = sym == 2 ? "mumps.zsym" : sym ? (s.single ? "mumps.ldlt.single" : "mumps.ldlt")
              : (s.single ? "mumps.lu.single" : "mumps.lu");
    host->view(call->in[0], &a);
    host->view(call->in[1], &b);
    if (c.dist) {
        if ((rc = check_dist(call, &c, &a, &b))) return rc;
    } else if (b.m != a.n) {
        return host->error(call, SILC_EARG, "mumps: right-hand side has %lld rows, A has %lld",
                           (long long)b.m, (long long)a.n);
    }
    if (b.n > INT_MAX)
        return host->error(call, SILC_EARG, "mumps: too many right-hand sides (%lld)",
                           (long long)b.n);
    if (a.n == 0 || b.n == 0) { /* nothing to factor or solve; MUMPS refuses N=0 */
        call->out = c.dist ? host->dist_dense_new(call->in[1], b.n)
                    : cplx     ? host->dense_new_complex(b.m, b.n)
                               : host->dense_new(b.m, b.n);
        rc = agree(call, &c, call->out ? SILC_OK : local_error(&c, SILC_ENOMEM, "mumps: out of memory"));
        if (rc && call->out) {
            host->release(call->out);
            call->out = NULL;
        }
        return rc;
    }
    F = host->attach_get(call->in[0], key);
    if (host->abi_minor >= 8 && r->condest_only) { /* the estimate alone, owed by an earlier solve */
        int icntl11;
        if (c.dist || !F || !F->live || !same_settings(&F->opts, &s))
            return host->error(call, SILC_EDECLINE, "mumps: no factorization attached to A for the condition estimate");
        icntl11 = (int)ICNTL(F, 11);
        ICNTL(F, 11) = 0; /* the error analysis would run on every one of the estimate's solves */
        rc = !condest_wanted(call, &s, F) ? SILC_OK : F->cplx ? estimate_cond_complex(call, F) : estimate_cond(call, F, NULL);
        ICNTL(F, 11) = icntl11;
        r->cond_est = F->cond_est;
        note_estimate(r, F); /* the note says how the estimate was made, and only that */
        return rc;
    }
    if (all_ranks(&c, F && F->live && same_settings(&F->opts, &s))) {
        r->reused_factor = 1;
    } else {
        /* An instance with other settings goes first (JOB=-2 is collective:
         * the attachments are alike on every rank); A keeps the dead F
         * until the new one replaces it. */
        if (F) factor_end(F);
        if ((rc = factor_new(call, &c, &a, sym, cplx, &s, &F))) return rc;
        attach_rc = host->attach_set(call->in[0], key, F, factor_free)
                        ? local_error(&c, SILC_ENOMEM, "mumps: cannot attach the factorization")
                        : SILC_OK;
        if ((rc = agree(call, &c, attach_rc))) {
            /* Where F was attached, A keeps it ended, with the other ranks. */
            if (attach_rc)
                factor_free(F);
            else
                factor_end(F);
            return rc;
        }
        r->factor_seconds = F->factor_seconds;
    }
#if SILC_MUMPS_MPI
    if (c.dist)
        rc = solve_dist(call, &c, F, &b, &X);
    else
#endif
        rc = solve_whole(call, F, &s, &b, &X);
    if (rc) return rc;
    fill_report(r, F, &c);
    call->out = X;
    return SILC_OK;
}

/* ---- tables ----------------------------------------------------------------------- */

static const silc_op_entry mumps_ops[SILC_OP_COUNT] = {
    [SILC_OP_SOLVE] = {solve_run, solve_accepts},
};

#if SILC_MUMPS_MPI
#define MUMPS_BUILD "MPI"
#define MUMPS_BUILD_MORE "; SOLVE collective on row-distributed operands"
/* SOLVE runs collectively on distributed operands (ABI 1.5). */
static const uint32_t mumps_collective[] = {SILC_COLLECTIVE(SILC_OP_SOLVE)};
#define MUMPS_COLLECTIVE mumps_collective
#define MUMPS_HOST_NEEDS SILC_HOST_NEEDS(dist_dense_new)
#else
#define MUMPS_BUILD "sequential"
#define MUMPS_BUILD_MORE ""
#define MUMPS_COLLECTIVE NULL
#define MUMPS_HOST_NEEDS SILC_HOST_NEEDS(dense_new_uninit)
#endif

static const silc_backend mumps_backends[] = {
    {NULL, "MUMPS " MUMPS_VERSION " " MUMPS_BUILD " multifrontal LU / LDL' (AMF order" MUMPS_BUILD_MORE ")",
     SILC_OP_COUNT,
     mumps_ops},
};

/* SOLVE takes complex operands (zmumps_c), whole or distributed. */
static const uint32_t mumps_complex_ops[] = {SILC_COMPLEX_OPS(SILC_OP_SOLVE)};

static silc_plugin mumps_plugin = {
    SILC_ABI_MAJOR, SILC_ABI_MINOR, sizeof(silc_plugin), (int)sizeof(silc_index),
    "mumps", "1.0 MUMPS " MUMPS_VERSION,
    1, mumps_backends,
    (int)(sizeof mumps_options / sizeof mumps_options[0]), mumps_options,
    NULL, /* set_threads: blas_threads_attach fills it when OpenBLAS is found */
    NULL,
    MUMPS_COLLECTIVE,
    mumps_complex_ops,
};

SILC_PLUGIN_EXPORT int silc_plugin_init(const silc_host_api *h, const silc_plugin **out,
                                        const char **errmsg)
{
    /* The MPI build calls host->comm, layout and dist_dense_new (ABI 1.5). */
    if (silc_host_check(h, MUMPS_HOST_NEEDS, errmsg) || !out) return 1;
    host = h;
    blas_threads_attach(&mumps_plugin); /* threaded only through its BLAS */
    *out = &mumps_plugin;
    return 0;
}
