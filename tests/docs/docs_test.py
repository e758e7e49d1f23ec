#!/usr/bin/env python3
"""The documented examples of README.md and deploy/ run against the current build.

Usage: docs_test.py --source-root DIR --build-root DIR --spinmodal EXE --spinmodald EXE
                    [--version V] GROUP           (GROUP: versions, readme, http, all)

versions  one version everywhere: meson.build's project(version:) (--version, else read from
          meson.build) = SM_VERSION of core/spinmodal.h = `spinmodal --version` = `spinmodald
          --version`; every X.Y.Z in README.md and deploy/ (subfolders too) is that version
          (or a known non-version, ALLOWED_OTHER_VERSIONS); every image tag spinmodald:TAG
          and every default of SPINMODAL_VERSION in deploy/ is it too; deploy/k8s/ names
          the image tag in one place.
readme    what README.md shows without a daemon: each "`CMD` prints (excerpt):" block is the
          output of CMD (numbers to the digits shown), each "`examples/X.json`:" block is that
          file, each inline `build/server/spinmodal …` command exits 0, the geometrically exact
          reference numbers are those of tests/reference, the daemon's flags and defaults are
          those of `spinmodald --help`, every repository path in backquotes exists; the
          "Command line" synopsis names every command and option of `spinmodal --help` and
          `spinmodal import --help` and no other; every ```sh block's spinmodal commands (other
          than the curl session's) run as written from the repository root after the
          documented build — `build/server/spinmodal …`, never a bare `spinmodal` (not on PATH),
          each exits 0 with output, and a CSV header shown in a line's comment is the first line
          of what it wrote; `meson install -C build`, when the README offers it, installs both
          programs (into a temporary --destdir).
http      the README's curl session against a real spinmodald (free loopback port, temporary
          database; tests/e2e/daemon.py): every command runs, its HTTP status is a success (or
          one the line's comment names), every output line shown under it ("#   …") is in its
          real output — the job id, the Location, the CSV row — and ID= is the id the daemon
          gave; the problem document shown is the daemon's answer to the request it describes;
          the Python client snippet and the inline client commands run against it.

Excerpts: JSON with "…" is compared as an excerpt: "abc…" is a prefix of the real string,
{…} any object, ", …}" more keys (otherwise the keys are exactly those shown), a string that
looks like a timestamp only has to be a timestamp.  Numbers agree to the digits shown (half a
unit of the last digit); numbers shown with more than 12 significant digits agree to 12
(the last bits depend on the BLAS kernels of the machine).

Prints one line per check (ok / FAIL); exit status 1 when a check failed.  Python 3
standard library only.
"""
import argparse
import ast
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "e2e"))
import daemon as dm  # noqa: E402  (tests/e2e/daemon.py)
import timescale as ts  # noqa: E402

SRC = BUILD = CLI = DAEMON = VERSION = None
FAILURES = []
TS_RE = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?Z$")
VERSION_RE = re.compile(r"(?<![\w.])(\d+\.\d+\.\d+)(?![\w.]*\d)")
# X.Y.Z strings in README.md and deploy/ that are not spinmodal's version: (regex of the
# context, why)
ALLOWED_OTHER_VERSIONS = [
    (r"version=0\.0\.4", "Prometheus text exposition format version"),
    (r"\b(?:before|since) \d+\.\d+\.\d+", "the earlier release a behaviour changed in"),
]


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        FAILURES.append(what)
    return bool(cond)


def read(rel):
    with open(os.path.join(SRC, rel), encoding="utf-8") as f:
        return f.read()


def env1():
    return dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")


def build_path(cmd):
    """A documented command names the build directory `build/`: use the one under test."""
    return re.sub(r"(^|\s)build/", lambda m: m.group(1) + BUILD.rstrip("/") + "/", cmd)


# ---------------------------------------------------------------- markdown

def code_blocks(text):
    """[(lang, body, text before the block since the previous block, line number)]."""
    out, pos = [], 0
    for m in re.finditer(r"^```(\w*)\n(.*?)^```\s*$", text, re.S | re.M):
        out.append((m.group(1), m.group(2), text[pos:m.start()], text[:m.start()].count("\n") + 1))
        pos = m.end()
    return out


