// The node/topic graph of the run on show, as rqt_graph draws it: nodes as ellipses, topics as
// boxes, an arrow from each publisher to its topic (labelled with the measured rate) and from
// the topic to each subscriber. Layered left to right by distance from the nodes nobody feeds.

import { api } from "../common/api.js";
import { byId, fill, h, svg } from "../common/dom.js";
import { app, emit, on } from "./state.js";

const REFRESH_MS = 2000; // [ms] while the run is live and this panel is open
const COLUMN_GAP = 56; // [px] between layers
const ROW = 54; // [px] between vertices of a layer
const CHAR = 7.2; // [px] width of a character at the graph's font size

const panel = byId("panel-graph");
const drawing = h("div", { class: "graph", dataset: { testid: "graph" } });
const idleToggle = h("input", { type: "checkbox", id: "graph-idle" });
const table = h("div", { class: "graph-table" });
const status = h("p", { class: "hint", role: "status" });
let timer = null;
let last = null;

export function initGraph() {
  fill(
    panel,
    h("div", { class: "panel-bar" }, h("label", { for: "graph-idle" }, idleToggle, " show topics nobody uses"), status),
    drawing,
    h("details", { class: "graph-details" }, h("summary", {}, "As a table"), table),
  );
  idleToggle.addEventListener("change", () => last && draw(last));
  on("run-shown", ({ live }) => {
    clearInterval(timer);
    last = null;
    fill(drawing);
    fill(table);
    status.textContent = "Loading…";
    refresh();
    if (live) timer = setInterval(() => !panel.hidden && refresh(), REFRESH_MS);
  });
  on("run-ended", () => {
    clearInterval(timer);
    refresh();
  });
  on("target", () => {
    clearInterval(timer);
    fill(drawing);
    status.textContent = "Run once to see the graph of its nodes and topics.";
  });
}

export function graphShown() {
  if (app.run) refresh();
}

async function refresh() {
  const run = app.run;
  if (!run) return;
  try {
    const graph = await api(run.links?.graph || `/api/runs/${run.id}/graph`);
    if (app.run?.id !== run.id) return;
    last = graph;
    draw(graph);
    app.graphNodes.set(run.id, graph.nodes);
    emit("run-graph", { run, graph });
    for (const topic of graph.topics) emit("run-topic", { topic: topic.name, msg_type: topic.type });
  } catch (error) {
    if (app.run?.id === run.id) status.textContent = `No graph: ${error.message}`;
  }
}

function rate(topic) {
  return topic.rate_hz ? `${topic.rate_hz >= 10 ? topic.rate_hz.toFixed(0) : topic.rate_hz.toFixed(1)} Hz` : "";
}

/** Vertices with their layer and row, and the edges between them. */
function layout(graph, showIdle) {
  const topics = graph.topics.filter((t) => showIdle || t.publishers.length || t.subscribers.length);
  const vertices = new Map();
  const vertex = (id, kind, label) => {
    if (!vertices.has(id)) vertices.set(id, { id, kind, label, width: label.length * CHAR + (kind === "node" ? 34 : 20), into: [], out: [] });
    return vertices.get(id);
  };
  for (const name of graph.nodes) vertex(`n:${name}`, "node", name);
  const edges = [];
  for (const topic of topics) {
    const t = vertex(`t:${topic.name}`, "topic", topic.name);
    t.topic = topic;
    for (const name of topic.publishers) edges.push({ from: vertex(`n:${name}`, "node", name), to: t, label: rate(topic) });
    for (const name of topic.subscribers) edges.push({ from: t, to: vertex(`n:${name}`, "node", name), label: "" });
  }
  for (const edge of edges) {
    edge.from.out.push(edge.to);
    edge.to.into.push(edge.from);
  }
  // Layers: breadth-first distance from the vertices nothing points at (then from any left).
  const all = [...vertices.values()];
  const queue = all.filter((v) => !v.into.length);
  for (const v of queue) v.layer = 0;
  const visit = () => {
    while (queue.length) {
      const v = queue.shift();
      for (const next of v.out) if (next.layer === undefined) (next.layer = v.layer + 1), queue.push(next);
    }
  };
  visit();
  for (const v of all) if (v.layer === undefined) (v.layer = 0), queue.push(v), visit();
  const layers = [];
  for (const v of all) (layers[v.layer] ||= []).push(v);
  // Two barycentre sweeps: a vertex sits near the mean row of what feeds it.
  for (let sweep = 0; sweep < 2; sweep++) {
    for (const layer of layers) {
      layer.forEach((v, index) => (v.row = index));
      for (const v of layer) {
        const rows = v.into.filter((u) => u.layer < v.layer).map((u) => u.row);
        v.order = rows.length ? rows.reduce((a, b) => a + b, 0) / rows.length : v.row;
      }
      layer.sort((a, b) => a.order - b.order);
      layer.forEach((v, index) => (v.row = index));
    }
  }
  return { layers, edges, hidden: graph.topics.length - topics.length };
}

