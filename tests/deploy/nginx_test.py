#!/usr/bin/env python3
"""deploy/nginx/spinmodal.conf in front of a real spinmodald.

Usage: nginx_test.py SPINMODALD SOURCE_ROOT

Starts spinmodald (temporary SQLite database, free loopback port; tests/e2e/daemon.py) and
nginx as a helper process (foreground, one process, a temporary prefix, a free loopback
port) with deploy/nginx/spinmodal.conf, changed only where a test must: `listen 80` becomes
the free port and the upstream's servers become the test daemon.  Through the proxy:
  - POST /spinmodal/v1/analyses answers 202 with Location /spinmodal/v1/analyses/{id}, and
    that Location answers the job's status;
  - /spinmodal/metrics is refused (also spelled /spinmodal//metrics, /spinmodal/%6detrics,
    with a query, HEAD) while the daemon itself serves it;
  - a body over --max-body is refused with 413;
  - GET …?wait=30 of a job that stays queued (the one worker busy with a long sweep,
    canceled afterwards) is answered by the daemon after 30 s, not cut by the proxy;
  - /spinmodal redirects to /spinmodal/, and the page is served there.
Exit 77 (skipped) when nginx is not installed (deploy/install-deps.sh lists it as optional).
"""
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import http.client
import json

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "e2e"))
import daemon as dm  # noqa: E402
import timescale as ts  # noqa: E402

FAILURES = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        FAILURES.append(what)
    return bool(cond)


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    p = s.getsockname()[1]
    s.close()
    return p


def find_nginx():
    return shutil.which("nginx") or next((p for p in ("/usr/sbin/nginx", "/usr/local/sbin/nginx") if os.access(p, os.X_OK)), None)


def test_conf(src_text, listen_port, upstream):
    """The shipped file with the listen port and the upstream servers replaced (nothing else)."""
    text, n = re.subn(r"^(\s*)listen\s+80\s*;", r"\1listen 127.0.0.1:%d;" % listen_port, src_text, flags=re.M)
    assert n == 1, "one `listen 80;` in the shipped file"
    m = re.search(r"^(\s*upstream\s+\w+\s*\{)(.*?)(\})", text, re.S | re.M)
    assert m, "an upstream block"
    body = re.sub(r"^\s*server\s+[\w.-]+:\d+[^;]*;\n", "", m.group(2), flags=re.M)
    body = "\n    server %s;\n" % upstream + body
    return text[:m.start(2)] + body + text[m.end(2):]


def request(port, method, path, body=None, headers=None, timeout=90):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    try:
        c.request(method, path, body=body, headers=headers or {})
        r = c.getresponse()
        data = r.read()
        return r.status, r.headers, data
    finally:
        c.close()


def post_json(port, path, obj):
    return request(port, "POST", path, json.dumps(obj).encode(), {"Content-Type": "application/json"})


def angled(n, omega):
    """The angled beam of examples/angled-beam-90.json with n + n elements and the speeds omega."""
    with open(os.path.join(SRC, "examples", "angled-beam-90.json")) as f:
        req = json.load(f)
    for m in req["structure"]["members"]:
        if "elements" in m:
            m["elements"] = n
    req["analysis"]["omega"] = omega
    req["analysis"]["mode_shapes"] = False
    return req


