/*
 * mpi_server.c -- silcd --mpi: `mpirun -np N silcd --mpi --listen URL`.
 *
 * Rank 0 owns the listening socket and every connection, in one process
 * (MPI ranks cannot fork per session), and serves one request at a time
 * from a poll loop; each session's engine runs on every rank (core/dist/
 * dist.h), on a communicator of its own.  Before rank 0's engine takes a
 * step the others must share (a session opening or closing, a PUT, a GET of
 * a distributed value, an EXEC, a DELETE), it broadcasts the step on a
 * control communicator; the other ranks sit in srv_follow (session.c) and
 * take the same step on their engine of that session, so all engines meet
 * in the same collectives.  Steps that only read rank 0's state (LIST, INFO
 * of the session) are not announced.
 *
 * Shutdown: SIGTERM or SIGINT on rank 0 (mpirun forwards them to every
 * rank) closes the sessions, tells the others to stop, and finalizes MPI.
 * A rank that dies takes the job with it (Open MPI's default), so the
 * clients see their connection close rather than wait forever.
 */
#define _POSIX_C_SOURCE 200809L
#include "server.h"

#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include <mpi.h>

#include "silc_comm.h"
#include "silc_mpi.h"

typedef struct ranks_impl {
    silc_comm_ops *ctrl;       /* the control communicator: commands, verdicts */
} ranks_impl;

static void ctrl_die(srv_ranks *R, const char *msg)
{
    ranks_impl *I = R->impl;
    srv_log(LOG_ERROR, "rank %d: control communicator: %s; ending the job", R->rank, msg);
    I->ctrl->abort(I->ctrl->impl, 70);
}

/* Header words: command, session id, text bytes (0 = no text). */
static int r_command(srv_ranks *R, int cmd, unsigned long id, const char *text)
{
    ranks_impl *I = R->impl;
    int64_t h[3];
    char msg[256];
    h[0] = cmd;
    h[1] = (int64_t)id;
    h[2] = text ? (int64_t)strlen(text) + 1 : 0;
    if (I->ctrl->bcast(I->ctrl->impl, h, 3, 0, msg, sizeof msg)) ctrl_die(R, msg);
    if (h[2]) {
        int64_t words = (h[2] + 7) / 8;
        uint64_t *buf = calloc((size_t)words, 8);
        if (!buf) ctrl_die(R, "out of memory sending a command");
        memcpy(buf, text, (size_t)h[2]);
        if (I->ctrl->bcast(I->ctrl->impl, buf, words, 0, msg, sizeof msg)) ctrl_die(R, msg);
        free(buf);
    }
    return 0;
}

static int r_receive(srv_ranks *R, int *cmd, unsigned long *id, char **text)
{
    ranks_impl *I = R->impl;
    int64_t h[3];
    char msg[256];
    *text = NULL;
    if (I->ctrl->bcast(I->ctrl->impl, h, 3, 0, msg, sizeof msg)) ctrl_die(R, msg);
    *cmd = (int)h[0];
    *id = (unsigned long)h[1];
    if (h[2] > 0) {
        int64_t words = (h[2] + 7) / 8;
        uint64_t *buf = calloc((size_t)words, 8);
        if (!buf) ctrl_die(R, "out of memory receiving a command");
        if (I->ctrl->bcast(I->ctrl->impl, buf, words, 0, msg, sizeof msg)) ctrl_die(R, msg);
        ((char *)buf)[h[2] - 1] = '\0';
        *text = (char *)buf;
    }
    return 0;
}

static void r_word(srv_ranks *R, int64_t *w)
{
    ranks_impl *I = R->impl;
    char msg[256];
    if (I->ctrl->bcast(I->ctrl->impl, w, 1, 0, msg, sizeof msg)) ctrl_die(R, msg);
}

static struct silc_comm_ops *r_engine_comm(srv_ranks *R, char *err, size_t errlen)
{
    (void)R;
    return silc_mpi_comm_ops(MPI_COMM_WORLD, err, errlen);
}

static srv_ranks the_ranks;
static ranks_impl the_impl;

int srv_mpi_init(int *argc, char ***argv, int64_t min_rows)
{
    char msg[256];
    int provided;
    if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
        fprintf(stderr, "silcd --mpi: MPI_Init_thread failed\n");
        return -1;
    }
    if (!(the_impl.ctrl = silc_mpi_comm_ops(MPI_COMM_WORLD, msg, sizeof msg))) {
        fprintf(stderr, "silcd --mpi: %s\n", msg);
        return -1;
    }
    the_ranks.rank = the_impl.ctrl->rank;
    the_ranks.size = the_impl.ctrl->size;
    the_ranks.min_rows = min_rows;
    the_ranks.command = r_command;
    the_ranks.receive = r_receive;
    the_ranks.word = r_word;
    the_ranks.engine_comm = r_engine_comm;
    the_ranks.impl = &the_impl;
    srv_mpi = &the_ranks;
    return 0;
}

void srv_mpi_finish(void)
{
    if (!srv_mpi) return;
    if (srv_mpi->rank == 0) r_command(srv_mpi, SRV_CMD_STOP, 0, NULL);
    if (the_impl.ctrl->destroy) the_impl.ctrl->destroy(the_impl.ctrl->impl);
    srv_mpi = NULL;
    MPI_Finalize();
}

/* Rank 0: connections and requests, one at a time. */
int srv_mpi_serve(int lfd, int is_tcp)
{
    session **open = calloc((size_t)srv_cfg.max_clients, sizeof *open);
    struct pollfd *p = calloc((size_t)srv_cfg.max_clients + 2, sizeof *p);
    unsigned long next_id = 1;
    int n = 0, i;
    if (!open || !p) {
        srv_log(LOG_ERROR, "out of memory");
        free(open);
        free(p);
        return -1;
    }
    for (;;) {
        p[0].fd = lfd;
        p[0].events = POLLIN;
        p[1].fd = srv_shutdown_fd;
        p[1].events = POLLIN;
        for (i = 0; i < n; i++) {
            p[i + 2].fd = srv_session_fd(open[i]);
            p[i + 2].events = POLLIN;
            p[i + 2].revents = 0;
        }
        p[0].revents = p[1].revents = 0;
        if (poll(p, (nfds_t)n + 2, -1) < 0) {
            if (errno == EINTR) continue;
            break;
        }
        if (p[1].revents) break;
        for (i = n - 1; i >= 0; i--) {
            if (!p[i + 2].revents) continue;
            if (srv_session_step(open[i]) != 0) {
                srv_session_close(open[i]);
                open[i] = open[--n];
            }
        }
        if (p[0].revents & POLLIN) {
            int fd = accept(lfd, NULL, NULL), one = 1;
            char peer[64];
            session *S;
            if (fd < 0) continue;
            if (n == srv_cfg.max_clients) {
                const char *why = "server busy: too many sessions (silcd --max-clients)";
                srv_log(LOG_WARN, "%s", why);
                close(fd);
                continue;
            }
            if (is_tcp) setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
            /* The handshake runs to its end here, so the peer's entry of
             * the authentication backoff is needed only meanwhile. */
            srv_peer_of(fd, peer, sizeof peer);
            srv_auth_hold(peer);
            if ((S = srv_session_open(fd, next_id++, NULL))) open[n++] = S;
            srv_auth_drop(peer);
        }
    }
    for (i = 0; i < n; i++) srv_session_close(open[i]);
    free(open);
    free(p);
    return 0;
}
