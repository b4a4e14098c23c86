/*
 * silc_plugin.h -- the SILC plugin ABI: the only header a backend plugin includes.
 *
 * A plugin is a shared object exporting one symbol, silc_plugin_init().  The
 * host passes it a table of services (silc_host_api: allocator, errors, options,
 * value constructors and accessors, attachments, timers) so the plugin never
 * links against libsilc; the plugin answers with a silc_plugin table naming its
 * backends, each with an ops table indexed by SILC_OP_*.  Both tables start with
 * abi_major / abi_minor / struct_size / index_bytes and only ever grow at the
 * end (as SQLite's versioned vtables do), so an older plugin keeps working with
 * a newer host.  A wrong major version or index width is refused by the loader.
 *
 * Rules (see plugins/README.md): no longjmp, exit or abort across the boundary;
 * every failure returns a SILC_E* status after calling host->error() with a
 * message that names the failing library call and its native code; numeric
 * outcomes (singular, not positive definite, not converged) are statuses, never
 * crashes.  Input values are immutable: read them through host->view(); a new
 * value is created by host->*_new(), filled through its view, and handed back in
 * call->out, after which the host owns it.
 */
#ifndef SILC_PLUGIN_H
#define SILC_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SILC_ABI_MAJOR 1
#define SILC_ABI_MINOR 10

/* Index type of CSR arrays.  Its width is part of the ABI (index_bytes). */
typedef int64_t silc_index;

#if defined(_WIN32)
#define SILC_PLUGIN_EXPORT __declspec(dllexport)
#else
#define SILC_PLUGIN_EXPORT __attribute__((visibility("default")))
#endif

/* ---- statuses (0 = ok) ---------------------------------------------------- */
enum silc_status {
    SILC_OK = 0,
    SILC_EARG = 1,        /* operands wrong for this operation (shape, format) */
    SILC_ENOMEM = 2,      /* allocation failed */
    SILC_ESINGULAR = 3,   /* matrix exactly singular (zero pivot) */
    SILC_ENOTSPD = 4,     /* Cholesky found a non-positive pivot: dispatcher falls back to LU */
    SILC_ENOTCONV = 5,    /* iterative method hit its iteration limit */
    SILC_EBREAKDOWN = 6,  /* iterative method broke down (division by ~0, NaN) */
    SILC_EDECLINE = 7,    /* plugin declines after all (e.g. structure test failed late): try next */
    SILC_ELIB = 8,        /* third-party library failure */
    SILC_EUNSUP = 9,      /* operation or option not supported */
    SILC_EINTERNAL = 10
};

/* ---- values ---------------------------------------------------------------- */

/* ABI 1.8: a value's field, real or complex.  A complex value stores each
 * entry as two doubles, the real part then the imaginary part (interleaved:
 * the layout of LAPACK's complex*16, C99's double complex, UMFPACK's and
 * KLU's packed complex arrays (Az = NULL), ZMUMPS_COMPLEX, NumPy's
 * complex128 and MPI_C_DOUBLE_COMPLEX).  Its view's val then holds 2 doubles
 * per entry (dense 2*m*n, csr 2*nnz, band 2*ld*n); every count in the view
 * (nnz, ld) still counts entries.  The host hands a complex operand only to
 * an op its backend lists in silc_plugin.complex_ops (never to a plugin older
 * than ABI 1.8), and never mixes fields in one call: where an operation
 * mixes a real and a complex operand, the host promotes the real one first
 * (or splits the call: a real A solved against a complex b is two real
 * solves sharing A's factorization).  host->field() tells a value's field. */
enum silc_field { SILC_FIELD_REAL = 0, SILC_FIELD_COMPLEX = 1 };
typedef struct silc_value silc_value; /* opaque, owned by the host */

enum silc_format {
    SILC_FMT_DENSE = 0, /* column-major, leading dimension m */
    SILC_FMT_CSR = 1,   /* rowptr[m+1], colind[nnz] sorted ascending per row, 0-based; explicit zeros allowed */
    SILC_FMT_BAND = 2   /* LAPACK general band storage: ld = kl+ku+1, A(i,j) = val[(ku+i-j) + j*ld] */
};

