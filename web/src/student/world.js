// The world from above, and what a person can do to a running robot: press its button, move
// the light, set a goal pose (click on the map; drag to aim), drive with the arrow keys where
// the exercise has the teleop node. The robot's path and pose come from the `tf` topic
// (map -> base_link), the occupancy grid from `map` when the exercise publishes one.

import { byId, fill, h, svg } from "../common/dom.js";
import { csvFileName, csvSamples, yawOf } from "../common/fields.js";
import { apiText } from "../common/api.js";
import { app, on, robotTopics, want } from "./state.js";
import { drivePad } from "./teleop.js";

const OWNER = "world";
const POSE_RATE_HZ = 10; // [Hz] the robot's pose on the map
const DRAG_COMMANDS_HZ = 10; // light moves while dragging; the server takes 50 commands/s
const TRAIL_POINTS = 5000;

const panel = byId("panel-world");
const status = h("p", { class: "hint", role: "status", dataset: { testid: "world-status" } });
let map = null; // {svg, layers}
let bounds = [0, 0, 1, 1];
let trail = [];
let pose = null;
let goal = null;
let light = null;
let grid = null;
let mode = "goal";

export function initWorld() {
  on("target", ({ target }) => {
    bounds = app.worlds.get(target.world)?.bounds || [0, 0, 1, 1];
    trail = [];
    pose = goal = light = grid = null;
    build(target);
    draw();
  });
  on("run-shown", ({ live }) => {
    trail = [];
    pose = goal = grid = null;
    if (live) {
      want(OWNER, "tf", POSE_RATE_HZ);
      want(OWNER, "goal", 2);
      want(OWNER, "map", 1);
    }
    enable(live);
    draw();
  });
  on("telemetry", ({ frame }) => {
    if (frame.topic === "tf") addPose(frame.msg);
    else if (frame.topic === "goal") goal = poseOf(frame.msg?.pose);
    else if (frame.topic === "map") grid = frame.msg;
    else return;
    draw();
  });
  on("run-ended", ({ run }) => {
    enable(false);
    replay(run);
  });
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

function build(target) {
  const [x0, y0, x1, y1] = bounds;
  const picture = svg("svg", {
    class: "world-map",
    viewBox: `${x0 - 0.05} ${-y1 - 0.05} ${x1 - x0 + 0.1} ${y1 - y0 + 0.1}`,
    role: "img",
    "aria-label": `Top view of ${app.worlds.get(target.world)?.title || target.world}, ${(x1 - x0).toFixed(1)} by ${(y1 - y0).toFixed(1)} m: click to set the goal or move the light`,
    dataset: { testid: "world-map" },
  });
  const layer = svg("g", { transform: "scale(1,-1)" });
  picture.append(layer);
  map = { svg: picture, layer };
  picture.addEventListener("pointerdown", pointerDown);

  const canPress = robotTopics(target.robot).some((t) => t.name.toLowerCase() === "button");
  const teleop = target.exercise?.builtin_nodes?.includes("teleop");
  const goalX = number("goal-x", "x [m]");
  const goalY = number("goal-y", "y [m]");
  const goalYaw = number("goal-yaw", "yaw [deg]");
  goalYaw.value = 0;
  const lightX = number("light-x", "x [m]");
  const lightY = number("light-y", "y [m]");
  const modeRadios = ["goal", "light"].map((value) =>
    h("label", {}, h("input", { type: "radio", name: "map-mode", value, checked: value === mode, onchange: () => (mode = value) }), ` ${value}`),
  );
  fill(
    panel,
    h(
      "div",
      { class: "world" },
      h("div", { class: "map-box" }, picture, h("fieldset", { class: "map-mode" }, h("legend", {}, "A click on the map sets the"), modeRadios), status),
      h(
        "div",
        { class: "interact" },
        canPress
          ? h("section", {}, h("h3", {}, "Button"), pressButton())
          : null,
        h(
          "section",
          {},
          h("h3", {}, "Goal pose"),
          h(
            "form",
            { class: "inline-form", onsubmit: (e) => (e.preventDefault(), sendGoal(+goalX.value, +goalY.value, (+goalYaw.value * Math.PI) / 180)) },
            labelled(goalX),
            labelled(goalY),
            labelled(goalYaw),
            h("button", { type: "submit", class: "small live-only", dataset: { testid: "goal-send" } }, "Set goal"),
          ),
        ),
        h(
          "section",
          {},
          h("h3", {}, "Light"),
          h(
            "form",
            { class: "inline-form", onsubmit: (e) => (e.preventDefault(), sendLight(+lightX.value, +lightY.value)) },
            labelled(lightX),
            labelled(lightY),
            h("button", { type: "submit", class: "small live-only", dataset: { testid: "light-send" } }, "Move light"),
          ),
        ),
        h("section", {}, h("h3", {}, "Drive"), teleop ? drivePad(send) : h("p", { class: "hint" }, "This exercise has no keyboard driving (no teleop node).")),
      ),
    ),
  );
  map.inputs = { goalX, goalY, goalYaw, lightX, lightY };
  enable(Boolean(app.live));
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
  Object.assign(map.inputs.goalYaw, { value: ((yaw * 180) / Math.PI).toFixed(0) });
  draw();
  send("goal", { x, y, yaw });
}

function sendLight(x, y) {
  map.inputs.lightX.value = x.toFixed(2);
  map.inputs.lightY.value = y.toFixed(2);
  send("light", { x, y }).then((ok) => {
    if (!ok) return;
    light = { x, y }; // drawn once the server has moved it
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
  map.svg.setPointerCapture(event.pointerId);
  let lastSent = 0;
  const move = (e) => {
    const p = worldPoint(e);
    if (mode === "light" && performance.now() - lastSent > 1000 / DRAG_COMMANDS_HZ) {
      lastSent = performance.now();
      sendLight(p.x, p.y);
    }
  };
  const up = (e) => {
    map.svg.removeEventListener("pointermove", move);
    map.svg.removeEventListener("pointerup", up);
    const p = worldPoint(e);
    if (mode === "light") return sendLight(p.x, p.y);
    const aimed = Math.hypot(p.x - start.x, p.y - start.y) > 0.03; // [m] a drag sets the heading
    sendGoal(start.x, start.y, aimed ? Math.atan2(p.y - start.y, p.x - start.x) : 0);
  };
  map.svg.addEventListener("pointermove", move);
  map.svg.addEventListener("pointerup", up);
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

function draw() {
  if (!map) return;
  const [x0, y0, x1, y1] = bounds;
  const span = Math.max(x1 - x0, y1 - y0);
  const step = span > 4 ? 1 : 0.5; // [m] grid lines
  const lines = [];
  for (let x = Math.ceil(x0 / step) * step; x <= x1 + 1e-9; x += step) lines.push(svg("line", { x1: x, x2: x, y1: y0, y2: y1 }));
  for (let y = Math.ceil(y0 / step) * step; y <= y1 + 1e-9; y += step) lines.push(svg("line", { x1: x0, x2: x1, y1: y, y2: y }));
  const size = span / 60; // robot and markers scale with the world
  fill(
    map.layer,
    svg("rect", { x: x0, y: y0, width: x1 - x0, height: y1 - y0, class: "floor" }),
    grid?.info ? gridImage(grid) : null,
    svg("g", { class: "grid-lines", "stroke-width": span / 500 }, lines),
    trail.length > 1 ? svg("polyline", { class: "trail", points: trail.map((p) => p.join(",")).join(" "), "stroke-width": span / 250 }) : null,
    goal ? marker(goal, size, "goal") : null,
    light ? svg("circle", { cx: light.x, cy: light.y, r: size * 0.8, class: "light" }) : null,
    pose ? marker(pose, size * 1.2, "robot") : null,
  );
}

/** An arrowhead at p pointing along p.yaw: the robot filled, a goal outlined. */
function marker(p, size, kind) {
  const at = (ahead, left) => [
    p.x + Math.cos(p.yaw) * ahead - Math.sin(p.yaw) * left,
    p.y + Math.sin(p.yaw) * ahead + Math.cos(p.yaw) * left,
  ];
  const points = [at(size * 1.3, 0), at(-size * 0.8, size * 0.8), at(-size * 0.4, 0), at(-size * 0.8, -size * 0.8)];
  return svg(
    "g",
    { class: kind, dataset: { testid: `map-${kind}` } },
    svg("polygon", { points: points.map((q) => q.join(",")).join(" "), "stroke-width": size / 5 }),
  );
}
