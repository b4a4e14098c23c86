/*
 * tuner.c -- automatic performance tuning: thread count by the seeds' model,
 * solver backend under an accuracy target, and wisdom (see tune.h).
 *
 * The tuner watches the stream of top-level EXEC texts.  A time-stepping
 * program repeats the same texts every step, so the smallest k for which the
 * last 3k texts repeat with period k is the step (or the program says so with
 * `tune step`).  Once two whole steps are seen the tuner (1) times whole steps
 * at candidate thread counts -- never more threads than the process may run
 * on unless tune.max_threads allows it -- keeping the minimum of m repeats,
 * until the leave-one-out rule says the fit is settled; (2) fits
 * f(p) = a/p + b*p + c and continues at p_opt; (3) times every loaded
 * backend that accepts each solve class of the step on copies of the live
 * matrices, factoring and back-solving separately, and picks the one with
 * the least predicted cost for the rest of the run among those meeting
 * tune.accuracy; (4) writes the result to the wisdom file, keyed by machine
 * and problem signature, so the next run with the same step skips straight
 * to the answer.
 *
 * The tuner pays for itself: what it spends beyond the program's own work
 * (steps sampled at a slower p, the backend trials) stays under tune.budget
 * of the run -- of the expected run when `tune on N` gave its length, else of
 * the time elapsed so far.  A sample or trial the budget cannot afford yet
 * waits until the run has lasted long enough (a run of unknown length that
 * stops early never paid more than its share); a sample already slower than
 * the best by more than the budget allows is not repeated.  A trial's cost
 * is predicted as two of the program's own slowest solves of the class (its
 * factorizations), or as the dearest trial so far if that was dearer.
 *
 * Thread counts change only between steps, so every timed step ran at one p.
 * Step times are the sum of the EXECs' own wall times: what SILC's thread
 * count can change, without the program's work between EXECs.
 */
#define _GNU_SOURCE /* sched_getaffinity, CPU_COUNT */
#include "tune.h"

#include <errno.h>
#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define T_HIST 192          /* EXEC hashes kept for period detection */
#define T_MAXK 48           /* longest period looked for */
#define T_MAXC 16           /* candidate thread counts */
#define T_MAXCLS 8          /* solve classes per step */
#define T_MAXB 16           /* candidate backends per class */
#define T_DEFAULT_STEPS 100 /* run length assumed for backend cost when unknown */

enum { PH_OFF, PH_WAIT, PH_WAIT2, PH_SAMPLE, PH_TRIALS, PH_DONE };

typedef struct t_point {
    int p;
    double tmin, t2;        /* least and second-least step time */
    int reps;
} t_point;

/* One solve class of a step: its live operands and, once tuned, the table. */
typedef struct t_class {
    char cls[40];
    silc_value *a, *b;      /* retained operands of the latest solve */
    silc_value *x0;         /* and its initial guess (solve.initial_guess), or NULL */
    uint64_t a_id;
    int count;              /* solves of this class in the step */
    int reuse;              /* the matrix kept its id from the previous step */
    char ran[64];           /* backend the program's solve used */
    int next;               /* trials: the next candidate to time */
    tuner_cand cand[T_MAXB];
    int ncand, winner;      /* winner -1: none met the accuracy target */
    char reason[320];
} t_class;

typedef struct tuner {
    int enabled, user_off;
    int in_command, step_mark, explicit_steps;
    /* period detection */
    uint64_t hist[T_HIST];
    int nhist, period, pos;
    uint64_t seq[T_MAXK];
    uint64_t step_hash;     /* running hash of the texts of the open step */
    int step_open, cur_p;
    double step_acc;
    int steps;              /* whole steps seen since tuning began */
    /* solves: of the running EXEC, of the open step, of the reference step */
    t_class pend[T_MAXCLS], cur[T_MAXCLS], ref[T_MAXCLS];
    int npend, ncur, nref;
    t_class tab[T_MAXCLS];  /* backend tables of the tuned classes, no operands */
    int ntab;
    t_class trial[T_MAXCLS]; /* classes whose backends are being timed, with operands */
    int ntrial;
    /* the account: what the run took, what tuning spent beyond it */
    double run_secs;        /* EXEC time of the whole steps seen since tuning began */
    double trial_secs;      /* wall time of the backend trials */
    int waiting;            /* sampling paused until the budget allows the next point */
    double trial_max;       /* the dearest trial so far */
    /* the slowest solve of each class since tuning was configured, steps or
     * not: the program's first solve factors before any step is seen */
    struct { char cls[40]; double secs; } slowest[T_MAXCLS];
    int nslowest;
    /* thread sampling */
    int phase;
    int cands[T_MAXC], ncands, ci;
    t_point pts[T_MAXC];
    int npts;
    double sample_total;
    int sample_steps;
    tuner_model model;
    int have_model, p_opt, from_wisdom;
    char choice[160];       /* why p_opt is not the model's, or "" */
    char stop[160];
    int expect_steps;
    double loo_tol, rep_tol;
    int max_rep;
    char signature[24];
    int progress;           /* a progress line is on the terminal */
    int wisdom_ignored;     /* `tune forget` in silcd: the operator's file is kept, not read */
} tuner;

/* ---- the model ------------------------------------------------------------- */

double tuner_model_eval(const tuner_model *m, double p)
{
    return m->a / p + m->b * p + m->c;
}

/* Householder QR of the n x 3 design matrix, then back substitution: better
 * conditioned than the normal equations when p spans 1..64. */
int tuner_fit(const double *p, const double *t, int n, int pmin, int pmax, tuner_model *m)
{
    double *A, *y, x[3], q = 0;
    int i, j, k, best = 0;
    memset(m, 0, sizeof *m);
    if (n < 3) return -1;
    A = malloc((size_t)n * 3 * sizeof *A);
    y = malloc((size_t)n * sizeof *y);
    if (!A || !y) {
        free(A), free(y);
        return -1;
    }
    for (i = 0; i < n; i++) {
        if (!(p[i] >= 1)) {
            free(A), free(y);
            return -1;
        }
        A[i] = 1.0 / p[i], A[n + i] = p[i], A[2 * n + i] = 1.0, y[i] = t[i];
    }
    for (k = 0; k < 3; k++) {
        double *col = A + (size_t)k * n, norm = 0, alpha, vtv;
        for (i = k; i < n; i++) norm += col[i] * col[i];
        norm = sqrt(norm);
        if (norm == 0) goto singular;
        alpha = col[k] > 0 ? -norm : norm;
        col[k] -= alpha;                     /* v = x - alpha e_k, stored in place */
        vtv = 0;
        for (i = k; i < n; i++) vtv += col[i] * col[i];
        for (j = k + 1; j < 3; j++) {
            double *cj = A + (size_t)j * n, s = 0;
            for (i = k; i < n; i++) s += col[i] * cj[i];
            s = 2 * s / vtv;
            for (i = k; i < n; i++) cj[i] -= s * col[i];
        }
        {
            double s = 0;
            for (i = k; i < n; i++) s += col[i] * y[i];
            s = 2 * s / vtv;
            for (i = k; i < n; i++) y[i] -= s * col[i];
        }
        col[k] = alpha;                      /* R's diagonal; below it is v, unused now */
        if (fabs(alpha) < 1e-12 * (fabs(A[0]) + 1)) goto singular;
    }
    for (k = 2; k >= 0; k--) {
        double s = y[k];
        for (j = k + 1; j < 3; j++) s -= A[(size_t)j * n + k] * x[j];
        x[k] = s / A[(size_t)k * n + k];
    }
    free(A), free(y);
    m->a = x[0], m->b = x[1], m->c = x[2];
    for (i = 0; i < n; i++) {
        double r = t[i] - tuner_model_eval(m, p[i]);
        q += r * r;
    }
    m->q = q;
    if (pmin < 1) pmin = 1;
    if (pmax < pmin) pmax = pmin;
    if (m->a > 0 && m->b > 0) {
        double s = sqrt(m->a / m->b);
        int lo = (int)floor(s), hi = (int)ceil(s);
        if (lo < pmin) lo = pmin;
        if (lo > pmax) lo = pmax;
        if (hi < pmin) hi = pmin;
        if (hi > pmax) hi = pmax;
        m->p_opt = tuner_model_eval(m, hi) < tuner_model_eval(m, lo) ? hi : lo;
        m->t_opt = tuner_model_eval(m, m->p_opt);
        return 0;
    }
    /* No interior minimum: trust the measurements, not the model. */
    m->guarded = 1;
    for (i = 1; i < n; i++)
        if (t[i] < t[best]) best = i;
    m->p_opt = (int)p[best];
    if (m->p_opt < pmin) m->p_opt = pmin;
    if (m->p_opt > pmax) m->p_opt = pmax;
    m->t_opt = t[best];
    return 0;
singular:
    free(A), free(y);
    return -1;
}

