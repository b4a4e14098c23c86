/*
 * remote.c -- the client transport of remote contexts (client.h): connect and
 * handshake, then one request frame per call and its replies.
 *
 * Arrays travel without being copied: a PUT sends the envelope's own arrays
 * with one sendmsg (header, descriptor, name, rowptr, colind, values), and a
 * VALUE reply is received straight into freshly allocated envelope arrays.
 *
 * The client trusts the server no more than the server trusts it: every
 * reply goes through protocol.c's checks (lengths against the descriptor,
 * CSR structure by the store's checked constructor), a value larger than
 * SILC_MAX_REPLY_BYTES (default 2 GiB) or a text over 64 MiB is refused
 * before anything is allocated, and a server that stops sending is an error
 * naming it after SILC_IO_TIMEOUT seconds (default 300).  The wait for an
 * EXEC's first reply has no timeout unless SILC_EXEC_TIMEOUT is set, since a
 * statement may compute for as long as it needs; a server whose machine
 * vanishes (no FIN ever comes) is found by TCP keepalive probes within about
 * 25 s (keep_alive below).
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE   /* TCP_KEEPIDLE and friends */
#include "client.h"

#include <errno.h>
#include <math.h>
#include <netdb.h>
#include <sched.h>
#include <stdatomic.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include "store.h"

/* A reply may take hours, so waiting for it has no timeout; a server whose
 * host dies or drops off the network is detected by the kernel instead:
 * probes after 10 s of silence, every 5 s, 3 unanswered end the connection
 * (25 s, under silcd's default --io-timeout of 30 s). */
static void keep_alive(int fd)
{
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_KEEPALIVE, &one, sizeof one);
#if defined(TCP_KEEPIDLE) && defined(TCP_KEEPINTVL) && defined(TCP_KEEPCNT)
    {
        int idle = 10, interval = 5, count = 3;
        setsockopt(fd, IPPROTO_TCP, TCP_KEEPIDLE, &idle, sizeof idle);
        setsockopt(fd, IPPROTO_TCP, TCP_KEEPINTVL, &interval, sizeof interval);
        setsockopt(fd, IPPROTO_TCP, TCP_KEEPCNT, &count, sizeof count);
    }
#endif
}

/* Whether a CANCEL may be written now (rem_cancel): only while an EXEC
 * waits for its reply, when nothing else is being sent, so its 16 bytes
 * never land inside another frame. */
enum { EXEC_IDLE, EXEC_AWAITING, EXEC_CANCELLING };

struct rem_conn {
    int fd;
    int broken;
    int io_timeout_ms;         /* SILC_IO_TIMEOUT: the longest silence inside a reply; -1 none */
    int exec_timeout_ms;       /* SILC_EXEC_TIMEOUT: the longest wait for an EXEC's reply; -1 none */
    proto_limits limits;       /* SILC_MAX_REPLY_BYTES per value; text as silcd's statements */
    atomic_int exec_state;   /* EXEC_*; lock-free, so rem_cancel is async-signal-safe */
    atomic_int cancel_sent;    /* a CANCEL went out for the EXEC awaited: its TEXT is dropped */
    proto_spin_memo spin;      /* how long the first reply to each kind of request took */
    char url[512];
};

/* Defaults of the client's reply limits (docs/remote.md, "What a client
 * accepts"): 2 GiB per value, text up to silcd's own 64 MiB statement cap,
 * 300 s of silence inside a reply. */
#define CLIENT_MAX_VALUE_BYTES ((uint64_t)2 << 30)
#define CLIENT_MAX_TEXT_BYTES ((uint64_t)64 << 20)
#define CLIENT_IO_TIMEOUT_S 300.0
/* A timeout other than 0 (none) lies in [1 ms, poll's resolution, and a
 * year]: 1e-7 was rounded up to 1 ms without a word, 1e30 refused without
 * naming the maximum. */
#define CLIENT_TIMEOUT_MIN_S 0.001
#define CLIENT_TIMEOUT_MAX_S 31536000.0

/* Seconds from the variable var (a decimal, 0 = no timeout), else dflt, as
 * poll's milliseconds (-1 for none); -1 with a message naming var. */
