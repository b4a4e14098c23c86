/*
 * test_largealloc.c -- the large-block allocator (core/util/largealloc.c)
 * that plugins get as host->large_* and plugin-suitesparse puts in
 * SuiteSparse_config.
 *
 * Checked: blocks of UTIL_LARGE_MIN_BYTES and more are its own mappings,
 * 2 MiB-aligned, zero-filled by calloc, and smaller ones malloc's; realloc
 * keeps the contents while it grows a block of its own, shrinks it in place,
 * and moves it back to malloc below the threshold; pointers it did not hand
 * out (malloc's, one 2 MiB-aligned from posix_memalign) go to libc's free
 * and realloc, which AddressSanitizer (CI's second run) would report as a
 * mismatched free otherwise; the registry's bound (past it, malloc serves);
 * out of memory and overflowing sizes give NULL and ENOMEM and leave the
 * block of a failed realloc as it was; several threads at once.  Where the
 * kernel has no transparent huge pages every call is libc's: the contents
 * checks still run, the ownership ones are skipped and say so.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "util.h"

#define MIB ((size_t)1 << 20)

static int thp;

/* Writes i * 31 + seed at every 4093rd offset i and at the last byte: a
 * pattern that depends only on the offset, so a block cut shorter still
 * holds its prefix's. */
static void fill(unsigned char *p, size_t n, unsigned seed)
{
    for (size_t i = 0; i < n; i += 4093) p[i] = (unsigned char)(i * 31 + seed);
    if (n) p[n - 1] = (unsigned char)((n - 1) * 31 + seed);
}

/* The pattern at every 4093rd offset below n. */
static int holds(const unsigned char *p, size_t n, unsigned seed)
{
    for (size_t i = 0; i < n; i += 4093)
        if (p[i] != (unsigned char)(i * 31 + seed)) return 0;
    return 1;
}

static void test_small_and_large(void)
{
    unsigned char *s = util_large_malloc(1000), *l = util_large_malloc(8 * MIB + 3);
    unsigned char *z = util_large_calloc(5, 2 * MIB);
    size_t nonzero = 0;
    CHECK(s && l && z, "allocations");
    if (!s || !l || !z) return;
    CHECK(!util_large_owns(s), "a small block is malloc's");
    if (thp) {
        CHECK(util_large_owns(l) && util_large_owns(z), "blocks of 4 MiB and more are the allocator's own");
        CHECK((uintptr_t)l % (2 * MIB) == 0 && (uintptr_t)z % (2 * MIB) == 0, "2 MiB-aligned");
    }
    for (size_t i = 0; i < 10 * MIB; i++) nonzero += z[i] != 0;
    CHECK(nonzero == 0, "calloc'd block is zero (%zu bytes not)", nonzero);
    fill(l, 8 * MIB + 3, 7);
    CHECK(holds(l, 8 * MIB + 3, 7) && l[8 * MIB + 2] == (unsigned char)((8 * MIB + 2) * 31 + 7),
          "the whole large block is writable");
    util_large_free(s);
    util_large_free(l);
    util_large_free(z);
    CHECK(!util_large_owns(l), "a freed block leaves the registry");
    util_large_free(NULL);
}

static void test_realloc_across_threshold(void)
{
    unsigned char *p = util_large_malloc(6 * MIB), *q;
    if (!p) {
        CHECK(0, "6 MiB");
        return;
    }
    fill(p, 6 * MIB, 1);
    q = util_large_realloc(p, 20 * MIB); /* grows: the pages move, the contents stay */
    CHECK(q && holds(q, 6 * MIB, 1), "growing keeps the contents");
    if (!q) return;
    if (thp) CHECK(util_large_owns(q) && (uintptr_t)q % (2 * MIB) == 0, "a grown block is still ours, aligned");
    fill(q, 20 * MIB, 2);
    p = util_large_realloc(q, 5 * MIB); /* shrinks in place */
    CHECK(p && holds(p, 5 * MIB, 2), "shrinking keeps the contents");
    if (thp) CHECK(p == q && util_large_owns(p), "shrinking stays in place");
    if (!p) return;
    q = util_large_realloc(p, MIB); /* below the threshold: back to malloc */
    CHECK(q && holds(q, MIB, 2), "moving below the threshold keeps the contents");
    CHECK(q && !util_large_owns(q), "a block below the threshold is malloc's");
    if (thp) CHECK(!util_large_owns(p), "and the mapping is gone");
    /* a small malloc block grown past the threshold is libc's realloc */
    p = util_large_realloc(q, 9 * MIB);
    CHECK(p && holds(p, MIB, 2), "libc's realloc keeps the contents");
    CHECK(p && !util_large_owns(p), "a block the allocator did not map stays libc's");
    util_large_free(p);
    p = util_large_realloc(NULL, 5 * MIB); /* realloc(NULL) is malloc */
    if (thp) CHECK(p && util_large_owns(p), "realloc(NULL, 5 MiB) maps");
    util_large_free(p);
}

