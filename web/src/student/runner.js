// Run controls and the run on show: start a run in simulation (clock, duration, seed; in free
// play optionally with the teleop node, "Drive with arrow keys") or on a bench robot
// (startOnRobot: realtime, the hardware panel's "Run on the real robot"), stop,
// what to run ("my nodes" with optional params, or a launch file of the workspace: opening a
// launch file's tab chooses it), stop,
// pause/resume (lockstep only), the progress of simulated time, the state and why it ended,
// and the checks. A live run is followed over its websocket and its record polled for the
// figures the websocket does not carry (node periods, time).

import { api } from "../common/api.js";
import { byId, fill, h } from "../common/dom.js";
import { LiveRun } from "../common/live.js";
import { flushAll, launchFiles, nodes, workspaceName } from "./editor.js";
import { parseParams } from "./params.js";
import { app, applyWants, emit, END_STATES, isLaunchFile, on } from "./state.js";

const POLL_MS = 1000; // [ms] the run's record while it is live: time, node periods
const END_WAIT_MS = 15000; // [ms] how long to wait for an ended run's checks to be stored

const form = byId("run-form");
const clockInput = byId("run-clock");
const durationInput = byId("run-duration");
const seedInput = byId("run-seed");
const teleopOption = byId("teleop-option");
const teleopInput = byId("run-teleop");
const whatInput = byId("run-what");
const paramsOption = byId("run-params-option");
const paramsInput = byId("run-params");
const TELEOP_KEY = "robodojo.teleop";
const runButton = byId("run-button");
const pauseButton = byId("pause-button");
const stopButton = byId("stop-button");
const progress = byId("run-progress");
const timeText = byId("run-time");
const stateText = byId("run-state");
const message = byId("run-message");
const checksBox = byId("checks");

let starting = false;
let poller = null;
let timeS = 0;
let state = null;
let endedRunId = null;

export function initRunner() {
  form.addEventListener("submit", (event) => {
    event.preventDefault();
    start();
  });
  stopButton.addEventListener("click", () => command("stop"));
  pauseButton.addEventListener("click", () => command(state === "paused" ? "resume" : "pause"));
  teleopInput.checked = localStorage.getItem(TELEOP_KEY) === "true";
  teleopInput.addEventListener("change", () => localStorage.setItem(TELEOP_KEY, String(teleopInput.checked)));
  on("target", ({ target }) => {
    clockInput.value = target.exercise?.clock || "lockstep";
    durationInput.value = target.exercise?.duration_s ?? 30;
    seedInput.value = "";
    teleopOption.hidden = Boolean(target.exercise) || Boolean(app.watching); // exercises say
    forget();
  });
  on("files", fillWhat);
  on("file-shown", ({ filename }) => {
    if (isLaunchFile(filename)) {
      fillWhat();
      whatInput.value = filename;
      paramsOption.hidden = true;
    }
  });
  whatInput.addEventListener("change", () => {
    paramsOption.hidden = whatInput.value !== "";
  });
  paramsInput.addEventListener("input", () => paramsInput.setCustomValidity(""));
  controls();
}

/** "Run: my nodes" or one of the workspace's launch files; the choice is kept if it remains. */
function fillWhat() {
  const chosen = whatInput.value;
  const launches = launchFiles();
  fill(
    whatInput,
    h("option", { value: "" }, "my nodes"),
    launches.map((name) => h("option", { value: name }, name)),
  );
  whatInput.value = launches.includes(chosen) ? chosen : "";
  paramsOption.hidden = whatInput.value !== "";
}

/** Whether a run on show is going (a new one cannot start meanwhile). */
export function runGoing() {
  return starting || Boolean(app.checking) || (Boolean(app.live) && !END_STATES.has(state));
}

/** The body of POST /api/runs for a check of the editor's nodes, every edit saved first (the
 * server reads launch and data files from the workspace). */
export async function checkBody() {
  if (!form.reportValidity()) throw new Error("fix the run settings first");
  await flushAll();
  return runBody();
}

/** Redraw the run controls (a check started or ended: runs wait for it). */
export function refreshControls() {
  controls();
}

/** The body of POST /api/runs for the editor's nodes and the target. */
function runBody() {
  const target = app.target;
  const body = target.exercise ? { exercise: target.exercise.id } : { robot: target.robot, world: target.world };
  const workspace = workspaceName();
  if (workspace) body.workspace = workspace; // its data files go into every node's folder
  if (whatInput.value) body.launch = { file: whatInput.value };
  else {
    const { params, problem } = parseParams(paramsInput.value);
    if (problem) throw new ParamsProblem(problem);
    body.nodes = nodes();
    if (Object.keys(params).length) for (const node of body.nodes) node.params = params;
  }
  body.clock = clockInput.value;
  body.duration = Number(durationInput.value);
  if (seedInput.value !== "") body.seed = Number(seedInput.value);
  if (!target.exercise && teleopInput.checked) body.teleop = true;
  return body;
}

