// The 3D view of the run on show: the server's viser client for that run, at
// /api/runs/{id}/viz/, in a frame. Loaded when its tab is first opened (WebGL is not free); a
// server without the route answers 404 and the panel says so.

import { probe } from "../common/api.js";
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

/** The tab was opened: load the view of the run on show, once. */
export async function vizShown() {
  const run = app.run;
  if (!run || shownRun === run.id) return;
  shownRun = run.id;
  const url = `/api/runs/${run.id}/viz/`;
  fill(panel, h("p", { class: "hint" }, "Looking for the 3D view…"));
  const available = await probe(url);
  if (shownRun !== run.id) return;
  if (!available.ok) {
    fill(panel, h("p", { class: "hint", dataset: { testid: "viz-unavailable" } }, `3D view not available (${available.detail}).`));
    return;
  }
  fill(
    panel,
    h("p", { class: "panel-bar" }, h("a", { href: url, target: "_blank", rel: "noopener" }, "Open the 3D view in a new tab")),
    h("iframe", { class: "viz-frame", src: url, title: "3D view of the run", dataset: { testid: "viz-frame" } }),
  );
}
