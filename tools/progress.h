/*
 * progress.h -- one progress line on stderr for long work (the cloth
 * program, the benches): shown only when stderr is a terminal, redrawn at
 * most ten times a second, erased at the end, so a log or a pipe gets
 * nothing of it.  Header-only: the programs that use it share no library.
 *
 *     progress p = {0};      (a zeroed one starts itself)
 *     progress_start(&p);
 *     for (k = 0; k < n; k++) { ...; progress_show(&p, "step %d of %d", k + 1, n); }
 *     progress_done(&p);
 */
#ifndef SILC_PROGRESS_H
#define SILC_PROGRESS_H

#include <stdarg.h>
#include <stdio.h>
#include <time.h>
#include <unistd.h>

typedef struct progress {
    int started;    /* on is known */
    int on;         /* stderr is a terminal */
    int shown;      /* a line is on it */
    double last;    /* when it was drawn */
} progress;

static inline double progress_now_(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static inline void progress_start(progress *p)
{
    p->started = 1;
    p->on = isatty(STDERR_FILENO);
    p->shown = 0;
    p->last = 0;
}

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static inline void progress_show(progress *p, const char *fmt, ...)
{
    va_list ap;
    double t;
    if (!p->started) progress_start(p);
    if (!p->on || (t = progress_now_()) - p->last < 0.1) return;
    p->last = t;
    fputc('\r', stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputs("\033[K", stderr); /* the rest of a longer earlier line */
    fflush(stderr);
    p->shown = 1;
}

static inline void progress_done(progress *p)
{
    if (p->shown) fputs("\r\033[K", stderr), fflush(stderr);
    p->shown = 0;
}

#endif
