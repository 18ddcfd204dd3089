// The world from above, and what a person can do to a running robot: press its button, move
// a movable light, set a goal pose (click on the map; drag to aim), drive with the arrow keys
// where the run has the teleop node. The world's walls, boxes, plants and posts, floor tape,
// lights and start pose come from /api/worlds; the robot's path and pose from the `tf` topic
// (map -> base_link), the occupancy grid from `map` when the exercise publishes one.

import { apiText } from "../common/api.js";
import { byId, fill, h, svg } from "../common/dom.js";
import { csvFileName, csvSamples, yawOf } from "../common/fields.js";
import { app, on, robotTopics, runHasTeleop, want } from "./state.js";
import { drivePad } from "./teleop.js";

const OWNER = "world";
const POSE_RATE_HZ = 10; // [Hz] the robot's pose on the map
const DRAG_COMMANDS_HZ = 10; // light moves while dragging; the server takes 50 commands/s
const TRAIL_POINTS = 5000;
const DEG = 180 / Math.PI;

const panel = byId("panel-world");
const status = h("p", { class: "hint", role: "status", dataset: { testid: "world-status" } });
let map = null; // {svg, layer, gridLayer, dynamic, inputs, driveBox}
let world = null; // the world as /api/worlds describes it
let bounds = [0, 0, 1, 1];
let trail = [];
let pose = null;
let goal = null;
let lights = []; // [{name, x, y, movable}] where they are now
let grid = null;
let mode = "goal";

export function initWorld() {
  on("target", ({ target }) => {
    trail = [];
    pose = goal = grid = null;
    showWorld(target.world, true);
    draw();
  });
  on("run-shown", ({ run, live }) => {
    trail = [];
    pose = goal = grid = null;
    // A free-play run may have been in another world of the robot: draw the run's world.
    if (!showWorld(run.world || app.target.world)) {
      lights = startLights(); // every run starts with the world's lights where the file has them
      drawGrid();
    }
    if (live) {
      want(OWNER, "tf", POSE_RATE_HZ);
      want(OWNER, "goal", 2);
      want(OWNER, "map", 1);
    }
    showDrive();
    enable(live);
    draw();
  });
  on("run-graph", ({ run }) => {
    if (app.run?.id === run.id) showDrive();
  });
  on("telemetry", ({ frame }) => {
    if (frame.topic === "tf") addPose(frame.msg);
    else if (frame.topic === "goal") goal = poseOf(frame.msg?.pose);
    else if (frame.topic === "map") {
      grid = frame.msg;
      drawGrid();
    } else return;
    draw();
  });
  on("run-ended", ({ run }) => {
    enable(false);
    replay(run);
  });
}

/** Build the map of this world unless it is already on show; true if it was built. */
function showWorld(worldId, always = false) {
  if (!always && world?.id === worldId && map) return false;
  world = app.worlds.get(worldId) || null;
  bounds = world?.bounds || [0, 0, 1, 1];
  lights = startLights();
  if (!movableLights().length) mode = "goal";
  build(app.target, worldId);
  return true;
}

function startLights() {
  return (world?.lights || []).map((light) => ({ ...light }));
}

function movableLights() {
  return lights.filter((light) => light.movable);
}

function poseOf(p) {
  return p ? { x: p.position.x, y: p.position.y, yaw: yawOf(p.orientation) } : null;
}

function addPose(msg) {
  const transform = msg?.transforms?.find((t) => t.child_frame_id === "base_link");
  if (!transform) return;
  const { translation, rotation } = transform.transform;
  pose = { x: translation.x, y: translation.y, yaw: yawOf(rotation) };
  trail.push([pose.x, pose.y]);
  if (trail.length > TRAIL_POINTS) trail.splice(0, trail.length - TRAIL_POINTS);
}

/** An ended run: its whole path from tf.csv. */
async function replay(run) {
  try {
    const samples = csvSamples(await apiText(`/api/runs/${run.id}/csv/${csvFileName("tf")}`));
    if (app.run?.id !== run.id) return;
    trail = [];
    for (const sample of samples) addPose(sample.msg);
    draw();
  } catch {
    // no recording: the map shows what the live view had
  }
}

