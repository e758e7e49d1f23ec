#!/usr/bin/env python3
"""MAC tables between two results (DESIGN.md 9.2): `spinmodal compare` and
GET /v1/analyses/{id}/mac?with=ID2.

Usage: compare_test.py SPINMODAL REFERENCE_BLADES_DIR [SPINMODALD]

BModes CertTest Test01 (tests/reference/blades/bmodes_certtest) imported by the CLI and solved
at 48 elements (20 modes) and at 30 elements (8 modes), then:
  - a result against itself: every diagonal MAC 1 (1e-12), matched by index, each row's best
    column its own mode;
  - 48 against 30 elements (two meshes of one blade): matched by span fraction (the finer
    interpolated), diagonal >= 0.99 for modes 1-8 and each row's best its own mode;
  - against BModes' own shapes, TestFiles/Test01_nonunif_blade.out (BModes v3.00, published
    with its CertTest): flap and lag columns, diagonal >= 0.99 for modes 1-5 (printed);
  - the import on BModes' own mesh (--bmodes-mesh: 12 members in a chain) against the same
    .out: read as one span, matched by index at BModes' 13 stations, diagonal >= 0.998 (1-4);
  - --format csv: the JSON's numbers, one row per mode of A;
  - refusals, exit 2 with the reason on stderr: planar against spatial, a request instead of a
    result, a case without shapes, a case that does not exist, a file that is neither;
    exit 64 for bad usage;
  - with SPINMODALD: the daemon's table for the two stored results equals the CLI's (JSON and
    CSV), a planar against a spatial one is 409 not-comparable, a missing `with` 400, an
    unknown id 404.
"""
import json
import os
import subprocess
import sys
import tempfile
import time

FAILURES = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILURES.append(what)
    return cond


def run(exe, args):
    p = subprocess.run([exe] + args, capture_output=True, timeout=120, text=True)
    return p.returncode, p.stdout, p.stderr


def solve(exe, tmp, name, req):
    path = os.path.join(tmp, name + ".json")
    with open(path, "w") as f:
        json.dump(req, f)
    rc, out, err = run(exe, ["solve", path])
    check(rc == 0, "solve %s (%d %s)" % (name, rc, err[:200]))
    res = os.path.join(tmp, name + ".result.json")
    with open(res, "w") as f:
        f.write(out)
    return path, res


def compare(exe, args):
    rc, out, err = run(exe, ["compare"] + args)
    return rc, (json.loads(out) if rc == 0 and out.startswith("{") else out), err


def t_tables(exe, tmp, bm):
    rc, text, err = run(exe, ["import", "bmodes", os.path.join(bm, "Test01_nonunif_blade.bmi")])
    if not check(rc == 0, "import Test01 (%d %s)" % (rc, err[:200])):
        return None
    req = json.loads(text)
    _, r48 = solve(exe, tmp, "t01_48", req)
    req30 = json.loads(text)
    req30["blade"]["elements"] = 30
    req30["analysis"]["modes"] = 8
    _, r30 = solve(exe, tmp, "t01_30", req30)

    rc, d, err = compare(exe, [r48, r48])
    if check(rc == 0, "self: exit 0 (%d %s)" % (rc, err[:200])):
        n = len(d["mac"])
        check(n == 20 and d["matching"] == "by_index", "self: 20 x 20, by index (%s)"
              % d["matching"])
        check(all(abs(d["mac"][i][i] - 1) < 1e-12 for i in range(n)), "self: diagonal 1")
        check(all(b["b"] == b["a"] for b in d["best"]), "self: each mode's best is itself")
    rc, d, err = compare(exe, [r48, r30])
    if check(rc == 0, "two meshes: exit 0 (%d %s)" % (rc, err[:200])):
        diag = [d["mac"][i][i] for i in range(8)]
        print("     48 vs 30 elements, diagonal: " + " ".join("%.5f" % v for v in diag))
        check(d["matching"] == "interpolated_a", "two meshes: the 48-element result "
              "interpolated at the 30-element nodes (%s)" % d["matching"])
        check(min(diag) >= 0.99, "two meshes: diagonal >= 0.99 (min %.5f)" % min(diag))
        check(all(d["best"][i]["b"] == i + 1 for i in range(8)),
              "two meshes: each of modes 1-8 finds itself")
    out = os.path.join(bm, "TestFiles", "Test01_nonunif_blade.out")
    rc, d, err = compare(exe, [r48, out])
    if check(rc == 0, "vs BModes .out: exit 0 (%d %s)" % (rc, err[:200])):
        diag = [d["mac"][i][i] for i in range(8)]
        print("     vs BModes Test01 .out, diagonal 1-8: " + " ".join("%.5f" % v for v in diag))
        print("     frequencies (Hz) spinmodal %s, BModes %s" % (
            " ".join("%.4f" % f for f in d["a"]["frequency_hz"][:5]),
            " ".join("%.4f" % f for f in d["b"]["frequency_hz"][:5])))
        check(d["b"]["source"] == "bmodes_out" and len(d["mac"][0]) == 20,
              "vs BModes .out: its 20 modes read")
        check(min(diag[:5]) >= 0.99, "vs BModes .out: diagonal >= 0.99 for modes 1-5 (min %.5f)"
              % min(diag[:5]))
        check(d["components"].startswith("flap, lag"), "vs BModes .out: flap and lag compared")
    rc, text, err = run(exe, ["import", "bmodes", "--bmodes-mesh", "1",
                              os.path.join(bm, "Test01_nonunif_blade.bmi")])
    _, rown = solve(exe, tmp, "t01_own", json.loads(text))
    rc, d, err = compare(exe, [rown, out])
    if check(rc == 0, "BModes' own mesh vs its .out: exit 0 (%d %s)" % (rc, err[:200])):
        diag = [d["mac"][i][i] for i in range(4)]
        print("     own mesh (12 members, one chain) vs BModes .out, diagonal 1-4: " +
              " ".join("%.5f" % v for v in diag))
        check(d["matching"] == "by_index" and d["a"]["points"] == 13,
              "own mesh: its 12 members read as one span of 13 nodes, BModes' stations (%s, %d)"
              % (d["matching"], d["a"]["points"]))
        check(min(diag) >= 0.998, "own mesh: diagonal >= 0.998 for modes 1-4 (min %.5f)"
              % min(diag))
    rc, csv, err = run(exe, ["compare", r48, r30, "--format", "csv"])
    rows = csv.strip().splitlines()
    _, d, _ = compare(exe, [r48, r30])
    check(rc == 0 and rows[0] == "mode_a,frequency_hz_a,label_a," +
          ",".join("b%d" % (j + 1) for j in range(8)) and len(rows) == 21,
          "csv: the header and one row per mode of A")
    check(rc == 0 and all(float(rows[i + 1].split(",")[3 + j]) == d["mac"][i][j]
                          for i in range(20) for j in range(8)), "csv: the JSON's numbers")
    return r48, r30


