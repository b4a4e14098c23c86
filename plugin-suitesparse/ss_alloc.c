/*
 * ss_alloc.c -- SuiteSparse's work space on huge pages (the host's large
 * allocator, ABI 1.9), under the option suitesparse.huge_pages.
 *
 * UMFPACK, CHOLMOD, KLU and SPQR allocate through the process-wide
 * SuiteSparse_config hooks, libc's malloc by default.  A factorization's
 * hundreds of MB then arrive one 4 KiB page fault at a time; from the host's
 * large allocator (2 MiB-aligned mappings advised MADV_HUGEPAGE) UMFPACK's
 * complex Helmholtz solve at 500^2 takes 14 000 faults instead of 132 000
 * and 0.74x the CPU time (docs/complex.md).
 *
 * The hooks are the process's, and a host program may call SuiteSparse
 * itself, so:
 *  - they are set once, at the first solve, and only if they still hold
 *    libc's functions: a program that installed its own keeps them (and
 *    huge_pages then changes nothing);
 *  - the hooks set are this file's, which use the large allocator only while
 *    this thread runs a SILC solve with huge_pages = auto (a thread-local
 *    flag): the program's own SuiteSparse calls get libc's malloc, as before;
 *  - free and realloc pass through the host's large_free/large_realloc,
 *    which give any pointer they did not hand out to libc's free/realloc, so
 *    blocks allocated before the hooks changed are freed correctly.
 * The plugin is never unloaded once accepted (core/dispatch/loader.c), so
 * the hooks stay valid for the life of the process.
 */
#include "ss.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

/* This thread is inside a SILC solve that wants huge pages. */
static _Thread_local int ss_large_on;
/* The hooks are ours (set by ss_hooks_install). */
static int ss_hooks_ours;

/* The host has the large allocator (ABI 1.9; a test's own host table may
 * be as long and leave it out). */
static int ss_large_ready(void)
{
    const silc_host_api *h = ss_host;
    return h->struct_size >= SILC_HOST_NEEDS(large_free) && h->large_alloc && h->large_calloc &&
           h->large_realloc && h->large_free;
}

static void *ss_malloc_hook(size_t bytes)
{
    return ss_large_on ? ss_host->large_alloc(bytes) : malloc(bytes);
}

static void *ss_calloc_hook(size_t count, size_t size)
{
    return ss_large_on ? ss_host->large_calloc(count, size) : calloc(count, size);
}

static void *ss_realloc_hook(void *p, size_t bytes)
{
    /* a block of ours stays ours whoever resizes it; a new one is ours only
     * inside a solve */
    if (!p && !ss_large_on) return malloc(bytes);
    return ss_host->large_realloc(p, bytes);
}

static void ss_free_hook(void *p)
{
    ss_host->large_free(p);
}

static void ss_hooks_install(void)
{
    struct SuiteSparse_config_struct *c = &SuiteSparse_config;
    if (c->malloc_func != malloc || c->calloc_func != calloc || c->realloc_func != realloc || c->free_func != free) {
        ss_host->log(2, "suitesparse: SuiteSparse_config holds the program's own allocator: kept "
                        "(suitesparse.huge_pages has no effect)");
        return;
    }
    c->malloc_func = ss_malloc_hook;
    c->calloc_func = ss_calloc_hook;
    c->realloc_func = ss_realloc_hook;
    c->free_func = ss_free_hook;
    ss_hooks_ours = 1;
}

int ss_huge_pages_mode(silc_call *call, int *on)
{
    const char *v = ss_host->option_string(call, "huge_pages", "auto");
    if (!strcmp(v, "auto")) *on = 1;
    else if (!strcmp(v, "off")) *on = 0;
    else
        return ss_host->error(call, SILC_EARG, "option 'suitesparse.huge_pages' expects auto or off, got '%s'", v);
    return SILC_OK;
}

int ss_with_huge_pages(silc_call *call, int (*run)(silc_call *call))
{
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    int on, was = ss_large_on, rc;
    if ((rc = ss_huge_pages_mode(call, &on))) return rc;
    if (on && ss_large_ready()) pthread_once(&once, ss_hooks_install);
    ss_large_on = on && ss_hooks_ours;
    rc = run(call);
    ss_large_on = was;
    return rc;
}
