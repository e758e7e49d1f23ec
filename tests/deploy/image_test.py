#!/usr/bin/env python3
"""deploy/Dockerfile builds an image that runs (podman or buildah).

Usage: image_test.py SOURCE_ROOT VERSION

1. A builder: podman, else buildah.  None -> skipped (exit 77) with the reason.
2. Usable: a one-file `FROM scratch` build succeeds (root or rootless storage works).
3. The base images (debian:bookworm, debian:bookworm-slim) are present or can be pulled;
   otherwise skipped with the reason (no network to the registry).
4. SPINMODAL_TEST_IMAGE=0 skips the build with that reason (it takes minutes: apt-get,
   npm ci, the whole meson build).
5. Builds deploy/Dockerfile from the source root with --build-arg SPINMODAL_VERSION=VERSION;
   the image's org.opencontainers.image.version label is VERSION and its user 10001; with
   podman also: `spinmodald --version` in it says VERSION and the daemon in it serves the
   web front end's /app.js (not only the plain API page) and /readyz on a SQLite in /tmp,
   with a read-only root file system.
Never passes without building: every other way out is a skip with the reason printed.
"""
import os
import shutil
import subprocess
import sys
import tempfile

FAILURES = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        FAILURES.append(what)
    return bool(cond)


def skip(why):
    print("SKIP " + why, flush=True)
    sys.exit(77)


def run(argv, timeout=600, **kw):
    try:
        return subprocess.run(argv, capture_output=True, text=True, timeout=timeout, **kw)
    except subprocess.TimeoutExpired as e:
        return subprocess.CompletedProcess(argv, 124, e.stdout or "", "timed out after %s s" % timeout)


def last(p):
    lines = (p.stderr or p.stdout or "").strip().splitlines()
    return lines[-1][:300] if lines else "exit %d" % p.returncode


def main():
    src, version = os.path.abspath(sys.argv[1]), sys.argv[2]
    tool = next((t for t in ("podman", "buildah") if shutil.which(t)), None)
    if not tool:
        skip("neither podman nor buildah is installed (Debian: apt-get install podman): the image was not built")
    build = [tool, "build"] if tool == "podman" else [tool, "bud"]
    tmp = tempfile.mkdtemp(prefix="spinmodal-image-")
    probe_tag = "localhost/spinmodal-probe:%d" % os.getpid()
    tag = "localhost/spinmodald:%s-test%d" % (version, os.getpid())
    try:
        with open(os.path.join(tmp, "Containerfile"), "w") as f:
            f.write("FROM scratch\nCOPY x /x\n")
        with open(os.path.join(tmp, "x"), "w") as f:
            f.write("x\n")
        p = run(build + ["-t", probe_tag, tmp], timeout=300)
        run([tool, "rmi", "-f", probe_tag] if tool == "podman" else [tool, "rmi", "-f", probe_tag], timeout=120)
        if p.returncode != 0:
            skip("%s cannot build here (a FROM scratch probe failed: %s)" % (tool, last(p)))
        for base in ("docker.io/library/debian:bookworm", "docker.io/library/debian:bookworm-slim"):
            if run([tool, "inspect", "--type", "image", base] if tool == "podman" else [tool, "inspect", base],
                   timeout=60).returncode == 0:
                continue
            p = run([tool, "pull", base], timeout=600)
            if p.returncode != 0:
                skip("%s works, but the base image %s is not here and cannot be pulled (%s): the image was not built"
                     % (tool, base, last(p)))
        if os.environ.get("SPINMODAL_TEST_IMAGE") == "0":
            skip("SPINMODAL_TEST_IMAGE=0: the image build (minutes) was not run")
        print("building deploy/Dockerfile with %s (minutes: apt-get, npm ci, meson)…" % tool, flush=True)
        p = run(build + ["-f", os.path.join(src, "deploy", "Dockerfile"), "--build-arg", "SPINMODAL_VERSION=" + version,
                         "-t", tag, src], timeout=3300)
        if not check(p.returncode == 0, "%s builds deploy/Dockerfile (%s)" % (" ".join(build), last(p))):
            print(p.stdout[-3000:], p.stderr[-3000:])
            return 1
        fmt = "{{ index .Config.Labels \"org.opencontainers.image.version\" }} {{ .Config.User }}"
        p = run([tool, "inspect", "--format", fmt, tag], timeout=60)
        label, _, user = p.stdout.strip().partition(" ")
        check(label == version, "the image's version label is %s (%s)" % (version, label))
        check(user.split(":")[0] == "10001", "the image runs as uid 10001 (%s)" % user)
        if tool != "podman":
            print("(buildah: the image is not run; podman runs it)")
        else:
            p = run(["podman", "run", "--rm", "--read-only", tag, "--version"], timeout=120)
            check(p.returncode == 0 and p.stdout.startswith("spinmodald %s" % version),
                  "`spinmodald --version` in the image says %s (%s)" % (version, p.stdout.strip()[:80] or last(p)))
            script = ("spinmodald --db /tmp/t.db --listen 127.0.0.1:8080 --workers 1 & sleep 2; "
                      "curl -fsS http://127.0.0.1:8080/readyz && echo && "
                      "curl -fsS -o /dev/null -w '%{http_code} %{content_type}\\n' http://127.0.0.1:8080/app.js; "
                      "kill %1; wait")
            p = run(["podman", "run", "--rm", "--read-only", "--tmpfs", "/tmp", "--entrypoint", "sh", tag, "-c", script],
                    timeout=120)
            out = p.stdout
            check('"status":"ready"' in out, "the daemon in the image is ready on SQLite in /tmp (%s)" % out.strip()[:200])
            check("200 " in out and "javascript" in out, "the image serves the web front end (/app.js) (%s)" % out.strip()[-120:])
    finally:
        run([tool, "rmi", "-f", tag], timeout=300)
        shutil.rmtree(tmp, ignore_errors=True)
    print("%d failure(s)" % len(FAILURES))
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
