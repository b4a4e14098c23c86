/*
 * fuzz_engine.h -- the engine the text fuzzers (fuzz_lang.c, fuzz_config.c)
 * run their inputs on: a real engine with the built-in reference plugin only,
 * its output discarded.
 *
 * eng_create always scans the build and install plugin directories
 * (engine.c), and in a build tree the first holds every plugin built: a
 * fuzzer must not depend on which those are, nor carry PETSc and MPI in its
 * address space, nor load anything from outside its own binary.  So this does
 * what eng_setup does without the directories and the config file (which
 * fuzz_config loads itself, with the same cfg_load_file).
 */
#ifndef SILC_FUZZ_ENGINE_H
#define SILC_FUZZ_ENGINE_H

#include <stdlib.h>

#include "dispatch.h"
#include "engine.h"

static void fuzz_discard(void *user, const char *text)
{
    (void)user;
    (void)text;
}

static silc_engine *fuzz_engine_new(void)
{
    silc_engine *E = calloc(1, sizeof *E);
    if (!E) return NULL;
    sb_init(&E->warnings);
    E->threads = 1;
    E->rand_state = 0x9E3779B97F4A7C15ull;
    if (store_init(&E->store) || cfg_create(E) || ld_create(E)) {
        eng_destroy(&E);
        return NULL;
    }
    ld_set_threads(E, 1);
    E->output = fuzz_discard;
    return E;
}

#endif
