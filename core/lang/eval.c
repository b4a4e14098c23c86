/*
 * eval.c -- runs parsed statements: the AST cache, expression evaluation,
 * assignment, control flow and the keyword statements (clear, who, set, info,
 * explain, tune).  It also feeds the tuner (tuner.c): each top-level EXEC's
 * text and time, and each solve that ran.
 *
 * Every arithmetic operation becomes a silc_call handed to disp_run(); the
 * core only builds values that are pure structure (literals, zeros, sparse
 * triplets, subscripts).  A statement computes its new value completely
 * before binding it, so a failing statement leaves the store untouched while
 * the earlier statements of the same text stay done.
 *
 * Operands in messages are quoted as the user wrote them when short ("'A'",
 * "'x + y'"), else called "the left operand" / "the right operand".
 */
#include "lang.h"
#include "tune.h"
#include "accuracy.h"
#include "dist.h"

#include <float.h>
#include <stddef.h>
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- AST cache ------------------------------------------------------------ */
/* Keyed by the exact text, so a time loop EXECing the same strings parses each
 * once.  Bounded: when full it is emptied and refills with what is in use. */
#define CACHE_BUCKETS 1024
#define CACHE_MAX 512

typedef struct cache_entry {
    lang_program *prog;
    struct cache_entry *next;
} cache_entry;

/* ---- the profile (core.profile = on, `profile`, silc --profile) ---------------
 * Like PETSc's -log_view: per statement and per plugin call, the count, the
 * time, the bytes handed in and out, the factorizations reused.  Rows are
 * keyed by their text; a bounded table (PROF_ROWS each), whose last row
 * gathers what does not fit. */
#define PROF_ROWS 48

typedef struct prof_row {
    char name[80];
    uint64_t count, reused;
    double seconds, bytes_in, bytes_out;
} prof_row;

typedef struct prof_table {
    prof_row rows[PROF_ROWS];
    size_t n;
} prof_table;

typedef struct lang_cache {
    cache_entry *b[CACHE_BUCKETS];
    size_t count;
    prof_table statements, calls;
    /* core.profile and core.display as of settings generation `generation`
     * (cfg_generation): read once per change of any setting, not by two
     * lookups a statement */
    uint64_t generation;
    int have_flags, profile, display;
} lang_cache;

/* The row named name (made when new; the last row takes the overflow). */
static prof_row *prof_row_of(prof_table *t, const char *name)
{
    size_t i;
    for (i = 0; i < t->n; i++)
        if (!strcmp(t->rows[i].name, name)) return &t->rows[i];
    if (t->n == PROF_ROWS) return &t->rows[PROF_ROWS - 1];
    memset(&t->rows[t->n], 0, sizeof t->rows[0]);
    snprintf(t->rows[t->n].name, sizeof t->rows[0].name, "%s", t->n == PROF_ROWS - 1 ? "(the rest)" : name);
    return &t->rows[t->n++];
}

/* The bytes of a value's arrays. */
static double value_bytes(const silc_value *v)
{
    if (!v) return 0;
    if (v->format == SILC_FMT_CSR)
        return (double)v->nnz * (sizeof(double) + sizeof(silc_index)) + (double)(v->m + 1) * sizeof(silc_index);
    if (v->format == SILC_FMT_BAND) return (double)v->ld * (double)v->n * sizeof(double);
    return (double)v->m * (double)v->n * sizeof(double);
}

static size_t text_hash(const char *s)
{
    size_t h = 2166136261u;
    while (*s) h = (h ^ (unsigned char)*s++) * 16777619u;
    return h % CACHE_BUCKETS;
}

static void cache_empty(lang_cache *c)
{
    size_t i;
    for (i = 0; i < CACHE_BUCKETS; i++) {
        while (c->b[i]) {
            cache_entry *e = c->b[i];
            c->b[i] = e->next;
            ps_free(e->prog);
            free(e);
        }
    }
    c->count = 0;
}

static void cache_free(void *p)
{
    if (!p) return;
    cache_empty(p);
    free(p);
}

/* Parsed program for text, from the cache or freshly parsed (and cached). */
static int program_for(silc_engine *E, const char *text, lang_program **out)
{
    lang_cache *c = E->lang_cache;
    cache_entry *e;
    size_t h = text_hash(text);
    char err[512];
    if (!c) {
        c = calloc(1, sizeof *c);
        if (!c) return eng_oom(E);
        E->lang_cache = c;
        E->lang_cache_free = cache_free;
    }
    for (e = c->b[h]; e; e = e->next) {
        if (!strcmp(e->prog->text, text)) {
            *out = e->prog;
            return 0;
        }
    }
    if (ps_parse(text, out, err, sizeof err)) return eng_error(E, "%s", err);
    if (c->count >= CACHE_MAX) cache_empty(c);
    e = malloc(sizeof *e);
    if (!e) {
        ps_free(*out);
        *out = NULL;
        return eng_oom(E);
    }
    e->prog = *out;
    e->next = c->b[h];
    c->b[h] = e;
    c->count++;
    return 0;
}

/* Whether key is "on" now, from the copy made under the settings' current
 * generation. */
static void read_flags(silc_engine *E, lang_cache *c)
{
    uint64_t g = cfg_generation(E);
    if (c->have_flags && c->generation == g) return;
    const char *p = cfg_get(E, "core.profile"), *d = cfg_get(E, "core.display");
    c->profile = p && !strcmp(p, "on");
    c->display = d && !strcmp(d, "on");
    c->generation = g;
    c->have_flags = 1;
}

/* ---- helpers shared with builtins.c and index.c ---------------------------- */

void ev_shape(const silc_value *v, char *out, size_t outlen)
{
    snprintf(out, outlen, "%lldx%lld", (long long)v->m, (long long)v->n);
}

/* Appends len bytes of s to out (of outlen bytes, *at used), cut as snprintf
 * would cut, and keeps it terminated. */
static void put_bytes(char *out, size_t outlen, size_t *at, const char *s, size_t len)
{
    if (*at + 1 >= outlen) return;
    if (len > outlen - 1 - *at) len = outlen - 1 - *at;
    memcpy(out + *at, s, len);
    *at += len;
    out[*at] = 0;
}

/* Copies and memcpy, not snprintf: every binary operation names its operands
 * for messages it rarely prints, and printf's machinery was a tenth of a
 * statement's fixed cost (docs/overhead.md, issue 30). */
void ev_operand_name(const lang_ev *V, const ast_node *n, int side, char *out, size_t outlen)
{
    size_t len = n->end - n->start, at = 0;
    const char *word = side == 0 ? "the left operand" : side == 1 ? "the right operand" : "the argument";
    if (!outlen) return;
    out[0] = 0;
    if (len < 24) {
        put_bytes(out, outlen, &at, "'", 1);
        put_bytes(out, outlen, &at, V->src + n->start, len);
        put_bytes(out, outlen, &at, "'", 1);
    } else {
        put_bytes(out, outlen, &at, word, strlen(word));
    }
}

static void add_backend(lang_ev *V, const char *name)
{
    size_t len = strlen(name), have = strlen(V->backends);
    const char *p = V->backends;
    if (!name[0]) return;
    while ((p = strstr(p, name)) != NULL) {
        if ((p == V->backends || p[-1] == ' ') && (p[len] == ',' || p[len] == 0)) return;
        p += len;
    }
    if (have + len + 3 > sizeof V->backends) return;
    if (have) strcat(V->backends, ", ");
    strcat(V->backends, name);
}

/* Appends text indented under an explain step. */
static void indent_into(strbuf *b, const char *text)
{
    while (*text) {
        const char *nl = strchr(text, '\n');
        size_t len = nl ? (size_t)(nl - text) : strlen(text);
        sb_printf(b, "     %.*s\n", (int)len, text);
        text += len + (nl ? 1 : 0);
    }
}

/* A plugin call's row of the profile: a solve by its backend, another
 * operation by the class it ran under. */
static void profile_call(lang_ev *V, const silc_call *call, const silc_report *rep, double seconds)
{
    lang_cache *c = V->E->lang_cache;
    char name[80];
    prof_row *r;
    int i;
    if (call->op == SILC_OP_SOLVE)
        snprintf(name, sizeof name, "solve: %s", rep->backend[0] ? rep->backend : "?");
    else
        snprintf(name, sizeof name, "%s", call->op_class ? call->op_class : "operation");
    r = prof_row_of(&c->calls, name);
    r->count++;
    r->seconds += seconds;
    for (i = 0; i < call->nin; i++) r->bytes_in += value_bytes(call->in[i]);
    r->bytes_out += value_bytes(call->out);
    if (call->op == SILC_OP_SOLVE && rep->reused_factor) r->reused++;
}

static silc_value *initial_guess(lang_ev *V, const ast_node *s);

/* A loop running: V->loop is the innermost, each frame on the C stack of
 * its own statement (exec_for, the while), so it is bounded as the
 * parser bounds nesting. */
typedef struct ev_loop {
    const ast_node *stmt;       /* the ST_FOR or ST_WHILE */
    int64_t left;               /* iterations after the running one; -1: unknown (a while) */
    const struct ev_loop *up;
} ev_loop;

/* Why the solve call is expected to be followed by more with the same A
 * (E->solve_again: dispatch.c then starts with a factorization), or NULL:
 * its A is written as a name that a loop around it, which runs again, does
 * not bind (ps_loop_binds: a loop that assigns A gets a new matrix each
 * time, and the one-shot rule stays); or `tune on N` said the run repeats. */
static const char *solve_again(const lang_ev *V, const silc_call *call)
{
    const ev_loop *l;
    const ast_node *a = V->solve_matrix;
    if (call->op != SILC_OP_SOLVE) return NULL;
    if (a && a->kind == AST_NAME)
        for (l = V->loop; l && !ps_loop_binds(l->stmt, a->name); l = l->up)
            if (l->left) return "inside a loop that does not change it";
    return tuner_solve_again(V->E);
}

