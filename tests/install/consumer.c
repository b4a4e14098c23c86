/*
 * consumer.c -- a user's C program against an installed SILC: solves a
 * small SPD system through the default dispatch, checks the answer, and
 * prints which plugin files the process mapped, so test_install.sh can see
 * that the installed libsilc found the installed plugins by itself.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <silc.h>

int main(void)
{
    static const int64_t rp[] = {0, 2, 5, 7};
    static const int64_t ci[] = {0, 1, 0, 1, 2, 1, 2};
    static const double v[] = {4, -1, -1, 4, -1, -1, 4};
    static const double b[] = {3, 2, 3};
    silc_envelope_t A, B, X;
    double x[3], err = 0;
    char line[4096];
    FILE *maps;
    int i;
    if (SILC_INIT() || silc_envelope_csr(&A, 3, 3, rp, ci, v) || silc_envelope_vector(&B, 3, b) ||
        SILC_PUT("A", &A) || SILC_PUT("b", &B) || SILC_EXEC("x = A \\ b") || SILC_GET(&X, "x") ||
        silc_envelope_to_dense(&X, x)) {
        fprintf(stderr, "consumer: %s\n", silc_errmsg());
        return 1;
    }
    for (i = 0; i < 3; i++) err = fmax(err, fabs(x[i] - 1)); /* A * ones = b */
    printf("consumer: SILC %s, x = A \\ b off by %.1e\n", SILC_VERSION, err);
    maps = fopen("/proc/self/maps", "r");
    while (maps && fgets(line, sizeof line, maps))
        /* one line per mapped segment: a file shows several times, which is harmless */
        if (strstr(line, "libsilc_plugin_") && strchr(line, '/')) printf("plugin %s", strchr(line, '/'));
    if (maps) fclose(maps);
    silc_envelope_free(&A);
    silc_envelope_free(&B);
    silc_envelope_free(&X);
    SILC_FINALIZE();
    return err < 1e-14 ? 0 : 1;
}
