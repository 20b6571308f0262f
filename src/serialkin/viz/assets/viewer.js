// serialkin interactive viewer (part of serialkin, MIT licence).
//
// This code runs inside an ES module <script> of the page written by
// serialkin.viz.viewer, after `THREE` (three.js) and `DATA` (the robot's chain arrays
// and the scene, see viewer_data() in viewer.py) have been defined.
//
// Forward kinematics is computed here, in the page, from the robot's general chain data,
// exactly as serialkin's compiled kernels do (serialkin/kinematics/kernels.py, eq 11):
//     T = F[0] · M_1(q_1) · F[1] · M_2(q_2) ··· M_n(q_n) · F[n]
// where M_i rotates by q_i + offset_i about (revolute) or translates by q_i + offset_i
// along (prismatic) the joint's unit axis. Link frame i is the pose right after M_i
// times L[i]; frame 0 is L[0] (the base). Matrices are row-major arrays of 16 numbers
// (float64), world z is up, lengths in metres, angles in radians.
//
// The robot's body: every visual shape is a child of its chain frame's group, placed at
// its origin (row-major 4x4 in that frame), so it moves with the frame. Meshes arrive
// quantised (uint16 per coordinate over the bounding box, p = lo + step * u) with uint16
// or uint32 triangle indices, base64 of little-endian arrays. The self-collision check
// runs after every change of q: for each checked capsule pair (s, t) the world axis ends
// are T_f a and T_f b, and the pair collides when the segment-segment distance minus
// both radii is below zero (as serialkin.collision.self_clearance computes it).

const N = DATA.n;
const F = DATA.F.map((m) => m.flat());
const L = DATA.L.map((m) => m.flat());
const META = DATA.meta;

// ------------------------------------------------------------------ kinematics
function postMultiply(T, A) {
  // T <- T · A for rigid transforms (last rows [0 0 0 1]), in place.
  for (let r = 0; r < 3; r++) {
    const t0 = T[4 * r], t1 = T[4 * r + 1], t2 = T[4 * r + 2];
    T[4 * r] = t0 * A[0] + t1 * A[4] + t2 * A[8];
    T[4 * r + 1] = t0 * A[1] + t1 * A[5] + t2 * A[9];
    T[4 * r + 2] = t0 * A[2] + t1 * A[6] + t2 * A[10];
    T[4 * r + 3] += t0 * A[3] + t1 * A[7] + t2 * A[11];
  }
}

function applyJoint(T, m, qi) {
  // T <- T · M(q): rotation about / translation along the joint axis (Rodrigues).
  const ax = m[0], ay = m[1], az = m[2];
  const x = qi + m[4];
  if (m[3] === 1) {
    for (let r = 0; r < 3; r++) {
      T[4 * r + 3] += x * (T[4 * r] * ax + T[4 * r + 1] * ay + T[4 * r + 2] * az);
    }
    return;
  }
  const c = Math.cos(x), s = Math.sin(x), v = 1.0 - c;
  const r00 = c + ax * ax * v, r01 = ax * ay * v - az * s, r02 = ax * az * v + ay * s;
  const r10 = ay * ax * v + az * s, r11 = c + ay * ay * v, r12 = ay * az * v - ax * s;
  const r20 = az * ax * v - ay * s, r21 = az * ay * v + ax * s, r22 = c + az * az * v;
  for (let r = 0; r < 3; r++) {
    const t0 = T[4 * r], t1 = T[4 * r + 1], t2 = T[4 * r + 2];
    T[4 * r] = t0 * r00 + t1 * r10 + t2 * r20;
    T[4 * r + 1] = t0 * r01 + t1 * r11 + t2 * r21;
    T[4 * r + 2] = t0 * r02 + t1 * r12 + t2 * r22;
  }
}

function kinematics(q) {
  // Link frames 0..n, joint frames 1..n (pose right after M_i) and the tool pose.
  const T = F[0].slice();
  const frames = [L[0].slice()];
  const joints = [];
  for (let i = 0; i < N; i++) {
    applyJoint(T, META[i], q[i]);
    joints.push(T.slice());
    const Ti = T.slice();
    postMultiply(Ti, L[i + 1]);
    frames.push(Ti);
    postMultiply(T, F[i + 1]);
  }
  return { frames, joints, tool: T };
}

const origin = (M) => [M[3], M[7], M[11]];
const rows4 = (M) => [M.slice(0, 4), M.slice(4, 8), M.slice(8, 12), M.slice(12, 16)];

