// downloads.js — the files a result offers: links for text made in the page
// (the "CSV (units shown)"), the daemon's span-wise, BModes-style and
// critical-speed files (offered only where the daemon has them, else
// disabled saying why), and the Campbell diagram and mode shape as SVG or PNG
// (export.js draws them).

import {SPEED_UNITS, FREQ_UNITS} from './request.js';
import {divergenceSvg} from './campbell.js';
import {exportSvg, svgToPng, campbellSvg, saveBlob} from './export.js';
import {spanwiseAvailability} from './spanwise.js';
import * as api from './api.js';
import {$} from './dom.js';
import {S, fileBase} from './state.js';
import {units, tableRows} from './units.js';
import {chart} from './campbell-panel.js';

/** A download link for text made in the page. */
export function setBlobLink(a, name, type, text) {
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
export function tableCsv() {
  const R = S.result;
  if (!R) return;
  const {head, rows} = tableRows(R.result);
  const u = units();
  const text = [head, ...rows].map((r) => r.map(csvCell).join(',')).join('\n') + '\n';
  setBlobLink($('dl-csv-units'), `${fileBase(R)}-${u.speed}-${u.freq}.csv`, 'text/csv', text);
  $('dl-csv-units').dataset.csv = text;
}

// ------------------------------------------------------------ the daemon's files

const SHAPE_FILES = {
  spanwise: {button: 'dl-spanwise', suffix: 'spanwise.csv', what: 'span-wise shapes',
    title: 'Flap, edge, their slopes, twist and axial motion of every mode along each member, each mode scaled to ' +
      '1 m at its largest (GET …/result?format=spanwise)'},
  bmodes: {button: 'dl-bmodes', suffix: 'bmodes.txt', what: 'the BModes-style table',
    title: 'The span-wise shapes in the layout of BModes\' .out: span_loc, flap disp, flap slope, lag disp, lag slope, ' +
      'twist, with BModes\' signs (GET …/result?format=bmodes)'},
};

export function dlMsg(text, cls = '') {
  const m = $('dl-msg');
  m.textContent = text;
  m.className = 'dl-msg ' + cls;
}

/** Offer the span-wise downloads only for a result the daemon has them for (else disabled, saying why). */
export function spanwiseControls() {
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
/** "Critical speeds (CSV)": the daemon's ?format=critical of a job whose result has critical_speeds. */
export function criticalControls() {
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

// ------------------------------------------------------------ SVG and PNG

function exportName(what, ext) {
  return `${fileBase()}-${what}.${ext}`;
}

export function campbellExportSvg() {
  const u = units();
  // the divergence speeds' bands are added to export.js's drawing (the PNG is this SVG rasterised)
  return divergenceSvg(campbellSvg(chart.plot, chart.last,
    `Campbell diagram (${SPEED_UNITS[u.speed].label}, ${FREQ_UNITS[u.freq].label})`), chart.plot, chart.last);
}

export function modeExportSvg() {
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

/** Wire the download and export buttons. */
export function initDownloads() {
  $('dl-spanwise').addEventListener('click', () => downloadShapes('spanwise'));
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
  $('campbell-svg').addEventListener('click', () => exportFile('campbell', 'svg'));
  $('campbell-png').addEventListener('click', () => exportFile('campbell', 'png'));
  $('mode-svg-dl').addEventListener('click', () => exportFile('mode', 'svg'));
  $('mode-png-dl').addEventListener('click', () => exportFile('mode', 'png'));
}
