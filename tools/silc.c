/*
 * silc.c -- the `silc` command: run a script, run statements given on the
 * command line, or talk to SILC interactively.
 *
 *     silc [options] run FILE        the whole file is one silc_exec, so control
 *                                    flow (if/while/break/continue) spans lines
 *     silc [options] -e STATEMENTS
 *     silc [options]                 REPL (readline line editing and history in
 *                                    ~/.silc_history when stdin is a terminal;
 *                                    Ctrl-C interrupts a statement or clears the line)
 *     silc [options] tune fit P:T...  fit the tuner's model to timings
 *     silc [options] tune report [F]  the tuner's last result from the wisdom file
 *                                    (the `tune` statement, so the same code answers)
 *
 * --put NAME=FILE.mtx loads Matrix Market files before running, --get NAME
 * prints values in Matrix Market format afterwards, so the command composes with
 * other tools through files and pipes.  Uses only the public API (silc.h), as
 * any other client would.  Exit status: 0 success, 1 failure (message on stderr
 * as "silc: ..."), 2 usage error.
 *
 * Values show as Octave shows them: the command turns core.display on, so a
 * statement without ';' prints its value (run, -e and the REPL alike).
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifdef SILC_HAVE_READLINE
#include <dlfcn.h>
#include <stddef.h>
/* for the types of what line_editor_open looks up: libreadline itself is
 * opened at run time */
#include <readline/history.h>
#include <readline/readline.h>
#endif

#include "silc.h"
#include "util.h" /* util_open_input: files.c is compiled in (tools/CMakeLists.txt) */

static const char usage_text[] =
    "usage: silc [options] run FILE      run a script (\"-\" reads standard input)\n"
    "       silc [options] -e STATEMENTS run statements given as text\n"
    "       silc [options]               interactive session\n"
    "       silc [options] tune fit P:T ...   fit f(p) = a/p + b*p + c to step times T\n"
    "                                    at thread counts P; prints a, b, c, q, p_opt\n"
    "       silc [options] tune report [FILE.svg]  samples, fit, p_opt and backends of\n"
    "                                    the last tuning on this machine (wisdom file),\n"
    "                                    plot to FILE.svg (default silc-tune.svg)\n"
    "options:\n"
    "  --put NAME=FILE.mtx  load a Matrix Market file as NAME before running (repeatable)\n"
    "  --put-allow-nonfinite\n"
    "                       let --put read inf, nan and values that overflow to inf\n"
    "                       (refused by default, naming line and column; the same as\n"
    "                       SILC_MM_ALLOW_NONFINITE=1)\n"
    "  --get NAME           after running, print NAME to standard output in Matrix\n"
    "                       Market format (repeatable, in the order given)\n"
    "  --config FILE        configuration file (default: $SILC_CONFIG, else ./silc.conf)\n"
    "  -h, --help           show this text\n"
    "  --version            show the version\n"
    "  --profile            time every statement and plugin call (bytes in and out,\n"
    "                       reused factorizations) and print the tables to standard\n"
    "                       error at the end, as PETSc's -log_view (core.profile)\n"
    "  --complete WORD      after running, print the names, statements, built-ins,\n"
    "                       plugins and settings (plugin options too) that start with\n"
    "                       WORD, one a line (what Tab completes)\n"
    "In the interactive session a line that ends inside an unclosed ( [ or {, or an\n"
    "if, while or for without its end, continues on the next line; 'quit', 'exit' or\n"
    "end of input (Ctrl-D) leaves.  Ctrl-C stops the running statement\n"
    "(\"interrupted\", the store as before it) or clears the line being typed.\n"
    "Warnings go to standard error as \"warning: ...\"; who, info and explain print\n"
    "to standard output.\n";

typedef struct {
    const char *config;
    const char *script;     /* run FILE */
    const char *statements; /* -e */
    const char **put_args;  /* NAME=FILE, as given */
    int nput;
    const char **get_names;
    int nget;
    char *tune_text;        /* statement built from `tune ...` arguments */
    const char *complete;   /* --complete WORD */
    int profile;            /* --profile */
    int allow_nonfinite;    /* --put-allow-nonfinite */
} cli_options;

