/*
 * files.c -- opening the files a statement names without being led
 * elsewhere: a path resolved beneath a root directory one component at a
 * time (openat with O_NOFOLLOW | O_DIRECTORY, so neither '..' nor a
 * symbolic link can leave the root, whatever the text looks like), and the
 * write-beside-then-rename pattern with a temporary that is created, never
 * reused (O_CREAT | O_EXCL | O_NOFOLLOW, a fresh random name), so a link
 * planted where the temporary will be cannot redirect the write.
 *
 * The policy (which root, what a session may name) is the options
 * database's (dispatch/config.c); this file only does what it is told.
 */
#define _POSIX_C_SOURCE 200809L
#include "util.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* Deepest folder nesting a path beneath a root may name. */
#define UTIL_MAX_DEPTH 64

static void say(char *why, size_t whylen, const char *fmt, const char *arg)
{
    if (why && whylen) snprintf(why, whylen, fmt, arg);
}

int util_dir_beneath(int rootfd, const char *rel, char *leaf, size_t leaflen, char *why, size_t whylen)
{
    char part[256];
    const char *p = rel;
    int dirfd, depth = 0;
    if (!rel || !*rel) return say(why, whylen, "%s", "no file name"), -1;
    if (rel[0] == '/') return say(why, whylen, "%s", UTIL_WHY_ABSOLUTE), -1;
    if ((dirfd = openat(rootfd, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC)) < 0)
        return say(why, whylen, "the data directory cannot be opened: %s", strerror(errno)), -1;
    for (;;) {
        size_t n = strcspn(p, "/");
        int next;
        if (n >= sizeof part) {
            close(dirfd);
            return say(why, whylen, "%s", "a path component is longer than 255 characters"), -1;
        }
        memcpy(part, p, n);
        part[n] = '\0';
        p += n;
        while (*p == '/') p++;
        if (!strcmp(part, "..")) {
            close(dirfd);
            return say(why, whylen, "%s", UTIL_WHY_DOTDOT), -1;
        }
        if (!*p) {
            if (!part[0] || !strcmp(part, ".")) {
                close(dirfd);
                return say(why, whylen, "%s", "it names a folder, not a file"), -1;
            }
            snprintf(leaf, leaflen, "%s", part);
            return dirfd;
        }
        if (!part[0] || !strcmp(part, ".")) continue;
        if (++depth > UTIL_MAX_DEPTH) {
            close(dirfd);
            return say(why, whylen, "more than %s nested folders", "64"), -1;
        }
        next = openat(dirfd, part, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
        if (next < 0) {
            int e = errno;
            struct stat st;
            /* O_DIRECTORY | O_NOFOLLOW says ENOTDIR or ELOOP of a link */
            int link = e == ELOOP || (e == ENOTDIR && fstatat(dirfd, part, &st, AT_SYMLINK_NOFOLLOW) == 0 &&
                                      S_ISLNK(st.st_mode));
            close(dirfd);
            if (link) return say(why, whylen, "%s", UTIL_WHY_SYMLINK), errno = ELOOP, -1;
            say(why, whylen, "folder '%s' does not exist or cannot be opened", part);
            return errno = e, -1;
        }
        close(dirfd);
        dirfd = next;
    }
}

int util_dir_of(const char *path, char *leaf, size_t leaflen)
{
    const char *slash = strrchr(path, '/');
    char dir[4096];
    if (!slash) {
        snprintf(leaf, leaflen, "%s", path);
        return open(".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    }
    if (!slash[1]) return errno = EISDIR, -1;
    snprintf(leaf, leaflen, "%s", slash + 1);
    if (slash == path) return open("/", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if ((size_t)(slash - path) >= sizeof dir) return errno = ENAMETOOLONG, -1;
    memcpy(dir, path, (size_t)(slash - path));
    dir[slash - path] = '\0';
    return open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
}

int util_tmp_create(int dirfd, const char *leaf, char *tmp, size_t tmplen)
{
    static uint64_t state;
    int tries;
    if (!state) state = ((uint64_t)time(NULL) << 20) ^ (uint64_t)getpid() ^ (uint64_t)(uintptr_t)&state;
    for (tries = 0; tries < 100; tries++) {
        int fd;
        /* xorshift64*: the name need not be secret, O_EXCL is what makes it ours */
        state ^= state >> 12, state ^= state << 25, state ^= state >> 27;
        if (snprintf(tmp, tmplen, ".%s.tmp%012llx", leaf,
                     (unsigned long long)((state * 2685821657736338717ull) >> 16)) >= (int)tmplen)
            return errno = ENAMETOOLONG, -1;
        fd = openat(dirfd, tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (fd >= 0 || errno != EEXIST) return fd;
    }
    return errno = EEXIST, -1;
}

int util_open_read_at(int dirfd, const char *leaf, int follow)
{
    struct stat st;
    /* O_NONBLOCK: a FIFO planted under the name must not hang the reader */
    int fd = openat(dirfd, leaf, O_RDONLY | (follow ? 0 : O_NOFOLLOW) | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return -1;
    if (fstat(fd, &st) || !S_ISREG(st.st_mode)) {
        close(fd);
        return errno = EINVAL, -1;
    }
    /* a second hard link may be a file from outside the root, linked in */
    if (!follow && st.st_nlink > 1) {
        close(fd);
        return errno = EMLINK, -1;
    }
    return fd;
}

int util_open_input(const char *path)
{
    int fd = open(path, O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC), flags;
    if (fd < 0) return -1;
    if ((flags = fcntl(fd, F_GETFL)) < 0 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) < 0) {
        int e = errno;
        close(fd);
        return errno = e, -1;
    }
    return fd;
}

void util_fd_path(int fd, char *out, size_t len)
{
    snprintf(out, len, "/proc/self/fd/%d", fd);
}
