// Client-side playback of a whole run (replay and report): play/pause,
// scrub, speed 0.25x-4x. The frame shown is the last one at or before the
// play time.
import { pxView } from "./state.js";

export class Player {
  constructor(frames, show) {
    this.frames = frames.filter((f) => typeof f.t_s === "number");
    this.show = show;
    this.t0 = this.frames.length ? this.frames[0].t_s : 0;
    this.t1 = this.frames.length ? this.frames[this.frames.length - 1].t_s : 0;
    this.t = this.t0;
    this.speed = 1;
    this.playing = false;
    this.shown = -1;
    this.last = null;
    pxView.replay = { playing: false, t_s: this.t, speed: 1, frames: this.frames.length };
    this.seek(this.t0);
  }

  index(t) {
    let lo = 0, hi = this.frames.length - 1;
    if (hi < 0) return -1;
    if (t <= this.frames[0].t_s) return 0;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (this.frames[mid].t_s <= t) lo = mid; else hi = mid - 1;
    }
    return lo;
  }

  seek(t) {
    this.t = Math.min(Math.max(t, this.t0), this.t1);
    const i = this.index(this.t);
    if (i >= 0 && i !== this.shown) {
      this.shown = i;
      this.show(this.frames[i]);
    }
    pxView.replay.t_s = this.t;
  }

  fraction() {
    return this.t1 > this.t0 ? (this.t - this.t0) / (this.t1 - this.t0) : 0;
  }

  seekFraction(x) {
    this.seek(this.t0 + x * (this.t1 - this.t0));
  }

  setPlaying(on) {
    if (on && this.t >= this.t1) this.seek(this.t0);
    this.playing = on && this.frames.length > 1;
    this.last = null;
    pxView.replay.playing = this.playing;
  }

  setSpeed(s) {
    this.speed = Math.min(Math.max(s, 0.25), 4);
    pxView.replay.speed = this.speed;
  }

  // Called once per animation frame with its time stamp (ms).
  tick(nowMs) {
    if (!this.playing) return false;
    if (this.last !== null) this.seek(this.t + ((nowMs - this.last) / 1000) * this.speed);
    this.last = nowMs;
    if (this.t >= this.t1) this.setPlaying(false);
    return true;
  }
}
