/*
 * check.h -- the tiny test harness every test program uses.
 *
 * CHECK(cond, fmt, ...) records a pass or a failure with its location;
 * CHECK_NEAR(got, want, tol) compares numbers; check_done() prints the closing
 * line "N passed, N failed" (read by CI) and returns the exit status.  Kept
 * header-only so each test is one self-contained program.
 */
#ifndef SILC_CHECK_H
#define SILC_CHECK_H

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

static int check_passed_, check_failed_;

/* The text of file path into buf (len bytes with the NUL; "" when the file
 * is absent); returns the bytes read.  For tests that read what a program
 * wrote (its log, its stderr). */
static inline size_t check_read_file(const char *path, char *buf, size_t len)
{
    FILE *f = fopen(path, "r");
    size_t n = 0;
    if (f) {
        n = fread(buf, 1, len - 1, f);
        fclose(f);
    }
    buf[n] = '\0';
    return n;
}

static void check_report_(int ok, const char *file, int line, const char *fmt, ...)
{
    if (ok) {
        check_passed_++;
        return;
    }
    check_failed_++;
    fprintf(stderr, "%s:%d: FAIL: ", file, line);
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

#define CHECK(cond, ...) check_report_(!!(cond), __FILE__, __LINE__, __VA_ARGS__)
#define CHECK_NEAR(got, want, tol)                                                       \
    do {                                                                                 \
        double g_ = (got), w_ = (want), t_ = (tol);                                      \
        check_report_(fabs(g_ - w_) <= t_ || (g_ == w_), __FILE__, __LINE__,             \
                      "%s = %.17g, want %.17g (tol %.3g)", #got, g_, w_, t_);            \
    } while (0)

static int check_done(void)
{
    printf("%d passed, %d failed\n", check_passed_, check_failed_);
    return check_failed_ ? 1 : 0;
}

#endif
