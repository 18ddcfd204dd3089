// Exercises: built-in and custom ones listed; a custom one made or edited from a template
// (a built-in, with title, text, duration, thresholds and optionally starter code changed) or
// from scratch (robot, world, clock, seeds, starter code, generic checks); custom ones deleted;
// any one tried (the reference solution of a built-in, the starter code of a custom one).

import { ApiError, api } from "../common/api.js";
import { h } from "../common/dom.js";
import { $, $$, busy, clearError, clearRowError, cmp, rowError, setOptions, shortId, showError } from "./dom.js";
import { vizUrl, watchUrl } from "./runs.js";
import { loadCatalog, loadExercises, state, subscribe } from "./state.js";

const MAX_NODES = 8;
const SCRATCH_STARTER = `"""Starter code: the student fills in step(). docs/controllers.md explains the step API."""

RATE_HZ = 10
SUBSCRIBE = []  # sensor topics obs carries, e.g. ["Distance"]


def step(obs):
    # read obs.<topic>; return (v, w), a dict {topic: value}, or None
    return None
`;

const form = () => $("#ex-form");
const builtins = () => state.exercises.filter((e) => !e.custom);
const builtin = (id) => state.exercises.find((e) => e.id === id && !e.custom);

// ------------------------------------------------------------------------------ list
function checkList(checks) {
  if (!checks || !checks.length) return h("span", { class: "muted" }, "–");
  return h(
    "ul",
    { class: "plain small" },
    checks.map((c) => h("li", {}, `${c.name} ${cmp(c.comparison)} ${c.threshold}${c.unit ? ` ${c.unit}` : ""}`)),
  );
}

function tryButton(exercise, cell) {
  const what = exercise.custom ? "starter code" : "reference solution";
  const label = exercise.custom ? "Try starter" : "Try reference";
  const button = h(
    "button",
    {
      type: "button",
      class: "small-btn",
      "data-testid": "exercise-try",
      "aria-label": `${label} of ${exercise.id}`,
      title: `run the ${what} as yourself, and watch it`,
    },
    label,
  );
  button.addEventListener("click", () =>
    busy(button, async () => {
      clearRowError(cell);
      cell.querySelector(".tried")?.remove();
      try {
        const run = await api(`/api/admin/exercises/${encodeURIComponent(exercise.id)}/try`, { method: "POST" });
        cell.append(
          h(
            "div",
            { class: "tried small", role: "status", "data-testid": "exercise-try-result" },
            `Run ${shortId(run.id)} started (${run.tried}): `,
            h("a", { href: watchUrl(run.id), target: "_blank", rel: "noopener" }, "Watch"),
            " · ",
            h("a", { href: vizUrl(run.id), target: "_blank", rel: "noopener" }, "3D"),
          ),
        );
      } catch (error) {
        rowError(cell, error);
      }
    }),
  );
  return button;
}

function exerciseRow(exercise) {
  const cell = h("td", { class: "row-actions" });
  if (exercise.error) {
    // A stored definition that no longer builds: shown with its reason, to edit or delete.
    cell.append(deleteButton(exercise, cell));
    return h(
      "tr",
      { dataset: { exerciseId: exercise.id }, class: "broken" },
      h("th", { scope: "row" }, exercise.title || exercise.id, h("br"), h("code", { class: "small" }, exercise.id)),
      h("td", { colspan: 3 }, h("span", { class: "error" }, exercise.error)),
      h("td", {}, "custom (broken)"),
      cell,
    );
  }
  cell.append(tryButton(exercise, cell), " ");
  if (exercise.custom) {
    const edit = h("button", { type: "button", class: "secondary small-btn", "aria-label": `Edit ${exercise.id}` }, "Edit");
    edit.addEventListener("click", () => openForm(exercise));
    cell.append(edit, " ", deleteButton(exercise, cell));
  } else {
    const copy = h(
      "button",
      { type: "button", class: "secondary small-btn", "aria-label": `Customise ${exercise.id}`, title: "a new custom exercise from this one" },
      "Customise",
    );
    copy.addEventListener("click", () => openForm(null, exercise.id));
    cell.append(copy);
  }
  const title = h("th", { scope: "row" }, exercise.title, h("br"), h("code", { class: "small" }, exercise.id));
  const more = h("details", { class: "small" }, h("summary", {}, "Details"));
  if (exercise.description) more.append(h("p", { class: "description" }, exercise.description));
  if (exercise.source) more.append(h("p", { class: "muted" }, `Source: ${exercise.source}`));
  if (exercise.seeds) more.append(h("p", { class: "muted" }, `Seeds: ${exercise.seeds.join(", ")}; clock: ${exercise.clock}`));
  for (const file of exercise.reference || []) {
    more.append(h("p", {}, `Reference solution, node ${file.name} (${file.filename}):`), h("pre", { class: "code" }, file.code));
  }
  for (const file of exercise.starter || []) {
    more.append(h("p", {}, `Starter code, node ${file.name}:`), h("pre", { class: "code" }, file.code));
  }
  title.append(more);
  const kind = exercise.custom
    ? h("span", {}, "custom", exercise.template ? h("span", { class: "muted small" }, h("br"), `from ${exercise.template}`) : null)
    : "built-in";
  return h(
    "tr",
    { dataset: { exerciseId: exercise.id } },
    title,
    h("td", {}, `${exercise.robot} in ${exercise.world}`),
    h("td", { class: "nowrap" }, `${exercise.duration_s} s`),
    h("td", {}, checkList(exercise.checks)),
    h("td", { class: "nowrap" }, kind),
    cell,
  );
}

