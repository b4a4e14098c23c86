/*
 * session.c -- one client connection of silcd, in a process of its own
 * (silcd.c forks one per connection): the handshake, then requests until
 * BYE, disconnect, idle timeout or shutdown, each answered on the session's
 * own engine (its own store: names never leak between sessions).
 *
 * The text that `who`, `info` and `explain` print is collected during the
 * call and sent with the reply, whose start and end are marked in the
 * session's slot (server.h): if this process dies, the parent then knows
 * whether the client can still be told why.
 *
 * Session memory (the val_bytes of every bound value, what the memo keeps
 * without a name, and the factorizations solves attached to what the
 * session holds: memo_held) is kept under max_session_bytes; the memo and
 * then the factorizations give way first (memo_release), so only the
 * values themselves can make a request fail (under silcd --mpi, rank 0
 * chooses what gives way and every rank lets it go together: memo_give_way).
 * A PUT is checked from its descriptor
 * before its arrays are read; an EXEC runs against a snapshot of the
 * bindings (eng_snapshot: names to retained values, which is cheap because
 * values are immutable) and is rolled back whole if it leaves the session
 * over the limit.
 */
#define _POSIX_C_SOURCE 200809L
#include "server.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include "client.h"
#include "dispatch.h"
#include "dist.h"
#include "engine.h"
#include "lang.h"

/* silcd --mpi: a reply waits here until rank 0's poll loop has written it
 * as fast as the client reads (srv_session_flush), so that a client that
 * does not read stalls no other session.  A part is a copy (headers,
 * texts), or a value's arrays, the value held until they are out.  The loop
 * reads no further request of a session while its reply waits, so one
 * reply at most is queued: a GET's value, which the session's limits
 * already count, and a few headers; before an EXEC's reply, the output it
 * streamed while running (at most STREAM_QUEUED_MAX of it unread). */
typedef struct reply_part {
    uint8_t *own;            /* a malloc'd copy, or NULL */
    const uint8_t *p;
    size_t len;
    silc_value *hold;        /* released once p[0..len) is out */
} reply_part;

typedef struct reply_queue {
    reply_part *parts;
    size_t first, n, cap;    /* parts[first..n) wait, the first from byte off */
    size_t off;
    uint64_t bytes;          /* still to write */
} reply_queue;

/* Frames an EXEC produces (who, info, explain), sent while it runs and
 * with its reply.  Consecutive pieces of text share one TEXT frame (up to
 * OUT_FRAME_TEXT bytes): a loop that shows a value per iteration would
 * otherwise send a frame per line, and a client reading frame by frame
 * falls behind a server writing them. */
typedef struct outbuf {
    uint8_t *p;
    size_t len, cap;
    size_t text_at;          /* 1 + where the last frame starts, when it is TEXT; else 0 */
    int failed;
} outbuf;

enum { OUT_FRAME_TEXT = 1 << 20 };

struct session {
    int fd;
    unsigned long id;
    volatile int *state;   /* shared with the parent: SLOT_* */
    silc_engine *E;
    outbuf out;
    proto_stream st;
    proto_limits lim;
    int slot;              /* the state of a session of silcd --mpi (no parent to share it with) */
    int announced;         /* silcd --mpi: the other ranks made an engine for it */
    int queued;            /* silcd --mpi: replies go to q, written by srv_session_flush */
    reply_queue q;
    srv_watch watch;       /* of the running EXEC (limits.c) */
    proto_spin_memo spin;  /* how long the client took to send the request after each kind */
    uint64_t last_kind;    /* proto_spin_kind of the request served last */
    char err[4096];
};

srv_ranks *srv_mpi;


static void out_frame(outbuf *o, uint32_t op, const char *text)
{
    size_t n = strlen(text), start = o->text_at ? o->text_at - 1 : 0, had = 0, need;
    int join;
    if (o->failed) return;
    if (o->text_at) had = o->len - start - PROTO_HEADER_BYTES; /* the last TEXT frame's body */
    join = op == PROTO_TEXT && o->text_at && had + n <= OUT_FRAME_TEXT;
    need = o->len + (join ? 0 : PROTO_HEADER_BYTES) + n;
    if (need > o->cap) {
        size_t cap = o->cap ? o->cap : 256;
        uint8_t *p;
        while (cap < need) cap *= 2;
        if (!(p = realloc(o->p, cap))) {
            o->failed = 1;
            return;
        }
        o->p = p;
        o->cap = cap;
    }
    if (join) {
        proto_encode_header(o->p + start, op, had + n);
        memcpy(o->p + o->len, text, n);
    } else {
        proto_encode_header(o->p + o->len, op, n);
        memcpy(o->p + o->len + PROTO_HEADER_BYTES, text, n);
        o->text_at = op == PROTO_TEXT ? o->len + 1 : 0;
    }
    o->len = need;
}

static void capture_output(void *user, const char *text)
{
    out_frame(&((session *)user)->out, PROTO_TEXT, text);
}

/* What the session holds: its bound values, what the memo keeps for it,
 * and the factorizations hung on either (memo.c: memo_held). */
static uint64_t session_bytes(const silc_engine *E)
{
    return memo_held(E, NULL);
}

/* A rank that cannot let go of what rank 0 planned would leave the ranks
 * disagreeing on which factorizations live (a distributed one dies
 * collectively): the job ends, as on other collective failures. */
