#!/usr/bin/env python3
"""End-to-end tests of the spinmodald HTTP daemon against server/DAEMON.md.

Usage: e2e_test.py SPINMODALD SCENARIO [SOURCE_ROOT]     (meson: one test per scenario)
       e2e_test.py SPINMODALD all [SOURCE_ROOT]
       e2e_test.py SPINMODALD list

Each scenario starts its own daemon(s) (tests/e2e/daemon.py) on 127.0.0.1:0 with a
database in a fresh temporary directory, prints one line per check (`ok` / `FAIL`)
and exits 1 on any failure.  On failure the temporary directory (daemon logs,
database) is kept and its path printed.  Schema checks use
tests/contracts/contract.py (contract.load(schemas_dir).validate(instance, name)).

The invalid requests of the `bad_requests` scenario are data: bad_requests.json.

Time: every wait polls for its condition and gives up after a budget scaled to the
machine (tests/e2e/timescale.py: base seconds times a factor from a reference solve
measured at the start and SPINMODAL_TEST_TIME_FACTOR, never past meson's timeout);
checks on an elapsed time use the same scale (timescale.scaled).
"""
import copy
import csv
import hashlib
import io
import json
import math
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import traceback

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.dont_write_bytecode = True   # no __pycache__ in the source tree
import daemon as dm  # noqa: E402
import timescale as ts  # noqa: E402

EXE = None
ROOT = None
CONTRACT = None
CONTRACT_NOTE = None
FAILURES = []
NOTES = []

# base budget (s) for a job to finish; scaled by timescale.budget() like every wait
DONE_TIMEOUT = 120.0

ID_RE = re.compile(r"^[0-9a-f]{64}$")
TS_RE = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z$")
STATES = ("queued", "running", "done", "failed", "canceled")
CSV_HEADER = "omega,mode,frequency_rad_s,frequency_hz,eig_re,eig_im,mac_to_previous,status,per_rev,rpm,label,label_confidence,tracked_index,tracking_flag"


# ------------------------------------------------------------------ checks

def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        FAILURES.append(what)
    return bool(cond)


def note(what):
    print("note " + what, flush=True)
    NOTES.append(what)


def load_contract():
    global CONTRACT, CONTRACT_NOTE
    path = os.path.join(ROOT, "tests", "contracts")
    if not os.path.exists(os.path.join(path, "contract.py")):
        CONTRACT_NOTE = "tests/contracts/contract.py missing: schema checks skipped"
        return
    sys.path.insert(0, path)
    try:
        import contract  # noqa: E402
        CONTRACT = contract.load(os.path.join(ROOT, "schemas"))
    except Exception as e:  # present but unusable (e.g. no jsonschema): a failure, not a skip
        check(False, "tests/contracts/contract.py loads the schemas (%r)" % e)


def schema_ok(instance, name, what):
    """Validate instance as schema `name` with tests/contracts/contract.py."""
    if CONTRACT is None:
        if CONTRACT_NOTE and CONTRACT_NOTE not in NOTES:
            note(CONTRACT_NOTE)
        return True
    try:
        res = CONTRACT.validate(instance, name)
    except Exception as e:  # a validation error (or a broken schema) is a failure
        msg = str(e).splitlines()[0] if str(e) else type(e).__name__
        return check(False, "%s validates as %s: %.400s" % (what, name, msg))
    if res is None or res is True:
        return check(True, "%s validates as %s" % (what, name))
    if isinstance(res, (list, tuple)):
        return check(not res, "%s validates as %s%s" % (what, name, (": %.400s" % (res,)) if res else ""))
    return check(bool(res), "%s validates as %s (%r)" % (what, name, res))


def problem_ok(r, status, what, pointer=None, pointer_prefix=None, schema=True, check_status=True):
    """r is an RFC 9457 problem answer with this status (and pointer)."""
    ok = True
    if check_status:
        ok = check(r.status == status, "%s: status %d (got %s: %s)" % (what, status, r.status, r.text(300)))
    ok &= check(r.media_type() == "application/problem+json",
                "%s: content type application/problem+json (got %r)" % (what, r.ctype()))
    doc = r.json()
    ok &= check(isinstance(doc, dict), "%s: problem body is a JSON object (%s)" % (what, r.text(200)))
    if not isinstance(doc, dict):
        return False
    ok &= check(doc.get("status") == status and isinstance(doc.get("title"), str)
                and isinstance(doc.get("type"), str),
                "%s: problem has type, title and status %d (got %s)" % (what, status, r.text(300)))
    if schema:
        ok &= schema_ok(doc, "Problem", what + ": problem")
    errs = doc.get("errors") or []
    ptrs = [e.get("pointer") for e in errs if isinstance(e, dict)]
    if pointer is not None:
        ok &= check(pointer in ptrs, "%s: errors has pointer %r (got %s)" % (what, pointer, ptrs))
    if pointer_prefix is not None:
        ok &= check(any(isinstance(p, str) and p.startswith(pointer_prefix) for p in ptrs),
                    "%s: errors has a pointer under %r (got %s)" % (what, pointer_prefix, ptrs))
    return ok


# ------------------------------------------------------------------ requests

SECTION = {"E": 7e10, "A": 4e-4, "I": 2e-7, "mass_per_length": 1.2}


def angled(n1=24, n2=24, omega=20, frames=None, **analysis):
    """The paper's beta = 90 deg angled beam (DESIGN.md section 3)."""
    req = {
        "structure": {
            "joints": {"O": [0, 0], "C": [5, 0], "P": [5, 5]},
            "sections": {"al": dict(SECTION)},
            "members": [
                {"id": "beam1", "from": "O", "to": "C", "section": "al", "elements": n1},
                {"id": "beam2", "from": "C", "to": "P", "section": "al", "elements": n2},
            ],
            "clamp": "O",
        },
        "analysis": {"omega": omega},
    }
    if frames is not None:
        req["frames"] = frames
    req["analysis"].update(analysis)
    return req


def table2_rf16():
    """Kim & Yoo (2006) Table 2, RF = 16 (tests/core/test_table2.c): basis "paper",
    no Coriolis, lumped mass, 24 + 24 elements, 3 elements per frame = 16 frames,
    stiffening on, Omega = 20 rad/s."""
    return angled(24, 24, 20, frames={"elements_per_frame": 3}, modes=3, geometric_stiffening=True,
                  coriolis=False, mass="lumped", substructure_modes="paper", mode_shapes=False)


TABLE2_RF16 = [7.3305, 49.5084, 107.8880]


def small(omega=10.0, **analysis):
    """A 4 + 4 element angled beam: a few milliseconds per speed."""
    a = {"mode_shapes": False}
    a.update(analysis)
    return angled(4, 4, omega, **a)


def long_sweep(n=32):
    """1001 speeds of a 32 + 32 element beam, per-element frames: ~12 s uninterrupted
    (much longer under ASan).  Used where a job must keep running; always canceled."""
    return angled(n, n, [20.0 * i / 1000 for i in range(1001)], mode_shapes=False)


def example(name):
    with open(os.path.join(ROOT, "examples", name)) as f:
        return json.load(f)


def reorder(obj):
    """The same JSON with every object's keys in reverse order."""
    if isinstance(obj, dict):
        return {k: reorder(obj[k]) for k in reversed(list(obj))}
    if isinstance(obj, list):
        return [reorder(v) for v in obj]
    return obj


# ------------------------------------------------------------------ daemon helpers

class Scenario:
    """Temporary directory and the daemons of one scenario (killed at the end)."""

    def __init__(self, name):
        self.name = name
        self.tmp = tempfile.mkdtemp(prefix="spinmodal-e2e-%s-" % name)
        self.daemons = []

    def daemon(self, args=(), name=None, start=True, **kw):
        d = dm.Daemon(EXE, self.tmp, list(args), name=name or "d%d" % (len(self.daemons) + 1), **kw)
        self.daemons.append(d)
        if start:
            d.start()
        return d

    def cleanup(self, failed):
        for d in self.daemons:
            if d.alive():
                d.kill()
        if failed:
            print("kept %s (daemon logs, databases)" % self.tmp)
            for d in self.daemons:
                if d.logpath and os.path.exists(d.logpath):
                    print("---- tail of %s" % d.logpath)
                    print(d.log_tail(25))
        else:
            shutil.rmtree(self.tmp, ignore_errors=True)


def stop_clean(d, what):
    """SIGTERM: exit status 0 and an `event=stopped` log line."""
    t0 = time.monotonic()
    rc = d.stop()
    check(rc == 0, "%s: SIGTERM -> exit status 0 (got %s, %.1f s)" % (what, rc, time.monotonic() - t0))
    check(d.stopped_logged(), "%s: log has an event=stopped line" % what)
    return rc


def job_path(jid):
    return "/v1/analyses/" + jid


def poll(d, jid, until=("done", "failed", "canceled"), timeout=DONE_TIMEOUT, interval=0.05, pred=None):
    """GET the job until its state is in `until` (or pred(doc) is true) or
    budget(timeout) runs out; the last doc."""
    deadline = time.monotonic() + ts.budget(timeout)
    doc = None
    while True:
        r = d.get(job_path(jid))
        doc = r.json() if r.status == 200 else None
        if doc is not None:
            if pred is not None and pred(doc):
                return doc
            if pred is None and doc.get("state") in until:
                return doc
        if time.monotonic() > deadline:
            return doc
        time.sleep(interval)


def submit(d, req, wait=None, headers=None):
    path = "/v1/analyses" + ("?wait=%s" % wait if wait is not None else "")
    return d.post(path, req, headers=headers)


def submit_id(d, req, what, wait=None, expect=(202, 200), headers=None):
    r = submit(d, req, wait, headers)
    doc = r.json() or {}
    check(r.status in expect and ID_RE.match(str(doc.get("id", ""))) is not None,
          "%s: POST -> %s with an id (got %s %s)" % (what, "/".join(map(str, expect)), r.status, r.text(300)))
    return doc.get("id"), r


def run_until_running(d, req, what):
    jid, r = submit_id(d, req, what, expect=(202,))
    doc = poll(d, jid, pred=lambda x: x.get("state") != "queued", timeout=60) if jid else None
    check(doc is not None and doc.get("state") == "running",
          "%s: job is running (state %s)" % (what, doc and doc.get("state")))
    return jid


def freqs(result):
    return [[m["frequency_rad_s"] for m in c.get("modes", [])] for c in result["cases"]]


def metrics(d):
    r = d.get("/metrics")
    return r, parse_prometheus(r.body.decode("utf-8", "replace"))


def parse_prometheus(text):
    """{'samples': [(name, {labels}, value)], 'types': {name: type}}"""
    samples, types, helps = [], {}, {}
    for line in text.splitlines():
        if line.startswith("# TYPE "):
            parts = line.split()
            if len(parts) >= 4:
                types[parts[2]] = parts[3]
            continue
        if line.startswith("# HELP "):
            parts = line.split(None, 3)
            if len(parts) >= 3:
                helps[parts[2]] = True
            continue
        if not line.strip() or line.startswith("#"):
            continue
        m = re.match(r"^([a-zA-Z_:][a-zA-Z0-9_:]*)(?:\{(.*)\})?\s+(\S+)(?:\s+-?\d+)?\s*$", line)
        if not m:
            samples.append(("__unparsable__", {"line": line}, float("nan")))
            continue
        labels = {k: re.sub(r"\\(.)", lambda x: {"n": "\n"}.get(x.group(1), x.group(1)), v)
                  for k, v in re.findall(r'([a-zA-Z_][a-zA-Z0-9_]*)="((?:[^"\\]|\\.)*)"', m.group(2) or "")}
        try:
            val = float(m.group(3))
        except ValueError:
            val = float("nan")
        samples.append((m.group(1), labels, val))
    return {"samples": samples, "types": types, "helps": helps}


def mval(pm, name, **labels):
    """Sum of the samples of `name` whose labels include `labels`; None when none."""
    vals = [v for n, l, v in pm["samples"] if n == name and all(l.get(k) == str(x) for k, x in labels.items())]
    return sum(vals) if vals else None


# ================================================================== scenarios