/** The start pose: the exercise's spawn if the catalogue names one, else the world's first. */
function startPose(target) {
  const spawns = world?.spawns || [];
  const named = target.world === world?.id ? target.exercise?.spawn : null;
  return spawns.find((s) => s.name === named) || spawns[0] || null;
}

function describe(target, worldId) {
  const [x0, y0, x1, y1] = bounds;
  const parts = [`Top view of ${world?.title || worldId}, ${(x1 - x0).toFixed(1)} by ${(y1 - y0).toFixed(1)} m`];
  const count = (n, one, many) => (n ? `${n} ${n === 1 ? one : many}` : null);
  const plants = (world?.circles || []).filter((c) => c[3] === "plant").length;
  const posts = (world?.circles || []).length - plants;
  const things = [
    count(world?.boxes?.length, "box", "boxes"),
    count(plants, "plant", "plants"),
    count(posts, "post", "posts"),
    world?.tape?.length ? "a taped line on the floor" : null,
    count(world?.lights?.length, "light", "lights"),
  ].filter(Boolean);
  if (things.length) parts.push(`with ${things.join(", ")}`);
  const start = startPose(target);
  if (start) parts.push(`the robot starts at x ${start.x} m, y ${start.y} m, heading ${Math.round(start.yaw * DEG)}°`);
  parts.push(movableLights().length ? "click to set the goal or move the light" : "click to set the goal");
  return parts.join("; ");
}

function build(target, worldId) {
  const [x0, y0, x1, y1] = bounds;
  const picture = svg("svg", {
    class: "world-map",
    viewBox: `${x0 - 0.05} ${-y1 - 0.05} ${x1 - x0 + 0.1} ${y1 - y0 + 0.1}`,
    role: "img",
    "aria-label": describe(target, worldId),
    dataset: { testid: "world-map" },
  });
  const layer = svg("g", { transform: "scale(1,-1)" });
  const gridLayer = svg("g", { class: "occupancy" });
  const dynamic = svg("g", { class: "dynamic" });
  layer.append(svg("rect", { x: x0, y: y0, width: x1 - x0, height: y1 - y0, class: "floor" }), gridLayer, staticLayer(target), dynamic);
  picture.append(layer);
  picture.addEventListener("pointerdown", pointerDown);

  const canPress = robotTopics(target.robot).some((t) => t.name.toLowerCase() === "button");
  const movable = movableLights();
  const goalX = number("goal-x", "x [m]");
  const goalY = number("goal-y", "y [m]");
  const goalYaw = number("goal-yaw", "yaw [deg]");
  goalYaw.value = 0;
  const lightX = number("light-x", "x [m]");
  const lightY = number("light-y", "y [m]");
  const lightName = h("select", { id: "light-name" }, movable.map((l) => h("option", { value: l.name }, l.name)));
  if (movable.length) {
    lightX.value = movable[0].x;
    lightY.value = movable[0].y;
  }
  lightName.addEventListener("change", () => {
    const light = lights.find((l) => l.name === lightName.value);
    if (!light) return;
    lightX.value = light.x;
    lightY.value = light.y;
  });
  const modeRadios = ["goal", "light"].map((value) =>
    h("label", {}, h("input", { type: "radio", name: "map-mode", value, checked: value === mode, onchange: () => (mode = value) }), ` ${value}`),
  );
  const driveBox = h("div", { class: "drive-box" });
  fill(
    panel,
    h(
      "div",
      { class: "world" },
      h(
        "div",
        { class: "map-box" },
        worldId !== target.world
          ? h("p", { class: "hint" }, `This run was in ${world?.title || worldId}; a new run goes to ${app.worlds.get(target.world)?.title || target.world}.`)
          : null,
        picture,
        legend(target),
        movable.length ? h("fieldset", { class: "map-mode" }, h("legend", {}, "A click on the map sets the"), modeRadios) : null,
        status,
      ),
      h(
        "div",
        { class: "interact" },
        canPress ? h("section", {}, h("h3", {}, "Button"), pressButton()) : null,
        h(
          "section",
          {},
          h("h3", {}, "Goal pose"),
          h(
            "form",
            { class: "inline-form", onsubmit: (e) => (e.preventDefault(), sendGoal(+goalX.value, +goalY.value, +goalYaw.value / DEG)) },
            labelled(goalX),
            labelled(goalY),
            labelled(goalYaw),
            h("button", { type: "submit", class: "small live-only", dataset: { testid: "goal-send" } }, "Set goal"),
          ),
        ),
        movable.length
          ? h(
              "section",
              {},
              h("h3", {}, movable.length > 1 ? "Lights" : "Light"),
              h(
                "form",
                { class: "inline-form", onsubmit: (e) => (e.preventDefault(), sendLight(lightName.value, +lightX.value, +lightY.value)) },
                movable.length > 1 ? h("label", { for: "light-name" }, "light ", lightName) : null,
                labelled(lightX),
                labelled(lightY),
                h("button", { type: "submit", class: "small live-only", dataset: { testid: "light-send" } }, "Move light"),
              ),
            )
          : null,
        h("section", {}, h("h3", {}, "Drive"), driveBox),
      ),
    ),
  );
  map = { svg: picture, layer, gridLayer, dynamic, driveBox, inputs: { goalX, goalY, goalYaw, lightX, lightY, lightName } };
  showDrive();
  enable(Boolean(app.live));
}

