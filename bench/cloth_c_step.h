/*
 * cloth_c_step.h -- the yardstick of issue 30 item 1: one cloth step as a
 * plain-C program written for speed would do it, the same arithmetic as the
 * cmp mode's statements (examples/cloth/cloth_drivers.c: forces, A and b
 * with the pins constrained, CG + Jacobi from the previous dv, v and x), so
 * `cloth_bench --seed-statements` can say what the statements cost over C.
 * tests/test_cloth_c_step.c checks that it lands where the statements do.
 */
#ifndef SILC_BENCH_CLOTH_C_STEP_H
#define SILC_BENCH_CLOTH_C_STEP_H

#include <stddef.h>
#include <stdint.h>

#include "cloth.h"

typedef struct cloth_c_step {
    cloth_model *m;
    double tol;        /* CG: ||b - A dv|| <= tol ||b||, lis-style's test */
    int maxiter;       /* lis-style's default, 1000 */
    int64_t N, nnz;    /* 3n; entries of A's constrained pattern */
    int64_t *rowptr, *colind, *diag; /* the pattern: no coupling to a pinned coordinate */
    int64_t *slot;     /* per spring and direction: A's ll, rr, lr, rl entries (nnz: the sink) */
    double *a;         /* nnz + 1: A's values, the last one a sink for dropped couplings */
    double *b, *dv, *dinv, *r, *z, *p, *q;
    int have_dv;       /* dv holds the last step's solution (the warm start) */
    int last_iterations;
    long iterations;   /* summed over the steps */
} cloth_c_step;

/* Builds the constrained pattern once; tol as for the cmp driver's CG. */
int cloth_c_step_open(cloth_c_step *c, cloth_model *m, double tol, char *err, size_t errlen);
/* One step: assembly, the solve, the update of m->x, m->v (and xprev, xfree,
 * the obstacle, as cloth_update does), each phase's seconds added to t when
 * t is not NULL.  -1 with err when CG fails. */
int cloth_c_step_run(cloth_c_step *c, cloth_times *t, char *err, size_t errlen);
void cloth_c_step_close(cloth_c_step *c);

#endif
