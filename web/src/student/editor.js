// The code editor: CodeMirror 6 with Python, a tab per node file of the workspace, each with its
// own undo history; edits are saved to the workspace a moment after typing stops (each save is
// a version on the server). Ctrl/Cmd+S saves now, Ctrl/Cmd+Enter runs. "+ Node" adds a node
// file; "+ File" adds a data file (CSV, YAML, JSON, TXT, a launch file), empty or uploaded,
// edited as text; a file the student added (not the exercise's starter) can be deleted with its
// versions (the tab's x, or Delete on the tab). A run opened by its id (app.watching) shows that run's code
// read-only instead of a workspace. A Python file gets the server's help as it is typed
// (assist.js: diagnostics, completion, signature help, hover, format); every editor's colours
// follow the system's light or dark preference (theme.js).

import { closeBrackets, closeBracketsKeymap } from "@codemirror/autocomplete";
import { defaultKeymap, history, historyKeymap, indentWithTab } from "@codemirror/commands";
import { python } from "@codemirror/lang-python";
import { bracketMatching, indentOnInput, indentUnit } from "@codemirror/language";
import { highlightSelectionMatches, search, searchKeymap } from "@codemirror/search";
import { EditorState, Prec } from "@codemirror/state";
import {
  drawSelection,
  dropCursor,
  EditorView,
  highlightActiveLine,
  highlightActiveLineGutter,
  highlightSpecialChars,
  keymap,
  lineNumbers,
} from "@codemirror/view";
import { api } from "../common/api.js";
import { byId, debounce, fill, h, when } from "../common/dom.js";
import { assistExtensions, formatAndReport, inertCompletion } from "./assist.js";
import { app, emit, fileOf, isLaunchFile, isNodeFile, nodeOf, on } from "./state.js";
import { systemTheme } from "./theme.js";

const AUTOSAVE_MS = 1200; // [ms] after the last keystroke; each save is a version on the server
const MAX_NODES = 8; // the API's limit of nodes in one run
const NODE_NAME = /^[A-Za-z][A-Za-z0-9_]{0,39}$/;
// A data file's path as the server takes it (server/service/workspace_files.py): at most two
// folders, parts of letters, digits, _ - and ., and one of these endings.
const DATA_FILE = /^([A-Za-z0-9_][A-Za-z0-9_.-]*\/){0,2}[A-Za-z0-9_][A-Za-z0-9_.-]*\.(csv|ya?ml|json|txt|launch|xml|launch\.py)$/i;
const MAX_DATA_BYTES = 1024 * 1024; // [B] the server's default cap per data file

const tabsElement = byId("file-tabs");
const statusElement = byId("save-status");
const addButton = byId("add-node");
const versionsButton = byId("versions-button");
const formatButton = byId("format-button");
const formatStatus = byId("format-status");
let view = null;
let workspace = null; // the workspace the files below belong to (null: a run's code, read-only)
let readOnly = false;
let confirmDialog = null;
/** filename -> {filename, state, savedCode, version, savedAt, saving, error, autosave} */
const files = new Map();
let current = null;
let onRun = () => {};

/** The extensions of one file's editor state; `filename` lets edits mark the right file. */
export function pythonExtensions({ readOnly = false, label = "Python code" } = {}) {
  return [
    lineNumbers(),
    highlightActiveLineGutter(),
    highlightSpecialChars(),
    drawSelection(),
    indentUnit.of("    "),
    systemTheme(),
    bracketMatching(),
    highlightSelectionMatches(),
    python(),
    EditorState.readOnly.of(readOnly),
    EditorView.contentAttributes.of(readOnly ? { "aria-label": label, "aria-readonly": "true" } : { "aria-label": label }),
  ];
}

/** A data file (CSV, YAML, a launch file): text without Python's highlighting, two-space indent. */
function textExtensions({ readOnly = false, label }) {
  return [
    lineNumbers(),
    highlightActiveLineGutter(),
    highlightSpecialChars(),
    drawSelection(),
    indentUnit.of("  "),
    systemTheme(),
    highlightSelectionMatches(),
    EditorState.readOnly.of(readOnly),
    EditorView.contentAttributes.of(readOnly ? { "aria-label": label, "aria-readonly": "true" } : { "aria-label": label }),
  ];
}

