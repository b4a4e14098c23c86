/*
 * ref_elementwise_z.c -- ADD, SCALE, EWISE, MAP, TRANSPOSE and REDUCE on
 * complex operands (ABI 1.8), handed over by the real entry points of
 * ref_elementwise.c (CONVERT and DIAG serve both fields there).
 *
 * Result formats follow the real ops' rule: a CSR result when every
 * implicit zero maps to zero (f(0) == 0, f(0,0) == 0, or a product with a
 * sparse operand), the operand's own structure for SCALE, MAP and
 * TRANSPOSE, dense otherwise; only ADD of two band values gives CSR here
 * rather than band (the union of the patterns, same values).  Results that
 * are real by definition (abs, real, imag, angle, not, the comparisons and
 * the logical operators, the norms) are real values.  Comparisons follow
 * Octave: == and != compare both parts, <, <=, >, >= the real parts; max
 * and min compare moduli, ties going to the larger angle.
 */
#include "ref.h"

#include <complex.h>
#include <float.h>
#include <math.h>
#include <string.h>

/* C11's CMPLX, which glibc defines for gcc but not for clang 14 (the
 * libFuzzer builds compile this file with clang). */
#ifndef CMPLX
#define CMPLX(x, y) __builtin_complex((double)(x), (double)(y))
#endif

typedef double complex zc;

static zc *zval(const silc_view *v)
{
    return (zc *)v->val;
}

/* re + i im, exact for infinite parts too (re + I * im is not: I * inf
 * gives a NaN real part); C11's CMPLX is missing from some compilers'
 * headers (clang's C99 mode in the fuzz build). */
static zc zmake(double re, double im)
{
    double parts[2] = {re, im};
    zc z;
    memcpy(&z, parts, sizeof z);
    return z;
}

static zc zget(const silc_view *v, int64_t i, int64_t j)
{
    zc z;
    ref_view_get_w(v, 2, i, j, (double *)&z);
    return z;
}

static int is_scalar(const silc_view *v)
{
    return v->m == 1 && v->n == 1;
}

/* Returns the m x n dense array D (w doubles per entry) as a value, freeing D. */
static int out_dense(silc_call *call, int64_t m, int64_t n, int w, double *D)
{
    if (!D) return ref_nomem(call);
    call->out = ref_value_from_dense_w(m, n, w, D);
    ref_free(D);
    return call->out ? 0 : ref_nomem(call);
}

static int both_complex(silc_call *call, const char *op)
{
    if (ref_width(call->in[0]) == 2 && ref_width(call->in[1]) == 2) return 1;
    ref_host->error(call, SILC_EARG, "%s: one operand is complex and the other real (the host promotes the real one first)",
                    op);
    return 0;
}

/* ---- merging sparse rows ------------------------------------------------------ */

typedef zc (*zcomb_fn)(zc a, zc b, const void *ctx);

/* Row-wise union (or intersection) of the row-compressed complex A and B,
 * each result entry f(a, b) with absent entries read as 0; the result has w
 * doubles per entry (1: the real part of f, which is then real). */
static int merge_rows(silc_call *call, const ref_sp *A, const ref_sp *B, int intersect, zcomb_fn f,
                      const void *ctx, int w)
{
    int64_t rows = A->n, cols = A->m;
    const zc *Ax = (const zc *)A->x, *Bx = (const zc *)B->x;
    ref_sp R;
    int64_t cap = intersect ? ref_sp_nnz(A) : ref_sp_nnz(A) + ref_sp_nnz(B);
    if (ref_sp_alloc(&R, cols, rows, cap, w)) return ref_nomem(call);
    int64_t nz = 0;
    for (int64_t r = 0; r < rows; r++) {
        R.p[r] = nz;
        int64_t ka = A->p[r], ea = A->p[r + 1], kb = B->p[r], eb = B->p[r + 1];
        while (ka < ea || kb < eb) {
            int64_t ca = ka < ea ? A->i[ka] : INT64_MAX, cb = kb < eb ? B->i[kb] : INT64_MAX;
            zc va = 0.0, vb = 0.0;
            int64_t c = ca < cb ? ca : cb;
            if (ca == c) va = Ax[ka++];
            if (cb == c) vb = Bx[kb++];
            if (intersect && ca != cb) continue;
            zc v = f(va, vb, ctx);
            R.i[nz] = c;
            if (w == 2) ((zc *)R.x)[nz++] = v;
            else R.x[nz++] = creal(v);
        }
    }
    R.p[rows] = nz;
    call->out = ref_value_from_rows_w(&R, w);
    ref_sp_free(&R);
    return call->out ? 0 : ref_nomem(call);
}

