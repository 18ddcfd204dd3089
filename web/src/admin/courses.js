// Courses: create one, pick one to enrol students and assign exercises, delete it; the grade
// book of a course (or of every student), fetched as CSV, parsed and shown as a table, with
// the CSV itself to download.

import { ApiError, api } from "../common/api.js";
import { parseCsv } from "../common/csv.js";
import { h } from "../common/dom.js";
import { $, $$, busy, clearError, clearRowError, rowError, setOptions, showError, timeEl } from "./dom.js";
import { showBoards } from "./leaderboards.js";
import { watchUrl } from "./runs.js";
import { exerciseTitle, loadCourses, loadUsers, state, subscribe } from "./state.js";

let selected = null; // the course shown in detail (GET /api/admin/courses/{id})

const GRADE_LABELS = {
  student_id: "Student id",
  student_name: "Student",
  email: "Email",
  exercise: "Exercise",
  best_score: "Best score",
  attempts: "Attempts",
  best_run_id: "Best run",
  best_run_url: "Best run (API)",
};

// ------------------------------------------------------------------------------ list
function renderCourses() {
  const rows = state.courses.map((course) => {
    const open = h(
      "button",
      {
        type: "button",
        class: "link",
        "aria-pressed": String(selected?.id === course.id),
        title: "show its students, exercises and grades",
      },
      course.name,
    );
    open.addEventListener("click", () => openCourse(course.id));
    return h(
      "tr",
      { dataset: { courseId: course.id }, class: selected?.id === course.id ? "selected" : null },
      h("th", { scope: "row" }, open),
      h("td", {}, String(course.student_count ?? "")),
      h("td", {}, course.exercises.length ? course.exercises.join(", ") : h("span", { class: "muted" }, "none")),
      h("td", {}, timeEl(course.created_at)),
    );
  });
  $("#courses-table tbody").replaceChildren(...rows);
  $("#courses-empty").hidden = state.courses.length > 0;
  for (const select of $$(".course-select")) {
    setOptions(select, state.courses.map((c) => [c.id, c.name]), { first: ["", "none"] });
  }
  setOptions($("#grades-course"), state.courses.map((c) => [c.id, c.name]), { first: ["", "every student"] });
  updateExportLink();
}

async function openCourse(id, focus = true) {
  try {
    clearError($("#courses-error"));
    selected = await api(`/api/admin/courses/${encodeURIComponent(id)}`);
  } catch (error) {
    showError($("#courses-error"), error);
    return;
  }
  renderDetail();
  renderCourses();
  $("#course-detail").hidden = false;
  if (focus) $("#h-course").focus();
  if ($("#grades-course").value !== id) {
    $("#grades-course").value = id;
    updateExportLink();
    loadGrades();
  }
}

async function refreshCourse() {
  if (!selected) return;
  await Promise.all([openCourse(selected.id, false), loadCourses()]);
}

