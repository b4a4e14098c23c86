/*
 * limits.c -- what no session of silcd may pass, whatever it runs
 * (docs/security.md, "Limits"):
 *
 * - the caps of a session's process, set once when it starts: its data
 *   segment (RLIMIT_DATA, from --max-session-bytes), its CPU seconds
 *   (RLIMIT_CPU, --max-cpu), and its death with its parent
 *   (PR_SET_PDEATHSIG), so that no session outlives silcd;
 * - the watch over a running request, which the evaluator asks between
 *   statements (silc_engine.cancel): its time limit (--max-request-seconds),
 *   its client hanging up, the server shutting down, and the client's
 *   CANCEL frame, which the watch reads off the socket while the request
 *   runs (an interrupt: "interrupted", docs/protocol.md).  Asking is cooperative;
 *   a request stuck inside a library call is ended by a timer in the
 *   session's process (the process dies of SIGALRM and silcd tells the
 *   client, silcd.c reap_children) or, when its client has gone, killed by
 *   silcd;
 * - under silcd --mpi, where one process per rank holds every session, the
 *   same caps end the whole job: --max-cpu caps each rank's CPU time over
 *   its life, and the request timer ends rank 0; the rank says why as it
 *   dies (srv_limit_job), mpirun takes the other ranks down, and the
 *   operator's supervisor restarts the job (mpirun restarts nothing).
 */
#define _GNU_SOURCE   /* POLLRDHUP */
#include "server.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include "client.h"
#include "engine.h"

/* The part of a process's data segment (kB, /proc/self/status VmData) made
 * before any session ran: libraries, their buffers, a sanitizer's shadow
 * memory.  0 if unknown. */
static uint64_t data_bytes_now(void)
{
    char line[256];
    unsigned long long kb = 0;
    FILE *f = fopen("/proc/self/status", "r");
    if (!f) return 0;
    while (fgets(line, sizeof line, f))
        if (sscanf(line, "VmData: %llu kB", &kb) == 1) break;
    fclose(f);
    return (uint64_t)kb << 10;
}

uint64_t srv_data_cap(int sessions)
{
    if (!srv_cfg.max_session_bytes) return 0;
    return data_bytes_now() + (uint64_t)sessions * 2 * srv_cfg.max_session_bytes +
           srv_cfg.pool_bytes + SRV_DATA_MARGIN;
}

int srv_limit_process(int parent, int sessions)
{
    struct rlimit r;
    uint64_t cap = srv_data_cap(sessions);
    /* Dies with the process that started it; if that one is already gone
     * (it died between fork and here), now. */
    if (prctl(PR_SET_PDEATHSIG, SIGKILL) != 0) {
        srv_log(LOG_ERROR, "prctl(PR_SET_PDEATHSIG): %s", strerror(errno));
        return -1;
    }
    if (getppid() != (pid_t)parent) _exit(1);
    if (cap) {
        r.rlim_cur = r.rlim_max = (rlim_t)cap;
        if (setrlimit(RLIMIT_DATA, &r) != 0) {
            srv_log(LOG_ERROR, "setrlimit(RLIMIT_DATA, %llu): %s", (unsigned long long)cap,
                    strerror(errno));
            return -1;
        }
    }
    if (srv_cfg.max_cpu_s > 0) {
        /* SIGXCPU at the limit, SIGKILL a second later if it is caught;
         * no core file of a process that may hold gigabytes. */
        r.rlim_cur = 0;
        r.rlim_max = 0;
        setrlimit(RLIMIT_CORE, &r);
        r.rlim_cur = (rlim_t)srv_cfg.max_cpu_s;
        r.rlim_max = (rlim_t)srv_cfg.max_cpu_s + 1;
        if (setrlimit(RLIMIT_CPU, &r) != 0) {
            srv_log(LOG_ERROR, "setrlimit(RLIMIT_CPU): %s", strerror(errno));
            return -1;
        }
    }
    return 0;
}

void srv_death_reason(int sig, int state, char *out, size_t outlen)
{
    out[0] = '\0';
    if (sig == SIGXCPU && srv_cfg.max_cpu_s > 0)
        snprintf(out, outlen, ": it used the %d s of CPU time a session may use (silcd "
                 "--max-cpu)", srv_cfg.max_cpu_s);
    else if (sig == SIGALRM && state == SLOT_RUNNING && srv_cfg.max_request_ms > 0)
        snprintf(out, outlen, ": its request took longer than %g s and did not stop within "
                 "%g s more (it was inside a library call) (silcd --max-request-seconds)",
                 srv_cfg.max_request_ms / 1000.0, SRV_REQUEST_GRACE_S);
    else if ((sig == SIGABRT || sig == SIGSEGV || sig == SIGBUS) && srv_cfg.max_session_bytes)
        snprintf(out, outlen, " (its data segment is capped at %llu bytes from silcd "
                 "--max-session-bytes: a library that cannot allocate may abort)",
                 (unsigned long long)srv_data_cap(1));
}

/* The last words of a rank of silcd --mpi that a limit ends: made before,
 * written from the signal handler (no allocation, no stdio there). */
static char cpu_words[400], alarm_words[400];
static size_t cpu_words_len, alarm_words_len;

static void say_why_and_die(int sig)
{
    ssize_t w = sig == SIGXCPU ? write(2, cpu_words, cpu_words_len)
                               : write(2, alarm_words, alarm_words_len);
    (void)w;
    signal(sig, SIG_DFL);
    raise(sig);
}

