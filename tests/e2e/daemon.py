"""Test harness for spinmodald: start/stop/kill/restart a daemon, talk HTTP to it.

Python 3 standard library only.  One Daemon object is one database and one
set of flags; start() may be called again after stop()/kill() (a restart on
the same database).  Everything the daemon writes on stdout/stderr is drained
by two threads into <workdir>/<name>.<n>.log (n counts the starts) and kept in
memory for wait_log()/log_lines().

    d = Daemon(exe, tmpdir, ["--workers", "1"])
    d.start()                       # reads the port from `event=listening addr=HOST:PORT`
    r = d.request("GET", "/livez")  # Response: r.status, r.headers, r.body, r.json()
    status, headers, body = r       # ... or unpacked
    rc = d.stop()                   # SIGTERM, waits, returns the exit status
    d.kill()                        # SIGKILL

Every `timeout` argument is a base budget in seconds (what an unloaded machine
needs, with a margin): the wait polls for its condition and gives up after
timescale.budget(timeout), i.e. scaled to this machine (tests/e2e/timescale.py).
"""
import http.client
import json
import os
import re
import select
import signal
import socket
import subprocess
import threading
import time

import timescale as ts

LISTEN_RE = re.compile(r"\bevent=listening\b.*?\baddr=(\S+):(\d+)")
STOPPED_RE = re.compile(r"\bevent=stopped\b|\"event\"\s*:\s*\"stopped\"")


def listening_addr(line):
    """(host, port) from a `listening` log line, logfmt or JSON (--log-format json); else None."""
    m = LISTEN_RE.search(line)
    if m:
        return m.group(1), int(m.group(2))
    if line.startswith("{") and "listening" in line:
        try:
            doc = json.loads(line)
        except ValueError:
            return None
        if isinstance(doc, dict) and doc.get("event") == "listening":
            m = re.match(r"^(\S+):(\d+)$", str(doc.get("addr", "")))
            if m:
                return m.group(1), int(m.group(2))
    return None


class DaemonError(Exception):
    pass


class Response:
    """One HTTP answer: status (int, or None when the connection closed without
    an answer), headers (dict-like with .get/.get_all, case-insensitive),
    body (bytes).  Unpacks as (status, headers, body)."""

    def __init__(self, status, headers, body, interim=None, error=None):
        self.status = status
        self.headers = headers if headers is not None else Headers([])
        self.body = body if body is not None else b""
        self.interim = interim or []   # 1xx status codes seen before the answer
        self.error = error             # socket error text when the exchange broke
        self.sent = None               # raw client: bytes sent (request line and headers included)
        self._json = None
        self._json_done = False

    def __iter__(self):
        return iter((self.status, self.headers, self.body))

    def json(self):
        """The body parsed as JSON, or None when it is not JSON."""
        if not self._json_done:
            self._json_done = True
            try:
                self._json = json.loads(self.body.decode("utf-8"))
            except (ValueError, UnicodeDecodeError):
                self._json = None
        return self._json

    def ctype(self):
        return (self.headers.get("Content-Type") or "").strip()

    def media_type(self):
        return self.ctype().split(";")[0].strip().lower()

    def text(self, limit=300):
        return self.body[:limit].decode("utf-8", "replace")

    def __repr__(self):
        return "<%s %s %s>" % (self.status, self.ctype(), self.text(200))


class Headers:
    """Minimal case-insensitive multi-map (for the raw-socket client)."""

    def __init__(self, pairs):
        self.pairs = list(pairs)

    def get(self, name, default=None):
        name = name.lower()
        for k, v in self.pairs:
            if k.lower() == name:
                return v
        return default

    def get_all(self, name, default=None):
        name = name.lower()
        vals = [v for k, v in self.pairs if k.lower() == name]
        return vals or default

    def items(self):
        return list(self.pairs)

    def __contains__(self, name):
        return self.get(name) is not None


def _env():
    env = dict(os.environ)
    env["OPENBLAS_NUM_THREADS"] = "1"
    env["OMP_NUM_THREADS"] = "1"
    # no SPINMODAL_* from the caller's environment may change the flags under test
    for k in list(env):
        if k.startswith("SPINMODAL_"):
            del env[k]
    return env


