/*
 * test_remote.c -- silcd under hostile and unlucky clients, on private
 * servers this test starts: malformed frames of every kind answered with an
 * ERROR or a clean disconnect while a well-behaved client keeps being served;
 * a client killed in the middle of a PUT; a client stalling inside a frame;
 * the session memory limit (PUT refused up front, EXEC rolled back, nothing
 * lost); token authentication and the refusal to listen off loopback without
 * one; identical messages, output and warnings in embedded and remote mode;
 * a clean SIGTERM shutdown.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>

#include "check.h"
#include "remote_util.h"
#include "silc.h"

static int contains(const char *s, const char *sub)
{
    return s && strstr(s, sub) != NULL;
}

/* The well-behaved client: x must stay 1..n throughout. */
static silc_context *good;
static const int good_n = 100;

static void good_still_served(const char *after)
{
    silc_envelope_t e;
    double s = 0;
    int64_t i;
    int ok = silc_exec(good, "t = sum(x)") == 0 && silc_get(good, &e, "t") == 0;
    CHECK(ok, "after %s: good client failed: %s", after, silc_context_errmsg(good));
    if (ok) {
        s = e.values[0];
        silc_envelope_free(&e);
    }
    CHECK(s == good_n * (good_n + 1) / 2.0, "after %s: sum(x) = %g", after, s);
    ok = silc_get(good, &e, "x") == 0;
    for (i = 0; ok && i < good_n; i++)
        if (e.values[i] != (double)(i + 1)) ok = 0;
    CHECK(ok, "after %s: x changed", after);
    silc_envelope_free(&e);
}

/* Sends bytes after a handshake; want_op is the reply expected (PROTO_ERROR),
 * then either the connection still answers LIST (alive) or is closed. */
static void malformed(const char *url, const void *bytes, size_t n, const char *msg, int alive,
                      const char *what)
{
    char *text = NULL;
    int fd = raw_open(url, PROTO_VERSION, NULL, &text), op;
    uint8_t list[PROTO_HEADER_BYTES];
    CHECK(fd >= 0, "%s: handshake failed", what);
    if (fd < 0) return;
    raw_send(fd, bytes, n);
    op = raw_reply(fd, &text, 5000);
    CHECK(op == PROTO_ERROR && contains(text, msg), "%s: reply %d '%s', want ERROR with '%s'",
          what, op, text ? text : "", msg);
    free(text);
    proto_encode_header(list, PROTO_LIST, 0);
    raw_send(fd, list, sizeof list);
    op = raw_reply(fd, &text, 5000);
    if (alive) CHECK(op == PROTO_OK, "%s: session did not survive (%d)", what, op);
    else CHECK(op == -1, "%s: connection not closed (%d)", what, op);
    free(text);
    close(fd);
    good_still_served(what);
}

