/*
 * mmio.c -- Matrix Market files to and from envelopes.
 *
 * Reading builds CSR from coordinate files (real, integer, pattern or
 * complex; general, symmetric or skew-symmetric, the stored triangle
 * mirrored, and for complex files hermitian, mirrored conjugated) and a
 * dense envelope from array files; a complex file gives a complex envelope
 * (two numbers a line: real and imaginary part).  Nothing is summed: a repeated (i, j) --
 * also one created by mirroring -- is an error naming both lines, because a
 * file that says the same entry twice is more likely broken than meant.
 * Explicit zeros are kept.  Every message names file:line.  Lines are read
 * whole (at most MM_MAX_LINE bytes: a file is input, so no line of it may make
 * the reader allocate without bound) and parsed with strtoll/strtod, which
 * reads a 150k-entry file in a few tens of milliseconds.
 */
#define _POSIX_C_SOURCE 200809L
#include "silc.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "store.h"
#include "util.h"

enum mm_field { MM_REAL, MM_INTEGER, MM_PATTERN, MM_COMPLEX };
enum mm_sym { MM_GENERAL, MM_SYMMETRIC, MM_SKEW, MM_HERMITIAN };

/* Doubles an entry of a field: a complex entry is its real and imaginary part. */
static int mm_width(int field)
{
    return field == MM_COMPLEX ? 2 : 1;
}

/* The mirror (j, i) of an entry (i, j) of value x (w doubles) under sym:
 * the same, negated, or conjugated. */
static void mm_mirror(int sym, int w, const double *x, double *out)
{
    out[0] = sym == MM_SKEW ? -x[0] : x[0];
    if (w == 2) out[1] = sym == MM_SKEW || sym == MM_HERMITIAN ? -x[1] : x[1];
}

/* A data line holds one entry ("row col value"); comments are free text.
 * 64 KiB is far beyond either, and bounds what one line can allocate. */
#define MM_MAX_LINE 65536

typedef struct mm_reader {
    FILE *f;
    const char *path;
    char *line;
    size_t cap;
    int64_t lineno;
    char *err;
    size_t errlen;
    int failed;            /* a message is set: later ones would only follow from it */
    int allow_nonfinite;   /* SILC_MM_ALLOW_NONFINITE=1: inf, nan and overflow read as IEEE values */
} mm_reader;

/* Formats "path:line: message" into the caller's buffer and the context-free
 * message buffer; returns -1. */