static void release_failed(unsigned long id, const char *why)
{
    srv_log(LOG_ERROR, "rank %d: session %lu: %s; ending the job (the ranks can no longer agree)",
            srv_mpi->rank, id, why);
    abort();
}

/* At the limit the memo and the factorizations go first: they are let go
 * until they fit what the bound values and more bytes about to be bound
 * leave.  Under silcd --mpi rank 0 makes the choice (memo_release_plan) and
 * every rank lets go of the same holders, in the same order, here and in
 * srv_follow: called only between commands, where every rank is. */
static void memo_give_way(session *S, double more)
{
    double room = (double)srv_cfg.max_session_bytes - more;
    strbuf plan;
    char why[512];
    if (!srv_cfg.max_session_bytes) return;
    if (!srv_mpi) {
        memo_release(S->E, room);
        return;
    }
    sb_init(&plan);
    memo_release_plan(S->E, room, &plan);
    if (plan.len) {
        srv_mpi->command(srv_mpi, SRV_CMD_RELEASE, S->id, sb_str(&plan));
        if (memo_release_named(S->E, sb_str(&plan), why, sizeof why)) release_failed(S->id, why);
    }
    sb_free(&plan);
}

/* What the session holds once the memo and the factorizations have given
 * way (memo_give_way), measured before anything is let go: under silcd
 * --mpi the verdict on a request comes first, and the ranks let go after
 * it, together. */
static uint64_t bytes_after_giving_way(const silc_engine *E)
{
    strbuf plan;
    uint64_t held;
    if (!srv_cfg.max_session_bytes) return session_bytes(E);
    sb_init(&plan);
    held = memo_release_plan(E, (double)srv_cfg.max_session_bytes, &plan);
    sb_free(&plan);
    return held;
}

static void part_done(reply_part *r)
{
    free(r->own);
    val_release(r->hold);
}

static int queue_part(reply_queue *q, const struct iovec *iov, silc_value *hold)
{
    reply_part *r;
    if (!iov->iov_len) return 0;
    if (q->n == q->cap) {
        size_t cap = q->cap ? 2 * q->cap : 8;
        reply_part *p = realloc(q->parts, cap * sizeof *p);
        if (!p) return -1;
        q->parts = p;
        q->cap = cap;
    }
    r = &q->parts[q->n];
    memset(r, 0, sizeof *r);
    r->len = iov->iov_len;
    if (hold) {
        r->hold = val_retain(hold);
        r->p = iov->iov_base;
    } else {
        if (!(r->own = malloc(r->len))) return -1;
        memcpy(r->own, iov->iov_base, r->len);
        r->p = r->own;
    }
    q->n++;
    q->bytes += r->len;
    return 0;
}

static void queue_clear(reply_queue *q)
{
    size_t k;
    for (k = q->first; k < q->n; k++) part_done(&q->parts[k]);
    q->first = q->n = q->off = 0;
    q->bytes = 0;
}

/* The parts of a reply to the client: written now (the forking server's
 * session: its process has nothing else to do, and --io-timeout bounds a
 * client that does not read), or queued (silcd --mpi).  Parts from index
 * borrowed on are arrays of hold, the others are copied. */
static int send_parts(session *S, const struct iovec *iov, int n, silc_value *hold, int borrowed)
{
    struct iovec v[8];
    char why[256];
    int i;
    if (!S->queued) {
        if (n > 8) return -1;
        memcpy(v, iov, (size_t)n * sizeof *iov);   /* proto_send consumes its iovecs */
        if (!proto_send(S->fd, v, n, srv_cfg.io_timeout_ms, why, sizeof why)) return 0;
        srv_log(LOG_INFO, "session %lu: %s", S->id, why);
        return -1;
    }
    for (i = 0; i < n; i++)
        if (queue_part(&S->q, &iov[i], i >= borrowed ? hold : NULL)) {
            srv_log(LOG_ERROR, "session %lu: out of memory queueing a reply: closed", S->id);
            return -1;
        }
    return 0;
}

/* One frame: its header, then body[0..n) (from borrowed on, arrays of hold). */
static int send_frame(session *S, uint32_t op, const struct iovec *body, int n, silc_value *hold,
                      int borrowed)
{
    uint8_t hdr[PROTO_HEADER_BYTES];
    struct iovec iov[PROTO_FRAME_PARTS];
    int parts = proto_frame_iov(hdr, op, body, n, iov);
    return parts < 0 ? -1 : send_parts(S, iov, parts, hold, borrowed + 1);
}

static int reply_text(session *S, uint32_t op, const char *text)
{
    struct iovec body;
    body.iov_base = (void *)(uintptr_t)text;
    body.iov_len = text ? strlen(text) : 0;
    *S->state = SLOT_REPLYING;
    return send_frame(S, op, &body, 1, NULL, 1);
}

static int reply_error(session *S, const char *msg)
{
    srv_log(LOG_DEBUG, "session %lu: error: %s", S->id, msg);
    return reply_text(S, PROTO_ERROR, msg);
}

