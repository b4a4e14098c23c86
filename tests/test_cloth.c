/*
 * test_cloth.c -- the seeds' mass-spring cloth step, through SILC and in plain C.
 *
 * A 4x4 grid of particles in 3-D joined by structural and shear springs takes
 * three implicit (linearized backward Euler) steps.  The program PUTs the mesh
 * data, EXECs the seeds' statements one at a time, and after each one fetches
 * every quantity it defined and compares it with the same quantity computed here
 * with dense arrays and a small Gaussian elimination -- nothing in the plain-C
 * path goes through SILC.
 *
 * Conventions (the seeds' transcription leaves these open; this is the
 * mathematically consistent reading):
 *   x, v      3n x 1, particle i's coordinates at rows 3i..3i+2;
 *   Y_L, Y_R  3s x 3n selection matrices: rows 3k..3k+2 pick the coordinates of
 *             spring k's left / right particle, so p = Y_L x - Y_R x stacks the
 *             spring vectors; Y_LT, Y_RT are their transposes, PUT as given;
 *   P         3s x s, column k holds spring k's 3-vector (P_row = 1..3s,
 *             P_col = spring of each coordinate, 1-based);
 *   X         the 3s x s indicator with the pattern of P and ones as values, so
 *             X * sqrt(K_stiff) repeats each spring's sqrt stiffness over its three
 *             coordinates and C1 = diag(X * sqrt(K_stiff)) is 3s x 3s;
 *   f         spring forces on the particles plus gravity:
 *             f = Y_RT * fij - Y_LT * fij + M * g (fij = K (z - L)/z * p pulls
 *             the left particle toward the right one);
 *   DfDx      T1 = -A1 A1' = -(Y_L - Y_R)' diag(K) (Y_L - Y_R), the stiffness of
 *             zero-rest-length springs: a symmetric negative semidefinite
 *             linearization, which keeps A = M - dt^2 DfDx - dt DfDv SPD;
 *   DfDv      -damping * M.
 */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "silc.h"

#define GRID 4
#define NP (GRID * GRID)         /* particles */
#define N3 (3 * NP)              /* coordinates */
#define MAXS (4 * GRID * GRID)   /* upper bound on springs */
#define STEPS 3
#define RTOL 1e-12

static int spring_l[MAXS], spring_r[MAXS], ns;

/* ---- small dense helpers (column-major, m x n) -------------------------------- */
static double *alloc(int m, int n)
{
    double *a = calloc((size_t)m * (size_t)n, sizeof *a);
    if (!a) {
        fprintf(stderr, "out of memory\n");
        exit(2);
    }
    return a;
}

/* c = a (m x k) * b (k x n) */
static void matmul(int m, int k, int n, const double *a, const double *b, double *c)
{
    for (int j = 0; j < n; j++)
        for (int i = 0; i < m; i++) {
            double s = 0;
            for (int l = 0; l < k; l++)
                s += a[i + (size_t)l * m] * b[l + (size_t)j * k];
            c[i + (size_t)j * m] = s;
        }
}

static void transpose(int m, int n, const double *a, double *t)
{
    for (int j = 0; j < n; j++)
        for (int i = 0; i < m; i++)
            t[j + (size_t)i * n] = a[i + (size_t)j * m];
}

/* In-place LU with partial pivoting of the n x n matrix a; returns 1 if singular. */
static int lu_factor(int n, double *a, int *piv)
{
    for (int k = 0; k < n; k++) {
        int p = k;
        for (int i = k + 1; i < n; i++)
            if (fabs(a[i + k * n]) > fabs(a[p + k * n]))
                p = i;
        piv[k] = p;
        if (a[p + k * n] == 0)
            return 1;
        if (p != k)
            for (int j = 0; j < n; j++) {
                double t = a[k + j * n];
                a[k + j * n] = a[p + j * n];
                a[p + j * n] = t;
            }
        for (int i = k + 1; i < n; i++) {
            double l = a[i + k * n] /= a[k + k * n];
            for (int j = k + 1; j < n; j++)
                a[i + j * n] -= l * a[k + j * n];
        }
    }
    return 0;
}

