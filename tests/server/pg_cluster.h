/*
 * pg_cluster.h — a throwaway PostgreSQL cluster for tests: initdb on a
 * temporary directory, the server on a free loopback port (pg_ctl), a
 * database per test, stopped and removed at the end — also when the test
 * dies (a guard process stops it when the test's end of a pipe closes).
 * Run as root, the server binaries run as `nobody` (PostgreSQL refuses
 * root).  Not thread-safe; call from the test's main thread.
 */
#ifndef SPINMODAL_TESTS_PG_CLUSTER_H
#define SPINMODAL_TESTS_PG_CLUSTER_H

#include <stddef.h>
#include <sys/types.h>

typedef struct pg_cluster {
    char bindir[512];   /* initdb, pg_ctl */
    char dir[256];      /* the temporary directory: data/, log, sockets */
    int port;           /* loopback TCP port of the server */
    uid_t uid;          /* the server's user (nobody when run as root) */
    gid_t gid;
    int drop;           /* 1: run the binaries as uid/gid */
    pid_t guard;        /* stops and removes the cluster when guard_fd closes */
    int guard_fd;       /* write end of the guard's pipe; -1 when none */
    int running;
} pg_cluster;

/*
 * Find the server binaries ($PG_BINDIR when set, and then only there;
 * else `pg_config --bindir`, then the newest /usr/lib/postgresql/<N>/bin),
 * create the cluster and start it.  Returns
 * 0; 77 when no server binaries exist (why says so: the caller skips);
 * -1 on any other failure (why says which step; the server's log tail is
 * printed).
 */
int pg_cluster_start(pg_cluster *c, char *why, size_t len);

/* pg_ctl stop -m fast (0 or -1). */
int pg_cluster_stop(pg_cluster *c);

/* Start the stopped cluster again on the same port (0 or -1). */
int pg_cluster_resume(pg_cluster *c);

/* pg_ctl restart -m fast (0 or -1). */
int pg_cluster_restart(pg_cluster *c);

/* Create database name (a fresh, empty one) and write its URI into dsn.
 * Returns 0 or -1. */
int pg_cluster_createdb(pg_cluster *c, const char *name, char *dsn, size_t len);

/* Stop the server, remove the directory, reap the guard.  NULL-safe. */
void pg_cluster_destroy(pg_cluster *c);

/* Run one SQL text on the database at dsn and copy the first column of
 * the first row (if any) into buf (may be NULL).  Returns 0 or -1. */
int pg_raw(const char *dsn, const char *sql, char *buf, size_t len);

/* A TCP port nobody listens on now at 127.0.0.1 (0 on failure). */
int pg_free_port(void);

#endif /* SPINMODAL_TESTS_PG_CLUSTER_H */
