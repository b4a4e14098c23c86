/*
 * proc_usage.h -- the CPU time and page faults of a process so far, read
 * from Linux's /proc (header-only, shared by bench/mpi and bench/mpi_direct).
 *
 * On a machine shared with other work, wall times measure the load as much
 * as the program; the CPU time a process used and the page faults it took
 * over a timed statement do not depend on who else runs, so bench/mpi.sh
 * prints them next to the times (docs/distributed.md, item 7).  A process
 * need not be this one: a client of `silcd --mpi` reads the server ranks'
 * usage by pid, so the work a request costs is counted wherever it runs.
 */
#ifndef SILC_BENCH_PROC_USAGE_H
#define SILC_BENCH_PROC_USAGE_H

#include <stdio.h>
#include <string.h>
#include <unistd.h>

typedef struct bench_usage {
    double cpu_s;     /* user + system time of all its threads (1/100 s steps on Linux) */
    double sys_s;     /* the system part: page faults, mmap, the kernel's side of messages */
    long long faults; /* minor + major page faults */
} bench_usage;

/* pid's usage so far (pid 0: this process).  Returns 0, or -1 when /proc
 * cannot tell (not Linux, the process gone): then *u is zero. */
static inline int bench_proc_usage(long pid, bench_usage *u)
{
    char path[64], line[1024], *p;
    unsigned long long minflt = 0, majflt = 0, utime = 0, stime = 0;
    long ticks = sysconf(_SC_CLK_TCK);
    FILE *f;
    int ok;
    memset(u, 0, sizeof *u);
    if (pid) snprintf(path, sizeof path, "/proc/%ld/stat", pid);
    else snprintf(path, sizeof path, "/proc/self/stat");
    if (ticks <= 0 || !(f = fopen(path, "r"))) return -1;
    ok = fgets(line, sizeof line, f) != NULL;
    fclose(f);
    /* Fields after the command name, which may hold spaces and ')': from
     * its last ')', field 3 (state) on; minflt is field 10, majflt 12,
     * utime 14 and stime 15 (every thread's, in clock ticks). */
    if (!ok || !(p = strrchr(line, ')'))) return -1;
    if (sscanf(p + 1, " %*c %*d %*d %*d %*d %*d %*u %llu %*u %llu %*u %llu %llu", &minflt, &majflt,
               &utime, &stime) != 4)
        return -1;
    u->cpu_s = (double)(utime + stime) / (double)ticks;
    u->sys_s = (double)stime / (double)ticks;
    u->faults = (long long)(minflt + majflt);
    return 0;
}

/* The usage between two readings. */
static inline bench_usage bench_usage_since(const bench_usage *before, const bench_usage *after)
{
    bench_usage d;
    d.cpu_s = after->cpu_s - before->cpu_s;
    d.sys_s = after->sys_s - before->sys_s;
    d.faults = after->faults - before->faults;
    return d;
}

#endif
