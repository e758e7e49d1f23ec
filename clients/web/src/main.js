// main.js — the spinmodal front end: structure editor + JSON view kept in
// sync and validated as the user types, analysis options, job submission
// with progress and cancel, results (frequency table, Campbell diagram, mode
// animation, downloads).  Served by spinmodald at / (server/DAEMON.md).
// Planar structures are drawn in the hub plane (drawing.js); spatial ones
// (DESIGN.md 7) in a 3D view the user turns (view3d.js), shared by the
// structure drawing and the mode animation.

import './style.css';
import {DEFAULTS, prettyJSON, structureToRows, rowsToStructure, speedsForm, speedsValue, cellValue,
  fmtNum, parentPtr, sig, isSpatial, structureOf, speedList, convertSpeed, rangeOf, SPEED_UNITS, FREQ_UNITS,
  ptr} from './request.js';
import {buildMesh} from './mesh.js';
import {drawStructure, modeView} from './drawing.js';
import {drawStructure3d, modeView3d, attachOrbit, homeCamera, PRESETS} from './view3d.js';
import {campbellChart, parseOrders, freqIn, errIn, flaggedCase, campbellData, COLORS, divergenceSpeeds, divergenceSvg}
  from './campbell.js';
import {exportSvg, svgToPng, campbellSvg, saveBlob} from './export.js';
import {StructureEditor} from './editor.js';
import {EXAMPLES} from './examples.js';
import {spanwiseAvailability, parseSpanwise, bladeChain, spanPoints, drawSpanwise} from './spanwise.js';
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
  warnings: [],        // input_warnings of the last validation or result: [{pointer, message}]
  blade: false,        // the request is in the blade form (DESIGN.md 8.1)
  speedKey: 'omega',   // the request gives analysis.omega or analysis.rpm
  speedRange: false,   // the speeds are a range {from, to, steps}
  ref: null,           // a result kept for comparison: {id, result, label}
  job: null,           // {id, state, progress, ...} status document of the current job
  pollGen: 0,
  result: null,        // {id, request (doc), result, mesh}
  anim: {frame: 0, running: true, raf: 0, t0: 0, view: null},
  view3d: null,        // the 3D switch: null = automatic (3D for a spatial structure), true, false
  cam: homeCamera(),   // the 3D camera {az, el} (degrees), shared by both drawings
  allModes: false,     // the Campbell diagram shows every mode, not the range the engine orders cross
};

// ---------------------------------------------------------------- sync

function setDoc(doc, from) {
  S.doc = doc && typeof doc === 'object' && !Array.isArray(doc) ? doc : {};
  if (from !== 'options') S.sweepError = null;
  S.blade = 'blade' in S.doc && !('structure' in S.doc);
  S.rows = structureToRows(S.doc.structure);
  if (from !== 'name') $('design-name').value = typeof S.doc.name === 'string' ? S.doc.name : '';
  if (from !== 'table') editor.render();
  if (from !== 'blade') renderBlade();
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
  if (!S.blade) S.doc.structure = rowsToStructure(S.rows);
  setText(prettyJSON(S.doc));
  if (from === 'rows') editor.render();
  afterChange();
}

function afterChange() {
  persist();
  computeLocalErrors();
  draw();
  scheduleValidate();
  showErrors();
  markStale();
}

/** Say so when the results shown are for another request than the editor's. */
function markStale() {
  const R = S.result;
  // the name is no part of what was solved (nor of the job id)
  const solved = (d) => JSON.stringify(d && typeof d === 'object' ? {...d, name: undefined} : d);
  $('result-stale').hidden = !R || solved(R.request) === solved(S.doc);
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
    persist(); // even half-typed: a reload brings back what was typed
    computeLocalErrors();
    scheduleValidate();
    showErrors();
  }
});

/** "1 member", "2 members". */
function plural(n, word, many = word + 's') {
  return `${n} ${n === 1 ? word : many}`;
}

// the design's name (the request's optional "name": lists and file names, not part of the job id)
$('design-name').addEventListener('input', () => {
  const t = $('design-name').value.trim();
  if (t) S.doc.name = t;
  else delete S.doc.name;
  setText(prettyJSON(S.doc));
  afterChange();
});

/** A name as a part of a file name: letters, digits, - _ . kept, the rest _, at most 60 characters. */
function fileSafe(name) {
  return String(name).normalize('NFKD').replace(/[\u0300-\u036f]/g, '').replace(/[^A-Za-z0-9._-]+/g, '_')
    .replace(/^[._]+|_+$/g, '').slice(0, 60);
}

/** The start of a result's file names: spinmodal-<name>-<id:12> (spinmodal-<id:12> without a name). */
function fileBase(R = S.result) {
  const id = R ? R.id.slice(0, 12) : 'x';
  const n = R && R.request && typeof R.request.name === 'string' ? fileSafe(R.request.name) : '';
  return n ? `spinmodal-${n}-${id}` : `spinmodal-${id}`;
}

// ------------------------------------------------------------- blade form

const STATION_COLS = [
  ['s', 's'], ['mass_per_length', 'μ (kg/m)'], ['EA', 'EA (N)'], ['EI_flap', 'EI<sub>flap</sub> (N·m²)'],
  ['EI_edge', 'EI<sub>edge</sub> (N·m²)'], ['GJ', 'GJ (N·m²)'], ['flap_inertia', 'i<sub>flap</sub> (kg·m)'],
  ['edge_inertia', 'i<sub>edge</sub> (kg·m)'], ['twist_deg', 'twist (°)'], ['inertia_twist_deg', 'inertia twist (°)'],
  ['cg_offset', 'cg offset (m)'], ['shear_center_offset', 'shear centre offset (m)'],
  ['tension_center_offset', 'tension centre offset (m)'],
];

/** Show the blade panel (fields, stations) instead of the structure tables for a request in the blade form. */
function renderBlade() {
  $('blade-panel').hidden = !S.blade;
  $('structure-tables').hidden = S.blade;
  document.querySelector('.spatial-switch').hidden = S.blade;
  if (!S.blade) return;
  const b = S.doc.blade && typeof S.doc.blade === 'object' ? S.doc.blade : {};
  for (const e of document.querySelectorAll('#blade-panel .blade-fields input[data-key]')) {
    e.value = fmtNum(b[e.dataset.key]);
  }
  $('blade-tip-mass').value = b.tip_mass && typeof b.tip_mass === 'object' ? fmtNum(b.tip_mass.mass) : '';
  const st = Array.isArray(b.stations) ? b.stations : [];
  const keys = STATION_COLS.filter(([k]) => st.some((r) => r && typeof r === 'object' && k in r));
  const thead = $('stations').tHead, tbody = $('stations').tBodies[0];
  thead.innerHTML = '<tr>' + keys.map(([, l]) => `<th scope="col">${l}</th>`).join('') + '</tr>';
  tbody.textContent = '';
  st.forEach((r, j) => {
    const tr = tbody.insertRow();
    tr.dataset.pointer = ptr('blade', 'stations', j);
    for (const [k] of keys) {
      const td = tr.insertCell();
      td.dataset.pointer = ptr('blade', 'stations', j, k);
      const v = r && typeof r === 'object' ? r[k] : undefined;
      const t = document.createElement('span');
      t.textContent = Array.isArray(v) ? v.map((x) => sig(x, 5)).join(', ') : typeof v === 'number' ? sig(v, 6) : v === undefined ? '' : String(v);
      const m = document.createElement('div');
      m.className = 'msg';
      td.append(t, m);
    }
  });
  $('stations-count').textContent = st.length ? `(${st.length}, from the root s = 0 to the tip s = 1)`
    : '(none: the section holds along the span)';
}

for (const e of document.querySelectorAll('#blade-panel .blade-fields input[data-key]')) {
  e.addEventListener('input', () => {
    const b = S.doc.blade && typeof S.doc.blade === 'object' ? S.doc.blade : (S.doc.blade = {});
    if (e.value.trim() === '' && e.dataset.key !== 'length') delete b[e.dataset.key];
    else b[e.dataset.key] = cellValue(e.value);
    setText(prettyJSON(S.doc));
    afterChange();
  });
}
$('blade-tip-mass').addEventListener('input', () => {
  const b = S.doc.blade && typeof S.doc.blade === 'object' ? S.doc.blade : (S.doc.blade = {});
  const t = $('blade-tip-mass').value.trim();
  if (t === '') delete b.tip_mass;
  else b.tip_mass = Object.assign(b.tip_mass && typeof b.tip_mass === 'object' ? b.tip_mass : {}, {mass: cellValue(t)});
  setText(prettyJSON(S.doc));
  afterChange();
});

