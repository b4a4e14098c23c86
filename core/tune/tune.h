/*
 * tune.h -- the tuner (core/tune/, tuner.c): automatic performance tuning (issue 6): the seeds' thread-count
 * model f(p) = a/p + b*p + c, the choice of a solver backend under an
 * accuracy target, and the wisdom file that lets the next run start tuned.
 *
 * The evaluator feeds the tuner: lang_exec() reports every top-level EXEC
 * (its text and wall time) through tuner_observe(), ev_run() every solve
 * through tuner_note_solve(), and the `tune` statement lands in
 * tuner_command().  From the EXEC texts the tuner finds the time step (the
 * repeating period of the sequence, or explicit `tune step` marks), times
 * whole steps at sampled thread counts, fits the model and continues at
 * p_opt.  Everything is idle until `tune on` or tune.threads = auto.
 *
 * The pure pieces (fit, leave-one-out stopping rule, period detection,
 * backend ranking, wisdom file) are exposed so tests can drive them with
 * synthetic timings; nothing here asserts anything about real clocks.
 */
#ifndef SILC_TUNE_H
#define SILC_TUNE_H

#include <stdint.h>

#include "dispatch.h"

/* ---- the model ------------------------------------------------------------- */
typedef struct tuner_model {
    double a, b, c;        /* f(p) = a/p + b*p + c */
    double q;              /* residual sum of squares of the fit */
    int p_opt;             /* predicted best thread count, within [pmin, pmax] */
    double t_opt;          /* f(p_opt); the best measured time when guarded */
    int guarded;           /* a <= 0 or b <= 0: p_opt is the best measured point */
} tuner_model;

/* Least-squares fit of n >= 3 points (distinct p >= 1) by Householder QR of
 * the n x 3 matrix [1/p, p, 1].  p_opt is floor or ceil of sqrt(a/b),
 * whichever f rates faster, clamped to [pmin, pmax]; when a <= 0 or b <= 0 the
 * model has no interior minimum and p_opt is the point with the least measured
 * time.  Returns 0, or -1 for fewer than 3 points or a rank-deficient matrix. */
int tuner_fit(const double *p, const double *t, int n, int pmin, int pmax, tuner_model *m);
double tuner_model_eval(const tuner_model *m, double p);

/* The stopping rule for the number of sampled points: with n >= 4 points,
 * refit leaving each point out in turn; stable when every such fit's p_opt
 * costs, under the full fit, at most tol more than the full p_opt, and every
 * such fit predicts its own best time within tol of the full prediction.
 * Returns 1 stable, 0 not (yet). */
int tuner_loo_stable(const double *p, const double *t, int n, int pmin, int pmax, double tol);

/* Smallest period k <= maxk such that the last 3k hashes of h[0..n) repeat
 * with period k (the last 2k when k > maxk/2 would not fit 3k); 0 if none. */
int tuner_detect_period(const uint64_t *h, int n, int maxk);
uint64_t tuner_hash(const char *text);

/* ---- backend choice -------------------------------------------------------- */
typedef struct tuner_cand {
    char backend[64];
    char opts[64];         /* variant: an option string for <backend>.options ("-i cg"),
                              or "key = value" for <backend>.key; "" if none */
    double first, repeat;  /* seconds: a solve that factors, one that reuses */
    double berr;           /* backward error the core computed */
    int failed;            /* the backend declined or failed */
    double cost;           /* predicted cost of the rest of the run (set by tuner_rank) */
    char why[96];          /* "too inaccurate (2e-08 > 1e-10)", "fastest", ... */
} tuner_cand;

/* Ranks candidates for a class whose solves happen per_step times a step for
 * steps more steps; reuse says whether the matrix survives between steps (a
 * factorization is then paid once).  Fills cost and why; returns the index
 * of the winner, or -1 when no candidate meets the accuracy target. */
int tuner_rank(tuner_cand *c, int n, double accuracy, double steps, int per_step, int reuse);

/* ---- the engine hooks ------------------------------------------------------ */
/* After each top-level EXEC (lang_exec). */
void tuner_observe(silc_engine *E, const char *text, double seconds);
/* The same for an EXEC that began at util_now() = started: the clock is read
 * only when the tuner is on (a read is 70-80 ns in a VM). */
void tuner_observe_since(silc_engine *E, const char *text, double started);
/* After each iteration of a top-level `while` loop (ev): one whole step of
 * seconds, the loop identified by key. */
void tuner_loop_step(silc_engine *E, uint64_t key, double seconds);
/* After each solve that ran (ev_run); retains the operands while needed. */
void tuner_note_solve(silc_engine *E, const silc_call *call);
/* `tune WORD [number|"file"]`: on, off, status, step, forget, report, fit.
 * For fit, the points are given as np (p, t) pairs in xs. */
int tuner_command(silc_engine *E, const char *word, const double *xs, int nx, const char *arg);
/* Appends the tuner's view of a solve class to `explain` output. */
void tuner_explain(silc_engine *E, const silc_call *call, strbuf *b);
/* Why a solve is expected to be repeated, as far as the tuner knows: tuning
 * is on, `tune on N` announced N > 1 steps, and no whole step has been seen
 * yet (a matrix first seen in a later step is one that changed between
 * steps, which the one-shot rule fits); else NULL.  For E->solve_again. */
const char *tuner_solve_again(const silc_engine *E);
void tuner_free(silc_engine *E);

/* ---- internals exposed for tests and the bench ---------------------------- */
/* Candidate thread counts for a process that may run on `cores` CPUs and
 * use at most max_threads (tune.max_threads, default cores): 1, 2, 4, ... up
 * to the smaller of the two (and it itself); only when max_threads exceeds
 * cores, the oversubscribed points up to it (1.5x, 2x, 3x and 4x of cores
 * when cores <= 4, then max_threads).  Returns the count (<= 16). */
int tuner_candidates(int cores, int max_threads, int *out);
/* Machine key for wisdom: "<cpu model>|<cores>" with blanks as '_'. */
void tuner_machine(char *out, size_t len);
/* Wisdom file path: tune.wisdom, else $SILC_WISDOM, else ~/.cache/silc/wisdom. */
void tuner_wisdom_path(silc_engine *E, char *out, size_t len);
/* Expected length of the run in steps (0 = unknown); `tune on N` sets it. */
void tuner_expect_steps(silc_engine *E, int steps);
/* Thread-sampling parameters the bench varies: relative tolerance of the
 * leave-one-out rule and of the repeat rule, and the repeat cap. */
void tuner_set_rule(silc_engine *E, double loo_tol, double rep_tol, int max_repeats);

#endif
