#!/usr/bin/env python3
"""Throughput of spinmodald with SQLite and with 1, 2, 3 replicas on one PostgreSQL.

A benchmark, not a test (`meson test` never runs it).  In one run, on the same
machine: N distinct small jobs (the angled beam, one speed each, no shapes)
submitted at once round-robin over the replicas, timed until the last is done
(jobs/s); then the cache-hit GET rate and p99 latency of one replica with wrk
(Debian package wrk) for SQLite and PostgreSQL.  Figures are printed as ratios
to the SQLite single daemon, measured in this one run.

usage: python3 tests/bench/bench_replicas.py BUILD_DIR [--jobs N] [--workers W] [--seconds S]
PostgreSQL comes from the server binaries (as in tests/e2e/replicas_test.py).
On a 2-core machine the replicas share the same two cores, so more replicas
cannot add throughput here: see the printed note.
"""
import argparse
import concurrent.futures
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir)
sys.path.insert(0, os.path.join(ROOT, "tests", "e2e"))
from daemon import Daemon  # noqa: E402
from replicas_test import Postgres  # noqa: E402


def body(i):
    with open(os.path.join(ROOT, "examples", "angled-beam-90.json")) as f:
        req = json.load(f)
    req["analysis"]["omega"] = 1.0 + 0.001 * i + 1e-7 * time.time() % 1e-3
    req["analysis"]["mode_shapes"] = False
    return json.dumps(req).encode()


def throughput(daemons, n):
    js = {"Content-Type": "application/json"}
    reqs = [body(i) for i in range(n)]
    t0 = time.monotonic()
    with concurrent.futures.ThreadPoolExecutor(16) as ex:
        ids = list(ex.map(lambda k: daemons[k % len(daemons)].request(
            "POST", "/v1/analyses", body=reqs[k], headers=js).json()["id"], range(n)))
    pending = set(ids)
    while pending:
        for j in list(pending):
            if daemons[0].get("/v1/analyses/" + j).json()["state"] in ("done", "failed"):
                pending.discard(j)
        time.sleep(0.05)
    return n / (time.monotonic() - t0), ids[0]


def wrk(d, job, seconds):
    if not shutil.which("wrk"):
        return None, None
    out = subprocess.run(["wrk", "-t2", "-c32", "-d%ds" % seconds, "--latency",
                          "http://127.0.0.1:%d/v1/analyses/%s" % (d.port, job)],
                         capture_output=True, text=True).stdout
    rate = re.search(r"Requests/sec:\s+([\d.]+)", out)
    p99 = re.search(r"99%\s+([\d.]+)(us|ms|s)", out)
    scale = {"us": 1e-3, "ms": 1.0, "s": 1e3}
    return (float(rate.group(1)) if rate else None,
            float(p99.group(1)) * scale[p99.group(2)] if p99 else None)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("build")
    ap.add_argument("--jobs", type=int, default=300)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--seconds", type=int, default=5)
    a = ap.parse_args()
    exe = os.path.abspath(os.path.join(a.build, "server", "spinmodald"))
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    tmp = tempfile.mkdtemp(prefix="spinmodal-bench-replicas-")
    rows = []
    pg = Postgres(tmp)
    try:
        d = Daemon(exe, tmp, ["--workers", str(a.workers)], name="sqlite", env=env)
        d.start()
        rate, job = throughput([d], a.jobs)
        g, p = wrk(d, job, a.seconds)
        rows.append(("SQLite, 1 daemon", rate, g, p))
        d.stop()
        pg.start()
        for n in (1, 2, 3):
            ds = []
            for k in range(n):
                x = Daemon(exe, tmp, ["--workers", str(a.workers), "--replica-id", "b%d%d" % (n, k)],
                           db=pg.dsn(), name="pg%d-%d" % (n, k), env=env)
                x.start()
                ds.append(x)
            rate, job = throughput(ds, a.jobs)
            g, p = wrk(ds[0], job, a.seconds) if n == 1 else (None, None)
            rows.append(("PostgreSQL, %d replica%s" % (n, "s" if n > 1 else ""), rate, g, p))
            for x in ds:
                x.stop()
    finally:
        pg.remove()
        shutil.rmtree(tmp, ignore_errors=True)
    base = rows[0][1]
    print("\n%-24s %10s %8s %12s %9s" % ("setup", "jobs/s", "ratio", "GET hit/s", "p99 ms"))
    for name, rate, g, p in rows:
        print("%-24s %10.1f %8.2f %12s %9s" % (name, rate, rate / base,
                                               "%.0f" % g if g else "-", "%.2f" % p if p else "-"))
    print("\n%d jobs, %d worker(s) per replica, %d cores, load %.1f.  Every replica here shares the"
          " same cores and the same PostgreSQL (fsync off), so the replica rows show the overhead"
          " of sharing the queue, not scaling: on a cluster each replica brings its own cores."
          % (a.jobs, a.workers, os.cpu_count(), os.getloadavg()[0]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
