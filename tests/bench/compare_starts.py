#!/usr/bin/env python3
"""tests/bench/compare_starts.py — what a change to the continuation from rest did, over a class
of single-speed requests (issue 27, solver 0.8.5: a spatial start from rest tries one step).
A tool, not a test: it prints.

    python3 tests/bench/compare_starts.py OLD_CLI NEW_CLI [--random N [SEED]]

The requests, one speed each: every example and every reference case of tests/reference/3d
(cases.json, cases_oop.json) at each of its listed speeds (at most 7 of them) and at 3x it;
BModes' CertTest files imported with and without `--bmodes-mesh 1` (by NEW_CLI); the precone
blade of sweep_cases.py at 0.5 to 120 rad/s, and at 192 elements.  Both CLIs solve each with
OPENBLAS_NUM_THREADS=1.  With --random N, N random spatial frames instead (seeded, default
seed 1): one to three members from a hub joint at 0 to 2 m, each in a random direction (outward,
inward, out of the plane, branched from the previous joint or not), random section stiffnesses
over two decades, a tip mass or none, at a random speed of 0.3 to 60 rad/s.  Per spatial request whose Newton iterations or frequencies differ: the
iterations of both, the largest relative change of a frequency, and the wall times (one run
each: indicative only).  Any change of a case's status, stability or number of modes is printed
as DIFFERENT.  Last lines: how many spatial requests take fewer, more and the same iterations,
the totals, and the largest frequency change.
"""
import copy
import glob
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sweep_cases import precone_blade  # noqa: E402

ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1")


