/*
 * test_server.c -- silcd's process model under faults (issue 14): a session
 * that crashes loses only itself, sessions compute at once, connections
 * that never speak cannot lock real clients out, and killed clients, a
 * killed server and SIGTERM lose nothing that was promised; a plugin file
 * that cannot be loaded is warned about once in silcd's log (issue 32).
 *
 * Every server here is private (remote_util.h), on loopback or a Unix
 * socket in a private directory; every wait is bounded and every loop
 * counted, so the test ends by itself whatever the server does.  No timing
 * is asserted beyond "before a generous bound" (a hang, not a speed):
 * bench/remote measures how fast.
 */
#define _DEFAULT_SOURCE
#include "check.h"
#include "remote_util.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <silc.h>
#include <stdint.h>

#include "util.h"

static int contains(const char *s, const char *sub)
{
    return s && strstr(s, sub) != NULL;
}

/* The session processes of silcd `parent`, from /proc (Linux). */
static int children_of(pid_t parent, pid_t *out, int max)
{
    char path[64];
    FILE *f;
    int n = 0;
    long pid;
    snprintf(path, sizeof path, "/proc/%d/task/%d/children", (int)parent, (int)parent);
    if (!(f = fopen(path, "r"))) return -1;
    while (n < max && fscanf(f, "%ld", &pid) == 1) out[n++] = (pid_t)pid;
    fclose(f);
    return n;
}

/* Waits (bounded) until silcd has `want` session processes; their count. */
static int await_children(pid_t parent, int want, int ms)
{
    pid_t kids[512];
    int n = -1, i;
    for (i = 0; i <= ms / 20; i++) {
        if ((n = children_of(parent, kids, 512)) == want) return n;
        sleep_ms(20);
    }
    return n;
}

static long rss_kib(pid_t pid)
{
    char path[64], line[256];
    long kib = -1;
    FILE *f;
    snprintf(path, sizeof path, "/proc/%d/status", (int)pid);
    if (!(f = fopen(path, "r"))) return -1;
    while (fgets(line, sizeof line, f))
        if (sscanf(line, "VmRSS: %ld", &kib) == 1) break;
    fclose(f);
    return kib;
}

/* silcd's resident memory: the parent and every session process. */
static long server_rss_kib(pid_t parent)
{
    pid_t kids[512];
    int n = children_of(parent, kids, 512), i;
    long total = rss_kib(parent);
    for (i = 0; i < n; i++) total += rss_kib(kids[i]);
    return total;
}

static silc_context *open_client(const char *url)
{
    silc_context *c = NULL;
    if (silc_open_remote(&c, url)) {
        CHECK(0, "cannot open a session on %s: %s", url, silc_errmsg());
        return NULL;
    }
    return c;
}

/* name = 7 * ones(n, 1) in session c, and a check that it is still there. */
static void put_marker(silc_context *c, const char *name, int n)
{
    char text[96];
    snprintf(text, sizeof text, "%s = 7 * ones(%d, 1)", name, n);
    CHECK(silc_exec(c, text) == 0, "marker %s: %s", name, silc_context_errmsg(c));
}

static void check_marker(silc_context *c, const char *name, int n, const char *after)
{
    char text[160];
    silc_envelope_t e;
    snprintf(text, sizeof text, "ok_ = rows(%s) == %d && norm(%s - 7, inf) == 0", name, n, name);
    CHECK(silc_exec(c, text) == 0 && silc_get(c, &e, "ok_") == 0 && e.values[0] == 1,
          "after %s: %s lost or changed (%s)", after, name, silc_context_errmsg(c));
    if (e.values) silc_envelope_free(&e);
}

/* ---- 1. a crash ends only its own session ------------------------------ */