def last_paragraph(before):
    paras = [p for p in re.split(r"\n\s*\n", before.strip()) if p.strip()]
    return paras[-1] if paras else ""


def inline_code(text):
    """Inline code spans outside fenced blocks."""
    text = re.sub(r"^```.*?^```\s*$", "", text, flags=re.S | re.M)
    return re.findall(r"`([^`\n]+)`", text)


# ---------------------------------------------------------------- excerpts

class Shown:
    """A number as printed in the docs (the text keeps its digits)."""

    def __init__(self, text):
        self.text = text

    def __repr__(self):
        return self.text


def parse_excerpt(text):
    """Parse JSON with "…" elisions (see the module doc)."""
    t = re.sub(r'"((?:[^"\\]|\\.)*)…"', lambda m: json.dumps({"$prefix": json.loads('"%s"' % m.group(1))}), text)
    t = re.sub(r"\{\s*…\s*\}", '{"$any": true}', t)
    t = re.sub(r",\s*…\s*\}", ', "$more": true}', t)
    t = re.sub(r",\s*…\s*\]", ', {"$more_items": true}]', t)
    return json.loads(t, parse_float=Shown, parse_int=Shown)


def number_ok(shown, actual):
    """actual agrees with the number shown to the digits shown (12 significant at most)."""
    if isinstance(actual, bool) or not isinstance(actual, (int, float)):
        return False
    s = shown.text
    v = float(s)
    mant, _, exp = s.lower().partition("e")
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    half = 0.5 * 10.0 ** (-decimals + (int(exp) if exp else 0))
    sig = len(re.sub(r"^[-+0.]*", "", mant.replace(".", "")).rstrip("0")) or 1
    if "." not in mant and not exp and isinstance(actual, int):
        return actual == int(s)
    if sig > 12:
        half = max(half, 0.5e-11 * abs(v))
    return abs(actual - v) <= half * (1 + 1e-9)


def match(shown, actual, path="", errs=None):
    """Compare an excerpt with the real value; appends 'path: why' to errs."""
    errs = [] if errs is None else errs
    if isinstance(shown, Shown):
        if not number_ok(shown, actual):
            errs.append("%s: shown %s, real %r" % (path or "/", shown.text, actual))
    elif isinstance(shown, dict):
        if shown == {"$any": True}:
            if not isinstance(actual, dict):
                errs.append("%s: shown an object, real %r" % (path, actual))
        elif set(shown) == {"$prefix"}:
            if not (isinstance(actual, str) and actual.startswith(shown["$prefix"])):
                errs.append("%s: shown %r…, real %r" % (path, shown["$prefix"], actual))
        elif not isinstance(actual, dict):
            errs.append("%s: shown an object, real %r" % (path, actual))
        else:
            keys = [k for k in shown if k != "$more"]
            for k in keys:
                if k not in actual:
                    errs.append("%s/%s: shown, not in the real output" % (path, k))
                else:
                    match(shown[k], actual[k], "%s/%s" % (path, k), errs)
            if "$more" not in shown and set(actual) - set(keys):
                errs.append("%s: real output has keys the excerpt neither shows nor elides (…): %s"
                            % (path or "/", sorted(set(actual) - set(keys))))
    elif isinstance(shown, list):
        more = bool(shown) and shown[-1] == {"$more_items": True}
        items = shown[:-1] if more else shown
        if not isinstance(actual, list) or (len(actual) != len(items) if not more else len(actual) < len(items)):
            errs.append("%s: shown %d items, real %s" % (path, len(items), len(actual) if isinstance(actual, list) else repr(actual)))
        else:
            for i, x in enumerate(items):
                match(x, actual[i], "%s/%d" % (path, i), errs)
    elif isinstance(shown, str) and TS_RE.match(shown):
        if not (isinstance(actual, str) and TS_RE.match(actual)):
            errs.append("%s: shown a timestamp, real %r" % (path, actual))
    elif shown != actual or type(shown) is not type(actual):
        errs.append("%s: shown %r, real %r" % (path, shown, actual))
    return errs


