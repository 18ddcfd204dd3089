// The student's page: log-in check, the catalogue, then every part wired to the shared state.
// Served at / by `robodojo serve`; bundled by web/build.mjs into web/static/student.js.

import "./student.css";
import { api } from "../common/api.js";
import { byId, fill, h, when } from "../common/dom.js";
import { tabs } from "../common/tabs.js";
import { initCatalog, leaveWatch } from "./catalog.js";
import { initCheck } from "./check.js";
import { initCompare } from "./compare.js";
import { initConsole } from "./console.js";
import { initEditor } from "./editor.js";
import { initEstop } from "./estop.js";
import { initFiles } from "./files.js";
import { graphShown, initGraph } from "./graph.js";
import { initHardware } from "./hardware.js";
import { initHistory } from "./history.js";
import { initLatency } from "./latency.js";
import { initLeaderboard } from "./leaderboard.js";
import { initPlots } from "./plots.js";
import { initRunner, showRun, start } from "./runner.js";
import { app, on } from "./state.js";
import { initVersions } from "./versions.js";
import { initViz, vizShown } from "./viz.js";
import { initWorld } from "./world.js";

function gate(text) {
  byId("loading").hidden = true;
  byId("lab").hidden = true;
  byId("gate").hidden = false;
  if (text) byId("gate-text").textContent = text;
}

function who(me) {
  fill(
    byId("who"),
    h("span", { dataset: { testid: "user-name" } }, me.name),
    me.role === "instructor" ? [" ", h("a", { href: "/admin" }, "Instructor page")] : null,
    " ",
    h(
      "button",
      {
        type: "button",
        class: "small",
        onclick: async () => {
          await api("/api/logout", { method: "POST" }).catch(() => {});
          location.reload();
        },
      },
      "Log out",
    ),
  );
}

/** The logged-in user, or null: GET /api/session never answers 401 (a browser logs every 401
 * as an error); a server without it (405) is asked /api/me. */
async function whoIsIn() {
  try {
    return (await api("/api/session")).user;
  } catch (error) {
    if (error.status !== 405) throw error;
  }
  try {
    return await api("/api/me");
  } catch (error) {
    if (error.status === 401) return null;
    throw error;
  }
}

/** The session ended while the page was open: say so, and leave the code on screen. */
function loggedOut() {
  const message = byId("run-message");
  fill(message, "Your session has ended, so nothing can be saved or run: open your invite link again (copy any unsaved code first).");
  message.hidden = false;
}

const notice = byId("notice");

function showNotice(error, ...content) {
  notice.classList.toggle("error", error);
  notice.setAttribute("role", error ? "alert" : "status");
  fill(notice, ...content);
  notice.hidden = false;
}

const NOT_FOUND = "no such run (or it is not yours)"; // the API's 404 sentence
const LIST_PAGE = 500; // the API's largest page of GET /api/runs

/** Whether a student's own runs include `id`. Asked before GET /api/runs/{id}, whose 404 for
 * someone else's run a browser would log as an error; instructors see every run. */
async function isMine(id) {
  for (let offset = 0; ; offset += LIST_PAGE) {
    const page = await api(`/api/runs?limit=${LIST_PAGE}&offset=${offset}`);
    if (page.runs.some((run) => run.id === id)) return true;
    if (!page.runs.length || offset + LIST_PAGE >= page.total) return false;
  }
}

/** The run the address names (/?run=ID: the instructor console's "Watch"), or null. A run that
 * is not there, or not this user's (students), is said in the notice. */
async function runOfAddress() {
  const id = new URLSearchParams(location.search).get("run");
  if (!id) return null;
  try {
    if (app.me.role !== "instructor" && !(await isMine(id))) throw new Error(NOT_FOUND);
    return await api(`/api/runs/${encodeURIComponent(id)}`);
  } catch (error) {
    const query = new URLSearchParams(location.search);
    query.delete("run");
    const search = query.toString();
    history.replaceState(null, "", `${location.pathname}${search ? `?${search}` : ""}${location.hash}`);
    showNotice(
      true,
      h("span", { dataset: { testid: "run-not-found" } }, `Run ${id}: ${error.message}.`),
      h("button", { type: "button", class: "small", onclick: () => (notice.hidden = true) }, "Dismiss"),
    );
    return null;
  }
}

/** Whose run is on show, for the notice: "your run", or the student's name (instructors). */
async function ownerOf(run) {
  if (run.user_id === app.me.id) return "your run";
  if (app.me.role === "instructor") {
    try {
      return `${(await api(`/api/admin/users/${encodeURIComponent(run.user_id)}`)).name}'s run`;
    } catch {
      // a user deleted since: the id says who
    }
  }
  return `the run of user ${run.user_id}`;
}

async function watchNotice(run) {
  const text = h("span", { dataset: { testid: "watch-notice" } }, `Watching ${run.id.slice(0, 8)}…: `);
  showNotice(
    false,
    text,
    h("button", { type: "button", class: "small", onclick: leaveWatch, dataset: { testid: "watch-leave" } }, "Back to my code"),
  );
  const owner = await ownerOf(run);
  if (app.watching !== run) return;
  const what = run.exercise ? (app.exercises.get(run.exercise)?.title ?? run.exercise) : `free play in ${app.worlds.get(run.world)?.title ?? run.world}`;
  text.textContent = `Watching ${owner} (${what}, started ${when(run.created_at)}): the editor shows its code, read only. `;
}

async function boot() {
  try {
    app.me = await whoIsIn();
  } catch (error) {
    gate(`The lab cannot be reached: ${error.message}`);
    return;
  }
  if (!app.me) {
    gate(null);
    return;
  }
  let robots, worlds, exercises;
  try {
    [robots, worlds, exercises] = await Promise.all([api("/api/robots"), api("/api/worlds"), api("/api/exercises")]);
  } catch (error) {
    gate(`The lab's catalogue could not be loaded: ${error.message}`);
    return;
  }
  for (const robot of robots) app.robots.set(robot.id, robot);
  for (const world of worlds) app.worlds.set(world.id, world);
  for (const exercise of exercises) app.exercises.set(exercise.id, exercise);
  who(app.me);
  window.addEventListener("robodojo:logged-out", loggedOut);

  initEditor({ run: start });
  initVersions();
  initRunner();
  initCheck();
  initEstop();
  initHardware();
  initConsole();
  initPlots();
  initLatency();
  initGraph();
  initWorld();
  initViz();
  initFiles();
  initHistory();
  initLeaderboard();
  initCompare();
  const viewTabs = tabs(byId("view-tabs"), (panelId) => {
    if (panelId === "panel-viz") vizShown();
    if (panelId === "panel-graph") graphShown();
  });
  byId("loading").hidden = true;
  byId("lab").hidden = false;
  app.watching = await runOfAddress();
  on("watch-ended", () => (notice.hidden = true));
  on("show-view", ({ panel }) => viewTabs.select(panel));
  on("drive", () => {
    viewTabs.select("panel-world");
    document.querySelector('[data-testid="teleop-pad"]')?.focus();
  });
  const run = app.watching;
  // Chooses the exercise (or the watched run's): every part loads what it shows.
  initCatalog(run ? (app.exercises.has(run.exercise) ? { exercise: run.exercise } : { robot: run.robot, world: run.world }) : null);
  if (run) {
    watchNotice(run);
    showRun(run);
  }
}

boot();
