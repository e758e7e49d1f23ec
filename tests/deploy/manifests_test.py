#!/usr/bin/env python3
"""The deployment files of deploy/ are consistent with the daemon they deploy.

Usage: manifests_test.py --source-root DIR --spinmodald EXE --version V GROUP
       (GROUP: k8s, compose, nginxconf, all)

k8s        every YAML document of deploy/k8s/ parses and is listed in kustomization.yaml; the
           spinmodald Deployment has >= 2 replicas, a liveness probe on /livez and a readiness
           probe on /readyz at the container port (= the port of SPINMODAL_LISTEN), CPU and memory
           requests <= limits, runAsNonRoot with a non-zero runAsUser, readOnlyRootFilesystem, no
           privilege escalation, /tmp on an emptyDir, SPINMODAL_DB from a Secret key holding a
           postgresql:// URI (no literal anywhere), SPINMODAL_REPLICA_ID from the pod name, the
           token file on a mounted Secret key, workers <= the CPU limit, a termination grace
           above the shutdown grace; the image tag is the project version; every SPINMODAL_*
           name (env, ConfigMap) is a variable of `spinmodald --help`; the Service selects the
           pod labels (and nothing else) and targets the container port; the HPA targets the
           Deployment on CPU with minReplicas >= 2; the example PostgreSQL's Service, user,
           database and password are the DSN's; the PDB selects the pods.  Then kubectl, when
           installed: `kubectl kustomize` renders the same objects (offline), and `kubectl apply
           --dry-run=client -k` is tried (it needs an API server for discovery; without one
           that part is skipped with the reason printed).
compose    deploy/compose.yaml parses; the default profile is the one SQLite service; profile
           `replicas` has postgres, >= 2 spinmodald replicas (same image, unique
           SPINMODAL_REPLICA_ID, DSN to the postgres service with its user, database and
           password, waiting for it healthy, no SQLite volume) and an nginx `lb` that mounts
           deploy/nginx/spinmodal.conf, whose upstream lists exactly the replicas at their port.
nginxconf  deploy/nginx/spinmodal.conf: client_max_body_size = the --max-body default,
           proxy_read/send_timeout above the longest ?wait= (DAEMON.md), /metrics refused under
           the sub-path, Location of the daemon (/v1/…) rewritten into the sub-path.

Prints one line per check (ok / FAIL / SKIP); exit 1 when a check failed.  Needs PyYAML
(Debian python3-yaml, deploy/install-deps.sh).
"""
import argparse
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
from urllib.parse import urlsplit, unquote

try:
    import yaml
except ImportError:
    print("FAIL PyYAML is missing: apt-get install python3-yaml (deploy/install-deps.sh)")
    sys.exit(1)

SRC = DAEMON = VERSION = None
FAILURES = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        FAILURES.append(what)
    return bool(cond)


def skip(what):
    print("SKIP " + what, flush=True)


def read(rel):
    with open(os.path.join(SRC, rel), encoding="utf-8") as f:
        return f.read()


_HELP = None


def help_env():
    """{SPINMODAL_NAME: default text} from `spinmodald --help`."""
    global _HELP
    if _HELP is None:
        p = subprocess.run([DAEMON, "--help"], capture_output=True, text=True, timeout=30)
        _HELP = dict(re.findall(r"^\s+env (SPINMODAL_\w+), default (.*)$", p.stdout + p.stderr, re.M))
        check(p.returncode == 0 and len(_HELP) >= 15, "`spinmodald --help` lists the variables (%d)" % len(_HELP))
    return _HELP


def env_names_ok(names, where):
    real = help_env()
    bad = sorted(n for n in names if n.startswith("SPINMODAL_") and n not in real)
    check(names and not bad, "%s: every SPINMODAL_* variable is a flag of `spinmodald --help` (%d; unknown: %s)"
          % (where, len([n for n in names if n.startswith("SPINMODAL_")]), bad))