static void fail(const char *fmt, ...)
{
    va_list ap;
    fflush(stdout); /* keep the order of output and messages on a terminal */
    fputs("silc: ", stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

/* Matches "--opt VALUE" and "--opt=VALUE"; advances *i past what it used.
 * Returns 1 on a match with *value set (NULL if the value is missing). */
static int take_option(int argc, char **argv, int *i, const char *opt, const char **value)
{
    size_t len = strlen(opt);
    if (strncmp(argv[*i], opt, len)) return 0;
    if (argv[*i][len] == '=') {
        *value = argv[*i] + len + 1;
        return 1;
    }
    if (argv[*i][len]) return 0;
    *value = *i + 1 < argc ? argv[++*i] : NULL;
    return 1;
}

/* `silc tune WORD ARGS...` becomes the statement `tune WORD ARGS...`, a file
 * name quoted.  Returns 0, or 2 on a usage error. */
static int tune_args(int argc, char **argv, int i, cli_options *o)
{
    size_t len = 16;
    int k;
    if (i >= argc || (strcmp(argv[i], "fit") && strcmp(argv[i], "report")))
        return fail("tune needs 'fit P:T ...' or 'report [FILE.svg]'"), 2;
    for (k = i; k < argc; k++) {
        if (strchr(argv[k], '"') || strchr(argv[k], '\n'))
            return fail("tune: argument '%s' may not contain quotes or newlines", argv[k]), 2;
        len += strlen(argv[k]) + 3;
    }
    if (!(o->tune_text = malloc(len))) return fail("out of memory"), 2;
    strcpy(o->tune_text, "tune");
    for (k = i; k < argc; k++) {
        int quote = !strcmp(argv[i], "report") && k > i;
        strcat(o->tune_text, quote ? " \"" : " ");
        strcat(o->tune_text, argv[k]);
        if (quote) strcat(o->tune_text, "\"");
    }
    o->statements = o->tune_text;
    return 0;
}

/* Returns 0 to go on, 1 after printing --help/--version, 2 on a usage error. */
static int parse_args(int argc, char **argv, cli_options *o)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = NULL;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage_text, stdout);
            return 1;
        } else if (!strcmp(a, "--version")) {
            printf("silc %s\n", SILC_VERSION);
            return 1;
        } else if (take_option(argc, argv, &i, "--config", &v)) {
            if (!v || !*v) return fail("--config needs a file name"), 2;
            o->config = v;
        } else if (take_option(argc, argv, &i, "--put", &v)) {
            const char *eq = v ? strchr(v, '=') : NULL;
            if (!eq || eq == v || !eq[1])
                return fail("--put needs NAME=FILE.mtx, got '%s'", v ? v : ""), 2;
            o->put_args[o->nput++] = v;
        } else if (take_option(argc, argv, &i, "--get", &v)) {
            if (!v || !*v) return fail("--get needs a name"), 2;
            o->get_names[o->nget++] = v;
        } else if (!strcmp(a, "--profile")) {
            o->profile = 1;
        } else if (!strcmp(a, "--put-allow-nonfinite")) {
            o->allow_nonfinite = 1;
        } else if (take_option(argc, argv, &i, "--complete", &v)) {
            if (!v) return fail("--complete needs a word (it may be empty)"), 2;
            o->complete = v;
        } else if (take_option(argc, argv, &i, "-e", &v)) {
            if (!v) return fail("-e needs statements"), 2;
            if (o->statements || o->script) return fail("give only one of 'run FILE' and -e"), 2;
            o->statements = v;
        } else if (!strcmp(a, "tune")) {
            if (o->statements || o->script) return fail("give only one of 'run FILE', -e and tune"), 2;
            return tune_args(argc, argv, i + 1, o);
        } else if (!strcmp(a, "run")) {
            if (i + 1 >= argc) return fail("run needs a file name"), 2;
            if (o->statements || o->script) return fail("give only one of 'run FILE' and -e"), 2;
            o->script = argv[++i];
        } else {
            fail("%s '%s' (see silc --help)", a[0] == '-' ? "unknown option" : "unknown command", a);
            return 2;
        }
    }
    return 0;
}

/* The longest script `silc run` reads: a bound on what a file (or a device
 * such as /dev/zero) can make the CLI allocate before a statement runs. */
#define SILC_MAX_SCRIPT_BYTES ((size_t)64 << 20)

