#!/usr/bin/env python3
"""The core's layers, from the built library (DESIGN.md 2, issue 24).

usage: layers_test.py LIBSPINMODAL.a

Reads the object files of libspinmodal with nm (defined and undefined symbols), builds the
file-level graph "file A calls a function defined in file B", and checks:
  1. no cycle between files (Tarjan's strongly connected components);
  2. calls go down the layers only: post -> solve -> model -> base, the kinds (planar/,
     spatial/) beside model and reached by nobody but through m->kind (kind.h): the only
     direct reference is the picker's to the two smi_kind tables (model/mesh.c); a kind
     never calls the other;
  3. every object file belongs to one of those folders.
Prints the offending edges; exit 1 when any check fails, 77 (skip) without nm.
"""
import collections
import os
import shutil
import subprocess
import sys

RANK = {"base": 0, "model": 1, "planar": 1, "spatial": 1, "solve": 2, "post": 3}


def graph(lib):
    members = subprocess.run(["ar", "t", lib], capture_output=True, text=True, check=True).stdout.split()
    defs, uses = {}, collections.defaultdict(set)
    for o in members:
        path = o if os.path.isabs(o) or os.path.exists(o) else os.path.join(os.path.dirname(lib), o)
        name = os.path.basename(o)
        name = name[:-4] if name.endswith(".c.o") else name
        f = name.replace("_", "/", 1)  # meson names core/planar/fe.c's object planar_fe.c.o
        out = subprocess.run(["nm", path], capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            p = line.split()
            if len(p) == 3 and p[1] in "TDRB":
                defs[p[2]] = (f, p[2])
            elif len(p) == 2 and p[0] == "U":
                uses[f].add(p[1])
    files = {f for f, _ in defs.values()} | set(uses)
    edges = collections.defaultdict(set)
    for f in files:
        for s in uses[f]:
            if s in defs and defs[s][0] != f:
                edges[f].add((defs[s][0], s))
    return files, edges


def cycles(files, edges):
    index, low, stack, on, out, n = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = n[0]
        n[0] += 1
        stack.append(v)
        on.add(v)
        for w, _ in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(files):
        if v not in index:
            visit(v)
    return out


def main():
    if not shutil.which("nm") or not shutil.which("ar"):
        print("SKIP: nm/ar (binutils) not found")
        return 77
    files, edges = graph(sys.argv[1])
    fails = 0
    stray = sorted(f for f in files if f.split("/")[0] not in RANK)
    print(("ok   " if not stray else "FAIL ") + "%d object files, each in a layer folder %s"
          % (len(files), stray or ""))
    fails += bool(stray)
    cyc = cycles(files, edges)
    print(("ok   " if not cyc else "FAIL ") + "no cycle between files %s" % (cyc or ""))
    fails += bool(cyc)
    up = []
    for f in sorted(files):
        for d, sym in sorted(edges.get(f, ())):
            lf, ld = f.split("/")[0], d.split("/")[0]
            if lf not in RANK or ld not in RANK:
                continue
            picker = f == "model/mesh" and sym in ("smi_kind_planar", "smi_kind_spatial")
            kinds = ("planar", "spatial")
            if (RANK[ld] > RANK[lf] or (lf in kinds and ld in kinds and lf != ld)
                    or (lf in ("model", "solve", "post") and ld in kinds)) and not picker:
                up.append("%s -> %s (%s)" % (f, d, sym))
    print(("ok   " if not up else "FAIL ") + "calls go down the layers only (post > solve > model > base; "
          "the kinds through m->kind only)")
    for u in up:
        print("       " + u)
    fails += bool(up)
    print("%d failed" % fails if fails else "all passed")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
