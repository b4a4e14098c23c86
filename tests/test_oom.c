/*
 * test_oom.c -- every allocation failure is survivable (issue 14, "faults
 * lose nothing that was promised"), checked the way SQLite's OOM loops do.
 *
 * The program links silc_failalloc, the engine compiled with
 * failalloc/failalloc.h, where failalloc_arm(n) makes the n-th allocation of
 * the engine from then on return NULL.  For each case below (a statement on
 * a fixture, or a call of the C API) it first runs the case with nothing
 * failing, to learn its result and how many allocations it makes (K), and
 * then, for n = 1 .. K, on a fresh context holding the fixture:
 *
 *   snapshot the store, arm fail-at-n, run the case, disarm, and then
 *   - if the case failed: its message contains "out of memory" (a message
 *     about something else is wrong: an allocation failure must never turn
 *     into a different error; when the fault-free run fails too, its own
 *     message is also accepted) and the store (every name, every value's
 *     bits, the `set` listing) is exactly the snapshot -- or, for a text
 *     whose statements run one after another (`a; b`, loop bodies), exactly
 *     one of the states listed with the case, since the statements before
 *     the failing one stay done;
 *   - if it succeeded although an allocation failed (the engine may absorb
 *     a failure, e.g. of a cache), everything is as in the fault-free run:
 *     store, printed output (less wall times) and warnings;
 *   - the context still works (a small statement and its result).
 * n = K + 1 must then succeed with nothing failed, as the fault-free run.
 *
 * Every case runs twice: with transient failures (only the n-th allocation
 * fails), the harder case for cleanup paths, which must go on after a
 * failure, and with persistent ones (every allocation from the n-th on
 * fails); --transient or --persistent runs one, a further argument only the
 * cases whose text contains it, --verbose names the absorbed failures.  Run under ASan (SILC_SANITIZE)
 * the same loop finds the leaks of the error paths.
 *
 * Only the built-in reference plugin loads (the library is built with plugin
 * directories that do not exist) and the array pool is off, so every array
 * comes from the counted allocator and the counts do not change run to run.
 * The cases are a representative set, not all of test_lang: each kind of
 * statement (arithmetic, sparse/dense/band products and solves, the
 * builtins that build values, subscripts and sub-block assignment,
 * concatenation, in-place updates, control flow, the keyword statements)
 * and each API call: 96 cases, 3461 injection points per mode, which take
 * 0.4 s (both modes) plain and about 2 s under ASan on two cores.
 */
#define _POSIX_C_SOURCE 200809L /* setenv */
#include "check.h"
#include "lang_fixture.h"

#define FAILALLOC_NO_MACROS
#include <failalloc.h>
#include <silc.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct oom_case {
    const char *text;   /* the statements, or what the API call does */
    /* An API case: runs armed on the fixture's context c; returns its rc and
     * leaves the message in msg. */
    int (*api)(silc_context *c, char *msg, size_t len);
    /* Stores a failure may also leave: texts run on the fixture, '|'
     * separated (states after some statements of text ran). */
    const char *states;
} oom_case;

/* ---- API cases ------------------------------------------------------------ */

static int api_open(silc_context *c, char *msg, size_t len)
{
    silc_context *d = NULL;
    int rc = silc_open(&d, NULL);
    (void)c;
    if (rc) snprintf(msg, len, "%s", d ? silc_context_errmsg(d) : silc_errmsg());
    silc_close(&d);
    return rc;
}

/* Puts e under name, where made is what e's constructor returned (a failed
 * constructor's message is the library's, a failed put's the context's). */
static int put_made(silc_context *c, const char *name, int made, silc_envelope_t *e, char *msg,
                    size_t len)
{
    int rc;
    if (made) {
        snprintf(msg, len, "%s", silc_errmsg());
        return made;
    }
    rc = silc_put(c, name, e);
    silc_envelope_free(e);
    if (rc) snprintf(msg, len, "%s", silc_context_errmsg(c));
    return rc;
}

