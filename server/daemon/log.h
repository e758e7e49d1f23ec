/*
 * log.h — structured one-line logs of spinmodald on stderr.
 *
 * One line per event: logfmt (`ts=… level=info event=request key=value …`)
 * by default, or one JSON object per line.  log_init is called once by
 * main before any thread starts; log_event may then be called from any
 * thread (each line is written with a single fputs under a lock, so lines
 * never interleave).
 */
#ifndef SPINMODAL_LOG_H
#define SPINMODAL_LOG_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum log_format { LOG_TEXT = 0, LOG_JSON = 1 } log_format;

/** Choose the format (before threads start).  quiet = 1 drops "debug" lines. */
void log_init(log_format f, int quiet);

/**
 * Write one line: level ("info", "warn", "error", "debug"), event name,
 * then NULL-terminated pairs of key and value strings (a NULL value is
 * skipped).  Values with spaces, quotes or '=' are quoted in logfmt;
 * JSON output escapes them.
 */
void log_event(const char *level, const char *event, ...)
#if defined(__GNUC__)
    __attribute__((sentinel))
#endif
    ;

/** RFC 3339 UTC timestamp with milliseconds of unix time t into buf[32]. */
void log_time(double t, char buf[32]);

/** Current unix time in seconds (CLOCK_REALTIME). */
double log_now(void);

#ifdef __cplusplus
}
#endif

#endif /* SPINMODAL_LOG_H */
