// The teach page: meshcat's viewer fed by the kinelab server, joint sliders, a draggable target, live readings.
"use strict";
const cfg = JSON.parse(document.getElementById("kinelab-config").textContent);
const THREE = MeshCat.THREE;
const viewer = new MeshCat.Viewer(document.getElementById("kinelab-viewer"));
const state = { seq: 0, busy: false, polling: false, pending: new Map(), dragging: null, readout: null, replies: 0,
                drags: 0 };
window.kinelab = state;  // what the browser tests and the console read

const node = (path) => viewer.scene_tree.find(path).object;
// one target per name in cfg.targets: a chain's "target", a whole robot's "target_0", "target_1", ...
const targetNode = (k = 0) => node(["meshcat", "frames", cfg.targets[k]]);
const handleNode = (k = 0) => node(["meshcat", "frames", cfg.targets[k], "handle", "<object>"]);

function bytes(b64) {
  const text = atob(b64), out = new Uint8Array(text.length);
  for (let i = 0; i < text.length; i++) out[i] = text.charCodeAt(i);
  return out;
}

function apply(reply) {
  // a reply older than one already applied (a poll overtaken by a drag's answer) would draw an earlier state over
  // the newer one; every reply carries everything since the seq its request gave, so a stale one adds nothing
  if (typeof reply.seq === "number" && reply.seq < state.seq) return;
  for (const c of reply.commands || []) viewer.handle_command_bytearray(bytes(c));
  if (reply.seq >= state.seq) {
    state.seq = reply.seq;
    if (reply.readout) show(reply.readout);
  }
  document.getElementById("kinelab-error").textContent = reply.error || "";
  state.replies += 1;
}

// the latest request of each key waits while one is in flight (a drag sends many: only its last one matters)
function post(action, body, key = action) {
  state.pending.set(key, { action, body });
  if (!state.busy) pump();
}

async function pump() {
  state.busy = true;
  while (state.pending.size) {
    const [key, { action, body }] = state.pending.entries().next().value;
    state.pending.delete(key);
    try {
      const r = await fetch(action, { method: "POST", headers: { "Content-Type": "application/json" },
                                      body: JSON.stringify({ ...body, since: state.seq }) });
      apply(await r.json());
    } catch (e) {
      document.getElementById("kinelab-error").textContent = "the kinelab server does not answer (stopped?)";
    }
  }
  state.busy = false;
}

async function poll() {
  if (!state.busy && !state.dragging) {
    state.polling = true;
    try { apply(await (await fetch("state?since=" + state.seq)).json()); } catch (e) { /* the server stopped */ }
    state.polling = false;
  }
  setTimeout(poll, 500);
}

// an element holding text only (no markup is ever parsed from a string)
function element(tag, text = "", className = "") {
  const e = document.createElement(tag);
  e.textContent = text;
  if (className) e.className = className;
  return e;
}

// -- joints -------------------------------------------------------------------------------------
const sliders = [];
function fmt(x, digits) { return Number(x).toFixed(digits); }
function jointText(j, v) {
  return j.kind === "prismatic" ? `${fmt(v, 4)} m` : `${fmt(v, 3)} rad (${fmt(v * 180 / Math.PI, 1)}°)`;
}
function buildSliders() {
  const box = document.getElementById("kinelab-joints");
  cfg.joints.forEach((j, k) => {
    const row = document.createElement("div");
    row.className = "joint";
    // a robot file's names are text, never markup: every string reaches the page through textContent
    row.append(element("span", j.name), element("span", "", "value"));
    const s = document.createElement("input");
    Object.assign(s, { type: "range", min: j.lower, max: j.upper, step: (j.upper - j.lower) / 2000,
                       value: cfg.q[j.iq] });
    s.id = `kinelab-joint-${k}`;
    s.addEventListener("pointerdown", () => { s.dataset.active = "1"; });
    s.addEventListener("pointerup", () => { delete s.dataset.active; });
    s.addEventListener("input", () => {
      row.querySelector(".value").textContent = jointText(j, Number(s.value));
      // the other joints as the server has them: a slider rounds its value to its step
      const q = (state.readout ? state.readout.q : cfg.q).slice();
      q[j.iq] = Number(s.value);
      post("q", { q });
    });
    row.appendChild(s);
    box.appendChild(row);
    sliders.push(s);
  });
}

