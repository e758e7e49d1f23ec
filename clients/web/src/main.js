// main.js — the spinmodal front end: structure editor + JSON view kept in
// sync and validated as the user types, analysis options, job submission
// with progress and cancel, results (frequency table, Campbell diagram, mode
// animation, downloads).  Served by spinmodald at / (server/DAEMON.md).
// Planar structures are drawn in the hub plane (drawing.js); spatial ones
// (DESIGN.md 7) in a 3D view the user turns (view3d.js), shared by the
// structure drawing and the mode animation.

import './style.css';
import {DEFAULTS, prettyJSON, structureToRows, rowsToStructure, speedsForm, speedsValue, cellValue,
  fmtNum, parentPtr, sig, isSpatial} from './request.js';
import {buildMesh} from './mesh.js';
import {drawStructure, modeView} from './drawing.js';
import {drawStructure3d, modeView3d, attachOrbit, homeCamera, PRESETS} from './view3d.js';
import {campbellChart} from './campbell.js';
import {StructureEditor} from './editor.js';
import {EXAMPLES} from './examples.js';
import * as api from './api.js';

const $ = (id) => document.getElementById(id);
const TERMINAL = new Set(['done', 'failed', 'canceled']);

const S = {
  doc: {},             // the request as last parsed
  rows: null,          // editable rows of doc.structure
  text: '',            // the JSON text (validated and submitted)
  parseError: null,    // JSON.parse message of the text, if it does not parse
  localErrors: [],     // errors found in the page: [{pointer | el, message}]
  serverErrors: [],    // errors from the daemon: [{pointer, message}]
  serverErrorsFrom: '', // 'validate' | 'submit'
  job: null,           // {id, state, progress, ...} status document of the current job
  pollGen: 0,
  result: null,        // {id, request (doc), result, mesh}
  anim: {frame: 0, running: true, raf: 0, t0: 0, view: null},
  view3d: null,        // the 3D switch: null = automatic (3D for a spatial structure), true, false
  cam: homeCamera(),   // the 3D camera {az, el} (degrees), shared by both drawings
};

// ---------------------------------------------------------------- sync

function setDoc(doc, from) {
  S.doc = doc && typeof doc === 'object' && !Array.isArray(doc) ? doc : {};
  if (from !== 'options') S.sweepError = null;
  S.rows = structureToRows(S.doc.structure);
  if (from !== 'table') editor.render();
  if (from !== 'options') renderOptions();
  if (from !== 'json') setText(prettyJSON(S.doc));
  afterChange();
}

function setText(t) {
  S.text = t;
  S.parseError = null;
  const ta = $('json');
  if (ta.value !== t) ta.value = t;
}

/** Rows or options changed: rebuild the doc and the JSON text. */
function docChanged(from) {
  S.doc.structure = rowsToStructure(S.rows);
  setText(prettyJSON(S.doc));
  if (from === 'rows') editor.render();
  afterChange();
}

function afterChange() {
  computeLocalErrors();
  draw();
  scheduleValidate();
  showErrors();
  markStale();
}

/** Say so when the results shown are for another request than the editor's. */
function markStale() {
  const R = S.result;
  $('result-stale').hidden = !R || JSON.stringify(R.request) === JSON.stringify(S.doc);
}

// -------------------------------------------------------------- editor

const editor = new StructureEditor(document, () => S.rows, (kind) => docChanged(kind));

$('json').addEventListener('input', () => {
  const t = $('json').value;
  S.text = t;
  try {
    const doc = JSON.parse(t);
    S.parseError = null;
    setDoc(doc, 'json');
  } catch (e) {
    S.parseError = e.message;
    computeLocalErrors();
    scheduleValidate();
    showErrors();
  }
});

// ------------------------------------------------------------- options

function an() {
  if (!S.doc.analysis || typeof S.doc.analysis !== 'object' || Array.isArray(S.doc.analysis)) S.doc.analysis = {};
  return S.doc.analysis;
}

function optValue(key) {
  const a = S.doc.analysis && typeof S.doc.analysis === 'object' ? S.doc.analysis : {};
  return key in a ? a[key] : DEFAULTS.analysis[key];
}

let speedMode = 'single';

