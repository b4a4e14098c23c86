/*
 * values_mm.c -- Matrix Market files read by the format's rules, one table
 * row per case: the file's text, then either the exact message after the
 * path ("line:column: ...") or the values it must load as.
 *
 * What the rows hold (docs/security.md, docs/reliability.md): integer
 * fields take integers within int64 only (1.5, 1e20 and 0x10 were loaded as
 * 1.5, 1e20 and 16); reals are decimal; overflow to inf, inf and nan are
 * refused unless SILC_MM_ALLOW_NONFINITE=1 (1e400 was inf and nan NaN
 * without a word); `hermitian` on a real field is refused (it was read as
 * symmetric); an entry above the diagonal of a symmetric file is refused
 * (it was mirrored).  A failed read leaves an envelope that PUT refuses.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "silc.h"

typedef struct mm_case {
    const char *text;
    int allow_nonfinite;
    const char *error;        /* exact message after "path:", or NULL */
    int64_t m, n;
    double want[4];           /* column-major, when error is NULL */
} mm_case;

#define HEAD_INT "%%MatrixMarket matrix coordinate integer general\n1 1 1\n"
#define HEAD_REAL "%%MatrixMarket matrix coordinate real general\n1 1 1\n"

static const mm_case cases[] = {
    /* integer fields: integers within int64, nothing else */
    {HEAD_INT "1 1 7\n", 0, NULL, 1, 1, {7}},
    {HEAD_INT "1 1 -9223372036854775808\n", 0, NULL, 1, 1, {-9223372036854775808.0}},
    /* values are doubles: an int64 with no exact double is refused, not rounded */
    {HEAD_INT "1 1 -9223372036854775807\n", 0,
     "3:5: integer value '-9223372036854775807' has no exact double (SILC stores doubles: integers beyond "
     "2^53 = 9007199254740992 only where exact)", 0, 0, {0}},
    {HEAD_INT "1 1 1.5\n", 0, "3:5: integer value '1.5' is not an integer", 0, 0, {0}},
    {HEAD_INT "1 1 1e20\n", 0, "3:5: integer value '1e20' is not an integer", 0, 0, {0}},
    {HEAD_INT "1 1 1e400\n", 0, "3:5: integer value '1e400' is not an integer", 0, 0, {0}},
    {HEAD_INT "1 1 0x10\n", 0, "3:5: integer value '0x10' is not an integer", 0, 0, {0}},
    {HEAD_INT "1 1 99999999999999999999\n", 0,
     "3:5: integer value '99999999999999999999' is outside the 64-bit integers", 0, 0, {0}},
    /* indices are integers too */
    {HEAD_REAL "1.0 1 2\n", 0, "3:1: row index '1.0' is not an integer", 0, 0, {0}},
    {HEAD_REAL "1 0x1 2\n", 0, "3:3: column index '0x1' is not an integer", 0, 0, {0}},
    /* reals: decimal, finite unless asked */
    {HEAD_REAL "1 1 -2.5e-3\n", 0, NULL, 1, 1, {-2.5e-3}},
    {HEAD_REAL "1 1 .5\n", 0, NULL, 1, 1, {0.5}},
    {HEAD_REAL "1 1 0x10\n", 0, "3:5: value '0x10' is not a decimal number", 0, 0, {0}},
    {HEAD_REAL "1 1 1e400\n", 0,
     "3:5: value '1e400' overflows the doubles (set SILC_MM_ALLOW_NONFINITE=1 to accept it as inf)", 0, 0, {0}},
    {HEAD_REAL "1 1 nan\n", 0, "3:5: value 'nan' is not finite (set SILC_MM_ALLOW_NONFINITE=1 to accept it)",
     0, 0, {0}},
    {HEAD_REAL "1 1 -Inf\n", 0, "3:5: value '-Inf' is not finite (set SILC_MM_ALLOW_NONFINITE=1 to accept it)",
     0, 0, {0}},
    {HEAD_REAL "1 1 1e400\n", 1, NULL, 1, 1, {INFINITY}},
    {HEAD_REAL "1 1 -inf\n", 1, NULL, 1, 1, {-INFINITY}},
    {HEAD_REAL "1 1 1 2\n", 0, "3:7: unexpected text after 'row column value'", 0, 0, {0}},
    {"%%MatrixMarket matrix array real general\n1 1\nnan\n", 0,
     "3:1: value 'nan' is not finite (set SILC_MM_ALLOW_NONFINITE=1 to accept it)", 0, 0, {0}},
    {"%%MatrixMarket matrix array integer general\n2 1\n3\n2.5\n", 0,
     "4:1: integer value '2.5' is not an integer", 0, 0, {0}},
    /* symmetry */
    {"%%MatrixMarket matrix coordinate real hermitian\n2 2 1\n2 1 3\n", 0,
     "1: symmetry 'hermitian' needs a complex field, and this file's is 'real' (say symmetric for a real "
     "symmetric matrix)", 0, 0, {0}},
    {"%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 4\n1 2 3\n", 0,
     "4:1: entry (1, 2) is above the diagonal: a symmetric file stores the lower triangle only", 0, 0, {0}},
    {"%%MatrixMarket matrix coordinate real skew-symmetric\n2 2 1\n1 2 3\n", 0,
     "3:1: entry (1, 2) is above the diagonal: a skew-symmetric file stores the lower triangle only", 0, 0, {0}},
    {"%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 4\n2 1 3\n", 0, NULL, 2, 2, {4, 3, 3, 0}},
    /* the size line: integers */
    {"%%MatrixMarket matrix coordinate real general\n2 2.0 1\n", 0, "2:3: column count '2.0' is not an integer",
     0, 0, {0}},
};

