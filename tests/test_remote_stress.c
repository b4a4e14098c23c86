/*
 * test_remote_stress.c -- 32 clients at once, 1000 mixed requests each (PUT,
 * EXEC, GET, output, errors) on one private silcd, every result checked:
 * nothing lost, nothing crossed between sessions.  Each client's data carry
 * its own signature (client id and step), so a value from another session or
 * an earlier step cannot pass for the right one.
 */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <stdint.h>

#include "check.h"
#include "remote_util.h"
#include "silc.h"

#define CLIENTS 32
#define REQUESTS 1000

static const char *url;

typedef struct client {
    int id;
    int ok, bad;
    char first_error[512];
    char out[256];
} client;

static void fail(client *c, const char *fmt, ...)
{
    va_list ap;
    c->bad++;
    if (c->first_error[0]) return;
    va_start(ap, fmt);
    vsnprintf(c->first_error, sizeof c->first_error, fmt, ap);
    va_end(ap);
}

static void capture(void *user, const char *text)
{
    client *c = user;
    strncat(c->out, text, sizeof c->out - 1 - strlen(c->out));
}

static void *run(void *p)
{
    client *c = p;
    silc_context *ctx = NULL;
    silc_envelope_t e, g;
    double v[8];
    char stmt[128];
    int k, i, n;
    if (silc_open_remote(&ctx, url)) {
        fail(c, "open: %s", silc_errmsg());
        return NULL;
    }
    silc_set_output(ctx, capture, c);
    /* Four requests per step: PUT v, EXEC w = v*2 + id, GET w, and a fourth:
     * usually GET v back, every 10th step an error, or a `who` whose output
     * must name only this session's names. */
    for (k = 0; k < REQUESTS / 4; k++) {
        n = 1 + (k + c->id) % 8;
        for (i = 0; i < n; i++) v[i] = c->id * 1000.0 + k + i * 0.5;
        silc_envelope_vector(&e, n, v);
        if (silc_put(ctx, "v", &e)) fail(c, "put %d: %s", k, silc_context_errmsg(ctx));
        silc_envelope_free(&e);
        snprintf(stmt, sizeof stmt, "w = v * 2 + %d", c->id);
        if (silc_exec(ctx, stmt)) fail(c, "exec %d: %s", k, silc_context_errmsg(ctx));
        if (silc_get(ctx, &g, "w")) {
            fail(c, "get %d: %s", k, silc_context_errmsg(ctx));
        } else {
            int good = g.m == n && g.n == 1;
            for (i = 0; good && i < n; i++) good = g.values[i] == 2 * v[i] + c->id;
            if (good) c->ok++;
            else fail(c, "step %d: wrong w (%lldx%lld, w[0] = %g)", k, (long long)g.m,
                      (long long)g.n, g.m > 0 ? g.values[0] : 0.0);
            silc_envelope_free(&g);
        }
        if (k % 10 == 0) {
            if (silc_exec(ctx, "z = nosuch + 1") == 0 ||
                !strstr(silc_context_errmsg(ctx), "undefined name 'nosuch'"))
                fail(c, "error %d: '%s'", k, silc_context_errmsg(ctx));
        } else if (k % 10 == 5) {
            c->out[0] = '\0';
            snprintf(stmt, sizeof stmt, "c%d = 1; who; clear c%d", c->id, c->id);
            if (silc_exec(ctx, stmt)) fail(c, "who: %s", silc_context_errmsg(ctx));
            snprintf(stmt, sizeof stmt, "c%d ", c->id);
            if (!strstr(c->out, stmt) || strstr(c->out, "\nz ")) fail(c, "who: %s", c->out);
            for (i = 0; i < CLIENTS; i++) {
                char other[16];
                snprintf(other, sizeof other, "c%d ", i);
                if (i != c->id && strstr(c->out, other)) fail(c, "saw c%d: %s", i, c->out);
            }
        } else if (silc_get(ctx, &g, "v")) {
            fail(c, "get v %d: %s", k, silc_context_errmsg(ctx));
        } else {
            int good = g.m == n;
            for (i = 0; good && i < n; i++) good = g.values[i] == v[i];
            if (!good) fail(c, "step %d: wrong v", k);
            silc_envelope_free(&g);
        }
    }
    silc_close(&ctx);
    return NULL;
}

int main(void)
{
    test_server s;
    const char *opts[] = {"--io-timeout=10", NULL};
    pthread_t th[CLIENTS];
    static client cl[CLIENTS];
    int i, total = 0;
    if (server_start(&s, NULL, opts) != 0) {
        CHECK(0, "silcd did not start");
        return check_done();
    }
    url = s.url;
    for (i = 0; i < CLIENTS; i++) {
        cl[i].id = i;
        pthread_create(&th[i], NULL, run, &cl[i]);
    }
    for (i = 0; i < CLIENTS; i++) pthread_join(th[i], NULL);
    for (i = 0; i < CLIENTS; i++) {
        CHECK(cl[i].bad == 0, "client %d: %d failures, first: %s", i, cl[i].bad, cl[i].first_error);
        CHECK(cl[i].ok == REQUESTS / 4, "client %d: %d of %d results verified", i, cl[i].ok,
              REQUESTS / 4);
        total += cl[i].ok;
    }
    printf("%d clients: %d results verified\n", CLIENTS, total);
    CHECK(server_stop(&s) == 0, "silcd did not shut down cleanly");
    return check_done();
}
