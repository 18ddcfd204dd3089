// A course's leaderboard of one exercise, as the instructor sees it: every student's best graded
// run with their name and pseudonym side by side (whichever the students see), hidden or not;
// show or hide it, choose names or pseudonyms, and reset it (runs started before then stop
// counting on the board; the grade book keeps them).

import { api } from "../common/api.js";
import { h } from "../common/dom.js";
import { $, busy, clearError, setOptions, showError, timeEl } from "./dom.js";
import { watchUrl } from "./runs.js";
import { exerciseTitle, state } from "./state.js";

let course = null; // the course on show ({id, name, exercises})

const boardPath = () =>
  `/api/courses/${encodeURIComponent(course.id)}/leaderboards/${encodeURIComponent($("#board-exercise").value)}`;

/** Called whenever the course on show is (re)drawn. */
export function showBoards(selected) {
  course = selected;
  const ids = course.exercises.length ? course.exercises : state.exercises.filter((e) => !e.error).map((e) => e.id);
  setOptions($("#board-exercise"), ids.map((id) => [id, exerciseTitle(id) || id]));
  load();
}

function figure(board, value) {
  if (value === null || value === undefined) return h("span", { class: "muted" }, "–");
  return `${+value.toFixed(3)}${board.key_figure?.unit ? ` ${board.key_figure.unit}` : ""}`;
}

function render(board) {
  $("#board-visible").checked = board.visible;
  $("#board-names").value = board.names;
  const key = board.key_figure;
  const ranking = key ? `score, then ${key.check} (${key.better} is better), then the earlier run` : "score, then the earlier run";
  $("#board-status").textContent =
    `${board.visible ? "Shown to the course's students" : "Hidden: students get 404"}, ranked by ${ranking}.` +
    (board.note ? ` The board was ${board.note}.` : "");
  $("#board-table thead").replaceChildren(
    h(
      "tr",
      {},
      ["#", "Student", "Pseudonym", "Score", key ? key.check : null, "Run", "When"]
        .filter(Boolean)
        .map((label) => h("th", { scope: "col" }, label)),
    ),
  );
  const rows = board.entries.map((e) =>
    h(
      "tr",
      { dataset: { userId: e.user_id } },
      h("td", { class: "num" }, e.rank),
      h("th", { scope: "row" }, e.real_name),
      h("td", {}, e.pseudonym),
      h("td", { class: "num" }, e.score),
      key ? h("td", { class: "num" }, figure(board, e.key_value)) : null,
      h("td", {}, h("a", { href: watchUrl(e.run_id), target: "_blank", rel: "noopener", title: e.run_id }, e.run_id.slice(0, 8))),
      h("td", {}, timeEl(e.achieved_at)),
    ),
  );
  if (!rows.length) rows.push(h("tr", {}, h("td", { colspan: 7, class: "muted" }, "No graded run on this board yet.")));
  $("#board-table tbody").replaceChildren(...rows);
}

async function load() {
  if (!course || !$("#board-exercise").value) {
    $("#board-table tbody").replaceChildren();
    $("#board-status").textContent = "Assign an exercise to see its leaderboard.";
    return;
  }
  const wanted = boardPath();
  try {
    clearError($("#board-error"));
    const board = await api(wanted);
    if (wanted === boardPath()) render(board); // not another course or exercise meanwhile
  } catch (error) {
    showError($("#board-error"), error);
  }
}

async function change(body) {
  clearError($("#board-error"));
  try {
    await api(`${boardPath()}/settings`, { method: "PUT", body });
  } catch (error) {
    showError($("#board-error"), error);
  }
  await load();
}

export function initBoards() {
  $("#board-exercise").addEventListener("change", load);
  $("#board-visible").addEventListener("change", (event) => change({ visible: event.currentTarget.checked }));
  $("#board-names").addEventListener("change", (event) => change({ names: event.currentTarget.value }));
  $("#board-reset").addEventListener("click", (event) => {
    if (!course) return;
    const title = exerciseTitle($("#board-exercise").value) || $("#board-exercise").value;
    if (!window.confirm(`Reset the leaderboard of '${title}' in '${course.name}'? Runs started before now stop counting on it; they stay in the grade book.`)) return;
    busy(event.currentTarget, async () => {
      clearError($("#board-error"));
      try {
        const answer = await api(`${boardPath()}/reset`, { method: "POST" });
        await load();
        $("#board-status").textContent = `${answer.message}. ${$("#board-status").textContent}`;
      } catch (error) {
        showError($("#board-error"), error);
      }
    });
  });
}