int tuner_loo_stable(const double *p, const double *t, int n, int pmin, int pmax, double tol)
{
    tuner_model full, part;
    double pp[T_MAXC * 4], tt[T_MAXC * 4];
    int i, j, k;
    if (n < 4 || n > T_MAXC * 4) return 0;
    if (tuner_fit(p, t, n, pmin, pmax, &full) || !(full.t_opt > 0)) return 0;
    for (i = 0; i < n; i++) {
        for (j = k = 0; j < n; j++)
            if (j != i) pp[k] = p[j], tt[k++] = t[j];
        if (tuner_fit(pp, tt, k, pmin, pmax, &part)) return 0;
        /* what choosing the reduced fit's answer would cost, by the full fit
         * (by the measurement when the full fit has no interior minimum) */
        if (part.p_opt != full.p_opt) {
            double cost = INFINITY;
            if (!full.guarded) cost = tuner_model_eval(&full, part.p_opt);
            else
                for (j = 0; j < n; j++)
                    if ((int)p[j] == part.p_opt) cost = t[j];
            if (cost > full.t_opt * (1 + tol)) return 0;
        }
        if (fabs(part.t_opt - full.t_opt) > tol * full.t_opt) return 0;
    }
    return 1;
}

/* ---- period detection ------------------------------------------------------ */

uint64_t tuner_hash(const char *text)
{
    return util_fnv1a(UTIL_FNV1A_START, text, strlen(text));
}

int tuner_detect_period(const uint64_t *h, int n, int maxk)
{
    int k, i;
    for (k = 1; k <= maxk; k++) {
        int need = 3 * k;
        if (need > n) need = 2 * k;   /* long periods: two repeats suffice */
        if (need > n) return 0;
        for (i = 0; i < need - k; i++)
            if (h[n - 1 - i] != h[n - 1 - i - k]) break;
        if (i == need - k) return k;
    }
    return 0;
}

/* ---- backend ranking -------------------------------------------------------- */

int tuner_rank(tuner_cand *c, int n, double accuracy, double steps, int per_step, int reuse)
{
    int i, best = -1;
    double solves;
    if (per_step < 1) per_step = 1;
    if (steps < 1) steps = 1;
    solves = steps * per_step;
    for (i = 0; i < n; i++) {
        if (c[i].failed) {
            c[i].cost = INFINITY;
            if (!c[i].why[0]) snprintf(c[i].why, sizeof c[i].why, "failed");
            continue;
        }
        /* a kept matrix is factored once; a new one every step */
        c[i].cost = reuse ? c[i].first + (solves - 1) * c[i].repeat
                          : steps * (c[i].first + (per_step - 1) * c[i].repeat);
        if (!(c[i].berr <= accuracy)) {
            snprintf(c[i].why, sizeof c[i].why, "too inaccurate (%.2g > %.2g)", c[i].berr, accuracy);
            continue;
        }
        if (best < 0 || c[i].cost < c[best].cost) best = i;
    }
    for (i = 0; i < n; i++) {
        if (c[i].failed || !(c[i].berr <= accuracy)) continue;
        if (i == best)
            snprintf(c[i].why, sizeof c[i].why, "fastest accurate");
        else
            snprintf(c[i].why, sizeof c[i].why, "%.2fx the winner's cost", c[i].cost / c[best].cost);
    }
    return best;
}

/* ---- machine, candidates, configuration ------------------------------------ */

/* The CPUs this process may run on (its affinity mask: taskset, a cgroup's
 * cpuset), not the machine's: past them a step measures oversubscription,
 * 10-25x slower on a 2-core box (docs/tuner.md). */
static int cores(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) == 0) {
        int c = CPU_COUNT(&set);
        if (c >= 1 && (n < 1 || c < n)) n = c;
    }
    return n < 1 ? 1 : n > 4096 ? 4096 : (int)n;
}

int tuner_candidates(int ncores, int max_threads, int *out)
{
    int n = 0, p, i, top = max_threads < ncores ? max_threads : ncores;
    static const int over[] = {3, 4, 6, 8};   /* halves of the core count: 1.5x .. 4x */
    if (top < 1) top = 1;
    for (p = 1; p < top && n < T_MAXC - 5; p *= 2) out[n++] = p;
    out[n++] = top;
    if (max_threads > ncores) {
        if (ncores <= 4)
            for (i = 0; i < 4; i++) {
                int q = over[i] * ncores / 2;
                if (q > out[n - 1] && q <= max_threads) out[n++] = q;
            }
        if (out[n - 1] < max_threads && n < T_MAXC) out[n++] = max_threads;
    }
    return n;
}

void tuner_machine(char *out, size_t len)
{
    char line[512], model[256] = "unknown-cpu";
    FILE *f = fopen("/proc/cpuinfo", "r");
    size_t i;
    if (f) {
        while (fgets(line, sizeof line, f)) {
            char *colon = strchr(line, ':');
            if (!strncmp(line, "model name", 10) && colon) {
                char *s = colon + 1;
                while (*s == ' ' || *s == '\t') s++;
                snprintf(model, sizeof model, "%s", s);
                break;
            }
        }
        fclose(f);
    }
    model[strcspn(model, "\r\n")] = 0;
    for (i = 0; model[i]; i++)
        if (model[i] == ' ' || model[i] == '\t' || model[i] == '|') model[i] = '_';
    snprintf(out, len, "%s|%d", model, cores());
}

void tuner_wisdom_path(silc_engine *E, char *out, size_t len)
{
    const char *p = cfg_get(E, "tune.wisdom"), *home;
    if (p && *p) {
        snprintf(out, len, "%s", p);
        return;
    }
    p = getenv("SILC_WISDOM");
    if (p && *p) {
        snprintf(out, len, "%s", p);
        return;
    }
    home = getenv("HOME");
    snprintf(out, len, "%s/.cache/silc/wisdom", home && *home ? home : ".");
}

static double cfg_number(silc_engine *E, const char *key, double def)
{
    const char *v = cfg_get(E, key);
    char *end;
    double x;
    if (!v) return def;
    x = strtod(v, &end);
    return end != v && !*end ? x : def;
}

/* tune.max_threads: the most threads a sample may use (default: the CPUs
 * the process may run on). */
