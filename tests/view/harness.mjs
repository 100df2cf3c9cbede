// Shared parts of the browser tests: Debian's chromium driven by
// playwright-core (from view/web/node_modules), checks counted and
// printed in the suite's format ("name: N passed, N failed, N skipped"),
// screenshots kept in build/tests/view/.
import { spawn } from "node:child_process";
import { createServer } from "node:net";
import { mkdirSync } from "node:fs";
import { join, resolve } from "node:path";
import { need } from "./fixture.mjs";

const { chromium } = need("playwright-core");
export const CHROMIUM = process.env.PX_CHROMIUM || "/usr/bin/chromium";
export const SHOTS = resolve(process.env.BUILD || "build", "tests/view");
export const WEB = resolve(process.env.BUILD || "build", "view/web");
// The project's tools the tests run against the page.
export const BIN = resolve(process.env.PX_VIEW_BIN || join(process.env.BUILD || "build", "bin"));

export async function launch() {
  // WebGL without a GPU: ANGLE on SwiftShader, software rendering.
  return chromium.launch({
    executablePath: CHROMIUM,
    args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--disable-gpu-sandbox"],
  });
}

export function checker(name) {
  let pass = 0, fail = 0, skip = 0;
  return {
    ok(cond, what, detail) {
      if (cond) { console.log(`ok   ${what}`); pass++; }
      else { console.log(`FAIL ${what}${detail === undefined ? "" : ": " + JSON.stringify(detail)}`); fail++; }
      return cond;
    },
    skip(what) { console.log(`skip ${what}`); skip++; },
    done() {
      console.log(`${name}: ${pass} passed, ${fail} failed, ${skip} skipped`);
      return fail === 0;
    },
  };
}

// A page with its console errors and uncaught exceptions collected.
export async function openPage(browser, url) {
  const page = await browser.newPage({ viewport: { width: 960, height: 540 } });
  const errors = [];
  // The browser's own line for a refused WebSocket is expected while a
  // server is down (the page retries every second); any other is an error.
  page.on("console", (m) => {
    if (m.type() === "error" && !/^WebSocket connection to .* failed: .*ERR_CONNECTION_REFUSED/.test(m.text())) errors.push(m.text());
  });
  page.on("pageerror", (e) => errors.push(String(e)));
  await page.goto(url);
  return { page, errors };
}

// Waits until fn(arg) is truthy in the page; false after timeoutMs.
export async function until(page, fn, arg, timeoutMs = 5000) {
  try {
    await page.waitForFunction(fn, arg, { timeout: timeoutMs, polling: 50 });
    return true;
  } catch (e) {
    return false;
  }
}

export const state = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.pxView)));

// Share of the WebGL canvas's pixels that differ from its clear colour.
export function drawnShare(page) {
  return page.evaluate(() => {
    const gl = document.querySelector("#view canvas");
    const c = document.createElement("canvas");
    c.width = gl.width;
    c.height = gl.height;
    const ctx = c.getContext("2d");
    ctx.drawImage(gl, 0, 0);
    const px = ctx.getImageData(0, 0, c.width, c.height).data;
    const [r0, g0, b0] = [px[0], px[1], px[2]];
    let other = 0;
    for (let i = 0; i < px.length; i += 4) {
      if (Math.abs(px[i] - 0x10) + Math.abs(px[i + 1] - 0x13) + Math.abs(px[i + 2] - 0x18) > 12) other++;
    }
    return { share: other / (px.length / 4), corner: [r0, g0, b0], width: c.width, height: c.height };
  });
}

export async function shot(page, file) {
  mkdirSync(SHOTS, { recursive: true });
  await page.screenshot({ path: join(SHOTS, file) });
}

export const near = (a, b, tol = 1e-9) =>
  Array.isArray(a) && Array.isArray(b) && a.length === b.length && a.every((v, i) => Math.abs(v - b[i]) <= tol);

