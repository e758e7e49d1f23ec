"""HTTP-level abuses of spinmodald (attack.py, category 'http').

Raw requests on fresh sockets: methods and paths no route has, path
traversal, odd query strings, huge and flooding headers, broken
Content-Length and chunked framing, Expect/Upgrade, HEAD and OPTIONS
oddities; then exchanges that need a script: pipelining, half-closed and
reset sockets, keep-alive runs, slowloris heads and bodies.  Every answer
must be one of the statuses the case accepts ('closed': the daemon closed
without an answer), never a 5xx, never a hang past the budget; the daemon
must be alive and /livez answer after every case.

A case is a dict: name, data (bytes sent at once), expect (tuple of ints or
'closed'), half_close, no_body (a HEAD: the answer must have no body).
"""
import json
import socket
import struct
import time

from common import (connect_from, is_open, livez, outcome_of, raw_exchange, small_request,
                    timescale)


def _req(method, path, headers=(), body=b"", version="HTTP/1.1", host=True, close=True,
         eol="\r\n"):
    lines = ["%s %s %s" % (method, path, version)]
    if host:
        lines.append("Host: 127.0.0.1")
    if close:
        lines.append("Connection: close")
    lines += list(headers)
    head = (eol.join(lines) + eol + eol).encode("latin-1", "surrogateescape")
    return head + body


def _post(path, body, extra=(), ctype="application/json"):
    hdrs = ["Content-Type: %s" % ctype] if ctype else []
    hdrs += ["Content-Length: %d" % len(body)] + list(extra)
    return _req("POST", path, hdrs, body)


