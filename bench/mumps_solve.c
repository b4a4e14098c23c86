/*
 * mumps_solve.c -- MUMPS's solve phase called directly, the baseline for
 * SILC's mumps backend in a loop that reuses one factorization (issue 30,
 * item 4: the diffusion loop).  No SILC: sequential MUMPS (dmumps_c and
 * smumps_c) with the settings the plugin uses for solve.sparse.spd (output
 * off, AMF ordering ICNTL(7)=2, LDL' SYM=1 on the lower triangle, assembled
 * centralized triplets), factored once, then JOB=3 on one dense right-hand
 * side again and again.
 *
 *     mumps_solve [-k K] [-reps R] [-icntl I V]...
 *         defaults: K = 200 (n = K^2), R = 100; -icntl sets ICNTL(I) = V in
 *         both instances before the analysis (repeatable)
 *
 * The matrix is the Crank-Nicolson diffusion matrix of bench/backends'
 * diffusion loop: A = I + s L, L the 5-point Laplacian of a K x K interior
 * grid, s = dt / (2 h^2), dt = 1e-3, h = 1 / (K + 1).  Each row prints the
 * median and the best JOB=3 time over R calls, and the backward error
 * ||b - A x||_inf / (||A||_inf ||x||_inf + ||b||_inf) of the last one, with
 * b = A * ones.  The single row scales nothing (A's entries are near 1).
 */
#define _POSIX_C_SOURCE 200809L
#include <dmumps_c.h>
#include <smumps_c.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define JOB_INIT (-1)
#define JOB_END (-2)
#define JOB_SOLVE 3
#define JOB_ANALYSE_FACTOR 4
#define USE_COMM_WORLD (-987654)

/* CPU time of the process: on a shared, loaded machine the wall clock
 * counts the other programs' turns too (MUMPS's sequential solve runs on
 * this one thread; OMP_NUM_THREADS=1 and OPENBLAS_NUM_THREADS=1). */
static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The lower triangle of A (1-based triplets) and its full row sums' max. */
typedef struct {
    int n, nz;
    MUMPS_INT *irn, *jcn;
    double *a;
    float *af;
} lower_triplets;

static int build(int k, lower_triplets *T)
{
    double h = 1.0 / (k + 1), s = 1e-3 / (2 * h * h);
    int i, j, p = 0;
    T->n = k * k;
    T->irn = malloc((size_t)T->n * 3 * sizeof *T->irn);
    T->jcn = malloc((size_t)T->n * 3 * sizeof *T->jcn);
    T->a = malloc((size_t)T->n * 3 * sizeof *T->a);
    T->af = malloc((size_t)T->n * 3 * sizeof *T->af);
    if (!T->irn || !T->jcn || !T->a || !T->af) return -1;
    for (i = 0; i < k; i++)
        for (j = 0; j < k; j++) {
            int r = i * k + j + 1;
            T->irn[p] = r, T->jcn[p] = r, T->a[p++] = 1 + 4 * s;
            if (j > 0) T->irn[p] = r, T->jcn[p] = r - 1, T->a[p++] = -s;
            if (i > 0) T->irn[p] = r, T->jcn[p] = r - k, T->a[p++] = -s;
        }
    T->nz = p;
    for (p = 0; p < T->nz; p++) T->af[p] = (float)T->a[p];
    return 0;
}

/* y = A x from the lower triangle (A symmetric). */
static void symv(const lower_triplets *T, const double *x, double *y)
{
    int p;
    memset(y, 0, (size_t)T->n * sizeof *y);
    for (p = 0; p < T->nz; p++) {
        int i = T->irn[p] - 1, j = T->jcn[p] - 1;
        y[i] += T->a[p] * x[j];
        if (i != j) y[j] += T->a[p] * x[i];
    }
}

static double norm_inf(const double *x, int n)
{
    double m = 0;
    for (int i = 0; i < n; i++)
        if (fabs(x[i]) > m) m = fabs(x[i]);
    return m;
}

static double backward_error(const lower_triplets *T, const double *b, const double *x, double nA)
{
    double *r = malloc((size_t)T->n * sizeof *r), be;
    symv(T, x, r);
    for (int i = 0; i < T->n; i++) r[i] = b[i] - r[i];
    be = norm_inf(r, T->n) / (nA * norm_inf(x, T->n) + norm_inf(b, T->n));
    free(r);
    return be;
}

static void print_row(const char *what, double *t, int reps, double be)
{
    qsort(t, (size_t)reps, sizeof *t, cmp_double);
    printf("%-34s %10.3f %10.3f %10.2g\n", what, 1e3 * t[reps / 2], 1e3 * t[0], be);
}

#define SETUP(id)                                                                                  \
    do {                                                                                           \
        (id).comm_fortran = USE_COMM_WORLD;                                                        \
        (id).par = 1;                                                                              \
        (id).sym = 1;                                                                              \
        (id).job = JOB_INIT;                                                                       \
    } while (0)
