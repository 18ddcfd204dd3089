// Server status: active runs, sandbox processes, CPU and memory, polled every 5 s while the page
// is visible (a line in the header; cards on the Status section).

import { api } from "../common/api.js";
import { h } from "../common/dom.js";
import { $, clearError, duration, showError } from "./dom.js";

const POLL_MS = 5000;
let timer = null;
let running = false;
let lastStatus = null; // the newest /api/admin/status answer
// How many live runs the Runs section lists now (null: it is not polling). The header counts
// these when it can: the server's count comes every 5 s and may lag the list (it once said
// "0 active runs" beside a running run).
let listedRuns = null;

function card(title, value, ...lines) {
  return h(
    "div",
    { class: "card" },
    h("h2", {}, title),
    h("p", { class: "big" }, value),
    ...lines.filter(Boolean).map((line) => h("p", { class: "muted small" }, line)),
  );
}

function hardwareCard(hw) {
  if (!hw) return null;
  const problems = Object.values(hw.problems || {}).reduce((n, lines) => n + lines.length, 0);
  return card(
    "Hardware",
    hw.rosserial_port ? `port ${hw.rosserial_port}` : "off",
    `rosserial listening: ${hw.listening ?? "?"}`,
    problems ? `${problems} problem${problems === 1 ? "" : "s"}: see Hardware` : "no problems",
  );
}

// Where runs execute: each worker process (or cluster worker) with its load, and the web
// process itself when it runs some (every run with --workers 0; real robots' runs beside worker
// processes, with no capacity of its own: a robot takes one run at a time).
function workersCard(workers) {
  if (!workers || !workers.length) return null;
  const pools = workers.filter((w) => w.capacity != null);
  const capacity = pools.reduce((n, w) => n + w.capacity, 0);
  const running = workers.reduce((n, w) => n + (w.running || 0), 0);
  const lines = workers.map((w) => {
    const load = w.capacity == null ? `${w.running} running` : `${w.running}/${w.capacity} running`;
    const warm = w.warm == null ? "" : `, ${w.warm} warm`;
    return `${w.role || "worker"} ${w.id}: ${load}${warm}, ${w.state}`;
  });
  return card("Workers", `${running}/${capacity} runs`, ...lines);
}

function mib(bytes) {
  return bytes == null ? "?" : `${(bytes / 2 ** 20).toFixed(1)} MiB`;
}

// Disk used by runs still on disk (measured as each ended), the budgets, the top students.
function diskCard(disk) {
  if (!disk) return null;
  const budget = (bytes) => (bytes ? mib(bytes) : "none");
  const top = (disk.top_students || [])
    .slice(0, 3)
    .map((s) => `${s.name} ${mib(s.bytes)}`)
    .join(", ");
  const days = disk.retention_days;
  return card(
    "Disk used by runs",
    mib(disk.runs_bytes),
    `budgets: lab ${budget(disk.lab_budget_bytes)}, per student ${budget(disk.student_budget_bytes)}`,
    top ? `most: ${top}` : "no run files yet",
    days ? `retention: files kept ${days} days; ${disk.runs_with_files_removed} run(s) removed`
      : "retention: files kept forever (PUT /api/admin/retention to change)",
  );
}

function render(s) {
  const runs = s.runs || {};
  const byState = Object.entries(runs.active_by_state || {})
    .map(([state, n]) => `${n} ${state}`)
    .join(", ");
  const machine = s.machine || {};
  const server = s.server || {};
  const sandbox = s.sandbox || {};
  const load = (machine.load_average || []).map((x) => x.toFixed(2)).join(" / ");
  const cards = [
    card(
      "Active runs",
      String(runs.active_runs ?? "–"),
      byState || "none",
      `limits: ${runs.max_runs_total ?? "?"} in all, ${runs.max_runs_per_student ?? "?"} per student`,
      `${runs.live_viewers ?? 0} live viewer(s); ${s.stored_active_runs ?? 0} active in the database`,
    ),
    card(
      "Sandbox processes",
      String(sandbox.count ?? runs.sandbox_processes ?? "–"),
      `${sandbox.rss_mib ?? "?"} MiB resident`,
      `${runs.sandbox_processes ?? 0} running student code; ${runs.warm_pool ?? 0} kept warm`,
    ),
    card(
      "CPU",
      `${machine.cpus ?? "?"} core${machine.cpus === 1 ? "" : "s"}`,
      `load average (1, 5, 15 min): ${load || "?"}`,
      `server process: ${server.cpu_percent ?? "?"} % of a core, ${server.threads ?? "?"} threads`,
    ),
    card(
      "Memory",
      `${machine.memory_used_percent ?? "?"} % used`,
      `${machine.memory_available_mib ?? "?"} MiB available`,
      `server process: ${server.rss_mib ?? "?"} MiB resident`,
    ),
    workersCard(runs.workers),
    diskCard(s.disk),
    hardwareCard(s.hardware),
    card(
      "Server",
      `up ${duration(s.uptime_s)}`,
      `database: ${s.database ?? "?"}`,
      s.queues ? `waiting runs: ${s.queues.waiting_runs}; ${s.queues.note || ""}` : null,
    ),
  ];
  $("#status-cards").replaceChildren(...cards.filter(Boolean));
  $("#status-updated").textContent = `Updated ${new Date().toLocaleTimeString()}; every ${POLL_MS / 1000} s.`;
  lastStatus = s;
  renderSummary();
}

/** The header line: the live runs (as listed, else as the server counts them), load, memory. */
function renderSummary() {
  const s = lastStatus || {};
  const machine = s.machine || {};
  const active = listedRuns ?? s.runs?.active_runs;
  const loadNow = machine.load_average ? machine.load_average[0].toFixed(1) : "?";
  const runsText = active == null ? "? active runs" : `${active} active run${active === 1 ? "" : "s"}`;
  $("#status-summary").textContent = `${runsText} · load ${loadNow}/${machine.cpus ?? "?"} · mem ${machine.memory_used_percent ?? "?"} %`;
}

/** The Runs section listed `count` live runs (null: it stopped polling); the header follows. */
export function setListedRuns(count) {
  listedRuns = count;
  renderSummary();
}

async function poll() {
  try {
    const s = await api("/api/admin/status");
    clearError($("#status-error"));
    render(s);
  } catch (error) {
    showError($("#status-error"), error);
  }
}

function schedule() {
  clearTimeout(timer);
  timer = null;
  if (!running || document.hidden) return;
  timer = setTimeout(async () => {
    await poll();
    schedule();
  }, POLL_MS);
}

export function startStatus() {
  running = true;
  poll();
  schedule();
  document.addEventListener("visibilitychange", () => {
    if (!document.hidden && running) poll();
    schedule();
  });
}

export function stopStatus() {
  running = false;
  schedule();
}

export const refreshStatus = poll;