class Daemon:
    def __init__(self, exe, workdir, args=(), db=None, name="spinmodald", env=None,
                 listen="127.0.0.1:0"):
        self.exe = exe
        self.workdir = workdir
        self.args = list(args)
        self.db = db or os.path.join(workdir, name + ".sqlite")
        self.name = name
        self.env = _env()
        if env:
            self.env.update(env)
        self.listen = listen
        self.proc = None
        self.host = None
        self.port = None
        self.starts = 0
        self.logpath = None
        self._lines = []
        self._lock = threading.Lock()
        self._cond = threading.Condition(self._lock)
        self._threads = []
        self._logf = None
        self.returncode = None

    # ------------------------------------------------------------ process
    def argv(self):
        return [self.exe, "--listen", self.listen, "--db", self.db] + self.args

    def start(self, timeout=20.0):
        """Start the daemon and wait for its `event=listening` line (budget(timeout) s).
        Raises DaemonError when it exits first or does not listen in time."""
        if self.proc is not None and self.proc.poll() is None:
            raise DaemonError("already running")
        self.starts += 1
        self.logpath = os.path.join(self.workdir, "%s.%d.log" % (self.name, self.starts))
        self._logf = open(self.logpath, "w", encoding="utf-8", errors="replace")
        with self._lock:
            self._lines = []
        self.returncode = None
        self.host = self.port = None
        self.started_at = time.monotonic()
        self.proc = subprocess.Popen(self.argv(), stdin=subprocess.DEVNULL,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     env=self.env, cwd=self.workdir)
        self._threads = [threading.Thread(target=self._drain, args=(self.proc.stderr, ""), daemon=True),
                         threading.Thread(target=self._drain, args=(self.proc.stdout, "[stdout] "), daemon=True)]
        for t in self._threads:
            t.start()
        timeout = ts.budget(timeout)
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                for line in self._lines:
                    addr = listening_addr(line)
                    if addr:
                        self.host, self.port = addr
                        return self
                if self.proc.poll() is not None and not any(t.is_alive() for t in self._threads):
                    # the tail from the lines in hand: log_tail() takes the lock held here
                    raise DaemonError("spinmodald exited with %s before listening; log:\n%s"
                                      % (self.proc.returncode, "\n".join(self._lines[-40:])))
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                self._cond.wait(min(left, 0.2))
        self.kill()
        raise DaemonError("no `event=listening` line within %.0f s; log:\n%s" % (timeout, self.log_tail()))

    def _drain(self, stream, prefix):
        for raw in iter(stream.readline, b""):
            line = raw.decode("utf-8", "replace").rstrip("\n")
            with self._cond:
                self._lines.append(prefix + line)
                try:
                    self._logf.write(prefix + line + "\n")
                    self._logf.flush()
                except ValueError:
                    pass
                self._cond.notify_all()
        stream.close()

    def _join(self):
        for t in self._threads:
            t.join(ts.budget(10))
        with self._lock:
            if self._logf:
                self._logf.close()
                self._logf = None

    def alive(self):
        return self.proc is not None and self.proc.poll() is None

    def signal(self, sig):
        if self.alive():
            self.proc.send_signal(sig)

    def stop(self, timeout=60.0):
        """SIGTERM and wait; returns the exit status (None if it had to be killed)."""
        if self.proc is None:
            return self.returncode
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
        try:
            self.returncode = self.proc.wait(ts.budget(timeout))
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
            self.returncode = None
        self._join()
        return self.returncode

    def wait_exit(self, timeout=60.0):
        try:
            self.returncode = self.proc.wait(ts.budget(timeout))
        except subprocess.TimeoutExpired:
            return None
        self._join()
        return self.returncode

    def kill(self):
        """SIGKILL (kill -9) and reap."""
        if self.proc is None:
            return
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGKILL)
        self.returncode = self.proc.wait()
        self._join()

    def restart(self, timeout=20.0):
        """Start again on the same database with the same flags."""
        if self.alive():
            raise DaemonError("restart of a running daemon")
        return self.start(timeout)

    def stopped_logged(self):
        return any(STOPPED_RE.search(l) for l in self.log_lines())

    # ------------------------------------------------------------ logs
    def log_lines(self):
        with self._lock:
            return list(self._lines)

    def log_tail(self, n=40):
        return "\n".join(self.log_lines()[-n:])

    def wait_log(self, pattern, timeout=10.0, start=0):
        """Wait for a log line (index >= start) matching regex pattern; the line or None."""
        rx = re.compile(pattern)
        deadline = time.monotonic() + ts.budget(timeout)
        with self._cond:
            while True:
                for line in self._lines[start:]:
                    if rx.search(line):
                        return line
                left = deadline - time.monotonic()
                if left <= 0:
                    return None
                self._cond.wait(min(left, 0.2))

    def log_count(self):
        with self._lock:
            return len(self._lines)

    # ------------------------------------------------------------ HTTP
    @property
    def base(self):
        return "http://%s:%d" % (self.host, self.port)

    def request(self, method, path, body=None, headers=None, timeout=60.0, json_body=None):
        """One request on a fresh connection.  body: bytes/str; json_body: an object
        sent as application/json (unless headers say otherwise).  Returns a
        Response; raises OSError/http.client errors when the connection fails."""
        hdrs = dict(headers or {})
        if json_body is not None:
            body = json.dumps(json_body)
            if not any(k.lower() == "content-type" for k in hdrs):
                hdrs["Content-Type"] = "application/json"
        if isinstance(body, str):
            body = body.encode("utf-8")
        conn = http.client.HTTPConnection(self.host, self.port, timeout=ts.budget(timeout))
        try:
            conn.request(method, path, body=body, headers=hdrs)
            r = conn.getresponse()
            data = r.read()
            return Response(r.status, r.headers, data)
        finally:
            conn.close()

    def get(self, path, **kw):
        return self.request("GET", path, **kw)

    def post(self, path, obj=None, **kw):
        return self.request("POST", path, json_body=obj, **kw)

    def delete(self, path, **kw):
        return self.request("DELETE", path, **kw)

    def get_json(self, path, **kw):
        r = self.get(path, **kw)
        return r.status, r.json()

    def raw(self, data, body_iter=None, half_close=False, timeout=20.0, read_first=False):
        """Send raw bytes (and optionally a body from an iterator of byte chunks,
        stopping early when the daemon answers) on a fresh connection and read one
        answer.  Returns a Response (status None when it closed without one)."""
        return raw_exchange(self.host, self.port, data, body_iter, half_close, ts.budget(timeout), read_first)


