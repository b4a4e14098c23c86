/*
 * test_memo.c -- the memo's table (core/lang/memo.c) against a model of
 * what it promises, written the plain way: a list of at most 64 keys
 * searched front to back, the least recently used evicted by a scan, a
 * result kept at a key's second sighting, a warned call's key dropped and
 * the keys naming a first sighting's result renamed to the kept one.  The
 * table finds keys through tag buckets and evicts from a use list (issue
 * 30: a scan of the 64 slots per lookup was a quarter of a small product's
 * fixed cost); this test drives memo_lookup / memo_note directly with
 * pseudo-random calls -- operands drawn with a skew so that keys come back
 * both within and beyond the table's reach, earlier results used as
 * operands so that renaming happens, a few warned calls -- and checks that
 * every lookup hands out exactly the value the model does, or nothing
 * when the model has nothing.  No clock, no plugin: values are 1 x 1
 * placeholders, only their ids matter.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "engine.h"
#include "lang.h"

#define MODEL_SLOTS 64 /* memo.c's MEMO_SLOTS: what a model of it must hold */

typedef struct model_slot {
    int op;
    uint64_t ids[2];
    silc_value *result; /* not a reference: the memo holds one */
    uint64_t first_id, used;
} model_slot;

static model_slot model[MODEL_SLOTS];
static int model_n;
static uint64_t model_clock;
static long model_renames; /* keys renamed: the sequence must make some */

static int model_find(int op, const uint64_t ids[2])
{
    for (int i = 0; i < model_n; i++)
        if (model[i].op == op && model[i].ids[0] == ids[0] && model[i].ids[1] == ids[1]) return i;
    return -1;
}

static void model_remove(int i)
{
    model[i] = model[--model_n];
}

static silc_value *model_lookup(int op, const uint64_t ids[2])
{
    int i = model_find(op, ids);
    if (i < 0 || !model[i].result) return NULL;
    model[i].used = ++model_clock;
    return model[i].result;
}

static void model_note(int op, const uint64_t ids[2], silc_value *result, int warned)
{
    int i = model_find(op, ids);
    if (warned) {
        if (i >= 0) model_remove(i);
        return;
    }
    if (i < 0) {
        if (model_n == MODEL_SLOTS) {
            int old = 0;
            for (int j = 1; j < model_n; j++)
                if (model[j].used < model[old].used) old = j;
            model_remove(old);
        }
        model[model_n].op = op;
        model[model_n].ids[0] = ids[0];
        model[model_n].ids[1] = ids[1];
        model[model_n].result = NULL;
        model[model_n].first_id = result->id;
        model[model_n].used = ++model_clock;
        model_n++;
        return;
    }
    model[i].used = ++model_clock;
    if (model[i].result) return;
    model[i].result = result;
    if (model[i].first_id && model[i].first_id != result->id) {
        uint64_t from = model[i].first_id;
        for (int j = 0; j < model_n; j++)
            for (int k = 0; k < 2; k++)
                if (model[j].ids[k] == from) {
                    model[j].ids[k] = result->id;
                    model_renames++;
                }
    }
    model[i].first_id = 0;
}

static uint64_t rng = 0x9E3779B97F4A7C15ull;

static unsigned next_random(unsigned below)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (unsigned)(rng % below);
}

/* An operand index skewed towards small numbers: some keys recur often,
 * others seldom enough to be evicted first. */
static unsigned skewed(unsigned below)
{
    unsigned a = next_random(below), b = next_random(below);
    return a < b ? a : b;
}

#define OPERANDS 10
#define STEPS 60000
#define KEEP_ALL (STEPS + OPERANDS)

int main(void)
{
    silc_engine *E = NULL;
    char err[512];
    static silc_value *alive[KEEP_ALL]; /* every value made, released at the end: ids are never reused */
    silc_value *operand[OPERANDS + 4];
    size_t nalive = 0;
    long hits = 0, misses = 0, mismatches = 0;
    if (eng_create(&E, NULL, err, sizeof err)) {
        fprintf(stderr, "eng_create: %s\n", err);
        return 1;
    }
    for (int i = 0; i < OPERANDS; i++) alive[nalive++] = operand[i] = val_dense_new(1, 1);
    for (int i = 0; i < 4; i++) operand[OPERANDS + i] = operand[i]; /* the last results, once there are some */
    for (long step = 0; step < STEPS; step++) {
        silc_call call;
        uint64_t ids[2];
        silc_value *got, *want;
        int op = next_random(2) ? SILC_OP_ADD : SILC_OP_MATMUL;
        memset(&call, 0, sizeof call);
        call.op = op;
        call.nin = 2;
        call.in[0] = operand[skewed(OPERANDS + 4)];
        call.in[1] = operand[skewed(OPERANDS)];
        call.alpha = 1;
        ids[0] = call.in[0]->id;
        ids[1] = call.in[1]->id;
        got = memo_lookup(E, &call);
        want = model_lookup(op, ids);
        if (got != want) mismatches++;
        if (got) {
            hits++;
            val_release(got); /* the memo's reference stays */
        } else {
            silc_value *result = val_dense_new(1, 1);
            int warned = next_random(50) == 0;
            if (!result || nalive == KEEP_ALL) break;
            alive[nalive++] = result;
            misses++;
            memo_note(E, &call, result, warned);
            model_note(op, ids, result, warned);
            /* results become operands: a chain whose first result the
             * memo renames to the kept one */
            operand[OPERANDS + step % 4] = result;
        }
    }
    printf("%ld lookups: %ld handed out, %ld computed, %ld keys renamed\n", hits + misses, hits, misses,
           model_renames);
    CHECK(mismatches == 0, "%ld of %ld lookups handed out another value than the model's", mismatches,
          hits + misses);
    /* The skew gives both: keys found again, and keys evicted before they
     * came back (so the table was full and evicting) */
    CHECK(hits > STEPS / 20 && misses > STEPS / 4, "hits %ld, misses %ld: the sequence tests too little", hits,
          misses);
    CHECK(model_renames > 0, "no key was renamed: the chains were not tested");
    CHECK(hits + misses == STEPS, "the run stopped early after %ld steps (out of memory)", hits + misses);
    memo_free(E);
    for (size_t i = 0; i < nalive; i++) val_release(alive[i]);
    eng_destroy(&E);
    return check_done();
}
