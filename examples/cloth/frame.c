/*
 * frame.c -- pictures of the cloth: one PNG per frame, so that a run can be
 * looked at (and made into a film) without a graphics library.
 *
 * The mesh is drawn in an oblique projection, seen from the front, right
 * and above:
 *     u = X + A Y,   v = Z + A Y,   A = 0.35,
 * so the depth axis y recedes up and to the right (a cabinet-like view in
 * which the x-z plane keeps its true shape).  Points that share (u, v) lie
 * on the line along D = (-A, 1, -A), the viewing direction, so p . D is the
 * depth: larger is further away.  Every grid quad is painted back to front
 * (the painter's algorithm: quads sorted by the depth of their centre) as
 * two flat triangles, shaded by |n . L| plus an ambient term, n the quad's
 * normal and L a fixed light from the front-left-above.  |.| makes the
 * lighting two-sided: the cloth's back is lit like its front.  The obstacle
 * goes behind the cloth: a sphere as a grey circle around its projected
 * centre, a floor as a grey line where it meets the front of the cloth.
 * The picture fits everything with a 5% margin, keeping the aspect ratio.
 * Quads with a non-finite corner are left out.  Every failure (a size
 * outside 16..4096, no memory, a file that cannot be opened or written) is
 * -1 with a message, with nothing leaked and no half-written file left.
 */
#define _POSIX_C_SOURCE 200809L
#include "cloth.h"
#include "png_rgb.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#define OBLIQUE 0.35
#define AMBIENT 0.3 /* the shade of a quad seen edge-on to the light: dark, never black */

typedef struct {
    unsigned char *rgb; /* w * h * 3 bytes, row 0 at the top */
    int w, h;
    double uc, vc, scale; /* the centre of the fitted (u, v) box, pixels per metre */
} canvas;

/* A quad to paint: its depth and its index (i + j * (nx - 1)). */
typedef struct {
    double depth;
    size_t q;
} quad_key;

static const unsigned char BACKGROUND[3] = {245, 245, 245};
static const unsigned char CLOTH[3] = {40, 95, 205};
static const unsigned char OUTLINE[3] = {130, 130, 130};

