/*
 * scale.c -- power-of-two scaling of solves far from 1 in magnitude; see
 * accuracy.h for why it exists and why it is exact.
 */
#include "accuracy.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SCALE_KEY "core.scaled"
#define SCALE_LIMIT 64          /* scale when max |entry| is beyond 2^+-64 */

typedef struct scaled_copy {
    int e;
    silc_value *v;
} scaled_copy;

static void scaled_free(void *p)
{
    scaled_copy *c = p;
    if (!c) return;
    val_release(c->v);
    free(c);
}

/* The exponent that brings v's largest entry near 1, limited so that its
 * smallest nonzero entry stays a normal number; 0 when v is moderate. */
static int exponent_for(const silc_value *v)
{
    double maxabs = val_max_abs(v); /* a right-hand side needs no more than this scan */
    silc_view w;
    double minabs = INFINITY;
    int64_t i;
    int e, emin;
    if (!(maxabs > 0) || !isfinite(maxabs)) return 0;
    frexp(maxabs, &e);
    if (e >= -SCALE_LIMIT && e <= SCALE_LIMIT) return 0;
    val_view(v, &w);
    for (i = 0; i < w.nnz * val_width(v); i++) /* both parts of a complex entry */
        if (w.val[i] != 0 && fabs(w.val[i]) < minabs) minabs = fabs(w.val[i]);
    frexp(minabs, &emin);
    /* 2^-e scales the max to [0.5, 1); the smallest must stay >= DBL_MIN. */
    if (emin - e < DBL_MIN_EXP) e = emin - DBL_MIN_EXP;
    return -e;
}

/* 2^e v with v's storage and pattern. */
static silc_value *scaled(const silc_value *v, int e)
{
    silc_value *s;
    int64_t i;
    switch (v->format) {
    case SILC_FMT_DENSE: s = val_new_unset_field(SILC_FMT_DENSE, v->field, v->m, v->n, 0, 0, 0); break;
    case SILC_FMT_CSR:
        s = val_new_unset_field(SILC_FMT_CSR, v->field, v->m, v->n, v->nnz, 0, 0);
        if (s) {
            memcpy(s->rowptr, v->rowptr, (size_t)(v->m + 1) * sizeof *s->rowptr);
            memcpy(s->colind, v->colind, (size_t)v->nnz * sizeof *s->colind);
            val_csr_set_nnz(s, v->nnz);
        }
        break;
    default: s = val_new_unset_field(SILC_FMT_BAND, v->field, v->m, v->n, 0, v->kl, v->ku); break;
    }
    if (!s) return NULL;
    for (i = 0; i < v->nnz * val_width(v); i++) s->val[i] = ldexp(v->val[i], e);
    return s;
}

int scale_solve_begin(silc_engine *E, silc_call *call, scale_state *S)
{
    const silc_value *A = call->in[0], *B = call->in[1];
    memset(S, 0, sizeof *S);
    S->A = A;
    S->B = B;
    S->X0 = call->nin >= 3 ? call->in[2] : NULL;
    S->ea = exponent_for(A);
    S->eb = exponent_for(B);
    if (S->ea) {
        scaled_copy *c = val_attach_get(A, SCALE_KEY);
        if (!c || c->e != S->ea) {
            c = calloc(1, sizeof *c);
            if (!c || !(c->v = scaled(A, S->ea))) {
                free(c);
                return eng_error(E, "out of memory scaling a system of extreme magnitude");
            }
            c->e = S->ea;
            if (val_attach_set(A, SCALE_KEY, c, scaled_free)) {
                scaled_free(c);
                return eng_error(E, "out of memory scaling a system of extreme magnitude");
            }
        }
        call->in[0] = c->v;
    }
    if (S->eb) {
        if (!(S->Bs = scaled(B, S->eb))) {
            call->in[0] = A;
            return eng_error(E, "out of memory scaling a system of extreme magnitude");
        }
        call->in[1] = S->Bs;
    }
    if (S->X0 && S->ea != S->eb) {
        if (!(S->X0s = scaled(S->X0, S->eb - S->ea))) {
            call->in[0] = A;
            call->in[1] = B;
            val_release(S->Bs);
            S->Bs = NULL;
            return eng_error(E, "out of memory scaling a system of extreme magnitude");
        }
        call->in[2] = S->X0s;
    }
    return 0;
}

int scale_solve_end(silc_call *call, scale_state *S)
{
    silc_value *X = call->out;
    int64_t i;
    int was_finite;
    call->in[0] = S->A;
    call->in[1] = S->B;
    if (S->X0) call->in[2] = S->X0;
    val_release(S->Bs);
    val_release(S->X0s);
    S->Bs = S->X0s = NULL;
    if (!X || S->ea == S->eb) return 0;
    was_finite = !val_has_nonfinite(X);
    for (i = 0; i < X->nnz * val_width(X); i++) X->val[i] = ldexp(X->val[i], S->ea - S->eb);
    val_forget_caches(X); /* they described the scaled solution */
    return was_finite && val_has_nonfinite(X);
}