int ev_run(lang_ev *V, silc_call *call, const char *what, silc_value **out)
{
    silc_engine *E = V->E;
    silc_report rep;
    size_t warned;
    int i, rc;
    double t0;
    *out = NULL;
    call->out = NULL;
    if (call->op == SILC_OP_SOLVE) {
        memset(&rep, 0, sizeof rep);
        rep.cond_est = -1;
        rep.rcond = -1;
        call->report = &rep;
        /* The statement's initial guess goes to the first solve whose
         * solution has its shape (exec_assign, solve.initial_guess); it is
         * looked up at the statement's first solve, so that a statement
         * without one pays no lookups for it. */
        if (V->warm_for) {
            V->warm_held = initial_guess(V, V->warm_for);
            V->warm = V->warm_held;
            V->warm_for = NULL;
        }
        if (V->warm && call->nin == 2 && V->warm->m == call->in[0]->n && V->warm->n == call->in[1]->n) {
            call->in[2] = V->warm;
            call->nin = 3;
            V->warm = NULL;
        }
    }
    if (V->explain) {
        strbuf d;
        char shape[48];
        sb_printf(V->explain_out, "  %d. %s:", ++V->explain_step, what);
        for (i = 0; i < call->nin; i++) {
            ev_shape(call->in[i], shape, sizeof shape);
            sb_printf(V->explain_out, "%s %s %s", i ? "," : "", shape,
                      val_format_name(call->in[i]->format));
        }
        sb_puts(V->explain_out, "\n");
        sb_init(&d);
        dist_explain(E, call, &d);
        E->solve_again = solve_again(V, call);
        rc = disp_explain(E, call, &d);
        E->solve_again = NULL;
        if (rc && strstr(E->err, "out of memory")) { /* not a reason to show, a failure */
            sb_free(&d);
            return -1;
        }
        if (!rc) tuner_explain(E, call, &d);
        indent_into(V->explain_out, rc ? E->err : sb_str(&d));
        if (d.failed) V->explain_out->failed = 1;   /* explain says out of memory */
        sb_free(&d);
        if (call->op == SILC_OP_SOLVE) {
            /* explain runs no solve: later steps see a placeholder of the right shape */
            *out = val_dense_new(call->in[0]->n, call->in[1]->n); /* whole: explain moves nothing */
            return *out ? 0 : eng_oom(E);
        }
    }
    /* The same operation on the same operands as before (memo.c): its value. */
    if ((call->out = memo_lookup(E, call))) {
        *out = call->out;
        return 0;
    }
    /* An interrupt is also asked between plugin calls, so a statement of
     * many operations stops within one of them; on a communicator only
     * after statements, where the ranks agree on it (exec_stmt). */
    if (!E->dist && eng_cancel_check(E)) return -1;
    warned = E->warnings.len;
    /* The evaluator records what a deferred backward error needs (bind). */
    E->accuracy_defer = 1;
    E->solve_again = solve_again(V, call);
    t0 = V->profile ? util_now() : 0;
    rc = E->dist ? dist_run(E, call) : disp_run(E, call);
    E->accuracy_defer = 0;
    E->solve_again = NULL;
    /* ... and right after one: a call that cannot be stopped from inside (a
     * MUMPS or UMFPACK factorization) is followed by nothing more */
    if (!rc && !E->dist && eng_cancel_check(E)) rc = -1;
    if (V->profile && !rc && call->out) profile_call(V, call, &rep, util_now() - t0);
    if (rc || !call->out) {
        if (call->out) val_release(call->out);
        call->out = NULL;
        if (!E->err[0]) eng_error(E, "%s failed (status %d)", what, rc);
        return -1;
    }
    if (call->op == SILC_OP_SOLVE) {
        V->has_solve = 1;
        V->report = rep;
        /* What `info` needs to compute a deferred backward error or
         * condition estimate (disp_condest_resolve) */
        if (rep.backward_error == ACC_DEFERRED || rep.condest_deferred == 1) {
            if (eng_pending_hold(&V->pending, call)) {
                val_release(call->out);
                call->out = NULL;
                return eng_oom(E);
            }
        } else {
            eng_pending_release(&V->pending);
        }
        add_backend(V, rep.backend);
        if (!E->dist) tuner_note_solve(E, call); /* the tuner times one process (issue 18) */
    }
    call->report = NULL;
    memo_note(E, call, call->out, E->warnings.len != warned);
    *out = call->out;
    return 0;
}

int ev_run_op(lang_ev *V, int op, int sub, const silc_value *a, const silc_value *b,
              double alpha, double beta, const char *what, silc_value **out)
{
    silc_call c;
    memset(&c, 0, sizeof c);
    c.op = op;
    c.sub = sub;
    c.nin = b ? 2 : 1;
    c.in[0] = a;
    c.in[1] = b;
    c.alpha = alpha;
    c.beta = beta;
    return ev_run(V, &c, what, out);
}

/* ---- names ------------------------------------------------------------------ */

static int undefined_name(lang_ev *V, const char *name)
{
    const char **names = NULL, **cands;
    size_t n = store_names(&V->E->store, &names), nb = 0, i;
    const char *best;
    while (bi_names[nb]) nb++;
    cands = (n || !V->E->store.count) ? malloc((n + nb + 1) * sizeof *cands) : NULL;
    if (!cands) {
        /* no suggestion: say why there is none */
        free(names);
        return eng_error(V->E, "undefined name '%s' (out of memory looking for a similar name)", name);
    }
    for (i = 0; i < n; i++) cands[i] = names[i];
    for (i = 0; i < nb; i++) cands[n + i] = bi_names[i];
    best = util_closest(name, cands, n + nb);
    if (best)
        eng_error(V->E, "undefined name '%s' (did you mean '%s'?)", name, best);
    else
        eng_error(V->E, "undefined name '%s'", name);
    free(cands);
    free(names);
    return -1;
}

static int eval_name(lang_ev *V, const ast_node *n, silc_value **out)
{
    silc_value *v = store_get(&V->E->store, n->name);
    double x;
    if (v) {
        *out = val_retain(v);
        return 0;
    }
    if (bi_constant(n->name, &x)) {
        *out = val_scalar_new(x);
        return *out ? 0 : eng_oom(V->E);
    }
    /* i and j: the imaginary unit unless a name is bound to them (a loop's
     * `for i = ...` wins, as in Octave) */
    if (!strcmp(n->name, "i") || !strcmp(n->name, "j")) {
        *out = val_scalar_new_complex(0, 1);
        return *out ? 0 : eng_oom(V->E);
    }
    return undefined_name(V, n->name);
}

/* ---- operators ---------------------------------------------------------------- */

static const char *op_text(int op)
{
    switch (op) {
    case TK_PLUS: case TK_PLUSEQ: return "+";
    case TK_MINUS: case TK_MINUSEQ: return "-";
    case TK_STAR: case TK_STAREQ: return "*";
    case TK_SLASH: case TK_SLASHEQ: return "/";
    case TK_BACKSLASH: return "\\";
    case TK_EMUL: return "*@";
    case TK_EDIV: return "/@";
    case TK_CARET: return "^";
    case TK_EPOW: return "^@";
    case TK_EQ: return "==";
    case TK_NE: return "!=";
    case TK_LT: return "<";
    case TK_LE: return "<=";
    case TK_GT: return ">";
    case TK_GE: return ">=";
    case TK_AND: return "&&";
    case TK_OR: return "||";
    default: return "?";
    }
}

static int ewise_sub(int op)
{
    switch (op) {
    case TK_EMUL: return SILC_EW_MUL;
    case TK_EDIV: return SILC_EW_DIV;
    case TK_EPOW: case TK_CARET: return SILC_EW_POW;
    case TK_EQ: return SILC_EW_EQ;
    case TK_NE: return SILC_EW_NE;
    case TK_LT: return SILC_EW_LT;
    case TK_LE: return SILC_EW_LE;
    case TK_GT: return SILC_EW_GT;
    case TK_GE: return SILC_EW_GE;
    case TK_AND: return SILC_EW_AND;
    default: return SILC_EW_OR;
    }
}

/* The operands' names are for messages only: a node's is quoted from the
 * source when a message needs it (operand_name), not for every operation
 * (two copies a statement, 2 % of a small product's fixed cost). */
typedef struct operands {
    const char *lname, *rname;   /* as quoted in messages, or NULL: from lnode, rnode */
    const ast_node *lnode, *rnode;
    char ltext[64], rtext[64];
    const char *what;            /* the operation's source text, for explain */
} operands;

/* The left (side 0) or right operand's name as messages quote it. */
static const char *operand_name(const lang_ev *V, operands *o, int side)
{
    const char **name = side ? &o->rname : &o->lname;
    char *text = side ? o->rtext : o->ltext;
    if (!*name) {
        ev_operand_name(V, side ? o->rnode : o->lnode, side, text, sizeof o->ltext);
        *name = text;
    }
    return *name;
}

static int shape_error(lang_ev *V, const char *fmt_head, int op, operands *o,
                       const silc_value *a, const silc_value *b)
{
    char sa[48], sb[48];
    ev_shape(a, sa, sizeof sa);
    ev_shape(b, sb, sizeof sb);
    return eng_error(V->E, "'%s' %s: %s is %s, %s is %s", op_text(op), fmt_head, operand_name(V, o, 0), sa,
                     operand_name(V, o, 1), sb);
}

static int same_or_scalar(const silc_value *a, const silc_value *b)
{
    return val_is_scalar(a) || val_is_scalar(b) || (a->m == b->m && a->n == b->n);
}

static silc_value *identity_like(const silc_value *a)
{
    int64_t i, n = a->m;
    silc_value *r;
    if (a->format == SILC_FMT_DENSE) {
        r = val_dense_new(n, n);
        if (r)
            for (i = 0; i < n; i++) r->val[i + i * n] = 1.0;
        return r;
    }
    r = val_csr_new(n, n, n);
    if (!r) return NULL;
    for (i = 0; i < n; i++) {
        r->rowptr[i] = i;
        r->colind[i] = i;
        r->val[i] = 1.0;
    }
    r->rowptr[n] = n;
    val_csr_set_nnz(r, n);
    return r;
}

/* A^k for square A and integer k >= 0 by repeated squaring. */
static int matrix_power(lang_ev *V, const silc_value *a, double k, const char *what,
                        silc_value **out)
{
    silc_value *result = NULL, *base = val_retain((silc_value *)a), *t;
    unsigned long long e = (unsigned long long)k;
    if (e == 0) {
        val_release(base);
        *out = identity_like(a);
        return *out ? 0 : eng_oom(V->E);
    }
    while (e) {
        if (e & 1) {
            if (!result) {
                result = val_retain(base);
            } else {
                if (ev_run_op(V, SILC_OP_MATMUL, 0, result, base, 1, 0, what, &t)) goto fail;
                val_release(result);
                result = t;
            }
        }
        e >>= 1;
        if (e) {
            if (ev_run_op(V, SILC_OP_MATMUL, 0, base, base, 1, 0, what, &t)) goto fail;
            val_release(base);
            base = t;
        }
    }
    val_release(base);
    *out = result;
    return 0;
fail:
    val_release(base);
    val_release(result);
    return -1;
}

