// The view page against the fixture server (fixture.mjs): live frames,
// reconnect, run end, replay and the self-contained report, in headless
// chromium. Run by test_view_page.sh.
import { readFileSync, writeFileSync, mkdirSync } from "node:fs";
import { join } from "node:path";
import { pathToFileURL } from "node:url";
import { startFixture, fixtureScene, fixtureTrack } from "./fixture.mjs";
import { launch, checker, openPage, until, state, drawnShare, shot, near, checkPlayer, fillReport, runSteps, WEB, SHOTS } from "./harness.mjs";

const t = checker("test_view_page");
// A hung browser must not hold the suite: fail after a minute.
setTimeout(() => { t.ok(false, "finished within 60 s"); t.done(); process.exit(1); }, 60000).unref();
const browser = await launch();
const allErrors = [];

async function live() {
  let fx = await startFixture({ root: WEB });
  const { page, errors } = await openPage(browser, fx.url);
  t.ok(await until(page, () => window.pxView && window.pxView.connected && window.pxView.framesReceived > 5),
    "live: connects and receives frames");
  let s = await state(page);
  t.ok(s.mode === "live" && s.sceneModels === 3, "live: mode live, the scene's 3 models", [s.mode, s.sceneModels]);
  t.ok(await page.isHidden("#replay") && await page.isHidden("#summary"), "live: no play bar, no summary");
  await until(page, () => window.pxView.renders > 2);
  const px = await drawnShare(page);
  t.ok(px.share > 0.01, "live: the WebGL canvas shows the scene (non-background pixels)", px);
  await shot(page, "live.png");

  // The drawn tool is the newest frame's tool, and it moves with the frames.
  const a = await page.evaluate(() => ({ d: window.pxView.toolDrawn, f: window.pxView.lastFrame.tool, n: window.pxView.framesReceived, p: window.pxView.plotPoints, r: window.pxView.renders }));
  t.ok(near(a.d, a.f), "live: toolDrawn equals the last frame's tool", a);
  await until(page, (n) => window.pxView.framesReceived > n + 10, a.n);
  const b = await page.evaluate(() => ({ d: window.pxView.toolDrawn, f: window.pxView.lastFrame.tool, p: window.pxView.plotPoints, r: window.pxView.renders }));
  t.ok(near(b.d, b.f) && !near(a.d, b.d, 1e-6), "live: the drawn tool follows the frames", [a.d, b.d]);
  t.ok(b.p > a.p && a.p > 0, "live: the plots receive data", [a.p, b.p]);
  t.ok(b.r > a.r, "live: the view keeps rendering", [a.r, b.r]);

  // The fixture swaps its cloud every 60 frames (2 s).
  t.ok(await until(page, () => window.pxView.cloudsSwapped >= 1, null, 4000), "live: a swapped cloud replaces the model's points");

  // Follow the tool: the camera's target moves with the tool.
  await page.check("#follow");
  const rel = () => page.evaluate(() => window.pxView.cameraTarget.map((v, i) => v - window.pxView.toolDrawn[i]));
  await page.waitForTimeout(100);
  const r0 = await rel();
  const n1 = (await state(page)).framesReceived;
  await until(page, (n) => window.pxView.framesReceived > n + 5, n1);
  await page.waitForTimeout(100);
  const r1 = await rel();
  t.ok(near(r0, r1, 1e-6), "live: follow tool keeps the camera on the tool", [r0, r1]);
  await page.uncheck("#follow");

  // The server goes away and comes back on the same port.
  const port = fx.port;
  await fx.close();
  t.ok(await until(page, () => !window.pxView.connected), "live: sees the server gone");
  t.ok((await page.textContent("#conn")).includes("retrying"), "live: shows disconnected");
  const n0 = (await state(page)).framesReceived;
  fx = await startFixture({ root: WEB, port });
  t.ok(await until(page, (n) => window.pxView.reconnects >= 1 && window.pxView.framesReceived > n + 5, n0, 4000),
    "live: reconnects within seconds and frames flow again", await state(page));

  // The run ends: the page says so and keeps its last state.
  fx.end();
  t.ok(await until(page, () => window.pxView.ended && !window.pxView.connected), "live: end -> run ended");
  t.ok((await page.textContent("#conn")) === "run ended", "live: shows \"run ended\"");
  s = await state(page);
  t.ok(s.lastFrame !== null && near(s.toolDrawn, s.lastFrame.tool), "live: keeps the last state after the end");
  t.ok(await until(page, () => window.pxView.reconnects >= 2 && window.pxView.connected, null, 4000),
    "live: picks up the restarted run");
  s = await state(page);
  t.ok(s.errors.length === 0, "live: no page errors", s.errors);
  allErrors.push(...errors);
  await page.close();
  await fx.close();
}

async function replay() {
  const fx = await startFixture({ root: WEB, mode: "replay" });
  const { page, errors } = await openPage(browser, fx.url);
  t.ok(await until(page, () => window.pxView.replay && window.pxView.mode === "replay"), "replay: track loaded, mode replay");
  t.ok(await page.isVisible("#replay"), "replay: the play bar is shown");
  await checkPlayer(t, page, "replay", fixtureTrack().frames);
  await shot(page, "replay.png");
  t.ok((await state(page)).errors.length === 0, "replay: no page errors");
  allErrors.push(...errors);
  await page.close();
  await fx.close();
}

async function report() {
  const tpl = readFileSync(join(WEB, "report-template.html"), "utf8");
  t.ok(tpl.split("/*PX_VIEW_DATA*/null").length === 2 && !/<script[^>]+src=/.test(tpl) && !/<link[^>]+stylesheet/.test(tpl),
    "report: the template is one file with the marker once");
  const scene = fixtureScene();
  scene.models[0].name = "</script><b>not markup</b>";
  const track = fixtureTrack();
  delete track.type;
  mkdirSync(SHOTS, { recursive: true });
  const file = join(SHOTS, "report.html");
  writeFileSync(file, fillReport(tpl, { scene, track }));
  const { page, errors } = await openPage(browser, pathToFileURL(file).href);
  t.ok(await until(page, () => window.pxView && window.pxView.mode === "report" && window.pxView.sceneModels === 3),
    "report: reads the inlined data, no socket");
  const rows = await page.$$eval("#summary-table tr", (r) => r.map((x) => x.textContent));
  t.ok(!(await page.isHidden("#summary")) && rows.some((r) => r.includes("latency_us.p99") && r.includes("16")),
    "report: the summary table", rows);
  await checkPlayer(t, page, "report", fixtureTrack().frames);
  await shot(page, "report.png");
  const s = await state(page);
  t.ok(s.errors.length === 0 && !s.connected, "report: no page errors, never connected", s.errors);
  allErrors.push(...errors);
  await page.close();
}

await runSteps(t, browser, [live, replay, report], allErrors);
