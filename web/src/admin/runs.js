// Runs: everyone's live runs (polled every 2 s, rows updated in place so keyboard focus stays
// on a Stop button; each has an emergency stop too: a real robot stops at once), and the
// recent runs with filters and paging. Watch opens the student page on the run; 3D opens the
// viser view.

import { api } from "../common/api.js";
import { h } from "../common/dom.js";
import {
  $,
  busy,
  clearError,
  clearRowError,
  cmp,
  duration,
  keepFocus,
  rowError,
  setOptions,
  shortId,
  showError,
  stateBadge,
  timeEl,
} from "./dom.js";
import { exerciseTitle, state, subscribe, userName } from "./state.js";
import { refreshStatus, setListedRuns } from "./status.js";

const LIVE_STATES = ["starting", "running", "paused"]; // the API filters on one state a request
const ACTIVE = new Set(["created", "starting", "running", "paused", "stopping"]);
const POLL_MS = 2000;
const PAGE = 25;

const live = new Map(); // run id -> {row, cells}
let liveTimer = null;
let livePaused = false;
let liveVisible = false;
let recentOffset = 0;
let recentTotal = 0;
let recentRuns = [];
let firstLive = true; // the first poll after showing the section: nothing has changed yet

export const watchUrl = (id) => `/?run=${encodeURIComponent(id)}`;
export const vizUrl = (id) => `/api/runs/${encodeURIComponent(id)}/viz/`;

function who(run) {
  const name = userName(run.user_id);
  return name ? h("span", { title: run.user_id }, name) : h("code", { title: run.user_id }, shortId(run.user_id));
}

function what(run) {
  const place = `${run.robot} in ${run.world}`;
  const bench = run.hardware ? h("span", { class: "hw-badge", title: "a run on a real robot of the bench" }, `real robot ${run.hardware}`) : null;
  if (!run.exercise) return h("span", {}, place, bench ? [" ", bench] : null);
  const title = exerciseTitle(run.exercise);
  return h(
    "span",
    {},
    h("span", { title: run.exercise }, title || run.exercise),
    h("br"),
    h("span", { class: "muted small" }, run.hardware ? run.robot : place),
    bench ? [" ", bench] : null,
  );
}

function links(run) {
  return [
    h(
      "a",
      { href: watchUrl(run.id), target: "_blank", rel: "noopener", "aria-label": `Watch run ${shortId(run.id)} (new tab)` },
      "Watch",
    ),
    " ",
    h(
      "a",
      { href: vizUrl(run.id), target: "_blank", rel: "noopener", "aria-label": `3D view of run ${shortId(run.id)} (new tab)` },
      "3D",
    ),
  ];
}

function stopButton(run, cell, after) {
  const button = h(
    "button",
    {
      type: "button",
      class: "danger small-btn",
      "data-testid": "run-stop",
      dataset: { runId: run.id, action: "stop" },
      "aria-label": `Stop run ${shortId(run.id)}`,
    },
    "Stop",
  );
  button.addEventListener("click", () => {
    if (button.dataset.done) return;
    busy(button, async () => {
      clearRowError(cell);
      try {
        await api(`/api/admin/runs/${encodeURIComponent(run.id)}/stop`, { method: "POST" });
        button.dataset.done = "1"; // stays focusable (and aria-disabled) until its row goes
        button.textContent = "Stopping…";
        after?.();
      } catch (error) {
        rowError(cell, error);
      }
    });
  });
  return button;
}

function estopButton(run, cell, after) {
  const button = h(
    "button",
    {
      type: "button",
      class: "estop small-btn",
      "data-testid": "run-estop",
      dataset: { runId: run.id, action: "estop" },
      "aria-label": `Emergency stop of run ${shortId(run.id)}${run.hardware ? ` on ${run.hardware}` : ""}`,
      title: run.hardware ? `Stops ${run.hardware} now` : "Stops the run now",
    },
    "E-stop",
  );
  button.addEventListener("click", () => {
    if (button.dataset.done) return;
    busy(button, async () => {
      clearRowError(cell);
      try {
        await api(`/api/runs/${encodeURIComponent(run.id)}/estop`, { method: "POST" });
        button.dataset.done = "1"; // stays focusable (and aria-disabled) until its row goes
        button.textContent = "Stopped";
        after?.();
      } catch (error) {
        rowError(cell, error);
      }
    });
  });
  return button;
}

