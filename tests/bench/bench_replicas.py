#!/usr/bin/env python3
"""Throughput scaling of spinmodald: workers of one daemon (SQLite), replicas on one PostgreSQL.

A benchmark, not a test (`meson test` never runs it); issue 27 goal 4.  In one run, on one
machine, it prints two tables:
  (a) one daemon on SQLite with W workers (--workers 1,2,4,8,16): jobs/s and the ratio to the
      first row (1 worker), and the efficiency ratio/W;
  (b) N replicas (--replicas 1,2,4,8) with --workers-per-replica workers each on one
      PostgreSQL: jobs/s, the ratio to the first row (1 replica) and the efficiency ratio/N.
Every job is an S-speed sweep (--speeds, default 11: omega from w0 to w0+10 rad/s) of
examples/angled-beam-90.json without mode shapes; every job of a run is distinct (w0 differs
by job and by run), so no job is a cache hit.  A row with T workers in all runs --jobs x T jobs
(so every row lasts about as long), on a fresh daemon and a fresh database (SQLite file, or a
PostgreSQL database of its own on the one server).

How jobs are submitted and polled (so that the client is not what is measured):
  - all jobs of a row are POSTed first, by --clients client threads (default 16), round-robin
    over the replicas; the daemon answers a POST after its store commit, before any solve;
  - completion is polled with two list requests per poll (`GET /v1/analyses?state=queued&limit=1`
    and `?state=running&limit=1`, both empty = done), every 2 % of the elapsed time (20-200 ms);
  - the rate printed is from the daemon's own timestamps: jobs / (last finished_at - first
    started_at), read afterwards from the list (`?state=done`), so neither the polling period
    nor the client's start-up counts; the wall rate (first POST -> done seen) is printed too.
  - `busy` is the daemon's own solve time (spinmodal_solve_duration_seconds_sum, all replicas)
    over workers x span: near 1.0 the workers never wait for work; `solve ms` is the mean solve
    time of a job (codec_run's own clock: model build and sweep; the result's JSON and CSV
    encoding, the store's write and the claim are the rest, 1 - busy) — rising with W means the
    cores interfere
    (memory bandwidth, frequency), a low `busy` with a flat `solve ms` means time outside the
    solve (store, claim, queue wait).

usage: python3 tests/bench/bench_replicas.py BUILD_DIR [--workers 1,2,4,8,16]
           [--replicas 1,2,4,8] [--workers-per-replica 2] [--jobs N] [--speeds 11]
           [--sqlite-only | --pg-only] [--pg-bin DIR] [--wrk] [--seconds S] [--clients C]
           [--daemon-env KEY=VALUE ...]
BUILD_DIR is a build folder (BUILD_DIR/server/spinmodald) or a folder holding spinmodald and
spinmodal (tests/bench/pack_device.sh's tree).  PostgreSQL: initdb/pg_ctl/createdb from
--pg-bin DIR, else $PG_BINDIR, else as tests/e2e/replicas_test.py finds them (pg_config,
/usr/lib/postgresql/*/bin); as root the server runs as `nobody` (replicas_test.Postgres), so
DIR and the libraries must be readable by nobody.  --wrk adds the cache-hit GET rate and p99
of one daemon (SQLite and one PostgreSQL replica) with wrk (Debian package wrk) for --seconds.
On a machine with fewer cores than workers the rows share the same cores: the ratios then
show the overhead of sharing, not scaling (the note printed says so).
"""
import argparse
import concurrent.futures
import json
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from datetime import datetime

HERE = os.path.dirname(os.path.abspath(__file__))
# in the repository: tests/bench/ beside tests/e2e/ and examples/; in a device pack: all in one folder
E2E = next((d for d in (os.path.join(HERE, os.pardir, "e2e"), HERE)
            if os.path.exists(os.path.join(d, "daemon.py"))), HERE)
sys.path.insert(0, E2E)
from daemon import Daemon  # noqa: E402
from replicas_test import Postgres  # noqa: E402

EXAMPLE = next((p for p in (os.path.join(HERE, os.pardir, os.pardir, "examples", "angled-beam-90.json"),
                            os.path.join(HERE, "angled-beam-90.json")) if os.path.exists(p)), None)
JS = {"Content-Type": "application/json"}
NONCE = random.Random().random()   # this run's jobs differ from any earlier run's (no cache hits)


