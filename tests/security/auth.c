/*
 * auth.c -- the attack suite's authentication and admission cases
 * (docs/security.md, "Authentication and admission"): who may open a
 * session on silcd, how fast a token can be guessed, whether silent
 * connections can lock a real client out, and silcd's strict options.
 *
 * Every server is private (remote_util.h) on 127.0.0.0/8 or a Unix socket;
 * every wait is bounded.  Timing is asserted only in the direction a slow
 * machine cannot break: "20 wrong guesses were NOT all answered within 1 s"
 * (a slow machine answers fewer), and "another address got in while this
 * one was still waiting" (an ordering, not a duration).
 */
#define _DEFAULT_SOURCE
#include "check.h"
#include "remote_util.h"

#include <silc.h>

static const char good_token[] = "0123456789abcdef0123456789abcdef";   /* test_token_file's */
static char scratch[64];   /* a private directory for files of this test */

static int contains(const char *s, const char *sub)
{
    return s && strstr(s, sub) != NULL;
}

static void put_file(const char *path, const char *text, mode_t mode)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, mode);
    if (fd >= 0) {
        if (write(fd, text, strlen(text)) != (ssize_t)strlen(text)) {}
        fchmod(fd, mode);
        close(fd);
    }
}

/* Runs silcd with argv (NULL-terminated), in directory cwd (NULL: here),
 * SILC_CONFIG set to config (NULL: unset); its stdout and stderr in out.
 * The exit status, or -1 if it was still running after 20 s (killed). */
static int run_silcd(const char *const *args, const char *cwd, const char *config, char *out,
                     size_t outlen)
{
    char log[128];
    const char *argv[24];
    int n = 0, i, status;
    pid_t pid;
    snprintf(log, sizeof log, "%s/run.log", scratch);
    argv[n++] = SILCD_PATH;
    for (i = 0; args[i] && n < 23; i++) argv[n++] = args[i];
    argv[n] = NULL;
    pid = fork();
    if (pid == 0) {
        int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0600);
        dup2(fd, 1);
        dup2(fd, 2);
        if (cwd && chdir(cwd) != 0) _exit(126);
        if (config) setenv("SILC_CONFIG", config, 1);
        else unsetenv("SILC_CONFIG");
        execv(SILCD_PATH, (char *const *)argv);
        _exit(127);
    }
    for (i = 0; i < 800; i++) {
        if (waitpid(pid, &status, WNOHANG) == pid) {
            check_read_file(log, out, outlen);
            return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
        }
        sleep_ms(25);
    }
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    check_read_file(log, out, outlen);
    return -1;
}

/* silcd ARGS must exit with status want and print exactly message as its
 * first line. */
static void expect_refusal(const char *const *args, const char *cwd, const char *config, int want,
                           const char *message, const char *what)
{
    char out[8192];
    int rc = run_silcd(args, cwd, config, out, sizeof out);
    size_t len = strcspn(out, "\n");
    CHECK(rc == want && strlen(message) == len && strncmp(out, message, len) == 0,
          "%s: exit %d (want %d), printed '%.*s', want '%s'", what, rc, want, (int)len, out,
          message);
}

/* ---- strict options ------------------------------------------------------ */

