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
 * silcd's --max-session-bytes (memo_held, session.c) and is the first
 * thing to go when the limit is reached: at the end of every request and
 * before a PUT (memo_release), before every call of a request and before a
 * load (memo_make_room), least recently used first; the factorizations
 * hung on bound values are counted and let go by the same walk, after the
 * memo's results (below).  Not used: for solves (their
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
    uint64_t tag;         /* a hash of the rest (key_tag), compared first */
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

/* Every call looks its key up and, in a loop whose operand changes every
 * step, adds it and evicts the least recently used key: with a scan of the
 * 64 slots for each, that was a quarter of a small product's fixed cost
 * (docs/overhead.md, issue 30).  So the slots are also chained by key tag
 * in MEMO_BUCKETS buckets (find), and kept in a list by use, least recently
 * used first (the order of `used`, which the holder walk below still
 * reads).  Slots are numbered by signed char: -1 is none. */
#define MEMO_BUCKETS 128
_Static_assert(MEMO_SLOTS < 127 && (MEMO_BUCKETS & (MEMO_BUCKETS - 1)) == 0, "slot numbers fit a signed char");

struct eng_memo {
    memo_slot slot[MEMO_SLOTS];
    signed char bucket[MEMO_BUCKETS]; /* the first slot of each tag bucket */
    signed char chain[MEMO_SLOTS];    /* the next slot in the same bucket */
    signed char older[MEMO_SLOTS], newer[MEMO_SLOTS]; /* the use list */
    signed char oldest, newest;
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

/* A hash of what tells keys apart most often (the operation and its
 * operands' ids): it picks the key's bucket, and a comparison of two keys
 * in one bucket stops at it unless they are the same. */
static uint64_t key_tag(const memo_key *k)
{
    uint64_t h = (uint64_t)k->op * 0x9E3779B97F4A7C15ull ^ (uint64_t)k->sub << 32 ^ (uint64_t)k->nin;
    for (int i = 0; i < 3; i++) h = (h ^ k->ids[i]) * 0x100000001B3ull;
    return h;
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
    k->tag = key_tag(k);
    return 0;
}

static void room_for_call(silc_engine *E, double need, const silc_call *keep);

static int same_key(const memo_key *a, const memo_key *b)
{
    /* Coefficients compare by bits: -0.0 and 0.0 scale differently. */
    return a->tag == b->tag && a->op == b->op && a->sub == b->sub && a->nin == b->nin && !memcmp(a->ids, b->ids, sizeof a->ids) &&
           !memcmp(&a->alpha, &b->alpha, sizeof a->alpha) && !memcmp(&a->beta, &b->beta, sizeof a->beta) &&
           !memcmp(&a->alpha_imag, &b->alpha_imag, sizeof a->alpha_imag) &&
           !memcmp(&a->beta_imag, &b->beta_imag, sizeof a->beta_imag) && a->ival[0] == b->ival[0] && a->ival[1] == b->ival[1];
}

static int bucket_of(uint64_t tag)
{
    return (int)((tag ^ tag >> 32) & (MEMO_BUCKETS - 1));
}

static void index_add(eng_memo *M, int i)
{
    int b = bucket_of(M->slot[i].key.tag);
    M->chain[i] = M->bucket[b];
    M->bucket[b] = (signed char)i;
}

static void index_remove(eng_memo *M, int i)
{
    signed char *at = &M->bucket[bucket_of(M->slot[i].key.tag)];
    while (*at != i) at = &M->chain[*at];
    *at = M->chain[i];
}

/* Slot i's neighbours in the use list point at it as slot `as`. */
static void order_link(eng_memo *M, int i, int as)
{
    if (M->older[i] >= 0) M->newer[M->older[i]] = (signed char)as;
    else M->oldest = (signed char)as;
    if (M->newer[i] >= 0) M->older[M->newer[i]] = (signed char)as;
    else M->newest = (signed char)as;
}

static void order_remove(eng_memo *M, int i)
{
    if (M->older[i] >= 0) M->newer[M->older[i]] = M->newer[i];
    else M->oldest = M->newer[i];
    if (M->newer[i] >= 0) M->older[M->newer[i]] = M->older[i];
    else M->newest = M->older[i];
}

static void order_append(eng_memo *M, int i)
{
    M->older[i] = M->newest;
    M->newer[i] = -1;
    if (M->newest >= 0) M->newer[M->newest] = (signed char)i;
    else M->oldest = (signed char)i;
    M->newest = (signed char)i;
}

/* The slot was used now: the newest in the list. */
static void touch(eng_memo *M, memo_slot *s)
{
    int i = (int)(s - M->slot);
    s->used = ++M->clock;
    order_remove(M, i);
    order_append(M, i);
}

static eng_memo *memo_new(void)
{
    eng_memo *M = calloc(1, sizeof *M);
    if (M) {
        memset(M->bucket, -1, sizeof M->bucket);
        M->oldest = M->newest = -1;
    }
    return M;
}

static memo_slot *find(eng_memo *M, const memo_key *k)
{
    int i;
    for (i = M->bucket[bucket_of(k->tag)]; i >= 0; i = M->chain[i])
        if (same_key(&M->slot[i].key, k)) return &M->slot[i];
    return NULL;
}

/* Empties slot s: the last slot moves into it. */
static void drop(eng_memo *M, memo_slot *s)
{
    int i = (int)(s - M->slot), last = M->n - 1;
    val_release(s->result);
    index_remove(M, i);
    order_remove(M, i);
    if (i != last) {
        index_remove(M, last);
        M->older[i] = M->older[last];
        M->newer[i] = M->newer[last];
        order_link(M, i, i);
        M->slot[i] = M->slot[last];
        index_add(M, i);
    }
    M->n--;
}

/* The least recently used slot holding a result, but not keep; -1 if none. */
static int oldest_result(const eng_memo *M, const memo_slot *keep)
{
    int i;
    for (i = M->oldest; i >= 0; i = M->newer[i])
        if (M->slot[i].result && &M->slot[i] != keep) return i;
    return -1;
}

/* A slot for key k, used now, evicting the least recently used when the
 * table is full. */
static memo_slot *make_room(eng_memo *M, const memo_key *k)
{
    memo_slot *s;
    if (M->n == MEMO_SLOTS) drop(M, &M->slot[M->oldest]);
    s = &M->slot[M->n];
    memset(s, 0, sizeof *s);
    s->key = *k;
    s->used = ++M->clock;
    index_add(M, M->n);
    order_append(M, M->n);
    M->n++;
    return s;
}

/* Keys naming the value `from` name `to` instead (see the top of the file);
 * their tags change, so the buckets are made again. */
static void rename_operand(eng_memo *M, uint64_t from, uint64_t to)
{
    int i, j;
    memset(M->bucket, -1, sizeof M->bucket);
    for (i = 0; i < M->n; i++) {
        memo_key *k = &M->slot[i].key;
        for (j = 0; j < k->nin; j++)
            if (k->ids[j] == from) k->ids[j] = to;
        k->tag = key_tag(k);
        index_add(M, i);
    }
}

silc_value *memo_lookup(silc_engine *E, const silc_call *call)
{
    memo_key k;
    memo_slot *s;
    double need = 0;
    int i;
    /* Before a call under a session's limit: room for what is kept and,
     * as a guess at what the call makes, its largest operand. */
    if (val_budget_room() != INT64_MAX) {
        for (i = 0; i < call->nin && i < 3; i++)
            if (call->in[i] && (double)val_bytes(call->in[i]) > need) need = (double)val_bytes(call->in[i]);
        room_for_call(E, need, call);
    }
    if (!E->memo || key_of(E, call, &k)) return NULL;
    s = find(E->memo, &k);
    if (!s || !s->result) return NULL;
    touch(E->memo, s);
    return val_retain(s->result);
}

void memo_note(silc_engine *E, const silc_call *call, silc_value *result, int warned)
{
    eng_memo *M;
    memo_key k;
    memo_slot *s;
    uint64_t bytes;
    if (key_of(E, call, &k)) return;
    if (!E->memo && !(E->memo = memo_new())) return; /* no table: nothing kept, nothing lost */
    M = E->memo;
    s = find(M, &k);
    if (warned) { /* its warnings belong to each run: never hand it out */
        if (s) drop(M, s);
        return;
    }
    if (!s) { /* the first sighting: remember the key only */
        s = make_room(M, &k);
        s->first_id = result ? result->id : 0;
        return;
    }
    touch(M, s);
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

/* ---- what a session holds ------------------------------------------------------
 * silcd's --max-session-bytes checks everything a session keeps alive: the
 * arrays of its bound values (per name, as bound), the arrays of the
 * memo's results no name holds, and the plugin state solves attached to
 * any value it holds -- a bound A's factorization as much as a memo
 * result's, and those of the operands an `info` record keeps for a
 * deferred estimate (eng_pending), which no name may hold any more.  One
 * walk measures all three and picks what goes first when the limit is
 * reached: the memo's results, least recently used first; then attached
 * state, least recently used first, that of values no name holds before
 * that of bound ones.  A released factorization is made again by the next
 * solve that needs it; an estimate owed on it says it was released
 * (DISP_CONDEST_LOST).  An attachment's bytes are what the dispatcher
 * measured across the plugin call that made it (val_attach_charge,
 * dispatch.c).  A value held twice (two names, a name and a record) has
 * its attachments counted once: the walk stamps each value it counted.
 * A distributed value's attachments are its own (a collective backend's
 * factorization, this rank's part of it) and those of its gathered whole
 * copy (a sequential backend's).
 *
 * On an SPMD engine (silcd --mpi) the same walk makes the same choice, but
 * nothing may be let go where it is made: a distributed factorization dies
 * collectively (MUMPS's JOB=-2, PETSc's destroy), on every rank at once,
 * and each rank measures its own part.  So rank 0's walk only plans
 * (memo_release_plan): each value it would let go is counted as gone and
 * named by what holds it on every rank -- a name, or an `info` record's
 * operand -- since value ids differ between ranks; silcd sends the plan to
 * every rank, and each lets go of the same holders in the same order
 * (memo_release_named).  The memo keeps nothing there (key_of). */

typedef struct holder_walk {
    memo_holdings h;
    const silc_call *keep;    /* the operands of the call about to run: not let go */
    int slot;                 /* the memo result to drop first, -1: none */
    const silc_value *value;  /* else the value whose attachments go first, NULL: none */
    int value_bound;
    uint64_t value_used;
    const char *holder;       /* what holds value on every rank: a name, or an info record's */
    int operand;              /* 0: value is bound to holder; 1-3: the record's pending A, B, X */
    const silc_value **gone;  /* planning (SPMD): the values in the plan, counted as let go */
    size_t ngone, capgone;
} holder_walk;

static uint64_t holder_walks; /* stamps values counted by the current walk (silc_value.counted) */

static int operand_of(const silc_call *call, const silc_value *v)
{
    int i;
    for (i = 0; call && i < call->nin && i < 3; i++)
        if (call->in[i] == v) return 1;
    return 0;
}

static int planned(const holder_walk *w, const silc_value *v)
{
    size_t i;
    for (i = 0; i < w->ngone; i++)
        if (w->gone[i] == v) return 1;
    return 0;
}

/* v's gathered whole copy, if it is distributed and has one. */
static const silc_value *whole_copy(const silc_value *v)
{
    return v && v->dist ? v->dist->whole : NULL;
}

/* Counts v's attachments (and its whole copy's) once per walk; a candidate
 * to let go unless the coming call needs it.  own: it is a memo result
 * (dropped as a whole).  holder, operand: what holds v (holder_walk). */
static void count_attached(holder_walk *w, const silc_value *v, uint64_t stamp, int bound, int own,
                           const char *holder, int operand)
{
    const silc_value *c = whole_copy(v);
    int64_t attached;
    uint64_t used;
    if (!v || v->counted == stamp) return;
    ((silc_value *)v)->counted = stamp; /* bookkeeping, not contents */
    if (planned(w, v)) return;          /* the plan lets it go */
    attached = val_attach_bytes(v);
    used = val_attach_last_use(v);
    if (c && c->counted != stamp) {
        ((silc_value *)c)->counted = stamp;
        attached += val_attach_bytes(c);
        if (val_attach_last_use(c) > used) used = val_attach_last_use(c);
    }
    if (attached <= 0) return;
    w->h.attached += (uint64_t)attached;
    if (own || operand_of(w->keep, v)) return;
    if (!w->value || (w->value_bound && !bound) || (w->value_bound == bound && used < w->value_used)) {
        w->value = v;
        w->value_bound = bound;
        w->value_used = used;
        w->holder = holder;
        w->operand = operand;
    }
}

static void walk(const silc_engine *E, holder_walk *w)
{
    const eng_memo *M = E->memo;
    const eng_info_entry *r;
    const store_entry *e;
    uint64_t stamp = ++holder_walks;
    size_t b;
    int i;
    memset(&w->h, 0, sizeof w->h);
    w->slot = -1;
    w->value = NULL;
    for (b = 0; b < E->store.nbuckets; b++)
        for (e = E->store.buckets[b]; e; e = e->next) {
            w->h.bound += val_bytes(e->value);
            count_attached(w, e->value, stamp, 1, 0, e->name, 0);
        }
    for (i = 0; M && i < M->n; i++) {
        const memo_slot *s = &M->slot[i];
        if (!s->result || s->result->bindings > 0) continue; /* a name holds it: counted above */
        w->h.memo_arrays += val_bytes(s->result);
        count_attached(w, s->result, stamp, 0, 1, NULL, 0);
        if (!operand_of(w->keep, s->result) && (w->slot < 0 || s->used < M->slot[w->slot].used)) w->slot = i;
    }
    for (r = E->infos; r; r = r->next) {
        count_attached(w, r->info.pending.A, stamp, 0, 0, r->name, 1);
        count_attached(w, r->info.pending.B, stamp, 0, 0, r->name, 2);
        count_attached(w, r->info.pending.X, stamp, 0, 0, r->name, 3);
    }
}

static uint64_t held_total(const memo_holdings *h)
{
    return h->bound + h->memo_arrays + h->attached;
}

/* Lets go of v's charged attachments and of its whole copy's. */
static void release_attached(const silc_value *v)
{
    val_attach_release(v);
    val_attach_release(whole_copy(v));
}

/* Drops the walk's first candidate: 0 if there was none. */
static int let_go(silc_engine *E, const holder_walk *w)
{
    if (w->slot >= 0) {
        drop(E->memo, &E->memo->slot[w->slot]);
        return 1;
    }
    if (w->value) {
        release_attached(w->value);
        return 1;
    }
    return 0;
}

/* Planning: the walk's first candidate goes into plan (an "OPERAND HOLDER"
 * line) and counts as gone from the next walk on; 0 if there was none.
 * Only a value's attachments can be named on every rank (the memo, which
 * could offer a slot, keeps nothing on an SPMD engine). */
static int plan_next(holder_walk *w, strbuf *plan)
{
    if (!w->value || !w->holder) return 0;
    if (w->ngone == w->capgone) {
        size_t cap = w->capgone ? 2 * w->capgone : 8;
        const silc_value **g = realloc(w->gone, cap * sizeof *g);
        if (!g) return 0; /* out of memory: the plan stops short; the caller sees what is left */
        w->gone = g;
        w->capgone = cap;
    }
    w->gone[w->ngone++] = w->value;
    sb_printf(plan, "%d %s\n", w->operand, w->holder);
    return 1;
}

uint64_t memo_held(const silc_engine *E, memo_holdings *h)
{
    holder_walk w;
    memset(&w, 0, sizeof w);
    walk(E, &w);
    if (h) *h = w.h;
    return held_total(&w.h);
}

/* The one choice of what gives way (the top of this part): the walk's first
 * candidate goes until the session fits room -- let go at once, or, with a
 * plan, written to it and counted as gone.  Returns what the session holds
 * after that. */
static uint64_t give_way(silc_engine *E, double room, strbuf *plan)
{
    holder_walk w;
    uint64_t held;
    memset(&w, 0, sizeof w);
    walk(E, &w);
    /* The values alone over: the caller refuses; letting go would lose
     * the factorizations for nothing. */
    if ((double)w.h.bound <= room)
        while ((double)held_total(&w.h) > room && (plan ? plan_next(&w, plan) : let_go(E, &w))) walk(E, &w);
    held = held_total(&w.h);
    free(w.gone);
    return held;
}

void memo_release(silc_engine *E, double room)
{
    give_way(E, room, NULL);
}

uint64_t memo_release_plan(const silc_engine *E, double room, strbuf *plan)
{
    return give_way((silc_engine *)E, room, plan); /* with a plan nothing is let go */
}

int memo_release_named(silc_engine *E, const char *plan, char *err, size_t errlen)
{
    char *copy = util_strdup(plan), *line, *end;
    int rc = 0;
    if (!copy) {
        snprintf(err, errlen, "out of memory reading a release plan");
        return -1;
    }
    for (line = copy; !rc && *line; line = end) {
        const silc_value *v = NULL;
        const char *holder = line + 2;
        int operand = line[0] - '0';
        if ((end = strchr(line, '\n')) != NULL) *end++ = '\0';
        else end = line + strlen(line);
        if (operand < 0 || operand > 3 || line[1] != ' ' || !*holder) {
            snprintf(err, errlen, "a malformed release plan line: '%.60s'", line);
            rc = -1;
            break;
        }
        if (operand == 0) {
            v = store_get(&E->store, holder);
        } else {
            const eng_info_entry *r;
            for (r = E->infos; r && strcmp(r->name, holder) != 0; r = r->next) {}
            if (r) v = operand == 1 ? r->info.pending.A : operand == 2 ? r->info.pending.B : r->info.pending.X;
        }
        if (!v) {
            snprintf(err, errlen, "the release plan names %s '%.200s', which this rank does not hold",
                     operand ? "an operand of the info record" : "the value", holder);
            rc = -1;
        } else {
            release_attached(v);
        }
    }
    free(copy);
    return rc;
}

/* Inside a request the budget counts the values alive (bound, temporary,
 * the memo's): what it cannot see is the attached state, which must fit
 * with need more bytes in what it has left. */
static void room_for_call(silc_engine *E, double need, const silc_call *keep)
{
    holder_walk w;
    if (val_budget_room() == INT64_MAX || E->dist) return;
    /* Every attachment alive in the process fits: no walk needed. */
    if ((double)val_attach_live_bytes() + need <= (double)val_budget_room()) return;
    memset(&w, 0, sizeof w);
    w.keep = keep;
    do walk(E, &w);
    while ((double)w.h.attached + need > (double)val_budget_room() && let_go(E, &w));
}

void memo_make_room(silc_engine *E, double need)
{
    room_for_call(E, need, NULL);
}

void memo_free(silc_engine *E)
{
    eng_memo *M = E->memo;
    if (!M) return;
    while (M->n) drop(M, &M->slot[M->n - 1]);
    free(M);
    E->memo = NULL;
}
