// campbell-panel.js — the Campbell diagram of the result shown (campbell.js
// draws it): the engine orders typed, the reference result overlaid
// ("Compare"), the fitted frequency axis and its note, the error-bar note,
// and the tables beside it: crossings with the orders, the daemon's critical
// speeds and divergence speeds, in the units shown.

import {sig, SPEED_UNITS, FREQ_UNITS} from './request.js';
import {campbellChart, parseOrders, COLORS, divergenceSpeeds} from './campbell.js';
import {getMac} from './api.js';
import {$, plural} from './dom.js';
import {S} from './state.js';
import {units} from './units.js';

/** The chart (campbell.js campbellChart), made by initCampbell. */
export let chart = null;

/** Make the chart and wire its buttons (all modes, reset zoom, compare). */
export function initCampbell() {
  chart = campbellChart($('campbell'), (last) => errbarNote(last));
  $('campbell-all').addEventListener('click', () => {
    S.allModes = !S.allModes;
    updateChart();
  });
  $('zoom-reset').addEventListener('click', updateChart);
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
}

/** Redraw the Campbell diagram and the tables beside it for the result shown (nothing without one). */
export function updateChart() {
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
  macTable(ref ? S.result.id : null, ref ? S.ref.id : null);
}

let macShown = ''; // "id|ref" of the table shown (or asked for)

/**
 * The MAC table between the modes of the result shown (rows) and the reference (columns), from
 * the daemon (GET /v1/analyses/{id}/mac?with=REF, DESIGN.md 9.2), asked once per pair; the
 * reason instead when they cannot be compared (another structure, no mode shapes).
 */
async function macTable(id, refId) {
  const key = id && refId ? `${id}|${refId}` : '';
  if (key === macShown) return;
  macShown = key;
  $('mac-table').hidden = true;
  $('mac-note').hidden = true;
  if (!key) return;
  let ans;
  try {
    ans = await getMac(id, refId);
  } catch (e) {
    ans = {ok: false, message: String(e.message || e)};
  }
  if (macShown !== key) return; // another pair was asked for meanwhile
  if (!ans.ok) {
    $('mac-note').textContent = `No MAC table against the reference: ${ans.message}`;
    $('mac-note').hidden = false;
    return;
  }
  const d = ans.doc;
  const head = $('mac-head');
  head.textContent = '';
  const th0 = document.createElement('th');
  th0.scope = 'col';
  th0.textContent = 'mode (Hz)';
  head.appendChild(th0);
  (d.b.frequency_hz || []).forEach((f, j) => {
    const th = document.createElement('th');
    th.scope = 'col';
    th.textContent = `${j + 1} (${sig(f, 4)})`;
    head.appendChild(th);
  });
  const tb = $('mac-table').tBodies[0];
  tb.textContent = '';
  d.mac.forEach((row, i) => {
    const tr = tb.insertRow();
    const lab = (d.a.labels || [])[i];
    tr.insertCell().textContent = `${i + 1} ${lab || ''} (${sig(d.a.frequency_hz[i], 4)})`;
    row.forEach((v, j) => {
      const td = tr.insertCell();
      td.textContent = v.toFixed(3);
      if (d.best[i] && d.best[i].b === j + 1) td.style.fontWeight = 'bold';
    });
  });
  $('mac-caption').textContent = `MAC against the reference (first speed of each; ${d.matching.replace('_', ' ')}; bold: the best match of each mode)`;
  $('mac-table').hidden = false;
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
