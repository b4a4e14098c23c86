/*
 * ss.h -- what the four SuiteSparse backends of the plugin share.
 *
 *   suitesparse.c  plugin table, init/shutdown (reference-counted: every
 *                  context that loads the module calls init once), threads
 *   ss_common.c    operands (views, right-hand sides, results), the
 *                  pattern-keyed cache of symbolic analyses, the lock, the
 *                  one cholmod_common, the Hager/Higham condition estimator
 *   umfpack.c      UMFPACK: general sparse LU
 *   cholmod.c      CHOLMOD: sparse Cholesky under the .spd classes
 *   klu.c          KLU: sparse LU for circuit-like matrices, fast refactor
 *   spqr.c         SuiteSparseQR: rectangular least squares
 *   ss_complex.c   complex values on UMFPACK, KLU and CHOLMOD (umfpack_zl,
 *                  klu_zl, CHOLMOD_COMPLEX); SPQR stays real
 *   ss_alloc.c     the libraries' large blocks on huge pages (huge_pages)
 *
 * Zero-copy: a CSR value of A is, array for array, the compressed-column form
 * of A'.  UMFPACK and KLU factor that A' in place and solve with the
 * transposed system (UMFPACK_At, klu_l_tsolve); CHOLMOD reads a symmetric A,
 * which is its own transpose.  Only SPQR needs A itself and transposes.
 */
#ifndef SS_H
#define SS_H

#include "silc_plugin.h"

#include <SuiteSparse_config.h>
#include <cholmod.h>

#include <stddef.h>
#include <stdint.h>

/* SuiteSparse's 64-bit entry points (umfpack_dl_, klu_l_, cholmod_l_) take
 * SuiteSparse_long arrays; SILC's CSR arrays are passed to them unchanged. */
_Static_assert(sizeof(SuiteSparse_long) == sizeof(silc_index),
               "SuiteSparse_long must be as wide as silc_index");

extern const silc_host_api *ss_host;

/* ---- suitesparse.c: the backends' ops (one accepts + run per library) ------- */
int ss_umfpack_accepts(const silc_call *call, const char **why);
int ss_umfpack_solve(silc_call *call);
int ss_cholmod_accepts(const silc_call *call, const char **why);
int ss_cholmod_solve(silc_call *call);
int ss_klu_accepts(const silc_call *call, const char **why);
int ss_klu_solve(silc_call *call);
int ss_spqr_accepts(const silc_call *call, const char **why);
int ss_spqr_solve(silc_call *call);

/* ---- ss_complex.c: complex values (ABI 1.8) on UMFPACK, KLU, CHOLMOD -------- */
int ss_is_complex(const silc_value *v);   /* 0 on a host older than ABI 1.8 */
int ss_umfpack_solve_complex(silc_call *call);
int ss_klu_solve_complex(silc_call *call);
int ss_cholmod_solve_complex(silc_call *call);

/* ---- ss_alloc.c: SuiteSparse's work space on huge pages (ABI 1.9) ---------- */
/* suitesparse.huge_pages: *on = 1 for auto, 0 for off; SILC_EARG otherwise. */
int ss_huge_pages_mode(silc_call *call, int *on);
/* run(call) with SuiteSparse's large blocks from the host's large allocator
 * when huge_pages says so (setting SuiteSparse_config's hooks at the first
 * call, unless the program set its own): every op of the plugin goes
 * through it. */
int ss_with_huge_pages(silc_call *call, int (*run)(silc_call *call));

/* ---- ss_common.c ------------------------------------------------------------ */
int ss_start(void);                 /* 0 on success; starts the cholmod_common */
void ss_finish(void);               /* frees caches, finishes the cholmod_common */
void ss_lock(void);                 /* guards the shared state below */
void ss_unlock(void);
cholmod_common *ss_cholmod_common(void); /* use only between ss_lock / ss_unlock */
/* SILC's thread count (set_threads); with 1, ss_cholmod_factorize keeps
 * CHOLMOD's OpenMP regions, whose thread count its build fixed, on the
 * calling thread (ss_common.c).  Call it under ss_lock, for every
 * cholmod_l_factorize. */