/* A borrowed view of a value's arrays.  For inputs, treat every array as const.
 * For a value the plugin just created (not yet returned), the arrays are writable. */
typedef struct silc_view {
    int64_t m, n;
    int format;             /* enum silc_format */
    double *val;            /* dense: m*n; csr: nnz; band: ld*n */
    silc_index *rowptr;     /* csr only */
    silc_index *colind;     /* csr only */
    int64_t nnz;            /* csr: stored entries; dense: m*n; band: ld*n */
    int64_t kl, ku, ld;     /* band only (ld = kl+ku+1) */
} silc_view;

/* Structural properties, computed by the host on first use and cached, in
 * three parts that cost different passes over the entries (ABI 1.4's
 * props_part asks for some of them; props asks for all):
 *   SILC_PROPS_SHAPE     every field but symmetric and the norms (one pass
 *                        over the values, two reads per row of the indices);
 *   SILC_PROPS_SYMMETRY  symmetric (a walk that visits each entry's mirror);
 *   SILC_PROPS_NORMS     norm1, norminf, normfro, maxabs (a pass with a
 *                        column-sum scatter).
 * A field outside the parts asked for holds whatever was there before. */
enum { SILC_PROPS_SHAPE = 1, SILC_PROPS_SYMMETRY = 2, SILC_PROPS_NORMS = 4, SILC_PROPS_ALL = 7 };
typedef struct silc_props {
    int square;
    int symmetric;          /* exactly symmetric values (pattern and value) */
    int pos_diag;           /* every diagonal entry > 0 (square only) */
    int diagonal;           /* no off-diagonal nonzero */
    int lower, upper;       /* lower / upper triangular (diagonal counts as both) */
    int64_t kl, ku;         /* lower / upper bandwidth of the nonzeros */
    int64_t nnz;            /* numerically nonzero entries */
    int has_nonfinite;      /* a NaN or Inf is stored */
    double norm1, norminf, normfro, maxabs; /* computed with scaling: no overflow */
    /* ABI 1.8 (SILC_PROPS_SYMMETRY part).  For a complex value, symmetric
     * means A = A.' (complex symmetric: the matrices COCG and LDL^T take) and
     * hermitian means A = A' (conjugate transpose: what Cholesky takes);
     * pos_diag means every diagonal entry is real and > 0.  For a real
     * value hermitian equals symmetric.  The norms use the modulus. */
    int hermitian;
} silc_props;

/* ---- operations ------------------------------------------------------------ */
/* Ops are numbered for ever; new ones are appended.  in[] are the operands; shapes
 * have been checked by the host, except where noted.  A 1x1 operand of ADD and
 * EWISE broadcasts against the other operand. */
enum silc_op {
    SILC_OP_ADD = 0,       /* out = alpha*in[0] + beta*in[1]                                  */
    SILC_OP_SCALE = 1,     /* out = alpha*in[0]                                               */
    SILC_OP_MATMUL = 2,    /* out = in[0] * in[1] (neither is 1x1: host turns that into SCALE) */
    SILC_OP_EWISE = 3,     /* out = in[0] (sub) in[1] element-wise; sub = enum silc_ewise     */
    SILC_OP_MAP = 4,       /* out = f(in[0]) element-wise; sub = enum silc_map                */
    SILC_OP_TRANSPOSE = 5, /* out = in[0]' (ABI 1.8, complex: sub 0 conjugate transpose ',
                              sub 1 plain transpose .'; the same for real values)           */
    SILC_OP_SOLVE = 6,     /* out = in[0] \ in[1]; fills call->report; options in call->options;
                              ABI 1.6: nin = 3 gives in[2], an initial guess (dense, the
                              solution's shape) an iterative method may start from (warm
                              start; it then sets report->initial_guess); others ignore it */
    SILC_OP_REDUCE = 7,    /* sub = enum silc_reduce; see there                               */
    SILC_OP_CONVERT = 8,   /* out = in[0] stored as format sub (band: kl = ival[0], ku = ival[1]) */
    SILC_OP_DIAG = 9,      /* sub 0: diag(v) -> CSR diagonal matrix; sub 1: diagvec(A) -> column */
    SILC_OP_COUNT = 10
};

