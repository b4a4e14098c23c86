/*
 * test_protocol.c -- unit tests of the wire protocol's encoder and decoders
 * (core/client/protocol.c) on memory streams: round trips of every message,
 * and each kind of malformed input answered with the right outcome
 * (PROTO_REFUSED: consumed, session goes on; PROTO_FATAL: close) and a
 * message naming the problem.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "store.h"
#include "client.h"

typedef struct buf {
    uint8_t p[1 << 16];
    size_t len;
} buf;

static void put(buf *b, const void *p, size_t n)
{
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

/* A PUT frame whose header length is body_len (arrays follow as given). */
static void put_frame(buf *b, const char *name, proto_desc d, uint64_t body_len,
                      const void *arrays, size_t n)
{
    uint8_t h[PROTO_HEADER_BYTES], dd[PROTO_DESC_BYTES];
    d.namelen = (uint32_t)strlen(name);
    proto_encode_header(h, PROTO_PUT, body_len);
    proto_encode_desc(dd, &d);
    put(b, h, sizeof h);
    put(b, dd, sizeof dd);
    put(b, name, d.namelen);
    put(b, arrays, n);
}

static const proto_limits lim = {1 << 20, 1 << 12};

static int read_req(buf *b, size_t *pos, proto_request *q, char *err)
{
    proto_stream s = {-1, 0, b->p, b->len, *pos};
    int rc = proto_read_request(&s, &lim, q, err, 512);
    *pos = s.mempos;
    return rc;
}

static int contains(const char *s, const char *sub)
{
    return strstr(s, sub) != NULL;
}

static void test_roundtrip(void)
{
    buf b = {{0}, 0};
    size_t pos = 0;
    proto_request q;
    proto_desc d;
    silc_value *v = NULL;
    char err[512];
    int64_t csr[4 + 3];
    double vals[3] = {1, 2, 3};
    uint8_t raw[sizeof csr + sizeof vals];
    proto_stream s;
    memset(&d, 0, sizeof d);
    d.format = SILC_CSR;
    d.m = 3;
    d.n = 4;
    d.nnz = 3;
    csr[0] = 0; csr[1] = 2; csr[2] = 2; csr[3] = 3;
    csr[4] = 1; csr[5] = 3; csr[6] = 0;
    memcpy(raw, csr, sizeof csr);
    memcpy(raw + sizeof csr, vals, sizeof vals);
    put_frame(&b, "S", d, PROTO_DESC_BYTES + 1 + sizeof raw, raw, sizeof raw);
    frame(&b, PROTO_EXEC, "x = S'", 6);
    frame(&b, PROTO_LIST, NULL, 0);

    CHECK(read_req(&b, &pos, &q, err) == 0, "PUT: %s", err);
    CHECK(q.op == PROTO_PUT && strcmp(q.text, "S") == 0, "PUT name");
    CHECK(q.layout.total == sizeof raw, "layout %llu", (unsigned long long)q.layout.total);
    s = (proto_stream){-1, 0, b.p, b.len, pos};
    CHECK(proto_read_value(&s, &q, &v, err, sizeof err) == 0, "value: %s", err);
    pos = s.mempos;
    CHECK(v && v->format == SILC_FMT_CSR && v->nnz == 3 && v->colind[1] == 3 && v->val[2] == 3,
          "CSR value content");
    val_release(v);
    proto_request_free(&q);
    CHECK(read_req(&b, &pos, &q, err) == 0 && q.op == PROTO_EXEC && strcmp(q.text, "x = S'") == 0,
          "EXEC text");
    proto_request_free(&q);
    CHECK(read_req(&b, &pos, &q, err) == 0 && q.op == PROTO_LIST, "LIST");
    proto_request_free(&q);
    CHECK(read_req(&b, &pos, &q, err) == PROTO_BROKEN && contains(err, "closed"), "end: %s", err);
}

/* One malformed frame followed by a LIST: want the outcome, the message, and
 * for PROTO_REFUSED the LIST still readable (the stream stayed in step). */