function draw(graph) {
  const { layers, edges, hidden } = layout(graph, idleToggle.checked);
  const tallest = Math.max(1, ...layers.map((l) => l.length));
  let x = 10;
  for (const layer of layers) {
    const width = Math.max(...layer.map((v) => v.width));
    const offset = ((tallest - layer.length) * ROW) / 2;
    for (const v of layer) {
      v.cx = x + width / 2;
      v.cy = 30 + offset + v.row * ROW;
    }
    x += width + COLUMN_GAP;
  }
  const width = x - COLUMN_GAP + 10;
  const height = tallest * ROW + 20;
  const marker = svg("marker", { id: "arrow", viewBox: "0 0 10 10", refX: 9, refY: 5, markerWidth: 7, markerHeight: 7, orient: "auto-start-reverse" }, svg("path", { d: "M0,0 L10,5 L0,10 z", class: "arrow-head" }));
  const picture = svg(
    "svg",
    { viewBox: `0 0 ${width} ${height}`, width, height, role: "img", "aria-label": `Graph of ${graph.nodes.length} nodes and their topics` },
    svg("defs", {}, marker),
    edges.map((edge) => edgePath(edge)),
    layers.flat().map((v) => vertexShape(v)),
  );
  fill(drawing, picture);
  status.textContent = hidden ? `${hidden} topic(s) with no publisher or subscriber hidden.` : "";
  fill(
    table,
    h(
      "table",
      { class: "data-table" },
      h("thead", {}, h("tr", {}, ["topic", "type", "publishers", "subscribers", "messages", "rate"].map((c) => h("th", { scope: "col" }, c)))),
      h(
        "tbody",
        {},
        graph.topics.map((t) => h("tr", {}, h("td", {}, t.name), h("td", {}, t.type), h("td", {}, t.publishers.join(", ")), h("td", {}, t.subscribers.join(", ")), h("td", { class: "num" }, t.messages), h("td", { class: "num" }, rate(t)))),
      ),
    ),
  );
}

function edgePath({ from, to, label }) {
  const x1 = from.cx + from.width / 2;
  const x2 = to.cx - to.width / 2;
  let d;
  let labelX;
  let labelY;
  if (x2 > x1) {
    const bend = (x2 - x1) / 2;
    d = `M${x1},${from.cy} C${x1 + bend},${from.cy} ${x2 - bend},${to.cy} ${x2},${to.cy}`;
    // The label sits 70% along the curve, where edges fanning out of one node have parted.
    const t = 0.7;
    const [a, b, c, e] = [(1 - t) ** 3, 3 * (1 - t) ** 2 * t, 3 * (1 - t) * t ** 2, t ** 3];
    labelX = a * x1 + b * (x1 + bend) + c * (x2 - bend) + e * x2;
    labelY = (a + b) * from.cy + (c + e) * to.cy - 4;
  } else {
    // Backwards (a cycle): out of the right side, around below, into the left side.
    const low = Math.max(from.cy, to.cy) + ROW * 0.7;
    d = `M${x1},${from.cy} C${x1 + 60},${low} ${x2 - 60},${low} ${x2},${to.cy}`;
    labelX = (x1 + x2) / 2;
    labelY = low - 4;
  }
  return svg(
    "g",
    { class: "edge" },
    svg("path", { d, "marker-end": "url(#arrow)" }),
    label ? svg("text", { x: labelX, y: labelY, "text-anchor": "middle", class: "edge-label" }, label) : null,
  );
}

function vertexShape(v) {
  const title = v.topic ? `${v.topic.name} (${v.topic.type}): ${v.topic.messages} messages${v.topic.rate_hz ? `, ${rate(v.topic)}` : ""}` : `node ${v.label}`;
  const shape =
    v.kind === "node"
      ? svg("ellipse", { cx: v.cx, cy: v.cy, rx: v.width / 2, ry: 17 })
      : svg("rect", { x: v.cx - v.width / 2, y: v.cy - 14, width: v.width, height: 28, rx: 3 });
  const idle = v.topic && !v.topic.messages;
  return svg(
    "g",
    { class: `vertex ${v.kind}${idle ? " idle" : ""}`, dataset: { testid: `graph-${v.kind}`, name: v.label } },
    svg("title", {}, title),
    shape,
    svg("text", { x: v.cx, y: v.cy + 4, "text-anchor": "middle" }, v.label),
  );
}
