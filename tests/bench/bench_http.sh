#!/usr/bin/env bash
# tests/bench/bench_http.sh — HTTP throughput of spinmodald (a benchmark, not a
# test: `meson test` never runs it).
#
# Builds buildtype=release in build-release (configured if missing), starts
# spinmodald on a free loopback port with a temporary database and
# --workers $(nproc), and measures with wrk (Debian package `wrk`):
#   (a) cache-hit GET /v1/analyses/{id} of a done 3-mode job
#       (examples/angled-beam-90.json): requests/s and p99 latency;
#   (b) cache-hit POST /v1/analyses of the identical request (wrk Lua script);
#   (c) cold jobs/s: N distinct requests (omega varied) submitted at once so
#       every worker is busy, timed from the first created_at to the last
#       finished_at, against the ceiling workers / t_solve, where t_solve is
#       the median timing_ms total (equilibrium + linearize + eigen) of 7 runs
#       of the CLI `spinmodal solve` on the example.  Also printed: the
#       ceiling from the CLI's median wall time (process start-up included,
#       so a lenient bound) and the median started_at -> finished_at of the
#       jobs (the daemon's cost per job: model, solve, encoding, store).
# Targets: (a) >= 10000 req/s with p99 < 5 ms; (c) >= 80 % of the ceiling.
# Ends with a summary table; exit status 0 when the benchmark ran (missed
# targets are marked in the table, not in the exit status), 1 on a setup error.
#
# Usage: bash tests/bench/bench_http.sh [--seconds S] [--threads T]
#          [--connections C] [--jobs N] [--workers W] [--build-dir DIR]
# Only loopback traffic; every loop is bounded in count and time.
set -euo pipefail
self=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/$(basename "${BASH_SOURCE[0]}")
cd "$(dirname "$self")/../.."
root=$PWD

seconds=10
threads=2
connections=32
jobs=100
workers=$(nproc 2>/dev/null || echo 2)
build="build-release"
example=examples/angled-beam-90.json

usage() { sed -n '2,/^set -euo/p' "$self" | sed '$d; s/^# \{0,1\}//'; exit "$1"; }
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --connections) connections=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --workers) workers=$2; shift 2 ;;
    --build-dir) build=$2; shift 2 ;;
    -h|--help) usage 0 ;;
    *) echo "bench_http: unknown argument '$1'" >&2; usage 64 >&2 ;;
  esac
done

say() { printf 'bench_http: %s\n' "$*"; }
die() { printf 'bench_http: error: %s\n' "$*" >&2; exit 1; }

for tool in wrk curl python3 meson ninja; do
  command -v "$tool" >/dev/null 2>&1 ||
    die "'$tool' not found (apt-get install $tool, or bash deploy/install-deps.sh)"
done

tmp=$(mktemp -d "${TMPDIR:-/tmp}/bench_http.XXXXXX")
daemon_pid=
cleanup() {
  if [ -n "$daemon_pid" ] && kill -0 "$daemon_pid" 2>/dev/null; then
    kill -TERM "$daemon_pid" 2>/dev/null || true
    wait "$daemon_pid" 2>/dev/null || true
  fi
  rm -rf "$tmp"
}
trap cleanup EXIT

# ------------------------------------------------------------------ build
if [ ! -d "$build/meson-private" ]; then
  meson setup "$build" --buildtype=release >"$tmp/build.log" 2>&1 ||
    { cat "$tmp/build.log" >&2; die "meson setup $build failed"; }
fi
ninja -C "$build" server/spinmodald server/spinmodal >"$tmp/build.log" 2>&1 ||
  { cat "$tmp/build.log" >&2; die "build of $build/server/spinmodald failed"; }
case $build in /*) bdir=$build ;; *) bdir=$root/$build ;; esac
daemon_bin=$bdir/server/spinmodald
cli_bin=$bdir/server/spinmodal
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1   # DESIGN §2: parallelism is across jobs

# ------------------------------------------------------- single solve time
# Median over 7 runs (after a warm-up) of `spinmodal solve`: "timing_ms wall_ms".
say "timing the CLI: $cli_bin solve $example"
out=$(python3 - "$cli_bin" "$example" <<'PY'
import json, statistics, subprocess, sys, time
cli, path = sys.argv[1], sys.argv[2]
subprocess.run([cli, "solve", path], stdout=subprocess.DEVNULL, check=True)  # warm-up
solve, wall = [], []
for _ in range(7):
    s = time.perf_counter()
    p = subprocess.run([cli, "solve", path], stdout=subprocess.PIPE, check=True)
    wall.append((time.perf_counter() - s) * 1e3)
    t = json.loads(p.stdout)["timing_ms"]
    solve.append(sum(v for v in t.values() if isinstance(v, (int, float))))
print("%.3f %.3f" % (statistics.median(solve), statistics.median(wall)))
PY
) || die "spinmodal solve $example failed"
read -r t_solve cli_wall <<<"$out"
say "t_solve ${t_solve} ms (median timing_ms total), CLI wall ${cli_wall} ms"

# ----------------------------------------------------------------- daemon
"$daemon_bin" --listen 127.0.0.1:0 --db "$tmp/bench.db" --workers "$workers" \
  2>"$tmp/daemon.log" &
daemon_pid=$!
port=
for _ in $(seq 100); do
  port=$(sed -n 's/.*event=listening .*addr=127\.0\.0\.1:\([0-9][0-9]*\).*/\1/p' "$tmp/daemon.log" | head -n 1)
  [ -n "$port" ] && break
  kill -0 "$daemon_pid" 2>/dev/null || break
  sleep 0.1
