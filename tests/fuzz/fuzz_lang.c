/*
 * fuzz_lang.c -- fuzz harness for the whole text path of silcd and the
 * embedded API: an input is statement text, lexed, parsed and run by
 * api_exec (what silc_exec and silcd's EXEC call) on an engine holding a
 * small fixed store.  Whatever the text, the run must end in success or a
 * failure with a non-empty message, never a crash, a leak or a sanitizer
 * report; no value may exceed the size cap the harness sets; and no input
 * may run for long (a loop budget ends `while (1) {}`).
 *
 * Built two ways from this one file, like fuzz_frame.c:
 *   - with clang -fsanitize=fuzzer: LLVMFuzzerTestOneInput for libFuzzer;
 *   - with SILC_FUZZ_DRIVER: a deterministic mutation fuzzer (xorshift
 *     mutations of the seed corpus: the statements of the language tests,
 *     tests/fuzz/corpus-lang, written by make_seeds.py) running a bounded
 *     number of inputs, for CI on any compiler:
 *         fuzz_lang ITERATIONS CORPUS_DIR...
 */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "client.h"
#include "engine.h"
#include "fuzz_engine.h"

/* The largest value an input may make.  Far below the machine's memory so
 * that sizes are refused by the cap, not by the allocator, and small enough
 * that the largest allowed operation (a dense product or solve of about
 * 180 x 180) takes milliseconds even under AddressSanitizer: a statement
 * that is merely big is not what this fuzzer looks for, and libFuzzer would
 * report it as a timeout.  (At 8 MiB a single 1000 x 1000 product took over
 * a second without sanitizers.) */
#ifndef FUZZ_CAP
#define FUZZ_CAP ((uint64_t)256 << 10)
#endif
/* `while` iterations per input (eval.c, E->loop_budget): enough for every
 * loop of the tests, and an end for `while (1) {}`.  The time of an input
 * is about this times the work of the loop's body, so it is kept low: 200
 * iterations of one 360 x 360 product took 7 s without sanitizers. */
#define FUZZ_LOOPS 100
/* Longest input run: the parser's limits are tested by test_lang; longer
 * texts only slow the fuzzer down. */
#define FUZZ_MAX_LEN 4096

/* The store every input starts from: the operands of test_lang.c and the
 * fixture of test_reliability.c (whose L and S are test_lang's here). */
static const char fixture_text[] =
    "v = [1; 2; 3]; w = [4; 5; 6]; r = [1, 2, 3]; idx = [1; 3]; s = 5; M = [1, 2; 3, 4]\n"
    "A = [1, 4, 7, 10; 2, 5, 8, 11; 3, 6, 9, 12]; D = diag([2; 4; 8])\n"
    "L = [2, 0, 0; 1, 1, 0; 0, 1, 4]; S = sparse([4, 1, 0; 1, 4, 1; 0, 1, 4])\n"
    "B = band([2, -1, 0; -1, 2, -1; 0, -1, 2], 1, 1)\n"
    "Z = [1, 2; 2, 4]; Zs = sparse(Z); b = [1; 1]; Ind = sparse([1, 2; 2, 1]); e1 = [1; 0; 0; 0]";

static int violations;
static long n_ok, n_failed, n_refused; /* for the driver's summary */
static int verbose;                    /* FUZZ_VERBOSE set: print every failure */

static void violation(const char *what, const char *text)
{
    violations++;
    fprintf(stderr, "fuzz_lang: invariant broken: %s\n  input: %.300s\n", what, text);
}

static char wisdom_dir[] = "/tmp/fuzz_lang_XXXXXX", wisdom_path[64];

static void remove_wisdom(void)
{
    remove(wisdom_path);
    rmdir(wisdom_dir);
}

/* The process-wide settings, once: the size cap, and a private wisdom file
 * (the tuner writes and `tune forget` removes the file SILC_WISDOM names
 * unless tune.wisdom is set, which refused() keeps inputs from doing). */
static void setup(void)
{
    static int done;
    if (done) return;
    done = 1;
    val_set_max_bytes(FUZZ_CAP, "fuzz cap");
    verbose = getenv("FUZZ_VERBOSE") != NULL;
    if (mkdtemp(wisdom_dir)) {
        snprintf(wisdom_path, sizeof wisdom_path, "%s/wisdom", wisdom_dir);
        setenv("SILC_WISDOM", wisdom_path, 1);
        atexit(remove_wisdom);
    } else {
        setenv("SILC_WISDOM", "/dev/null/fuzz-wisdom", 1); /* unwritable: nothing written */
    }
    unsetenv("SILC_VERBOSE");
}

/* Inputs the harness does not run, because the language lets them reach
 * outside the process, which no fuzzer may do: core.plugin_path dlopens
 * every plugin of a directory (any directory); tune.wisdom names the file
 * the tuner rewrites and `tune forget` removes; `tune report "file"` writes
 * an SVG wherever it is told, and `save "file"` an HDF5 file.  Keys, keywords and strings are taken
 * literally (no escapes, no case folding: lexer.c, config.c), so the
 * substrings find every spelling.  Everything else of `set` and `tune` runs,
 * the tuner writing only its private wisdom file (setup). */