// ------------------------------------------------------------------------------ detail
function renderDetail() {
  const course = selected;
  $("#h-course").textContent = course.name;
  clearError($("#course-error"));

  const list = $("#course-exercises");
  list.replaceChildren(
    ...course.exercises.map((id) => {
      const remove = h(
        "button",
        { type: "button", class: "chip-x", "aria-label": `Take ${id} off the course` },
        "×",
      );
      const item = h("li", { class: "chip" }, h("span", { title: id }, exerciseTitle(id) || id), remove);
      remove.addEventListener("click", () =>
        busy(remove, async () => {
          try {
            await api(`/api/admin/courses/${encodeURIComponent(course.id)}/exercises/${encodeURIComponent(id)}`, { method: "DELETE" });
            await refreshCourse();
            $("#course-add-ex").elements.exercise.focus();
          } catch (error) {
            showError($("#course-error"), error);
          }
        }),
      );
      return item;
    }),
  );
  if (!course.exercises.length) list.append(h("li", { class: "muted" }, "No exercise assigned yet."));
  setOptions(
    $("#course-add-ex").elements.exercise,
    state.exercises.filter((e) => !e.error && !course.exercises.includes(e.id)).map((e) => [e.id, `${e.title} (${e.id})`]),
  );

  const students = course.students || [];
  $("#course-students tbody").replaceChildren(
    ...students.map((s) => {
      const cell = h("td", { class: "row-actions" });
      const remove = h(
        "button",
        { type: "button", class: "secondary small-btn", "aria-label": `Unenrol ${s.name}` },
        "Unenrol",
      );
      remove.addEventListener("click", () =>
        busy(remove, async () => {
          clearRowError(cell);
          try {
            await api(`/api/admin/courses/${encodeURIComponent(course.id)}/students/${encodeURIComponent(s.id)}`, { method: "DELETE" });
            await refreshCourse();
            $("#h-course-students").focus();
          } catch (error) {
            rowError(cell, error);
          }
        }),
      );
      cell.append(remove);
      return h(
        "tr",
        { dataset: { userId: s.id } },
        h("th", { scope: "row" }, s.name),
        h("td", {}, s.email || ""),
        h("td", {}, s.disabled ? "disabled" : "active"),
        cell,
      );
    }),
  );
  if (!students.length) {
    $("#course-students tbody").append(h("tr", {}, h("td", { colspan: 4, class: "muted" }, "No student enrolled yet.")));
  }
  renderEnrolList();
  showBoards(course);
}

function renderEnrolList() {
  if (!selected) return;
  const form = $("#course-enrol");
  const filter = form.elements.filter.value.trim().toLowerCase();
  const enrolled = new Set((selected.students || []).map((s) => s.id));
  const candidates = state.users
    .filter((u) => u.role === "student" && !enrolled.has(u.id))
    .filter((u) => !filter || u.name.toLowerCase().includes(filter) || (u.email || "").toLowerCase().includes(filter))
    .sort((a, b) => a.name.localeCompare(b.name));
  const list = $("#enrol-list");
  list.replaceChildren(
    ...candidates.map((u) =>
      h(
        "label",
        { class: "check" },
        h("input", { type: "checkbox", value: u.id, name: "student" }),
        ` ${u.name}`,
        u.email ? h("span", { class: "muted" }, ` ${u.email}`) : null,
        u.disabled ? h("span", { class: "muted" }, " (disabled)") : null,
      ),
    ),
  );
  if (!candidates.length) {
    list.append(h("p", { class: "muted small" }, filter ? "No student matches." : "Every student is enrolled. Add students on the Users page."));
  }
}

// ------------------------------------------------------------------------------ grades
function updateExportLink() {
  const course = $("#grades-course").value;
  $("#grades-export").href = `/api/admin/grades.csv${course ? `?course=${encodeURIComponent(course)}` : ""}`;
}

function gradeCell(header, value) {
  if (header === "best_run_id" && value) {
    return h("td", {}, h("a", { href: watchUrl(value), target: "_blank", rel: "noopener", title: value }, value.slice(0, 8)));
  }
  if (header === "best_run_url" && value) {
    return h("td", {}, h("a", { href: value, target: "_blank", rel: "noopener" }, "JSON"));
  }
  if (header === "best_score") {
    return h("td", { class: "num" }, value === "" ? h("span", { class: "muted" }, "–") : value);
  }
  if (header === "attempts") return h("td", { class: "num" }, value);
  return h("td", {}, value);
}

async function loadGrades() {
  const table = $("#grades-table");
  const course = $("#grades-course").value;
  updateExportLink();
  let text;
  try {
    clearError($("#grades-error"));
    text = await api(`/api/admin/grades.csv${course ? `?course=${encodeURIComponent(course)}` : ""}`);
    if (typeof text !== "string") throw new ApiError(0, "the grade book did not come as CSV text");
  } catch (error) {
    showError($("#grades-error"), error);
    return;
  }
  const [header = [], ...rows] = parseCsv(text);
  $("thead", table).replaceChildren(
    h("tr", {}, header.map((name) => h("th", { scope: "col", title: name }, GRADE_LABELS[name] || name))),
  );
  $("tbody", table).replaceChildren(
    ...rows.map((row) => h("tr", {}, header.map((name, i) => gradeCell(name, row[i] ?? "")))),
  );
  $("#grades-empty").hidden = rows.length > 0;
}

