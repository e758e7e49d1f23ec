#!/usr/bin/env python3
"""The hostile re-run of issue 10: spinmodald attacked on loopback as a hostile
client and an unlucky operator would, with a table of what happened.

usage: attack.py SPINMODALD [--quick] [--soak S] [--load S] [--only LIST]
                 [--keep] [--verbose]

Starts the real daemon (the path given) on temporary directories, one daemon
per category, and runs:

  bodies      >= 80 hostile request bodies, each to POST /v1/analyses and POST
              /v1/validate (bodies.py): every answer a 4xx problem document with
              a pointer, never a 5xx, a hang or a crash;
  http        >= 110 HTTP-level abuses (abuses.py): methods, paths, traversal,
              queries, headers, Content-Length, chunked framing, Expect/Upgrade,
              HEAD/OPTIONS, pipelining, half-closed and reset sockets, slowloris
              heads and bodies;
  trickle     600 connections trickling request heads, from one address and
              from 60, while /livez must keep answering;
  durability  kill -9 during bursts of submissions and during sweeps, restart:
              every acknowledged (202/200) job present and done, none lost
              (durability.py);
  faults      database faults: read-only, deleted under a running daemon,
              corrupt at start, a second daemon on the same file (also through
              a symlink and a hard link) while the first is under load, a full
              disk (a 3 MB tmpfs; skipped when this process may not mount)
              (faults.py); a SQLite write lock held by another process and
              PostgreSQL paused with SIGSTOP under load (stall.py; the
              PostgreSQL part skipped without its server binaries);
  polls       600 long polls (GET and POST ?wait=60) from 10 addresses, each
              polling again once answered, while /livez, /readyz, /metrics and
              POST must answer and at most --max-waiters wait (polls.py);
  imports     hostile blade files to POST /v1/import/{format} (imports.py):
              extreme numbers, el_loc out of order, UTF-16, degenerate radii:
              each a 422 with its line and field, never a 5xx; and a .bmi
              whose sec_props_file leaves its folder (the CLI: exit 2, the file
              not read);
  load        cached-result GET rate and p99 for --load seconds (wrk when on
              PATH, else a Python client) (load.py);
  soak        --soak seconds of submissions, GETs and malformed validates:
              RSS start/end/max, database bytes per job (load.py).

--quick: a subset of bodies and abuses, one kill -9, the database faults
without load, no trickle from many addresses, 300 long polls from 5 addresses
for 2 s, no load figure, no soak (the
meson test e2e-attack-quick).  Every wait polls for its condition and gives up
after a budget scaled to the machine (tests/e2e/timescale.py), so no check
passes or fails by speed.

Exit status 0 when every invariant held, 1 when one broke (listed at the end
of the table: a 5xx other than a documented 503, a crash, a lost job, a NaN in
a solved result, /livez not answering during the trickle), 2 on a setup error.
"""
import argparse
import faulthandler
import os
import signal
import shutil
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from common import Daemon, Tally, timescale  # noqa: E402
import abuses  # noqa: E402
import bodies  # noqa: E402
import durability  # noqa: E402
import faults  # noqa: E402
import imports  # noqa: E402
import polls  # noqa: E402
import load  # noqa: E402

CATEGORIES = ["bodies", "http", "trickle", "polls", "imports", "durability", "faults", "load",
              "soak"]


def done_job(d):
    """Submit the small request with ?wait and return its id once done."""
    r = d.post("/v1/analyses?wait=%g" % timescale.wait_param(60), common.small_request(omega=3.0))
    doc = r.json() or {}
    if doc.get("state") != "done":
        raise common.DaemonError("the setup job is %s (%s)" % (doc.get("state"), r.status))
    return doc["id"]


def cat_bodies(exe, tmp, tally, args):
    d = Daemon(exe, tmp, ["--workers", "1"], name="bodies")
    d.start()
    try:
        accepted = bodies.run(d, tally, quick=args.quick)
        bodies.follow(d, tally, accepted)
        tally.check(d.alive(), "bodies", "the daemon is alive at the end")
        items = (d.get("/v1/analyses?limit=100").json() or {}).get("items") or []
        extra = sorted(set(i.get("id") for i in items) - set(j for _, j in accepted))
        tally.check(not extra, "bodies", "no refused body stored a job (%s)"
                    % [x[:12] for x in extra])
        crash_free(d, tally, "bodies")
    finally:
        finish(d, tally, "bodies")


def cat_http(exe, tmp, tally, args):
    deadline = 3.0
    d = Daemon(exe, tmp, ["--workers", "1", "--request-deadline", str(deadline)], name="http")
    d.start()
    try:
        job = done_job(d)
        abuses.run_raw(d, tally, job, quick=args.quick)
        abuses.scripted(d, tally, job, quick=args.quick, deadline=deadline)
        tally.check(d.alive(), "http", "the daemon is alive at the end")
        crash_free(d, tally, "http")
    finally:
        finish(d, tally, "http")