def t_submit(sc):
    """submit -> poll -> result: the Table 2 RF16 numbers; Location; Job/result schemas."""
    d = sc.daemon(["--workers", "2"])
    req = table2_rf16()
    r = submit(d, req)
    doc = r.json() or {}
    check(r.status == 202, "submit: POST -> 202 (got %s %s)" % (r.status, r.text(300)))
    check(r.media_type() == "application/json", "submit: status document is application/json (%r)" % r.ctype())
    jid = doc.get("id", "")
    check(ID_RE.match(jid) is not None, "submit: id is 64 lowercase hex digits (%r)" % jid)
    loc = r.headers.get("Location") or ""
    check(loc.endswith("/v1/analyses/" + jid) and (loc.startswith("/") or loc.startswith("http")),
          "submit: Location points to the job (%r)" % loc)
    check(doc.get("state") in ("queued", "running"), "submit: state queued or running (%s)" % doc.get("state"))
    check(doc.get("progress", {}).get("total") == 1, "submit: progress.total 1 (%s)" % doc.get("progress"))
    check(doc.get("links", {}).get("self") == job_path(jid)
          and doc.get("links", {}).get("result") == job_path(jid) + "/result",
          "submit: links self/result (%s)" % doc.get("links"))
    check(TS_RE.match(str(doc.get("created_at"))) is not None, "submit: created_at RFC 3339 ms UTC (%s)"
          % doc.get("created_at"))
    check(doc.get("finished_at") is None and doc.get("error") is None and doc.get("cancel_requested") is False,
          "submit: finished_at/error null, cancel_requested false")
    check("result" not in doc or doc.get("result") is None, "submit: no result before done")
    schema_ok(doc, "Job", "submit: 202 status document")
    # follow the Location
    path = re.sub(r"^https?://[^/]+", "", loc) or job_path(jid)
    r2 = d.get(path)
    check(r2.status == 200 and (r2.json() or {}).get("id") == jid, "submit: GET Location -> 200 the job (%s)" % r2.status)
    done = poll(d, jid)
    check(done is not None and done.get("state") == "done", "submit: job done (state %s, error %s)"
          % (done and done.get("state"), done and done.get("error")))
    if not done or done.get("state") != "done":
        return
    schema_ok(done, "Job", "submit: done status document")
    check(done["progress"] == {"done": 1, "total": 1}, "submit: progress 1/1 (%s)" % done["progress"])
    check(done.get("attempts") == 1, "submit: attempts 1 (%s)" % done.get("attempts"))
    ts = [done.get(k) for k in ("created_at", "started_at", "finished_at")]
    check(all(TS_RE.match(str(t)) for t in ts) and ts[0] <= ts[1] <= ts[2],
          "submit: created <= started <= finished, RFC 3339 ms UTC (%s)" % ts)
    check(done.get("error") is None, "submit: error null")
    rr = d.get(job_path(jid) + "/result")
    check(rr.status == 200 and rr.media_type() == "application/json",
          "submit: GET /result -> 200 application/json (%s %r)" % (rr.status, rr.ctype()))
    res = rr.json()
    if not check(isinstance(res, dict), "submit: result is JSON"):
        return
    schema_ok(res, "result", "submit: result document")
    check(done.get("result") == res, "submit: status document's result equals /result")
    w = freqs(res)[0]
    check(len(w) == 3 and all(abs(a - b) <= 0.01 for a, b in zip(w, TABLE2_RF16)),
          "submit: Table 2 RF16 omega_1..3 = %s within 0.01 of %s" % (["%.4f" % x for x in w], TABLE2_RF16))
    check(res.get("model", {}).get("frames") == 16 and res["model"].get("elements") == 48,
          "submit: model 48 elements, 16 frames (%s)" % res.get("model"))
    check(res["cases"][0]["status"] == "solved", "submit: case solved")
    solver = res.get("solver", {})
    want = hashlib.sha256(("%s:%s" % (solver.get("request_sha256"), solver.get("version"))).encode()).hexdigest()
    check(jid == want, "submit: id = sha256(request_sha256 ':' version)")
    check(d.wait_log(r"event=job_done\b.*\bjob=%s" % jid[:12], 5) is not None, "submit: log has event=job_done for the job")
    check(d.wait_log(r"event=request\b.*\bmethod=POST\b.*\bpath=/v1/analyses\b.*\bstatus=202\b.*\bjob=%s" % jid[:12], 5)
          is not None, "submit: log has the POST request line with status=202 and job=ID")
    stop_clean(d, "submit")
    bad = [l for l in d.log_lines() if not re.match(r"^ts=\d{4}-\d\d-\d\dT[\d:.]+Z level=(debug|info|warn|error) event=\w+", l)]
    check(not bad, "submit: every log line is logfmt `ts=... level=... event=...` (%s)" % bad[:2])


def t_resubmit(sc):
    """Identical resubmission: 200, same id, the result, a cache hit; canonical id."""
    d = sc.daemon(["--workers", "2"])
    req = small(12)
    jid, r = submit_id(d, req, "resubmit: first", expect=(202,))
    if not jid:
        return
    done = poll(d, jid)
    check(done and done.get("state") == "done", "resubmit: first job done")
    _, m0 = metrics(d)
    hits0 = mval(m0, "spinmodal_cache_hits_total") or 0
    r2 = submit(d, req)
    doc2 = r2.json() or {}
    check(r2.status == 200 and doc2.get("id") == jid, "resubmit: identical POST -> 200 with the same id (%s %s)"
          % (r2.status, doc2.get("id")))
    check(doc2.get("state") == "done" and isinstance(doc2.get("result"), dict),
          "resubmit: the answer carries the result (state %s)" % doc2.get("state"))
    if isinstance(doc2.get("result"), dict):
        rr = d.get(job_path(jid) + "/result")
        check(rr.json() == doc2["result"], "resubmit: result equals GET /result")
    schema_ok(doc2, "Job", "resubmit: 200 status document")
    _, m1 = metrics(d)
    hits1 = mval(m1, "spinmodal_cache_hits_total")
    check(hits1 is not None and hits1 >= hits0 + 1, "resubmit: spinmodal_cache_hits_total %s -> %s" % (hits0, hits1))
    variants = {
        "keys in reverse order": reorder(req),
        "explicit defaults": angled(4, 4, 12, frames="per_element", modes=3, geometric_stiffening=True,
                                    coriolis=True, mass="lumped", substructure_modes="augmented",
                                    modes_per_frame="all", mode_shapes=False),
        "omega 12.0 written as 1.2e1 and point_masses []": None,
    }
    text = json.dumps(req).replace('"omega": 12', '"omega": 1.2e1').replace('"clamp": "O"', '"clamp": "O", "point_masses": []')
    for what, v in variants.items():
        if v is None:
            r3 = d.request("POST", "/v1/analyses", body=text, headers={"Content-Type": "application/json"})
        else:
            r3 = submit(d, v)
        check(r3.status == 200 and (r3.json() or {}).get("id") == jid,
              "resubmit: %s -> 200, same id (%s %s)" % (what, r3.status, (r3.json() or {}).get("id")))
    other = small(12, modes=4)
    r4 = submit(d, other)
    check(r4.status == 202 and (r4.json() or {}).get("id") not in (None, jid),
          "resubmit: a different request (modes 4) -> 202, another id (%s)" % r4.status)
    _, m2 = metrics(d)
    check((mval(m2, "spinmodal_cache_misses_total") or 0) >= 2,
          "resubmit: spinmodal_cache_misses_total counts the 2 new jobs (%s)" % mval(m2, "spinmodal_cache_misses_total"))
    stop_clean(d, "resubmit")


def t_wait(sc):
    """?wait=S on POST and GET; bad wait values -> 400 /query/wait."""
    d = sc.daemon(["--workers", "1"])
    t0 = time.monotonic()
    w30 = ts.wait_param(30)
    r = submit(d, small(11), wait=w30)
    el = time.monotonic() - t0
    doc = r.json() or {}
    check(r.status == 200 and doc.get("state") == "done" and isinstance(doc.get("result"), dict),
          "wait: POST ?wait=%g of a small job -> 200 done with the result (%s %s, %.2f s)"
          % (w30, r.status, doc.get("state"), el))
    schema_ok(doc, "Job", "wait: POST ?wait=%g answer" % w30)
    t0 = time.monotonic()
    r = submit(d, long_sweep(), wait=0.1)
    el = time.monotonic() - t0
    doc = r.json() or {}
    lid = doc.get("id")
    check(r.status == 202 and doc.get("state") in ("queued", "running"),
          "wait: POST ?wait=0.1 of a long sweep -> 202 queued/running (%s %s)" % (r.status, doc.get("state")))
    check(0.09 <= el < ts.scaled(5), "wait: POST ?wait=0.1 blocked about 0.1 s (%.3f s, at most %.1f)"
          % (el, ts.scaled(5)))
    check(r.headers.get("Location", "").endswith(job_path(str(lid))), "wait: 202 has Location")
    if lid:
        poll(d, lid, pred=lambda x: x.get("state") == "running", timeout=30)
        t0 = time.monotonic()
        r = d.get(job_path(lid) + "?wait=0.5")
        el = time.monotonic() - t0
        check(r.status == 200 and (r.json() or {}).get("state") == "running" and 0.45 <= el < ts.scaled(5),
              "wait: GET ?wait=0.5 of the running sweep -> 200 running after ~0.5 s (%s %s, %.3f s, at most %.1f)"
              % (r.status, (r.json() or {}).get("state"), el, ts.scaled(5)))
        t0 = time.monotonic()
        r = d.get(job_path(lid) + "?wait=0")
        el = time.monotonic() - t0
        check(r.status == 200 and el < ts.scaled(2), "wait: GET ?wait=0 -> 200 at once (%.3f s, at most %.1f)"
              % (el, ts.scaled(2)))
        for bad in ("-1", "100", "abc", "", "60.5", "nan", "inf", "1e999"):
            rb = d.get(job_path(lid) + "?wait=" + bad)
            problem_ok(rb, 400, "wait: GET ?wait=%s" % bad, pointer="/query/wait")
        for bad in ("-1", "100", "abc"):
            rb = submit(d, small(11.5), wait=bad)
            problem_ok(rb, 400, "wait: POST ?wait=%s" % bad, pointer="/query/wait")
        rr = d.delete(job_path(lid))
        check(rr.status == 202, "wait: DELETE the running sweep -> 202 (%s)" % rr.status)
    # GET ?wait= until a queued job is done
    sid, _ = submit_id(d, small(11.25), "wait: queue a small job", expect=(202,))
    if sid:
        t0 = time.monotonic()
        r = d.get(job_path(sid) + "?wait=%g" % w30)
        doc = r.json() or {}
        check(r.status == 200 and doc.get("state") == "done" and isinstance(doc.get("result"), dict),
              "wait: GET ?wait=%g of a small job -> 200 done with the result (%s, %.2f s)"
              % (w30, doc.get("state"), time.monotonic() - t0))
    # the job submitted with a bad wait must not exist
    r = d.get("/v1/analyses?limit=100")
    ids = [it.get("id") for it in (r.json() or {}).get("items", [])]
    check(len(ids) == 3, "wait: POSTs with a bad wait stored nothing (%d jobs listed, want 3)" % len(ids))
    if lid:
        poll(d, lid, timeout=60)
    stop_clean(d, "wait")


