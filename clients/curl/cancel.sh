#!/usr/bin/env bash
# cancel.sh — cancel a queued or running spinmodald job.
#
#   cancel.sh JOB_ID
#
# DELETE /v1/analyses/ID.  A queued job is canceled at once (HTTP 200, state "canceled"); a
# running one is asked to stop (HTTP 202, "cancel_requested": true) and becomes canceled at its
# next Newton iteration or speed.  Prints the status document.  A job that already finished
# answers 409 (exit 3).
#
# Environment: SPINMODAL_URL (default http://127.0.0.1:8080), SPINMODAL_TOKEN (bearer token,
# needed when the daemon runs with --token-file).  Needs curl.
#
# Exit status: 0 canceled or cancel requested; 3 connection error or HTTP error (404 unknown id,
# 409 already finished, 401 missing token ...; the problem document on stderr); 64 usage.
set -euo pipefail

usage() { echo "usage: ${0##*/} JOB_ID"; }

URL=${SPINMODAL_URL:-http://127.0.0.1:8080}
URL=${URL%/}
AUTH=()
if [ -n "${SPINMODAL_TOKEN:-}" ]; then AUTH=(-H "Authorization: Bearer $SPINMODAL_TOKEN"); fi

case ${1:-} in
    -h|--help) usage; exit 0 ;;
    ''|-*) usage >&2; exit 64 ;;
esac
[ $# -eq 1 ] || { usage >&2; exit 64; }

if ! out=$(curl -sS -X DELETE ${AUTH[@]+"${AUTH[@]}"} -w '\n%{http_code}' "$URL/v1/analyses/$1"); then
    echo "${0##*/}: cannot reach spinmodald at $URL" >&2
    exit 3
fi
code=${out##*$'\n'}
body=${out%$'\n'*}
case $code in
    200|202) printf '%s\n' "$body" ;;
    *) echo "${0##*/}: HTTP $code from DELETE /v1/analyses/$1" >&2
       printf '%s\n' "$body" >&2
       exit 3 ;;
esac