enum silc_ewise {
    SILC_EW_MUL = 0, SILC_EW_DIV, SILC_EW_POW, SILC_EW_MAX, SILC_EW_MIN,
    SILC_EW_EQ, SILC_EW_NE, SILC_EW_LT, SILC_EW_LE, SILC_EW_GT, SILC_EW_GE,
    SILC_EW_AND, SILC_EW_OR  /* comparisons and logic give 1.0 / 0.0 */
};

enum silc_map {
    SILC_MAP_NEG = 0, SILC_MAP_ABS, SILC_MAP_SQRT, SILC_MAP_EXP, SILC_MAP_LOG,
    SILC_MAP_SIN, SILC_MAP_COS, SILC_MAP_NOT,
    /* ABI 1.8, for complex values (a real operand is handled too: real and
     * conj copy it, imag gives zeros, angle 0 or pi).  REAL, IMAG, ABS and
     * ANGLE give a real result; the others keep the operand's field.  SQRT
     * and LOG of a complex value take the principal branch (C99 csqrt, clog);
     * a real operand stays real (the host promotes a real operand with
     * negative entries to complex first, as Octave does). */
    SILC_MAP_REAL, SILC_MAP_IMAG, SILC_MAP_CONJ, SILC_MAP_ANGLE
};

/* REDUCE: for a vector (m==1 or n==1) the result is 1x1; for a matrix it is the
 * 1xn row of per-column results (as MATLAB), except NORM, NORM1, NORMINF,
 * NORMFRO and DOT, which always give 1x1.  NORM of a vector is the 2-norm, of a
 * matrix the 2-norm (largest singular value).  DOT takes in[0], in[1] of the
 * same shape and returns sum(in0 .* in1).  ABI 1.8, complex: SUM and DOT give a
 * complex result (DOT conjugates nothing: the language's dot() conjugates its
 * first operand before asking, as Octave's does); MAX and MIN compare by
 * modulus and return the entry (ties: the larger angle, Octave's rule); the
 * norms use the modulus and are real. */
enum silc_reduce {
    SILC_RED_SUM = 0, SILC_RED_MAX, SILC_RED_MIN, SILC_RED_DOT,
    SILC_RED_NORM, SILC_RED_NORM1, SILC_RED_NORMINF, SILC_RED_NORMFRO
};

/* What a solver tells about its result.  The host fills backend, wall time and the
 * backward error itself; a plugin fills what it knows and leaves the rest alone
 * (the host zeroes the report and sets cond_est = -1 before the call).
 * cond_est must be an estimate of cond_1(A) = ||A||_1 ||A^-1||_1 that can be
 * trusted to a small factor (Hager-Higham through the backend's own
 * factorization: inv_norm1_est / inv_norm1_est_block), or -1: the host turns
 * it into a forward-error bound.  A library's cheap pivot ratio is not such an
 * estimate (it can be 200x low: UMFPACK's for the 40 x 40 1-D Laplacian is
 * 5.07, cond_1 840); it goes in pivot_ratio (ABI 1.7).  An iterative method that makes no
 * extra solves leaves cond_est at -1 ("not estimated"). */