function progress(run) {
  const time = Number(run.time_s) || 0;
  const total = Number(run.duration_s) || 0;
  const bar = h("progress", { max: total || 1, value: Math.min(time, total || 1), "aria-label": "robot time" });
  return [bar, " ", h("span", { class: "small" }, `${duration(time)} of ${duration(total)}`)];
}

// ------------------------------------------------------------------------------ live
function liveRow(run) {
  const actions = h("td", { class: "row-actions" });
  const cells = {
    who: h("td", {}, who(run)),
    what: h("td", {}, what(run)),
    state: h("td", {}, stateBadge(run.state)),
    time: h("td", { class: "nowrap" }, progress(run)),
    actions,
  };
  actions.append(...links(run), " ", stopButton(run, actions, pollLive), " ", estopButton(run, actions, pollLive));
  const row = h(
    "tr",
    { dataset: { runId: run.id } },
    h("th", { scope: "row" }, h("code", { title: run.id }, shortId(run.id))),
    cells.who,
    cells.what,
    cells.state,
    cells.time,
    h("td", {}, timeEl(run.started_at || run.created_at)),
    actions,
  );
  return { row, cells, run };
}

function renderLive(runs) {
  const body = $("#live-table tbody");
  const seen = new Set();
  let changed = false; // a run appeared or ended: the recent list and the status follow
  runs.sort((a, b) => String(b.created_at).localeCompare(String(a.created_at)));
  for (const run of runs) {
    seen.add(run.id);
    let entry = live.get(run.id);
    if (!entry) {
      entry = liveRow(run);
      live.set(run.id, entry);
      changed = true;
    } else {
      if (entry.run.state !== run.state) entry.cells.state.replaceChildren(stateBadge(run.state));
      const bar = entry.cells.time.querySelector("progress");
      bar.value = Math.min(Number(run.time_s) || 0, Number(run.duration_s) || 1);
      entry.cells.time.querySelector("span").textContent = `${duration(run.time_s)} of ${duration(run.duration_s)}`;
      entry.run = run;
    }
  }
  for (const [id, entry] of live) {
    if (!seen.has(id)) {
      if (entry.row.contains(document.activeElement)) $("#h-live").focus();
      entry.row.remove();
      live.delete(id);
      changed = true;
    }
  }
  // Order the rows newest first without moving rows that are already in place.
  let previous = null;
  for (const run of runs) {
    const { row } = live.get(run.id);
    const want = previous ? previous.nextSibling : body.firstChild;
    if (want !== row) body.insertBefore(row, want);
    previous = row;
  }
  $("#live-empty").hidden = runs.length > 0;
  setListedRuns(runs.length);
  $("#live-updated").textContent = `updated ${new Date().toLocaleTimeString()}`;
  if (changed && !firstLive) {
    if (recentOffset === 0) loadRecent();
    refreshStatus();
  }
  firstLive = false;
}

async function pollLive() {
  try {
    const answers = await Promise.all(
      LIVE_STATES.map((s) => api(`/api/admin/runs?state=${s}&limit=500`)),
    );
    clearError($("#live-error"));
    renderLive(answers.flatMap((a) => a.runs));
  } catch (error) {
    showError($("#live-error"), error);
  }
}

function schedule() {
  clearTimeout(liveTimer);
  liveTimer = null;
  if (!liveVisible || livePaused || document.hidden) return;
  liveTimer = setTimeout(async () => {
    await pollLive();
    schedule();
  }, POLL_MS);
}

// ------------------------------------------------------------------------------ recent
function scoreCell(run) {
  if (run.score === null || run.score === undefined) return h("td", { class: "muted" }, "–");
  const checks = run.checks || [];
  const passed = checks.filter((c) => c.passed).length;
  const title = checks
    .map((c) => `${c.passed ? "✓" : "✗"} ${c.name}: ${Number(c.value).toPrecision(3)} ${c.unit || ""} (${cmp(c.comparison)} ${c.threshold})`)
    .join("\n");
  return h(
    "td",
    { title },
    `${Math.round(run.score * 100)} %`,
    checks.length ? h("span", { class: "muted small" }, ` ${passed}/${checks.length} checks`) : null,
  );
}