/* Reads a whole file ("-" = standard input) into a NUL-terminated buffer:
 * at most SILC_MAX_SCRIPT_BYTES, text only (a NUL byte stops the read at
 * once), and a FIFO with no writer reads as empty instead of hanging. */
static char *read_file(const char *path)
{
    int fd = strcmp(path, "-") ? util_open_input(path) : 0;
    size_t len = 0, cap = 4096;
    char *buf;
    ssize_t got = 0;
    if (fd < 0) {
        fail("cannot open '%s': %s", path, strerror(errno));
        return NULL;
    }
    buf = malloc(cap);
    while (buf) {
        got = read(fd, buf + len, cap - 1 - len);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) break;
        if (memchr(buf + len, '\0', (size_t)got)) {
            fail("'%s' is not a text file (it contains NUL bytes)", path);
            break;
        }
        len += (size_t)got;
        if (len == cap - 1) {
            char *grown;
            if (cap >= SILC_MAX_SCRIPT_BYTES) {
                fail("'%s' is over %zu MiB: not a script silc runs", path, SILC_MAX_SCRIPT_BYTES >> 20);
                break;
            }
            if (!(grown = realloc(buf, cap * 2))) {
                fail("out of memory reading '%s'", path);
                break;
            }
            buf = grown;
            cap *= 2;
        }
    }
    if (fd > 0) close(fd);
    if (!buf) {
        fail("out of memory reading '%s'", path);
        return NULL;
    }
    if (got != 0) { /* a read error, NUL bytes or the cap (said above) */
        if (got < 0) fail("cannot read '%s': %s", path, strerror(errno));
        free(buf);
        return NULL;
    }
    buf[len] = '\0';
    return buf;
}

static void print_warnings(const silc_context *ctx)
{
    const char *w = silc_context_warnings(ctx);
    fflush(stdout);
    while (w && *w) {
        size_t len = strcspn(w, "\n");
        if (len) fprintf(stderr, "warning: %.*s\n", (int)len, w);
        w += len + (w[len] == '\n');
    }
}

/* ---- Ctrl-C in the interactive session ------------------------------------ */

/* SIGINT interrupts the running statement (silc_cancel, which is
 * async-signal-safe and, on a remote context, sends CANCEL to silcd); at
 * the prompt it drops the line being typed.  The handler only sets flags
 * and calls silc_cancel; the REPL acts on them outside the handler. */
static silc_context *interrupt_ctx;
static volatile sig_atomic_t exec_running;      /* a statement runs */
static volatile sig_atomic_t exec_interrupts;   /* Ctrl-C presses during it */
static volatile sig_atomic_t line_interrupted;  /* Ctrl-C at the prompt */
/* Written by the handler at the prompt, so the prompt's wait wakes up
 * whichever thread the signal landed on and however it raced the wait. */
static int wake_pipe[2] = {-1, -1};

static void on_sigint(int sig)
{
    static const char again[] = "\nsilc: still running (inside a library call that does not "
                                "stop); Ctrl-C once more quits\n";
    ssize_t ignored;
    (void)sig;
    if (!exec_running) {
        int saved_errno = errno;
        line_interrupted = 1;
        if (wake_pipe[1] >= 0) {
            ignored = write(wake_pipe[1], "", 1);
            (void)ignored;
        }
        errno = saved_errno;
        return;
    }
    silc_cancel(interrupt_ctx);
    if (++exec_interrupts == 2) {
        ignored = write(STDERR_FILENO, again, sizeof again - 1);
        (void)ignored;
    } else if (exec_interrupts >= 3) {
        /* A call that never returns: the third press quits, as the
         * terminal's default would have (history is saved line by line). */
        signal(SIGINT, SIG_DFL);
        raise(SIGINT);
    }
}

/* Without SA_RESTART, so that a read at the prompt returns EINTR. */
static void catch_sigint(silc_context *ctx)
{
    struct sigaction sa;
    interrupt_ctx = ctx;
    if (pipe(wake_pipe) == 0) {
        for (int k = 0; k < 2; k++) {
            fcntl(wake_pipe[k], F_SETFL, O_NONBLOCK);
            fcntl(wake_pipe[k], F_SETFD, FD_CLOEXEC);
        }
    } else {
        wake_pipe[0] = wake_pipe[1] = -1; /* Ctrl-C at the prompt then waits for a key */
    }
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
}

