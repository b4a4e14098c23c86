/*
 * context.c -- the state every layer of one engine shares: the error
 * buffer, output, warnings and the per-name records that `info` shows
 * (context.h says why these sit below the layers that report through them).
 */
#define _POSIX_C_SOURCE 200809L
#include "context.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void info_entry_free(eng_info_entry *e)
{
    free(e->name);
    free(e->info.statement);
    eng_pending_release(&e->info.pending);
    free(e);
}

void eng_info_free_all(silc_engine *E)
{
    eng_info_entry *e, *next;
    for (e = E->infos; e; e = next) {
        next = e->next;
        info_entry_free(e);
    }
    E->infos = NULL;
}

int eng_error(silc_engine *E, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(E->err, sizeof E->err, fmt, ap);
    va_end(ap);
    return -1;
}

int eng_oom(silc_engine *E)
{
    const char *why = val_refusal();
    return eng_error(E, "%s", *why ? why : "out of memory");
}

int eng_cancel_pending(silc_engine *E, char *why, size_t whylen)
{
    if (atomic_load_explicit(&E->interrupt, memory_order_relaxed)) {
        snprintf(why, whylen, "%s", ENG_INTERRUPTED);
        return 1;
    }
    return E->cancel && E->cancel(E->cancel_user, why, whylen) != 0;
}

int eng_cancel_check(silc_engine *E)
{
    char why[sizeof E->err];
    if (!eng_cancel_pending(E, why, sizeof why)) return 0;
    return eng_error(E, "%s", why);
}

void eng_interrupt(silc_engine *E)
{
    atomic_store_explicit(&E->interrupt, 1, memory_order_relaxed);
}

void eng_interrupt_clear(silc_engine *E)
{
    atomic_store_explicit(&E->interrupt, 0, memory_order_relaxed);
}

/* ---- snapshots ------------------------------------------------------------ */

/* The copy of a record holds its own references to the deferred backward
 * error's operands (and its own copy of the options), so the record it came
 * from may be replaced meanwhile.  -1 (p empty) when out of memory. */
static int pending_retain(eng_pending *p)
{
    if (p->options && !(p->options = util_strdup(p->options))) {
        memset(p, 0, sizeof *p);
        return -1;
    }
    if (p->A) val_retain(p->A);
    if (p->B) val_retain(p->B);
    if (p->X) val_retain(p->X);
    return 0;
}

static void infos_free(eng_info_entry *e)
{
    while (e) {
        eng_info_entry *next = e->next;
        info_entry_free(e);
        e = next;
    }
}

void eng_snapshot_free(eng_snapshot *s)
{
    size_t i;
    for (i = 0; i < s->n; i++) {
        free(s->bindings[i].name);
        val_release(s->bindings[i].value);
    }
    free(s->bindings);
    infos_free(s->infos);
    memset(s, 0, sizeof *s);
}

static int binding_order(const void *a, const void *b)
{
    return strcmp(((const eng_binding *)a)->name, ((const eng_binding *)b)->name);
}

int eng_snapshot_take(const silc_engine *E, eng_snapshot *s)
{
    size_t b;
    const store_entry *e;
    const eng_info_entry *ie;
    eng_info_entry **tail = &s->infos;
    memset(s, 0, sizeof *s);
    s->rand_state = E->rand_state;
    if (!(s->bindings = calloc(E->store.count + 1, sizeof *s->bindings))) goto oom;
    for (b = 0; b < E->store.nbuckets; b++)
        for (e = E->store.buckets[b]; e; e = e->next) {
            if (!(s->bindings[s->n].name = util_strdup(e->name))) goto oom;
            s->bindings[s->n++].value = val_retain(e->value);
        }
    qsort(s->bindings, s->n, sizeof *s->bindings, binding_order);
    for (ie = E->infos; ie; ie = ie->next) {
        eng_info_entry *c = calloc(1, sizeof *c);
        if (!c) goto oom;
        *tail = c;
        tail = &c->next;
        c->info = ie->info;
        c->info.statement = NULL;
        memset(&c->info.pending, 0, sizeof c->info.pending);
        if (!(c->name = util_strdup(ie->name))) goto oom;
        if (ie->info.statement && !(c->info.statement = util_strdup(ie->info.statement)))
            goto oom;
        c->info.pending = ie->info.pending;
        if (pending_retain(&c->info.pending)) goto oom;
    }
    return 0;
oom:
    eng_snapshot_free(s);
    return -1;
}

