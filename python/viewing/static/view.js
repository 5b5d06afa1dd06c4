// The live view's page: one websocket to the server (python/view.py), which
// runs this page's FMU instance. Once per instance it sends the grid (JSON)
// and the rest shape x* with the modeShapes Phi (float32); each frame q and
// each holder's placement (R, t), and this page draws node i at
// R_h (x*_i + Phi_i q) + t_h (h its holder, holder 1 for free nodes): the
// positions the FMU reports (python/viewing/page.py). A run that does not
// expand so sends positions. Controls go back as JSON (viewing/protocol.py).
import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";
import { TransformControls } from "three/addons/controls/TransformControls.js";
import { CSS2DObject, CSS2DRenderer } from "three/addons/renderers/CSS2DRenderer.js";
import GUI from "lil-gui";

const SHAPES = 0, MODAL = 1, POSITIONS = 2;
const LINE_NODES = 2500, GALLERY = 6;
const CLASSES = ["in-plane", "out-of-plane", "symmetric", "antisymmetric"];
const COLOURS = { springs: 0x3c78c8, nodes: 0x14285a, held: 0xdc2828, load: 0xf09614, sheet: 0x5aa0e6, ghost: 0x969696 };

// What tests and measurements read: counts, the positions drawn, helpers.
// expanding, drawing: ms spent in this script on new frames, and in all of draw() with three.js's render calls.
const view = (window.view = { received: 0, drawn: 0, frame: -1, positions: null, ghosts: 0, expanding: 0, drawing: 0 });

// ?antialias=1: multisampled (smoother lines; software WebGL draws half as fast or less).
const query = new URLSearchParams(location.search);
const renderer = new THREE.WebGLRenderer({ antialias: query.get("antialias") === "1" });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
document.body.appendChild(renderer.domElement);
const labels = new CSS2DRenderer();
labels.setSize(window.innerWidth, window.innerHeight);
Object.assign(labels.domElement.style, { position: "absolute", top: "0", pointerEvents: "none" });
document.body.appendChild(labels.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xffffff);
scene.add(new THREE.HemisphereLight(0xffffff, 0x666666, 2.5));
const camera = new THREE.PerspectiveCamera(50, window.innerWidth / window.innerHeight, 0.001, 1000);
const orbit = new OrbitControls(camera, renderer.domElement);
window.addEventListener("resize", () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
  labels.setSize(window.innerWidth, window.innerHeight);
});

const socket = new WebSocket(`ws://${location.host}/ws`);
socket.binaryType = "arraybuffer";
const send = (message) => socket.readyState === 1 && socket.send(JSON.stringify(message));
view.send = send;

let inst = null, rest = null, shapes = null, x = null, latest = null;
let drawn = null, handles = [], loadHandle = null, pulling = false, dirtyHolders = new Set();
let gui = null, ui = {}, gallery = [], extent = 1, lastReadouts = null, notes = [];

socket.onmessage = (event) => {
  view.received++;
  if (typeof event.data === "string") onJson(JSON.parse(event.data));
  else onBinary(event.data);
};
socket.onclose = () => note("the server closed the connection");

function onBinary(buffer) {
  const [kind, frame] = new Uint32Array(buffer, 0, 2);
  const data = new Float32Array(buffer, 8);
  if (kind === SHAPES) {
    const n3 = 3 * inst.nodes;
    rest = data.slice(0, n3);
    shapes = data.slice(n3);
    build();
  } else if (inst && data.length === (kind === MODAL ? inst.modes + 12 * inst.pivots.length : 3 * inst.nodes)) {
    latest = { kind, frame, data };
  }
}

function onJson(m) {
  if (m.type === "instance") inst = m;
  else if (m.type === "controls") showControls(m);
  else if (m.type === "readouts") { lastReadouts = m; showReadouts(); }
  else if (m.type === "refused") note("refused: " + m.why);
  else if (m.type === "note") note(m.text);
}

function note(text) {
  notes.push(text);
  notes = notes.slice(-5);
  showReadouts();
}

// ---- the expansion -----------------------------------------------------

