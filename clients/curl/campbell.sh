#!/usr/bin/env bash
# campbell.sh — Campbell diagram data: solve a request at a range of speeds, print the CSV.
#
#   campbell.sh REQUEST.json START:STOP:COUNT      e.g. campbell.sh examples/angled-beam-90.json 0:20:101
#   campbell.sh REQUEST.json 0,5,10,20             explicit speeds (rad/s)
#   campbell.sh --rpm REQUEST.json 0:15:16         the same in rev/min (0, 1, ... 15)
#
# COUNT is the number of speeds, both ends included, as in `spinmodal import --rpm` and the
# Python client: 0:15:1 is refused (it would be 0 alone).
#
# Replaces the request's speeds (analysis.omega or analysis.rpm, whichever it has: the
# importers write rpm) by COUNT evenly spaced speeds from START to STOP (both included), in
# rad/s (analysis.omega) or with --rpm in rev/min (analysis.rpm), switches mode shapes off (a sweep needs only the frequencies), submits the sweep,
# waits and prints the frequency CSV (one row per speed and mode; see csv.sh).  The JSON edit
# uses python3 (jq is not required).
#
# Environment: SPINMODAL_URL (default http://127.0.0.1:8080), SPINMODAL_TOKEN (bearer token).
# Needs curl, python3, and csv.sh and submit.sh next to this script.
#
# Exit status: as csv.sh — 0 ok, 1 the job failed (e.g. no equilibrium at some speeds; the CSV
# is still printed) or was canceled, 2 invalid request, 3 connection/HTTP error, 64 usage.
set -euo pipefail

usage() { echo "usage: ${0##*/} [--rpm] REQUEST.json START:STOP:COUNT | [--rpm] REQUEST.json S1,S2,..."; }

case ${1:-} in -h|--help) usage; exit 0 ;; esac
key=omega
if [ "${1:-}" = --rpm ]; then key=rpm; shift; fi
[ $# -eq 2 ] || { usage >&2; exit 64; }
if [ "$1" != - ] && [ ! -r "$1" ]; then echo "${0##*/}: cannot read $1" >&2; exit 2; fi

# Build the sweep request (exit 64 on a bad range, 2 on a file that is not JSON).
sweep=$(python3 - "$1" "$2" "$key" <<'PY'
import json, sys
path, spec, key = sys.argv[1], sys.argv[2], sys.argv[3]
try:
    if ":" in spec:
        start, stop, count = spec.split(":")
        start, stop, count = float(start), float(stop), int(count)
        if count < 1 or (count == 1 and stop != start):
            raise ValueError  # 0:15:1 would be 0 alone: COUNT counts the speeds (0:15:16)
        speeds = [start] if count == 1 else \
            [start + i * (stop - start) / (count - 1) for i in range(count - 1)] + [stop]
    else:
        speeds = [float(s) for s in spec.split(",")]
except ValueError:
    print("campbell.sh: bad speed range %r (START:STOP:COUNT, COUNT speeds with both ends "
          "included, so COUNT 1 only when START = STOP; or S1,S2,...)" % spec, file=sys.stderr)
    sys.exit(64)
try:
    req = json.load(sys.stdin if path == "-" else open(path))
    req.setdefault("analysis", {})
    req["analysis"].pop("rpm" if key == "omega" else "omega", None)
    req["analysis"][key] = [round(s, 12) + 0.0 for s in speeds]
    req["analysis"]["mode_shapes"] = False
except (ValueError, AttributeError, TypeError) as e:
    print("campbell.sh: %s is not a JSON request: %s" % (path, e), file=sys.stderr)
    sys.exit(2)
json.dump(req, sys.stdout)
PY
)
"$(dirname "$0")/csv.sh" - <<<"$sweep"
