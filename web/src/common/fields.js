// Fields of decoded ROS messages, as the websocket sends them ({"linear": {"x": 0.1}, "data":
// [1, 2]}) and as the CSV export writes them (columns "linear.x"; arrays as one JSON column).
// A field is named by a path: "linear.x", "data[0]", "transforms[0].transform.translation.x".

import { parseCsv } from "./csv.js";

export const LONG_ARRAY = 16; // arrays longer than this are offered as one field with an index

/**
 * The plottable leaves of a message: numbers and booleans. Long arrays of numbers come as one
 * entry {path: "ranges", length: 360, array: true}; short ones element by element.
 * @returns {{path: string, array?: boolean, length?: number}[]}
 */
export function leaves(message, prefix = "", out = []) {
  if (Array.isArray(message)) {
    if (message.length > LONG_ARRAY && message.every((v) => typeof v === "number" || v === null)) {
      out.push({ path: prefix, array: true, length: message.length });
      return out;
    }
    message.slice(0, LONG_ARRAY).forEach((item, index) => leaves(item, `${prefix}[${index}]`, out));
    return out;
  }
  if (message !== null && typeof message === "object") {
    for (const [key, value] of Object.entries(message)) leaves(value, prefix ? `${prefix}.${key}` : key, out);
    return out;
  }
  if (typeof message === "number" || typeof message === "boolean" || message === null) out.push({ path: prefix });
  return out;
}

/** "transforms[0].transform.x" -> ["transforms", 0, "transform", "x"] */
export function pathKeys(path) {
  const keys = [];
  for (const part of path.split(".")) {
    const match = /^([^[]*)((?:\[\d+\])*)$/.exec(part);
    if (!match) return [part];
    if (match[1]) keys.push(match[1]);
    for (const index of match[2].matchAll(/\[(\d+)\]/g)) keys.push(Number(index[1]));
  }
  return keys;
}

/** A function message -> number (or null) for a path. */
export function getter(path) {
  const keys = pathKeys(path);
  return (message) => {
    let value = message;
    for (const key of keys) {
      if (value === null || value === undefined) return null;
      value = value[key];
    }
    if (typeof value === "boolean") return value ? 1 : 0;
    return typeof value === "number" && Number.isFinite(value) ? value : null;
  };
}

/** The CSV file name the server gives a topic: "/ultrasonic/range_0" -> "ultrasonic__range_0.csv". */
export function csvFileName(topic) {
  const parts = topic
    .split("/")
    .filter((p) => p && p !== "." && p !== "..")
    .map((p) => p.replace(/[^\w.-]+/gu, "_"));
  const stem = parts.join("__").replace(/^\.+|\.+$/g, "");
  return `${stem || "topic"}.csv`;
}

function cell(text) {
  if (text === "true") return true;
  if (text === "false") return false;
  if (text === "") return null;
  const first = text[0];
  if (first === "[" || first === "{") {
    try {
      // The export writes non-finite floats as JSON's de facto Infinity/NaN; JSON.parse does not.
      return JSON.parse(text.replace(/-?\bInfinity\b|\bNaN\b/g, "null"));
    } catch {
      return text;
    }
  }
  const number = Number(text);
  return Number.isNaN(number) && text !== "NaN" ? text : number;
}

/**
 * A topic's CSV as samples {time_s, msg}: each row rebuilt into the message's nested shape
 * ("linear.x" -> {linear: {x}}), so the same paths and getters serve live and recorded data.
 */
export function csvSamples(text) {
  const [header, ...rows] = parseCsv(text);
  if (!header || header[0] !== "time_s") return [];
  const columns = header.slice(1).map((name) => name.split("."));
  const samples = [];
  for (const row of rows) {
    if (row.length < header.length) continue;
    const msg = {};
    columns.forEach((keys, index) => {
      let node = msg;
      for (const key of keys.slice(0, -1)) node = node[key] ??= {};
      node[keys[keys.length - 1]] = cell(row[index + 1]);
    });
    samples.push({ time_s: Number(row[0]), msg });
  }
  return samples;
}

/** Yaw [rad] of a quaternion {x, y, z, w}. */
export function yawOf(q) {
  return Math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
}
