// The page against the real server: a short simulated run of
// proxima-run --view on the real clock, stopped and started again (the
// page reconnects), then the run's telemetry replayed by proxima-view
// and written as its HTML report. Run by test_view_e2e.sh.
import { mkdirSync, existsSync, rmSync } from "node:fs";
import { join } from "node:path";
import { pathToFileURL } from "node:url";
import { launch, checker, openPage, until, state, drawnShare, shot, near, checkPlayer, runSteps, freePort, run, served,
  WEB, SHOTS } from "./harness.mjs";

const t = checker("test_view_e2e");
setTimeout(() => { t.ok(false, "finished within 90 s"); t.done(); process.exit(1); }, 90000).unref();
const CONFIG = "config/examples/haptic_sim.yaml";
const OUT = join(SHOTS, "e2e");
rmSync(OUT, { recursive: true, force: true });
mkdirSync(OUT, { recursive: true });
// The first run's files are replayed (the restarted one is short).
const CSV = join(OUT, "telemetry.csv");
const SUMMARY = join(OUT, "run-summary.json");
const CSV2 = join(OUT, "telemetry-2.csv");

const runArgs = (port, csv, summary) => [CONFIG, "--duration-s", "60", "--view", `127.0.0.1:${port}`,
  "--view-root", WEB, "--telemetry", csv, ...(summary ? ["--summary-json", summary] : [])];

const browser = await launch();
const procs = [];
const allErrors = [];

async function live() {
  const port = await freePort();
  const url = `http://127.0.0.1:${port}/`;
  let p = run("proxima-run", runArgs(port, CSV, SUMMARY));
  procs.push(p);
  t.ok(await served(url, p), "proxima-run --view serves the page", p.out);
  const { page, errors } = await openPage(browser, url);
  t.ok(await until(page, () => window.pxView && window.pxView.connected && window.pxView.framesReceived > 5, null, 8000),
    "live: connects and receives frames", p.out);
  let s = await state(page);
  t.ok(s.mode === "live" && s.sceneModels >= 1, "live: mode live, the config's models", [s.mode, s.sceneModels]);
  await until(page, () => window.pxView.renders > 2);
  const px = await drawnShare(page);
  t.ok(px.share > 0.01, "live: the WebGL canvas shows the scene", px);
  const a = await page.evaluate(() => ({ d: window.pxView.toolDrawn, f: window.pxView.lastFrame, n: window.pxView.framesReceived, p: window.pxView.plotPoints }));
  t.ok(near(a.d, a.f.tool), "live: toolDrawn equals the last frame's tool", a);
  await until(page, (n) => window.pxView.framesReceived > n + 15, a.n);
  const b = await page.evaluate(() => ({ d: window.pxView.toolDrawn, f: window.pxView.lastFrame, p: window.pxView.plotPoints }));
  t.ok(near(b.d, b.f.tool) && b.f.t_s > a.f.t_s && !near(a.d, b.d, 1e-9), "live: the drawn tool follows the run", [a.d, b.d]);
  t.ok(b.p > a.p && a.p > 0, "live: the plots receive data", [a.p, b.p]);
  await shot(page, "e2e-live.png");

  // Ctrl-C ends the run: the page says so; a new run on the port is picked up.
  p.kill("SIGINT");
  t.ok((await p.done) === 0 && existsSync(CSV) && existsSync(SUMMARY), "live: proxima-run ends on SIGINT with status 0, writes its files", p.out);
  t.ok(await until(page, () => window.pxView.ended && !window.pxView.connected), "live: the page shows the run ended");
  const n0 = (await state(page)).framesReceived;
  p = run("proxima-run", runArgs(port, CSV2));
  procs.push(p);
  t.ok(await until(page, (n) => window.pxView.reconnects >= 1 && window.pxView.connected &&
    window.pxView.framesReceived > n + 10, n0, 10000), "live: reconnects to the restarted run, frames flow again", p.out);
  p.kill("SIGINT");
  t.ok((await p.done) === 0 && existsSync(CSV2), "live: the restarted run ends and writes its telemetry", p.out);
  s = await state(page);
  t.ok(s.errors.length === 0, "live: no page errors", s.errors);
  allErrors.push(...errors);
  await page.close();
}

async function replay() {
  const port = await freePort();
  const url = `http://127.0.0.1:${port}/`;
  const p = run("proxima-view", ["--port", `127.0.0.1:${port}`, "--config", CONFIG, "--web-root", WEB, "--summary", SUMMARY, CSV]);
  procs.push(p);
  t.ok(await served(url, p), "proxima-view serves the replay", p.out);
  const { page, errors } = await openPage(browser, url);
  t.ok(await until(page, () => window.pxView && window.pxView.mode === "replay" && window.pxView.replay, null, 8000),
    "replay: the run is loaded, mode replay", p.out);
  await checkPlayer(t, page, "replay");
  const rows = await page.$$eval("#summary-table tr", (r) => r.length);
  t.ok(rows > 0, "replay: the summary table", rows);
  await shot(page, "e2e-replay.png");
  t.ok((await state(page)).errors.length === 0, "replay: no page errors");
  allErrors.push(...errors);
  await page.close();
  p.kill("SIGINT");
  await p.done;
}

async function report() {
  const html = join(OUT, "run.html");
  const p = run("proxima-view", ["--html", html, "--config", CONFIG, "--template", join(WEB, "report-template.html"),
    "--summary", SUMMARY, CSV]);
  t.ok((await p.done) === 0 && existsSync(html), "proxima-view --html writes the report", p.out);
  const { page, errors } = await openPage(browser, pathToFileURL(html).href);
  t.ok(await until(page, () => window.pxView && window.pxView.mode === "report" && window.pxView.sceneModels >= 1, null, 8000),
    "report: the page reads its inlined run");
  await checkPlayer(t, page, "report");
  await shot(page, "e2e-report.png");
  t.ok((await state(page)).errors.length === 0, "report: no page errors");
  allErrors.push(...errors);
  await page.close();
}

await runSteps(t, browser, [live, replay, report], allErrors, () => {
  for (const p of procs) if (p.exitCode === null) p.kill("SIGKILL");
});
