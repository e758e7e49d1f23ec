#!/usr/bin/env python3
"""`spinmodal export elastodyn` and GET .../result?format=elastodyn (DESIGN.md 9.3).

Usage: elastodyn_test.py SPINMODAL REFERENCE_BLADES_DIR [SPINMODALD]

The NREL 5-MW blade (r-test's NRELOffshrBsline5MW_Blade.dat, --tip-radius 63 --hub-radius 1.5,
0 rpm) imported and solved by the CLI, then:
  - export elastodyn: exit 0, the fifteen BldFl1Sh(2) ... BldEdgSh(6) lines in the NREL file's
    layout, the fit report as '!' lines, each fit clean and within 1 % of tip; RESULT from '-'
    gives the same bytes;
  - --patch DECK: the deck with exactly those fifteen values replaced, every other byte the
    same (CRLF kept), and it imports to the same request as the original;
  - refusals: a planar result (exit 1 and why), bad options (exit 64), a deck without the
    coefficient lines (exit 1, the name);
  - with SPINMODALD: the daemon's ?format=elastodyn answer is the CLI's bytes (text/plain), a
    planar result's is a 409 no-elastodyn-shapes, and the format is listed in the 400 for a
    bad value.
The numbers themselves (against the NREL file's coefficients, the analytic polynomial) are
tests/codec/elastodyn_test.c and tests/core/test_elastodyn.c.
"""
import json
import os
import re
import subprocess
import sys
import tempfile
import time

FAILURES = []
NAMES = ["%s(%d)" % (n, k) for n in ("BldFl1Sh", "BldFl2Sh", "BldEdgSh") for k in range(2, 7)]


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILURES.append(what)
    return cond


def run(exe, args, stdin=None):
    p = subprocess.run([exe] + args, capture_output=True, timeout=120, input=stdin)
    return p.returncode, p.stdout, p.stderr.decode("utf-8", "replace")


def values(text):
    """{name: value} of the coefficient lines of an export or a deck."""
    out = {}
    for line in text.splitlines():
        m = re.match(r"\s*(\S+)\s+(Bld(?:Fl1|Fl2|Edg)Sh\(\d\))", line)
        if m:
            out[m.group(2)] = float(m.group(1))
    return out


def t_export(exe, tmp, dat):
    rc, req, err = run(exe, ["import", "elastodyn", dat, "--tip-radius", "63", "--hub-radius",
                             "1.5", "--rpm", "0"])
    if not check(rc == 0, "import the NREL 5-MW blade (%d %s)" % (rc, err[:200])):
        return None
    reqf = os.path.join(tmp, "blade.json")
    with open(reqf, "wb") as f:
        f.write(req)
    rc, res, err = run(exe, ["solve", reqf])
    resf = os.path.join(tmp, "result.json")
    with open(resf, "wb") as f:
        f.write(res)
    check(rc == 0, "solve (%d)" % rc)
    rc, out, err = run(exe, ["export", "elastodyn", resf])
    text = out.decode()
    check(rc == 0 and err == "", "export elastodyn: exit 0, nothing on stderr (%d %s)" % (rc, err))
    lines = [ln for ln in text.splitlines() if not ln.startswith("!")]
    check([re.split(r"\s+", ln.strip())[1] for ln in lines] == NAMES,
          "the fifteen coefficient lines in ElastoDyn's order")
    check(lines[0].endswith("BldFl1Sh(2) - Flap mode 1, coeff of x^2") and
          lines[1].endswith("BldFl1Sh(3) -            , coeff of x^3"),
          "the NREL file's layout (%r)" % lines[:2])
    v = values(text)
    for fit in ("BldFl1Sh", "BldFl2Sh", "BldEdgSh"):
        s = sum(v["%s(%d)" % (fit, k)] for k in range(2, 7))
        check(abs(s - 1) < 1e-12, "%s: the written C2..C6 sum to 1 (%.15f)" % (fit, s))
        toks = [re.split(r"\s+", ln.strip())[0] for ln in lines if fit in ln]
        sig = max(len(t.lstrip("-").replace(".", "").lstrip("0")) for t in toks)
        check(sig == 7, "%s: seven significant digits on the largest (%s)" % (fit, toks))
    report = [ln for ln in text.splitlines() if ln.startswith("! Bld")]
    check(len(report) == 3 and not any("warning" in ln for ln in text.splitlines()),
          "a report line per fit, no warning")
    for ln in report:
        m = re.search(r"largest ([0-9.e+-]+) \(of tip\)", ln)
        check(m and float(m.group(1)) < 0.01, "within 1 %% of tip: %s" % ln[:60])
    rc, out2, _ = run(exe, ["export", "elastodyn", "-"], stdin=res)
    check(rc == 0 and out2 == out, "RESULT from stdin: the same bytes")
    return resf, out


