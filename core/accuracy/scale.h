/*
 * scale.h -- solves of systems far from 1 in magnitude (entries near 1e+-300)
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
#ifndef SILC_SCALE_H
#define SILC_SCALE_H

#include "context.h"

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