static void lu_solve(int n, const double *lu, const int *piv, double *b)
{
    for (int k = 0; k < n; k++) {
        double t = b[k];
        b[k] = b[piv[k]];
        b[piv[k]] = t;
        for (int i = k + 1; i < n; i++)
            b[i] -= lu[i + k * n] * b[k];
    }
    for (int k = n - 1; k >= 0; k--) {
        b[k] /= lu[k + k * n];
        for (int i = 0; i < k; i++)
            b[i] -= lu[i + k * n] * b[k];
    }
}

static double norm1(int n, const double *a)
{
    double best = 0;
    for (int j = 0; j < n; j++) {
        double s = 0;
        for (int i = 0; i < n; i++)
            s += fabs(a[i + j * n]);
        if (s > best)
            best = s;
    }
    return best;
}

/* Solves a x = b (a untouched); returns the exact 1-norm condition number. */
static double solve_with_cond(int n, const double *a, const double *b, double *x)
{
    double *lu = alloc(n, n), *e = alloc(n, 1), invnorm = 0;
    int *piv = malloc(sizeof *piv * (size_t)n);
    if (!piv)
        exit(2);
    memcpy(lu, a, sizeof *lu * (size_t)n * (size_t)n);
    if (lu_factor(n, lu, piv)) {
        fprintf(stderr, "plain-C reference: A is singular\n");
        exit(2);
    }
    memcpy(x, b, sizeof *x * (size_t)n);
    lu_solve(n, lu, piv, x);
    for (int j = 0; j < n; j++) { /* column j of the inverse */
        memset(e, 0, sizeof *e * (size_t)n);
        e[j] = 1;
        lu_solve(n, lu, piv, e);
        double s = 0;
        for (int i = 0; i < n; i++)
            s += fabs(e[i]);
        if (s > invnorm)
            invnorm = s;
    }
    free(lu);
    free(e);
    free(piv);
    return norm1(n, a) * invnorm;
}

/* ---- SILC side ---------------------------------------------------------------- */
static void put_dense(silc_context *ctx, const char *name, int m, int n, const double *a)
{
    silc_envelope_t e;
    int rc = silc_envelope_dense(&e, m, n, a);
    CHECK(rc == 0, "envelope for %s", name);
    if (rc == 0) {
        CHECK(silc_put(ctx, name, &e) == 0, "put %s: %s", name, silc_context_errmsg(ctx));
        silc_envelope_free(&e);
    }
}

/* PUTs the dense m x n array a as a CSR matrix of its nonzeros. */
static void put_sparse(silc_context *ctx, const char *name, int m, int n, const double *a)
{
    int64_t *rowptr = calloc((size_t)m + 1, sizeof *rowptr);
    int64_t *colind = calloc((size_t)m * (size_t)n + 1, sizeof *colind);
    double *val = calloc((size_t)m * (size_t)n + 1, sizeof *val);
    if (!rowptr || !colind || !val)
        exit(2);
    int64_t nz = 0;
    for (int i = 0; i < m; i++) {
        for (int j = 0; j < n; j++)
            if (a[i + (size_t)j * m] != 0) {
                colind[nz] = j;
                val[nz++] = a[i + (size_t)j * m];
            }
        rowptr[i + 1] = nz;
    }
    silc_envelope_t e;
    int rc = silc_envelope_csr(&e, m, n, rowptr, colind, val);
    CHECK(rc == 0, "envelope for %s", name);
    if (rc == 0) {
        CHECK(silc_put(ctx, name, &e) == 0, "put %s: %s", name, silc_context_errmsg(ctx));
        silc_envelope_free(&e);
    }
    free(rowptr);
    free(colind);
    free(val);
}

/* Fetches name and compares it with want (m x n) to rtol of its largest entry. */
static void expect(silc_context *ctx, int step, const char *name, int m, int n,
                   const double *want, double rtol)
{
    silc_envelope_t e = {0};
    if (silc_get(ctx, &e, name)) {
        CHECK(0, "step %d: get %s: %s", step, name, silc_context_errmsg(ctx));
        return;
    }
    if (silc_envelope_rows(&e) != m || silc_envelope_cols(&e) != n) {
        CHECK(0, "step %d: %s is %lldx%lld, want %dx%d", step, name,
              (long long)silc_envelope_rows(&e), (long long)silc_envelope_cols(&e), m, n);
        silc_envelope_free(&e);
        return;
    }
    double *got = alloc(m, n), scale = 0, worst = 0;
    size_t at = 0, len = (size_t)m * (size_t)n;
    CHECK(silc_envelope_to_dense(&e, got) == 0, "step %d: %s to dense", step, name);
    for (size_t k = 0; k < len; k++)
        if (fabs(want[k]) > scale)
            scale = fabs(want[k]);
    for (size_t k = 0; k < len; k++) {
        double d = fabs(got[k] - want[k]);
        if (!(d <= worst)) {
            worst = d;
            at = k;
        }
    }
    CHECK(worst <= rtol * (scale > 0 ? scale : 1),
          "step %d: %s(%d,%d) = %.17g, want %.17g (|diff| %.3g, rtol %.3g, scale %.3g)", step, name,
          (int)(at % (size_t)m) + 1, (int)(at / (size_t)m) + 1, got[at], want[at], worst, rtol,
          scale);
    free(got);
    silc_envelope_free(&e);
}

