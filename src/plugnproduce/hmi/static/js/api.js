// Talking to the HMI's HTTP API: JSON in and out, the bearer token for changes, one-line errors.

const TOKEN_KEY = "pnp-token";

/** An error response: its status and the API's one-line message. */
export class ApiError extends Error {
  constructor(status, detail, body) {
    super(detail);
    this.status = status;
    this.body = body;
  }
}

/** The token in use (from the page's #token=... or the token dialog), or "". */
export function token() {
  return sessionStorage.getItem(TOKEN_KEY) || "";
}

export function setToken(value) {
  if (value) sessionStorage.setItem(TOKEN_KEY, value);
  else sessionStorage.removeItem(TOKEN_KEY);
}

/** Take the token from the address ("#token=...") and remove it from the address bar. */
export function tokenFromAddress() {
  const match = /(?:^#|&)token=([^&]+)/.exec(location.hash);
  if (match) {
    setToken(decodeURIComponent(match[1]));
    history.replaceState(null, "", location.pathname + location.search);
  }
}

let askForToken = async () => false;

/** Install the function that asks the user for a token (resolves true when one was given). */
export function onTokenNeeded(fn) {
  askForToken = fn;
}

async function send(method, path, body, { auth, raw, contentType }) {
  const headers = {};
  if (body !== undefined) headers["content-type"] = contentType || "application/json";
  if (auth && token()) headers.authorization = `Bearer ${token()}`;
  const init = { method, headers };
  if (body !== undefined) init.body = raw ? body : JSON.stringify(body);
  const res = await fetch(path, init);
  const type = res.headers.get("content-type") || "";
  const data = type.includes("json") ? await res.json() : await res.text();
  if (!res.ok) {
    const detail = (data && data.detail) || `${res.status} ${res.statusText}`;
    throw new ApiError(res.status, typeof detail === "string" ? detail : JSON.stringify(detail), data);
  }
  return data;
}

/**
 * Call the API. `auth` requests carry the bearer token; a 401 asks for the token once and retries.
 * Returns the parsed JSON (or text); throws ApiError with the server's one-line message.
 */
export async function api(method, path, body, options = {}) {
  const opts = { auth: false, raw: false, ...options };
  try {
    return await send(method, path, body, opts);
  } catch (err) {
    if (err instanceof ApiError && err.status === 401 && opts.auth && (await askForToken())) {
      return send(method, path, body, opts);
    }
    throw err;
  }
}

export const get = (path) => api("GET", path);
export const post = (path, body, options) => api("POST", path, body, options);
export const del = (path, options) => api("DELETE", path, undefined, options);
