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
//   SPINMODAL_WEB_ONLY      "towers": run only the tower checks (a quick local run)
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

/** Screenshot of one element (a close look at a chart). */
async function shotEl(page, sel, name) {
  fs.mkdirSync(SHOTS, {recursive: true});
  const file = path.join(SHOTS, name);
  await page.locator(sel).screenshot({path: file});
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

/** The plotted Campbell line holding mode k (sorted index) of case c: the series of its tracked_index. */
function lineSeries(p, c, k = 0) {
  const t = c.modes[k].tracked_index;
  return p.series.find((s) => s.kind === 'mode' && s.line === t);
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
  ok(await waitFor(page, () => /^mode 1( \([^)]*\))? at Ω = 0 rad\/s/.test(document.getElementById('mode-desc').textContent), null,
    'mode 1 at rest'), 'flapping-blade: mode 1 at 0 rad/s selected', await page.textContent('#mode-desc'));
  ok((await page.textContent('#mode-desc')).startsWith(`mode 1 (${m.label}) at`) && m.label === '1st flap',
    'flapping-blade: the mode description names the result\'s label (1st flap)', `${m.label}`);
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

const TWO_PI = 2 * Math.PI;
const BLADES = new URL('../reference/blades/bmodes_certtest/', import.meta.url).pathname;

/** The text of a page-made download (a blob link or a saved blob) after clicking sel. */
async function downloadText(page, sel, encoding = 'utf8') {
  const [d] = await Promise.all([page.waitForEvent('download'), page.click(sel)]);
  const buf = fs.readFileSync(await d.path());
  return {name: d.suggestedFilename(), text: encoding ? buf.toString(encoding) : null, buf};
}

/**
 * Units (issue 13 item 5): rpm / rad/s for speeds and rad/s / Hz / per rev for
 * frequencies on the Campbell axes, the table and the "CSV (units shown)"
 * download, checked against the result of the 0…20 rad/s sweep; engine orders
 * as the user picks them; zoom in y.
 */
async function unitsAndCampbell(page, result) {
  const c20 = result.cases.find((c) => c.omega === 20);
  const rpm20 = 20 * 60 / TWO_PI;
  await page.selectOption('#speed-unit', 'rpm');
  let p = await page.evaluate(() => window.__spinmodal.campbell());
  ok(Math.abs(p.x[p.x.length - 1] - rpm20) <= 1e-9 * rpm20 && /rpm/.test(p.axisLabels[0]),
    'rpm: the Campbell x axis is in rpm (last speed = 20·60/2π)', `${p.x[p.x.length - 1]} vs ${rpm20}; ${p.axisLabels[0]}`);
  const xi = p.x.length - 1;
  const m1 = lineSeries(p, c20);
  ok(Math.abs(m1.values[xi] - c20.modes[0].frequency_rad_s) <= 1e-12 * c20.modes[0].frequency_rad_s,
    'rpm: mode 1 is still plotted in rad/s at that speed', String(m1.values[xi]));
  const eo1 = p.series.find((s) => s.label === '1P');
  ok(Math.abs(eo1.values[xi] - 20) < 1e-9, 'rpm axis with rad/s frequencies: the 1P line is ω = Ω = 20 rad/s at 190.99 rpm',
    String(eo1.values[xi]));
  let head = await page.textContent('#freq-table thead');
  let last = await page.locator('#freq-table tbody tr').last().locator('th').textContent();
  ok(/Ω \(rpm\)/.test(head) && Number(last) === Number(rpm20.toPrecision(6)), 'rpm: the table gives the speed in rpm',
    `${head.slice(0, 40)} | ${last}`);
  await page.selectOption('#freq-unit', 'hz');
  p = await page.evaluate(() => window.__spinmodal.campbell());
  const hz = lineSeries(p, c20).values[xi];
  ok(Math.abs(hz - c20.modes[0].frequency_hz) <= 1e-12 * hz && /Hz/.test(p.axisLabels[1]),
    'Hz: the Campbell y axis is the result\'s frequency_hz', `${hz} vs ${c20.modes[0].frequency_hz}`);
  ok(Math.abs(p.series.find((s) => s.label === '2P').values[xi] - 2 * 20 / TWO_PI) < 1e-9,
    'Hz against rpm: the 2P line is 2·Ω/2π Hz (not 2·Ω)');
  const cell = await page.locator('#freq-table tbody tr').last().locator('td').nth(1).textContent();
  ok(Number(cell) === Number(c20.modes[0].frequency_hz.toPrecision(6)), 'Hz: the table gives f₁ in Hz', cell);
  const cross = await page.locator('#crossings tbody tr').first().locator('td').allTextContents();
  const pc = p.crossings[0];
  ok(Math.abs(Number(cross[2]) - Number((pc.omega * 60 / TWO_PI).toPrecision(5))) < 1e-9 &&
    Math.abs(Number(cross[3]) - Number((pc.freq / TWO_PI).toPrecision(5))) < 1e-9,
  'the crossings table follows the units (rpm, Hz)', JSON.stringify([cross, pc]));
  const csv = await downloadText(page, '#dl-csv-units');
  const lines = csv.text.trim().split('\n');
  const row20 = lines[lines.length - 1].split(',').map(Number);
  ok(lines[0].startsWith('speed (rpm),status,mode 1 (Hz)') && Math.abs(row20[0] - rpm20) <= 1e-12 * rpm20 &&
    row20[2] === c20.modes[0].frequency_hz, 'CSV (units shown): rpm and Hz columns, the values of the result',
  `${lines[0]} | ${lines[lines.length - 1]}`);
  await page.selectOption('#freq-unit', 'rev');
  p = await page.evaluate(() => window.__spinmodal.campbell());
  const pr = lineSeries(p, c20).values[xi];
  ok(Math.abs(pr - c20.modes[0].per_rev) <= 1e-12 && p.series.find((s) => s.label === '3P').values.every((v) => v === 3),
    'per rev: mode 1 is the result\'s per_rev and the 3P line is the constant 3', `${pr} vs ${c20.modes[0].per_rev}`);
  await shot(page, '10-units-rpm-per-rev.png');
  await page.selectOption('#speed-unit', 'rad');
  await page.selectOption('#freq-unit', 'rad');

  // engine orders as picked; each line labelled on the plot
  await page.fill('#eo-list', '1, 3, 5');
  p = await page.evaluate(() => window.__spinmodal.campbell());
  const eo = p.series.filter((s) => /^\d+P$/.test(s.label)).map((s) => s.label);
  ok(JSON.stringify(eo) === '["1P","3P","5P"]' && p.crossings.every((c) => [1, 3, 5].includes(c.order)),
    'engine orders as picked (1, 3, 5): only those lines and crossings', JSON.stringify(eo));
  await page.fill('#eo-list', '1-4');
  // zoom: a drag mostly up-down zooms y only (a low mode need not be squashed against the axis)
  const before = (await page.evaluate(() => window.__spinmodal.campbell())).scales;
  const over = page.locator('#campbell .u-over');
  const b = await over.boundingBox();
  await page.mouse.move(b.x + b.width * 0.5, b.y + b.height * 0.70);
  await page.mouse.down();
  await page.mouse.move(b.x + b.width * 0.51, b.y + b.height * 0.98, {steps: 6});
  await page.mouse.up();
  const after = (await page.evaluate(() => window.__spinmodal.campbell())).scales;
  ok(after.y[1] < 0.5 * before.y[1] && after.y[1] > 0 && Math.abs(after.x[1] - before.x[1]) < 1e-9,
    'zoom in y: a vertical drag narrows the frequency axis, the speed axis stays', JSON.stringify([before, after]));
  await shot(page, '11-campbell-zoom-y.png');
  await page.click('#zoom-reset');
  const reset = (await page.evaluate(() => window.__spinmodal.campbell())).scales;
  ok(Math.abs(reset.y[1] - before.y[1]) < 1e-9, 'Reset zoom shows everything again', JSON.stringify(reset));
  // mode colours told apart from each other and from the crossing markers
  const colours = await page.evaluate(() => {
    const items = Array.from(document.querySelectorAll('#campbell .u-legend .u-series'));
    return items.map((e) => [e.querySelector('.u-label') ? e.querySelector('.u-label').textContent : '',
      getComputedStyle(e.querySelector('.u-marker')).borderColor]);
  });
  const pl = await page.evaluate(() => window.__spinmodal.campbell());
  const names = new Set(pl.series.filter((s) => s.kind === 'mode').map((s) => s.label));
  const modeCols = colours.filter(([l]) => names.has(l)).map(([, c]) => c);
  const markNames = pl.series.filter((s) => ['crossings', 'critical', 'tracking'].includes(s.kind)).map((s) => s.label);
  const markCols = colours.filter(([l]) => markNames.includes(l)).map(([, c]) => c);
  ok(modeCols.length === 3 && new Set(modeCols).size === 3 && markCols.length === 3 &&
    !modeCols.some((c) => markCols.includes(c)),
  'mode colours differ from each other and from the crossing markers', JSON.stringify(colours));
}

/** SVG and PNG of the Campbell diagram and the mode shape; a second design overlaid on the first. */
async function exportsAndCompare(page, result) {
  const svg = await downloadText(page, '#campbell-svg');
  ok(/\.svg$/.test(svg.name) && /^<\?xml/.test(svg.text) && /<svg[^>]+xmlns="http:\/\/www.w3.org\/2000\/svg"/.test(svg.text) &&
    svg.text.includes('1st bending') && svg.text.includes('1P') && (svg.text.match(/<path /g) || []).length >= 3 + 4,
  'Campbell as SVG: vector paths of the modes and engine orders, with the legend', `${svg.name} ${svg.text.length} bytes`);
  const png = await downloadText(page, '#campbell-png', null);
  ok(/\.png$/.test(png.name) && png.buf.subarray(1, 4).toString() === 'PNG' && png.buf.length > 5000,
    'Campbell as PNG', `${png.name} ${png.buf.length} bytes`);
  fs.mkdirSync(SHOTS, {recursive: true});
  fs.writeFileSync(path.join(SHOTS, '18-campbell-export.png'), png.buf); // the exported file, to look at
  const msvg = await downloadText(page, '#mode-svg-dl');
  ok(/<path[^>]*id="mode-path"/.test(msvg.text) && /<style>[^<]*svg \.mode/.test(msvg.text),
    'mode shape as SVG (the drawing with its styles)', msvg.text.slice(0, 200));
  const mpng = await downloadText(page, '#mode-png-dl', null);
  ok(mpng.buf.subarray(1, 4).toString() === 'PNG' && mpng.buf.length > 2000, 'mode shape as PNG', String(mpng.buf.length));
  fs.writeFileSync(path.join(SHOTS, '19-mode-export.png'), mpng.buf);
  const withReq = await downloadText(page, '#dl-json-req');
  const wr = JSON.parse(withReq.text);
  ok(wr.request && wr.request.structure && wr.result && wr.result.cases.length === result.cases.length &&
    JSON.stringify(wr.request.analysis.omega) === JSON.stringify(result.cases.map((c) => c.omega)),
  'JSON + request: the result with the request that produced it');

  // compare: keep this result, change the design (a heavier tip), solve, both on the Campbell diagram
  await page.click('#keep-ref');
  const text = (await page.inputValue('#json')).replace('"mass_per_length": 1.2', '"mass_per_length": 2.4');
  await page.fill('#json', text);
  await page.click('#submit');
  await waitFor(page, () => document.body.dataset.jobState === 'done', null, 'the second design', 180000);
  const r20 = result.cases.find((c) => c.omega === 20);
  ok(await waitFor(page, (t) => (window.__spinmodal.campbell().series || []).some((s) => s.kind === 'ref' && s.line === t),
    r20.modes[0].tracked_index, 'the overlay'), 'compare: the reference result is overlaid');
  const p = await page.evaluate(() => window.__spinmodal.campbell());
  const xi = p.x.indexOf(20);
  const refS = p.series.find((s) => s.kind === 'ref' && s.line === r20.modes[0].tracked_index);
  const ref1 = refS.values[xi];
  const now = await page.evaluate(() => window.__spinmodal.result);
  const cur1 = lineSeries(p, now.cases.find((c) => c.omega === 20)).values[xi];
  const want = r20.modes[0].frequency_rad_s;
  ok(refS.label === `ref ${r20.modes[0].label}`, 'compare: the reference line is named by its label', refS.label);
  ok(ref1 === want && cur1 < want, 'compare: ref mode 1 at 20 rad/s is the first design\'s, the heavier beam\'s is lower',
    `${ref1} vs ${want}; now ${cur1}`);
  // the MAC table against the reference (GET /v1/analyses/{id}/mac, DESIGN.md 9.2): mass per length
  // doubled everywhere keeps every shape, so the diagonal is 1
  ok(await waitFor(page, () => !document.getElementById('mac-table').hidden, null, 'the MAC table'),
    'compare: the MAC table against the reference is shown', await page.textContent('#mac-note'));
  const macRows = await page.$$eval('#mac-table tbody tr', (trs) => trs.map((tr) => [...tr.cells].slice(1).map((td) => Number(td.textContent))));
  ok(macRows.length === now.cases[0].modes.length && macRows.every((r, i) => r[i] >= 0.999),
    'compare: one MAC row per mode, the diagonal 1 (same shapes)', JSON.stringify(macRows));
  await shot(page, '12-compare-designs.png');
  await page.click('#clear-ref');
  ok(await page.evaluate(() => document.getElementById('mac-table').hidden), 'Stop comparing hides the MAC table');
  ok(!(await page.evaluate(() => window.__spinmodal.campbell())).series.some((s) => /^ref /.test(s.label)),
    'Stop comparing removes the overlay');
  ok(!(await page.evaluate(() => window.__spinmodal.campbell())).series.some((s) => s.kind === 'ref'),
    'Stop comparing: no reference series left');
  await page.fill('#json', text.replace('"mass_per_length": 2.4', '"mass_per_length": 1.2'));
}

/**
 * Towers (issue 25 item 4, DESIGN.md 8.5 and 9.3): BModes' Test03 tower
 * imports into the tower form (not mangled into a "structure" by an edit),
 * the tower panel edits height, top mass and gravity, and the solved tower's
 * modes are named "1st fore-aft"/"1st side-side"; the ElastoDyn coefficients
 * are the daemon's ?format=elastodyn numbers, five per shape summing to 1,
 * and the plotted fit follows the computed shape.
 */
async function towers(page, base) {
  await page.click('#open-blade');
  await page.selectOption('#import-format', 'bmodes');
  if (await page.isChecked('#import-bmodes-mesh')) await page.uncheck('#import-bmodes-mesh');
  await page.setInputFiles('#import-main', {name: 'Test03_tower.bmi', mimeType: 'text/plain',
    buffer: fs.readFileSync(path.join(BLADES, 'Test03_tower.bmi'))});
  await page.setInputFiles('#import-sec', {name: 'tower_sec_props.dat', mimeType: 'text/plain',
    buffer: fs.readFileSync(path.join(BLADES, 'tower_sec_props.dat'))});
  await page.click('#import-go');
  ok(await waitFor(page, () => !document.getElementById('import-dialog').open && window.__spinmodal.doc.tower, null,
    'the imported tower'), 'BModes Test03 (a tower) imports into the editor', await page.textContent('#import-error'));
  let doc = await page.evaluate(() => window.__spinmodal.doc);
  ok(doc.tower && doc.tower.height === 82.39 && !('structure' in doc) && !('blade' in doc) &&
    await page.isVisible('#tower-panel') && !await page.isVisible('#structure-tables') &&
    await page.inputValue('#tower-height') === '82.39' && await page.locator('#tower-stations tbody tr').count() > 0,
  'the tower form: the tower panel with its height and stations, no structure tables',
  JSON.stringify({...doc.tower, stations: undefined}));
  ok(/a tower of 82\.39 m/.test(await page.textContent('#file-msg')), 'the message says a tower was imported',
    await page.textContent('#file-msg'));
  ok(await page.locator('#structure-svg .member, #structure-svg line.member, #structure-svg path.member').count() > 0,
    'the tower is drawn', await page.textContent('#structure-desc'));

  // an edit of the analysis options must keep the tower form (it used to add an empty "structure")
  await page.fill('#modes', '10');
  doc = await page.evaluate(() => window.__spinmodal.doc);
  ok(doc.analysis.modes === 10 && !('structure' in doc) && doc.tower.height === 82.39,
    'an options edit keeps the tower form', JSON.stringify(Object.keys(doc)));
  // the tower fields edit the request
  const tm0 = JSON.stringify(doc.tower.top_mass);
  await page.fill('#tower-height', '90');
  await page.check('#tower-gravity');
  doc = await page.evaluate(() => window.__spinmodal.doc);
  ok(doc.tower.height === 90 && doc.tower.gravity === true && JSON.stringify(doc.tower.top_mass) === tm0 &&
    /"gravity": true/.test(await page.inputValue('#json')), 'the tower fields edit height and gravity',
  JSON.stringify({...doc.tower, stations: undefined}));
  await page.uncheck('#tower-gravity');
  await page.fill('#tower-height', '82.39');
  await page.fill('#tower-top-inertia', '1e6, 2e6, 3e6');
  ok((await page.evaluate(() => window.__spinmodal.doc.tower.top_mass.inertia)).join() === '1000000,2000000,3000000',
    'the top mass inertia field writes [fa, ss, up]');
  await page.fill('#tower-top-inertia', JSON.parse(tm0).inertia ? JSON.parse(tm0).inertia.join(', ') : '');
  doc = await page.evaluate(() => window.__spinmodal.doc);
  ok(!('gravity' in doc.tower) && JSON.stringify(doc.tower.top_mass) === tm0, 'and back', JSON.stringify(doc.tower.top_mass));

  const r = await solveHere(page, base, 'the Test03 tower');
  if (!r) return;
  const labels = await page.$$eval('#freq-table td.mlabel', (ts) => ts.map((t) => t.textContent));
  ok(labels.includes('1st fore-aft') && labels.includes('1st side-side') && labels.includes('2nd fore-aft'),
    'the frequency table names the tower\'s modes fore-aft and side-side', labels.join(' | '));
  ok(await waitFor(page, () => window.__spinmodal.coeffs() && window.__spinmodal.coeffs().points.length > 0, null,
    'the coefficients'), 'the coefficients of the solved tower are shown');
  const cf = await page.evaluate(() => window.__spinmodal.coeffs());
  const rows = await page.$$eval('#coeffs-table tbody tr', (trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent)));
  const names = ['TwFAM1Sh', 'TwFAM2Sh', 'TwSSM1Sh', 'TwSSM2Sh'];
  ok(rows.length === 4 && rows.every((row, i) => row[0] === names[i] && row.length === 8),
    'the table: TwFAM1Sh, TwFAM2Sh, TwSSM1Sh, TwSSM2Sh, mode, five coefficients and their sum', JSON.stringify(rows));
  const sums = rows.map((row) => row.slice(2, 7).map(Number).reduce((a, b) => a + b, 0));
  ok(rows.every((row) => row.slice(2, 7).every((t) => Number.isFinite(Number(t)))) &&
    sums.every((x) => Math.abs(x - 1) < 1e-9) && rows.every((row) => Math.abs(Number(row[7]) - 1) < 1e-9),
  'five numbers per shape, summing to 1', JSON.stringify(sums));
  // the daemon's text, parsed here on its own: the same numbers
  const text = await (await fetch(`${base}/v1/analyses/${r.id}/result?format=elastodyn`)).text();
  const api = {};
  for (const m of text.matchAll(/^\s*(\S+)\s+(TwFAM[12]Sh|TwSSM[12]Sh)\((\d)\)/gm)) (api[m[2]] ||= []).push(Number(m[1]));
  ok(names.every((n, i) => JSON.stringify(api[n]) === JSON.stringify(rows[i].slice(2, 7).map(Number))),
    'they are the daemon\'s ?format=elastodyn coefficients', JSON.stringify(api));
  const fa1 = cf.fits.find((f) => f.name === 'TwFAM1Sh');
  const m1 = r.result.cases[0].modes[fa1.mode - 1];
  ok(fa1 && m1 && /fore-aft/.test(m1.label) && cf.plotted === 'TwFAM1Sh',
    'TwFAM1Sh is a fore-aft mode of the result, plotted first', JSON.stringify({fa1, label: m1 && m1.label}));
  const pts = cf.points;
  ok(pts.length === 49 && pts[0].x === 0 && Math.abs(pts[pts.length - 1].x - 1) < 1e-12 &&
    Math.abs(pts[pts.length - 1].y - 1) < 1e-12 && cf.maxDiff < 0.01,
  'the computed shape (49 nodes, 0 at the base, 1 at the top) and the fit agree within 1 % of the top',
  `${pts.length} points, max difference ${cf.maxDiff}`);
  const drawn = await page.$$eval('#coeffs-svg polyline', (ls) => ls.map((l) => l.dataset.series));
  ok(drawn.includes('fit') && drawn.includes('computed'), 'the plot draws the fit and the computed shape', drawn.join());
  await page.selectOption('#coeffs-fit', 'TwSSM2Sh');
  ok(await waitFor(page, () => window.__spinmodal.coeffs() && window.__spinmodal.coeffs().plotted === 'TwSSM2Sh', null,
    'the second side-side shape'), 'choosing TwSSM2Sh plots it');
  const ss2 = await page.evaluate(() => window.__spinmodal.coeffs());
  ok(ss2.points.length === 49 && ss2.maxDiff < 0.05, 'TwSSM2Sh: fit and computed shape within 5 % of the top',
    String(ss2.maxDiff));
  await shotEl(page, '#coeffs-box', '27-tower-coefficients.png');
  await shot(page, '28-tower.png');
}