done
[ -n "$port" ] || { cat "$tmp/daemon.log" >&2; die "spinmodald did not log event=listening"; }
base=http://127.0.0.1:$port
say "spinmodald pid $daemon_pid on $base, $workers workers"

# json_field FIELD: read a JSON document on stdin, print its top-level FIELD.
json_field() { python3 -c 'import json, sys; print(json.load(sys.stdin).get(sys.argv[1]))' "$1"; }

# The done job that (a) and (b) hit.
doc=$(curl -sS --max-time 70 -H 'Content-Type: application/json' \
        --data-binary @"$example" "$base/v1/analyses?wait=60")
job_id=$(printf '%s' "$doc" | json_field id)
job_state=$(printf '%s' "$doc" | json_field state)
[ "$job_state" = "done" ] || die "the example job is '$job_state', not done: $doc"
hit_code=$(curl -sS --max-time 10 -o /dev/null -w '%{http_code}' -H 'Content-Type: application/json' \
             --data-binary @"$example" "$base/v1/analyses")
[ "$hit_code" = 200 ] || die "POST of a done request answered $hit_code, not 200 (cache hit)"
say "job $job_id done; POST of the same request answers 200"

# run_wrk NAME ARGS...: wrk with --latency; prints "req_s p99_ms non2xx".
run_wrk() {
  local name=$1; shift
  wrk -t"$threads" -c"$connections" -d"${seconds}s" --timeout 5s --latency "$@" \
    >"$tmp/$name.txt" 2>&1 || { cat "$tmp/$name.txt" >&2; die "wrk $name failed"; }
  python3 - "$tmp/$name.txt" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
rps = float(re.search(r"Requests/sec:\s*([0-9.]+)", text).group(1))
m = re.search(r"^\s*99%\s+([0-9.]+)(us|ms|s)\s*$", text, re.M)
p99 = float(m.group(1)) * {"us": 1e-3, "ms": 1.0, "s": 1e3}[m.group(2)]
m = re.search(r"Non-2xx or 3xx responses:\s*([0-9]+)", text)
err = int(m.group(1)) if m else 0
m = re.search(r"Socket errors:.*", text)
if m:
    err += sum(int(x) for x in re.findall(r"[0-9]+", m.group(0)))
print("%.0f %.3f %d" % (rps, p99, err))
PY
}

# ----------------------------------------------------------- (a) and (b)
say "(a) GET /v1/analyses/{id}: ${seconds} s, $threads threads, $connections connections"
out=$(run_wrk get "$base/v1/analyses/$job_id")
read -r get_rps get_p99 get_err <<<"$out"
cat >"$tmp/post.lua" <<LUA
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
local f = assert(io.open("$root/$example", "rb"))
wrk.body = f:read("*a")
f:close()
LUA
say "(b) POST /v1/analyses (cache hit): ${seconds} s, $threads threads, $connections connections"
out=$(run_wrk post -s "$tmp/post.lua" "$base/v1/analyses")
read -r post_rps post_p99 post_err <<<"$out"

