// The server's JSON API: requests (the page's busy state while any is in flight), their errors
// as messages, and the page's error line.

import { $, body, state } from './state.js';

export function busy(delta) {
  state.inflight += delta;
  if (state.inflight > 0) body.dataset.state = 'loading';
}

export function settle(ok) {
  if (state.inflight > 0) return;
  body.dataset.state = ok ? 'ready' : 'error';
}

export class ApiError extends Error {}

// Fetch JSON; a 4xx/5xx answer's {"error"} becomes an ApiError with that message.
export async function api(url, options) {
  busy(1);
  try {
    let response;
    try {
      response = await fetch(url, options);
    } catch (e) {
      throw new ApiError(`the server did not answer (${e && e.message ? e.message : 'network error'})`);
    }
    const text = await response.text();
    let data = null;
    try {
      data = text ? JSON.parse(text) : null;
    } catch (e) {
      if (response.ok) throw new ApiError(`unreadable answer from ${url.split('?')[0]}`);
    }
    if (!response.ok) {
      const message = data && typeof data.error === 'string' ? data.error : `${response.status} ${response.statusText}`;
      throw new ApiError(message);
    }
    return data;
  } finally {
    busy(-1);
  }
}

export function showError(message) {
  const e = $('#error');
  e.textContent = message;
  e.hidden = false;
}

export function clearError() {
  const e = $('#error');
  e.textContent = '';
  e.hidden = true;
}

export async function fetchText(url) {
  busy(1);
  try {
    const r = await fetch(url);
    const text = await r.text();
    if (!r.ok) {
      let message = `${r.status} ${r.statusText}`;
      try {
        const d = JSON.parse(text);
        if (d && d.error) message = d.error;
      } catch (e) {
        /* not JSON */
      }
      throw new ApiError(message);
    }
    return text;
  } finally {
    busy(-1);
  }
}
