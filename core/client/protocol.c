/*
 * protocol.c -- frame encoding, decoding and validation of the wire protocol
 * (client.h, docs/protocol.md), shared by the client, the server and the
 * fuzz harness so that there is one decoder to get right.
 *
 * Every decoder follows the same order: read a fixed-size part, check each
 * count against the limits and the frame length with overflow-safe
 * arithmetic, and only then allocate and read the variable part.  A message
 * that is well framed but unacceptable is consumed whole (PROTO_REFUSED) so
 * that the session survives it; one whose length cannot be trusted ends the
 * connection (PROTO_FATAL).
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE 1   /* madvise */
#include "client.h"
#include "util.h"

#include <errno.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "store.h"

/* Bytes of a frame body skipped rather than ending the session: a refused
 * message up to this size costs a read, a larger one a reconnect. */
#define PROTO_SKIP_LIMIT ((uint64_t)1 << 20)

static int perr(int rc, char *err, size_t errlen, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static int perr(int rc, char *err, size_t errlen, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    return rc;
}

int proto_parse_url(const char *url, proto_addr *a, char *err, size_t errlen)
{
    const char *hp, *colon, *host_end;
    size_t hl;
    char *end;
    long port;
    memset(a, 0, sizeof *a);
    if (!url) return perr(-1, err, errlen, "no server address");
    if (strncmp(url, "unix:", 5) == 0) {
        const char *path = url + 5;
        if (strncmp(path, "//", 2) == 0) path += 2;
        if (!*path) return perr(-1, err, errlen, "'%s': empty socket path", url);
        if (strlen(path) >= sizeof a->path)
            return perr(-1, err, errlen, "'%s': socket path longer than %zu bytes", url,
                        sizeof a->path - 1);
        a->is_unix = 1;
        strcpy(a->path, path);
        return 0;
    }
    if (strncmp(url, "tcp://", 6) != 0)
        return perr(-1, err, errlen, "'%s': server address must be tcp://host:port or "
                    "unix:/path", url);
    hp = url + 6;
    if (*hp == '[') {
        host_end = strchr(hp, ']');
        if (!host_end || host_end[1] != ':')
            return perr(-1, err, errlen, "'%s': expected [address]:port", url);
        hp++;
        colon = host_end + 1;
    } else {
        colon = strrchr(hp, ':');
        if (!colon) return perr(-1, err, errlen, "'%s': missing :port", url);
        host_end = colon;
    }
    hl = (size_t)(host_end - hp);
    if (hl == 0 || hl >= sizeof a->host) return perr(-1, err, errlen, "'%s': bad host", url);
    memcpy(a->host, hp, hl);
    port = strtol(colon + 1, &end, 10);
    if (end == colon + 1 || *end || port < 0 || port > 65535)
        return perr(-1, err, errlen, "'%s': port must be a number in 0..65535", url);
    snprintf(a->port, sizeof a->port, "%ld", port);
    return 0;
}

/* ---- encoding -------------------------------------------------------------- */

void proto_put_u32(uint8_t *p, uint32_t x)
{
    int i;
    for (i = 0; i < 4; i++) p[i] = (uint8_t)(x >> (8 * i));
}

void proto_put_u64(uint8_t *p, uint64_t x)
{
    int i;
    for (i = 0; i < 8; i++) p[i] = (uint8_t)(x >> (8 * i));
}

uint32_t proto_get_u32(const uint8_t *p)
{
    uint32_t x = 0;
    int i;
    for (i = 3; i >= 0; i--) x = (x << 8) | p[i];
    return x;
}

uint64_t proto_get_u64(const uint8_t *p)
{
    uint64_t x = 0;
    int i;
    for (i = 7; i >= 0; i--) x = (x << 8) | p[i];
    return x;
}

void proto_encode_hello(uint8_t out[PROTO_HELLO_BYTES], uint32_t version, uint32_t token_len)
{
    memcpy(out, PROTO_MAGIC, 4);
    proto_put_u32(out + 4, version);
    proto_put_u32(out + 8, token_len);
}

void proto_encode_header(uint8_t out[PROTO_HEADER_BYTES], uint32_t op, uint64_t len)
{
    proto_put_u32(out, op);
    proto_put_u32(out + 4, 0);
    proto_put_u64(out + 8, len);
}

void proto_encode_desc(uint8_t out[PROTO_DESC_BYTES], const proto_desc *d)
{
    proto_put_u32(out, d->format);
    proto_put_u32(out + 4, d->namelen);
    proto_put_u64(out + 8, (uint64_t)d->m);
    proto_put_u64(out + 16, (uint64_t)d->n);
    proto_put_u64(out + 24, (uint64_t)d->nnz);
    proto_put_u64(out + 32, (uint64_t)d->kl);
    proto_put_u64(out + 40, (uint64_t)d->ku);
}

static void decode_desc(const uint8_t in[PROTO_DESC_BYTES], proto_desc *d)
{
    d->format = proto_get_u32(in);
    d->namelen = proto_get_u32(in + 4);
    d->m = (int64_t)proto_get_u64(in + 8);
    d->n = (int64_t)proto_get_u64(in + 16);
    d->nnz = (int64_t)proto_get_u64(in + 24);
    d->kl = (int64_t)proto_get_u64(in + 32);
    d->ku = (int64_t)proto_get_u64(in + 40);
}

const char *proto_op_name(uint32_t op)
{
    switch (op) {
    case PROTO_PUT: return "PUT";
    case PROTO_GET: return "GET";
    case PROTO_EXEC: return "EXEC";
    case PROTO_DELETE: return "DELETE";
    case PROTO_LIST: return "LIST";
    case PROTO_INFO: return "INFO";
    case PROTO_EXPLAIN: return "EXPLAIN";
    case PROTO_BYE: return "BYE";
    case PROTO_CANCEL: return "CANCEL";
    case PROTO_GET_COMPLEX: return "GET_COMPLEX";
    case PROTO_OK: return "OK";
    case PROTO_ERROR: return "ERROR";
    case PROTO_VALUE: return "VALUE";
    case PROTO_TEXT: return "TEXT";
    case PROTO_WARN: return "WARN";
    default: return NULL;
    }
}

/* a*b into *out unless it exceeds limit (both non-negative). */
static int mul_within(uint64_t a, uint64_t b, uint64_t limit, uint64_t *out)
{
    if (a != 0 && b > limit / a) return -1;
    *out = a * b;
    return *out <= limit ? 0 : -1;
}

int proto_layout_of(const proto_desc *d, uint64_t max_bytes, proto_layout *L, char *err,
                    size_t errlen)
{
    uint64_t count, rp, ci, va, entry = d->format & SILC_COMPLEX ? 16 : 8;
    int format = env_format_base((int)(d->format & 0xffff));
    memset(L, 0, sizeof *L);
    if ((d->format & ~(uint32_t)SILC_COMPLEX) > SILC_BAND)
        return perr(-1, err, errlen, "unknown value format %u", (unsigned)d->format);
    if (d->m < 0 || d->n < 0 || d->nnz < 0 || d->kl < 0 || d->ku < 0)
        return perr(-1, err, errlen, "negative size in value descriptor (m = %lld, n = %lld, "
                    "nnz = %lld, kl = %lld, ku = %lld)", (long long)d->m, (long long)d->n,
                    (long long)d->nnz, (long long)d->kl, (long long)d->ku);
    if (d->m > PROTO_MAX_DIM || d->n > PROTO_MAX_DIM)
        return perr(-1, err, errlen, "dimensions %lldx%lld exceed the protocol's limit of 2^40",
                    (long long)d->m, (long long)d->n);
    switch (format) {
    case SILC_DENSE:
        if (mul_within((uint64_t)d->m, (uint64_t)d->n, UINT64_MAX / 16, &count) ||
            (uint64_t)d->nnz != count)
            return perr(-1, err, errlen, "dense %lldx%lld value declares %lld entries",
                        (long long)d->m, (long long)d->n, (long long)d->nnz);
        if (d->kl || d->ku) return perr(-1, err, errlen, "dense value with band widths");
        rp = ci = 0;
        va = count * entry;
        break;
    case SILC_CSR:
        if (d->kl || d->ku) return perr(-1, err, errlen, "csr value with band widths");
        if ((uint64_t)d->nnz > UINT64_MAX / 32)
            return perr(-1, err, errlen, "csr value declares %lld entries", (long long)d->nnz);
        rp = ((uint64_t)d->m + 1) * 8;
        ci = (uint64_t)d->nnz * 8;
        va = (uint64_t)d->nnz * entry;
        break;
    default: /* SILC_BAND */
        if (d->kl > INT32_MAX || d->ku > INT32_MAX ||
            mul_within((uint64_t)(d->kl + d->ku + 1), (uint64_t)d->n, UINT64_MAX / 16, &count) ||
            (uint64_t)d->nnz != count)
            return perr(-1, err, errlen, "band %lldx%lld value with kl = %lld, ku = %lld "
                        "declares %lld entries", (long long)d->m, (long long)d->n,
                        (long long)d->kl, (long long)d->ku, (long long)d->nnz);
        rp = ci = 0;
        va = count * entry;
        break;
    }
    /* Each part is below 2^61, so the sum cannot wrap. */
    L->rowptr_bytes = rp;
    L->colind_bytes = ci;
    L->values_bytes = va;
    L->total = rp + ci + va;
    if (L->total > max_bytes)
    {
        char over[200];
        util_fmt_over_limit(over, sizeof over, (double)L->total, (double)max_bytes);
        return perr(-1, err, errlen, "%lldx%lld %s value of %s", (long long)d->m, (long long)d->n,
                    val_format_name(format), over);
    }
    return 0;
}

int proto_value_iov(const silc_value *v, proto_desc *d, struct iovec iov[3])
{
    proto_layout L;
    char err[256];
    int k = 0;
    memset(d, 0, sizeof *d);
    d->format = (uint32_t)env_format_code(v->format, v->field);
    d->m = v->m;
    d->n = v->n;
    d->nnz = v->nnz;
    if (v->format == SILC_FMT_BAND) {
        d->kl = v->kl;
        d->ku = v->ku;
    }
    if (proto_layout_of(d, UINT64_MAX, &L, err, sizeof err)) return -1;
    if (L.rowptr_bytes) {
        iov[k].iov_base = v->rowptr;
        iov[k++].iov_len = (size_t)L.rowptr_bytes;
    }
    if (L.colind_bytes) {
        iov[k].iov_base = v->colind;
        iov[k++].iov_len = (size_t)L.colind_bytes;
    }
    if (L.values_bytes) {
        iov[k].iov_base = v->val;
        iov[k++].iov_len = (size_t)L.values_bytes;
    }
    return k;
}

/* ---- I/O ------------------------------------------------------------------- */

/* Drops the first n bytes of an iovec array; returns the new start. */
static struct iovec *iov_advance(struct iovec *iov, int *iovcnt, size_t n)
{
    while (*iovcnt > 0 && n >= iov->iov_len) {
        n -= iov->iov_len;
        iov++;
        (*iovcnt)--;
    }
    if (*iovcnt > 0) {
        iov->iov_base = (char *)iov->iov_base + n;
        iov->iov_len -= n;
    }
    return iov;
}

int64_t proto_now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}

