#!/usr/bin/env node
// build.mjs — build the web front end into a directory spinmodald embeds.
//
//   node build.mjs --src clients/web --npm NPM --work BUILD/npm --out BUILD/site
//
// 1. copies package.json and package-lock.json into --work and runs
//    `npm ci --no-audit --no-fund --ignore-scripts` there, only when
//    node_modules is missing or the lock file changed (a stamp holds its hash);
// 2. bundles src/main.js with esbuild (uPlot included, CSS extracted) into
//    app.js + app.css, copies src/index.html, writes licenses.txt;
// 3. replaces --out as a whole (written beside it, then renamed), so the
//    directory is complete or absent and its mtime marks the build for ninja.
// Nothing is written into the source tree.  Works on Node 18 and later.

import {createHash} from 'node:crypto';
import {spawnSync} from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import {createRequire} from 'node:module';

function arg(name, def) {
  const i = process.argv.indexOf(name);
  if (i < 0 || i + 1 >= process.argv.length) {
    if (def !== undefined) return def;
    console.error(`build.mjs: missing ${name}`);
    process.exit(2);
  }
  return process.argv[i + 1];
}

const src = path.resolve(arg('--src'));
const work = path.resolve(arg('--work'));
const out = path.resolve(arg('--out'));
const npm = arg('--npm', 'npm');

function copyIfChanged(from, to) {
  const data = fs.readFileSync(from);
  if (!fs.existsSync(to) || !fs.readFileSync(to).equals(data)) fs.writeFileSync(to, data);
  return data;
}

// ---------------------------------------------------------------- npm ci
fs.mkdirSync(work, {recursive: true});
copyIfChanged(path.join(src, 'package.json'), path.join(work, 'package.json'));
const lock = copyIfChanged(path.join(src, 'package-lock.json'), path.join(work, 'package-lock.json'));
const want = createHash('sha256').update(lock).digest('hex');
const stamp = path.join(work, 'node_modules', '.spinmodal-lock-sha256');
const have = fs.existsSync(stamp) ? fs.readFileSync(stamp, 'utf8').trim() : '';
if (have !== want) {
  console.log(`build.mjs: npm ci in ${work}`);
  const r = spawnSync(npm, ['ci', '--no-audit', '--no-fund', '--ignore-scripts'], {
    cwd: work,
    stdio: 'inherit',
    env: {...process.env, npm_config_update_notifier: 'false', npm_config_loglevel: 'warn'},
  });
  if (r.error || r.status !== 0) {
    console.error(`build.mjs: npm ci failed (${r.error ? r.error.message : 'status ' + r.status}); ` +
      'the web front end needs the npm registry once to fetch its pinned packages');
    process.exit(1);
  }
  fs.writeFileSync(stamp, want + '\n');
}

// ---------------------------------------------------------------- bundle
const nodeModules = path.join(work, 'node_modules');
const require = createRequire(path.join(work, 'package.json'));
const esbuild = require('esbuild');
const tmp = out + '.tmp';
fs.rmSync(tmp, {recursive: true, force: true});
fs.mkdirSync(tmp, {recursive: true});

try {
  await esbuild.build({
    entryPoints: {app: path.join(src, 'src', 'main.js')},
    bundle: true,
    minify: true,
    format: 'iife',
    target: 'es2020',
    outdir: tmp,
    nodePaths: [nodeModules],
    legalComments: 'none',
    logLevel: 'warning',
    charset: 'utf8',
  });
} catch (e) {
  console.error('build.mjs: esbuild failed');
  process.exit(1);
}
fs.copyFileSync(path.join(src, 'src', 'index.html'), path.join(tmp, 'index.html'));
const uplotDir = path.dirname(require.resolve('uplot/package.json'));
const uplotVersion = JSON.parse(fs.readFileSync(path.join(uplotDir, 'package.json'), 'utf8')).version;
fs.writeFileSync(path.join(tmp, 'licenses.txt'),
  'Third-party software in the spinmodal web front end (app.js, app.css)\n\n' +
  `uPlot ${uplotVersion} — https://github.com/leeoniya/uPlot\n\n` +
  fs.readFileSync(path.join(uplotDir, 'LICENSE'), 'utf8'));

for (const f of ['app.js', 'app.css', 'index.html']) {
  if (!fs.existsSync(path.join(tmp, f))) {
    console.error(`build.mjs: ${f} was not produced`);
    process.exit(1);
  }
}
fs.rmSync(out, {recursive: true, force: true});
fs.renameSync(tmp, out);
const now = new Date();
fs.utimesSync(out, now, now);
const sizes = fs.readdirSync(out).map((f) => `${f} ${fs.statSync(path.join(out, f)).size} B`).join(', ');
console.log(`build.mjs: ${out}: ${sizes}`);
