/*
 * silcd.c -- the SILC server: options, the listening socket, signals, and one
 * thread per connection (session.c).  Runs in the foreground; SIGTERM or
 * SIGINT stops accepting, lets requests in flight finish, closes idle
 * sessions, and exits 0.  docs/server.md is the user's guide.
 */
#define _POSIX_C_SOURCE 200809L
#include "server.h"
#include "pool.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "protocol.h"
#include "silc.h"

srv_config srv_cfg = {
    "tcp://127.0.0.1:7070", NULL, 0, NULL, 0,
    (uint64_t)2 << 30,   /* max_value_bytes: 2 GiB */
    (uint64_t)4 << 30,   /* max_session_bytes: 4 GiB */
    (uint64_t)64 << 20,  /* max_text_bytes: 64 MiB */
    30000, 256, LOG_INFO,
    (uint64_t)1 << 30};  /* pool_bytes: 1 GiB */
pthread_mutex_t srv_compute_lock = PTHREAD_MUTEX_INITIALIZER;
int srv_shutdown_fd = -1;

static int shutdown_pipe[2] = {-1, -1};
static pthread_mutex_t count_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t count_zero = PTHREAD_COND_INITIALIZER;
static int active_sessions;

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
          "  --token-file FILE       shared secret clients must present (required off loopback)\n"
          "  --max-value-bytes N     largest value one PUT may carry (default 2G)\n"
          "  --max-session-bytes N   memory of the values bound in one session, 0 = no limit (default 4G)\n"
          "  --max-clients N         concurrent sessions (default 256)\n"
          "  --array-pool N          freed value arrays kept for the next PUT, 0 = none (default 1G)\n"
          "  --io-timeout SECONDS    drop a peer that stalls inside a frame (default 30)\n"
          "  --log-level LEVEL       error, warn, info (default) or debug\n"
          "  --ready-file FILE       write the listening address to FILE once ready\n"
          "  --help, --version\n", f);
}

/* "123", "64K", "512M", "2G" (powers of 1024). */
static int parse_size(const char *s, uint64_t *out)
{
    char *end;
    unsigned long long x;
    int shift = 0;
    if (!s || *s == '-') return -1;
    x = strtoull(s, &end, 10);
    if (end == s) return -1;
    switch (*end) {
    case 'k': case 'K': shift = 10; end++; break;
    case 'm': case 'M': shift = 20; end++; break;
    case 'g': case 'G': shift = 30; end++; break;
    case 't': case 'T': shift = 40; end++; break;
    default: break;
    }
    if (*end || (shift && x > (UINT64_MAX >> shift))) return -1;
    *out = (uint64_t)x << shift;
    return 0;
}

static int parse_int(const char *s, int lo, int hi, int *out)
{
    char *end;
    long x;
    if (!s) return -1;
    x = strtol(s, &end, 10);
    if (end == s || *end || x < lo || x > hi) return -1;
    *out = (int)x;
    return 0;
}

/* The secret: the file's first line, which must not be empty. */
static int read_token(const char *path)
{
    char buf[PROTO_MAX_TOKEN + 2];
    size_t n;
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "silcd: cannot read token file '%s': %s\n", path, strerror(errno));
        return -1;
    }
    n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    buf[strcspn(buf, "\r\n")] = '\0';
    if (!*buf || strlen(buf) > PROTO_MAX_TOKEN) {
        fprintf(stderr, "silcd: token file '%s' must hold a token of 1..%u bytes on its first "
                "line\n", path, PROTO_MAX_TOKEN);
        return -1;
    }
    srv_cfg.token_len = strlen(buf);
    if (!(srv_cfg.token = malloc(srv_cfg.token_len + 1))) return -1;
    memcpy(srv_cfg.token, buf, srv_cfg.token_len + 1);
    return 0;
}