static void expect(buf *b, int want, const char *msg, const char *what)
{
    size_t pos = 0;
    proto_request q;
    char err[512] = "";
    int rc;
    frame(b, PROTO_LIST, NULL, 0);
    rc = read_req(b, &pos, &q, err);
    CHECK(rc == want, "%s: outcome %d, want %d (%s)", what, rc, want, err);
    CHECK(contains(err, msg), "%s: message '%s' lacks '%s'", what, err, msg);
    proto_request_free(&q);
    if (want == PROTO_REFUSED) {
        CHECK(read_req(b, &pos, &q, err) == 0 && q.op == PROTO_LIST, "%s: stream out of step", what);
        proto_request_free(&q);
    }
    b->len = 0;
}

/* A PUT that decodes but whose arrays are refused by proto_read_value. */
static void expect_value(buf *b, const char *msg, const char *what)
{
    size_t pos = 0;
    proto_request q;
    silc_value *v = NULL;
    char err[512] = "";
    proto_stream s;
    int rc = read_req(b, &pos, &q, err);
    CHECK(rc == 0, "%s: descriptor refused: %s", what, err);
    if (rc == 0) {
        s = (proto_stream){-1, 0, b->p, b->len, pos};
        rc = proto_read_value(&s, &q, &v, err, sizeof err);
        CHECK(rc == PROTO_REFUSED && !v, "%s: outcome %d", what, rc);
        CHECK(contains(err, msg), "%s: message '%s' lacks '%s'", what, err, msg);
    }
    proto_request_free(&q);
    b->len = 0;
}