int proto_spin(struct pollfd *p, int n, int64_t budget_ns)
{
    int64_t t0 = proto_now_ns();
    do {
        int i;
        for (i = 0; i < n; i++) p[i].revents = 0;
        if (poll(p, (nfds_t)n, 0) > 0) return 1;
    } while (proto_now_ns() - t0 < budget_ns);
    return 0;
}

/* Texts longer than this are hashed by their length and first bytes: a
 * kind needs no more, and a 64 MiB statement is not read twice. */
#define SPIN_KIND_TEXT_BYTES 4096

uint64_t proto_spin_kind(uint32_t op, const char *text)
{
    size_t n = text ? strlen(text) : 0;
    unsigned char head[12]; /* op and the text's length, least significant byte first */
    uint64_t h;
    int k;
    for (k = 0; k < 4; k++) head[k] = (unsigned char)(op >> (8 * k));
    for (k = 0; k < 8; k++) head[4 + k] = (unsigned char)((uint64_t)n >> (8 * k));
    h = util_fnv1a(UTIL_FNV1A_START, head, sizeof head);
    if (n) h = util_fnv1a(h, text, n < SPIN_KIND_TEXT_BYTES ? n : SPIN_KIND_TEXT_BYTES);
    return h ? h : 1;
}

int64_t proto_spin_budget(proto_spin_memo *m, uint64_t key)
{
    unsigned slot = (unsigned)(key % PROTO_SPIN_KINDS);
    if (m->kind[slot].key != key || m->kind[slot].waited_ns < PROTO_SPIN_NS) return PROTO_SPIN_NS;
    if (++m->kind[slot].sleeps >= PROTO_SPIN_PROBE) {
        m->kind[slot].sleeps = 0;
        return PROTO_SPIN_NS;
    }
    return 0;
}

