#!/usr/bin/env python3
"""POST /v1/import/{bmodes|elastodyn|csv} against the real daemon (server/DAEMON.md).

Usage: import_test.py SPINMODALD REFERENCE_BLADES_DIR

Starts one daemon (harness: daemon.py) with a small --max-body and checks: the
BModes JSON body {"main", "sec_props"} gives the import document (200); elastodyn
and csv take the raw text or JSON {"main"}, with ?tip_radius= etc.; a main ElastoDyn file
takes the files it names as JSON {"main", "files": {NAME: text}}; a refused file is
a 422 problem document naming file, line and field; wrong media type 415, malformed
JSON 400, bad query 400, body over --max-body 413, unknown format 404, GET 405;
--auth-reads makes the token necessary, as for /v1/validate; nothing is stored (the
job list stays empty).
"""
import json
import os
import shutil
import sys
import tempfile

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


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def scenario(exe, ref, tmp):
    bm = os.path.join(ref, "bmodes_certtest")
    main = read(os.path.join(bm, "Test02_blade_with_tip_mass.bmi"))
    sec = read(os.path.join(bm, "blade_sec_props.dat"))
    with open(os.path.join(ref, "elastodyn", "NRELOffshrBsline5MW_Blade.dat"), "rb") as f:
        ed = f.read()
    d = dm.Daemon(exe, tmp, ["--workers", "1", "--max-body", "200000"], name="imp")
    d.start()
    try:
        r = d.post("/v1/import/bmodes", {"main": main, "sec_props": sec})
        doc = r.json() or {}
        blade = doc.get("request", {}).get("blade", {})
        check(r.status == 200 and r.headers.get("Content-Type") == "application/json",
              "bmodes: 200 application/json (got %s)" % r.status)
        check(set(doc) == {"request", "warnings", "input_warnings", "source"},
              "bmodes: request, warnings, input_warnings, source")
        check(blade.get("length") == 33.25 and blade.get("hub_radius") == 1.75 and
              len(blade.get("stations", [])) == 21, "bmodes: length, hub radius, 21 stations")
        check(blade.get("stations", [{}] * 3)[2].get("mass_per_length") == 181.672,
              "bmodes: station 3 mass 181.672")
        check(blade.get("tip_mass", {}).get("inertia") == [2.5, 1.75, 10.0], "bmodes: tip inertia")
        check(doc.get("request", {}).get("analysis", {}).get("rpm") == [60.0], "bmodes: rpm [60]")

        bad = "\n".join(l.replace("2611.3E+06", "abc") if i == 7 else l
                        for i, l in enumerate(sec.split("\n")))
        r = d.post("/v1/import/bmodes", {"main": main, "sec_props": bad})
        p = r.json() or {}
        want = 'blade_sec_props.dat:8: axial_stff: not a number ("abc")'
        check(r.status == 422 and r.headers.get("Content-Type") == "application/problem+json",
              "bad section file: 422 problem+json (got %s)" % r.status)
        check(p.get("detail") == want and p.get("file") == "blade_sec_props.dat" and
              p.get("line") == 8 and p.get("field") == "axial_stff",
              "bad section file: detail, file, line, field (%s)" % p)
        check(p.get("errors") == [{"pointer": "/sec_props", "message": want}],
              "bad section file: errors[0] points at /sec_props")
        r = d.post("/v1/import/bmodes", {"main": main.replace("1         beam_type", "2         beam_type"),
                                         "sec_props": sec, "name": "tower.bmi"})
        p = r.json() or {}
        check(r.status == 422 and str(p.get("detail", "")).startswith(
              "tower.bmi:51: tow_support: missing: beam_type (line 6) is 2 (tower)")
              and p["errors"][0]["pointer"] == "/main",
              "a blade's file marked as a tower: 422 naming tower.bmi:51 and line 6 (%s)"
              % p.get("detail"))
        # a real tower (BModes CertTest Test03, tow_support 0) imports as the tower form
        r = d.post("/v1/import/bmodes", {"main": read(os.path.join(bm, "Test03_tower.bmi")),
                                         "sec_props": read(os.path.join(bm, "tower_sec_props.dat"))})
        tower = ((r.json() or {}).get("request") or {}).get("tower") or {}
        check(r.status == 200 and tower.get("height", 0) > 0 and tower.get("stations"),
              "Test03 tower: 200 with the tower form (got %s, keys %s)"
              % (r.status, sorted(tower)[:6]))
        r = d.post("/v1/import/bmodes", {"main": main})
        check(r.status == 400 and (r.json() or {}).get("errors", [{}])[0].get("pointer") == "/sec_props",
              "bmodes without sec_props: 400 /sec_props (got %s)" % r.status)
        r = d.post("/v1/import/bmodes", {"main": main, "sec_props": sec, "extra": "x"})
        check(r.status == 400, "bmodes unknown key: 400 (got %s)" % r.status)
        r = d.request("POST", "/v1/import/bmodes", body=b"{\"main\": ", headers={"Content-Type": "application/json"})
        check(r.status == 400, "malformed JSON: 400 (got %s)" % r.status)
        r = d.request("POST", "/v1/import/bmodes", body=main.encode(), headers={"Content-Type": "text/plain"})
        check(r.status == 415, "bmodes as text/plain: 415 (got %s)" % r.status)

        # ElastoDyn: raw text with query parameters, or JSON {"main"}
        r = d.request("POST", "/v1/import/elastodyn?tip_radius=63&hub_radius=1.5&rpm=12.1&name=5MW.dat",
                      body=ed, headers={"Content-Type": "text/plain"})
        doc = r.json() or {}
        blade = doc.get("request", {}).get("blade", {})
        check(r.status == 200 and blade.get("length") == 61.5 and len(blade.get("stations", [])) == 49,
              "elastodyn raw: 200, length 61.5, 49 stations (got %s)" % r.status)
        check(doc.get("source", {}).get("file") == "5MW.dat" and len(doc.get("warnings", [])) == 2,
              "elastodyn: ?name= and 2 warnings")
        check([w.get("pointer") for w in doc.get("input_warnings", [])] ==
              ["/blade/section/EA", "/blade/section/GJ"],
              "elastodyn: input_warnings {pointer, message} at the assumed EA and GJ (issue 26)")
        r = d.post("/v1/import/elastodyn", {"main": ed.decode()})
        p = r.json() or {}
        check(r.status == 422 and p.get("field") == "tip_radius" and
              p.get("errors", [{}])[0].get("pointer") == "/query/tip_radius",
              "elastodyn without tip_radius: 422 /query/tip_radius (got %s)" % r.status)
        r = d.request("POST", "/v1/import/elastodyn?tip_radius=abc", body=ed,
                      headers={"Content-Type": "text/plain"})
        check(r.status == 400, "bad ?tip_radius: 400 (got %s)" % r.status)

        # a main ElastoDyn file with the files it names (TwrFile, BldFile) in "files"
        edd = os.path.join(ref, "elastodyn")
        edmain = read(os.path.join(edd, "NRELOffshrBsline5MW_Onshore_ElastoDyn.dat"))
        twr = "NRELOffshrBsline5MW_Onshore_ElastoDyn_Tower.dat"
        bld = "NRELOffshrBsline5MW_Blade.dat"
        files = {twr: read(os.path.join(edd, twr)), bld: read(os.path.join(edd, bld))}
        r = d.post("/v1/import/elastodyn", {"main": edmain, "files": files, "name": "5MW.dat"})
        tw = (r.json() or {}).get("request", {}).get("tower", {})
        check(r.status == 200 and tw.get("height") == 87.6 and len(tw.get("stations", [])) == 11
              and 3.49e5 < tw.get("top_mass", {}).get("mass", 0) < 3.50e5,
              "elastodyn main file with its files: 200, the tower form (87.6 m, 11 stations, "
              "top mass %s kg) (got %s)" % (tw.get("top_mass", {}).get("mass"), r.status))
        r = d.post("/v1/import/elastodyn", {"main": edmain, "files": {twr: files[twr]},
                                            "name": "5MW.dat"})
        p = r.json() or {}
        check(r.status == 422 and p.get("field") == "BldFile(1)" and bld in p.get("detail", "")
              and p.get("errors", [{}])[0].get("pointer") == "/main",
              "elastodyn main file without its blade file: 422 at /main, BldFile(1) (%s)"
              % p.get("detail"))
        r = d.post("/v1/import/elastodyn", {"main": edmain, "files": [files[twr]]})
        check(r.status == 400 and ((r.json() or {}).get("errors") or [{}])[0].get("pointer")
              == "/files", "elastodyn \"files\" not an object: 400 at /files (got %s)" % r.status)
        r = d.post("/v1/import/bmodes", {"main": main, "sec_props": sec, "files": {}})
        check(r.status == 400, "bmodes takes no \"files\": 400 (got %s)" % r.status)

        # CSV
        text = b"s,mass_per_length,EI_flap,EI_edge,GJ,EA\n0,10,1e6,2e6,1e5,1e8\n1,5,1e5,2e5,1e4,5e7\n"
        r = d.request("POST", "/v1/import/csv?tip_radius=10", body=text, headers={"Content-Type": "text/csv"})
        doc = r.json() or {}
        check(r.status == 200 and doc.get("request", {}).get("blade", {}).get("length") == 10.0,
              "csv: 200, length 10 (got %s)" % r.status)
        r = d.request("POST", "/v1/import/csv?tip_radius=10", body=text.replace(b"0,10,", b"0,0,"),
                      headers={"Content-Type": "text/csv"})
        p = r.json() or {}
        check(r.status == 422 and p.get("detail") == "stations.csv:2: mass_per_length: must be > 0 (0)",
              "csv zero mass: 422 (%s)" % p.get("detail"))
        r = d.request("POST", "/v1/import/csv", body=text, headers={"Content-Type": "image/png"})
        check(r.status == 415, "csv as image/png: 415 (got %s)" % r.status)

        # limits and routes
        r = d.request("POST", "/v1/import/csv", body=b"x" * 200001, headers={"Content-Type": "text/csv"})
        check(r.status == 413, "body over --max-body: 413 (got %s)" % r.status)
        r = d.request("POST", "/v1/import/xml", body=b"x", headers={"Content-Type": "text/plain"})
        check(r.status == 404, "unknown format: 404 (got %s)" % r.status)
        r = d.request("GET", "/v1/import/csv")
        check(r.status == 405 and "POST" in (r.headers.get("Allow") or ""), "GET: 405 Allow POST")
        r = d.request("GET", "/v1/analyses")
        check(r.status == 200 and (r.json() or {}).get("items") == [], "imports queue no jobs")
    finally:
        d.stop()

    # --auth-reads: the token is needed, as for /v1/validate
    tok = os.path.join(tmp, "token")
    with open(tok, "w") as f:
        f.write("s3cret\n")
    d = dm.Daemon(exe, tmp, ["--workers", "1", "--token-file", tok, "--auth-reads", "yes"], name="auth")
    d.start()
    try:
        r = d.post("/v1/import/bmodes", {"main": main, "sec_props": sec})
        check(r.status == 401, "--auth-reads without token: 401 (got %s)" % r.status)
        r = d.post("/v1/import/bmodes", {"main": main, "sec_props": sec},
                   headers={"Authorization": "Bearer s3cret"})
        check(r.status == 200, "--auth-reads with token: 200 (got %s)" % r.status)
    finally:
        d.stop()
    d = dm.Daemon(exe, tmp, ["--workers", "1", "--token-file", tok], name="tok")
    d.start()
    try:
        r = d.post("/v1/import/bmodes", {"main": main, "sec_props": sec})
        check(r.status == 200, "token without --auth-reads: import needs none (got %s)" % r.status)
    finally:
        d.stop()


def main(argv):
    if len(argv) != 3:
        print("usage: import_test.py SPINMODALD REFERENCE_BLADES_DIR", file=sys.stderr)
        return 64
    exe, ref = os.path.abspath(argv[1]), os.path.abspath(argv[2])
    ts.calibrate(daemon_exe=exe, quiet=True)
    tmp = tempfile.mkdtemp(prefix="spinmodal-e2e-import-")
    try:
        scenario(exe, ref, tmp)
    except Exception as e:  # a harness failure is a test failure with its cause
        check(False, "raised %r" % (e,))
        raise
    finally:
        if not FAILURES:
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            print("kept %s" % tmp)
    print("%d failure(s)" % len(FAILURES))
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
