/*
 * auth.c -- who may open a session on silcd: the token file (private,
 * long enough), `silcd --make-token`, the constant-time comparison, and the
 * per-peer backoff that makes guessing the token slow.
 *
 * The backoff lives in memory shared by silcd's parent and its session
 * processes (one per connection, silcd.c).  The parent records which peer
 * addresses hold connections (srv_auth_hold / srv_auth_drop, so an entry in
 * use is never given to another address); the session process that reads a
 * hello checks its token through srv_auth_verify.  After a failed check the
 * next check for that address may happen only after a delay that doubles
 * per failure (AUTH_DELAY_FIRST_MS up to AUTH_DELAY_CAP_MS) and is reset by
 * a success.  Checks of one address are serialized: a check first claims
 * the address's window with a compare-and-swap, so guesses sent on many
 * connections at once are still tried one per delay.  The fields the
 * session processes write are lock-free atomics, so a session process
 * killed at any instant (eviction, handshake timeout) leaves no lock held.
 * docs/security.md ("Authentication and admission") is the operator's view.
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE   /* MAP_ANONYMOUS */
#include "server.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "client.h"
#include "util.h"

enum {
    AUTH_DELAY_FIRST_MS = 100,      /* after the first failure */
    AUTH_DELAY_CAP_MS = SRV_AUTH_MAX_WAIT_MS,   /* the doubling stops here */
    AUTH_BURST_QUIET_MS = 60000,    /* a failure this long after the last one starts a new burst */
    AUTH_MAKE_TOKEN_BYTES = 16      /* random bytes; written as 32 hex digits */
};

typedef struct peer_entry {
    char addr[64];                   /* parent only; "" = free */
    int refs;                        /* parent only: live connections from addr */
    _Atomic uint32_t failures;       /* in the current burst; 0 after a success */
    _Atomic int64_t not_before_ms;   /* no check for addr before this (monotonic ms) */
    _Atomic int64_t last_fail_ms;
} peer_entry;

static peer_entry *peers;
static int n_peers;

static int64_t now_ms(void)
{
    return (int64_t)(util_now() * 1000.0);
}

static int64_t delay_after(uint32_t failures)
{
    int64_t d = AUTH_DELAY_FIRST_MS;
    while (failures-- > 1 && d < AUTH_DELAY_CAP_MS) d *= 2;
    return d < AUTH_DELAY_CAP_MS ? d : AUTH_DELAY_CAP_MS;
}

void srv_peer_of(int fd, char *out, size_t outlen)
{
    struct sockaddr_storage ss;
    socklen_t sl = sizeof ss;
    out[0] = '\0';
    if (getpeername(fd, (struct sockaddr *)&ss, &sl) != 0) return;
    if (ss.ss_family == AF_INET)
        inet_ntop(AF_INET, &((struct sockaddr_in *)&ss)->sin_addr, out, (socklen_t)outlen);
    else if (ss.ss_family == AF_INET6)
        inet_ntop(AF_INET6, &((struct sockaddr_in6 *)&ss)->sin6_addr, out, (socklen_t)outlen);
}

/* ---- the token file ---------------------------------------------------- */

int srv_auth_load_token(const char *path)
{
    char buf[PROTO_MAX_TOKEN + 2];
    struct stat st;
    ssize_t n;
    size_t len;
    /* O_NONBLOCK: a fifo named as the token file must not hang the start. */
    int fd = open(path, O_RDONLY | O_NOCTTY | O_NONBLOCK);
    if (fd < 0) {
        fprintf(stderr, "silcd: cannot read token file '%s': %s\n", path, strerror(errno));
        return -1;
    }
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        fprintf(stderr, "silcd: token file '%s' is not a regular file\n", path);
        close(fd);
        return -1;
    }
    if (st.st_uid != geteuid()) {
        fprintf(stderr, "silcd: token file '%s' is owned by uid %u, not by the user silcd runs "
                "as (uid %u): another user could have written or could read it\n", path,
                (unsigned)st.st_uid, (unsigned)geteuid());
        close(fd);
        return -1;
    }
    if (st.st_mode & 077) {
        fprintf(stderr, "silcd: token file '%s' has mode %04o: it must be readable by its "
                "owner only (chmod 600 '%s')\n", path, (unsigned)(st.st_mode & 07777), path);
        close(fd);
        return -1;
    }
    n = read(fd, buf, sizeof buf - 1);
    close(fd);
    if (n < 0) {
        fprintf(stderr, "silcd: cannot read token file '%s': %s\n", path, strerror(errno));
        return -1;
    }
    buf[n] = '\0';
    buf[strcspn(buf, "\r\n")] = '\0';
    len = strlen(buf);
    if (len < SRV_MIN_TOKEN_BYTES || len > PROTO_MAX_TOKEN) {
        fprintf(stderr, "silcd: token file '%s' holds a token of %zu bytes on its first line: "
                "%u to %u are needed (silcd --make-token FILE writes one of 32)\n", path, len,
                SRV_MIN_TOKEN_BYTES, PROTO_MAX_TOKEN);
        return -1;
    }
    free(srv_cfg.token);
    if (!(srv_cfg.token = malloc(len + 1))) return -1;
    memcpy(srv_cfg.token, buf, len + 1);
    srv_cfg.token_len = len;
    return 0;
}

