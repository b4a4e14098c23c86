/*
 * server.h -- what silcd.c (the parent process: options, listening, signals,
 * one child process per connection) and session.c (one connection, in its
 * child: handshake, requests, the session's engine) share.  docs/server.md
 * explains the process model.
 */
#ifndef SILCD_SERVER_H
#define SILCD_SERVER_H

#include <stddef.h>
#include <stdint.h>

enum { LOG_ERROR = 0, LOG_WARN = 1, LOG_INFO = 2, LOG_DEBUG = 3 };

typedef struct srv_config {
    const char *listen;          /* tcp://host:port or unix:/path */
    const char *engine_config;   /* silc.conf for every session's engine, or NULL */
    int threads;                 /* thread budget of one operation; 0 = the config's */
    char *token;                 /* shared secret, NULL = none */
    size_t token_len;
    uint64_t max_value_bytes;    /* arrays of one PUT */
    uint64_t max_session_bytes;  /* values bound in one session; 0 = unlimited */
    uint64_t max_text_bytes;     /* one statement */
    int io_timeout_ms;           /* a peer stalling inside a frame is dropped after this */
    int handshake_timeout_ms;    /* a connection must complete its handshake within this */
    int idle_timeout_ms;         /* a session idle this long is closed; 0 = never */
    int max_clients;
    double peer_share;           /* of max_clients, the most one peer address may hold */
    int log_level;
    uint64_t pool_bytes;         /* freed value arrays kept for reuse; 0 = none */
    int max_cpu_s;               /* CPU seconds of one session's process; 0 = no limit */
    int max_request_ms;          /* wall-clock time of one request; 0 = no limit */
    const char *data_dir;        /* --data-dir: sessions' files beneath it; NULL = none */
    int shared_data_dir;         /* --shared-data-dir: one folder for all, not session-<id> */
} srv_config;

extern srv_config srv_cfg;
/* Readable once this process should stop: a session polls it while idle. */
extern int srv_shutdown_fd;

/* Where a session's child stands, in memory shared with the parent, so that
 * when a child dies the parent knows whether the client's stream is at a
 * frame boundary (it can then send the client an ERROR saying what
 * happened) or in the middle of a reply (it can only close). */
enum {
    SLOT_FREE = 0,
    SLOT_HANDSHAKE,   /* accepted; no hello from the server yet */
    SLOT_READY,       /* between replies: reading a request */
    SLOT_REPLYING,    /* a reply is partly sent */
    SLOT_RUNNING      /* computing an EXEC: silcd watches for the client hanging up */
};

