/*
 * test_store.c — behaviour of the SQLite job store (server/daemon/store.h) on a
 * real database file in a mkdtemp directory: schema version and WAL on a
 * fresh open, submission outcomes, claim order, finish with large texts
 * read back byte-exactly, cancel and requeue in every state, newest-first
 * pagination and state filters, counts, crash recovery on reopen, refusal
 * of newer, foreign and non-SQLite files, and 4 threads claiming 200 jobs
 * (each exactly once) while 2 threads read.
 */
#include "store.h"

#include <pthread.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
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
    len = snprintf(req, sizeof req, "{\"job\":%u}", n);
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

/* First column of the first row of sql as text into buf. */
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
static void test_lifecycle(store *s, const char *path)
{
    store_job j, k;
    store_state state = STORE_QUEUED;
    char id[65], buf[64];
    int outcome = -1;
    long long counts[STORE_N_STATES];

    CHECK(store_schema_version(s) == 1, "fresh schema version 1, got %d", store_schema_version(s));
    CHECK(raw_text(path, "PRAGMA journal_mode", buf, sizeof buf) == SQLITE_OK && !strcmp(buf, "wal"),
          "journal mode wal, got '%s'", buf);
    CHECK(raw_text(path, "PRAGMA user_version", buf, sizeof buf) == SQLITE_OK && !strcmp(buf, "1"),
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
    CHECK(raw_text(path, "SELECT count(*) FROM jobs", buf, sizeof buf) == SQLITE_OK &&
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
              page[0].state == STORE_CANCELED && page[1].state == STORE_QUEUED,
          "first page");
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
static void test_concurrent(const char *dir)
{
    store *s = NULL;
    char path[600], err[256];
    pthread_t tc[N_CLAIMERS], tr[N_READERS];
    claimer *cl = calloc(N_CLAIMERS, sizeof *cl);
    reader rd[N_READERS];
    int outcome, started_c = 0, started_r = 0, total = 0, once = 1, errors = 0;
    long long counts[STORE_N_STATES];

    snprintf(path, sizeof path, "%s/conc.db", dir);
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
    remove_db(path);
}

int main(void)
{
    char tmpl[512], path[600], err[256];
    const char *tmp = getenv("TMPDIR");
    store *s = NULL;
    int requeued = -1;

    snprintf(tmpl, sizeof tmpl, "%s/test_store.XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (mkdtemp(tmpl) == NULL) {
        perror("mkdtemp");
        return 1;
    }
    snprintf(path, sizeof path, "%s/jobs.db", tmpl);

    test_names();
    CHECK(store_open(&s, path, &requeued, err, sizeof err) == STORE_OK && s != NULL,
          "fresh open: %s", err);
    CHECK(requeued == 0, "nothing to requeue on a fresh database");
    if (s != NULL) {
        test_lifecycle(s, path);
        test_list(s);
        store_close(s);
        test_reopen(path);
    }
    test_refused(tmpl);
    test_concurrent(tmpl);

    remove_db(path);
    if (rmdir(tmpl) != 0)
        perror("rmdir");
    printf("%d checks, %d failures\n", checks, failures);
    return failures ? 1 : 0;
}