def quantity(q):
    """A Kubernetes quantity as a float (cores or bytes)."""
    q = str(q)
    m = re.fullmatch(r"([0-9.]+)(m|Ki|Mi|Gi|Ti|k|M|G|T)?", q)
    if not m:
        return None
    mult = {None: 1, "m": 1e-3, "Ki": 2 ** 10, "Mi": 2 ** 20, "Gi": 2 ** 30, "Ti": 2 ** 40,
            "k": 1e3, "M": 1e6, "G": 1e9, "T": 1e12}[m.group(2)]
    return float(m.group(1)) * mult


def selects(selector, labels):
    return bool(selector) and all(labels.get(k) == v for k, v in selector.items())


def listen_port(listen):
    m = re.search(r":(\d+)$", str(listen or ""))
    return int(m.group(1)) if m else None


# ================================================================ k8s

def load_k8s():
    d = os.path.join(SRC, "deploy", "k8s")
    docs, files = [], sorted(f for f in os.listdir(d) if f.endswith((".yaml", ".yml")))
    for f in files:
        try:
            with open(os.path.join(d, f), encoding="utf-8") as fh:
                parsed = [x for x in yaml.safe_load_all(fh) if x is not None]
        except yaml.YAMLError as e:
            check(False, "deploy/k8s/%s parses as YAML (%s)" % (f, e))
            continue
        check(parsed and all(isinstance(x, dict) and x.get("kind") and x.get("apiVersion") for x in parsed),
              "deploy/k8s/%s parses: %s" % (f, ", ".join("%s/%s" % (x.get("kind"), (x.get("metadata") or {}).get("name"))
                                                         for x in parsed if isinstance(x, dict))))
        docs += [(f, x) for x in parsed if isinstance(x, dict)]
    return files, docs


def find(docs, kind, name=None):
    return [x for _, x in docs if x.get("kind") == kind and (name is None or x["metadata"].get("name") == name)]


