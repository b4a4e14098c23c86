/*
 * silc_mpi.c -- libsilc_mpi: the MPI side of SILC's SPMD mode.  libsilc never
 * links MPI; it runs an SPMD engine on a table of collectives
 * (silc_comm.h).  This library fills that table with MPI calls on a
 * duplicate of the program's communicator (silc_mpi_comm_ops, also used by
 * silcd --mpi), opens a context on it (silc_open_mpi), and, when a program
 * links it, registers the opener that SILC_INIT uses under SILC_MODE=spmd
 * (MPI_COMM_WORLD).  Every function of the table is collective and moves
 * 8-byte words; the message of a failure names the MPI call.
 */
#include <limits.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#include "silc.h"
#include "silc_comm.h"
#include "silc_mpi.h"

/* One allocation holds the table and what its functions need, so that the
 * table handed to silc_open_comm is freed by its own destroy: the engine
 * calls destroy last and never touches the table after. */
typedef struct mpi_impl {
    silc_comm_ops ops;
    MPI_Comm comm;      /* the duplicate; ops.handle points here */
    /* int copies of the int64 counts and displacements, allocated once for
     * the communicator's size so that no call allocates: a malloc failing
     * on one rank only would leave the others waiting in the collective. */
    int *sc, *sd, *rc, *rd;
} mpi_impl;

/* Open MPI 4.1 implements MPI 3.1, which has no large-count (MPI_Count)
 * collectives, so counts and displacements must fit an int. */
#define WORDS_MAX ((int64_t)INT_MAX)

static int fail(char *msg, size_t msglen, const char *fmt, ...)
{
    if (msg && msglen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, msglen, fmt, ap);
        va_end(ap);
    }
    return -1;
}

/* The message of an MPI error code, as "MPI_Xxx failed: <error string>". */
static int mpi_fail(char *msg, size_t msglen, const char *call, int err)
{
    char s[MPI_MAX_ERROR_STRING];
    int len = 0;
    if (MPI_Error_string(err, s, &len) != MPI_SUCCESS) snprintf(s, sizeof s, "error code %d", err);
    else s[len < MPI_MAX_ERROR_STRING ? len : MPI_MAX_ERROR_STRING - 1] = '\0';
    return fail(msg, msglen, "%s failed: %s", call, s);
}

/* The int copy of n counts or displacements; 0, or 1 if one is negative or
 * over INT_MAX (*bad gets it). */
static int to_ints(const int64_t *v, int n, int *out, int64_t *bad)
{
    for (int i = 0; i < n; i++) {
        if (v[i] < 0 || v[i] > WORDS_MAX) {
            *bad = v[i];
            return 1;
        }
        out[i] = (int)v[i];
    }
    return 0;
}

static int range_fail(char *msg, size_t msglen, const char *call, const char *what, int64_t v)
{
    if (v < 0) return fail(msg, msglen, "%s: negative %s (%lld words)", call, what, (long long)v);
    return fail(msg, msglen,
                "%s: %s of %lld words is over INT_MAX (%d): this MPI (version %d.%d) has no "
                "large-count collectives",
                call, what, (long long)v, INT_MAX, MPI_VERSION, MPI_SUBVERSION);
}

/* Where the arguments of a call differ between ranks (a rooted v-call, where
 * only the root's counts matter, or alltoallv, where each rank has its own),
 * one rank may find one out of range while the others are fine; they must all
 * give up together, or the others would wait for it in the collective.  Each
 * rank says whether it can go on (0) or not (its rank + 1); the largest
 * failing rank is then known everywhere, and the ranks that could have gone
 * on name it. */
static int agree(mpi_impl *I, const char *call, int local_bad, char *msg, size_t msglen)
{
    int mine = local_bad ? I->ops.rank + 1 : 0, worst = 0;
    int err = MPI_Allreduce(&mine, &worst, 1, MPI_INT, MPI_MAX, I->comm);
    if (err != MPI_SUCCESS) return mpi_fail(msg, msglen, "MPI_Allreduce", err);
    if (worst && !local_bad)
        return fail(msg, msglen,
                    "%s: rank %d cannot take part (its counts are missing or out of range)", call,
                    worst - 1);
    return worst ? -1 : 0;
}

/* ---- the table ------------------------------------------------------------- */

