"""kill -9 during bursts of submissions and during sweeps (attack.py, category 'durability').

A job is acknowledged when its POST was answered 202 or 200: it is then
committed (DAEMON.md: submissions are fsynced before the answer).  Each round
kills the daemon with SIGKILL while submissions or sweeps are under way,
restarts it on the same database and checks every job acknowledged so far:
present (not 404), and done in the end (a job that was running is run again:
attempts grows).  A job that is missing, or ends in any state but done, is
lost.  Submissions in flight at the kill were never acknowledged and may or
may not exist.
"""
import json
import random
import threading
import time

from common import Daemon, small_request, solved_nan, sweep_request, timescale, wait_until


class Acks:
    """The acknowledged jobs: id -> first answer status; thread-safe.  lost
    collects every id ever found missing or not done."""

    def __init__(self):
        self.ids = {}
        self.lock = threading.Lock()
        self.unanswered = 0
        self.lost = set()

    def add(self, jid, status):
        with self.lock:
            self.ids.setdefault(jid, status)

    def count(self):
        with self.lock:
            return len(self.ids)


def _submitter(d, acks, stop, seed, counter):
    """Submit distinct small jobs on fresh connections until stop or an error."""
    rng = random.Random(seed)
    while not stop.is_set():
        with counter[1]:
            counter[0] += 1
            k = counter[0]
        req = small_request(omega=1.0 + k * 1e-4, elements=rng.choice((2, 3, 4)))
        try:
            r = d.request("POST", "/v1/analyses", body=json.dumps(req),
                          headers={"Content-Type": "application/json"}, timeout=10)
        except Exception:   # noqa: BLE001 - the daemon is being killed
            with acks.lock:
                acks.unanswered += 1
            return
        doc = r.json() or {}
        if r.status in (200, 202) and doc.get("id"):
            acks.add(doc["id"], r.status)


def _settle(d, acks, tally, category, what):
    """Every acknowledged job present and done; returns (lost, not_done, reruns)."""
    lost, not_done, reruns = [], [], 0
    for jid in sorted(acks.ids):
        def ended():
            r = d.get("/v1/analyses/%s?wait=%g" % (jid, timescale.wait_param(10)))
            if r.status == 404:
                return {"state": "missing"}
            doc = r.json() or {}
            return doc if doc.get("state") in ("done", "failed", "canceled") else None
        doc = wait_until(ended, 120) or {"state": "not finished"}
        if doc["state"] == "missing":
            lost.append(jid)
        elif doc["state"] != "done":
            not_done.append((jid, doc["state"], (doc.get("error") or {}).get("type")))
        else:
            reruns += doc.get("attempts", 1) > 1
            where = solved_nan(doc.get("result"))
            tally.check(where is None, category, "%s: job %s… has no NaN (%s)"
                        % (what, jid[:12], where))
    acks.lost.update(lost)
    acks.lost.update(j for j, _, _ in not_done)
    return lost, not_done, reruns


def bursts(exe, tmp, tally, rounds, category="durability"):
    """Rounds of 4 submitting threads killed with SIGKILL after a random number
    of acknowledgements; all jobs acknowledged in any round checked after each."""
    d = Daemon(exe, tmp, ["--workers", "2"], name="bursts")
    acks = Acks()
    rng = random.Random(10)
    counter = [0, threading.Lock()]
    d.start()
    for rnd in range(rounds):
        before = acks.count()
        target = before + rng.randint(40, 120)
        stop = threading.Event()
        threads = [threading.Thread(target=_submitter, args=(d, acks, stop, 100 * rnd + t, counter),
                                    daemon=True) for t in range(4)]
        for t in threads:
            t.start()
        wait_until(lambda: acks.count() >= target or not any(t.is_alive() for t in threads), 60)
        d.kill()           # while the submitters still send
        stop.set()
        for t in threads:
            t.join(timescale.budget(20))
        tally.add(category, "burst: kill -9 with submissions in flight")
        d.restart()
        lost, not_done, reruns = _settle(d, acks, tally, category, "burst %d" % (rnd + 1))
        tally.check(not lost and not not_done, category,
                    "burst %d: all %d acknowledged jobs present and done (lost %d: %s; not done: %s)"
                    % (rnd + 1, acks.count(), len(lost), [x[:12] for x in lost[:5]], not_done[:5]))
        print("burst %d: %d acknowledged (%d new), %d in flight at the kills so far, %d re-run"
              % (rnd + 1, acks.count(), acks.count() - before, acks.unanswered, reruns), flush=True)
    tally.add(category, "burst: jobs acknowledged", acks.count())
    tally.add(category, "burst: submissions unanswered (in flight)", acks.unanswered)
    rc = d.stop()
    tally.check(rc == 0, category, "bursts: the daemon stops with exit 0 (%s)" % rc)
    return acks, d


