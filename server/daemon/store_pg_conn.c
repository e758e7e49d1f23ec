/*
 * store_pg_conn.c — the PostgreSQL backend's sessions: error kinds from
 * SQLSTATEs and broken connections, connecting (libpq), a small pool that
 * reconnects by itself after a server restart (at most once a second while
 * the server is down), and running prepared statements.  The job operations
 * on top of it are store_pg.c; opening and migrations store_pg_open.c.
 *
 * Deadlines (store.h, DESIGN.md §F).  libpq's blocking calls wait for the
 * server's answer without end: a stopped server (SIGSTOP), or a network
 * that drops packets while the kernel still acknowledges, leaves them
 * blocked for as long as it lasts, and no TCP option or statement_timeout
 * ends that (the server is not running to time anything out).  So every
 * session is nonblocking and every round trip is libpq's asynchronous
 * sequence: PQsend… then PQflush / PQconsumeInput / PQisBusy driven by
 * poll() on PQsocket until the call's deadline (pg_await), and connects
 * are PQconnectStartParams + PQconnectPoll likewise (connect_timeout is
 * the application's to apply there, and is).  A session whose deadline
 * passed is closed: nothing else can be sent on it while the server owes
 * an answer, and its statement may still run when the server wakes.
 *
 * The breaker.  A connect that fails, or a call that spends its whole
 * deadline without an answer, marks the server down: for STORE_PG_RETRY_MS
 * every call fails at once with the same kind (STORE_UNAVAILABLE or
 * STORE_TIMEOUT) and the words of that failure, then one call at a time
 * tries; any answer of the server ends it.  Callers therefore never queue
 * up behind deadlines of a server that does not answer.  Probes (readiness,
 * metrics) use a session of their own with a short budget; one that times
 * out does not trip the breaker (a slow answer to a probe is not a stall),
 * only the probes' own: they answer at once for a second.
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
    return store_mono();
}

/* ---- the breaker ----------------------------------------------------------- */

/* The server did not answer (kind STORE_UNAVAILABLE or STORE_TIMEOUT, in
 * text's words): fail every call at once for STORE_PG_RETRY_MS. */
static void mark_down(store_pg *q, int kind, const char *text)
{
    (void)pthread_mutex_lock(&q->pool_lock);
    q->down = 1;
    q->down_kind = kind;
    q->retry_at = store_mono() + STORE_PG_RETRY_MS / 1000.0;
    snprintf(q->down_text, sizeof q->down_text, "%s", text);
    (void)pthread_mutex_unlock(&q->pool_lock);
}

/* May a call of op start?  While down: at once the recorded kind of the
 * failure, except one call at a time once the retry time came (*trying
 * 1: it must end with breaker_leave).  Returns a store_rc. */
static int breaker_enter(store *s, const char *op, int probe, int *trying)
{
    store_pg *q = s->impl;
    char text[256], msg[360];
    int kind;

    *trying = 0;
    (void)pthread_mutex_lock(&q->pool_lock);
    if (probe && !q->down && store_mono() < q->probe_retry_at) {
        (void)pthread_mutex_unlock(&q->pool_lock);
        return store_note_error_state(s, STORE_TIMEOUT, NULL, op, "PostgreSQL did not answer "
                                      "the last probe in time (probes retry once a second)");
    }
    if (!q->down) {
        (void)pthread_mutex_unlock(&q->pool_lock);
        return STORE_OK;
    }
    if (!q->trying && store_mono() >= q->retry_at) {
        q->trying = 1;
        *trying = 1;
        (void)pthread_mutex_unlock(&q->pool_lock);
        return STORE_OK;
    }
    kind = q->down_kind;
    snprintf(text, sizeof text, "%s", q->down_text);
    (void)pthread_mutex_unlock(&q->pool_lock);
    snprintf(msg, sizeof msg, "%s (retried at most once a second): %s",
             kind == STORE_TIMEOUT ? "PostgreSQL does not answer" : "PostgreSQL unreachable",
             text);
    return store_note_error_state(s, kind, NULL, op, msg);
}

/* The end of a call: an answer of the server ends the down state; the one
 * call allowed while down that got none sets the next try. */
static void breaker_leave(store_pg *q, int trying, int answered)
{
    (void)pthread_mutex_lock(&q->pool_lock);
    if (answered) {
        q->down = 0;
        q->probe_retry_at = 0.0;
    }
    if (trying) {
        q->trying = 0;
        if (!answered)
            q->retry_at = store_mono() + STORE_PG_RETRY_MS / 1000.0;
    }
    (void)pthread_mutex_unlock(&q->pool_lock);
}