static int parse_args(int argc, char **argv, const char **ready_file)
{
    int i;
    for (i = 1; i < argc; i++) {
        const char *opt = argv[i], *val = NULL;
        char name[64];
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
        if (strncmp(opt, "--", 2) != 0) {
            fprintf(stderr, "silcd: unexpected argument '%s'\n", opt);
            return -1;
        }
        if (eq) {
            snprintf(name, sizeof name, "%.*s", (int)(eq - opt), opt);
            val = eq + 1;
        } else {
            snprintf(name, sizeof name, "%s", opt);
            if (i + 1 < argc) val = argv[++i];
        }
        if (!val) {
            fprintf(stderr, "silcd: %s needs a value\n", name);
            return -1;
        }
        if (strcmp(name, "--listen") == 0) srv_cfg.listen = val;
        else if (strcmp(name, "--config") == 0) srv_cfg.engine_config = val;
        else if (strcmp(name, "--threads") == 0) ok = !parse_int(val, 1, 4096, &srv_cfg.threads);
        else if (strcmp(name, "--token-file") == 0) ok = !read_token(val);
        else if (strcmp(name, "--max-value-bytes") == 0) ok = !parse_size(val, &srv_cfg.max_value_bytes);
        else if (strcmp(name, "--max-session-bytes") == 0) ok = !parse_size(val, &srv_cfg.max_session_bytes);
        else if (strcmp(name, "--array-pool") == 0) ok = !parse_size(val, &srv_cfg.pool_bytes);
        else if (strcmp(name, "--max-clients") == 0) ok = !parse_int(val, 1, 65536, &srv_cfg.max_clients);
        else if (strcmp(name, "--io-timeout") == 0) {
            double s = strtod(val, NULL);
            ok = s > 0 && s <= 86400;
            srv_cfg.io_timeout_ms = (int)(s * 1000);
            if (srv_cfg.io_timeout_ms < 1) srv_cfg.io_timeout_ms = 1;
        } else if (strcmp(name, "--log-level") == 0) {
            int k;
            ok = 0;
            for (k = 0; k < 4; k++)
                if (strcmp(val, level_names[k]) == 0) {
                    srv_cfg.log_level = k;
                    ok = 1;
                }
        } else if (strcmp(name, "--ready-file") == 0) *ready_file = val;
        else {
            fprintf(stderr, "silcd: unknown option '%s' (see silcd --help)\n", name);
            return -1;
        }
        if (!ok) {
            fprintf(stderr, "silcd: invalid value '%s' for %s\n", val, name);
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
        if (!is_loopback(res->ai_addr) && !srv_cfg.token) {
            fprintf(stderr, "silcd: refusing to listen on non-loopback address %s without "
                    "--token-file (anyone who can reach it could run code in this server)\n",
                    a->host);
            freeaddrinfo(res);
            return -1;
        }
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

typedef struct session_arg {
    int fd;
    unsigned long id;
} session_arg;

static void *session_thread(void *p)
{
    session_arg a = *(session_arg *)p;
    free(p);
    srv_session(a.fd, a.id);
    pthread_mutex_lock(&count_lock);
    if (--active_sessions == 0) pthread_cond_broadcast(&count_zero);
    pthread_mutex_unlock(&count_lock);
    return NULL;
}

/* Refuses a connection over --max-clients with a proper hello and ERROR. */
static void refuse_busy(int fd)
{
    uint8_t hello[PROTO_HELLO_BYTES];
    struct iovec iov;
    char why[128];
    proto_encode_hello(hello, PROTO_VERSION, 0);
    iov.iov_base = hello;
    iov.iov_len = sizeof hello;
    if (proto_send(fd, &iov, 1, 1000, why, sizeof why) == 0)
        proto_send_text(fd, PROTO_ERROR, "server busy: too many sessions (silcd --max-clients)",
                        1000, why, sizeof why);
    close(fd);
}

static void accept_loop(int lfd, int is_tcp)
{
    unsigned long next_id = 1;
    struct pollfd p[2];
    p[0].fd = lfd;
    p[0].events = POLLIN;
    p[1].fd = shutdown_pipe[0];
    p[1].events = POLLIN;
    for (;;) {
        session_arg *a;
        pthread_t th;
        pthread_attr_t attr;
        int fd, one = 1, busy;
        p[0].revents = p[1].revents = 0;
        if (poll(p, 2, -1) < 0) continue;
        if (p[1].revents) return;
        if (!(p[0].revents & POLLIN)) continue;
        fd = accept(lfd, NULL, NULL);
        if (fd < 0) continue;
        if (is_tcp) setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
        pthread_mutex_lock(&count_lock);
        busy = active_sessions >= srv_cfg.max_clients;
        if (!busy) active_sessions++;
        pthread_mutex_unlock(&count_lock);
        if (busy) {
            srv_log(LOG_WARN, "refusing a connection: %d sessions open", srv_cfg.max_clients);
            refuse_busy(fd);
            continue;
        }
        a = malloc(sizeof *a);
        pthread_attr_init(&attr);
        pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
        if (a) {
            a->fd = fd;
            a->id = next_id++;
        }
        if (!a || pthread_create(&th, &attr, session_thread, a) != 0) {
            srv_log(LOG_ERROR, "cannot start a session thread");
            free(a);
            close(fd);
            pthread_mutex_lock(&count_lock);
            active_sessions--;
            pthread_mutex_unlock(&count_lock);
        }
        pthread_attr_destroy(&attr);
    }
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

int main(int argc, char **argv)
{
    const char *ready_file = NULL;
    const uint16_t probe = 1;
    struct sigaction sa;
    proto_addr addr;
    char url[600], err[512];
    int lfd;
    if (parse_args(argc, argv, &ready_file)) return 2;
    if (*(const uint8_t *)&probe != 1) {
        fprintf(stderr, "silcd: the wire protocol needs a little-endian host\n");
        return 1;
    }
    if (proto_parse_url(srv_cfg.listen, &addr, err, sizeof err)) {
        fprintf(stderr, "silcd: --listen: %s\n", err);
        return 2;
    }
    if (pipe(shutdown_pipe) != 0) return 1;
    fcntl(shutdown_pipe[1], F_SETFL, O_NONBLOCK);
    srv_shutdown_fd = shutdown_pipe[0];
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    sa.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &sa, NULL);
    if ((lfd = open_listener(&addr, url, sizeof url)) < 0) return 1;
    pool_install((size_t)srv_cfg.pool_bytes); /* core/src/pool.c */
    /* A value a statement makes is held to the same limit as one a PUT
     * carries, checked before it is allocated. */
    val_set_max_bytes(srv_cfg.max_value_bytes, "silcd --max-value-bytes");
    srv_log(LOG_INFO, "listening on %s (max %llu bytes per value, %llu per session%s)", url,
            (unsigned long long)srv_cfg.max_value_bytes,
            (unsigned long long)srv_cfg.max_session_bytes, srv_cfg.token ? ", token required" : "");
    if (ready_file && write_ready_file(ready_file, url)) {
        fprintf(stderr, "silcd: cannot write ready file '%s'\n", ready_file);
        return 1;
    }
    accept_loop(lfd, !addr.is_unix);
    srv_log(LOG_INFO, "shutting down: waiting for %d session(s)", active_sessions);
    close(lfd);
    if (addr.is_unix) unlink(addr.path);
    pthread_mutex_lock(&count_lock);
    while (active_sessions > 0) pthread_cond_wait(&count_zero, &count_lock);
    pthread_mutex_unlock(&count_lock);
    srv_log(LOG_INFO, "stopped");
    free(srv_cfg.token);
    return 0;
}