static void test_crash(const char *plugin_dir)
{
    test_server srv;
    char conf[512], opt[600];
    FILE *f;
    silc_context *a, *b;
    snprintf(conf, sizeof conf, "%s/crash.conf", plugin_dir);
    f = fopen(conf, "w");
    if (!f) {
        CHECK(0, "cannot write %s", conf);
        return;
    }
    fprintf(f, "[core]\nplugin_path = %s\n[dispatch]\nadd = crash, reference\n", plugin_dir);
    fclose(f);
    snprintf(opt, sizeof opt, "%s", conf);
    {
        const char *opts[] = {"--config", opt, "--log-level", "error", NULL};
        if (server_start(&srv, NULL, opts)) {
            CHECK(0, "silcd with the crash plugin did not start");
            return;
        }
    }
    a = open_client(srv.url);
    b = open_client(srv.url);
    if (!a || !b) goto out;
    put_marker(a, "keep", 1000);
    CHECK(silc_exec(b, "y = 2 * [1; 2]") == 0, "the crash plugin's scale: %s", silc_context_errmsg(b));
    /* abort() in a plugin, as a library's failed assertion */
    CHECK(silc_exec(b, "y = 13 * [1; 2]") != 0 &&
              contains(silc_context_errmsg(b), "lost: the server process running it died of signal 6"),
          "abort in a session: want a message naming signal 6, got '%s'", silc_context_errmsg(b));
    CHECK(contains(silc_context_errmsg(b), "other sessions are unaffected"),
          "crash message: '%s'", silc_context_errmsg(b));
    CHECK(silc_exec(b, "z = 1") != 0, "a crashed session answered again");
    check_marker(a, "keep", 1000, "another session's abort");
    silc_close(&b);
    /* SIGSEGV, as a plugin bug */
    b = open_client(srv.url);
    if (!b) goto out;
    /* (signal 11; 6 in sanitizer builds, whose SEGV handler aborts) */
    CHECK(silc_exec(b, "y = 11 * [1; 2]") != 0 &&
              (contains(silc_context_errmsg(b), "died of signal 11") ||
               contains(silc_context_errmsg(b), "died of signal 6")),
          "segfault in a session: '%s'", silc_context_errmsg(b));
    check_marker(a, "keep", 1000, "another session's segfault");
    silc_close(&b);
    b = open_client(srv.url);
    CHECK(b && silc_exec(b, "w = 3 * [1; 2]") == 0, "a new session after two crashes");
    CHECK(await_children(srv.pid, 2, 3000) == 2, "silcd keeps one process per live session");
out:
    silc_close(&a);
    silc_close(&b);
    CHECK(server_stop(&srv) == 0, "silcd did not shut down cleanly after crashes");
}

/* ---- 2. sessions do not queue behind each other ------------------------- */

typedef struct long_exec {
    const char *url;
    const char *text;
    int rc;
    char err[512];
    volatile int done;
} long_exec;

static void *run_long(void *p)
{
    long_exec *L = p;
    silc_context *c = NULL;
    L->rc = -1;
    if (silc_open_remote(&c, L->url) == 0) {
        L->rc = silc_exec(c, L->text);
        snprintf(L->err, sizeof L->err, "%s", L->rc ? silc_context_errmsg(c) : "");
        silc_close(&c);
    } else {
        snprintf(L->err, sizeof L->err, "%s", silc_errmsg());
    }
    L->done = 1;
    return NULL;
}

/* A statement that never ends by itself: the tests that need a request in
 * flight stop it with silcd's own limit (--max-request-seconds) or by
 * killing or stopping the server.  (An iteration count calibrated against
 * the server was tried: under CI's load a cold first session measured 15x
 * slow and the "long" loop ended before the tests looked at it.) */
static const char long_text[] = "i = 0; while (1) { i = i + 1 }";

/* Runs long_text in a new session of url on a thread of its own. */
static void start_long(long_exec *L, pthread_t *th, const char *url)
{
    memset(L, 0, sizeof *L);
    L->url = url;
    L->text = long_text;
    pthread_create(th, NULL, run_long, L);
}

static void test_no_queue(void)
{
    test_server srv;
    const char *opts[] = {"--log-level", "error", "--max-request-seconds", "4", NULL};
    long_exec L;
    pthread_t th;
    silc_context *c;
    int k, answered = 0;
    if (server_start(&srv, NULL, opts)) {
        CHECK(0, "silcd did not start");
        return;
    }
    start_long(&L, &th, srv.url);
    c = open_client(srv.url);
    sleep_ms(100);
    /* While the long statement runs, another session's tiny ones answer. */
    for (k = 0; c && k < 20 && !L.done; k++)
        if (silc_exec(c, "t = 1 + 1") == 0 && !L.done) answered++;
    CHECK(answered >= 5, "only %d tiny EXECs answered while another session computed (they queue)",
          answered);
    pthread_join(th, NULL);
    CHECK(L.rc != 0 && contains(L.err, "request took longer than 4 s: stopped"),
          "the endless EXEC under --max-request-seconds 4: '%s'", L.err);
    silc_close(&c);
    CHECK(server_stop(&srv) == 0, "silcd did not shut down cleanly");
}

/* ---- 3. connections that never speak ----------------------------------- */

