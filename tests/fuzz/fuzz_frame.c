/*
 * fuzz_frame.c -- fuzz harness for the wire protocol's decoders (protocol.c):
 * an input is a byte stream as a server would receive it (hello, then
 * requests, PUT arrays read or skipped as the server would) and, read again,
 * as a client would receive it (replies, VALUE arrays into an envelope).
 * Whatever the bytes, decoding must end in a message or a clean refusal,
 * never a crash, a leak or an over-read, and everything it accepts must be
 * consistent (a decoded value passes the same checks as an embedded PUT).
 *
 * Built two ways from this one file:
 *   - with clang -fsanitize=fuzzer: LLVMFuzzerTestOneInput for libFuzzer;
 *   - with SILC_FUZZ_DRIVER: a deterministic mutation fuzzer (seeds below,
 *     xorshift mutations) running a bounded number of inputs, for CI on any
 *     compiler:  fuzz_frame [iterations] [--write-seeds DIR]
 */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store.h"
#include "client.h"

static int violations;

static void violation(const char *what)
{
    violations++;
    fprintf(stderr, "fuzz_frame: invariant broken: %s\n", what);
}

/* A decoded value must be one an embedded silc_put would accept. */
static void check_value(const silc_value *v, const proto_request *q)
{
    silc_envelope_t e;
    char err[256];
    memset(&e, 0, sizeof e);
    e.m = v->m;
    e.n = v->n;
    e.format = (silc_format_t)v->format;
    e.values = v->val;
    e.rowptr = v->rowptr;
    e.colind = v->colind;
    e.nnz = v->nnz;
    e.kl = v->kl;
    e.ku = v->ku;
    if (env_check(&e, err, sizeof err)) violation("accepted value fails env_check");
    if (v->m != q->desc.m || v->n != q->desc.n) violation("value shape differs from descriptor");
}

static void as_server(const uint8_t *data, size_t size)
{
    proto_stream s = {-1, 0, data, size, 0};
    proto_limits lim = {1 << 20, 1 << 16};
    proto_request q;
    uint32_t version;
    char *token = NULL, err[512];
    int rc, i;
    if (proto_read_hello(&s, &version, &token, err, sizeof err)) return;
    free(token);
    for (i = 0; i < 64; i++) {
        rc = proto_read_request(&s, &lim, &q, err, sizeof err);
        if (rc == 0 && q.op == PROTO_PUT) {
            silc_value *v = NULL;
            if (q.layout.total > lim.max_value_bytes) violation("PUT over the limit accepted");
            /* The server skips what it refuses for its own reasons. */
            if (q.desc.namelen & 1) {
                rc = proto_skip(&s, q.layout.total, err, sizeof err);
            } else {
                rc = proto_read_value(&s, &q, &v, err, sizeof err);
                if (rc == 0) {
                    if (!v) violation("PUT read without a value");
                    else check_value(v, &q);
                }
                val_release(v);
            }
        }
        if (rc == 0 && q.text && strlen(q.text) != q.textlen) violation("text length");
        proto_request_free(&q);
        if (rc < 0) break;
    }
}

