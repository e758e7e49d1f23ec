/*
 * main.c — spinmodald, the analysis daemon (server/DAEMON.md).
 *
 * How it fits: reads the flags (each with a SPINMODAL_* environment
 * variable; the flag wins), reads the token file once, turns SIGTERM and
 * SIGINT into a byte on a self-pipe (blocked in the threads it starts,
 * main reads the pipe after the start) and ignores SIGPIPE, then starts
 * the modules in order store_open -> jobs_start -> http_start and logs
 * `listening` with the bound address.  On SIGTERM/SIGINT: `stopping`, http_begin_stop (POST
 * answers 503), jobs_stop (grace period), http_stop, store_close,
 * `stopped`, exit 0.
 *
 * Exit status: 0 after a clean stop, 64 on a bad flag, 1 when it cannot
 * start (token file, database, port).
 */
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <microhttpd.h>
#include <sqlite3.h>

#include "codec.h"
#include "http.h"
#include "jobs.h"
#include "log.h"
#include "metrics.h"
#include "spinmodal.h"
#include "store.h"

enum { EXIT_START = 1, EXIT_USAGE = 64 };

#define MAIN_TOKEN_MAX 4096   /* bytes of a token file */
#define MAIN_PRUNE_EVERY_MS (10 * 60 * 1000) /* retention runs at start and then this often */

/* The flags, in --help order. */
enum {
    F_LISTEN,
    F_DB,
    F_WORKERS,
    F_QUEUE_MAX,
    F_MAX_BODY,
    F_MAX_ELEMENTS,
    F_MAX_SPEEDS,
    F_MAX_COORDINATES,
    F_MAX_FRAME_DOFS,
    F_MAX_RESULT_BYTES,
    F_JOB_TIMEOUT,
    F_TOKEN_FILE,
    F_AUTH_READS,
    F_CORS_ORIGIN,
    F_MAX_CONNECTIONS,
    F_MAX_CONNECTIONS_PER_CLIENT,
    F_MAX_WAITERS,
    F_REQUEST_DEADLINE,
    F_RETAIN_AGE,
    F_RETAIN_BYTES,
    F_REPLICA_ID,
    F_LEASE,
    F_DB_TIMEOUT,
    F_SHUTDOWN_GRACE,
    F_LOG_FORMAT,
    F_N
};

typedef struct main_flag {
    const char *name;   /* without the leading -- */
    const char *env;    /* environment variable */
    const char *arg;    /* argument name in --help */
    const char *def;    /* default in --help */
    const char *help;   /* one line */
} main_flag;