/* Both operands by rows (compressed columns of their transposes). */
static int rows_pair(const silc_view *a, const silc_view *b, ref_sp *A, ref_sp *B)
{
    if (ref_spt_from_view_w(a, 2, A)) return SILC_ENOMEM;
    if (ref_spt_from_view_w(b, 2, B)) {
        ref_sp_free(A);
        return SILC_ENOMEM;
    }
    return 0;
}

/* ---- SCALE, ADD ------------------------------------------------------------------ */

static int scale_copy(silc_call *call, const silc_view *v, zc alpha)
{
    silc_value *out = ref_same_structure(v, 2);
    if (!out) return ref_nomem(call);
    silc_view o;
    ref_host->view(out, &o);
    int64_t nz = ref_stored(v);
    for (int64_t k = 0; k < nz; k++) zval(&o)[k] = alpha * zval(v)[k];
    call->out = out;
    return 0;
}

int ref_op_scale_z(silc_call *call)
{
    silc_view a;
    ref_host->view(call->in[0], &a);
    return scale_copy(call, &a, zmake(call->alpha, call->alpha_imag));
}

typedef struct lin_ctx {
    zc alpha, beta;
} lin_ctx;

static zc lin(zc a, zc b, const void *ctx)
{
    const lin_ctx *c = ctx;
    return c->alpha * a + c->beta * b;
}

int ref_op_add_z(silc_call *call)
{
    if (!both_complex(call, "add")) return SILC_EARG;
    silc_view a, b;
    ref_host->view(call->in[0], &a);
    ref_host->view(call->in[1], &b);
    zc al = zmake(call->alpha, call->alpha_imag), be = zmake(call->beta, call->beta_imag);
    int sa = is_scalar(&a), sb = is_scalar(&b);
    if (sa != sb) {
        const silc_view *X = sa ? &b : &a;
        zc cx = sa ? be : al, s = sa ? al * zget(&a, 0, 0) : be * zget(&b, 0, 0);
        if (s == 0.0) return scale_copy(call, X, cx);
        zc *D = (zc *)ref_dense_from_view_w(X, 2);
        if (!D) return ref_nomem(call);
        for (int64_t k = 0; k < X->m * X->n; k++) D[k] = cx * D[k] + s;
        return out_dense(call, X->m, X->n, 2, (double *)D);
    }
    if (a.m != b.m || a.n != b.n)
        return ref_host->error(call, SILC_EARG, "add: shapes %lldx%lld and %lldx%lld differ",
                               (long long)a.m, (long long)a.n, (long long)b.m, (long long)b.n);
    if (a.format != SILC_FMT_DENSE && b.format != SILC_FMT_DENSE) {
        ref_sp A, B;
        if (rows_pair(&a, &b, &A, &B)) return ref_nomem(call);
        lin_ctx c = {al, be};
        int st = merge_rows(call, &A, &B, 0, lin, &c, 2);
        ref_sp_free(&A);
        ref_sp_free(&B);
        return st;
    }
    zc *A = (zc *)ref_dense_from_view_w(&a, 2), *B = (zc *)ref_dense_from_view_w(&b, 2);
    if (!A || !B) {
        ref_free(A);
        ref_free(B);
        return ref_nomem(call);
    }
    for (int64_t k = 0; k < a.m * a.n; k++) A[k] = al * A[k] + be * B[k];
    ref_free(B);
    return out_dense(call, a.m, a.n, 2, (double *)A);
}

