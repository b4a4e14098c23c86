/*
 * silcd.c -- the SILC server's parent process: options, the listening
 * socket, signals, and one child process per connection (fork after accept,
 * as PostgreSQL does), which runs the session (session.c).
 *
 * A session owns a whole process so that nothing it does can hurt another:
 * a plugin that crashes or a library that aborts takes down only its own
 * session, whose client gets an ERROR saying so from this parent, and two
 * sessions compute at once on two cores with no lock between them.  The
 * parent never runs an engine.  It loads the plugins once before it
 * listens (the children inherit them, as PostgreSQL's preloaded libraries),
 * limits connections (--max-clients, --peer-share), gives each a deadline
 * for its handshake, and on SIGTERM or SIGINT stops accepting, lets the
 * children finish the requests in flight, and exits 0.  docs/server.md is
 * the user's guide.
 */
#define _GNU_SOURCE      /* POLLRDHUP, MAP_ANONYMOUS */
#include "server.h"
#include "client.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <sys/auxv.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "engine.h"
#include "silc.h"

srv_config srv_cfg = {
    "tcp://127.0.0.1:7070", NULL, 0, NULL, 0,
    (uint64_t)2 << 30,   /* max_value_bytes: 2 GiB */
    (uint64_t)4 << 30,   /* max_session_bytes: 4 GiB */
    (uint64_t)64 << 20,  /* max_text_bytes: 64 MiB */
    30000,               /* io_timeout_ms */
    5000,                /* handshake_timeout_ms */
    0,                   /* idle_timeout_ms: never */
    256,                 /* max_clients */
    0.5,                 /* peer_share */
    LOG_INFO,
    (uint64_t)1 << 30,   /* pool_bytes: 1 GiB */
    0,                   /* max_cpu_s: no limit */
    0,                   /* max_request_ms: no limit */
    NULL,                /* data_dir: sessions keep no files */
    0};                  /* shared_data_dir */
int srv_shutdown_fd = -1;

/* Written by the signal handlers, read by the poll loops.  In a child,
 * shutdown_pipe is its own: a signal to one session stops only that one. */
static int shutdown_pipe[2] = {-1, -1};
static int child_pipe[2] = {-1, -1};   /* SIGCHLD: a session process ended */

/* One connection: what the parent knows of it.  state lives in memory
 * shared with the child (server.h); the rest is the parent's. */
typedef struct conn {
    pid_t pid;                 /* 0: free */
    int fd;                    /* the parent's copy, to tell the client of a crash */
    unsigned long id;
    char peer[64];             /* "127.0.0.1", or "" on a Unix socket */
    double accepted;           /* util_now() */
    double hung_up;            /* when its client hung up, 0 = not, -1 = killed for it */
} conn;

static conn *conns;
static pid_t server_pid;           /* the parent, which session processes die with */
static volatile int *conn_state;   /* max_clients ints, MAP_SHARED */
static int n_conns;

static const char *const level_names[] = {"error", "warn", "info", "debug"};

void srv_log(int level, const char *fmt, ...)
{
    char stamp[32], line[2048];
    time_t now = time(NULL);
    struct tm tm;
    va_list ap;
    if (level > srv_cfg.log_level) return;
    localtime_r(&now, &tm);
    strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M:%S", &tm);
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    /* One fprintf per line: lines of concurrent sessions never interleave. */
    fprintf(stderr, "%s silcd[%s]: %s\n", stamp, level_names[level], line);
}

static void usage(FILE *f)
{
    fputs("usage: silcd [options]\n"
          "  --listen URL            tcp://host:port (default tcp://127.0.0.1:7070) or unix:/path\n"
          "  --config FILE           silc.conf for every session's engine\n"
          "  --threads N             threads one operation may use (default: core.threads)\n"
          "  --token-file FILE       the secret clients must present; required on TCP (a file of\n"
          "                          mode 0600 owned by silcd's user, a first line of 16+ bytes)\n"
          "  --insecure              listen on TCP without a token (anyone who can connect may\n"
          "                          run code as this user: loud warning at start)\n"
          "  --make-token FILE       write a new random token to FILE (mode 0600; never\n"
          "                          overwrites) and exit\n"
          "  --max-value-bytes N     largest value one PUT may carry (default 2G)\n"
          "  --max-session-bytes N   memory of the values bound in one session, 0 = no limit (default 4G)\n"
          "  --max-clients N         concurrent connections, handshakes included (default 256)\n"
          "  --peer-share F          the share of --max-clients one TCP peer address may hold\n"
          "                          (default 0.5)\n"
          "  --handshake-timeout S   close a connection that has not completed its handshake\n"
          "                          after S seconds (default 5)\n"
          "  --idle-timeout S        close a session idle for S seconds, 0 = never (default 0)\n"
          "  --array-pool N          freed value arrays kept for the next PUT, 0 = none (default 1G)\n"
          "  --io-timeout SECONDS    drop a peer that stalls inside a frame (default 30)\n"
          "  --max-request-seconds S stop a request running longer than S seconds; the store is\n"
          "                          as before it (default 0 = no limit)\n"
          "  --max-cpu SECONDS       CPU time one session's process may use, 0 = no limit\n"
          "                          (default 0; with --mpi: of each rank over the job's life,\n"
          "                          all sessions together: reaching it ends the job)\n"
          "  --log-level LEVEL       error, warn, info (default) or debug\n"
          "  --ready-file FILE       write the listening address to FILE once ready\n"
          "  --data-dir DIR          sessions may save, load and plot files, each beneath its own\n"
          "                          DIR/session-<id> (made 0700); default: no files (docs/security.md)\n"
          "  --shared-data-dir       with --data-dir: every session works in DIR itself\n"
          "  --mpi                   run on every rank of mpirun: rank 0 serves, every session's\n"
          "                          engine runs on all ranks (docs/distributed.md)\n"
          "  --dist-min-rows N       with --mpi: PUT values of N rows or more are split in row\n"
          "                          blocks among the ranks, smaller ones copied whole (default 1000)\n"
          "  --help, --version\n", f);
}

