/*
 * client.h -- the client side of the engine (core/client/): what silc.h
 * promises, embedded (api.c: contexts over an engine of their own) or
 * remote (remote.c over the wire protocol, protocol.c, which silcd shares),
 * the array pool (pool.c) and Matrix Market files (mmio.c).  It sits on
 * top: it calls the engine, the language and the store, and nothing below
 * calls it.
 *
 * ---- the embedded operations (api.c) behind silc_put, silc_get and silc_exec,
 * shared by api.c (embedded contexts) and silcd (one engine per session), so
 * that a remote caller gets exactly the messages an embedded one gets.
 * Each returns 0 or -1 with the message in err.
 */
#ifndef SILC_CLIENT_H
#define SILC_CLIENT_H

#include <stddef.h>
#include <stdint.h>
#include <sys/uio.h>

#include "engine.h"
#include "silc.h"
#include "store.h"
#include "util.h"

/* Names follow the language's identifiers, so every put value can be used. */
int api_check_name(const char *name, char *err, size_t errlen);
/* Binds v (retained) to name as data from the program. */
int api_bind(silc_engine *E, const char *name, silc_value *v, char *err, size_t errlen);
/* The value bound to name (borrowed), or NULL with "undefined name 'u' (did
 * you mean 'v'?)" in err. */
const silc_value *api_lookup(silc_engine *E, const char *name, char *err, size_t errlen);
/* Runs statements, warnings collected in E->warnings (cleared first). */
int api_exec(silc_engine *E, const char *statements, char *err, size_t errlen);

/*
 * ---- the pool (pool.c): the process's pool of recently freed large arrays (pool.c says
 * why).  silcd installs it with its --array-pool cap; a program using libsilc
 * gets it at its first silc_open / silc_open_remote with the cap
 * $SILC_ARRAY_POOL (MiB; 0 turns it off), else POOL_DEFAULT_MIB.
 */

#define POOL_DEFAULT_MIB 256

/* Makes value and envelope arrays recycle through the pool, which keeps at
 * most cap bytes; 0 leaves arrays to malloc and free.  Call before the
 * threads that use values start. */
void pool_install(size_t cap);
/* pool_install with the library's default cap, once per process. */
void pool_install_default(void);

/*
 * ---- the wire protocol (protocol.c): one implementation of frame encoding,
 * decoding and validation shared by the remote client (remote.c), the server
 * (server/) and the fuzz harness (tests/fuzz/).  docs/protocol.md is the
 * normative description; this section is its C form.
 *
 * A connection opens with a 12-byte hello each way ("SILC", u32 version,
 * u32 token length, then the token from the client), then carries frames:
 * a 16-byte header (u32 opcode, u32 flags = 0, u64 body length), then the
 * body.  Integers are little-endian; array payloads are the host's doubles
 * and int64s, sent as they lie in memory (silcd and the client refuse to run
 * on a big-endian host rather than swap).
 *
 * Decoding never trusts a length: every count is checked against the limits
 * and against the body length with overflow-safe arithmetic before anything
 * is allocated, and a value's arrays are read straight into their final
 * place (the value's arrays on the server, the envelope's on the client).
 * Reading goes through a proto_stream, a socket with a timeout or a memory
 * buffer, so the fuzz harness drives exactly the code the server runs.
 */

#define PROTO_MAGIC "SILC"
#define PROTO_VERSION 1u
#define PROTO_HELLO_BYTES 12
#define PROTO_HEADER_BYTES 16
#define PROTO_DESC_BYTES 48
#define PROTO_MAX_TOKEN 4096u
#define PROTO_MAX_NAME 1024u
#define PROTO_MAX_DIM ((int64_t)1 << 40)   /* rows or columns of one value */

enum proto_op {
    /* requests */
    PROTO_PUT = 1, PROTO_GET = 2, PROTO_EXEC = 3, PROTO_DELETE = 4,
    PROTO_LIST = 5, PROTO_INFO = 6, PROTO_EXPLAIN = 7, PROTO_BYE = 8,
    PROTO_CANCEL = 9,   /* no reply of its own: it ends the running EXEC early */
    PROTO_GET_COMPLEX = 10, /* GET from a client that takes complex values: a plain GET of
                               a complex value is refused, so an older client never
                               receives one (an older server refuses this opcode) */
    /* replies */
    PROTO_OK = 128, PROTO_ERROR = 129, PROTO_VALUE = 130, PROTO_TEXT = 131, PROTO_WARN = 132
};

/* Outcomes of the decoders, beyond 0 = a well-formed message was read. */
enum {
    PROTO_REFUSED = 1,   /* the message was read whole but is not acceptable: reply ERROR, go on */
    PROTO_FATAL = -1,    /* the stream cannot be resynchronised: reply ERROR, then close */
    PROTO_BROKEN = -2    /* end of stream, I/O error or timeout: close */
};

typedef struct proto_limits {
    uint64_t max_value_bytes;  /* arrays of one value */
    uint64_t max_text_bytes;   /* statements, messages, output */
} proto_limits;

