/*
 * accuracy.h -- the backward error every solve reports, computed by the core
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

/* Normwise backward error of X as a solution of A X = B (infinity norm; the
 * normal equations' residual for rectangular A).  -1 when it cannot be
 * computed. */
double acc_backward_error(const silc_value *A, const silc_value *B, const silc_value *X);

/* Fills call->report->backward_error after a successful solve: at once, or
 * ACC_DEFERRED when the caller allows deferral (may_defer), the solve
 * neither iterated nor refined, and either it only reused a factorization
 * and solve.backward_error is not "always", or solve.backward_error is
 * "on_request".  Warns when the result does not solve the system.  when is
 * solve.backward_error (NULL when not set): the dispatcher reads the
 * options, this layer below it is told them. */
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

/* The deferred backward error held by p (context.h: eng_pending_hold),
 * computed now (with the warning a bad one deserves); releases p. */
double acc_pending_resolve(silc_engine *E, eng_pending *p, const char *backend);

#endif