static const main_flag main_flags[F_N] = {
    {"listen", "SPINMODAL_LISTEN", "HOST:PORT", "127.0.0.1:8080",
     "address to listen on; [IPv6]:PORT; port 0 = any free port"},
    {"db", "SPINMODAL_DB", "PATH|URI", "./spinmodal.db",
     "SQLite database file, or postgresql://user@host/db to share one queue between replicas"},
    {"workers", "SPINMODAL_WORKERS", "N", "online cores", "solver threads (1-1024)"},
    {"queue-max", "SPINMODAL_QUEUE_MAX", "N", "1000", "queued jobs before POST answers 429"},
    {"max-body", "SPINMODAL_MAX_BODY", "BYTES", "1048576", "largest request body (413 above)"},
    {"max-elements", "SPINMODAL_MAX_ELEMENTS", "N", "2000", "most finite elements of a request"},
    {"max-speeds", "SPINMODAL_MAX_SPEEDS", "N", "1001", "most speeds of a request"},
    {"max-coordinates", "SPINMODAL_MAX_COORDINATES", "N", "1000",
     "most modal coordinates of a model on the dense path (cost ~n^3: ~5.6 s, ~200 MB a speed at 1000)"},
    {"max-frame-dofs", "SPINMODAL_MAX_FRAME_DOFS", "N", "1200",
     "most degrees of freedom in one frame's component-mode problem (cost ~n^3)"},
    {"max-result-bytes", "SPINMODAL_MAX_RESULT_BYTES", "BYTES", "50000000",
     "largest result document, estimated from the request (422 above; 0 = no limit)"},
    {"job-timeout", "SPINMODAL_JOB_TIMEOUT", "S", "30",
     "seconds of solving before a job fails; requests whose dense solves are estimated longer are refused (422)"},
    {"token-file", "SPINMODAL_TOKEN_FILE", "PATH", "none (no auth)",
     "file holding the bearer token POST and DELETE need"},
    {"auth-reads", "SPINMODAL_AUTH_READS", "yes|no", "no",
     "with a token: reading jobs, /metrics and /v1/validate need it too"},
    {"cors-origin", "SPINMODAL_CORS_ORIGIN", "ORIGIN", "none",
     "the one origin (scheme://host[:port]) allowed to call from browsers"},
    {"max-connections", "SPINMODAL_MAX_CONNECTIONS", "N", "512",
     "open connections (one thread each); an eighth (at least 16) is kept for probes and writes"},
    {"max-connections-per-client", "SPINMODAL_MAX_CONNECTIONS_PER_CLIENT", "N", "64",
     "open connections from one IP address (0 = no limit; behind a proxy raise it)"},
    {"max-waiters", "SPINMODAL_MAX_WAITERS", "N", "a quarter of --max-connections (128)",
     "long polls (?wait) waiting at once, <= half of --max-connections; over it the oldest "
     "answers at once with the job's state (0 = ?wait never blocks)"},
    {"request-deadline", "SPINMODAL_REQUEST_DEADLINE", "S", "30",
     "seconds for a request's head and body to arrive, however slowly sent"},
    {"retain-age", "SPINMODAL_RETAIN_AGE", "S", "2592000 (30 days)",
     "finished jobs older than this are removed (0 = keep by age)"},
    {"retain-bytes", "SPINMODAL_RETAIN_BYTES", "BYTES", "1073741824 (1 GiB)",
     "oldest finished jobs are removed above this much live data (0 = no bound)"},
    {"replica-id", "SPINMODAL_REPLICA_ID", "ID", "host:pid:random",
     "PostgreSQL: the owner id this replica stamps on the jobs it claims (unique per replica)"},
    {"lease", "SPINMODAL_LEASE", "S", "30",
     "PostgreSQL: seconds a claimed job stays this replica's without a heartbeat"},
    {"db-timeout", "SPINMODAL_DB_TIMEOUT", "S", "5",
     "deadline of one database call (locks, connection, each round trip); past it 503 with "
     "Retry-After. Probes (/readyz, /metrics) wait at most 0.5 s"},
    {"shutdown-grace", "SPINMODAL_SHUTDOWN_GRACE", "S", "10",
     "seconds running jobs get to finish on SIGTERM"},
    {"log-format", "SPINMODAL_LOG_FORMAT", "text|json", "text", "log lines on stderr"},
};

/* The effective settings. */
typedef struct main_opts {
    char host[256];          /* listen address, without brackets */
    int port;                /* 0..65535 */
    int ipv6;                /* host was given in [brackets] */
    const char *db;
    long workers, queue_max, max_body, max_elements, max_speeds, max_coordinates, max_frame_dofs;
    double job_timeout;      /* s, > 0 */
    double shutdown_grace;   /* s, >= 0 */
    double retain_age;       /* s, 0 = no age bound */
    const char *replica_id;  /* NULL = generated */
    double lease;            /* s, PostgreSQL claims */
    double db_timeout;       /* s, deadline of one store call */
    long long retain_bytes;  /* bytes, 0 = no size bound */
    long long max_result_bytes; /* estimated bytes of a result document, 0 = no limit */
    const char *token_file;  /* NULL = no auth */
    int auth_reads;          /* 1: reads need the token too */
    const char *cors_origin; /* NULL = no CORS */
    long per_client;         /* connections per IP address, 0 = no limit */
    long max_connections;    /* open connections, >= 32 */
    long max_waiters;        /* waiting long polls, <= max_connections / 2; -1 = a quarter */
    double request_deadline; /* s, > 0 */
    log_format format;
} main_opts;

/* The running daemon, for the stop. */
typedef struct main_daemon {
    store *st;
    metrics *mx;
    jobs *j;
    http *h;
} main_daemon;

