/*
 * log.c — structured one-line logs (see log.h).  The format is chosen once
 * at start; a mutex keeps lines whole when worker and HTTP threads log at
 * the same time.
 */
#include "log.h"

#include "codec.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

static log_format log_fmt = LOG_TEXT;   /* set once by log_init before threads */
static int log_quiet = 1;
static pthread_mutex_t log_lock = PTHREAD_MUTEX_INITIALIZER;

void log_init(log_format f, int quiet)
{
    log_fmt = f;
    log_quiet = quiet;
}

double log_now(void)
{
    struct timespec ts;

    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void log_time(double t, char buf[32])
{
    codec_time_rfc3339(t, buf);
}

/* Append text to line (cap bytes), truncating. */
static void log_put(char *line, size_t cap, size_t *n, const char *s, size_t len)
{
    if (*n + len >= cap)
        len = *n + 1 < cap ? cap - *n - 1 : 0;
    memcpy(line + *n, s, len);
    *n += len;
    line[*n] = '\0';
}

/* Append value v escaped for the format (quoted when needed). */
static void log_put_value(char *line, size_t cap, size_t *n, const char *v)
{
    int quote = log_fmt == LOG_JSON || *v == '\0' || strpbrk(v, " \"=\t\n\r\\") != NULL;
    char esc[8];
    const unsigned char *p;

    if (quote)
        log_put(line, cap, n, "\"", 1);
    for (p = (const unsigned char *)v; *p; p++) {
        if (*p == '"' || *p == '\\') {
            esc[0] = '\\';
            esc[1] = (char)*p;
            log_put(line, cap, n, esc, 2);
        } else if (*p < 0x20) {
            snprintf(esc, sizeof(esc), "\\u%04x", *p);
            log_put(line, cap, n, esc, strlen(esc));
        } else {
            log_put(line, cap, n, (const char *)p, 1);
        }
    }
    if (quote)
        log_put(line, cap, n, "\"", 1);
}

static void log_put_pair(char *line, size_t cap, size_t *n, const char *k, const char *v,
                         int first)
{
    if (log_fmt == LOG_JSON) {
        log_put(line, cap, n, first ? "{\"" : ",\"", 2);
        log_put(line, cap, n, k, strlen(k));
        log_put(line, cap, n, "\":", 2);
    } else {
        if (!first)
            log_put(line, cap, n, " ", 1);
        log_put(line, cap, n, k, strlen(k));
        log_put(line, cap, n, "=", 1);
    }
    log_put_value(line, cap, n, v);
}

void log_event(const char *level, const char *event, ...)
{
    char line[2048], ts[32];
    size_t n = 0;
    const char *k, *v;
    va_list ap;

    if (log_quiet && strcmp(level, "debug") == 0)
        return;
    line[0] = '\0';
    log_time(log_now(), ts);
    log_put_pair(line, sizeof(line) - 4, &n, "ts", ts, 1);
    log_put_pair(line, sizeof(line) - 4, &n, "level", level, 0);
    log_put_pair(line, sizeof(line) - 4, &n, "event", event, 0);
    va_start(ap, event);
    while ((k = va_arg(ap, const char *)) != NULL) {
        v = va_arg(ap, const char *);
        if (v)
            log_put_pair(line, sizeof(line) - 4, &n, k, v, 0);
    }
    va_end(ap);
    if (log_fmt == LOG_JSON)
        log_put(line, sizeof(line), &n, "}", 1);
    log_put(line, sizeof(line), &n, "\n", 1);
    pthread_mutex_lock(&log_lock);
    fputs(line, stderr);
    fflush(stderr);
    pthread_mutex_unlock(&log_lock);
}
