// The student's page: log-in check, the catalogue, then every part wired to the shared state.
// Served at / by `robodojo serve`; bundled by web/build.mjs into web/static/student.js.

import "./student.css";
import { api } from "../common/api.js";
import { byId, fill, h } from "../common/dom.js";
import { tabs } from "../common/tabs.js";
import { initCatalog } from "./catalog.js";
import { initConsole } from "./console.js";
import { initEditor } from "./editor.js";
import { initFiles } from "./files.js";
import { graphShown, initGraph } from "./graph.js";
import { initHistory } from "./history.js";
import { initLatency } from "./latency.js";
import { initPlots } from "./plots.js";
import { initRunner, start } from "./runner.js";
import { app } from "./state.js";
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
  initConsole();
  initPlots();
  initLatency();
  initGraph();
  initWorld();
  initViz();
  initFiles();
  initHistory();
  tabs(byId("view-tabs"), (panelId) => {
    if (panelId === "panel-viz") vizShown();
    if (panelId === "panel-graph") graphShown();
  });
  byId("loading").hidden = true;
  byId("lab").hidden = false;
  initCatalog(); // chooses the exercise: every part loads what it shows
}

boot();