static void main_help(void)
{
    int i;

    printf("spinmodald %s: HTTP daemon computing natural frequencies of spinning beam "
           "structures\n\nusage: spinmodald [OPTION]...\n\noptions (each also read from the "
           "environment variable shown; the option wins):\n",
           SM_VERSION);
    for (i = 0; i < F_N; i++)
        printf("  --%s %s\n      %s\n      env %s, default %s\n", main_flags[i].name,
               main_flags[i].arg, main_flags[i].help, main_flags[i].env, main_flags[i].def);
    printf("  -h, --help       show this help\n"
           "  -V, --version    show the versions\n\n"
           "exit status: 0 after a clean stop (SIGTERM, SIGINT), 64 bad option,\n"
           "1 cannot start (token file, database, port)\n");
}

static void main_version(void)
{
    printf("spinmodald %s (libspinmodal %s, libmicrohttpd %s, SQLite %s)\n", SM_VERSION,
           sm_version(), MHD_get_version(), sqlite3_libversion());
}

/* ------------------------------------------------------------ values */

/* Integer in [lo, hi]; 0 or -1. */
static int main_long(const char *s, long lo, long hi, long *out)
{
    char *end;
    long v;

    errno = 0;
    v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi || s[0] == '+' || s[0] == ' ')
        return -1;
    *out = v;
    return 0;
}

/* Number of seconds in [lo, hi]; 0 or -1. */
static int main_seconds(const char *s, double lo, double hi, double *out)
{
    char *end;
    double v;

    errno = 0;
    v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v) || v < lo || v > hi ||
        strpbrk(s, "xXnNiI") != NULL)
        return -1;
    *out = v;
    return 0;
}

/* HOST:PORT or [IPV6]:PORT into o; 0 or -1. */
static int main_listen(const char *s, main_opts *o)
{
    const char *colon, *host = s;
    size_t n;
    long port;

    o->ipv6 = 0;
    if (s[0] == '[') {
        const char *close = strchr(s, ']');
        if (!close || close[1] != ':')
            return -1;
        host = s + 1;
        n = (size_t)(close - host);
        colon = close + 1;
        o->ipv6 = 1;
    } else {
        colon = strrchr(s, ':');
        if (!colon)
            return -1;
        n = (size_t)(colon - s);
        if (memchr(s, ':', n)) /* a bare IPv6 address needs brackets */
            return -1;
    }
    if (n == 0 || n >= sizeof(o->host) || main_long(colon + 1, 0, 65535, &port))
        return -1;
    memcpy(o->host, host, n);
    o->host[n] = '\0';
    o->port = (int)port;
    return 0;
}

/* 1 when s is non-empty printable ASCII (safe in a header). */
static int main_printable(const char *s)
{
    if (!*s)
        return 0;
    for (; *s; s++)
        if (*s < 0x20 || *s > 0x7e)
            return 0;
    return 1;
}

/*
 * 1 when s is one exact origin, scheme "://" host [":" port], as
 * Access-Control-Allow-Origin needs: http or https, no path, no wildcard,
 * no list.
 */
static int main_origin(const char *s)
{
    const char *host = strncmp(s, "https://", 8) == 0  ? s + 8
                       : strncmp(s, "http://", 7) == 0 ? s + 7
                                                       : NULL;
    const char *p;

    if (!host || !*host || !main_printable(s))
        return 0;
    for (p = host; *p; p++)
        if (!(isalnum((unsigned char)*p) || strchr(".-:[]", *p)))
            return 0;
    return 1;
}

