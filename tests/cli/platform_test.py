#!/usr/bin/env python3
"""A free base through the CLI: elastic clamp and floating platform (DESIGN.md 8.6; issue 25).

Usage: platform_test.py SPINMODAL REFERENCE_DIR

- BModes' OC3 Hywind example (old-NWTC/BModes docs/examples/OC3Hywind.bmi, tow_support 2,
  hub_conn 2) through `import bmodes --bmodes-mesh 1` against BModes v3.00 run by us on the same
  deck (tests/reference/bmodes_offshore/oc3hywind_frequencies.csv, its provenance in the header):
  all 20 modes within 0.5 % (the platform's six rigid-body modes and the tower's bending).
- The platform's rigid-body frequencies by hand: a stiff, light mast on a platform whose
  matrices are given about points below the clamp joint (mass about its c.m., the others about
  a reference point).  Carried to the joint, heave and yaw stand alone and surge-pitch and
  sway-roll are 2x2 problems det(K - w^2 M) = 0, the mast's lumped masses added as rigid
  masses (sum m, sum m y, sum m y^2): all six frequencies to 1e-5.
- An elastic clamp with the platform's matrices carried to the joint gives the same modes.
- The tower form's platform (tower axes fa, ss, up) equals the structure form's in hub axes
  (fa = z, ss = x, up = y).
- Refusals with pointers: a speed other than 0, "clamp": null without a platform, a planar
  structure on a free base, a negative mass; hub_conn 3 without a platform in a .bmi
  (file:line:field); a direction held twice.
- BModes' CS_Monopile example (docs/examples/CS_Monopile.bmi, hub_conn 3: the base held in heave
  and yaw, free laterally on the mudline's 6x6 soil springs) through `--bmodes-mesh 1` against
  BModes v3.00 run by us (tests/reference/bmodes_offshore/cs_monopile_frequencies.csv): modes
  1-10 within 0.5 %, all 20 within 1 %.
"""
import copy
import csv
import json
import math
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
    p = subprocess.run([exe] + args, capture_output=True, text=True, cwd=cwd, input=stdin)
    return p.returncode, p.stdout, p.stderr


def solve_doc(exe, req):
    rc, out, err = run(exe, ["solve", "-"], stdin=json.dumps(req))
    try:
        return rc, json.loads(out or err)  # a 422 document comes on stderr
    except ValueError:
        return rc, {"errors": [{"pointer": "?", "message": err}]}


def freqs(exe, req, name):
    rc, d = solve_doc(exe, req)
    if not check(rc == 0 and "cases" in d, "%s: solved (%s)" % (name, str(d.get("errors"))[:300])):
        return []
    return [m["frequency_hz"] for m in d["cases"][0]["modes"]]


def oc3(exe, ref):
    src = os.path.join(ref, "bmodes_offshore")
    with open(os.path.join(src, "oc3hywind_frequencies.csv")) as f:
        want = [float(r["freq_Hz"]) for r in csv.DictReader(l for l in f if not l.startswith("#"))]
    rc, out, err = run(exe, ["import", "bmodes", "--bmodes-mesh", "1", "OC3Hywind.bmi"], cwd=src)
    if not check(rc == 0, "OC3 Hywind --bmodes-mesh 1 imported (%s)" % err.strip()[-300:]):
        return
    req = json.loads(out)
    req["analysis"]["modes"] = len(want)
    got = freqs(exe, req, "OC3 Hywind")
    if not check(len(got) >= len(want), "OC3 Hywind: %d modes" % len(got)):
        return
    dev = [(g - w) / w for g, w in zip(got, want)]
    for i, (g, w, e) in enumerate(zip(got, want, dev)):
        print("     mode %2d: %.8g Hz, BModes %.8g Hz (%+.4f %%)" % (i + 1, g, w, 100 * e))
    check(max(abs(e) for e in dev) < 5e-3,
          "OC3 Hywind: modes 1-%d within 0.5 %% of BModes (max %.4f %%)"
          % (len(want), 100 * max(abs(e) for e in dev)))


