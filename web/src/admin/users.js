// Users: the list (filter), one created, many imported from CSV, disable/enable, a new token.
// An invite link exists only in the answer that made its token: it is shown once, to copy.

import { api } from "../common/api.js";
import { toCsv } from "../common/csv.js";
import { h } from "../common/dom.js";
import { $, busy, clearError, clearRowError, copyText, keepFocus, rowError, showError, timeEl } from "./dom.js";
import { loadUsers, state, subscribe } from "./state.js";

let lastBulk = [];

function showInvite(user) {
  const panel = $("#invite");
  $("#invite-who").textContent = user.email ? `${user.name} (${user.email})` : user.name;
  $("#invite-link").value = user.invite_url;
  panel.hidden = false;
  panel.scrollIntoView({ block: "nearest" });
  $("#invite-link").focus();
  $("#invite-link").select();
}

function showBulkInvites(users) {
  lastBulk = users;
  const panel = $("#bulk-invites");
  const body = $("tbody", panel);
  body.replaceChildren(
    ...users.map((u, i) => {
      const id = `bulk-link-${i}`;
      return h(
        "tr",
        {},
        h("td", {}, u.name),
        h("td", {}, u.email || ""),
        h(
          "td",
          {},
          h(
            "div",
            { class: "copy-row" },
            h("label", { class: "sr-only", for: id }, `Invite link of ${u.name}`),
            h("input", { id, readonly: true, value: u.invite_url, class: "link-input" }),
            h("button", { type: "button", class: "copy secondary small-btn", "data-copy": `#${id}`, "aria-label": `Copy the invite link of ${u.name}` }, "Copy"),
          ),
        ),
      );
    }),
  );
  panel.hidden = false;
  panel.focus();
}

function bulkCsv() {
  return toCsv([["name", "email", "invite_url"], ...lastBulk.map((u) => [u.name, u.email || "", u.invite_url])]);
}

function actionsFor(user) {
  const cell = h("td", { class: "row-actions" });
  const self = state.me && state.me.id === user.id;
  const toggle = h(
    "button",
    {
      type: "button",
      class: user.disabled ? "secondary small-btn" : "danger small-btn",
      "data-testid": user.disabled ? "user-enable" : "user-disable",
      dataset: { action: "toggle" },
      "aria-label": `${user.disabled ? "Enable" : "Disable"} ${user.name}`,
      title: self && !user.disabled ? "you cannot disable yourself" : null,
    },
    user.disabled ? "Enable" : "Disable",
  );
  toggle.addEventListener("click", () =>
    busy(toggle, async () => {
      clearRowError(cell);
      try {
        await api(`/api/admin/users/${encodeURIComponent(user.id)}`, { method: "PATCH", body: { disabled: !user.disabled } });
        await loadUsers();
      } catch (error) {
        rowError(cell, error);
      }
    }),
  );
  const renew = h(
    "button",
    {
      type: "button",
      class: "secondary small-btn",
      "data-testid": "user-new-token",
      dataset: { action: "token" },
      "aria-label": `New token for ${user.name}`,
      title: "a new token: the old invite link stops working",
    },
    "New token",
  );
  renew.addEventListener("click", () =>
    busy(renew, async () => {
      clearRowError(cell);
      try {
        const answer = await api(`/api/admin/users/${encodeURIComponent(user.id)}/token`, { method: "POST" });
        showInvite(answer);
        loadUsers();
      } catch (error) {
        rowError(cell, error);
      }
    }),
  );
  cell.append(toggle, " ", renew);
  return cell;
}

