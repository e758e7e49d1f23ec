/*
 * http_guard.c — the budgets of connection slots: a deadline for every
 * request (its head and body must have arrived within --request-deadline
 * seconds, however slowly the bytes trickle), slots kept free for probes and
 * writes, and a cap on waiting long polls (--max-waiters).
 *
 * Why: libmicrohttpd's connection timeout is an idle timeout, which a client
 * sending one byte every few seconds resets forever; 600 such sockets held
 * every connection slot and /livez stopped answering.  The per-client
 * connection limit (MHD_OPTION_PER_IP_CONNECTION_LIMIT, set in http.c) keeps
 * one client from taking every slot; this file bounds how long any slot is
 * held by a request that is not complete.
 *
 * How: libmicrohttpd tells us of every connection (MHD_OPTION_NOTIFY_CONNECTION);
 * each gets a guard record in a list, with its socket and a deadline:
 *   - connection accepted, or the previous request on it answered: now + D
 *     (the next request's head and body must be in by then; an idle
 *     keep-alive connection is closed then too);
 *   - the request is complete and being answered (?wait, a large result):
 *     no deadline (the idle timeout still applies to a reader that stops).
 * A guard thread wakes once a second and shuts down (shutdown(2), not
 * close) the socket of every record past its deadline; the connection's own
 * thread then sees the end of the stream and libmicrohttpd closes it.  The
 * record is removed under the same lock in the CLOSED notification, which
 * libmicrohttpd sends before it closes the socket, so the guard never
 * touches a descriptor that was closed and reused.
 *
 * Shedding.  The per-client limit does not stop trickling clients spread
 * over many addresses: 600 of them from 60 addresses held all 512
 * connection slots, and libmicrohttpd refused every other connection
 * (/livez included) until the deadline closed them, when they could come
 * back.  So at most held_cap connections (the limit less an eighth,
 * http_guard_set_caps) may be held; a new connection over that shuts down
 * an idle keep-alive connection, or else the incomplete one whose deadline
 * is nearest (the one that has waited longest).  A complete request is
 * answered at once, so the slots kept free always serve it.
 *
 * Long polls.  A request with ?wait=S is complete, so shedding cannot
 * close it: 600 GET ?wait=30 from 10 addresses held all 512 slots for 30 s.
 * So at most max_waiters requests wait at once (a quarter of the limit by
 * default, never more than half); a new one over that releases the oldest,
 * which answers at its next slice (HTTP_WAIT_SLICE) with the job's current
 * state, as if its wait had ended (the client polls again).  Its connection
 * is then an idle keep-alive one, which shedding may close.  Waiters,
 * connections being answered and incomplete ones together stay under
 * held_cap while there are incomplete ones to close, so the slots kept
 * free stay free for /livez, /readyz, /metrics and writes.
 *
 * Under a flood that polls again at once and reopens what is closed (the
 * attack tool's 'polls'), three things ate the slots kept free: released
 * long polls still finishing their slice (at most max_waiters / 2 now, see
 * http_waiter_make_room), connections shut down but not yet closed by
 * their starved threads (counted in n_dying and shed for), and shed
 * connections whose request had been read meanwhile (not served:
 * http_guard_answering says so).
 */
#include "http_internal.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>

#include "log.h"

/* One connection: its socket and deadline; a node of http->conns. */
struct http_conn {
    int fd;                  /* the connection's socket */
    double deadline;         /* monotonic s; 0 = none (a request is being answered) */
    int expired;             /* 1 once the guard shut the socket down */
    int served;              /* 1 once a request on it was answered (idle keep-alive) */
    unsigned spared;         /* the shed round that found its request arriving */
    struct http_conn *prev, *next;
};

#define HTTP_SHED_SPARE 16 /* most connections with a request arriving spared per shed */

/* 1 when a should be shed before b: idle keep-alive first, then the nearest deadline. */
static int http_guard_before(const http_conn *a, const http_conn *b)
{
    if (a->served != b->served)
        return a->served;
    return a->deadline < b->deadline;
}

void http_guard_set_caps(http *h, int connection_limit, int max_waiters)
{
    int reserve = connection_limit / 8 > 16 ? connection_limit / 8 : 16;

    h->held_cap = connection_limit - reserve > 1 ? connection_limit - reserve : 1;
    h->max_waiters = max_waiters < connection_limit / 2 ? max_waiters : connection_limit / 2;
    if (h->max_waiters < 0)
        h->max_waiters = 0;
}