void ss_set_omp_threads(int nthreads);
void ss_cholmod_factorize(cholmod_sparse *A, cholmod_factor *L, cholmod_common *cc);

int ss_nomem(silc_call *call, const char *what);

/* The factorization attached to A = call->in[0] under key, or a new one made
 * by make() and attached (destroy frees it with A).  Sets report->
 * reused_factor and factor_seconds.  what names it in an out-of-memory
 * message.  Returns a silc_status. */
typedef int (*ss_make_fn)(silc_call *call, const silc_view *a, void **out);
int ss_attached_factor(silc_call *call, const silc_view *a, const char *key, ss_make_fn make,
                       void (*destroy)(void *), const char *what, void **out);
int ss_ends_with(const char *s, const char *suffix);
/* Shared accepts: A must be CSR (and square when square is set). */
int ss_accepts_csr(const silc_call *call, int square, const char **why);

/* B as a dense column-major m x k array: x gets every entry. */
void ss_rhs_copy(const silc_view *b, double *x);
/* The right-hand side as a dense column-major m x k array: a dense B is
 * borrowed (*owned = 0), anything else copied. */
double *ss_rhs_dense(const silc_view *b, int *owned);
/* A new dense m x k value filled from x (column-major, leading dimension ld). */
silc_value *ss_dense_value(int64_t m, int64_t k, const double *x, int64_t ld);

/*
 * The condition estimate is Hager/Higham's (ss_square_cond, below: block
 * form through the factors, once per factorization).  The libraries'
 * cheap pivot ratio can miss ill-conditioning by orders of magnitude (5.07
 * from UMFPACK for the 1-D Laplacian of cond_1 840), so it is never reported as the
 * estimate, only as pivot_ratio, labelled.  The plugin option "condest":
 *   true (default; "auto" means the same) estimate;
 *   false                                 no estimate ("not estimated"),
 * and the session's accuracy.condest = off (report->condest_off, ABI 1.7)
 * turns it off too.  A factorization made without an estimate gets one on
 * its next solve that wants it, so the setting means the same whenever it
 * is set.
 */
enum { SS_CONDEST_ALWAYS = 0, SS_CONDEST_NEVER };
int ss_condest_mode(silc_call *call, int *mode);
/* 1 when this call should have a condition estimate (mode and accuracy.condest). */
int ss_condest_wanted(const silc_call *call, int mode);

/* Estimate of ||A^{-1}||_1 for an n x n A given by solves with A (trans = 0)
 * and A' (trans = 1) in place on x; about 5 pairs of solves.  -1 on failure. */
double ss_inv_norm1(int64_t n, int (*solve)(void *ctx, double *x, int trans), void *ctx);

/*
 * Symbolic analyses keyed by sparsity pattern.  A time loop that builds a new
 * matrix with the same pattern each step (A = K + dt*M) gets a new value, so
 * the attachment of the old one is no help; the last symbolic object of each
 * backend is kept here with an exact copy of the pattern it was made for and
 * handed to the next value whose pattern matches (sizes first, then memcmp).
 * Entries are reference-counted: the cache holds one reference and every
 * factorization that needs its symbolic object (KLU's) holds another.  An
 * entry may also keep one spare numeric object donated by a factorization
 * whose value died, so KLU can refactor into it without pivoting.
 */
enum { SS_UMFPACK = 0, SS_CHOLMOD, SS_KLU, SS_NCACHE };

