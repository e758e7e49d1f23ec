// coeffs.js — ElastoDyn mode-shape coefficients of a solved blade or tower
// (DESIGN.md 9.3): the daemon's text (GET …/result?format=elastodyn, the
// bytes of `spinmodal export elastodyn`) parsed into a table, five
// coefficients C2…C6 per shape (they sum to 1: φ(1) = 1), and a plot of the
// fitted polynomial Σ C_k x^k (k = 2…6) over 0…1 against the computed shape
// of the same mode (the span-wise CSV of spanwise.js, less the root's value,
// divided by the tip value).  The page asks only where the daemon can answer
// (a spatial result with mode shapes of one member, or of a member "blade"),
// so no request of it is a 409.

import * as api from './api.js';
import {parseSpanwise, bladeChain, spanPoints, spanwiseAvailability} from './spanwise.js';
import {sig} from './request.js';
import {$} from './dom.js';
import {S, selectedCase} from './state.js';

const NS = 'http://www.w3.org/2000/svg';

/**
 * The daemon's ElastoDyn text as [{case, fits: [{name, mode, freqHz, label,
 * coeffs: [C2…C6], note}]}]; a fit without a mode has coeffs [] and the note.
 */
export function parseElastodyn(text) {
  const cases = [];
  let cur = null;
  const fit = (name) => {
    if (!cur) cases.push(cur = {case: 1, fits: []});
    let f = cur.fits.find((x) => x.name === name);
    if (!f) cur.fits.push(f = {name, mode: null, freqHz: null, label: '', coeffs: [], note: ''});
    return f;
  };
  for (const line of text.split(/\r?\n/)) {
    let m = /^! case (\d+) of \d+/.exec(line);
    if (m) {
      cases.push(cur = {case: Number(m[1]), fits: []});
      continue;
    }
    m = /^! (\w+Sh): (.*)$/.exec(line);
    if (m) {
      const f = fit(m[1]);
      const d = /^mode (\d+) \(([^ ]+) Hz, ([^)]*)\)/.exec(m[2]);
      if (d) Object.assign(f, {mode: Number(d[1]), freqHz: Number(d[2]), label: d[3]});
      else f.note = m[2];
      continue;
    }
    m = /^\s*(\S+)\s+(\w+Sh)\((\d)\)/.exec(line);
    if (m) fit(m[2]).coeffs[Number(m[3]) - 2] = Number(m[1]);
  }
  return cases;
}

/** φ(x) = Σ C_k x^k, k = 2…6. */
export const poly = (c, x) => c.reduce((s, ck, i) => s + ck * x ** (i + 2), 0);

/** Can the daemon give coefficients for this result (so the page asks)? */
function available(R) {
  if (!R || !spanwiseAvailability(R.id, R.result).ok) return false;
  const ms = R.result.model.members;
  return ms.length === 1 || ms.some((m) => m.id === 'blade');
}

/** The fore-aft / flap shapes use the flap column, the side-side / edge ones the edge column. */
const column = (name) => (/^TwFA|^BldFl/.test(name) ? 'flap' : 'edge');

function el(name, attrs, parent) {
  const e = document.createElementNS(NS, name);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  parent.append(e);
  return e;
}

/** Draw the fitted polynomial (line) and the computed shape (line with dots) over 0…1. */
function drawFit(svg, c, pts) {
  svg.textContent = '';
  const W = 600, H = 200, L = 46, R = 14, T = 24, B = 30;
  const fitPts = Array.from({length: 101}, (_, i) => ({x: i / 100, y: poly(c, i / 100)}));
  const ys = fitPts.concat(pts).map((p) => p.y);
  let lo = Math.min(0, ...ys), hi = Math.max(1, ...ys);
  const pad = 0.06 * (hi - lo);
  lo -= pad;
  hi += pad;
  const X = (x) => L + x * (W - L - R), Y = (y) => T + (hi - y) / (hi - lo) * (H - T - B);
  el('rect', {x: L, y: T, width: W - L - R, height: H - T - B, class: 'sw-frame'}, svg);
  for (const x of [0, 0.25, 0.5, 0.75, 1]) {
    el('line', {x1: X(x), x2: X(x), y1: T, y2: H - B, class: 'sw-grid'}, svg);
    el('text', {x: X(x), y: H - B + 14, class: 'sw-tick', 'text-anchor': 'middle'}, svg).textContent = String(x);
  }
  const raw = (hi - lo) / 4, p10 = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((k) => k * p10).find((v) => v >= raw);
  const yt = [];
  for (let y = Math.ceil(lo / step) * step; y <= hi; y += step) yt.push(Number(y.toPrecision(6)));
  for (const y of yt) {
    el('line', {x1: L, x2: W - R, y1: Y(y), y2: Y(y), class: y === 0 ? 'sw-zero' : 'sw-grid'}, svg);
    el('text', {x: L - 5, y: Y(y) + 4, class: 'sw-tick', 'text-anchor': 'end'}, svg).textContent = String(y);
  }
  const line = (p, cls, series) => el('polyline', {class: 'sw-line ' + cls, 'data-series': series,
    points: p.map((q) => `${X(q.x).toFixed(2)},${Y(q.y).toFixed(2)}`).join(' ')}, svg);
  line(pts, 'sw-edge', 'computed');
  for (const p of pts) el('circle', {cx: X(p.x).toFixed(2), cy: Y(p.y).toFixed(2), r: 2.2, class: 'cf-dot'}, svg);
  line(fitPts, 'sw-flap cf-fit', 'fit');
  el('line', {x1: L, x2: L + 22, y1: 12, y2: 12, class: 'sw-line sw-flap cf-fit'}, svg);
  el('text', {x: L + 27, y: 16, class: 'sw-legend'}, svg).textContent = 'fit Σ C_k x^k';
  el('line', {x1: L + 150, x2: L + 172, y1: 12, y2: 12, class: 'sw-line sw-edge'}, svg);
  el('text', {x: L + 177, y: 16, class: 'sw-legend'}, svg).textContent = 'computed (FE nodes)';
}