async function post(body) {
  // The server reads launch files and data files from the workspace: every edit is saved first.
  await flushAll();
  const run = await api("/api/runs", { method: "POST", body });
  if (body.teleop) app.teleopRuns.add(run.id);
  showRun(run);
  if (body.teleop) emit("drive"); // the World tab, its pad focused: the arrow keys drive
  return run;
}

/** Start a run of the editor's nodes for the target. */
export async function start() {
  if (runGoing()) return;
  if (app.watching) {
    say("This is a run opened by its id, with its code read only: go back to your code to run.");
    return;
  }
  if (!form.reportValidity()) return;
  starting = true;
  controls();
  say("");
  try {
    await post(runBody());
  } catch (error) {
    if (error instanceof ParamsProblem) {
      paramsInput.setCustomValidity(error.message);
      paramsInput.reportValidity();
    }
    say(error.message); // the server's sentence, verbatim
  } finally {
    starting = false;
    controls();
  }
}

/** Start the editor's nodes on the bench robot `name` (realtime; the server checks the turn and
 * the simulation gate). Resolves with the run; rejects with the ApiError (its body carries the
 * gate verdict of a 409), which the caller shows. */
export async function startOnRobot(name) {
  if (runGoing()) throw new Error("a run is going: stop it first");
  if (app.watching) throw new Error("this is a run opened by its id: go back to your code to run");
  if (!durationInput.reportValidity()) throw new Error("give the run a duration first");
  starting = true;
  controls();
  say("");
  try {
    const body = runBody();
    body.hardware = name;
    body.clock = "realtime"; // a real robot lives in real time
    delete body.seed; // the world is the real one
    return await post(body);
  } finally {
    starting = false;
    controls();
  }
}

/** A line of the Params field that cannot be read; said before anything is sent. */
class ParamsProblem extends Error {}

/** No run on show (another exercise was chosen); a live run goes on, unwatched. */
function forget() {
  app.live?.close();
  app.live = null;
  clearInterval(poller);
  poller = null;
  app.run = null;
  state = null;
  timeS = 0;
  stateText.textContent = "";
  say("");
  showChecks(null);
  progressOf(null);
  controls();
}

/** Put a run on show: live (followed over its websocket) unless it has ended. */
export function showRun(run) {
  app.live?.close();
  app.live = null;
  clearInterval(poller);
  poller = null;
  app.run = run;
  state = run.state;
  timeS = run.time_s || 0;
  endedRunId = null;
  stateText.textContent = run.reason || run.state;
  say(failureText(run));
  showChecks(run);
  const live = !END_STATES.has(run.state);
  emit("run-shown", { run, live });
  if (live) {
    app.live = new LiveRun(run.id, { onFrame: (frame) => frameOf(run.id, frame), onStatus: (text) => text && say(text) });
    applyWants();
    poller = setInterval(() => poll(run.id), POLL_MS);
  } else {
    emit("run-ended", { run });
  }
  progressOf(run);
  controls();
}

function frameOf(runId, frame) {
  if (app.run?.id !== runId) return;
  switch (frame.type) {
    case "snapshot":
      setState(frame.state, frame.reason, frame.time_s);
      for (const [topic, type] of Object.entries(frame.topics || {})) emit("run-topic", { topic, msg_type: type });
      break;
    case "telemetry":
      if (frame.time_s > timeS) timeS = frame.time_s;
      emit("telemetry", { frame });
      progressOf(app.run);
      break;
    case "log":
      emit("log", { node: frame.node, line: frame.line });
      break;
    case "state":
      setState(frame.state, frame.reason, frame.time_s);
      break;
    case "topic":
      emit("run-topic", { topic: frame.topic, msg_type: frame.msg_type });
      break;
    case "checks":
      showChecks({ checks: frame.checks, score: frame.score });
      break;
    case "dropped":
      emit("log", { node: null, line: `(${frame.count} console lines were missed: the view fell behind)` });
      break;
    case "end":
    case "gone":
      finish(runId);
      break;
  }
}

function setState(newState, reason, time) {
  state = newState;
  if (Number.isFinite(time) && time > timeS) timeS = time;
  emit("run-state", { state: newState, reason, time_s: time });
  if (app.run) {
    app.run.state = newState;
    app.run.reason = reason;
  }
  stateText.textContent = reason || newState;
  progressOf(app.run);
  controls();
}

