/*
 * test_complex_core.c -- complex values in the core (issue 31): the store's
 * complex constructors and their limits, the properties of complex values
 * (modulus norms, A = A.' and A = A', a real positive diagonal, NaN in an
 * imaginary part), promotion and the real/imaginary parts, and complex
 * envelopes PUT and fetched through the C API, embedded and through a
 * private silcd, where a client that did not ask for complex values is
 * refused one by name; the dispatcher's gating, promotion and classes; the
 * language (literals, i/j, parts, sqrt/log of negatives, dot, solves); and
 * Matrix Market complex files.  Truth is exact arithmetic on small matrices
 * whose norms and symmetries are known in closed form, exact solutions (b
 * formed from x_true), the bits of what was sent, the shared matrices' own
 * lines, and SciPy's norms of them (scipy.io.mmread, stored below).
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE 1
#include <complex.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "dispatch.h"
#include "remote_util.h"
#include "silc.h"
#include "store.h"

/* [2, 1+i; 1-i, 3]: Hermitian with a real positive diagonal; norm1 =
 * norminf = 3 + sqrt(2), normfro = sqrt(4 + 2 + 2 + 9). */
static const double herm[8] = {2, 0, 1, -1, 1, 1, 3, 0}; /* column-major, interleaved */
/* [2, 1+i; 1+i, 3]: complex symmetric, not Hermitian. */
static const double csym[8] = {2, 0, 1, 1, 1, 1, 3, 0};

static silc_value *dense_complex(int64_t m, int64_t n, const double *z)
{
    silc_value *v = val_dense_new_complex(m, n);
    if (v) memcpy(v->val, z, (size_t)(2 * m * n) * sizeof(double));
    return v;
}

static void test_values(void)
{
    silc_value *h = dense_complex(2, 2, herm), *s = dense_complex(2, 2, csym), *p, *re, *im;
    const silc_props *ph, *ps;
    CHECK(h && s && h->field == SILC_FIELD_COMPLEX && val_width(h) == 2, "complex dense values");
    CHECK(val_bytes(h) == 8 * sizeof(double), "a 2x2 complex value holds %zu bytes, want 64", val_bytes(h));
    ph = val_props(h);
    ps = val_props(s);
    CHECK(ph->hermitian && !ph->symmetric && ph->pos_diag, "Hermitian: hermitian %d symmetric %d pos_diag %d",
          ph->hermitian, ph->symmetric, ph->pos_diag);
    CHECK(ps->symmetric && !ps->hermitian, "complex symmetric: symmetric %d hermitian %d", ps->symmetric,
          ps->hermitian);
    CHECK_NEAR(ph->norm1, 3 + sqrt(2.0), 1e-15);
    CHECK_NEAR(ph->norminf, 3 + sqrt(2.0), 1e-15);
    CHECK_NEAR(ph->normfro, sqrt(17.0), 1e-15);
    CHECK_NEAR(ph->maxabs, 3, 0);
    CHECK(ph->nnz == 4 && !ph->diagonal && ph->square, "shape of a full 2x2 complex value");
    CHECK(creal(val_get_complex(h, 0, 1)) == 1 && cimag(val_get_complex(h, 0, 1)) == 1, "entry (0, 1)");
    CHECK(val_get(h, 1, 0) == 1, "val_get gives the real part");

    /* A diagonal entry with an imaginary part is not a positive diagonal. */
    {
        double z[8] = {2, 0.5, 0, 0, 0, 0, 3, 0};
        silc_value *d = dense_complex(2, 2, z);
        CHECK(!val_props(d)->pos_diag && val_props(d)->diagonal, "2+0.5i on the diagonal is not positive");
        val_release(d);
    }
    /* NaN in an imaginary part only: seen by the scan and the properties. */
    {
        double z[4] = {1, 0, 2, NAN};
        silc_value *d = dense_complex(2, 1, z), *d2 = dense_complex(2, 1, z);
        CHECK(val_has_nonfinite(d), "NaN imaginary part not found by the scan");
        CHECK(val_props(d2)->has_nonfinite, "NaN imaginary part not found by the properties");
        val_release(d);
        val_release(d2);
    }
    /* Promotion and the parts. */
    {
        silc_value *r = val_dense_new(2, 1);
        r->val[0] = 4, r->val[1] = -5;
        p = val_promote(r);
        CHECK(p && p->field == SILC_FIELD_COMPLEX && p->val[0] == 4 && p->val[1] == 0 && p->val[2] == -5 &&
                  p->val[3] == 0, "promotion of [4; -5]");
        CHECK(val_imag_is_zero(p) && !val_imag_is_zero(h), "val_imag_is_zero");
        CHECK(val_props(r)->hermitian == val_props(r)->symmetric, "a real value's hermitian is its symmetric");
        val_release(r);
        val_release(p);
    }
    re = val_part(h, 0);
    im = val_part(h, 1);
    CHECK(re && im && re->field == SILC_FIELD_REAL && re->val[2] == 1 && im->val[1] == -1 && im->val[2] == 1,
          "real and imaginary parts");
    val_release(re);
    val_release(im);
    val_release(h);
    val_release(s);

    /* The limits count 2 doubles an entry: a 10x10 complex value needs
     * 1600 bytes, a real one 800. */
    val_set_max_bytes(1000, "the test's limit");
    p = val_dense_new(10, 10);
    CHECK(p != NULL, "a 10x10 real value fits 1000 bytes");
    val_release(p);
    p = val_dense_new_complex(10, 10);
    CHECK(p == NULL && strstr(val_refusal(), "1600") && strstr(val_refusal(), "the test's limit"),
          "a 10x10 complex value over 1000 bytes: %s", val_refusal());
    p = val_csr_new_complex(10, 10, INT64_MAX / 4);
    CHECK(p == NULL, "an overflowing complex CSR capacity was accepted");
    val_set_max_bytes(0, NULL);
}