/* The largest size an option takes: values are counted in int64_t bytes
 * downstream, and a saturated strtoull must not pass for a real number. */
#define SIZE_OPTION_MAX ((uint64_t)INT64_MAX)
#define SECONDS_OPTION_MIN 0.001
#define SECONDS_OPTION_MAX 86400.0

/* "123", "64K", "512M", "2G" (util_parse_size), at most SIZE_OPTION_MAX. */
static int parse_size(const char *s, uint64_t *out, char *why, size_t whylen)
{
    return util_parse_size(s, SIZE_OPTION_MAX, out, why, whylen);
}

/* A decimal integer in [lo, hi]; -1 with why naming the range. */
static int parse_count(const char *s, long long lo, long long hi, long long *out, char *why,
                       size_t whylen)
{
    char *end;
    long long x;
    snprintf(why, whylen, "expected an integer from %lld to %lld", lo, hi);
    if (!s || !((*s >= '0' && *s <= '9') || (*s == '-' && s[1] >= '0' && s[1] <= '9'))) return -1;
    errno = 0;
    x = strtoll(s, &end, 10);
    if (*end || errno == ERANGE || x < lo || x > hi) return -1;
    *out = x;
    return 0;
}

static int parse_int(const char *s, int lo, int hi, int *out, char *why, size_t whylen)
{
    long long x;
    if (parse_count(s, lo, hi, &x, why, whylen)) return -1;
    *out = (int)x;
    return 0;
}

/* Seconds (fractions allowed) from SECONDS_OPTION_MIN to SECONDS_OPTION_MAX,
 * as milliseconds; zero_ok admits 0 (= off). */
static int parse_seconds(const char *s, int zero_ok, int *ms, char *why, size_t whylen)
{
    char *end;
    double x;
    snprintf(why, whylen, "expected %sseconds from %g to %g", zero_ok ? "0 (off) or " : "",
             SECONDS_OPTION_MIN, SECONDS_OPTION_MAX);
    if (!s || !((*s >= '0' && *s <= '9') || *s == '.')) return -1;
    x = strtod(s, &end);
    if (*end || !(x >= 0 && x <= SECONDS_OPTION_MAX)) return -1;
    if (x == 0 ? !zero_ok : x < SECONDS_OPTION_MIN) return -1;
    *ms = (int)(x * 1000 + 0.5);
    return 0;
}

static int mpi_mode;               /* --mpi */
static int insecure;               /* --insecure: TCP without a token */
static const char *make_token;     /* --make-token FILE */
static int64_t dist_min_rows = 1000; /* --dist-min-rows */

/* The options that take a value; any other "--name" is unknown (and
 * --mpi, --insecure, --help, --version take none). */
static const char *const value_options[] = {
    "--listen", "--config", "--threads", "--token-file", "--make-token", "--max-value-bytes",
    "--max-session-bytes", "--array-pool", "--max-clients", "--io-timeout",
    "--handshake-timeout", "--idle-timeout", "--peer-share", "--log-level", "--ready-file",
    "--dist-min-rows", "--max-request-seconds", "--max-cpu", "--data-dir", NULL};

static int takes_value(const char *name)
{
    int k;
    for (k = 0; value_options[k]; k++)
        if (strcmp(name, value_options[k]) == 0) return 1;
    return 0;
}

static int unknown_option(const char *name)
{
    fprintf(stderr, "silcd: unknown option '%s'\n", name);
    usage(stderr);
    return -1;
}

