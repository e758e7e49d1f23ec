#!/usr/bin/env python3
"""Tests of the spinmodald clients (clients/python, clients/curl) against a real daemon.

Usage: clients_test.py SPINMODALD SPINMODAL SOURCE_ROOT SCENARIO   (meson: one test per scenario)
       clients_test.py SPINMODALD SPINMODAL SOURCE_ROOT all

Each scenario starts its own spinmodald on a free loopback port with a temporary database
(daemon.py), runs the clients against it and prints one line per check; the exit status is 1
when a check failed, 77 (skip) when curl is missing for the curl scenario.

Time: every wait polls for its condition and gives up after timescale.budget(base)
(tests/e2e/timescale.py: scaled to the machine by a reference solve measured at the
start and SPINMODAL_TEST_TIME_FACTOR, never past meson's timeout).
"""
import sys
sys.dont_write_bytecode = True          # no __pycache__ in the source tree
import json
import math
import os
import re
import subprocess
import time
import traceback

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.append(os.path.join(os.path.dirname(HERE), "e2e"))   # timescale.py (after HERE: its daemon.py is not ours)
import timescale as ts  # noqa: E402
from daemon import Daemon, free_port  # noqa: E402

SPINMODALD = SPINMODAL = SRC = None
FAILURES = []
os.environ["PYTHONDONTWRITEBYTECODE"] = "1"   # nor from the client processes
os.environ["OPENBLAS_NUM_THREADS"] = "1"      # the CLI: one BLAS thread (DESIGN.md section 2)
B = ts.budget                                 # B(base): a wait's upper bound on this machine


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        FAILURES.append(what)
    return cond


def close(a, b, rel):
    return a is not None and b is not None and abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)


def example(name):
    return os.path.join(SRC, "examples", name)


def load_example(name):
    with open(example(name)) as f:
        return json.load(f)


def cli_solve(request, csv=False):
    """The one-shot CLI's answer for the same request (a dict), as JSON or CSV text."""
    args = [SPINMODAL, "solve"] + (["--csv"] if csv else []) + ["-"]
    p = subprocess.run(args, input=json.dumps(request).encode(), capture_output=True,
                       timeout=B(120))
    if p.returncode not in (0, 3):
        raise RuntimeError("spinmodal solve failed (%d): %s" % (p.returncode, p.stderr.decode()))
    return p.stdout.decode() if csv else json.loads(p.stdout)


def angled_sweep(speeds, elements=24):
    req = load_example("angled-beam-90.json")
    req["analysis"]["omega"] = speeds
    req["analysis"]["mode_shapes"] = False
    for m in req["structure"]["members"]:
        m["elements"] = elements
    return req


def no_equilibrium_request():
    """Single frame at beta = 90 deg, 20 rad/s: no equilibrium (README), small and fast."""
    req = load_example("angled-beam-90.json")
    req["frames"] = "single"
    req["analysis"]["mode_shapes"] = False
    for m in req["structure"]["members"]:
        m["elements"] = 6
    return req


def invalid_request():
    req = load_example("angled-beam-90.json")
    req["structure"]["sections"]["al"]["E"] = -1
    return req


def client_module():
    sys.path.insert(0, os.path.join(SRC, "clients", "python"))
    import spinmodal_client
    return spinmodal_client


def wait_running(c, id, timeout):
    """Poll until job id is running (or done/failed: then it is too late) or budget(timeout)
    runs out; the last status."""
    end = time.monotonic() + B(timeout)
    st = c.get(id)
    while st["state"] != "running" and st["state"] not in ("done", "failed") \
            and time.monotonic() < end:
        time.sleep(0.02)
        st = c.get(id)
    return st


def long_sweep():
    """201 speeds of the per-element angled beam: seconds of work, canceled long before the end."""
    return angled_sweep([round(20.0 * i / 200, 6) for i in range(201)])


def raises(fn, exc):
    try:
        fn()
    except exc as e:
        return e
    return None


def write_json(d, name, obj):
    path = os.path.join(d, name)
    with open(path, "w") as f:
        json.dump(obj, f)
    return path


# ====================================================================== scenarios

def scenario_solve(d):
    """submit + wait + result of examples/angled-beam-90.json; omega1 as the CLI; cache hit; csv."""
    sm = client_module()
    c = sm.Client(d.url, timeout=B(30))
    check(c.health().get("status") == "ready", "health(): /readyz status ready")
    check(c.live() == {"status": "ok"}, "live(): /livez {\"status\":\"ok\"}")

    st = c.submit(example("angled-beam-90.json"))
    check(re.fullmatch(r"[0-9a-f]{64}", st.get("id", "")) is not None, "submit(): id is 64 hex digits")
    check(st.get("state") in ("queued", "running", "done"), "submit(): state %r" % st.get("state"))
    final = c.wait(st["id"], timeout=B(60))
    check(final["state"] == "done", "wait(): final state done (got %r, error %r)"
          % (final["state"], final.get("error")))
    check(final["progress"] == {"done": 1, "total": 1}, "wait(): progress 1/1 (%r)" % final["progress"])
    res = c.result(st["id"])
    w1 = res["cases"][0]["modes"][0]["frequency_rad_s"]
    ref = cli_solve(load_example("angled-beam-90.json"))
    w1_cli = ref["cases"][0]["modes"][0]["frequency_rad_s"]
    check(close(w1, w1_cli, 1e-9), "result(): omega1 %.12g = CLI %.12g (1e-9 relative)" % (w1, w1_cli))
    check(res["solver"]["request_sha256"] == ref["solver"]["request_sha256"],
          "result(): request_sha256 as the CLI's")
    check(len(res["cases"][0]["modes"]) == 3 and "shape" in res["cases"][0]["modes"][0],
          "result(): 3 modes with shapes")
    check(final.get("result") == res, "status document embeds the same result")

    again = c.submit(load_example("angled-beam-90.json"), wait=5)
    check(again["id"] == st["id"] and again["state"] == "done" and "result" in again,
          "submit() of the same request (as a dict): same id, done, result embedded (cache hit)")
    check(c.get(st["id"])["state"] == "done", "get(): done")

    text = c.csv(st["id"])
    lines = text.strip().split("\n")
    check(lines[0] == "omega,mode,frequency_rad_s,frequency_hz,eig_re,eig_im,mac_to_previous,status,per_rev,rpm,label,label_confidence,tracked_index,tracking_flag",
          "csv(): header")
    check(len(lines) == 4, "csv(): 3 rows (%d)" % (len(lines) - 1))
    row = lines[1].split(",")
    check(row[1] == "1" and close(float(row[2]), w1_cli, 1e-9) and row[7] == "solved",
          "csv(): row 1 is mode 1, omega1 as the CLI, solved")
    # per_rev = omega1 / Omega and rpm = Omega 60 / (2 pi), appended after status (DESIGN.md 8)
    check(close(float(row[8]), float(row[2]) / float(row[0]), 1e-15)
          and close(float(row[9]), float(row[0]) * 60 / (2 * math.pi), 1e-15),
          "csv(): per_rev = omega1 / Omega and rpm = Omega 60 / 2 pi")
    check(text == cli_solve(load_example("angled-beam-90.json"), csv=True) or
          all(close(float(a.split(",")[2]), float(b.split(",")[2]), 1e-9)
              for a, b in zip(lines[1:], cli_solve(load_example("angled-beam-90.json"), csv=True)
                              .strip().split("\n")[1:])),
          "csv(): the CLI's CSV (frequencies to 1e-9)")

    # a failed job: no equilibrium -> failed with a result stored
    st = c.submit(no_equilibrium_request(), wait=60)
    st = c.wait(st["id"], timeout=B(60))
    check(st["state"] == "failed" and (st.get("error") or {}).get("type") == "no_equilibrium",
          "no equilibrium: state failed, error.type no_equilibrium (%r, %r)" % (st["state"], st.get("error")))
    check("result" in st and c.result(st["id"])["cases"][0]["status"] == "no_equilibrium",
          "no equilibrium: result stored and served, case status no_equilibrium")
    rows = c.campbell(no_equilibrium_request(), speeds=[20])
    check(len(rows) == 1 and rows[0]["mode"] is None and rows[0]["status"] == "no_equilibrium",
          "campbell() of a failed sweep with result: one row without mode (%r)" % rows)