def body(i, speeds):
    with open(EXAMPLE) as f:
        req = json.load(f)
    w0 = 1.0 + 0.001 * i + 1e-6 * NONCE
    if speeds == 1:
        req["analysis"]["omega"] = w0
    else:
        req["analysis"]["omega"] = {"from": w0, "to": w0 + 10.0, "steps": speeds - 1}
    req["analysis"]["mode_shapes"] = False
    return json.dumps(req).encode()


def stamp(s):
    return datetime.strptime(s, "%Y-%m-%dT%H:%M:%S.%fZ").timestamp()


def solve_sum(daemons):
    """(sum of solve seconds, count) over the daemons' /metrics."""
    s = n = 0.0
    for d in daemons:
        text = d.get("/metrics").body.decode()
        m1 = re.search(r"^spinmodal_solve_duration_seconds_sum (\S+)", text, re.M)
        m2 = re.search(r"^spinmodal_solve_duration_seconds_count (\S+)", text, re.M)
        s += float(m1.group(1)) if m1 else 0.0
        n += float(m2.group(1)) if m2 else 0.0
    return s, n


TCK = os.sysconf("SC_CLK_TCK")


def proc_cpu(pids):
    """(CPU seconds user+system, minor page faults) summed over the live pids."""
    cpu = flt = 0
    for pid in pids:
        try:
            with open("/proc/%d/stat" % pid) as f:
                v = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        flt += int(v[7])
        cpu += int(v[11]) + int(v[12])
    return cpu / TCK, flt


def pg_pids():
    """The PostgreSQL server's processes (every `postgres` process of this machine)."""
    out = []
    for e in os.listdir("/proc"):
        if e.isdigit():
            try:
                with open("/proc/%s/comm" % e) as f:
                    if f.read().strip() == "postgres":
                        out.append(int(e))
            except OSError:
                pass
    return out


def empty(d, state):
    r = d.get("/v1/analyses?state=%s&limit=1" % state)
    return r.status == 200 and not r.json()["items"]


def throughput(daemons, n, speeds, clients, workers):
    """Run n distinct jobs over the daemons; a dict of the figures."""
    reqs = [body(i, speeds) for i in range(n)]
    s0, c0 = solve_sum(daemons)
    dpids = [x.proc.pid for x in daemons]
    pgp = pg_pids()
    d0, f0 = proc_cpu(dpids)
    p0, _ = proc_cpu(pgp)
    t0 = time.monotonic()

    def submit(k):
        r = daemons[k % len(daemons)].request("POST", "/v1/analyses", body=reqs[k], headers=JS)
        if r.status not in (200, 202):
            raise RuntimeError("POST %d: %s %s" % (k, r.status, r.body[:300]))
        return r.json()["id"]

    with concurrent.futures.ThreadPoolExecutor(clients) as ex:
        ids = list(ex.map(submit, range(n)))
    t_sub = time.monotonic() - t0
    d = daemons[0]
    while True:
        el = time.monotonic() - t0
        time.sleep(min(0.2, max(0.02, 0.02 * el)))
        if empty(d, "queued") and empty(d, "running"):
            break
    wall = time.monotonic() - t0
    d1, f1 = proc_cpu(dpids)
    p1, _ = proc_cpu(pgp)   # the backends of the replicas' connections live as long as the row
    # the daemon's timestamps of every job of this row (fresh database: the row's jobs only)
    starts, ends, states = [], [], {}
    path = "/v1/analyses?limit=100"
    while path:
        doc = d.get(path).json()
        for it in doc["items"]:
            states[it["state"]] = states.get(it["state"], 0) + 1
            if it.get("started_at") and it.get("finished_at"):
                starts.append(stamp(it["started_at"]))
                ends.append(stamp(it["finished_at"]))
        path = doc["next"]
    if states.get("done", 0) != n:
        raise RuntimeError("expected %d jobs done, the store has %s" % (n, states))
    span = max(ends) - min(starts)
    s1, c1 = solve_sum(daemons)
    return {"rate": n / span, "wall_rate": n / wall, "span": span, "submit": t_sub,
            "solve_ms": 1e3 * (s1 - s0) / max(1, c1 - c0), "busy": (s1 - s0) / (workers * span),
            "job": ids[0], "n": n, "d_ms": 1e3 * (d1 - d0) / n, "pg_ms": 1e3 * (p1 - p0) / n,
            "faults": (f1 - f0) / n}


