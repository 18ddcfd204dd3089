// The 3D view of the run on show: the server's viser client for that run, at the run's
// `links.viz` (/api/runs/{id}/viz/), in a frame. Loaded when its tab is opened (WebGL is not
// free). A frame does not report an HTTP error, so its document is read once loaded (same
// origin): anything but viser's HTML page (the API's JSON {"detail"}, the browser's error page)
// shows "not available" with the server's sentence.

import { byId, fill, h } from "../common/dom.js";
import { app, on } from "./state.js";

const panel = byId("panel-viz");
let shownRun = null; // the run whose view the panel holds

export function initViz() {
  on("target", () => {
    shownRun = null;
    fill(panel, h("p", { class: "hint" }, "Run once to see it in 3D."));
  });
  on("run-shown", () => {
    shownRun = null;
    if (!panel.hidden) vizShown();
    else fill(panel, h("p", { class: "hint" }, "Open this tab to load the 3D view."));
  });
}

function unavailable(detail) {
  fill(panel, h("p", { class: "hint", dataset: { testid: "viz-unavailable" } }, `3D view not available (${detail}).`));
}

/** Why the frame's page is not the 3D view, or "" if it is. */
function problemOf(frame) {
  let doc;
  try {
    doc = frame.contentDocument;
  } catch {
    return "the page could not be loaded";
  }
  if (!doc) return "the page could not be loaded"; // the browser's own error page
  if (doc.contentType === "text/html") return "";
  const text = doc.body?.textContent || "";
  try {
    const detail = JSON.parse(text).detail;
    if (detail) return typeof detail === "string" ? detail : JSON.stringify(detail);
  } catch {
    // not the API's JSON
  }
  return text.trim().slice(0, 200) || `the server sent ${doc.contentType}`;
}

/** The tab was opened: load the view of the run on show, once. */
export function vizShown() {
  const run = app.run;
  if (!run || shownRun === run.id) return;
  shownRun = run.id;
  const url = run.links?.viz;
  if (!url) {
    unavailable("this server has no 3D view");
    return;
  }
  const loading = h("p", { class: "hint", role: "status" }, "Loading the 3D view…");
  const frame = h("iframe", { class: "viz-frame", src: url, title: "3D view of the run", dataset: { testid: "viz-frame" } });
  frame.addEventListener("load", () => {
    if (shownRun !== run.id || !frame.isConnected) return;
    const problem = problemOf(frame);
    if (problem) unavailable(problem);
    else loading.remove();
  });
  fill(
    panel,
    h("p", { class: "panel-bar" }, h("a", { href: url, target: "_blank", rel: "noopener" }, "Open the 3D view in a new tab"), loading),
    frame,
  );
}
