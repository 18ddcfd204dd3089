// What the page's parts share: the catalogue, the chosen exercise (or robot in a world), the run
// on show, and events between the parts. Each part listens for what it draws; none reaches
// into another's DOM.
//
// Events (detail):
//   target     {target}            another exercise or robot/world was chosen
//   run-shown  {run, live}         a run is on show: just started (live) or opened from history
//   run-record {run}               a fresher record of the run on show (polled while live)
//   telemetry  {frame}             a telemetry frame of the live run
//   log        {node, line}        a log line of the live run
//   run-state  {state, reason, time_s}
//   run-topic  {topic, msg_type}   a topic of the live run seen for the first time
//   run-ended  {run}               the run on show has ended and its record (checks) is stored
//   goto-line  {node, line}        show this line of this node's file in the editor

export const app = {
  me: null,
  robots: new Map(), // id -> {id, title, worlds, topics}
  worlds: new Map(), // id -> {id, title, robots, bounds}
  exercises: new Map(), // id -> the exercise as /api/exercises describes it
  /** {workspace, exercise: object|null, robot, world} */
  target: null,
  /** The run on show (its latest record) and whether it is live. */
  run: null,
  live: null, // LiveRun while the run on show is going
};

const bus = new EventTarget();

export function emit(name, detail = {}) {
  bus.dispatchEvent(new CustomEvent(name, { detail }));
}

export function on(name, listener) {
  bus.addEventListener(name, (event) => listener(event.detail));
}

export const END_STATES = new Set(["finished", "failed", "interrupted"]);

/** The topics each part wants from the live run, at what rate; the highest rate wins. */
const wants = new Map(); // topic -> Map(owner -> rate)

export function want(owner, topic, rateHz) {
  if (!wants.has(topic)) wants.set(topic, new Map());
  if (rateHz > 0) wants.get(topic).set(owner, rateHz);
  else wants.get(topic).delete(owner);
  applyWant(topic);
}

function applyWant(topic) {
  if (!app.live) return;
  const rates = [...(wants.get(topic)?.values() || [])];
  app.live.follow(topic, rates.length ? Math.max(...rates) : 0);
}

/** Send every wanted subscription to a new live connection. */
export function applyWants() {
  for (const topic of wants.keys()) applyWant(topic);
}

/** The robot's topics that the robot publishes (sensors), then the others, as the API lists them. */
export function robotTopics(robotId) {
  return app.robots.get(robotId)?.topics || [];
}

/** A node's file name from its node name, and back. */
export const fileOf = (node) => `${node}.py`;
export const nodeOf = (filename) => filename.replace(/\.py$/, "");