static int timeout_from_env(const char *var, double dflt, int *ms, char *err, size_t errlen)
{
    const char *v = getenv(var);
    double sec = dflt;
    if (v && *v) {
        char *end;
        errno = 0;
        sec = strtod(v, &end);
        if (*end || end == v || errno ||
            !(sec == 0 || (sec >= CLIENT_TIMEOUT_MIN_S && sec <= CLIENT_TIMEOUT_MAX_S))) {
            snprintf(err, errlen, "%s = '%s': expected 0 (no timeout) or seconds from 0.001 to 31536000", var,
                     v);
            return -1;
        }
    }
    *ms = sec > 0 ? (int)ceil(sec * 1000) : -1;
    return 0;
}

/* The connection's limits and timeouts from the environment. */
static int limits_from_env(rem_conn *c, char *err, size_t errlen)
{
    const char *v = getenv("SILC_MAX_REPLY_BYTES");
    char why[160];
    c->limits.max_value_bytes = CLIENT_MAX_VALUE_BYTES;
    c->limits.max_text_bytes = CLIENT_MAX_TEXT_BYTES;
    if (v && *v && util_parse_size(v, (uint64_t)INT64_MAX, &c->limits.max_value_bytes, why, sizeof why)) {
        snprintf(err, errlen, "SILC_MAX_REPLY_BYTES = '%s': %s", v, why);
        return -1;
    }
    if (timeout_from_env("SILC_IO_TIMEOUT", CLIENT_IO_TIMEOUT_S, &c->io_timeout_ms, err, errlen))
        return -1;
    return timeout_from_env("SILC_EXEC_TIMEOUT", 0, &c->exec_timeout_ms, err, errlen);
}

static int connect_addr(const proto_addr *a, char *err, size_t errlen)
{
    int fd = -1, one = 1, rc;
    if (a->is_unix) {
        struct sockaddr_un sa;
        memset(&sa, 0, sizeof sa);
        sa.sun_family = AF_UNIX;
        memcpy(sa.sun_path, a->path, strlen(a->path) + 1);
        fd = socket(AF_UNIX, SOCK_STREAM, 0);
        if (fd >= 0 && connect(fd, (struct sockaddr *)&sa, sizeof sa) == 0) return fd;
        snprintf(err, errlen, "%s", strerror(errno));
    } else {
        struct addrinfo hints, *res = NULL, *ai;
        memset(&hints, 0, sizeof hints);
        hints.ai_socktype = SOCK_STREAM;
        rc = getaddrinfo(a->host, a->port, &hints, &res);
        if (rc) {
            snprintf(err, errlen, "%s", gai_strerror(rc));
            return -1;
        }
        snprintf(err, errlen, "no address");
        for (ai = res; ai; ai = ai->ai_next) {
            fd = socket(ai->ai_family, ai->ai_socktype, ai->ai_protocol);
            if (fd < 0) continue;
            if (connect(fd, ai->ai_addr, ai->ai_addrlen) == 0) break;
            snprintf(err, errlen, "%s", strerror(errno));
            close(fd);
            fd = -1;
        }
        freeaddrinfo(res);
        /* Small requests must not wait for Nagle's coalescing. */
        if (fd >= 0) setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
        if (fd >= 0) keep_alive(fd);
        if (fd >= 0) return fd;
    }
    if (fd >= 0) close(fd);
    return -1;
}

static int lost(rem_conn *c, const char *why, char *err, size_t errlen)
{
    c->broken = 1;
    snprintf(err, errlen, "connection to silc server %s lost: %s", c->url, why);
    return -1;
}

/* A reply that could not be read (rc from protocol.c).  A value over the
 * cap was skipped whole (PROTO_REFUSED): the session goes on.  Otherwise
 * the stream is out of step, so the connection is closed and later calls
 * say so; the message says whether the server fell silent, closed, or sent
 * something a server must not. */
static int bad_reply(rem_conn *c, int rc, const char *why, char *err, size_t errlen)
{
    if (rc == PROTO_REFUSED) {
        snprintf(err, errlen, "silc server %s: reply refused: %s", c->url, why);
        return -1;
    }
    if (rc != PROTO_BROKEN) {
        c->broken = 1;
        snprintf(err, errlen, "silc server %s sent a bad reply: %s (connection closed)", c->url,
                 why);
        return -1;
    }
    if (strncmp(why, "timed out", 9) == 0) {
        c->broken = 1;
        snprintf(err, errlen, "silc server %s stopped sending in the middle of a reply: %s "
                 "(SILC_IO_TIMEOUT; connection closed)", c->url, why);
        return -1;
    }
    return lost(c, why, err, errlen);
}

