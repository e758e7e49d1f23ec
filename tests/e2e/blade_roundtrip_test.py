#!/usr/bin/env python3
"""Blade round trip (issue 12): import -> JSON -> solve gives the same numbers through the CLI,
the Python client and the daemon; span-wise shapes (DESIGN.md 8.3) the same bytes everywhere
and BModes' shapes and signs on BModes' own blade.

Usage: blade_roundtrip_test.py SPINMODALD SPINMODAL_CLI REFERENCE_BLADES_DIR PYTHON_CLIENT_DIR

BModes CertTest Test01 (tests/reference/blades/bmodes_certtest):
  1. CLI: `spinmodal import bmodes`, `spinmodal solve`, `spinmodal export spanwise|bmodes`.
  2. Daemon: POST /v1/import/bmodes gives the CLI's request; POST /v1/analyses?wait its
     frequencies bit for bit; GET .../result?format=spanwise|bmodes the CLI export's bytes.
  3. Python client (clients/python, as a user runs it): `import bmodes FILE` (it finds the
     section file the .bmi names), `solve`, `solve --spanwise` and `--bmodes`: the same again.
  4. The shapes against BModes' published Test01 output (TestFiles/Test01_nonunif_blade.out):
     the dominant component of modes 1-4 (flap, lag, flap, lag) within 2 % of BModes' (both
     scaled to 1 at their largest value; our blade is the stations' linear interpolant at 48
     elements, BModes' its 12 midpoint-sampled elements, so the frequencies differ by 1.5-4.6 %
     and the shapes by less), and the coupling signs of mode 1 (lag and twist against flap) as
     BModes prints them.
  5. A planar result has no span-wise shapes: the CLI says so (exit 1), the daemon 409.
"""
import json
import os
import re
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True
sys.path.insert(0, HERE)
import daemon as dm  # noqa: E402
import timescale as ts  # noqa: E402

FAILURES = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILURES.append(what)
    return cond


def run(argv, stdin=None):
    p = subprocess.run(argv, input=stdin, capture_output=True, text=True,
                       timeout=ts.budget(120))
    return p.returncode, p.stdout, p.stderr


def solve(d, body):
    """POST /v1/analyses?wait, then GET ...?wait until the job is final (a slow machine, e.g.
    under sanitizers, takes longer than one wait); the status document."""
    r = d.post("/v1/analyses?wait=20", body)
    st = r.json() or {}
    deadline = time.monotonic() + ts.budget(240)
    while st.get("id") and st.get("state") not in ("done", "failed", "canceled") and \
            time.monotonic() < deadline:
        st = d.get_json("/v1/analyses/%s?wait=20" % st["id"])[1] or {}
    if st.get("state") != "done":
        print("     job: %s %s" % (r.status, json.dumps(st)[:300]))
    return st


def freqs(result):
    return [[m["frequency_rad_s"] for m in c["modes"]] for c in result["cases"]]


def bmodes_published(path, n):
    """Mode blocks of a BModes .out: [[[span, flap, flap', lag, lag', twist], ...], ...]."""
    with open(path, encoding="utf-8") as f:
        blocks = re.split(r"-------- Mode No\.", f.read())[1:]
    out = []
    for b in blocks[:n]:
        out.append([[float(x) for x in line.split()] for line in b.splitlines()
                    if re.match(r"^\s*-?\d\.\d{4}\s", line)])
    return out


def table_modes(text):
    """Our BModes-style table parsed the same way (first speed)."""
    blocks = re.split(r"-------- Mode No\.", text)[1:]
    return [[[float(x) for x in line.split()] for line in b.splitlines()
             if re.match(r"^\s*-?\d\.\d{4}\s", line)] for b in blocks]


def interp(x, xs, ys):
    for i in range(len(xs) - 1):
        if xs[i] <= x <= xs[i + 1]:
            t = (x - xs[i]) / (xs[i + 1] - xs[i])
            return ys[i] + t * (ys[i + 1] - ys[i])
    return ys[-1]


