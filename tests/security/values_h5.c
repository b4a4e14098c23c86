/*
 * values_h5.c -- crafted HDF5 files handed to `load` (docs/security.md,
 * "Values handed to SILC").  Every file is written here with the HDF5 C
 * API, in the build directory, under a value limit of 64 MiB set for this
 * process as silcd's --max-value-bytes sets it.
 *
 * Each case asserts the exact refusal, that the name it asked for is not
 * bound and that A, bound before, still holds its value.  The cases: a
 * dataset with external storage pointing at a canary file (whose bytes must
 * not come back), a virtual dataset, an external link (at the top and
 * inside a CSR group), a CSR group whose indptr ends past its data, float
 * indices (0.9 was truncated to 0), a band claim of 2^40 rows with one
 * stored entry, and a CSR claim of 40 M entries written as unallocated
 * chunks (the file is small, the claim is 640 MB) whose refusal must come
 * before anything is read: peak RSS may not grow by more than 32 MiB.  A
 * well-formed CSR group loads bit for bit, so the refusals are not a
 * blanket one.
 *
 * Against a silcd of its own (--data-dir, a Unix socket in the build
 * directory, --max-session-bytes 12M), a load is checked against what the
 * session has left from the files' shapes, summed over everything it would
 * bind, before anything is read: two 8 MB values in one file are refused
 * together (nothing bound, the session process's peak RSS grown by less
 * than reading either would cost), one of them alone loads and holds its fill value exactly, and
 * then the other is refused beside it.
 */
#define _POSIX_C_SOURCE 200809L
#include <hdf5.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "silc.h"
#include "store.h"

static char dir[400];

#ifdef SILCD_PATH
#include "remote_util.h"
#endif

/* The process's peak resident set (VmHWM), in bytes. */
static long long peak_rss(void)
{
    char line[256];
    long long kb = -1;
    FILE *f = fopen("/proc/self/status", "r");
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "VmHWM:", 6)) kb = atoll(line + 6);
    if (f) fclose(f);
    return kb * 1024;
}