static int refused(const char *text)
{
    return strstr(text, "plugin_path") || strstr(text, "wisdom") || strstr(text, "report") || strstr(text, "save");
}

static void check_store(silc_engine *E, const char *text)
{
    const char **names = NULL;
    size_t n = store_names(&E->store, &names), i;
    for (i = 0; i < n; i++) {
        const silc_value *v = store_get(&E->store, names[i]);
        if (!v) violation("store_names lists a name store_get does not find", text);
        else if (val_bytes(v) > FUZZ_CAP) violation("a value larger than the size cap", text);
    }
    free(names);
}

/* Each input on a fresh engine and fixture: that costs about 0.1 ms
 * (the 297 seeds run in 0.03 s), less than restoring a used engine's store,
 * options, tuner and records would take to get right. */
static void run(const char *text)
{
    silc_engine *E = fuzz_engine_new();
    char err[4096];
    if (!E || api_exec(E, fixture_text, err, sizeof err)) {
        violation(E ? err : "cannot create an engine", "(the fixture)");
        eng_destroy(&E);
        return;
    }
    E->loop_budget = FUZZ_LOOPS;
    err[0] = '\0';
    if (api_exec(E, text, err, sizeof err)) {
        n_failed++;
        if (verbose) fprintf(stderr, "---- %s\n  -> %s\n", text, err);
        if (!E->err[0]) violation("a failing exec without a message", text);
    } else {
        n_ok++;
    }
    check_store(E, text);
    if (ld_plugin_count(E) != 1) violation("a plugin was loaded", text);
    eng_destroy(&E);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text;
    setup();
    if (size > FUZZ_MAX_LEN || !(text = malloc(size + 1))) return 0;
    memcpy(text, data, size);
    text[size] = '\0';       /* the API takes C strings: text ends at a NUL */
    if (!refused(text)) run(text);
    else n_refused++;
    free(text);
    if (violations) abort();
    return 0;
}

#ifdef SILC_FUZZ_DRIVER
#include "fuzz_driver.h"

/* Pieces of the language the mutations insert. */
static const char *const fuzz_tokens[] = {
    "x", "v", "M", "S", "B", "A", "Zs", "end", " = ", " += ", "; ", "\n", "[", "]", "(", ")",
    "{", "}", ", ", ":", "'", " + ", " - ", " * ", " \\ ", " / ", " ^ ", " *@ ", " /@ ", " ^@ ",
    " == ", " < ", " && ", " || ", "!", "0", "1", "-1", "2", "0.5", "1e10", "1e300", "-1e300",
    "nan", "inf", "-inf", "4.9e-324", "9007199254740993", "1e-320", "\"fro\"", "\"x\"",
    "if (1) { ", "while (x < 3) { x += 1 ", "while (1) { ", "break", "continue", "explain ",
    "info x", "who", "clear x", "set ", "set dispatch.solve.dense = reference",
    "set solve.refine = 3", "set solve.backward_error = on_request", "set core.threads = 4096",
    "set tune.threads = auto", "tune on", "tune step", "tune off", "tune status", "tune forget",
    "tune fit 1:2 2:1 4:1.5", "\"backend = reference\"", "\"refine = 2\"",
    "zeros(", "ones(", "eye(", "rand(", "size(", "rows(", "cols(", "nnz(", "sparse(", "dense(",
    "band(", "diag(", "diagvec(", "sum(", "max(", "min(", "dot(", "norm(", "abs(", "sqrt(",
    "exp(", "log(", "sin(", "cos(", "trans(", "solve(", "sparse(1, 1, 1, 1e5, 1e5)",
    "eye(300)", "rand(300)", "x = ", "x[", "x[end + 1] = 1", "x[1:2, :] = ",
};

static void report(void)
{
    printf("fuzz_lang: %ld ran, %ld failed with a message, %ld refused by the harness\n", n_ok,
           n_failed, n_refused);
}

int main(int argc, char **argv)
{
    silc_engine *E;
    char err[4096];
    setup();
    /* The loop budget must end a loop that never would. */
    if (!(E = fuzz_engine_new())) return 1;
    E->loop_budget = FUZZ_LOOPS;
    if (api_exec(E, "x = 0; while (1) { x += 1 }", err, sizeof err) == 0 ||
        strcmp(err, "statement 2: loop stopped after 100 iterations (the engine's loop budget)"))
        violation("the loop budget does not end while (1)", err);
    eng_destroy(&E);
    return fuzz_main(argc, argv, "fuzz_lang", FUZZ_MAX_LEN, fuzz_tokens,
                     sizeof fuzz_tokens / sizeof *fuzz_tokens, &violations, report);
}
#endif
