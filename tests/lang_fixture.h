/*
 * lang_fixture.h -- the operands the language tests run on (test_lang.c),
 * shared by the tests that run the same statements another way
 * (test_oom.c): dense v w r idx s M A D L, CSR S, band B.
 */
#ifndef SILC_LANG_FIXTURE_H
#define SILC_LANG_FIXTURE_H

#include <silc.h>
#include <stdint.h>

static int lang_fixture_dense(silc_context *c, const char *name, int64_t m, int64_t n,
                              const double *x)
{
    silc_envelope_t e;
    int rc = silc_envelope_dense(&e, m, n, x) || silc_put(c, name, &e);
    silc_envelope_free(&e);
    return rc;
}

/* Puts the operands into c; 0, or -1 with the context's message. */
static int lang_fixture_put(silc_context *c)
{
    static const double v[] = {1, 2, 3}, w[] = {4, 5, 6}, idx[] = {1, 3}, s = 5;
    static const double M[] = {1, 3, 2, 4};
    static const double A[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    static const double D[] = {2, 0, 0, 0, 4, 0, 0, 0, 8};
    static const double L[] = {2, 1, 0, 0, 1, 1, 0, 0, 4};
    static const int64_t Sp[] = {0, 2, 5, 7}, Si[] = {0, 1, 0, 1, 2, 1, 2};
    static const double Sv[] = {4, 1, 1, 4, 1, 1, 4};
    /* band storage, ld = 3: rows are superdiagonal, diagonal, subdiagonal */
    static const double Bb[] = {0, 2, -1, -1, 2, -1, -1, 2, 0};
    silc_envelope_t e;
    int rc = lang_fixture_dense(c, "v", 3, 1, v) || lang_fixture_dense(c, "w", 3, 1, w) ||
             lang_fixture_dense(c, "r", 1, 3, v) || lang_fixture_dense(c, "idx", 2, 1, idx) ||
             lang_fixture_dense(c, "s", 1, 1, &s) || lang_fixture_dense(c, "M", 2, 2, M) ||
             lang_fixture_dense(c, "A", 3, 4, A) || lang_fixture_dense(c, "D", 3, 3, D) ||
             lang_fixture_dense(c, "L", 3, 3, L);
    if (!rc) {
        rc = silc_envelope_csr(&e, 3, 3, Sp, Si, Sv) || silc_put(c, "S", &e);
        silc_envelope_free(&e);
    }
    if (!rc) {
        rc = silc_envelope_band(&e, 3, 3, 1, 1, Bb) || silc_put(c, "B", &e);
        silc_envelope_free(&e);
    }
    return rc ? -1 : 0;
}

#endif