void proto_spin_learn(proto_spin_memo *m, uint64_t key, int64_t waited_ns)
{
    unsigned slot = (unsigned)(key % PROTO_SPIN_KINDS);
    if (m->kind[slot].key != key) {
        m->kind[slot].key = key;
        m->kind[slot].sleeps = 0;
    }
    m->kind[slot].waited_ns = waited_ns;
}

/* Waits until fd is ready (spinning first, see PROTO_SPIN_NS; timeout_ms < 0
 * waits for ever); 0, or PROTO_BROKEN on timeout or error. */
static int wait_fd(int fd, short events, int timeout_ms, char *err, size_t errlen)
{
    struct pollfd p;
    int rc;
    p.fd = fd;
    p.events = events;
    if (proto_spin(&p, 1, PROTO_SPIN_NS)) return 0;
    do rc = poll(&p, 1, timeout_ms < 0 ? -1 : timeout_ms);
    while (rc < 0 && errno == EINTR);
    if (rc == 0)
        return perr(PROTO_BROKEN, err, errlen, "timed out after %d ms waiting for the peer",
                    timeout_ms);
    if (rc < 0) return perr(PROTO_BROKEN, err, errlen, "poll: %s", strerror(errno));
    return 0;
}

/* Both directions try the socket first and wait only when it is not ready:
 * the bytes of a small request have usually arrived already, and a poll per
 * read would double the system calls.  A wait spins before it sleeps, which
 * on a bulk transfer (the peer is busy filling or draining the socket) means
 * it never sleeps: waking a sleeping thread cost more than the copy of the
 * chunk it waited for. */