// ------------------------------------------------------------------ state and page
const state = {
  q: DATA.q.slice(),
  frame: 0,
  playing: false,
  renders: 0,
  webgl: false,
  error: null,
};
const $ = (id) => document.getElementById(id);
const fmt = (v, d = 4) => (Math.abs(v) < 0.5 * 10 ** -d ? 0 : v).toFixed(d);

function showMessage(text) {
  const box = $("sk-message");
  box.textContent = text;
  box.hidden = false;
}

// ------------------------------------------------------------------ three.js scene
const S = DATA.scale;
const view = $("sk-view");
function webglAvailable() {
  try {
    const c = document.createElement("canvas");
    return !!(window.WebGL2RenderingContext && c.getContext("webgl2"));
  } catch (err) {
    return false;
  }
}
let renderer = null;
if (webglAvailable()) {
  try {
    renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    state.webgl = true;
  } catch (err) {
    state.error = String(err);
  }
} else {
  state.error = "WebGL 2 is not available";
}
if (!renderer) {
  showMessage(
    "WebGL is not available in this browser, so the robot cannot be drawn. " +
      "The sliders, the end-effector readout and window.serialkin still work.",
  );
}
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f6f8);
const camera = new THREE.PerspectiveCamera(40, 1, S * 0.005, S * 200);
camera.up.set(0, 0, 1);
if (renderer) {
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  view.appendChild(renderer.domElement);
  renderer.domElement.id = "sk-canvas";
}

scene.add(new THREE.HemisphereLight(0xffffff, 0x8090a0, 2.0));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(2 * S, -1.5 * S, 3 * S);
scene.add(sun);

// ground grid in the world xy plane (GridHelper lies in xz: turn it)
const gridSize = 2 ** Math.ceil(Math.log2(2.4 * S));
const grid = new THREE.GridHelper(gridSize, 16, 0x9aa5b1, 0xd5dbe1);
grid.rotation.x = Math.PI / 2;
grid.position.z = DATA.ground_z;
scene.add(grid);
const worldAxes = new THREE.AxesHelper(0.25 * S);
scene.add(worldAxes);

const linkMat = new THREE.MeshStandardMaterial({ color: 0x2f6db5, metalness: 0.1, roughness: 0.5 });
const jointMatR = new THREE.MeshStandardMaterial({ color: 0xf0a030, metalness: 0.1, roughness: 0.4 });
const jointMatP = new THREE.MeshStandardMaterial({ color: 0x9b59b6, metalness: 0.1, roughness: 0.4 });
const baseMat = new THREE.MeshStandardMaterial({ color: 0x444a52, roughness: 0.6 });
const eeMat = new THREE.MeshStandardMaterial({ color: 0xd03030, roughness: 0.4 });
const outsideMat = new THREE.MeshStandardMaterial({ color: 0xe02020, emissive: 0x600000 });
const rLink = DATA.sizes.link_radius, rJoint = DATA.sizes.joint_radius;
const Y = new THREE.Vector3(0, 1, 0);

const robotGroup = new THREE.Group();
scene.add(robotGroup);
// the skeleton (links as cylinders, joints, base box): the whole robot when it has no
// visual geometry, a toggle otherwise
const skeletonGroup = new THREE.Group();
robotGroup.add(skeletonGroup);
const unitCyl = new THREE.CylinderGeometry(1, 1, 1, 20);
const links = [];
for (let i = 0; i <= N; i++) {
  const m = new THREE.Mesh(unitCyl, linkMat);
  skeletonGroup.add(m);
  links.push(m);
}
const jointMeshes = [];
for (let i = 0; i < N; i++) {
  const prismatic = META[i][3] === 1;
  const geom = prismatic
    ? new THREE.BoxGeometry(1.6 * rJoint, 3.2 * rJoint, 1.6 * rJoint)
    : new THREE.CylinderGeometry(rJoint, rJoint, 3.2 * rJoint, 24);
  const m = new THREE.Mesh(geom, prismatic ? jointMatP : jointMatR);
  skeletonGroup.add(m);
  jointMeshes.push(m);
}
const base = new THREE.Mesh(new THREE.BoxGeometry(4 * rJoint, 4 * rJoint, 1.5 * rJoint), baseMat);
base.matrixAutoUpdate = false;
skeletonGroup.add(base);

// the end effector: a red ball on the tool frame, with its triad
const ee = new THREE.Group();
ee.matrixAutoUpdate = false;
const eeBall = new THREE.Mesh(new THREE.SphereGeometry(1.2 * rLink, 20, 14), eeMat);
ee.add(eeBall);
ee.add(new THREE.AxesHelper(0.12 * S));
robotGroup.add(ee);

