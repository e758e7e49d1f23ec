/*
 * test_store.c — behaviour of the job store (server/daemon/store.h), one
 * suite run against each backend: `test_store sqlite` on a real database
 * file in a mkdtemp directory, `test_store postgresql` on a throwaway
 * PostgreSQL cluster it starts itself (pg_cluster.c; exit 77, skipped,
 * when the server binaries are missing).
 *
 * Both backends: schema version on a fresh open, submission outcomes,
 * claim order, finish with large texts read back byte-exactly, cancel and
 * requeue in every state, newest-first pagination and state filters,
 * counts, crash recovery on reopen, 4 threads claiming 200 jobs (each
 * exactly once) while 2 threads read, a cancel seen by the job's worker
 * (store_cancel_requested, store_state_of), the lease calls.
 * SQLite only: WAL, refusal of newer, foreign and non-SQLite files.
 * PostgreSQL only (several replicas = several store handles): refusals
 * (bad URI, unreachable server without the password in the message, newer
 * schema, foreign table), six stores opening a fresh database at once
 * (one migration), two handles × two threads claiming 400 jobs (each
 * exactly once; claims/s printed) and submitting the same ids at once
 * (one insert each), lease expiry and renewal, the attempt limit, and a
 * server restart and stop survived by the same handle (STORE_UNAVAILABLE
 * quickly while it is down, then working again without a reopen).
 */
#include "pg_cluster.h"
#include "store.h"

#include <pthread.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static int failures = 0;
static int checks = 0;

#define CHECK(cond, ...)                                      \
    do {                                                      \
        checks++;                                             \
        if (!(cond)) {                                        \
            failures++;                                       \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);       \
            printf(__VA_ARGS__);                              \
            printf("\n");                                     \
        }                                                     \
    } while (0)

enum { N_CONC = 200, N_CLAIMERS = 4, N_READERS = 2 };

/* The backend under test: a SQLite file in dir, or databases of a cluster. */
typedef struct backend {
    int pg;               /* 0: SQLite; 1: PostgreSQL */
    const char *dir;      /* SQLite: the mkdtemp directory */
    pg_cluster *cl;       /* PostgreSQL: the throwaway cluster */
} backend;

/* A fresh, empty database called name: a file path in b->dir (SQLite) or
 * the URI of a new database of the cluster.  Returns 0 or -1. */
static int fresh_db(const backend *b, const char *name, char *out, size_t len)
{
    if (b->pg)
        return pg_cluster_createdb(b->cl, name, out, len);
    snprintf(out, len, "%s/%s.db", b->dir, name);
    return 0;
}

