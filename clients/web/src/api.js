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
async function call(method, path, {body, signal, write = false} = {}) {
  const headers = {Accept: 'application/json, application/problem+json'};
  if (body !== undefined) headers['Content-Type'] = 'application/json';
  const tok = getToken();
  if (write && tok) headers.Authorization = 'Bearer ' + tok;
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
      canonical: b.canonical};
  }
  return {supported: true, valid: false, errors: problemErrors(ans), status: ans.status};
}

// ------------------------------------------------------------------- jobs

/** POST /v1/analyses: {status, doc (status document) | errors, retryAfter}. */
export async function submit(text) {
  const ans = await call('POST', 'v1/analyses', {body: text, write: true});
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
  const ans = await call('DELETE', `v1/analyses/${encodeURIComponent(id)}`, {write: true});
  if (ans.ok) return {status: ans.status, doc: ans.body};
  return {status: ans.status, errors: problemErrors(ans)};
}

/** GET /v1/analyses/{id}/result: the result document, or throws. */
export async function getResult(id) {
  const ans = await call('GET', `v1/analyses/${encodeURIComponent(id)}/result`);
  if (!ans.ok || !ans.body) throw new Error(problemErrors(ans)[0].message);
  return ans.body;
}

export function resultUrl(id, format) {
  return url(`v1/analyses/${encodeURIComponent(id)}/result` + (format ? `?format=${format}` : ''));
}
