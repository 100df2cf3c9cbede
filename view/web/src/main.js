// The proxima view page. Live: frames from the server's WebSocket
// (mode "live"), or a whole run sent once (mode "replay"). Report: the
// run inlined in the page as PX_VIEW_DATA (mode "report"), no socket.
import { pxView, reportError } from "./state.js";
import { View } from "./scene.js";
import { Plots } from "./plots.js";
import { Player } from "./player.js";
import { connect } from "./link.js";
import { showSummary } from "./summary.js";

const $ = (id) => document.getElementById(id);
const view = new View($("view"));
const plots = new Plots($("plots"));
let player = null;
let paused = false;

const fmt = (v, k, unit) => (typeof v === "number" ? (v * k).toFixed(2) + " " + unit : "–");

function showFrame(f) {
  pxView.lastFrame = f;
  view.setFrame(f);
  $("contact").classList.toggle("active", !!f.contact);
  $("safe").classList.toggle("active", !!f.safe);
  const fn = Array.isArray(f.force_n) ? Math.hypot(f.force_n[0], f.force_n[1], f.force_n[2]) : null;
  $("readout").textContent = `t ${fmt(f.t_s, 1, "s")}  d ${fmt(f.distance_m, 1e3, "mm")}  |F| ${fmt(fn, 1, "N")}` +
    (typeof f.scale === "number" && f.scale < 1 ? `  speed ×${f.scale.toFixed(2)}` : "");
  if (player) {
    $("time").textContent = f.t_s.toFixed(3) + " s";
    plots.setCursor(f.t_s);
  }
}

function setConn(state) {
  const el = $("conn");
  el.className = "state " + state;
  el.textContent = { on: "connected", off: "disconnected, retrying", ended: "run ended" }[state] || state;
  if (state === "on") pxView.ended = false;
}

function startPlayer(track) {
  const frames = (track && track.frames) || [];
  plots.setAll(frames);
  player = new Player(frames, showFrame);
  $("replay").hidden = false;
  $("pause").hidden = true;
  showSummary(track && track.summary);
  syncScrub();
}

function syncScrub() {
  if (player) $("scrub").value = String(Math.round(player.fraction() * 1000));
  $("play").textContent = player && player.playing ? "Pause" : "Play";
}

function onMessage(msg) {
  switch (msg.type) {
  case "hello":
    pxView.mode = msg.mode === "replay" ? "replay" : "live";
    document.title = "proxima view" + (msg.name ? " – " + msg.name : "");
    $("title").textContent = "proxima view" + (msg.name ? ": " + msg.name : "");
    break;
  case "scene":
    // A new connection may be a new run: start again from its scene.
    view.setScene(msg);
    plots.clear();
    player = null;
    $("replay").hidden = true;
    $("pause").hidden = false;
    break;
  case "frame":
    pxView.framesReceived++;
    plots.push(msg);
    if (!paused) showFrame(msg);
    break;
  case "cloud":
    view.setCloud(msg.id, msg.positions);
    break;
  case "track":
    startPlayer(msg);
    break;
  case "end":
    pxView.ended = true;
    setConn("ended");
    break;
  default:
    break; // unknown messages are for later versions
  }
}

$("follow").addEventListener("change", (e) => { view.follow = e.target.checked; });
$("reset").addEventListener("click", () => view.resetCamera());
$("pause").addEventListener("click", () => {
  paused = !paused;
  $("pause").textContent = paused ? "Resume" : "Pause";
});
$("play").addEventListener("click", () => {
  if (player) player.setPlaying(!player.playing);
  syncScrub();
});
$("scrub").addEventListener("input", (e) => {
  if (player) player.seekFraction(Number(e.target.value) / 1000);
});
$("speed").addEventListener("change", (e) => {
  if (player) player.setSpeed(Number(e.target.value));
});

function loop(now) {
  try {
    if (player && player.tick(now)) syncScrub();
    plots.draw();
    view.render();
  } catch (e) {
    reportError(e && e.stack ? e.stack : e);
  }
  requestAnimationFrame(loop);
}
requestAnimationFrame(loop);

const data = window.PX_VIEW_DATA;
if (data && typeof data === "object") {
  pxView.mode = "report";
  $("conn").className = "state";
  $("conn").textContent = "report";
  if (data.scene) view.setScene(data.scene);
  startPlayer(data.track);
} else {
  const proto = location.protocol === "https:" ? "wss:" : "ws:";
  connect(`${proto}//${location.host}/ws`, onMessage, setConn);
}
