// The exercise picker (or a robot in a world, for free play) and the exercise's text: what to
// do, the checks a run is graded on, and the robot's topics. The choice is kept in the address
// (#exercise_id or #free/robot/world) and in localStorage, so a reload comes back to it. A run
// opened by its id (/?run=ID, app.watching) chooses its own exercise or robot and world; any
// other choice leaves it (and drops ?run= from the address).

import { byId, fill, h } from "../common/dom.js";
import { app, emit } from "./state.js";

const FREE = "__free__";
const STORE_KEY = "robodojo.target";
const exerciseSelect = byId("exercise-select");
const robotSelect = byId("robot-select");
const worldSelect = byId("world-select");

/** `initial`: the target of a run opened by its id, else the address's or the saved one. */
export function initCatalog(initial = null) {
  const exercises = [...app.exercises.values()];
  fill(
    exerciseSelect,
    h("optgroup", { label: "Exercises" }, exercises.map((e) => h("option", { value: e.id }, e.title))),
    h("optgroup", { label: "Free play" }, h("option", { value: FREE }, "A robot in a world (no checks)")),
  );
  fill(robotSelect, [...app.robots.values()].map((r) => h("option", { value: r.id }, r.title)));
  exerciseSelect.addEventListener("change", () => choose(targetFromControls()));
  robotSelect.addEventListener("change", () => {
    fillWorlds(robotSelect.value);
    choose(targetFromControls());
  });
  worldSelect.addEventListener("change", () => choose(targetFromControls()));
  window.addEventListener("hashchange", () => {
    const wanted = parseHash(location.hash);
    if (wanted && workspaceKey(wanted) !== workspaceKey(app.target || {})) choose(wanted);
  });
  const details = byId("exercise-text");
  details.open = localStorage.getItem("robodojo.textOpen") !== "false";
  details.addEventListener("toggle", () => localStorage.setItem("robodojo.textOpen", String(details.open)));
  byId("picker").hidden = false;
  const saved = initial || parseHash(location.hash) || readSaved() || { exercise: exercises[0]?.id };
  choose(saved, { keepWatching: true });
}

/** Back from a run opened by its id to the student's own code of the same target. */
export function leaveWatch() {
  if (app.watching) choose(targetFromControls());
}

function workspaceKey(target) {
  return target.exercise ? `e:${target.exercise?.id || target.exercise}` : `f:${target.robot}:${target.world}`;
}

