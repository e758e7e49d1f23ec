"""Hostile bodies for POST /v1/analyses and POST /v1/validate (attack.py, category 'bodies').

Every case is a request body nobody should get a job or a 5xx for: broken JSON,
numbers and nesting at and past what a parser or a double holds, wrong types,
arrays and counts within and beyond the limits, unicode tricks in names and
keys, duplicate keys, models too large or too costly to build, degenerate
geometry.  Each is sent to both routes on a fresh connection; the answer must
be a 4xx problem document (application/problem+json) whose errors carry a
JSON pointer (400 and 422; 413 is about the body as a whole and has none), the
expected status and pointer when the case names one, within the time budget.

A few bodies are well-formed but absurd (a speed of 1e308 rad/s, a point mass
of 1e308 kg, a twist of 1e308 degrees): the codec takes them, as it should (a
request within the schema), and the invariant is then about the job: it must
end, done or failed with the solver's own error type, with no NaN or infinity
in any number of its result.

A case: name, body (bytes), expect (statuses, or JOB), pointer (exact, or a
prefix ending in '*'), chunked (send with Transfer-Encoding: chunked).
"""
import copy
import json
import time

from common import (is_problem, livez, nonfinite, outcome_of, problem_pointers,
                    raw_exchange, small_request, solved_nan, timescale, wait_until)

MAX_BODY = 1048576   # the daemon's default --max-body, which the run keeps
JOB = "job"          # expect: accepted (202/200), the job must end cleanly (below)


def _small():
    return small_request(omega=10.0)


def _set(ptr, value, base=None):
    """A copy of the small request with the JSON pointer ptr set to value."""
    doc = copy.deepcopy(base or _small())
    toks = ptr.split("/")[1:]
    cur = doc
    for t in toks[:-1]:
        cur = cur[int(t)] if isinstance(cur, list) else cur.setdefault(t, {})
    last = toks[-1]
    if isinstance(cur, list):
        cur[int(last)] = value
    else:
        cur[last] = value
    return doc


def _j(doc):
    return json.dumps(doc).encode()


def _replace(old, new, base=None):
    text = json.dumps(base or _small())
    assert old in text, old
    return text.replace(old, new, 1).encode()


def _spatial():
    return {"structure": {"joints": {"root": [0.5, 0], "tip": [10.5, 0, 0.3]},
                          "sections": {"blade": {"EA": 2.8e7, "EI_flap": 1.4e4, "EI_edge": 5.6e4,
                                                 "GJ": 1.3e4, "mass_per_length": 1.2}},
                          "members": [{"id": "blade", "from": "root", "to": "tip",
                                       "section": "blade", "elements": 8}],
                          "clamp": "root"},
            "analysis": {"omega": 12, "modes": 4}}


def _blade(**blade):
    b = {"length": 10.0, "hub_radius": 0.5,
         "section": {"EA": 2.8e7, "EI_flap": 1.4e4, "EI_edge": 5.6e4, "GJ": 1.3e4,
                     "mass_per_length": 1.2}, "elements": 8}
    b.update(blade)
    return {"blade": b, "analysis": {"rpm": 100, "modes": 4}}


def _chain(n, elements=1, name_len=1):
    """A chain of n members O-j1-j2-... (n joints + 1); names padded to name_len."""
    def jn(i):
        return ("j%d" % i).ljust(name_len, "x")
    joints = {jn(i): [float(i), 0.0] for i in range(n + 1)}
    members = [{"id": "m%d" % i, "from": jn(i), "to": jn(i + 1), "section": "s",
                "elements": elements} for i in range(n)]
    return {"structure": {"joints": joints,
                          "sections": {"s": {"E": 7e10, "A": 4e-4, "I": 2e-7,
                                             "mass_per_length": 1.2}},
                          "members": members, "clamp": jn(0)},
            "analysis": {"omega": 1.0}}


def _padded(body, size):
    """body (a JSON object text) padded with spaces before its closing brace to size bytes."""
    assert body.endswith(b"}") and len(body) <= size
    return body[:-1] + b" " * (size - len(body)) + b"}"


