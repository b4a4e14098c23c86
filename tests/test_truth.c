/*
 * test_truth.c -- SILC's numbers against independent truth computed by numpy/scipy.
 *
 * tests/gen_truth.py wrote small fixed matrices to SILC_TEST_DATA/inputs/NAME.mtx
 * and, for every case of truth.tsv (name, statements, expect file, cond), the
 * numpy/scipy answer to SILC_TEST_DATA/expect/FILE.  For each case this program
 * opens a fresh context, PUTs every input under its file stem, runs the
 * statements and compares `r` with the expected matrix.  The expected files are
 * parsed here by a few lines of C rather than by silc_mm_read, so a reader bug
 * cannot make a wrong answer look right.  Tolerance, relative to the largest
 * expected magnitude: 1e-14 for exact operations ("-"), 1e-12 * max(1, cond)
 * for solves.  A failing case is reported by name with the worst entry.
 */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "silc.h"

#ifndef SILC_TEST_DATA
#define SILC_TEST_DATA "tests/data"
#endif

#define MAX_INPUTS 64

typedef struct {
    char name[64];
    silc_envelope_t e;
} input;

static input inputs[MAX_INPUTS];
static int ninputs;

/* Loads every DATA/inputs/NAME.mtx; the variable name is the file stem. */
static int load_inputs(const char *data)
{
    char dir[1024], path[2048], err[256];
    snprintf(dir, sizeof dir, "%s/inputs", data);
    DIR *d = opendir(dir);
    if (!d) {
        fprintf(stderr, "cannot open input directory %s\n", dir);
        return 1;
    }
    struct dirent *de;
    int rc = 0;
    while ((de = readdir(d)) != NULL) {
        size_t len = strlen(de->d_name);
        if (len < 5 || strcmp(de->d_name + len - 4, ".mtx") != 0)
            continue;
        if (ninputs == MAX_INPUTS || len - 4 >= sizeof inputs[0].name) {
            fprintf(stderr, "too many inputs or name too long: %s\n", de->d_name);
            rc = 1;
            break;
        }
        input *in = &inputs[ninputs];
        memcpy(in->name, de->d_name, len - 4);
        in->name[len - 4] = '\0';
        snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
        if (silc_mm_read(&in->e, path, err, sizeof err)) {
            fprintf(stderr, "silc_mm_read %s: %s\n", path, err);
            rc = 1;
            break;
        }
        ninputs++;
    }
    closedir(d);
    return rc;
}

/* Reads a dense Matrix Market array file (column-major) written by gen_truth.py.
 * Returns a malloc'd array, or NULL with a message. */
static double *read_expect(const char *path, int64_t *m, int64_t *n)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "cannot open %s\n", path);
        return NULL;
    }
    char line[256];
    long long mm = -1, nn = -1;
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '%')
            continue;
        if (sscanf(line, "%lld %lld", &mm, &nn) == 2)
            break;
    }
    double *v = NULL;
    if (mm >= 0 && nn >= 0)
        v = malloc(sizeof *v * (size_t)(mm * nn > 0 ? mm * nn : 1));
    for (long long k = 0; v && k < mm * nn; k++) {
        if (fscanf(f, "%lf", &v[k]) != 1) {
            free(v);
            v = NULL;
        }
    }
    fclose(f);
    if (!v)
        fprintf(stderr, "%s: not a dense Matrix Market array\n", path);
    *m = mm;
    *n = nn;
    return v;
}

