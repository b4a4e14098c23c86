/*
 * helmholtz.c -- a complex sparse solve through SILC: the 2-D Helmholtz
 * equation with absorbing boundaries (helmholtz.h), embedded.
 *
 *     helmholtz [-n N] [-k K] [-o picture.png]
 *
 * First the plane wave u = exp(i k x), whose exact solution is known: the
 * program prints the largest error on the grid (it falls as h^2; the test
 * checks that).  Then a Gaussian source at the centre of the square, whose
 * waves leave through the absorbing sides: with -o (and libpng) |u| is
 * written as a picture, dark blue for 0 to yellow for max |u|, y up.
 */
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helmholtz.h"
#include "silc.h"
#ifdef HELMHOLTZ_PNG
#include "png_rgb.h"
#endif

/* |u| on the (n+1)^2 grid as an RGB picture of (n+1)^2 pixels, row 0 at y = 1. */
static int write_picture(const char *path, int n, const double *u)
{
#ifdef HELMHOLTZ_PNG
    int N = n + 1;
    const double complex *z = (const double complex *)u;
    double top = 0.0;
    unsigned char *rgb = malloc((size_t)N * (size_t)N * 3);
    char err[512];
    if (!rgb) {
        fprintf(stderr, "helmholtz: out of memory for the picture\n");
        return -1;
    }
    for (int64_t k = 0; k < (int64_t)N * N; k++) top = fmax(top, cabs(z[k]));
    for (int r = 0; r < N; r++)
        for (int i = 0; i < N; i++) {
            double t = top > 0 ? cabs(z[i + (int64_t)(N - 1 - r) * N]) / top : 0.0;
            unsigned char *p = rgb + 3 * ((size_t)r * (size_t)N + (size_t)i);
            p[0] = (unsigned char)(255.0 * t);                  /* dark blue ... yellow */
            p[1] = (unsigned char)(40.0 + 200.0 * t);
            p[2] = (unsigned char)(120.0 * (1.0 - t));
        }
    int rc = png_write_rgb(path, N, N, rgb, err, sizeof err);
    if (rc) fprintf(stderr, "helmholtz: %s\n", err);
    free(rgb);
    return rc;
#else
    (void)n;
    (void)u;
    fprintf(stderr, "helmholtz: built without libpng: no picture %s\n", path);
    return -1;
#endif
}

int main(int argc, char **argv)
{
    int n = 200;
    double k = 20.0;
    const char *png = NULL;
    for (int a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "-n") && a + 1 < argc) n = atoi(argv[++a]);
        else if (!strcmp(argv[a], "-k") && a + 1 < argc) k = atof(argv[++a]);
        else if (!strcmp(argv[a], "-o") && a + 1 < argc) png = argv[++a];
        else {
            fprintf(stderr, "usage: helmholtz [-n N] [-k K] [-o picture.png]\n");
            return 2;
        }
    }
    silc_context *c = NULL;
    char err[512];
    if (silc_open(&c, NULL)) {
        fprintf(stderr, "helmholtz: %s\n", silc_errmsg());
        return 1;
    }
    int64_t rows = (int64_t)(n + 1) * (n + 1);
    double *u = n >= 2 && n <= 4000 ? malloc((size_t)(2 * rows) * sizeof *u) : NULL;
    int rc = 1;
    if (!u) {
        fprintf(stderr, "helmholtz: need 2 <= n <= 4000 (got %d)\n", n);
    } else if (helmholtz_solve(c, n, k, HELMHOLTZ_PLANE_WAVE, u, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
    } else {
        printf("plane wave exp(i k x), k = %g, n = %d (h = %g, %lld unknowns): max |u - u_exact| = %.3e\n", k, n,
               1.0 / n, (long long)rows, helmholtz_plane_wave_error(n, k, u));
        rc = 0;
        if (png) {
            if (helmholtz_solve(c, n, k, HELMHOLTZ_SOURCE, u, err, sizeof err)) {
                fprintf(stderr, "%s\n", err);
                rc = 1;
            } else if (write_picture(png, n, u)) {
                rc = 1;
            } else {
                printf("Gaussian source: |u| written to %s\n", png);
            }
        }
    }
    free(u);
    silc_close(&c);
    return rc;
}
