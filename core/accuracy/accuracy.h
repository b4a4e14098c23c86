/*
 * accuracy.h -- the accuracy machinery (core/accuracy/), which the dispatcher
 * calls around every solve: the backward error (accuracy.c), iterative
 * refinement and the finite-operand check (refine.c), and exact scaling of
 * systems far from 1 in magnitude (scale.c).  It reads no option and runs
 * no backend itself: the dispatcher, above it, passes the settings in and
 * hands refinement its correction solve as a callback (refine_how).
 *
 * ---- the backward error (accuracy.c): every solve reports it, computed by the core
 * the same way whichever backend solved, and when it is computed.
 *
 * A solve that factors or iterates gets its backward error at once: one
 * residual is cheap next to a factorization, and it catches a bad factor or a
 * solver that claims convergence it did not reach.  A back-substitution that
 * reuses a factorization (the body of a time loop) costs about as much as
 * that residual, so by default its backward error is deferred: the solve
 * keeps its operands (values are immutable, so they cannot change under it)
 * and `info` computes the number when someone asks.  Deferring loses nothing
 * that matters: LU and Cholesky are backward stable for every right-hand side
 * with the same bound (|dA| <= c n eps |L||U|), a property of the factors
 * that the first, checked solve already measured.  solve.backward_error =
 * always (a key, or per call "backward_error = always") computes it on every
 * solve, and with it the "does not solve the system" warning.
 * solve.backward_error = on_request defers it for every direct solve, the
 * first of a factorization too: for a program of many millisecond solves
 * whose residual pass, next to a factorization of a few ns per nonzero,
 * would cost a few per cent.  It gives up the check of the factors at
 * solve time (the "does not solve" warning then comes with `info`); the
 * library's own failure codes, the condition-estimate warnings and the
 * NaN/Inf check of the result stay.  Iterative and refined solves keep
 * theirs at once: there it checks a convergence claim, for the price of one
 * of the iteration's products.
 */
#ifndef SILC_ACCURACY_H
#define SILC_ACCURACY_H

#include "context.h"

/* report->backward_error of a solve whose backward error is deferred. */
#define ACC_DEFERRED (-2.0)

/* R = B - A X for k columns (A m x n; X n x k, B and R m x k, column-major).
 * extended: the sums are carried in double-double (lo, m x k, receives the
 * low parts' contribution; NULL when not extended). */
void acc_residual(const silc_value *A, const double *B, const double *X, int64_t k, int extended,
                  double *R, double *lo);
/* Infinity norm of the m x k column-major array (max row sum of |.|); NaN wins. */
double acc_norm_inf(const double *x, int64_t m, int64_t k);
/* Dense copy of any value (m x n, column-major); NULL when out of memory. */
double *acc_dense_copy(const silc_value *v);
/* The same three for complex systems (A of either field; B, X, R complex,
 * m x k and n x k column-major): R = B - A X, the infinity norm by moduli
 * (the complex backward error's), and a complex dense copy of any value
 * (double _Complex: this header does not pull in <complex.h>'s I). */
void acc_residual_complex(const silc_value *A, const double _Complex *B, const double _Complex *X, int64_t k,
                          double _Complex *R);
double acc_norm_inf_complex(const double _Complex *z, int64_t m, int64_t k);
double _Complex *acc_dense_copy_complex(const silc_value *v);

/* Normwise backward error of X as a solution of A X = B (infinity norm; the
 * normal equations' residual for rectangular A).  -1 when it cannot be
 * computed. */
double acc_backward_error(const silc_value *A, const silc_value *B, const silc_value *X);