void srv_log(int level, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

typedef struct session session;
/* --idle-timeout reached: logs it and tells the client why (its next read
 * finds the ERROR); the caller then closes the session. */
void srv_session_expire(session *S);

/* Serves one accepted connection until BYE, disconnect, idle timeout or
 * shutdown, then closes fd.  Runs in the session's own process; id numbers
 * the session in the log; *state is its slot (above).  1 if a session was
 * opened (the handshake completed), else 0. */
int srv_session(int fd, unsigned long id, volatile int *state);

/* ---- who may open a session (auth.c; docs/security.md) ----
 * A token shorter than this is refused at start: a guess must be hopeless. */
#define SRV_MIN_TOKEN_BYTES 16u
/* The longest a check waits behind the failures of its peer address. */
#define SRV_AUTH_MAX_WAIT_MS 10000
/* Reads the token file into srv_cfg.token: a regular file owned by silcd's
 * effective user, readable by no one else, whose first line holds the token.
 * -1 with the reason printed to stderr. */
int srv_auth_load_token(const char *path);
/* silcd --make-token: a new random token (32 hex digits) in a new file of
 * mode 0600; never overwrites.  -1 with the reason printed. */
int srv_auth_make_token(const char *path);
/* The peer's address ("127.0.0.1"), or "" on a Unix socket. */
void srv_peer_of(int fd, char *out, size_t outlen);
/* The per-peer backoff of failed authentications, in memory shared with
 * the session processes: setup once (before forking), hold an address while
 * a connection from it lives, drop it when the connection ends. */
int srv_auth_setup(int max_connections);
void srv_auth_hold(const char *addr);
void srv_auth_drop(const char *addr);
/* The token a client sent on fd: 0 if it may in (or no token is required),
 * else -1 with why.  A failure makes the peer's next check wait (doubling,
 * reset by a success); may_wait 0 (silcd --mpi, one process for every
 * session) refuses such a check unchecked instead of waiting. */
int srv_auth_verify(int fd, const char *given, int may_wait, char *why, size_t whylen);
/* Admission (--max-clients, --peer-share), the same for both servers: a
 * newcomer from peer (its address, "" on a Unix socket) among nslots slots
 * (at describes slot i).  The slot to give it, free or (*evict = 1, why =
 * the limit, for the log) held by the oldest connection that has not
 * completed its handshake, of peer if peer is at its share, else of anyone
 * when no slot is free: the caller closes that one first.  -1 with why, the
 * client's message, when every connection in the way is an open session. */
typedef struct srv_slot_view {
    int live, handshaking;
    const char *peer;
    double accepted;   /* util_now() */
} srv_slot_view;
typedef void (*srv_slot_at)(void *user, int i, srv_slot_view *out);
int srv_admit(const char *peer, int nslots, srv_slot_at at, void *user, int *evict, char *why,
              size_t whylen);
/* Refuses a connection with a hello and an ERROR saying why; closes fd. */
void srv_refuse(int fd, const char *why);
/* ---- limits.c: what no session may pass (docs/security.md, "Limits") ---- */
#define SRV_REQUEST_GRACE_S 2.0   /* past --max-request-seconds, before the process is ended */
#define SRV_SHUTDOWN_GRACE_S 2.0  /* a request in flight at SIGTERM, before it is stopped */
#define SRV_HANGUP_GRACE_S 0.5    /* a client gone, before silcd kills its running session */
#define SRV_WATCH_POLL_S 0.02     /* how often a running request looks at its socket */
#define SRV_DATA_MARGIN ((uint64_t)256 << 20)
#define SRV_MAX_STATEMENT_BYTES ((size_t)4 << 20)  /* longer statement texts are not parsed */
/* The RLIMIT_DATA of a process holding this many sessions: what it has
 * mapped already + 2 x --max-session-bytes each (the values, and as much
 * again for a statement's temporaries and a library's work arrays) +
 * --array-pool + SRV_DATA_MARGIN; 0 (none) without --max-session-bytes. */
uint64_t srv_data_cap(int sessions);
/* In a process that runs engines: die with parent (PR_SET_PDEATHSIG; exits
 * at once if it is already gone), RLIMIT_DATA (srv_data_cap), RLIMIT_CPU
 * (--max-cpu).  -1 if a cap could not be set. */
int srv_limit_process(int parent, int sessions);
/* silcd --mpi, on every rank after srv_limit_process: a rank that reaches
 * --max-cpu (SIGXCPU), or rank 0 whose request is stuck past
 * --max-request-seconds and its grace (SIGALRM), logs why and dies, which
 * ends the job. */
void srv_limit_job(int rank);
/* What a session process's death by sig (in slot state) says about a
 * limit, as a tail for the client's message ("" if nothing). */
void srv_death_reason(int sig, int state, char *out, size_t outlen);
enum { SRV_STOP_NONE = 0, SRV_STOP_TIME, SRV_STOP_GONE, SRV_STOP_SHUTDOWN };
/* One running request's watch: the engine's cancel hook (srv_watch_check,
 * user = the watch) stops it past --max-request-seconds, when the client on
 * fd hangs up, or a grace after shutdown; stop says which.  A CANCEL frame
 * from the client (read by the watch) interrupts it: cancelled. */
typedef struct srv_watch {
    int fd;
    double deadline, next_poll, shutdown_at;
    int stop;
    int cancelled;   /* the client sent CANCEL: "interrupted", an ordinary failure (no stop) */
    char why[256];   /* the client's message once stop is set */
    /* Called at each poll: sends what the request has printed so far;
     * nonzero when the client cannot be written to (it has gone). */
    int (*flush)(void *user);
    void *flush_user;
} srv_watch;
void srv_watch_begin(srv_watch *w, int fd);
/* A request's library output (output.c): while it runs, descriptor 1 is a
 * pipe the watch empties; srv_output_end gives what it held (NULL: none),
 * at most 1 MiB, and how many bytes beyond were dropped.  Without
 * srv_output_init (once per process; -1 if it failed) nothing is caught. */
int srv_output_init(void);
void srv_output_begin(void);
void srv_output_drain(void);
const char *srv_output_end(unsigned long long *dropped);
void srv_watch_end(srv_watch *w);
int srv_watch_check(void *user, char *why, size_t whylen);

/* ---- silcd --mpi (mpi_server.c; docs/server.md, docs/distributed.md) ----
 * Rank 0 holds every connection in one process and serves one request at a
 * time; each session's engine runs on every rank (dist.h), so before rank
 * 0's engine takes a step that the other ranks must share, it announces the
 * step (command), and the other ranks, in srv_follow, take the same step on
 * their engine of that session. */
enum { SRV_CMD_OPEN = 1, SRV_CMD_CLOSE, SRV_CMD_PUT, SRV_CMD_GET, SRV_CMD_EXEC, SRV_CMD_DELETE,
       SRV_CMD_STOP, SRV_CMD_RELEASE /* text: rank 0's plan of what gives way (memo_release_plan) */ };
struct silc_comm_ops;
typedef struct srv_ranks {
    int rank, size;
    int64_t min_rows;            /* --dist-min-rows: smaller PUTs are copied whole to every rank */
    /* rank 0: tells the others the next step of session id (text: its name or statements) */
    int (*command)(struct srv_ranks *R, int cmd, unsigned long id, const char *text);
    /* other ranks: the next step; *text malloc'd (NULL if none) */
    int (*receive)(struct srv_ranks *R, int *cmd, unsigned long *id, char **text);
    /* rank 0's *w to every rank (a verdict only rank 0 can reach) */
    void (*word)(struct srv_ranks *R, int64_t *w);
    /* a communicator for one session's engine (collective) */
    struct silc_comm_ops *(*engine_comm)(struct srv_ranks *R, char *err, size_t errlen);
    void *impl;
} srv_ranks;
extern srv_ranks *srv_mpi;       /* NULL unless silcd --mpi */

/* The pieces of srv_session that rank 0 of silcd --mpi drives from its own
 * event loop, which reads every connection at once and hands a session
 * only whole messages, in memory (mpi_server.c).  A memory stream holds
 * what that reader kept: the bytes a decoder skips (a refused body, a
 * refused PUT's arrays) are dropped unread (client.h, proto_skip).
 * open: the client's hello (12 bytes and its token) in memory; handshake
 * and engine; NULL, fd closed, if it failed.  wants_arrays: of a PUT whose
 * header, descriptor and name are in head, whether its arrays will be read
 * (1) or refused unread (0).  serve: one request, frame = its kept bytes;
 * 0, or -1 when the session is over.  close. */
session *srv_session_open_hello(int fd, unsigned long id, const uint8_t *hello, size_t len);
int srv_session_wants_arrays(session *S, const uint8_t *head, size_t len);
int srv_session_serve(session *S, const uint8_t *frame, size_t len);
/* Its replies are queued (one at most): flush writes what the socket takes
 * now, without blocking: 0 all out, 1 some left (pending bytes), -1 the
 * connection broke; close writes a last reply if the socket takes it. */
int srv_session_flush(session *S);
uint64_t srv_session_pending(const session *S);
void srv_session_close(session *S);
/* The other ranks of silcd --mpi: follow rank 0's commands until STOP. */
int srv_follow(void);
/* mpi_server.c, built when MPI is found (SILC_HAVE_MPI): MPI_Init and the
 * control communicator (sets srv_mpi); rank 0's serving loop; the end
 * (tells the others to stop, MPI_Finalize). */
int srv_mpi_init(int *argc, char ***argv, int64_t min_rows);
int srv_mpi_serve(int lfd, int is_tcp);
void srv_mpi_finish(void);


#endif
