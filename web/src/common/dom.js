// A few DOM helpers: build elements without innerHTML, so text from the server (log lines,
// exercise text, file names) is always text.

/**
 * h("button", {class: "x", onclick: fn, dataset: {testid: "run"}}, "Run")
 * Attributes: `class`, `dataset`, `style` (object), on* (listeners), booleans (present if true),
 * anything else via setAttribute. Children: nodes, strings, numbers, arrays, null (skipped).
 */
export function h(tag, attributes = {}, ...children) {
  const element = tag.includes(":")
    ? document.createElementNS("http://www.w3.org/2000/svg", tag.split(":")[1])
    : document.createElement(tag);
  for (const [key, value] of Object.entries(attributes || {})) {
    if (value === undefined || value === null || value === false) continue;
    if (key === "class") element.setAttribute("class", value);
    else if (key === "dataset") Object.assign(element.dataset, value);
    else if (key === "style" && typeof value === "object") Object.assign(element.style, value);
    else if (key.startsWith("on") && typeof value === "function") {
      element.addEventListener(key.slice(2), value);
    } else if (value === true) element.setAttribute(key, "");
    else element.setAttribute(key, String(value));
  }
  append(element, children);
  return element;
}

/** SVG element: svg("circle", {cx: 1}) */
export function svg(tag, attributes = {}, ...children) {
  return h(`svg:${tag}`, attributes, ...children);
}

function append(element, children) {
  for (const child of children) {
    if (child === null || child === undefined || child === false) continue;
    if (Array.isArray(child)) append(element, child);
    else element.append(child instanceof Node ? child : String(child));
  }
}

/** Replace an element's children. */
export function fill(element, ...children) {
  element.replaceChildren();
  append(element, children);
  return element;
}

export function byId(id) {
  const element = document.getElementById(id);
  if (!element) throw new Error(`index.html has no element #${id}`);
  return element;
}

/** 1234 -> "1.2 kB" */
export function bytes(count) {
  if (count < 1000) return `${count} B`;
  if (count < 1e6) return `${(count / 1e3).toFixed(1)} kB`;
  return `${(count / 1e6).toFixed(1)} MB`;
}

/** A duration in seconds as a short human string: 0.0123 -> "12.3 ms". */
export function seconds(value) {
  if (value === null || value === undefined || !Number.isFinite(value)) return "-";
  if (value === 0) return "0";
  const abs = Math.abs(value);
  if (abs < 1e-3) return `${(value * 1e6).toFixed(0)} µs`;
  if (abs < 1) return `${(value * 1e3).toPrecision(3)} ms`;
  return `${value.toFixed(2)} s`;
}

/** An ISO date as local "HH:MM:SS" today, "D Mon HH:MM" otherwise. */
export function when(iso) {
  if (!iso) return "";
  const date = new Date(iso);
  const now = new Date();
  const time = date.toLocaleTimeString([], { hour: "2-digit", minute: "2-digit", second: "2-digit" });
  if (date.toDateString() === now.toDateString()) return time;
  return `${date.toLocaleDateString([], { day: "numeric", month: "short" })} ${time.slice(0, 5)}`;
}

/** Call fn at most once per `ms`, the last call winning (trailing). */
export function debounce(fn, ms) {
  let timer = null;
  const wrapped = (...args) => {
    clearTimeout(timer);
    timer = setTimeout(() => {
      timer = null;
      fn(...args);
    }, ms);
  };
  wrapped.cancel = () => clearTimeout(timer);
  wrapped.pending = () => timer !== null;
  return wrapped;
}