function renderOptions() {
  const a = S.doc.analysis && typeof S.doc.analysis === 'object' ? S.doc.analysis : {};
  const f = speedsForm(a.omega);
  speedMode = f.mode;
  for (const r of document.querySelectorAll('input[name="speed-mode"]')) r.checked = r.value === f.mode;
  if (f.mode === 'single') $('omega').value = f.value;
  if (f.mode === 'sweep') {
    $('sweep-from').value = f.from;
    $('sweep-to').value = f.to;
    $('sweep-count').value = f.count;
  }
  if (f.mode === 'list') $('omega-list').value = f.list;
  showSpeedMode();

  const fr = 'frames' in S.doc ? S.doc.frames : DEFAULTS.frames;
  let scheme = typeof fr === 'string' ? fr : 'per_element', n = '';
  if (fr && typeof fr === 'object') {
    scheme = 'per_member' in fr ? 'per_member' : 'elements_per_frame';
    n = fmtNum(fr[scheme]);
  }
  $('frames').value = ['per_element', 'single', 'per_member', 'elements_per_frame'].includes(scheme) ? scheme : 'per_element';
  $('frames-n').value = n;
  showFramesN();

  $('basis').value = String(optValue('substructure_modes'));
  $('mass').value = String(optValue('mass'));
  $('modes').value = fmtNum(optValue('modes'));
  const mpf = optValue('modes_per_frame');
  $('modes-per-frame').value = mpf === 'all' ? '' : fmtNum(mpf);
  $('coriolis').checked = optValue('coriolis') === true;
  $('stiffening').checked = optValue('geometric_stiffening') === true;
  $('mode-shapes').checked = optValue('mode_shapes') === true;
}

function showSpeedMode() {
  document.querySelector('.speed-single').hidden = speedMode !== 'single';
  document.querySelector('.speed-sweep').hidden = speedMode !== 'sweep';
  document.querySelector('.speed-list').hidden = speedMode !== 'list';
}

function showFramesN() {
  const s = $('frames').value;
  const n = $('frames-n');
  n.hidden = !(s === 'per_member' || s === 'elements_per_frame');
  n.dataset.pointer = `/frames/${s}`;
  n.setAttribute('aria-label', s === 'per_member' ? 'runs per member (k)' : 'elements per frame (n)');
}

function speedFields() {
  return {mode: speedMode, value: $('omega').value, from: $('sweep-from').value, to: $('sweep-to').value,
    count: $('sweep-count').value, list: $('omega-list').value};
}

function speedsChanged() {
  const v = speedsValue(speedFields());
  S.sweepError = v.error ? {message: v.error, el: $({from: 'sweep-from', to: 'sweep-to', count: 'sweep-count'}[v.field])} : null;
  if (!v.error) an().omega = v.value;
  docChanged('options');
}

for (const r of document.querySelectorAll('input[name="speed-mode"]')) {
  r.addEventListener('change', () => {
    if (!r.checked) return;
    const prev = speedsValue(speedFields());
    speedMode = r.value;
    // carry the speeds over into the new form
    const om = prev.value;
    const nums = Array.isArray(om) ? om.filter((x) => typeof x === 'number') : typeof om === 'number' ? [om] : [];
    if (speedMode === 'single' && nums.length) $('omega').value = fmtNum(nums[nums.length - 1]);
    if (speedMode === 'sweep') {
      const hi = nums.length ? Math.max(...nums) : 20;
      $('sweep-from').value = $('sweep-from').value || '0';
      $('sweep-to').value = $('sweep-to').value || fmtNum(hi > 0 ? hi : 20);
      $('sweep-count').value = $('sweep-count').value || '21';
    }
    if (speedMode === 'list') $('omega-list').value = nums.map(fmtNum).join(', ');
    showSpeedMode();
    speedsChanged();
  });
}
for (const id of ['omega', 'sweep-from', 'sweep-to', 'sweep-count', 'omega-list']) {
  $(id).addEventListener('input', speedsChanged);
}

function framesChanged() {
  showFramesN();
  const s = $('frames').value;
  S.doc.frames = s === 'per_member' || s === 'elements_per_frame' ? {[s]: cellValue($('frames-n').value || '2')} : s;
  if ((s === 'per_member' || s === 'elements_per_frame') && !$('frames-n').value) $('frames-n').value = '2';
  docChanged('options');
}
$('frames').addEventListener('change', framesChanged);
$('frames-n').addEventListener('input', framesChanged);

