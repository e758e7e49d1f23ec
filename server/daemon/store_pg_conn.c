/*
 * store_pg_conn.c — the PostgreSQL backend's sessions: error kinds from
 * SQLSTATEs and broken connections, connecting (libpq), a small pool that
 * reconnects by itself after a server restart (at most once a second while
 * the server is down), and running prepared statements.  The job operations
 * on top of it are store_pg.c; opening and migrations store_pg_open.c.
 */
#include "store_pg.h"
#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ---- errors --------------------------------------------------------------- */

int store_pg_kind(const char *sqlstate, int connection_bad)
{
    static const struct {
        const char *state;
        int kind;
    } table[] = {
        {"57P01", STORE_UNAVAILABLE},   /* admin_shutdown: the server stops or restarts */
        {"57P02", STORE_UNAVAILABLE},   /* crash_shutdown */
        {"57P03", STORE_UNAVAILABLE},   /* cannot_connect_now: starting up */
        {"53300", STORE_UNAVAILABLE},   /* too_many_connections */
        {"53100", STORE_FULL},          /* disk_full */
        {"58030", STORE_IOERR},         /* io_error */
        {"XX001", STORE_CORRUPT},       /* data_corrupted */
        {"XX002", STORE_CORRUPT},       /* index_corrupted */
        {"25006", STORE_READONLY},      /* read_only_sql_transaction: a standby */
        {"42501", STORE_READONLY},      /* insufficient_privilege */
        {"55P03", STORE_BUSY},          /* lock_not_available: lock_timeout */
        {"57014", STORE_BUSY},          /* query_canceled: statement_timeout */
        {"40001", STORE_BUSY},          /* serialization_failure */
        {"40P01", STORE_BUSY},          /* deadlock_detected */
    };

    if (connection_bad)
        return STORE_UNAVAILABLE;   /* whatever the message: the session is gone */
    if (sqlstate == NULL || sqlstate[0] == '\0')
        return STORE_ERROR;
    if (strncmp(sqlstate, "08", 2) == 0)   /* connection_exception */
        return STORE_UNAVAILABLE;
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
        if (strcmp(sqlstate, table[i].state) == 0)
            return table[i].kind;
    return STORE_ERROR;
}

/* libpq's message on one line, spaces collapsed ("ERROR:  x\nDETAIL: y\n" →
 * "ERROR: x DETAIL: y"). */
static void one_line(char *out, size_t len, const char *msg)
{
    size_t n;

    snprintf(out, len, "%s", msg && msg[0] ? msg : "no message from libpq");
    for (char *p = out; *p; p++)
        if (*p == '\n' || *p == '\r' || *p == '\t')
            *p = ' ';
    for (char *p = out; (p = strstr(p, "  ")) != NULL;)   /* "…refused \tIs…" */
        memmove(p, p + 1, strlen(p + 1) + 1);
    n = strlen(out);
    while (n > 0 && out[n - 1] == ' ')
        out[--n] = '\0';
}

/* Record the failure of res (may be NULL) on c and return its kind. */
static int pg_fail(pg_conn *c, PGresult *res)
{
    const char *state = res ? PQresultErrorField(res, PG_DIAG_SQLSTATE) : NULL;
    const char *msg = res ? PQresultErrorMessage(res) : NULL;
    int bad = c->conn == NULL || PQstatus(c->conn) != CONNECTION_OK;
    char text[256];

    if ((msg == NULL || msg[0] == '\0') && c->conn != NULL)
        msg = PQerrorMessage(c->conn);
    one_line(text, sizeof text, msg);
    return store_note_error_state(c->owner, store_pg_kind(state, bad), state, c->op, text);
}

int store_pg_fail_kind(pg_conn *c, int kind, const char *text)
{
    return store_note_error_state(c->owner, kind, NULL, c->op, text);
}

