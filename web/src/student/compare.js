// Sim vs real: a run on a real robot beside the simulation run of the same code that passed its
// gate (GET /api/runs/{id}/comparison). The exercise's checks side by side with the gap in a
// sentence, then one chart per topic with both runs on one time base: simulation solid, robot
// dashed. Shown for the run on show once it has ended, for its owner and for instructors (who
// open a student's run by its id).

import uPlot from "uplot";
import { api } from "../common/api.js";
import { byId, fill, h } from "../common/dom.js";
import { emit, on } from "./state.js";

const PANEL = "panel-compare";
const COLORS = ["#1d4ed8", "#dc2626", "#059669", "#d97706"];
const CHART_HEIGHT = 180; // [px]
const HELD = uPlot.paths.stepped({ align: 1 }); // drawn as the server samples: held, not ramped
const panel = byId(PANEL);
const status = h("p", { class: "hint", role: "status", dataset: { testid: "compare-status" } });
const body = h("div", { class: "compare", dataset: { testid: "compare" } });
let charts = [];
let shown = null; // the run id whose comparison is drawn

export function initCompare() {
  fill(panel, status, body);
  on("run-shown", ({ run, live }) => {
    clear();
    if (!run.links?.comparison) {
      status.textContent = "Open a run on a real robot to compare it with the simulation run of the same code that passed its gate.";
    } else if (live) {
      status.textContent = "The comparison with the simulation run shows when this run has ended.";
    }
  });
  on("run-ended", ({ run }) => run.links?.comparison && load(run));
  new ResizeObserver(resize).observe(panel);
}

/** A history row's "Sim vs real": put the run on show first, then this panel. */
export function showComparison() {
  emit("show-view", { panel: PANEL });
}

function clear() {
  for (const chart of charts) chart.destroy();
  charts = [];
  shown = null;
  fill(body);
}

async function load(run) {
  if (shown === run.id) return;
  clear();
  shown = run.id;
  status.textContent = "Loading the comparison…";
  let report;
  try {
    report = await api(run.links.comparison);
  } catch (error) {
    if (shown === run.id) status.textContent = error.message;
    return;
  }
  if (shown !== run.id) return;
  status.textContent = "";
  render(report);
}

function render(report) {
  fill(
    body,
    h(
      "p",
      { class: "compare-head" },
      `On ${report.robot} (${report.states.hardware}, ${seconds(report.durations_s.hardware)}) against the simulation run `,
      h("a", { href: `/?run=${encodeURIComponent(report.simulation_run)}`, dataset: { testid: "compare-sim-link" } }, report.simulation_run.slice(0, 8)),
      ` (${report.states.simulation}, ${seconds(report.durations_s.simulation)}) that passed its gate.`,
    ),
    report.checks.length ? checkTable(report.checks) : h("p", { class: "hint" }, "Free play has no checks: only the topics are compared."),
    h("p", { class: "hint" }, "Simulation: solid line. Robot: dashed line. Samples held until the next one, on one time base from each run's start."),
  );
  for (const [topic, series] of byTopic(report.series)) body.append(chart(topic, series, report.time_s));
}

function checkTable(checks) {
  const value = (side, unit) => (side.value === null ? "–" : `${format(side.value)}${unit ? ` ${unit}` : ""}${side.passed ? " ✓" : " ✗"}`);
  return h(
    "table",
    { class: "data-table compare-checks", dataset: { testid: "compare-checks" } },
    h("thead", {}, h("tr", {}, h("th", {}, "Check"), h("th", {}, "Simulation"), h("th", {}, "Robot"), h("th", {}, "Gap"))),
    h(
      "tbody",
      {},
      checks.map((c) =>
        h(
          "tr",
          { dataset: { check: c.name } },
          h("td", {}, c.name.replaceAll("_", " ")),
          h("td", {}, value(c.simulation, c.unit)),
          h("td", {}, value(c.hardware, c.unit)),
          h("td", {}, c.sentence.slice(c.sentence.lastIndexOf(": ") + 2)),
        ),
      ),
    ),
  );
}

function byTopic(series) {
  const topics = new Map();
  for (const s of series) {
    if (!topics.has(s.topic)) topics.set(s.topic, []);
    topics.get(s.topic).push(s);
  }
  return topics;
}

function chart(topic, series, times) {
  const figure = h("figure", { class: "compare-chart", dataset: { testid: "compare-chart", topic } }, h("figcaption", {}, topic));
  const lines = [];
  const data = [times];
  series.forEach((s, index) => {
    const color = COLORS[index % COLORS.length];
    const label = `${s.field}${s.unit ? ` [${s.unit}]` : ""}`;
    for (const [side, dash] of [["simulation", undefined], ["hardware", [6, 4]]]) {
      if (s[side].every((v) => v === null)) continue; // this run has no such topic
      lines.push({ label: `${label} ${side === "hardware" ? "robot" : "sim"}`, stroke: color, width: 1.5, dash, paths: HELD, points: { show: false } });
      data.push(s[side]);
    }
  });
  const options = {
    width: Math.max(200, panel.clientWidth - 16),
    height: CHART_HEIGHT,
    scales: { x: { time: false } },
    cursor: { sync: { key: "robodojo-compare" } },
    axes: [{ label: "time [s]", labelSize: 18, size: 36 }, { size: 56 }],
    series: [{ label: "t [s]" }, ...lines],
  };
  charts.push(new uPlot(options, data, figure));
  return figure;
}

function resize() {
  if (!panel.clientWidth) return; // hidden: sized when it shows
  for (const chart of charts) chart.setSize({ width: Math.max(200, panel.clientWidth - 16), height: CHART_HEIGHT });
}

function format(value) {
  return Math.abs(value) >= 100 ? value.toFixed(0) : value.toPrecision(3).replace(/\.?0+$/, "");
}

function seconds(value) {
  return `${(value || 0).toFixed(1)} s`;
}