static int max_threads(silc_engine *E)
{
    const char *v = cfg_get(E, "tune.max_threads");
    char *end;
    long n;
    if (!v || !strcmp(v, "auto")) return cores();
    n = strtol(v, &end, 10);
    return end != v && !*end && n >= 1 && n <= 4096 ? (int)n : cores();
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static tuner *tuner_get(silc_engine *E)
{
    tuner *T = E->tuner;
    if (T) return T;
    T = calloc(1, sizeof *T);
    if (!T) return NULL;
    T->ncands = tuner_candidates(cores(), cores(), T->cands);
    T->loo_tol = 0.02;
    T->rep_tol = 0.02;
    T->max_rep = 4;
    T->p_opt = E->threads;
    E->tuner = T;
    return T;
}

void tuner_expect_steps(silc_engine *E, int steps)
{
    tuner *T = tuner_get(E);
    if (T) T->expect_steps = steps > 0 ? steps : 0;
}

const char *tuner_solve_again(const silc_engine *E)
{
    const tuner *T = E->tuner;
    return T && T->enabled && T->expect_steps > 1 && T->steps == 0 ? "in the first step of a run `tune on N` "
                                                                      "said repeats"
                                                                    : NULL;
}

void tuner_set_rule(silc_engine *E, double loo_tol, double rep_tol, int max_repeats)
{
    tuner *T = tuner_get(E);
    if (!T) return;
    if (loo_tol > 0) T->loo_tol = loo_tol;
    if (rep_tol > 0) T->rep_tol = rep_tol;
    if (max_repeats >= 1) T->max_rep = max_repeats;
}

/* ---- solve records ---------------------------------------------------------- */

static void classes_clear(t_class *c, int *n)
{
    int i;
    for (i = 0; i < *n; i++) val_release(c[i].a), val_release(c[i].b), val_release(c[i].x0);
    memset(c, 0, sizeof *c * (size_t)*n);
    *n = 0;
}

static t_class *class_find(t_class *c, int n, const char *cls)
{
    int i;
    for (i = 0; i < n; i++)
        if (!strcmp(c[i].cls, cls)) return &c[i];
    return NULL;
}

/* Moves the running EXEC's solves into the open step (latest operands win). */
static void pend_merge(tuner *T)
{
    int i;
    for (i = 0; i < T->npend; i++) {
        t_class *p = &T->pend[i], *c = class_find(T->cur, T->ncur, p->cls);
        if (!c && T->ncur < T_MAXCLS) {
            c = &T->cur[T->ncur++];
            memset(c, 0, sizeof *c);
            snprintf(c->cls, sizeof c->cls, "%s", p->cls);
        }
        if (!c) continue;
        val_release(c->a), val_release(c->b), val_release(c->x0);
        c->a = p->a, c->b = p->b, c->x0 = p->x0, c->a_id = p->a_id;
        p->a = p->b = p->x0 = NULL;
        c->count += p->count;
        snprintf(c->ran, sizeof c->ran, "%s", p->ran);
    }
    classes_clear(T->pend, &T->npend);
}

/* The slowest solve of class cls seen so far (0 if none). */
static double *slowest(tuner *T, const char *cls)
{
    int i;
    for (i = 0; i < T->nslowest; i++)
        if (!strcmp(T->slowest[i].cls, cls)) return &T->slowest[i].secs;
    if (T->nslowest == T_MAXCLS) return NULL;
    snprintf(T->slowest[T->nslowest].cls, sizeof T->slowest[0].cls, "%s", cls);
    T->slowest[T->nslowest].secs = 0;
    return &T->slowest[T->nslowest++].secs;
}

void tuner_note_solve(silc_engine *E, const silc_call *call)
{
    tuner *T = E->tuner;
    const char *chain[4];
    t_class *c;
    double *worst;
    if (!T && cfg_get(E, "tune.threads")) T = tuner_get(E);
    if (!T || call->nin < 2 || disp_classes(E, call, chain) < 1) return;
    if (call->report && (worst = slowest(T, chain[0])) && call->report->seconds > *worst)
        *worst = call->report->seconds;
    if (!T->enabled || T->phase == PH_DONE) return;
    c = class_find(T->pend, T->npend, chain[0]);
    if (!c) {
        if (T->npend >= T_MAXCLS) return;
        c = &T->pend[T->npend++];
        memset(c, 0, sizeof *c);
        snprintf(c->cls, sizeof c->cls, "%s", chain[0]);
    }
    val_release(c->a), val_release(c->b), val_release(c->x0);
    c->a = val_retain((silc_value *)call->in[0]);
    c->b = val_retain((silc_value *)call->in[1]);
    c->x0 = call->nin >= 3 && call->in[2] ? val_retain((silc_value *)call->in[2]) : NULL;
    c->a_id = call->in[0]->id;
    c->count++;
    if (call->report) snprintf(c->ran, sizeof c->ran, "%s", call->report->backend);
}

/* ---- progress and wisdom ----------------------------------------------------- */

static void progress(tuner *T, int done)
{
    if (!isatty(2)) return;
    if (done) {
        if (T->progress) fputc('\n', stderr);
        T->progress = 0;
        return;
    }
    fprintf(stderr, "\rtune: step %d, sampling p = %d (point %d of at most %d)   ", T->steps,
            T->cands[T->ci], T->ci + 1, T->ncands);
    fflush(stderr);
    T->progress = 1;
}

/* Problem signature: the step's statement sequence, then each solve class
 * with its sizes and nnz (the structure class is in the class name). */
static void signature(tuner *T)
{
    uint64_t h = T->step_hash;
    char buf[160];
    int i;
    for (i = 0; i < T->ncur; i++) {
        const t_class *c = &T->cur[i];
        snprintf(buf, sizeof buf, "%s %lldx%lld nnz %lld rhs %lld", c->cls, (long long)c->a->m,
                 (long long)c->a->n, (long long)val_props_part(c->a, SILC_PROPS_SHAPE)->nnz,
                 (long long)c->b->n);
        h = (h ^ tuner_hash(buf)) * 1099511628211ull;
    }
    snprintf(T->signature, sizeof T->signature, "%016llx", (unsigned long long)h);
}

static int mkdirs_for(const char *path)
{
    char dir[1024];
    char *s;
    snprintf(dir, sizeof dir, "%s", path);
    for (s = dir + 1; *s; s++) {
        if (*s != '/') continue;
        *s = 0;
        if (mkdir(dir, 0755) && errno != EEXIST) return -1;
        *s = '/';
    }
    return 0;
}

/* Rewrites the wisdom file without this machine+signature's lines, then
 * appends the current results. */
static void wisdom_write(silc_engine *E, tuner *T)
{
    char path[1024], machine[300], prefix[400], line[4096];
    cfg_file place;
    FILE *in, *out;
    strbuf b;
    int i;
    tuner_wisdom_path(E, path, sizeof path);
    tuner_machine(machine, sizeof machine);
    snprintf(prefix, sizeof prefix, "%s\t%s\t", machine, T->signature);
    if (mkdirs_for(path) || cfg_file_write_operator(E, "tune", path, &place)) return;
    if (!(out = fdopen(place.fd, "w"))) {
        cfg_file_close(&place);
        return;
    }
    place.fd = -1; /* out owns it now */
    fputs("# silc wisdom v1: machine, signature, then 'threads' p_opt a b c q samples\n"
          "# (p:seconds:repeats, comma separated) or 'backend' class winner\n", out);
    in = fopen(path, "r");
    if (in) {
        while (fgets(line, sizeof line, in))
            if (line[0] != '#' && strncmp(line, prefix, strlen(prefix))) fputs(line, out);
        fclose(in);
    }
    sb_init(&b);
    sb_printf(&b, "%sthreads\t%d\t%.9g %.9g %.9g %.9g\t", prefix, T->p_opt, T->model.a, T->model.b,
              T->model.c, T->model.q);
    for (i = 0; i < T->npts; i++)
        sb_printf(&b, "%s%d:%.9g:%d", i ? "," : "", T->pts[i].p, T->pts[i].tmin, T->pts[i].reps);
    if (!T->npts) sb_puts(&b, "-");
    sb_puts(&b, "\n");
    fputs(sb_str(&b), out);
    sb_free(&b);
    for (i = 0; i < T->ntab; i++)
        if (T->tab[i].ncand && T->tab[i].winner >= 0)
            fprintf(out, "%sbackend\t%s\t%s\t%s\n", prefix, T->tab[i].cls,
                    T->tab[i].cand[T->tab[i].winner].backend, T->tab[i].cand[T->tab[i].winner].opts);
    /* a failed write discards the temporary and keeps the old file */
    if (fclose(out)) cfg_file_close(&place);
    else cfg_file_commit(E, "tune", path, &place);
}

/* The setting a variant stands for: an option string ("-i cg -p none") is
 * <backend>.options, "key = value" is <backend>.key.  Returns the value. */
static const char *variant_setting(const char *backend, const char *opts, char *key, size_t keylen)
{
    const char *eq = opts[0] != '-' ? strchr(opts, '=') : NULL;
    size_t klen;
    if (!eq) {
        snprintf(key, keylen, "%s.options", backend);
        return opts;
    }
    for (klen = (size_t)(eq - opts); klen > 0 && opts[klen - 1] == ' '; klen--) continue;
    snprintf(key, keylen, "%s.%.*s", backend, (int)klen, opts);
    for (eq++; *eq == ' '; eq++) continue;
    return eq;
}

/* Sets dispatch.<cls> (and the plugin's setting for a variant); returns 1
 * if that changes what runs. */
static int apply_winner(silc_engine *E, const char *cls, const tuner_cand *w, const char *ran)
{
    char key[80];
    if (!strcmp(w->backend, ran) && !w->opts[0]) return 0;
    snprintf(key, sizeof key, "dispatch.%s", cls);
    if (cfg_set(E, CFG_SCOPE_SESSION, key, w->backend)) return 0;
    if (w->opts[0]) {
        const char *value = variant_setting(w->backend, w->opts, key, sizeof key);
        cfg_set(E, CFG_SCOPE_SESSION, key, value);
    }
    return 1;
}

/* Parses a 'threads' record's fields into T's samples and model. */
static int wisdom_parse_threads(tuner *T, char *fields)
{
    char *tok, *save;
    int p, used = 0;
    if (sscanf(fields, "%d %lg %lg %lg %lg %n", &p, &T->model.a, &T->model.b, &T->model.c,
               &T->model.q, &used) != 5 || !used)
        return -1;
    T->p_opt = p;
    T->npts = 0;
    for (tok = strtok_r(fields + used, ",\r\n", &save); tok && T->npts < T_MAXC;
         tok = strtok_r(NULL, ",\r\n", &save)) {
        t_point *pt = &T->pts[T->npts];
        if (sscanf(tok, "%d:%lg:%d", &pt->p, &pt->tmin, &pt->reps) == 3) T->npts++;
    }
    T->model.p_opt = p;
    T->model.t_opt = tuner_model_eval(&T->model, p);
    T->model.guarded = !(T->model.a > 0 && T->model.b > 0);
    T->have_model = T->npts >= 3;
    return 0;
}

/* Looks up this machine's record for signature sig (NULL: the last threads
 * record of this machine, for `silc tune report`).  Applies backends when
 * apply is set.  Returns 1 if a threads record was found. */
static int wisdom_read(silc_engine *E, tuner *T, const char *sig, int apply)
{
    char path[1024], machine[300], line[4096];
    FILE *f;
    int found = 0;
    size_t ml;
    if (T->wisdom_ignored) return 0;
    tuner_wisdom_path(E, path, sizeof path);
    tuner_machine(machine, sizeof machine);
    ml = strlen(machine);
    f = fopen(path, "r");
    if (!f) return 0;
    while (fgets(line, sizeof line, f)) {
        char *s, *kind, *rest;
        if (line[0] == '#' || strncmp(line, machine, ml) || line[ml] != '\t') continue;
        s = line + ml + 1;
        kind = strchr(s, '\t');
        if (!kind) continue;
        *kind++ = 0;
        if (sig && strcmp(s, sig)) continue;
        rest = strchr(kind, '\t');
        if (!rest) continue;
        *rest++ = 0;
        if (!strcmp(kind, "threads")) {
            if (!wisdom_parse_threads(T, rest)) {
                found = 1;
                snprintf(T->signature, sizeof T->signature, "%s", s);
            }
        } else if (!strcmp(kind, "backend") && apply && T->ntab < T_MAXCLS) {
            t_class *c = &T->tab[T->ntab];
            char *w = strchr(rest, '\t'), *o;
            if (!w) continue;
            *w++ = 0;
            w[strcspn(w, "\r\n")] = 0;
            o = strchr(w, '\t');
            if (o) *o++ = 0;
            memset(c, 0, sizeof *c);
            snprintf(c->cls, sizeof c->cls, "%s", rest);
            snprintf(c->cand[0].backend, sizeof c->cand[0].backend, "%s", w);
            snprintf(c->cand[0].opts, sizeof c->cand[0].opts, "%s", o ? o : "");
            if (!ld_find(E, w) || !apply_winner(E, rest, &c->cand[0], "")) continue;
            snprintf(c->reason, sizeof c->reason, "%s%s%s, from the wisdom file", w, o && *o ? " " : "",
                     o ? o : "");
            c->winner = -1;
            T->ntab++;
        }
    }
    fclose(f);
    return found;
}

/* ---- backend trials ------------------------------------------------------------ */

/* A copy under a new id: trials factor afresh instead of finding the
 * program's attached factorization. */
static silc_value *val_copy(const silc_value *v)
{
    silc_value *c = NULL;
    if (v->format == SILC_FMT_CSR) {
        c = val_csr_new(v->m, v->n, v->nnz);
        if (c) {
            memcpy(c->rowptr, v->rowptr, (size_t)(v->m + 1) * sizeof *v->rowptr);
            memcpy(c->colind, v->colind, (size_t)v->nnz * sizeof *v->colind);
            memcpy(c->val, v->val, (size_t)v->nnz * sizeof *v->val);
            val_csr_set_nnz(c, v->nnz);
        }
    } else {
        c = v->format == SILC_FMT_BAND ? val_band_new(v->m, v->n, v->kl, v->ku)
                                       : val_dense_new(v->m, v->n);
        if (c) memcpy(c->val, v->val, (size_t)v->nnz * sizeof *v->val);
    }
    return c;
}

static int trial_solve(silc_engine *E, const silc_value *a, const silc_value *b, const silc_value *x0,
                       const char *opts, silc_report *rep)
{
    silc_call call;
    int rc;
    memset(&call, 0, sizeof call);
    memset(rep, 0, sizeof *rep);
    rep->cond_est = rep->rcond = -1;
    call.op = SILC_OP_SOLVE;
    call.nin = 2;
    call.in[0] = a;
    call.in[1] = b;
    if (x0) call.in[2] = x0, call.nin = 3;
    call.options = opts;
    call.report = rep;
    rc = disp_run(E, &call);
    if (call.out) val_release(call.out);
    return rc || !call.out;
}

/* Variants tried for a backend, in classes starting with cls (NULL: all).
 * The iterative plugins' defaults alone would judge the method by one
 * preconditioner; the direct ones are also tried at mixed precision (a
 * single-precision factor refined to double: faster, and as accurate while
 * cond < 1 / eps_single, which the measured backward error checks).  SA-AMG
 * is tried on SPD classes only: it refuses unsymmetric matrices.  opts ""
 * is the backend's defaults; see variant_setting for the rest. */
static const struct {
    const char *backend, *cls, *opts;
} variants[] = {
    {"lis-style", NULL, "-i cg -p none"}, {"lis-style", NULL, "-i cg -p ilu"},
    {"lis-style", NULL, "-i bicgstab -p ilu"}, {"lis-style", "solve.sparse.spd", "-i cg -p saamg"},
    {"petsc", NULL, "-ksp_type cg -pc_type icc"},
    {"petsc", NULL, "-ksp_type gmres -pc_type ilu"},
    {"lapack", "solve.dense", ""}, {"lapack", "solve.dense", "precision = mixed"},
    {"mumps", "solve.sparse", ""}, {"mumps", "solve.sparse", "precision = single"},
};

/* Times candidate k of class c: a solve that factors, then one that reuses. */
static void trial_one(silc_engine *E, t_class *c, tuner_cand *k)
{
    silc_value *a;
    silc_report r1, r2;
    char opts[200];
    if (k->opts[0]) {
        char key[80];
        const char *value = variant_setting(k->backend, k->opts, key, sizeof key);
        snprintf(opts, sizeof opts, "backend = %s; %s = %s", k->backend, key, value);
    } else {
        snprintf(opts, sizeof opts, "backend = %s", k->backend);
    }
    a = val_copy(c->a);
    if (!a) {
        k->failed = 1;
        snprintf(k->why, sizeof k->why, "out of memory copying the matrix");
        return;
    }
    /* The repeat starts from the program's initial guess when it gave one
     * (the previous step's solution): what an iterative backend would do in
     * the loop, against a direct one's back-substitution. */
    if (trial_solve(E, a, c->b, NULL, opts, &r1) || trial_solve(E, a, c->b, c->x0, opts, &r2)) {
        k->failed = 1;
        snprintf(k->why, sizeof k->why, "failed: %.80s", E->err);
    } else {
        k->first = r1.seconds;
        k->repeat = r2.seconds < r1.seconds ? r2.seconds : r1.seconds;
        k->berr = r1.backward_error > r2.backward_error ? r1.backward_error : r2.backward_error;
    }
    val_release(a);
}

/* Lists the candidates of class c (every loaded backend that accepts its
 * operands, with the variants above) without timing any. */
static void plan_class(silc_engine *E, t_class *c)
{
    const char **names = NULL;
    size_t nn = ld_backend_names(E, &names), i, v;
    silc_call probe;
    c->ncand = c->next = 0;
    memset(&probe, 0, sizeof probe);
    probe.op = SILC_OP_SOLVE;
    probe.nin = 2;
    probe.in[0] = c->a;
    probe.in[1] = c->b;
    probe.op_class = c->cls;
    for (i = 0; i < nn && c->ncand < T_MAXB; i++) {
        const ld_backend *lb = ld_find(E, names[i]);
        const silc_op_entry *op;
        const char *why = NULL;
        int nv = 0;
        if (!lb || lb->backend->n_ops <= SILC_OP_SOLVE) continue;
        op = &lb->backend->ops[SILC_OP_SOLVE];
        if (!op->run || (op->accepts && !op->accepts(&probe, &why))) continue;
        for (v = 0; v <= sizeof variants / sizeof variants[0] && c->ncand < T_MAXB; v++) {
            const char *opts;
            tuner_cand *k;
            if (v < sizeof variants / sizeof variants[0]) {
                if (strcmp(variants[v].backend, names[i]) ||
                    (variants[v].cls && strncmp(c->cls, variants[v].cls, strlen(variants[v].cls))))
                    continue;
                opts = variants[v].opts;
            } else if (!nv) {
                opts = ""; /* no variant listed: the backend's defaults */
            } else {
                break;
            }
            k = &c->cand[c->ncand++];
            memset(k, 0, sizeof *k);
            snprintf(k->backend, sizeof k->backend, "%s", names[i]);
            snprintf(k->opts, sizeof k->opts, "%s", opts);
            nv++;
        }
    }
    free(names);
}

/* The user's own dispatch.<cls> wins over the tuner: it is reported, not
 * overridden. */
static int user_set(silc_engine *E, t_class *c)
{
    char key[80];
    size_t len = strlen(c->reason);
    snprintf(key, sizeof key, "dispatch.%s", c->cls);
    if (!cfg_get(E, key)) return 0;
    snprintf(c->reason + len, sizeof c->reason - len, "; not applied: %s is set in the configuration",
             key);
    return 1;
}

/* Every candidate of c timed: rank them, apply the winner, keep the table. */
static void judge_class(silc_engine *E, tuner *T, t_class *c)
{
    double steps = T->expect_steps > T->steps ? T->expect_steps - T->steps : T_DEFAULT_STEPS;
    double acc = cfg_number(E, "tune.accuracy", 1e-10);
    c->winner = tuner_rank(c->cand, c->ncand, acc, steps, c->count, c->reuse);
    if (c->winner < 0) {
        snprintf(c->reason, sizeof c->reason,
                 "no candidate met tune.accuracy = %.2g; dispatch left as configured", acc);
    } else {
        snprintf(c->reason, sizeof c->reason,
                 "%s%s%s: least predicted cost (%.3g s) for %.0f more steps x %d solve(s), factor %s, "
                 "among backends with backward error <= %.2g",
                 c->cand[c->winner].backend, c->cand[c->winner].opts[0] ? " " : "",
                 c->cand[c->winner].opts, c->cand[c->winner].cost, steps, c->count,
                 c->reuse ? "once (matrix kept)" : "every step (matrix changes)", acc);
        if (!user_set(E, c)) apply_winner(E, c->cls, &c->cand[c->winner], c->ran);
    }
    if (T->ntab < T_MAXCLS) {
        T->tab[T->ntab] = *c;
        T->tab[T->ntab].a = T->tab[T->ntab].b = T->tab[T->ntab].x0 = NULL;
        T->ntab++;
    }
}

/* ---- the budget ------------------------------------------------------------------ */

static double best_time(const tuner *T, int *best_p)
{
    double best = INFINITY;
    int i;
    if (best_p) *best_p = T->npts ? T->pts[0].p : 1;
    for (i = 0; i < T->npts; i++)
        if (T->pts[i].tmin < best) {
            best = T->pts[i].tmin;
            if (best_p) *best_p = T->pts[i].p;
        }
    return best;
}

/* What tuning has cost beyond the program's own work: the sampled steps'
 * time over the best p's, and the trials. */
static double spent(const tuner *T)
{
    double best = best_time(T, NULL), excess = T->npts ? T->sample_total - T->sample_steps * best : 0;
    return (excess > 0 ? excess : 0) + T->trial_secs;
}

/* What tuning may have cost by now: tune.budget of the expected run when
 * `tune on N` gave its length, else of the run so far. */
static double allowance(silc_engine *E, const tuner *T)
{
    double budget = cfg_number(E, "tune.budget", 0.05), per_step = T->steps ? T->run_secs / T->steps : 0;
    if (T->expect_steps > 0) return budget * T->expect_steps * per_step;
    return budget * T->run_secs;
}

/* Times pending trials while the budget affords them (predicted: two of
 * the program's slowest solves of the class); judges each class whose
 * candidates are all timed.  Returns 1 when every class is judged. */
static int run_trials(silc_engine *E, tuner *T)
{
    char err[sizeof E->err];
    size_t wlen = E->warnings.len;
    int i, done = 1, wfailed = E->warnings.failed;
    memcpy(err, E->err, sizeof err);
    for (i = 0; i < T->ntrial; i++) {
        t_class *c = &T->trial[i];
        while (c->next < c->ncand) {
            const double *worst = slowest(T, c->cls);
            double t0, took, predicted = 2 * (worst && *worst > 0 ? *worst : 1e-6);
            if (T->trial_max > predicted) predicted = T->trial_max;
            if (spent(T) + predicted > allowance(E, T)) break;
            t0 = now();
            trial_one(E, c, &c->cand[c->next++]);
            took = now() - t0;
            T->trial_secs += took;
            if (took > T->trial_max) T->trial_max = took;
        }
        if (c->next < c->ncand) done = 0;
        else if (c->a) {
            judge_class(E, T, c);
            val_release(c->a), val_release(c->b), val_release(c->x0);
            c->a = c->b = c->x0 = NULL;
        }
    }
    memcpy(E->err, err, sizeof err);
    if (E->warnings.s && E->warnings.len > wlen) {
        E->warnings.len = wlen;
        E->warnings.s[wlen] = 0;
    }
    E->warnings.failed = wfailed;   /* the trials' warnings are dropped, their failures too */
    return done;
}

/* ---- thread sampling ----------------------------------------------------------- */

static void points(const tuner *T, double *p, double *t)
{
    int i;
    for (i = 0; i < T->npts; i++) p[i] = T->pts[i].p, t[i] = T->pts[i].tmin;
}

/* The tuning is over: forget the operands, keep the answer. */
static void done(silc_engine *E, tuner *T)
{
    T->phase = PH_DONE;
    classes_clear(T->trial, &T->ntrial);
    wisdom_write(E, T);
}

/* Thread sampling is over: continue at p_opt, then time the backends. */
static void finish(silc_engine *E, tuner *T, const char *why)
{
    double p[T_MAXC], t[T_MAXC];
    int i, lo = 1 << 30, hi = 1, best = 0;
    points(T, p, t);
    for (i = 0; i < T->npts; i++) {
        if (T->pts[i].p < lo) lo = T->pts[i].p;
        if (T->pts[i].p > hi) hi = T->pts[i].p;
        if (t[i] < t[best]) best = i;
    }
    T->have_model = T->npts >= 3 && !tuner_fit(p, t, T->npts, lo, hi, &T->model);
    T->choice[0] = 0;
    if (T->have_model) {
        /* A measurement beats the model where there is one: the model's p_opt
         * is judged by its own sample when it was sampled, else by f, and the
         * best sample wins if it was faster.  This matters when f cannot
         * follow the data (past the core count OpenMP's time jumps instead of
         * growing like b p) and puts sqrt(a/b) on the wrong side of a sample. */
        double est = tuner_model_eval(&T->model, T->model.p_opt);
        int measured = 0;
        for (i = 0; i < T->npts; i++)
            if (T->pts[i].p == T->model.p_opt) est = t[i], measured = 1;
        T->p_opt = T->model.p_opt;
        if (T->npts && t[best] < est && T->pts[best].p != T->model.p_opt) {
            T->p_opt = T->pts[best].p;
            snprintf(T->choice, sizeof T->choice,
                     "the best sample (p = %d, %.6g s) beat the model's p_opt = %d (%.6g s %s)",
                     T->p_opt, t[best], T->model.p_opt, est, measured ? "measured" : "predicted");
        }
    } else if (T->npts) {
        T->p_opt = T->pts[best].p;
    }
    snprintf(T->stop, sizeof T->stop, "%s", why);
    T->waiting = 0;
    progress(T, 1);
    ld_set_threads(E, T->p_opt);
    classes_clear(T->ref, &T->nref);
    T->phase = PH_TRIALS;
    if (run_trials(E, T)) done(E, T);
    else wisdom_write(E, T); /* the threads' answer, while the backends wait for the budget */
}

/* Whether the budget affords the next thread count's sample now. */
static int next_affordable(silc_engine *E, tuner *T, const t_point *pt)
{
    double p[T_MAXC], t[T_MAXC], best = best_time(T, NULL), next_t = pt->tmin;
    tuner_model m;
    points(T, p, t);
    if (T->ci + 1 < T->ncands && T->npts >= 3 && !tuner_fit(p, t, T->npts, 1, 1 << 20, &m) && !m.guarded)
        next_t = tuner_model_eval(&m, T->cands[T->ci + 1]);
    /* two repeats at least, each next_t - best slower than the best */
    return spent(T) + 2 * (next_t > best ? next_t - best : 0) <= allowance(E, T);
}

static void advance(silc_engine *E, tuner *T)
{
    T->ci++;
    ld_set_threads(E, T->cands[T->ci]);
    progress(T, 0);
}

static void sample(silc_engine *E, tuner *T, double secs)
{
    t_point *pt = NULL;
    double p[T_MAXC], t[T_MAXC], best;
    int i, complete, best_p;
    if (T->waiting) {
        /* At the best p so far, until the run has earned the next sample. */
        for (i = 0; i < T->npts; i++)
            if (T->pts[i].p == T->cands[T->ci]) pt = &T->pts[i];
        if (pt && next_affordable(E, T, pt)) {
            T->waiting = 0;
            advance(E, T);
        }
        return;
    }
    for (i = 0; i < T->npts; i++)
        if (T->pts[i].p == T->cur_p) pt = &T->pts[i];
    if (!pt) {
        pt = &T->pts[T->npts++];
        memset(pt, 0, sizeof *pt);
        pt->p = T->cur_p;
        pt->tmin = pt->t2 = INFINITY;
    }
    if (secs < pt->tmin) pt->t2 = pt->tmin, pt->tmin = secs;
    else if (secs < pt->t2) pt->t2 = secs;
    pt->reps++;
    T->sample_total += secs;
    T->sample_steps++;
    /* m: the two best repeats agree, or the cap is reached */
    complete = pt->reps >= T->max_rep || (pt->reps >= 2 && pt->t2 - pt->tmin <= T->rep_tol * pt->tmin) ||
               T->max_rep == 1;
    best = best_time(T, &best_p);
    /* a sample slower than the best is not repeated past what the budget allows */
    if (!complete && pt->tmin > best && spent(T) > allowance(E, T)) complete = 1;
    /* n: leave-one-out stability, the budget, or the end of the candidates */
    points(T, p, t);
    if (complete && T->npts >= 4 &&
        tuner_loo_stable(p, t, T->npts, T->cands[0], T->cands[T->ci], T->loo_tol)) {
        finish(E, T, "p_opt and its predicted time stable under leave-one-out");
        return;
    }
    if (!complete) return;
    if (T->ci + 1 >= T->ncands) {
        finish(E, T, "every candidate thread count sampled");
        return;
    }
    if (!next_affordable(E, T, pt)) {
        if (T->expect_steps > 0) {
            finish(E, T, "sampling would exceed tune.budget of the expected run");
            return;
        }
        /* The run's length is unknown: its allowance grows as it goes on. */
        T->waiting = 1;
        ld_set_threads(E, best_p);
        return;
    }
    advance(E, T);
}

/* A whole step ended after secs seconds of EXEC time. */
static void step_done(silc_engine *E, tuner *T, double secs)
{
    int i;
    T->steps++;
    T->run_secs += secs;
    switch (T->phase) {
    case PH_WAIT:
        signature(T);
        if (wisdom_read(E, T, T->signature, 1)) {
            T->from_wisdom = 1;
            snprintf(T->stop, sizeof T->stop, "from the wisdom file");
            T->phase = PH_DONE;
            ld_set_threads(E, T->p_opt);
            break;
        }
        classes_clear(T->ref, &T->nref);
        memcpy(T->ref, T->cur, sizeof T->cur);
        T->nref = T->ncur;
        memset(T->cur, 0, sizeof T->cur);
        T->ncur = 0;
        T->phase = PH_WAIT2;
        break;
    case PH_WAIT2:
        /* The backends to time later, on this step's operands (kept). */
        classes_clear(T->trial, &T->ntrial);
        for (i = 0; i < T->ncur && T->ntrial < T_MAXCLS; i++) {
            t_class *c = &T->trial[T->ntrial++], *prev = class_find(T->ref, T->nref, T->cur[i].cls);
            *c = T->cur[i];
            c->a = val_retain(c->a);
            c->b = val_retain(c->b);
            c->x0 = c->x0 ? val_retain(c->x0) : NULL;
            c->reuse = prev && prev->a_id == c->a_id;
            plan_class(E, c);
        }
        T->ncands = tuner_candidates(cores(), max_threads(E), T->cands);
        T->phase = PH_SAMPLE;
        T->ci = 0;
        ld_set_threads(E, T->cands[0]);
        progress(T, 0);
        break;
    case PH_SAMPLE:
        sample(E, T, secs);
        break;
    case PH_TRIALS:
        if (run_trials(E, T)) done(E, T);
        break;
    default:
        break;
    }
    classes_clear(T->cur, &T->ncur);
}

static void step_open(silc_engine *E, tuner *T)
{
    T->step_open = 1;
    T->step_acc = 0;
    T->step_hash = 1469598103934665603ull;
    T->cur_p = E->threads;
    classes_clear(T->cur, &T->ncur);
}

static void reset(tuner *T)
{
    classes_clear(T->pend, &T->npend);
    classes_clear(T->cur, &T->ncur);
    classes_clear(T->ref, &T->nref);
    memset(T->tab, 0, sizeof T->tab);
    T->ntab = 0;
    T->nhist = T->period = T->pos = T->step_open = T->steps = 0;
    T->npts = T->ci = T->sample_steps = T->have_model = T->from_wisdom = T->waiting = 0;
    classes_clear(T->trial, &T->ntrial);
    T->run_secs = T->trial_secs = T->trial_max = 0;
    T->choice[0] = 0;
    T->sample_total = 0;
    T->stop[0] = T->signature[0] = 0;
    memset(&T->model, 0, sizeof T->model);
    T->phase = T->enabled ? PH_WAIT : PH_OFF;
}

/* Follows tune.threads: "auto" turns tuning on (unless `tune off` said
 * otherwise), a number fixes the thread count while not tuning. */
static void follow_config(silc_engine *E, tuner *T, const char *v)
{
    char *end;
    long n;
    if (!strcmp(v, "auto")) {
        if (!T->enabled && !T->user_off) {
            T->enabled = 1;
            reset(T);
        }
        return;
    }
    n = strtol(v, &end, 10);
    if (!T->enabled && end != v && !*end && n >= 1 && n != E->threads) ld_set_threads(E, (int)n);
}

/* tuner_observe, with the EXEC's seconds given, or (since_start) its start
 * on util_now()'s clock: then the clock is read only by a tuner that is on. */
static void observe(silc_engine *E, const char *text, double seconds, int since_start)
{
    tuner *T = E->tuner;
    const char *cfg = cfg_get(E, "tune.threads");
    uint64_t h;
    if (!T) {
        if (!cfg) return;
        if (!(T = tuner_get(E))) return;
    }
    if (cfg) follow_config(E, T, cfg);
    if (T->in_command) {
        T->in_command = 0;
        if (!T->step_mark) {
            classes_clear(T->pend, &T->npend);
            return;
        }
    }
    if (!T->enabled) {
        T->step_mark = 0;
        classes_clear(T->pend, &T->npend);
        return;
    }
    if (since_start) seconds = util_now() - seconds;
    h = tuner_hash(text);
    if (T->explicit_steps) {
        if (T->step_open) {
            T->step_acc += seconds;
            T->step_hash = (T->step_hash ^ h) * 1099511628211ull;
            pend_merge(T);
        } else {
            classes_clear(T->pend, &T->npend);
        }
        if (T->step_mark) {
            if (T->step_open) step_done(E, T, T->step_acc);
            step_open(E, T);
        }
        T->step_mark = 0;
        return;
    }
    if (T->nhist == T_HIST) {
        memmove(T->hist, T->hist + T_HIST / 2, sizeof T->hist / 2);
        T->nhist = T_HIST / 2;
    }
    T->hist[T->nhist++] = h;
    if (T->period) {
        if (h != T->seq[T->pos]) {
            T->period = 0;      /* the program left its loop: find the new period */
            T->step_open = 0;
        } else {
            if (T->pos == 0) step_open(E, T);
            T->step_acc += seconds;
            T->step_hash = (T->step_hash ^ h) * 1099511628211ull;
            pend_merge(T);
            if (++T->pos == T->period) {
                T->pos = 0;
                T->step_open = 0;
                step_done(E, T, T->step_acc);
            }
            return;
        }
    }
    classes_clear(T->pend, &T->npend);
    if (!T->period) {
        int k = tuner_detect_period(T->hist, T->nhist, T_MAXK);
        if (k) {
            T->period = k;
            T->pos = 0;
            memcpy(T->seq, T->hist + T->nhist - k, (size_t)k * sizeof *T->seq);
        }
    }
}

void tuner_observe(silc_engine *E, const char *text, double seconds)
{
    observe(E, text, seconds, 0);
}

void tuner_observe_since(silc_engine *E, const char *text, double started)
{
    observe(E, text, started, 1);
}

/* A script's time loop (`while` in one EXEC, as `silc run` runs it): every
 * iteration of the outermost loop is a whole step, so the tuner works where
 * no EXEC texts repeat. */
void tuner_loop_step(silc_engine *E, uint64_t key, double seconds)
{
    tuner *T = E->tuner;
    const char *cfg = cfg_get(E, "tune.threads");
    if (!T) {
        if (!cfg || !(T = tuner_get(E))) return;
    }
    if (cfg) follow_config(E, T, cfg);
    if (!T->enabled) {
        classes_clear(T->pend, &T->npend);
        return;
    }
    step_open(E, T);
    T->step_hash = (T->step_hash ^ key) * 1099511628211ull;
    T->step_acc = seconds;
    pend_merge(T);
    T->step_open = 0;
    step_done(E, T, seconds);
}

/* ---- reports ------------------------------------------------------------------ */

static const char *phase_name(const tuner *T)
{
    switch (T->phase) {
    case PH_WAIT:
    case PH_WAIT2: return T->period || T->explicit_steps ? "waiting for two whole steps"
                                                         : "looking for the time step";
    case PH_SAMPLE: return T->waiting ? "sampling thread counts (the next sample waits for the budget)"
                                      : "sampling thread counts";
    case PH_TRIALS: return "timing backends (as the budget allows)";
    case PH_DONE: return "tuned";
    default: return "off";
    }
}

static void describe(silc_engine *E, const tuner *T, strbuf *b)
{
    char machine[300];
    int i, j;
    tuner_machine(machine, sizeof machine);
    sb_printf(b, "state = %s\n", phase_name(T));
    sb_printf(b, "machine = %s\n", machine);
    if (T->explicit_steps) sb_puts(b, "step = marked by 'tune step'\n");
    else if (T->period) sb_printf(b, "period = %d EXEC%s\n", T->period, T->period > 1 ? "s" : "");
    sb_printf(b, "steps = %d\n", T->steps);
    if (T->phase != PH_OFF)
        sb_printf(b, "spent = %.3g s of %.3g s allowed (tune.budget of the %s)\n", spent(T), allowance(E, T),
                  T->expect_steps > 0 ? "expected run" : "run so far");
    sb_printf(b, "threads = %d\n", E->threads);
    if (T->signature[0]) sb_printf(b, "signature = %s\n", T->signature);
    if (T->npts) {
        sb_printf(b, "sampled steps = %d\n", T->sample_steps);
        sb_puts(b, "samples (p: least step time of m repeats):\n");
        for (i = 0; i < T->npts; i++)
            sb_printf(b, "  p = %d: %.6g s (m = %d)\n", T->pts[i].p, T->pts[i].tmin, T->pts[i].reps);
    }
    if (T->have_model) {
        sb_printf(b, "a = %.6g\nb = %.6g\nc = %.6g\nq = %.6g\n", T->model.a, T->model.b, T->model.c,
                  T->model.q);
        if (T->model.guarded)
            sb_puts(b, "fit has no interior minimum (a <= 0 or b <= 0): p_opt is the best sample\n");
    }
    if (T->phase == PH_DONE || T->phase == PH_TRIALS) {
        sb_printf(b, "p_opt = %d\n", T->p_opt);
        if (T->choice[0]) sb_printf(b, "chosen because = %s\n", T->choice);
        else if (T->have_model)
            sb_printf(b, "predicted step time = %.6g s\n", tuner_model_eval(&T->model, T->p_opt));
        sb_printf(b, "stopped because = %s\n", T->stop);
    }
    for (i = 0; i < T->ntab; i++) {
        const t_class *c = &T->tab[i];
        if (!c->ncand && !c->reason[0]) continue;
        sb_printf(b, "backends for %s (%d solve%s a step, ran on %s):\n", c->cls, c->count,
                  c->count == 1 ? "" : "s", c->ran[0] ? c->ran : "?");
        if (c->ncand)
            sb_printf(b, "  %-24s %11s %11s %10s %11s  %s\n", "backend", "first s", "repeat s",
                      "berr", "cost s", "verdict");
        for (j = 0; j < c->ncand; j++) {
            const tuner_cand *k = &c->cand[j];
            char name[140];
            snprintf(name, sizeof name, "%s%s%s", k->backend, k->opts[0] ? " " : "", k->opts);
            if (k->failed)
                sb_printf(b, "  %-24s %11s %11s %10s %11s  %s\n", name, "-", "-", "-", "-",
                          k->why);
            else
                sb_printf(b, "  %-24s %11.4g %11.4g %10.2g %11.4g  %s\n", name, k->first,
                          k->repeat, k->berr, k->cost, k->why);
        }
        sb_printf(b, "  winner: %s\n", c->reason);
    }
}

void tuner_explain(silc_engine *E, const silc_call *call, strbuf *b)
{
    tuner *T = E->tuner;
    const char *chain[4];
    const t_class *c;
    int j;
    if (!T || call->op != SILC_OP_SOLVE || disp_classes(E, call, chain) < 1) return;
    c = class_find((t_class *)T->tab, T->ntab, chain[0]);
    if (!c || !c->reason[0]) return;
    sb_printf(b, "tuner: %s\n", c->reason);
    for (j = 0; j < c->ncand; j++)
        sb_printf(b, "  %s%s%s: first %.3g s, repeat %.3g s, backward error %.2g: %s\n",
                  c->cand[j].backend, c->cand[j].opts[0] ? " " : "", c->cand[j].opts, c->cand[j].first, c->cand[j].repeat, c->cand[j].berr,
                  c->cand[j].why);
}

/* The plot: measured times as points, f(p) as a curve, p_opt as a dashed
 * line, on a log2 p axis. */
static int write_svg(const tuner *T, FILE *f)
{
    const double W = 640, H = 400, L = 70, R = 20, TOP = 40, BOT = 50;
    double pmin = 1e300, pmax = 0, tmax = 0, x0, x1;
    int i;
    for (i = 0; i < T->npts; i++) {
        if (T->pts[i].p < pmin) pmin = T->pts[i].p;
        if (T->pts[i].p > pmax) pmax = T->pts[i].p;
        if (T->pts[i].tmin > tmax) tmax = T->pts[i].tmin;
    }
    if (T->p_opt > 0 && T->p_opt < pmin) pmin = T->p_opt;
    if (T->p_opt > pmax) pmax = T->p_opt;
    if (!(pmin < 1e300)) pmin = 1, pmax = 2;
    if (pmax <= pmin) pmax = pmin * 2;
    if (!(tmax > 0)) tmax = 1;
    tmax *= 1.15;
    x0 = log2(pmin), x1 = log2(pmax);
#define SX(p) (L + (log2(p) - x0) / (x1 - x0) * (W - L - R))
#define SY(t) (TOP + (1 - (t) / tmax) * (H - TOP - BOT))
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
               "viewBox=\"0 0 %.0f %.0f\" font-family=\"sans-serif\" font-size=\"12\">\n",
            W, H, W, H);
    fprintf(f, "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n");
    fprintf(f, "<text x=\"%.0f\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">step time "
               "vs threads: f(p) = a/p + b p + c</text>\n", W / 2);
    fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n", L,
            H - BOT, W - R, H - BOT);
    fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n", L,
            TOP, L, H - BOT);
    for (i = 0; i < T->npts; i++)
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%d</text>\n",
                SX(T->pts[i].p), H - BOT + 16, T->pts[i].p);
    for (i = 0; i <= 4; i++)
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%.3g</text>\n", L - 6,
                SY(tmax * i / 4) + 4, tmax * i / 4);
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">threads p (log scale)</text>\n",
            (L + W - R) / 2, H - 12);
    fprintf(f, "<text x=\"16\" y=\"%.1f\" transform=\"rotate(-90 16 %.1f)\" "
               "text-anchor=\"middle\">seconds per step</text>\n",
            (TOP + H - BOT) / 2, (TOP + H - BOT) / 2);
    if (T->have_model) {
        fprintf(f, "<polyline class=\"fit\" fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"2\" "
                   "points=\"");
        for (i = 0; i <= 100; i++) {
            double p = pow(2, x0 + (x1 - x0) * i / 100), t = tuner_model_eval(&T->model, p);
            if (t < 0) t = 0;
            if (t > tmax) t = tmax;
            fprintf(f, "%s%.1f,%.1f", i ? " " : "", SX(p), SY(t));
        }
        fprintf(f, "\"/>\n");
    }
    for (i = 0; i < T->npts; i++)
        fprintf(f, "<circle class=\"sample\" cx=\"%.1f\" cy=\"%.1f\" r=\"4\" fill=\"#d62728\">"
                   "<title>p = %d: %.4g s</title></circle>\n",
                SX(T->pts[i].p), SY(T->pts[i].tmin), T->pts[i].p, T->pts[i].tmin);
    if (T->p_opt > 0) {
        fprintf(f, "<line id=\"p_opt\" x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" "
                   "stroke=\"#2ca02c\" stroke-dasharray=\"6,4\" stroke-width=\"2\"/>\n",
                SX(T->p_opt), TOP, SX(T->p_opt), H - BOT);
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" fill=\"#2ca02c\">p_opt = %d</text>\n",
                SX(T->p_opt) + 4, TOP + 12, T->p_opt);
    }
    fprintf(f, "</svg>\n");
