"""Database faults an unlucky operator causes (attack.py, category 'faults').

  two daemons   a second spinmodald on the database of a first one that is
                under load (submissions and reads), by the same path, by
                other spellings of it, through a symlink and a hard link: each
                must refuse to start (exit 1, "in use"), and the first must
                neither lose nor run again any job it acknowledged;
  corrupt       damaged, truncated, foreign, newer and empty files, garbage
                WAL and shared-memory files, a directory: refused at start
                with exit 1 and a sentence, or started when SQLite can use the
                file as it is (an empty file, a WAL or -shm it discards) — never
                a crash;
  deleted       the file deleted under a running daemon: /readyz 503 'gone',
                POST 503, reads still answered, a clean stop;
  read-only     the database files made immutable under a running daemon
                (chattr +i: writes through open descriptors fail too): POST
                503, /readyz 503, reads answered, back to normal once writable
                again; a start on an immutable file and on a read-only bind
                mount refused (exit 1); needs chattr and mount, skipped otherwise;
  full disk     a 3 MB tmpfs filled up: the job whose result does not fit ends
                failed (store_error) or back in the queue, never running
                without a worker; /readyz 503 and back; needs mount.
  stalls        a SQLite write lock held by another process, and PostgreSQL
                paused with SIGSTOP under load: every answer within the
                deadlines, nothing lost or run twice (stall.py; issue 23 item 3).
"""
import os
import sqlite3
import subprocess
import threading

from common import (Daemon, db_bytes, small_request, start_or_refuse, sweep_request,
                    timescale, wait_until)
from daemon import listening_addr
import stall

JS = {"Content-Type": "application/json"}


def _try_start(exe, tmp, db, name):
    """Start a daemon on db: (outcome, log, Daemon or None).  outcome 'started'
    (then a Daemon attached to it, for requests: the caller stops it),
    'refused exit N' or 'hung'."""
    outcome, proc, log = start_or_refuse(exe, tmp, db, name)
    if proc is None:
        return outcome, log, None
    d = Daemon(exe, tmp, db=db, name=name)
    d.proc = proc
    d.host, d.port = listening_addr([l for l in log.splitlines() if "event=listening" in l][0])
    return outcome, log, d


def _stop(d):
    """SIGTERM a daemon started by _try_start; its exit status."""
    if d is None:
        return None
    d.proc.terminate()
    try:
        return d.proc.wait(timescale.budget(30))
    except Exception:   # noqa: BLE001
        d.proc.kill()
        return d.proc.wait()


def _workers_busy(d):
    """spinmodal_workers_busy of d's /metrics (0 when unreadable)."""
    try:
        text = d.get("/metrics", timeout=10).body.decode()
    except OSError:
        return 0
    for line in text.splitlines():
        if line.startswith("spinmodal_workers_busy "):
            return float(line.split()[1])
    return 0


def _sanitizer(text):
    return any(s in text for s in ("AddressSanitizer", "runtime error:", "LeakSanitizer",
                                   "Segmentation"))


