// The exercise's leaderboard in each of the student's courses that set it, at the top of the
// exercise's text: the student's rank in the summary line, the top of the board when opened
// (open or closed is remembered, closed at first so the exercise's text stays in view). Names or pseudonyms are as the
// instructor chose (the server decides; this only shows what it sends). A board the instructor
// hid answers 404 and is left out. Reloaded when another exercise is chosen and when a run ends.

import { ApiError, api } from "../common/api.js";
import { byId, fill, h } from "../common/dom.js";
import { app, on } from "./state.js";

const TOP_ROWS = 5; // the board's head; the student's own row is added below it when further down
const box = byId("leaderboard");
const OPEN_KEY = "robodojo.leaderboardOpen";
let courses = null; // [{id, name, exercises}] of the student, loaded once

export function initLeaderboard() {
  on("target", () => refresh());
  on("run-ended", () => refresh());
}

async function myCourses() {
  if (courses === null) courses = (await api("/api/courses")).courses;
  return courses;
}

async function boardOf(course, exerciseId) {
  try {
    return await api(`/api/courses/${encodeURIComponent(course.id)}/leaderboards/${encodeURIComponent(exerciseId)}`);
  } catch (error) {
    if (error instanceof ApiError && error.status === 404) return null; // hidden by the instructor
    throw error;
  }
}

async function refresh() {
  const target = app.target;
  const exercise = target?.exercise;
  if (!exercise) {
    box.hidden = true;
    return;
  }
  let boards;
  try {
    const setting = (await myCourses()).filter((c) => !c.exercises.length || c.exercises.includes(exercise.id));
    boards = (await Promise.all(setting.map((c) => boardOf(c, exercise.id)))).filter(Boolean);
  } catch (error) {
    if (app.target !== target) return;
    fill(box, h("p", { class: "hint" }, `Leaderboard: ${error.message}`));
    box.hidden = false;
    return;
  }
  if (app.target !== target) return; // another exercise was chosen meanwhile
  fill(box, boards.map(boardView));
  box.hidden = !boards.length;
}

function figure(board, value) {
  if (!board.key_figure) return null;
  if (value === null || value === undefined) return "-";
  const unit = board.key_figure.unit ? ` ${board.key_figure.unit}` : "";
  return `${+value.toFixed(2)}${unit}`;
}

function boardView(board) {
  const key = board.key_figure;
  const shown = board.entries.slice(0, TOP_ROWS);
  const own = board.entries.find((e) => e.you);
  if (own && own.rank > TOP_ROWS) shown.push(own);
  const standing = board.you
    ? `you are ${board.you.rank} of ${board.you.of}${board.names === "pseudonyms" ? `, as ${board.you.name}` : ""}`
    : "not on it yet: a finished, graded run puts you there";
  const ranking = key ? `by score, then ${key.check} (${key.better} is better), then the earlier run` : "by score, then the earlier run";
  const details = h(
    "details",
    { class: "leaderboard", dataset: { testid: "leaderboard", course: board.course } },
    h("summary", {}, `Leaderboard · ${board.course_name}: `, h("span", { class: "leaderboard-you", dataset: { testid: "leaderboard-rank" } }, standing)),
    shown.length
      ? h(
          "table",
          { class: "leaderboard-table" },
          h("caption", { class: "hint" }, `Best graded run of each student, ${ranking}.${board.note ? ` The board was ${board.note}.` : ""}`),
          h(
            "thead",
            {},
            h("tr", {}, h("th", { scope: "col" }, "#"), h("th", { scope: "col" }, "who"), h("th", { scope: "col" }, "score"), key ? h("th", { scope: "col" }, key.check) : null),
          ),
          h(
            "tbody",
            {},
            shown.map((e) =>
              h(
                "tr",
                { class: e.you ? "you" : null, "aria-current": e.you ? "true" : null },
                h("td", {}, e.rank),
                h("td", {}, e.name),
                h("td", {}, `${Math.round(e.score * 100)} %`),
                key ? h("td", {}, figure(board, e.key_value)) : null,
              ),
            ),
          ),
        )
      : h("p", { class: "hint" }, `No graded runs on this board yet${board.note ? ` (${board.note})` : ""}.`),
  );
  details.open = localStorage.getItem(OPEN_KEY) === "true";
  details.addEventListener("toggle", () => localStorage.setItem(OPEN_KEY, String(details.open)));
  return details;
}