/* Set flag f from value v; 0, or -1 with what a valid value is in *want. */
static int main_set(main_opts *o, int f, const char *v, const char **want)
{
    switch (f) {
    case F_LISTEN:
        *want = "HOST:PORT (IPv4 or a name, or [IPv6]) with a port from 0 to 65535";
        return main_listen(v, o);
    case F_DB:
        *want = "a file path";
        o->db = v;
        return *v ? 0 : -1;
    case F_WORKERS:
        *want = "an integer from 1 to 1024";
        return main_long(v, 1, 1024, &o->workers);
    case F_QUEUE_MAX:
        *want = "an integer from 1 to 10000000";
        return main_long(v, 1, 10000000, &o->queue_max);
    case F_MAX_BODY:
        *want = "a number of bytes from 1 to 1073741824";
        return main_long(v, 1, 1073741824L, &o->max_body);
    case F_MAX_ELEMENTS:
        *want = "an integer from 1 to 1000000";
        return main_long(v, 1, 1000000, &o->max_elements);
    case F_MAX_SPEEDS:
        *want = "an integer from 1 to 100000";
        return main_long(v, 1, 100000, &o->max_speeds);
    case F_MAX_COORDINATES:
        *want = "an integer from 1 to 1000000";
        return main_long(v, 1, 1000000, &o->max_coordinates);
    case F_MAX_FRAME_DOFS:
        *want = "an integer from 3 to 1000000";
        return main_long(v, 3, 1000000, &o->max_frame_dofs);
    case F_MAX_RESULT_BYTES: {
        long b = 0;
        *want = "a number of bytes from 0 (no limit) to 1099511627776 (1 TiB)";
        if (main_long(v, 0, 1099511627776L, &b))
            return -1;
        o->max_result_bytes = b;
        return 0;
    }
    case F_JOB_TIMEOUT:
        *want = "a number of seconds greater than 0 (at most 1000000)";
        return main_seconds(v, 1e-3, 1e6, &o->job_timeout);
    case F_TOKEN_FILE:
        *want = "a file path";
        o->token_file = v;
        return *v ? 0 : -1;
    case F_AUTH_READS:
        *want = "yes or no";
        if (strcmp(v, "yes") && strcmp(v, "no"))
            return -1;
        o->auth_reads = strcmp(v, "yes") == 0;
        return 0;
    case F_CORS_ORIGIN:
        *want = "one origin such as https://example.org or http://localhost:5173 "
                "(scheme, host and port only; no '*', path or list)";
        o->cors_origin = v;
        return main_origin(v) ? 0 : -1;
    case F_MAX_CONNECTIONS:
        *want = "an integer from 32 to 65536";
        return main_long(v, 32, 65536, &o->max_connections);
    case F_MAX_WAITERS:
        *want = "an integer from 0 to 32768 (at most half of --max-connections)";
        return main_long(v, 0, 32768, &o->max_waiters);
    case F_MAX_CONNECTIONS_PER_CLIENT:
        *want = "an integer from 0 (no limit) to 100000";
        return main_long(v, 0, 100000, &o->per_client);
    case F_REQUEST_DEADLINE:
        *want = "a number of seconds from 1 to 3600";
        return main_seconds(v, 1.0, 3600.0, &o->request_deadline);
    case F_REPLICA_ID:
        *want = "1 to 63 printable characters";
        o->replica_id = v;
        return main_printable(v) && strlen(v) < 64 ? 0 : -1;
    case F_LEASE:
        *want = "a number of seconds from 3 to 3600";
        return main_seconds(v, 3.0, 3600.0, &o->lease);
    case F_DB_TIMEOUT:
        *want = "a number of seconds from 0.5 to 600";
        return main_seconds(v, 0.5, 600.0, &o->db_timeout);
    case F_RETAIN_AGE:
        *want = "a number of seconds from 0 (keep) to 3153600000 (100 years)";
        return main_seconds(v, 0.0, 3153600000.0, &o->retain_age);
    case F_RETAIN_BYTES: {
        long b = 0;
        *want = "a number of bytes from 0 (no bound) to 1099511627776 (1 TiB)";
        if (main_long(v, 0, 1099511627776L, &b))
            return -1;
        o->retain_bytes = b;
        return 0;
    }
    case F_SHUTDOWN_GRACE:
        *want = "a number of seconds from 0 to 3600";
        return main_seconds(v, 0.0, 3600.0, &o->shutdown_grace);
    default:
        *want = "text or json";
        if (strcmp(v, "text") && strcmp(v, "json"))
            return -1;
        o->format = strcmp(v, "json") == 0 ? LOG_JSON : LOG_TEXT;
        return 0;
    }
}

static void main_defaults(main_opts *o)
{
    long cores = sysconf(_SC_NPROCESSORS_ONLN);

    memset(o, 0, sizeof(*o));
    strcpy(o->host, "127.0.0.1");
    o->port = 8080;
    o->db = "./spinmodal.db";
    o->workers = cores < 1 ? 1 : cores > 1024 ? 1024 : cores;
    o->queue_max = 1000;
    o->max_body = 1048576;
    o->max_elements = 2000;
    o->max_speeds = 1001;
    o->max_coordinates = SM_DENSE_MAX_DEFAULT;
    o->max_frame_dofs = 1200;
    o->max_result_bytes = 50000000;
    o->job_timeout = 30.0;
    o->per_client = 64;
    o->max_connections = 512;
    o->max_waiters = -1;
    o->request_deadline = 30.0;
    o->shutdown_grace = 10.0;
    o->retain_age = 2592000.0;
    o->lease = 30.0;
    o->db_timeout = 5.0;
    o->retain_bytes = 1073741824LL;
    o->format = LOG_TEXT;
}