function expand({ kind, data }) {
  const n = inst.nodes, r = inst.modes;
  if (kind === POSITIONS) {
    for (let i = 0; i < 3 * n; i++) x[i] = data[i];
    return;
  }
  for (let i = 0; i < 3 * n; i++) x[i] = rest[i];
  for (let m = 0; m < r; m++) {
    const q = data[m];
    if (q === 0) continue;
    const phi = shapes.subarray(3 * n * m, 3 * n * (m + 1));
    for (let i = 0; i < 3 * n; i++) x[i] += phi[i] * q;
  }
  const holderOf = inst.holderOf;
  for (let i = 0; i < n; i++) {
    const p = r + 12 * holderOf[i], a = x[3 * i], b = x[3 * i + 1], c = x[3 * i + 2];
    x[3 * i] = data[p] * a + data[p + 1] * b + data[p + 2] * c + data[p + 9];
    x[3 * i + 1] = data[p + 3] * a + data[p + 4] * b + data[p + 5] * c + data[p + 10];
    x[3 * i + 2] = data[p + 6] * a + data[p + 7] * b + data[p + 8] * c + data[p + 11];
  }
}

// ---- the scene ---------------------------------------------------------

function clear() {
  for (const h of [...handles, loadHandle]) if (h) { scene.remove(h.getHelper()); scene.remove(h.object); h.dispose(); }
  if (drawn) for (const o of drawn.objects) { scene.remove(o); o.geometry.dispose(); }
  showGallery(0);
  handles = []; loadHandle = null; drawn = null;
}

function points(attribute, index, colour, size) {
  const g = new THREE.BufferGeometry();
  g.setAttribute("position", attribute);
  if (index) g.setIndex(index);
  return new THREE.Points(g, new THREE.PointsMaterial({ color: colour, size, sizeAttenuation: false }));
}

function surface(positions) {
  const { nx, ny } = inst, cells = [];
  for (let i = 0; i < ny - 1; i++) for (let j = 0; j < nx - 1; j++) { const a = i * nx + j; cells.push(a, a + 1, a + nx, a + 1, a + nx + 1, a + nx); }
  const g = new THREE.BufferGeometry();
  g.setAttribute("position", positions);
  g.setIndex(cells);
  return g;
}

function build() {
  clear();
  const n = inst.nodes;
  x = new Float64Array(rest);
  const attribute = new THREE.BufferAttribute(new Float32Array(rest), 3);
  attribute.setUsage(THREE.DynamicDrawUsage);
  const objects = [];
  const big = n > LINE_NODES;
  if (big) {
    // Flat shading: each cell's normal from the screen-space derivatives of its
    // position in the fragment shader, so no per-frame vertex normals in the script.
    objects.push(new THREE.Mesh(surface(attribute), new THREE.MeshLambertMaterial({ color: COLOURS.sheet, side: THREE.DoubleSide, flatShading: true })));
  } else {
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", attribute);
    g.setIndex(inst.springs.flat());
    objects.push(new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: COLOURS.springs })));
    objects.push(points(attribute, null, COLOURS.nodes, 5));
  }
  objects.push(points(attribute, inst.holders.flat(), COLOURS.held, big ? 6 : 10));
  objects.push(points(attribute, [inst.loadNode], COLOURS.load, big ? 8 : 12));
  for (const o of objects) scene.add(o);
  drawn = { attribute, objects, big };
  // The camera on the sheet: square on for a 2D sheet, from the front and above one side for 3D.
  const box = new THREE.Box3().setFromBufferAttribute(attribute);
  const center = box.getCenter(new THREE.Vector3());
  extent = Math.max(...box.getSize(new THREE.Vector3()).toArray()) || 1;
  const from = inst.dim === 2 ? new THREE.Vector3(0, 0, 2.2) : new THREE.Vector3(1.1, 0.5, 1.6);
  camera.position.copy(center).addScaledVector(from, extent);
  orbit.target.copy(center);
  orbit.enableRotate = inst.dim === 3;
  orbit.update();
  inst.pivots.forEach((pivot, k) => {
    const anchor = new THREE.Object3D();
    anchor.position.fromArray(pivot);
    handles.push(handle(anchor, 1.0, () => dirtyHolders.add(k)));
  });
  loadHandle = handle(new THREE.Object3D(), 0.6, () => pulling && send({ type: "pull", position: loadHandle.object.position.toArray() }));
  loadHandle.object.position.fromArray(rest, 3 * inst.loadNode);
  loadHandle.addEventListener("dragging-changed", (e) => {
    pulling = e.value;
    if (!pulling) send({ type: "pull", position: null });
  });
  buildControls();
}

function handle(object, size, moved) {
  scene.add(object);
  const control = new TransformControls(camera, renderer.domElement);
  control.attach(object);
  control.size = size;
  control.showZ = inst.dim === 3;
  control.addEventListener("dragging-changed", (e) => (orbit.enabled = !e.value));
  control.addEventListener("objectChange", moved);
  scene.add(control.getHelper());
  return control;
}

