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

int eng_cancel_check(silc_engine *E)
{
    char why[sizeof E->err];
    if (!E->cancel || !E->cancel(E->cancel_user, why, sizeof why)) return 0;
    return eng_error(E, "%s", why);
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

int eng_info_reserve(silc_engine *E, const char *name)
{
    if (!E || !name) return -1;
    if (!info_entry(E, name)) return eng_error(E, "out of memory recording info for '%s'", name);
    return 0;
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

void eng_pending_hold(eng_pending *p, const silc_call *call)
{
    eng_pending_release(p);
    p->A = val_retain((silc_value *)call->in[0]);
    p->B = val_retain((silc_value *)call->in[1]);
    p->X = val_retain(call->out);
}

void eng_pending_release(eng_pending *p)
{
    val_release(p->A);
    val_release(p->B);
    val_release(p->X);
    memset(p, 0, sizeof *p);
}
