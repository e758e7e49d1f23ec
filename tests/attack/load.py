"""Load figures (attack.py, categories 'load' and 'soak').

load  GET /v1/analyses/{id} of a done job (the example, 3 modes with shapes: the
      cached read that tests/bench/bench_http.sh measures as (a)) for --load
      seconds: requests per second and p99 latency.  With wrk on PATH (Debian
      package wrk) it is `wrk -t2 -c32 --latency`, as the benchmark; without it
      a Python client (2 processes x 8 keep-alive connections: slower than
      wrk, the figure says which).  Every answer must be 200.
soak  --soak seconds of a mixed loop on one daemon: distinct small submissions,
      status and result reads, identical resubmissions (cache hits) and
      malformed POST /v1/validate bodies, from 2 threads.  The daemon's RSS is
      sampled every second (start, end, max, and the mean of the last tenth
      against the second tenth: the growth a leak would show); the database
      size (file + WAL) is divided by the jobs stored.  No answer may be a 5xx,
      no solved result may hold a NaN.
"""
import http.client
import json
import multiprocessing
import os
import re
import shutil
import subprocess
import threading
import time

from common import (EXAMPLE, Daemon, db_bytes, rss_kb, small_request, solved_nan, timescale)


def _done_example(d):
    with open(EXAMPLE, "rb") as f:
        body = f.read()
    r = d.request("POST", "/v1/analyses?wait=%g" % timescale.wait_param(60), body=body,
                  headers={"Content-Type": "application/json"})
    doc = r.json() or {}
    if doc.get("state") != "done":
        raise RuntimeError("the example job is %s" % doc.get("state"))
    return doc["id"], len(r.body)


def _wrk(url, seconds):
    p = subprocess.run(["wrk", "-t2", "-c32", "-d%ds" % max(1, int(round(seconds))), "--timeout",
                        "5s", "--latency", url], capture_output=True, text=True,
                       timeout=seconds + 60)
    text = p.stdout
    rps = float(re.search(r"Requests/sec:\s*([0-9.]+)", text).group(1))
    m = re.search(r"^\s*99%\s+([0-9.]+)(us|ms|s)\s*$", text, re.M)
    p99 = float(m.group(1)) * {"us": 1e-3, "ms": 1.0, "s": 1e3}[m.group(2)]
    m = re.search(r"Non-2xx or 3xx responses:\s*([0-9]+)", text)
    bad = int(m.group(1)) if m else 0
    m = re.search(r"Socket errors:.*", text)
    if m:
        bad += sum(int(x) for x in re.findall(r"[0-9]+", m.group(0)))
    total = int(re.search(r"([0-9]+) requests in", text).group(1))
    return rps, p99, bad, total


def _py_worker(args):
    host, port, path, seconds, conns = args
    lat, bad = [], 0
    cs = [http.client.HTTPConnection(host, port, timeout=10) for _ in range(conns)]
    end = time.monotonic() + seconds
    i = 0
    while time.monotonic() < end:
        c = cs[i % conns]
        i += 1
        t0 = time.perf_counter()
        try:
            c.request("GET", path)
            r = c.getresponse()
            r.read()
            bad += r.status != 200
        except (OSError, http.client.HTTPException):
            bad += 1
            cs[(i - 1) % conns] = http.client.HTTPConnection(host, port, timeout=10)
            continue
        lat.append(time.perf_counter() - t0)
    return lat, bad


def _python_client(d, path, seconds):
    with multiprocessing.Pool(2) as pool:
        parts = pool.map(_py_worker, [(d.host, d.port, path, seconds, 8)] * 2)
    lat = sorted(x for p in parts for x in p[0])
    bad = sum(p[1] for p in parts)
    p99 = lat[int(0.99 * (len(lat) - 1))] * 1e3 if lat else float("nan")
    return len(lat) / seconds, p99, bad, len(lat) + bad


def category_load(exe, tmp, tally, args, category="load"):
    if args.load <= 0:
        tally.skip("load", "--load 0")
        return
    d = Daemon(exe, tmp, ["--workers", "2"], name="load")
    d.start()
    try:
        jid, size = _done_example(d)
        path = "/v1/analyses/" + jid
        if shutil.which("wrk"):
            how = "wrk -t2 -c32"
            rps, p99, bad, total = _wrk(d.base + path, args.load)
        else:
            how = "Python client, 2 processes x 8 connections (no wrk on PATH)"
            rps, p99, bad, total = _python_client(d, path, args.load)
        tally.add(category, "cached GET answered 200", total - bad)
        tally.add(category, "cached GET not 200 or socket error", bad)
        tally.check(bad == 0, category, "every cached GET answered 200 (%d not)" % bad)
        tally.figure("load: cached GET /v1/analyses/{id} (%d-byte document), %s, %g s"
                     % (size, how, args.load), "%.0f req/s, p99 %.2f ms" % (rps, p99))
    finally:
        rc = d.stop()
        tally.check(rc == 0, category, "load: clean stop (exit %s)" % rc)


