// main.js — the spinmodal front end: structure editor + JSON view kept in
// sync and validated as the user types, analysis options, job submission
// with progress and cancel, results (frequency table, Campbell diagram, mode
// animation, downloads).  Served by spinmodald at / (server/DAEMON.md).
// Planar structures are drawn in the hub plane (drawing.js); spatial ones
// (DESIGN.md 7) in a 3D view the user turns (view3d.js), shared by the
// structure drawing and the mode animation.
//
// The page is split by concern, each module importing what it uses (the
// state object S from state.js) and exporting an init function that wires
// its controls; this file calls them in order and starts the page:
//   state.js (S, kept design, file names)   dom.js ($, plural)
//   design.js (the request <-> tables, JSON, blade panel, examples)
//   tower.js, tower-model.js, stations.js (the tower form; stations tables)
//   coeffs.js (ElastoDyn coefficients of a blade or tower, fit vs computed)
//   options.js (Analysis panel)   errors.js (errors, warnings, /v1/validate)
//   views.js (structure drawing, 3D camera, mode animation, span-wise plot)
//   jobs.js (Solve, progress, Cancel, past jobs)   files.js (open, save, import)
//   results.js (result shown, frequency table)   units.js (units shown)
//   campbell-panel.js (Campbell diagram, crossings, critical and divergence
//   tables, compare)   downloads.js (result files, SVG and PNG exports)

import './style.css';
import * as api from './api.js';
import {$} from './dom.js';
import {S, stored} from './state.js';
import {units} from './units.js';
import {initDesign, loadExample, loadDoc, setText} from './design.js';
import {initViews, setRunning} from './views.js';
import {initJobs} from './jobs.js';
import {chart, initCampbell} from './campbell-panel.js';
import {initResults} from './results.js';
import {fileMsg, initFiles} from './files.js';
import {initCoefficients} from './coeffs.js';
import {campbellExportSvg, modeExportSvg, initDownloads} from './downloads.js';

initDesign();
initViews();
initJobs();
initCampbell();
initResults();
initFiles();
initDownloads();
initCoefficients();

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
  // the ElastoDyn coefficients shown ({case, fits: [{name, mode, label, coeffs}], plotted, points, maxDiff} or null)
  coeffs: () => S.coeffs || null,
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
