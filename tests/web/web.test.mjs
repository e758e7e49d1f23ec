#!/usr/bin/env node
// web.test.mjs — the web front end in a real browser (Debian's chromium driven
// by playwright-core) against a spinmodald on a loopback port.
//
// Environment (set by tests/web/meson.build):
//   SPINMODALD              the daemon executable
//   SPINMODAL_NODE_MODULES  node_modules holding playwright-core (clients/web's npm dir)
//   SPINMODAL_SCREENSHOTS   where screenshots are written
//   SPINMODAL_EXAMPLES      the repository's examples/ (the spatial examples the page loads)
//   CHROMIUM                browser executable (default /usr/bin/chromium)
//   SPINMODAL_TEST_CLI, SPINMODAL_TEST_TIME_FACTOR, SPINMODAL_TEST_TIMEOUT
//                           time budgets, as in tests/e2e/timescale.py: every wait
//                           polls for its condition and gives up after a base budget
//                           times a factor (a reference solve by the CLI measured at
//                           the start, or the announced factor), never past meson's
//                           timeout
// Exit status: 0 all checks passed, 1 a check failed, 77 skipped (no browser
// or no playwright-core).  Prints one "ok"/"not ok" line per check and a
// closing "N passed, N failed" line.

import {spawn, spawnSync} from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import {createRequire} from 'node:module';

const DAEMON = process.env.SPINMODALD;
const NODE_MODULES = process.env.SPINMODAL_NODE_MODULES || '';
const SHOTS = process.env.SPINMODAL_SCREENSHOTS || path.join(process.cwd(), 'screenshots');
const EXAMPLES = process.env.SPINMODAL_EXAMPLES || new URL('../../examples', import.meta.url).pathname;
const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
const SKIP = 77;

function skip(why) {
  console.log(`SKIP: ${why}`);
  process.exit(SKIP);
}

if (!fs.existsSync(CHROMIUM)) skip(`${CHROMIUM} not found (apt-get install chromium; deploy/install-deps.sh does)`);
let chromium;
try {
  const require = createRequire(path.join(NODE_MODULES || process.cwd(), 'x.js'));
  ({chromium} = require('playwright-core'));
} catch (e) {
  skip(`playwright-core not found under ${NODE_MODULES || '(SPINMODAL_NODE_MODULES unset)'}: ${e.message.split('\n')[0]}`);
}
if (!DAEMON || !fs.existsSync(DAEMON)) {
  console.error(`SPINMODALD not set or missing: ${DAEMON}`);
  process.exit(1);
}

// ------------------------------------------------------------------ checks
let passed = 0, failed = 0;
function ok(cond, what, detail = '') {
  if (cond) {
    passed++;
    console.log(`ok ${passed + failed} - ${what}`);
  } else {
    failed++;
    console.log(`not ok ${passed + failed} - ${what}${detail ? ': ' + detail : ''}`);
  }
  return cond;
}

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// ------------------------------------------------------------------ time (tests/e2e/timescale.py)
const T_START = Date.now();
const TS = JSON.parse(fs.readFileSync(new URL('../e2e/timescale.json', import.meta.url), 'utf8'));
const envFactor = Math.max(1, Number(process.env.SPINMODAL_TEST_TIME_FACTOR || 1) || 1);

/** Median wall time (s) of 3 reference solves by the CLI, or null. */
function referenceSolveSeconds(cli) {
  const times = [];
  for (let i = 0; i < 3; i++) {
    const t0 = Date.now();
    const p = spawnSync(cli, ['solve', '-'], {input: JSON.stringify(TS.reference_request),
      env: {...process.env, OPENBLAS_NUM_THREADS: '1', OMP_NUM_THREADS: '1'}, stdio: ['pipe', 'ignore', 'ignore'],
      timeout: 60000 * TS.max_factor});
    if (p.status !== 0) return null;
    times.push((Date.now() - t0) / 1000);
  }
  return times.sort((a, b) => a - b)[1];
}

const FACTOR = (() => {
  const cli = process.env.SPINMODAL_TEST_CLI;
  const t = cli && fs.existsSync(cli) ? referenceSolveSeconds(cli) : null;
  const cal = t === null ? 1 : Math.max(1, t / TS.nominal_solve_s);
  const f = Math.min(TS.max_factor, Math.max(envFactor, cal));
  console.log(`# timescale: ${t === null ? 'no calibration (no CLI)' : `reference solve ${t.toFixed(3)} s ` +
    `(nominal ${TS.nominal_solve_s} s) -> ${cal.toFixed(2)}`}; SPINMODAL_TEST_TIME_FACTOR ${envFactor}; ` +
    `factor ${f.toFixed(2)}`);
  return f;
})();
const HARD_MS = Number(process.env.SPINMODAL_TEST_TIMEOUT) > 0
  ? Number(process.env.SPINMODAL_TEST_TIMEOUT) * envFactor * 1000 : null;

/** ms on this machine's scale (for a fixed interval of a negative check). */
const scaledMs = (ms) => ms * FACTOR;

/** Upper bound (ms) of a wait that needs well under baseMs unloaded: scaled, and cut to
 *  end before meson kills the test (minus a margin to report it). */
function budgetMs(baseMs) {
  let b = baseMs * FACTOR;
  if (HARD_MS !== null) {
    const margin = Math.min(30000, Math.max(3000, 0.1 * HARD_MS));
    const left = HARD_MS - margin - (Date.now() - T_START);
    if (left < b) b = Math.max(500, left);
  }
  return Math.round(b);
}