def shape_error(ours, theirs, col):
    """Largest difference of column col, each scaled to +1 at BModes' largest value, over
    BModes' stations (ours interpolated linearly to them)."""
    s = [r[0] for r in ours]
    o = [interp(r[0], s, [q[col] for q in ours]) for r in theirs]
    t = [r[col] for r in theirs]
    k = max(range(len(t)), key=lambda i: abs(t[i]))
    if o[k] == 0:
        return float("inf")
    return max(abs(a / o[k] - b / t[k]) for a, b in zip(o, t))


def scenario(exe, cli, ref, client_dir, tmp):
    bm = os.path.join(ref, "bmodes_certtest")
    bmi = os.path.join(bm, "Test01_nonunif_blade.bmi")
    with open(bmi, encoding="utf-8") as f:
        main_text = f.read()
    with open(os.path.join(bm, "blade_sec_props.dat"), encoding="utf-8") as f:
        sec_text = f.read()

    # 1. the CLI
    rc, req_text, err = run([cli, "import", "bmodes", bmi])
    check(rc == 0, "cli import exit 0 (%d: %s)" % (rc, err.strip()[:200]))
    req = json.loads(req_text)
    req_path = os.path.join(tmp, "test01.json")
    with open(req_path, "w", encoding="utf-8") as f:
        f.write(req_text)
    rc, res_text, err = run([cli, "solve", req_path])
    check(rc == 0, "cli solve exit 0 (%d: %s)" % (rc, err.strip()[:200]))
    res_cli = json.loads(res_text)
    res_path = os.path.join(tmp, "test01.result.json")
    with open(res_path, "w", encoding="utf-8") as f:
        f.write(res_text)
    rc, span_cli, err = run([cli, "export", "spanwise", res_path])
    check(rc == 0 and span_cli.startswith("omega,rpm,mode,frequency_hz,per_rev,member,"),
          "cli export spanwise: the CSV header (%d: %s)" % (rc, err.strip()[:200]))
    rc, table_cli, err = run([cli, "export", "bmodes", "-"], stdin=res_text)
    check(rc == 0 and "span_loc\tflap disp\tflap slope\tlag disp\tlag slope\ttwist" in table_cli,
          "cli export bmodes (stdin): BModes' column header")
    hz = [m["frequency_hz"] for m in res_cli["cases"][0]["modes"]]
    print("     Test01 imported, 48 elements, 60 rpm, Coriolis off: " +
          ", ".join("%.4f" % h for h in hz[:6]) + " Hz")

    # rows: one per mode and node, slopes the derivative of the displacements
    rows = [r.split(",") for r in span_cli.strip().splitlines()[1:]]
    n_nodes = len(res_cli["model"]["members"][0]["nodes"])
    check(len(rows) == len(hz) * n_nodes == 20 * 49,
          "spanwise CSV: one row per mode and node (%d rows, %d modes x %d nodes)"
          % (len(rows), len(hz), n_nodes))
    m1 = [[float(x) for x in r[7:15]] for r in rows if r[2] == "1"]  # s, span_m, flap, ...
    worst = 0.0
    for i in range(1, len(m1) - 1):  # central differences of flap and edge against the slopes
        ds = m1[i + 1][0] - m1[i - 1][0]
        for d, sl in ((2, 3), (4, 5)):
            fd = (m1[i + 1][d] - m1[i - 1][d]) / ds
            worst = max(worst, abs(fd - m1[i][sl]))
    scale = max(abs(r[3]) for r in m1)
    check(worst < 0.01 * scale, "spanwise mode 1: slopes = d(shape)/ds to %.2g of the largest "
          "slope (< 1 %%)" % (worst / scale))
    check(max(max(abs(r[2]), abs(r[4])) for r in m1) == 1.0 and m1[0][2:8] == [0.0] * 6,
          "spanwise mode 1: largest displacement 1 (m), clamped root 0")

    # 4. BModes' published shapes and signs
    pub = bmodes_published(os.path.join(bm, "TestFiles", "Test01_nonunif_blade.out"), 4)
    ours = table_modes(table_cli)
    for k, col, name in ((0, 1, "flap"), (1, 3, "lag"), (2, 1, "flap"), (3, 3, "lag")):
        e = shape_error(ours[k], pub[k], col)
        check(e < 0.02, "mode %d %s shape within 2 %% of BModes' published Test01 (%.2f %%)"
              % (k + 1, name, 100 * e))
    tip_o, tip_p = ours[0][-1], pub[0][-1]
    for col, name in ((3, "lag"), (5, "twist")):
        ro, rp = tip_o[col] / tip_o[1], tip_p[col] / tip_p[1]
        check(ro * rp > 0 and abs(ro / rp - 1) < 0.2,
              "mode 1 tip %s/flap %+.3f, BModes %+.3f: same sign, within 20 %%"
              % (name, ro, rp))

    # 2. the daemon
    d = dm.Daemon(exe, tmp, ["--workers", "1"], name="blade")
    d.start()
    try:
        r = d.post("/v1/import/bmodes", {"main": main_text, "sec_props": sec_text,
                                         "name": "Test01_nonunif_blade.bmi"})
        doc = r.json() or {}
        check(r.status == 200 and doc.get("request") == req,
              "daemon import: the CLI's request (status %s)" % r.status)
        st = solve(d, doc.get("request"))
        check(st.get("state") == "done", "daemon solve: done (%s)" % st.get("state"))
        res_d = st.get("result") or d.get_json("/v1/analyses/%s/result" % st.get("id"))[1]
        check(freqs(res_d) == freqs(res_cli), "daemon frequencies = CLI frequencies, bit for bit")
        jid = st.get("id")
        r = d.get("/v1/analyses/%s/result?format=spanwise" % jid)
        check(r.status == 200 and r.ctype().startswith("text/csv") and
              r.body.decode() == span_cli, "daemon ?format=spanwise = CLI export, byte for byte")
        r = d.get("/v1/analyses/%s/result?format=bmodes" % jid)
        check(r.status == 200 and r.ctype().startswith("text/plain") and
              r.body.decode() == table_cli, "daemon ?format=bmodes = CLI export, byte for byte")
        r = d.get("/v1/analyses/%s/result?format=shapes" % jid)
        check(r.status == 400, "daemon ?format=shapes: 400 (%s)" % r.status)

        # 3. the Python client, as a user runs it
        env = dict(os.environ, PYTHONPATH=client_dir, SPINMODAL_URL=d.base)
        pc = [sys.executable, "-m", "spinmodal_client"]

        def client(*args, stdin=None):
            p = subprocess.run(pc + list(args), input=stdin, capture_output=True, text=True,
                               env=env, timeout=ts.budget(120))
            return p.returncode, p.stdout, p.stderr

        rc, out, err = client("import", "bmodes", bmi)
        check(rc == 0 and json.loads(out or "null") == req and "Wagner" in err,
              "client import: the CLI's request, the Wagner warning on stderr (%d)" % rc)
        # BModes' own model through the daemon and the client: the CLI's request again
        rc, own_cli, err = run([cli, "import", "bmodes", "--bmodes-mesh", "8", bmi])
        r = d.post("/v1/import/bmodes?bmodes_mesh=8", {"main": main_text, "sec_props": sec_text,
                                                       "name": "Test01_nonunif_blade.bmi"})
        check(rc == 0 and r.status == 200 and (r.json() or {}).get("request") ==
              json.loads(own_cli or "null"), "?bmodes_mesh=8: the CLI's --bmodes-mesh 8 request")
        rc, out, err = client("import", "bmodes", "--bmodes-mesh", "8", bmi)
        check(rc == 0 and json.loads(out or "null") == json.loads(own_cli or "null"),
              "client import --bmodes-mesh 8: the CLI's request (%d)" % rc)
        r = d.post("/v1/import/bmodes?bmodes_mesh=0", {"main": main_text, "sec_props": sec_text})
        check(r.status == 400, "?bmodes_mesh=0: 400 (%s)" % r.status)
        r = d.post("/v1/import/csv?bmodes_mesh=8&tip_radius=10", {"main": "s,mass_per_length\n"})
        check(r.status == 400 and "bmodes only" in r.text(), "csv ?bmodes_mesh=8: 400 (%s)"
              % r.status)
        rc, out, err = client("solve", req_path)
        check(rc == 0 and freqs(json.loads(out or "{}")) == freqs(res_cli),
              "client solve: the CLI's frequencies, bit for bit (%d)" % rc)
        rc, out, err = client("solve", "--spanwise", req_path)
        check(rc == 0 and out == span_cli, "client solve --spanwise = CLI export (%d)" % rc)
        rc, out, err = client("solve", "--bmodes", req_path)
        check(rc == 0 and out == table_cli, "client solve --bmodes = CLI export (%d)" % rc)

        # critical speeds from the stored result (?format=critical) = the CLI's --critical-csv
        crit_req = {"blade": {"length": 31.623, "elements": 24,
                              "section": {"EA": 1e10, "EI_flap": 1e8, "EI_edge": 4e8, "GJ": 1e8,
                                          "mass_per_length": 100}},
                    "analysis": {"omega": {"from": 0, "to": 12, "steps": 12}, "modes": 4,
                                 "mode_shapes": False, "engine_orders": [1, 2]}}
        c_path = os.path.join(tmp, "critical.json")
        with open(c_path, "w", encoding="utf-8") as f:
            json.dump(crit_req, f)
        rc, crit_cli, err = run([cli, "solve", "--critical-csv", c_path])
        st = solve(d, crit_req)
        r = d.get("/v1/analyses/%s/result?format=critical" % st.get("id"))
        check(rc == 0 and crit_cli.count("\n") >= 2 and r.status == 200 and
              r.ctype().startswith("text/csv") and r.body.decode() == crit_cli,
              "daemon ?format=critical = CLI --critical-csv, byte for byte (%d rows)"
              % (crit_cli.count("\n") - 1))

        # 5. planar: no span-wise shapes
        planar = {"structure": {"joints": {"a": [0, 0], "b": [1, 0]},
                                "sections": {"s": {"E": 7e10, "A": 1e-4, "I": 1e-9,
                                                   "mass_per_length": 0.27}},
                                "members": [{"from": "a", "to": "b", "section": "s",
                                             "elements": 4}],
                                "clamp": "a"},
                  "analysis": {"omega": 1, "modes": 2}}
        st = solve(d, planar)
        r = d.get("/v1/analyses/%s/result?format=spanwise" % st.get("id"))
        check(r.status == 409 and "spatial" in r.text(), "planar ?format=spanwise: 409 saying "
              "why (%s)" % r.status)
        p_path = os.path.join(tmp, "planar.json")
        with open(p_path, "w", encoding="utf-8") as f:
            json.dump(planar, f)
        rc, out, err = run([cli, "solve", p_path])
        rc2, out2, err2 = run([cli, "export", "spanwise", "-"], stdin=out)
        check(rc2 == 1 and out2 == "" and "spatial" in err2,
              "cli export of a planar result: exit 1, says why (%d: %s)" % (rc2, err2.strip()))
    finally:
        d.stop()


def main(argv):
    if len(argv) != 5:
        print(__doc__)
        return 2
    exe, cli, ref, client = (os.path.abspath(a) for a in argv[1:5])
    ts.calibrate(exe, cli)
    with tempfile.TemporaryDirectory(prefix="sm-blade-") as tmp:
        try:
            scenario(exe, cli, ref, client, tmp)
        except Exception as e:  # a harness failure is a test failure with its cause
            check(False, "raised %r" % (e,))
            raise
    print("%d failure(s)" % len(FAILURES) if FAILURES else "all checks passed")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