static void as_client(const uint8_t *data, size_t size)
{
    proto_stream s = {-1, 0, data, size, 0};
    proto_limits lim = {1 << 20, 1 << 16};
    proto_reply r;
    char err[512];
    int i;
    for (i = 0; i < 64; i++) {
        int rc = proto_read_reply(&s, &lim, &r, err, sizeof err);
        if (rc == 0 && r.op == PROTO_VALUE) {
            char why[256];
            if (env_check(&r.env, why, sizeof why)) violation("accepted VALUE fails env_check");
        }
        proto_reply_free(&r);
        if (rc) break;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    proto_addr a;
    char err[256], *url;
    as_server(data, size);
    as_client(data, size);
    if ((url = malloc(size + 1))) {
        memcpy(url, data, size);
        url[size] = '\0';
        proto_parse_url(url, &a, err, sizeof err);
        free(url);
    }
    if (violations) abort();
    return 0;
}

#ifdef SILC_FUZZ_DRIVER
/* ---- the deterministic driver ------------------------------------------------ */
typedef struct buf {
    uint8_t *p;
    size_t len, cap;
} buf;

static void put(buf *b, const void *p, size_t n)
{
    if (b->len + n > b->cap) {
        b->cap = (b->len + n) * 2 + 64;
        b->p = realloc(b->p, b->cap);
        if (!b->p) exit(1);
    }
    if (n) memcpy(b->p + b->len, p, n); /* p may be NULL for an empty body */
    b->len += n;
}

static void frame(buf *b, uint32_t op, const void *body, size_t n)
{
    uint8_t h[PROTO_HEADER_BYTES];
    proto_encode_header(h, op, n);
    put(b, h, sizeof h);
    put(b, body, n);
}

static void put_frame(buf *b, const char *name, const proto_desc *d0, const void *arrays,
                      size_t n)
{
    uint8_t h[PROTO_HEADER_BYTES], dd[PROTO_DESC_BYTES];
    proto_desc d = *d0;
    d.namelen = (uint32_t)strlen(name);
    proto_encode_header(h, PROTO_PUT, PROTO_DESC_BYTES + d.namelen + n);
    proto_encode_desc(dd, &d);
    put(b, h, sizeof h);
    put(b, dd, sizeof dd);
    put(b, name, d.namelen);
    put(b, arrays, n);
}

static void seed_requests(buf *b)
{
    uint8_t hello[PROTO_HELLO_BYTES];
    double dv[6] = {1, 2, 3, 4, 5, 6};
    int64_t csr[3 + 1 + 3 + 3];
    double *cv = (double *)(csr + 7);
    proto_desc d;
    proto_encode_hello(hello, PROTO_VERSION, 3);
    put(b, hello, sizeof hello);
    put(b, "abc", 3);
    memset(&d, 0, sizeof d);
    d.format = SILC_DENSE;
    d.m = 2;
    d.n = 3;
    d.nnz = 6;
    put_frame(b, "A", &d, dv, sizeof dv);
    /* 3x3 CSR with rows {0}, {1, 2}, {}: rowptr, colind, values. */
    csr[0] = 0; csr[1] = 1; csr[2] = 3; csr[3] = 3;
    csr[4] = 0; csr[5] = 1; csr[6] = 2;
    cv[0] = 1.5; cv[1] = -2; cv[2] = 4;
    d.format = SILC_CSR;
    d.m = d.n = 3;
    d.nnz = 3;
    put_frame(b, "S", &d, csr, sizeof csr);
    d.format = SILC_BAND;
    d.m = d.n = 2;
    d.kl = 1;
    d.ku = 0;
    d.nnz = 4;
    put_frame(b, "Bd", &d, dv, 4 * sizeof(double));
    frame(b, PROTO_EXEC, "x = A * 2", 9);
    frame(b, PROTO_GET, "x", 1);
    frame(b, PROTO_LIST, NULL, 0);
    frame(b, PROTO_INFO, NULL, 0);
    frame(b, PROTO_EXPLAIN, "y = S \\ ones(3,1)", 17);
    frame(b, PROTO_DELETE, "A", 1);
    frame(b, PROTO_BYE, NULL, 0);
}

static void seed_replies(buf *b)
{
    uint8_t dd[PROTO_DESC_BYTES], h[PROTO_HEADER_BYTES];
    int64_t csr[2 + 1 + 1];
    double *cv = (double *)(csr + 3);
    proto_desc d;
    frame(b, PROTO_OK, "silcd", 5);
    frame(b, PROTO_TEXT, "x  2x3 dense\n", 13);
    frame(b, PROTO_WARN, "matrix is singular\n", 19);
    memset(&d, 0, sizeof d);
    d.format = SILC_CSR;
    d.m = 1;
    d.n = 4;
    d.nnz = 1;
    csr[0] = 0; csr[1] = 1; csr[2] = 3;
    cv[0] = 7;
    proto_encode_desc(dd, &d);
    proto_encode_header(h, PROTO_VALUE, sizeof dd + sizeof csr);
    put(b, h, sizeof h);
    put(b, dd, sizeof dd);
    put(b, csr, sizeof csr);
    frame(b, PROTO_ERROR, "undefined name 'u'", 18);
}

#include "fuzz_rng.h"
#define next fuzz_next

/* One to eight mutations of the kinds that find length bugs: bit flips,
 * interesting integers over length fields, truncation, chunk copies. */
static size_t mutate(uint8_t *p, size_t len, size_t cap)
{
    static const uint64_t interesting[] = {0, 1, 0x7f, 0x80, 0xff, 0xffff, 0x7fffffff,
                                           0xffffffffull, (uint64_t)1 << 40, (uint64_t)-1,
                                           (uint64_t)INT64_MAX, 48, 16};
    int k, nm = 1 + (int)(next() % 8);
    for (k = 0; k < nm && len > 0; k++) {
        size_t at = (size_t)(next() % len), n;
        switch (next() % 6) {
        case 0: p[at] ^= (uint8_t)(1u << (next() % 8)); break;
        case 1: p[at] = (uint8_t)next(); break;
        case 2: {
            uint64_t x = interesting[next() % (sizeof interesting / sizeof *interesting)];
            size_t w = next() % 2 ? 8 : 4;
            if (at + w <= len) {
                if (w == 8) proto_put_u64(p + at, x);
                else proto_put_u32(p + at, (uint32_t)x);
            }
            break;
        }
        case 3: len = at; break;
        case 4: /* copy a chunk over another place */
            n = (size_t)(next() % 64);
            if (at + n <= len) {
                size_t to = (size_t)(next() % len);
                if (to + n > cap) n = cap - to;
                memmove(p + to, p + at, n);
                if (to + n > len) len = to + n;
            }
            break;
        default: /* insert random bytes */
            n = (size_t)(next() % 16);
            if (len + n <= cap) {
                size_t i;
                memmove(p + at + n, p + at, len - at);
                for (i = 0; i < n; i++) p[at + i] = (uint8_t)next();
                len += n;
            }
            break;
        }
    }
    return len;
}

static void write_seed(const char *dir, const char *name, const buf *b)
{
    char path[4096];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (!(f = fopen(path, "wb"))) return;
    fwrite(b->p, 1, b->len, f);
    fclose(f);
}

int main(int argc, char **argv)
{
    buf seeds[2] = {{NULL, 0, 0}, {NULL, 0, 0}};
    long iterations = argc > 1 ? atol(argv[1]) : 20000, i;
    uint8_t *work;
    size_t cap;
    seed_requests(&seeds[0]);
    seed_replies(&seeds[1]);
    if (argc > 3 && strcmp(argv[2], "--write-seeds") == 0) {
        write_seed(argv[3], "requests", &seeds[0]);
        write_seed(argv[3], "replies", &seeds[1]);
        return 0;
    }
    cap = seeds[0].len + seeds[1].len + 4096;
    if (!(work = malloc(cap))) return 1;
    for (i = 0; i < 2; i++) LLVMFuzzerTestOneInput(seeds[i].p, seeds[i].len);
    for (i = 0; i < iterations; i++) {
        const buf *s = &seeds[next() % 2];
        size_t len;
        memcpy(work, s->p, s->len);
        len = mutate(work, s->len, cap);
        LLVMFuzzerTestOneInput(work, len);
    }
    printf("fuzz_frame: %ld mutated inputs decoded\n", iterations);
    printf("%d passed, %d failed\n", violations ? 0 : 1, violations ? 1 : 0);
    free(work);
    free(seeds[0].p);
    free(seeds[1].p);
    return violations != 0;
}
#endif
