/*
 * clients_c.c -- the C client (libsilc's remote mode) as clients.py drives
 * it against its fake silcd: opens a remote context on URL, makes each call
 * (get:NAME with silc_get, getc:NAME with silc_get_complex, exec:TEXT) and
 * prints one line per call, "OK <format> <shape> ..." or "ERROR silc:
 * <message>", and exits 0 by itself whatever the server sent (a signal exit
 * is what the test catches).
 *
 *     clients_c URL CALL...
 */
#include <stdio.h>
#include <string.h>

#include "silc.h"

static void print_value(const silc_envelope_t *e)
{
    if (e->format == SILC_BAND)
        printf("OK band %lldx%lld kl=%lld ku=%lld\n", (long long)e->m, (long long)e->n,
               (long long)e->kl, (long long)e->ku);
    else if (e->format == SILC_CSR)
        printf("OK csr %lldx%lld nnz %lld\n", (long long)e->m, (long long)e->n,
               (long long)e->nnz);
    else if (silc_envelope_is_complex(e))
        printf("OK complex dense %lldx%lld %g %g\n", (long long)e->m, (long long)e->n,
               e->m * e->n > 0 ? e->values[0] : 0.0, e->m * e->n > 0 ? e->values[1] : 0.0);
    else
        printf("OK dense %lldx%lld %g\n", (long long)e->m, (long long)e->n,
               e->m * e->n > 0 ? e->values[0] : 0.0);
}

int main(int argc, char **argv)
{
    silc_context *ctx = NULL;
    int i;
    if (argc < 2) {
        fprintf(stderr, "usage: clients_c URL CALL...\n");
        return 2;
    }
    if (silc_open_remote(&ctx, argv[1])) {
        printf("ERROR silc: %s\n", silc_errmsg());
        return 0;
    }
    for (i = 2; i < argc; i++) {
        if (strncmp(argv[i], "exec:", 5) == 0) {
            if (silc_exec(ctx, argv[i] + 5)) printf("ERROR silc: %s\n", silc_context_errmsg(ctx));
            else printf("OK exec\n");
        } else {
            silc_envelope_t e;
            int complex_ok = strncmp(argv[i], "getc:", 5) == 0;
            const char *name = strchr(argv[i], ':') + 1;
            if (complex_ok ? silc_get_complex(ctx, &e, name) : silc_get(ctx, &e, name)) {
                printf("ERROR silc: %s\n", silc_context_errmsg(ctx));
                continue;
            }
            print_value(&e);
            silc_envelope_free(&e);
        }
        fflush(stdout);
    }
    silc_close(&ctx);
    return 0;
}
