#!/usr/bin/env python3
"""make_seeds.py -- write the hand-made seeds of tests/fuzz/corpus/.

Usage: python3 tests/fuzz/make_seeds.py tests/fuzz/corpus

Each seed is one nasty request for the codec fuzz target (fuzz_codec.c):
tiny valid models (they reach codec_model_new, sm_solve and the encoders),
deep nesting, huge/overflowing/subnormal numbers, invalid UTF-8, NUL bytes,
duplicate keys, long names (pointers, messages cut on a UTF-8 boundary),
zero-length members and topology errors, speed sweeps at and over the limit,
and a body over the fuzz target's 12 KiB cap (413).  The seeds are committed;
rerun this only to change them.  A regression seed for a fixed crash is added
by hand (copy the crash file here under a descriptive name).
"""
import json
import os
import sys

if len(sys.argv) != 2:
    sys.exit("usage: make_seeds.py OUT_DIR")
out = sys.argv[1]
os.makedirs(out, exist_ok=True)


def base():
    """A valid two-element cantilever: the starting point of most seeds."""
    r = {
        "structure": {
            "joints": {"O": [0, 0], "C": [1, 0]},
            "sections": {"s": {"E": 7e10, "A": 4e-4, "I": 2e-7, "mass_per_length": 1.2}},
            "members": [{"id": "m", "from": "O", "to": "C", "section": "s", "elements": 2}],
            "clamp": "O",
        },
        "analysis": {"omega": 10},
    }
    return r


def w(name, data):
    """Write one seed: bytes as they are, str as UTF-8, anything else as JSON."""
    if isinstance(data, str):
        data = data.encode("utf-8", "surrogatepass")
    elif not isinstance(data, bytes):
        data = json.dumps(data).encode()
    with open(os.path.join(out, name), "wb") as f:
        f.write(data)

# valid tiny models: these reach codec_model_new, sm_solve and the encoders
w("tiny-solved.json", base())
r = base(); r["analysis"] = {"omega": 0, "modes": 1, "coriolis": False, "mass": "consistent",
     "substructure_modes": "paper", "modes_per_frame": 1, "mode_shapes": False,
     "geometric_stiffening": False}
r["frames"] = {"per_member": 1}
w("tiny-all-options.json", r)
r = base(); r["frames"] = {"elements_per_frame": 1}
r["structure"]["point_masses"] = [{"joint": "C", "mass": 0}, {"joint": "C", "mass": 2.5}]
w("tiny-point-masses.json", r)
r = base(); r["analysis"]["omega"] = 1e6          # far past any equilibrium
w("tiny-runaway-speed.json", r)
r = base(); r["structure"]["sections"]["s"] = {"E": 1e-300, "A": 1e-300, "I": 1e-300, "mass_per_length": 1e300}
w("tiny-extreme-section.json", r)

# deep nesting: past jansson's depth limit (400), and deep inside a field (422)
w("deep-nesting-array.json", "[" * 5000 + "]" * 5000)
w("deep-nesting-object.json", '{"":' * 2100 + "1" + "}" * 2100)
r = base(); inner = "[" * 1000 + "]" * 1000
w("deep-nesting-in-joint.json", json.dumps(r).replace('"C": [1, 0]', '"C": ' + inner))

# huge and odd numbers
w("huge-numbers.json", json.dumps(base()).replace('"omega": 10', '"omega": 1.7976931348623157e308')
  .replace('"E": 70000000000.0', '"E": 1.7976931348623157e308')
  .replace('"elements": 2', '"elements": 9223372036854775807'))
w("number-overflow-real.json", json.dumps(base()).replace('"omega": 10', '"omega": 1e400'))
w("number-overflow-int.json", json.dumps(base()).replace('"elements": 2', '"elements": 99999999999999999999'))
w("number-subnormal-negzero.json", json.dumps(base()).replace('"omega": 10', '"omega": [-0.0, 5e-324, 0]')
  .replace('[1, 0]', '[1e-320, -0.0]'))
w("number-modes-real.json", json.dumps(base()).replace('"omega": 10', '"omega": 10, "modes": 2.0, "modes_per_frame": 1e308'))

# invalid UTF-8, NUL bytes, escapes
w("invalid-utf8-name.json", json.dumps(base()).encode().replace(b'"C"', b'"C\xff\xfe"', 1))
w("invalid-utf8-overlong.json", json.dumps(base()).encode().replace(b'"O"', b'"\xc0\x80"', 1))
w("lone-surrogate-escape.json", json.dumps(base()).replace('"m"', '"\\ud800"'))
w("nul-escape-in-key.json", json.dumps(base()).replace('"C": [1, 0]', '"C\\u0000x": [1, 0]'))
w("nul-raw-in-string.json", json.dumps(base()).encode().replace(b'"m"', b'"m\x00n"'))
w("nul-after-document.json", json.dumps(base()).encode() + b"\x00garbage")
w("bom-prefix.json", b"\xef\xbb\xbf" + json.dumps(base()).encode())