static int api_put_dense_new(silc_context *c, char *msg, size_t len)
{
    static const double x[] = {1, 2, 3, 4, 5, 6};
    silc_envelope_t e;
    return put_made(c, "x", silc_envelope_dense(&e, 3, 2, x), &e, msg, len);
}

static int api_put_dense_over(silc_context *c, char *msg, size_t len)
{
    static const double x[] = {7, 8, 9};
    silc_envelope_t e;
    /* rebinding: on failure v keeps its value */
    return put_made(c, "v", silc_envelope_dense(&e, 3, 1, x), &e, msg, len);
}

static int api_put_csr(silc_context *c, char *msg, size_t len)
{
    /* unsorted columns: the constructor sorts them */
    static const int64_t rp[] = {0, 2, 3, 5}, ci[] = {2, 0, 1, 2, 0};
    static const double vals[] = {1, 2, 3, 4, 5};
    silc_envelope_t e;
    return put_made(c, "S", silc_envelope_csr(&e, 3, 3, rp, ci, vals), &e, msg, len);
}

static int api_put_band(silc_context *c, char *msg, size_t len)
{
    static const double bb[] = {0, 4, 1, 1, 4, 1, 1, 4, 0};
    silc_envelope_t e;
    return put_made(c, "y", silc_envelope_band(&e, 3, 3, 1, 1, bb), &e, msg, len);
}

static int api_get(silc_context *c, const char *name, char *msg, size_t len)
{
    silc_envelope_t e;
    int rc = silc_get(c, &e, name);
    if (rc) {
        snprintf(msg, len, "%s", silc_context_errmsg(c));
        CHECK(e.values == NULL && e.rowptr == NULL && e.colind == NULL,
              "a failed silc_get of '%s' left arrays in the envelope", name);
    }
    silc_envelope_free(&e);
    return rc;
}

static int api_get_dense(silc_context *c, char *msg, size_t len)
{
    return api_get(c, "A", msg, len);
}

static int api_get_csr(silc_context *c, char *msg, size_t len)
{
    return api_get(c, "S", msg, len);
}

static int api_get_band(silc_context *c, char *msg, size_t len)
{
    return api_get(c, "B", msg, len);
}

static int api_mm(const char *file, char *msg, size_t len)
{
    silc_envelope_t e;
    char err[1024];
    int rc = silc_mm_read(&e, file, err, sizeof err);
    if (rc) {
        snprintf(msg, len, "%s", err);
        CHECK(e.values == NULL && e.rowptr == NULL && e.colind == NULL,
              "a failed silc_mm_read of %s left arrays in the envelope", file);
    }
    silc_envelope_free(&e);
    return rc;
}

static int api_mm_coordinate(silc_context *c, char *msg, size_t len)
{
    (void)c;
    return api_mm(SILC_TEST_DATA "/inputs/Su.mtx", msg, len);
}

static int api_mm_array(silc_context *c, char *msg, size_t len)
{
    (void)c;
    return api_mm(SILC_TEST_DATA "/inputs/A.mtx", msg, len);
}

#define STMT(text) {text, NULL, NULL}
#define MULTI(text, states) {text, NULL, states}
#define API(text, fn) {text, fn, NULL}

