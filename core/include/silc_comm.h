/*
 * silc_comm.h -- the collectives an SPMD engine needs, as a table of
 * functions, so that libsilc never links MPI.
 *
 * libsilc_mpi (mpi/, silc_mpi.h) fills this table with MPI calls on a
 * communicator and opens a context on it; another transport could fill it
 * too.  Every function is collective over all ranks, moves 8-byte words
 * (doubles or int64s, bit for bit) and returns 0, or non-zero after writing
 * the library's message (naming the call) into msg.  Counts and
 * displacements are in words and per rank.  The reductions give every rank
 * the same bits (reduce to rank 0, then broadcast), so ranks that run the
 * same statements on the results take the same branches.
 */
#ifndef SILC_COMM_H
#define SILC_COMM_H

#include "silc.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SILC_COMM_VERSION 1

typedef struct silc_comm_ops {
    int version;                /* SILC_COMM_VERSION */
    size_t struct_size;         /* sizeof(silc_comm_ops) */
    int rank, size;
    const void *handle;         /* what plugins get from host->comm (an MPI_Comm *) */
    void *impl;                 /* passed back to every function */
    int (*bcast)(void *impl, void *buf, int64_t words, int root, char *msg, size_t msglen);
    /* Every rank's `words` words (the same count everywhere) into recv, rank by rank. */
    int (*allgather)(void *impl, const void *send, int64_t words, void *recv, char *msg, size_t msglen);
    /* root == -1: every rank receives (allgatherv). */
    int (*gatherv)(void *impl, const void *send, int64_t words, void *recv, const int64_t *counts,
                   const int64_t *displs, int root, char *msg, size_t msglen);
    int (*scatterv)(void *impl, const void *send, const int64_t *counts, const int64_t *displs,
                    void *recv, int64_t words, int root, char *msg, size_t msglen);
    int (*alltoallv)(void *impl, const void *send, const int64_t *scounts, const int64_t *sdispls,
                     void *recv, const int64_t *rcounts, const int64_t *rdispls, char *msg, size_t msglen);
    /* In place over n doubles: op 0 sum, 1 max, 2 min. */
    int (*reduce)(void *impl, double *x, int64_t n, int op, char *msg, size_t msglen);
    /* Ends every rank of the job (a rank that cannot go on consistently). */
    void (*abort)(void *impl, int code);
    void (*destroy)(void *impl);  /* at silc_close; may be NULL */
} silc_comm_ops;

/* Opens an embedded context whose engine runs on every rank of ops (taken
 * over: destroy is called at close, also on failure).  Collective. */
SILC_API int silc_open_comm(silc_context **out, const char *config_path, silc_comm_ops *ops);

/* SILC_INIT with SILC_MODE=spmd opens its default context through the
 * opener registered here (libsilc_mpi registers silc_open_mpi on
 * MPI_COMM_WORLD from a constructor when the program links it); without
 * one, SILC_MODE=spmd is an error saying to link libsilc_mpi. */
typedef int (*silc_spmd_opener)(silc_context **out, const char *config_path);
SILC_API void silc_set_spmd_opener(silc_spmd_opener open);

#ifdef __cplusplus
}
#endif
#endif /* SILC_COMM_H */
