/*
 * png_rgb.h -- writes an RGB picture to a PNG file, for the examples that
 * draw one (cloth's frames, helmholtz's |u|); needs libpng.
 */
#ifndef PNG_RGB_H
#define PNG_RGB_H

#include <stddef.h>

/* Writes w x h pixels of rgb (3 bytes each, row 0 at the top) to path.  On
 * failure returns -1 with the message in err, and leaves no half-written
 * regular file behind. */
int png_write_rgb(const char *path, int w, int h, const unsigned char *rgb, char *err, size_t errlen);

#endif
