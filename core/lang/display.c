/*
 * display.c -- how a value is shown: `x = 3`, a small matrix in full, a
 * large one summarised, and `disp(x)`.
 *
 * The layout is Octave's, so that a user comparing the two sees the same
 * text for the common cases (tests/conformance/octave holds Octave's own
 * output for them): a scalar on the name's line (`x = 3.1416`); a matrix
 * after `A =` and a blank line, every column in one field width with two
 * spaces between, integers as integers, otherwise a fixed number of
 * decimals chosen from the largest and smallest magnitudes (Octave's
 * make_real_matrix_format), or the e-format when that field would be wider
 * than the precision allows; an empty value as `[](0x3)`; a small sparse
 * value as Octave lists one, `(i, j) -> v` in column order.  `format long`
 * (core.format = long) shows 16 significant digits instead of 5.
 *
 * What Octave would print in screenfuls -- more than DP_MAX_ROWS rows or
 * DP_MAX_COLS columns, or a sparse value of more than DP_MAX_SPARSE entries
 * -- is summarised instead: size, format, nnz and the top-left corner.  Wide
 * rows are split into column chunks of at most DP_WIDTH characters, as
 * Octave's "Columns 1 through 8:".
 *
 * A complex value is shown as Octave's make_complex_format shows it: each
 * entry "re + imi" (" - " when the imaginary part's sign bit is set, so
 * conj(3) is "3 - 0i"), the real part in a field one wider than the
 * imaginary part's (the sign column), both chosen as for a real value from
 * the digits of the largest and of the smallest magnitude over both parts;
 * a scalar keeps its field width ("z =  1 + 2i").
 */
#include "lang.h"
#include "dist.h"

#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define DP_MAX_ROWS 40
#define DP_MAX_COLS 40
#define DP_MAX_SPARSE 100
#define DP_CORNER 6     /* rows and columns of a summary's corner */
#define DP_WIDTH 80     /* a terminal's columns */

typedef struct dp_format {
    int integer;        /* every finite entry is a whole number */
    int efmt;           /* e-format */
    int fw, rd;         /* field width, decimals */
} dp_format;

/* Digits before the point of |x| (Octave's engineering num_digits): 1 for 3.2, 0 for 0.5, -1 for 0.05. */
static int digits_of(double x)
{
    return x == 0 ? 0 : (int)floor(log10(fabs(x))) + 1;
}

/* Octave's make_real_format / make_real_matrix_format for entries of
 * magnitudes in [min_abs, max_abs], at prec significant digits (5 short, 16
 * long).  Octave turns to the e-format when the digits a fixed layout needs
 * pass min(prec + 2, 16) -- a matrix of integers counting its sign column --
 * which is what its 7.3 prints (1234567 stays whole in short, 12345678 and
 * [1 1234567] do not; 0.031416 is fixed in short, e-format in long). */
static void choose_format_digits(dp_format *f, int x_max, int x_min, int all_int, int scalar, int nonfinite,
                                 int prec)
{
    int ld = 1, rd = 1, side, limit = prec + 2 < 16 ? prec + 2 : 16;
    memset(f, 0, sizeof *f);
    if (all_int) {
        int d = x_max > x_min ? x_max : x_min;
        if (d < 1) d = 1;
        if (d + (scalar ? 0 : 1) <= limit) {
            f->integer = 1;
            f->fw = d + 1;   /* Octave keeps a column for the sign, negative or not */
            if (nonfinite && f->fw < 4) f->fw = 4;
            return;
        }
        f->efmt = 1;
    }
    for (side = 0; side < 2 && !f->efmt; side++) {
        int x = side == 0 ? x_max : x_min, l, r;
        if (x > 0) {
            l = x;
            r = prec > x ? prec - x : prec;
        } else if (x < 0) {
            l = 1;
            r = prec > x ? prec - x : prec;
        } else {
            l = 1;
            r = prec > 1 ? prec - 1 : prec;
        }
        if (side == 0 || l > ld) ld = l;
        if (side == 0 || r > rd) rd = r;
    }
    if (f->efmt || ld + rd > limit) {
        f->efmt = 1;
        f->rd = prec - 1;
        f->fw = 1 + 1 + 1 + f->rd + 4;   /* sign, digit, point, decimals, e+NN */
        return;
    }
    f->rd = rd;
    f->fw = 1 + ld + 1 + rd;
    if (nonfinite && f->fw < 4) f->fw = 4;
}