/* ---- EWISE ---------------------------------------------------------------------- */

/* Octave's order for max/min of complex numbers: by modulus, then angle. */
static int zless(zc a, zc b)
{
    double ma = cabs(a), mb = cabs(b);
    return ma < mb || (ma == mb && carg(a) < carg(b));
}

/* The subs whose result is real (0 or 1). */
static int ew_real_result(int sub)
{
    return sub >= SILC_EW_EQ;
}

static zc ewz(int sub, zc a, zc b)
{
    switch (sub) {
    case SILC_EW_MUL: return a * b;
    case SILC_EW_DIV: return a / b;
    case SILC_EW_POW: return b == 0.0 ? 1.0 : cpow(a, b); /* x^0 = 1, as Octave (cpow(0, 0) is NaN) */
    case SILC_EW_MAX:
        if (isnan(creal(a)) || isnan(cimag(a))) return b; /* NaN ignored, as the real fmax */
        if (isnan(creal(b)) || isnan(cimag(b))) return a;
        return zless(a, b) ? b : a;
    case SILC_EW_MIN:
        if (isnan(creal(a)) || isnan(cimag(a))) return b;
        if (isnan(creal(b)) || isnan(cimag(b))) return a;
        return zless(b, a) ? b : a;
    case SILC_EW_EQ: return a == b;
    case SILC_EW_NE: return a != b;
    case SILC_EW_LT: return creal(a) < creal(b);
    case SILC_EW_LE: return creal(a) <= creal(b);
    case SILC_EW_GT: return creal(a) > creal(b);
    case SILC_EW_GE: return creal(a) >= creal(b);
    case SILC_EW_AND: return a != 0.0 && b != 0.0;
    default: return a != 0.0 || b != 0.0;
    }
}

static zc ew_comb(zc a, zc b, const void *ctx)
{
    return ewz(*(const int *)ctx, a, b);
}

/* CSR X with every stored entry combined with the matching entry of Y (a
 * scalar broadcast when Y is 1x1); X on the left when x_left. */
static int ew_on_pattern(silc_call *call, const silc_view *X, const silc_view *Y, int x_left, int w)
{
    silc_value *out = ref_same_structure(X, w);
    if (!out) return ref_nomem(call);
    silc_view o;
    ref_host->view(out, &o);
    int sy = is_scalar(Y);
    zc s = sy ? zget(Y, 0, 0) : 0.0;
    for (int64_t i = 0; i < X->m; i++)
        for (int64_t k = X->rowptr[i]; k < X->rowptr[i + 1]; k++) {
            zc y = sy ? s : zget(Y, i, X->colind[k]);
            zc v = x_left ? ewz(call->sub, zval(X)[k], y) : ewz(call->sub, y, zval(X)[k]);
            if (w == 2) zval(&o)[k] = v;
            else o.val[k] = creal(v);
        }
    call->out = out;
    return 0;
}