/* v scaled by the scalar s, complex or real (alpha_imag: ABI 1.8). */
static int run_scale(lang_ev *V, const silc_value *v, double complex s, const char *what, silc_value **out)
{
    silc_call c;
    memset(&c, 0, sizeof c);
    c.op = SILC_OP_SCALE;
    c.nin = 1;
    c.in[0] = v;
    c.alpha = creal(s);
    c.alpha_imag = cimag(s);
    return ev_run(V, &c, what, out);
}

/* 1 / the scalar value v: a real v keeps the real division's bits. */
static double complex reciprocal(const silc_value *v)
{
    return v->field == SILC_FIELD_COMPLEX ? 1.0 / val_get_complex(v, 0, 0) : 1.0 / val_scalar(v);
}

/* a op b for every binary operator. */
static int apply_binary(lang_ev *V, int op, operands *o, const silc_value *a,
                        const silc_value *b, silc_value **out)
{
    silc_engine *E = V->E;
    char sa[48];
    switch (op) {
    case TK_PLUS: case TK_PLUSEQ: case TK_MINUS: case TK_MINUSEQ:
        if (!same_or_scalar(a, b))
            return shape_error(V, "needs operands of the same shape or a scalar", op, o, a, b);
        return ev_run_op(V, SILC_OP_ADD, 0, a, b, 1, (op == TK_PLUS || op == TK_PLUSEQ) ? 1 : -1,
                         o->what, out);
    case TK_STAR: case TK_STAREQ:
        if (val_is_scalar(a)) return run_scale(V, b, val_get_complex(a, 0, 0), o->what, out);
        if (val_is_scalar(b)) return run_scale(V, a, val_get_complex(b, 0, 0), o->what, out);
        if (a->n != b->m) return shape_error(V, "inner dimensions differ", op, o, a, b);
        return ev_run_op(V, SILC_OP_MATMUL, 0, a, b, 1, 0, o->what, out);
    case TK_SLASH: case TK_SLASHEQ: {
        silc_value *at, *bt, *x;
        int rc;
        if (val_is_scalar(b)) return run_scale(V, a, reciprocal(b), o->what, out);
        if (a->n != b->n)
            return shape_error(V, "needs operands with the same number of columns", op, o, a, b);
        /* a / B = (B' \ a')' */
        if (ev_run_op(V, SILC_OP_TRANSPOSE, 0, a, NULL, 0, 0, o->what, &at)) return -1;
        if (ev_run_op(V, SILC_OP_TRANSPOSE, 0, b, NULL, 0, 0, o->what, &bt)) {
            val_release(at);
            return -1;
        }
        rc = ev_run_op(V, SILC_OP_SOLVE, 0, bt, at, 0, 0, o->what, &x);
        val_release(at);
        val_release(bt);
        if (rc) return -1;
        rc = ev_run_op(V, SILC_OP_TRANSPOSE, 0, x, NULL, 0, 0, o->what, out);
        val_release(x);
        return rc;
    }
    case TK_BACKSLASH:
        if (val_is_scalar(a)) return run_scale(V, b, reciprocal(a), o->what, out);
        if (a->m != b->m)
            return shape_error(V, "needs as many rows in the right-hand side", op, o, a, b);
        /* NaN/Inf named by the user's operand text (refine.c; the dispatcher
         * repeats the check with role names for every other route).  A dense
         * A not read yet is checked by the dispatcher, in the one read of A
         * that also copies it for the backend, and named here if refused. */
        {
            int a_later = refine_check_finite_later(V->E, a, b), rc;
            if ((!a_later && refine_check_finite(V->E, a, 1, operand_name(V, o, 0))) ||
                refine_check_finite(V->E, b, 0, operand_name(V, o, 1)))
                return -1;
            rc = ev_run_op(V, SILC_OP_SOLVE, 0, a, b, 0, 0, o->what, out);
            if (rc && a_later && refine_check_finite(V->E, a, 1, operand_name(V, o, 0))) return -1;
            return rc;
        }
    case TK_CARET:
        if (val_is_scalar(a) && val_is_scalar(b))
            return ev_run_op(V, SILC_OP_EWISE, SILC_EW_POW, a, b, 0, 0, o->what, out);
        if (a->m != a->n) {
            ev_shape(a, sa, sizeof sa);
            return eng_error(E, "%s is %s but '^' needs a square matrix", operand_name(V, o, 0), sa);
        }
        if (!val_is_scalar(b)) {
            ev_shape(b, sa, sizeof sa);
            return eng_error(E, "'^' needs a scalar exponent: %s is %s (use '^@' for element-wise powers)",
                             operand_name(V, o, 1), sa);
        }
        {
            double k = val_scalar(b);
            if (!(k >= 0 && k == floor(k) && k < 9.0e15)) {
                char kt[40];
                util_fmt_double(kt, sizeof kt, k);
                return eng_error(E, "'^' of a matrix needs a nonnegative integer exponent, got %s "
                                    "(use '^@' for element-wise powers)", kt);
            }
            return matrix_power(V, a, k, o->what, out);
        }
    default:
        if (!same_or_scalar(a, b))
            return shape_error(V, "needs operands of the same shape or a scalar", op, o, a, b);
        return ev_run_op(V, SILC_OP_EWISE, ewise_sub(op), a, b, 0, 0, o->what, out);
    }
}

static void node_text(const lang_ev *V, const ast_node *n, char *out, size_t outlen)
{
    size_t len = n->end - n->start;
    if (len >= outlen) len = outlen - 1;
    memcpy(out, V->src + n->start, len);
    out[len] = 0;
}

/* Binary node n applied to its operands a and b, already evaluated (and
 * released here). */
UTIL_NOINLINE static int binary_of(lang_ev *V, const ast_node *n, silc_value *a, silc_value *b, silc_value **out)
{
    char what[256];
    operands o;
    int rc;
    node_text(V, n, what, sizeof what);
    o.lname = o.rname = NULL;
    o.lnode = n->kids[0];
    o.rnode = n->kids[1];
    o.what = what;
    V->solve_matrix = n->op == TK_BACKSLASH ? n->kids[0] : NULL;
    rc = apply_binary(V, n->op, &o, a, b, out);
    V->solve_matrix = NULL;
    val_release(a);
    val_release(b);
    return rc;
}

static int eval_binary(lang_ev *V, const ast_node *n, silc_value **out)
{
    silc_value *a, *b;
    if (ev_expr_dist(V, n->kids[0], &a)) return -1;
    /* && and || short-circuit on a scalar left side, so `k <= n && v[k] > 0` is safe */
    if ((n->op == TK_AND || n->op == TK_OR) && val_is_scalar(a)) {
        int truth = val_get_complex(a, 0, 0) != 0;
        if (truth == (n->op == TK_OR)) {
            val_release(a);
            *out = val_scalar_new(truth ? 1.0 : 0.0);
            return *out ? 0 : eng_oom(V->E);
        }
    }
    if (ev_expr_dist(V, n->kids[1], &b)) {
        val_release(a);
        return -1;
    }
    return binary_of(V, n, a, b, out);
}

/* Unary node n applied to its operand a, already evaluated (and released
 * here).  Apart from eval_unary so that the text buffer is not on the stack
 * once per level of the recursion. */
UTIL_NOINLINE static int unary_of(lang_ev *V, const ast_node *n, silc_value *a, silc_value **out)
{
    char what[256];
    int rc;
    node_text(V, n, what, sizeof what);
    if (n->kind == AST_TRANSPOSE) /* sub 0: A' (conjugate), 1: A.' (silc_plugin.h) */
        rc = ev_run_op(V, SILC_OP_TRANSPOSE, n->op == TK_DOTQUOTE ? 1 : 0, a, NULL, 0, 0, what, out);
    else
        rc = ev_run_op(V, SILC_OP_MAP, n->op == TK_NOT ? SILC_MAP_NOT : SILC_MAP_NEG, a, NULL, 0, 0,
                       what, out);
    val_release(a);
    return rc;
}

static int eval_unary(lang_ev *V, const ast_node *n, silc_value **out)
{
    silc_value *a;
    if (ev_expr_dist(V, n->kids[0], &a)) return -1;
    if (n->op == TK_PLUS) {
        *out = a;
        return 0;
    }
    return unary_of(V, n, a, out);
}

/* diagvec(L' * R): entry j is sum_k L(k, j) R(k, j), the column sums of
 * L .* R, so for real L and R of the same shape (m x n, m > 1) it is formed
 * as that, without L' or the n x n product -- for the cloth's
 * sqrt(diagvec(P' * P)), the spring lengths, a transpose and a sparse
 * product a step become an element-wise product and a column sum.  For
 * CSR operands the sums run in the product's order (k ascending), so the
 * bits are the product's; dense ones differ from BLAS's order by rounding.
 * Any other operands (complex, other shapes, scalars) take the general
 * path: the transpose, the product and its diagonal. */
int ev_is_diagvec_of_product(const ast_node *call)
{
    const ast_node *p = call->nkids == 1 ? call->kids[0] : NULL;
    return p && p->kind == AST_BINARY && p->op == TK_STAR && p->kids[0]->kind == AST_TRANSPOSE;
}

int ev_diagvec_of_product(lang_ev *V, const ast_node *call, silc_value **out)
{
    const ast_node *prod = call->kids[0], *tr = prod->kids[0];
    silc_value *l, *r, *e = NULL, *sums = NULL, *p = NULL;
    char what[256];
    int rc;
    *out = NULL;
    if (ev_expr(V, tr->kids[0], &l)) return -1;
    if (ev_expr(V, prod->kids[1], &r)) {
        val_release(l);
        return -1;
    }
    node_text(V, call, what, sizeof what);
    if (l->field != SILC_FIELD_COMPLEX && r->field != SILC_FIELD_COMPLEX && l->m == r->m && l->n == r->n &&
        l->m > 1) {
        rc = ev_run_op(V, SILC_OP_EWISE, SILC_EW_MUL, l, r, 0, 0, what, &e) ||
             ev_run_op(V, SILC_OP_REDUCE, SILC_RED_SUM, e, NULL, 0, 0, what, &sums) ||
             ev_run_op(V, SILC_OP_TRANSPOSE, 1, sums, NULL, 0, 0, what, out);
        val_release(l), val_release(r), val_release(e), val_release(sums);
        return rc ? -1 : 0;
    }
    if (unary_of(V, tr, l, &l)) { /* releases l */
        val_release(r);
        return -1;
    }
    if (binary_of(V, prod, l, r, &p)) return -1; /* releases l and r */
    rc = ev_run_op(V, SILC_OP_DIAG, 1, p, NULL, 0, 0, what, out);
    val_release(p);
    return rc;
}