def cases(job, quick=False):
    """The raw cases; job is the id of a done job (for the {id} routes)."""
    c = []
    small = json.dumps(small_request(omega=10.0)).encode()

    def add(name, data, expect, half_close=False, no_body=False, quick_too=False):
        c.append({"name": name, "data": data, "expect": tuple(expect), "half_close": half_close,
                  "no_body": no_body, "quick": quick_too})

    routes = ["/v1/analyses", "/v1/validate", "/v1/analyses/" + job,
              "/v1/analyses/%s/result" % job, "/v1/analyses/%s/request" % job, "/livez",
              "/metrics", "/v1/schemas/request"]
    # --- methods no route has (40) --------------------------------------------
    for path in routes:
        for m in ("PUT", "PATCH", "TRACE", "BREW", "get"):
            add("%s %s" % (m, path), _req(m, path), [405, 400, 501],
                quick_too=(m == "PUT" and path == "/livez"))
    add("CONNECT authority", _req("CONNECT", "127.0.0.1:80"), [400, 404, 405, 501, "closed"])
    add("method 1000 chars", _req("X" * 1000, "/livez"), [400, 405, 501, "closed"])
    add("method with NUL", _req("GE\x00T", "/livez"), [400, 405, 501, "closed"])
    add("empty method", _req("", "/livez"), [400, "closed"])
    add("tab separator", b"GET\t/livez HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
        [400, 405, 404, 501, "closed"])

    # --- paths -------------------------------------------------------------------
    for p in ("/../../etc/passwd", "/v1/schemas/../../DESIGN.md",
              "/v1/schemas/%2e%2e/%2e%2e/DESIGN.md", "/v1/schemas/..%2f..%2fDESIGN.md",
              "/v1/analyses/../../../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd",
              "/..%5c..%5cetc%5cpasswd", "/static/../../../../../../etc/shadow"):
        add("GET " + p, _req("GET", p), [400, 404], quick_too=(p == "/../../etc/passwd"))
    for p, want in (("//v1//analyses", [404]), ("/v1/analyses/", [404]),
                    ("/v1/analyses/%s/" % job, [404]), ("/livez%00", [404, 400]),
                    ("/livez?", [200]), ("/livez#frag", [200, 404, 400]),
                    ("http://127.0.0.1/livez", [200, 404, 400]), ("*", [404, 400]),
                    ("livez", [404, 400]), ("/" + "a" * 8000, [404, 414, 431, 400, "closed"]),
                    ("/" + "a" * 100000, [414, 431, 400, "closed"]),
                    ("/v1/\xff\xfe", [404, 400]),
                    ("/v1/analyses/" + "".join("%%%02x" % ord(ch) for ch in job), [200, 404]),
                    ("/v1/analyses/" + job.upper(), [404]),
                    ("/v1/analyses/%s/result/../request" % job, [404, 200]),
                    ("/v1/analyses/%s%%00" % job, [404]),
                    ("/v1/import/../validate", [404, 405]), ("/v1/import/", [404]),
                    ("/v1/import/bmodes/", [404]), ("/openapi.json/", [404])):
        add("GET " + p[:60], _req("GET", p), want, quick_too=(p == "/v1/analyses/"))

    # --- query strings ----------------------------------------------------------
    a = "/v1/analyses/" + job
    for q, want in (("?wait=1e1", [400]), ("?wait=NaN", [400]), ("?wait=inf", [400]),
                    ("?wait=60.0000001", [400]), ("?wait=-0", [400]), ("?wait=%00", [400]),
                    ("?wait=0.5&wait=99", [200, 400]), ("?wait", [400, 200]),
                    ("?wait=" + "9" * 30, [400]), ("?%00=1", [200]),
                    ("?" + "&".join("p%d=%d" % (i, i) for i in range(3000)), [200, 400, 414, 431,
                                                                              "closed"])):
        add("GET {id}" + q[:40], _req("GET", a + q), want, quick_too=(q == "?wait=NaN"))
    r = a + "/result"
    for q, want in (("?format=CSV", [400]), ("?format=", [400]), ("?format=csv&format=json",
                                                                   [200, 400]),
                    ("?format=spanwise", [409]), ("?format=%63sv", [200]),
                    ("?format=csv%00json", [400])):
        add("GET result" + q, _req("GET", r + q), want)
    for q, want in (("?limit=1&limit=1000", [200, 400]), ("?limit=0x10", [400]),
                    ("?before=0", [400]), ("?before=-1", [400]),
                    ("?before=99999999999999999999", [400]), ("?state=done&state=bogus",
                                                              [200, 400]),
                    ("?state=DONE", [400]), ("?limit=%2B5", [400]), ("?limit= 5", [400, "closed"]),
                    ("?limit=" + "1" * 5000, [400])):
        add("GET list" + q[:40], _req("GET", "/v1/analyses" + q), want)
    add("POST wait=nan", _post("/v1/analyses?wait=nan", small), [400])
    add("POST wait=61", _post("/v1/analyses?wait=61", small), [400], quick_too=True)

    # --- headers ----------------------------------------------------------------
    add("header 100 KB", _req("GET", "/livez", ["X-Big: " + "a" * 100000]),
        [400, 413, 431, "closed"], quick_too=True)
    add("header flood 10000", _req("GET", "/livez", ["X-H%d: v" % i for i in range(10000)]),
        [400, 413, 431, "closed"])
    add("header flood 100 same name", _req("GET", "/livez", ["X-Same: v"] * 100), [200])
    add("header without colon", _req("GET", "/livez", ["NoColonHere"]), [400, 200, "closed"])
    add("header with NUL", _req("GET", "/livez", ["X-Nul: a\x00b"]), [400, 200, "closed"])
    add("obs-fold header", _req("GET", "/livez", ["X-Fold: a", " continued"]), [400, 200])
    add("space before colon", _req("GET", "/livez", ["Host : x"]), [400, 200])
    add("two Content-Types", _post("/v1/validate", small, ["Content-Type: text/plain"]),
        [400, 415, 200])
    add("charset latin1", _post("/v1/validate", small, ctype="application/json; charset=latin1"),
        [415])
    add("two charsets", _post("/v1/validate", small,
                              ctype="application/json; charset=utf-8; charset=latin1"), [415])
    add("ctype 10 KB params", _post("/v1/validate", small,
                                    ctype="application/json" + "; a=b" * 2000), [200, 415])
    add("empty Authorization", _post("/v1/validate", small, ["Authorization:"]), [200])
    add("Authorization 10 KB", _post("/v1/validate", small, ["Authorization: Bearer " + "t" * 10000]),
        [200])
    add("no Host 1.1", _req("GET", "/livez", host=False), [400])
    add("no Host 1.0", _req("GET", "/livez", host=False, version="HTTP/1.0", close=False), [200])
    add("HTTP/2.0 line", _req("GET", "/livez", version="HTTP/2.0"), [505, 400, "closed"])
    add("HTTP/0.9", b"GET /livez\r\n\r\n", [400, 505, "closed"])
    add("HTTP/1.1x", _req("GET", "/livez", version="HTTP/1.1x"), [400, 505, "closed"])
    add("HTTP/9.9", _req("GET", "/livez", version="HTTP/9.9"), [400, 505, "closed"])
    add("double spaces", b"GET  /livez  HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
        [400, "closed"])
    add("LF-only lines", _req("GET", "/livez", eol="\n"), [200, 400])
    add("CR-only lines", _req("GET", "/livez", eol="\r"), [400, "closed"])
    add("garbage bytes", bytes(range(256)) * 4, [400, "closed"])
    add("TLS ClientHello", b"\x16\x03\x01\x00\xa5\x01\x00\x00\xa1\x03\x03" + b"\x00" * 100,
        [400, "closed"])

    # --- Content-Length -----------------------------------------------------------
    def cl(value, body=small, path="/v1/validate"):
        return _req("POST", path, ["Content-Type: application/json", "Content-Length: " + value],
                    body)
    add("CL negative", cl("-1"), [400, 413])
    add("CL 2^64", cl("18446744073709551616"), [400, 413], quick_too=True)
    add("CL 1,1", cl("1,1"), [400, 413])
    add("CL plus", cl("+%d" % len(small)), [400, 413])
    add("CL hex", cl("0x10"), [400, 413])
    add("CL 1e3", cl("1e3"), [400, 413])
    add("CL with spaces", cl(" %d " % len(small)), [200, 400])
    add("CL twice different", _req("POST", "/v1/validate",
                                   ["Content-Type: application/json", "Content-Length: 5",
                                    "Content-Length: %d" % len(small)], small), [400])
    add("CL too small", cl("10"), [400])
    add("CL too large then half-close", cl(str(len(small) + 100)), [400, "closed"],
        half_close=True)
    add("CL 0 POST", cl("0", b""), [400])
    add("CL on GET", _req("GET", "/livez", ["Content-Length: 5"], b"hello"), [200, 400])
    add("CL on DELETE unknown", _req("DELETE", "/v1/analyses/" + "0" * 64, ["Content-Length: 3"],
                                     b"abc"), [404, 400, 405])

    # --- Transfer-Encoding ---------------------------------------------------------
    def te(value, body, path="/v1/validate", extra=()):
        return _req("POST", path, ["Content-Type: application/json",
                                   "Transfer-Encoding: " + value] + list(extra), body)
    add("chunk size not hex", te("chunked", b"zz\r\n{}\r\n0\r\n\r\n"), [400, "closed"],
        quick_too=True)
    add("chunk size overflow", te("chunked", b"ffffffffffffffffffff\r\n{}\r\n0\r\n\r\n"),
        [400, 413, "closed"])
    # libmicrohttpd 0.9.75 answers a chunk-size line longer than its buffer with its
    # own 500 page (1.0 with 413): documented in DAEMON.md, Known limits
    add("chunk extension 100 KB", te("chunked", b"2;" + b"e" * 100000 + b"\r\n{}\r\n0\r\n\r\n"),
        [400, 413, 500, "closed"])
    add("chunk trailers", te("chunked", b"%x\r\n" % len(small) + small + b"\r\n0\r\nX-T: 1\r\n\r\n"),
        [200])
    add("TE gzip", te("gzip", small), [400, 411, 415, 501, "closed"])
    add("TE chunked, chunked", te("chunked, chunked", b"%x\r\n" % len(small) + small +
                                  b"\r\n0\r\n\r\n"), [200, 400, 501, "closed"])
    add("TE and CL", te("chunked", b"%x\r\n" % len(small) + small + b"\r\n0\r\n\r\n",
                        extra=["Content-Length: 3"]), [200, 400])
    add("chunked unterminated half-close", te("chunked", b"4\r\n{}  \r\n"), [400, "closed"],
        half_close=True)
    add("chunk longer than size", te("chunked", b"2\r\n{}}}\r\n0\r\n\r\n"), [400, "closed"])
    add("TE on GET", _req("GET", "/livez", ["Transfer-Encoding: chunked"], b"0\r\n\r\n"),
        [200, 400])

    # --- Expect / Upgrade ------------------------------------------------------------
    add("Expect 100 on GET", _req("GET", "/livez", ["Expect: 100-continue"]), [200, 417])
    add("Expect bogus", _post("/v1/validate", small, ["Expect: teapot"]), [200, 417])
    add("Upgrade websocket", _req("GET", "/livez", ["Upgrade: websocket", "Connection: Upgrade",
                                                    "Sec-WebSocket-Key: x", "Sec-WebSocket-Version: 13"],
                                  close=False), [200, 400, 426])
    add("Upgrade h2c", _req("GET", "/livez", ["Upgrade: h2c", "HTTP2-Settings: AAMAAABkAAQAAP__"]),
        [200])
    add("HTTP/2 preface", b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n", [400, 505, "closed"])

    # --- HEAD and OPTIONS oddities --------------------------------------------------
    for p in ("/livez", "/readyz", "/metrics", "/v1/analyses", a, a + "/result",
              a + "/request", "/openapi.json", "/"):
        add("HEAD " + p[:50], _req("HEAD", p), [200], no_body=True, quick_too=(p == a))
    add("HEAD with body", _req("HEAD", "/livez", ["Content-Length: 4"], b"abcd"), [200, 400],
        no_body=True)
    add("HEAD unknown", _req("HEAD", "/nothing"), [404], no_body=True)
    add("OPTIONS *", _req("OPTIONS", "*"), [405, 404])
    add("OPTIONS unknown", _req("OPTIONS", "/nothing"), [404, 405])
    add("OPTIONS with Origin", _req("OPTIONS", "/v1/analyses", ["Origin: http://evil.example",
                                                                "Access-Control-Request-Method: POST"]),
        [405])
    add("GET with evil Origin", _req("GET", "/livez", ["Origin: http://evil.example"]), [200])
    if quick:
        c = [x for x in c if x["quick"]]
    return c


def _head_answer(r):
    """The answer to a HEAD read until close: its status, headers and what
    followed the head (which must be nothing)."""
    from daemon import Headers, Response
    buf = r.body
    end = buf.find(b"\r\n\r\n")
    if end < 0 or not buf.startswith(b"HTTP/1."):
        return r
    lines = buf[:end].decode("latin-1").split("\r\n")
    pairs = [tuple(x.strip() for x in l.split(":", 1)) for l in lines[1:] if ":" in l]
    return Response(int(lines[0].split()[1]), Headers(pairs), buf[end + 4:])


def _library_page(r):
    """True when r is one of libmicrohttpd's own HTML error pages."""
    return r is not None and r.media_type() in ("text/html", "") and b"<html>" in r.body


def run_raw(d, tally, job, quick=False, category="http"):
    for case in cases(job, quick):
        t0 = time.monotonic()
        try:
            r = raw_exchange(d.host, d.port, case["data"], None, case["half_close"],
                             timescale.budget(15))
        except OSError as e:
            r = None
            err = repr(e)
        if r is not None and case["no_body"] and r.status is None:
            r = _head_answer(r)
        out = outcome_of(r) if r is not None else "connection error"
        if out in ("unparsable",):
            out = "closed"
        st = r.status if r is not None else None
        ok = (st if st is not None else out) in case["expect"]
        if ok and case["no_body"] and r is not None and r.body:
            ok = False
        if isinstance(st, int) and st >= 500 and st in case["expect"] and not _library_page(r):
            ok = False   # a documented 5xx comes from libmicrohttpd, never from the daemon
        label = "as expected" if ok else "UNEXPECTED"
        if ok and isinstance(st, int) and st >= 500:
            label = "libmicrohttpd's page (documented)"
        tally.add(category, "%s %s" % (out, label))
        tally.check(ok, category, "%s: %s expected, got %s %s (%.2f s)"
                    % (case["name"], "/".join(map(str, case["expect"])), out,
                       (r.text(120) if r is not None else err), time.monotonic() - t0))
        if isinstance(st, int) and st >= 500 and st not in case["expect"]:
            tally.broken(category, "%s: a 5xx (%s)" % (case["name"], st))
        if not livez(d):
            tally.broken(category, "after %s: /livez does not answer (alive %s)"
                         % (case["name"], d.alive()))
            if not d.alive():
                return


# ---------------------------------------------------------------- scripted

def _read_answers(s, n, budget):
    """Read until n complete answers (status lines counted with their bodies) or close."""
    from daemon import _parse_response
    buf = b""
    got = []
    end = time.monotonic() + budget
    s.settimeout(0.5)
    while len(got) < n and time.monotonic() < end:
        p = _parse_response(buf) if buf else None
        if p is not None and p[1]:
            r = p[0]
            got.append(r.status)
            # drop what this answer used: re-serialise is hard, so find the body end
            head_end = buf.find(b"\r\n\r\n") + 4
            length = int(r.headers.get("Content-Length") or 0)
            buf = buf[head_end + length:]
            continue
        try:
            chunk = s.recv(65536)
        except socket.timeout:
            continue
        except OSError:
            break
        if not chunk:
            break
        buf += chunk
    return got


def scripted(d, tally, job, quick=False, deadline=3.0, category="http"):
    """The exchanges that need a script; each counts as one abuse."""
    small = json.dumps(small_request(omega=10.0)).encode()
    b = timescale.budget

    def one(name, fn):
        t0 = time.monotonic()
        try:
            ok, detail = fn()
        except Exception as e:   # noqa: BLE001 - the abuse itself may raise anything
            ok, detail = False, "raised %r" % e
        tally.add(category, "%s %s" % ("scripted", "as expected" if ok else "UNEXPECTED"))
        tally.check(ok, category, "%s: %s (%.2f s)" % (name, detail, time.monotonic() - t0))
        if not livez(d):
            tally.broken(category, "after %s: /livez does not answer (alive %s)"
                         % (name, d.alive()))

    def pipelined_gets(n=50):
        s = socket.create_connection((d.host, d.port), timeout=b(10))
        one_req = b"GET /livez HTTP/1.1\r\nHost: x\r\n\r\n"
        s.sendall(one_req * (n - 1) + b"GET /livez HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
        got = _read_answers(s, n, b(20))
        s.close()
        return got == [200] * n, "%d pipelined GETs: %d answers, statuses %s" % (
            n, len(got), sorted(set(got)))

    def pipelined_mixed():
        s = socket.create_connection((d.host, d.port), timeout=b(10))
        data = (b"POST /v1/validate HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                b"Content-Length: %d\r\n\r\n" % len(small) + small +
                b"GET /v1/analyses/" + job.encode() + b" HTTP/1.1\r\nHost: x\r\n\r\n" +
                b"POST /v1/validate HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                b"Content-Length: 2\r\n\r\n[]" +
                b"GET /livez HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
        s.sendall(data)
        got = _read_answers(s, 4, b(20))
        s.close()
        return got[:2] == [200, 200] and len(got) == 4 and got[3] == 200 and got[2] in (400, 422), \
            "POST, GET, bad POST, GET pipelined: %s" % got

    def pipelined_after_413():
        s = socket.create_connection((d.host, d.port), timeout=b(10))
        s.sendall(b"POST /v1/validate HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                  b"Content-Length: 99999999\r\n\r\n" + b"GET /livez HTTP/1.1\r\nHost: x\r\n\r\n")
        got = _read_answers(s, 2, b(10))
        s.close()
        return got[:1] == [413] and len(got) <= 2, "413 then a pipelined GET: %s" % got

    def half_closed_complete():
        r = raw_exchange(d.host, d.port, b"GET /livez HTTP/1.1\r\nHost: x\r\n\r\n", None, True,
                         b(10))
        return r.status == 200, "GET then SHUT_WR: %s" % outcome_of(r)

    def half_closed_mid_head():
        r = raw_exchange(d.host, d.port, b"GET /livez HTTP/1.1\r\nHo", None, True, b(10))
        return r.status in (None, 400), "half a head then SHUT_WR: %s" % outcome_of(r)

    def connect_close(n=200):
        for _ in range(n):
            socket.create_connection((d.host, d.port), timeout=b(5)).close()
        return livez(d), "%d connect-then-close" % n

    def connect_rst(n=100):
        for i in range(n):
            s = socket.create_connection((d.host, d.port), timeout=b(5))
            s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            if i % 2:
                s.send(b"POST /v1/validate HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                       b"Content-Length: 1000\r\n\r\n{\"a\":")
            s.close()
        return livez(d), "%d resets, half of them in the middle of a body" % n

    def reset_while_answering():
        s = socket.create_connection((d.host, d.port), timeout=b(5))
        s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        s.send(("GET /v1/analyses/%s?wait=2 HTTP/1.1\r\nHost: x\r\n\r\n" % job).encode())
        s.close()
        return True, "reset after a GET"

    def keep_alive_run(n=200):
        s = socket.create_connection((d.host, d.port), timeout=b(10))
        statuses = []
        for i in range(n):
            s.sendall(("GET /v1/analyses/%s HTTP/1.1\r\nHost: x\r\n\r\n" % job).encode())
            got = _read_answers(s, 1, b(10))
            if not got:
                break
            statuses += got
        s.close()
        return statuses == [200] * n, "%d requests on one keep-alive connection: %d answered" % (
            n, len(statuses))

    def slowloris_head():
        s = socket.create_connection((d.host, d.port), timeout=b(5))
        head = b"GET /livez HTTP/1.1\r\nHost: x\r\nX-Slow: " + b"a" * 1000
        t0 = time.monotonic()
        i = 0
        while time.monotonic() - t0 < b(6 * deadline) and is_open(s):
            try:
                s.send(head[i:i + 1])
            except OSError:
                break
            i += 1
            time.sleep(0.5)
        took = time.monotonic() - t0
        closed = not is_open(s)
        s.close()
        return closed and took >= deadline * 0.9, \
            "a head trickled at 2 bytes/s is closed after %.1f s (deadline %g s)" % (took, deadline)

    def slowloris_body():
        s = socket.create_connection((d.host, d.port), timeout=b(5))
        s.send(b"POST /v1/validate HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
               b"Content-Length: 100000\r\n\r\n")
        t0 = time.monotonic()
        while time.monotonic() - t0 < b(6 * deadline) and is_open(s):
            try:
                s.send(b" ")
            except OSError:
                break
            time.sleep(0.5)
        took = time.monotonic() - t0
        closed = not is_open(s)
        s.close()
        return closed and took >= deadline * 0.9, \
            "a body trickled at 2 bytes/s is closed after %.1f s (deadline %g s)" % (took, deadline)

    def idle_keep_alive():
        s = socket.create_connection((d.host, d.port), timeout=b(5))
        s.sendall(b"GET /livez HTTP/1.1\r\nHost: x\r\n\r\n")
        got = _read_answers(s, 1, b(5))
        closed = wait_closed(s, b(6 * deadline))
        s.close()
        return got == [200] and closed, "an idle keep-alive connection is closed (%s, %s)" % (
            got, closed)

    def wait_closed(s, budget):
        end = time.monotonic() + budget
        while time.monotonic() < end:
            if not is_open(s):
                return True
            time.sleep(0.2)
        return False

    def slow_reader():
        # ask for a result and read one byte a second; the daemon must not stall others
        s = socket.create_connection((d.host, d.port), timeout=b(5))
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1024)
        s.sendall(("GET /v1/analyses/%s/result HTTP/1.1\r\nHost: x\r\n\r\n" % job).encode())
        s.recv(1)
        ok = livez(d)
        s.close()
        return ok, "/livez answers while a reader of a result stalls"

    tests = [("pipelined 50 GETs", pipelined_gets), ("pipelined mixed", pipelined_mixed),
             ("pipelined after 413", pipelined_after_413),
             ("half-closed after a request", half_closed_complete),
             ("half-closed mid head", half_closed_mid_head), ("connect-close x200", connect_close),
             ("reset x100", connect_rst), ("reset while answering", reset_while_answering),
             ("keep-alive x200", keep_alive_run), ("slowloris head", slowloris_head),
             ("slowloris body", slowloris_body), ("idle keep-alive", idle_keep_alive),
             ("slow reader", slow_reader)]
    if quick:
        tests = [t for t in tests if t[0] in ("pipelined mixed", "half-closed after a request",
                                              "reset x100", "slowloris head")]
    for name, fn in tests:
        one(name, fn)


# ---------------------------------------------------------------- trickle

def trickle(d, tally, n=600, sources=1, per_client=64, category="trickle"):
    """n connections trickling a request head one byte at a time, from `sources`
    loopback addresses (127.0.0.2 ...), reopened as soon as the daemon closes
    one; /livez from 127.0.0.1 must answer while they are held, and once they
    stop the request deadline must close every one."""
    import threading
    tag = "%d address%s" % (sources, "es" if sources > 1 else "")
    what = "%d trickling connections from %s" % (n, tag)
    head = b"GET /livez HTTP/1.1\r\nHost: x\r\nX-Slow: "
    socks = [None] * n
    opened = [0]
    stop = threading.Event()

    def src(i):
        k = i % sources
        return "127.0.%d.%d" % (1 + k // 250, 2 + k % 250)

    def reopen(i):
        try:
            s = connect_from(src(i), d.port, timescale.budget(5))
            s.send(head[:1])
            socks[i] = s
            opened[0] += 1
        except OSError:
            socks[i] = None

    def attacker():
        # keep every slot of the attack filled until told to stop
        while not stop.is_set():
            for i in range(n):
                if stop.is_set():
                    break
                s = socks[i]
                if s is None or not is_open(s):
                    if s is not None:
                        s.close()
                    reopen(i)
            stop.wait(0.2)

    for i in range(n):
        reopen(i)
    time.sleep(0.5)
    th = threading.Thread(target=attacker, daemon=True)
    th.start()
    held_max = 0
    answered = 0
    probes = 5
    for _ in range(probes):
        held_max = max(held_max, sum(1 for s in list(socks) if s is not None and is_open(s)))
        try:
            r = d.get("/livez", timeout=5)
            answered += r.status == 200
        except OSError:
            pass
        time.sleep(0.3)
    stop.set()
    th.join(timescale.budget(30))
    tally.add(category, "%s: connections opened" % tag, opened[0])
    tally.add(category, "%s: most held at once" % tag, held_max)
    tally.add(category, "%s: /livez answered" % tag, answered)
    tally.add(category, "%s: /livez unanswered" % tag, probes - answered)
    tally.check(answered == probes, category, "%s: /livez answers while %d are held (%d of %d)"
                % (what, held_max, answered, probes))
    if sources == 1:
        tally.check(held_max <= per_client, category,
                    "%s: at most %d held (per-client limit): %d" % (what, per_client, held_max))
    held = [s for s in socks if s is not None and is_open(s)]
    sent = 1

    def all_closed():
        nonlocal sent
        alive = 0
        for s in held:
            if is_open(s):
                try:
                    s.send(head[sent:sent + 1] if sent < len(head) else b"a")
                    alive += 1
                except OSError:
                    pass
        sent += 1
        time.sleep(1.0)
        return alive == 0
    closed = timescale.wait_until(all_closed, 60, 0.0)
    tally.check(closed, category, "%s: the request deadline closes every one" % what)
    for s in socks:
        if s is not None:
            s.close()
    tally.check(livez(d), category, "%s: /livez answers afterwards" % what)