static int parse_args(int argc, char **argv, const char **ready_file)
{
    int i;
    for (i = 1; i < argc; i++) {
        const char *opt = argv[i], *val = NULL;
        char name[64], why[160] = "";
        const char *eq = strchr(opt, '=');
        int ok = 1;
        if (strcmp(opt, "--help") == 0 || strcmp(opt, "-h") == 0) {
            usage(stdout);
            exit(0);
        }
        if (strcmp(opt, "--version") == 0) {
            printf("silcd %s (protocol %u)\n", SILC_VERSION, PROTO_VERSION);
            exit(0);
        }
        if (strcmp(opt, "--mpi") == 0) {
            mpi_mode = 1;
            continue;
        }
        if (strcmp(opt, "--insecure") == 0) {
            insecure = 1;
            continue;
        }
        if (strcmp(opt, "--shared-data-dir") == 0) {
            srv_cfg.shared_data_dir = 1;
            continue;
        }
        if (opt[0] != '-') {
            fprintf(stderr, "silcd: unexpected argument '%s'\n", opt);
            usage(stderr);
            return -1;
        }
        snprintf(name, sizeof name, "%.*s", eq ? (int)(eq - opt) : (int)strlen(opt), opt);
        if (!takes_value(name)) return unknown_option(name);
        if (eq) val = eq + 1;
        else if (i + 1 < argc) val = argv[++i];
        if (!val) {
            fprintf(stderr, "silcd: %s needs a value\n", name);
            return -1;
        }
        if (strcmp(name, "--listen") == 0) srv_cfg.listen = val;
        else if (strcmp(name, "--config") == 0) srv_cfg.engine_config = val;
        else if (strcmp(name, "--data-dir") == 0) {
            struct stat st;
            srv_cfg.data_dir = val;
            ok = stat(val, &st) == 0 && S_ISDIR(st.st_mode);
            if (!ok) snprintf(why, sizeof why, "not a directory silcd can reach");
        }
        else if (strcmp(name, "--threads") == 0)
            ok = !parse_int(val, 1, 4096, &srv_cfg.threads, why, sizeof why);
        else if (strcmp(name, "--token-file") == 0) {
            if (srv_auth_load_token(val)) return -1;   /* it said why */
        } else if (strcmp(name, "--make-token") == 0) make_token = val;
        else if (strcmp(name, "--max-value-bytes") == 0)
            ok = !parse_size(val, &srv_cfg.max_value_bytes, why, sizeof why);
        else if (strcmp(name, "--max-session-bytes") == 0)
            ok = !parse_size(val, &srv_cfg.max_session_bytes, why, sizeof why);
        else if (strcmp(name, "--array-pool") == 0)
            ok = !parse_size(val, &srv_cfg.pool_bytes, why, sizeof why);
        else if (strcmp(name, "--max-clients") == 0)
            ok = !parse_int(val, 1, 65536, &srv_cfg.max_clients, why, sizeof why);
        else if (strcmp(name, "--io-timeout") == 0)
            ok = !parse_seconds(val, 0, &srv_cfg.io_timeout_ms, why, sizeof why);
        else if (strcmp(name, "--max-request-seconds") == 0)
            ok = !parse_seconds(val, 1, &srv_cfg.max_request_ms, why, sizeof why);
        else if (strcmp(name, "--max-cpu") == 0)
            ok = !parse_int(val, 0, 86400 * 365, &srv_cfg.max_cpu_s, why, sizeof why);
        else if (strcmp(name, "--handshake-timeout") == 0)
            ok = !parse_seconds(val, 0, &srv_cfg.handshake_timeout_ms, why, sizeof why);
        else if (strcmp(name, "--idle-timeout") == 0)
            ok = !parse_seconds(val, 1, &srv_cfg.idle_timeout_ms, why, sizeof why);
        else if (strcmp(name, "--peer-share") == 0) {
            char *end;
            srv_cfg.peer_share = strtod(val, &end);
            ok = end != val && !*end && srv_cfg.peer_share > 0 && srv_cfg.peer_share <= 1;
            snprintf(why, sizeof why, "expected a fraction above 0 and at most 1");
        } else if (strcmp(name, "--log-level") == 0) {
            int k;
            ok = 0;
            for (k = 0; k < 4; k++)
                if (strcmp(val, level_names[k]) == 0) {
                    srv_cfg.log_level = k;
                    ok = 1;
                }
            snprintf(why, sizeof why, "expected error, warn, info or debug");
        } else if (strcmp(name, "--ready-file") == 0) *ready_file = val;
        else if (strcmp(name, "--dist-min-rows") == 0) {
            long long r = 0;
            ok = !parse_count(val, 1, INT64_MAX, &r, why, sizeof why);
            dist_min_rows = r;
        }
        if (!ok) {
            fprintf(stderr, "silcd: invalid value '%s' for %s: %s\n", val, name, why);
            return -1;
        }
    }
    return 0;
}

static int is_loopback(const struct sockaddr *sa)
{
    if (sa->sa_family == AF_INET)
        return (ntohl(((const struct sockaddr_in *)sa)->sin_addr.s_addr) >> 24) == 127;
    if (sa->sa_family == AF_INET6)
        return memcmp(&((const struct sockaddr_in6 *)sa)->sin6_addr, &in6addr_loopback,
                      sizeof in6addr_loopback) == 0;
    return 0;
}

