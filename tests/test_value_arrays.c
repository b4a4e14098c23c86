/*
 * test_value_arrays.c -- where the arrays of values and envelopes live
 * (val_array_alloc / val_array_free, core/store/value.c), and every path
 * that frees, pools or grows one.
 *
 * Arrays of UTIL_LARGE_MIN_BYTES and more are the large-block allocator's
 * mappings on transparent huge pages (core/util/largealloc.c), smaller ones
 * malloc's, and each path must know which: the array pool (core/client/
 * pool.c) sizes a large block by its mapping, since malloc_usable_size knows
 * nothing of it, and unmaps the arrays it evicts; the plugins' host->realloc
 * and host->free take both kinds; silc_envelope_free releases the arrays a
 * GET hands out.  A libc free or realloc of a mapping would crash, and under
 * AddressSanitizer (CI's second run) is reported as a free of memory that is
 * not malloc's, so the pool, host-table and API parts below check those
 * paths as well as the numbers that pass through them.  Where the kernel has
 * no transparent huge pages every array is malloc's: the contents checks
 * still run, the ownership ones are skipped and say so.
 */
#include "check.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "client.h"
#include "dispatch.h"
#include "silc.h"
#include "silc_plugin.h"
#include "store.h"
#include "util.h"

#define MIB ((size_t)1 << 20)
#define POOL_CAP (64 * MIB)

static int thp;

static int all_zero(const unsigned char *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (p[i]) return 0;
    return 1;
}

/* Without the pool: a large array is a huge-page mapping, zero-filled when
 * asked, a small one is malloc's; both are freed by val_array_free. */
static void test_alloc(void)
{
    double *small = val_array_alloc(100, sizeof(double), 1);
    size_t count = 5 * MIB / sizeof(double);
    double *big = val_array_alloc((int64_t)count, sizeof(double), 1);
    double *empty = val_array_alloc(0, sizeof(double), 1);
    CHECK(small && big && empty, "arrays allocated");
    if (!small || !big || !empty) return;
    CHECK(!util_large_owns(small) && !util_large_owns(empty), "small arrays are malloc's");
    if (thp) CHECK(util_large_owns(big) && (uintptr_t)big % (2 * MIB) == 0, "a 5 MiB array is a 2 MiB-aligned mapping");
    if (thp) CHECK(util_large_size(big) == 6 * MIB, "mapped %zu bytes, want 6 MiB", util_large_size(big));
    CHECK(util_large_size(small) == 0, "a malloc block has no mapping size");
    CHECK(all_zero((unsigned char *)small, 100 * sizeof(double)) && all_zero((unsigned char *)big, count * sizeof(double)),
          "zero-filled");
    big[count - 1] = 1.5;
    val_array_free(small);
    val_array_free(big);
    val_array_free(empty);
    val_array_free(NULL);
}

/* With the pool: a freed large array is kept and handed out again for any
 * request its mapping holds (6 MiB for a 5 MiB array), zeroed when asked;
 * arrays pushed out past the cap are unmapped. */
static void test_pool(void)
{
    unsigned char *a, *b, *evict[8];
    pool_install(POOL_CAP);
    a = val_array_alloc((int64_t)(5 * MIB), 1, 0);
    CHECK(a != NULL, "5 MiB array");
    if (!a) return;
    memset(a, 7, 5 * MIB);
    val_array_free(a); /* into the pool */
    b = val_array_alloc((int64_t)(5 * MIB), 1, 0);
    CHECK(b == a, "the pool hands the same array back for the same size");
    val_array_free(b);
    if (thp) {
        b = val_array_alloc((int64_t)(6 * MIB), 1, 1);
        CHECK(b == a, "and for 6 MiB, which its 6 MiB mapping holds");
        CHECK(b && all_zero(b, 6 * MIB), "zeroed on request, to the mapping's end");
        val_array_free(b);
    }
    /* eight 12 MiB arrays into a 64 MiB pool: the oldest are evicted (and
     * unmapped, or freed, by the pool) to make room for the newest */
    for (int i = 0; i < 8; i++) {
        evict[i] = val_array_alloc((int64_t)(12 * MIB), 1, 0);
        CHECK(evict[i] != NULL, "12 MiB array %d", i);
        if (evict[i]) memset(evict[i], i + 1, 12 * MIB);
    }
    for (int i = 0; i < 8; i++) val_array_free(evict[i]);
    b = val_array_alloc((int64_t)(12 * MIB), 1, 0);
    {
        int j = 8;
        while (j > 0 && evict[j - 1] != b) j--;
        CHECK(j >= 4, "a 12 MiB request gets one of the 5 newest arrays back (got %d of 8)", j);
        CHECK(b && j > 0 && b[12 * MIB - 1] == j, "with what it held");
    }
    val_array_free(b);
}

/* The host table plugins allocate with: realloc keeps the contents across
 * the threshold both ways, free takes either kind. */