#define QUIET(id)                                                                                  \
    do {                                                                                           \
        (id).icntl[0] = (id).icntl[1] = (id).icntl[2] = 0;                                         \
        (id).icntl[3] = 0;                                                                         \
        (id).icntl[6] = 2; /* AMF */                                                               \
        (id).n = T.n;                                                                              \
        (id).nnz = T.nz;                                                                           \
        (id).irn = T.irn;                                                                          \
        (id).jcn = T.jcn;                                                                          \
        (id).nrhs = 1;                                                                             \
        (id).lrhs = T.n;                                                                           \
    } while (0)

int main(int argc, char **argv)
{
    int k = 200, reps = 100, r, i, nset = 0, set_i[40], set_v[40], nemin = 0;
    lower_triplets T;
    DMUMPS_STRUC_C d;
    SMUMPS_STRUC_C s;
    double *b, *x, *t, nA, t0;
    float *xf;
    for (i = 1; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "-k") == 0) k = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "-reps") == 0) reps = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "-nemin") == 0) nemin = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "-icntl") == 0 && i + 2 < argc && nset < 40 && atoi(argv[i + 1]) >= 1 &&
                 atoi(argv[i + 1]) <= 40) {
            set_i[nset] = atoi(argv[i + 1]);
            set_v[nset++] = atoi(argv[i + 2]);
            i++;
        } else break;
    }
    if (i < argc || k < 2 || reps < 1) {
        fprintf(stderr, "usage: mumps_solve [-k K >= 2] [-reps R >= 1] [-icntl I(1..40) V]...\n");
        return 2;
    }
    if (build(k, &T)) return 1;
    b = malloc((size_t)T.n * sizeof *b);
    x = malloc((size_t)T.n * sizeof *x);
    xf = malloc((size_t)T.n * sizeof *xf);
    t = malloc((size_t)reps * sizeof *t);
    if (!b || !x || !xf || !t) return 1;
    for (i = 0; i < T.n; i++) x[i] = 1;
    symv(&T, x, b);
    {
        double s_ = 1e-3 / (2.0 / ((k + 1.0) * (k + 1.0)));
        nA = 1 + 8 * s_; /* |1 + 4s| + 4 |s| */
    }
    printf("MUMPS JOB=3 called directly, n = %d (%d x %d Crank-Nicolson), SYM=1, AMF, %d calls, CPU time\n", T.n, k, k,
           reps);
    printf("%-34s %10s %10s %10s\n", "", "median ms", "best ms", "bwd err");

    memset(&d, 0, sizeof d);
    SETUP(d);
    dmumps_c(&d);
    QUIET(d);
    d.a = T.a;
    for (i = 0; i < nset; i++) d.icntl[set_i[i] - 1] = set_v[i];
    if (nemin > 0) d.keep[0] = nemin;
    t0 = now();
    d.job = JOB_ANALYSE_FACTOR;
    dmumps_c(&d);
    if (d.infog[0] < 0) {
        fprintf(stderr, "dmumps JOB=4 failed: INFOG(1)=%d\n", d.infog[0]);
        return 1;
    }
    printf("%-34s %10.3f   (entries in factors INFOG(9) = %d, tree nodes KEEP(28) = %d)\n",
           "dmumps analysis + factorization", 1e3 * (now() - t0), d.infog[8], d.keep[27]);
    for (r = 0; r < reps; r++) {
        memcpy(x, b, (size_t)T.n * sizeof *x);
        d.rhs = x;
        d.job = JOB_SOLVE;
        t0 = now();
        dmumps_c(&d);
        t[r] = now() - t0;
    }
    print_row("dmumps JOB=3, 1 column", t, reps, backward_error(&T, b, x, nA));
    d.job = JOB_END;
    dmumps_c(&d);

    memset(&s, 0, sizeof s);
    SETUP(s);
    smumps_c(&s);
    QUIET(s);
    s.a = T.af;
    for (i = 0; i < nset; i++) s.icntl[set_i[i] - 1] = set_v[i];
    if (nemin > 0) s.keep[0] = nemin;
    t0 = now();
    s.job = JOB_ANALYSE_FACTOR;
    smumps_c(&s);
    if (s.infog[0] < 0) {
        fprintf(stderr, "smumps JOB=4 failed: INFOG(1)=%d\n", s.infog[0]);
        return 1;
    }
    printf("%-34s %10.3f\n", "smumps analysis + factorization", 1e3 * (now() - t0));
    for (r = 0; r < reps; r++) {
        for (i = 0; i < T.n; i++) xf[i] = (float)b[i];
        s.rhs = xf;
        s.job = JOB_SOLVE;
        t0 = now();
        smumps_c(&s);
        t[r] = now() - t0;
    }
    for (i = 0; i < T.n; i++) x[i] = xf[i];
    print_row("smumps JOB=3, 1 column", t, reps, backward_error(&T, b, x, nA));
    s.job = JOB_END;
    smumps_c(&s);
    free(b);
    free(x);
    free(xf);
    free(t);
    free(T.irn);
    free(T.jcn);
    free(T.a);
    free(T.af);
    return 0;
}