#ifdef SILC_HAVE_READLINE
/* ---- line editing: GNU readline, opened when a terminal session starts ----- */

/* The command does not link readline (nor libtinfo behind it): `-e`, `run`,
 * `--complete` and a piped session never call it, and loading two more
 * libraries is a measurable part of starting the command (issue 30,
 * start-up: docs/overhead.md has the table).  An interactive session
 * opens it by its soname, which the dynamic loader looks for where it
 * looks for a linked library: silc's RUNPATH (no relative entry) and the
 * system's directories.  The soname's number is the major version of the
 * headers compiled against (readline's own rule for naming its library), so
 * the library opened has the interface used.  What it needs of it, by name: */
#define SILC_STRINGIFY(x) #x
#define SILC_STRING_OF(x) SILC_STRINGIFY(x)
#define SILC_READLINE_SONAME "libreadline.so." SILC_STRING_OF(RL_VERSION_MAJOR)
typedef struct {
    char *(*readline)(const char *);
    void (*add_history)(const char *);
    void (*using_history)(void);
    void (*stifle_history)(int);
    int (*read_history)(const char *);
    int (*write_history)(const char *);
    int (*append_history)(int, const char *);
    int (*history_truncate_file)(const char *, int);
    void (*replace_line)(const char *, int);
    char **(*completion_matches)(const char *, rl_compentry_func_t *);
    rl_completion_func_t **attempted_completion_function; /* variables: their addresses */
    int *attempted_completion_over;
    int *catch_signals;
    rl_getc_func_t **getc_function;
} line_editor;

static line_editor rl; /* all NULL until line_editor_open succeeds */

/* One entry of line_editor: the symbol and where its address goes (a
 * function's, or a variable's: the field is then a pointer to it).  The
 * unevaluated assignment in sizeof makes the compiler check the field's
 * type against readline's own declaration, without referring to it. */