/* base[subscripts]: the subscripts are evaluated by ix_extract. */
static UTIL_NOINLINE int eval_index(lang_ev *V, const ast_node *n, silc_value **out)
{
    silc_value *base;
    char what[64];
    int rc;
    if (ev_expr(V, n->kids[0], &base)) return -1;
    ev_operand_name(V, n->kids[0], 2, what, sizeof what);
    rc = ix_extract(V, n->kids + 1, n->nkids - 1, what, base, out);
    val_release(base);
    return rc;
}

/* v(i), A(i, j), v(): Octave's subscripts on the variable n names. */
static UTIL_NOINLINE int eval_call_index(lang_ev *V, const ast_node *n, silc_value **out)
{
    silc_value *base;
    char what[80];
    int rc;
    if (eval_name(V, n, &base)) return -1;
    if (dist_make_whole(V->E, &base)) {
        val_release(base);
        return -1;
    }
    if (n->nkids == 0) { /* v() is v, as in Octave */
        *out = base;
        return 0;
    }
    snprintf(what, sizeof what, "'%s'", n->name);
    rc = ix_extract(V, n->kids, n->nkids, what, base, out);
    val_release(base);
    return rc;
}

int ev_expr(lang_ev *V, const ast_node *n, silc_value **out)
{
    if (ev_expr_dist(V, n, out)) return -1;
    if (dist_make_whole(V->E, out)) {
        val_release(*out);
        *out = NULL;
        return -1;
    }
    return 0;
}

/* A distributed 1x1 (a row block of one row, np = 1) is made whole: every
 * consumer of a scalar reads its entry. */
static int scalar_whole(lang_ev *V, int rc, silc_value **out)
{
    if (rc == 0 && dist_is(*out) && val_is_scalar(*out) && dist_make_whole(V->E, out)) {
        val_release(*out);
        *out = NULL;
        return -1;
    }
    return rc;
}

/* ---- ranges ------------------------------------------------------------------- */

/* Octave's tolerant floor (Hagerty's FL5, liboctave Range.cc): x within ct
 * (relative) below an integer counts as that integer, so 0:0.1:1 has 11
 * elements although (1 - 0) / 0.1 is 9.999999999999998. */
static double tolerant_floor(double x, double ct)
{
    double q = x < 0 ? 1 - ct : 1, rmax = q / (2 - ct), t1 = 1 + floor(x);
    t1 = (ct / q) * (t1 < 0 ? -t1 : t1);
    t1 = rmax < t1 ? rmax : t1;
    t1 = ct > t1 ? ct : t1;
    t1 = floor(x + t1);
    return (x <= 0 || t1 - x < rmax) ? t1 : t1 - 1;
}

static int tolerant_equal(double u, double v, double ct)
{
    double tu = fabs(u), tv = fabs(v);
    return fabs(u - v) < (tu > tv ? tu : tv) * ct;
}

/* The elements of base:inc:limit as Octave counts them (its numel and
 * final value): 0 when inc is 0 or points away from limit. */
static double range_count(double base, double inc, double limit)
{
    double ct = 3 * DBL_EPSILON, n;
    if (inc == 0 || (limit > base && inc < 0) || (limit < base && inc > 0)) return 0;
    n = tolerant_floor((limit - base + inc) / inc, ct);
    if (n < 0) n = 0;
    if (n > 0 && !tolerant_equal(base + (n - 1) * inc, limit, ct)) {
        if (n > 1 && tolerant_equal(base + (n - 2) * inc, limit, ct)) n--;
        else if (tolerant_equal(base + n * inc, limit, ct)) n++;
    }
    return n;
}

/* Element k (0-based) of a range of count elements: the last one is held
 * to the limit, and made whole when every element is (Octave's final value). */
static double range_at(double base, double inc, double limit, double count, double k)
{
    double x = base + k * inc;
    if (k > 0 && k == count - 1) {
        if ((inc > 0 && x >= limit) || (inc < 0 && x <= limit)) x = limit;
        if (base == floor(base) && inc == floor(inc)) x = floor(x + 0.5);
    }
    return x;
}

typedef struct range_spec {
    double base, inc, limit, count;
} range_spec;

/* Evaluates the ends (and step) of a range node: each must be a finite scalar. */
static int range_of(lang_ev *V, const ast_node *n, range_spec *r)
{
    double x[3] = {0, 0, 0};
    size_t i;
    for (i = 0; i < n->nkids; i++) {
        silc_value *v;
        if (ev_expr(V, n->kids[i], &v)) return -1;
        if (!val_is_scalar(v)) {
            char shape[48];
            ev_shape(v, shape, sizeof shape);
            val_release(v);
            return eng_error(V->E, "a range's %s must be a scalar, got %s",
                             i == 0 ? "start" : i + 1 == n->nkids ? "end" : "step", shape);
        }
        x[i] = val_scalar(v);
        val_release(v);
        if (!isfinite(x[i]))
            return eng_error(V->E, "a range needs finite ends and step, got %g", x[i]);
    }
    r->base = x[0];
    r->inc = n->nkids == 3 ? x[1] : 1;
    r->limit = x[n->nkids - 1];
    r->count = range_count(r->base, r->inc, r->limit);
    return 0;
}

/* base:inc:limit as a 1xN dense row, as Octave's range is. */
static int eval_range(lang_ev *V, const ast_node *n, silc_value **out)
{
    range_spec r;
    int64_t k, count;
    if (range_of(V, n, &r)) return -1;
    if (val_claim(r.count * sizeof(double), "the range"))
        return eng_error(V->E, "a range of %.4g elements is larger than one value may be", r.count);
    count = (int64_t)r.count;
    if (!(*out = val_dense_new(1, count))) return eng_oom(V->E);
    for (k = 0; k < count; k++) (*out)->val[k] = range_at(r.base, r.inc, r.limit, r.count, (double)k);
    return 0;
}

static int expr_any(lang_ev *V, const ast_node *n, silc_value **out);

int ev_expr_dist(lang_ev *V, const ast_node *n, silc_value **out)
{
    return scalar_whole(V, expr_any(V, n, out), out);
}

static int expr_any(lang_ev *V, const ast_node *n, silc_value **out)
{
    silc_engine *E = V->E;
    *out = NULL;
    switch (n->kind) {
    case AST_NUM:
        *out = n->imag ? val_scalar_new_complex(0, n->num) : val_scalar_new(n->num);
        return *out ? 0 : eng_oom(E);
    case AST_NAME:
        return eval_name(V, n, out);
    case AST_END:
        if (!V->in_subscript)
            return eng_error(E, "'end' here is not inside a subscript (v(end), A(end, :) on a variable)");
        *out = val_scalar_new((double)V->end_value);
        return *out ? 0 : eng_oom(E);
    case AST_STRING:
        return eng_error(E, "a string (\"%s\") is only allowed as an option argument", n->name);
    case AST_COLON_ALL:
        return eng_error(E, "':' alone is only allowed as a subscript (A(:, j) on a variable)");
    case AST_RANGE:
        return eval_range(V, n, out);
    case AST_BINARY:
        return eval_binary(V, n, out);
    case AST_UNARY:
    case AST_TRANSPOSE:
        return eval_unary(V, n, out);
    case AST_INDEX:
        return eval_index(V, n, out);
    case AST_CALL:
        /* v(i) on a variable is a subscript: a variable hides a function of
         * the same name, as in Octave */
        if (store_get(&E->store, n->name)) return eval_call_index(V, n, out);
        return bi_call(V, n, out);
    case AST_MATRIX:
        return cc_matrix(V, n, out);
    default:
        return eng_error(E, "internal error: statement where an expression was expected");
    }
}

/* ---- statements ---------------------------------------------------------------- */

enum { FLOW_NEXT = 0, FLOW_BREAK, FLOW_CONTINUE };

static char *stmt_text(const lang_ev *V, const ast_node *n)
{
    size_t len = n->end - n->start;
    char *s = malloc(len + 1);
    if (s) {
        memcpy(s, V->src + n->start, len);
        s[len] = 0;
    }
    return s;
}

_Static_assert(sizeof ((eng_info *)0)->backends == sizeof ((lang_ev *)0)->backends,
               "bind copies the statement's backends whole");

/* Binds name to v (taking over the caller's reference) and records how it
 * was computed.
 *
 * The record `info` shows is written in place: a loop rebinds a name each
 * step, and building a 1.2 KB record on the stack to copy it over the old
 * one wrote 40 cache lines a statement, which a product that has streamed
 * its matrix through the cache finds evicted (docs/overhead.md, SpMV).  The
 * statement's text goes into the buffer the record holds when it fits (a
 * loop's statement is often the same each time), else into a new one; the
 * report is copied only for a statement that solved (`info` reads it only
 * then: has_solve). */