void srv_limit_job(int rank)
{
    struct sigaction sa;
    const char *restart = "every session is lost; mpirun restarts nothing: the operator's "
                          "supervisor restarts silcd";
    snprintf(cpu_words, sizeof cpu_words, "silcd[error]: rank %d used the %d s of CPU time a "
             "rank may use (silcd --max-cpu): ending the MPI job; %s\n", rank,
             srv_cfg.max_cpu_s, restart);
    snprintf(alarm_words, sizeof alarm_words, "silcd[error]: rank %d: a request took longer "
             "than %g s and did not stop within %g s more (it is inside a library call) "
             "(silcd --max-request-seconds): ending the MPI job; %s\n", rank,
             srv_cfg.max_request_ms / 1000.0, SRV_REQUEST_GRACE_S, restart);
    cpu_words_len = strlen(cpu_words);
    alarm_words_len = strlen(alarm_words);
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = say_why_and_die;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGXCPU, &sa, NULL);
    sigaction(SIGALRM, &sa, NULL);
}

/* The forced end of a request stuck where the watch is never asked: the
 * default action of SIGALRM ends the process (silcd.c names the cause);
 * under silcd --mpi, rank 0, and with it the job (srv_limit_job). */
static void arm_request_timer(double seconds)
{
    struct itimerval t;
    memset(&t, 0, sizeof t);
    t.it_value.tv_sec = (time_t)seconds;
    t.it_value.tv_usec = (suseconds_t)((seconds - (double)(time_t)seconds) * 1e6);
    setitimer(ITIMER_REAL, &t, NULL);
}

void srv_watch_begin(srv_watch *w, int fd)
{
    double now = util_now();
    memset(w, 0, sizeof *w);
    w->fd = fd;
    w->next_poll = now + SRV_WATCH_POLL_S;
    if (srv_cfg.max_request_ms > 0) {
        w->deadline = now + srv_cfg.max_request_ms / 1000.0;
        arm_request_timer(srv_cfg.max_request_ms / 1000.0 + SRV_REQUEST_GRACE_S);
    }
}

void srv_watch_end(srv_watch *w)
{
    if (w->deadline > 0) arm_request_timer(0);
}

/* POLLRDHUP: the peer closed (or shut down its writing side); POLLHUP and
 * POLLERR: the connection is gone.  Request bytes already waiting (POLLIN)
 * are not a hang-up. */
static int client_gone(int fd)
{
    struct pollfd p;
    p.fd = fd;
    p.events = POLLRDHUP;
    p.revents = 0;
    return poll(&p, 1, 0) > 0 && (p.revents & (POLLRDHUP | POLLHUP | POLLERR));
}

/* A CANCEL frame is the next thing on the socket: taken off it (1).  The
 * header is peeked first, so anything else a client sent is left for the
 * request loop; a header not yet whole is looked at again next poll. */
static int cancel_arrived(int fd)
{
    uint8_t h[PROTO_HEADER_BYTES];
    ssize_t n = recv(fd, h, sizeof h, MSG_PEEK | MSG_DONTWAIT);
    if (n != (ssize_t)sizeof h || proto_get_u32(h) != PROTO_CANCEL || proto_get_u32(h + 4) != 0 ||
        proto_get_u64(h + 8) != 0)
        return 0;
    return recv(fd, h, sizeof h, MSG_DONTWAIT) == (ssize_t)sizeof h;
}

static int shutdown_requested(void)
{
    struct pollfd p;
    if (srv_shutdown_fd < 0) return 0;
    p.fd = srv_shutdown_fd;
    p.events = POLLIN;
    p.revents = 0;
    return poll(&p, 1, 0) > 0;
}

/* Records why the watch stops its request and hands the evaluator the same
 * text (the session replies with w->why: no "statement k:" in front). */
static int stop_because(srv_watch *w, int stop, char *why, size_t whylen)
{
    switch (stop) {
    case SRV_STOP_TIME:
        snprintf(w->why, sizeof w->why, "request took longer than %g s: stopped; the store is "
                 "as before the statement", srv_cfg.max_request_ms / 1000.0);
        break;
    case SRV_STOP_GONE:
        snprintf(w->why, sizeof w->why, "the client disconnected: request stopped");
        break;
    default:
        snprintf(w->why, sizeof w->why, "server shutting down: request stopped after a grace "
                 "of %g s; its values are gone", SRV_SHUTDOWN_GRACE_S);
        break;
    }
    w->stop = stop;
    snprintf(why, whylen, "%s", w->why);
    return 1;
}

int srv_watch_check(void *user, char *why, size_t whylen)
{
    srv_watch *w = user;
    double now = util_now();
    if (w->stop) return stop_because(w, w->stop, why, whylen);
    if (w->cancelled) {
        snprintf(why, whylen, "%s", ENG_INTERRUPTED);
        return 1;
    }
    if (w->deadline > 0 && now >= w->deadline) return stop_because(w, SRV_STOP_TIME, why, whylen);
    /* The clock is cheap (vDSO), system calls are not: poll every 20 ms. */
    if (now < w->next_poll) return 0;
    w->next_poll = now + SRV_WATCH_POLL_S;
    srv_output_drain(); /* room in the pipe for what a library prints next */
    if ((w->flush && w->flush(w->flush_user)) || client_gone(w->fd))
        return stop_because(w, SRV_STOP_GONE, why, whylen);
    if (cancel_arrived(w->fd)) {
        w->cancelled = 1;
        snprintf(why, whylen, "%s", ENG_INTERRUPTED);
        return 1;
    }
    if (!w->shutdown_at && shutdown_requested()) w->shutdown_at = now + SRV_SHUTDOWN_GRACE_S;
    if (w->shutdown_at && now >= w->shutdown_at)
        return stop_because(w, SRV_STOP_SHUTDOWN, why, whylen);
    return 0;
}