def two_daemons(exe, tmp, tally, quick, category="faults"):
    db = os.path.join(tmp, "shared.db")
    a = Daemon(exe, tmp, ["--workers", "2"], db=db, name="first")
    a.start()
    acks, lock, stop = {}, threading.Lock(), threading.Event()
    reads = [0]

    def submitter(seed):
        k = 0
        while not stop.is_set() and k < 1000:   # about 20 submissions a second each
            k += 1
            stop.wait(0.05)
            req = (sweep_request(101, first=0.003 * (seed * 1000 + k), elements=16) if k % 10 == 0
                   else small_request(omega=2.0 + 1e-4 * (seed * 100000 + k)))
            try:
                r = a.post("/v1/analyses", req, timeout=30)
            except OSError:
                continue
            if r.status in (200, 202):
                with lock:
                    acks[r.json()["id"]] = r.status

    def reader():
        while not stop.is_set():
            with lock:
                ids = list(acks)[-5:]
            for jid in ids:
                try:
                    a.get("/v1/analyses/" + jid, timeout=30)
                    reads[0] += 1
                except OSError:
                    pass
            stop.wait(0.01)
    threads = [threading.Thread(target=submitter, args=(i,), daemon=True) for i in range(2)]
    threads.append(threading.Thread(target=reader, daemon=True))
    for t in threads:
        t.start()
    wait_until(lambda: len(acks) >= 20, 30)
    link = os.path.join(tmp, "link.db")
    hard = os.path.join(tmp, "hard.db")
    os.symlink(db, link)
    os.link(db, hard)
    sub = os.path.join(tmp, "sub")
    os.makedirs(sub)
    paths = [("same path", db), ("same path again", db),
             ("./ spelling", os.path.join(tmp, ".", "shared.db")),
             ("../ spelling", os.path.join(sub, os.pardir, "shared.db")),
             ("symlink", link), ("hard link", hard)]
    rounds = 1 if quick else 3
    if quick:
        paths = [paths[0], paths[4], paths[5]]
    busy_at = 0
    for i, (what, path) in enumerate(paths * rounds):
        before = len(acks)
        busy_at += _workers_busy(a) > 0
        outcome, log, b = _try_start(exe, tmp, path, "second%d" % i)
        ok = outcome.startswith("refused exit 1") and "in use" in log
        tally.add(category, "second daemon (%s): %s" % (what, outcome.split(" exit")[0]))
        tally.check(ok, category, "a second daemon on the database (%s) refuses to start, "
                    "'in use' (%s: %s)" % (what, outcome, log.strip().splitlines()[-1][:200]
                                           if log.strip() else ""))
        if b is not None:
            b.proc.kill()
            b.proc.wait()
        wait_until(lambda: len(acks) >= before + 10, 10)   # the first takes jobs meanwhile
    tally.add(category, "second daemon attempts while a job ran on the first", busy_at)
    stop.set()
    for t in threads:
        t.join(timescale.budget(60))
    lost, reruns, not_done = [], [], []
    for jid in list(acks):
        def ended():
            r = a.get("/v1/analyses/%s?wait=%g" % (jid, timescale.wait_param(10)))
            if r.status == 404:
                return {"state": "missing"}
            doc = r.json() or {}
            return doc if doc.get("state") not in ("queued", "running") else None
        doc = wait_until(ended, 120) or {"state": "not finished"}
        if doc["state"] == "missing":
            lost.append(jid)
        elif doc["state"] != "done":
            not_done.append((jid[:12], doc["state"]))
        elif doc.get("attempts") != 1:
            reruns.append((jid[:12], doc.get("attempts")))
    tally.add(category, "first daemon under load: jobs acknowledged", len(acks))
    tally.add(category, "first daemon under load: reads", reads[0])
    tally.check(not lost and not not_done and not reruns, category,
                "the first daemon lost no job and ran none twice (%d acknowledged; lost %s, "
                "not done %s, run again %s)" % (len(acks), lost[:3], not_done[:3], reruns[:3]))
    rc = a.stop()
    tally.check(rc == 0, category, "the first daemon stops with exit 0 (%s)" % rc)
    return db


def _copy(src, dst):
    with open(src, "rb") as f, open(dst, "wb") as g:
        g.write(f.read())