static double mono(void)
{
    struct timespec ts;

    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Job id number n: 64 hex digits. */
static void make_id(unsigned n, char id[65])
{
    snprintf(id, 65, "%064x", n);
}

static int submit(store *s, unsigned n, double now, int *outcome, store_job *job)
{
    char id[65], req[64];
    int len;

    make_id(n, id);
    /* job 16 has a "name" (codec_request_stored_text), which a listing reads */
    len = snprintf(req, sizeof req,
                   n == 16 ? "{\"job\":%u,\"name\":\"job \\\"16\\\"\"}" : "{\"job\":%u}", n);
    return store_submit(s, id, req, (size_t)len, 11, now, outcome, job);
}

/* Run one SQL text on the database file directly; 0 on success. */
static int raw_exec(const char *path, const char *sql)
{
    sqlite3 *db = NULL;
    int rc = sqlite3_open(path, &db);

    if (rc == SQLITE_OK)
        rc = sqlite3_exec(db, sql, NULL, NULL, NULL);
    sqlite3_close(db);
    return rc;
}

/* First column of the first row of sql as text into buf (SQLite file). */
static int raw_text(const char *path, const char *sql, char *buf, size_t len)
{
    sqlite3 *db = NULL;
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_open(path, &db);

    buf[0] = '\0';
    if (rc == SQLITE_OK)
        rc = sqlite3_prepare_v2(db, sql, -1, &st, NULL);
    if (rc == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW)
        snprintf(buf, len, "%s", (const char *)sqlite3_column_text(st, 0));
    sqlite3_finalize(st);
    sqlite3_close(db);
    return rc;
}

/* The same on either backend: SQLITE_OK (0) on success. */
static int raw_text_b(const backend *b, const char *target, const char *sql, char *buf,
                      size_t len)
{
    if (b->pg)
        return pg_raw(target, sql, buf, len) == 0 ? SQLITE_OK : SQLITE_ERROR;
    return raw_text(target, sql, buf, len);
}

static void remove_db(const char *path)
{
    char p[600];

    unlink(path);
    snprintf(p, sizeof p, "%s-wal", path);
    unlink(p);
    snprintf(p, sizeof p, "%s-shm", path);
    unlink(p);
    snprintf(p, sizeof p, "%s.lock", path);
    unlink(p);
}

static void test_names(void)
{
    store_state st = STORE_DONE;

    CHECK(!strcmp(store_state_name(STORE_CANCELED), "canceled"), "name canceled");
    CHECK(!strcmp(store_state_name(STORE_N_STATES), "unknown"), "name out of range");
    CHECK(store_state_parse("running", &st) == STORE_OK && st == STORE_RUNNING, "parse running");
    CHECK(store_state_parse("RUNNING", &st) == STORE_NOT_FOUND, "parse is exact");
    CHECK(store_state_parse(NULL, &st) == STORE_NOT_FOUND, "parse NULL");
    store_job_clear(NULL);
}

/* Submit, claim, finish, cancel, requeue on one database. */
static void test_lifecycle(const backend *b, store *s, const char *path)
{
    store_job j, k;
    store_state state = STORE_QUEUED;
    char id[65], buf[64];
    int outcome = -1;
    long long counts[STORE_N_STATES];

    CHECK(store_schema_version(s) == 1, "fresh schema version 1, got %d", store_schema_version(s));
    CHECK(!strcmp(store_backend_name(s), b->pg ? "postgresql" : "sqlite"), "backend %s",
          store_backend_name(s));
    CHECK(store_caps(s) == (b->pg ? STORE_CAP_SHARED | STORE_CAP_SECRET_PATH : 0u),
          "capabilities %#x", store_caps(s));
    if (!b->pg)
        CHECK(raw_text(path, "PRAGMA journal_mode", buf, sizeof buf) == SQLITE_OK &&
                  !strcmp(buf, "wal"), "journal mode wal, got '%s'", buf);
    CHECK(raw_text_b(b, path, b->pg ? "SELECT version FROM spinmodal_schema" : "PRAGMA user_version",
                     buf, sizeof buf) == SQLITE_OK && !strcmp(buf, "1"),
          "user_version 1 in the file, got '%s'", buf);
    CHECK(store_check_writable(s) == STORE_OK, "writable");
    CHECK(store_claim_next(s, 1.0, &j) == STORE_NOT_FOUND, "claim on empty store");
    make_id(1, id);
    CHECK(store_get(s, id, 0, &j) == STORE_NOT_FOUND, "get unknown");

    /* 1, 2, 3 new; 1 again is existing */
    CHECK(submit(s, 1, 100.5, &outcome, &j) == STORE_OK && outcome == 1, "submit new: %d", outcome);
    CHECK(!strcmp(j.id, id) && j.state == STORE_QUEUED && j.seq == 1 && j.speeds_total == 11 &&
              j.speeds_done == 0 && j.attempts == 0 && j.created_at == 100.5 && j.started_at == 0 &&
              j.finished_at == 0 && !j.has_result && j.request == NULL && j.error == NULL,
          "new job as stored (seq %lld state %d)", j.seq, (int)j.state);
    store_job_clear(&j);
    CHECK(raw_text_b(b, path, "SELECT count(*) FROM jobs", buf, sizeof buf) == SQLITE_OK &&
              !strcmp(buf, "1"), "committed: another connection sees the job (%s)", buf);
    CHECK(submit(s, 2, 101, &outcome, NULL) == STORE_OK && outcome == 1, "submit 2");
    CHECK(submit(s, 3, 102, &outcome, NULL) == STORE_OK && outcome == 1, "submit 3");
    CHECK(submit(s, 1, 103, &outcome, &j) == STORE_OK && outcome == 0 && j.seq == 1 &&
              j.created_at == 100.5, "submit existing queued: outcome %d", outcome);
    store_job_clear(&j);

    /* claims in submission order, with the request text */
    CHECK(store_claim_next(s, 200, &j) == STORE_OK && j.seq == 1 && j.state == STORE_RUNNING &&
              j.attempts == 1 && j.started_at == 200 && j.request != NULL &&
              !strcmp(j.request, "{\"job\":1}") && j.request_len == 9,
          "claim 1 (seq %lld, request %s)", j.seq, j.request ? j.request : "(null)");
    store_job_clear(&j);
    CHECK(store_claim_next(s, 201, &j) == STORE_OK && j.seq == 2, "claim 2 (seq %lld)", j.seq);
    store_job_clear(&j);
    CHECK(submit(s, 1, 104, &outcome, &j) == STORE_OK && outcome == 0 && j.state == STORE_RUNNING,
          "submit existing running: outcome %d", outcome);
    store_job_clear(&j);

    /* finish 1 done with a 1 MB result and a CSV; read back byte-exactly */
    size_t rlen = 1u << 20, clen = 100000;
    char *res = malloc(rlen + 1), *csv = malloc(clen + 1);
    CHECK(res && csv, "alloc");
    if (!res || !csv) {
        free(res);
        free(csv);
        return;
    }
    for (size_t i = 0; i < rlen; i++)
        res[i] = (char)(' ' + (i * 7919u) % 95);   /* printable, NUL-free */
    res[rlen] = '\0';
    for (size_t i = 0; i < clen; i++)
        csv[i] = i % 20 == 19 ? '\n' : (char)('0' + i % 10);
    csv[clen] = '\0';
    make_id(1, id);
    CHECK(store_finish(s, id, STORE_DONE, 300, 11, NULL, res, rlen, csv, clen) == STORE_OK,
          "finish 1 done");
    CHECK(store_get(s, id, STORE_WITH_RESULT | STORE_WITH_CSV | STORE_WITH_REQUEST, &j) == STORE_OK &&
              j.state == STORE_DONE && j.speeds_done == 11 && j.finished_at == 300 && j.has_result &&
              j.result_len == rlen && j.result && !memcmp(j.result, res, rlen) &&
              j.result[rlen] == '\0' && j.csv_len == clen && j.result_csv &&
              !memcmp(j.result_csv, csv, clen) && j.request && j.error == NULL,
          "result and csv read back byte-exactly (%zu, %zu bytes)", j.result_len, j.csv_len);
    store_job_clear(&j);
    CHECK(store_get(s, id, STORE_WITH_CSV, &j) == STORE_OK && j.has_result && j.result == NULL &&
              j.request == NULL && j.result_csv && j.csv_len == clen,
          "flags choose the texts loaded");
    store_job_clear(&j);
    CHECK(store_get(s, id, 0, &j) == STORE_OK && j.has_result && j.result == NULL &&
              j.result_csv == NULL, "has_result without loading it");
    store_job_clear(&j);
    CHECK(store_finish(s, id, STORE_DONE, 301, 11, NULL, "{}", 2, NULL, 0) == STORE_CONFLICT,
          "finish of a done job");
    make_id(3, id);
    CHECK(store_finish(s, id, STORE_DONE, 301, 11, NULL, "{}", 2, NULL, 0) == STORE_CONFLICT,
          "finish of a queued job");
    make_id(99, id);
    CHECK(store_finish(s, id, STORE_DONE, 301, 11, NULL, "{}", 2, NULL, 0) == STORE_NOT_FOUND,
          "finish of an unknown job");
    CHECK(submit(s, 1, 105, &outcome, &j) == STORE_OK && outcome == 0 && j.state == STORE_DONE &&
              j.has_result, "submit existing done: outcome %d", outcome);
    store_job_clear(&j);
    free(res);
    free(csv);

    /* finish 2 failed with an error; resubmission queues it last */
    const char *err = "{\"type\":\"timeout\",\"title\":\"time limit\"}";
    make_id(2, id);
    CHECK(store_finish(s, id, STORE_FAILED, 310, 4, err, NULL, 0, NULL, 0) == STORE_OK,
          "finish 2 failed");
    CHECK(store_get(s, id, STORE_WITH_RESULT, &j) == STORE_OK && j.state == STORE_FAILED &&
              !j.has_result && j.result == NULL && j.error && !strcmp(j.error, err) &&
              j.speeds_done == 4, "failed job with its error");
    store_job_clear(&j);
    CHECK(submit(s, 2, 400, &outcome, &j) == STORE_OK && outcome == 2 && j.state == STORE_QUEUED &&
              j.seq == 4 && j.attempts == 0 && j.speeds_done == 0 && j.error == NULL &&
              j.started_at == 0 && j.finished_at == 0 && j.created_at == 101 && !j.has_result,
          "resubmit failed: outcome %d seq %lld created %.1f", outcome, j.seq, j.created_at);
    store_job_clear(&j);

    /* cancel: queued 2 → canceled; resubmit it; running → flag; done → conflict */
    CHECK(store_cancel(s, id, 410, &state) == STORE_OK && state == STORE_CANCELED, "cancel queued");
    CHECK(store_get(s, id, 0, &j) == STORE_OK && j.state == STORE_CANCELED && j.finished_at == 410,
          "canceled job");
    store_job_clear(&j);
    CHECK(store_cancel(s, id, 411, &state) == STORE_CONFLICT && state == STORE_CANCELED,
          "cancel canceled");
    CHECK(submit(s, 2, 420, &outcome, &j) == STORE_OK && outcome == 2 && j.seq == 5 &&
              j.state == STORE_QUEUED, "resubmit canceled: outcome %d seq %lld", outcome, j.seq);
    store_job_clear(&j);
    CHECK(store_claim_next(s, 430, &j) == STORE_OK && j.seq == 3, "claim 3 before resubmitted 2");
    store_job_clear(&j);
    make_id(3, id);
    CHECK(store_cancel(s, id, 440, &state) == STORE_OK && state == STORE_RUNNING,
          "cancel running stays running");
    CHECK(store_get(s, id, 0, &j) == STORE_OK && j.state == STORE_RUNNING && j.cancel_requested &&
              j.finished_at == 0, "cancel_requested set");
    store_job_clear(&j);
    make_id(1, id);
    CHECK(store_cancel(s, id, 450, &state) == STORE_CONFLICT && state == STORE_DONE, "cancel done");
    make_id(99, id);
    CHECK(store_cancel(s, id, 450, &state) == STORE_NOT_FOUND, "cancel unknown");
    make_id(3, id);
    CHECK(store_finish(s, id, STORE_CANCELED, 460, 2, NULL, NULL, 0, NULL, 0) == STORE_OK,
          "worker finishes the canceled job");
    CHECK(store_get(s, id, 0, &j) == STORE_OK && j.state == STORE_CANCELED && j.cancel_requested,
          "canceled after the request");
    store_job_clear(&j);

    /* requeue: 4 then 2 queued; claim 2, requeue it, it runs first again */
    CHECK(submit(s, 4, 500, &outcome, NULL) == STORE_OK && outcome == 1, "submit 4");
    CHECK(store_claim_next(s, 510, &j) == STORE_OK && j.seq == 5 && j.attempts == 1, "claim 2");
    store_job_clear(&j);
    make_id(2, id);
    CHECK(store_requeue(s, id) == STORE_OK, "requeue running");
    CHECK(store_get(s, id, 0, &k) == STORE_OK && k.state == STORE_QUEUED && k.attempts == 0 &&
              k.started_at == 0 && k.seq == 5, "requeued: queued, attempts back to 0, seq kept");
    store_job_clear(&k);
    CHECK(store_requeue(s, id) == STORE_CONFLICT, "requeue queued");
    make_id(99, id);
    CHECK(store_requeue(s, id) == STORE_NOT_FOUND, "requeue unknown");
    CHECK(store_claim_next(s, 520, &j) == STORE_OK && j.seq == 5, "requeued job first");
    store_job_clear(&j);

    /* now: 1 done, 2 running (seq 5), 3 canceled, 4 queued (seq 6) */
    CHECK(store_count(s, counts) == STORE_OK && counts[STORE_QUEUED] == 1 &&
              counts[STORE_RUNNING] == 1 && counts[STORE_DONE] == 1 && counts[STORE_FAILED] == 0 &&
              counts[STORE_CANCELED] == 1,
          "count %lld %lld %lld %lld %lld", counts[0], counts[1], counts[2], counts[3], counts[4]);
    CHECK(store_check_writable(s) == STORE_OK, "writable");
}

/* Newest first, pages through before/more, state filter. */
static void test_list(store *s)
{
    store_job page[4];
    long long seen[32];
    int n = -1, more = -1, total = 0, outcome;
    long long before = 0;

    /* add 7 … 16 (ten jobs, seq 7 … 16); cancel the even ones */
    for (unsigned i = 7; i <= 16; i++) {
        char id[65];
        CHECK(submit(s, i, 600 + i, &outcome, NULL) == STORE_OK && outcome == 1, "submit %u", i);
        make_id(i, id);
        if (i % 2 == 0)
            CHECK(store_cancel(s, id, 700, NULL) == STORE_OK, "cancel %u", i);
    }
    memset(page, 0, sizeof page);
    /* all 14 jobs (1 … 4, 7 … 16), 4 at a time: 4 + 4 + 4 + 2 */
    for (int p = 0; p < 5; p++) {
        CHECK(store_list(s, before, -1, 4, page, &n, &more) == STORE_OK, "list page %d", p);
        for (int i = 0; i < n && total < 32; i++)
            seen[total++] = page[i].seq;
        if (n > 0)
            before = page[n - 1].seq;
        for (int i = 0; i < n; i++)
            store_job_clear(&page[i]);
        if (!more)
            break;
    }
    CHECK(total == 14, "14 jobs listed, got %d", total);
    int desc = 1;
    for (int i = 1; i < total; i++)
        desc = desc && seen[i] < seen[i - 1];
    CHECK(desc && total > 0 && seen[0] == 16 && seen[total - 1] == 1, "newest first, 16 … 1");
    CHECK(store_list(s, 0, -1, 4, page, &n, &more) == STORE_OK && n == 4 && more == 1 &&
              page[0].seq == 16 && page[3].seq == 13 && page[0].request == NULL &&
              page[0].state == STORE_CANCELED && page[1].state == STORE_QUEUED &&
              page[0].name && !strcmp(page[0].name, "job \"16\"") && page[1].name == NULL,
          "first page, with the name of job 16: %s", page[0].name ? page[0].name : "(none)");
    for (int i = 0; i < n; i++)
        store_job_clear(&page[i]);
    CHECK(store_list(s, 5, -1, 4, page, &n, &more) == STORE_OK && n == 2 && more == 0 &&
              page[0].seq == 3 && page[1].seq == 1, "last page before 5: n %d more %d", n, more);
    for (int i = 0; i < n; i++)
        store_job_clear(&page[i]);
    CHECK(store_list(s, 0, STORE_CANCELED, 4, page, &n, &more) == STORE_OK && n == 4 &&
              more == 1 && page[0].seq == 16 && page[3].seq == 10,
          "canceled filter: n %d first %lld", n, page[0].seq);
    for (int i = 0; i < n; i++)
        store_job_clear(&page[i]);
    CHECK(store_list(s, 10, STORE_CANCELED, 4, page, &n, &more) == STORE_OK && n == 2 &&
              more == 0 && page[0].seq == 8 && page[1].seq == 3, "canceled, before 10");
    for (int i = 0; i < n; i++)
        store_job_clear(&page[i]);
    CHECK(store_list(s, 0, STORE_DONE, 4, page, &n, &more) == STORE_OK && n == 1 && more == 0 &&
              page[0].seq == 1 && page[0].has_result && page[0].result == NULL, "done filter");
    for (int i = 0; i < n; i++)
        store_job_clear(&page[i]);
    CHECK(store_list(s, 0, STORE_FAILED, 4, page, &n, &more) == STORE_OK && n == 0 && more == 0,
          "failed filter: none");
    CHECK(store_list(s, 0, -1, 0, NULL, &n, &more) == STORE_OK && n == 0 && more == 1,
          "max 0 still says more");
}

/* Close with a job running (then one more with a cancel request), reopen. */
static void test_reopen(const char *path)
{
    store *s = NULL;
    store_job j;
    char id[65], err[256];
    int requeued = -1;
    long long counts[STORE_N_STATES];

    CHECK(store_open(&s, path, &requeued, err, sizeof err) == STORE_OK && s, "reopen: %s", err);
    if (s == NULL)
        return;
    /* job 2 (seq 5) was left running; claim 4 and ask to cancel it too */
    CHECK(requeued == 1, "requeued 1 at reopen, got %d", requeued);
    make_id(2, id);
    CHECK(store_get(s, id, 0, &j) == STORE_OK && j.state == STORE_QUEUED && j.started_at == 0 &&
              j.attempts == 1, "left running → queued, attempts kept (state %d, attempts %d)",
          (int)j.state, j.attempts);
    store_job_clear(&j);
    CHECK(store_claim_next(s, 800, &j) == STORE_OK && j.seq == 5 && j.attempts == 2,
          "requeued job claimed first");
    store_job_clear(&j);
    CHECK(store_claim_next(s, 801, &j) == STORE_OK && j.seq == 6, "then job 4");
    store_job_clear(&j);
    make_id(4, id);
    CHECK(store_cancel(s, id, 802, NULL) == STORE_OK, "cancel running 4");
    store_close(s);
    s = NULL;

    /* a "crash" with both running: both requeued, 4 keeps its cancel request */
    CHECK(store_open(&s, path, &requeued, err, sizeof err) == STORE_OK && s, "reopen 2: %s", err);
    if (s == NULL)
        return;
    CHECK(requeued == 2, "requeued 2, got %d", requeued);
    CHECK(store_get(s, id, 0, &j) == STORE_OK && j.state == STORE_QUEUED && j.cancel_requested &&
              j.finished_at == 0 && j.started_at == 0,
          "running with cancel requested → queued, request kept (state %d)", (int)j.state);
    store_job_clear(&j);
    CHECK(store_count(s, counts) == STORE_OK && counts[STORE_RUNNING] == 0 &&
              counts[STORE_QUEUED] == 7 && counts[STORE_CANCELED] == 6,
          "counts after reopen: %lld queued %lld canceled", counts[0], counts[4]);
    CHECK(store_claim_next(s, 900, &j) == STORE_OK && j.seq == 5 && j.attempts == 3 &&
              !j.cancel_requested, "2 first, third attempt");
    store_job_clear(&j);
    CHECK(store_claim_next(s, 901, &j) == STORE_OK && j.seq == 6 && j.cancel_requested,
          "4 is handed out with its cancel request");
    store_job_clear(&j);
    CHECK(store_cancel(s, id, 902, NULL) == STORE_OK, "cancel requested again");
    CHECK(store_finish(s, id, STORE_CANCELED, 903, 0, NULL, NULL, 0, NULL, 0) == STORE_OK,
          "worker cancels 4");
    make_id(2, id);
    CHECK(store_requeue(s, id) == STORE_OK, "graceful stop requeues 2");
    CHECK(store_schema_version(s) == 1, "schema version kept");
    store_close(s);
}

/* Files that must be refused with a sentence. */
static void test_refused(const char *dir)
{
    store *s = (store *)&s;
    char path[600], err[256];
    int requeued = -1;
    FILE *f;

    snprintf(path, sizeof path, "%s/newer.db", dir);
    CHECK(raw_exec(path, "CREATE TABLE t (x); PRAGMA user_version = 999;") == SQLITE_OK, "newer db");
    CHECK(store_open(&s, path, &requeued, err, sizeof err) == STORE_ERROR && s == NULL &&
              requeued == 0, "newer schema refused");
    CHECK(strstr(err, "database schema version 999 is newer than this spinmodald (1)") != NULL,
          "newer schema sentence: '%s'", err);
    remove_db(path);

    snprintf(path, sizeof path, "%s/text.db", dir);
    f = fopen(path, "w");
    CHECK(f != NULL, "create text file");
    if (f) {
        for (int i = 0; i < 200; i++)
            fputs("this is not a database\n", f);
        fclose(f);
    }
    s = (store *)&s;
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_CORRUPT && s == NULL,
          "text file refused as corrupt (SQLITE_NOTADB)");
    CHECK(strstr(err, "is not a SQLite database") != NULL, "not-a-database sentence: '%s'", err);
    remove_db(path);

    snprintf(path, sizeof path, "%s/short.db", dir);
    f = fopen(path, "w");
    if (f) {
        fputs("hello", f);
        fclose(f);
    }
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_CORRUPT && s == NULL,
          "5-byte file refused as corrupt (SQLITE_NOTADB)");
    CHECK(strstr(err, "is not a SQLite database") != NULL, "short file sentence: '%s'", err);
    remove_db(path);

    snprintf(path, sizeof path, "%s/other.db", dir);
    CHECK(raw_exec(path, "CREATE TABLE jobs (x);") == SQLITE_OK, "other app's db");
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_ERROR && s == NULL,
          "foreign database refused");
    CHECK(strstr(err, "not a spinmodal") != NULL, "foreign sentence: '%s'", err);
    remove_db(path);

    snprintf(path, sizeof path, "%s/no/such/dir/x.db", dir);
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_ERROR && s == NULL,
          "missing directory refused");
    CHECK(strstr(err, "cannot open database") != NULL, "open sentence: '%s'", err);
    CHECK(store_open(&s, path, NULL, NULL, 0) == STORE_ERROR, "err may be NULL");
    CHECK(store_open(&s, ":memory:", NULL, err, sizeof err) == STORE_ERROR && s == NULL &&
              strstr(err, "cannot use WAL") != NULL, "in-memory database refused: '%s'", err);
}