/* Value descriptor: the first 48 bytes of PUT and VALUE bodies. */
typedef struct proto_desc {
    uint32_t format;           /* SILC_DENSE, SILC_CSR, SILC_BAND, | SILC_COMPLEX for a complex
                                  value (values then 16 bytes an entry, interleaved re, im) */
    uint32_t namelen;          /* PUT: bytes of the name that follows; VALUE: 0 */
    int64_t m, n, nnz, kl, ku;
} proto_desc;

/* Byte counts of a value's arrays, in wire order. */
typedef struct proto_layout {
    uint64_t rowptr_bytes, colind_bytes, values_bytes, total;
} proto_layout;

/* A source of bytes: a socket (fd >= 0, each wait bounded by timeout_ms, < 0
 * for none) or, with fd < 0, the memory buffer mem[0..memlen). */
typedef struct proto_stream {
    int fd;
    int timeout_ms;
    const uint8_t *mem;
    size_t memlen, mempos;
} proto_stream;

/* A decoded request.  text is NUL-terminated and malloc'd (name of PUT, GET,
 * DELETE, INFO; statements of EXEC, EXPLAIN), NULL when the body is empty. */
typedef struct proto_request {
    uint32_t op;
    char *text;
    size_t textlen;
    proto_desc desc;           /* PUT */
    proto_layout layout;       /* PUT: what proto_read_value will read */
} proto_request;

/* A decoded reply: text for OK, ERROR, TEXT, WARN; env for VALUE. */
typedef struct proto_reply {
    uint32_t op;
    char *text;
    size_t textlen;
    silc_envelope_t env;
} proto_reply;

/* Where a server listens: tcp://host:port (host may be [v6]) or unix:/path. */
typedef struct proto_addr {
    int is_unix;
    char host[256], port[16];
    char path[108];            /* sun_path's size on Linux */
} proto_addr;
int proto_parse_url(const char *url, proto_addr *a, char *err, size_t errlen);

/* ---- encoding -------------------------------------------------------------- */
void proto_put_u32(uint8_t *p, uint32_t x);
void proto_put_u64(uint8_t *p, uint64_t x);
uint32_t proto_get_u32(const uint8_t *p);
uint64_t proto_get_u64(const uint8_t *p);
void proto_encode_hello(uint8_t out[PROTO_HELLO_BYTES], uint32_t version, uint32_t token_len);
void proto_encode_header(uint8_t out[PROTO_HEADER_BYTES], uint32_t op, uint64_t len);
/* A frame's parts: iov[0] = hdr, filled with op and the body's length, then
 * body[0..n).  Returns n + 1, or -1 when n > PROTO_FRAME_PARTS - 1.  One
 * function for the client's send and the server's (which may queue it). */
#define PROTO_FRAME_PARTS 8
int proto_frame_iov(uint8_t hdr[PROTO_HEADER_BYTES], uint32_t op, const struct iovec *body, int n,
                    struct iovec iov[PROTO_FRAME_PARTS]);
void proto_encode_desc(uint8_t out[PROTO_DESC_BYTES], const proto_desc *d);
/* Descriptor and array pointers of a value, for sending it without a copy;
 * returns the number of iovecs (at most 3) filled, -1 if too large. */
int proto_value_iov(const silc_value *v, proto_desc *d, struct iovec iov[3]);
/* Checks a descriptor (format, signs, dimensions, nnz consistency) and
 * computes its layout with overflow-safe arithmetic; refuses a value larger
 * than max_bytes.  Messages name the offending field. */
int proto_layout_of(const proto_desc *d, uint64_t max_bytes, proto_layout *L, char *err,
                    size_t errlen);
const char *proto_op_name(uint32_t op);

/* ---- I/O ------------------------------------------------------------------- */
/* Reads or writes every byte of iov (modified); 0 or PROTO_BROKEN with err
 * saying why ("connection closed by peer", "timed out after 30 s", ...). */
int proto_recv(proto_stream *s, struct iovec *iov, int iovcnt, char *err, size_t errlen);
int proto_send(int fd, struct iovec *iov, int iovcnt, int timeout_ms, char *err, size_t errlen);

/* How long a reader or writer busy-waits before it sleeps in poll.  Waking a
 * sleeping thread costs ~10 us on the 2-core VM (more than the whole server
 * side of a small EXEC, and more than copying the 64 KiB a bulk transfer
 * waits for), so a wait inside a frame spins this long first: a bulk
 * transfer never sleeps.  The waits between frames -- a client for the
 * first reply to its request, silcd for a session's next request -- spin
 * only when the last wait of the same kind ended within this time
 * (proto_spin_memo below): a ping-pong of small requests never sleeps,
 * and a side whose peer is computing (an EXEC of milliseconds, a client
 * between steps) sleeps at once instead of burning 50 us of a core per
 * request, which the CPU clock of a shared machine counts. */
#define PROTO_SPIN_NS 50000
/* Polls the n descriptors (for their events) without blocking until one is
 * ready (1) or budget_ns have passed (0; 0 ns polls once); revents are set
 * as by poll. */