static int mm_fail(mm_reader *r, int64_t line, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static int mm_fail(mm_reader *r, int64_t line, const char *fmt, ...)
{
    char msg[768];
    va_list ap;
    if (r->failed) return -1;
    r->failed = 1;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (line > 0) env_error("%s:%lld: %s", r->path, (long long)line, msg);
    else env_error("%s: %s", r->path, msg);
    if (r->err && r->errlen) snprintf(r->err, r->errlen, "%s", env_error_last());
    return -1;
}

/* mm_fail at the column of position at in the current line:
 * "path:line:column: message". */
static int mm_fail_at(mm_reader *r, const char *at, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static int mm_fail_at(mm_reader *r, const char *at, const char *fmt, ...)
{
    char msg[700];
    va_list ap;
    if (r->failed) return -1;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    r->failed = 1;
    env_error("%s:%lld:%lld: %s", r->path, (long long)r->lineno, (long long)(at - r->line) + 1, msg);
    if (r->err && r->errlen) snprintf(r->err, r->errlen, "%s", env_error_last());
    return -1;
}

/* Reads the next line into r->line (with its newline, if any); 1 when there
 * is one, 0 at end of file, -1 when it is longer than MM_MAX_LINE or holds a
 * NUL byte (reported).  The FILE is this reader's alone, hence getc_unlocked. */
static int mm_read_line(mm_reader *r)
{
    size_t len = 0;
    int ch;
    while ((ch = getc_unlocked(r->f)) != EOF) {
        if (len + 2 > r->cap) {
            size_t cap = r->cap ? 2 * r->cap : 256;
            char *grown;
            if (cap > MM_MAX_LINE + 2) cap = MM_MAX_LINE + 2;
            if (len + 2 > cap)
                return mm_fail(r, r->lineno + 1, "line longer than %d bytes (not a Matrix Market file?)",
                               MM_MAX_LINE);
            if (!(grown = realloc(r->line, cap))) return mm_fail(r, r->lineno + 1, "out of memory");
            r->line = grown;
            r->cap = cap;
        }
        if (ch == 0) return mm_fail(r, r->lineno + 1, "a NUL byte: not a text file");
        r->line[len++] = (char)ch;
        if (ch == '\n') break;
    }
    /* a failed read is not the end of the file (a directory read as empty) */
    if (ch == EOF && ferror(r->f)) return mm_fail(r, r->lineno + 1, "cannot read: %s", strerror(errno));
    if (len == 0) return 0;
    r->line[len] = 0;
    r->lineno++;
    return 1;
}

/* Next line that is neither a comment nor blank; NULL at end of file or on a
 * line mm_read_line refuses (r->failed tells them apart). */
static char *mm_next_data_line(mm_reader *r)
{
    for (;;) {
        char *p;
        if (mm_read_line(r) <= 0) return NULL;
        p = r->line;
        while (isspace((unsigned char)*p)) p++;
        if (*p && *p != '%') return p;
    }
}

/* ---- tokens, by the format's rules --------------------------------------
 * Matrix Market numbers are decimal: an integer is [+-]digits within int64;
 * a real is [+-]digits[.digits][(e|E)[+-]digits] (or with the digits after
 * the point only).  strtod alone would also take hex ("0x10"), "inf" and
 * "nan", and strtoll would stop silently at "1.5"'s point; each token is
 * therefore matched whole first, and a refusal names its line:column. */

/* Length of the token at s (up to white space). */
static size_t token_len(const char *s)
{
    size_t n = 0;
    while (s[n] && !isspace((unsigned char)s[n])) n++;
    return n;
}

/* 1 when s[0..len) is [+-]digits. */
static int is_integer_token(const char *s, size_t len)
{
    size_t k = (len > 0 && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
    if (k == len) return 0;
    for (; k < len; k++)
        if (!isdigit((unsigned char)s[k])) return 0;
    return 1;
}

/* 1 when s[0..len) is a decimal real as above. */
static int is_decimal_token(const char *s, size_t len)
{
    size_t k = 0, digits = 0;
    if (k < len && (s[k] == '+' || s[k] == '-')) k++;
    while (k < len && isdigit((unsigned char)s[k])) k++, digits++;
    if (k < len && s[k] == '.') {
        k++;
        while (k < len && isdigit((unsigned char)s[k])) k++, digits++;
    }
    if (!digits) return 0;
    if (k < len && (s[k] == 'e' || s[k] == 'E')) {
        size_t exp_digits = 0;
        k++;
        if (k < len && (s[k] == '+' || s[k] == '-')) k++;
        while (k < len && isdigit((unsigned char)s[k])) k++, exp_digits++;
        if (!exp_digits) return 0;
    }
    return k == len;
}

/* 1 when s[0..len) spells an infinity or a NaN (as strtod reads them). */
static int is_nonfinite_token(const char *s, size_t len)
{
    size_t k = (len > 0 && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
    return (len - k == 3 && (!strncasecmp(s + k, "inf", 3) || !strncasecmp(s + k, "nan", 3))) ||
           (len - k == 8 && !strncasecmp(s + k, "infinity", 8)) ||
           (len - k > 3 && !strncasecmp(s + k, "nan(", 4) && s[len - 1] == ')');
}

/* The token at p for a message: at most 40 bytes, then "...". */
static const char *token_text(const char *p, size_t len, char *buf, size_t buflen)
{
    snprintf(buf, buflen, "%.*s%s", (int)(len < 40 ? len : 40), p, len > 40 ? "..." : "");
    return buf;
}

/* p past the blanks before a token, not past the line's end. */
static const char *skip_blanks(const char *p)
{
    while (isspace((unsigned char)*p) && *p != '\n') p++;
    return p;
}

/* Skips white space, then reads one whole integer token within int64.
 * what names the field in messages ("row index", "value"). */
static int parse_int_token(mm_reader *r, const char **s, const char *what, int64_t *out)
{
    const char *p = skip_blanks(*s);
    char *end, tok[64];
    size_t len;
    long long x;
    len = token_len(p);
    if (len == 0) return mm_fail_at(r, p, "expected %s, found the end of the line", what);
    if (!is_integer_token(p, len))
        return mm_fail_at(r, p, "%s '%s' is not an integer", what, token_text(p, len, tok, sizeof tok));
    errno = 0;
    x = strtoll(p, &end, 10);
    if (errno == ERANGE)
        return mm_fail_at(r, p, "%s '%s' is outside the 64-bit integers", what, token_text(p, len, tok, sizeof tok));
    *s = end;
    *out = (int64_t)x;
    return 0;
}

/* Skips white space, then reads one value token of the field: an integer
 * for integer fields, a decimal real for real ones; infinities, NaNs and
 * reals beyond the doubles only when the reader allows non-finite values. */
static int parse_value_token(mm_reader *r, const char **s, int field, double *out)
{
    const char *p = skip_blanks(*s);
    char *end, tok[64];
    size_t len;
    int nonfinite;
    if (field == MM_INTEGER) {
        int64_t x;
        if (parse_int_token(r, s, "integer value", &x)) return -1;
        *out = (double)x;
        /* Values are doubles: an integer past 2^53 that has no double of its
         * own would be stored as a neighbour, silently. */
        if (*out >= 9223372036854775808.0 || (int64_t)*out != x)
            return mm_fail_at(r, p, "integer value '%s' has no exact double (SILC stores doubles: "
                                    "integers beyond 2^53 = 9007199254740992 only where exact)",
                              token_text(p, token_len(p), tok, sizeof tok));
        return 0;
    }
    len = token_len(p);
    if (len == 0) return mm_fail_at(r, p, "expected a value, found the end of the line");
    nonfinite = !is_decimal_token(p, len);
    if (nonfinite && !is_nonfinite_token(p, len))
        return mm_fail_at(r, p, "value '%s' is not a decimal number", token_text(p, len, tok, sizeof tok));
    if (nonfinite && !r->allow_nonfinite)
        return mm_fail_at(r, p, "value '%s' is not finite (set SILC_MM_ALLOW_NONFINITE=1 to accept it)",
                          token_text(p, len, tok, sizeof tok));
    errno = 0;
    *out = strtod(p, &end);
    if (errno == ERANGE && isinf(*out) && !r->allow_nonfinite)
        return mm_fail_at(r, p, "value '%s' overflows the doubles (set SILC_MM_ALLOW_NONFINITE=1 to accept "
                                "it as inf)", token_text(p, len, tok, sizeof tok));
    *s = end;
    return 0;
}

static int only_space(const char *s)
{
    while (isspace((unsigned char)*s)) s++;
    return *s == '\0';
}

/* The banner: "%%MatrixMarket matrix <format> <field> <symmetry>". */
static int mm_banner(mm_reader *r, int *is_array, int *field, int *sym)
{
    char w[5][64];
    int got = mm_read_line(r);
    if (got < 0) return -1;
    if (got == 0) return mm_fail(r, 1, "empty file (expected a %%%%MatrixMarket banner)");
    if (sscanf(r->line, "%63s %63s %63s %63s %63s", w[0], w[1], w[2], w[3], w[4]) != 5 ||
        strcasecmp(w[0], "%%MatrixMarket") != 0)
        return mm_fail(r, 1, "not a Matrix Market file (expected '%%%%MatrixMarket matrix "
                             "<coordinate|array> <field> <symmetry>')");
    if (strcasecmp(w[1], "matrix") != 0) return mm_fail(r, 1, "object '%s' is not supported (only 'matrix')", w[1]);
    if (strcasecmp(w[2], "coordinate") == 0) *is_array = 0;
    else if (strcasecmp(w[2], "array") == 0) *is_array = 1;
    else return mm_fail(r, 1, "unknown format '%s' (expected coordinate or array)", w[2]);
    if (strcasecmp(w[3], "real") == 0 || strcasecmp(w[3], "double") == 0) *field = MM_REAL;
    else if (strcasecmp(w[3], "integer") == 0) *field = MM_INTEGER;
    else if (strcasecmp(w[3], "pattern") == 0) *field = MM_PATTERN;
    else if (strcasecmp(w[3], "complex") == 0) *field = MM_COMPLEX;
    else return mm_fail(r, 1, "unknown field '%s' (expected real, integer, pattern or complex)", w[3]);
    /* Hermitian is a property of complex matrices only: a real, integer or
     * pattern file that says hermitian is malformed (its writer meant
     * something this reader cannot know; issue 32). */
    if (strcasecmp(w[4], "general") == 0) *sym = MM_GENERAL;
    else if (strcasecmp(w[4], "symmetric") == 0) *sym = MM_SYMMETRIC;
    else if (strcasecmp(w[4], "hermitian") == 0 && *field == MM_COMPLEX) *sym = MM_HERMITIAN;
    else if (strcasecmp(w[4], "hermitian") == 0)
        return mm_fail(r, 1, "symmetry 'hermitian' needs a complex field, and this file's is '%s' "
                             "(say symmetric for a real symmetric matrix)", w[3]);
    else if (strcasecmp(w[4], "skew-symmetric") == 0) *sym = MM_SKEW;
    else return mm_fail(r, 1, "unknown symmetry '%s' (expected general, symmetric or skew-symmetric)", w[4]);
    if (*is_array && *field == MM_PATTERN) return mm_fail(r, 1, "an array file cannot have field 'pattern'");
    return 0;
}

/* What the size line claims, checked before anything is allocated: the
 * value and, for coordinate files, the triplets read before assembly (four
 * 8-byte arrays of up to 2 nz entries for symmetric files, and the
 * assembly's own copies). */
static int mm_claim(int is_array, int64_t m, int64_t n, int64_t nz, int sym, int w)
{
    char what[160];
    double cap = sym == MM_GENERAL ? (double)nz : 2.0 * (double)nz, bytes;
    if (is_array) {
        bytes = (double)m * (double)n * 8 * w;
        snprintf(what, sizeof what, "the %lldx%lld array the size line announces", (long long)m,
                 (long long)n);
    } else {
        bytes = ((double)m + 1) * 24 + ((double)n + 1) * 8 + cap * (32 + 32 + 16 * (w - 1));
        snprintf(what, sizeof what, "the %lldx%lld matrix of %lld entries the size line announces",
                 (long long)m, (long long)n, (long long)nz);
    }
    return val_claim(bytes, what);
}

/* Reads the array body (column-major; symmetric files hold the lower
 * triangle column by column, skew-symmetric ones without the diagonal). */
static int mm_read_array(mm_reader *r, silc_envelope_t *e, int64_t m, int64_t n, int field, int sym)
{
    int64_t i, j;
    int w = mm_width(field), c;
    double *a;
    if (sym != MM_GENERAL && m != n)
        return mm_fail(r, r->lineno, "a symmetric, skew-symmetric or hermitian matrix must be square, not "
                                     "%lldx%lld", (long long)m, (long long)n);
    if (w == 2 ? silc_envelope_dense_complex(e, m, n, NULL) : silc_envelope_dense(e, m, n, NULL))
        return mm_fail(r, r->lineno, "out of memory for %lldx%lld", (long long)m, (long long)n);
    a = e->values;
    for (j = 0; j < n; j++) {
        int64_t i0 = sym == MM_GENERAL ? 0 : sym == MM_SKEW ? j + 1 : j;
        for (i = i0; i < m; i++) {
            const char *p = mm_next_data_line(r);
            double x[2] = {0, 0};
            if (!p) {
                silc_envelope_free(e);
                return mm_fail(r, r->lineno, "file ends before entry (%lld, %lld)", (long long)i + 1,
                               (long long)j + 1);
            }
            for (c = 0; c < w; c++)
                if (parse_value_token(r, &p, field == MM_COMPLEX ? MM_REAL : field, &x[c])) {
                    silc_envelope_free(e);
                    return -1;
                }
            if (!only_space(p) && mm_fail_at(r, p + strspn(p, " \t"), w == 2 ? "expected two numbers per line "
                                             "(real and imaginary part)" : "expected one number per line")) {
                silc_envelope_free(e);
                return -1;
            }
            if (sym == MM_HERMITIAN && i == j && x[1] != 0) {
                silc_envelope_free(e);
                return mm_fail(r, r->lineno, "diagonal entry (%lld, %lld) of a hermitian file has imaginary "
                                             "part %g (it must be real)", (long long)i + 1, (long long)j + 1, x[1]);
            }
            memcpy(a + (i + j * m) * w, x, (size_t)w * sizeof *x);
            if (sym != MM_GENERAL && i != j) mm_mirror(sym, w, x, a + (j + i * m) * w);
        }
    }
    if (mm_next_data_line(r)) {
        silc_envelope_free(e);
        return mm_fail(r, r->lineno, "more entries than the size line announces");
    }
    return 0;
}

/* Triplets in file order with the line each came from (mirrors share it). */
typedef struct triplets {
    int64_t *i, *j, *line;
    double *x;
    int64_t n;
} triplets;

static void triplets_free(triplets *t)
{
    free(t->i), free(t->j), free(t->line), free(t->x);
}

/* Assembles CSR: a counting sort by column, then a stable one by row, leaves
 * every row sorted by column; equal neighbours are duplicates. */
static int mm_assemble(mm_reader *r, const triplets *t, int64_t m, int64_t n, int w, silc_envelope_t *e)
{
    int64_t *cp = calloc((size_t)n + 1, sizeof *cp), *bycol = malloc(((size_t)t->n + 1) * sizeof *bycol);
    int64_t *rp = calloc((size_t)m + 1, sizeof *rp), *next = malloc(((size_t)m + 1) * sizeof *next);
    int64_t *ci = malloc(((size_t)t->n + 1) * sizeof *ci), *src = malloc(((size_t)t->n + 1) * sizeof *src);
    double *x = malloc(((size_t)t->n + 1) * (size_t)w * sizeof *x);
    int64_t k, a, rc = 0;
    if (!cp || !bycol || !rp || !next || !ci || !src || !x) {
        rc = mm_fail(r, 0, "out of memory for %lld entries", (long long)t->n);
        goto done;
    }
    for (k = 0; k < t->n; k++) cp[t->j[k] + 1]++;
    for (a = 0; a < n; a++) cp[a + 1] += cp[a];
    for (k = 0; k < t->n; k++) bycol[cp[t->j[k]]++] = k;
    for (k = 0; k < t->n; k++) rp[t->i[k] + 1]++;
    for (a = 0; a < m; a++) rp[a + 1] += rp[a];
    memcpy(next, rp, (size_t)m * sizeof *next);
    for (a = 0; a < t->n; a++) {
        int64_t s = bycol[a], d = next[t->i[s]]++;
        ci[d] = t->j[s];
        memcpy(x + d * w, t->x + s * w, (size_t)w * sizeof *x);
        src[d] = s;
    }
    for (a = 0; a < m; a++)
        for (k = rp[a] + 1; k < rp[a + 1]; k++)
            if (ci[k] == ci[k - 1]) {
                int64_t l1 = t->line[src[k - 1]], l2 = t->line[src[k]];
                rc = mm_fail(r, l1 > l2 ? l1 : l2, "duplicate entry (%lld, %lld)%s (also at line %lld)",
                             (long long)a + 1, (long long)ci[k] + 1,
                             l1 == l2 ? " from mirroring the diagonal" : "",
                             (long long)(l1 > l2 ? l2 : l1));
                goto done;
            }
    memset(e, 0, sizeof *e);
    e->m = m;
    e->n = n;
    e->format = w == 2 ? SILC_CSR_COMPLEX : SILC_CSR;
    e->rowptr = rp;
    e->colind = ci;
    e->values = x;
    e->nnz = t->n;
    rp = ci = NULL;
    x = NULL;
done:
    free(cp), free(bycol), free(rp), free(next), free(ci), free(src), free(x);
    return (int)rc;
}

static int mm_read_coordinate(mm_reader *r, silc_envelope_t *e, int64_t m, int64_t n, int64_t nz,
                              int field, int sym)
{
    triplets t = {0};
    int64_t cap, k;
    int rc, w = mm_width(field), c;
    if (sym != MM_GENERAL && m != n)
        return mm_fail(r, r->lineno, "a symmetric, skew-symmetric or hermitian matrix must be square, not "
                                     "%lldx%lld", (long long)m, (long long)n);
    cap = sym == MM_GENERAL ? nz : 2 * nz;
    t.i = malloc(((size_t)cap + 1) * sizeof *t.i);
    t.j = malloc(((size_t)cap + 1) * sizeof *t.j);
    t.line = malloc(((size_t)cap + 1) * sizeof *t.line);
    t.x = malloc(((size_t)cap + 1) * (size_t)w * sizeof *t.x);
    if (!t.i || !t.j || !t.line || !t.x) {
        triplets_free(&t);
        return mm_fail(r, r->lineno, "out of memory for %lld entries", (long long)nz);
    }
    for (k = 0; k < nz; k++) {
        const char *p = mm_next_data_line(r);
        int64_t i, j;
        double x[2] = {1.0, 0.0};
        if (!p) {
            triplets_free(&t);
            return mm_fail(r, r->lineno, "file ends after %lld of %lld entries", (long long)k, (long long)nz);
        }
        const char *start = p;
        if (parse_int_token(r, &p, "row index", &i) || parse_int_token(r, &p, "column index", &j)) {
            triplets_free(&t);
            return -1;
        }
        for (c = 0; c < (field == MM_PATTERN ? 0 : w); c++)
            if (parse_value_token(r, &p, field == MM_COMPLEX ? MM_REAL : field, &x[c])) {
                triplets_free(&t);
                return -1;
            }
        if (!only_space(p) && mm_fail_at(r, p + strspn(p, " \t"), "unexpected text after '%s'",
                                         field == MM_PATTERN ? "row column"
                                         : w == 2          ? "row column real imaginary"
                                                           : "row column value")) {
            triplets_free(&t);
            return -1;
        }
        if (i < 1 || i > m || j < 1 || j > n) {
            triplets_free(&t);
            return mm_fail_at(r, start, "entry (%lld, %lld) is outside the %lldx%lld matrix",
                              (long long)i, (long long)j, (long long)m, (long long)n);
        }
        if (sym == MM_SKEW && i == j) {
            triplets_free(&t);
            return mm_fail_at(r, start, "diagonal entry (%lld, %lld) in a skew-symmetric file",
                              (long long)i, (long long)j);
        }
        /* The format stores the lower triangle of a symmetric or
         * skew-symmetric matrix; an entry above it is refused rather than
         * mirrored, since the file then says A(i,j) where it may also say
         * A(j,i) differently. */
        if (sym != MM_GENERAL && i < j) {
            triplets_free(&t);
            return mm_fail_at(r, start, "entry (%lld, %lld) is above the diagonal: a %s file stores the "
                                        "lower triangle only", (long long)i, (long long)j,
                              sym == MM_SKEW ? "skew-symmetric" : sym == MM_HERMITIAN ? "hermitian" : "symmetric");
        }
        if (sym == MM_HERMITIAN && i == j && x[1] != 0) {
            triplets_free(&t);
            return mm_fail_at(r, start, "diagonal entry (%lld, %lld) of a hermitian file has imaginary part "
                                        "%g (it must be real)", (long long)i, (long long)j, x[1]);
        }
        t.i[t.n] = i - 1;
        t.j[t.n] = j - 1;
        memcpy(t.x + t.n * w, x, (size_t)w * sizeof *x);
        t.line[t.n++] = r->lineno;
        if (sym != MM_GENERAL && i != j) {
            t.i[t.n] = j - 1;
            t.j[t.n] = i - 1;
            mm_mirror(sym, w, x, t.x + t.n * w);
            t.line[t.n++] = r->lineno;
        }
    }
    if (mm_next_data_line(r)) {
        triplets_free(&t);
        return mm_fail(r, r->lineno, "more entries than the %lld the size line announces", (long long)nz);
    }
    rc = mm_assemble(r, &t, m, n, w, e);
    triplets_free(&t);
    return rc;
}

int silc_mm_read(silc_envelope_t *e, const char *path, char *err, size_t errlen)
{
    mm_reader r;
    int is_array = 0, field = MM_REAL, sym = MM_GENERAL, rc;
    int64_t m, n, nz = 0;
    const char *p;
    memset(&r, 0, sizeof r);
    r.path = path ? path : "(null)";
    r.allow_nonfinite = getenv("SILC_MM_ALLOW_NONFINITE") && !strcmp(getenv("SILC_MM_ALLOW_NONFINITE"), "1");
    r.err = err;
    r.errlen = errlen;
    if (err && errlen) err[0] = '\0';
    if (!e) return mm_fail(&r, 0, "NULL envelope");
    memset(e, 0, sizeof *e);
    if (!path) return mm_fail(&r, 0, "NULL path"), env_mark_not_constructed(e);
    {   /* util_open_input: a FIFO with no writer reads as empty, never hangs */
        int fd = util_open_input(path);
        if (fd < 0 || !(r.f = fdopen(fd, "r"))) {
            int why = errno;
            if (fd >= 0) close(fd);
            return mm_fail(&r, 0, "cannot open: %s", strerror(why)), env_mark_not_constructed(e);
        }
    }
    rc = mm_banner(&r, &is_array, &field, &sym);
    if (rc == 0) {
        p = mm_next_data_line(&r);
        if (!p) rc = mm_fail(&r, r.lineno, "file ends before the size line");
        else if (parse_int_token(&r, &p, "row count", &m) || parse_int_token(&r, &p, "column count", &n) ||
                 (!is_array && parse_int_token(&r, &p, "entry count", &nz)) || !only_space(p) || m < 0 ||
                 n < 0 || nz < 0)
            rc = mm_fail(&r, r.lineno, "expected the size line '%s'", is_array ? "rows cols" : "rows cols entries");
        else if (mm_claim(is_array, m, n, nz, sym, mm_width(field)))
            rc = mm_fail(&r, r.lineno, "%s", val_refusal());
        else if (is_array)
            rc = mm_read_array(&r, e, m, n, field, sym);
        else
            rc = mm_read_coordinate(&r, e, m, n, nz, field, sym);
    }
    if (rc == 0 && r.failed) {          /* a refused line read as the end of the file */
        silc_envelope_free(e);
        rc = -1;
    }
    if (rc == 0) { /* what every value handed to SILC passes (val_parts_check) */
        char why[512];
        if (env_check(e, why, sizeof why)) {
            silc_envelope_free(e);
            rc = mm_fail(&r, 0, "%s", why);
        }
    }
    /* A failed read leaves e as a failed constructor does: a PUT of it is
     * refused with this message. */
    if (rc) env_mark_not_constructed(e);
    free(r.line);
    fclose(r.f);
    return rc;
}

int silc_mm_write(const silc_envelope_t *e, FILE *out)
{
    int64_t i, j, k, count = 0;
    int w = silc_envelope_is_complex(e) ? 2 : 1;
    const char *field = w == 2 ? "complex" : "real";
    if (!e || !out) return env_error("silc_mm_write: NULL %s", e ? "stream" : "envelope");
    switch (env_format_base((int)e->format)) {
    case SILC_DENSE:
        if (e->m * e->n > 0 && !e->values) return env_error("silc_mm_write: envelope has no values");
        fprintf(out, "%%%%MatrixMarket matrix array %s general\n%lld %lld\n", field, (long long)e->m,
                (long long)e->n);
        for (k = 0; k < e->m * e->n; k++) {
            if (w == 2) fprintf(out, "%.17g %.17g\n", e->values[2 * k], e->values[2 * k + 1]);
            else fprintf(out, "%.17g\n", e->values[k]);
        }
        break;
    case SILC_CSR:
        if (!e->rowptr) return env_error("silc_mm_write: CSR envelope has no rowptr");
        fprintf(out, "%%%%MatrixMarket matrix coordinate %s general\n%lld %lld %lld\n", field,
                (long long)e->m, (long long)e->n, (long long)e->rowptr[e->m]);
        for (i = 0; i < e->m; i++)
            for (k = e->rowptr[i]; k < e->rowptr[i + 1]; k++) {
                if (w == 2)
                    fprintf(out, "%lld %lld %.17g %.17g\n", (long long)i + 1, (long long)e->colind[k] + 1,
                            e->values[2 * k], e->values[2 * k + 1]);
                else
                    fprintf(out, "%lld %lld %.17g\n", (long long)i + 1, (long long)e->colind[k] + 1,
                            e->values[k]);
            }
        break;
    case SILC_BAND: {
        /* Only the nonzeros: the zero corners of band storage are not entries. */
        int64_t ld = e->kl + e->ku + 1;
        for (k = 0; k < 2; k++) {
            if (k == 1)
                fprintf(out, "%%%%MatrixMarket matrix coordinate %s general\n%lld %lld %lld\n", field,
                        (long long)e->m, (long long)e->n, (long long)count);
            for (j = 0; j < e->n; j++) {
                int64_t lo = j - e->ku > 0 ? j - e->ku : 0;
                int64_t hi = j + e->kl < e->m - 1 ? j + e->kl : e->m - 1;
                for (i = lo; i <= hi; i++) {
                    /* entry (i, j) of the band: w doubles (re, im for a complex one) */
                    const double *x = e->values + w * ((e->ku + i - j) + j * ld);
                    if (x[0] == 0 && (w == 1 || x[1] == 0)) continue;
                    if (k == 0) count++;
                    else if (w == 2)
                        fprintf(out, "%lld %lld %.17g %.17g\n", (long long)i + 1, (long long)j + 1, x[0], x[1]);
                    else fprintf(out, "%lld %lld %.17g\n", (long long)i + 1, (long long)j + 1, x[0]);
                }
            }
        }
        break;
    }
    default:
        return env_error("silc_mm_write: unknown format %d", (int)e->format);
    }
    if (ferror(out)) return env_error("silc_mm_write: write failed");
    return 0;
}