static void choose_format(dp_format *f, double max_abs, double min_abs, int all_int, int scalar,
                          int nonfinite, int prec)
{
    choose_format_digits(f, digits_of(max_abs), digits_of(min_abs), all_int, scalar, nonfinite, prec);
}

/* Largest and smallest magnitude of the finite numbers seen, and whether
 * they are all whole and any was not finite. */
typedef struct dp_range {
    double max_abs, min_abs;
    int all_int, nonfinite, any;
} dp_range;

static void range_start(dp_range *r)
{
    r->max_abs = 0, r->min_abs = HUGE_VAL;
    r->all_int = 1, r->nonfinite = 0, r->any = 0;
}

static void range_add(dp_range *r, double x)
{
    if (!isfinite(x)) {
        r->nonfinite = 1;
        return;
    }
    r->any = 1;
    if (fabs(x) > r->max_abs) r->max_abs = fabs(x);
    if (fabs(x) < r->min_abs) r->min_abs = fabs(x);
    if (x != floor(x)) r->all_int = 0;
}

/* Octave's complex format from the ranges of the real and imaginary parts:
 * for a matrix the digits of the larger maximum and of the larger minimum
 * (make_complex_matrix_format), for a scalar the digits of the larger and
 * of the smaller part (make_complex_scalar_format: 1e-3 + 2i is shown in
 * the e-format, [1e-3 + 1i, 100] is not); f->fw is then the real part's
 * field, f->fw - 1 the imaginary part's. */
static void choose_complex_format(dp_format *f, dp_range *re, dp_range *im, int scalar, int prec)
{
    int r_max, r_min, i_max, i_min, x_max, x_min;
    if (!re->any) re->min_abs = 0;
    if (!im->any) im->min_abs = 0;
    r_max = digits_of(re->max_abs), r_min = digits_of(re->min_abs);
    i_max = digits_of(im->max_abs), i_min = digits_of(im->min_abs);
    x_max = r_max > i_max ? r_max : i_max;
    x_min = scalar ? (r_max < i_max ? r_max : i_max) : r_min > i_min ? r_min : i_min;
    choose_format_digits(f, x_max, x_min, re->all_int && im->all_int, scalar, re->nonfinite || im->nonfinite,
                         prec);
}

/* The format for a set of entries: get(k) for k < count. */
static void format_for(dp_format *f, const silc_value *v, const int64_t *rows, const int64_t *cols,
                       int64_t nr, int64_t nc, int prec)
{
    double max_abs = 0, min_abs = HUGE_VAL;
    int all_int = 1, nonfinite = 0, any = 0;
    int64_t i, j;
    if (v->field == SILC_FIELD_COMPLEX) {
        dp_range re, im;
        range_start(&re);
        range_start(&im);
        for (j = 0; j < nc; j++)
            for (i = 0; i < nr; i++) {
                double complex z = val_get_complex(v, rows ? rows[i] : i, cols ? cols[j] : j);
                range_add(&re, creal(z));
                range_add(&im, cimag(z));
            }
        choose_complex_format(f, &re, &im, 0, prec);
        return;
    }
    for (j = 0; j < nc; j++)
        for (i = 0; i < nr; i++) {
            double x = val_get(v, rows ? rows[i] : i, cols ? cols[j] : j);
            if (!isfinite(x)) {
                nonfinite = 1;
                continue;
            }
            any = 1;
            if (fabs(x) > max_abs) max_abs = fabs(x);
            if (fabs(x) < min_abs) min_abs = fabs(x);
            if (x != floor(x)) all_int = 0;
        }
    if (!any) min_abs = 0;
    choose_format(f, max_abs, min_abs, all_int, 0, nonfinite, prec);
}

