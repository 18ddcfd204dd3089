// "Check all seeds": the exercise's grading cases (seed and start pose, as `robodojo check` runs
// them) started as runs of the editor's nodes, two at a time (the student's run limit), with a
// progress bar over every case's simulated time, each case's checks shown as soon as its run is
// judged, and the verdict by each check's worst case (GET /api/exercises/{id}/check sums it up:
// the same rule the command line and the grade book use).

import { api, ApiError } from "../common/api.js";
import { byId, fill, h } from "../common/dom.js";
import { checkChip, checkBody, refreshControls, runGoing } from "./runner.js";
import { app, on } from "./state.js";

const POLL_MS = 300; // [ms] the summary while cases run: a judged case shows within ~0.3 s
const AT_ONCE = 2; // cases running together: the lab's default runs per student
const RETRY_MS = 2000; // [ms] a case refused for the run limit is tried again after this

const button = byId("check-button");
const panel = byId("check-panel");
const bar = byId("check-progress");
const text = byId("check-text");
const stopButton = byId("check-stop");
const casesBox = byId("check-cases");
const verdictBox = byId("check-verdict");

let check = null; // {exercise, cases, runIds: [], stopped, timer}

export function initCheck() {
  button.addEventListener("click", () => startCheck());
  stopButton.addEventListener("click", () => stopCheck());
  on("target", ({ target }) => {
    button.hidden = !target.exercise || Boolean(app.watching);
    if (check) stopCheck();
    panel.hidden = true;
  });
  on("run-controls", ({ going }) => {
    button.disabled = going || Boolean(check) || Boolean(app.watching);
  });
}

/** Whether a check's cases are being started or run. */
export function checkGoing() {
  return Boolean(check);
}

async function startCheck() {
  const exercise = app.target?.exercise;
  if (!exercise || check || runGoing()) return;
  let body;
  try {
    body = await checkBody();
  } catch (error) {
    say(error.message);
    return;
  }
  body.clock = exercise.clock; // judged as `robodojo check` judges: its clock, its duration
  body.duration = exercise.duration_s;
  delete body.seed;
  delete body.teleop;
  const cases = exercise.cases || [];
  check = { exercise, cases, runIds: [], stopped: false, timer: null, summary: null };
  app.checking = true;
  refreshControls();
  panel.hidden = false;
  stopButton.disabled = false;
  fill(casesBox);
  fill(verdictBox);
  show(null);
  const current = check;
  current.timer = setInterval(() => poll(current), POLL_MS);
  try {
    for (let index = 0; index < cases.length && !current.stopped; index++) {
      await roomForOneMore(current);
      if (current.stopped) break;
      current.runIds.push(await startCase(current, body, index));
      poll(current);
    }
  } catch (error) {
    say(error.message); // the server's sentence, verbatim
    finishCheck(current);
  }
}

/** Wait until fewer than AT_ONCE of this check's runs are going. */
async function roomForOneMore(current) {
  while (!current.stopped) {
    const runs = current.summary?.runs || [];
    const going = current.runIds.length - runs.filter((run) => ["finished", "failed", "interrupted"].includes(run.state)).length;
    if (going < AT_ONCE) return;
    await sleep(POLL_MS);
  }
}

async function startCase(current, body, index) {
  for (;;) {
    try {
      const run = await api("/api/runs", { method: "POST", body: { ...body, case: index } });
      return run.id;
    } catch (error) {
      // Another run of this student (another tab) holds a slot: wait for it, as a person would.
      if (!(error instanceof ApiError && error.status === 429) || current.stopped) throw error;
      say(`${error.message} (trying again)`);
      await sleep(RETRY_MS);
    }
  }
}

async function poll(current) {
  if (check !== current || !current.runIds.length || current.polling) return;
  current.polling = true;
  try {
    const ids = current.runIds.join(",");
    const summary = await api(`/api/exercises/${current.exercise.id}/check?runs=${ids}`);
    if (check !== current) return;
    current.summary = summary;
    show(summary);
    const allStarted = current.stopped || current.runIds.length === current.cases.length;
    if (allStarted && summary.ended === current.runIds.length) finishCheck(current);
  } catch (error) {
    say(error.message);
  } finally {
    current.polling = false;
  }
}

function show(summary) {
  const cases = check?.cases || [];
  const runs = summary?.runs || [];
  let done = 0;
  let total = 0;
  for (const [index] of cases.entries()) {
    const run = runs[index];
    const duration = run?.duration_s || check.exercise.duration_s || 1;
    total += duration;
    done += run ? Math.min(run.time_s || 0, duration) : 0;
  }
  bar.max = total || 1;
  bar.value = done;
  const ended = summary?.ended || 0;
  const percent = total ? Math.round((100 * done) / total) : 0;
  bar.setAttribute("aria-valuetext", `${ended} of ${cases.length} cases judged, ${percent}% of their time simulated`);
  text.textContent = `${ended} of ${cases.length} cases judged`;
  fill(
    casesBox,
    runs.map((run) => {
      const start = cases[run.case]?.start;
      const where = start ? ` from (${start[0]}, ${start[1]})` : "";
      const judged = ["finished", "failed", "interrupted"].includes(run.state) && run.checks.length;
      return h(
        "li",
        { dataset: { testid: "check-case", case: String(run.case), state: run.state } },
        h("span", { class: "case-name" }, `Seed ${run.seed}${where}: `),
        judged ? run.checks.map((c) => checkChip(c)) : h("span", { class: "case-state" }, run.reason || run.state),
      );
    }),
  );
  if (summary?.done) {
    const passed = summary.passed;
    fill(
      verdictBox,
      h(
        "span",
        { class: `score ${passed ? "pass" : "fail"}`, dataset: { testid: "check-verdict" } },
        passed ? "Passes on every case" : "Does not pass on every case",
      ),
      summary.checks.map((c) => checkChip({ ...c, description: `${c.description} (worst case)` })),
    );
  }
}

function stopCheck() {
  const current = check;
  if (!current) return;
  current.stopped = true;
  stopButton.disabled = true;
  for (const run of current.summary?.runs || []) {
    if (!["finished", "failed", "interrupted"].includes(run.state)) {
      api(`/api/runs/${run.id}/stop`, { method: "POST" }).catch(() => {});
    }
  }
  say("Check stopped: the cases that ran are shown.");
}

function finishCheck(current) {
  if (check !== current) return;
  clearInterval(current.timer);
  check = null;
  app.checking = false;
  stopButton.disabled = true;
  refreshControls();
}

function say(sentence) {
  text.textContent = sentence;
}

function sleep(ms) {
  return new Promise((resolve) => setTimeout(resolve, ms));
}