static const oom_case cases[] = {
    /* arithmetic and products: dense, sparse, band */
    STMT("x = 1 + 2 * 3"),
    STMT("x = 2 * v + 1"),
    STMT("x = v' * w"),
    STMT("x = M * M"),
    STMT("x = A' * A"),
    STMT("x = S * v"),
    STMT("x = S ^ 2"),
    STMT("x = B * v"),
    STMT("x = v *@ w - v ^@ 2"),
    STMT("x = M ^ 3"),
    STMT("x = S' + S - 2 * S"),
    STMT("x = S *@ S"),
    STMT("x = ones(1, 3) * S"),
    STMT("x = B' * B"),
    STMT("x = -M' + trans(M)"),
    STMT("x = v > 1 || !v"),
    STMT("x = 2 ^@ v + abs(-v) + sqrt(v) + exp(v) + log(v) + sin(v) + cos(v)"),
    /* solves through the reference plugin */
    STMT("x = M \\ v[1:2]"),
    STMT("x = D \\ v"),
    STMT("x = L \\ v"),
    STMT("x = S \\ (S * v)"),
    STMT("x = B \\ ones(3, 1)"),
    STMT("x = r / D"),
    STMT("x = M / M"),
    STMT("x = S \\ [v, w]"),
    STMT("x = B \\ [v, w]"),
    STMT("x = A' \\ v"),
    STMT("x = A \\ v"),
    STMT("x = sparse(A) \\ v"),
    STMT("x = solve(D, v, \"backend = reference\")"),
    STMT("x = [1, 1; 1, 1 + 1e-15] \\ [1; 1]"),
    /* builtins that build values */
    STMT("x = zeros(2, 3) + ones(2, 1) * r[1:3]"),
    STMT("x = eye(3)"),
    STMT("x = rand(2, 3)"),
    STMT("x = sparse(idx, idx, 5, 3, 3)"),
    STMT("x = sparse(M)"),
    STMT("x = dense(S)"),
    STMT("x = band(S, 1, 1)"),
    STMT("x = diag(v)"),
    STMT("x = diagvec(S)"),
    STMT("x = sum(S) + sum(M)[1]"),
    STMT("x = norm(S, 1) + norm(M, \"fro\") + norm(v)"),
    STMT("x = max(M)"),
    STMT("x = max(v, 2) + min(v, w) + dot(v, w)"),
    STMT("x = sparse(v, v, w, 3, 3)"),
    STMT("x = band(M, 1, 1)"),
    STMT("x = dense(B)"),
    STMT("x = nnz(B) + size(A, 2)"),
    /* subscripts and assignment into blocks */
    STMT("x = A[2:3, 3:4]"),
    STMT("x = S[1:2, 2:3]"),
    STMT("x = A[idx, idx]"),
    STMT("x = v[end] + S[5] + A[:, end][2]"),
    STMT("x = B[:, 2]"),
    STMT("x = S'[2, :]"),
    STMT("v[2] = 9"),
    STMT("S[1, 3] = 7"),
    STMT("B[1, 2] = 5"),
    STMT("A[:, 2] = ones(3, 1)"),
    STMT("S[2, :] = 0"),
    STMT("S[1:2, 1:2] = M"),
    STMT("B[1, 3] = 5"),
    STMT("v[idx] = w[1:2]"),
    /* concatenation */
    STMT("x = [M, idx; idx', s]"),
    STMT("x = [S, v; v', 1]"),
    STMT("x = [[], 5; B, v]"),
    /* updates in place */
    STMT("v += w"),
    STMT("v -= 2 * w"),
    STMT("v = v - w"),
    STMT("M *= M"),
    STMT("v /= 2"),
    STMT("S += S"),
    /* control flow */
    STMT("if (s > 3) { x = v } else { x = w }"),
    MULTI("k = 0; while (k < 2) { k += 1; v += w }",
          "k = 0|k = 1|k = 1; v += w|k = 2; v += w|k = 2; v += w; v += w"),
    /* keyword statements */
    MULTI("x = 0; while (1) { x += 1; if (x >= 2) { break } }", "x = 0|x = 1|x = 2"),
    MULTI("x = rand(3); y = size(x)", "x = rand(3)"),
    STMT("who"),
    STMT("info S"),
    MULTI("x = S \\ v; info x", "x = S \\ v"),
    STMT("explain x = S \\ v"),
    STMT("explain x = [M, idx] * v[1:2]"),
    STMT("set dispatch.solve.dense = reference"),
    STMT("set"),
    STMT("clear v"),
    STMT("clear"),
    /* errors, whose messages allocate too */
    STMT("x = vv + 1"),
    STMT("x = v + M"),
    /* the C API */
    API("silc_open", api_open),
    API("silc_envelope_dense + silc_put of a new name", api_put_dense_new),
    API("silc_envelope_dense + silc_put over 'v'", api_put_dense_over),
    API("silc_envelope_csr + silc_put over 'S'", api_put_csr),
    API("silc_envelope_band + silc_put", api_put_band),
    API("silc_get dense", api_get_dense),
    API("silc_get csr", api_get_csr),
    API("silc_get band", api_get_band),
    API("silc_mm_read coordinate", api_mm_coordinate),
    API("silc_mm_read array", api_mm_array),
};