/** Solve what the editor holds; the API result of the job, or null. */
async function solveHere(page, base, what, budget = 180000) {
  await page.click('#submit');
  const done = await waitFor(page, () => ['done', 'failed', 'canceled', 'rejected'].includes(document.body.dataset.jobState) &&
    window.__spinmodal.job && window.__spinmodal.job.state === document.body.dataset.jobState && window.__spinmodal.result &&
    document.getElementById('result-stale').hidden, null, what, budget);
  const state = await page.evaluate(() => document.body.dataset.jobState);
  if (!ok(done && state === 'done', `${what}: the job runs to done`, `${state}: ${await page.textContent('#job-status')}`)) return null;
  const id = await page.evaluate(() => window.__spinmodal.job.id);
  return {id, result: await (await fetch(`${base}/v1/analyses/${id}/result`)).json()};
}

const CROSS_BLADE = {blade: {length: 31.623, elements: 24, section: {EA: 1e10, EI_flap: 1e8, EI_edge: 4e8, GJ: 1e8,
  mass_per_length: 100}}, analysis: {omega: {from: 0, to: 12, steps: 12}, modes: 4}};

/**
 * Trust (issue 13, DESIGN.md 9.1 and 9.4) on the page: the straight blade with
 * EI_edge = 4·EI_flap swept 0…12 rad/s, whose first flap and first edge modes
 * cross.  The Campbell lines follow tracked_index through the swap, the
 * crossing flag is a marker, the legend and table carry the labels; "find
 * critical speeds" sends the engine orders and the daemon's critical speeds
 * are tabled (rad/s and rpm), marked and downloadable byte for byte; "error
 * estimate" sends error_estimate and the table's ± are the API's.
 */
