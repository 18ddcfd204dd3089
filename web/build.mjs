// Bundle the browser client with esbuild: src/<page>/main.js -> static/<page>.js and
// static/<page>.css (minified, for current Chromium and Firefox). The output is committed, so
// installing RoboDojo needs no Node.js; see README.md.
//
//   node build.mjs            build every page (each folder of src/ with a main.js)
//   node build.mjs student    build only these pages
//   node build.mjs --check    build in memory; fail if static/ differs from the sources
//   node build.mjs --dev      unminified with inline source maps (do not commit)
//
// The page's HTML (index.html for "student", <page>.html otherwise) loads the bundle as
// /static/<page>.js?v=<hash>; the hash is rewritten here, so a browser never runs a stale
// bundle after an upgrade.

import { createHash } from "node:crypto";
import { existsSync, readdirSync, readFileSync, writeFileSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { gzipSync } from "node:zlib";
import * as esbuild from "esbuild";

const here = dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
const check = args.includes("--check");
const dev = args.includes("--dev");
const named = args.filter((a) => !a.startsWith("--"));
const TARGET = ["chrome115", "firefox115", "safari16"]; // browsers of the last two years

const pages = readdirSync(join(here, "src"), { withFileTypes: true })
  .filter((d) => d.isDirectory() && existsSync(join(here, "src", d.name, "main.js")))
  .map((d) => d.name)
  .filter((name) => !named.length || named.includes(name));
if (named.length && pages.length !== named.length) {
  console.error(`unknown page(s): ${named.filter((n) => !pages.includes(n)).join(", ")}`);
  process.exit(2);
}

const htmlOf = (page) => join(here, page === "student" ? "index.html" : `${page}.html`);
const hash = (bytes) => createHash("sha256").update(bytes).digest("hex").slice(0, 10);

let stale = [];
for (const page of pages) {
  const result = await esbuild.build({
    entryPoints: { [page]: join(here, "src", page, "main.js") },
    outdir: join(here, "static"),
    bundle: true,
    format: "esm",
    target: TARGET,
    minify: !dev,
    sourcemap: dev ? "inline" : false,
    legalComments: "none", // the licences are listed in README.md
    charset: "utf8",
    write: false,
    logLevel: "warning",
  });
  const outputs = result.outputFiles.map((file) => ({ path: file.path, contents: Buffer.from(file.contents) }));
  const html = htmlOf(page);
  if (existsSync(html)) {
    let text = readFileSync(html, "utf8");
    for (const output of outputs) {
      const name = output.path.split("/").pop();
      text = text.replace(new RegExp(`/static/${name.replace(".", "\\.")}(\\?v=[0-9a-f]*)?"`), `/static/${name}?v=${hash(output.contents)}"`);
    }
    outputs.push({ path: html, contents: Buffer.from(text) });
  }
  for (const output of outputs) {
    const before = existsSync(output.path) ? readFileSync(output.path) : null;
    if (check) {
      if (!before || !before.equals(output.contents)) stale.push(output.path);
      continue;
    }
    if (!before || !before.equals(output.contents)) writeFileSync(output.path, output.contents);
    if (!output.path.endsWith(".html")) {
      const kb = (n) => `${(n / 1024).toFixed(1)} KiB`;
      console.log(`${output.path.slice(here.length + 1)}: ${kb(output.contents.length)} (${kb(gzipSync(output.contents).length)} gzipped)`);
    }
  }
}
if (check) {
  if (stale.length) {
    console.error(`out of date (run: cd web && npm ci && node build.mjs):\n  ${stale.join("\n  ")}`);
    process.exit(1);
  }
  console.log(`static/ matches src/ for: ${pages.join(", ")}`);
}