static void test_strict_options(void)
{
    char dir[128], fifo[128], big[128], cwd[128], sock[160], msg[512], out[8192];
    FILE *f;
    int i;
    snprintf(dir, sizeof dir, "%s/a-directory", scratch);
    snprintf(fifo, sizeof fifo, "%s/a-fifo", scratch);
    snprintf(big, sizeof big, "%s/big.conf", scratch);
    snprintf(cwd, sizeof cwd, "%s/cwd", scratch);
    snprintf(sock, sizeof sock, "unix:%s/s", scratch);
    mkdir(dir, 0700);
    mkfifo(fifo, 0600);
    mkdir(cwd, 0700);
    snprintf(msg, sizeof msg, "%s/silc.conf", cwd);
    mkdir(msg, 0700);   /* ./silc.conf, a directory */
    if ((f = fopen(big, "w"))) {   /* 2 MiB of comment lines: a valid config, but too large */
        for (i = 0; i < 32768; i++) fprintf(f, "; %61s\n", "x");
        fclose(f);
    }
    {
        int rc = run_silcd((const char *const[]){"--bogus", NULL}, NULL, NULL, out, sizeof out);
        CHECK(rc == 2 && strncmp(out, "silcd: unknown option '--bogus'\nusage: silcd", 44) == 0,
              "--bogus: exit %d, printed '%.80s'", rc, out);
    }
    expect_refusal((const char *const[]){"--bogus=1", NULL}, NULL, NULL, 2,
                   "silcd: unknown option '--bogus'", "--bogus=1");
    expect_refusal((const char *const[]){"-x", NULL}, NULL, NULL, 2,
                   "silcd: unknown option '-x'", "-x");
    expect_refusal((const char *const[]){"--max-value-bytes", "99999999999999999999999", NULL}, NULL,
                   NULL, 2, "silcd: invalid value '99999999999999999999999' for --max-value-bytes: "
                   "too large: the maximum is 9223372036854775807 bytes", "--max-value-bytes overflow");
    expect_refusal((const char *const[]){"--max-session-bytes", "8589934592G", NULL}, NULL, NULL, 2,
                   "silcd: invalid value '8589934592G' for --max-session-bytes: too large: the "
                   "maximum is 9223372036854775807 bytes", "--max-session-bytes 2^63");
    expect_refusal((const char *const[]){"--array-pool", "18446744073709551615", NULL}, NULL, NULL, 2,
                   "silcd: invalid value '18446744073709551615' for --array-pool: too large: the "
                   "maximum is 9223372036854775807 bytes", "--array-pool 2^64-1");
    expect_refusal((const char *const[]){"--max-value-bytes", "-1", NULL}, NULL, NULL, 2,
                   "silcd: invalid value '-1' for --max-value-bytes: expected a size in bytes with "
                   "an optional K, M, G or T suffix", "--max-value-bytes -1");
    expect_refusal((const char *const[]){"--dist-min-rows", "99999999999999999999999", NULL}, NULL,
                   NULL, 2, "silcd: invalid value '99999999999999999999999' for --dist-min-rows: "
                   "expected an integer from 1 to 9223372036854775807", "--dist-min-rows overflow");
    expect_refusal((const char *const[]){"--max-clients", "99999999999999999999", NULL}, NULL, NULL, 2,
                   "silcd: invalid value '99999999999999999999' for --max-clients: expected an "
                   "integer from 1 to 65536", "--max-clients overflow");
    expect_refusal((const char *const[]){"--io-timeout", "0.0000001", NULL}, NULL, NULL, 2,
                   "silcd: invalid value '0.0000001' for --io-timeout: expected seconds from 0.001 "
                   "to 86400", "--io-timeout below 1 ms");
    expect_refusal((const char *const[]){"--handshake-timeout", "1e9", NULL}, NULL, NULL, 2,
                   "silcd: invalid value '1e9' for --handshake-timeout: expected seconds from 0.001 "
                   "to 86400", "--handshake-timeout above a day");
    expect_refusal((const char *const[]){"--idle-timeout", "nan", NULL}, NULL, NULL, 2,
                   "silcd: invalid value 'nan' for --idle-timeout: expected 0 (off) or seconds "
                   "from 0.001 to 86400", "--idle-timeout nan");
    /* Config paths that are not regular files, and one too large. */
    snprintf(msg, sizeof msg, "silcd: config file %s is not a regular file", dir);
    expect_refusal((const char *const[]){"--listen", sock, "--config", dir, NULL}, NULL, NULL, 2, msg,
                   "--config a directory");
    snprintf(msg, sizeof msg, "silcd: config file %s is not a regular file", fifo);
    expect_refusal((const char *const[]){"--listen", sock, "--config", fifo, NULL}, NULL, NULL, 2, msg,
                   "--config a fifo");
    expect_refusal((const char *const[]){"--listen", sock, "--config", "/dev/zero", NULL}, NULL, NULL,
                   2, "silcd: config file /dev/zero is not a regular file", "--config a device");
    {
        /* /dev/null alone among devices: the empty config it is used as. */
        test_server srv;
        int rc = server_start(&srv, NULL, (const char *const[]){"--config", "/dev/null", NULL});
        CHECK(rc == 0, "--config /dev/null was refused (%d)", rc);
        if (rc == 0) CHECK(server_stop(&srv) == 0, "silcd --config /dev/null did not stop cleanly");
    }
    snprintf(msg, sizeof msg, "silcd: config file %s is 2097152 bytes, over the limit of 1048576", big);
    expect_refusal((const char *const[]){"--listen", sock, "--config", big, NULL}, NULL, NULL, 2, msg,
                   "--config of 2 MiB");
    snprintf(msg, sizeof msg, "silcd: config file %s is not a regular file", dir);
    expect_refusal((const char *const[]){"--listen", sock, NULL}, NULL, dir, 2, msg,
                   "SILC_CONFIG a directory");
    expect_refusal((const char *const[]){"--listen", sock, NULL}, cwd, NULL, 2,
                   "silcd: config file ./silc.conf is not a regular file", "./silc.conf a directory");
}

