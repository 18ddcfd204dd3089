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
//   run-controls {going}           the run controls were redrawn: a run is starting or going
//   goto-line  {node, line}        show this line of this node's file in the editor
//   run-graph  {run, graph}        the node/topic graph of the run on show (its built-in nodes)
//   drive      {}                  a run to drive with the arrow keys started: show the pad
//   watch-ended {}                 the run opened by its id is left for the student's own code
//   files      {names}             the workspace's files changed (added, deleted, loaded)
//   file-shown {filename}          the editor shows this file
//   show-view  {panel}             select this view tab (e.g. "panel-compare" from the history)

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
  /** A run opened by its id (/?run=ID, e.g. an instructor watching a student's run): the
   * editor shows that run's code read-only instead of a workspace. */
  watching: null,
  /** Ids of runs this page started with the teleop node (free play, "Drive with arrow keys"). */
  teleopRuns: new Set(),
  /** run id -> the nodes its graph lists (student and built-in), once the graph is loaded. */
  graphNodes: new Map(),
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

/** Whether the arrow keys can drive this run: the page started it with teleop, its exercise
 * has the teleop node, or its graph lists one. */
export function runHasTeleop(run) {
  if (!run) return Boolean(app.target?.exercise?.builtin_nodes?.includes("teleop"));
  if (app.teleopRuns.has(run.id)) return true;
  if (app.exercises.get(run.exercise)?.builtin_nodes?.includes("teleop")) return true;
  return Boolean(app.graphNodes.get(run.id)?.includes("teleop"));
}

/** A node's file name from its node name, and back. */
export const fileOf = (node) => `${node}.py`;
export const nodeOf = (filename) => filename.replace(/\.py$/, "");
/** A node of a run started from the page: a .py file at the top of the workspace. */
export const isNodeFile = (filename) => /^[^/]+\.py$/.test(filename) && !/\.launch\.py$/i.test(filename);
// ROS 1 XML (.launch, .xml) or a ROS 2 Python launch file (.launch.py), read by the server.
export const isLaunchFile = (filename) => /\.(launch|xml|launch\.py)$/i.test(filename);
