/*
 * test_help.c -- `help` and its table (core/lang/help.c): the README's two
 * tables are exactly the table's markdown (one table serves both), every
 * word `help` lists answers `help WORD` with its usage, and an unknown word
 * is an error with a suggestion.  Also the parse: `help` is a keyword, and a
 * name `help` can still be assigned.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "engine.h"
#include "lang.h"

/* The README's text between the marker line that contains tag and the
 * next end marker. */
static char *readme_table(const char *readme, const char *tag)
{
    const char *a = strstr(readme, tag), *b;
    char *t;
    if (!a || !(a = strchr(a, '\n')) || !(b = strstr(a, "<!-- end help table -->"))) return NULL;
    a++;
    t = malloc((size_t)(b - a) + 1);
    if (t) memcpy(t, a, (size_t)(b - a)), t[b - a] = 0;
    return t;
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    long n;
    char *s;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    rewind(f);
    s = malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) n = 0;
    if (s) s[n] = 0;
    fclose(f);
    return s;
}

static char heard[16384];

static void hear(void *user, const char *text)
{
    (void)user;
    strncat(heard, text, sizeof heard - strlen(heard) - 1);
}

int main(void)
{
    char *readme = slurp(SILC_SOURCE_DIR "/README.md"), err[256];
    strbuf b, all;
    const char *p;
    int statements, words = 0;
    CHECK(readme != NULL, "read README.md");
    for (statements = 0; readme && statements < 2; statements++) {
        char *t = readme_table(readme, statements ? "help table: statements" : "help table: built-ins");
        sb_init(&b);
        lang_help_markdown(&b, statements);
        CHECK(t && !strcmp(t, sb_str(&b)), "README's %s table is not core/lang/help.c's; it should read:\n%s",
              statements ? "statement" : "built-in", sb_str(&b));
        free(t);
        sb_free(&b);
    }
    free(readme);
    sb_init(&all);
    CHECK(lang_help(&all, NULL, err, sizeof err) == 0, "help lists");
    p = strchr(sb_str(&all), '\n');
    while (p && *p) {
        char word[32];
        int n = 0;
        while (*p == ' ' || *p == '\n') p++;
        if (!*p || sscanf(p, "%31s%n", word, &n) != 1) break;
        p += n;
        sb_init(&b);
        CHECK(lang_help(&b, word, err, sizeof err) == 0 && strstr(sb_str(&b), word),
              "help %s: %s", word, sb_str(&b));
        sb_free(&b);
        words++;
    }
    sb_free(&all);
    CHECK(words >= 40, "help lists %d words", words);
    sb_init(&b);
    CHECK(lang_help(&b, "sparce", err, sizeof err) != 0 &&
              !strcmp(err, "help: no statement or built-in 'sparce' (did you mean 'sparse'?)"),
          "unknown word: %s", err);
    sb_free(&b);
    {
        silc_engine *E = NULL;
        char e2[256];
        CHECK(eng_create(&E, NULL, e2, sizeof e2) == 0, "engine: %s", e2);
        if (E) {
            CHECK(lang_exec(E, "help = 3; x = help + 1") == 0, "a variable named help: %s", E->err);
            CHECK(lang_exec(E, "help solve") == 0, "help solve: %s", E->err);
            CHECK(lang_exec(E, "help nosuch") != 0 && strstr(E->err, "no statement or built-in 'nosuch'"),
                  "help nosuch: %s", E->err);
            /* issue 29: settings and plugin options are discoverable */
            E->output = hear;
            heard[0] = 0;
            CHECK(lang_exec(E, "help set") == 0 && strstr(heard, "  solve.verify           auto, off or a bound") &&
                      strstr(heard, "; default auto\n") && strstr(heard, "core.plugin_path"),
                  "help set: %s", heard);
            heard[0] = 0;
            CHECK(lang_exec(E, "help solve.verify") == 0 &&
                      !strncmp(heard, "solve.verify: auto, off or a bound: the backward error above which the next "
                                      "listed backend takes over\n  default: auto\n  now: solve.verify", 120),
                  "help KEY: %s", heard);
            heard[0] = 0;
            CHECK(lang_exec(E, "help core.plugin_path") == 0 && strstr(heard, "a server setting"),
                  "help of a server setting: %s", heard);
            CHECK(lang_exec(E, "help solve.verfy") != 0 &&
                      !strcmp(E->err, "unknown key 'solve.verfy'; did you mean 'solve.verify'?"),
                  "help of a misspelt key: %s", E->err);
            heard[0] = 0;
            CHECK(lang_exec(E, "help reference") == 0 && strstr(heard, "plugin reference") &&
                      strstr(heard, "no options"),
                  "help PLUGIN: %s", heard);
            heard[0] = 0;
            CHECK(lang_exec(E, "help for") == 0 && strstr(heard, "for i = 1:n ... end"), "help for: %s", heard);
            heard[0] = 0;
            CHECK(lang_exec(E, "help :") == 0 && strstr(heard, "0:0.1:1"), "help ':': %s", heard);
            E->output = NULL;
            eng_destroy(&E);
        }
    }
    printf("help: %d words, README tables match\n", words);
    return check_done();
}
