// What a run left: the files the student's code saved (images shown inline), the recording
// (MCAP, opens in Foxglove), a CSV per topic and each node's log. Downloads come once the run
// has ended, when they are complete.

import { api } from "../common/api.js";
import { byId, bytes, fill, h } from "../common/dom.js";
import { app, on } from "./state.js";

const IMAGE = /\.(png|jpe?g|gif|svg|webp)$/i;

const panel = byId("panel-files");

export function initFiles() {
  on("target", () => fill(panel, h("p", { class: "hint" }, "Run once to see the files it leaves.")));
  on("run-shown", ({ live }) => {
    if (live) fill(panel, h("p", { class: "hint" }, "The run's files and downloads come when it has ended."));
  });
  on("run-ended", ({ run }) => load(run));
}

async function load(run) {
  const id = run.id;
  const [artifacts, csv] = await Promise.all([
    api(`/api/runs/${id}/artifacts`).catch((error) => ({ error: error.message })),
    api(`/api/runs/${id}/csv`).catch((error) => ({ error: error.message })),
  ]);
  if (app.run?.id !== id) return;
  const nodes = [...new Set([...Object.keys(run.nodes || {}), ...(run.code || []).map((c) => c.name)])];
  fill(
    panel,
    h("h3", {}, "Saved by your code"),
    artifactList(artifacts),
    h("h3", {}, "Downloads"),
    h(
      "p",
      { class: "downloads" },
      h("a", { class: "button-link", href: `/api/runs/${id}/recording.mcap`, download: `robodojo-${id}.mcap`, dataset: { testid: "mcap-download" } }, "Recording (MCAP)"),
      " ",
      h("span", { class: "hint" }, "every topic, opens in Foxglove Studio"),
    ),
    csv.error
      ? h("p", { class: "hint" }, `CSV: ${csv.error}`)
      : h(
          "ul",
          { class: "csv-list", dataset: { testid: "csv-downloads" }, "aria-label": "A CSV file per topic" },
          csv.files.map((file) => h("li", {}, h("a", { class: "button-link small", href: file.url, download: `${id}-${file.name}`, dataset: { testid: "csv-download" } }, file.name))),
        ),
    nodes.length
      ? h(
          "p",
          { class: "downloads" },
          "Logs: ",
          nodes.map((node) => [h("a", { href: `/api/runs/${id}/logs/${encodeURIComponent(node)}.log`, download: `${id}-${node}.log` }, `${node}.log`), " "]),
        )
      : null,
  );
}

function artifactList(artifacts) {
  if (artifacts.error) return h("p", { class: "hint" }, artifacts.error);
  if (!artifacts.files.length) return h("p", { class: "hint" }, "No files. Files your code writes in its working directory (plt.savefig, CSV) appear here.");
  return h(
    "ul",
    { class: "artifacts", dataset: { testid: "artifacts" } },
    artifacts.files.map((file) =>
      h(
        "li",
        { dataset: { testid: "artifact", name: file.name } },
        IMAGE.test(file.name) ? h("img", { src: file.url, alt: `${file.name}, saved by the run`, loading: "lazy" }) : null,
        h("a", { href: file.url, download: file.name.split("/").pop() }, file.name),
        ` ${bytes(file.bytes)}`,
      ),
    ),
  );
}
