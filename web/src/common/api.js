// The JSON API of `robodojo serve`: same-origin fetch with the session cookie (the server's CSRF
// guard checks the Origin the browser sends, so no token travels here). Every 4xx answer carries
// {"detail": sentence}; ApiError keeps that sentence so it can be shown verbatim.

export class ApiError extends Error {
  /** `body`: the whole decoded answer when it was JSON (e.g. a refusal's "gate" verdict). */
  constructor(status, detail, body = null) {
    super(detail);
    this.name = "ApiError";
    this.status = status;
    this.body = body;
  }
}

const SHORT_TEXT = 300; // [characters] a plain-text error answer up to this long is shown as is

/**
 * The sentence of an error answer's decoded body. A string `detail` is the server's own
 * sentence; a list is FastAPI's validation errors, shown as "body.email: msg; ..." so the
 * field at fault is named.
 */
export function detailText(status, statusText, payload) {
  if (payload && typeof payload === "object" && "detail" in payload) {
    const { detail } = payload;
    if (typeof detail === "string") return detail;
    if (Array.isArray(detail)) {
      return detail.map((d) => (d && d.msg ? `${(d.loc || []).join(".")}: ${d.msg}` : String(d))).join("; ");
    }
    return JSON.stringify(detail);
  }
  if (typeof payload === "string" && payload.trim() && payload.length < SHORT_TEXT) return payload.trim();
  return `${status} ${statusText || "error"}`.trim();
}

/** [sentence, decoded JSON body or null] of an error answer. */
async function detailOf(response) {
  let payload = null;
  try {
    const type = response.headers.get("content-type") || "";
    payload = type.includes("json") ? await response.json() : await response.text();
  } catch {
    // an unreadable body: the status line says what happened
  }
  const body = payload && typeof payload === "object" && "detail" in payload ? payload : null;
  return [detailText(response.status, response.statusText, payload), body];
}

/**
 * fetch `path`; resolve with the decoded JSON (or the text of a non-JSON answer), reject with an
 * ApiError carrying the server's sentence.
 * options: `method`; `body` sent as JSON, or as is with `contentType` (a CSV upload); `signal`;
 * `quiet401`: a 401 is this call's own answer (a wrong token typed at login), not a session
 * that ended, so the page is not told "robodojo:logged-out".
 */
export async function api(path, { method = "GET", body, contentType, signal, quiet401 = false } = {}) {
  const options = { method, credentials: "same-origin", signal, headers: {} };
  if (body !== undefined) {
    options.headers["content-type"] = contentType || "application/json";
    options.body = contentType ? body : JSON.stringify(body);
  }
  let response;
  try {
    response = await fetch(path, options);
  } catch (error) {
    if (error.name === "AbortError") throw error;
    throw new ApiError(0, "the server does not answer; check that it is running and reload");
  }
  if (!response.ok) {
    // A session that ended (logged out elsewhere, token renewed): the page shows the way back.
    if (response.status === 401 && !quiet401) window.dispatchEvent(new CustomEvent("robodojo:logged-out"));
    throw new ApiError(response.status, ...(await detailOf(response)));
  }
  const type = response.headers.get("content-type") || "";
  return type.includes("json") ? response.json() : response.text();
}

/** Text of a file the API serves (a CSV, a log). */
export async function apiText(path, { signal } = {}) {
  const response = await fetch(path, { credentials: "same-origin", signal });
  if (!response.ok) throw new ApiError(response.status, ...(await detailOf(response)));
  return response.text();
}