// ------------------------------------------------------------------------------ wiring
export function initCourses() {
  subscribe("courses", renderCourses);
  subscribe("users", renderEnrolList);
  subscribe("exercises", () => {
    if (selected) renderDetail();
  });

  const create = $("#create-course");
  create.addEventListener("submit", async (event) => {
    event.preventDefault();
    await busy($("button[type=submit]", create), async () => {
      clearError(create);
      try {
        const course = await api("/api/admin/courses", { method: "POST", body: { name: create.elements.name.value } });
        create.reset();
        await loadCourses();
        await openCourse(course.id);
      } catch (error) {
        showError(create, error);
      }
    });
  });

  const assign = $("#course-add-ex");
  assign.addEventListener("submit", async (event) => {
    event.preventDefault();
    if (!selected) return;
    await busy($("button[type=submit]", assign), async () => {
      clearError(assign);
      const exercise = assign.elements.exercise.value;
      if (!exercise) {
        showError(assign, "every exercise is assigned already");
        return;
      }
      try {
        await api(`/api/admin/courses/${encodeURIComponent(selected.id)}/exercises/${encodeURIComponent(exercise)}`, { method: "PUT" });
        await refreshCourse();
        loadGrades();
        assign.elements.exercise.focus();
      } catch (error) {
        showError(assign, error);
      }
    });
  });

  const enrol = $("#course-enrol");
  enrol.elements.filter.addEventListener("input", renderEnrolList);
  $("#enrol-all").addEventListener("click", () => {
    for (const box of $$("#enrol-list input[type=checkbox]")) box.checked = true;
  });
  enrol.addEventListener("submit", async (event) => {
    event.preventDefault();
    if (!selected) return;
    const ids = $$("#enrol-list input[type=checkbox]:checked").map((box) => box.value);
    await busy($("button[type=submit]", enrol), async () => {
      clearError(enrol);
      if (!ids.length) {
        showError(enrol, "tick the students to enrol first");
        return;
      }
      try {
        for (const id of ids) {
          await api(`/api/admin/courses/${encodeURIComponent(selected.id)}/students/${encodeURIComponent(id)}`, { method: "PUT" });
        }
      } catch (error) {
        showError(enrol, error);
      }
      await refreshCourse();
      loadGrades();
      enrol.elements.filter.focus();
    });
  });

  $("#course-delete").addEventListener("click", async (event) => {
    if (!selected) return;
    if (!window.confirm(`Delete the course '${selected.name}'? Its students and their runs stay.`)) return;
    await busy(event.currentTarget, async () => {
      try {
        await api(`/api/admin/courses/${encodeURIComponent(selected.id)}`, { method: "DELETE" });
        selected = null;
        $("#course-detail").hidden = true;
        $("#grades-course").value = "";
        await loadCourses();
        loadGrades();
        $("#h-course-list").focus();
      } catch (error) {
        showError($("#course-error"), error);
      }
    });
  });

  $("#grades-course").addEventListener("change", loadGrades);
  $("#grades-refresh").addEventListener("click", (event) => busy(event.currentTarget, loadGrades));
  $("#h-course-list").tabIndex = -1;
  $("#h-course-students").tabIndex = -1;
}

export async function showCourses() {
  try {
    clearError($("#courses-error"));
    await Promise.all([loadCourses(), state.users.length ? null : loadUsers()]);
    if (selected) await openCourse(selected.id, false);
  } catch (error) {
    showError($("#courses-error"), error);
  }
  loadGrades();
}