#undef SX
#undef SY
    return ferror(f) ? -1 : 0;
}

/* The plot written to place (cfg_file_write'n beside svg), renamed over svg
 * when whole; a failed write keeps the old file. */
static int save_svg(silc_engine *E, const tuner *T, const char *svg, cfg_file *place)
{
    FILE *f;
    int bad;
    if (!(f = fdopen(place->fd, "w"))) {
        cfg_file_close(place);
        return eng_error(E, "tune report: cannot write '%s': %s", svg, strerror(errno));
    }
    place->fd = -1; /* f owns it now */
    bad = write_svg(T, f);
    if (fclose(f) || bad) {
        cfg_file_close(place);
        return eng_error(E, "tune report: cannot write '%s': %s", svg, strerror(errno));
    }
    return cfg_file_commit(E, "tune report", svg, place);
}

static int report(silc_engine *E, tuner *T, const char *svg)
{
    strbuf b;
    tuner saved;
    const tuner *show = T;
    cfg_file place;
    /* a silcd that keeps no files still reports, without the plot, unless
     * the statement named a file */
    int plot = svg || cfg_serving(E) != 1, rc = 0;
    if (!svg) svg = "silc-tune.svg";
    /* the file first: a refused name is refused whatever there is to show */
    if (plot && cfg_file_write(E, "tune report", svg, &place)) return -1;
    if (!T->npts && T->phase != PH_DONE) {
        /* nothing tuned in this session: show the machine's last wisdom */
        memset(&saved, 0, sizeof saved);
        saved.wisdom_ignored = T->wisdom_ignored;
        if (!wisdom_read(E, &saved, NULL, 0)) {
            char path[1024];
            if (plot) cfg_file_close(&place);
            if (cfg_serving(E))
                return eng_error(E, "tune report: nothing tuned in this session and no wisdom for "
                                    "this machine in the operator's wisdom file");
            tuner_wisdom_path(E, path, sizeof path);
            return eng_error(E, "tune report: nothing tuned in this session and no wisdom for "
                                "this machine in '%s'", path);
        }
        saved.phase = PH_DONE;
        snprintf(saved.stop, sizeof saved.stop, "from the wisdom file");
        show = &saved;
    }
    sb_init(&b);
    sb_puts(&b, "tune report\n");
    describe(E, show, &b);
    if (!plot)
        sb_puts(&b, "plot: not written (this silcd keeps no files for sessions: silcd --data-dir)\n");
    else if (save_svg(E, show, svg, &place))
        rc = -1;
    else
        sb_printf(&b, "plot = %s\n", svg);
    if (!rc) eng_print(E, sb_str(&b));
    sb_free(&b);
    return rc;
}

