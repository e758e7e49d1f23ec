// state.js — the page's one state object S (the request being edited, the
// job followed, the result shown, the animation and the 3D camera), the
// accessors every view shares (the case selected, the file names of a
// result) and the design kept across reloads (localStorage).  The modules
// import S from here; nothing else holds page state except each module's own
// private bookkeeping (timers, caches, sequence numbers).

import {homeCamera} from './view3d.js';
import {$} from './dom.js';

export const S = {
  doc: {},             // the request as last parsed
  rows: null,          // editable rows of doc.structure
  text: '',            // the JSON text (validated and submitted)
  parseError: null,    // JSON.parse message of the text, if it does not parse
  localErrors: [],     // errors found in the page: [{pointer | el, message}]
  serverErrors: [],    // errors from the daemon: [{pointer, message}]
  serverErrorsFrom: '', // 'validate' | 'submit'
  warnings: [],        // input_warnings of the last validation or result: [{pointer, message}]
  blade: false,        // the request is in the blade form (DESIGN.md 8.1)
  tower: false,        // the request is in the tower form (DESIGN.md 8.5)
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
  sweepError: null,    // the sweep fields' error found in the page: {message, el}
  validated: null,     // the text /v1/validate last found valid
  submitted: null,     // {id, request} of the job last submitted or reopened
  lastExport: null,    // {name, type, size} of the last file saved from the page
  spanPlot: null,      // the span-wise shape plotted: {omega, mode, points, ranges}
};

const STORE_KEY = 'spinmodal.request';

/** Keep the editor's text across reloads (localStorage; nothing leaves the browser). */
export function persist() {
  try {
    localStorage.setItem(STORE_KEY, S.text);
  } catch {
    /* storage full or disabled: the design lives in the page only */
  }
}

/** The text kept by persist (null when there is none or storage is disabled). */
export function stored() {
  try {
    return localStorage.getItem(STORE_KEY);
  } catch {
    return null;
  }
}

/** A name as a part of a file name: letters, digits, - _ . kept, the rest _, at most 60 characters. */
export function fileSafe(name) {
  return String(name).normalize('NFKD').replace(/[\u0300-\u036f]/g, '').replace(/[^A-Za-z0-9._-]+/g, '_')
    .replace(/^[._]+|_+$/g, '').slice(0, 60);
}

/** The start of a result's file names: spinmodal-<name>-<id:12> (spinmodal-<id:12> without a name). */
export function fileBase(R = S.result) {
  const id = R ? R.id.slice(0, 12) : 'x';
  const n = R && R.request && typeof R.request.name === 'string' ? fileSafe(R.request.name) : '';
  return n ? `spinmodal-${n}-${id}` : `spinmodal-${id}`;
}

/** The case of the result shown that the mode list selects (null without a result). */
export function selectedCase() {
  const R = S.result;
  if (!R) return null;
  const i = Number($('mode-speed').value);
  return R.result.cases[Number.isInteger(i) ? i : 0] || null;
}
