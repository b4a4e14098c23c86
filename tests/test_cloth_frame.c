/*
 * test_frame.c -- checks frame_write_png (frame.c) by reading its pictures
 * back with libpng: the size, that cloth and background both show, that
 * shading follows the light, that bad sizes and paths are refused with a
 * message, and that non-finite or degenerate meshes do not crash.
 *
 *     test_frame [demo.png]
 *
 * With an argument, the picture of a 32 x 32 cloth draped over a sphere is
 * also kept there, to be looked at.  The last line is "N passed, M failed";
 * the exit status is non-zero on failure.
 */
#define _POSIX_C_SOURCE 200809L
#include "cloth.h"

#include <math.h>
#include <png.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int passed, failed;
static char dir[64] = "/tmp/test_frame.XXXXXX";

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (cond)                                                                                  \
            passed++;                                                                              \
        else {                                                                                     \
            failed++;                                                                              \
            printf("FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);                                 \
            printf(__VA_ARGS__);                                                                   \
            printf("\n");                                                                          \
        }                                                                                          \
    } while (0)

typedef struct {
    unsigned char *rgb;
    int w, h;
} picture;

static void tmp_path(char *buf, size_t len, const char *name)
{
    snprintf(buf, len, "%s/%s", dir, name);
}

/* Reads an RGB PNG; 0 on success. */
static int read_png(const char *path, picture *p)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    p->rgb = NULL;
    if (!png_image_begin_read_from_file(&img, path)) return -1;
    img.format = PNG_FORMAT_RGB;
    p->rgb = malloc(PNG_IMAGE_SIZE(img));
    if (!p->rgb || !png_image_finish_read(&img, NULL, p->rgb, 0, NULL)) {
        png_image_free(&img);
        free(p->rgb);
        p->rgb = NULL;
        return -1;
    }
    p->w = (int)img.width, p->h = (int)img.height;
    return 0;
}

static const unsigned char *pixel(const picture *p, int px, int py)
{
    return p->rgb + 3 * ((size_t)py * (size_t)p->w + (size_t)px);
}

static int is_background(const unsigned char *c)
{
    return c[0] >= 235 && c[1] >= 235 && c[2] >= 235;
}

/* Clearly blue: the cloth, however it is shaded. */
static int is_cloth(const unsigned char *c)
{
    return c[2] > c[0] + 20 && c[2] > c[1] + 10;
}

static int is_grey(const unsigned char *c)
{
    return c[0] == c[1] && c[1] == c[2] && c[0] < 200;
}

static int count(const picture *p, int (*pred)(const unsigned char *))
{
    int px, py, n = 0;
    for (py = 0; py < p->h; py++)
        for (px = 0; px < p->w; px++) n += pred(pixel(p, px, py));
    return n;
}

/* A scene with the fields frame.c reads. */
static cloth_scene scene(int nx, int ny, cloth_obstacle_kind obstacle)
{
    cloth_scene s;
    memset(&s, 0, sizeof s);
    snprintf(s.name, sizeof s.name, "test");
    s.nx = nx, s.ny = ny, s.width = s.height = 1;
    s.obstacle = obstacle;
    s.center[2] = -0.4, s.radius = 0.3;
    s.floor_z = -0.5;
    return s;
}

/* A flat nx x ny grid of side 1 centred on the origin in z = 0, turned by
 * tilt degrees about x. */
static double *grid(int nx, int ny, double tilt)
{
    double *x = malloc((size_t)nx * (size_t)ny * 3 * sizeof *x), t = tilt * acos(-1) / 180;
    int i, j;
    if (!x) exit(2);
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++) {
            double *p = x + 3 * (j * nx + i), y = (double)j / (ny - 1) - 0.5;
            p[0] = (double)i / (nx - 1) - 0.5, p[1] = y * cos(t), p[2] = y * sin(t);
        }
    return x;
}

static void test_picture(void)
{
    cloth_scene s = scene(8, 8, OBSTACLE_SPHERE);
    double *x = grid(8, 8, 30);
    char path[128], err[256] = "";
    picture p;
    int rc, cloth, back, edge = 0, px, py;
    tmp_path(path, sizeof path, "tilted.png");
    rc = frame_write_png(path, &s, x, 200, 150, err, sizeof err);
    CHECK(rc == 0, "%s", err);
    CHECK(read_png(path, &p) == 0, "cannot read %s back", path);
    if (p.rgb) {
        CHECK(p.w == 200 && p.h == 150, "size %d x %d", p.w, p.h);
        cloth = count(&p, is_cloth), back = count(&p, is_background);
        CHECK(cloth > 200 * 150 / 10, "%d cloth pixels", cloth);
        CHECK(back > 200 * 150 / 10, "%d background pixels", back);
        CHECK(count(&p, is_grey) > 20, "the sphere's outline: %d grey pixels", count(&p, is_grey));
        /* The 5% margin: a 4% border is all background. */
        for (py = 0; py < p.h; py++)
            for (px = 0; px < p.w; px++)
                if ((px < 8 || px >= 192 || py < 6 || py >= 144) && !is_background(pixel(&p, px, py))) edge++;
        CHECK(edge == 0, "%d pixels drawn in the margin", edge);
        free(p.rgb);
    }
    free(x);
}