typedef struct claimer {
    store *s;
    int claimed[N_CONC];   /* job n - 1000 claimed this many times by this thread */
    int n;
    int errors;
} claimer;

static void *claim_loop(void *arg)
{
    claimer *c = arg;
    store_job j;
    int rc;

    while ((rc = store_claim_next(c->s, 900, &j)) == STORE_OK) {
        unsigned n = (unsigned)strtoul(j.id, NULL, 16);
        if (n >= 1000 && n < 1000 + N_CONC)
            c->claimed[n - 1000]++;
        else
            c->errors++;
        c->n++;
        store_job_clear(&j);
    }
    if (rc != STORE_NOT_FOUND)
        c->errors++;
    return NULL;
}

typedef struct reader {
    store *s;
    int reads;
    int errors;
} reader;

static void *read_loop(void *arg)
{
    reader *r = arg;
    store_job j, page[5];
    char id[65];
    int n, more;

    memset(page, 0, sizeof page);
    for (int i = 0; i < 300; i++) {
        make_id(1000u + (unsigned)(i % N_CONC), id);
        if (store_get(r->s, id, STORE_WITH_REQUEST, &j) != STORE_OK || j.request == NULL)
            r->errors++;
        store_job_clear(&j);
        if (store_list(r->s, 0, -1, 5, page, &n, &more) != STORE_OK || n != 5)
            r->errors++;
        for (int k = 0; k < n; k++)
            store_job_clear(&page[k]);
        r->reads++;
    }
    return NULL;
}

