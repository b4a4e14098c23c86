/*
 * mpi_server.c -- silcd --mpi: `mpirun -np N silcd --mpi --listen URL`.
 *
 * Rank 0 owns the listening socket and every connection, in one process
 * (MPI ranks cannot fork per session): one poll loop reads all connections
 * at once (below, "rank 0"), and runs each complete request in turn; each
 * session's engine runs on every rank (core/dist/dist.h), on a
 * communicator of its own.  Before rank 0's engine takes a
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
 * clients see their connection close rather than wait forever.  The other
 * ranks wait for rank 0's next command without spinning (await_header).
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
#include <time.h>
#include <unistd.h>

#include <mpi.h>

#include "client.h"
#include "engine.h"
#include "silc_comm.h"
#include "silc_mpi.h"

typedef struct ranks_impl {
    silc_comm_ops *ctrl;       /* the control communicator: commands' texts, verdicts */
    MPI_Comm wake;             /* commands' headers, awaited without spinning (await_header) */
} ranks_impl;

/* How a rank other than 0 waits for rank 0's next command.  A blocking
 * MPI_Bcast would spin in Open MPI's progress engine (99 % of a core per
 * idle rank, for as long as the server runs), so the header comes by
 * MPI_Ibcast, tested in a loop: without sleeping for AWAIT_SPIN_S after the
 * last command (requests that follow each other pay nothing), then with
 * naps from AWAIT_NAP_MIN_NS doubling to AWAIT_NAP_MAX_NS, the most a
 * request after an idle period waits for this rank (bench/mpi_wake.py). */
#define AWAIT_SPIN_S 0.002
#define AWAIT_NAP_MIN_NS 50000L
#define AWAIT_NAP_MAX_NS 1000000L

static int await_header(MPI_Request *req)
{
    double spin_until = util_now() + AWAIT_SPIN_S;
    long nap = AWAIT_NAP_MIN_NS;
    for (;;) {
        int done = 0;
        struct timespec t;
        if (MPI_Test(req, &done, MPI_STATUS_IGNORE) != MPI_SUCCESS) return -1;
        if (done) return 0;
        if (util_now() < spin_until) continue;
        t.tv_sec = 0;
        t.tv_nsec = nap;
        nanosleep(&t, NULL);
        if ((nap *= 2) > AWAIT_NAP_MAX_NS) nap = AWAIT_NAP_MAX_NS;
    }
}

/* The three header words of a command (rank 0 sends, the others wait). */
static int header_bcast(ranks_impl *I, int64_t h[3], int rank)
{
    MPI_Request req;
    if (MPI_Ibcast(h, 3, MPI_INT64_T, 0, I->wake, &req) != MPI_SUCCESS) return -1;
    if (rank == 0) return MPI_Wait(&req, MPI_STATUS_IGNORE) == MPI_SUCCESS ? 0 : -1;
    return await_header(&req);
}

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
    if (header_bcast(I, h, R->rank)) ctrl_die(R, "MPI_Ibcast of a command failed");
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
    if (header_bcast(I, h, R->rank)) ctrl_die(R, "MPI_Ibcast of a command failed");
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
    if (MPI_Comm_dup(MPI_COMM_WORLD, &the_impl.wake) != MPI_SUCCESS) {
        fprintf(stderr, "silcd --mpi: MPI_Comm_dup failed\n");
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
    MPI_Comm_free(&the_impl.wake);
    srv_mpi = NULL;
    MPI_Finalize();
}

/* ---- rank 0: every connection read at once ------------------------------------
 *
 * One poll loop reads every connection without blocking, each into a
 * buffer of its own, and hands a session a message only when the bytes its
 * decoder will read are all in (srv_session_serve decodes them from memory
 * with the forking server's code), so a peer that stalls or trickles holds
 * up no one but itself.  What is kept of a message is only what the decoder
 * reads: a hello and its token; a request's header and text; a PUT's
 * descriptor and name, and its arrays only once the session has admitted
 * them (srv_session_wants_arrays: the limits checked from the descriptor).
 * A buffer grows as bytes arrive, never to what a header announces, and
 * the bytes of a refused body are dropped as they come.  Deadlines: the
 * handshake must be done within --handshake-timeout of the accept; a peer
 * that sends nothing for --io-timeout in the middle of a message is dropped.
 * Replies are still written by the session with the forking server's
 * blocking sends (--io-timeout bounds a client that does not read). */

#define READ_CHUNK ((size_t)64 << 10)   /* a buffer grows by at least this, at most doubling */

