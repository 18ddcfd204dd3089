// "Real robot": the panel of the bench robots of the target's kind (the exercise's robot, or
// free play's), each with its connection, its queue, Join / Leave and, when the student's
// turn came (their place is "offered"), "Run on the real robot" (POST /api/runs with
// `hardware`; always realtime). GET /api/hardware is polled every 2 s while the panel is open
// (and the page visible). A refusal is said in the panel: the simulation gate (409: this exact
// code has not finished a simulation run of the exercise) as its verdict, with a button to run
// it in simulation; not your turn (429) and a robot that cannot run (422) as the server's
// sentence.
//
// The server's `offered_until_s` is its own monotonic clock, so the countdown ("start within
// N s") runs from when the page first saw the offer (or the join that made it), less one poll:
// it may end a little before the server's, never after.

import { api } from "../common/api.js";
import { byId, fill, h } from "../common/dom.js";
import { runGoing, start, startOnRobot } from "./runner.js";
import { app, on } from "./state.js";

const POLL_MS = 2000;
const OPEN_KEY = "robodojo.hwOpen";
const DEADLINES_KEY = "robodojo.hwOffers"; // "robot|offered_until_s" -> local deadline [ms epoch]

const toggle = byId("real-robot-button");
const panel = byId("hw-panel");
const list = byId("hw-robots");
const note = byId("hw-note");
const gateBox = byId("hw-gate");
const message = byId("hw-message");

let robots = []; // the last GET /api/hardware
let loaded = false;
let pollTimer = null;
let tickTimer = null;
let lastPollMs = 0;
let busy = false; // a join, leave or start is on its way
let offeredAtJoin = null; // the robot whose join was offered the turn at once (exact deadline)
const rows = new Map(); // robot name -> {item, parts}

export function initHardware() {
  // Opened from the keyboard (a click with no pointer: detail 0), focus moves into the panel.
  toggle.addEventListener("click", (event) => setOpen(panel.hidden, { focus: panel.hidden && event.detail === 0 }));
  byId("hw-close").addEventListener("click", () => setOpen(false, { focus: true }));
  panel.addEventListener("keydown", (event) => {
    // Escape is the emergency stop while a run is going; otherwise it closes the panel
    if (event.key === "Escape" && !runGoing()) setOpen(false, { focus: true });
  });
  document.addEventListener("visibilitychange", schedule);
  on("target", () => {
    showGate(null);
    say("");
    render();
  });
  for (const event of ["run-controls", "run-shown", "run-ended"]) on(event, render);
  on("run-ended", ({ run }) => run.hardware && poll()); // the robot went to the next student
  setOpen(localStorage.getItem(OPEN_KEY) === "true");
  if (panel.hidden) poll(); // once: a place held from before opens the panel
}

function setOpen(open, { focus = false } = {}) {
  panel.hidden = !open;
  toggle.setAttribute("aria-expanded", String(open));
  localStorage.setItem(OPEN_KEY, String(open));
  if (open) {
    poll();
    if (focus) panel.focus();
  } else {
    schedule();
    if (focus) toggle.focus();
  }
}

/** Polled while the panel is open, and while the student holds a place (the toggle's badge
 * says when their turn came), unless the page is hidden. */
function schedule() {
  clearTimeout(pollTimer);
  pollTimer = null;
  const holding = robots.some((r) => r.my_position);
  if ((panel.hidden && !holding) || document.hidden) return;
  pollTimer = setTimeout(poll, POLL_MS);
}

async function poll() {
  clearTimeout(pollTimer);
  try {
    const answer = await api("/api/hardware");
    robots = answer.robots || [];
    if (!loaded && panel.hidden && robots.some((r) => r.my_position)) setOpen(true);
    loaded = true;
    if (message.dataset.from === "poll") say("");
    noteOffers();
    lastPollMs = Date.now();
    render();
  } catch (error) {
    if (error.status !== 401) say(`The robots' state could not be loaded: ${error.message}`, "poll");
  } finally {
    schedule();
  }
}