typedef struct silc_report {
    char method[64];        /* e.g. "LU (partial pivoting, COLAMD order)" */
    double cond_est;        /* 1-norm condition estimate, -1 = unknown */
    double rcond;           /* reciprocal condition estimate as the library reports it, -1 = unknown */
    int64_t iterations;     /* iterative solvers; 0 for direct */
    double resid;           /* final relative residual of an iterative solver */
    int reused_factor;      /* 1 if an attached factorization was reused */
    double factor_seconds, solve_seconds;
    char note[256];         /* anything else worth showing in `info` */
    /* host-filled */
    char backend[64];
    double seconds;
    double backward_error;
    /* ABI 1.2 (write these only when host->abi_minor >= 2) */
    int single_factor;      /* plugin: x comes from a single-precision factorization; the core
                               refines it in double (solve.refine, default 10 steps for these) */
    int refine_steps;       /* host: iterative-refinement steps the core kept */
    double backward_error_unrefined; /* host: backward error before refinement, -1 = none ran */
    /* ABI 1.6 */
    int initial_guess;      /* plugin: 1 when it started from the initial guess in[2] */
    double tol;             /* plugin: an iterative method's stopping tolerance on the relative
                               residual (the host verifies the result against it), 0 if none */
    char attempts[512];     /* host: the backends of the list that failed before this one */
    /* ABI 1.7 (read or write these only when host->abi_minor >= 7) */
    int condest_off;        /* host, set before the call: 1 when accuracy.condest = off: make no
                               condition estimate (the host discards cond_est then anyway) */
    double pivot_ratio;     /* plugin: a library's cheap max/min ratio of the factor's diagonal
                               (UMFPACK's, KLU's, CHOLMOD's 1/rcond), shown labelled as such;
                               not a bound, never used for one; 0 = none */
    double forward_bound;   /* host: est ||A^-1||_1 * max_j ||b_j - A x_j||_1 / ||x_j||_1, the
                               residual bound on the relative forward error with the
                               estimate in place of ||A^-1||_1; -1 = none */
    /* ABI 1.8: the condition estimate made when the report is read, where it
     * costs too much next to the factorization (docs/accuracy.md).  Read or
     * write these only when host->abi_minor >= 8. */
    int condest_later;      /* host, set before the call: make no estimate that costs solves of
                               its own in this call; say instead that it is owed
                               (condest_deferred = 1) and what it costs (condest_solves).
                               1: with condest_lower where the plugin has one (auto); 2: no
                               lower bound is wanted either (accuracy.condest = on_request,
                               whose estimate is never made at once: a bound would be solves
                               spent for nothing).  A plugin that knows only "nonzero"
                               treats 2 as 1, which costs only the bound. */
    int condest_only;       /* host, set before the call: make only the estimate, with the
                               factorization an earlier call attached to in[0] (same options and
                               class); solve nothing (out stays NULL), factor nothing: with no
                               factorization attached return SILC_EDECLINE */
    int condest_deferred;   /* plugin: 1 = the estimate is owed (condest_later); host: 2 = made
                               when the report was read, 3 = could not be made then */
    double condest_solves;  /* plugin: the estimate's cost in solves like this call's (column
                               solves over this call's columns, or solve phases) */
    double condest_lower;   /* plugin, with condest_deferred: a lower bound of cond_1(A) it got for
                               next to nothing (||A||_1 ||A^-1 x||_1 / ||x||_1 for the estimator's
                               start block solved with the user's columns), which makes the host
                               estimate at once when it hints at ill-conditioning; 0 = none */
} silc_report;

/* The library pivot ratio (report->pivot_ratio) above which the host makes an
 * owed estimate at once, for its warnings, unless condest_lower proves that
 * they cannot fire (docs/accuracy.md).  A ratio is no bound, so a plugin
 * whose ratio is above it spares the whole estimate by solving a start
 * vector for a rigorous condest_lower instead (SuiteSparse: e/n).  A
 * constant, not a field: the layout and the ABI version are unchanged. */
#define SILC_CONDEST_PIVOT_HINT 1e6

typedef struct silc_call {
    int op;                     /* enum silc_op */
    int sub;                    /* op-specific selector */
    int nin;
    const silc_value *in[3];
    double alpha, beta;         /* ADD / SCALE coefficients */
    int64_t ival[2];            /* CONVERT band widths */
    const char *options;        /* SOLVE: per-call option text, may be NULL */
    silc_value *out;            /* set by the plugin on success */
    silc_report *report;        /* SOLVE only, never NULL then */
    void *host_private;         /* host bookkeeping (error buffer, option scope) */
    const char *op_class;       /* class being tried, e.g. "solve.sparse.spd": a SOLVE under a
                                   ".spd" class should try Cholesky and return SILC_ENOTSPD on
                                   failure; under the general class it should use LU */
    /* ABI 1.8: imaginary parts of alpha and beta, for ADD and SCALE on
     * complex values (0 otherwise; the host promotes a real operand scaled by
     * a complex alpha first, so a call with a nonzero imaginary part has
     * complex operands). */
    double alpha_imag, beta_imag;
} silc_call;