/* ---- waiting on the socket ------------------------------------------------ */

/* Milliseconds left before c's deadline, 0 when it passed. */
static int ms_left(const pg_conn *c)
{
    double left = (c->deadline - store_mono()) * 1000.0;

    return left <= 0.0 ? 0 : left > 2e9 ? 2000000000 : (int)left + 1;
}

/* Send what libpq holds and read until the current result is complete
 * (PQisBusy 0), polling c's socket until the deadline.  Returns STORE_OK,
 * STORE_TIMEOUT, or STORE_ERROR when libpq failed (its words in
 * PQerrorMessage); nothing recorded. */
static int pg_await(pg_conn *c)
{
    struct pollfd p;
    int f, n, ms;

    for (;;) {
        f = PQflush(c->conn);   /* 0: all sent, 1: more to send, -1: failed */
        if (f < 0)
            return STORE_ERROR;
        if (f == 0 && !PQisBusy(c->conn))
            return STORE_OK;
        ms = ms_left(c);
        if (ms == 0)
            return STORE_TIMEOUT;
        p.fd = PQsocket(c->conn);
        p.events = (short)(POLLIN | (f == 1 ? POLLOUT : 0));
        p.revents = 0;
        if (p.fd < 0)
            return STORE_ERROR;
        n = poll(&p, 1, ms);
        if (n < 0 && errno != EINTR)
            return STORE_ERROR;
        /* read-ready: the answer, or input the server sends before it
         * reads more of ours (libpq's nonblocking protocol) */
        if (n > 0 && (p.revents & (POLLIN | POLLERR | POLLHUP)) && !PQconsumeInput(c->conn))
            return STORE_ERROR;
    }
}

/* After a PQsend…: every result of the command, within the deadline; *out
 * the first failed one, else the last (NULL when none came).  Returns
 * STORE_OK (the server answered), STORE_TIMEOUT or STORE_ERROR (libpq
 * failed); nothing recorded. */
static int pg_collect(pg_conn *c, PGresult **out)
{
    PGresult *r, *keep = NULL;
    ExecStatusType st;
    int rc;

    *out = NULL;
    for (;;) {
        rc = pg_await(c);
        if (rc != STORE_OK) {
            PQclear(keep);
            return rc;
        }
        r = PQgetResult(c->conn);
        if (r == NULL)
            break;
        st = keep ? PQresultStatus(keep) : PGRES_COMMAND_OK;
        if (st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK) {
            PQclear(keep);
            keep = r;
        } else {
            PQclear(r);   /* keep the first failure */
        }
    }
    c->answered = 1;
    *out = keep;
    return STORE_OK;
}

/* The deadline of c passed during what: close the session (the server
 * still owes an answer on it), record STORE_TIMEOUT, and unless c is the
 * probes' session mark the server stalled. */
static int pg_timeout(pg_conn *c, const char *what)
{
    store_pg *q = c->owner->impl;
    char text[256];

    snprintf(text, sizeof text, "PostgreSQL did not answer within %d ms (%s); the session "
             "is closed", c->budget_ms, what);
    store_pg_disconnect(c);
    if (!c->probe) {
        mark_down(q, STORE_TIMEOUT, text);
    } else {   /* the next probes answer at once for a second (two in one /metrics) */
        (void)pthread_mutex_lock(&q->pool_lock);
        q->probe_retry_at = store_mono() + STORE_PG_RETRY_MS / 1000.0;
        (void)pthread_mutex_unlock(&q->pool_lock);
    }
    return store_note_error_state(c->owner, STORE_TIMEOUT, NULL, c->op, text);
}

/* A PQsend… that returned sent: collect its answer into *res (NULL on
 * failure).  A failure is recorded and its kind returned; STORE_OK means
 * the server answered, not that the command succeeded. */
static int pg_answer(pg_conn *c, int sent, PGresult **res, const char *what)
{
    int rc;

    *res = NULL;
    if (!sent)
        return pg_fail(c, NULL);
    rc = pg_collect(c, res);
    if (rc == STORE_TIMEOUT)
        return pg_timeout(c, what);
    if (rc != STORE_OK || *res == NULL)
        return pg_fail(c, NULL);
    return STORE_OK;
}

/* ---- sessions ------------------------------------------------------------- */

