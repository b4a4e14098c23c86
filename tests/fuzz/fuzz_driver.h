/*
 * fuzz_driver.h -- the deterministic mutation driver shared by the text
 * fuzzers (fuzz_lang.c, fuzz_config.c) when they are built with
 * SILC_FUZZ_DRIVER instead of libFuzzer: it reads the seed corpus
 * directories named on the command line (in file-name order, so that a run
 * does not depend on the file system), runs every seed, then ITERATIONS
 * mutants of them made with a fixed xorshift sequence, so a CI failure
 * reproduces exactly.  The including file defines fuzz_tokens[] (pieces of
 * its input language that byte mutations would take long to find) and
 * LLVMFuzzerTestOneInput, then calls fuzz_main.
 */
#ifndef SILC_FUZZ_DRIVER_H
#define SILC_FUZZ_DRIVER_H

#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_rng.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct fuzz_seed {
    char *p;
    size_t len;
} fuzz_seed;

static fuzz_seed *fuzz_seeds;
static size_t fuzz_nseeds;
static void fuzz_add_seed(const char *p, size_t len)
{
    fuzz_seed *ns = realloc(fuzz_seeds, (fuzz_nseeds + 1) * sizeof *ns);
    if (!ns) exit(1);
    fuzz_seeds = ns;
    if (!(ns[fuzz_nseeds].p = malloc(len + 1))) exit(1);
    if (len) memcpy(ns[fuzz_nseeds].p, p, len);
    ns[fuzz_nseeds].p[len] = '\0';
    ns[fuzz_nseeds++].len = len;
}

static int fuzz_cmp_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static void fuzz_read_dir(const char *prog, const char *dir, size_t max_len)
{
    DIR *d = opendir(dir);
    struct dirent *ent;
    char **names = NULL, path[4096], *buf = malloc(max_len);
    size_t n = 0, i;
    if (!d || !buf) {
        fprintf(stderr, "%s: cannot read %s\n", prog, dir);
        exit(2);
    }
    while ((ent = readdir(d)) != NULL) {
        char **nn;
        if (ent->d_name[0] == '.') continue;
        if (!(nn = realloc(names, (n + 1) * sizeof *nn))) exit(1);
        names = nn;
        if (!(names[n] = malloc(strlen(ent->d_name) + 1))) exit(1);
        strcpy(names[n++], ent->d_name);
    }
    closedir(d);
    if (n) qsort(names, n, sizeof *names, fuzz_cmp_name);
    for (i = 0; i < n; i++) {
        FILE *f;
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        if ((f = fopen(path, "rb"))) {
            size_t len = fread(buf, 1, max_len, f);
            fclose(f);
            fuzz_add_seed(buf, len);
        }
        free(names[i]);
    }
    free(names);
    free(buf);
}

/* A whole line of a seed (its text up to a newline or ';'), for splicing
 * statements: what keeps a mutant runnable while it combines two seeds. */
static const char *fuzz_line(size_t *len)
{
    const fuzz_seed *s = &fuzz_seeds[fuzz_next() % fuzz_nseeds];
    size_t from = s->len ? (size_t)(fuzz_next() % s->len) : 0, to;
    while (from > 0 && s->p[from - 1] != '\n' && s->p[from - 1] != ';') from--;
    for (to = from; to < s->len && s->p[to] != '\n' && s->p[to] != ';'; to++) continue;
    *len = to - from;
    return s->p + from;
}

/* One mutation, sometimes a few: bit flips, printable bytes, deletions,
 * tokens inserted, chunks of another seed or of the input itself, whole
 * statements spliced in at a statement boundary. */
static size_t fuzz_mutate(char *p, size_t len, size_t cap, const char *const *tokens,
                          size_t ntokens)
{
    int k, nm = fuzz_next() % 4 ? 1 : 2 + (int)(fuzz_next() % 3);
    for (k = 0; k < nm; k++) {
        size_t at = (size_t)(fuzz_next() % (len + 1)), n, inslen = 0;
        const char *ins = NULL, *sep = "";
        switch (fuzz_next() % 10) {
        case 0:
            if (at < len) p[at] ^= (char)(1u << (fuzz_next() % 8));
            break;
        case 1:
            if (at < len) p[at] = (char)(32 + fuzz_next() % 95);
            break;
        case 2:
            n = (size_t)(fuzz_next() % 8) + 1;
            if (at + n <= len) {
                memmove(p + at, p + at + n, len - at - n);
                len -= n;
            }
            break;
        case 3: {
            const fuzz_seed *s = &fuzz_seeds[fuzz_next() % fuzz_nseeds];
            size_t from = s->len ? (size_t)(fuzz_next() % s->len) : 0;
            inslen = (size_t)(fuzz_next() % 32);
            if (from + inslen > s->len) inslen = s->len - from;
            ins = s->p + from;
            break;
        }
        case 4:
            if (len) {
                size_t from = (size_t)(fuzz_next() % len);
                inslen = (size_t)(fuzz_next() % 16);
                if (from + inslen > len) inslen = len - from;
                ins = p + from;
            }
            break;
        case 5:
        case 6:
            while (at > 0 && p[at - 1] != '\n') at--;
            ins = fuzz_line(&inslen);
            sep = "\n";
            break;
        default:
            ins = tokens[fuzz_next() % ntokens];
            inslen = strlen(ins);
            break;
        }
        if (ins && inslen + 1 <= 256 && len + inslen + 1 <= cap) {
            char tmp[256];
            size_t seplen = strlen(sep);
            memcpy(tmp, ins, inslen); /* ins may point into p */
            memcpy(tmp + inslen, sep, seplen);
            inslen += seplen;
            memmove(p + at + inslen, p + at, len - at);
            memcpy(p + at, tmp, inslen);
            len += inslen;
        }
    }
    return len;
}

/* prog ITERATIONS CORPUS_DIR...: every seed, then ITERATIONS mutants;
 * report (may be NULL) prints the harness's own counts at the end. */
static int fuzz_main(int argc, char **argv, const char *prog, size_t max_len,
                     const char *const *tokens, size_t ntokens, const int *violations,
                     void (*report)(void))
{
    long iterations = argc > 1 ? atol(argv[1]) : 1000, i;
    char *work;
    int a;
    for (a = 2; a < argc; a++) fuzz_read_dir(prog, argv[a], max_len);
    if (!fuzz_nseeds) {
        fprintf(stderr, "usage: %s ITERATIONS CORPUS_DIR...  (no seeds found)\n", prog);
        return 2;
    }
    if (!(work = malloc(max_len + 1))) return 1;
    for (i = 0; i < (long)fuzz_nseeds; i++)
        LLVMFuzzerTestOneInput((const uint8_t *)fuzz_seeds[i].p, fuzz_seeds[i].len);
    for (i = 0; i < iterations; i++) {
        const fuzz_seed *s = &fuzz_seeds[fuzz_next() % fuzz_nseeds];
        size_t len;
        memcpy(work, s->p, s->len);
        len = fuzz_mutate(work, s->len, max_len, tokens, ntokens);
        LLVMFuzzerTestOneInput((const uint8_t *)work, len);
    }
    printf("%s: %zu seeds and %ld mutated inputs run\n", prog, fuzz_nseeds, iterations);
    if (report) report();
    printf("%d passed, %d failed\n", *violations ? 0 : 1, *violations ? 1 : 0);
    free(work);
    for (i = 0; i < (long)fuzz_nseeds; i++) free(fuzz_seeds[i].p);
    free(fuzz_seeds);
    return *violations != 0;
}

#endif