// ------------------------------------------------------------------ daemon
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'spinmodal-web-'));
const daemons = [];
let daemonLog = '';

/** Start spinmodald on a free loopback port; resolves to its base URL. */
function startDaemon(name, extra = []) {
  return new Promise((resolve, reject) => {
    const proc = spawn(DAEMON, ['--listen', '127.0.0.1:0', '--db', path.join(tmp, name + '.db'), '--workers', '2',
      ...extra], {stdio: ['ignore', 'ignore', 'pipe'], env: {...process.env, OPENBLAS_NUM_THREADS: '1'}});
    daemons.push(proc);
    const limit = budgetMs(30000);
    const timer = setTimeout(() => reject(new Error(`no "event=listening" line within ${limit / 1000} s`)), limit);
    let buf = '';
    proc.stderr.setEncoding('utf8');
    proc.stderr.on('data', (d) => {
      daemonLog += d;
      buf += d;
      const m = /event=listening\s+addr=(\S+)/.exec(buf);
      if (m) {
        clearTimeout(timer);
        buf = '';
        resolve(`http://${m[1]}`);
      }
    });
    proc.on('exit', (code, sig) => {
      clearTimeout(timer);
      reject(new Error(`spinmodald exited (${code ?? sig}) before listening:\n${daemonLog}`));
    });
  });
}

async function stopDaemons() {
  for (const proc of daemons) {
    if (proc.exitCode !== null || proc.signalCode !== null) continue;
    const done = new Promise((r) => proc.once('exit', r));
    proc.kill('SIGTERM');
    const t = setTimeout(() => proc.kill('SIGKILL'), budgetMs(15000));
    await done;
    clearTimeout(t);
  }
}

// ------------------------------------------------------------------ helpers
async function shot(page, name) {
  fs.mkdirSync(SHOTS, {recursive: true});
  const file = path.join(SHOTS, name);
  await page.screenshot({path: file, fullPage: true});
  console.log(`# screenshot ${file}`);
}

/** Poll fn in the page until it is true; false after budgetMs(timeout). */
async function waitFor(page, fn, arg, what, timeout = 15000) {
  const limit = budgetMs(timeout);
  try {
    await page.waitForFunction(fn, arg, {timeout: limit, polling: 100});
    return true;
  } catch (e) {
    console.log(`# timed out waiting for ${what} (${limit / 1000} s)`);
    return false;
  }
}

/** Message shown next to a control: the text of its aria-describedby element. */
async function messageOf(page, locator) {
  return locator.evaluate((el) => {
    const id = el.getAttribute('aria-describedby');
    const m = id && document.getElementById(id.split(' ')[0]);
    return m ? m.textContent : '';
  });
}

/** Coordinates of the member lines of the structure drawing. */
function memberLines(page) {
  return page.$$eval('#structure-svg line.member', (ls) => ls.map((l) => ['x1', 'y1', 'x2', 'y2']
    .map((a) => Number(l.getAttribute(a)))));
}

/** Drag across the middle of an svg by (dx, dy) px, in steps as a hand would. */
async function drag(page, sel, dx, dy) {
  const loc = page.locator(sel);
  await loc.scrollIntoViewIfNeeded();
  const b = await loc.boundingBox();
  const x = b.x + b.width / 2, y = b.y + b.height / 2;
  await page.mouse.move(x, y);
  await page.mouse.down();
  await page.mouse.move(x + dx, y + dy, {steps: 8});
  await page.mouse.up();
}

/** Points "x y" of an SVG path ("M x y L x y …"). */
function pathPoints(d) {
  const v = (d.match(/-?\d+(\.\d+)?(e-?\d+)?/g) || []).map(Number);
  const out = [];
  for (let i = 0; i + 1 < v.length; i += 2) out.push([v[i], v[i + 1]]);
  return out;
}

/**
 * Spatial structures (DESIGN.md 7) through the real page and daemon: each
 * spatial example loads from examples/, is drawn in 3D, turns when dragged
 * and back with Reset, solves; the flapping blade's first mode at rest (a flap
 * mode) moves the drawn nodes out of the hub plane by what the result says;
 * a table and a JSON edit of a spatial request keep its spatial data and solve.
 */
