// Keyboard driving (the exercise's teleop node): while the pad has focus, the arrow keys drive;
// a key sends "pressed" once when it goes down and "released" when it comes up, as the server's
// teleop node expects (it repeats the command while a key is held). The four buttons do the
// same for a mouse or a touch screen.

import { h } from "../common/dom.js";

const KEYS = { ArrowUp: "up", ArrowDown: "down", ArrowLeft: "left", ArrowRight: "right" };
const ARROWS = { up: "▲", down: "▼", left: "◀", right: "▶" };

/** The pad; `send(op, fields)` sends a live command. */
export function drivePad(send) {
  const held = new Set();
  const set = (key, pressed) => {
    if (held.has(key) === pressed) return;
    (pressed ? held.add : held.delete).call(held, key);
    send("teleop", { key, pressed });
  };
  const releaseAll = () => [...held].forEach((key) => set(key, false));
  const buttons = Object.entries(ARROWS).map(([key, arrow]) => {
    const button = h("button", { type: "button", class: `drive ${key} live-only`, "aria-label": `drive ${key}`, tabindex: -1 }, arrow);
    button.addEventListener("pointerdown", () => set(key, true));
    for (const type of ["pointerup", "pointerleave"]) button.addEventListener(type, () => set(key, false));
    return button;
  });
  const pad = h(
    "div",
    {
      class: "drive-pad",
      tabindex: 0,
      role: "application",
      "aria-label": "Drive the robot: focus here, then hold the arrow keys",
      dataset: { testid: "teleop-pad" },
    },
    h("span", { class: "drive-hint" }, "Click here, then hold the arrow keys"),
    h("div", { class: "drive-buttons" }, buttons),
  );
  pad.addEventListener("keydown", (event) => {
    const key = KEYS[event.key];
    if (!key) return;
    event.preventDefault();
    if (!event.repeat) set(key, true);
  });
  pad.addEventListener("keyup", (event) => {
    const key = KEYS[event.key];
    if (!key) return;
    event.preventDefault();
    set(key, false);
  });
  pad.addEventListener("focusout", releaseAll);
  return pad;
}
