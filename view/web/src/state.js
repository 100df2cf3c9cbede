// The page's state as tests read it (window.pxView). The fields are part
// of the view contract (docs/view-page.md); add fields, never rename.
export const pxView = {
  connected: false,
  mode: "live",          // "live" | "replay" | "report"
  framesReceived: 0,
  lastFrame: null,       // the frame the view shows (live: the newest received)
  toolDrawn: [0, 0, 0],  // the tool mesh's world position as drawn
  sceneModels: 0,
  plotPoints: 0,
  renders: 0,
  errors: [],
  reconnects: 0,
  ended: false,          // live: the server said the run finished
  replay: null,          // replay/report: {playing, t_s, speed, frames}
  cameraTarget: [0, 0, 0], // the point the camera orbits (follows the tool when asked)
  cloudsSwapped: 0,      // "cloud" messages applied to a model of the scene
  cloudPoints: 0,        // points of the last cloud applied
  linksDrawn: 0,         // arm links of the scene drawn (scene.robot.links)
  linkPositions: [],     // each link mesh's world position as drawn [[x,y,z],...]
  clearancesDrawn: 0,    // witness segments drawn in the last frame
};

export function reportError(what) {
  const s = String(what);
  pxView.errors.push(s);
  if (pxView.errors.length > 100) pxView.errors.shift();
}

window.pxView = pxView;
window.addEventListener("error", (e) => reportError(e.message || e));
window.addEventListener("unhandledrejection", (e) => reportError(e.reason));