/* ------------------------------------------------------------ parsing */

/* "spinmodald: <before>'<arg>'<after>." and a hint; returns EXIT_USAGE. */
static int main_usage(const char *before, const char *arg, const char *after)
{
    fprintf(stderr, "spinmodald: %s'%s'%s.\nTry 'spinmodald --help'.\n", before, arg, after);
    return EXIT_USAGE;
}

/*
 * Collect the flags of argv into given[] (the last one wins); *action is
 * 'h' or 'V' for --help/--version.  Returns 0 or EXIT_USAGE.
 */
static int main_scan(int argc, char **argv, const char *given[F_N], int *action)
{
    struct option longopts[F_N + 3];
    int i, c;

    for (i = 0; i < F_N; i++) {
        longopts[i].name = main_flags[i].name;
        longopts[i].has_arg = required_argument;
        longopts[i].flag = NULL;
        longopts[i].val = 256 + i;
    }
    longopts[F_N] = (struct option){"help", no_argument, NULL, 'h'};
    longopts[F_N + 1] = (struct option){"version", no_argument, NULL, 'V'};
    longopts[F_N + 2] = (struct option){NULL, 0, NULL, 0};
    opterr = 0;
    while ((c = getopt_long(argc, argv, ":hV", longopts, NULL)) != -1) {
        if (c == 'h' || c == 'V') {
            *action = c;
            return 0;
        }
        if (c == ':')
            return main_usage("option ", argv[optind - 1], " needs a value");
        if (c == '?')
            return main_usage("unknown option ", argv[optind - 1], "");
        given[c - 256] = optarg;
    }
    if (optind < argc)
        return main_usage("unexpected argument ", argv[optind], "");
    return 0;
}

/*
 * --max-waiters against --max-connections: a quarter of it when not given,
 * refused above half (long polls must leave slots for everything else).
 * Returns 0 or EXIT_USAGE.
 */
static int main_waiters(main_opts *o)
{
    if (o->max_waiters < 0) {
        o->max_waiters = o->max_connections / 4;
        return 0;
    }
    if (o->max_waiters <= o->max_connections / 2)
        return 0;
    fprintf(stderr, "spinmodald: --max-waiters needs at most half of --max-connections (%ld), "
                    "not '%ld'.\nTry 'spinmodald --help'.\n",
            o->max_connections / 2, o->max_waiters);
    return EXIT_USAGE;
}

/* Parse argv and the environment into o.  Returns 0, EXIT_USAGE, or -1 after --help/--version. */
static int main_parse(int argc, char **argv, main_opts *o)
{
    const char *given[F_N] = {NULL}, *v, *want;
    char source[64];
    int i, action = 0, rc;

    main_defaults(o);
    rc = main_scan(argc, argv, given, &action);
    if (rc)
        return rc;
    if (action) {
        if (action == 'h')
            main_help();
        else
            main_version();
        return -1;
    }
    for (i = 0; i < F_N; i++) {
        v = given[i];
        snprintf(source, sizeof(source), "--%s", main_flags[i].name);
        if (!v) {
            v = getenv(main_flags[i].env);
            snprintf(source, sizeof(source), "%s", main_flags[i].env);
        }
        if (!v || (!given[i] && !*v)) /* an empty variable counts as unset */
            continue;
        if (main_set(o, i, v, &want)) {
            fprintf(stderr, "spinmodald: %s needs %s, not '%s'.\nTry 'spinmodald --help'.\n",
                    source, want, v);
            return EXIT_USAGE;
        }
    }
    return main_waiters(o);
}

/*
 * Read the token file once, trimmed, into *token (malloc'd).  Returns 0,
 * or EXIT_START after printing why.
 */