/* Waits up to timeout_ms (-1: for ever) for the first byte of a reply; -1
 * with why ("sent nothing for 300 s (SILC_IO_TIMEOUT)") when none came.
 * Always here, never in proto_recv, whose waits are the I/O timeout: an
 * EXEC's reply may rightly take longer.  Spins spin_ns first, so that a
 * small request's round trip does not pay for waking a sleeping thread
 * (client.h, PROTO_SPIN_NS: how long is learned per kind of request). */
static int await_first_byte(rem_conn *c, int timeout_ms, const char *var, int64_t spin_ns,
                            char *why, size_t whylen)
{
    struct pollfd p;
    int rc;
    p.fd = c->fd;
    p.events = POLLIN;
    if (proto_spin(&p, 1, spin_ns)) return 0;
    do rc = poll(&p, 1, timeout_ms);
    while (rc < 0 && errno == EINTR);
    if (rc > 0) return 0;
    if (rc < 0) snprintf(why, whylen, "poll: %s", strerror(errno));
    else snprintf(why, whylen, "sent nothing for %g s (%s)", timeout_ms / 1000.0, var);
    return -1;
}

/* The reply that ends a request: OK, ERROR (its text into err), or VALUE into
 * *env when env is not NULL.  TEXT and WARN before it go to fn and warnings.
 * Each reply frame is awaited for the I/O timeout, or for an EXEC (exec set)
 * the EXEC timeout; inside a frame every wait is the I/O timeout.  kind
 * (proto_spin_kind of the request; 0 for none) sets and learns how long the
 * wait for the first frame spins; later frames follow it at once. */
static int await_reply(rem_conn *c, silc_envelope_t *env, silc_output_fn fn, void *user,
                       strbuf *warnings, int exec, uint64_t kind, char *err, size_t errlen)
{
    proto_stream s = {c->fd, c->io_timeout_ms, NULL, 0, 0};
    int64_t spin_ns = kind ? proto_spin_budget(&c->spin, kind) : PROTO_SPIN_NS,
            started = proto_now_ns();
    size_t dropped = 0; /* bytes of TEXT dropped after a CANCEL */
    for (;;) {
        proto_reply r;
        char why[512];
        int rc;
        if (await_first_byte(c, exec ? c->exec_timeout_ms : c->io_timeout_ms,
                             exec ? "SILC_EXEC_TIMEOUT" : "SILC_IO_TIMEOUT", spin_ns, why,
                             sizeof why)) {
            c->broken = 1;
            snprintf(err, errlen, "silc server %s %s; connection closed", c->url, why);
            return -1;
        }
        if (kind) {
            proto_spin_learn(&c->spin, kind, proto_now_ns() - started);
            kind = 0;
            spin_ns = PROTO_SPIN_NS;
        }
        if ((rc = proto_read_reply(&s, &c->limits, &r, why, sizeof why)))
            return bad_reply(c, rc, why, err, errlen);
        switch (r.op) {
        case PROTO_TEXT:
            /* After a CANCEL, output the statement made before it
             * stopped may still be on its way (silcd sends it every 20
             * ms, and the sockets hold hundreds of KB of a loop that
             * shows a value per iteration: half a second on a terminal).
             * The interrupt should be seen at once, so that output is
             * dropped and counted in a warning. */
            if (atomic_load(&c->cancel_sent)) dropped += strlen(r.text);
            else if (fn) fn(user, r.text);
            else fputs(r.text, stdout);
            break;
        case PROTO_WARN:
            if (warnings) sb_puts(warnings, r.text);
            break;
        case PROTO_OK:
            proto_reply_free(&r);
            return env ? bad_reply(c, PROTO_FATAL, "OK reply where a value was expected", err, errlen) : 0;
        case PROTO_ERROR:
            snprintf(err, errlen, "%s", r.text);
            proto_reply_free(&r);
            if (dropped && warnings)
                sb_printf(warnings, "interrupted: %zu bytes of the statement's output, still on the way "
                          "from the server, were not shown\n", dropped);
            return -1;
        default: /* PROTO_VALUE */
            if (!env) {
                proto_reply_free(&r);
                return bad_reply(c, PROTO_FATAL, "unexpected VALUE reply", err, errlen);
            }
            *env = r.env;
            memset(&r.env, 0, sizeof r.env);
            proto_reply_free(&r);
            return 0;
        }
        proto_reply_free(&r);
    }
}