def monopile(exe, ref):
    """BModes' CS_Monopile (hub_conn 3: the base held in heave and yaw on 6x6 soil springs)."""
    src = os.path.join(ref, "bmodes_offshore")
    with open(os.path.join(src, "cs_monopile_frequencies.csv")) as f:
        want = [float(r["freq_Hz"]) for r in csv.DictReader(l for l in f if not l.startswith("#"))]
    rc, out, err = run(exe, ["import", "bmodes", "--bmodes-mesh", "1", "CS_Monopile.bmi"], cwd=src)
    if not check(rc == 0, "CS_Monopile --bmodes-mesh 1 imported (%s)" % err.strip()[-300:]):
        return
    req = json.loads(out)
    check(req["structure"]["platform"].get("held") == ["y", "ry"],
          "CS_Monopile: hub_conn 3 holds the base in heave and yaw (hub y, ry): %s"
          % req["structure"]["platform"].get("held"))
    req["analysis"]["modes"] = len(want)
    got = freqs(exe, req, "CS_Monopile")
    if not check(len(got) >= len(want), "CS_Monopile: %d modes" % len(got)):
        return
    dev = [(g - w) / w for g, w in zip(got, want)]
    for i, (g, w, e) in enumerate(zip(got, want, dev)):
        print("     mode %2d: %.8g Hz, BModes %.8g Hz (%+.4f %%)" % (i + 1, g, w, 100 * e))
    check(max(abs(e) for e in dev[:10]) < 5e-3,
          "CS_Monopile: modes 1-10 within 0.5 %% of BModes (max %.4f %%)"
          % (100 * max(abs(e) for e in dev[:10])))
    check(max(abs(e) for e in dev) < 1e-2,
          "CS_Monopile: modes 1-%d within 1 %% of BModes (max %.4f %%)"
          % (len(want), 100 * max(abs(e) for e in dev)))


# The stiff mast's platform: masses, stiffnesses (hub axes x, y = up, z; rx, ry, rz).
PM, PI = 2.0e5, [3.0e7, 1.0e7, 2.0e7]          # platform mass and inertia about its c.m.
PA = [5.0e4, 2.0e4, 6.0e4]                     # added mass, translations (about the reference)
PK = [4.0e4, 3.0e5, 5.0e4]                     # hydrostatic + mooring, translations
PR = [4.0e8, 2.0e7, 3.0e8]                     # rotations (rx, ry, rz)
DM, DA = 30.0, 20.0                            # c.m. and reference point below the joint
MU, L, NE = 2.0, 10.0, 8                       # the mast: kg/m, m, elements


def diag(t, r):
    return {"translational": t, "rotational": r}


def mast(base):
    return {"structure": dict({
        "joints": {"a": [0, 0, 0], "b": [0, L, 0]},
        "sections": {"s": {"mass_per_length": MU, "EA": 1e13, "EI_flap": 1e13, "EI_edge": 1e13,
                           "GJ": 1e13, "flap_inertia": 1e-9, "edge_inertia": 1e-9}},
        "members": [{"id": "m", "from": "a", "to": "b", "section": "s", "elements": NE}]},
        **base), "analysis": {"omega": 0, "modes": 6}}


def platform_req():
    return mast({"clamp": None, "platform": {
        "joint": "a", "mass": diag([PM] * 3, PI), "added_mass": diag(PA, [0, 0, 0]),
        "hydrostatic": diag([0, PK[1], 0], [PR[0] / 2, 0, PR[2] / 2]),
        "mooring": diag([PK[0], 0, PK[2]], [PR[0] / 2, PR[1], PR[2] / 2]),
        "reference": [0, -DA, 0], "mass_reference": [0, -DM, 0]}})


def pair(k11, k12, k22, m11, m12, m22):
    """The two w^2 of det(K - w^2 M) = 0 for 2x2 K, M."""
    a = m11 * m22 - m12 * m12
    b = -(k11 * m22 + k22 * m11 - 2 * k12 * m12)
    c = k11 * k22 - k12 * k12
    s = math.sqrt(b * b - 4 * a * c)
    return [(-b - s) / (2 * a), (-b + s) / (2 * a)]


