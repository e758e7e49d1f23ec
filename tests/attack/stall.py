"""A database that stops answering (attack.py, category 'faults'; issue 23 item 3).

  sqlite lock   another process holds the SQLite write lock while clients POST
                at once: each answers 503 + Retry-After within --db-timeout and
                a margin (they used to wait the busy timeout one after another:
                the twelfth 60 s), /readyz 503 'busy' and /metrics within the
                probes' bound, a read of a job answers; once the lock is let go
                the same requests run;
  pg stall      PostgreSQL paused (SIGSTOP of the postmaster and every backend)
                for a while (quick: 6 s; full: 20 s) under submissions, reads
                and probes: /readyz answers 503 'db_timeout' within the probes'
                bound, /metrics answers, every POST and GET answers (503 +
                Retry-After, or a 2xx) within --db-timeout and a margin, never a
                hang; after SIGCONT /readyz recovers and every job acknowledged
                (before, during or after) ends done, none lost, none run twice
                (job_done events per id).  Skipped without PostgreSQL server
                binaries (tests/e2e/replicas_test.py's throwaway cluster).
"""
import os
import signal
import sqlite3
import threading
import time

from common import Daemon, small_request, timescale, wait_until

JS = {"Content-Type": "application/json"}
DB_TIMEOUT = 5.0   # the daemon's default --db-timeout
PROBE_BOUND = 2.0  # probes answer within 0.5 s; scaled, with a margin for HTTP
CALL_BOUND = DB_TIMEOUT + 3.0


def _timed(fn):
    """(fn()'s value or the exception it raised, seconds)."""
    t0 = time.monotonic()
    try:
        v = fn()
    except Exception as e:  # noqa: BLE001 - a hang shows as a client timeout here
        v = e
    return v, time.monotonic() - t0


def _status(r):
    return getattr(r, "status", None) or type(r).__name__


def _database(r):
    try:
        return ((r.json() or {}).get("checks") or {}).get("database")
    except Exception:  # noqa: BLE001
        return None


def sqlite_lock(exe, tmp, tally, quick, category="faults"):
    n = 6 if quick else 16
    d = Daemon(exe, tmp, ["--workers", "1"], name="locked")
    d.start()
    try:
        r = d.post("/v1/analyses?wait=%g" % timescale.wait_param(30), small_request(omega=7.0))
        jid = (r.json() or {}).get("id")
        con = sqlite3.connect(d.db, timeout=0, isolation_level=None)
        con.execute("BEGIN IMMEDIATE")
        answers = []

        def post(i):
            answers.append(_timed(lambda: d.request("POST", "/v1/analyses", headers=JS,
                                                    json_body=small_request(omega=8.0 + 0.01 * i),
                                                    timeout=150)))
        threads = [threading.Thread(target=post, args=(i,)) for i in range(n)]
        for t in threads:
            t.start()
        time.sleep(0.3)
        r, took = _timed(lambda: d.get("/readyz", timeout=90))
        tally.add(category, "sqlite locked by another process: /readyz %s %s"
                  % (_status(r), _database(r)))
        tally.check(_status(r) == 503 and _database(r) == "busy" and
                    took <= timescale.scaled(PROBE_BOUND), category,
                    "sqlite lock: /readyz 503 'busy' within %.1f s (%s %s in %.2f s)"
                    % (timescale.scaled(PROBE_BOUND), _status(r), _database(r), took))
        r, took = _timed(lambda: d.get("/metrics", timeout=90))
        tally.check(_status(r) == 200 and took <= timescale.scaled(PROBE_BOUND), category,
                    "sqlite lock: /metrics answers (%s in %.2f s)" % (_status(r), took))
        r, took = _timed(lambda: d.get("/v1/analyses/%s" % jid, timeout=90))
        tally.check(_status(r) == 200, category, "sqlite lock: a read of a job answers (%s)"
                    % _status(r))
        for t in threads:
            t.join(timescale.budget(200))
        worst = max((t for _, t in answers), default=0.0)
        for v, _ in answers:
            tally.add(category, "sqlite locked by another process: POST %s" % _status(v))
            tally.check(_status(v) == 503 and v.headers.get("Retry-After"), category,
                        "sqlite lock: POST 503 with Retry-After (%s)" % _status(v))
        tally.figure("faults: sqlite lock, slowest of %d concurrent POSTs, s" % n,
                     "%.2f" % worst)
        tally.check(worst <= timescale.scaled(CALL_BOUND), category,
                    "sqlite lock: every POST answered within --db-timeout and a margin "
                    "(slowest %.2f s, bound %.1f s)" % (worst, timescale.scaled(CALL_BOUND)))
        con.rollback()
        con.close()
        ok = wait_until(lambda: d.get("/readyz").status == 200, 10)
        tally.check(ok, category, "sqlite lock: /readyz 200 once the lock is let go")
        r = d.post("/v1/analyses?wait=%g" % timescale.wait_param(30), small_request(omega=8.0))
        tally.check((r.json() or {}).get("state") == "done", category,
                    "sqlite lock: the same request runs afterwards (%s)" % r.status)
    finally:
        rc = d.stop()
    tally.check(rc == 0, category, "sqlite lock: clean stop (exit %s)" % rc)


