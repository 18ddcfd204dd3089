// The editor's help with Python files, from the server's analysis (server/api/routes/editor.py;
// the student's code is read there, never run):
// - diagnostics as you type: LINT_DELAY_MS after the last keystroke (none while typing faster),
//   the request in flight aborted by a newer one and an answer for an older text dropped;
//   underlined, with the rule and its sentence, a marker in the gutter, F8 / Ctrl+Shift+M;
// - completion (Ctrl+Space, or typing a name or a ".") and signature help (signature.js);
// - hover: a name's type, unit and documentation;
// - format (ruff format): Shift+Alt+F or the Format button; one undoable edit.

import { autocompletion } from "@codemirror/autocomplete";
import { syntaxTree } from "@codemirror/language";
import { lintGutter, linter, lintKeymap } from "@codemirror/lint";
import { StateEffect } from "@codemirror/state";
import { EditorView, hoverTooltip, keymap } from "@codemirror/view";
import { h } from "../common/dom.js";
import { ask, isAbort, lineColumnOf, offsetOf } from "./assist_client.js";
import { signatureHelp, signatureLayout } from "./signature.js";

const LINT_DELAY_MS = 400; // [ms] after the last keystroke: no request while typing faster
const COMPLETE_DELAY_MS = 120; // [ms] after a keystroke that may start a completion
const HOVER_DELAY_MS = 350; // [ms] the pointer rests on a name before its docs are asked for
const HOVER_CHARS = 800; // [characters] of a hover text shown; the rest is cut with "…"
const RELINT_MS = 3000; // [ms] before asking again when part of the analysis did not answer
const MAX_RELINTS = 5; // ... at most this many times for one text (a lab with the help off)
// The rule of the server's note that part of the analysis did not answer (busy, still starting:
// server/editor/service.py); the rest of the diagnostics came, and asking again fills it in.
const LIMIT_RULE = "robodojo-limit";

// The server's completion kinds as CodeMirror's icons name them.
const COMPLETION_TYPES = { module: "namespace", class: "class", function: "function", property: "property", keyword: "keyword", variable: "variable", text: "text" };
const NAME_BEFORE = /[\p{L}_][\p{L}\p{N}_]*$/u;
const NAME_PART = /^[\p{L}\p{N}_]*$/u;

/** One diagnostic of the server's answer as CodeMirror's lint shows it (the rule beneath). */
function toDiagnostic(state, found) {
  const from = offsetOf(state, found.line, found.column);
  const to = Math.max(from, offsetOf(state, found.end_line ?? found.line, found.end_column ?? found.column));
  return { from, to, severity: found.severity, source: found.rule, message: found.message };
}

/** Lint again though the text did not change (see needsRefresh below). */
const relint = StateEffect.define();

function lintSource(filename) {
  let inFlight = null; // the AbortController of the request on its way
  let relints = { doc: null, count: 0 }; // asked again for this text so many times
  const askAgainLater = (view, doc) => {
    if (relints.doc !== doc) relints = { doc, count: 0 };
    if (++relints.count > MAX_RELINTS) return;
    setTimeout(() => {
      if (view.state.doc === doc) view.dispatch({ effects: relint.of(null) });
    }, RELINT_MS);
  };
  return async (view) => {
    inFlight?.abort();
    const controller = new AbortController();
    inFlight = controller;
    const state = view.state;
    try {
      const answer = await ask("lint", { code: state.doc.toString(), filename }, { signal: controller.signal });
      if (answer.diagnostics.some((found) => found.rule === LIMIT_RULE)) askAgainLater(view, state.doc);
      return answer.diagnostics.map((found) => toDiagnostic(state, found));
    } catch (error) {
      // Superseded, no answer, or a server without the editor's routes: the next edit asks again.
      if (isAbort(error) || error.status === 0 || error.status === 404 || error.status >= 500) return [];
      // The server's refusal (a file over the analysis limit, say) is the student's to read.
      return [{ from: 0, to: 0, severity: "info", source: "editor help", message: error.message }];
    } finally {
      if (inFlight === controller) inFlight = null;
    }
  };
}

function completionSource(filename) {
  return async (context) => {
    const name = context.matchBefore(NAME_BEFORE);
    const before = context.state.sliceDoc(Math.max(0, context.pos - 2), context.pos);
    const afterDot = before.endsWith(".") && !/\d\.$/.test(before); // `obs.`, not the 1. of 1.5
    if (!context.explicit && !name && !afterDot) return null;
    if (syntaxTree(context.state).resolveInner(context.pos, -1).name === "Comment") return null;
    const controller = new AbortController();
    context.addEventListener("abort", () => controller.abort());
    const { state } = context;
    let answer;
    try {
      answer = await ask("complete", { code: state.doc.toString(), filename, ...lineColumnOf(state, context.pos) }, { signal: controller.signal });
    } catch {
      return null; // aborted, or no answer: no list this time
    }
    if (!answer.completions?.length) return null;
    return {
      from: name ? name.from : context.pos,
      options: answer.completions.map((offered, index) => ({
        order: index, // the server's rank (see byServerOrder)
        label: offered.label,
        type: COMPLETION_TYPES[offered.type] || "text",
        detail: offered.detail || undefined,
        info: offered.doc && offered.doc !== offered.detail ? offered.doc : undefined,
      })),
      validFor: NAME_PART, // typing more of the name filters this list without asking again
    };
  };
}