static void test_malformed(void)
{
    static buf b;
    proto_desc d;
    uint8_t h[PROTO_HEADER_BYTES];
    int64_t csr[3 + 2];
    double vals[4] = {0};
    uint8_t raw[64];

    frame(&b, 77, "abc", 3);
    expect(&b, PROTO_REFUSED, "unknown request opcode 77", "unknown opcode");

    proto_encode_header(h, PROTO_EXEC, (uint64_t)1 << 60);
    put(&b, h, sizeof h);
    expect(&b, PROTO_FATAL, "exceeds the limit", "oversized length");

    proto_encode_header(h, PROTO_LIST, 0);
    proto_put_u32(h + 4, 5);
    put(&b, h, sizeof h);
    expect(&b, PROTO_FATAL, "flags", "non-zero flags");

    proto_encode_header(h, PROTO_EXEC, 100);
    put(&b, h, sizeof h);
    put(&b, "x = 1", 5);
    {
        size_t pos = 0;
        proto_request q;
        char err[512];
        CHECK(read_req(&b, &pos, &q, err) == PROTO_BROKEN, "truncated body: %s", err);
        proto_request_free(&q);
        b.len = 0;
    }

    frame(&b, PROTO_EXEC, "a\0b", 3);
    expect(&b, PROTO_REFUSED, "NUL", "NUL in statement");

    frame(&b, PROTO_LIST, "x", 1);
    expect(&b, PROTO_REFUSED, "must be empty", "LIST with body");

    memset(&d, 0, sizeof d);
    d.format = SILC_DENSE;
    d.m = (int64_t)1 << 50;
    d.n = 1;
    d.nnz = d.m;
    put_frame(&b, "x", d, PROTO_DESC_BYTES + 1, NULL, 0);
    expect(&b, PROTO_REFUSED, "exceed the protocol's limit", "huge dimensions");

    d.m = -3;
    d.nnz = 0;
    put_frame(&b, "x", d, PROTO_DESC_BYTES + 1, NULL, 0);
    expect(&b, PROTO_REFUSED, "negative size", "negative size");

    d.m = 2;
    d.n = 2;
    d.nnz = 3;
    put_frame(&b, "x", d, PROTO_DESC_BYTES + 1 + 24, vals, 24);
    expect(&b, PROTO_REFUSED, "declares 3 entries", "dense nnz inconsistent");

    d.nnz = 4;
    put_frame(&b, "x", d, PROTO_DESC_BYTES + 1 + 24, vals, 24);
    expect(&b, PROTO_FATAL, "descriptor needs 32", "length inconsistent with descriptor");

    d.m = 512;
    d.n = 512;
    d.nnz = 512 * 512;
    put_frame(&b, "big", d, PROTO_DESC_BYTES + 3 + 512 * 512 * 8, NULL, 0);
    CHECK(b.len < sizeof b.p, "buffer");
    {
        /* The arrays follow in the stream: pad with zeros so the skip succeeds. */
        size_t pad = 512 * 512 * 8;
        uint8_t *big = calloc(1, b.len + pad + PROTO_HEADER_BYTES);
        proto_stream s;
        proto_request q;
        char err[512];
        memcpy(big, b.p, b.len);
        proto_encode_header(big + b.len + pad, PROTO_LIST, 0);
        s = (proto_stream){-1, 0, big, b.len + pad + PROTO_HEADER_BYTES, 0};
        CHECK(proto_read_request(&s, &lim, &q, err, sizeof err) == PROTO_REFUSED &&
                  contains(err, "per value (silcd --max-value-bytes)"), "value over limit: %s", err);
        proto_request_free(&q);
        CHECK(proto_read_request(&s, &lim, &q, err, sizeof err) == 0 && q.op == PROTO_LIST,
              "stream in step after a skipped value");
        proto_request_free(&q);
        free(big);
        b.len = 0;
    }

    /* CSR: rowptr[m] disagrees with nnz; a column out of range (embedded text). */
    d.format = SILC_CSR;
    d.m = 2;
    d.n = 3;
    d.nnz = 2;
    csr[0] = 0; csr[1] = 1; csr[2] = 1; csr[3] = 0; csr[4] = 2;
    memcpy(raw, csr, sizeof csr);
    memcpy(raw + sizeof csr, vals, 16);
    put_frame(&b, "S", d, PROTO_DESC_BYTES + 1 + sizeof csr + 16, raw, sizeof csr + 16);
    expect_value(&b, "'S': rowptr[m] = 1 but the descriptor declares 2", "nnz inconsistent");
    csr[2] = 2;
    csr[4] = 7;
    memcpy(raw, csr, sizeof csr);
    put_frame(&b, "S", d, PROTO_DESC_BYTES + 1 + sizeof csr + 16, raw, sizeof csr + 16);
    expect_value(&b, "'S': column index 7 out of range [0, 3) in row 1", "column out of range");
    csr[1] = 2; /* row 0 holds columns {2, 1}: unsorted */
    csr[3] = 2;
    csr[4] = 1;
    memcpy(raw, csr, sizeof csr);
    put_frame(&b, "S", d, PROTO_DESC_BYTES + 1 + sizeof csr + 16, raw, sizeof csr + 16);
    expect_value(&b, "not sorted", "unsorted columns");

    d.format = 9;
    put_frame(&b, "S", d, PROTO_DESC_BYTES + 1, NULL, 0);
    expect(&b, PROTO_REFUSED, "unknown value format 9", "unknown format");
}

static void test_hello_and_url(void)
{
    uint8_t h[PROTO_HELLO_BYTES + 5];
    proto_stream s;
    uint32_t version;
    char *token = NULL, err[256];
    proto_addr a;
    proto_encode_hello(h, 7, 5);
    memcpy(h + PROTO_HELLO_BYTES, "s3cr3", 5);
    s = (proto_stream){-1, 0, h, sizeof h, 0};
    CHECK(proto_read_hello(&s, &version, &token, err, sizeof err) == 0 && version == 7 &&
              token && strcmp(token, "s3cr3") == 0, "hello round trip");
    free(token);
    memcpy(h, "HTTP", 4);
    s = (proto_stream){-1, 0, h, sizeof h, 0};
    CHECK(proto_read_hello(&s, &version, &token, err, sizeof err) == PROTO_FATAL &&
              contains(err, "bad magic"), "bad magic: %s", err);
    proto_encode_hello(h, 1, 1u << 30);
    s = (proto_stream){-1, 0, h, sizeof h, 0};
    CHECK(proto_read_hello(&s, &version, &token, err, sizeof err) == PROTO_FATAL, "huge token");

    CHECK(proto_parse_url("tcp://127.0.0.1:7070", &a, err, sizeof err) == 0 && !a.is_unix &&
              strcmp(a.host, "127.0.0.1") == 0 && strcmp(a.port, "7070") == 0, "tcp url");
    CHECK(proto_parse_url("tcp://[::1]:9", &a, err, sizeof err) == 0 && strcmp(a.host, "::1") == 0,
          "v6 url");
    CHECK(proto_parse_url("unix:/tmp/s.sock", &a, err, sizeof err) == 0 && a.is_unix &&
              strcmp(a.path, "/tmp/s.sock") == 0, "unix url");
    CHECK(proto_parse_url("http://x:1", &a, err, sizeof err) != 0 && contains(err, "tcp://"),
          "bad scheme: %s", err);
    CHECK(proto_parse_url("tcp://host:99999", &a, err, sizeof err) != 0, "bad port");
}