/** What does not move: floor tape, boxes, walls, plants and posts, the start pose. */
function staticLayer(target) {
  const [x0, y0, x1, y1] = bounds;
  const span = Math.max(x1 - x0, y1 - y0);
  const step = span > 4 ? 1 : 0.5; // [m] grid lines
  const lines = [];
  for (let x = Math.ceil(x0 / step) * step; x <= x1 + 1e-9; x += step) lines.push(svg("line", { x1: x, x2: x, y1: y0, y2: y1 }));
  for (let y = Math.ceil(y0 / step) * step; y <= y1 + 1e-9; y += step) lines.push(svg("line", { x1: x0, x2: x1, y1: y, y2: y }));
  const w = world || {};
  const start = startPose(target);
  return svg(
    "g",
    { class: "static" },
    svg("g", { class: "grid-lines", "stroke-width": span / 500 }, lines),
    svg(
      "g",
      { class: "tape", dataset: { testid: "map-tape" } },
      (w.tape || []).map(([ax, ay, bx, by, width]) => svg("line", { x1: ax, y1: ay, x2: bx, y2: by, "stroke-width": width })),
    ),
    svg(
      "g",
      { class: "boxes" },
      (w.boxes || []).map(([cx, cy, width, depth, yaw]) =>
        svg("rect", { class: "box", x: -width / 2, y: -depth / 2, width, height: depth, transform: `translate(${cx} ${cy}) rotate(${yaw * DEG})`, dataset: { testid: "map-box" } }),
      ),
    ),
    svg(
      "g",
      { class: "walls", "stroke-width": Math.max(0.015, span / 300) },
      (w.segments || []).map(([ax, ay, bx, by]) => svg("line", { x1: ax, y1: ay, x2: bx, y2: by, dataset: { testid: "map-wall" } })),
    ),
    svg(
      "g",
      { class: "circles" },
      (w.circles || []).map(([cx, cy, r, kind]) => svg("circle", { class: kind === "plant" ? "plant" : "post", cx, cy, r, dataset: { testid: `map-${kind === "plant" ? "plant" : "post"}` } })),
    ),
    start ? marker(start, span / 60, "start", "map-start") : null,
  );
}

