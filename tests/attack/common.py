"""Shared pieces of the hostile re-run (attack.py): the tally, the checks, helpers.

Python 3 standard library only.  The daemon harness and the time scale are
those of the end-to-end tests (tests/e2e/daemon.py, tests/e2e/timescale.py):
every wait polls for its condition and gives up after a base budget times the
machine's factor, so nothing here passes or fails by how fast the machine is.
"""
import json
import math
import os
import select
import socket
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, os.pardir, os.pardir))
sys.path.insert(0, os.path.join(ROOT, "tests", "e2e"))

from daemon import Daemon, DaemonError, raw_exchange  # noqa: E402,F401
import timescale  # noqa: E402,F401

EXAMPLE = os.path.join(ROOT, "examples", "angled-beam-90.json")
JSON_CT = {"Content-Type": "application/json"}


class Tally:
    """Counts per (category, outcome) and the broken invariants.

    add(category, outcome) counts one request or event; broken(category, what)
    records an invariant that does not hold (the run then exits 1); note()
    keeps a figure for the report.
    """

    def __init__(self, verbose=False):
        self.counts = {}          # category -> {outcome: n}
        self.order = []           # categories in first-seen order
        self.violations = []      # (category, text)
        self.figures = []         # (name, value text)
        self.skipped = []         # (what, why)
        self.verbose = verbose
        self.lock = threading.Lock()

    def add(self, category, outcome, n=1):
        with self.lock:
            if category not in self.counts:
                self.counts[category] = {}
                self.order.append(category)
            c = self.counts[category]
            c[outcome] = c.get(outcome, 0) + n

    def broken(self, category, what):
        with self.lock:
            self.violations.append((category, what))
        print("BROKEN [%s] %s" % (category, what), flush=True)

    def check(self, ok, category, what):
        if not ok:
            self.broken(category, what)
        elif self.verbose:
            print("ok [%s] %s" % (category, what), flush=True)
        return ok

    def figure(self, name, value):
        with self.lock:
            self.figures.append((name, value))
        print("figure %s: %s" % (name, value), flush=True)

    def skip(self, what, why):
        self.skipped.append((what, why))
        print("SKIP %s: %s" % (what, why), flush=True)

    def total(self, category):
        return sum(self.counts.get(category, {}).values())

    def table(self):
        """The report: one line per category and outcome, then figures and violations."""
        out = ["%-12s %-62s %7s" % ("category", "outcome", "count"), "-" * 83]
        for cat in self.order:
            items = sorted(self.counts[cat].items(), key=lambda kv: (-kv[1], kv[0]))
            for i, (outcome, n) in enumerate(items):
                out.append("%-12s %-62s %7d" % (cat if i == 0 else "", outcome[:62], n))
            out.append("%-12s %-62s %7d" % ("", "= total", self.total(cat)))
        if self.figures:
            out.append("")
            for name, value in self.figures:
                out.append("%-60s %s" % (name, value))
        for what, why in self.skipped:
            out.append("skipped: %s (%s)" % (what, why))
        out.append("")
        out.append("invariants broken: %d" % len(self.violations))
        for cat, what in self.violations:
            out.append("  [%s] %s" % (cat, what))
        return "\n".join(out)


def outcome_of(r):
    """A short label of an answer: '422', '413', 'closed', 'timeout', ..."""
    if r is None:
        return "no answer"
    if r.status is None:
        err = r.error or ""
        if "timeout" in err:
            return "timeout"
        return "closed" if not r.body else "unparsable"
    return str(r.status)


def problem_pointers(r):
    """The pointers of a problem document's errors (None when it is not one)."""
    doc = r.json()
    if not isinstance(doc, dict) or "status" not in doc or "title" not in doc:
        return None
    errs = doc.get("errors")
    if not isinstance(errs, list):
        return []
    return [e.get("pointer") for e in errs if isinstance(e, dict)]


def is_problem(r):
    return r.media_type() == "application/problem+json" and problem_pointers(r) is not None


def livez(d, base=10):
    """True when GET /livez answers 200 within budget(base) seconds."""
    try:
        r = d.get("/livez", timeout=base)
        return r.status == 200
    except OSError:
        return False


