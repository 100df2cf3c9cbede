// The view page against the fixture server (fixture.mjs): live frames,
// reconnect, run end, replay and the self-contained report, in headless
// chromium. Run by test_view_page.sh.
import { readFileSync, writeFileSync, mkdirSync } from "node:fs";
import { join } from "node:path";
import { pathToFileURL } from "node:url";
import { startFixture, fixtureScene, fixtureTrack } from "./fixture.mjs";
import { launch, checker, openPage, until, state, drawnShare, shot, near, WEB, SHOTS } from "./harness.mjs";

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

async function checkPlayer(page, label) {
  let s = await state(page);
  t.ok(s.replay && s.replay.frames === 120 && s.plotPoints === 120, `${label}: the whole run is loaded`, s.replay);
  const frames = fixtureTrack().frames;
  // Scrub to the middle: the tool is the frame at that time.
  await page.$eval("#scrub", (el) => { el.value = "500"; el.dispatchEvent(new Event("input")); });
  s = await state(page);
  const mid = frames.filter((f) => f.t_s <= s.replay.t_s).pop();
  t.ok(near(s.toolDrawn, mid.tool) && s.lastFrame.cycle === mid.cycle, `${label}: scrub shows the frame at that time`,
    [s.replay.t_s, s.toolDrawn, mid.tool]);
  // Play, then pause: the time moves, then holds.
  await page.click("#play");
  t.ok(await until(page, (x) => window.pxView.replay.t_s > x + 0.1, s.replay.t_s, 3000), `${label}: play advances the time`);
  await page.click("#play");
  const s2 = await state(page);
  await page.waitForTimeout(150);
  const s3 = await state(page);
  t.ok(!s3.replay.playing && s3.replay.t_s === s2.replay.t_s && near(s3.toolDrawn, s2.toolDrawn),
    `${label}: pause holds the time and the tool`, [s2.replay, s3.replay]);
  t.ok(!near(s2.toolDrawn, s.toolDrawn, 1e-6), `${label}: play moved the tool`, [s.toolDrawn, s2.toolDrawn]);
  // From the start at 4x: the whole run (4 s) plays in about 1 s.
  await page.$eval("#scrub", (el) => { el.value = "0"; el.dispatchEvent(new Event("input")); });
  await page.selectOption("#speed", "4");
  const w0 = Date.now();
  await page.click("#play");
  t.ok(await until(page, () => !window.pxView.replay.playing, null, 3000), `${label}: 4x plays to the end`);
  const ms = Date.now() - w0;
  const s4 = await state(page);
  t.ok(s4.replay.speed === 4 && ms < 2500 && near(s4.toolDrawn, frames[frames.length - 1].tool),
    `${label}: at 4x the 4 s run took ${ms} ms and ends on its last frame`, s4.replay);
  const px = await drawnShare(page);
  t.ok(px.share > 0.01, `${label}: the WebGL canvas shows the scene`, px);
}

async function replay() {
  const fx = await startFixture({ root: WEB, mode: "replay" });
  const { page, errors } = await openPage(browser, fx.url);
  t.ok(await until(page, () => window.pxView.replay && window.pxView.mode === "replay"), "replay: track loaded, mode replay");
  t.ok(await page.isVisible("#replay"), "replay: the play bar is shown");
  await checkPlayer(page, "replay");
  await shot(page, "replay.png");
  t.ok((await state(page)).errors.length === 0, "replay: no page errors");
  allErrors.push(...errors);
  await page.close();
  await fx.close();
}

// The report tool's substitution: the marker replaced by the JSON object,
// "</" written as "<\/" so no string can close the script element.
export function fillReport(template, data) {
  const marker = "/*PX_VIEW_DATA*/null";
  const parts = template.split(marker);
  if (parts.length !== 2) throw new Error("report template: marker not found exactly once");
  return parts[0] + JSON.stringify(data).replace(/<\//g, "<\\/") + parts[1];
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
  await checkPlayer(page, "report");
  await shot(page, "report.png");
  const s = await state(page);
  t.ok(s.errors.length === 0 && !s.connected, "report: no page errors, never connected", s.errors);
  allErrors.push(...errors);
  await page.close();
}

const timed = async (f) => { const t0 = Date.now(); await f(); console.log(`   (${f.name}: ${Date.now() - t0} ms)`); };
try {
  await timed(live);
  await timed(replay);
  await timed(report);
  t.ok(allErrors.length === 0, "no console errors on any page", allErrors);
} catch (e) {
  t.ok(false, "the browser test ran to its end", String(e && e.stack || e));
} finally {
  await browser.close();
}
process.exit(t.done() ? 0 : 1);
