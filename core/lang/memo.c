/*
 * memo.c -- results of operations that a time loop repeats on the same
 * operands, kept and handed out again.
 *
 * Values never change without a new id (value.c), so an operation (its op,
 * selector, coefficients and the ids of its operands) always gives the same
 * result.  A loop such as the seeds' cloth step recomputes, every step,
 * quantities built only from values that never change -- C1 =
 * diag(X * sqrt(K_stiff)), A1, T1 = -A1 * A1', A = M - dt^2 DfDx - dt DfDv --
 * and pays the sparse products each time; worse, A comes out as a new value
 * every step, so a direct solver factors it again.  Here such a result is
 * returned as the value it was the first time: the products run once, and
 * A keeps its id, so its factorization is reused.
 *
 * A key is remembered (without its result) the first time it is seen, and
 * its result is kept only when the same key comes again: most operations of
 * a loop have an operand that changes every step and would only fill the
 * table.  The table is small and bounded (MEMO_SLOTS entries, MEMO_BYTES of
 * results with what hangs off them), least recently used first out.
 *
 * Chains settle in one step.  The first sighting's result is not kept, so
 * the next step computes the operation again as a new value; an operation
 * on that result (X * sqrt(K) after sqrt(K)) would then see a new operand
 * id every step until its input settled, and a chain of d operations took
 * 2d steps to settle (the cloth's A: 12 levels, 40 sparse products in its
 * first 25 steps).  So the slot notes its first result's id, and when the
 * result is kept the keys naming that id are renamed to the kept one: the
 * two are the same operation on the same operands, the premise of the
 * table, and the whole chain is kept in its second step.
 *
 * A kept result is memory the session holds without a name: its arrays
 * (unless a name holds it too) and, above all, what later calls attached
 * to it -- a solve with it leaves its factorization there, often many
 * times the matrix (issue 33: 30 rounds of `B = A * c` kept, solved and
 * cleared grew a 16 MiB silcd session to 629 MiB).  So it counts against
 * silcd's --max-session-bytes (memo_charge, session.c) and is the first
 * thing to go when the limit is reached: at the end of every request and
 * before a PUT (memo_shrink), before every call of a request and before a
 * load (memo_make_room), least recently used first.  An attachment's bytes
 * are what the dispatcher measured the plugin call that made it keep
 * (val_attach_charge, disp_run).  Not used: for solves (their
 * report and warnings belong to each statement), in explain, for calls
 * that warned, on SPMD engines (ranks number values differently, and every
 * rank must take the same path).  A result handed out is shared, so an
 * in-place update of it (x += ...) copies first, as for any shared value.
 */
#define _POSIX_C_SOURCE 200809L
#include "lang.h"

#include <stdlib.h>
#include <string.h>

#define MEMO_SLOTS 64
#define MEMO_BYTES ((uint64_t)128 << 20)

typedef struct memo_key {
    int op, sub, nin;
    uint64_t ids[3];
    double alpha, beta, alpha_imag, beta_imag;
    int64_t ival[2];
} memo_key;

typedef struct memo_slot {
    memo_key key;
    silc_value *result;   /* NULL: seen once, no result kept */
    uint64_t first_id;    /* the id of the first sighting's result (not kept), or 0 */
    uint64_t used;        /* for least-recently-used eviction */
} memo_slot;

struct eng_memo {
    memo_slot slot[MEMO_SLOTS];
    int n;
    uint64_t clock;
};

/* A kept result with everything attached to it: what MEMO_BYTES bounds. */
static uint64_t result_bytes(const silc_value *v)
{
    return v ? (uint64_t)val_bytes(v) + (uint64_t)val_attach_bytes(v) : 0;
}

static uint64_t table_bytes(const eng_memo *M)
{
    uint64_t total = 0;
    int i;
    for (i = 0; i < M->n; i++) total += result_bytes(M->slot[i].result);
    return total;
}

/* The call's key; -1 for a call never kept: a solve (its report and
 * warnings belong to each statement), one with per-call options, or one on
 * an SPMD engine (ranks number values differently, and every rank must
 * take the same path). */
static int key_of(const silc_engine *E, const silc_call *call, memo_key *k)
{
    int i;
    if (E->dist || call->op == SILC_OP_SOLVE || call->options || call->nin < 1 || call->nin > 3) return -1;
    memset(k, 0, sizeof *k);
    k->op = call->op;
    k->sub = call->sub;
    k->nin = call->nin;
    for (i = 0; i < call->nin; i++) {
        if (!call->in[i]) return -1;
        k->ids[i] = call->in[i]->id;
    }
    k->alpha = call->alpha;
    k->beta = call->beta;
    k->alpha_imag = call->alpha_imag;
    k->beta_imag = call->beta_imag;
    k->ival[0] = call->ival[0];
    k->ival[1] = call->ival[1];
    return 0;
}

static int same_key(const memo_key *a, const memo_key *b)
{
    /* Coefficients compare by bits: -0.0 and 0.0 scale differently. */
    return a->op == b->op && a->sub == b->sub && a->nin == b->nin && !memcmp(a->ids, b->ids, sizeof a->ids) &&
           !memcmp(&a->alpha, &b->alpha, sizeof a->alpha) && !memcmp(&a->beta, &b->beta, sizeof a->beta) &&
           !memcmp(&a->alpha_imag, &b->alpha_imag, sizeof a->alpha_imag) &&
           !memcmp(&a->beta_imag, &b->beta_imag, sizeof a->beta_imag) && a->ival[0] == b->ival[0] && a->ival[1] == b->ival[1];
}

