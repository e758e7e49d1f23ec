"""contract.py -- load spinmodal's API contracts and validate documents offline.

The contracts are the three files of schemas/: request.schema.json and
result.schema.json (JSON Schema 2020-12) and openapi.json (OpenAPI 3.1, whose
components/schemas describe the daemon's other documents).  They refer to each
other by URL ($id); this module resolves those references from the files on
disk and never touches the network.

Usage (Python 3.11 standard library + jsonschema >= 4.10, e.g. Debian 12's
python3-jsonschema 4.10.3):

    import contract
    c = contract.load("schemas")          # the schemas/ directory
    c.validate(doc, "result")             # raises jsonschema.ValidationError
    c.validate(status, "Job")             # any components/schemas name
    c.is_valid(problem, "Problem")        # True/False
    c.errors(req, "request")              # list of ValidationError, best first
    c.check_openapi()                     # raises ContractError listing every problem

Names: "request", "result", or a name of openapi.json components/schemas
("Job", "JobList", "Problem", "Health", "Request", "Result", ...).
"""
import copy
import json
import os
import re
import warnings
from urllib.parse import urldefrag, urljoin

import jsonschema
from jsonschema import Draft202012Validator

try:  # jsonschema >= 4.18 deprecates RefResolver; Debian 12 (4.10.3) has no `referencing`
    from jsonschema import RefResolver
except ImportError:  # pragma: no cover - every 4.x still exports it
    from jsonschema.validators import RefResolver

REQUEST_ID = "https://spinmodal.dev/schemas/request.schema.json"
RESULT_ID = "https://spinmodal.dev/schemas/result.schema.json"
# openapi.json has no $id (OpenAPI 3.1 documents cannot declare one): this is the
# base URI its "#/components/..." references are resolved against.
OPENAPI_URI = "https://spinmodal.dev/openapi.json"

# Component schemas other engineers' tests rely on.
REQUIRED_COMPONENTS = ("Job", "JobList", "Problem", "Request", "Result", "Health")

HTTP_METHODS = ("get", "put", "post", "delete", "options", "head", "patch", "trace")

ValidationError = jsonschema.ValidationError


class ContractError(AssertionError):
    """A contract document is broken; .problems lists every problem found."""

    def __init__(self, problems):
        self.problems = list(problems)
        super().__init__("%d contract problem(s):\n  %s" % (len(self.problems), "\n  ".join(self.problems)))


def _offline(uri):
    raise jsonschema.RefResolutionError(
        "reference to %s is not one of the local contract documents (no network access)" % uri)