static int main_token(const char *path, char **token)
{
    const char *why = NULL;
    char *buf = NULL, *s;
    size_t n, len;
    FILE *f;

    *token = NULL;
    f = fopen(path, "rb");
    if (!f) {
        why = strerror(errno);
        goto fail;
    }
    buf = malloc(MAIN_TOKEN_MAX + 1);
    if (!buf) {
        why = strerror(ENOMEM);
        goto fail;
    }
    n = fread(buf, 1, MAIN_TOKEN_MAX + 1, f);
    if (ferror(f))
        why = strerror(errno ? errno : EIO);
    else if (n > MAIN_TOKEN_MAX)
        why = "it is larger than 4096 bytes";
    else if (memchr(buf, '\0', n))
        why = "it holds a NUL byte";
    if (why)
        goto fail;
    fclose(f);
    f = NULL;
    buf[n] = '\0';
    for (s = buf; *s && strchr(" \t\r\n", *s); s++)
        ;
    len = strlen(s);
    while (len > 0 && strchr(" \t\r\n", s[len - 1]))
        s[--len] = '\0';
    if (len == 0) {
        why = "it is empty";
        goto fail;
    }
    memmove(buf, s, len + 1);
    *token = buf;
    return 0;
fail:
    if (f)
        fclose(f);
    free(buf);
    fprintf(stderr, "spinmodald: cannot use the token file '%s': %s.\n", path, why);
    return EXIT_START;
}

/* ------------------------------------------------------------ running */

/* "HOST:PORT" or "[HOST]:PORT" of the bound address into buf. */
static void main_addr(const main_opts *o, int port, char *buf, size_t cap)
{
    if (o->ipv6 || strchr(o->host, ':'))
        snprintf(buf, cap, "[%s]:%d", o->host, port);
    else
        snprintf(buf, cap, "%s:%d", o->host, port);
}

static void main_fail(const char *what, const char *detail)
{
    log_event("error", "start_failed", "error", what, "detail", detail, (const char *)NULL);
}

/*
 * The store's error callback (on the failing thread, at the failure): log
 * the kind and SQLite's own text, count it by kind.  Never calls the store.
 */
static void main_store_error(void *ctx, const store_error *e)
{
    char code[16];

    snprintf(code, sizeof(code), "%d", e->backend_rc);
    log_event("error", "store_error", "op", e->op, "kind", store_rc_name(e->rc), "code", code,
              "sqlstate", e->sqlstate[0] ? e->sqlstate : NULL, "detail", e->text,
              (const char *)NULL);
    metrics_store_error(ctx, e->rc);
}

/* The store's prune-on-insert callback: count what --retain-bytes removed. */
static void main_store_pruned(void *ctx, long long n)
{
    metrics_store_pruned(ctx, n);
}

/* Open the store and the metrics; 0 or EXIT_START. */
static int main_open(const main_opts *o, main_daemon *d)
{
    store_settings set;
    char err[512], n[32];
    int requeued = 0, rc;

    d->mx = metrics_new();
    if (!d->mx) {
        main_fail("out of memory", NULL);
        return EXIT_START;
    }
    err[0] = '\0';
    store_default_settings(&set);
    set.path = o->db;
    set.owner = o->replica_id;
    set.lease_s = o->lease;
    set.on_error = main_store_error;
    set.on_error_ctx = d->mx;
    set.timeout_ms = (int)(o->db_timeout * 1000.0);
    set.retain_bytes = o->retain_bytes;   /* pruned on insert too, not only periodically */
    set.on_pruned = main_store_pruned;
    set.on_pruned_ctx = d->mx;
    rc = store_open_with(&d->st, &set, &requeued, err, sizeof(err));
    if (rc != STORE_OK) {
        /* err names the file, or host:port/database of a URI (never its password) */
        log_event("error", "store_open_failed", "kind", store_rc_name(rc), "detail",
                  err[0] ? err : store_strerror(rc), (const char *)NULL);
        main_fail("cannot open the database", err[0] ? err : store_strerror(rc));
        return EXIT_START;
    }
    snprintf(n, sizeof(n), "%d", requeued);
    log_event("info", "recovered", "jobs", n, "backend", store_backend_name(d->st), "owner",
              store_owner(d->st), "db",
              store_caps(d->st) & STORE_CAP_SECRET_PATH ? NULL : o->db, (const char *)NULL);
    return 0;
}