def t_cancel(sc):
    """DELETE running (202 -> canceled), queued (200), done (409); resubmission of canceled."""
    d = sc.daemon(["--workers", "1"])
    lid = run_until_running(d, long_sweep(), "cancel: long sweep")
    qid, r = submit_id(d, small(13), "cancel: queued job", expect=(202,))
    check((r.json() or {}).get("state") == "queued", "cancel: second job is queued behind the sweep (%s)"
          % (r.json() or {}).get("state"))
    if qid:
        r = d.delete(job_path(qid))
        doc = r.json() or {}
        check(r.status == 200 and doc.get("state") == "canceled",
              "cancel: DELETE queued -> 200 canceled (%s %s)" % (r.status, doc.get("state")))
        schema_ok(doc, "Job", "cancel: DELETE queued answer")
        g = d.get(job_path(qid)).json() or {}
        check(g.get("state") == "canceled" and TS_RE.match(str(g.get("finished_at"))) is not None,
              "cancel: canceled job has state canceled and finished_at (%s %s)" % (g.get("state"), g.get("finished_at")))
        problem_ok(d.get(job_path(qid) + "/result"), 409, "cancel: GET /result of a canceled job")
        problem_ok(d.delete(job_path(qid)), 409, "cancel: DELETE of a canceled job")
    if lid:
        t0 = time.monotonic()
        r = d.delete(job_path(lid))
        doc = r.json() or {}
        check(r.status == 202 and doc.get("cancel_requested") is True,
              "cancel: DELETE running -> 202 with cancel_requested true (%s %s)" % (r.status, r.text(200)))
        schema_ok(doc, "Job", "cancel: DELETE running answer")
        g = poll(d, lid, timeout=60, interval=0.02)
        el = time.monotonic() - t0
        check(g and g.get("state") == "canceled", "cancel: running job becomes canceled (%s)" % (g and g.get("state")))
        check(el < ts.scaled(5), "cancel: canceled within %.1f s (5 s unloaded) (%.2f s)" % (ts.scaled(5), el))
        if g:
            check(g["progress"]["done"] < g["progress"]["total"],
                  "cancel: progress stopped early (%s)" % g["progress"])
            schema_ok(g, "Job", "cancel: canceled status document")
        problem_ok(d.get(job_path(lid) + "/result"), 409, "cancel: GET /result of the canceled sweep")
    # DELETE of a done job
    did, r = submit_id(d, small(14), "cancel: small job", wait=ts.wait_param(30), expect=(200,))
    if did:
        rr = d.delete(job_path(did))
        problem_ok(rr, 409, "cancel: DELETE of a done job")
        check((d.get(job_path(did)).json() or {}).get("state") == "done", "cancel: done job is still done")
    problem_ok(d.delete(job_path("0" * 64)), 404, "cancel: DELETE of an unknown id")
    # resubmission of a canceled job
    if qid:
        r = submit(d, small(13))
        doc = r.json() or {}
        check(r.status == 202 and doc.get("id") == qid and doc.get("state") in ("queued", "running"),
              "cancel: resubmission of the canceled job -> 202, same id, queued (%s %s)" % (r.status, doc.get("state")))
        check(doc.get("error") is None and doc.get("cancel_requested") is False,
              "cancel: resubmitted job has no error and cancel_requested false")
        g = poll(d, qid)
        check(g and g.get("state") == "done" and isinstance(g.get("result"), dict),
              "cancel: resubmitted job completes (%s)" % (g and g.get("state")))
        check(g and g.get("attempts") == 1, "cancel: attempts reset to 1 after resubmission (%s)" % (g and g.get("attempts")))
    if lid:
        r = submit(d, long_sweep())
        check(r.status == 202 and (r.json() or {}).get("state") in ("queued", "running"),
              "cancel: resubmission of the canceled sweep -> 202 (%s)" % r.status)
        g = poll(d, lid, pred=lambda x: x.get("state") == "running", timeout=30)
        check(g and g.get("progress", {}).get("done", 99) < 1001, "cancel: resubmitted sweep runs again")
        r = d.delete(job_path(lid))
        check(r.status in (200, 202), "cancel: DELETE again -> 200/202 (%s)" % r.status)
        g = poll(d, lid, timeout=60)
        check(g and g.get("state") == "canceled", "cancel: canceled again")
    check(d.wait_log(r"event=job_canceled\b", 5) is not None, "cancel: log has event=job_canceled")
    stop_clean(d, "cancel")


def t_solve_threads(sc):
    """--solve-threads (issue 27): a sweep whose speeds' eigen-analyses run on 4 threads gives the
    bytes of one thread (JSON without its timings, and CSV) and the CLI's document; a running sweep
    on 4 threads stops on DELETE; 0 or 65 threads are refused at start (exit 64)."""
    req = angled(12, 12, [20.0 * i / 30 for i in range(31)])
    texts = {}
    for t in (1, 4):
        d = sc.daemon(["--workers", "1", "--solve-threads", str(t)], name="threads%d" % t)
        jid, r = submit_id(d, req, "solve_threads: %d thread(s)" % t)
        g = poll(d, jid) if jid else None
        if check(g and g.get("state") == "done", "solve_threads: %d thread(s): sweep done (%s)"
                 % (t, g and g.get("state"))):
            body = d.get(job_path(jid) + "/result").body
            texts[t] = (re.sub(rb',?"timing_ms":\{[^}]*\}', b"", body),
                        d.get(job_path(jid) + "/result?format=csv").body)
        if t == 4:
            lid = run_until_running(d, long_sweep(), "solve_threads: long sweep")
            if lid:
                t0 = time.monotonic()
                r = d.delete(job_path(lid))
                check(r.status == 202, "solve_threads: DELETE running sweep -> 202 (%s)" % r.status)
                g = poll(d, lid, timeout=60, interval=0.02)
                el = time.monotonic() - t0
                check(g and g.get("state") == "canceled" and g["progress"]["done"] < g["progress"]["total"],
                      "solve_threads: the sweep on 4 threads is canceled early (%s)" % (g and g.get("progress")))
                check(el < ts.scaled(5), "solve_threads: canceled within %.1f s (%.2f s)" % (ts.scaled(5), el))
        stop_clean(d, "solve_threads %d" % t)
    if check(len(texts) == 2, "solve_threads: both results"):
        check(texts[1][0] == texts[4][0], "solve_threads: result JSON on 4 threads = on 1, byte for byte")
        check(texts[1][1] == texts[4][1], "solve_threads: result CSV on 4 threads = on 1, byte for byte")
        cli = os.environ.get("SPINMODAL_TEST_CLI")
        if cli:
            path = os.path.join(sc.tmp, "threads.json")
            with open(path, "w") as f:
                json.dump(req, f)
            p = subprocess.run([cli, "solve", "--threads", "3", path], capture_output=True,
                               timeout=ts.budget(60), env=dm._env())
            mine = json.loads(texts[4][0])
            theirs = json.loads(p.stdout or b"null") or {}
            theirs.pop("timing_ms", None)
            check(p.returncode == 0 and mine == theirs,
                  "solve_threads: the daemon's document = the CLI's with --threads 3 (exit %d)" % p.returncode)
    for bad in ("0", "65", "x"):
        p = subprocess.run([EXE, "--solve-threads", bad, "--db", os.path.join(sc.tmp, "flags.sqlite")],
                           capture_output=True, timeout=ts.budget(20), env=dm._env(), cwd=sc.tmp)
        check(p.returncode == 64 and b"solve-threads" in p.stderr + p.stdout,
              "solve_threads: --solve-threads %s -> exit 64 naming the flag (got %d)" % (bad, p.returncode))


def t_csv(sc):
    """/result?format=csv agrees with the JSON result."""
    d = sc.daemon(["--workers", "2"])
    req = example("angled-beam-90-sweep.json")
    jid, r = submit_id(d, req, "csv: sweep", wait=ts.wait_param(30), expect=(200,))
    if not jid:
        return
    res = d.get(job_path(jid) + "/result").json()
    rc = d.get(job_path(jid) + "/result?format=csv")
    ct = rc.ctype().lower().replace(" ", "")
    check(rc.status == 200 and ct.startswith("text/csv") and "charset=utf-8" in ct,
          "csv: 200 text/csv; charset=utf-8 (%s %r)" % (rc.status, rc.ctype()))
    text = rc.body.decode("utf-8")
    lines = text.splitlines()
    check(bool(lines) and lines[0] == CSV_HEADER, "csv: header line (%r)" % (lines[:1],))
    rows = list(csv.DictReader(io.StringIO(text)))
    want = sum(len(c.get("modes", [])) or 1 for c in res["cases"])
    check(len(rows) == want, "csv: %d rows (one per speed and mode), got %d" % (want, len(rows)))
    bad = []
    i = 0
    for c in res["cases"]:
        for k, m in enumerate(c.get("modes", [])):
            if i >= len(rows):
                break
            row = rows[i]
            i += 1

            def near(s, v):
                return v is None and s == "" or (s != "" and v is not None
                                                and abs(float(s) - v) <= 1e-12 * max(1.0, abs(v)))
            ok = (near(row["omega"], c["omega"]) and row["mode"] == str(k + 1)
                  and near(row["frequency_rad_s"], m["frequency_rad_s"])
                  and near(row["frequency_hz"], m["frequency_hz"])
                  and near(row["eig_re"], m["eigenvalue"][0]) and near(row["eig_im"], m["eigenvalue"][1])
                  and near(row["mac_to_previous"], m.get("mac_to_previous"))
                  and row["status"] == c["status"])
            if not ok:
                bad.append((row, c["omega"], m))
    check(not bad, "csv: every row agrees with the JSON frequencies%s" % (": first mismatch %s" % (bad[0],) if bad else ""))
    rj = d.get(job_path(jid) + "/result?format=json")
    check(rj.status == 200 and rj.body == d.get(job_path(jid) + "/result").body,
          "csv: ?format=json is the JSON result")
    problem_ok(d.get(job_path(jid) + "/result?format=xml"), 400, "csv: ?format=xml", pointer="/query/format")
    stop_clean(d, "csv")


def t_auth(sc):
    """--token-file: POST/DELETE need `Authorization: Bearer TOKEN`; GET does not."""
    token = "s3cret-Token-42"
    tf = os.path.join(sc.tmp, "token")
    with open(tf, "w") as f:
        f.write(token + "\n")
    os.chmod(tf, 0o600)
    d = sc.daemon(["--token-file", tf, "--workers", "1"])
    req = small(15)

    def unauthorized(r, what):
        problem_ok(r, 401, what)
        check((r.headers.get("WWW-Authenticate") or "").startswith("Bearer"),
              "%s: WWW-Authenticate: Bearer (%r)" % (what, r.headers.get("WWW-Authenticate")))

    unauthorized(submit(d, req), "auth: POST without a token")
    unauthorized(submit(d, req, headers={"Authorization": "Bearer wrong"}), "auth: POST with a wrong token")
    unauthorized(submit(d, req, headers={"Authorization": "Bearer " + token + "x"}), "auth: POST with a longer token")
    unauthorized(submit(d, req, headers={"Authorization": "Bearer " + token[:-1]}), "auth: POST with a token prefix")
    unauthorized(submit(d, req, headers={"Authorization": "Basic " + token}), "auth: POST with Basic")
    unauthorized(submit(d, req, headers={"Authorization": token}), "auth: POST with the bare token")
    r = d.get("/v1/analyses")
    check(r.status == 200 and (r.json() or {}).get("items") == [], "auth: rejected POSTs stored nothing (%s)" % r.text(200))
    r = submit(d, req, headers={"Authorization": "Bearer " + token})
    jid = (r.json() or {}).get("id")
    check(r.status == 202 and jid, "auth: POST with the token -> 202 (%s %s)" % (r.status, r.text(200)))
    if jid:
        r = d.get(job_path(jid))
        check(r.status == 200, "auth: GET the job without a token -> 200 (%s)" % r.status)
        unauthorized(d.delete(job_path(jid)), "auth: DELETE without a token")
        unauthorized(d.delete(job_path(jid), headers={"Authorization": "Bearer nope"}), "auth: DELETE with a wrong token")
        poll(d, jid)
        r = d.get(job_path(jid) + "/result")
        check(r.status == 200, "auth: GET /result without a token -> 200 (%s)" % r.status)
        r = d.delete(job_path(jid), headers={"Authorization": "Bearer " + token})
        check(r.status in (200, 202, 409), "auth: DELETE with the token passes auth (%s, done job -> 409)" % r.status)
    for p in ("/livez", "/readyz", "/metrics", "/v1/analyses", "/openapi.json"):
        check(d.get(p).status == 200, "auth: GET %s without a token -> 200" % p)
    stop_clean(d, "auth")
    # the same from the environment (SPINMODAL_TOKEN_FILE)
    d2 = sc.daemon(["--workers", "1"], env={"SPINMODAL_TOKEN_FILE": tf})
    problem_ok(submit(d2, req), 401, "auth: SPINMODAL_TOKEN_FILE: POST without a token")
    r = submit(d2, req, headers={"Authorization": "Bearer " + token})
    check(r.status == 202, "auth: SPINMODAL_TOKEN_FILE: POST with the token -> 202 (%s)" % r.status)
    stop_clean(d2, "auth env")


