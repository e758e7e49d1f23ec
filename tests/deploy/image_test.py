#!/usr/bin/env python3
"""deploy/Dockerfile builds an image whose spinmodald serves, as the image's non-root user.

Usage: image_test.py SOURCE_ROOT VERSION

Needs root, podman, debootstrap, unshare and chroot; without one of them: skipped (exit 77)
with the reason.  SPINMODAL_TEST_IMAGE=0 skips it too.  No registry is used:

1. Base: a Debian 12 root file system made by `debootstrap --variant=minbase bookworm`
   from SPINMODAL_IMAGE_MIRROR (default http://deb.debian.org/debian), kept as a tarball
   in SPINMODAL_IMAGE_CACHE (default /var/cache/spinmodal-image) for 30 days; made again
   when missing or older (or into the test's temporary directory when the cache cannot be
   written).
2. A podman storage of its own in a temporary directory (--root/--runroot; driver overlay,
   vfs where overlay does not work), so the host's podman configuration and images play
   no part; the tarball is imported under each name that deploy/Dockerfile's FROM lines
   give (debian:bookworm, debian:bookworm-slim).
3. `podman build --isolation=chroot --pull=never --format docker` of deploy/Dockerfile
   with --build-arg SPINMODAL_VERSION=VERSION (apt-get and npm ci inside need the
   network).  Where the host trusts local CAs (/usr/local/share/ca-certificates, e.g. a
   proxy that re-signs TLS) that folder is mounted read-only into the build's RUN steps,
   so the build trusts what the host trusts.
4. The image's configuration: version label VERSION, a non-root user, the HEALTHCHECK on
   /livez.
5. `podman run` needs cgroup and rlimit control that some machines refuse: the image's
   file system is used directly instead (`podman image mount`, read-only).  Like a
   container runtime and deploy/k8s/deployment.yaml (readOnlyRootFilesystem, /tmp an
   emptyDir), in a private mount namespace (unshare -m): a fresh directory owned by the
   image's user on each VOLUME, a tmpfs on /tmp, /proc; then
   `chroot --userspec=USER` runs the image's ENTRYPOINT in its WORKDIR with its ENV,
   only SPINMODAL_LISTEN changed to a free loopback port (the host's network).
   Checked: `spinmodald --version` says VERSION; /livez; the web page and its /app.js;
   one job (POST, ?wait= until done, its result); the daemon runs as the image's user
   and its database in the volume belongs to that user; the image's curl (the
   HEALTHCHECK's tool) gets /livez; SIGTERM stops it with status 0.
Prints the time of each step and in all.  Never passes without building: every other way
out is a skip with the reason printed.
"""
import http.client
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "e2e"))
import timescale as ts  # noqa: E402

FAILURES = []
T0 = time.monotonic()
BASE_MAX_AGE_S = 30 * 86400
BASES = ("debian:bookworm", "debian:bookworm-slim")


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        FAILURES.append(what)
    return bool(cond)


def skip(why):
    print("SKIP " + why, flush=True)
    sys.exit(77)


def step(what):
    print("[%6.1f s] %s" % (time.monotonic() - T0, what), flush=True)


def run(argv, timeout=600, **kw):
    try:
        return subprocess.run(argv, capture_output=True, text=True, timeout=timeout, **kw)
    except subprocess.TimeoutExpired as e:
        return subprocess.CompletedProcess(argv, 124, e.stdout or "", "timed out after %s s" % timeout)


def last(p):
    lines = (p.stderr or p.stdout or "").strip().splitlines()
    return lines[-1][:300] if lines else "exit %d" % p.returncode


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    p = s.getsockname()[1]
    s.close()
    return p


def call(port, method, path, body=None, timeout=90):
    """(status, headers, body) of one request to 127.0.0.1:port; (0, {}, b"") when refused."""
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    try:
        hdr = {"Content-Type": "application/json"} if body is not None else {}
        c.request(method, path, body=body, headers=hdr)
        r = c.getresponse()
        return r.status, r.headers, r.read()
    except OSError:
        return 0, {}, b""
    finally:
        c.close()


