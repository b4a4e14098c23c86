/*
 * fuzz_config.c -- fuzz harness for the config file reader (config.c over
 * inih): an input is the bytes of a config file, written to a temporary file
 * and read by cfg_load_file, the function silc_open and silcd use.  Whatever
 * the bytes, reading must end in success or in one message of the form
 * "<path>:<line>: ..." naming a line of the file, never a crash, a leak or a
 * sanitizer report.  A file that is accepted then governs a few statements
 * (dense, sparse and band solves, explain, set), which must run or fail with
 * a message: the dispatcher and the solve options see every accepted value.
 *
 * Built two ways from this one file, like fuzz_frame.c:
 *   - with clang -fsanitize=fuzzer: LLVMFuzzerTestOneInput for libFuzzer;
 *   - with SILC_FUZZ_DRIVER: a deterministic mutation fuzzer over the seed
 *     corpus (tests/fuzz/corpus-config, written by make_seeds.py from the
 *     config texts of the tests), for CI on any compiler:
 *         fuzz_config ITERATIONS CORPUS_DIR...
 */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "client.h"
#include "engine.h"
#include "fuzz_engine.h"

/* Longer files only repeat what shorter ones test (inih reads line by line). */
#define FUZZ_MAX_LEN 4096

static const char statements[] =
    "M = [4, 1; 1, 3]; b = [1; 2]; x = M \\ b; S = sparse(M); y = S \\ b\n"
    "B = band(M, 1, 1); z = B \\ b; u = solve(S, b, \"refine = 1\")\n"
    "explain w = S \\ b\nset";

static int violations;
static long n_ok, n_refused, n_skipped; /* for the driver's summary */
static char path[64];

static void violation(const char *what, const char *detail, const uint8_t *data, size_t size)
{
    violations++;
    fprintf(stderr, "fuzz_config: invariant broken: %s\n  %s\n  input (%zu bytes): %.*s\n", what,
            detail, size, (int)(size < 300 ? size : 300), (const char *)data);
}

static void remove_file(void)
{
    remove(path);
}

/* The file every input is written to, made once. */
static int setup(void)
{
    int fd;
    if (path[0]) return 0;
    snprintf(path, sizeof path, "/tmp/fuzz_config_XXXXXX");
    if ((fd = mkstemp(path)) < 0) return -1;
    close(fd);
    atexit(remove_file);
    unsetenv("SILC_VERBOSE");
    return 0;
}

/* Lines of the input as the reader counts them: a last line without a
 * newline counts too. */
static long count_lines(const uint8_t *data, size_t size)
{
    long n = 0;
    size_t i;
    for (i = 0; i < size; i++)
        if (data[i] == '\n') n++;
    return n + (size && data[size - 1] != '\n');
}

/* A refusal must be "<path>:<line>: <message>" with 1 <= line <= the file's
 * lines (+1: a NUL byte is reported on the line it starts). */
static void check_message(const char *err, const uint8_t *data, size_t size)
{
    size_t n = strlen(path);
    const char *p = err + n + 1;
    long line = 0;
    if (strncmp(err, path, n) || err[n] != ':') {
        violation("a refusal that does not start with the file's path", err, data, size);
        return;
    }
    if (!isdigit((unsigned char)*p)) {
        /* only running out of memory names no line */
        if (strcmp(p, " out of memory reading the config file"))
            violation("a refusal without a line number", err, data, size);
        return;
    }
    while (isdigit((unsigned char)*p)) line = line * 10 + (*p++ - '0');
    if (line < 1 || line > count_lines(data, size) + 1 || strncmp(p, ": ", 2) || !p[2])
        violation("a refusal whose line is not a line of the file, or without a message", err,
                  data, size);
}

static int contains(const uint8_t *data, size_t size, const char *word)
{
    size_t n = strlen(word), i;
    for (i = 0; i + n <= size; i++)
        if (memcmp(data + i, word, n) == 0) return 1;
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    silc_engine *E;
    FILE *f;
    char err[4096];
    if (size > FUZZ_MAX_LEN) return 0;
    /* core.plugin_path loads every plugin of a directory while the file is
     * read, and tune.wisdom names a file the tuner may rewrite: keys are
     * matched literally (config.c), so the substrings find every spelling.
     * The fuzzer stays inside its process. */
    if (contains(data, size, "plugin_path") || contains(data, size, "wisdom")) {
        n_skipped++;
        return 0;
    }
    if (setup() || !(f = fopen(path, "wb"))) {
        violation("cannot write the config file", path, data, 0);
        abort();
    }
    if (size) fwrite(data, 1, size, f);
    if (fclose(f)) abort();
    if (!(E = fuzz_engine_new())) abort();
    if (cfg_load_file(E, path)) {
        n_refused++;
        if (!E->err[0]) violation("a refusal without a message", "", data, size);
        else check_message(E->err, data, size);
    } else {
        n_ok++;
        if (api_exec(E, statements, err, sizeof err) && !E->err[0])
            violation("a failing exec without a message", err, data, size);
    }
    if (ld_plugin_count(E) != 1) violation("a plugin was loaded", "", data, size);
    eng_destroy(&E);
    if (violations) abort();
    return 0;
}

#ifdef SILC_FUZZ_DRIVER
#include "fuzz_driver.h"

static const char *const fuzz_tokens[] = {
    "[dispatch]\n", "[tune]\n", "[core]\n", "[solve]\n", "[reference]\n", "[lapack]\n",
    "[mumps]\n", "[petsc]\n", "[lis-style]\n", "[suitesparse]\n", "[", "]", " = ", "=", ":",
    "\n", "\r\n", ";", "#", " ", "\t", "threads", "auto", "4096", "0", "-1",
    "99999999999999999999", "accuracy", "budget", "1e-10", "1e400", "nan", "refine",
    "refine_residual", "extended", "backward_error", "on_request", "solve.dense",
    "solve.sparse", "solve.sparse.spd", "solve.band", "reference", "lapack",
    "suitesparse.umfpack", ", ", ",,", "tune.threads = 2\n", "solve.refine = 100\n",
    "dispatch.solve.dense = reference, reference\n", "options = -i cg\n", "verbose = true\n",
};

static void report(void)
{
    printf("fuzz_config: %ld accepted, %ld refused with file:line, %ld skipped by the harness\n",
           n_ok, n_refused, n_skipped);
}

int main(int argc, char **argv)
{
    return fuzz_main(argc, argv, "fuzz_config", FUZZ_MAX_LEN, fuzz_tokens,
                     sizeof fuzz_tokens / sizeof *fuzz_tokens, &violations, report);
}
#endif