function deleteButton(exercise, cell) {
  const button = h(
    "button",
    { type: "button", class: "danger small-btn", "data-testid": "exercise-delete", "aria-label": `Delete ${exercise.id}` },
    "Delete",
  );
  button.addEventListener("click", () => {
    if (!window.confirm(`Delete the custom exercise '${exercise.id}'? Its runs stay.`)) return;
    busy(button, async () => {
      clearRowError(cell);
      try {
        await api(`/api/admin/exercises/${encodeURIComponent(exercise.id)}`, { method: "DELETE" });
        if (form().dataset.editing === exercise.id) closeForm();
        await loadExercises();
        $("#h-ex-list").focus();
      } catch (error) {
        rowError(cell, error);
      }
    });
  });
  return button;
}

function renderList() {
  $("#ex-table tbody").replaceChildren(...state.exercises.map(exerciseRow));
}

// ------------------------------------------------------------------------------ form
function mode() {
  return form().elements.mode.value;
}

function setMode(value) {
  const f = form();
  for (const radio of f.elements.mode) radio.checked = radio.value === value;
  for (const el of $$(".only-template", f)) el.hidden = value !== "template";
  for (const el of $$(".only-scratch", f)) el.hidden = value !== "scratch";
  if (value === "scratch") {
    for (const name of ["title", "duration_s", "description"]) f.elements[name].placeholder = "";
  }
}

function nodeEditor(name = "", code = "") {
  const index = $$(".node", $("#ex-nodes")).length;
  const nameId = `ex-node-name-${Date.now()}-${index}`;
  const codeId = `${nameId}-code`;
  const remove = h("button", { type: "button", class: "secondary small-btn" }, "Remove node");
  const box = h(
    "div",
    { class: "node" },
    h("label", { for: nameId }, "Node name"),
    h("input", { id: nameId, class: "node-name", value: name, maxlength: 40, pattern: "[A-Za-z][A-Za-z0-9_]{0,39}", spellcheck: "false", autocomplete: "off" }),
    h("label", { for: codeId }, "Python code"),
    h("textarea", { id: codeId, class: "node-code code", rows: 12, spellcheck: "false" }),
    remove,
  );
  $("textarea", box).value = code;
  remove.addEventListener("click", () => {
    box.remove();
    updateNodeButtons();
    $("#ex-add-node").focus();
  });
  return box;
}

function setNodes(nodes) {
  $("#ex-nodes").replaceChildren(...nodes.map((n) => nodeEditor(n.name, n.code)));
  updateNodeButtons();
}

function updateNodeButtons() {
  const count = $$(".node", $("#ex-nodes")).length;
  $("#ex-add-node").disabled = count >= MAX_NODES;
}

function starterVisible() {
  const show = mode() === "scratch" || form().elements.override_starter.checked;
  $("#ex-nodes").hidden = !show;
  $("#ex-add-node").hidden = !show;
}

function checkRow(check, ticked, threshold) {
  const id = `ex-check-${check.name}`;
  const unit = check.unit ? ` ${check.unit}` : "";
  return h(
    "tr",
    { dataset: { check: check.name } },
    h("td", {}, h("input", { type: "checkbox", id, class: "check-use", checked: ticked, "aria-label": `use ${check.name}` })),
    h("td", {}, h("label", { for: id }, h("code", {}, check.name)), h("div", { class: "muted small" }, check.description || "")),
    h("td", { class: "nowrap" }, `value ${cmp(check.comparison)} threshold${unit ? ` [${unit.trim()}]` : ""}`),
    h(
      "td",
      {},
      h("input", {
        type: "number",
        step: "any",
        class: "check-threshold",
        value: threshold ?? "",
        "aria-label": `threshold of ${check.name}${unit}`,
      }),
    ),
  );
}