/* PUT a complex dense and CSR value, fetch them back bit for bit with
 * silc_get_complex; silc_get refuses them by name.  label says where. */
static void round_trip(silc_context *c, const char *label)
{
    /* CSR [0, 1-2i, 0; 3i, 0, 4; 0, 0, -5+0.25i], given with unsorted rows. */
    int64_t rp[4] = {0, 1, 3, 4}, ci[4] = {1, 2, 0, 2};
    double cv[8] = {1, -2, 4, 0, 0, 3, -5, 0.25};
    double dense[18];
    int64_t first = -1;
    silc_envelope_t a, z, out;
    CHECK(silc_envelope_dense_complex(&z, 2, 2, herm) == 0, "%s: dense complex envelope", label);
    CHECK(silc_envelope_is_complex(&z) && z.format == SILC_DENSE_COMPLEX, "%s: envelope format", label);
    CHECK(silc_envelope_csr_complex(&a, 3, 3, rp, ci, cv) == 0, "%s: csr complex envelope: %s", label,
          silc_errmsg());
    /* the constructor sorted row 1: columns 0, 2 with their values */
    CHECK(a.colind[1] == 0 && a.values[2] == 0 && a.values[3] == 3 && a.colind[2] == 2 && a.values[4] == 4,
          "%s: row 1 sorted with its complex values", label);
    CHECK(silc_put(c, "z", &z) == 0, "%s: put z: %s", label, silc_context_errmsg(c));
    CHECK(silc_put(c, "A", &a) == 0, "%s: put A: %s", label, silc_context_errmsg(c));
    CHECK(silc_get(c, &out, "z") != 0 && strstr(silc_context_errmsg(c), "'z' is complex"),
          "%s: silc_get of a complex value: %s", label, silc_context_errmsg(c));
    silc_envelope_free(&out);
    /* silc_get_rows is pointed to its own complex call, remote as embedded
     * (silcd's GET names silc_get_complex); silc_get_rows_complex brings
     * the whole value from row 0 on one process. */
    CHECK(silc_get_rows(c, &out, &first, "z") != 0 && out.values == NULL &&
              strstr(silc_context_errmsg(c), "'z' is complex") &&
              strstr(silc_context_errmsg(c), "fetch it with silc_get_rows_complex,"),
          "%s: silc_get_rows of a complex value: %s", label, silc_context_errmsg(c));
    silc_envelope_free(&out);
    first = -1;
    CHECK(silc_get_rows_complex(c, &out, &first, "z") == 0 && first == 0 && out.format == SILC_DENSE_COMPLEX &&
              out.m == 2 && out.n == 2 && !memcmp(out.values, herm, sizeof herm),
          "%s: silc_get_rows_complex z: first %lld, %s", label, (long long)first, silc_context_errmsg(c));
    silc_envelope_free(&out);
    CHECK(silc_get_complex(c, &out, "z") == 0, "%s: get_complex z: %s", label, silc_context_errmsg(c));
    CHECK(out.format == SILC_DENSE_COMPLEX && out.m == 2 && out.n == 2 &&
              !memcmp(out.values, herm, sizeof herm), "%s: z came back changed", label);
    silc_envelope_free(&out);
    CHECK(silc_get_complex(c, &out, "A") == 0, "%s: get_complex A: %s", label, silc_context_errmsg(c));
    CHECK(out.format == SILC_CSR_COMPLEX && out.nnz == 4 && !memcmp(out.values, a.values, 8 * sizeof(double)) &&
              !memcmp(out.colind, a.colind, 4 * sizeof(int64_t)), "%s: A came back changed", label);
    CHECK(silc_envelope_to_dense(&out, dense) == 0 && dense[2 * 1 + 0] == 0 && dense[2 * 1 + 1] == 3 &&
              dense[2 * (0 + 1 * 3)] == 1 && dense[2 * (0 + 1 * 3) + 1] == -2, "%s: complex to_dense", label);
    silc_envelope_free(&out);
    /* A real value still comes through silc_get, and silc_get_complex. */
    CHECK(silc_exec(c, "r = [1; 2]") == 0, "%s: exec: %s", label, silc_context_errmsg(c));
    CHECK(silc_get(c, &out, "r") == 0 && out.format == SILC_DENSE && out.values[1] == 2, "%s: real get", label);
    silc_envelope_free(&out);
    CHECK(silc_get_complex(c, &out, "r") == 0 && out.format == SILC_DENSE, "%s: real get_complex", label);
    silc_envelope_free(&out);
    /* A hand-filled complex CSR envelope with a bad column is refused. */
    a.colind[3] = 7;
    CHECK(silc_put(c, "B", &a) != 0 && strstr(silc_context_errmsg(c), "column index 7"), "%s: bad column: %s",
          label, silc_context_errmsg(c));
    silc_envelope_free(&a);
    silc_envelope_free(&z);
}