async function poll(runId) {
  try {
    const run = await api(`/api/runs/${runId}`);
    if (app.run?.id !== runId) return;
    app.run = run;
    if (run.time_s > timeS) timeS = run.time_s;
    emit("run-record", { run });
    progressOf(run);
    if (END_STATES.has(run.state)) finish(runId);
  } catch {
    // the websocket reports a lost server; a missed poll is harmless
  }
}

/** The run ended: wait until its record (with the checks) is stored, then tell every part. */
async function finish(runId) {
  if (endedRunId === runId) return;
  endedRunId = runId;
  clearInterval(poller);
  poller = null;
  const deadline = Date.now() + END_WAIT_MS;
  let run = app.run;
  while (Date.now() < deadline) {
    try {
      run = await api(`/api/runs/${runId}`);
      if (END_STATES.has(run.state)) break;
    } catch {
      break;
    }
    await new Promise((resolve) => setTimeout(resolve, 300));
  }
  if (app.run?.id !== runId) return;
  app.live?.close();
  app.live = null;
  app.run = run;
  state = run.state;
  timeS = run.time_s ?? timeS;
  stateText.textContent = run.reason || run.state;
  say(failureText(run));
  showChecks(run);
  progressOf(run);
  controls();
  emit("run-ended", { run });
}

async function command(action) {
  const run = app.run;
  if (!run) return;
  try {
    await api(`/api/runs/${run.id}/${action}`, { method: "POST" });
    if (action !== "stop") setState(action === "pause" ? "paused" : "running", "", timeS);
  } catch (error) {
    say(error.message);
  }
}

function progressOf(run) {
  const duration = run?.duration_s || 0;
  progress.max = duration || 1;
  progress.value = Math.min(timeS, duration || 0);
  progress.setAttribute("aria-valuetext", duration ? `${timeS.toFixed(1)} of ${duration} seconds` : "no run");
  timeText.textContent = run ? `${timeS.toFixed(1)} / ${duration} s` : "no run yet";
  if (run && !stateText.textContent) stateText.textContent = run.reason || run.state;
}

function controls() {
  const active = Boolean(app.live) && !END_STATES.has(state);
  emit("run-controls", { going: starting || active });
  runButton.disabled = starting || active || Boolean(app.watching) || Boolean(app.checking);
  runButton.textContent = starting ? "Starting…" : "▶ Run in simulation";
  stopButton.disabled = !active;
  const lockstep = app.run?.clock === "lockstep";
  pauseButton.disabled = !active || !lockstep || !["running", "paused"].includes(state);
  pauseButton.textContent = state === "paused" ? "Resume" : "Pause";
  pauseButton.setAttribute("aria-pressed", String(state === "paused"));
  pauseButton.title = active && !lockstep ? "Only lockstep runs can pause: a realtime run keeps the robot's time." : "";
}

/** A failed run's reason, with a link to the line when it names one. */
function failureText(run) {
  if (!run || run.state !== "failed") return "";
  const match = /node (\w+) raised .* at line (\d+)/.exec(run.reason || "");
  if (!match) return run.reason;
  const [, node, line] = match;
  return [
    `${run.reason} `,
    h(
      "button",
      { type: "button", class: "link", dataset: { testid: "traceback-link" }, onclick: () => emit("goto-line", { node, line: Number(line) }) },
      `show ${node}.py line ${line}`,
    ),
  ];
}

function say(content) {
  fill(message, content || "");
  message.hidden = !content || (Array.isArray(content) && !content.length);
}

function showChecks(run) {
  const checks = run?.checks || [];
  if (!checks.length) {
    fill(checksBox);
    checksBox.hidden = true;
    return;
  }
  checksBox.hidden = false;
  const passed = checks.filter((c) => c.passed).length;
  fill(
    checksBox,
    h("span", { class: `score ${passed === checks.length ? "pass" : "fail"}` }, `${passed}/${checks.length} checks passed`),
    checks.map((check) => checkChip(check)),
  );
}

export function checkChip(check) {
  const unit = check.unit ? ` ${check.unit}` : "";
  const value = check.value === null || check.value === undefined ? "none" : +Number(check.value).toPrecision(3);
  return h(
    "span",
    { class: `check ${check.passed ? "pass" : "fail"}`, title: check.description || "", dataset: { testid: "check", check: check.name, passed: String(check.passed) } },
    h("span", { "aria-hidden": "true" }, check.passed ? "✓ " : "✗ "),
    h("span", { class: "sr-only" }, check.passed ? "passed: " : "failed: "),
    `${check.name} ${value}${value === "none" ? "" : unit} (${check.comparison} ${check.threshold}${unit})`,
  );
}