struct pollfd;
int proto_spin(struct pollfd *p, int n, int64_t budget_ns);

/* What the last waits of each kind took, so that the next wait of that
 * kind spins only if spinning would have paid: a kind is a request's
 * opcode and text (an EXEC's statements, a GET's name), hashed, which a
 * program's loop repeats.  A kind not seen yet spins; one whose last wait
 * outlasted PROTO_SPIN_NS does not, except every PROTO_SPIN_PROBE-th wait,
 * which spins again to notice a kind that became quick.  A direct-mapped
 * table of PROTO_SPIN_KINDS entries: a colliding kind takes the entry
 * over. */
#define PROTO_SPIN_KINDS 64
#define PROTO_SPIN_PROBE 16
typedef struct proto_spin_memo {
    struct {
        uint64_t key;        /* 0: empty */
        int64_t waited_ns;   /* the last wait of that kind */
        unsigned sleeps;     /* waits without spinning since the last spin */
    } kind[PROTO_SPIN_KINDS];
} proto_spin_memo;
/* The kind of a wait for the reply to (or the request after) op with text
 * (NULL: none): never 0. */
uint64_t proto_spin_kind(uint32_t op, const char *text);
/* The spin budget of the next wait of kind key: PROTO_SPIN_NS or 0. */
int64_t proto_spin_budget(proto_spin_memo *m, uint64_t key);
/* Records that a wait of kind key took waited_ns. */
void proto_spin_learn(proto_spin_memo *m, uint64_t key, int64_t waited_ns);
/* Nanoseconds of the monotonic clock, for timing waits. */
int64_t proto_now_ns(void);
/* Sends one frame whose body is the concatenation of body[0..n). */
int proto_send_frame(int fd, uint32_t op, const struct iovec *body, int n, int timeout_ms,
                     char *err, size_t errlen);
int proto_send_text(int fd, uint32_t op, const char *text, int timeout_ms, char *err,
                    size_t errlen);
/* Drops nbytes of the stream unread.  A memory stream holds what its filler
 * kept of a message (silcd --mpi's reader keeps only the bytes a decoder
 * reads, server/mpi_server.c): skipping past its end succeeds, those bytes
 * never having been kept; reading past it fails. */
int proto_skip(proto_stream *s, uint64_t nbytes, char *err, size_t errlen);

/* ---- decoding -------------------------------------------------------------- */
/* Hello from the peer: checks the magic; *version and *token (malloc'd,
 * NUL-terminated, NULL if empty) are returned for the caller to judge. */
int proto_read_hello(proto_stream *s, uint32_t *version, char **token, char *err, size_t errlen);
/* Server side: one request.  For PUT only the descriptor and name are read;
 * the caller then calls proto_read_value or proto_skip(layout.total). */
int proto_read_request(proto_stream *s, const proto_limits *lim, proto_request *r, char *err,
                       size_t errlen);
/* Reads the arrays of a PUT into a new value and validates it exactly as an
 * embedded silc_put would (same messages).  PROTO_REFUSED leaves *out NULL. */
int proto_read_value(proto_stream *s, const proto_request *r, silc_value **out, char *err,
                     size_t errlen);
void proto_request_free(proto_request *r);
/* Client side: one reply, VALUE arrays read straight into r->env and
 * checked as a PUT's are.  A well-framed VALUE over lim->max_value_bytes is
 * skipped and PROTO_REFUSED; any other bad reply is PROTO_FATAL. */
int proto_read_reply(proto_stream *s, const proto_limits *lim, proto_reply *r, char *err,
                     size_t errlen);
void proto_reply_free(proto_reply *r);

/*
 * ---- remote contexts (remote.c): the client transport: a connection to silcd
 * carrying the calls of silc.h as protocol frames (above).  Used only by
 * api.c, which keeps the context-level state (output callback, warnings,
 * message) and calls these for the wire.
 *
 * Each call returns 0, or -1 with the message in err: the server's own text
 * for a refused request (identical to the embedded message), or a transport
 * failure naming the server.  After a transport failure the connection is
 * dead and every later call says so.
 */

typedef struct rem_conn rem_conn;

/* url: tcp://host:port or unix:/path.  token may be NULL (none). */
int rem_open(rem_conn **out, const char *url, const char *token, char *err, size_t errlen);
void rem_close(rem_conn **c);               /* says BYE, then closes */
int rem_put(rem_conn *c, const char *name, const silc_envelope_t *e, char *err, size_t errlen);
int rem_get(rem_conn *c, silc_envelope_t *e, const char *name, int accept_complex, char *err,
            size_t errlen);
/* EXEC: TEXT replies go to fn (stdout when NULL) as they come,
 * WARN replies are appended to warnings. */
int rem_exec(rem_conn *c, const char *statements, silc_output_fn fn, void *user,
             strbuf *warnings, char *err, size_t errlen);
/* Sends CANCEL if an EXEC is waiting for its reply (else nothing); its
 * reply then comes as usual, ERROR "interrupted" if the server stopped it.
 * Async-signal-safe and callable from another thread (silc_cancel). */
int rem_cancel(rem_conn *c);

#endif
