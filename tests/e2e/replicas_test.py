#!/usr/bin/env python3
"""Several spinmodald replicas on one throwaway PostgreSQL (DESIGN.md §6, issue 15).

usage: replicas_test.py SPINMODALD

Starts a PostgreSQL cluster of its own (initdb + pg_ctl on a temporary
directory and a free loopback port; as root the server runs as `nobody`) and
three daemons on it (--db postgresql://…, --lease 3), then shows:
  1. 200 distinct jobs submitted round-robin all end `done`, each run to
     completion exactly once (job_done events counted over the three logs);
  2. a replica killed with -9 while it runs a job loses nothing: another
     replica finishes the job after the lease expires;
  3. a job canceled through another replica than the one running it stops;
  4. `?wait=` on another replica returns when the job finishes;
  5. a PostgreSQL restart mid-run is survived: /readyz goes 503 while it is
     down and back to 200, and jobs submitted afterwards complete;
  6. a replica paused (SIGSTOP) past its lease loses its job to another, and
     afterwards runs the jobs it claims;
  7. the 429 bound (--queue-max) counts the queue all replicas share.
Without PostgreSQL server binaries it exits 77 (meson: skipped), saying why.
Waits are upper bounds scaled by timescale.py; none decides a pass by time.
"""
import glob
import json
import os
import pwd
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from daemon import Daemon  # noqa: E402
import timescale  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLE = os.path.join(HERE, os.pardir, os.pardir, "examples", "angled-beam-90.json")
SKIP = 77
failures = []
LEASE = "3"   # set in main(): 3 s times the machine's slowness (a starved heartbeat must not lose leases)


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)
    return ok


def wait_until(cond, base, interval=0.1):
    end = time.monotonic() + timescale.budget(base)
    while True:
        v = cond()
        if v or time.monotonic() > end:
            return v
        time.sleep(interval)


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


class Postgres:
    """A throwaway cluster: initdb, pg_ctl start/stop/restart, removed at the end."""

    def __init__(self, tmp):
        self.bindir = self.find_bindir()
        self.dir = tempfile.mkdtemp(prefix="spinmodal-pg-", dir="/tmp")
        self.data = os.path.join(self.dir, "data")
        self.port = free_port()
        self.drop = os.geteuid() == 0
        if self.drop:
            pw = pwd.getpwnam("nobody")
            self.uid, self.gid = pw.pw_uid, pw.pw_gid
            os.chown(self.dir, self.uid, self.gid)

    @staticmethod
    def find_bindir():
        cands = []
        if os.environ.get("PG_BINDIR"):
            cands = [os.environ["PG_BINDIR"]]
        else:
            try:
                out = subprocess.run(["pg_config", "--bindir"], capture_output=True, text=True)
                if out.returncode == 0:
                    cands.append(out.stdout.strip())
            except OSError:
                pass
            cands += sorted(glob.glob("/usr/lib/postgresql/*/bin"), reverse=True)
        for c in cands:
            if os.access(os.path.join(c, "initdb"), os.X_OK) and \
               os.access(os.path.join(c, "pg_ctl"), os.X_OK):
                return c
        return None

    def _run(self, args, check_rc=True):
        def demote():
            if self.drop:
                os.setgroups([])
                os.setgid(self.gid)
                os.setuid(self.uid)
        p = subprocess.run(args, preexec_fn=demote, capture_output=True, text=True,
                           cwd=self.dir, timeout=timescale.budget(120))
        if check_rc and p.returncode != 0:
            raise RuntimeError("%s failed: %s %s" % (args[0], p.stdout[-400:], p.stderr[-400:]))
        return p

    def ctl(self, action, mode="fast"):
        opts = "-p %d -k %s -c listen_addresses=127.0.0.1 -c fsync=off" % (self.port, self.dir)
        args = [os.path.join(self.bindir, "pg_ctl"), "-D", self.data, "-l",
                os.path.join(self.dir, "log"), "-w", "-o", opts]
        if action in ("stop", "restart"):
            args += ["-m", mode]
        return self._run(args + [action], check_rc=(action != "stop"))

    def start(self):
        self._run([os.path.join(self.bindir, "initdb"), "-D", self.data, "-A", "trust",
                   "-U", "postgres", "-E", "UTF8"])
        self.ctl("start")
        self._run([os.path.join(self.bindir, "createdb"), "-h", "127.0.0.1", "-p",
                   str(self.port), "-U", "postgres", "spinmodal"])

    def dsn(self):
        return "postgresql://postgres@127.0.0.1:%d/spinmodal" % self.port

    def remove(self):
        try:
            self.ctl("stop", "immediate")
        finally:
            shutil.rmtree(self.dir, ignore_errors=True)