/*
 * ---- the forward-error bound.  For a square system, x - x_true = A^-1 r with
 * r = b - A x, so for every column
 *
 *     ||x - x_true||_1 / ||x||_1  <=  ||A^-1||_1 ||r||_1 / ||x||_1,
 *
 * a rigorous bound with the exact ||A^-1||_1.  The report's forward_bound is
 * that right-hand side with ||A^-1||_1 replaced by its Hager-Higham estimate
 * (cond_est / ||A||_1; a lower bound of the true norm, within a factor 3 on
 * the shared matrices, tests/test_condest_matrices.c), the largest over the
 * columns, relative to the computed x.  It comes from the same residual pass
 * as the backward error (one more add per row) and exists only when the
 * backend gave a condition estimate.  Relative to x_true it is B / (1 - B)
 * for B < 1.  Unlike `cond x backward error` it needs no first-order
 * argument and no norm mixing (the backward error is an infinity-norm one).
 */

/* Fills call->report->backward_error after a successful solve: at once, or
 * ACC_DEFERRED when the caller allows deferral (may_defer), the solve
 * neither iterated nor refined, and either it only reused a factorization
 * and solve.backward_error is not "always", or solve.backward_error is
 * "on_request".  Warns when the result does not solve the system.  when is
 * solve.backward_error (NULL when not set): the dispatcher reads the
 * options, this layer below it is told them.  Computed at once, it also
 * fills report->forward_bound (above). */
void acc_report(silc_engine *E, silc_call *call, int may_defer, const char *when);

/* The largest backward error a solve's result may have and still count as
 * a solution (solve.verify): `auto` (default) 1e-6 for a direct solve, and
 * for an iterative one ACC_VERIFY_FACTOR x the tolerance it reported (1e-3
 * when it reported none); a number sets the direct bound and the least
 * iterative one; `off` gives INFINITY.  verify is solve.verify's value
 * (NULL when not set).  A result above it fails the solve
 * over to the next backend of the list (dispatch.c). */
#define ACC_VERIFY_FACTOR 10.0
double acc_verify_limit(const char *verify, const silc_report *r);

/* A lower bound of cond_1(A) that a solve gives for free: A X = B, so
 * ||A^-1||_1 >= ||x_j||_1 / ||b_j||_1 for every column, times ||A||_1 (A's
 * properties; complex operands by modulus).  One pass over B and X; -1
 * when not computed (not square, distributed, or B not dense).  The dispatcher's hint that a matrix may be
 * ill-conditioned, when it weighs deferring the condition estimate. */
double acc_cond_lower_bound(const silc_value *A, const silc_value *B, const silc_value *X);

/* The deferred backward error held by p (context.h: eng_pending_hold),
 * computed now into r->backward_error (with the warning a bad one
 * deserves), with r->forward_bound; releases p. */
void acc_pending_resolve(silc_engine *E, eng_pending *p, silc_report *r);

/*
 * ---- refinement (refine.c): what the dispatcher asks of it: the finite-operand check
 * made before any solve, and iterative refinement after a direct solve.
 *
 * Refinement lives once in the core, whichever backend solved: the residual
 * r = b - A x is formed here (in double, or in double-double for
 * solve.refine_residual = extended), the correction A d = r is solved by the
 * same backend with the same options (its factorization, attached to A, makes
 * that one more triangular solve), and x += d.  Keys: solve.refine (steps,
 * per call "refine = 2") and solve.refine_residual (double | extended).  A
 * backend whose factorization is single precision sets report->single_factor
 * and gets up to REFINE_SINGLE_DEFAULT steps unless refine is set; they stop
 * at working precision, or at tune.accuracy when that is set (the accuracy
 * the tuner chose a mixed-precision backend for: one step instead of two
 * on the diffusion loop, docs/accuracy.md).
 */

#define REFINE_SINGLE_DEFAULT 10
/* Backward error a refined single-precision solve must reach (or the
 * refinement's target, when larger), else a warning says refinement did not
 * converge (a lone single solve gives ~1e-8, a converged refinement ~1e-16). */
#define REFINE_SINGLE_CONVERGED 1e-12

/* If v stores a NaN or Inf, sets E->err to "<name> has NaN at (i, j)" (1-based)
 * and returns -1; else 0.  Cheap when v is finite.  matrix: v is a solve's
 * matrix, whose properties the dispatcher computes anyway, so they answer
 * (one pass over it, not a scan and then the properties); else v is a
 * right-hand side and gets val_has_nonfinite's scan. */