/* Sends the collected TEXT frames, then WARN if any, then OK or ERROR. */
static int finish_exec(session *S, int rc, const char *warnings)
{
    struct iovec iov;
    if (S->out.failed) {
        S->out.failed = 0;
        S->out.len = S->out.text_at = 0;
        if (!rc) {
            snprintf(S->err, sizeof S->err, "out of memory collecting the statement's output");
            rc = -1;
        }
    }
    iov.iov_base = S->out.p;
    iov.iov_len = S->out.len;
    S->out.len = S->out.text_at = 0;
    *S->state = SLOT_REPLYING;
    if (iov.iov_len && send_parts(S, &iov, 1, NULL, 1)) return -1;
    if (warnings && *warnings && reply_text(S, PROTO_WARN, warnings)) return -1;
    return rc ? reply_error(S, S->err) : reply_text(S, PROTO_OK, NULL);
}

/* The output an EXEC has made so far, sent while it runs (the watch's
 * poll, every 20 ms): a long loop shows its progress as it goes, as it does
 * embedded, the session holds 20 ms of it rather than the whole run's, and
 * an interrupt is not followed by everything the run printed.  silcd --mpi
 * cannot block rank 0 on one client: it queues the piece and writes what
 * the socket takes now (the rest goes with the next poll or the reply);
 * while more than STREAM_QUEUED_MAX waits unread, the output stays in out,
 * as it did before streaming, rather than grow the queue too. */
enum { STREAM_QUEUED_MAX = 4 << 20 };

static int stream_output(void *user)
{
    session *S = user;
    struct iovec iov;
    if (S->out.failed || !S->out.len) return 0;
    if (S->queued && S->q.bytes > STREAM_QUEUED_MAX) return srv_session_flush(S) < 0 ? -1 : 0;
    iov.iov_base = S->out.p;
    iov.iov_len = S->out.len;
    S->out.len = S->out.text_at = 0;
    if (send_parts(S, &iov, 1, NULL, 1)) return -1;
    return S->queued && srv_session_flush(S) < 0 ? -1 : 0;
}

/* An EXEC runs against a snapshot (rolled back whole on a verdict) when a
 * memory or time limit may stop it; the same on every rank. */
static int exec_guarded(void)
{
    return srv_cfg.max_session_bytes > 0 || srv_cfg.max_request_ms > 0;
}

/* The values an EXEC makes count at their peak, with those bound before it
 * (values alive in the process for other reasons are exempt: another
 * session's under silcd --mpi, the engine's caches). */
static void exec_budget(const silc_engine *E, int on)
{
    memo_holdings h;
    if (!on || !srv_cfg.max_session_bytes) {
        val_budget_set(0, 0, NULL);
        return;
    }
    /* The memo's results are values alive: the budget counts them (the
     * factorizations it cannot see: memo_make_room adds them). */
    memo_held(E, &h);
    val_budget_set(val_live_bytes() - (int64_t)(h.bound + h.memo_arrays), srv_cfg.max_session_bytes,
                   "the session's limit, silcd --max-session-bytes");
}

/* What libraries printed during the request (output.c) goes to its client
 * with the request's own output, not to silcd's log. */
static void library_output(session *S)
{
    unsigned long long dropped;
    const char *text = srv_output_end(&dropped);
    char note[160];
    if (!text) return;
    if (*text) out_frame(&S->out, PROTO_TEXT, text);
    if (dropped) {
        snprintf(note, sizeof note, "silcd: %llu more bytes of library output dropped (at most 1 MiB a request)\n",
                 dropped);
        out_frame(&S->out, PROTO_TEXT, note);
    }
}

