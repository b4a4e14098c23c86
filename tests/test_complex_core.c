/*
 * test_complex_core.c -- complex values in the core (issue 31): the store's
 * complex constructors and their limits, the properties of complex values
 * (modulus norms, A = A.' and A = A', a real positive diagonal, NaN in an
 * imaginary part), promotion and the real/imaginary parts, and complex
 * envelopes PUT and fetched through the C API, embedded and through a
 * private silcd, where a client that did not ask for complex values is
 * refused one by name.  Truth is exact arithmetic on small matrices whose
 * norms and symmetries are known in closed form, and the bits of what was
 * sent.
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

int main(void)
{
    test_values();
    test_gating();
    test_api();
    return check_done();
}