def t_k8s():
    files, docs = load_k8s()
    kust = [x for f, x in docs if x.get("kind") == "Kustomization"]
    if check(len(kust) == 1, "deploy/k8s has one kustomization.yaml"):
        res = kust[0].get("resources") or []
        others = sorted(f for f in files if f not in ("kustomization.yaml", "kustomization.yml"))
        check(sorted(res) == others, "kustomization.yaml lists every manifest (%s; files %s)" % (sorted(res), others))
    objs = [x for f, x in docs if x.get("kind") != "Kustomization"]
    names = [(x["kind"], x["metadata"].get("name")) for x in objs]
    check(len(set(names)) == len(names), "no two objects share a kind and name (%s)" % names)

    deps = [x for x in find(docs, "Deployment")
            if any(str(c.get("image", "")).split("/")[-1].startswith("spinmodald")
                   for c in x["spec"]["template"]["spec"].get("containers", []))]
    if not check(len(deps) == 1, "one Deployment runs the spinmodald image (%d)" % len(deps)):
        return
    dep = deps[0]
    spec, pod = dep["spec"], dep["spec"]["template"]["spec"]
    plabels = (dep["spec"]["template"].get("metadata") or {}).get("labels") or {}
    check(isinstance(spec.get("replicas"), int) and spec["replicas"] >= 2, "Deployment replicas >= 2 (%s)" % spec.get("replicas"))
    check(selects((spec.get("selector") or {}).get("matchLabels"), plabels),
          "the Deployment's selector matches its pod labels (%s)" % plabels)
    conts = [c for c in pod["containers"] if str(c.get("image", "")).split("/")[-1].startswith("spinmodald")]
    c = conts[0]

    # the image
    image = str(c.get("image", ""))
    tag = image.rsplit(":", 1)[1] if ":" in image.split("/")[-1] else None
    check(tag == VERSION, "the image %s is tagged with the project version %s" % (image, VERSION))

    # environment
    cms = {x["metadata"]["name"]: x for x in find(docs, "ConfigMap")}
    secrets = {x["metadata"]["name"]: x for x in find(docs, "Secret")}

    def secret_value(name, key):
        s = secrets.get(name) or {}
        if key in (s.get("stringData") or {}):
            return str(s["stringData"][key])
        if key in (s.get("data") or {}):
            import base64
            return base64.b64decode(s["data"][key]).decode()
        return None

    env = {e["name"]: e for e in c.get("env", [])}
    cm_env = {}
    for ef in c.get("envFrom", []):
        ref = (ef.get("configMapRef") or {}).get("name")
        if check(ref in cms, "envFrom configMapRef %s is a ConfigMap of deploy/k8s" % ref):
            data = cms[ref].get("data") or {}
            check(all(k.startswith("SPINMODAL_") for k in data), "ConfigMap %s holds SPINMODAL_* settings only (%s)"
                  % (ref, sorted(data)))
            check(all(isinstance(v, str) for v in data.values()), "ConfigMap %s values are strings" % ref)
            cm_env.update(data)
    env_names_ok(sorted(set(env) | set(cm_env)), "Deployment env + ConfigMap")
    db = env.get("SPINMODAL_DB") or {}
    ref = ((db.get("valueFrom") or {}).get("secretKeyRef")) or {}
    check("SPINMODAL_DB" not in cm_env and "value" not in db and ref.get("name") and ref.get("key"),
          "SPINMODAL_DB comes from a Secret key, not a literal (%s)" % ref)
    dsn = secret_value(ref.get("name"), ref.get("key")) if ref else None
    check(dsn is not None and re.match(r"^postgres(ql)?://", dsn),
          "Secret %s/%s is a postgresql:// DSN" % (ref.get("name"), ref.get("key")))
    check(not any(re.search(r"postgres(ql)?://", str(v)) for v in cm_env.values())
          and not any(re.search(r"postgres(ql)?://", str(e.get("value", ""))) for e in env.values()),
          "no DSN literal in the ConfigMap or the Deployment")
    rid = ((env.get("SPINMODAL_REPLICA_ID") or {}).get("valueFrom") or {}).get("fieldRef") or {}
    check(rid.get("fieldPath") == "metadata.name", "SPINMODAL_REPLICA_ID is the pod name (downward API) (%s)" % rid)
    tokfile = (env.get("SPINMODAL_TOKEN_FILE") or {}).get("value") or cm_env.get("SPINMODAL_TOKEN_FILE")
    vols = {v["name"]: v for v in pod.get("volumes", [])}
    mounts = c.get("volumeMounts", [])
    tok_ok = False
    if check(tokfile, "SPINMODAL_TOKEN_FILE is set (%s)" % tokfile):
        for m in mounts:
            mp = m["mountPath"].rstrip("/") + "/"
            v = vols.get(m["name"], {})
            if tokfile.startswith(mp) and "secret" in v:
                fname = tokfile[len(mp):]
                items = v["secret"].get("items")
                key = next((i["key"] for i in items if i["path"] == fname), None) if items else fname
                tok_ok = secret_value(v["secret"].get("secretName"), key) is not None and m.get("readOnly") is True
        check(tok_ok, "the token file %s is a key of a Secret mounted read-only" % tokfile)

    # probes
    ports = {p.get("name"): p["containerPort"] for p in c.get("ports", [])}
    cport = listen_port(cm_env.get("SPINMODAL_LISTEN") or (env.get("SPINMODAL_LISTEN") or {}).get("value"))
    check(cport is not None and cport in ports.values(),
          "the container port %s is the port of SPINMODAL_LISTEN (%s)" % (sorted(ports.values()), cport))

    def port_of(p):
        return ports.get(p) if isinstance(p, str) else p

    for probe, path in (("livenessProbe", "/livez"), ("readinessProbe", "/readyz")):
        g = (c.get(probe) or {}).get("httpGet") or {}
        check(g.get("path") == path and port_of(g.get("port")) == cport,
              "%s: GET %s on the container port (%s %s)" % (probe, path, g.get("path"), g.get("port")))
    # resources
    res = c.get("resources") or {}
    req, lim = res.get("requests") or {}, res.get("limits") or {}
    ok = all(quantity(req.get(k)) and quantity(lim.get(k)) and quantity(req[k]) <= quantity(lim[k]) for k in ("cpu", "memory"))
    check(ok, "resources: cpu and memory requests <= limits (%s / %s)" % (req, lim))
    workers = cm_env.get("SPINMODAL_WORKERS")
    check(workers and quantity(lim.get("cpu")) and int(workers) <= quantity(lim["cpu"]) + 1e-9,
          "SPINMODAL_WORKERS (%s) <= the CPU limit (%s)" % (workers, lim.get("cpu")))
    # security
    psc, csc = pod.get("securityContext") or {}, c.get("securityContext") or {}
    nonroot = csc.get("runAsNonRoot", psc.get("runAsNonRoot"))
    uid = csc.get("runAsUser", psc.get("runAsUser"))
    check(nonroot is True and isinstance(uid, int) and uid > 0, "non-root: runAsNonRoot %s, runAsUser %s" % (nonroot, uid))
    check(csc.get("readOnlyRootFilesystem") is True, "readOnlyRootFilesystem: true")
    check(csc.get("allowPrivilegeEscalation") is False and "ALL" in ((csc.get("capabilities") or {}).get("drop") or []),
          "no privilege escalation, all capabilities dropped")
    tmp = [m for m in mounts if m["mountPath"] == "/tmp"]
    check(tmp and "emptyDir" in vols.get(tmp[0]["name"], {}), "/tmp is an emptyDir (writable with a read-only root)")
    grace = int(cm_env.get("SPINMODAL_SHUTDOWN_GRACE") or re.sub(r"\D", "", help_env().get("SPINMODAL_SHUTDOWN_GRACE", "10")))
    pre = (((c.get("lifecycle") or {}).get("preStop") or {}).get("exec") or {}).get("command") or []
    pre_s = int(pre[1]) if len(pre) == 2 and pre[0] == "sleep" else 0
    tgp = pod.get("terminationGracePeriodSeconds", 30)
    check(tgp > grace + pre_s, "terminationGracePeriodSeconds %s > preStop %s s + shutdown grace %s s" % (tgp, pre_s, grace))

    # Service
    svcs = [s for s in find(docs, "Service") if selects(s["spec"].get("selector"), plabels)]
    if check(len(svcs) == 1, "one Service selects the spinmodald pods (%d)" % len(svcs)):
        s = svcs[0]
        other = [x["metadata"]["name"] for x in find(docs, "Deployment") + find(docs, "StatefulSet")
                 if x is not dep and selects(s["spec"]["selector"], (x["spec"]["template"].get("metadata") or {}).get("labels") or {})]
        check(not other, "the Service %s selects no other workload (%s)" % (s["metadata"]["name"], other))
        tps = [port_of(p.get("targetPort", p.get("port"))) for p in s["spec"].get("ports", [])]
        check(tps and all(tp == cport for tp in tps), "the Service targets the container port %s (%s)" % (cport, tps))
    # HPA
    hpas = find(docs, "HorizontalPodAutoscaler")
    if check(len(hpas) == 1, "one HorizontalPodAutoscaler"):
        h = hpas[0]["spec"]
        t = h.get("scaleTargetRef") or {}
        check(t.get("kind") == "Deployment" and t.get("name") == dep["metadata"]["name"] and t.get("apiVersion") == "apps/v1",
              "the HPA targets the Deployment %s (%s)" % (dep["metadata"]["name"], t))
        check(h.get("minReplicas", 1) >= 2 and h.get("maxReplicas", 0) >= h.get("minReplicas", 1),
              "HPA replicas %s..%s (min >= 2)" % (h.get("minReplicas"), h.get("maxReplicas")))
        cpu = [m for m in h.get("metrics", []) if m.get("type") == "Resource" and m["resource"]["name"] == "cpu"]
        check(cpu, "the HPA scales on CPU")
    for pdb in find(docs, "PodDisruptionBudget"):
        check(selects(pdb["spec"]["selector"].get("matchLabels"), plabels), "the PDB selects the spinmodald pods")

    # the example PostgreSQL
    sts = find(docs, "StatefulSet")
    if check(len(sts) == 1 and dsn, "one StatefulSet (the example PostgreSQL)"):
        pg = sts[0]
        pglabels = pg["spec"]["template"]["metadata"]["labels"]
        pgc = pg["spec"]["template"]["spec"]["containers"][0]
        pgenv = {e["name"]: e for e in pgc.get("env", [])}
        u = urlsplit(dsn)
        pgsvc = [s for s in find(docs, "Service") if selects(s["spec"].get("selector"), pglabels)]
        check(pgsvc and u.hostname == pgsvc[0]["metadata"]["name"]
              and (u.port or 5432) in [p["port"] for p in pgsvc[0]["spec"]["ports"]],
              "the DSN's host:port %s:%s is the PostgreSQL Service" % (u.hostname, u.port))
        check(unquote(u.username or "") == (pgenv.get("POSTGRES_USER") or {}).get("value")
              and u.path.lstrip("/") == (pgenv.get("POSTGRES_DB") or {}).get("value"),
              "the DSN's user and database are POSTGRES_USER and POSTGRES_DB")
        pref = ((pgenv.get("POSTGRES_PASSWORD") or {}).get("valueFrom") or {}).get("secretKeyRef") or {}
        check(pref and unquote(u.password or "") == secret_value(pref.get("name"), pref.get("key")),
              "the DSN's password is the PostgreSQL's POSTGRES_PASSWORD (from a Secret)")
        check(pg["spec"].get("volumeClaimTemplates"), "PostgreSQL keeps its data on a PersistentVolumeClaim")
    text = read("deploy/k8s/secret.example.yaml")
    check(all("EXAMPLE" in str(v) for s in secrets.values() for v in (s.get("stringData") or {}).values())
          and "EXAMPLE" in text.split("apiVersion")[0],
          "every example Secret value is marked EXAMPLE")

    kubectl(objs)