function draw() {
  const begin = performance.now();
  if (latest && drawn) {
    expand(latest);
    view.frame = latest.frame;
    latest = null;
    drawn.attribute.array.set(x);
    drawn.attribute.needsUpdate = true;
    if (!pulling) loadHandle.object.position.fromArray(x, 3 * inst.loadNode);
    view.positions = x;
  }
  view.expanding += performance.now() - begin;
  for (const k of dirtyHolders) {
    const o = handles[k].object;
    send({ type: "holder", holder: k, position: o.position.toArray(), quaternion: o.quaternion.toArray() });
  }
  dirtyHolders.clear();
  renderer.render(scene, camera);
  labels.render(scene, camera);
  view.drawing += performance.now() - begin;
  view.drawn++;
  requestAnimationFrame(draw);
}
requestAnimationFrame(draw);

// ---- the mode gallery (drawn here from modeShapes) ---------------------

function showGallery(first) {
  for (const o of gallery) { scene.remove(o); if (o.geometry) o.geometry.dispose(); if (o.element) o.element.remove(); }
  gallery = [];
  view.ghosts = 0;
  if (!inst || first < 1 || first > inst.modes) return;
  const n = inst.nodes, center = new THREE.Box3().setFromArray(rest).getCenter(new THREE.Vector3());
  for (let k = 0, j = first; k < GALLERY && j <= inst.modes; k++, j++) {
    const phi = shapes.subarray(3 * n * (j - 1), 3 * n * j);
    let most = 0;
    for (const v of phi) most = Math.max(most, Math.abs(v));
    const scale = (0.2 * extent) / (most || 1);
    // Left of the sheet (the controls are on the right), three to a row.
    const at = center.clone().add(new THREE.Vector3(-(2.25 - 0.62 * (k % 3)) * extent, 0.25 * extent - 0.65 * extent * Math.floor(k / 3), 0));
    const xs = new Float32Array(3 * n);
    for (let i = 0; i < 3 * n; i++) xs[i] = 0.45 * (rest[i] + scale * phi[i] - center.getComponent(i % 3)) + at.getComponent(i % 3);
    const attribute = new THREE.BufferAttribute(xs, 3);
    let ghost;
    if (drawn.big) ghost = new THREE.Mesh(surface(attribute), new THREE.MeshBasicMaterial({ color: COLOURS.ghost, side: THREE.DoubleSide, wireframe: true }));
    else {
      const g = new THREE.BufferGeometry();
      g.setAttribute("position", attribute);
      g.setIndex(inst.springs.flat());
      ghost = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: COLOURS.ghost }));
    }
    const div = document.createElement("div");
    div.className = "mode-label";
    div.textContent = `mode ${j}: ${inst.frequencies[j - 1].toFixed(2)} Hz`;
    const label = new CSS2DObject(div);
    label.position.copy(at).add(new THREE.Vector3(0, 0.28 * extent, 0));
    for (const o of [ghost, label]) { scene.add(o); gallery.push(o); }
    view.ghosts++;
  }
}

// ---- the controls --------------------------------------------------------

