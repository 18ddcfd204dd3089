// The JSON API of `robodojo serve`: same-origin fetch with the session cookie. Every 4xx answer
// carries {"detail": sentence}; ApiError keeps that sentence so it can be shown verbatim.

export class ApiError extends Error {
  /** `body`: the whole decoded answer when it was JSON (e.g. a refusal's "gate" verdict). */
  constructor(status, detail, body = null) {
    super(detail);
    this.status = status;
    this.body = body;
  }
}

/** [sentence, decoded JSON body or null] of an error answer. */
async function detailOf(response) {
  try {
    const body = await response.json();
    if (typeof body.detail === "string") return [body.detail, body];
    if (body.detail !== undefined) return [JSON.stringify(body.detail), body];
  } catch {
    // not JSON: fall through to the status line
  }
  return [`${response.status} ${response.statusText || "error"}`.trim(), null];
}

/** fetch `path`; resolve with the decoded JSON, reject with an ApiError carrying the detail. */
export async function api(path, { method = "GET", body, signal } = {}) {
  const options = { method, credentials: "same-origin", signal, headers: {} };
  if (body !== undefined) {
    options.headers["content-type"] = "application/json";
    options.body = JSON.stringify(body);
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
    if (response.status === 401) window.dispatchEvent(new CustomEvent("robodojo:logged-out"));
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
