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
 * ranks wait for rank 0's next command at rest, in poll() on a wake-up
 * socket from rank 0 (await_wake; await_header where there is none), and
 * end when that socket closes (rank 0 gone).
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE   /* getifaddrs, IFF_UP */
#include "server.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/syscall.h>
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

/* How a rank other than 0 takes rank 0's next command.  A blocking
 * MPI_Bcast would spin in Open MPI's progress engine (99 % of a core per
 * idle rank, for as long as the server runs), so the header comes by
 * MPI_Ibcast, tested in a loop: without sleeping for AWAIT_SPIN_S after the
 * last command (requests that follow each other pay nothing), then with
 * naps from AWAIT_NAP_MIN_NS doubling to AWAIT_NAP_MAX_NS.  A rank with a
 * wake-up socket (below) enters it only once rank 0's byte has come, so
 * the naps never start; one without one rests this way (2-4 % of a core). */
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

static srv_ranks the_ranks;
static ranks_impl the_impl;

/* ---- waking the resting ranks ------------------------------------------------
 *
 * Even MPI_Ibcast tested with naps costs a resting rank a few percent of a
 * core (Open MPI progresses the request on every test).  So a rank other
 * than 0 waits outside MPI, in poll() on a TCP socket to rank 0 that rank 0
 * writes one byte to before each command; only then does it join the
 * command's broadcast.  At start rank 0 listens on an ephemeral port of
 * every address, broadcasts over MPI its interface addresses (others first,
 * loopback last), the port and a random secret; each rank tries the
 * addresses in turn (WAKE_CONNECT_MS each), proves it holds the first half
 * of the secret and checks that rank 0 answers with the second half (a
 * stray listener on another host's address cannot).  Rank 0 keeps only
 * connections that present the secret (the others are closed and logged),
 * until every rank has finished trying (an MPI barrier), then closes the
 * listener.  A rank that could not connect (a firewall) waits by testing
 * MPI_Ibcast with naps as before, and says so once.  The socket closing
 * means rank 0 is gone: the rank exits, and with it the job.  docs/
 * distributed.md ("An idle server rests") gives the measured costs. */

#define WAKE_SECRET_BYTES 32          /* each half */
#define WAKE_MAX_ADDRS 16
#define WAKE_CONNECT_MS 1000          /* per address: connect, then rank 0's answer */

typedef struct wake_offer {
    uint8_t secret[2 * WAKE_SECRET_BYTES];  /* [0, 32): the rank's proof; the rest: rank 0's */
    int32_t port;                           /* 0: rank 0 could not listen */
    int32_t count;
    struct {
        int32_t family;                     /* AF_INET, AF_INET6 */
        uint8_t addr[16];
    } addr[WAKE_MAX_ADDRS];
} wake_offer;

/* What a rank sends on connecting: the proof, then its rank. */
#define WAKE_HELLO_BYTES (WAKE_SECRET_BYTES + 4)

static int *wake_fds;      /* rank 0: per rank, the socket, or -1 (that rank polls MPI) */
static int wake_fd = -1;   /* the other ranks: the socket from rank 0, or -1 */

/* Rank 0's addresses, loopback last; IPv6 link-local ones are left out
 * (they need an interface the other host would have to name). */
static void wake_addresses(wake_offer *o)
{
    struct ifaddrs *ifs = NULL, *i;
    int pass;
    o->count = 0;
    if (getifaddrs(&ifs) != 0) return;
    for (pass = 0; pass < 2; pass++)
        for (i = ifs; i && o->count < WAKE_MAX_ADDRS; i = i->ifa_next) {
            const struct sockaddr *sa = i->ifa_addr;
            int loop = (i->ifa_flags & IFF_LOOPBACK) != 0;
            if (!sa || !(i->ifa_flags & IFF_UP) || loop != pass) continue;
            if (sa->sa_family == AF_INET) {
                o->addr[o->count].family = AF_INET;
                memcpy(o->addr[o->count++].addr, &((const struct sockaddr_in *)sa)->sin_addr, 4);
            } else if (sa->sa_family == AF_INET6) {
                const struct in6_addr *a = &((const struct sockaddr_in6 *)sa)->sin6_addr;
                if (IN6_IS_ADDR_LINKLOCAL(a)) continue;
                o->addr[o->count].family = AF_INET6;
                memcpy(o->addr[o->count++].addr, a, 16);
            }
        }
    freeifaddrs(ifs);
}