/* 4 threads claim 200 jobs while 2 threads read: each claimed exactly once. */
static void test_concurrent(const backend *b)
{
    store *s = NULL;
    char path[600], err[256];
    pthread_t tc[N_CLAIMERS], tr[N_READERS];
    claimer *cl = calloc(N_CLAIMERS, sizeof *cl);
    reader rd[N_READERS];
    int outcome, started_c = 0, started_r = 0, total = 0, once = 1, errors = 0;
    long long counts[STORE_N_STATES];

    CHECK(fresh_db(b, "conc", path, sizeof path) == 0, "fresh database conc");
    CHECK(cl != NULL, "alloc");
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_OK, "open: %s", err);
    if (s == NULL || cl == NULL) {
        free(cl);
        store_close(s);
        return;
    }
    for (unsigned i = 0; i < N_CONC; i++)
        CHECK(submit(s, 1000 + i, 1000 + i, &outcome, NULL) == STORE_OK && outcome == 1,
              "submit %u", i);
    for (int t = 0; t < N_READERS; t++) {
        rd[t] = (reader){s, 0, 0};
        if (pthread_create(&tr[t], NULL, read_loop, &rd[t]) == 0)
            started_r++;
    }
    for (int t = 0; t < N_CLAIMERS; t++) {
        cl[t].s = s;
        if (pthread_create(&tc[t], NULL, claim_loop, &cl[t]) == 0)
            started_c++;
    }
    CHECK(started_c == N_CLAIMERS && started_r == N_READERS, "threads started");
    for (int t = 0; t < started_c; t++)
        pthread_join(tc[t], NULL);
    for (int t = 0; t < started_r; t++)
        pthread_join(tr[t], NULL);
    for (int i = 0; i < N_CONC; i++) {
        int c = 0;
        for (int t = 0; t < N_CLAIMERS; t++)
            c += cl[t].claimed[i];
        once = once && c == 1;
    }
    for (int t = 0; t < N_CLAIMERS; t++) {
        total += cl[t].n;
        errors += cl[t].errors;
        printf("claimer %d: %d jobs\n", t, cl[t].n);
    }
    for (int t = 0; t < N_READERS; t++)
        errors += rd[t].errors;
    CHECK(total == N_CONC && once && errors == 0, "each job claimed once: total %d, errors %d",
          total, errors);
    CHECK(store_count(s, counts) == STORE_OK && counts[STORE_RUNNING] == N_CONC &&
              counts[STORE_QUEUED] == 0, "all running");
    CHECK(store_check_writable(s) == STORE_OK, "writable after the run");
    store_close(s);
    free(cl);
    if (!b->pg)
        remove_db(path);
}


