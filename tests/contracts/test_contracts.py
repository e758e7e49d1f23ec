#!/usr/bin/env python3
"""Contract tests: schemas/ against the codec's cases, the CLI's real output and DAEMON.md.

Usage: test_contracts.py [--source-root DIR] [--spinmodal EXE] GROUP
  GROUP: schemas | requests | invalid | cli | openapi | negative | all
meson registers one test per group (suite 'contracts').  Each check prints one
line "ok   ..." or "FAIL ..."; the exit status is 1 on any failure.

Needs Python 3.11 and jsonschema >= 4.10 (Debian 12: python3-jsonschema 4.10.3).
"""
import argparse
import copy
import glob
import json
import os
import subprocess
import sys
import tempfile

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

try:
    import contract  # noqa: E402
except ImportError as e:  # jsonschema missing: a failure with its cause, not a skip
    print("FAIL cannot import contract.py: %s (install python3-jsonschema)" % e)
    sys.exit(1)

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
EXE = None
C = None
FAILURES = []

# ------------------------------------------------------------------ helpers


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILURES.append(what)
    return cond


def note(what):
    print("note " + what)


def read_json(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def ptr(path):
    """JSON pointer of a jsonschema error path."""
    return "".join("/" + str(p).replace("~", "~0").replace("/", "~1") for p in path)


def all_error_pointers(errors):
    """Pointers of errors and of their oneOf/anyOf sub-errors."""
    out = []
    stack = list(errors)
    while stack:
        e = stack.pop()
        out.append(ptr(e.absolute_path))
        stack.extend(e.context or [])
    return out


def related(a, b):
    """a is b, or one is a prefix (by whole tokens) of the other."""
    return a == b or b.startswith(a + "/") or a.startswith(b + "/") or a == "" or b == ""


def validates(instance, name, what):
    errs = C.errors(instance, name)
    if errs:
        e = errs[0]
        return check(False, "%s validates against %s: %s at %s" % (what, name, e.message[:300], ptr(e.absolute_path)))
    return check(True, "%s validates against %s" % (what, name))


def rejected(instance, name, what):
    return check(not C.is_valid(instance, name), "%s is rejected by %s" % (what, name))


def run_cli(args, stdin=None, timeout=600):
    p = subprocess.run([EXE] + args, input=stdin, capture_output=True, timeout=timeout)
    return p.returncode, p.stdout.decode("utf-8", "replace"), p.stderr.decode("utf-8", "replace")


CASES = os.path.join(ROOT, "tests", "codec", "cases")


def codec_cases():
    """(name, dir, valid) for every tests/codec/cases/<name>/."""
    out = []
    for d in sorted(glob.glob(os.path.join(CASES, "*", ""))):
        d = d.rstrip(os.sep)
        if os.path.exists(os.path.join(d, "request.json")):
            out.append((os.path.basename(d), d, not os.path.exists(os.path.join(d, "expected-error.json"))))
    return out


def load_case_request(d, name="request.json"):
    """The parsed request, or None when it is not JSON (malformed-json, duplicate keys ...)."""
    def no_dupes(pairs):
        keys = [k for k, _ in pairs]
        if len(keys) != len(set(keys)):
            raise ValueError("duplicate key")
        return dict(pairs)
    try:
        with open(os.path.join(d, name), encoding="utf-8") as f:
            return json.load(f, object_pairs_hook=no_dupes,
                             parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
    except (ValueError, UnicodeDecodeError):
        return None


# Invalid codec cases whose error a JSON Schema expresses: the schema must reject
# them too, with an error at (or above/below) the codec's JSON pointer.
SCHEMA_REJECTS = [
    "E-string", "I-null", "analysis-not-object", "clamp-number", "coriolis-string",
    "elements-fraction", "elements-missing", "elements-string", "elements-zero",
    "frames-elements-per-frame-fraction", "frames-number", "frames-per-member-zero",
    "frames-two-keys", "frames-unknown-key", "frames-unknown-string", "joint-coord-string",
    "joint-name-escaped", "joint-not-array", "joint-three-coords", "joints-empty",
    "joints-not-object", "many-errors", "mass-foo", "member-from-number", "member-id-empty",
    "member-id-number", "member-missing-to", "member-not-object", "member-unknown-key",
    "members-empty", "members-missing", "members-not-array", "missing-analysis",
    "missing-clamp", "missing-omega", "missing-structure", "mode-shapes-null",
    "modes-fraction", "modes-per-frame-string", "modes-per-frame-zero", "modes-too-many",
    "modes-zero", "negative-E", "negative-mass-per-length", "omega-array-negative",
    "omega-array-of-strings", "omega-empty-array", "omega-negative", "omega-string",
    "point-mass-negative", "point-mass-unknown-key", "point-masses-not-array",
    "root-not-object", "section-missing-I", "section-not-object", "section-unknown-key",
    "sections-not-object", "stiffening-number", "structure-not-object",
    "substructure-modes-foo", "unknown-analysis-key", "unknown-structure-key",
    "unknown-top-level-key", "unknown-top-level-key-typo", "zero-A",
    # spatial requests (DESIGN.md 7.3)
    "spatial-mixed-kinds", "spatial-mixed-kinds-planar-second", "section-mixes-forms",
    "section-material-with-I", "section-stiffness-missing-GJ", "section-material-missing-J",
    "section-planar-with-inertia", "twist-with-planar", "flap-direction-with-planar",
    "point-mass-inertia-with-planar", "paper-basis-spatial", "twist-string", "spatial-EA-zero",
    "spatial-GJ-negative", "spatial-flap-inertia-negative", "spatial-edge-inertia-negative",
    "spatial-EI-flap-null", "flap-direction-zero", "flap-direction-two-numbers",
    "flap-direction-string", "point-mass-inertia-negative", "point-mass-inertia-number",
    # blades (DESIGN.md 8)
    "stations-with-planar", "stations-s-outside", "stations-only-one", "stations-not-array",
    "stations-entry-not-object", "stations-s-missing", "stations-non-numeric",
    "stations-negative-stiffness", "stations-zero-mass", "stations-negative-inertia",
    "stations-unknown-key", "stations-material-key", "stations-offset-one-number",
    "stations-too-many", "section-offset-with-planar", "section-offset-string",
    "point-mass-offset-two-numbers", "point-mass-products-with-planar", "rpm-and-omega",
    "rpm-negative", "range-unknown-key", "speeds-missing", "blade-and-structure",
    "blade-length-zero", "blade-length-missing", "blade-precone-90", "blade-hub-radius-negative",
    "blade-elements-zero", "blade-unknown-key", "blade-station-error", "blade-tip-inertia-negative",
    "blade-tip-mass-missing", "blade-paper-basis", "blade-not-object", "blade-planar-section",
    # analysis.rotary_inertia (DESIGN.md 8.5)
    "rotary-inertia-unknown", "rotary-inertia-planar",
]

# Invalid codec cases a JSON Schema cannot express (not forced; printed for information).
SCHEMA_CANNOT = {
    "malformed-json": "not JSON at all (400 before any schema applies)",
    "duplicate-key": "duplicate object keys: JSON parsers keep one, the codec rejects the text (400)",
    "number-overflow": "1e400 overflows a double: a parse error (400) in the codec",
    "request-too-large": "a byte limit of the request text (413)",
    "clamp-unknown-joint": "reference: the clamp must name a key of structure.joints",
    "unknown-joint-from": "reference: member.from must name a key of structure.joints",
    "unknown-joint-to": "reference: member.to must name a key of structure.joints",
    "unknown-section": "reference: member.section must name a key of structure.sections",
    "point-mass-unknown-joint": "reference: point_mass.joint must name a key of structure.joints",
    "duplicate-member-id": "uniqueness of a property across array items",
    "member-same-joint": "from != to compares two values of the instance",
    "zero-length-member": "needs the coordinates of the referenced joints",
    "clamp-not-on-member": "topology: the clamp must be an end of some member",
    "joint-not-on-member": "topology: every joint must be an end of some member",
    "cycle": "topology (found by sm_model_new)",
    "disconnected-member": "topology (found by sm_model_new)",
    "too-many-elements-total": "a sum over members (server limit --max-elements)",
    "too-many-elements-member": "configurable server limit --max-elements (not a fixed maximum)",
    "too-many-elements-huge": "configurable server limit --max-elements (not a fixed maximum)",
    "too-many-speeds-default": "configurable server limit --max-speeds (not a fixed maxItems)",
    "too-many-speeds": "run with a lowered limit (max_speeds 3); valid at the default limits",
    "too-many-joints": "run with a lowered limit (max_joints 2); valid at the default limits",
    "too-many-members": "run with a lowered limit (max_members 1); valid at the default limits",
    "too-many-shape-values": "a product speeds x modes x nodes x 3 (x 2) against 4e6",
    "twist-overflow": "1e400 overflows a double: a parse error (400) in the codec",
    "material-EA-overflows": "a product of two fields (EA = E*A) overflows",
    "spatial-default-inertia-overflows": "a computed default (mass_per_length*EI_flap/EA) overflows",
    "spatial-zero-length-member": "needs the coordinates of the referenced joints ([x, y] is z = 0)",
    "spatial-stiffness-range": "element stiffness EI_flap/l^3 needs the element lengths",
    "material-EA-range": "element stiffness E*A/l needs a product and the element lengths",
    "spatial-shape-values": "a product speeds x modes x nodes x 6 (x 2) against a lowered limit",
    "spatial-on-axis-no-flap-direction": "geometry: a member on the spin axis at radius zero (core)",
    "spatial-flap-direction-along-member": "geometry: flap_direction parallel to the member (core)",
    "spatial-frame-too-large": "a cost bound from the model's sizes (lowered --max-frame-dofs)",
    "stations-s-not-increasing": "order of values across array items",
    "stations-s-repeated": "order of values across array items",
    "stations-first-not-zero": "a value of the first array item (prefixItems would do; kept simple)",
    "stations-last-not-one": "a value of the last array item",
    "stations-missing-key": "the same keys at every array item",
    "stations-section-not-completed": "a section completed by its members' stations (cross-reference)",
    "point-mass-products-not-psd": "positive semi-definiteness of a tensor from two fields",
    "blade-tip-not-psd": "positive semi-definiteness of a tensor from two fields",
    "range-to-below-from": "to >= from compares two values",
    "range-steps-zero": "steps >= 1 unless from == to compares values",
    "range-too-many-speeds": "run with a lowered limit (max_speeds 3)",
    "blade-station-missing-key": "the same keys at every array item",
    "blade-section-incomplete": "a section completed by the stations (cross-reference)",
    "blade-no-section-no-stations": "a section completed by the stations (cross-reference)",
}

# Valid codec cases a JSON Schema cannot accept (the codec is more permissive than the schema).
SCHEMA_CANNOT_ACCEPT = {
    "stations-complete-section": "a section may leave out what the stations of every member "
                                 "using it give (DESIGN.md 8): a cross-reference between sections "
                                 "and members; the schema asks for complete sections there",
}

# --------------------------------------------------------------------- groups


def t_schemas():
    """The schemas themselves are valid 2020-12 schemas with the right $id."""
    for name, schema in (("request.schema.json", C.request), ("result.schema.json", C.result)):
        try:
            contract.Draft202012Validator.check_schema(schema)
            check(True, "%s is a valid 2020-12 schema" % name)
        except contract.jsonschema.SchemaError as e:
            check(False, "%s is a valid 2020-12 schema: %s" % (name, e.message))
    probs = C.check_schemas()
    check(not probs, "component schemas valid, $id and $schema right %s" % (probs or ""))
    probs = C.check_refs()
    check(not probs, "every $ref of the three documents resolves locally %s" % (probs or ""))
    check(C.request.get("$id") == contract.REQUEST_ID, "request $id")
    check(C.result.get("$id") == contract.RESULT_ID, "result $id")

    # every property of the request schema has a title and a description
    missing = []

    def walk(node, where):
        if isinstance(node, dict):
            for key in ("properties",):
                for pname, sub in node.get(key, {}).items():
                    if isinstance(sub, dict) and not ("$ref" in sub and len(sub) == 1):
                        if not sub.get("title") or not sub.get("description"):
                            missing.append(where + "/" + key + "/" + pname)
            for k, v in node.items():
                walk(v, where + "/" + k)
        elif isinstance(node, list):
            for i, v in enumerate(node):
                walk(v, "%s/%d" % (where, i))
    for name, schema in (("request", C.request), ("result", C.result)):
        missing.clear()
        walk(schema, "")
        # "if/then" constraint fragments restate properties; they need no title
        missing = [m for m in missing if "/then/" not in m and "/if/" not in m]
        check(not missing, "%s schema: title and description on every property %s" % (name, missing[:10] or ""))

    # defaults in the request schema are the codec's (server/codec/)
    an = C.request["$defs"]["analysis"]["properties"]
    want = {"modes": 3, "geometric_stiffening": True, "coriolis": True, "mass": "lumped",
            "substructure_modes": "augmented", "modes_per_frame": "all", "mode_shapes": True}
    got = {k: an[k].get("default") for k in want}
    check(got == want, "analysis defaults are the codec's (%s)" % got)
    check(C.request["$defs"]["frames"].get("default") == "per_element", "frames default per_element")
    check(C.request["$defs"]["structure"]["properties"]["point_masses"].get("default") == [],
          "point_masses default []")


def t_requests():
    """Examples and valid codec cases validate against the request schema."""
    examples = sorted(glob.glob(os.path.join(ROOT, "examples", "*.json")))
    check(len(examples) >= 3, "found %d examples" % len(examples))
    for path in examples:
        validates(read_json(path), "request", "examples/" + os.path.basename(path))
        validates(read_json(path), "Request", "examples/%s (as openapi Request)" % os.path.basename(path))
    n = 0
    for name, d, valid in codec_cases():
        if not valid:
            continue
        if name in SCHEMA_CANNOT_ACCEPT:
            note("%s: valid, not expressible in the schema (%s)" % (name, SCHEMA_CANNOT_ACCEPT[name]))
            continue
        for path in sorted(glob.glob(os.path.join(d, "*.json"))):
            base = os.path.basename(path)
            if base in ("checks.json",):
                continue
            doc = load_case_request(d, base)
            check(doc is not None, "codec case %s/%s is JSON" % (name, base))
            if doc is not None:
                validates(doc, "request", "codec case %s/%s" % (name, base))
                n += 1
    check(n >= 5, "validated %d valid codec requests" % n)

    # the request examples of README.md (planar and spatial) validate too
    import re
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as f:
        readme = f.read()
    kinds = []
    for body in re.findall(r"^```json\n(.*?)^```", readme, re.S | re.M):
        try:
            doc = json.loads(body)
        except ValueError:
            continue  # excerpts with elisions
        if isinstance(doc, dict) and "structure" in doc and "analysis" in doc:
            secs = doc["structure"].get("sections", {})
            kind = "spatial" if any("EA" in x or "G" in x for x in secs.values()) else "planar"
            kinds.append(kind)
            validates(doc, "request", "README.md %s request example" % kind)
    check("planar" in kinds and "spatial" in kinds, "README.md shows a planar and a spatial request (%s)" % kinds)


def t_invalid():
    """Invalid codec cases: the schema rejects those a schema can express."""
    cases = {name: (d, valid) for name, d, valid in codec_cases()}
    for name in SCHEMA_REJECTS:
        if not check(name in cases and not cases[name][1], "invalid codec case %s exists" % name):
            continue
        d = cases[name][0]
        doc = load_case_request(d)
        if not check(doc is not None, "%s: request.json is JSON" % name):
            continue
        errs = C.errors(doc, "request")
        if not check(bool(errs), "%s: rejected by request.schema.json" % name):
            continue
        expected = read_json(os.path.join(d, "expected-error.json")).get("errors", [])
        want = expected[0].get("pointer") if expected else None
        got = all_error_pointers(errs)
        if want is not None:
            check(any(related(g, want) for g in got),
                  "%s: a schema error is at or around the codec's pointer %r (schema: %s)"
                  % (name, want, sorted(set(got))[:6]))
    for name, (d, valid) in sorted(cases.items()):
        if valid or name in SCHEMA_REJECTS:
            continue
        doc = load_case_request(d)
        verdict = "not JSON" if doc is None else ("rejected" if not C.is_valid(doc, "request") else "accepted")
        if name in SCHEMA_CANNOT:
            note("%s: not expressible in the schema (%s); schema: %s" % (name, SCHEMA_CANNOT[name], verdict))
        else:
            note("%s: invalid codec case not classified in test_contracts.py; schema: %s" % (name, verdict))


def angled(omega, frames="per_element", **analysis):
    req = {
        "structure": {
            "joints": {"O": [0, 0], "C": [5, 0], "P": [5, 5]},
            "sections": {"al": {"E": 7e10, "A": 4e-4, "I": 2e-7, "mass_per_length": 1.2}},
            "members": [
                {"id": "beam1", "from": "O", "to": "C", "section": "al", "elements": 12},
                {"id": "beam2", "from": "C", "to": "P", "section": "al", "elements": 12},
            ],
            "clamp": "O",
        },
        "frames": frames,
        "analysis": dict({"omega": omega}, **analysis),
    }
    return req


def solve(tmp, name, req, want_rc=0):
    """Run `spinmodal solve`; the parsed result or None."""
    path = os.path.join(tmp, name + ".json")
    if not isinstance(req, str):
        with open(path, "w") as f:
            json.dump(req, f)
    else:
        path = req
    rc, out, err = run_cli(["solve", path])
    if not check(rc == want_rc, "%s: spinmodal solve exits %d (got %d; %.300s)" % (name, want_rc, rc, err)):
        return None
    try:
        return json.loads(out)
    except ValueError as e:
        check(False, "%s: result is JSON (%s)" % (name, e))
        return None


def t_cli():
    """The CLI's real output validates against result.schema.json."""
    with tempfile.TemporaryDirectory(prefix="spinmodal-contracts-") as tmp:
        for path in sorted(glob.glob(os.path.join(ROOT, "examples", "*.json"))):
            name = "examples/" + os.path.basename(path)
            doc = solve(tmp, name, path)
            if doc is not None:
                validates(doc, "result", name)
                validates(doc, "Result", name + " (as openapi Result)")
            rc, out, err = run_cli(["validate", path])
            if check(rc == 0, "%s: spinmodal validate exits 0" % name):
                v = json.loads(out)
                validates(v["canonical"], "request", name + ": canonical form")
                vv = dict(v, id="0" * 64)
                validates(vv, "Validation", name + ": validate output (+ id) as /v1/validate answer")

        scenarios = [
            ("coriolis", angled(6.0, coriolis=True, modes=4), 0),
            ("no-coriolis", angled(6.0, coriolis=False, modes=4), 0),
            ("no-shapes", angled(6.0, mode_shapes=False), 0),
            ("error-estimate", angled([0, 6.0], mode_shapes=False, error_estimate=True), 0),
            ("sweep-paper-consistent", angled([0, 3, 6], {"per_member": 2}, mass="consistent",
                                              substructure_modes="paper", modes_per_frame=6), 0),
            ("no-equilibrium", angled([10, 20], "single", geometric_stiffening=True), 3),
            ("no-stiffening-sweep", angled([0, 6, 12], {"per_member": 1},
                                           geometric_stiffening=False, coriolis=True, mode_shapes=False), 3),
        ]
        docs = {}
        for name, req, want_rc in scenarios:
            check(C.is_valid(req, "request"), "%s: request is valid" % name)
            doc = solve(tmp, name, req, want_rc)
            if doc is not None:
                validates(doc, "result", name)
                docs[name] = doc

        # a spatial request (DESIGN.md 7.3): result and validate answer against the contracts
        sp = {"structure": {"joints": {"root": [0.5, 0], "C": [3, 0, 0.1], "tip": [5.5, 0.5, 0.3]},
                            "sections": {"in": {"E": 7e10, "G": 2.6e10, "A": 4e-4, "I_flap": 2e-7, "I_edge": 8e-7,
                                                "J": 5e-7, "mass_per_length": 1.2},
                                         "out": {"EA": 2.8e7, "EI_flap": 1.4e4, "EI_edge": 5.6e4, "GJ": 1.3e4,
                                                 "mass_per_length": 1.2, "flap_inertia": 5e-4}},
                            "members": [{"from": "root", "to": "C", "section": "in", "elements": 6, "twist_deg": 5},
                                        {"from": "C", "to": "tip", "section": "out", "elements": 6,
                                         "flap_direction": [0, 0, 1]}],
                            "point_masses": [{"joint": "tip", "mass": 0.2, "inertia": [0, 0, 1e-3]}],
                            "clamp": "root"},
              "frames": {"per_member": 2}, "analysis": {"omega": [0, 8], "modes": 4}}
        check(C.is_valid(sp, "request"), "spatial: request is valid")
        doc = solve(tmp, "spatial", sp, 0)
        if doc is not None:
            validates(doc, "result", "spatial")
            validates(doc, "Result", "spatial (as openapi Result)")
            check(doc["model"].get("spatial") is True and doc["model"].get("dof_per_node") == 6,
                  "spatial: model.spatial true, dof_per_node 6")
        path = os.path.join(tmp, "spatial.json")
        rc, out, err = run_cli(["validate", path])
        if check(rc == 0, "spatial: spinmodal validate exits 0"):
            v = json.loads(out)
            validates(v["canonical"], "request", "spatial: canonical form")
            validates(dict(v, id="0" * 64), "Validation", "spatial: validate output (+ id) as /v1/validate answer")

        # facts the schema leaves to the request: complex shapes with Coriolis only
        d = docs.get("coriolis")
        if d:
            modes = d["cases"][0]["modes"]
            check(modes and all("re" in m["shape"] and "im" in m["shape"] for m in modes),
                  "coriolis: every mode has shape.re and shape.im")
        d = docs.get("no-coriolis")
        if d:
            modes = d["cases"][0]["modes"]
            check(modes and all("re" in m["shape"] and "im" not in m["shape"] for m in modes),
                  "no-coriolis: real shapes only (no shape.im)")
        d = docs.get("no-shapes")
        if d:
            check(all("shape" not in m for c in d["cases"] for m in c["modes"]), "no-shapes: no shape")
        d = docs.get("error-estimate")
        if d:
            modes = [m for c in d["cases"] for m in c["modes"]]
            check(modes and all(list(m)[-1] == "error_estimate" and m["error_estimate"] > 0
                                for m in modes), "error-estimate: error_estimate last, > 0")
            e = copy.deepcopy(d)
            e["cases"][0]["modes"][0]["error_estimate"] = -1.0
            rejected(e, "result", "a negative error_estimate")
        d = docs.get("no-equilibrium")
        if d:
            st = [c["status"] for c in d["cases"]]
            check(st == ["solved", "no_equilibrium"], "no-equilibrium: statuses %s" % st)
            bad = d["cases"][1]
            check("diagnostics" in bad and "stability" not in bad and bad["modes"] == [],
                  "no-equilibrium: diagnostics, no stability, no modes")

        # the problem document of an invalid request (stderr, exit 2) is a Problem
        bad = angled(1.0, modes=0)
        bad["structure"]["members"][0]["to"] = "Q"
        path = os.path.join(tmp, "bad.json")
        with open(path, "w") as f:
            json.dump(bad, f)
        rc, out, err = run_cli(["solve", path])
        if check(rc == 2, "invalid request: exit 2"):
            prob = json.loads(err)
            validates(prob, "Problem", "CLI problem document (422)")
        rc, out, err = run_cli(["solve", "-"], stdin=b'{"structure": ')
        if check(rc == 2, "malformed request: exit 2"):
            validates(json.loads(err), "Problem", "CLI problem document (400)")

        # an "unstable" case (none of the scenarios above is) built from a solved one
        d = docs.get("no-shapes")
        if d:
            case = copy.deepcopy(d["cases"][0])
            case["status"] = "unstable"
            case["stability"] = {"stable": False, "negative_eigenvalues": 1}
            case["diagnostics"] = {"iterations": 3, "residual": 1e-12, "last_omega": case["omega"],
                                   "message": "negative eigenvalue of K*"}
            doc = dict(d, cases=[case])
            validates(doc, "result", "synthetic unstable case")
            del case["diagnostics"]
            rejected(doc, "result", "unstable case without diagnostics")


def t_openapi():
    """openapi.json passes the structural checks against DAEMON.md."""
    try:
        summary = C.check_openapi()
        check(True, "check_openapi: %s" % summary)
    except contract.ContractError as e:
        for p in e.problems:
            check(False, "check_openapi: " + p)
        return
    comps = C.openapi["components"]["schemas"]
    for name in contract.REQUIRED_COMPONENTS:
        check(name in comps, "components/schemas/%s present" % name)
    check(comps["Request"].get("$ref") == contract.REQUEST_ID, "Request is a $ref to the request schema $id")
    check(comps["Result"].get("$ref") == contract.RESULT_ID, "Result is a $ref to the result schema $id")
    body = C.openapi["paths"]["/v1/analyses"]["post"]["requestBody"]["content"]["application/json"]["schema"]
    check(body.get("$ref") == contract.REQUEST_ID, "POST /v1/analyses body is the request schema by $id")
    paths = C.openapi["paths"]

    def media(path, method, status):
        r = paths[path][method]["responses"][status]
        if "$ref" in r:
            r = C._resolve_ref(contract.OPENAPI_URI, r["$ref"])
        return r, sorted(r.get("content", {}))
    expect = [
        ("/v1/analyses", "post", "202", ["application/json"], ["Location"]),
        ("/v1/analyses", "post", "429", ["application/problem+json"], ["Retry-After"]),
        ("/v1/analyses", "post", "401", ["application/problem+json"], ["WWW-Authenticate"]),
        ("/v1/analyses/{id}/result", "get", "200", ["application/json", "text/csv"], []),
        ("/v1/schemas/request", "get", "200", ["application/schema+json"], []),
        ("/v1/schemas/result", "get", "200", ["application/schema+json"], []),
        ("/metrics", "get", "200", ["text/plain"], []),
        ("/", "get", "200", ["text/html"], []),
        ("/readyz", "get", "503", ["application/problem+json"], ["Retry-After"]),
        ("/livez", "options", "405", ["application/problem+json"], ["Allow"]),
    ]
    for path, method, status, types, headers in expect:
        try:
            r, got = media(path, method, status)
        except KeyError:
            check(False, "%s %s %s exists" % (method.upper(), path, status))
            continue
        check(got == types and all(h in r.get("headers", {}) for h in headers),
              "%s %s %s: %s with headers %s (got %s, %s)"
              % (method.upper(), path, status, types, headers, got, sorted(r.get("headers", {}))))
    sec = C.openapi["components"].get("securitySchemes", {})
    check(any(s.get("type") == "http" and s.get("scheme") == "bearer" for s in sec.values()),
          "bearer security scheme")
    for path, method in (("/v1/analyses", "post"), ("/v1/analyses/{id}", "delete")):
        s = paths[path][method].get("security", [])
        check({} in s and any(s_ for s_ in s), "%s %s: bearer optional" % (method.upper(), path))

    # documents in the shapes DAEMON.md shows
    jid = "ab" * 32
    running = {"id": jid, "state": "running", "progress": {"done": 12, "total": 101},
               "created_at": "2026-11-21T10:00:00.123Z", "started_at": "2026-11-21T10:00:00.200Z",
               "finished_at": None, "attempts": 1, "cancel_requested": False, "error": None,
               "links": {"self": "/v1/analyses/" + jid, "result": "/v1/analyses/" + jid + "/result"}}
    validates(running, "Job", "DAEMON.md status document")
    validates({"items": [running], "next": "/v1/analyses?limit=1&before=7"}, "JobList", "job list")
    validates({"items": [], "next": None}, "JobList", "empty job list")
    validates({"status": "ok"}, "Health", "livez body")
    validates({"status": "ready", "checks": {"database": "ok", "workers": "2/2"}}, "Health", "readyz body")
    validates({"type": "about:blank", "title": "Unprocessable Content", "status": 422, "detail": "x",
               "errors": [{"pointer": "/structure/joints/a~1b", "message": "m"}]}, "Problem", "422 problem")
    validates({"type": "about:blank", "title": "Bad Request", "status": 400,
               "errors": [{"pointer": "/query/wait", "message": "m"}]}, "Problem", "query problem")
    failed = dict(running, state="failed", finished_at="2026-11-21T10:00:01.000Z",
                  error={"type": "no_equilibrium", "title": "No equilibrium", "detail": "d",
                         "diagnostics": {"last_omega": 18.0}})
    validates(failed, "Job", "failed job")
    rejected(dict(running, state="paused"), "Job", "unknown state")
    rejected(dict(running, id="XYZ"), "Job", "bad id")
    rejected(dict(running, created_at="2026-11-21 10:00:00"), "Job", "timestamp without T/ms/Z")
    rejected(dict(running, state="done", finished_at="2026-11-21T10:00:01.000Z"), "Job", "done job without result")
    rejected(dict(running, state="done", finished_at="2026-11-21T10:00:01.000Z", result={"solver": {}}),
             "Job", "done job with a broken result (checked through Result)")
    rejected({"items": [dict(running, result={})], "next": None}, "JobList", "list item with result")
    rejected({"status": "ready"}, "Health", "readyz without checks")
    rejected({"title": "x", "status": 422}, "Problem", "problem without type")
    rejected({"type": "about:blank", "title": "x", "status": 422,
              "errors": [{"pointer": "structure", "message": "m"}]}, "Problem", "pointer without leading /")


def t_negative():
    """Self-checks: mutated documents and instances must fail."""
    example = read_json(os.path.join(ROOT, "examples", "angled-beam-90.json"))
    validates(example, "request", "baseline example")

    def mut_enum(req, res, api):
        req["$defs"]["analysis"]["properties"]["mass"]["enum"] = ["consistent"]
    m = contract.mutated(C, mut_enum)
    check(not m.is_valid(example, "request"), "mutated request schema (mass enum) rejects the example")
    check(not m.is_valid(example, "Request"), "... also through openapi's Request $ref (cross-file resolution)")

    def mut_result(req, res, api):
        del res["$defs"]["mode"]["properties"]["shape"]["properties"]["im"]
    m = contract.mutated(C, mut_result)
    res_doc = {"solver": {"name": "spinmodal", "version": "0.1.0", "request_sha256": "0" * 64},
               "model": {"nodes": 2, "elements": 1, "frames": 1, "coordinates": 2},
               "cases": [{"omega": 1.0, "status": "solved",
                          "equilibrium": {"converged": True, "iterations": 2, "residual": 0.0},
                          "stability": {"stable": True, "negative_eigenvalues": 0},
                          "modes": [{"frequency_rad_s": 1.0, "frequency_hz": 0.16, "eigenvalue": [0.0, 1.0],
                                     "mac_to_previous": None, "previous_index": None,
                                     "shape": {"re": [[0, 0, 0], [1, 0, 0]], "im": [[0, 0, 0], [0, 0, 0]]},
                                     "per_rev": 1.0}],
                          "rpm": 9.549296585513721}],
               "timing_ms": {"equilibrium": 0.1, "linearize": 0.1, "eigen": 0.1}}
    validates(res_doc, "result", "baseline result document")
    check(not m.is_valid(res_doc, "result"), "mutated result schema (no shape.im) rejects a Coriolis result")
    check(not m.is_valid(dict(res_doc), "Result"), "... also through openapi's Result $ref")

    for what, edit in [
        ("status bogus", lambda d: d["cases"][0].__setitem__("status", "bogus")),
        ("solved without stability", lambda d: d["cases"][0].pop("stability")),
        ("solved with stable false", lambda d: d["cases"][0]["stability"].__setitem__("stable", False)),
        ("no_equilibrium without diagnostics", lambda d: (d["cases"][0].__setitem__("status", "no_equilibrium"),
                                                         d["cases"][0].pop("stability"))),
        ("unknown top-level key", lambda d: d.__setitem__("extra", 1)),
        ("sha256 not hex", lambda d: d["solver"].__setitem__("request_sha256", "xyz")),
        ("triple of 2", lambda d: d["cases"][0]["modes"][0]["shape"]["re"].__setitem__(0, [0, 0])),
        ("negative frequency", lambda d: d["cases"][0]["modes"][0].__setitem__("frequency_rad_s", -1.0)),
        ("cases empty", lambda d: d.__setitem__("cases", [])),
    ]:
        bad = copy.deepcopy(res_doc)
        edit(bad)
        rejected(bad, "result", "result with " + what)

    # a spatial result (DESIGN.md 7.3): "spatial" and "dof_per_node" in model, rows of 6
    sp_doc = copy.deepcopy(res_doc)
    sp_doc["model"].update({"spatial": True, "dof_per_node": 6})
    sp_case = sp_doc["cases"][0]
    sp_case["equilibrium"].update({"joints": {"O": [0, 0, 0, 0, 0, 0], "C": [1, 0, 0.1, 0, -0.1, 0]},
                                   "nodes": [[0, 0, 0, 0, 0, 0], [1, 0, 0.1, 0, -0.1, 0]]})
    sp_case["modes"][0]["shape"] = {"re": [[0] * 6, [0, 0, 1, 0, 0.5, 0]], "im": [[0] * 6, [0.1, 0, 0, 0, 0, 0]]}
    validates(sp_doc, "result", "spatial result document")
    validates(sp_doc, "Result", "spatial result document (as openapi Result)")
    for what, edit in [
        ("spatial model, a triple node row", lambda d: d["cases"][0]["equilibrium"]["nodes"].__setitem__(0, [0, 0, 0])),
        ("spatial model, a triple joint row", lambda d: d["cases"][0]["equilibrium"]["joints"].__setitem__("O", [0, 0, 0])),
        ("spatial model, a triple shape row", lambda d: d["cases"][0]["modes"][0]["shape"]["im"].__setitem__(1, [0, 0, 0])),
        ("spatial without dof_per_node", lambda d: d["model"].pop("dof_per_node")),
        ("dof_per_node 3", lambda d: d["model"].__setitem__("dof_per_node", 3)),
        ("spatial false", lambda d: d["model"].__setitem__("spatial", False)),
    ]:
        bad = copy.deepcopy(sp_doc)
        edit(bad)
        rejected(bad, "result", "result with " + what)
    bad = copy.deepcopy(res_doc)
    bad["cases"][0]["modes"][0]["shape"]["re"] = [[0] * 6, [1, 0, 0, 0, 0, 0]]
    rejected(bad, "result", "planar result (no model.spatial) with a shape row of 6")

    # spatial requests: both forms of section, z, twist, flap direction, inertia
    sp_req = {"structure": {"joints": {"O": [0.5, 0], "T": [5.5, 0, 0.5]},
                            "sections": {"a": {"EA": 2.8e7, "EI_flap": 1.4e4, "EI_edge": 5.6e4, "GJ": 1.3e4,
                                               "mass_per_length": 1.2, "flap_inertia": 6e-4},
                                         "b": {"E": 7e10, "G": 2.6e10, "A": 4e-4, "I_flap": 2e-7, "I_edge": 8e-7,
                                               "J": 5e-7, "mass_per_length": 1.2}},
                            "members": [{"from": "O", "to": "T", "section": "a", "elements": 4, "twist_deg": 12,
                                         "flap_direction": [0, 0, 1]}],
                            "point_masses": [{"joint": "T", "mass": 1, "inertia": [0, 0, 0.1]}],
                            "clamp": "O"},
              "analysis": {"omega": 10}}
    validates(sp_req, "request", "spatial request (stiffness and material forms)")
    for what, edit in [
        ("a planar section beside spatial ones", lambda r: r["structure"]["sections"].__setitem__(
            "c", {"E": 7e10, "A": 4e-4, "I": 2e-7, "mass_per_length": 1.2})),
        ("EA beside E in one section", lambda r: r["structure"]["sections"]["b"].__setitem__("EA", 1e7)),
        ("a spatial section without GJ", lambda r: r["structure"]["sections"]["a"].pop("GJ")),
        ("a joint of 4 numbers", lambda r: r["structure"]["joints"].__setitem__("T", [5, 0, 0, 0])),
        ("flap_direction of 2 numbers", lambda r: r["structure"]["members"][0].__setitem__("flap_direction", [0, 1])),
        ("flap_direction [0, 0, 0]", lambda r: r["structure"]["members"][0].__setitem__("flap_direction", [0, 0.0, 0])),
        ("a negative point-mass inertia", lambda r: r["structure"]["point_masses"][0].__setitem__("inertia", [0, -1, 0])),
        ("the paper basis", lambda r: r["analysis"].__setitem__("substructure_modes", "paper")),
        ("edge_inertia -1e-4", lambda r: r["structure"]["sections"]["b"].__setitem__("edge_inertia", -1e-4)),
    ]:
        bad = copy.deepcopy(sp_req)
        edit(bad)
        rejected(bad, "request", "spatial request with " + what)
    for what, edit in [
        ("a joint with z", lambda r: r["structure"]["joints"].__setitem__("P", [5, 5, 0])),
        ("twist_deg", lambda r: r["structure"]["members"][0].__setitem__("twist_deg", 0)),
        ("flap_direction", lambda r: r["structure"]["members"][0].__setitem__("flap_direction", [0, 0, 1])),
        ("a point-mass inertia", lambda r: r["structure"].__setitem__(
            "point_masses", [{"joint": "P", "mass": 1, "inertia": [0, 0, 0]}])),
        ("flap_inertia in a planar section", lambda r: r["structure"]["sections"]["al"].__setitem__("flap_inertia", 1e-4)),
    ]:
        bad = copy.deepcopy(example)
        edit(bad)
        rejected(bad, "request", "planar request with " + what)

    for what, edit in [
        ("negative omega", lambda r: r["analysis"].__setitem__("omega", -1)),
        ("frames 'per_frame'", lambda r: r.__setitem__("frames", "per_frame")),
        ("modes 2.5", lambda r: r["analysis"].__setitem__("modes", 2.5)),
        ("E 0", lambda r: r["structure"]["sections"]["al"].__setitem__("E", 0)),
        ("unknown analysis key", lambda r: r["analysis"].__setitem__("corriolis", True)),
        ("boolean omega", lambda r: r["analysis"].__setitem__("omega", True)),
    ]:
        bad = copy.deepcopy(example)
        edit(bad)
        rejected(bad, "request", "request with " + what)
    ok = copy.deepcopy(example)
    ok["structure"]["members"][0]["elements"] = 24.0
    ok["frames"] = {"elements_per_frame": 3}
    validates(ok, "request", "request with integral real elements and elements_per_frame")

    def expect_raise(what, edit, needle):
        m = contract.mutated(C, edit)
        try:
            m.check_openapi()
            check(False, "check_openapi fails on %s" % what)
        except contract.ContractError as e:
            check(any(needle in p for p in e.problems),
                  "check_openapi fails on %s (%s)" % (what, e.problems[:2]))
    expect_raise("a missing DAEMON.md path", lambda q, s, a: a["paths"].pop("/livez"), "/livez")
    expect_raise("a dangling $ref", lambda q, s, a: a["paths"]["/livez"]["get"]["responses"].__setitem__(
        "500", {"$ref": "#/components/responses/Nope"}), "Nope")
    expect_raise("a missing Job component", lambda q, s, a: a["components"]["schemas"].pop("JobList"), "JobList")
    expect_raise("an operation without responses",
                 lambda q, s, a: a["paths"]["/metrics"]["get"].__setitem__("responses", {}), "no responses")
    expect_raise("an example that no longer matches",
                 lambda q, s, a: a["components"]["schemas"]["JobState"].__setitem__("enum", ["queued"]),
                 "example")
    expect_raise("a spatial example (examples/spatial) that no longer matches",
                 lambda q, s, a: a["paths"]["/v1/validate"]["post"]["responses"]["200"]["content"][
                     "application/json"]["examples"]["spatial"]["value"]["canonical"]["analysis"].__setitem__(
                     "substructure_modes", "paper"), "examples/spatial")
    expect_raise("a missing query parameter",
                 lambda q, s, a: a["paths"]["/v1/analyses"]["get"].__setitem__("parameters", []), "'limit'")
    expect_raise("an error response that is not problem+json",
                 lambda q, s, a: a["paths"]["/readyz"]["get"]["responses"].__setitem__(
                     "503", {"description": "x", "content": {"application/json": {"schema": {}}}}),
                 "problem+json")
    expect_raise("a reference to a remote document",
                 lambda q, s, a: a["components"]["schemas"].__setitem__(
                     "Remote", {"$ref": "https://example.com/x.json"}), "example.com")
    expect_raise("an invalid request schema",
                 lambda q, s, a: q.__setitem__("type", "objekt"), "request.schema.json")


GROUPS = {
    "schemas": t_schemas,
    "requests": t_requests,
    "invalid": t_invalid,
    "cli": t_cli,
    "openapi": t_openapi,
    "negative": t_negative,
}


def main():
    global ROOT, EXE, C, CASES
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--source-root", default=ROOT)
    ap.add_argument("--spinmodal", help="the spinmodal CLI (group cli)")
    ap.add_argument("group", choices=sorted(GROUPS) + ["all"])
    a = ap.parse_args()
    ROOT = os.path.abspath(a.source_root)
    CASES = os.path.join(ROOT, "tests", "codec", "cases")
    names = sorted(GROUPS) if a.group == "all" else [a.group]
    if "cli" in names:
        if not a.spinmodal:
            ap.error("group cli needs --spinmodal EXE")
        EXE = os.path.abspath(a.spinmodal)
    print("python %s, jsonschema %s" % (sys.version.split()[0], _jsonschema_version()))
    C = contract.load(os.path.join(ROOT, "schemas"))
    for name in names:
        try:
            GROUPS[name]()
        except Exception as e:  # a crash of the script is a failure, with its cause
            import traceback
            traceback.print_exc()
            check(False, "%s: %s: %s" % (name, type(e).__name__, e))
    print("%d failed" % len(FAILURES))
    return 1 if FAILURES else 0


def _jsonschema_version():
    try:
        from importlib.metadata import version
        return version("jsonschema")
    except Exception:  # noqa: BLE001
        return "?"


if __name__ == "__main__":
    sys.exit(main())