def scenario_cancel(d):
    """cancel of a running long sweep (202, then canceled), of a queued job (200), 409 after."""
    sm = client_module()
    c = sm.Client(d.url, timeout=B(30))
    long_req = long_sweep()
    st = c.submit(long_req)
    check(st["state"] in ("queued", "running"), "long sweep queued or running (%s)" % st["state"])
    check(st["progress"]["total"] == 201, "progress.total 201 (%r)" % st["progress"])
    st = wait_running(c, st["id"], 30)
    check(st["state"] == "running", "long sweep running (%s)" % st["state"])

    # one worker: a second job stays queued behind the sweep
    other = c.submit(angled_sweep([1.0, 2.0], elements=8))
    check(other["state"] == "queued", "second job queued behind it (%s)" % other["state"])
    got = c.cancel(other["id"])
    check(got["state"] == "canceled", "cancel() of a queued job: canceled at once (%s)" % got["state"])
    check(c.get(other["id"])["state"] == "canceled", "get() after cancel: canceled")
    e = raises(lambda: c.result(other["id"]), sm.SpinmodalError)
    check(e is not None and e.status == 409, "result() of a canceled job: SpinmodalError 409 (%r)"
          % (e and e.status))

    got = c.cancel(st["id"])
    check(got["state"] in ("running", "canceled"), "cancel() of the running sweep: %s" % got["state"])
    check(got["state"] == "canceled" or got.get("cancel_requested") is True,
          "cancel() of the running sweep: cancel_requested true (%r)" % got.get("cancel_requested"))
    t0 = time.monotonic()
    fin = c.wait(st["id"], timeout=B(30))
    check(fin["state"] == "canceled", "wait(): the sweep ends canceled (%s)" % fin["state"])
    check(fin["progress"]["done"] < 201, "canceled before the end (%r)" % fin["progress"])
    print("     (canceled after %.2f s, %d/201 speeds)" % (time.monotonic() - t0, fin["progress"]["done"]))

    e = raises(lambda: c.cancel(st["id"]), sm.SpinmodalError)
    check(e is not None and e.status == 409 and e.title,
          "cancel() of a canceled job: SpinmodalError 409 with a title (%r)" % [e and (e.status, e.title)])
    t0 = time.monotonic()
    check(c.wait(st["id"], timeout=B(5))["state"] == "canceled" and c.wait(other["id"], timeout=B(5))["state"]
          == "canceled" and time.monotonic() - t0 < ts.scaled(2),
          "wait() of finished jobs returns at once (%.2f s, at most %.1f)" % (time.monotonic() - t0, ts.scaled(2)))

    # a canceled job submitted again is queued again (new attempt)
    again = c.submit(angled_sweep([1.0, 2.0], elements=8), wait=30)
    check(again["id"] == other["id"] and again["state"] in ("queued", "running", "done"),
          "submit() of a canceled request queues it again (%s)" % again["state"])
    fin = c.wait(again["id"], timeout=B(60))
    check(fin["state"] == "done", "resubmitted job done (%s)" % fin["state"])

    # TimeoutError from wait(): a job that runs longer than the timeout
    st = c.submit(long_req)
    e = raises(lambda: c.wait(st["id"], timeout=0.3), TimeoutError)
    check(e is not None, "wait(timeout=0.3) on a long sweep raises TimeoutError")
    c.cancel(st["id"])
    c.wait(st["id"], timeout=B(30))