/* A unix socket path already in use by a live server is an error; a stale
 * socket file from a crashed one is removed; anything else is left alone. */
static int claim_unix_path(const char *path)
{
    struct stat st;
    struct sockaddr_un sa;
    int fd, live;
    if (lstat(path, &st) != 0) return 0;
    if (!S_ISSOCK(st.st_mode)) {
        fprintf(stderr, "silcd: '%s' exists and is not a socket\n", path);
        return -1;
    }
    memset(&sa, 0, sizeof sa);
    sa.sun_family = AF_UNIX;
    memcpy(sa.sun_path, path, strlen(path) + 1);
    fd = socket(AF_UNIX, SOCK_STREAM, 0);
    live = fd >= 0 && connect(fd, (struct sockaddr *)&sa, sizeof sa) == 0;
    if (fd >= 0) close(fd);
    if (live) {
        fprintf(stderr, "silcd: another server is listening on '%s'\n", path);
        return -1;
    }
    unlink(path);
    return 0;
}

/* Binds and listens; writes the actual address (port 0 resolved) to url. */
static int open_listener(const proto_addr *a, char *url, size_t urllen)
{
    int fd = -1, one = 1;
    if (a->is_unix) {
        struct sockaddr_un sa;
        mode_t old;
        if (claim_unix_path(a->path)) return -1;
        memset(&sa, 0, sizeof sa);
        sa.sun_family = AF_UNIX;
        memcpy(sa.sun_path, a->path, strlen(a->path) + 1);
        fd = socket(AF_UNIX, SOCK_STREAM, 0);
        /* Only the owner may connect: the socket is the session's only guard. */
        old = umask(077);
        if (fd < 0 || bind(fd, (struct sockaddr *)&sa, sizeof sa) != 0 || listen(fd, 128) != 0) {
            umask(old);
            fprintf(stderr, "silcd: cannot listen on unix:%s: %s\n", a->path, strerror(errno));
            if (fd >= 0) close(fd);
            return -1;
        }
        umask(old);
        snprintf(url, urllen, "unix:%s", a->path);
    } else {
        struct addrinfo hints, *res = NULL;
        struct sockaddr_storage ss;
        socklen_t sl = sizeof ss;
        char host[INET6_ADDRSTRLEN];
        int rc;
        memset(&hints, 0, sizeof hints);
        hints.ai_socktype = SOCK_STREAM;
        hints.ai_flags = AI_PASSIVE;
        if ((rc = getaddrinfo(a->host, a->port, &hints, &res)) != 0) {
            fprintf(stderr, "silcd: cannot resolve '%s': %s\n", a->host, gai_strerror(rc));
            return -1;
        }
        if (!srv_cfg.token)   /* --insecure: main refused TCP without a token otherwise */
            srv_log(LOG_ERROR, "WARNING: --insecure: listening on %s:%s with no token: %s can "
                    "run code and read and write files as this user", a->host, a->port,
                    is_loopback(res->ai_addr) ? "every local user"
                                              : "anyone who can reach this address");
        fd = socket(res->ai_family, res->ai_socktype, res->ai_protocol);
        if (fd >= 0) setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        if (fd < 0 || bind(fd, res->ai_addr, res->ai_addrlen) != 0 || listen(fd, 128) != 0) {
            fprintf(stderr, "silcd: cannot listen on %s:%s: %s\n", a->host, a->port,
                    strerror(errno));
            if (fd >= 0) close(fd);
            freeaddrinfo(res);
            return -1;
        }
        freeaddrinfo(res);
        getsockname(fd, (struct sockaddr *)&ss, &sl);
        if (ss.ss_family == AF_INET6) {
            inet_ntop(AF_INET6, &((struct sockaddr_in6 *)&ss)->sin6_addr, host, sizeof host);
            snprintf(url, urllen, "tcp://[%s]:%u", host,
                     (unsigned)ntohs(((struct sockaddr_in6 *)&ss)->sin6_port));
        } else {
            inet_ntop(AF_INET, &((struct sockaddr_in *)&ss)->sin_addr, host, sizeof host);
            snprintf(url, urllen, "tcp://%s:%u", host,
                     (unsigned)ntohs(((struct sockaddr_in *)&ss)->sin_port));
        }
    }
    return fd;
}

static void on_signal(int sig)
{
    ssize_t rc;
    (void)sig;
    /* Never read: the pipe stays readable, waking every poll on it. */
    rc = write(shutdown_pipe[1], "x", 1);
    (void)rc;
}

static void on_child(int sig)
{
    ssize_t rc;
    (void)sig;
    rc = write(child_pipe[1], "c", 1);   /* non-blocking: a full pipe already wakes */
    (void)rc;
}

static void slot_at(void *user, int i, srv_slot_view *v)
{
    (void)user;
    v->live = conns[i].pid != 0;
    v->handshaking = conn_state[i] == SLOT_HANDSHAKE;
    v->peer = conns[i].peer;
    v->accepted = conns[i].accepted;
}