def line_ok(shown, real_lines):
    """A shown output line (not JSON) is one of the real lines: fields split at commas and
    blanks, numbers to the digits shown, the rest exactly."""
    def fields(line):
        return re.split(r"(?:,|\s+)", line.strip())
    want = fields(shown)
    for line in real_lines:
        got = fields(line)
        if len(got) != len(want):
            continue
        if all(w == g or (re.fullmatch(r"-?\d+(\.\d+)?([eE][-+]?\d+)?", w) and
                          re.fullmatch(r"-?\d+(\.\d+)?([eE][-+]?\d+)?", g) and
                          number_ok(Shown(w), int(g) if re.fullmatch(r"-?\d+", g) else float(g)))
               for w, g in zip(want, got)):
            return True
    return False


# ================================================================ versions

def t_versions():
    meson_text = read("meson.build")
    m = re.search(r"project\s*\([^)]*?\bversion\s*:\s*'([^']+)'", meson_text, re.S)
    meson_version = m.group(1) if m else None
    v = VERSION or meson_version
    check(v is not None and re.fullmatch(r"\d+\.\d+\.\d+", v), "the project version %r is X.Y.Z" % v)
    check(meson_version == v, "meson.build project(version:) %r = %r" % (meson_version, v))
    m = re.search(r'#define\s+SM_VERSION\s+"([^"]+)"', read("core/spinmodal.h"))
    check(m and m.group(1) == v, "core/spinmodal.h SM_VERSION %r = meson.build's %r" % (m and m.group(1), v))
    for exe, name in ((CLI, "spinmodal"), (DAEMON, "spinmodald")):
        p = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=ts.budget(30), env=env1())
        first = (p.stdout or p.stderr).splitlines()[0] if (p.stdout or p.stderr) else ""
        check(p.returncode == 0 and re.match(r"^%s %s\b" % (name, re.escape(v)), first),
              "`%s --version` says %s %s (%r)" % (name, name, v, first))
    files = ["README.md"]
    for top, dirs, names in os.walk(os.path.join(SRC, "deploy")):   # deploy/, deploy/k8s/, deploy/nginx/ …
        dirs.sort()
        files += [os.path.relpath(os.path.join(top, f), SRC) for f in sorted(names)]
    tags, defaults = [], []
    for rel in files:
        text = read(rel)
        for n, line in enumerate(text.splitlines(), 1):
            for m in VERSION_RE.finditer(line):
                if m.group(1) == v:
                    continue
                why = [w for rx, w in ALLOWED_OTHER_VERSIONS if re.search(rx, line)]
                check(bool(why), "%s:%d: %s is the version %s (%s)" % (rel, n, m.group(1), v, line.strip()[:120]))
            for m in re.finditer(r"\bspinmodald:([\w.${}:-]+)", line):
                tags.append((rel, n, m.group(1)))
            for m in re.finditer(r"(?:ARG\s+SPINMODAL_VERSION=|\$\{SPINMODAL_VERSION:-)([^}\s]*)", line):
                defaults.append((rel, n, m.group(1)))
    for rel, n, tag in tags:
        ok = tag == v or tag == "${SPINMODAL_VERSION:-%s}" % v
        check(ok, "%s:%d: image tag spinmodald:%s is the version %s" % (rel, n, tag, v))
    check(any(rel == "deploy/Dockerfile" for rel, _, _ in defaults),
          "deploy/Dockerfile has ARG SPINMODAL_VERSION=<default> (%s)" % defaults)
    check(any(rel == "deploy/compose.yaml" for rel, _, _ in defaults),
          "deploy/compose.yaml uses ${SPINMODAL_VERSION:-<default>}")
    for rel, n, d in defaults:
        check(d == v, "%s:%d: SPINMODAL_VERSION defaults to the version %s (%r)" % (rel, n, v, d))
    check(len(tags) >= 3, "image tags found in deploy/ and README.md (%d)" % len(tags))
    k8s = [t for t in tags if t[0].startswith("deploy/k8s/")]
    check(len(k8s) == 1, "deploy/k8s/ names the image spinmodald:TAG in one place (%s)" % k8s)