def scenario_campbell(d):
    """campbell() rows (speeds x modes, omega ascending, CLI values), list() with paging."""
    sm = client_module()
    c = sm.Client(d.url, timeout=B(30))
    speeds = sm.parse_speeds("0:20:6")
    check(speeds == [0.0, 4.0, 8.0, 12.0, 16.0, 20.0], "parse_speeds('0:20:6') (%r)" % speeds)
    check(sm.parse_speeds("0,5,10") == [0.0, 5.0, 10.0], "parse_speeds('0,5,10')")
    rows = c.campbell(example("angled-beam-90-sweep.json"), speeds=speeds)
    check(len(rows) == len(speeds) * 3, "campbell(): %d rows = 6 speeds x 3 modes" % len(rows))
    om = [r["omega"] for r in rows]
    check(all(a <= b for a, b in zip(om, om[1:])), "campbell(): omega ascending")
    check(sorted(set(om)) == speeds, "campbell(): the requested speeds")
    check([r["mode"] for r in rows] == [1, 2, 3] * 6, "campbell(): modes 1..3 per speed")
    check(all(r["status"] == "solved" for r in rows), "campbell(): every row solved")
    check(all(close(r["frequency_hz"], r["frequency_rad_s"] / (2 * math.pi), 1e-12) for r in rows),
          "campbell(): frequency_hz = frequency_rad_s / 2 pi")
    ref_req = load_example("angled-beam-90-sweep.json")
    ref_req["analysis"]["omega"] = speeds
    ref = sm.parse_csv(cli_solve(ref_req, csv=True))
    check(len(ref) == len(rows) and all(close(a["frequency_rad_s"], b["frequency_rad_s"], 1e-9)
                                        for a, b in zip(rows, ref)),
          "campbell(): frequencies as the CLI's sweep (1e-9)")
    rows2 = c.campbell(load_example("angled-beam-90-sweep.json"))
    check(len(rows2) == 11 * 3, "campbell() without speeds: the request's 11 speeds x 3 modes (%d)"
          % len(rows2))

    # list(): several jobs, pages of one, state filter
    ids = set()
    for k in range(3):
        st = c.submit(angled_sweep([float(k)], elements=8), wait=30)
        ids.add(c.wait(st["id"], timeout=B(60))["id"])
    all_items = list(c.list(limit=100))
    check(len(all_items) == 5, "list(limit=100): 5 jobs (%d)" % len(all_items))
    paged = list(c.list(limit=1))
    check([i["id"] for i in paged] == [i["id"] for i in all_items],
          "list(limit=1) follows next through 5 pages, same order")
    check(ids <= {i["id"] for i in paged}, "list(): the submitted ids")
    check(all("result" not in i for i in paged), "list(): items without result")
    check(paged[0]["id"] == st["id"], "list(): newest first")
    done = list(c.list(state="done", limit=2))
    check(len(done) == 5 and all(i["state"] == "done" for i in done), "list(state='done', limit=2): 5 done")
    check(list(c.list(state="canceled")) == [], "list(state='canceled'): none")
    e = raises(lambda: list(c.list(limit=1000)), sm.SpinmodalError)
    check(e is not None and e.status == 400 and any(x.get("pointer") == "/query/limit" for x in e.errors),
          "list(limit=1000): 400 with pointer /query/limit (%r)" % [e and (e.status, e.errors)])
    # the daemon's next link (informational: the client adds state= itself if it is missing)
    page = c._call("GET", "/v1/analyses?limit=1&state=done")[2]
    print("     (next with state filter: %r)" % page.get("next"))
    # the importers write analysis.rpm: speeds in rad/s or in rpm replace it (issue 26: 422 before)
    blade = load_example("tapered-blade.json")
    rows_w = c.campbell(blade, speeds=[0, 2 * math.pi])
    check(sorted(set(r["omega"] for r in rows_w)) == [0.0, 2 * math.pi] and
          all(r["status"] == "solved" for r in rows_w),
          "campbell(request with analysis.rpm, speeds=[0, 2 pi]): solved at those speeds (%r)" %
          sorted(set(r["omega"] for r in rows_w)))
    rows_r = c.campbell(blade, rpm=[0, 60])
    check(len(rows_r) == len(rows_w) and all(close(a["frequency_rad_s"], b["frequency_rad_s"], 1e-9)
                                             for a, b in zip(rows_r, rows_w)) and
          all(close(r["rpm"], r["omega"] * 60 / (2 * math.pi), 1e-9) for r in rows_r),
          "campbell(rpm=[0, 60]) = campbell(speeds=[0, 2 pi]) (1e-9), rpm column")
    check(raises(lambda: c.campbell(blade, speeds=[1], rpm=[1]), ValueError) is not None,
          "campbell(speeds=, rpm=) together: ValueError")


def resolve(doc, pointer):
    """The value at an RFC 6901 pointer of doc; KeyError/IndexError when it is not there."""
    for tok in pointer.split("/")[1:]:
        tok = tok.replace("~1", "/").replace("~0", "~")
        doc = doc[int(tok)] if isinstance(doc, list) else doc[tok]
    return doc


def scenario_import(d):
    """import_file(): warnings as {pointer, message} like a result's input_warnings; rpm ranges."""
    sm = client_module()
    c = sm.Client(d.url, timeout=B(30))
    nrel = os.path.join(SRC, "tests", "reference", "blades", "elastodyn",
                        "NRELOffshrBsline5MW_Blade.dat")
    with open(nrel) as f:
        text = f.read()
    # issue 26: one shape for the warnings of an import and of a result
    doc = c.import_file("elastodyn", text, tip_radius=63, hub_radius=1.5, rpm=12.1)
    iw = doc.get("input_warnings")
    check(isinstance(iw, list) and all(isinstance(w, dict) and set(w) == {"pointer", "message"}
                                       for w in iw),
          "import_file(): input_warnings are {pointer, message} (%r)" % (iw,))
    check([w["pointer"] for w in iw or []] == ["/blade/section/EA", "/blade/section/GJ"],
          "import_file(): the pointers name the assumed EA and GJ (%r)" % [w.get("pointer") for w in iw or []])
    ok = True
    for w in iw or []:
        try:
            resolve(doc["request"], w["pointer"])
        except (KeyError, IndexError, ValueError):
            ok = False
    check(bool(iw) and ok, "import_file(): every pointer is a field of the imported request")
    check(doc.get("warnings") == [w["message"] for w in iw or []],
          "import_file(): 'warnings' keeps the same messages as strings (older clients)")
    # a slip both the import and the solve warn about: the same shape in both documents
    slip = c.import_file("elastodyn", text, tip_radius=63000, hub_radius=1.5, rpm=12.1)
    st = c.submit(slip["request"], wait=30)
    st = c.wait(st["id"], timeout=B(120))
    res = st.get("result") or c.result(st["id"])
    rw = res.get("input_warnings", [])
    check(bool(rw) and bool(slip.get("input_warnings")) and
          {frozenset(w) for w in rw} == {frozenset(w) for w in slip["input_warnings"]} ==
          {frozenset({"pointer", "message"})},
          "import and result warnings: the same keys {pointer, message} (%r / %r)"
          % ([sorted(w) for w in slip.get("input_warnings", [])], [sorted(w) for w in rw]))
    # an older daemon sends only the strings: the client gives them the same shape
    real_call = c._call
    c._call = lambda *a, **k: (200, {}, {"request": {}, "warnings": ["w1"], "source": {}})
    try:
        old = c.import_file("csv", "x")
    finally:
        c._call = real_call
    check(old.get("input_warnings") == [{"pointer": "", "message": "w1"}],
          "import_file() from an older daemon: input_warnings from the strings (%r)" % old)
    # rpm: one speed, a list, a range of COUNT speeds; 0:12:1 is refused, not 0 alone
    for rpm, want in ((12.1, [12.1]), ([0, 6], [0.0, 6.0]), ("0,6", [0.0, 6.0]),
                      ("0:12:4", {"from": 0.0, "to": 12.0, "steps": 3}), ("5:5:1", [5.0])):
        got = c.import_file("elastodyn", text, tip_radius=63, hub_radius=1.5,
                            rpm=rpm)["request"]["analysis"]["rpm"]
        check(got == want, "import_file(rpm=%r): analysis.rpm %r (%r)" % (rpm, want, got))
    for bad in ("0:12:1", "12:0:3", "0:12", "x"):
        e = raises(lambda: c.import_file("elastodyn", text, tip_radius=63, rpm=bad), sm.SpinmodalError)
        check(e is not None and e.status == 400 and [x.get("pointer") for x in e.errors] == ["/query/rpm"],
              "import_file(rpm=%r): 400 at /query/rpm (%r)" % (bad, e and (e.status, e.errors)))
    check(raises(lambda: sm.parse_speeds("0:15:1"), ValueError) is not None,
          "parse_speeds('0:15:1'): ValueError (COUNT counts the speeds: it would be 0 alone)")
    check(sm.parse_speeds("0:15:16") == [float(k) for k in range(16)] and sm.parse_speeds("5:5:1") == [5.0],
          "parse_speeds('0:15:16'): 0 ... 15; '5:5:1': [5]")
    # python3 -m spinmodal_client import: warnings on stderr with their pointer, --rpm ranges
    env = dict(os.environ, SPINMODAL_URL=d.url)
    env.pop("SPINMODAL_TOKEN", None)
    p = run_py(["import", "elastodyn", nrel, "--tip-radius", "63", "--hub-radius", "1.5",
                "--rpm", "0:12:13", "--full"], env)
    out = json.loads(p.stdout) if p.returncode == 0 else {}
    check(p.returncode == 0 and out.get("request", {}).get("analysis", {}).get("rpm") ==
          {"from": 0.0, "to": 12.0, "steps": 12},
          "python CLI import --rpm 0:12:13: analysis.rpm the range (%d %s)" % (p.returncode, p.stderr[-300:]))
    check(p.stderr.count("warning: /blade/section/") == 2,
          "python CLI import: 'warning: POINTER: message' on stderr (%r)" % p.stderr[-300:])
    p = run_py(["import", "elastodyn", nrel, "--tip-radius", "63", "--rpm", "0:12:1"], env)
    check(p.returncode == 64 and p.stdout == "" and "0:12:13" in p.stderr,
          "python CLI import --rpm 0:12:1: exit 64, suggests 0:12:13 (%d %r)" % (p.returncode, p.stderr[-200:]))