def t_errors(sc):
    """400 404 405 409 413 415 422 429 503: problem+json documents."""
    d = sc.daemon(["--workers", "1", "--queue-max", "1", "--max-body", "16384", "--shutdown-grace", "5"])
    ctj = {"Content-Type": "application/json"}
    r = d.request("POST", "/v1/analyses", body='{"structure": {"joints": ', headers=ctj)
    problem_ok(r, 400, "errors: malformed JSON", pointer="")
    msgs = [e.get("message", "") for e in (r.json() or {}).get("errors", []) if isinstance(e, dict)]
    check(any(re.search(r"line|column", m) for m in msgs), "errors: malformed JSON message has line/column (%s)" % msgs)
    problem_ok(d.get("/v1/analyses?limit=abc"), 400, "errors: bad query ?limit=abc", pointer="/query/limit")
    problem_ok(d.get("/v2/analyses"), 404, "errors: unknown route")
    problem_ok(d.get("/nope"), 404, "errors: unknown route /nope")
    problem_ok(d.get(job_path("0" * 64)), 404, "errors: unknown id")
    problem_ok(d.get(job_path("0" * 64) + "/result"), 404, "errors: result of an unknown id")
    problem_ok(d.get(job_path("not-an-id")), 404, "errors: malformed id")
    problem_ok(d.get(job_path("A" * 64)), 404, "errors: uppercase hex id")
    problem_ok(d.get(job_path("0" * 63)), 404, "errors: 63-digit id")
    for method, path, need in (("PUT", "/v1/analyses", {"GET", "POST"}), ("DELETE", "/livez", {"GET"}),
                               ("PATCH", job_path("0" * 64), {"GET", "DELETE"}),
                               ("POST", job_path("0" * 64) + "/result", {"GET"})):
        r = d.request(method, path, body=b"{}" if method != "DELETE" else None,
                      headers=ctj if method != "DELETE" else None)
        problem_ok(r, 405, "errors: %s %s" % (method, path))
        allow = {a.strip().upper() for a in (r.headers.get("Allow") or "").split(",") if a.strip()}
        check(need <= allow, "errors: %s %s: Allow lists %s (%r)" % (method, path, sorted(need), r.headers.get("Allow")))
    big = json.dumps(small(1, **{})).rstrip("}") + ', "pad": "' + "x" * 20000 + '"}'
    problem_ok(d.request("POST", "/v1/analyses", body=big, headers=ctj), 413, "errors: 20 kB body > --max-body 16384")
    problem_ok(d.request("POST", "/v1/analyses", body=json.dumps(small(1)), headers={"Content-Type": "text/plain"}),
               415, "errors: text/plain")
    problem_ok(d.request("POST", "/v1/analyses", body=json.dumps(small(1))), 415, "errors: no content type")
    problem_ok(d.request("POST", "/v1/analyses", body=json.dumps(small(1)),
                         headers={"Content-Type": "application/x-www-form-urlencoded"}), 415, "errors: form content type")
    bad = small(1)
    bad["structure"]["members"][1]["to"] = "Q"
    problem_ok(submit(d, bad), 422, "errors: unknown joint", pointer="/structure/members/1/to")
    many = small(1, modes=0)
    many["structure"]["members"][1]["to"] = "Q"
    many["structure"]["sections"]["al"]["E"] = -1
    many["frames"] = "per_frame"
    r = submit(d, many)
    problem_ok(r, 422, "errors: four errors at once", pointer="/analysis/modes")
    ptrs = sorted(e.get("pointer") for e in (r.json() or {}).get("errors", []))
    check({"/structure/members/1/to", "/structure/sections/al/E", "/frames", "/analysis/modes"} <= set(ptrs),
          "errors: every error's pointer is listed (%s)" % ptrs)
    # charset parameter accepted
    r = d.request("POST", "/v1/analyses?wait=%g" % ts.wait_param(30), body=json.dumps(small(1)),
                  headers={"Content-Type": "application/json; charset=utf-8"})
    sid = (r.json() or {}).get("id")
    check(r.status == 200 and sid, "errors: application/json; charset=utf-8 accepted (-> 200 after wait) (%s %s)"
          % (r.status, r.text(200)))
    if sid:
        problem_ok(d.delete(job_path(sid)), 409, "errors: DELETE of a done job")
    # 409 / 429 with a long job running (--workers 1 --queue-max 1)
    lid = run_until_running(d, long_sweep(), "errors: long sweep")
    if lid:
        problem_ok(d.get(job_path(lid) + "/result"), 409, "errors: GET /result of a running job")
    qid, _ = submit_id(d, small(2), "errors: one queued job", expect=(202,))
    r = submit(d, small(3))
    problem_ok(r, 429, "errors: queue full")
    ra = r.headers.get("Retry-After") or ""
    check(ra.isdigit(), "errors: 429 has Retry-After seconds (%r)" % ra)
    # 503 while stopping (SIGTERM with --shutdown-grace 5 and the sweep still running)
    n0 = d.log_count()
    d.signal(signal.SIGTERM)
    t0 = time.monotonic()
    check(d.wait_log(r"event=stopping\b", 5, start=n0) is not None, "errors: log has event=stopping after SIGTERM")
    # spinmodald logs `stopping` just before its HTTP side begins to refuse (main.c:
    # log_event, then main_stop): wait for /readyz to say so, then the POST must be
    # refused.  (A POST at once after the log line raced with that and got 429.)
    def not_ready():
        """/readyz's answer (or connection error) once it is no longer 200; else None."""
        try:
            x = d.get("/readyz")
        except (ConnectionError, OSError) as e:
            return e
        return None if x.status == 200 else x
    r = ts.wait_until(not_ready, 5)
    if isinstance(r, dm.Response):
        problem_ok(r, 503, "errors: /readyz while stopping")
    else:
        check(isinstance(r, ConnectionRefusedError), "errors: /readyz while stopping: 503 or refused (%r)"
              % (r if r is not None else "still 200 after %.1f s" % ts.budget(5)))
    try:
        r = submit(d, small(4))
        problem_ok(r, 503, "errors: POST while stopping")
        check(r.status != 503 or bool(r.headers.get("Retry-After")), "errors: 503 has Retry-After")
    except (ConnectionError, OSError, socket.error) as e:
        check(isinstance(e, ConnectionRefusedError), "errors: POST while stopping: 503 or connection refused (got %r)" % e)
    rc = d.wait_exit(60)
    el = time.monotonic() - t0
    check(rc == 0, "errors: exit status 0 after SIGTERM (%s)" % rc)
    check(el < 5 + ts.scaled(10), "errors: stopped within the grace period (5 s) + %.0f s (%.1f s)" % (ts.scaled(10), el))
    check(d.stopped_logged(), "errors: log has event=stopped")
    # the interrupted sweep and the queued job are back in the queue after a restart
    d.restart()
    check(d.wait_log(r"event=recovered\b", 5) is not None, "errors: restart logs event=recovered")
    for jid, what in ((lid, "interrupted sweep"), (qid, "queued job")):
        if jid:
            g = d.get(job_path(jid)).json() or {}
            check(g.get("state") in ("queued", "running", "done"),
                  "errors: %s is queued/running again after the restart (%s)" % (what, g.get("state")))
            d.delete(job_path(jid))
    stop_clean(d, "errors")


def t_concurrent(sc):
    """50 concurrent distinct submissions: all accepted, all done, distinct ids, right results."""
    d = sc.daemon(["--workers", "2"])
    n = 50
    omegas = [10.0 + 0.2 * i for i in range(n)]
    out = [None] * n
    barrier = threading.Barrier(n)

    def go(i):
        try:
            barrier.wait(ts.budget(10))
            out[i] = submit(d, small(omegas[i]))
        except Exception as e:  # recorded as a failed submission
            out[i] = e

    t0 = time.monotonic()
    ths = [threading.Thread(target=go, args=(i,)) for i in range(n)]
    for t in ths:
        t.start()
    join_end = time.monotonic() + ts.budget(120)
    for t in ths:
        t.join(max(0.1, join_end - time.monotonic()))
    statuses = [getattr(r, "status", repr(r)) for r in out]
    check(all(s in (200, 202) for s in statuses), "concurrent: all 50 POSTs -> 202/200 (%s)" % statuses)
    ids = [(r.json() or {}).get("id") if isinstance(r, dm.Response) else None for r in out]
    check(len(set(ids)) == n and None not in ids, "concurrent: 50 distinct ids")
    w1 = []
    for i, jid in enumerate(ids):
        if not jid:
            w1.append(None)
            continue
        g = poll(d, jid)
        if not (g and g.get("state") == "done"):
            check(False, "concurrent: job %d done (%s)" % (i, g and g.get("state")))
            w1.append(None)
            continue
        res = g["result"]
        c = res["cases"][0]
        if not check(abs(c["omega"] - omegas[i]) < 1e-12, "concurrent: job %d result is for its own omega" % i):
            pass
        w1.append(c["modes"][0]["frequency_rad_s"] if c.get("modes") else None)
    el = time.monotonic() - t0
    check(all(w is not None for w in w1), "concurrent: all 50 jobs done with modes (%.1f s)" % el)
    # ~0.3 s unloaded; a pool whose workers idle (5 s poll) while jobs are queued takes 5 s or more
    check(el < ts.scaled(4.5), "concurrent: all 50 jobs done within %.1f s, no worker idle while jobs "
          "are queued (%.1f s)" % (ts.scaled(4.5), el))
    if all(w is not None for w in w1):
        check(all(b > a for a, b in zip(w1, w1[1:])), "concurrent: omega_1 increases with Omega (10 .. 19.8 rad/s)")
        check(abs(w1[7] - 5.293064363939) < 1e-6, "concurrent: omega_1 at 11.4 rad/s = 5.293064 (%.9f)" % w1[7])
    r = d.get("/readyz")
    check(r.status == 200, "concurrent: /readyz 200 afterwards (%s %s)" % (r.status, r.text(200)))
    _, pm = metrics(d)
    check(mval(pm, "spinmodal_jobs", state="done") == n, "concurrent: spinmodal_jobs{state=done} = 50 (%s)"
          % mval(pm, "spinmodal_jobs", state="done"))
    r = d.get("/v1/analyses?limit=100")
    check(len((r.json() or {}).get("items", [])) == n, "concurrent: 50 jobs listed")
    stop_clean(d, "concurrent")


def t_queue_full(sc):
    """--workers 1 --queue-max 2: one running + two queued, the next POST -> 429 and nothing stored."""
    d = sc.daemon(["--workers", "1", "--queue-max", "2"])
    lid = run_until_running(d, long_sweep(), "queue_full: long sweep")
    aid, ra = submit_id(d, small(3), "queue_full: first queued", expect=(202,))
    bid, rb = submit_id(d, small(4), "queue_full: second queued", expect=(202,))
    check((ra.json() or {}).get("state") == "queued" and (rb.json() or {}).get("state") == "queued",
          "queue_full: both are queued")
    r = submit(d, small(5))
    problem_ok(r, 429, "queue_full: third queued job")
    retry = r.headers.get("Retry-After") or ""
    check(retry.isdigit(), "queue_full: Retry-After is a number of seconds (%r)" % retry)
    r2 = submit(d, small(5), wait=1)
    problem_ok(r2, 429, "queue_full: again with ?wait=1")
    # an identical resubmission of a queued job is not a new job: no 429
    r3 = submit(d, small(3))
    check(r3.status == 202 and (r3.json() or {}).get("id") == aid,
          "queue_full: resubmitting a queued job -> 202, same id (%s)" % r3.status)
    items = (d.get("/v1/analyses?limit=100").json() or {}).get("items", [])
    check(sorted(it.get("id") for it in items) == sorted([lid, aid, bid]),
          "queue_full: nothing stored for the rejected job (%d jobs listed)" % len(items))
    _, pm = metrics(d)
    check(mval(pm, "spinmodal_queue_depth") == 2, "queue_full: spinmodal_queue_depth 2 (%s)" % mval(pm, "spinmodal_queue_depth"))
    check((mval(pm, "spinmodal_http_requests_total", code="429") or 0) >= 2,
          "queue_full: 429s counted in spinmodal_http_requests_total")
    r = d.delete(job_path(aid))
    check(r.status == 200, "queue_full: DELETE of a queued job -> 200 (%s)" % r.status)
    cid, r = submit_id(d, small(5), "queue_full: after one left the queue", expect=(202,))
    d.delete(job_path(lid))
    for jid, what in ((bid, "second"), (cid, "fourth")):
        if jid:
            g = poll(d, jid)
            check(g and g.get("state") == "done", "queue_full: %s job done after the sweep was canceled" % what)
    g = poll(d, lid, timeout=30)
    check(g and g.get("state") == "canceled", "queue_full: sweep canceled")
    stop_clean(d, "queue_full")


