// The console's DOM helpers (elements themselves are built with common/dom.js's `h`, never
// innerHTML from data): error lines next to their control, busy buttons, copying, dates,
// durations, pickers, focus kept across a redraw.

import { h } from "../common/dom.js";

export const $ = (selector, root = document) => root.querySelector(selector);
export const $$ = (selector, root = document) => [...root.querySelectorAll(selector)];

/** The error line of a form (its p.error), or the element itself when it is one. */
function errorLine(target) {
  if (!target) return null;
  if (target.matches?.("p.error, div.error, span.error")) return target;
  return target.querySelector?.(":scope > p.error, :scope p.error") || null;
}

/** Show the server's sentence, verbatim, in the error line of `target`. */
export function showError(target, error) {
  const line = errorLine(target);
  const message = error instanceof Error ? error.message : String(error);
  if (!line) {
    console.warn(message); // eslint-disable-line no-console
    return;
  }
  line.textContent = message;
  line.hidden = false;
}

export function clearError(target) {
  const line = errorLine(target);
  if (line) {
    line.textContent = "";
    line.hidden = true;
  }
}

/** An error shown right after a control in a table row (for row actions). */
export function rowError(cell, error) {
  let line = cell.querySelector(".error");
  if (!line) {
    line = h("span", { class: "error row-error", role: "alert" });
    cell.append(line);
  }
  line.textContent = error instanceof Error ? error.message : String(error);
  line.hidden = false;
}

export function clearRowError(cell) {
  cell.querySelector(".error")?.remove();
}

/**
 * Run `work` while `button` shows busy; a second press meanwhile does nothing. The button is
 * aria-disabled, not disabled, so keyboard focus stays on it (a disabled button drops it).
 */
export async function busy(button, work) {
  if (button && button.getAttribute("aria-busy") === "true") return undefined;
  if (button) {
    button.setAttribute("aria-busy", "true");
    button.setAttribute("aria-disabled", "true");
  }
  try {
    return await work();
  } finally {
    if (button) {
      button.removeAttribute("aria-busy");
      if (!button.dataset.done) button.removeAttribute("aria-disabled");
    }
  }
}

/** Copy text; falls back to selecting it where the Clipboard API is missing (plain http). */
export async function copyText(text, button) {
  let ok = false;
  if (navigator.clipboard && window.isSecureContext) {
    try {
      await navigator.clipboard.writeText(text);
      ok = true;
    } catch {
      ok = false;
    }
  }
  if (!ok) {
    const area = h("textarea", { "aria-hidden": "true", class: "offscreen" });
    area.value = text;
    document.body.append(area);
    area.select();
    try {
      ok = document.execCommand("copy");
    } catch {
      ok = false;
    }
    area.remove();
  }
  if (button) {
    const label = button.dataset.label || button.textContent;
    button.dataset.label = label;
    button.textContent = ok ? "Copied" : "Select and copy (Ctrl+C)";
    setTimeout(() => {
      button.textContent = label;
    }, 1600);
  }
  return ok;
}

const dateTime = new Intl.DateTimeFormat(undefined, { dateStyle: "short", timeStyle: "medium" });

/** A <time> element for an ISO date, or a dash. */
export function timeEl(iso) {
  if (!iso) return h("span", { class: "muted" }, "–");
  const date = new Date(iso);
  if (Number.isNaN(date.getTime())) return h("span", {}, iso);
  return h("time", { datetime: iso, title: iso }, dateTime.format(date));
}

/** A span of seconds as people say it: "8.5 s", "12 min 3 s", "5 h 2 min", "3 d 4 h". */
export function duration(value) {
  if (value === null || value === undefined || Number.isNaN(Number(value))) return "–";
  const s = Number(value);
  if (s < 60) return `${s.toFixed(s < 10 ? 1 : 0)} s`;
  if (s < 3600) {
    const m = Math.floor(s / 60);
    return `${m} min ${Math.floor(s - 60 * m)} s`;
  }
  const hours = Math.floor(s / 3600);
  if (hours < 48) return `${hours} h ${Math.floor((s - 3600 * hours) / 60)} min`;
  return `${Math.floor(hours / 24)} d ${hours % 24} h`;
}

export const shortId = (id) => (id ? String(id).slice(0, 8) : "");

/** Replace the options of a <select>, keeping its value when it is still offered. */
export function setOptions(select, options, { keep = true, first = null } = {}) {
  const current = select.value;
  select.replaceChildren();
  if (first) select.append(h("option", { value: first[0] }, first[1]));
  for (const [value, label] of options) select.append(h("option", { value }, label));
  if (keep && [...select.options].some((o) => o.value === current)) select.value = current;
}

export function stateBadge(state) {
  return h("span", { class: `state state-${state}` }, state);
}

/** "<=" -> "≤", ">=" -> "≥" (the API's comparisons, shown as people write them). */
export function cmp(comparison) {
  return { "<=": "≤", ">=": "≥", "<": "<", ">": ">", "==": "=" }[comparison] || comparison;
}

/**
 * Redraw `container` with `render()` and put keyboard focus back on the same control: the
 * element with the same data-action inside the row with the same data-key.
 */
export function keepFocus(container, render) {
  const active = document.activeElement;
  const row = active && container.contains(active) ? active.closest("[data-key]") : null;
  const action = active?.dataset?.action || "";
  render();
  if (!row) return;
  const sameRow = container.querySelector(`[data-key="${CSS.escape(row.dataset.key)}"]`);
  if (!sameRow) return;
  const again = sameRow.querySelector(`[data-action="${CSS.escape(action)}"]`) || sameRow.querySelector("a[href], button");
  again?.focus();
}