// ------------------------------------------------------------------------------ the countdown
function deadlines() {
  try {
    return JSON.parse(localStorage.getItem(DEADLINES_KEY)) || {};
  } catch {
    return {};
  }
}

/** The offered places of mine seen for the first time get their local deadline: offered since
 * the last poll (2 s ago) at the earliest; a join that was offered at once is exact. */
function noteOffers() {
  const known = deadlines();
  const kept = {};
  const now = Date.now();
  const recent = lastPollMs && now - lastPollMs < 3 * POLL_MS ? lastPollMs : now;
  for (const robot of robots) {
    const place = myPlace(robot);
    if (place?.state !== "offered") continue;
    const key = `${robot.name}|${place.offered_until_s}`;
    const since = offeredAtJoin === robot.name ? now : recent;
    kept[key] = known[key] ?? since + (robot.queue.start_within_s || 60) * 1000;
  }
  offeredAtJoin = null;
  localStorage.setItem(DEADLINES_KEY, JSON.stringify(kept));
}

function secondsLeft(robot) {
  const place = myPlace(robot);
  if (place?.state !== "offered") return null;
  const deadline = deadlines()[`${robot.name}|${place.offered_until_s}`];
  return deadline ? Math.max(0, Math.floor((deadline - Date.now()) / 1000)) : robot.queue.start_within_s;
}

// ------------------------------------------------------------------------------ drawing
function myPlace(robot) {
  if (!robot.my_position) return null;
  return robot.queue.places.find((p) => p.position === robot.my_position) || { position: robot.my_position, state: "waiting" };
}

/** "TurtleBot" of "TurtleBot (Roomba 531 base, ...)". */
function kindTitle(kind) {
  return (app.robots.get(kind)?.title || kind || "robot").split(" (")[0];
}

/** "about 4 min", "about 40 s" */
function about(seconds) {
  if (!Number.isFinite(seconds) || seconds <= 0) return "now";
  if (seconds < 90) return `about ${Math.round(seconds)} s`;
  return `about ${Math.round(seconds / 60)} min`;
}

function connectionOf(robot) {
  if (!robot.in_service) return { cls: "off", text: "out of service" };
  if (robot.connection === "connected") return { cls: "ok", text: "connected" };
  if (robot.connection.startsWith("connected")) return { cls: "warn", text: robot.connection };
  return { cls: "off", text: robot.connection };
}

function row(name) {
  let entry = rows.get(name);
  if (entry) return entry;
  const parts = {
    name: h("strong", { class: "hw-name" }, name),
    kind: h("span", { class: "hw-kind" }),
    connection: h("span", { class: "hw-connection", dataset: { testid: "hw-connection" } }),
    queue: h("span", { class: "hw-queue" }),
    position: h("span", { class: "hw-position", dataset: { testid: "hw-position" }, "aria-live": "polite" }),
    join: h("button", { type: "button", class: "small", dataset: { testid: "hw-join" }, onclick: (e) => isOff(e.currentTarget) || join(name) }, "Join queue"),
    leave: h("button", { type: "button", class: "small", dataset: { testid: "hw-leave" }, onclick: (e) => isOff(e.currentTarget) || leave(name) }, "Leave queue"),
    run: h("button", { type: "button", class: "primary hw-run", dataset: { testid: "hw-run" }, onclick: (e) => isOff(e.currentTarget) || runOn(name) }, "▶ Run on the real robot"),
    why: h("span", { class: "hw-why", id: `hw-why-${name}` }),
  };
  parts.run.setAttribute("aria-describedby", parts.why.id);
  const item = h(
    "li",
    { class: "hw-robot", dataset: { testid: "hw-robot", name } },
    h("div", { class: "hw-line" }, parts.name, parts.kind, parts.connection, parts.queue),
    h("div", { class: "hw-line" }, parts.position, parts.join, parts.leave, parts.run, parts.why),
  );
  entry = { item, parts };
  rows.set(name, entry);
  return entry;
}