static int do_exec(session *S, const char *text)
{
    silc_engine *E = S->E;
    eng_snapshot snap;
    char *warnings;
    uint64_t used;
    int rc, guarded = exec_guarded(), r, stop, refused;
    int64_t over;
    if (guarded && eng_snapshot_take(E, &snap)) {
        return reply_error(S, "out of memory preparing the statement");
    }
    if (srv_mpi) srv_mpi->command(srv_mpi, SRV_CMD_EXEC, S->id, text);
    *S->state = SLOT_RUNNING;
    exec_budget(E, 1);
    srv_watch_begin(&S->watch, S->fd);
    S->watch.flush = stream_output;
    S->watch.flush_user = S;
    srv_output_begin();
    rc = api_exec(E, text, S->err, sizeof S->err);
    library_output(S);
    srv_watch_end(&S->watch);
    refused = val_budget_refused();
    exec_budget(E, 0);
    *S->state = SLOT_READY;
    stop = S->watch.stop;
    if (stop) {
        /* The plain reason, not "statement k: " or "rank 0 of N: ". */
        snprintf(S->err, sizeof S->err, "%s", S->watch.why);
        srv_log(LOG_INFO, "session %lu: %s", S->id, S->watch.why);
    } else if (rc && S->watch.cancelled) {
        /* Interrupted by the client's CANCEL.  Under silcd --mpi only rank
         * 0 read it, and the ranks' agreement named it ("statement 2: rank
         * 0 of 2: interrupted"): the client is told what any other server
         * says, "statement 2: interrupted". */
        char *rank = srv_mpi ? strstr(S->err, "rank 0 of ") : NULL, *colon;
        if (rank && (colon = strstr(rank, ": ")) != NULL && !strcmp(colon + 2, ENG_INTERRUPTED))
            memmove(rank, colon + 2, strlen(colon + 2) + 1);
        srv_log(LOG_INFO, "session %lu: %s", S->id, S->err);
    }
    if (guarded) {
        if (!srv_mpi) memo_give_way(S, 0);
        used = srv_mpi ? bytes_after_giving_way(E) : session_bytes(E);
        /* A value refused at the peak fails the request like a limit
         * crossed at its end: rolled back whole. */
        over = stop || refused || (srv_cfg.max_session_bytes && used > srv_cfg.max_session_bytes);
        if (srv_mpi) srv_mpi->word(srv_mpi, &over); /* rank 0's verdict decides for all */
        if (stop) {
            if (eng_snapshot_restore(E, &snap))
                snprintf(S->err, sizeof S->err, "out of memory restoring the session");
            rc = -1;
        } else if (over && refused) {
            char why[1024];
            snprintf(why, sizeof why, "%.1000s", S->err);
            snprintf(S->err, sizeof S->err, "session memory limit exceeded: %s; the whole request "
                     "was rolled back", why);
            if (eng_snapshot_restore(E, &snap))
                snprintf(S->err, sizeof S->err, "out of memory restoring the session");
            rc = -1;
        } else if (over) {
            char done[512];
            snprintf(done, sizeof done, "%.500s", rc ? S->err : "");
            snprintf(S->err, sizeof S->err, "session memory limit exceeded: the values bound "
                     "would hold %llu bytes, the limit is %llu bytes (silcd "
                     "--max-session-bytes); the whole request was rolled back%s%.500s",
                     (unsigned long long)used, (unsigned long long)srv_cfg.max_session_bytes,
                     rc ? "; it had also failed: " : "", done);
            if (eng_snapshot_restore(E, &snap))
                snprintf(S->err, sizeof S->err, "out of memory restoring the session");
            rc = -1;
        } else {
            eng_snapshot_free(&snap);
        }
        /* Every rank has the verdict and the same store: they let go now. */
        if (srv_mpi) memo_give_way(S, 0);
    }
    /* A client that has gone is not answered: the session ends. */
    if (stop == SRV_STOP_GONE) return -1;
    warnings = util_strdup(sb_str(&E->warnings));
    r = finish_exec(S, rc, warnings);
    if (stop == SRV_STOP_SHUTDOWN) r = -1;
    free(warnings);
    return r;
}

/* Whether a PUT's arrays may be read: 0, or -1 with S->err saying why not
 * (a bad name, a descriptor the value checker refuses, a session that cannot
 * hold the value), decided from the descriptor alone. */
static int put_refusal(session *S, const proto_request *q)
{
    const silc_value *old;
    uint64_t used, old_bytes;
    val_parts claim;
    double cost;
    char why[512];
    if (api_check_name(q->text, S->err, sizeof S->err)) return -1;
    /* The descriptor's claim, by the checker every value passes
     * (val_parts_claim): overflow and the value limit, with band storage
     * charged for its rows, before a byte of the arrays is read. */
    memset(&claim, 0, sizeof claim);
    claim.format = env_format_base((int)q->desc.format);
    claim.field = env_format_field((int)q->desc.format);
    claim.m = q->desc.m, claim.n = q->desc.n, claim.nnz = q->desc.nnz;
    claim.kl = q->desc.kl, claim.ku = q->desc.ku;
    if (claim.format != SILC_FMT_CSR) claim.nnz = 0;
    if (val_parts_claim(&claim, why, sizeof why)) {
        snprintf(S->err, sizeof S->err, "'%s': %s", q->text, why);
        return -1;
    }
    cost = val_parts_bytes(&claim);
    if (cost < (double)q->layout.total) cost = (double)q->layout.total;
    if (srv_cfg.max_session_bytes > 0) {
        old = store_get(&S->E->store, q->text);
        old_bytes = old ? val_bytes(old) : 0;
        memo_give_way(S, cost - (double)old_bytes);
        used = session_bytes(S->E);
        if ((double)(used - old_bytes) + cost > (double)srv_cfg.max_session_bytes) {
            snprintf(S->err, sizeof S->err, "session memory limit exceeded: storing '%s' "
                     "(%.0f bytes) would bring the session to %.0f bytes, the limit is %llu "
                     "bytes (silcd --max-session-bytes); '%s' is unchanged", q->text, cost,
                     (double)(used - old_bytes) + cost,
                     (unsigned long long)srv_cfg.max_session_bytes, q->text);
            return -1;
        }
    }
    return 0;
}

/* PUT: refuse before reading the arrays when the session cannot hold them. */
static int do_put(session *S, proto_stream *st, const proto_request *q)
{
    silc_value *v = NULL;
    char why[512];
    int rc;
    if (put_refusal(S, q)) {
        if (proto_skip(st, q->layout.total, why, sizeof why)) return -1;
        return reply_error(S, S->err);
    }
    rc = proto_read_value(st, q, &v, S->err, sizeof S->err);
    if (rc == PROTO_REFUSED) return reply_error(S, S->err);
    if (rc) {
        srv_log(LOG_INFO, "session %lu: PUT '%s' abandoned: %s", S->id, q->text, S->err);
        return -1;
    }
    if (srv_mpi) { /* to every rank: row blocks, or whole when small (dist_share) */
        silc_value *w;
        srv_mpi->command(srv_mpi, SRV_CMD_PUT, S->id, q->text);
        rc = dist_share(S->E, v, srv_mpi->min_rows, &w);
        val_release(v);
        if (rc) return reply_error(S, S->E->err);
        v = w;
    }
    rc = api_bind(S->E, q->text, v, S->err, sizeof S->err);
    val_release(v);
    return rc ? reply_error(S, S->err) : reply_text(S, PROTO_OK, NULL);
}