def t_kill9(sc):
    """SIGKILL during a 101-speed sweep, restart on the same db: resumed, same frequencies."""
    req = example("angled-beam-90.json")
    req["analysis"]["omega"] = [20.0 * i / 100 for i in range(101)]
    d = sc.daemon(["--workers", "1"], name="killed")
    jid, r = submit_id(d, req, "kill9: sweep", expect=(202,))
    if not jid:
        return
    # a job answered 202 is committed: it survives the kill (queued behind the sweep)
    qid, _ = submit_id(d, small(7.5), "kill9: queued job", expect=(202,))
    g = poll(d, jid, pred=lambda x: x.get("progress", {}).get("done", 0) > 0 or x.get("state") != "queued"
             and x.get("state") != "running", timeout=60, interval=0.01)
    at = g and g.get("progress", {}).get("done")
    check(g and g.get("state") == "running" and 0 < at < 101,
          "kill9: sweep running with progress before the kill (%s, %s)" % (g and g.get("state"), g and g.get("progress")))
    d.kill()
    check(d.returncode == -signal.SIGKILL, "kill9: daemon killed by SIGKILL (%s)" % d.returncode)
    t0 = time.monotonic()
    d.restart()
    check(d.wait_log(r"event=recovered\b", 10) is not None, "kill9: restart logs event=recovered")
    g = poll(d, jid, timeout=DONE_TIMEOUT, interval=0.02)
    el = time.monotonic() - t0
    check(g and g.get("state") == "done", "kill9: the job is resumed and completes (%s)" % (g and g.get("state")))
    if not (g and g.get("state") == "done"):
        return
    print("info kill9: killed at progress %s/101; restart-to-done %.2f s; attempts %s"
          % (at, el, g.get("attempts")), flush=True)
    check(g.get("attempts") == 2, "kill9: attempts 2 after one interrupted run (%s)" % g.get("attempts"))
    schema_ok(g, "Job", "kill9: resumed job")
    if qid:
        q = poll(d, qid)
        check(q and q.get("state") == "done", "kill9: the job queued before the kill survives and completes (%s)"
              % (q and q.get("state")))
    res = d.get(job_path(jid) + "/result").json()
    # the same request uninterrupted in a fresh daemon
    f = sc.daemon(["--workers", "1"], name="fresh")
    fid, fr = submit_id(f, req, "kill9: fresh daemon", wait=ts.wait_param(60), expect=(200,))
    check(fid == jid, "kill9: same id in a fresh daemon")
    ref = (fr.json() or {}).get("result")
    if not isinstance(ref, dict):
        g2 = poll(f, fid)
        ref = g2 and g2.get("result")
    if isinstance(ref, dict) and isinstance(res, dict):
        a, b = freqs(res), freqs(ref)
        worst = 0.0
        same_shape = len(a) == len(b) and all(len(x) == len(y) for x, y in zip(a, b))
        if same_shape:
            for x, y in zip(a, b):
                for u, v in zip(x, y):
                    worst = max(worst, abs(u - v) / max(abs(v), 1e-300))
        check(same_shape and worst <= 1e-12,
              "kill9: resumed frequencies equal the uninterrupted run (worst relative difference %.3g)" % worst)
        check([c["status"] for c in res["cases"]] == [c["status"] for c in ref["cases"]],
              "kill9: case statuses equal")
    else:
        check(False, "kill9: both results available")
    stop_clean(d, "kill9 restarted")
    stop_clean(f, "kill9 fresh")


def t_timeout(sc):
    """--job-timeout: a long sweep fails with error.type timeout."""
    limit = "0.2"
    d = sc.daemon(["--workers", "1", "--job-timeout", limit], start=False)
    try:
        d.start()
    except dm.DaemonError as e:
        note("timeout: --job-timeout 0.2 refused (%s); using 1" % str(e).splitlines()[0])
        limit = "1"
        d = sc.daemon(["--workers", "1", "--job-timeout", limit])
    # an 80 + 80 element sweep takes the tree path, whose time the request check does not estimate
    # (the 32 + 32 one is dense: its estimated 12 s past this limit is a 422 at POST since issue 23)
    jid, r = submit_id(d, long_sweep(80), "timeout: long sweep", expect=(202,))
    if not jid:
        return
    t0 = time.monotonic()
    g = poll(d, jid, timeout=60)
    el = time.monotonic() - t0
    check(g and g.get("state") == "failed", "timeout: state failed (%s)" % (g and g.get("state")))
    err = (g or {}).get("error") or {}
    check(err.get("type") == "timeout" and isinstance(err.get("title"), str),
          "timeout: error.type timeout with a title (%s)" % err)
    check(el < float(limit) + ts.scaled(10), "timeout: failed within the limit + %.0f s (%.2f s)" % (ts.scaled(10), el))
    if g:
        schema_ok(g, "Job", "timeout: failed status document")
        check(g["progress"]["done"] < g["progress"]["total"], "timeout: not all speeds done (%s)" % g["progress"])
        check(g.get("result") is None, "timeout: no result in the status document")
    problem_ok(d.get(job_path(jid) + "/result"), 409, "timeout: GET /result of the timed-out job")
    check(d.wait_log(r"event=job_failed\b", 5) is not None, "timeout: log has event=job_failed")
    _, pm = metrics(d)
    check(mval(pm, "spinmodal_jobs_finished_total", state="failed") == 1, "timeout: jobs_finished_total{state=failed} 1")
    r = submit(d, long_sweep(80))
    doc = r.json() or {}
    check(r.status == 202 and doc.get("state") in ("queued", "running") and doc.get("error") is None,
          "timeout: resubmission of the timed-out job -> 202 queued again, error dropped (%s %s)"
          % (r.status, doc.get("state")))
    g = poll(d, jid, timeout=60)
    check(g and g.get("state") == "failed" and (g.get("error") or {}).get("type") == "timeout",
          "timeout: times out again (%s)" % (g and g.get("state")))
    stop_clean(d, "timeout")


def t_no_equilibrium(sc):
    """Single frame at 20 rad/s with stiffening: failed/no_equilibrium, the result still served."""
    d = sc.daemon(["--workers", "2"])
    req = angled(24, 24, 20, frames="single", geometric_stiffening=True, mode_shapes=False)
    jid, r = submit_id(d, req, "no_equilibrium: single frame", wait=ts.wait_param(30), expect=(200,))
    if not jid:
        return
    g = r.json() or {}
    if g.get("state") not in ("done", "failed"):
        g = poll(d, jid)
    check(g.get("state") == "failed", "no_equilibrium: state failed (%s)" % g.get("state"))
    err = g.get("error") or {}
    check(err.get("type") == "no_equilibrium", "no_equilibrium: error.type no_equilibrium (%s)" % err)
    check(isinstance(g.get("result"), dict), "no_equilibrium: the status document carries the result")
    schema_ok(g, "Job", "no_equilibrium: status document")
    rr = d.get(job_path(jid) + "/result")
    res = rr.json()
    check(rr.status == 200 and isinstance(res, dict), "no_equilibrium: GET /result -> 200 (%s)" % rr.status)
    if isinstance(res, dict):
        schema_ok(res, "result", "no_equilibrium: result")
        c = res["cases"][0]
        check(c.get("status") == "no_equilibrium" and isinstance(c.get("diagnostics"), dict),
              "no_equilibrium: case status no_equilibrium with diagnostics (%s)" % c.get("status"))
        check(g.get("result") == res, "no_equilibrium: status document's result equals /result")
    rc = d.get(job_path(jid) + "/result?format=csv")
    rows = list(csv.DictReader(io.StringIO(rc.body.decode("utf-8", "replace"))))
    check(rc.status == 200 and len(rows) == 1 and rows[0].get("status") == "no_equilibrium"
          and rows[0].get("mode") == "" and rows[0].get("frequency_rad_s") == "",
          "no_equilibrium: CSV has one row with empty mode fields, status no_equilibrium (%s)" % rows)
    # a sweep: the other speed is still solved
    sweep = angled(8, 8, [2, 20], frames="single", geometric_stiffening=True, mode_shapes=False)
    sid, r = submit_id(d, sweep, "no_equilibrium: sweep [2, 20]", wait=ts.wait_param(30), expect=(200,))
    if sid:
        g = poll(d, sid)
        res = (g or {}).get("result") or {}
        st = [c.get("status") for c in res.get("cases", [])]
        check(g.get("state") == "failed" and st == ["solved", "no_equilibrium"],
              "no_equilibrium: sweep failed with cases solved, no_equilibrium (%s %s)" % (g.get("state"), st))
        check(g["progress"] == {"done": 2, "total": 2}, "no_equilibrium: progress 2/2 (%s)" % g.get("progress"))
    # an identical failed job is queued again (202), its old error and result dropped
    r = submit(d, req)
    doc = r.json() or {}
    check(r.status == 202 and doc.get("id") == jid and doc.get("state") in ("queued", "running"),
          "no_equilibrium: identical resubmission of the failed job -> 202 queued again (%s %s)"
          % (r.status, doc.get("state")))
    check(doc.get("error") is None and doc.get("result") is None,
          "no_equilibrium: resubmitted job has no old error/result (%s)" % r.text(200))
    g = poll(d, jid)
    check(g and g.get("state") == "failed" and (g.get("error") or {}).get("type") == "no_equilibrium"
          and g.get("attempts") == 1, "no_equilibrium: fails the same way again, attempts 1 (%s, %s)"
          % (g and g.get("state"), g and g.get("attempts")))
    stop_clean(d, "no_equilibrium")


# ------------------------------------------------------------------ bad requests (data)

def _ptr_tokens(ptr):
    return [t.replace("~1", "/").replace("~0", "~") for t in ptr.split("/")[1:]]


def _ptr_set(doc, ptr, value, delete=False):
    toks = _ptr_tokens(ptr)
    cur = doc
    for t in toks[:-1]:
        cur = cur[int(t)] if isinstance(cur, list) else cur[t]
    last = toks[-1]
    if isinstance(cur, list):
        if delete:
            del cur[int(last)]
        elif last == "-":
            cur.append(value)
        else:
            cur[int(last)] = value
    elif delete:
        del cur[last]
    else:
        cur[last] = value


def _gen_body(name, base_text):
    """Body generators: (bytes or None, iterator of chunks or None, length)."""
    m = re.match(r"(\d+)MB$", name)
    if m:
        n = int(m.group(1)) * 1024 * 1024
        head, tail = b'{"pad": "', b'"}'
        fill = n - len(head) - len(tail)

        def it():
            yield head
            left = fill
            while left > 0:
                k = min(left, 65536)
                yield b"a" * k
                left -= k
            yield tail
        return None, it(), n
    if name == "1MiB+1":
        n = 1024 * 1024 + 1
        return b'{"pad": "' + b"a" * (n - 11) + b'"}', None, n
    m = re.match(r"deep-nesting-(\d+)$", name)
    if m:
        k = int(m.group(1))
        b = b"[" * k + b"]" * k
        return b, None, len(b)
    m = re.match(r"deep-object-nesting-(\d+)$", name)
    if m:
        k = int(m.group(1))
        b = b'{"a":' * k + b"1" + b"}" * k
        return b, None, len(b)
    if name == "invalid-utf8":
        b = base_text.encode().replace(b'"beam1"', b'"beam\xff\xfe1"')
        return b, None, len(b)
    if name == "overlong-utf8":
        b = base_text.encode().replace(b'"beam1"', b'"beam\xc0\xaf1"')
        return b, None, len(b)
    if name == "lone-surrogate-escape":
        b = base_text.encode().replace(b'"beam1"', b'"beam\\ud800x"')
        return b, None, len(b)
    if name == "nul-in-string":
        b = base_text.encode().replace(b'"beam1"', b'"beam\x001"')
        return b, None, len(b)
    if name == "nul-after-json":
        b = base_text.encode() + b"\x00"
        return b, None, len(b)
    if name == "nul-escape-in-key":
        b = base_text.encode().replace(b'"O": [0, 0]', b'"O\\u0000": [0, 0]')
        return b, None, len(b)
    if name == "trailing-garbage":
        b = base_text.encode() + b" {}"
        return b, None, len(b)
    raise ValueError("unknown body generator %r" % name)


def _chunked(body, size=1000):
    out = b""
    for i in range(0, len(body), size):
        part = body[i:i + size]
        out += b"%x\r\n" % len(part) + part + b"\r\n"
    return out + b"0\r\n\r\n"