int refine_check_finite(silc_engine *E, const silc_value *v, int matrix, const char *name);
/* 1 when the check of a solve's matrix A is better left to the dispatcher,
 * which makes it for every solve before any backend runs, after the shape
 * pass that may copy A for the backend on the way (dispatch.c's
 * prepare_dense_copy): A whole, dense and real with its shape not known yet,
 * and b finite (else A's check comes first, as its message does).  A caller
 * that names the operands (eval.c) names A after the solve failed. */
int refine_check_finite_later(const silc_engine *E, const silc_value *A, const silc_value *b);

/* Steps a direct result that failed verification gets before the next
 * backend of the list is tried (the fallback chain, dispatch.c), unless
 * solve.refine is set: then its steps ran already. */
#define REFINE_RESCUE_STEPS 3
/* Longest message a failed correction solve leaves in err. */
#define REFINE_WHY_MAX 1024
/* What the dispatcher tells refine_solve: the settings it read, and how to
 * solve the correction A D = R by the backend that made call->out, with the
 * call's class and options (call->out's shape; NULL, and why in err, when
 * it fails).  A callback because this layer sits below the dispatcher: the
 * call goes up once, like the host API's. */
typedef struct refine_how {
    const char *steps;          /* solve.refine, NULL when not set */
    const char *residual;       /* solve.refine_residual, NULL when not set */
    const char *backend;        /* the backend's full name, for the warning */
    double target;              /* tune.accuracy when set, else 0: the backward error at which
                                   the default refinement of a single-precision factor stops */
    silc_value *(*correct)(const void *ctx, silc_engine *E, const silc_call *call, const silc_value *R,
                           char *err, size_t errlen);
    const void *ctx;            /* the dispatcher's, for correct */
} refine_how;
/* Refines call->out, a solution just computed by how's backend, as how's
 * settings and call->report->single_factor ask, and at least at_least
 * steps when solve.refine is not set; replaces call->out when a step was
 * kept and records steps, the backward error before and a note in the
 * report.  Never fails the solve: a correction that cannot be computed ends
 * the refinement with a note. */
void refine_solve(silc_engine *E, silc_call *call, const refine_how *how, int64_t at_least);

/*
 * ---- scaling (scale.c): solves of systems far from 1 in magnitude (entries near 1e+-300)
 * by exact power-of-two scaling, for every backend at once.
 *
 * A backend's norms, pivots thresholds and inner products are tuned for data
 * of moderate size: PETSc's ILU finds "zero pivots" at 1e-300 and CG's inner
 * products underflow.  Multiplying A and B by powers of two rounds nothing
 * (unless an entry would become subnormal, which the exponent avoids), so the
 * dispatcher solves (2^ea A) Y = 2^eb B instead and returns X = 2^(ea-eb) Y
 * (an initial guess X0 goes in as 2^(eb-ea) X0).
 * The backward error is invariant under this scaling, so the report is the
 * original system's.  The scaled A is an attachment of A, so a time loop
 * still factors once.
 */

typedef struct scale_state {
    const silc_value *A, *B, *X0; /* the caller's operands, restored at the end */
    silc_value *Bs;             /* scaled B (owned), NULL if B is not scaled */
    silc_value *X0s;            /* the initial guess in[2] scaled like the solution (owned) */
    int ea, eb;                 /* exponents applied to A and B */
} scale_state;

/* Replaces call->in[0] / in[1] by scaled copies when either lies beyond
 * 2^+-64.  Returns 0 (with nothing to undo when no scaling was needed), or -1
 * with E->err set on allocation failure. */
int scale_solve_begin(silc_engine *E, silc_call *call, scale_state *S);
/* Restores the operands and scales call->out (a fresh value) back.  Returns
 * 1 when that overflowed (a solution beyond the largest double, which the
 * scaled solve could represent but the caller's cannot), else 0. */
int scale_solve_end(silc_call *call, scale_state *S);

#endif