/* A listener on an ephemeral port of every address (IPv6 and IPv4 when the
 * host has IPv6, else IPv4); its port in *port. */
static int wake_listen(int32_t *port)
{
    struct sockaddr_storage ss;
    socklen_t sl = sizeof ss;
    int fd = socket(AF_INET6, SOCK_STREAM, 0), off = 0;
    memset(&ss, 0, sizeof ss);
    if (fd >= 0) {
        struct sockaddr_in6 *a = (struct sockaddr_in6 *)&ss;
        setsockopt(fd, IPPROTO_IPV6, IPV6_V6ONLY, &off, sizeof off);
        a->sin6_family = AF_INET6;
        a->sin6_addr = in6addr_any;
        if (bind(fd, (struct sockaddr *)a, sizeof *a) != 0) {
            close(fd);
            fd = -1;
        }
    }
    if (fd < 0) {
        struct sockaddr_in *a = (struct sockaddr_in *)&ss;
        memset(&ss, 0, sizeof ss);
        a->sin_family = AF_INET;
        a->sin_addr.s_addr = htonl(INADDR_ANY);
        if ((fd = socket(AF_INET, SOCK_STREAM, 0)) < 0) return -1;
        if (bind(fd, (struct sockaddr *)a, sizeof *a) != 0) {
            close(fd);
            return -1;
        }
    }
    if (listen(fd, 64) != 0 || getsockname(fd, (struct sockaddr *)&ss, &sl) != 0) {
        close(fd);
        return -1;
    }
    *port = ntohs(ss.ss_family == AF_INET6 ? ((struct sockaddr_in6 *)&ss)->sin6_port
                                           : ((struct sockaddr_in *)&ss)->sin_port);
    fcntl(fd, F_SETFL, O_NONBLOCK);
    return fd;
}

static int same_bytes(const uint8_t *a, const uint8_t *b, size_t n)
{
    uint8_t d = 0;
    size_t i;
    for (i = 0; i < n; i++) d |= (uint8_t)(a[i] ^ b[i]);
    return d == 0;
}

/* Waits up to ms for fd to be ready for events; 1 if it is. */
static int wait_fd(int fd, short events, int ms)
{
    struct pollfd p;
    double end = util_now() + ms / 1000.0;
    p.fd = fd;
    p.events = events;
    for (;;) {
        int left = (int)((end - util_now()) * 1000), rc;
        if (left < 0) return 0;
        p.revents = 0;
        rc = poll(&p, 1, left);
        if (rc > 0) return 1;
        if (rc == 0 || errno != EINTR) return 0;
    }
}

/* A rank other than 0: the first of rank 0's addresses that answers with
 * its half of the secret; -1 if none does. */