typedef int (*silc_op_fn)(silc_call *call);
/* Returns 1 if the backend takes these operands, else 0 with *why set to a short
 * static reason ("needs a symmetric matrix").  Must be cheap: it may ask
 * silc_props_of() for the parts it reads. */
typedef int (*silc_accepts_fn)(const silc_call *call, const char **why);

typedef struct silc_op_entry {
    silc_op_fn run;             /* NULL = not provided */
    silc_accepts_fn accepts;    /* NULL = accepts anything run is given */
} silc_op_entry;

/* ---- options --------------------------------------------------------------- */
enum silc_opt_type { SILC_OPT_INT = 0, SILC_OPT_DOUBLE, SILC_OPT_STRING, SILC_OPT_BOOL };

typedef struct silc_option_spec {
    const char *key;            /* without the plugin prefix: "icntl_7" */
    int type;                   /* enum silc_opt_type */
    const char *default_value;  /* as text */
    const char *help;
} silc_option_spec;

/* ---- distribution (ABI 1.5) ------------------------------------------------ */
/* Where the rows of a distributed value live: rank r holds the contiguous
 * rows [starts[r], starts[r+1]) of the m_global rows; this rank holds
 * m_local = starts[rank+1] - starts[rank] rows from first_row on.  Every
 * column is on every rank (PETSc's MPIAIJ and MPI vector layout). */
typedef struct silc_layout {
    int64_t m_global;
    int64_t first_row, m_local;
    int rank, size;
    const int64_t *starts;      /* size + 1 entries, owned by the host */
} silc_layout;