function fileExtensions(filename, { readOnly: locked = false } = {}) {
  const language = filename.endsWith(".py") ? pythonExtensions : textExtensions;
  if (locked) {
    return [
      language({ readOnly: true, label: `Code of ${filename} in the run on show (read only)` }),
      search({ top: true }),
      keymap.of([...defaultKeymap, ...searchKeymap]),
      inertCompletion,
    ];
  }
  return [
    language({ label: `${filename.endsWith(".py") ? "Code" : "Text"} of ${filename} (Escape then Tab leaves the editor)` }),
    history(),
    dropCursor(),
    EditorState.allowMultipleSelections.of(true),
    indentOnInput(),
    closeBrackets(),
    highlightActiveLine(),
    search({ top: true }),
    Prec.high(
      keymap.of([
        { key: "Mod-s", preventDefault: true, run: () => (saveNow(filename), true) },
        { key: "Mod-Enter", preventDefault: true, run: () => (onRun(), true) },
      ]),
    ),
    keymap.of([...closeBracketsKeymap, ...defaultKeymap, ...searchKeymap, ...historyKeymap, indentWithTab]),
    EditorView.updateListener.of((update) => {
      if (update.docChanged) edited(filename);
    }),
    filename.endsWith(".py") ? assistExtensions({ filename, report: showFormatOutcome }) : inertCompletion,
  ];
}

export function initEditor({ run }) {
  onRun = run;
  view = new EditorView({
    parent: byId("editor"),
    state: EditorState.create({ doc: "# loading…", extensions: [pythonExtensions({ readOnly: true }), inertCompletion] }),
  });
  on("target", ({ changedWorkspace }) => {
    if (app.watching) showRunCode(app.watching);
    else if (changedWorkspace || readOnly) load(app.target.workspace);
  });
  on("goto-line", ({ node, line }) => gotoLine(node, line));
  tabsElement.addEventListener("keydown", tabKeys);
  tabsElement.addEventListener("click", (event) => {
    const cross = event.target.closest(".tab-delete");
    if (!cross) return;
    event.stopPropagation();
    confirmDelete(cross.dataset.file);
  });
  formatButton.addEventListener("click", () => {
    if (current?.endsWith(".py") && !readOnly) formatAndReport(view, current, showFormatOutcome);
  });
  initAddNode();
  initAddFile();
  window.addEventListener("beforeunload", () => {
    for (const file of files.values()) if (isDirty(file)) save(file, { keepalive: true });
  });
}

/** The code of every node (the .py files at the top of the workspace), in tab order: what a
 * run is started with. An emptied file is left out. Data files reach the nodes through the
 * workspace (`workspace` in POST /api/runs). */
export function nodes() {
  return [...files.values()]
    .filter((file) => isNodeFile(file.filename))
    .map((file) => ({ name: nodeOf(file.filename), code: code(file) }))
    .filter((node) => node.code.trim() !== "");
}

/** The workspace's launch files (.launch, .xml, .launch.py), in tab order. */
export function launchFiles() {
  return readOnly ? [] : [...files.keys()].filter(isLaunchFile);
}

/** The workspace on show (null while a run's code is shown read only). */
export function workspaceName() {
  return workspace;
}

/** Edited since the last save (starter code nobody touched is not saved). */
function isDirty(file) {
  return Boolean(file.edited) && code(file) !== file.savedCode;
}

function code(file) {
  return file.filename === current ? view.state.doc.toString() : file.state.doc.toString();
}

async function load(name) {
  await flushAll();
  workspace = name;
  setReadOnly(false);
  files.clear();
  current = null;
  fill(tabsElement);
  setStatus("Loading…");
  let listing;
  try {
    listing = await api(`/api/workspaces/${encodeURIComponent(name)}`);
  } catch (error) {
    setStatus(`Could not load the code: ${error.message}`, true);
    return;
  }
  if (workspace !== name || app.watching) return; // another workspace was chosen meanwhile
  const loaded = ordered(listing.files);
  for (const entry of loaded) addFile(entry.filename, entry.code, entry.version, entry.saved_at);
  show(loaded[0].filename);
}