typedef struct conn {
    int fd;
    unsigned long id;
    session *S;             /* NULL while in the handshake */
    char peer[64];
    double handshake_end;   /* while S is NULL */
    double last_byte;       /* when the peer last sent, for --io-timeout inside a message */
    uint8_t *buf;           /* the message being assembled, as far as kept */
    size_t kept, cap;
    size_t want;            /* bytes_to_keep as last asked (0: ask) */
    uint64_t drop;          /* bytes of the last message still to drop unread */
} conn;

/* How many leading bytes of the current message must be kept before it is
 * decided (the decoder reads no further): grows as the kept bytes say more. */
static size_t bytes_to_keep(const conn *c)
{
    const size_t head = PROTO_HEADER_BYTES + PROTO_DESC_BYTES;
    uint64_t len, namelen;
    uint32_t op;
    if (!c->S) {
        uint32_t token;
        if (c->kept < PROTO_HELLO_BYTES) return PROTO_HELLO_BYTES;
        token = proto_get_u32(c->buf + 8);
        return token > PROTO_MAX_TOKEN ? PROTO_HELLO_BYTES : PROTO_HELLO_BYTES + token;
    }
    if (c->kept < PROTO_HEADER_BYTES) return PROTO_HEADER_BYTES;
    op = proto_get_u32(c->buf);
    len = proto_get_u64(c->buf + 8);
    switch (op) { /* the texts proto_read_request reads, within its limits */
    case PROTO_GET: case PROTO_GET_COMPLEX: case PROTO_DELETE: case PROTO_INFO:
        return len <= PROTO_MAX_NAME ? PROTO_HEADER_BYTES + (size_t)len : PROTO_HEADER_BYTES;
    case PROTO_EXEC: case PROTO_EXPLAIN:
        return len <= srv_cfg.max_text_bytes ? PROTO_HEADER_BYTES + (size_t)len
                                             : PROTO_HEADER_BYTES;
    case PROTO_PUT: break;
    default: return PROTO_HEADER_BYTES;
    }
    if (len < PROTO_DESC_BYTES) return PROTO_HEADER_BYTES;
    if (c->kept < head) return head;
    namelen = proto_get_u32(c->buf + PROTO_HEADER_BYTES + 4);
    if (namelen == 0 || namelen > PROTO_MAX_NAME || namelen > len - PROTO_DESC_BYTES) return head;
    if (c->kept < head + namelen) return head + (size_t)namelen;
    return srv_session_wants_arrays(c->S, c->buf, head + (size_t)namelen)
               ? PROTO_HEADER_BYTES + (size_t)len
               : head + (size_t)namelen;
}

static void conn_end(conn *c)
{
    if (c->S) srv_session_close(c->S);
    else close(c->fd);
    srv_auth_drop(c->peer);
    free(c->buf);
    memset(c, 0, sizeof *c);
    c->fd = -1;
}

/* The kept message decided: the handshake or one request.  0, or -1 when
 * the connection is over (its session closed, its fd too). */
static int conn_decide(conn *c)
{
    int rc = 0;
    if (!c->S) {
        c->S = srv_session_open_hello(c->fd, c->id, c->buf, c->kept);
        if (!c->S) { /* closed fd; told the client why */
            c->fd = -1;
            rc = -1;
        }
    } else { /* the body's bytes beyond those kept: none, or those the decoder skips */
        c->drop = proto_get_u64(c->buf + 8) - (c->kept - PROTO_HEADER_BYTES);
        rc = srv_session_serve(c->S, c->buf, c->kept);
    }
    c->kept = c->want = 0;
    if (c->cap > READ_CHUNK) { /* a large message's buffer goes with it */
        free(c->buf);
        c->buf = NULL;
        c->cap = 0;
    }
    return rc;
}

/* Reads what the peer has sent, without blocking; decides a message once
 * its kept bytes are in (one per call: every connection gets its turn).
 * 0, or -1 when the connection is over. */