def t_refusals(exe, tmp, r48):
    planar = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
        os.path.abspath(__file__)))), "examples", "angled-beam-90.json")
    preq, pres = solve(exe, tmp, "planar", json.load(open(planar)))
    with open(os.path.join(tmp, "t01_48.json")) as f:
        noshape = json.load(f)
    noshape["analysis"]["mode_shapes"] = False
    _, rnos = solve(exe, tmp, "noshapes", noshape)
    junk = os.path.join(tmp, "junk.out")
    with open(junk, "w") as f:
        f.write("Results generated by nothing\n1 2 3\n")
    for args, want, what in (
            ([r48, pres], "components", "planar against spatial"),
            ([r48, preq], "not a result document", "a request instead of a result"),
            ([r48, rnos], "no mode shapes", "a case without shapes"),
            ([r48, r48, "--case", "2"], "no case 2", "a case that does not exist"),
            ([r48, junk], "not a BModes .out", "a file that is neither")):
        rc, out, err = run(exe, ["compare"] + args)
        check(rc == 2 and want in err and not out, "refused: %s (exit %d: %s)"
              % (what, rc, err.strip()[:160]))
    for args in ([r48], [r48, r48, "--case", "0"], [r48, r48, "--format", "xml"]):
        rc, _, _ = run(exe, ["compare"] + args)
        check(rc == 64, "usage: compare %s exits 64 (%d)" % (" ".join(args[1:]), rc))
    return preq


def t_daemon(exe, daemon_exe, tmp, r48, preq):
    sys.path.append(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                                 "e2e"))
    import daemon as dm
    d = dm.Daemon(daemon_exe, tmp, ["--workers", "1"], name="compare")
    d.start()
    try:
        ids = []
        for name in ("t01_48.json", "t01_30.json", os.path.basename(preq)):
            with open(os.path.join(tmp, name)) as f:
                st = d.post("/v1/analyses?wait=30", json.load(f)).json() or {}
            deadline = time.monotonic() + 120
            while st.get("id") and st.get("state") not in ("done", "failed", "canceled") and \
                    time.monotonic() < deadline:
                st = d.get_json("/v1/analyses/%s?wait=20" % st["id"])[1] or {}
            check(st.get("state") == "done", "daemon: %s solved (%s)" % (name, st.get("state")))
            ids.append(st.get("id"))
        r30 = os.path.join(tmp, "t01_30.result.json")
        _, want, _ = compare(exe, [r48, r30])
        r = d.get("/v1/analyses/%s/mac?with=%s" % (ids[0], ids[1]))
        check(r.status == 200 and r.json() == want,
              "daemon: the table is the CLI's (%d)" % r.status)
        _, csv, _ = run(exe, ["compare", r48, r30, "--format", "csv"])
        r = d.get("/v1/analyses/%s/mac?with=%s&format=csv" % (ids[0], ids[1]))
        check(r.status == 200 and r.body.decode() == csv, "daemon: the CSV is the CLI's")
        r = d.get("/v1/analyses/%s/mac?with=%s" % (ids[0], ids[2]))
        check(r.status == 409 and "not-comparable" in (r.json() or {}).get("type", "") and
              "components" in (r.json() or {}).get("detail", ""),
              "daemon: planar against spatial is 409 not-comparable (%d)" % r.status)
        r = d.get("/v1/analyses/%s/mac" % ids[0])
        check(r.status == 400, "daemon: no `with` is 400 (%d)" % r.status)
        r = d.get("/v1/analyses/%s/mac?with=%s" % (ids[0], "0" * 64))
        check(r.status == 404, "daemon: an unknown second id is 404 (%d)" % r.status)
    finally:
        d.stop()


def main():
    if len(sys.argv) not in (3, 4):
        print(__doc__)
        return 64
    exe = os.path.abspath(sys.argv[1])
    bm = os.path.join(sys.argv[2], "bmodes_certtest")
    with tempfile.TemporaryDirectory() as tmp:
        got = t_tables(exe, tmp, bm)
        if got:
            preq = t_refusals(exe, tmp, got[0])
            if len(sys.argv) == 4:
                t_daemon(exe, os.path.abspath(sys.argv[3]), tmp, got[0], preq)
    print("%d failures" % len(FAILURES))
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