async function trust(page, base) {
  await page.fill('#json', JSON.stringify(CROSS_BLADE, null, 2));
  await page.fill('#eo-orders', '1, 2');
  let an = await page.evaluate(() => window.__spinmodal.doc.analysis);
  ok(!('engine_orders' in an) && !('error_estimate' in an) && await page.inputValue('#eo-list') === '1, 2',
    'orders typed without "find critical speeds": no engine_orders key (job ids unchanged); the Campbell orders follow',
    JSON.stringify(an));
  await page.check('#critical');
  an = await page.evaluate(() => window.__spinmodal.doc.analysis);
  ok(JSON.stringify(an.engine_orders) === '[1,2]' && !('error_estimate' in an),
    '"find critical speeds" sends analysis.engine_orders [1, 2], and no error_estimate key', JSON.stringify(an));
  const got = await solveHere(page, base, 'the crossing blade');
  if (!got) return;
  const {id, result} = got;
  const cases = result.cases.slice().sort((a, b) => a.omega - b.omega);
  const at0 = cases[0], at12 = cases[cases.length - 1];
  const edge = at0.modes.find((m) => m.label === '1st edge'), flap = at0.modes.find((m) => m.label === '1st flap');
  ok(edge && flap && at0.modes.indexOf(edge) === 1 && at12.modes[0].tracked_index === edge.tracked_index,
    'API: the 1st edge mode is sorted 2nd at rest and 1st at 12 rad/s (the sorted indices swap)',
    JSON.stringify(cases.map((c) => c.modes.map((m) => m.tracked_index))));
  const p = await page.evaluate(() => window.__spinmodal.campbell());
  const line = p.series.find((s) => s.kind === 'mode' && s.label === '1st edge');
  let worst = 0, n = 0;
  for (const c of cases) {
    const m = c.modes.find((x) => x.tracked_index === line.line);
    const v = line.values[p.x.indexOf(c.omega)];
    worst = Math.max(worst, Math.abs(v - m.frequency_rad_s) / m.frequency_rad_s);
    n++;
  }
  ok(line && line.line === edge.tracked_index && n === 13 && worst === 0,
    'the plotted line "1st edge" holds, at each of the 13 speeds, the frequency of the mode with its tracked_index',
    `line ${line && line.line}, worst relative difference ${worst}`);
  const flaggedAt = cases.filter((c) => c.modes.some((m) => m.tracking_flag === 'crossing'));
  const mk = p.marks.filter((m) => m.kind === 'crossing');
  ok(flaggedAt.length === 1 && flaggedAt[0].omega === 7 && mk.length === 1 && mk[0].at === 7 &&
    JSON.stringify(mk[0].lines) === JSON.stringify([flap.tracked_index, edge.tracked_index].sort()) &&
    mk[0].omega > 6 && mk[0].omega < 7 && JSON.stringify(mk[0].names.slice().sort()) === '["1st edge","1st flap"]',
  'one crossing marker, for the flag at 7 rad/s, where the two lines meet between 6 and 7 rad/s',
  JSON.stringify(mk));
  const legend = await page.$$eval('#campbell .u-legend .u-series .u-label', (ls) => ls.map((l) => l.textContent));
  ok(['1st flap', '1st edge', '2nd flap', '2nd edge'].every((l) => legend.includes(l)), 'the legend names the lines by their labels',
    JSON.stringify(legend));
  // pointing at the crossing marker tells which lines
  const over = page.locator('#campbell .u-over');
  await over.scrollIntoViewIfNeeded();
  const b = await over.boundingBox();
  const px = (x, y) => [b.x + (x - p.scales.x[0]) / (p.scales.x[1] - p.scales.x[0]) * b.width,
    b.y + (1 - (y - p.scales.y[0]) / (p.scales.y[1] - p.scales.y[0])) * b.height];
  await page.mouse.move(...px(mk[0].x, mk[0].y));
  ok(await waitFor(page, () => /^Modes cross: 1st (flap|edge) and 1st (flap|edge)/.test(document.getElementById('campbell').dataset.tip || ''),
    null, 'the crossing tooltip'), 'hovering the crossing marker names the two lines',
  await page.getAttribute('#campbell', 'data-tip'));
  await shot(page, '30-tracked-crossing.png');
  await shotEl(page, 'figure.chart', '30-tracked-crossing-chart.png');
  await page.mouse.move(b.x - 20, b.y - 20);
  const svgX = await downloadText(page, '#campbell-svg');
  ok(['1st flap', '1st edge', 'critical speeds', 'modes cross'].every((t) => svgX.text.includes(t)) &&
    (svgX.text.match(/r="2\.5" fill="#111111"/g) || []).length === 1 + 3,
  'the Campbell SVG names the lines by label and draws the 3 critical speeds and the crossing (legend too)',
  `${svgX.text.length} bytes`);

  // labels in the table
  const labCells = await page.locator('#freq-table tbody tr').first().locator('td.mlabel').allTextContents();
  ok(JSON.stringify(labCells) === JSON.stringify(at0.modes.map((m) => m.label)), 'the frequency table has a label column per mode',
    JSON.stringify(labCells));

  // critical speeds: the daemon's table, in rad/s and rpm, and its CSV byte for byte
  const cs = result.critical_speeds;
  const critRows = async () => page.$$eval('#critical-table tbody tr', (trs) => trs.map((tr) =>
    Array.from(tr.cells).map((td) => td.dataset.value)));
  let rows = await critRows();
  const same = (r, c, sp) => r.length === 5 && Number(r[0]) === c.order && r[1] === c.label && Number(r[2]) === sp &&
    Number(r[3]) === c.frequency_rad_s && r[4] === String(c.refined);
  ok(cs.length === 3 && rows.length === cs.length && cs.every((c, i) => same(rows[i], c, c.omega)),
    `the critical-speed table is the API's critical_speeds (${cs.length} rows: order, label, Ω, ω, refined)`,
    JSON.stringify({rows, cs: cs.map((c) => [c.order, c.label, c.omega, c.refined])}));
  const e1 = cs.find((c) => c.order === 1 && c.label === '1st edge');
  ok(e1 && Math.abs(e1.omega - 7.7420) < 1e-3 && e1.refined, '1P meets the 1st edge near 7.742 rad/s, refined',
    JSON.stringify(e1));
  ok(p.critical.length === cs.length && p.critical.every((c, i) => c.omega === cs[i].omega && c.y === cs[i].frequency_rad_s),
    'the critical speeds are marked on the Campbell diagram', JSON.stringify(p.critical.map((c) => [c.x, c.y])));
  await page.selectOption('#speed-unit', 'rpm');
  await page.selectOption('#freq-unit', 'hz');
  rows = await critRows();
  const rpmOk = cs.every((c, i) => Math.abs(Number(rows[i][2]) - c.omega * 60 / TWO_PI) <= 1e-12 * c.omega * 60 / TWO_PI &&
    Number(rows[i][3]) === c.frequency_hz);
  const head = await page.textContent('#critical-table thead');
  ok(rpmOk && /Ω \(rpm\)/.test(head) && /f \(Hz\)/.test(head), 'in rpm and Hz: Ω·60/2π and the result\'s frequency_hz',
    JSON.stringify(rows));
  await shot(page, '31-critical-speeds-rpm.png');
  await page.selectOption('#speed-unit', 'rad');
  await page.selectOption('#freq-unit', 'rad');
  const csv = await downloadText(page, '#dl-critical');
  const apiCsv = Buffer.from(await (await fetch(`${base}/v1/analyses/${id}/result?format=critical`)).arrayBuffer());
  ok(csv.buf.equals(apiCsv) && apiCsv.length > 0 && csv.name === `spinmodal-${id.slice(0, 12)}-critical.csv` &&
    csv.text.trim().split('\n').length === 1 + cs.length, '"Critical speeds (CSV)" is ?format=critical byte for byte',
  `${csv.name}, ${csv.buf.length} vs ${apiCsv.length} bytes: ${csv.text.split('\n')[0]}`);

  // error estimate: a coarser blade (6 elements) so that the bars are visible
  await page.fill('#json', JSON.stringify({...CROSS_BLADE, blade: {...CROSS_BLADE.blade, elements: 6},
    analysis: {...CROSS_BLADE.analysis, engine_orders: [1, 2]}}, null, 2));
  ok(await page.isChecked('#critical') && !await page.isChecked('#error-estimate'),
    'a request with engine_orders ticks "find critical speeds"');
  await page.check('#error-estimate');
  an = await page.evaluate(() => window.__spinmodal.doc.analysis);
  ok(an.error_estimate === true, '"error estimate (slower)" sends analysis.error_estimate: true', JSON.stringify(an));
  const got2 = await solveHere(page, base, 'the blade with error estimates', 300000);
  if (!got2) return;
  const r2 = got2.result.cases.slice().sort((a, b) => a.omega - b.omega);
  const errCells = async () => page.$$eval('#freq-table tbody tr', (trs) => trs.map((tr) =>
    Array.from(tr.querySelectorAll('td.fq')).map((td) => {
      const pm = td.querySelector('.pm');
      return pm && pm.dataset.err !== undefined ? [Number(pm.dataset.err), pm.textContent] : null;
    })));
  let cells = await errCells();
  let bad = [];
  r2.forEach((c, i) => c.modes.forEach((m, k) => {
    const cell = cells[i][k];
    const want = m.error_estimate;
    if (typeof want !== 'number' ? cell !== null : !cell || cell[0] !== want ||
      cell[1] !== ` ± ${Number(want.toPrecision(2))}`) bad.push([c.omega, k, cell, want]);
  }));
  const nErr = r2.reduce((t, c) => t + c.modes.filter((m) => typeof m.error_estimate === 'number').length, 0);
  ok(nErr === 13 * 4 && bad.length === 0, `the table shows ± error_estimate of all ${nErr} frequencies (rad/s)`,
    JSON.stringify(bad.slice(0, 4)));
  await page.selectOption('#freq-unit', 'hz');
  cells = await errCells();
  bad = [];
  r2.forEach((c, i) => c.modes.forEach((m, k) => {
    const want = m.error_estimate / TWO_PI;
    if (!cells[i][k] || Math.abs(cells[i][k][0] - want) > 1e-12 * want) bad.push([c.omega, k, cells[i][k], want]);
  }));
  ok(bad.length === 0, 'in Hz the ± are error_estimate/2π', JSON.stringify(bad.slice(0, 4)));
  const csvU = (await page.evaluate(() => window.__spinmodal.tableCsv())).split('\n');
  ok(csvU[0].startsWith('speed (rad/s),status,mode 1 (Hz),mode 1 ± (Hz),mode 1 label,'),
    'CSV (units shown): each mode\'s value, ± and label', csvU[0]);
  await page.selectOption('#freq-unit', 'rad');
  const eb = (await page.evaluate(() => window.__spinmodal.campbell())).errbars;
  ok(eb.list.length === 13 * 4 && eb.drawn > 0 && eb.drawn + eb.hidden <= eb.list.length &&
    await page.isVisible('#errbar-note'), 'the Campbell diagram has error bars (drawn where longer than their point)',
  `${eb.list.length} bars, ${eb.drawn} drawn, ${eb.hidden} too small; ${await page.textContent('#errbar-note')}`);
  await shot(page, '32-error-bars.png');
  await shotEl(page, 'figure.chart', '32-error-bars-chart.png');
  await page.uncheck('#error-estimate');
  await page.uncheck('#critical');
  an = await page.evaluate(() => window.__spinmodal.doc.analysis);
  ok(!('error_estimate' in an) && !('engine_orders' in an), 'unticked, both keys are gone from the request', JSON.stringify(an));
}