def base_tarball(tmp):
    """The path of the bookworm minbase tarball: the cached one, else made (and cached)."""
    cache = os.environ.get("SPINMODAL_IMAGE_CACHE") or "/var/cache/spinmodal-image"
    try:
        os.makedirs(cache, exist_ok=True)
        probe = tempfile.mkdtemp(prefix="w-", dir=cache)
        os.rmdir(probe)
    except OSError as e:
        print("the cache %s cannot be written (%s): the base is made in the test's directory" % (cache, e))
        cache = tmp
    tar = os.path.join(cache, "debian-bookworm-minbase.tar")
    if os.path.exists(tar) and time.time() - os.path.getmtime(tar) < BASE_MAX_AGE_S:
        step("base: cached %s (%.0f MB, %.1f days old)" % (tar, os.path.getsize(tar) / 1e6,
                                                          (time.time() - os.path.getmtime(tar)) / 86400))
        return tar
    mirror = os.environ.get("SPINMODAL_IMAGE_MIRROR") or "http://deb.debian.org/debian"
    step("base: debootstrap --variant=minbase bookworm from %s (about a minute)" % mirror)
    work = tempfile.mkdtemp(prefix="debootstrap-", dir=cache)
    try:
        rootfs = os.path.join(work, "rootfs")
        p = run(["debootstrap", "--variant=minbase", "bookworm", rootfs, mirror], timeout=1200)
        if p.returncode != 0:
            print(p.stdout[-2000:], p.stderr[-2000:])
            skip("debootstrap cannot make the base here (%s): the image was not built" % last(p))
        part = os.path.join(work, "base.tar")
        p = run(["tar", "-C", rootfs, "--numeric-owner", "-cf", part, "."], timeout=600)
        if not check(p.returncode == 0, "tar of the debootstrap root (%s)" % last(p)):
            sys.exit(1)
        os.replace(part, tar)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    step("base: %s (%.0f MB)" % (tar, os.path.getsize(tar) / 1e6))
    return tar


def from_names(dockerfile):
    """The image names of the Dockerfile's FROM lines (not the names of its own stages)."""
    names, stages = [], set()
    with open(dockerfile) as f:
        for line in f:
            m = re.match(r"\s*FROM\s+(?:--\S+\s+)*(\S+)(?:\s+AS\s+(\S+))?", line, re.I)
            if m:
                if m.group(1).lower() not in stages:
                    names.append(m.group(1))
                if m.group(2):
                    stages.add(m.group(2).lower())
    return names


class Podman:
    """podman with a storage of its own under DIR (no host configuration, no registry)."""

    def __init__(self, d, driver):
        self.argv = ["podman", "--root", os.path.join(d, "root"), "--runroot", os.path.join(d, "run"),
                     "--storage-driver", driver]
        self.driver = driver

    def __call__(self, *args, timeout=600):
        return run(self.argv + list(args), timeout=timeout)


def import_base(tmp, tar):
    """A Podman whose storage holds the base tarball as localhost/spinmodal-base (overlay, else vfs)."""
    for driver in ("overlay", "vfs"):
        d = os.path.join(tmp, "storage-" + driver)
        pm = Podman(d, driver)
        with open(tar, "rb") as f:
            try:
                p = subprocess.run(pm.argv + ["import", "-", "localhost/spinmodal-base:bookworm"], stdin=f,
                                   capture_output=True, text=True, timeout=600)
            except subprocess.TimeoutExpired:
                p = subprocess.CompletedProcess([], 124, "", "timed out")
        if p.returncode == 0:
            step("podman: storage driver %s, base imported" % driver)
            return pm
        print("podman import with the %s driver failed: %s" % (driver, last(p)))
        pm("rmi", "-a", "-f")
        umount_under(d)
        shutil.rmtree(d, ignore_errors=True)
    skip("podman cannot import the base image here (neither overlay nor vfs storage works)")


def umount_under(path):
    """Unmount whatever is mounted under path (deepest first)."""
    path = os.path.realpath(path)
    try:
        with open("/proc/self/mounts") as f:
            points = [ln.split()[1].replace("\\040", " ") for ln in f]
    except OSError:
        return
    for m in sorted((m for m in points if m == path or m.startswith(path + "/")), key=len, reverse=True):
        run(["umount", "-l", m], timeout=60)