static int bind(lang_ev *V, const ast_node *stmt, const char *name, silc_value *v, double t0)
{
    size_t len = stmt->end - stmt->start;
    eng_info *rec;
    char *text;
    int rc;
    if (V->explain) {
        char shape[48];
        ev_shape(v, shape, sizeof shape);
        sb_printf(V->explain_out, "  result: %s would be bound to a %s %s value (not run)\n", name,
                  shape, val_format_name(v->format));
        val_release(v);
        return 0;
    }
    /* What can fail is done first, so that running out of memory leaves
     * neither a binding without its record nor a record without its
     * binding: the text, then the record of a new name (rebinding a name
     * allocates nothing more).  (An update in place made both beforehand,
     * bind_reserve, since it cannot be undone.) */
    if (V->E->warnings.failed) {   /* a result without its warning would be trusted */
        val_release(v);
        return eng_error(V->E, "out of memory recording a warning of '%s'", name);
    }
    rec = eng_info_get(V->E, name);
    text = V->bind_text;
    V->bind_text = NULL;
    if (!text && !(rec && rec->statement && strlen(rec->statement) >= len) && !(text = stmt_text(V, stmt))) {
        val_release(v);
        return eng_error(V->E, "out of memory binding '%s'", name);
    }
    if (!rec && !(rec = eng_info_make(V->E, name))) { /* "out of memory recording info for 'x'" */
        free(text);
        val_release(v);
        return -1;
    }
    if (text) {
        free(rec->statement);
        rec->statement = text;
    } else {
        memcpy(rec->statement, V->src + stmt->start, len);
        rec->statement[len] = 0;
    }
    rec->has_solve = V->has_solve;
    if (V->has_solve) rec->report = V->report;
    eng_pending_release(&rec->pending);
    rec->pending = V->pending; /* handed over */
    memset(&V->pending, 0, sizeof V->pending);
    rec->seconds = util_now() - t0;
    memcpy(rec->backends, V->backends, sizeof rec->backends); /* the same size, terminated */
    rec->ranks = 0;
    rec->moved_matrix = rec->moved_vector = 0;
    if (V->E->dist) {
        rec->ranks = V->E->dist->size;
        rec->moved_matrix = V->E->dist->moved_matrix - V->moved0[0];
        rec->moved_vector = V->E->dist->moved_vector - V->moved0[1];
    }
    rc = store_set(&V->E->store, name, v);
    val_release(v);
    if (rc) {
        eng_info_remove(V->E, name);
        return eng_error(V->E, "out of memory binding '%s'", name);
    }
    return 0;
}

/* Makes what bind() allocates for stmt before x changes in place, which
 * cannot be undone: then running out of memory stops the statement while x
 * is still as it was. */
static int bind_reserve(lang_ev *V, const ast_node *stmt)
{
    if (!V->bind_text && !(V->bind_text = stmt_text(V, stmt)))
        return eng_error(V->E, "out of memory binding '%s'", stmt->name);
    return eng_info_make(V->E, stmt->name) ? 0 : -1;
}

static int opassign_token(int op)
{
    switch (op) {
    case TK_PLUSEQ: return TK_PLUS;
    case TK_MINUSEQ: return TK_MINUS;
    case TK_STAREQ: return TK_STAR;
    default: return TK_SLASH;
    }
}

/* Copy-on-write for `x += r`, `x -= r`, `x *= c`, `x /= c` (DESIGN 5): when
 * x's dense value is held by the store's binding alone (two references: the
 * binding's and the caller's) and carries no attachments, nobody else can see it
 * change, so the result is written over it instead of into a new array.  r
 * is a dense array of x's shape or a scalar, c a scalar.  The arithmetic is
 * what SILC_OP_ADD / SCALE compute (1*x + (+-1)*r is x +- r exactly; x / c
 * is a scale by 1/c), so the numbers do not depend on which path ran.
 *
 * With a scale s (a scalar value), `x += s * r` and `x -= s * r` for a
 * dense r of x's shape: the time-stepping update (`u += dt * v`) without
 * the temporary s * r.  Each s * r_i is rounded before it is added, as
 * SILC_OP_SCALE then SILC_OP_ADD round it (no contraction to a fused
 * multiply-add: the build targets x86-64 without FMA, and GCC does not
 * contract across statements in ISO C mode).  Returns 1 when done; under
 * explain, 1 when it would be done, after saying so (stmt: the statement);
 * -1 when out of memory before anything changed. */
static int update_in_place(lang_ev *V, int op, silc_value *x, const silc_value *r,
                           const silc_value *s, const ast_node *stmt)
{
    int64_t i, n = x->m * x->n;
    int scalar = !s && val_is_scalar(r) && !val_is_scalar(x);
    double c = scalar ? val_scalar(r) : 0;
    /* Distributed values are never updated in place: their arrays are blocks (dist.h). */
    /* Nor complex ones: the loop below is real arithmetic. */
    if (x->field || r->field || (s && s->field)) return 0;
    if (x->dist || r->dist || x->format != SILC_FMT_DENSE || x->refcount != 2 || x->attach ||
        !(scalar || (r->format == SILC_FMT_DENSE && r->m == x->m && r->n == x->n)))
        return 0;
    if ((op == TK_STAREQ || op == TK_SLASHEQ) && (!scalar || s)) return 0;
    if (V->explain) {
        char xs[48], rs[48], what[256];
        node_text(V, stmt, what, sizeof what);
        ev_shape(x, xs, sizeof xs);
        ev_shape(r, rs, sizeof rs);
        sb_printf(V->explain_out, "  %d. %s: %s dense, %s %s%s\n", ++V->explain_step, what, xs, rs,
                  val_format_name(r->format), s ? ", 1x1 scale" : "");
        indent_into(V->explain_out, "in place: nothing else holds the value, so the core writes the "
                                    "result over its array (no backend, no new array)");
        return 1;
    }
    if (bind_reserve(V, stmt)) return -1;
    {
        /* r is another value (x += x leaves x shared, so never comes here). */
        double *restrict xv = x->val;
        const double *restrict rv = scalar ? NULL : r->val;
        if (s) {
            double k = val_scalar(s);
            if (op == TK_PLUSEQ) for (i = 0; i < n; i++) xv[i] += k * rv[i];
            else for (i = 0; i < n; i++) xv[i] -= k * rv[i];
        } else if (op == TK_PLUSEQ || op == TK_MINUSEQ) {
            double sign = op == TK_PLUSEQ ? 1 : -1; /* x + (-r) is x - r, bit for bit */
            if (scalar) for (i = 0, c *= sign; i < n; i++) xv[i] += c;
            else if (sign > 0) for (i = 0; i < n; i++) xv[i] += rv[i];
            else for (i = 0; i < n; i++) xv[i] -= rv[i];
        } else {
            c = op == TK_STAREQ ? c : 1.0 / c; /* as apply_binary: x / c is a scale by 1/c */
            for (i = 0; i < n; i++) xv[i] *= c;
        }
    }
    val_mutated(x);
    return 1;
}

/* The operand e of an update of x by op (+= -= *= /=): applied to x in
 * place when update_in_place allows it (returns 1), else its value in *out
 * (returns 0), or -1 on error.  e = s * y with a scalar s is scaled into x
 * without the temporary s * y. */
static int update_operand(lang_ev *V, int op, silc_value *x, const ast_node *stmt, const ast_node *e,
                          silc_value **out)
{
    int rc;
    *out = NULL;
    if ((op == TK_PLUSEQ || op == TK_MINUSEQ) && e->kind == AST_BINARY && e->op == TK_STAR) {
        const silc_value *k;
        silc_value *a, *b;
        if (ev_expr_dist(V, e->kids[0], &a)) return -1;
        if (ev_expr_dist(V, e->kids[1], &b)) {
            val_release(a);
            return -1;
        }
        k = val_is_scalar(a) ? a : val_is_scalar(b) ? b : NULL;
        if (k && (rc = update_in_place(V, op, x, k == a ? b : a, k, stmt)) != 0) {
            val_release(a);
            val_release(b);
            return rc;
        }
        if (binary_of(V, e, a, b, out)) return -1;
    } else if (ev_expr_dist(V, e, out)) {
        return -1;
    }
    if (!(rc = update_in_place(V, op, x, *out, NULL, stmt))) return 0;
    val_release(*out);
    *out = NULL;
    return rc;
}

/* `x = x + e` and `x = x - e` are the updates `x += e` and `x -= e`: the
 * same arithmetic (so the same bits), in place under the same conditions.
 * Returns TK_PLUSEQ / TK_MINUSEQ for such a statement, else 0. */
static int self_update_op(const ast_node *s)
{
    const ast_node *e = s->kids[0];
    if (s->kind != ST_ASSIGN || e->kind != AST_BINARY || (e->op != TK_PLUS && e->op != TK_MINUS) ||
        e->kids[0]->kind != AST_NAME || strcmp(e->kids[0]->name, s->name) != 0)
        return 0;
    return e->op == TK_PLUS ? TK_PLUSEQ : TK_MINUSEQ;
}

/* The previous value of the assignment's target, as the initial guess of
 * its solve (solve.initial_guess): `previous` whenever the target holds a
 * dense value; `auto` (the default) only when this same statement computed
 * it -- a time loop, where the last step's solution is close to this one's;
 * `zero` never.  Iterative backends start from it (direct ones ignore it).
 * explain and distributed engines start from zero. */
static silc_value *initial_guess(lang_ev *V, const ast_node *s)
{
    const char *mode = cfg_get(V->E, "solve.initial_guess");
    silc_value *prev;
    const eng_info *info;
    size_t len = s->end - s->start;
    if (V->explain || V->E->dist || (mode && !strcmp(mode, "zero"))) return NULL;
    prev = store_get(&V->E->store, s->name);
    if (!prev || prev->format != SILC_FMT_DENSE || prev->dist) return NULL;
    if (!mode || !strcmp(mode, "auto")) {
        info = eng_info_get(V->E, s->name);
        if (!info || !info->statement || strlen(info->statement) != len ||
            memcmp(info->statement, V->src + s->start, len))
            return NULL;
    }
    return val_retain(prev);
}