def by_hand():
    """The six rigid-body frequencies (Hz) of the platform and the rigid lumped mast."""
    h = L / NE
    ms = [MU * h * (0.5 if i in (0, NE) else 1.0) for i in range(NE + 1)]
    s0 = sum(ms)
    s1 = sum(m * i * h for i, m in enumerate(ms))       # sum m y
    s2 = sum(m * (i * h) ** 2 for i, m in enumerate(ms))  # sum m y^2
    w2 = [PK[1] / (PM + PA[1] + s0), PR[1] / PI[1]]      # heave, yaw
    # surge-pitch (x, rz): a point at y moves by u_x - y theta_z; the platform's points at -d
    w2 += pair(PK[0], PK[0] * DA, PR[2] + PK[0] * DA ** 2,
               PM + PA[0] + s0, PM * DM + PA[0] * DA - s1,
               PI[2] + PM * DM ** 2 + PA[0] * DA ** 2 + s2)
    # sway-roll (z, rx): a point at y moves by u_z + y theta_x
    w2 += pair(PK[2], -PK[2] * DA, PR[0] + PK[2] * DA ** 2,
               PM + PA[2] + s0, -PM * DM - PA[2] * DA + s1,
               PI[0] + PM * DM ** 2 + PA[2] * DA ** 2 + s2)
    return sorted(math.sqrt(x) / (2 * math.pi) for x in w2)


def rigid(exe):
    want = by_hand()
    got = freqs(exe, platform_req(), "stiff mast on a platform")[:6]
    if not check(len(got) == 6, "platform: six modes"):
        return
    dev = max(abs(g - w) / w for g, w in zip(got, want))
    print("     by hand %s Hz" % ", ".join("%.7g" % w for w in want))
    print("     solver  %s Hz" % ", ".join("%.7g" % g for g in got))
    check(dev < 1e-5, "platform: six rigid-body frequencies by hand within 1e-5 (%.2e)" % dev)
    # the same matrices carried to the joint by hand, as an elastic clamp
    k = [[0.0] * 6 for _ in range(6)]
    m = [[0.0] * 6 for _ in range(6)]
    for i in range(3):
        k[i][i], k[i + 3][i + 3] = PK[i], PR[i]
        m[i][i], m[i + 3][i + 3] = PM + PA[i], PI[i]
    k[0][5] = k[5][0] = PK[0] * DA
    k[2][3] = k[3][2] = -PK[2] * DA
    k[5][5] += PK[0] * DA ** 2
    k[3][3] += PK[2] * DA ** 2
    m[0][5] = m[5][0] = PM * DM + PA[0] * DA
    m[2][3] = m[3][2] = -PM * DM - PA[2] * DA
    m[5][5] += PM * DM ** 2 + PA[0] * DA ** 2
    m[3][3] += PM * DM ** 2 + PA[2] * DA ** 2
    el = freqs(exe, mast({"clamp": {"joint": "a", "stiffness": k, "mass": m}}), "elastic clamp")
    check(len(el) == 6 and max(abs(a - b) / b for a, b in zip(el, got)) < 1e-9,
          "elastic clamp with the platform's matrices at the joint: the same six modes (1e-9)")


