// A small stand-in for the view server, speaking the view contract
// (docs/view-page.md): static files of the built page and a WebSocket on
// /ws (subprotocol proxima-view.v1) sending hello, scene, then frames at
// 30 Hz (live) or one track (replay). The page's own tests run against
// it; the end-to-end test runs the real server.
import { createServer } from "node:http";
import { readFileSync, existsSync } from "node:fs";
import { join, resolve } from "node:path";
import { createRequire } from "node:module";

export const WEB_PKG = resolve("view/web/package.json");
export const need = createRequire(WEB_PKG);
const { WebSocketServer } = need("ws");

const TYPES = { ".html": "text/html; charset=utf-8", ".js": "text/javascript", ".css": "text/css" };

// A unit box centred at c with half-size h: 8 vertices, 12 triangles.
function box(c, h) {
  const p = [];
  for (let i = 0; i < 8; i++) p.push(c[0] + (i & 1 ? h : -h), c[1] + (i & 2 ? h : -h), c[2] + (i & 4 ? h : -h));
  const idx = [0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5];
  return { positions: p, indices: idx };
}

export function fixtureScene() {
  const cloud = [];
  for (let i = 0; i < 200; i++) cloud.push(-0.08 + 0.0008 * i, 0.06, 0.01 * Math.sin(i / 10));
  return {
    type: "scene",
    models: [
      { id: 0, name: "block", kind: "mesh", pose: [0, 0, 0, 1, 0, 0, 0], ...box([0, 0, -0.02], 0.02) },
      { id: 1, name: "cloud", kind: "cloud", pose: [0, 0, 0, 1, 0, 0, 0], positions: cloud, indices: [] },
      { id: 2, name: "mover", kind: "prim", pose: [0.05, 0, 0, 1, 0, 0, 0], ...box([0, 0, 0], 0.008) },
    ],
    tool: { radius_m: 0.002 },
    robot: {
      links: [{ name: "link1", ...box([0, 0, 0.02], 0.006) }, { name: "link2", ...box([0, 0, 0.02], 0.005) }],
      protective_distance_m: 0.01, influence_distance_m: 0.03,
    },
    bounds: [-0.1, -0.1, -0.05, 0.1, 0.1, 0.08],
  };
}

// The fixture run: the tool circles above the block.
export function fixtureFrame(i, rateHz = 30) {
  const t = i / rateHz;
  const a = t * 2;
  const tool = [0.04 * Math.cos(a), 0.04 * Math.sin(a), 0.005 + 0.004 * Math.sin(3 * a)];
  const d = tool[2];
  return {
    type: "frame", t_s: t, cycle: i * 33, tool, proxy: [tool[0], tool[1], Math.max(tool[2], 0.002)],
    closest: [tool[0], tool[1], 0], distance_m: d, force_n: [0, 0, d < 0.002 ? 400 * (0.002 - d) : 0],
    penetration_m: Math.max(0, 0.002 - d), contact: d < 0.002, safe: false,
    latency_us: 10 + (i % 7), compute_us: 3 + (i % 3) * 0.5, scale: 1.0,
    models: [[2, 0.05, 0.02 * Math.sin(a), 0, 1, 0, 0, 0]],
    links: [[-0.06, 0, 0, 1, 0, 0, 0], [-0.06, 0, 0.04, Math.cos(a / 2), 0, Math.sin(a / 2), 0]],
    clearances: [[-0.06, 0, 0.04, tool[0], tool[1], tool[2], 0.005 + 0.03 * (1 + Math.cos(a)) / 2]],
  };
}

export function fixtureTrack(n = 120) {
  const frames = [];
  for (let i = 0; i < n; i++) {
    const f = fixtureFrame(i);
    delete f.type;
    frames.push(f);
  }
  return { type: "track", frames, summary: { cycles: n * 33, overruns: 0, latency_us: { p50: 10, p99: 16 } } };
}

// Starts the fixture on 127.0.0.1:port (0: any free port). mode "live"
// streams frames until close() or end(); "replay" sends one track.
export function startFixture({ root, port = 0, mode = "live", rateHz = 30 } = {}) {
  const http = createServer((req, res) => {
    const path = req.url === "/" ? "/index.html" : req.url;
    const file = join(root, path);
    if (req.method !== "GET" || !["/index.html", "/app.js", "/app.css"].includes(path) || !existsSync(file)) {
      res.writeHead(404).end("not found");
      return;
    }
    res.writeHead(200, { "Content-Type": TYPES[path.slice(path.lastIndexOf("."))] });
    res.end(readFileSync(file));
  });
  const wss = new WebSocketServer({ noServer: true, handleProtocols: (p) => (p.has("proxima-view.v1") ? "proxima-view.v1" : false) });
  const timers = new Set();
  http.on("upgrade", (req, sock, head) => {
    if (req.url !== "/ws") { sock.destroy(); return; }
    wss.handleUpgrade(req, sock, head, (ws) => {
      ws.send(JSON.stringify({ type: "hello", version: 1, mode, name: "fixture", period_ns: 1000000, rate_hz: rateHz }));
      ws.send(JSON.stringify(fixtureScene()));
      if (mode === "replay") {
        ws.send(JSON.stringify(fixtureTrack()));
        return;
      }
      let i = 0;
      const tm = setInterval(() => {
        ws.send(JSON.stringify(fixtureFrame(i++, rateHz)));
        if (i % 60 === 0) ws.send(JSON.stringify({ type: "cloud", id: 1, t_s: i / rateHz, positions: [0, 0.06, 0, 0.01, 0.06, 0] }));
      }, 1000 / rateHz);
      timers.add(tm);
      ws.on("close", () => { clearInterval(tm); timers.delete(tm); });
    });
  });
  return new Promise((ok, fail) => {
    http.once("error", fail);
    http.listen(port, "127.0.0.1", () => ok({
      port: http.address().port,
      url: `http://127.0.0.1:${http.address().port}/`,
      // The run finished: "end", then the socket closes.
      end() {
        for (const ws of wss.clients) { ws.send(JSON.stringify({ type: "end" })); ws.close(); }
      },
      close() {
        for (const tm of timers) clearInterval(tm);
        for (const ws of wss.clients) ws.terminate();
        wss.close();
        http.closeAllConnections();
        return new Promise((done) => http.close(() => done()));
      },
    }));
  });
}

// Run on its own: node tests/view/fixture.mjs [PORT] [live|replay]
if (import.meta.url === `file://${process.argv[1]}`) {
  const f = await startFixture({ root: resolve("build/view/web"), port: Number(process.argv[2] || 8765), mode: process.argv[3] || "live" });
  console.log(`fixture: ${f.url}`);
}