int ref_op_ewise_z(silc_call *call)
{
    if (!both_complex(call, "element-wise")) return SILC_EARG;
    silc_view a, b;
    ref_host->view(call->in[0], &a);
    ref_host->view(call->in[1], &b);
    int sub = call->sub;
    if (sub < SILC_EW_MUL || sub > SILC_EW_OR)
        return ref_host->error(call, SILC_EUNSUP, "element-wise operation %d is unknown", sub);
    int sa = is_scalar(&a), sb = is_scalar(&b), w = ew_real_result(sub) ? 1 : 2;
    if (!sa && !sb && (a.m != b.m || a.n != b.n))
        return ref_host->error(call, SILC_EARG, "element-wise: shapes %lldx%lld and %lldx%lld differ",
                               (long long)a.m, (long long)a.n, (long long)b.m, (long long)b.n);
    int ca = !sa && a.format == SILC_FMT_CSR, cb = !sb && b.format == SILC_FMT_CSR;
    int sparse_mul = sub == SILC_EW_MUL && (ca || cb);
    if ((ca && cb && (sparse_mul || ewz(sub, 0.0, 0.0) == 0.0))) {
        ref_sp A, B;
        if (rows_pair(&a, &b, &A, &B)) return ref_nomem(call);
        int st = merge_rows(call, &A, &B, sparse_mul, ew_comb, &sub, w);
        ref_sp_free(&A);
        ref_sp_free(&B);
        return st;
    }
    if (ca && (sparse_mul || (sb && ewz(sub, 0.0, zget(&b, 0, 0)) == 0.0))) return ew_on_pattern(call, &a, &b, 1, w);
    if (cb && (sparse_mul || (sa && ewz(sub, zget(&a, 0, 0), 0.0) == 0.0))) return ew_on_pattern(call, &b, &a, 0, w);
    int64_t m = sa ? b.m : a.m, n = sa ? b.n : a.n;
    zc *A = (zc *)ref_dense_from_view_w(&a, 2), *B = (zc *)ref_dense_from_view_w(&b, 2);
    double *D = ref_alloc((size_t)(m * n * w), sizeof(double));
    if (!A || !B || !D) {
        ref_free(A);
        ref_free(B);
        ref_free(D);
        return ref_nomem(call);
    }
    for (int64_t k = 0; k < m * n; k++) {
        zc v = ewz(sub, A[sa ? 0 : k], B[sb ? 0 : k]);
        if (w == 2) ((zc *)D)[k] = v;
        else D[k] = creal(v);
    }
    ref_free(A);
    ref_free(B);
    return out_dense(call, m, n, w, D);
}

/* ---- MAP ------------------------------------------------------------------------ */

static int map_real_result(int sub)
{
    return sub == SILC_MAP_ABS || sub == SILC_MAP_NOT || sub == SILC_MAP_REAL || sub == SILC_MAP_IMAG ||
           sub == SILC_MAP_ANGLE;
}

static zc mapz(int sub, zc x)
{
    switch (sub) {
    case SILC_MAP_NEG: return -x;
    case SILC_MAP_ABS: return cabs(x);
    case SILC_MAP_SQRT: return csqrt(x); /* principal branch */
    case SILC_MAP_EXP: return cexp(x);
    case SILC_MAP_LOG: return clog(x); /* principal branch */
    case SILC_MAP_SIN: return csin(x);
    case SILC_MAP_COS: return ccos(x);
    case SILC_MAP_REAL: return creal(x);
    case SILC_MAP_IMAG: return cimag(x);
    case SILC_MAP_CONJ: return conj(x);
    case SILC_MAP_ANGLE: return carg(x);
    default: return x == 0.0;
    }
}

int ref_op_map_z(silc_call *call)
{
    silc_view a;
    ref_host->view(call->in[0], &a);
    int sub = call->sub;
    if (sub < SILC_MAP_NEG || sub > SILC_MAP_ANGLE)
        return ref_host->error(call, SILC_EUNSUP, "map function %d is unknown", sub);
    int w = map_real_result(sub) ? 1 : 2;
    if (a.format == SILC_FMT_DENSE || mapz(sub, 0.0) == 0.0) {
        silc_value *out = ref_same_structure(&a, w);
        if (!out) return ref_nomem(call);
        silc_view o;
        ref_host->view(out, &o);
        int64_t nz = ref_stored(&a);
        for (int64_t k = 0; k < nz; k++) {
            zc v = mapz(sub, zval(&a)[k]);
            if (w == 2) zval(&o)[k] = v;
            else o.val[k] = creal(v);
        }
        call->out = out;
        return 0;
    }
    zc *A = (zc *)ref_dense_from_view_w(&a, 2);
    double *D = ref_alloc((size_t)(a.m * a.n * w), sizeof(double));
    if (!A || !D) {
        ref_free(A);
        ref_free(D);
        return ref_nomem(call);
    }
    for (int64_t k = 0; k < a.m * a.n; k++) {
        zc v = mapz(sub, A[k]);
        if (w == 2) ((zc *)D)[k] = v;
        else D[k] = creal(v);
    }
    ref_free(A);
    return out_dense(call, a.m, a.n, w, D);
}