function render() {
  if (!app.target) return;
  const kind = app.target.robot;
  const shown = robots.filter((r) => r.kind === kind || r.my_position);
  const slot = robots[0]?.queue?.slot_s;
  note.textContent = `Your code drives the real ${kindTitle(kind)}, in real time${slot ? `, for at most ${about(slot).replace("about ", "")}` : ""}. It must have finished a simulation run of this ${app.target?.exercise ? "exercise" : "robot"} first.`;
  const names = new Set(shown.map((r) => r.name));
  for (const [name, { item }] of rows) {
    if (!names.has(name)) {
      if (item.contains(document.activeElement)) toggle.focus();
      item.remove();
      rows.delete(name);
    }
  }
  if (!shown.length) {
    fill(list, h("li", { class: "hw-none" }, loaded ? `No ${kindTitle(kind)} is on the lab's bench: ask your instructor.` : "Loading the robots…"));
  } else {
    list.querySelector(".hw-none")?.remove();
    let previous = null; // in the server's order, moving no row that is in place (focus stays)
    for (const robot of shown) {
      const { item } = row(robot.name);
      const want = previous ? previous.nextSibling : list.firstChild;
      if (want !== item) list.insertBefore(item, want);
      previous = item;
    }
    for (const robot of shown) drawRow(robot, kind);
  }
  drawToggle();
  clearTimeout(tickTimer);
  if (!panel.hidden && robots.some((r) => myPlace(r)?.state === "offered")) tickTimer = setTimeout(render, 1000);
}

function drawRow(robot, kind) {
  const { item, parts } = row(robot.name);
  const place = myPlace(robot);
  const state = place?.state || "none";
  const connection = connectionOf(robot);
  const sameKind = robot.kind === kind;
  item.dataset.state = state;
  item.dataset.connection = robot.connection;
  parts.kind.textContent = sameKind ? "" : `(a ${kindTitle(robot.kind)})`;
  parts.connection.className = `hw-connection ${connection.cls}`;
  parts.connection.textContent = connection.text;
  parts.queue.textContent = robot.queue.places.length ? `${robot.queue.places.length} in the queue` : "queue empty";
  item.classList.toggle("mine", Boolean(place));
  item.classList.toggle("offered", state === "offered");

  let position = "";
  if (state === "waiting") {
    position = `You are number ${place.position} in the queue: estimated start in ${about(robot.my_estimated_wait_s ?? place.estimated_wait_s)}.`;
  } else if (state === "offered") {
    const left = secondsLeft(robot);
    position = left > 0 ? `Your turn: start within ${left} s` : "Your turn: start now, or it passes to the next student";
  } else if (state === "running") {
    position = "Your run has the robot.";
  }
  parts.position.textContent = position;
  parts.position.hidden = !position;
  parts.position.dataset.position = place ? String(place.position) : "";

  const keep = (button) => document.activeElement === button;
  const joinFocused = keep(parts.join);
  const leaveFocused = keep(parts.leave);
  // aria-disabled, not disabled: a control that is off keeps keyboard focus
  parts.join.hidden = Boolean(place) || !sameKind;
  off(parts.join, busy || !robot.in_service);
  parts.join.title = robot.in_service ? `Wait for your turn on ${robot.name}` : `${robot.name} is out of service`;
  parts.leave.hidden = !place || state === "running";
  off(parts.leave, busy);
  if (joinFocused && parts.join.hidden) parts.leave.focus();
  if (leaveFocused && parts.leave.hidden) (parts.join.hidden ? toggle : parts.join).focus();

  // Why "Run on the real robot" is off, the first reason that holds.
  const why =
    state !== "offered"
      ? place
        ? state === "running"
          ? "your run has the robot"
          : "it is not your turn yet"
        : "join the queue first"
      : !sameKind
        ? `this is a ${kindTitle(robot.kind)}: choose one of its exercises or free play`
        : !robot.in_service
          ? "out of service"
          : robot.connection === "not connected"
            ? "the robot is not connected"
            : app.watching
              ? "go back to your code first"
              : runGoing()
                ? "a run is going"
                : busy
                  ? "starting…"
                  : "";
  off(parts.run, Boolean(why));
  parts.run.hidden = !sameKind && !place;
  parts.why.textContent = why ? `(${why})` : "";
  parts.why.hidden = !why || parts.run.hidden || state === "running";
}

