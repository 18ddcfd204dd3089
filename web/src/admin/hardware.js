// Hardware: the robots on the bench (GET /api/admin/robots: kind, address, connection; in
// service or not, removed), a robot registered (POST), each robot's queue (GET /api/hardware:
// instructors see who holds each place) with move-up and skip, and the rosserial listener's
// port and problems (GET /api/admin/status "hardware"). Polled every 2 s while the section is
// shown; rows are redrawn with keepFocus, so keyboard focus stays on the same control.

import { api } from "../common/api.js";
import { h } from "../common/dom.js";
import { $, busy, clearError, clearRowError, duration, keepFocus, rowError, shortId, showError } from "./dom.js";
import { subscribe, userName } from "./state.js";

const POLL_MS = 2000;
const TRANSPORT = { crowbot: "rosserial over WiFi", turtlebot: "Create OI on a serial port" };
const LIMITS = ["max_linear_m_s", "max_angular_rad_s", "max_linear_accel_m_s2", "max_angular_accel_rad_s2"];

let visible = false;
let paused = false;
let timer = null;
let robots = []; // GET /api/admin/robots
let benches = new Map(); // name -> GET /api/hardware's robot (its queue)
let hardware = null; // /api/admin/status "hardware"
let drawn = ""; // what the tables show: redrawn only when it changed (a click is never lost)

function who(userId) {
  const name = userName(userId);
  return name ? h("span", { title: userId }, name) : h("code", { title: userId }, shortId(userId));
}

// health.state (server/hardware/health.py): connected / syncing / stale / disconnected.
function connectionCell(robot) {
  const text = robot.connection || "not connected";
  const state = robot.health ? robot.health.state : "disconnected";
  const cls = state === "disconnected" ? "conn-off" : text === "connected" ? "conn-ok" : "conn-warn";
  const ago = robot.health ? robot.health.last_heard_s_ago : null;
  const title = ago === null || ago === undefined ? "" : `last heard ${ago.toFixed(1)} s ago`;
  return h("td", { class: "reason" }, h("span", { class: `conn ${cls}`, title }, text));
}

// ------------------------------------------------------------------------------ robots
function robotRow(robot) {
  const actions = h("td", { class: "row-actions" });
  const service = h("input", {
    type: "checkbox",
    id: `service-${robot.name}`,
    "data-testid": "robot-service",
    dataset: { action: "service" },
  });
  service.checked = robot.in_service;
  const serviceCell = h(
    "td",
    {},
    h("label", { class: "check", for: service.id }, service, h("span", {}, robot.in_service ? "in service" : "out of service")),
  );
  service.addEventListener("change", async () => {
    clearRowError(serviceCell);
    try {
      await api(`/api/admin/robots/${encodeURIComponent(robot.name)}`, { method: "PATCH", body: { in_service: service.checked } });
      await poll();
    } catch (error) {
      service.checked = !service.checked;
      rowError(serviceCell, error);
    }
  });
  const remove = h(
    "button",
    {
      type: "button",
      class: "danger small-btn",
      "data-testid": "robot-remove",
      dataset: { action: "remove" },
      "aria-label": `Remove ${robot.name}`,
    },
    "Remove",
  );
  remove.addEventListener("click", () => {
    if (!window.confirm(`Remove '${robot.name}' from the bench? Its runs stay; students in its queue lose their place.`)) return;
    busy(remove, async () => {
      clearRowError(actions);
      try {
        await api(`/api/admin/robots/${encodeURIComponent(robot.name)}`, { method: "DELETE" });
        $("#h-robots").focus();
        await poll();
      } catch (error) {
        rowError(actions, error);
      }
    });
  });
  actions.append(remove);
  const queue = benches.get(robot.name)?.queue?.places || [];
  const address = robot.baud ? `${robot.address} at ${robot.baud} baud` : robot.address;
  return h(
    "tr",
    { dataset: { key: robot.name, name: robot.name }, class: robot.in_service ? "" : "disabled" },
    h("th", { scope: "row" }, h("code", {}, robot.name)),
    h("td", {}, robot.kind, h("br"), h("span", { class: "muted small" }, TRANSPORT[robot.kind] || robot.transport)),
    h("td", {}, h("code", {}, address), h("br"), h("span", { class: "muted small" }, `watchdog ${duration(robot.watchdog_s)}`)),
    connectionCell(robot),
    serviceCell,
    h("td", {}, queue.length ? `${queue.length} in the queue` : "empty"),
    actions,
  );
}