/* A client that completes its handshake computes in spite of the n silent
 * connections fds; then they close and the server stops cleanly. */
static void served_then_stop(test_server *srv, const int *fds, int n, const char *who)
{
    silc_context *c = open_client(srv->url);
    int i;
    CHECK(c && silc_exec(c, "x = 2 * 3") == 0, "%s: %s", who, c ? silc_context_errmsg(c) : silc_errmsg());
    silc_close(&c);
    for (i = 0; i < n; i++) close(fds[i]);
    CHECK(server_stop(srv) == 0, "silcd did not shut down cleanly");
}

static void test_idle_connections(void)
{
    test_server srv;
    int fds[300], i, n = 0, port;
    silc_context *c;
    /* Same peer (a Unix socket): 300 silent connections against 256 slots.
     * The oldest silent ones give way to new connections, so a real
     * client, which completes its handshake at once, gets in. */
    {
        const char *opts[] = {"--log-level", "error", "--handshake-timeout", "30", NULL};
        if (server_start(&srv, NULL, opts)) {
            CHECK(0, "silcd did not start");
            return;
        }
        for (i = 0; i < 300; i++)
            if ((fds[n] = raw_connect(srv.url)) >= 0) n++;
        CHECK(n == 300, "only %d of 300 idle connections made", n);
        served_then_stop(&srv, fds, n, "a real client behind 300 idle connections");
    }
    /* TCP, 300 silent connections from 127.0.0.2: that peer holds at most
     * its share (--peer-share 0.5 of 64): each connection past it closes
     * the peer's oldest silent one (its newest 32 are still open), and a
     * client from 127.0.0.1 is served.  TCP needs a token: a private file
     * that the client presents through SILC_TOKEN_FILE. */
    {
        char tokf[64], tokopt[80];
        const char *opts[] = {"--log-level", "error", "--max-clients", "64", "--peer-share", "0.5",
                              "--handshake-timeout", "30", tokopt, NULL};
        int evicted = 0, open_now = 0;
        if (test_token_file(tokf, sizeof tokf)) {
            CHECK(0, "cannot write a token file");
            return;
        }
        snprintf(tokopt, sizeof tokopt, "--token-file=%s", tokf);
        if (server_start(&srv, "tcp://127.0.0.1:0", opts)) {
            CHECK(0, "silcd on tcp did not start");
            unlink(tokf);
            return;
        }
        port = atoi(strrchr(srv.url, ':') + 1);
        for (i = n = 0; i < 300; i++) {
            int fd = tcp_from("127.0.0.2", port);
            if (fd >= 0) fds[n++] = fd;
        }
        CHECK(n == 300, "only %d of 300 idle tcp connections made", n);
        for (i = 0; i < 10; i++) evicted += closed_within(fds[i], 3000);
        for (i = n - 10; i < n; i++) {
            struct pollfd p = {fds[i], POLLIN, 0};
            open_now += poll(&p, 1, 0) == 0;
        }
        CHECK(evicted == 10, "the oldest silent connections of a peer at its share: %d of 10 closed",
              evicted);
        CHECK(open_now == 10, "the newest silent connections: %d of 10 still open", open_now);
        setenv("SILC_TOKEN_FILE", tokf, 1);
        served_then_stop(&srv, fds, n, "a client from another address");
        unsetenv("SILC_TOKEN_FILE");
        unlink(tokf);
    }
    /* --handshake-timeout closes a silent connection; --idle-timeout a
     * session that stopped asking, and its client is told why. */
    {
        const char *opts[] = {"--log-level", "error", "--handshake-timeout", "0.3",
                              "--idle-timeout", "0.5", NULL};
        int fd;
        if (server_start(&srv, NULL, opts)) {
            CHECK(0, "silcd did not start");
            return;
        }
        fd = raw_connect(srv.url);
        CHECK(fd >= 0 && closed_within(fd, 5000), "a silent connection outlived --handshake-timeout 0.3");
        if (fd >= 0) close(fd);
        c = open_client(srv.url);
        CHECK(c && silc_exec(c, "x = 1") == 0, "a session under --idle-timeout");
        sleep_ms(1500);
        CHECK(c && silc_exec(c, "x = 2") != 0 &&
                  (contains(silc_context_errmsg(c), "idle for 0.5 s (silcd --idle-timeout)") ||
                   contains(silc_context_errmsg(c), "lost")),
              "an idle session: '%s'", c ? silc_context_errmsg(c) : "");
        silc_close(&c);
        CHECK(await_children(srv.pid, 0, 3000) == 0, "session processes left after the timeouts");
        CHECK(server_stop(&srv) == 0, "silcd did not shut down cleanly");
    }
}