function recentRow(run) {
  // data-key: a redraw puts focus back on the same control of the same run (keepFocus)
  const actions = h("td", { class: "row-actions" }, ...links(run));
  if (!ACTIVE.has(run.state)) {
    actions.append(" ", h("a", { href: `/api/runs/${encodeURIComponent(run.id)}/recording.mcap`, download: true }, "Recording"));
  } else {
    actions.append(" ", stopButton(run, actions, loadRecent));
  }
  return h(
    "tr",
    { dataset: { runId: run.id, key: run.id } },
    h("th", { scope: "row" }, h("code", { title: run.id }, shortId(run.id))),
    h("td", {}, who(run)),
    h("td", {}, what(run)),
    h("td", {}, stateBadge(run.state), run.reason ? h("div", { class: "muted small reason" }, run.reason) : null),
    scoreCell(run),
    h("td", {}, timeEl(run.created_at)),
    actions,
  );
}

async function loadRecent() {
  const form = $("#runs-filter");
  const params = new URLSearchParams({ limit: String(PAGE), offset: String(recentOffset) });
  for (const key of ["user", "exercise", "state"]) {
    const value = form.elements[key].value;
    if (value) params.set(key, value);
  }
  try {
    const answer = await api(`/api/admin/runs?${params}`);
    clearError($("#recent-error"));
    recentTotal = answer.total;
    recentRuns = answer.runs;
    const body = $("#recent-table tbody");
    keepFocus(body, () => body.replaceChildren(...answer.runs.map(recentRow)));
    $("#recent-empty").hidden = answer.runs.length > 0;
    const last = recentOffset + answer.runs.length;
    $("#recent-count").textContent = recentTotal
      ? `${recentOffset + 1}–${last} of ${recentTotal}`
      : "none";
    $("#recent-newer").disabled = recentOffset === 0;
    $("#recent-older").disabled = last >= recentTotal;
  } catch (error) {
    showError($("#recent-error"), error);
  }
}

function fillFilters() {
  const form = $("#runs-filter");
  setOptions(
    form.elements.user,
    [...state.users].sort((a, b) => a.name.localeCompare(b.name)).map((u) => [u.id, u.email ? `${u.name} (${u.email})` : u.name]),
    { first: ["", "anyone"] },
  );
  setOptions(
    form.elements.exercise,
    state.exercises.map((e) => [e.id, e.title ? `${e.title} (${e.id})` : e.id]),
    { first: ["", "any"] },
  );
}

/** Names arrived or changed: redraw who ran what, keeping the rows (and focus) in place. */
function renameRows() {
  fillFilters();
  for (const entry of live.values()) {
    entry.cells.who.replaceChildren(who(entry.run));
    entry.cells.what.replaceChildren(what(entry.run));
  }
  const body = $("#recent-table tbody");
  if (recentRuns.length) keepFocus(body, () => body.replaceChildren(...recentRuns.map(recentRow)));
}

export function initRuns() {
  subscribe("users", renameRows);
  subscribe("exercises", renameRows);
  $("#h-live").tabIndex = -1;
  $("#runs-filter").addEventListener("submit", (event) => {
    event.preventDefault();
    recentOffset = 0;
    busy(event.submitter, loadRecent);
  });
  $("#recent-newer").addEventListener("click", () => {
    recentOffset = Math.max(0, recentOffset - PAGE);
    loadRecent();
  });
  $("#recent-older").addEventListener("click", () => {
    recentOffset += PAGE;
    loadRecent();
  });
  const pause = $("#live-pause");
  pause.addEventListener("click", () => {
    livePaused = !livePaused;
    pause.setAttribute("aria-pressed", String(livePaused));
    pause.textContent = livePaused ? "Resume updates" : "Pause updates";
    if (!livePaused) pollLive();
    schedule();
  });
  document.addEventListener("visibilitychange", () => {
    if (!document.hidden && liveVisible && !livePaused) pollLive();
    schedule();
  });
}

/** The Runs section is shown (true) or hidden (false): polling follows. */
export function showRuns(visible) {
  liveVisible = visible;
  if (!visible) setListedRuns(null); // not polled any more: the server's count is fresher
  if (visible) {
    firstLive = true;
    pollLive();
    loadRecent();
  }
  schedule();
}