function bindOpt(id, key, read) {
  const e = $(id);
  e.addEventListener(e.type === 'checkbox' || e.tagName === 'SELECT' ? 'change' : 'input', () => {
    const v = read(e);
    if (v === undefined) delete an()[key];
    else an()[key] = v;
    docChanged('options');
  });
}
bindOpt('basis', 'substructure_modes', (e) => e.value);
bindOpt('mass', 'mass', (e) => e.value);
bindOpt('modes', 'modes', (e) => cellValue(e.value));
bindOpt('modes-per-frame', 'modes_per_frame', (e) => (e.value.trim() === '' || e.value.trim() === 'all' ? 'all' : cellValue(e.value)));
bindOpt('coriolis', 'coriolis', (e) => e.checked);
bindOpt('stiffening', 'geometric_stiffening', (e) => e.checked);
bindOpt('mode-shapes', 'mode_shapes', (e) => e.checked);

// --------------------------------------------------------------- errors

function computeLocalErrors() {
  const out = [];
  const seen = new Map();
  for (const tr of document.querySelectorAll('#joints tbody tr, #sections tbody tr')) {
    const input = tr.querySelector('input.name');
    const kind = tr.closest('table').id === 'joints' ? 'joint' : 'section';
    const key = kind + ':' + input.value;
    if (input.value === '') out.push({el: input, message: `a ${kind} name must not be empty`});
    else if (seen.has(key)) out.push({el: input, message: `duplicate ${kind} name '${input.value}'`});
    seen.set(key, true);
  }
  if (S.sweepError) out.push(S.sweepError);
  if (S.parseError) out.push({pointer: '', message: `not valid JSON: ${S.parseError}`, local: true});
  S.localErrors = out;
}

/** The registered element of a pointer, or of its nearest ancestor. */
function targetOf(pointer) {
  const reg = new Map();
  for (const e of document.querySelectorAll('[data-pointer]')) {
    if (e.hidden || e.closest('[hidden]')) continue;
    const p = e.dataset.pointer;
    const isControl = /^(INPUT|SELECT|TEXTAREA)$/.test(e.tagName);
    if (!reg.has(p) || (isControl && !/^(INPUT|SELECT|TEXTAREA)$/.test(reg.get(p).tagName))) reg.set(p, e);
  }
  let p = pointer;
  while (p !== null) {
    if (reg.has(p)) return reg.get(p);
    p = parentPtr(p);
  }
  return null;
}

function msgSlot(e) {
  if (!e) return $('json-msg');
  if (/^(INPUT|SELECT|TEXTAREA)$/.test(e.tagName)) {
    const id = e.getAttribute('aria-describedby');
    const byId = id && document.getElementById(id.split(' ')[0]);
    if (byId && byId.classList.contains('msg')) return byId;
    return e.closest('td, .field, fieldset')?.querySelector('.msg') || $('json-msg');
  }
  return e.querySelector(':scope > .msg') || e.querySelector('.msg') || $('json-msg');
}

function controlOf(e) {
  if (!e) return $('json');
  if (/^(INPUT|SELECT|TEXTAREA)$/.test(e.tagName)) return e;
  return e.querySelector('input:not([hidden]), select, textarea');
}

function showErrors() {
  for (const m of document.querySelectorAll('.msg')) m.textContent = '';
  for (const c of document.querySelectorAll('[aria-invalid]')) c.removeAttribute('aria-invalid');
  const list = $('errors');
  list.textContent = '';
  // the daemon's JSON syntax error (line, column) replaces the browser's own
  const server = S.serverErrors;
  const daemonSyntax = S.parseError && server.some((e) => e.pointer === '');
  const all = S.localErrors.filter((e) => !(e.local && daemonSyntax)).concat(server);
  for (const err of all) {
    const target = err.el || targetOf(err.pointer);
    const slot = err.pointer === '' && !err.el ? $('json-msg') : msgSlot(target);
    const line = document.createElement('div');
    line.className = 'err';
    line.textContent = err.message;
    slot.append(line);
    const ctl = err.pointer === '' && !err.el ? $('json') : controlOf(target);
    if (ctl) ctl.setAttribute('aria-invalid', 'true');

    const li = document.createElement('li');
    const b = document.createElement('button');
    b.type = 'button';
    b.className = 'linkish';
    b.textContent = err.el ? '(page)' : err.pointer === '' ? '(document)' : err.pointer;
    b.addEventListener('click', () => (ctl || $('json')).focus());
    li.append(b, ' ', err.message);
    list.append(li);
  }
  $('errors-box').hidden = all.length === 0;
  const v = $('validity');
  if (all.length) {
    v.textContent = `${all.length} error${all.length === 1 ? '' : 's'}` +
      (S.serverErrorsFrom === 'submit' && server.length ? ' (from the last submission)' : '');
    v.className = 'validity bad';
  } else if (api.validateAvailable() === true && S.validated === S.text) {
    v.textContent = 'valid';
    v.className = 'validity good';
  } else {
    v.textContent = api.validateAvailable() === false ? 'checked when solved' : '';
    v.className = 'validity';
  }
}