def _pg_processes(pg):
    """The postmaster's pid and its children's."""
    with open(os.path.join(pg.data, "postmaster.pid")) as f:
        pm = int(f.readline())
    kids = []
    for p in os.listdir("/proc"):
        if not p.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % p) as f:
                ppid = int(f.read().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        if ppid == pm:
            kids.append(int(p))
    return [pm] + kids


class _Traffic:
    """Submissions (distinct small requests), reads and probes from three threads,
    each answer timed and tagged with the phase it started in."""

    def __init__(self, d):
        self.d, self.phase, self.stop = d, "before", threading.Event()
        self.acked, self.seen, self.lock, self.k = [], [], threading.Lock(), 0
        self.threads = [threading.Thread(target=f) for f in (self.posts, self.reads,
                                                              self.probes)]

    def note(self, what, r, took, phase):
        with self.lock:
            self.seen.append((phase, what, _status(r), took, r))

    def posts(self):
        while not self.stop.is_set():
            with self.lock:
                self.k += 1
                k, phase = self.k, self.phase
            r, took = _timed(lambda: self.d.request("POST", "/v1/analyses", headers=JS,
                                                    json_body=small_request(omega=20 + 0.01 * k),
                                                    timeout=60))
            if _status(r) in (200, 202):
                with self.lock:
                    self.acked.append(r.json()["id"])
            self.note("POST", r, took, phase)
            time.sleep(0.05)

    def reads(self):
        while not self.stop.is_set():
            with self.lock:
                jid, phase = (self.acked[-1] if self.acked else "0" * 64), self.phase
            r, took = _timed(lambda: self.d.get("/v1/analyses/" + jid, timeout=60))
            self.note("GET", r, took, phase)
            time.sleep(0.1)

    def probes(self):
        while not self.stop.is_set():
            for path in ("/readyz", "/metrics"):
                phase = self.phase
                r, took = _timed(lambda: self.d.get(path, timeout=60))
                self.note(path, r, took, phase)
            time.sleep(0.2)

    def start(self):
        for t in self.threads:
            t.start()

    def finish(self):
        self.stop.set()
        for t in self.threads:
            t.join(timescale.budget(120))


def pg_stall(exe, tmp, tally, quick, category="faults"):
    from replicas_test import Postgres
    pg = Postgres(tmp)
    if pg.bindir is None:
        tally.skip("faults: PostgreSQL stall", "no PostgreSQL server binaries (PG_BINDIR)")
        return
    pg.start()
    d, stopped, traffic = None, [], None
    try:
        d = Daemon(exe, tmp, ["--workers", "2"], db=pg.dsn(), name="stall")
        d.start()
        traffic = _Traffic(d)
        traffic.start()
        time.sleep(2.0)
        stopped = _pg_processes(pg)
        with traffic.lock:
            traffic.phase = "stalled"
        for pid in stopped:
            os.kill(pid, signal.SIGSTOP)
        time.sleep(6.0 if quick else 20.0)
        with traffic.lock:
            traffic.phase = "after"
        for pid in stopped:
            os.kill(pid, signal.SIGCONT)
        stopped = []
        ready = wait_until(lambda: d.get("/readyz").status == 200, 30)
        tally.check(ready, category, "pg stall: /readyz 200 again after SIGCONT")
        time.sleep(2.0)
        traffic.finish()
        _pg_stall_checks(tally, category, traffic)

        def all_done():
            return all((d.get("/v1/analyses/" + j).json() or {}).get("state") == "done"
                       for j in traffic.acked)
        ok = wait_until(all_done, 120)
        states = {}
        for j in traffic.acked:
            s = (d.get("/v1/analyses/" + j).json() or {}).get("state")
            states[s] = states.get(s, 0) + 1
        tally.add(category, "pg stall: jobs acknowledged", len(traffic.acked))
        tally.check(ok, category, "pg stall: every acknowledged job ends done (%s)" % states)
        counts = {}
        for line in d.log_lines():
            if "event=job_done" in line:
                for tok in line.split():
                    if tok.startswith("job="):
                        counts[tok[4:]] = counts.get(tok[4:], 0) + 1
        twice = [j for j, c in counts.items() if c > 1]
        tally.check(not twice, category, "pg stall: no job run twice (%s)" % twice[:3])
        rc = d.stop()
        d = None
        tally.check(rc == 0, category, "pg stall: clean stop (exit %s)" % rc)
    finally:
        if traffic is not None:
            traffic.finish()
        for pid in stopped:
            try:
                os.kill(pid, signal.SIGCONT)
            except OSError:
                pass
        if d is not None:
            d.kill()
        pg.remove()


def _pg_stall_checks(tally, category, traffic):
    """The invariants of the answers seen while PostgreSQL was stopped."""
    worst = {}
    for phase, what, status, took, r in traffic.seen:
        tally.add(category, "pg stall %s: %s %s" % (phase, what, status))
        key = "probe" if what.startswith("/") else "call"
        if phase == "stalled":
            worst[key] = max(worst.get(key, 0.0), took)
        if not isinstance(status, int):
            tally.broken(category, "pg stall: %s (%s) got no answer: %s" % (what, phase, status))
        elif status >= 500:
            tally.check(status == 503 and r.headers.get("Retry-After"), category,
                        "pg stall: %s %s is a 503 with Retry-After" % (what, status))
    stalled_ready = [r for phase, what, _, _, r in traffic.seen
                     if phase == "stalled" and what == "/readyz"]
    tally.check(any(_database(r) == "db_timeout" for r in stalled_ready), category,
                "pg stall: /readyz said 'db_timeout' while stopped (%s)"
                % sorted(set(str(_database(r)) for r in stalled_ready)))
    tally.check(not any(_status(r) == 200 for r in stalled_ready), category,
                "pg stall: /readyz never 200 while stopped")
    for key, bound in (("probe", PROBE_BOUND), ("call", CALL_BOUND)):
        tally.figure("faults: pg stall, slowest %s while stopped, s" % key,
                     "%.2f" % worst.get(key, 0.0))
        tally.check(worst.get(key, 0.0) <= timescale.scaled(bound), category,
                    "pg stall: slowest %s while stopped %.2f s (bound %.1f s)"
                    % (key, worst.get(key, 0.0), timescale.scaled(bound)))


def category(exe, tmp, tally, quick, name="faults"):
    sqlite_lock(exe, tmp, tally, quick, name)
    pg_stall(exe, tmp, tally, quick, name)