/* ---- the calls of several replicas, on either backend --------------------- */

/* A cancel asked through one handle (another replica's, on PostgreSQL) is
 * seen by the worker of the job through store_cancel_requested and
 * store_state_of. */
static void test_cancel_seen(const backend *b)
{
    store *s = NULL, *other = NULL;
    store_job j;
    store_state state = STORE_DONE;
    char path[600], err[256], id[65];
    int flag = -1, outcome;

    CHECK(fresh_db(b, "cancelseen", path, sizeof path) == 0, "fresh database cancelseen");
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_OK, "open: %s", err);
    if (s == NULL)
        return;
    other = s;   /* SQLite: one store per file; the same handle plays both parts */
    if (b->pg)
        CHECK(store_open(&other, path, NULL, err, sizeof err) == STORE_OK, "second: %s", err);
    if (other == NULL) {
        store_close(s);
        return;
    }
    make_id(7000, id);
    CHECK(store_cancel_requested(s, id, &flag) == STORE_NOT_FOUND && flag == 0,
          "cancel_requested of an unknown job");
    CHECK(store_state_of(s, id, &state) == STORE_NOT_FOUND, "state_of an unknown job");
    CHECK(submit(s, 7000, 10, &outcome, NULL) == STORE_OK && outcome == 1, "submit");
    CHECK(store_state_of(other, id, &state) == STORE_OK && state == STORE_QUEUED, "state queued");
    CHECK(store_claim_next(s, 20, &j) == STORE_OK && !strcmp(j.id, id), "claim");
    if (b->pg)
        CHECK(!strcmp(j.owner, store_owner(s)) && j.lease_until == 20 + 30,
              "claim stamps owner '%s' and lease %.1f", j.owner, j.lease_until);
    else
        CHECK(j.owner[0] == '\0' && j.lease_until == 0, "SQLite stores no owner or lease");
    store_job_clear(&j);
    CHECK(store_cancel_requested(s, id, &flag) == STORE_OK && flag == 0, "not asked yet");
    CHECK(store_cancel(other, id, 30, &state) == STORE_OK && state == STORE_RUNNING,
          "cancel through the other replica");
    CHECK(store_cancel_requested(s, id, &flag) == STORE_OK && flag == 1, "the worker sees it");
    CHECK(store_state_of(other, id, &state) == STORE_OK && state == STORE_RUNNING,
          "still running");
    CHECK(store_renew_lease(s, id, store_owner(s), 40, 30) == STORE_OK, "heartbeat while running");
    CHECK(store_finish(s, id, STORE_CANCELED, 50, 0, NULL, NULL, 0, NULL, 0) == STORE_OK,
          "the worker finishes it canceled");
    CHECK(store_state_of(other, id, &state) == STORE_OK && state == STORE_CANCELED,
          "state_of canceled");
    CHECK(store_renew_lease(s, id, store_owner(s), 60, 30) == STORE_CONFLICT,
          "no heartbeat for an ended job");
    make_id(7001, id);
    CHECK(store_renew_lease(s, id, store_owner(s), 60, 30) == STORE_NOT_FOUND,
          "no heartbeat for an unknown job");
    CHECK(store_renew_lease(s, id, NULL, 60, 30) == STORE_INVALID, "owner required");
    CHECK(store_renew_lease(s, id, "x", 60, 0) == STORE_INVALID, "lease > 0 required");
    CHECK(store_requeue_expired(s, 1e12, 0, NULL, NULL) == STORE_INVALID, "max_attempts >= 1");
    if (other != s)
        store_close(other);
    store_close(s);
    if (!b->pg)
        remove_db(path);
}

/* SQLite: nothing expires (one process); renewals only check the state. */
static void test_lease_sqlite(const backend *b)
{
    store *s = NULL;
    store_job j;
    char path[600], err[256], id[65];
    int requeued = -1, failed = -1, outcome;

    CHECK(fresh_db(b, "lease", path, sizeof path) == 0, "fresh database lease");
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_OK, "open: %s", err);
    if (s == NULL)
        return;
    CHECK(store_owner(s) != NULL && store_owner(s)[0] != '\0', "an owner id: '%s'", store_owner(s));
    CHECK(submit(s, 8000, 10, &outcome, NULL) == STORE_OK, "submit");
    make_id(8000, id);
    CHECK(store_renew_lease(s, id, store_owner(s), 11, 30) == STORE_CONFLICT, "queued: conflict");
    CHECK(store_claim_next(s, 20, &j) == STORE_OK, "claim");
    store_job_clear(&j);
    CHECK(store_renew_lease(s, id, "anyone", 1e9, 30) == STORE_OK, "running: ok, owner unused");
    CHECK(store_requeue_expired(s, 1e12, 1, &requeued, &failed) == STORE_OK && requeued == 0 &&
              failed == 0, "nothing expires on SQLite");
    CHECK(store_get(s, id, 0, &j) == STORE_OK && j.state == STORE_RUNNING, "still running");
    store_job_clear(&j);
    store_close(s);
    remove_db(path);
}

/* ---- PostgreSQL only ------------------------------------------------------- */

/* Opens that must be refused with a sentence, or fail fast. */
static void test_refused_pg(const backend *b)
{
    store *s = (store *)&s;
    char dsn[256], path[600], err[512];
    double t;
    int port = pg_free_port(), rc;

    CHECK(store_open(&s, "postgresql://127.0.0.1/x?nosuchparam=1", NULL, err, sizeof err) ==
              STORE_INVALID && s == NULL && strstr(err, "invalid PostgreSQL URI") != NULL,
          "bad URI refused: '%s'", err);
    snprintf(dsn, sizeof dsn, "postgresql://postgres:sekrit@127.0.0.1:%d/x", port);
    t = mono();
    rc = store_open(&s, dsn, NULL, err, sizeof err);
    t = mono() - t;
    CHECK(rc == STORE_UNAVAILABLE && s == NULL, "nothing listening: unavailable (%s)",
          store_rc_name(rc));
    CHECK(strstr(err, "cannot connect to PostgreSQL database 127.0.0.1:") != NULL &&
              strstr(err, "sekrit") == NULL, "unreachable sentence without the password: '%s'",
          err);
    CHECK(t < 3.0, "refused quickly: %.3f s", t);
    CHECK(store_is_db_error(STORE_UNAVAILABLE) && !strcmp(store_rc_name(STORE_UNAVAILABLE),
                                                          "unavailable"), "unavailable kind");

    CHECK(fresh_db(b, "newer", path, sizeof path) == 0, "fresh database newer");
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_OK, "open newer: %s", err);
    store_close(s);
    CHECK(pg_raw(path, "UPDATE spinmodal_schema SET version = 999", NULL, 0) == 0, "bump version");
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_ERROR && s == NULL &&
              strstr(err, "database schema version 999 is newer than this spinmodald (1)"),
          "newer schema refused: '%s'", err);

    CHECK(fresh_db(b, "foreign_app", path, sizeof path) == 0, "fresh database foreign_app");
    CHECK(pg_raw(path, "CREATE TABLE jobs (x integer)", NULL, 0) == 0, "foreign table");
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_ERROR && s == NULL &&
              strstr(err, "not a spinmodal one"), "foreign database refused: '%s'", err);
}

typedef struct opener {
    const char *dsn;
    int rc;
    int version;
    char err[256];
} opener;