def main():
    global SRC
    exe, SRC = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    nginx = find_nginx()
    if not nginx:
        print("SKIP nginx is not installed (Debian: apt-get install nginx; deploy/install-deps.sh "
              "installs it as optional): deploy/nginx/spinmodal.conf was checked statically only (deploy-nginxconf)")
        return 77
    ts.calibrate(exe)
    tmp = tempfile.mkdtemp(prefix="spinmodal-nginx-")
    # one worker kept busy by a long sweep (below), whose ~67 MB result is over the default
    # --max-result-bytes and whose run may pass the default --job-timeout (30 s) on a slow
    # machine: neither limit here (the ?wait below must find the sweep still running)
    d = dm.Daemon(exe, tmp, ["--workers", "1", "--max-result-bytes", "0", "--job-timeout", "600"])
    ngx = None
    try:
        d.start()
        port = free_port()
        with open(os.path.join(SRC, "deploy", "nginx", "spinmodal.conf")) as f:
            conf = test_conf(f.read(), port, "%s:%d" % (d.host, d.port))
        with open(os.path.join(tmp, "spinmodal.conf"), "w") as f:
            f.write(conf)
        with open(os.path.join(tmp, "nginx.conf"), "w") as f:
            f.write("""daemon off;
master_process off;
pid %(t)s/nginx.pid;
error_log %(t)s/error.log info;
events { worker_connections 64; }
http {
    access_log %(t)s/access.log;
    client_body_temp_path %(t)s/body;
    proxy_temp_path %(t)s/proxy;
    fastcgi_temp_path %(t)s/fastcgi;
    uwsgi_temp_path %(t)s/uwsgi;
    scgi_temp_path %(t)s/scgi;
    include %(t)s/spinmodal.conf;
}
""" % {"t": tmp})
        p = subprocess.run([nginx, "-t", "-p", tmp, "-c", os.path.join(tmp, "nginx.conf")], capture_output=True, text=True)
        if not check(p.returncode == 0, "nginx -t accepts deploy/nginx/spinmodal.conf (%s)" % p.stderr.strip()[-400:]):
            return 1
        ngx = subprocess.Popen([nginx, "-p", tmp, "-c", os.path.join(tmp, "nginx.conf")],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        up = ts.wait_until(lambda: _answers(port), 10)
        if not check(up, "nginx listens on 127.0.0.1:%d" % port):
            return 1

        # POST under the sub-path: 202 + Location under the sub-path, which works
        req = angled(4, [10.0])
        st, h, body = post_json(port, "/spinmodal/v1/analyses", req)
        doc = json.loads(body or b"{}")
        loc = h.get("Location", "")
        check(st == 202 and loc == "/spinmodal/v1/analyses/%s" % doc.get("id"),
              "POST /spinmodal/v1/analyses -> 202, Location %s" % loc)
        st2, _, b2 = request(port, "GET", loc + "?wait=%g" % ts.wait_param(30))
        check(st2 == 200 and json.loads(b2).get("id") == doc.get("id") and json.loads(b2).get("state") == "done",
              "GET the Location through the proxy -> 200, the job, done (%s %s)" % (st2, b2[:120]))
        st3, _, _ = request(port, "GET", "/spinmodal/v1/analyses/%s/result" % doc.get("id"))
        check(st3 == 200, "GET /spinmodal/v1/analyses/{id}/result -> 200 (%s)" % st3)

        # /metrics: refused on the public side, served by the daemon itself
        for method, path in (("GET", "/spinmodal/metrics"), ("GET", "/spinmodal//metrics"),
                             ("GET", "/spinmodal/%6detrics"), ("GET", "/spinmodal/metrics?x=1"),
                             ("HEAD", "/spinmodal/metrics")):
            st, _, b = request(port, method, path)
            check(st in (403, 404) and b"spinmodal_" not in b, "%s %s through the proxy is refused (%s)" % (method, path, st))
        r = d.get("/metrics")
        check(r.status == 200 and b"spinmodal_queue_depth" in r.body, "the daemon itself serves /metrics (%s)" % r.status)

        # body limit = --max-body (1 MiB)
        big = b'{"x":"' + b"a" * (1048576 + 10) + b'"}'
        st, _, _ = request(port, "POST", "/spinmodal/v1/analyses", big, {"Content-Type": "application/json"})
        check(st == 413, "a body over 1 MiB -> 413 (%s)" % st)

        # the page under the sub-path
        st, h, _ = request(port, "GET", "/spinmodal")
        check(st == 301 and h.get("Location", "").endswith("/spinmodal/"), "/spinmodal -> 301 /spinmodal/ (%s %s)"
              % (st, h.get("Location")))
        st, h, b = request(port, "GET", "/spinmodal/")
        check(st == 200 and b"<html" in b.lower(), "GET /spinmodal/ serves the page (%s)" % st)

        # ?wait=30 is not cut: the one worker runs a long sweep, a small job stays queued
        long1 = angled(400, [20.0 * i / 1000 for i in range(1001)])
        st, _, b = post_json(port, "/spinmodal/v1/analyses", long1)
        id1 = json.loads(b).get("id")
        st, _, b = post_json(port, "/spinmodal/v1/analyses", angled(4, [11.0]))
        id2 = json.loads(b).get("id")
        t0 = time.monotonic()
        st, _, b = request(port, "GET", "/spinmodal/v1/analyses/%s?wait=30" % id2, timeout=120)
        el = time.monotonic() - t0
        state = (json.loads(b) if b.startswith(b"{") else {}).get("state")
        st1, _, b1 = request(port, "GET", "/spinmodal/v1/analyses/%s" % id1)
        check(st == 200 and state == "queued" and el >= 29.5,
              "GET ?wait=30 through the proxy: the daemon's own answer after %.1f s (%s, state %s; the long "
              "sweep ahead of it: %s), not cut by the proxy" % (el, st, state, (json.loads(b1) or {}).get("state")))
        for i in (id1, id2):
            request(port, "DELETE", "/spinmodal/v1/analyses/%s" % i)
        rc = d.stop()
        check(rc == 0, "spinmodald stops cleanly (%s)" % rc)
    finally:
        if ngx is not None and ngx.poll() is None:
            ngx.send_signal(signal.SIGQUIT)
            try:
                ngx.wait(10)
            except subprocess.TimeoutExpired:
                ngx.kill()
                ngx.wait()
        if d.alive():
            d.kill()
        if FAILURES:
            print("kept %s (daemon and nginx logs)" % tmp)
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    print("%d failure(s)" % len(FAILURES))
    for f in FAILURES:
        print("  FAIL " + f)
    return 1 if FAILURES else 0


def _answers(port):
    try:
        socket.create_connection(("127.0.0.1", port), 0.5).close()
        return True
    except OSError:
        return False


SRC = None
if __name__ == "__main__":
    sys.exit(main())