def request(first_omega, n_speeds=1, elements=24):
    with open(EXAMPLE) as f:
        req = json.load(f)
    for m in req["structure"]["members"]:
        m["elements"] = elements
    req["analysis"]["omega"] = [first_omega + 0.01 * i for i in range(n_speeds)]
    req["analysis"]["mode_shapes"] = False
    return json.dumps(req).encode()


def post(d, body, query=""):
    return d.request("POST", "/v1/analyses" + query, body=body,
                     headers={"Content-Type": "application/json"})


def state(d, job):
    r = d.get("/v1/analyses/" + job)
    return r.json() if r.status == 200 else {"state": "http-%s" % r.status}


def owner_of(daemons, job):
    """The replica whose log has job_started for job last (the one running it)."""
    best, seq = None, -1
    for d in daemons:
        if not d.alive():
            continue
        for k, line in enumerate(d.log_lines()):
            if "job_started" in line and job in line and k > seq:
                best, seq = d, k
    return best


def done_counts(daemons):
    counts = {}
    for d in daemons:
        for line in d.log_lines():
            if "event=job_done" in line:
                for tok in line.split():
                    if tok.startswith("job="):
                        counts[tok[4:]] = counts.get(tok[4:], 0) + 1
    return counts


def main():
    exe = os.path.abspath(sys.argv[1])
    timescale.calibrate(exe)
    global LEASE
    LEASE = "%g" % round(3 * max(1.0, timescale.factor()), 1)
    pg_bin = Postgres.find_bindir()
    if not pg_bin:
        print("SKIP: no PostgreSQL server binaries (initdb, pg_ctl): install the Debian "
              "package postgresql (deploy/install-deps.sh does)")
        return SKIP
    tmp = tempfile.mkdtemp(prefix="spinmodal-replicas-")
    pg = Postgres(tmp)
    daemons = []
    retired = []   # daemons stopped or killed, for the log on failure
    try:
        pg.start()
        for k in range(3):
            d = Daemon(exe, tmp, ["--workers", "1", "--lease", LEASE, "--replica-id", "r%d" % k],
                       db=pg.dsn(), name="replica%d" % k)
            d.start()
            daemons.append(d)
        check(all(d.get("/readyz").status == 200 for d in daemons), "three replicas ready")
        check(all("postgres@" not in l for d in daemons for l in d.log_lines()),
              "the DSN is not in the logs")

        # 1. 200 jobs round-robin, each done exactly once
        ids = []
        for i in range(200):
            r = post(daemons[i % 3], request(1.0 + 0.1 * i))
            if r.status in (200, 202):
                ids.append(r.json()["id"])
        check(len(set(ids)) == 200, "200 distinct jobs accepted (%d)" % len(set(ids)))
        alldone = wait_until(lambda: all(state(daemons[0], j)["state"] == "done" for j in ids),
                             180, 0.5)
        check(alldone, "all 200 jobs done (read through one replica)")
        counts = done_counts(daemons)
        twice = [j for j in ids if counts.get(j, 0) != 1]
        check(not twice, "each job ran to completion exactly once (job_done per id: %s)"
              % ({j[:8]: counts.get(j, 0) for j in twice[:5]} or "all 1"))
        busy = [sum(1 for j in ids if any("event=job_done" in l and j in l
                                          for l in d.log_lines())) for d in daemons]
        check(all(b > 0 for b in busy), "every replica did some of the work %s" % busy)

        # 2. kill -9 the replica running a job: another finishes it after the lease
        slow = request(5.01, n_speeds=120, elements=96)
        r = post(daemons[0], slow)
        job = r.json()["id"]
        running = wait_until(lambda: state(daemons[0], job)["state"] == "running", 60)
        own = wait_until(lambda: owner_of(daemons, job), 10)
        check(running and own is not None, "the slow job runs on a replica")
        if own is not None:
            own.kill()
            others = [d for d in daemons if d is not own]
            doc = wait_until(lambda: state(others[0], job) if state(others[0], job)["state"]
                             in ("done", "failed") else None, 180, 0.5)
            check(doc is not None and doc["state"] == "done",
                  "after kill -9 of its replica the job is finished by another (%s, attempts %s)"
                  % (doc and doc["state"], doc and doc.get("attempts")))
            check(any("event=job_done" in l and job in l for d in others for l in d.log_lines()),
                  "job_done for it is in another replica's log")
            retired.append(own)
            daemons = others

        # 3. cancel through another replica than the owner
        r = post(daemons[0], request(6.01, n_speeds=200, elements=96))
        job = r.json()["id"]
        wait_until(lambda: state(daemons[0], job)["state"] == "running", 60)
        own = wait_until(lambda: owner_of(daemons, job), 10)
        other = [d for d in daemons if d is not own][0] if own else daemons[1]
        r = other.request("DELETE", "/v1/analyses/" + job)
        check(r.status in (200, 202), "DELETE through the other replica accepted (%s)" % r.status)
        doc = wait_until(lambda: state(other, job) if state(other, job)["state"]
                         in ("canceled", "done", "failed") else None, 60, 0.25)
        check(doc is not None and doc["state"] == "canceled",
              "the job running on another replica stops: canceled (%s %s)"
              % (doc and doc["state"], doc and json.dumps(doc.get("error"))[:300]))

        # 4. ?wait on another replica
        r = post(daemons[0], request(7.01, n_speeds=20, elements=48))
        job = r.json()["id"]
        r = daemons[1].get("/v1/analyses/%s?wait=%g" % (job, timescale.wait_param(60)))
        check(r.status == 200 and r.json().get("state") == "done",
              "?wait on another replica returns the finished job (%s %s)"
              % (r.status, r.json().get("state") if r.status == 200 else ""))

        # 5. PostgreSQL restart mid-run
        r = post(daemons[0], request(8.01, n_speeds=60, elements=96))
        job = r.json()["id"]
        pg.ctl("stop", "fast")
        down = wait_until(lambda: daemons[0].get("/readyz").status == 503, 30)
        check(down, "/readyz is 503 while PostgreSQL is down")
        r = post(daemons[1], request(9.01))
        check(r.status == 503, "POST answers 503 while PostgreSQL is down (%s)" % r.status)
        pg.ctl("start")
        up = wait_until(lambda: all(d.get("/readyz").status == 200 for d in daemons), 60)
        check(up, "/readyz is 200 again on every replica, without a restart of the daemons")
        doc = wait_until(lambda: state(daemons[0], job) if state(daemons[0], job)["state"]
                         in ("done", "failed") else None, 180, 0.5)
        check(doc is not None and doc["state"] == "done",
              "the job running across the restart ends done (%s: %s)"
              % (doc and doc["state"], doc and json.dumps(doc.get("error"))[:300]))
        r = post(daemons[1], request(9.02), "?wait=%g" % timescale.wait_param(60))
        check(r.status == 200 and r.json().get("state") == "done",
              "a job submitted after the restart completes (%s)" % r.status)

        # 6. a replica paused past its lease loses its job to the other and then
        #    runs the next job it claims (the loss belonged to that job, not to
        #    the worker's slot: 0.8.0 kept it and lost every later job there)
        a, b = daemons
        job = post(a, request(10.01, n_speeds=120, elements=96)).json()["id"]
        wait_until(lambda: state(a, job)["state"] == "running", 60)
        if wait_until(lambda: owner_of(daemons, job), 10) is b:
            a, b = b, a
        mark_a, mark_b = a.log_count(), b.log_count()
        a.signal(signal.SIGSTOP)
        taken = b.wait_log("event=job_started job=%s" % job, 60, mark_b)
        a.signal(signal.SIGCONT)
        check(taken is not None, "a job whose replica is paused past its lease is taken over")
        lost = a.wait_log("event=job_lost job=%s" % job, 30, mark_a)
        check(lost is not None, "the paused replica, resumed, gives the job up (job_lost)")
        mark_a = a.log_count()
        check(b.stop() == 0, "%s stops cleanly" % b.name)
        retired.append(b)
        daemons = [a]
        doc = wait_until(lambda: state(a, job) if state(a, job)["state"]
                         in ("done", "failed") else None, 180, 0.5)
        check(doc is not None and doc["state"] == "done",
              "the taken-over job ends done (%s)" % (doc and doc["state"]))
        mark_a = a.log_count()
        r = post(a, request(10.51, n_speeds=3), "?wait=%g" % timescale.wait_param(60))
        nxt = r.json().get("id") if r.status in (200, 202) else None
        check(r.status == 200 and r.json().get("state") == "done" and
              a.wait_log("event=job_done job=%s" % nxt, 5, mark_a) is not None,
              "the replica that lost a job runs the next one it claims to the end (%s %s)"
              % (r.status, r.json().get("state") if r.status in (200, 202) else ""))
        for d in daemons:
            check(d.stop() == 0, "%s stops cleanly" % d.name)
        retired += daemons
        daemons = []

        # 7. the queue bound (429) counts the shared queue, not one replica's submissions
        for k in range(2):
            d = Daemon(exe, tmp, ["--workers", "1", "--lease", LEASE, "--queue-max", "5"],
                       db=pg.dsn(), name="bounded%d" % k)
            d.start()
            daemons.append(d)
        x, y = daemons
        slow = [post(x, request(3.01 + 0.01 * k, n_speeds=300, elements=96)).json()["id"]
                for k in range(2)]
        wait_until(lambda: all(state(x, j)["state"] == "running" for j in slow), 60)
        time.sleep(1.2)  # the replica's count of the shared queue is up to 1 s old (DAEMON.md)
        before = [l for l in x.get("/metrics").body.decode().splitlines()
                  if l.startswith("spinmodal_jobs{")]
        codes = [post(x, request(4.001 + 0.001 * k)).status for k in range(5)]
        check(codes == [202] * 5, "5 jobs queued through one replica %s (store before: %s)"
              % (codes, before))
        r = post(y, request(4.0055))
        check(r.status == 429 and r.headers.get("Retry-After"),
              "the other replica answers 429 (+ Retry-After): the shared queue is full (%s)"
              % r.status)
        for j in slow:
            x.request("DELETE", "/v1/analyses/" + j)
        for d in daemons:
            check(d.stop() == 0, "%s stops cleanly" % d.name)
        retired += daemons
        daemons = []
    finally:
        if failures:   # what the replicas said about leases and the store, for the log
            for d in daemons + retired:
                for l in d.log_lines():
                    if os.environ.get("SPINMODAL_TEST_FULL_LOG") or "level=warn" in l or "level=error" in l:
                        print("  %s: %s" % (d.name, l[:300]))
        for d in daemons:
            if d.alive():
                d.kill()
        pg.remove()
        shutil.rmtree(tmp, ignore_errors=True)
    if failures:
        print("%d failed" % len(failures))
        return 1
    print("all passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