int srv_auth_make_token(const char *path)
{
    static const char hex[] = "0123456789abcdef";
    unsigned char raw[AUTH_MAKE_TOKEN_BYTES];
    char text[2 * AUTH_MAKE_TOKEN_BYTES + 2];
    size_t i;
    ssize_t w;
    int fd, rnd = open("/dev/urandom", O_RDONLY);
    if (rnd < 0 || read(rnd, raw, sizeof raw) != (ssize_t)sizeof raw) {
        fprintf(stderr, "silcd: --make-token: cannot read /dev/urandom\n");
        if (rnd >= 0) close(rnd);
        return -1;
    }
    close(rnd);
    for (i = 0; i < sizeof raw; i++) {
        text[2 * i] = hex[raw[i] >> 4];
        text[2 * i + 1] = hex[raw[i] & 15];
    }
    text[2 * sizeof raw] = '\n';
    text[2 * sizeof raw + 1] = '\0';
    /* O_EXCL: never overwrite (nor follow a symlink planted at path). */
    fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW, 0600);
    if (fd < 0) {
        fprintf(stderr, "silcd: --make-token: cannot create '%s': %s%s\n", path, strerror(errno),
                errno == EEXIST ? " (an existing token file is never overwritten)" : "");
        return -1;
    }
    w = write(fd, text, strlen(text));
    if (w != (ssize_t)strlen(text) || fchmod(fd, 0600) != 0 || close(fd) != 0) {
        fprintf(stderr, "silcd: --make-token: cannot write '%s': %s\n", path, strerror(errno));
        unlink(path);
        return -1;
    }
    printf("silcd: wrote a new token to %s (mode 0600); start silcd with --token-file %s "
           "and give clients SILC_TOKEN_FILE=%s\n", path, path, path);
    return 0;
}

/* Length-independent timing: the loop runs over the expected token whatever
 * the client sent, and differences are OR-ed, never branched on. */
static int token_matches(const char *given)
{
    size_t glen = given ? strlen(given) : 0, i;
    unsigned diff = glen != srv_cfg.token_len;
    for (i = 0; i < srv_cfg.token_len; i++)
        diff |= (unsigned)(uint8_t)srv_cfg.token[i] ^ (unsigned)(i < glen ? (uint8_t)given[i] : 0);
    return diff == 0;
}

/* ---- the per-peer backoff ---------------------------------------------- */

