/*
 * config.c — spinmodald's settings (config.h): the option table, the flags
 * and their SPINMODAL_* environment variables, the checks of each value,
 * --help and --version, and the token file.
 *
 * How it fits: main.c calls config_parse first and config_token once,
 * then starts the daemon from the config_opts they filled; nothing else
 * reads argv or the environment.  Each option is one row of config_flags[]
 * (name, variable, argument, default, help line: --help prints the rows in
 * order) and one case of config_set (the check, and the text of what a
 * valid value is); the flag wins over the variable, an empty variable
 * counts as unset, the last of a repeated flag wins.  A bad value prints
 * "spinmodald: SOURCE needs WANT, not 'VALUE'." and exits 64.
 *
 * A new option: an F_ constant, a row of config_flags[] at the same place,
 * a field of config_opts with its default in config_defaults, a case of
 * config_set, and the line of server/DAEMON.md's flag table.
 */
#include "config.h"

#include <ctype.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <microhttpd.h>
#include <sqlite3.h>

#include "spinmodal.h"

#define CONFIG_TOKEN_MAX 4096 /* bytes of a token file */

/* The flags, in --help order. */
enum {
    F_LISTEN,
    F_DB,
    F_WORKERS,
    F_SOLVE_THREADS,
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

typedef struct config_flag {
    const char *name; /* without the leading -- */
    const char *env;  /* environment variable */
    const char *arg;  /* argument name in --help */
    const char *def;  /* default in --help */
    const char *help; /* one line */
} config_flag;

static const config_flag config_flags[F_N] = {
    {"listen", "SPINMODAL_LISTEN", "HOST:PORT", "127.0.0.1:8080",
     "address to listen on; [IPv6]:PORT; port 0 = any free port"},
    {"db", "SPINMODAL_DB", "PATH|URI", "./spinmodal.db",
     "SQLite database file, or postgresql://user@host/db to share one queue between replicas"},
    {"workers", "SPINMODAL_WORKERS", "N", "online cores", "solver threads (1-1024)"},
    {"solve-threads", "SPINMODAL_SOLVE_THREADS", "N", "1",
     "threads one sweep job may use (1-64; up to workers x N in all): its speeds' "
     "eigen-analyses run beside the continuation, same results"},
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


static void config_help(void)
{
    int i;

    printf("spinmodald %s: HTTP daemon computing natural frequencies of spinning beam "
           "structures\n\nusage: spinmodald [OPTION]...\n\noptions (each also read from the "
           "environment variable shown; the option wins):\n",
           SM_VERSION);
    for (i = 0; i < F_N; i++)
        printf("  --%s %s\n      %s\n      env %s, default %s\n", config_flags[i].name,
               config_flags[i].arg, config_flags[i].help, config_flags[i].env, config_flags[i].def);
    printf("  -h, --help       show this help\n"
           "  -V, --version    show the versions\n\n"
           "exit status: 0 after a clean stop (SIGTERM, SIGINT), 64 bad option,\n"
           "1 cannot start (token file, database, port)\n");
}

static void config_version(void)
{
    printf("spinmodald %s (libspinmodal %s, libmicrohttpd %s, SQLite %s)\n", SM_VERSION,
           sm_version(), MHD_get_version(), sqlite3_libversion());
}

/* ------------------------------------------------------------ values */

/* Integer in [lo, hi]; 0 or -1. */
static int config_long(const char *s, long lo, long hi, long *out)
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
static int config_seconds(const char *s, double lo, double hi, double *out)
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
static int config_listen(const char *s, config_opts *o)
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
    if (n == 0 || n >= sizeof(o->host) || config_long(colon + 1, 0, 65535, &port))
        return -1;
    memcpy(o->host, host, n);
    o->host[n] = '\0';
    o->port = (int)port;
    return 0;
}

/* 1 when s is non-empty printable ASCII (safe in a header). */
static int config_printable(const char *s)
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
static int config_origin(const char *s)
{
    const char *host = strncmp(s, "https://", 8) == 0  ? s + 8
                       : strncmp(s, "http://", 7) == 0 ? s + 7
                                                       : NULL;
    const char *p;

    if (!host || !*host || !config_printable(s))
        return 0;
    for (p = host; *p; p++)
        if (!(isalnum((unsigned char)*p) || strchr(".-:[]", *p)))
            return 0;
    return 1;
}

/* Set flag f from value v; 0, or -1 with what a valid value is in *want. */
static int config_set(config_opts *o, int f, const char *v, const char **want)
{
    switch (f) {
    case F_LISTEN:
        *want = "HOST:PORT (IPv4 or a name, or [IPv6]) with a port from 0 to 65535";
        return config_listen(v, o);
    case F_DB:
        *want = "a file path";
        o->db = v;
        return *v ? 0 : -1;
    case F_WORKERS:
        *want = "an integer from 1 to 1024";
        return config_long(v, 1, 1024, &o->workers);
    case F_SOLVE_THREADS:
        *want = "an integer from 1 to 64";
        return config_long(v, 1, 64, &o->solve_threads);
    case F_QUEUE_MAX:
        *want = "an integer from 1 to 10000000";
        return config_long(v, 1, 10000000, &o->queue_max);
    case F_MAX_BODY:
        *want = "a number of bytes from 1 to 1073741824";
        return config_long(v, 1, 1073741824L, &o->max_body);
    case F_MAX_ELEMENTS:
        *want = "an integer from 1 to 1000000";
        return config_long(v, 1, 1000000, &o->max_elements);
    case F_MAX_SPEEDS:
        *want = "an integer from 1 to 100000";
        return config_long(v, 1, 100000, &o->max_speeds);
    case F_MAX_COORDINATES:
        *want = "an integer from 1 to 1000000";
        return config_long(v, 1, 1000000, &o->max_coordinates);
    case F_MAX_FRAME_DOFS:
        *want = "an integer from 3 to 1000000";
        return config_long(v, 3, 1000000, &o->max_frame_dofs);
    case F_MAX_RESULT_BYTES: {
        long b = 0;
        *want = "a number of bytes from 0 (no limit) to 1099511627776 (1 TiB)";
        if (config_long(v, 0, 1099511627776L, &b))
            return -1;
        o->max_result_bytes = b;
        return 0;
    }
    case F_JOB_TIMEOUT:
        *want = "a number of seconds greater than 0 (at most 1000000)";
        return config_seconds(v, 1e-3, 1e6, &o->job_timeout);
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
        return config_origin(v) ? 0 : -1;
    case F_MAX_CONNECTIONS:
        *want = "an integer from 32 to 65536";
        return config_long(v, 32, 65536, &o->max_connections);
    case F_MAX_WAITERS:
        *want = "an integer from 0 to 32768 (at most half of --max-connections)";
        return config_long(v, 0, 32768, &o->max_waiters);
    case F_MAX_CONNECTIONS_PER_CLIENT:
        *want = "an integer from 0 (no limit) to 100000";
        return config_long(v, 0, 100000, &o->per_client);
    case F_REQUEST_DEADLINE:
        *want = "a number of seconds from 1 to 3600";
        return config_seconds(v, 1.0, 3600.0, &o->request_deadline);
    case F_REPLICA_ID:
        *want = "1 to 63 printable characters";
        o->replica_id = v;
        return config_printable(v) && strlen(v) < 64 ? 0 : -1;
    case F_LEASE:
        *want = "a number of seconds from 3 to 3600";
        return config_seconds(v, 3.0, 3600.0, &o->lease);
    case F_DB_TIMEOUT:
        *want = "a number of seconds from 0.5 to 600";
        return config_seconds(v, 0.5, 600.0, &o->db_timeout);
    case F_RETAIN_AGE:
        *want = "a number of seconds from 0 (keep) to 3153600000 (100 years)";
        return config_seconds(v, 0.0, 3153600000.0, &o->retain_age);
    case F_RETAIN_BYTES: {
        long b = 0;
        *want = "a number of bytes from 0 (no bound) to 1099511627776 (1 TiB)";
        if (config_long(v, 0, 1099511627776L, &b))
            return -1;
        o->retain_bytes = b;
        return 0;
    }
    case F_SHUTDOWN_GRACE:
        *want = "a number of seconds from 0 to 3600";
        return config_seconds(v, 0.0, 3600.0, &o->shutdown_grace);
    default:
        *want = "text or json";
        if (strcmp(v, "text") && strcmp(v, "json"))
            return -1;
        o->format = strcmp(v, "json") == 0 ? LOG_JSON : LOG_TEXT;
        return 0;
    }
}

static void config_defaults(config_opts *o)
{
    long cores = sysconf(_SC_NPROCESSORS_ONLN);

    memset(o, 0, sizeof(*o));
    strcpy(o->host, "127.0.0.1");
    o->port = 8080;
    o->db = "./spinmodal.db";
    o->workers = cores < 1 ? 1 : cores > 1024 ? 1024 : cores;
    o->solve_threads = 1;
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

/* "spinmodald: <before>'<arg>'<after>." and a hint; returns CONFIG_EXIT_USAGE. */
static int config_usage(const char *before, const char *arg, const char *after)
{
    fprintf(stderr, "spinmodald: %s'%s'%s.\nTry 'spinmodald --help'.\n", before, arg, after);
    return CONFIG_EXIT_USAGE;
}

/*
 * Collect the flags of argv into given[] (the last one wins); *action is
 * 'h' or 'V' for --help/--version.  Returns 0 or CONFIG_EXIT_USAGE.
 */
static int config_scan(int argc, char **argv, const char *given[F_N], int *action)
{
    struct option longopts[F_N + 3];
    int i, c;

    for (i = 0; i < F_N; i++) {
        longopts[i].name = config_flags[i].name;
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
            return config_usage("option ", argv[optind - 1], " needs a value");
        if (c == '?')
            return config_usage("unknown option ", argv[optind - 1], "");
        given[c - 256] = optarg;
    }
    if (optind < argc)
        return config_usage("unexpected argument ", argv[optind], "");
    return 0;
}

/*
 * --max-waiters against --max-connections: a quarter of it when not given,
 * refused above half (long polls must leave slots for everything else).
 * Returns 0 or CONFIG_EXIT_USAGE.
 */
static int config_waiters(config_opts *o)
{
    if (o->max_waiters < 0) {
        o->max_waiters = o->max_connections / 4;
        return 0;
    }
    if (o->max_waiters <= o->max_connections / 2)
        return 0;
    fprintf(stderr,
            "spinmodald: --max-waiters needs at most half of --max-connections (%ld), "
            "not '%ld'.\nTry 'spinmodald --help'.\n",
            o->max_connections / 2, o->max_waiters);
    return CONFIG_EXIT_USAGE;
}

int config_parse(int argc, char **argv, config_opts *o)
{
    const char *given[F_N] = {NULL}, *v, *want;
    char source[64];
    int i, action = 0, rc;

    config_defaults(o);
    rc = config_scan(argc, argv, given, &action);
    if (rc)
        return rc;
    if (action) {
        if (action == 'h')
            config_help();
        else
            config_version();
        return -1;
    }
    for (i = 0; i < F_N; i++) {
        v = given[i];
        snprintf(source, sizeof(source), "--%s", config_flags[i].name);
        if (!v) {
            v = getenv(config_flags[i].env);
            snprintf(source, sizeof(source), "%s", config_flags[i].env);
        }
        if (!v || (!given[i] && !*v)) /* an empty variable counts as unset */
            continue;
        if (config_set(o, i, v, &want)) {
            fprintf(stderr, "spinmodald: %s needs %s, not '%s'.\nTry 'spinmodald --help'.\n",
                    source, want, v);
            return CONFIG_EXIT_USAGE;
        }
    }
    rc = config_waiters(o);
    if (rc)
        return rc;
    if (o->auth_reads && !o->token_file) {
        fprintf(stderr, "spinmodald: --auth-reads yes needs a token: give --token-file too.\n"
                        "Try 'spinmodald --help'.\n");
        return CONFIG_EXIT_USAGE;
    }
    return 0;
}

int config_token(const char *path, char **token)
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
    buf = malloc(CONFIG_TOKEN_MAX + 1);
    if (!buf) {
        why = strerror(ENOMEM);
        goto fail;
    }
    n = fread(buf, 1, CONFIG_TOKEN_MAX + 1, f);
    if (ferror(f))
        why = strerror(errno ? errno : EIO);
    else if (n > CONFIG_TOKEN_MAX)
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
    return CONFIG_EXIT_START;
}