def run_bad_case(d, case, bases):
    """Send one catalogue case over a raw socket; returns the Response."""
    method = case.get("method", "POST")
    path = case.get("path", "/v1/analyses")
    if "path_gen" in case:
        g = case["path_gen"]
        m = re.match(r"overlong-url-(\d+)$", g)
        if not m:
            raise ValueError("unknown path generator %r" % g)
        path = path + "a" * int(m.group(1))
    headers = case.get("headers")
    body, body_iter, length = None, None, None
    base_text = None
    if "base" in case:
        base = copy.deepcopy(bases[case["base"]])
        for ptr, val in case.get("set", {}).items():
            _ptr_set(base, ptr, val)
        for ptr in case.get("delete", []):
            _ptr_set(base, ptr, None, delete=True)
        base_text = json.dumps(base)
        for a, b in case.get("replace", []):
            if a not in base_text:
                raise ValueError("%s: %r not in the base text" % (case["name"], a))
            base_text = base_text.replace(a, b, 1)
        body = base_text.encode("utf-8")
    if "body" in case:
        body = case["body"].encode("utf-8")
    if "body_json" in case:
        body = json.dumps(case["body_json"]).encode("utf-8")
    if "body_gen" in case:
        body, body_iter, length = _gen_body(case["body_gen"], base_text or json.dumps(bases["small"]))
    if headers is None:
        headers = {"Content-Type": "application/json"} if (body is not None or body_iter is not None) else {}
    lines = ["%s %s HTTP/1.1" % (method, path), "Host: 127.0.0.1:%d" % d.port, "Connection: close"]
    chunked = case.get("chunked", False)
    for k, v in headers.items():
        lines.append("%s: %s" % (k, v))
    lines += case.get("header_lines", [])
    if "long_header" in case:
        lines.append("%s: %s" % (case["long_header"][0], "a" * int(case["long_header"][1])))
    if chunked:
        lines.append("Transfer-Encoding: chunked")
        if body_iter is not None:
            inner = body_iter
            body_iter = (b"%x\r\n" % len(c) + c + b"\r\n" for c in inner)
            body_iter = _concat(body_iter, [b"0\r\n\r\n"])
        elif body is not None:
            body = _chunked(body)
    if "content_length" in case:
        if case["content_length"] is not None:
            lines.append("Content-Length: %s" % case["content_length"])
    elif not chunked and (body is not None or body_iter is not None):
        lines.append("Content-Length: %d" % (length if length is not None else len(body)))
    head = ("\r\n".join(lines) + "\r\n\r\n").encode("latin-1")
    if "raw_body" in case:
        body = case["raw_body"].encode("latin-1")
    expect100 = case.get("expect_100", False)
    if body_iter is None and body is not None:
        body_iter = iter([body[i:i + 65536] for i in range(0, len(body), 65536)])
    if not expect100 and body_iter is not None and (length or 0) <= 65536 and body is not None and len(body) <= 65536:
        return d.raw(head + body, half_close=case.get("half_close", False), timeout=case.get("timeout", 20))
    return d.raw(head, body_iter=body_iter, half_close=case.get("half_close", False),
                 timeout=case.get("timeout", 20), read_first=expect100)


def _concat(a, b):
    for x in a:
        yield x
    for x in b:
        yield x


def t_bad_requests(sc):
    """The catalogue of bad_requests.json: each answered with the expected 4xx, /livez
    200 after every case, never a 5xx, the daemon alive at the end, nothing stored."""
    with open(os.path.join(HERE, "bad_requests.json")) as f:
        cat = json.load(f)
    d = sc.daemon(cat.get("daemon_args", []))
    bases = cat["bases"]
    seen_5xx = []
    accepted = []   # (case, job id) of bad requests the daemon accepted
    ncases = len(cat["cases"])
    check(ncases >= 40, "bad_requests: the catalogue has %d cases (>= 40)" % ncases)
    for case in cat["cases"]:
        name = case["name"]
        want = case["status"] if isinstance(case["status"], list) else [case["status"]]
        try:
            r = run_bad_case(d, case, bases)
        except Exception as e:
            check(False, "bad %s: request raised %r" % (name, e))
            traceback.print_exc()
            continue
        got = r.status if r.status is not None else "closed"
        if got in (200, 202) and got not in want and isinstance(r.json(), dict) and r.json().get("id"):
            accepted.append((name, r.json()["id"]))
        ok = check(got in want, "bad %s: status %s (got %s%s: %s)" % (name, "/".join(map(str, want)), got,
                                                                  " [%s]" % r.error if r.error else "", r.text(160)))
        if isinstance(r.status, int) and r.status >= 500:
            seen_5xx.append((name, r.status))
        if r.interim:
            check(100 not in r.interim or not case.get("expect_100"),
                  "bad %s: no 100 Continue before the final answer (interim %s)" % (name, r.interim))
        if ok and isinstance(r.status, int) and r.status >= 400 and case.get("problem", True):
            problem_ok(r, r.status, "bad %s" % name, pointer=case.get("pointer"),
                       pointer_prefix=case.get("pointer_prefix"), check_status=False)
        if "max_sent_mb" in case and r.sent is not None:
            check(r.sent <= case["max_sent_mb"] * 1024 * 1024,
                  "bad %s: answered before the whole body was read (%.1f MB sent, at most %s MB expected)"
                  % (name, r.sent / 1048576.0, case["max_sent_mb"]))
        if case.get("allow"):
            check(bool(r.headers.get("Allow")), "bad %s: 405 has Allow (%r)" % (name, r.headers.get("Allow")))
        for s in case.get("not_in_body", []):
            check(s.encode() not in r.body, "bad %s: answer does not contain %r" % (name, s))
        # liveness after every case
        try:
            lv = d.get("/livez", timeout=10)
            check(lv.status == 200, "bad %s: /livez 200 afterwards (%s)" % (name, lv.status))
            if lv.status >= 500:
                seen_5xx.append((name + " /livez", lv.status))
        except Exception as e:
            check(False, "bad %s: /livez afterwards raised %r (alive: %s)" % (name, e, d.alive()))
            if not d.alive():
                break
    check(not seen_5xx, "bad_requests: no 5xx answer was ever seen (%s)" % seen_5xx)
    for name, jid in accepted:
        g = poll(d, jid, timeout=60)
        print("info bad %s: accepted as job %s..., which ended %s, error %s"
              % (name, jid[:12], g and g.get("state"), json.dumps((g or {}).get("error"))), flush=True)
        if g:
            schema_ok(g, "Job", "bad %s: status document of the accepted job" % name)
    check(d.alive(), "bad_requests: the daemon is still alive")
    r = d.get("/readyz")
    check(r.status == 200, "bad_requests: /readyz 200 at the end (%s)" % r.status)
    items = (d.get("/v1/analyses?limit=100").json() or {}).get("items")
    check(items == [], "bad_requests: no rejected request stored a job (%s)" % [i.get("id") for i in items or []])
    stop_clean(d, "bad_requests")


# ------------------------------------------------------------------ metrics, list, misc

def t_metrics(sc):
    """/metrics: families, labels, and values that move as expected."""
    d = sc.daemon(["--workers", "2"])
    r, m0 = metrics(d)
    ct = r.ctype().replace(" ", "").lower()
    check(r.status == 200 and ct.startswith("text/plain") and "version=0.0.4" in ct,
          "metrics: 200 text/plain; version=0.0.4 (%s %r)" % (r.status, r.ctype()))
    unp = [l for n, l, v in m0["samples"] if n == "__unparsable__"]
    check(not unp, "metrics: every sample line parses (%s)" % unp[:3])
    for fam, typ in (("spinmodal_http_requests_total", "counter"), ("spinmodal_jobs", "gauge"),
                     ("spinmodal_queue_depth", "gauge"), ("spinmodal_workers", "gauge"),
                     ("spinmodal_workers_busy", "gauge"), ("spinmodal_solve_duration_seconds", "histogram"),
                     ("spinmodal_cache_hits_total", "counter"), ("spinmodal_cache_misses_total", "counter"),
                     ("spinmodal_jobs_finished_total", "counter")):
        t = m0["types"].get(fam)
        check(t == typ, "metrics: # TYPE %s %s (got %s)" % (fam, typ, t))
    for s in STATES:
        check(mval(m0, "spinmodal_jobs", state=s) == 0, "metrics: spinmodal_jobs{state=%s} 0 at start" % s)
    check(mval(m0, "spinmodal_queue_depth") == 0, "metrics: queue depth 0")
    check(mval(m0, "spinmodal_workers") == 2, "metrics: spinmodal_workers 2 (%s)" % mval(m0, "spinmodal_workers"))
    check(mval(m0, "spinmodal_solve_duration_seconds_count") == 0, "metrics: no solves yet")
    # traffic
    ids = []
    for w in (6, 7):
        jid, _ = submit_id(d, small(w), "metrics: job %s" % w, wait=ts.wait_param(30), expect=(200,))
        ids.append(jid)
    jid, _ = submit_id(d, small(8), "metrics: job 8", expect=(202,))
    ids.append(jid)
    if jid:
        poll(d, jid)
    submit(d, small(6))                                  # cache hit
    d.get(job_path("f" * 64))                            # 404
    d.request("PUT", "/v1/analyses")                     # 405
    submit(d, {"structure": 1, "analysis": {}})          # 422
    r, m1 = metrics(d)

    def delta(name, **lab):
        return (mval(m1, name, **lab) or 0) - (mval(m0, name, **lab) or 0)

    check(delta("spinmodal_http_requests_total", route="/v1/analyses", method="POST", code="200") == 3,
          "metrics: requests_total{route=/v1/analyses,method=POST,code=200} +3 (%s)"
          % delta("spinmodal_http_requests_total", route="/v1/analyses", method="POST", code="200"))
    check(delta("spinmodal_http_requests_total", route="/v1/analyses", method="POST", code="202") == 1,
          "metrics: requests_total{...,code=202} +1")
    check(delta("spinmodal_http_requests_total", route="/v1/analyses", method="POST", code="422") == 1,
          "metrics: requests_total{...,code=422} +1")
    check(delta("spinmodal_http_requests_total", route="/v1/analyses/{id}", method="GET", code="404") == 1,
          "metrics: requests_total{route=/v1/analyses/{id},method=GET,code=404} +1 (%s)"
          % sorted({(l.get("route"), l.get("method"), l.get("code")) for n, l, v in m1["samples"]
                    if n == "spinmodal_http_requests_total"}))
    # DAEMON.md does not say how methods outside GET/HEAD/POST/DELETE/OPTIONS are
    # labelled; http.c folds them into method="OTHER" (bounded cardinality)
    put405 = (delta("spinmodal_http_requests_total", route="/v1/analyses", method="PUT", code="405")
              + delta("spinmodal_http_requests_total", route="/v1/analyses", method="OTHER", code="405"))
    check(put405 == 1, "metrics: requests_total{route=/v1/analyses,method=PUT|OTHER,code=405} +1 (%s)" % put405)
    check((delta("spinmodal_http_requests_total", route="/v1/analyses/{id}", method="GET", code="200") or 0) >= 1,
          "metrics: GET /v1/analyses/{id} 200s counted under the route template")
    check(not any(n == "spinmodal_http_requests_total" and ids[0] and ids[0] in l.get("route", "")
                  for n, l, v in m1["samples"]), "metrics: no job id in a route label")
    check(delta("spinmodal_cache_misses_total") == 3, "metrics: cache misses +3 (%s)" % delta("spinmodal_cache_misses_total"))
    check(delta("spinmodal_cache_hits_total") == 1, "metrics: cache hits +1 (%s)" % delta("spinmodal_cache_hits_total"))
    check(mval(m1, "spinmodal_jobs", state="done") == 3, "metrics: spinmodal_jobs{state=done} 3")
    check(delta("spinmodal_jobs_finished_total", state="done") == 3, "metrics: jobs_finished_total{state=done} +3")
    check(delta("spinmodal_solve_duration_seconds_count") == 3, "metrics: solve duration count +3")
    check((mval(m1, "spinmodal_solve_duration_seconds_sum") or 0) > 0, "metrics: solve duration sum > 0")
    buckets = sorted(((float(l["le"]), v) for n, l, v in m1["samples"]
                      if n == "spinmodal_solve_duration_seconds_bucket"), key=lambda x: x[0])
    les = [b[0] for b in buckets]
    check(buckets and les[-1] == math.inf and abs(les[0] - 0.005) < 1e-12 and 60.0 in les,
          "metrics: buckets 0.005 ... 60, +Inf (%s)" % les)
    check(all(b[1] >= a[1] for a, b in zip(buckets, buckets[1:])), "metrics: buckets cumulative")
    check(buckets and buckets[-1][1] == mval(m1, "spinmodal_solve_duration_seconds_count"),
          "metrics: +Inf bucket equals _count")
    check(mval(m1, "spinmodal_queue_depth") == 0 and mval(m1, "spinmodal_workers_busy") == 0,
          "metrics: idle: queue depth 0, workers busy 0")
    # gauges while a job runs
    lid = run_until_running(d, long_sweep(), "metrics: long sweep")
    _, m2 = metrics(d)
    check(mval(m2, "spinmodal_jobs", state="running") == 1 and mval(m2, "spinmodal_workers_busy") == 1,
          "metrics: running 1, workers busy 1 (%s, %s)" % (mval(m2, "spinmodal_jobs", state="running"),
                                                           mval(m2, "spinmodal_workers_busy")))
    if lid:
        d.delete(job_path(lid))
        poll(d, lid, timeout=60)
        _, m3 = metrics(d)
        check(mval(m3, "spinmodal_jobs", state="canceled") == 1
              and (mval(m3, "spinmodal_jobs_finished_total", state="canceled") or 0) == 1,
              "metrics: canceled job counted in jobs{state=canceled} and jobs_finished_total{state=canceled}")
    stop_clean(d, "metrics")


