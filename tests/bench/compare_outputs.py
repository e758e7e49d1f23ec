#!/usr/bin/env python3
"""tests/bench/compare_outputs.py — what a speed change did to the answers (issue 27's "planar
bytes unchanged, no frequency moves by more than 1e-10").  A tool, not a test: it prints.

    python3 tests/bench/compare_outputs.py OLD_CLI NEW_CLI [FILE...]

Solves every request of examples/ and tests/codec/cases/ (or the FILEs), plus generated tree-path
requests (examples/ and the codec cases have none: planar angled beam at 599 and 1799
coordinates with and without Coriolis, spatial precone blade at 288 coordinates over 21 speeds
and at 1200 coordinates) and the one-frame models of sweep_cases.large_frames (planar 500 and 664
coordinates, spatial 360), with both CLIs, as JSON and as --csv, with OPENBLAS_NUM_THREADS=1.
It compares the outputs byte for byte without timing_ms, the solver version and "seconds", and
for each request whose JSON differs prints the largest change of a frequency or eigenvalue
(the imaginary part: a frequency; and the real part: a growth or decay rate, both relative to the
larger part of the eigenvalue), of a mode shape (absolute: shapes are normalised to
1) and of the equilibrium's nodes (absolute, m and rad).  Last line: how many planar requests
differ (must be 0) and the largest relative frequency change of the spatial ones.
"""
import glob
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sweep_cases import large_frames, precone_blade  # noqa: E402


def generated(tmp):
    out = []
    beam = json.load(open(os.path.join(ROOT, "examples", "angled-beam-90.json")))
    for ne, cor in ((100, True), (100, False), (300, True)):
        r = json.loads(json.dumps(beam))
        for mb in r["structure"]["members"]:
            mb["elements"] = ne
        r["analysis"].update({"omega": [0, 5, 10, 20], "coriolis": cor, "modes": 4})
        out.append(("planar-tree-%d-%s.json" % (6 * ne - 1, "c" if cor else "n"), r))
    out.append(("spatial-tree-288.json", precone_blade(mode_shapes=True)))
    out.append(("spatial-tree-1200.json", precone_blade(200, [0.0, 10.0, 20.0], 6, mode_shapes=True)))
    out += [(name + ".json", r) for name, r in large_frames(ROOT)]
    files = []
    for name, r in out:
        path = os.path.join(tmp, name)
        json.dump(r, open(path, "w"))
        files.append(path)
    return files


def norm(s):
    s = re.sub(r'"timing_ms":\{[^}]*\}', "", s)
    s = re.sub(r'"version":"[^"]*"', "", s)
    return re.sub(r'"seconds":[0-9.e+-]+', "", s)


def walk(a, b, path, acc):
    if isinstance(a, dict) and isinstance(b, dict):
        if a.keys() != b.keys():
            acc["struct"].append(path)
            return
        for k in a:
            walk(a[k], b[k], path + "/" + k, acc)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            acc["struct"].append(path)
            return
        nums = [x for x in a if isinstance(x, (int, float)) and not isinstance(x, bool)]
        if nums and len(nums) == len(a):
            scale = max(abs(x) for x in nums) or 1.0
            for x, y in zip(a, b):
                if not isinstance(y, (int, float)) or isinstance(y, bool):
                    acc["struct"].append(path)
                    return
                if "/shape/" in path:
                    acc["shape"] = max(acc["shape"], abs(x - y))
                elif "/equilibrium/nodes" in path:
                    acc["nodes"] = max(acc["nodes"], abs(x - y))
            if path.endswith("/eigenvalue") and len(a) == 2:  # [re, im]: rate and frequency
                acc["rate"] = max(acc["rate"], abs(a[0] - b[0]) / scale)
                acc["freq"] = max(acc["freq"], abs(a[1] - b[1]) / scale)
            return
        for i, (x, y) in enumerate(zip(a, b)):
            walk(x, y, "%s/%d" % (path, i), acc)
    elif isinstance(a, (int, float)) and not isinstance(a, bool):
        if not isinstance(b, (int, float)) or isinstance(b, bool):
            acc["struct"].append(path)
        elif "frequency" in path and a != b:
            acc["freq"] = max(acc["freq"], abs(a - b) / max(abs(a), abs(b)))
    elif a != b and not path.endswith("/version"):
        acc["struct"].append(path)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    old, new = sys.argv[1], sys.argv[2]
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    with tempfile.TemporaryDirectory() as tmp:
        files = sys.argv[3:]
        if not files:
            files = sorted(glob.glob(os.path.join(ROOT, "examples", "*.json")) +
                           glob.glob(os.path.join(ROOT, "tests", "codec", "cases", "*", "*.json")))
            files = [f for f in files if not f.endswith(("checks.json", "limits.json", "expect.json"))]
            files += generated(tmp)
        same = total = 0
        planar_diff, worst = [], 0.0
        for f in files:
            name = os.path.relpath(f, ROOT) if f.startswith(ROOT) else os.path.basename(f)
            runs = {}
            for extra in ([], ["--csv"]):
                res = []
                for exe in (old, new):
                    p = subprocess.run([exe, "solve"] + extra + [f], capture_output=True, text=True,
                                       env=env, timeout=600)
                    res.append((p.returncode, norm(p.stdout), norm(p.stderr), p.stdout))
                runs[bool(extra)] = res
                total += 1
                same += res[0][:3] == res[1][:3]
            a, b = runs[False]
            if a[:3] == b[:3] and runs[True][0][:3] == runs[True][1][:3]:
                continue
            try:
                ja, jb = json.loads(a[3]), json.loads(b[3])
            except ValueError:
                print("%-64s differs (exit %d / %d, not JSON)" % (name, a[0], b[0]))
                planar_diff.append(name)
                continue
            for d in (ja, jb):
                d.pop("timing_ms", None)
            spatial = bool(ja.get("model", {}).get("spatial"))
            acc = {"freq": 0.0, "rate": 0.0, "shape": 0.0, "nodes": 0.0, "struct": []}
            walk(ja, jb, "", acc)
            if not spatial:
                planar_diff.append(name)
            else:
                worst = max(worst, acc["freq"])
            print("%-60s %s frequency %.1e  Re %.1e  shape %.1e  nodes %.1e%s" % (
                name, "spatial" if spatial else "PLANAR", acc["freq"], acc["rate"], acc["shape"], acc["nodes"],
                "  other: " + ", ".join(acc["struct"][:3]) if acc["struct"] else ""))
        print("%d of %d outputs byte-identical; planar requests that differ: %d; largest relative "
              "frequency change of a spatial request: %.1e" % (same, total, len(planar_diff), worst))


if __name__ == "__main__":
    main()