static int exec_assign(lang_ev *V, const ast_node *s, double t0)
{
    silc_value *v = NULL, *cur = NULL, *r;
    char ln[64], what[256];
    operands o;
    int op = s->kind == ST_OPASSIGN ? s->op : self_update_op(s), rc;
    if (s->kind != ST_ASSIGN || op) cur = store_get(&V->E->store, s->name);
    if (s->kind == ST_ASSIGN && !cur) {
        V->warm_for = s; /* ev_run finds the initial guess at the first solve */
        rc = ev_expr_dist(V, s->kids[0], &v);
        V->warm_for = NULL;
        V->warm = NULL;
        val_release(V->warm_held);
        V->warm_held = NULL;
        if (rc) return -1;
        return bind(V, s, s->name, v, t0);
    }
    if (!cur && s->kind == ST_INDEX_ASSIGN) {
        /* q(3) = 1 on a new name makes it, as Octave does: as if q = [] */
        if (!(cur = val_dense_new(0, 0))) return eng_oom(V->E);
    } else {
        if (!cur) return undefined_name(V, s->name);
        val_retain(cur);      /* the rhs may rebind nothing, but stay safe */
    }
    if (op) {
        rc = update_operand(V, op, cur, s, s->kind == ST_OPASSIGN ? s->kids[0] : s->kids[0]->kids[1], &r);
        if (rc < 0) {
            val_release(cur);
            return -1;
        }
        if (rc > 0) return bind(V, s, s->name, cur, t0); /* hands over the reference taken above */
        if (s->kind == ST_ASSIGN) { /* x = x + e, with that expression's wording */
            if (binary_of(V, s->kids[0], cur, r, &v)) return -1;
            return bind(V, s, s->name, v, t0);
        }
    } else if ((s->kind == ST_INDEX_ASSIGN ? ev_expr : ev_expr_dist)(V, s->kids[0], &r)) {
        val_release(cur);
        return -1;
    }
    /* x[i] = r reads and writes x's entries: a whole copy of a distributed x. */
    if (s->kind == ST_INDEX_ASSIGN && dist_make_whole(V->E, &cur)) {
        val_release(cur);
        val_release(r);
        return -1;
    }
    snprintf(ln, sizeof ln, "'%s'", s->name);
    node_text(V, s, what, sizeof what);
    o.lname = ln;
    o.rname = NULL;
    o.lnode = NULL;
    o.rnode = s->kids[0];
    o.what = what;
    if (s->kind == ST_OPASSIGN)
        rc = apply_binary(V, opassign_token(s->op), &o, cur, r, &v);
    else
        rc = ix_assign(V, s->kids + 1, s->nkids - 1, ln, cur, r, &v);
    val_release(cur);
    val_release(r);
    if (rc) return -1;
    return bind(V, s, s->name, v, t0);
}

/* Prints b and frees it, or, when an append to it ran out of memory, prints
 * nothing: a listing cut short would pass for a complete one. */
static int print_whole(silc_engine *E, strbuf *b, const char *what)
{
    int failed = b->failed;
    if (!failed) eng_print(E, sb_str(b));
    sb_free(b);
    return failed ? eng_error(E, "out of memory printing the output of %s", what) : 0;
}

static int exec_who(lang_ev *V)
{
    const char **names = NULL;
    size_t n = store_names(&V->E->store, &names), i, w = 4, sw = 4;
    strbuf b;
    char shape[48];
    sb_init(&b);
    if (n == 0 && V->E->store.count) return eng_error(V->E, "out of memory listing the names");
    if (n == 0) {
        eng_print(V->E, "no variables\n");
        free(names);
        return 0;
    }
    for (i = 0; i < n; i++) {
        silc_value *v = store_get(&V->E->store, names[i]);
        ev_shape(v, shape, sizeof shape);
        if (strlen(names[i]) > w) w = strlen(names[i]);
        if (strlen(shape) > sw) sw = strlen(shape);
    }
    sb_printf(&b, "%-*s  %-*s  %-6s  %s\n", (int)w, "name", (int)sw, "size", "format", "nnz");
    for (i = 0; i < n; i++) {
        silc_value *v = store_get(&V->E->store, names[i]);
        ev_shape(v, shape, sizeof shape);
        sb_printf(&b, "%-*s  %-*s  %-6s  nnz %lld\n", (int)w, names[i], (int)sw, shape,
                  val_format_name(v->format), (long long)val_props_part(v, SILC_PROPS_SHAPE)->nnz);
    }
    free(names);
    return print_whole(V->E, &b, "who");
}

static void clear_name(silc_engine *E, const char *name)
{
    store_remove(&E->store, name);
    eng_info_remove(E, name);
}

static int exec_clear(lang_ev *V, const ast_node *s)
{
    size_t i;
    if (s->nkids == 0) {
        const char **names = NULL;
        size_t n = store_names(&V->E->store, &names);
        for (i = 0; i < n; i++) eng_info_remove(V->E, names[i]);
        free(names);
        store_clear(&V->E->store);
        return 0;
    }
    for (i = 0; i < s->nkids; i++) clear_name(V->E, s->kids[i]->name);
    return 0;
}

static char *trimmed(const char *s, size_t len)
{
    char *r;
    while (len && (*s == ' ' || *s == '\t')) s++, len--;
    while (len && (s[len - 1] == ' ' || s[len - 1] == '\t' || s[len - 1] == '\r')) len--;
    r = malloc(len + 1);
    if (r) {
        memcpy(r, s, len);
        r[len] = 0;
    }
    return r;
}

static int exec_set(lang_ev *V, const ast_node *s)
{
    silc_engine *E = V->E;
    const char *eq;
    char *key, *value;
    int rc;
    if (!s->name) {
        strbuf b;
        sb_init(&b);
        cfg_list(E, &b);
        return print_whole(E, &b, "set");
    }
    eq = strchr(s->name, '=');
    key = trimmed(s->name, eq ? (size_t)(eq - s->name) : strlen(s->name));
    if (!key) return eng_oom(E);
    if (!eq) {
        strbuf b;
        sb_init(&b);
        rc = cfg_show_key(E, key, &b, 0);
        free(key);
        if (rc) {
            sb_free(&b);
            return -1;
        }
        return print_whole(E, &b, "set");
    }
    value = trimmed(eq + 1, strlen(eq + 1));
    if (!value) {
        free(key);
        return eng_oom(E);
    }
    if (!key[0]) rc = eng_error(E, "set needs a key before '=', as in 'set dispatch.solve.dense = lapack'");
    else rc = cfg_set(E, CFG_SCOPE_SESSION, key, value);
    free(key);
    free(value);
    return rc ? -1 : 0;
}

static int exec_info(lang_ev *V, const ast_node *s)
{
    silc_engine *E = V->E;
    silc_value *v = store_get(&E->store, s->name);
    eng_info *in;
    strbuf b;
    char shape[48], num[40];
    if (!v) return undefined_name(V, s->name);
    in = eng_info_get(E, s->name);
    sb_init(&b);
    ev_shape(v, shape, sizeof shape);
    sb_printf(&b, "%s: %s %s, nnz %lld\n", s->name, shape, val_format_name(v->format),
              (long long)val_props_part(v, SILC_PROPS_SHAPE)->nnz);
    if (dist_is(v)) {
        const dist_part *P = v->dist->part;
        sb_printf(&b, "  distributed: rows in %d blocks (rank 0: %lld rows", P->size,
                  (long long)(P->starts[1] - P->starts[0]));
        if (P->size > 1)
            sb_printf(&b, ", rank %d: %lld rows", P->size - 1,
                      (long long)(P->starts[P->size] - P->starts[P->size - 1]));
        sb_puts(&b, ")\n");
    } else if (E->dist) {
        sb_printf(&b, "  whole on each of the %d ranks\n", E->dist->size);
    }
    if (!in) {
        sb_puts(&b, "  deposited by PUT (no statement of this session computed it)\n");
    } else {
        const silc_report *r = &in->report;
        int deferred = in->has_solve && r->backward_error == ACC_DEFERRED;
        char why[96] = "";
        /* An owed condition estimate first: the forward-error bound comes
         * from the residual pass with it (a computed backward error is
         * computed again, to the same bits). */
        if (in->has_solve && r->condest_deferred) disp_condest_why(r, why, sizeof why);
        if (in->has_solve && r->condest_deferred == 1) {
            if (disp_condest_resolve(E, &in->pending, &in->report)) {
                sb_free(&b);
                return -1;
            }
            if (r->cond_est >= 0 && !deferred) {
                double be = r->backward_error;
                acc_pending_resolve(E, &in->pending, &in->report);
                if (!(r->forward_bound >= 0) || r->backward_error < 0) { /* its residual ran out of memory */
                    in->report.backward_error = be;
                    sb_free(&b);
                    return eng_error(E, "out of memory computing the forward error bound");
                }
            }
            else if (!deferred) eng_pending_release(&in->pending);
        }
        if (deferred)
            acc_pending_resolve(E, &in->pending, &in->report);
        sb_printf(&b, "  statement: %s\n", in->statement ? in->statement : "");
        sb_printf(&b, "  wall time: %.3g s\n", in->seconds);
        if (in->ranks)
            sb_printf(&b, "  ranks: %d; moved between ranks by the statement: %llu bytes of matrices, "
                          "%llu bytes of vectors\n", in->ranks, (unsigned long long)in->moved_matrix,
                      (unsigned long long)in->moved_vector);
        if (!in->has_solve) {
            sb_puts(&b, "  no solve in this statement\n");
        } else {
            sb_printf(&b, "  solve: %s\n", r->method[0] ? r->method : "(method not reported)");
            sb_printf(&b, "  backend: %s\n", in->backends[0] ? in->backends : r->backend);
            sb_printf(&b, "  backward error: %.3g%s\n", r->backward_error,
                      !deferred          ? ""
                      : r->reused_factor ? " (computed now: the solve reused a factorization)"
                                         : " (computed now: solve.backward_error = on_request)");
            if (r->backward_error_unrefined >= 0)
                sb_printf(&b, "  refinement: %d step%s, backward error before: %.3g\n",
                          r->refine_steps, r->refine_steps == 1 ? "" : "s",
                          r->backward_error_unrefined);
            if (r->cond_est >= 0) {
                if (r->condest_deferred == DISP_CONDEST_READ)
                    /* the why line holds timings: "time:" marks such lines */
                    sb_printf(&b, "  condition estimate: %.3g (of cond_1(A), through the backend's factorization; "
                                  "computed when the report was first read)\n  deferred at solve time: %s\n",
                              r->cond_est, why);
                else
                    sb_printf(&b, "  condition estimate: %.3g (of cond_1(A), through the backend's factorization)\n",
                              r->cond_est);
                /* The residual bound with the estimated ||A^-1||_1 (accuracy.h). */
                if (r->forward_bound >= 0)
                    sb_printf(&b, "  forward error bound (estimate: est ||A^-1||_1 ||b - A x||_1 / ||x||_1): %.3g\n",
                              r->forward_bound);
            } else {
                sb_printf(&b, "  condition estimate: not estimated (%s); no forward error bound\n",
                          r->condest_off ? "accuracy.condest = off"
                          : r->condest_deferred == DISP_CONDEST_LOST
                              ? "deferred at solve time, and the factorization was released before the report was read"
                          : r->iterations > 0 ? "iterative solver"
                                              : "the backend gives none");
            }
            if (r->pivot_ratio > 0)
                sb_printf(&b, "  condition (factor-diagonal ratio, not a bound): %.3g\n", r->pivot_ratio);
            sb_printf(&b, "  iterations: %lld\n", (long long)r->iterations);
            if (r->initial_guess)
                sb_printf(&b, "  initial guess: the previous value of %s (warm start)\n", s->name);
            if (r->attempts[0]) sb_printf(&b, "  earlier attempts (failed, the next listed backend took over):\n    %s\n", r->attempts);
            if (r->iterations > 0) {
                util_fmt_double(num, sizeof num, r->resid);
                sb_printf(&b, "  final relative residual: %s\n", num);
            }
            sb_printf(&b, "  reused factorization: %s\n", r->reused_factor ? "yes" : "no");
            sb_printf(&b, "  solve time: %.3g s\n", r->seconds);
            if (r->note[0]) sb_printf(&b, "  note: %s\n", r->note);
        }
    }
    return print_whole(E, &b, "info");
}

