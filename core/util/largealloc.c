/*
 * largealloc.c -- an allocator for large blocks on transparent huge pages,
 * for a library's work space (SuiteSparse's, through the host API).
 *
 * A sparse factorization touches hundreds of MB of fresh memory: UMFPACK's
 * on the 500^2 complex Helmholtz matrix about 530 MB, 132 000 minor faults
 * of 4 KiB pages, and then runs dense kernels over it with a TLB miss per
 * 4 KiB.  Served from 2 MiB-aligned mappings advised MADV_HUGEPAGE, the same
 * solve takes 14 000 faults and 0.74x the CPU time (docs/complex.md).  glibc
 * gets the same only with glibc.malloc.hugetlb=1, which is the host
 * program's choice (silcd sets it for itself): this allocator serves only
 * the callers that ask for it and changes nothing else in the process.
 *
 * Blocks of UTIL_LARGE_MIN_BYTES and more are mmap'd, rounded up to whole
 * 2 MiB pages and aligned to 2 MiB; smaller ones are malloc's.  Our blocks
 * are recorded in a bounded registry (UTIL_LARGE_MAX_BLOCKS live blocks; past it a
 * request is served by malloc), so that free and realloc of a pointer we did
 * not hand out -- a block a library allocated before these functions were
 * installed -- go to libc's free and realloc.  A pointer not aligned to
 * 2 MiB cannot be ours, which keeps the registry's lock off the path of
 * every small free.  Where the kernel has no transparent huge pages (or
 * they are "never"), and off Linux, every call is libc's.
 */
#define _GNU_SOURCE 1 /* mremap */
#include "util.h"

#include <errno.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#if defined(__linux__) && defined(MADV_HUGEPAGE) && defined(MREMAP_FIXED)
#define LARGE_MMAP 1
#else
#define LARGE_MMAP 0
#endif

#define LARGE_ALIGN ((size_t)2 << 20) /* x86-64's PMD huge page */

typedef struct large_block {
    void *p;
    size_t len; /* mapped bytes, a multiple of LARGE_ALIGN */
} large_block;

static pthread_mutex_t large_lock = PTHREAD_MUTEX_INITIALIZER;
static large_block large_blocks[UTIL_LARGE_MAX_BLOCKS];
static int large_count;
static size_t large_mapped; /* the sum of the live blocks' len */

/* ---- whether the kernel gives huge pages --------------------------------- */

static int thp_usable;

/* /sys/kernel/mm/transparent_hugepage/enabled reads "always [madvise]
 * never": the bracketed word is the mode, and MADV_HUGEPAGE works under
 * "always" and "madvise". */
static void thp_probe(void)
{
    char line[128] = "";
    FILE *f = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    if (!f) return;
    if (fgets(line, sizeof line, f))
        thp_usable = strstr(line, "[always]") != NULL || strstr(line, "[madvise]") != NULL;
    fclose(f);
}

int util_huge_pages_available(void)
{
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    if (!LARGE_MMAP) return 0;
    pthread_once(&once, thp_probe);
    return thp_usable;
}

/* ---- the registry ---------------------------------------------------------- */

/* Index of p in the registry, or -1; under large_lock. */
static int large_find(const void *p)
{
    for (int i = 0; i < large_count; i++)
        if (large_blocks[i].p == p) return i;
    return -1;
}

/* p's mapped length if it is one of our blocks (and removes it when take),
 * else 0. */
static size_t large_lookup(const void *p, int take)
{
    size_t len = 0;
    int i;
    if (!p || (uintptr_t)p % LARGE_ALIGN != 0) return 0;
    pthread_mutex_lock(&large_lock);
    if ((i = large_find(p)) >= 0) {
        len = large_blocks[i].len;
        if (take) {
            large_mapped -= len;
            large_blocks[i] = large_blocks[--large_count];
        }
    }
    pthread_mutex_unlock(&large_lock);
    return len;
}

int util_large_owns(const void *p)
{
    return large_lookup(p, 0) != 0;
}

size_t util_large_in_use(void)
{
    size_t bytes;
    pthread_mutex_lock(&large_lock);
    bytes = large_mapped;
    pthread_mutex_unlock(&large_lock);
    return bytes;
}

/* Records a block; 0, or -1 when the registry is full. */
static int large_record(void *p, size_t len)
{
    int ok;
    pthread_mutex_lock(&large_lock);
    ok = large_count < UTIL_LARGE_MAX_BLOCKS;
    if (ok) {
        large_blocks[large_count++] = (large_block){p, len};
        large_mapped += len;
    }
    pthread_mutex_unlock(&large_lock);
    return ok ? 0 : -1;
}

/* The entry of old becomes {now, len} (a block resized or moved); under
 * large_lock. */
static void large_rerecord_locked(const void *old, void *now, size_t len)
{
    int i;
    if ((i = large_find(old)) >= 0) {
        large_mapped += len - large_blocks[i].len; /* modulo 2^N: a shrink subtracts */
        large_blocks[i] = (large_block){now, len};
    }
}

static void large_rerecord(const void *old, void *now, size_t len)
{
    pthread_mutex_lock(&large_lock);
    large_rerecord_locked(old, now, len);
    pthread_mutex_unlock(&large_lock);
}

