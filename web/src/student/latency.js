// Latency: each node's loop period (p50, p95, p99, max) while the run goes, from the run's
// record; when it has ended, histograms from metrics.json of the loop period, the compute time
// of each wake and the command latency, with the p50 and p99 marked.

import { api } from "../common/api.js";
import { byId, fill, h, seconds, svg } from "../common/dom.js";
import { app, on } from "./state.js";

const MEASURES = {
  period: "loop period",
  compute: "compute time per wake",
  command_latency: "command latency",
};
const WIDTH = 420; // [px] of a histogram's drawing (it scales with the panel)
const HEIGHT = 150;

const panel = byId("panel-latency");
const tableBox = h("div", { class: "latency-table", dataset: { testid: "latency-table" } });
const charts = h("div", { class: "histograms", dataset: { testid: "latency-histograms" } });
const measure = h("select", { id: "latency-measure" }, Object.entries(MEASURES).map(([key, label]) => h("option", { value: key }, label)));
const status = h("p", { class: "hint", role: "status" });
let metrics = null;

export function initLatency() {
  fill(
    panel,
    h("h3", {}, "Loop period per node"),
    tableBox,
    h("div", { class: "panel-bar" }, h("label", { for: "latency-measure" }, "Histogram of "), measure),
    status,
    charts,
  );
  measure.addEventListener("change", drawHistograms);
  on("target", () => reset("Run once to see how regularly each node runs."));
  on("run-shown", ({ live }) => {
    reset(live ? "Histograms come when the run has ended." : "Loading…");
    table(app.run);
  });
  on("run-record", ({ run }) => table(run));
  on("run-ended", ({ run }) => {
    table(run);
    loadMetrics(run.id);
  });
}

function reset(text) {
  metrics = null;
  fill(tableBox);
  fill(charts);
  status.textContent = text;
}

/** Periods: the stored ones of an ended run, else the live ones. */
function table(run) {
  if (!run) return;
  const stored = Object.entries(run.nodes || {}).map(([name, node]) => [name, node.period, node]);
  const live = Object.entries(run.nodes_live || {}).map(([name, node]) => [name, node.period, null]);
  const rows = stored.length ? stored : live;
  if (!rows.length) return;
  fill(
    tableBox,
    h(
      "table",
      { class: "data-table" },
      h("caption", { class: "sr-only" }, "Loop period of each node"),
      h("thead", {}, h("tr", {}, ["node", "wakes", "p50", "p95", "p99", "max", "outcome"].map((c, i) => h("th", { scope: "col", class: i && i < 6 ? "num" : null }, c)))),
      h(
        "tbody",
        {},
        rows.map(([name, period = {}, node]) =>
          h(
            "tr",
            { dataset: { testid: "latency-row", node: name } },
            h("th", { scope: "row" }, name),
            h("td", { class: "num" }, period?.count ?? 0),
            ["p50_s", "p95_s", "p99_s", "max_s"].map((key) => h("td", { class: "num" }, seconds(period?.[key]))),
            h("td", {}, node?.outcome || (app.live ? "running" : "")),
          ),
        ),
      ),
    ),
  );
}

async function loadMetrics(runId) {
  try {
    const loaded = await api(`/api/runs/${runId}/metrics.json`);
    if (app.run?.id !== runId) return;
    metrics = loaded;
    status.textContent = "";
    drawHistograms();
  } catch (error) {
    if (app.run?.id === runId) status.textContent = `No histograms: ${error.message}`;
  }
}

function drawHistograms() {
  if (!metrics) return;
  const key = measure.value;
  const nodes = Object.entries(metrics.nodes || {}).filter(([, node]) => node[key]?.histogram);
  if (!nodes.length) {
    fill(charts, h("p", { class: "hint" }, `No ${MEASURES[key]} was measured.`));
    return;
  }
  fill(charts, nodes.map(([name, node]) => histogram(name, node[key], MEASURES[key])));
}

function histogram(name, summary, what) {
  const { edges_s: edges, counts } = summary.histogram;
  const most = Math.max(1, ...counts);
  const left = 34;
  const bottom = 22;
  const plotWidth = WIDTH - left - 8;
  const plotHeight = HEIGHT - bottom - 8;
  const span = edges[edges.length - 1] - edges[0] || 1;
  const xOf = (value) => left + ((value - edges[0]) / span) * plotWidth;
  const bars = counts.map((count, i) => {
    const x = xOf(edges[i]);
    const barWidth = Math.max(1, xOf(edges[i + 1]) - x - 1);
    const barHeight = (count / most) * plotHeight;
    return svg("rect", { x, y: 8 + plotHeight - barHeight, width: barWidth, height: barHeight, class: "bar" }, svg("title", {}, `${seconds(edges[i])} to ${seconds(edges[i + 1])}: ${count}`));
  });
  const marks = [
    ["p50", summary.p50_s],
    ["p99", summary.p99_s],
  ]
    .filter(([, value]) => Number.isFinite(value))
    .map(([label, value], index) =>
      svg(
        "g",
        { class: `mark ${label}` },
        svg("line", { x1: xOf(value), x2: xOf(value), y1: 8, y2: 8 + plotHeight }),
        // The label sits on the side of the line with more room.
        xOf(value) > left + plotWidth / 2
          ? svg("text", { x: xOf(value) - 3, y: 18 + index * 12, "text-anchor": "end" }, `${label} ${seconds(value)}`)
          : svg("text", { x: xOf(value) + 3, y: 18 + index * 12 }, `${label} ${seconds(value)}`),
      ),
    );
  return h(
    "figure",
    { class: "histogram", dataset: { testid: "latency-histogram", node: name } },
    h("figcaption", {}, `${name}: ${what} (${summary.count} samples)`),
    svg(
      "svg",
      { viewBox: `0 0 ${WIDTH} ${HEIGHT}`, role: "img", "aria-label": `Histogram of ${name}'s ${what}: p50 ${seconds(summary.p50_s)}, p99 ${seconds(summary.p99_s)}` },
      bars,
      marks,
      svg("line", { x1: left, x2: WIDTH - 8, y1: 8 + plotHeight, y2: 8 + plotHeight, class: "axis" }),
      svg("text", { x: left, y: HEIGHT - 6, class: "tick" }, seconds(edges[0])),
      svg("text", { x: WIDTH - 8, y: HEIGHT - 6, class: "tick", "text-anchor": "end" }, seconds(edges[edges.length - 1])),
      svg("text", { x: left - 4, y: 16, class: "tick", "text-anchor": "end" }, String(most)),
      svg("text", { x: left - 4, y: 8 + plotHeight, class: "tick", "text-anchor": "end" }, "0"),
    ),
  );
}