int eng_snapshot_restore(silc_engine *E, eng_snapshot *s)
{
    size_t b, i;
    int rc = 0;
    /* Names bound since the snapshot go, and the others get their old
     * values back; neither allocates (rebinding a bound name reuses its
     * entry), so a failure cannot leave the store half restored, except
     * for a name cleared meanwhile, which needs a new entry. */
    for (b = 0; b < E->store.nbuckets; b++) {
        store_entry *e = E->store.buckets[b], *next;
        for (; e; e = next) {
            eng_binding key;
            next = e->next;
            key.name = e->name;
            if (!bsearch(&key, s->bindings, s->n, sizeof *s->bindings, binding_order))
                store_remove(&E->store, e->name);
        }
    }
    for (i = 0; i < s->n; i++)
        if (store_get(&E->store, s->bindings[i].name) != s->bindings[i].value &&
            store_set(&E->store, s->bindings[i].name, s->bindings[i].value))
            rc = -1;
    eng_info_free_all(E);
    E->infos = s->infos;
    s->infos = NULL;
    E->rand_state = s->rand_state;
    eng_snapshot_free(s);
    return rc;
}

void eng_print(silc_engine *E, const char *text)
{
    if (!text) return;
    if (E && E->output) E->output(E->output_user, text);
    else fputs(text, stdout);
}

void eng_warn(silc_engine *E, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    sb_vprintf(&E->warnings, fmt, ap);
    va_end(ap);
    sb_puts(&E->warnings, "\n");
}

/* The record of name, made (empty) when absent; NULL when out of memory. */
static eng_info_entry *info_entry(silc_engine *E, const char *name)
{
    eng_info_entry *e;
    for (e = E->infos; e; e = e->next)
        if (strcmp(e->name, name) == 0) return e;
    e = calloc(1, sizeof *e);
    if (!e || !(e->name = util_strdup(name))) {
        free(e);
        return NULL;
    }
    e->next = E->infos;
    E->infos = e;
    return e;
}

eng_info *eng_info_make(silc_engine *E, const char *name)
{
    eng_info_entry *e;
    if (!E || !name) return NULL;
    if (!(e = info_entry(E, name))) {
        eng_error(E, "out of memory recording info for '%s'", name);
        return NULL;
    }
    return &e->info;
}

int eng_info_take(silc_engine *E, const char *name, eng_info *info)
{
    eng_info_entry *e;
    if (!E || !name || !info) return -1;
    if (!(e = info_entry(E, name))) {
        free(info->statement);
        eng_pending_release(&info->pending);
        return eng_error(E, "out of memory recording info for '%s'", name);
    }
    free(e->info.statement);
    eng_pending_release(&e->info.pending);
    e->info = *info;
    return 0;
}

int eng_info_set(silc_engine *E, const char *name, eng_info *info)
{
    eng_info copy;
    if (!E || !name || !info) return -1;
    copy = *info;
    if (info->statement && !(copy.statement = util_strdup(info->statement))) {
        eng_pending_release(&info->pending);
        return eng_error(E, "out of memory recording info for '%s'", name);
    }
    return eng_info_take(E, name, &copy);
}

eng_info *eng_info_get(const silc_engine *E, const char *name)
{
    eng_info_entry *e;
    if (!E || !name) return NULL;
    for (e = E->infos; e; e = e->next)
        if (strcmp(e->name, name) == 0) return &e->info;
    return NULL;
}

void eng_info_remove(silc_engine *E, const char *name)
{
    eng_info_entry **pe, *e;
    if (!E || !name) return;
    for (pe = &E->infos; *pe; pe = &(*pe)->next) {
        if (strcmp((*pe)->name, name) == 0) {
            e = *pe;
            *pe = e->next;
            info_entry_free(e);
            return;
        }
    }
}

int eng_pending_hold(eng_pending *p, const silc_call *call)
{
    eng_pending_release(p);
    if (call->options && !(p->options = util_strdup(call->options))) return -1;
    p->A = val_retain((silc_value *)call->in[0]);
    p->B = val_retain((silc_value *)call->in[1]);
    p->X = val_retain(call->out);
    p->op_class = call->op_class;
    p->sub = call->sub;
    return 0;
}

void eng_pending_release(eng_pending *p)
{
    val_release(p->A);
    val_release(p->B);
    val_release(p->X);
    free(p->options);
    memset(p, 0, sizeof *p);
}