double store_pg_mono(void)
{
    struct timespec ts;

    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- sessions ------------------------------------------------------------- */

/* Notices (a NOTICE of a migration, a WARNING) are not failures: dropped. */
static void pg_quiet(void *arg, const char *message)
{
    (void)arg;
    (void)message;
}

int store_pg_connect(store *s, pg_conn *c, char *err, size_t errlen)
{
    store_pg *q = s->impl;
    char set[128];
    /* defaults first: the URI (dbname, expanded) overrides any of them */
    const char *const keys[] = {"connect_timeout", "client_encoding", "fallback_application_name",
                                "keepalives_idle", "keepalives_interval", "keepalives_count",
                                "tcp_user_timeout", "dbname", NULL};
    const char *const vals[] = {"2", "UTF8", "spinmodald", "10", "5", "3", "15000", q->dsn,
                                NULL};
    PGresult *res;
    int kind;

    store_pg_disconnect(c);
    c->conn = PQconnectdbParams(keys, vals, 1);
    if (c->conn == NULL) {
        snprintf(err, errlen, "out of memory connecting to PostgreSQL");
        return STORE_NOMEM;
    }
    if (PQstatus(c->conn) != CONNECTION_OK) {
        one_line(err, errlen, PQerrorMessage(c->conn));
        store_pg_disconnect(c);
        return STORE_UNAVAILABLE;
    }
    (void)PQsetNoticeProcessor(c->conn, pg_quiet, NULL);
    /* a row lock waits busy_timeout_ms at most; a statement 60 s */
    snprintf(set, sizeof set, "SET lock_timeout = %d; SET statement_timeout = %d",
             q->lock_timeout_ms, STORE_PG_STATEMENT_MS);
    res = PQexec(c->conn, set);
    if (PQresultStatus(res) != PGRES_COMMAND_OK) {
        kind = store_pg_kind(res ? PQresultErrorField(res, PG_DIAG_SQLSTATE) : NULL,
                             PQstatus(c->conn) != CONNECTION_OK);
        one_line(err, errlen, res ? PQresultErrorMessage(res) : PQerrorMessage(c->conn));
        PQclear(res);
        store_pg_disconnect(c);
        return kind;
    }
    PQclear(res);
    return STORE_OK;
}

void store_pg_disconnect(pg_conn *c)
{
    if (c->conn != NULL)
        PQfinish(c->conn);
    c->conn = NULL;
    c->prepared = 0;
}

/* Is the idle session of c still there?  Reads what the server sent since
 * its last use, while the socket has any (poll with no wait): a server
 * that stopped or restarted sent a FATAL notice and closed the stream,
 * and reading to the end of it marks the session bad.  Never blocks. */
static int pg_alive(pg_conn *c)
{
    struct pollfd p;
    PGresult *res;

    if (c->conn == NULL || PQstatus(c->conn) != CONNECTION_OK)
        return 0;
    p.fd = PQsocket(c->conn);
    p.events = POLLIN;
    for (int i = 0; i < 8 && p.fd >= 0; i++) {   /* notice, then end of stream */
        p.revents = 0;
        if (poll(&p, 1, 0) <= 0)
            break;
        if (PQconsumeInput(c->conn) == 0 || PQstatus(c->conn) != CONNECTION_OK)
            return 0;
    }
    while (!PQisBusy(c->conn) && (res = PQgetResult(c->conn)) != NULL)
        PQclear(res);   /* nothing is pending on an idle session; drain anyway */
    return PQstatus(c->conn) == CONNECTION_OK &&
           PQtransactionStatus(c->conn) == PQTRANS_IDLE;
}

/* ---- the pool ------------------------------------------------------------- */

/* Wait for a free connection of q (pool_lock held) until STORE_PG_WAIT_MS
 * passed; NULL then. */
static pg_conn *pool_take(store_pg *q)
{
    struct timespec until;
    pg_conn *c;

    (void)clock_gettime(CLOCK_REALTIME, &until);
    until.tv_sec += STORE_PG_WAIT_MS / 1000;
    while (q->free_conns == NULL) {
        int e = pthread_cond_timedwait(&q->pool_cond, &q->pool_lock, &until);
        if (e != 0 && q->free_conns == NULL)
            return NULL;
    }
    c = q->free_conns;
    q->free_conns = c->next;
    return c;
}

static void pool_give(store_pg *q, pg_conn *c)
{
    (void)pthread_mutex_lock(&q->pool_lock);
    c->next = q->free_conns;
    q->free_conns = c;
    (void)pthread_cond_signal(&q->pool_cond);
    (void)pthread_mutex_unlock(&q->pool_lock);
}

/* Open a new session on c for a call, unless the server was unreachable
 * a moment ago (then fail at once).  Returns a store_rc (recorded). */
static int pool_connect(store *s, pg_conn *c)
{
    store_pg *q = s->impl;
    char text[256], msg[320];
    int rc;

    (void)pthread_mutex_lock(&q->pool_lock);
    if (q->down && (q->connecting || store_pg_mono() < q->retry_at)) {
        snprintf(text, sizeof text, "%s", q->down_text);
        (void)pthread_mutex_unlock(&q->pool_lock);
        snprintf(msg, sizeof msg, "PostgreSQL unreachable (retried at most once a second): %s",
                 text);
        return store_note_error_state(s, STORE_UNAVAILABLE, NULL, c->op, msg);
    }
    if (q->down)
        q->connecting = 1;   /* one probe at a time while it is down */
    (void)pthread_mutex_unlock(&q->pool_lock);

    rc = store_pg_connect(s, c, text, sizeof text);

    (void)pthread_mutex_lock(&q->pool_lock);
    q->connecting = 0;
    if (rc == STORE_OK) {
        q->down = 0;
    } else if (rc == STORE_UNAVAILABLE) {
        q->down = 1;
        q->retry_at = store_pg_mono() + STORE_PG_RETRY_MS / 1000.0;
        snprintf(q->down_text, sizeof q->down_text, "%s", text);
    }
    (void)pthread_mutex_unlock(&q->pool_lock);
    if (rc != STORE_OK)
        return store_note_error_state(s, rc, NULL, c->op, text);
    return STORE_OK;
}

int store_pg_acquire(store *s, const char *op, pg_conn **out)
{
    store_pg *q = s->impl;
    pg_conn *c;
    int rc;

    *out = NULL;
    if (pthread_mutex_lock(&q->pool_lock) != 0)
        return store_note_error_state(s, STORE_ERROR, NULL, op, "cannot take the pool's lock");
    c = pool_take(q);
    (void)pthread_mutex_unlock(&q->pool_lock);
    if (c == NULL)
        return store_note_error_state(s, STORE_BUSY, NULL, op,
                                      "every PostgreSQL connection of the pool stayed in use "
                                      "for 10 s");
    c->op = op;
    if (c->conn != NULL && !pg_alive(c))
        store_pg_disconnect(c);   /* closed by the server while idle: a new one */
    if (c->conn == NULL) {
        rc = pool_connect(s, c);
        if (rc != STORE_OK) {
            pool_give(q, c);
            return rc;
        }
    }
    *out = c;
    return STORE_OK;
}

void store_pg_release(store *s, pg_conn *c)
{
    if (c->conn != NULL && (PQstatus(c->conn) != CONNECTION_OK ||
                            PQtransactionStatus(c->conn) != PQTRANS_IDLE))
        store_pg_disconnect(c);
    pool_give(s->impl, c);
}

/* ---- statements ----------------------------------------------------------- */

int store_pg_run(pg_conn *c, int k, int n, const char *const *vals, const int *lens,
                 const int *fmts, PGresult **res)
{
    char name[16];
    PGresult *r;
    ExecStatusType st;
    int kind;

    *res = NULL;
    snprintf(name, sizeof name, "sm%d", k);
    if (!(c->prepared & (1ull << k))) {
        r = PQprepare(c->conn, name, store_pg_sql[k], n, NULL);
        if (PQresultStatus(r) != PGRES_COMMAND_OK) {
            kind = pg_fail(c, r);
            PQclear(r);
            return kind;
        }
        PQclear(r);
        c->prepared |= 1ull << k;
    }
    r = PQexecPrepared(c->conn, name, n, vals, lens, fmts, 0);
    st = PQresultStatus(r);
    if (st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK) {
        *res = r;
        return STORE_OK;
    }
    kind = pg_fail(c, r);
    PQclear(r);
    return kind;
}

int store_pg_exec(pg_conn *c, const char *sql)
{
    PGresult *r = PQexec(c->conn, sql);
    int kind = STORE_OK;

    if (PQresultStatus(r) != PGRES_COMMAND_OK)
        kind = pg_fail(c, r);
    PQclear(r);
    return kind;
}

long long store_pg_changed(PGresult *res)
{
    const char *t = PQcmdTuples(res);

    return t && t[0] ? strtoll(t, NULL, 10) : 0;
}

/* Roll back c's open transaction, if any (a failed statement left it
 * aborted); a session that cannot is closed at release. */
void store_pg_rollback(pg_conn *c)
{
    PGresult *r;

    if (c->conn == NULL || PQtransactionStatus(c->conn) == PQTRANS_IDLE)
        return;
    r = PQexec(c->conn, "ROLLBACK");
    PQclear(r);
}

