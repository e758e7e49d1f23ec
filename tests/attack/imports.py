"""Hostile blade files for POST /v1/import/{format} and `spinmodal import` (attack.py,
category 'imports'; issue 23 items 4, 5, 6 and 8).

Daemon: numbers that are merely extreme (1.7976931348623157e308 in a file or a query, which
rounds to infinity at the document's 15 digits; rot_rpm x rpm_mult 1e200 x 1e200; an EI that
makes the assumed EA or GJ overflow; radii near 1e308 that make it underflow to 0), BModes
el_loc out of order or outside [0, 1], text that is UTF-16 (with or without its byte-order
mark) or holds NUL bytes, blades of 2.2e-16 m.  Every one must be a 422 problem document naming
the line and field (or a 400 for a query that is not a number), never a 5xx ("503 out of memory,
retry later" was the answer to eleven of them) and never a 200; a CSV with a UTF-8 byte-order
mark must be the same 200 as without it.

CLI (when the spinmodal binary sits beside spinmodald, or SPINMODAL_TEST_CLI names it): a .bmi
whose sec_props_file is '../../../../etc/passwd', '/etc/passwd' or '-' must exit 2 without
reading it (no line of the file in the message, standard input not read).
"""
import json
import os
import subprocess
import time
from urllib.parse import quote

from common import is_problem, livez, outcome_of, timescale

HERE = os.path.dirname(os.path.abspath(__file__))
REF = os.path.join(HERE, os.pardir, "reference", "blades")
BIG = "1.7976931348623157e308"
OK_CSV = "s,mass_per_length,EI_flap,EI_edge\n0,1,1,1\n1,1,1,1\n"


def _read(rel):
    with open(os.path.join(REF, rel)) as f:
        return f.read()


def _line(text, n, old, new):
    lines = text.split("\n")
    assert old in lines[n - 1], (n, old)
    lines[n - 1] = lines[n - 1].replace(old, new, 1)
    return "\n".join(lines)