/* GET (accept_complex 0) or GET_COMPLEX: a client that did not announce
 * complex values is refused one, naming it (client.h). */
static int do_get(session *S, const char *name, int accept_complex)
{
    silc_value *v;
    proto_desc d;
    uint8_t desc[PROTO_DESC_BYTES];
    struct iovec body[4];
    int k, rc;
    v = (silc_value *)api_lookup(S->E, name, S->err, sizeof S->err);
    if (v && dist_is(v)) { /* its blocks, gathered to rank 0 (once: kept with the value) */
        srv_mpi->command(srv_mpi, SRV_CMD_GET, S->id, name);
        if (!(v = (silc_value *)dist_whole(S->E, v, 0))) return reply_error(S, S->E->err);
        /* The copy kept counts with the value: factorizations make room. */
        memo_give_way(S, 0);
    }
    if (v && !accept_complex && env_refuse_complex(name, v, "silc_get_complex", S->err, sizeof S->err)) v = NULL;
    val_retain(v);
    if (!v) return reply_error(S, S->err);
    k = proto_value_iov(v, &d, body + 1);
    proto_encode_desc(desc, &d);
    body[0].iov_base = desc;
    body[0].iov_len = sizeof desc;
    *S->state = SLOT_REPLYING;
    rc = k < 0 ? reply_error(S, "value too large to send")
               : send_frame(S, PROTO_VALUE, body, k + 1, v, 1);
    val_release(v);
    return rc;
}

static int do_delete(session *S, const char *name)
{
    int rc = 0;
    if (!api_lookup(S->E, name, S->err, sizeof S->err)) {
        rc = -1;
    } else {
        if (srv_mpi) srv_mpi->command(srv_mpi, SRV_CMD_DELETE, S->id, name);
        store_remove(&S->E->store, name);
        eng_info_remove(S->E, name);
    }
    return rc ? reply_error(S, S->err) : reply_text(S, PROTO_OK, NULL);
}

static int do_list(session *S)
{
    const char **names = NULL;
    strbuf b;
    size_t i, n;
    int rc;
    sb_init(&b);
    n = store_names(&S->E->store, &names);
    for (i = 0; i < n; i++) sb_printf(&b, "%s%s", i ? "\n" : "", names[i]);
    free(names);
    rc = reply_text(S, PROTO_OK, sb_str(&b));
    sb_free(&b);
    return rc;
}

/* INFO without a name describes the session; with one, runs `info name`. */
static int do_info(session *S, const char *name)
{
    char text[1024];
    uint64_t used;
    size_t count;
    if (name) {
        strbuf b;
        int rc;
        if (api_check_name(name, S->err, sizeof S->err)) return reply_error(S, S->err);
        sb_init(&b);
        sb_printf(&b, "info %s", name);
        rc = do_exec(S, sb_str(&b));
        sb_free(&b);
        return rc;
    }
    used = session_bytes(S->E);
    count = S->E->store.count;
    snprintf(text, sizeof text,
             "server: silcd %s, protocol %u\nsession: %lu\nnames: %zu\nbytes: %llu\n"
             "max_session_bytes: %llu\nmax_value_bytes: %llu\n",
             SILC_VERSION, PROTO_VERSION, S->id, count, (unsigned long long)used,
             (unsigned long long)srv_cfg.max_session_bytes,
             (unsigned long long)srv_cfg.max_value_bytes);
    if (reply_text(S, PROTO_TEXT, text)) return -1;
    return reply_text(S, PROTO_OK, NULL);
}

/* The hello exchange must end within --handshake-timeout however slowly
 * the peer trickles its bytes: SIGALRM ends this process, and the parent
 * logs why (silcd.c, reap_children). */
static void handshake_deadline(int ms)
{
    struct itimerval t;
    /* silcd --mpi holds all sessions in one process: a timer would end
     * them all; there the handshake's reads time out one by one. */
    if (srv_mpi) return;
    memset(&t, 0, sizeof t);
    t.it_value.tv_sec = ms / 1000;
    t.it_value.tv_usec = (ms % 1000) * 1000;
    setitimer(ITIMER_REAL, &t, NULL);
}

/* A session's engine, with the server's configuration; on every rank of
 * silcd --mpi (collective there).  It is a server session's (cfg_serve): no
 * server settings, files only beneath --data-dir (docs/security.md). */
static int session_engine(silc_engine **E, unsigned long id, char *err, size_t errlen)
{
    int rc;
    if (srv_mpi) {
        struct silc_comm_ops *comm = srv_mpi->engine_comm(srv_mpi, err, errlen);
        rc = comm ? eng_create_comm(E, srv_cfg.engine_config, comm, err, errlen) : -1;
    } else {
        rc = eng_create(E, srv_cfg.engine_config, err, errlen);
    }
    if (!rc) (*E)->max_statement_bytes = SRV_MAX_STATEMENT_BYTES;
    if (!rc && cfg_serve(*E, srv_cfg.data_dir, srv_cfg.shared_data_dir, id)) {
        snprintf(err, errlen, "%s", (*E)->err);
        eng_destroy(E);
        return -1;
    }
    if (!rc && srv_cfg.threads > 0) {
        (*E)->threads = srv_cfg.threads;
        ld_set_threads(*E, srv_cfg.threads);
    }
    return rc;
}

