// Live plots: click a topic, then its fields (numeric leaves of the message, arrays by index);
// each plotted topic gets a chart of its fields against time, cursors in step across charts, as
// the papers' figures of distance, light, errors and control actions. Live samples come over
// the websocket at 20 Hz at most; when the run ends (or for a run opened from history) each
// plotted topic is redrawn from the run's CSV export, every sample at full rate.

import uPlot from "uplot";
import "uplot/dist/uPlot.min.css";
import { apiText } from "../common/api.js";
import { byId, fill, h } from "../common/dom.js";
import { csvFileName, csvSamples, getter, leaves } from "../common/fields.js";
import { app, on, robotTopics, want } from "./state.js";

const PLOT_RATE_HZ = 20; // [Hz] telemetry of a plotted topic: smooth enough, cheap to send
const REDRAW_MS = 200; // [ms] at most five redraws a second per chart
const MAX_SAMPLES = 20000; // per topic in the browser; 20 Hz for 16 minutes
const MAX_BIG_SAMPLES = 2000; // per topic whose messages are large (scans, maps)
const BIG_MESSAGE_CHARS = 2000;
const COLORS = ["#1d4ed8", "#dc2626", "#059669", "#d97706", "#7c3aed", "#0891b2", "#db2777", "#4b5563"];
const OWNER = "plots";

const panel = byId("panel-plots");
const topicList = h("ul", { class: "topic-list", dataset: { testid: "topic-list" }, "aria-label": "Topics" });
const fieldBox = h("div", { class: "field-box" });
const chartArea = h("div", { class: "plot-area", dataset: { testid: "plot-area" } });
const note = h("p", { class: "plot-note", role: "status" });

/** topic -> {type, samples: [{time_s, msg}], fromCsv: bool, loading: Promise|null} */
const topics = new Map();
/** topic -> {paths: [path], figure, chart, timer} in the order they were added */
const plotted = new Map();
let selected = null;
let recorded = false; // the run on show has ended: its CSV files hold every sample
let csvTopics = null; // topic names that have a CSV file (for an ended run)
let xMax = 0; // [s] the newest time on any chart: all charts span 0..xMax, so they line up

export function initPlots() {
  fill(
    panel,
    h(
      "div",
      { class: "plots-side" },
      h("h3", {}, "Topics"),
      topicList,
      fieldBox,
      h("button", { type: "button", class: "small", onclick: clearPlots, dataset: { testid: "clear-plots" } }, "Clear plots"),
    ),
    h("div", { class: "plots-main" }, note, chartArea),
  );
  new ResizeObserver(resizeCharts).observe(chartArea);
  on("target", ({ target }) => {
    for (const topic of [...plotted.keys()]) removeChart(topic);
    topics.clear();
    selected = null;
    recorded = false;
    csvTopics = null;
    xMax = 0;
    note.textContent = "";
    for (const t of robotTopics(target.robot)) topicEntry(t.name, t.type);
    for (const { topic, path } of savedSelection(target.robot)) addPath(topic, path, { save: false });
    renderTopics();
    renderFields();
  });
  on("run-shown", ({ live }) => {
    recorded = !live;
    csvTopics = null;
    xMax = 0;
    for (const entry of topics.values()) Object.assign(entry, { samples: [], fromCsv: false, loading: null });
    note.textContent = live ? "" : "Loading the run's recording…";
    for (const topic of plotted.keys()) redraw(topic);
    renderFields();
    if (!live) return;
    for (const topic of plotted.keys()) want(OWNER, topic, PLOT_RATE_HZ);
    if (selected) want(OWNER, selected, PLOT_RATE_HZ);
  });
  on("run-topic", ({ topic, msg_type }) => {
    const known = topics.get(topic);
    if (known && (known.type || !msg_type)) return;
    topicEntry(topic, msg_type).type = msg_type;
    renderTopics();
  });
  on("telemetry", ({ frame }) => receive(frame));
  on("run-ended", ({ run }) => loadRecording(run));
}

function topicEntry(name, type) {
  if (!topics.has(name)) topics.set(name, { type, samples: [], fromCsv: false, loading: null });
  return topics.get(name);
}

function receive(frame) {
  const entry = topicEntry(frame.topic, frame.msg_type);
  if (entry.fromCsv || frame.msg === null || frame.msg === undefined) return;
  const samples = entry.samples;
  samples.push({ time_s: frame.time_s, msg: frame.msg });
  if (samples.length === 1) {
    entry.cap = JSON.stringify(frame.msg).length > BIG_MESSAGE_CHARS ? MAX_BIG_SAMPLES : MAX_SAMPLES;
    if (frame.topic === selected) renderFields();
  }
  if (samples.length > entry.cap * 1.1) samples.splice(0, samples.length - entry.cap);
  if (plotted.has(frame.topic)) {
    xMax = Math.max(xMax, frame.time_s);
    scheduleRedraw(frame.topic);
  }
}

