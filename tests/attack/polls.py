"""The long-poll flood (attack.py, category 'polls'; issue 23 item 2).

600 GET /v1/analyses/{id}?wait=60 from 10 loopback addresses (60 each, under the per-client
limit of 64) on a job that stays queued, and a few POST /v1/analyses?wait=60 (submit and wait:
a waiter too), each connection polling again as soon as it is answered and reopened when the
daemon closes it.  On 0.7.0 they held all 512 connection slots for the whole wait: /livez,
/readyz, /metrics and POST were refused at connect.  Now at most --max-waiters long polls wait
(a quarter of --max-connections by default: 128), a newer one answers the oldest at once with
the job's current state, and an eighth of the slots is kept free.

Invariants: while the flood runs, every probe from 127.0.0.1 (GET /livez, /readyz, /metrics,
POST /v1/validate, POST /v1/analyses) answers with its status within its budget; the waiting
long polls never exceed spinmodal_http_waiters_limit; every early answer of a GET is a 200 with
the job's state queued or running (a POST's: 202 with its job unfinished); nothing answers 5xx;
/livez answers after the flood.
"""
import json
import select
import threading
import time

from common import JSON_CT, connect_from, livez, small_request, sweep_request, timescale

CATEGORY = "polls"


class _Poller:
    """One attacking connection that sends `data` again each time it is answered."""

    def __init__(self, source, port, data):
        self.source, self.port, self.data = source, port, data
        self.s = None
        self.buf = b""

    def open(self):
        self.close()
        self.s = connect_from(self.source, self.port, timescale.budget(5))
        self.s.sendall(self.data)
        self.s.setblocking(False)
        self.buf = b""

    def close(self):
        if self.s is not None:
            self.s.close()
            self.s = None

    def answers(self):
        """Read what arrived; the whole answers in it as (status, body), and whether the
        daemon closed the connection."""
        out, closed = [], False
        try:
            while True:
                data = self.s.recv(65536)
                if not data:
                    closed = True
                    break
                self.buf += data
        except BlockingIOError:
            pass
        except OSError:
            closed = True
        while True:
            end = self.buf.find(b"\r\n\r\n")
            if end < 0:
                break
            head = self.buf[:end].decode("latin-1").split("\r\n")
            length = 0
            for line in head[1:]:
                k, _, v = line.partition(":")
                if k.strip().lower() == "content-length":
                    length = int(v.strip())
            if len(self.buf) < end + 4 + length:
                break
            try:
                status = int(head[0].split()[1])
            except (IndexError, ValueError):
                status = 0
            out.append((status, self.buf[end + 4:end + 4 + length]))
            self.buf = self.buf[end + 4 + length:]
        return out, closed


def _flood(d, tally, pollers, stop, seen):
    """Keep every poller waiting: resend on each answer, reopen on each close."""
    for p in pollers:
        try:
            p.open()
            seen["opened"] += 1
        except OSError:
            seen["refused"] += 1
    while not stop.is_set():
        live = [p for p in pollers if p.s is not None]
        try:
            ready, _, _ = select.select([p.s for p in live], [], [], 0.1) if live else ([], [], [])
        except (OSError, ValueError):
            ready = []
        by_sock = {p.s: p for p in live}
        for s in ready:
            p = by_sock[s]
            got, closed = p.answers()
            for status, body in got:
                seen["answers"] += 1
                _classify(tally, p, status, body, seen)
            try:
                if closed:
                    seen["closed"] += 1
                    p.open()
                    seen["opened"] += 1
                elif got:
                    p.s.sendall(p.data)
                    seen["polls"] += 1
            except OSError:
                p.close()
                seen["refused"] += 1
        for p in pollers:   # reopen the ones refused earlier
            if p.s is None and not stop.is_set():
                try:
                    p.open()
                    seen["opened"] += 1
                except OSError:
                    pass


def _classify(tally, p, status, body, seen):
    """Count an answer to a long poll; a wrong one breaks the invariant."""
    try:
        state = json.loads(body).get("state")
    except (ValueError, AttributeError):
        state = None
    post = p.data.startswith(b"POST")
    tally.add(CATEGORY, "%s ?wait answered %d %s" % ("POST" if post else "GET", status, state))
    if status >= 500 or state not in ("queued", "running") or status != (202 if post else 200):
        seen["wrong"].append((status, state))