static void test_host_table(void)
{
    const silc_host_api *h = host_api();
    unsigned char *p = h->alloc(3 * MIB), *q;
    CHECK(p != NULL, "host alloc 3 MiB");
    if (!p) return;
    memset(p, 5, 3 * MIB);
    q = h->realloc(p, 9 * MIB); /* malloc's block grows past the threshold */
    CHECK(q && q[0] == 5 && q[3 * MIB - 1] == 5, "grown, contents kept");
    if (!q) return;
    memset(q + 3 * MIB, 6, 6 * MIB);
    p = h->realloc(q, 20 * MIB); /* a mapping (with huge pages) grows */
    CHECK(p && p[0] == 5 && p[9 * MIB - 1] == 6, "grown again, contents kept");
    if (!p) return;
    q = h->realloc(p, 1 * MIB); /* back below the threshold */
    CHECK(q && q[0] == 5 && q[1 * MIB - 1] == 5, "shrunk, prefix kept");
    if (q) h->free(q);
    p = h->calloc(2, 4 * MIB);
    CHECK(p && all_zero(p, 8 * MIB), "host calloc 8 MiB zero-filled");
    if (thp && p) CHECK(util_large_owns(p), "and a mapping");
    h->free(p);
}

/* Through the API: dense and CSR values of several MiB in, a product out,
 * checked element by element against the exact result, every envelope
 * released by silc_envelope_free. */
static void test_api(void)
{
    enum { N = 1024 };           /* 8 MiB dense */
    const int64_t n = 400000;    /* tridiagonal: 9.6 MB of values and of colind */
    silc_context *c = NULL;
    silc_envelope_t A = {0}, B = {0}, S = {0}, x = {0}, y = {0}, S2 = {0};
    double *dense = malloc((size_t)N * N * sizeof *dense), *vals = malloc((size_t)(3 * n) * sizeof *vals);
    double *ones = malloc((size_t)n * sizeof *ones);
    int64_t *rowptr = malloc((size_t)(n + 1) * sizeof *rowptr), *colind = malloc((size_t)(3 * n) * sizeof *colind);
    int64_t k = 0, bad = 0;
    CHECK(dense && vals && ones && rowptr && colind, "host arrays");
    if (!dense || !vals || !ones || !rowptr || !colind) goto out;
    CHECK(silc_open(&c, NULL) == 0, "open: %s", c ? silc_context_errmsg(c) : silc_errmsg());
    if (!c) goto out;

    for (size_t i = 0; i < (size_t)N * N; i++) dense[i] = (double)(i % 1000) - 500.0;
    CHECK(silc_envelope_dense(&A, N, N, dense) == 0, "dense envelope");
    if (thp) CHECK(util_large_owns(A.values), "the envelope's 8 MiB array is a mapping");
    CHECK(silc_put(c, "A", &A) == 0 && silc_exec(c, "B = A + A") == 0 && silc_get(c, &B, "B") == 0, "B = A + A: %s",
          silc_context_errmsg(c));
    CHECK(B.m == N && B.n == N && B.values, "B is %lld x %lld", (long long)B.m, (long long)B.n);
    if (B.values && B.m == N && B.n == N)
        for (size_t i = 0; i < (size_t)N * N; i++) bad += B.values[i] != 2.0 * dense[i];
    CHECK(bad == 0, "%lld entries of B differ from 2 A", (long long)bad);

    /* S(i,i) = i + 1, S(i,i+-1) = 1: (S * ones)_i = i + 1 + its neighbours */
    for (int64_t i = 0; i < n; i++) {
        rowptr[i] = k;
        if (i > 0) colind[k] = i - 1, vals[k++] = 1.0;
        colind[k] = i, vals[k++] = (double)(i + 1);
        if (i + 1 < n) colind[k] = i + 1, vals[k++] = 1.0;
        ones[i] = 1.0;
    }
    rowptr[n] = k;
    CHECK(silc_envelope_csr(&S, n, n, rowptr, colind, vals) == 0 && silc_envelope_vector(&x, n, ones) == 0,
          "CSR and vector envelopes");
    CHECK(silc_put(c, "S", &S) == 0 && silc_put(c, "x", &x) == 0 && silc_exec(c, "y = S * x") == 0 &&
              silc_get(c, &y, "y") == 0 && silc_get(c, &S2, "S") == 0,
          "y = S * x: %s", silc_context_errmsg(c));
    bad = 0;
    if (y.values && y.m == n)
        for (int64_t i = 0; i < n; i++) bad += y.values[i] != (double)(i + 1) + (i > 0) + (i + 1 < n);
    else
        bad = 1;
    CHECK(bad == 0, "%lld entries of y differ from the exact product", (long long)bad);
    CHECK(S2.nnz == k && S2.rowptr && S2.colind && S2.values &&
              memcmp(S2.rowptr, rowptr, (size_t)(n + 1) * sizeof *rowptr) == 0 &&
              memcmp(S2.colind, colind, (size_t)k * sizeof *colind) == 0 &&
              memcmp(S2.values, vals, (size_t)k * sizeof *vals) == 0,
          "S comes back as it went in");
    /* replacing and clearing values frees their arrays (into the pool, or unmapped) */
    CHECK(silc_exec(c, "A = 1; B = 2; S = 3; y = 4; x = 5") == 0, "values replaced: %s", silc_context_errmsg(c));
out:
    silc_envelope_free(&A), silc_envelope_free(&B), silc_envelope_free(&S);
    silc_envelope_free(&x), silc_envelope_free(&y), silc_envelope_free(&S2);
    CHECK(A.values == NULL && S2.rowptr == NULL, "envelopes zeroed");
    silc_close(&c);
    free(dense), free(vals), free(ones), free(rowptr), free(colind);
}

int main(void)
{
    thp = util_huge_pages_available();
    if (!thp) printf("transparent huge pages unavailable: ownership checks skipped, libc's path checked\n");
    test_alloc(); /* before the pool is installed */
    test_pool();
    test_host_table();
    test_api();
    return check_done();
}
