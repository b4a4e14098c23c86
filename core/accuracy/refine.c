/*
 * refine.c -- iterative refinement of direct solves, and the check that a
 * solve's operands are finite.
 *
 * Refinement (Wilkinson; Higham, "Accuracy and Stability", ch. 12): with x
 * from a backend, repeat r = b - A x, solve A d = r with the same backend,
 * x += d.  Two flavours, chosen by solve.refine_residual:
 *
 *   double    r in working precision.  This repairs an unstable or low-
 *             precision solve (a single-precision factorization, a pivot
 *             order that lost accuracy) down to a backward error of order
 *             eps, but cannot beat the forward error cond * eps.  The loop
 *             stops when the backward error reaches eps or stops halving, and
 *             a step that makes it worse is thrown away.  The default steps
 *             of a single-precision factorization (solve.refine not set)
 *             stop earlier, at how->target (tune.accuracy), when one is set:
 *             the tuner picked that backend for that accuracy, and each
 *             step costs a residual and a solve.
 *   extended  r accumulated in double-double (each product split exactly
 *             with fma, each sum with TwoSum), rounded once.  Then the
 *             forward error itself converges to about eps while
 *             cond * eps < 1.  The backward error of a stable solve is
 *             already at eps, so this loop watches the size of the
 *             correction instead, as LAPACK's xGERFSX does: it stops when
 *             ||d|| / ||x|| reaches eps or stops halving.
 *
 * The correction solve goes straight to the backend that made x (not through
 * the dispatcher again), with the same class and per-call options, so it
 * finds the factorization that backend attached to A.  Only the dispatcher
 * can run a backend, and it sits above this layer, so it hands the
 * correction solve down as a callback (refine_how), with the settings of
 * solve.refine and solve.refine_residual it read.  Least-squares and
 * iterative solves are left alone with a note: the first has no square
 * residual equation, the second is better served by a tighter tolerance.
 *
 * A complex system (complex A) is refined the same way in complex
 * arithmetic: x, r and d are complex arrays (two doubles an entry,
 * interleaved), r = b - A x and the norms are accuracy.c's complex ones
 * (moduli), so the backward error it stops on is the one the report shows.
 * Its residual is always in double: solve.refine_residual = extended has
 * no complex double-double kernel, and a note says so.
 */
#define _POSIX_C_SOURCE 200809L
#include "accuracy.h"

#include <float.h>
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- finite operands ------------------------------------------------------- */

int refine_check_finite_later(const silc_engine *E, const silc_value *A, const silc_value *b)
{
    return E && !E->dist && A && b && !A->dist && A->format == SILC_FMT_DENSE && A->field == SILC_FIELD_REAL &&
           !(A->props_have & SILC_PROPS_SHAPE) && !val_has_nonfinite(b);
}

int refine_check_finite(silc_engine *E, const silc_value *v, int matrix, const char *name)
{
    silc_view w;
    int64_t i, j, p;
    if (!v || !(matrix ? val_props_part(v, SILC_PROPS_SHAPE)->has_nonfinite : val_has_nonfinite(v))) return 0;
    val_view(v, &w);
    if (v->field == SILC_FIELD_COMPLEX) {
        /* a NaN or Inf in either part; named by the worse of the two */
        for (j = 0; j < w.n; j++)
            for (i = 0; i < w.m; i++) {
                double complex z = val_get_complex(v, i, j);
                double re = creal(z), im = cimag(z);
                if (isfinite(re) && isfinite(im)) continue;
                return eng_error(E, "%s has %s at (%lld, %lld): a solve needs finite entries", name,
                                 isnan(re) || isnan(im) ? "NaN" : "Inf", (long long)i + 1, (long long)j + 1);
            }
        return 0;
    }
    for (i = 0; i < w.m; i++)
        for (j = 0; j < w.n; j++) {
            double x;
            if (w.format == SILC_FMT_CSR) { /* only stored entries can be non-finite */
                if (j > 0) break;
                for (p = w.rowptr[i]; p < w.rowptr[i + 1]; p++)
                    if (!isfinite(w.val[p])) {
                        j = w.colind[p];
                        x = w.val[p];
                        goto found;
                    }
                continue;
            }
            x = val_get(v, i, j);
            if (!isfinite(x)) goto found;
            continue;
        found:
            return eng_error(E, "%s has %s at (%lld, %lld): a solve needs finite entries", name,
                             isnan(x) ? "NaN" : x > 0 ? "Inf" : "-Inf", (long long)i + 1,
                             (long long)j + 1);
        }
    return 0;
}