static memo_slot *find(eng_memo *M, const memo_key *k)
{
    int i;
    for (i = 0; i < M->n; i++)
        if (same_key(&M->slot[i].key, k)) return &M->slot[i];
    return NULL;
}

static void drop(eng_memo *M, memo_slot *s)
{
    val_release(s->result);
    *s = M->slot[--M->n];
}

/* The least recently used slot holding a result, but not keep; -1 if none. */
static int oldest_result(const eng_memo *M, const memo_slot *keep)
{
    int i, old = -1;
    for (i = 0; i < M->n; i++)
        if (M->slot[i].result && &M->slot[i] != keep && (old < 0 || M->slot[i].used < M->slot[old].used)) old = i;
    return old;
}

/* A free slot, evicting the least recently used when the table is full. */
static memo_slot *make_room(eng_memo *M)
{
    int i, old = 0;
    if (M->n < MEMO_SLOTS) return &M->slot[M->n++];
    for (i = 1; i < M->n; i++)
        if (M->slot[i].used < M->slot[old].used) old = i;
    drop(M, &M->slot[old]);
    return &M->slot[M->n++];
}

/* Keys naming the value `from` name `to` instead (see the top of the file). */
static void rename_operand(eng_memo *M, uint64_t from, uint64_t to)
{
    int i, j;
    for (i = 0; i < M->n; i++)
        for (j = 0; j < M->slot[i].key.nin; j++)
            if (M->slot[i].key.ids[j] == from) M->slot[i].key.ids[j] = to;
}

silc_value *memo_lookup(silc_engine *E, const silc_call *call)
{
    memo_key k;
    memo_slot *s;
    double need = 0;
    int i;
    if (!E->memo) return NULL;
    /* Before a call under a session's limit: room for what is kept and,
     * as a guess at what the call makes, its largest operand. */
    for (i = 0; i < call->nin && i < 3; i++)
        if (call->in[i] && (double)val_bytes(call->in[i]) > need) need = (double)val_bytes(call->in[i]);
    memo_make_room(E, need);
    if (key_of(E, call, &k)) return NULL;
    s = find(E->memo, &k);
    if (!s || !s->result) return NULL;
    s->used = ++E->memo->clock;
    return val_retain(s->result);
}

void memo_note(silc_engine *E, const silc_call *call, silc_value *result, int warned)
{
    eng_memo *M;
    memo_key k;
    memo_slot *s;
    uint64_t bytes;
    if (key_of(E, call, &k)) return;
    if (!E->memo && !(E->memo = calloc(1, sizeof *E->memo))) return; /* no table: nothing kept, nothing lost */
    M = E->memo;
    s = find(M, &k);
    if (warned) { /* its warnings belong to each run: never hand it out */
        if (s) drop(M, s);
        return;
    }
    if (!s) { /* the first sighting: remember the key only */
        s = make_room(M);
        memset(s, 0, sizeof *s);
        s->key = k;
        s->first_id = result ? result->id : 0;
        s->used = ++M->clock;
        return;
    }
    s->used = ++M->clock;
    if (s->result) return;
    bytes = result_bytes(result);
    while (table_bytes(M) + bytes > MEMO_BYTES) {
        int old = oldest_result(M, s);
        if (old < 0) return; /* larger than the whole table: not kept */
        /* drop() moves the last slot into the freed one: keep s pointing at our key. */
        if (s == &M->slot[M->n - 1]) s = &M->slot[old];
        drop(M, &M->slot[old]);
    }
    s->result = val_retain(result);
    if (s->first_id && s->first_id != result->id) rename_operand(M, s->first_id, result->id);
    s->first_id = 0;
}

uint64_t memo_charge(const silc_engine *E, uint64_t *arrays)
{
    const eng_memo *M = E->memo;
    uint64_t own = 0, attached = 0;
    int i;
    for (i = 0; M && i < M->n; i++) {
        const silc_value *v = M->slot[i].result;
        if (!v) continue;
        if (v->bindings <= 0) own += val_bytes(v);
        attached += (uint64_t)val_attach_bytes(v);
    }
    if (arrays) *arrays = own;
    return own + attached;
}

void memo_shrink(silc_engine *E, uint64_t room)
{
    eng_memo *M = E->memo;
    int old;
    while (M && memo_charge(E, NULL) > room && (old = oldest_result(M, NULL)) >= 0) drop(M, &M->slot[old]);
}

void memo_make_room(silc_engine *E, double need)
{
    eng_memo *M = E->memo;
    int old;
    /* The budget counts the results' arrays already (they are values
     * alive, and silcd's budget does not exempt them); what hangs off them
     * it cannot see. */
    while (M && val_budget_room() != INT64_MAX) {
        uint64_t arrays, attached = memo_charge(E, &arrays) - arrays;
        if ((double)attached + need <= (double)val_budget_room() || (old = oldest_result(M, NULL)) < 0) return;
        drop(M, &M->slot[old]);
    }
}

void memo_free(silc_engine *E)
{
    eng_memo *M = E->memo;
    if (!M) return;
    while (M->n) drop(M, &M->slot[M->n - 1]);
    free(M);
    E->memo = NULL;
}