/*
 * Called with guard_lock held after a connection was added (except = the
 * newcomer) or went back to waiting for a request (except NULL): while more
 * than held_cap connections are open (waiting for their request, being
 * answered or in a long poll; or shut down and not yet closed: those hold a
 * slot of libmicrohttpd's too), shut down one waiting for its request, never
 * `except`: an idle keep-alive connection (already served) first, then the
 * one with the nearest deadline.  So a new client whose first request is on
 * its way is not closed for connections that were answered (the long polls
 * answered early).  The second call matters when libmicrohttpd is at its
 * limit and accepts nobody: closing idle connections frees slots.
 *
 * A candidate whose socket holds unread bytes has a request arriving (a
 * probe whose thread has not run yet, under load): it is spared, up to
 * HTTP_SHED_SPARE of them per call, so a flood that reopens connections as
 * fast as they close cannot make a probe the oldest and have it closed.
 * Tricklers are read as their bytes come, so their sockets are empty.
 */
static void http_guard_shed(http *h, const http_conn *except)
{
    http_conn *k, *oldest;
    unsigned round = ++h->shed_round;
    int spared = 0, n, excess = h->n_held + h->n_dying - h->held_cap;

    while (excess > 0) {
        oldest = NULL;
        for (k = h->conns; k; k = k->next)
            if (!k->expired && k->deadline > 0.0 && k != except && k->spared != round &&
                (!oldest || http_guard_before(k, oldest)))
                oldest = k;
        if (!oldest)
            return;
        n = 0;
        if (spared < HTTP_SHED_SPARE && ioctl(oldest->fd, FIONREAD, &n) == 0 && n > 0) {
            oldest->spared = round;
            spared++;
            continue;
        }
        oldest->expired = 1;
        shutdown(oldest->fd, SHUT_RDWR);
        h->shed_pending++;
        h->n_held--;
        h->n_dying++;
        excess--;
    }
}

/* MHD_OPTION_NOTIFY_CONNECTION: track connections from accept to close. */
void http_guard_notify(void *cls, struct MHD_Connection *c, void **socket_context,
                       enum MHD_ConnectionNotificationCode code)
{
    http *h = cls;
    http_conn *k = *socket_context;
    const union MHD_ConnectionInfo *ci;

    if (code == MHD_CONNECTION_NOTIFY_STARTED) {
        ci = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
        k = calloc(1, sizeof(*k));
        if (!k || !ci) { /* untracked: only the idle timeout applies */
            free(k);
            return;
        }
        k->fd = ci->connect_fd;
        pthread_mutex_lock(&h->guard_lock);
        k->deadline = http_mono() + h->request_deadline;
        k->next = h->conns;
        if (h->conns)
            h->conns->prev = k;
        h->conns = k;
        h->n_held++;
        http_guard_shed(h, k);
        pthread_mutex_unlock(&h->guard_lock);
        *socket_context = k;
        return;
    }
    if (!k)
        return;
    pthread_mutex_lock(&h->guard_lock);
    if (!k->expired)
        h->n_held--;
    else
        h->n_dying--;
    if (k->prev)
        k->prev->next = k->next;
    else
        h->conns = k->next;
    if (k->next)
        k->next->prev = k->prev;
    pthread_mutex_unlock(&h->guard_lock);
    free(k);
    *socket_context = NULL;
}

/* The guard record of connection c, or NULL when it is not tracked. */
static http_conn *http_guard_of(struct MHD_Connection *c)
{
    const union MHD_ConnectionInfo *ci =
        MHD_get_connection_info(c, MHD_CONNECTION_INFO_SOCKET_CONTEXT);

    return ci ? ci->socket_context : NULL;
}

int http_guard_answering(http *h, struct MHD_Connection *c)
{
    http_conn *k = http_guard_of(c);
    int expired;

    if (!k)
        return 0;
    pthread_mutex_lock(&h->guard_lock);
    k->deadline = 0.0;
    expired = k->expired;
    pthread_mutex_unlock(&h->guard_lock);
    return expired;
}

void http_guard_answered(http *h, struct MHD_Connection *c)
{
    http_conn *k = c ? http_guard_of(c) : NULL;

    if (!k)
        return;
    pthread_mutex_lock(&h->guard_lock);
    if (!k->expired) {
        k->deadline = http_mono() + h->request_deadline;
        k->served = 1;
        http_guard_shed(h, NULL);
    }
    pthread_mutex_unlock(&h->guard_lock);
}

/* ------------------------------------------------------------- long polls */

/*
 * Over the cap, a newcomer releases the oldest waiter, which answers at the
 * end of its slice (up to HTTP_WAIT_SLICE later) and holds its slot until
 * then.  A flood that polls again at once could keep hundreds of them so
 * (the connection limit reached, probes refused): at most half as many
 * as max_waiters (at least one) may be finishing at a time; past that the
 * newcomer is the one answered at once.  Both count as answered early.
 * Called with guard_lock held; 0 = join, -1 = answer at once.
 */
static int http_waiter_make_room(http *h)
{
    http_waiter *old;
    int releasing_cap = h->max_waiters / 2 > 1 ? h->max_waiters / 2 : 1;

    if (h->n_waiters < h->max_waiters)
        return 0;
    h->released_pending++;
    h->released_total++;
    old = h->waiters;
    if (!old || h->n_releasing >= releasing_cap)
        return -1;
    h->waiters = old->next;
    if (h->waiters)
        h->waiters->prev = NULL;
    else
        h->waiters_tail = NULL;
    old->prev = old->next = NULL;
    old->released = 1;
    h->n_waiters--;
    h->n_releasing++;
    return 0;
}