/** Speeds with warnings or without equilibrium: hollow grey, not in the lines, never used for crossings. */
async function flaggedSpeeds(page) {
  const p = await page.evaluate(() => window.__spinmodal.campbell());
  const res = await page.evaluate(() => window.__spinmodal.result);
  const bad = new Set(res.cases.filter((c) => c.status !== 'solved' || (c.warnings || []).length).map((c) => c.omega));
  const lines = p.series.filter((s) => s.kind === 'mode');
  ok(bad.size > 0 && p.flagged.length > 0 && p.flagged.every((f) => bad.has(f.x)) && lines.length > 0 &&
    lines.every((m) => p.x.every((x, i) => !bad.has(x) || m.values[i] === null || m.values[i] === undefined)),
  'flagged speeds are drawn apart (hollow), not on the mode lines', `${p.flagged.length} flagged points at ${[...bad]}`);
  const sorted = res.cases.map((c) => c.omega).sort((a, b) => a - b);
  const okX = p.crossings.every((c) => {
    const i = sorted.findIndex((o, k) => k + 1 < sorted.length && o <= c.omega && c.omega <= sorted[k + 1]);
    return i >= 0 && !bad.has(sorted[i]) && !bad.has(sorted[i + 1]);
  });
  ok(okX, 'no crossing uses a flagged speed', JSON.stringify(p.crossings.map((c) => c.omega)));
}

/** The L-shaped structure of /tmp/w/rm_sweep.json: a torsion-soft radial arm (GJ = 100 N·m²) carrying a stiff
 *  mast along the spin axis, swept 0…5 rad/s: it diverges (1st torsion) at about 3.223 rad/s. */
const RM_SWEEP = {
  structure: {
    joints: {O: [0.5, 0, 0], C: [3.5, 0, 0], P: [3.5, 0, 2]},
    sections: {
      sq: {EA: 108444000, EI_flap: 14000, EI_edge: 14000, GJ: 10758, mass_per_length: 1.2, flap_inertia: 0.0001549,
        edge_inertia: 0.0001549},
      arm: {EA: 10844400000, EI_flap: 1400000, EI_edge: 1400000, GJ: 100, mass_per_length: 1.2, flap_inertia: 0.0001549,
        edge_inertia: 0.0001549},
      mast: {EA: 10844400000, EI_flap: 1400000, EI_edge: 1400000, GJ: 1075800, mass_per_length: 1.2,
        flap_inertia: 0.0001549, edge_inertia: 0.0001549},
    },
    members: [
      {id: 'm1', from: 'O', to: 'C', section: 'arm', elements: 12},
      {id: 'm2', from: 'C', to: 'P', section: 'mast', elements: 12},
    ],
    clamp: 'O',
  },
  frames: 'per_element',
  analysis: {omega: [0, 2, 3, 4, 5], modes: 2, coriolis: false, mass: 'lumped'},
};
const RM_DIVERGENCE = 3.2230732746; // rad/s, the daemon's refined divergence speed

/** RGBA of the pixels of a PNG (a screenshot or a download), decoded by the page. */
async function pngPixels(page, buf, x, y, w = 1, h = 1) {
  return page.evaluate(async ({b64, x, y, w, h}) => {
    const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
    const bmp = await createImageBitmap(new Blob([bytes], {type: 'image/png'}));
    const cv = document.createElement('canvas');
    cv.width = bmp.width;
    cv.height = bmp.height;
    const ctx = cv.getContext('2d');
    ctx.drawImage(bmp, 0, 0);
    return Array.from(ctx.getImageData(x, y, w, h).data);
  }, {b64: buf.toString('base64'), x, y, w, h});
}

/** Is an RGBA pixel reddish (the divergence band or its line, a grid line over it or not: red well above green and
 *  blue; white, grey and the mode colours are not)? */
const reddish = (px) => px[0] > 120 && px[0] - px[1] > 40 && px[0] - px[2] > 40;

/**
 * Divergence speeds (result.divergence_speeds, present only when the sweep
 * crossed one) on the page: the L-shaped arm swept 0, 2, 3 rad/s (below it)
 * draws nothing new; swept 0…5 rad/s it diverges in 1st torsion at 3.223
 * rad/s: a red band at that speed on the Campbell diagram (its place checked
 * against the axis mapping of the plot area, in rad/s and in rpm) labelled
 * "divergence 1st torsion", the unstable speeds beyond it shaded up to the
 * end of the sweep, a table row (kind, mode, Ω, bracket, refined), a tooltip,
 * and the band in the exported SVG and PNG.
 */