/*
 * Retention: remove the oldest finished jobs beyond --retain-age and
 * --retain-bytes (queued and running jobs are never removed); count and log.
 * The store also keeps --retain-bytes on every insert (set.retain_bytes):
 * this periodic pass catches up the age bound and what other replicas wrote.
 */
static void main_prune(const main_opts *o, main_daemon *d)
{
    long long removed = 0;
    char n[32];
    int rc;

    if (o->retain_age <= 0.0 && o->retain_bytes <= 0)
        return;
    rc = store_prune(d->st, log_now(), o->retain_age, o->retain_bytes, &removed);
    metrics_store_pruned(d->mx, removed);
    if (removed > 0 || rc != STORE_OK) {
        snprintf(n, sizeof(n), "%lld", removed);
        log_event(rc == STORE_OK ? "info" : "error", "store_pruned", "jobs", n, "store",
                  rc == STORE_OK ? NULL : store_rc_name(rc), (const char *)NULL);
    }
}

/* Start the pool and the HTTP server; 0 or EXIT_START. */
static int main_serve(const main_opts *o, const char *token, main_daemon *d)
{
    jobs_config jc;
    http_config hc;
    char addr[300], workers[16];
    int rc;

    http_default_config(&hc);
    hc.host = o->host;
    hc.port = o->port;
    hc.max_body = (size_t)o->max_body;
    hc.limits.max_request_bytes = (size_t)o->max_body;
    hc.limits.max_elements = (int)o->max_elements;
    hc.limits.max_speeds = (int)o->max_speeds;
    hc.limits.max_coordinates = (int)o->max_coordinates;
    hc.limits.max_frame_dofs = (int)o->max_frame_dofs;
    hc.limits.max_solve_seconds = o->job_timeout;
    hc.limits.max_result_bytes = (size_t)o->max_result_bytes;
    hc.token = token;
    hc.auth_reads = o->auth_reads;
    hc.cors_origin = o->cors_origin;
    hc.per_client_limit = (unsigned)o->per_client;
    hc.connection_limit = (unsigned)o->max_connections;
    hc.max_waiters = (unsigned)o->max_waiters;
    hc.request_deadline = o->request_deadline;
    jc.workers = (int)o->workers;
    jc.queue_max = (int)o->queue_max;
    jc.job_timeout = o->job_timeout;
    jc.shared = (store_caps(d->st) & STORE_CAP_SHARED) != 0;
    jc.lease = o->lease;
    jc.limits = hc.limits;
    rc = jobs_start(&d->j, d->st, d->mx, &jc);
    if (rc != JOBS_OK) {
        main_fail("cannot start the workers",
                  rc == JOBS_NOMEM ? "out of memory" : "the database failed");
        return EXIT_START;
    }
    main_addr(o, o->port, addr, sizeof(addr));
    rc = http_start(&d->h, &hc, d->j, d->st, d->mx);
    if (rc != HTTP_OK) {
        main_fail(rc == HTTP_ADDRESS ? "cannot resolve the listen address"
                  : rc == HTTP_NOMEM ? "out of memory"
                                     : "cannot listen (address in use or not permitted)",
                  addr);
        return EXIT_START;
    }
    main_addr(o, http_port(d->h), addr, sizeof(addr));
    snprintf(workers, sizeof(workers), "%ld", o->workers);
    log_event("info", "listening", "addr", addr, "workers", workers, "version", SM_VERSION,
              (const char *)NULL);
    return 0;
}

/* Stop in DAEMON.md order; safe on a partly started daemon. */
static void main_stop(main_daemon *d, double grace)
{
    http_begin_stop(d->h);
    jobs_stop(d->j, grace);
    d->j = NULL;
    http_stop(d->h);
    d->h = NULL;
    store_close(d->st);
    d->st = NULL;
    metrics_free(d->mx);
    d->mx = NULL;
}

/*
 * Write end of the self-pipe.  The one global of the daemon: a signal
 * handler gets no argument.  Set before the handlers are installed.
 */
static volatile sig_atomic_t main_signal_fd = -1;

/* SIGTERM/SIGINT: one byte (the signal number) into the self-pipe. */
static void main_on_signal(int sig)
{
    int saved = errno;
    unsigned char b = (unsigned char)sig;
    ssize_t n;

    if (main_signal_fd >= 0) {
        n = write(main_signal_fd, &b, 1);
        (void)n; /* a full pipe already holds a stop request */
    }
    errno = saved;
}