/* ---- mappings -------------------------------------------------------------- */

/* bytes rounded up to whole huge pages; 0 when that overflows. */
static size_t large_length(size_t bytes)
{
    if (bytes > SIZE_MAX - 2 * LARGE_ALIGN) return 0;
    return (bytes + LARGE_ALIGN - 1) / LARGE_ALIGN * LARGE_ALIGN;
}

#if LARGE_MMAP
/* len bytes of fresh zero pages at a LARGE_ALIGN boundary, advised
 * MADV_HUGEPAGE; NULL when the kernel refuses.  Over-maps by one huge page
 * and unmaps the ends, so the block starts on a huge page. */
static void *large_map(size_t len)
{
    char *raw = mmap(NULL, len + LARGE_ALIGN, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    size_t head;
    if (raw == MAP_FAILED) return NULL;
    head = (LARGE_ALIGN - (uintptr_t)raw % LARGE_ALIGN) % LARGE_ALIGN;
    if (head) munmap(raw, head);
    if (LARGE_ALIGN - head) munmap(raw + head + len, LARGE_ALIGN - head);
    /* advice, not a promise: without huge pages the block still works */
    (void)madvise(raw + head, len, MADV_HUGEPAGE);
    return raw + head;
}

static void large_unmap(void *p, size_t len)
{
    munmap(p, len);
}

/* Moves the len mapped bytes at p to a new mapping of newlen > len bytes
 * (the kernel moves the page tables: no copy, and huge pages stay huge) and
 * re-records the block.  NULL when there is no room, p untouched.  The move
 * unmaps p, so another thread's mmap may get p back at once: the move and
 * the re-record are one step under large_lock, else that thread could
 * record p while p's old entry is still there, and the re-record could
 * take its entry for ours (test_largealloc's threads lost data that way,
 * about 1 run in 100). */
static void *large_grow(void *p, size_t len, size_t newlen)
{
    void *q = large_map(newlen);
    if (!q) return NULL;
    pthread_mutex_lock(&large_lock);
    if (mremap(p, len, len, MREMAP_MAYMOVE | MREMAP_FIXED, q) == MAP_FAILED) {
        memcpy(q, p, len);
        munmap(p, len);
    }
    large_rerecord_locked(p, q, newlen);
    pthread_mutex_unlock(&large_lock);
    return q;
}
#else
static void *large_map(size_t len)
{
    (void)len;
    return NULL;
}
static void large_unmap(void *p, size_t len)
{
    (void)p, (void)len;
}
static void *large_grow(void *p, size_t len, size_t newlen)
{
    (void)p, (void)len, (void)newlen;
    return NULL;
}
#endif

/* A new block of ours, zero-filled, or NULL: too large for the address
 * space (errno ENOMEM), or huge pages are not to be had here or the
 * registry is full (errno untouched: the caller falls back to libc). */
static void *large_new(size_t bytes, int *refused)
{
    size_t len = large_length(bytes);
    void *p;
    *refused = 0;
    if (!util_huge_pages_available()) return NULL;
    if (!len || !(p = large_map(len))) {
        *refused = 1;
        errno = ENOMEM;
        return NULL;
    }
    if (large_record(p, len)) {
        large_unmap(p, len);
        return NULL;
    }
    return p;
}

/* ---- the four functions ---------------------------------------------------- */

void *util_large_malloc(size_t bytes)
{
    int refused;
    void *p;
    if (bytes < UTIL_LARGE_MIN_BYTES) return malloc(bytes);
    if ((p = large_new(bytes, &refused)) || refused) return p;
    return malloc(bytes);
}

void *util_large_calloc(size_t count, size_t size)
{
    int refused;
    void *p;
    if (size && count > SIZE_MAX / size) {
        errno = ENOMEM;
        return NULL;
    }
    if (count * size < UTIL_LARGE_MIN_BYTES) return calloc(count, size);
    /* fresh anonymous pages are zero already */
    if ((p = large_new(count * size, &refused)) || refused) return p;
    return calloc(count, size);
}

void util_large_free(void *p)
{
    size_t len = large_lookup(p, 1);
    if (len) large_unmap(p, len);
    else free(p);
}

void *util_large_realloc(void *p, size_t bytes)
{
    size_t len, newlen;
    void *q;
    if (!p) return util_large_malloc(bytes);
    if (!(len = large_lookup(p, 0))) return realloc(p, bytes);
    if (bytes < UTIL_LARGE_MIN_BYTES) { /* ours, now small: back to malloc */
        if (!(q = malloc(bytes ? bytes : 1))) return NULL;
        memcpy(q, p, bytes);
        util_large_free(p);
        return q;
    }
    if (!(newlen = large_length(bytes))) {
        errno = ENOMEM;
        return NULL;
    }
    if (newlen <= len) { /* shrinking in place: unmap the tail */
        if (newlen < len) {
            large_rerecord(p, p, newlen);
            large_unmap((char *)p + newlen, len - newlen);
        }
        return p;
    }
    if (!(q = large_grow(p, len, newlen))) {
        errno = ENOMEM;
        return NULL;
    }
    return q;
}