function renderRobots() {
  const body = $("#robots-table tbody");
  keepFocus(body, () => body.replaceChildren(...robots.map(robotRow)));
  $("#robots-empty").hidden = robots.length > 0;
  const hw = hardware || {};
  $("#hw-listening").textContent = hw.rosserial_port
    ? `CrowBots connect to this server's rosserial port ${hw.rosserial_port} (listening: ${hw.listening}).`
    : `rosserial is not listening${hw.listening && hw.listening !== "yes" ? `: ${hw.listening}` : ""}.`;
  const problems = Object.entries(hw.problems || {});
  $("#hw-problems").replaceChildren(
    ...(problems.length
      ? [
          h("h3", {}, "Problems"),
          h(
            "ul",
            { class: "problems" },
            problems.flatMap(([name, lines]) => lines.map((line) => h("li", {}, h("code", {}, name), ": ", line))),
          ),
        ]
      : []),
  );
}

// ------------------------------------------------------------------------------ queues
function queueAction(label, testid, robot, place, path, body, cell) {
  const button = h(
    "button",
    {
      type: "button",
      class: testid === "queue-skip" ? "danger small-btn" : "secondary small-btn",
      "data-testid": testid,
      dataset: { action: testid },
      "aria-label": `${label}: ${userName(place.user_id) || shortId(place.user_id)} on ${robot.name}`,
    },
    label,
  );
  button.addEventListener("click", () =>
    busy(button, async () => {
      clearRowError(cell);
      try {
        await api(`/api/admin/hardware/${encodeURIComponent(robot.name)}/queue/${path}`, { method: "POST", body });
        await poll();
      } catch (error) {
        rowError(cell, error);
      }
    }),
  );
  return button;
}

function estopButton(runId, cell) {
  const button = h(
    "button",
    {
      type: "button",
      class: "estop small-btn",
      "data-testid": "queue-estop",
      dataset: { action: "estop" },
      "aria-label": `Emergency stop of run ${shortId(runId)}`,
    },
    "Emergency stop",
  );
  button.addEventListener("click", () =>
    busy(button, async () => {
      clearRowError(cell);
      try {
        await api(`/api/runs/${encodeURIComponent(runId)}/estop`, { method: "POST" });
        await poll();
      } catch (error) {
        rowError(cell, error);
      }
    }),
  );
  return button;
}

function waitText(place) {
  if (place.state === "offered") return "their turn: to start";
  if (place.state === "running") return "has the robot";
  return `starts in at most ${duration(place.estimated_wait_s)}`;
}

function placeRow(robot, place, waitingIndex) {
  const cell = h("td", { class: "row-actions" });
  if (place.state === "waiting" && waitingIndex > 1) {
    // move counts among the waiting students: up one is their index less one
    cell.append(queueAction("Move up", "queue-move", robot, place, "move", { user_id: place.user_id, position: waitingIndex - 1 }, cell), " ");
  }
  if (place.state === "running" && place.run_id) {
    cell.append(
      h("a", { href: `/?run=${encodeURIComponent(place.run_id)}`, target: "_blank", rel: "noopener", "aria-label": `Watch run ${shortId(place.run_id)} (new tab)` }, "Watch"),
      " ",
      estopButton(place.run_id, cell),
    );
  } else {
    cell.append(queueAction("Skip", "queue-skip", robot, place, "skip", { user_id: place.user_id }, cell));
  }
  return h(
    "tr",
    { dataset: { key: `${robot.name}|${place.user_id}`, userId: place.user_id, state: place.state } },
    h("td", { class: "num" }, String(place.position)),
    h("td", {}, who(place.user_id)),
    h("td", {}, h("span", { class: `state state-${place.state === "offered" ? "starting" : place.state === "running" ? "running" : "paused"}` }, place.state), " ", h("span", { class: "muted small wait" }, waitText(place))),
    cell,
  );
}

function queueBlock(robot) {
  const bench = benches.get(robot.name);
  const queue = bench?.queue || { places: [] };
  let waiting = 0;
  const rows = queue.places.map((place) => placeRow(robot, place, place.state === "waiting" ? ++waiting : 0));
  const headingId = `h-queue-${robot.name}`;
  return h(
    "section",
    { class: "queue", "data-testid": "robot-queue", dataset: { name: robot.name } },
    h(
      "h3",
      { id: headingId },
      h("code", {}, robot.name),
      " ",
      h("span", { class: "muted small" }, `${queue.places.length} in the queue · slot ${duration(queue.slot_s)} · start within ${duration(queue.start_within_s)}${robot.in_service ? "" : " · out of service: the queue waits"}`),
    ),
    rows.length
      ? h(
          "div",
          { class: "table-wrap" },
          h(
            "table",
            { "aria-labelledby": headingId },
            h("thead", {}, h("tr", {}, h("th", { scope: "col" }, "#"), h("th", { scope: "col" }, "Student"), h("th", { scope: "col" }, "State"), h("th", { scope: "col" }, h("span", { class: "sr-only" }, "Actions")))),
            h("tbody", {}, rows),
          ),
        )
      : h("p", { class: "muted small" }, "Nobody is waiting."),
  );
}

