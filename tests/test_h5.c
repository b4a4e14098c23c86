/*
 * test_h5.c -- save / load in HDF5 (core/lang/h5io.c) through the API
 * (silc_save, silc_load) and the statements: every value kind comes back
 * bit for bit (dense, vector, scalar, empty, CSR, band; real and complex); names choose what
 * is saved and loaded; and every failure is a message that names what is
 * wrong, with nothing changed: a missing file, an unreadable one, a file
 * that is not HDF5 (each with its reason), an object that is not a SILC
 * layout asked for by name, a name the file lacks, an undefined name to
 * save (the old file stays); a load of the whole file skips another
 * program's objects and names them in a warning.
 * tests/test_h5.py checks the files against h5py and scipy.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "testlib.h"

static silc_context *c;
static char path[256], other[256];

/* x's entries, column-major (m x n); NULL on failure. */
static double *entries(const char *name, int64_t *m, int64_t *n)
{
    return tl_get_dense(c, name, m, n);
}

/* Names a and b hold the same shape and entries (formats: test_round_trip). */
static int same(const char *a, const char *b)
{
    double *x, *y;
    int64_t m1 = -1, n1 = -1, m2 = -2, n2 = -2, k;
    int ok;
    x = entries(a, &m1, &n1), y = entries(b, &m2, &n2);
    ok = x && y && m1 == m2 && n1 == n2;
    for (k = 0; ok && k < m1 * n1; k++) ok = x[k] == y[k];
    free(x), free(y);
    return ok;
}

static void test_round_trip(void)
{
    static const char *const kinds[] = {"D", "v", "s", "E", "S", "B", NULL};
    const char *fmt;
    int k;
    CHECK(silc_exec(c, "D = [1, 2, 3; 4, 5, 6.5]; v = [1e-300; -2; 3e300]; s = 7; E = zeros(0, 3); "
                       "S = sparse([1; 3; 2; 3], [1; 1; 2; 3], [1.5; -2; 3; 4], 3, 4); "
                       "B = band(sparse([1; 2; 2; 3], [1; 1; 2; 3], [1; 2; 3; 4], 3, 3), 1, 0)") == 0,
          "values: %s", silc_context_errmsg(c));
    CHECK(silc_exec(c, "D0 = D; v0 = v; s0 = s; E0 = E; S0 = S; B0 = B") == 0, "copies");
    CHECK(silc_save(c, path, "D v s E S B") == 0, "save: %s", silc_context_errmsg(c));
    CHECK(silc_exec(c, "clear D v s E S B") == 0, "clear");
    CHECK(silc_load(c, path, NULL) == 0, "load all: %s", silc_context_errmsg(c));
    for (k = 0; kinds[k]; k++) {
        char copy[8];
        snprintf(copy, sizeof copy, "%s0", kinds[k]);
        CHECK(same(kinds[k], copy), "%s comes back as it was saved", kinds[k]);
    }
    /* formats: CSR and band stay themselves */
    fmt = tl_out_info(c, "S");
    CHECK(strstr(fmt, "S: 3x4 csr") != NULL, "S stays CSR:\n%s", fmt);
    fmt = tl_out_info(c, "B");
    CHECK(strstr(fmt, "B: 3x3 band") != NULL, "B stays band:\n%s", fmt);
    /* names choose */
    CHECK(silc_exec(c, "clear D S") == 0 && silc_load(c, path, "S") == 0, "load S: %s", silc_context_errmsg(c));
    CHECK(same("S", "S0") && strstr(tl_out_exec(c, "who"), "\nD ") == NULL, "only S was loaded:\n%s", tl_out());
    CHECK(silc_exec(c, "save \"" "/tmp/silc-test-h5-only.h5" "\" s; clear s; load \"/tmp/silc-test-h5-only.h5\"") == 0 &&
              same("s", "s0"),
          "statements: %s", silc_context_errmsg(c));
    remove("/tmp/silc-test-h5-only.h5");
}

/* Complex dense, vector, scalar, CSR and band (h5py's compound {r, i})
 * come back bit for bit, in their formats: x - x0 is exactly 0 only when
 * every real and imaginary part is the one saved (none is NaN). */
static void test_complex_round_trip(void)
{
    static const char *const kinds[] = {"Z", "w", "t", "Zs", "Zb", NULL};
    int k;
    CHECK(silc_exec(c, "Z = [1 + 2i, 1/3 - 1i/7; -4i, 5.5]; w = [1e-300 + 3e300i; -2]; t = 2 - 1i/3; "
                       "Zs = sparse([1; 3; 2], [1; 1; 3], [1.5 - 2i; 1i/3; 4], 3, 4); "
                       "Zb = band(sparse([1; 2; 2; 3], [1; 1; 2; 3], [1i; 2; 3 + 1i/7; 4], 3, 3), 1, 0); "
                       "Z0 = Z; w0 = w; t0 = t; Zs0 = Zs; Zb0 = Zb") == 0,
          "complex values: %s", silc_context_errmsg(c));
    CHECK(silc_save(c, path, "Z w t Zs Zb") == 0, "save of complex values: %s", silc_context_errmsg(c));
    CHECK(silc_exec(c, "clear Z w t Zs Zb") == 0 && silc_load(c, path, NULL) == 0, "load of complex values: %s",
          silc_context_errmsg(c));
    for (k = 0; kinds[k]; k++) {
        char text[200];
        double *d;
        int64_t m = 0, n = 0;
        snprintf(text, sizeof text, "d = max(max(abs(dense(%s - %s0)))); i = max(max(abs(dense(imag(%s)))))",
                 kinds[k], kinds[k], kinds[k]);
        CHECK(silc_exec(c, text) == 0, "%s: %s", text, silc_context_errmsg(c));
        d = entries("d", &m, &n);
        CHECK(d && m == 1 && n == 1 && d[0] == 0.0, "complex %s comes back as it was saved", kinds[k]);
        free(d);
        d = entries("i", &m, &n);
        CHECK(d && d[0] > 0, "complex %s keeps its imaginary parts", kinds[k]);
        free(d);
    }
    CHECK(strstr(tl_out_info(c, "Zs"), "Zs: 3x4 csr") != NULL, "complex Zs stays CSR:\n%s", tl_out());
    CHECK(strstr(tl_out_info(c, "Zb"), "Zb: 3x3 band") != NULL, "complex Zb stays band:\n%s", tl_out());
}