/* Broadcast and reduce see the same n on every rank, so they can move any
 * number of words in pieces of at most INT_MAX, and do. */
static int c_bcast(void *impl, void *buf, int64_t words, int root, char *msg, size_t msglen)
{
    mpi_impl *I = impl;
    unsigned char *p = buf;
    if (words < 0) return range_fail(msg, msglen, "MPI_Bcast", "count", words);
    while (words > 0) {
        int k = words > WORDS_MAX ? INT_MAX : (int)words;
        int err = MPI_Bcast(p, k, MPI_UINT64_T, root, I->comm);
        if (err != MPI_SUCCESS) return mpi_fail(msg, msglen, "MPI_Bcast", err);
        p += (size_t)k * 8, words -= k;
    }
    return 0;
}

static int c_allgather(void *impl, const void *send, int64_t words, void *recv, char *msg,
                       size_t msglen)
{
    mpi_impl *I = impl;
    /* words is the same on every rank (silc_comm.h), so all fail here alike. */
    if (words < 0 || words > WORDS_MAX)
        return range_fail(msg, msglen, "MPI_Allgather", "count", words);
    int err =
        MPI_Allgather(send, (int)words, MPI_UINT64_T, recv, (int)words, MPI_UINT64_T, I->comm);
    return err != MPI_SUCCESS ? mpi_fail(msg, msglen, "MPI_Allgather", err) : 0;
}

static int c_gatherv(void *impl, const void *send, int64_t words, void *recv, const int64_t *counts,
                     const int64_t *displs, int root, char *msg, size_t msglen)
{
    mpi_impl *I = impl;
    const char *call = root < 0 ? "MPI_Allgatherv" : "MPI_Gatherv";
    int n = I->ops.size, receives = root < 0 || root == I->ops.rank, err;
    int64_t bad = 0;
    int local = 0;
    if (words < 0 || words > WORDS_MAX) local = 1, bad = words;
    else if (receives && (!counts || !displs)) local = 2;
    else if (receives && (to_ints(counts, n, I->rc, &bad) || to_ints(displs, n, I->rd, &bad)))
        local = 1;
    /* allgatherv: every rank holds the same counts and displacements, so
     * every rank reaches the same verdict and no agreement is needed. */
    if (root >= 0 && agree(I, call, local, msg, msglen) && !local) return -1;
    if (local == 2)
        return fail(msg, msglen, "%s: no counts or displacements on the receiver", call);
    if (local) return range_fail(msg, msglen, call, "count or displacement", bad);
    if (root < 0)
        err = MPI_Allgatherv(send, (int)words, MPI_UINT64_T, recv, I->rc, I->rd, MPI_UINT64_T,
                             I->comm);
    else
        err = MPI_Gatherv(send, (int)words, MPI_UINT64_T, recv, receives ? I->rc : NULL,
                          receives ? I->rd : NULL, MPI_UINT64_T, root, I->comm);
    return err != MPI_SUCCESS ? mpi_fail(msg, msglen, call, err) : 0;
}

static int c_scatterv(void *impl, const void *send, const int64_t *counts, const int64_t *displs,
                      void *recv, int64_t words, int root, char *msg, size_t msglen)
{
    mpi_impl *I = impl;
    int n = I->ops.size, sends = root == I->ops.rank, local = 0;
    int64_t bad = 0;
    if (words < 0 || words > WORDS_MAX) local = 1, bad = words;
    else if (sends && (!counts || !displs)) local = 2;
    else if (sends && (to_ints(counts, n, I->sc, &bad) || to_ints(displs, n, I->sd, &bad)))
        local = 1;
    if (agree(I, "MPI_Scatterv", local, msg, msglen) && !local) return -1;
    if (local == 2)
        return fail(msg, msglen, "MPI_Scatterv: no counts or displacements on the root");
    if (local) return range_fail(msg, msglen, "MPI_Scatterv", "count or displacement", bad);
    int err = MPI_Scatterv(send, sends ? I->sc : NULL, sends ? I->sd : NULL, MPI_UINT64_T, recv,
                           (int)words, MPI_UINT64_T, root, I->comm);
    return err != MPI_SUCCESS ? mpi_fail(msg, msglen, "MPI_Scatterv", err) : 0;
}