def _read_json(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def _pointer_get(doc, fragment):
    """Resolve an RFC 6901 fragment ("" or "/a/b") in doc; KeyError if absent."""
    if fragment in ("", "/"):
        return doc
    if not fragment.startswith("/"):
        raise KeyError("not a JSON pointer: %r" % fragment)
    node = doc
    for raw in fragment[1:].split("/"):
        part = raw.replace("~1", "/").replace("~0", "~")
        if isinstance(node, list):
            if not re.fullmatch(r"0|[1-9][0-9]*", part) or int(part) >= len(node):
                raise KeyError(fragment)
            node = node[int(part)]
        elif isinstance(node, dict):
            if part not in node:
                raise KeyError(fragment)
            node = node[part]
        else:
            raise KeyError(fragment)
    return node


def _walk_refs(node, where=""):
    """Yield (json pointer of the $ref, $ref value) for every $ref in node."""
    if isinstance(node, dict):
        for key, value in node.items():
            esc = key.replace("~", "~0").replace("/", "~1")
            if key == "$ref" and isinstance(value, str):
                yield where + "/$ref", value
            else:
                yield from _walk_refs(value, where + "/" + esc)
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield from _walk_refs(value, "%s/%d" % (where, i))


def daemon_routes(daemon_md_text):
    """Routes of the '## Routes' table of server/DAEMON.md.

    Returns a list of (METHOD, path, [query parameter names]); the row
    `OPTIONS *` gives ("OPTIONS", "*", []).
    """
    routes = []
    in_routes = False
    for line in daemon_md_text.splitlines():
        if line.startswith("## "):
            in_routes = line.strip().lower() == "## routes"
            continue
        if not in_routes or not line.startswith("|"):
            continue
        m = re.match(r"^\|((?:[^|\\]|\\.)*)\|", line)
        if not m:
            continue
        for span in re.findall(r"`([^`]+)`", m.group(1)):
            sm = re.match(r"^([A-Z]+)\s+(\S+)$", span.replace("\\|", "|"))
            if not sm:
                continue
            method, target = sm.groups()
            path = re.split(r"[\[?]", target, maxsplit=1)[0]
            query = re.findall(r"[?&]([A-Za-z_][A-Za-z0-9_]*)=", target[len(path):])
            routes.append((method, path, query))
    return routes


class Contracts:
    """The three contract documents and validators over them."""

    def __init__(self, request, result, openapi, schemas_dir=None):
        self.request = request
        self.result = result
        self.openapi = openapi
        self.schemas_dir = schemas_dir
        self.store = {REQUEST_ID: request, RESULT_ID: result, OPENAPI_URI: openapi}

    # ------------------------------------------------------------ validation

    def names(self):
        """Every name validate() accepts."""
        comps = sorted(self.openapi.get("components", {}).get("schemas", {}))
        return ["request", "result"] + comps

    def _resolver(self, base_uri, referrer):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            return RefResolver(base_uri, referrer, store=dict(self.store),
                               handlers={"http": _offline, "https": _offline})

    def validator(self, name):
        """A new Draft202012Validator for name.

        Not cached: the RefResolver keeps a stack of base URIs, and some jsonschema
        versions (seen with 4.26) leave it unbalanced after a validation that went
        through a schema with its own $id, so each validation gets a fresh one.
        """
        if name == "request":
            schema, base, referrer = self.request, REQUEST_ID, self.request
        elif name == "result":
            schema, base, referrer = self.result, RESULT_ID, self.result
        else:
            comps = self.openapi.get("components", {}).get("schemas", {})
            if name not in comps:
                raise KeyError("unknown contract name %r; known: %s" % (name, ", ".join(self.names())))
            schema, base, referrer = comps[name], OPENAPI_URI, self.openapi
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            return Draft202012Validator(schema, resolver=self._resolver(base, referrer))

    def validate(self, instance, name):
        """Raise jsonschema.ValidationError (the most relevant error) unless instance matches name."""
        v = self.validator(name)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            error = jsonschema.exceptions.best_match(v.iter_errors(instance))
        if error is not None:
            raise error

    def errors(self, instance, name):
        """Every validation error of instance against name, most relevant first."""
        v = self.validator(name)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            errs = list(v.iter_errors(instance))
        return sorted(errs, key=jsonschema.exceptions.relevance)

    def is_valid(self, instance, name):
        return not self.errors(instance, name)

    # ------------------------------------------------------------- structure

    def check_schemas(self):
        """Each schema (and each OpenAPI component schema) is a valid 2020-12 schema."""
        problems = []
        docs = [("request.schema.json", self.request), ("result.schema.json", self.result)]
        docs += [("openapi.json#/components/schemas/" + k, s)
                 for k, s in self.openapi.get("components", {}).get("schemas", {}).items()]
        for what, schema in docs:
            try:
                Draft202012Validator.check_schema(schema)
            except jsonschema.SchemaError as e:
                problems.append("%s is not a valid 2020-12 schema: %s at %s"
                                % (what, e.message, "/" + "/".join(map(str, e.absolute_path))))
        for what, schema, want in (("request.schema.json", self.request, REQUEST_ID),
                                   ("result.schema.json", self.result, RESULT_ID)):
            if schema.get("$id") != want:
                problems.append("%s: $id is %r, want %r" % (what, schema.get("$id"), want))
            if schema.get("$schema") != "https://json-schema.org/draft/2020-12/schema":
                problems.append("%s: $schema is not 2020-12" % what)
        return problems

    def _resolve_ref(self, base, ref):
        """Resolve ref relative to base among the local documents; return the target."""
        url, fragment = urldefrag(urljoin(base, ref))
        if url not in self.store:
            raise KeyError("%s is not a local contract document" % url)
        return _pointer_get(self.store[url], fragment)

    def check_refs(self):
        """Every $ref of the three documents resolves locally."""
        problems = []
        for base, doc, name in ((REQUEST_ID, self.request, "request.schema.json"),
                                (RESULT_ID, self.result, "result.schema.json"),
                                (OPENAPI_URI, self.openapi, "openapi.json")):
            for where, ref in _walk_refs(doc):
                try:
                    self._resolve_ref(base, ref)
                except KeyError as e:
                    problems.append("%s#%s: $ref %r does not resolve (%s)" % (name, where, ref, e))
        return problems

    def check_openapi(self, daemon_md=None):
        """Structural checks of openapi.json; raises ContractError listing every problem.

        daemon_md: path of server/DAEMON.md (default: ../server/DAEMON.md next to
        the schemas directory, when it exists).  Returns a short summary dict.
        """
        api = self.openapi
        problems = []
        if not str(api.get("openapi", "")).startswith("3.1."):
            problems.append("openapi version is %r, want 3.1.x" % api.get("openapi"))
        for key in ("title", "version"):
            if not api.get("info", {}).get(key):
                problems.append("info.%s is missing" % key)
        comps = api.get("components", {})
        for name in REQUIRED_COMPONENTS:
            if name not in comps.get("schemas", {}):
                problems.append("components/schemas/%s is missing" % name)
        problems += self.check_refs()
        problems += self.check_schemas()

        paths = api.get("paths", {})
        if not paths:
            problems.append("no paths")
        op_ids = {}
        statuses = set()
        n_ops = 0
        for path, item in paths.items():
            if not path.startswith("/"):
                problems.append("path %r does not start with /" % path)
            if "$ref" in item:
                item = self._resolve_ref(OPENAPI_URI, item["$ref"])
            templated = set(re.findall(r"\{([^}]+)\}", path))
            path_params = item.get("parameters", [])
            for method in HTTP_METHODS:
                op = item.get(method)
                if op is None:
                    continue
                n_ops += 1
                where = "%s %s" % (method.upper(), path)
                oid = op.get("operationId")
                if not oid:
                    problems.append("%s: no operationId" % where)
                elif oid in op_ids:
                    problems.append("%s: operationId %r also used by %s" % (where, oid, op_ids[oid]))
                else:
                    op_ids[oid] = where
                resps = op.get("responses")
                if not isinstance(resps, dict) or not resps:
                    problems.append("%s: no responses" % where)
                    resps = {}
                declared = set()
                for p in list(path_params) + list(op.get("parameters", [])):
                    try:
                        p = self._resolve_ref(OPENAPI_URI, p["$ref"]) if "$ref" in p else p
                    except KeyError:
                        continue  # reported by check_refs
                    if p.get("in") == "path":
                        declared.add(p.get("name"))
                        if p.get("required") is not True:
                            problems.append("%s: path parameter %r must be required" % (where, p.get("name")))
                    if "schema" not in p and "content" not in p:
                        problems.append("%s: parameter %r has no schema" % (where, p.get("name")))
                if declared != templated:
                    problems.append("%s: path parameters %s, template has %s"
                                    % (where, sorted(declared), sorted(templated)))
                for status, r in resps.items():
                    if not re.fullmatch(r"[1-5][0-9][0-9]|[1-5]XX|default", str(status)):
                        problems.append("%s: bad response key %r" % (where, status))
                        continue
                    statuses.add(str(status))
                    try:
                        r = self._resolve_ref(OPENAPI_URI, r["$ref"]) if "$ref" in r else r
                    except KeyError:
                        continue
                    if not r.get("description"):
                        problems.append("%s %s: response has no description" % (where, status))
                    content = r.get("content", {})
                    if str(status)[0] in "45" and list(content) != ["application/problem+json"]:
                        problems.append("%s %s: error responses must be application/problem+json only, got %s"
                                        % (where, status, sorted(content)))
                    for mt, media in content.items():
                        if "schema" not in media:
                            problems.append("%s %s %s: no schema" % (where, status, mt))
                if "requestBody" in op and not op["requestBody"].get("content"):
                    problems.append("%s: requestBody without content" % where)
        problems += self._check_examples()
        problems += self._check_daemon_routes(daemon_md, statuses)
        if problems:
            raise ContractError(problems)
        return {"paths": len(paths), "operations": n_ops, "refs_checked": True,
                "statuses": sorted(statuses)}

    def _check_examples(self):
        """Every `example` of a media type, and every `value` of its `examples`, validates
        against its schema."""
        problems = []

        def media_types(node, where):
            if isinstance(node, dict):
                for k, v in node.items():
                    w = where + "/" + k.replace("~", "~0").replace("/", "~1")
                    if k == "content" and isinstance(v, dict):
                        for mt, media in v.items():
                            if not isinstance(media, dict) or "schema" not in media:
                                continue
                            mw = w + "/" + mt.replace("~", "~0").replace("/", "~1")
                            if "example" in media:
                                yield mw, media
                            for name, ex in (media.get("examples") or {}).items():
                                if isinstance(ex, dict) and "value" in ex:
                                    yield (mw + "/examples/" + name.replace("~", "~0").replace("/", "~1"),
                                           {"schema": media["schema"], "example": ex["value"]})
                    yield from media_types(v, w)
            elif isinstance(node, list):
                for i, v in enumerate(node):
                    yield from media_types(v, "%s/%d" % (where, i))

        for where, media in media_types(self.openapi, ""):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", DeprecationWarning)
                v = Draft202012Validator(media["schema"], resolver=self._resolver(OPENAPI_URI, self.openapi))
                try:
                    err = jsonschema.exceptions.best_match(v.iter_errors(media["example"]))
                except Exception as e:  # noqa: BLE001 - a broken schema: report, go on
                    first = (str(e).strip().splitlines() or [""])[0]
                    problems.append("openapi.json#%s: cannot check the example: %s: %s"
                                    % (where, type(e).__name__, first[:200]))
                    continue
            if err is not None:
                problems.append("openapi.json#%s/example does not match its schema: %s at %s"
                                % (where, err.message, "/" + "/".join(map(str, err.absolute_path))))
        return problems

    def _check_daemon_routes(self, daemon_md, statuses):
        """Every route of DAEMON.md's route table is in paths, with its query parameters."""
        if daemon_md is None and self.schemas_dir:
            guess = os.path.join(self.schemas_dir, os.pardir, "server", "DAEMON.md")
            daemon_md = guess if os.path.exists(guess) else None
        if daemon_md is None:
            return []
        with open(daemon_md, encoding="utf-8") as f:
            text = f.read()
        routes = daemon_routes(text)
        problems = []
        if not routes:
            return ["%s: no routes found in its '## Routes' table" % daemon_md]
        paths = self.openapi.get("paths", {})
        documented = set()
        for method, path, query in routes:
            if path == "*":  # OPTIONS *: every path answers OPTIONS (204 or 405)
                for p, item in paths.items():
                    if method.lower() not in item:
                        problems.append("DAEMON.md has `%s *` but path %s has no %s operation"
                                        % (method, p, method.lower()))
                continue
            documented.add(path)
            op = paths.get(path, {}).get(method.lower())
            if op is None:
                problems.append("DAEMON.md route `%s %s` is not in openapi.json paths" % (method, path))
                continue
            names = set()
            for p in list(paths[path].get("parameters", [])) + list(op.get("parameters", [])):
                try:
                    p = self._resolve_ref(OPENAPI_URI, p["$ref"]) if "$ref" in p else p
                except KeyError:
                    continue
                if p.get("in") == "query":
                    names.add(p.get("name"))
            for q in query:
                if q not in names:
                    problems.append("`%s %s`: query parameter %r of DAEMON.md is not declared" % (method, path, q))
        for path in paths:
            if path not in documented:
                problems.append("openapi.json path %s is not a route of DAEMON.md" % path)
        # every status of DAEMON.md's error table is used by some operation
        for status in re.findall(r"^\|\s*([45][0-9][0-9])\s*\|", text, flags=re.M):
            if status not in statuses:
                problems.append("status %s of DAEMON.md's error table is not a response of any operation" % status)
        return problems


def load(schemas_dir):
    """Read schemas_dir/{request.schema.json,result.schema.json,openapi.json}."""
    return Contracts(_read_json(os.path.join(schemas_dir, "request.schema.json")),
                     _read_json(os.path.join(schemas_dir, "result.schema.json")),
                     _read_json(os.path.join(schemas_dir, "openapi.json")),
                     schemas_dir=os.path.abspath(schemas_dir))


def mutated(contracts, edit):
    """A deep copy of contracts with edit(request, result, openapi) applied (for negative tests)."""
    req, res, api = copy.deepcopy((contracts.request, contracts.result, contracts.openapi))
    edit(req, res, api)
    return Contracts(req, res, api, schemas_dir=contracts.schemas_dir)
