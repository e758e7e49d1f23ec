#!/usr/bin/env bash
# tests/bench/run.sh — build spinmodal with buildtype=release in build-bench
# and run bench_core (median wall time of sm_model_new + sm_solve for the
# angled beam; see bench_core.c).  Arguments are passed to bench_core, e.g.
#   bash tests/bench/run.sh --seconds 5 a b
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
if [ -d build-bench/meson-private ]; then
  meson configure build-bench -Dbuildtype=release
else
  meson setup build-bench -Dbuildtype=release
fi
ninja -C build-bench tests/bench/bench_core
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
exec build-bench/tests/bench/bench_core "$@"