// ----------------------------------------------------------- validation

let vTimer = 0, vAbort = null, vSeq = 0;

function scheduleValidate() {
  clearTimeout(vTimer);
  if (api.validateAvailable() === false) return;
  vTimer = setTimeout(runValidate, 250);
}

async function runValidate() {
  const text = S.text;
  const seq = ++vSeq;
  if (vAbort) vAbort.abort();
  vAbort = new AbortController();
  let r;
  try {
    r = await api.validate(text, vAbort.signal);
  } catch (e) {
    if (e.name !== 'AbortError') console.warn('validate:', e);
    return;
  }
  if (seq !== vSeq) return;
  if (!r.supported) {
    showErrors();
    return;
  }
  S.serverErrors = r.errors;
  S.serverErrorsFrom = 'validate';
  S.validated = r.valid ? text : null;
  showErrors();
}

// --------------------------------------------------------------- drawing

let meshCache = {key: '', mesh: null};

function meshOf(doc) {
  const key = JSON.stringify([doc.structure, doc.frames]);
  if (meshCache.key !== key) meshCache = {key, mesh: buildMesh(doc.structure, 'frames' in doc ? doc.frames : DEFAULTS.frames)};
  return meshCache.mesh;
}

function draw() {
  const st = S.doc.structure && typeof S.doc.structure === 'object' ? S.doc.structure : {};
  const mesh = meshOf(S.doc);
  let equilibrium = null, eqLabel = '';
  const R = S.result;
  if (R && $('show-equilibrium').checked && JSON.stringify(R.request.structure) === JSON.stringify(S.doc.structure)) {
    const c = selectedCase();
    if (c && c.status !== 'no_equilibrium' && c.equilibrium && Array.isArray(c.equilibrium.nodes)) {
      equilibrium = c.equilibrium.nodes;
      eqLabel = `steady shape at Ω = ${sig(c.omega)} rad/s (${c.status})`;
    }
  }
  const in3d = structureIn3d();
  const opts = {frames: $('show-frames').checked, nodes: $('show-nodes').checked, equilibrium, eqLabel};
  const svg = $('structure-svg');
  if (in3d) drawStructure3d(svg, st, mesh, S.cam, opts);
  else drawStructure(svg, st, mesh, opts);
  const n = Object.keys(mesh.joints).length, m = mesh.lines.length;
  $('structure-desc').textContent = (mesh.ok
    ? `${n} joints, ${m} members, ${mesh.elems.length} elements, ${mesh.frames.length} frames` +
      (equilibrium ? `; blue: ${eqLabel}` : '')
    : `${n} joints, ${m} members drawn (${mesh.reason || 'incomplete'})`) +
    (in3d ? '. 3D view, z (the spin axis) up; frames: red e1 along the member, blue e3 the flap normal; ' +
      'dashed grey: shadows on the hub plane. Drag (or arrow keys) to turn, Home or double click to reset.' : '');
  viewControls();
}
for (const id of ['show-frames', 'show-nodes', 'show-equilibrium']) $(id).addEventListener('change', draw);

// ------------------------------------------------------------- 3D view

/** Is the structure drawn in 3D?  The switch, else whether the structure is spatial. */
function structureIn3d() {
  return S.view3d ?? !!(S.rows && S.rows.spatial);
}

/** Is the mode shape drawn in 3D?  The switch, else whether the solved request or its result is spatial. */
function modeIn3d() {
  const R = S.result;
  if (!R) return false;
  return S.view3d ?? (isSpatial(R.request && R.request.structure) || (R.result.model || {}).spatial === true);
}

/** The 3D switch, the view presets and the reset buttons follow the views shown. */
function viewControls() {
  const s3 = structureIn3d(), m3 = modeIn3d();
  $('view-3d').checked = s3;
  $('view-preset').hidden = !s3;
  $('view-reset').hidden = !s3;
  $('mode-view-reset').hidden = !m3;
  const key = Object.keys(PRESETS).find((k) => PRESETS[k].az === S.cam.az && PRESETS[k].el === S.cam.el);
  $('view-preset').value = key || '';
  for (const [svg, on] of [[$('structure-svg'), s3], [$('mode-svg'), m3]]) {
    if (on) svg.setAttribute('tabindex', '0');
    else svg.removeAttribute('tabindex');
  }
}