static int c_alltoallv(void *impl, const void *send, const int64_t *scounts, const int64_t *sdispls,
                       void *recv, const int64_t *rcounts, const int64_t *rdispls, char *msg,
                       size_t msglen)
{
    mpi_impl *I = impl;
    int n = I->ops.size, local = 0;
    int64_t bad = 0;
    if (!scounts || !sdispls || !rcounts || !rdispls) local = 2;
    else if (to_ints(scounts, n, I->sc, &bad) || to_ints(sdispls, n, I->sd, &bad) ||
             to_ints(rcounts, n, I->rc, &bad) || to_ints(rdispls, n, I->rd, &bad))
        local = 1;
    if (agree(I, "MPI_Alltoallv", local, msg, msglen) && !local) return -1;
    if (local == 2) return fail(msg, msglen, "MPI_Alltoallv: no counts or displacements");
    if (local) return range_fail(msg, msglen, "MPI_Alltoallv", "count or displacement", bad);
    int err = MPI_Alltoallv(send, I->sc, I->sd, MPI_UINT64_T, recv, I->rc, I->rd, MPI_UINT64_T,
                            I->comm);
    return err != MPI_SUCCESS ? mpi_fail(msg, msglen, "MPI_Alltoallv", err) : 0;
}

/* MPI_Allreduce may combine in a different order on different ranks (and so
 * round differently); reducing to rank 0 and broadcasting its result gives
 * every rank the same bits, so ranks branching on the result agree. */
static int c_reduce(void *impl, double *x, int64_t n, int op, char *msg, size_t msglen)
{
    mpi_impl *I = impl;
    MPI_Op mop = op == 0 ? MPI_SUM : op == 1 ? MPI_MAX : op == 2 ? MPI_MIN : MPI_OP_NULL;
    if (mop == MPI_OP_NULL) return fail(msg, msglen, "reduce: unknown operation %d", op);
    if (n < 0) return range_fail(msg, msglen, "MPI_Reduce", "count", n);
    while (n > 0) {
        int k = n > WORDS_MAX ? INT_MAX : (int)n, err;
        err = MPI_Reduce(I->ops.rank == 0 ? MPI_IN_PLACE : x, x, k, MPI_DOUBLE, mop, 0, I->comm);
        if (err != MPI_SUCCESS) return mpi_fail(msg, msglen, "MPI_Reduce", err);
        err = MPI_Bcast(x, k, MPI_DOUBLE, 0, I->comm);
        if (err != MPI_SUCCESS) return mpi_fail(msg, msglen, "MPI_Bcast", err);
        x += k, n -= k;
    }
    return 0;
}

static void c_abort(void *impl, int code)
{
    mpi_impl *I = impl;
    MPI_Abort(I->comm, code);
    abort(); /* MPI_Abort should not return; if it does, this rank still must not go on */
}

static void c_destroy(void *impl)
{
    mpi_impl *I = impl;
    int finalized = 0;
    if (!I) return;
    /* Freeing a communicator after MPI_Finalize is erroneous; a program that
     * finalises before silc_close only leaks the duplicate. */
    MPI_Finalized(&finalized);
    if (!finalized && I->comm != MPI_COMM_NULL) MPI_Comm_free(&I->comm);
    free(I->sc);
    free(I);
}

/* ---- the public calls ------------------------------------------------------ */