static void test_api(void)
{
    silc_context *c;
    test_server s;
    if (silc_open(&c, NULL)) {
        CHECK(0, "open: %s", silc_errmsg());
        return;
    }
    round_trip(c, "embedded");
    silc_close(&c);
    signal(SIGPIPE, SIG_IGN);
    if (server_start(&s, NULL, NULL) != 0) {
        CHECK(0, "silcd did not start");
        return;
    }
    if (silc_open_remote(&c, s.url) == 0) {
        round_trip(c, "remote");
        silc_close(&c);
    } else {
        CHECK(0, "open remote: %s", silc_errmsg());
    }
    CHECK(server_stop(&s) == 0, "silcd did not stop cleanly");
}

/* SCALE of in through the dispatcher with the session list (or the
 * per-call options); rc as disp_run's, out the result (NULL on failure). */
static int scale(silc_engine *E, const silc_value *in, double alpha, double alpha_imag, const char *options,
                 silc_value **out)
{
    silc_call c;
    int rc;
    memset(&c, 0, sizeof c);
    c.op = SILC_OP_SCALE;
    c.nin = 1;
    c.in[0] = in;
    c.alpha = alpha;
    c.alpha_imag = alpha_imag;
    c.options = options;
    rc = disp_run(E, &c);
    *out = c.out;
    return rc;
}

/* The gating: a complex operand goes only to a backend whose plugin lists
 * the op in complex_ops (ABI 1.8), is passed over by a 1.7 plugin, and
 * gets a clear error when no backend of the list takes it; a real operand
 * with a complex alpha is promoted. */
