// Signature help: while the cursor is inside a call's parentheses, a tooltip above the call
// shows the called function's parameters (the one being typed in bold) and the first lines of
// its documentation, from POST /api/editor/complete. One request a moment after the cursor
// stops (none while typing); a newer position aborts the one in flight; Escape hides it.

import { syntaxTree } from "@codemirror/language";
import { StateEffect, StateField } from "@codemirror/state";
import { EditorView, keymap, showTooltip, ViewPlugin } from "@codemirror/view";
import { h } from "../common/dom.js";
import { ask, lineColumnOf } from "./assist_client.js";

const SIGNATURE_DELAY_MS = 250; // [ms] after the cursor stops inside a call
const SIGNATURE_DOC_CHARS = 300; // [characters] of the docstring shown under the parameters

/** Show {from, signature} (from: the offset of the call's "("), or null to hide. */
const setSignature = StateEffect.define();

/** The offset of the "(" of the innermost call whose arguments hold `pos`, or null. */
function callAt(state, pos) {
  for (let node = syntaxTree(state).resolveInner(pos, -1); node; node = node.parent) {
    if (node.name !== "ArgList") continue;
    const closed = node.lastChild?.name === ")";
    if (pos > node.from && (pos < node.to || !closed)) return node.from;
  }
  return null;
}

const signatureField = StateField.define({
  create: () => null,
  update(shown, transaction) {
    for (const effect of transaction.effects) if (effect.is(setSignature)) shown = effect.value;
    if (shown && (transaction.docChanged || transaction.selection)) {
      // Kept while the cursor stays in the same call; hidden when it leaves.
      const from = transaction.changes.mapPos(shown.from);
      shown = callAt(transaction.state, transaction.state.selection.main.head) === from ? { ...shown, from } : null;
    }
    return shown;
  },
  provide: (field) =>
    showTooltip.compute([field], (state) => {
      const shown = state.field(field);
      return shown && { pos: shown.from, above: true, create: () => ({ dom: render(shown.signature) }) };
    }),
});

/** "name(a, b=1)" with the active parameter in bold, then the start of its documentation. */
function render({ label, params = [], active = 0, doc }) {
  const open = label.indexOf("(");
  const name = params[active];
  const at = name ? label.indexOf(name, open + 1) : -1;
  const line =
    at < 0
      ? h("code", {}, label)
      : h("code", {}, label.slice(0, at), h("strong", { class: "cm-signature-active" }, name), label.slice(at + name.length));
  const firstParagraph = (doc || "").trim().split(/\n\s*\n/)[0];
  const text = firstParagraph.length > SIGNATURE_DOC_CHARS ? `${firstParagraph.slice(0, SIGNATURE_DOC_CHARS)}…` : firstParagraph;
  return h(
    "div",
    { class: "cm-signature", dataset: { testid: "signature-help" } },
    line,
    text ? h("div", { class: "cm-signature-doc" }, text) : null,
  );
}

/** Ask for the signature a moment after the cursor stops inside a call of `filename`. */
function requester(filename) {
  return ViewPlugin.fromClass(
    class {
      constructor(view) {
        this.view = view;
        this.timer = null;
        this.inFlight = null; // AbortController of the request on its way
      }

      update(update) {
        if (!update.docChanged && !update.selectionSet) return;
        this.cancel();
        const { main } = update.state.selection;
        if (main.empty && callAt(update.state, main.head) !== null) {
          this.timer = setTimeout(() => this.request(), SIGNATURE_DELAY_MS);
        }
      }

      async request() {
        const state = this.view.state;
        const pos = state.selection.main.head;
        const from = callAt(state, pos);
        if (from === null) return;
        const controller = new AbortController();
        this.inFlight = controller;
        let answer;
        try {
          answer = await ask("complete", { code: state.doc.toString(), filename, ...lineColumnOf(state, pos) }, { signal: controller.signal });
        } catch {
          return; // aborted by a newer position, or no answer: no tooltip (the next stop asks again)
        } finally {
          if (this.inFlight === controller) this.inFlight = null;
        }
        const now = this.view.state;
        if (now.doc !== state.doc || now.selection.main.head !== pos) return; // moved on meanwhile
        this.view.dispatch({ effects: setSignature.of(answer.signature ? { from, signature: answer.signature } : null) });
      }

      cancel() {
        clearTimeout(this.timer);
        this.inFlight?.abort();
        this.inFlight = null;
      }

      destroy() {
        this.cancel();
      }
    },
  );
}

const hideOnEscape = keymap.of([
  {
    key: "Escape",
    run: (view) => {
      if (!view.state.field(signatureField, false)) return false;
      view.dispatch({ effects: setSignature.of(null) });
      return true;
    },
  },
]);

/** Signature help for the Python file `filename`. */
export function signatureHelp(filename) {
  return [signatureField, requester(filename), hideOnEscape];
}

export const signatureLayout = EditorView.baseTheme({
  ".cm-signature": { padding: "0.25rem 0.5rem", maxWidth: "70ch", fontSize: "0.85rem" },
  ".cm-signature code": { fontFamily: "var(--mono)", whiteSpace: "pre-wrap" },
  ".cm-signature-active": { textDecoration: "underline" },
  ".cm-signature-doc": { marginTop: "0.2rem", whiteSpace: "pre-wrap" },
});