static int exec(silc_context *ctx, int step, const char *stmt)
{
    int rc = silc_exec(ctx, stmt);
    CHECK(rc == 0, "step %d: `%s` failed: %s", step, stmt, silc_context_errmsg(ctx));
    return rc;
}

/* ---- the mesh ----------------------------------------------------------------- */
static void add_spring(int a, int b)
{
    spring_l[ns] = a;
    spring_r[ns] = b;
    ns++;
}

/* A deterministic perturbation in [-1, 1) so springs start stretched or compressed. */
static double wobble(unsigned *state)
{
    *state = *state * 1103515245u + 12345u;
    return ((*state >> 8) & 0xffff) / 32768.0 - 1.0;
}

int main(void)
{
    const double h = 0.25, dt = 0.02, damping = 0.2;
    double x[N3], v[N3], g[N3], fixed[N3], mass[N3];
    unsigned seed = 12345;

    for (int r = 0; r < GRID; r++)
        for (int c = 0; c < GRID; c++) {
            int i = r * GRID + c;
            if (c + 1 < GRID)
                add_spring(i, i + 1); /* structural */
            if (r + 1 < GRID)
                add_spring(i, i + GRID);
            if (r + 1 < GRID && c + 1 < GRID) { /* shear */
                add_spring(i, i + GRID + 1);
                add_spring(i + 1, i + GRID);
            }
        }
    const int s = ns, S3 = 3 * s;
    double *K = alloc(s, 1), *L = alloc(s, 1);
    for (int k = 0; k < s; k++) {
        int a = spring_l[k], b = spring_r[k];
        int diagonal = (a % GRID != b % GRID) && (a / GRID != b / GRID);
        K[k] = 40.0 + 3.0 * (k % 7);
        L[k] = diagonal ? h * sqrt(2.0) : h;
    }
    for (int i = 0; i < NP; i++) {
        double px = (i % GRID) * h, py = (i / GRID) * h;
        x[3 * i] = px + 0.02 * wobble(&seed);
        x[3 * i + 1] = py + 0.02 * wobble(&seed);
        x[3 * i + 2] = 0.02 * wobble(&seed);
        int pinned = (i == NP - GRID || i == NP - 1); /* the two top corners */
        for (int d = 0; d < 3; d++) {
            v[3 * i + d] = pinned ? 0 : 0.1 * wobble(&seed);
            fixed[3 * i + d] = pinned ? 0 : 1;
            mass[3 * i + d] = 0.05 + 0.01 * (i % 3);
            g[3 * i + d] = d == 2 ? -9.81 : 0;
        }
    }

    /* Matrices shared by every step (dense here, sparse inside SILC). */
    double *YL = alloc(S3, N3), *YR = alloc(S3, N3), *YLT = alloc(N3, S3), *YRT = alloc(N3, S3);
    double *X = alloc(S3, s), *M = alloc(N3, N3), Prow[MAXS * 3], Pcol[MAXS * 3];
    for (int k = 0; k < s; k++)
        for (int d = 0; d < 3; d++) {
            int row = 3 * k + d;
            YL[row + (size_t)(3 * spring_l[k] + d) * S3] = 1;
            YR[row + (size_t)(3 * spring_r[k] + d) * S3] = 1;
            X[row + (size_t)k * S3] = 1;
            Prow[row] = row + 1;
            Pcol[row] = k + 1;
        }
    transpose(S3, N3, YL, YLT);
    transpose(S3, N3, YR, YRT);
    for (int i = 0; i < N3; i++)
        M[i + i * N3] = mass[i];

    silc_context *ctx = NULL;
    if (silc_open(&ctx, NULL)) {
        CHECK(0, "silc_open: %s", ctx ? silc_context_errmsg(ctx) : silc_errmsg());
        return check_done();
    }
    double sd = s;
    put_dense(ctx, "x", N3, 1, x);
    put_dense(ctx, "v", N3, 1, v);
    put_dense(ctx, "g", N3, 1, g);
    put_dense(ctx, "fixed", N3, 1, fixed);
    put_dense(ctx, "K_stiff", s, 1, K);
    put_dense(ctx, "L", s, 1, L);
    put_dense(ctx, "P_row", S3, 1, Prow);
    put_dense(ctx, "P_col", S3, 1, Pcol);
    put_dense(ctx, "s", 1, 1, &sd);
    put_dense(ctx, "dt", 1, 1, &dt);
    put_dense(ctx, "damping", 1, 1, &damping);
    put_sparse(ctx, "Y_L", S3, N3, YL);
    put_sparse(ctx, "Y_R", S3, N3, YR);
    put_sparse(ctx, "Y_LT", N3, S3, YLT);
    put_sparse(ctx, "Y_RT", N3, S3, YRT);
    put_sparse(ctx, "X", S3, s, X);
    put_sparse(ctx, "M", N3, N3, M);

    double *p = alloc(S3, 1), *P = alloc(S3, s), *z = alloc(s, 1), *w = alloc(s, 1);
    double *fij = alloc(S3, 1), *zhat = alloc(s, 1), *Pzhat = alloc(S3, 1);
    double *C1 = alloc(S3, S3), *A1 = alloc(N3, S3), *A1T = alloc(S3, N3), *T1 = alloc(N3, N3);
    double *f = alloc(N3, 1), *DfDv = alloc(N3, N3), *A = alloc(N3, N3), *b = alloc(N3, 1);
    double *dv = alloc(N3, 1), *tmp = alloc(N3, 1);

    for (int step = 1; step <= STEPS; step++) {
        /* p = Y_L * x - Y_R * x */
        for (int k = 0; k < s; k++)
            for (int d = 0; d < 3; d++)
                p[3 * k + d] = x[3 * spring_l[k] + d] - x[3 * spring_r[k] + d];
        if (exec(ctx, step, "p = Y_L * x - Y_R * x"))
            break;
        expect(ctx, step, "p", S3, 1, p, RTOL);

        /* P = sparse(P_row, P_col, p, 3*s, s) */
        memset(P, 0, sizeof *P * (size_t)S3 * (size_t)s);
        for (int row = 0; row < S3; row++)
            P[row + (size_t)(row / 3) * S3] = p[row];
        if (exec(ctx, step, "P = sparse(P_row, P_col, p, 3*s, s)"))
            break;
        expect(ctx, step, "P", S3, s, P, RTOL);

        /* z = sqrt(diagvec(P' * P)) */
        for (int k = 0; k < s; k++)
            z[k] = sqrt(p[3 * k] * p[3 * k] + p[3 * k + 1] * p[3 * k + 1] +
                        p[3 * k + 2] * p[3 * k + 2]);
        if (exec(ctx, step, "z = sqrt(diagvec(P' * P))"))
            break;
        expect(ctx, step, "z", s, 1, z, RTOL);

        /* fij = P * (K_stiff *@ (z - L) /@ z) */
        for (int k = 0; k < s; k++)
            w[k] = K[k] * (z[k] - L[k]) / z[k];
        matmul(S3, s, 1, P, w, fij);
        if (exec(ctx, step, "fij = P * (K_stiff *@ (z - L) /@ z)"))
            break;
        expect(ctx, step, "fij", S3, 1, fij, RTOL);

        /* zhat = ones(s, 1) /@ z; Pzhat = P * zhat */
        for (int k = 0; k < s; k++)
            zhat[k] = 1.0 / z[k];
        matmul(S3, s, 1, P, zhat, Pzhat);
        if (exec(ctx, step, "zhat = ones(s, 1) /@ z; Pzhat = P * zhat"))
            break;
        expect(ctx, step, "zhat", s, 1, zhat, RTOL);
        expect(ctx, step, "Pzhat", S3, 1, Pzhat, RTOL);

        /* C1 = diag(X * sqrt(K_stiff)) */
        memset(C1, 0, sizeof *C1 * (size_t)S3 * (size_t)S3);
        for (int row = 0; row < S3; row++)
            C1[row + (size_t)row * S3] = sqrt(K[row / 3]);
        if (exec(ctx, step, "C1 = diag(X * sqrt(K_stiff))"))
            break;
        expect(ctx, step, "C1", S3, S3, C1, RTOL);

        /* A1 = Y_LT * C1 - Y_RT * C1; T1 = -A1 * A1' */
        for (size_t k = 0; k < (size_t)N3 * (size_t)S3; k++)
            A1[k] = YLT[k] - YRT[k];
        for (int j = 0; j < S3; j++) /* right-multiplying by a diagonal scales columns */
            for (int i = 0; i < N3; i++)
                A1[i + (size_t)j * N3] *= C1[j + (size_t)j * S3];
        transpose(N3, S3, A1, A1T);
        matmul(N3, S3, N3, A1, A1T, T1);
        for (int k = 0; k < N3 * N3; k++)
            T1[k] = -T1[k];
        if (exec(ctx, step, "A1 = Y_LT * C1 - Y_RT * C1; T1 = -A1 * A1'"))
            break;
        expect(ctx, step, "A1", N3, S3, A1, RTOL);
        expect(ctx, step, "T1", N3, N3, T1, RTOL);

        /* The force and its derivatives (see the conventions at the top). */
        for (int i = 0; i < N3; i++)
            f[i] = mass[i] * g[i];
        for (int k = 0; k < s; k++)
            for (int d = 0; d < 3; d++) {
                f[3 * spring_l[k] + d] -= fij[3 * k + d];
                f[3 * spring_r[k] + d] += fij[3 * k + d];
            }
        for (int k = 0; k < N3 * N3; k++)
            DfDv[k] = -damping * M[k];
        if (exec(ctx, step, "f = Y_RT * fij - Y_LT * fij + M * g; DfDx = T1; DfDv = -damping * M"))
            break;
        expect(ctx, step, "f", N3, 1, f, RTOL);
        expect(ctx, step, "DfDx", N3, N3, T1, RTOL);
        expect(ctx, step, "DfDv", N3, N3, DfDv, RTOL);

        /* A = M - (dt * dt) * DfDx - dt * DfDv */
        for (int k = 0; k < N3 * N3; k++)
            A[k] = M[k] - (dt * dt) * T1[k] - dt * DfDv[k];
        if (exec(ctx, step, "A = M - (dt * dt) * DfDx - dt * DfDv"))
            break;
        expect(ctx, step, "A", N3, N3, A, RTOL);

        /* b = dt * (f + dt * (DfDx * v)) */
        matmul(N3, N3, 1, T1, v, tmp);
        for (int i = 0; i < N3; i++)
            b[i] = dt * (f[i] + dt * tmp[i]);
        if (exec(ctx, step, "b = dt * (f + dt * (DfDx * v))"))
            break;
        expect(ctx, step, "b", N3, 1, b, RTOL);

        /* dv = A \ b, to a bound scaled by the exact 1-norm condition number */
        double cond = solve_with_cond(N3, A, b, dv);
        double stol = RTOL * (cond > 1 ? cond : 1);
        if (exec(ctx, step, "dv = A \\ b"))
            break;
        expect(ctx, step, "dv", N3, 1, dv, stol);

        /* v += dv *@ fixed; x += dt * v (carry the solve's tolerance forward) */
        for (int i = 0; i < N3; i++)
            v[i] += dv[i] * fixed[i];
        if (exec(ctx, step, "v += dv *@ fixed"))
            break;
        expect(ctx, step, "v", N3, 1, v, stol);
        for (int i = 0; i < N3; i++)
            x[i] += dt * v[i];
        if (exec(ctx, step, "x += dt * v"))
            break;
        expect(ctx, step, "x", N3, 1, x, stol);
    }

    silc_close(&ctx);
    double *owned[] = {K, L, YL, YR, YLT, YRT, X, M, p, P, z, w, fij, zhat, Pzhat,
                       C1, A1, A1T, T1, f, DfDv, A, b, dv, tmp};
    for (size_t i = 0; i < sizeof owned / sizeof owned[0]; i++)
        free(owned[i]);
    return check_done();
}
