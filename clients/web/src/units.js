// units.js — the results in the units shown: the speed (rad/s | rpm) and
// frequency (rad/s | Hz | per rev) pickers above the results, values as text
// in those units, the frequency table as rows (the table and the "CSV (units
// shown)" download), and the units remembered per kind of request
// (localStorage spinmodal.units).

import {sig, SPEED_UNITS, FREQ_UNITS} from './request.js';
import {freqIn, errIn} from './campbell.js';
import {$} from './dom.js';
import {S} from './state.js';

/** The display units of the results: {speed: 'rad' | 'rpm', freq: 'rad' | 'hz' | 'rev'}. */
export function units() {
  return {speed: $('speed-unit').value, freq: $('freq-unit').value};
}

/** A case's speed as text in the speed unit shown: "20 rad/s", "190.986 rpm". */
export function speedText(c, n = 6) {
  const su = units().speed;
  const v = su === 'rpm' ? (typeof c.rpm === 'number' ? c.rpm : c.omega * 60 / (2 * Math.PI)) : c.omega;
  return `${sig(v, n)} ${SPEED_UNITS[su].label}`;
}

/** A mode's frequency as text in the frequency unit shown. */
export function freqText(m, c, n = 6) {
  const fu = units().freq;
  const v = freqIn(fu, m, c.omega);
  return v === null ? '–' : `${sig(v, n)} ${FREQ_UNITS[fu].label}`;
}

/** "Ω = 8, 10 rad/s" or "Ω = 8…18 rad/s (6 speeds)" for the cases cs. */
export function speedsText(cs) {
  const su = units().speed, u = SPEED_UNITS[su].label;
  const v = cs.map((c) => (su === 'rpm' ? (typeof c.rpm === 'number' ? c.rpm : c.omega * 60 / (2 * Math.PI)) : c.omega));
  if (v.length <= 4) return `Ω = ${v.map((x) => sig(x)).join(', ')} ${u}`;
  return `${v.length} speeds (Ω = ${sig(Math.min(...v))}…${sig(Math.max(...v))} ${u})`;
}

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
export function applyUnits(request) {
  const kind = speedKind(request);
  const pref = unitPrefs()[kind] || {};
  const want = {...UNIT_DEFAULTS[kind]};
  if (pref.speed in SPEED_UNITS) want.speed = pref.speed;
  if (pref.freq in FREQ_UNITS) want.freq = pref.freq;
  $('speed-unit').value = want.speed;
  $('freq-unit').value = want.freq;
}

/** The user picked a unit: remember it for the results of this kind of request. */
export function rememberUnits() {
  if (!S.result) return;
  const all = unitPrefs();
  all[speedKind(S.result.request)] = units();
  try {
    localStorage.setItem(UNITS_KEY, JSON.stringify(all));
  } catch {
    /* storage disabled: the choice holds for this page only */
  }
}

/** The frequency table in the units shown: [[header…], [row…]…] (also the "CSV (units shown)" download). */
export function tableRows(result) {
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
