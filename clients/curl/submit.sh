#!/usr/bin/env bash
# submit.sh — submit an analysis request to spinmodald, wait for it, print the result JSON.
#
#   submit.sh [--status | --id] [--wait S] [--no-wait] REQUEST.json|-
#
# POSTs the request (POST /v1/analyses?wait=S: the daemon holds the answer up to S seconds),
# then long-polls GET /v1/analyses/ID?wait=S until the job is done, failed or canceled.
# Prints the result document (GET /v1/analyses/ID/result) on stdout; --status prints the final
# status document instead, --id only the job id.  --no-wait: POST only, print the status
# document (or the id) as answered, do not wait (exit 0 unless it is already failed/canceled).
# The API is described in server/DAEMON.md.
#
# Environment: SPINMODAL_URL (default http://127.0.0.1:8080), SPINMODAL_TOKEN (bearer token,
# needed for POST/DELETE when the daemon runs with --token-file).  Needs curl and python3.
#
# Exit status: 0 done; 1 the job failed or was canceled (its error on stderr; a result stored
# for a failed job — no equilibrium at some speeds — is still printed); 2 invalid request
# (HTTP 400/413/415/422, the problem document on stderr); 3 connection error or any other
# HTTP error; 64 usage.
set -euo pipefail

usage() { echo "usage: ${0##*/} [--status | --id] [--wait S] [--no-wait] REQUEST.json|-"; }

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
        printf '%s\n' "$body"
        return 0
    fi
    echo "${0##*/}: HTTP $code from $method $path" >&2
    printf '%s\n' "$body" >&2
    case $code in 400|413|415|422) exit 2 ;; *) exit 3 ;; esac
}

# has NAME: read a status document on stdin, succeed when it has a non-null field NAME.
has() {
    python3 -c 'import json, sys; sys.exit(json.load(sys.stdin).get(sys.argv[1]) is None)' "$1"
}

# field NAME: read a status document on stdin, print one top-level field ("" when absent/null).
field() {
    python3 -c 'import json, sys
v = json.load(sys.stdin).get(sys.argv[1])
print("" if v is None else v if isinstance(v, str) else json.dumps(v))' "$1"
}

show=result wait=30 file='' nowait=0
while [ $# -gt 0 ]; do
    case $1 in
        -h|--help) usage; exit 0 ;;
        --status) show=status ;;
        --id) show=id ;;
        --no-wait) nowait=1 ;;
        --wait) [ $# -ge 2 ] || { usage >&2; exit 64; }; wait=$2; shift ;;
        -) [ -z "$file" ] || { usage >&2; exit 64; }; file=- ;;
        -*) usage >&2; exit 64 ;;
        *) [ -z "$file" ] || { usage >&2; exit 64; }; file=$1 ;;
    esac
    shift
done
[ -n "$file" ] || { usage >&2; exit 64; }
if [ "$file" != - ] && [ ! -r "$file" ]; then echo "${0##*/}: cannot read $file" >&2; exit 2; fi

# Submit; the answer is the status document (200 with the result when already done).
[ $nowait = 0 ] || wait=0
status=$(api POST "/v1/analyses?wait=$wait" -H 'Content-Type: application/json' --data-binary "@$file")
id=$(field id <<<"$status")
state=$(field state <<<"$status")

if [ $nowait = 1 ]; then
    if [ $show = id ]; then echo "$id"; else printf '%s\n' "$status"; fi
    case $state in failed|canceled) echo "${0##*/}: job $id $state" >&2; exit 1 ;; esac
    exit 0
fi

# Long-poll until the job leaves queued/running.
while [ "$state" = queued ] || [ "$state" = running ]; do
    sleep 0.2   # (only matters if a proxy cuts long polls short)
    status=$(api GET "/v1/analyses/$id?wait=$wait")
    state=$(field state <<<"$status")
done

case $show in
    id) echo "$id" ;;
    status) printf '%s\n' "$status" ;;
    result)
        # A result is stored when the job is done, and when it failed by no equilibrium.
        if [ "$state" = "done" ] || has result <<<"$status"; then
            api GET "/v1/analyses/$id/result"
        fi ;;
esac
if [ "$state" != "done" ]; then
    error=$(field error <<<"$status")
    echo "${0##*/}: job $id $state${error:+: $error}" >&2
    exit 1
fi