static void test_gating(void)
{
    silc_engine *E = NULL;
    char err[1024], path[1024];
    static const double z[4] = {1, 2, 3, -1};
    silc_value *Z = dense_complex(2, 1, z), *R = val_dense_new(2, 1), *out = NULL;
    R->val[0] = 1, R->val[1] = 3;
    CHECK(eng_create(&E, "/dev/null", err, sizeof err) == 0, "eng_create: %s", err);
    if (!E) return;
    snprintf(path, sizeof path, "%s/abi_old_minor.so", ABI_PLUGIN_DIR);
    CHECK(ld_load_file(E, path) == 0, "old_minor refused: %s", E->err);
    snprintf(path, sizeof path, "%s/abi_takes_complex.so", ABI_PLUGIN_DIR);
    CHECK(ld_load_file(E, path) == 0, "takes_complex refused: %s", E->err);
    CHECK(cfg_set(E, CFG_SCOPE_SESSION, "dispatch.add", "old_minor, takes_complex") == 0, "%s", E->err);

    /* complex: old_minor is passed over, takes_complex gives 2z + 2 */
    CHECK(scale(E, Z, 2, 0, NULL, &out) == 0, "complex scale: %s", E->err);
    CHECK(out && out->field == SILC_FIELD_COMPLEX && out->val[0] == 4 && out->val[1] == 4 && out->val[2] == 8 &&
              out->val[3] == -2, "2z + 2 from takes_complex");
    val_release(out);
    /* real: old_minor runs (2r + 1) */
    CHECK(scale(E, R, 2, 0, NULL, &out) == 0 && out && out->field == SILC_FIELD_REAL && out->val[0] == 3 &&
              out->val[1] == 7, "real scale by old_minor: %s", E->err);
    val_release(out);
    /* a complex alpha on a real operand: promoted, (2 + i) r + 2 */
    CHECK(scale(E, R, 2, 1, NULL, &out) == 0, "promoted scale: %s", E->err);
    CHECK(out && out->field == SILC_FIELD_COMPLEX && out->val[0] == 4 && out->val[1] == 1 && out->val[2] == 8 &&
              out->val[3] == 3, "(2 + i) r + 2 after promotion");
    val_release(out);
    CHECK(R->field == SILC_FIELD_REAL && R->refcount == 1, "the promoted operand was changed or kept");
    /* no backend of the list takes complex values: a clear error */
    CHECK(scale(E, Z, 2, 0, "backend = old_minor", &out) != 0 && !out, "old plugin ran a complex scale");
    CHECK(strstr(E->err, "no backend can run scale (add) on complex values") &&
              strstr(E->err, "operand 1 (2x1 complex dense)") &&
              strstr(E->err, "old_minor does not take complex values"), "error: %s", E->err);
    val_release(Z);
    val_release(R);
    eng_destroy(&E);
}

/* Fetches name (complex) from c into a malloc'd interleaved array of m*n
 * entries; NULL with a failed check otherwise. */
static double *fetch(silc_context *c, const char *name, int64_t m, int64_t n)
{
    silc_envelope_t e;
    double *z = NULL;
    if (silc_get_complex(c, &e, name)) {
        CHECK(0, "get %s: %s", name, silc_context_errmsg(c));
        return NULL;
    }
    if (e.m == m && e.n == n && (z = malloc((size_t)(2 * m * n) * sizeof *z))) {
        if (silc_envelope_is_complex(&e)) {
            silc_envelope_to_dense(&e, z);
        } else { /* a real value: imaginary parts 0 */
            silc_envelope_to_dense(&e, z + m * n);
            for (int64_t k = 0; k < m * n; k++) z[2 * k] = z[m * n + k], z[2 * k + 1] = 0;
        }
    } else {
        CHECK(0, "%s is %lldx%lld, want %lldx%lld", name, (long long)e.m, (long long)e.n, (long long)m,
              (long long)n);
    }
    silc_envelope_free(&e);
    return z;
}

static void expect_scalar(silc_context *c, const char *name, double re, double im, double tol)
{
    double *z = fetch(c, name, 1, 1);
    if (!z) return;
    CHECK(fabs(z[0] - re) <= tol && fabs(z[1] - im) <= tol, "%s = %.17g + %.17gi, want %.17g + %.17gi", name, z[0],
          z[1], re, im);
    free(z);
}

static void run(silc_context *c, const char *text)
{
    CHECK(silc_exec(c, text) == 0, "'%s': %s", text, silc_context_errmsg(c));
}

