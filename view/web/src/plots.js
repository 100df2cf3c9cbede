// The live plots beside the view: distance, force, penetration, latency
// and compute time against the run's time. Live frames are appended to a
// bounded window and drawn at screen rate (once per animation frame, not
// per message); replay and report plot the whole run with a cursor.
import uPlot from "uplot";
import { pxView } from "./state.js";

const WINDOW = 900;        // samples kept live: 30 s at 30 Hz
const REPLAY_MAX = 4000;   // samples plotted of a whole run
const PLOT_H = 104;        // five plots fit beside a 600 px view

const mag = (v) => (Array.isArray(v) ? Math.hypot(v[0], v[1], v[2]) : null);
const num = (v) => (typeof v === "number" && isFinite(v) ? v : null);

const SERIES = [
  { title: "distance", unit: "mm", color: "#4fc3f7", get: (f) => (num(f.distance_m) === null ? null : f.distance_m * 1e3) },
  { title: "force", unit: "N", color: "#76ff03", get: (f) => mag(f.force_n) },
  { title: "penetration", unit: "mm", color: "#ff4081", get: (f) => (num(f.penetration_m) === null ? null : f.penetration_m * 1e3) },
  { title: "latency", unit: "µs", color: "#ffb300", get: (f) => num(f.latency_us) },
  { title: "compute time", unit: "µs", color: "#b388ff", get: (f) => num(f.compute_us) },
];

// Draws a vertical line at the replay time.
function cursorPlugin(plots) {
  return {
    hooks: {
      draw: (u) => {
        if (plots.cursorT === null) return;
        const x = u.valToPos(plots.cursorT, "x", true);
        const ctx = u.ctx;
        ctx.save();
        ctx.strokeStyle = "#e0e0e0";
        ctx.lineWidth = 1;
        ctx.beginPath();
        ctx.moveTo(x, u.bbox.top);
        ctx.lineTo(x, u.bbox.top + u.bbox.height);
        ctx.stroke();
        ctx.restore();
      },
    },
  };
}

export class Plots {
  constructor(container) {
    this.container = container;
    this.t = [];
    this.y = SERIES.map(() => []);
    this.cursorT = null;
    this.dirty = false;
    this.charts = SERIES.map((s) => new uPlot({
      title: `${s.title} (${s.unit})`,
      width: this.width(),
      height: PLOT_H,
      legend: { show: false },
      cursor: { drag: { x: false, y: false } },
      scales: { x: { time: false } },
      axes: [
        { stroke: "#8a94a3", grid: { stroke: "#2b313a" }, ticks: { stroke: "#2b313a" } },
        { stroke: "#8a94a3", grid: { stroke: "#2b313a" }, ticks: { stroke: "#2b313a" }, size: 56 },
      ],
      series: [{ label: "t (s)" }, { label: s.title, stroke: s.color, width: 1.5, spanGaps: false }],
      plugins: [cursorPlugin(this)],
    }, [[], []], container));
    new ResizeObserver(() => {
      const w = this.width();
      for (const c of this.charts) c.setSize({ width: w, height: PLOT_H });
    }).observe(container);
  }

  width() {
    return Math.max(200, this.container.clientWidth - 12);
  }

  clear() {
    this.t = [];
    this.y = SERIES.map(() => []);
    this.cursorT = null;
    this.dirty = true;
    pxView.plotPoints = 0;
  }

  // Live: one frame appended; the oldest dropped past the window.
  push(f) {
    if (typeof f.t_s !== "number") return;
    this.t.push(f.t_s);
    SERIES.forEach((s, i) => this.y[i].push(s.get(f)));
    if (this.t.length > WINDOW) {
      const drop = this.t.length - WINDOW;
      this.t.splice(0, drop);
      for (const a of this.y) a.splice(0, drop);
    }
    pxView.plotPoints = this.t.length;
    this.dirty = true;
  }

  // Replay: the whole run, thinned to at most REPLAY_MAX samples.
  setAll(frames) {
    this.clear();
    const step = Math.max(1, Math.ceil(frames.length / REPLAY_MAX));
    for (let i = 0; i < frames.length; i += step) {
      const f = frames[i];
      if (typeof f.t_s !== "number") continue;
      this.t.push(f.t_s);
      SERIES.forEach((s, k) => this.y[k].push(s.get(f)));
    }
    pxView.plotPoints = this.t.length;
  }

  setCursor(t) {
    this.cursorT = t;
    for (const c of this.charts) c.redraw(false, false);
  }

  // Called once per animation frame.
  draw() {
    if (!this.dirty) return;
    this.dirty = false;
    this.charts.forEach((c, i) => c.setData([this.t, this.y[i]]));
  }
}