def scenario_errors(d):
    """SpinmodalError fields on 422, 400, 404, 409; connection errors; retry on 429."""
    sm = client_module()
    c = sm.Client(d.url, timeout=B(30))
    e = raises(lambda: c.submit(invalid_request()), sm.SpinmodalError)
    check(e is not None and e.status == 422, "422: SpinmodalError status 422 (%r)" % (e and e.status))
    if e is not None:
        check(bool(e.title) and e.type is not None, "422: type %r, title %r" % (e.type, e.title))
        check(e.invalid_request, "422: invalid_request")
        ptrs = [x.get("pointer") for x in e.errors]
        check("/structure/sections/al/E" in ptrs, "422: errors has pointer /structure/sections/al/E (%r)"
              % ptrs)
        check(all(x.get("message") for x in e.errors), "422: every error has a message")
        check("/structure/sections/al/E" in str(e), "422: str() names the pointer")
        check(e.retry_after is None, "422: no retry_after")
    v = c.validate(example("angled-beam-90.json"))
    check(v.get("valid") is True and re.fullmatch(r"[0-9a-f]{64}", v.get("id", "")) is not None
          and "canonical" in v, "validate(): valid, id, canonical")
    check(list(c.list()) == [], "validate(): nothing stored")
    e = raises(lambda: c.validate(invalid_request()), sm.SpinmodalError)
    check(e is not None and e.status == 422 and "/structure/sections/al/E" in [x.get("pointer") for x in e.errors],
          "validate() of an invalid request: 422 with the pointer")
    big = dict(load_example("angled-beam-90.json"), comment="x" * (2 << 20))
    e = raises(lambda: c.submit(big), sm.SpinmodalError)
    check(e is not None and e.status == 413 and e.invalid_request,
          "2 MiB body: SpinmodalError 413 (the early answer is read) (%r)" % [e and (e.status, str(e))])
    e = raises(lambda: c.submit(b'{"structure": '), sm.SpinmodalError)
    check(e is not None and e.status == 400 and [x.get("pointer") for x in e.errors] == [""],
          "400 malformed JSON: pointer \"\" (%r)" % [e and (e.status, e.errors)])
    e = raises(lambda: c.submit(load_example("angled-beam-90.json"), wait=-1), sm.SpinmodalError)
    check(e is None, "submit(wait=-1) is clamped to 0 (no 400)")
    e = raises(lambda: c._call("POST", "/v1/analyses", body=json.dumps(load_example("angled-beam-90.json"))
                               .encode(), query={"wait": "61"}), sm.SpinmodalError)
    check(e is not None and e.status == 400 and any(x.get("pointer") == "/query/wait" for x in e.errors),
          "?wait=61: 400 with pointer /query/wait (%r)" % [e and (e.status, e.errors)])
    e = raises(lambda: c.get("0" * 64), sm.SpinmodalError)
    check(e is not None and e.status == 404 and bool(e.title), "404 unknown id: status 404, title (%r)"
          % [e and (e.status, e.title)])
    check(e is not None and not e.invalid_request, "404: not invalid_request")
    e = raises(lambda: c.get("not-an-id"), sm.SpinmodalError)
    check(e is not None and e.status == 404, "404 for an id that is not 64 hex digits")
    e = raises(lambda: c.result("f" * 64), sm.SpinmodalError)
    check(e is not None and e.status == 404, "404 result of an unknown id")
    e = raises(lambda: c.cancel("f" * 64), sm.SpinmodalError)
    check(e is not None and e.status == 404, "404 cancel of an unknown id")
    st = c.submit(example("angled-beam-90.json"), wait=60)
    st = c.wait(st["id"], timeout=B(60))
    e = raises(lambda: c.cancel(st["id"]), sm.SpinmodalError)
    check(e is not None and e.status == 409, "409 cancel of a done job")
    check(st["id"] == v["id"], "validate() id = the job id")

    bad = sm.Client("http://127.0.0.1:%d" % free_port(), timeout=B(5))
    e = raises(bad.health, sm.SpinmodalError)
    check(isinstance(e, sm.SpinmodalConnectionError) and e.status is None and "127.0.0.1" in str(e),
          "connection refused: SpinmodalConnectionError naming the URL (%s)" % e)
    e = raises(lambda: bad.submit(example("angled-beam-90.json")), sm.SpinmodalConnectionError)
    check(e is not None, "connection refused on submit: SpinmodalConnectionError")