static int fail(char *err, size_t errlen, const char *fmt, ...)
{
    if (err && errlen > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return -1;
}

static void project(const double *p, double *u, double *v)
{
    *u = p[0] + OBLIQUE * p[1];
    *v = p[2] + OBLIQUE * p[1];
}

static int finite3(const double *p)
{
    return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
}

/* Screen coordinates of (u, v); v grows up, rows grow down. */
static void to_pixel(const canvas *c, double u, double v, double *px, double *py)
{
    *px = 0.5 * c->w + (u - c->uc) * c->scale;
    *py = 0.5 * c->h - (v - c->vc) * c->scale;
}

/* t rounded down and clamped to [lo, hi]; NaN gives lo.  Converting an
 * out-of-range double to int is undefined, so every loop bound goes
 * through here. */
static int clampi(double t, int lo, int hi)
{
    if (!(t > lo)) return lo;
    if (t >= hi) return hi;
    return (int)t;
}

static void put(canvas *c, int px, int py, const unsigned char *col)
{
    unsigned char *d = c->rgb + 3 * ((size_t)py * (size_t)c->w + (size_t)px);
    d[0] = col[0], d[1] = col[1], d[2] = col[2];
}

/* Fills the pixels whose centres lie in the triangle (edges included, so
 * that the two halves of a quad and neighbouring quads leave no cracks). */
static void fill_triangle(canvas *c, const double *x, const double *y, const unsigned char *col)
{
    double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    int k, px, py, x0, x1, y0, y1;
    for (k = 0; k < 3; k++)
        if (!isfinite(x[k]) || !isfinite(y[k])) return;
    if (!(fabs(area) > 0) || !isfinite(area)) return;
    x0 = clampi(floor(fmin(x[0], fmin(x[1], x[2]))), 0, c->w - 1);
    x1 = clampi(ceil(fmax(x[0], fmax(x[1], x[2]))), 0, c->w - 1);
    y0 = clampi(floor(fmin(y[0], fmin(y[1], y[2]))), 0, c->h - 1);
    y1 = clampi(ceil(fmax(y[0], fmax(y[1], y[2]))), 0, c->h - 1);
    for (py = y0; py <= y1; py++)
        for (px = x0; px <= x1; px++) {
            double sx = px + 0.5, sy = py + 0.5, e[3];
            /* Edge functions, signed by the area so that either winding works. */
            for (k = 0; k < 3; k++) {
                int a = k, b = (k + 1) % 3;
                e[k] = ((x[b] - x[a]) * (sy - y[a]) - (sx - x[a]) * (y[b] - y[a])) * area;
            }
            if (e[0] >= 0 && e[1] >= 0 && e[2] >= 0) put(c, px, py, col);
        }
}

/* A ring about 2 pixels wide around (cx, cy). */
static void draw_circle(canvas *c, double cx, double cy, double r)
{
    int px, py, x0, x1, y0, y1;
    if (!isfinite(cx) || !isfinite(cy) || !isfinite(r) || !(r > 0)) return;
    x0 = clampi(floor(cx - r - 2), 0, c->w - 1), x1 = clampi(ceil(cx + r + 2), 0, c->w - 1);
    y0 = clampi(floor(cy - r - 2), 0, c->h - 1), y1 = clampi(ceil(cy + r + 2), 0, c->h - 1);
    for (py = y0; py <= y1; py++)
        for (px = x0; px <= x1; px++)
            if (fabs(hypot(px + 0.5 - cx, py + 0.5 - cy) - r) <= 1.0) put(c, px, py, OUTLINE);
}

static void draw_hline(canvas *c, double y)
{
    int px, py;
    if (!isfinite(y) || y < -1 || y > c->h + 1) return;
    for (py = clampi(y - 1, 0, c->h - 1); py <= clampi(y + 1, 0, c->h - 1); py++)
        for (px = 0; px < c->w; px++) put(c, px, py, OUTLINE);
}

/* Far quads first; the index breaks ties so pictures are reproducible. */
static int cmp_far_first(const void *a, const void *b)
{
    const quad_key *p = a, *q = b;
    if (p->depth != q->depth) return p->depth < q->depth ? 1 : -1;
    return (p->q > q->q) - (p->q < q->q);
}

/* Fits the (u, v) box of the finite particles and the obstacle into the
 * picture.  An empty or single-point box still gives a usable scale. */
static void fit(canvas *c, const cloth_scene *s, const double *x, size_t n)
{
    double umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY, ymin = INFINITY;
    double u, v, du, dv, sc = INFINITY;
    size_t p;
    for (p = 0; p < n; p++) {
        const double *q = x + 3 * p;
        if (!finite3(q)) continue;
        project(q, &u, &v);
        umin = fmin(umin, u), umax = fmax(umax, u), vmin = fmin(vmin, v), vmax = fmax(vmax, v);
        ymin = fmin(ymin, q[1]);
    }
    if (s->obstacle == OBSTACLE_SPHERE && finite3(s->center) && isfinite(s->radius) && s->radius > 0) {
        project(s->center, &u, &v);
        umin = fmin(umin, u - s->radius), umax = fmax(umax, u + s->radius);
        vmin = fmin(vmin, v - s->radius), vmax = fmax(vmax, v + s->radius);
    } else if (s->obstacle == OBSTACLE_FLOOR && isfinite(s->floor_z) && isfinite(ymin)) {
        v = s->floor_z + OBLIQUE * ymin;
        vmin = fmin(vmin, v), vmax = fmax(vmax, v);
    }
    if (!(umin <= umax)) umin = umax = 0; /* nothing finite to show */
    if (!(vmin <= vmax)) vmin = vmax = 0;
    /* Halves first: umin + umax may overflow where their halves do not. */
    c->uc = 0.5 * umin + 0.5 * umax, c->vc = 0.5 * vmin + 0.5 * vmax;
    du = umax - umin, dv = vmax - vmin;
    if (du > 0) sc = 0.9 * c->w / du;
    if (dv > 0) sc = fmin(sc, 0.9 * c->h / dv);
    c->scale = isfinite(sc) ? sc : 1.0; /* all points equal: any scale shows them */
}

/* Paints the quads back to front; -1 if out of memory. */
static int draw_cloth(canvas *c, const cloth_scene *s, const double *x)
{
    /* Light from the front-left-above, and the viewing direction. */
    static const double L[3] = {-0.4, -0.6, 1.0}, D[3] = {-OBLIQUE, 1.0, -OBLIQUE};
    double llen = sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]);
    size_t nx = (size_t)s->nx, nq = (nx - 1) * (size_t)(s->ny - 1), m = 0, k;
    quad_key *keys = malloc(nq * sizeof *keys);
    if (!keys) return -1;
    for (k = 0; k < nq; k++) {
        size_t i = k % (nx - 1), j = k / (nx - 1), p = j * nx + i;
        const double *c0 = x + 3 * p, *c1 = c0 + 3, *c2 = c1 + 3 * nx, *c3 = c0 + 3 * nx;
        double depth = 0;
        int a;
        if (!finite3(c0) || !finite3(c1) || !finite3(c2) || !finite3(c3)) continue;
        for (a = 0; a < 3; a++) depth += D[a] * (c0[a] + c1[a] + c2[a] + c3[a]);
        if (!isfinite(depth)) continue;
        keys[m].depth = depth, keys[m].q = k, m++;
    }
    qsort(keys, m, sizeof *keys, cmp_far_first);
    for (k = 0; k < m; k++) {
        size_t i = keys[k].q % (nx - 1), j = keys[k].q / (nx - 1), p = j * nx + i;
        const double *q[4];
        double d1[3], d2[3], n[3], len, shade, px[4], py[4], tx[3], ty[3];
        unsigned char col[3];
        int a;
        q[0] = x + 3 * p, q[1] = q[0] + 3, q[2] = q[1] + 3 * nx, q[3] = q[0] + 3 * nx;
        /* The normal from the diagonals: defined for non-planar quads too. */
        for (a = 0; a < 3; a++) d1[a] = q[2][a] - q[0][a], d2[a] = q[3][a] - q[1][a];
        n[0] = d1[1] * d2[2] - d1[2] * d2[1];
        n[1] = d1[2] * d2[0] - d1[0] * d2[2];
        n[2] = d1[0] * d2[1] - d1[1] * d2[0];
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        shade = fabs(n[0] * L[0] + n[1] * L[1] + n[2] * L[2]) / (len * llen);
        if (!(len > 0) || !isfinite(shade)) shade = 0; /* a collapsed quad */
        shade = AMBIENT + (1 - AMBIENT) * fmin(shade, 1.0);
        for (a = 0; a < 3; a++) col[a] = (unsigned char)(CLOTH[a] * shade + 0.5);
        for (a = 0; a < 4; a++) {
            double u, v;
            project(q[a], &u, &v);
            to_pixel(c, u, v, &px[a], &py[a]);
        }
        tx[0] = px[0], tx[1] = px[1], tx[2] = px[2], ty[0] = py[0], ty[1] = py[1], ty[2] = py[2];
        fill_triangle(c, tx, ty, col);
        tx[1] = px[2], tx[2] = px[3], ty[1] = py[2], ty[2] = py[3];
        fill_triangle(c, tx, ty, col);
    }
    free(keys);
    return 0;
}