/* The mean r + g + b of the non-background pixels of a one-quad scene with
 * corners a, b, c, d; -1 on failure. */
static double quad_brightness(const double *a, const double *b, const double *c, const double *d)
{
    cloth_scene s = scene(2, 2, OBSTACLE_NONE);
    double x[12], sum = 0;
    char path[128], err[256] = "";
    picture p;
    int px, py, n = 0;
    memcpy(x, a, 3 * sizeof *x), memcpy(x + 3, b, 3 * sizeof *x);
    memcpy(x + 6, d, 3 * sizeof *x), memcpy(x + 9, c, 3 * sizeof *x); /* (0,1) is d, (1,1) is c */
    tmp_path(path, sizeof path, "quad.png");
    if (frame_write_png(path, &s, x, 64, 64, err, sizeof err) != 0 || read_png(path, &p) != 0) {
        printf("quad: %s\n", err);
        return -1;
    }
    for (py = 0; py < p.h; py++)
        for (px = 0; px < p.w; px++) {
            const unsigned char *q = pixel(&p, px, py);
            if (!is_background(q)) sum += q[0] + q[1] + q[2], n++;
        }
    free(p.rgb);
    return n > 100 ? sum / n : -1;
}

/* The light comes mostly from above (frame.c), so a level quad is lit more
 * than an upright one facing the viewer; and the lighting is two-sided. */
static void test_shading(void)
{
    static const double l0[3] = {0, 0, 0}, l1[3] = {1, 0, 0}, l2[3] = {1, 1, 0}, l3[3] = {0, 1, 0};
    static const double u0[3] = {0, 0, 0}, u1[3] = {1, 0, 0}, u2[3] = {1, 0, 1}, u3[3] = {0, 0, 1};
    double level = quad_brightness(l0, l1, l2, l3), upright = quad_brightness(u0, u1, u2, u3);
    double flipped = quad_brightness(l0, l3, l2, l1);
    CHECK(level > 0 && upright > 0, "level %g, upright %g", level, upright);
    CHECK(upright < level - 30, "upright %g not darker than level %g", upright, level);
    CHECK(upright > 60, "upright %g: too dark (no ambient light?)", upright);
    CHECK(fabs(flipped - level) < 1e-9, "flipped %g, level %g: lighting not two-sided", flipped, level);
}

static void test_refusals(void)
{
    cloth_scene s = scene(8, 8, OBSTACLE_SPHERE);
    double *x = grid(8, 8, 0);
    char path[128], err[256], small[8];
    int rc;
    tmp_path(path, sizeof path, "small.png");
    err[0] = 0, rc = frame_write_png(path, &s, x, 8, 100, err, sizeof err);
    CHECK(rc == -1 && strstr(err, "8 x 100"), "w = 8: rc %d, err \"%s\"", rc, err);
    CHECK(access(path, F_OK) != 0, "w = 8 left a file");
    err[0] = 0, rc = frame_write_png(path, &s, x, 100, 5000, err, sizeof err);
    CHECK(rc == -1 && err[0], "h = 5000: rc %d, err \"%s\"", rc, err);
    err[0] = 0, rc = frame_write_png("/nonexistent/dir/x.png", &s, x, 100, 100, err, sizeof err);
    CHECK(rc == -1 && strstr(err, "/nonexistent/dir/x.png") && strstr(err, "cannot open"),
          "unwritable: rc %d, err \"%s\"", rc, err);
    s.nx = 1, err[0] = 0, rc = frame_write_png(path, &s, x, 100, 100, err, sizeof err);
    CHECK(rc == -1 && err[0], "nx = 1: rc %d, err \"%s\"", rc, err);
    s.nx = 8;
    /* A short err buffer gets a truncated message, not an overflow. */
    memset(small, 'x', sizeof small);
    rc = frame_write_png("/nonexistent/dir/x.png", &s, x, 100, 100, small, 4);
    CHECK(rc == -1 && small[3] == 0 && strlen(small) == 3 && small[4] == 'x', "short err: \"%.4s\"", small);
    rc = frame_write_png("/nonexistent/dir/x.png", &s, x, 100, 100, NULL, 0);
    CHECK(rc == -1, "err NULL: rc %d", rc);
    free(x);
}

/* Non-finite, huge and coincident positions: a picture or a message, never
 * a crash (the sanitizer build watches the rest). */