static void put_number(strbuf *b, const dp_format *f, double x, int width)
{
    if (isnan(x)) sb_printf(b, "%*s", width, "NaN");
    else if (isinf(x)) sb_printf(b, "%*s", width, x < 0 ? "-Inf" : "Inf");
    else if (f->integer || x == 0) sb_printf(b, "%*.0f", width, 0.0 * 0 + x + 0.0);  /* Octave writes 0, never -0 */
    else if (f->efmt) sb_printf(b, "%*.*e", width, f->rd, x);
    else sb_printf(b, "%*.*f", width, f->rd, x);
}

/* re + imi with the real part in width, the imaginary part in width - 1
 * (width 0: as narrow as they go). */
static void put_complex(strbuf *b, const dp_format *f, double complex z, int width)
{
    double im = cimag(z);
    put_number(b, f, creal(z), width);
    sb_puts(b, signbit(im) && !isnan(im) ? " - " : " + ");
    put_number(b, f, isnan(im) ? im : fabs(im), width > 0 ? width - 1 : 0);
    sb_puts(b, "i");
}

/* Rows and columns of v (all of them, or a corner) in chunks that fit DP_WIDTH. */
static void put_matrix(strbuf *b, const silc_value *v, int64_t nr, int64_t nc, int prec)
{
    dp_format f;
    int64_t per, c0, i, j;
    int cplx = v->field == SILC_FIELD_COMPLEX;
    format_for(&f, v, NULL, NULL, nr, nc, prec);
    /* Octave's column widths: 2 spaces before a real entry; a complex one
     * takes both fields and 7 more (" + ", "i", the separator) */
    per = DP_WIDTH / (cplx ? 2 * f.fw - 1 + 7 : f.fw + 2);
    if (per < 1) per = 1;
    for (c0 = 0; c0 < nc; c0 += per) {
        int64_t c1 = c0 + per < nc ? c0 + per : nc;
        if (nc > per) {
            if (c1 - c0 == 1) sb_printf(b, " Column %lld:\n\n", (long long)c0 + 1);
            else if (c1 == nc && c1 - c0 == 2)
                sb_printf(b, " Columns %lld and %lld:\n\n", (long long)c0 + 1, (long long)c1);
            else
                sb_printf(b, " Columns %lld through %lld:\n\n", (long long)c0 + 1, (long long)c1);
        }
        for (i = 0; i < nr; i++) {
            for (j = c0; j < c1; j++) {
                sb_puts(b, "  ");
                if (cplx) put_complex(b, &f, val_get_complex(v, i, j), f.fw);
                else put_number(b, &f, val_get(v, i, j), f.fw);
            }
            sb_puts(b, "\n");
        }
        if (c1 < nc) sb_puts(b, "\n");
    }
}

/* Octave's listing of a small sparse value: (i, j) -> v in column order. */
static void put_sparse(strbuf *b, const silc_value *v, int64_t nnz, int prec)
{
    dp_format f;
    double max_abs = 0, min_abs = HUGE_VAL;
    int all_int = 1, nonfinite = 0;
    int64_t i, j, wi = digits_of((double)v->m), wj = digits_of((double)v->n);
    for (i = 0; i < v->m; i++)
        for (j = 0; j < v->n; j++) {
            double x = val_get(v, i, j);
            if (x == 0) continue;
            if (!isfinite(x)) {
                nonfinite = 1;
                continue;
            }
            if (fabs(x) > max_abs) max_abs = fabs(x);
            if (fabs(x) < min_abs) min_abs = fabs(x);
            if (x != floor(x)) all_int = 0;
        }
    if (min_abs == HUGE_VAL) min_abs = 0;
    choose_format(&f, max_abs, min_abs, all_int, 1, nonfinite, prec);
    if (v->field == SILC_FIELD_COMPLEX) {
        dp_range re, im;
        range_start(&re);
        range_start(&im);
        for (i = 0; i < v->m; i++)
            for (j = 0; j < v->n; j++) {
                double complex z = val_get_complex(v, i, j);
                if (z == 0) continue;
                range_add(&re, creal(z));
                range_add(&im, cimag(z));
            }
        choose_complex_format(&f, &re, &im, 0, prec);
    }
    sb_printf(b, "Compressed Column Sparse (rows = %lld, cols = %lld, nnz = %lld [%.0f%%])\n\n",
              (long long)v->m, (long long)v->n, (long long)nnz,
              100.0 * (double)nnz / ((double)v->m * (double)v->n));
    /* column order; the value is at most DP_MAX_SPARSE entries of a bounded
     * shape here (show_value), so the full scan is small */
    for (j = 0; j < v->n; j++)
        for (i = 0; i < v->m; i++) {
            double complex z = val_get_complex(v, i, j);
            if (z == 0) continue;
            sb_printf(b, "  (%*lld, %*lld) -> ", (int)wi, (long long)i + 1, (int)wj, (long long)j + 1);
            if (v->field == SILC_FIELD_COMPLEX) put_complex(b, &f, z, f.fw);
            else put_number(b, &f, creal(z), 0);
            sb_puts(b, "\n");
        }
}