/** The workspace's files (the server lists the starter files not saved yet as version 0) with
 * the starter's files first, in the exercise's order; a template for an empty free-play one. */
function ordered(listed) {
  const starter = (app.target?.exercise?.starter || []).map((s) => fileOf(s.name));
  const rank = (file) => (starter.includes(file.filename) ? starter.indexOf(file.filename) : starter.length);
  const files = listed.map((file, index) => ({ ...file, index })).sort((a, b) => rank(a) - rank(b) || a.index - b.index);
  return files.length ? files : [{ filename: "controller.py", version: 0, code: template() }];
}

/** The code of a run (opened by its id), a read-only tab per node. */
async function showRunCode(run) {
  await flushAll();
  if (app.watching !== run) return;
  workspace = null;
  setReadOnly(true);
  files.clear();
  current = null;
  const code = run.code?.length ? run.code : [{ name: "no_code", code: "# This run's code is not available." }];
  for (const node of code) addFile(fileOf(node.name), node.code, 0, null, { readOnly: true });
  show(fileOf(code[0].name));
}

function setReadOnly(locked) {
  readOnly = locked;
  addButton.hidden = locked;
  byId("add-node-form").hidden = true;
  addButton.setAttribute("aria-expanded", "false");
  byId("add-file").hidden = locked;
  byId("add-file").setAttribute("aria-expanded", "false");
  byId("add-file-form").hidden = true;
  versionsButton.disabled = locked;
}

function addFile(filename, text, version, savedAt, { readOnly: locked = false } = {}) {
  const file = {
    filename,
    state: EditorState.create({ doc: text, extensions: fileExtensions(filename, { readOnly: locked }) }),
    savedCode: version > 0 ? text : null, // starter code is not saved until it is edited
    version,
    savedAt,
    saving: null,
    error: null,
  };
  file.autosave = debounce(() => save(file), AUTOSAVE_MS);
  files.set(filename, file);
  renderTabs();
  emit("files", { names: [...files.keys()] });
  return file;
}

/** A step-API skeleton for a new node of the target robot. */
function template() {
  const robot = app.robots.get(app.target?.robot);
  const sensor = robot?.topics.find((t) => t.direction === "publish" && /^[A-Za-z_]\w*$/.test(t.name));
  const name = sensor ? sensor.name : "Distance";
  return `"""My controller for the ${robot?.title || "robot"}. Step API: step(obs) runs RATE_HZ times a second."""

RATE_HZ = 10  # [Hz]
SUBSCRIBE = ["${name}"]  # obs.${name} is the latest message (None before the first one)


def step(obs):
    if obs.${name} is None:
        return None  # nothing has arrived yet: publish nothing
    print(obs.time, obs.${name})
    return None  # or (v [m/s], w [rad/s]), or {topic: message}
`;
}

/** A file the student added (not one of the exercise's starter files), when another remains. */
function deletable(filename) {
  if (readOnly || files.size < 2) return false;
  return !(app.target?.exercise?.starter || []).some((s) => fileOf(s.name) === filename);
}

function renderTabs() {
  fill(
    tabsElement,
    [...files.values()].map((file) => {
      const dirty = isDirty(file);
      const canDelete = deletable(file.filename);
      return h(
        "button",
        {
          type: "button",
          role: "tab",
          class: `file-tab${canDelete ? " can-delete" : ""}`,
          "aria-selected": String(file.filename === current),
          "aria-controls": "editor",
          "aria-keyshortcuts": canDelete ? "Delete" : null,
          "aria-describedby": canDelete ? "file-delete-hint" : null,
          tabindex: file.filename === current ? 0 : -1,
          dataset: { testid: "editor-tab", file: file.filename },
          onclick: () => show(file.filename),
        },
        file.filename,
        dirty ? h("span", { class: "dirty", title: "unsaved changes", "aria-label": "(unsaved)" }, " •") : null,
        // A mouse's way to delete; the keyboard's is Delete on the tab (aria-keyshortcuts).
        canDelete
          ? h("span", { class: "tab-delete", "aria-hidden": "true", title: `Delete ${file.filename}`, dataset: { testid: "file-delete", file: file.filename } })
          : null,
      );
    }),
  );
}