/* ---- the token rules ----------------------------------------------------- */

static void test_token_rules(void)
{
    char tok[128], opt[160], msg[512], out[8192], text[128];
    struct stat st;
    test_server srv;
    silc_context *c = NULL;
    size_t i, n;
    int ok;
    /* TCP without a token: refused, on the default address as on any. */
    expect_refusal((const char *const[]){NULL}, NULL, NULL, 1,
                   "silcd: refusing to listen on tcp://127.0.0.1:7070 without --token-file: every "
                   "local user (and anyone who can reach the address) could run code as this user; "
                   "create a token with 'silcd --make-token FILE' and pass --token-file FILE, listen "
                   "on a Unix socket (unix:/path, mode 0600), or pass --insecure to accept the risk",
                   "silcd on its default TCP address without a token");
    /* --insecure: starts, says so loudly, and lets anyone in. */
    unsetenv("SILC_TOKEN");
    unsetenv("SILC_TOKEN_FILE");
    if (server_start(&srv, "tcp://127.0.0.1:0", (const char *const[]){"--insecure", NULL}) == 0) {
        char logf[400];
        snprintf(logf, sizeof logf, "%s/log", srv.dir);
        check_read_file(logf, out, sizeof out);
        CHECK(contains(out, "WARNING: --insecure: listening on 127.0.0.1:0 with no token: every local "
                            "user can run code and read and write files as this user"),
              "--insecure: no loud warning in the log: '%s'", out);
        ok = silc_open_remote(&c, srv.url) == 0 && silc_exec(c, "x = 1") == 0;
        CHECK(ok, "--insecure: a client without a token: %s", c ? silc_context_errmsg(c) : silc_errmsg());
        silc_close(&c);
        CHECK(server_stop(&srv) == 0, "--insecure server did not stop cleanly");
    } else {
        CHECK(0, "silcd --insecure on TCP did not start");
    }
    /* Token files that are not private, or too short. */
    snprintf(tok, sizeof tok, "%s/token", scratch);
    snprintf(opt, sizeof opt, "--token-file=%s", tok);
    put_file(tok, "0123456789abcdef0123456789abcdef\n", 0644);
    snprintf(msg, sizeof msg, "silcd: token file '%s' has mode 0644: it must be readable by its owner "
             "only (chmod 600 '%s')", tok, tok);
    expect_refusal((const char *const[]){opt, NULL}, NULL, NULL, 2, msg, "a token file of mode 0644");
    put_file(tok, "0123456789abcde\n", 0600);
    snprintf(msg, sizeof msg, "silcd: token file '%s' holds a token of 15 bytes on its first line: 16 "
             "to 4096 are needed (silcd --make-token FILE writes one of 32)", tok);
    expect_refusal((const char *const[]){opt, NULL}, NULL, NULL, 2, msg, "a token of 15 bytes");
    snprintf(opt, sizeof opt, "--token-file=%s", scratch);
    snprintf(msg, sizeof msg, "silcd: token file '%s' is not a regular file", scratch);
    expect_refusal((const char *const[]){opt, NULL}, NULL, NULL, 2, msg, "a directory as token file");
    /* a FIFO with no writer (test_strict_options made it): refused, not waited on */
    snprintf(opt, sizeof opt, "--token-file=%s/a-fifo", scratch);
    snprintf(msg, sizeof msg, "silcd: token file '%s/a-fifo' is not a regular file", scratch);
    expect_refusal((const char *const[]){opt, NULL}, NULL, NULL, 2, msg, "a fifo as token file");
    snprintf(opt, sizeof opt, "--token-file=%s", tok);
    if (geteuid() == 0) {
        put_file(tok, "0123456789abcdef0123456789abcdef\n", 0600);
        if (chown(tok, 65534, 65534) == 0) {
            snprintf(msg, sizeof msg, "silcd: token file '%s' is owned by uid 65534, not by the user "
                     "silcd runs as (uid 0): another user could have written or could read it", tok);
            expect_refusal((const char *const[]){opt, NULL}, NULL, NULL, 2, msg,
                           "a token file owned by nobody");
        } else {
            printf("skipped: cannot chown a file to nobody (%s)\n", strerror(errno));
        }
    } else {
        printf("skipped: a token file owned by another user needs root to arrange\n");
    }
    unlink(tok);
    /* --make-token: a new 0600 file of 32 hex digits, never overwritten,
     * that a client then presents. */
    snprintf(msg, sizeof msg, "silcd: wrote a new token to %s (mode 0600); start silcd with "
             "--token-file %s and give clients SILC_TOKEN_FILE=%s", tok, tok, tok);
    expect_refusal((const char *const[]){"--make-token", tok, NULL}, NULL, NULL, 0, msg, "--make-token");
    CHECK(stat(tok, &st) == 0 && S_ISREG(st.st_mode) && (st.st_mode & 07777) == 0600 &&
              st.st_size == 33 && st.st_uid == geteuid(),
          "--make-token wrote mode %o, %lld bytes", (unsigned)(st.st_mode & 07777), (long long)st.st_size);
    n = check_read_file(tok, text, sizeof text);
    for (i = 0, ok = n == 33 && text[32] == '\n'; i < 32 && ok; i++)
        ok = (text[i] >= '0' && text[i] <= '9') || (text[i] >= 'a' && text[i] <= 'f');
    CHECK(ok, "--make-token wrote '%s', not 32 hex digits and a newline", text);
    {
        char again[128];
        snprintf(msg, sizeof msg, "silcd: --make-token: cannot create '%s': File exists (an existing "
                 "token file is never overwritten)", tok);
        expect_refusal((const char *const[]){"--make-token", tok, NULL}, NULL, NULL, 1, msg,
                       "--make-token over an existing file");
        check_read_file(tok, again, sizeof again);
        CHECK(strcmp(again, text) == 0, "--make-token changed an existing file");
    }
    if (server_start(&srv, "tcp://127.0.0.1:0", (const char *const[]){opt, NULL}) == 0) {
        setenv("SILC_TOKEN_FILE", tok, 1);
        ok = silc_open_remote(&c, srv.url) == 0 && silc_exec(c, "x = 2 * 3") == 0;
        CHECK(ok, "the token --make-token wrote, through SILC_TOKEN_FILE: %s",
              c ? silc_context_errmsg(c) : silc_errmsg());
        silc_close(&c);
        unsetenv("SILC_TOKEN_FILE");
        CHECK(silc_open_remote(&c, srv.url) != 0 &&
                  contains(silc_errmsg(), "authentication failed: missing token"),
              "no token over TCP: '%s'", silc_errmsg());
        CHECK(server_stop(&srv) == 0, "token server did not stop cleanly");
    } else {
        CHECK(0, "silcd with the token of --make-token did not start");
    }
    unlink(tok);
}

