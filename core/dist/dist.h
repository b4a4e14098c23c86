/*
 * dist.h -- distributed values: the engine on every rank of a communicator.
 *
 * In an SPMD context (silc_open_mpi) and in `silcd --mpi` every rank runs
 * its own engine on the same statements in the same order, so every rank
 * reaches every collective at the same point: the evaluator, the
 * dispatcher and the plugins stay the single-process code, and this module
 * is the only one that talks to the communicator (through silc_comm.h's
 * table: libsilc never links MPI).
 *
 * A value is whole (an ordinary value, the same on every rank) or
 * distributed by contiguous row blocks (store.h: val_dist, PETSc's layout),
 * real or complex alike (a complex entry moves, and is counted, as 2 doubles).
 * Data moves only where the layout must change, and each move is counted:
 *   - an operation whose operands are all whole runs on every rank, moving
 *     nothing (scalars, small values: the same bits everywhere);
 *   - element-wise operations, sums, norms, dots and the sparse
 *     matrix-vector product run on each rank's rows (the product first
 *     gathers the vector, once per vector value);
 *   - a solve runs collectively when its backend lists SOLVE in its
 *     collective_ops (petsc, the MPI build of mumps), on the blocks as they
 *     are: a matrix is never moved again after it was distributed;
 *   - anything else gathers its distributed operands to every rank (once
 *     per value: the copy is kept with the value) and runs the ordinary
 *     dispatch on every rank, whose result is whole.  `explain` says which.
 * Failures are collective: after each distributed step every rank learns
 * the lowest failing rank's message ("rank 1 of 2: petsc: ..."), and the
 * store changes only when all succeeded.  A failure of the communicator
 * itself ends the job (ops->abort) with the message on stderr, rather than
 * leave ranks waiting for each other.
 */
#ifndef SILC_DIST_H
#define SILC_DIST_H

#include "context.h"
#include "silc_comm.h"

/* The dispatcher's disp_run, which dist_run hands every operation it cannot
 * run on the blocks itself (and runs on the blocks): this layer sits below
 * the dispatcher, which calls it on every walk, so the call up goes through
 * the pointer the engine registers with dist_attach. */
typedef int (*dist_run_fn)(silc_engine *E, silc_call *call);

typedef struct dist_ctx {
    silc_comm_ops *ops;
    dist_run_fn run;
    int rank, size;
    /* Bytes received from other ranks, summed over all ranks (so every rank
     * counts the same), split by what moved: CSR values are matrices, dense
     * ones vectors.  Since the engine started; `info` shows per-statement
     * differences. */
    uint64_t moved_matrix, moved_vector;
} dist_ctx;

/* The engine runs on ops's ranks from now on (taken over: destroyed with
 * the engine), dispatching through run.  Before any value exists. */
int dist_attach(silc_engine *E, silc_comm_ops *ops, dist_run_fn run);
void dist_detach(silc_engine *E);
/* Rank and size; 0 and 1 without a communicator. */
int dist_rank(const silc_engine *E);
int dist_size(const silc_engine *E);

/* Collective: the sum of x over the ranks (x without a communicator). */
double dist_sum(silc_engine *E, double x);
/* Agreement after a step every rank ran: rc is this rank's status.  Returns
 * 0 when every rank succeeded; else the status of the lowest failing rank,
 * whose message every rank's E->err then holds, prefixed "rank r of N: ". */
int dist_agree(silc_engine *E, int rc);
/* SPMD: the same API call on every rank?  what is the call ("EXEC",
 * "PUT"...), text its name or statements.  A mismatch is an error on every
 * rank naming the first rank that differs from rank 0. */
int dist_check_call(silc_engine *E, const char *what, const char *text);

/* v's whole value, gathered (once: kept with v) to every rank (all) or to
 * rank 0 only.  Borrowed; on ranks that did not receive it, NULL.  A whole
 * v is returned as it is.  NULL with E->err on failure (then on every rank). */
const silc_value *dist_whole(silc_engine *E, const silc_value *v, int all);
/* Takes v over and returns a whole value with its contents (retained). */
int dist_make_whole(silc_engine *E, silc_value **v);
/* Whether v is distributed (whatever rank we are). */
#define dist_is(v) ((v) && (v)->dist != NULL)

/* A complex copy of the distributed real value v, each rank promoting its
 * own block (nothing moves).  Collective; NULL on every rank when one ran
 * out of memory. */
silc_value *dist_promote(silc_engine *E, const silc_value *v);

/* SPMD: binds name to the value whose rows [first_row, first_row +
 * block->m) this rank holds (block taken over).  Collective. */
int dist_put_rows(silc_engine *E, const char *name, int64_t first_row, silc_value *block);
/* This rank's rows of v (retained) and the first one's index. */
int dist_rows_of(silc_engine *E, const silc_value *v, silc_value **block, int64_t *first_row);
/* MPI server: rank 0's value v (NULL on the others) becomes a value on
 * every rank: distributed by rows when it has at least min_rows rows (and
 * one per rank), else copied whole.  Collective; *out retained. */
int dist_share(silc_engine *E, silc_value *v, int64_t min_rows, silc_value **out);

/* The dispatcher's entry for an evaluated operation on an SPMD engine
 * (eval.c calls this instead of disp_run when E->dist is set): runs call
 * as the header comment says. */
int dist_run(silc_engine *E, silc_call *call);
/* For the dispatcher's walk: how a backend is to run call; collective: it
 * runs call->op collectively (dispatch.h: ld_backend_collective).
 * DIST_LOCAL: no distributed operand, run as always.
 * DIST_COLLECTIVE: b runs on every rank on the row blocks.
 * DIST_GATHERED: the operands were replaced by whole copies.
 * -1: failure (E->err).  dist_walk_end puts the operands back. */
enum { DIST_LOCAL = 0, DIST_COLLECTIVE = 1, DIST_GATHERED = 2 };
typedef struct dist_swap {
    const silc_value *in[3];
    silc_value *tmp[3];
    int mode;
} dist_swap;
int dist_walk_begin(silc_engine *E, silc_call *call, int collective, dist_swap *s);
void dist_walk_end(silc_call *call, dist_swap *s);
/* Any distributed operand in call. */
int dist_call_has(const silc_call *call);

/* Backward error of a distributed solve (accuracy.c's measure). */
double dist_backward_error(const silc_value *A, const silc_value *B, const silc_value *X);
/* One line for `explain` on where call runs (nothing without distributed
 * operands). */
void dist_explain(silc_engine *E, const silc_call *call, strbuf *b);

#endif
