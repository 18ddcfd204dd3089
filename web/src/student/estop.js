// The emergency stop: a big red button, always in view (fixed to the window's corner) while
// the run on show is going. On a real robot it is what stops the robot now; on a simulated run
// it is a hard stop. Escape presses it when keyboard focus is not in the editor (where Escape is
// the editor's own; and not over an open dialog during a simulated run, where Escape closes
// the dialog). It sends the live websocket's "estop" op and, when the socket is not open or has
// not answered within a second, POST /api/runs/{id}/estop.

import { api } from "../common/api.js";
import { byId } from "../common/dom.js";
import { app, END_STATES, on } from "./state.js";

const ACK_MS = 1000; // [ms] the websocket's answer; then the HTTP fallback
const button = byId("estop");
const label = byId("estop-label");
const status = byId("estop-status");

let pressedFor = null; // the run id the last press was for

/** Whether the run on show is going (live and not ended). */
function going() {
  return Boolean(app.live && app.run && !END_STATES.has(app.run.state));
}

const STATUS_KEPT_MS = 8000; // [ms] the last press's line stays this long after the run ended
let statusTimer = null;

function update() {
  const run = app.run;
  const show = going();
  if (run?.id !== pressedFor) status.textContent = "";
  if (!show) {
    if (!button.hidden && status.textContent) {
      clearTimeout(statusTimer);
      statusTimer = setTimeout(() => !going() && (status.textContent = ""), STATUS_KEPT_MS);
    }
    const focused = document.activeElement === button;
    button.hidden = true;
    if (focused) byId("run-button").focus(); // not lost to the page's body
    return;
  }
  button.hidden = false;
  const hardware = run.hardware;
  button.classList.toggle("hardware", Boolean(hardware));
  button.dataset.hardware = hardware ? "true" : "false";
  label.textContent = hardware ? `Stops ${hardware} now` : "Stops the run now";
}

export function initEstop() {
  button.addEventListener("click", () => emergencyStop());
  document.addEventListener("keydown", onKey, true);
  for (const event of ["run-controls", "run-shown", "run-state", "run-record", "run-ended", "target"]) on(event, update);
  update();
}

function onKey(event) {
  if (event.key !== "Escape" || event.repeat || !going()) return;
  const target = event.target instanceof Element ? event.target : null;
  if (target?.closest("#editor, .cm-editor")) return; // the editor's Escape (then Tab leaves it)
  if (!app.run.hardware && document.querySelector("dialog[open]")) return; // closes the dialog
  emergencyStop();
}

/** Stop the run on show at once: the websocket's op, else (or if unanswered) the HTTP call. */
export async function emergencyStop() {
  const run = app.run;
  if (!run || !going()) return;
  pressedFor = run.id;
  status.textContent = `Emergency stop sent${run.hardware ? ` to ${run.hardware}` : ""}.`;
  button.setAttribute("aria-busy", "true");
  try {
    if (await viaSocket()) return;
    await api(`/api/runs/${encodeURIComponent(run.id)}/estop`, { method: "POST" });
  } catch (error) {
    // 409: it has ended meanwhile (stopped is what was wanted); otherwise say why
    status.textContent = error.status === 409 ? "The run had already ended." : `Emergency stop failed: ${error.message}. Press again, or switch the robot off.`;
  } finally {
    button.removeAttribute("aria-busy");
  }
}

/** true once the live socket acknowledged the op within ACK_MS. */
async function viaSocket() {
  const live = app.live;
  if (!live?.socket || live.socket.readyState !== WebSocket.OPEN) return false;
  const answer = live.command("estop").then(
    () => true,
    () => false,
  );
  const late = new Promise((resolve) => setTimeout(() => resolve(false), ACK_MS));
  return Promise.race([answer, late]);
}
