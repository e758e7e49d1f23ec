/*
 * config.h — spinmodald's settings (server/DAEMON.md's flag table): the
 * flags, each with a SPINMODAL_* environment variable (the flag wins),
 * checked and gathered into one config_opts; --help and --version; the
 * token file.  Used by main.c only; config.c says where a new option goes.
 */
#ifndef SPINMODAL_CONFIG_H
#define SPINMODAL_CONFIG_H

#include "log.h"

/* Exit status of spinmodald for a bad option (64, EX_USAGE) and for a daemon that cannot
 * start (token file, database, port). */
enum { CONFIG_EXIT_START = 1, CONFIG_EXIT_USAGE = 64 };

/* The effective settings. */
typedef struct config_opts {
    char host[256]; /* listen address, without brackets */
    int port;       /* 0..65535 */
    int ipv6;       /* host was given in [brackets] */
    const char *db;
    long workers, solve_threads, queue_max, max_body, max_elements, max_speeds, max_coordinates,
        max_frame_dofs;
    double job_timeout;         /* s, > 0 */
    double shutdown_grace;      /* s, >= 0 */
    double retain_age;          /* s, 0 = no age bound */
    const char *replica_id;     /* NULL = generated */
    double lease;               /* s, PostgreSQL claims */
    double db_timeout;          /* s, deadline of one store call */
    long long retain_bytes;     /* bytes, 0 = no size bound */
    long long max_result_bytes; /* estimated bytes of a result document, 0 = no limit */
    const char *token_file;     /* NULL = no auth */
    int auth_reads;             /* 1: reads need the token too */
    const char *cors_origin;    /* NULL = no CORS */
    long per_client;            /* connections per IP address, 0 = no limit */
    long max_connections;       /* open connections, >= 32 */
    long max_waiters;           /* waiting long polls, <= max_connections / 2; -1 = a quarter */
    double request_deadline;    /* s, > 0 */
    log_format format;
} config_opts;

/**
 * Fill *o from the defaults, then the environment, then argv (argc, argv
 * as main gets them).  Returns 0; CONFIG_EXIT_USAGE after printing to
 * stderr what is wrong (an unknown option, a missing or bad value,
 * --max-waiters over half of --max-connections, --auth-reads without
 * --token-file); or -1 after printing --help or --version to stdout.
 * The strings of *o point into argv or the environment.
 */
int config_parse(int argc, char **argv, config_opts *o);

/**
 * Read the token file path once, trimmed of blanks and newlines, into
 * *token (malloc'd, the caller frees it).  Returns 0, or CONFIG_EXIT_START
 * after printing why to stderr (cannot open, over 4096 bytes, a NUL byte,
 * empty).
 */
int config_token(const char *path, char **token);

#endif /* SPINMODAL_CONFIG_H */