/* ---- the host's services --------------------------------------------------- */
typedef struct silc_host_api {
    int abi_major, abi_minor;
    size_t struct_size;
    int index_bytes;            /* sizeof(silc_index) on the host */

    void *(*alloc)(size_t bytes);
    void *(*calloc)(size_t count, size_t size);
    void *(*realloc)(void *p, size_t bytes);
    void (*free)(void *p);

    /* Record the failure message of this call and return status, so a plugin
     * writes `return host->error(call, SILC_ESINGULAR, "umfpack_dl_numeric: ...")`. */
    int (*error)(silc_call *call, int status, const char *fmt, ...)
#if defined(__GNUC__)
        __attribute__((format(printf, 3, 4)))
#endif
        ;
    void (*log)(int level, const char *fmt, ...); /* 0 error, 1 warn, 2 info, 3 debug */

    /* Typed options of this plugin, looked up in the per-call options, the
     * session's `set`, then the config file.  key is without the plugin prefix.
     * Return 0 and the default when absent; non-zero (after host->error) when
     * present but not of the type. */
    int (*option_int)(silc_call *call, const char *key, int64_t def, int64_t *out);
    int (*option_double)(silc_call *call, const char *key, double def, double *out);
    const char *(*option_string)(silc_call *call, const char *key, const char *def);

    /* New values, zero-filled, NULL on allocation failure.  Fill through view(). */
    silc_value *(*dense_new)(int64_t m, int64_t n);
    silc_value *(*csr_new)(int64_t m, int64_t n, int64_t nnz_capacity);
    silc_value *(*band_new)(int64_t m, int64_t n, int64_t kl, int64_t ku);
    /* Set the final entry count of a CSR value built with a larger capacity. */
    int (*csr_set_nnz)(silc_value *v, int64_t nnz);
    void (*release)(silc_value *v);     /* drop a value the plugin created and will not return */

    void (*view)(const silc_value *v, silc_view *out);
    const silc_props *(*props)(const silc_value *v);
    uint64_t (*id)(const silc_value *v); /* unique per value for the process lifetime */

    /* Attachments: derived data (a factorization, a converted copy) hung on an
     * immutable value and destroyed with it.  key should start with the backend
     * name.  set replaces (destroying) an existing attachment of the same key. */
    void *(*attach_get)(const silc_value *v, const char *key);
    int (*attach_set)(const silc_value *v, const char *key, void *data, void (*destroy)(void *));

    double (*now)(void);        /* monotonic seconds */
    int (*threads)(void);       /* thread budget the tuner grants right now */

    /* ABI 1.1: Hager-Higham estimate of ||A^{-1}||_1 (LAPACK dlacon's method)
     * for a backend whose library gives no condition estimate or only a crude
     * one: apply(ctx, x, trans, work) overwrites x (length n) with A^{-1} x, or
     * A^{-T} x when trans is 1, using the backend's factorization; work is
     * passed through.  A handful of solves; returns -1 if a solve failed.
     * cond_1(A) ~ props(A)->norm1 * estimate. */
    double (*inv_norm1_est)(int64_t n, int (*apply)(void *ctx, double *x, int trans, double *work),
                            void *ctx, double *work);

    /* ABI 1.3: the block form (Higham-Tisseur, MATLAB's normest1) for a
     * library whose solve phase costs about the same for a few columns as
     * for one.  apply(ctx, X, t, trans) overwrites the n x t column-major X
     * with A^{-1} X (A^{-T} X when trans is 1); at most itmax applications
     * of A^{-1} (2: the start, one gradient step, one improvement; 5 is
     * dlacon's limit), t <= 64 columns.  A backend can fold the first block
     * into a solve it makes anyway: inv_norm1_start writes the starting block
     * X0 (n x t), and Y0 = A^{-1} X0 is passed in; Y0 = NULL makes the
     * estimator apply it.  Returns -1 if a solve failed. */
    void (*inv_norm1_start)(int64_t n, int t, double *X0);
    double (*inv_norm1_est_block)(int64_t n, int t, int itmax,
                                  int (*apply)(void *ctx, double *X, int t, int trans), void *ctx,
                                  const double *Y0);
    /* ABI 1.3: dense_new without zeroing, for a result the plugin writes
     * entirely (a solve copying b into it and solving in place): zeroing a
     * vector the size of a back-substitution's output costs a few per cent
     * of the back-substitution. */
    silc_value *(*dense_new_uninit)(int64_t m, int64_t n);
    /* ABI 1.4: only the parts of the properties named in parts (SILC_PROPS_*),
     * each computed once and cached; the others are not computed.  Asking
     * props() for "is it symmetric?" also summed the norms: on bcsstk16 that
     * was 0.3 ms, 1.5% of a MUMPS factorization.  Call it through
     * silc_props_of(), which falls back to props() on an older host. */
    const silc_props *(*props_part)(const silc_value *v, int parts);

    /* ABI 1.5: distributed values (the MPI server and SPMD programs; see
     * docs/distributed.md).  A backend that lists an op in its
     * silc_plugin.collective_ops may be handed operands distributed by
     * contiguous row blocks (PETSc's layout); the same call then runs on
     * every rank of the communicator at once, each rank seeing its own block.
     * comm: the communicator of this call (a pointer to an MPI_Comm), with
     * this rank and the size; NULL (rank 0, size 1) when the call runs on one
     * process, and then every operand is whole.  A plugin built without MPI
     * never calls these and lists no collective op. */
    const void *(*comm)(const silc_call *call, int *rank, int *size);
    /* 1 and *out if v is distributed; view() then shows this rank's block:
     * m = out->m_local rows, CSR column indices global.  0 if v is whole. */
    int (*layout)(const silc_value *v, silc_layout *out);
    /* A distributed dense value with like's row blocks (like is
     * distributed) and n columns, this rank's block zero-filled: the
     * result of a collective call (x = A \ b: like = b).  NULL on failure.
     * ABI 1.8: the value has like's field (a complex like gives a complex
     * result, 2 doubles per entry): the one distributed constructor serves
     * both fields, as a collective complex solve needs. */
    silc_value *(*dist_dense_new)(const silc_value *like, int64_t n);

    /* ABI 1.7: 1 when the request running this call is to stop (an
     * interrupt: Ctrl-C in the REPL, silc_cancel, a CANCEL frame; silcd's
     * --max-request-seconds, its client gone, the server shutting down),
     * else 0.  An iterative method asks between iterations and then returns
     * host->error(call, SILC_ELIB, "stopped on request"); the host reports
     * the reason.  Cheap (a clock read; a system call every 20 ms).  Always
     * 0 on a distributed call: its ranks must stop together, which they do
     * after the statement.  Check struct_size >= SILC_HOST_NEEDS(cancelled). */
    int (*cancelled)(silc_call *call);

    /* ABI 1.8: complex values (see enum silc_field).  field(v) is v's field.
     * The constructors are dense_new/csr_new/band_new for complex values,
     * zero-filled; their views hold 2 doubles per entry. */
    int (*field)(const silc_value *v);
    silc_value *(*dense_new_complex)(int64_t m, int64_t n);
    silc_value *(*csr_new_complex)(int64_t m, int64_t n, int64_t nnz_capacity);
    silc_value *(*band_new_complex)(int64_t m, int64_t n, int64_t kl, int64_t ku);
    /* Hager-Higham for complex A (LAPACK zlacn2's method): as inv_norm1_est,
     * with x and work n complex entries (2n doubles, interleaved) and trans 1
     * meaning the conjugate transpose, A^{-H} x.  cond_1(A) ~ props(A)->norm1
     * (the modulus 1-norm) * estimate. */
    double (*inv_norm1_est_complex)(int64_t n, int (*apply)(void *ctx, double *x, int trans, double *work),
                                    void *ctx, double *work);
    /* A collective backend that moves a value's entries between ranks
     * itself (its own MPI calls, not its library's) counts them here, so
     * that `info` shows them with the core's own: bytes received by all the
     * ranks together (the same number on every rank), of vectors (matrix 0)
     * or matrices (1).  Check struct_size >= SILC_HOST_NEEDS(dist_moved). */
    void (*dist_moved)(silc_call *call, int matrix, uint64_t bytes);

    /* ABI 1.9: malloc, calloc, realloc and free for a library's large work
     * space: blocks of 4 MiB and more come from 2 MiB-aligned mappings on
     * transparent huge pages (where the kernel has them; otherwise, and for
     * smaller blocks, these are libc's), which cut a sparse factorization's
     * page faults and TLB misses (UMFPACK on a 250 000-unknown complex
     * system: 0.74x the CPU time).  large_free and large_realloc take any
     * pointer, passing one they did not hand out to libc's free and
     * realloc, so a plugin can put them in a library's process-wide hooks
     * (SuiteSparse_config) while the library holds older blocks.  Not
     * counted against the value size limit, like the library's own malloc.
     * Check struct_size >= SILC_HOST_NEEDS(large_free). */
    void *(*large_alloc)(size_t bytes);
    void *(*large_calloc)(size_t count, size_t size);
    void *(*large_realloc)(void *p, size_t bytes);
    void (*large_free)(void *p);

    /* ABI 1.10: a copy of the dense real operand v's m*n entries
     * (column-major, leading dimension m) that the host made in the same
     * read of v as its own checks of v (the shape and NaN/Inf before a
     * solve), now the plugin's: overwrite it (factor in place) and release
     * it with host->free.  NULL when the host made none for v in this call
     * (it makes one only for a square solve matrix whose class needs a
     * factorization of all of it, once): then copy v yourself.  Taken
     * instead of a memcpy, it spares a read of A from memory, which at
     * n = 1000 is a few per cent of a dgesv.  Check struct_size >=
     * SILC_HOST_NEEDS(take_dense_copy). */
    double *(*take_dense_copy)(silc_call *call, const silc_value *v);
} silc_host_api;