async function divergence(page, base) {
  const drawn = () => page.evaluate(() => ({
    bands: document.querySelectorAll('#campbell .campbell-divergence').length,
    labels: Array.from(document.querySelectorAll('#campbell .campbell-divergence-label')).map((l) => l.textContent),
    shaded: document.querySelectorAll('#campbell .campbell-unstable').length,
    table: !document.getElementById('divergence-table').hidden,
    note: !document.getElementById('divergence-note').hidden,
    plotted: window.__spinmodal.campbell().divergence.length,
    svg: /divergence|unstable/.test(window.__spinmodal.campbellSvg()),
  }));
  // below the divergence speed: the page as before
  await page.fill('#json', JSON.stringify({...RM_SWEEP, analysis: {...RM_SWEEP.analysis, omega: [0, 2, 3]}}, null, 2));
  const below = await solveHere(page, base, 'the L-shaped arm swept below its divergence speed');
  if (!below) return;
  let d0 = await drawn();
  ok(!('divergence_speeds' in below.result) && below.result.cases.every((c) => c.status === 'solved') &&
    d0.bands === 0 && d0.labels.length === 0 && d0.shaded === 0 && !d0.table && !d0.note && d0.plotted === 0 && !d0.svg,
  'a sweep without divergence (no divergence_speeds): no band, label or shading, no divergence table, none in the SVG',
  JSON.stringify(d0));

  // through it
  await page.fill('#json', JSON.stringify(RM_SWEEP, null, 2));
  const got = await solveHere(page, base, 'the L-shaped arm swept through its divergence speed');
  if (!got) return;
  const {result} = got;
  const ds = result.divergence_speeds || [];
  const dv = ds[0] || {};
  ok(ds.length === 1 && dv.kind === 'onset' && dv.mode === '1st torsion' && Math.abs(dv.omega_rad_s - RM_DIVERGENCE) < 1e-6 &&
    JSON.stringify(dv.bracket) === '[3,4]' && dv.refined === true,
  'API: one divergence speed, the onset of 1st torsion at 3.2231 rad/s between 3 and 4 rad/s, refined', JSON.stringify(ds));
  ok(result.cases.filter((c) => c.omega > dv.omega_rad_s).every((c) => c.status === 'unstable' && c.stability &&
    c.stability.stable === false), 'API: the speeds above it are unstable',
  JSON.stringify(result.cases.map((c) => [c.omega, c.status])));
  ok(await waitFor(page, () => document.querySelectorAll('#campbell .campbell-divergence').length === 1, null,
    'the divergence band'), 'one divergence band on the Campbell diagram');

  /** The band, its label and the shading as laid out, and where the plot's axis mapping puts the speed x. */
  const layout = () => page.evaluate(() => {
    const box = (el) => {
      const r = el.getBoundingClientRect();
      return {x: r.x, y: r.y, width: r.width, height: r.height};
    };
    const q = (sel) => document.querySelector(`#campbell ${sel}`);
    const p = window.__spinmodal.campbell();
    const lab = q('.campbell-divergence-label'), sh = q('.campbell-unstable');
    return {plot: box(q('.u-under')), band: box(q('.campbell-divergence')), x: Number(q('.campbell-divergence').dataset.x),
      label: lab ? {text: lab.textContent, ...box(lab)} : null, shaded: sh ? box(sh) : null,
      bg: getComputedStyle(q('.campbell-divergence')).backgroundColor, scales: p.scales, divergence: p.divergence,
      unstable: p.unstable};
  });
  const pxOf = (L, v) => L.plot.x + (v - L.scales.x[0]) / (L.scales.x[1] - L.scales.x[0]) * L.plot.width;
  let L = await layout();
  let want = pxOf(L, RM_DIVERGENCE), mid = L.band.x + L.band.width / 2;
  ok(Math.abs(mid - want) <= 1.5 && L.band.width >= 4 && L.band.height === L.plot.height && L.x === dv.omega_rad_s &&
    /^rgba\(220, 38, 38, 0\.[1-4]\d*\)$/.test(L.bg),
  'the band (translucent red, the plot\'s height) is centred on the axis mapping of 3.2231 rad/s (within 1.5 px)',
  `band centre ${mid.toFixed(2)} px, axis ${want.toFixed(2)} px, width ${L.band.width}, ${L.bg}`);
  ok(L.label && L.label.text === 'divergence 1st torsion' && Math.abs(L.label.x - (L.band.x + L.band.width)) <= 4,
    'its label "divergence 1st torsion" is beside it', JSON.stringify(L.label));
  const end = pxOf(L, 5);
  ok(L.shaded && Math.abs(L.shaded.x - want) <= 1.5 && Math.abs(L.shaded.x + L.shaded.width - end) <= 1.5 &&
    L.unstable.length === 1 && L.unstable[0].from === dv.omega_rad_s && L.unstable[0].to === 5,
  'the unstable range is shaded from the divergence speed to the end of the sweep (5 rad/s)',
  `${JSON.stringify(L.shaded)}, ${want.toFixed(2)}…${end.toFixed(2)} px`);
  // what is seen: the screenshot's pixels in the band are red, beside it (at the same height) not
  await page.locator('#campbell').scrollIntoViewIfNeeded();
  L = await layout();
  want = pxOf(L, RM_DIVERGENCE);
  const shotBuf = await page.screenshot({clip: {x: Math.round(want) - 30, y: Math.round(L.plot.y + L.plot.height / 2), width: 61,
    height: 1}});
  const row = await pngPixels(page, shotBuf, 0, 0, 61, 1);
  const pix = (i) => row.slice(4 * i, 4 * i + 4);
  ok(reddish(pix(30)) && !reddish(pix(5)), 'on the screen the band is red at its speed (and not 25 px before it)',
    JSON.stringify([pix(30), pix(5)]));

  // the table
  const divRows = async () => page.$$eval('#divergence-table tbody tr', (trs) => trs.map((tr) =>
    Array.from(tr.cells).map((td) => [td.textContent, td.dataset.value])));
  let rows = await divRows();
  ok(await page.isVisible('#divergence-table') && await page.isVisible('#divergence-note') && rows.length === 1 &&
    rows[0][0][1] === 'onset' && rows[0][1][1] === '1st torsion' && Number(rows[0][2][1]) === dv.omega_rad_s &&
    rows[0][2][0] === String(Number(dv.omega_rad_s.toPrecision(6))) && rows[0][3][0] === '3 … 4' && rows[0][4][0] === 'yes',
  'the divergence table lists it: onset, 1st torsion, Ω in rad/s, between 3 … 4 rad/s, refined', JSON.stringify(rows));
  ok(/Ω \(rad\/s\)/.test(await page.textContent('#divergence-table thead')), 'the table\'s speed column is in rad/s');

  // pointing at the band says what it is
  const yTip = L.plot.y + L.plot.height * 0.45;
  await page.mouse.move(want, yTip);
  ok(await waitFor(page, () => /^Divergence speed \(onset\) of 1st torsion at Ω = 3\.2231 rad\/s/.test(
    document.getElementById('campbell').dataset.tip || ''), null, 'the divergence tooltip'),
  'hovering the band names the mode and the speed', await page.getAttribute('#campbell', 'data-tip'));
  await shot(page, '33-divergence.png');
  await shotEl(page, 'figure.chart', '33-divergence-chart.png');
  await page.mouse.move(L.plot.x - 20, L.plot.y - 20);

  // in rpm: the band at the result's rpm, the table in rpm
  await page.selectOption('#speed-unit', 'rpm');
  ok(await waitFor(page, (rpm) => {
    const b = document.querySelector('#campbell .campbell-divergence');
    return b && Number(b.dataset.x) === rpm;
  }, dv.rpm, 'the band in rpm'), 'in rpm the band is at the result\'s rpm');
  L = await layout();
  want = pxOf(L, dv.rpm);
  mid = L.band.x + L.band.width / 2;
  rows = await divRows();
  ok(Math.abs(mid - want) <= 1.5 && Math.abs(dv.rpm - RM_DIVERGENCE * 60 / TWO_PI) < 1e-3 &&
    Math.abs(L.shaded.x + L.shaded.width - pxOf(L, 5 * 60 / TWO_PI)) <= 1.5,
  'in rpm: the band on the axis mapping of 30.778 rpm (within 1.5 px), shaded to 47.75 rpm',
  `band centre ${mid.toFixed(2)} px, axis ${want.toFixed(2)} px`);
  const br = rows[0][3][1].split(',').map(Number);
  ok(Number(rows[0][2][1]) === dv.rpm && Math.abs(br[0] - 3 * 60 / TWO_PI) < 1e-9 && Math.abs(br[1] - 4 * 60 / TWO_PI) < 1e-9 &&
    /Ω \(rpm\)/.test(await page.textContent('#divergence-table thead')),
  'in rpm the table has the result\'s rpm and the bracket ·60/2π', JSON.stringify(rows));
  await page.selectOption('#speed-unit', 'rad');
  await waitFor(page, (om) => {
    const b = document.querySelector('#campbell .campbell-divergence');
    return b && Number(b.dataset.x) === om;
  }, dv.omega_rad_s, 'the band in rad/s');

  // the exported SVG and PNG carry the band
  const svg = (await downloadText(page, '#campbell-svg')).text;
  const clip = /<clipPath id="plot"><rect x="([\d.]+)" y="([\d.]+)" width="([\d.]+)" height="([\d.]+)"/.exec(svg);
  const band = /<rect class="divergence-band" x="([\d.]+)" y="[\d.]+" width="([\d.]+)"/.exec(svg);
  L = await layout();
  let svgWant = NaN, svgMid = NaN;
  if (clip && band) {
    const [cx, , cw] = clip.slice(1).map(Number);
    svgWant = cx + (RM_DIVERGENCE - L.scales.x[0]) / (L.scales.x[1] - L.scales.x[0]) * cw;
    svgMid = Number(band[1]) + Number(band[2]) / 2;
  }
  ok(Math.abs(svgMid - svgWant) <= 1 && />divergence 1st torsion<\/text>/.test(svg) && /class="unstable-range"/.test(svg) &&
    />divergence speed<\/text>/.test(svg),
  'the exported SVG has the band at 3.2231 rad/s on its axis (within 1 px), its label, the shading and a legend row',
    `band centre ${svgMid} vs ${svgWant}`);
  const png = await downloadText(page, '#campbell-png', null);
  let pngOk = false, pngPix = null;
  if (clip) {
    const y = Math.round(2 * (Number(clip[2]) + Number(clip[4]) / 2));
    const x = Math.round(2 * svgWant); // svgToPng draws at twice the SVG's size
    pngPix = [await pngPixels(page, png.buf, x, y), await pngPixels(page, png.buf, x - 40, y)];
    pngOk = reddish(pngPix[0]) && !reddish(pngPix[1]);
  }
  ok(/\.png$/.test(png.name) && pngOk, 'the exported PNG is red at the band (and not beside it)', JSON.stringify(pngPix));

  // back below it: the band goes
  await page.fill('#json', JSON.stringify({...RM_SWEEP, analysis: {...RM_SWEEP.analysis, omega: [0, 2, 3]}}, null, 2));
  if (!await solveHere(page, base, 'the sweep below the divergence speed again')) return;
  d0 = await drawn();
  ok(d0.bands === 0 && d0.labels.length === 0 && d0.shaded === 0 && !d0.table && d0.plotted === 0 && !d0.svg,
    'the next result without divergence speeds: the band, shading and table are gone', JSON.stringify(d0));
}

/**
 * Blades (issue 12): the BModes certification blade Test01 opened with "Open
 * blade file…" (the .bmi and its section file) loads as a blade-form request,
 * is drawn, solves at its 60 rpm; a broken file names file, line and field;
 * a unit slip is a warning next to its field; speeds in rpm and as a range.
 */
