#!/usr/bin/env bash
# csv.sh — print the frequency table (CSV) of a spinmodald job.
#
#   csv.sh JOB_ID            the CSV of a finished job (GET /v1/analyses/ID/result?format=csv)
#   csv.sh REQUEST.json|-    submit the request, wait for it (via submit.sh), then print its CSV
#
# Columns: omega,mode,frequency_rad_s,frequency_hz,eig_re,eig_im,mac_to_previous,status,per_rev,
# rpm — one row per speed and mode (a speed without equilibrium has one row with empty mode
# fields; per_rev is empty at omega = 0).  Span-wise mode shapes of a spatial job:
# curl "$SPINMODAL_URL/v1/analyses/ID/result?format=spanwise" (or format=bmodes), DAEMON.md.
#
# Environment: SPINMODAL_URL (default http://127.0.0.1:8080), SPINMODAL_TOKEN (bearer token).
# Needs curl and python3, and submit.sh next to this script for a request file.
#
# Exit status: 0 ok; 1 the job failed or was canceled (the CSV is still printed when a result
# is stored); 2 invalid request (400/413/415/422); 3 connection error or other HTTP error
# (409: the job has no result yet); 64 usage.
set -euo pipefail

usage() { echo "usage: ${0##*/} JOB_ID | REQUEST.json | -"; }

URL=${SPINMODAL_URL:-http://127.0.0.1:8080}
URL=${URL%/}
AUTH=()
if [ -n "${SPINMODAL_TOKEN:-}" ]; then AUTH=(-H "Authorization: Bearer $SPINMODAL_TOKEN"); fi

# api METHOD PATH [CURL ARGS...]: the body on stdout when the status is 2xx; otherwise the
# body (an RFC 9457 problem document) on stderr and exit 2 (invalid request) or 3.
api() {
    local method=$1 path=$2 out code body
    shift 2
    if ! out=$(curl -sS -X "$method" ${AUTH[@]+"${AUTH[@]}"} -w '\n%{http_code}' "$@" "$URL$path"); then
        echo "${0##*/}: cannot reach spinmodald at $URL ($method $path)" >&2
        exit 3
    fi
    code=${out##*$'\n'}
    body=${out%$'\n'*}
    if [ "$code" -ge 200 ] && [ "$code" -lt 300 ]; then
        printf '%s' "$body"
        return 0
    fi
    echo "${0##*/}: HTTP $code from $method $path" >&2
    printf '%s\n' "$body" >&2
    case $code in 400|413|415|422) exit 2 ;; *) exit 3 ;; esac
}

case ${1:-} in
    -h|--help) usage; exit 0 ;;
    '') usage >&2; exit 64 ;;
esac
[ $# -eq 1 ] || { usage >&2; exit 64; }

if [[ $1 =~ ^[0-9a-f]{64}$ ]]; then
    api GET "/v1/analyses/$1/result?format=csv"
    exit 0
fi
if [ "$1" != - ] && [ ! -r "$1" ]; then echo "${0##*/}: cannot read $1" >&2; exit 2; fi

# A request: submit.sh waits for the job and prints its final status document.
rc=0
status=$("$(dirname "$0")/submit.sh" --status "$1") || rc=$?
[ $rc -le 1 ] || exit $rc
# Job id, and whether a result is stored (done, or failed by no equilibrium).
read -r id has_result < <(python3 -c 'import json, sys
d = json.load(sys.stdin); print(d["id"], int(d.get("result") is not None))' <<<"$status")
if [ "$has_result" = 1 ]; then
    api GET "/v1/analyses/$id/result?format=csv"
fi
exit $rc