/** A key to the map's symbols, for what this world has. */
function legend(target) {
  const w = world || {};
  const items = [
    w.segments?.length ? ["wall", "walls"] : null,
    w.boxes?.length ? ["box", "boxes"] : null,
    w.circles?.some((c) => c[3] === "plant") ? ["plant", "plants"] : null,
    w.circles?.some((c) => c[3] !== "plant") ? ["post", "posts"] : null,
    w.tape?.length ? ["tape", "tape"] : null,
    w.lights?.length ? ["light", movableLights().length ? "light (movable)" : "light"] : null,
    startPose(target) ? ["start", "start pose"] : null,
    ["robot", "robot"],
    ["goal", "goal"],
  ].filter(Boolean);
  return h(
    "ul",
    { class: "map-legend", "aria-label": "Map key" },
    items.map(([kind, text]) => h("li", {}, h("span", { class: `swatch ${kind}`, "aria-hidden": "true" }), text)),
  );
}

function number(id, label) {
  const input = h("input", { id, type: "number", step: "any", required: true, size: 6 });
  input.dataset.label = label;
  return input;
}

function labelled(input) {
  return h("label", { for: input.id }, `${input.dataset.label} `, input);
}

function pressButton() {
  const button = h("button", { type: "button", class: "live-only press", "aria-pressed": "false", dataset: { testid: "robot-button" } }, "Hold to press the robot's button");
  const set = (pressed) => {
    if (button.getAttribute("aria-pressed") === String(pressed)) return;
    button.setAttribute("aria-pressed", String(pressed));
    send("button", { pressed });
  };
  button.addEventListener("pointerdown", () => set(true));
  for (const type of ["pointerup", "pointerleave", "blur"]) button.addEventListener(type, () => set(false));
  button.addEventListener("keydown", (e) => {
    if ((e.key === " " || e.key === "Enter") && !e.repeat) {
      e.preventDefault();
      set(true);
    }
  });
  button.addEventListener("keyup", (e) => (e.key === " " || e.key === "Enter") && set(false));
  return button;
}

/** The teleop pad when the run on show (or, before any run, the exercise) has the teleop node. */
function showDrive() {
  if (!map) return;
  const teleop = runHasTeleop(app.run);
  if (map.driveBox.dataset.teleop === String(teleop)) return;
  map.driveBox.dataset.teleop = String(teleop);
  let text;
  if (app.target?.exercise) text = "This exercise has no keyboard driving (no teleop node).";
  else if (app.run) text = "This run was started without keyboard driving: tick “Drive with arrow keys” before Run.";
  else text = "Tick “Drive with arrow keys” before Run to drive the robot with the keyboard.";
  fill(map.driveBox, teleop ? drivePad(send) : h("p", { class: "hint" }, text));
  enable(Boolean(app.live));
}

function enable(live) {
  for (const element of panel.querySelectorAll(".live-only")) element.disabled = !live;
  status.textContent = live ? "" : "Start a run to interact with the robot.";
}

/** A live command; the server's sentence when it refuses. */
function send(op, fields) {
  if (!app.live) return Promise.resolve(false);
  return app.live.command(op, fields).then(
    () => {
      status.textContent = "";
      return true;
    },
    (error) => {
      status.textContent = error.message;
      return false;
    },
  );
}

function sendGoal(x, y, yaw) {
  goal = { x, y, yaw };
  Object.assign(map.inputs.goalX, { value: x.toFixed(2) });
  Object.assign(map.inputs.goalY, { value: y.toFixed(2) });
  Object.assign(map.inputs.goalYaw, { value: (yaw * DEG).toFixed(0) });
  draw();
  send("goal", { x, y, yaw });
}

function sendLight(name, x, y) {
  map.inputs.lightX.value = x.toFixed(2);
  map.inputs.lightY.value = y.toFixed(2);
  send("light", { name, x, y }).then((ok) => {
    if (!ok) return;
    const light = lights.find((l) => l.name === name);
    if (light) Object.assign(light, { x, y }); // drawn once the server has moved it
    draw();
  });
}

/** World coordinates of a pointer event on the map. */
function worldPoint(event) {
  const point = new DOMPoint(event.clientX, event.clientY).matrixTransform(map.layer.getScreenCTM().inverse());
  const [x0, y0, x1, y1] = bounds;
  return { x: Math.min(x1, Math.max(x0, point.x)), y: Math.min(y1, Math.max(y0, point.y)) };
}