# ================================================================ readme (no daemon)

def run_cmd(cmd, env=None, timeout=120, stdin=None):
    return subprocess.run(["bash", "-c", cmd], cwd=SRC, capture_output=True, text=True, input=stdin,
                          env=env or env1(), timeout=ts.budget(timeout))


def t_readme():
    text = read("README.md")
    blocks = code_blocks(text)
    n_prints = n_files = 0
    for lang, body, before, lineno in blocks:
        para = last_paragraph(before)
        m = re.search(r"`([^`]+)` prints \(excerpt\):\s*$", para)
        if m:
            n_prints += 1
            cmd = m.group(1)
            p = run_cmd(build_path(cmd))
            check(p.returncode == 0, "README:%d: `%s` exits 0 (%d %s)" % (lineno, cmd, p.returncode, p.stderr[-200:]))
            try:
                shown = parse_excerpt(body)
            except ValueError as e:
                check(False, "README:%d: the excerpt parses (%s)" % (lineno, e))
                continue
            errs = match(shown, json.loads(p.stdout)) if p.returncode == 0 else ["no output"]
            check(not errs, "README:%d: the excerpt is the output of `%s`%s"
                  % (lineno, cmd, (": " + "; ".join(errs[:8])) if errs else ""))
        m = re.match(r"^`(examples/[\w.-]+\.json)`:", para)
        if m and lang == "json":
            n_files += 1
            path = os.path.join(SRC, m.group(1))
            ok = os.path.exists(path)
            with open(path) as f:
                same = ok and json.load(f) == json.loads(body)
            check(same, "README:%d: the block is %s" % (lineno, m.group(1)))
    check(n_prints >= 1, "README has a \"`CMD` prints (excerpt):\" block (%d)" % n_prints)
    check(n_files >= 1, "README shows an examples/ file (%d)" % n_files)

    # inline one-shot CLI commands
    cmds = sorted({c for c in inline_code(text) if re.match(r"^build/server/spinmodal \w", c)})
    check(cmds, "README has inline `build/server/spinmodal …` commands")
    for c in cmds:
        p = run_cmd(build_path(c))
        check(p.returncode == 0 and p.stdout.strip(), "README: `%s` exits 0 with output (%d %s)" % (c, p.returncode, p.stderr[-200:]))
    # other examples named in the text solve
    for ex in sorted(set(re.findall(r"`(examples/[\w.-]+\.json)`", text))):
        p = subprocess.run([CLI, "solve", ex], cwd=SRC, capture_output=True, timeout=ts.budget(120), env=env1())
        check(p.returncode == 0, "README names %s: it solves (exit %d)" % (ex, p.returncode))

    # the geometrically exact reference quoted under the worked example
    m = re.search(r"\(`(tests/reference/[\w.]+\.csv)`, FE48 row, β = (\d+)°,\s*Ω = (\d+)\) is ([\d.]+), ([\d.]+), ([\d.]+) rad/s\s+"
                  r"with the free end at \(([\d.]+), ([\d.]+)\) m", text)
    if check(m, "README quotes the geometrically exact reference (FE48 row)"):
        import csv
        with open(os.path.join(SRC, m.group(1))) as f:
            rows = [r for r in csv.DictReader(f) if r["source"].startswith("FE48")
                    and float(r["beta_deg"]) == float(m.group(2)) and float(r["omega"]) == float(m.group(3))]
        if check(len(rows) == 1, "%s has the FE48 row beta %s omega %s" % (m.group(1), m.group(2), m.group(3))):
            r = rows[0]
            real = [r["w1_coriolis"], r["w2_coriolis"], r["w3_coriolis"], r["tip_X1"], r["tip_X2"]]
            shown = [m.group(i) for i in range(4, 9)]
            check(all(number_ok(Shown(s), float(x)) for s, x in zip(shown, real)),
                  "README's reference numbers %s are the CSV's %s to the digits shown" % (shown, real))

    # the daemon's flags and defaults (README "The daemon")
    p = subprocess.run([DAEMON, "--help"], capture_output=True, text=True, timeout=ts.budget(30), env=env1())
    helptext = p.stdout + p.stderr
    para = re.search(r"`spinmodald --help` lists every flag.*?\n\n", text, re.S)
    if check(para, "README has the daemon's flag list"):
        flags = re.findall(r"`(--[\w-]+)[^`]*`(?: \(([^)]*)\))?", para.group(0))
        check(len(flags) >= 10, "README lists the daemon's flags (%d)" % len(flags))
        for flag, default in flags:
            m2 = re.search(r"^\s+%s\b.*?\n(?:.*\n)*?\s+env \S+, default (.*)$" % re.escape(flag), helptext, re.M)
            if not check(m2, "README's %s is a flag of `spinmodald --help`" % flag):
                continue
            real = m2.group(1).strip()
            if default and re.fullmatch(r"[\w.:/-]+( s| MiB)?", default):   # a value, not a description
                want = {"1 MiB": "1048576", "cores": "online cores"}.get(default, re.sub(r" s$", "", default))
                check(want == real, "README's default of %s (%s) is the --help default (%s)" % (flag, default, real))

    cli_synopsis(text)
    cli_blocks(text)
    meson_install(text)

    # repository paths in backquotes exist
    missing, n_paths = [], 0
    for c in sorted(set(inline_code(text))):
        # a relative path with a file name (a dot in its last part) or a directory (ending in /)
        if re.match(r"^[\w-][\w.-]*(/[\w.-]+)*/?$", c) and "/" in c and ("." in c.rstrip("/").split("/")[-1] or c.endswith("/")):
            path = c
            if c.startswith("build/"):
                path = os.path.join(BUILD, c[len("build/"):])
            elif not os.path.isabs(c):
                path = os.path.join(SRC, c)
            n_paths += 1
            if not os.path.exists(path):
                missing.append(c)
    check(n_paths >= 20 and not missing, "every repository path README names exists (%d paths; missing: %s)"
          % (n_paths, missing))


