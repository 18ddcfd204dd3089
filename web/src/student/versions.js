// Version history of the file on show: every save is a version on the server. List them, view
// one (read-only, highlighted), restore one (saved again as the newest version), or go back to
// the exercise's starter code.

import { EditorState } from "@codemirror/state";
import { EditorView } from "@codemirror/view";
import { api } from "../common/api.js";
import { byId, bytes, fill, h, when } from "../common/dom.js";
import { currentFile, flushAll, focusEditor, pythonExtensions, replaceCurrent, starterOf } from "./editor.js";

let dialog = null;
let preview = null;

function build() {
  const list = h("ol", { class: "version-list", reversed: true, dataset: { testid: "version-list" } });
  const previewBox = h("div", { class: "version-preview", dataset: { testid: "version-preview" } });
  const message = h("p", { class: "dialog-message", role: "status" });
  const title = h("h2", { id: "versions-title" }, "Versions");
  dialog = h(
    "dialog",
    { class: "versions", "aria-labelledby": "versions-title", dataset: { testid: "versions-dialog" } },
    h("div", { class: "dialog-head" }, title, h("button", { type: "button", class: "small", onclick: () => dialog.close() }, "Close")),
    message,
    h("div", { class: "versions-body" }, h("div", { class: "version-scroll" }, list), previewBox),
  );
  dialog.addEventListener("close", focusEditor);
  document.body.append(dialog);
  preview = new EditorView({ parent: previewBox, state: previewState("") });
  return { list, message, title };
}

function previewState(text) {
  return EditorState.create({ doc: text, extensions: pythonExtensions({ readOnly: true, label: "The chosen version (read only)" }) });
}

let parts = null;

export function initVersions() {
  byId("versions-button").addEventListener("click", open);
}

async function open() {
  parts ||= build();
  const file = currentFile();
  if (!file) return;
  await flushAll();
  parts.title.textContent = `Versions of ${file.filename}`;
  parts.message.textContent = "Loading…";
  fill(parts.list);
  preview.setState(previewState(""));
  dialog.showModal();
  let versions = [];
  let listing = null;
  try {
    listing = await api(`${base(file)}/versions`);
    versions = listing.versions;
  } catch (error) {
    if (error.status !== 404) {
      parts.message.textContent = error.message;
      return;
    }
  }
  const starter = starterOf(file.filename);
  parts.message.textContent = versions.length
    ? "Every save is a version. View one, or restore it as the newest." + pruned(listing)
    : "No saved versions yet: edits are saved a moment after you stop typing.";
  const newestFirst = [...versions].sort((a, b) => b.version - a.version);
  fill(
    parts.list,
    newestFirst.map((v) =>
      h(
        "li",
        { value: v.version, dataset: { testid: "version-item", version: v.version } },
        h("span", { class: "version-label" }, `v${v.version}`, v.version === file.version ? " (current)" : ""),
        h("span", { class: "version-meta" }, `${when(v.saved_at)} · ${bytes(v.bytes)}`),
        h("button", { type: "button", class: "small", onclick: () => view(file, v.version) }, "View"),
        h("button", { type: "button", class: "small", onclick: () => restore(file, v.version), disabled: v.version === file.version }, "Restore"),
      ),
    ),
    starter !== null
      ? h(
          "li",
          { class: "starter", value: 0 },
          h("span", { class: "version-label" }, "starter"),
          h("span", { class: "version-meta" }, "the exercise's starter code"),
          h("button", { type: "button", class: "small", onclick: () => preview.setState(previewState(starter)) }, "View"),
          h("button", { type: "button", class: "small", onclick: () => restoreStarter(starter) }, "Restore"),
        )
      : null,
  );
  if (newestFirst.length) view(file, newestFirst[0].version);
}

// What the history keeps (server/store/workspaces.py), said when older versions were removed.
function pruned(listing) {
  if (!listing?.pruned) return "";
  const kept = listing.kept;
  return (
    ` Versions before v${listing.oldest_kept} were removed: a file keeps its newest ` +
    `${kept.versions_per_file} versions, and this workspace the newest ${bytes(kept.workspace_bytes)} of history.`
  );
}

function base(file) {
  return `/api/workspaces/${encodeURIComponent(file.workspace)}/files/${encodeURIComponent(file.filename)}`;
}

async function view(file, number) {
  try {
    const version = await api(`${base(file)}/versions/${number}`);
    preview.setState(previewState(version.code));
    parts.message.textContent = `v${number}, saved ${when(version.saved_at)}`;
  } catch (error) {
    parts.message.textContent = error.message;
  }
}

async function restore(file, number) {
  try {
    const saved = await api(`${base(file)}/versions/${number}/restore`, { method: "POST" });
    replaceCurrent(saved.code, saved);
    dialog.close();
  } catch (error) {
    parts.message.textContent = error.message;
  }
}

function restoreStarter(starter) {
  replaceCurrent(starter); // an ordinary edit: undoable, saved as a new version
  dialog.close();
}
