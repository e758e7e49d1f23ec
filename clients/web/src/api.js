// api.js — the daemon's HTTP API (server/DAEMON.md) as used by the page.
// Paths are relative to the page, so the front end also works behind a
// reverse proxy that serves the daemon under a prefix.

const TOKEN_KEY = 'spinmodal.token';

export function getToken() {
  try {
    return sessionStorage.getItem(TOKEN_KEY) || '';
  } catch {
    return '';
  }
}

export function setToken(t) {
  try {
    if (t) sessionStorage.setItem(TOKEN_KEY, t);
    else sessionStorage.removeItem(TOKEN_KEY);
  } catch {
    /* storage disabled: the token lives only in the field */
  }
}

export function url(path) {
  return new URL(path.replace(/^\//, ''), document.baseURI).toString();
}

/** An answer: {status, ok, body (parsed JSON or null), text, headers}. */
async function call(method, path, {body, signal} = {}) {
  const headers = {Accept: 'application/json, application/problem+json'};
  if (body !== undefined) headers['Content-Type'] = 'application/json';
  const tok = getToken();
  if (tok) headers.Authorization = 'Bearer ' + tok; // also reads: --auth-reads
  const res = await fetch(url(path), {method, headers, body, signal, cache: 'no-store'});
  const text = await res.text();
  let parsed = null;
  if (text && /json/.test(res.headers.get('Content-Type') || '')) {
    try {
      parsed = JSON.parse(text);
    } catch {
      parsed = null;
    }
  }
  return {status: res.status, ok: res.ok, body: parsed, text, headers: res.headers};
}

/** The errors of a problem document, or one built from an answer without one. */
export function problemErrors(ans) {
  const b = ans.body;
  if (b && Array.isArray(b.errors) && b.errors.length) {
    return b.errors.map((e) => ({pointer: String(e.pointer ?? ''), message: String(e.message ?? '')}));
  }
  const msg = b && (b.detail || b.title) ? [b.title, b.detail].filter(Boolean).join(': ')
    : `HTTP ${ans.status}`;
  return [{pointer: '', message: msg}];
}

// ------------------------------------------------------------- validation

let validateSupported = null; // null: not yet known; false after a 404/405

export function validateAvailable() {
  return validateSupported;
}

/**
 * Validate request text without creating a job: POST /v1/validate.
 * Returns {supported: false} when the daemon has no such route (404/405),
 * else {supported: true, valid, errors, status, id, canonical}.
 */
export async function validate(text, signal) {
  if (validateSupported === false) return {supported: false};
  const ans = await call('POST', 'v1/validate', {body: text, signal});
  if (ans.status === 404 || ans.status === 405) {
    validateSupported = false;
    return {supported: false};
  }
  validateSupported = true;
  if (ans.status === 200) {
    const b = ans.body || {};
    return {supported: true, valid: b.valid !== false, errors: [], status: 200, id: b.id,
      canonical: b.canonical, warnings: warningsOf(b)};
  }
  return {supported: true, valid: false, errors: problemErrors(ans), status: ans.status};
}

// ------------------------------------------------------------------- jobs

/** POST /v1/analyses: {status, doc (status document) | errors, retryAfter}. */
export async function submit(text) {
  const ans = await call('POST', 'v1/analyses', {body: text});
  if (ans.status === 200 || ans.status === 202) return {status: ans.status, doc: ans.body};
  return {status: ans.status, errors: problemErrors(ans), retryAfter: ans.headers.get('Retry-After')};
}

/** GET /v1/analyses/{id}?wait=S: {status, doc | errors}. */
export async function getStatus(id, wait, signal) {
  const q = wait ? `?wait=${wait}` : '';
  const ans = await call('GET', `v1/analyses/${encodeURIComponent(id)}${q}`, {signal});
  if (ans.ok) return {status: ans.status, doc: ans.body};
  return {status: ans.status, errors: problemErrors(ans)};
}

/** DELETE /v1/analyses/{id}: {status, doc | errors}. */
export async function cancel(id) {
  const ans = await call('DELETE', `v1/analyses/${encodeURIComponent(id)}`);
  if (ans.ok) return {status: ans.status, doc: ans.body};
  return {status: ans.status, errors: problemErrors(ans)};
}

/** GET /v1/analyses/{id}/result: the result document, or throws. */
export async function getResult(id) {
  const ans = await call('GET', `v1/analyses/${encodeURIComponent(id)}/result`);
  if (!ans.ok || !ans.body) throw new Error(problemErrors(ans)[0].message);
  return ans.body;
}

/**
 * GET /v1/analyses/{id}/mac?with=ID2: the MAC table between the modes of the first case of
 * both results (DESIGN.md 9.2): {ok: true, doc} or {ok: false, message} (409 not-comparable:
 * different structures or no mode shapes; 404 on a daemon without the route).
 */
export async function getMac(id, withId) {
  const ans = await call('GET', `v1/analyses/${encodeURIComponent(id)}/mac?with=${encodeURIComponent(withId)}`);
  if (ans.ok && ans.body) return {ok: true, doc: ans.body};
  return {ok: false, status: ans.status, message: problemErrors(ans)[0].message};
}

/**
 * GET /v1/analyses/{id}/result?format=F as a file: {ok: true, blob, type} with
 * the daemon's bytes unchanged (its Content-Type), or {ok: false, status,
 * message} (409 no-spanwise-shapes: a planar result or one without shapes).
 */
export async function getResultFile(id, format) {
  const headers = {};
  const tok = getToken();
  if (tok) headers.Authorization = 'Bearer ' + tok;
  const res = await fetch(resultUrl(id, format), {headers, cache: 'no-store'});
  const type = res.headers.get('Content-Type') || 'application/octet-stream';
  if (res.ok) return {ok: true, blob: await res.blob(), type};
  const text = await res.text();
  let b = null;
  try {
    b = /json/.test(type) ? JSON.parse(text) : null;
  } catch {
    b = null;
  }
  return {ok: false, status: res.status, message: (b && (b.detail || b.title)) || `HTTP ${res.status}`};
}

export function resultUrl(id, format) {
  return url(`v1/analyses/${encodeURIComponent(id)}/result` + (format ? `?format=${format}` : ''));
}

/** The input_warnings of a validate answer or a result: [{pointer, message}]. */
export function warningsOf(doc) {
  const w = doc && Array.isArray(doc.input_warnings) ? doc.input_warnings : [];
  return w.map((e) => ({pointer: String(e.pointer ?? ''), message: String(e.message ?? '')}));
}

// ---------------------------------------------------------------- import

/**
 * POST /v1/import/{format} (DAEMON.md, Importers): body {main, sec_props?, name}
 * (JSON, the files' texts), query tip_radius, hub_radius, rpm, bmodes_mesh
 * (BModes' own mesh: the answer's request is then in the structure form).  Returns
 * {ok: true, request, warnings, source} or {ok: false, status, message, file,
 * line, field, errors}.
 */
export async function importBlade(format, body, query = {}) {
  const q = new URLSearchParams();
  for (const [k, v] of Object.entries(query)) if (v !== '' && v !== undefined && v !== null) q.set(k, String(v));
  const qs = q.toString();
  const ans = await call('POST', `v1/import/${encodeURIComponent(format)}${qs ? '?' + qs : ''}`,
    {body: JSON.stringify(body)});
  const b = ans.body || {};
  if (ans.status === 200 && b.request) {
    return {ok: true, request: b.request, warnings: Array.isArray(b.warnings) ? b.warnings : [], source: b.source || {}};
  }
  return {ok: false, status: ans.status, message: b.detail || b.title || `HTTP ${ans.status}`, file: b.file,
    line: b.line, field: b.field, errors: problemErrors(ans)};
}

// ------------------------------------------------------------ past jobs

/** GET /v1/analyses?limit=N: the newest jobs (status documents without results). */
export async function listJobs(limit = 30) {
  const ans = await call('GET', `v1/analyses?limit=${limit}`);
  if (!ans.ok || !ans.body || !Array.isArray(ans.body.items)) throw new Error(problemErrors(ans)[0].message);
  return ans.body.items;
}

/** GET /v1/analyses/{id}/request: the job's canonical request, or throws. */
export async function getRequest(id) {
  const ans = await call('GET', `v1/analyses/${encodeURIComponent(id)}/request`);
  if (!ans.ok || !ans.body) throw new Error(problemErrors(ans)[0].message);
  return ans.body;
}