/* Notices (a NOTICE of a migration, a WARNING) are not failures: dropped. */
static void pg_quiet(void *arg, const char *message)
{
    (void)arg;
    (void)message;
}

/* The value of keyword in the options of conn (NULL when unset). */
static char *conn_option(PGconn *conn, const char *keyword, char *buf, size_t len)
{
    PQconninfoOption *opts = PQconninfo(conn);
    char *found = NULL;

    for (PQconninfoOption *o = opts; o && o->keyword; o++) {
        if (strcmp(o->keyword, keyword) == 0 && o->val != NULL && o->val[0] != '\0') {
            snprintf(buf, len, "%s", o->val);
            found = buf;
        }
    }
    PQconninfoFree(opts);
    return found;
}

/* PQconnectPoll until the session is up, before c->deadline and the DSN's
 * connect_timeout (libpq leaves it to the application here; it counts 1
 * as 2).  Returns STORE_OK, STORE_UNAVAILABLE or STORE_TIMEOUT, err set. */
static int connect_poll(pg_conn *c, char *err, size_t errlen)
{
    PostgresPollingStatusType st = PGRES_POLLING_WRITING;
    char buf[32], *v = conn_option(c->conn, "connect_timeout", buf, sizeof buf);
    double end = c->deadline, begun = store_mono();
    struct pollfd p;
    int limit = v ? atoi(v) : 0, ms;

    if (limit == 1)
        limit = 2;
    if (limit > 0 && begun + limit < end)
        end = begun + limit;
    while (st != PGRES_POLLING_OK) {
        if (st == PGRES_POLLING_FAILED || PQstatus(c->conn) == CONNECTION_BAD) {
            one_line(err, errlen, PQerrorMessage(c->conn));
            return STORE_UNAVAILABLE;
        }
        ms = (int)((end - store_mono()) * 1000.0);
        if (ms <= 0) {
            snprintf(err, errlen, "PostgreSQL did not complete the connection within %.1f s",
                     store_mono() - begun);
            return STORE_TIMEOUT;
        }
        p.fd = PQsocket(c->conn);
        p.events = st == PGRES_POLLING_READING ? POLLIN : POLLOUT;
        p.revents = 0;
        if (poll(&p, 1, ms) == 0)
            continue;   /* the time check above ends it */
        st = PQconnectPoll(c->conn);
    }
    return STORE_OK;
}

/* The session's timeouts, each unless the DSN's options (or PGOPTIONS)
 * set it: statement_timeout stmt_ms, lock_timeout the settings'.  err set
 * on failure. */
static int session_settings(store *s, pg_conn *c, int stmt_ms, char *err, size_t errlen)
{
    store_pg *q = s->impl;
    char opts[512], sql[160], *o = conn_option(c->conn, "options", opts, sizeof opts);
    PGresult *res = NULL;
    int n = 0, rc;

    sql[0] = '\0';
    if (o == NULL || strstr(o, "statement_timeout") == NULL)
        n += snprintf(sql + n, sizeof sql - (size_t)n, "SET statement_timeout = %d;", stmt_ms);
    if (o == NULL || strstr(o, "lock_timeout") == NULL)
        snprintf(sql + n, sizeof sql - (size_t)n, "SET lock_timeout = %d", q->lock_timeout_ms);
    if (sql[0] == '\0')
        return STORE_OK;
    rc = PQsendQuery(c->conn, sql) ? pg_collect(c, &res) : STORE_ERROR;
    if (rc == STORE_OK && res != NULL && PQresultStatus(res) == PGRES_COMMAND_OK) {
        PQclear(res);
        return STORE_OK;
    }
    if (rc == STORE_TIMEOUT)
        snprintf(err, errlen, "PostgreSQL did not answer the session's settings in time");
    else
        one_line(err, errlen, res ? PQresultErrorMessage(res) : PQerrorMessage(c->conn));
    if (rc == STORE_OK)
        rc = store_pg_kind(res ? PQresultErrorField(res, PG_DIAG_SQLSTATE) : NULL,
                           PQstatus(c->conn) != CONNECTION_OK);
    else if (rc == STORE_ERROR)
        rc = STORE_UNAVAILABLE;
    PQclear(res);
    return rc;
}

