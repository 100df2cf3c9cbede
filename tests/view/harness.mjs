// Shared parts of the browser tests: Debian's chromium driven by
// playwright-core (from view/web/node_modules), checks counted and
// printed in the suite's format ("name: N passed, N failed, N skipped"),
// screenshots kept in build/tests/view/.
import { mkdirSync } from "node:fs";
import { join, resolve } from "node:path";
import { need } from "./fixture.mjs";

const { chromium } = need("playwright-core");
export const CHROMIUM = process.env.PX_CHROMIUM || "/usr/bin/chromium";
export const SHOTS = resolve(process.env.BUILD || "build", "tests/view");
export const WEB = resolve(process.env.BUILD || "build", "view/web");

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
  page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
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