def cat_trickle(exe, tmp, tally, args):
    deadline, per_client = 3.0, 64
    d = Daemon(exe, tmp, ["--workers", "1", "--request-deadline", str(deadline),
                          "--max-connections-per-client", str(per_client)], name="trickle")
    d.start()
    try:
        n = 100 if args.quick else 600
        abuses.trickle(d, tally, n=n, sources=1, per_client=per_client)
        if not args.quick:
            abuses.trickle(d, tally, n=600, sources=60, per_client=per_client)
        crash_free(d, tally, "trickle")
    finally:
        finish(d, tally, "trickle")


def cat_polls(exe, tmp, tally, args):
    d = Daemon(exe, tmp, ["--workers", "1"], name="polls")   # default connection flags
    d.start()
    try:
        polls.run(d, tally, quick=args.quick)
        crash_free(d, tally, "polls")
    finally:
        finish(d, tally, "polls")


def cat_imports(exe, tmp, tally, args):
    d = Daemon(exe, tmp, ["--workers", "1"], name="imports")
    d.start()
    try:
        imports.run(d, tally)
        tally.check(d.alive(), "imports", "the daemon is alive at the end")
        crash_free(d, tally, "imports")
    finally:
        finish(d, tally, "imports")
    imports.cli(exe, tmp, tally)


def crash_free(d, tally, category):
    """No sanitizer report or crash in the daemon's log so far."""
    bad = [l for l in d.log_lines() if "ERROR: AddressSanitizer" in l or "runtime error:" in l
           or "ERROR: LeakSanitizer" in l or "Segmentation" in l]
    tally.check(not bad, category, "no sanitizer report in the log (%s)" % bad[:2])


def scan_logs(top, tally, category):
    """No sanitizer report or crash in any daemon log written under top."""
    found = []
    for dirpath, _, names in os.walk(top):
        for n in names:
            if n.endswith(".log"):
                with open(os.path.join(dirpath, n), "rb") as f:
                    text = f.read().decode("utf-8", "replace")
                for key in ("ERROR: AddressSanitizer", "runtime error:", "ERROR: LeakSanitizer",
                            "Segmentation fault", "SUMMARY: UndefinedBehaviorSanitizer"):
                    if key in text:
                        found.append("%s: %s" % (n, key))
    tally.add(category, "daemon logs with a sanitizer report", len(found))
    tally.check(not found, category, "no sanitizer report in any daemon log (%s)" % found[:5])


def finish(d, tally, category):
    """Stop d cleanly (exit 0: LeakSanitizer found nothing either)."""
    if not d.alive():
        tally.broken(category, "the daemon died (exit %s); log tail:\n%s"
                     % (d.proc.returncode if d.proc else None, d.log_tail(15)))
        return
    rc = d.stop()
    tally.check(rc == 0, category, "the daemon stops with exit 0 (got %s)%s"
                % (rc, "" if rc == 0 else "; log tail:\n" + d.log_tail(30)))
    crash_free(d, tally, category)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("exe")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--soak", type=float, default=180.0)
    ap.add_argument("--load", type=float, default=5.0)
    ap.add_argument("--only", default="")
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()
    exe = os.path.abspath(args.exe)
    if not os.access(exe, os.X_OK):
        print("attack: %s is not an executable" % exe, file=sys.stderr)
        return 2
    only = [c for c in args.only.split(",") if c] or CATEGORIES
    if args.quick:
        only = [c for c in only if c not in ("load", "soak")]
    unknown = [c for c in only if c not in CATEGORIES]
    if unknown:
        print("attack: unknown categories %s (known: %s)" % (unknown, CATEGORIES), file=sys.stderr)
        return 2
    faulthandler.register(signal.SIGUSR1)   # kill -USR1: every thread's stack on stderr
    timescale.calibrate(exe)
    tally = Tally(verbose=args.verbose)
    tmp = tempfile.mkdtemp(prefix="spinmodal-attack-")
    t0 = time.monotonic()
    funcs = {"bodies": cat_bodies, "http": cat_http, "trickle": cat_trickle, "polls": cat_polls,
             "imports": cat_imports,
             "durability": durability.category, "faults": faults.category,
             "load": load.category_load, "soak": load.category_soak}
    try:
        for cat in only:
            if cat not in funcs:
                continue
            print("== %s (%.0f s)" % (cat, time.monotonic() - t0), flush=True)
            sub = os.path.join(tmp, cat)
            os.makedirs(sub)
            try:
                funcs[cat](exe, sub, tally, args)
            except common.DaemonError as e:
                tally.broken(cat, "setup: %s" % e)
            scan_logs(sub, tally, cat)
    finally:
        if args.keep:
            print("kept %s" % tmp)
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    print("\n== spinmodald %s, %s, %.0f s" % (exe, timescale.info(), time.monotonic() - t0))
    print(tally.table(), flush=True)
    return 1 if tally.violations else 0


if __name__ == "__main__":
    sys.exit(main())