function off(button, isOff) {
  if (isOff) button.setAttribute("aria-disabled", "true");
  else button.removeAttribute("aria-disabled");
}

const isOff = (button) => button.getAttribute("aria-disabled") === "true";

function drawToggle() {
  const offered = robots.find((r) => myPlace(r)?.state === "offered");
  const waiting = robots.find((r) => myPlace(r)?.state === "waiting");
  let badge = "";
  if (offered) badge = " · your turn!";
  else if (waiting) badge = ` · #${waiting.my_position}`;
  toggle.textContent = `Real robot${badge}`;
  toggle.classList.toggle("turn", Boolean(offered));
}

// ------------------------------------------------------------------------------ actions
function say(text, from = "action") {
  message.textContent = text || "";
  message.dataset.from = from;
  message.hidden = !text;
}

function showGate(verdict) {
  if (!verdict) {
    gateBox.hidden = true;
    fill(gateBox);
    return;
  }
  gateBox.dataset.passed = String(Boolean(verdict.passed));
  gateBox.hidden = false;
  fill(
    gateBox,
    h("strong", { class: "hw-gate-title" }, "Run it in simulation first"),
    h("p", {}, sentence(verdict.reason)),
    h(
      "button",
      {
        type: "button",
        class: "small",
        onclick: () => {
          showGate(null);
          start();
        },
      },
      "▶ Run in simulation",
    ),
  );
}

/** "run this code" -> "Run this code." */
function sentence(text) {
  const trimmed = String(text || "").trim();
  if (!trimmed) return "";
  return `${trimmed[0].toUpperCase()}${trimmed.slice(1)}${/[.!?]$/.test(trimmed) ? "" : "."}`;
}

async function act(work) {
  if (busy) return;
  busy = true;
  say("");
  render();
  try {
    await work();
  } catch (error) {
    say(error.message);
  } finally {
    busy = false;
    render();
  }
}

function join(name) {
  return act(async () => {
    const answer = await api(`/api/hardware/${encodeURIComponent(name)}/queue`, { method: "POST" });
    const robot = robots.find((r) => r.name === name);
    if (robot) {
      robot.my_position = answer.position;
      robot.my_estimated_wait_s = answer.estimated_wait_s;
      const places = robot.queue.places.filter((p) => p.position !== answer.position);
      places.push({ position: answer.position, state: answer.state, estimated_wait_s: answer.estimated_wait_s, offered_until_s: null });
      robot.queue.places = places.sort((a, b) => a.position - b.position);
    }
    if (answer.state === "offered") offeredAtJoin = name;
    await poll();
  });
}

function leave(name) {
  return act(async () => {
    await api(`/api/hardware/${encodeURIComponent(name)}/queue`, { method: "DELETE" });
    await poll();
  });
}

function runOn(name) {
  return act(async () => {
    showGate(null);
    try {
      await startOnRobot(name);
      document.querySelector('[data-testid="estop"]')?.focus(); // the one key that matters now
    } catch (error) {
      if (error.status === 409 && error.body?.gate) {
        showGate(error.body.gate);
        return;
      }
      throw error; // 429: not your turn (with the position); 422: the robot cannot run
    } finally {
      poll();
    }
  });
}