/* The language against exact arithmetic. */
static void test_language(void)
{
    silc_context *c;
    /* A = [2+i, 1, 0; -1, 3-2i, 1i; 0, 2, 4+i] (complex, unsymmetric),
     * x_true = [1-i; 2i; 3] and b = A x_true worked out by hand:
     * row 1: (2+i)(1-i) + 2i = 3 - i + 2i = 3 + i
     * row 2: -(1-i) + (3-2i)(2i) + 3i = -1 + i + 6i + 4 + 3i = 3 + 10i
     * row 3: 2(2i) + (4+i)3 = 12 + 7i */
    static const double xt[6] = {1, -1, 0, 2, 3, 0};
    double *x;
    if (silc_open(&c, NULL)) {
        CHECK(0, "open: %s", silc_errmsg());
        return;
    }
    run(c, "z = (1+2i)*(3-1i); u = i; w = 2.5j; e3 = 1e3i; r = real(z); m = imag(z); cj = conj(z);"
           "an = angle(-1); ab = abs(3-4i); sq = sqrt(-4); lg = log(-1); d = dot([1i; 2], [1; 1i]);"
           "cx = complex(2, -3); ir = isreal(cx); ir2 = isreal(r); t = [1+2i, 3]'; p = [1+2i, 3].';"
           "s = sum([1+2i; 3-1i]); nr = norm([3+4i; 0]);");
    expect_scalar(c, "z", 5, 5, 0);
    expect_scalar(c, "u", 0, 1, 0);
    expect_scalar(c, "w", 0, 2.5, 0);
    expect_scalar(c, "e3", 0, 1000, 0);
    expect_scalar(c, "r", 5, 0, 0);
    expect_scalar(c, "m", 5, 0, 0);
    expect_scalar(c, "cj", 5, -5, 0);
    expect_scalar(c, "ab", 5, 0, 0);
    expect_scalar(c, "sq", 0, 2, 0);
    expect_scalar(c, "lg", 0, M_PI, 1e-15);
    expect_scalar(c, "an", M_PI, 0, 1e-15);
    expect_scalar(c, "d", 0, 1, 0);  /* conj(1i) * 1 + 2 * 1i */
    expect_scalar(c, "cx", 2, -3, 0);
    expect_scalar(c, "ir", 0, 0, 0);
    expect_scalar(c, "ir2", 1, 0, 0);
    expect_scalar(c, "s", 4, 1, 0);
    expect_scalar(c, "nr", 5, 0, 1e-15);
    if ((x = fetch(c, "t", 2, 1))) {
        CHECK(x[0] == 1 && x[1] == -2 && x[2] == 3 && x[3] == 0 && signbit(x[3]), "' conjugates: [1-2i; 3-0i]");
        free(x);
    }
    if ((x = fetch(c, "p", 2, 1))) {
        CHECK(x[0] == 1 && x[1] == 2 && x[2] == 3 && x[3] == 0 && !signbit(x[3]), ".' does not conjugate");
        free(x);
    }
    /* a name bound to i wins over the imaginary unit */
    run(c, "for i = 1:3\nend\nk = i");
    expect_scalar(c, "k", 3, 0, 0);
    run(c, "clear i\nk = i");
    expect_scalar(c, "k", 0, 1, 0);

    /* subscripts and for loops keep both parts; a complex rhs makes a real target complex */
    run(c, "v = [1+2i, 3, 4i]; e = v[2]; v[3] = 5-1i; sv = v[3]; Sc = sparse([1 2], [1 2], [1+2i, 3], 2, 2);"
           "q = Sc[1, 1]; Sc[2, 1] = 7i; q2 = Sc[2, 1]; r = [1 2 3]; r[2] = 1i; t2 = r[2]; t3 = r[3];"
           "for col = [1i, 2-3i]\nend\nlast = col");
    expect_scalar(c, "e", 3, 0, 0);
    expect_scalar(c, "sv", 5, -1, 0);
    expect_scalar(c, "q", 1, 2, 0);
    expect_scalar(c, "q2", 0, 7, 0);
    expect_scalar(c, "t2", 0, 1, 0);
    expect_scalar(c, "t3", 3, 0, 0);
    expect_scalar(c, "last", 2, -3, 0);
    /* (complex values saved to and loaded from HDF5: tests/test_h5.c, test_h5.py) */

    /* complex dense and sparse solves, and a real A against a complex b */
    run(c, "A = [2+1i, 1, 0; -1, 3-2i, 1i; 0, 2, 4+1i]; b = [3+1i; 3+10i; 12+7i];"
           "x = A \\ b; xs = sparse(A) \\ b;"
           "R = [4, 1, 0; 1, 3, 1; 0, 1, 2]; br = R * [1-1i; 2i; 3]; xr = R \\ br;");
    for (int k = 0; k < 3; k++) {
        const char *names[3] = {"x", "xs", "xr"};
        if (!(x = fetch(c, names[k], 3, 1))) continue;
        for (int q = 0; q < 6; q++) CHECK(fabs(x[q] - xt[q]) <= 1e-14, "%s[%d] = %.17g, want %g", names[k], q, x[q], xt[q]);
        free(x);
    }
    /* NaN in an imaginary part is refused where a real NaN is */
    CHECK(silc_exec(c, "bn = [1; complex(0, nan); 1]; y = A \\ bn") != 0 &&
              strstr(silc_context_errmsg(c), "NaN at (2, 1)"),
          "NaN imaginary part in b: %s", silc_context_errmsg(c));
    CHECK(silc_exec(c, "An = A; An = [2+1i, 1, 0; -1, complex(3, inf), 1i; 0, 2, 4+1i]; y = An \\ b") != 0 &&
              strstr(silc_context_errmsg(c), "Inf at (2, 2)"),
          "Inf imaginary part in A: %s", silc_context_errmsg(c));
    silc_close(&c);
}