async function spatial(page, base) {
  const cases = [
    {key: 'flapping-blade', file: 'flapping-blade.json', members: 1, elements: 24, speeds: 6},
    {key: 'out-of-plane-arm', file: 'out-of-plane-arm.json', members: 2, elements: 32, speeds: 1},
  ];
  for (const c of cases) {
    const want = JSON.parse(fs.readFileSync(path.join(EXAMPLES, c.file), 'utf8'));
    await page.selectOption('#example', c.key);
    ok(/Spatial/.test(await page.textContent('#example-desc')), `${c.key}: the example list describes it`,
      await page.textContent('#example-desc'));
    await page.click('#load-example');
    const doc = await page.evaluate(() => JSON.parse(window.__spinmodal.request));
    ok(JSON.stringify(doc) === JSON.stringify(want), `${c.key}: the page loads examples/${c.file}`,
      JSON.stringify(doc).slice(0, 200));
    ok(await page.isChecked('#spatial') && await page.isChecked('#view-3d'),
      `${c.key}: shown as a spatial model, in the 3D view`);
    const view = await page.evaluate(() => window.__spinmodal.view());
    const lines0 = await memberLines(page);
    ok(view.structure === '3d' && lines0.length === c.members, `${c.key}: the 3D view draws ${c.members} member(s)`,
      `${view.structure}, ${lines0.length}`);
    ok(await page.locator('#structure-svg .triad line').count() === 3, `${c.key}: the x, y, z triad is drawn`);
    if (c.key === 'out-of-plane-arm') {
      // the mast C -> P (along z) stands up on the screen: z is up in every view the user can reach
      const [x1, y1, x2, y2] = lines0[1];
      ok(y1 - y2 > 40 && Math.abs(x2 - x1) < 0.2 * (y1 - y2), 'out-of-plane-arm: the mast along z is drawn upright',
        JSON.stringify(lines0[1]));
      ok(await page.getByLabel('z of joint P (m)').inputValue() === '2' &&
        await page.getByLabel('flap direction (x, y, z) of member 2').inputValue() === '1, 0, 0',
      'out-of-plane-arm: z and the flap direction in the tables');
    }

    // turning the view: dragging changes the drawing, Reset brings it back
    await drag(page, '#structure-svg', 120, 40);
    const turned = await page.evaluate(() => window.__spinmodal.view());
    const lines1 = await memberLines(page);
    ok(turned.az !== view.az && turned.el !== view.el && JSON.stringify(lines1) !== JSON.stringify(lines0),
      `${c.key}: dragging turns the view (az ${view.az} -> ${turned.az}, el ${view.el} -> ${turned.el})`,
      JSON.stringify([lines0[0], lines1[0]]));
    await shot(page, `07-${c.key}-turned.png`);
    await page.click('#view-reset');
    ok(JSON.stringify(await memberLines(page)) === JSON.stringify(lines0), `${c.key}: Reset view restores the drawing`);

    // solve with the real daemon
    await page.click('#submit');
    const done = await waitFor(page, () => ['done', 'failed', 'canceled', 'rejected'].includes(document.body.dataset.jobState),
      null, `the ${c.key} job`, 180000);
    const state = await page.evaluate(() => document.body.dataset.jobState);
    if (!ok(done && state === 'done', `${c.key}: the spatial job runs to done`,
      `${state}: ${await page.textContent('#job-status')}; ${JSON.stringify(await page.evaluate(() =>
        window.__spinmodal.errors()))}`.slice(0, 600))) {
      continue;
    }
    const job = await page.evaluate(() => window.__spinmodal.job);
    const result = await (await fetch(`${base}/v1/analyses/${job.id}/result`)).json();
    ok(result.model && result.model.spatial === true && result.model.dof_per_node === 6 &&
      result.cases.length === c.speeds, `${c.key}: the result is spatial (6 values per node), ${c.speeds} speed(s)`,
    JSON.stringify(result.model));
    ok(await waitFor(page, () => window.__spinmodal.result && document.getElementById('equilibrium-path'), null,
      'the steady shape'), `${c.key}: the steady shape is drawn`);
    const eqSegs = ((await page.getAttribute('#structure-svg #equilibrium-path', 'd')) || '').split('L').length - 1;
    ok(eqSegs === c.elements, `${c.key}: steady shape: one segment per element`, String(eqSegs));
    const modeRows = await page.locator('#freq-table tbody tr').count();
    ok(modeRows === c.speeds, `${c.key}: frequency table: one row per speed`, String(modeRows));
    ok(await waitFor(page, () => window.__spinmodal.anim().view === '3d' && window.__spinmodal.anim().drawn, null,
      'the 3D mode view'), `${c.key}: the mode shape is animated in 3D`);

    if (c.key === 'flapping-blade') await flapMode(page, result);
    await shot(page, `08-${c.key}-result.png`);

    // the mode view turns too, and with it the structure drawing (one camera)
    const m0 = await page.evaluate(() => window.__spinmodal.anim());
    const s0 = await memberLines(page);
    await page.click('#mode-play'); // paused: only the turn can change the path
    const p0 = await page.evaluate(() => window.__spinmodal.anim().path);
    await drag(page, '#mode-svg', -90, 30);
    const p1 = await page.evaluate(() => window.__spinmodal.anim().path);
    ok(p1 !== p0 && JSON.stringify(await memberLines(page)) !== JSON.stringify(s0),
      `${c.key}: dragging the mode view turns both views`, `${m0.frame}`);
    await page.click('#mode-view-reset');
    await page.click('#mode-play');
  }

  // a spatial request edited in the tables and as JSON keeps its spatial data and solves
  await page.selectOption('#example', 'out-of-plane-arm');
  await page.click('#load-example');
  await page.getByLabel('z of joint P (m)').fill('2.5');
  await page.getByLabel('EI_flap (N·m²) of section sq').fill('15000');
  let doc = await page.evaluate(() => JSON.parse(window.__spinmodal.request));
  const sq = doc.structure.sections.sq;
  ok(JSON.stringify(doc.structure.joints.P) === '[3,0,2.5]' && sq.EI_flap === 15000 && sq.GJ === 10758 &&
    sq.flap_inertia === 1.549e-4 && !('E' in sq) && JSON.stringify(doc.structure.members[1].flap_direction) === '[1,0,0]',
  'spatial table edits keep z, the spatial section data and the flap direction', JSON.stringify(doc.structure));
  const text = (await page.inputValue('#json')).replace(/("id": "mast"[^}]*"elements": )16/, '$112');
  await page.fill('#json', text);
  doc = await page.evaluate(() => window.__spinmodal.doc);
  ok(doc.structure.members[1].elements === 12 && await page.getByLabel('elements of member 2').inputValue() === '12',
    'a JSON edit of a spatial request updates the tables');
  await page.click('#submit');
  await waitFor(page, () => ['done', 'failed', 'canceled', 'rejected'].includes(document.body.dataset.jobState), null,
    'the edited spatial job', 180000);
  const st = await page.evaluate(() => [document.body.dataset.jobState, window.__spinmodal.result &&
    window.__spinmodal.result.model]);
  ok(st[0] === 'done' && st[1] && st[1].nodes === 1 + 16 + 12 && st[1].spatial === true,
    'the edited spatial request solves (1 + 16 + 12 nodes)', JSON.stringify(st));
  if (st[0] === 'done') {
    ok(await waitFor(page, (n) => window.__spinmodal.anim().drawn && window.__spinmodal.anim().drawn.world.length === n,
      29, 'the mode of the edited arm'), 'its modes are drawn for the edited mesh');
  }
  await shot(page, '09-out-of-plane-arm-edited.png');

  // back to a planar example: the planar view again
  await page.selectOption('#example', 'angled-90');
  await page.click('#load-example');
  ok(await page.evaluate(() => window.__spinmodal.view().structure) === 'plane' && !await page.isChecked('#spatial'),
    'a planar example after a spatial one: planar tables and the hub-plane view');
}

