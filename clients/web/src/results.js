// results.js — the result shown: showResult takes a job's (or a file's)
// result, its request and status document into S.result and fills the
// results panel (summary with the wall time, one note per distinct failure
// or warning, the frequency table, the Campbell diagram, the mode lists,
// the downloads); showUnits redraws what depends on the units picked.

import {DEFAULTS, sig, structureOf, SPEED_UNITS, FREQ_UNITS} from './request.js';
import {buildMesh} from './mesh.js';
import {flaggedCase} from './campbell.js';
import * as api from './api.js';
import {$, plural} from './dom.js';
import {S, fileBase} from './state.js';
import {units, speedText, speedsText, applyUnits, rememberUnits, tableRows} from './units.js';
import {showErrors} from './errors.js';
import {draw, modeSelectors, startMode} from './views.js';
import {updateChart} from './campbell-panel.js';
import {setBlobLink, dlMsg, spanwiseControls, criticalControls, tableCsv} from './downloads.js';

/** Say so when the results shown are for another request than the editor's. */
export function markStale() {
  const R = S.result;
  // the name is no part of what was solved (nor of the job id)
  const solved = (d) => JSON.stringify(d && typeof d === 'object' ? {...d, name: undefined} : d);
  $('result-stale').hidden = !R || solved(R.request) === solved(S.doc);
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
export function showResult(id, request, result, job = null) {
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
export function showUnits() {
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

/** The frequency table in the units shown (speeds with a warning greyed, ± and labels where the result has them). */
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

/** Wire the unit pickers: a unit picked is remembered and the results redrawn in it. */
export function initResults() {
  for (const id of ['freq-unit', 'speed-unit']) {
    $(id).addEventListener('change', () => {
      rememberUnits();
      showUnits();
    });
  }
}