BAD_VALIDATES = [b"{", b"[]", b'{"structure": 1}', b'{"analysis": {"omega": NaN}}',
                 b"[" * 5000 + b"]" * 5000, json.dumps(small_request(omega=-1.0)).encode(),
                 json.dumps(small_request(elements=0)).encode()]


def category_soak(exe, tmp, tally, args, category="soak"):
    seconds = args.soak
    if seconds <= 0:
        tally.skip("soak", "--soak 0")
        return
    d = Daemon(exe, tmp, ["--workers", "2"], name="soak")
    d.start()
    pid = d.proc.pid
    samples = [(0.0, rss_kb(pid))]
    stop = threading.Event()
    jobs = {}
    lock = threading.Lock()
    js = {"Content-Type": "application/json"}

    def count(what, r):
        st = r.status if r is not None else "error"
        tally.add(category, "%s %s" % (what, st))
        if isinstance(st, int) and st >= 500:
            tally.broken(category, "%s answered %s: %s" % (what, st, r.text(160)))

    def submitter():
        k = 0
        while not stop.is_set():
            k += 1
            try:
                r = d.post("/v1/analyses", small_request(omega=0.5 + 1e-4 * k,
                                                         elements=2 + k % 4), timeout=30)
                count("POST new job", r)
                if r.status in (200, 202):
                    with lock:
                        jobs[r.json()["id"]] = k
                if k % 5 == 0:
                    r = d.post("/v1/analyses", small_request(omega=0.5 + 1e-4 * (k - 4),
                                                             elements=2 + (k - 4) % 4), timeout=30)
                    count("POST identical (cache)", r)
                with lock:
                    recent = list(jobs)[-3:]
                for jid in recent:
                    r = d.get("/v1/analyses/" + jid, timeout=30)
                    count("GET status", r)
                    doc = r.json() or {}
                    if doc.get("state") == "done":
                        where = solved_nan(doc.get("result"))
                        if where:
                            tally.broken(category, "NaN in job %s: %s" % (jid[:12], where))
                        r = d.get("/v1/analyses/%s/result?format=csv" % jid, timeout=30)
                        count("GET result csv", r)
            except OSError as e:
                tally.add(category, "connection error")
                tally.broken(category, "soak request failed: %r" % e)
            stop.wait(0.02)

    def validator():
        k = 0
        while not stop.is_set():
            body = BAD_VALIDATES[k % len(BAD_VALIDATES)]
            k += 1
            try:
                r = d.request("POST", "/v1/validate", body=body, headers=js, timeout=30)
                count("POST malformed validate", r)
            except OSError as e:
                tally.add(category, "connection error")
                tally.broken(category, "soak validate failed: %r" % e)
            stop.wait(0.01)

    threads = [threading.Thread(target=submitter, daemon=True),
               threading.Thread(target=validator, daemon=True)]
    t0 = time.monotonic()
    for t in threads:
        t.start()
    while time.monotonic() - t0 < seconds and d.alive():
        time.sleep(1.0)
        samples.append((time.monotonic() - t0, rss_kb(pid)))
    stop.set()
    for t in threads:
        t.join(timescale.budget(60))
    alive = d.alive()
    tally.check(alive, category, "the daemon is alive after the soak")
    # let the queue drain, then size the database per job
    def drained():
        r = d.get("/metrics")
        m = re.search(r"^spinmodal_queue_depth (\d+)", r.body.decode(), re.M)
        return m and int(m.group(1)) == 0
    timescale.wait_until(drained, 120, 0.5)
    samples.append((time.monotonic() - t0, rss_kb(pid)))
    stored = len(jobs)
    size = db_bytes(d.db)
    rss = [kb for _, kb in samples if kb > 0]
    n = len(rss)
    early = rss[max(1, n // 10):max(2, n // 5)]
    late = rss[-max(1, n // 10):]
    grow = (sum(late) / len(late)) - (sum(early) / len(early)) if early and late else 0
    rc = d.stop()
    tally.check(rc == 0, category, "soak: clean stop (exit %s)" % rc)
    tally.figure("soak: duration, jobs stored", "%.0f s, %d jobs" % (seconds, stored))
    tally.figure("soak: RSS start / end / max", "%.1f / %.1f / %.1f MB"
                 % (rss[0] / 1024, rss[-1] / 1024, max(rss) / 1024))
    tally.figure("soak: RSS mean of the last tenth minus the second tenth", "%+.1f MB"
                 % (grow / 1024))
    tally.figure("soak: database bytes (file + WAL) per job", "%.0f B (%d bytes, %d jobs)"
                 % (size / max(1, stored), size, stored))
    with open(os.path.join(tmp, "rss.json"), "w") as f:
        json.dump(samples, f)