def corrupt(exe, tmp, tally, good_db, quick, category="faults"):
    """Start on damaged copies of good_db (a clean, stopped database)."""
    size = os.path.getsize(good_db)

    def damaged_page(p):
        _copy(good_db, p)
        with open(p, "r+b") as f:
            f.seek(4096 if size > 8192 else size // 2)
            f.write(os.urandom(4096))

    def truncated(p):
        _copy(good_db, p)
        with open(p, "r+b") as f:
            f.truncate(max(1, size // 2))

    def header_zeroed(p):
        _copy(good_db, p)
        with open(p, "r+b") as f:
            f.write(b"\0" * 100)

    def text_file(p):
        with open(p, "w") as f:
            f.write("this is not a database\n" * 100)

    def empty(p):
        open(p, "wb").close()

    def newer_schema(p):
        _copy(good_db, p)
        c = sqlite3.connect(p)
        c.execute("PRAGMA user_version = 99")
        c.commit()
        c.close()

    def foreign_app(p):
        c = sqlite3.connect(p)
        c.execute("CREATE TABLE t (x)")
        c.execute("PRAGMA application_id = 42")
        c.commit()
        c.close()

    def garbage_wal(p):
        _copy(good_db, p)
        with open(p + "-wal", "wb") as f:
            f.write(os.urandom(64 * 1024))

    def garbage_shm(p):
        _copy(good_db, p)
        with open(p + "-shm", "wb") as f:
            f.write(os.urandom(32 * 1024))

    def directory(p):
        os.makedirs(p)

    def missing_dir(p):
        pass   # the path's directory does not exist

    variants = [("damaged page", damaged_page, "refused", "corrupt"),
                ("truncated to half", truncated, "refused", None),
                ("header zeroed", header_zeroed, "refused", None),
                ("text file", text_file, "refused", None),
                ("empty file", empty, "started", None),
                ("newer schema", newer_schema, "refused", None),
                ("another application's", foreign_app, "refused", None),
                ("garbage WAL", garbage_wal, "either", None),
                ("garbage -shm", garbage_shm, "either", None),
                ("a directory", directory, "refused", None),
                ("in a missing directory", missing_dir, "refused", None)]
    if quick:
        variants = [variants[0], variants[4]]
    for i, (what, make, want, word) in enumerate(variants):
        p = os.path.join(tmp, "corrupt%d" % i, "jobs.db")
        if what != "in a missing directory":
            os.makedirs(os.path.dirname(p))
        make(p)
        outcome, log, d = _try_start(exe, tmp, p, "corrupt%d" % i)
        if d is not None:
            r = d.get("/v1/analyses?limit=100")
            if want == "either":
                # SQLite discards a WAL or -shm it cannot use: the jobs must still be there
                items = (r.json() or {}).get("items") or []
                tally.check(r.status == 200 and len(items) > 0, category,
                            "%s: started with the jobs of the database (%s, %d jobs)"
                            % (what, r.status, len(items)))
            tally.check(_stop(d) == 0, category, "%s: clean stop" % what)
        kind = "refused" if outcome.startswith("refused") else "started"
        tally.add(category, "start on a database %s: %s" % (what, outcome))
        ok = (want == "either" or kind == want) and not _sanitizer(log)
        if kind == "refused":
            ok = ok and outcome == "refused exit 1" and "event=start_failed" in log
            ok = ok and (word is None or word in log.lower())
        tally.check(ok, category, "start on a database %s: %s expected, %s (%s)"
                    % (what, want, outcome, log.strip().splitlines()[-1][-200:]
                       if log.strip() else ""))


def deleted(exe, tmp, tally, category="faults"):
    db = os.path.join(tmp, "deleted.db")
    d = Daemon(exe, tmp, ["--workers", "1"], db=db, name="deleted")
    d.start()
    r = d.post("/v1/analyses?wait=%g" % timescale.wait_param(30), small_request(omega=4.0))
    jid = (r.json() or {}).get("id")
    os.unlink(db)
    r = d.get("/readyz")
    check = (r.json() or {}).get("checks", {}).get("database")
    tally.add(category, "database deleted under the daemon: /readyz %s %s" % (r.status, check))
    tally.check(r.status == 503 and check == "gone", category,
                "deleted database: /readyz 503 'gone' (%s %s)" % (r.status, check))
    r = d.post("/v1/analyses", small_request(omega=4.5))
    tally.add(category, "database deleted under the daemon: POST %s" % r.status)
    tally.check(r.status == 503 and r.headers.get("Retry-After"), category,
                "deleted database: POST 503 with Retry-After (%s)" % r.status)
    r = d.get("/v1/analyses/%s" % jid)
    tally.add(category, "database deleted under the daemon: GET of a job %s" % r.status)
    tally.check(r.status in (200, 503), category, "deleted database: a read answers (%s)"
                % r.status)
    rc = d.stop()
    tally.check(rc == 0, category, "deleted database: clean stop (exit %s)" % rc)


def _mount_tmpfs(path, size="3m"):
    os.makedirs(path, exist_ok=True)
    p = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=" + size, "tmpfs", path],
                       capture_output=True, text=True)
    return p.returncode == 0, (p.stderr.strip() or "exit %d" % p.returncode)


def _remount(path, mode):
    return subprocess.run(["mount", "-o", "remount," + mode, path], capture_output=True).returncode == 0


def _chattr(flag, paths):
    """chattr flag (+i / -i) on the paths that exist; True when it worked."""
    paths = [p for p in paths if os.path.exists(p)]
    try:
        return subprocess.run(["chattr", flag] + paths, capture_output=True).returncode == 0
    except OSError:
        return False


def read_only(exe, tmp, tally, category="faults"):
    """The database made read-only under a running daemon (chattr +i: writes
    through open descriptors fail too), then starts on an immutable file and
    on a read-only bind mount."""
    ro = os.path.join(tmp, "ro")
    os.makedirs(ro)
    db = os.path.join(ro, "jobs.db")
    files = [db, db + "-wal", db + "-shm"]
    d = Daemon(exe, tmp, ["--workers", "1"], db=db, name="readonly")
    d.start()
    try:
        r = d.post("/v1/analyses?wait=%g" % timescale.wait_param(30), small_request(omega=6.0))
        jid = (r.json() or {}).get("id")
        if not _chattr("+i", files):
            tally.skip("read-only database", "chattr +i failed (needs root and ext2/3/4)")
            return
        r = d.get("/readyz")
        check = (r.json() or {}).get("checks", {}).get("database")
        tally.add(category, "database made read-only under the daemon: /readyz %s %s"
                  % (r.status, check))
        tally.check(r.status == 503 and check not in (None, "ok"), category,
                    "read-only: /readyz 503 naming the database (%s %s)" % (r.status, check))
        r = d.post("/v1/analyses", small_request(omega=6.5))
        tally.add(category, "database made read-only under the daemon: POST %s" % r.status)
        tally.check(r.status == 503 and r.headers.get("Retry-After"), category,
                    "read-only: POST 503 with Retry-After (%s %s)" % (r.status, r.text(120)))
        r = d.get("/v1/analyses/" + str(jid))
        tally.add(category, "database made read-only under the daemon: GET of a job %s" % r.status)
        tally.check(r.status == 200, category, "read-only: a read answers 200 (%s)" % r.status)
        _chattr("-i", files)
        back = wait_until(lambda: d.get("/readyz").status == 200, 60)
        tally.check(back, category, "read-only: /readyz 200 once writable again")
        r = d.post("/v1/analyses?wait=%g" % timescale.wait_param(30), small_request(omega=6.5))
        tally.add(category, "writable again: POST %s %s" % (r.status, (r.json() or {}).get("state")))
        tally.check(r.status in (200, 202), category, "read-only: POST accepted again (%s)"
                    % r.status)
    finally:
        _chattr("-i", files)
        rc = d.stop()
    tally.check(rc == 0, category, "read-only: clean stop (exit %s)" % rc)
    # a start on an immutable database file
    _chattr("+i", [db])
    try:
        outcome, log, b = _try_start(exe, tmp, db, "readonly-file")
        _stop(b)
    finally:
        _chattr("-i", [db])
    tally.add(category, "start on a read-only database file: %s" % outcome)
    tally.check(outcome == "refused exit 1" and ("read-only" in log or "readonly" in log),
                category, "start on a read-only database file: exit 1 saying so (%s: %s)"
                % (outcome, log.strip().splitlines()[-1][-200:] if log.strip() else ""))
    # a start on a read-only file system (a read-only bind mount of the directory)
    view = os.path.join(tmp, "ro-view")
    os.makedirs(view)
    p = subprocess.run(["mount", "--bind", ro, view], capture_output=True, text=True)
    if p.returncode != 0:
        tally.skip("start on a read-only file system", "cannot bind-mount here (%s)"
                   % p.stderr.strip())
        return
    try:
        if not _remount(view, "bind,ro"):
            tally.skip("start on a read-only file system", "cannot remount read-only")
            return
        outcome, log, b = _try_start(exe, tmp, os.path.join(view, "jobs.db"), "readonly-fs")
        _stop(b)
        tally.add(category, "start on a read-only file system: %s" % outcome)
        tally.check(outcome == "refused exit 1" and ("read-only" in log or "readonly" in log),
                    category, "start on a read-only file system: exit 1 saying so (%s: %s)"
                    % (outcome, log.strip().splitlines()[-1][-200:] if log.strip() else ""))
    finally:
        subprocess.run(["umount", view], capture_output=True)


def full_disk(exe, tmp, tally, category="faults"):
    disk = os.path.join(tmp, "fulldisk")
    ok, why = _mount_tmpfs(disk, "3m")
    if not ok:
        tally.skip("full disk", "cannot mount a 3 MB tmpfs here (%s): needs root and mount "
                   "permission" % why)
        return
    d = None
    try:
        d = Daemon(exe, tmp, ["--workers", "1", "--retain-age", "0", "--retain-bytes", "0"],
                   db=os.path.join(disk, "jobs.db"), name="fulldisk")
        d.start()
        filler = os.path.join(disk, "filler")
        st = os.statvfs(disk)
        with open(filler, "wb") as f:
            f.write(b"\0" * max(0, st.f_bavail * st.f_frsize - 150 * 1024))
        big = sweep_request(40, 0.0, elements=24)
        big["analysis"]["mode_shapes"] = True
        big["analysis"]["modes"] = 6
        r = d.post("/v1/analyses", big)
        tally.add(category, "full disk: POST of a job with a 2 MB result %s" % r.status)
        jid = (r.json() or {}).get("id")
        doc = None
        if jid:
            def settled():
                x = d.get("/v1/analyses/" + jid).json() or {}
                return x if x.get("state") in ("failed", "queued", "done") and \
                    x.get("attempts", 0) >= 1 else None
            doc = wait_until(settled, 120)
        state = (doc or {}).get("state")
        etype = ((doc or {}).get("error") or {}).get("type")
        tally.add(category, "full disk: the job ends %s %s" % (state, etype or ""))
        tally.check(state in ("failed", "queued") and (state != "failed" or etype == "store_error"),
                    category, "full disk: the job is failed store_error or queued, never left "
                    "running (%s %s)" % (state, etype))
        r = d.get("/readyz")
        tally.add(category, "full disk: /readyz %s %s" % (
            r.status, (r.json() or {}).get("checks", {}).get("database")))
        tally.check(r.status == 503, category, "full disk: /readyz 503 (%s)" % r.status)
        os.unlink(filler)
        tally.check(wait_until(lambda: d.get("/readyz").status == 200, 60), category,
                    "full disk: /readyz 200 once space is freed")
        r = d.post("/v1/analyses", big)
        done = wait_until(lambda: (d.get("/v1/analyses/%s" % jid).json() or {}).get("state")
                          in ("done", "failed"), 120)
        doc = d.get("/v1/analyses/%s" % jid).json() or {}
        tally.check(doc.get("state") == "done", category,
                    "full disk: the same request completes once space is freed (POST %s; %s %s)"
                    % (r.status, doc.get("state"), (doc.get("error") or {}).get("detail")))
        rc = d.stop()
        d = None
        tally.check(rc == 0, category, "full disk: clean stop (exit %s)" % rc)
    finally:
        if d is not None:
            d.kill()
        subprocess.run(["umount", disk], capture_output=True)


def category(exe, tmp, tally, args, name="faults"):
    good = two_daemons(exe, tmp, tally, args.quick)
    corrupt(exe, tmp, tally, good, args.quick)
    deleted(exe, tmp, tally)
    if not args.quick:
        read_only(exe, tmp, tally)
        full_disk(exe, tmp, tally)
    stall.category(exe, tmp, tally, args.quick)
    tally.figure("faults: database after the two-daemon run, bytes", db_bytes(good))