#define LINE_EDITOR_SYMBOL(field, symbol) \
    {#symbol, offsetof(line_editor, field), sizeof(((line_editor *)0)->field = symbol)}
#define LINE_EDITOR_VARIABLE(field, symbol) \
    {#symbol, offsetof(line_editor, field), sizeof(((line_editor *)0)->field = &symbol)}
static const struct {
    const char *name;
    size_t offset, size;
} line_editor_symbols[] = {
    LINE_EDITOR_SYMBOL(readline, readline),
    LINE_EDITOR_SYMBOL(add_history, add_history),
    LINE_EDITOR_SYMBOL(using_history, using_history),
    LINE_EDITOR_SYMBOL(stifle_history, stifle_history),
    LINE_EDITOR_SYMBOL(read_history, read_history),
    LINE_EDITOR_SYMBOL(write_history, write_history),
    LINE_EDITOR_SYMBOL(append_history, append_history),
    LINE_EDITOR_SYMBOL(history_truncate_file, history_truncate_file),
    LINE_EDITOR_SYMBOL(replace_line, rl_replace_line),
    LINE_EDITOR_SYMBOL(completion_matches, rl_completion_matches),
    LINE_EDITOR_VARIABLE(attempted_completion_function, rl_attempted_completion_function),
    LINE_EDITOR_VARIABLE(attempted_completion_over, rl_attempted_completion_over),
    LINE_EDITOR_VARIABLE(catch_signals, rl_catch_signals),
    LINE_EDITOR_VARIABLE(getc_function, rl_getc_function),
};

/* Opens readline and fills rl; 0 on success.  On failure rl stays all NULL
 * and the session reads plain lines, saying once why there is no line
 * editing or history. */
static int line_editor_open(void)
{
    line_editor found;
    size_t k;
    void *lib = dlopen(SILC_READLINE_SONAME, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fail("no line editing or history: %s", dlerror());
        return -1;
    }
    for (k = 0; k < sizeof line_editor_symbols / sizeof line_editor_symbols[0]; k++) {
        void *sym = dlsym(lib, line_editor_symbols[k].name);
        if (!sym || line_editor_symbols[k].size != sizeof sym) {
            fail("no line editing or history: %s has no '%s'", SILC_READLINE_SONAME, line_editor_symbols[k].name);
            dlclose(lib);
            return -1;
        }
        /* POSIX's round trip of a function's address through void * */
        memcpy((char *)&found + line_editor_symbols[k].offset, &sym, sizeof sym);
    }
    rl = found;
    return 0;
}

/* readline's reader (rl_getc_function): on Ctrl-C the line typed so far is
 * dropped and readline returns at once, so the REPL can also drop the lines
 * of an unfinished statement and show a fresh prompt.  readline's own
 * SIGINT handling is off (rl_catch_signals = 0): it would end the process. */
static int read_key(FILE *in)
{
    for (;;) {
        struct pollfd p[2];
        unsigned char c;
        char drain[64];
        ssize_t n;
        if (line_interrupted) {
            rl.replace_line("", 0);
            return '\n';
        }
        p[0].fd = fileno(in);
        p[1].fd = wake_pipe[0];
        p[0].events = p[1].events = POLLIN;
        p[0].revents = p[1].revents = 0;
        if (poll(p, wake_pipe[0] >= 0 ? 2 : 1, -1) < 0) {
            if (errno == EINTR) continue;
            return EOF;
        }
        if (p[1].revents) { /* the flag is looked at above */
            while (read(wake_pipe[0], drain, sizeof drain) > 0) {}
            continue;
        }
        n = read(p[0].fd, &c, 1);
        if (n == 1) return c;
        if (n == 0 || errno != EINTR) return EOF;
    }
}
#endif

/* Runs statements and reports warnings and any error; returns 0 on success. */
static int run_text(silc_context *ctx, const char *text)
{
    int rc;
    exec_interrupts = 0;
    exec_running = 1;
    rc = silc_exec(ctx, text);
    exec_running = 0;
    print_warnings(ctx);
    if (rc) fail("%s", silc_context_errmsg(ctx));
    return rc;
}

static int load_puts(silc_context *ctx, const cli_options *o)
{
    /* silc_mm_read takes the user's leave from the environment (silc.h), so
     * the option sets the variable rather than carry a second switch */
    if (o->allow_nonfinite && setenv("SILC_MM_ALLOW_NONFINITE", "1", 1))
        return fail("--put-allow-nonfinite: %s", strerror(errno)), 1;
    for (int k = 0; k < o->nput; k++) {
        const char *eq = strchr(o->put_args[k], '=');
        int namelen = (int)(eq - o->put_args[k]);
        char *name = malloc((size_t)namelen + 1);
        if (!name) return fail("out of memory"), 1;
        memcpy(name, o->put_args[k], (size_t)namelen);
        name[namelen] = '\0';
        char err[512] = "";
        silc_envelope_t e = {0};
        int rc = silc_mm_read(&e, eq + 1, err, sizeof err);
        if (rc)
            fail("--put %s: %s", o->put_args[k], *err ? err : "cannot read the file");
        else if ((rc = silc_put(ctx, name, &e)))
            fail("--put %s: %s", o->put_args[k], silc_context_errmsg(ctx));
        silc_envelope_free(&e);
        free(name);
        if (rc) return 1;
    }
    return 0;
}

static int print_gets(silc_context *ctx, const cli_options *o)
{
    for (int k = 0; k < o->nget; k++) {
        silc_envelope_t e = {0};
        if (silc_get_complex(ctx, &e, o->get_names[k])) { /* the CLI prints either field */
            fail("--get %s: %s", o->get_names[k], silc_context_errmsg(ctx));
            return 1;
        }
        int rc = silc_mm_write(&e, stdout);
        silc_envelope_free(&e);
        if (rc) return fail("--get %s: error writing standard output", o->get_names[k]), 1;
    }
    return 0;
}

/* ---- completion ----------------------------------------------------------- */

/* Output of one statement, collected (for completion's `help` and `who`). */
typedef struct {
    char *s;
    size_t len;
} collected;

static void collect(void *user, const char *text)
{
    collected *c = user;
    size_t add = strlen(text);
    char *grown = realloc(c->s, c->len + add + 1);
    if (!grown) return;
    memcpy(grown + c->len, text, add + 1);
    c->s = grown;
    c->len += add;
}

static char *output_of(silc_context *ctx, const char *stmt)
{
    collected c = {NULL, 0};
    int rc;
    silc_set_output(ctx, collect, &c);
    rc = silc_exec(ctx, stmt);
    silc_set_output(ctx, NULL, NULL);
    if (rc) {
        free(c.s);
        return NULL;
    }
    return c.s;
}

/* Every completion of prefix: the session's names (from `who`), the
 * statements and built-ins (from `help`), the settings' keys with every
 * loaded plugin's options (from `set`), quit and exit; a malloc'd array of
 * malloc'd strings ending in NULL, in that order, without repeats. */
/* Drops the lines of text that do not start with a blank: `help`'s
 * headings, leaving its lists (statements and built-ins, plugins). */
static void keep_indented_lines(char *text)
{
    char *to = text, *line = text;
    while (text && *line) {
        size_t len = strcspn(line, "\n");
        len += line[len] == '\n';
        if (*line == ' ') {
            memmove(to, line, len);
            to += len;
        }
        line += len;
    }
    if (text) *to = '\0';
}

static char **completions(silc_context *ctx, const char *prefix)
{
    char *who = output_of(ctx, "who"), *help = output_of(ctx, "help"), *p;
    char *keys = output_of(ctx, "set");
    size_t n = 0, cap = 16, plen = strlen(prefix), k;
    char **out = malloc(cap * sizeof *out);
    const char *fixed = "quit exit";
    keep_indented_lines(help);
    for (int src = 0; src < 4 && out; src++) {
        /* who: the first word of each line after the header; help: every
         * word of its lists; set: the first word of every line; then the
         * REPL's own commands */
        p = src == 0 ? who : src == 1 ? help : src == 2 ? keys : (char *)fixed;
        if (!p) continue;
        if (src == 0) p = strchr(p, '\n');
        while (p && *p && out) {
            size_t wl;
            p += strspn(p, " \t\n");
            wl = strcspn(p, " \t\n");
            if (wl && !strncmp(p, prefix, plen)) {
                for (k = 0; k < n && (strlen(out[k]) != wl || strncmp(out[k], p, wl)); k++) continue;
                if (k == n) {
                    if (n + 2 > cap) {
                        char **grown = realloc(out, (cap *= 2) * sizeof *out);
                        if (!grown) break;
                        out = grown;
                    }
                    if ((out[n] = malloc(wl + 1))) memcpy(out[n], p, wl), out[n++][wl] = 0;
                }
            }
            p += wl;
            if (src == 0 || src == 2) p = strchr(p, '\n'); /* the rest of the line: shape, value */
        }
    }
    if (out) out[n] = NULL;
    free(who);
    free(help);
    free(keys);
    return out;
}

static void free_completions(char **c)
{
    for (size_t k = 0; c && c[k]; k++) free(c[k]);
    free(c);
}

#ifdef SILC_HAVE_READLINE
static silc_context *completion_ctx;

static char *completion_next(const char *text, int state)
{
    static char **list;
    static size_t at;
    if (state == 0) {
        free_completions(list);
        list = completions(completion_ctx, text);
        at = 0;
    }
    return list && list[at] ? strdup(list[at++]) : NULL;
}

static char **complete(const char *text, int start, int end)
{
    (void)start, (void)end;
    *rl.attempted_completion_over = 1; /* no file names */
    return rl.completion_matches(text, completion_next);
}
#endif

/* ---- the interactive session ------------------------------------------------ */

/* Net number of ( [ { left open in text, ignoring strings and comments: a line
 * that ends with brackets open continues on the next.  Strings and comments
 * end at a newline, so the count of a buffer is the sum of its lines'. */
static long open_brackets(const char *s)
{
    long depth = 0;
    int in_string = 0;
    for (; *s; s++) {
        if (in_string) {
            if (*s == '\\' && s[1] && s[1] != '\n') s++;
            else if (*s == '"' || *s == '\n') in_string = 0;
        } else if (*s == '"') {
            in_string = 1;
        } else if (*s == '#') {
            s += strcspn(s, "\n");
            if (!*s) break;
        } else if (*s == '(' || *s == '[' || *s == '{') {
            depth++;
        } else if (*s == ')' || *s == ']' || *s == '}') {
            depth--;
        }
    }
    return depth;
}

/* Net number of Octave-style blocks a line opens: `if`, `while` or `for`
 * first in a statement, without a `{` later on the line (the brace form,
 * counted by open_brackets), opens one; `end` (endif, endwhile, endfor)
 * first in a statement closes one; a line starting with `{` is the brace
 * of the block the line before opened.  A heuristic for when to run what
 * was typed: the parser says what is wrong with the text. */
static long open_blocks(const char *s)
{
    long n = 0;
    int at_start = 1, opened = 0;
    s += strspn(s, " \t");
    if (*s == '{') n--;
    for (; *s; s++) {
        if (*s == '"') {
            s++;
            while (*s && *s != '"' && *s != '\n') s++;
            if (!*s) break;
            at_start = 0;
        } else if (*s == '#') {
            break;
        } else if (*s == ';' || *s == ',') {
            at_start = 1;
        } else if (*s == '{') {
            if (opened) n--, opened--;
            at_start = 1;
        } else if (isalpha((unsigned char)*s) || *s == '_') {
            size_t len = 1;
            while (isalnum((unsigned char)s[len]) || s[len] == '_') len++;
            if (at_start) {
                const char *after = s + len + strspn(s + len, " \t");
                int assigned = after[0] == '=' && after[1] != '=';
                if (!assigned && ((len == 2 && !strncmp(s, "if", 2)) || (len == 5 && !strncmp(s, "while", 5)) ||
                                  (len == 3 && !strncmp(s, "for", 3))))
                    n++, opened++;
                else if (!assigned && ((len == 3 && !strncmp(s, "end", 3)) || (len == 5 && !strncmp(s, "endif", 5)) ||
                                       (len == 8 && !strncmp(s, "endwhile", 8)) ||
                                       (len == 6 && !strncmp(s, "endfor", 6))))
                    n--;
            }
            at_start = (len == 4 && !strncmp(s, "else", 4));
            s += len - 1;
        } else if (*s != ' ' && *s != '\t') {
            at_start = 0;
        }
    }
    return n;
}

static int is_command(const char *line, const char *word)
{
    line += strspn(line, " \t");
    size_t len = strlen(word);
    return !strncmp(line, word, len) && line[len + strspn(line + len, " \t;")] == '\0';
}

/* One line without its newline, malloc'd; NULL at end of input.  After
 * Ctrl-C at the prompt line_interrupted is set (the line is then "", or
 * NULL from getline, and means nothing). */
static char *read_line(int interactive, const char *prompt)
{
    line_interrupted = 0;
#ifdef SILC_HAVE_READLINE
    if (interactive && rl.readline) return rl.readline(prompt);
#endif
    if (interactive) {
        fputs(prompt, stdout);
        fflush(stdout);
    }
    char *line = NULL;
    size_t cap = 0;
    ssize_t len = getline(&line, &cap, stdin);
    if (len < 0) {
        free(line);
        if (line_interrupted) {
            clearerr(stdin); /* EINTR is not the end of input */
            putchar('\n');
        }
        return NULL;
    }
    if (len > 0 && line[len - 1] == '\n') line[len - 1] = '\0';
    return line;
}

#ifdef SILC_HAVE_READLINE
static char *history_path(void)
{
    const char *home = getenv("HOME");
    if (!home || !*home) return NULL;
    size_t len = strlen(home) + sizeof "/.silc_history";
    char *path = malloc(len);
    if (path) snprintf(path, len, "%s/.silc_history", home);
    return path;
}
#endif

/* Statements are run as soon as their brackets close; a failing one is reported
 * and the session goes on.  Returns 1 if input was not a terminal and some
 * statement failed, so scripted sessions can be checked. */
static int repl(silc_context *ctx)
{
    int interactive = isatty(STDIN_FILENO), failed = 0;
    size_t len = 0, cap = 0;
    long open = 0;     /* brackets the buffered lines leave open */
    long blocks = 0;   /* Octave-style blocks they leave open (open_blocks) */
    char *buf = NULL;
#ifdef SILC_HAVE_READLINE
    char *hist = NULL;
    if (interactive && line_editor_open() == 0) {
        hist = history_path();
        completion_ctx = ctx;
        *rl.attempted_completion_function = complete;
        rl.using_history();
        rl.stifle_history(1000);
        /* Each line is appended to the file as it is entered, so a session
         * that ends any way at all keeps its lines; a first session makes
         * the file (append_history does not). */
        if (hist && rl.read_history(hist) == ENOENT) rl.write_history(hist);
        *rl.catch_signals = 0;
        *rl.getc_function = read_key;
    }
#endif
    if (interactive) catch_sigint(ctx);
    if (interactive) printf("silc %s -- 'quit' or Ctrl-D to leave, silc --help for usage\n", SILC_VERSION);
    for (;;) {
        char *line = read_line(interactive, len ? "...> " : "silc> ");
        if (line_interrupted) {
            /* Ctrl-C at the prompt: the statement being typed, all its
             * lines, is dropped; only Ctrl-D or quit/exit leave. */
            free(line);
            len = 0;
            open = 0;
            continue;
        }
        if (!line) {
            if (interactive) putchar('\n');
            break;
        }
        if (!len && (is_command(line, "quit") || is_command(line, "exit"))) {
            free(line);
            break;
        }
#ifdef SILC_HAVE_READLINE
        if (rl.add_history && line[strspn(line, " \t")]) {
            rl.add_history(line);
            if (hist) rl.append_history(1, hist);
        }
#endif
        size_t add = strlen(line);
        if (len + add + 2 > cap) {
            size_t ncap = (len + add + 2) * 2;
            char *grown = realloc(buf, ncap);
            if (!grown) {
                free(line);
                fail("out of memory");
                failed = 1;
                break;
            }
            buf = grown, cap = ncap;
        }
        memcpy(buf + len, line, add);
        len += add;
        buf[len++] = '\n';
        buf[len] = '\0';
        open += open_brackets(line);
        blocks += open_blocks(line);
        free(line);
        /* Past the language's nesting limit no closing line can make the text
         * valid: run it now, so the parser names the limit, rather than
         * buffering forever. */
        if ((open > 0 || blocks > 0) && open <= SILC_MAX_NESTING && blocks <= SILC_MAX_NESTING) continue;
        if (buf[strspn(buf, " \t\r\n")] && run_text(ctx, buf)) failed = 1;
        len = 0;
        open = 0;
        blocks = 0;
    }
    /* Input ended inside open brackets: run it anyway so the parser says what
     * is unclosed. */
    if (len && buf[strspn(buf, " \t\r\n")] && run_text(ctx, buf)) failed = 1;
    free(buf);
#ifdef SILC_HAVE_READLINE
    if (hist) rl.history_truncate_file(hist, 1000);
    free(hist);
#endif
    return interactive ? 0 : failed;
}

int main(int argc, char **argv)
{
    cli_options o = {0};
    o.put_args = calloc((size_t)argc, sizeof *o.put_args);
    o.get_names = calloc((size_t)argc, sizeof *o.get_names);
    if (!o.put_args || !o.get_names) {
        fail("out of memory");
        return 1;
    }
    int status = parse_args(argc, argv, &o);
    if (status) {
        free(o.put_args), free(o.get_names), free(o.tune_text);
        return status == 1 ? 0 : 2;
    }

    silc_context *ctx = NULL;
    if (silc_open(&ctx, o.config)) {
        fail("%s", ctx ? silc_context_errmsg(ctx) : silc_errmsg());
        status = 1;
    } else {
        /* Values show as in Octave: a statement without ';' prints its value
         * (core.display; an embedded SILC_EXEC never prints). */
        status = load_puts(ctx, &o) || run_text(ctx, "set core.display = on") ||
                 (o.profile && run_text(ctx, "set core.profile = on"));
        if (!status && o.script) {
            char *text = read_file(o.script);
            status = !text || run_text(ctx, text);
            free(text);
        } else if (!status && o.statements) {
            status = run_text(ctx, o.statements);
        } else if (!status && !o.complete) {
            status = repl(ctx);
        }
        if (!status) status = print_gets(ctx, &o);
        if (o.profile) {   /* after a failure too: where the time went is still worth seeing */
            char *table = output_of(ctx, "profile");
            fflush(stdout);
            if (table) fputs(table, stderr);
            free(table);
        }
        if (!status && o.complete) {
            char **c = completions(ctx, o.complete);
            for (size_t k = 0; c && c[k]; k++) puts(c[k]);
            free_completions(c);
        }
    }
    silc_close(&ctx);
    free(o.put_args), free(o.get_names), free(o.tune_text);
    if (fflush(stdout) || ferror(stdout)) {
        fail("error writing standard output");
        status = 1;
    }
    return status ? 1 : 0;
}