static int usable(rem_conn *c, char *err, size_t errlen)
{
    if (!c->broken) return 0;
    snprintf(err, errlen, "connection to silc server %s was lost earlier; open a new context",
             c->url);
    return -1;
}

int rem_open(rem_conn **out, const char *url, const char *token, char *err, size_t errlen)
{
    proto_addr a;
    rem_conn *c;
    uint8_t hello[PROTO_HELLO_BYTES];
    struct iovec iov[2];
    proto_stream s;
    uint32_t version;
    char *tok = NULL, why[512];
    size_t toklen = token ? strlen(token) : 0;
    const uint16_t probe = 1;
    *out = NULL;
    if (*(const uint8_t *)&probe != 1) {
        snprintf(err, errlen, "remote mode needs a little-endian host");
        return -1;
    }
    if (proto_parse_url(url, &a, err, errlen)) return -1;
    if (toklen > PROTO_MAX_TOKEN) {
        snprintf(err, errlen, "token longer than %u bytes", PROTO_MAX_TOKEN);
        return -1;
    }
    if (!(c = calloc(1, sizeof *c))) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    snprintf(c->url, sizeof c->url, "%s", url);
    if (limits_from_env(c, err, errlen)) {
        free(c);
        return -1;
    }
    if ((c->fd = connect_addr(&a, why, sizeof why)) < 0) {
        snprintf(err, errlen, "cannot connect to silc server %s: %s", url, why);
        free(c);
        return -1;
    }
    proto_encode_hello(hello, PROTO_VERSION, (uint32_t)toklen);
    iov[0].iov_base = hello;
    iov[0].iov_len = sizeof hello;
    iov[1].iov_base = (void *)(uintptr_t)token;
    iov[1].iov_len = toklen;
    s = (proto_stream){c->fd, c->io_timeout_ms, NULL, 0, 0};
    if (proto_send(c->fd, iov, 2, c->io_timeout_ms, why, sizeof why) ||
        await_first_byte(c, c->io_timeout_ms, "SILC_IO_TIMEOUT", PROTO_SPIN_NS, why, sizeof why) ||
        proto_read_hello(&s, &version, &tok, why, sizeof why)) {
        snprintf(err, errlen, "handshake with silc server %s failed: %s", url, why);
        free(tok);
        close(c->fd);
        free(c);
        return -1;
    }
    free(tok);
    if (await_reply(c, NULL, NULL, NULL, NULL, 0, 0, why, sizeof why)) {
        if (c->broken) snprintf(err, errlen, "%s", why);
        else snprintf(err, errlen, "silc server %s refused the connection: %s", url, why);
        close(c->fd);
        free(c);
        return -1;
    }
    *out = c;
    return 0;
}

void rem_close(rem_conn **pc)
{
    rem_conn *c;
    char why[256];
    if (!pc || !*pc) return;
    c = *pc;
    /* Closing waits 5 s at most for the server's goodbye. */
    if (c->io_timeout_ms < 0 || c->io_timeout_ms > 5000) c->io_timeout_ms = 5000;
    if (!c->broken && proto_send_text(c->fd, PROTO_BYE, NULL, 5000, why, sizeof why) == 0)
        await_reply(c, NULL, NULL, NULL, NULL, 0, 0, why, sizeof why);
    close(c->fd);
    free(c);
    *pc = NULL;
}

