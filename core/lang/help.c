/*
 * help.c -- one table of the language's statements and built-ins, with a
 * line of usage and a sentence each: what `help` and `help NAME` print, what
 * the REPL completes, and the two tables of the README (test_help checks
 * that the README holds exactly lang_help_markdown's text).  A statement
 * or built-in added to the language gets its row here.  `help set` adds the
 * options database's table of server and session settings (config.c).
 */
#include "lang.h"
#include "dispatch.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>

#include "util.h"

typedef struct help_entry {
    const char *names;  /* the words that find it, space separated */
    int statement;      /* 1: a statement form; 0: a built-in */
    const char *usage;  /* the first column of the README table */
    const char *text;
} help_entry;

static const help_entry entries[] = {
    {"=", 1, "`x = e`", "bind `x` to a new value"},
    {"+= -= *= /=", 1, "`x += e`, `-=`, `*=` (matrix product), `/=` (right division)",
     "compound assignment; a dense `x` that nothing else holds is updated in place (copy-on-write), and "
     "`x += dt * v` scales `v` into `x` with no temporary: at the speed of the plain C loop from 10⁴ entries "
     "up, 3.9-6.5x faster than making a new array (docs/overhead.md). `x = x + e` and `x = x - e` are the "
     "same updates. The numbers are those of the copying path, bit for bit"},
    {"[]=", 1, "`x(i, j) = e`, `x(a:b) = e`, `x(x > 0) = e`, `x[i, j] = e`",
     "assign into a block of `x` (same shape, or a scalar): a new value is bound to `x`, the old one is "
     "left as it was (copy-on-write); a subscript past the end grows `x` zero-filled, as in "
     "Octave (a new name starts as `[]`)"},
    {"()", 1, "`f(args)`",
     "procedure call (value discarded); on a variable, `v(i)` and `A(i, j)` are subscripts (a variable "
     "hides a built-in of its name, as in Octave)"},
    {"if elseif else while for end break continue", 1,
     "`if c ... elseif c ... else ... end`, `while c ... end`, `for i = 1:n ... end`; or with braces "
     "`if (c) { ... } else { ... }`, `while (c) { ... }`, `for (i = v) { ... }`; `break`, `continue`",
     "control flow; `c` must be 1x1, nonzero is true; `for` binds `i` to each column of the value in turn (a "
     "range is never built whole); each iteration of a top-level `while` or `for` is a time step to the tuner; "
     "`,` separates statements as `;` does, but without hiding the value"},
    {"display format disp ans", 1, "`x`, `x = e` (no `;`), `disp(x)`, `format long`, `format short`",
     "with `core.display = on` (the `silc` command's setting; an embedded `SILC_EXEC` never prints) a "
     "statement without `;` shows its value as Octave does: small values in full, larger ones (over 40 rows or "
     "columns, sparse over 100 entries) summarised by size, format, nnz and top-left corner; an expression's "
     "value is shown and bound as `ans`. `disp(x)` always shows `x` without its name; `format long` shows 16 "
     "significant digits (`core.format`)"},
    {"clear", 1, "`clear`, `clear a b`", "remove names"},
    {"who", 1, "`who`", "names, shapes, formats"},
    {"set", 1, "`set key = value`, `set key`, `set`",
     "session option (same keys as the config file); `set key` shows the value in force and where it came "
     "from (default, file:line, session), `set` lists every key so, plugin options included; `help key` "
     "describes one and `help PLUGIN` lists a plugin's options with their defaults; in silcd a server "
     "setting (core.plugin_path, tune.wisdom, ...: `help set` lists them) is refused"},
    {"info", 1, "`info x`",
     "how `x` was last computed: statement, backend, method, time, backward error, condition estimate, "
     "iterations, factor reuse, warm start, earlier attempts of the fallback chain"},
    {"explain", 1, "`explain stmt`",
     "what would run and why (class, backend list and where it came from, each backend's verdict), without "
     "running solves or changing the store"},
    {"tune", 1, "`tune on [N]`, `tune off`, `tune status`, `tune step`, `tune report [\"f.svg\"]`, `tune forget`",
     "the tuner: thread count and backend for a time loop (docs/tuner.md)"},
    {"help", 1, "`help`, `help name`", "the statements, built-ins and loaded plugins, or one of them"},
    {"save load", 1, "`save \"f.h5\" [a b ...]`, `load \"f.h5\" [a b ...]`",
     "values to and from HDF5 (all names, or those given): dense as a 2-D dataset, CSR as a group with "
     "`data`, `indices`, `indptr` and a `shape` attribute (scipy's and anndata's layout), band as LAPACK "
     "storage with `kl`, `ku`; a failed save keeps the old file, a failed load changes no name; in silcd the "
     "file is beneath the session's folder under `silcd --data-dir` (no absolute path, `..` or symbolic "
     "link), refused without it"},
    {"[", 0, "`[1 2; 3 4]`, `[1, 2; 3, 4]`, `[A, b; c', d]`",
     "matrix literal / concatenation: `,` or white space side by side (`[1 -2]` is two entries, `[1 - 2]` "
     "one, as in Octave), `;` or a line break stacks; `[]` is 0×0 and is skipped in concatenation; CSR if "
     "any block is CSR"},
    {":", 0, "`a:b`, `a:s:b`",
     "row vector from a to b in steps of s (default 1), counted as Octave counts (`0:0.1:1` has 11 entries, "
     "the last exactly 1); empty when s points away from b; looser than `+ -`, tighter than comparisons "
     "(`1:n+1`); in a subscript the indices it lists"},
    {"zeros ones", 0, "`zeros(m[,n])`, `ones(m[,n])`", "dense; one argument gives m×m"},
    {"eye", 0, "`eye(n[,m])`", "CSR identity (sparse: this is a sparse-solver tool)"},
    {"rand", 0, "`rand(m[,n])`", "dense uniform [0,1), reproducible per context (xorshift64*)"},
    {"size rows cols nnz", 0, "`size(A)`, `size(A,d)`, `rows(A)`, `cols(A)`, `nnz(A)`",
     "shape; `nnz` counts numerically nonzero entries"},
    {"sparse", 0, "`sparse(i,j,v,m,n)`", "CSR from 1-based triplets, duplicates summed, `v` may be a scalar"},
    {"sparse dense band", 0, "`sparse(A)`, `dense(A)`, `band(A,kl,ku)`",
     "format conversion; `band` refuses an entry outside the band"},
    {"diag diagvec", 0, "`diag(v)`, `diagvec(A)`", "vector → CSR diagonal matrix; diagonal → column vector"},
    {"sum max min", 0, "`sum(A)`, `max(A)`, `min(A)`", "1×1 for a vector, else the row of per-column results"},
    {"max min", 0, "`max(A,B)`, `min(A,B)`", "element-wise"},
    {"dot norm", 0, "`dot(x,y)`, `norm(x[,p])`",
     "p = 1, 2, `inf` or `\"fro\"`; `norm(A)` of a matrix is the 2-norm"},
    {"abs sqrt exp log sin cos", 0, "`abs sqrt exp log sin cos`",
     "element-wise; `sqrt` and `log` of a real value with a negative entry are complex, as in Octave"},
    {"trans", 0, "`trans(A)`", "`A'`"},
    {"' .'", 0, "`A'`, `A.'`", "conjugate transpose, plain transpose (the same for a real `A`)"},
    {"i j complex", 0, "`2i`, `2.5j`, `1e3i`, `i`, `j`, `complex(a,b)`",
     "complex numbers: an imaginary literal, the imaginary unit (unless `i` or `j` is bound to a value), "
     "`a + bi` from real `a` and `b`"},
    {"real imag conj angle abs isreal", 0, "`real(z)`, `imag(z)`, `conj(z)`, `angle(z)`, `isreal(z)`",
     "parts, conjugate, argument (element-wise; `real` and `imag` give real values); `isreal` is 1 for a "
     "real value (a complex value stays complex until `real` demotes it); `dot(x,y)` conjugates `x`"},
    {"solve", 0, "`solve(A, b, \"options\")`",
     "`A \\ b` with per-call options, e.g. `\"backend = suitesparse.klu\"` or `\"mumps.icntl_7 = 5\"`"},
    {"pi inf nan eps Inf NaN", 0, "`pi`, `inf` (`Inf`), `nan` (`NaN`), `eps`",
     "constants (a variable of the same name shadows them)"},
};
enum { NENTRIES = sizeof entries / sizeof entries[0] };

