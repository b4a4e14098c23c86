/*
 * util.c -- small shared helpers of the core: the growable string buffer,
 * the "did you mean" suggestion, the monotonic clock and the shortest
 * round-trip formatting of doubles.  Kept in one place so that every module's
 * messages read alike.
 */
#define _POSIX_C_SOURCE 200809L
#include "util.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

void sb_init(strbuf *b)
{
    b->s = NULL;
    b->len = b->cap = 0;
    b->failed = 0;
}

void sb_free(strbuf *b)
{
    free(b->s);
    sb_init(b);
}

/* Makes room for extra more characters plus the terminator. */
static int sb_reserve(strbuf *b, size_t extra)
{
    size_t need = b->len + extra + 1, cap;
    char *s;
    if (need <= b->cap) return 0;
    cap = b->cap ? b->cap : 64;
    while (cap < need) cap *= 2;
    s = realloc(b->s, cap);
    if (!s) {
        b->failed = 1;
        return -1;
    }
    b->s = s;
    b->cap = cap;
    return 0;
}

int sb_puts(strbuf *b, const char *s)
{
    size_t n = strlen(s);
    if (sb_reserve(b, n)) return -1;
    memcpy(b->s + b->len, s, n + 1);
    b->len += n;
    return 0;
}

int sb_vprintf(strbuf *b, const char *fmt, va_list ap)
{
    va_list ap2;
    int n;
    va_copy(ap2, ap);
    n = vsnprintf(NULL, 0, fmt, ap2);
    va_end(ap2);
    if (n < 0 || sb_reserve(b, (size_t)n)) return -1;
    vsnprintf(b->s + b->len, (size_t)n + 1, fmt, ap);
    b->len += (size_t)n;
    return 0;
}

int sb_printf(strbuf *b, const char *fmt, ...)
{
    va_list ap;
    int rc;
    va_start(ap, fmt);
    rc = sb_vprintf(b, fmt, ap);
    va_end(ap);
    return rc;
}

const char *sb_str(const strbuf *b)
{
    return b->s ? b->s : "";
}

/* Damerau-Levenshtein distance in its optimal-string-alignment form, with
 * three rolling rows: an adjacent transposition ("alpah" for "alpha") costs
 * 1, as a typo does, where plain Levenshtein counts 2 and, for a five-letter
 * name, misses the suggestion.  Names are short, so the rows live on the
 * stack unless a name is unusually long. */
static size_t edit_distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b), i, j, d;
    size_t stack[3][64], *prev2, *prev, *cur, *heap = NULL;
    if (lb + 1 <= 64) {
        prev2 = stack[0];
        prev = stack[1];
        cur = stack[2];
    } else {
        heap = malloc(3 * (lb + 1) * sizeof *heap);
        if (!heap) return (size_t)-1;
        prev2 = heap;
        prev = heap + lb + 1;
        cur = heap + 2 * (lb + 1);
    }
    for (j = 0; j <= lb; j++) prev[j] = j;
    for (i = 1; i <= la; i++) {
        size_t *t;
        cur[0] = i;
        for (j = 1; j <= lb; j++) {
            size_t sub = prev[j - 1] + (a[i - 1] != b[j - 1]);
            size_t del = prev[j] + 1, ins = cur[j - 1] + 1;
            d = sub < del ? sub : del;
            if (ins < d) d = ins;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
                prev2[j - 2] + 1 < d)
                d = prev2[j - 2] + 1;
            cur[j] = d;
        }
        t = prev2;
        prev2 = prev;
        prev = cur;
        cur = t;
    }
    d = prev[lb];
    free(heap);
    return d;
}

int util_is_name(const char *s)
{
    if (!(isalpha((unsigned char)*s) || *s == '_')) return 0;
    for (s++; *s; s++)
        if (!(isalnum((unsigned char)*s) || *s == '_')) return 0;
    return 1;
}

const char *util_closest(const char *name, const char *const *cands, size_t ncands)
{
    size_t limit, best_d = (size_t)-1, i;
    const char *best = NULL;
    if (!name || !cands) return NULL;
    limit = strlen(name) / 3;
    if (limit < 1) limit = 1;
    for (i = 0; i < ncands; i++) {
        size_t d;
        if (!cands[i] || strcmp(cands[i], name) == 0) continue;
        d = edit_distance(name, cands[i]);
        if (d <= limit && d < best_d) {
            best_d = d;
            best = cands[i];
        }
    }
    return best;
}

uint64_t util_fnv1a(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    size_t i;
    for (i = 0; i < n; i++) h = (h ^ b[i]) * 1099511628211ull;
    return h;
}

double util_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

char *util_strdup(const char *s)
{
    size_t n;
    char *p;
    if (!s) return NULL;
    n = strlen(s) + 1;
    p = malloc(n);
    if (p) memcpy(p, s, n);
    return p;
}

void util_fmt_double(char *out, size_t outlen, double x)
{
    static const char *const fmts[] = {"%.15g", "%.16g", "%.17g"};
    size_t k;
    if (!out || outlen == 0) return;
    for (k = 0; k < 3; k++) {
        snprintf(out, outlen, fmts[k], x);
        /* NaN never compares equal to itself; %.15g already prints it exactly. */
        if (x != x || strtod(out, NULL) == x) return;
    }
}

/* 1536 -> "1.5 KiB": the unit a reader grasps at once, beside the exact count. */
static void fmt_binary(char *out, size_t outlen, double bytes)
{
    static const char *const unit[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    int u = 0;
    while (bytes >= 1024 && u < 6) {
        bytes /= 1024;
        u++;
    }
    snprintf(out, outlen, u ? "%.1f %s" : "%.0f %s", bytes, unit[u]);
}

void util_fmt_over_limit(char *out, size_t outlen, double need, double limit)
{
    char a[32], b[32], c[32];
    fmt_binary(a, sizeof a, need);
    fmt_binary(b, sizeof b, limit);
    fmt_binary(c, sizeof c, need - limit);
    snprintf(out, outlen, "%.0f bytes (%s), over the limit of %.0f bytes (%s) by %s", need, a,
             limit, b, c);
}

/* "123", "64K", "512M", "2G" (powers of 1024), at most max;
 * -1 with why on anything else. */
int util_parse_size(const char *s, uint64_t max, uint64_t *out, char *why, size_t whylen)
{
    char *end;
    unsigned long long x;
    int shift = 0;
    snprintf(why, whylen, "expected a size in bytes with an optional K, M, G or T suffix");
    if (!s || !(*s >= '0' && *s <= '9')) return -1;
    errno = 0;
    x = strtoull(s, &end, 10);
    switch (*end) {
    case 'k': case 'K': shift = 10; end++; break;
    case 'm': case 'M': shift = 20; end++; break;
    case 'g': case 'G': shift = 30; end++; break;
    case 't': case 'T': shift = 40; end++; break;
    default: break;
    }
    if (*end) return -1;
    if (errno == ERANGE || x > (max >> shift)) {
        snprintf(why, whylen, "too large: the maximum is %llu bytes",
                 (unsigned long long)max);
        return -1;
    }
    *out = (uint64_t)x << shift;
    return 0;
}