/* ---- guessing the token -------------------------------------------------- */

/* One attempt from src with token: the reply's opcode (its text in *msg). */
static int attempt(const char *src, int port, const char *token, char **msg, int timeout_ms)
{
    int fd = tcp_from(src, port), op;
    *msg = NULL;
    if (fd < 0) return -1;
    op = raw_handshake(fd, PROTO_VERSION, token, msg, timeout_ms);
    close(fd);
    return op;
}

static int count_lines(const char *text, const char *sub)
{
    int n = 0;
    for (; (text = strstr(text, sub)); text += strlen(sub)) n++;
    return n;
}

static void test_guessing(void)
{
    char tok[64], opt[96], logf[400], *msg = NULL, *log;
    test_server srv;
    int port, answered = 0, wrong_msgs = 0, fds[20], nfd = 0, i, op, waiting = 0;
    size_t got[20] = {0};
    double t0;
    if (test_token_file(tok, sizeof tok)) {
        CHECK(0, "cannot write a token file");
        return;
    }
    snprintf(opt, sizeof opt, "--token-file=%s", tok);
    if (server_start(&srv, "tcp://127.0.0.1:0", (const char *const[]){opt, NULL})) {
        CHECK(0, "token server did not start");
        unlink(tok);
        return;
    }
    port = atoi(strrchr(srv.url, ':') + 1);
    /* One guess after another from 127.0.0.1, for 1 s: without a delay a
     * loopback round trip answers hundreds; with it, a handful. */
    t0 = util_now();
    while (answered < 20 && util_now() - t0 < 1.0) {
        op = attempt("127.0.0.1", port, "0123456789abcdef0123456789abcdeX", &msg, 20000);
        answered++;
        wrong_msgs += op == PROTO_ERROR && contains(msg, "authentication failed: wrong token");
        free(msg);
    }
    CHECK(answered < 20, "20 wrong tokens were all answered within 1 s: no delay");
    CHECK(wrong_msgs == answered, "%d of %d wrong tokens told 'authentication failed: wrong token'",
          wrong_msgs, answered);
    /* 20 guesses at once from 127.0.0.3: still tried one per delay. */
    for (i = 0; i < 20; i++) {
        uint8_t hello[PROTO_HELLO_BYTES];
        const char *guess = "0123456789abcdef0123456789abcdeY";
        if ((fds[nfd] = tcp_from("127.0.0.3", port)) < 0) continue;
        proto_encode_hello(hello, PROTO_VERSION, (uint32_t)strlen(guess));
        raw_send(fds[nfd], hello, sizeof hello);
        raw_send(fds[nfd], guess, strlen(guess));
        nfd++;
    }
    CHECK(nfd == 20, "only %d of 20 parallel guesses connected", nfd);
    /* The server's hello comes at once; the answer to the token after it
     * (an ERROR frame, or a close). */
    t0 = util_now();
    for (answered = 0; util_now() - t0 < 1.0;) {
        struct pollfd p[20];
        for (i = 0; i < nfd; i++) p[i] = (struct pollfd){fds[i], POLLIN, 0};
        if (poll(p, (nfds_t)nfd, 50) <= 0) continue;
        for (i = 0; i < nfd; i++) {
            char buf[512];
            ssize_t r;
            if (!p[i].revents || fds[i] < 0) continue;
            r = recv(fds[i], buf, sizeof buf, MSG_DONTWAIT);
            if (r > 0) got[i] += (size_t)r;
            if (r == 0 || got[i] > PROTO_HELLO_BYTES) {
                close(fds[i]);
                fds[i] = -1;
                answered++;
            }
        }
    }
    CHECK(answered < 20, "20 wrong tokens sent at once were all answered within 1 s");
    /* Meanwhile another address with the right token gets in at once: its
     * OK comes while 127.0.0.3's guesses still wait their turn. */
    op = attempt("127.0.0.2", port, good_token, &msg, 5000);
    CHECK(op == PROTO_OK, "the right token from 127.0.0.2 during 127.0.0.3's backoff: %d '%s'", op,
          msg ? msg : "");
    free(msg);
    for (i = 0; i < nfd; i++) {
        char buf[512];
        ssize_t r = fds[i] >= 0 ? recv(fds[i], buf, sizeof buf, MSG_DONTWAIT) : 0;
        if (r > 0) got[i] += (size_t)r;
        if (fds[i] >= 0 && r != 0 && got[i] <= PROTO_HELLO_BYTES) waiting++;
    }
    CHECK(waiting > 0, "127.0.0.2 waited until all of 127.0.0.3's guesses were answered");
    for (i = 0; i < nfd; i++)
        if (fds[i] >= 0) close(fds[i]);
    /* The right token from 127.0.0.1 still gets in (after its wait), which
     * ends the burst. */
    op = attempt("127.0.0.1", port, good_token, &msg, 20000);
    CHECK(op == PROTO_OK, "the right token from 127.0.0.1 after its wrong ones: %d '%s'", op,
          msg ? msg : "");
    free(msg);
    /* Logged once per burst, not once per attempt. */
    snprintf(logf, sizeof logf, "%s/log", srv.dir);
    log = calloc(1, 1 << 20);
    if (log) {
        check_read_file(logf, log, 1 << 20);
        CHECK(count_lines(log, "refused: authentication failed: wrong token from 127.0.0.1;") == 1,
              "the burst from 127.0.0.1 was not logged exactly once:\n%s", log);
        CHECK(count_lines(log, "refused: authentication failed: wrong token from 127.0.0.3;") == 1,
              "the burst from 127.0.0.3 was not logged exactly once:\n%s", log);
        CHECK(contains(log, "127.0.0.1: authenticated after "), "the end of 127.0.0.1's burst is not "
              "in the log:\n%s", log);
        free(log);
    }
    CHECK(server_stop(&srv) == 0, "token server did not stop cleanly");
    unlink(tok);
}

