// jobs.js — jobs on the daemon: the bearer token, Solve (POST /v1/analyses),
// following the job (GET …?wait=1: progress, then its result or its errors),
// Cancel (DELETE), and the past jobs list with Reopen (the job's canonical
// request into the editor, with its status and result).

import * as api from './api.js';
import {$, plural} from './dom.js';
import {S} from './state.js';
import {showErrors} from './errors.js';
import {showResult} from './results.js';
import {loadDoc} from './design.js';
import {fileMsg} from './files.js';

const TERMINAL = new Set(['done', 'failed', 'canceled']);

function setStatus(text, cls = '') {
  const s = $('job-status');
  s.textContent = text;
  s.className = cls;
}

function showJob(doc) {
  S.job = doc;
  const p = doc.progress || {done: 0, total: 0};
  const prog = $('progress');
  prog.max = Math.max(1, p.total || 1);
  prog.value = Math.min(prog.max, p.done || 0);
  prog.setAttribute('aria-valuetext', `${p.done} of ${p.total} speeds`);
  let t = `${doc.state}: ${p.done} / ${p.total} speeds`;
  if (doc.cancel_requested && !TERMINAL.has(doc.state)) t += ' (cancel requested)';
  if (doc.error) t += ` — ${doc.error.title || doc.error.type}${doc.error.detail ? ': ' + doc.error.detail : ''}`;
  setStatus(t, doc.state === 'done' ? 'ok' : doc.state === 'failed' ? 'bad' : '');
  $('cancel').disabled = TERMINAL.has(doc.state);
  $('submit').disabled = !TERMINAL.has(doc.state);
  document.body.dataset.jobState = doc.state;
}

async function solve() {
  const text = S.text;
  let request;
  try {
    request = JSON.parse(text);
  } catch {
    request = null;
  }
  $('submit').disabled = true;
  setStatus('submitting…');
  document.body.dataset.jobState = 'submitting';
  const gen = ++S.pollGen;
  let r;
  try {
    r = await api.submit(text);
  } catch (e) {
    $('submit').disabled = false;
    document.body.dataset.jobState = 'unreachable';
    setStatus(`cannot reach the daemon: ${e.message}`, 'bad');
    return;
  }
  if (!r.doc) {
    $('submit').disabled = false;
    document.body.dataset.jobState = 'rejected';
    S.serverErrors = r.errors;
    S.serverErrorsFrom = 'submit';
    showErrors();
    const what = r.status === 422 ? 'the request is invalid (see the errors)'
      : r.status === 429 ? `the queue is full; retry in ${r.retryAfter || 'a few'} s`
        : r.status === 401 ? 'a bearer token is required (Token, top right)'
          : r.errors.map((e) => e.message).join('; ');
    setStatus(`not submitted: ${what}`, 'bad');
    return;
  }
  S.serverErrors = [];
  showErrors();
  S.submitted = {id: r.doc.id, request};
  showJob(r.doc);
  await poll(r.doc, gen);
}

async function poll(doc, gen) {
  let cur = doc;
  let failures = 0;
  while (!TERMINAL.has(cur.state)) {
    if (gen !== S.pollGen) return;
    let r;
    try {
      r = await api.getStatus(cur.id, 1);
    } catch {
      r = null;
    }
    if (gen !== S.pollGen) return;
    if (!r || !r.doc) {
      if (++failures > 30) {
        setStatus('lost contact with the daemon', 'bad');
        $('submit').disabled = false;
        return;
      }
      await new Promise((res) => setTimeout(res, 1000));
      continue;
    }
    failures = 0;
    cur = r.doc;
    showJob(cur);
  }
  showJob(cur);
  if (cur.error && Array.isArray(cur.error.errors) && cur.error.errors.length) {
    // e.g. a cycle or a disconnected member, found when the model is built
    S.serverErrors = cur.error.errors.map((e) => ({pointer: String(e.pointer ?? ''), message: String(e.message ?? '')}));
    S.serverErrorsFrom = 'submit';
    showErrors();
  }
  if (cur.state === 'done' || cur.result) {
    let result = cur.result;
    if (!result) {
      try {
        result = await api.getResult(cur.id);
      } catch (e) {
        setStatus(`${cur.state}; no result: ${e.message}`, 'bad');
        return;
      }
    }
    if (gen !== S.pollGen) return;
    showResult(cur.id, S.submitted && S.submitted.id === cur.id ? S.submitted.request : S.doc, result, cur);
  }
}

