// The page against the real server on an arm: proxima-run --view on
// config/examples/can_avoid_urdf.yaml (the URDF arm with the simulated
// depth sensor, real clock): the robot's links drawn and moving with the
// frames, the camera's clouds applied; then proxima-view replaying that
// run's telemetry: the links from its joint positions, moved by the
// slider, and the closest link-obstacle pair drawn where the run had
// one. Run by test_view_arm.sh.
import { mkdirSync, existsSync, rmSync, readFileSync } from "node:fs";
import { join } from "node:path";
import { launch, checker, openPage, until, state, drawnShare, shot, near, runSteps, freePort, run, served,
  WEB, SHOTS } from "./harness.mjs";

const t = checker("test_view_arm");
setTimeout(() => { t.ok(false, "finished within 90 s"); t.done(); process.exit(1); }, 90000).unref();
const OUT = join(SHOTS, "arm");
rmSync(OUT, { recursive: true, force: true });
mkdirSync(OUT, { recursive: true });
const ARM_CONFIG = "config/examples/can_avoid_urdf.yaml";
const ARM_CSV = join(OUT, "telemetry-arm.csv");

const browser = await launch();
const procs = [];
const allErrors = [];

// The drawn links' positions differ between two states (by more than tol).
const linksMoved = (a, b, tol = 1e-6) => a.length === b.length && a.some((p, i) => !near(p, b[i], tol));

async function live() {
  const port = await freePort();
  const url = `http://127.0.0.1:${port}/`;
  const p = run("proxima-run", [ARM_CONFIG, "--duration-s", "60", "--view", `127.0.0.1:${port}`,
    "--view-root", WEB, "--telemetry", ARM_CSV]);
  procs.push(p);
  t.ok(await served(url, p), "arm: proxima-run --view serves the page", p.out);
  const { page, errors } = await openPage(browser, url);
  t.ok(await until(page, () => window.pxView && window.pxView.connected && window.pxView.framesReceived > 3, null, 8000),
    "arm: connects and receives frames", p.out);
  let s = await state(page);
  t.ok(s.linksDrawn === 7 && s.sceneModels === 2, "arm: scene.robot's seven links drawn, the floor and the camera's cloud",
    [s.linksDrawn, s.sceneModels]);
  t.ok(Array.isArray(s.lastFrame.links) && s.lastFrame.links.length === 7 && s.linkPositions.length === 7,
    "arm: frames carry the links' poses", s.lastFrame);
  const a = s;
  t.ok(await until(page, (x) => window.pxView.framesReceived > x + 10, a.framesReceived, 5000), "arm: frames flow");
  s = await state(page);
  t.ok(linksMoved(a.linkPositions, s.linkPositions) && near(s.linkPositions[2], s.lastFrame.links[2].slice(0, 3), 1e-6),
    "arm: the drawn links move with the frames", [a.linkPositions[2], s.linkPositions[2]]);
  t.ok(await until(page, () => window.pxView.cloudsSwapped > 0 && window.pxView.cloudPoints > 0, null, 8000),
    "arm: the depth sensor's cloud is applied", await state(page).then((x) => [x.cloudsSwapped, x.cloudPoints]));
  const px = await drawnShare(page);
  t.ok(px.share > 0.01, "arm: the WebGL canvas shows the scene", px);
  await shot(page, "arm-live.png");
  // the box comes within reach 5 to 6.5 s into the run: the replay
  // below needs that part
  t.ok(await until(page, () => window.pxView.lastFrame.t_s > 6.6, null, 15000), "arm: the run passes 6.6 s");
  p.kill("SIGINT");
  t.ok((await p.done) === 0 && existsSync(ARM_CSV), "arm: the run ends on SIGINT and writes its telemetry", p.out);
  s = await state(page);
  t.ok(s.errors.length === 0, "arm: no page errors", s.errors);
  allErrors.push(...errors);
  await page.close();
}

// The replay: the links from the CSV's joint positions.
async function replay() {
  const vport = await freePort();
  const v = run("proxima-view", ["--port", `127.0.0.1:${vport}`, "--config", ARM_CONFIG, "--web-root", WEB, ARM_CSV]);
  procs.push(v);
  t.ok(await served(`http://127.0.0.1:${vport}/`, v), "arm replay: proxima-view serves it", v.out);
  const r = await openPage(browser, `http://127.0.0.1:${vport}/`);
  t.ok(await until(r.page, () => window.pxView && window.pxView.replay && window.pxView.linksDrawn === 7, null, 8000),
    "arm replay: the run and its seven links loaded", v.out);
  await r.page.$eval("#scrub", (el) => { el.value = "100"; el.dispatchEvent(new Event("input")); });
  const b = await state(r.page);
  await r.page.$eval("#scrub", (el) => { el.value = "900"; el.dispatchEvent(new Event("input")); });
  const c = await state(r.page);
  t.ok(b.replay.t_s < c.replay.t_s && linksMoved(b.linkPositions, c.linkPositions) &&
    near(c.linkPositions[2], c.lastFrame.links[2].slice(0, 3), 1e-6), "arm replay: scrubbing moves the links",
  [b.linkPositions[2], c.linkPositions[2]]);
  // the closest link-obstacle pair where the run had one (the box in
  // reach, about 5 s into the run: before the live page connected)
  const rows = readFileSync(ARM_CSV, "utf8").trim().split("\n").map((l) => l.split(","));
  const col = rows[0].indexOf("distance_m");
  const t0 = Number(rows[1][0]), t1 = Number(rows[rows.length - 1][0]);
  const near0 = rows.slice(1).filter((x) => Number(x[col]) < 0.2).map((x) => Number(x[0]));
  t.ok(near0.length > 0, "arm replay: the run came within 0.2 m", [t0, t1]);
  const at = (near0[0] + near0[near0.length - 1]) / 2;
  await r.page.$eval("#scrub", (el, v) => { el.value = String(v); el.dispatchEvent(new Event("input")); },
    Math.round(1000 * (at - t0) / (t1 - t0)));
  const d = await state(r.page);
  t.ok(d.clearancesDrawn === 1 && Array.isArray(d.lastFrame.clearances) && d.lastFrame.clearances[0][6] < 0.25,
    "arm replay: the closest link-obstacle pair is drawn", [at, d.lastFrame]);
  await shot(r.page, "arm-replay.png");
  t.ok((await state(r.page)).errors.length === 0, "arm replay: no page errors");
  allErrors.push(...r.errors);
  await r.page.close();
  v.kill("SIGINT");
  await v.done;
}

await runSteps(t, browser, [live, replay], allErrors, () => {
  for (const p of procs) if (p.exitCode === null) p.kill("SIGKILL");
});
