/*
 * values_put.c -- envelopes a program hands to silc_put that lie about
 * themselves, embedded and against a silcd of its own on a Unix socket in
 * the build directory (docs/security.md, "Values handed to SILC").
 *
 * Each case PUTs a bad envelope under a name that already holds a known
 * 3x3 CSR matrix, and asserts the exact refusal and that the name still
 * holds that matrix, bit for bit (GET compared with the arrays that built
 * it).  The remote client checks before it sends, so its messages are the
 * embedded ones; what only the server can refuse (a claim over its
 * --max-value-bytes) is asserted with the server's message.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "remote_util.h"
#include "silc.h"

static const int64_t good_rp[4] = {0, 2, 3, 5}, good_ci[5] = {0, 2, 1, 0, 2};
static const double good_x[5] = {4, 1, 5, 1, 6};

/* The name A holds exactly the good matrix. */
static int holds_good(silc_context *ctx)
{
    silc_envelope_t g;
    int same;
    if (silc_get(ctx, &g, "A")) return 0;
    same = g.format == SILC_CSR && g.m == 3 && g.n == 3 && g.nnz == 5 &&
           !memcmp(g.rowptr, good_rp, sizeof good_rp) && !memcmp(g.colind, good_ci, sizeof good_ci) &&
           !memcmp(g.values, good_x, sizeof good_x);
    silc_envelope_free(&g);
    return same;
}

/* A hand-filled CSR envelope over the caller's arrays. */
static silc_envelope_t hand_csr(int64_t m, int64_t n, int64_t nnz, int64_t *rp, int64_t *ci, double *x)
{
    silc_envelope_t e;
    memset(&e, 0, sizeof e);
    e.format = SILC_CSR, e.m = m, e.n = n, e.nnz = nnz, e.rowptr = rp, e.colind = ci, e.values = x;
    return e;
}

/* PUT e to A must fail with exactly want, and A keep the good matrix. */
static void refused(silc_context *ctx, const char *mode, const silc_envelope_t *e, const char *want,
                    const char *what)
{
    const char *got;
    CHECK(silc_put(ctx, "A", e) != 0, "%s: %s: accepted", mode, what);
    got = silc_context_errmsg(ctx);
    CHECK(!strcmp(got, want), "%s: %s:\n   got  '%s'\n   want '%s'", mode, what, got, want);
    CHECK(holds_good(ctx), "%s: %s: A changed by a refused PUT", mode, what);
}

/* The cases every context must refuse alike. */
static void envelope_cases(silc_context *ctx, const char *mode)
{
    silc_envelope_t good, e;
    int64_t rp[5] = {0, 2, 3, 5, 0}, ci[5] = {0, 2, 1, 0, 2}, bad_rp0[4] = {1, 2, 3, 5};
    double x[5] = {4, 1, 5, 1, 6}, one = 1;
    static const char band_2_40[] = "'A': a 1099511627776x1 band value needs 8796093022224 bytes (8.0 TiB), "
                                    "over the limit of ";
    CHECK(silc_envelope_csr(&good, 3, 3, good_rp, good_ci, good_x) == 0, "%s: good CSR: %s", mode,
          silc_errmsg());
    CHECK(silc_put(ctx, "A", &good) == 0, "%s: good PUT: %s", mode, silc_context_errmsg(ctx));
    silc_envelope_free(&good);
    CHECK(holds_good(ctx), "%s: A does not hold what was PUT", mode);

    /* rowptr[m] beyond the entries the envelope has: was a SIGSEGV. */
    rp[3] = 1000000;
    e = hand_csr(3, 3, 5, rp, ci, x);
    refused(ctx, mode, &e, "'A': rowptr[m] = 1000000 but the value has 5 entries (nnz): m or rowptr is wrong",
            "rowptr[m] > nnz");
    rp[3] = 5;
    /* nnz saying fewer entries than rowptr[m]. */
    e = hand_csr(3, 3, 2, rp, ci, x);
    refused(ctx, mode, &e, "'A': rowptr[m] = 5 but the value has 2 entries (nnz): m or rowptr is wrong",
            "nnz < rowptr[m]");
    /* A row count too small, and one too large (rowptr[4] is 0 here, as
     * whatever follows an array in memory may be). */
    e = hand_csr(2, 3, 5, rp, ci, x);
    refused(ctx, mode, &e, "'A': rowptr[m] = 3 but the value has 5 entries (nnz): m or rowptr is wrong",
            "m too small");
    e = hand_csr(4, 3, 5, rp, ci, x);
    refused(ctx, mode, &e, "'A': rowptr decreases at row 3 (rowptr[3] = 5 > rowptr[4] = 0)", "m too large");
    rp[4] = (int64_t)1 << 40;
    e = hand_csr(4, 3, 5, rp, ci, x);
    refused(ctx, mode, &e,
            "'A': rowptr[m] = 1099511627776 but the value has 5 entries (nnz): m or rowptr is wrong",
            "m too large, garbage after rowptr");
    /* A negative entry count and an overflowing one. */
    e = hand_csr(3, 3, -1, rp, ci, x);
    refused(ctx, mode, &e, "'A': a 3x3 csr value cannot have -1 entries", "negative nnz");
    e = hand_csr(3, 3, INT64_MAX / 8, rp, ci, x);
    refused(ctx, mode, &e, "'A': a 3x3 csr value cannot have 1152921504606846975 entries", "huge nnz");
    /* Dense with an m*n that overflows. */
    memset(&e, 0, sizeof e);
    e.format = SILC_DENSE, e.m = (int64_t)1 << 40, e.n = (int64_t)1 << 40, e.values = x;
    refused(ctx, mode, &e, "'A': invalid size 1099511627776x1099511627776: m*n overflows", "dense overflow");

    /* Envelopes whose construction failed: were PUT as 0x0 values. */
    CHECK(silc_envelope_csr(&e, 3, 3, bad_rp0, ci, x) != 0, "%s: rowptr[0] = 1 constructed", mode);
    refused(ctx, mode, &e, "envelope 'A' was not constructed: silc_envelope_csr: rowptr[0] is 1, must be 0",
            "failed CSR constructor");
    CHECK(silc_envelope_dense(&e, -1, 2, NULL) != 0, "%s: -1x2 constructed", mode);
    refused(ctx, mode, &e, "envelope 'A' was not constructed: silc_envelope_dense: invalid size -1x2",
            "failed dense constructor");
    silc_envelope_free(&e);

    /* A band value of 2^40 rows and one stored entry: its rows are charged
     * (its norms sum by row), 8 TiB over any machine this runs on. */
    CHECK(silc_envelope_band(&e, (int64_t)1 << 40, 1, 0, 0, &one) == 0, "%s: band envelope: %s", mode,
          silc_errmsg());
    CHECK(silc_put(ctx, "A", &e) != 0 &&
              !strncmp(silc_context_errmsg(ctx), band_2_40, strlen(band_2_40)),
          "%s: 2^40 x 1 band: %s", mode, silc_context_errmsg(ctx));
    CHECK(holds_good(ctx), "%s: 2^40 band: A changed", mode);
    silc_envelope_free(&e);
}