async function blades(page, base) {
  // a broken section file: the error names the file, line and field
  await page.click('#open-blade');
  await page.selectOption('#import-format', 'bmodes');
  const bmi = fs.readFileSync(path.join(BLADES, 'Test01_nonunif_blade.bmi'));
  const sec = fs.readFileSync(path.join(BLADES, 'blade_sec_props.dat'), 'utf8');
  const broken = sec.split('\n').map((l, i) => (i === 7 ? l.replace(/^(\s*\S+\s+\S+\s+\S+\s+)\S+/, '$1abc') : l)).join('\n');
  await page.setInputFiles('#import-main', {name: 'Test01_nonunif_blade.bmi', mimeType: 'text/plain', buffer: bmi});
  await page.setInputFiles('#import-sec', {name: 'blade_sec_props.dat', mimeType: 'text/plain', buffer: Buffer.from(broken)});
  await page.click('#import-go');
  ok(await waitFor(page, () => document.getElementById('import-error').textContent !== '', null, 'the import error'),
    'a broken section file is refused');
  const ie = await page.evaluate(() => ({text: document.getElementById('import-error').textContent,
    ...document.getElementById('import-error').dataset}));
  ok(ie.file === 'blade_sec_props.dat' && ie.line === '8' && ie.field === 'mass_den' &&
    /blade_sec_props\.dat, line 8, field mass_den/.test(ie.text) && /not a number/.test(ie.text),
  'the import error names the file, line and field', JSON.stringify(ie));
  await shot(page, '13-import-error.png');

  // the real files
  await page.setInputFiles('#import-sec', {name: 'blade_sec_props.dat', mimeType: 'text/plain', buffer: Buffer.from(sec)});
  await page.click('#import-go');
  ok(await waitFor(page, () => !document.getElementById('import-dialog').open && window.__spinmodal.doc.blade, null,
    'the imported blade'), 'BModes Test01 imports into the editor');
  const doc = await page.evaluate(() => window.__spinmodal.doc);
  ok(doc.blade.length === 33.25 && doc.blade.hub_radius === 1.75 && doc.blade.stations.length === 21 &&
    JSON.stringify(doc.analysis.rpm) === '[60]' && !('structure' in doc),
  'the blade form: length 33.25 m, hub 1.75 m, 21 stations, 60 rpm', JSON.stringify({...doc.blade, stations: undefined}));
  ok(await page.isVisible('#blade-panel') && !await page.isVisible('#joints') &&
    await page.inputValue('#blade-length') === '33.25' && await page.locator('#stations tbody tr').count() === 21,
  'the blade panel shows its fields and the 21 stations (the structure tables are hidden)');
  ok(await page.inputValue('#speed-in-unit') === 'rpm' && await page.inputValue('#omega-list') === '60' &&
    await page.isVisible('#omega-list'),
    'speeds given in rpm are shown in rpm');
  const v = await page.evaluate(() => window.__spinmodal.view());
  const lines = await memberLines(page);
  ok(v.structure === '3d' && lines.length === 1 && Math.hypot(lines[0][2] - lines[0][0], lines[0][3] - lines[0][1]) > 100,
    'the blade is drawn expanded: one member root → tip, in 3D', JSON.stringify(lines));
  const frames = await page.locator('#structure-svg .frame-x').count();
  ok(frames === 48, 'the blade\'s 48 elements carry 48 frames', String(frames));
  await shot(page, '14-bmodes-imported.png');
  // solve: 60 rpm
  await page.click('#submit');
  const done = await waitFor(page, () => ['done', 'failed', 'rejected'].includes(document.body.dataset.jobState) &&
    window.__spinmodal.result && window.__spinmodal.result.model.nodes === 49, null, 'the blade job', 180000);
  const r = await page.evaluate(() => window.__spinmodal.result);
  ok(done && r && r.cases.length === 1 && r.cases[0].rpm === 60 && r.cases[0].modes.length === 20,
    'the imported blade solves at 60 rpm (20 modes)', JSON.stringify(r && r.cases[0] && {rpm: r.cases[0].rpm}));
  if (r) {
    const bm = fs.readFileSync(path.join(BLADES, 'certtest_frequencies.csv'), 'utf8');
    console.log(`# Test01 at 60 rpm: f1..f3 = ${r.cases[0].modes.slice(0, 3).map((m) => m.frequency_hz.toFixed(4)).join(', ')} Hz` +
      ` (BModes: ${bm.split('\n').slice(0, 3).join(' | ').slice(0, 160)})`);
    ok(await page.inputValue('#speed-unit') === 'rpm' &&
      await page.locator('#freq-table tbody tr').first().locator('th').textContent() === '60',
    'a result of a request in rpm is shown in rpm');
    ok(await waitFor(page, () => window.__spinmodal.anim().drawn && window.__spinmodal.anim().drawn.world.length === 49, null,
      'the blade mode'), 'the blade\'s mode shape is animated on the expanded mesh (49 nodes)');
  }
  await shot(page, '15-bmodes-solved.png');
  if (r) await spanwiseShapes(page, base, r);

  // a unit slip: a warning next to the field (not an error), from /v1/validate
  await page.fill('#blade-length', '33.25');
  const json0 = await page.inputValue('#json');
  const gj0 = /"GJ": ([^,}\s]+)/.exec(json0)[1];
  const text = json0.replace(`"GJ": ${gj0}`, '"GJ": 0.5'); // the first station's
  await page.fill('#json', text);
  ok(await waitFor(page, () => window.__spinmodal.warnings().some((w) => w.pointer === '/blade/stations/0/GJ'), null,
    'the unit-slip warning'), 'a unit slip (GJ = 0.5 N·m²) gives an input_warning with its pointer',
  JSON.stringify(await page.evaluate(() => window.__spinmodal.warnings())));
  const slot = await page.evaluate(() => {
    const td = document.querySelector('#stations td[data-pointer="/blade/stations/0/GJ"]');
    return td ? td.querySelector('.msg').textContent : null;
  });
  ok(slot && /⚠/.test(slot) && /GJ/.test(slot) && /valid, \d+ warning/.test(await page.textContent('#validity')),
    'the warning is shown next to the station\'s GJ; the request stays valid', `${slot} | ${await page.textContent('#validity')}`);
  await shot(page, '16-unit-slip-warning.png');

  // speeds: rad/s <-> rpm, and a range {from, to, steps}
  await page.fill('#json', text.replace('"GJ": 0.5', `"GJ": ${gj0}`).replace(/"rpm": \[60\]/, '"rpm": {"from": 0, "to": 600, "steps": 4}'));
  ok(await page.isChecked('input[name="speed-mode"][value="sweep"]') && await page.inputValue('#sweep-to') === '600' &&
    await page.inputValue('#sweep-count') === '5', 'a range in rpm reads as a sweep 0…600 rpm, 5 speeds');
  await page.fill('#sweep-to', '300');
  let an = await page.evaluate(() => window.__spinmodal.doc.analysis);
  ok(JSON.stringify(an.rpm) === '{"from":0,"to":300,"steps":4}', 'editing it keeps the range form', JSON.stringify(an.rpm));
  await page.selectOption('#speed-in-unit', 'rad');
  an = await page.evaluate(() => window.__spinmodal.doc.analysis);
  ok(!('rpm' in an) && an.omega && Math.abs(an.omega.to - 300 * TWO_PI / 60) < 1e-9 && an.omega.steps === 4 &&
    await page.inputValue('#sweep-to') === String(an.omega.to), 'switching the speeds to rad/s converts them (300 rpm = 10π rad/s)',
  JSON.stringify(an.omega));
  await page.selectOption('#speed-in-unit', 'rpm');
  an = await page.evaluate(() => window.__spinmodal.doc.analysis);
  ok(!('omega' in an) && Math.abs(an.rpm.to - 300) < 1e-9, 'and back to rpm', JSON.stringify(an.rpm));
  await bmodesOwnMesh(page, bmi, sec);
}

const SPANWISE_HEADER = 'omega,rpm,mode,frequency_hz,per_rev,member,member_id,s,span_m,flap,flap_slope,edge,edge_slope,twist,axial';

/**
 * Span-wise mode shapes (DESIGN.md 8.3) of the solved Test01 blade: the two
 * downloads are the daemon's ?format=spanwise|bmodes bytes, and the plot under
 * the mode is the CSV's rows of the selected mode.
 */
async function spanwiseShapes(page, base, result) {
  const id = await page.evaluate(() => window.__spinmodal.job.id);
  const sw = await page.evaluate(() => window.__spinmodal.spanwise());
  ok(sw.available && sw.buttons.every((b) => !b.disabled) && Array.isArray(result.model.members) &&
    result.model.members.length === 1, 'a spatial result with shapes (model.members): the span-wise downloads are offered',
  JSON.stringify(sw));
  const csv = await downloadText(page, '#dl-spanwise');
  const api = Buffer.from(await (await fetch(`${base}/v1/analyses/${id}/result?format=spanwise`)).arrayBuffer());
  const lines = csv.text.trim().split('\n');
  ok(lines[0] === SPANWISE_HEADER, 'the span-wise CSV has the header omega,rpm,mode,…,twist,axial', lines[0]);
  ok(csv.buf.equals(api) && api.length > 0, 'the span-wise CSV download is the daemon\'s ?format=spanwise, byte for byte',
    `${csv.buf.length} vs ${api.length} bytes`);
  ok(lines.length === 1 + 20 * 49 && csv.name === `spinmodal-Test01_nonunif_blade-${id.slice(0, 12)}-spanwise.csv`,
    'one row per mode and node (20 × 49), the file named from the design name (the imported file\'s) and the job id',
    `${lines.length} lines, ${csv.name}`);
  const bt = await downloadText(page, '#dl-bmodes');
  const bapi = Buffer.from(await (await fetch(`${base}/v1/analyses/${id}/result?format=bmodes`)).arrayBuffer());
  ok(bt.text.includes('span_loc\tflap disp') && bt.buf.equals(bapi) && bt.name === `spinmodal-Test01_nonunif_blade-${id.slice(0, 12)}-bmodes.txt`,
    'the BModes-style table: "span_loc\\tflap disp" columns, the daemon\'s ?format=bmodes bytes', `${bt.name} ${bt.buf.length} bytes`);
  // the plot under the mode: mode 1's points are the CSV's rows of mode 1 (span fraction s of the one member)
  await page.selectOption('#mode-index', '0');
  ok(await waitFor(page, () => {
    const p = window.__spinmodal.spanwise().plot;
    return p && p.mode === 1 && p.points.length === 49;
  }, null, 'the span-wise plot of mode 1'), 'the span-wise plot shows mode 1 along the blade (49 nodes)');
  const plot = (await page.evaluate(() => window.__spinmodal.spanwise())).plot;
  const rows1 = lines.slice(1).map((l) => l.split(',')).filter((f) => f[2] === '1');
  const tip = rows1[rows1.length - 1].map(Number);
  const pt = plot.points[plot.points.length - 1];
  ok(pt.x === 1 && pt.flap === tip[9] && pt.edge === tip[11] && pt.twist === tip[13] && Math.abs(tip[9]) === 1,
    'the plotted tip of mode 1 is the CSV\'s (flap 1 m: the 1st flap mode scaled to 1 m)',
    JSON.stringify({pt, tip: [tip[9], tip[11], tip[13]]}));
  const drawn = await page.$$eval('#spanwise-svg polyline.sw-line', (ls) => ls.map((l) => [l.dataset.series,
    l.getAttribute('points').split(' ').length]));
  ok(JSON.stringify(drawn) === '[["flap",49],["edge",49],["twist",49]]', 'flap, edge and twist are drawn', JSON.stringify(drawn));
  await page.locator('#results .downloads').scrollIntoViewIfNeeded();
  await shot(page, '20-spanwise-controls.png');
}

/**
 * "BModes' own mesh (reproduce BModes)" in the import dialog: ?bmodes_mesh=8
 * gives BModes' 12 elements as uniform members in the structure form; it is
 * loaded, drawn and solved, and its first frequency is BModes' published one.
 */
async function bmodesOwnMesh(page, bmi, sec) {
  await page.click('#open-blade');
  await page.selectOption('#import-format', 'bmodes');
  ok(await page.isVisible('#import-bmodes-mesh') && await page.isDisabled('#import-bmodes-k') &&
    await page.inputValue('#import-bmodes-k') === '8' && /element midpoints/.test(await page.textContent('#import-bmesh-hint')),
  'the import dialog offers BModes\' own mesh (8 elements per BModes element by default), with its one-line explanation');
  await page.check('#import-bmodes-mesh');
  ok(!await page.isDisabled('#import-bmodes-k'), 'checking it enables the elements field');
  await page.setInputFiles('#import-main', {name: 'Test01_nonunif_blade.bmi', mimeType: 'text/plain', buffer: bmi});
  await page.setInputFiles('#import-sec', {name: 'blade_sec_props.dat', mimeType: 'text/plain', buffer: Buffer.from(sec)});
  await shot(page, '21-import-bmodes-mesh.png');
  await page.selectOption('#import-format', 'csv');
  ok(!await page.isVisible('#import-bmodes-mesh'), 'the option is shown for BModes only');
  await page.selectOption('#import-format', 'bmodes');
  const [req] = await Promise.all([page.waitForRequest((q) => /\/v1\/import\/bmodes/.test(q.url())), page.click('#import-go')]);
  ok(new URL(req.url()).searchParams.get('bmodes_mesh') === '8', 'the import sends ?bmodes_mesh=8', req.url());
  ok(await waitFor(page, () => !document.getElementById('import-dialog').open && window.__spinmodal.doc.structure &&
    (window.__spinmodal.doc.structure.members || []).length === 12, null, 'the BModes-mesh request'),
  'BModes\' own mesh loads as a structure of 12 members');
  const doc = await page.evaluate(() => window.__spinmodal.doc);
  ok(!('blade' in doc) && doc.structure.members.every((m) => m.elements === 8) && doc.structure.clamp === 'root' &&
    await page.locator('#members tbody tr').count() === 12 && await page.locator('#structure-svg line.member').count() === 12,
  'the members table and the drawing show the 12 members (8 elements each)', JSON.stringify(doc.structure.members.map((m) => m.id)));
  ok(/BModes' own mesh/.test(await page.textContent('#file-msg')), 'the file message says BModes\' own mesh',
    await page.textContent('#file-msg'));
  await page.click('#submit');
  const done = await waitFor(page, () => document.body.dataset.jobState === 'done' && window.__spinmodal.result &&
    (window.__spinmodal.result.model.members || []).length === 12, null, 'the BModes-mesh job', 180000);
  const r = await page.evaluate(() => window.__spinmodal.result);
  const f1 = done && r ? r.cases[0].modes[0].frequency_hz : NaN;
  console.log(`# BModes' own mesh, Test01 at 60 rpm: f1 = ${f1} Hz (BModes 1.7517 Hz)`);
  ok(done && r.model.nodes === 97 && Math.abs(f1 - 1.7517) <= 0.01 * 1.7517,
    'solved: its first frequency is within 1 % of BModes\' published 1.7517 Hz (Test01 mode 1)', `${f1} Hz`);
  ok(await waitFor(page, () => {
    const p = window.__spinmodal.spanwise().plot;
    return p && p.points.length === 97 && p.points[96].x === 1;
  }, null, 'the span-wise plot of the 12 members'), 'the span-wise plot runs root → tip across the 12 members (97 nodes)');
  await shot(page, '22-bmodes-mesh-solved.png');
}