/* Hello both ways, then OK, or ERROR and -1.  The client's hello comes from
 * in (silcd --mpi: read already, in memory), else from the socket. */
static int handshake(session *S, const proto_stream *in)
{
    proto_stream st = {S->fd, srv_cfg.handshake_timeout_ms, NULL, 0, 0};
    uint8_t hello[PROTO_HELLO_BYTES];
    struct iovec iov;
    uint32_t version;
    char *token = NULL, why[512];
    int rc;
    if (in) st = *in;
    handshake_deadline(srv_cfg.handshake_timeout_ms);
    rc = proto_read_hello(&st, &version, &token, why, sizeof why);
    if (rc) {
        srv_log(LOG_INFO, "session %lu: handshake failed: %s", S->id, why);
        if (rc == PROTO_FATAL) reply_error(S, why);
        free(token);
        return -1;
    }
    proto_encode_hello(hello, PROTO_VERSION, 0);
    iov.iov_base = hello;
    iov.iov_len = sizeof hello;
    if (send_parts(S, &iov, 1, NULL, 1)) {
        free(token);
        return -1;
    }
    if (version != PROTO_VERSION) {
        snprintf(why, sizeof why, "protocol version %u is not supported (this server speaks %u)",
                 (unsigned)version, PROTO_VERSION);
        rc = -1;
    } else {
        /* The hello is in: the deadline now leaves room for the wait that
         * recent failures from this peer impose (auth.c; logged there). */
        handshake_deadline(srv_cfg.handshake_timeout_ms + SRV_AUTH_MAX_WAIT_MS);
        rc = srv_auth_verify(S->fd, token, !srv_mpi, why, sizeof why);
        if (rc) {
            free(token);
            handshake_deadline(0);
            reply_error(S, why);
            return -1;
        }
    }
    free(token);
    handshake_deadline(0);
    if (rc) {
        srv_log(LOG_WARN, "session %lu: refused: %s", S->id, why);
        reply_error(S, why);
        return -1;
    }
    if (srv_mpi) srv_mpi->command(srv_mpi, SRV_CMD_OPEN, S->id, NULL);
    S->announced = srv_mpi != NULL;
    rc = session_engine(&S->E, S->id, S->err, sizeof S->err);
    if (rc) {
        srv_log(LOG_ERROR, "session %lu: engine: %s", S->id, S->err);
        reply_error(S, S->err);
        return -1;
    }
    S->E->output = capture_output;
    S->E->output_user = S;
    S->E->cancel = srv_watch_check;
    S->E->cancel_user = &S->watch;
    return reply_text(S, PROTO_OK, "silcd " SILC_VERSION);
}

void srv_session_expire(session *S)
{
    char msg[160];
    snprintf(msg, sizeof msg, "session closed: idle for %g s (silcd --idle-timeout); "
             "its values are gone", srv_cfg.idle_timeout_ms / 1000.0);
    srv_log(LOG_INFO, "session %lu: %s", S->id, msg);
    reply_text(S, PROTO_ERROR, msg);
    if (!S->queued) shutdown(S->fd, SHUT_WR);   /* queued: written as the session closes */
}

/* Waits for the next request; 0 when one is arriving, -1 on shutdown or
 * after --idle-timeout, which the client is told with an ERROR that its
 * next read finds.  Spins first only when the client followed the last
 * request of this kind quickly (client.h, proto_spin_memo). */
static int await_request(session *S)
{
    struct pollfd p[2];
    double deadline = util_now() + srv_cfg.idle_timeout_ms / 1000.0;
    int64_t started = proto_now_ns();
    p[0].fd = S->fd;
    p[0].events = POLLIN;
    p[1].fd = srv_shutdown_fd;
    p[1].events = POLLIN;
    if (proto_spin(p, 2, proto_spin_budget(&S->spin, S->last_kind))) {
        proto_spin_learn(&S->spin, S->last_kind, proto_now_ns() - started);
        return p[1].revents ? -1 : 0;
    }
    for (;;) {
        int wait = -1, rc;
        if (srv_cfg.idle_timeout_ms > 0) {
            double left = deadline - util_now();
            wait = left > 0 ? (int)(left * 1000) + 1 : 0;
        }
        p[0].revents = p[1].revents = 0;
        rc = poll(p, 2, wait);
        if (rc < 0) continue;
        if (p[1].revents) return -1;
        if (p[0].revents) {
            proto_spin_learn(&S->spin, S->last_kind, proto_now_ns() - started);
            return 0;
        }
        if (rc == 0 && srv_cfg.idle_timeout_ms > 0 && util_now() >= deadline) {
            srv_session_expire(S);
            return -1;
        }
    }
}