// link frames as triads (toggle)
const triads = [];
for (let i = 0; i <= N; i++) {
  const a = new THREE.AxesHelper(0.08 * S);
  a.matrixAutoUpdate = false;
  a.visible = false;
  robotGroup.add(a);
  triads.push(a);
}

function setMatrix(obj, M) {
  obj.matrix.set(...M);
  obj.matrixWorldNeedsUpdate = true;
}

function placeSegment(mesh, a, b, radius) {
  const d = new THREE.Vector3(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
  const len = d.length();
  mesh.visible = len > 1e-9;
  if (!mesh.visible) return;
  mesh.position.set((a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2);
  mesh.quaternion.setFromUnitVectors(Y, d.divideScalar(len));
  mesh.scale.set(radius, len, radius);
}

// ------------------------------------------------------------------ link geometry
function b64bytes(text) {
  // base64 text -> Uint8Array (its own buffer, offset 0: typed views of it are aligned)
  const bin = atob(text);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

function meshGeometry(m) {
  // Decode one embedded mesh: positions lo + step * u (u uint16), indices uint16/uint32.
  const u = new Uint16Array(b64bytes(m.positions).buffer);
  const pos = new Float32Array(u.length);
  for (let i = 0; i < u.length; i += 3) {
    pos[i] = m.lo[0] + m.step[0] * u[i];
    pos[i + 1] = m.lo[1] + m.step[1] * u[i + 1];
    pos[i + 2] = m.lo[2] + m.step[2] * u[i + 2];
  }
  const ib = b64bytes(m.indices).buffer;
  const idx = m.index_bytes === 4 ? new Uint32Array(ib) : new Uint16Array(ib);
  const g = new THREE.BufferGeometry();
  g.setAttribute("position", new THREE.BufferAttribute(pos, 3));
  g.setIndex(new THREE.BufferAttribute(idx, 1));
  g.computeVertexNormals();
  return g;
}

// one group per chain frame that carries shapes; its matrix is the frame's world pose
const frameGroups = new Map();
function frameGroup(f) {
  if (!frameGroups.has(f)) {
    const g = new THREE.Group();
    g.matrixAutoUpdate = false;
    robotGroup.add(g);
    frameGroups.set(f, g);
  }
  return frameGroups.get(f);
}

const hitMat = new THREE.MeshStandardMaterial({ color: 0xe02020, emissive: 0x700000, roughness: 0.5 });
const ROT_Y_TO_Z = new THREE.Matrix4().makeRotationX(Math.PI / 2); // three's y axis onto z
const meshGeometries = DATA.meshes.map(meshGeometry);
const visualObjects = [];
for (const sh of DATA.shapes) {
  let geom;
  let alongZ = false;
  if (sh.kind === "mesh") geom = meshGeometries[sh.mesh];
  else if (sh.kind === "box") geom = new THREE.BoxGeometry(...sh.size);
  else if (sh.kind === "sphere") geom = new THREE.SphereGeometry(sh.radius, 32, 20);
  else if (sh.kind === "cylinder") {
    geom = new THREE.CylinderGeometry(sh.radius, sh.radius, sh.length, 32);
    alongZ = true;
  } else {
    geom = new THREE.CapsuleGeometry(sh.radius, sh.length, 8, 24);
    alongZ = true;
  }
  const [r, g, b, a] = sh.rgba;
  const mat = new THREE.MeshStandardMaterial({
    color: new THREE.Color(r, g, b), metalness: 0.05, roughness: 0.55,
    transparent: a < 1, opacity: a,
  });
  const obj = new THREE.Mesh(geom, mat);
  obj.matrixAutoUpdate = false;
  obj.matrix.set(...sh.origin);
  if (alongZ) obj.matrix.multiply(ROT_Y_TO_Z);
  obj.userData = { kind: sh.kind, link: sh.link, body: sh.body, material: mat };
  frameGroup(sh.frame).add(obj);
  visualObjects.push(obj);
}

// collision capsules (a toggle) and the pairs checked in the page
const COL = DATA.collision;
const capsuleMat = new THREE.MeshStandardMaterial({
  color: 0x20a090, transparent: true, opacity: 0.35, roughness: 0.7, depthWrite: false,
});
const capsuleHitMat = new THREE.MeshStandardMaterial({
  color: 0xe02020, transparent: true, opacity: 0.6, roughness: 0.7, depthWrite: false,
});
const capsuleObjects = [];
if (COL) {
  for (let s = 0; s < COL.radius.length; s++) {
    const a = COL.a[s], b = COL.b[s];
    const len = Math.hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    const m = new THREE.Mesh(new THREE.CapsuleGeometry(COL.radius[s], len, 6, 20), capsuleMat);
    m.position.set((a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2);
    if (len > 0) {
      m.quaternion.setFromUnitVectors(Y, new THREE.Vector3(b[0] - a[0], b[1] - a[1], b[2] - a[2]).divideScalar(len));
    }
    m.visible = false;
    frameGroup(COL.frame[s]).add(m);
    capsuleObjects.push(m);
  }
}

function segmentDistance(p1, q1, p2, q2) {
  // Distance between segments p1q1 and p2q2: closest points by clamped parameters
  // s, t in [0, 1] (Ericson, Real-Time Collision Detection, 5.1.9).
  const d1 = [q1[0] - p1[0], q1[1] - p1[1], q1[2] - p1[2]];
  const d2 = [q2[0] - p2[0], q2[1] - p2[1], q2[2] - p2[2]];
  const r = [p1[0] - p2[0], p1[1] - p2[1], p1[2] - p2[2]];
  const dot = (u, v) => u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
  const clamp = (x) => Math.min(1, Math.max(0, x));
  const a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
  const eps = 1e-24;
  let s = 0, t = 0;
  if (a <= eps && e <= eps) {
    s = t = 0;
  } else if (a <= eps) {
    t = clamp(f / e);
  } else {
    const c = dot(d1, r);
    if (e <= eps) {
      s = clamp(-c / a);
    } else {
      const b = dot(d1, d2), denom = a * e - b * b;
      s = denom > 0 ? clamp((b * f - c * e) / denom) : 0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = clamp(-c / a);
      } else if (t > 1) {
        t = 1;
        s = clamp((b - c) / a);
      }
    }
  }
  return Math.hypot(r[0] + d1[0] * s - d2[0] * t, r[1] + d1[1] * s - d2[1] * t,
    r[2] + d1[2] * s - d2[2] * t);
}

function transformPoint(T, p) {
  return [
    T[0] * p[0] + T[1] * p[1] + T[2] * p[2] + T[3],
    T[4] * p[0] + T[5] * p[1] + T[6] * p[2] + T[7],
    T[8] * p[0] + T[9] * p[1] + T[10] * p[2] + T[11],
  ];
}

let collisionState = { distance: null, pair: null, colliding: [] };
function checkCollisions() {
  // Smallest signed distance over the checked pairs and every colliding body pair.
  if (!COL) return;
  const A = [], B = [];
  for (let s = 0; s < COL.radius.length; s++) {
    const T = current.frames[COL.frame[s]];
    A.push(transformPoint(T, COL.a[s]));
    B.push(transformPoint(T, COL.b[s]));
  }
  let best = Infinity, bestPair = null;
  const hits = new Map(); // "i,j" body pair -> smallest distance
  for (const [s, t] of COL.pairs) {
    const d = segmentDistance(A[s], B[s], A[t], B[t]) - COL.radius[s] - COL.radius[t];
    const i = Math.min(COL.body[s], COL.body[t]), j = Math.max(COL.body[s], COL.body[t]);
    if (d < best) {
      best = d;
      bestPair = [i, j];
    }
    if (d < 0) {
      const key = `${i},${j}`;
      if (!hits.has(key) || d < hits.get(key)) hits.set(key, d);
    }
  }
  const hitBodies = new Set();
  const colliding = [];
  for (const [key, d] of hits) {
    const [i, j] = key.split(",").map(Number);
    hitBodies.add(i);
    hitBodies.add(j);
    colliding.push([COL.bodies[i], COL.bodies[j], d]);
  }
  colliding.sort((x, y) => x[2] - y[2]);
  for (let s = 0; s < capsuleObjects.length; s++) {
    capsuleObjects[s].material = hitBodies.has(COL.body[s]) ? capsuleHitMat : capsuleMat;
  }
  for (const o of visualObjects) {
    o.material = o.userData.body >= 0 && hitBodies.has(o.userData.body) ? hitMat : o.userData.material;
  }
  collisionState = {
    distance: Number.isFinite(best) ? best : null,
    pair: bestPair ? [COL.bodies[bestPair[0]], COL.bodies[bestPair[1]]] : null,
    colliding,
  };
  const box = $("sk-collision");
  if (colliding.length) {
    const shown = colliding.slice(0, 6).map((c) => `${c[0]} – ${c[1]} (${fmt(c[2])} m)`);
    if (colliding.length > 6) shown.push(`… and ${colliding.length - 6} more pairs`);
    box.textContent = `colliding (${colliding.length}):\n` + shown.join("\n");
    box.classList.add("sk-hit");
  } else {
    box.textContent = bestPair
      ? `clear: ${fmt(best)} m\nclosest ${COL.bodies[bestPair[0]]} – ${COL.bodies[bestPair[1]]}`
      : "no pairs to check";
    box.classList.remove("sk-hit");
  }
}

// the point layer (a toggle)
let pointCloud = null;
if (DATA.points && DATA.points.count > 0) {
  const pos = new Float32Array(b64bytes(DATA.points.positions).buffer);
  const rgb = b64bytes(DATA.points.colors);
  const g = new THREE.BufferGeometry();
  g.setAttribute("position", new THREE.BufferAttribute(pos, 3));
  g.setAttribute("color", new THREE.BufferAttribute(rgb, 3, true));
  pointCloud = new THREE.Points(g, new THREE.PointsMaterial({ size: 0.012 * S, vertexColors: true }));
  scene.add(pointCloud);
}

function shownOnScreen(obj) {
  for (let o = obj; o; o = o.parent) if (!o.visible) return false;
  return true;
}

function drawn() {
  // What is on screen now: visual shapes (meshes and primitives), their triangles,
  // collision capsules, points, whether the skeleton is shown, and what is drawn red
  // for a collision (links of the visual shapes, number of capsules; shown or not).
  const vis = visualObjects.filter(shownOnScreen);
  const tri = (o) => (o.geometry.index ? o.geometry.index.count : o.geometry.attributes.position.count) / 3;
  return {
    shapes: vis.length,
    meshes: vis.filter((o) => o.userData.kind === "mesh").length,
    primitives: vis.filter((o) => o.userData.kind !== "mesh").length,
    triangles: vis.filter((o) => o.userData.kind === "mesh").reduce((acc, o) => acc + tri(o), 0),
    capsules: capsuleObjects.filter(shownOnScreen).length,
    points: pointCloud && shownOnScreen(pointCloud) ? DATA.points.count : 0,
    skeleton: shownOnScreen(skeletonGroup),
    highlighted: visualObjects.filter((o) => o.material === hitMat).map((o) => o.userData.link),
    capsulesHit: capsuleObjects.filter((o) => o.material === capsuleHitMat).length,
  };
}

function shapePoses() {
  // World matrix (row-major 4x4) of every visual shape as drawn, in DATA.shapes order
  // (cylinders and capsules include the turn of three.js's y axis onto the shape's z).
  return visualObjects.map((o) => {
    o.updateMatrixWorld(true);
    return rows4(o.matrixWorld.clone().transpose().elements);
  });
}

function clearance() {
  // The in-page self-collision check for the current q (null distance: no model).
  return {
    distance: collisionState.distance,
    pair: collisionState.pair,
    colliding: collisionState.colliding.map((c) => c.slice()),
  };
}

// ------------------------------------------------------------------ path, trace, obstacles
function polyline(points, color, width) {
  const g = new THREE.BufferGeometry().setFromPoints(points.map((p) => new THREE.Vector3(...p)));
  return new THREE.Line(g, new THREE.LineBasicMaterial({ color, linewidth: width }));
}

const pathGroup = new THREE.Group();
scene.add(pathGroup);
if (DATA.path_points && DATA.path_points.length > 1) {
  pathGroup.add(polyline(DATA.path_points, 0x1f9d3a, 2));
  const dots = new THREE.BufferGeometry().setFromPoints(
    DATA.path_points.map((p) => new THREE.Vector3(...p)),
  );
  pathGroup.add(new THREE.Points(dots, new THREE.PointsMaterial({ color: 0x1f9d3a, size: 0.012 * S })));
}
const traceGroup = new THREE.Group();
scene.add(traceGroup);
if (DATA.trajectory && DATA.trajectory.length > 1) {
  traceGroup.add(polyline(DATA.trajectory.map((q) => origin(kinematics(q).tool)), 0xe07b00, 1));
}

const obstacleGroup = new THREE.Group();
scene.add(obstacleGroup);
const obstacleMat = new THREE.MeshStandardMaterial({
  color: 0x7f8c8d, transparent: true, opacity: 0.45, roughness: 0.8, depthWrite: false,
});
for (const o of DATA.obstacles) {
  let mesh;
  if (o.kind === "sphere") {
    mesh = new THREE.Mesh(new THREE.SphereGeometry(o.radius, 32, 20), obstacleMat);
    mesh.position.set(...o.center);
  } else if (o.kind === "cylinder") {
    const h = o.height === null ? Math.max(4 * o.radius, 0.3 * S) : o.height; // null: infinite
    mesh = new THREE.Mesh(new THREE.CylinderGeometry(o.radius, o.radius, h, 40), obstacleMat);
    mesh.position.set(...o.center);
    mesh.rotation.x = Math.PI / 2; // cylinder axis along world z
  } else {
    const len = Math.hypot(o.b[0] - o.a[0], o.b[1] - o.a[1], o.b[2] - o.a[2]);
    mesh = new THREE.Mesh(new THREE.CapsuleGeometry(o.radius, len, 8, 24), obstacleMat);
    placeSegment(mesh, o.a, o.b, 1);
    mesh.scale.set(1, 1, 1);
  }
  obstacleGroup.add(mesh);
}

// ------------------------------------------------------------------ update and render
function outsideLimits(i) {
  // True when q_i is outside its joint limits (null limits: unlimited).
  const [lo, hi] = DATA.qlim[i];
  return (lo !== null && state.q[i] < lo - 1e-12) || (hi !== null && state.q[i] > hi + 1e-12);
}

let current = kinematics(state.q);

function updateRobot() {
  current = kinematics(state.q);
  const pts = current.frames.map(origin);
  pts.push(origin(current.tool));
  for (let i = 0; i <= N; i++) placeSegment(links[i], pts[i], pts[i + 1], rLink);
  for (let i = 0; i < N; i++) {
    const J = current.joints[i];
    const m = META[i];
    const axis = new THREE.Vector3(
      J[0] * m[0] + J[1] * m[1] + J[2] * m[2],
      J[4] * m[0] + J[5] * m[1] + J[6] * m[2],
      J[8] * m[0] + J[9] * m[1] + J[10] * m[2],
    ).normalize();
    jointMeshes[i].position.set(J[3], J[7], J[11]);
    jointMeshes[i].quaternion.setFromUnitVectors(Y, axis);
    const out = outsideLimits(i);
    jointMeshes[i].material = out ? outsideMat : m[3] === 1 ? jointMatP : jointMatR;
  }
  setMatrix(base, current.frames[0]);
  setMatrix(ee, current.tool);
  for (let i = 0; i <= N; i++) setMatrix(triads[i], current.frames[i]);
  for (const [f, g] of frameGroups) setMatrix(g, current.frames[f]);
  scene.updateMatrixWorld(true);
  checkCollisions();
  updateReadout();
}

function render() {
  if (!renderer) return;
  renderer.render(scene, camera);
  state.renders += 1;
}

let pending = false;
function requestRender() {
  if (pending) return;
  pending = true;
  requestAnimationFrame(() => {
    pending = false;
    render();
  });
}

function resize() {
  if (!renderer) return;
  const w = Math.max(view.clientWidth, 50), h = Math.max(view.clientHeight, 50);
  renderer.setSize(w, h, true);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  render();
}

// ------------------------------------------------------------------ camera: orbit, pan, zoom
const orbit = { target: new THREE.Vector3(...DATA.view.target), radius: 0, azimuth: 0, elevation: 0 };
function resetView() {
  orbit.target.set(...DATA.view.target);
  orbit.radius = DATA.view.radius;
  orbit.azimuth = DATA.view.azimuth;
  orbit.elevation = DATA.view.elevation;
  updateCamera();
}
function updateCamera() {
  const ce = Math.cos(orbit.elevation);
  camera.position.set(
    orbit.target.x + orbit.radius * ce * Math.cos(orbit.azimuth),
    orbit.target.y + orbit.radius * ce * Math.sin(orbit.azimuth),
    orbit.target.z + orbit.radius * Math.sin(orbit.elevation),
  );
  camera.lookAt(orbit.target);
  camera.updateMatrixWorld(true);
  requestRender();
}

if (renderer) {
  const el = renderer.domElement;
  let drag = null;
  el.addEventListener("pointerdown", (ev) => {
    drag = { x: ev.clientX, y: ev.clientY, pan: ev.button === 2 || ev.shiftKey || ev.button === 1 };
    el.setPointerCapture(ev.pointerId);
  });
  el.addEventListener("pointermove", (ev) => {
    if (!drag) return;
    const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
    drag.x = ev.clientX;
    drag.y = ev.clientY;
    if (drag.pan) {
      const k = (orbit.radius * 1.5) / Math.max(el.clientHeight, 1);
      const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
      const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
      orbit.target.addScaledVector(right, -dx * k).addScaledVector(up, dy * k);
    } else {
      orbit.azimuth -= dx * 0.008;
      orbit.elevation = Math.min(1.55, Math.max(-1.55, orbit.elevation + dy * 0.008));
    }
    updateCamera();
  });
  const end = () => { drag = null; };
  el.addEventListener("pointerup", end);
  el.addEventListener("pointercancel", end);
  el.addEventListener("contextmenu", (ev) => ev.preventDefault());
  el.addEventListener("dblclick", resetView);
  el.addEventListener(
    "wheel",
    (ev) => {
      ev.preventDefault();
      orbit.radius = Math.min(S * 50, Math.max(S * 0.05, orbit.radius * Math.exp(ev.deltaY * 0.001)));
      updateCamera();
    },
    { passive: false },
  );
}

// ------------------------------------------------------------------ controls
const sliders = [];
const boxes = [];
function buildJointControls() {
  const host = $("sk-joints");
  for (let i = 0; i < N; i++) {
    const lim = DATA.slider_limits[i];
    const row = document.createElement("div");
    row.className = "sk-joint";
    const label = document.createElement("label");
    label.htmlFor = `sk-joint-${i}`;
    label.textContent = `${DATA.joint_names[i]} (${DATA.joint_types[i]})`;
    const unit = document.createElement("span");
    unit.className = "sk-unit";
    unit.id = `sk-unit-${i}`;
    const slider = document.createElement("input");
    Object.assign(slider, { type: "range", id: `sk-joint-${i}`, min: lim[0], max: lim[1], step: "any" });
    slider.value = state.q[i];
    slider.dataset.joint = i;
    const box = document.createElement("input");
    Object.assign(box, { type: "number", id: `sk-joint-${i}-value`, step: "any" });
    box.value = state.q[i];
    box.setAttribute("aria-label", `${DATA.joint_names[i]} value`);
    slider.addEventListener("input", () => setJoint(i, slider.valueAsNumber, "slider"));
    // step="any" keeps slider values exact; keys move by 1/200 (PageUp/Down 1/20) of the range
    slider.addEventListener("keydown", (ev) => {
      const span = lim[1] - lim[0];
      const steps = { ArrowRight: 1, ArrowUp: 1, ArrowLeft: -1, ArrowDown: -1, PageUp: 10, PageDown: -10 };
      let v = null;
      if (ev.key in steps) v = state.q[i] + (steps[ev.key] * span) / 200;
      else if (ev.key === "Home") v = lim[0];
      else if (ev.key === "End") v = lim[1];
      if (v === null) return;
      ev.preventDefault();
      setJoint(i, Math.min(lim[1], Math.max(lim[0], v)), "api");
    });
    box.addEventListener("change", () => {
      const v = parseFloat(box.value);
      if (Number.isFinite(v)) setJoint(i, v, "box");
    });
    const head = document.createElement("div");
    head.className = "sk-head";
    head.append(label, unit);
    const body = document.createElement("div");
    body.className = "sk-body";
    body.append(slider, box);
    row.append(head, body);
    host.appendChild(row);
    sliders.push(slider);
    boxes.push(box);
  }
}

function syncControl(i, source) {
  if (source !== "slider") sliders[i].value = state.q[i];
  if (source !== "box") boxes[i].value = +state.q[i].toPrecision(10);
  const u = $(`sk-unit-${i}`);
  u.classList.toggle("sk-outside", outsideLimits(i));
  u.title = outsideLimits(i) ? "outside the joint limits" : "";
  u.textContent =
    DATA.joint_types[i] === "R"
      ? `${fmt(state.q[i], 4)} rad = ${fmt((state.q[i] * 180) / Math.PI, 2)}°`
      : `${fmt(state.q[i], 4)} m`;
}

function updateReadout() {
  const p = origin(current.tool);
  $("sk-ee").textContent = `x ${fmt(p[0])}  y ${fmt(p[1])}  z ${fmt(p[2])}  [m]`;
  $("sk-pose").textContent = rows4(current.tool)
    .map((r) => r.map((v) => fmt(v).padStart(8)).join(" "))
    .join("\n");
}

function setJoint(i, v, source = "api") {
  if (!Number.isInteger(i) || i < 0 || i >= N) {
    throw new RangeError(`joint index must be an integer in 0..${N - 1}, got ${i}`);
  }
  const x = Number(v);
  if (!Number.isFinite(x)) throw new RangeError(`joint value must be finite, got ${v}`);
  state.q[i] = x;
  syncControl(i, source);
  updateRobot();
  render();
  return endEffector();
}

function setJoints(q) {
  if (!Array.isArray(q) || q.length !== N) {
    throw new RangeError(`expected ${N} joint values, got ${q}`);
  }
  for (let i = 0; i < N; i++) {
    state.q[i] = Number(q[i]);
    syncControl(i, "api");
  }
  updateRobot();
  render();
  return endEffector();
}

function endEffector() {
  // The drawn end effector: the tool group's world matrix as the scene holds it.
  ee.updateMatrixWorld(true);
  const e = ee.matrixWorld.elements; // column-major
  const matrix = [
    [e[0], e[4], e[8], e[12]],
    [e[1], e[5], e[9], e[13]],
    [e[2], e[6], e[10], e[14]],
    [e[3], e[7], e[11], e[15]],
  ];
  return { position: [e[12], e[13], e[14]], matrix };
}

function linkOrigins() {
  // Drawn skeleton points: link-frame origins 0..n and the tool point (as plot_robot).
  const pts = triads.map((t) => {
    t.updateMatrixWorld(true);
    const e = t.matrixWorld.elements;
    return [e[12], e[13], e[14]];
  });
  pts.push(endEffector().position);
  return pts;
}

// trajectory playback
const TRAJ = DATA.trajectory || [];
function setFrame(k) {
  if (TRAJ.length === 0) throw new RangeError("this page has no trajectory");
  const j = Math.max(0, Math.min(TRAJ.length - 1, Math.round(k)));
  state.frame = j;
  $("sk-frame").value = j;
  $("sk-frame-label").textContent = `${j + 1} / ${TRAJ.length}`;
  return setJoints(TRAJ[j].slice());
}
let lastTick = 0;
function tick(t) {
  if (!state.playing) return;
  const fps = Number($("sk-fps").value);
  if (t - lastTick >= 1000 / fps) {
    lastTick = t;
    setFrame((state.frame + 1) % TRAJ.length);
  }
  requestAnimationFrame(tick);
}
function play() {
  if (TRAJ.length < 2 || state.playing) return;
  state.playing = true;
  $("sk-play").textContent = "Pause";
  requestAnimationFrame(tick);
}
function pause() {
  state.playing = false;
  $("sk-play").textContent = "Play";
}

function buildTrajectoryControls() {
  if (TRAJ.length === 0) return;
  $("sk-trajectory").hidden = false;
  const fr = $("sk-frame");
  fr.max = TRAJ.length - 1;
  fr.addEventListener("input", () => {
    pause();
    setFrame(fr.valueAsNumber);
  });
  $("sk-play").addEventListener("click", () => (state.playing ? pause() : play()));
  $("sk-frame-label").textContent = `1 / ${TRAJ.length}`;
}

function bindToggles() {
  const bind = (id, fn) => {
    const box = $(id);
    box.addEventListener("change", () => {
      fn(box.checked);
      render();
    });
    fn(box.checked);
  };
  bind("sk-show-frames", (on) => triads.forEach((t) => (t.visible = on)));
  bind("sk-show-path", (on) => (pathGroup.visible = on));
  bind("sk-show-trace", (on) => (traceGroup.visible = on));
  bind("sk-show-obstacles", (on) => (obstacleGroup.visible = on));
  bind("sk-show-grid", (on) => (grid.visible = worldAxes.visible = on));
  const offer = (id, present, checked, fn) => {
    const box = $(id);
    box.closest("label").hidden = !present;
    box.checked = checked;
    bind(id, fn);
  };
  const hasVisual = visualObjects.length > 0;
  offer("sk-show-visual", hasVisual, true, (on) => visualObjects.forEach((o) => (o.visible = on)));
  offer("sk-show-skeleton", hasVisual, !hasVisual, (on) => {
    skeletonGroup.visible = on;
    eeBall.visible = on;
  });
  offer("sk-show-collision", !!COL, !!(COL && COL.show), (on) => capsuleObjects.forEach((o) => (o.visible = on)));
  offer("sk-show-points", !!pointCloud, true, (on) => pointCloud && (pointCloud.visible = on));
  if (pointCloud) $("sk-points-label").textContent = `${DATA.points.label} (${DATA.points.count})`;
  $("sk-collision-section").hidden = !COL;
  $("sk-reset-view").addEventListener("click", resetView);
  $("sk-home").addEventListener("click", () => setJoints(DATA.q.slice()));
}

// ------------------------------------------------------------------ start
buildJointControls();
buildTrajectoryControls();
for (let i = 0; i < N; i++) syncControl(i, "api");
bindToggles();
updateRobot();
window.addEventListener("resize", resize);
orbit.radius = DATA.view.radius;
resetView();
resize();

window.serialkin = {
  ready: true,
  version: DATA.version,
  n: N,
  data: DATA,
  state,
  setJoint: (i, v) => setJoint(i, v),
  setJoints,
  getJoints: () => state.q.slice(),
  endEffector,
  linkOrigins,
  fk: (q) => rows4(kinematics(q).tool),
  setFrame,
  play,
  pause,
  frameCount: TRAJ.length,
  resetView,
  render,
  drawn,
  clearance,
  shapePoses,
};
// time from the start of navigation to a drawn, scriptable page [ms] (benchmarks read it)
state.readyMs = performance.now();
document.body.dataset.ready = "true";