static void test_malformed(const char *url)
{
    uint8_t b[512];
    proto_desc d;
    size_t n;
    int64_t csr[5];
    char *text;
    int fd, op;

    proto_encode_header(b, 77, 3);
    memcpy(b + PROTO_HEADER_BYTES, "abc", 3);
    malformed(url, b, PROTO_HEADER_BYTES + 3, "unknown request opcode 77", 1, "unknown opcode");

    proto_encode_header(b, PROTO_EXEC, (uint64_t)1 << 62);
    malformed(url, b, PROTO_HEADER_BYTES, "exceeds the limit", 0, "oversized length");

    proto_encode_header(b, PROTO_GET, 1);
    proto_put_u32(b + 4, 1);
    malformed(url, b, PROTO_HEADER_BYTES, "flags", 0, "non-zero flags");

    memset(&d, 0, sizeof d);
    d.format = SILC_DENSE;
    d.m = (int64_t)1 << 45;
    d.n = (int64_t)1 << 45;
    d.nnz = 1;
    n = raw_put_header(b, "h", d, PROTO_DESC_BYTES + 1);
    malformed(url, b, n, "exceed the protocol's limit", 1, "huge dimensions");

    d.m = -1;
    d.n = 4;
    d.nnz = -4;
    n = raw_put_header(b, "h", d, PROTO_DESC_BYTES + 1);
    malformed(url, b, n, "negative size", 1, "negative sizes");

    d.m = 2;
    d.n = 2;
    d.nnz = 4;
    n = raw_put_header(b, "h", d, (uint64_t)-1);
    malformed(url, b, n, "descriptor needs 32", 0, "length inconsistent with descriptor");

    /* 600 KB over the 512 KB limit, sent whole: refused, the arrays skipped,
     * the session goes on. */
    {
        size_t payload = 75000 * 8;
        uint8_t *big = calloc(1, 128 + payload);
        d.m = 75000;
        d.n = 1;
        d.nnz = d.m;
        n = raw_put_header(big, "h", d, PROTO_DESC_BYTES + 1 + payload);
        malformed(url, big, n + payload, "value of 600000 bytes (585.9 KiB), over the limit of 524288 bytes (512.0 KiB) by 73.9 KiB per value (silcd --max-value-bytes)",
                  1, "value over the limit");
        free(big);
    }

    d.format = SILC_CSR;
    d.m = 2;
    d.n = 3;
    d.nnz = 2;
    csr[0] = 0; csr[1] = 1; csr[2] = 1; csr[3] = 0; csr[4] = 2;
    n = raw_put_header(b, "S", d, PROTO_DESC_BYTES + 1 + sizeof csr + 16);
    memcpy(b + n, csr, sizeof csr);
    memset(b + n + sizeof csr, 0, 16);
    malformed(url, b, n + sizeof csr + 16, "rowptr[m] = 1 but the descriptor declares 2", 1,
              "nnz inconsistent");

    proto_encode_header(b, PROTO_EXEC, 5);
    memcpy(b + PROTO_HEADER_BYTES, "x\0= 1", 5);
    malformed(url, b, PROTO_HEADER_BYTES + 5, "NUL", 1, "NUL in statement");

    /* Wrong version and bad magic: ERROR, then closed. */
    fd = raw_open(url, 99, NULL, &text);
    CHECK(fd < 0 && contains(text, "protocol version 99 is not supported"), "wrong version: %s",
          text ? text : "");
    free(text);
    fd = raw_connect(url);
    raw_send(fd, "GET / HTTP/1.0\r\n\r\n", 18);
    op = raw_reply(fd, &text, 5000);
    CHECK(op == PROTO_ERROR && contains(text, "bad magic"), "bad magic: %d %s", op,
          text ? text : "");
    free(text);
    op = raw_reply(fd, &text, 5000);
    CHECK(op == -1, "bad magic: not closed");
    free(text);
    close(fd);

    /* Truncated frames: closed at once, or dropped after the io timeout. */
    fd = raw_open(url, PROTO_VERSION, NULL, &text);
    raw_send(fd, b, 7);
    close(fd);
    good_still_served("truncated header, then close");
    fd = raw_open(url, PROTO_VERSION, NULL, &text);
    proto_encode_header(b, PROTO_EXEC, 100);
    raw_send(fd, b, PROTO_HEADER_BYTES + 10);
    good_still_served("a stalled frame (while it stalls)");
    op = raw_reply(fd, &text, 5000);
    CHECK(op == -1, "stalled frame: not dropped after the io timeout (%d)", op);
    free(text);
    close(fd);
    good_still_served("stalled frame");
}

/* A child process connects, sends half of a 4 MiB PUT of 'x', and is killed. */
static void test_killed_mid_put(const char *url)
{
    /* 2 MiB of a 4 MiB PUT, then SIGKILL */
    pid_t pid = raw_partial_put(url, "x", 512 * 1024, 2u << 20);
    CHECK(pid > 0, "child did not start its PUT");
    if (pid > 0) {
        kill(pid, SIGKILL);
        waitpid(pid, NULL, 0);
    }
    good_still_served("a client killed mid-PUT");
}

static void test_session_limit(void)
{
    silc_envelope_t e, g;
    double *big = calloc(65000, sizeof(double));
    /* 520 KB each: under the value limit, two of them over the session's. */
    CHECK(silc_envelope_vector(&e, 65000, big) == 0, "envelope");
    CHECK(silc_put(good, "y", &e) == 0, "first 520 KB put: %s", silc_context_errmsg(good));
    CHECK(silc_put(good, "z", &e) != 0 &&
              contains(silc_context_errmsg(good), "session memory limit exceeded: storing 'z'"),
          "second put over the session limit: %s", silc_context_errmsg(good));
    /* Rebinding y to a value of the same size fits: the old one is released. */
    CHECK(silc_put(good, "y", &e) == 0, "rebinding y: %s", silc_context_errmsg(good));
    CHECK(silc_exec(good, "w = y * 2; t2 = 5") != 0 &&
              contains(silc_context_errmsg(good), "rolled back"),
          "exec over the limit: %s", silc_context_errmsg(good));
    CHECK(silc_get(good, &g, "w") != 0 && contains(silc_context_errmsg(good), "undefined name 'w'"),
          "w bound after rollback");
    CHECK(silc_get(good, &g, "t2") != 0, "t2 bound after rollback");
    CHECK(silc_exec(good, "clear y") == 0, "clear y: %s", silc_context_errmsg(good));
    good_still_served("session limit");
    silc_envelope_free(&e);
    free(big);
}