/* ---- 4. faults lose nothing that was promised -------------------------- */

/* A client SIGKILLed 100 MB into a 200 MB PUT: its session process ends,
 * the memory it held goes back, the other session keeps its values. */
static void test_killed_client(void)
{
    test_server srv;
    const char *opts[] = {"--log-level", "error", "--max-value-bytes", "512M", NULL};
    silc_context *a;
    long before, during = 0, after = 0;
    pid_t pid;
    int status;
    if (server_start(&srv, NULL, opts)) {
        CHECK(0, "silcd did not start");
        return;
    }
    a = open_client(srv.url);
    if (!a) goto out;
    put_marker(a, "keep", 1000);
    before = server_rss_kib(srv.pid);
    pid = raw_partial_put(srv.url, "big", 25 * 1000 * 1000, 100u << 20);
    CHECK(pid > 0, "the client did not send its 100 MB");
    if (pid < 0) goto out;
    sleep_ms(200);
    during = server_rss_kib(srv.pid);
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    CHECK(await_children(srv.pid, 1, 5000) == 1, "the killed client's session process is still there");
    after = server_rss_kib(srv.pid);
    printf("silcd RSS: %ld MiB before, %ld MiB 100 MB into the PUT, %ld MiB after the kill\n",
           before / 1024, during / 1024, after / 1024);
    CHECK(during - before > 90 * 1024, "the partial PUT was not received (%ld KiB)", during - before);
    CHECK(after - before < 16 * 1024, "memory not given back: %ld KiB more than before", after - before);
    check_marker(a, "keep", 1000, "a client killed mid-PUT");
out:
    silc_close(&a);
    CHECK(server_stop(&srv) == 0, "silcd did not shut down cleanly");
}

/* silcd killed (every process of it) during a long EXEC: the client gets
 * "connection ... lost" at once instead of waiting for ever. */
static void test_killed_server(void)
{
    test_server srv;
    const char *opts[] = {"--log-level", "error", "--io-timeout", "2", NULL};
    long_exec L;
    pthread_t th;
    pid_t kids[64];
    double t0;
    int n, i, status;
    if (server_start(&srv, NULL, opts)) {
        CHECK(0, "silcd did not start");
        return;
    }
    start_long(&L, &th, srv.url);
    await_children(srv.pid, 1, 3000);
    sleep_ms(200);
    n = children_of(srv.pid, kids, 64);
    kill(srv.pid, SIGKILL);
    for (i = 0; i < n; i++) kill(kids[i], SIGKILL);
    waitpid(srv.pid, &status, 0);
    t0 = util_now();
    for (i = 0; i < 250 && !L.done; i++) sleep_ms(20);
    CHECK(L.done, "the client still waits 5 s after the server was killed");
    pthread_join(th, NULL);
    CHECK(L.rc != 0 && contains(L.err, "connection to silc server") && contains(L.err, "lost"),
          "client of a killed server: '%s'", L.err);
    printf("client told of the killed server after %.3f s: %s\n", util_now() - t0, L.err);
    {
        char cmd[400];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", srv.dir);
        if (system(cmd)) {}
    }
}

/* SIGTERM during an endless EXEC: it is answered (stopped after the
 * shutdown grace), new connections are refused, and silcd exits 0. */
static void test_sigterm_drains(void)
{
    test_server srv;
    const char *opts[] = {"--log-level", "error", NULL};
    long_exec L;
    pthread_t th;
    silc_context *idle;
    int status, i;
    if (server_start(&srv, NULL, opts)) {
        CHECK(0, "silcd did not start");
        return;
    }
    idle = open_client(srv.url);
    start_long(&L, &th, srv.url);
    await_children(srv.pid, 2, 3000);
    sleep_ms(200);
    kill(srv.pid, SIGTERM);
    sleep_ms(100);
    CHECK(raw_connect(srv.url) < 0, "a new connection accepted after SIGTERM");
    CHECK(!L.done, "the long EXEC ended before it could have finished");
    for (i = 0; i < 3000 && waitpid(srv.pid, &status, WNOHANG) != srv.pid; i++) sleep_ms(20);
    CHECK(i < 3000, "silcd still running 60 s after SIGTERM");
    pthread_join(th, NULL);
    /* Answered: stopped by the shutdown grace (docs/security.md, "Limits"). */
    CHECK(L.rc != 0 && contains(L.err, "server shutting down: request stopped after a grace"),
          "the EXEC in flight at SIGTERM was not answered: %s", L.err);
    CHECK(i < 3000 && WIFEXITED(status) && WEXITSTATUS(status) == 0, "silcd's exit after SIGTERM: %d",
          status);
    CHECK(silc_exec(idle, "x = 1") != 0, "an idle session survived SIGTERM");
    silc_close(&idle);
    {
        char cmd[400];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", srv.dir);
        if (system(cmd)) {}
    }
}

