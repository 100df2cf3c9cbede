// The WebSocket to the server: read-only, one JSON object per text frame.
// Reconnects every second after the socket closes, so a restarted run is
// picked up without reloading the page.
import { pxView } from "./state.js";

const RETRY_MS = 1000;

export function connect(url, onMessage, onState) {
  let opened = 0;
  let ws = null;
  function open() {
    try {
      ws = new WebSocket(url, "proxima-view.v1");
    } catch (e) {
      setTimeout(open, RETRY_MS);
      return;
    }
    ws.onopen = () => {
      if (opened++ > 0) pxView.reconnects++;
      pxView.connected = true;
      onState("on");
    };
    ws.onmessage = (ev) => {
      if (typeof ev.data !== "string") return;
      let msg;
      try {
        msg = JSON.parse(ev.data);
      } catch (e) {
        return; // a message that is not JSON is not ours: ignore it
      }
      onMessage(msg);
    };
    ws.onclose = () => {
      pxView.connected = false;
      onState(pxView.ended ? "ended" : "off");
      setTimeout(open, RETRY_MS);
    };
    // An error is always followed by close, which retries.
    ws.onerror = () => {};
  }
  open();
}
