// errors.js — errors and warnings next to the fields they name: the page's
// own checks (empty or duplicate names, the sweep fields, JSON syntax), the
// daemon's errors (POST /v1/validate as the user types, or the submission)
// and input_warnings, each placed by its JSON pointer on the control that
// carries it (data-pointer) and listed under the editor; "valid" beside them.

import {parentPtr} from './request.js';
import * as api from './api.js';
import {$} from './dom.js';
import {S} from './state.js';

export function computeLocalErrors() {
  const out = [];
  const seen = new Map();
  for (const tr of document.querySelectorAll('#joints tbody tr, #sections tbody tr')) {
    const input = tr.querySelector('input.name');
    const kind = tr.closest('table').id === 'joints' ? 'joint' : 'section';
    const key = kind + ':' + input.value;
    if (input.value === '') out.push({el: input, message: `a ${kind} name must not be empty`});
    else if (seen.has(key)) out.push({el: input, message: `duplicate ${kind} name '${input.value}'`});
    seen.set(key, true);
  }
  if (S.sweepError) out.push(S.sweepError);
  if (S.parseError) out.push({pointer: '', message: `not valid JSON: ${S.parseError}`, local: true});
  S.localErrors = out;
}

/** The registered element of a pointer, or of its nearest ancestor. */
function targetOf(pointer) {
  const reg = new Map();
  for (const e of document.querySelectorAll('[data-pointer]')) {
    if (e.hidden || e.closest('[hidden]')) continue;
    const p = e.dataset.pointer;
    const isControl = /^(INPUT|SELECT|TEXTAREA)$/.test(e.tagName);
    if (!reg.has(p) || (isControl && !/^(INPUT|SELECT|TEXTAREA)$/.test(reg.get(p).tagName))) reg.set(p, e);
  }
  let p = pointer;
  while (p !== null) {
    if (reg.has(p)) return reg.get(p);
    p = parentPtr(p);
  }
  return null;
}

function msgSlot(e) {
  if (!e) return $('json-msg');
  if (/^(INPUT|SELECT|TEXTAREA)$/.test(e.tagName)) {
    const id = e.getAttribute('aria-describedby');
    const byId = id && document.getElementById(id.split(' ')[0]);
    if (byId && byId.classList.contains('msg')) return byId;
    return e.closest('td, .field, fieldset')?.querySelector('.msg') || $('json-msg');
  }
  return e.querySelector(':scope > .msg') || e.querySelector('.msg') || $('json-msg');
}

function controlOf(e) {
  if (!e) return $('json');
  if (/^(INPUT|SELECT|TEXTAREA)$/.test(e.tagName)) return e;
  return e.querySelector('input:not([hidden]), select, textarea');
}

export function showErrors() {
  for (const m of document.querySelectorAll('.msg')) m.textContent = '';
  for (const c of document.querySelectorAll('[aria-invalid]')) c.removeAttribute('aria-invalid');
  const list = $('errors');
  list.textContent = '';
  // the daemon's JSON syntax error (line, column) replaces the browser's own
  const server = S.serverErrors;
  const daemonSyntax = S.parseError && server.some((e) => e.pointer === '');
  const all = S.localErrors.filter((e) => !(e.local && daemonSyntax)).concat(server);
  for (const err of all) {
    const target = err.el || targetOf(err.pointer);
    const slot = err.pointer === '' && !err.el ? $('json-msg') : msgSlot(target);
    const line = document.createElement('div');
    line.className = 'err';
    line.textContent = err.message;
    slot.append(line);
    const ctl = err.pointer === '' && !err.el ? $('json') : controlOf(target);
    if (ctl) ctl.setAttribute('aria-invalid', 'true');

    const li = document.createElement('li');
    const b = document.createElement('button');
    b.type = 'button';
    b.className = 'linkish';
    b.textContent = err.el ? '(page)' : err.pointer === '' ? '(document)' : err.pointer;
    b.addEventListener('click', () => (ctl || $('json')).focus());
    li.append(b, ' ', err.message);
    list.append(li);
  }
  $('errors-box').hidden = all.length === 0;
  // input_warnings (unit slips): next to their field as the errors, and listed
  const wl = $('warnings');
  wl.textContent = '';
  for (const w of S.warnings) {
    const target = targetOf(w.pointer);
    const slot = w.pointer === '' ? $('json-msg') : msgSlot(target);
    const line = document.createElement('div');
    line.className = 'warn';
    line.textContent = '⚠ ' + w.message;
    slot.append(line);
    const li = document.createElement('li');
    const b = document.createElement('button');
    b.type = 'button';
    b.className = 'linkish';
    b.textContent = w.pointer || '(document)';
    b.addEventListener('click', () => (controlOf(target) || $('json')).focus());
    li.append(b, ' ', w.message);
    wl.append(li);
  }
  $('warnings-box').hidden = S.warnings.length === 0;
  const v = $('validity');
  if (all.length) {
    v.textContent = `${all.length} error${all.length === 1 ? '' : 's'}` +
      (S.serverErrorsFrom === 'submit' && server.length ? ' (from the last submission)' : '');
    v.className = 'validity bad';
  } else if (api.validateAvailable() === true && S.validated === S.text) {
    v.textContent = 'valid' + (S.warnings.length ? `, ${S.warnings.length} warning${S.warnings.length === 1 ? '' : 's'}` : '');
    v.className = 'validity good';
  } else {
    v.textContent = api.validateAvailable() === false ? 'checked when solved' : '';
    v.className = 'validity';
  }
}

// ----------------------------------------------------------- validation

let vTimer = 0, vAbort = null, vSeq = 0;

export function scheduleValidate() {
  clearTimeout(vTimer);
  if (api.validateAvailable() === false) return;
  vTimer = setTimeout(runValidate, 250);
}

async function runValidate() {
  const text = S.text;
  const seq = ++vSeq;
  if (vAbort) vAbort.abort();
  vAbort = new AbortController();
  let r;
  try {
    r = await api.validate(text, vAbort.signal);
  } catch (e) {
    if (e.name !== 'AbortError') console.warn('validate:', e);
    return;
  }
  if (seq !== vSeq) return;
  if (!r.supported) {
    showErrors();
    return;
  }
  S.serverErrors = r.errors;
  S.serverErrorsFrom = 'validate';
  S.validated = r.valid ? text : null;
  S.warnings = r.valid ? r.warnings || [] : [];
  showErrors();
}
