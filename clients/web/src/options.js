// options.js — the Analysis panel: speeds (one, a sweep, a list; in rad/s
// or rpm, converted when switched), frames, basis, mass, modes, Coriolis,
// stiffening, mode shapes, critical speeds (the engine orders, one list with
// the Campbell diagram's) and the error estimate, shown from S.doc.analysis
// by renderOptions and written back into it as they are edited.  The editor
// (design.js) passes the function that rebuilds the JSON text.

import {DEFAULTS, speedsForm, speedsValue, cellValue, fmtNum, speedList, convertSpeed, rangeOf} from './request.js';
import {parseOrders} from './campbell.js';
import {$} from './dom.js';
import {S} from './state.js';
import {showUnits} from './results.js';
import {updateChart} from './campbell-panel.js';

/** design.js docChanged: the options changed, rebuild the doc's JSON text (set by initOptions). */
let docChanged = () => {};

function an() {
  if (!S.doc.analysis || typeof S.doc.analysis !== 'object' || Array.isArray(S.doc.analysis)) S.doc.analysis = {};
  return S.doc.analysis;
}

function optValue(key) {
  const a = S.doc.analysis && typeof S.doc.analysis === 'object' ? S.doc.analysis : {};
  return key in a ? a[key] : DEFAULTS.analysis[key];
}

let speedMode = 'single';

export function renderOptions() {
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

function framesChanged() {
  showFramesN();
  const s = $('frames').value;
  S.doc.frames = s === 'per_member' || s === 'elements_per_frame' ? {[s]: cellValue($('frames-n').value || '2')} : s;
  if ((s === 'per_member' || s === 'elements_per_frame') && !$('frames-n').value) $('frames-n').value = '2';
  docChanged('options');
}

function bindOpt(id, key, read) {
  const e = $(id);
  e.addEventListener(e.type === 'checkbox' || e.tagName === 'SELECT' ? 'change' : 'input', () => {
    const v = read(e);
    if (v === undefined) delete an()[key];
    else an()[key] = v;
    docChanged('options');
  });
}

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

/** Wire the Analysis panel; onDocChanged('options') rebuilds the JSON text from S.doc. */
export function initOptions(onDocChanged) {
  docChanged = onDocChanged;
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

  $('frames').addEventListener('change', framesChanged);
  $('frames-n').addEventListener('input', framesChanged);

  bindOpt('basis', 'substructure_modes', (e) => e.value);
  bindOpt('mass', 'mass', (e) => e.value);
  bindOpt('modes', 'modes', (e) => cellValue(e.value));
  bindOpt('modes-per-frame', 'modes_per_frame', (e) => (e.value.trim() === '' || e.value.trim() === 'all' ? 'all' : cellValue(e.value)));
  bindOpt('coriolis', 'coriolis', (e) => e.checked);
  bindOpt('stiffening', 'geometric_stiffening', (e) => e.checked);
  bindOpt('mode-shapes', 'mode_shapes', (e) => e.checked);
  // only when ticked: without it the key is absent and the job id is that of before (DESIGN.md 9.4)
  bindOpt('error-estimate', 'error_estimate', (e) => (e.checked ? true : undefined));

  $('critical').addEventListener('change', () => {
    if ($('critical').checked) an().engine_orders = parseOrders($('eo-orders').value);
    else delete an().engine_orders;
    docChanged('options');
  });
  $('eo-orders').addEventListener('input', () => ordersChanged('eo-orders'));
  $('eo-list').addEventListener('input', () => ordersChanged('eo-list'));
}