int proto_recv(proto_stream *s, struct iovec *iov, int iovcnt, char *err, size_t errlen)
{
    while (iovcnt > 0 && iov->iov_len == 0) iov++, iovcnt--;
    while (iovcnt > 0) {
        ssize_t got;
        if (s->fd < 0) {
            size_t n = s->memlen - s->mempos;
            if (n == 0) return perr(PROTO_BROKEN, err, errlen, "connection closed by peer");
            if (n > iov->iov_len) n = iov->iov_len;
            memcpy(iov->iov_base, s->mem + s->mempos, n);
            s->mempos += n;
            got = (ssize_t)n;
        } else {
            struct msghdr msg;
            memset(&msg, 0, sizeof msg);
            msg.msg_iov = iov;
            msg.msg_iovlen = (size_t)(iovcnt > 64 ? 64 : iovcnt);
            got = recvmsg(s->fd, &msg, MSG_DONTWAIT);
            if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
                int rc = wait_fd(s->fd, POLLIN, s->timeout_ms, err, errlen);
                if (rc) return rc;
                continue;
            }
            if (got < 0 && errno == EINTR) continue;
            if (got < 0) return perr(PROTO_BROKEN, err, errlen, "receive: %s", strerror(errno));
            if (got == 0) return perr(PROTO_BROKEN, err, errlen, "connection closed by peer");
        }
        iov = iov_advance(iov, &iovcnt, (size_t)got);
    }
    return 0;
}