/** Do any two of the rects {x, y, w, h} overlap (by more than 0.5 px)? The pairs that do. */
function overlaps(rects) {
  const out = [];
  for (let i = 0; i < rects.length; i++) {
    for (let j = i + 1; j < rects.length; j++) {
      const a = rects[i], b = rects[j];
      if (a.x < b.x + b.w - 0.5 && b.x < a.x + a.w - 0.5 && a.y < b.y + b.h - 0.5 && b.y < a.y + a.h - 0.5) out.push([a, b]);
    }
  }
  return out;
}

/**
 * A blade engineer's first hour (issue 26, the web page): BModes Test01 is
 * imported with a section file under another name (a warning names both), the
 * caption, the structure's words and the design name follow the import, no
 * UI text cites DESIGN; a dense rpm sweep (121 speeds) is shown in rpm and Hz,
 * without beaded markers or pixel rounding, its frequency axis fitted to the
 * modes the engine orders cross (the orders readable), the orders' labels
 * never overlapping (also with 12 orders); the summary gives the job's wall
 * time; the user's unit choice is remembered; the design name is in the past
 * jobs, the listing and the export file names; the twist axis of a mode
 * without twist is small; one speed is a table, not an empty diagram.
 */
async function firstHour(page, base) {
  const bmi = fs.readFileSync(path.join(BLADES, 'Test01_nonunif_blade.bmi'));
  const sec = fs.readFileSync(path.join(BLADES, 'blade_sec_props.dat'));
  await page.selectOption('#example', 'angled-90');
  await page.click('#load-example');
  ok(/aluminium/.test(await page.textContent('#example-desc')), 'the β = 90° example has its caption (aluminium beams)');
  await page.click('#open-blade');
  await page.selectOption('#import-format', 'bmodes');
  if (await page.isChecked('#import-bmodes-mesh')) await page.uncheck('#import-bmodes-mesh');
  await page.setInputFiles('#import-main', {name: 'Test01_nonunif_blade.bmi', mimeType: 'text/plain', buffer: bmi});
  await page.setInputFiles('#import-sec', {name: 'tower_sec_props.dat', mimeType: 'text/plain', buffer: sec});
  await page.click('#import-go');
  ok(await waitFor(page, () => !document.getElementById('import-dialog').open && window.__spinmodal.doc.blade, null,
    'the import'), 'Test01 imports with a section file of another name');
  const mism = await page.locator('#import-warnings li.sec-mismatch').allTextContents();
  ok(mism.length === 1 && mism[0].includes('blade_sec_props.dat') && mism[0].includes('tower_sec_props.dat'),
    'a section file whose name differs from the .bmi\'s sec_props_file is a warning naming both', JSON.stringify(mism));
  const cap = await page.textContent('#example-desc');
  ok(!/aluminium/.test(cap) && /Imported from Test01_nonunif_blade\.bmi/.test(cap) && /33\.25 m/.test(cap),
    'after an import the caption describes the import, not the last example', cap);
  const sdesc = await page.textContent('#structure-desc');
  ok(/\b1 member,/.test(sdesc) && !/\b1 members\b/.test(sdesc), 'one member is "1 member", not "1 members"', sdesc);
  ok(await page.inputValue('#design-name') === 'Test01_nonunif_blade' &&
    (await page.evaluate(() => window.__spinmodal.doc.name)) === 'Test01_nonunif_blade',
  'the import names the design after its file (the request\'s name)', await page.inputValue('#design-name'));
  const design = await page.evaluate(() => {
    const texts = [document.body.innerText];
    for (const e of document.querySelectorAll('[title], [placeholder], [aria-label]')) {
      texts.push(e.getAttribute('title') || '', e.getAttribute('placeholder') || '', e.getAttribute('aria-label') || '');
    }
    for (const e of document.querySelectorAll('[hidden], template, dialog')) texts.push(e.textContent);
    return texts.filter((t) => /DESIGN(\.md)?\s*§|DESIGN\.md/.test(t)).map((t) => t.slice(0, 80));
  });
  ok(design.length === 0, 'no UI text (shown, hidden, titles) cites DESIGN §', JSON.stringify(design));

  // a dense sweep in rpm: 0…60 rpm, 121 speeds, 8 modes, no shapes
  const doc = await page.evaluate(() => window.__spinmodal.doc);
  doc.analysis = {...doc.analysis, rpm: {from: 0, to: 60, steps: 120}, modes: 8, mode_shapes: false};
  await page.fill('#json', JSON.stringify(doc, null, 2));
  await page.fill('#eo-list', '1-4');
  const got = await solveHere(page, base, 'the dense rpm sweep of Test01');
  if (!got) return;
  ok(await page.inputValue('#speed-unit') === 'rpm' && await page.inputValue('#freq-unit') === 'hz',
    'a request in rpm is shown in rpm and Hz by default', `${await page.inputValue('#speed-unit')} ${await page.inputValue('#freq-unit')}`);
  let p = await page.evaluate(() => window.__spinmodal.campbell());
  const modeStyles = p.seriesStyle.filter((s, i) => p.series[i].kind === 'mode');
  const lineStyles = p.seriesStyle.filter((s, i) => ['mode', 'eo'].includes(p.series[i].kind));
  ok(p.x.length >= 121 && !p.markers && modeStyles.length >= 8 && modeStyles.every((s) => !s.points) &&
    lineStyles.every((s) => s.pxAlign === 0),
  'a dense sweep (121 speeds): lines without point markers, not rounded to whole pixels',
  JSON.stringify({n: p.x.length, markers: p.markers, styles: lineStyles.slice(0, 3)}));
  const eoTop = Math.max(...p.series.filter((s) => s.kind === 'eo').flatMap((s) => s.values.filter((v) => typeof v === 'number')));
  const modeMax = Math.max(...p.series.filter((s) => s.kind === 'mode').flatMap((s) => s.values.filter((v) => typeof v === 'number')));
  console.log(`# Test01 0…60 rpm: 4P ends at ${eoTop} Hz, the modes reach ${modeMax} Hz, y axis 0…${p.scales.y[1]} Hz`);
  ok(p.focus && p.focus.on && eoTop / p.scales.y[1] >= 0.45 && eoTop / modeMax < 0.3 && p.crossings.length > 0,
    'modes far above the orders (4P ends below 30 % of them): the y axis is fitted so that the orders fill ≥ 45 % of it',
    JSON.stringify({eoTop, modeMax, y: p.scales.y, focus: p.focus}));
  ok(/higher mode/.test(await page.textContent('#focus-note')) && await page.isVisible('#campbell-all'),
    'a note says modes lie above, with a "Show all modes" button', await page.textContent('#focus-note'));
  let rects = p.labelRects.filter((r) => /^\dP$/.test(r.text));
  ok(rects.length === 4 && overlaps(p.labelRects).length === 0,
    'the engine-order labels 1P…4P are shown and no two labels overlap (their boxes in the page)', JSON.stringify(p.labelRects));
  await shotEl(page, '#campbell', '23-campbell-rpm-dense.png');
  await page.click('#campbell-all');
  const pa = await page.evaluate(() => window.__spinmodal.campbell());
  ok(!pa.focus.on && pa.scales.y[1] >= modeMax, '"Show all modes" shows every mode', JSON.stringify(pa.scales.y));
  await page.click('#campbell-all');
  await page.fill('#eo-list', '1-12');
  p = await page.evaluate(() => window.__spinmodal.campbell());
  rects = p.labelRects.filter((r) => /^\d+P$/.test(r.text));
  ok(rects.length >= 8 && overlaps(p.labelRects).length === 0 &&
    p.labelRects.every((r) => r.x >= -0.5 && r.y >= -0.5),
  'with engine orders 1-12 the labels still never overlap', `${rects.length} labels; overlaps ${JSON.stringify(overlaps(p.labelRects))}`);
  await shotEl(page, '#campbell', '24-campbell-12-orders.png');
  await page.fill('#eo-list', '1-4');

  // the job's wall time, not the solver's own timing
  const st = await (await fetch(`${base}/v1/analyses/${got.id}`)).json();
  const wall = (Date.parse(st.finished_at) - Date.parse(st.started_at)) / 1000;
  const summary = await page.textContent('#result-summary');
  ok(/wall time/.test(summary) && Number(await page.getAttribute('#result-summary', 'data-wall-s')) === wall &&
    summary.includes(`wall time ${wall < 1 ? Number((wall * 1000).toPrecision(3)) + ' ms' : Number(wall.toPrecision(3)) + ' s'}`),
  'the summary gives the job\'s wall time (finished_at − started_at)', `${summary} | ${wall} s`);
  ok(/\b121 speeds\b/.test(summary) && !/\b1 members\b/.test(summary), 'the summary counts in words', summary);

  // the name: in the listing, the past jobs and the file names
  const list = await (await fetch(`${base}/v1/analyses?limit=100`)).json();
  const item = list.items.find((j) => j.id === got.id);
  ok(item && item.name === 'Test01_nonunif_blade', 'the listing carries the request\'s name', JSON.stringify(item && item.name));
  const svg = await downloadText(page, '#campbell-svg');
  ok(svg.name === `spinmodal-Test01_nonunif_blade-${got.id.slice(0, 12)}-campbell.svg` && /class="eo-label"/.test(svg.text),
    'the Campbell SVG is named after the design and the job; it has the order labels', svg.name);
  const boxes = Array.from(svg.text.matchAll(/<rect class="eo-label-box" x="([\d.]+)" y="([\d.]+)" width="([\d.]+)" height="([\d.]+)"/g))
    .map((m) => ({x: +m[1], y: +m[2], w: +m[3], h: +m[4]}));
  ok(boxes.length === 4 && overlaps(boxes).length === 0, 'the exported order labels do not overlap either', JSON.stringify(boxes));

  // the user's unit choice is remembered (rpm requests: per rev from now on)
  await page.selectOption('#freq-unit', 'rev');
  const prefs = await page.evaluate(() => JSON.parse(localStorage.getItem('spinmodal.units') || '{}'));
  ok(prefs.rpm && prefs.rpm.freq === 'rev', 'the unit picked is kept in localStorage', JSON.stringify(prefs));
  await page.reload({waitUntil: 'load'});
  await waitFor(page, () => window.__spinmodal && window.__spinmodal.doc.blade, null, 'the reload');
  ok(/Test01_nonunif_blade/.test(await page.textContent('#example-desc')), 'after a reload the caption names the design',
    await page.textContent('#example-desc'));
  await page.locator('#past-jobs').focus();
  ok(await waitFor(page, (id) => Array.from(document.querySelectorAll('#past-jobs option'))
    .some((o) => o.value === id && o.textContent.startsWith('Test01_nonunif_blade · ')), got.id, 'the named past job'),
  'the past jobs list shows the design name');
  await page.selectOption('#past-jobs', got.id);
  await page.click('#open-job');
  ok(await waitFor(page, (id) => window.__spinmodal.job && window.__spinmodal.job.id === id && window.__spinmodal.result &&
    window.__spinmodal.campbell(), got.id, 'the reopened job'), 'the named job reopens');
  ok(await page.inputValue('#freq-unit') === 'rev' && await page.inputValue('#speed-unit') === 'rpm',
    'after a reload, a result in rpm is shown in the frequency unit the user chose (per rev)');
  ok(/wall time/.test(await page.textContent('#result-summary')), 'a reopened job gives its wall time too');
  await page.selectOption('#freq-unit', 'hz');

  // one speed (Test01 at 60 rpm, 4 modes)
  doc.analysis = {...doc.analysis, rpm: [60], modes: 4};
  await page.fill('#json', JSON.stringify(doc, null, 2));
  const one = await solveHere(page, base, 'Test01 at 60 rpm');
  if (!one) return;
  // one speed: a table of the frequencies, not an empty diagram
  ok(await page.evaluate(() => window.__spinmodal.campbellView()) === 'single' &&
    await page.locator('#campbell table.campbell-single-table tbody tr').count() === 4 &&
    await page.locator('#campbell canvas').count() === 0 && await page.locator('#campbell .campbell-eo-label').count() === 0 &&
    await page.isDisabled('#campbell-svg'),
  'one speed: the frequencies are a table with bars (4 modes), no diagram, no floating labels, no diagram export');
  const f1 = await page.locator('#campbell table.campbell-single-table tbody tr').first().locator('td').nth(1).textContent();
  ok(Number(f1) === Number(one.result.cases[0].modes[0].frequency_hz.toPrecision(6)), 'its first row is f₁ in Hz', f1);
  await shotEl(page, '#campbell', '25-campbell-one-speed.png');

  // the twist axis of a mode without twist (a uniform blade without offsets, its 1st flap mode):
  // scaled to the data with a minimum span, not ±1 rad stretched to 2 rad by the zero line
  await page.fill('#json', JSON.stringify({name: 'uniform blade', blade: {length: 10, elements: 12, section: {EA: 1e10,
    EI_flap: 1e6, EI_edge: 4e6, GJ: 1e6, mass_per_length: 50}}, analysis: {omega: [5], modes: 3, mode_shapes: true}}, null, 2));
  const ub = await solveHere(page, base, 'a uniform blade');
  if (!ub) return;
  await page.selectOption('#mode-index', '0');
  ok(await waitFor(page, () => window.__spinmodal.spanwise().plot && window.__spinmodal.spanwise().plot.mode === 1, null,
    'the span-wise plot'), 'the span-wise plot of mode 1 of the uniform blade');
  const sp = (await page.evaluate(() => window.__spinmodal.spanwise())).plot;
  const tw = sp.points.map((q) => q.twist), tmax = Math.max(...tw.map(Math.abs));
  const span = sp.ranges.twist[1] - sp.ranges.twist[0];
  ok(tmax < 1e-6 && span <= 0.05 && Math.min(...tw) >= sp.ranges.twist[0] && Math.max(...tw) <= sp.ranges.twist[1],
    'a mode without twist: the twist axis spans a few hundredths of a rad at most (not ±1…2 rad)',
    `twist ≤ ${tmax} rad, axis ${JSON.stringify(sp.ranges.twist)}`);
  await shotEl(page, '#spanwise-box', '26-spanwise-no-twist.png');
}