def speeds_of(a):
    key = "rpm" if "rpm" in a else "omega"
    sp = a.get(key, [0])
    if isinstance(sp, dict):  # {"from", "to", "steps"}
        sp = [sp["from"] + (sp["to"] - sp["from"]) * i / sp["steps"] for i in range(sp["steps"] + 1)]
    if not isinstance(sp, list):
        sp = [sp]
    return key, sp[:: max(1, len(sp) // 6)]


def requests(new_cli):
    reqs = {}
    for w in [0.5, 1, 2, 5, 10, 15, 20, 30, 40]:
        reqs["precone_%g" % w] = precone_blade(omegas=[w], modes=6)
    for w in [10, 20]:
        reqs["precone192_%g" % w] = precone_blade(elements=192, omegas=[w], modes=6)
    for f in sorted(glob.glob(os.path.join(ROOT, "examples", "*.json"))):
        reqs["ex_" + os.path.basename(f)[:-5]] = json.load(open(f))
    for name in ["cases.json", "cases_oop.json"]:
        for k, v in json.load(open(os.path.join(ROOT, "tests", "reference", "3d", name))).items():
            if isinstance(v, dict) and "request" in v:
                reqs["ref_" + k] = v["request"]
    certs = os.path.join(ROOT, "tests", "reference", "blades", "bmodes_certtest", "Test0*.bmi")
    for b in sorted(glob.glob(certs)):
        for mesh in (["--bmodes-mesh", "1"], []):
            p = subprocess.run([new_cli, "import", "bmodes", b] + mesh, capture_output=True, text=True)
            if p.returncode == 0:
                reqs["bm_" + os.path.basename(b)[:6] + ("m" if mesh else "")] = json.loads(p.stdout)
    out = {}
    for k, r in reqs.items():
        key, sp = speeds_of(r.get("analysis", {}))
        for v in sp:
            for f in (1.0, 3.0):
                if v == 0 and f > 1:
                    continue
                q = copy.deepcopy(r)
                q.setdefault("analysis", {})[key] = [v * f]
                out["%s_%s%g" % (k, key, v * f)] = q
    return out


def random_requests(n, seed):
    import math
    import random
    rnd = random.Random(seed)
    out = {}
    for i in range(n):
        joints = {"H": [rnd.uniform(0, 2), 0.0, 0.0]}
        members, names = [], ["H"]
        for j in range(rnd.randint(1, 3)):
            frm = names[-1] if j == 0 or rnd.random() < 0.7 else rnd.choice(names)
            th, ph = rnd.uniform(-math.pi, math.pi), rnd.uniform(-math.pi / 2, math.pi / 2)
            if j == 0 and rnd.random() < 0.6:  # mostly outward first
                th, ph = rnd.uniform(-0.5, 0.5), rnd.uniform(-0.5, 0.5)
            ln = rnd.uniform(0.5, 5)
            x = joints[frm]
            to = "J%d" % (j + 1)
            joints[to] = [x[0] + ln * math.cos(ph) * math.cos(th), x[1] + ln * math.cos(ph) * math.sin(th),
                          x[2] + ln * math.sin(ph)]
            names.append(to)
            members.append({"id": "m%d" % j, "from": frm, "to": to, "section": "s%d" % j,
                            "elements": rnd.randint(4, 16)})
        sections = {}
        for j in range(len(members)):
            ei = 10 ** rnd.uniform(2, 4)
            sections["s%d" % j] = {"EA": ei * 10 ** rnd.uniform(3.5, 4.5), "EI_flap": ei,
                                   "EI_edge": ei * rnd.uniform(1, 10), "GJ": ei * rnd.uniform(0.5, 2),
                                   "mass_per_length": rnd.uniform(0.5, 5), "flap_inertia": 1e-4,
                                   "edge_inertia": 9e-4}
        st = {"joints": joints, "sections": sections, "members": members, "clamp": "H"}
        if rnd.random() < 0.4:
            st["point_masses"] = [{"joint": names[-1], "mass": rnd.uniform(0.1, 3)}]
        w = round(10 ** rnd.uniform(math.log10(0.3), math.log10(60)), 3)
        out["random%03d_omega%g" % (i, w)] = {"structure": st, "frames": "per_element",
                                              "analysis": {"omega": [w], "modes": 4}}
    return out


def solve(cli, path):
    t = time.time()
    p = subprocess.run([cli, "solve", path, "--threads", "1"], capture_output=True, text=True, env=ENV)
    t = time.time() - t
    try:
        r = json.loads(p.stdout)
    except ValueError:
        return {"error": p.stderr[-300:], "t": t}
    c = r["cases"][0]
    e = c.get("equilibrium", {})
    return {"spatial": r["model"].get("spatial"), "it": e.get("iterations"), "t": t,
            "ev": [m["eigenvalue"] for m in c.get("modes", [])],
            "other": (c.get("status"), json.dumps(c.get("stability"), sort_keys=True), e.get("converged"))}


def main():
    if len(sys.argv) not in (3, 5, 6) or (len(sys.argv) > 3 and sys.argv[3] != "--random"):
        sys.exit(__doc__)
    old, new = (os.path.abspath(x) for x in sys.argv[1:3])
    fewer = more = same = 0
    tot = [0, 0]
    worst, worst_k = 0.0, ""
    with tempfile.TemporaryDirectory() as tmp:
        reqs = (random_requests(int(sys.argv[4]), int(sys.argv[5]) if len(sys.argv) > 5 else 1)
                if len(sys.argv) > 3 else requests(new))
        for k in sorted(reqs):
            path = os.path.join(tmp, k + ".json")
            json.dump(reqs[k], open(path, "w"))
            a, b = solve(old, path), solve(new, path)
            if "error" in a or "error" in b:
                print("%-40s ERROR %s | %s" % (k, a.get("error", ""), b.get("error", "")))
                continue
            if a["other"] != b["other"] or len(a["ev"]) != len(b["ev"]):
                print("%-40s DIFFERENT %s -> %s, %d -> %d modes" % (k, a["other"], b["other"],
                                                                    len(a["ev"]), len(b["ev"])))
            d = 0.0
            for x, y in zip(a["ev"], b["ev"]):
                scale = max(abs(x[0]), abs(x[1])) or 1.0
                d = max(d, abs(x[0] - y[0]) / scale, abs(x[1] - y[1]) / scale)
            if d > worst:
                worst, worst_k = d, k
            if not a["spatial"] or a["it"] is None or b["it"] is None:
                continue
            tot[0] += a["it"]
            tot[1] += b["it"]
            fewer += b["it"] < a["it"]
            more += b["it"] > a["it"]
            same += b["it"] == a["it"]
            if a["it"] != b["it"] or d > 0:
                print("%-40s iterations %4d -> %4d  frequency %.1e  %.0f -> %.0f ms"
                      % (k, a["it"], b["it"], d, 1e3 * a["t"], 1e3 * b["t"]))
    print("spatial requests: %d fewer iterations, %d more, %d the same; %d -> %d in all"
          % (fewer, more, same, tot[0], tot[1]))
    print("largest relative change of an eigenvalue: %.1e (%s)" % (worst, worst_k or "none"))


if __name__ == "__main__":
    main()