# duplicate keys (rejected by JSON_REJECT_DUPLICATES): top level and nested
w("duplicate-key-nested.json", json.dumps(base()).replace('"A": 0.0004', '"A": 0.0004, "A": 0.0005'))
w("duplicate-key-joint.json", json.dumps(base()).replace('"C": [1, 0]', '"C": [1, 0], "C": [2, 0]'))

# long strings: names used in pointers and messages, cut for messages
long_name = "\u00e9" * 3000             # 6000 bytes of 2-byte UTF-8
w("long-joint-name.json", json.dumps(base(), ensure_ascii=False).replace('"C"', json.dumps(long_name, ensure_ascii=False)))
w("long-unknown-key.json", json.dumps(base()).replace('"omega": 10', '"omega": 10, "' + "omegaa" * 700 + '": 1'))
w("name-cut-at-multibyte.json", json.dumps(base(), ensure_ascii=False).replace('"s"', '"' + "x" * 59 + "\U0001F300" * 3 + '"', 1))
w("name-tilde-slash.json", json.dumps(base()).replace('"C"', '"~0/~1/~"'))
w("body-too-large.json", '{"pad": "' + "x" * 13000 + '"}')
w("malformed-multibyte-near-error.json", '{"structure": ' + "\u00e9" * 200 + "}")

# 0-length members and other local topology errors
r = base(); r["structure"]["members"][0]["to"] = "O"
w("member-from-equals-to.json", r)
r = base(); r["structure"]["joints"]["C"] = [0, 0]
w("member-zero-length.json", r)
r = base(); r["structure"]["members"][0]["elements"] = 0
w("member-zero-elements.json", r)
r = base(); r["structure"]["joints"]["D"] = [2, 0]; r["structure"]["joints"]["E"] = [3, 0]
r["structure"]["members"].append({"from": "D", "to": "E", "section": "s", "elements": 1})
w("member-disconnected.json", r)
r = base(); r["structure"]["joints"]["P"] = [1, 1]
r["structure"]["members"] += [{"from": "C", "to": "P", "section": "s", "elements": 1},
                              {"from": "P", "to": "O", "section": "s", "elements": 1}]
w("member-cycle.json", r)

# sweeps
r = base(); r["analysis"]["omega"] = [float(i) for i in range(20)]
w("sweep-at-limit.json", r)
r = base(); r["analysis"]["omega"] = [float(i) for i in range(21)]
w("sweep-over-limit.json", r)
r = base(); r["analysis"]["omega"] = [30, 0, 10, 10, "x", -1, None, [1], {"a": 1}]
w("sweep-mixed.json", r)
r = base(); r["analysis"]["omega"] = []
w("sweep-empty.json", r)
r = base(); r["analysis"]["omega"] = [5, 5]; r["structure"]["members"][0]["elements"] = 1
w("sweep-repeated-speed.json", r)

# odd documents
w("empty.json", b"")
w("null.json", "null")
w("whitespace.json", " \t\r\n ")
w("many-errors.json", json.dumps({"structure": {"joints": {str(i): "x" for i in range(150)}}, "x": 1}))

# spatial requests (DESIGN.md 7.3): tiny valid ones in both section forms, and mismatches
def spatial():
    r = base()
    r["structure"]["joints"]["C"] = [1, 0, 0.25]
    r["structure"]["sections"]["s"] = {"EA": 2.8e7, "EI_flap": 1.4e4, "EI_edge": 5.6e4, "GJ": 1.3e4,
                                       "mass_per_length": 1.2}
    return r
w("spatial-stiffness.json", spatial())
r = spatial(); r["structure"]["sections"]["s"] = {"E": 7e10, "G": 2.6e10, "A": 4e-4, "I_flap": 2e-7,
                                                  "I_edge": 8e-7, "J": 5e-7, "mass_per_length": 1.2,
                                                  "flap_inertia": 1e-4}
r["structure"]["members"][0].update({"twist_deg": 1e300, "flap_direction": [0, 1e-300, 1]})
r["structure"]["point_masses"] = [{"joint": "C", "mass": 1, "inertia": [0, 5e-324, 1e308]}]
w("spatial-material-extremes.json", r)
r = spatial(); r["structure"]["sections"]["p"] = {"E": 7e10, "A": 4e-4, "I": 2e-7, "mass_per_length": 1.2,
                                                  "EA": 1, "G": 1}
r["analysis"]["substructure_modes"] = "paper"
r["structure"]["members"][0]["flap_direction"] = [0, 0, 0]
w("spatial-mixed-everything.json", r)
r = base(); r["structure"]["joints"]["C"] = [1, 0, 0]
r["structure"]["members"][0]["twist_deg"] = 5
r["structure"]["point_masses"] = [{"joint": "C", "mass": 1, "inertia": [1, 1]}]
w("spatial-fields-planar-sections.json", r)
