/*
 * failalloc.c -- the counting allocator behind failalloc.h: the engine's
 * allocations of the test build of test_oom.c come here, and the n-th one
 * after failalloc_arm(n, ...) returns NULL, as the C library's would when
 * memory runs out.  The engine is single-threaded per context and the test
 * uses one thread, so plain counters suffice.
 */
#include "failalloc.h"

/* This file is compiled with the rest of the library, under the forced
 * include: here the names must mean the C library's functions again (before
 * <stdlib.h> declares them). */
#undef malloc
#undef calloc
#undef realloc
#undef strdup
#undef clock_gettime

#include <execinfo.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static int armed, persistent_, trace = -1;
static long target, counted, failures;

/* FAILALLOC_TRACE=1 in the environment prints the stack of each failed
 * allocation to stderr: where a finding of test_oom.c starts. */
static void maybe_trace(void)
{
    void *frames[24];
    int n;
    if (trace < 0) trace = getenv("FAILALLOC_TRACE") != NULL;
    if (!trace) return;
    n = backtrace(frames, 24);
    write(2, "failalloc: failed here\n", sizeof "failalloc: failed here\n" - 1);
    backtrace_symbols_fd(frames, n, 2);
}

/* 1 when this allocation is to fail. */
static int fail_now(void)
{
    if (!armed) return 0;
    counted++;
    if (counted == target || (persistent_ && counted > target)) {
        failures++;
        maybe_trace();
        return 1;
    }
    return 0;
}

void *failalloc_malloc(size_t bytes)
{
    return fail_now() ? NULL : malloc(bytes);
}

void *failalloc_calloc(size_t count, size_t size)
{
    return fail_now() ? NULL : calloc(count, size);
}

void *failalloc_realloc(void *p, size_t bytes)
{
    return fail_now() ? NULL : realloc(p, bytes);
}

char *failalloc_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *p = fail_now() ? NULL : malloc(n);
    if (p) memcpy(p, s, n);
    return p;
}

void failalloc_arm(long n, int persistent)
{
    armed = 1;
    persistent_ = persistent;
    target = n;
    counted = 0;
    failures = 0;
}

long failalloc_disarm(void)
{
    armed = 0;
    return counted;
}

long failalloc_count(void)
{
    return counted;
}

long failalloc_failures(void)
{
    return failures;
}

/* The counting clock of failalloc.h: deterministic, and never standing still
 * (a loop waiting for a deadline still ends). */
int failalloc_clock_gettime(int clock, struct timespec *ts)
{
    static long long ticks;
    long long us = 100 * ++ticks;
    (void)clock;
    ts->tv_sec = (time_t)(us / 1000000);
    ts->tv_nsec = (long)(us % 1000000) * 1000;
    return 0;
}