def wrk(d, job, seconds):
    if not shutil.which("wrk"):
        return None
    out = subprocess.run(["wrk", "-t2", "-c32", "-d%ds" % seconds, "--latency",
                          "http://127.0.0.1:%d/v1/analyses/%s" % (d.port, job)],
                         capture_output=True, text=True).stdout
    rate = re.search(r"Requests/sec:\s+([\d.]+)", out)
    p99 = re.search(r"99%\s+([\d.]+)(us|ms|s)", out)
    scale = {"us": 1e-3, "ms": 1.0, "s": 1e3}
    return (float(rate.group(1)) if rate else None,
            float(p99.group(1)) * scale[p99.group(2)] if p99 else None)


def counts(text):
    try:
        v = [int(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError("a comma-separated list of integers: %r" % text)
    if not v or min(v) < 1:
        raise argparse.ArgumentTypeError("counts must be >= 1: %r" % text)
    return v


def find_exe(build, name):
    for p in (os.path.join(build, "server", name), os.path.join(build, name)):
        if os.access(p, os.X_OK):
            return os.path.abspath(p)
    sys.exit("no %s under %s (a build folder, or a folder holding it)" % (name, build))


def table(title, unit, rows, first):
    print("\n" + title)
    print("%-4s %5s %8s %6s %5s %5s %8s %7s %7s %7s %8s %7s %6s" % (
        unit, "jobs", "jobs/s", "ratio", "eff", "busy", "solve ms", "cpu ms", "pg ms", "faults",
        "wall j/s", "submit", "span"))
    base = rows[0][1]["rate"]
    for k, r in rows:
        ratio = r["rate"] / base
        print("%-4s %5d %8.1f %6.2f %5.2f %5.2f %8.1f %7.1f %7s %7.0f %8.1f %7.2f %6.2f" % (
            k, r["n"], r["rate"], ratio, ratio / (k / first), r["busy"], r["solve_ms"], r["d_ms"],
            "%.2f" % r["pg_ms"] if r["pg_ms"] > 0 else "-", r["faults"], r["wall_rate"],
            r["submit"], r["span"]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("build")
    ap.add_argument("--workers", type=counts, default=[1, 2, 4, 8, 16],
                    help="table (a): workers of the one SQLite daemon (default 1,2,4,8,16)")
    ap.add_argument("--replicas", type=counts, default=[1, 2, 4, 8],
                    help="table (b): replicas on one PostgreSQL (default 1,2,4,8)")
    ap.add_argument("--workers-per-replica", type=int, default=2)
    ap.add_argument("--jobs", type=int, default=30,
                    help="jobs per worker in a row (a row with T workers in all runs jobs*T)")
    ap.add_argument("--speeds", type=int, default=11, help="speeds per job (default 11)")
    ap.add_argument("--clients", type=int, default=16, help="client threads that submit")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--sqlite-only", action="store_true")
    g.add_argument("--pg-only", action="store_true")
    ap.add_argument("--pg-bin", help="PostgreSQL bin folder (initdb, pg_ctl, postgres, createdb)")
    ap.add_argument("--wrk", action="store_true", help="add the cache-hit GET rate (wrk)")
    ap.add_argument("--seconds", type=int, default=5, help="wrk's duration")
    ap.add_argument("--daemon-env", action="append", default=[], metavar="KEY=VALUE",
                    help="an environment variable for the daemons only (repeatable)")
    a = ap.parse_args()
    if a.speeds < 1 or a.jobs < 1 or a.workers_per_replica < 1 or a.clients < 1:
        ap.error("--speeds, --jobs, --workers-per-replica and --clients must be >= 1")
    if a.pg_bin:
        os.environ["PG_BINDIR"] = os.path.abspath(a.pg_bin)
    exe = find_exe(a.build, "spinmodald")
    env = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    for kv in a.daemon_env:
        if "=" not in kv:
            ap.error("--daemon-env takes KEY=VALUE: %r" % kv)
        env[kv.split("=", 1)[0]] = kv.split("=", 1)[1]
    # the harness scales its waits by a reference solve of the CLI beside the daemon
    os.environ.setdefault("SPINMODAL_TEST_CLI", find_exe(os.path.dirname(exe), "spinmodal"))
    print("spinmodald %s; nproc %d (os.cpu_count %d); load %s; %s"
          % (exe, len(os.sched_getaffinity(0)), os.cpu_count(),
             " ".join("%.2f" % x for x in os.getloadavg()), os.uname().release))
    print("jobs: %d-speed sweeps of angled-beam-90 (48 elements, planar, mode_shapes false), %d per"
          " worker in a row, all distinct; submitted by %d client threads (one connection each POST),"
          " round-robin over replicas; completion polled by 2 list requests every 2%% of the elapsed"
          " time; rate = jobs / (last finished_at - first started_at) of the daemon's own timestamps"
          % (a.speeds, a.jobs, a.clients))
    if a.daemon_env:
        print("daemon environment: %s" % " ".join(a.daemon_env))
    tmp = tempfile.mkdtemp(prefix="spinmodal-bench-replicas-")
    sq, pgr, gets = [], [], []
    pg = None
    try:
        if not a.pg_only:
            for w in a.workers:
                d = Daemon(exe, tmp, ["--workers", str(w)], name="sqlite-w%d" % w, env=env)
                d.start()
                try:
                    r = throughput([d], a.jobs * w, a.speeds, a.clients, w)
                    if a.wrk and w == a.workers[0]:
                        gets.append(("SQLite, 1 daemon", wrk(d, r["job"], a.seconds)))
                finally:
                    d.stop()
                sq.append((w, r))
                print("  sqlite %2d workers: %.1f jobs/s" % (w, r["rate"]), flush=True)
        if not a.sqlite_only:
            if not Postgres.find_bindir():
                print("no PostgreSQL server binaries (--pg-bin DIR, PG_BINDIR or /usr/lib/postgresql):"
                      " table (b) skipped")
            else:
                pg = Postgres(tmp)
                pg.start()
                print("PostgreSQL: %s (fsync off, as %s)" % (pg.bindir, "nobody" if pg.drop else "this user"))
                wpr = a.workers_per_replica
                for n in a.replicas:
                    db = "bench_r%d" % n
                    pg._run([os.path.join(pg.bindir, "createdb"), "-h", "127.0.0.1", "-p",
                             str(pg.port), "-U", "postgres", db])
                    dsn = "postgresql://postgres@127.0.0.1:%d/%s" % (pg.port, db)
                    ds = []
                    try:
                        for k in range(n):
                            x = Daemon(exe, tmp, ["--workers", str(wpr), "--replica-id", "r%d-%d" % (n, k)],
                                       db=dsn, name="pg%d-%d" % (n, k), env=env)
                            x.start()
                            ds.append(x)
                        r = throughput(ds, a.jobs * wpr * n, a.speeds, a.clients, wpr * n)
                        if a.wrk and n == a.replicas[0]:
                            gets.append(("PostgreSQL, 1 replica", wrk(ds[0], r["job"], a.seconds)))
                    finally:
                        for x in ds:
                            x.stop()
                    pgr.append((n, r))
                    print("  pg %d x %d workers: %.1f jobs/s" % (n, wpr, r["rate"]), flush=True)
    finally:
        if pg:
            pg.remove()
        shutil.rmtree(tmp, ignore_errors=True)
    if sq:
        table("(a) one daemon, SQLite, W workers (ratio to W=%d; eff = ratio / (W/%d))"
              % (sq[0][0], sq[0][0]), "W", sq, sq[0][0])
    if pgr:
        table("(b) N replicas x %d workers, one PostgreSQL (ratio to N=%d; eff = ratio / (N/%d))"
              % (a.workers_per_replica, pgr[0][0], pgr[0][0]), "N", pgr, pgr[0][0])
    for name, g in gets:
        print("%-24s GET hit/s %s  p99 ms %s" % (name, "%.0f" % g[0] if g and g[0] else "-",
                                                 "%.2f" % g[1] if g and g[1] else "-"))
    if a.wrk and not shutil.which("wrk"):
        print("wrk not found: no GET row")
    most = max([w for w, _ in sq] + [n * a.workers_per_replica for n, _ in pgr] + [1])
    cores = len(os.sched_getaffinity(0))
    print("\n%d cores, load after %s." % (cores, " ".join("%.2f" % x for x in os.getloadavg())))
    if most > cores:
        print("Note: rows with more workers than the %d cores share them (and the client and"
              " PostgreSQL run here too): those rows show the overhead of sharing, not scaling."
              % cores)
    return 0


if __name__ == "__main__":
    sys.exit(main())