function tabKeys(event) {
  const buttons = [...tabsElement.querySelectorAll('[role="tab"]')];
  const index = buttons.indexOf(document.activeElement);
  if (index < 0) return;
  if (event.key === "Delete" && deletable(buttons[index].dataset.file)) {
    event.preventDefault();
    confirmDelete(buttons[index].dataset.file);
    return;
  }
  const step = { ArrowRight: 1, ArrowLeft: -1 }[event.key];
  if (!step) return;
  event.preventDefault();
  const next = buttons[(index + step + buttons.length) % buttons.length];
  show(next.dataset.file);
  tabsElement.querySelector(`[data-file="${CSS.escape(next.dataset.file)}"]`)?.focus();
}

function show(filename) {
  if (current && files.has(current)) files.get(current).state = view.state;
  current = filename;
  view.setState(files.get(filename).state);
  renderTabs();
  showStatus();
  formatButton.disabled = readOnly || !filename.endsWith(".py"); // Python only, never a run's code
  emit("file-shown", { filename });
}

function edited(filename) {
  const file = files.get(filename);
  if (!file) return;
  formatStatus.textContent = ""; // a format's outcome is about the text before this edit
  file.edited = true;
  file.error = null;
  file.autosave();
  if (filename === current) {
    renderTabsSoon();
    showStatus();
  }
}

const renderTabsSoon = debounce(renderTabs, 150);

async function save(file, { keepalive = false } = {}) {
  file.autosave.cancel();
  if (file.deleted || readOnly) return;
  const text = code(file);
  if (text === file.savedCode) return;
  if (file.saving) {
    await file.saving; // one save at a time per file, the newest text last
    return save(file);
  }
  const url = `/api/workspaces/${encodeURIComponent(workspace)}/files/${encodeURIComponent(file.filename)}`;
  if (keepalive) {
    fetch(url, { method: "PUT", keepalive: true, credentials: "same-origin", headers: { "content-type": "application/json" }, body: JSON.stringify({ code: text }) });
    return;
  }
  const target = workspace;
  file.saving = api(url, { method: "PUT", body: { code: text } })
    .then((saved) => {
      if (target !== workspace) return;
      file.savedCode = text;
      file.version = saved.version;
      file.savedAt = saved.saved_at;
      file.error = null;
    })
    .catch((error) => {
      file.error = error.message;
    })
    .finally(() => {
      file.saving = null;
      if (target === workspace) {
        renderTabs();
        if (file.filename === current) showStatus();
      }
    });
  if (file.filename === current) showStatus();
  return file.saving;
}

function saveNow(filename) {
  const file = files.get(filename);
  if (file) save(file);
}

/** Save every file with unsaved edits; resolves when the server has them all. */
export async function flushAll() {
  await Promise.all([...files.values()].map((file) => (isDirty(file) ? save(file) : file.saving)));
}

function showStatus() {
  const file = files.get(current);
  if (!file) return setStatus("");
  if (readOnly) return setStatus("Read only: the code this run was started with");
  if (file.error) return setStatus(`Not saved: ${file.error}`, true);
  if (file.saving) return setStatus("Saving…");
  if (file.savedCode === null && !file.edited) return setStatus("Starter code");
  if (code(file) !== file.savedCode) return setStatus("Unsaved changes");
  setStatus(`Saved v${file.version}${file.savedAt ? ` at ${when(file.savedAt)}` : ""}`);
}

/** "Formatted.", or why not (a syntax error's line), beside the Format button until the next edit. */
function showFormatOutcome(text, error) {
  formatStatus.textContent = text;
  formatStatus.classList.toggle("error", error);
}

function setStatus(text, error = false) {
  statusElement.textContent = text;
  statusElement.classList.toggle("error", error);
}