# ---------------------------------------------------------------- raw client

def _parse_response(buf):
    """Parse one complete HTTP response from buf; returns (Response, interim) or
    None when buf is incomplete.  Skips 1xx interim answers."""
    interim = []
    while True:
        end = buf.find(b"\r\n\r\n")
        if end < 0:
            return None
        head = buf[:end].decode("latin-1")
        lines = head.split("\r\n")
        m = re.match(r"HTTP/\d\.\d (\d{3})", lines[0])
        if not m:
            return Response(None, None, buf, error="unparsable answer: %r" % buf[:200]), True
        status = int(m.group(1))
        pairs = []
        for l in lines[1:]:
            if ":" in l:
                k, v = l.split(":", 1)
                pairs.append((k.strip(), v.strip()))
        rest = buf[end + 4:]
        if 100 <= status < 200:
            interim.append(status)
            buf = rest
            continue
        hd = Headers(pairs)
        te = (hd.get("Transfer-Encoding") or "").lower()
        cl = hd.get("Content-Length")
        if te == "chunked":
            body, pos = b"", 0
            while True:
                nl = rest.find(b"\r\n", pos)
                if nl < 0:
                    return None
                size = int(rest[pos:nl].split(b";")[0].strip() or b"0", 16)
                if size == 0:
                    break
                if len(rest) < nl + 2 + size + 2:
                    return None
                body += rest[nl + 2:nl + 2 + size]
                pos = nl + 2 + size + 2
            return Response(status, hd, body, interim), True
        if cl is not None:
            n = int(cl)
            if len(rest) < n:
                return None
            return Response(status, hd, rest[:n], interim), True
        return (Response(status, hd, rest, interim), False)  # until close


def raw_exchange(host, port, data, body_iter=None, half_close=False, timeout=20.0, read_first=False):
    s = socket.create_connection((host, port), timeout=timeout)
    buf = b""
    error = None
    sent = 0
    deadline = time.monotonic() + timeout
    try:
        s.setblocking(False)

        def pump_read(wait):
            nonlocal buf
            r, _, _ = select.select([s], [], [], wait)
            if not r:
                return False
            try:
                chunk = s.recv(65536)
            except BlockingIOError:
                return False
            if not chunk:
                return None   # EOF
            buf += chunk
            return True

        def send_all(payload):
            """Send payload; stop early (returns False) when an answer arrives or the
            peer closes."""
            nonlocal error, sent
            view = memoryview(payload)
            while view:
                if time.monotonic() > deadline:
                    error = "send timeout"
                    return False
                r, w, _ = select.select([s], [s], [], 0.5)
                if r:
                    return False   # the daemon answered (or closed): stop sending
                if w:
                    try:
                        n = s.send(view[:65536])
                    except BlockingIOError:
                        continue
                    except OSError as e:
                        error = "send: %s" % e
                        return False
                    view = view[n:]
                    sent += n
            return True

        ok = send_all(data)
        if ok and read_first:
            # Expect: 100-continue: wait (up to 3 s on an unloaded machine, like
            # curl's 1 s) for a final answer or a 100 before sending the body
            wait_until = min(deadline, time.monotonic() + ts.budget(3.0))
            while time.monotonic() < wait_until:
                got = pump_read(0.2)
                if got is None:
                    break
                p = _parse_response(buf) if buf else None
                if p is not None and p[1]:
                    p[0].sent = sent
                    return p[0]
                if re.match(rb"HTTP/1\.[01] 100[^\r]*\r\n\r\n", buf):
                    break   # interim 100: send the body
        if ok and body_iter is not None:
            for chunk in body_iter:
                if not send_all(chunk):
                    break
        if half_close:
            try:
                s.shutdown(socket.SHUT_WR)
            except OSError:
                pass
        while time.monotonic() < deadline:
            p = _parse_response(buf) if buf else None
            if p is not None and p[1]:
                p[0].sent = sent
                return p[0]
            try:
                got = pump_read(0.5)
            except OSError as e:
                error = error or "recv: %s" % e
                break
            if got is None:
                break
        else:
            error = error or "timeout waiting for the answer"
    finally:
        s.close()
    p = _parse_response(buf) if buf else None
    if p is not None:
        r = p[0]
        r.error = error
        r.sent = sent
        return r
    r = Response(None, None, buf, error=error or "closed without an answer")
    r.sent = sent
    return r