int srv_auth_setup(int max_connections)
{
    /* Every live connection's address, and room to remember addresses
     * that failed after their connections closed. */
    n_peers = max_connections + 256;
    peers = mmap(NULL, (size_t)n_peers * sizeof *peers, PROT_READ | PROT_WRITE,
                 MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (peers == MAP_FAILED) {
        peers = NULL;
        return -1;
    }
    return 0;
}

static peer_entry *find_peer(const char *addr)
{
    int i;
    for (i = 0; peers && i < n_peers; i++)
        if (peers[i].addr[0] && strcmp(peers[i].addr, addr) == 0) return &peers[i];
    return NULL;
}

void srv_auth_hold(const char *addr)
{
    peer_entry *e;
    int i, pick = -1;
    if (!peers || !*addr) return;   /* a Unix socket: its mode admits only the owner */
    if ((e = find_peer(addr))) {
        e->refs++;
        return;
    }
    /* A free entry, else the unused one whose last failure is oldest: an
     * address with failures is forgotten last. */
    for (i = 0; i < n_peers; i++) {
        if (peers[i].refs) continue;
        if (!peers[i].addr[0] || atomic_load(&peers[i].failures) == 0) {
            pick = i;
            break;
        }
        if (pick < 0 || atomic_load(&peers[i].last_fail_ms) < atomic_load(&peers[pick].last_fail_ms))
            pick = i;
    }
    if (pick < 0) return;   /* cannot happen: more entries than connections */
    e = &peers[pick];
    snprintf(e->addr, sizeof e->addr, "%s", addr);
    e->refs = 1;
    atomic_store(&e->failures, 0);
    atomic_store(&e->not_before_ms, 0);
    atomic_store(&e->last_fail_ms, 0);
}

void srv_auth_drop(const char *addr)
{
    peer_entry *e = *addr ? find_peer(addr) : NULL;
    if (e && e->refs > 0) e->refs--;
}

static void sleep_ms(int64_t ms)
{
    struct timespec ts;
    ts.tv_sec = (time_t)(ms / 1000);
    ts.tv_nsec = (long)(ms % 1000) * 1000000L;
    nanosleep(&ts, NULL);
}

int srv_auth_verify(int fd, const char *given, int may_wait, char *why, size_t whylen)
{
    char addr[64];
    peer_entry *e;
    int64_t now, nb, last;
    uint32_t failures, n;
    if (!srv_cfg.token) return 0;
    srv_peer_of(fd, addr, sizeof addr);
    e = *addr ? find_peer(addr) : NULL;
    if (!e) {
        /* A Unix socket (mode 0600): no backoff, the comparison alone. */
        if (token_matches(given)) return 0;
        snprintf(why, whylen, "authentication failed: %s token", given ? "wrong" : "missing");
        srv_log(LOG_WARN, "refused: %s", why);
        return -1;
    }
    /* Claim the address's window: only the claimant compares; the others
     * wait (or, in silcd --mpi, which cannot wait, are refused unchecked). */
    for (;;) {
        now = now_ms();
        nb = atomic_load(&e->not_before_ms);
        failures = atomic_load(&e->failures);
        if (now >= nb) {
            if (failures && now - atomic_load(&e->last_fail_ms) > AUTH_BURST_QUIET_MS) {
                if (failures > 1)
                    srv_log(LOG_WARN, "%s: the previous burst of failed authentications "
                            "ended with %u failures", addr, (unsigned)failures);
                failures = 0;
            }
            if (atomic_compare_exchange_strong(&e->not_before_ms, &nb,
                                               now + delay_after(failures + 1)))
                break;
            continue;
        }
        if (!may_wait) {
            snprintf(why, whylen, "authentication refused unchecked: too many failed attempts "
                     "from %s; retry in %.1f s", addr, (double)(nb - now) / 1000.0);
            return -1;
        }
        sleep_ms(nb - now < 20 ? nb - now : 20);
    }
    if (token_matches(given)) {
        n = atomic_exchange(&e->failures, 0);
        atomic_store(&e->not_before_ms, 0);
        if (n > 1)
            srv_log(LOG_WARN, "%s: authenticated after %u failed attempts", addr, (unsigned)n);
        return 0;
    }
    last = atomic_exchange(&e->last_fail_ms, now);
    if (failures == 0 && atomic_load(&e->failures) != 0) atomic_store(&e->failures, 0);
    n = atomic_fetch_add(&e->failures, 1) + 1;
    snprintf(why, whylen, "authentication failed: %s token", given ? "wrong" : "missing");
    if (n == 1)
        srv_log(LOG_WARN, "refused: %s from %s; further failures from %s wait %d ms doubling "
                "to %d s each and are logged once per burst", why, addr, addr,
                AUTH_DELAY_FIRST_MS, AUTH_DELAY_CAP_MS / 1000);
    else
        srv_log(LOG_DEBUG, "refused: %s from %s (failure %u of this burst; %lld ms since "
                "the last)", why, addr, (unsigned)n, (long long)(now - last));
    return -1;
}

/* ---- admission: --max-clients and --peer-share ------------------------- */

int srv_admit(const char *peer, int nslots, srv_slot_at at, void *user, int *evict, char *why,
              size_t whylen)
{
    int i, free_slot = -1, from_peer = 0, oldest_peer = -1, oldest = -1;
    int peer_cap = (int)(srv_cfg.peer_share * srv_cfg.max_clients);
    double t_peer = 0, t_any = 0;
    if (peer_cap < 1) peer_cap = 1;
    *evict = 0;
    for (i = 0; i < nslots; i++) {
        srv_slot_view v;
        int mine;
        at(user, i, &v);
        if (!v.live) {
            if (free_slot < 0) free_slot = i;
            continue;
        }
        mine = *peer && strcmp(v.peer, peer) == 0;
        from_peer += mine;
        if (!v.handshaking) continue;
        if (oldest < 0 || v.accepted < t_any) oldest = i, t_any = v.accepted;
        if (mine && (oldest_peer < 0 || v.accepted < t_peer)) oldest_peer = i, t_peer = v.accepted;
    }
    if (*peer && from_peer >= peer_cap) {
        if (oldest_peer >= 0) {
            snprintf(why, whylen, "--peer-share %g of --max-clients %d", srv_cfg.peer_share,
                     srv_cfg.max_clients);
            *evict = 1;
            return oldest_peer;
        }
        snprintf(why, whylen, "server busy: %s holds %d open sessions, its share of %d (silcd "
                 "--peer-share %g of --max-clients)", peer, from_peer, peer_cap,
                 srv_cfg.peer_share);
        return -1;
    }
    if (free_slot >= 0) return free_slot;
    if (oldest >= 0) {
        snprintf(why, whylen, "--max-clients %d", srv_cfg.max_clients);
        *evict = 1;
        return oldest;
    }
    snprintf(why, whylen, "server busy: too many sessions (silcd --max-clients %d)",
             srv_cfg.max_clients);
    return -1;
}

void srv_refuse(int fd, const char *why)
{
    uint8_t hello[PROTO_HELLO_BYTES];
    struct iovec iov;
    char err[128];
    proto_encode_hello(hello, PROTO_VERSION, 0);
    iov.iov_base = hello;
    iov.iov_len = sizeof hello;
    if (proto_send(fd, &iov, 1, 1000, err, sizeof err) == 0)
        proto_send_text(fd, PROTO_ERROR, why, 1000, err, sizeof err);
    close(fd);
}