// -- readings -----------------------------------------------------------------------------------
function show(r) {
  state.readout = r;
  cfg.joints.forEach((j, k) => {
    const s = sliders[k], v = r.q[j.iq];
    if (!s.dataset.active) s.value = v;
    s.parentNode.querySelector(".value").textContent = jointText(j, v);
  });
  document.getElementById("kinelab-q").textContent = `q = [${r.q.map((v) => fmt(v, 6)).join(", ")}]`;
  document.getElementById("kinelab-status").textContent = r.status;
  if (r.rows) {  // a whole robot's page: its rows as the server words them
    table(r.rows);
    return;
  }
  const deg = (a) => a.map((x) => fmt(x * 180 / Math.PI, 2)).join(", ");
  const rows = [
    ["tool position", r.tool.position_m.map((x) => fmt(x, 4)).join(", ") + " m"],
    ["tool roll, pitch, yaw", deg(r.tool.rpy_rad) + " °"],
    ["target position", r.target.position_m.map((x) => fmt(x, 4)).join(", ") + " m"],
    ["target error", `${r.position_error_m.toExponential(2)} m, ${r.rotation_error_rad.toExponential(2)} rad`],
    ["σ_min (scaled J)", r.sigma_min.toExponential(3) + (r.rank < r.full_rank ? `  — singular: rank ${r.rank} of ${r.full_rank}` : "")],
    ["manipulability", r.manipulability.toExponential(3)],
    ["ellipsoid radii", r.ellipsoid_radii_m_per_rad.map((x) => fmt(x, 3)).join(", ") + " m/rad"],
    ["contacts", r.collisions ? (r.contacts.length ? r.contacts.join("; ") : "none") : "not checked"],
  ];
  table(rows);
  document.getElementById("kinelab-collisions").checked = r.collisions;
}

function table(rows) {
  document.getElementById("kinelab-readout").replaceChildren(
    ...rows.map(([k, v]) => { const tr = element("tr"); tr.append(element("td", k), element("td", v)); return tr; }));
}

// -- the target: drag to move, Shift+drag to turn -----------------------------------------------
const raycaster = new THREE.Raycaster();
function ray(event) {
  const rect = viewer.renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
                                -((event.clientY - rect.top) / rect.height) * 2 + 1);
  raycaster.setFromCamera(ndc, viewer.camera);
  return raycaster;
}

function sendTarget(k) {
  const e = targetNode(k).matrix.elements;  // column-major
  const rows = [];
  for (let r = 0; r < 4; r++) for (let c = 0; c < 4; c++) rows.push(e[c * 4 + r]);
  post("target", { index: k, matrix: rows }, `target ${k}`);
}

function onDown(event) {
  if (event.button !== 0) return;
  const r = ray(event);
  let best = null;  // the nearest handle under the pointer
  cfg.targets.forEach((_, k) => {
    const hit = r.intersectObject(handleNode(k), true)[0];
    if (hit && (!best || hit.distance < best.hit.distance)) best = { k, hit };
  });
  if (!best) return;
  event.stopPropagation();
  event.preventDefault();
  viewer.controls.enabled = false;
  const normal = viewer.camera.getWorldDirection(new THREE.Vector3());
  const centre = handleNode(best.k).getWorldPosition(new THREE.Vector3());
  state.dragging = { index: best.k, turn: event.shiftKey, x: event.clientX, y: event.clientY,
                     plane: new THREE.Plane().setFromNormalAndCoplanarPoint(normal, centre),
                     offset: centre.clone().sub(best.hit.point) };
}

