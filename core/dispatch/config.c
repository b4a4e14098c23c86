/*
 * config.c -- the options database: every key SILC understands, in three
 * scopes that shadow each other (config file < session `set` < per-call
 * options of solve(A, b, "...")).
 *
 * A key is "section.name": dispatch.<class> (an ordered list of backends),
 * tune.threads / tune.accuracy / tune.budget / tune.wisdom / tune.max_threads, core.plugin_path / core.threads,
 * solve.refine / solve.refine_residual (iterative refinement, refine.c) and
 * solve.backward_error (deferred | always | on_request, accuracy.h) -- per call these may be
 * written without the section: "refine = 2" --, and
 * <plugin>.<option> for the typed options a loaded plugin lists.  The INI file
 * (read with inih) spells the same keys as [section] name = value.  Every key
 * and value is checked when it is set, not when it is used, so a typo is
 * reported with its file and line and the closest valid spelling instead of
 * being silently ignored.  Names that SILC knows but that are not installed
 * here (a [mumps] section on a machine without MUMPS) are accepted, so one
 * config file serves every machine.
 *
 * Settings come in two kinds (docs/security.md): server settings, which name
 * a path, load code or raise a thread cap, and which only the operator sets
 * (silcd's config file or command line), and session settings, which `set`
 * and per-call options may change.  One table below (key_rules) says which
 * is which; `help set` prints it.  An engine becomes a server session's with
 * cfg_serve: from then on a session or call scope naming a server setting is
 * refused, free-form plugin option strings are sanitized, and the files a
 * statement names resolve beneath silcd's --data-dir (util/files.c does the
 * opening).  An embedded engine is its own operator: everything stays
 * settable and paths mean what the operating system says.
 */
#define _POSIX_C_SOURCE 200809L
#include "dispatch.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <ini.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct cfg_entry {
    char *key;
    char *value;
    char *origin;        /* "silc.conf:3", "session", "call": what `set` shows */
    struct cfg_entry *next;
} cfg_entry;

struct cfg_db {
    cfg_entry *scope[3]; /* indexed by enum cfg_scope, each in insertion order */
    const char *file;    /* the config file being read (cfg_load_file), for origins */
    int file_line;
    int serving;         /* a silcd session's engine (cfg_serve) */
    int data_fd;         /* its folder under --data-dir, -1 = file statements refused */
    uint64_t generation; /* counts changes of any setting (cfg_generation) */
    void *derived;       /* the dispatcher's cache of what it derives from settings (cfg_derived) */
};

static const char *const scope_names[3] = {"file", "session", "call"};
static const char *const tune_keys[] = {"threads", "accuracy", "budget", "wisdom", "max_threads"};
static const char *const core_keys[] = {"plugin_path", "threads", "display", "format", "profile"};
static const char *const solve_keys[] = {"refine", "refine_residual", "backward_error", "initial_guess",
                                         "verify"};

/* Longest list a dispatch key may name; more would only repeat names. */
#define CFG_MAX_LIST 32

/* ---- small text helpers --------------------------------------------------- */

static int in_list(const char *s, const char *const *list, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++)
        if (strcmp(s, list[i]) == 0) return 1;
    return 0;
}

static size_t count_names(const char *const *list)
{
    size_t n = 0;
    while (list[n]) n++;
    return n;
}

/* Copies s[0..len) trimmed of surrounding white space into out (outlen > 0). */
static void trim_copy(char *out, size_t outlen, const char *s, size_t len)
{
    while (len && isspace((unsigned char)*s)) s++, len--;
    while (len && isspace((unsigned char)s[len - 1])) len--;
    if (len >= outlen) len = outlen - 1;
    memcpy(out, s, len);
    out[len] = '\0';
}

static int parse_int(const char *s, int64_t *out)
{
    char *end;
    long long v;
    errno = 0;
    v = strtoll(s, &end, 10);
    if (end == s || *end != '\0' || errno == ERANGE) return -1;
    *out = (int64_t)v;
    return 0;
}

