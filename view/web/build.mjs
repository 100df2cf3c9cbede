// Builds the view page into static files the server serves (no network
// at run time): index.html, app.js (three.js, uPlot and the page bundled),
// app.css, and report-template.html, the same page in one file with the
// script and styles inlined and the marker /*PX_VIEW_DATA*/null where
// the report tool puts the run's {"scene":...,"track":...} object.
//   node build.mjs [--out DIR]     (default: ../../build/view/web)
import * as esbuild from "esbuild";
import { readFileSync, writeFileSync, mkdirSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
const oi = args.indexOf("--out");
const out = resolve(oi >= 0 ? args[oi + 1] : join(here, "../../build/view/web"));
mkdirSync(out, { recursive: true });

const common = { bundle: true, minify: true, write: false, logLevel: "warning", legalComments: "none" };
const js = await esbuild.build({
  ...common, entryPoints: [join(here, "src/main.js")], format: "iife", target: "es2020",
});
const css = await esbuild.build({ ...common, entryPoints: [join(here, "src/style.css")] });
const appJs = js.outputFiles[0].text;
const appCss = css.outputFiles[0].text;
const html = readFileSync(join(here, "src/index.html"), "utf8");

const LINK = '<link rel="stylesheet" href="app.css">';
const SCRIPT = '<script src="app.js"></script>';
for (const tag of [LINK, SCRIPT]) {
  if (html.split(tag).length !== 2) throw new Error(`src/index.html: expected ${tag} once`);
}
const MARKER = "/*PX_VIEW_DATA*/null";
if (appJs.includes(MARKER)) throw new Error("app.js contains the report marker");
// Inlined text must not close its element early.
const report = html
  .replace(LINK, () => `<style>${appCss.replace(/<\/style/gi, "<\\/style")}</style>`)
  .replace(SCRIPT, () => `<script>window.PX_VIEW_DATA = ${MARKER};</script>\n` +
    `<script>${appJs.replace(/<\/script/gi, "<\\/script")}</script>`);

writeFileSync(join(out, "app.js"), appJs);
writeFileSync(join(out, "app.css"), appCss);
writeFileSync(join(out, "index.html"), html);
writeFileSync(join(out, "report-template.html"), report);
console.log(`view/web: ${out} (app.js ${(appJs.length / 1024).toFixed(0)} KiB, report ${(report.length / 1024).toFixed(0)} KiB)`);
