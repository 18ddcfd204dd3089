// Run history of the exercise (or robot, in free play): each run's state, settings and check
// results; "Open" puts it on show again (its plots from its CSV files, its console, graph,
// latency, files and 3D view). Choosing an exercise opens its newest run.

import { api } from "../common/api.js";
import { byId, fill, h, when } from "../common/dom.js";
import { leaveWatch } from "./catalog.js";
import { showComparison } from "./compare.js";
import { checkChip, showRun } from "./runner.js";
import { app, END_STATES, on } from "./state.js";

const LIMIT = 50;
const panel = byId("panel-history");
const list = h("div", { class: "history", dataset: { testid: "run-history" } });
const status = h("p", { class: "hint", role: "status" });
let runs = [];

export function initHistory() {
  fill(panel, h("div", { class: "panel-bar" }, h("button", { type: "button", class: "small", onclick: () => load() }, "Refresh"), status), list);
  on("target", () => load({ openNewest: true }));
  on("run-shown", ({ live }) => (live ? load() : render()));
  on("run-ended", () => load());
}

async function load({ openNewest = false } = {}) {
  const target = app.target;
  // Free play: the robot's runs (the server filters by robot; its exercise runs are left out).
  const query = target.exercise ? `exercise=${encodeURIComponent(target.exercise.id)}&limit=${LIMIT}` : `robot=${encodeURIComponent(target.robot)}&limit=${LIMIT * 2}`;
  let answer;
  try {
    answer = await api(`/api/runs?${query}`);
  } catch (error) {
    status.textContent = error.message;
    return;
  }
  if (app.target !== target) return;
  runs = target.exercise ? answer.runs : answer.runs.filter((r) => !r.exercise).slice(0, LIMIT);
  status.textContent = app.watching
    ? "Your own runs; opening one leaves the run opened by its id."
    : runs.length
      ? ""
      : "No runs yet.";
  render();
  if (!openNewest || app.watching) return; // a run opened by its id stays on show
  const showing = app.run && runs.some((r) => r.id === app.run.id);
  // Free play opens the newest run in the world chosen (the robot's runs span its worlds).
  const newest = runs.find((r) => target.exercise || r.world === target.world);
  if (newest && !showing) showRun(newest);
}

function render() {
  fill(
    list,
    runs.map((run) => {
      const checks = run.checks || [];
      const passed = checks.filter((c) => c.passed).length;
      const current = app.run?.id === run.id;
      return h(
        "article",
        { class: `history-row ${run.state}${current ? " current" : ""}`, "aria-current": current ? "true" : null, dataset: { testid: "history-row", run: run.id } },
        h(
          "div",
          { class: "history-head" },
          h("span", { class: "history-when" }, when(run.created_at)),
          h("span", { class: `state-badge ${run.state}` }, run.state),
          h("span", { class: "history-settings" }, `${run.clock}, ${run.duration_s} s${run.seed !== null && run.seed !== undefined ? `, seed ${run.seed}` : ""}${target(run)}`),
          checks.length ? h("span", { class: `score ${passed === checks.length ? "pass" : "fail"}` }, `${passed}/${checks.length}`) : null,
          h(
            "button",
            { type: "button", class: "small", disabled: current, onclick: () => open(run), dataset: { testid: "history-open" }, "aria-label": `Open the run of ${when(run.created_at)}` },
            current ? "On show" : END_STATES.has(run.state) ? "Open" : "Follow",
          ),
          run.links?.comparison && END_STATES.has(run.state)
            ? h(
                "button",
                { type: "button", class: "small", onclick: () => compare(run, current), dataset: { testid: "history-compare" }, "aria-label": `Compare the robot run of ${when(run.created_at)} with its simulation run` },
                "Sim vs real",
              )
            : null,
        ),
        run.reason && run.state !== "finished" ? h("p", { class: "history-reason" }, run.reason) : null,
        checks.length ? h("div", { class: "checks small" }, checks.map(checkChip)) : null,
      );
    }),
  );
}

/** Put a run on show; from a run opened by its id, back to the student's own code first. */
function open(run) {
  leaveWatch();
  showRun(run);
}

/** A robot run beside its simulation run: put it on show (unless it is), then the Sim vs real view. */
function compare(run, current) {
  if (!current) open(run);
  showComparison();
}

function target(run) {
  return app.target?.exercise ? "" : `, ${run.world}`;
}
