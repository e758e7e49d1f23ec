#!/usr/bin/env python3
"""`spinmodal import {bmodes|elastodyn|csv}`: exit codes, stdout JSON, stderr messages.

Usage: import_test.py SPINMODAL REFERENCE_BLADES_DIR

The importers' numbers and every bad-file message are checked by
tests/codec/import_test.c; this checks the command: the request on stdout parses
and is the blade form, warnings go to stderr, a refused file prints one
"FILE:LINE: FIELD: ..." line and exits 2 with nothing on stdout, a missing
file exits 1, bad options exit 64, and the section file is found relative to
the .bmi wherever the command runs.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

FAILURES = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILURES.append(what)
    return cond


def run(exe, args, cwd=None, stdin=None):
    p = subprocess.run([exe] + args, capture_output=True, timeout=60, cwd=cwd, input=stdin)
    return p.returncode, p.stdout.decode("utf-8", "replace"), p.stderr.decode("utf-8", "replace")


def reference(ref, name, test, variant=None):
    """Frequencies (Hz) of modes 1-10: the published CertTest (certtest_frequencies.csv) or our
    BModes runs (bmodes_refined.csv, variant)."""
    import csv
    if variant is None:
        with open(os.path.join(ref, "bmodes_certtest", "certtest_frequencies.csv")) as f:
            rows = [r for r in csv.DictReader(f) if r["test"] == test]
        return [float(r["freq_Hz"]) for r in rows][:10]
    with open(os.path.join(ref, name)) as f:
        lines = [line.strip().split(",") for line in f if line.strip() and line[0] != "#"]
    return [float(r[3]) for r in lines if r[0] == test and r[1] == variant][:10]


def bmodes_own_model(exe, ref, tmp):
    """--bmodes-mesh 8: BModes' 12 elements as uniform members (midpoint properties), 8 FE
    elements each, Coriolis off, no Wagner term: BModes' own model through the importer.
    Test01 against BModes' published numbers (modes 1-6 within 1 %, 7-10 within 2 %); Test02
    against BModes at its 12 elements with the tip mass's centrifugal force in the blade tension
    (our patched run, bmodes_refined.csv "tip_tension_12el": published BModes leaves it out,
    BldVib.f90:279, which puts its flap modes 3.9 / 6.1 % low), the lag modes 1-2 within 1.5 %
    (BModes also gives the tip mass no in-plane centrifugal softening)."""
    cases = (("Test01_nonunif_blade", None, (1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0)),
             ("Test02_blade_with_tip_mass", "tip_tension_12el",
              (1.0, 1.5, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0)))
    for test, variant, tol in cases:
        bmi = os.path.join(ref, "bmodes_certtest", test + ".bmi")
        rc, out, err = run(exe, ["import", "bmodes", "--bmodes-mesh", "8", bmi])
        req = json.loads(out) if rc == 0 else {}
        st = req.get("structure", {})
        check(rc == 0 and "blade" not in req and len(st.get("members", [])) == 12 and
              "bmodes_mesh 8" in err,
              "%s --bmodes-mesh 8: the structure form, 12 members, the warning says so" % test)
        path = os.path.join(tmp, test + ".own.json")
        with open(path, "w") as f:
            f.write(out)
        rc, out, err = run(exe, ["solve", path])
        res = json.loads(out) if rc == 0 else {"cases": [{"modes": []}]}
        hz = [m["frequency_hz"] for m in res["cases"][0]["modes"]][:10]
        want = reference(ref, "bmodes_refined.csv", test, variant)
        check(len(hz) == 10 == len(want), "%s: 10 modes solved and referenced" % test)
        for i, (a, b) in enumerate(zip(hz, want)):
            e = 100 * (a / b - 1)
            check(abs(e) <= tol[i], "%s mode %2d: %.4f Hz, BModes %s %.4f Hz: %+.2f %% (within %g %%)"
                  % (test, i + 1, a, variant or "published", b, e, tol[i]))
        if variant:
            pub = reference(ref, None, test)
            check(len(pub) == 10 and pub[0] < 0.97 * hz[0] and pub[2] < 0.95 * hz[2],
                  "%s: published BModes flap 1 and 2 (%.4f, %.4f Hz) 3 %% and 5 %% or more below "
                  "(its tip mass is left out of the tension)" % (test, pub[0], pub[2]))


def extreme_numbers_exit_2(exe, bm, tmp):
    """Issue 23 item 4: numbers that are merely extreme were "import: out of memory", exit 1;
    now exit 2 with FILE:LINE: FIELD (the option's name when it came from an option)."""
    big = "1.7976931348623157e308"
    csv = os.path.join(tmp, "ok.csv")
    with open(csv, "w") as f:
        f.write("s,mass_per_length,EI_flap,EI_edge\n0,1,1,1\n1,1,1,1\n")
    ei = os.path.join(tmp, "ei.csv")
    with open(ei, "w") as f:
        f.write("s,mass_per_length,EI_flap,EI_edge\n0,1,1e305,1\n1,1,1,1\n")
    with open(os.path.join(bm, "Test01_nonunif_blade.bmi")) as f:
        bmi = f.read().split("\n")
    rpm = list(bmi)
    rpm[6] = rpm[6].replace("60.0", "1e200")
    rpm[7] = rpm[7].replace("1.0 ", "1e200 ")
    with open(os.path.join(tmp, "rpm.bmi"), "w") as f:
        f.write("\n".join(rpm))
    shutil.copy(os.path.join(bm, "blade_sec_props.dat"), tmp)
    cases = ((["csv", ei, "--tip-radius", "20"], ei + ":2: EI_flap: "),
             (["csv", csv, "--tip-radius", big], csv + ": tip_radius: out of range"),
             (["csv", csv, "--tip-radius", "20", "--rpm", big], csv + ": rpm: out of range"),
             (["bmodes", os.path.join(tmp, "rpm.bmi")],
              os.path.join(tmp, "rpm.bmi") + ":8: rpm_mult: rot_rpm x rpm_mult"))
    for args, want in cases:
        rc, out, err = run(exe, ["import"] + args)
        check(rc == 2 and out == "" and err.startswith(want) and "out of memory" not in err,
              "item 4: %s -> exit 2, %s... (got %d: %s)" % (" ".join(args[:1] + args[2:]), want,
                                                           rc, err.strip()))


def sec_props_file_confined(exe, bm, tmp):
    """Issue 23 item 8: the .bmi's sec_props_file could name any file ('../../../etc/passwd'
    printed its line 2; '-' read standard input).  It is relative to the .bmi's folder and must
    stay inside it unless --allow-outside; '-' is refused; an error quotes at most 40 escaped
    characters of a line."""
    with open(os.path.join(bm, "Test01_nonunif_blade.bmi")) as f:
        bmi = f.read()
    sub = os.path.join(tmp, "confined", "sub")
    os.makedirs(os.path.join(sub, "inner"))
    secret = os.path.join(tmp, "confined", "secret.dat")
    with open(secret, "w") as f:
        f.write("title\nSECRET-" + "x" * 60 + "\x1b[2J\n")
    shutil.copy(os.path.join(bm, "blade_sec_props.dat"), os.path.join(sub, "inner", "s.dat"))

    def bmi_naming(name):
        path = os.path.join(sub, "p.bmi")
        with open(path, "w") as f:
            f.write(bmi.replace("'blade_sec_props.dat'", "'%s'" % name))
        return path

    deep = "../" * 12 + "etc/passwd"
    for name, why in ((deep, "a '..' component leaves the .bmi's folder"),
                      ("../secret.dat", "a '..' component leaves the .bmi's folder"),
                      ("inner/../../secret.dat", "a '..' component leaves the .bmi's folder"),
                      (secret, "an absolute path, outside the .bmi's folder"),
                      ("/etc/passwd", "an absolute path, outside the .bmi's folder")):
        path = bmi_naming(name)
        rc, out, err = run(exe, ["import", "bmodes", path])
        check(rc == 2 and out == "" and err.startswith(path + ":31: sec_props_file: cannot read")
              and why in err and "--allow-outside" in err and "SECRET" not in err
              and "root:" not in err, "item 8: %s refused (%s)" % (name, err.strip()))
    bmi_naming("-")  # the .bmi in the working folder: its "-" was standard input
    rc, out, err = run(exe, ["import", "bmodes", "p.bmi"], cwd=sub, stdin=b"title\n21\n")
    check(rc == 2 and "'-' is not standard input" in err, "item 8: '-' refused, stdin not read "
          "(%s)" % err.strip())
    # inside the folder: read, relative to the .bmi wherever the command runs
    rc, out, err = run(exe, ["import", "bmodes", bmi_naming("inner/s.dat")], cwd="/")
    check(rc == 0 and json.loads(out)["blade"]["length"] == 33.25,
          "item 8: inner/s.dat below the .bmi's folder is read (%s)" % err.strip())
    # --allow-outside reads it; the error quotes a short, escaped excerpt of the line only
    rc, out, err = run(exe, ["import", "bmodes", bmi_naming("../secret.dat"), "--allow-outside"])
    line = err.strip()
    check(rc == 2 and line.startswith("../secret.dat:2: n_secs: not a number (\"SECRET-xxx") and
          "x" * 34 not in line and line.endswith("...\")") and "\x1b" not in line,
          "item 8: --allow-outside reads it; at most 40 characters of its line quoted (%s)" % line)
    rc, out, err = run(exe, ["import", "csv", "x.csv", "--allow-outside"])
    check(rc == 64 and "usage:" in err, "item 8: --allow-outside on csv: usage, exit 64")
    rc, out, err = run(exe, ["import", "--help"])
    check(rc == 0 and "--allow-outside" in out, "item 8: import --help documents --allow-outside")


def rpm_ranges(exe, bmi, tmp):
    """--rpm takes one speed, a list or START:STOP:COUNT (COUNT speeds, both ends included, as
    the Python client and campbell.sh): a range is the request's {from, to, steps}, and it
    solves at those speeds; 0:15:1 (which would be 0 rpm alone) and STOP < START are usage
    errors (issue 26)."""
    for spec, want in (("0:15:16", {"from": 0.0, "to": 15.0, "steps": 15}),
                       ("0,5,10", [0.0, 5.0, 10.0]), ("7:7:1", [7.0]), ("12.1", [12.1])):
        rc, out, err = run(exe, ["import", "bmodes", bmi, "--rpm", spec])
        req = json.loads(out) if rc == 0 else {}
        check(rc == 0 and req.get("analysis", {}).get("rpm") == want,
              "--rpm %s: analysis.rpm %r (%d %r)" % (spec, want, rc, req.get("analysis", {}).get("rpm")))
        if spec == "0:15:16":
            check("rotor speeds 0 to 15 rpm given (a range)" in err,
                  "--rpm 0:15:16: the warning names the range (%s)" % err.strip())
    rc, out, err = run(exe, ["import", "bmodes", bmi, "--rpm", "0:15:4"])
    path = os.path.join(tmp, "range.json")
    with open(path, "w") as f:
        f.write(out)
    rc, out, err = run(exe, ["solve", "--csv", path])
    lines = out.strip().split("\n") if rc == 0 else ["rpm"]
    col = lines[0].split(",").index("rpm")
    rpms = sorted({round(float(line.split(",")[col]), 9) for line in lines[1:]})
    check(rpms == [0.0, 5.0, 10.0, 15.0], "--rpm 0:15:4 solves at 0, 5, 10, 15 rpm (%d %r)" % (rc, rpms))
    for spec, say in (("0:15:1", "0:15:16"), ("15:0:4", "STOP must not be below START"),
                      ("0:15", "START:STOP:COUNT"), ("0:15:2.5", "COUNT"), ("1,x", "list"),
                      ("-1", "speed >= 0")):
        rc, out, err = run(exe, ["import", "bmodes", bmi, "--rpm", spec])
        check(rc == 64 and out == "" and say in err and "usage:" in err,
              "--rpm %s: exit 64, says %r (%d %s)" % (spec, say, rc, err.strip()[:160]))


def csv_bom(exe, tmp):
    """Issue 23 item 6: Excel's "CSV UTF-8" (a byte-order mark) imports; UTF-16 is refused."""
    text = "s, mass_per_length, EI_flap, EI_edge\n0,1,1,1\n1,1,1,1\n"
    rc, out, err = run(exe, ["import", "csv", "-", "--tip-radius", "20"], stdin=text.encode())
    rc2, out2, err2 = run(exe, ["import", "csv", "-", "--tip-radius", "20"],
                          stdin=b"\xef\xbb\xbf" + text.encode())
    check(rc == rc2 == 0 and out == out2, "item 6: a UTF-8 BOM imports as without (%s)" % err2.strip())
    rc, out, err = run(exe, ["import", "csv", "-", "--tip-radius", "20"],
                       stdin=text.encode("utf-16"))
    check(rc == 2 and "UTF-16" in err and "UTF-8" in err, "item 6: UTF-16 refused (%s)" % err.strip())


def main(argv):
    if len(argv) != 3:
        print("usage: import_test.py SPINMODAL REFERENCE_BLADES_DIR", file=sys.stderr)
        return 64
    exe, ref = os.path.abspath(argv[1]), os.path.abspath(argv[2])
    bm = os.path.join(ref, "bmodes_certtest")
    test02 = os.path.join(bm, "Test02_blade_with_tip_mass.bmi")
    ed = os.path.join(ref, "elastodyn", "NRELOffshrBsline5MW_Blade.dat")
    tmp = tempfile.mkdtemp(prefix="spinmodal-import-")
    try:
        # BModes: the request on stdout, from another working directory
        rc, out, err = run(exe, ["import", "bmodes", test02], cwd=tmp)
        check(rc == 0, "bmodes Test02: exit 0 (got %d, %s)" % (rc, err.strip()))
        req = json.loads(out) if rc == 0 else {}
        blade = req.get("blade", {})
        check(set(req) == {"blade", "frames", "analysis"}, "bmodes: stdout is the request only")
        check(blade.get("length") == 33.25 and blade.get("hub_radius") == 1.75,
              "bmodes: length 33.25, hub_radius 1.75")
        check(len(blade.get("stations", [])) == 21, "bmodes: 21 stations")
        check(blade.get("stations", [{}] * 3)[2].get("mass_per_length") == 181.672,
              "bmodes: station 3 mass_per_length 181.672")
        check(blade.get("tip_mass") == {"mass": 40.0, "offset": [0.0, 0.05, 0.0],
                                        "inertia": [2.5, 1.75, 10.0], "products": [0.0, 0.0, 0.0]},
              "bmodes: tip mass 40 kg, offset [0, 0.05, 0], inertia [2.5, 1.75, 10]")
        check(req.get("analysis", {}).get("rpm") == [60.0], "bmodes: analysis.rpm [60]")
        check(blade.get("section") == {"ip_over_a": 0.0},
              "bmodes: section.ip_over_a 0 (BModes has no Wagner term)")
        check(err.count("warning:") == 1 and "Wagner" in err,
              "bmodes: one warning on stderr, the Wagner term left out")
        check("181.672," in out, "bmodes: numbers printed at 15 digits (181.672)")

        # --full --pretty: the import document; --rpm overrides with a warning
        rc, out, err = run(exe, ["import", "bmodes", test02, "--full", "--pretty", "--rpm", "30"])
        doc = json.loads(out) if rc == 0 else {}
        check(rc == 0 and set(doc) == {"request", "warnings", "input_warnings", "source"},
              "bmodes --full: request, warnings, input_warnings, source")
        # issue 26: the import's warnings have the shape of a result's input_warnings
        check([w.get("pointer") for w in doc.get("input_warnings", [])] ==
              ["/analysis/rpm", "/blade/section/ip_over_a"] and
              all(set(w) == {"pointer", "message"} for w in doc["input_warnings"]),
              "bmodes --full: input_warnings [{pointer, message}] at /analysis/rpm and "
              "/blade/section/ip_over_a (%r)" % doc.get("input_warnings"))
        check(doc.get("warnings") == [w["message"] for w in doc.get("input_warnings", [])],
              "bmodes --full: warnings, the same messages as strings (older clients)")
        check(doc.get("request", {}).get("analysis", {}).get("rpm") == [30.0], "bmodes --rpm 30")
        check(doc.get("source", {}).get("el_loc", [None])[-1] == 1.0, "bmodes: source.el_loc")
        check("\n  " in out, "--pretty indents")
        check(err.startswith("spinmodal: warning: /analysis/rpm: rotor speed 30 rpm given"),
              "bmodes --rpm: warning with its pointer on stderr (%s)" % err.strip())
        rpm_ranges(exe, test02, tmp)

        # a refused file: one line on stderr, exit 2, nothing on stdout
        rc, out, err = run(exe, ["import", "bmodes", os.path.join(bm, "Test03_tower.bmi")])
        # towers are imported since issue 25 (the tower form; tests/cli/tower_test.py)
        check(rc == 0 and "tower" in json.loads(out or "{}"),
              "tower: the tower form (got %d)" % rc)
        # the section file is relative to the .bmi: copy the .bmi alone -> cannot read it
        lone = os.path.join(tmp, "lone.bmi")
        shutil.copy(test02, lone)
        rc, out, err = run(exe, ["import", "bmodes", lone])
        check(rc == 2 and err.strip() == lone + ":31: sec_props_file: cannot read "
              "\"blade_sec_props.dat\": No such file or directory", "sec file missing: %s" % err.strip())
        # a bad section file next to it
        with open(os.path.join(bm, "blade_sec_props.dat")) as f:
            lines = f.read().split("\n")
        lines[7] = lines[7].replace("2611.3E+06", "abc")
        with open(os.path.join(tmp, "blade_sec_props.dat"), "w") as f:
            f.write("\n".join(lines))
        rc, out, err = run(exe, ["import", "bmodes", "lone.bmi"], cwd=tmp)
        check(rc == 2 and err.strip() == 'blade_sec_props.dat:8: axial_stff: not a number ("abc")',
              "bad section file: exit 2 and message (%s)" % err.strip())

        # ElastoDyn: needs --tip-radius
        rc, out, err = run(exe, ["import", "elastodyn", ed, "--tip-radius", "63", "--hub-radius",
                                 "1.5", "--rpm", "12.1"])
        req = json.loads(out) if rc == 0 else {}
        check(rc == 0 and req.get("blade", {}).get("length") == 61.5 and
              len(req["blade"]["stations"]) == 49, "elastodyn: exit 0, length 61.5, 49 stations")
        check(err.count("spinmodal: warning:") == 2, "elastodyn: 2 warnings (EA, GJ assumed)")
        rc, out, err = run(exe, ["import", "elastodyn", ed])
        check(rc == 2 and out == "" and ": tip_radius: the file does not give the blade length" in err,
              "elastodyn without --tip-radius: exit 2 (%s)" % err.strip())

        # CSV from stdin
        text = b"# stations\nr [m], mass_per_length [kg/m], EI_flap [N m^2], EI_edge [N m^2]\n" \
               b"1, 50, 1e7, 2e7\n6, 10, 1e6, 2e6\n"
        rc, out, err = run(exe, ["import", "csv", "-"], stdin=text)
        req = json.loads(out) if rc == 0 else {}
        check(rc == 0 and req.get("blade", {}).get("hub_radius") == 1.0 and
              req["blade"]["length"] == 5.0, "csv from stdin: hub 1, length 5 (%s)" % err.strip())
        rc, out, err = run(exe, ["import", "csv", "-"], stdin=text.replace(b"[N m^2], EI_edge", b"[MPa], EI_edge"))
        check(rc == 2 and err.strip() == "<stdin>:2: EI_flap: unknown unit [MPa]; expected [N m^2] (SI)",
              "csv unknown unit: exit 2 (%s)" % err.strip())

        # I/O and usage
        rc, out, err = run(exe, ["import", "csv", os.path.join(tmp, "nope.csv")])
        check(rc == 1 and "cannot read" in err, "missing file: exit 1")
        for args, what in ((["import"], "no format"), (["import", "xml", "f"], "unknown format"),
                           (["import", "csv"], "no file"), (["import", "csv", "a", "b"], "two files"),
                           (["import", "csv", "a", "--tip-radius"], "option without value"),
                           (["import", "csv", "a", "--tip-radius", "x"], "non-numeric option"),
                           (["import", "csv", "a", "--bogus"], "unknown option")):
            rc, out, err = run(exe, args)
            check(rc == 64 and out == "" and "usage:" in err, "usage: %s -> exit 64 (got %d)" % (what, rc))
        rc, out, err = run(exe, ["--help"])
        check(rc == 0 and "import FORMAT FILE" in out, "--help mentions import")
        for args, what in ((["import", "bmodes", test02, "--bmodes-mesh", "0"], "--bmodes-mesh 0"),
                           (["import", "bmodes", test02, "--bmodes-mesh", "2.5"], "--bmodes-mesh 2.5"),
                           (["import", "csv", "a", "--bmodes-mesh", "8"], "--bmodes-mesh on csv")):
            rc, out, err = run(exe, args)
            check(rc == 64 and out == "" and "usage:" in err, "usage: %s -> exit 64 (got %d)" % (what, rc))
        bmodes_own_model(exe, ref, tmp)
        extreme_numbers_exit_2(exe, bm, tmp)
        sec_props_file_confined(exe, bm, tmp)
        csv_bom(exe, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print("%d failure(s)" % len(FAILURES))
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