int store_pg_connect(store *s, pg_conn *c, int stmt_ms, char *err, size_t errlen)
{
    store_pg *q = s->impl;
    /* defaults first: the URI (dbname, expanded) overrides any of them */
    const char *const keys[] = {"connect_timeout", "client_encoding", "fallback_application_name",
                                "keepalives_idle", "keepalives_interval", "keepalives_count",
                                "tcp_user_timeout", "dbname", NULL};
    const char *const vals[] = {"2", "UTF8", "spinmodald", "10", "5", "3", "15000", q->dsn,
                                NULL};
    int rc;

    store_pg_disconnect(c);
    c->conn = PQconnectStartParams(keys, vals, 1);
    if (c->conn == NULL) {
        snprintf(err, errlen, "out of memory connecting to PostgreSQL");
        return STORE_NOMEM;
    }
    rc = connect_poll(c, err, errlen);
    if (rc == STORE_OK && PQsetnonblocking(c->conn, 1) != 0) {
        one_line(err, errlen, PQerrorMessage(c->conn));
        rc = STORE_UNAVAILABLE;
    }
    if (rc == STORE_OK) {
        (void)PQsetNoticeProcessor(c->conn, pg_quiet, NULL);
        rc = session_settings(s, c, stmt_ms, err, errlen);
    }
    if (rc != STORE_OK)
        store_pg_disconnect(c);
    return rc;
}