/* Runs one case in a fresh context and checks r; returns 1 if it passed. */
static int run_case(const char *data, const char *name, const char *stmt, const char *file,
                    const char *condtext)
{
    char path[2048];
    int64_t em, en;
    snprintf(path, sizeof path, "%s/expect/%s", data, file);
    double *want = read_expect(path, &em, &en);
    if (!want)
        return 0;
    double rtol = 1e-14;
    if (strcmp(condtext, "-") != 0) {
        double c = atof(condtext);
        rtol = 1e-12 * (c > 1 ? c : 1);
    }

    int ok = 0;
    silc_context *ctx = NULL;
    silc_envelope_t r = {0};
    double *got = NULL;
    if (silc_open(&ctx, NULL)) {
        fprintf(stderr, "[%s] silc_open: %s\n", name, ctx ? silc_context_errmsg(ctx) : silc_errmsg());
        goto done;
    }
    for (int i = 0; i < ninputs; i++) {
        if (silc_put(ctx, inputs[i].name, &inputs[i].e)) {
            fprintf(stderr, "[%s] put %s: %s\n", name, inputs[i].name, silc_context_errmsg(ctx));
            goto done;
        }
    }
    if (silc_exec(ctx, stmt)) {
        fprintf(stderr, "[%s] `%s` failed: %s\n", name, stmt, silc_context_errmsg(ctx));
        goto done;
    }
    if (silc_get(ctx, &r, "r")) {
        fprintf(stderr, "[%s] get r: %s\n", name, silc_context_errmsg(ctx));
        goto done;
    }
    if (silc_envelope_rows(&r) != em || silc_envelope_cols(&r) != en) {
        fprintf(stderr, "[%s] `%s` gave %lldx%lld, want %lldx%lld\n", name, stmt,
                (long long)silc_envelope_rows(&r), (long long)silc_envelope_cols(&r),
                (long long)em, (long long)en);
        goto done;
    }
    got = malloc(sizeof *got * (size_t)(em * en > 0 ? em * en : 1));
    if (!got || silc_envelope_to_dense(&r, got)) {
        fprintf(stderr, "[%s] cannot convert r to dense\n", name);
        goto done;
    }
    double scale = 0, worst = 0;
    int64_t at = 0;
    for (int64_t k = 0; k < em * en; k++)
        if (fabs(want[k]) > scale)
            scale = fabs(want[k]);
    if (scale == 0)
        scale = 1;
    for (int64_t k = 0; k < em * en; k++) {
        double d = fabs(got[k] - want[k]);
        if (!(d <= worst)) { /* also catches NaN */
            worst = d;
            at = k;
        }
    }
    ok = worst <= rtol * scale;
    if (!ok)
        fprintf(stderr, "[%s] `%s`: r(%lld,%lld) = %.17g, want %.17g (|diff| %.3g > %.3g)\n", name,
                stmt, (long long)(at % em + 1), (long long)(at / em + 1), got[at], want[at], worst,
                rtol * scale);
done:
    free(got);
    free(want);
    silc_envelope_free(&r);
    silc_close(&ctx);
    return ok;
}

int main(int argc, char **argv)
{
    const char *data = argc > 1 ? argv[1] : SILC_TEST_DATA;
    char path[2048], line[4096];
    if (load_inputs(data)) {
        CHECK(0, "inputs of %s could not be loaded", data);
        return check_done();
    }
    snprintf(path, sizeof path, "%s/truth.tsv", data);
    FILE *f = fopen(path, "r");
    CHECK(f != NULL, "cannot open %s", path);
    int ncases = 0;
    while (f && fgets(line, sizeof line, f)) {
        line[strcspn(line, "\r\n")] = '\0';
        if (line[0] == '#' || line[0] == '\0')
            continue;
        char *field[4];
        int nf = 0;
        char *p = line;
        for (; nf < 4 && p; nf++) {
            field[nf] = p;
            p = strchr(p, '\t');
            if (p)
                *p++ = '\0';
        }
        if (nf != 4 || p) {
            CHECK(0, "truth.tsv: malformed line starting '%s'", line);
            continue;
        }
        ncases++;
        CHECK(run_case(data, field[0], field[1], field[2], field[3]), "case %s: %s", field[0],
              field[1]);
    }
    if (f)
        fclose(f);
    CHECK(ncases >= 40, "only %d cases in truth.tsv", ncases);
    for (int i = 0; i < ninputs; i++)
        silc_envelope_free(&inputs[i].e);
    return check_done();
}