def kubectl(objs):
    exe = shutil.which("kubectl")
    if not exe:
        skip("kubectl: not installed (Debian: kubernetes-client); the manifests were checked without it")
        return
    kdir = os.path.join(SRC, "deploy", "k8s")
    tmp = tempfile.mkdtemp(prefix="spinmodal-kubectl-")
    try:
        # No kubeconfig of the machine may be used: a throwaway one pointing at a closed port.
        s = socket.socket()
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
        s.close()
        kc = os.path.join(tmp, "config")
        with open(kc, "w") as f:
            f.write("apiVersion: v1\nkind: Config\nclusters: [{name: none, cluster: {server: 'http://127.0.0.1:%d'}}]\n"
                    "contexts: [{name: none, context: {cluster: none, user: none}}]\nusers: [{name: none, user: {}}]\n"
                    "current-context: none\n" % port)
        env = dict(os.environ, KUBECONFIG=kc, HOME=tmp)
        v = subprocess.run([exe, "version", "--client"], capture_output=True, text=True, timeout=60, env=env)
        print("     kubectl: %s" % " ".join((v.stdout or v.stderr).split())[:120])
        p = subprocess.run([exe, "kustomize", kdir], capture_output=True, text=True, timeout=120, env=env)
        if check(p.returncode == 0, "`kubectl kustomize deploy/k8s` renders (%s)" % p.stderr.strip()[-300:]):
            rendered = sorted((x["kind"], x["metadata"]["name"]) for x in yaml.safe_load_all(p.stdout) if x)
            want = sorted((x["kind"], x["metadata"]["name"]) for x in objs)
            check(rendered == want, "kustomize renders exactly the manifests' objects (%d)" % len(want))
        p = subprocess.run([exe, "apply", "--dry-run=client", "-k", kdir], capture_output=True, text=True, timeout=120, env=env)
        err = p.stderr.strip()
        if p.returncode != 0 and re.search(r"connection refused|unable to recognize|failed to download openapi|"
                                           r"couldn't get current server API group list|no such host", err):
            skip("`kubectl apply --dry-run=client -k deploy/k8s`: kubectl needs an API server even for a client "
                 "dry run (discovery, OpenAPI) and none runs here: %s" % err.splitlines()[-1][:200])
        else:
            check(p.returncode == 0, "`kubectl apply --dry-run=client -k deploy/k8s` (%s%s)" % (p.stdout.strip()[-300:], err[-300:]))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


