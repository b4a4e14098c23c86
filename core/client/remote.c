/*
 * remote.c -- the client transport of remote contexts (client.h): connect and
 * handshake, then one request frame per call and its replies.
 *
 * Arrays travel without being copied: a PUT sends the envelope's own arrays
 * with one sendmsg (header, descriptor, name, rowptr, colind, values), and a
 * VALUE reply is received straight into freshly allocated envelope arrays.
 * The client waits for the server without a timeout, since a statement may
 * compute for as long as it needs; a server that dies shows as a closed
 * connection, and one whose machine vanishes (no FIN ever comes) is found by
 * TCP keepalive probes within about 25 s (keep_alive below).
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE   /* TCP_KEEPIDLE and friends */
#include "client.h"

#include <errno.h>
#include <netdb.h>
#include <sched.h>
#include <stdatomic.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
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
    atomic_int exec_state;   /* EXEC_*; lock-free, so rem_cancel is async-signal-safe */
    char url[512];
};

/* Replies a client accepts: text up to 1 GiB, values as large as memory. */
static const proto_limits client_limits = {UINT64_MAX / 2, (uint64_t)1 << 30};

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

/* The reply that ends a request: OK, ERROR (its text into err), or VALUE into
 * *env when env is not NULL.  TEXT and WARN before it go to fn and warnings. */
static int await_reply(rem_conn *c, silc_envelope_t *env, silc_output_fn fn, void *user,
                       strbuf *warnings, char *err, size_t errlen)
{
    proto_stream s = {c->fd, -1, NULL, 0, 0};
    for (;;) {
        proto_reply r;
        char why[512];
        if (proto_read_reply(&s, &client_limits, &r, why, sizeof why)) return lost(c, why, err, errlen);
        switch (r.op) {
        case PROTO_TEXT:
            if (fn) fn(user, r.text);
            else fputs(r.text, stdout);
            break;
        case PROTO_WARN:
            if (warnings) sb_puts(warnings, r.text);
            break;
        case PROTO_OK:
            proto_reply_free(&r);
            return env ? lost(c, "OK reply where a value was expected", err, errlen) : 0;
        case PROTO_ERROR:
            snprintf(err, errlen, "%s", r.text);
            proto_reply_free(&r);
            return -1;
        default: /* PROTO_VALUE */
            if (!env) {
                proto_reply_free(&r);
                return lost(c, "unexpected VALUE reply", err, errlen);
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
    s = (proto_stream){c->fd, -1, NULL, 0, 0};
    if (proto_send(c->fd, iov, 2, -1, why, sizeof why) ||
        proto_read_hello(&s, &version, &tok, why, sizeof why)) {
        snprintf(err, errlen, "handshake with silc server %s failed: %s", url, why);
        free(tok);
        close(c->fd);
        free(c);
        return -1;
    }
    free(tok);
    if (await_reply(c, NULL, NULL, NULL, NULL, why, sizeof why)) {
        snprintf(err, errlen, "silc server %s refused the connection: %s", url, why);
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
    if (!c->broken && proto_send_text(c->fd, PROTO_BYE, NULL, 5000, why, sizeof why) == 0)
        await_reply(c, NULL, NULL, NULL, NULL, why, sizeof why);
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
    d.nnz = e->format == SILC_CSR ? e->rowptr[e->m] : e->nnz;
    if (e->format == SILC_BAND) {
        d.kl = e->kl;
        d.ku = e->ku;
    }
    if (e->format == SILC_DENSE) d.nnz = e->m * e->n;
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
    if (proto_send_frame(c->fd, PROTO_PUT, body, 5, -1, why, sizeof why))
        return lost(c, why, err, errlen);
    return await_reply(c, NULL, NULL, NULL, NULL, err, errlen);
}

int rem_get(rem_conn *c, silc_envelope_t *e, const char *name, char *err, size_t errlen)
{
    char why[512];
    if (usable(c, err, errlen)) return -1;
    if (proto_send_text(c->fd, PROTO_GET, name, -1, why, sizeof why))
        return lost(c, why, err, errlen);
    return await_reply(c, e, NULL, NULL, NULL, err, errlen);
}

int rem_exec(rem_conn *c, const char *statements, silc_output_fn fn, void *user,
             strbuf *warnings, char *err, size_t errlen)
{
    char why[512];
    int rc, state;
    if (usable(c, err, errlen)) return -1;
    if (proto_send_text(c->fd, PROTO_EXEC, statements, -1, why, sizeof why))
        return lost(c, why, err, errlen);
    atomic_store(&c->exec_state, EXEC_AWAITING);
    rc = await_reply(c, NULL, fn, user, warnings, err, errlen);
    /* A CANCEL being written (another thread) finishes before the next
     * request may be sent; a signal handler's has finished by now. */
    for (;;) {
        state = EXEC_AWAITING;
        if (atomic_compare_exchange_strong(&c->exec_state, &state, EXEC_IDLE)) break;
        if (state == EXEC_IDLE) break;
        sched_yield();
    }
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
