/*
 * util.h -- small shared helpers of the core: a growable string buffer, the
 * closest-name suggestion used by every "did you mean" message, a
 * monotonic clock, and (files.c) opening files without following links out
 * of a root or through a planted temporary.  One implementation serves the
 * parser, the config reader and the dispatcher so their messages read alike.
 */
#ifndef SILC_UTIL_H
#define SILC_UTIL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

/* The complex number re + im*i, exact for every re and im (Inf and NaN
 * parts included, which re + im*I is not): C11's CMPLX, which glibc
 * defines for gcc but not for clang 14. */
static inline double _Complex util_cmplx(double re, double im)
{
    union {
        double _Complex z;
        double part[2];
    } u = {.part = {re, im}};
    return u.z;
}

typedef struct strbuf {
    char *s;
    size_t len, cap;
    int failed;   /* an append ran out of memory: the text is incomplete */
} strbuf;

void sb_init(strbuf *b);
void sb_free(strbuf *b);
int sb_puts(strbuf *b, const char *s);
int sb_printf(strbuf *b, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
int sb_vprintf(strbuf *b, const char *fmt, va_list ap);
const char *sb_str(const strbuf *b);   /* "" when empty */

/* Closest candidate by edit distance, or NULL if none is close enough (distance
 * at most max(1, strlen(name)/3)). */
const char *util_closest(const char *name, const char *const *cands, size_t ncands);

/* 1 when s is a name the language binds: a letter or '_', then letters,
 * digits and '_' (what PUT, load and the lexer accept). */
int util_is_name(const char *s);

/* Marks a helper of a recursive function that holds large buffers, so the
 * compiler does not inline them into each level of the recursion (the
 * evaluator walks expression trees SILC_MAX_EXPR_HEIGHT deep). */
#if defined(__GNUC__)
#define UTIL_NOINLINE __attribute__((noinline))
#else
#define UTIL_NOINLINE
#endif

double util_now(void);                 /* monotonic seconds */
/* FNV-1a: h carried through the n bytes at p.  Start from UTIL_FNV1A_START;
 * the tuner's step keys, the SPMD call check and the protocol's wait kinds
 * all hash with it. */
#define UTIL_FNV1A_START 1469598103934665603ull
uint64_t util_fnv1a(uint64_t h, const void *p, size_t n);
char *util_strdup(const char *s);
/* Formats a double the way the language prints values: %.17g, but shortest
 * round-trip form (tries %.15g, %.16g first). */
void util_fmt_double(char *out, size_t outlen, double x);

/* "<need> bytes (74.5 GiB), over the limit of <limit> bytes (2.0 GiB) by
 * 72.5 GiB": one wording for every size a client, a file or a statement can
 * claim (value.c, protocol.c), so a refusal says how far over it is.  need
 * is a double because a claimed size may not fit in 64 bits. */
void util_fmt_over_limit(char *out, size_t outlen, double need, double limit);

/* ---- files (files.c): opening what a statement names, without being led
 * elsewhere ---- */

/* Why util_dir_beneath refused a path, as the messages say it. */
#define UTIL_WHY_ABSOLUTE "an absolute path is not allowed"
#define UTIL_WHY_DOTDOT "'..' is not allowed"
#define UTIL_WHY_SYMLINK "it passes through a symbolic link, which is not followed"

/* The folder holding the file rel names beneath the directory rootfd, opened
 * one component at a time with O_NOFOLLOW | O_DIRECTORY: an absolute path,
 * '..', a symbolic link or a missing folder is refused with why filled.
 * Returns the folder's descriptor and the file's own name in leaf, or -1. */
int util_dir_beneath(int rootfd, const char *rel, char *leaf, size_t leaflen, char *why, size_t whylen);
/* The folder holding path (resolved as the operating system does: the
 * caller is its own operator) and the file's own name in leaf; -1 + errno. */
int util_dir_of(const char *path, char *leaf, size_t leaflen);
/* A new temporary beside leaf in dirfd, created O_CREAT | O_EXCL | O_NOFOLLOW
 * under a fresh name (written to tmp): a file or link already there is never
 * written through.  Returns its descriptor (write-only) or -1 + errno. */
int util_tmp_create(int dirfd, const char *leaf, char *tmp, size_t tmplen);
/* leaf in dirfd opened for reading, if it is a regular file (a FIFO does
 * not block the caller) and, unless follow, neither a symbolic link nor a
 * file with other hard links; -1 + errno otherwise (EINVAL: not a regular
 * file, ELOOP: a symbolic link, EMLINK: hard links). */
int util_open_read_at(int dirfd, const char *leaf, int follow);
/* Opens a user-named input file for reading without letting the open hang:
 * a FIFO with no writer is opened (O_NONBLOCK) and then read blocking, so
 * it reads as empty instead of waiting forever, while a pipe with a writer
 * (`<(zcat a.mtx.gz)`) reads normally.  What kinds of file a caller accepts,
 * and how many bytes, is the caller's rule (fstat the descriptor).  The
 * descriptor is close-on-exec; -1 with errno on failure. */
int util_open_input(const char *path);
/* "/proc/self/fd/N": a name for an open descriptor that libraries taking a
 * file name (HDF5) open as that very file. */
void util_fd_path(int fd, char *out, size_t len);

/* A size as silcd's options and the clients' SILC_MAX_REPLY_BYTES take it:
 * "123", "64K", "512M", "2G", "1T" (powers of 1024), at most max; -1 with
 * why on anything else. */
int util_parse_size(const char *s, uint64_t max, uint64_t *out, char *why, size_t whylen);

/* ---- large blocks (largealloc.c): a library's work space on transparent
 * huge pages ---- */

/* Requests from this size up are served by 2 MiB-aligned mappings advised
 * MADV_HUGEPAGE (where the kernel has transparent huge pages), smaller ones
 * by malloc.  UMFPACK's work space on a 250 000-unknown complex system comes
 * in blocks of 6 to 450 MB. */
#define UTIL_LARGE_MIN_BYTES ((size_t)4 << 20)
/* Live mappings it keeps track of; past them, malloc serves. */
#define UTIL_LARGE_MAX_BLOCKS 256
/* malloc, calloc, realloc and free by those rules.  free and realloc take
 * any pointer: one these functions did not hand out goes to libc's free or
 * realloc, so they can replace a library's hooks while blocks it allocated
 * before are still live.  Thread-safe; NULL and errno ENOMEM when out of
 * memory (realloc then leaves the block as it was). */
void *util_large_malloc(size_t bytes);
void *util_large_calloc(size_t count, size_t size);
void *util_large_realloc(void *p, size_t bytes);
void util_large_free(void *p);
/* 1 when p is a live block of the large allocator's own mappings. */
int util_large_owns(const void *p);
/* The bytes the large allocator's own mappings hold now: memory that
 * glibc's mallinfo2 does not see, for whoever measures what a call kept. */
size_t util_large_in_use(void);
/* 1 when the kernel gives transparent huge pages to an madvise'd mapping
 * (mode "always" or "madvise"); otherwise the functions above are libc's. */
int util_huge_pages_available(void);

#endif