def rss_kb(pid):
    try:
        with open("/proc/%d/status" % pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return -1


def db_bytes(path):
    """Bytes of a SQLite database with its WAL and shared-memory files."""
    n = 0
    for ext in ("", "-wal", "-shm"):
        try:
            n += os.path.getsize(path + ext)
        except OSError:
            pass
    return n


def small_request(omega=10.0, elements=4, **analysis):
    """A valid, cheap planar request (distinct omegas give distinct jobs)."""
    req = {"structure": {"joints": {"O": [0, 0], "C": [5, 0], "P": [5, 5]},
                         "sections": {"al": {"E": 7e10, "A": 4e-4, "I": 2e-7,
                                             "mass_per_length": 1.2}},
                         "members": [{"id": "beam1", "from": "O", "to": "C", "section": "al",
                                      "elements": elements},
                                     {"id": "beam2", "from": "C", "to": "P", "section": "al",
                                      "elements": elements}],
                         "clamp": "O"},
           "analysis": {"omega": omega, "mode_shapes": False}}
    req["analysis"].update(analysis)
    return req


def sweep_request(n_speeds, first=0.0, elements=24):
    """The angled beam of the example swept over n_speeds speeds (a longer job)."""
    with open(EXAMPLE) as f:
        req = json.load(f)
    for m in req["structure"]["members"]:
        m["elements"] = elements
    req["analysis"]["omega"] = [first + 0.1 * i for i in range(n_speeds)]
    req["analysis"]["mode_shapes"] = False
    return req


def nonfinite(doc, path=""):
    """The path of the first number of a parsed JSON document that is not
    finite (Python's json reads the NaN and Infinity tokens), or None."""
    if isinstance(doc, float):
        return None if math.isfinite(doc) else (path or "/")
    if isinstance(doc, dict):
        items = doc.items()
    elif isinstance(doc, list):
        items = enumerate(doc)
    else:
        return None
    for k, v in items:
        where = nonfinite(v, "%s/%s" % (path, k))
        if where:
            return where
    return None


def solved_nan(result):
    """Where a solved case of a result document has a number that is not finite
    or a missing frequency; None when every solved case is clean."""
    if not isinstance(result, dict):
        return None
    for i, case in enumerate(result.get("cases") or []):
        if not isinstance(case, dict) or case.get("status") != "solved":
            continue
        for k, mode in enumerate(case.get("modes") or []):
            f = mode.get("frequency_rad_s") if isinstance(mode, dict) else None
            if not isinstance(f, (int, float)) or not math.isfinite(f):
                return "cases/%d/modes/%d/frequency_rad_s = %r" % (i, k, f)
            ev = mode.get("eigenvalue")
            if isinstance(ev, list) and not all(isinstance(x, (int, float)) and math.isfinite(x)
                                                for x in ev):
                return "cases/%d/modes/%d/eigenvalue = %r" % (i, k, ev)
    return None


def connect_from(source, port, timeout):
    """A TCP connection to 127.0.0.1:port from the loopback address source."""
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.bind((source, 0))
    s.settimeout(timeout)
    s.connect(("127.0.0.1", port))
    return s


def is_open(s):
    """True when the peer has not closed socket s (never waits; False for a
    socket closed here)."""
    try:
        readable, _, _ = select.select([s], [], [], 0)
        if not readable:
            return True
        return s.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) != b""
    except BlockingIOError:
        return True
    except (OSError, ValueError):
        return False


def wait_until(cond, base, interval=0.05):
    return timescale.wait_until(cond, base, interval)


def elapsed(t0):
    return time.monotonic() - t0


def start_or_refuse(exe, workdir, db, name, args=("--workers", "1"), base=30):
    """Start spinmodald on db expecting it may refuse: ('started', Popen, log)
    once it logs event=listening (the caller stops it), or ('refused exit N',
    None, log) when it exits first.  (tests/e2e/daemon.py's Daemon.start
    deadlocks on its own lock when a daemon exits before listening: it calls
    log_tail() while holding the condition's lock.)"""
    import subprocess
    logpath = os.path.join(workdir, name + ".log")
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    for k in list(env):
        if k.startswith("SPINMODAL_"):
            del env[k]
    with open(logpath, "wb") as logf:
        p = subprocess.Popen([exe, "--listen", "127.0.0.1:0", "--db", db] + list(args),
                             stdin=subprocess.DEVNULL, stdout=logf, stderr=logf, env=env,
                             cwd=workdir)
    end = time.monotonic() + timescale.budget(base)
    while True:
        with open(logpath, "rb") as f:
            log = f.read().decode("utf-8", "replace")
        if "event=listening" in log:
            return "started", p, log
        rc = p.poll()
        if rc is not None:
            with open(logpath, "rb") as f:
                log = f.read().decode("utf-8", "replace")
            return "refused exit %d" % rc, None, log
        if time.monotonic() > end:
            p.kill()
            p.wait()
            return "hung", None, log
        time.sleep(0.05)