// ------------------------------------------------------------ past jobs

let jobsLoaded = 0;

async function refreshJobs() {
  if (Date.now() - jobsLoaded < 2000) return;
  jobsLoaded = Date.now();
  let items;
  try {
    items = await api.listJobs(30);
  } catch (e) {
    fileMsg(`past jobs: ${e.message}`, 'bad');
    return;
  }
  const sel = $('past-jobs');
  const prev = sel.value;
  sel.textContent = '';
  const none = document.createElement('option');
  none.value = '';
  none.textContent = items.length ? `— ${items.length} recent —` : '— none yet —';
  sel.append(none);
  for (const j of items) {
    const o = document.createElement('option');
    o.value = j.id;
    const when = (j.created_at || '').replace('T', ' ').replace(/\.\d+Z$/, ' UTC');
    o.textContent = (typeof j.name === 'string' ? `${j.name} · ` : '') +
      `${when} · ${j.state} · ${j.progress ? plural(j.progress.total, 'speed') : '? speeds'} · ${j.id.slice(0, 8)}`;
    if (typeof j.name === 'string') o.dataset.name = j.name;
    sel.append(o);
  }
  if (prev && Array.from(sel.options).some((o) => o.value === prev)) sel.value = prev;
}

/** Reopen a past job: its request into the editor (GET …/request), its result if it has one. */
async function reopenJob(id) {
  if (!id) return;
  fileMsg(`opening job ${id.slice(0, 12)}…`);
  let request, st;
  try {
    request = await api.getRequest(id);
    st = await api.getStatus(id);
  } catch (e) {
    fileMsg(`job ${id.slice(0, 12)}: ${e.message}`, 'bad');
    return;
  }
  S.pollGen++;
  loadDoc(request, `Past job ${id.slice(0, 12)}` + (request && typeof request.name === 'string' ? ` — “${request.name}”` : '') +
    (st && st.doc && st.doc.created_at ? `, submitted ${st.doc.created_at.replace('T', ' ').replace(/\.\d+Z$/, ' UTC')}` : '') + '.');
  if (st && st.doc) {
    showJob(st.doc);
    S.submitted = {id, request: S.doc};
    if (!TERMINAL.has(st.doc.state)) poll(st.doc, S.pollGen);
    else if (st.doc.result) showResult(id, S.doc, st.doc.result, st.doc);
  }
  fileMsg(`reopened job ${id.slice(0, 12)} (${st && st.doc ? st.doc.state : '?'})`, 'ok');
}

/** Wire the token field, Solve, Cancel and the past jobs. */
export function initJobs() {
  $('token').value = api.getToken();
  $('token').addEventListener('change', () => api.setToken($('token').value.trim()));
  $('analysis-form').addEventListener('submit', (ev) => {
    ev.preventDefault();
    solve();
  });
  $('cancel').addEventListener('click', async () => {
    if (!S.job) return;
    $('cancel').disabled = true;
    const id = S.job.id;
    const r = await api.cancel(id).catch((e) => ({errors: [{message: e.message}]}));
    // The poll may have seen the job end while DELETE was on its way: its answer (the job as
    // it was when the cancel was asked, "running") must not overwrite that last state, or the
    // page would stay "running" with Solve disabled (CI saw it once under AddressSanitizer).
    if (r.doc) {
      if (!(S.job && S.job.id === id && TERMINAL.has(S.job.state))) showJob(r.doc);
    } else setStatus(`cancel failed: ${r.errors.map((e) => e.message).join('; ')}`, 'bad');
  });
  $('past-jobs').addEventListener('focus', refreshJobs);
  $('past-jobs').addEventListener('pointerdown', refreshJobs);
  $('open-job').addEventListener('click', () => reopenJob($('past-jobs').value));
}