def cases():
    """(name, format, query, body: str/bytes = the file, dict = JSON, statuses, (line, field))."""
    bmi = _read("bmodes_certtest/Test01_nonunif_blade.bmi")
    sec = _read("bmodes_certtest/blade_sec_props.dat")
    ed = _read("elastodyn/NRELOffshrBsline5MW_Blade.dat")

    def bm(main=None, sec_props=None):
        return {"main": main or bmi, "sec_props": sec_props or sec}

    return [
        # item 4: extreme numbers
        ("csv EI_flap 1e305, EA assumed", "csv", "?tip_radius=20",
         "s,mass_per_length,EI_flap,EI_edge\n0,1,1e305,1\n1,1,1,1\n", (422,), (2, "EI_flap")),
        ("csv EI_edge 1e308, GJ assumed", "csv", "?tip_radius=20",
         "s,mass_per_length,EI_flap,EI_edge,EA\n0,1,1,1,1\n1,1,1,1e308,1\n", (422,), (3, "EI_edge")),
        ("csv ?tip_radius=DBL_MAX", "csv", "?tip_radius=" + BIG, OK_CSV, (422,), (0, "tip_radius")),
        ("csv ?rpm=DBL_MAX", "csv", "?tip_radius=20&rpm=" + BIG, OK_CSV, (422,), (0, "rpm")),
        ("csv ?hub_radius=DBL_MAX", "csv", "?tip_radius=20&hub_radius=" + BIG, OK_CSV, (422,),
         (0, "hub_radius")),
        ("csv ?rpm=1e999", "csv", "?tip_radius=20&rpm=1e999", OK_CSV, (400,), None),
        ("csv value DBL_MAX", "csv", "?tip_radius=20",
         "s,mass_per_length,EI_flap,EI_edge,EA,GJ\n0,1,1,1,1,1\n1," + BIG + ",1,1,1,1\n", (422,),
         (3, "mass_per_length")),
        ("elastodyn ?tip_radius=DBL_MAX", "elastodyn", "?tip_radius=" + BIG, ed, (422,),
         (0, "tip_radius")),
        ("elastodyn ?rpm=DBL_MAX", "elastodyn", "?tip_radius=63&rpm=" + BIG, ed, (422,), (0, "rpm")),
        ("bmodes ?rpm=DBL_MAX", "bmodes", "?rpm=" + BIG, bm(), (422,), (0, "rpm")),
        ("bmodes rot_rpm 1e200 x rpm_mult 1e200", "bmodes", "",
         bm(_line(_line(bmi, 7, "60.0", "1e200"), 8, "1.0 ", "1e200 ")), (422,), (8, "rpm_mult")),
        ("bmodes el_loc DBL_MAX", "bmodes", "", bm(_line(bmi, 48, "0.90", BIG)), (422,),
         (48, "el_loc")),
        ("bmodes radius DBL_MAX", "bmodes", "", bm(_line(bmi, 9, "35.0", BIG)), (422,),
         (9, "radius")),
        ("bmodes radius DBL_MAX, bmodes_mesh", "bmodes", "?bmodes_mesh=2",
         bm(_line(bmi, 9, "35.0", BIG)), (422,), (9, "radius")),
        ("bmodes axial_stff DBL_MAX", "bmodes", "", bm(sec_props=_line(sec, 8, "2611.3E+06", BIG)),
         (422,), (8, "axial_stff")),
        ("bmodes axial_stff 1e300 x axial_stff_mult 1e10", "bmodes", "",
         bm(_line(bmi, 40, "1.0 ", "1e10 "), _line(sec, 8, "2611.3E+06", "1e300")), (422,),
         (8, "axial_stff")),
        ("bmodes tip_mass DBL_MAX", "bmodes", "", bm(_line(bmi, 19, "0. ", BIG + " ")), (422,),
         (19, "tip_mass")),
        # item 5: el_loc
        ("bmodes el_loc unsorted, bmodes_mesh", "bmodes", "?bmodes_mesh=4",
         bm(_line(bmi, 48, "0.08  0.16", "0.16  0.08")), (422,), (48, "el_loc")),
        ("bmodes el_loc unsorted", "bmodes", "", bm(_line(bmi, 48, "0.08  0.16", "0.16  0.08")),
         (422,), (48, "el_loc")),
        ("bmodes el_loc negative", "bmodes", "", bm(_line(bmi, 48, "0.08", "-0.08")), (422,),
         (48, "el_loc")),
        ("bmodes el_loc above 1", "bmodes", "", bm(_line(bmi, 48, "0.90", "1.5")), (422,),
         (48, "el_loc")),
        # item 6: encodings and radii
        ("csv UTF-16 LE with BOM", "csv", "?tip_radius=20", OK_CSV.encode("utf-16"), (422,),
         (1, "encoding")),
        ("csv UTF-16 BE with BOM", "csv", "?tip_radius=20",
         b"\xfe\xff" + OK_CSV.encode("utf-16-be"), (422,), (1, "encoding")),
        ("csv UTF-16 LE without BOM", "csv", "?tip_radius=20", OK_CSV.encode("utf-16-le"), (422,),
         (1, "encoding")),
        # JSON strings are UTF-8 without NUL (jansson refuses \u0000: 400 before the importer)
        ("csv NUL in a JSON main", "csv", "?tip_radius=20", {"main": OK_CSV + "\0"}, (400,), None),
        ("bmodes UTF-16 sec_props (NUL bytes)", "bmodes", "",
         bm(sec_props=sec.encode("utf-16-le").decode("latin-1")), (400,), None),
        ("elastodyn UTF-16 file", "elastodyn", "?tip_radius=63", ed.encode("utf-16"), (422,),
         (1, "encoding")),
        ("csv r near 1e308 (EA 0)", "csv", "",
         "r,mass_per_length,EI_flap,EI_edge\n1e308,1,1,1\n1.7e308,1,1,1\n", (422,), (3, "r")),
        ("csv r 1 -> 1+2e-16", "csv", "",
         "r,mass_per_length,EI_flap,EI_edge\n1,1,1,1\n1.0000000000000002,1,1,1\n", (422,), (3, "r")),
        ("csv ?tip_radius=1e-300", "csv", "?tip_radius=1e-300", OK_CSV, (422,), (0, "tip_radius")),
        ("bmodes radius 1+1e-15 over hub_rad 1", "bmodes", "",
         bm(_line(_line(bmi, 9, "35.0", "1.000000000000001"), 10, "1.75", "1")), (422,),
         (10, "hub_rad")),
    ]