int main(void)
{
    char path[512], err[1024], want[1200];
    size_t k;
    snprintf(path, sizeof path, "%s/tests/values_mm.mtx", SILC_BINARY_DIR);
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const mm_case *c = &cases[k];
        silc_envelope_t e;
        FILE *f = fopen(path, "w");
        int rc;
        if (!f || fputs(c->text, f) < 0 || fclose(f)) {
            CHECK(0, "cannot write %s", path);
            return check_done();
        }
        if (c->allow_nonfinite) setenv("SILC_MM_ALLOW_NONFINITE", "1", 1);
        else unsetenv("SILC_MM_ALLOW_NONFINITE");
        rc = silc_mm_read(&e, path, err, sizeof err);
        if (c->error) {
            snprintf(want, sizeof want, "%s:%s", path, c->error);
            CHECK(rc != 0, "case %zu: accepted, want '%s'", k, c->error);
            CHECK(rc == 0 || !strcmp(err, want), "case %zu:\n   got  '%s'\n   want '%s'", k, err, want);
            /* what was not read cannot be PUT (was a 0x0 value) */
            if (rc) {
                silc_context *ctx = NULL;
                char put_want[1400];
                snprintf(put_want, sizeof put_want, "envelope 'M' was not constructed: %s", want);
                CHECK(silc_open(&ctx, NULL) == 0, "open: %s", silc_errmsg());
                CHECK(ctx && silc_put(ctx, "M", &e) != 0 && !strcmp(silc_context_errmsg(ctx), put_want),
                      "case %zu: PUT of the failed read: '%s'", k, ctx ? silc_context_errmsg(ctx) : "");
                silc_close(&ctx);
            }
        } else {
            double got[4] = {0, 0, 0, 0};
            int64_t i;
            CHECK(rc == 0, "case %zu: refused: %s", k, err);
            if (rc == 0) {
                CHECK(e.m == c->m && e.n == c->n, "case %zu: %lldx%lld", k, (long long)e.m, (long long)e.n);
                CHECK(silc_envelope_to_dense(&e, got) == 0, "case %zu: to_dense", k);
                for (i = 0; i < c->m * c->n; i++)
                    CHECK(got[i] == c->want[i], "case %zu: entry %lld is %.17g, want %.17g", k, (long long)i,
                          got[i], c->want[i]);
            }
        }
        silc_envelope_free(&e);
    }
    unsetenv("SILC_MM_ALLOW_NONFINITE");
    remove(path);
    return check_done();
}