int proto_send(int fd, struct iovec *iov, int iovcnt, int timeout_ms, char *err, size_t errlen)
{
    while (iovcnt > 0 && iov->iov_len == 0) iov++, iovcnt--;
    while (iovcnt > 0) {
        struct msghdr msg;
        ssize_t put;
        memset(&msg, 0, sizeof msg);
        msg.msg_iov = iov;
        msg.msg_iovlen = (size_t)(iovcnt > 64 ? 64 : iovcnt);
        /* MSG_NOSIGNAL: a vanished peer is an error to report, not SIGPIPE. */
        put = sendmsg(fd, &msg, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (put < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            int rc = wait_fd(fd, POLLOUT, timeout_ms, err, errlen);
            if (rc) return rc;
            continue;
        }
        if (put < 0 && errno == EINTR) continue;
        if (put < 0) return perr(PROTO_BROKEN, err, errlen, "send: %s", strerror(errno));
        iov = iov_advance(iov, &iovcnt, (size_t)put);
    }
    return 0;
}

int proto_frame_iov(uint8_t hdr[PROTO_HEADER_BYTES], uint32_t op, const struct iovec *body, int n,
                    struct iovec iov[PROTO_FRAME_PARTS])
{
    uint64_t len = 0;
    int i;
    if (n > PROTO_FRAME_PARTS - 1) return -1;
    iov[0].iov_base = hdr;
    iov[0].iov_len = PROTO_HEADER_BYTES;
    for (i = 0; i < n; i++) {
        iov[i + 1] = body[i];
        len += body[i].iov_len;
    }
    proto_encode_header(hdr, op, len);
    return n + 1;
}

int proto_send_frame(int fd, uint32_t op, const struct iovec *body, int n, int timeout_ms,
                     char *err, size_t errlen)
{
    uint8_t hdr[PROTO_HEADER_BYTES];
    struct iovec iov[PROTO_FRAME_PARTS];
    int parts = proto_frame_iov(hdr, op, body, n, iov);
    if (parts < 0) return perr(PROTO_FATAL, err, errlen, "internal: frame of %d parts", n);
    return proto_send(fd, iov, parts, timeout_ms, err, errlen);
}

int proto_send_text(int fd, uint32_t op, const char *text, int timeout_ms, char *err,
                    size_t errlen)
{
    struct iovec body;
    body.iov_base = (void *)(uintptr_t)text;
    body.iov_len = text ? strlen(text) : 0;
    return proto_send_frame(fd, op, &body, 1, timeout_ms, err, errlen);
}

int proto_skip(proto_stream *s, uint64_t nbytes, char *err, size_t errlen)
{
    size_t chunk = nbytes < ((uint64_t)1 << 16) ? (size_t)nbytes : (size_t)1 << 16;
    uint8_t *sink;
    int rc = 0;
    if (nbytes == 0) return 0;
    if (s->fd < 0) { /* see client.h: what memory does not hold was dropped unread */
        size_t here = s->mempos < s->memlen ? s->memlen - s->mempos : 0;
        s->mempos += nbytes < here ? (size_t)nbytes : here;
        return 0;
    }
    if (!(sink = malloc(chunk))) return perr(PROTO_BROKEN, err, errlen, "out of memory");
    while (nbytes > 0 && rc == 0) {
        struct iovec iov;
        iov.iov_base = sink;
        iov.iov_len = nbytes < chunk ? (size_t)nbytes : chunk;
        nbytes -= iov.iov_len;
        rc = proto_recv(s, &iov, 1, err, errlen);
    }
    free(sink);
    return rc;
}

static int recv_buf(proto_stream *s, void *buf, size_t n, char *err, size_t errlen)
{
    struct iovec iov;
    iov.iov_base = buf;
    iov.iov_len = n;
    return proto_recv(s, &iov, 1, err, errlen);
}

/* Reads n bytes of text into a fresh NUL-terminated string (NULL if n == 0). */
static int recv_text(proto_stream *s, uint64_t n, char **out, char *err, size_t errlen)
{
    char *t;
    int rc;
    *out = NULL;
    if (n == 0) return 0;
    if (!(t = malloc((size_t)n + 1)))
        return perr(PROTO_FATAL, err, errlen, "out of memory for a %llu-byte text",
                    (unsigned long long)n);
    if ((rc = recv_buf(s, t, (size_t)n, err, errlen))) {
        free(t);
        return rc;
    }
    t[n] = '\0';
    *out = t;
    return 0;
}

/* ---- decoding -------------------------------------------------------------- */

int proto_read_hello(proto_stream *s, uint32_t *version, char **token, char *err, size_t errlen)
{
    uint8_t h[PROTO_HELLO_BYTES];
    uint32_t len;
    int rc;
    *token = NULL;
    if ((rc = recv_buf(s, h, sizeof h, err, errlen))) return rc;
    if (memcmp(h, PROTO_MAGIC, 4) != 0)
        return perr(PROTO_FATAL, err, errlen, "not a SILC peer (bad magic in the hello)");
    *version = proto_get_u32(h + 4);
    len = proto_get_u32(h + 8);
    if (len > PROTO_MAX_TOKEN)
        return perr(PROTO_FATAL, err, errlen, "token of %u bytes exceeds the limit of %u",
                    (unsigned)len, PROTO_MAX_TOKEN);
    return recv_text(s, len, token, err, errlen);
}

/* Reads a header; PROTO_FATAL for flags or lengths that cannot be trusted. */
static int read_header(proto_stream *s, uint32_t *op, uint64_t *len, char *err, size_t errlen)
{
    uint8_t h[PROTO_HEADER_BYTES];
    int rc;
    if ((rc = recv_buf(s, h, sizeof h, err, errlen))) return rc;
    *op = proto_get_u32(h);
    *len = proto_get_u64(h + 8);
    if (proto_get_u32(h + 4) != 0)
        return perr(PROTO_FATAL, err, errlen, "frame flags %u are not 0 (protocol version 1)",
                    (unsigned)proto_get_u32(h + 4));
    return 0;
}

/* Skips a refused body of any length, keeping err; PROTO_REFUSED or PROTO_BROKEN. */
static int skip_refused(proto_stream *s, uint64_t len, char *err, size_t errlen)
{
    char discard[128];
    if (proto_skip(s, len, discard, sizeof discard)) {
        snprintf(err, errlen, "%s", discard);
        return PROTO_BROKEN;
    }
    return PROTO_REFUSED;
}

/* A body that is read whole and then refused; a long one ends the session. */
static int refuse_body(proto_stream *s, uint64_t len, int rc_if_read, char *err,
                       size_t errlen)
{
    if (len > PROTO_SKIP_LIMIT) return PROTO_FATAL;
    return skip_refused(s, len, err, errlen) == PROTO_REFUSED ? rc_if_read : PROTO_BROKEN;
}

/* The NUL-free text of a name or statement; NUL inside is refused. */
static int text_body(proto_stream *s, uint64_t len, uint64_t limit, const char *what,
                     proto_request *r, char *err, size_t errlen)
{
    int rc;
    if (len > limit) {
        perr(0, err, errlen, "%s of %llu bytes exceeds the limit of %llu bytes", what,
             (unsigned long long)len, (unsigned long long)limit);
        return refuse_body(s, len, PROTO_REFUSED, err, errlen);
    }
    if ((rc = recv_text(s, len, &r->text, err, errlen))) return rc;
    r->textlen = (size_t)len;
    if (r->text && strlen(r->text) != r->textlen) {
        free(r->text);
        r->text = NULL;
        return perr(PROTO_REFUSED, err, errlen, "%s contains a NUL byte", what);
    }
    return 0;
}

int proto_read_request(proto_stream *s, const proto_limits *lim, proto_request *r, char *err,
                       size_t errlen)
{
    uint8_t d[PROTO_DESC_BYTES];
    uint64_t len;
    int rc;
    memset(r, 0, sizeof *r);
    if ((rc = read_header(s, &r->op, &len, err, errlen))) return rc;
    switch (r->op) {
    case PROTO_LIST:
    case PROTO_BYE:
    case PROTO_CANCEL:
        if (len != 0) {
            perr(0, err, errlen, "%s frame with a %llu-byte body (must be empty)",
                 proto_op_name(r->op), (unsigned long long)len);
            return refuse_body(s, len, PROTO_REFUSED, err, errlen);
        }
        return 0;
    case PROTO_GET:
    case PROTO_GET_COMPLEX:
    case PROTO_DELETE:
    case PROTO_INFO:
        if ((rc = text_body(s, len, PROTO_MAX_NAME, "name", r, err, errlen))) return rc;
        if (!r->text && r->op != PROTO_INFO)
            return perr(PROTO_REFUSED, err, errlen, "%s without a name", proto_op_name(r->op));
        return 0;
    case PROTO_EXEC:
    case PROTO_EXPLAIN:
        if ((rc = text_body(s, len, lim->max_text_bytes, "statement text", r, err, errlen)))
            return rc;
        if (!r->text) r->text = calloc(1, 1);
        return r->text ? 0 : perr(PROTO_FATAL, err, errlen, "out of memory");
    case PROTO_PUT:
        if (len < PROTO_DESC_BYTES) {
            perr(0, err, errlen, "PUT frame of %llu bytes is shorter than its descriptor",
                 (unsigned long long)len);
            return refuse_body(s, len, PROTO_REFUSED, err, errlen);
        }
        if ((rc = recv_buf(s, d, sizeof d, err, errlen))) return rc;
        len -= PROTO_DESC_BYTES;
        decode_desc(d, &r->desc);
        if (r->desc.namelen == 0 || r->desc.namelen > PROTO_MAX_NAME || r->desc.namelen > len) {
            perr(0, err, errlen, "PUT name length %u is out of range", (unsigned)r->desc.namelen);
            return refuse_body(s, len, PROTO_REFUSED, err, errlen);
        }
        if ((rc = text_body(s, r->desc.namelen, PROTO_MAX_NAME, "name", r, err, errlen)))
            return rc;
        len -= r->desc.namelen;
        if (proto_layout_of(&r->desc, UINT64_MAX, &r->layout, err, errlen))
            return refuse_body(s, len, PROTO_REFUSED, err, errlen);
        if (r->layout.total != len)
            return perr(PROTO_FATAL, err, errlen, "PUT '%s': frame carries %llu bytes of "
                        "arrays, the descriptor needs %llu", r->text, (unsigned long long)len,
                        (unsigned long long)r->layout.total);
        if (r->layout.total > lim->max_value_bytes) {
            /* Only the limit is exceeded and the length is consistent, so the
             * stream stays in step: skip the arrays and keep the session. */
            char over[200];
            util_fmt_over_limit(over, sizeof over, (double)len, (double)lim->max_value_bytes);
            perr(0, err, errlen, "'%s': %lldx%lld %s value of %s per value (silcd "
                 "--max-value-bytes)", r->text, (long long)r->desc.m, (long long)r->desc.n,
                 val_format_name(env_format_base((int)r->desc.format)), over);
            return skip_refused(s, len, err, errlen);
        }
        return 0;
    default:
        perr(0, err, errlen, "unknown request opcode %u", (unsigned)r->op);
        return refuse_body(s, len, PROTO_REFUSED, err, errlen);
    }
}

/* Linux 5.14's MADV_POPULATE_WRITE, by number where the headers are older. */
#if defined(__linux__) && !defined(MADV_POPULATE_WRITE)
#define MADV_POPULATE_WRITE 23
#endif

/* Maps the pages of a fresh array in one call before a large receive: taking
 * the page faults one by one inside recvmsg costs more than the copy itself
 * on some virtual machines (5x on the project's CI machines).  Huge pages
 * first where the kernel gives them only on request (transparent_hugepage
 * "madvise"): 512 times fewer faults, and fewer TLB entries to shoot down
 * when the array is unmapped.  Advisory: kernels without either just fault
 * as usual; pages already mapped (a recycled array) are left as they are. */
static void prefault(void *p, size_t n)
{
#ifdef MADV_POPULATE_WRITE
    uintptr_t page = 4096, lo = ((uintptr_t)p + page - 1) & ~(page - 1),
              hi = ((uintptr_t)p + n) & ~(page - 1), huge = (uintptr_t)2 << 20;
    if (n < ((size_t)1 << 20) || hi <= lo) return;
#ifdef MADV_HUGEPAGE
    if (n >= 4 * huge) {
        uintptr_t hlo = (lo + huge - 1) & ~(huge - 1), hhi = hi & ~(huge - 1);
        if (hhi > hlo) madvise((void *)hlo, hhi - hlo, MADV_HUGEPAGE);
    }
#endif
    madvise((void *)lo, hi - lo, MADV_POPULATE_WRITE);
#else
    (void)p;
    (void)n;
#endif
}

/* The most of an array mapped ahead of the bytes received: a PUT that
 * announces 2 GiB and sends nothing costs its receiver 64 MiB of memory, not
 * 2 GiB (the array is only reserved; its pages are touched as data comes). */
#define RECV_CHUNK_BYTES ((size_t)64 << 20)

/* Reads a value's arrays into rowptr/colind/values as laid out by L, each
 * in chunks mapped (prefault) just before their bytes are read. */
static int recv_arrays(proto_stream *s, const proto_layout *L, void *rowptr, void *colind,
                       void *values, char *err, size_t errlen)
{
    uint8_t *base[3];
    size_t bytes[3];
    int k, rc;
    base[0] = rowptr, bytes[0] = (size_t)L->rowptr_bytes;
    base[1] = colind, bytes[1] = (size_t)L->colind_bytes;
    base[2] = values, bytes[2] = (size_t)L->values_bytes;
    for (k = 0; k < 3; k++) {
        size_t done = 0;
        while (done < bytes[k]) {
            struct iovec iov;
            size_t n = bytes[k] - done < RECV_CHUNK_BYTES ? bytes[k] - done : RECV_CHUNK_BYTES;
            prefault(base[k] + done, n);
            iov.iov_base = base[k] + done;
            iov.iov_len = n;
            if ((rc = proto_recv(s, &iov, 1, err, errlen))) return rc;
            done += n;
        }
    }
    return 0;
}

/* The envelope view of arrays in the wire layout, for env_check. */
static void view_envelope(const proto_desc *d, double *values, int64_t *rowptr, int64_t *colind,
                          silc_envelope_t *e)
{
    memset(e, 0, sizeof *e);
    e->m = d->m;
    e->n = d->n;
    e->format = (silc_format_t)d->format;
    e->values = values;
    e->rowptr = rowptr;
    e->colind = colind;
    e->nnz = d->nnz;
    e->kl = d->kl;
    e->ku = d->ku;
}

/* Checks received arrays as embedded silc_put does, after rowptr[m] == nnz.
 * When they are a value's own (v), a CSR value gets its shape in the same
 * pass, as there. */
static int check_arrays(const proto_desc *d, const char *name, silc_value *v, double *values,
                        int64_t *rowptr, int64_t *colind, char *err, size_t errlen)
{
    silc_envelope_t view;
    char why[512];
    /* First, so that env_check's walk over colind stays inside the nnz
     * entries that were received (rowptr[0] = 0 and monotone rows, which it
     * checks before that walk, then bound every index by rowptr[m]). */
    if (env_format_base((int)d->format) == SILC_CSR && rowptr[d->m] != d->nnz)
        return perr(PROTO_REFUSED, err, errlen, "'%s': rowptr[m] = %lld but the descriptor "
                    "declares %lld entries", name, (long long)rowptr[d->m], (long long)d->nnz);
    view_envelope(d, values, rowptr, colind, &view);
    if (v && env_format_base((int)d->format) == SILC_CSR ? env_csr_fill(v, &view, why, sizeof why)
                                   : env_check(&view, why, sizeof why))
        return perr(PROTO_REFUSED, err, errlen, "'%s': %s", name, why);
    return 0;
}

int proto_read_value(proto_stream *s, const proto_request *r, silc_value **out, char *err,
                     size_t errlen)
{
    const proto_desc *d = &r->desc;
    silc_value *v;
    int rc;
    *out = NULL;
    /* Unset: every byte is received (or the value dropped), so zeroing the
     * arrays first would only cost a pass over memory. */
    v = val_new_unset_field(env_format_base((int)d->format), env_format_field((int)d->format), d->m, d->n,
                            d->nnz, d->kl, d->ku);
    if (!v) {
        snprintf(err, errlen, "out of memory copying a %lldx%lld %s matrix", (long long)d->m,
                 (long long)d->n, val_format_name(env_format_base((int)d->format)));
        return skip_refused(s, r->layout.total, err, errlen);
    }
    rc = recv_arrays(s, &r->layout, v->rowptr, v->colind, v->val, err, errlen);
    if (!rc) rc = check_arrays(d, r->text, v, v->val, v->rowptr, v->colind, err, errlen);
    if (rc) {
        val_release(v);
        return rc;
    }
    *out = v;
    return 0;
}

void proto_request_free(proto_request *r)
{
    free(r->text);
    memset(r, 0, sizeof *r);
}

int proto_read_reply(proto_stream *s, const proto_limits *lim, proto_reply *r, char *err,
                     size_t errlen)
{
    uint8_t d[PROTO_DESC_BYTES];
    proto_desc desc;
    proto_layout L;
    silc_envelope_t *e = &r->env;
    uint64_t len;
    int rc;
    memset(r, 0, sizeof *r);
    if ((rc = read_header(s, &r->op, &len, err, errlen))) return rc;
    switch (r->op) {
    case PROTO_OK:
    case PROTO_ERROR:
    case PROTO_TEXT:
    case PROTO_WARN:
        if (len > lim->max_text_bytes)
            return perr(PROTO_FATAL, err, errlen, "%s reply of %llu bytes exceeds the limit of "
                        "%llu bytes", proto_op_name(r->op), (unsigned long long)len,
                        (unsigned long long)lim->max_text_bytes);
        if ((rc = recv_text(s, len, &r->text, err, errlen))) return rc;
        r->textlen = (size_t)len;
        if (!r->text && !(r->text = calloc(1, 1)))
            return perr(PROTO_FATAL, err, errlen, "out of memory");
        return 0;
    case PROTO_VALUE:
        if (len < PROTO_DESC_BYTES)
            return perr(PROTO_FATAL, err, errlen, "VALUE reply shorter than its descriptor");
        if ((rc = recv_buf(s, d, sizeof d, err, errlen))) return rc;
        decode_desc(d, &desc);
        if (desc.namelen != 0)
            return perr(PROTO_FATAL, err, errlen, "VALUE reply with a name length");
        if (proto_layout_of(&desc, UINT64_MAX, &L, err, errlen)) return PROTO_FATAL;
        if (L.total != len - PROTO_DESC_BYTES)
            return perr(PROTO_FATAL, err, errlen, "VALUE reply carries %llu bytes of arrays, "
                        "its descriptor needs %llu", (unsigned long long)(len - PROTO_DESC_BYTES),
                        (unsigned long long)L.total);
        if (L.total > lim->max_value_bytes) {
            /* A consistent frame over the receiver's cap: skipped, so that
             * the stream stays in step and the session keeps its values. */
            char over[200];
            util_fmt_over_limit(over, sizeof over, (double)L.total, (double)lim->max_value_bytes);
            perr(0, err, errlen, "a %lldx%lld %s value of %s per value (SILC_MAX_REPLY_BYTES)",
                 (long long)desc.m, (long long)desc.n, val_format_name(env_format_base((int)desc.format)), over);
            return skip_refused(s, L.total, err, errlen);
        }
        /* From the pool: a GET of the same size each step receives into the
         * array the last one freed. */
        e->values = val_array_alloc((int64_t)L.values_bytes, 1, 0);
        if (env_format_base((int)desc.format) == SILC_CSR) {
            e->rowptr = val_array_alloc((int64_t)L.rowptr_bytes, 1, 0);
            e->colind = val_array_alloc((int64_t)L.colind_bytes, 1, 0);
        }
        if (!e->values || (env_format_base((int)desc.format) == SILC_CSR && (!e->rowptr || !e->colind))) {
            silc_envelope_free(e);
            return perr(PROTO_FATAL, err, errlen, "out of memory for a %lldx%lld %s value",
                        (long long)desc.m, (long long)desc.n,
                        val_format_name(env_format_base((int)desc.format)));
        }
        e->m = desc.m;
        e->n = desc.n;
        e->format = (silc_format_t)desc.format;
        e->nnz = desc.nnz;
        e->kl = desc.kl;
        e->ku = desc.ku;
        rc = recv_arrays(s, &L, e->rowptr, e->colind, e->values, err, errlen);
        if (!rc && check_arrays(&desc, "VALUE", NULL, e->values, e->rowptr, e->colind, err, errlen))
            rc = PROTO_FATAL;
        if (rc) silc_envelope_free(e);
        return rc;
    default:
        return perr(PROTO_FATAL, err, errlen, "unknown reply opcode %u", (unsigned)r->op);
    }
}

void proto_reply_free(proto_reply *r)
{
    free(r->text);
    silc_envelope_free(&r->env);
    memset(r, 0, sizeof *r);
}
