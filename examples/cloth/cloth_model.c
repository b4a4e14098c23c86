/*
 * cloth_model.c -- the cloth every driver advances: the mesh and its
 * springs, forces, the implicit-Euler system, the update, the obstacle, the
 * energies, and the original program's own CG.
 *
 * The system is the seeds' (cloth.h): with DfDx the stiffness of
 * zero-rest-length springs and DfDv = -damping M,
 *     A = (1 + dt damping) M + dt^2 Lk,   b = dt (f - dt Lk v),
 * Lk the spring "Laplacian" (K on a spring's two ends, -K between them) for
 * each coordinate direction alone.  A couples only equal directions, so its
 * pattern is the particle graph's with every entry repeated for x, y, z.
 * DfDx does not depend on the positions under this linearization, so A is
 * the same every step; the drivers still form it every step, as the seeds'
 * programs did, so that the three time the same step.
 *
 * Pinned coordinates are constrained inside the solve (Baraff and Witkin's
 * filter, written as a selection): with S = diag(fixed) the system solved is
 *     (S A S + (I - S) (1 + dt damping) M) dv = S b,
 * i.e. the free coordinates' block of A with the pinned rows and columns
 * removed, and dv = 0 on the pinned ones.  Solving as if the pins were free
 * and dropping their dv afterwards (the seeds' way) lets the pins' neighbours
 * follow a fall the pins never make: 7.7x stretched springs on `hanging`.
 */
#define _POSIX_C_SOURCE 200809L
#include "cloth.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double dist3(const double *a, const double *b)
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

static int cmp_int64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* The springs of the grid: structural, shear, and bend when k_bend > 0. */
static int add_springs(cloth_model *m)
{
    const cloth_scene *s = m->scene;
    int nx = s->nx, ny = s->ny, i, j, cap = 6 * m->n, ns = 0;
    m->sl = malloc((size_t)cap * sizeof *m->sl);
    m->sr = malloc((size_t)cap * sizeof *m->sr);
    m->k = malloc((size_t)cap * sizeof *m->k);
    m->rest = malloc((size_t)cap * sizeof *m->rest);
    if (!m->sl || !m->sr || !m->k || !m->rest) return -1;
#define SPRING(a, b, kk)                                                                           \
    do {                                                                                           \
        m->sl[ns] = (a), m->sr[ns] = (b), m->k[ns] = (kk);                                         \
        m->rest[ns] = dist3(m->x + 3 * (a), m->x + 3 * (b));                                       \
        ns++;                                                                                      \
    } while (0)
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++) {
            int p = j * nx + i;
            if (i + 1 < nx) SPRING(p, p + 1, s->k_struct);
            if (j + 1 < ny) SPRING(p, p + nx, s->k_struct);
            if (s->k_shear > 0 && i + 1 < nx && j + 1 < ny) {
                SPRING(p, p + nx + 1, s->k_shear);
                SPRING(p + 1, p + nx, s->k_shear);
            }
            if (s->k_bend > 0 && i + 2 < nx) SPRING(p, p + 2, s->k_bend);
            if (s->k_bend > 0 && j + 2 < ny) SPRING(p, p + 2 * nx, s->k_bend);
        }
#undef SPRING
    m->ns = ns;
    return 0;
}