/* What a factorization tells every solve that uses it. */
typedef struct ss_factor_info {
    double rcond;               /* the library's reciprocal estimate (SPQR: 1/cond), -1 = none */
    double cond;                /* the condition estimate, valid when estimated */
    int estimated;              /* cond holds a Hager/Higham estimate */
    double pivot_ratio;         /* the library's max/min factor diagonal (1/rcond), 0 = none */
    double *start_solved;       /* the estimator's start solved for an owed estimate's lower
                                   bound, its first step: A^-1 [e/n, alternating] (n x
                                   SS_EST_COLS, real: ss_start_due; complex, 2 doubles an
                                   entry: ss_complex.c); NULL when none */
    char method[64];
    char note[160];
} ss_factor_info;

/* The condition estimate of a square factorization: Hager/Higham (LAPACK
 * dlacn2's count of solves) with the host's estimator.  The start is two
 * columns, e/n and Higham's alternating vector (the extra vector dlacn2
 * solves last); the one with the larger ||A^-1 x||_1 goes on alone: one
 * A^-T solve (the gradient), one A^-1 solve (the best unit vector), so
 * four column solves in three applications, where the two-column block
 * form carried both columns through and made six.  SuiteSparse's solves
 * cost per column (KLU's solve of a very sparse matrix is a pass over its
 * factors, a sixth of a refactorization on 494_bus), so a column less is
 * a sixth less; the estimates are those of the block form on the shared
 * matrices but west0067 (0.69 of cond_1 against 0.97, as dlacon's: the
 * test allows 10x).  The first application rides along with KLU's user
 * solve when it is due (ss_cond_due): the solve takes ss_rhs_with_start's
 * array, B with the starting block after it, and passes the solved block
 * as Y0 (KLU's solve rounds each column alike however many ride along);
 * Y0 = NULL makes ss_square_cond solve the start itself (UMFPACK, one
 * column per call anyway; CHOLMOD, whose supernodal solve of more columns
 * would round the user's otherwise).  apply(ctx, X, t, trans) overwrites the
 * n x t X with A^-1 X (A^-T X).  Sets fi->cond = norm1(A) ||A^{-1}||_1 and
 * fi->estimated; nothing when not due or when a solve fails. */
#define SS_EST_COLS 2
#define SS_EST_STEPS 2
typedef int (*ss_block_fn)(void *ctx, double *X, int t, int trans);
int ss_cond_due(const silc_call *call, int mode, const ss_factor_info *fi);

/* The estimate made when the report is read (ABI 1.8, docs/accuracy.md).
 * ss_condest_later: the host asks to leave out an estimate that costs solves
 * (ss_cond_due is then 0); ss_report_owed, after the solve of k columns,
 * tells it that one is owed and its cost in such solves.  ss_condest_only:
 * the host asks for the estimate alone, made with the factorization attached
 * to A (none attached: ss_no_factor, a decline; nothing is factored; the
 * report's note then says how the estimate was made, and the host adds it
 * to the solve's). */
#define SS_EST_COLUMN_SOLVES 4 /* the start's two columns, then one A' and one A solve */
int ss_condest_later(const silc_call *call);
int ss_condest_only(const silc_call *call);
void ss_report_owed(silc_call *call, int mode, const ss_factor_info *fi, int64_t k);
/* An owed estimate of a real UMFPACK or KLU factorization whose pivot ratio
 * is above the host's hint (SILC_CONDEST_PIVOT_HINT) would be made at once
 * for its warnings, four column solves, though the ratio is no bound (4.6e6
 * on olm1000, cond_1 3e6).  The estimator's start block solved (e/n and
 * the alternating vector) gives a rigorous bound instead, ||A||_1 max_j
 * ||A^-1 x_j||_1 / ||x_j||_1, which settles it by the host's rule for
 * bounds (the reference's and MUMPS's).  Both columns: e/n alone is 4e5
 * to 1e7 times weaker on the Hilbert matrices of order 9-11 (A^-1 e
 * cancels; the block's bound is within 2.8 of cond_1), whose warnings were
 * then lost (test_extremes).  The solved block is kept in
 * fi->start_solved, the estimate's start when it is made (two solves
 * then).  ss_start_due: the bound is wanted after this call's solve;
 * ss_keep_start takes the solved block (KLU solves it with the user's
 * columns, as under accuracy.condest = now: ss_rhs_with_start);
 * ss_solve_start solves it alone (UMFPACK).  Out of memory they keep
 * nothing: the host then goes by the ratio and makes the estimate at once. */