/* Blocks from before the allocator was installed, or from another allocator
 * altogether, must go back to libc. */
static void test_foreign_pointers(void)
{
    void *m = malloc(12 * MIB), *a = NULL, *r;
    CHECK(m && posix_memalign(&a, 2 * MIB, 4 * MIB) == 0, "libc blocks");
    if (!m || !a) return;
    CHECK(!util_large_owns(m) && !util_large_owns(a), "not ours, even 2 MiB-aligned");
    memset(a, 3, 4 * MIB);
    r = util_large_realloc(a, 16 * MIB);
    CHECK(r && ((unsigned char *)r)[4 * MIB - 1] == 3 && !util_large_owns(r), "foreign realloc is libc's");
    util_large_free(r ? r : a);
    util_large_free(m);
}

static void test_out_of_memory(void)
{
    unsigned char *p;
    errno = 0;
    CHECK(!util_large_malloc(SIZE_MAX - 5) && errno == ENOMEM, "a size that cannot be rounded up");
    errno = 0;
    CHECK(!util_large_calloc(SIZE_MAX / 2, 4) && errno == ENOMEM, "calloc's product overflows");
    if (!thp) return;
    /* more than a 47-bit address space holds: the mapping fails */
    errno = 0;
    CHECK(!util_large_malloc((size_t)1 << 48) && errno == ENOMEM, "a mapping the kernel refuses");
    if (!(p = util_large_malloc(8 * MIB))) {
        CHECK(0, "8 MiB");
        return;
    }
    fill(p, 8 * MIB, 9);
    errno = 0;
    CHECK(!util_large_realloc(p, (size_t)1 << 48) && errno == ENOMEM, "a failed grow is NULL");
    CHECK(util_large_owns(p) && holds(p, 8 * MIB, 9), "and leaves the block as it was");
    CHECK(!util_large_realloc(p, SIZE_MAX - 5), "an overflowing grow is NULL");
    CHECK(util_large_owns(p), "still the same block");
    util_large_free(p);
}

/* Past UTIL_LARGE_MAX_BLOCKS live blocks the registry is full and malloc
 * serves (the mappings are not touched: virtual memory only). */
static void test_registry_bound(void)
{
    enum { N = UTIL_LARGE_MAX_BLOCKS + 8 };
    static void *p[N];
    int owned = 0, got = 0;
    for (int i = 0; i < N; i++) {
        p[i] = util_large_malloc(UTIL_LARGE_MIN_BYTES);
        got += p[i] != NULL;
        owned += util_large_owns(p[i]);
    }
    CHECK(got == N, "%d of %d blocks", got, N);
    if (thp) CHECK(owned == UTIL_LARGE_MAX_BLOCKS, "%d blocks mapped, want the bound %d", owned, UTIL_LARGE_MAX_BLOCKS);
    for (int i = 0; i < N; i++) util_large_free(p[i]);
    p[0] = util_large_malloc(UTIL_LARGE_MIN_BYTES);
    if (thp) CHECK(util_large_owns(p[0]), "freed slots are used again");
    util_large_free(p[0]);
}

/* Threads allocating, growing, shrinking and freeing at once. */
static void *churn(void *arg)
{
    unsigned seed = (unsigned)(uintptr_t)arg, bad = 0;
    for (int i = 0; i < 40; i++) {
        size_t a = (size_t)((seed + i * 7u) % 12u + 1u) * MIB, b = (size_t)((seed + i * 5u) % 12u + 1u) * MIB;
        unsigned char *p = util_large_malloc(a), *q;
        if (!p) return (void *)1;
        fill(p, a, seed + (unsigned)i);
        q = util_large_realloc(p, b);
        if (!q) return (void *)1;
        bad += !holds(q, a < b ? a : b, seed + (unsigned)i);
        util_large_free(q);
    }
    return (void *)(uintptr_t)bad;
}

static void test_threads(void)
{
    pthread_t t[4];
    uintptr_t bad = 0;
    for (uintptr_t i = 0; i < 4; i++) pthread_create(&t[i], NULL, churn, (void *)i);
    for (int i = 0; i < 4; i++) {
        void *r;
        pthread_join(t[i], &r);
        bad += (uintptr_t)r;
    }
    CHECK(bad == 0, "%lu failures across the threads", (unsigned long)bad);
}

int main(void)
{
    thp = util_huge_pages_available();
    if (!thp) printf("transparent huge pages unavailable: ownership checks skipped, libc's path checked\n");
    test_small_and_large();
    test_realloc_across_threshold();
    test_foreign_pointers();
    test_out_of_memory();
    test_registry_bound();
    test_threads();
    return check_done();
}