def cli_synopsis(text):
    """The "## Command line" block names every command and option the CLI's help lists, and no
    other (issue 26: the README omitted --critical-csv and --bmodes-mesh)."""
    m = re.search(r"^## Command line\n(.*?)(?=^## )", text, re.M | re.S)
    blocks = code_blocks(m.group(1)) if m else []
    if not check(blocks, "README has a \"## Command line\" section with the synopsis"):
        return
    shown = blocks[0][1]
    helps = ""
    for args in (["--help"], ["import", "--help"]):
        p = subprocess.run([CLI] + args, capture_output=True, text=True, timeout=ts.budget(30), env=env1())
        check(p.returncode == 0, "`spinmodal %s` exits 0 (%d)" % (" ".join(args), p.returncode))
        helps += p.stdout
    opt = re.compile(r"(?<![\w-])--[a-z][a-z-]*")
    real, doc = set(opt.findall(helps)), set(opt.findall(shown))
    check(real and not real - doc, "README's command-line synopsis names every option of `spinmodal "
          "--help` and `spinmodal import --help` (missing: %s)" % sorted(real - doc))
    check(not doc - real, "README's command-line synopsis names no option the CLI lacks (%s)"
          % sorted(doc - real))
    usage = re.findall(r"^(?:usage:)?\s+spinmodal (\w+)", helps, re.M)
    listed = set(re.findall(r"^spinmodal (\w+)", shown, re.M))
    check(set(usage) and not set(usage) - listed, "README's synopsis has every command of the usage "
          "(%s; missing %s)" % (sorted(set(usage)), sorted(set(usage) - listed)))