// The report tool's substitution: the marker replaced by the JSON object,
// "</" written as "<\/" so no string can close the script element.
export function fillReport(template, data) {
  const parts = template.split("/*PX_VIEW_DATA*/null");
  if (parts.length !== 2) throw new Error("report template: marker not found exactly once");
  return parts[0] + JSON.stringify(data).replace(/<\//g, "<\\/") + parts[1];
}

// Replay and report: the run is loaded, the slider shows the frame at its
// time, play moves the tool, pause holds it, 4x plays four times as fast.
// frames: the run's frames when the test knows them (checked exactly).
export async function checkPlayer(t, page, label, frames) {
  let s = await state(page);
  const n = frames ? frames.length : s.replay && s.replay.frames;
  t.ok(s.replay && n > 1 && s.replay.frames === n && s.plotPoints > 1, `${label}: the whole run is loaded`,
    [s.replay, s.plotPoints]);
  const speeds = await page.$$eval("#speed option", (o) => o.map((x) => Number(x.value)));
  t.ok(speeds[0] === 0.25 && speeds[speeds.length - 1] === 4, `${label}: speeds 0.25x to 4x`, speeds);
  await page.$eval("#scrub", (el) => { el.value = "500"; el.dispatchEvent(new Event("input")); });
  s = await state(page);
  const f = s.lastFrame;
  const at = frames && frames.filter((x) => x.t_s <= s.replay.t_s).pop();
  t.ok(f && f.t_s <= s.replay.t_s && near(s.toolDrawn, f.tool) && (!at || f.cycle === at.cycle),
    `${label}: the slider shows the frame at its time`, [s.replay.t_s, f && f.t_s, at && at.t_s]);
  // From the start (a short run must not end under the test's feet).
  await page.$eval("#scrub", (el) => { el.value = "0"; el.dispatchEvent(new Event("input")); });
  s = await state(page);
  await page.selectOption("#speed", "1");
  await page.click("#play");
  t.ok(await until(page, (x) => window.pxView.replay.t_s > x + 0.1, s.replay.t_s, 3000), `${label}: play advances the time`);
  await page.click("#play");
  const s2 = await state(page);
  await page.waitForTimeout(150);
  const s3 = await state(page);
  t.ok(!s3.replay.playing && s3.replay.t_s === s2.replay.t_s && near(s3.toolDrawn, s2.toolDrawn),
    `${label}: pause holds the time and the tool`, [s2.replay, s3.replay]);
  t.ok(!near(s2.toolDrawn, s.toolDrawn, 1e-7), `${label}: play moved the tool`, [s.toolDrawn, s2.toolDrawn]);
  // 4x: the play time runs four times the clock of the animation frames
  // (the player steps by their time stamps), sampled over frames after
  // the first one of the play.
  await page.$eval("#scrub", (el) => { el.value = "0"; el.dispatchEvent(new Event("input")); });
  await page.selectOption("#speed", "4");
  const r = await page.evaluate(async () => {
    const v = window.pxView.replay;
    const frame = () => new Promise((ok) => requestAnimationFrame(ok));
    document.getElementById("play").click();
    const w = [], ts = [];
    await frame();
    for (let i = 0; i < 30 && v.playing; i++) {
      w.push(await frame());
      ts.push(v.t_s);
      if (w.length >= 3 && w[w.length - 1] - w[0] > 300) break;
    }
    if (v.playing) document.getElementById("play").click();
    const n = w.length - 1;
    return { ratio: n > 0 ? (ts[n] - ts[0]) / ((w[n] - w[0]) / 1000) : null, speed: v.speed, samples: w.length };
  });
  t.ok(r.speed === 4 && r.ratio > 3.6 && r.ratio < 4.4, `${label}: 4x plays four times as fast`, r);
  const px = await drawnShare(page);
  t.ok(px.share > 0.01, `${label}: the WebGL canvas shows the scene`, px);
}

/* Run the test's steps in order, each timed, then check that no page
 * logged an error; the browser always closes (after cleanup). Exits the
 * process with the checker's verdict. */
export async function runSteps(t, browser, steps, allErrors, cleanup = () => {}) {
  try {
    for (const f of steps) {
      const t0 = Date.now();
      await f();
      console.log(`   (${f.name}: ${Date.now() - t0} ms)`);
    }
    t.ok(allErrors.length === 0, "no console errors on any page", allErrors);
  } catch (e) {
    t.ok(false, "the browser test ran to its end", String((e && e.stack) || e));
  } finally {
    cleanup();
    await browser.close();
  }
  process.exit(t.done() ? 0 : 1);
}

export function freePort() {
  return new Promise((ok, fail) => {
    const s = createServer();
    s.once("error", fail);
    s.listen(0, "127.0.0.1", () => { const p = s.address().port; s.close(() => ok(p)); });
  });
}

// A tool of the project, its output kept for the failure report.
export function run(tool, args) {
  const p = spawn(join(BIN, tool), args, { stdio: ["ignore", "pipe", "pipe"] });
  p.out = "";
  p.stdout.on("data", (d) => { p.out += d; });
  p.stderr.on("data", (d) => { p.out += d; });
  p.done = new Promise((ok) => p.on("exit", (code, sig) => ok(code === null ? sig : code)));
  return p;
}

// Until the server answers GET / (or the process ended).
export async function served(url, proc, ms = 10000) {
  const end = Date.now() + ms;
  while (Date.now() < end && proc.exitCode === null) {
    try {
      const r = await fetch(url);
      if (r.ok) return true;
    } catch (e) { /* not listening yet */ }
    await new Promise((ok) => setTimeout(ok, 100));
  }
  return false;
}