static void *open_loop(void *arg)
{
    opener *o = arg;
    store *s = NULL;

    o->rc = store_open(&s, o->dsn, NULL, o->err, sizeof o->err);
    if (s != NULL) {
        o->version = store_schema_version(s);
        store_close(s);
    }
    return NULL;
}

/* Six replicas start together on a fresh database: one migrates. */
static void test_open_together(const backend *b)
{
    enum { N = 6 };
    pthread_t t[N];
    opener o[N];
    char path[600], buf[32];
    int ok = 0;

    CHECK(fresh_db(b, "together", path, sizeof path) == 0, "fresh database together");
    for (int i = 0; i < N; i++) {
        memset(&o[i], 0, sizeof o[i]);
        o[i].dsn = path;
        o[i].rc = -100;
        if (pthread_create(&t[i], NULL, open_loop, &o[i]) != 0)
            o[i].dsn = NULL;
    }
    for (int i = 0; i < N; i++) {
        if (o[i].dsn)
            pthread_join(t[i], NULL);
        ok += o[i].rc == STORE_OK && o[i].version == 1;
        if (o[i].rc != STORE_OK)
            printf("opener %d: %s: %s\n", i, store_rc_name(o[i].rc), o[i].err);
    }
    CHECK(ok == N, "%d of %d opened at version 1", ok, N);
    CHECK(pg_raw(path, "SELECT count(*) FROM spinmodal_schema", buf, sizeof buf) == 0 &&
              !strcmp(buf, "1"), "one schema row: %s", buf);
}

enum { N_REPL = 400 };

typedef struct replica_claimer {
    store *s;
    unsigned base;
    int *claimed;          /* shared [N_REPL], updated under lock */
    pthread_mutex_t *lock;
    int n;
    int errors;
} replica_claimer;

static void *replica_claim_loop(void *arg)
{
    replica_claimer *c = arg;
    store_job j;
    int rc;

    while ((rc = store_claim_next(c->s, 5000, &j)) == STORE_OK) {
        unsigned n = (unsigned)strtoul(j.id, NULL, 16);
        if (n >= c->base && n < c->base + N_REPL && !strcmp(j.owner, store_owner(c->s))) {
            pthread_mutex_lock(c->lock);
            c->claimed[n - c->base]++;
            pthread_mutex_unlock(c->lock);
        } else {
            c->errors++;
        }
        c->n++;
        store_job_clear(&j);
    }
    if (rc != STORE_NOT_FOUND)
        c->errors++;
    return NULL;
}

/* Claim N_REPL jobs (ids base …) with nthreads threads over the handles
 * hs[t % nh]; returns claims per second, checks each job claimed once. */
static double claim_all(store **hs, int nh, int nthreads, unsigned base, const char *what)
{
    pthread_t t[8];
    replica_claimer c[8];
    pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
    int *claimed = calloc(N_REPL, sizeof *claimed), outcome, once = 1, total = 0, errors = 0;
    int per_handle[2] = {0, 0};
    double t0, secs;

    if (claimed == NULL)
        return 0;
    for (unsigned i = 0; i < N_REPL; i++)
        CHECK(submit(hs[i % (unsigned)nh], base + i, 1000 + i, &outcome, NULL) == STORE_OK &&
                  outcome == 1, "submit %u", base + i);
    t0 = mono();
    for (int i = 0; i < nthreads; i++) {
        c[i] = (replica_claimer){hs[i % nh], base, claimed, &lock, 0, 0};
        if (pthread_create(&t[i], NULL, replica_claim_loop, &c[i]) != 0)
            c[i].s = NULL;
    }
    for (int i = 0; i < nthreads; i++) {
        if (c[i].s != NULL)
            pthread_join(t[i], NULL);
        total += c[i].n;
        errors += c[i].errors;
        per_handle[i % nh] += c[i].n;
    }
    secs = mono() - t0;
    for (int i = 0; i < N_REPL; i++)
        once = once && claimed[i] == 1;
    CHECK(total == N_REPL && once && errors == 0,
          "%s: each job claimed once: total %d, errors %d", what, total, errors);
    if (nh == 2)
        CHECK(per_handle[0] > 0 && per_handle[1] > 0, "%s: both replicas claimed (%d, %d)", what,
              per_handle[0], per_handle[1]);
    printf("%s: %d claims in %.3f s = %.0f claims/s (per handle: %d, %d)\n", what, total, secs,
           total / secs, per_handle[0], per_handle[1]);
    free(claimed);
    return total / secs;
}

typedef struct racer {
    store *s;
    int inserted;
    int errors;
} racer;

static void *submit_race(void *arg)
{
    racer *r = arg;
    int outcome;

    for (unsigned i = 0; i < 100; i++) {
        if (submit(r->s, 90000 + i, 1, &outcome, NULL) != STORE_OK)
            r->errors++;
        else
            r->inserted += outcome == 1;
    }
    return NULL;
}

/* Two replicas (handles) claiming and submitting at once. */
static void test_replicas(const backend *b)
{
    store *s[2] = {NULL, NULL};
    pthread_t t[2];
    racer r[2];
    char path[600], err[256];
    long long counts[STORE_N_STATES];

    CHECK(fresh_db(b, "replicas", path, sizeof path) == 0, "fresh database replicas");
    for (int i = 0; i < 2; i++)
        CHECK(store_open(&s[i], path, NULL, err, sizeof err) == STORE_OK, "replica %d: %s", i, err);
    if (s[0] == NULL || s[1] == NULL) {
        store_close(s[0]);
        store_close(s[1]);
        return;
    }
    CHECK(strcmp(store_owner(s[0]), store_owner(s[1])) != 0, "owners differ: %s, %s",
          store_owner(s[0]), store_owner(s[1]));
    claim_all(s, 1, 1, 10000, "one handle, 1 thread");
    claim_all(s, 1, 2, 20000, "one handle, 2 threads");
    claim_all(s, 2, 2, 30000, "two handles, 1 thread each");
    claim_all(s, 2, 4, 40000, "two handles, 2 threads each");

    /* the same 100 new ids submitted by both replicas at once: one insert each */
    for (int i = 0; i < 2; i++) {
        r[i] = (racer){s[i], 0, 0};
        if (pthread_create(&t[i], NULL, submit_race, &r[i]) != 0)
            r[i].s = NULL;
    }
    for (int i = 0; i < 2; i++)
        if (r[i].s)
            pthread_join(t[i], NULL);
    CHECK(r[0].inserted + r[1].inserted == 100 && r[0].errors + r[1].errors == 0,
          "racing submissions: %d + %d inserted, %d errors", r[0].inserted, r[1].inserted,
          r[0].errors + r[1].errors);
    CHECK(store_count(s[1], counts) == STORE_OK && counts[STORE_QUEUED] == 100 &&
              counts[STORE_RUNNING] == 4 * N_REPL, "shared counts: %lld queued, %lld running",
          counts[STORE_QUEUED], counts[STORE_RUNNING]);
    store_close(s[0]);
    store_close(s[1]);
}