def cli_blocks(text):
    """Each ```sh block with spinmodal commands, other than the curl session, run line by line as
    written, from a copy of the repository root (links to its folders, build/ the build under
    test) so that what they write stays out of the tree.  A bare `spinmodal` is not on PATH after
    the documented build: it fails.  Lines that need the daemon ($U, curl) are the http group's."""
    import shutil
    n = 0
    for lang, body, _, lineno in code_blocks(text):
        if lang != "sh" or re.search(r"^U=http://", body, re.M) or \
                not re.search(r"^(?:build/server/)?spinmodal\s", body, re.M):
            continue
        tmp = tempfile.mkdtemp(prefix="spinmodal-docs-sh-")
        try:
            for name in os.listdir(SRC):
                if not name.startswith("build"):
                    os.symlink(os.path.join(SRC, name), os.path.join(tmp, name))
            os.symlink(BUILD, os.path.join(tmp, "build"))
            for i, line in enumerate(body.splitlines()):
                cmd, comment = (re.split(r"\s+#\s+", line, 1) + [""])[:2]
                where = "README:%d" % (lineno + 1 + i)
                if re.match(r"^spinmodal\s", cmd):
                    check(False, "%s: `%s` calls a bare spinmodal, which the documented build does not "
                          "put on PATH (write build/server/spinmodal)" % (where, cmd.strip()[:80]))
                    continue
                if not cmd.startswith("build/server/spinmodal "):
                    continue
                n += 1
                p = subprocess.run(["bash", "-c", cmd], cwd=tmp, capture_output=True, text=True,
                                   timeout=ts.budget(120), env=env1())
                out = p.stdout
                m = re.search(r">\s*([\w.-]+)\s*$", cmd)
                if m and os.path.exists(os.path.join(tmp, m.group(1))):
                    with open(os.path.join(tmp, m.group(1))) as f:
                        out = f.read()
                check(p.returncode == 0 and out.strip(), "%s: `%s` runs as written: exit 0 with output "
                      "(%d %s)" % (where, cmd.strip()[:90], p.returncode, p.stderr.strip()[-200:]))
                if re.fullmatch(r"\w+(,\w+)+", comment.strip()):
                    first = out.splitlines()[0] if out else ""
                    check(first == comment.strip(), "%s: the header shown is the first line of its output "
                          "(shown %s, real %s)" % (where, comment.strip(), first))
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
    check(n >= 4, "README's ```sh blocks of CLI commands run (%d commands)" % n)


def meson_install(text):
    """`meson install -C build` as the README offers it: both programs land in a bin/ folder."""
    import shutil
    if "`meson install -C build`" not in text:
        return
    meson = shutil.which("meson")
    if not meson:
        print("SKIP meson is not on PATH: `meson install -C build` not tried")
        return
    tmp = tempfile.mkdtemp(prefix="spinmodal-docs-install-")
    try:
        p = subprocess.run([meson, "install", "-C", BUILD, "--no-rebuild", "--destdir", tmp], capture_output=True,
                           text=True, timeout=ts.budget(120))
        found = {f: os.path.join(top, f) for top, _, names in os.walk(tmp) for f in names
                 if f in ("spinmodal", "spinmodald") and os.path.basename(top) == "bin"}
        ok = p.returncode == 0 and set(found) == {"spinmodal", "spinmodald"}
        if ok:
            v = subprocess.run([found["spinmodal"], "--version"], capture_output=True, text=True,
                               timeout=ts.budget(30))
            ok = v.returncode == 0 and v.stdout.startswith("spinmodal ")
        check(ok, "README's `meson install -C build` installs bin/spinmodal and bin/spinmodald (%d %s)"
              % (p.returncode, sorted(found)))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


# ================================================================ http (a real daemon)