static void test_degenerate(void)
{
    cloth_scene s = scene(8, 8, OBSTACLE_SPHERE);
    double *x = grid(8, 8, 20);
    char path[128], err[256] = "";
    picture p;
    int k, rc;
    tmp_path(path, sizeof path, "odd.png");
    x[3 * 9] = NAN, x[3 * 20 + 2] = INFINITY, x[3 * 63 + 1] = -INFINITY;
    rc = frame_write_png(path, &s, x, 100, 100, err, sizeof err);
    CHECK(rc == 0, "some NaN: %s", err);
    CHECK(read_png(path, &p) == 0 && count(&p, is_cloth) > 100, "some NaN: no cloth drawn");
    free(p.rgb);
    for (k = 0; k < 3 * 64; k++) x[k] = NAN;
    rc = frame_write_png(path, &s, x, 100, 100, err, sizeof err);
    CHECK(rc == 0, "all NaN: %s", err);
    s.obstacle = OBSTACLE_FLOOR;
    rc = frame_write_png(path, &s, x, 100, 100, err, sizeof err);
    CHECK(rc == 0, "all NaN, floor: %s", err);
    for (k = 0; k < 3 * 64; k++) x[k] = 0.25;
    s.obstacle = OBSTACLE_NONE;
    rc = frame_write_png(path, &s, x, 100, 100, err, sizeof err);
    CHECK(rc == 0, "all equal: %s", err);
    for (k = 0; k < 3 * 64; k++) x[k] = (k % 2 ? 1 : -1) * 1e308 * (k % 5);
    s.obstacle = OBSTACLE_SPHERE, s.radius = 1e308;
    rc = frame_write_png(path, &s, x, 100, 100, err, sizeof err);
    CHECK(rc == 0, "huge: %s", err);
    s.radius = NAN, s.center[0] = INFINITY;
    rc = frame_write_png(path, &s, x, 100, 100, err, sizeof err);
    CHECK(rc == 0, "NaN sphere: %s", err);
    free(x);
}

/* A floor shows as a grey line across the picture. */
static void test_floor(void)
{
    cloth_scene s = scene(8, 8, OBSTACLE_FLOOR);
    double *x = grid(8, 8, 60);
    char path[128], err[256] = "";
    picture p;
    int rc, px, py, line = 0;
    tmp_path(path, sizeof path, "floor.png");
    rc = frame_write_png(path, &s, x, 120, 100, err, sizeof err);
    CHECK(rc == 0, "%s", err);
    if (rc == 0 && read_png(path, &p) == 0) {
        for (py = 0; py < p.h; py++) {
            int grey = 0;
            for (px = 0; px < p.w; px++) grey += is_grey(pixel(&p, px, py));
            line += grey > p.w * 9 / 10;
        }
        CHECK(line >= 1 && line <= 4, "%d grey rows", line);
        free(p.rgb);
    }
    free(x);
}

/* A 32 x 32 cloth of side 2 dropped centred on a sphere of radius 0.5: each
 * particle keeps its distance s from the centre along the cloth, lying on
 * the sphere up to the angle TH0 and then hanging along the tangent there,
 * with folds that deepen towards the hem. */
static void test_drape(const char *keep)
{
    enum { N = 32 };
    const double R = 0.5, TH0 = 1.0, PI = acos(-1);
    cloth_scene s = scene(N, N, OBSTACLE_SPHERE);
    double *x = malloc(3 * N * N * sizeof *x);
    char path[128], err[256] = "";
    picture p;
    int i, j, rc;
    if (!x) exit(2);
    s.center[0] = s.center[1] = s.center[2] = 0, s.radius = R;
    for (j = 0; j < N; j++)
        for (i = 0; i < N; i++) {
            double gx = 2.0 * i / (N - 1) - 1, gy = 2.0 * j / (N - 1) - 1, d = hypot(gx, gy);
            double phi = atan2(gy, gx), rho, z, *q = x + 3 * (j * N + i);
            if (d <= R * TH0) {
                rho = R * sin(d / R), z = R * cos(d / R) + 0.01;
            } else {
                double l = d - R * TH0, fold = 0.12 * l * cos(8 * phi);
                rho = R * sin(TH0) + l * cos(TH0) * 0.6 + fold, z = R * cos(TH0) + 0.01 - l * sin(TH0);
                z += 0.05 * l * sin(8 * phi + PI / 4);
            }
            q[0] = rho * cos(phi), q[1] = rho * sin(phi), q[2] = z;
        }
    tmp_path(path, sizeof path, "drape.png");
    rc = frame_write_png(path, &s, x, 480, 400, err, sizeof err);
    CHECK(rc == 0, "%s", err);
    if (rc == 0 && read_png(path, &p) == 0) {
        CHECK(count(&p, is_cloth) > 480 * 400 / 8, "%d cloth pixels", count(&p, is_cloth));
        free(p.rgb);
    }
    if (keep) {
        rc = frame_write_png(keep, &s, x, 480, 400, err, sizeof err);
        CHECK(rc == 0, "%s", err);
    }
    free(x);
}

int main(int argc, char **argv)
{
    const char *names[] = {"tilted.png", "quad.png", "small.png", "odd.png", "floor.png", "drape.png"};
    char path[128];
    size_t k;
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 2;
    }
    test_picture();
    test_shading();
    test_refusals();
    test_degenerate();
    test_floor();
    test_drape(argc > 1 ? argv[1] : NULL);
    for (k = 0; k < sizeof names / sizeof *names; k++) tmp_path(path, sizeof path, names[k]), remove(path);
    rmdir(dir);
    printf("%d passed, %d failed\n", passed, failed);
    return failed != 0;
}