static int serve_one(session *S, proto_stream *st, const proto_limits *lim)
{
    proto_request q;
    int rc = proto_read_request(st, lim, &q, S->err, sizeof S->err);
    if (rc == PROTO_BROKEN) {
        srv_log(LOG_INFO, "session %lu: %s", S->id, S->err);
        rc = -1;
    } else if (rc == PROTO_FATAL) {
        srv_log(LOG_WARN, "session %lu: malformed frame, closing: %s", S->id, S->err);
        reply_error(S, S->err);
        rc = -1;
    } else if (rc == PROTO_REFUSED) {
        rc = reply_error(S, S->err);
    } else {
        srv_log(LOG_DEBUG, "session %lu: %s", S->id, proto_op_name(q.op));
        S->last_kind = proto_spin_kind(q.op, q.text);
        switch (q.op) {
        case PROTO_PUT: rc = do_put(S, st, &q); break;
        case PROTO_GET: rc = do_get(S, q.text, 0); break;
        case PROTO_GET_COMPLEX: rc = do_get(S, q.text, 1); break;
        case PROTO_EXEC: rc = do_exec(S, q.text); break;
        case PROTO_DELETE: rc = do_delete(S, q.text); break;
        case PROTO_LIST: rc = do_list(S); break;
        case PROTO_INFO: rc = do_info(S, q.text); break;
        case PROTO_EXPLAIN: {
            strbuf b;
            sb_init(&b);
            sb_printf(&b, "explain %s", q.text);
            rc = do_exec(S, sb_str(&b));
            sb_free(&b);
            break;
        }
        case PROTO_CANCEL:
            /* It came after the EXEC it was meant for had ended (the
             * watch takes one that comes in time, limits.c): nothing to
             * stop, and no reply, as the client expects none. */
            rc = 0;
            break;
        default: /* PROTO_BYE */
            reply_text(S, PROTO_OK, NULL);
            rc = -1;
            break;
        }
    }
    proto_request_free(&q);
    return rc;
}

static session *session_open(int fd, unsigned long id, volatile int *state,
                             const proto_stream *hello, int queued)
{
    session *S = calloc(1, sizeof *S);
    if (!S) {
        srv_log(LOG_ERROR, "session %lu: out of memory", id);
        close(fd);
        return NULL;
    }
    S->fd = fd;
    S->id = id;
    S->queued = queued;
    S->state = state ? state : &S->slot;
    S->lim.max_value_bytes = srv_cfg.max_value_bytes;
    S->lim.max_text_bytes = srv_cfg.max_text_bytes;
    S->st = (proto_stream){fd, srv_cfg.io_timeout_ms, NULL, 0, 0};
    if (handshake(S, hello)) {
        srv_session_close(S);
        return NULL;
    }
    *S->state = SLOT_READY;
    srv_log(LOG_INFO, "session %lu: open", id);
    if (srv_output_init()) /* once per process: a session's, or rank 0's under --mpi */
        srv_log(LOG_WARN, "session %lu: no pipe for library output: what libraries print goes to silcd's "
                "standard output", id);
    return S;
}

session *srv_session_open_hello(int fd, unsigned long id, const uint8_t *hello, size_t len)
{
    proto_stream st = {-1, 0, hello, len, 0};
    return session_open(fd, id, NULL, &st, 1);
}

int srv_session_wants_arrays(session *S, const uint8_t *head, size_t len)
{
    proto_stream st = {-1, 0, head, len, 0};
    proto_request q;
    char why[512];
    int want = proto_read_request(&st, &S->lim, &q, why, sizeof why) == 0 &&
               q.op == PROTO_PUT && put_refusal(S, &q) == 0;
    proto_request_free(&q);
    return want;
}

int srv_session_serve(session *S, const uint8_t *frame, size_t len)
{
    proto_stream st = {-1, 0, frame, len, 0};
    int rc = serve_one(S, &st, &S->lim);
    *S->state = SLOT_READY;
    return rc;
}

static int session_step(session *S)
{
    int rc = serve_one(S, &S->st, &S->lim);
    *S->state = SLOT_READY;
    return rc;
}