/** The table: one row a shape, its mode, C2…C6 and their sum. */
function renderTable(fits) {
  const t = $('coeffs-table');
  t.tHead.innerHTML = '<tr><th scope="col">shape</th><th scope="col">mode</th>' +
    [2, 3, 4, 5, 6].map((k) => `<th scope="col">C${k}</th>`).join('') + '<th scope="col">sum</th></tr>';
  const tb = t.tBodies[0];
  tb.textContent = '';
  for (const f of fits) {
    const tr = tb.insertRow();
    tr.dataset.shape = f.name;
    const cells = f.coeffs.length === 5
      ? [f.name, `${f.mode} (${f.label}, ${sig(f.freqHz, 5)} Hz)`, ...f.coeffs.map(String),
        String(Number(f.coeffs.reduce((a, b) => a + b, 0).toPrecision(12)))]
      : [f.name, f.note];
    for (const v of cells) tr.insertCell().textContent = v;
    if (f.coeffs.length !== 5) tr.cells[1].colSpan = 7;
  }
}

let seq = 0;

/** Show (or hide) the coefficients of the result shown, for the case selected. */
export async function showCoefficients() {
  const my = ++seq;
  const R = S.result, c = selectedCase(), box = $('coeffs-box');
  S.coeffs = null;
  if (!available(R) || !c) {
    box.hidden = true;
    return;
  }
  R.elastodyn ||= api.getResultFile(R.id, 'elastodyn')
    .then(async (r) => (r.ok ? {cases: parseElastodyn(await r.blob.text())} : {error: `${r.status} ${r.message}`}))
    .catch((e) => ({error: e.message}));
  R.spanwise ||= api.getResultFile(R.id, 'spanwise')
    .then(async (r) => (r.ok ? {rows: parseSpanwise(await r.blob.text())} : {error: `${r.status} ${r.message}`}))
    .catch((e) => ({error: e.message}));
  const [ed, sw] = await Promise.all([R.elastodyn, R.spanwise]);
  if (my !== seq) return;
  box.hidden = false;
  const k = R.result.cases.indexOf(c) + 1;
  const block = ed.cases ? ed.cases.find((x) => x.case === k) : null;
  if (!block) {
    renderTable([]);
    $('coeffs-svg').textContent = '';
    $('coeffs-cap').textContent = `coefficients: ${ed.error || `none for case ${k}`}`;
    return;
  }
  renderTable(block.fits);
  const fits = block.fits.filter((f) => f.coeffs.length === 5);
  const sel = $('coeffs-fit'), was = sel.value;
  sel.textContent = '';
  for (const f of fits) sel.append(new Option(`${f.name}: mode ${f.mode} (${f.label})`, f.name));
  if (fits.some((f) => f.name === was)) sel.value = was;
  const f = fits.find((x) => x.name === sel.value);
  const chain = bladeChain(R.result.model.members);
  const raw = f && chain && sw.rows ? spanPoints(sw.rows, chain, c.omega, f.mode) : [];
  const col = f ? column(f.name) : 'flap';
  const y0 = raw.length ? raw[0][col] : 0, tip = raw.length ? raw[raw.length - 1][col] - y0 : 0;
  const pts = tip ? raw.map((p) => ({x: p.x, y: (p[col] - y0) / tip})) : [];
  S.coeffs = {case: k, fits: block.fits.map((x) => ({...x, coeffs: x.coeffs.slice()})), plotted: f ? f.name : null,
    points: pts, maxDiff: pts.length ? Math.max(...pts.map((p) => Math.abs(p.y - poly(f.coeffs, p.x)))) : null};
  if (!f || !pts.length) {
    $('coeffs-svg').textContent = '';
    $('coeffs-cap').textContent = f ? `no span-wise shape of mode ${f.mode} to compare (${sw.error || 'none'})` : '';
    return;
  }
  drawFit($('coeffs-svg'), f.coeffs, pts);
  $('coeffs-cap').textContent = `${f.name}: mode ${f.mode} (${f.label}), the fitted polynomial against the computed ` +
    `${col === 'flap' ? (R.request.tower ? 'fore-aft' : 'flap') : (R.request.tower ? 'side-side' : 'edge')} shape ` +
    `(less the root's value, over the tip's), x from the root 0 to the tip 1; largest difference at the nodes ` +
    `${sig(S.coeffs.maxDiff, 2)} of the tip. The daemon's ?format=elastodyn text` +
    `${R.request.tower ? '' : ' (a blade\'s shapes in the twisted principal axes, the plotted ones untwisted)'}.`;
}

/** Wire the shape selector. */
export function initCoefficients() {
  $('coeffs-fit').addEventListener('change', showCoefficients);
}
