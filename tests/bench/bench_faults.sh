#!/usr/bin/env bash
# tests/bench/bench_faults.sh — issue 27 goal 1: what a page fault costs on this machine, and
# whether small solves get faster when their heap is faulted in up front (prefault.so by
# LD_PRELOAD, 1 or 2 MB) or comes in huge pages (GLIBC_TUNABLES=glibc.malloc.hugetlb=1).  Each
# setting runs bench_small.sh NEW (N runs, medians; wall, CPU and the child's minor faults).  On
# the 2-core machine here a fault costs 1.1 us, populating the heap costs what it saves, and the
# 12-element blade stays at ~5 ms; under the device's gVisor a fault may cost far more.  A
# benchmark, never a test.
#   bash tests/bench/bench_faults.sh NEW [N] [PROBE PRELOAD]
# NEW: a dynamically linked CLI (meson setup -Dstatic_cli=disabled): LD_PRELOAD does not reach a
# static-pie one (meson's default where it links, DESIGN.md 2.1): its prefault rows would measure
# nothing, so the script refuses it.
# PROBE, PRELOAD: fault_probe and prefault.so (default: build/tests/bench/; tests/bench/
# device_run.sh --prepare puts copies in its carried folder for a machine without a build).
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
new=${1:?usage: bench_faults.sh NEW [N] [PROBE PRELOAD]}
n=${2:-15}
probe=${3:-build/tests/bench/fault_probe}
pre=$(realpath "${4:-build/tests/bench/prefault.so}")
if ! readelf -lW "$new" | grep -q INTERP; then
    echo "bench_faults.sh: $new is linked static (no program interpreter): LD_PRELOAD cannot" \
         "reach it; build one with meson setup -Dstatic_cli=disabled" >&2
    exit 2
fi
"$probe"
for v in "X=default" "LD_PRELOAD=$pre PREFAULT_MB=1" "LD_PRELOAD=$pre PREFAULT_MB=2" \
         "GLIBC_TUNABLES=glibc.malloc.hugetlb=1"; do
    echo "== ${v#X=}"
    env $v bash tests/bench/bench_small.sh "$new" "" "$n" | tail -n +2
done