static hid_t dataset(hid_t loc, const char *name, hid_t type, hid_t mem, hsize_t n, const void *data)
{
    hid_t sp = H5Screate_simple(1, &n, NULL);
    hid_t d = H5Dcreate2(loc, name, type, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (data) H5Dwrite(d, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    H5Sclose(sp);
    return d;
}

static void attr_i64(hid_t obj, const char *name, const int64_t *v, hsize_t n)
{
    hid_t sp = H5Screate_simple(1, &n, NULL);
    hid_t a = H5Acreate2(obj, name, H5T_STD_I64LE, sp, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, H5T_NATIVE_INT64, v);
    H5Aclose(a);
    H5Sclose(sp);
}

static void attr_str(hid_t obj, const char *name, const char *text)
{
    hid_t t = H5Tcopy(H5T_C_S1), sp = H5Screate(H5S_SCALAR), a;
    H5Tset_size(t, strlen(text) + 1);
    a = H5Acreate2(obj, name, t, sp, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, t, text);
    H5Aclose(a);
    H5Sclose(sp);
    H5Tclose(t);
}

/* A CSR group: data and indices of nnz entries (indices as float64 when
 * float_indices), indptr of m+1, shape (m, n). */
static void csr_group(hid_t file, const char *name, int64_t m, int64_t n, const double *data,
                      const void *indices, int float_indices, hsize_t nnz, const int64_t *indptr)
{
    hid_t g = H5Gcreate2(file, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int64_t shape[2] = {m, n};
    H5Dclose(dataset(g, "data", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, nnz, data));
    if (float_indices) H5Dclose(dataset(g, "indices", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, nnz, indices));
    else H5Dclose(dataset(g, "indices", H5T_STD_I64LE, H5T_NATIVE_INT64, nnz, indices));
    H5Dclose(dataset(g, "indptr", H5T_STD_I64LE, H5T_NATIVE_INT64, (hsize_t)m + 1, indptr));
    attr_i64(g, "shape", shape, 2);
    H5Gclose(g);
}

/* A holds [1 3; 2 4] exactly. */
static int a_intact(silc_context *ctx)
{
    static const double want[4] = {1, 2, 3, 4};
    silc_envelope_t e;
    int ok;
    if (silc_get(ctx, &e, "A")) return 0;
    ok = e.format == SILC_DENSE && e.m == 2 && e.n == 2 && !memcmp(e.values, want, sizeof want);
    silc_envelope_free(&e);
    return ok;
}

static int bound(silc_context *ctx, const char *name)
{
    silc_envelope_t e;
    int rc = silc_get(ctx, &e, name);
    silc_envelope_free(&e);
    return rc == 0;
}

/* load names from path must fail with exactly "load: <what> in '<path>'<rest>". */
static void refused(silc_context *ctx, const char *path, const char *names, const char *what, const char *rest,
                    const char *absent)
{
    char want[1200];
    const char *got;
    snprintf(want, sizeof want, "load: %s in '%s'%s", what, path, rest);
    CHECK(silc_load(ctx, path, names) != 0, "%s: loaded", what);
    got = silc_context_errmsg(ctx);
    CHECK(!strcmp(got, want), "%s:\n   got  '%s'\n   want '%s'", what, got, want);
    CHECK(!strstr(got, "0x"), "%s: the message shows an address: %s", what, got);
    CHECK(a_intact(ctx), "%s: A changed by a refused load", what);
    CHECK(!bound(ctx, absent), "%s: '%s' was bound", what, absent);
}

#ifdef SILCD_PATH
/* A 1000 x 1000 dense dataset of unallocated chunks whose fill value is
 * 0.5: 8 MB to load, a few hundred bytes in the file. */
static void filled_dense(hid_t file, const char *name)
{
    hsize_t dims[2] = {1000, 1000}, chunk[2] = {100, 100};
    double half = 0.5;
    hid_t sp = H5Screate_simple(2, dims, NULL), dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(dcpl, 2, chunk);
    H5Pset_fill_value(dcpl, H5T_NATIVE_DOUBLE, &half);
    H5Dclose(H5Dcreate2(file, name, H5T_IEEE_F64LE, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT));
    H5Pclose(dcpl);
    H5Sclose(sp);
}

static void session_budget_cases(void)
{
    static const char two_refused[] =
        "session memory limit exceeded: load: 'two.h5': its 2 values (16000000 bytes) would bring the values held "
        "at once (bound and temporary) to 16000000 bytes (15.3 MiB), over the limit of 12582912 bytes (12.0 MiB) "
        "by 3.3 MiB (the session's limit, silcd --max-session-bytes); the whole request was rolled back";
    static const char q_refused[] =
        "session memory limit exceeded: load: 'two.h5': 'Q' (8000000 bytes) would bring the values held at once "
        "(bound and temporary) to 16000008 bytes (15.3 MiB), over the limit of 12582912 bytes (12.0 MiB) by "
        "3.3 MiB (the session's limit, silcd --max-session-bytes); the whole request was rolled back";
    char data[300], file_path[320], sock[250], listen[300];
    const char *opts[] = {"--max-session-bytes", "12M", "--data-dir", data, "--shared-data-dir", NULL};
    silc_context *ctx = NULL;
    test_server srv;
    silc_envelope_t e;
    pid_t session;
    long long before, after;
    hid_t file;

    snprintf(data, sizeof data, "%s/tests/values_h5_data", SILC_BINARY_DIR);
    snprintf(file_path, sizeof file_path, "%s/two.h5", data);
    snprintf(sock, sizeof sock, "%s/tests/values_h5.sock", SILC_BINARY_DIR);
    snprintf(listen, sizeof listen, "unix:%s", sock);
    {
        char cmd[900];
        snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -m 700 '%s'", data, data);
        CHECK(system(cmd) == 0, "cannot make %s", data);
    }
    file = H5Fcreate(file_path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    filled_dense(file, "P");
    filled_dense(file, "Q");
    H5Fclose(file);
    remove(sock);
    if (server_start(&srv, listen, opts) != 0) {
        CHECK(0, "silcd did not start");
        return;
    }
    CHECK(silc_open_remote(&ctx, listen) == 0, "remote open: %s", silc_errmsg());
    if (!ctx) {
        server_stop(&srv);
        return;
    }
    session = only_child_of(srv.pid);
    before = session > 0 ? proc_status_bytes(session, "VmHWM:") : -1;
    CHECK(before > 0, "cannot read the session process's VmHWM");

    /* Both: 16 MB from the shapes, over 12 MiB: refused before reading. */
    CHECK(silc_exec(ctx, "load \"two.h5\"") != 0, "two 8 MB values loaded under a 12 MiB session limit");
    CHECK(!strcmp(silc_context_errmsg(ctx), two_refused), "load of both:\n   got  '%s'\n   want '%s'",
          silc_context_errmsg(ctx), two_refused);
    CHECK(!bound(ctx, "P") && !bound(ctx, "Q"), "a refused load bound something");
    /* Reading even one of them costs 16 MB (the value, and the row-major
     * buffer it is read through); the refusal costs a few (HDF5's file
     * handle; more under AddressSanitizer, whose allocator keeps its own). */
    after = proc_status_bytes(session, "VmHWM:");
    CHECK(after - before < (12LL << 20), "the session's peak RSS grew by %lld bytes refusing the load",
          after - before);
    printf("refusing the load grew the session's peak RSS by %.1f MiB\n", (after - before) / 1048576.0);

    /* One fits, and holds its fill value exactly. */
    CHECK(silc_exec(ctx, "load \"two.h5\" P; s = sum(sum(P))") == 0, "load of P alone: %s",
          silc_context_errmsg(ctx));
    CHECK(silc_get(ctx, &e, "s") == 0 && e.m == 1 && e.n == 1 && e.values[0] == 500000.0,
          "sum(sum(P)) is not 1e6 * 0.5");
    silc_envelope_free(&e);

    /* Beside it, the other is over: refused, P and s kept. */
    CHECK(silc_exec(ctx, "load \"two.h5\" Q") != 0, "Q loaded beside P under a 12 MiB session limit");
    CHECK(!strcmp(silc_context_errmsg(ctx), q_refused), "load of Q:\n   got  '%s'\n   want '%s'",
          silc_context_errmsg(ctx), q_refused);
    CHECK(!bound(ctx, "Q") && bound(ctx, "P") && bound(ctx, "s"), "the refused load of Q changed the names");
    silc_close(&ctx);
    CHECK(server_stop(&srv) == 0, "silcd did not stop cleanly");
    remove(sock);
    {
        char cmd[900];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", data);
        CHECK(system(cmd) == 0, "cannot remove %s", data);
    }
}
#endif

int main(void)
{
    static const char canary_text[64] = "CANARY-5f3a: these bytes belong to another file, not to SILC!";
    char path[600], canary[600], src[600];
    silc_context *ctx = NULL;
    silc_envelope_t a;
    const double a_vals[4] = {1, 2, 3, 4};
    hid_t file, sp, dcpl, d;
    FILE *f;

    snprintf(dir, sizeof dir, "%s/tests", SILC_BINARY_DIR);
    snprintf(path, sizeof path, "%s/values_h5.h5", dir);
    snprintf(canary, sizeof canary, "%s/values_h5.canary", dir);
    snprintf(src, sizeof src, "%s/values_h5_src.h5", dir);
    val_set_max_bytes((uint64_t)64 << 20, "the test's 64 MiB limit");

    /* The canary, and a second file for links and virtual mappings. */
    f = fopen(canary, "wb");
    CHECK(f && fwrite(canary_text, 1, sizeof canary_text, f) == sizeof canary_text && fclose(f) == 0,
          "cannot write the canary");
    file = H5Fcreate(src, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    {
        double s[4] = {7, 7, 7, 7};
        H5Dclose(dataset(file, "S", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 4, s));
    }
    H5Fclose(file);

    file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    /* X: 8 doubles whose raw data is the canary file */
    {
        hsize_t n = 8;
        dcpl = H5Pcreate(H5P_DATASET_CREATE);
        H5Pset_external(dcpl, canary, 0, sizeof canary_text);
        sp = H5Screate_simple(1, &n, NULL);
        H5Dclose(H5Dcreate2(file, "X", H5T_IEEE_F64LE, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT));
        H5Sclose(sp);
        H5Pclose(dcpl);
    }
    /* V: virtual, mapped from src:/S */
    {
        hsize_t n = 4;
        hid_t srcsp;
        sp = H5Screate_simple(1, &n, NULL);
        srcsp = H5Screate_simple(1, &n, NULL);
        dcpl = H5Pcreate(H5P_DATASET_CREATE);
        H5Pset_virtual(dcpl, sp, src, "/S", srcsp);
        H5Dclose(H5Dcreate2(file, "V", H5T_IEEE_F64LE, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT));
        H5Pclose(dcpl);
        H5Sclose(srcsp);
        H5Sclose(sp);
    }
    /* L: an external link to src:/S; E: a CSR group whose data is one */
    H5Lcreate_external(src, "/S", file, "L", H5P_DEFAULT, H5P_DEFAULT);
    {
        hid_t g = H5Gcreate2(file, "E", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        int64_t shape[2] = {1, 4}, ip[2] = {0, 4}, ci[4] = {0, 1, 2, 3};
        H5Lcreate_external(src, "/S", g, "data", H5P_DEFAULT, H5P_DEFAULT);
        H5Dclose(dataset(g, "indices", H5T_STD_I64LE, H5T_NATIVE_INT64, 4, ci));
        H5Dclose(dataset(g, "indptr", H5T_STD_I64LE, H5T_NATIVE_INT64, 2, ip));
        attr_i64(g, "shape", shape, 2);
        H5Gclose(g);
    }
    /* C: a 64 x 2^62 CSR group whose indptr ends at 1000 over 3 entries
     * (was read past its buffer and bound 64 x 4611686018427387904 of heap) */
    {
        static int64_t ip[65];
        int64_t ci[3] = {0, 1, 2}, k;
        double x[3] = {1, 2, 3};
        for (k = 0; k <= 64; k++) ip[k] = k < 3 ? k : 3;
        ip[64] = 1000;
        csr_group(file, "C", 64, (int64_t)1 << 62, x, ci, 0, 3, ip);
    }
    /* F: float indices, 0.9 among them (was truncated to 0) */
    {
        int64_t ip[3] = {0, 1, 2};
        double ci[2] = {0.9, 1}, x[2] = {1, 2};
        csr_group(file, "F", 2, 2, x, ci, 1, 2, ip);
    }
    /* B: a band claim of 2^40 x 1, one stored entry */
    {
        hsize_t dims[2] = {1, 1};
        int64_t kl = 0, ku = 0, shape[2] = {(int64_t)1 << 40, 1};
        double one = 1;
        sp = H5Screate_simple(2, dims, NULL);
        d = H5Dcreate2(file, "B", H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, &one);
        attr_str(d, "silc-format", "band");
        attr_i64(d, "kl", &kl, 1);
        attr_i64(d, "ku", &ku, 1);
        attr_i64(d, "shape", shape, 2);
        H5Dclose(d);
        H5Sclose(sp);
    }
    /* Big: 1 x 40 000 000 CSR whose data and indices are unallocated chunks */
    {
        hsize_t n = 40000000, chunk = 1 << 16;
        int64_t shape[2] = {1, 40000000}, ip[2] = {0, 40000000};
        hid_t g = H5Gcreate2(file, "Big", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        dcpl = H5Pcreate(H5P_DATASET_CREATE);
        H5Pset_chunk(dcpl, 1, &chunk);
        sp = H5Screate_simple(1, &n, NULL);
        H5Dclose(H5Dcreate2(g, "data", H5T_IEEE_F64LE, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT));
        H5Dclose(H5Dcreate2(g, "indices", H5T_STD_I64LE, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT));
        H5Sclose(sp);
        H5Pclose(dcpl);
        H5Dclose(dataset(g, "indptr", H5T_STD_I64LE, H5T_NATIVE_INT64, 2, ip));
        attr_i64(g, "shape", shape, 2);
        H5Gclose(g);
    }
    /* D: a 99 999 x 99 999 dense dataset of unallocated chunks (80 GB to
     * load, a few KB in the file): the dense claim, as the CSR and band ones
     * (not 100 000: "100000x1..." would hold the "0x" the address check
     * looks for) */
    {
        hsize_t dims[2] = {99999, 99999}, chunk[2] = {100, 100};
        dcpl = H5Pcreate(H5P_DATASET_CREATE);
        H5Pset_chunk(dcpl, 2, chunk);
        sp = H5Screate_simple(2, dims, NULL);
        H5Dclose(H5Dcreate2(file, "D", H5T_IEEE_F64LE, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT));
        H5Sclose(sp);
        H5Pclose(dcpl);
    }
    /* G: a well-formed 2 x 3 CSR group */
    {
        int64_t ip[3] = {0, 2, 3}, ci[3] = {0, 2, 1};
        double x[3] = {1.5, -2, 1e-300};
        csr_group(file, "G", 2, 3, x, ci, 0, 3, ip);
    }
    H5Fclose(file);

    CHECK(silc_open(&ctx, NULL) == 0, "open: %s", silc_errmsg());
    if (!ctx) return check_done();
    CHECK(silc_envelope_dense(&a, 2, 2, a_vals) == 0 && silc_put(ctx, "A", &a) == 0, "PUT A: %s",
          silc_context_errmsg(ctx));
    silc_envelope_free(&a);

    refused(ctx, path, "X", "'X'", " has external storage (its raw data lives in another file): refused", "X");
    CHECK(!strstr(silc_context_errmsg(ctx), "CANARY"), "the canary's bytes came back");
    refused(ctx, path, "V", "'V'", " is a virtual dataset (mapped from other datasets or files): refused", "V");
    refused(ctx, path, "L", "'L'", " is an external link (to an object of another file): refused", "L");
    refused(ctx, path, "E", "'E/data'", " is an external link (to an object of another file): refused", "E");
    refused(ctx, path, "G X", "'X'", " has external storage (its raw data lives in another file): refused", "G");
    refused(ctx, path, "C", "'C'", ": rowptr[m] = 1000 but the value has 3 entries (nnz): m or rowptr is wrong", "C");
    refused(ctx, path, "F", "'F/indices'",
            " is not an integer dataset: indices must be integers (a float index would be truncated)", "F");
    refused(ctx, path, "B", "'B'",
            ": a 1099511627776x1 band value needs 8796093022224 bytes (8.0 TiB), over the limit of 67108864 "
            "bytes (64.0 MiB) by 8.0 TiB: the most one value may hold (the test's 64 MiB limit)", "B");
    {
        long long before = peak_rss();
        refused(ctx, path, "Big", "'Big'",
                ": a 1x40000000 csr value of 40000000 entries needs 640000016 bytes (610.4 MiB), over the "
                "limit of 67108864 bytes (64.0 MiB) by 546.4 MiB: the most one value may hold (the test's "
                "64 MiB limit)", "Big");
        CHECK(peak_rss() - before < (32LL << 20), "peak RSS grew by %lld bytes refusing a 40M-entry claim",
              peak_rss() - before);
        before = peak_rss();
        refused(ctx, path, "D", "'D'",
                ": a 99999x99999 dense value needs 79998400008 bytes (74.5 GiB), over the limit of 67108864 "
                "bytes (64.0 MiB) by 74.4 GiB: the most one value may hold (the test's 64 MiB limit)", "D");
        CHECK(peak_rss() - before < (32LL << 20), "peak RSS grew by %lld bytes refusing an 80 GB dense claim",
              peak_rss() - before);
    }
    /* The whole file: the first object refused names itself, nothing bound. */
    CHECK(silc_load(ctx, path, NULL) != 0, "the whole crafted file loaded");
    CHECK(a_intact(ctx) && !bound(ctx, "G"), "a failed load of everything bound something");

    /* The control: G loads exactly. */
    CHECK(silc_load(ctx, path, "G") == 0, "G refused: %s", silc_context_errmsg(ctx));
    {
        silc_envelope_t g;
        const int64_t rp[3] = {0, 2, 3}, ci[3] = {0, 2, 1};
        const double x[3] = {1.5, -2, 1e-300};
        CHECK(silc_get(ctx, &g, "G") == 0 && g.format == SILC_CSR && g.m == 2 && g.n == 3 && g.nnz == 3 &&
                  !memcmp(g.rowptr, rp, sizeof rp) && !memcmp(g.colind, ci, sizeof ci) &&
                  !memcmp(g.values, x, sizeof x),
              "G not loaded bit for bit");
        silc_envelope_free(&g);
    }
    silc_close(&ctx);
    remove(path);
    remove(src);
    remove(canary);
#ifdef SILCD_PATH
    session_budget_cases();
#endif
    return check_done();
}
