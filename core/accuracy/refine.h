/*
 * refine.h -- what the dispatcher asks of refine.c: the finite-operand check
 * made before any solve, and iterative refinement after a direct solve.
 *
 * Refinement lives once in the core, whichever backend solved: the residual
 * r = b - A x is formed here (in double, or in double-double for
 * solve.refine_residual = extended), the correction A d = r is solved by the
 * same backend with the same options (its factorization, attached to A, makes
 * that one more triangular solve), and x += d.  Keys: solve.refine (steps,
 * per call "refine = 2") and solve.refine_residual (double | extended).  A
 * backend whose factorization is single precision sets report->single_factor
 * and gets up to REFINE_SINGLE_DEFAULT steps unless refine is set.
 */
#ifndef SILC_REFINE_H
#define SILC_REFINE_H

#include "context.h"

#define REFINE_SINGLE_DEFAULT 10
/* Backward error a refined single-precision solve must reach, else a warning
 * says refinement did not converge (a lone single solve gives ~1e-8, a
 * converged refinement ~1e-16). */
#define REFINE_SINGLE_CONVERGED 1e-12

/* If v stores a NaN or Inf, sets E->err to "<name> has NaN at (i, j)" (1-based)
 * and returns -1; else 0.  Cheap when v is finite.  matrix: v is a solve's
 * matrix, whose properties the dispatcher computes anyway, so they answer
 * (one pass over it, not a scan and then the properties); else v is a
 * right-hand side and gets val_has_nonfinite's scan. */
int refine_check_finite(silc_engine *E, const silc_value *v, int matrix, const char *name);

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

#endif