/* Leases: renewal, expiry, the owner's exclusive finish, the attempt limit. */
static void test_lease_pg(const backend *b)
{
    store *a = NULL, *c = NULL;
    store_settings set;
    store_job j;
    char path[600], err[256], id[65];
    int requeued = -1, failed = -1, outcome, flag = 0;

    CHECK(fresh_db(b, "lease", path, sizeof path) == 0, "fresh database lease");
    store_default_settings(&set);
    set.path = path;
    set.owner = "replica-a";
    set.lease_s = 30;
    CHECK(store_open_with(&a, &set, NULL, err, sizeof err) == STORE_OK, "open a: %s", err);
    set.owner = "replica-c";
    CHECK(store_open_with(&c, &set, NULL, err, sizeof err) == STORE_OK, "open c: %s", err);
    if (a == NULL || c == NULL) {
        store_close(a);
        store_close(c);
        return;
    }
    CHECK(!strcmp(store_owner(a), "replica-a"), "owner from the settings");
    make_id(8100, id);
    CHECK(submit(a, 8100, 1000, &outcome, NULL) == STORE_OK, "submit");
    CHECK(store_claim_next(a, 1000, &j) == STORE_OK && j.lease_until == 1030 &&
              !strcmp(j.owner, "replica-a") && j.attempts == 1, "a claims until 1030");
    store_job_clear(&j);
    CHECK(store_requeue_expired(c, 1020, 3, &requeued, &failed) == STORE_OK && requeued == 0 &&
              failed == 0, "not expired at 1020");
    CHECK(store_renew_lease(a, id, "replica-a", 1025, 30) == STORE_OK, "a renews at 1025");
    CHECK(store_get(c, id, 0, &j) == STORE_OK && j.lease_until == 1055, "lease until 1055: %.1f",
          j.lease_until);
    store_job_clear(&j);
    CHECK(store_renew_lease(c, id, "replica-c", 1026, 30) == STORE_CONFLICT,
          "c cannot renew a's job");
    CHECK(store_requeue_expired(c, 1050, 3, &requeued, &failed) == STORE_OK && requeued == 0,
          "renewed: not expired at 1050");
    /* a stops renewing (its replica died): c puts the job back at 1060 */
    CHECK(store_cancel(c, id, 1058, NULL) == STORE_OK, "a cancel is asked meanwhile");
    CHECK(store_requeue_expired(c, 1060, 3, &requeued, &failed) == STORE_OK && requeued == 1 &&
              failed == 0, "expired at 1060: requeued %d failed %d", requeued, failed);
    CHECK(store_get(c, id, 0, &j) == STORE_OK && j.state == STORE_QUEUED && j.owner[0] == '\0' &&
              j.lease_until == 0 && j.started_at == 0 && j.attempts == 1 && j.cancel_requested,
          "queued again, attempts and cancel request kept (state %s)", store_state_name(j.state));
    store_job_clear(&j);
    CHECK(store_renew_lease(a, id, "replica-a", 1061, 30) == STORE_CONFLICT,
          "a's late heartbeat: lease lost");
    CHECK(store_claim_next(c, 1070, &j) == STORE_OK && !strcmp(j.owner, "replica-c") &&
              j.attempts == 2 && j.cancel_requested, "c claims it, with the cancel request");
    store_job_clear(&j);
    CHECK(store_finish(a, id, STORE_DONE, 1071, 11, NULL, "{}", 2, NULL, 0) == STORE_CONFLICT,
          "a's late finish is refused");
    CHECK(store_requeue(a, id) == STORE_CONFLICT, "a cannot requeue c's job");
    CHECK(store_cancel_requested(c, id, &flag) == STORE_OK && flag == 1, "c sees the cancel");
    CHECK(store_finish(c, id, STORE_CANCELED, 1072, 0, NULL, NULL, 0, NULL, 0) == STORE_OK,
          "c finishes it canceled");

    /* a poison job: three claims whose worker dies; the third expiry fails it */
    make_id(8200, id);
    CHECK(submit(a, 8200, 2000, &outcome, NULL) == STORE_OK && outcome == 1, "submit poison");
    for (int k = 1; k <= 3; k++) {
        double t0 = 2000 + 100.0 * k;
        CHECK(store_claim_next(k % 2 ? a : c, t0, &j) == STORE_OK && !strcmp(j.id, id) &&
                  j.attempts == k, "claim %d (attempts %d)", k, j.attempts);
        store_job_clear(&j);
        CHECK(store_requeue_expired(k % 2 ? c : a, t0 + 31, 3, &requeued, &failed) == STORE_OK &&
                  requeued == (k < 3) && failed == (k == 3),
              "expiry %d: requeued %d failed %d", k, requeued, failed);
    }
    CHECK(store_get(a, id, 0, &j) == STORE_OK && j.state == STORE_FAILED && j.finished_at == 2331 &&
              j.error && strstr(j.error, "{\"type\":\"interrupted\",") == j.error &&
              strstr(j.error, "claimed 3 times"), "failed as interrupted: %s",
          j.error ? j.error : "(null)");
    store_job_clear(&j);
    CHECK(store_claim_next(a, 2400, &j) == STORE_NOT_FOUND, "not claimed again");
    CHECK(submit(c, 8200, 2500, &outcome, &j) == STORE_OK && outcome == 2 &&
              j.state == STORE_QUEUED && j.attempts == 0 && j.error == NULL,
          "resubmitted: outcome %d", outcome);
    store_job_clear(&j);
    store_close(a);
    store_close(c);
}

/* Retention on PostgreSQL: by age, then by size; never unfinished jobs. */
static void test_prune_pg(const backend *b)
{
    store *s = NULL;
    store_job j;
    char path[600], err[256], id[65], *res = malloc(20000);
    long long removed = -1, live = 0, file = 0, live2 = 0, counts[STORE_N_STATES];
    int outcome;

    CHECK(fresh_db(b, "prune", path, sizeof path) == 0, "fresh database prune");
    CHECK(store_open(&s, path, NULL, err, sizeof err) == STORE_OK, "open: %s", err);
    if (s == NULL || res == NULL) {
        free(res);
        store_close(s);
        return;
    }
    unsigned x = 2463534242u;
    for (int i = 0; i < 20000; i++) {   /* pseudo-random: pglz cannot shrink it */
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        res[i] = (char)('!' + x % 90);
    }
    /* ten jobs finished at 100 … 109, one queued, one running */
    for (unsigned i = 0; i < 12; i++) {
        CHECK(submit(s, 9500 + i, i, &outcome, NULL) == STORE_OK, "submit %u", i);
        CHECK(store_claim_next(s, 50, &j) == STORE_OK, "claim %u", i);
        store_job_clear(&j);
        make_id(9500 + i, id);
        if (i < 10)
            CHECK(store_finish(s, id, STORE_DONE, 100 + i, 11, NULL, res, 20000, NULL, 0) ==
                      STORE_OK, "finish %u", i);
    }
    CHECK(submit(s, 9600, 1, &outcome, NULL) == STORE_OK, "a queued one");
    CHECK(store_size(s, &live, &file) == STORE_OK && live > 10 * 20000 && file > live,
          "size: live %lld file %lld", live, file);
    CHECK(store_prune(s, 1000, 1000 - 103.5, 0, &removed) == STORE_OK && removed == 4,
          "by age: the 4 ended before 103.5, removed %lld", removed);
    make_id(9503, id);
    CHECK(store_get(s, id, 0, &j) == STORE_NOT_FOUND, "job ended at 103 gone");
    make_id(9504, id);
    CHECK(store_get(s, id, 0, &j) == STORE_OK, "job ended at 104 kept");
    store_job_clear(&j);
    CHECK(store_size(s, &live2, &file) == STORE_OK && live2 < live, "live shrank: %lld -> %lld",
          live, live2);
    /* keep about two results' worth: the oldest finished go first */
    CHECK(store_prune(s, 1000, 0, live2 - (live2 - 3000) / 6 * 4, &removed) == STORE_OK &&
              removed >= 3 && removed <= 5, "by size: removed %lld", removed);
    make_id(9509, id);
    CHECK(store_get(s, id, 0, &j) == STORE_OK, "the newest finished job kept");
    store_job_clear(&j);
    CHECK(store_prune(s, 1000, 0, 1, &removed) == STORE_OK, "size 1: everything finished");
    CHECK(store_count(s, counts) == STORE_OK && counts[STORE_DONE] == 0 &&
              counts[STORE_QUEUED] == 1 && counts[STORE_RUNNING] == 2,
          "unfinished kept: %lld queued %lld running %lld done", counts[STORE_QUEUED],
          counts[STORE_RUNNING], counts[STORE_DONE]);
    free(res);
    store_close(s);
}