/* A free slot for a new connection from peer, or -1 with why set
 * (srv_admit).  A connection closed to make room is killed and waited for
 * here, so that it cannot touch the slot's state once reused.  A client
 * completes its handshake in a millisecond, so connections that never
 * send a byte (or wait out the delay of a failed authentication) cannot
 * lock real clients out. */
static int take_slot(const char *peer, char *why, size_t whylen)
{
    int evict, slot = srv_admit(peer, n_conns, slot_at, NULL, &evict, why, whylen);
    if (slot < 0 || !evict) return slot;
    srv_log(LOG_WARN, "session %lu%s%s: closed unauthenticated to make room (%s)", conns[slot].id,
            *conns[slot].peer ? " from " : "", conns[slot].peer, why);
    kill(conns[slot].pid, SIGKILL);
    waitpid(conns[slot].pid, NULL, 0);
    close(conns[slot].fd);
    srv_auth_drop(conns[slot].peer);
    conns[slot].pid = 0;
    conns[slot].fd = -1;
    conn_state[slot] = SLOT_FREE;
    return slot;
}

static void sigmask_session_signals(int how)
{
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGTERM);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGCHLD);
    sigprocmask(how, &set, NULL);
}

/* In the new child: its own shutdown pipe and signals, none of the parent's
 * descriptors but its connection, then the session. */
static void run_child(int lfd, int slot)
{
    struct sigaction sa;
    int i, fd = conns[slot].fd;
    close(lfd);
    for (i = 0; i < n_conns; i++)
        if (conns[i].pid && i != slot) close(conns[i].fd);
    close(shutdown_pipe[0]);
    close(shutdown_pipe[1]);
    close(child_pipe[0]);
    close(child_pipe[1]);
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = SIG_DFL;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGCHLD, &sa, NULL);
    if (srv_limit_process(server_pid, 1)) _exit(1);
    if (pipe(shutdown_pipe) != 0) _exit(1);
    fcntl(shutdown_pipe[1], F_SETFL, O_NONBLOCK);
    srv_shutdown_fd = shutdown_pipe[0];
    sigmask_session_signals(SIG_UNBLOCK);
    /* A session that ran ends with exit: the plugins' shutdown and (in
     * sanitizer builds) the leak check run as in any process.  A connection
     * that never completed its handshake made no engine, and a flood of them
     * must not cost a leak scan each: _exit. */
    if (srv_session(fd, conns[slot].id, &conn_state[slot])) exit(0);
    _exit(0);
}

static void start_session(int lfd, int fd, unsigned long id, const char *peer)
{
    char why[256];
    pid_t pid;
    int slot = take_slot(peer, why, sizeof why);
    if (slot < 0) {
        srv_log(LOG_WARN, "refusing a connection%s%s: %s", *peer ? " from " : "", peer, why);
        srv_refuse(fd, why);
        return;
    }
    conns[slot].fd = fd;
    conns[slot].id = id;
    conns[slot].accepted = util_now();
    conns[slot].hung_up = 0;
    snprintf(conns[slot].peer, sizeof conns[slot].peer, "%s", peer);
    conn_state[slot] = SLOT_HANDSHAKE;
    srv_auth_hold(peer);   /* before fork: the child finds its peer's entry */
    sigmask_session_signals(SIG_BLOCK);   /* until the child has its own pipes */
    pid = fork();
    if (pid == 0) run_child(lfd, slot);
    sigmask_session_signals(SIG_UNBLOCK);
    if (pid < 0) {
        srv_log(LOG_ERROR, "cannot start a session process: %s", strerror(errno));
        srv_refuse(fd, "server cannot start a session: fork failed");
        srv_auth_drop(peer);
        conn_state[slot] = SLOT_FREE;
        return;
    }
    conns[slot].pid = pid;
}

/* Collects every ended session process.  One that died of a signal while
 * its client waited at a frame boundary gets an ERROR naming the signal;
 * no other session is touched. */
static void reap_children(void)
{
    int status, i;
    pid_t pid;
    while ((pid = waitpid(-1, &status, WNOHANG)) > 0) {
        for (i = 0; i < n_conns && conns[i].pid != pid; i++) {}
        if (i == n_conns) continue;
        if (WIFSIGNALED(status)) {
            int sig = WTERMSIG(status), st = conn_state[i];
            if (st == SLOT_HANDSHAKE && sig == SIGALRM) {
                srv_log(LOG_INFO, "session %lu: no handshake within %g s, closed "
                        "(--handshake-timeout)", conns[i].id, srv_cfg.handshake_timeout_ms / 1000.0);
            } else if (st == SLOT_HANDSHAKE) {
                srv_log(LOG_INFO, "session %lu: closed in its handshake (signal %d)", conns[i].id, sig);
            } else if (conns[i].hung_up < 0) {
                /* killed by watch_hangups, which logged it */
            } else {
                char msg[768], err[128], limit[300];
                srv_death_reason(sig, st, limit, sizeof limit);
                snprintf(msg, sizeof msg, "session %lu lost: the server process running it died "
                         "of signal %d (%s)%s; its values are gone, other sessions are unaffected",
                         conns[i].id, sig, strsignal(sig), limit);
                srv_log(LOG_ERROR, "%s", msg);
                if (st == SLOT_READY || st == SLOT_RUNNING)
                    proto_send_text(conns[i].fd, PROTO_ERROR, msg, 1000, err, sizeof err);
            }
        } else if (WIFEXITED(status) && WEXITSTATUS(status) != 0) {
            srv_log(LOG_ERROR, "session %lu: its process exited with status %d", conns[i].id,
                    WEXITSTATUS(status));
        }
        close(conns[i].fd);
        srv_auth_drop(conns[i].peer);
        conns[i].pid = 0;
        conns[i].fd = -1;
        conns[i].hung_up = 0;
        conn_state[i] = SLOT_FREE;
    }
}