function buildControls() {
  if (gui) gui.destroy();
  gui = new GUI({ title: "Modal mass-spring sheet", width: 300 });
  const values = { pause: () => send({ type: "play", playing: !values.playing }), reset: () => send({ type: "reset" }), scene: inst.scene, handle: "move" };
  values.playing = inst.playing;
  const run = gui.addFolder("Run");
  ui.play = run.add(values, "pause").name(inst.playing ? "Pause" : "Play");
  run.add(values, "reset").name("Reset");
  run.add(values, "scene", inst.scenes).name("Scene").onChange((name) => send({ type: "scene", name }));
  if (inst.dim === 3) run.add(values, "handle", ["move", "turn"]).name("holder handle").onChange((m) => handles.forEach((h) => h.setMode(m === "move" ? "translate" : "rotate")));
  const g = gui.addFolder("Gravity and damping");
  const gravity = () => send({ type: "gravity", ...values.gravity });
  values.gravity = { ...inst.gravity };
  g.add(values.gravity, "size", 0, 30, 0.01).name("|g| [m/s²]").onChange(gravity);
  g.add(values.gravity, "turn", -180, 180, 1).name("turned in plane [°]").onChange(gravity);
  g.add(values.gravity, "out", -90, 90, 1).name("out of plane [°]").onChange(gravity).disable(inst.dim === 2);
  values.damping = { ...inst.damping };
  const damping = () => send({ type: "damping", ...values.damping });
  g.add(values.damping, "alpha", 0, 5, 0.01).name("damping α [1/s]").onChange(damping);
  g.add(values.damping, "beta", 0, 0.01, 0.0001).name("damping β [s]").onChange(damping);
  const w = gui.addFolder("Mode weights");
  if (!inst.takesWeights) w.add({ note: "a modal run only" }, "note").name("weights act on").disable();
  values.classes = Object.fromEntries(CLASSES.map((c) => [c, 1]));
  for (const c of CLASSES) {
    w.add(values.classes, c, 0, 2, 0.01).name(`${c} (${inst.classes[c]})`).disable(!inst.takesWeights || inst.classes[c] === 0)
      .onChange((value) => send({ type: "classWeight", class: c, value }));
  }
  values.modes = inst.weights.slice(0, inst.modeSliders);
  for (let j = 0; j < inst.modeSliders; j++) {
    w.add(values.modes, j, 0, 2, 0.01).name(`mode ${j + 1}: ${inst.frequencies[j].toFixed(2)} Hz`)
      .onChange((value) => send({ type: "modeWeight", mode: j, value }));
  }
  if (inst.modeSliders > 6) w.close();
  const gal = gui.addFolder("Mode gallery");
  values.gallery = 0;
  gal.add(values, "gallery", 0, inst.modes, 1).name(`from mode (0: none; ${GALLERY} shown)`).onChange((v) => showGallery(v));
  ui.values = values;
}

function showControls(m) {
  if (!gui) return;
  const values = ui.values;
  values.playing = m.playing;
  ui.play.name(m.playing ? "Pause" : "Play");
  Object.assign(values.gravity, m.gravity);
  Object.assign(values.damping, m.damping);
  for (let j = 0; j < values.modes.length; j++) values.modes[j] = m.weights[j];
  for (const c of gui.controllersRecursive()) c.updateDisplay();
  // After a refused step: each holder's handle where the FMU kept the holder (pivot + translation, turned by the rotation vector).
  if (m.anchors) m.anchors.forEach((a, k) => {
    const o = handles[k].object, turn = new THREE.Vector3(a[3], a[4], a[5]), angle = turn.length();
    o.position.fromArray(inst.pivots[k]).add(new THREE.Vector3(a[0], a[1], a[2]));
    o.quaternion.setFromAxisAngle(angle > 0 ? turn.divideScalar(angle) : turn.set(1, 0, 0), angle);
  });
}

function showReadouts() {
  const el = document.getElementById("readout");
  const lines = [];
  const m = lastReadouts;
  if (m) {
    const r = m.readouts, f = (v, d = 3) => (v === null ? "–" : Number(v).toPrecision(d));
    lines.push(`t = ${m.time.toFixed(2)} s · real-time factor ${m.rtf.toFixed(2)} · frames/s sent ${m.rate.toFixed(0)}, drawn ${view.rate || 0}`);
    lines.push(`kinetic ${f(r.kineticEnergy, 4)} J · potential ${f(r.potentialEnergy, 4)} J`);
    for (let k = 0; k < inst.pivots.length; k++) lines.push(`holder ${k + 1} force (${r[`holder ${k + 1} force`].map((v) => f(v)).join(", ")}) N`);
    lines.push(`forceResidual ${f(r.forceResidual)} · trainingRange ${f(r.trainingRange)} · errorEstimate ${f(r.errorEstimate)} · reducedFraction ${f(r.reducedFraction)}`);
    lines.push(`${m.playing ? "running" : "paused"} · ${m.expanded ? "modes expanded in the page" : "positions sent"}`);
  }
  el.firstChild.textContent = lines.join("\n");
  document.getElementById("log").textContent = [...(m ? m.warnings : []), ...notes].join("\n");
}

// Frames drawn a second, for the readouts.
let mark = performance.now(), drawn0 = 0;
setInterval(() => {
  const now = performance.now();
  view.rate = Math.round((1000 * (view.drawn - drawn0)) / (now - mark));
  mark = now;
  drawn0 = view.drawn;
}, 500);

// Where a world point is drawn, in CSS pixels from the canvas's top left (tests aim the mouse with it).
view.onScreen = (p) => {
  const v = new THREE.Vector3(...p).project(camera);
  return [((v.x + 1) / 2) * window.innerWidth, ((1 - v.y) / 2) * window.innerHeight];
};
view.hovered = (k) => handles[k] && handles[k].axis;
view.pivot = (k) => handles[k].object.position.toArray();