/**
 * The flapping blade's first mode at rest is a flap mode (z): the animated
 * drawing moves its nodes out of the hub plane by amp·(re·cos θ − im·sin θ)
 * of the result's shape rows, and #mode-path is the projection drawn.
 */
async function flapMode(page, result) {
  const ci = result.cases.findIndex((k) => k.omega === 0);
  const c0 = result.cases[ci];
  const m = c0.modes[0];
  const dz = Math.max(...m.shape.re.map((r, k) => Math.hypot(r[2], m.shape.im[k][2])));
  const dxy = Math.max(...m.shape.re.map((r, k) => Math.hypot(r[0], r[1], m.shape.im[k][0], m.shape.im[k][1])));
  ok(m.shape.re[0].length === 6 && dz > 10 * dxy, 'flapping-blade: the first mode at rest is a flap mode (API shape)',
    `max |dz| ${dz}, max |dx, dy| ${dxy}`);
  await page.selectOption('#mode-speed', String(ci));
  await page.selectOption('#mode-index', '0');
  ok(await waitFor(page, () => /^mode 1 at Ω = 0 rad\/s/.test(document.getElementById('mode-desc').textContent), null,
    'mode 1 at rest'), 'flapping-blade: mode 1 at 0 rad/s selected', await page.textContent('#mode-desc'));
  // frames of the animation as drawn, until the tip has been well out of the plane and has
  // travelled on the screen (a cycle takes 2 s; the budget allows for a slow machine)
  const seen = [];
  const deadline = Date.now() + budgetMs(20000);
  const base = c0.equilibrium.nodes;
  let out = 0;
  const tipY = [];
  const travel = () => (tipY.length ? Math.max(...tipY) - Math.min(...tipY) : 0);
  while (Date.now() < deadline) {
    const a = await page.evaluate(() => window.__spinmodal.anim());
    if (a.drawn) {
      seen.push(a);
      out = Math.max(out, ...a.drawn.world.map((p, k) => Math.abs(p[2] - base[k][2]) / a.drawn.amp));
      tipY.push(a.drawn.screen[a.drawn.screen.length - 1][1]);
      if (out > 0.5 * dz && travel() > 20) break;
    }
    await sleep(50);
  }
  const last = seen[seen.length - 1];
  ok(last && out > 0.5 * dz, 'flapping-blade: the animated flap mode moves nodes out of the hub plane',
    `max |z - z_steady| / amp = ${out}, shape max |dz| = ${dz}`);
  if (!last) return;
  // the drawn nodes are the result's: base + amp·(re·cos θ − im·sin θ), translations dx, dy, dz
  let err = 0;
  const cs = Math.cos(last.drawn.theta), sn = Math.sin(last.drawn.theta);
  last.drawn.world.forEach((p, k) => {
    for (let j = 0; j < 3; j++) {
      const w = c0.equilibrium.nodes[k][j] + last.drawn.amp * (m.shape.re[k][j] * cs - m.shape.im[k][j] * sn);
      err = Math.max(err, Math.abs(p[j] - w));
    }
  });
  ok(err <= 1e-9 * (1 + last.drawn.amp), 'flapping-blade: drawn node positions are the result\'s shape at the drawn phase',
    `max error ${err} m`);
  // what #mode-path draws is the projection of those nodes (the blade is one chain of 24 elements)
  const pts = pathPoints(last.path);
  const perr = pts.length === last.drawn.screen.length
    ? Math.max(...pts.map((p, k) => Math.hypot(p[0] - last.drawn.screen[k][0], p[1] - last.drawn.screen[k][1]))) : Infinity;
  ok(perr <= 0.01, 'flapping-blade: #mode-path is the projection of the drawn nodes', `${pts.length} points, ${perr} px`);
  // and the motion is visible: the tip moves on the screen (z is up in the home view)
  ok(travel() > 20, 'flapping-blade: the tip moves up and down on the screen',
    `${Math.min(...tipY).toFixed(1)}…${Math.max(...tipY).toFixed(1)} px over ${seen.length} frames`);
  await shot(page, '08-flapping-blade-mode1.png');
}