/* ---- the loop -------------------------------------------------------------- */

/* Steps asked for: solve.refine, else the default of single-precision
 * factorizations, else none. */
static int64_t steps_wanted(const refine_how *how, const silc_report *r, int *extended)
{
    *extended = how->residual && strcmp(how->residual, "extended") == 0;
    if (how->steps) return strtoll(how->steps, NULL, 10);
    return r->single_factor ? REFINE_SINGLE_DEFAULT : 0;
}

static void add_note(silc_report *r, const char *text)
{
    size_t len = strlen(r->note);
    snprintf(r->note + len, sizeof r->note - len, "%s%s", len ? "; " : "", text);
}

/* The arrays of the loop hold n x k entries of A's field: w doubles each
 * (1 real, 2 complex interleaved).  These four pick the field's kernel. */
static double *field_copy(const silc_value *v, int w)
{
    return w == 2 ? (double *)acc_dense_copy_complex(v) : acc_dense_copy(v);
}

static double field_norm_inf(const double *x, int64_t n, int64_t k, int w)
{
    return w == 2 ? acc_norm_inf_complex((const double complex *)x, n, k) : acc_norm_inf(x, n, k);
}

/* R = B - A X (lo: the double-double low parts, real and extended only). */
static void field_residual(const silc_value *A, const double *B, const double *X, int64_t k, int extended,
                           double *R, double *lo, int w)
{
    if (w == 2)
        acc_residual_complex(A, (const double complex *)B, (const double complex *)X, k, (double complex *)R);
    else
        acc_residual(A, B, X, k, extended, R, lo);
}

static silc_value *field_dense_new(int64_t n, int64_t k, int w, const double *from)
{
    silc_value *v = w == 2 ? val_dense_new_complex(n, k) : val_dense_new(n, k);
    if (v) memcpy(v->val, from, (size_t)(w * n * k) * sizeof *from);
    return v;
}

