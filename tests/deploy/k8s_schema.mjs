// tests/deploy/k8s_schema.mjs — validate deploy/k8s/*.yaml against the Kubernetes API
// schemas bundled by the npm package kubernetes-models (JSON schemas of the API's
// OpenAPI definitions, validated with ajv; no cluster, no network once installed).
// Run by hand (not registered in meson: it needs two npm packages, see deploy/configuration.md):
//   npm install --prefix /tmp/k8sval --no-audit --no-fund kubernetes-models@5.1.0 js-yaml@5.5.0
//   node tests/deploy/k8s_schema.mjs deploy/k8s /tmp/k8sval
// Catches wrong types and missing required fields (replicas: "two", no containers), not
// unknown fields (the schemas allow them): a misspelled optional field passes.
// Exit 0 when every object is valid, 1 otherwise.
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";
import { pathToFileURL } from "node:url";

const [dir, prefix] = process.argv.slice(2);
if (!dir || !prefix) {
  console.error("usage: node k8s_schema.mjs K8S_DIR NPM_PREFIX");
  process.exit(2);
}
const require = createRequire(path.join(path.resolve(prefix), "node_modules", "x.js"));
const yaml = require("js-yaml");
const models = path.dirname(require.resolve("kubernetes-models/package.json"));

let bad = 0;
let good = 0;
for (const f of fs.readdirSync(dir).filter((x) => x.endsWith(".yaml")).sort()) {
  for (const doc of yaml.loadAll(fs.readFileSync(path.join(dir, f), "utf8"))) {
    if (!doc || !doc.kind) continue;
    const what = `${f}: ${doc.apiVersion} ${doc.kind} ${doc.metadata?.name ?? ""}`;
    if (String(doc.apiVersion).startsWith("kustomize.config.k8s.io/")) {
      console.log(`skip ${what} (kustomize's file, not an API object)`);
      continue;
    }
    const pkg = JSON.parse(fs.readFileSync(path.join(models, "package.json"), "utf8"));
    const sub = pkg.exports?.[`./${doc.apiVersion}`];
    const file = sub && (sub.import?.default ?? sub.import ?? sub.default);
    const Cls = file && (await import(pathToFileURL(path.join(models, file)).href))[doc.kind];
    if (!Cls) {
      console.log(`FAIL ${what}: no schema for this kind`);
      bad++;
      continue;
    }
    try {
      new Cls(doc).validate();
      console.log(`ok   ${what}`);
      good++;
    } catch (e) {
      console.log(`FAIL ${what}: ${e.message}`);
      bad++;
    }
  }
}
console.log(`${good} valid, ${bad} invalid (kubernetes-models ${JSON.parse(fs.readFileSync(path.join(models, "package.json"), "utf8")).version})`);
process.exit(bad || !good ? 1 : 0);