void dp_show(silc_engine *E, strbuf *b, const char *name, const silc_value *v)
{
    const char *style = cfg_get(E, "core.format");
    int prec = style && !strcmp(style, "long") ? 16 : 5;
    int64_t nnz;
    if (dist_is(v)) {
        sb_printf(b, "%s%s%lldx%lld %s, distributed by rows over the ranks\n", name ? name : "",
                  name ? " = " : "", (long long)v->m, (long long)v->n, val_format_name(v->format));
        return;
    }
    if (v->m == 0 || v->n == 0) {
        sb_printf(b, "%s%s[](%lldx%lld)\n", name ? name : "", name ? " = " : "", (long long)v->m,
                  (long long)v->n);
        return;
    }
    if (v->m == 1 && v->n == 1 && v->field == SILC_FIELD_COMPLEX) {
        dp_format f;
        dp_range re, im;
        double complex z = val_get_complex(v, 0, 0);
        range_start(&re);
        range_start(&im);
        range_add(&re, creal(z));
        range_add(&im, cimag(z));
        choose_complex_format(&f, &re, &im, 1, prec);
        if (name) sb_printf(b, "%s = ", name);
        put_complex(b, &f, z, f.fw);
        sb_puts(b, "\n");
        return;
    }
    if (v->m == 1 && v->n == 1) {
        dp_format f;
        double x = val_get(v, 0, 0);
        double a = isfinite(x) ? fabs(x) : 0;
        choose_format(&f, a, a, !isfinite(x) || x == floor(x), 1, !isfinite(x), prec);
        if (name) sb_printf(b, "%s = ", name);
        put_number(b, &f, x, 0);
        sb_puts(b, "\n");
        return;
    }
    nnz = val_props_part(v, SILC_PROPS_SHAPE)->nnz;
    if (v->format == SILC_FMT_CSR && nnz <= DP_MAX_SPARSE && v->m <= 1000 && v->n <= 1000) {
        if (name) sb_printf(b, "%s =\n\n", name);
        put_sparse(b, v, nnz, prec);
        sb_puts(b, "\n");
        return;
    }
    if (v->format != SILC_FMT_CSR && v->m <= DP_MAX_ROWS && v->n <= DP_MAX_COLS) {
        if (name) sb_printf(b, "%s =\n\n", name);
        put_matrix(b, v, v->m, v->n, prec);
        if (name) sb_puts(b, "\n");
        return;
    }
    sb_printf(b, "%s%s%lldx%lld %s, nnz %lld (%.3g%%); the top-left corner:\n\n", name ? name : "",
              name ? " = " : "", (long long)v->m, (long long)v->n, val_format_name(v->format),
              (long long)nnz, 100.0 * (double)nnz / ((double)v->m * (double)v->n));
    put_matrix(b, v, v->m < DP_CORNER ? v->m : DP_CORNER, v->n < DP_CORNER ? v->n : DP_CORNER, prec);
    sb_puts(b, "\n");
}