/* ---- TRANSPOSE ------------------------------------------------------------------ */

/* sub 0: A' (conjugate transpose), sub 1: A.' (plain). */
int ref_op_transpose_z(silc_call *call)
{
    silc_view a;
    ref_host->view(call->in[0], &a);
    int cj = call->sub == 0;
    if (a.format == SILC_FMT_CSR) {
        ref_sp C; /* compressed columns of A = the rows of A.' */
        if (ref_sp_from_view_w(&a, 2, &C)) return ref_nomem(call);
        if (cj)
            for (int64_t k = 0; k < ref_sp_nnz(&C); k++) ((zc *)C.x)[k] = conj(((zc *)C.x)[k]);
        call->out = ref_value_from_rows_w(&C, 2);
        ref_sp_free(&C);
        return call->out ? 0 : ref_nomem(call);
    }
    if (a.format == SILC_FMT_BAND) {
        silc_value *out = ref_host->band_new_complex(a.n, a.m, a.ku, a.kl);
        if (!out) return ref_nomem(call);
        silc_view o;
        ref_host->view(out, &o);
        for (int64_t j = 0; j < a.n; j++) {
            int64_t lo = j - a.ku > 0 ? j - a.ku : 0, hi = j + a.kl + 1 < a.m ? j + a.kl + 1 : a.m;
            for (int64_t i = lo; i < hi; i++) {
                zc v = zval(&a)[(a.ku + i - j) + j * a.ld];
                zval(&o)[(o.ku + j - i) + i * o.ld] = cj ? conj(v) : v;
            }
        }
        call->out = out;
        return 0;
    }
    zc *D = ref_alloc((size_t)(a.m * a.n), sizeof(zc));
    if (!D) return ref_nomem(call);
    for (int64_t j = 0; j < a.n; j++)
        for (int64_t i = 0; i < a.m; i++) {
            zc v = zval(&a)[i + j * a.m];
            D[j + i * a.n] = cj ? conj(v) : v;
        }
    return out_dense(call, a.n, a.m, 2, (double *)D);
}

/* ---- REDUCE ---------------------------------------------------------------------- */

/* The 2-norm of complex A: the largest singular value of the real
 * [Re -Im; Im Re] (2m x 2n), whose singular values are A's, each twice, so
 * the real kernel (ref_norm2) serves. */
static int znorm2(const ref_sp *C, double *out)
{
    int64_t m = C->m, n = C->n, nz = ref_sp_nnz(C);
    const zc *x = (const zc *)C->x;
    ref_sp R;
    if (ref_sp_alloc(&R, 2 * m, 2 * n, 4 * nz, 1)) return SILC_ENOMEM;
    int64_t q = 0;
    for (int half = 0; half < 2; half++) /* columns j (half 0) and n + j (half 1) */
        for (int64_t j = 0; j < n; j++) {
            R.p[half * n + j] = q;
            for (int64_t k = C->p[j]; k < C->p[j + 1]; k++) { /* upper block rows first */
                R.i[q] = C->i[k];
                R.x[q++] = half ? -cimag(x[k]) : creal(x[k]);
            }
            for (int64_t k = C->p[j]; k < C->p[j + 1]; k++) {
                R.i[q] = m + C->i[k];
                R.x[q++] = half ? creal(x[k]) : cimag(x[k]);
            }
        }
    R.p[2 * n] = q;
    int st = ref_norm2(&R, out);
    ref_sp_free(&R);
    return st;
}