/* Every session's client, watched for hanging up (p from index 3 on);
 * returns the poll timeout.  A session whose client has gone ends by
 * itself when idle (it reads EOF) or running the evaluator (which looks at
 * its socket every SRV_WATCH_POLL_S); one still computing SRV_HANGUP_GRACE_S
 * after the hang-up is stuck inside a library call, and is killed here, so
 * that a client gone frees its slot and its core within a second whatever
 * the session runs.  Sessions that are finishing by themselves (exiting,
 * their leak check in sanitizer builds) are left alone. */
static int watch_hangups(struct pollfd *p, nfds_t *np)
{
    double now = util_now();
    int i, wait = -1;
    for (i = 0; i < n_conns; i++) {
        if (!conns[i].pid) continue;
        if (!conns[i].hung_up) {
            p[*np].fd = conns[i].fd;
            p[*np].events = POLLRDHUP;
            p[*np].revents = 0;
            (*np)++;
        } else if (conn_state[i] == SLOT_RUNNING && now >= conns[i].hung_up + SRV_HANGUP_GRACE_S) {
            srv_log(LOG_INFO, "session %lu: still computing %g s after its client hung up: "
                    "killed", conns[i].id, SRV_HANGUP_GRACE_S);
            kill(conns[i].pid, SIGKILL);   /* reaped on its SIGCHLD */
            conns[i].hung_up = -1;         /* killed: no second kill */
        } else if (conns[i].hung_up > 0) {
            /* Until it ends: look again soon (it may start computing a
             * request the client sent before it went). */
            int ms = conn_state[i] == SLOT_RUNNING
                         ? (int)((conns[i].hung_up + SRV_HANGUP_GRACE_S - now) * 1000) + 1
                         : 100;
            if (wait < 0 || ms < wait) wait = ms;
        }
    }
    return wait;
}

static void note_hangups(const struct pollfd *p, nfds_t n)
{
    nfds_t k;
    int i;
    for (k = 3; k < n; k++) {
        if (!(p[k].revents & (POLLRDHUP | POLLHUP | POLLERR))) continue;
        for (i = 0; i < n_conns; i++)
            if (conns[i].pid && conns[i].fd == p[k].fd && !conns[i].hung_up) {
                srv_log(LOG_DEBUG, "session %lu: its client hung up", conns[i].id);
                conns[i].hung_up = util_now();
            }
    }
}

static int live_sessions(void)
{
    int i, n = 0;
    for (i = 0; i < n_conns; i++) n += conns[i].pid != 0;
    return n;
}

static void drain_pipe(int fd)
{
    char buf[64];
    while (read(fd, buf, sizeof buf) > 0) {}
}

static void accept_loop(int lfd, int is_tcp)
{
    unsigned long next_id = 1;
    struct pollfd *p = calloc((size_t)n_conns + 3, sizeof *p);
    if (!p) {
        srv_log(LOG_ERROR, "out of memory");
        return;
    }
    p[0].fd = lfd;
    p[0].events = POLLIN;
    p[1].fd = shutdown_pipe[0];
    p[1].events = POLLIN;
    p[2].fd = child_pipe[0];
    p[2].events = POLLIN;
    for (;;) {
        char peer[64];
        int fd, one = 1, wait;
        nfds_t np = 3;
        p[0].revents = p[1].revents = p[2].revents = 0;
        wait = watch_hangups(p, &np);
        if (poll(p, np, wait) < 0) continue;
        note_hangups(p, np);
        if (p[2].revents) {
            drain_pipe(child_pipe[0]);
            reap_children();
        }
        if (p[1].revents) {
            free(p);
            return;
        }
        if (!(p[0].revents & POLLIN)) continue;
        fd = accept(lfd, NULL, NULL);
        if (fd < 0) continue;
        if (is_tcp) setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
        srv_peer_of(fd, peer, sizeof peer);
        start_session(lfd, fd, next_id++, peer);
    }
}