def cases(quick=False):
    """The catalogue, as a list of dicts (quick: a fixed subset of about 25)."""
    S = _small()
    c = []

    def add(name, body, expect, pointer=None, chunked=False, quick_too=False):
        c.append({"name": name, "body": body, "expect": tuple(expect), "pointer": pointer,
                  "chunked": chunked, "quick": quick_too})

    # --- syntax: 400 with pointer "" -----------------------------------------
    good = _j(S)
    add("truncated-object", good[:len(good) // 2], [400], "", quick_too=True)
    add("empty-body", b"", [400], "", quick_too=True)
    add("whitespace-only", b" \r\n\t " * 100, [400], "")
    add("utf8-bom-prefix", b"\xef\xbb\xbf" + good, [400], "")
    add("trailing-comma", good[:-1] + b",}", [400], "")
    add("single-quotes", good.replace(b'"', b"'"), [400], "")
    add("comment", good[:-1] + b" /* x */}", [400], "")
    add("two-documents", good + good, [400], "", quick_too=True)
    add("NaN-literal", _replace('"E": 70000000000.0', '"E": NaN'), [400], "", quick_too=True)
    add("Infinity-literal", _replace('"omega": 10.0', '"omega": Infinity'), [400], "")
    add("minus-Infinity-literal", _replace('"A": 0.0004', '"A": -Infinity'), [400], "")
    add("number-1e999", _replace('"E": 70000000000.0', '"E": 1e999'), [400], "", quick_too=True)
    add("number-minus-1e999", _replace('"omega": 10.0', '"omega": -1e999'), [400], "")
    add("hex-number", _replace('"omega": 10.0', '"omega": 0x10'), [400], "")
    add("leading-zeros", _replace('"omega": 10.0', '"omega": 007'), [400], "")
    add("leading-plus", _replace('"omega": 10.0', '"omega": +1'), [400], "")
    add("bare-fraction", _replace('"omega": 10.0', '"omega": .5'), [400], "")
    add("trailing-dot", _replace('"omega": 10.0', '"omega": 1.'), [400], "")
    add("integer-2^64", _replace('"elements": 4', '"elements": 18446744073709551616'), [400], "")
    add("integer-1e400-digits", _replace('"elements": 4', '"elements": ' + "9" * 400), [400], "")
    add("number-10k-digits", _replace('"omega": 10.0', '"omega": -1.' + "0" * 10000), [422],
        "/analysis/omega")
    add("deep-arrays-100000", b"[" * 100000 + b"]" * 100000, [400], "", quick_too=True)
    add("deep-objects-100000", b'{"a":' * 100000 + b"1" + b"}" * 100000, [400], "")
    add("deep-arrays-2049", b"[" * 2049 + b"]" * 2049, [400], "")
    add("deep-in-omega-2000", _replace('"omega": 10.0', '"omega": ' + "[" * 2000 + "1" + "]" * 2000),
        [400, 422], "*")
    add("unclosed-deep-10000", b"[" * 10000, [400], "")
    add("invalid-utf8", good.replace(b'"beam1"', b'"beam\xff\xfe1"'), [400], "", quick_too=True)
    add("overlong-utf8", good.replace(b'"beam1"', b'"beam\xc0\xaf1"'), [400], "")
    add("utf8-surrogate-bytes", good.replace(b'"beam1"', b'"beam\xed\xa0\x80"'), [400], "")
    add("lone-surrogate-escape", good.replace(b'"beam1"', b'"beam\\ud800x"'), [400], "")
    add("reversed-surrogates", good.replace(b'"beam1"', b'"\\udc00\\ud800"'), [400], "")
    add("raw-nul-in-string", good.replace(b'"beam1"', b'"beam\x001"'), [400], "")
    add("raw-control-in-string", good.replace(b'"beam1"', b'"beam\x011"'), [400], "")
    add("nul-after-document", good + b"\x00", [400], "")
    add("unterminated-string", good[:good.index(b'"beam1"') + 4], [400], "")
    add("bad-escape", good.replace(b'"beam1"', b'"beam\\x41"'), [400], "")
    add("short-unicode-escape", good.replace(b'"beam1"', b'"beam\\u12"'), [400], "")
    add("duplicate-top-keys", b'{"analysis": {"omega": 1}, "analysis": {"omega": 2}}', [400], "",
        quick_too=True)
    add("duplicate-nested-keys", _replace('"clamp": "O"', '"clamp": "O", "clamp": "C"'), [400], "")
    add("duplicate-key-by-escape", _replace('"clamp": "O"', '"clamp": "O", "\\u0063lamp": "C"'),
        [400], "")
    add("root-array", b"[]", [400, 422], "*")
    add("root-string", b'"structure"', [400, 422], "*")
    add("root-null", b"null", [400, 422], "*")
    add("root-true", b"true", [400, 422], "*")
    add("root-number", b"1e308", [400, 422], "*")
    add("whitespace-padded-to-limit", _padded(_j(_set("/structure/sections/al/E", -1.0)), MAX_BODY),
        [422], "/structure/sections/al/E")

    # --- numbers at the edges of a double: 422 at the field ------------------
    sec = "/structure/sections/al/"
    for key, val in (("E", 1e308), ("A", 1e308), ("mass_per_length", 1e308), ("I", 5e-324),
                     ("E", 4.9e-324), ("E", 1e-320), ("A", 2.2250738585072014e-308)):
        add("%s-%g" % (key, val), _j(_set(sec + key, val)), [422], "*", quick_too=(val == 5e-324))
    add("E-and-A-1e200", _j(_set(sec + "A", 1e200, _set(sec + "E", 1e200))), [422], "*")
    add("omega-1e308", _j(_set("/analysis/omega", 1e308)), [JOB], "/analysis/omega*",
        quick_too=True)
    add("omega-1e150", _j(_set("/analysis/omega", 1e150)), [JOB], "/analysis/omega*")
    add("omega-range-to-1e300", _j(_set("/analysis/omega", {"from": 0, "to": 1e300, "steps": 10})),
        [JOB], "/analysis/omega*")
    add("omega-sweep-with-1e200", _j(_set("/analysis/omega", [0, 1, 1e200])), [JOB],
        "/analysis/omega*")
    add("rpm-1e308", _j(_blade() | {"analysis": {"rpm": 1e308, "modes": 4}}), [JOB],
        "/analysis/rpm*")
    add("joint-at-1e308", _j(_set("/structure/joints/P", [5, 1e308])), [422], "*")
    add("joint-at-1e154", _j(_set("/structure/joints/P", [1e154, 1e154])), [422], "*")
    add("joint-at-minus-1e200", _j(_set("/structure/joints/C", [-1e200, 0])), [422], "*")
    add("joints-1e-300-apart", _j(_set("/structure/joints/C", [1e-300, 0],
                                       _set("/structure/joints/O", [0, 0]))), [422], "*")
    add("elements-2^32+4", _replace('"elements": 4', '"elements": 4294967300'), [422],
        "/structure/members/0/elements", quick_too=True)
    add("elements-2^63-1", _replace('"elements": 4', '"elements": 9223372036854775807'), [422],
        "/structure/members/0/elements")
    add("elements-minus-2^63", _replace('"elements": 4', '"elements": -9223372036854775808'), [422],
        "/structure/members/0/elements")
    add("elements-2.5", _replace('"elements": 4', '"elements": 2.5'), [422],
        "/structure/members/0/elements")
    add("modes-2^32+3", _j(_set("/analysis/modes", 4294967299)), [422], "/analysis/modes",
        quick_too=True)
    add("modes-minus-1", _j(_set("/analysis/modes", -1)), [422], "/analysis/modes")
    add("modes-per-frame-2^31", _j(_set("/analysis/modes_per_frame", 2147483648)), [422],
        "/analysis/modes_per_frame")
    add("point-mass-1e308", _j(_set("/structure/point_masses", [{"joint": "P", "mass": 1e308}])),
        [JOB], "/structure/point_masses*")
    add("twist-1e308", _j(_set("/structure/members/0/twist_deg", 1e308, _spatial())), [JOB],
        "/structure/members/0/twist_deg")
    add("spatial-EA-1e300", _j(_set("/structure/sections/blade/EA", 1e300, _spatial())), [422],
        "/structure/sections/blade*")
    add("blade-length-1e308", _j(_blade(length=1e308)), [422], "/blade*")
    add("blade-hub-radius-1e308", _j(_blade(hub_radius=1e308)), [422], "/blade*")
    add("engine-orders-1e9", _j(_set("/analysis/engine_orders", [1e9])), [422],
        "/analysis/engine_orders*")

    # --- wrong types: 422 at the field ----------------------------------------
    add("structure-string", _j(_set("/structure", "x")), [422], "/structure", quick_too=True)
    add("joints-array", _j(_set("/structure/joints", [[0, 0]])), [422], "/structure/joints")
    add("joint-object", _j(_set("/structure/joints/C", {"x": 5, "y": 0})), [422],
        "/structure/joints/C*")
    add("members-object", _j(_set("/structure/members", {"0": {}})), [422], "/structure/members")
    add("member-number", _j(_set("/structure/members/1", 7)), [422], "/structure/members/1")
    add("omega-object", _j(_set("/analysis/omega", {"x": 1})), [422], "/analysis/omega*")
    add("omega-bool", _j(_set("/analysis/omega", True)), [422], "/analysis/omega")
    add("coriolis-string-true", _j(_set("/analysis/coriolis", "true")), [422], "/analysis/coriolis")
    add("clamp-array", _j(_set("/structure/clamp", ["O"])), [422], "/structure/clamp")
    add("frames-array", _j(_set("/frames", ["single"])), [422], "/frames")
    add("modes-bool", _j(_set("/analysis/modes", True)), [422], "/analysis/modes")
    add("range-steps-1e9", _j(_set("/analysis/omega", {"from": 0, "to": 1, "steps": 1e9})), [422],
        "/analysis/omega*")
    add("range-steps-minus-1", _j(_set("/analysis/omega", {"from": 0, "to": 1, "steps": -1})),
        [422], "/analysis/omega*")
    add("range-steps-1.5", _j(_set("/analysis/omega", {"from": 0, "to": 1, "steps": 1.5})),
        [422], "/analysis/omega*")

    # --- arrays and counts within and beyond the limits -----------------------
    add("speeds-1002", _j(_set("/analysis/omega", [0.1 * i for i in range(1002)])), [422],
        "/analysis/omega*", quick_too=True)
    add("speeds-150000", _j(_set("/analysis/omega", [1] * 150000)), [422], "/analysis/omega*")
    add("speeds-1001-last-bad", _j(_set("/analysis/omega", [1.0] * 1000 + ["x"])), [422],
        "/analysis/omega/1000")
    add("joints-1001", _j(_chain(1000)), [422], "/structure/joints*")
    add("joints-40000-short", _j(_set("/structure/joints", {"j%d" % i: [i, 0]
                                                             for i in range(40000)})),
        [422], "/structure/joints*")
    add("sections-1001", _j(_set("/structure/sections",
                                 {"s%d" % i: {"E": 1, "A": 1, "I": 1, "mass_per_length": 1}
                                  for i in range(1001)})), [422], "/structure/sections*")
    add("members-1001", _j(_chain(1001)), [422], "*")
    add("members-2000-each-10-elements", _j(_chain(999, elements=10)), [422], "*")
    add("elements-total-2001", _j(_chain(1, elements=2001)), [422], "*", quick_too=True)
    add("error-storm-999-sections", _j(_set("/structure/sections",
                                            {"s%d" % i: {"E": -1, "A": "x", "I": None,
                                                         "mass_per_length": [], "Q": 1}
                                             for i in range(999)})), [422], "/structure/sections*")
    add("name-900KB-unknown-joint", _j(_set("/structure/members/0/to", "J" * 900000)), [422],
        "/structure/members/0/to", quick_too=True)
    add("key-900KB", _j(_set("/analysis/" + "k" * 900000, 1)), [422], "/analysis/k*")
    add("body-exactly-max", _padded(_j(_set("/analysis/omega", -1)), MAX_BODY), [422],
        "/analysis/omega")
    add("body-max-plus-1", _padded(_j(_set("/analysis/omega", -1)), MAX_BODY + 1), [413], None,
        quick_too=True)
    add("body-8MB", _padded(_j(_set("/analysis/omega", -1)), 8 * MAX_BODY), [413], None)
    add("body-max-plus-1-chunked", _padded(_j(_set("/analysis/omega", -1)), MAX_BODY + 1), [413],
        None, chunked=True)
    add("invalid-chunked", _j(_set("/analysis/omega", -1)), [422], "/analysis/omega",
        chunked=True, quick_too=True)

    # --- models too large or too costly to build, degenerate geometry --------
    big = _chain(1, elements=2000)
    big["frames"] = "single"
    add("single-frame-over-2000-elements", _j(big), [422], "/frames", quick_too=True)
    big2 = _chain(1, elements=1000)
    big2["frames"] = "single"
    add("single-frame-over-1000-elements", _j(big2), [422], "/frames")
    pe = _chain(2, elements=1000)
    pe["frames"] = {"elements_per_frame": 20}
    add("coordinates-over-4000", _j(pe), [422], "/structure")
    est = _chain(1, elements=1500)
    est["analysis"]["error_estimate"] = True
    add("error-estimate-over-limits", _j(est), [422], "/analysis/error_estimate")
    add("zero-length-member", _j(_set("/structure/joints/C", [0, 0])), [422], "*", quick_too=True)
    add("member-same-joint", _j(_set("/structure/members/1/to", "C")), [422], "/structure/members*")
    cyc = _small()
    cyc["structure"]["members"].append({"id": "beam3", "from": "P", "to": "O", "section": "al",
                                        "elements": 2})
    add("cycle", _j(cyc), [422], "/structure/members*")
    add("clamp-unknown", _j(_set("/structure/clamp", "Z")), [422], "/structure/clamp")
    add("stations-1001", _j(_blade(stations=[{"s": i / 1000.0, "mass_per_length": 1.0}
                                              for i in range(1001)])), [422], "/blade/stations*")
    add("stations-not-increasing", _j(_blade(stations=[{"s": 0, "mass_per_length": 1},
                                                        {"s": 0.5, "mass_per_length": 1},
                                                        {"s": 0.4, "mass_per_length": 1},
                                                        {"s": 1, "mass_per_length": 1}])),
        [422], "/blade/stations*")
    add("blade-elements-2001", _j(_blade(elements=2001)), [422], "/blade*")
    add("engine-orders-17", _j(_set("/analysis/engine_orders", list(range(1, 18)))), [422],
        "/analysis/engine_orders*")
    # issue 23 item 9: a small request for a huge result (3.9 M shape numbers, 94 MB), and the
    # largest sweep of a 2000-element model without shapes (its steady states ~200 MB)
    big = _blade(elements=2000)
    big["analysis"] = {"rpm": {"from": 0, "to": 260, "steps": 26}, "modes": 6, "mode_shapes": True}
    # issue 23 item 1: a ~240-byte request for 200 modes of a 666-element blade (on 0.7.0 ~100 s
    # and 2.3 GB a speed on the dense path); a dense sweep estimated past --job-timeout
    many = _blade(elements=666)
    many["analysis"] = {"omega": [10], "modes": 200, "mode_shapes": False}
    add("modes-200-of-666-elements", _j(many), [422], "/analysis/modes", quick_too=True)
    dense = _blade(elements=150)
    dense["analysis"] = {"omega": [0.2 * i for i in range(101)], "modes": 100, "mode_shapes": False}
    add("dense-sweep-past-job-timeout", _j(dense), [422], "/analysis/omega")
    add("result-94MB-shapes", _j(big), [422], "/analysis/mode_shapes", quick_too=True)
    sweep = _blade(elements=2000)
    sweep["analysis"] = {"rpm": {"from": 0, "to": 1000, "steps": 1000}, "modes": 10,
                         "mode_shapes": False}
    add("result-steady-states-1001-speeds", _j(sweep), [422], "/analysis/rpm")

    # --- unicode tricks in names and keys: pointers escaped right -------------
    weird = _small()
    weird["structure"]["sections"] = {"a/b~c": {"E": -1, "A": 4e-4, "I": 2e-7,
                                                "mass_per_length": 1.2}}
    for m in weird["structure"]["members"]:
        m["section"] = "a/b~c"
    add("section-name-slash-tilde", _j(weird), [422], "/structure/sections/a~1b~0c/E",
        quick_too=True)
    add("rtl-override-joint", _j(_set("/structure/members/0/to", "C\u202e")), [422],
        "/structure/members/0/to")
    add("zero-width-joint", _j(_set("/structure/members/0/to", "C\u200b")), [422],
        "/structure/members/0/to")
    add("homoglyph-top-key", _replace('"structure"', '"\u0455tructure"'), [422], "*")
    add("nul-escape-in-name", _j(_set("/structure/clamp", "O\u0000")), [400], "")
    add("quote-newline-in-id", _j(_set("/structure/members/0/section", "al\"\n\\")), [422],
        "/structure/members/0/section")
    add("emoji-unknown-key", _j(_set("/analysis/\U0001f4a5", 1)), [422], "/analysis/\U0001f4a5")
    add("empty-key", _j(_set("/analysis/", 1)), [422], "/analysis/")
    if quick:
        c = [x for x in c if x["quick"]]
    return c


def chunked(body, size=4096):
    out = []
    for i in range(0, len(body), size):
        part = body[i:i + size]
        out.append(b"%x\r\n" % len(part) + part + b"\r\n")
    out.append(b"0\r\n\r\n")
    return out


def _pointer_ok(want, pointers):
    if want is None:
        return True
    if want.endswith("*"):
        return any(isinstance(p, str) and p.startswith(want[:-1]) for p in pointers)
    return want in pointers


def send(d, route, case, timeout):
    """POST case's body to route on a fresh connection; the Response."""
    body = case["body"]
    lines = ["POST %s HTTP/1.1" % route, "Host: 127.0.0.1:%d" % d.port,
             "Content-Type: application/json", "Connection: close"]
    if case["chunked"]:
        lines.append("Transfer-Encoding: chunked")
        head = ("\r\n".join(lines) + "\r\n\r\n").encode()
        return raw_exchange(d.host, d.port, head, iter(chunked(body)), False, timeout)
    lines.append("Content-Length: %d" % len(body))
    head = ("\r\n".join(lines) + "\r\n\r\n").encode()
    parts = [body[i:i + 65536] for i in range(0, len(body), 65536)]
    return raw_exchange(d.host, d.port, head, iter(parts), False, timeout)


def run(d, tally, quick=False, category="bodies"):
    """Send every case to both routes.  Returns the (name, id) of the jobs the
    well-formed absurd cases (JOB) made, for follow(); any other case the
    daemon accepts breaks the invariant."""
    accepted = []
    for case in cases(quick):
        job_case = JOB in case["expect"]
        for route in ("/v1/analyses", "/v1/validate"):
            what = "%s %s" % (case["name"], route)
            t0 = time.monotonic()
            try:
                r = send(d, route, case, timescale.budget(30))
            except OSError as e:
                tally.add(category, "connection error")
                tally.broken(category, "%s: %r" % (what, e))
                continue
            took = time.monotonic() - t0
            out = outcome_of(r)
            st = r.status
            pointers = problem_pointers(r) or []
            if job_case:
                good = st in ((200, 202) if route == "/v1/analyses" else (200,))
                if good and route == "/v1/analyses":
                    accepted.append((case["name"], (r.json() or {}).get("id")))
                tally.add(category, "%s well-formed absurd, %s" % (
                    out, "accepted" if good else "UNEXPECTED"))
                tally.check(good, category, "%s: accepted as a job (got %s %s)"
                            % (what, out, r.text(160)))
                continue
            good = st in case["expect"]
            if isinstance(st, int) and 400 <= st < 500:
                good = good and is_problem(r)
                if st in (400, 422):
                    good = good and bool(pointers) and all(isinstance(p, str) for p in pointers)
                good = good and _pointer_ok(case["pointer"], pointers)
            tally.add(category, "%s %s" % (out, "as expected" if good else "UNEXPECTED"))
            tally.check(isinstance(st, int) and 400 <= st < 500, category,
                        "%s: a 4xx (got %s %s, %.2f s)" % (what, out, r.text(160), took))
            tally.check(good, category, "%s: status %s with pointer %r (got %s, pointers %s: %s)"
                        % (what, "/".join(map(str, case["expect"])), case["pointer"], out,
                           pointers[:3], r.text(200)))
            if tally.verbose:
                print("  %-40s %-13s %s %.3f s %s" % (case["name"], route, out, took, pointers[:2]))
        if not livez(d):
            tally.broken(category, "after %s: /livez does not answer (alive: %s)"
                         % (case["name"], d.alive()))
            if not d.alive():
                break
    return accepted


CLEAN_FAILURES = ("no_equilibrium", "eigen_failed", "solver_error", "timeout")


def follow(d, tally, accepted, category="bodies"):
    """Each job of a well-formed absurd body must end (done, or failed with a
    solver's error type) and have no NaN or infinity in a solved case."""
    for name, jid in accepted:
        def ended():
            doc = d.get("/v1/analyses/%s?wait=5" % jid).json() or {}
            return doc if doc.get("state") in ("done", "failed", "canceled") else None
        doc = wait_until(ended, 120) if jid else None
        state = doc.get("state") if doc else "not finished"
        etype = ((doc or {}).get("error") or {}).get("type")
        tally.add(category + " jobs", "%s%s" % (state, " " + etype if etype else ""))
        tally.check(doc is not None and (state == "done" or etype in CLEAN_FAILURES), category,
                    "%s: the job ends done or failed by the solver (%s %s)" % (name, state, etype))
        res = (doc or {}).get("result")
        if res is not None:
            where = solved_nan(res) or nonfinite(res)
            tally.check(where is None, category, "%s: no NaN or infinity in the result (%s)"
                        % (name, where))
