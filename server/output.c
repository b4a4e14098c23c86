/*
 * output.c -- what a library prints to standard output while a request
 * runs goes to that request's client, not to silcd's log.
 *
 * Libraries print on their own: PETSc's -ksp_converged_reason, its
 * deprecation warnings and eigenvalue estimates, a solver's banner.  In a
 * silcd session that text used to reach the operator's terminal or log
 * (silcd's standard output), where the client who asked for it never saw
 * it and the operator got another user's output.  So while a request runs,
 * descriptor 1 is a pipe; the watch empties it between statements and
 * every 20 ms (srv_watch_check), and after the request what it held is
 * sent to the client as TEXT frames, like `disp` output, after the
 * request's own output.  Under silcd --mpi every rank catches its own;
 * rank 0's goes to the client, the others' are dropped (session.c).
 *
 * Bounded: at most SRV_OUTPUT_MAX bytes a request are kept; the rest is
 * read and counted, and the client is told how many bytes were dropped.
 * The pipe's writing end does not block (a library printing while nobody
 * empties the pipe, inside one long call, gets EAGAIN and loses that text,
 * which the count cannot see; the pipe holds 1 MiB where the system
 * allows it).  silcd's own log goes to standard error, untouched.
 */
#define _GNU_SOURCE /* F_SETPIPE_SZ, pipe2 */
#include "server.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdio_ext.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define SRV_OUTPUT_MAX ((size_t)1 << 20)
#define SRV_OUTPUT_PIPE (1 << 20)

static struct {
    int ready;            /* srv_output_init succeeded in this process */
    int capturing;        /* between srv_output_begin and srv_output_end */
    int rd, wr, saved;    /* the pipe, and silcd's own descriptor 1 */
    char *text;           /* what was kept, NUL-terminated */
    size_t len;
    unsigned long long dropped;
} out = {0, 0, -1, -1, -1, NULL, 0, 0};

int srv_output_init(void)
{
    int fds[2];
    if (out.ready) return 0;
    if (pipe2(fds, O_NONBLOCK | O_CLOEXEC)) return -1;
    (void)fcntl(fds[1], F_SETPIPE_SZ, SRV_OUTPUT_PIPE); /* else the default 64 KiB */
    if ((out.saved = fcntl(1, F_DUPFD_CLOEXEC, 3)) < 0 || !(out.text = malloc(SRV_OUTPUT_MAX + 1))) {
        close(fds[0]);
        close(fds[1]);
        if (out.saved >= 0) close(out.saved);
        out.saved = -1;
        return -1;
    }
    out.rd = fds[0];
    out.wr = fds[1];
    out.ready = 1;
    return 0;
}

void srv_output_begin(void)
{
    if (!out.ready) return;
    fflush(stdout);
    out.len = 0;
    out.dropped = 0;
    out.capturing = dup2(out.wr, 1) == 1;
}

void srv_output_drain(void)
{
    char buf[8192];
    ssize_t n;
    if (!out.capturing) return;
    while ((n = read(out.rd, buf, sizeof buf)) > 0 || (n < 0 && errno == EINTR)) {
        size_t keep;
        if (n < 0) continue;
        keep = SRV_OUTPUT_MAX - out.len < (size_t)n ? SRV_OUTPUT_MAX - out.len : (size_t)n;
        memcpy(out.text + out.len, buf, keep);
        out.len += keep;
        out.dropped += (unsigned long long)((size_t)n - keep);
    }
}

const char *srv_output_end(unsigned long long *dropped)
{
    size_t i;
    int tries;
    *dropped = 0;
    if (!out.capturing) return NULL;
    /* stdio's buffer goes to the pipe, emptied as it fills, before silcd's
     * descriptor comes back: none of it may reach the operator's log. */
    for (tries = 0; tries < 64; tries++) {
        int flushed = fflush(stdout) == 0;
        srv_output_drain();
        if (flushed) break;
        clearerr(stdout);
    }
    if (tries == 64) __fpurge(stdout); /* what could not be written is dropped, not logged */
    clearerr(stdout);
    dup2(out.saved, 1);
    out.capturing = 0;
    for (i = 0; i < out.len; i++)
        if (out.text[i] == '\0') out.text[i] = ' '; /* a TEXT frame is text */
    out.text[out.len] = '\0';
    *dropped = out.dropped;
    return out.len || out.dropped ? out.text : NULL;
}