async function run() {
  fs.rmSync(SHOTS, {recursive: true, force: true}); // this run's screenshots only
  const base = await startDaemon('web');
  console.log(`# spinmodald at ${base}`);

  // static files: the front end at /, the plain page at /api.html
  const root = await fetch(base + '/');
  const html = await root.text();
  ok(root.status === 200 && /text\/html/.test(root.headers.get('content-type')) && html.includes('app.js'),
    'GET / serves the front end', `${root.status} ${root.headers.get('content-type')}`);
  const js = await fetch(base + '/app.js');
  ok(js.status === 200 && /javascript/.test(js.headers.get('content-type')), 'GET /app.js is JavaScript',
    `${js.status} ${js.headers.get('content-type')}`);
  const plain = await fetch(base + '/api.html');
  ok(plain.status === 200 && (await plain.text()).includes('/openapi.json'), 'GET /api.html is the plain API page');

  const browser = await chromium.launch({
    executablePath: CHROMIUM,
    timeout: budgetMs(180000),
    headless: true,
    args: ['--headless', '--no-sandbox', '--disable-background-networking',
           '--disable-dev-shm-usage', '--disable-gpu'],  // small /dev/shm in containers
  });
  const context = await browser.newContext({viewport: {width: 1440, height: 900}, acceptDownloads: true});
  // playwright's own waits (actions, navigation, downloads; 30 s by default) on the same scale
  context.setDefaultTimeout(budgetMs(30000));
  context.setDefaultNavigationTimeout(budgetMs(30000));
  const page = await context.newPage();
  const consoleErrors = [];
  const foreign = [];
  page.on('console', (m) => {
    // the browser logs every HTTP error answer; those are checked in badResponses
    if (m.type() === 'error' && !/^Failed to load resource: the server responded with a status of/.test(m.text())) {
      consoleErrors.push(m.text());
    }
  });
  page.on('pageerror', (e) => consoleErrors.push(String(e)));
  const badResponses = [];
  page.on('response', (r) => {
    // 422 from /v1/validate and /v1/analyses is the API answering an invalid request
    const expected = r.status() === 422 && /\/v1\/(validate|analyses)$/.test(new URL(r.url()).pathname);
    if (r.status() >= 400 && !expected) badResponses.push(`${r.status()} ${r.request().method()} ${r.url()}`);
  });
  page.on('request', (r) => {
    if (!r.url().startsWith(base + '/') && !r.url().startsWith('data:') && !r.url().startsWith('blob:')) {
      foreign.push(r.url());
    }
  });

  try {
    await page.goto(base + '/', {waitUntil: 'load'});
    ok(await waitFor(page, () => window.__spinmodal && document.querySelectorAll('#joints tbody tr').length > 0,
      null, 'the app to start'), 'page loads and the editor fills in');
    ok((await page.title()).includes('spinmodal'), 'page title');

    // accessibility: every control has an accessible name
    const unnamed = await page.evaluate(() => Array.from(document.querySelectorAll('input, select, textarea, button'))
      .filter((e) => !(e.labels && e.labels.length) && !e.getAttribute('aria-label') &&
        !e.getAttribute('aria-labelledby') && !(e.tagName === 'BUTTON' && e.textContent.trim()))
      .map((e) => e.id || e.outerHTML.slice(0, 80)));
    ok(unnamed.length === 0, 'every control has a label', unnamed.join(', '));

    // load the beta = 90 degree example
    await page.selectOption('#example', 'angled-90');
    await page.click('#load-example');
    const jointRows = await page.locator('#joints tbody tr').count();
    const memberRows = await page.locator('#members tbody tr').count();
    ok(jointRows === 3 && memberRows === 2, 'β = 90° example: 3 joints, 2 members', `${jointRows}, ${memberRows}`);
    const text = await page.inputValue('#json');
    ok(/"P": \[5, 5\]/.test(text) && /"clamp": "O"/.test(text), 'JSON view shows the example', text.slice(0, 200));
    const svgLines = await page.locator('#structure-svg line.member').count();
    ok(svgLines === 2, 'drawing shows 2 members', String(svgLines));
    ok(await page.locator('#structure-svg .clamp').count() === 1 && await page.locator('#structure-svg .axis').count() === 1,
      'drawing shows the clamp and the hub axis');
    ok(await page.locator('#structure-svg .frame-x').count() === 48, 'drawing shows 48 frames (per element)',
      String(await page.locator('#structure-svg .frame-x').count()));

    // table -> JSON, JSON -> table
    const px = page.getByLabel('x of joint P (m)');
    await px.fill('5.5');
    ok(/"P": \[5\.5, 5\]/.test(await page.inputValue('#json')), 'a table edit updates the JSON view');
    await px.fill('5');
    const j = (await page.inputValue('#json')).replace('"elements": 24}\n', '"elements": 20}\n');
    await page.fill('#json', j);
    ok(await page.getByLabel('elements of member 2').inputValue() === '20', 'a JSON edit updates the tables');
    await page.fill('#json', j.replace('"elements": 20}', '"elements": 24}'));
    ok(await page.getByLabel('elements of member 2').inputValue() === '24', 'JSON view restored');

    // validation as the user types: the daemon's message next to the field
    const E = page.getByLabel('E (Pa) of section al');
    await E.fill('-5');
    const hasValidate = await waitFor(page, () => window.__spinmodal.validateAvailable() !== null, null,
      'the validation route to answer', 5000) && await page.evaluate(() => window.__spinmodal.validateAvailable());
    console.log(`# POST /v1/validate ${hasValidate ? 'answers' : 'is not available: errors come from the submission'}`);
    if (!hasValidate) await page.click('#submit');
    ok(await waitFor(page, () => {
      const el = document.querySelector('[aria-label="E (Pa) of section al"]');
      const m = document.getElementById(el.getAttribute('aria-describedby'));
      return m && /positive number/.test(m.textContent);
    }, null, 'the error next to E'), 'an invalid edit shows the daemon\'s error next to the field',
    await messageOf(page, E));
    ok(await E.getAttribute('aria-invalid') === 'true', 'the invalid field is marked aria-invalid');
    const errs = await page.evaluate(() => window.__spinmodal.errors());
    ok(errs.some((e) => e.pointer === '/structure/sections/al/E'), 'error pointer is /structure/sections/al/E',
      JSON.stringify(errs));
    await shot(page, '01-invalid-edit.png');
    await E.fill('7e10');
    if (hasValidate) {
      ok(await waitFor(page, () => document.getElementById('validity').textContent === 'valid', null, 'valid'),
        'fixing the value clears the error (validated)');
    }

    // a 0…20 rad/s sweep
    await page.check('input[name="speed-mode"][value="sweep"]');
    await page.fill('#sweep-from', '0');
    await page.fill('#sweep-to', '20');
    await page.fill('#sweep-count', '11');
    const om = await page.evaluate(() => window.__spinmodal.doc.analysis.omega);
    ok(Array.isArray(om) && om.length === 11 && om[0] === 0 && om[10] === 20, 'sweep 0…20 rad/s in the request',
      JSON.stringify(om));
    const seen = new Set();
    const watch = setInterval(async () => {
      try {
        seen.add(await page.textContent('#job-status'));
      } catch { /* page busy */ }
    }, 50);
    await page.click('#submit');
    const done = await waitFor(page, () => ['done', 'failed', 'canceled'].includes(document.body.dataset.jobState),
      null, 'the job to finish', 180000);
    clearInterval(watch);
    const state = await page.evaluate(() => document.body.dataset.jobState);
    ok(done && state === 'done', 'the sweep runs to done', state);
    console.log(`# status texts seen: ${JSON.stringify(Array.from(seen))}`);
    ok(Array.from(seen).some((t) => /\d+ \/ 11 speeds/.test(t || '')), 'progress shown as done / total speeds');
    ok(await waitFor(page, () => window.__spinmodal.campbell() !== null, null, 'the Campbell diagram'),
      'Campbell diagram drawn');
    const job = await page.evaluate(() => window.__spinmodal.job);
    const resultRes = await fetch(`${base}/v1/analyses/${job.id}/result`);
    const result = await resultRes.json();
    const c20 = result.cases.find((c) => c.omega === 20);
    const plotted = await page.evaluate(() => window.__spinmodal.campbell());
    const xi = plotted.x.indexOf(20);
    const m1 = plotted.series.find((s) => s.label === 'mode 1');
    const f20 = m1 && xi >= 0 ? m1.values[xi] : NaN;
    const api20 = c20.modes[0].frequency_rad_s;
    console.log(`# Campbell mode 1 at 20 rad/s: plotted ${f20}, API ${api20}`);
    ok(Math.abs(f20 - api20) <= 1e-12 * Math.abs(api20), 'Campbell first frequency at 20 rad/s equals the API value',
      `${f20} vs ${api20}`);
    ok(api20 > 6.9 && api20 < 7.1, 'first frequency at 20 rad/s is about 7.0 rad/s (README)', String(api20));
    const eo = plotted.series.filter((s) => /^\d+P$/.test(s.label));
    ok(eo.length >= 3 && eo[0].values[xi] === 20 && eo[1].values[xi] === 40, 'engine-order lines 1P, 2P, 3P…',
      eo.map((s) => s.label).join(' '));
    ok(plotted.crossings.length > 0 && plotted.crossings.every((c) => c.omega >= 0 && c.omega <= 20),
      'engine-order crossings marked', JSON.stringify(plotted.crossings.slice(0, 3)));
    const xing = plotted.crossings.find((c) => c.mode === 1 && c.order === 1);
    ok(!xing || Math.abs(xing.freq - xing.omega) < 1e-9, 'a 1× crossing lies on ω = Ω');
    const rows = await page.locator('#freq-table tbody tr').count();
    ok(rows === 11, 'frequency table: one row per speed', String(rows));
    const cell = await page.locator('#freq-table tbody tr').last().locator('td').nth(1).textContent();
    ok(Math.abs(Number(cell) - api20) < 1e-4 * api20, 'frequency table shows ω1 at 20 rad/s', cell);
    ok(await page.locator('#structure-svg #equilibrium-path').count() === 1, 'steady deflected shape overlaid');

    // mode animation
    const a0 = await page.evaluate(() => window.__spinmodal.anim());
    await waitFor(page, (f0) => window.__spinmodal.anim().frame > f0 + 5, a0.frame, 'animation frames');
    const a1 = await page.evaluate(() => window.__spinmodal.anim());
    ok(a1.frame > a0.frame + 5 && a1.path !== a0.path && a1.path.length > 0, 'mode animation runs (frames, path change)',
      `${a0.frame} -> ${a1.frame}`);
    ok(result.cases.find((c) => c.omega === 20).modes[0].shape.im !== undefined, 'complex (gyroscopic) shapes in the result');
    await page.selectOption('#mode-index', '1');
    await waitFor(page, () => document.getElementById('mode-desc').textContent.includes('mode 2'), null, 'mode 2');
    ok((await page.textContent('#mode-desc')).includes('mode 2'), 'mode 2 selected');
    await shot(page, '02-sweep-results.png');
    await page.click('#mode-play');
    const p0 = await page.evaluate(() => window.__spinmodal.anim());
    await sleep(scaledMs(300)); // paused: no frame may come in this time
    const p1 = await page.evaluate(() => window.__spinmodal.anim());
    ok(!p1.running && p1.frame === p0.frame, 'pause stops the animation');
    await page.keyboard.press('Enter'); // the focused Pause/Play button
    await waitFor(page, () => window.__spinmodal.anim().running, null, 'the animation to run again');
    ok((await page.evaluate(() => window.__spinmodal.anim())).running, 'play again from the keyboard');

    // CSV download
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#dl-csv')]);
    const csvPath = await download.path();
    const csv = fs.readFileSync(csvPath, 'utf8');
    const apiCsv = await (await fetch(`${base}/v1/analyses/${job.id}/result?format=csv`)).text();
    ok(csv === apiCsv && csv.startsWith('omega,mode,frequency_rad_s,frequency_hz'), 'CSV download equals the API CSV',
      csv.slice(0, 80));
    ok(csv.trim().split('\n').length === 1 + 11 * 3, 'CSV has one row per speed and mode');
    ok(/\.csv$/.test(download.suggestedFilename()), 'CSV file name', download.suggestedFilename());
    const [dj] = await Promise.all([page.waitForEvent('download'), page.click('#dl-json')]);
    const jdoc = JSON.parse(fs.readFileSync(await dj.path(), 'utf8'));
    ok(jdoc.cases && jdoc.cases.length === 11, 'JSON download is the result document');

    // cancel a long job
    await page.fill('#sweep-count', '1001');
    await page.uncheck('#mode-shapes');
    await page.click('#submit');
    ok(await waitFor(page, () => /^running: [1-9]\d* \/ 1001 speeds/.test(document.getElementById('job-status').textContent),
      null, 'progress of the running job', 60000), 'progress of a running job (done / total, updated while it runs)',
    await page.textContent('#job-status'));
    const prog = await page.evaluate(() => [document.getElementById('progress').value, document.getElementById('progress').max]);
    ok(prog[0] > 0 && prog[1] === 1001, 'progress bar follows the job', JSON.stringify(prog));
    await page.click('#cancel');
    ok(await waitFor(page, () => ['done', 'failed', 'canceled'].includes(document.body.dataset.jobState), null,
      'the job to stop', 60000), 'the long job stops');
    const st2 = await page.evaluate(() => document.body.dataset.jobState);
    ok(st2 === 'canceled', 'cancel: the job is canceled', st2);
    await shot(page, '03-canceled.png');

    // a sweep with speeds without equilibrium (single frame at β = 90°, DESIGN.md §1.3)
    await page.selectOption('#frames', 'single');
    await page.fill('#sweep-count', '11');
    await page.click('#submit');
    ok(await waitFor(page, () => ['done', 'failed', 'canceled'].includes(document.body.dataset.jobState) &&
      window.__spinmodal.result && window.__spinmodal.job.state !== 'running', null, 'the single-frame job', 120000),
    'single-frame sweep finishes');
    const st3 = await page.evaluate(() => [document.body.dataset.jobState, window.__spinmodal.job.error && window.__spinmodal.job.error.type]);
    ok(st3[0] === 'failed' && st3[1] === 'no_equilibrium', 'single frame: job failed with no_equilibrium', JSON.stringify(st3));
    const notes = await page.textContent('#case-notes');
    ok(/20 rad\/s\)?: no_equilibrium/.test(notes), 'speeds without equilibrium are reported', notes.slice(0, 200));
    ok((notes.match(/no_equilibrium/g) || []).length === 1, 'one message for the one failure, not one per speed', notes);
    ok(/Warning at \d+ speeds \(Ω = 8…18 rad\/s\): FE node \d+ turns [\d.]+ rad relative to its frame/.test(notes),
      'speeds outside the small-rotation range of a frame carry the warning', notes.slice(0, 400));
    const solvedRows = await page.locator('#freq-table tbody td:text-is("solved")').count();
    ok(solvedRows >= 5 && solvedRows < 11, 'the other speeds are still shown', String(solvedRows));
    await shot(page, '04-no-equilibrium.png');
    await page.selectOption('#frames', 'per_element');
    ok(await page.isVisible('#result-stale'), 'results marked as stale after an edit');

    // examples load and draw
    for (const key of ['angled-0', 'angled-45', 'blade', 'branched']) {
      await page.selectOption('#example', key);
      await page.click('#load-example');
      const n = await page.locator('#structure-svg line.member').count();
      ok(n >= 1, `example ${key} drawn`, String(n));
    }
    ok(await page.evaluate(() => window.__spinmodal.view().structure) === 'plane', 'a planar example is drawn in the hub plane');
    await shot(page, '05-branched.png');
    await page.check('#view-3d');
    ok(await page.evaluate(() => window.__spinmodal.view().structure) === '3d' &&
      await page.locator('#structure-svg line.member').count() === 3, 'the 3D switch draws a planar structure in 3D');
    await page.uncheck('#view-3d');
    ok(await page.evaluate(() => window.__spinmodal.view().structure) === 'plane', 'and back in the hub plane');
    // the spatial switch: exact conversions only (EA = E·A, EI_edge = E·I), and back
    await page.check('#spatial');
    let trunk = (await page.evaluate(() => window.__spinmodal.doc)).structure.sections.trunk;
    ok(trunk.EA === 4.2e7 && trunk.EI_edge === 28000 && trunk.mass_per_length === 1.8 && !('E' in trunk) &&
      !('EI_flap' in trunk) && await page.getByLabel('GJ (N·m²) of section trunk').inputValue() === '' &&
      await page.locator('#joints thead th', {hasText: 'z (m)'}).count() === 1 &&
      await page.evaluate(() => window.__spinmodal.view().structure) === '3d',
    'the spatial switch: EA = E·A, EI_edge = E·I, EI_flap and GJ left to fill in, z column, 3D view',
    JSON.stringify(trunk));
    await page.uncheck('#spatial');
    trunk = (await page.evaluate(() => window.__spinmodal.doc)).structure.sections.trunk;
    ok(JSON.stringify(trunk) === JSON.stringify({E: 7e10, A: 6e-4, I: 4e-7, mass_per_length: 1.8}) &&
      await page.evaluate(() => window.__spinmodal.view().structure) === 'plane',
    'and back: the planar section as it was, the hub-plane view', JSON.stringify(trunk));

    await spatial(page, base);

    // without POST /v1/validate (an older daemon: 404), errors come from the submission
    const page2 = await context.newPage();
    await page2.route('**/v1/validate', (route) => route.fulfill({status: 404,
      contentType: 'application/problem+json', body: '{"type":"about:blank","title":"Not Found","status":404}'}));
    await page2.goto(base + '/', {waitUntil: 'load'});
    await waitFor(page2, () => window.__spinmodal && window.__spinmodal.validateAvailable() === false, null,
      'the 404 of /v1/validate');
    const mass = page2.getByLabel('mass per length (kg/m) of section al');
    await mass.fill('heavy');
    await sleep(scaledMs(400)); // no message may appear in this time
    ok(await messageOf(page2, mass) === '', 'no validation while typing without /v1/validate');
    await page2.click('#submit');
    ok(await waitFor(page2, () => {
      const el = document.querySelector('[aria-label="mass per length (kg/m) of section al"]');
      return /must be a number/.test(document.getElementById(el.getAttribute('aria-describedby')).textContent);
    }, null, 'the 422 of the submission'), 'fallback: the submission\'s 422 error shows next to the field',
    await messageOf(page2, mass));
    ok(/not submitted/.test(await page2.textContent('#job-status')), 'fallback: nothing was submitted');
    await shot(page2, '06-fallback-submit-error.png');
    await page2.close();

    // a daemon that wants a bearer token for writes (--token-file)
    fs.writeFileSync(path.join(tmp, 'token'), 'web-test-secret\n');
    const base3 = await startDaemon('auth', ['--token-file', path.join(tmp, 'token')]);
    const page3 = await context.newPage();
    page3.on('pageerror', (e) => consoleErrors.push(String(e)));
    await page3.goto(base3 + '/', {waitUntil: 'load'});
    await waitFor(page3, () => window.__spinmodal && document.getElementById('validity').textContent === 'valid', null,
      'validation without a token');
    ok(await page3.textContent('#validity') === 'valid', 'token: /v1/validate needs no token');
    await page3.fill('#omega', '5');
    await page3.click('#submit');
    ok(await waitFor(page3, () => /bearer token is required/.test(document.getElementById('job-status').textContent),
      null, 'the 401'), 'token: a submission without it asks for the token', await page3.textContent('#job-status'));
    await page3.click('.token summary');
    await page3.fill('#token', 'web-test-secret');
    await page3.press('#token', 'Enter');
    await page3.locator('#token').blur();
    await page3.click('#submit');
    ok(await waitFor(page3, () => document.body.dataset.jobState === 'done', null, 'the job with a token', 60000),
      'token: with the token the job runs', await page3.textContent('#job-status'));
    await page3.close();

    ok(foreign.length === 0, 'no request leaves the daemon', foreign.join(' '));
    ok(badResponses.length === 0, 'no unexpected HTTP error answers', badResponses.join(' | '));
    ok(consoleErrors.length === 0, 'no errors in the browser console', consoleErrors.join(' | '));
  } catch (e) {
    ok(false, 'browser session', e.stack || String(e));
    try {
      await shot(page, 'failure.png');
    } catch { /* page gone */ }
  } finally {
    await browser.close();
  }
}

let code = 0;
try {
  await run();
} catch (e) {
  ok(false, 'test run', e.stack || String(e));
} finally {
  await stopDaemons();
  fs.rmSync(tmp, {recursive: true, force: true});
}
if (failed) {
  console.log('# daemon log (last lines):');
  console.log(daemonLog.split('\n').slice(-30).map((l) => '#   ' + l).join('\n'));
  code = 1;
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(code);
