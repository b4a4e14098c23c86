/*
 * remote_util.h -- helpers of the remote tests: start a private silcd with
 * given options and wait until it listens, stop it, and speak raw protocol
 * on a socket for the tests that must send what no client would.
 */
#ifndef SILC_REMOTE_UTIL_H
#define SILC_REMOTE_UTIL_H

#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "client.h"
#include "util.h"

typedef struct test_server {
    pid_t pid;
    char url[600];
    char dir[256];
} test_server;

static inline void sleep_ms(int ms)
{
    struct timespec ts;
    ts.tv_sec = ms / 1000;
    ts.tv_nsec = (long)(ms % 1000) * 1000000L;
    nanosleep(&ts, NULL);
}

/* Starts silcd with the NULL-terminated extra options; the ready file gives
 * the address.  listen NULL: a fresh unix socket in a private directory.
 * Returns 0, or the server's exit status (> 0) if it refused to start. */
static inline int server_start(test_server *s, const char *listen, const char *const *opts)
{
    char ready[400], lst[400], logf[400];
    const char *argv[32];
    int n = 0, i, status;
    snprintf(s->dir, sizeof s->dir, "/tmp/silc-rt-XXXXXX");
    if (!mkdtemp(s->dir)) return -1;
    snprintf(ready, sizeof ready, "%s/ready", s->dir);
    snprintf(logf, sizeof logf, "%s/log", s->dir);
    if (listen) snprintf(lst, sizeof lst, "%s", listen);
    else snprintf(lst, sizeof lst, "unix:%s/s", s->dir);
    argv[n++] = SILCD_PATH;
    argv[n++] = "--listen";
    argv[n++] = lst;
    argv[n++] = "--ready-file";
    argv[n++] = ready;
    argv[n++] = "--log-level";
    argv[n++] = "warn";
    for (i = 0; opts && opts[i] && n < 30; i++) argv[n++] = opts[i];
    argv[n] = NULL;
    s->pid = fork();
    if (s->pid == 0) {
        FILE *f = freopen(logf, "w", stderr);
        (void)f;
        execv(SILCD_PATH, (char *const *)argv);
        _exit(127);
    }
    for (i = 0; i < 400; i++) {
        FILE *f = fopen(ready, "r");
        if (f) {
            int ok = fgets(s->url, sizeof s->url, f) != NULL;
            fclose(f);
            if (ok) {
                s->url[strcspn(s->url, "\n")] = '\0';
                return 0;
            }
        }
        if (waitpid(s->pid, &status, WNOHANG) == s->pid)
            return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
        sleep_ms(25);
    }
    kill(s->pid, SIGKILL);
    waitpid(s->pid, &status, 0);
    return -1;
}

/* SIGTERM; returns the exit status (0 for a clean shutdown). */
static inline int server_stop(test_server *s)
{
    int status = 0, i;
    char cmd[400];
    kill(s->pid, SIGTERM);
    for (i = 0; i < 400; i++) {
        if (waitpid(s->pid, &status, WNOHANG) == s->pid) break;
        sleep_ms(25);
    }
    if (i == 400) {
        kill(s->pid, SIGKILL);
        waitpid(s->pid, &status, 0);
        status = -1;
    }
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", s->dir);
    if (system(cmd)) {}
    return status < 0 ? -1 : (WIFEXITED(status) ? WEXITSTATUS(status) : 128);
}