int http_waiter_join(http *h, http_waiter *w)
{
    memset(w, 0, sizeof(*w));
    pthread_mutex_lock(&h->guard_lock);
    if (h->max_waiters <= 0 || http_waiter_make_room(h)) {
        pthread_mutex_unlock(&h->guard_lock);
        return -1;
    }
    w->prev = h->waiters_tail;
    if (h->waiters_tail)
        h->waiters_tail->next = w;
    else
        h->waiters = w;
    h->waiters_tail = w;
    h->n_waiters++;
    pthread_mutex_unlock(&h->guard_lock);
    return 0;
}

int http_waiter_released(http *h, http_waiter *w)
{
    int released;

    pthread_mutex_lock(&h->guard_lock);
    released = w->released;
    pthread_mutex_unlock(&h->guard_lock);
    return released;
}

void http_waiter_leave(http *h, http_waiter *w)
{
    pthread_mutex_lock(&h->guard_lock);
    if (!w->released) { /* still in the list */
        if (w->prev)
            w->prev->next = w->next;
        else
            h->waiters = w->next;
        if (w->next)
            w->next->prev = w->prev;
        else
            h->waiters_tail = w->prev;
        h->n_waiters--;
    } else {
        h->n_releasing--;
    }
    w->prev = w->next = NULL;
    pthread_mutex_unlock(&h->guard_lock);
}

void http_waiter_counts(http *h, int *waiting, int *cap, unsigned long long *released)
{
    pthread_mutex_lock(&h->guard_lock);
    *waiting = h->n_waiters;
    *cap = h->max_waiters;
    *released = h->released_total;
    pthread_mutex_unlock(&h->guard_lock);
}

/* ------------------------------------------------------------- the thread */

/* Shut down the sockets past their deadline; returns how many. */
static int http_guard_sweep(http *h, double now)
{
    http_conn *k;
    int n = 0;

    for (k = h->conns; k; k = k->next)
        if (!k->expired && k->deadline > 0.0 && now > k->deadline) {
            k->expired = 1;
            shutdown(k->fd, SHUT_RDWR);
            h->n_held--;
            h->n_dying++;
            n++;
        }
    return n;
}

static void *http_guard_main(void *arg)
{
    http *h = arg;
    struct timespec ts;
    char count[16];
    int n, shed, released;

    pthread_mutex_lock(&h->guard_lock);
    while (!h->guard_stop) {
        clock_gettime(CLOCK_REALTIME, &ts);
        ts.tv_sec += 1;
        pthread_cond_timedwait(&h->guard_cv, &h->guard_lock, &ts);
        if (h->guard_stop)
            break;
        shed = h->shed_pending;
        h->shed_pending = 0;
        if (shed > 0) { /* logged here, once a second, not once per connection */
            pthread_mutex_unlock(&h->guard_lock);
            snprintf(count, sizeof(count), "%d", shed);
            log_event("warn", "connections_shed", "closed", count, "reason",
                      "more connections held than the slots kept free allow",
                      (const char *)NULL);
            metrics_shed(h->mx, shed);
            pthread_mutex_lock(&h->guard_lock);
        }
        released = h->released_pending;
        h->released_pending = 0;
        if (released > 0) {
            pthread_mutex_unlock(&h->guard_lock);
            snprintf(count, sizeof(count), "%d", released);
            log_event("info", "long_polls_released", "answered", count, "reason",
                      "more long polls (?wait) than --max-waiters: the oldest answered early",
                      (const char *)NULL);
            pthread_mutex_lock(&h->guard_lock);
        }
        n = http_guard_sweep(h, http_mono());
        if (n > 0) {
            pthread_mutex_unlock(&h->guard_lock);
            snprintf(count, sizeof(count), "%d", n);
            log_event("warn", "request_deadline", "closed", count, "reason",
                      "request head or body not complete within --request-deadline",
                      (const char *)NULL);
            metrics_deadline_closed(h->mx, n);
            pthread_mutex_lock(&h->guard_lock);
        }
    }
    pthread_mutex_unlock(&h->guard_lock);
    return NULL;
}

int http_guard_start(http *h)
{
    if (pthread_create(&h->guard_thread, NULL, http_guard_main, h))
        return HTTP_NOMEM;
    h->guard_started = 1;
    return HTTP_OK;
}

void http_guard_stop(http *h)
{
    if (!h->guard_started)
        return;
    pthread_mutex_lock(&h->guard_lock);
    h->guard_stop = 1;
    pthread_cond_broadcast(&h->guard_cv);
    pthread_mutex_unlock(&h->guard_lock);
    pthread_join(h->guard_thread, NULL);
    h->guard_started = 0;
}