/** Among equally good matches, the server's order, private and dunder names last (CodeMirror
 * would sort them by label, putting `__annotations__` before `linear`). */
function byServerOrder(a, b) {
  const privacy = (option) => (option.label.startsWith("__") ? 2 : option.label.startsWith("_") ? 1 : 0);
  return privacy(a) - privacy(b) || (a.order ?? 0) - (b.order ?? 0);
}

function hoverSource(filename) {
  return async (view, pos) => {
    const word = view.state.wordAt(pos);
    if (!word) return null;
    const state = view.state;
    let answer;
    try {
      answer = await ask("hover", { code: state.doc.toString(), filename, ...lineColumnOf(state, pos) });
    } catch {
      return null;
    }
    if (!answer.text || view.state.doc !== state.doc) return null;
    const text = answer.text.length > HOVER_CHARS ? `${answer.text.slice(0, HOVER_CHARS)}…` : answer.text;
    return {
      pos: word.from,
      end: word.to,
      above: true,
      create: () => ({ dom: h("div", { class: "cm-hover-doc", dataset: { testid: "hover-doc" } }, text) }),
    };
  };
}

/**
 * Format the Python file on show in `view` with the server's formatter. The new text replaces
 * the part that changed in one transaction (one Ctrl+Z undoes it; the cursor stays where the
 * text around it did not change). Resolves with a sentence for the student; rejects with one
 * (a syntax error: the server's sentence names the line).
 */
export async function formatCode(view, filename) {
  const state = view.state;
  const before = state.doc.toString();
  let answer;
  try {
    answer = await ask("format", { code: before, filename }, { target: false });
  } catch (error) {
    // A 422 is the server's sentence on the syntax error ("cannot format: line 3 ..."), as is.
    const sentence = error.status === 422 ? error.message : `Not formatted: ${error.message}`;
    throw new Error(sentence.charAt(0).toUpperCase() + sentence.slice(1));
  }
  if (view.state.doc !== state.doc) throw new Error("Not formatted: the code changed meanwhile; press Format again.");
  const after = answer.code;
  if (after === before) return "Already formatted.";
  let start = 0;
  while (start < before.length && start < after.length && before[start] === after[start]) start += 1;
  let end = 0; // characters equal at the end, not reaching into the common start
  while (end < before.length - start && end < after.length - start && before[before.length - 1 - end] === after[after.length - 1 - end]) end += 1;
  view.dispatch({
    changes: { from: start, to: before.length - end, insert: after.slice(start, after.length - end) },
    userEvent: "format",
    scrollIntoView: true,
  });
  return "Formatted.";
}

/** Format `view`'s file and tell the student the outcome through `report(text, isError)`. */
export function formatAndReport(view, filename, report) {
  formatCode(view, filename).then(
    (sentence) => report(sentence, false),
    (error) => report(error.message, true),
  );
}

/** Shift+Alt+F by the key's place (event.code), so it also works where Alt types a letter (macOS). */
function formatShortcut(filename, report) {
  return EditorView.domEventHandlers({
    keydown(event, view) {
      if (event.code !== "KeyF" || !event.shiftKey || !event.altKey || event.ctrlKey || event.metaKey) return false;
      event.preventDefault();
      formatAndReport(view, filename, report);
      return true;
    },
  });
}

const layout = EditorView.baseTheme({
  ".cm-hover-doc": { padding: "0.3rem 0.5rem", maxWidth: "70ch", whiteSpace: "pre-wrap", fontSize: "0.85rem" },
  ".cm-diagnosticSource": { opacity: "1" }, // the rule id stays readable (contrast)
});

/**
 * For every editor state without the help (a data file, a run's code, the page's first state):
 * completion's state with no source. CodeMirror's completion plugin has no destroy, so a query
 * of a Python file's editor that answers after the tab switched reads that state field from
 * the state now on show, and a state without it throws "Field is not present in this state".
 */
export const inertCompletion = autocompletion({ override: [], activateOnTyping: false });

/** The help for a writable Python file; `report(text, isError)` tells the student a format's outcome. */
export function assistExtensions({ filename, report }) {
  return [
    linter(lintSource(filename), {
      delay: LINT_DELAY_MS,
      needsRefresh: (update) => update.transactions.some((tr) => tr.effects.some((effect) => effect.is(relint))),
    }),
    lintGutter(),
    autocompletion({ override: [completionSource(filename)], activateOnTypingDelay: COMPLETE_DELAY_MS, compareCompletions: byServerOrder }),
    hoverTooltip(hoverSource(filename), { hoverTime: HOVER_DELAY_MS, hideOnChange: true }),
    signatureHelp(filename),
    keymap.of(lintKeymap),
    formatShortcut(filename, report),
    layout,
    signatureLayout,
  ];
}