/* ---- the fixture, as test_lang.c's operands ------------------------------------ */

static char captured[1 << 14];

static void capture(void *user, const char *text)
{
    (void)user;
    strncat(captured, text, sizeof captured - strlen(captured) - 1);
}

static silc_context *fixture(void)
{
    silc_context *c = NULL;
    if (silc_open(&c, NULL)) {
        CHECK(0, "silc_open: %s", c ? silc_context_errmsg(c) : silc_errmsg());
        return NULL;
    }
    silc_set_output(c, capture, NULL);
    /* Every owed condition estimate made when read: under the default
     * (auto) the choice follows the solve's timings, and with it the count
     * of allocations, which this test replays. */
    if (silc_exec(c, "set accuracy.condest = on_request") || lang_fixture_put(c)) {
        CHECK(0, "fixture: %s", silc_context_errmsg(c));
        silc_close(&c);
    }
    return c;
}

/* ---- snapshots ---------------------------------------------------------------- */

#define MAX_NAMES 32

/* Everything a statement could change: the names (`who`), each value's
 * bits, and the settings (`set`). */
typedef struct snapshot {
    char who[4096], set[4096];
    char names[MAX_NAMES][32];
    silc_envelope_t vals[MAX_NAMES];
    int n;
} snapshot;

static void snapshot_take(silc_context *c, snapshot *s)
{
    const char *p;
    memset(s, 0, sizeof *s);
    captured[0] = 0;
    CHECK(silc_exec(c, "who") == 0, "who: %s", silc_context_errmsg(c));
    snprintf(s->who, sizeof s->who, "%s", captured);
    captured[0] = 0;
    CHECK(silc_exec(c, "set") == 0, "set: %s", silc_context_errmsg(c));
    snprintf(s->set, sizeof s->set, "%s", captured);
    captured[0] = 0;
    /* the names: the first word of each line of `who` after its heading */
    p = strchr(s->who, '\n');
    if (!strncmp(s->who, "no variables", 12)) p = NULL;
    while (p && p[1] && s->n < MAX_NAMES) {
        size_t len = strcspn(p + 1, " \n");
        snprintf(s->names[s->n], sizeof s->names[0], "%.*s", (int)len, p + 1);
        CHECK(silc_get(c, &s->vals[s->n], s->names[s->n]) == 0, "get %s: %s", s->names[s->n],
              silc_context_errmsg(c));
        s->n++;
        p = strchr(p + 1, '\n');
    }
}

static void snapshot_free(snapshot *s)
{
    int i;
    for (i = 0; i < s->n; i++) silc_envelope_free(&s->vals[i]);
    s->n = 0;
}

static int same_envelope(const silc_envelope_t *a, const silc_envelope_t *b)
{
    size_t nv = (size_t)a->nnz;
    if (a->format != b->format || a->m != b->m || a->n != b->n || a->nnz != b->nnz || a->kl != b->kl ||
        a->ku != b->ku)
        return 0;
    if (nv && memcmp(a->values, b->values, nv * sizeof(double))) return 0;
    if (a->format == SILC_CSR && (memcmp(a->rowptr, b->rowptr, (size_t)(a->m + 1) * sizeof(int64_t)) ||
                                  (nv && memcmp(a->colind, b->colind, nv * sizeof(int64_t)))))
        return 0;
    return 1;
}