/** The checks table: the template's checks or the generic ones; `chosen` maps name -> threshold. */
function setChecks(chosen = null) {
  const body = $("#ex-checks");
  if (mode() === "template") {
    const template = builtin(form().elements.template.value);
    const checks = template ? template.checks : [];
    body.replaceChildren(
      ...checks.map((c) => checkRow(c, chosen ? c.name in chosen : true, chosen && c.name in chosen ? chosen[c.name] : c.threshold)),
    );
  } else {
    const defaults = { collisions: 0 };
    const picked = chosen || defaults;
    body.replaceChildren(...state.genericChecks.map((c) => checkRow(c, c.name in picked, picked[c.name])));
  }
}

function templateChanged() {
  const f = form();
  const template = builtin(f.elements.template.value);
  if (!template) return;
  f.elements.title.placeholder = template.title;
  f.elements.duration_s.placeholder = String(template.duration_s);
  f.elements.description.placeholder = template.description;
  setChecks();
  if (f.elements.override_starter.checked) setNodes(template.starter);
}

function worldsFor(robot) {
  return state.worlds.filter((w) => (w.robots || []).includes(robot));
}

function robotChanged() {
  const f = form();
  setOptions(f.elements.world, worldsFor(f.elements.robot.value).map((w) => [w.id, `${w.title} (${w.id})`]));
}

function fillPickers() {
  const f = form();
  setOptions(f.elements.template, builtins().map((e) => [e.id, `${e.title} (${e.id})`]));
  setOptions(f.elements.robot, state.robots.map((r) => [r.id, r.id]));
  robotChanged();
}

async function openForm(exercise = null, templateId = null) {
  const f = form();
  if (!state.robots.length) {
    try {
      await loadCatalog();
    } catch (error) {
      showError($("#ex-error"), error);
      return;
    }
  }
  clearError(f);
  f.reset();
  fillPickers();
  f.dataset.editing = exercise ? exercise.id : "";
  f.elements.id.disabled = Boolean(exercise);
  for (const radio of f.elements.mode) radio.disabled = Boolean(exercise);
  $("#h-ex-form").textContent = exercise ? `Edit custom exercise ${exercise.id}` : "New custom exercise";
  $("#ex-submit").textContent = exercise ? "Save changes" : "Create exercise";

  if (!exercise) {
    setMode("template");
    if (templateId) f.elements.template.value = templateId;
    f.elements.id.value = templateId ? `${templateId}_custom`.slice(0, 64) : "";
    setNodes([]);
    templateChanged();
  } else if (exercise.template) {
    setMode("template");
    f.elements.id.value = exercise.id;
    f.elements.template.value = exercise.template;
    const template = builtin(exercise.template);
    templateChanged();
    // Leave a field empty when it is the template's own (empty means "the built-in's").
    if (!template || exercise.title !== template.title) f.elements.title.value = exercise.title || "";
    if (!template || exercise.description !== template.description) f.elements.description.value = exercise.description || "";
    if (!template || exercise.duration_s !== template.duration_s) f.elements.duration_s.value = exercise.duration_s;
    setChecks(Object.fromEntries(exercise.checks.map((c) => [c.name, c.threshold])));
    const same = template && JSON.stringify(template.starter.map((s) => [s.name, s.code])) === JSON.stringify(exercise.starter.map((s) => [s.name, s.code]));
    f.elements.override_starter.checked = !same;
    setNodes(same ? [] : exercise.starter);
  } else {
    setMode("scratch");
    f.elements.id.value = exercise.id;
    f.elements.robot.value = exercise.robot;
    robotChanged();
    f.elements.world.value = exercise.world;
    f.elements.title.value = exercise.title || "";
    f.elements.description.value = exercise.description || "";
    f.elements.duration_s.value = exercise.duration_s;
    f.elements.clock.value = exercise.clock || "lockstep";
    f.elements.seeds.value = (exercise.seeds || []).join(", ");
    setChecks(Object.fromEntries(exercise.checks.map((c) => [c.name, c.threshold])));
    setNodes(exercise.starter);
  }
  starterVisible();
  f.hidden = false;
  f.scrollIntoView({ block: "start" });
  (exercise ? f.elements.title : f.elements.id).focus();
}

function closeForm() {
  const f = form();
  f.hidden = true;
  f.dataset.editing = "";
}