# ================================================================ compose

def nginx_upstream(text):
    """[(host, port)] of the `upstream spinmodal` block."""
    m = re.search(r"^\s*upstream\s+\w+\s*\{(.*?)\}", text, re.S | re.M)
    if not m:
        return []
    return [(h, int(p)) for h, p in re.findall(r"^\s*server\s+([\w.-]+):(\d+)\b", m.group(1), re.M)]


def t_compose():
    try:
        doc = yaml.safe_load(read("deploy/compose.yaml"))
    except yaml.YAMLError as e:
        check(False, "deploy/compose.yaml parses (%s)" % e)
        return
    svcs = doc.get("services") or {}
    check(svcs, "deploy/compose.yaml parses: services %s" % sorted(svcs))
    default = sorted(n for n, s in svcs.items() if not s.get("profiles"))
    check(default == ["spinmodald"], "the default profile is the one spinmodald service (%s)" % default)
    d = svcs.get("spinmodald") or {}
    denv = d.get("environment") or {}
    check(not re.match(r"^postgres", str(denv.get("SPINMODAL_DB", ""))) and str(denv.get("SPINMODAL_DB", "")).startswith("/var/lib/spinmodal/"),
          "the default service keeps SQLite on its volume (%s)" % denv.get("SPINMODAL_DB"))
    env_names_ok(sorted(denv), "compose service spinmodald")
    check(d.get("image") == "spinmodald:${SPINMODAL_VERSION:-%s}" % VERSION, "the default image tag is the version (%s)" % d.get("image"))

    prof = {n: s for n, s in svcs.items() if "replicas" in (s.get("profiles") or [])}
    pgs = [n for n, s in prof.items() if str(s.get("image", "")).startswith("postgres:")]
    reps = sorted(n for n, s in prof.items() if s.get("image") == d.get("image"))
    lbs = [n for n, s in prof.items() if str(s.get("image", "")).startswith("nginx:")]
    check(len(pgs) == 1 and len(reps) >= 2 and len(lbs) == 1 and len(prof) == 2 + len(reps),
          "profile replicas: one postgres, >= 2 spinmodald replicas, one nginx (%s %s %s)" % (pgs, reps, lbs))
    if not (pgs and reps and lbs):
        return
    pg = prof[pgs[0]]
    penv = pg.get("environment") or {}
    check(pg.get("healthcheck") and pg.get("volumes"), "postgres has a health check and a volume")
    ids, ports = [], set()
    for n in reps:
        s = prof[n]
        e = s.get("environment") or {}
        env_names_ok(sorted(e), "compose service %s" % n)
        dsn = str(e.get("SPINMODAL_DB", ""))
        m = re.match(r"^postgres(?:ql)?://([^:@/]+):(.+)@([\w.-]+):(\d+)/(\w+)$", dsn)
        check(m and m.group(3) == pgs[0] and m.group(4) == "5432" and m.group(1) == penv.get("POSTGRES_USER")
              and m.group(2) == penv.get("POSTGRES_PASSWORD") and m.group(5) == penv.get("POSTGRES_DB"),
              "%s: SPINMODAL_DB is the postgres service with its user, password and database (%s)" % (n, dsn))
        dep = s.get("depends_on") or {}
        check(isinstance(dep, dict) and (dep.get(pgs[0]) or {}).get("condition") == "service_healthy",
              "%s waits for postgres to be healthy" % n)
        check(not s.get("volumes") and s.get("read_only") is True, "%s: no SQLite volume, read-only root" % n)
        ids.append(e.get("SPINMODAL_REPLICA_ID"))
        ports.add(listen_port(e.get("SPINMODAL_LISTEN")))
    check(all(ids) and len(set(ids)) == len(ids), "every replica has its own SPINMODAL_REPLICA_ID (%s)" % ids)
    lb = prof[lbs[0]]
    conf = [v.split(":")[0] for v in lb.get("volumes", []) if v.split(":")[1].startswith("/etc/nginx/")]
    check(conf == ["./nginx/spinmodal.conf"] and os.path.exists(os.path.join(SRC, "deploy", "nginx", "spinmodal.conf")),
          "the nginx service mounts deploy/nginx/spinmodal.conf (%s)" % conf)
    ups = nginx_upstream(read("deploy/nginx/spinmodal.conf"))
    check(sorted(ups) == sorted((n, p) for n in reps for p in ports) and len(ports) == 1,
          "nginx's upstream is exactly the replicas at their port (%s)" % ups)
    check(sorted(lb.get("depends_on") or {}) == reps, "nginx starts after the replicas")
    check(all(str(p).startswith("127.0.0.1:") for p in lb.get("ports", [])) and lb.get("ports"),
          "nginx is published on loopback (%s)" % lb.get("ports"))
    check(not pg.get("ports"), "postgres is not published")
    for tool in (["docker", "compose"], ["podman-compose"], ["docker-compose"]):
        if shutil.which(tool[0]):
            p = subprocess.run(tool + ["-f", os.path.join(SRC, "deploy", "compose.yaml"), "--profile", "replicas",
                                       "config", "-q"], capture_output=True, text=True, timeout=60)
            if p.returncode == 0:
                check(True, "`%s config` accepts deploy/compose.yaml" % " ".join(tool))
                return
            print("     (%s config: %s)" % (" ".join(tool), (p.stderr.strip().splitlines() or ["?"])[-1][:160]))
    skip("no working compose implementation (docker compose, podman-compose, docker-compose) to run `config`: "
         "the file was checked by the rules above only")


