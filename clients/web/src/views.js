// views.js — the drawings: the structure (in the hub plane, drawing.js, or
// in 3D, view3d.js) with the steady shape of the case selected, the 3D switch,
// camera presets and orbit shared by both drawings, the animated mode shape
// of the case and mode selected, and a blade's span-wise shape plot under it.

import {DEFAULTS, sig, isSpatial, structureOf, FREQ_UNITS} from './request.js';
import {buildMesh} from './mesh.js';
import {drawStructure, modeView} from './drawing.js';
import {drawStructure3d, modeView3d, attachOrbit, homeCamera, PRESETS} from './view3d.js';
import {errIn, campbellData} from './campbell.js';
import {spanwiseAvailability, parseSpanwise, bladeChain, spanPoints, drawSpanwise} from './spanwise.js';
import {showCoefficients} from './coeffs.js';
import * as api from './api.js';
import {$, plural} from './dom.js';
import {S, selectedCase} from './state.js';
import {units, speedText, freqText} from './units.js';

// --------------------------------------------------------------- drawing

let meshCache = {key: '', mesh: null};

function meshOf(doc) {
  const st = structureOf(doc);
  const key = JSON.stringify([st, doc.frames]);
  if (meshCache.key !== key) meshCache = {key, mesh: buildMesh(st, 'frames' in doc ? doc.frames : DEFAULTS.frames)};
  return meshCache.mesh;
}

export function draw() {
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

// ------------------------------------------------------------- 3D view

/** Is the structure drawn in 3D?  The switch, else whether the structure is spatial. */
function structureIn3d() {
  return S.view3d ?? (S.blade || S.tower || !!(S.rows && S.rows.spatial));
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

/** The drawings' controls: what they show, the 3D switch, the camera, the mode list and animation. */
export function initViews() {
  for (const id of ['show-frames', 'show-nodes', 'show-equilibrium']) $(id).addEventListener('change', draw);
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
  $('mode-play').addEventListener('click', () => setRunning(!S.anim.running));
  $('mode-speed').addEventListener('change', () => {
    modeSelectors();
    startMode();
    draw();
  });
  $('mode-index').addEventListener('change', startMode);
  $('mode-amp').addEventListener('input', startMode);
}

// ---------------------------------------------------------- mode animation

export function modeSelectors() {
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

export function startMode() {
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

export function setRunning(on) {
  S.anim.running = on;
  const b = $('mode-play');
  b.textContent = on ? 'Pause' : 'Play';
  b.setAttribute('aria-pressed', on ? 'true' : 'false');
  if (on && !S.anim.raf) S.anim.raf = requestAnimationFrame(tick);
}

// ------------------------------------------------------------ span-wise shape

let spanSeq = 0;

/**
 * For a blade (members in one straight chain) with span-wise shapes: the
 * selected mode's flap, edge and twist against the span fraction, from the
 * daemon's span-wise CSV (fetched once per result).
 */
async function showSpanwisePlot() {
  showCoefficients();
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
  const tower = !!(R.request && R.request.tower);
  const ranges = drawSpanwise($('spanwise-svg'), pts, tower ? {flap: 'fore-aft (m)', edge: 'side-side (m)'} : {});
  S.spanPlot = {omega: c.omega, mode: k + 1, points: pts, ranges};
  cap.textContent = (tower ? `Shape of mode ${k + 1} along the tower (base 0 → top 1): fore-aft and side-side `
    : `Span-wise shape of mode ${k + 1} at Ω = ${speedText(c)}: flap (out of the rotor plane) and edge (in it) `) +
    'in m, the mode scaled to 1 m at its largest; twist in rad on the right axis ' +
    `(the span-wise CSV, ${chain.parts.length === 1 ? 'one member' : `${chain.parts.length} members`} root → tip).`;
}