function parseHash(hash) {
  const text = decodeURIComponent(hash.replace(/^#/, ""));
  if (!text) return null;
  const free = text.match(/^free\/([^/]+)\/([^/]+)$/);
  if (free) return { robot: free[1], world: free[2] };
  return { exercise: text };
}

function readSaved() {
  try {
    return JSON.parse(localStorage.getItem(STORE_KEY));
  } catch {
    return null;
  }
}

function fillWorlds(robotId, selected) {
  const robot = app.robots.get(robotId);
  const worlds = (robot?.worlds || []).map((id) => app.worlds.get(id)).filter(Boolean);
  fill(worldSelect, worlds.map((w) => h("option", { value: w.id }, w.title)));
  if (selected && worlds.some((w) => w.id === selected)) worldSelect.value = selected;
}

function targetFromControls() {
  if (exerciseSelect.value !== FREE) return { exercise: exerciseSelect.value };
  return { robot: robotSelect.value, world: worldSelect.value };
}

/** The target `wanted` ({exercise: id} or {robot, world}) names, or the nearest valid one. */
function resolve(wanted) {
  const exercise = wanted?.exercise && app.exercises.get(wanted.exercise);
  if (exercise) return { workspace: exercise.id, exercise, robot: exercise.robot, world: exercise.world };
  const first = [...app.exercises.values()][0];
  if (!wanted?.robot && first) return resolve({ exercise: first.id });
  const robot = app.robots.has(wanted?.robot) ? wanted.robot : [...app.robots.keys()][0];
  const worlds = app.robots.get(robot)?.worlds || [];
  const world = worlds.includes(wanted?.world) ? wanted.world : worlds[0];
  return { workspace: robot, exercise: null, robot, world };
}

function choose(wanted, { keepWatching = false } = {}) {
  const wasWatching = Boolean(app.watching);
  if (wasWatching && !keepWatching) {
    app.watching = null;
    emit("watch-ended");
  }
  const target = resolve(wanted);
  exerciseSelect.value = target.exercise ? target.exercise.id : FREE;
  byId("free-play").hidden = Boolean(target.exercise);
  robotSelect.value = target.robot;
  fillWorlds(target.robot, target.world);
  const hash = target.exercise ? `#${target.exercise.id}` : `#free/${target.robot}/${target.world}`;
  const query = new URLSearchParams(location.search);
  if (!app.watching) query.delete("run");
  const search = query.toString();
  const address = `${location.pathname}${search ? `?${search}` : ""}${hash}`;
  if (address !== `${location.pathname}${location.search}${location.hash}`) history.replaceState(null, "", address);
  if (!app.watching) {
    localStorage.setItem(
      STORE_KEY,
      JSON.stringify(target.exercise ? { exercise: target.exercise.id } : { robot: target.robot, world: target.world }),
    );
  }
  const changedWorkspace = !app.target || app.target.workspace !== target.workspace || wasWatching !== Boolean(app.watching);
  app.target = target;
  showText(target);
  emit("target", { target, changedWorkspace });
}

/** Text with `code` spans and blank-line paragraphs, as the exercise descriptions are written. */
function prose(text) {
  return text
    .split(/\n\s*\n/)
    .map((paragraph) =>
      h(
        "p",
        {},
        paragraph.split(/(`[^`]+`)/).map((part) => (part.startsWith("`") && part.endsWith("`") ? h("code", {}, part.slice(1, -1)) : part)),
      ),
    );
}

function checkLine(check) {
  const unit = check.unit ? ` ${check.unit}` : "";
  return h(
    "li",
    {},
    h("code", {}, check.name),
    ` ${check.comparison} ${check.threshold}${unit}: `,
    check.description || "",
  );
}

function topicTable(robot) {
  return h(
    "table",
    { class: "topics-table" },
    h("caption", { class: "sr-only" }, `Topics of the ${robot.title}`),
    h("thead", {}, h("tr", {}, h("th", { scope: "col" }, "topic"), h("th", { scope: "col" }, "type"), h("th", { scope: "col" }, "robot"), h("th", { scope: "col" }, "what"))),
    h(
      "tbody",
      {},
      robot.topics.map((t) =>
        h(
          "tr",
          {},
          h("td", {}, h("code", {}, t.name)),
          h("td", {}, t.type),
          h("td", {}, t.direction === "publish" ? `publishes${t.rate_hz ? ` ${+t.rate_hz.toFixed(1)} Hz` : ""}` : "subscribes"),
          h("td", {}, t.description),
        ),
      ),
    ),
  );
}

function showText(target) {
  const robot = app.robots.get(target.robot);
  const world = app.worlds.get(target.world);
  const exercise = target.exercise;
  byId("exercise-title").textContent = exercise ? exercise.title : `Free play: ${robot?.title} in ${world?.title}`;
  const meta = [
    `Robot: ${robot?.title || target.robot}`,
    `World: ${world?.title || target.world}`,
    exercise ? `${exercise.duration_s} s, ${exercise.clock}` : null,
    exercise?.builtin_nodes?.length ? `Server nodes: ${exercise.builtin_nodes.join(", ")}` : null,
  ].filter(Boolean);
  fill(
    byId("exercise-body"),
    h("p", { class: "meta" }, meta.join(" · ")),
    exercise ? prose(exercise.description) : h("p", {}, "Write any controller for this robot and world. Runs are not graded."),
    exercise?.checks?.length ? [h("h3", {}, "Checks"), h("ul", { class: "check-list" }, exercise.checks.map(checkLine))] : null,
    exercise?.source ? h("p", { class: "source" }, `Source: ${exercise.source}`) : null,
    robot ? h("details", { class: "robot-topics" }, h("summary", {}, `${robot.title}: topics`), topicTable(robot)) : null,
  );
}
