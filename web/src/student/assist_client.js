// The editor-help routes of the server (POST /api/editor/{lint,complete,hover,format}) as the
// editor calls them: the file's text with the exercise and robot it is written for (so topic
// names and the step API's `obs.` are known), and positions converted between CodeMirror's
// offsets and the server's (line 1-based, column 0-based in characters: Python's code points,
// where CodeMirror counts UTF-16 units).

import { api } from "../common/api.js";
import { app } from "./state.js";

/** POST `body` to /api/editor/`route`, with the exercise and robot on show unless `target` is
 * false (format needs neither); `signal` aborts it (a newer request replaces it). */
export function ask(route, body, { signal, target = true } = {}) {
  const context = target ? { exercise: app.target?.exercise?.id ?? null, robot: app.target?.robot ?? null } : {};
  return api(`/api/editor/${route}`, { method: "POST", signal, body: { ...body, ...context } });
}

/** An aborted request (superseded, or its editor moved on): nothing to show, nothing to say. */
export const isAbort = (error) => error?.name === "AbortError";

/** {line, column} of offset `pos` in `state`, as the server counts them. */
export function lineColumnOf(state, pos) {
  const line = state.doc.lineAt(pos);
  return { line: line.number, column: [...line.text.slice(0, pos - line.from)].length };
}

/** The offset of the server's (line, column) in `state`, clamped to the document. */
export function offsetOf(state, lineNumber, column) {
  const doc = state.doc;
  if (lineNumber > doc.lines) return doc.length;
  const line = doc.line(Math.max(1, lineNumber));
  let offset = 0;
  let characters = 0;
  for (const character of line.text) {
    if (characters >= column) break;
    offset += character.length; // 2 for a character outside the BMP
    characters += 1;
  }
  return line.from + offset;
}