int ss_start_due(const silc_call *call, int mode, const ss_factor_info *fi);
/* The start block of both fields: X gets the n x SS_EST_COLS block (e/n,
 * the alternating vector) of width doubles an entry (1 real; 2 complex,
 * imaginary parts 0, which is the complex estimator's e/n and alternating
 * vector too).  ss_start_bound: its bound ||A||_1 max_j ||A^-1 x_j||_1 from
 * the solved block Y (the columns have 1-norm 1; complex by modulus). */
void ss_start_block(int64_t n, int width, double *X);
double ss_start_bound(silc_call *call, int64_t n, int width, const double *Y);
void ss_keep_start(ss_factor_info *fi, int64_t n, const double *y);
void ss_solve_start(ss_factor_info *fi, int64_t n, ss_block_fn apply, void *ctx);
int ss_no_factor(silc_call *call, const char *library);
/* The condest_only call once the factorization is found: the estimate
 * (made now if it is not yet), its note alone in the report; SILC_OK. */
int ss_estimate_alone(silc_call *call, int mode, int64_t n, ss_block_fn apply, void *ctx, ss_factor_info *fi);
void ss_square_cond(silc_call *call, int mode, int64_t n, ss_block_fn apply, void *ctx, ss_factor_info *fi,
                    const double *Y0);
/* B (b->n columns) then the estimator's starting block (SS_EST_COLS
 * columns), n rows each, in one array from host->alloc; NULL when out of
 * memory. */
double *ss_rhs_with_start(const silc_view *b, int64_t n);

/* The start every square solve shares: views of A and B, a decline unless A
 * is square CSR, and the condest option.  0, SILC_EDECLINE or an error. */
int ss_square_solve_begin(silc_call *call, silc_view *a, silc_view *b, int *condest);

/* fi->pivot_ratio from the library's rcond (UMFPACK, KLU, CHOLMOD: a ratio
 * of the factor's extreme diagonal entries). */
void ss_pivot_ratio(ss_factor_info *fi);
/* Copies a factorization's method, note and estimates into the report. */
void ss_report_factor(silc_report *r, const ss_factor_info *fi);

typedef struct ss_symbolic {
    int refs;
    int tag;                    /* backend variant the analysis was made for */
    int64_t m, n, nnz;
    silc_index *rowptr, *colind;
    void *obj;                  /* the library's symbolic object */
    void (*destroy)(void *obj);
    void *spare;                /* a donated numeric object, or NULL */
    void (*spare_destroy)(void *spare);
} ss_symbolic;

/* A retained entry of cache slot whose pattern equals a's and tag matches, or NULL. */
ss_symbolic *ss_sym_find(int slot, const silc_view *a, int tag);
/* A new entry (one reference, the caller's) owning obj, remembered in slot
 * (replacing the previous one).  NULL on allocation failure: obj is then
 * still the caller's. */
ss_symbolic *ss_sym_remember(int slot, const silc_view *a, int tag, void *obj,
                             void (*destroy)(void *obj));
void ss_sym_release(ss_symbolic *e);
/* Takes the spare numeric object out of e (NULL if none). */
void *ss_sym_take_spare(ss_symbolic *e);
/* Offers a numeric object made from e's analysis to e; destroys it with
 * spare_destroy when e already has one or is no longer in the cache. */
void ss_sym_donate(int slot, ss_symbolic *e, void *spare, void (*spare_destroy)(void *));

#endif
