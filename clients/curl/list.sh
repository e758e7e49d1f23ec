#!/usr/bin/env bash
# list.sh — list spinmodald jobs, newest first.
#
#   list.sh [--state queued|running|done|failed|canceled] [--limit N] [--all] [--json]
#
# GET /v1/analyses?limit=N[&state=S].  Prints one line per job: id, state, progress
# (speeds done/total), created_at.  The daemon answers a page of N jobs (1...100, default 20)
# and a "next" link to the older ones; --all follows the links to the end, otherwise the
# command for the next page is printed on stderr.  --json prints each status document as one
# JSON line instead.
#
# Environment: SPINMODAL_URL (default http://127.0.0.1:8080), SPINMODAL_TOKEN (bearer token;
# not needed for reading).  Needs curl and python3.
#
# Exit status: 0 ok; 2 bad parameter (HTTP 400); 3 connection error or other HTTP error; 64 usage.
set -euo pipefail

usage() { echo "usage: ${0##*/} [--state queued|running|done|failed|canceled] [--limit N] [--before SEQ] [--all] [--json]"; }

URL=${SPINMODAL_URL:-http://127.0.0.1:8080}
URL=${URL%/}
AUTH=()
if [ -n "${SPINMODAL_TOKEN:-}" ]; then AUTH=(-H "Authorization: Bearer $SPINMODAL_TOKEN"); fi

state='' limit=20 before='' all=0 json=0
while [ $# -gt 0 ]; do
    case $1 in
        -h|--help) usage; exit 0 ;;
        --state|--limit|--before)
            [ $# -ge 2 ] || { usage >&2; exit 64; }
            case $1 in --state) state=$2 ;; --limit) limit=$2 ;; --before) before=$2 ;; esac
            shift ;;
        --all) all=1 ;;
        --json) json=1 ;;
        *) usage >&2; exit 64 ;;
    esac
    shift
done

path="/v1/analyses?limit=$limit${before:+&before=$before}${state:+&state=$state}"
while [ -n "$path" ]; do
    if ! out=$(curl -sS ${AUTH[@]+"${AUTH[@]}"} -w '\n%{http_code}' "$URL$path"); then
        echo "${0##*/}: cannot reach spinmodald at $URL" >&2
        exit 3
    fi
    code=${out##*$'\n'}
    body=${out%$'\n'*}
    if [ "$code" != 200 ]; then
        echo "${0##*/}: HTTP $code from GET $path" >&2
        printf '%s\n' "$body" >&2
        [ "$code" = 400 ] && exit 2
        exit 3
    fi
    # Print the page; the last line of python's output is "next:" + the next path ("" at the end).
    # The state filter is added to "next" if the daemon left it out.
    page=$(python3 -c 'import json, sys
doc = json.load(sys.stdin)
as_json, state = sys.argv[1] == "1", sys.argv[2]
for it in doc.get("items") or []:
    if as_json:
        print(json.dumps(it))
    else:
        p = it.get("progress") or {}
        print("%s  %-8s  %5s/%-5s  %s" % (it.get("id"), it.get("state"), p.get("done", ""),
                                          p.get("total", ""), it.get("created_at") or ""))
nxt = doc.get("next") or ""
if nxt and state and "state=" not in nxt:
    nxt += ("&" if "?" in nxt else "?") + "state=" + state
print("next:" + nxt)' "$json" "$state" <<<"$body")
    last=${page##*$'\n'}
    next=${last#next:}
    if [ "$page" = "$last" ]; then page=; else page=${page%$'\n'*}; fi
    [ -z "$page" ] || printf '%s\n' "$page"
    path=
    if [ -n "$next" ]; then
        if [ $all = 1 ]; then
            path=$next
        else
            more=$(python3 -c 'import sys, urllib.parse as u
print(u.parse_qs(u.urlsplit(sys.argv[1]).query).get("before", [""])[0])' "$next")
            echo "more: ${0##*/} --limit $limit${state:+ --state $state} --before $more" >&2
        fi
    fi
done