def t_list(sc):
    """GET /v1/analyses: newest first, limit/next pagination, state filter, JobList."""
    d = sc.daemon(["--workers", "2"])
    ids = []
    for i in range(6):
        jid, _ = submit_id(d, small(2.5 + i), "list: job %d" % i, wait=ts.wait_param(30), expect=(200,))
        ids.append(jid)
    cid = run_until_running(d, long_sweep(), "list: sweep to cancel")
    if cid:
        d.delete(job_path(cid))
        poll(d, cid, timeout=60)
    ids.append(cid)
    newest_first = list(reversed(ids))
    r = d.get("/v1/analyses")
    doc = r.json() or {}
    check(r.status == 200 and r.media_type() == "application/json", "list: 200 application/json")
    schema_ok(doc, "JobList", "list: full list")
    items = doc.get("items", [])
    check([it.get("id") for it in items] == newest_first, "list: 7 jobs, newest first")
    check(all("result" not in it for it in items), "list: items carry no result")
    check(doc.get("next") is None, "list: next null when everything fits (%s)" % doc.get("next"))
    # pagination
    seen, pages, path = [], 0, "/v1/analyses?limit=2"
    while path and pages < 10:
        r = d.get(path)
        doc = r.json() or {}
        pages += 1
        if not check(r.status == 200, "list: page %d (%s) -> 200 (%s)" % (pages, path, r.status)):
            break
        schema_ok(doc, "JobList", "list: page %d" % pages)
        got = [it.get("id") for it in doc.get("items", [])]
        check(len(got) <= 2, "list: page %d has at most 2 items" % pages)
        seen += got
        nxt = doc.get("next")
        if nxt is not None:
            check(re.match(r"^/v1/analyses\?(.*&)?limit=2(&.*)?$", nxt) is not None and "before=" in nxt,
                  "list: next is /v1/analyses?limit=2&before=SEQ (%s)" % nxt)
        path = nxt
    check(seen == newest_first, "list: limit=2 pages through all 7 jobs in order, no duplicates (%d pages)" % pages)
    check(pages in (4, 5), "list: 4 pages (or 5 with an empty last one): %d" % pages)
    # state filter
    r = d.get("/v1/analyses?state=done")
    got = [it.get("id") for it in (r.json() or {}).get("items", [])]
    check(got == newest_first[1:], "list: ?state=done lists the 6 done jobs")
    r = d.get("/v1/analyses?state=canceled")
    got = [(it.get("id"), it.get("state")) for it in (r.json() or {}).get("items", [])]
    check(got == [(cid, "canceled")], "list: ?state=canceled lists the canceled job")
    r = d.get("/v1/analyses?state=queued")
    check((r.json() or {}).get("items") == [], "list: ?state=queued is empty")
    seen, path, pages = [], "/v1/analyses?state=done&limit=4", 0
    while path and pages < 5:
        doc = d.get(path).json() or {}
        seen += [(it.get("id"), it.get("state")) for it in doc.get("items", [])]
        path = doc.get("next")
        pages += 1
    check([s for _, s in seen] == ["done"] * 6 and [i for i, _ in seen] == newest_first[1:],
          "list: ?state=done&limit=4 with next keeps the filter (%s)" % [s for _, s in seen])
    for q, ptr in (("limit=0", "/query/limit"), ("limit=101", "/query/limit"), ("limit=abc", "/query/limit"),
                   ("limit=2.5", "/query/limit"), ("state=bogus", "/query/state"), ("before=abc", "/query/before")):
        problem_ok(d.get("/v1/analyses?" + q), 400, "list: ?%s" % q, pointer=ptr)
    r = d.get("/v1/analyses?limit=100")
    check(r.status == 200 and len((r.json() or {}).get("items", [])) == 7, "list: limit=100 accepted")
    stop_clean(d, "list")


def t_misc(sc):
    """/, /openapi.json, schemas byte for byte, /livez, /readyz, HEAD, flags, durability,
    GET /v1/analyses/{id}/request (t_job_request)."""
    t_job_request(sc)
    d = sc.daemon(["--workers", "2"])
    r = d.get("/")
    check(r.status == 200 and r.media_type() == "text/html", "misc: GET / is HTML (%s %r)" % (r.status, r.ctype()))
    if b'href="/openapi.json"' in r.body:
        check(True, "misc: GET / links /openapi.json")
    else:
        # DAEMON.md: / is the plain API page "(later the web front end)"; with the
        # front end built (server/meson.build) the plain page is /api.html
        ra = d.get("/api.html")
        check(ra.status == 200 and ra.media_type() == "text/html" and b'href="/openapi.json"' in ra.body,
              "misc: GET / is the web front end and /api.html is HTML linking /openapi.json (%s)" % ra.status)
    r = d.request("HEAD", "/")
    check(r.status == 200 and r.body == b"", "misc: HEAD / -> 200 without a body")
    for path, fname, ctype in (("/v1/schemas/request", "request.schema.json", "application/schema+json"),
                               ("/v1/schemas/result", "result.schema.json", "application/schema+json"),
                               ("/openapi.json", "openapi.json", "application/json")):
        with open(os.path.join(ROOT, "schemas", fname), "rb") as f:
            want = f.read()
        r = d.get(path)
        check(r.status == 200 and r.media_type() == ctype, "misc: GET %s -> 200 %s (%s %r)" % (path, ctype, r.status, r.ctype()))
        check(r.body == want, "misc: %s equals schemas/%s byte for byte (%d vs %d bytes)" % (path, fname, len(r.body), len(want)))
    oa = d.get("/openapi.json").json() or {}
    check(str(oa.get("openapi", "")).startswith("3.1"), "misc: /openapi.json is OpenAPI 3.1 (%s)" % oa.get("openapi"))
    r = d.get("/livez")
    check(r.status == 200 and r.json() == {"status": "ok"}, "misc: /livez 200 {\"status\":\"ok\"} (%s)" % r.text(100))
    schema_ok(r.json(), "Health", "misc: /livez")
    r = d.get("/readyz")
    doc = r.json() or {}
    check(r.status == 200 and doc.get("status") == "ready" and doc.get("checks", {}).get("database") == "ok"
          and doc.get("checks", {}).get("workers") == "2/2", "misc: /readyz 200 ready, database ok, workers 2/2 (%s)" % r.text(200))
    schema_ok(doc, "Health", "misc: /readyz")
    r = d.request("HEAD", "/livez")
    check(r.status == 200 and r.body == b"", "misc: HEAD /livez -> 200 without a body")
    r = d.request("OPTIONS", "/v1/analyses")
    check(r.status == 405, "misc: OPTIONS without --cors-origin -> 405 (%s)" % r.status)
    jid, r = submit_id(d, small(9), "misc: job", wait=ts.wait_param(30), expect=(200,))
    before = d.get(job_path(jid) + "/result").body if jid else b""
    before_csv = d.get(job_path(jid) + "/result?format=csv").body if jid else b""
    n0 = d.log_count()
    stop_clean(d, "misc")
    lines = d.log_lines()[n0:]
    i_stop = [i for i, l in enumerate(lines) if "event=stopping" in l]
    i_done = [i for i, l in enumerate(lines) if "event=stopped" in l]
    check(i_stop and i_done and i_stop[0] < i_done[-1], "misc: log has event=stopping then event=stopped")
    # durability: a restart on the same database still serves the old result
    d.restart()
    if jid:
        g = d.get(job_path(jid)).json() or {}
        check(g.get("state") == "done", "misc: after a restart the job is still done")
        r = d.get(job_path(jid) + "/result")
        check(r.status == 200 and r.body == before, "misc: after a restart /result is byte-identical")
        check(d.get(job_path(jid) + "/result?format=csv").body == before_csv, "misc: ... and the CSV too")
        r = submit(d, small(9))
        check(r.status == 200 and (r.json() or {}).get("id") == jid, "misc: after a restart the POST is a cache hit (200)")
    stop_clean(d, "misc restarted")
    # flags and exit codes
    env = dm._env()
    for args, want, what in ((["--version"], 0, "--version"), (["--help"], 0, "--help"),
                             (["--bogus-flag"], 64, "an unknown flag"), (["--workers", "0"], 64, "--workers 0"),
                             (["--workers", "abc"], 64, "--workers abc"), (["--listen", "nonsense"], 64, "--listen nonsense"),
                             (["--log-format", "xml"], 64, "--log-format xml"),
                             (["--job-timeout", "-1"], 64, "--job-timeout -1")):
        p = subprocess.run([EXE] + args + (["--db", os.path.join(sc.tmp, "flags.sqlite")] if want else []),
                           capture_output=True, timeout=ts.budget(20), env=env, cwd=sc.tmp)
        check(p.returncode == want, "misc: spinmodald %s -> exit %d (got %d: %.200s)"
              % (" ".join(args), want, p.returncode, (p.stderr or p.stdout).decode("utf-8", "replace")))
        if what == "--version":
            check(re.search(rb"\d+\.\d+\.\d+", p.stdout + p.stderr) is not None, "misc: --version prints a version")
    # port taken, database unusable -> 1
    a = sc.daemon(["--workers", "1"], name="porttaken")
    b = dm.Daemon(EXE, sc.tmp, ["--workers", "1"], name="second", listen="127.0.0.1:%d" % a.port)
    p = subprocess.run(b.argv(), capture_output=True, timeout=ts.budget(30), env=env, cwd=sc.tmp)
    check(p.returncode == 1, "misc: a port already taken -> exit 1 (got %d)" % p.returncode)
    p = subprocess.run([EXE, "--listen", "127.0.0.1:0", "--db", os.path.join(sc.tmp, "no", "such", "dir", "x.sqlite")],
                       capture_output=True, timeout=ts.budget(30), env=env, cwd=sc.tmp)
    check(p.returncode == 1, "misc: an unusable database -> exit 1 (got %d)" % p.returncode)
    stop_clean(a, "misc port holder")
    # --cors-origin: preflight 204 with CORS headers, the origin on ordinary answers
    origin = "https://app.example.org"
    c = sc.daemon(["--workers", "1", "--cors-origin", origin], name="cors")
    r = c.request("OPTIONS", "/v1/analyses", headers={"Origin": origin, "Access-Control-Request-Method": "POST",
                                                       "Access-Control-Request-Headers": "content-type, authorization"})
    methods = (r.headers.get("Access-Control-Allow-Methods") or "").upper()
    check(r.status == 204 and r.headers.get("Access-Control-Allow-Origin") == origin and "POST" in methods,
          "misc: --cors-origin: OPTIONS preflight -> 204 with Allow-Origin and Allow-Methods (%s %s)"
          % (r.status, dict(r.headers.items())))
    r = c.get("/livez", headers={"Origin": origin})
    check(r.headers.get("Access-Control-Allow-Origin") == origin, "misc: --cors-origin: GET carries Access-Control-Allow-Origin")
    stop_clean(c, "misc cors")
    # --log-format json: one JSON object per line
    j = sc.daemon(["--workers", "1", "--log-format", "json"], name="jsonlog")
    j.get("/livez")
    stop_clean(j, "misc json logs")
    lines = [l for l in j.log_lines() if not l.startswith("[stdout]")]
    parsed = []
    for l in lines:
        try:
            parsed.append(json.loads(l))
        except ValueError:
            parsed.append(None)
    check(lines and all(isinstance(p, dict) and "event" in p and "ts" in p and "level" in p for p in parsed),
          "misc: --log-format json: every log line is a JSON object with ts, level, event (%s)"
          % [l for l, p in zip(lines, parsed) if not isinstance(p, dict)][:2])
    check(any(isinstance(p, dict) and p.get("event") == "request" and p.get("path") == "/livez"
              and p.get("status") in (200, "200") for p in parsed), "misc: --log-format json: request line for /livez")
    # environment variables (flag wins)
    e = sc.daemon(["--workers", "1"], name="envflags", env={"SPINMODAL_WORKERS": "3", "SPINMODAL_MAX_SPEEDS": "2"})
    doc = e.get("/readyz").json() or {}
    check(doc.get("checks", {}).get("workers") == "1/1", "misc: --workers wins over SPINMODAL_WORKERS (%s)" % doc.get("checks"))
    r = submit(e, small([1, 2, 3]))
    problem_ok(r, 422, "misc: SPINMODAL_MAX_SPEEDS=2 applies", pointer="/analysis/omega")
    stop_clean(e, "misc env")