/** The camera changed: redraw both views (the animation keeps its phase). */
function cameraChanged() {
  draw();
  if (S.result && modeIn3d()) buildModeView();
}
attachOrbit($('structure-svg'), () => S.cam, cameraChanged);
attachOrbit($('mode-svg'), () => S.cam, cameraChanged);
// switching the model between planar and spatial (editor.js) lets the view follow it again
$('spatial').addEventListener('change', () => {
  S.view3d = null;
  draw();
});
$('view-3d').addEventListener('change', () => {
  S.view3d = $('view-3d').checked;
  draw();
  if (S.result) buildModeView();
});
for (const id of ['view-reset', 'mode-view-reset']) {
  $(id).addEventListener('click', () => {
    Object.assign(S.cam, homeCamera());
    cameraChanged();
  });
}
for (const [k, p] of Object.entries(PRESETS)) {
  const o = document.createElement('option');
  o.value = k;
  o.textContent = p.label;
  $('view-preset').append(o);
}
$('view-preset').addEventListener('change', () => {
  const p = PRESETS[$('view-preset').value];
  if (!p) return;
  S.cam.az = p.az;
  S.cam.el = p.el;
  cameraChanged();
});

// --------------------------------------------------------------- examples

for (const ex of EXAMPLES) {
  const o = document.createElement('option');
  o.value = ex.key;
  o.textContent = ex.label;
  o.title = ex.desc;
  $('example').append(o);
}
$('load-example').addEventListener('click', () => loadExample($('example').value));
function exampleDesc() {
  const ex = EXAMPLES.find((e) => e.key === $('example').value);
  $('example-desc').textContent = ex ? ex.desc : '';
}
$('example').addEventListener('change', exampleDesc);

function loadExample(key) {
  const ex = EXAMPLES.find((e) => e.key === key) || EXAMPLES[0];
  $('example').value = ex.key;
  exampleDesc();
  S.view3d = null;
  Object.assign(S.cam, homeCamera());
  S.serverErrors = [];
  S.sweepError = null;
  setDoc(ex.doc(), 'example');
}

// ------------------------------------------------------------------ token

$('token').value = api.getToken();
$('token').addEventListener('change', () => api.setToken($('token').value.trim()));

// ------------------------------------------------------------------- jobs

function setStatus(text, cls = '') {
  const s = $('job-status');
  s.textContent = text;
  s.className = cls;
}

function showJob(doc) {
  S.job = doc;
  const p = doc.progress || {done: 0, total: 0};
  const prog = $('progress');
  prog.max = Math.max(1, p.total || 1);
  prog.value = Math.min(prog.max, p.done || 0);
  prog.setAttribute('aria-valuetext', `${p.done} of ${p.total} speeds`);
  let t = `${doc.state}: ${p.done} / ${p.total} speeds`;
  if (doc.cancel_requested && !TERMINAL.has(doc.state)) t += ' (cancel requested)';
  if (doc.error) t += ` — ${doc.error.title || doc.error.type}${doc.error.detail ? ': ' + doc.error.detail : ''}`;
  setStatus(t, doc.state === 'done' ? 'ok' : doc.state === 'failed' ? 'bad' : '');
  $('cancel').disabled = TERMINAL.has(doc.state);
  $('submit').disabled = !TERMINAL.has(doc.state);
  document.body.dataset.jobState = doc.state;
}

$('analysis-form').addEventListener('submit', (ev) => {
  ev.preventDefault();
  solve();
});

async function solve() {
  const text = S.text;
  let request;
  try {
    request = JSON.parse(text);
  } catch {
    request = null;
  }
  $('submit').disabled = true;
  setStatus('submitting…');
  document.body.dataset.jobState = 'submitting';
  const gen = ++S.pollGen;
  let r;
  try {
    r = await api.submit(text);
  } catch (e) {
    $('submit').disabled = false;
    document.body.dataset.jobState = 'unreachable';
    setStatus(`cannot reach the daemon: ${e.message}`, 'bad');
    return;
  }
  if (!r.doc) {
    $('submit').disabled = false;
    document.body.dataset.jobState = 'rejected';
    S.serverErrors = r.errors;
    S.serverErrorsFrom = 'submit';
    showErrors();
    const what = r.status === 422 ? 'the request is invalid (see the errors)'
      : r.status === 429 ? `the queue is full; retry in ${r.retryAfter || 'a few'} s`
        : r.status === 401 ? 'a bearer token is required (Token, top right)'
          : r.errors.map((e) => e.message).join('; ');
    setStatus(`not submitted: ${what}`, 'bad');
    return;
  }
  S.serverErrors = [];
  showErrors();
  S.submitted = {id: r.doc.id, request};
  showJob(r.doc);
  await poll(r.doc, gen);
}