static void expect(int rc, const char *want, const char *what)
{
    CHECK(rc != 0 && tl_contains(silc_context_errmsg(c), want), "%s: got '%s', want '%s'", what,
          rc ? silc_context_errmsg(c) : "success", want);
}

static void test_failures(void)
{
    FILE *f;
    double *before;
    int64_t m = 0, n = 0;
    CHECK(silc_exec(c, "D = [9, 9]") == 0, "D");
    expect(silc_load(c, "/nonexistent/x.h5", NULL), "load: cannot read '/nonexistent/x.h5': No such file or directory",
           "missing file");
    f = fopen(other, "w");
    if (f) fputs("not hdf5\n", f), fclose(f);
    expect(silc_load(c, other, NULL), "is not an HDF5 file", "a text file");
    if (geteuid() != 0) { /* root reads any file */
        chmod(other, 0);
        expect(silc_load(c, other, NULL), "Permission denied", "an unreadable file");
        chmod(other, 0600);
    }
    expect(silc_load(c, path, "nosuch"), "load: 'nosuch' is not in", "a name the file lacks");
    expect(silc_save(c, path, "D nosuch"), "save: undefined name 'nosuch'", "an undefined name");
    CHECK(silc_load(c, path, "D") == 0, "the old file stays after a failed save: %s", silc_context_errmsg(c));
    expect(silc_save(c, "/nonexistent/dir/x.h5", "D"), "save: cannot create '/nonexistent/dir/x.h5'",
           "an unwritable place");
    expect(silc_exec(c, "load x"), "load needs a file name in quotes", "parse");
    expect(silc_load(c, "a\"b", NULL), "without '\"'", "a quote in the path");
    /* A file with an object of no SILC layout: a load of all binds the rest
     * and names what it skipped; a load of that object by name fails and
     * changes nothing. */
    CHECK(silc_exec(c, "D = [9, 9]") == 0, "D again");
    before = entries("D", &m, &n);
    if (system("/usr/bin/python3 -c \"import h5py; f = h5py.File('/tmp/silc-test-h5-bad.h5', 'w'); "
               "f['D'] = [[1.0, 2.0]]; g = f.create_group('G'); g['x'] = [1.0]\" 2>/dev/null") == 0) {
        double *after;
        expect(silc_load(c, "/tmp/silc-test-h5-bad.h5", "D G"),
               "load: 'G' in '/tmp/silc-test-h5-bad.h5' is not a SILC value", "a group that is not CSR, by name");
        after = entries("D", &m, &n);
        CHECK(before && after && m == 1 && n == 2 && after[0] == 9 && after[1] == 9,
              "D keeps its value after the failed load");
        free(after);
        CHECK(silc_load(c, "/tmp/silc-test-h5-bad.h5", NULL) == 0, "a load of all skips G: %s", silc_context_errmsg(c));
        after = entries("D", &m, &n);
        CHECK(after && m == 1 && n == 2 && after[0] == 1 && after[1] == 2, "D is the file's [1, 2]");
        free(after);
        CHECK(tl_contains(silc_context_warnings(c), "load: skipped 1 object of '/tmp/silc-test-h5-bad.h5' that is "
                                                    "not a SILC value: 'G' (not a SILC value: a group needs"),
              "the warning names G: %s", silc_context_warnings(c));
        CHECK(!strstr(tl_out_exec(c, "who"), "\nG "), "G is not bound:\n%s", tl_out());
        remove("/tmp/silc-test-h5-bad.h5");
    } else {
        printf("test_h5: no h5py: the foreign-layout case skipped\n");
    }
    free(before);
}

int main(void)
{
    snprintf(path, sizeof path, "/tmp/silc-test-h5-%ld.h5", (long)getpid());
    snprintf(other, sizeof other, "/tmp/silc-test-h5-%ld.txt", (long)getpid());
    if (silc_open(&c, NULL)) {
        CHECK(0, "silc_open: %s", silc_errmsg());
        return check_done();
    }
    silc_set_output(c, tl_out_fn, NULL);
    if (silc_exec(c, "save \"/tmp/silc-test-h5-probe.h5\"") &&
        tl_contains(silc_context_errmsg(c), "HDF5 support is not installed")) {
        printf("test_h5: no HDF5 module: %s\n", silc_context_errmsg(c));
        silc_close(&c);
        return check_done();
    }
    remove("/tmp/silc-test-h5-probe.h5");
    test_round_trip();
    test_failures();
    test_complex_round_trip();
    remove(path);
    remove(other);
    silc_close(&c);
    return check_done();
}