static int parse_double(const char *s, double *out)
{
    char *end;
    double v;
    errno = 0;
    v = strtod(s, &end);
    if (end == s || *end != '\0' || errno == ERANGE || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

static int parse_bool(const char *s, int64_t *out)
{
    static const char *const yes[] = {"1", "true", "yes", "on"};
    static const char *const no[] = {"0", "false", "no", "off"};
    size_t i;
    for (i = 0; i < 4; i++) {
        if (strcmp(s, yes[i]) == 0) return *out = 1, 0;
        if (strcmp(s, no[i]) == 0) return *out = 0, 0;
    }
    return -1;
}

/* ---- names: sections, plugins, backends ----------------------------------- */

/* A backend name SILC knows: one of ld_known_backends or one a loaded plugin
 * provides (third-party plugins are configurable too). */
static int backend_known(const silc_engine *E, const char *name)
{
    size_t i;
    for (i = 0; ld_known_backends[i]; i++)
        if (strcmp(ld_known_backends[i], name) == 0) return 1;
    return ld_find(E, name) != NULL;
}

/* Every configurable backend name, for suggestions; *out is malloc'd. */
static size_t backend_candidates(const silc_engine *E, const char ***out)
{
    const char **loaded = NULL, **all;
    size_t nl = ld_backend_names(E, &loaded), nk = count_names(ld_known_backends), i;
    all = malloc((nk + nl + 1) * sizeof *all);
    if (!all) {
        free(loaded);
        *out = NULL;
        return 0;
    }
    for (i = 0; i < nk; i++) all[i] = ld_known_backends[i];
    for (i = 0; i < nl; i++) all[nk + i] = loaded[i];
    free(loaded);
    *out = all;
    return nk + nl;
}

/* A name like "umfpack" is far (by edit distance) from "suitesparse.umfpack"
 * yet plainly meant it: the part after the dot is compared too, exactly and
 * then by edit distance, after the full names. */
static const char *suggest_backend(const silc_engine *E, const char *name)
{
    const char **cands, **tails;
    const char *best = NULL, *tail;
    size_t n = backend_candidates(E, &cands), i;
    tails = malloc((n + 1) * sizeof *tails);
    for (i = 0; i < n; i++) {
        const char *dot = strchr(cands[i], '.');
        if (tails) tails[i] = dot ? dot + 1 : NULL;
        if (dot && strcmp(dot + 1, name) == 0 && !best) best = cands[i];
    }
    if (!best) best = util_closest(name, cands, n);
    if (!best && tails && (tail = util_closest(name, tails, n)) != NULL)
        for (i = 0; i < n && !best; i++)
            if (tails[i] == tail) best = cands[i];
    free(tails);
    free(cands);
    return best;
}

/* Reports an unknown backend; `where` says which key named it. */
static int unknown_backend(silc_engine *E, const char *name, const char *where)
{
    const char *best = suggest_backend(E, name);
    if (best)
        return eng_error(E, "unknown backend '%s' in %s; did you mean '%s'?", name, where, best);
    return eng_error(E, "unknown backend '%s' in %s (known: reference, lapack, "
                        "suitesparse.umfpack, suitesparse.cholmod, suitesparse.klu, "
                        "suitesparse.spqr, mumps, petsc, lis-style)", name, where);
}

/* Plugin part ("suitesparse") of a known backend name, into out. */
static void plugin_part(const char *backend, char *out, size_t outlen)
{
    const char *dot = strchr(backend, '.');
    trim_copy(out, outlen, backend, dot ? (size_t)(dot - backend) : strlen(backend));
}

/* 1 if section names a plugin SILC knows of (installed or not). */
static int plugin_known(const char *section)
{
    char buf[64];
    size_t i;
    for (i = 0; ld_known_backends[i]; i++) {
        plugin_part(ld_known_backends[i], buf, sizeof buf);
        if (strcmp(buf, section) == 0) return 1;
    }
    return 0;
}

static int unknown_section(silc_engine *E, const char *section)
{
    /* Fixed sections, known plugins, loaded plugins: all valid section names. */
    char known[16][64];
    const char *cands[16 + 64];
    size_t n = 0, nk = 0, i, np = ld_plugin_count(E);
    const char *best;
    cands[n++] = "dispatch";
    cands[n++] = "tune";
    cands[n++] = "core";
    cands[n++] = "solve";
    cands[n++] = "accuracy";
    for (i = 0; ld_known_backends[i] && nk < 16; i++) {
        plugin_part(ld_known_backends[i], known[nk], sizeof known[nk]);
        cands[n++] = known[nk++];
    }
    for (i = 0; i < np && n < sizeof cands / sizeof cands[0]; i++)
        cands[n++] = ld_plugin_at(E, i)->table->name;
    best = util_closest(section, cands, n);
    if (best) return eng_error(E, "unknown section [%s]; did you mean [%s]?", section, best);
    return eng_error(E, "unknown section [%s] (sections: dispatch, tune, core, solve, or a plugin name)",
                     section);
}

static const char *suggest_key(const silc_engine *E, const char *key, char *out, size_t outlen);

/* An unknown section.name: the suggestion is the nearest real key of any
 * section (`solve.sparse` means `dispatch.solve.sparse`), else the nearest
 * name of this section. */
static int unknown_key(silc_engine *E, const char *section, const char *name,
                       const char *const *keys, size_t nkeys)
{
    char full[256], near[256];
    const char *best;
    snprintf(full, sizeof full, "%s.%s", section, name);
    if (suggest_key(E, full, near, sizeof near))
        return eng_error(E, "unknown key '%s'; did you mean '%s'?", full, near);
    best = util_closest(name, keys, nkeys);
    if (best) return eng_error(E, "unknown key '%s.%s'; did you mean '%s.%s'?", section, name,
                               section, best);
    return eng_error(E, "unknown key '%s.%s'", section, name);
}

/* ---- value checks ---------------------------------------------------------- */

/* A comma list of backend names; writes the normalised list "a, b, c" to norm. */
static int check_backend_list(silc_engine *E, const char *key, const char *value, strbuf *norm)
{
    const char *p = value;
    int count = 0;
    for (;;) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        char name[128];
        size_t nl;
        int optional;
        trim_copy(name, sizeof name, p, len);
        /* "name?" lists an optional backend (dispatch.c: disp_check_configured) */
        nl = strlen(name);
        optional = nl > 1 && name[nl - 1] == '?';
        if (optional) name[nl - 1] = '\0';
        if (!name[0])
            return eng_error(E, "%s: empty backend name in list '%s'", key, value);
        if (!backend_known(E, name)) return unknown_backend(E, name, key);
        if (optional) name[nl - 1] = '?';
        if (++count > CFG_MAX_LIST)
            return eng_error(E, "%s: more than %d backends listed", key, CFG_MAX_LIST);
        if ((count > 1 && sb_puts(norm, ", ")) || sb_puts(norm, name))
            return eng_error(E, "out of memory setting '%s'", key);
        if (!comma) break;
        p = comma + 1;
    }
    return 0;
}

static int check_threads(silc_engine *E, const char *key, const char *value)
{
    int64_t n;
    if (strcmp(value, "auto") == 0) return 0;
    if (parse_int(value, &n) || n < 1 || n > 4096)
        return eng_error(E, "%s expects 'auto' or a thread count from 1 to 4096, got '%s'", key,
                         value);
    return 0;
}

static int check_option(silc_engine *E, const silc_plugin *pl, const char *name,
                        const char *value)
{
    const char **keys;
    int i;
    int64_t iv;
    double dv;
    const silc_option_spec *spec = NULL;
    for (i = 0; i < pl->n_options; i++)
        if (strcmp(pl->options[i].key, name) == 0) spec = &pl->options[i];
    if (!spec) {
        const char *best = NULL;
        keys = malloc((size_t)(pl->n_options + 1) * sizeof *keys);
        if (keys) {
            for (i = 0; i < pl->n_options; i++) keys[i] = pl->options[i].key;
            best = util_closest(name, keys, (size_t)pl->n_options);
        }
        if (best)
            eng_error(E, "plugin '%s' has no option '%s'; did you mean '%s'?", pl->name, name, best);
        else if (pl->n_options == 0)
            eng_error(E, "plugin '%s' has no option '%s' (it takes no options)", pl->name, name);
        else
            eng_error(E, "plugin '%s' has no option '%s'", pl->name, name);
        free(keys);
        return -1;
    }
    switch (spec->type) {
    case SILC_OPT_INT:
        if (parse_int(value, &iv))
            return eng_error(E, "option '%s.%s' expects an integer, got '%s'", pl->name, name, value);
        break;
    case SILC_OPT_DOUBLE:
        if (parse_double(value, &dv))
            return eng_error(E, "option '%s.%s' expects a number, got '%s'", pl->name, name, value);
        break;
    case SILC_OPT_BOOL:
        if (parse_bool(value, &iv))
            return eng_error(E, "option '%s.%s' expects true or false, got '%s'", pl->name, name,
                             value);
        break;
    default:
        break;
    }
    return 0;
}

/* value as the one to store (norm), or "out of memory" (a short value
 * stored silently would be another setting). */
static int keep_value(silc_engine *E, strbuf *norm, const char *section, const char *name,
                      const char *value)
{
    if (sb_puts(norm, value) == 0) return 0;
    return eng_error(E, "out of memory setting '%s%s%s'", section, section[0] ? "." : "", name);
}

/* Validates section.name = value; on success norm holds the value to store. */
static int check_key(silc_engine *E, int scope, const char *section, const char *name,
                     const char *value, strbuf *norm)
{
    const ld_plugin *pl;
    double acc;
    if (!section[0]) {
        if (strcmp(name, "backend") == 0) {
            if (scope != CFG_SCOPE_CALL)
                return eng_error(E, "'backend' forces a backend for one call only; use "
                                    "dispatch.<class> to change the default");
            if (!backend_known(E, value)) return unknown_backend(E, value, "option 'backend'");
            return keep_value(E, norm, section, name, value);
        }
        return eng_error(E, "key '%s' has no section (write section.key, e.g. tune.threads)",
                         name);
    }
    if (!name[0]) return eng_error(E, "key '%s.' names no option", section);
    if (!value[0]) return eng_error(E, "%s.%s: empty value", section, name);
    if (strcmp(section, "dispatch") == 0) {
        char key[160];
        size_t nc = count_names(disp_class_names), i;
        for (i = 0; i < nc; i++)
            if (strcmp(disp_class_names[i], name) == 0) break;
        if (i == nc) {
            const char *best = util_closest(name, disp_class_names, nc);
            if (best)
                return eng_error(E, "unknown dispatch class '%s'; did you mean '%s'?", name, best);
            return eng_error(E, "unknown dispatch class '%s'", name);
        }
        snprintf(key, sizeof key, "dispatch.%s", name);
        return check_backend_list(E, key, value, norm);
    }
    if (strcmp(section, "tune") == 0) {
        if (strcmp(name, "threads") == 0) {
            if (check_threads(E, "tune.threads", value)) return -1;
        } else if (strcmp(name, "accuracy") == 0) {
            if (parse_double(value, &acc) || acc <= 0 || acc >= 1)
                return eng_error(E, "tune.accuracy expects a number between 0 and 1, got '%s'",
                                 value);
        } else if (strcmp(name, "budget") == 0) {
            if (parse_double(value, &acc) || acc <= 0 || acc > 1)
                return eng_error(E, "tune.budget expects a share of the run above 0 and at most 1, "
                                    "got '%s'", value);
        } else if (strcmp(name, "max_threads") == 0) {
            if (check_threads(E, "tune.max_threads", value)) return -1;
        } else if (strcmp(name, "wisdom") != 0) {
            return unknown_key(E, section, name, tune_keys, 5);
        }
        return keep_value(E, norm, section, name, value);
    }
    if (strcmp(section, "core") == 0) {
        if (strcmp(name, "threads") == 0) {
            if (check_threads(E, "core.threads", value)) return -1;
        } else if (strcmp(name, "display") == 0 || strcmp(name, "profile") == 0) {
            if (strcmp(value, "on") != 0 && strcmp(value, "off") != 0)
                return eng_error(E, "core.%s expects 'on' or 'off', got '%s'", name, value);
        } else if (strcmp(name, "format") == 0) {
            if (strcmp(value, "short") != 0 && strcmp(value, "long") != 0)
                return eng_error(E, "core.format expects 'short' or 'long', got '%s'", value);
        } else if (strcmp(name, "plugin_path") != 0) {
            return unknown_key(E, section, name, core_keys, sizeof core_keys / sizeof core_keys[0]);
        }
        return keep_value(E, norm, section, name, value);
    }
    if (strcmp(section, "accuracy") == 0) { /* accuracy.condest (dispatch.c: report_reset, condest_settle) */
        if (strcmp(name, "condest") != 0) return unknown_key(E, section, name, (const char *const[]){"condest"}, 1);
        if (strcmp(value, "auto") != 0 && strcmp(value, "now") != 0 && strcmp(value, "on") != 0 &&
            strcmp(value, "on_request") != 0 && strcmp(value, "off") != 0)
            return eng_error(E, "accuracy.condest expects auto, now, on_request, on (= auto) or off, got '%s'",
                             value);
        return keep_value(E, norm, section, name, value);
    }
    if (strcmp(section, "solve") == 0) {
        int64_t steps;
        if (strcmp(name, "refine") == 0) {
            if (parse_int(value, &steps) || steps < 0 || steps > 100)
                return eng_error(E, "solve.refine expects a number of refinement steps from 0 to "
                                    "100, got '%s'", value);
        } else if (strcmp(name, "refine_residual") == 0) {
            if (strcmp(value, "double") != 0 && strcmp(value, "extended") != 0)
                return eng_error(E, "solve.refine_residual expects 'double' or 'extended', got '%s'",
                                 value);
        } else if (strcmp(name, "backward_error") == 0) {
            if (strcmp(value, "always") != 0 && strcmp(value, "deferred") != 0 &&
                strcmp(value, "on_request") != 0)
                return eng_error(E, "solve.backward_error expects 'deferred', 'always' or "
                                    "'on_request', got '%s'", value);
        } else if (strcmp(name, "initial_guess") == 0) {
            if (strcmp(value, "auto") != 0 && strcmp(value, "previous") != 0 && strcmp(value, "zero") != 0)
                return eng_error(E, "solve.initial_guess expects 'auto', 'previous' or 'zero', got '%s'",
                                 value);
        } else if (strcmp(name, "verify") == 0) {
            if (strcmp(value, "auto") != 0 && strcmp(value, "off") != 0 &&
                (parse_double(value, &acc) || acc <= 0 || acc >= 1))
                return eng_error(E, "solve.verify expects 'auto', 'off' or a backward error between 0 and 1, "
                                    "got '%s'", value);
        } else {
            return unknown_key(E, section, name, solve_keys, 5);
        }
        return keep_value(E, norm, section, name, value);
    }
    pl = ld_find_plugin(E, section);
    if (pl) {
        if (check_option(E, pl->table, name, value)) return -1;
        return keep_value(E, norm, section, name, value);
    }
    if (plugin_known(section)) return keep_value(E, norm, section, name, value);
    return unknown_section(E, section);
}

/* ---- the database ---------------------------------------------------------- */

static void free_list(cfg_entry *e)
{
    while (e) {
        cfg_entry *next = e->next;
        free(e->key);
        free(e->value);
        free(e->origin);
        free(e);
        e = next;
    }
}

static cfg_entry **find_slot(cfg_db *db, int scope, const char *key)
{
    cfg_entry **pe;
    for (pe = &db->scope[scope]; *pe; pe = &(*pe)->next)
        if (strcmp((*pe)->key, key) == 0) break;
    return pe;
}

/* ---- server settings and session settings ------------------------------------ */

/* What a session of silcd may do with a key. */
enum key_kind {
    KEY_SESSION,   /* settable by `set` and per-call options */
    KEY_SERVER,    /* names a path, loads code or raises a cap: silcd's config only */
    KEY_FREEFORM,  /* a plugin's free-form option string: sanitized (freeform_refusal) */
    KEY_THREADS    /* a thread count: at most the operator's cap (session_thread_cap) */
};

typedef struct key_rule {
    const char *key;   /* a key, or a pattern shown as such ("dispatch.<class>") */
    enum key_kind kind;
    const char *dflt;  /* the value in force when nothing sets it; NULL: a pattern, or a
                          plugin's option (its own table gives the default) */
    const char *why;
} key_rule;

/* THE table of settings: which key is whose (docs/security.md, `help
 * set`), its default and what it does (`set`, `help KEY`).  A key not
 * listed is a session setting: dispatch.<class> (default: the built-in
 * list, disp_default_list) and a plugin's typed options (its own table). */
static const key_rule key_rules[] = {
    {"core.plugin_path", KEY_SERVER, "(none)", "folders whose plugins are loaded: loads code"},
    {"core.threads", KEY_SERVER, "1", "the thread budget of one operation"},
    {"tune.wisdom", KEY_SERVER, "(SILC_WISDOM, else ~/.silc_wisdom)",
     "the wisdom file: names a path the tuner writes"},
    {"tune.max_threads", KEY_SERVER, "auto", "the tuner's thread cap (may exceed the cores)"},
    {"mumps.icntl_1", KEY_SERVER, NULL, "MUMPS error output unit: a Fortran unit writes a file"},
    {"mumps.icntl_2", KEY_SERVER, NULL, "MUMPS diagnostics unit: a Fortran unit writes a file"},
    {"mumps.icntl_3", KEY_SERVER, NULL, "MUMPS global information unit: a Fortran unit writes a file"},
    {"mumps.icntl_22", KEY_SERVER, NULL, "MUMPS out-of-core factorization: writes the factors to files"},
    {"tune.threads", KEY_THREADS, "(core.threads; the tuner's choice after 'tune on')",
     "threads of the solves, or 'auto' for the tuner; in silcd at most tune.max_threads (else the cores)"},
    {"petsc.options", KEY_FREEFORM, NULL, "PETSc's option string; in silcd no option that views, monitors, "
                                          "logs, dumps, names a file, loads code or sets threads"},
    {"lis-style.options", KEY_FREEFORM, NULL, "the Lis-style option string; sanitized as petsc.options"},
    {"dispatch.<class>", KEY_SESSION, NULL, "the backends a class of operation tries, in order"},
    {"tune.accuracy", KEY_SESSION, "1e-10", "the accuracy the tuner's backend choice must reach"},
    {"tune.budget", KEY_SESSION, "0.05", "the share of the run the tuner may spend measuring"},
    {"accuracy.condest", KEY_SESSION, "auto",
     "auto (or on), now, on_request or off: the condition estimate of every solve; auto makes it at solve "
     "time when it costs at most 15 % of the factorization or the matrix looks ill-conditioned, else when "
     "the report is read (info); now always at solve time; on_request always when read"},
    {"solve.refine", KEY_SESSION, "(up to 3 steps when a direct result misses solve.verify)",
     "steps of iterative refinement after a direct solve (0 to 100)"},
    {"solve.refine_residual", KEY_SESSION, "double", "double or extended: the refinement's residual"},
    {"solve.backward_error", KEY_SESSION, "deferred",
     "deferred, always or on_request: when a solve's backward error is computed"},
    {"solve.initial_guess", KEY_SESSION, "auto", "auto, previous or zero: warm starts of iterative solves"},
    {"solve.verify", KEY_SESSION, "auto",
     "auto, off or a bound: the backward error above which the next listed backend takes over"},
    {"core.display", KEY_SESSION, "off",
     "on: a statement without ';' shows its value (the silc command turns it on; SILC_EXEC never prints)"},
    {"core.format", KEY_SESSION, "short", "short or long: 5 or 16 significant digits when values are shown"},
    {"core.profile", KEY_SESSION, "off",
     "on: time every statement and plugin call, with bytes in and out and reused factorizations; "
     "the statement 'profile' prints the tables (silc --profile: at exit)"},
    {"<plugin>.<option>", KEY_SESSION, NULL, "a plugin's typed options (other than those above): help PLUGIN"},
};

static const key_rule *rule_of(const char *key)
{
    size_t i;
    for (i = 0; i < sizeof key_rules / sizeof key_rules[0]; i++)
        if (!strcmp(key_rules[i].key, key)) return &key_rules[i];
    return NULL;
}

void cfg_describe_keys(strbuf *b)
{
    size_t i;
    int server;
    for (server = 1; server >= 0; server--) {
        sb_puts(b, server ? "server settings (silcd's config file or command line only; any setting in "
                            "an embedded program):\n"
                          : "session settings (set, or solve(A, b, \"key = value\")):\n");
        for (i = 0; i < sizeof key_rules / sizeof key_rules[0]; i++)
            if ((key_rules[i].kind == KEY_SERVER) == server)
                sb_printf(b, "  %-22s %s%s%s\n", key_rules[i].key, key_rules[i].why,
                          key_rules[i].dflt ? "; default " : "", key_rules[i].dflt ? key_rules[i].dflt : "");
    }
    sb_puts(b, "'set' lists every key with the value in force and where it came from; 'help KEY' "
               "describes one; 'help PLUGIN' lists a plugin's options\n");
}

/* ---- every key, for listing and suggestions ----------------------------------- */

/* One key SILC knows here: its default and what it does. */
typedef struct key_info {
    char key[160];
    const char *dflt;
    const char *why;
} key_info;

/* Calls visit for every concrete key: the table's, each dispatch class's,
 * and each loaded plugin's options; stops when visit returns nonzero. */
static int each_key(const silc_engine *E, int (*visit)(void *u, const key_info *k), void *u)
{
    key_info k;
    size_t i, p, np = ld_plugin_count(E);
    for (i = 0; i < sizeof key_rules / sizeof key_rules[0]; i++) {
        if (!key_rules[i].dflt) continue;   /* a pattern, or a plugin's (below) */
        snprintf(k.key, sizeof k.key, "%s", key_rules[i].key);
        k.dflt = key_rules[i].dflt;
        k.why = key_rules[i].why;
        if (visit(u, &k)) return 1;
    }
    for (i = 0; disp_class_names[i]; i++) {
        snprintf(k.key, sizeof k.key, "dispatch.%s", disp_class_names[i]);
        k.dflt = disp_default_list(disp_class_names[i]);
        k.why = "the backends this class of operation tries, in order (the built-in list when unset)";
        if (visit(u, &k)) return 1;
    }
    for (p = 0; p < np; p++) {
        const silc_plugin *pl = ld_plugin_at(E, p)->table;
        int o;
        for (o = 0; o < pl->n_options; o++) {
            snprintf(k.key, sizeof k.key, "%s.%s", pl->name, pl->options[o].key);
            k.dflt = pl->options[o].default_value && pl->options[o].default_value[0]
                         ? pl->options[o].default_value
                         : "(the library's own default)";
            k.why = pl->options[o].help ? pl->options[o].help : "";
            if (visit(u, &k)) return 1;
        }
    }
    return 0;
}

typedef struct key_search {
    const char *want;
    key_info found;
    int hit;
    const char **names;   /* every key, for the nearest one */
    size_t n, cap;
    char (*store)[160];
} key_search;

static int find_visit(void *u, const key_info *k)
{
    key_search *s = u;
    if (strcmp(s->want, k->key) != 0) return 0;
    s->found = *k;
    s->hit = 1;
    return 1;
}

static int collect_visit(void *u, const key_info *k)
{
    key_search *s = u;
    if (s->n < s->cap) {
        memcpy(s->store[s->n], k->key, sizeof s->store[0]);
        s->names[s->n] = s->store[s->n];
        s->n++;
    }
    return 0;
}

static int find_key(const silc_engine *E, const char *key, key_info *out)
{
    key_search s;
    memset(&s, 0, sizeof s);
    s.want = key;
    each_key(E, find_visit, &s);
    if (s.hit) *out = s.found;
    return s.hit;
}

/* The real key nearest to key, into out: "dispatch." + key when that is one
 * (`solve.sparse`), else the nearest by edit distance.  NULL when none is
 * near (or memory ran out). */
static const char *suggest_key(const silc_engine *E, const char *key, char *out, size_t outlen)
{
    key_search s;
    key_info k;
    const char *best = NULL;
    char with[200];
    snprintf(with, sizeof with, "dispatch.%s", key);
    if (find_key(E, with, &k)) {
        snprintf(out, outlen, "%s", with);
        return out;
    }
    memset(&s, 0, sizeof s);
    s.cap = 4096;
    s.names = malloc(s.cap * sizeof *s.names);
    s.store = malloc(s.cap * sizeof *s.store);
    if (s.names && s.store) {
        each_key(E, collect_visit, &s);
        if ((best = util_closest(key, s.names, s.n))) snprintf(out, outlen, "%s", best);
    }
    free(s.names);
    free(s.store);
    return best ? out : NULL;
}

/* The entry in force for key (the narrowest scope that has it), or NULL. */
static const cfg_entry *entry_in_force(const silc_engine *E, const char *key)
{
    int s;
    for (s = CFG_SCOPE_CALL; s >= CFG_SCOPE_FILE; s--) {
        cfg_entry *e = *find_slot(E->cfg, s, key);
        if (e) return e;
    }
    return NULL;
}

static void put_setting(const silc_engine *E, strbuf *b, const char *key, const char *dflt)
{
    const cfg_entry *e = entry_in_force(E, key);
    sb_printf(b, "%-30s = %s  (%s)\n", key, e ? e->value : dflt, e ? e->origin : "default");
}

typedef struct list_ctx {
    const silc_engine *E;
    strbuf *b;
} list_ctx;

static int list_visit(void *u, const key_info *k)
{
    list_ctx *c = u;
    put_setting(c->E, c->b, k->key, k->dflt);
    return 0;
}

void cfg_list(const silc_engine *E, strbuf *b)
{
    list_ctx c;
    int s;
    key_info k;
    if (!E || !E->cfg) return;
    c.E = E;
    c.b = b;
    each_key(E, list_visit, &c);
    /* set keys no table lists: a known plugin's options while it is not installed */
    for (s = CFG_SCOPE_FILE; s <= CFG_SCOPE_CALL; s++) {
        const cfg_entry *e;
        for (e = E->cfg->scope[s]; e; e = e->next)
            if (!find_key(E, e->key, &k) && entry_in_force(E, e->key) == e)
                sb_printf(b, "%-30s = %s  (%s; its plugin is not loaded)\n", e->key, e->value, e->origin);
    }
}

int cfg_show_key(silc_engine *E, const char *key, strbuf *b, int describe)
{
    key_info k;
    char near[256];
    const cfg_entry *e;
    if (find_key(E, key, &k)) {
        if (describe) {
            const key_rule *r = rule_of(key);
            sb_printf(b, "%s: %s\n  default: %s\n", key, k.why, k.dflt);
            if (r && r->kind == KEY_SERVER) sb_puts(b, "  a server setting: silcd's config file only\n");
            if (r && r->kind == KEY_FREEFORM) sb_printf(b, "  in silcd: %s\n", r->why);
            sb_puts(b, "  now: ");
        }
        put_setting(E, b, key, k.dflt);
        return 0;
    }
    if ((e = entry_in_force(E, key))) {   /* a key of a known plugin that is not loaded */
        sb_printf(b, "%-30s = %s  (%s; its plugin is not loaded)\n", key, e->value, e->origin);
        return 0;
    }
    if (suggest_key(E, key, near, sizeof near))
        return eng_error(E, "unknown key '%s'; did you mean '%s'?", key, near);
    return eng_error(E, "unknown key '%s' ('set' lists every key)", key);
}

int cfg_describe_plugin(const silc_engine *E, const char *name, strbuf *b)
{
    const ld_plugin *lp = ld_find_plugin(E, name);
    const silc_plugin *pl;
    int o, i;
    if (!lp) return -1;
    pl = lp->table;
    sb_printf(b, "plugin %s %s\n", pl->name, pl->version ? pl->version : "");
    for (i = 0; i < pl->n_backends; i++)
        sb_printf(b, "  backend %s%s%s: %s\n", pl->name, pl->backends[i].name ? "." : "",
                  pl->backends[i].name ? pl->backends[i].name : "",
                  pl->backends[i].description ? pl->backends[i].description : "");
    if (pl->n_options == 0) sb_puts(b, "  no options\n");
    else sb_printf(b, "  options (set %s.KEY = VALUE; default in brackets):\n", pl->name);
    for (o = 0; o < pl->n_options; o++) {
        static const char *const types[] = {"integer", "number", "text", "true/false"};
        const silc_option_spec *sp = &pl->options[o];
        sb_printf(b, "    %s.%s [%s] (%s): %s\n", pl->name, sp->key,
                  sp->default_value && sp->default_value[0] ? sp->default_value : "library default",
                  sp->type >= 0 && sp->type < 4 ? types[sp->type] : "?", sp->help ? sp->help : "");
    }
    return 0;
}

void cfg_list_plugins(const silc_engine *E, strbuf *b)
{
    size_t i, n = ld_plugin_count(E);
    sb_puts(b, "plugins ('help PLUGIN' for its backends and options):\n ");
    for (i = 0; i < n; i++) sb_printf(b, " %s", ld_plugin_at(E, i)->table->name);
    sb_puts(b, "\n");
}

/* Words in a free-form option's name that make it a server's business: what
 * views, monitors, logs, dumps or names a file, loads code (-dll_append,
 * -python), starts a debugger, or sets a thread count (PETSc's -*_view
 * :file, -log_view, -options_file, -malloc_dump; Lis's -omp_num_threads;
 * MUMPS's output units and out-of-core through PETSc). */
static const char *const freeform_denied[] = {
    "view", "monitor", "log", "dump", "file", "dll", "debug", "draw", "saws", "python", "history",
    "info", "trace", "malloc", "options", "error", "display", "objects", "write", "save", "load",
    "output", "print", "thread", "mumps_icntl_1", "mumps_icntl_2", "mumps_icntl_3", "mumps_icntl_4",
    "mumps_icntl_22", "ooc", "yaml", "prefix", "memory", "help"};

/* 0 if a session of silcd may pass text as key's free-form option string;
 * else -1 with the refusal.  Characters are limited first (no ':' or '/'
 * can then name a file or a viewer, no quotes can hide a space), then every
 * "-name" is checked against freeform_denied. */
static int freeform_refusal(silc_engine *E, const char *key, const char *text)
{
    const char *p;
    size_t i;
    for (p = text; *p; p++)
        if (!isalnum((unsigned char)*p) && !strchr(" \t_.+,=-", *p))
            return eng_error(E, "%s: the character '%c' is refused in a silcd session (it could name a "
                                "file or a viewer); only letters, digits, spaces and _ . + , = - are allowed",
                             key, *p);
    for (p = text; *p;) {
        size_t n;
        while (*p == ' ' || *p == '\t') p++;
        n = strcspn(p, " \t");
        if (n > 1 && p[0] == '-' && isalpha((unsigned char)p[1])) {
            char name[128];
            trim_copy(name, sizeof name, p + 1, n - 1);
            for (i = 0; name[i]; i++) name[i] = (char)tolower((unsigned char)name[i]);
            for (i = 0; i < sizeof freeform_denied / sizeof freeform_denied[0]; i++)
                if (strstr(name, freeform_denied[i]))
                    return eng_error(E, "%s: '-%s' is refused in a silcd session: options that view, "
                                        "monitor, log, dump, name a file, load code or set threads are "
                                        "server settings (set them in silcd's config)", key, name);
        }
        p += n;
    }
    return 0;
}

/* The operator's thread cap of a session: tune.max_threads from the config
 * file, else the cores. */
static long session_thread_cap(const silc_engine *E)
{
    cfg_entry *e = *find_slot(E->cfg, CFG_SCOPE_FILE, "tune.max_threads");
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    if (e && strcmp(e->value, "auto")) return strtol(e->value, NULL, 10);
    return cores > 0 ? cores : 1;
}

/* In a silcd session, what a session or call scope may not set, per
 * key_rules: 0 if allowed, else -1 with the refusal. */
static int session_refusal(silc_engine *E, int scope, const char *key, const char *value)
{
    const key_rule *r;
    if (!E->cfg->serving || scope == CFG_SCOPE_FILE || !(r = rule_of(key))) return 0;
    switch (r->kind) {
    case KEY_SERVER:
        return eng_error(E, "'%s' is a server setting: set it in silcd's config", key);
    case KEY_FREEFORM:
        return freeform_refusal(E, key, value);
    case KEY_THREADS:
        if (strcmp(value, "auto")) {
            long cap = session_thread_cap(E), n = strtol(value, NULL, 10);
            if (n > cap)
                return eng_error(E, "%s = %ld is over this server's cap of %ld threads (tune.max_threads, a "
                                    "server setting, else the cores)", key, n, cap);
        }
        return 0;
    default:
        return 0;
    }
}

/* Stores key = value in scope (replacing an earlier value of that key). */
static int store_value(silc_engine *E, int scope, const char *key, const char *value)
{
    cfg_entry **pe = find_slot(E->cfg, scope, key), *e;
    char where[300];
    char *v = util_strdup(value), *o;
    if (scope == CFG_SCOPE_FILE && E->cfg->file)
        snprintf(where, sizeof where, "%s:%d", E->cfg->file, E->cfg->file_line);
    else
        snprintf(where, sizeof where, "%s", scope_names[scope]);
    o = util_strdup(where);
    if (!v || !o) {
        free(v);
        free(o);
        return eng_error(E, "out of memory setting '%s'", key);
    }
    E->cfg->generation++;
    if (*pe) {
        free((*pe)->value);
        free((*pe)->origin);
        (*pe)->value = v;
        (*pe)->origin = o;
        return 0;
    }
    e = calloc(1, sizeof *e);
    if (!e || !(e->key = util_strdup(key))) {
        free(e);
        free(v);
        free(o);
        return eng_error(E, "out of memory setting '%s'", key);
    }
    e->value = v;
    e->origin = o;
    *pe = e;
    return 0;
}

int cfg_create(silc_engine *E)
{
    E->cfg = calloc(1, sizeof *E->cfg);
    if (!E->cfg) return eng_error(E, "out of memory creating the options database");
    E->cfg->data_fd = -1;
    return 0;
}

void cfg_destroy(silc_engine *E)
{
    int s;
    if (!E || !E->cfg) return;
    for (s = 0; s < 3; s++) free_list(E->cfg->scope[s]);
    free(E->cfg->derived);
    if (E->cfg->data_fd >= 0) close(E->cfg->data_fd);
    free(E->cfg);
    E->cfg = NULL;
}

/* Checks and stores section.name = value.  Loading plugins named by
 * core.plugin_path right away lets the rest of the same file configure them. */
static int set_parts(silc_engine *E, int scope, const char *section, const char *name,
                     const char *value)
{
    strbuf norm, key;
    int rc;
    if (scope < CFG_SCOPE_FILE || scope > CFG_SCOPE_CALL)
        return eng_error(E, "invalid option scope %d", scope);
    sb_init(&norm);
    sb_init(&key);
    rc = check_key(E, scope, section, name, value, &norm);
    if (rc == 0 && (section[0] ? sb_printf(&key, "%s.%s", section, name) : sb_puts(&key, name)))
        rc = eng_error(E, "out of memory setting '%s%s%s'", section, section[0] ? "." : "", name);
    else if (rc == 0 && (rc = session_refusal(E, scope, sb_str(&key), sb_str(&norm))) == 0)
        rc = store_value(E, scope, sb_str(&key), sb_str(&norm));
    if (rc == 0 && strcmp(section, "core") == 0 && strcmp(name, "plugin_path") == 0)
        rc = ld_load_path(E, value);
    sb_free(&norm);
    sb_free(&key);
    return rc ? -1 : 0;
}

int cfg_set(silc_engine *E, int scope, const char *key, const char *value)
{
    char k[256], v[4096], section[128];
    const char *dot;
    if (!E || !key || !value) return -1;
    trim_copy(k, sizeof k, key, strlen(key));
    trim_copy(v, sizeof v, value, strlen(value));
    if (!k[0]) return eng_error(E, "empty option key");
    dot = strchr(k, '.');
    /* The solve knobs read naturally without their section:
     * solve(A, b, "refine = 2"). */
    if (!dot && in_list(k, solve_keys, sizeof solve_keys / sizeof solve_keys[0]))
        return set_parts(E, scope, "solve", k, v);
    if (!dot) return set_parts(E, scope, "", k, v);
    trim_copy(section, sizeof section, k, (size_t)(dot - k));
    return set_parts(E, scope, section, dot + 1, v);
}

int cfg_set_call_options(silc_engine *E, const char *text)
{
    const char *p = text;
    cfg_clear_call_options(E);
    if (!text) return 0;
    while (*p) {
        size_t len = strcspn(p, ";\n");
        char item[4096], *eq;
        trim_copy(item, sizeof item, p, len);
        p += len;
        if (*p) p++;
        if (!item[0]) continue;
        eq = strchr(item, '=');
        if (!eq) {
            cfg_clear_call_options(E);
            return eng_error(E, "option '%s' needs the form key = value", item);
        }
        *eq = '\0';
        if (cfg_set(E, CFG_SCOPE_CALL, item, eq + 1)) {
            cfg_clear_call_options(E);
            return -1;
        }
    }
    return 0;
}

void cfg_clear_call_options(silc_engine *E)
{
    if (!E || !E->cfg || !E->cfg->scope[CFG_SCOPE_CALL]) return;
    free_list(E->cfg->scope[CFG_SCOPE_CALL]);
    E->cfg->scope[CFG_SCOPE_CALL] = NULL;
    E->cfg->generation++;
}

uint64_t cfg_generation(const silc_engine *E)
{
    return E && E->cfg ? E->cfg->generation : 0;
}

void *cfg_derived(const silc_engine *E, size_t bytes)
{
    if (!E || !E->cfg) return NULL;
    if (!E->cfg->derived) E->cfg->derived = calloc(1, bytes);
    return E->cfg->derived;
}

const char *cfg_get(const silc_engine *E, const char *key)
{
    int s;
    if (!E || !E->cfg || !key) return NULL;
    for (s = CFG_SCOPE_CALL; s >= CFG_SCOPE_FILE; s--) {
        cfg_entry *e = *find_slot(E->cfg, s, key);
        if (e) return e->value;
    }
    return NULL;
}

/* ---- the INI file ---------------------------------------------------------- */

/* inih (as packaged) does not pass line numbers to the handler, so the reader
 * counts them. */
typedef struct file_ctx {
    silc_engine *E;
    FILE *fp;
    const char *path;
    int line;
    int err_line;          /* line of the first rejected key or line, 0 if none */
    char err[sizeof ((silc_engine *)0)->err];
    long bytes;            /* read so far: at most CFG_MAX_FILE_BYTES */
} file_ctx;

/* A config file is a few hundred bytes of settings; anything this large is
 * not one, and reading it would only cost memory and time. */
#define CFG_MAX_FILE_BYTES (1L << 20)

/* Hands inih one whole line.  inih reads into a buffer of its build's
 * INI_MAX_LINE bytes (num) and would silently cut a longer line, or take its
 * rest as the next line; and a NUL byte would hide the rest of its line.
 * Either ends the file here with an error naming the line. */
static char *file_reader(char *str, int num, void *stream)
{
    file_ctx *c = stream;
    int len = 0, ch = 0;
    if (c->err_line) return NULL;          /* nothing after the first error */
    while (len < num - 1 && (ch = getc(c->fp)) != EOF) {
        if (++c->bytes > CFG_MAX_FILE_BYTES) {   /* it grew after the size check */
            c->err_line = c->line + 1;
            snprintf(c->err, sizeof c->err, "the file is over %ld bytes, the limit", CFG_MAX_FILE_BYTES);
            return NULL;
        }
        if (ch == 0) {
            c->err_line = c->line + 1;
            snprintf(c->err, sizeof c->err, "a NUL byte: not a text file");
            return NULL;
        }
        str[len++] = (char)ch;
        if (ch == '\n') break;
    }
    if (len == 0) return NULL;
    str[len] = 0;
    c->line++;
    if (ch != '\n' && len == num - 1) {
        ch = getc(c->fp);                  /* a line of exactly num - 1 characters? */
        if (ch != EOF && ch != '\n') {
            c->err_line = c->line;
            snprintf(c->err, sizeof c->err, "line longer than %d characters (the INI reader's limit)", num - 1);
            return NULL;
        }
    }
    return str;
}

static int file_handler(void *user, const char *section, const char *name, const char *value)
{
    file_ctx *c = user;
    if (c->err_line) return 0; /* keep the first error; apply nothing after it */
    if (!name) return 1;
    /* Before any [section] the flat form "tune.threads = 4" is allowed. */
    if (section && section[0]) {
        if (set_parts(c->E, CFG_SCOPE_FILE, section, name, value ? value : "") == 0) return 1;
    } else if (cfg_set(c->E, CFG_SCOPE_FILE, name, value ? value : "") == 0) {
        return 1;
    }
    c->err_line = c->line;
    memcpy(c->err, c->E->err, sizeof c->err);
    return 0;
}

/* The line a value of the file came from, for its origin in `set`. */
static int file_handler_at(void *user, const char *section, const char *name, const char *value)
{
    file_ctx *c = user;
    c->E->cfg->file_line = c->line;
    return file_handler(user, section, name, value);
}

/* The null device: "no settings", as `--config /dev/null` is often meant. */
static int is_null_device(const struct stat *st)
{
    struct stat null;
    return S_ISCHR(st->st_mode) && stat("/dev/null", &null) == 0 && S_ISCHR(null.st_mode) &&
           st->st_rdev == null.st_rdev;
}

/* The config file, if it is a regular file of at most CFG_MAX_FILE_BYTES
 * (or the null device): a directory, fifo or other device is refused before
 * a byte is read (util_open_input: a fifo cannot hang the open). */
static FILE *open_config(silc_engine *E, const char *path)
{
    struct stat st;
    FILE *fp;
    int fd = util_open_input(path);
    if (fd < 0) {
        eng_error(E, "cannot read config file %s: %s", path, strerror(errno));
        return NULL;
    }
    if (fstat(fd, &st) != 0 || !(S_ISREG(st.st_mode) || is_null_device(&st))) {
        eng_error(E, "config file %s is not a regular file", path);
    } else if (st.st_size > CFG_MAX_FILE_BYTES) {
        eng_error(E, "config file %s is %lld bytes, over the limit of %ld", path,
                  (long long)st.st_size, CFG_MAX_FILE_BYTES);
    } else if ((fp = fdopen(fd, "r"))) {
        return fp;
    } else {
        eng_error(E, "cannot read config file %s: %s", path, strerror(errno));
    }
    close(fd);
    return NULL;
}

int cfg_load_file(silc_engine *E, const char *path)
{
    file_ctx c;
    int rc;
    memset(&c, 0, sizeof c);
    c.E = E;
    c.path = path;
    if (!(c.fp = open_config(E, path))) return -1;
    E->cfg->file = path;
    rc = ini_parse_stream(file_reader, &c, file_handler_at, &c);
    E->cfg->file = NULL;
    fclose(c.fp);
    if (rc < 0) return eng_error(E, "%s: out of memory reading the config file", path);
    /* the first error wins: inih's syntax errors are numbered as ours */
    if (c.err_line && (rc == 0 || rc == c.err_line))
        return eng_error(E, "%s:%d: %s", path, c.err_line, c.err);
    if (rc == 0) return 0;
    return eng_error(E, "%s:%d: syntax error (expected '[section]' or 'key = value')", path, rc);
}

/* ---- a silcd session's files ------------------------------------------------- */

int cfg_serve(silc_engine *E, const char *data_dir, int shared, unsigned long session_id)
{
    int root, dir;
    char name[64];
    E->cfg->serving = 1;
    if (!data_dir) return 0;
    /* The operator's own path: resolved as the operating system does. */
    if ((root = open(data_dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC)) < 0)
        return eng_error(E, "silcd --data-dir %s: %s", data_dir, strerror(errno));
    if (shared) {
        E->cfg->data_fd = root;
        return 0;
    }
    snprintf(name, sizeof name, "session-%lu", session_id);
    /* Every rank of silcd --mpi makes it: the first one wins, the rest find it. */
    if (mkdirat(root, name, 0700) && errno != EEXIST) {
        int e = errno;
        close(root);
        return eng_error(E, "silcd --data-dir %s: cannot create %s: %s", data_dir, name, strerror(e));
    }
    dir = openat(root, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    close(root);
    if (dir < 0) return eng_error(E, "silcd --data-dir %s: cannot open %s: %s", data_dir, name, strerror(errno));
    E->cfg->data_fd = dir;
    return 0;
}

int cfg_serving(const silc_engine *E)
{
    if (!E || !E->cfg || !E->cfg->serving) return 0;
    return E->cfg->data_fd >= 0 ? 2 : 1;
}

/* The folder and name of the file a statement names: beneath the session's
 * folder in silcd, as the operating system resolves it when embedded (or
 * when the operator named it: trusted). */
static int file_place(silc_engine *E, const char *what, const char *path, int trusted, int writing,
                      cfg_file *f)
{
    char why[256];
    f->fd = f->dirfd = -1;
    f->tmp[0] = '\0';
    if (!path || !*path) return eng_error(E, "%s: no file name", what);
    if (trusted || !E->cfg->serving) {
        if ((f->dirfd = util_dir_of(path, f->leaf, sizeof f->leaf)) < 0)
            return eng_error(E, "%s: cannot %s '%s': %s", what, writing ? "create" : "read", path,
                             strerror(errno));
        return 0;
    }
    if (E->cfg->data_fd < 0)
        return eng_error(E, "%s: this silcd keeps no files for sessions (the operator enables them with "
                            "silcd --data-dir DIR)", what);
    if ((f->dirfd = util_dir_beneath(E->cfg->data_fd, path, f->leaf, sizeof f->leaf, why, sizeof why)) < 0)
        return eng_error(E, "%s: '%s' is refused: %s (files are named relative to the session's folder "
                            "under silcd's --data-dir)", what, path, why);
    return 0;
}

int cfg_file_read(silc_engine *E, const char *what, const char *path, cfg_file *f)
{
    if (file_place(E, what, path, 0, 0, f)) return -1;
    /* embedded, a link is the user's own: followed, as the OS would */
    if ((f->fd = util_open_read_at(f->dirfd, f->leaf, !E->cfg->serving)) < 0) {
        int e = errno;
        cfg_file_close(f);
        if (e == ELOOP && E->cfg->serving)
            return eng_error(E, "%s: '%s' is refused: %s (files are named relative to the session's "
                                "folder under silcd's --data-dir)", what, path, UTIL_WHY_SYMLINK);
        if (e == EMLINK)
            return eng_error(E, "%s: '%s' is refused: it has other hard links, which could lead out of "
                                "silcd's --data-dir", what, path);
        if (e == EINVAL) return eng_error(E, "%s: '%s' is not a regular file", what, path);
        return eng_error(E, "%s: cannot read '%s': %s", what, path, strerror(e));
    }
    return 0;
}

static int file_write(silc_engine *E, const char *what, const char *path, int trusted, cfg_file *f)
{
    if (file_place(E, what, path, trusted, 1, f)) return -1;
    if ((f->fd = util_tmp_create(f->dirfd, f->leaf, f->tmp, sizeof f->tmp)) < 0) {
        int e = errno;
        f->tmp[0] = '\0';
        cfg_file_close(f);
        return eng_error(E, "%s: cannot create '%s': %s", what, path, strerror(e));
    }
    return 0;
}

int cfg_file_write(silc_engine *E, const char *what, const char *path, cfg_file *f)
{
    return file_write(E, what, path, 0, f);
}

int cfg_file_write_operator(silc_engine *E, const char *what, const char *path, cfg_file *f)
{
    return file_write(E, what, path, 1, f);
}

int cfg_file_commit(silc_engine *E, const char *what, const char *path, cfg_file *f)
{
    int rc = 0;
    if (f->fd >= 0 && close(f->fd)) rc = eng_error(E, "%s: writing '%s' failed: %s", what, path, strerror(errno));
    f->fd = -1;
    /* rename replaces whatever is at the name, a symbolic link included,
     * and never writes through it */
    if (!rc && renameat(f->dirfd, f->tmp, f->dirfd, f->leaf))
        rc = eng_error(E, "%s: cannot replace '%s': %s", what, path, strerror(errno));
    else if (!rc)
        f->tmp[0] = '\0';
    cfg_file_close(f);
    return rc;
}

void cfg_file_close(cfg_file *f)
{
    if (f->fd >= 0) close(f->fd);
    if (f->tmp[0] && f->dirfd >= 0) unlinkat(f->dirfd, f->tmp, 0);
    if (f->dirfd >= 0) close(f->dirfd);
    f->fd = f->dirfd = -1;
    f->tmp[0] = '\0';
}
