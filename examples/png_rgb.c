/*
 * png_rgb.c -- an RGB buffer to a PNG file through libpng's simplified API
 * (png_rgb.h): the one place the examples talk to libpng.
 */
#define _POSIX_C_SOURCE 200809L
#include "png_rgb.h"

#include <errno.h>
#include <png.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

int png_write_rgb(const char *path, int w, int h, const unsigned char *rgb, char *err, size_t errlen)
{
    png_image img;
    struct stat st;
    int ok, regular;
    FILE *f = fopen(path, "wb");
    if (!f) {
        if (err && errlen) snprintf(err, errlen, "%s: cannot open for writing: %s", path, strerror(errno));
        return -1;
    }
    /* A failed write removes what it left, but only from a regular file:
     * never a device or a pipe such as /dev/stdout. */
    regular = fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode);
    /* The simplified API catches libpng's errors itself (its own setjmp),
     * frees its structures on every path and leaves the message in img. */
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    img.width = (png_uint_32)w, img.height = (png_uint_32)h;
    img.format = PNG_FORMAT_RGB;
    ok = png_image_write_to_stdio(&img, f, 0, rgb, 0, NULL);
    /* fclose may be where a full disk shows up, so it counts too. */
    if (fclose(f) != 0 && ok) {
        int e = errno;
        if (regular) remove(path);
        if (err && errlen) snprintf(err, errlen, "%s: cannot write: %s", path, strerror(e));
        return -1;
    }
    if (!ok) {
        if (regular) remove(path);
        if (err && errlen) snprintf(err, errlen, "%s: libpng: %s", path, img.message[0] ? img.message : "write failed");
        return -1;
    }
    return 0;
}