def build(pm, src, version, tag):
    dockerfile = os.path.join(src, "deploy", "Dockerfile")
    names = from_names(dockerfile)
    for n in names:
        short = n[len("docker.io/library/"):] if n.startswith("docker.io/library/") else n
        if not check(short in BASES, "deploy/Dockerfile's FROM %s is a Debian 12 image (%s)" % (n, ", ".join(BASES))):
            return False
        p = pm("tag", "localhost/spinmodal-base:bookworm", n)
        if not check(p.returncode == 0, "the base tagged %s (%s)" % (n, last(p))):
            return False
    argv = ["build", "--isolation=chroot", "--pull=never", "--format", "docker", "-f", dockerfile,
            "--build-arg", "SPINMODAL_VERSION=" + version, "-t", tag]
    cas = "/usr/local/share/ca-certificates"
    if os.path.isdir(cas) and any(n.endswith(".crt") for _, _, fs in os.walk(cas) for n in fs):
        argv += ["--volume", "%s:%s:ro" % (cas, cas)]
        print("the host's local CAs (%s) are mounted into the build's RUN steps" % cas)
    step("build: podman %s (minutes: apt-get, npm ci, meson)" % " ".join(argv[:5]))
    p = pm(*(argv + [src]), timeout=1800)
    if not check(p.returncode == 0, "podman build of deploy/Dockerfile (%s)" % last(p)):
        print(p.stdout[-4000:], p.stderr[-4000:])
        return False
    step("build: done")
    return True


def image_config(pm, tag, version):
    """The image's Config (dict) after checking its label, user and health check; None if unreadable."""
    p = pm("image", "inspect", tag)
    if not check(p.returncode == 0, "podman image inspect (%s)" % (last(p) if p.returncode else "exit 0")):
        return None
    data = json.loads(p.stdout)
    data = data[0] if isinstance(data, list) else data
    cfg = data.get("Config") or {}
    cfg.setdefault("Healthcheck", data.get("Healthcheck") or data.get("HealthCheck"))   # podman: beside Config
    label = (cfg.get("Labels") or {}).get("org.opencontainers.image.version")
    check(label == version, "the image's version label is %s (%s)" % (version, label))
    user = cfg.get("User") or ""
    check(user.split(":")[0] not in ("", "0", "root"), "the image's USER is not root (%r)" % user)
    hc = " ".join((cfg.get("Healthcheck") or {}).get("Test") or [])
    check("/livez" in hc, "the image's HEALTHCHECK asks /livez (%s)" % hc)
    return cfg


def user_ids(root, user):
    """(uid, gid) of the image's USER (numbers, or names looked up in its /etc/passwd)."""
    name, _, group = user.partition(":")
    ents = {}
    with open(os.path.join(root, "etc", "passwd")) as f:
        for ln in f:
            parts = ln.split(":")
            if len(parts) > 3:
                ents[parts[0]] = (int(parts[2]), int(parts[3]))
    uid, gid = (int(name), None) if name.isdigit() else ents.get(name, (None, None))
    if group:
        if group.isdigit():
            gid = int(group)
        else:
            with open(os.path.join(root, "etc", "group")) as f:
                gid = next((int(ln.split(":")[2]) for ln in f if ln.split(":")[0] == group), gid)
    if gid is None:
        gid = next((g for u, g in ents.values() if u == uid), uid)
    return uid, gid


def jail_argv(root, cfg, uid, gid, tmp, argv):
    """unshare + chroot argv that runs argv in the image like a container with a read-only root."""
    vols = sorted((cfg.get("Volumes") or {}).keys())
    script = ["set -e"]
    args = [root]
    for i, v in enumerate(vols):
        d = os.path.join(tmp, "volume%d" % i)
        if not os.path.isdir(d):
            os.makedirs(d)
            os.chown(d, uid, gid)
            os.chmod(d, 0o750)
        args += [d, v]
        script.append('mount --bind "${%d}" "$1${%d}"' % (len(args) - 1, len(args)))
    script += ['mount -t proc proc "$1/proc"', 'mount -t tmpfs -o mode=1777 tmpfs "$1/tmp"',
               'r="$1"; shift %d' % len(args),
               'exec %s --userspec=%d:%d "$r" /usr/bin/env -C "%s" "$@"'
               % (shutil.which("chroot"), uid, gid, cfg.get("WorkingDir") or "/")]
    return [shutil.which("unshare"), "--mount", "--propagation", "private", "--", "/bin/sh", "-c",
            "\n".join(script), "jail"] + args + argv


def image_env(cfg, **over):
    env = dict(e.split("=", 1) for e in cfg.get("Env") or [] if "=" in e)
    env.update(over)
    return env


def read_status(pid):
    try:
        with open("/proc/%d/status" % pid) as f:
            return dict(ln.split(":", 1) for ln in f if ":" in ln)
    except OSError:
        return {}