# -------------------------------------------------------------- (c) cold
say "(c) $jobs distinct jobs on $workers workers"
out=$(python3 - "$base" "$root/$example" "$jobs" <<'PY'
import datetime, http.client, json, sys, time, urllib.parse
base, path, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
url = urllib.parse.urlsplit(base)
req = json.load(open(path))
bodies = []
for k in range(n):
    req["analysis"]["omega"] = 20.0 + 1e-3 * (k + 1)   # distinct ids, same cost
    bodies.append(json.dumps(req).encode())
conn = http.client.HTTPConnection(url.hostname, url.port, timeout=70)
hdr = {"Content-Type": "application/json"}
ids = []
t0 = time.perf_counter()
for b in bodies:                       # one keep-alive connection: submissions are cheap
    conn.request("POST", "/v1/analyses", body=b, headers=hdr)
    r = conn.getresponse()
    doc = json.loads(r.read())
    if r.status not in (200, 202):
        sys.exit("POST answered %d: %s" % (r.status, doc))
    ids.append(doc["id"])
docs = []
for i in ids:                          # each wait returns as soon as that job ends
    for _ in range(10):
        conn.request("GET", "/v1/analyses/%s?wait=60" % i)
        r = conn.getresponse()
        doc = json.loads(r.read())
        if doc["state"] not in ("queued", "running"):
            break
    docs.append(doc)
wall = time.perf_counter() - t0
def ts(s):
    return datetime.datetime.strptime(s, "%Y-%m-%dT%H:%M:%S.%fZ").timestamp()
bad = sum(d["state"] != "done" for d in docs)
try:
    server = max(ts(d["finished_at"]) for d in docs) - min(ts(d["created_at"]) for d in docs)
    runs = sorted(ts(d["finished_at"]) - ts(d["started_at"]) for d in docs)
    run, busy = runs[n // 2] * 1e3, sum(runs)
except (KeyError, TypeError, ValueError):
    server, run, busy = wall, float("nan"), float("nan")
print("%.2f %.3f %.3f %d %.1f %.3f" % (n / max(server, 1e-9), wall, server, bad, run, busy))
PY
) || die "cold jobs failed"
read -r cold_jobs_s cold_wall_s cold_server_s cold_bad job_ms busy_s <<<"$out"
busy_pct=$(python3 -c "print('%.0f' % (100.0 * $busy_s / ($workers * $cold_server_s)))")
ceiling=$(python3 -c "print('%.2f' % ($workers * 1000.0 / $t_solve))")
ratio=$(python3 -c "print('%.0f' % (100.0 * $cold_jobs_s / $ceiling))")
wall_ceiling=$(python3 -c "print('%.2f' % ($workers * 1000.0 / $cli_wall))")
wall_ratio=$(python3 -c "print('%.0f' % (100.0 * $cold_jobs_s / $wall_ceiling))")
[ "$cold_bad" -eq 0 ] || say "warning: $cold_bad of $jobs cold jobs did not end 'done'"

# ---------------------------------------------------------------- summary
verdict() { python3 -c "print('ok' if $1 else 'MISSED')"; }
printf '\n%-40s %12s   %-14s %s\n' "spinmodald (workers $workers, wrk -t$threads -c$connections -d${seconds}s)" "value" "target" ""
printf '%-40s %12s   %-14s %s\n' "(a) GET  /v1/analyses/{id}    req/s" "$get_rps" ">= 10000" "$(verdict "$get_rps >= 10000")"
printf '%-40s %12s   %-14s %s\n' "(a) GET  /v1/analyses/{id}    p99 ms" "$get_p99" "< 5" "$(verdict "$get_p99 < 5")"
printf '%-40s %12s   %-14s %s\n' "(a) errors (non-2xx, socket)" "$get_err" "0" "$(verdict "$get_err == 0")"
printf '%-40s %12s   %-14s %s\n' "(b) POST /v1/analyses (hit)   req/s" "$post_rps" "" ""
printf '%-40s %12s   %-14s %s\n' "(b) POST /v1/analyses (hit)   p99 ms" "$post_p99" "" ""
printf '%-40s %12s   %-14s %s\n' "(b) errors (non-2xx, socket)" "$post_err" "0" "$(verdict "$post_err == 0")"
printf '%-40s %12s   %-14s %s\n' "(c) cold jobs/s ($jobs jobs)" "$cold_jobs_s" "" ""
printf '%-40s %12s   %-14s %s\n' "(c) ceiling workers/t_solve   jobs/s" "$ceiling" "" ""
printf '%-40s %12s   %-14s %s\n' "(c) cold / ceiling            %" "$ratio" ">= 80" "$(verdict "$ratio >= 80")"
printf '%-40s %12s\n' "    t_solve ms (median timing_ms total)" "$t_solve"
printf '%-40s %12s\n' "    median job started->finished ms" "$job_ms"
printf '%-40s %12s\n' "    workers busy during the cold run %" "$busy_pct"
printf '%-40s %12s\n' "    CLI wall ms; cold / (workers/wall) %" "$cli_wall; $wall_ratio"
printf '%-40s %12s\n' "    cold: server span / client wall s" "$cold_server_s / $cold_wall_s"
printf '%-40s %12s\n' "    load average (1 min) at the end" "$(cut -d' ' -f1 /proc/loadavg)"
