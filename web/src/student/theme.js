// The editors' colours: a light theme and a dark one, chosen by the system's preference
// (prefers-color-scheme) and switched live when it changes, in every editor on the page (the
// code editor, the versions preview) and in the states of the tabs not on show (each one
// catches up when it is shown). The colours of both themes keep text at WCAG AA contrast
// (4.5:1) against their backgrounds: axe-core checks the editor in the end-to-end tests.

import { defaultHighlightStyle, HighlightStyle, syntaxHighlighting } from "@codemirror/language";
import { Compartment } from "@codemirror/state";
import { EditorView, ViewPlugin } from "@codemirror/view";
import { tags as t } from "@lezer/highlight";

const systemScheme = window.matchMedia("(prefers-color-scheme: dark)");
const slot = new Compartment();
const liveViews = new Set();

// Light: CodeMirror's default highlighting on white, with the page's focus colours; only the
// default's "invalid" red (4.0:1 on white) is darkened.
const light = [
  EditorView.theme({
    "&": { backgroundColor: "#ffffff", color: "#1c2430" },
    ".cm-diagnosticSource": { color: "#4b5563" },
    ".cm-completionDetail": { color: "#4b5563" },
    ".cm-signature-doc, .cm-hover-doc": { color: "#374151" },
    ".cm-tooltip-autocomplete ul li[aria-selected]": { backgroundColor: "#1d4ed8", color: "#ffffff" },
    ".cm-tooltip-autocomplete ul li[aria-selected] .cm-completionDetail": { color: "inherit" },
  }),
  syntaxHighlighting(HighlightStyle.define([{ tag: t.invalid, color: "#c00000" }])),
  syntaxHighlighting(defaultHighlightStyle, { fallback: true }),
];

const DARK = {
  background: "#161b22",
  gutter: "#1b2129",
  text: "#e6edf3",
  muted: "#9aa7b4", // line numbers, details: 6.9:1 on the background
  selection: "#264f78",
  activeLine: "#ffffff0d",
  panel: "#1f2630",
  border: "#3a4350",
};

const dark = [
  EditorView.theme(
    {
      "&": { backgroundColor: DARK.background, color: DARK.text },
      ".cm-content": { caretColor: "#f0f6fc" },
      ".cm-cursor, .cm-dropCursor": { borderLeftColor: "#f0f6fc" },
      "&.cm-focused > .cm-scroller > .cm-selectionLayer .cm-selectionBackground, .cm-selectionBackground, .cm-content ::selection":
        { backgroundColor: DARK.selection },
      ".cm-activeLine": { backgroundColor: DARK.activeLine },
      ".cm-gutters": { backgroundColor: DARK.gutter, color: DARK.muted, borderRight: `1px solid ${DARK.border}` },
      ".cm-activeLineGutter": { backgroundColor: "#2a323d", color: DARK.text },
      ".cm-panels": { backgroundColor: DARK.panel, color: DARK.text },
      ".cm-panels-top": { borderBottom: `1px solid ${DARK.border}` },
      ".cm-textfield": { backgroundColor: DARK.background, color: DARK.text, border: `1px solid ${DARK.border}` },
      ".cm-button": { backgroundImage: "none", backgroundColor: "#2a323d", color: DARK.text, border: `1px solid ${DARK.border}` },
      ".cm-tooltip": { backgroundColor: DARK.panel, color: DARK.text, border: `1px solid ${DARK.border}` },
      ".cm-tooltip-autocomplete ul li[aria-selected]": { backgroundColor: "#1f6feb", color: "#ffffff" },
      ".cm-tooltip-autocomplete ul li[aria-selected] .cm-completionDetail": { color: "inherit" },
      ".cm-completionDetail, .cm-diagnosticSource": { color: DARK.muted },
      ".cm-signature-doc, .cm-hover-doc": { color: "#c9d1d9" },
      ".cm-searchMatch": { backgroundColor: "#bb800966", outline: "1px solid #bb8009" },
      ".cm-searchMatch.cm-searchMatch-selected": { backgroundColor: "#1f6feb66" },
      ".cm-selectionMatch": { backgroundColor: "#3fb95026" },
      "&.cm-focused .cm-matchingBracket": { backgroundColor: "#3fb9504d", color: DARK.text },
    },
    { dark: true },
  ),
  syntaxHighlighting(
    HighlightStyle.define([
      { tag: [t.keyword, t.controlKeyword, t.definitionKeyword, t.moduleKeyword, t.operatorKeyword], color: "#ff7b72" },
      { tag: [t.string, t.special(t.string)], color: "#a5d6ff" },
      { tag: [t.number, t.bool, t.null, t.atom], color: "#79c0ff" },
      { tag: t.comment, color: "#9aa7b4", fontStyle: "italic" },
      { tag: [t.definition(t.variableName), t.function(t.definition(t.variableName))], color: "#d2a8ff" },
      { tag: [t.className, t.definition(t.className), t.typeName], color: "#ffa657" },
      { tag: [t.propertyName, t.function(t.propertyName)], color: "#7ee787" },
      { tag: t.self, color: "#ffa198" },
      { tag: [t.meta, t.processingInstruction], color: "#e3b341" },
      { tag: t.invalid, color: "#ffa198", textDecoration: "underline wavy" },
      { tag: t.emphasis, fontStyle: "italic" },
      { tag: t.strong, fontWeight: "bold" },
    ]),
  ),
];

const themeFor = (isDark) => (isDark ? dark : light);

/** Reconfigure `view` if its theme is not the system's (e.g. a tab's state made before a switch). */
function follow(view) {
  if (!liveViews.has(view)) return;
  const isDark = systemScheme.matches;
  if (view.state.facet(EditorView.darkTheme) !== isDark) view.dispatch({ effects: slot.reconfigure(themeFor(isDark)) });
}

// A view registers itself while it holds a state with this extension; a state shown later
// (setState) recreates the plugin, which catches up after the update it is built in (a view
// cannot be dispatched to while it updates; the microtask runs before the next paint).
const tracker = ViewPlugin.define((view) => {
  liveViews.add(view);
  queueMicrotask(() => follow(view));
  return { destroy: () => liveViews.delete(view) };
});

systemScheme.addEventListener("change", () => {
  for (const view of liveViews) follow(view);
});

/** The editor colours that follow the system's light or dark preference. */
export function systemTheme() {
  return [slot.of(themeFor(systemScheme.matches)), tracker];
}