/* After SIGTERM: the idle sessions close at once; a request in flight
 * gets SRV_SHUTDOWN_GRACE_S to finish (then its evaluator stops it) and
 * one second more before its process is killed, as on a second signal. */
static void drain_sessions(void)
{
    struct pollfd p[2];
    int i, forced = 0;
    double kill_at = util_now() + SRV_SHUTDOWN_GRACE_S + 1;
    /* A connection still in its handshake was promised nothing: it goes
     * now, instead of waiting out --handshake-timeout. */
    for (i = 0; i < n_conns; i++)
        if (conns[i].pid) kill(conns[i].pid, conn_state[i] == SLOT_HANDSHAKE ? SIGKILL : SIGTERM);
    drain_pipe(shutdown_pipe[0]);
    p[0].fd = child_pipe[0];
    p[0].events = POLLIN;
    p[1].fd = shutdown_pipe[0];
    p[1].events = POLLIN;
    while (reap_children(), live_sessions() > 0) {
        p[0].revents = p[1].revents = 0;
        if (poll(p, 2, 200) < 0) continue;
        if (p[0].revents) drain_pipe(child_pipe[0]);
        if ((p[1].revents || util_now() >= kill_at) && !forced) {
            srv_log(LOG_WARN, "%s: killing %d session(s)",
                    p[1].revents ? "second signal" : "shutdown grace over", live_sessions());
            for (i = 0; i < n_conns; i++)
                if (conns[i].pid) kill(conns[i].pid, SIGKILL);
            forced = 1;
        }
    }
}

/* Loads the plugins once (an engine made and dropped), so every session
 * process inherits them instead of loading each for itself, and a bad
 * --config stops the server at start instead of failing every session. */
static int preload_plugins(void)
{
    silc_engine *E = NULL;
    char err[1024];
    if (eng_create(&E, srv_cfg.engine_config, err, sizeof err)) {
        fprintf(stderr, "silcd: %s\n", err);
        return -1;
    }
    eng_open_plugins(E); /* the engine opens plugins at first use; here, all of them */
    eng_destroy(&E);
    return 0;
}

static int write_ready_file(const char *path, const char *url)
{
    char tmp[4096];
    FILE *f;
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    if (!(f = fopen(tmp, "w"))) return -1;
    fprintf(f, "%s\n", url);
    if (fclose(f) != 0) return -1;
    return rename(tmp, path);
}

/* A session is a fresh process, so every page its heap touches the first
 * time is a page fault: ~20 us each on a virtual machine, and a 50-step
 * cloth run through silcd took ~3400 of them in its session (the values
 * the statements make before the memo settles), 0.3x of the whole C step
 * (docs/cloth.md).  glibc backs its heap and its large blocks with
 * transparent huge pages when the tunable glibc.malloc.hugetlb=1 is set
 * (one fault per 2 MiB, 1/50 of the cost per byte here), but reads
 * tunables only when a program starts: so silcd executes itself again,
 * once, with the tunable added to GLIBC_TUNABLES, before it does anything
 * else.  Left alone: a GLIBC_TUNABLES that already names the tunable (the
 * operator's choice; =0 turns this off), a kernel whose huge pages are
 * not "madvise" (with "always" the heap has them already, with "never"
 * there are none), a secure-execution start (glibc drops the variable
 * there).  silcd --mpi too, before MPI starts (the exec keeps the pid
 * the launcher knows): its ranks hold their sessions in one long-lived
 * process, but a first large factorization still touched every page of
 * MUMPS's ~150 MB afresh, a quarter of a 500^2 one-shot solve's CPU time
 * (docs/distributed.md, item 7).  If the exec fails silcd goes on as it is. */