void store_pg_disconnect(pg_conn *c)
{
    if (c->conn != NULL)
        PQfinish(c->conn);   /* nonblocking: the goodbye is not waited for */
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

/* A free connection of q within ms (the probes' session when probe);
 * NULL when none came free. */
static pg_conn *pool_take(store_pg *q, int probe, int ms)
{
    struct timespec until = store_wall_in(ms);
    pg_conn *c;
    int e = 0;

    if (probe)
        return pthread_mutex_timedlock(&q->probe_lock, &until) == 0 ? &q->probe_conn : NULL;
    if (pthread_mutex_lock(&q->pool_lock) != 0)
        return NULL;
    while (q->free_conns == NULL && e == 0)
        e = pthread_cond_timedwait(&q->pool_cond, &q->pool_lock, &until);
    c = q->free_conns;
    if (c != NULL)
        q->free_conns = c->next;
    (void)pthread_mutex_unlock(&q->pool_lock);
    return c;
}

static void pool_give(store_pg *q, pg_conn *c)
{
    if (c->probe) {
        (void)pthread_mutex_unlock(&q->probe_lock);
        return;
    }
    (void)pthread_mutex_lock(&q->pool_lock);
    c->next = q->free_conns;
    q->free_conns = c;
    (void)pthread_cond_signal(&q->pool_cond);
    (void)pthread_mutex_unlock(&q->pool_lock);
}

/* Open a new session on c for a call.  A failure to reach the server, or
 * a connect past connect_timeout (not a probe's short budget), marks it
 * down.  Returns a store_rc (recorded). */
static int pool_connect(store *s, pg_conn *c)
{
    store_pg *q = s->impl;
    char text[256];
    int rc = store_pg_connect(s, c, s->timeout_ms, text, sizeof text);

    if (rc == STORE_OK) {
        c->answered = 1;
        return STORE_OK;
    }
    if (rc == STORE_UNAVAILABLE || (rc == STORE_TIMEOUT && !c->probe)) {
        mark_down(q, rc, text);
    } else if (rc == STORE_TIMEOUT) {
        (void)pthread_mutex_lock(&q->pool_lock);
        q->probe_retry_at = store_mono() + STORE_PG_RETRY_MS / 1000.0;
        (void)pthread_mutex_unlock(&q->pool_lock);
    }
    return store_note_error_state(s, rc, NULL, c->op, text);
}

/* store_pg_acquire and store_pg_acquire_probe. */
static int pool_acquire(store *s, const char *op, int probe, pg_conn **out)
{
    store_pg *q = s->impl;
    int ms = probe ? s->probe_ms : s->timeout_ms, trying = 0, rc;
    double deadline = store_mono() + ms / 1000.0;
    char text[160];
    pg_conn *c;

    *out = NULL;
    rc = breaker_enter(s, op, probe, &trying);
    if (rc != STORE_OK)
        return rc;
    c = pool_take(q, probe, ms);
    if (c == NULL) {
        breaker_leave(q, trying, 0);
        snprintf(text, sizeof text, "no PostgreSQL connection came free within %d ms (each "
                 "waits for the server)", ms);
        return store_note_error_state(s, STORE_TIMEOUT, NULL, op, text);
    }
    c->op = op;
    c->deadline = deadline;
    c->budget_ms = ms;
    c->answered = 0;
    if (c->conn != NULL && !pg_alive(c))
        store_pg_disconnect(c);   /* closed by the server while idle: a new one */
    if (c->conn == NULL) {
        rc = pool_connect(s, c);
        if (rc != STORE_OK) {
            breaker_leave(q, trying, 0);
            pool_give(q, c);
            return rc;
        }
    }
    c->trying = trying;   /* the one call allowed while down: store_pg_release tells */
    *out = c;
    return STORE_OK;
}

int store_pg_acquire(store *s, const char *op, pg_conn **out)
{
    return pool_acquire(s, op, 0, out);
}

int store_pg_acquire_probe(store *s, const char *op, pg_conn **out)
{
    return pool_acquire(s, op, 1, out);
}

void store_pg_release(store *s, pg_conn *c)
{
    if (c->conn != NULL && (PQstatus(c->conn) != CONNECTION_OK ||
                            PQtransactionStatus(c->conn) != PQTRANS_IDLE))
        store_pg_disconnect(c);
    breaker_leave(s->impl, c->trying, c->answered);
    c->trying = 0;
    pool_give(s->impl, c);
}

/* ---- statements ----------------------------------------------------------- */

/* The answer r of a statement or command of c: *res = r when it succeeded
 * (the caller's to PQclear), else recorded, cleared, and its kind. */
static int pg_result(pg_conn *c, PGresult *r, PGresult **res)
{
    ExecStatusType st = PQresultStatus(r);
    int kind;

    if (st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK) {
        *res = r;
        return STORE_OK;
    }
    kind = pg_fail(c, r);
    PQclear(r);
    return kind;
}

int store_pg_run(pg_conn *c, int k, int n, const char *const *vals, const int *lens,
                 const int *fmts, PGresult **res)
{
    char name[16];
    PGresult *r;
    double sent = 0.0;
    int kind;

    *res = NULL;
    if (c->conn == NULL)
        return pg_fail(c, NULL);
    snprintf(name, sizeof name, "sm%d", k);
    if (!(c->prepared & (1ull << k))) {
        kind = pg_answer(c, PQsendPrepare(c->conn, name, store_pg_sql[k], n, NULL), &r,
                         "preparing a statement");
        if (kind != STORE_OK)
            return kind;
        if (PQresultStatus(r) != PGRES_COMMAND_OK) {
            kind = pg_fail(c, r);
            PQclear(r);
            return kind;
        }
        PQclear(r);
        c->prepared |= 1ull << k;
    }
    for (int i = 0; i < n && lens && fmts; i++)   /* large texts: time to send them */
        sent += fmts[i] == 1 && vals[i] ? (double)lens[i] : 0.0;
    c->deadline += sent / STORE_PG_SEND_RATE;
    kind = pg_answer(c, PQsendQueryPrepared(c->conn, name, n, vals, lens, fmts, 0), &r,
                     "running a statement");
    return kind == STORE_OK ? pg_result(c, r, res) : kind;
}

int store_pg_query(pg_conn *c, const char *sql, PGresult **res)
{
    PGresult *r;
    int kind;

    *res = NULL;
    if (c->conn == NULL)
        return pg_fail(c, NULL);
    kind = pg_answer(c, PQsendQuery(c->conn, sql), &r, "running a command");
    return kind == STORE_OK ? pg_result(c, r, res) : kind;
}

int store_pg_exec(pg_conn *c, const char *sql)
{
    PGresult *r = NULL;
    int kind = store_pg_query(c, sql, &r);

    PQclear(r);
    return kind;
}

long long store_pg_changed(PGresult *res)
{
    const char *t = PQcmdTuples(res);

    return t && t[0] ? strtoll(t, NULL, 10) : 0;
}

/* Roll back c's open transaction, if any (a failed statement left it
 * aborted); a session that cannot (or whose deadline passed) is closed,
 * here or at release, which ends the transaction on the server. */
void store_pg_rollback(pg_conn *c)
{
    PGresult *r = NULL;

    if (c->conn == NULL || PQtransactionStatus(c->conn) == PQTRANS_IDLE)
        return;
    if (ms_left(c) == 0 || PQtransactionStatus(c->conn) == PQTRANS_ACTIVE) {
        store_pg_disconnect(c);
        return;
    }
    if (PQsendQuery(c->conn, "ROLLBACK") && pg_collect(c, &r) == STORE_OK) {
        PQclear(r);
        return;
    }
    PQclear(r);
    store_pg_disconnect(c);
}