def curl_session(text, d):
    """The ```sh block that starts U=http://…: each command run in order."""
    blocks = [b for b in code_blocks(text) if b[0] == "sh" and re.search(r"^U=http://", b[1], re.M)]
    if not check(len(blocks) == 1, "README has one curl session (```sh with U=http://…) (%d)" % len(blocks)):
        return
    _, body, _, lineno = blocks[0]
    steps = []   # [command line, line number, [shown output lines]]
    for i, line in enumerate(body.splitlines()):
        if line.startswith("#   ") and steps:
            steps[-1][2].append(line[4:])
        elif line.strip() and not line.startswith("#"):
            steps.append([line, lineno + 1 + i, []])
    state = {"U": None, "ID": None}
    last_id = None
    n_cmds = 0
    for cmd, n, shown in steps:
        m = re.match(r"^(\w+)=(\S+)$", cmd)
        if m:
            var, val = m.groups()
            if var == "U":
                check(val == "http://127.0.0.1:8080", "README:%d: U is the daemon's default address (%s)" % (n, val))
                state["U"] = d.base
            elif var == "ID":
                check(last_id is not None and val == last_id,
                      "README:%d: ID= is the id the daemon gave for the submission (shown %s, real %s)" % (n, val, last_id))
                state["ID"] = last_id or val
            else:
                state[var] = val
            continue
        n_cmds += 1
        comment = cmd.split(" # ", 1)[1] if " # " in cmd else ""
        allowed = {int(x) for x in re.findall(r"\b([1-5]\d\d)\b", comment)}
        prelude = "".join("%s=%s\n" % (k, shlex.quote(v)) for k, v in state.items() if v is not None)
        prelude += "curl() { command curl -w '\\n@@HTTP %{http_code}\\n' \"$@\"; }\n"
        p = run_cmd(prelude + cmd)
        codes = [int(x) for x in re.findall(r"^@@HTTP (\d+)$", p.stdout, re.M)]
        out = re.sub(r"\n?@@HTTP \d+\n", "\n", p.stdout)
        good = all((c in allowed) if allowed else (200 <= c < 400) for c in codes)
        check(p.returncode == 0 and codes and good,
              "README:%d: `%s` runs: exit %d, HTTP %s%s" % (n, cmd.split(" # ")[0].strip()[:90], p.returncode, codes,
                                                           " (allowed %s)" % sorted(allowed) if allowed else ""))
        # the body (after the headers with -i) as JSON, when it is JSON
        bodytext = re.split(r"\r?\n\r?\n", out, 1)[-1] if out.startswith("HTTP/") else out
        try:
            doc = json.loads(bodytext)
        except ValueError:
            doc = None
        if isinstance(doc, dict) and "/v1/analyses" in cmd and "-X" not in cmd and isinstance(doc.get("id"), str) \
                and last_id is None:
            last_id = doc["id"]
        real_lines = [l.rstrip("\r") for l in out.splitlines()]
        for s in shown:
            if s.lstrip().startswith("{"):
                try:
                    ex = parse_excerpt(s)
                except ValueError as e:
                    check(False, "README:%d: the excerpt %r parses (%s)" % (n, s[:60], e))
                    continue
                errs = match(ex, doc) if doc is not None else ["the output is not JSON"]
                check(not errs, "README:%d: the shown answer %s… is the real one%s"
                      % (n, s[:40], (": " + "; ".join(errs[:6])) if errs else ""))
            else:
                check(line_ok(s, real_lines), "README:%d: the shown output line is in the real output: %s%s"
                      % (n, s[:100], "" if line_ok(s, real_lines) else "\n       real: %s" % " | ".join(real_lines[:6])[:600]))
    check(n_cmds >= 8, "the curl session has its commands (%d)" % n_cmds)


def problem_example(text, d):
    """The problem document shown after "Errors are `application/problem+json`": the daemon's
    answer to the worked example with the field it points at set to the unknown joint."""
    blocks = [b for b in code_blocks(text) if b[0] == "json" and "application/problem+json" in last_paragraph(b[2])]
    if not check(len(blocks) == 1, "README shows one problem document (%d)" % len(blocks)):
        return
    _, body, _, lineno = blocks[0]
    shown = json.loads(body)
    errs = shown.get("errors") or [{}]
    ptr, msg = errs[0].get("pointer", ""), errs[0].get("message", "")
    m = re.search(r"unknown joint '([^']+)'", msg)
    if not check(ptr.startswith("/structure/members/") and m, "README:%d: the problem is an unknown joint of a member (%s %s)"
                 % (lineno, ptr, msg)):
        return
    with open(os.path.join(SRC, "examples", "angled-beam-90.json")) as f:
        req = json.load(f)
    _, _, _, i, key = ptr.split("/")
    req["structure"]["members"][int(i)][key] = m.group(1)
    r = d.post("/v1/analyses", req)
    check(r.status == shown.get("status") and r.media_type() == "application/problem+json",
          "README:%d: the daemon answers %s application/problem+json (%s %s)" % (lineno, shown.get("status"), r.status, r.ctype()))
    check(r.json() == shown, "README:%d: the problem document shown is the daemon's answer (real %s)" % (lineno, r.text(400)))