# ================================================================ nginx conf (static)

def seconds(v):
    m = re.fullmatch(r"(\d+)(ms|s|m)?", v)
    return None if not m else int(m.group(1)) * {"ms": 0.001, "s": 1, None: 1, "m": 60}[m.group(2)]


def t_nginxconf():
    text = read("deploy/nginx/spinmodal.conf")
    code = re.sub(r"#.*", "", text)
    m = re.search(r"\bclient_max_body_size\s+(\d+)([kKmM]?)\s*;", code)
    body = int(m.group(1)) * {"": 1, "k": 1024, "m": 2 ** 20}[m.group(2).lower()] if m else None
    want = int(re.sub(r"\D.*", "", help_env().get("SPINMODAL_MAX_BODY", "x")) or 0)
    check(body == want, "client_max_body_size (%s) = spinmodald's --max-body default (%s)" % (body, want))
    dm = re.search(r"0 ≤ S ≤ (\d+)", read("server/DAEMON.md"))
    wmax = int(dm.group(1)) if dm else 60
    for d in ("proxy_read_timeout", "proxy_send_timeout"):
        m = re.search(r"\b%s\s+(\w+)\s*;" % d, code)
        v = seconds(m.group(1)) if m else None
        check(v is not None and v > wmax, "%s (%s s) is above the longest ?wait= (%s s)" % (d, v, wmax))
    loc = re.search(r"location\s+(/[\w/-]*/)\s*\{(.*?)\n\s*\}", code, re.S)
    if not check(loc, "a location /PREFIX/ proxies the API"):
        return
    prefix, block = loc.group(1), loc.group(2)
    check(re.search(r"proxy_pass\s+http://\w+/\s*;", block), "%s strips the prefix (proxy_pass with a URI /)" % prefix)
    check(re.search(r"proxy_redirect\s+/\s+%s\s*;" % re.escape(prefix), block),
          "the daemon's Location /v1/… is rewritten into %s (proxy_redirect / %s)" % (prefix, prefix))
    mm = re.search(r"location\s+=\s+%smetrics\s*\{([^}]*)\}" % re.escape(prefix), code)
    check(mm and re.search(r"\b(deny\s+all|return\s+40\d)\b", mm.group(1)), "%smetrics is refused" % prefix)


GROUPS = {"k8s": t_k8s, "compose": t_compose, "nginxconf": t_nginxconf}


def main():
    global SRC, DAEMON, VERSION
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--source-root", required=True)
    ap.add_argument("--spinmodald", required=True)
    ap.add_argument("--version", required=True, help="meson.project_version()")
    ap.add_argument("group", choices=list(GROUPS) + ["all"])
    a = ap.parse_args()
    SRC, DAEMON, VERSION = os.path.abspath(a.source_root), os.path.abspath(a.spinmodald), a.version
    for g in (GROUPS if a.group == "all" else [a.group]):
        print("== " + g, flush=True)
        try:
            GROUPS[g]()
        except Exception as e:  # a crash is a failure, with its cause
            import traceback
            traceback.print_exc()
            check(False, "%s: raised %r" % (g, e))
    print("%d failure(s)" % len(FAILURES))
    for f in FAILURES:
        print("  FAIL " + f)
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