/** Ask, then delete a file the student added: its versions on the server, its tab here. */
function confirmDelete(filename) {
  const file = files.get(filename);
  if (!file || !deletable(filename)) return;
  if (!confirmDialog) {
    confirmDialog = h(
      "dialog",
      { class: "confirm", "aria-labelledby": "delete-title", "aria-describedby": "delete-text", dataset: { testid: "file-delete-dialog" } },
      h("h2", { id: "delete-title" }),
      h("p", { id: "delete-text" }),
      h(
        "form",
        { method: "dialog", class: "dialog-buttons" },
        h("button", { type: "submit", value: "cancel", class: "small", autofocus: true, dataset: { testid: "file-delete-cancel" } }, "Cancel"),
        h("button", { type: "submit", value: "delete", class: "small danger", dataset: { testid: "file-delete-confirm" } }, "Delete"),
      ),
    );
    document.body.append(confirmDialog);
  }
  const count = Math.max(file.version, file.saving ? 1 : 0);
  confirmDialog.querySelector("#delete-title").textContent = `Delete ${filename}?`;
  confirmDialog.querySelector("#delete-text").textContent = count
    ? `${filename} and its ${count} saved version${count === 1 ? "" : "s"} are deleted from your workspace. This cannot be undone.`
    : `${filename} has not been saved yet: its tab is closed.`;
  confirmDialog.returnValue = "";
  confirmDialog.addEventListener(
    "close",
    () => {
      if (confirmDialog.returnValue === "delete") deleteFile(filename);
      else tabsElement.querySelector(`[data-file="${CSS.escape(filename)}"]`)?.focus();
    },
    { once: true },
  );
  confirmDialog.showModal();
}

async function deleteFile(filename) {
  const file = files.get(filename);
  if (!file) return;
  const name = workspace;
  file.deleted = true; // no more saves: a late one would bring it back
  file.autosave.cancel();
  if (file.saving) await file.saving;
  if (file.version > 0) {
    try {
      await api(`/api/workspaces/${encodeURIComponent(name)}/files/${encodeURIComponent(filename)}`, { method: "DELETE" });
    } catch (error) {
      if (error.status !== 404) {
        file.deleted = false;
        setStatus(`Not deleted: ${error.message}`, true);
        return;
      }
    }
  }
  if (workspace !== name || files.get(filename) !== file) return;
  const names = [...files.keys()];
  const index = names.indexOf(filename);
  files.delete(filename);
  emit("files", { names: [...files.keys()] });
  if (current === filename) {
    current = null;
    show(names[index + 1] || names[index - 1]);
  } else renderTabs();
  setStatus(`Deleted ${filename}`);
  tabsElement.querySelector('[aria-selected="true"]')?.focus();
}

/** The file on show and its workspace (for the versions dialog). */
export function currentFile() {
  const file = files.get(current);
  return file ? { workspace, filename: file.filename, version: file.version, code: code(file) } : null;
}

/** Replace the text of the file on show (an undoable edit); `saved` marks it as that version. */
export function replaceCurrent(text, saved = null) {
  const file = files.get(current);
  if (!file) return;
  view.dispatch({ changes: { from: 0, to: view.state.doc.length, insert: text } });
  if (saved) {
    file.autosave.cancel();
    file.savedCode = text;
    file.version = saved.version;
    file.savedAt = saved.saved_at;
    file.error = null;
  }
  renderTabs();
  showStatus();
}

/** Starter code of the file on show, if the exercise has one. */
export function starterOf(filename) {
  return app.target?.exercise?.starter?.find((s) => fileOf(s.name) === filename)?.code ?? null;
}

function gotoLine(node, lineNumber) {
  const filename = fileOf(node);
  if (!files.has(filename)) return;
  show(filename);
  const doc = view.state.doc;
  const line = doc.line(Math.max(1, Math.min(lineNumber, doc.lines)));
  view.dispatch({
    selection: { anchor: line.from, head: line.to },
    effects: EditorView.scrollIntoView(line.from, { y: "center" }),
  });
  view.focus();
}