def t_validate(sc):
    """POST /v1/validate: the id, SHA-256 and canonical form; nothing stored; the
    same problems as POST /v1/analyses; no token needed."""
    token = "validate-token"
    tf = os.path.join(sc.tmp, "token")
    with open(tf, "w") as f:
        f.write(token + "\n")
    d = sc.daemon(["--workers", "1", "--token-file", tf, "--max-body", "16384"])
    req = small(16)
    r = d.post("/v1/validate", req)
    doc = r.json() or {}
    check(r.status == 200 and r.media_type() == "application/json" and doc.get("valid") is True,
          "validate: valid request without a token -> 200 {valid: true} (%s %s)" % (r.status, r.text(200)))
    check(ID_RE.match(str(doc.get("id"))) is not None and ID_RE.match(str(doc.get("request_sha256"))) is not None,
          "validate: id and request_sha256 are 64 hex digits")
    canon = doc.get("canonical") or {}
    check(canon.get("frames") == "per_element" and canon.get("analysis", {}).get("coriolis") is True
          and canon.get("analysis", {}).get("modes") == 3, "validate: canonical form has the defaults applied")
    r2 = d.post("/v1/validate", reorder(req))
    check((r2.json() or {}).get("id") == doc.get("id"), "validate: same id for reordered keys")
    items = (d.get("/v1/analyses").json() or {}).get("items")
    check(items == [], "validate: nothing stored (%s)" % items)
    _, pm = metrics(d)
    check(mval(pm, "spinmodal_queue_depth") == 0 and not mval(pm, "spinmodal_cache_misses_total"),
          "validate: nothing queued, no cache miss counted")
    r = submit(d, req, headers={"Authorization": "Bearer " + token})
    check(r.status == 202 and (r.json() or {}).get("id") == doc.get("id"),
          "validate: POST /v1/analyses gives the id /v1/validate announced (%s)" % r.status)
    hdr = {"Content-Type": "application/json"}
    problem_ok(d.request("POST", "/v1/validate", body='{"structure": ', headers=hdr), 400, "validate: malformed JSON", pointer="")
    bad = small(16)
    bad["structure"]["members"][1]["to"] = "Q"
    problem_ok(d.post("/v1/validate", bad), 422, "validate: unknown joint", pointer="/structure/members/1/to")
    problem_ok(d.request("POST", "/v1/validate", body=json.dumps(req), headers={"Content-Type": "text/plain"}),
               415, "validate: text/plain")
    problem_ok(d.request("POST", "/v1/validate", body=json.dumps(req)[:-1] + ', "pad": "' + "x" * 20000 + '"}',
                         headers=hdr), 413, "validate: body > --max-body")
    r = d.get("/v1/validate")
    problem_ok(r, 405, "validate: GET /v1/validate")
    check("POST" in (r.headers.get("Allow") or ""), "validate: Allow lists POST (%r)" % r.headers.get("Allow"))
    stop_clean(d, "validate")


def spatial_blade(**analysis):
    """A spatial blade (DESIGN.md 7.3): precone (z), both section forms, twist, a
    flap direction and a tip inertia; 8 + 8 elements, a few tens of ms per speed."""
    return {
        "structure": {
            "joints": {"root": [0.5, 0], "mid": [3, 0, 0.1], "tip": [5.5, 0, 0.2]},
            "sections": {"inner": {"E": 7e10, "G": 2.6e10, "A": 4e-4, "I_flap": 2e-7, "I_edge": 8e-7,
                                   "J": 5e-7, "mass_per_length": 1.2},
                         "outer": {"EA": 2.8e7, "EI_flap": 1.4e4, "EI_edge": 5.6e4, "GJ": 1.3e4,
                                   "mass_per_length": 1.2}},
            "members": [{"id": "in", "from": "root", "to": "mid", "section": "inner", "elements": 8,
                         "twist_deg": 8},
                        {"id": "out", "from": "mid", "to": "tip", "section": "outer", "elements": 8,
                         "flap_direction": [0, 0, 1]}],
            "point_masses": [{"joint": "tip", "mass": 0.2, "inertia": [0, 0, 1e-3]}],
            "clamp": "root",
        },
        "frames": {"per_member": 2},
        "analysis": dict({"omega": [0, 6], "modes": 4}, **analysis),
    }


def t_spatial(sc):
    """A spatial request over HTTP: validate, submit, the result (rows of 6, schema), CSV,
    the same job for the request with its defaults written out, 422s with pointers."""
    d = sc.daemon(["--workers", "1"])
    req = spatial_blade()
    r = d.post("/v1/validate", req)
    v = r.json() or {}
    check(r.status == 200 and v.get("valid") is True, "spatial: /v1/validate -> 200 (%s %s)" % (r.status, r.text(300)))
    schema_ok(v, "Validation", "spatial: validate answer")
    canon = v.get("canonical") or {}
    jid, r = submit_id(d, req, "spatial", wait=60)
    check(jid == v.get("id"), "spatial: the job id is the one /v1/validate announced")
    done = poll(d, jid) if jid else None
    if not check(done is not None and done.get("state") == "done", "spatial: job done (%s)" % (done and done.get("error"))):
        stop_clean(d, "spatial")
        return
    res = d.get(job_path(jid) + "/result").json() or {}
    schema_ok(res, "result", "spatial: result document")
    schema_ok(done, "Job", "spatial: done status document")
    check(res.get("model", {}).get("spatial") is True and res["model"].get("dof_per_node") == 6,
          "spatial: model.spatial true, dof_per_node 6 (%s)" % res.get("model"))
    rows = [r for c in res.get("cases", []) for r in c["equilibrium"].get("nodes", [])]
    rows += [r for c in res.get("cases", []) for r in c["equilibrium"].get("joints", {}).values()]
    rows += [r for c in res.get("cases", []) for m in c["modes"] for part in m["shape"].values() for r in part]
    check(rows and all(len(x) == 6 for x in rows), "spatial: every row has 6 numbers (%d rows)" % len(rows))
    joints = res["cases"][0]["equilibrium"]["joints"]
    check(abs(joints["tip"][2] - 0.2) < 1e-9 and joints["root"] == [0.5, 0.0, 0.0, 0.0, 0.0, 0.0],
          "spatial: at rest the tip is at its z, the clamp at rest (%s)" % joints)
    csv = d.get(job_path(jid) + "/result?format=csv")
    lines = csv.body.decode().splitlines()
    check(csv.status == 200 and lines[0].startswith("omega,mode,frequency_rad_s") and len(lines) == 1 + 2 * 4,
          "spatial: CSV with one row per speed and mode (%s, %d lines)" % (csv.status, len(lines)))
    # the canonical form (defaults written out) is the same question: 200, the same job
    r = submit(d, canon)
    check(r.status == 200 and (r.json() or {}).get("id") == jid,
          "spatial: the canonical request is the same job (%s)" % r.status)
    # errors
    bad = spatial_blade(substructure_modes="paper")
    problem_ok(d.post("/v1/analyses", bad), 422, "spatial: paper basis", pointer="/analysis/substructure_modes")
    bad = spatial_blade()
    bad["structure"]["sections"]["outer"]["E"] = 7e10
    problem_ok(d.post("/v1/analyses", bad), 422, "spatial: EA and E in one section",
               pointer="/structure/sections/outer/E")
    bad = spatial_blade()
    bad["structure"]["members"][1]["flap_direction"] = [2.5, 0, 0.1]
    problem_ok(d.post("/v1/analyses", bad), 422, "spatial: flap_direction along the member (from the core)",
               pointer="/structure/members/1/flap_direction")
    stop_clean(d, "spatial")


def t_job_request(sc):
    """GET /v1/analyses/{id}/request: the job's canonical request (the web page reopens past jobs
    with it); 404 for an unknown id; the token rules of GET /v1/analyses/{id}."""
    d = sc.daemon(["--workers", "1"], name="request")
    req = small(7, modes=2)
    v = d.post("/v1/validate", req).json() or {}
    jid, r = submit_id(d, req, "request: job", wait=ts.wait_param(30), expect=(200,))
    if jid:
        r = d.get(job_path(jid) + "/request")
        check(r.status == 200 and r.media_type() == "application/json",
              "request: GET /request -> 200 application/json (%s %r)" % (r.status, r.ctype()))
        got = r.json()
        check(got == v.get("canonical"), "request: it is the canonical request (= /v1/validate's canonical): %s"
              % r.text(200))
        check(got.get("analysis", {}).get("coriolis") is True and got.get("frames") == "per_element",
              "request: defaults written out (%s)" % r.text(300))
        r2 = submit(d, got)
        check(r2.status == 200 and (r2.json() or {}).get("id") == jid,
              "request: POSTing it back is the same job (a cache hit, %s)" % r2.status)
        r = d.request("HEAD", job_path(jid) + "/request")
        check(r.status == 200 and r.body == b"", "request: HEAD -> 200 without a body (%s)" % r.status)
        problem_ok(d.post(job_path(jid) + "/request", req), 405, "request: POST /request -> 405")
    problem_ok(d.get(job_path("0" * 64) + "/request"), 404, "request: unknown id -> 404")
    problem_ok(d.get("/v1/analyses/not-an-id/request"), 404, "request: malformed id -> 404")
    problem_ok(d.get(job_path("0" * 64) + "/requests"), 404, "request: /requests is no route -> 404")
    stop_clean(d, "request")
    # --auth-reads: the token is needed as for GET /v1/analyses/{id}, checked before the id
    token = "req-Token-7"
    tf = os.path.join(sc.tmp, "req-token")
    with open(tf, "w") as f:
        f.write(token + "\n")
    os.chmod(tf, 0o600)
    d = sc.daemon(["--workers", "1", "--token-file", tf, "--auth-reads", "yes"], name="request-auth")
    auth = {"Authorization": "Bearer " + token}
    jid, r = submit_id(d, req, "request: job (auth)", wait=ts.wait_param(30), expect=(200,), headers=auth)
    if jid:
        problem_ok(d.get(job_path(jid) + "/request"), 401, "request: --auth-reads: without a token -> 401")
        problem_ok(d.get(job_path(jid)), 401, "request: --auth-reads: GET of the job without a token -> 401 too")
        r = d.get(job_path(jid) + "/request", headers=auth)
        check(r.status == 200 and r.json() == v.get("canonical"), "request: --auth-reads: with the token -> 200 (%s)"
              % r.status)
    problem_ok(d.get(job_path("0" * 64) + "/request"), 401, "request: --auth-reads: unknown id without a token -> 401")
    problem_ok(d.get(job_path("0" * 64) + "/request", headers=auth), 404,
               "request: --auth-reads: unknown id with the token -> 404")
    stop_clean(d, "request auth")


# ------------------------------------------------------------------ main

SCENARIOS = {
    "submit": t_submit,
    "resubmit": t_resubmit,
    "wait": t_wait,
    "cancel": t_cancel,
    "solve_threads": t_solve_threads,
    "csv": t_csv,
    "auth": t_auth,
    "errors": t_errors,
    "concurrent": t_concurrent,
    "queue_full": t_queue_full,
    "kill9": t_kill9,
    "timeout": t_timeout,
    "no_equilibrium": t_no_equilibrium,
    "bad_requests": t_bad_requests,
    "metrics": t_metrics,
    "list": t_list,
    "misc": t_misc,
    "validate": t_validate,
    "spatial": t_spatial,
    "request": t_job_request,
}


def main(argv):
    global EXE, ROOT
    if len(argv) >= 3 and argv[2] == "list":
        print("\n".join(SCENARIOS))
        return 0
    if len(argv) < 3:
        print("usage: e2e_test.py SPINMODALD SCENARIO|all [SOURCE_ROOT]", file=sys.stderr)
        return 64
    EXE = os.path.abspath(argv[1])
    ROOT = os.path.abspath(argv[3]) if len(argv) > 3 else os.path.dirname(os.path.dirname(HERE))
    load_contract()
    ts.calibrate(daemon_exe=EXE)
    names = list(SCENARIOS) if argv[2] == "all" else argv[2].split(",")
    total0 = time.monotonic()
    for name in names:
        if name not in SCENARIOS:
            print("unknown scenario %r (have: %s)" % (name, ", ".join(SCENARIOS)), file=sys.stderr)
            return 64
        n_fail = len(FAILURES)
        sc = Scenario(name)
        t0 = time.monotonic()
        try:
            SCENARIOS[name](sc)
        except Exception as e:
            check(False, "%s: raised %r" % (name, e))
            traceback.print_exc()
        finally:
            sc.cleanup(len(FAILURES) > n_fail)
        print("time %s: %.2f s" % (name, time.monotonic() - t0), flush=True)
    print("%d failure(s), %.2f s" % (len(FAILURES), time.monotonic() - total0))
    for f in FAILURES:
        print("  FAIL " + f)
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