/** A design is never lost: a reload keeps the request, a file saves and opens it, a past job reopens. */
async function keepTheDesign(page, base) {
  await page.selectOption('#example', 'branched');
  await page.click('#load-example');
  await page.getByLabel('x of joint A (m)').fill('3.25');
  const before = await page.inputValue('#json');
  await page.reload({waitUntil: 'load'});
  await waitFor(page, () => window.__spinmodal && document.querySelectorAll('#joints tbody tr').length > 0, null, 'the reload');
  ok(await page.inputValue('#json') === before && await page.getByLabel('x of joint A (m)').inputValue() === '3.25',
    'a reload keeps the request being edited');
  const saved = await downloadText(page, '#save-request');
  ok(saved.text.trim() === before.trim() && /\.json$/.test(saved.name), 'Save request downloads the request', saved.name);
  await page.selectOption('#example', 'angled-45');
  await page.click('#load-example');
  await page.setInputFiles('#open-request', {name: 'mine.json', mimeType: 'application/json', buffer: Buffer.from(saved.text)});
  ok(await waitFor(page, (t) => document.getElementById('json').value.trim() === t.trim(), before, 'the opened file'),
    'Open request… loads a saved request');
  // reopen a past job: its canonical request (GET /v1/analyses/{id}/request) and its result
  const list = await (await fetch(`${base}/v1/analyses?limit=100&state=done`)).json();
  const job = list.items.find((j) => j.progress.total === 11);
  await page.locator('#past-jobs').focus();
  await waitFor(page, (id) => Array.from(document.querySelectorAll('#past-jobs option')).some((o) => o.value === id), job.id,
    'the past jobs list');
  await page.selectOption('#past-jobs', job.id);
  await page.click('#open-job');
  const want = await (await fetch(`${base}/v1/analyses/${job.id}/request`)).json();
  ok(await waitFor(page, (id) => window.__spinmodal.job && window.__spinmodal.job.id === id && window.__spinmodal.result, job.id,
    'the reopened job'), 'Reopen: the past job and its result are shown');
  const doc = await page.evaluate(() => window.__spinmodal.doc);
  ok(JSON.stringify(doc) === JSON.stringify(want) && (await page.locator('#freq-table tbody tr').count()) === 11,
    'Reopen: the editor holds the job\'s canonical request, the table its 11 speeds', JSON.stringify(doc).slice(0, 120));
  ok(!await page.isVisible('#result-stale'), 'Reopen: the result matches the request in the editor');
  await shot(page, '17-reopened-job.png');
  await page.selectOption('#example', 'angled-90');
  await page.click('#load-example');
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
    const expected = r.status() === 422 && /\/v1\/(validate|analyses|import\/\w+)$/.test(new URL(r.url()).pathname);
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
    if (process.env.SPINMODAL_WEB_ONLY === 'towers') { // a quick local run of the tower part alone
      await towers(page, base);
      ok(badResponses.length === 0, 'no unexpected HTTP error answers', badResponses.join(' | '));
      ok(consoleErrors.length === 0, 'no errors in the browser console', consoleErrors.join(' | '));
      return;
    }

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
    const m1 = lineSeries(plotted, c20);
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
    const xing = plotted.crossings.find((c) => c.line === 0 && c.order === 1);
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
    // span-wise shapes: a planar result has none (the daemon answers 409): both downloads disabled, saying why
    const sw0 = await page.evaluate(() => window.__spinmodal.spanwise());
    ok(!sw0.available && sw0.buttons.every((b) => b.disabled && /planar result has no span-wise shapes/.test(b.title)) &&
      await page.isDisabled('#dl-spanwise') && await page.isDisabled('#dl-bmodes') && sw0.plot === null &&
      !await page.isVisible('#spanwise-box'),
    'a planar result: "Span-wise shapes (CSV)" and "BModes-style table" disabled, the tooltip says why',
    JSON.stringify(sw0));
    await unitsAndCampbell(page, result);
    await exportsAndCompare(page, result);

    // cancel a long job
    await page.fill('#sweep-count', '1001');
    await page.uncheck('#mode-shapes');
    await page.click('#submit');
    ok(await waitFor(page, () => /^running: [1-9]\d* \/ 1001 speeds/.test(document.getElementById('job-status').textContent),
      null, 'progress of the running job', 60000), 'progress of a running job (done / total, updated while it runs)',
    await page.textContent('#job-status'));
    const prog = await page.evaluate(() => [document.getElementById('progress').value, document.getElementById('progress').max]);
    ok(prog[0] > 0 && prog[1] === 1001, 'progress bar follows the job', JSON.stringify(prog));
    // DELETE's answer (the job as it was when the cancel was asked: running) held back until the
    // page's poll has seen the job end: the late answer must not take the page back to
    // "running" with Solve disabled (a race CI once lost under AddressSanitizer)
    let heldBack = false;
    const isJob = (url) => /\/v1\/analyses\/[^/]+$/.test(url.pathname);
    const holdDelete = async (route) => {
      if (route.request().method() !== 'DELETE') return route.continue();
      const resp = await route.fetch();
      await waitFor(page, () => ['done', 'failed', 'canceled'].includes(document.body.dataset.jobState), null,
        'the poll to see the job end', 60000);
      heldBack = true;
      return route.fulfill({response: resp});
    };
    await page.route(isJob, holdDelete);
    await page.click('#cancel');
    ok(await waitFor(page, () => ['done', 'failed', 'canceled'].includes(document.body.dataset.jobState), null,
      'the job to stop', 60000), 'the long job stops');
    for (let i = 0; i < 600 && !heldBack; i++) await sleep(scaledMs(100));
    await sleep(scaledMs(500)); // the page takes the held answer
    await page.unroute(isJob, holdDelete);
    const st2 = await page.evaluate(() => document.body.dataset.jobState);
    ok(heldBack && st2 === 'canceled', 'cancel: the job is canceled, and stays so after DELETE answers late', st2);
    ok(!await page.isDisabled('#submit'), 'cancel: Solve is enabled again');
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
    await flaggedSpeeds(page);
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
    await blades(page, base);
    await towers(page, base);
    await firstHour(page, base);
    await keepTheDesign(page, base);
    try {
      await trust(page, base);
      await divergence(page, base);
    } finally { // the next pages open with the stored request: the β = 90° example again
      await page.selectOption('#example', 'angled-90');
      await page.click('#load-example');
    }

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