/* NULL if a and b hold the same store, else what differs. */
static const char *snapshot_diff(const snapshot *a, const snapshot *b)
{
    static char why[128];
    int i;
    if (strcmp(a->who, b->who)) return "the names or shapes";
    if (strcmp(a->set, b->set)) return "the settings";
    for (i = 0; i < a->n; i++)
        if (!same_envelope(&a->vals[i], &b->vals[i])) {
            snprintf(why, sizeof why, "the value of '%s'", a->names[i]);
            return why;
        }
    return NULL;
}

/* The output less its lines holding wall times, which differ run to run. */
static void timeless(char *out, size_t len, const char *text)
{
    out[0] = 0;
    while (*text) {
        size_t n = strcspn(text, "\n");
        if (text[n] == '\n') n++;
        if (!(strstr(text, "time:") && strstr(text, "time:") < text + n))
            strncat(out, text, n < len - strlen(out) - 1 ? n : len - strlen(out) - 1);
        text += n;
    }
}

/* ---- running a case ----------------------------------------------------------- */

typedef struct outcome {
    int rc;
    long allocs, failures;
    char msg[4096], out[1 << 14], warnings[1024];
} outcome;

static int persistent, verbose;

/* Runs case t on c, failing allocation n (0: none). */
static void run_armed(const oom_case *t, silc_context *c, long n, outcome *o)
{
    captured[0] = 0;
    o->msg[0] = 0;
    failalloc_arm(n ? n : -1, n ? persistent : 0);
    if (t->api) {
        o->rc = t->api(c, o->msg, sizeof o->msg);
    } else {
        o->rc = silc_exec(c, t->text);
        if (o->rc) snprintf(o->msg, sizeof o->msg, "%s", silc_context_errmsg(c));
    }
    o->allocs = failalloc_disarm();
    o->failures = failalloc_failures();
    timeless(o->out, sizeof o->out, captured);
    snprintf(o->warnings, sizeof o->warnings, "%s", silc_context_warnings(c));
    captured[0] = 0;
}

/* The context still computes. */
static void check_alive(silc_context *c, const char *text, long n)
{
    silc_envelope_t e;
    double x = 0;
    int ok = silc_exec(c, "chk_ = sum(ones(3, 1)) * 2") == 0 && silc_get(c, &e, "chk_") == 0;
    if (ok) {
        ok = e.m == 1 && e.n == 1 && silc_envelope_to_dense(&e, &x) == 0 && x == 6;
        silc_envelope_free(&e);
    }
    CHECK(ok, "[%s] fail at %ld: context unusable afterwards: %s", text, n, silc_context_errmsg(c));
}

static long total_points, total_failed_runs, total_absorbed;

