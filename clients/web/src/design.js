// design.js — the request being edited: S.doc and its JSON text kept in sync
// with the structure tables (editor.js), the JSON textarea, the design name,
// the blade panel (a request in the blade form) and the Analysis panel
// (options.js); each change is kept (localStorage), checked, drawn and
// validated.  Also the examples and loadDoc, which puts a request from a
// file, an import or a past job into the editor.

import {prettyJSON, structureToRows, rowsToStructure, cellValue, fmtNum} from './request.js';
import {renderStations} from './stations.js';
import {renderTower, initTower} from './tower.js';
import {homeCamera} from './view3d.js';
import {StructureEditor} from './editor.js';
import {EXAMPLES} from './examples.js';
import {$} from './dom.js';
import {S, persist} from './state.js';
import {computeLocalErrors, showErrors, scheduleValidate} from './errors.js';
import {draw} from './views.js';
import {markStale} from './results.js';
import {renderOptions, initOptions} from './options.js';

/** The structure tables (editor.js), made by initDesign. */
let editor = null;

/** Put doc into the editor; from names the control it came from, which is not redrawn. */
function setDoc(doc, from) {
  S.doc = doc && typeof doc === 'object' && !Array.isArray(doc) ? doc : {};
  if (from !== 'options') S.sweepError = null;
  S.blade = 'blade' in S.doc && !('structure' in S.doc);
  S.tower = 'tower' in S.doc && !('structure' in S.doc) && !S.blade;
  S.rows = structureToRows(S.doc.structure);
  if (from !== 'name') $('design-name').value = typeof S.doc.name === 'string' ? S.doc.name : '';
  if (from !== 'table') editor.render();
  if (from !== 'blade') renderBlade();
  if (from !== 'tower') renderTower();
  if (from !== 'options') renderOptions();
  if (from !== 'json') setText(prettyJSON(S.doc));
  afterChange();
}

/** Show t as the request's JSON text (S.text), leaving the textarea alone when it already holds t. */
export function setText(t) {
  S.text = t;
  S.parseError = null;
  const ta = $('json');
  if (ta.value !== t) ta.value = t;
}

/** Rows or options changed: rebuild the doc and the JSON text. */
function docChanged(from) {
  if (!S.blade && !S.tower) S.doc.structure = rowsToStructure(S.rows);
  setText(prettyJSON(S.doc));
  if (from === 'rows') editor.render();
  afterChange();
}

/** After any edit: keep the text, check it, redraw, validate it with the daemon, show errors, mark the results stale. */
function afterChange() {
  persist();
  computeLocalErrors();
  draw();
  scheduleValidate();
  showErrors();
  markStale();
}

// ------------------------------------------------------------- blade form

/** Show the blade panel (fields, stations) instead of the structure tables for a request in the blade form. */
function renderBlade() {
  $('blade-panel').hidden = !S.blade;
  $('structure-tables').hidden = S.blade || S.tower;
  document.querySelector('.spatial-switch').hidden = S.blade || S.tower;
  if (!S.blade) return;
  const b = S.doc.blade && typeof S.doc.blade === 'object' ? S.doc.blade : {};
  for (const e of document.querySelectorAll('#blade-panel .blade-fields input[data-key]')) {
    e.value = fmtNum(b[e.dataset.key]);
  }
  $('blade-tip-mass').value = b.tip_mass && typeof b.tip_mass === 'object' ? fmtNum(b.tip_mass.mass) : '';
  const n = renderStations($('stations'), 'blade', b.stations);
  $('stations-count').textContent = n ? `(${n}, from the root s = 0 to the tip s = 1)`
    : '(none: the section holds along the span)';
}

// --------------------------------------------------------------- examples

function exampleDesc() {
  const ex = EXAMPLES.find((e) => e.key === $('example').value);
  $('example-desc').textContent = ex ? ex.desc : '';
}

export function loadExample(key) {
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
export function loadDoc(doc, caption = '') {
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

/** Make the structure tables and wire the editor: JSON text, design name, blade panel, options, examples. */
export function initDesign() {
  editor = new StructureEditor(document, () => S.rows, (kind) => docChanged(kind));

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

  // the design's name (the request's optional "name": lists and file names, not part of the job id)
  $('design-name').addEventListener('input', () => {
    const t = $('design-name').value.trim();
    if (t) S.doc.name = t;
    else delete S.doc.name;
    setText(prettyJSON(S.doc));
    afterChange();
  });
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
  initTower(() => {
    setText(prettyJSON(S.doc));
    afterChange();
  });
  initOptions(docChanged);
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
  $('example').addEventListener('change', exampleDesc);
}
