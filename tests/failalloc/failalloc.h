/*
 * failalloc.h -- the allocation hook of the out-of-memory test (test_oom.c).
 *
 * tests/CMakeLists.txt compiles the engine a second time, into the static
 * library silc_failalloc, with `-include failalloc.h`: every malloc, calloc,
 * realloc and strdup written in the engine's own sources (the folders of core/,
 * plugin-reference) then goes through the counting wrappers of failalloc.c,
 * which can be told to fail the n-th allocation from now.  Production builds
 * never see this header.  free is left alone: the wrappers hand out blocks of
 * the real allocator, so any free (also one passed as a destructor pointer)
 * releases them, and ASan's leak scan does the accounting.
 *
 * The header includes no system header, so a source's own feature macros
 * (_POSIX_C_SOURCE before <stdlib.h>) still come first; the C library's
 * declarations, rewritten to the wrapper names, agree with the ones below.
 * The macros are plain names, not function-like, so that the allocator of
 * the plugin host table (host->realloc(...)) and a function pointer to
 * calloc are renamed alike in every source of the library.
 */
#ifndef SILC_FAILALLOC_H
#define SILC_FAILALLOC_H

#include <stddef.h>

void *failalloc_malloc(size_t bytes);
void *failalloc_calloc(size_t count, size_t size);
void *failalloc_realloc(void *p, size_t bytes);
char *failalloc_strdup(const char *s);

/* From the next allocation on, count allocations and fail the n-th (n >= 1);
 * persistent: also every one after it, else only that one (transient). */
void failalloc_arm(long n, int persistent);
/* Stops failing and counting; returns how many allocations were counted. */
long failalloc_disarm(void);
/* Allocations counted since failalloc_arm. */
long failalloc_count(void);
/* Failures injected since failalloc_arm. */
long failalloc_failures(void);

/* The engine's clock, made a counter: each reading is 100 us after the one
 * before.  A timing the engine prints or keeps (a report's "time:", the
 * deferred estimate's share of a factorization) has a length, and with it
 * the growth of the buffer it is written into: with the wall clock, a slow
 * or loaded machine made a statement allocate once more or less than the
 * fault-free run this test replays (seen in CI: `x = S \ v; info x`, 81
 * allocations against 82).  clockid_t is int on the C libraries we build on. */
struct timespec;
int failalloc_clock_gettime(int clock, struct timespec *ts);

/* test_oom.c includes this header for the functions above without the macros. */
#ifndef FAILALLOC_NO_MACROS
#define clock_gettime failalloc_clock_gettime
#define malloc failalloc_malloc
#define calloc failalloc_calloc
#define realloc failalloc_realloc
#define strdup failalloc_strdup
#endif

#endif