def t_patch(exe, tmp, dat, resf, text):
    with open(dat, "rb") as f:
        deck = f.read()
    rc, out, err = run(exe, ["export", "elastodyn", resf, "--patch", dat])
    if not check(rc == 0, "--patch: exit 0 (%d %s)" % (rc, err)):
        return
    want = values(text.decode())
    got = values(out.decode())
    check(got == want, "--patch: the deck holds the exported values")
    # every byte but the fifteen value tokens: split both into lines, compare token-wise
    a, b = deck.split(b"\n"), out.split(b"\n")
    same = len(a) == len(b)
    changed = 0
    for la, lb in zip(a, b):
        if la == lb:
            continue
        ta, tb = re.match(rb"(\s*)(\S+)(.*)", la, re.S), re.match(rb"(\s*)(\S+)(.*)", lb, re.S)
        same &= bool(ta and tb and ta.group(1) == tb.group(1) and ta.group(3) == tb.group(3))
        changed += 1
    check(same and changed == 15, "--patch: byte-identical but for 15 values (%d lines differ)"
          % changed)
    check(deck.count(b"\r\n") == out.count(b"\r\n") > 80, "--patch: CRLF kept")
    patched = os.path.join(tmp, "patched.dat")
    with open(patched, "wb") as f:
        f.write(out)
    args = ["--tip-radius", "63", "--hub-radius", "1.5", "--rpm", "0"]
    r1 = run(exe, ["import", "elastodyn", dat] + args)[1]
    r2 = run(exe, ["import", "elastodyn", patched] + args)[1]
    check(r1 == r2 and r1, "the patched deck imports to the same request")
    rc, out, err = run(exe, ["export", "elastodyn", resf, "--patch", dat, "--case", "1"])
    check(rc == 0, "--case 1")
    rc, out, err = run(exe, ["export", "elastodyn", resf, "--patch", dat, "--case", "2"])
    check(rc == 1 and "no such case" in err, "--case 2 of one case: exit 1 (%d %s)" % (rc, err))
    cut = os.path.join(tmp, "cut.dat")
    with open(cut, "wb") as f:
        f.write(deck.replace(b"BldEdgSh(6)", b"BldEdgSh(7)"))
    rc, out, err = run(exe, ["export", "elastodyn", resf, "--patch", cut])
    check(rc == 1 and "BldEdgSh(6)" in err and out == b"",
          "a deck without BldEdgSh(6): exit 1, named (%s)" % err.strip())


def t_refusals(exe, tmp):
    planar = {"structure": {"joints": {"root": [0, 0], "tip": [1, 0]},
                            "sections": {"s": {"E": 2e11, "A": 1e-4, "I": 1e-9,
                                               "mass_per_length": 0.785}},
                            "members": [{"id": "beam", "from": "root", "to": "tip",
                                         "section": "s", "elements": 4}],
                            "clamp": "root"},
              "analysis": {"omega": 0}}
    reqf = os.path.join(tmp, "planar.json")
    with open(reqf, "w") as f:
        json.dump(planar, f)
    rc, res, err = run(exe, ["solve", reqf])
    resf = os.path.join(tmp, "planar_result.json")
    with open(resf, "wb") as f:
        f.write(res)
    rc, out, err = run(exe, ["export", "elastodyn", resf])
    check(rc == 1 and "spatial" in err and out == b"", "a planar result: exit 1 (%s)" % err.strip())
    for args in (["export", "elastodyn"], ["export", "elastodyn", resf, "--case", "0"],
                 ["export", "elastodyn", resf, "--bogus"], ["export", "elastodyn", resf, resf]):
        rc, out, err = run(exe, args)
        check(rc == 64, "usage %s: exit 64 (%d)" % (" ".join(args[2:]), rc))


def t_daemon(daemon_exe, tmp, text):
    sys.path.append(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                 "e2e"))
    import daemon as dm
    d = dm.Daemon(daemon_exe, tmp, ["--workers", "1"], name="elastodyn")
    d.start()
    try:
        ids = []
        for name in ("blade.json", "planar.json"):
            with open(os.path.join(tmp, name)) as f:
                r = d.post("/v1/analyses?wait=30", json.load(f))
            st = r.json() or {}
            deadline = time.monotonic() + 120
            while st.get("id") and st.get("state") not in ("done", "failed", "canceled") and \
                    time.monotonic() < deadline:
                st = d.get_json("/v1/analyses/%s?wait=20" % st["id"])[1] or {}
            check(st.get("state") == "done", "daemon: %s solved (%s)" % (name, st.get("state")))
            ids.append(st.get("id"))
        r = d.get("/v1/analyses/%s/result?format=elastodyn" % ids[0])
        check(r.status == 200 and r.media_type() == "text/plain" and r.body == text,
              "daemon: ?format=elastodyn is the CLI's bytes (%d %s)" % (r.status, r.ctype()))
        r = d.get("/v1/analyses/%s/result?format=elastodyn" % ids[1])
        check(r.status == 409 and "no-elastodyn-shapes" in (r.json() or {}).get("type", ""),
              "daemon: a planar result is a 409 no-elastodyn-shapes (%d)" % r.status)
        r = d.get("/v1/analyses/%s/result?format=bogus" % ids[0])
        check(r.status == 400 and "elastodyn" in r.body.decode(),
              "daemon: a bad format lists elastodyn (%d)" % r.status)
    finally:
        d.stop()


def main():
    global EXE
    if len(sys.argv) not in (3, 4):
        print(__doc__)
        return 64
    EXE = os.path.abspath(sys.argv[1])
    dat = os.path.join(sys.argv[2], "elastodyn", "NRELOffshrBsline5MW_Blade.dat")
    with tempfile.TemporaryDirectory() as tmp:
        got = t_export(EXE, tmp, dat)
        if got:
            t_patch(EXE, tmp, dat, *got)
        t_refusals(EXE, tmp)
        if got and len(sys.argv) == 4:
            t_daemon(os.path.abspath(sys.argv[3]), tmp, got[1])
    print("%d failures" % len(FAILURES))
    return 1 if FAILURES else 0


EXE = None
if __name__ == "__main__":
    sys.dont_write_bytecode = True
    sys.exit(main())