/** The request body the form describes; throws an Error (shown verbatim) when incomplete. */
function body() {
  const f = form();
  const out = {};
  const text = (name) => f.elements[name].value.trim();
  if (text("title")) out.title = text("title");
  if (text("description")) out.description = f.elements.description.value;
  if (text("duration_s")) {
    const duration = Number(text("duration_s"));
    if (!Number.isFinite(duration) || duration <= 0) throw new Error("the duration is a number of seconds above 0");
    out.duration_s = duration;
  }
  out.checks = [];
  for (const row of $$("#ex-checks tr")) {
    if (!$(".check-use", row).checked) continue;
    const raw = $(".check-threshold", row).value.trim();
    const threshold = Number(raw);
    if (raw === "" || !Number.isFinite(threshold)) throw new Error(`give check '${row.dataset.check}' a threshold (a number)`);
    out.checks.push({ name: row.dataset.check, threshold });
  }
  if (!out.checks.length) throw new Error("tick at least one check: an exercise is graded by its checks");
  const nodes = $$(".node", $("#ex-nodes")).map((box) => ({ name: $(".node-name", box).value.trim(), code: $(".node-code", box).value }));
  if (mode() === "template") {
    out.template = f.elements.template.value;
    if (f.elements.override_starter.checked) {
      if (!nodes.length) throw new Error("add a node for the starter code, or untick 'replace the built-in's starter code'");
      out.starter = nodes;
    }
  } else {
    out.robot = f.elements.robot.value;
    out.world = f.elements.world.value;
    out.clock = f.elements.clock.value;
    if (!out.title) throw new Error("an exercise from scratch needs a title");
    if (out.duration_s === undefined) throw new Error("an exercise from scratch needs a duration");
    if (!nodes.length) throw new Error("an exercise from scratch needs starter code: add a node");
    out.starter = nodes;
    const seeds = text("seeds");
    if (seeds) {
      const list = seeds.split(/[\s,;]+/).filter(Boolean).map(Number);
      if (list.some((s) => !Number.isInteger(s) || s < 0)) throw new Error("seeds are whole numbers 0 or above, separated by commas");
      out.seeds = list;
    }
  }
  for (const node of out.starter || []) {
    if (!node.name) throw new Error("every starter node needs a name (a letter, then letters, digits or _)");
  }
  return out;
}

async function submit(event) {
  event.preventDefault();
  const f = form();
  const button = $("#ex-submit");
  await busy(button, async () => {
    clearError(f);
    let payload;
    try {
      payload = body();
    } catch (error) {
      showError(f, error);
      return;
    }
    const editing = f.dataset.editing;
    try {
      let saved;
      if (editing) {
        saved = await api(`/api/admin/exercises/${encodeURIComponent(editing)}`, { method: "PUT", body: payload });
      } else {
        const id = f.elements.id.value.trim();
        if (!id) throw new ApiError(0, "give the exercise an id: lower case, digits and _, 3 to 64 characters");
        saved = await api("/api/admin/exercises", { method: "POST", body: { id, ...payload } });
      }
      closeForm();
      await loadExercises();
      const row = $(`#ex-table tr[data-exercise-id="${CSS.escape(saved.id)}"]`);
      if (row) {
        row.classList.add("flash");
        row.scrollIntoView({ block: "center" });
        $("button", row)?.focus();
      }
    } catch (error) {
      showError(f, error);
    }
  });
}

export function initExercises() {
  subscribe("exercises", renderList);
  const f = form();
  $("#ex-new").addEventListener("click", () => openForm());
  $("#ex-cancel").addEventListener("click", () => {
    closeForm();
    $("#ex-new").focus();
  });
  for (const radio of f.elements.mode) {
    radio.addEventListener("change", () => {
      setMode(mode());
      if (mode() === "template") templateChanged();
      else {
        setChecks();
        if (!$$(".node", $("#ex-nodes")).length) setNodes([{ name: "controller", code: SCRATCH_STARTER }]);
      }
      starterVisible();
    });
  }
  f.elements.template.addEventListener("change", templateChanged);
  f.elements.robot.addEventListener("change", robotChanged);
  f.elements.override_starter.addEventListener("change", () => {
    if (f.elements.override_starter.checked && !$$(".node", $("#ex-nodes")).length) {
      const template = builtin(f.elements.template.value);
      setNodes(template ? template.starter : [{ name: "controller", code: SCRATCH_STARTER }]);
    }
    starterVisible();
  });
  $("#ex-add-node").addEventListener("click", () => {
    const box = nodeEditor(`node${$$(".node", $("#ex-nodes")).length + 1}`, mode() === "scratch" ? SCRATCH_STARTER : "");
    $("#ex-nodes").append(box);
    updateNodeButtons();
    $(".node-name", box).focus();
  });
  f.addEventListener("submit", submit);
}

export async function showExercises() {
  try {
    clearError($("#ex-error"));
    await loadExercises();
  } catch (error) {
    showError($("#ex-error"), error);
  }
}