def tower_form(exe):
    """A stiff tower on a platform with surge-pitch coupling, tower form vs structure form."""
    kt = [[0.0] * 6 for _ in range(6)]  # tower axes (fa, ss, up, r_fa, r_ss, r_up)
    for i, v in enumerate([4e4, 5e4, 3e5, 4e8, 3e8, 2e7]):
        kt[i][i] = v
    kt[0][4] = kt[4][0] = 1.5e6       # fore-aft translation with pitch (rotation about ss)
    mt = copy.deepcopy(kt)
    for i, v in enumerate([2.5e5, 2.6e5, 2.2e5, 3e7, 2e7, 1e7]):
        mt[i][i] = v
    mt[0][4] = mt[4][0] = -1e6
    sec = {"mass_per_length": MU, "EA": 1e13, "EI_flap": 1e13, "EI_edge": 1e13, "GJ": 1e13,
           "flap_inertia": 1e-9, "edge_inertia": 1e-9}
    tw = {"tower": {"height": L, "elements": NE, "section": sec,
                    "platform": {"mass": mt, "mooring": kt, "reference_height": -DA}},
          "analysis": {"omega": 0, "modes": 6}}
    got = freqs(exe, tw, "tower form platform")
    perm = [1, 2, 0]  # hub x = ss, hub y = up, hub z = fa

    def hub(a):
        return [[a[perm[i % 3] + 3 * (i // 3)][perm[j % 3] + 3 * (j // 3)] for j in range(6)]
                for i in range(6)]
    st = {"structure": {
        "joints": {"base": [0, 0, 0], "top": [0, L, 0]}, "sections": {"tower": sec},
        "members": [{"id": "tower", "from": "base", "to": "top", "section": "tower",
                     "elements": NE, "flap_direction": [0, 0, 1]}],
        "clamp": None, "platform": {"joint": "base", "mass": hub(mt), "mooring": hub(kt),
                                    "reference": [0, -DA, 0]}},
        "analysis": {"omega": 0, "modes": 6}}
    want = freqs(exe, st, "structure form platform")
    check(len(got) == 6 and len(want) == 6 and
          max(abs(a - b) / b for a, b in zip(got, want)) < 1e-9,
          "tower form's platform (fa, ss, up) = the structure's in hub axes (1e-9)")


def refusals(exe, ref, tmp):
    req = platform_req()
    req["analysis"]["omega"] = [0, 1]
    rc, d = solve_doc(exe, req)
    e = d.get("errors", [{}])[0]
    check(rc == 2 and e.get("pointer", "").startswith("/analysis/omega") and "at rest" in e.get("message", ""),
          "a free base at speed: 422 at /analysis/omega (%s)" % e)
    req = mast({"clamp": None})
    rc, d = solve_doc(exe, req)
    e = d.get("errors", [{}])[0]
    check(rc == 2 and e.get("pointer") == "/structure/clamp" and "platform" in e.get("message"),
          "clamp null without a platform: 422 at /structure/clamp (%s)" % e)
    req = platform_req()
    req["structure"]["platform"]["mass"]["translational"][1] = -1
    rc, d = solve_doc(exe, req)
    e = d.get("errors", [{}])[0]
    check(rc == 2 and e.get("pointer") == "/structure/platform/mass/translational/1",
          "negative platform mass: 422 at its entry (%s)" % e)
    req = platform_req()
    req["structure"]["platform"]["hydrostatic"] = diag([0, 0, 0], [0, 0, 0])
    req["structure"]["platform"]["mooring"] = diag([1, 1, 1], [1, 1, 0])
    rc, d = solve_doc(exe, req)
    modes = d.get("cases", [{}])[0].get("modes", [])
    check(rc == 0 and modes and modes[0]["frequency_hz"] == 0 and
          modes[0].get("label") == "1st rigid-body" and modes[1]["frequency_hz"] > 0,
          "a platform free in yaw: its rigid-body yaw at 0 Hz, labelled (%s)"
          % [(m.get("label"), m["frequency_hz"]) for m in modes[:2]])
    src = os.path.join(ref, "bmodes_offshore")
    shutil.copy(os.path.join(src, "OC3Hywind_tower_secs.dat"), tmp)
    with open(os.path.join(src, "OC3Hywind.bmi")) as f:
        text = f.read()
    with open(os.path.join(tmp, "held.bmi"), "w") as f:
        f.write(text.replace("2         hub_conn", "3         hub_conn")
                .replace("2          tow_support", "0          tow_support"))
    rc, out, err = run(exe, ["import", "bmodes", "held.bmi"], cwd=tmp)
    check(rc == 2 and "held.bmi:13: hub_conn: 3" in err and "tow_support 2" in err,
          "hub_conn 3 without a platform: exit 2 at file:line:field (%s)" % err.strip()[:200])
    req = platform_req()
    req["structure"]["platform"]["held"] = ["y", "y"]
    rc, d = solve_doc(exe, req)
    e = d.get("errors", [{}])[0]
    check(rc == 2 and e.get("pointer") == "/structure/platform/held/1",
          "a direction held twice: 422 at its entry (%s)" % e)


def main():
    exe, ref = os.path.abspath(sys.argv[1]), sys.argv[2]
    tmp = tempfile.mkdtemp(prefix="spinmodal-platform-")
    try:
        oc3(exe, ref)
        monopile(exe, ref)
        rigid(exe)
        tower_form(exe)
        refusals(exe, ref, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if FAILURES:
        print("%d failure(s)" % len(FAILURES))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
