// files.js — requests as files and blade or tower files: "Open request…" (a request,
// or a "JSON + request" download with its result), "Save request", and the
// "Open blade file…" dialog, which sends POST /v1/import/{format} and puts
// the answer's request into the editor with the importer's warnings.

import {fmtNum, speedList} from './request.js';
import {saveBlob} from './export.js';
import * as api from './api.js';
import {$, plural} from './dom.js';
import {S, fileSafe} from './state.js';
import {loadDoc} from './design.js';
import {showResult} from './results.js';

/** The message under the file buttons. */

export function fileMsg(text, cls = '') {
  const m = $('file-msg');
  m.textContent = text;
  m.className = 'file-msg ' + cls;
}

function readFile(f) {
  return f.text ? f.text() : new Promise((res, rej) => {
    const r = new FileReader();
    r.onload = () => res(String(r.result));
    r.onerror = () => rej(r.error);
    r.readAsText(f);
  });
}

// ------------------------------------------------------------ blade import

const IMPORT_MAIN = {bmodes: 'BModes main file (.bmi: a blade, or a tower with beam_type 2)', elastodyn: 'ElastoDyn blade file (.dat)',
  csv: 'CSV file (a header row naming the columns: s or r, mass_per_length, EI_flap …)'};

function importFormat() {
  const f = $('import-format').value;
  $('import-main-label').textContent = IMPORT_MAIN[f];
  $('import-sec-field').hidden = f !== 'bmodes';
  $('import-bmesh-field').hidden = f !== 'bmodes';
  $('import-bmodes-k').disabled = !$('import-bmodes-mesh').checked;
  $('import-tip').placeholder = f === 'bmodes' ? 'from the file' : 'required (m)';
  $('import-error').textContent = '';
}

