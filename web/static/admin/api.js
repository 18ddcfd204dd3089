// The admin API over fetch: the session cookie goes along (same origin); an error answer
// becomes an ApiError whose message is the server's `detail` sentence, verbatim.

export class ApiError extends Error {
  constructor(status, message) {
    super(message);
    this.name = "ApiError";
    this.status = status;
  }
}

function detailOf(status, statusText, payload) {
  if (payload && typeof payload === "object" && "detail" in payload) {
    const { detail } = payload;
    if (typeof detail === "string") return detail;
    if (Array.isArray(detail)) {
      return detail.map((d) => (d && d.msg ? `${(d.loc || []).join(".")}: ${d.msg}` : String(d))).join("; ");
    }
    return JSON.stringify(detail);
  }
  if (typeof payload === "string" && payload.trim() && payload.length < 300) return payload.trim();
  return `the server answered ${status} ${statusText || ""}`.trim();
}

// Listeners told when the session is gone (401): the page shows its login message.
const unauthorized = new Set();
export function onUnauthorized(listener) {
  unauthorized.add(listener);
}

/**
 * api("GET", "/api/admin/users") -> parsed JSON (or text for non-JSON answers).
 * options: {json} a body sent as JSON; {body, type} a raw body and its content type;
 *          {quiet401} do not tell the listeners about a 401 (the first /api/me).
 */
export async function api(method, path, options = {}) {
  const init = { method, credentials: "same-origin", headers: { Accept: "application/json" } };
  if (options.json !== undefined) {
    init.body = JSON.stringify(options.json);
    init.headers["Content-Type"] = "application/json";
  } else if (options.body !== undefined) {
    init.body = options.body;
    init.headers["Content-Type"] = options.type || "text/plain";
  }
  let response;
  try {
    response = await fetch(path, init);
  } catch (error) {
    throw new ApiError(0, `the server did not answer (${error.message}); is it running?`);
  }
  const type = response.headers.get("content-type") || "";
  let payload = null;
  try {
    payload = type.includes("json") ? await response.json() : await response.text();
  } catch {
    payload = null;
  }
  if (!response.ok) {
    if (response.status === 401 && !options.quiet401) unauthorized.forEach((fn) => fn());
    throw new ApiError(response.status, detailOf(response.status, response.statusText, payload));
  }
  return payload;
}

export const get = (path, options) => api("GET", path, options);
export const post = (path, json, options = {}) => api("POST", path, { ...options, json });
export const put = (path, json, options = {}) => api("PUT", path, { ...options, json });
export const patch = (path, json, options = {}) => api("PATCH", path, { ...options, json });
export const del = (path, options) => api("DELETE", path, options);

export const enc = encodeURIComponent;