silc_comm_ops *silc_mpi_comm_ops(MPI_Comm comm, char *msg, size_t msglen)
{
    int initialized = 0, finalized = 0, err;
    MPI_Initialized(&initialized);
    MPI_Finalized(&finalized);
    if (!initialized || finalized) {
        fail(msg, msglen, "silc_mpi_comm_ops: MPI is %s",
             finalized ? "already finalised" : "not initialised: call MPI_Init first");
        return NULL;
    }
    if (comm == MPI_COMM_NULL) {
        fail(msg, msglen, "silc_mpi_comm_ops: MPI_COMM_NULL is not a communicator");
        return NULL;
    }
    int n = 0, inter = 0, ok, all_ok = 0;
    if ((err = MPI_Comm_test_inter(comm, &inter)) != MPI_SUCCESS) {
        mpi_fail(msg, msglen, "MPI_Comm_test_inter", err);
        return NULL;
    }
    /* The engine's collectives are those of one group of ranks. */
    if (inter) {
        fail(msg, msglen, "silc_mpi_comm_ops: an intercommunicator is not supported");
        return NULL;
    }
    if ((err = MPI_Comm_size(comm, &n)) != MPI_SUCCESS) {
        mpi_fail(msg, msglen, "MPI_Comm_size", err);
        return NULL;
    }
    mpi_impl *I = calloc(1, sizeof *I);
    if (I) I->sc = malloc(4 * (size_t)n * sizeof *I->sc);
    /* The ranks agree on the allocations before the first collective of the
     * table: a rank that gave up alone would leave the others waiting in
     * MPI_Comm_dup or in the engine's first collective. */
    ok = I && I->sc;
    if ((err = MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_MIN, comm)) != MPI_SUCCESS || !all_ok) {
        if (err != MPI_SUCCESS) mpi_fail(msg, msglen, "MPI_Allreduce", err);
        else if (!ok) fail(msg, msglen, "silc_mpi_comm_ops: out of memory for %d ranks", n);
        else fail(msg, msglen, "silc_mpi_comm_ops: another rank ran out of memory");
        if (I) free(I->sc);
        free(I);
        return NULL;
    }
    I->comm = MPI_COMM_NULL;
    /* A duplicate keeps SILC's messages apart from the program's, whatever
     * tags the program uses. */
    if ((err = MPI_Comm_dup(comm, &I->comm)) != MPI_SUCCESS) {
        mpi_fail(msg, msglen, "MPI_Comm_dup", err);
        I->comm = MPI_COMM_NULL;
        c_destroy(I);
        return NULL;
    }
    /* Errors come back as codes, to be reported with SILC's message, instead
     * of ending the job from inside a collective. */
    const char *call = "MPI_Comm_set_errhandler";
    err = MPI_Comm_set_errhandler(I->comm, MPI_ERRORS_RETURN);
    if (err == MPI_SUCCESS) call = "MPI_Comm_rank", err = MPI_Comm_rank(I->comm, &I->ops.rank);
    if (err == MPI_SUCCESS) call = "MPI_Comm_size", err = MPI_Comm_size(I->comm, &I->ops.size);
    if (err != MPI_SUCCESS) {
        mpi_fail(msg, msglen, call, err);
        c_destroy(I);
        return NULL;
    }
    I->sd = I->sc + n, I->rc = I->sd + n, I->rd = I->rc + n;
    I->ops.version = SILC_COMM_VERSION;
    I->ops.struct_size = sizeof(silc_comm_ops);
    I->ops.handle = &I->comm;
    I->ops.impl = I;
    I->ops.bcast = c_bcast;
    I->ops.allgather = c_allgather;
    I->ops.gatherv = c_gatherv;
    I->ops.scatterv = c_scatterv;
    I->ops.alltoallv = c_alltoallv;
    I->ops.reduce = c_reduce;
    I->ops.abort = c_abort;
    I->ops.destroy = c_destroy;
    return &I->ops;
}

int silc_open_mpi(silc_context **out, MPI_Comm comm, const char *config_path)
{
    char msg[1024];
    if (out) *out = NULL;
    silc_comm_ops *ops = silc_mpi_comm_ops(comm, msg, sizeof msg);
    if (!ops) {
        /* silc.h has no call that sets silc_errmsg() from outside libsilc, so
         * the reason goes to stderr, where an MPI job's launcher shows it. */
        fprintf(stderr, "silc_open_mpi: %s\n", msg);
        return -1;
    }
    return silc_open_comm(out, config_path, ops);
}

/* The opener of SILC_INIT under SILC_MODE=spmd: the whole job. */
static int open_world(silc_context **out, const char *config_path)
{
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (!initialized) {
        if (out) *out = NULL;
        fprintf(stderr, "SILC_MODE=spmd: MPI is not initialised: call MPI_Init before SILC_INIT\n");
        return -1;
    }
    return silc_open_mpi(out, MPI_COMM_WORLD, config_path);
}

/* Linking libsilc_mpi is what makes SILC_MODE=spmd available to SILC_INIT:
 * libsilc cannot name MPI, so this library announces itself when it loads. */
__attribute__((constructor)) static void register_spmd_opener(void)
{
    silc_set_spmd_opener(open_world);
}