/* ---- admission ----------------------------------------------------------- */

/* 300 silent connections from 127.0.0.1, then a real client from 127.0.0.1:
 * it gets in, and the oldest silent ones were closed to make room. */
static void silent_then_real(const char *const *extra, const char *what)
{
    char tok[64], opt[96];
    const char *opts[12];
    test_server srv;
    silc_context *c = NULL;
    int fds[300], n = 0, i, port, ok;
    if (test_token_file(tok, sizeof tok)) {
        CHECK(0, "cannot write a token file");
        return;
    }
    snprintf(opt, sizeof opt, "--token-file=%s", tok);
    opts[0] = opt;
    opts[1] = "--handshake-timeout";
    opts[2] = "30";
    for (i = 0; extra[i] && i < 8; i++) opts[3 + i] = extra[i];
    opts[3 + i] = NULL;
    if (server_start(&srv, "tcp://127.0.0.1:0", opts)) {
        CHECK(0, "%s: silcd did not start", what);
        unlink(tok);
        return;
    }
    port = atoi(strrchr(srv.url, ':') + 1);
    for (i = 0; i < 300; i++)
        if ((fds[n] = tcp_from("127.0.0.1", port)) >= 0) n++;
    CHECK(n == 300, "%s: only %d of 300 silent connections made", what, n);
    setenv("SILC_TOKEN_FILE", tok, 1);
    ok = silc_open_remote(&c, srv.url) == 0 && silc_exec(c, "x = 2 * 3") == 0;
    CHECK(ok, "%s: a real client from 127.0.0.1 behind 300 silent ones: %s", what,
          c ? silc_context_errmsg(c) : silc_errmsg());
    silc_close(&c);
    CHECK(n > 0 && closed_within(fds[0], 3000), "%s: the oldest silent connection is still open", what);
    for (i = 0; i < n; i++) close(fds[i]);
    unsetenv("SILC_TOKEN_FILE");
    CHECK(server_stop(&srv) == 0, "%s: silcd did not stop cleanly", what);
    unlink(tok);
}