static void exec_with_huge_page_heap(char **argv)
{
    static const char tunable[] = "glibc.malloc.hugetlb=1";
    const char *old = getenv("GLIBC_TUNABLES");
    char mode[128] = "", *both;
    size_t got = 0;
    FILE *f;
    if ((old && strstr(old, "glibc.malloc.hugetlb")) || getauxval(AT_SECURE)) return;
    if ((f = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r"))) {
        got = fread(mode, 1, sizeof mode - 1, f);
        fclose(f);
    }
    mode[got] = '\0';
    if (!strstr(mode, "[madvise]")) return;
    if (!(both = malloc((old ? strlen(old) : 0) + sizeof tunable + 1))) return;
    sprintf(both, "%s%s%s", old ? old : "", old && *old ? ":" : "", tunable);
    if (setenv("GLIBC_TUNABLES", both, 1) == 0) {
        /* By its own path, not /proc/self/exe: the process's name (ps,
         * pgrep, the launcher's view) stays silcd, not "exe". */
        char self[4096];
        ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
        if (len > 0) {
            self[len] = '\0';
            execv(self, argv);
        }
        if (old) setenv("GLIBC_TUNABLES", old, 1);
        else unsetenv("GLIBC_TUNABLES");
    }
    free(both);
}

int main(int argc, char **argv)
{
    const char *ready_file = NULL;
    const uint16_t probe = 1;
    struct sigaction sa;
    proto_addr addr;
    char url[600], err[512];
    int lfd, i;
    if (parse_args(argc, argv, &ready_file)) return 2;
    if (make_token) return srv_auth_make_token(make_token) ? 1 : 0;
    exec_with_huge_page_heap(argv);
    if (*(const uint8_t *)&probe != 1) {
        fprintf(stderr, "silcd: the wire protocol needs a little-endian host\n");
        return 1;
    }
    if (proto_parse_url(srv_cfg.listen, &addr, err, sizeof err)) {
        fprintf(stderr, "silcd: --listen: %s\n", err);
        return 2;
    }
    if (!addr.is_unix && !srv_cfg.token && !insecure) {
        fprintf(stderr, "silcd: refusing to listen on %s without --token-file: every local user "
                "(and anyone who can reach the address) could run code as this user; create a "
                "token with 'silcd --make-token FILE' and pass --token-file FILE, listen on a "
                "Unix socket (unix:/path, mode 0600), or pass --insecure to accept the risk\n",
                srv_cfg.listen);
        return 1;
    }
    if (mpi_mode) {
#ifdef SILC_HAVE_MPI
        if (srv_mpi_init(&argc, &argv, dist_min_rows)) return 1;
        /* Every rank: gone with the launcher's daemon, its data segment
         * capped for the sessions it may hold. */
        if (srv_limit_process(getppid(), srv_cfg.max_clients)) return 1;
        srv_limit_job(srv_mpi->rank);
        if (srv_mpi->rank != 0) {
            /* mpirun forwards SIGTERM and SIGINT to every rank: rank 0
             * alone decides when the others stop (SRV_CMD_STOP). */
            signal(SIGTERM, SIG_IGN);
            signal(SIGINT, SIG_IGN);
            val_set_max_bytes(srv_cfg.max_value_bytes, "silcd --max-value-bytes");
            srv_follow();
            srv_mpi_finish();
            return 0;
        }
#else
        fprintf(stderr, "silcd: --mpi: this silcd was built without MPI (apt-get install "
                        "libopenmpi-dev, then rebuild)\n");
        return 2;
#endif
    }
    server_pid = getpid();
    n_conns = srv_cfg.max_clients;
    conns = calloc((size_t)n_conns, sizeof *conns);
    conn_state = mmap(NULL, (size_t)n_conns * sizeof *conn_state, PROT_READ | PROT_WRITE,
                      MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (!conns || conn_state == MAP_FAILED || srv_auth_setup(n_conns) || pipe(shutdown_pipe) != 0 ||
        pipe(child_pipe) != 0) {
        fprintf(stderr, "silcd: cannot set up: %s\n", strerror(errno));
        return 1;
    }
    for (i = 0; i < n_conns; i++) conns[i].fd = -1;
    fcntl(shutdown_pipe[0], F_SETFL, O_NONBLOCK);   /* drained once, at shutdown */
    fcntl(shutdown_pipe[1], F_SETFL, O_NONBLOCK);
    fcntl(child_pipe[0], F_SETFL, O_NONBLOCK);
    fcntl(child_pipe[1], F_SETFL, O_NONBLOCK);
    srv_shutdown_fd = shutdown_pipe[0];
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    sa.sa_handler = on_child;
    sa.sa_flags = SA_NOCLDSTOP;
    sigaction(SIGCHLD, &sa, NULL);
    sa.sa_flags = 0;
    sa.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &sa, NULL);
    /* A statement's value is held to the same limit as one a PUT carries,
     * checked before it is allocated. */
    val_set_max_bytes(srv_cfg.max_value_bytes, "silcd --max-value-bytes");
    if (preload_plugins()) return 2;   /* the configuration is wrong: as a bad option */
    if ((lfd = open_listener(&addr, url, sizeof url)) < 0) return 1;
    pool_install((size_t)srv_cfg.pool_bytes); /* core/client/pool.c: each session's own */
    srv_log(LOG_INFO, "listening on %s (max %llu bytes per value, %llu per session%s)", url,
            (unsigned long long)srv_cfg.max_value_bytes,
            (unsigned long long)srv_cfg.max_session_bytes, srv_cfg.token ? ", token required" : "");
    if (ready_file && write_ready_file(ready_file, url)) {
        fprintf(stderr, "silcd: cannot write ready file '%s'\n", ready_file);
        return 1;
    }
#ifdef SILC_HAVE_MPI
    if (srv_mpi) srv_mpi_serve(lfd, !addr.is_unix);
    else
#endif
        accept_loop(lfd, !addr.is_unix);
    srv_log(LOG_INFO, "shutting down: waiting for %d session(s)", live_sessions());
    close(lfd);
    if (addr.is_unix) unlink(addr.path);
    drain_sessions();
#ifdef SILC_HAVE_MPI
    srv_mpi_finish();
#endif
    srv_log(LOG_INFO, "stopped");
    free(srv_cfg.token);
    free(conns);
    return 0;
}