function initAddNode() {
  const button = addButton;
  const form = byId("add-node-form");
  const input = byId("add-node-name");
  button.addEventListener("click", () => {
    form.hidden = !form.hidden;
    button.setAttribute("aria-expanded", String(!form.hidden));
    if (!form.hidden) input.focus();
  });
  form.addEventListener("keydown", (event) => {
    if (event.key === "Escape") {
      form.hidden = true;
      button.setAttribute("aria-expanded", "false");
      button.focus();
    }
  });
  form.addEventListener("submit", (event) => {
    event.preventDefault();
    const name = input.value.trim();
    let problem = null;
    if (!NODE_NAME.test(name)) problem = "a node name starts with a letter, then letters, digits or _ (at most 40)";
    else if (files.has(fileOf(name))) problem = `there is already a node '${name}'`;
    else if ([...files.keys()].filter(isNodeFile).length >= MAX_NODES) problem = `a run has at most ${MAX_NODES} nodes`;
    input.setCustomValidity(problem || "");
    if (problem) {
      input.reportValidity();
      return;
    }
    const file = addFile(fileOf(name), template(), 0, null);
    file.edited = true;
    show(file.filename);
    save(file);
    input.value = "";
    form.hidden = true;
    button.setAttribute("aria-expanded", "false");
    view.focus();
  });
  input.addEventListener("input", () => input.setCustomValidity(""));
}

/** A skeleton for a new data file: a launch file gets a node to start from (a ROS 2 one for
 * .launch.py, a ROS 1 one otherwise). */
function dataTemplate(name) {
  if (!isLaunchFile(name)) return "";
  const node = [...files.keys()].find(isNodeFile) || "controller.py";
  if (/\.launch\.py$/i.test(name)) {
    return `from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument("speed", default_value="0.2"),
        Node(
            package="my_pkg",
            executable="${nodeOf(node)}",
            name="${nodeOf(node)}",
            output="screen",
            parameters=[{"speed": LaunchConfiguration("speed")}],
        ),
    ])
`;
  }
  return `<launch>
  <node pkg="my_pkg" type="${node}" name="${nodeOf(node)}" output="screen">
    <!-- <param name="speed" value="0.2"/> -->
  </node>
</launch>
`;
}

/** "+ File": a data file by name (empty, or a launch file's skeleton), or one uploaded from
 * the computer (read as text; the server refuses binary files with a sentence). */
function initAddFile() {
  const button = byId("add-file");
  const form = byId("add-file-form");
  const input = byId("add-file-name");
  const upload = byId("add-file-upload");
  const close = () => {
    form.hidden = true;
    button.setAttribute("aria-expanded", "false");
  };
  button.addEventListener("click", () => {
    form.hidden = !form.hidden;
    button.setAttribute("aria-expanded", String(!form.hidden));
    if (!form.hidden) input.focus();
  });
  form.addEventListener("keydown", (event) => {
    if (event.key === "Escape") {
      close();
      button.focus();
    }
  });
  const problemOf = (name) => {
    if (name.startsWith("/") || name.split("/").some((part) => part.startsWith("."))) return "a file stays inside the workspace: no hidden files, '..' or leading '/'";
    if (!DATA_FILE.test(name)) return "a data file's name ends .csv, .yaml, .json, .txt, .launch, .xml or .launch.py (folders: config/gains.yaml)";
    return null;
  };
  form.addEventListener("submit", (event) => {
    event.preventDefault();
    const name = input.value.trim();
    const problem = problemOf(name) || (files.has(name) ? `there is already a file '${name}'` : null);
    input.setCustomValidity(problem || "");
    if (problem) {
      input.reportValidity();
      return;
    }
    createFile(name, dataTemplate(name));
    input.value = "";
    close();
    view.focus();
  });
  input.addEventListener("input", () => input.setCustomValidity(""));
  upload.addEventListener("change", async () => {
    const chosen = upload.files?.[0];
    upload.value = "";
    if (!chosen) return;
    const name = chosen.name.replace(/\s+/g, "_");
    let problem = /^[A-Za-z][A-Za-z0-9_]{0,39}\.py$/.test(name) ? null : problemOf(name); // a node, or data
    if (!problem && chosen.size > MAX_DATA_BYTES) problem = `${name} has ${chosen.size} bytes; the limit is ${MAX_DATA_BYTES}`;
    if (problem) {
      setStatus(`Not uploaded: ${problem}`, true);
      return;
    }
    const text = await chosen.text();
    close();
    if (files.has(name)) {
      show(name);
      replaceCurrent(text); // an edit: saved as the file's next version
    } else createFile(name, text);
  });
}

function createFile(name, text) {
  const file = addFile(name, text, 0, null);
  file.edited = true;
  show(name);
  save(file);
}

export function focusEditor() {
  view?.focus();
}