async function poll(doc, gen) {
  let cur = doc;
  let failures = 0;
  while (!TERMINAL.has(cur.state)) {
    if (gen !== S.pollGen) return;
    let r;
    try {
      r = await api.getStatus(cur.id, 1);
    } catch {
      r = null;
    }
    if (gen !== S.pollGen) return;
    if (!r || !r.doc) {
      if (++failures > 30) {
        setStatus('lost contact with the daemon', 'bad');
        $('submit').disabled = false;
        return;
      }
      await new Promise((res) => setTimeout(res, 1000));
      continue;
    }
    failures = 0;
    cur = r.doc;
    showJob(cur);
  }
  showJob(cur);
  if (cur.error && Array.isArray(cur.error.errors) && cur.error.errors.length) {
    // e.g. a cycle or a disconnected member, found when the model is built
    S.serverErrors = cur.error.errors.map((e) => ({pointer: String(e.pointer ?? ''), message: String(e.message ?? '')}));
    S.serverErrorsFrom = 'submit';
    showErrors();
  }
  if (cur.state === 'done' || cur.result) {
    let result = cur.result;
    if (!result) {
      try {
        result = await api.getResult(cur.id);
      } catch (e) {
        setStatus(`${cur.state}; no result: ${e.message}`, 'bad');
        return;
      }
    }
    if (gen !== S.pollGen) return;
    showResult(cur.id, S.submitted && S.submitted.id === cur.id ? S.submitted.request : S.doc, result);
  }
}

$('cancel').addEventListener('click', async () => {
  if (!S.job) return;
  $('cancel').disabled = true;
  const r = await api.cancel(S.job.id).catch((e) => ({errors: [{message: e.message}]}));
  if (r.doc) showJob(r.doc);
  else setStatus(`cancel failed: ${r.errors.map((e) => e.message).join('; ')}`, 'bad');
});

// ---------------------------------------------------------------- results

const chart = campbellChart($('campbell'));

function selectedCase() {
  const R = S.result;
  if (!R) return null;
  const i = Number($('mode-speed').value);
  return R.result.cases[Number.isInteger(i) ? i : 0] || null;
}

function showResult(id, request, result) {
  const mesh = buildMesh(request && request.structure, request && 'frames' in request ? request.frames : DEFAULTS.frames);
  S.result = {id, request, result, mesh};
  $('results').hidden = false;
  $('dl-json').href = api.resultUrl(id);
  $('dl-json').setAttribute('download', `spinmodal-${id.slice(0, 12)}.json`);
  $('dl-csv').href = api.resultUrl(id, 'csv');
  $('dl-csv').setAttribute('download', `spinmodal-${id.slice(0, 12)}.csv`);

  const md = result.model || {};
  const cases = result.cases || [];
  const bad = cases.filter((c) => c.status !== 'solved');
  $('result-summary').textContent = `${cases.length} speed${cases.length === 1 ? '' : 's'}; model: ${md.nodes} nodes, ` +
    `${md.elements} elements, ${md.frames} frames, ${md.coordinates} coordinates` +
    (result.timing_ms ? `; ${sig((result.timing_ms.equilibrium || 0) + (result.timing_ms.linearize || 0) +
      (result.timing_ms.eigen || 0), 3)} ms` : '') + '.';
  const notes = $('case-notes');
  notes.textContent = '';
  for (const c of bad) {
    const p = document.createElement('p');
    p.className = 'note';
    const d = c.diagnostics || {};
    p.textContent = `Ω = ${sig(c.omega)} rad/s: ${c.status}` + (d.message ? ` — ${d.message}` : '') +
      (typeof d.last_omega === 'number' ? ` (last speed reached ${sig(d.last_omega)} rad/s)` : '');
    notes.append(p);
  }
  // warnings (outside the model's validity): one note for all the speeds that carry one
  const warned = cases.filter((c) => Array.isArray(c.warnings) && c.warnings.length > 0);
  if (warned.length) {
    const om = warned.map((c) => c.omega);
    const p = document.createElement('p');
    p.className = 'note warning';
    p.textContent = `Warning at ${warned.length === 1 ? `Ω = ${sig(om[0])} rad/s` :
      `${warned.length} speeds (Ω = ${sig(Math.min(...om))}…${sig(Math.max(...om))} rad/s)`}: ${warned[0].warnings[0]}`;
    notes.append(p);
  }

  // speed selector: request order, default the highest speed that has modes
  const sel = $('mode-speed');
  sel.textContent = '';
  let best = -1;
  const hasModes = (c) => Array.isArray(c.modes) && c.modes.length > 0;
  cases.forEach((c, i) => {
    const o = document.createElement('option');
    o.value = String(i);
    o.textContent = `${sig(c.omega)} rad/s${c.status === 'solved' ? '' : ' (' + c.status + ')'}`;
    sel.append(o);
    if (hasModes(c) && (best < 0 || c.omega >= cases[best].omega)) best = i;
  });
  if (best < 0) best = 0;
  sel.value = String(best);
  markStale();
  freqTable(result);
  updateChart();
  modeSelectors();
  startMode();
  draw();
}