function renderQueues() {
  const box = $("#robot-queues");
  keepFocus(box, () =>
    box.replaceChildren(...(robots.length ? robots.map(queueBlock) : [h("p", { class: "muted" }, "No robot, no queue.")])),
  );
}

/** Redraw what changed; the estimated waits (they change every poll while a robot runs) are
 * updated in place. */
function draw(force = false) {
  const places = [...benches.values()].map((b) => b.queue.places.map(({ estimated_wait_s, ...rest }) => rest));
  const now = JSON.stringify([robots, places, hardware]);
  if (force || now !== drawn) {
    drawn = now;
    renderRobots();
    renderQueues();
    return;
  }
  for (const bench of benches.values()) {
    for (const place of bench.queue.places) {
      const row = $(`#robot-queues tr[data-key="${CSS.escape(`${bench.name}|${place.user_id}`)}"] .wait`);
      if (row) row.textContent = waitText(place);
    }
  }
}

// ------------------------------------------------------------------------------ polling
async function poll() {
  try {
    const [inventory, bench, status] = await Promise.all([api("/api/admin/robots"), api("/api/hardware"), api("/api/admin/status")]);
    clearError($("#hw-error"));
    robots = inventory.robots;
    benches = new Map(bench.robots.map((r) => [r.name, r]));
    hardware = status.hardware || null;
    draw();
    $("#hw-updated").textContent = `updated ${new Date().toLocaleTimeString()}`;
  } catch (error) {
    showError($("#hw-error"), error);
  }
}

function schedule() {
  clearTimeout(timer);
  timer = null;
  if (!visible || paused || document.hidden) return;
  timer = setTimeout(async () => {
    await poll();
    schedule();
  }, POLL_MS);
}

// ------------------------------------------------------------------------------ the form
function kindChanged(form) {
  const serial = form.elements.kind.value === "turtlebot";
  for (const element of form.querySelectorAll(".only-serial")) element.hidden = !serial;
  form.elements.baud.disabled = !serial;
  $("#robot-address-label").replaceChildren(
    "Address ",
    h("span", { class: "muted" }, serial ? "(the serial port, e.g. /dev/ttyUSB0)" : "(the CrowBot's IP, as it connects)"),
  );
  form.elements.address.placeholder = serial ? "/dev/ttyUSB0" : "192.168.1.50";
}

async function register(form) {
  clearError(form);
  const values = form.elements;
  const body = { name: values.name.value.trim(), kind: values.kind.value, address: values.address.value.trim() };
  if (body.kind === "turtlebot") body.baud = Number(values.baud.value);
  if (values.watchdog_s.value !== "") body.watchdog_s = Number(values.watchdog_s.value);
  const given = LIMITS.filter((name) => values[name].value !== "");
  if (given.length && given.length < LIMITS.length) {
    const missing = LIMITS.find((name) => values[name].value === "");
    values[missing].setCustomValidity("give all four limits, or none");
    values[missing].reportValidity();
    values[missing].addEventListener("input", () => values[missing].setCustomValidity(""), { once: true });
    return;
  }
  if (given.length) body.limits = Object.fromEntries(LIMITS.map((name) => [name, Number(values[name].value)]));
  try {
    await api("/api/admin/robots", { method: "POST", body });
    form.reset();
    kindChanged(form);
    await poll();
    $(`#robots-table tr[data-name="${CSS.escape(body.name)}"]`)?.classList.add("flash");
    values.name.focus();
  } catch (error) {
    showError(form, error);
  }
}

export function initHardware() {
  subscribe("users", () => draw(true));
  $("#h-robots").tabIndex = -1;
  const form = $("#robot-form");
  form.elements.kind.addEventListener("change", () => kindChanged(form));
  kindChanged(form);
  form.addEventListener("submit", (event) => {
    event.preventDefault();
    busy(event.submitter, () => register(form));
  });
  const pause = $("#hw-pause");
  pause.addEventListener("click", () => {
    paused = !paused;
    pause.setAttribute("aria-pressed", String(paused));
    pause.textContent = paused ? "Resume updates" : "Pause updates";
    if (!paused) poll();
    schedule();
  });
  document.addEventListener("visibilitychange", () => {
    if (!document.hidden && visible && !paused) poll();
    schedule();
  });
}

/** The Hardware section is shown (true) or left (false): polling follows. */
export function showHardware(show) {
  visible = show;
  if (show) poll();
  schedule();
}