def scenario_queue_full(d):
    """429 + Retry-After with --queue-max 1 and one worker; submit(retry=True) waits it out."""
    sm = client_module()
    c = sm.Client(d.url, timeout=B(30))
    first = c.submit(long_sweep())
    check(wait_running(c, first["id"], 30)["state"] == "running", "long sweep running")
    c.submit(angled_sweep([1.0], elements=8))        # fills the queue (queue-max 1)
    e = raises(lambda: c.submit(angled_sweep([2.0], elements=8)), sm.SpinmodalError)
    check(e is not None and e.status == 429, "429 when the queue is full (%r)" % (e and e.status))
    check(e is not None and e.retry_after is not None and e.retry_after >= 0,
          "429: retry_after from Retry-After (%r)" % (e and e.retry_after))
    check(e is not None and not e.invalid_request, "429: not invalid_request")
    c.cancel(first["id"])      # the queued job runs, the queue empties, the retry gets through
    st = c.submit(angled_sweep([2.0], elements=8), retry=True, retries=30)
    check(st["state"] in ("queued", "running", "done"), "submit(retry=True) gets through (%s)" % st["state"])
    c.wait(st["id"], timeout=B(60))


def scenario_token(d):
    """--token-file: POST/DELETE need the bearer token, GET does not; python client and curl."""
    sm = client_module()
    anon = sm.Client(d.url, timeout=B(30))
    auth = sm.Client(d.url, token="s3cret-token", timeout=B(30))
    wrong = sm.Client(d.url, token="wrong", timeout=B(30))
    e = raises(lambda: anon.submit(example("angled-beam-90.json")), sm.SpinmodalError)
    check(e is not None and e.status == 401, "no token: submit() 401 (%r)" % (e and e.status))
    e = raises(lambda: wrong.submit(example("angled-beam-90.json")), sm.SpinmodalError)
    check(e is not None and e.status == 401, "wrong token: submit() 401 (%r)" % (e and e.status))
    st = auth.submit(example("angled-beam-90.json"), wait=60)
    check(st["state"] in ("queued", "running", "done"), "right token: submit() accepted (%s)" % st["state"])
    st = anon.wait(st["id"], timeout=B(60))
    check(st["state"] == "done", "no token: wait()/get() work (GET needs no token)")
    check(anon.result(st["id"])["cases"][0]["status"] == "solved", "no token: result() works")
    e = raises(lambda: anon.cancel(st["id"]), sm.SpinmodalError)
    check(e is not None and e.status == 401, "no token: cancel() 401 (%r)" % (e and e.status))

    env = dict(os.environ, SPINMODAL_URL=d.url)
    env.pop("SPINMODAL_TOKEN", None)
    p = run_py(["solve", example("straight-blade.json")], env)
    check(p.returncode == 3 and "401" in p.stderr, "python CLI without --token: exit 3, 401 (%d)" % p.returncode)
    p = run_py(["solve", example("straight-blade.json"), "--token", "s3cret-token"], env)
    check(p.returncode == 0, "python CLI --token: exit 0 (%d) %s" % (p.returncode, p.stderr[-300:]))
    if have_curl():
        p = run_sh("submit.sh", [example("straight-blade.json")], env)
        check(p.returncode == 3 and "401" in p.stderr, "submit.sh without SPINMODAL_TOKEN: exit 3, 401 (%d)"
              % p.returncode)
        p = run_sh("submit.sh", [example("straight-blade.json")], dict(env, SPINMODAL_TOKEN="s3cret-token"))
        check(p.returncode == 0 and json.loads(p.stdout)["cases"][0]["status"] == "solved",
              "submit.sh with SPINMODAL_TOKEN: exit 0, result (%d) %s" % (p.returncode, p.stderr[-300:]))


# --------------------------------------------------------------- python CLI

def run_py(args, env, cwd=None, timeout=None):
    if cwd is None:
        env = dict(env, PYTHONPATH=os.path.join(SRC, "clients", "python"))
    return subprocess.run([sys.executable, "-m", "spinmodal_client"] + args, env=env, cwd=cwd,
                          capture_output=True, text=True, timeout=timeout or B(120))


