#!/usr/bin/env python3
"""The main ElastoDyn file imported as a tower (DESIGN.md 8.5, issue 25 items 3-4).

`spinmodal import elastodyn NRELOffshrBsline5MW_Onshore_ElastoDyn.dat` (old-NWTC/FAST, see
tests/reference/blades/elastodyn/README.md) reads the tower file and the blade file it names:
the tower form with TowerHt, the tower file's stations and ElastoDyn's tower-top mass (NacMass +
HubMass + YawBrMass + 3 blades).  ElastoDyn has no EA or GJ: the stand-ins must not move the
bending frequencies (<= 1e-6 relative) when they change 10x, nor when more modes are asked
(shared DESIGN B).  Usage: elastodyn_tower_test.py SPINMODAL REFERENCE_DIR
"""
import copy
import json
import os
import subprocess
import sys
import tempfile

CLI, REF = sys.argv[1], os.path.join(sys.argv[2], "elastodyn")
MAIN = os.path.join(REF, "NRELOffshrBsline5MW_Onshore_ElastoDyn.dat")


def run(*args, **kw):
    return subprocess.run([CLI, *args], capture_output=True, text=True, **kw)


def solve(req, tmp):
    path = os.path.join(tmp, "req.json")
    with open(path, "w") as f:
        json.dump(req, f)
    p = run("solve", path)
    assert p.returncode == 0, p.stderr
    res = json.loads(p.stdout)
    return res["cases"][0]["modes"]


def bending(modes, n=6):
    """The lowest n bending modes' frequencies (labels flap = fore-aft, edge = side-side)."""
    out = [m["frequency_hz"] for m in modes if "torsion" not in m["label"] and "axial" not in m["label"]]
    return out[:n]


def main():
    fails = []
    p = run("import", "elastodyn", MAIN)
    assert p.returncode == 0, p.stderr
    req = json.loads(p.stdout)
    tw = req["tower"]
    # the main file's numbers: TowerHt 87.6, TowerBsHt 0, the tower file's 11 stations
    assert tw["height"] == 87.6 and tw["base_height"] == 0.0, tw
    assert len(tw["stations"]) == 11 and tw["stations"][0]["EI_flap"] == 6.14343e11
    top = tw["top_mass"]
    # TwrTpMass = 240000 + 56780 + 0 + 3 x the blade (17608.8 kg by the trapezoid rule over
    # BMassDen x AdjBlMs; NREL's report: 17740 kg, its ~350 t rotor-nacelle assembly)
    if not 3.49e5 < top["mass"] < 3.50e5:
        fails.append(f"top mass {top['mass']}")
    assert req["analysis"]["omega"] == [0.0] and "rpm" not in req["analysis"]
    with tempfile.TemporaryDirectory() as tmp:
        base = solve(req, tmp)
        f0 = bending(base)
        print("bending frequencies (Hz):", " ".join(f"{f:.6f}" for f in f0))
        # NREL 5-MW report (Jonkman et al. 2009, table 9-1): tower 1st FA 0.3240, 1st SS 0.3120 Hz
        if not (0.30 < f0[0] < 0.34 and 0.30 < f0[1] < 0.34):
            fails.append(f"first pair {f0[:2]}")
        for key in ("EA", "GJ"):
            for fac in (10.0, 0.1):
                r = copy.deepcopy(req)
                r["tower"]["section"][key] *= fac
                f1 = bending(solve(r, tmp))
                dev = max(abs(a / b - 1) for a, b in zip(f1, f0))
                print(f"{key} x {fac}: max relative change {dev:.2e}")
                if dev > 1e-6:
                    fails.append(f"{key} x {fac} moves the bending frequencies by {dev:.2e}")
        r = copy.deepcopy(req)
        r["analysis"]["modes"] = 20
        f1 = bending(solve(r, tmp))
        dev = max(abs(a / b - 1) for a, b in zip(f1, f0))
        print(f"20 modes asked instead of 10: max relative change {dev:.2e}")
        if dev > 1e-6:
            fails.append(f"modes 20 moves the bending frequencies by {dev:.2e}")
    # a tower file alone has no height; rpm does not apply to the main file
    p = run("import", "elastodyn", os.path.join(REF, "NRELOffshrBsline5MW_Onshore_ElastoDyn_Tower.dat"))
    if p.returncode == 0 or "TwrFile" not in p.stderr:
        fails.append("a tower file alone: " + p.stderr)
    p = run("import", "elastodyn", MAIN, "--rpm", "12.1")
    if p.returncode == 0:
        fails.append("--rpm on the main file accepted")
    # a main file whose TwrFile leaves its folder is refused at its line
    with tempfile.TemporaryDirectory() as tmp:
        text = open(MAIN, "rb").read().replace(b'"NRELOffshrBsline5MW_Onshore_ElastoDyn_Tower.dat"',
                                               b'"../secret/Tower.dat"')
        path = os.path.join(tmp, "main.dat")
        open(path, "wb").write(text)
        p = run("import", "elastodyn", path)
        if p.returncode == 0 or ":110: TwrFile:" not in p.stderr:
            fails.append("TwrFile outside the folder: " + p.stderr)
    for f in fails:
        print("FAIL:", f)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