int ref_op_reduce_z(silc_call *call)
{
    silc_view a;
    ref_host->view(call->in[0], &a);
    int sub = call->sub;
    int vec = a.m == 1 || a.n == 1;
    if (sub == SILC_RED_DOT) {
        silc_view b;
        if (call->nin < 2) return ref_host->error(call, SILC_EARG, "dot: needs two operands");
        if (!both_complex(call, "dot")) return SILC_EARG;
        ref_host->view(call->in[1], &b);
        if (a.m != b.m || a.n != b.n)
            return ref_host->error(call, SILC_EARG, "dot: shapes %lldx%lld and %lldx%lld differ",
                                   (long long)a.m, (long long)a.n, (long long)b.m, (long long)b.n);
        zc r = 0.0;
        if (a.format == SILC_FMT_CSR || b.format == SILC_FMT_CSR) {
            const silc_view *S = a.format == SILC_FMT_CSR ? &a : &b, *O = S == &a ? &b : &a;
            for (int64_t i = 0; i < S->m; i++)
                for (int64_t k = S->rowptr[i]; k < S->rowptr[i + 1]; k++) r += zval(S)[k] * zget(O, i, S->colind[k]);
        } else {
            for (int64_t j = 0; j < a.n; j++)
                for (int64_t i = 0; i < a.m; i++) r += zget(&a, i, j) * zget(&b, i, j);
        }
        zc *D = ref_alloc(1, sizeof(zc));
        if (D) D[0] = r;
        return out_dense(call, 1, 1, 2, (double *)D);
    }
    ref_sp C;
    if (ref_sp_from_view_w(&a, 2, &C)) return ref_nomem(call);
    const zc *x = (const zc *)C.x;
    int64_t nz = ref_sp_nnz(&C);
    if (sub == SILC_RED_SUM || sub == SILC_RED_MAX || sub == SILC_RED_MIN) {
        if (sub != SILC_RED_SUM && a.m * a.n == 0) {
            ref_sp_free(&C);
            return ref_host->error(call, SILC_EARG, "%s of an empty %lldx%lld matrix",
                                   sub == SILC_RED_MAX ? "max" : "min", (long long)a.m, (long long)a.n);
        }
        int64_t groups = vec ? 1 : a.n, glen = vec ? a.m * a.n : a.m;
        zc *D = ref_alloc((size_t)groups, sizeof(zc));
        if (!D) {
            ref_sp_free(&C);
            return ref_nomem(call);
        }
        for (int64_t g = 0; g < groups; g++) {
            int64_t c0 = vec ? 0 : g, c1 = vec ? a.n : g + 1;
            int64_t cnt = C.p[c1] - C.p[c0], k = C.p[c0];
            zc acc = 0.0;
            if (sub == SILC_RED_SUM) {
                for (; k < C.p[c1]; k++) acc += x[k];
            } else { /* implicit zeros take part; NaN entries are skipped unless all are NaN */
                int have = cnt < glen;
                acc = cnt < glen ? 0.0 : NAN;
                for (; k < C.p[c1]; k++) {
                    if (isnan(creal(x[k])) || isnan(cimag(x[k]))) continue;
                    if (!have || (sub == SILC_RED_MAX ? zless(acc, x[k]) : zless(x[k], acc))) acc = x[k];
                    have = 1;
                }
            }
            D[g] = acc;
        }
        ref_sp_free(&C);
        return out_dense(call, 1, groups, 2, (double *)D);
    }
    double r = 0.0;
    int st = 0;
    if (sub == SILC_RED_NORMFRO || (sub == SILC_RED_NORM && vec)) {
        r = ref_nrm2(2 * nz, C.x, 1); /* the moduli's 2-norm is the parts' */
    } else if (sub == SILC_RED_NORM) {
        st = znorm2(&C, &r);
    } else if (sub == SILC_RED_NORM1 || sub == SILC_RED_NORMINF) {
        st = ref_sp_norm1_inf(&C, a.m, a.n, vec, sub == SILC_RED_NORM1, 2, &r);
    } else {
        ref_sp_free(&C);
        return ref_host->error(call, SILC_EUNSUP, "reduction %d is unknown", sub);
    }
    ref_sp_free(&C);
    if (st) return ref_nomem(call);
    double *D = ref_alloc(1, sizeof(double));
    if (D) D[0] = r;
    return out_dense(call, 1, 1, 1, D);
}