def serve(root, cfg, version, tmp):
    """Run the image's ENTRYPOINT (spinmodald) from its file system; check it serves."""
    uid, gid = user_ids(root, cfg.get("User") or "")
    check(uid not in (None, 0), "the image's user is uid %s, gid %s" % (uid, gid))
    if not uid:
        return
    entry = cfg.get("Entrypoint") or []
    check(entry and entry[-1].endswith("spinmodald"), "the ENTRYPOINT is spinmodald (%s)" % entry)
    p = run(jail_argv(root, cfg, uid, gid, tmp, entry + ["--version"]), env=image_env(cfg), timeout=120)
    check(p.returncode == 0 and p.stdout.startswith("spinmodald %s" % version),
          "`spinmodald --version` in the image says %s (%s)" % (version, p.stdout.strip()[:80] or last(p)))
    port = free_port()
    env = image_env(cfg, SPINMODAL_LISTEN="127.0.0.1:%d" % port, SPINMODAL_WORKERS="1")
    log = open(os.path.join(tmp, "spinmodald.log"), "w+")
    step("run: the image's spinmodald as %d:%d on 127.0.0.1:%d" % (uid, gid, port))
    d = subprocess.Popen(jail_argv(root, cfg, uid, gid, tmp, entry), env=env, stdout=log, stderr=subprocess.STDOUT)
    try:
        ts.wait_until(lambda: d.poll() is not None or call(port, "GET", "/livez")[0] == 200, 20)
        st, _, body = call(port, "GET", "/livez")
        if not check(st == 200 and d.poll() is None, "GET /livez -> 200 (%s %s)" % (st, body[:80])):
            log.seek(0)
            print(log.read()[-3000:])
            return
        s = read_status(d.pid)
        ids = (s.get("Uid", "").split() + s.get("Gid", "").split())
        check(s.get("Name", "").strip() == "spinmodald" and ids and all(int(x) == (uid if i < 4 else gid)
                                                                       for i, x in enumerate(ids)),
              "the daemon runs as the image's user (%s: Uid %s, Gid %s)"
              % (s.get("Name", "?").strip(), s.get("Uid", "?").strip(), s.get("Gid", "?").strip()))
        st, h, body = call(port, "GET", "/")
        check(st == 200 and b"<title>spinmodal" in body and "html" in h.get("Content-Type", ""),
              "GET / serves the web page (%s, %d bytes)" % (st, len(body)))
        st, h, body = call(port, "GET", "/app.js")
        check(st == 200 and "javascript" in h.get("Content-Type", "") and len(body) > 10000,
              "GET /app.js serves the front end (%s %s, %d bytes)" % (st, h.get("Content-Type"), len(body)))
        job(port)
        db = (image_env(cfg).get("SPINMODAL_DB") or "")
        vols = sorted((cfg.get("Volumes") or {}).keys())
        host_db = next((os.path.join(tmp, "volume%d" % i, os.path.relpath(db, v)) for i, v in enumerate(vols)
                        if db.startswith(v.rstrip("/") + "/")), None)
        check(host_db and os.path.exists(host_db) and os.stat(host_db).st_uid == uid,
              "the database %s is in the volume and belongs to uid %s" % (db, uid))
        hc = (cfg.get("Healthcheck") or {}).get("Test") or []
        cmd = hc[1] if len(hc) == 2 and hc[0] == "CMD-SHELL" else " ".join(hc[1:])
        cmd = cmd.replace("127.0.0.1:8080", "127.0.0.1:%d" % port)
        p = run(["false"]) if "livez" not in cmd else run(jail_argv(root, cfg, uid, gid, tmp, ["/bin/sh", "-c", cmd]), env=image_env(cfg), timeout=120)
        check(p.returncode == 0, "the HEALTHCHECK command in the image passes (port %d: %s)" % (port, p.returncode))
        d.send_signal(signal.SIGTERM)
        try:
            rc = d.wait(ts.budget(30))
        except subprocess.TimeoutExpired:
            rc = "still running"
        check(rc == 0, "SIGTERM stops the daemon with status 0 (%s)" % rc)
    finally:
        if d.poll() is None:
            d.kill()
            d.wait()
        log.seek(0)
        tail = log.read().strip().splitlines()
        print("daemon log (last lines):\n  " + "\n  ".join(tail[-6:]))
        log.close()


def frequencies(res):
    """The frequencies (Hz) of a result document, case by case."""
    return [[m.get("frequency_hz") for m in c.get("modes") or []] for c in res.get("cases") or []]