def scenario_python_cli(d):
    """python3 -m spinmodal_client: solve/status/cancel/list/campbell, exit codes 0/1/2/3/64."""
    env = dict(os.environ, SPINMODAL_URL=d.url)
    env.pop("SPINMODAL_TOKEN", None)
    env.pop("PYTHONPATH", None)
    pkg = os.path.join(SRC, "clients", "python")
    p = run_py(["solve", example("angled-beam-90.json")], env, cwd=pkg)
    check(p.returncode == 0, "cd clients/python && python3 -m spinmodal_client solve: exit 0 (%d) %s"
          % (p.returncode, p.stderr[-300:]))
    res = json.loads(p.stdout) if p.returncode == 0 else {}
    w1_cli = cli_solve(load_example("angled-beam-90.json"))["cases"][0]["modes"][0]["frequency_rad_s"]
    check(close(res.get("cases", [{}])[0].get("modes", [{}])[0].get("frequency_rad_s"), w1_cli, 1e-9),
          "solve: omega1 as the CLI")
    p = run_py(["solve", "--csv", example("angled-beam-90.json"), "--url", d.url], dict(env, SPINMODAL_URL="http://127.0.0.1:1"))
    check(p.returncode == 0 and p.stdout.startswith("omega,mode,") and len(p.stdout.strip().split("\n")) == 4,
          "PYTHONPATH=clients/python ... solve --csv --url: exit 0, header + 3 rows (%d)" % p.returncode)
    # solve --table (DESIGN.md 8): the same table as the CLI's --table, from the daemon's result
    p = run_py(["solve", "--table", example("tapered-blade.json")], env)
    cli = subprocess.run([SPINMODAL, "solve", "--table", example("tapered-blade.json")], capture_output=True, text=True,
                         timeout=B(120), env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    lines = p.stdout.splitlines()
    check(p.returncode == 0 and lines and lines[0].split() == ["omega_rad_s", "rpm", "mode", "freq_rad_s",
                                                               "freq_hz", "per_rev", "status", "label"]
          and len(set(len(l) for l in lines)) == 1,
          "solve --table: header, aligned rows (%d) %s" % (p.returncode, p.stderr[-200:]))
    check(p.stdout == cli.stdout, "solve --table: the same table as `spinmodal solve --table`:\n%s\n%s"
          % (p.stdout[:400], cli.stdout[:400]))
    with open(example("angled-beam-90.json")) as f:
        p = subprocess.run([sys.executable, "-m", "spinmodal_client", "solve", "-"], stdin=f, env=dict(env, PYTHONPATH=pkg),
                           capture_output=True, text=True, timeout=B(120))
    check(p.returncode == 0, "solve - (stdin): exit 0 (%d)" % p.returncode)

    tmp = os.path.join(d.tmp, "cli")
    os.makedirs(tmp, exist_ok=True)
    bad = write_json(tmp, "bad.json", invalid_request())
    p = run_py(["solve", bad], env)
    check(p.returncode == 2 and "/structure/sections/al/E" in p.stderr,
          "solve of an invalid request: exit 2, pointer on stderr (%d)" % p.returncode)
    malformed = os.path.join(tmp, "malformed.json")
    with open(malformed, "w") as f:
        f.write("{not json")
    p = run_py(["solve", malformed], env)
    check(p.returncode == 2 and "400" in p.stderr, "solve of malformed JSON: exit 2, 400 (%d)" % p.returncode)
    p = run_py(["validate", example("angled-beam-90.json")], env)
    check(p.returncode == 0 and json.loads(p.stdout).get("valid") is True, "validate: exit 0, valid")
    p = run_py(["validate", bad], env)
    check(p.returncode == 2 and "/structure/sections/al/E" in p.stderr, "validate of an invalid request: exit 2")
    p = run_py(["solve", os.path.join(tmp, "missing.json")], env)
    check(p.returncode == 2, "solve of a missing file: exit 2 (%d)" % p.returncode)
    noeq = write_json(tmp, "noeq.json", no_equilibrium_request())
    p = run_py(["solve", noeq], env)
    check(p.returncode == 1 and "no_equilibrium" in p.stderr and json.loads(p.stdout or "{}").get("cases"),
          "solve with no equilibrium: exit 1, error on stderr, result on stdout (%d)" % p.returncode)
    p = run_py(["solve", example("angled-beam-90.json"), "--url", "http://127.0.0.1:%d" % free_port()], env)
    check(p.returncode == 3 and "cannot reach" in p.stderr, "solve, daemon not there: exit 3 (%d) %s"
          % (p.returncode, p.stderr.strip()[-200:]))

    sm = client_module()
    c = sm.Client(d.url)
    sid = c.submit(example("angled-beam-90.json"))["id"]
    p = run_py(["status", sid], env)
    check(p.returncode == 0 and json.loads(p.stdout)["state"] == "done", "status ID: exit 0, done")
    failed = [i["id"] for i in c.list(state="failed")]
    check(len(failed) == 1, "one failed job (%d)" % len(failed))
    nid = failed[0] if failed else "0" * 64
    p = run_py(["status", nid], env)
    check(p.returncode == 1, "status of a failed job: exit 1 (%d)" % p.returncode)
    p = run_py(["status", "0" * 64], env)
    check(p.returncode == 3 and "404" in p.stderr, "status of an unknown id: exit 3, 404 (%d)" % p.returncode)
    p = run_py(["cancel", sid], env)
    check(p.returncode == 3 and "409" in p.stderr, "cancel of a done job: exit 3, 409 (%d)" % p.returncode)
    n_jobs = len(list(c.list()))
    p = run_py(["list"], env)
    check(p.returncode == 0 and n_jobs == 3 and len(p.stdout.strip().split("\n")) == n_jobs and sid in p.stdout,
          "list: exit 0, 3 jobs (angled beam, tapered blade, the failed one) (%d): %s" % (p.returncode, p.stdout))
    p = run_py(["list", "--state", "failed", "--json", "--limit", "1"], env)
    check(p.returncode == 0 and [json.loads(x)["id"] for x in p.stdout.split("\n") if x] == [nid],
          "list --state failed --json: the failed job")
    p = run_py(["campbell", example("angled-beam-90-sweep.json"), "--speeds", "0:20:3"], env)
    lines = p.stdout.strip().split("\n")
    check(p.returncode == 0 and len(lines) == 4 and "mode 3" in lines[0]
          and [float(x.split()[0]) for x in lines[1:]] == [0.0, 10.0, 20.0],
          "campbell --speeds 0:20:3: exit 0, header + 3 speed lines (%d):\n%s" % (p.returncode, p.stdout))
    p = run_py(["campbell", example("angled-beam-90-sweep.json"), "--speeds", "0:20"], env)
    check(p.returncode == 64, "campbell --speeds 0:20: exit 64 (%d)" % p.returncode)
    p = run_py(["campbell", example("tapered-blade.json"), "--rpm", "0:60:2", "--csv"], env)
    rows = p.stdout.strip().split("\n")[1:]
    om = sorted(set(round(float(r.split(",")[0]), 9) for r in rows)) if p.returncode == 0 else []
    check(p.returncode == 0 and om == [0.0, round(2 * math.pi, 9)],
          "campbell --rpm 0:60:2 of a request with analysis.rpm: exit 0 at 0 and 2 pi rad/s (%d %r %s)"
          % (p.returncode, om, p.stderr[-200:]))
    p = run_py(["campbell", example("tapered-blade.json"), "--rpm", "0:60:2", "--speeds", "0,1"], env)
    check(p.returncode == 64, "campbell --rpm with --speeds: exit 64 (%d)" % p.returncode)
    p = run_py([], env)
    check(p.returncode == 64, "no command: exit 64 (%d)" % p.returncode)
    p = run_py(["solve"], env)
    check(p.returncode == 64 and "usage" in p.stderr, "solve without a file: exit 64, usage (%d)" % p.returncode)
    p = run_py(["--help"], env)
    check(p.returncode == 0 and "solve" in p.stdout, "--help: exit 0")


# --------------------------------------------------------------- curl scripts

def have_curl():
    from shutil import which
    return which("curl") is not None


def run_sh(script, args, env, stdin=None, timeout=None):
    return subprocess.run(["bash", os.path.join(SRC, "clients", "curl", script)] + args, env=env,
                          input=stdin, capture_output=True, text=True, timeout=timeout or B(120))


def scenario_curl(d):
    """clients/curl/*.sh end to end against the daemon: output and exit codes."""
    if not have_curl():
        print("SKIP curl is not installed")
        sys.exit(77)
    env = dict(os.environ, SPINMODAL_URL=d.url + "/")   # a trailing slash is tolerated
    env.pop("SPINMODAL_TOKEN", None)
    tmp = os.path.join(d.tmp, "curl")
    os.makedirs(tmp, exist_ok=True)

    for s in ("submit.sh", "csv.sh", "campbell.sh", "cancel.sh", "list.sh"):
        p = run_sh(s, ["--help"], env)
        check(p.returncode == 0 and p.stdout.startswith("usage: " + s), "%s --help: usage, exit 0" % s)
        p = run_sh(s, ["--bogus", "x", "y"], env)
        check(p.returncode == 64 and "usage: " + s in p.stderr, "%s with wrong args: usage on stderr, exit 64 (%d)"
              % (s, p.returncode))

    w1_cli = cli_solve(load_example("angled-beam-90.json"))["cases"][0]["modes"][0]["frequency_rad_s"]
    p = run_sh("submit.sh", [example("angled-beam-90.json")], env)
    check(p.returncode == 0, "submit.sh: exit 0 (%d) %s" % (p.returncode, p.stderr[-300:]))
    res = json.loads(p.stdout) if p.returncode == 0 else {}
    check(close(res.get("cases", [{}])[0].get("modes", [{}])[0].get("frequency_rad_s"), w1_cli, 1e-9),
          "submit.sh: prints the result, omega1 as the CLI")
    p = run_sh("submit.sh", ["--id", example("angled-beam-90.json")], env)
    jid = p.stdout.strip()
    check(p.returncode == 0 and re.fullmatch(r"[0-9a-f]{64}", jid) is not None, "submit.sh --id: the id")
    p = run_sh("submit.sh", ["--status", "-"], env, stdin=open(example("straight-blade.json")).read())
    check(p.returncode == 0 and json.loads(p.stdout)["state"] == "done", "submit.sh --status - (stdin): done")

    bad = write_json(tmp, "bad.json", invalid_request())
    p = run_sh("submit.sh", [bad], env)
    prob = p.stderr[p.stderr.find("{"):] if "{" in p.stderr else "{}"
    check(p.returncode == 2 and p.stdout == "" and json.loads(prob).get("status") == 422
          and "/structure/sections/al/E" in prob,
          "submit.sh of an invalid request: exit 2, problem+json on stderr (%d) %s" % (p.returncode, p.stderr[-300:]))
    noeq = write_json(tmp, "noeq.json", no_equilibrium_request())
    p = run_sh("submit.sh", [noeq], env)
    check(p.returncode == 1 and "failed" in p.stderr and json.loads(p.stdout or "{}").get("cases"),
          "submit.sh with no equilibrium: exit 1, error on stderr, result on stdout (%d)" % p.returncode)
    p = run_sh("submit.sh", [example("angled-beam-90.json")], dict(env, SPINMODAL_URL="http://127.0.0.1:%d" % free_port()))
    check(p.returncode == 3 and "cannot reach" in p.stderr, "submit.sh, daemon not there: exit 3 (%d)" % p.returncode)
    big = write_json(tmp, "big.json", dict(load_example("angled-beam-90.json"), comment="x" * (2 << 20)))
    p = run_sh("submit.sh", [big], env)
    check(p.returncode == 2 and "413" in p.stderr, "submit.sh of a 2 MiB body: exit 2, 413 (%d) %s"
          % (p.returncode, p.stderr[-300:]))
    p = run_sh("submit.sh", [os.path.join(tmp, "missing.json")], env)
    check(p.returncode == 2, "submit.sh of a missing file: exit 2 (%d)" % p.returncode)

    p = run_sh("csv.sh", [jid], env)
    lines = p.stdout.strip().split("\n")
    check(p.returncode == 0 and lines[0].startswith("omega,mode,frequency_rad_s,frequency_hz") and len(lines) == 4,
          "csv.sh ID: exit 0, header + 3 rows (%d)" % p.returncode)
    check(len(lines) > 1 and close(float(lines[1].split(",")[2]), w1_cli, 1e-9), "csv.sh ID: omega1 as the CLI")
    p = run_sh("csv.sh", [example("straight-blade.json")], env)
    check(p.returncode == 0 and len(p.stdout.strip().split("\n")) == 5, "csv.sh REQUEST: exit 0, header + 4 rows (%d)"
          % p.returncode)
    p = run_sh("csv.sh", [noeq], env)
    check(p.returncode == 1 and p.stdout.strip().split("\n")[-1].split(",")[7] == "no_equilibrium",
          "csv.sh of a failed job: exit 1, CSV still printed (%d)" % p.returncode)
    p = run_sh("csv.sh", ["0" * 64], env)
    check(p.returncode == 3 and "404" in p.stderr, "csv.sh of an unknown id: exit 3, 404 (%d)" % p.returncode)

    p = run_sh("campbell.sh", [example("angled-beam-90.json"), "0:20:4"], env)
    lines = p.stdout.strip().split("\n")
    check(p.returncode == 0 and len(lines) == 1 + 4 * 3, "campbell.sh 0:20:4: exit 0, 12 rows (%d, %d lines) %s"
          % (p.returncode, len(lines), p.stderr[-300:]))
    om = [float(x.split(",")[0]) for x in lines[1:]]
    want = [0.0, 20.0 / 3, 40.0 / 3, 20.0]
    check(om == sorted(om) and len(set(om)) == 4 and all(close(x, y, 1e-9) for x, y in zip(sorted(set(om)), want)),
          "campbell.sh: omega 0, 6.67, 13.3, 20 ascending (%r)" % sorted(set(om)))
    p = run_sh("campbell.sh", [example("angled-beam-90.json"), "0,10"], env)
    check(p.returncode == 0 and len(p.stdout.strip().split("\n")) == 7, "campbell.sh 0,10: exit 0, 6 rows")
    p = run_sh("campbell.sh", ["--rpm", example("tapered-blade.json"), "0:60:2"], env)
    lines = p.stdout.strip().split("\n")
    om = sorted(set(round(float(x.split(",")[0]), 9) for x in lines[1:]))
    check(p.returncode == 0 and om == [0.0, round(2 * math.pi, 9)],
          "campbell.sh --rpm on an imported-style request (analysis.rpm): exit 0, 0 and 60 rpm (%d %r %s)"
          % (p.returncode, om, p.stderr[-200:]))
    p = run_sh("campbell.sh", [example("tapered-blade.json"), "0,5"], env)
    check(p.returncode == 0 and len(p.stdout.strip().split("\n")) == 1 + 2 * 4,
          "campbell.sh rad/s on a request with analysis.rpm: exit 0, 8 rows (%d %s)" % (p.returncode, p.stderr[-200:]))
    p = run_sh("campbell.sh", [example("angled-beam-90.json"), "0:x:3"], env)
    check(p.returncode == 64, "campbell.sh with a bad range: exit 64 (%d)" % p.returncode)
    p = run_sh("campbell.sh", ["--rpm", example("tapered-blade.json"), "0:15:1"], env)
    check(p.returncode == 64 and "COUNT" in p.stderr,
          "campbell.sh --rpm 0:15:1: exit 64, COUNT counts the speeds (%d %r)" % (p.returncode, p.stderr[-200:]))

    # cancel.sh of a running sweep (one worker, the daemon of this scenario)
    sm = client_module()
    c = sm.Client(d.url)
    long_path = write_json(tmp, "long.json", long_sweep())
    p = run_sh("submit.sh", ["--no-wait", "--id", long_path], env)
    check(p.returncode == 0 and re.fullmatch(r"[0-9a-f]{64}\n", p.stdout) is not None,
          "submit.sh --no-wait --id: exit 0 at once, the id (%d)" % p.returncode)
    st = wait_running(c, p.stdout.strip() or "0" * 64, 30)
    p = run_sh("cancel.sh", [st["id"]], env)
    doc = json.loads(p.stdout) if p.returncode == 0 else {}
    check(p.returncode == 0 and (doc.get("cancel_requested") is True or doc.get("state") == "canceled"),
          "cancel.sh of a running sweep: exit 0, cancel_requested (%d) %s" % (p.returncode, p.stderr[-300:]))
    fin = c.wait(st["id"], timeout=B(30))
    check(fin["state"] == "canceled", "the sweep ends canceled (%s)" % fin["state"])
    p = run_sh("cancel.sh", [st["id"]], env)
    check(p.returncode == 3 and "409" in p.stderr, "cancel.sh of a canceled job: exit 3, 409 (%d)" % p.returncode)
    # submit.sh resubmits the canceled sweep and waits; canceled under it, it exits 1
    bg = subprocess.Popen(["bash", os.path.join(SRC, "clients", "curl", "submit.sh"), "--wait", "2", long_path],
                          env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    end = time.monotonic() + B(30)
    while c.get(st["id"])["state"] != "running" and time.monotonic() < end and bg.poll() is None:
        time.sleep(0.02)
    c.cancel(st["id"])
    out, err = bg.communicate(timeout=B(60))
    check(bg.returncode == 1 and "canceled" in err and out == "",
          "submit.sh of a job canceled while it waits: exit 1, 'canceled' on stderr (%d) %s" % (bg.returncode, err[-300:]))

    n_jobs = len(list(c.list(limit=100)))
    p = run_sh("list.sh", [], env)
    check(p.returncode == 0 and len(p.stdout.strip().split("\n")) == n_jobs,
          "list.sh: exit 0, one line per job (%d lines, %d jobs)" % (len(p.stdout.strip().split("\n")), n_jobs))
    p = run_sh("list.sh", ["--limit", "2"], env)
    check(p.returncode == 0 and len(p.stdout.strip().split("\n")) == 2 and "--before" in p.stderr,
          "list.sh --limit 2: 2 lines, next page hint on stderr")
    p = run_sh("list.sh", ["--limit", "1", "--all"], env)
    check(p.returncode == 0 and len(p.stdout.strip().split("\n")) == n_jobs, "list.sh --limit 1 --all: every job")
    p = run_sh("list.sh", ["--state", "failed", "--json", "--limit", "1", "--all"], env)
    items = [json.loads(x) for x in p.stdout.split("\n") if x]
    check(p.returncode == 0 and len(items) == 1 and items[0]["state"] == "failed",
          "list.sh --state failed --json --all: the one failed job (%r)" % [i["state"] for i in items])
    p = run_sh("list.sh", ["--limit", "0"], env)
    check(p.returncode == 2 and "400" in p.stderr, "list.sh --limit 0: exit 2, 400 (%d)" % p.returncode)


SCENARIOS = {
    "solve": (scenario_solve, {}),
    "cancel": (scenario_cancel, {"workers": 1}),
    "campbell": (scenario_campbell, {}),
    "errors": (scenario_errors, {}),
    "queue_full": (scenario_queue_full, {"workers": 1, "extra": ["--queue-max", "1"]}),
    "token": (scenario_token, {"token": "s3cret-token"}),
    "python_cli": (scenario_python_cli, {}),
    "import": (scenario_import, {}),
    "curl": (scenario_curl, {"workers": 1}),
}


def run_scenario(name):
    fn, kw = SCENARIOS[name]
    print("== %s: %s" % (name, fn.__doc__.strip().split("\n")[0]), flush=True)
    d = Daemon(SPINMODALD, **kw)
    try:
        d.start()
    except Exception as e:
        check(False, "%s: daemon started: %s" % (name, e))
        return
    t0 = time.monotonic()
    try:
        fn(d)
    except SystemExit:
        raise
    except Exception:
        traceback.print_exc()
        check(False, "%s: no exception" % name)
    finally:
        print("     (%s: %.1f s)" % (name, time.monotonic() - t0))
        rc = d.stop()
        if rc != 0:
            print("WARN spinmodald exit status %r after SIGTERM (DAEMON.md: 0 after a clean stop)" % rc)
        if FAILURES:
            print("---- spinmodald log (last 60 lines)")
            print("\n".join(d.log().split("\n")[-60:]))


def main(argv):
    global SPINMODALD, SPINMODAL, SRC
    if len(argv) != 5 or (argv[4] != "all" and argv[4] not in SCENARIOS):
        print("usage: %s SPINMODALD SPINMODAL SOURCE_ROOT {%s|all}" % (argv[0], "|".join(SCENARIOS)),
              file=sys.stderr)
        return 64
    SPINMODALD, SPINMODAL, SRC = os.path.abspath(argv[1]), os.path.abspath(argv[2]), os.path.abspath(argv[3])
    ts.calibrate(cli=SPINMODAL)
    for name in (SCENARIOS if argv[4] == "all" else [argv[4]]):
        run_scenario(name)
    print("%d check(s) failed" % len(FAILURES) if FAILURES else "all checks passed")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