// ------------------------------------------------------------- keep the design

const STORE_KEY = 'spinmodal.request';

/** Keep the editor's text across reloads (localStorage; nothing leaves the browser). */
function persist() {
  try {
    localStorage.setItem(STORE_KEY, S.text);
  } catch {
    /* storage full or disabled: the design lives in the page only */
  }
}

function stored() {
  try {
    return localStorage.getItem(STORE_KEY);
  } catch {
    return null;
  }
}

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
  S.speedKey = 'rpm' in a && !('omega' in a) ? 'rpm' : 'omega';
  const f = speedsForm(a[S.speedKey]);
  S.speedRange = !!f.range;
  const unit = S.speedKey === 'rpm' ? 'rpm' : 'rad/s';
  $('speed-in-unit').value = S.speedKey === 'rpm' ? 'rpm' : 'rad';
  $('speed-legend-unit').textContent = unit;
  document.querySelector('fieldset.speeds').dataset.pointer = `/analysis/${S.speedKey}`;
  for (const [id, t] of [['omega', 'Ω'], ['sweep-from', 'from'], ['sweep-to', 'to']]) {
    document.querySelector(`label[for="${id}"]`).textContent = `${t} (${unit})`;
  }
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
  // critical speeds: the orders of the request are the ones shown (both order fields)
  $('critical').checked = Array.isArray(a.engine_orders);
  if (Array.isArray(a.engine_orders)) setOrdersText(a.engine_orders.join(', '));
  $('error-estimate').checked = a.error_estimate === true;
}

/** The engine orders typed (Analysis and the Campbell diagram show the same text). */
function setOrdersText(t) {
  for (const id of ['eo-orders', 'eo-list']) if ($(id).value !== t) $(id).value = t;
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
    count: $('sweep-count').value, list: $('omega-list').value, range: S.speedRange,
    unit: S.speedKey === 'rpm' ? 'rpm' : 'rad/s'};
}

function speedsChanged() {
  const v = speedsValue(speedFields());
  S.sweepError = v.error ? {message: v.error, el: $({from: 'sweep-from', to: 'sweep-to', count: 'sweep-count'}[v.field])} : null;
  if (!v.error) {
    an()[S.speedKey] = v.value;
    delete an()[S.speedKey === 'rpm' ? 'omega' : 'rpm'];
  }
  docChanged('options');
}