/** The run has ended: every sample of the plotted (and the selected) topics, from its CSV. */
async function loadRecording(run) {
  recorded = true;
  try {
    const listing = JSON.parse(await apiText(`/api/runs/${run.id}/csv`));
    if (app.run?.id !== run.id) return;
    const byFile = new Map([...topics.keys()].map((name) => [csvFileName(name), name]));
    csvTopics = new Set(listing.files.map((f) => byFile.get(f.name) || f.name.replace(/\.csv$/, "").replaceAll("__", "/")));
    for (const name of csvTopics) topicEntry(name, topics.get(name)?.type || "");
    note.textContent = "";
  } catch (error) {
    note.textContent = `No recorded samples: ${error.message}`;
    return;
  }
  renderTopics();
  const wanted = new Set([...plotted.keys(), selected].filter(Boolean));
  await Promise.all([...wanted].map((topic) => fromCsv(topic, run.id)));
}

async function fromCsv(topic, runId) {
  const entry = topics.get(topic);
  if (!entry || entry.fromCsv || !csvTopics?.has(topic)) return;
  entry.loading ||= apiText(`/api/runs/${runId}/csv/${encodeURIComponent(csvFileName(topic))}`)
    .then((text) => {
      if (app.run?.id !== runId) return;
      entry.samples = csvSamples(text);
      entry.fromCsv = true;
      if (plotted.has(topic) && entry.samples.length) xMax = Math.max(xMax, entry.samples[entry.samples.length - 1].time_s);
    })
    .catch((error) => {
      note.textContent = `${topic}: ${error.message}`;
    })
    .finally(() => {
      entry.loading = null;
    });
  await entry.loading;
  for (const name of plotted.keys()) redraw(name); // the common time span may have grown
  if (topic === selected) renderFields();
}