static int exec_stmt(lang_ev *V, const ast_node *s, int *flow);

/* ---- display ----------------------------------------------------------------- */

/* Whether a statement without ';' shows its value: core.display = on, which
 * the silc command sets (an embedded program's SILC_EXEC never prints
 * values), and never under explain. */
static int displaying(const lang_ev *V, const ast_node *s)
{
    lang_cache *c = V->E->lang_cache; /* made by program_for before any statement */
    if (s->quiet || V->explain) return 0;
    read_flags(V->E, c);
    return c->display;
}

static int show(lang_ev *V, const char *name, const silc_value *v)
{
    strbuf b;
    silc_value *whole = NULL;
    int rc;
    /* A small value distributed by rows is gathered to be shown (every rank
     * runs this alike: core.display is the same on all); a large one is
     * described without moving it. */
    if (dist_is(v) && v->m <= 40 && v->n <= 40) {
        whole = val_retain((silc_value *)v);
        if (dist_make_whole(V->E, &whole)) {
            val_release(whole);
            return -1;
        }
        v = whole;
    }
    sb_init(&b);
    dp_show(V->E, &b, name, v);
    rc = print_whole(V->E, &b, "the display");
    val_release(whole);
    return rc;
}

/* disp(x): shows x without its name, whatever core.display says (it is
 * asked for); a statement of its own, since it has no value. */
static int exec_disp(lang_ev *V, const ast_node *call)
{
    silc_value *v;
    int rc;
    if (call->nkids != 1) return eng_error(V->E, "disp takes one argument, got %zu", call->nkids);
    if (ev_expr(V, call->kids[0], &v)) return -1;
    rc = V->explain ? 0 : show(V, NULL, v);
    val_release(v);
    return rc;
}

/* An expression statement: a name shows as itself (`x = 3`), any other
 * value as Octave's `ans = ...`, and binds ans when it is shown. */
static int exec_expr(lang_ev *V, const ast_node *s, double t0)
{
    const ast_node *e = s->kids[0];
    silc_value *v;
    if (e->kind == AST_CALL && !strcmp(e->name, "disp")) return exec_disp(V, e);
    if (ev_expr(V, e, &v)) return -1;
    if (V->explain) {
        char shape[48];
        ev_shape(v, shape, sizeof shape);
        sb_printf(V->explain_out, "  result: a %s %s value (not run)\n", shape,
                  val_format_name(v->format));
    }
    if (V->E->warnings.failed) {
        val_release(v);
        return eng_error(V->E, "out of memory recording a warning");
    }
    if (!displaying(V, s)) {
        val_release(v);
        return 0;
    }
    if (e->kind == AST_NAME && store_get(&V->E->store, e->name)) {
        int rc = show(V, e->name, v);
        val_release(v);
        return rc;
    }
    if (show(V, "ans", v)) {
        val_release(v);
        return -1;
    }
    return bind(V, s, "ans", v, t0);
}

static int exec_tune(lang_ev *V, const ast_node *s)
{
    double xs[128];
    const char *file = NULL;
    size_t i;
    int nx = 0;
    for (i = 0; i < s->nkids; i++) {
        if (s->kids[i]->kind == AST_STRING) file = s->kids[i]->name;
        else if (nx < 128) xs[nx++] = s->kids[i]->num;
        else return eng_error(V->E, "tune %s: too many numbers (at most 64 points)", s->name);
    }
    return tuner_command(V->E, s->name, xs, nx, file);
}

static int exec_explain(lang_ev *V, const ast_node *s)
{
    strbuf b;
    int flow = FLOW_NEXT, rc;
    char *text = stmt_text(V, s->kids[0]);
    if (!text) return eng_error(V->E, "out of memory printing the output of explain");
    sb_init(&b);
    sb_printf(&b, "explain: %s\n", text);
    free(text);
    V->explain = 1;
    V->explain_out = &b;
    V->explain_step = 0;
    rc = exec_stmt(V, s->kids[0], &flow);
    V->explain = 0;
    V->explain_out = NULL;
    if (rc) {
        sb_free(&b);
        return rc;
    }
    if (V->explain_step == 0) sb_puts(&b, "  no operation runs: values are built by the core\n");
    return print_whole(V->E, &b, "explain");
}

static int condition(lang_ev *V, const ast_node *c, int *truth)
{
    silc_value *v;
    char shape[48];
    double x;
    if (ev_expr(V, c, &v)) return -1;
    if (!val_is_scalar(v)) {
        ev_shape(v, shape, sizeof shape);
        val_release(v);
        return eng_error(V->E, "condition must be a scalar, got %s", shape);
    }
    x = val_scalar(v);
    val_release(v);
    /* NaN != 0 holds, so `if nan` would run its block and `while nan`
     * loop for ever: an error, as Octave's `if NaN`. */
    if (isnan(x)) return eng_error(V->E, "condition is NaN");
    *truth = x != 0;
    return 0;
}

static int exec_block(lang_ev *V, const ast_node *b, int *flow)
{
    size_t i;
    for (i = 0; i < b->nkids; i++) {
        if (exec_stmt(V, b->kids[i], flow)) return -1;
        if (*flow != FLOW_NEXT) return 0;
    }
    return 0;
}

static int exec_stmt_here(lang_ev *V, const ast_node *s, int *flow);
static int empty_loop_cancelled(lang_ev *V);
static int exec_for(lang_ev *V, const ast_node *s, int *flow);
static int exec_profile(lang_ev *V, const ast_node *s);

/* One statement; on a communicator every rank learns whether every rank
 * ran it (dist.h): a statement that failed on one rank alone (out of
 * memory) stops all, instead of leaving that rank out of the next
 * collective. */
/* rc as every rank of a communicator agrees on it (any failure fails all);
 * rc itself without one, and under explain, which runs nothing collective. */
static int ranks_agree(lang_ev *V, int rc)
{
    return V->E->dist && !V->explain ? (dist_agree(V->E, rc) ? -1 : 0) : rc;
}

static int exec_stmt(lang_ev *V, const ast_node *s, int *flow)
{
    int rc = exec_stmt_here(V, s, flow);
    /* After the statement, not before: on a communicator the ranks then
     * learn of a stop in the agreement they make anyway, and all stop at
     * the same statement (only rank 0's engine has a cancel hook). */
    if (!rc && !V->explain) rc = eng_cancel_check(V->E);
    return ranks_agree(V, rc);
}

/* A `while` whose body is empty runs no statement to check after: its
 * iterations ask here (agreed between ranks as exec_stmt's checks are;
 * the caller skips it under explain). */
static int empty_loop_cancelled(lang_ev *V)
{
    return ranks_agree(V, eng_cancel_check(V->E));
}

static int exec_stmt_here(lang_ev *V, const ast_node *s, int *flow)
{
    /* The text's first statement starts at lang_exec's clock read: a clock
     * read costs 70-80 ns in a VM (kvm-clock), a twentieth of a statement. */
    double t0 = V->t_first > 0 ? V->t_first : util_now();
    int truth;
    V->t_first = 0;
    *flow = FLOW_NEXT;
    V->has_solve = 0;
    V->backends[0] = 0;
    if (V->E->dist) {
        V->moved0[0] = V->E->dist->moved_matrix;
        V->moved0[1] = V->E->dist->moved_vector;
    }
    eng_pending_release(&V->pending);
    switch (s->kind) {
    case ST_EXPR:
        return exec_expr(V, s, t0);
    case ST_ASSIGN:
    case ST_OPASSIGN:
    case ST_INDEX_ASSIGN:
        if (exec_assign(V, s, t0)) return -1;
        return displaying(V, s) ? show(V, s->name, store_get(&V->E->store, s->name)) : 0;
    case ST_CLEAR:
        return exec_clear(V, s);
    case ST_WHO:
        return exec_who(V);
    case ST_SET:
        return exec_set(V, s);
    case ST_INFO:
        return exec_info(V, s);
    case ST_EXPLAIN:
        return exec_explain(V, s);
    case ST_TUNE:
        return exec_tune(V, s);
    case ST_SAVE:
    case ST_LOAD: {
        const char *names[256];
        size_t i;
        if (s->nkids > 256) return eng_error(V->E, "%s: at most 256 names at once", s->kind == ST_SAVE ? "save" : "load");
        for (i = 0; i < s->nkids; i++) names[i] = s->kids[i]->name;
        return (s->kind == ST_SAVE ? h5_save : h5_load)(V->E, s->name, names, s->nkids);
    }
    case ST_HELP: {
        strbuf b;
        char err[200];
        sb_init(&b);
        /* help KEY (a setting) and help PLUGIN (its options) ask the options database */
        if (s->name && strchr(s->name, '.')) {
            if (cfg_show_key(V->E, s->name, &b, 1)) {
                sb_free(&b);
                return -1;
            }
            return print_whole(V->E, &b, "help");
        }
        if (s->name && !cfg_describe_plugin(V->E, s->name, &b)) return print_whole(V->E, &b, "help");
        if (lang_help(&b, s->name, err, sizeof err)) {
            sb_free(&b);
            return eng_error(V->E, "%s", err);
        }
        if (!s->name) cfg_list_plugins(V->E, &b);
        return print_whole(V->E, &b, "help");
    }
    case ST_BREAK:
        *flow = FLOW_BREAK;
        return 0;
    case ST_CONTINUE:
        *flow = FLOW_CONTINUE;
        return 0;
    case ST_BLOCK:
        return exec_block(V, s, flow);
    case ST_IF:
        if (condition(V, s->cond, &truth)) return -1;
        if (truth) return exec_block(V, s->kids[0], flow);
        return s->els ? exec_stmt(V, s->els, flow) : 0;
    case ST_FOR:
        return exec_for(V, s, flow);
    case ST_PROFILE:
        return exec_profile(V, s);
    case ST_WHILE: {
        /* An iteration of the outermost loop is a time step to the tuner
         * (a script's loop is the program's time loop; tuner_loop_step). */
        int rc = 0, outer = V->loop_depth++ == 0 && !V->explain;
        uint64_t key = outer ? tuner_hash(V->src) ^ ((uint64_t)s->line << 32 | (uint32_t)s->col) : 0;
        ev_loop loop = {s, -1, V->loop};
        V->loop = &loop;
        for (;;) {
            double ti = util_now();
            if ((rc = condition(V, s->cond, &truth)) || !truth) break;
            if (V->E->loop_budget && ++V->loops > V->E->loop_budget) {
                rc = eng_error(V->E, "loop stopped after %llu iterations (the engine's loop budget)",
                               (unsigned long long)V->E->loop_budget);
                break;
            }
            if (!s->kids[0]->nkids && !V->explain && (rc = empty_loop_cancelled(V))) break;
            if ((rc = exec_block(V, s->kids[0], flow))) break;
            if (outer) tuner_loop_step(V->E, key, util_now() - ti);
            if (*flow == FLOW_BREAK) break;
        }
        V->loop_depth--;
        V->loop = loop.up;
        if (!rc) *flow = FLOW_NEXT;
        return rc;
    }
    default:
        return eng_error(V->E, "internal error: expression where a statement was expected");
    }
}