def job(port):
    """One analysis through the daemon in the image: 202, done, its result (the host's CLI's numbers)."""
    with open(os.path.join(SRC, "examples", "angled-beam-90.json")) as f:
        req = json.load(f)
    req["analysis"]["omega"] = [0.0, 10.0]
    req["analysis"]["mode_shapes"] = False
    st, h, body = call(port, "POST", "/v1/analyses", json.dumps(req).encode())
    jid = (json.loads(body) if body.startswith(b"{") else {}).get("id")
    if not check(st == 202 and jid, "POST /v1/analyses -> 202 with an id (%s %s)" % (st, body[:120])):
        return

    def state():
        b = call(port, "GET", "/v1/analyses/%s?wait=%g" % (jid, ts.wait_param(10)))[2]
        return (json.loads(b) if b.startswith(b"{") else {}).get("state") in ("done", "failed", "canceled")
    ts.wait_until(state, 60)
    st, _, body = call(port, "GET", "/v1/analyses/%s" % jid)
    check(st == 200 and (json.loads(body) if body.startswith(b"{") else {}).get("state") == "done",
          "the job is done (%s %s)" % (st, body[:160]))
    st, _, body = call(port, "GET", "/v1/analyses/%s/result" % jid)
    got = frequencies(json.loads(body) if body.startswith(b"{") else {})
    check(st == 200 and len(got) == 2 and all(len(c) == 3 and all(isinstance(x, float) and x > 0 for x in c)
                                              for c in got),
          "GET its result -> 200: 2 speeds x 3 modes (%s, Hz %s)" % (st, got or body[:160]))
    cli = os.environ.get("SPINMODAL_TEST_CLI")
    if cli and os.access(cli, os.X_OK):
        p = run([cli, "solve", "-"], input=json.dumps(req), timeout=300)
        want = frequencies(json.loads(p.stdout) if p.returncode == 0 else {})
        same = len(want) == len(got) and all(len(a) == len(b) and all(abs(x - y) <= 1e-6 * abs(y) for x, y in zip(a, b))
                                             for a, b in zip(got, want))
        check(same, "the image's result = the host build's `spinmodal solve` within 1e-6 (image %s, host %s)"
              % (got, want))


def main():
    global SRC
    SRC, version = os.path.abspath(sys.argv[1]), sys.argv[2]
    if os.environ.get("SPINMODAL_TEST_IMAGE") == "0":
        skip("SPINMODAL_TEST_IMAGE=0: the image build (minutes) was not run")
    if os.geteuid() != 0:
        skip("not root: debootstrap, podman's chroot build, mount and chroot need root (the image was not built)")
    need = [t for t in ("podman", "debootstrap", "unshare", "chroot") if not shutil.which(t)]
    if need:
        skip("%s not installed (Debian: apt-get install podman debootstrap; see deploy/configuration.md): "
             "the image was not built" % " and ".join(need))
    # the sandbox must allow what running the image needs (a mount namespace, a tmpfs in it):
    # a container that forbids them is an environment without the capability, not a defect
    probe = subprocess.run(["unshare", "-m", "sh", "-c", "mount -t tmpfs tmpfs /mnt && umount /mnt"],
                           capture_output=True, text=True)
    if probe.returncode != 0:
        skip("this machine refuses a mount namespace with a tmpfs (unshare -m: %s): the image "
             "cannot be run here" % (probe.stderr.strip()[:200] or probe.returncode))
    tmp = tempfile.mkdtemp(prefix="spinmodal-image-")
    tag = "localhost/spinmodald:%s-test" % version
    pm = root = None
    try:
        tar = base_tarball(tmp)
        pm = import_base(tmp, tar)
        if not build(pm, SRC, version, tag):
            return 1
        ts.calibrate()   # after the build: the waits below scale with this machine's load
        cfg = image_config(pm, tag, version)
        if cfg is None:
            return 1
        p = pm("image", "mount", tag)
        root = p.stdout.strip()
        if not check(p.returncode == 0 and os.path.isdir(root), "podman image mount (%s)" % (root or last(p))):
            return 1
        serve(root, cfg, version, tmp)
    finally:
        if pm is not None:
            if root:
                pm("image", "unmount", "-f", tag)
            pm("rmi", "-a", "-f", timeout=600)
        umount_under(tmp)
        shutil.rmtree(tmp, ignore_errors=True)
        step("end (storage removed)")
    print("%d failure(s)" % len(FAILURES))
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