function pointerDown(event) {
  if (!app.live) {
    status.textContent = "Start a run to interact with the robot.";
    return;
  }
  const start = worldPoint(event);
  const lightMode = mode === "light" && movableLights().length > 0;
  const name = map.inputs.lightName.value || movableLights()[0]?.name;
  map.svg.setPointerCapture(event.pointerId);
  let lastSent = 0;
  const move = (e) => {
    const p = worldPoint(e);
    if (lightMode && performance.now() - lastSent > 1000 / DRAG_COMMANDS_HZ) {
      lastSent = performance.now();
      sendLight(name, p.x, p.y);
    }
  };
  const up = (e) => {
    map.svg.removeEventListener("pointermove", move);
    map.svg.removeEventListener("pointerup", up);
    const p = worldPoint(e);
    if (lightMode) return sendLight(name, p.x, p.y);
    const aimed = Math.hypot(p.x - start.x, p.y - start.y) > 0.03; // [m] a drag sets the heading
    sendGoal(start.x, start.y, aimed ? Math.atan2(p.y - start.y, p.x - start.x) : 0);
  };
  map.svg.addEventListener("pointermove", move);
  map.svg.addEventListener("pointerup", up);
}

/** The occupancy grid, redrawn only when a new one arrives (a data URL is not cheap). */
function drawGrid() {
  if (!map) return;
  fill(map.gridLayer, grid?.info ? gridImage(grid) : null);
}

function gridImage(occupancy) {
  const { width, height, resolution, origin } = occupancy.info;
  const canvas = document.createElement("canvas");
  canvas.width = width;
  canvas.height = height;
  const context = canvas.getContext("2d");
  const image = context.createImageData(width, height);
  occupancy.data.forEach((value, i) => {
    const shade = value < 0 ? 200 : 255 - Math.round((Math.min(100, value) / 100) * 200);
    image.data.set([shade, shade, shade, 255], i * 4);
  });
  context.putImageData(image, 0, 0);
  // Row 0 of the grid is at the origin (bottom); the layer's y flip puts the image's top there.
  return svg("image", { href: canvas.toDataURL(), x: origin.position.x, y: origin.position.y, width: width * resolution, height: height * resolution, style: "image-rendering: pixelated" });
}

/** What moves: the lights, the path, the goal and the robot. */
function draw() {
  if (!map) return;
  const [x0, y0, x1, y1] = bounds;
  const span = Math.max(x1 - x0, y1 - y0);
  const size = span / 60; // robot and markers scale with the world
  fill(
    map.dynamic,
    lights.map((light) =>
      svg(
        "g",
        { class: `light${light.movable ? " movable" : ""}`, dataset: { testid: "map-light", name: light.name, movable: String(light.movable) } },
        svg("circle", { class: "glow", cx: light.x, cy: light.y, r: size * 1.8 }),
        svg("circle", { class: "bulb", cx: light.x, cy: light.y, r: size * 0.8, "stroke-width": size / 6 }),
      ),
    ),
    trail.length > 1 ? svg("polyline", { class: "trail", points: trail.map((p) => p.join(",")).join(" "), "stroke-width": span / 250 }) : null,
    goal ? marker(goal, size, "goal") : null,
    pose ? marker(pose, size * 1.2, "robot") : null,
  );
}

/** An arrowhead at p pointing along p.yaw: the robot filled, a goal or the start outlined. */
function marker(p, size, kind, testid = `map-${kind}`) {
  const at = (ahead, left) => [
    p.x + Math.cos(p.yaw) * ahead - Math.sin(p.yaw) * left,
    p.y + Math.sin(p.yaw) * ahead + Math.cos(p.yaw) * left,
  ];
  const points = [at(size * 1.3, 0), at(-size * 0.8, size * 0.8), at(-size * 0.4, 0), at(-size * 0.8, -size * 0.8)];
  return svg(
    "g",
    { class: kind, dataset: { testid } },
    svg("polygon", { points: points.map((q) => q.join(",")).join(" "), "stroke-width": size / 5 }),
  );
}