for (const r of document.querySelectorAll('input[name="speed-mode"]')) {
  r.addEventListener('change', () => {
    if (!r.checked) return;
    const prev = speedsValue(speedFields());
    speedMode = r.value;
    // carry the speeds over into the new form
    const nums = speedList(prev.value);
    S.speedRange = S.speedRange && speedMode === 'sweep';
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

/**
 * The speeds' unit in the request: analysis.omega (rad/s) or analysis.rpm.
 * Switching converts the speeds (12 significant digits; a range stays a range)
 * and the results are then shown in that speed unit too.
 */
$('speed-in-unit').addEventListener('change', () => {
  const toRpm = $('speed-in-unit').value === 'rpm';
  const from = S.speedKey, to = toRpm ? 'rpm' : 'omega';
  if (from === to) return;
  const a = an();
  const v = a[from];
  const conv = (x) => (typeof x === 'number' ? convertSpeed(x, toRpm) : x);
  const r = rangeOf(v);
  delete a[from];
  a[to] = r ? {...v, from: conv(r.from), to: conv(r.to)} : Array.isArray(v) ? v.map(conv) : conv(v);
  renderOptions();
  docChanged('options');
  $('speed-unit').value = toRpm ? 'rpm' : 'rad';
  if (S.result) showUnits();
});

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
// only when ticked: without it the key is absent and the job id is that of before (DESIGN.md 9.4)
bindOpt('error-estimate', 'error_estimate', (e) => (e.checked ? true : undefined));

/**
 * "find critical speeds": the engine orders typed go to analysis.engine_orders
 * (unticked: the key is absent, so the job id does not change).  The orders
 * fields of the Analysis panel and of the Campbell diagram are one list.
 */
function ordersChanged(from) {
  setOrdersText($(from).value);
  if ($('critical').checked) {
    an().engine_orders = parseOrders($('eo-orders').value);
    docChanged('options');
  }
  updateChart();
}
$('critical').addEventListener('change', () => {
  if ($('critical').checked) an().engine_orders = parseOrders($('eo-orders').value);
  else delete an().engine_orders;
  docChanged('options');
});
$('eo-orders').addEventListener('input', () => ordersChanged('eo-orders'));
$('eo-list').addEventListener('input', () => ordersChanged('eo-list'));

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
  // input_warnings (unit slips): next to their field as the errors, and listed
  const wl = $('warnings');
  wl.textContent = '';
  for (const w of S.warnings) {
    const target = targetOf(w.pointer);
    const slot = w.pointer === '' ? $('json-msg') : msgSlot(target);
    const line = document.createElement('div');
    line.className = 'warn';
    line.textContent = '⚠ ' + w.message;
    slot.append(line);
    const li = document.createElement('li');
    const b = document.createElement('button');
    b.type = 'button';
    b.className = 'linkish';
    b.textContent = w.pointer || '(document)';
    b.addEventListener('click', () => (controlOf(target) || $('json')).focus());
    li.append(b, ' ', w.message);
    wl.append(li);
  }
  $('warnings-box').hidden = S.warnings.length === 0;
  const v = $('validity');
  if (all.length) {
    v.textContent = `${all.length} error${all.length === 1 ? '' : 's'}` +
      (S.serverErrorsFrom === 'submit' && server.length ? ' (from the last submission)' : '');
    v.className = 'validity bad';
  } else if (api.validateAvailable() === true && S.validated === S.text) {
    v.textContent = 'valid' + (S.warnings.length ? `, ${S.warnings.length} warning${S.warnings.length === 1 ? '' : 's'}` : '');
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
  S.warnings = r.valid ? r.warnings || [] : [];
  showErrors();
}

// --------------------------------------------------------------- drawing

let meshCache = {key: '', mesh: null};

function meshOf(doc) {
  const st = structureOf(doc);
  const key = JSON.stringify([st, doc.frames]);
  if (meshCache.key !== key) meshCache = {key, mesh: buildMesh(st, 'frames' in doc ? doc.frames : DEFAULTS.frames)};
  return meshCache.mesh;
}

function draw() {
  const st0 = structureOf(S.doc);
  const st = st0 && typeof st0 === 'object' ? st0 : {};
  const mesh = meshOf(S.doc);
  let equilibrium = null, eqLabel = '';
  const R = S.result;
  if (R && $('show-equilibrium').checked && JSON.stringify(structureOf(R.request)) === JSON.stringify(st0)) {
    const c = selectedCase();
    if (c && c.status !== 'no_equilibrium' && c.equilibrium && Array.isArray(c.equilibrium.nodes)) {
      equilibrium = c.equilibrium.nodes;
      eqLabel = `steady shape at Ω = ${speedText(c)} (${c.status})`;
    }
  }
  const in3d = structureIn3d();
  const opts = {frames: $('show-frames').checked, nodes: $('show-nodes').checked, equilibrium, eqLabel};
  const svg = $('structure-svg');
  if (in3d) drawStructure3d(svg, st, mesh, S.cam, opts);
  else drawStructure(svg, st, mesh, opts);
  const n = Object.keys(mesh.joints).length, m = mesh.lines.length;
  $('structure-desc').textContent = (mesh.ok
    ? `${plural(n, 'joint')}, ${plural(m, 'member')}, ${plural(mesh.elems.length, 'element')}, ` +
      `${plural(mesh.frames.length, 'frame')}` + (equilibrium ? `; blue: ${eqLabel}` : '')
    : `${plural(n, 'joint')}, ${plural(m, 'member')} drawn (${mesh.reason || 'incomplete'})`) +
    (in3d ? '. 3D view, z (the spin axis) up; frames: red e1 along the member, blue e3 the flap normal; ' +
      'dashed grey: shadows on the hub plane. Drag (or arrow keys) to turn, Home or double click to reset.' : '');
  viewControls();
}
for (const id of ['show-frames', 'show-nodes', 'show-equilibrium']) $(id).addEventListener('change', draw);

// ------------------------------------------------------------- 3D view

/** Is the structure drawn in 3D?  The switch, else whether the structure is spatial. */
function structureIn3d() {
  return S.view3d ?? (S.blade || !!(S.rows && S.rows.spatial));
}

/** Is the mode shape drawn in 3D?  The switch, else whether the solved request or its result is spatial. */
function modeIn3d() {
  const R = S.result;
  if (!R) return false;
  return S.view3d ?? (isSpatial(structureOf(R.request)) || (R.result.model || {}).spatial === true);
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

{ // the list shows no example while the editor holds a file, an import or a past job
  const o = document.createElement('option');
  o.value = '';
  o.textContent = '—';
  o.disabled = true;
  $('example').append(o);
}
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
  S.warnings = [];
  S.sweepError = null;
  setDoc(ex.doc(), 'example');
}

/** Load a request document into the editor (a file, an import, a past job); caption says where it came from. */
function loadDoc(doc, caption = '') {
  $('example').value = '';
  $('example-desc').textContent = caption;
  S.view3d = null;
  Object.assign(S.cam, homeCamera());
  S.serverErrors = [];
  S.warnings = [];
  S.sweepError = null;
  S.parseError = null;
  setDoc(doc, 'file');
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
    showResult(cur.id, S.submitted && S.submitted.id === cur.id ? S.submitted.request : S.doc, result, cur);
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

const chart = campbellChart($('campbell'), (last) => errbarNote(last));

function selectedCase() {
  const R = S.result;
  if (!R) return null;
  const i = Number($('mode-speed').value);
  return R.result.cases[Number.isInteger(i) ? i : 0] || null;
}

/** The display units of the results: {speed: 'rad' | 'rpm', freq: 'rad' | 'hz' | 'rev'}. */
function units() {
  return {speed: $('speed-unit').value, freq: $('freq-unit').value};
}

/** A case's speed as text in the speed unit shown: "20 rad/s", "190.986 rpm". */
function speedText(c, n = 6) {
  const su = units().speed;
  const v = su === 'rpm' ? (typeof c.rpm === 'number' ? c.rpm : c.omega * 60 / (2 * Math.PI)) : c.omega;
  return `${sig(v, n)} ${SPEED_UNITS[su].label}`;
}

/** A mode's frequency as text in the frequency unit shown. */
function freqText(m, c, n = 6) {
  const fu = units().freq;
  const v = freqIn(fu, m, c.omega);
  return v === null ? '–' : `${sig(v, n)} ${FREQ_UNITS[fu].label}`;
}

/** "Ω = 8, 10 rad/s" or "Ω = 8…18 rad/s (6 speeds)" for the cases cs. */
function speedsText(cs) {
  const su = units().speed, u = SPEED_UNITS[su].label;
  const v = cs.map((c) => (su === 'rpm' ? (typeof c.rpm === 'number' ? c.rpm : c.omega * 60 / (2 * Math.PI)) : c.omega));
  if (v.length <= 4) return `Ω = ${v.map((x) => sig(x)).join(', ')} ${u}`;
  return `${v.length} speeds (Ω = ${sig(Math.min(...v))}…${sig(Math.max(...v))} ${u})`;
}

/** Cases grouped by what went wrong: one entry per distinct status + message (numbers ignored). */
function groupBy(cases, text) {
  const groups = new Map();
  for (const c of cases) {
    const t = text(c);
    const key = t.replace(/-?\d+(\.\d+)?(e[-+]?\d+)?/gi, '#');
    if (!groups.has(key)) groups.set(key, {text: t, cases: []});
    groups.get(key).cases.push(c);
  }
  return Array.from(groups.values());
}

/**
 * Show a result: id (a job's, or "file…"), the request it is for, the result
 * document and the job's status document (its wall time; null for a file).
 */
function showResult(id, request, result, job = null) {
  const mesh = buildMesh(structureOf(request), request && 'frames' in request ? request.frames : DEFAULTS.frames);
  S.result = {id, request, result, mesh, job};
  $('results').hidden = false;
  const fb = fileBase();
  $('dl-json').href = api.resultUrl(id);
  $('dl-json').setAttribute('download', `${fb}.json`);
  $('dl-csv').href = api.resultUrl(id, 'csv');
  $('dl-csv').setAttribute('download', `${fb}.csv`);
  setBlobLink($('dl-json-req'), `${fb}-with-request.json`, 'application/json',
    JSON.stringify({request, result}, null, 1));
  dlMsg('');
  spanwiseControls();
  criticalControls();
  const rw = api.warningsOf(result);
  if (rw.length && JSON.stringify(request) === JSON.stringify(S.doc)) {
    const have = new Set(S.warnings.map((w) => w.pointer + '\n' + w.message));
    S.warnings = S.warnings.concat(rw.filter((w) => !have.has(w.pointer + '\n' + w.message)));
    showErrors();
  }
  applyUnits(request);
  const sel = $('mode-speed');
  sel.textContent = '';
  let best = -1;
  const cases = result.cases || [];
  const hasModes = (c) => Array.isArray(c.modes) && c.modes.length > 0;
  cases.forEach((c, i) => {
    const o = document.createElement('option');
    o.value = String(i);
    sel.append(o);
    if (hasModes(c) && (best < 0 || c.omega >= cases[best].omega)) best = i;
  });
  if (best < 0) best = 0;
  sel.value = String(best);
  markStale();
  showUnits();
  startMode();
  draw();
}

// ------------------------------------------------------------- units shown

const UNITS_KEY = 'spinmodal.units';
/** The units a result is shown in by default: a request in rpm in rpm and Hz, one in rad/s in rad/s. */
const UNIT_DEFAULTS = {rpm: {speed: 'rpm', freq: 'hz'}, omega: {speed: 'rad', freq: 'rad'}};

/** 'rpm' for a request that gives its speeds in rpm, else 'omega'. */
function speedKind(request) {
  const a = request && request.analysis;
  return a && typeof a === 'object' && 'rpm' in a && !('omega' in a) ? 'rpm' : 'omega';
}

/** The user's choices of units, per kind of request (localStorage): {rpm: {speed, freq}, omega: …}. */
function unitPrefs() {
  try {
    const p = JSON.parse(localStorage.getItem(UNITS_KEY) || '{}');
    return p && typeof p === 'object' ? p : {};
  } catch {
    return {};
  }
}

/** Show a result of request in the units the user last chose for such a request, else the defaults. */
function applyUnits(request) {
  const kind = speedKind(request);
  const pref = unitPrefs()[kind] || {};
  const want = {...UNIT_DEFAULTS[kind]};
  if (pref.speed in SPEED_UNITS) want.speed = pref.speed;
  if (pref.freq in FREQ_UNITS) want.freq = pref.freq;
  $('speed-unit').value = want.speed;
  $('freq-unit').value = want.freq;
}

/** The user picked a unit: remember it for the results of this kind of request. */
function rememberUnits() {
  if (!S.result) return;
  const all = unitPrefs();
  all[speedKind(S.result.request)] = units();
  try {
    localStorage.setItem(UNITS_KEY, JSON.stringify(all));
  } catch {
    /* storage disabled: the choice holds for this page only */
  }
}

/** "26.1 s", "850 ms": a duration in seconds as text. */
function durationText(s) {
  return s < 1 ? `${sig(s * 1000, 3)} ms` : s < 600 ? `${sig(s, 3)} s` : `${sig(s / 60, 3)} min`;
}

/**
 * How long the job took: its wall time from started_at to finished_at (the
 * refined solves of an error estimate and the critical-speed solves
 * included), or for a result without its job the solver's own timing_ms.
 */
function timingText(R) {
  const j = R.job, t = R.result.timing_ms;
  const t0 = j ? Date.parse(j.started_at) : NaN, t1 = j ? Date.parse(j.finished_at) : NaN;
  const solve = t ? (t.equilibrium || 0) + (t.linearize || 0) + (t.eigen || 0) : null;
  if (Number.isFinite(t0) && Number.isFinite(t1) && t1 >= t0) {
    const est = R.request && R.request.analysis && R.request.analysis.error_estimate === true;
    return `wall time ${durationText((t1 - t0) / 1000)}` + (solve !== null
      ? ` (the requested speeds' solves: ${durationText(solve / 1000)}${est ? '; the rest is the error estimate\'s refined solves' : ''})`
      : '');
  }
  return solve !== null ? `solver time ${durationText(solve / 1000)}` : '';
}

/** Everything of the results that depends on the units shown. */
function showUnits() {
  const R = S.result;
  if (!R) return;
  const result = R.result;
  const md = result.model || {};
  const cases = result.cases || [];
  const tt = timingText(R);
  $('result-summary').textContent = `${plural(cases.length, 'speed')}; model: ${plural(md.nodes, 'node')}, ` +
    `${plural(md.elements, 'element')}, ${plural(md.frames, 'frame')}, ${plural(md.coordinates, 'coordinate')}` +
    (tt ? `; ${tt}` : '') + '.';
  $('result-summary').dataset.wallS = R.job && Date.parse(R.job.finished_at) >= Date.parse(R.job.started_at)
    ? String((Date.parse(R.job.finished_at) - Date.parse(R.job.started_at)) / 1000) : '';
  const notes = $('case-notes');
  notes.textContent = '';
  // one note per distinct failure (status and message), naming its speeds
  const bad = cases.filter((c) => c.status !== 'solved');
  for (const g of groupBy(bad, (c) => {
    const d = c.diagnostics || {};
    return `${c.status}` + (d.message ? ` — ${d.message}` : '');
  })) {
    const p = document.createElement('p');
    p.className = 'note';
    p.textContent = `${speedsText(g.cases)}: ${g.text}`;
    notes.append(p);
  }
  // warnings (outside the model's validity): one note per distinct warning, for all the speeds that carry it
  const warned = cases.filter((c) => Array.isArray(c.warnings) && c.warnings.length > 0);
  for (const g of groupBy(warned, (c) => c.warnings[0])) {
    const p = document.createElement('p');
    p.className = 'note warning';
    p.textContent = `Warning at ${g.cases.length === 1 ? speedsText(g.cases) : speedsText(g.cases).replace(/^Ω = /, `${g.cases.length} speeds (Ω = `) + (g.cases.length <= 4 ? ')' : '')}: ${g.text}`;
    notes.append(p);
  }
  if (bad.length || warned.length) {
    const p = document.createElement('p');
    p.className = 'hint';
    p.textContent = 'On the Campbell diagram these speeds are hollow grey circles, left out of the lines and the crossings.';
    notes.append(p);
  }
  const sel = $('mode-speed');
  cases.forEach((c, i) => {
    const o = sel.options[i];
    if (o) o.textContent = speedText(c) + (c.status === 'solved' ? '' : ` (${c.status})`);
  });
  freqTable(result);
  updateChart();
  modeSelectors();
  startMode();
  draw();
  tableCsv();
}

/** The frequency table in the units shown: [[header…], [row…]…] (also the "CSV (units shown)" download). */
function tableRows(result) {
  const u = units();
  const cases = (result.cases || []).slice().sort((a, b) => a.omega - b.omega);
  const n = cases.reduce((m, c) => Math.max(m, (c.modes || []).length), 0);
  const hasLabel = cases.some((c) => (c.modes || []).some((m) => m && typeof m.label === 'string'));
  const hasErr = cases.some((c) => (c.modes || []).some((m) => m && 'error_estimate' in m));
  const fl = FREQ_UNITS[u.freq].label;
  const head = [`speed (${SPEED_UNITS[u.speed].label})`, 'status'];
  for (let k = 1; k <= n; k++) {
    head.push(`mode ${k} (${fl})`);
    if (hasErr) head.push(`mode ${k} ± (${fl})`);
    if (hasLabel) head.push(`mode ${k} label`);
  }
  const rows = cases.map((c) => {
    const sp = u.speed === 'rpm' ? (typeof c.rpm === 'number' ? c.rpm : c.omega * 60 / (2 * Math.PI)) : c.omega;
    const r = [sp, c.status];
    for (let k = 0; k < n; k++) {
      const m = (c.modes || [])[k];
      r.push(freqIn(u.freq, m, c.omega));
      if (hasErr) r.push(errIn(u.freq, m, c.omega));
      if (hasLabel) r.push(m && typeof m.label === 'string' ? m.label : null);
    }
    return r;
  });
  return {head, rows, cases, n, hasLabel, hasErr};
}

function freqTable(result) {
  const u = units();
  const {rows, cases, n, hasLabel, hasErr} = tableRows(result);
  const per = 1 + (hasErr ? 1 : 0) + (hasLabel ? 1 : 0); // values per mode in a row
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
  hr.append(th(`Ω (${SPEED_UNITS[u.speed].label})`), th('status'));
  const fsym = u.freq === 'hz' ? 'f' : u.freq === 'rev' ? 'ω/Ω' : 'ω';
  for (let k = 1; k <= n; k++) {
    hr.append(th(`${fsym}<sub>${k}</sub> (${FREQ_UNITS[u.freq].label})` + (hasErr ? ' ± error' : '')));
    if (hasLabel) {
      const e = th(`label<sub>${k}</sub>`);
      e.className = 'mlabel';
      e.title = 'The mode\'s kind by its strain energy (flap, edge, torsion, axial, bending; coupled when no part exceeds 60 %), numbered by frequency at that speed';
      hr.append(e);
    }
  }
  rows.forEach((r, i) => {
    const c = cases[i];
    const tr = tbody.insertRow();
    if (flaggedCase(c)) tr.className = 'flagged';
    const h = document.createElement('th');
    h.scope = 'row';
    h.textContent = sig(r[0]);
    tr.append(h);
    const st = tr.insertCell();
    st.textContent = r[1];
    if (Array.isArray(c.warnings) && c.warnings.length) {
      st.title = c.warnings.join('\n');
      st.className = 'warned';
    }
    if (c.status !== 'solved') st.className = 'bad';
    for (let k = 0; k < n; k++) {
      const v = r[2 + per * k];
      const td = tr.insertCell();
      td.className = 'fq';
      td.textContent = v === null ? '–' : sig(v);
      if (hasErr) {
        const e = r[3 + per * k];
        const sp = document.createElement('span');
        sp.className = 'pm';
        sp.textContent = e === null ? '' : ` ± ${sig(e, 2)}`;
        if (e !== null) sp.dataset.err = String(e);
        td.title = e === null ? 'no error estimate for this mode (not matched in the refined meshes)'
          : `estimated distance to the converged beam model: ${sig(e, 3)} ${FREQ_UNITS[u.freq].label}`;
        td.append(sp);
      }
      if (hasLabel) {
        const m = (c.modes || [])[k];
        const lt = tr.insertCell();
        lt.className = 'mlabel';
        lt.textContent = m && typeof m.label === 'string' ? m.label : '';
        if (m && typeof m.label_confidence === 'number') lt.title = `confidence ${sig(m.label_confidence, 3)} (dominant strain-energy fraction)`;
      }
    }
  });
}

/** A download link for text made in the page. */
function setBlobLink(a, name, type, text) {
  if (a.dataset.url) URL.revokeObjectURL(a.dataset.url);
  const u = URL.createObjectURL(new Blob([text], {type}));
  a.dataset.url = u;
  a.href = u;
  a.setAttribute('download', name);
}

function csvCell(v) {
  if (v === null || v === undefined) return '';
  if (typeof v === 'number') return String(v);
  const t = String(v);
  return /[",\n]/.test(t) ? '"' + t.replace(/"/g, '""') + '"' : t;
}

/** The "CSV (units shown)" download: the table as shown, at full precision. */
function tableCsv() {
  const R = S.result;
  if (!R) return;
  const {head, rows} = tableRows(R.result);
  const u = units();
  const text = [head, ...rows].map((r) => r.map(csvCell).join(',')).join('\n') + '\n';
  setBlobLink($('dl-csv-units'), `${fileBase(R)}-${u.speed}-${u.freq}.csv`, 'text/csv', text);
  $('dl-csv-units').dataset.csv = text;
}

function updateChart() {
  if (!S.result) return;
  const orders = parseOrders($('eo-list').value);
  const u = units();
  const ref = S.ref && S.ref.id !== S.result.id ? S.ref.result : null;
  $('ref-note').hidden = !ref;
  $('ref-note').textContent = ref ? `Dashed thin lines: the reference result ${S.ref.label}.` : '';
  const critical = criticalOf(S.result);
  const d = chart.update({result: S.result.result, orders, units: u, ref, critical, allModes: S.allModes});
  focusNote(d);
  for (const id of ['campbell-svg', 'campbell-png']) {
    $(id).disabled = d.single;
    $(id).title = d.single ? 'One speed: no Campbell diagram to export (the table is in the CSV downloads)' : '';
  }
  $('zoom-reset').hidden = d.single;
  const tb = $('crossings').tBodies[0];
  $('cross-speed-h').textContent = `Ω (${SPEED_UNITS[u.speed].label})`;
  $('cross-freq-h').textContent = `${FREQ_UNITS[u.freq].sym} (${FREQ_UNITS[u.freq].label})`;
  tb.textContent = '';
  for (const c of d.cross) {
    const tr = tb.insertRow();
    const sp = SPEED_UNITS[u.speed].of(c.omega);
    const f = u.freq === 'rev' ? c.order : FREQ_UNITS[u.freq].of(c.freq, c.omega);
    for (const v of [c.name, `${c.order}P`, sig(sp, 5), sig(f, 5)]) tr.insertCell().textContent = v;
  }
  // the orders the daemon covered are in the critical-speed table; the others (if any) here
  const left = orders.filter((k) => !(critical && critical.orders.includes(k)));
  $('crossings').hidden = !left.length;
  if (!d.cross.length) {
    const td = tb.insertRow().insertCell();
    td.colSpan = 4;
    td.textContent = d.rows.length > 1 ? 'none in the speed range' : 'a sweep is needed';
  }
  $('critical-hint').hidden = !!critical || d.rows.length < 2 || !orders.length;
  criticalTable(critical);
  divergenceTable(S.result.result);
}

/**
 * The result's divergence speeds (divergence_speeds, only when the sweep
 * crossed one) in the speed unit shown: kind, mode, Ω, the bracket of sweep
 * speeds, refined; hidden without them.
 */
function divergenceTable(result) {
  const ds = divergenceSpeeds(result);
  const t = $('divergence-table');
  t.hidden = !ds.length;
  $('divergence-note').hidden = !ds.length;
  const tb = t.tBodies[0];
  tb.textContent = '';
  if (!ds.length) return;
  const su = units().speed, ul = SPEED_UNITS[su].label;
  const sp = (d) => (su === 'rpm' ? d.rpm : SPEED_UNITS[su].of(d.omega));
  $('div-speed-h').textContent = `Ω (${ul})`;
  $('div-bracket-h').textContent = `between (${ul})`;
  for (const d of ds) {
    const tr = tb.insertRow();
    tr.className = `divergence ${d.kind}`;
    const br = d.bracket ? d.bracket.map((om) => SPEED_UNITS[su].of(om)) : null;
    const cells = [[d.kind, d.kind], [d.mode || '–', d.mode || ''], [sig(sp(d), 6), sp(d)],
      [br ? `${sig(br[0], 6)} … ${sig(br[1], 6)}` : '–', br ? br.join(',') : ''], [d.refined ? 'yes' : 'no', d.refined]];
    for (const [text, v] of cells) {
      const td = tr.insertCell();
      td.textContent = text;
      td.dataset.value = String(v);
    }
    tr.cells[0].title = d.kind === 'onset'
      ? 'the steady state loses static stability here: the lowest eigenvalue of K* passes through zero (a static divergence)'
      : 'the steady state regains static stability here: the lowest eigenvalue of K* comes back through zero';
    if (d.negative) tr.cells[0].title += `; negative eigenvalues of K*: ${d.negative[0]} → ${d.negative[1]}`;
    tr.cells[3].title = 'the speeds of the sweep on either side of the divergence speed';
    tr.cells[4].title = d.refined
      ? `refined by ${d.refineSolves ?? 'a few'} solve(s) at single speeds (regula falsi on the lowest eigenvalue of K*)` +
        (d.omegaInterpolated !== null ? `; linear interpolation between the sweep's speeds gave ` +
          `${sig(SPEED_UNITS[su].of(d.omegaInterpolated), 6)} ${ul}` : '')
      : 'interpolated between the speeds of the sweep (not refined)';
  }
}

/**
 * The result's critical speeds (DESIGN.md 9.1) for the chart: {orders (the
 * request's engine_orders, else those listed), points}, or null without them.
 */
function criticalOf(R) {
  const cs = R && R.result && Array.isArray(R.result.critical_speeds) ? R.result.critical_speeds : null;
  if (!cs) return null;
  const req = R.request && R.request.analysis && Array.isArray(R.request.analysis.engine_orders)
    ? R.request.analysis.engine_orders : null;
  return {
    orders: (req || cs.map((c) => c.order)).map(Number),
    points: cs.map((c) => ({order: c.order, line: c.tracked_index, label: c.label, omega: c.omega, rpm: c.rpm,
      freq: c.frequency_rad_s, refined: c.refined === true})),
  };
}

/** The daemon's critical speeds in the units shown: order, mode label, speed, frequency, refined. */
function criticalTable(critical) {
  const R = S.result;
  const cs = R && Array.isArray(R.result.critical_speeds) ? R.result.critical_speeds : null;
  const t = $('critical-table');
  t.hidden = !critical;
  const tb = t.tBodies[0];
  tb.textContent = '';
  if (!cs) return;
  const u = units();
  $('crit-speed-h').textContent = `Ω (${SPEED_UNITS[u.speed].label})`;
  $('crit-freq-h').textContent = `${FREQ_UNITS[u.freq].sym} (${FREQ_UNITS[u.freq].label})`;
  for (const c of cs) {
    const tr = tb.insertRow();
    const sp = u.speed === 'rpm' ? (typeof c.rpm === 'number' ? c.rpm : c.omega * 60 / (2 * Math.PI)) : c.omega;
    const f = u.freq === 'hz' ? (typeof c.frequency_hz === 'number' ? c.frequency_hz : c.frequency_rad_s / (2 * Math.PI))
      : u.freq === 'rev' ? c.order : c.frequency_rad_s;
    const cells = [[`${c.order}P`, c.order], [c.label || `line ${c.tracked_index}`, c.label], [sig(sp, 6), sp], [sig(f, 6), f],
      [c.refined ? 'yes' : 'no', c.refined]];
    for (const [text, v] of cells) {
      const td = tr.insertCell();
      td.textContent = text;
      td.dataset.value = String(v);
    }
    const sw = tr.cells[1];
    sw.style.borderLeft = `4px solid ${COLORS[c.tracked_index % COLORS.length]}`;
    if (!c.refined) tr.cells[4].title = 'interpolated between the speeds of the sweep; the refining solve found no equilibrium or lost the mode';
    else tr.cells[4].title = `refined by ${c.refine_solves} solve(s) at single speeds, |ω − kΩ|/kΩ = ${sig(c.residual, 2)}`;
  }
  if (!cs.length) {
    const td = tb.insertRow().insertCell();
    td.colSpan = 5;
    td.textContent = 'none in the speed range';
  }
}

/** Say when the y range is fitted to the engine orders (modes above it left out) and offer all modes. */
function focusNote(d) {
  const f = d.focus, n = $('focus-note'), b = $('campbell-all');
  n.hidden = !f || d.single;
  b.hidden = !f || d.single;
  if (!f || d.single) return;
  const fu = FREQ_UNITS[d.units.freq].label;
  b.textContent = d.focused ? 'Show all modes' : 'Fit to the engine orders';
  b.setAttribute('aria-pressed', d.focused ? 'false' : 'true');
  n.textContent = d.focused
    ? `The frequency axis is fitted to the modes the engine orders cross and the next one above (up to ${sig(f.top, 3)} ${fu}); ` +
      `${plural(f.hidden, 'higher mode')} (up to ${sig(f.max, 3)} ${fu}) ${f.hidden === 1 ? 'lies' : 'lie'} above: “Show all modes”.`
    : `All modes, up to ${sig(f.max, 3)} ${fu}: the engine orders stay below ${sig(f.top, 3)} ${fu}.`;
}
$('campbell-all').addEventListener('click', () => {
  S.allModes = !S.allModes;
  updateChart();
});

/** Say how the error bars are shown: drawn where longer than the point, else only in the tooltip. */
function errbarNote(last) {
  const n = $('errbar-note');
  const e = last && last.errDrawn;
  if (!e || !e.total) {
    n.hidden = true;
    return;
  }
  n.hidden = false;
  const fu = FREQ_UNITS[last.units.freq].label;
  n.textContent = e.hidden && !e.drawn
    ? `Error bars (± up to ${sig(e.max, 2)} ${fu}) are too small to see at this scale: point at a mode to read its ±, or zoom in.`
    : `Error bars: ± the estimated error of each frequency (up to ${sig(e.max, 2)} ${fu})` +
      (e.hidden ? `; ${e.hidden} too small to see at this scale (point at a mode to read its ±).` : '.');
  n.title = 'error_estimate of each frequency: refined meshes (2×, 4× the elements) and Richardson extrapolation; ' +
    `a bar is drawn where it reaches beyond its point marker (${e.drawn} drawn, ${e.hidden} smaller).`;
  n.dataset.drawn = String(e.drawn);
  n.dataset.hidden = String(e.hidden);
}
for (const id of ['freq-unit', 'speed-unit']) {
  $(id).addEventListener('change', () => {
    rememberUnits();
    showUnits();
  });
}
$('zoom-reset').addEventListener('click', updateChart);

// ---------------------------------------------------------- mode animation

function modeSelectors() {
  const c = selectedCase();
  const sel = $('mode-index');
  const prev = sel.value;
  sel.textContent = '';
  (c && c.modes ? c.modes : []).forEach((m, k) => {
    const o = document.createElement('option');
    o.value = String(k);
    o.textContent = `${k + 1}: ${freqText(m, c, 5)}` + (typeof m.label === 'string' ? ` (${m.label})` : '');
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
    showSpanwisePlot();
    return;
  }
  buildModeView();
  S.anim.omega = m ? m.frequency_rad_s : 0;
  if (!m) desc.textContent = `no modes at Ω = ${speedText(c)} (${c.status})`;
  else if (!m.shape) desc.textContent = 'no mode shapes in this result (turn "mode shapes" on and solve again)';
  else {
    const fu = units().freq;
    const other = fu === 'hz' ? `${sig(m.frequency_rad_s)} rad/s` : `${sig(m.frequency_hz)} Hz`;
    desc.textContent = `mode ${k + 1}${typeof m.label === 'string' ? ` (${m.label})` : ''} at Ω = ${speedText(c)}: ` +
      `${FREQ_UNITS[fu].sym} = ${freqText(m, c)}` +
      (errIn(fu, m, c.omega) !== null ? ` ± ${sig(errIn(fu, m, c.omega), 2)}` : '') + ` (${other})` +
      (Number.isInteger(m.tracked_index) && m.tracking_flag ? `, ${m.tracking_flag} with ` +
        `${lineName(m.tracking_partner)}` : '') +
      (m.shape.im ? ', complex (gyroscopic): u(t) = Re((re + i·im)·e^{iωt})' : '') +
      '. Grey: undeformed; blue line: steady shape; animated: the mode, one cycle every 2 s' +
      (modeIn3d() ? '; faint: its shadow on the hub plane. Drag to turn the view.' : '.');
  }
  svg.dataset.mode = String(k);
  svg.dataset.case = $('mode-speed').value;
  showSpanwisePlot();
}

/** The Campbell name of a tracked line of the result shown. */
function lineName(id) {
  const l = S.result ? campbellData(S.result.result).lines.find((x) => x.id === id) : null;
  return l ? l.name : `line ${id}`;
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

// ------------------------------------------------------------ files

function fileMsg(text, cls = '') {
  const m = $('file-msg');
  m.textContent = text;
  m.className = 'file-msg ' + cls;
}

function readFile(f) {
  return f.text ? f.text() : new Promise((res, rej) => {
    const r = new FileReader();
    r.onload = () => res(String(r.result));
    r.onerror = () => rej(r.error);
    r.readAsText(f);
  });
}

$('open-request').addEventListener('change', async () => {
  const f = $('open-request').files[0];
  if (!f) return;
  const text = await readFile(f);
  let doc;
  try {
    doc = JSON.parse(text);
  } catch (e) {
    fileMsg(`${f.name}: not a JSON request (${e.message})`, 'bad');
    $('open-request').value = '';
    return;
  }
  // a "JSON + request" download holds {request, result}
  const req = doc && typeof doc === 'object' && doc.request && doc.result ? doc.request : doc;
  loadDoc(req, `Opened ${f.name}` + (req && typeof req.name === 'string' ? ` (“${req.name}”)` : '') + '.');
  if (doc && doc.request && doc.result) showResult(doc.result.solver ? 'file-' + f.name : 'file', doc.request, doc.result);
  fileMsg(`opened ${f.name}`, 'ok');
  $('open-request').value = '';
});

$('save-request').addEventListener('click', () => {
  const name = (typeof S.doc.name === 'string' && fileSafe(S.doc.name) ? fileSafe(S.doc.name)
    : $('example').value && !S.blade ? $('example').value : 'request') + '.json';
  saveBlob(new Blob([S.text.endsWith('\n') ? S.text : S.text + '\n'], {type: 'application/json'}), `spinmodal-${name}`);
  fileMsg(`saved spinmodal-${name} (your downloads)`, 'ok');
});

// ------------------------------------------------------------ past jobs

let jobsLoaded = 0;

async function refreshJobs() {
  if (Date.now() - jobsLoaded < 2000) return;
  jobsLoaded = Date.now();
  let items;
  try {
    items = await api.listJobs(30);
  } catch (e) {
    fileMsg(`past jobs: ${e.message}`, 'bad');
    return;
  }
  const sel = $('past-jobs');
  const prev = sel.value;
  sel.textContent = '';
  const none = document.createElement('option');
  none.value = '';
  none.textContent = items.length ? `— ${items.length} recent —` : '— none yet —';
  sel.append(none);
  for (const j of items) {
    const o = document.createElement('option');
    o.value = j.id;
    const when = (j.created_at || '').replace('T', ' ').replace(/\.\d+Z$/, ' UTC');
    o.textContent = (typeof j.name === 'string' ? `${j.name} · ` : '') +
      `${when} · ${j.state} · ${j.progress ? plural(j.progress.total, 'speed') : '? speeds'} · ${j.id.slice(0, 8)}`;
    if (typeof j.name === 'string') o.dataset.name = j.name;
    sel.append(o);
  }
  if (prev && Array.from(sel.options).some((o) => o.value === prev)) sel.value = prev;
}
$('past-jobs').addEventListener('focus', refreshJobs);
$('past-jobs').addEventListener('pointerdown', refreshJobs);

/** Reopen a past job: its request into the editor (GET …/request), its result if it has one. */
async function reopenJob(id) {
  if (!id) return;
  fileMsg(`opening job ${id.slice(0, 12)}…`);
  let request, st;
  try {
    request = await api.getRequest(id);
    st = await api.getStatus(id);
  } catch (e) {
    fileMsg(`job ${id.slice(0, 12)}: ${e.message}`, 'bad');
    return;
  }
  S.pollGen++;
  loadDoc(request, `Past job ${id.slice(0, 12)}` + (request && typeof request.name === 'string' ? ` — “${request.name}”` : '') +
    (st && st.doc && st.doc.created_at ? `, submitted ${st.doc.created_at.replace('T', ' ').replace(/\.\d+Z$/, ' UTC')}` : '') + '.');
  if (st && st.doc) {
    showJob(st.doc);
    S.submitted = {id, request: S.doc};
    if (!TERMINAL.has(st.doc.state)) poll(st.doc, S.pollGen);
    else if (st.doc.result) showResult(id, S.doc, st.doc.result, st.doc);
  }
  fileMsg(`reopened job ${id.slice(0, 12)} (${st && st.doc ? st.doc.state : '?'})`, 'ok');
}
$('open-job').addEventListener('click', () => reopenJob($('past-jobs').value));

// ------------------------------------------------------------ blade import

const IMPORT_MAIN = {bmodes: 'BModes main file (.bmi)', elastodyn: 'ElastoDyn blade file (.dat)',
  csv: 'CSV file (a header row naming the columns: s or r, mass_per_length, EI_flap …)'};

function importFormat() {
  const f = $('import-format').value;
  $('import-main-label').textContent = IMPORT_MAIN[f];
  $('import-sec-field').hidden = f !== 'bmodes';
  $('import-bmesh-field').hidden = f !== 'bmodes';
  $('import-bmodes-k').disabled = !$('import-bmodes-mesh').checked;
  $('import-tip').placeholder = f === 'bmodes' ? 'from the file' : 'required (m)';
  $('import-error').textContent = '';
}
$('import-format').addEventListener('change', importFormat);
$('import-bmodes-mesh').addEventListener('change', importFormat);
$('open-blade').addEventListener('click', () => {
  importFormat();
  $('import-dialog').showModal();
});

/** Import the chosen files: POST /v1/import/{format}; the request goes into the editor. */
async function importBlade() {
  const format = $('import-format').value;
  const main = $('import-main').files[0], sec = $('import-sec').files[0];
  const err = $('import-error');
  err.textContent = '';
  if (!main) {
    err.textContent = 'Choose the file to import.';
    return;
  }
  if (format === 'bmodes' && !sec) {
    err.textContent = 'A BModes import needs the section-properties file too (the one the .bmi names).';
    return;
  }
  const body = {main: await readFile(main), name: main.name};
  if (format === 'bmodes') body.sec_props = await readFile(sec);
  const q = {tip_radius: $('import-tip').value.trim(), hub_radius: $('import-hub').value.trim(),
    rpm: $('import-rpm').value.trim()};
  const ownMesh = format === 'bmodes' && $('import-bmodes-mesh').checked;
  if (ownMesh) {
    // BModes' own model: its elements as uniform members, K FE elements each (DAEMON.md, Importers)
    const k = $('import-bmodes-k').value.trim();
    if (!/^\d+$/.test(k) || Number(k) < 1 || Number(k) > 1000) {
      err.textContent = 'FE elements per BModes element: a whole number from 1 to 1000.';
      return;
    }
    q.bmodes_mesh = k;
  }
  let r;
  try {
    r = await api.importBlade(format, body, q);
  } catch (e) {
    err.textContent = `cannot reach the daemon: ${e.message}`;
    return;
  }
  if (!r.ok) {
    // 422: FILE:LINE: FIELD: what is wrong
    const where = r.file ? `${r.file}${r.line ? `, line ${r.line}` : ''}${r.field ? `, field ${r.field}` : ''}` : '';
    err.textContent = '';
    const h = document.createElement('strong');
    h.textContent = where ? `${where}: ` : `${r.status}: `;
    const t = document.createElement('span');
    t.textContent = r.message;
    err.append(h, t);
    err.dataset.file = r.file || '';
    err.dataset.line = r.line ? String(r.line) : '';
    err.dataset.field = r.field || '';
    return;
  }
  $('import-dialog').close();
  const src = r.source || {};
  const req = r.request && typeof r.request === 'object' ? r.request : {};
  // a name for the past jobs and the file names: the file's, unless the request has one
  if (typeof req.name !== 'string' && fileSafe(main.name.replace(/\.[^.]*$/, ''))) req.name = main.name.replace(/\.[^.]*$/, '');
  const b = req.blade && typeof req.blade === 'object' ? req.blade : null;
  const an = req.analysis && typeof req.analysis === 'object' ? req.analysis : {};
  const sp = 'rpm' in an ? speedList(an.rpm) : [];
  loadDoc(req, `Imported from ${main.name}${format === 'bmodes' ? ` + ${sec.name}` : ''}` + (src.title ? ` (“${src.title}”)` : '') +
    (b ? `: a blade of ${fmtNum(b.length)} m${Array.isArray(b.stations) ? `, ${plural(b.stations.length, 'station')}` : ''}`
      : req.structure && Array.isArray(req.structure.members) ? `: ${plural(req.structure.members.length, 'member')}` : '') +
    (sp.length === 1 ? `, ${fmtNum(sp[0])} rpm` : '') + '.');
  $('import-notes').hidden = false;
  $('import-source').textContent = `${src.file || main.name}${src.sec_props_file ? ' + ' + src.sec_props_file : ''}` +
    (src.title ? ` — “${src.title}”` : '');
  const ul = $('import-warnings');
  ul.textContent = '';
  const warnings = r.warnings.slice();
  // the section file chosen is not the one the .bmi names (a tower table would import without a word)
  const baseName = (t) => String(t).split(/[\\/]/).pop();
  if (format === 'bmodes' && typeof src.sec_props_file === 'string' && src.sec_props_file &&
      baseName(src.sec_props_file).toLowerCase() !== sec.name.toLowerCase() &&
      !warnings.some((w) => String(typeof w === 'string' ? w : w.message).includes(sec.name))) {
    warnings.unshift({file: main.name, field: 'sec_props_file', mismatch: true,
      message: `the .bmi names the section file “${src.sec_props_file}”, but “${sec.name}” was chosen: ` +
        'check that it is this blade\'s table (a tower\'s would import without an error)'});
  }
  for (const w of warnings) {
    const li = document.createElement('li');
    li.textContent = typeof w === 'string' ? w : [w.file && `${w.file}${w.line ? ':' + w.line : ''}`, w.field, w.message]
      .filter(Boolean).join(': ') || JSON.stringify(w);
    if (w && w.mismatch) {
      li.className = 'warn sec-mismatch';
      li.textContent = '⚠ ' + li.textContent;
    }
    ul.append(li);
  }
  if (!warnings.length) {
    const li = document.createElement('li');
    li.className = 'ok';
    li.textContent = 'no import warnings';
    ul.append(li);
  }
  const st = S.doc.structure;
  fileMsg(ownMesh && st && Array.isArray(st.members)
    ? `imported ${main.name} (BModes' own mesh): ${st.members.length} members of ${q.bmodes_mesh} elements — press Solve`
    : `imported ${main.name} (${format}): a blade of ${S.doc.blade && S.doc.blade.length} m — press Solve`, 'ok');
}
$('import-go').addEventListener('click', importBlade);

// ------------------------------------------------------------ span-wise shapes

const SHAPE_FILES = {
  spanwise: {button: 'dl-spanwise', suffix: 'spanwise.csv', what: 'span-wise shapes',
    title: 'Flap, edge, their slopes, twist and axial motion of every mode along each member, each mode scaled to ' +
      '1 m at its largest (GET …/result?format=spanwise)'},
  bmodes: {button: 'dl-bmodes', suffix: 'bmodes.txt', what: 'the BModes-style table',
    title: 'The span-wise shapes in the layout of BModes\' .out: span_loc, flap disp, flap slope, lag disp, lag slope, ' +
      'twist, with BModes\' signs (GET …/result?format=bmodes)'},
};

function dlMsg(text, cls = '') {
  const m = $('dl-msg');
  m.textContent = text;
  m.className = 'dl-msg ' + cls;
}

/** Offer the span-wise downloads only for a result the daemon has them for (else disabled, saying why). */
function spanwiseControls() {
  const R = S.result;
  const av = R ? spanwiseAvailability(R.id, R.result) : {ok: false, why: 'no result'};
  for (const [, f] of Object.entries(SHAPE_FILES)) {
    const b = $(f.button);
    b.disabled = !av.ok || b.dataset.busy === '1';
    b.title = av.ok ? f.title : av.why;
  }
  const wrap = $('spanwise-dl');
  wrap.title = av.ok ? '' : av.why; // a disabled button shows no tooltip in some browsers: its wrapper does
  wrap.dataset.available = av.ok ? 'yes' : 'no';
  return av;
}

/** Fetch ?format=spanwise|bmodes from the daemon and save it as the daemon wrote it. */
async function downloadShapes(format) {
  const R = S.result;
  const f = SHAPE_FILES[format];
  if (!R || !spanwiseControls().ok) return;
  const b = $(f.button);
  b.dataset.busy = '1';
  b.disabled = true;
  dlMsg(`fetching ${f.what}…`);
  let r;
  try {
    r = await api.getResultFile(R.id, format);
  } catch (e) {
    r = {ok: false, message: `cannot reach the daemon: ${e.message}`};
  }
  delete b.dataset.busy;
  spanwiseControls();
  if (!r.ok) {
    dlMsg(`${f.what}: ${r.status ? r.status + ' ' : ''}${r.message}`, 'bad');
    return;
  }
  const name = `${fileBase(R)}-${f.suffix}`;
  S.lastExport = {name, type: r.blob.type, size: r.blob.size};
  saveBlob(r.blob, name);
  dlMsg(`saved ${name} (your downloads)`, 'ok');
}
$('dl-spanwise').addEventListener('click', () => downloadShapes('spanwise'));

/** "Critical speeds (CSV)": the daemon's ?format=critical of a job whose result has critical_speeds. */
function criticalControls() {
  const R = S.result;
  const has = R && Array.isArray(R.result.critical_speeds);
  const job = R && !/^file/.test(R.id);
  const why = !R ? 'no result' : !has ? 'this result has no critical speeds: tick "find critical speeds" (Analysis) and solve'
    : !job ? 'a result opened from a file: the daemon has no job to serve the CSV from' : '';
  const b = $('dl-critical');
  b.disabled = !!why || b.dataset.busy === '1';
  b.title = why || 'The critical speeds as CSV (order, tracked mode, label, Ω in rad/s and rpm, frequency, refined …): ' +
    'GET …/result?format=critical';
  $('critical-dl').title = why;
  $('critical-dl').hidden = !has;
}
$('dl-critical').addEventListener('click', async () => {
  const R = S.result;
  if (!R) return;
  const b = $('dl-critical');
  b.dataset.busy = '1';
  b.disabled = true;
  dlMsg('fetching the critical speeds…');
  let r;
  try {
    r = await api.getResultFile(R.id, 'critical');
  } catch (e) {
    r = {ok: false, message: `cannot reach the daemon: ${e.message}`};
  }
  delete b.dataset.busy;
  criticalControls();
  if (!r.ok) {
    dlMsg(`critical speeds: ${r.status ? r.status + ' ' : ''}${r.message}`, 'bad');
    return;
  }
  const name = `${fileBase(R)}-critical.csv`;
  S.lastExport = {name, type: r.blob.type, size: r.blob.size};
  saveBlob(r.blob, name);
  dlMsg(`saved ${name} (your downloads)`, 'ok');
});
$('dl-bmodes').addEventListener('click', () => downloadShapes('bmodes'));

let spanSeq = 0;

/**
 * For a blade (members in one straight chain) with span-wise shapes: the
 * selected mode's flap, edge and twist against the span fraction, from the
 * daemon's span-wise CSV (fetched once per result).
 */
async function showSpanwisePlot() {
  const seq = ++spanSeq;
  const R = S.result;
  const box = $('spanwise-box');
  const c = selectedCase();
  const k = Number($('mode-index').value) || 0;
  const m = c && c.modes ? c.modes[k] : null;
  const av = R ? spanwiseAvailability(R.id, R.result) : {ok: false};
  const chain = av.ok ? bladeChain(R.result.model.members) : null;
  S.spanPlot = null;
  if (!chain || !m || !m.shape) {
    box.hidden = true;
    return;
  }
  if (!R.spanwise) {
    R.spanwise = api.getResultFile(R.id, 'spanwise')
      .then(async (r) => (r.ok ? {rows: parseSpanwise(await r.blob.text())} : {error: `${r.status} ${r.message}`}))
      .catch((e) => ({error: e.message}));
  }
  const sw = await R.spanwise;
  if (seq !== spanSeq) return; // another mode or result meanwhile
  const cap = $('spanwise-cap');
  box.hidden = false;
  if (sw.error) {
    $('spanwise-svg').textContent = '';
    cap.textContent = `span-wise shapes: ${sw.error}`;
    return;
  }
  const pts = spanPoints(sw.rows, chain, c.omega, k + 1);
  if (!pts.length) {
    box.hidden = true;
    return;
  }
  const ranges = drawSpanwise($('spanwise-svg'), pts);
  S.spanPlot = {omega: c.omega, mode: k + 1, points: pts, ranges};
  cap.textContent = `Span-wise shape of mode ${k + 1} at Ω = ${speedText(c)}: flap (out of the rotor plane) and ` +
    'edge (in it) in m, the mode scaled to 1 m at its largest; twist in rad on the right axis ' +
    `(the span-wise CSV, ${chain.parts.length === 1 ? 'one member' : `${chain.parts.length} members`} root → tip).`;
}

// ------------------------------------------------------------ compare and export

$('keep-ref').addEventListener('click', () => {
  const R = S.result;
  if (!R) return;
  S.ref = {id: R.id, result: R.result, label: `${R.id.slice(0, 8)} (${(R.result.cases || []).length} speeds)`};
  $('keep-ref').textContent = `Reference: ${R.id.slice(0, 8)} — keep this one instead`;
  $('clear-ref').hidden = false;
  updateChart();
});
$('clear-ref').addEventListener('click', () => {
  S.ref = null;
  $('keep-ref').textContent = 'Compare: keep as reference';
  $('clear-ref').hidden = true;
  updateChart();
});

function exportName(what, ext) {
  return `${fileBase()}-${what}.${ext}`;
}

function campbellExportSvg() {
  const u = units();
  // the divergence speeds' bands are added to export.js's drawing (the PNG is this SVG rasterised)
  return divergenceSvg(campbellSvg(chart.plot, chart.last,
    `Campbell diagram (${SPEED_UNITS[u.speed].label}, ${FREQ_UNITS[u.freq].label})`), chart.plot, chart.last);
}

function modeExportSvg() {
  return exportSvg($('mode-svg'), $('mode-desc').textContent.split('. ')[0]);
}

async function exportFile(kind, fmt) {
  if (!S.result || !chart.plot) return;
  const svg = kind === 'campbell' ? campbellExportSvg() : modeExportSvg();
  const name = exportName(kind, fmt);
  const blob = fmt === 'svg' ? new Blob([svg], {type: 'image/svg+xml'}) : await svgToPng(svg);
  S.lastExport = {name, type: blob.type, size: blob.size};
  saveBlob(blob, name);
}
$('campbell-svg').addEventListener('click', () => exportFile('campbell', 'svg'));
$('campbell-png').addEventListener('click', () => exportFile('campbell', 'png'));
$('mode-svg-dl').addEventListener('click', () => exportFile('mode', 'svg'));
$('mode-png-dl').addEventListener('click', () => exportFile('mode', 'png'));

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
  // 'diagram', or 'single' (one speed: the frequencies as a table with bars)
  campbellView: () => $('campbell').dataset.view || '',
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
  warnings: () => S.warnings.map((w) => ({...w})),
  units,
  campbellSvg: () => (chart.plot ? campbellExportSvg() : null),
  modeSvg: () => modeExportSvg(),
  tableCsv: () => $('dl-csv-units').dataset.csv || '',
  lastExport: () => S.lastExport || null,
  // the span-wise downloads ({available, why}) and the plotted span-wise shape ({omega, mode, points} or null)
  spanwise: () => ({available: $('spanwise-dl').dataset.available === 'yes', why: $('spanwise-dl').title,
    buttons: ['dl-spanwise', 'dl-bmodes'].map((id) => ({id, disabled: $(id).disabled, title: $(id).title})),
    plot: S.spanPlot || null}),
  loadExample,
  loadDoc,
};

const reduce = window.matchMedia && window.matchMedia('(prefers-reduced-motion: reduce)').matches;
// the design of the last visit, else the first example
const kept = stored();
let keptDoc = null;
try {
  keptDoc = kept ? JSON.parse(kept) : null;
} catch {
  keptDoc = null;
}
if (keptDoc && typeof keptDoc === 'object') {
  loadDoc(keptDoc, 'Your request from the last visit (kept in this browser)' +
    (typeof keptDoc.name === 'string' ? `: “${keptDoc.name}”.` : '.'));
  fileMsg('your request from the last visit (kept in this browser)', 'ok');
} else if (kept && kept.trim()) {
  loadExample('angled-90');
  setText(kept); // half-typed JSON: shown as it was, with its syntax error
  $('json').dispatchEvent(new Event('input'));
} else {
  loadExample('angled-90');
}
setRunning(!reduce);