/* ---- the `tune` statement --------------------------------------------------------- */

static int cmd_fit(silc_engine *E, const double *xs, int nx)
{
    double p[64], t[64];
    int n = nx / 2, i, lo = 1 << 30, hi = 1;
    tuner_model m;
    char line[256];
    if (nx % 2 || n < 3 || n > 64)
        return eng_error(E, "tune fit needs 3 to 64 points written p:seconds, as in "
                            "'tune fit 1:13.5 2:7.23 4:4.41'");
    for (i = 0; i < n; i++) {
        p[i] = xs[2 * i], t[i] = xs[2 * i + 1];
        if (!(p[i] >= 1) || p[i] != floor(p[i]) || !(t[i] > 0) || !isfinite(t[i]))
            return eng_error(E, "tune fit: point %d: need a whole thread count >= 1 and a time > 0",
                             i + 1);
        if ((int)p[i] < lo) lo = (int)p[i];
        if ((int)p[i] > hi) hi = (int)p[i];
    }
    if (tuner_fit(p, t, n, lo, hi, &m))
        return eng_error(E, "tune fit: the points do not determine a, b and c (need 3 distinct p)");
    snprintf(line, sizeof line, "a = %.6g\nb = %.6g\nc = %.6g\nq = %.6g\np_opt = %d\n%s", m.a, m.b,
             m.c, m.q, m.p_opt,
             m.guarded ? "note = a <= 0 or b <= 0: p_opt is the fastest measured point\n" : "");
    eng_print(E, line);
    return 0;
}