/* ---- 5. sessions' heap on transparent huge pages ---------------------- */

/* Whether the kernel gives huge pages on request (the only mode in which
 * silcd asks glibc for them: silcd.c, exec_with_huge_page_heap). */
static int thp_on_request(void)
{
    char mode[128] = "";
    size_t got = 0;
    FILE *f = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    if (f) {
        got = fread(mode, 1, sizeof mode - 1, f);
        fclose(f);
    }
    mode[got] = '\0';
    return strstr(mode, "[madvise]") != NULL;
}

/* The value of GLIBC_TUNABLES in pid's environment ("" if unset). */
static void tunables_of(pid_t pid, char *out, size_t len)
{
    char path[64], env[1 << 16];
    size_t got = 0, at;
    FILE *f;
    snprintf(path, sizeof path, "/proc/%ld/environ", (long)pid);
    out[0] = '\0';
    if (!(f = fopen(path, "r"))) return;
    got = fread(env, 1, sizeof env - 1, f);
    fclose(f);
    env[got] = '\0';
    for (at = 0; at < got; at += strlen(env + at) + 1)
        if (!strncmp(env + at, "GLIBC_TUNABLES=", 15)) snprintf(out, len, "%s", env + at + 15);
}

/* Whether a [heap] mapping of pid is marked for huge pages (VmFlags "hg"). */
static int heap_marked_huge(pid_t pid)
{
    char path[64], line[512];
    int in_heap = 0, marked = 0;
    FILE *f;
    snprintf(path, sizeof path, "/proc/%ld/smaps", (long)pid);
    if (!(f = fopen(path, "r"))) return -1;
    while (fgets(line, sizeof line, f)) {
        unsigned long lo, hi;
        char perms[8];
        if (sscanf(line, "%lx-%lx %7s", &lo, &hi, perms) == 3) /* a mapping's first line */
            in_heap = strstr(line, "[heap]") != NULL;
        else if (in_heap && !strncmp(line, "VmFlags:", 8) && strstr(line, " hg"))
            marked = 1;
    }
    fclose(f);
    return marked;
}

/* silcd asks for huge pages by re-executing itself with the tunable
 * added (a session's heap is then marked for them), keeps what else
 * GLIBC_TUNABLES held, and leaves an operator's own setting alone.  (What
 * /proc shows of the variable is its first tunable only: glibc 2.36 cuts
 * the original string at each ':' as it parses it.) */
static void test_huge_page_heap(void)
{
    static const struct {
        const char *given, *shown;
        int huge;
    } cases[] = {{NULL, "glibc.malloc.hugetlb=1", 1},
                 {"glibc.malloc.arena_max=2", "glibc.malloc.arena_max=2", 1},
                 {"glibc.malloc.hugetlb=0", "glibc.malloc.hugetlb=0", 0}};
    const char *saved = getenv("GLIBC_TUNABLES");
    char *keep = saved ? strdup(saved) : NULL;
    size_t k;
    if (!thp_on_request()) {
        printf("test_huge_page_heap: skipped: this kernel's transparent huge pages are not "
               "'madvise', so silcd does not ask for them\n");
        free(keep);
        return;
    }
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        test_server srv;
        silc_context *c;
        char got[4096];
        pid_t session;
        if (cases[k].given) setenv("GLIBC_TUNABLES", cases[k].given, 1);
        else unsetenv("GLIBC_TUNABLES");
        if (server_start(&srv, NULL, NULL) != 0) {
            CHECK(0, "silcd did not start with GLIBC_TUNABLES=%s", cases[k].given);
            continue;
        }
        tunables_of(srv.pid, got, sizeof got);
        CHECK(!strncmp(got, cases[k].shown, strlen(cases[k].shown)),
              "GLIBC_TUNABLES=%s: silcd runs with '%s', want '%s'",
              cases[k].given ? cases[k].given : "(unset)", got, cases[k].shown);
        /* The heap a session computes in (not checked under ASan, whose
         * allocator is not glibc's). */
        if ((c = open_client(srv.url)) != NULL) {
            put_marker(c, "h", 1 << 18);
            session = only_child_of(srv.pid);
            if (!getenv("ASAN_OPTIONS") && session > 0)
                CHECK(heap_marked_huge(session) == cases[k].huge,
                      "GLIBC_TUNABLES=%s: the session's heap %s marked for huge pages",
                      cases[k].given ? cases[k].given : "(unset)",
                      heap_marked_huge(session) ? "is" : "is not");
            CHECK(session > 0, "one session process");
            silc_close(&c);
        }
        CHECK(server_stop(&srv) == 0, "silcd stops cleanly");
    }
    if (keep) setenv("GLIBC_TUNABLES", keep, 1);
    else unsetenv("GLIBC_TUNABLES");
    free(keep);
}