typedef struct err_seen {
    pthread_mutex_t lock;
    int unavailable;
    char text[256];
} err_seen;

static void on_error(void *ctx, const store_error *e)
{
    err_seen *x = ctx;

    pthread_mutex_lock(&x->lock);
    if (e->rc == STORE_UNAVAILABLE) {
        x->unavailable++;
        snprintf(x->text, sizeof x->text, "%s", e->text);
    }
    pthread_mutex_unlock(&x->lock);
}

/* The server restarts, then stops and comes back: the same handle reports
 * STORE_UNAVAILABLE quickly while it is down and works again after. */
static void test_restart(const backend *b)
{
    err_seen seen = {PTHREAD_MUTEX_INITIALIZER, 0, ""};
    store_settings set;
    store *s = NULL;
    store_job j;
    store_error e;
    char path[600], err[256], id[65];
    long long counts[STORE_N_STATES];
    double t, worst = 0;
    int outcome, rc, ok_after = 0;

    CHECK(fresh_db(b, "restart", path, sizeof path) == 0, "fresh database restart");
    store_default_settings(&set);
    set.path = path;
    set.on_error = on_error;
    set.on_error_ctx = &seen;
    CHECK(store_open_with(&s, &set, NULL, err, sizeof err) == STORE_OK, "open: %s", err);
    if (s == NULL)
        return;
    CHECK(submit(s, 9100, 1, &outcome, NULL) == STORE_OK, "submit before");
    make_id(9100, id);

    /* pg_ctl restart: the pooled session is closed by the server; the next
     * call notices it before sending and reconnects */
    CHECK(pg_cluster_restart(b->cl) == 0, "pg_ctl restart");
    CHECK((rc = store_get(s, id, 0, &j)) == STORE_OK && j.state == STORE_QUEUED,
          "first call after a restart works: %s", store_rc_name(rc));
    store_job_clear(&j);

    /* stopped: every call fails with the unavailable kind, quickly */
    CHECK(pg_cluster_stop(b->cl) == 0, "pg_ctl stop");
    for (int i = 0; i < 5; i++) {
        t = mono();
        switch (i) {
        case 0: rc = store_health(s); break;
        case 1: rc = store_get(s, id, 0, &j); break;
        case 2: rc = submit(s, 9101, 2, &outcome, NULL); break;
        case 3: rc = store_claim_next(s, 3, &j); break;
        default: rc = store_count(s, counts); break;
        }
        t = mono() - t;
        worst = t > worst ? t : worst;
        CHECK(rc == STORE_UNAVAILABLE, "call %d while stopped: %s", i, store_rc_name(rc));
    }
    CHECK(worst < 2.5, "each failed within %.3f s", worst);
    CHECK(store_last_error(s, &e) == STORE_UNAVAILABLE && e.text[0], "last error: %s", e.text);
    pthread_mutex_lock(&seen.lock);
    CHECK(seen.unavailable >= 5 && seen.text[0], "callback saw %d: %s", seen.unavailable,
          seen.text);
    pthread_mutex_unlock(&seen.lock);
    printf("while stopped: slowest call %.4f s; libpq said: %s\n", worst, e.text);

    /* back: health recovers by itself, the same handle works */
    CHECK(pg_cluster_resume(b->cl) == 0, "pg_ctl start again");
    t = mono();
    while (mono() - t < 20) {
        if (store_health(s) == STORE_OK) {
            ok_after = 1;
            break;
        }
        nanosleep(&(struct timespec){0, 50000000}, NULL);
    }
    CHECK(ok_after, "healthy again after %.2f s", mono() - t);
    printf("healthy again %.2f s after the server started\n", mono() - t);
    CHECK(submit(s, 9101, 4, &outcome, NULL) == STORE_OK && outcome == 1, "submit after");
    CHECK(store_claim_next(s, 5, &j) == STORE_OK && !strcmp(j.id, id), "claim after");
    store_job_clear(&j);
    CHECK(store_count(s, counts) == STORE_OK && counts[STORE_QUEUED] == 1 &&
              counts[STORE_RUNNING] == 1, "counts after");
    store_close(s);
}

/* ---- the two runs ----------------------------------------------------------- */

/* The suite both backends pass; first is the fresh database's target. */
static void run_shared(const backend *b, const char *path)
{
    store *s = NULL;
    char err[256];
    int requeued = -1;

    test_names();
    CHECK(store_open(&s, path, &requeued, err, sizeof err) == STORE_OK && s != NULL,
          "fresh open: %s", err);
    CHECK(requeued == 0, "nothing to requeue on a fresh database");
    if (s != NULL) {
        test_lifecycle(b, s, path);
        test_list(s);
        store_close(s);
        test_reopen(path);
    }
    test_concurrent(b);
    test_cancel_seen(b);
}

static int run_sqlite(void)
{
    char tmpl[512], path[600];
    const char *tmp = getenv("TMPDIR");
    backend b = {0, tmpl, NULL};

    snprintf(tmpl, sizeof tmpl, "%s/test_store.XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (mkdtemp(tmpl) == NULL) {
        perror("mkdtemp");
        return 1;
    }
    snprintf(path, sizeof path, "%s/jobs.db", tmpl);
    run_shared(&b, path);
    test_refused(tmpl);
    test_lease_sqlite(&b);
    remove_db(path);
    if (rmdir(tmpl) != 0)
        perror("rmdir");
    return 0;
}

static int run_pg(void)
{
    pg_cluster cl;
    backend b = {1, NULL, &cl};
    char why[512], path[600];
    double t = mono();
    int rc = pg_cluster_start(&cl, why, sizeof why);

    if (rc == 77) {
        printf("SKIP: %s\n", why);
        pg_cluster_destroy(&cl);
        return 77;
    }
    if (rc != 0) {
        printf("FAIL: cannot start a PostgreSQL cluster: %s\n", why);
        pg_cluster_destroy(&cl);
        return 1;
    }
    printf("PostgreSQL cluster in %s on port %d (%s), started in %.2f s\n", cl.dir, cl.port,
           cl.bindir, mono() - t);
    if (fresh_db(&b, "jobs", path, sizeof path) != 0) {
        printf("FAIL: createdb\n");
        pg_cluster_destroy(&cl);
        return 1;
    }
    run_shared(&b, path);
    test_refused_pg(&b);
    test_open_together(&b);
    test_replicas(&b);
    test_lease_pg(&b);
    test_prune_pg(&b);
    test_restart(&b);
    pg_cluster_destroy(&cl);
    return 0;
}

int main(int argc, char **argv)
{
    const char *which = argc > 1 ? argv[1] : "sqlite";
    int rc;

    if (strcmp(which, "sqlite") == 0) {
        rc = run_sqlite();
    } else if (strcmp(which, "postgresql") == 0) {
        rc = run_pg();
    } else {
        fprintf(stderr, "usage: test_store [sqlite|postgresql]\n");
        return 2;
    }
    if (rc != 0 && rc != 1)
        return rc;   /* 77: skipped */
    printf("%s: %d checks, %d failures\n", which, checks, failures);
    return failures || rc ? 1 : 0;
}