/* ---- what a plugin provides ------------------------------------------------ */
typedef struct silc_backend {
    const char *name;           /* "umfpack"; full name is "<plugin>.<name>"; NULL = plugin name alone */
    const char *description;
    int n_ops;                  /* entries in ops (ops past n_ops are "not provided") */
    const silc_op_entry *ops;   /* indexed by enum silc_op */
} silc_backend;

typedef struct silc_plugin {
    int abi_major, abi_minor;
    size_t struct_size;
    int index_bytes;            /* sizeof(silc_index) the plugin was built with */

    const char *name;           /* "suitesparse", "reference" */
    const char *version;        /* of the plugin and, after a space, of the library */
    int n_backends;
    const silc_backend *backends;

    int n_options;              /* typed options the plugin reads; others are errors */
    const silc_option_spec *options;

    void (*set_threads)(int nthreads); /* NULL if the plugin is single-threaded */
    void (*shutdown)(void);            /* NULL if nothing to release; called once at unload */

    /* ABI 1.5: per backend (n_backends entries, in the order of backends),
     * the ops it runs collectively on distributed operands, as bits
     * SILC_COLLECTIVE(op); NULL = none.  Only such calls see host->comm. */
    const uint32_t *collective_ops;

    /* ABI 1.8: per backend (n_backends entries), the ops that take complex
     * operands, as bits SILC_COMPLEX_OPS(op); NULL = none.  The host hands
     * complex values to no other op: the dispatcher passes over a backend
     * that lacks the bit ("does not take complex values") to the next of the
     * list, so a plugin built against a real-only library (PETSc's real
     * build) simply leaves the bit out, and an accepts() function may still
     * decline a complex call it cannot take, with its reason. */
    const uint32_t *complex_ops;
} silc_plugin;
#define SILC_COLLECTIVE(op) (1u << (op))
#define SILC_COMPLEX_OPS(op) (1u << (op))

