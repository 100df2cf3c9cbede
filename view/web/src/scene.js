// The 3D view: the scene's models as sent once per connection, and the
// per-frame state (tool, proxy, closest point, force, arm links,
// clearances, moving models, swapped clouds). World frame, metres, z up.
import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { pxView } from "./state.js";

const COLORS = {
  model: 0x7d8ea3, cloud: 0x9ecbff, link: 0xb0a27a, tool: 0x4fc3f7, toolContact: 0xffb300,
  toolSafe: 0xf44336, proxy: 0xe0e0e0, closest: 0xff4081, segment: 0xff4081, force: 0x76ff03,
};

function setPose(obj, p) {
  // [x,y,z,qw,qx,qy,qz]
  obj.position.set(p[0], p[1], p[2]);
  obj.quaternion.set(p[4], p[5], p[6], p[3]).normalize();
}

function triGeometry(positions, indices) {
  const g = new THREE.BufferGeometry();
  g.setAttribute("position", new THREE.Float32BufferAttribute(positions || [], 3));
  if (indices && indices.length) g.setIndex(new THREE.BufferAttribute(Uint32Array.from(indices), 1));
  g.computeVertexNormals();
  g.computeBoundingSphere();
  return g;
}

export class View {
  constructor(container) {
    this.container = container;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.setClearColor(0x101318);
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.001, 100);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableDamping = false;
    this.controls.addEventListener("change", () => { this.dirty = true; });
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x303840, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.6);
    sun.position.set(1, -1.5, 2);
    this.scene.add(sun);
    this.world = new THREE.Group();     // models, links: rebuilt per scene
    this.scene.add(this.world);
    this.follow = false;
    this.dirty = true;
    this.models = new Map();            // id -> Object3D
    this.links = [];
    this.robot = null;
    this.size = 0.1;
    this.makeMarkers(0.002);
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  makeMarkers(radius) {
    const sphere = new THREE.SphereGeometry(1, 24, 16);
    this.toolMat = new THREE.MeshStandardMaterial({ color: COLORS.tool, emissive: 0x0b3040 });
    this.tool = new THREE.Mesh(sphere, this.toolMat);
    this.proxy = new THREE.Mesh(sphere, new THREE.MeshBasicMaterial({ color: COLORS.proxy, wireframe: true }));
    this.closest = new THREE.Mesh(sphere, new THREE.MeshBasicMaterial({ color: COLORS.closest }));
    const segGeo = new THREE.BufferGeometry();
    segGeo.setAttribute("position", new THREE.Float32BufferAttribute(new Float32Array(6), 3));
    this.segment = new THREE.Line(segGeo, new THREE.LineBasicMaterial({ color: COLORS.segment }));
    this.segment.frustumCulled = false;
    this.force = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 0.01, COLORS.force);
    this.clearGeo = new THREE.BufferGeometry();
    this.clearCap = 0;
    this.clearances = new THREE.LineSegments(this.clearGeo, new THREE.LineBasicMaterial({ vertexColors: true }));
    this.clearances.frustumCulled = false;
    for (const o of [this.tool, this.proxy, this.closest, this.segment, this.force, this.clearances]) {
      o.visible = false;
      this.scene.add(o);
    }
    this.setMarkerRadius(radius);
  }

  setMarkerRadius(radius) {
    // The tool is drawn at its radius, never smaller than a visible dot.
    const r = Math.max(radius, this.size * 0.01);
    this.tool.scale.setScalar(r);
    this.proxy.scale.setScalar(r * 1.15);
    this.closest.scale.setScalar(r * 0.6);
  }

  resize() {
    const w = Math.max(1, this.container.clientWidth);
    const h = Math.max(1, this.container.clientHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }

  clear() {
    for (const o of [...this.world.children]) {
      this.world.remove(o);
      o.traverse((c) => {
        if (c.geometry) c.geometry.dispose();
        if (c.material) c.material.dispose();
      });
    }
    this.models.clear();
    this.links = [];
    this.robot = null;
    pxView.sceneModels = 0;
    pxView.linksDrawn = 0;
    pxView.linkPositions = [];
  }

  setScene(scene) {
    this.clear();
    for (const m of scene.models || []) {
      let obj;
      if (m.kind === "cloud") {
        const g = new THREE.BufferGeometry();
        g.setAttribute("position", new THREE.Float32BufferAttribute(m.positions || [], 3));
        obj = new THREE.Points(g, new THREE.PointsMaterial({ color: COLORS.cloud, size: 3, sizeAttenuation: false }));
      } else {
        obj = new THREE.Mesh(triGeometry(m.positions, m.indices), new THREE.MeshStandardMaterial({
          color: COLORS.model, roughness: 0.75, metalness: 0.05, side: THREE.DoubleSide,
          transparent: true, opacity: 0.7, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
        }));
      }
      obj.name = m.name || "model " + m.id;
      if (m.pose) setPose(obj, m.pose);
      this.models.set(m.id, obj);
      this.world.add(obj);
    }
    pxView.sceneModels = this.models.size;
    this.robot = scene.robot || null;
    if (this.robot) {
      for (const l of this.robot.links || []) {
        const obj = new THREE.Mesh(triGeometry(l.positions, l.indices), new THREE.MeshStandardMaterial({
          color: COLORS.link, roughness: 0.6, metalness: 0.2 }));
        obj.name = l.name || "link";
        this.links.push(obj);
        this.world.add(obj);
      }
    }
    pxView.linksDrawn = this.links.length;
    this.fitBounds(scene.bounds);
    this.setMarkerRadius((scene.tool && scene.tool.radius_m) || 0);
    this.dirty = true;
  }

  fitBounds(b) {
    const box = new THREE.Box3();
    if (Array.isArray(b) && b.length === 6 && b[3] >= b[0]) {
      box.set(new THREE.Vector3(b[0], b[1], b[2]), new THREE.Vector3(b[3], b[4], b[5]));
    } else {
      box.setFromObject(this.world);
    }
    if (box.isEmpty()) box.set(new THREE.Vector3(-0.1, -0.1, -0.1), new THREE.Vector3(0.1, 0.1, 0.1));
    const c = box.getCenter(new THREE.Vector3());
    this.size = Math.max(box.getSize(new THREE.Vector3()).length(), 1e-3);
    this.home = { target: c.clone(), eye: c.clone().add(new THREE.Vector3(0.9, -1.3, 0.8).multiplyScalar(this.size * 0.55)) };
    this.camera.near = this.size * 1e-3;
    this.camera.far = this.size * 50;
    if (this.grid) this.scene.remove(this.grid);
    const step = Math.pow(10, Math.floor(Math.log10(this.size / 2)));
    const n = Math.max(2, Math.ceil(this.size / step));
    this.grid = new THREE.GridHelper(n * step, n, 0x39414c, 0x262c34);
    this.grid.rotation.x = Math.PI / 2;
    this.grid.position.set(c.x, c.y, box.min.z);
    this.scene.add(this.grid);
    this.resetCamera();
  }

  resetCamera() {
    if (!this.home) return;
    this.controls.target.copy(this.home.target);
    this.camera.position.copy(this.home.eye);
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.dirty = true;
  }

  noteTarget() {
    const c = this.controls.target;
    pxView.cameraTarget = [c.x, c.y, c.z];
  }

  // One frame of telemetry (a "frame" message or a track entry).
  setFrame(f) {
    const t = f.tool;
    if (Array.isArray(t)) {
      const before = this.tool.position.clone();
      this.tool.position.set(t[0], t[1], t[2]);
      this.tool.visible = true;
      pxView.toolDrawn = [t[0], t[1], t[2]];
      if (this.follow) {
        const d = this.tool.position.clone().sub(before);
        this.controls.target.add(d);
        this.camera.position.add(d);
        this.controls.update();
        this.noteTarget();
      }
    }
    this.toolMat.color.setHex(f.safe ? COLORS.toolSafe : f.contact ? COLORS.toolContact : COLORS.tool);
    if (Array.isArray(f.proxy)) {
      this.proxy.position.set(f.proxy[0], f.proxy[1], f.proxy[2]);
      this.proxy.visible = true;
    } else this.proxy.visible = false;
    const c = f.closest;
    if (Array.isArray(c) && Array.isArray(t)) {
      this.closest.position.set(c[0], c[1], c[2]);
      const p = this.segment.geometry.attributes.position;
      p.setXYZ(0, t[0], t[1], t[2]);
      p.setXYZ(1, c[0], c[1], c[2]);
      p.needsUpdate = true;
      this.closest.visible = this.segment.visible = true;
    } else this.closest.visible = this.segment.visible = false;
    this.setForce(f.force_n, f.proxy || t);
    if (Array.isArray(f.models)) {
      for (const m of f.models) {
        const obj = this.models.get(m[0]);
        if (obj) setPose(obj, m.slice(1));
      }
    }
    if (Array.isArray(f.links)) {
      f.links.forEach((p, i) => { if (this.links[i]) setPose(this.links[i], p); });
      pxView.linkPositions = this.links.map((o) => [o.position.x, o.position.y, o.position.z]);
    }
    this.setClearances(f.clearances);
    this.dirty = true;
  }

  setForce(fv, at) {
    if (!Array.isArray(fv) || !Array.isArray(at)) {
      this.force.visible = false;
      return;
    }
    const v = new THREE.Vector3(fv[0], fv[1], fv[2]);
    const n = v.length();
    if (!(n > 1e-6)) {
      this.force.visible = false;
      return;
    }
    // 1 N is 2% of the scene; long forces are drawn no longer than 25%.
    const len = Math.min(n * this.size * 0.02, this.size * 0.25);
    this.force.position.set(at[0], at[1], at[2]);
    this.force.setDirection(v.divideScalar(n));
    this.force.setLength(len, len * 0.2, len * 0.1);
    this.force.visible = true;
  }

  setClearances(list) {
    if (!Array.isArray(list) || list.length === 0) {
      this.clearances.visible = false;
      pxView.clearancesDrawn = 0;
      return;
    }
    if (list.length > this.clearCap) {
      this.clearCap = Math.max(list.length, 2 * this.clearCap, 16);
      this.clearGeo.setAttribute("position", new THREE.BufferAttribute(new Float32Array(this.clearCap * 6), 3));
      this.clearGeo.setAttribute("color", new THREE.BufferAttribute(new Float32Array(this.clearCap * 6), 3));
    }
    const pos = this.clearGeo.attributes.position;
    const col = this.clearGeo.attributes.color;
    const prot = (this.robot && this.robot.protective_distance_m) || 0;
    const infl = (this.robot && this.robot.influence_distance_m) || prot;
    const color = new THREE.Color();
    list.forEach((s, i) => {
      pos.setXYZ(2 * i, s[0], s[1], s[2]);
      pos.setXYZ(2 * i + 1, s[3], s[4], s[5]);
      const d = s[6];
      // Red inside the protective distance, amber inside the influence distance.
      color.setHex(d <= prot ? 0xf44336 : d <= infl ? 0xffb300 : 0x4caf50);
      col.setXYZ(2 * i, color.r, color.g, color.b);
      col.setXYZ(2 * i + 1, color.r, color.g, color.b);
    });
    pos.needsUpdate = col.needsUpdate = true;
    this.clearGeo.setDrawRange(0, list.length * 2);
    this.clearances.visible = true;
    pxView.clearancesDrawn = list.length;
  }

  // A swapped point cloud replaces the model's points.
  setCloud(id, positions) {
    const obj = this.models.get(id);
    if (!obj || !obj.isPoints) return;
    obj.geometry.dispose();
    obj.geometry = new THREE.BufferGeometry();
    obj.geometry.setAttribute("position", new THREE.Float32BufferAttribute(positions || [], 3));
    pxView.cloudsSwapped++;
    pxView.cloudPoints = obj.geometry.attributes.position.count;
    this.dirty = true;
  }

  render() {
    if (!this.dirty) return;
    this.dirty = false;
    this.noteTarget();
    this.renderer.render(this.scene, this.camera);
    pxView.renders++;
  }
}