static int wake_connect(const wake_offer *o, int rank, char *why, size_t whylen)
{
    uint8_t hello[WAKE_HELLO_BYTES], answer[WAKE_SECRET_BYTES];
    int k;
    memcpy(hello, o->secret, WAKE_SECRET_BYTES);
    proto_put_u32(hello + WAKE_SECRET_BYTES, (uint32_t)rank);
    snprintf(why, whylen, "rank 0 offered no address");
    for (k = 0; k < o->count; k++) {
        struct sockaddr_storage ss;
        socklen_t sl;
        size_t got = 0;
        int fd, err = 0, one = 1;
        char host[INET6_ADDRSTRLEN] = "?";
        memset(&ss, 0, sizeof ss);
        if (o->addr[k].family == AF_INET) {
            struct sockaddr_in *a = (struct sockaddr_in *)&ss;
            a->sin_family = AF_INET;
            a->sin_port = htons((uint16_t)o->port);
            memcpy(&a->sin_addr, o->addr[k].addr, 4);
            sl = sizeof *a;
            inet_ntop(AF_INET, &a->sin_addr, host, sizeof host);
        } else {
            struct sockaddr_in6 *a = (struct sockaddr_in6 *)&ss;
            a->sin6_family = AF_INET6;
            a->sin6_port = htons((uint16_t)o->port);
            memcpy(&a->sin6_addr, o->addr[k].addr, 16);
            sl = sizeof *a;
            inet_ntop(AF_INET6, &a->sin6_addr, host, sizeof host);
        }
        if ((fd = socket(ss.ss_family, SOCK_STREAM, 0)) < 0) continue;
        fcntl(fd, F_SETFL, O_NONBLOCK);
        if (connect(fd, (struct sockaddr *)&ss, sl) != 0 && errno != EINPROGRESS) err = errno;
        if (!err && !wait_fd(fd, POLLOUT, WAKE_CONNECT_MS)) err = ETIMEDOUT;
        sl = sizeof err;
        if (!err && getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &sl) != 0) err = errno;
        if (!err && send(fd, hello, sizeof hello, MSG_NOSIGNAL) != (ssize_t)sizeof hello)
            err = errno ? errno : EPIPE;
        while (!err && got < sizeof answer) {
            ssize_t r;
            if (!wait_fd(fd, POLLIN, WAKE_CONNECT_MS)) err = ETIMEDOUT;
            else if ((r = recv(fd, answer + got, sizeof answer - got, 0)) > 0) got += (size_t)r;
            else if (r == 0) err = ECONNRESET;
            else if (errno != EINTR && errno != EAGAIN) err = errno;
        }
        if (!err && !same_bytes(answer, o->secret + WAKE_SECRET_BYTES, sizeof answer)) err = EPROTO;
        if (!err) {
            fcntl(fd, F_SETFL, 0);
            setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
            return fd;
        }
        snprintf(why, whylen, "%s port %d: %s", host, (int)o->port,
                 err == EPROTO ? "not rank 0 (wrong answer)" : strerror(err));
        close(fd);
    }
    return -1;
}

/* A connection to rank 0's wake-up listener, until it has shown its hello. */
typedef struct wake_pending {
    int fd;
    size_t got;
    uint8_t hello[WAKE_HELLO_BYTES];
} wake_pending;

/* Rank 0, one pending connection readable: its hello judged once whole.
 * 1 while incomplete; 0 when judged (kept in wake_fds or closed). */