/*
 * Signals: SIGTERM/SIGINT write to the self-pipe fds (the handler works in
 * whichever thread takes them, the BLAS library's own threads started
 * before main included), and are blocked in this thread so the threads
 * started next inherit the block (main unblocks them once it waits on the
 * pipe); SIGPIPE is ignored.  0 or -1.
 */
static int main_signals(int fds[2], sigset_t *set)
{
    struct sigaction sa;

    if (pipe(fds))
        return -1;
    if (fcntl(fds[0], F_SETFD, FD_CLOEXEC) || fcntl(fds[1], F_SETFD, FD_CLOEXEC) ||
        fcntl(fds[1], F_SETFL, O_NONBLOCK))
        return -1;
    main_signal_fd = fds[1];
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = SIG_IGN;
    sigemptyset(&sa.sa_mask);
    if (sigaction(SIGPIPE, &sa, NULL))
        return -1;
    sa.sa_handler = main_on_signal;
    sa.sa_flags = SA_RESTART;
    if (sigemptyset(set) || sigaddset(set, SIGTERM) || sigaddset(set, SIGINT) ||
        sigaddset(&sa.sa_mask, SIGTERM) || sigaddset(&sa.sa_mask, SIGINT) ||
        sigaction(SIGTERM, &sa, NULL) || sigaction(SIGINT, &sa, NULL) ||
        pthread_sigmask(SIG_BLOCK, set, NULL))
        return -1;
    return 0;
}

/* Wait for SIGTERM/SIGINT (a byte on the self-pipe); returns the signal. */
static int main_wait_signal(int fd, const sigset_t *set, const main_opts *o, main_daemon *d)
{
    struct pollfd p = {fd, POLLIN, 0};
    unsigned char b = 0;
    ssize_t n;
    int ready;

    pthread_sigmask(SIG_UNBLOCK, set, NULL);
    main_prune(o, d);
    for (;;) {
        ready = poll(&p, 1, MAIN_PRUNE_EVERY_MS);
        if (ready == 0) {
            main_prune(o, d);
            continue;
        }
        if (ready < 0 && errno == EINTR)
            continue;
        break;
    }
    do
        n = read(fd, &b, 1);
    while (n < 0 && errno == EINTR);
    return n == 1 ? (int)b : SIGTERM;
}

static void main_close_pipe(int fds[2])
{
    main_signal_fd = -1;
    if (fds[0] >= 0)
        close(fds[0]);
    if (fds[1] >= 0)
        close(fds[1]);
}

int main(int argc, char **argv)
{
    main_daemon d = {NULL, NULL, NULL, NULL};
    int rc, sig, fds[2] = {-1, -1};
    char *token = NULL;
    main_opts o;
    sigset_t set;

    rc = main_parse(argc, argv, &o);
    if (rc)
        return rc < 0 ? 0 : rc;
    if (o.auth_reads && !o.token_file) {
        fprintf(stderr, "spinmodald: --auth-reads yes needs a token: give --token-file too.\n"
                        "Try 'spinmodald --help'.\n");
        return EXIT_USAGE;
    }
    log_init(o.format, 1);
    if (o.token_file && main_token(o.token_file, &token))
        return EXIT_START;
    if (main_signals(fds, &set)) {
        fprintf(stderr, "spinmodald: cannot set up the signals: %s.\n", strerror(errno));
        main_close_pipe(fds);
        free(token);
        return EXIT_START;
    }
    rc = main_open(&o, &d);
    if (!rc)
        rc = main_serve(&o, token, &d);
    free(token);
    if (rc) {
        main_stop(&d, 0.0);
        main_close_pipe(fds);
        return rc;
    }
    sig = main_wait_signal(fds[0], &set, &o, &d);
    http_begin_stop(d.h); /* refuse first, then say so: a client that reads the log sees 503 */
    log_event("info", "stopping", "signal", sig == SIGINT ? "SIGINT" : "SIGTERM",
              (const char *)NULL);
    main_stop(&d, o.shutdown_grace);
    log_event("info", "stopped", (const char *)NULL);
    main_close_pipe(fds);
    return 0;
}