static void run_case(const oom_case *t)
{
    snapshot before, after, ref_after, *states = NULL;
    outcome *ref = calloc(1, sizeof *ref), *o = calloc(1, sizeof *o);
    silc_context *c;
    int nstates = 0, i;
    long n, absorbed = 0;
    if (!ref || !o) {
        CHECK(0, "test out of memory");
        free(ref);
        free(o);
        return;
    }
    /* the fault-free run: result and allocation count */
    if (!(c = fixture())) goto done;
    snapshot_take(c, &before);   /* as below: its `who` makes the parse cache */
    snapshot_free(&before);
    run_armed(t, c, 0, ref);
    snapshot_take(c, &ref_after);
    silc_close(&c);
    CHECK(ref->failures == 0, "[%s] failed an allocation unarmed", t->text);
    /* the other stores a failure may leave */
    if (t->states) {
        const char *p = t->states;
        states = calloc(16, sizeof *states);
        while (states && *p && nstates < 16) {
            char text[256];
            size_t len = strcspn(p, "|");
            snprintf(text, sizeof text, "%.*s", (int)len, p);
            if ((c = fixture())) {
                CHECK(silc_exec(c, text) == 0, "state '%s': %s", text, silc_context_errmsg(c));
                snapshot_take(c, &states[nstates++]);
                silc_close(&c);
            }
            p += len + (p[len] == '|');
        }
    }
    for (n = 1; n <= ref->allocs + 1; n++) {
        const char *diff;
        if (!(c = fixture())) break;
        snapshot_take(c, &before);
        run_armed(t, c, n, o);
        snapshot_take(c, &after);
        total_points++;
        if (o->failures == 0) {
            /* past the last allocation: as the fault-free run */
            CHECK(n == ref->allocs + 1 && o->allocs == ref->allocs,
                  "[%s] fail at %ld: no allocation failed (%ld made, %ld unarmed)", t->text, n, o->allocs,
                  ref->allocs);
            CHECK(o->rc == ref->rc && !strcmp(o->msg, ref->msg) && !snapshot_diff(&after, &ref_after),
                  "[%s] unarmed again: not as the first run", t->text);
        } else if (o->rc) {
            total_failed_runs++;
            CHECK(strstr(o->msg, "out of memory") || (ref->rc && !strcmp(o->msg, ref->msg)),
                  "[%s] fail at %ld: message \"%s\" does not say out of memory", t->text, n, o->msg);
            diff = snapshot_diff(&before, &after);
            for (i = 0; diff && i < nstates; i++)
                if (!snapshot_diff(&states[i], &after)) diff = NULL;
            CHECK(!diff, "[%s] fail at %ld (\"%s\"): %s changed", t->text, n, o->msg, diff);
        } else {
            /* the failure was absorbed: nothing may show it */
            total_absorbed++;
            absorbed++;
            if (verbose) printf("[%s] fail at %ld absorbed\n", t->text, n);
            diff = snapshot_diff(&ref_after, &after);
            CHECK(!diff, "[%s] fail at %ld absorbed, but %s differs from the fault-free run", t->text, n,
                  diff);
            CHECK(!strcmp(o->out, ref->out), "[%s] fail at %ld absorbed, but the output differs:\n%s\nwant\n%s",
                  t->text, n, o->out, ref->out);
            CHECK(!strcmp(o->warnings, ref->warnings),
                  "[%s] fail at %ld absorbed, but the warnings differ: \"%s\", want \"%s\"", t->text, n,
                  o->warnings, ref->warnings);
        }
        check_alive(c, t->text, n);
        snapshot_free(&before);
        snapshot_free(&after);
        silc_close(&c);
        if (o->failures == 0) break;
    }
    printf("%-52.52s %4ld allocations, %ld absorbed\n", t->text, ref->allocs, absorbed);
    snapshot_free(&ref_after);
    for (i = 0; i < nstates; i++) snapshot_free(&states[i]);
    free(states);
done:
    free(ref);
    free(o);
}

int main(int argc, char **argv)
{
    size_t i;
    int mode, first = 0, last = 1;
    const char *only = NULL;
    for (i = 1; i < (size_t)argc; i++) {
        if (!strcmp(argv[i], "--transient")) last = 0;
        else if (!strcmp(argv[i], "--persistent")) first = 1;
        else if (!strcmp(argv[i], "--verbose")) verbose = 1;   /* names the absorbed failures */
        else only = argv[i];   /* runs the cases whose text contains it */
    }
    /* Nothing from outside: no configuration file, no plugins, no server,
     * no array pool (pooled arrays would bypass the counted allocator). */
    unsetenv("SILC_CONFIG");
    unsetenv("SILC_PLUGIN_PATH");
    unsetenv("SILC_SERVER");
    setenv("SILC_ARRAY_POOL", "0", 1);
    for (mode = first; mode <= last; mode++) {
        persistent = mode;
        total_points = total_failed_runs = total_absorbed = 0;
        for (i = 0; i < sizeof cases / sizeof cases[0]; i++)
            if (!only || strstr(cases[i].text, only)) run_case(&cases[i]);
        printf("%ld injection points (%s), %ld ended in out of memory, %ld absorbed\n", total_points,
               persistent ? "persistent" : "transient", total_failed_runs, total_absorbed);
    }
    return check_done();
}