function onMove(event) {
  const d = state.dragging;
  if (!d) return;
  const t = targetNode(d.index);
  if (d.turn) {
    const dx = event.clientX - d.x, dy = event.clientY - d.y;
    if (dx === 0 && dy === 0) return;
    const m = viewer.camera.matrixWorld.elements;
    const right = new THREE.Vector3(m[0], m[1], m[2]), up = new THREE.Vector3(m[4], m[5], m[6]);
    const axis = up.multiplyScalar(dx).add(right.multiplyScalar(dy)).normalize();
    axis.transformDirection(new THREE.Matrix4().copy(t.parent.matrixWorld).invert());
    t.quaternion.premultiply(new THREE.Quaternion().setFromAxisAngle(axis, 0.01 * Math.hypot(dx, dy)));
    d.x = event.clientX; d.y = event.clientY;
  } else {
    const p = ray(event).ray.intersectPlane(d.plane, new THREE.Vector3());
    if (!p) return;
    t.position.copy(t.parent.worldToLocal(p.add(d.offset)));
  }
  t.updateMatrix();
  viewer.set_dirty();
  sendTarget(d.index);
}

function onUp() {
  if (!state.dragging) return;
  state.dragging = null;
  state.drags += 1;
  viewer.controls.enabled = true;
}

// where the handle is on the screen (CSS pixels), for a test that drags it
state.handleOnScreen = (k = 0) => {
  const p = handleNode(k).getWorldPosition(new THREE.Vector3()).project(viewer.camera);
  const rect = viewer.renderer.domElement.getBoundingClientRect();
  return [rect.left + (p.x + 1) / 2 * rect.width, rect.top + (1 - p.y) / 2 * rect.height];
};
// a drawn frame's pose in the base frame, rows first
state.drawnPose = (name) => {
  // meshcat sets a transform as position, quaternion and scale; three.js composes the matrix at the next render,
  // which a busy machine's page may not have reached yet: composed here, it is what that render draws
  const o = node(["meshcat", "frames", name]);
  o.updateMatrix();
  const e = o.matrix.elements, rows = [];
  for (let r = 0; r < 4; r++) for (let c = 0; c < 4; c++) rows.push(e[c * 4 + r]);
  return rows;
};
state.apply = apply;  // a test replays an old reply through it
state.idle = () => !state.busy && !state.polling && state.pending.size === 0 && !state.dragging;

document.getElementById("kinelab-heading").textContent = cfg.heading;
document.getElementById("kinelab-legend").textContent = cfg.legend;
if (cfg.whole) {  // a whole robot's page: no branches, no collision switch; the snap puts every target back
  for (const id of ["kinelab-prev", "kinelab-next", "kinelab-collisions-label"]) {
    document.getElementById(id).hidden = true;
  }
  document.getElementById("kinelab-snap").textContent = "targets to hands";
  document.getElementById("kinelab-help").textContent = "Drag a gold ball to move that hand's target (Shift+drag "
    + "turns it); the whole robot follows, its feet and centre of mass held. Drag elsewhere to turn the view, "
    + "right-drag to pan, wheel to zoom.";
}
document.getElementById("kinelab-prev").addEventListener("click", () => post("branch", { step: -1 }));
document.getElementById("kinelab-next").addEventListener("click", () => post("branch", { step: 1 }));
document.getElementById("kinelab-snap").addEventListener("click", () => post("snap", {}));
document.getElementById("kinelab-collisions").addEventListener("change",
  (e) => post("collisions", { on: e.target.checked }));
viewer.renderer.domElement.addEventListener("pointerdown", onDown);
window.addEventListener("pointermove", onMove);
window.addEventListener("pointerup", onUp);
buildSliders();
fetch("state?since=0").then((r) => r.json()).then((reply) => { apply(reply); state.ready = true; poll(); });