/* A top-level statement's row of the profile, by its first line of text. */
static void profile_statement(lang_ev *V, const ast_node *s, double seconds)
{
    lang_cache *c = V->E->lang_cache;
    char name[80];
    size_t len = s->end - s->start;
    const char *nl = memchr(V->src + s->start, '\n', len);
    prof_row *r;
    if (nl) len = (size_t)(nl - (V->src + s->start));
    if (len > 38) len = 38;   /* the table's column */
    snprintf(name, sizeof name, "%.*s%s", (int)len, V->src + s->start, nl || s->end - s->start > 38 ? " ..." : "");
    r = prof_row_of(&c->statements, name);
    r->count++;
    r->seconds += seconds;
}

static void put_profile_table(strbuf *b, const char *title, const prof_table *t, int calls)
{
    size_t i;
    sb_printf(b, "%-44s %8s %11s", title, "count", "time (s)");
    if (calls) sb_printf(b, " %12s %12s %7s", "bytes in", "bytes out", "reused");
    sb_puts(b, "\n");
    if (!t->n) sb_puts(b, "  (none)\n");
    for (i = 0; i < t->n; i++) {
        const prof_row *r = &t->rows[i];
        sb_printf(b, "  %-42s %8llu %11.4g", r->name, (unsigned long long)r->count, r->seconds);
        if (calls) sb_printf(b, " %12.4g %12.4g %7llu", r->bytes_in, r->bytes_out, (unsigned long long)r->reused);
        sb_puts(b, "\n");
    }
}

/* profile: the tables; profile clear: empties them. */
static int exec_profile(lang_ev *V, const ast_node *s)
{
    lang_cache *c = V->E->lang_cache;
    const char *p = cfg_get(V->E, "core.profile");
    strbuf b;
    if (s->name) {   /* clear */
        memset(&c->statements, 0, sizeof c->statements);
        memset(&c->calls, 0, sizeof c->calls);
        return 0;
    }
    sb_init(&b);
    sb_printf(&b, "profile (core.profile = %s; time is wall time, a statement's includes its calls; "
                  "reused = solves that reused a factorization)\n", p ? p : "off");
    put_profile_table(&b, "statement", &c->statements, 0);
    put_profile_table(&b, "plugin call (solve: backend; else the class)", &c->calls, 1);
    return print_whole(V->E, &b, "profile");
}

/* The column k of the values a for loop walks: a range's element k (the
 * range is never built whole: `for i = 1:1e9` needs no 8 GB), or column k
 * of a value (a scalar when it has one row). */
static int for_value(lang_ev *V, const range_spec *r, const silc_value *all, int64_t k,
                     silc_value **out)
{
    int64_t i;
    if (!all) {
        *out = val_scalar_new(range_at(r->base, r->inc, r->limit, r->count, (double)k));
        return *out ? 0 : eng_oom(V->E);
    }
    if (!(*out = val_new_unset_field(SILC_FMT_DENSE, all->field, all->m, 1, 0, 0, 0))) return eng_oom(V->E);
    for (i = 0; i < all->m; i++) {
        double complex z = val_get_complex(all, i, k); /* a complex column stays complex */
        (*out)->val[i * val_width(all)] = creal(z);
        if (all->field == SILC_FIELD_COMPLEX) (*out)->val[2 * i + 1] = cimag(z);
    }
    return 0;
}

/* for name = e: binds name to each column of e in turn and runs the body.
 * The loop budget, the tuner's time steps and the cancel checks are those
 * of `while`. */
static int exec_for(lang_ev *V, const ast_node *s, int *flow)
{
    range_spec r = {0, 0, 0, 0};
    silc_value *all = NULL;
    int64_t k, count;
    int rc = 0, outer;
    uint64_t key;
    ev_loop loop = {s, 0, V->loop};
    if (s->cond->kind == AST_RANGE) {
        if (range_of(V, s->cond, &r)) return -1;
        count = (int64_t)r.count;
    } else {
        if (ev_expr(V, s->cond, &all)) return -1;
        count = all->m > 0 ? all->n : 0;
    }
    outer = V->loop_depth++ == 0 && !V->explain;
    key = outer ? tuner_hash(V->src) ^ ((uint64_t)s->line << 32 | (uint32_t)s->col) : 0;
    V->loop = &loop;
    for (k = 0; k < count; k++) {
        double ti = util_now();
        silc_value *v;
        loop.left = count - k - 1;
        if (V->E->loop_budget && ++V->loops > V->E->loop_budget) {
            rc = eng_error(V->E, "loop stopped after %llu iterations (the engine's loop budget)",
                           (unsigned long long)V->E->loop_budget);
            break;
        }
        if ((rc = for_value(V, &r, all, k, &v))) break;
        /* the loop variable's record is its own, not the last solve's of the body */
        V->has_solve = 0;
        V->backends[0] = 0;
        eng_pending_release(&V->pending);
        if ((rc = bind(V, s, s->name, v, ti))) break;
        if (!s->kids[0]->nkids && !V->explain && (rc = empty_loop_cancelled(V))) break;
        if ((rc = exec_block(V, s->kids[0], flow))) break;
        if (outer) tuner_loop_step(V->E, key, util_now() - ti);
        if (*flow == FLOW_BREAK) break;
        if (V->explain) break;   /* explain describes one pass */
    }
    V->loop_depth--;
    V->loop = loop.up;
    val_release(all);
    if (!rc) *flow = FLOW_NEXT;
    return rc;
}

/* A statement that holds other statements (a loop, an `if`, a block),
 * whose inner bindings must be undone if it fails or is interrupted part
 * way; any other statement computes its value whole before binding it.
 * Kinds not listed here count as compound, so a new one is undone too. */
static int is_compound(const ast_node *s)
{
    switch (s->kind) {
    case ST_EXPR: case ST_ASSIGN: case ST_OPASSIGN: case ST_INDEX_ASSIGN: case ST_CLEAR:
    case ST_WHO: case ST_SET: case ST_INFO: case ST_EXPLAIN: case ST_BREAK: case ST_CONTINUE:
    case ST_TUNE: case ST_HELP: case ST_PROFILE: case ST_SAVE: case ST_LOAD:
        return 0;
    default:
        return 1;
    }
}

/* One top-level statement.  A compound one runs against a snapshot of the
 * store (eng_snapshot), put back when it fails -- the same on every rank,
 * since failures are agreed -- so that an interrupted loop leaves the
 * store as before it, as any failed statement does. */
static int exec_top(lang_ev *V, const ast_node *s)
{
    eng_snapshot snap;
    int flow, rc;
    if (!is_compound(s)) return exec_stmt(V, s, &flow);
    rc = eng_snapshot_take(V->E, &snap) ? eng_error(V->E, "out of memory preparing the statement") : 0;
    if (ranks_agree(V, rc)) { /* every rank runs the statement, or none */
        if (!rc) eng_snapshot_free(&snap);
        return -1;
    }
    rc = exec_stmt(V, s, &flow);
    if (!rc) {
        eng_snapshot_free(&snap);
        return 0;
    }
    if (eng_snapshot_restore(V->E, &snap)) {
        char msg[sizeof V->E->err];
        memcpy(msg, V->E->err, sizeof msg);
        eng_error(V->E, "%.2000s; out of memory undoing the statement: some names are unbound", msg);
    }
    return -1;
}

int lang_exec(silc_engine *E, const char *text)
{
    lang_program *prog;
    lang_ev V;
    size_t i;
    double t0 = util_now();
    if (!text) return eng_error(E, "no statement text");
    E->err[0] = 0;
    if (E->max_statement_bytes) {
        size_t len = strlen(text);
        if (len > E->max_statement_bytes)
            return eng_error(E, "statement text of %zu bytes is over the limit of %zu bytes: split it, "
                             "or PUT large data as a value", len, E->max_statement_bytes);
    }
    if (program_for(E, text, &prog)) return -1;
    memset(&V, 0, offsetof(lang_ev, report)); /* the report is written by the solve that sets has_solve */
    V.E = E;
    V.src = prog->text;
    V.t_first = t0;
    read_flags(E, E->lang_cache);
    V.profile = ((lang_cache *)E->lang_cache)->profile;
    for (i = 0; i < prog->nstmts; i++) {
        int rc;
        double ts = V.profile ? util_now() : 0;
        E->err[0] = 0;
        rc = exec_top(&V, prog->stmts[i]);
        if (V.profile && prog->stmts[i]->kind != ST_PROFILE) profile_statement(&V, prog->stmts[i], util_now() - ts);
        if (rc) {
            eng_pending_release(&V.pending);
            free(V.bind_text);
            if (prog->nstmts > 1) {
                char msg[sizeof E->err];
                memcpy(msg, E->err, sizeof msg);
                eng_error(E, "statement %zu: %s", i + 1, msg);
            }
            return -1;
        }
    }
    eng_pending_release(&V.pending);
    free(V.bind_text);
    tuner_observe_since(E, text, t0);
    return 0;
}