int rem_put(rem_conn *c, const char *name, const silc_envelope_t *e, char *err, size_t errlen)
{
    proto_desc d;
    proto_layout L;
    uint8_t desc[PROTO_DESC_BYTES];
    struct iovec body[5];
    char why[512];
    if (usable(c, err, errlen)) return -1;
    memset(&d, 0, sizeof d);
    d.format = (uint32_t)e->format;
    d.namelen = (uint32_t)strlen(name);
    d.m = e->m;
    d.n = e->n;
    /* CSR envelopes were checked by env_check, so rowptr[m] is their count. */
    d.nnz = env_format_base((int)e->format) == SILC_CSR ? e->rowptr[e->m] : e->nnz;
    if (env_format_base((int)e->format) == SILC_BAND) {
        d.kl = e->kl;
        d.ku = e->ku;
    }
    if (env_format_base((int)e->format) == SILC_DENSE) d.nnz = e->m * e->n;
    if (d.namelen > PROTO_MAX_NAME) {
        snprintf(err, errlen, "name longer than %u bytes", PROTO_MAX_NAME);
        return -1;
    }
    if (proto_layout_of(&d, UINT64_MAX, &L, why, sizeof why)) {
        snprintf(err, errlen, "'%s': %s", name, why);
        return -1;
    }
    proto_encode_desc(desc, &d);
    body[0].iov_base = desc;
    body[0].iov_len = sizeof desc;
    body[1].iov_base = (void *)(uintptr_t)name;
    body[1].iov_len = d.namelen;
    body[2].iov_base = e->rowptr;
    body[2].iov_len = (size_t)L.rowptr_bytes;
    body[3].iov_base = e->colind;
    body[3].iov_len = (size_t)L.colind_bytes;
    body[4].iov_base = e->values;
    body[4].iov_len = (size_t)L.values_bytes;
    if (proto_send_frame(c->fd, PROTO_PUT, body, 5, c->io_timeout_ms, why, sizeof why))
        return lost(c, why, err, errlen);
    return await_reply(c, NULL, NULL, NULL, NULL, 0, proto_spin_kind(PROTO_PUT, name), err, errlen);
}

int rem_get(rem_conn *c, silc_envelope_t *e, const char *name, int accept_complex, char *err,
            size_t errlen)
{
    char why[512];
    if (usable(c, err, errlen)) return -1;
    if (proto_send_text(c->fd, accept_complex ? PROTO_GET_COMPLEX : PROTO_GET, name, c->io_timeout_ms,
                        why, sizeof why))
        return lost(c, why, err, errlen);
    if (await_reply(c, e, NULL, NULL, NULL, 0, proto_spin_kind(PROTO_GET, name), err, errlen))
        return -1;
    /* A plain GET's caller reads real values only (silc.h): a server that
     * answers it with a complex one breaks the protocol, and the caller
     * must not read half of each entry. */
    if (!accept_complex && silc_envelope_is_complex(e)) {
        silc_envelope_free(e);
        return bad_reply(c, PROTO_FATAL, "a complex value in reply to a GET, which asks for real "
                         "values only", err, errlen);
    }
    return 0;
}

int rem_exec(rem_conn *c, const char *statements, silc_output_fn fn, void *user,
             strbuf *warnings, char *err, size_t errlen)
{
    char why[512];
    int rc, state;
    if (usable(c, err, errlen)) return -1;
    if (proto_send_text(c->fd, PROTO_EXEC, statements, c->io_timeout_ms, why, sizeof why))
        return lost(c, why, err, errlen);
    atomic_store(&c->cancel_sent, 0);
    atomic_store(&c->exec_state, EXEC_AWAITING);
    rc = await_reply(c, NULL, fn, user, warnings, 1, proto_spin_kind(PROTO_EXEC, statements), err,
                     errlen);
    /* A CANCEL being written (another thread) finishes before the next
     * request may be sent; a signal handler's has finished by now. */
    for (;;) {
        state = EXEC_AWAITING;
        if (atomic_compare_exchange_strong(&c->exec_state, &state, EXEC_IDLE)) break;
        if (state == EXEC_IDLE) break;
        sched_yield();
    }
    atomic_store(&c->cancel_sent, 0); /* the next request's text is shown */
    return rc;
}

int rem_cancel(rem_conn *c)
{
    uint8_t frame[PROTO_HEADER_BYTES];
    size_t sent = 0;
    int state = EXEC_AWAITING, saved_errno = errno;
    if (!c) return -1;
    if (!atomic_compare_exchange_strong(&c->exec_state, &state, EXEC_CANCELLING)) return 0;
    proto_encode_header(frame, PROTO_CANCEL, 0);
    /* Output that arrives from now on is the backlog of a statement being
     * stopped: marked before the frame goes, or the reader could show what
     * the server sent in answer to it while this thread had not yet set it. */
    atomic_store(&c->cancel_sent, 1);
    /* send() is async-signal-safe; proto_send polls and formats messages. */
    while (sent < sizeof frame) {
        ssize_t n = send(c->fd, frame + sent, sizeof frame - sent, MSG_NOSIGNAL);
        if (n > 0) sent += (size_t)n;
        else if (n < 0 && errno == EINTR) continue;
        else break; /* the connection is failing: the reply's read says so */
    }
    atomic_store(&c->exec_state, EXEC_AWAITING);
    errno = saved_errno; /* a signal handler must leave errno as it found it */
    return 0;
}