int frame_write_png(const char *path, const cloth_scene *s, const double *x, int w, int h, char *err,
                    size_t errlen)
{
    canvas c;
    size_t k;
    int ok;
    if (!path || !s || !x) return fail(err, errlen, "frame_write_png: no path, scene or positions");
    if (w < 16 || w > 4096 || h < 16 || h > 4096)
        return fail(err, errlen, "%s: picture size %d x %d outside 16..4096", path, w, h);
    if (s->nx < 2 || s->ny < 2)
        return fail(err, errlen, "%s: mesh %d x %d: need at least 2 x 2 particles", path, s->nx, s->ny);
    c.w = w, c.h = h;
    c.rgb = malloc((size_t)w * (size_t)h * 3);
    if (!c.rgb) return fail(err, errlen, "%s: out of memory for a %d x %d picture", path, w, h);
    for (k = 0; k < (size_t)w * (size_t)h; k++) memcpy(c.rgb + 3 * k, BACKGROUND, 3);
    fit(&c, s, x, (size_t)s->nx * (size_t)s->ny);
    if (s->obstacle == OBSTACLE_SPHERE && finite3(s->center)) {
        double u, v, px, py;
        project(s->center, &u, &v);
        to_pixel(&c, u, v, &px, &py);
        draw_circle(&c, px, py, s->radius * c.scale);
    } else if (s->obstacle == OBSTACLE_FLOOR) {
        /* The floor's front edge under the cloth: where the nearest row would rest. */
        double ymin = INFINITY, px, py;
        for (k = 0; k < (size_t)s->nx * (size_t)s->ny; k++)
            if (finite3(x + 3 * k)) ymin = fmin(ymin, x[3 * k + 1]);
        to_pixel(&c, 0, s->floor_z + OBLIQUE * ymin, &px, &py);
        draw_hline(&c, py);
    }
    if (draw_cloth(&c, s, x) != 0) {
        free(c.rgb);
        return fail(err, errlen, "%s: out of memory sorting the quads", path);
    }
    ok = png_write_rgb(path, w, h, c.rgb, err, errlen);
    free(c.rgb);
    return ok;
}
