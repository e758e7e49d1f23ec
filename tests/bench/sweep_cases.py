"""tests/bench/sweep_cases.py — the sweep cases of issue 27's benchmarks, written once
(bench_sweeps.sh, bench_ab.sh, bench_large.sh, compare_outputs.py): the R3-style precone blade of
bench_spatial.c, hub radius 1 m, 10 m at 10 degrees precone, per-element frames (6 coordinates
each), clamped at the hub; the benchmark files (write_bench_files); and the models with one large
frame (large_frames: the classical floating-frame setup)."""
import json
import math
import os


def precone_blade(elements=48, omegas=None, modes=3, **analysis):
    """The request (a dict): elements per blade, speeds in rad/s (default 0..20 by 1), modes,
    and further analysis fields (e.g. mode_shapes=True)."""
    b = math.radians(10)
    a = {"omega": [float(i) for i in range(21)] if omegas is None else list(omegas), "modes": modes}
    a.update(analysis)
    return {"structure": {"joints": {"H": [1, 0, 0], "T": [1 + 10 * math.cos(b), 0, 10 * math.sin(b)]},
                          "sections": {"s": {"EA": 8.4e7, "EI_flap": 2800, "EI_edge": 25200, "GJ": 3883,
                                             "mass_per_length": 3.0, "flap_inertia": 1e-4,
                                             "edge_inertia": 9e-4}},
                          "members": [{"id": "b", "from": "H", "to": "T", "section": "s",
                                       "elements": elements}],
                          "clamp": "H"},
            "frames": "per_element", "analysis": a}


def write_bench_files(folder, root="."):
    """The benchmark sweeps as request files in folder: planar101.json (examples/angled-beam-90.json
    at 101 speeds, 0 to 20 rad/s), blade21.json (precone_blade()) and blade101.json (the blade at
    the same 101 speeds).  root: the repository."""
    speeds = [20 * i / 100 for i in range(101)]
    with open(os.path.join(root, "examples", "angled-beam-90.json")) as f:
        r = json.load(f)
    r["analysis"]["omega"] = speeds
    for name, req in (("planar101", r), ("blade21", precone_blade()),
                      ("blade101", precone_blade(omegas=speeds))):
        with open(os.path.join(folder, name + ".json"), "w") as f:
            json.dump(req, f)


def large_frames(root="."):
    """(name, request) of the one-frame models: the angled beam (examples/angled-beam-90.json)
    with 125 and 166 elements a member in one frame (500 and 664 coordinates, planar, 0 and
    10 rad/s), and the precone blade with 60 elements in one frame (360 coordinates, spatial, 0
    and 20 rad/s, 4 modes).  root: the repository."""
    out = []
    for ne in (125, 166):
        with open(os.path.join(root, "examples", "angled-beam-90.json")) as f:
            r = json.load(f)
        r["frames"] = "single"
        for mb in r["structure"]["members"]:
            mb["elements"] = ne
        r["analysis"]["omega"] = [0, 10]
        out.append(("planar-1frame-%d" % (4 * ne), r))
    b = precone_blade(60, [0, 20], 4)
    b["frames"] = "single"
    out.append(("spatial-1frame-360", b))
    return out


if __name__ == "__main__":
    import sys
    write_bench_files(sys.argv[1])