int main(void)
{
    silc_context *ctx = NULL;
    test_server srv;
    char listen[300], sock[250];
    const char *opts[] = {"--max-value-bytes", "64M", "--max-session-bytes", "64M", NULL};
    silc_envelope_t band;
    double one = 1;

    CHECK(silc_open(&ctx, NULL) == 0, "embedded open: %s", silc_errmsg());
    if (ctx) envelope_cases(ctx, "embedded");
    silc_close(&ctx);

    snprintf(sock, sizeof sock, "%s/tests/values_put.sock", SILC_BINARY_DIR);
    remove(sock);
    snprintf(listen, sizeof listen, "unix:%s", sock);
    if (server_start(&srv, listen, opts) != 0) {
        CHECK(0, "silcd did not start");
        return check_done();
    }
    CHECK(silc_open_remote(&ctx, listen) == 0, "remote open: %s", silc_errmsg());
    if (ctx) {
        envelope_cases(ctx, "remote");
        /* 250 000 000 x 1 band, one stored entry: 8 bytes on the wire, but
         * its rows cost 2 GB the first time its norms are asked for (the
         * session reached 1.9 GB under a 64 MiB limit).  Refused from the
         * descriptor. */
        CHECK(silc_envelope_band(&band, 250000000, 1, 0, 0, &one) == 0, "band 250e6: %s", silc_errmsg());
        CHECK(silc_put(ctx, "A", &band) != 0, "remote: 250e6 x 1 band accepted under 64 MiB");
        CHECK(!strcmp(silc_context_errmsg(ctx),
                      "'A': a 250000000x1 band value needs 2000000016 bytes (1.9 GiB), over the limit of "
                      "67108864 bytes (64.0 MiB) by 1.8 GiB: the most one value may hold "
                      "(silcd --max-value-bytes)"),
              "remote: 250e6 x 1 band: %s", silc_context_errmsg(ctx));
        CHECK(holds_good(ctx), "remote: 250e6 band: A changed");
        /* The claim's point: the session process never came near the
         * 2 GB.  Its peak resident set (VmHWM, from its start: plugins,
         * the good A, the refusal) stays under an eighth of the claim. */
        {
            pid_t session = only_child_of(srv.pid);
            long long hwm = session > 0 ? proc_status_bytes(session, "VmHWM:") : -1;
            CHECK(hwm > 0, "remote: cannot read the session process's VmHWM (pid %ld)", (long)session);
            CHECK(hwm < 2000000016LL / 8, "remote: the session's peak RSS reached %lld bytes for a refused "
                  "2000000016-byte band claim", hwm);
            printf("session process %ld: VmHWM %.1f MiB after the refused 1.9 GiB band claim\n", (long)session,
                   hwm / 1048576.0);
        }
        silc_envelope_free(&band);
        silc_close(&ctx);
    }
    CHECK(server_stop(&srv) == 0, "silcd did not stop cleanly");
    remove(sock);
    return check_done();
}