function renderTopics() {
  const names = [...topics.keys()].sort((a, b) => a.localeCompare(b));
  fill(
    topicList,
    names.map((name) => {
      const entry = topics.get(name);
      const absent = recorded && csvTopics && !csvTopics.has(name);
      return h(
        "li",
        {},
        h(
          "button",
          {
            type: "button",
            class: `topic-item${plotted.has(name) ? " plotted" : ""}`,
            "aria-pressed": String(name === selected),
            dataset: { testid: "topic-item", topic: name },
            disabled: absent,
            onclick: () => select(name),
          },
          h("span", { class: "topic-name" }, name),
          h("span", { class: "topic-type" }, entry.type.replace(/^\w+_msgs\//, "")),
        ),
      );
    }),
  );
}

function select(topic) {
  if (selected && selected !== topic && !plotted.has(selected)) want(OWNER, selected, 0);
  selected = topic;
  if (app.live) want(OWNER, topic, PLOT_RATE_HZ);
  if (recorded && app.run) fromCsv(topic, app.run.id);
  renderTopics();
  renderFields();
}

function renderFields() {
  if (!selected) {
    fill(fieldBox, h("p", { class: "hint" }, "Click a topic to see its fields."));
    return;
  }
  const entry = topics.get(selected);
  const last = entry?.samples[entry.samples.length - 1];
  const chosen = new Set(plotted.get(selected)?.paths || []);
  let body;
  if (last) {
    body = h(
      "ul",
      { class: "field-list", dataset: { testid: "field-list" }, "aria-label": `Fields of ${selected}` },
      leaves(last.msg).map((leaf) => (leaf.array ? arrayField(leaf, chosen) : field(leaf.path, chosen.has(leaf.path)))),
      [...chosen].filter((path) => /\[\d+\]$/.test(path) && !leaves(last.msg).some((l) => l.path === path)).map((path) => field(path, true)),
    );
  } else if (entry?.loading) body = h("p", { class: "hint" }, "Loading…");
  else if (app.live) body = h("p", { class: "hint" }, `Waiting for a message on ${selected}…`);
  else body = h("p", { class: "hint" }, app.run ? `No messages on ${selected} in this run.` : "Run once to see this topic's fields.");
  fill(fieldBox, h("h3", {}, `Fields of ${selected}`), body);
}

function field(path, pressed) {
  return h(
    "li",
    {},
    h(
      "button",
      { type: "button", class: "field", "aria-pressed": String(pressed), dataset: { testid: "topic-field", field: path }, onclick: () => togglePath(selected, path) },
      path,
    ),
  );
}

function arrayField(leaf, chosen) {
  const input = h("input", { type: "number", min: 0, max: leaf.length - 1, value: 0, class: "index", "aria-label": `Index into ${leaf.path} (0 to ${leaf.length - 1})` });
  return h(
    "li",
    { class: "array-field" },
    h("span", {}, `${leaf.path}[0…${leaf.length - 1}]`),
    input,
    h(
      "button",
      {
        type: "button",
        class: "small",
        onclick: () => {
          const index = Math.max(0, Math.min(leaf.length - 1, Math.trunc(Number(input.value) || 0)));
          const path = `${leaf.path}[${index}]`;
          if (!chosen.has(path)) togglePath(selected, path);
        },
      },
      "Plot",
    ),
  );
}

function togglePath(topic, path) {
  const chart = plotted.get(topic);
  if (chart?.paths.includes(path)) {
    chart.paths = chart.paths.filter((p) => p !== path);
    if (!chart.paths.length) removeChart(topic);
    else rebuildChart(topic);
  } else addPath(topic, path);
  saveSelection();
  renderTopics();
  renderFields();
}

function addPath(topic, path, { save = true } = {}) {
  topicEntry(topic, "");
  if (!plotted.has(topic)) {
    const figure = h("figure", { class: "chart", dataset: { testid: "plot", topic } });
    const remove = h("button", { type: "button", class: "small chart-close", "aria-label": `Remove the plot of ${topic}`, onclick: () => (removeChart(topic), saveSelection(), renderTopics(), renderFields()) }, "×");
    figure.append(h("figcaption", {}, topic, remove));
    chartArea.append(figure);
    plotted.set(topic, { paths: [], figure, chart: null, timer: null });
    if (app.live) want(OWNER, topic, PLOT_RATE_HZ);
    if (recorded && app.run) fromCsv(topic, app.run.id);
  }
  plotted.get(topic).paths.push(path);
  rebuildChart(topic);
  if (save) saveSelection();
}

function removeChart(topic) {
  const chart = plotted.get(topic);
  if (!chart) return;
  chart.chart?.destroy();
  chart.figure.remove();
  clearTimeout(chart.timer);
  plotted.delete(topic);
  if (topic !== selected) want(OWNER, topic, 0);
  resizeCharts();
}

function clearPlots() {
  for (const topic of [...plotted.keys()]) removeChart(topic);
  saveSelection();
  renderTopics();
  renderFields();
}

function chartSize() {
  const width = chartArea.clientWidth - 8;
  const count = Math.max(1, plotted.size);
  const height = Math.max(130, Math.min(260, (chartArea.clientHeight - count * 44) / count));
  return { width: Math.max(200, width), height: Math.floor(height) };
}

function rebuildChart(topic) {
  const chart = plotted.get(topic);
  chart.chart?.destroy();
  const options = {
    ...chartSize(),
    scales: { x: { time: false, range: (u, min, max) => [0, Math.max(max || 0, xMax) || 1] } },
    cursor: { sync: { key: "robodojo-plots" } },
    axes: [{ label: "time [s]", labelSize: 18, size: 36 }, { size: 56 }],
    series: [{ label: "t [s]", value: (u, v) => (v === null || v === undefined ? "-" : v.toFixed(2)) }].concat(
      chart.paths.map((path, index) => ({ label: path, stroke: COLORS[index % COLORS.length], width: 1.5, spanGaps: true })),
    ),
  };
  chart.chart = new uPlot(options, data(topic), chart.figure);
  resizeCharts();
}

function data(topic) {
  const samples = topics.get(topic)?.samples || [];
  const x = samples.map((s) => s.time_s);
  return [x, ...plotted.get(topic).paths.map((path) => {
    const get = getter(path);
    return samples.map((s) => get(s.msg));
  })];
}

function scheduleRedraw(topic) {
  const chart = plotted.get(topic);
  if (!chart || chart.timer) return;
  chart.timer = setTimeout(() => {
    chart.timer = null;
    redraw(topic);
  }, REDRAW_MS);
}

function redraw(topic) {
  const chart = plotted.get(topic);
  if (chart?.chart) chart.chart.setData(data(topic));
}

function resizeCharts() {
  if (!chartArea.clientWidth) return; // the panel is hidden: sized when it shows
  const size = chartSize();
  for (const chart of plotted.values()) chart.chart?.setSize(size);
}

function storeKey(robot) {
  return `robodojo.plots.${robot}`;
}

function savedSelection(robot) {
  try {
    const saved = JSON.parse(localStorage.getItem(storeKey(robot)));
    if (Array.isArray(saved)) return saved.filter((s) => typeof s.topic === "string" && typeof s.path === "string");
  } catch {
    // fall through to the defaults
  }
  return defaultSelection(robot);
}

/** First plots for a robot: its first simple sensor and its velocity command. */
function defaultSelection(robot) {
  const list = robotTopics(robot);
  const sensor = list.find((t) => t.direction === "publish" && t.type.startsWith("std_msgs/"));
  const velocity = list.find((t) => t.direction === "subscribe" && t.type === "geometry_msgs/Twist");
  const out = [];
  if (sensor) out.push({ topic: sensor.name, path: sensor.type.endsWith("MultiArray") ? "data[0]" : "data" });
  if (velocity) out.push({ topic: velocity.name, path: "linear.x" }, { topic: velocity.name, path: "angular.z" });
  return out;
}

function saveSelection() {
  if (!app.target) return;
  const selection = [...plotted.entries()].flatMap(([topic, chart]) => chart.paths.map((path) => ({ topic, path })));
  localStorage.setItem(storeKey(app.target.robot), JSON.stringify(selection));
}