static inline int raw_connect(const char *url)
{
    struct sockaddr_un sa;
    int fd;
    if (strncmp(url, "unix:", 5) != 0) return -1;
    if (strlen(url + 5) >= sizeof sa.sun_path) return -1;
    memset(&sa, 0, sizeof sa);
    sa.sun_family = AF_UNIX;
    memcpy(sa.sun_path, url + 5, strlen(url + 5) + 1);
    fd = socket(AF_UNIX, SOCK_STREAM, 0);
    if (fd >= 0 && connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

static inline int raw_send(int fd, const void *p, size_t n)
{
    struct iovec iov;
    char err[128];
    iov.iov_base = (void *)(uintptr_t)p;
    iov.iov_len = n;
    return proto_send(fd, &iov, 1, 5000, err, sizeof err);
}

/* Reads one reply; returns its opcode (text in *text, malloc'd) or -1 on
 * EOF/error, -2 on timeout. */
static inline int raw_reply(int fd, char **text, int timeout_ms)
{
    proto_stream s = {fd, timeout_ms, NULL, 0, 0};
    proto_limits lim = {(uint64_t)1 << 32, (uint64_t)1 << 24};
    proto_reply r;
    char err[256];
    int rc = proto_read_reply(&s, &lim, &r, err, sizeof err);
    *text = NULL;
    if (rc) return strstr(err, "timed out") ? -2 : -1;
    *text = r.text;
    r.text = NULL;
    rc = (int)r.op;
    proto_reply_free(&r);
    return rc;
}

/* Handshakes on fd with the given version and token: the server's reply
 * opcode (PROTO_OK; PROTO_ERROR with its text in *msg), -1 if the
 * connection closed or failed, -2 if nothing came within timeout_ms. */
static inline int raw_handshake(int fd, uint32_t version, const char *token, char **msg,
                                int timeout_ms)
{
    uint8_t hello[PROTO_HELLO_BYTES], back[PROTO_HELLO_BYTES];
    size_t tl = token ? strlen(token) : 0;
    proto_stream s;
    struct iovec iov;
    char err[128];
    *msg = NULL;
    proto_encode_hello(hello, version, (uint32_t)tl);
    raw_send(fd, hello, sizeof hello);
    if (tl) raw_send(fd, token, tl);
    s = (proto_stream){fd, timeout_ms, NULL, 0, 0};
    iov.iov_base = back;
    iov.iov_len = sizeof back;
    if (proto_recv(&s, &iov, 1, err, sizeof err)) return strstr(err, "timed out") ? -2 : -1;
    return raw_reply(fd, msg, timeout_ms);
}

/* Connects and handshakes with the given version and token; returns the fd
 * after the server's OK, or -1 (with the ERROR text in *msg if one came). */
static inline int raw_open(const char *url, uint32_t version, const char *token, char **msg)
{
    int fd = raw_connect(url);
    *msg = NULL;
    if (fd < 0) return -1;
    if (raw_handshake(fd, version, token, msg, 5000) != PROTO_OK) {
        close(fd);
        return -1;
    }
    free(*msg);
    *msg = NULL;
    return fd;
}

/* The header, descriptor and name of a PUT frame whose body (descriptor,
 * name, arrays) claims body_len bytes. */
static inline size_t raw_put_header(uint8_t *out, const char *name, proto_desc d, uint64_t body_len)
{
    d.namelen = (uint32_t)strlen(name);
    proto_encode_header(out, PROTO_PUT, body_len);
    proto_encode_desc(out + PROTO_HEADER_BYTES, &d);
    memcpy(out + PROTO_HEADER_BYTES + PROTO_DESC_BYTES, name, d.namelen);
    return PROTO_HEADER_BYTES + PROTO_DESC_BYTES + d.namelen;
}

/* Forks a client that opens a session on url, starts the PUT of a dense
 * m x 1 value named name, sends the first `sent` bytes of its arrays (whole
 * MiB chunks, each a valid double pattern) and waits to be killed.  Returns
 * its pid once those bytes are sent, or -1. */
static inline pid_t raw_partial_put(const char *url, const char *name, int64_t m, size_t sent)
{
    int pfd[2];
    char c;
    pid_t pid;
    if (pipe(pfd)) return -1;
    pid = fork();
    if (pid == 0) {
        const size_t chunk = 1u << 20;
        uint8_t b[256], *junk = malloc(chunk);
        proto_desc d;
        size_t done;
        char *text;
        int fd = raw_open(url, PROTO_VERSION, NULL, &text);
        memset(junk, 0x3f, chunk);   /* 0.49: nothing for the server to refuse */
        memset(&d, 0, sizeof d);
        d.format = SILC_DENSE;
        d.m = m;
        d.n = 1;
        d.nnz = m;
        raw_send(fd, b, raw_put_header(b, name, d, PROTO_DESC_BYTES + strlen(name) + (uint64_t)m * 8));
        for (done = 0; done < sent; done += chunk) raw_send(fd, junk, chunk);
        if (write(pfd[1], "k", 1) != 1) {}
        pause();
        _exit(0);
    }
    close(pfd[1]);
    if (pid > 0 && read(pfd[0], &c, 1) != 1) {
        kill(pid, SIGKILL);
        waitpid(pid, NULL, 0);
        pid = -1;
    }
    close(pfd[0]);
    return pid;
}

/* Connects to 127.0.0.1:port from the loopback address src (127.0.0.0/8). */
static inline int tcp_from(const char *src, int port)
{
    struct sockaddr_in a, b;
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) return -1;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    inet_pton(AF_INET, src, &a.sin_addr);
    memset(&b, 0, sizeof b);
    b.sin_family = AF_INET;
    b.sin_port = htons((uint16_t)port);
    inet_pton(AF_INET, "127.0.0.1", &b.sin_addr);
    if (bind(fd, (struct sockaddr *)&a, sizeof a) != 0 ||
        connect(fd, (struct sockaddr *)&b, sizeof b) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

/* 1 if the server closed fd within ms (EOF, after an optional reply). */
static inline int closed_within(int fd, int ms)
{
    struct pollfd p;
    char buf[512];
    double end = util_now() + ms / 1000.0;
    p.fd = fd;
    p.events = POLLIN;
    while (util_now() < end) {
        ssize_t n;
        p.revents = 0;
        if (poll(&p, 1, 50) <= 0) continue;
        n = read(fd, buf, sizeof buf);
        if (n <= 0) return 1;
    }
    return 0;
}

/* A private token file for a TCP server (silcd requires one: mode 0600,
 * 16 bytes or more): path gets its name; the caller unlinks it. */
static inline int test_token_file(char *path, size_t len)
{
    static const char token[] = "0123456789abcdef0123456789abcdef\n";
    int fd;
    snprintf(path, len, "/tmp/silc-token-%d-XXXXXX", (int)getpid());
    if ((fd = mkstemp(path)) < 0) return -1;   /* mode 0600 */
    if (write(fd, token, sizeof token - 1) != (ssize_t)(sizeof token - 1)) {
        close(fd);
        unlink(path);
        return -1;
    }
    return close(fd);
}

/* The one child process of parent (a forking silcd with one session open:
 * that session's process), or -1 if it has none or more than one. */
static inline pid_t only_child_of(pid_t parent)
{
    char path[300], line[512];
    pid_t found = -1;
    int count = 0;
    struct dirent *e;
    DIR *proc = opendir("/proc");
    if (!proc) return -1;
    /* /proc/N/stat: "N (comm) S PPID ...", comm may hold anything but ends
     * at the last ')'. */
    while ((e = readdir(proc)) && count < 2) {
        char *close_paren;
        long ppid;
        FILE *f;
        if (e->d_name[0] < '1' || e->d_name[0] > '9') continue;
        snprintf(path, sizeof path, "/proc/%s/stat", e->d_name);
        if (!(f = fopen(path, "r"))) continue;
        if (fgets(line, sizeof line, f) && (close_paren = strrchr(line, ')')) &&
            sscanf(close_paren + 1, " %*c %ld", &ppid) == 1 && ppid == (long)parent) {
            found = (pid_t)atol(e->d_name);
            count++;
        }
        fclose(f);
    }
    closedir(proc);
    return count == 1 ? found : -1;
}

/* A "Vm...:" line of /proc/PID/status in bytes (field "VmHWM:" is the peak
 * resident set), or -1. */
static inline long long proc_status_bytes(pid_t pid, const char *field)
{
    char path[64], line[256];
    long long kb = -1;
    FILE *f;
    snprintf(path, sizeof path, "/proc/%ld/status", (long)pid);
    if (!(f = fopen(path, "r"))) return -1;
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, field, strlen(field))) kb = atoll(line + strlen(field));
    fclose(f);
    return kb < 0 ? -1 : kb * 1024;
}

#endif