def clients(text, d):
    env = dict(env1(), SPINMODAL_URL=d.base, PYTHONPATH=os.path.join(SRC, "clients", "python"))
    env.pop("SPINMODAL_TOKEN", None)
    ref = json.loads(subprocess.run([CLI, "solve", "examples/angled-beam-90.json"], cwd=SRC, capture_output=True,
                                    timeout=ts.budget(120), env=env1()).stdout)
    w_ref = [m["frequency_rad_s"] for m in ref["cases"][0]["modes"]]
    blocks = [b for b in code_blocks(text) if b[0] == "python" and "spinmodal_client" in b[1]]
    if check(len(blocks) == 1, "README shows the Python client (%d)" % len(blocks)):
        _, body, _, lineno = blocks[0]
        check("http://127.0.0.1:8080" in body, "README:%d: the snippet uses the daemon's default address" % lineno)
        p = subprocess.run([sys.executable, "-c", body.replace("http://127.0.0.1:8080", d.base)], cwd=SRC,
                           capture_output=True, text=True, timeout=ts.budget(120), env=env)
        try:
            printed = ast.literal_eval(p.stdout.strip().splitlines()[-1])
        except (ValueError, SyntaxError, IndexError):
            printed = None
        check(p.returncode == 0 and isinstance(printed, list) and len(printed) == len(w_ref)
              and all(abs(a - b) <= 1e-9 * abs(b) for a, b in zip(printed, w_ref)),
              "README:%d: the Python snippet runs and prints the CLI's frequencies (exit %d: %s %s)"
              % (lineno, p.returncode, p.stdout.strip()[-200:], p.stderr.strip()[-300:]))
    cmds = sorted({c for c in inline_code(text)
                   if re.match(r"^(PYTHONPATH=clients/python python3 -m spinmodal_client|clients/curl/\w+\.sh) \S", c)})
    check(len(cmds) >= 2, "README names client commands (%s)" % cmds)
    for c in cmds:
        p = run_cmd(c, env=env)
        check(p.returncode == 0 and p.stdout.strip(), "README: `%s` runs against the daemon: exit 0 with output (%d %s)"
              % (c, p.returncode, p.stderr.strip()[-300:]))


def t_http():
    text = read("README.md")
    tmp = tempfile.mkdtemp(prefix="spinmodal-docs-")
    d = dm.Daemon(DAEMON, tmp, ["--workers", "1"])
    try:
        d.start()
        curl_session(text, d)
        problem_example(text, d)
        clients(text, d)
        rc = d.stop()
        check(rc == 0, "the daemon stops cleanly (exit %s)" % rc)
    finally:
        if d.alive():
            d.kill()
        if FAILURES:
            print("kept %s (daemon log)" % tmp)
        else:
            import shutil
            shutil.rmtree(tmp, ignore_errors=True)


GROUPS = {"versions": t_versions, "readme": t_readme, "http": t_http}


def main():
    global SRC, BUILD, CLI, DAEMON, VERSION
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--source-root", required=True)
    ap.add_argument("--build-root", required=True)
    ap.add_argument("--spinmodal", required=True)
    ap.add_argument("--spinmodald", required=True)
    ap.add_argument("--version", default=None, help="meson.project_version()")
    ap.add_argument("group", choices=list(GROUPS) + ["all"])
    a = ap.parse_args()
    SRC, BUILD = os.path.abspath(a.source_root), os.path.abspath(a.build_root)
    CLI, DAEMON, VERSION = os.path.abspath(a.spinmodal), os.path.abspath(a.spinmodald), a.version
    ts.calibrate(cli=CLI)
    for g in (GROUPS if a.group == "all" else [a.group]):
        print("== " + g, flush=True)
        try:
            GROUPS[g]()
        except Exception as e:  # a crash is a failure, with its cause
            import traceback
            traceback.print_exc()
            check(False, "%s: raised %r" % (g, e))
    print("%d failure(s)" % len(FAILURES))
    for f in FAILURES:
        print("  FAIL " + f)
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
