// The instructor console: who is logged in (GET /api/me), the sections behind the nav links
// (#runs, #users, ...), and the things every section shares (copy buttons, logging out).
// Served at /admin by `robodojo serve`; bundled by web/build.mjs into web/static/admin.js.

import "./admin.css";
import { ApiError, api } from "../common/api.js";
import { h } from "../common/dom.js";
import { $, $$, copyText } from "./dom.js";
import { initCourses, showCourses } from "./courses.js";
import { initExercises, showExercises } from "./exercises.js";
import { initHardware, showHardware } from "./hardware.js";
import { initBoards } from "./leaderboards.js";
import { initRuns, showRuns } from "./runs.js";
import { loadCourses, loadExercises, loadUsers, state } from "./state.js";
import { startStatus, stopStatus, refreshStatus } from "./status.js";
import { initUsers, showUsers } from "./users.js";

const SECTIONS = {
  runs: () => showRuns(true),
  users: showUsers,
  exercises: showExercises,
  courses: showCourses,
  hardware: () => showHardware(true),
  status: refreshStatus,
};
let current = null;

function gate(...content) {
  for (const section of $$("main > .section")) section.hidden = true;
  $("#nav").hidden = true;
  $("#who").hidden = !state.me;
  showRuns(false);
  showHardware(false);
  stopStatus();
  current = null;
  const box = $("#gate");
  box.replaceChildren(...content);
  box.hidden = false;
}

function tokenForm() {
  const form = h(
    "form",
    { class: "inline-form token-form", "data-testid": "token-form" },
    h("label", {}, "Invite link or token ", h("input", { name: "token", type: "password", autocomplete: "off", required: true, size: 40 })),
    h("button", { type: "submit" }, "Log in"),
    h("p", { class: "error wide", role: "alert", hidden: true }),
  );
  form.addEventListener("submit", async (event) => {
    event.preventDefault();
    let token = form.elements.token.value.trim();
    try {
      token = new URL(token).searchParams.get("token") || token;
    } catch {
      // not a link: the token itself
    }
    const line = $("p.error", form);
    try {
      await api("/api/session", { method: "POST", body: { token }, quiet401: true });
      window.location.reload();
    } catch (error) {
      line.textContent = error.message;
      line.hidden = false;
    }
  });
  return form;
}

function notLoggedIn() {
  state.me = null;
  gate(
    h("h1", {}, "Please log in"),
    h(
      "p",
      {},
      "This is the instructor console of RoboDojo. Open your login link in this browser: the one ",
      h("code", {}, "robodojo serve"),
      " printed at its first start (",
      h("code", {}, "…/login?token=…"),
      "), or a new one from ",
      h("code", {}, "robodojo login-url"),
      ". Then come back to ",
      h("a", { href: "/admin" }, "/admin"),
      ".",
    ),
    h("p", { class: "muted" }, "Or paste the link (or its token) here:"),
    tokenForm(),
  );
}

function notInstructor(me) {
  gate(
    h("h1", {}, "For instructors only"),
    h("p", {}, `You are logged in as ${me.name}, a ${me.role}. This console is for instructors: the lab's page is where your exercises are.`),
    h("p", {}, h("a", { href: "/", class: "button" }, "Go to the lab")),
  );
}

function route(initial = false) {
  const name = window.location.hash.replace(/^#/, "");
  if (!(name in SECTIONS)) {
    if (current) return; // another anchor (the skip link): stay where we are
    return show("runs", initial);
  }
  return show(name, initial);
}

function show(name, initial) {
  if (!state.me) return;
  if (current !== name) {
    for (const section of $$("main > .section")) section.hidden = section.id !== `section-${name}`;
    for (const link of $$("#nav a")) {
      if (link.dataset.section === name) link.setAttribute("aria-current", "page");
      else link.removeAttribute("aria-current");
    }
    if (current === "runs") showRuns(false);
    if (current === "hardware") showHardware(false);
    current = name;
    document.title = `RoboDojo · ${$(`#section-${name} h1`).textContent} · Instructor console`;
    if (!initial) {
      const heading = $(`#section-${name} h1`);
      heading.tabIndex = -1;
      heading.focus();
    }
  }
  SECTIONS[name]();
}

async function start() {
  document.addEventListener("click", (event) => {
    const button = event.target.closest("[data-copy]");
    if (!button) return;
    const source = $(button.dataset.copy);
    if (source) copyText(source.value, button);
  });
  $("#logout").addEventListener("click", async () => {
    try {
      await api("/api/logout", { method: "POST" });
    } finally {
      notLoggedIn();
    }
  });
  window.addEventListener("robodojo:logged-out", notLoggedIn); // a 401 of any later call
  initUsers();
  initRuns();
  initExercises();
  initCourses();
  initBoards();
  initHardware();

  let me;
  try {
    me = await api("/api/me", { quiet401: true });
  } catch (error) {
    if (error instanceof ApiError && error.status === 401) notLoggedIn();
    else gate(h("h1", {}, "The server did not answer"), h("p", { class: "error" }, error.message), h("p", {}, "Reload the page to try again."));
    return;
  }
  state.me = me;
  $("#who-name").textContent = `${me.name} (${me.role})`;
  $("#who").hidden = false;
  if (me.role !== "instructor") {
    notInstructor(me);
    return;
  }
  $("#gate").hidden = true;
  $("#nav").hidden = false;
  // Names for the runs tables, pickers for the forms: loaded once, refreshed after changes.
  Promise.all([loadUsers(), loadExercises(), loadCourses()]).catch((error) => {
    console.warn(error.message); // eslint-disable-line no-console
  });
  startStatus();
  window.addEventListener("hashchange", () => route(false));
  route(true);
}

start();