/* The solve classes of complex matrices. */
static void test_classes(void)
{
    silc_engine *E = NULL;
    char err[512];
    const char *chain[4];
    silc_value *H = dense_complex(2, 2, herm), *S = dense_complex(2, 2, csym), *b = val_dense_new_complex(2, 1);
    silc_call c;
    CHECK(eng_create(&E, "/dev/null", err, sizeof err) == 0, "eng_create: %s", err);
    if (!E) return;
    memset(&c, 0, sizeof c);
    c.op = SILC_OP_SOLVE;
    c.nin = 2;
    c.in[0] = H;
    c.in[1] = b;
    CHECK(disp_classes(E, &c, chain) >= 1 && !strcmp(chain[0], "solve.dense.spd"),
          "Hermitian, real positive diagonal: %s", chain[0]);
    c.in[0] = S;
    CHECK(disp_classes(E, &c, chain) >= 1 && !strcmp(chain[0], "solve.dense"), "complex symmetric: %s", chain[0]);
    val_release(H);
    val_release(S);
    val_release(b);
    eng_destroy(&E);
}

/* The first data line of an .mtx file (after the size line) as i j re im. */
static int first_entry(const char *path, int64_t *i, int64_t *j, double *re, double *im)
{
    char line[256];
    int seen_size = 0, ok = 0;
    FILE *f = fopen(path, "r");
    if (!f) return 0;
    while (fgets(line, sizeof line, f))
        if (line[0] != '%') {
            long long a, b;
            if (seen_size++ == 0) continue;
            ok = sscanf(line, "%lld %lld %lf %lf", &a, &b, re, im) == 4;
            *i = a - 1, *j = b - 1;
            break;
        }
    fclose(f);
    return ok;
}

/* The value at (i, j) of a complex CSR envelope (0 if absent). */
static double complex csr_entry(const silc_envelope_t *e, int64_t i, int64_t j)
{
    for (int64_t k = e->rowptr[i]; k < e->rowptr[i + 1]; k++)
        if (e->colind[k] == j) return e->values[2 * k] + e->values[2 * k + 1] * I;
    return 0;
}