/* 1 when word is one of the space-separated names. */
static int names_has(const char *names, const char *word)
{
    size_t len = strlen(word);
    while (*names) {
        size_t n = strcspn(names, " ");
        if (n == len && !strncmp(names, word, len)) return 1;
        names += n + (names[n] == ' ');
    }
    return 0;
}

/* Each word once, in table order, into words (at most max). */
static size_t all_words(const char **words, char (*store)[32], size_t max)
{
    size_t count = 0, i, k;
    for (i = 0; i < NENTRIES; i++) {
        const char *p = entries[i].names;
        while (*p) {
            size_t n = strcspn(p, " ");
            if (n < 32 && count < max) {
                snprintf(store[count], 32, "%.*s", (int)n, p);
                for (k = 0; k < count && strcmp(words[k], store[count]); k++) continue;
                if (k == count) words[count] = store[count], count++;
            }
            p += n + (p[n] == ' ');
        }
    }
    return count;
}

/* text without markdown's backquotes (a terminal shows them as noise). */
static void put_plain(strbuf *out, const char *text)
{
    for (; *text; text++)
        if (*text != '`') sb_printf(out, "%c", *text);
}

int lang_help(strbuf *out, const char *name, char *err, size_t errlen)
{
    const char *words[96];
    char store[96][32];
    size_t i, n, found = 0;
    if (!name || !*name) {
        n = all_words(words, store, 96);
        sb_puts(out, "statements and built-ins ('help NAME' for one):\n ");
        for (i = 0; i < n; i++)
            if (isalpha((unsigned char)words[i][0])) sb_printf(out, " %s", words[i]);
        sb_puts(out, "\n");
        return 0;
    }
    for (i = 0; i < NENTRIES; i++)
        if (names_has(entries[i].names, name)) {
            if (found) sb_puts(out, "\n");
            put_plain(out, entries[i].usage);
            sb_puts(out, "\n    ");
            put_plain(out, entries[i].text);
            sb_puts(out, "\n");
            if (!strcmp(name, "set")) cfg_describe_keys(out);
            found++;
        }
    if (found) return 0;
    n = all_words(words, store, 96);
    {
        const char *near = util_closest(name, words, n);
        if (near) snprintf(err, errlen, "help: no statement or built-in '%s' (did you mean '%s'?)", name, near);
        else snprintf(err, errlen, "help: no statement or built-in '%s'", name);
    }
    return -1;
}

void lang_help_markdown(strbuf *out, int statements)
{
    size_t i;
    sb_puts(out, statements ? "| form | meaning |\n| --- | --- |\n" : "| built-in | result |\n| --- | --- |\n");
    for (i = 0; i < NENTRIES; i++)
        if (entries[i].statement == statements) sb_printf(out, "| %s | %s |\n", entries[i].usage, entries[i].text);
}