function freqTable(result) {
  const cases = (result.cases || []).slice().sort((a, b) => a.omega - b.omega);
  const n = cases.reduce((m, c) => Math.max(m, (c.modes || []).length), 0);
  const thead = $('freq-table').tHead, tbody = $('freq-table').tBodies[0];
  thead.textContent = '';
  tbody.textContent = '';
  const hr = thead.insertRow();
  const th = (t, scope = 'col') => {
    const e = document.createElement('th');
    e.scope = scope;
    e.innerHTML = t;
    return e;
  };
  hr.append(th('Ω (rad/s)'), th('status'));
  for (let k = 1; k <= n; k++) hr.append(th(`ω<sub>${k}</sub> (rad/s)`), th(`f<sub>${k}</sub> (Hz)`));
  for (const c of cases) {
    const tr = tbody.insertRow();
    const h = document.createElement('th');
    h.scope = 'row';
    h.textContent = sig(c.omega);
    tr.append(h);
    const st = tr.insertCell();
    st.textContent = c.status;
    if (c.status !== 'solved') st.className = 'bad';
    for (let k = 0; k < n; k++) {
      const m = (c.modes || [])[k];
      tr.insertCell().textContent = m ? sig(m.frequency_rad_s) : '–';
      tr.insertCell().textContent = m ? sig(m.frequency_hz) : '–';
    }
  }
}

function updateChart() {
  if (!S.result) return;
  const orders = Math.max(0, Math.min(20, Math.floor(Number($('eo-count').value) || 0)));
  const d = chart.update({result: S.result.result, orders, unit: $('freq-unit').value});
  const tb = $('crossings').tBodies[0];
  tb.textContent = '';
  for (const c of d.cross) {
    const tr = tb.insertRow();
    for (const v of [`mode ${c.mode}`, `${c.order}×`, sig(c.omega, 5), sig(c.freq, 5), sig(c.freq / (2 * Math.PI), 5)]) {
      tr.insertCell().textContent = v;
    }
  }
  if (!d.cross.length) {
    const td = tb.insertRow().insertCell();
    td.colSpan = 5;
    td.textContent = d.rows.length > 1 ? 'none in the speed range' : 'a sweep is needed';
  }
}
$('eo-count').addEventListener('input', updateChart);
$('freq-unit').addEventListener('change', updateChart);

// ---------------------------------------------------------- mode animation

function modeSelectors() {
  const c = selectedCase();
  const sel = $('mode-index');
  const prev = sel.value;
  sel.textContent = '';
  (c && c.modes ? c.modes : []).forEach((m, k) => {
    const o = document.createElement('option');
    o.value = String(k);
    o.textContent = `${k + 1}: ${sig(m.frequency_rad_s, 5)} rad/s`;
    sel.append(o);
  });
  if (prev && Number(prev) < sel.options.length) sel.value = prev;
}