static void test_matrix_market(void)
{
    char path[1024], err[512];
    silc_envelope_t e, back;
    silc_value *v;
    int64_t i, j;
    double re, im;
    FILE *f;
    /* young1c: complex general.  SciPy (scipy.io.mmread, sparse.linalg.norm)
     * gives norm1 = norminf = 474.46000000000004, fro = 6484.533199159227. */
    snprintf(path, sizeof path, "%s/young1c.mtx", SILC_SHARED_MATRICES);
    CHECK(silc_mm_read(&e, path, err, sizeof err) == 0, "young1c: %s", err);
    CHECK(e.format == SILC_CSR_COMPLEX && e.m == 841 && e.nnz == 4089, "young1c: %lldx%lld, %lld entries",
          (long long)e.m, (long long)e.n, (long long)e.nnz);
    if (first_entry(path, &i, &j, &re, &im))
        CHECK(csr_entry(&e, i, j) == re + im * I, "young1c (%lld, %lld) is not the file's %g + %gi", (long long)i + 1,
              (long long)j + 1, re, im);
    else
        CHECK(0, "young1c: could not read its first entry");
    CHECK(env_to_value(&e, &v, err, sizeof err) == 0, "young1c to value: %s", err);
    if (v) {
        const silc_props *p = val_props(v);
        CHECK_NEAR(p->norm1, 474.46000000000004, 1e-12);
        CHECK_NEAR(p->norminf, 474.46000000000004, 1e-12);
        CHECK_NEAR(p->normfro, 6484.533199159227, 1e-9);
        val_release(v);
    }
    /* written and read back: the same bits */
    snprintf(path, sizeof path, "%s/tests/complex_core_roundtrip.mtx", SILC_BINARY_DIR);
    if ((f = fopen(path, "w"))) {
        CHECK(silc_mm_write(&e, f) == 0, "write: %s", silc_errmsg());
        fclose(f);
        CHECK(silc_mm_read(&back, path, err, sizeof err) == 0, "read back: %s", err);
        CHECK(back.format == e.format && back.nnz == e.nnz &&
                  !memcmp(back.values, e.values, (size_t)(2 * e.nnz) * sizeof(double)) &&
                  !memcmp(back.colind, e.colind, (size_t)e.nnz * sizeof(int64_t)), "young1c changed on a round trip");
        silc_envelope_free(&back);
        remove(path);
    }
    silc_envelope_free(&e);
    /* mhd1280b: complex hermitian, the lower triangle stored.  SciPy: norm1
     * 79.9740013444046, fro 110.21058008001548. */
    snprintf(path, sizeof path, "%s/mhd1280b.mtx", SILC_SHARED_MATRICES);
    CHECK(silc_mm_read(&e, path, err, sizeof err) == 0, "mhd1280b: %s", err);
    if (e.values) {
        /* the file's line "4 2 0.0001443808 -1.114648e-18": its mirror is the conjugate */
        CHECK(csr_entry(&e, 3, 1) == 0.0001443808 - 1.114648e-18 * I, "mhd1280b (4, 2)");
        CHECK(csr_entry(&e, 1, 3) == 0.0001443808 + 1.114648e-18 * I, "mhd1280b (2, 4) is not the conjugate");
        CHECK(env_to_value(&e, &v, err, sizeof err) == 0, "mhd1280b to value: %s", err);
        if (v) {
            const silc_props *p = val_props(v);
            CHECK(p->hermitian && !p->symmetric && p->pos_diag, "mhd1280b: hermitian %d symmetric %d pos_diag %d",
                  p->hermitian, p->symmetric, p->pos_diag);
            CHECK_NEAR(p->norm1, 79.9740013444046, 1e-12);
            CHECK_NEAR(p->normfro, 110.21058008001548, 1e-11);
            val_release(v);
        }
    }
    silc_envelope_free(&e);
    /* refusals: real hermitian (issue 32), an imaginary hermitian diagonal */
    snprintf(path, sizeof path, "%s/tests/complex_core_bad.mtx", SILC_BINARY_DIR);
    if ((f = fopen(path, "w"))) {
        fputs("%%MatrixMarket matrix coordinate real hermitian\n2 2 1\n1 1 1\n", f);
        fclose(f);
        CHECK(silc_mm_read(&e, path, err, sizeof err) != 0 && strstr(err, "needs a complex field"), "real hermitian: %s",
              err);
        silc_envelope_free(&e);
    }
    if ((f = fopen(path, "w"))) {
        fputs("%%MatrixMarket matrix coordinate complex hermitian\n2 2 2\n1 1 1 0\n2 2 1 0.5\n", f);
        fclose(f);
        CHECK(silc_mm_read(&e, path, err, sizeof err) != 0 && strstr(err, ":4:") && strstr(err, "must be real"),
              "hermitian diagonal with an imaginary part: %s", err);
        silc_envelope_free(&e);
    }
    if ((f = fopen(path, "w"))) { /* a complex array file, symmetric (not conjugated) */
        fputs("%%MatrixMarket matrix array complex symmetric\n2 2\n1 2\n3 4\n5 6\n", f);
        fclose(f);
        CHECK(silc_mm_read(&e, path, err, sizeof err) == 0 && e.format == SILC_DENSE_COMPLEX && e.values[2] == 3 &&
                  e.values[3] == 4 && e.values[4] == 3 && e.values[5] == 4 && e.values[6] == 5,
              "complex symmetric array: %s", err);
        silc_envelope_free(&e);
    }
    remove(path);
}

int main(void)
{
    test_values();
    test_gating();
    test_classes();
    test_language();
    test_matrix_market();
    test_api();
    return check_done();
}