static void capture(void *user, const char *text)
{
    strncat((char *)user, text, 4095 - strlen((char *)user));
}

/* Messages, output and warnings: the same text embedded and remote. */
static void test_same_texts(void)
{
    static const char *const bad[] = {"u = undefined_thing + 1", "x = (1 + ", "x = [1,2] * [3,4]",
                                      "set dispatch.solve.dense = nosuch"};
    silc_context *emb = NULL;
    silc_envelope_t e, g;
    char out_e[4096] = "", out_r[4096] = "";
    int64_t rp[3] = {0, 2, 3}, ci[3] = {1, 0, 1};
    double v[3] = {1, 2, 3};
    const char *server = getenv("SILC_SERVER");
    size_t i;
    char saved[600] = "";
    /* An embedded context even when the whole suite runs remote. */
    if (server) snprintf(saved, sizeof saved, "%s", server);
    unsetenv("SILC_SERVER");
    CHECK(silc_open(&emb, NULL) == 0, "embedded open");
    if (*saved) setenv("SILC_SERVER", saved, 1);
    for (i = 0; i < sizeof bad / sizeof *bad; i++) {
        int re = silc_exec(emb, bad[i]), rr = silc_exec(good, bad[i]);
        CHECK(re != 0 && rr != 0 && strcmp(silc_context_errmsg(emb), silc_context_errmsg(good)) == 0,
              "'%s': embedded '%s' vs remote '%s'", bad[i], silc_context_errmsg(emb),
              silc_context_errmsg(good));
    }
    CHECK(silc_get(emb, &g, "qqqqqq") != 0 && silc_get(good, &g, "qqqqqq") != 0 &&
              strcmp(silc_context_errmsg(emb), silc_context_errmsg(good)) == 0,
          "get: '%s' vs '%s'", silc_context_errmsg(emb), silc_context_errmsg(good));
    /* An envelope with unsorted columns, built by hand. */
    memset(&e, 0, sizeof e);
    e.m = 2;
    e.n = 2;
    e.format = SILC_CSR;
    e.rowptr = rp;
    e.colind = ci;
    e.values = v;
    e.nnz = 3;
    CHECK(silc_put(emb, "S", &e) != 0 && silc_put(good, "S", &e) != 0 &&
              strcmp(silc_context_errmsg(emb), silc_context_errmsg(good)) == 0,
          "put: '%s' vs '%s'", silc_context_errmsg(emb), silc_context_errmsg(good));
    CHECK(silc_put(good, "1x", &e) != 0 && contains(silc_context_errmsg(good), "invalid name"),
          "invalid name");
    /* who/info/explain output and warnings. */
    silc_set_output(emb, capture, out_e);
    silc_set_output(good, capture, out_r);
    /* The same names on both sides, so that `who` prints the same. */
    CHECK(silc_exec(emb, "x = ones(100, 1); t = 1") == 0, "embedded x");
    CHECK(silc_exec(emb, "A = ones(2,2) + eye(2)*1e-14; b = A \\ ones(2,1)") == 0,
          "embedded ill-conditioned solve: %s", silc_context_errmsg(emb));
    CHECK(silc_exec(good, "A = ones(2,2) + eye(2)*1e-14; b = A \\ ones(2,1)") == 0,
          "remote ill-conditioned solve: %s", silc_context_errmsg(good));
    CHECK(strcmp(silc_context_warnings(emb), silc_context_warnings(good)) == 0 &&
              *silc_context_warnings(good),
          "warnings: '%s' vs '%s'", silc_context_warnings(emb), silc_context_warnings(good));
    silc_exec(emb, "who; explain c = A \\ b");
    silc_exec(good, "who; explain c = A \\ b");
    CHECK(strcmp(out_e, out_r) == 0 && contains(out_r, "A"), "output:\n%s\nvs\n%s", out_e, out_r);
    silc_set_output(good, NULL, NULL);
    silc_exec(good, "clear A b");
    silc_close(&emb);
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static void test_tokens(void)
{
    test_server s;
    char tokf[128], opt[160], *text = NULL;
    const char *opts[3];
    int fd;
    silc_context *c = NULL;
    snprintf(tokf, sizeof tokf, "/tmp/silc-token-%d", (int)getpid());
    write_file(tokf, "correct horse battery staple\n");
    chmod(tokf, 0600);   /* silcd refuses a token file others can read */
    snprintf(opt, sizeof opt, "--token-file=%s", tokf);
    opts[0] = opt;
    opts[1] = NULL;
    CHECK(server_start(&s, NULL, opts) == 0, "token server did not start");
    fd = raw_open(s.url, PROTO_VERSION, "correct horse battery staple", &text);
    CHECK(fd >= 0, "right token refused: %s", text ? text : "");
    if (fd >= 0) close(fd);
    fd = raw_open(s.url, PROTO_VERSION, "correct horse battery stapler", &text);
    CHECK(fd < 0 && contains(text, "authentication failed: wrong token"), "wrong token: %s",
          text ? text : "");
    free(text);
    fd = raw_open(s.url, PROTO_VERSION, NULL, &text);
    CHECK(fd < 0 && contains(text, "authentication failed: missing token"), "missing token: %s",
          text ? text : "");
    free(text);
    /* Through the API: SILC_TOKEN_FILE and SILC_TOKEN. */
    unsetenv("SILC_TOKEN");
    setenv("SILC_TOKEN_FILE", tokf, 1);
    CHECK(silc_open_remote(&c, s.url) == 0, "SILC_TOKEN_FILE: %s", silc_errmsg());
    silc_close(&c);
    setenv("SILC_TOKEN", "nope", 1);
    CHECK(silc_open_remote(&c, s.url) != 0 && contains(silc_errmsg(), "authentication failed"),
          "SILC_TOKEN wrong: %s", silc_errmsg());
    unsetenv("SILC_TOKEN");
    unsetenv("SILC_TOKEN_FILE");
    CHECK(server_stop(&s) == 0, "token server did not stop cleanly");

    /* TCP on loopback, port chosen by the kernel, with the token. */
    CHECK(server_start(&s, "tcp://127.0.0.1:0", opts) == 0, "tcp server did not start");
    setenv("SILC_TOKEN", "correct horse battery staple", 1);
    CHECK(silc_open_remote(&c, s.url) == 0 && silc_exec(c, "q = 2 + 2") == 0,
          "tcp session: %s", c ? silc_context_errmsg(c) : silc_errmsg());
    silc_close(&c);
    unsetenv("SILC_TOKEN");
    CHECK(server_stop(&s) == 0, "tcp server did not stop cleanly");

    /* Off loopback: refused without a token (nothing is bound). */
    CHECK(server_start(&s, "tcp://0.0.0.0:0", NULL) == 1, "non-loopback listen without a token "
          "was not refused");
    CHECK(server_start(&s, NULL, (const char *const[]){"--token-file=/nonexistent/tok", NULL}) != 0,
          "missing token file accepted");
    unlink(tokf);
}

int main(void)
{
    test_server s;
    const char *opts[] = {"--io-timeout=1", "--max-value-bytes=512K", "--max-session-bytes=1000000",
                          NULL};
    silc_envelope_t x;
    double xs[100];
    int i;
    signal(SIGPIPE, SIG_IGN);
    if (server_start(&s, NULL, opts) != 0) {
        CHECK(0, "silcd did not start");
        return check_done();
    }
    CHECK(silc_open_remote(&good, s.url) == 0, "open: %s", silc_errmsg());
    for (i = 0; i < good_n; i++) xs[i] = i + 1;
    silc_envelope_vector(&x, good_n, xs);
    CHECK(silc_put(good, "x", &x) == 0, "put x: %s", silc_context_errmsg(good));
    silc_envelope_free(&x);
    test_malformed(s.url);
    test_killed_mid_put(s.url);
    test_session_limit();
    test_same_texts();
    silc_close(&good);
    CHECK(server_stop(&s) == 0, "silcd did not shut down cleanly on SIGTERM");
    test_tokens();
    return check_done();
}
