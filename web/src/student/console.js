// The console: what each node printed, live, a line per log frame, filterable by node. A
// traceback's `File "pid.py", line 12` is a link to that line in the editor (a student node's
// file is `<node name>.py`). When a run ends, lines the live view missed are filled in from the
// run's stored logs.

import { api } from "../common/api.js";
import { byId, fill, h } from "../common/dom.js";
import { emit, nodeOf, on } from "./state.js";

const MAX_LINES = 5000; // in the page; the run's full logs stay downloadable
const FRAME = /File "([A-Za-z][A-Za-z0-9_]*)\.py", line (\d+)/;
const ERROR_LINE = /^(Traceback \(most recent call last\)|\w*(Error|Exception|Interrupt)\b)/;

const box = byId("console");
const filter = byId("console-filter");
let pending = []; // lines waiting for the next animation frame
let scheduled = false;
let counts = new Map(); // node -> lines shown live
let runId = null;
let followedLive = false; // the run on show was followed live (so lines may have been missed)

export function initConsole() {
  byId("console-clear").addEventListener("click", () => fill(box));
  filter.addEventListener("change", applyFilter);
  on("run-shown", ({ run, live }) => {
    runId = run.id;
    followedLive = live;
    fill(box);
    pending = [];
    counts = new Map();
    setNodes(Object.keys(run.nodes || {}).concat((run.code || []).map((c) => c.name)));
    if (!live) fillFromStore(run.id, true);
  });
  on("log", ({ node, line }) => add(node, line));
  on("run-ended", ({ run }) => {
    if (followedLive && run.id === runId) fillFromStore(run.id, false);
  });
  on("target", () => {
    fill(box);
    runId = null;
  });
}

function setNodes(names) {
  const current = filter.value;
  const unique = [...new Set(names.filter(Boolean))];
  fill(filter, h("option", { value: "" }, "all"), unique.map((n) => h("option", { value: n }, n)));
  filter.value = unique.includes(current) ? current : "";
}

function add(node, line) {
  counts.set(node, (counts.get(node) || 0) + 1);
  if (node && ![...filter.options].some((o) => o.value === node)) filter.append(h("option", { value: node }, node));
  pending.push([node, line]);
  if (!scheduled) {
    scheduled = true;
    requestAnimationFrame(flush);
  }
}

function flush() {
  scheduled = false;
  const atBottom = box.scrollTop + box.clientHeight >= box.scrollHeight - 24;
  const fragment = document.createDocumentFragment();
  for (const [node, line] of pending) fragment.append(lineElement(node, line));
  pending = [];
  box.append(fragment);
  while (box.childElementCount > MAX_LINES) box.firstElementChild.remove();
  if (atBottom) box.scrollTop = box.scrollHeight;
}

function lineElement(node, text) {
  const element = h("div", { class: `line${ERROR_LINE.test(text.trim()) ? " error" : ""}`, dataset: { node: node || "" } });
  if (node) element.append(h("span", { class: "node-tag" }, node));
  const match = FRAME.exec(text);
  if (match) {
    const [whole, fileNode, lineNumber] = match;
    const index = match.index;
    element.append(
      text.slice(0, index),
      h(
        "button",
        {
          type: "button",
          class: "link",
          dataset: { testid: "traceback-link", node: fileNode, line: lineNumber },
          title: `Show line ${lineNumber} of ${fileNode}.py in the editor`,
          onclick: () => emit("goto-line", { node: nodeOf(`${fileNode}.py`), line: Number(lineNumber) }),
        },
        whole,
      ),
      text.slice(index + whole.length),
    );
    element.classList.add("error");
  } else element.append(text);
  element.hidden = Boolean(filter.value) && filter.value !== (node || "");
  return element;
}

function applyFilter() {
  for (const element of box.children) element.hidden = Boolean(filter.value) && filter.value !== element.dataset.node;
}

/** The run's stored logs (a node's lines together); `always`, or only if lines were missed. */
async function fillFromStore(id, always) {
  let logs;
  try {
    logs = (await api(`/api/runs/${id}/logs`)).nodes;
  } catch (error) {
    if (always) add(null, `(no logs: ${error.message})`);
    return;
  }
  if (id !== runId) return;
  const missed = Object.entries(logs).some(([node, lines]) => lines.length > (counts.get(node) || 0));
  if (!always && !missed) return;
  fill(box);
  pending = [];
  counts = new Map();
  setNodes(Object.keys(logs));
  for (const [node, lines] of Object.entries(logs)) for (const line of lines.slice(-MAX_LINES)) add(node, line);
}