void refine_solve(silc_engine *E, silc_call *call, const refine_how *how, int64_t at_least)
{
    silc_report *r = call->report;
    const silc_value *A = call->in[0], *Bv = call->in[1];
    double *B = NULL, *X = NULL, *R = NULL, *lo = NULL, nA, nB, be, be0, dprev = INFINITY;
    double t0 = util_now();
    int64_t want, step, kept = 0, n = A->n, k = Bv->n;
    double enough = DBL_EPSILON; /* the backward error at which the double-residual loop stops */
    int extended, w = A->field == SILC_FIELD_COMPLEX ? 2 : 1;
    char note[200], why[REFINE_WHY_MAX];
    const char *stop = "step limit";
    r->backward_error_unrefined = -1;
    r->refine_steps = 0;
    want = steps_wanted(how, r, &extended);
    if (!how->steps && r->single_factor && how->target > enough) enough = how->target;
    if (!how->steps && want < at_least) want = at_least;
    if (want <= 0 || !call->out) return;
    if (A->m != A->n || n == 0 || k == 0) {
        if (A->m != A->n) add_note(r, "refinement skipped: least-squares solve");
        return;
    }
    if (w == 1 && (Bv->field == SILC_FIELD_COMPLEX || call->out->field == SILC_FIELD_COMPLEX)) {
        /* the dispatcher splits such a solve into real ones (disp_run), which are refined */
        add_note(r, "refinement skipped: real matrix with a complex right-hand side");
        return;
    }
    if (r->iterations > 0 && !r->single_factor) {
        add_note(r, "refinement skipped: iterative solver (tighten its tolerance instead)");
        return;
    }
    if (w == 2 && extended) {
        add_note(r, "complex system: refinement residual in double (no complex double-double kernel)");
        extended = 0;
    }
    B = field_copy(Bv, w);
    X = field_copy(call->out, w);
    R = malloc((size_t)(w * n * k) * sizeof *R);
    lo = extended ? malloc((size_t)(n * k) * sizeof *lo) : NULL;
    if (!B || !X || !R || (extended && !lo)) {
        add_note(r, "refinement skipped: out of memory");
        goto done;
    }
    nA = val_props(A)->norminf;
    nB = field_norm_inf(B, n, k, w);
    field_residual(A, B, X, k, extended, R, lo, w);
    be = be0 = field_norm_inf(R, n, k, w) / (nA * field_norm_inf(X, n, k, w) + nB);
    for (step = 0; step < want; step++) {
        silc_value *Rv, *D;
        double *Xn, ben, dn;
        int64_t i;
        if (!extended && be <= enough) {
            stop = enough > DBL_EPSILON ? "backward error at tune.accuracy" : "backward error at working precision";
            break;
        }
        if (!(be == be)) {
            stop = "residual is not finite";
            break;
        }
        Rv = field_dense_new(n, k, w, R);
        if (!Rv) {
            stop = "out of memory";
            break;
        }
        D = how->correct(how->ctx, E, call, Rv, why, sizeof why);
        val_release(Rv);
        if (!D) {
            stop = why;
            break;
        }
        Xn = field_copy(D, w); /* becomes the candidate x + d */
        val_release(D);
        if (!Xn) {
            stop = "out of memory";
            break;
        }
        dn = field_norm_inf(Xn, n, k, w) / field_norm_inf(X, n, k, w);
        for (i = 0; i < w * n * k; i++) Xn[i] += X[i];
        field_residual(A, B, Xn, k, extended, R, lo, w);
        ben = field_norm_inf(R, n, k, w) / (nA * field_norm_inf(Xn, n, k, w) + nB);
        if (extended ? !(dn < dprev) : !(ben < be)) {
            /* Not an improvement: the previous x stays. */
            free(Xn);
            stop = extended ? "correction stopped shrinking" : "backward error stopped decreasing";
            break;
        }
        free(X);
        X = Xn;
        kept++;
        if (extended ? (dn <= DBL_EPSILON || dn > 0.5 * dprev) : ben > 0.5 * be) {
            be = ben;
            stop = extended ? (dn <= DBL_EPSILON ? "correction at working precision"
                                                 : "correction stopped halving")
                            : "backward error stopped halving";
            break;
        }
        be = ben;
        dprev = dn;
    }
    if (kept > 0) {
        silc_value *out = field_dense_new(n, k, w, X);
        if (out) {
            val_release(call->out);
            call->out = out;
        } else {
            kept = 0;
            stop = "out of memory";
        }
    }
    r->refine_steps = (int)kept;
    r->backward_error_unrefined = be0;
    snprintf(note, sizeof note, "refinement (%s residual): %lld step%s, backward error %.2g -> %.2g (%.60s)",
             extended ? "double-double" : "double", (long long)kept, kept == 1 ? "" : "s", be0,
             kept ? be : be0, stop);
    add_note(r, note);
    /* A single-precision factor gains about -log10(cond * eps_single) digits
     * per step, none once the (scaled) matrix's condition reaches
     * 1 / eps_single: then x is about as bad as the single solve, and says so. */
    if (r->single_factor && !((kept ? be : be0) <= fmax(REFINE_SINGLE_CONVERGED, enough)))
        eng_warn(E,
                 "'\\': refinement of %s's single-precision factorization stopped at backward "
                 "error %.2g (%s): too ill-conditioned for a single-precision factor, use a "
                 "double one",
                 how->backend, kept ? be : be0, stop);
done:
    r->seconds += util_now() - t0;
    free(B);
    free(X);
    free(R);
    free(lo);
}