/* The check every silc_plugin_init starts with: the host table exists, speaks
 * this major version and index width, and is long enough to hold every host
 * function the plugin calls (needed = SILC_HOST_NEEDS(last field used), so a
 * newer plugin still runs on an older host when it only uses older fields).
 * Returns 0, or 1 with *errmsg set to a static reason. */
#define SILC_HOST_NEEDS(field) (offsetof(silc_host_api, field) + sizeof(((silc_host_api *)0)->field))
static inline int silc_host_check(const silc_host_api *h, size_t needed, const char **errmsg)
{
    const char *why = NULL;
    if (!h) why = "no host table";
    else if (h->abi_major != SILC_ABI_MAJOR) why = "the host speaks another ABI major version";
    else if (h->index_bytes != (int)sizeof(silc_index)) why = "the host uses another index width";
    else if (h->struct_size < needed) why = "the host table lacks functions this plugin calls";
    if (why && errmsg) *errmsg = why;
    return why != NULL;
}

/* The parts of v's properties a plugin reads: through props_part when the
 * host has it (ABI 1.4), else all of them through props, so a plugin using
 * this keeps running on a 1.0 host. */
static inline const silc_props *silc_props_of(const silc_host_api *h, const silc_value *v, int parts)
{
    return h->struct_size >= SILC_HOST_NEEDS(props_part) ? h->props_part(v, parts) : h->props(v);
}

/* A plugin's own large arrays that outlive the call (a solver attachment's
 * copy of A's indices, a factorization's triplets): from the host's
 * large-block allocator when it has one (ABI 1.9: from 4 MiB up on
 * transparent huge pages, a few page faults to fill instead of one per
 * 4 KiB, each ~11 us on a VM), else from alloc.  Free them with
 * silc_large_free_of. */
static inline int silc_host_has_large_(const silc_host_api *h)
{
    return h->struct_size >= SILC_HOST_NEEDS(large_free) && h->large_alloc && h->large_free;
}

static inline void *silc_large_alloc_of(const silc_host_api *h, size_t bytes)
{
    return silc_host_has_large_(h) ? h->large_alloc(bytes) : h->alloc(bytes);
}

static inline void silc_large_free_of(const silc_host_api *h, void *p)
{
    if (silc_host_has_large_(h)) h->large_free(p);
    else h->free(p);
}

/* The one exported symbol.  Returns 0 and *out on success; on failure returns
 * non-zero and may set *errmsg to a static message. */
typedef int (*silc_plugin_init_fn)(const silc_host_api *host, const silc_plugin **out,
                                   const char **errmsg);
#define SILC_PLUGIN_INIT_SYMBOL "silc_plugin_init"
/* Declared here once, so that a plugin only defines it. */
SILC_PLUGIN_EXPORT int silc_plugin_init(const silc_host_api *host, const silc_plugin **out,
                                        const char **errmsg);

#ifdef __cplusplus
}
#endif
#endif /* SILC_PLUGIN_H */
