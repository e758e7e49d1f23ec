#!/usr/bin/env bash
# tests/bench/bench_bmodes.sh — issue 27 goal 5: spinmodal against BModes v3.00, side by side, in
# one run on the same machine: whole-process wall and CPU time (medians of N alternating runs)
# and peak memory (RSS, under /usr/bin/time) on the BModes CertTest blade Test01 at 12, 48, 96
# and 192 elements (BModes' own mesh refined: each of its 12 elements cut in k; spinmodal reads
# the same model with `import bmodes --bmodes-mesh k`), and a 16-speed sweep at 48 elements
# (BModes: 16 runs, one per rot_rpm; spinmodal: one request with 16 speeds).  A benchmark, never a test: it
# prints a table and checks nothing.  It skips (exit 0, a line saying why) without gfortran or
# without BModes' source.
#   bash tests/bench/bench_bmodes.sh SPINMODAL [N]          (N default 5; cases where one BModes
#                                                            run takes > 5 s get 1 run)
# BMODES_ELEMENTS="12 48": only those sizes (default 12 48 96 192); BMODES_SWEEP=0: no sweep row.
# BMODES_BIN=PATH: use that BModes binary (built by this script with BMODES_KEEP=PATH) instead of
# building one, e.g. on a machine without gfortran.
# BModes' source: $BMODES_SRC, a checkout of github.com/old-NWTC/BModes (a work tree with src/,
# or a bare git directory; default: the tool library's mirror /work/.mirror/old-NWTC+BModes/repo).
# Built with gfortran -O2 (-O3 with BMODES_FFLAGS=-O3); one patch, stated: eigsolver.f's
# NMAX 1000 -> 4000 (BModes has 9 nselt + 6 degrees of freedom: 192 elements need 1734).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
spin=$(realpath "${1:?usage: bench_bmodes.sh SPINMODAL [N]}")
n=${2:-5}
src=${BMODES_SRC:-/work/.mirror/old-NWTC+BModes/repo}
fflags=${BMODES_FFLAGS:--O2}
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if [ -n "${BMODES_BIN:-}" ]; then # a BModes built earlier by this script (a machine without gfortran)
  bmodes=$(realpath "$BMODES_BIN")
  rev="prebuilt $BMODES_BIN"
elif ! command -v gfortran >/dev/null; then
  echo "bench_bmodes: skipped (no gfortran: apt-get install gfortran)"; exit 0
elif [ ! -d "$src/src/bmodes" ] && ! git --git-dir="$src" rev-parse HEAD >/dev/null 2>&1; then
  echo "bench_bmodes: skipped (no BModes source at $src: set BMODES_SRC)"; exit 0
fi

# ---- build BModes (BMODES_KEEP=PATH: copy the binary there, for BMODES_BIN on another machine)
if [ -z "${BMODES_BIN:-}" ]; then
mkdir -p "$tmp/bm"
if [ -d "$src/src/bmodes" ]; then
  cp -r "$src/src" "$tmp/bm/"
  rev=$(git -C "$src" rev-parse --short HEAD 2>/dev/null || echo "work tree")
else
  git --git-dir="$src" archive HEAD src 2>/dev/null | tar -x -C "$tmp/bm"
  rev=$(git --git-dir="$src" rev-parse --short HEAD)
