/*
 * server.h -- what silcd.c (process: options, listening, signals) and
 * session.c (one connection: handshake, requests, the session's engine)
 * share.  docs/server.md explains the concurrency model.
 */
#ifndef SILCD_SERVER_H
#define SILCD_SERVER_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

enum { LOG_ERROR = 0, LOG_WARN = 1, LOG_INFO = 2, LOG_DEBUG = 3 };

typedef struct srv_config {
    const char *listen;          /* tcp://host:port or unix:/path */
    const char *engine_config;   /* silc.conf for every session's engine, or NULL */
    int threads;                 /* thread budget of one operation; 0 = the config's */
    char *token;                 /* shared secret, NULL = none */
    size_t token_len;
    uint64_t max_value_bytes;    /* arrays of one PUT */
    uint64_t max_session_bytes;  /* values bound in one session; 0 = unlimited */
    uint64_t max_text_bytes;     /* one statement */
    int io_timeout_ms;           /* a peer stalling inside a frame is dropped after this */
    int max_clients;
    int log_level;
    uint64_t pool_bytes;         /* freed value arrays kept for reuse; 0 = none */
} srv_config;

extern srv_config srv_cfg;
/* Held around every call into an engine: plugins and their libraries keep
 * process-wide state (docs/server.md). */
extern pthread_mutex_t srv_compute_lock;
/* Readable once shutdown has begun: sessions poll it while idle. */
extern int srv_shutdown_fd;

void srv_log(int level, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Serves one accepted connection until BYE, disconnect or shutdown, then
 * closes fd.  id numbers the session in the log. */
void srv_session(int fd, unsigned long id);


#endif