/** Import the chosen files: POST /v1/import/{format}; the request goes into the editor. */
async function importBlade() {
  const format = $('import-format').value;
  const main = $('import-main').files[0], sec = $('import-sec').files[0];
  const err = $('import-error');
  err.textContent = '';
  if (!main) {
    err.textContent = 'Choose the file to import.';
    return;
  }
  if (format === 'bmodes' && !sec) {
    err.textContent = 'A BModes import needs the section-properties file too (the one the .bmi names).';
    return;
  }
  const body = {main: await readFile(main), name: main.name};
  if (format === 'bmodes') body.sec_props = await readFile(sec);
  const q = {tip_radius: $('import-tip').value.trim(), hub_radius: $('import-hub').value.trim(),
    rpm: $('import-rpm').value.trim()};
  const ownMesh = format === 'bmodes' && $('import-bmodes-mesh').checked;
  if (ownMesh) {
    // BModes' own model: its elements as uniform members, K FE elements each (DAEMON.md, Importers)
    const k = $('import-bmodes-k').value.trim();
    if (!/^\d+$/.test(k) || Number(k) < 1 || Number(k) > 1000) {
      err.textContent = 'FE elements per BModes element: a whole number from 1 to 1000.';
      return;
    }
    q.bmodes_mesh = k;
  }
  let r;
  try {
    r = await api.importBlade(format, body, q);
  } catch (e) {
    err.textContent = `cannot reach the daemon: ${e.message}`;
    return;
  }
  if (!r.ok) {
    // 422: FILE:LINE: FIELD: what is wrong
    const where = r.file ? `${r.file}${r.line ? `, line ${r.line}` : ''}${r.field ? `, field ${r.field}` : ''}` : '';
    err.textContent = '';
    const h = document.createElement('strong');
    h.textContent = where ? `${where}: ` : `${r.status}: `;
    const t = document.createElement('span');
    t.textContent = r.message;
    err.append(h, t);
    err.dataset.file = r.file || '';
    err.dataset.line = r.line ? String(r.line) : '';
    err.dataset.field = r.field || '';
    return;
  }
  $('import-dialog').close();
  const src = r.source || {};
  const req = r.request && typeof r.request === 'object' ? r.request : {};
  // a name for the past jobs and the file names: the file's, unless the request has one
  if (typeof req.name !== 'string' && fileSafe(main.name.replace(/\.[^.]*$/, ''))) req.name = main.name.replace(/\.[^.]*$/, '');
  const b = req.blade && typeof req.blade === 'object' ? req.blade : null;
  const tw = req.tower && typeof req.tower === 'object' ? req.tower : null;
  const an = req.analysis && typeof req.analysis === 'object' ? req.analysis : {};
  const sp = 'rpm' in an ? speedList(an.rpm) : [];
  loadDoc(req, `Imported from ${main.name}${format === 'bmodes' ? ` + ${sec.name}` : ''}` + (src.title ? ` (“${src.title}”)` : '') +
    (b ? `: a blade of ${fmtNum(b.length)} m${Array.isArray(b.stations) ? `, ${plural(b.stations.length, 'station')}` : ''}`
      : tw ? `: a tower of ${fmtNum(tw.height)} m${Array.isArray(tw.stations) ? `, ${plural(tw.stations.length, 'station')}` : ''}`
      : req.structure && Array.isArray(req.structure.members) ? `: ${plural(req.structure.members.length, 'member')}` : '') +
    (sp.length === 1 ? `, ${fmtNum(sp[0])} rpm` : '') + '.');
  $('import-notes').hidden = false;
  $('import-source').textContent = `${src.file || main.name}${src.sec_props_file ? ' + ' + src.sec_props_file : ''}` +
    (src.title ? ` — “${src.title}”` : '');
  const ul = $('import-warnings');
  ul.textContent = '';
  const warnings = r.warnings.slice();
  // the section file chosen is not the one the .bmi names (a tower table would import without a word)
  const baseName = (t) => String(t).split(/[\\/]/).pop();
  if (format === 'bmodes' && typeof src.sec_props_file === 'string' && src.sec_props_file &&
      baseName(src.sec_props_file).toLowerCase() !== sec.name.toLowerCase() &&
      !warnings.some((w) => String(typeof w === 'string' ? w : w.message).includes(sec.name))) {
    warnings.unshift({file: main.name, field: 'sec_props_file', mismatch: true,
      message: `the .bmi names the section file “${src.sec_props_file}”, but “${sec.name}” was chosen: ` +
        'check that it is this blade\'s table (a tower\'s would import without an error)'});
  }
  for (const w of warnings) {
    const li = document.createElement('li');
    li.textContent = typeof w === 'string' ? w : [w.file && `${w.file}${w.line ? ':' + w.line : ''}`, w.field, w.message]
      .filter(Boolean).join(': ') || JSON.stringify(w);
    if (w && w.mismatch) {
      li.className = 'warn sec-mismatch';
      li.textContent = '⚠ ' + li.textContent;
    }
    ul.append(li);
  }
  if (!warnings.length) {
    const li = document.createElement('li');
    li.className = 'ok';
    li.textContent = 'no import warnings';
    ul.append(li);
  }
  const st = S.doc.structure;
  fileMsg(ownMesh && st && Array.isArray(st.members)
    ? `imported ${main.name} (BModes' own mesh): ${st.members.length} members of ${q.bmodes_mesh} elements — press Solve`
    : `imported ${main.name} (${format}): ${S.doc.tower ? `a tower of ${S.doc.tower.height}` : `a blade of ${S.doc.blade && S.doc.blade.length}`} m — press Solve`, 'ok');
}

/** Wire the open and save buttons and the import dialog. */
export function initFiles() {
  $('open-request').addEventListener('change', async () => {
    const f = $('open-request').files[0];
    if (!f) return;
    const text = await readFile(f);
    let doc;
    try {
      doc = JSON.parse(text);
    } catch (e) {
      fileMsg(`${f.name}: not a JSON request (${e.message})`, 'bad');
      $('open-request').value = '';
      return;
    }
    // a "JSON + request" download holds {request, result}
    const req = doc && typeof doc === 'object' && doc.request && doc.result ? doc.request : doc;
    loadDoc(req, `Opened ${f.name}` + (req && typeof req.name === 'string' ? ` (“${req.name}”)` : '') + '.');
    if (doc && doc.request && doc.result) showResult(doc.result.solver ? 'file-' + f.name : 'file', doc.request, doc.result);
    fileMsg(`opened ${f.name}`, 'ok');
    $('open-request').value = '';
  });

  $('save-request').addEventListener('click', () => {
    const name = (typeof S.doc.name === 'string' && fileSafe(S.doc.name) ? fileSafe(S.doc.name)
      : $('example').value && !S.blade ? $('example').value : 'request') + '.json';
    saveBlob(new Blob([S.text.endsWith('\n') ? S.text : S.text + '\n'], {type: 'application/json'}), `spinmodal-${name}`);
    fileMsg(`saved spinmodal-${name} (your downloads)`, 'ok');
  });
  $('import-format').addEventListener('change', importFormat);
  $('import-bmodes-mesh').addEventListener('change', importFormat);
  $('open-blade').addEventListener('click', () => {
    importFormat();
    $('import-dialog').showModal();
  });
  $('import-go').addEventListener('click', importBlade);
}
