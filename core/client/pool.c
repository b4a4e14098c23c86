/*
 * pool.c -- the process's pool of recently freed large arrays: value arrays
 * and the arrays of envelopes (val_array_alloc / val_array_free).
 *
 * glibc serves every array above 32 MiB with its own mmap, so without this a
 * PUT receives into freshly mapped pages (the kernel zeroes and faults in
 * each 4 KiB page), a GET of the same size each step does the same on the
 * client, and the array each replaces is unmapped afterwards (a TLB shootdown
 * across cores).  With the pool the array freed by one step is the one the
 * next step receives into.
 *
 * Values are immutable and reference-counted, so an array reaches the pool
 * only when its last value is freed.  The pool keeps at most POOL_SLOTS
 * arrays of at least POOL_MIN_BYTES, the cap given to pool_install in all,
 * and hands an array out only for a request of at least 3/4 of its size, so
 * little memory is wasted.  In silcd pooled memory is the server's, not any
 * session's: session limits never see it.  An array idle for
 * POOL_IDLE_SECONDS is freed at the next pool call.
 */
#define _GNU_SOURCE 1 /* malloc_usable_size */
#include "client.h"

#include <pthread.h>

#include <malloc.h>
#include <stdlib.h>
#include <time.h>

#include "store.h"

enum { POOL_SLOTS = 8, POOL_IDLE_SECONDS = 30 };
#define POOL_MIN_BYTES ((size_t)1 << 20)

typedef struct slot {
    void *p;
    size_t bytes; /* malloc_usable_size: what the array can really hold */
    time_t freed;
} slot;

static pthread_mutex_t pool_lock = PTHREAD_MUTEX_INITIALIZER;
static slot slots[POOL_SLOTS];
static size_t pooled_bytes, cap_bytes;
static int installed; /* pool_install was called: the default does not override it */

/* $SILC_ARRAY_POOL MiB; unset or not a number: the default. */
static void install_from_env(void)
{
    const char *v = getenv("SILC_ARRAY_POOL");
    char *end = NULL;
    double mib = v && *v ? strtod(v, &end) : POOL_DEFAULT_MIB;
    if (installed) return;
    if (end && (*end || !(mib >= 0))) mib = POOL_DEFAULT_MIB;
    pool_install((size_t)(mib * 1048576.0));
}

static time_t now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec;
}

/* Frees slot i; under pool_lock. */
static void drop(int i)
{
    free(slots[i].p);
    pooled_bytes -= slots[i].bytes;
    slots[i].p = NULL;
    slots[i].bytes = 0;
}

static void drop_idle(time_t t)
{
    int i;
    for (i = 0; i < POOL_SLOTS; i++)
        if (slots[i].p && t - slots[i].freed > POOL_IDLE_SECONDS) drop(i);
}

static void *pool_take(size_t bytes)
{
    void *p = NULL;
    int i, best = -1;
    if (bytes < POOL_MIN_BYTES) return NULL;
    pthread_mutex_lock(&pool_lock);
    drop_idle(now_s());
    for (i = 0; i < POOL_SLOTS; i++)
        if (slots[i].p && slots[i].bytes >= bytes && slots[i].bytes / 4 * 3 <= bytes &&
            (best < 0 || slots[i].bytes < slots[best].bytes))
            best = i;
    if (best >= 0) {
        p = slots[best].p;
        pooled_bytes -= slots[best].bytes;
        slots[best].p = NULL;
        slots[best].bytes = 0;
    }
    pthread_mutex_unlock(&pool_lock);
    return p;
}

/* Keeps p when it is large and fits under the cap, evicting the oldest
 * arrays to make room: the newest is the likeliest to be asked for next. */
static int pool_give(void *p)
{
    size_t bytes = malloc_usable_size(p);
    time_t t;
    int i, kept = 0;
    if (bytes < POOL_MIN_BYTES || bytes > cap_bytes) return 0;
    t = now_s();
    pthread_mutex_lock(&pool_lock);
    drop_idle(t);
    for (;;) {
        int free_slot = -1, oldest = -1;
        for (i = 0; i < POOL_SLOTS; i++) {
            if (!slots[i].p) free_slot = i;
            else if (oldest < 0 || slots[i].freed < slots[oldest].freed) oldest = i;
        }
        if (free_slot >= 0 && pooled_bytes + bytes <= cap_bytes) {
            slots[free_slot].p = p;
            slots[free_slot].bytes = bytes;
            slots[free_slot].freed = t;
            pooled_bytes += bytes;
            kept = 1;
            break;
        }
        if (oldest < 0) break;
        drop(oldest);
    }
    pthread_mutex_unlock(&pool_lock);
    return kept;
}

void pool_install(size_t cap)
{
    installed = 1;
    cap_bytes = cap;
    if (cap > 0) val_set_array_pool(pool_take, pool_give);
}

void pool_install_default(void)
{
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    pthread_once(&once, install_from_env);
}