function startMode() {
  const R = S.result;
  const c = selectedCase();
  const k = Number($('mode-index').value) || 0;
  const m = c && c.modes ? c.modes[k] : null;
  const svg = $('mode-svg');
  const desc = $('mode-desc');
  S.anim.view = null;
  if (!R || !R.mesh.ok || !c) {
    svg.textContent = '';
    desc.textContent = R && !R.mesh.ok ? `cannot draw: ${R.mesh.reason}` : '';
    return;
  }
  buildModeView();
  S.anim.omega = m ? m.frequency_rad_s : 0;
  if (!m) desc.textContent = `no modes at Ω = ${sig(c.omega)} rad/s (${c.status})`;
  else if (!m.shape) desc.textContent = 'no mode shapes in this result (turn "mode shapes" on and solve again)';
  else {
    desc.textContent = `mode ${k + 1} at Ω = ${sig(c.omega)} rad/s: ω = ${sig(m.frequency_rad_s)} rad/s ` +
      `(${sig(m.frequency_hz)} Hz)` + (m.shape.im ? ', complex (gyroscopic): u(t) = Re((re + i·im)·e^{iωt})' : '') +
      '. Grey: undeformed; blue line: steady shape; animated: the mode, one cycle every 2 s' +
      (modeIn3d() ? '; faint: its shadow on the hub plane. Drag to turn the view.' : '.');
  }
  svg.dataset.mode = String(k);
  svg.dataset.case = $('mode-speed').value;
}

/** (Re)build the mode view of the selected case and mode, in the plane or in 3D, at the current phase. */
function buildModeView() {
  const R = S.result;
  const c = selectedCase();
  const svg = $('mode-svg');
  S.anim.view = null;
  if (!R || !R.mesh.ok || !c) return;
  const k = Number($('mode-index').value) || 0;
  const m = c.modes ? c.modes[k] : null;
  const eq = c.equilibrium && Array.isArray(c.equilibrium.nodes) ? c.equilibrium.nodes : null;
  const amp = Number($('mode-amp').value);
  S.anim.view = modeIn3d() ? modeView3d(svg, R.mesh, eq, m && m.shape, amp, S.cam)
    : modeView(svg, R.mesh, eq, m && m.shape, amp);
  if (S.anim.view.ok && typeof S.anim.theta === 'number') S.anim.view.frame(S.anim.theta);
  viewControls();
}

function tick(ts) {
  const A = S.anim;
  A.raf = 0;
  if (!A.running) return;
  if (!A.t0) A.t0 = ts;
  if (A.view && A.view.ok) {
    const theta = (((ts - A.t0) / 2000) % 1) * 2 * Math.PI; // one cycle every 2 s
    A.view.frame(theta);
    A.frame += 1;
    A.theta = theta;
    $('mode-frame').value = String(A.frame);
    $('mode-frame').textContent = String(A.frame);
    $('mode-svg').dataset.frame = String(A.frame);
  }
  A.raf = requestAnimationFrame(tick);
}

function setRunning(on) {
  S.anim.running = on;
  const b = $('mode-play');
  b.textContent = on ? 'Pause' : 'Play';
  b.setAttribute('aria-pressed', on ? 'true' : 'false');
  if (on && !S.anim.raf) S.anim.raf = requestAnimationFrame(tick);
}

$('mode-play').addEventListener('click', () => setRunning(!S.anim.running));
$('mode-speed').addEventListener('change', () => {
  modeSelectors();
  startMode();
  draw();
});
$('mode-index').addEventListener('change', startMode);
$('mode-amp').addEventListener('input', startMode);

// ------------------------------------------------------------------ start

window.__spinmodal = {
  get request() {
    return S.text;
  },
  get doc() {
    return S.doc;
  },
  get job() {
    return S.job;
  },
  get result() {
    return S.result && S.result.result;
  },
  campbell: () => chart.plotted(),
  anim: () => ({frame: S.anim.frame, running: S.anim.running, theta: S.anim.theta,
    path: ($('mode-path') && $('mode-path').getAttribute('d')) || '',
    view: $('mode-svg').dataset.view || '',
    // the 3D view's last frame as drawn: {theta, amp, world: [[x, y, z]…], screen: [[X, Y]…]} per node
    drawn: S.anim.view && S.anim.view.last ? S.anim.view.last() : null}),
  view: () => ({structure: $('structure-svg').dataset.view || '', mode: $('mode-svg').dataset.view || '',
    az: S.cam.az, el: S.cam.el}),
  errors: () => S.localErrors.map((e) => ({pointer: e.pointer ?? null, message: e.message}))
    .concat(S.serverErrors.map((e) => ({...e}))),
  validateAvailable: () => api.validateAvailable(),
  loadExample,
};

const reduce = window.matchMedia && window.matchMedia('(prefers-reduced-motion: reduce)').matches;
loadExample('angled-90');
setRunning(!reduce);