/* Position of column c in row r of m's pattern (it is there by construction). */
static int64_t entry(const cloth_model *m, int64_t r, int64_t c)
{
    int64_t lo = m->rowptr[r], hi = m->rowptr[r + 1] - 1;
    while (lo < hi) {
        int64_t mid = lo + (hi - lo) / 2;
        if (m->colind[mid] < c) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* A's pattern: row 3p+d holds columns 3q+d for p and every spring neighbour q. */
static int build_pattern(cloth_model *m)
{
    int n = m->n, k, p, d;
    int64_t *deg = calloc((size_t)n + 1, sizeof *deg), *adj = NULL, *fill = NULL, at = 0;
    int rc = -1;
    if (!deg) return -1;
    for (k = 0; k < m->ns; k++) deg[m->sl[k] + 1]++, deg[m->sr[k] + 1]++;
    for (p = 0; p < n; p++) deg[p + 1] += deg[p] + 1; /* + the diagonal */
    adj = malloc((size_t)deg[n] * sizeof *adj);
    fill = calloc((size_t)n, sizeof *fill);
    m->rowptr = malloc((size_t)(3 * n + 1) * sizeof *m->rowptr);
    m->colind = malloc((size_t)(3 * deg[n]) * sizeof *m->colind);
    if (!adj || !fill || !m->rowptr || !m->colind) goto out;
    for (p = 0; p < n; p++) adj[deg[p] + fill[p]++] = p;
    for (k = 0; k < m->ns; k++) {
        adj[deg[m->sl[k]] + fill[m->sl[k]]++] = m->sr[k];
        adj[deg[m->sr[k]] + fill[m->sr[k]]++] = m->sl[k];
    }
    m->rowptr[0] = 0;
    for (p = 0; p < n; p++) {
        int64_t lo = deg[p], hi = deg[p + 1], q, w;
        qsort(adj + lo, (size_t)(hi - lo), sizeof *adj, cmp_int64);
        for (d = 0; d < 3; d++) {
            for (q = lo, w = -1; q < hi; q++) {
                if (adj[q] == w) continue; /* two springs between the same pair share an entry */
                w = adj[q];
                m->colind[at++] = 3 * w + d;
            }
            m->rowptr[3 * p + d + 1] = at;
        }
    }
    m->nnz = at;
    m->diag = malloc((size_t)(3 * n) * sizeof *m->diag);
    m->spring_slot = malloc((size_t)(12 * (m->ns ? m->ns : 1)) * sizeof *m->spring_slot);
    if (!m->diag || !m->spring_slot) goto out;
    for (p = 0; p < 3 * n; p++) m->diag[p] = entry(m, p, p);
    for (k = 0; k < m->ns; k++)
        for (d = 0; d < 3; d++) {
            int64_t l = 3 * (int64_t)m->sl[k] + d, r = 3 * (int64_t)m->sr[k] + d, *slot = m->spring_slot + 12 * k + 4 * d;
            slot[0] = entry(m, l, l), slot[1] = entry(m, r, r), slot[2] = entry(m, l, r), slot[3] = entry(m, r, l);
        }
    rc = 0;
out:
    free(deg);
    free(adj);
    free(fill);
    return rc;
}

int cloth_model_init(cloth_model *m, const cloth_scene *s, char *err, size_t errlen)
{
    int n = s->nx * s->ny, i, j, p, d;
    double tilt = s->tilt * acos(-1.0) / 180;
    memset(m, 0, sizeof *m);
    m->scene = s;
    m->n = n;
    m->x = calloc((size_t)3 * n, sizeof *m->x);
    m->v = calloc((size_t)3 * n, sizeof *m->v);
    m->x0 = calloc((size_t)3 * n, sizeof *m->x0);
    m->mass = calloc((size_t)3 * n, sizeof *m->mass);
    m->fixed = calloc((size_t)3 * n, sizeof *m->fixed);
    m->gvec = calloc((size_t)3 * n, sizeof *m->gvec);
    m->xprev = calloc((size_t)3 * n, sizeof *m->xprev);
    m->xfree = calloc((size_t)3 * n, sizeof *m->xfree);
    if (!m->x || !m->v || !m->x0 || !m->mass || !m->fixed || !m->gvec || !m->xprev || !m->xfree) goto oom;
    /* Flat in z = 0, then turned by `tilt` about the x axis. */
    for (j = 0; j < s->ny; j++)
        for (i = 0; i < s->nx; i++) {
            double X = s->width * i / (s->nx - 1), Y = s->height * j / (s->ny - 1);
            p = j * s->nx + i;
            m->x[3 * p] = X;
            m->x[3 * p + 1] = Y * cos(tilt);
            m->x[3 * p + 2] = Y * sin(tilt);
        }
    memcpy(m->x0, m->x, (size_t)3 * n * sizeof *m->x);
    memcpy(m->xprev, m->x, (size_t)3 * n * sizeof *m->x);
    memcpy(m->xfree, m->x, (size_t)3 * n * sizeof *m->x);
    for (p = 0; p < n; p++)
        for (d = 0; d < 3; d++) {
            m->mass[3 * p + d] = s->mass / n;
            m->fixed[3 * p + d] = 1;
            m->gvec[3 * p + d] = s->gravity[d];
        }
    for (i = 0; i < s->npins; i++) {
        p = s->pin_j[i] * s->nx + s->pin_i[i];
        for (d = 0; d < 3; d++) m->fixed[3 * p + d] = 0;
    }
    if (add_springs(m) || build_pattern(m)) goto oom;
    return 0;
oom:
    cloth_model_free(m);
    snprintf(err, errlen, "out of memory for a %dx%d cloth", s->nx, s->ny);
    return -1;
}

void cloth_model_free(cloth_model *m)
{
    free(m->sl), free(m->sr), free(m->k), free(m->rest);
    free(m->x), free(m->v), free(m->x0), free(m->mass), free(m->fixed), free(m->gvec);
    free(m->xprev), free(m->xfree);
    free(m->rowptr), free(m->colind), free(m->diag), free(m->spring_slot);
    memset(m, 0, sizeof *m);
}

void cloth_forces(const cloth_model *m, const double *x, double *f)
{
    int k, d, i;
    for (i = 0; i < 3 * m->n; i++) f[i] = m->mass[i] * m->gvec[i];
    for (k = 0; k < m->ns; k++) {
        const double *a = x + 3 * m->sl[k], *b = x + 3 * m->sr[k];
        double z = dist3(a, b), c = z > 0 ? m->k[k] * (z - m->rest[k]) / z : 0;
        for (d = 0; d < 3; d++) { /* fij = K (z - L)/z p pulls left toward right */
            double fij = c * (a[d] - b[d]);
            f[3 * m->sl[k] + d] -= fij;
            f[3 * m->sr[k] + d] += fij;
        }
    }
}

void cloth_system(const cloth_model *m, const double *f, const double *v, double *a_val, double *b)
{
    const cloth_scene *s = m->scene;
    double dt = s->dt, dt2 = dt * dt;
    int64_t i, r;
    int k, d;
    memset(a_val, 0, (size_t)m->nnz * sizeof *a_val);
    for (r = 0; r < 3 * m->n; r++) {
        a_val[m->diag[r]] = (1 + dt * s->damping) * m->mass[r];
        b[r] = f[r];
    }
    for (k = 0; k < m->ns; k++)
        for (d = 0; d < 3; d++) {
            int64_t l = 3 * m->sl[k] + d, q = 3 * m->sr[k] + d;
            const int64_t *slot = m->spring_slot + 12 * k + 4 * d;
            double kk = m->k[k];
            a_val[slot[0]] += dt2 * kk;
            a_val[slot[1]] += dt2 * kk;
            a_val[slot[2]] -= dt2 * kk;
            a_val[slot[3]] -= dt2 * kk;
            /* b = dt (f + dt DfDx v), DfDx v = -(K (v_l - v_r)) on l, +... on r */
            b[l] -= dt * kk * (v[l] - v[q]);
            b[q] += dt * kk * (v[l] - v[q]);
        }
    for (i = 0; i < 3 * m->n; i++) b[i] *= dt;
    if (m->pins_after_solve) return;
    for (r = 0; r < 3 * m->n; r++) {
        b[r] *= m->fixed[r];
        for (i = m->rowptr[r]; i < m->rowptr[r + 1]; i++)
            if (m->colind[i] != r && (m->fixed[r] == 0 || m->fixed[m->colind[i]] == 0)) a_val[i] = 0;
        if (m->fixed[r] == 0) a_val[m->diag[r]] = (1 + dt * s->damping) * m->mass[r];
    }
}

void cloth_collide(const cloth_model *m, double *x, double *v)
{
    const cloth_scene *s = m->scene;
    int p, d;
    if (s->obstacle == OBSTACLE_SPHERE) {
        for (p = 0; p < m->n; p++) {
            double *q = x + 3 * p, r = dist3(q, s->center);
            if (r >= s->radius || !(r > 0)) continue;
            for (d = 0; d < 3; d++) {
                q[d] = s->center[d] + (q[d] - s->center[d]) * (s->radius / r);
                v[3 * p + d] = 0;
            }
        }
    } else if (s->obstacle == OBSTACLE_FLOOR) {
        for (p = 0; p < m->n; p++)
            if (x[3 * p + 2] < s->floor_z) {
                x[3 * p + 2] = s->floor_z;
                for (d = 0; d < 3; d++) v[3 * p + d] = 0;
            }
    }
}

void cloth_update(cloth_model *m, const double *dv)
{
    int i;
    memcpy(m->xprev, m->x, (size_t)3 * m->n * sizeof *m->x);
    for (i = 0; i < 3 * m->n; i++) m->v[i] += dv[i] * m->fixed[i];
    for (i = 0; i < 3 * m->n; i++) m->x[i] += m->scene->dt * m->v[i];
    memcpy(m->xfree, m->x, (size_t)3 * m->n * sizeof *m->x);
    cloth_collide(m, m->x, m->v);
}

void cloth_energy(const cloth_model *m, const double *x, const double *v, double *kinetic, double *spring)
{
    double ek = 0, es = 0;
    int i, k;
    for (i = 0; v && i < 3 * m->n; i++) ek += 0.5 * m->mass[i] * v[i] * v[i];
    for (k = 0; k < m->ns; k++) {
        double e = dist3(x + 3 * m->sl[k], x + 3 * m->sr[k]) - m->rest[k];
        es += 0.5 * m->k[k] * e * e;
    }
    *kinetic = ek;
    *spring = es;
}

double cloth_gravity_energy(const cloth_model *m, const double *x)
{
    double e = 0;
    int i;
    for (i = 0; i < 3 * m->n; i++) e -= m->mass[i] * m->gvec[i] * x[i];
    return e;
}

double cloth_total_energy(const cloth_model *m, const double *x, const double *v)
{
    double ek, es;
    cloth_energy(m, x, v, &ek, &es);
    return ek + es + cloth_gravity_energy(m, x);
}

double cloth_energy_scale(const cloth_model *m)
{
    const cloth_scene *s = m->scene;
    double g = sqrt(s->gravity[0] * s->gravity[0] + s->gravity[1] * s->gravity[1] + s->gravity[2] * s->gravity[2]);
    double ek, es;
    cloth_energy(m, m->x0, NULL, &ek, &es);
    return s->mass * g * fmax(s->width, s->height) + es;
}

double cloth_max_stretch(const cloth_model *m, const double *x)
{
    double worst = 0;
    int k;
    for (k = 0; k < m->ns; k++) {
        double r = dist3(x + 3 * m->sl[k], x + 3 * m->sr[k]) / m->rest[k];
        if (!(r <= worst)) worst = r; /* a NaN sticks */
    }
    return worst;
}

double cloth_condition_bound(const cloth_model *m)
{
    const cloth_scene *s = m->scene;
    double dt2 = s->dt * s->dt, hi = 0, lo = INFINITY;
    double *diag = calloc((size_t)3 * m->n, sizeof *diag), *off = calloc((size_t)3 * m->n, sizeof *off);
    int k, d, r;
    if (!diag || !off) {
        free(diag), free(off);
        return INFINITY;
    }
    for (k = 0; k < m->ns; k++)
        for (d = 0; d < 3; d++) {
            int l = 3 * m->sl[k] + d, q = 3 * m->sr[k] + d, both = m->fixed[l] != 0 && m->fixed[q] != 0;
            diag[l] += dt2 * m->k[k] * (m->fixed[l] != 0);
            diag[q] += dt2 * m->k[k] * (m->fixed[q] != 0);
            off[l] += both ? dt2 * m->k[k] : 0;
            off[q] += both ? dt2 * m->k[k] : 0;
        }
    for (r = 0; r < 3 * m->n; r++) {
        double a = (1 + s->dt * s->damping) * m->mass[r] + diag[r];
        hi = fmax(hi, a + off[r]);
        lo = fmin(lo, a - off[r]);
    }
    free(diag), free(off);
    return lo > 0 ? hi / lo : INFINITY;
}

double cloth_default_tol(const cloth_model *m)
{
    return m->scene->accuracy / cloth_condition_bound(m);
}

double cloth_backward_error(const cloth_model *m, const double *a_val, const double *b, const double *x)
{
    double rmax = 0, anorm = 0, xmax = 0, bmax = 0;
    int64_t r, q;
    for (r = 0; r < 3 * m->n; r++) {
        double sum = 0, row = 0;
        for (q = m->rowptr[r]; q < m->rowptr[r + 1]; q++) {
            sum += a_val[q] * x[m->colind[q]];
            row += fabs(a_val[q]);
        }
        rmax = fmax(rmax, fabs(b[r] - sum));
        anorm = fmax(anorm, row);
        xmax = fmax(xmax, fabs(x[r]));
        bmax = fmax(bmax, fabs(b[r]));
    }
    return anorm * xmax + bmax > 0 ? rmax / (anorm * xmax + bmax) : 0;
}

double cloth_max_displacement(const cloth_model *m, const double *x)
{
    double worst = 0;
    int p;
    for (p = 0; p < m->n; p++) {
        double r = dist3(x + 3 * p, m->x0 + 3 * p);
        if (!(r <= worst)) worst = r; /* a NaN sticks */
    }
    return worst;
}

/* y = A x on m's pattern. */
static void spmv(const cloth_model *m, const double *a, const double *x, double *y)
{
    int64_t r, q;
    for (r = 0; r < 3 * m->n; r++) {
        double s = 0;
        for (q = m->rowptr[r]; q < m->rowptr[r + 1]; q++) s += a[q] * x[m->colind[q]];
        y[r] = s;
    }
}

int cloth_cg(const cloth_model *m, const double *a_val, const double *b, double *x, double tol)
{
    int64_t N = 3 * m->n, i;
    double *r = malloc((size_t)N * sizeof *r), *z = malloc((size_t)N * sizeof *z);
    double *p = malloc((size_t)N * sizeof *p), *q = malloc((size_t)N * sizeof *q);
    double *dinv = malloc((size_t)N * sizeof *dinv), rz, bnorm = 0, rnorm;
    int it = -1, k;
    if (!r || !z || !p || !q || !dinv) goto out;
    for (i = 0; i < N; i++) {
        dinv[i] = 1 / a_val[m->diag[i]];
        x[i] = 0;
        r[i] = b[i];
        z[i] = dinv[i] * r[i];
        p[i] = z[i];
        bnorm += b[i] * b[i];
    }
    bnorm = sqrt(bnorm);
    for (rz = 0, i = 0; i < N; i++) rz += r[i] * z[i];
    if (bnorm == 0) {
        it = 0;
        goto out;
    }
    for (k = 1; k <= 10 * N; k++) {
        double pq = 0, alpha, rz_new = 0;
        spmv(m, a_val, p, q);
        for (i = 0; i < N; i++) pq += p[i] * q[i];
        alpha = rz / pq;
        rnorm = 0;
        for (i = 0; i < N; i++) {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
            rnorm += r[i] * r[i];
        }
        if (sqrt(rnorm) <= tol * bnorm) {
            it = k;
            break;
        }
        for (i = 0; i < N; i++) {
            z[i] = dinv[i] * r[i];
            rz_new += r[i] * z[i];
        }
        for (i = 0; i < N; i++) p[i] = z[i] + (rz_new / rz) * p[i];
        rz = rz_new;
    }
out:
    free(r), free(z), free(p), free(q), free(dinv);
    return it;
}