int tuner_command(silc_engine *E, const char *word, const double *xs, int nx, const char *arg)
{
    tuner *T = tuner_get(E);
    if (!T) return eng_error(E, "out of memory starting the tuner");
    T->in_command = 1;
    if (!strcmp(word, "fit")) return cmd_fit(E, xs, nx);
    if (!strcmp(word, "on")) {
        if (nx == 1 && xs[0] >= 1) T->expect_steps = (int)xs[0];
        if (!T->enabled) {
            T->enabled = 1;
            T->user_off = 0;
            reset(T);
        }
        return 0;
    }
    if (!strcmp(word, "off")) {
        T->enabled = 0;
        T->user_off = 1;
        T->explicit_steps = 0;
        progress(T, 1);
        classes_clear(T->pend, &T->npend);
        classes_clear(T->ref, &T->nref);
        classes_clear(T->trial, &T->ntrial);
        if (T->phase != PH_DONE) T->phase = PH_OFF;
        return 0;
    }
    if (!strcmp(word, "step")) {
        if (!T->explicit_steps) {
            T->explicit_steps = 1;
            T->period = 0;
            T->step_open = 0;
        }
        T->step_mark = 1;
        return 0;
    }
    if (!strcmp(word, "status")) {
        strbuf b;
        sb_init(&b);
        describe(E, T, &b);
        eng_print(E, sb_str(&b));
        sb_free(&b);
        return 0;
    }
    if (!strcmp(word, "forget")) {
        char path[1024];
        if (cfg_serving(E)) {
            /* the wisdom file is the operator's (a server setting): the
             * session tunes afresh without it, and the file stays */
            reset(T);
            T->wisdom_ignored = 1;
            eng_print(E, "tune forget: this session's tuning is forgotten and it no longer reads the "
                         "wisdom file, which is the operator's and was kept\n");
            return 0;
        }
        tuner_wisdom_path(E, path, sizeof path);
        if (remove(path) && errno != ENOENT)
            return eng_error(E, "tune forget: cannot remove '%s': %s", path, strerror(errno));
        reset(T);
        return 0;
    }
    if (!strcmp(word, "report")) return report(E, T, arg && *arg ? arg : NULL);
    return eng_error(E, "unknown tune command '%s' (on, off, status, step, forget, report, fit)",
                     word);
}

void tuner_free(silc_engine *E)
{
    tuner *T = E ? E->tuner : NULL;
    if (!T) return;
    classes_clear(T->pend, &T->npend);
    classes_clear(T->cur, &T->ncur);
    classes_clear(T->ref, &T->nref);
    classes_clear(T->trial, &T->ntrial);
    free(T);
    E->tuner = NULL;
}