static int wake_judge(wake_pending *w, const wake_offer *o, int size)
{
    ssize_t r = recv(w->fd, w->hello + w->got, sizeof w->hello - w->got, MSG_DONTWAIT);
    uint32_t rank;
    int one = 1;
    if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return 1;
    if (r > 0 && (w->got += (size_t)r) < sizeof w->hello) return 1;
    rank = proto_get_u32(w->hello + WAKE_SECRET_BYTES);
    if (r <= 0 || !same_bytes(w->hello, o->secret, WAKE_SECRET_BYTES) || rank == 0 ||
        rank >= (uint32_t)size || wake_fds[rank] >= 0) {
        char peer[64];
        srv_peer_of(w->fd, peer, sizeof peer);
        srv_log(LOG_WARN, "wake-up port: closed a connection from %s that did not present "
                "the job's secret", *peer ? peer : "?");
        close(w->fd);
        return 0;
    }
    fcntl(w->fd, F_SETFL, 0);
    setsockopt(w->fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    if (send(w->fd, o->secret + WAKE_SECRET_BYTES, WAKE_SECRET_BYTES, MSG_NOSIGNAL) !=
        WAKE_SECRET_BYTES) {
        close(w->fd);
        return 0;
    }
    wake_fds[rank] = w->fd;
    return 0;
}

/* Rank 0: accepts and judges connections until every rank has finished
 * trying (the barrier req completes), then closes the listener and what
 * has not shown a hello. */
static void wake_accept(int lfd, const wake_offer *o, int size, MPI_Request *req)
{
    int cap = 2 * size + 8, n = 0, i, done = 0;
    wake_pending *w = calloc((size_t)cap, sizeof *w);
    struct pollfd *p = calloc((size_t)cap + 1, sizeof *p);
    while (w && p && !done) {
        p[0].fd = lfd;
        p[0].events = POLLIN;
        p[0].revents = 0;
        for (i = 0; i < n; i++) {
            p[i + 1].fd = w[i].fd;
            p[i + 1].events = POLLIN;
            p[i + 1].revents = 0;
        }
        poll(p, (nfds_t)n + 1, 10);
        for (i = n - 1; i >= 0; i--)
            if (p[i + 1].revents && !wake_judge(&w[i], o, size)) w[i] = w[--n];
        if (p[0].revents & POLLIN) {
            int fd = accept(lfd, NULL, NULL);
            if (fd >= 0 && n == cap) {
                srv_log(LOG_WARN, "wake-up port: too many connections, one closed");
                close(fd);
            } else if (fd >= 0) {
                fcntl(fd, F_SETFL, O_NONBLOCK);
                memset(&w[n], 0, sizeof w[n]);
                w[n++].fd = fd;
            }
        }
        if (MPI_Test(req, &done, MPI_STATUS_IGNORE) != MPI_SUCCESS) break;
    }
    if (!done) MPI_Wait(req, MPI_STATUS_IGNORE);   /* out of memory: no socket, but in step */
    for (i = 0; i < n; i++) {
        if (w[i].got) srv_log(LOG_WARN, "wake-up port: closed a connection that did not finish "
                              "presenting the job's secret");
        close(w[i].fd);
    }
    close(lfd);
    free(w);
    free(p);
}

/* Collective, at start: the wake-up sockets (above) on the ranks that can
 * reach rank 0; the others are told, and say once, that they poll MPI. */
static void wake_setup(int rank, int size)
{
    wake_offer o;
    MPI_Request req;
    uint8_t *kept = calloc((size_t)size, 1);
    int lfd = -1, i, n = 0;
    char why[256];
    memset(&o, 0, sizeof o);
    if (rank == 0) wake_fds = malloc((size_t)size * sizeof *wake_fds);
    if (!kept || (rank == 0 && !wake_fds)) {  /* the ranks would leave step: the job ends */
        srv_log(LOG_ERROR, "rank %d: out of memory setting up wake-ups", rank);
        MPI_Abort(MPI_COMM_WORLD, 70);
    }
    if (rank == 0) {
        int rnd = open("/dev/urandom", O_RDONLY);
        for (i = 0; i < size; i++) wake_fds[i] = -1;
        if (rnd >= 0 &&
            read(rnd, o.secret, sizeof o.secret) == (ssize_t)sizeof o.secret &&
            (lfd = wake_listen(&o.port)) >= 0)
            wake_addresses(&o);
        if (rnd >= 0) close(rnd);
        if (lfd < 0 || !o.count) {
            srv_log(LOG_WARN, "rank 0: no wake-up listener (%s): resting ranks will poll MPI",
                    lfd < 0 ? strerror(errno) : "no address");
            o.count = 0;
        }
    }
    MPI_Bcast(&o, (int)sizeof o, MPI_BYTE, 0, the_impl.wake);
    if (rank != 0 && o.count) wake_fd = wake_connect(&o, rank, why, sizeof why);
    MPI_Ibarrier(the_impl.wake, &req);
    if (rank == 0 && lfd >= 0) wake_accept(lfd, &o, size, &req);
    else MPI_Wait(&req, MPI_STATUS_IGNORE);
    if (rank == 0)
        for (i = 1; i < size; i++) n += kept[i] = wake_fds[i] >= 0;
    MPI_Bcast(kept, size, MPI_BYTE, 0, the_impl.wake);
    if (rank == 0) {
        srv_log(LOG_INFO, "%d of %d ranks rest on a wake-up socket", n, size - 1);
    } else if (!kept[rank]) {
        if (wake_fd >= 0) close(wake_fd);
        wake_fd = -1;
        srv_log(LOG_WARN, "rank %d: cannot reach rank 0 for wake-ups (%s): resting by polling "
                "MPI instead (a few %% of a core; docs/distributed.md)", rank,
                o.count ? why : "rank 0 has no wake-up listener");
    }
    free(kept);
}

/* Rank 0, before a command: a byte to every rank that rests on a socket
 * (a full buffer already wakes it; a rank gone is MPI's to notice). */
static void wake_ranks(int size)
{
    int i;
    for (i = 1; wake_fds && i < size; i++)
        if (wake_fds[i] >= 0 && send(wake_fds[i], "w", 1, MSG_DONTWAIT | MSG_NOSIGNAL) < 0 &&
            errno != EAGAIN && errno != EWOULDBLOCK)
            srv_log(LOG_WARN, "rank 0: waking rank %d: %s", i, strerror(errno));
}

/* The kernel's struct sched_attr (glibc before 2.41 declares none). */
struct sched_attr_v1 {
    uint32_t size, sched_policy;
    uint64_t sched_flags;
    int32_t sched_nice;
    uint32_t sched_priority;
    uint64_t sched_runtime, sched_deadline, sched_period;
};

/* A task that has slept long is woken with no credit by Linux's EEVDF
 * scheduler (6.6 and later): on a busy machine it waited 2-4 ms for a CPU
 * after rank 0's byte.  A short time slice (sched_runtime of a normal
 * task, honoured since Linux 6.12; ignored before) gives it an early
 * deadline, so its wake-up preempts: the rank asks for REST_SLICE_NS while
 * it rests and for the default (0) once woken, so its computing is not cut
 * into short slices.  Failure changes nothing but the wake-up delay. */
#define REST_SLICE_NS 100000
static void rest_slice(int resting)
{
#ifdef SYS_sched_setattr
    struct sched_attr_v1 a;
    memset(&a, 0, sizeof a);
    a.size = sizeof a;
    a.sched_policy = 0;   /* SCHED_OTHER */
    a.sched_runtime = resting ? REST_SLICE_NS : 0;
    (void)syscall(SYS_sched_setattr, 0, &a, 0);
#else
    (void)resting;
#endif
}

/* A rank other than 0: rank 0's byte for the next command.  For
 * AWAIT_SPIN_S it is looked for without sleeping (requests that follow each
 * other pay no wake-up), then awaited in poll.  The socket closing means
 * rank 0 has gone (killed, or ended by a limit): this rank ends too. */
static void await_wake(int rank)
{
    double spin_until = util_now() + AWAIT_SPIN_S;
    for (;;) {
        char b;
        ssize_t got = recv(wake_fd, &b, 1, MSG_DONTWAIT);
        if (got == 1) return;
        if (got == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
            srv_log(LOG_ERROR, "rank %d: rank 0 is gone (%s): ending this rank", rank,
                    got == 0 ? "its wake-up socket closed" : strerror(errno));
            _exit(1);
        }
        if (util_now() >= spin_until) {
            rest_slice(1);
            wait_fd(wake_fd, POLLIN, 60000);
            rest_slice(0);
        }
    }
}

/* The three header words of a command (rank 0 sends, the others wait:
 * on their wake-up socket if they have one, then in the broadcast). */
static int header_bcast(ranks_impl *I, int64_t h[3], int rank)
{
    MPI_Request req;
    if (rank == 0) wake_ranks(the_ranks.size);
    else if (wake_fd >= 0) await_wake(rank);
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
    wake_setup(the_ranks.rank, the_ranks.size);
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
    int i;
    if (!srv_mpi) return;
    if (srv_mpi->rank == 0) r_command(srv_mpi, SRV_CMD_STOP, 0, NULL);
    for (i = 0; wake_fds && i < srv_mpi->size; i++)
        if (wake_fds[i] >= 0) close(wake_fds[i]);
    free(wake_fds);
    wake_fds = NULL;
    if (wake_fd >= 0) close(wake_fd);
    wake_fd = -1;
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
 * Replies are queued by the session and written by this loop as the socket
 * takes them (srv_session_flush): a connection whose reply waits is not
 * read until the reply is out, and is dropped when its client takes no
 * byte of it for --io-timeout, so a client that does not read its GET
 * stalls no one.  A session that sends nothing for --idle-timeout between
 * requests is closed, as by the forking server (srv_session_expire); a
 * newcomer is admitted by the same rules (srv_admit: --max-clients,
 * --peer-share, the oldest unauthenticated connection giving way). */

#define READ_CHUNK ((size_t)64 << 10)   /* a buffer grows by at least this, at most doubling */

typedef struct conn {
    int fd;
    unsigned long id;
    session *S;             /* NULL while in the handshake */
    char peer[64];
    double accepted;
    double handshake_end;   /* while S is NULL */
    double last_byte;       /* when a byte last went either way: --io-timeout, --idle-timeout */
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
    /* The reply goes out now if the socket takes it (a client that reads
     * pays no poll round), else as the client reads (srv_mpi_serve). */
    c->last_byte = util_now();
    if (!rc && c->S && srv_session_flush(c->S) < 0) rc = -1;
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
    int writing = c->S && srv_session_pending(c->S), idle = 0;
    *over = 0;
    if (!c->S) end = c->handshake_end;
    else if (c->kept || c->drop || writing) end = c->last_byte + srv_cfg.io_timeout_ms / 1000.0;
    else if (srv_cfg.idle_timeout_ms > 0) {
        end = c->last_byte + srv_cfg.idle_timeout_ms / 1000.0;
        idle = 1;
    }
    if (end < 0) return -1;
    if (now < end) return (int)((end - now) * 1000) + 1;
    if (!c->S)
        srv_log(LOG_INFO, "session %lu: no handshake within %g s, closed (--handshake-timeout)",
                c->id, srv_cfg.handshake_timeout_ms / 1000.0);
    else if (idle)
        srv_session_expire(c->S);   /* says why; conn_end writes it if the socket takes it */
    else
        srv_log(LOG_INFO, "session %lu: timed out after %d ms waiting for the peer %s "
                "(--io-timeout): closed", c->id, srv_cfg.io_timeout_ms,
                writing ? "to read a reply" : "inside a request");
    *over = 1;
    return -1;
}

/* The connection's reply waits: written as far as the socket takes it.
 * 0, or -1 when the connection is over. */
static int conn_write(conn *c)
{
    uint64_t before = srv_session_pending(c->S);
    int rc = srv_session_flush(c->S);
    if (rc < 0) return -1;
    if (srv_session_pending(c->S) < before) c->last_byte = util_now();
    return 0;
}

static conn *admit_cs;   /* srv_mpi_serve's connections, for conn_at */
static int admit_n;

static void conn_at(void *user, int i, srv_slot_view *v)
{
    (void)user;
    v->live = i < admit_n;
    v->handshaking = v->live && !admit_cs[i].S;
    v->peer = admit_cs[i].peer;
    v->accepted = admit_cs[i].accepted;
}

/* A new connection: a slot by srv_admit (closing the oldest unauthenticated
 * connection in the way), or refused with the reason.  Returns the new n. */
static int conn_admit(conn *cs, int n, int fd, int is_tcp, unsigned long id)
{
    char peer[64], why[256];
    int one = 1, evict, slot;
    conn *c;
    srv_peer_of(fd, peer, sizeof peer);
    admit_cs = cs;
    admit_n = n;
    slot = srv_admit(peer, srv_cfg.max_clients, conn_at, NULL, &evict, why, sizeof why);
    if (slot < 0) {
        srv_log(LOG_WARN, "refusing a connection%s%s: %s", *peer ? " from " : "", peer, why);
        srv_refuse(fd, why);
        return n;
    }
    if (evict) {
        srv_log(LOG_WARN, "session %lu%s%s: closed unauthenticated to make room (%s)", cs[slot].id,
                *cs[slot].peer ? " from " : "", cs[slot].peer, why);
        conn_end(&cs[slot]);
    } else {
        slot = n++;   /* srv_admit gives the first free slot: n */
    }
    if (is_tcp) setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    c = &cs[slot];
    memset(c, 0, sizeof *c);
    c->fd = fd;
    c->id = id;
    c->accepted = util_now();
    c->handshake_end = c->accepted + srv_cfg.handshake_timeout_ms / 1000.0;
    /* The peer's entry of the authentication backoff, while it is connected. */
    snprintf(c->peer, sizeof c->peer, "%s", peer);
    srv_auth_hold(c->peer);
    return n;
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
            p[i + 2].events = cs[i].S && srv_session_pending(cs[i].S) ? POLLOUT : POLLIN;
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
            if ((p[i + 2].events == POLLOUT ? conn_write(&cs[i]) : conn_read(&cs[i])) != 0) {
                conn_end(&cs[i]);
                cs[i] = cs[--n];
            }
        }
        if (p[0].revents & POLLIN) {
            int fd = accept(lfd, NULL, NULL);
            if (fd >= 0) n = conn_admit(cs, n, fd, is_tcp, next_id++);
        }
    }
    for (i = 0; i < n; i++) conn_end(&cs[i]);
    free(cs);
    free(p);
    return 0;
}