/* A peer whose share is all open sessions: the newcomer is refused with
 * the reason, and another address still gets in. */
static void share_of_sessions(void)
{
    char tok[64], opt[96];
    test_server srv;
    silc_context *c[5] = {NULL};
    int i, ok;
    if (test_token_file(tok, sizeof tok)) {
        CHECK(0, "cannot write a token file");
        return;
    }
    snprintf(opt, sizeof opt, "--token-file=%s", tok);
    if (server_start(&srv, "tcp://127.0.0.1:0",
                     (const char *const[]){opt, "--max-clients", "8", "--peer-share", "0.5", NULL})) {
        CHECK(0, "silcd did not start");
        unlink(tok);
        return;
    }
    setenv("SILC_TOKEN_FILE", tok, 1);
    for (i = 0, ok = 1; i < 4; i++) ok &= silc_open_remote(&c[i], srv.url) == 0;
    CHECK(ok, "4 sessions from 127.0.0.1 within its share of 4: %s", silc_errmsg());
    CHECK(silc_open_remote(&c[4], srv.url) != 0 &&
              contains(silc_errmsg(), "server busy: 127.0.0.1 holds 4 open sessions, its share of 4 "
                                      "(silcd --peer-share 0.5 of --max-clients)"),
          "a 5th session from 127.0.0.1: '%s'", silc_errmsg());
    {
        /* Another address: silc_open_remote connects from 127.0.0.1, so by
         * hand, with the token. */
        char *msg = NULL;
        int port = atoi(strrchr(srv.url, ':') + 1);
        int op = attempt("127.0.0.2", port, good_token, &msg, 5000);
        CHECK(op == PROTO_OK, "127.0.0.2 while 127.0.0.1 holds its share: %d '%s'", op, msg ? msg : "");
        free(msg);
    }
    for (i = 0; i < 5; i++) silc_close(&c[i]);
    unsetenv("SILC_TOKEN_FILE");
    CHECK(server_stop(&srv) == 0, "silcd did not stop cleanly");
    unlink(tok);
}

int main(void)
{
    char cmd[160];
    signal(SIGPIPE, SIG_IGN);
    unsetenv("SILC_SERVER");
    snprintf(scratch, sizeof scratch, "/tmp/silc-auth-XXXXXX");
    if (!mkdtemp(scratch)) {
        perror("mkdtemp");
        return 1;
    }
    test_strict_options();
    test_token_rules();
    test_guessing();
    silent_then_real((const char *const[]){NULL}, "defaults (--max-clients 256, --peer-share 0.5)");
    silent_then_real((const char *const[]){"--max-clients", "8", NULL}, "--max-clients 8");
    share_of_sessions();
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", scratch);
    if (system(cmd)) {}
    return check_done();
}