def _probes(d, tally, rounds, worst):
    """Each probe once per round; returns how many did not answer as they should."""
    bad = 0
    for k in range(rounds):
        for method, path, body, want in (
                ("GET", "/livez", None, 200), ("GET", "/readyz", None, 200),
                ("GET", "/metrics", None, 200),
                ("POST", "/v1/validate", json.dumps(small_request()), 200),
                ("POST", "/v1/analyses", json.dumps(small_request(omega=30.0 + k)), 202)):
            t0 = time.monotonic()
            try:
                got = d.request(method, path, body=body, headers=JSON_CT if body else None,
                                timeout=10).status
            except Exception as e:  # noqa: BLE001 (refused, reset, timed out)
                got = type(e).__name__
            worst[0] = max(worst[0], time.monotonic() - t0)
            tally.add(CATEGORY, "probe %s %s: %s" % (method, path, got))
            bad += got != want
        time.sleep(0.2)
    return bad


def _waiters(d):
    """(waiting, limit) from /metrics, None when absent or unanswered."""
    try:
        text = d.get("/metrics", timeout=10).body.decode("utf-8", "replace")
    except Exception:  # noqa: BLE001
        return None, None
    vals = dict(l.split(" ", 1) for l in text.splitlines()
                if l.startswith("spinmodal_http_waiters") and " " in l)
    get = lambda k: int(float(vals[k])) if k in vals else None  # noqa: E731
    return get("spinmodal_http_waiters"), get("spinmodal_http_waiters_limit")


def run(d, tally, quick=False):
    """The flood against daemon d (default connection flags, one worker)."""
    n, sources, seconds = (300, 5, 2.0) if quick else (600, 10, 10.0)
    sweeps = []
    for k in range(2):      # ~12 s of one core each: the target stays queued behind them
        req = sweep_request(1001, elements=32)
        req["analysis"]["omega"] = [20.0 * i / 1000 + k for i in range(1001)]
        sweeps.append((d.post("/v1/analyses", req).json() or {}).get("id"))
    target = d.post("/v1/analyses", small_request(omega=77.0))
    job = (target.json() or {}).get("id", "0" * 64)
    get = ("GET /v1/analyses/%s?wait=60 HTTP/1.1\r\nHost: x\r\n\r\n" % job).encode()
    pollers = []
    for i in range(n):
        data = get
        if i % 50 == 49:    # submit and wait: a waiter too (a distinct job each)
            body = json.dumps(small_request(omega=100.0 + i)).encode()
            data = (b"POST /v1/analyses?wait=60 HTTP/1.1\r\nHost: x\r\nContent-Type: "
                    b"application/json\r\nContent-Length: %d\r\n\r\n" % len(body)) + body
        k = i % sources
        pollers.append(_Poller("127.0.%d.%d" % (1 + k // 250, 2 + k % 250), d.port, data))
    seen = {"opened": 0, "refused": 0, "answers": 0, "closed": 0, "polls": 0, "wrong": []}
    stop = threading.Event()
    th = threading.Thread(target=_flood, args=(d, tally, pollers, stop, seen), daemon=True)
    th.start()
    worst, most, limit, bad = [0.0], 0, None, 0
    end = time.monotonic() + seconds
    try:
        time.sleep(0.5)
        while True:
            bad += _probes(d, tally, 1, worst)
            waiting, lim = _waiters(d)
            if waiting is not None:
                most, limit = max(most, waiting), lim
            if time.monotonic() > end:
                break
    finally:
        stop.set()
        th.join(timescale.budget(30))
        for p in pollers:
            p.close()
    what = "%d long polls from %d addresses" % (n, sources)
    tally.add(CATEGORY, "connections opened", seen["opened"])
    tally.add(CATEGORY, "connections closed by the daemon", seen["closed"])
    tally.add(CATEGORY, "connects refused", seen["refused"])
    tally.add(CATEGORY, "polls sent again on an answered connection", seen["polls"])
    tally.figure("polls: most long polls waiting at once (limit %s)" % limit, most)
    tally.figure("polls: slowest probe during the flood", "%.3f s" % worst[0])
    tally.check(bad == 0, CATEGORY, "%s: every probe answers while they wait (%d did not)"
                % (what, bad))
    tally.check(limit is not None and most <= limit, CATEGORY,
                "%s: at most --max-waiters wait (%s of %s)" % (what, most, limit))
    tally.check(seen["answers"] > 0 and not seen["wrong"], CATEGORY,
                "%s: the early answers carry the job's current state (%d answers, wrong: %s)"
                % (what, seen["answers"], seen["wrong"][:3]))
    tally.check(livez(d), CATEGORY, "%s: /livez answers afterwards" % what)
    for s in sweeps:
        try:
            if s:
                d.delete("/v1/analyses/%s" % s, timeout=10)
        except Exception:  # noqa: BLE001 (0.7.0 may still refuse: the stop cancels them)
            pass
