/*
 * test_suitesparse_hooks.c -- plugin-suitesparse and the process-wide
 * SuiteSparse_config allocator hooks (plugin-suitesparse/ss_alloc.c).
 *
 *   test_suitesparse_hooks       the program leaves SuiteSparse_config alone
 *                                (libc's functions)
 *   test_suitesparse_hooks own   the program sets its own hooks first
 *
 * default: SILC's first UMFPACK solve puts the plugin's hooks in
 * SuiteSparse_config; outside a solve they are libc's (a block the program
 * allocates through them is not the large allocator's, and a block malloc'd
 * before they were set is freed through them correctly: AddressSanitizer
 * would report a mismatched free); with suitesparse.huge_pages = auto the
 * solve takes fewer than half the minor page faults it takes with off (its
 * ~40 MB of work space on 2 MiB pages instead of 4 KiB ones; only where the
 * kernel has transparent huge pages); both solves give the same x, which
 * solves A x = b.  own: the program's hooks stay in place through SILC's
 * solves and SuiteSparse allocates through them.  The two cases run as two
 * processes, since the hooks are set once per process.
 *
 * The system is examples/helmholtz's (complex symmetric, 200 x 200
 * vertices), which suitesparse.umfpack solves as UMFPACK_A.
 */
#define _POSIX_C_SOURCE 200809L
#include <complex.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include <SuiteSparse_config.h>

#include "check.h"
#include "helmholtz.h"
#include "silc.h"
#include "util.h"

enum { GRID = 199 }; /* intervals: 200 x 200 vertices */

static long own_calls;

static void *own_malloc(size_t n)
{
    own_calls++;
    return malloc(n);
}
static void *own_calloc(size_t n, size_t s)
{
    own_calls++;
    return calloc(n, s);
}
static void *own_realloc(void *p, size_t n)
{
    own_calls++;
    return realloc(p, n);
}
static void own_free(void *p)
{
    free(p);
}

static long minor_faults(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return u.ru_minflt;
}

/* ||b - A x||_1 / ||b||_1 */
static double residual(const silc_envelope_t *A, const double complex *x, const double complex *b)
{
    const double complex *v = (const double complex *)A->values;
    double r = 0, nb = 0;
    for (int64_t i = 0; i < A->m; i++) {
        double complex s = b[i];
        for (int64_t p = A->rowptr[i]; p < A->rowptr[i + 1]; p++) s -= v[p] * x[A->colind[p]];
        r += cabs(s);
        nb += cabs(b[i]);
    }
    return r / nb;
}

/* x = A \ b by suitesparse.umfpack in a fresh context with
 * suitesparse.huge_pages = huge; the solve's minor faults in *faults. */
static int solve(const silc_envelope_t *A, const double complex *b, const char *huge, double complex *x,
                 long *faults)
{
    silc_envelope_t Eb, Ex;
    silc_context *c = NULL;
    char set[128];
    long f0;
    int rc = -1;
    snprintf(set, sizeof set, "set dispatch.solve.sparse = suitesparse.umfpack; set suitesparse.huge_pages = %s",
             huge);
    if (silc_envelope_dense_complex(&Eb, A->m, 1, (const double *)b) == 0 && silc_open(&c, NULL) == 0 &&
        silc_put(c, "A", A) == 0 && silc_put(c, "b", &Eb) == 0 && silc_exec(c, set) == 0) {
        f0 = minor_faults();
        if (silc_exec(c, "x = A \\ b;") == 0) {
            *faults = minor_faults() - f0;
            if (silc_get_complex(c, &Ex, "x") == 0) {
                rc = silc_envelope_to_dense(&Ex, (double *)x);
                silc_envelope_free(&Ex);
            }
        }
    }
    if (rc) fprintf(stderr, "solve (huge_pages = %s): %s\n", huge, c ? silc_context_errmsg(c) : silc_errmsg());
    if (c) silc_close(&c);
    silc_envelope_free(&Eb);
    return rc;
}