def sweeps(exe, tmp, tally, rounds, category="durability"):
    """Rounds of long sweeps (and small jobs queued behind them) killed while a
    sweep runs with progress, twice in a row in the last round (the re-run killed
    again); every acknowledged job done in the end, the killed sweeps re-run."""
    d = Daemon(exe, tmp, ["--workers", "2"], name="sweeps")
    d.start()
    acks = Acks()
    killed = []        # ids of sweeps running at a kill
    for rnd in range(rounds):
        ids = []
        for k in range(3):
            req = sweep_request(201, first=0.01 * (rnd * 10 + k + 1), elements=20)
            r = d.post("/v1/analyses", req)
            if r.status in (200, 202):
                acks.add(r.json()["id"], r.status)
                ids.append(r.json()["id"])
        for k in range(10):
            r = d.post("/v1/analyses", small_request(omega=5.0 + rnd + 0.05 * k))
            if r.status in (200, 202):
                acks.add(r.json()["id"], r.status)
        kills = 2 if rnd == rounds - 1 else 1
        for _ in range(kills):
            def running():
                for jid in ids:
                    doc = d.get("/v1/analyses/" + jid).json() or {}
                    if doc.get("state") == "running" and doc.get("progress", {}).get("done", 0) > 0:
                        return jid
                return None
            jid = wait_until(running, 60, 0.01)
            d.kill()
            tally.add(category, "sweep: kill -9 with a sweep running")
            tally.check(jid is not None, category,
                        "sweep round %d: a sweep was running with progress at the kill" % (rnd + 1))
            if jid:
                killed.append(jid)
            d.restart()
        lost, not_done, reruns = _settle(d, acks, tally, category, "sweep round %d" % (rnd + 1))
        tally.check(not lost and not not_done, category,
                    "sweep round %d: all %d acknowledged jobs present and done (lost %d; not done %s)"
                    % (rnd + 1, acks.count(), len(lost), not_done[:5]))
    for jid in set(killed):
        doc = d.get("/v1/analyses/" + jid).json() or {}
        tally.check(doc.get("attempts", 0) >= 2, category,
                    "sweep %s… killed while running was run again (attempts %s)"
                    % (jid[:12], doc.get("attempts")))
    tally.add(category, "sweep: jobs acknowledged", acks.count())
    rc = d.stop()
    tally.check(rc == 0, category, "sweeps: the daemon stops with exit 0 (%s)" % rc)
    return acks


def category(exe, tmp, tally, args, name="durability"):
    rounds = 1 if args.quick else 5
    t0 = time.monotonic()
    acks, d = bursts(exe, tmp, tally, rounds)
    sacks = sweeps(exe, tmp, tally, 1 if args.quick else 3)
    # a last clean restart: everything acknowledged is still there, done
    d.restart()
    lost, not_done, _ = _settle(d, acks, tally, name, "after a clean restart")
    tally.check(not lost and not not_done, name, "after a clean restart: %d jobs present and done"
                % acks.count())
    d.stop()
    total = acks.count() + sacks.count()
    tally.figure("durability: acknowledged jobs across kill -9", total)
    tally.figure("durability: jobs lost", len(acks.lost | sacks.lost))
    print("durability: %.0f s" % (time.monotonic() - t0))