function renderUsers() {
  const filter = $("#users-filter").value.trim().toLowerCase();
  const shown = state.users.filter(
    (u) => !filter || u.name.toLowerCase().includes(filter) || (u.email || "").toLowerCase().includes(filter),
  );
  const rows = shown.map((u) =>
    h(
      "tr",
      { dataset: { userId: u.id, key: u.id }, class: u.disabled ? "disabled" : null },
      h("th", { scope: "row" }, u.name, state.me && state.me.id === u.id ? h("span", { class: "muted" }, " (you)") : null),
      h("td", {}, u.email || h("span", { class: "muted" }, "–")),
      h("td", {}, u.role),
      h("td", {}, u.disabled ? h("span", { class: "state state-failed" }, "disabled") : "active"),
      h("td", {}, timeEl(u.created_at)),
      h("td", {}, timeEl(u.token_created_at)),
      actionsFor(u),
    ),
  );
  const body = $("#users-table tbody");
  keepFocus(body, () => body.replaceChildren(...rows));
  const students = state.users.filter((u) => u.role === "student").length;
  $("#users-count").textContent =
    `${shown.length} shown of ${state.users.length} (${students} student${students === 1 ? "" : "s"})`;
}

export function initUsers() {
  subscribe("users", renderUsers);
  $("#users-filter").addEventListener("input", renderUsers);

  const form = $("#create-user");
  form.addEventListener("submit", async (event) => {
    event.preventDefault();
    const button = $("button[type=submit]", form);
    await busy(button, async () => {
      clearError(form);
      const data = new FormData(form);
      const body = { name: String(data.get("name")).trim(), role: data.get("role") };
      const email = String(data.get("email") || "").trim();
      if (email) body.email = email;
      if (data.get("course")) body.course = data.get("course");
      try {
        const user = await api("/api/admin/users", { method: "POST", body });
        form.reset();
        showInvite(user);
        await loadUsers();
      } catch (error) {
        showError(form, error);
      }
    });
  });

  const bulk = $("#bulk-users");
  bulk.elements.file.addEventListener("change", async () => {
    clearError(bulk);
    const file = bulk.elements.file.files[0];
    if (!file) return;
    if (file.size > 2 * 1024 * 1024) {
      showError(bulk, `${file.name} is ${Math.round(file.size / 1024)} KiB; a class list is far smaller`);
      return;
    }
    bulk.elements.csv.value = await file.text();
  });
  bulk.addEventListener("submit", async (event) => {
    event.preventDefault();
    const button = $("button[type=submit]", bulk);
    await busy(button, async () => {
      clearError(bulk);
      const text = bulk.elements.csv.value;
      if (!text.trim()) {
        showError(bulk, "paste the CSV or pick a file first (a header line name,email, then a student a line)");
        return;
      }
      const course = bulk.elements.course.value;
      const path = `/api/admin/users/bulk${course ? `?course=${encodeURIComponent(course)}` : ""}`;
      try {
        const answer = await api(path, { method: "POST", body: text, contentType: "text/csv" });
        bulk.reset();
        showBulkInvites(answer.users);
        await loadUsers();
      } catch (error) {
        showError(bulk, error);
      }
    });
  });

  $("#invite-close").addEventListener("click", () => {
    $("#invite").hidden = true;
    $("#invite-link").value = "";
    $("#create-user").elements.name.focus();
  });
  $("#bulk-close").addEventListener("click", () => {
    $("#bulk-invites").hidden = true;
    $("#bulk-invites tbody").replaceChildren();
    lastBulk = [];
    $("#bulk-users").elements.csv.focus();
  });
  $("#bulk-copy").addEventListener("click", (event) => copyText(bulkCsv(), event.currentTarget));
  $("#bulk-download").addEventListener("click", () => {
    const url = URL.createObjectURL(new Blob([bulkCsv()], { type: "text/csv" }));
    const link = h("a", { href: url, download: "invite-links.csv" });
    document.body.append(link);
    link.click();
    link.remove();
    setTimeout(() => URL.revokeObjectURL(url), 1000);
  });
}

export async function showUsers() {
  try {
    clearError($("#users-error"));
    await loadUsers();
  } catch (error) {
    showError($("#users-error"), error);
  }
}