/* A bad value of the option is refused by name. */
static void check_bad_option(const silc_envelope_t *A, const double complex *b)
{
    silc_envelope_t Eb;
    silc_context *c = NULL;
    int rc = -1;
    if (silc_envelope_dense_complex(&Eb, A->m, 1, (const double *)b) == 0 && silc_open(&c, NULL) == 0 &&
        silc_put(c, "A", A) == 0 && silc_put(c, "b", &Eb) == 0 &&
        silc_exec(c, "set dispatch.solve.sparse = suitesparse.umfpack; set suitesparse.huge_pages = maybe") == 0)
        rc = silc_exec(c, "x = A \\ b;");
    CHECK(rc != 0 && c && strstr(silc_context_errmsg(c), "huge_pages") && strstr(silc_context_errmsg(c), "maybe"),
          "a bad huge_pages value is refused by name: '%s'", c ? silc_context_errmsg(c) : "");
    if (c) silc_close(&c);
    silc_envelope_free(&Eb);
}

int main(int argc, char **argv)
{
    int own = argc > 1 && !strcmp(argv[1], "own");
    silc_envelope_t A;
    char err[256];
    long f_auto = 0, f_off = 0;
    int64_t n = (int64_t)(GRID + 1) * (GRID + 1);
    double complex *b = malloc((size_t)n * sizeof *b), *x = malloc((size_t)n * sizeof *x),
                   *y = malloc((size_t)n * sizeof *y);
    void *before = malloc(64);
    if (!b || !x || !y || helmholtz_assemble(GRID, 50, HELMHOLTZ_SOURCE, &A, (double *)b, err, sizeof err)) {
        fprintf(stderr, "setup: %s\n", b && x && y ? err : "out of memory");
        return 1;
    }
    if (own) {
        SuiteSparse_config.malloc_func = own_malloc;
        SuiteSparse_config.calloc_func = own_calloc;
        SuiteSparse_config.realloc_func = own_realloc;
        SuiteSparse_config.free_func = own_free;
    } else {
        CHECK(SuiteSparse_config.malloc_func == malloc, "libc's malloc before any solve");
    }

    /* the first solve also loads the plugin and its libraries: not counted */
    CHECK(solve(&A, b, "off", y, &f_off) == 0, "solve with huge_pages = off");
    CHECK(solve(&A, b, "auto", x, &f_auto) == 0, "solve with huge_pages = auto");
    CHECK(solve(&A, b, "off", y, &f_off) == 0, "solve with huge_pages = off, again");
    CHECK(residual(&A, x, b) < 1e-10, "x solves A x = b: residual %.3g", residual(&A, x, b));
    CHECK(memcmp(x, y, (size_t)n * sizeof *x) == 0, "the allocator changes no bit of x");
    check_bad_option(&A, b);

    if (own) {
        CHECK(SuiteSparse_config.malloc_func == own_malloc && SuiteSparse_config.calloc_func == own_calloc &&
                  SuiteSparse_config.realloc_func == own_realloc && SuiteSparse_config.free_func == own_free,
              "the program's own hooks are kept");
        CHECK(own_calls > 10, "SuiteSparse allocated through the program's hooks (%ld calls)", own_calls);
    } else {
        void *p;
        CHECK(SuiteSparse_config.malloc_func != malloc && SuiteSparse_config.free_func != free,
              "the plugin's hooks are set by the first solve");
        p = SuiteSparse_config.malloc_func(8u << 20);
        CHECK(p && !util_large_owns(p), "outside a solve the hooks are libc's malloc");
        SuiteSparse_config.free_func(p);
        SuiteSparse_config.free_func(before); /* from before the hooks: libc's free */
        before = NULL;
        if (util_huge_pages_available())
            CHECK(f_auto * 2 < f_off, "huge pages: %ld minor faults, against %ld with huge_pages = off", f_auto,
                  f_off);
        else
            printf("transparent huge pages unavailable: fault counts not compared (%ld, %ld)\n", f_auto, f_off);
    }
    free(before);
    silc_envelope_free(&A);
    free(b);
    free(x);
    free(y);
    return check_done();
}