/* ---- 8. a plugin that cannot be loaded is warned about once ---------- */

/* Occurrences of sub in the file at path (at most its first 64 KiB); -1 if
 * it cannot be read. */
static int count_in_file(const char *path, const char *sub)
{
    static char text[65536];
    FILE *f = fopen(path, "r");
    size_t len;
    int n = 0;
    const char *p;
    if (!f) return -1;
    len = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[len] = '\0';
    for (p = text; (p = strstr(p, sub)); p += strlen(sub)) n++;
    return n;
}

/* A file on silcd's plugin path that is not a shared object: its log says
 * so once, however many sessions and commands meet it (issue 32: three
 * times per command), and every session still computes. */
static void test_plugin_warned_once(const char *plugin_dir)
{
    test_server srv;
    char dir[512], bogus[600], conf[600], logf[300], want[700];
    FILE *f;
    int i, n;
    snprintf(dir, sizeof dir, "%s/bogus-plugin", plugin_dir);
    snprintf(bogus, sizeof bogus, "%s/libsilc_plugin_bogus.so", dir);
    snprintf(conf, sizeof conf, "%s/bogus.conf", plugin_dir);
    mkdir(dir, 0700);
    if (!(f = fopen(bogus, "w")) || fputs("not a shared object\n", f) < 0 || fclose(f)) {
        CHECK(0, "cannot write %s", bogus);
        return;
    }
    if (!(f = fopen(conf, "w")) || fprintf(f, "[core]\nplugin_path = %s\n", dir) < 0 || fclose(f)) {
        CHECK(0, "cannot write %s", conf);
        return;
    }
    if (server_start(&srv, NULL, (const char *const[]){"--config", conf, NULL})) {
        CHECK(0, "silcd with a bogus plugin file did not start");
        return;
    }
    for (i = 0; i < 3; i++) {
        silc_context *c = open_client(srv.url);
        silc_envelope_t x;
        double got[2] = {0, 0};
        if (!c) break;
        /* a sparse solve asks for backends; a misspelt one lists them all,
         * which opens every file on the path */
        CHECK(silc_exec(c, "A = sparse([4, 1; 1, 3]); x = A \\ [5; 4]") == 0 && silc_get(c, &x, "x") == 0 &&
                  silc_envelope_to_dense(&x, got) == 0 && fabs(got[0] - 1) < 1e-12 && fabs(got[1] - 1) < 1e-12,
              "session %d with a bogus plugin file: x = (%g, %g) %s", i, got[0], got[1], silc_context_errmsg(c));
        silc_envelope_free(&x);
        CHECK(silc_exec(c, "set dispatch.solve.sparse = nosuch_backend") != 0,
              "session %d: a misspelt backend was accepted", i);
        silc_close(&c);
    }
    snprintf(logf, sizeof logf, "%s/log", srv.dir);
    snprintf(want, sizeof want, "warning: cannot load plugin %s:", bogus);
    n = count_in_file(logf, want);
    CHECK(n == 1, "silcd's log warns about a plugin that cannot be loaded %d times over 3 sessions, not once", n);
    CHECK(server_stop(&srv) == 0, "silcd with a bogus plugin file did not stop cleanly");
    remove(bogus);
    remove(conf);
    rmdir(dir);
}

int main(int argc, char **argv)
{
    const char *plugin_dir = argc > 1 ? argv[1] : CRASH_PLUGIN_DIR;
    signal(SIGPIPE, SIG_IGN);
    test_crash(plugin_dir);
    test_no_queue();
    test_idle_connections();
    test_killed_client();
    test_killed_server();
    test_sigterm_drains();
    test_huge_page_heap();
    test_plugin_warned_once(plugin_dir);
    return check_done();
}