static int conn_read(conn *c)
{
    static uint8_t sink[READ_CHUNK];
    for (;;) {
        size_t want, room;
        ssize_t got;
        if (c->drop) {
            got = recv(c->fd, sink, c->drop < sizeof sink ? (size_t)c->drop : sizeof sink,
                       MSG_DONTWAIT);
        } else {
            /* Asked again only when the bytes asked for are in: a PUT's
             * admission is decided once, not per chunk of its arrays. */
            if (!c->want || c->kept == c->want) c->want = bytes_to_keep(c);
            want = c->want;
            if (c->kept == want) return conn_decide(c);
            if (c->cap < want) { /* grow with the bytes that came, not the announced ones */
                size_t cap = c->cap * 2 > c->kept + READ_CHUNK ? c->cap * 2 : c->kept + READ_CHUNK;
                uint8_t *p;
                if (cap > want) cap = want;
                if (!(p = realloc(c->buf, cap))) {
                    srv_log(LOG_ERROR, "session %lu: out of memory reading a request of %zu "
                            "bytes: closed", c->id, want);
                    return -1;
                }
                c->buf = p;
                c->cap = cap;
            }
            room = (c->cap < want ? c->cap : want) - c->kept;
            got = recv(c->fd, c->buf + c->kept, room, MSG_DONTWAIT);
        }
        if (got < 0 && errno == EINTR) continue;
        if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return 0;
        if (got <= 0) {
            srv_log(LOG_INFO, "session %lu: %s", c->id,
                    got == 0 ? "connection closed by peer" : strerror(errno));
            return -1;
        }
        c->last_byte = util_now();
        if (c->drop) c->drop -= (uint64_t)got;
        else c->kept += (size_t)got;
    }
}

/* A connection past its deadline: ended, with the reason logged.  Else the
 * milliseconds until its deadline (-1: none). */
static int conn_deadline(conn *c, double now, int *over)
{
    double end = -1;
    *over = 0;
    if (!c->S) end = c->handshake_end;
    else if (c->kept || c->drop) end = c->last_byte + srv_cfg.io_timeout_ms / 1000.0;
    if (end < 0) return -1;
    if (now < end) return (int)((end - now) * 1000) + 1;
    if (!c->S)
        srv_log(LOG_INFO, "session %lu: no handshake within %g s, closed (--handshake-timeout)",
                c->id, srv_cfg.handshake_timeout_ms / 1000.0);
    else
        srv_log(LOG_INFO, "session %lu: timed out after %d ms waiting for the peer inside a "
                "request (--io-timeout): closed", c->id, srv_cfg.io_timeout_ms);
    *over = 1;
    return -1;
}

int srv_mpi_serve(int lfd, int is_tcp)
{
    conn *cs = calloc((size_t)srv_cfg.max_clients, sizeof *cs);
    struct pollfd *p = calloc((size_t)srv_cfg.max_clients + 2, sizeof *p);
    unsigned long next_id = 1;
    int n = 0, i;
    if (!cs || !p) {
        srv_log(LOG_ERROR, "out of memory");
        free(cs);
        free(p);
        return -1;
    }
    for (;;) {
        double now = util_now();
        int wait = -1;
        for (i = n - 1; i >= 0; i--) {
            int over, ms = conn_deadline(&cs[i], now, &over);
            if (over) {
                conn_end(&cs[i]);
                cs[i] = cs[--n];
                continue;
            }
            if (ms >= 0 && (wait < 0 || ms < wait)) wait = ms;
        }
        p[0].fd = lfd;
        p[0].events = POLLIN;
        p[1].fd = srv_shutdown_fd;
        p[1].events = POLLIN;
        for (i = 0; i < n; i++) {
            p[i + 2].fd = cs[i].fd;
            p[i + 2].events = POLLIN;
            p[i + 2].revents = 0;
        }
        p[0].revents = p[1].revents = 0;
        if (poll(p, (nfds_t)n + 2, wait) < 0) {
            if (errno == EINTR) continue;
            break;
        }
        if (p[1].revents) break;
        for (i = n - 1; i >= 0; i--) {
            if (!p[i + 2].revents) continue;
            if (conn_read(&cs[i]) != 0) {
                conn_end(&cs[i]);
                cs[i] = cs[--n];
            }
        }
        if (p[0].revents & POLLIN) {
            int fd = accept(lfd, NULL, NULL), one = 1;
            conn *c;
            if (fd < 0) continue;
            if (n == srv_cfg.max_clients) {
                srv_log(LOG_WARN, "server busy: too many sessions (silcd --max-clients)");
                close(fd);
                continue;
            }
            if (is_tcp) setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
            c = &cs[n++];
            memset(c, 0, sizeof *c);
            c->fd = fd;
            c->id = next_id++;
            c->handshake_end = util_now() + srv_cfg.handshake_timeout_ms / 1000.0;
            /* The peer's entry of the authentication backoff, while it is connected. */
            srv_peer_of(fd, c->peer, sizeof c->peer);
            srv_auth_hold(c->peer);
        }
    }
    for (i = 0; i < n; i++) conn_end(&cs[i]);
    free(cs);
    free(p);
    return 0;
}