def _send(d, fmt, query, body, timeout):
    path = "/v1/import/" + fmt + query.replace("+", quote("+"))
    if isinstance(body, dict):
        return d.request("POST", path, body=json.dumps(body),
                         headers={"Content-Type": "application/json"}, timeout=timeout)
    if isinstance(body, str):
        body = body.encode()
    return d.request("POST", path, body=body, headers={"Content-Type": "text/csv"},
                     timeout=timeout)


def run(d, tally, category="imports"):
    for name, fmt, query, body, expect, where in cases():
        t0 = time.monotonic()
        try:
            r = _send(d, fmt, query, body, timescale.budget(30))
        except OSError as e:
            tally.add(category, "connection error")
            tally.broken(category, "%s: %r" % (name, e))
            continue
        took = time.monotonic() - t0
        p = r.json() if is_problem(r) else {}
        p = p if isinstance(p, dict) else {}
        good = r.status in expect and is_problem(r)
        if where and r.status == 422:
            good = good and p.get("line") == where[0] and p.get("field") == where[1]
        tally.add(category, "%s %s" % (outcome_of(r), "as expected" if good else "UNEXPECTED"))
        tally.check(not (isinstance(r.status, int) and r.status >= 500), category,
                    "%s: never a 5xx (got %s %s)" % (name, outcome_of(r), r.text(160)))
        tally.check(good, category, "%s: %s%s (got %s, %.2f s: %s)"
                    % (name, "/".join(map(str, expect)),
                       " at line %d, field %s" % where if where else "", outcome_of(r), took,
                       p.get("detail") or r.text(160)))
        if not livez(d):
            tally.broken(category, "after %s: /livez does not answer (alive: %s)"
                         % (name, d.alive()))
            if not d.alive():
                return
    plain = _send(d, "csv", "?tip_radius=20", OK_CSV, timescale.budget(30))
    bom = _send(d, "csv", "?tip_radius=20", b"\xef\xbb\xbf" + OK_CSV.encode(), timescale.budget(30))
    good = plain.status == bom.status == 200 and plain.body == bom.body
    tally.add(category, "%s %s" % (outcome_of(bom), "as expected" if good else "UNEXPECTED"))
    tally.check(good, category, "csv with a UTF-8 BOM: the same 200 as without (got %s: %s)"
                % (outcome_of(bom), bom.text(160)))


def cli(exe, tmp, tally, category="imports"):
    """`spinmodal import bmodes` with a .bmi whose sec_props_file leaves its folder."""
    cli_exe = os.environ.get("SPINMODAL_TEST_CLI") or os.path.join(os.path.dirname(exe),
                                                                     "spinmodal")
    if not os.access(cli_exe, os.X_OK):
        tally.skip("imports: the CLI's sec_props_file", "no spinmodal beside %s" % exe)
        return
    bmi = _read("bmodes_certtest/Test01_nonunif_blade.bmi")
    sub = os.path.join(tmp, "bmi", "sub")
    os.makedirs(sub)
    secret = os.path.join(tmp, "bmi", "secret.dat")
    with open(secret, "w") as f:
        f.write("title\nSECRET-LINE-TWO\n")
    names = ["../" * 16 + "etc/passwd", "/etc/passwd", "../secret.dat", secret,
             "inner/../../secret.dat", "-"]
    for name in names:
        path = os.path.join(sub, "p.bmi")
        with open(path, "w") as f:
            f.write(bmi.replace("'blade_sec_props.dat'", "'%s'" % name))
        p = subprocess.run([cli_exe, "import", "bmodes", "p.bmi"], cwd=sub, capture_output=True,
                           input=b"title\n21\n", timeout=timescale.budget(30))
        err = p.stderr.decode("utf-8", "replace")
        good = (p.returncode == 2 and p.stdout == b"" and ":31: sec_props_file:" in err and
                "SECRET" not in err and "root:" not in err and "daemon:" not in err)
        tally.add(category, "cli exit %d %s" % (p.returncode, "as expected" if good else
                                                "UNEXPECTED"))
        tally.check(good, category, "cli sec_props_file %r: exit 2 without reading it (got %d: %s)"
                    % (name, p.returncode, err.strip()[:200]))