/* The learned spin budgets (client.h, proto_spin_memo), fed waits as
 * numbers: the policy, not the clock. */
static void test_spin_memo(void)
{
    proto_spin_memo m;
    uint64_t solve = proto_spin_kind(PROTO_EXEC, "dv = A \\ b"),
             update = proto_spin_kind(PROTO_EXEC, "x += dt * v"), get = proto_spin_kind(PROTO_GET, "x"),
             other, collide = 0;
    int k, spins = 0;
    memset(&m, 0, sizeof m);
    CHECK(solve && update && get && solve != update && solve != proto_spin_kind(PROTO_GET, "dv = A \\ b") &&
              get != proto_spin_kind(PROTO_GET, "y") && get == proto_spin_kind(PROTO_GET, "x"),
          "kinds tell op and text apart, and repeat");
    CHECK(proto_spin_budget(&m, solve) == PROTO_SPIN_NS, "a new kind spins");
    proto_spin_learn(&m, solve, 3000000);          /* a 3 ms EXEC */
    proto_spin_learn(&m, get, 20000);              /* a 20 us GET */
    CHECK(proto_spin_budget(&m, get) == PROTO_SPIN_NS, "a quick kind spins");
    CHECK(proto_spin_budget(&m, update) == PROTO_SPIN_NS, "another kind is not judged by a slow one");
    /* A slow kind sleeps at once, but probes once every PROTO_SPIN_PROBE waits. */
    for (k = 0; k < 4 * PROTO_SPIN_PROBE; k++) spins += proto_spin_budget(&m, solve) != 0;
    CHECK(spins == 4, "a slow kind spins %d times in %d waits, want 4", spins, 4 * PROTO_SPIN_PROBE);
    proto_spin_learn(&m, solve, PROTO_SPIN_NS - 1); /* it became quick */
    CHECK(proto_spin_budget(&m, solve) == PROTO_SPIN_NS, "a kind that became quick spins again");
    proto_spin_learn(&m, solve, PROTO_SPIN_NS);
    CHECK(proto_spin_budget(&m, solve) == 0, "a wait as long as the spin itself was not caught by it");
    /* A kind in the same slot takes it over and starts afresh. */
    for (k = 0; k < 100000 && !collide; k++) {
        char name[32];
        snprintf(name, sizeof name, "v%d", k);
        other = proto_spin_kind(PROTO_GET, name);
        if (other != solve && other % PROTO_SPIN_KINDS == solve % PROTO_SPIN_KINDS) collide = other;
    }
    CHECK(collide != 0, "a colliding kind was found");
    CHECK(proto_spin_budget(&m, collide) == PROTO_SPIN_NS, "a colliding kind is new, so spins");
    proto_spin_learn(&m, collide, 10);
    CHECK(proto_spin_budget(&m, solve) == PROTO_SPIN_NS, "the slot's old kind is forgotten, so spins");
}

int main(void)
{
    test_roundtrip();
    test_malformed();
    test_hello_and_url();
    test_spin_memo();
    return check_done();
}