fi
sed -i 's/parameter (NMAX=1000)/parameter (NMAX=4000)/' "$tmp/bm/src/bmodes/eigsolver.f"
(
  mkdir -p "$tmp/bm/build" && cd "$tmp/bm/build"
  L=../src/NWTC_Library_v1 B=../src/bmodes F="$fflags -cpp -ffree-line-length-none"
  for f in $L/DoubPrec.f90 $L/SysGnuLinux.f90 $L/NWTC_IO.f90 $L/NWTC_Num.f90 $L/NWTC_Aero.f90 \
           $L/ModMesh.f90 $L/NWTC_Library.f90 $B/modules.f90 $B/Alloc.f90 $B/heap_sort.f90 \
           $B/utilss.f90 $B/SetProg.f90 $B/Struct.f90 $B/BldVib.f90 $B/BModes.f90; do
    gfortran $F -c "$f"
  done
  gfortran "$fflags" -std=legacy -c $B/eigsolver.f
  gfortran -o bmodes ./*.o
) >"$tmp/build.log" 2>&1 || { echo "bench_bmodes: BModes build failed:"; tail -20 "$tmp/build.log"; exit 1; }
bmodes="$tmp/bm/build/bmodes"
[ -n "${BMODES_KEEP:-}" ] && cp "$bmodes" "$BMODES_KEEP"
fi

# ---- cases: BModes inputs (refined el_loc; rot_rpm) and spinmodal requests (--bmodes-mesh k)
ref=tests/reference/blades/bmodes_certtest
cp "$ref/blade_sec_props.dat" "$tmp/"
python3 - "$ref/Test01_nonunif_blade.bmi" "$tmp" "$spin" <<'PY'
import json, math, subprocess, sys
bmi, tmp, spin = sys.argv[1], sys.argv[2], sys.argv[3]
lines = open(bmi).read().split("\n")
i = next(j for j, l in enumerate(lines) if l.split()[1:2] == ["nselt:"])
loc = [float(x) for x in lines[i + 2].split()]
rpm_line = next(j for j, l in enumerate(lines) if "rot_rpm:" in l)
def write(name, k, rpm):
    el = [loc[e] + (loc[e + 1] - loc[e]) * t / k for e in range(len(loc) - 1) for t in range(k)]
    el.append(loc[-1])
    out = list(lines)
    out[i] = "%-9d nselt:     no of blade or tower elements (-)" % (len(el) - 1)
    out[i + 2] = "  ".join("%.10g" % x for x in el)
    out[rpm_line] = "%-9g rot_rpm:    rotor speed (rpm)" % rpm
    open("%s/%s.bmi" % (tmp, name), "w").write("\n".join(out))  # BModes: the refined mesh
    orig = list(lines)
    orig[rpm_line] = out[rpm_line]
    open("%s/%s_12.bmi" % (tmp, name), "w").write("\n".join(orig))  # spinmodal: cut k itself
    r = subprocess.run([spin, "import", "bmodes", "--bmodes-mesh", str(k), "%s/%s_12.bmi" % (tmp, name)],
                       capture_output=True, text=True, check=True)
    return json.loads(r.stdout)
for k in (1, 4, 8, 16):
    req = write("t01_%d" % (12 * k), k, 60.0)
    json.dump(req, open("%s/t01_%d.json" % (tmp, 12 * k), "w"))
speeds = [60.0 * j / 15 for j in range(16)]
for j, rpm in enumerate(speeds):
    req = write("sweep_%02d" % j, 4, rpm)
an = req["analysis"]
an.pop("rpm", None)
an["omega"] = [r * 2 * math.pi / 60 for r in speeds]
json.dump(req, open("%s/sweep.json" % tmp, "w"))
PY

python3 - "$n" "$spin" "$bmodes" "$tmp" "$rev" "$fflags" "${BMODES_ELEMENTS:-12 48 96 192}" \
  "${BMODES_SWEEP:-1}" <<'PY'
import os, statistics, sys, time
n, spin, bmodes, tmp, rev, fflags, sizes, sweep = int(sys.argv[1]), *sys.argv[2:]
null = os.open(os.devnull, os.O_WRONLY)

def once(argv):
    """Wall ms and CPU ms (user + system) of one whole process (posix_spawn, cwd = tmp)."""
    fa = [(os.POSIX_SPAWN_DUP2, null, 1), (os.POSIX_SPAWN_DUP2, null, 2)]
    t0 = time.perf_counter_ns()
    pid = os.posix_spawn(argv[0], argv, os.environ, file_actions=fa)
    _, status, ru = os.wait4(pid, 0)
    wall = (time.perf_counter_ns() - t0) / 1e6
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit("failed: %s" % " ".join(argv))
    return wall, (ru.ru_utime + ru.ru_stime) * 1e3

def peak_mib(argv):
    """Peak RSS in MiB, measured under /usr/bin/time: a process spawned from this one starts on
    Python's pages (posix_spawn shares them until exec) and its ru_maxrss never reads below
    Python's own ~14 MiB.  None without /usr/bin/time."""
    if not os.access("/usr/bin/time", os.X_OK):
        return None
    out = os.path.join(tmp, "rss.txt")
    pid = os.posix_spawn("/usr/bin/time", ["/usr/bin/time", "-f", "%M", "-o", out] + argv,
                         os.environ, file_actions=[(os.POSIX_SPAWN_DUP2, null, 1),
                                                   (os.POSIX_SPAWN_DUP2, null, 2)])
    os.waitpid(pid, 0)
    return int(open(out).read().split()[-1]) / 1024.0

os.chdir(tmp)
cases = [("Test01, %d el., 1 speed" % e, [[bmodes, "t01_%d.bmi" % e]],
          [spin, "solve", "t01_%d.json" % e]) for e in map(int, sizes.split())]
if sweep != "0":
  cases.append(("16-speed sweep, 48 el.", [[bmodes, "sweep_%02d.bmi" % j] for j in range(16)],
                [spin, "solve", "sweep.json"]))
print("BModes v3.00 (old-NWTC/BModes %s, gfortran %s, NMAX 4000) vs %s; OPENBLAS_NUM_THREADS=1;"
      " medians of alternating runs; CPU = user + system" % (rev, fflags, spin))
print("%-24s %4s %10s %10s %6s %9s %9s %6s %7s %7s" % (
    "case", "runs", "BModes ms", "spinmodal", "ratio", "BM CPU", "spin CPU", "ratio",
    "BM MiB", "sp MiB"))
fmt_mib = lambda x: "%7s" % "n/a" if x is None else "%7.1f" % x
for name, bm_runs, sp in cases:
    first = [once(a) for a in bm_runs]  # also warms the page cache
    once(sp)
    k = 1 if sum(w for w, _ in first) > 5000 else n
    bt, bc, st, sc = [], [], [], []
    for _ in range(k):
        r = [once(a) for a in bm_runs]
        bt.append(sum(w for w, _ in r))
        bc.append(sum(c for _, c in r))
        w, c = once(sp)
        st.append(w)
        sc.append(c)
    mem = [peak_mib(a) for a in bm_runs]
    bm_mem = None if None in mem else max(mem)
    sp_mem = peak_mib(sp)
    med = statistics.median
    print("%-24s %4d %10.1f %10.1f %6.1f %9.1f %9.1f %6.1f %s %s" % (
        name, k, med(bt), med(st), med(bt) / med(st), med(bc), med(sc),
        med(bc) / max(med(sc), 1e-9), fmt_mib(bm_mem), fmt_mib(sp_mem)))
PY