int srv_session_flush(session *S)
{
    reply_queue *q = &S->q;
    while (q->first < q->n) {
        struct iovec iov[64];
        struct msghdr m;
        size_t k, cnt = 0;
        ssize_t sent;
        for (k = q->first; k < q->n && cnt < 64; k++, cnt++) {
            size_t skip = k == q->first ? q->off : 0;
            iov[cnt].iov_base = (void *)(uintptr_t)(q->parts[k].p + skip);
            iov[cnt].iov_len = q->parts[k].len - skip;
        }
        memset(&m, 0, sizeof m);
        m.msg_iov = iov;
        m.msg_iovlen = cnt;
        sent = sendmsg(S->fd, &m, MSG_DONTWAIT | MSG_NOSIGNAL);
        if (sent < 0 && errno == EINTR) continue;
        if (sent < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return 1;
        if (sent < 0) {
            srv_log(LOG_INFO, "session %lu: writing a reply: %s", S->id, strerror(errno));
            return -1;
        }
        q->bytes -= (uint64_t)sent;
        while (sent > 0) {
            reply_part *r = &q->parts[q->first];
            size_t left = r->len - q->off;
            if ((size_t)sent < left) {
                q->off += (size_t)sent;
                break;
            }
            sent -= (ssize_t)left;
            part_done(r);
            q->first++;
            q->off = 0;
        }
    }
    q->first = q->n = 0;
    return 0;
}

uint64_t srv_session_pending(const session *S)
{
    return S->q.bytes;
}

void srv_session_close(session *S)
{
    if (!S) return;
    /* A last reply (BYE's OK, a refusal, --idle-timeout's ERROR) goes out
     * if the socket takes it now; a reply the client is not reading is
     * dropped. */
    if (S->queued && srv_session_flush(S) == 1)
        srv_log(LOG_INFO, "session %lu: closed with %llu bytes of its reply unread", S->id,
                (unsigned long long)S->q.bytes);
    if (S->announced) srv_mpi->command(srv_mpi, SRV_CMD_CLOSE, S->id, NULL);
    if (S->E) {
        eng_destroy(&S->E);
        srv_log(LOG_INFO, "session %lu: closed", S->id);
    }
    free(S->out.p);
    queue_clear(&S->q);
    free(S->q.parts);
    close(S->fd);
    free(S);
}

int srv_session(int fd, unsigned long id, volatile int *state)
{
    session *S = session_open(fd, id, state, NULL, 0);
    if (!S) return 0;
    while (await_request(S) == 0 && session_step(S) == 0) {}
    srv_session_close(S);
    return 1;
}

/* ---- the other ranks of silcd --mpi ------------------------------------------ */

typedef struct follower {
    unsigned long id;
    silc_engine *E;
    struct follower *next;
} follower;

static silc_engine *engine_of(follower *list, unsigned long id)
{
    for (; list; list = list->next)
        if (list->id == id) return list->E;
    return NULL;
}

static void quiet(void *user, const char *text)
{
    (void)user;
    (void)text;
}

/* The engine-side half of each of rank 0's steps above, in the same order,
 * so that both reach the same collectives: do_put's dist_share, do_get's
 * dist_whole, do_exec's statements and verdict, do_delete, memo_give_way's
 * release, the engine's creation and end. */
int srv_follow(void)
{
    follower *list = NULL, **pp, *f;
    char err[4096];
    /* What a library prints on this rank during a request is not the
     * operator's: it is caught and dropped (a replicated solve prints on
     * every rank; rank 0 sends its copy). */
    if (srv_output_init())
        srv_log(LOG_WARN, "rank %d: no pipe for library output: what libraries print goes to silcd's "
                "standard output", srv_mpi->rank);
    for (;;) {
        int cmd;
        unsigned long id;
        char *text = NULL;
        silc_engine *E;
        if (srv_mpi->receive(srv_mpi, &cmd, &id, &text)) break;
        if (cmd == SRV_CMD_STOP) {
            free(text);
            break;
        }
        E = engine_of(list, id);
        if (cmd == SRV_CMD_CLOSE && !E) {
            /* its engine could not be made here: nothing to close */
        } else if (cmd == SRV_CMD_OPEN) {
            silc_engine *ne = NULL;
            if (session_engine(&ne, id, err, sizeof err) == 0) {
                if (!(f = calloc(1, sizeof *f))) {
                    srv_log(LOG_ERROR, "rank %d: out of memory following session %lu", srv_mpi->rank, id);
                    abort(); /* this rank can no longer follow rank 0: the job ends */
                }
                ne->output = quiet;
                f->id = id;
                f->E = ne;
                f->next = list;
                list = f;
            }
        } else if (!E) {
            srv_log(LOG_ERROR, "rank %d: command %d for unknown session %lu", srv_mpi->rank, cmd, id);
            abort();
        } else if (cmd == SRV_CMD_CLOSE) {
            for (pp = &list; *pp && (*pp)->id != id; pp = &(*pp)->next) {}
            f = *pp;
            *pp = f->next;
            eng_destroy(&f->E);
            free(f);
        } else if (cmd == SRV_CMD_PUT) {
            silc_value *w;
            if (dist_share(E, NULL, srv_mpi->min_rows, &w) == 0) {
                api_bind(E, text, w, err, sizeof err);
                val_release(w);
            }
        } else if (cmd == SRV_CMD_GET) {
            const silc_value *v = store_get(&E->store, text);
            if (v) dist_whole(E, v, 0);
        } else if (cmd == SRV_CMD_RELEASE) {
            if (memo_release_named(E, text ? text : "", err, sizeof err)) release_failed(id, err);
        } else if (cmd == SRV_CMD_DELETE) {
            store_remove(&E->store, text);
            eng_info_remove(E, text);
        } else if (cmd == SRV_CMD_EXEC) {
            eng_snapshot snap;
            int guarded = exec_guarded(), have = 0;
            int64_t over = 0;
            unsigned long long dropped;
            if (guarded) have = eng_snapshot_take(E, &snap) == 0;
            exec_budget(E, 1);
            srv_output_begin();
            api_exec(E, text, err, sizeof err);
            srv_output_end(&dropped); /* rank 0's copy is the client's; this one is dropped */
            exec_budget(E, 0);
            if (guarded) {
                srv_mpi->word(srv_mpi, &over);
                if (over && have) eng_snapshot_restore(E, &snap);
                else if (have) eng_snapshot_free(&snap);
            }
        }
        free(text);
    }
    while (list) {
        f = list->next;
        eng_destroy(&list->E);
        free(list);
        list = f;
    }
    return 0;
}
