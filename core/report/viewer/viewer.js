// The 3D viewer of surfinspect's pages (core/report/viewer_page.h). Reads the
// page's data (<script id="si-data">, JSON) and payload (<script
// id="si-payload">, base64 of little-endian typed arrays) and shows, by
// data.kind:
// - 'report' (report.html, core/report/html_report.h): the scanned points
//   in the part frame, coloured by the error map's palette index computed in
//   C++ (core/report/html_payload.h), the CAD mesh as a translucent overlay
//   with the area the scan did not see in grey,
//   the defects with their ids;
// - 'trend_map' (trend.html, core/history/trend_html.h): the CAD mesh with
//   each triangle coloured by its mean deviation over the parts, or by its
//   sigma, indices again computed in C++.
// Both have a colour legend in mm and show the value under the pointer.
// window.surfinspect reports `ready` and the time it took (ms since
// navigation start) for tests.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

// detail: what the last frame drew ('preview' or 'full'); settled: the full
// set is on screen and nothing is pending (tests wait for it).
const state = {
  ready: false, errors: [], shown: 0, tti_ms: null, views: 0, picks: 0, timings: {},
  detail: null, settled: false, full_frames: 0, preview_frames: 0, preview_points: 0,
};
const mark = (name) => { state.timings[name] = Math.round(performance.now()); };
mark('module');
window.surfinspect = state;
window.addEventListener('error', (e) => state.errors.push(String(e.message)));

const data = JSON.parse(document.getElementById('si-data').textContent);
const RUN = 84; // core/report/deviation_palette.h
// Software WebGL (SwiftShader: headless Chromium, and desktops without a GPU)
// draws points too slowly for a full frame of a million to follow the camera
// (bench/report_viewer_bench.py prints a preview and a full frame's cost).
// The first frame, and every frame while the camera moves, therefore draw a
// prefix of the payload, which core/report/progressive_order.h spreads
// evenly over the part, with the points enlarged
// to close the gaps; the full set is drawn once the camera has rested for
// REFINE_MS. Clouds of at most 1.5 x PREVIEW_POINTS are always drawn whole.
const PREVIEW_POINTS = 250000;
const REFINE_MS = 200;

function decodeBase64(text) {
  if (Uint8Array.fromBase64) return Uint8Array.fromBase64(text);
  const bin = atob(text);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) out[i] = bin.charCodeAt(i);
  return out;
}

function typed(bytes, [offset, length], Type) {
  return new Type(bytes.buffer, bytes.byteOffset + offset, length / Type.BYTES_PER_ELEMENT);
}

// The palette index of a deviation, as core/report/deviation_palette.cpp
// computes it; used to draw the legend (points carry their index).
function paletteIndex(d, tol, range) {
  if (Number.isNaN(d)) return 0;
  const bin = (f) => Math.min(RUN - 1, Math.max(0, Math.floor(f * RUN)));
  if (Math.abs(d) <= tol) return 86 + bin((d / tol + 1) / 2);
  const s = range > tol ? (Math.abs(d) - tol) / (range - tol) : 1;
  if (s > 1) return d > 0 ? 254 : 1;
  return d > 0 ? 170 + bin(s) : 2 + RUN - 1 - bin(s);
}

function rgb(index) {
  const p = data.palette;
  return `rgb(${p[3 * index]},${p[3 * index + 1]},${p[3 * index + 2]})`;
}

function dequantise(q, min, step, centre) {
  const out = new Float32Array(q.length);
  for (let i = 0; i < q.length; i += 3)
    for (let a = 0; a < 3; ++a) out[i + a] = min[a] + q[i + a] * step[a] - centre[a];
  return out;
}

function buildPoints(bytes, centre) {
  const P = data.points;
  const q = typed(bytes, P.positions, Uint16Array);
  const index = typed(bytes, P.palette_index, Uint8Array);
  const colors = new Uint8Array(3 * P.shown);
  for (let i = 0; i < P.shown; ++i)
    for (let a = 0; a < 3; ++a) colors[3 * i + a] = data.palette[3 * index[i] + a];
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(dequantise(q, P.min, P.step, centre), 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(colors, 3, true));
  geometry.computeBoundingSphere();
  const ext = P.step.map((s) => s * 65535).sort((a, b) => b - a);
  const spacing = Math.sqrt(Math.max(ext[0] * ext[1], 1e-6) / Math.max(P.shown, 1));
  const material = new THREE.PointsMaterial({ size: 2 * spacing, vertexColors: true });
  const points = new THREE.Points(geometry, material);
  points.userData.deviations = typed(bytes, P.deviations, Int16Array);
  points.userData.spacing = spacing;
  return points;
}

// The first n points of `points` (the same GPU buffers), enlarged by
// sqrt(shown / n) so that they cover the surface as the full set does; null
// when the full set is small enough to draw every frame.
function buildPreview(points, shown) {
  if (shown <= 1.5 * PREVIEW_POINTS) return null;
  const geometry = new THREE.BufferGeometry();
  for (const name of ['position', 'color']) geometry.setAttribute(name, points.geometry.getAttribute(name));
  geometry.setDrawRange(0, PREVIEW_POINTS);
  geometry.boundingSphere = points.geometry.boundingSphere;
  const material = points.material.clone();
  material.size = points.material.size * Math.sqrt(shown / PREVIEW_POINTS);
  const preview = new THREE.Points(geometry, material);
  preview.visible = false;
  return preview;
}

function buildMesh(bytes, centre) {
  const M = data.mesh;
  if (!M) return null;
  const geometry = new THREE.BufferGeometry();
  const q = typed(bytes, M.positions, Uint16Array);
  geometry.setAttribute('position', new THREE.BufferAttribute(dequantise(q, M.min, M.step, centre), 3));
  geometry.setIndex(new THREE.BufferAttribute(typed(bytes, M.indices, Uint32Array), 1));
  // Unlit: one cheap shader program less to compile before the first frame.
  const material = new THREE.MeshBasicMaterial({
    color: 0xb8c4d0, transparent: true, opacity: 0.16, depthWrite: false, side: THREE.DoubleSide,
  });
  return new THREE.Mesh(geometry, material);
}

// The CAD triangles the scan did not wholly see (data.unseen, from
// report.coverage), grey over the mesh: the more of a triangle went unseen,
// the more opaque. A triangle's own vertices, so each has its shade.
function buildUnseen(mesh) {
  const U = data.unseen;
  if (!mesh || !U || U.triangles.length === 0) return null;
  const at = mesh.geometry.getAttribute('position').array, index = mesh.geometry.getIndex().array;
  const n = U.triangles.length, position = new Float32Array(9 * n), colour = new Float32Array(12 * n);
  for (let k = 0; k < n; ++k) {
    const t = U.triangles[k], alpha = 0.25 + 0.6 * (1 - U.covered[k]);
    for (let c = 0; c < 3; ++c) {
      const v = index[3 * t + c];
      for (let a = 0; a < 3; ++a) position[9 * k + 3 * c + a] = at[3 * v + a];
      colour.set([0.42, 0.42, 0.47, alpha], 12 * k + 4 * c);
    }
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(position, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(colour, 4));  // RGBA: alpha per vertex
  const material = new THREE.MeshBasicMaterial({
    vertexColors: true, transparent: true, depthWrite: false, side: THREE.DoubleSide,
  });
  return new THREE.Mesh(geometry, material);
}

// scale: {tol, range, signed, title, none}: the colour bar of paletteIndex
// over [-range, range] (or [0, range] when not signed), ticks at the band and
// range ends, and the colour of `none` (no value).
function drawLegend(canvas, scale) {
  const g = canvas.getContext('2d');
  const { width: w, height: h } = canvas;
  const { range, tol } = scale, span = 1.12 * range, low = scale.signed ? -span : 0;
  const top = 14, bottom = h - 40, barX = 8, barW = 22;
  const yOf = (d) => top + ((span - d) / (span - low)) * (bottom - top);
  g.clearRect(0, 0, w, h);
  g.fillStyle = 'rgba(255,255,255,0.9)';
  g.fillRect(0, 0, w, h);
  for (let y = top; y < bottom; ++y) {
    const d = span - ((y - top + 0.5) / (bottom - top)) * (span - low);
    g.fillStyle = rgb(paletteIndex(d, tol, range));
    g.fillRect(barX, y, barW, 1);
  }
  g.fillStyle = '#111';
  g.font = '11px sans-serif';
  g.textBaseline = 'middle';
  for (const d of scale.signed ? [range, tol, 0, -tol, -range] : [range, tol, 0]) {
    const y = yOf(d);
    g.fillRect(barX + barW, Math.round(y), 5, 1);
    g.fillText(`${d > 0 && scale.signed ? '+' : ''}${+d.toPrecision(4)} mm`, barX + barW + 8, y);
  }
  g.fillStyle = rgb(0);
  g.fillRect(barX, h - 30, barW, 12);
  g.fillStyle = '#111';
  g.fillText(scale.none, barX + barW + 8, h - 24);
  g.fillText(scale.title, barX, 6);
}

const VIEWS = {
  iso: [1, -1, 0.8], top: [0, -1e-4, 1], bottom: [0, 1e-4, -1], front: [0, -1, 0],
  back: [0, 1, 0], left: [-1, 0, 0], right: [1, 0, 0],
};

// The renderer, scene, camera and controls for content of bounding radius
// `radius` around the origin (`centre` in part coordinates).
function createView(radius, centre) {
  THREE.ColorManagement.enabled = false; // the palette's bytes reach the screen unchanged
  const renderer = new THREE.WebGLRenderer({ antialias: false });
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.domElement.classList.add('gl');
  document.getElementById('viewer').prepend(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x20242a);
  const camera = new THREE.PerspectiveCamera(35, 1, radius / 1000, radius * 20);
  camera.up.set(0, 0, 1);
  const controls = new OrbitControls(camera, renderer.domElement);
  return {
    renderer, scene, camera, controls, points: null, preview: null, defects: [], radius, centre,
    anim: null, refine: null, dragging: false, size: [0, 0],
  };
}

// Sizes the view to its element (and keeps it so), draws the first frame
// and declares the page ready.
function showView(view) {
  const viewer = document.getElementById('viewer');
  const { renderer, camera } = view;
  const resize = () => {
    const size = [viewer.clientWidth, viewer.clientHeight];
    if (size[0] === view.size[0] && size[1] === view.size[1]) return;
    view.size = size;
    renderer.setSize(size[0], size[1], false);
    camera.aspect = size[0] / Math.max(size[1], 1);
    camera.updateProjectionMatrix();
    if (state.ready) changed(view);
  };
  resize();
  new ResizeObserver(resize).observe(viewer);
  setView(view, 'iso', false);
  // Interactive once the first frame is complete, not merely queued.
  const gl = renderer.getContext();
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  mark('rendered');
  // For benchmarks: one frame of the given detail drawn to completion, ms.
  state.frame_ms = (detail = 'full') => {
    const t = performance.now();
    draw(view, detail);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
    return performance.now() - t;
  };
  // For tests: where part point p (mm) is on the page, in CSS pixels.
  state.project = (p) => {
    const v = new THREE.Vector3(...p.map((x, a) => x - view.centre[a])).project(camera);
    const r = renderer.domElement.getBoundingClientRect();
    return [r.left + ((v.x + 1) / 2) * r.width, r.top + ((1 - v.y) / 2) * r.height];
  };
  state.ready = true;
  state.tti_ms = performance.now();
}

function reportMain() {
  const note = document.getElementById('viewer-note');
  const P = data.points;
  note.textContent = `${P.shown.toLocaleString('en')} of ${P.finite.toLocaleString('en')} points shown` +
    (P.thinned ? ` (thinned on a grid: up to ${P.per_cell} per ${P.cell_mm.toPrecision(3)} mm cell, ` +
      'largest |deviation| first; the statistics are over all points)' : '') +
    (data.mesh_omitted ? '; the CAD mesh is too large to embed' : '') +
    (data.unseen ? `; grey: CAD not seen within ${data.unseen.distance_mm} mm ` +
      `(${(100 * data.unseen.surface).toFixed(1)}% of the surface seen)` : '');
  drawLegend(document.getElementById('legend'), {
    tol: data.tolerance_mm, range: data.range_mm, signed: true, title: 'deviation', none: 'unmatched',
  });
  if (P.shown === 0) { state.ready = true; state.tti_ms = performance.now(); return; }
  const bytes = decodeBase64(document.getElementById('si-payload').textContent);
  mark('decoded');
  const centre = [0, 1, 2].map((a) => P.min[a] + P.step[a] * 32767.5);
  const points = buildPoints(bytes, centre);
  const preview = buildPreview(points, P.shown);
  const mesh = buildMesh(bytes, centre);
  const unseen = buildUnseen(mesh);
  mark('built');
  const view = createView(points.geometry.boundingSphere.radius || 1, centre);
  view.points = points;
  view.preview = preview;
  for (const o of [points, preview, mesh, unseen]) if (o) view.scene.add(o);
  view.defects = addDefects(view.scene, centre, view.radius);
  wireCamera(view, (e) => pick(view, e));
  wireReport(view, mesh, unseen);
  state.shown = P.shown;
  state.preview_points = preview ? PREVIEW_POINTS : P.shown;
  showView(view);
}

function addDefects(scene, centre, radius) {
  const labels = document.getElementById('labels');
  return data.defects.filter((d) => Array.isArray(d.centroid_mm)).map((d) => {
    const at = new THREE.Vector3(...d.centroid_mm.map((v, a) => v - centre[a]));
    const r = Math.max((d.extent_mm || 0) / 2, radius / 200);
    const ring = new THREE.Mesh(new THREE.SphereGeometry(r, 16, 10),
      new THREE.MeshBasicMaterial({ color: 0xff33ff, wireframe: true, transparent: true, opacity: 0.7 }));
    ring.position.copy(at);
    scene.add(ring);
    const label = document.createElement('div');
    label.className = 'label';
    label.textContent = `D${d.id} ${d.kind ?? ''} ${d.peak_mm != null ? (+d.peak_mm).toFixed(3) + ' mm' : ''}`;
    labels.appendChild(label);
    return { defect: d, at, ring, label, r };
  });
}

// Draws a frame of the given detail now.
function draw(view, detail) {
  const full = detail === 'full' || !view.preview;
  if (view.points) view.points.visible = full;
  if (view.preview) view.preview.visible = !full;
  render(view);
  state.detail = full ? 'full' : 'preview';
  if (full) state.full_frames += 1;
  else state.preview_frames += 1;
}

// The camera or the scene changed: a preview frame now, the full set once
// nothing has changed for REFINE_MS and no drag or flight is under way.
function changed(view) {
  draw(view, 'preview');
  state.settled = false;
  clearTimeout(view.refine);
  view.refine = setTimeout(() => {
    view.refine = null;
    if (view.anim || view.dragging) return; // their end calls changed() again
    draw(view, 'full');
    if (!state.timings.full) mark('full');
    state.settled = true;
  }, view.preview ? REFINE_MS : 0);
}

function render(view) {
  const { renderer, scene, camera, defects } = view;
  renderer.render(scene, camera);
  const w = renderer.domElement.clientWidth, h = renderer.domElement.clientHeight;
  const v = new THREE.Vector3();
  for (const m of defects) {
    v.copy(m.at).project(camera);
    const visible = m.ring.visible && v.z < 1 && Math.abs(v.x) <= 1 && Math.abs(v.y) <= 1;
    m.label.style.display = visible ? '' : 'none';
    m.label.style.left = `${((v.x + 1) / 2) * w}px`;
    m.label.style.top = `${((1 - v.y) / 2) * h}px`;
  }
}

// Moves the camera to look at `target` from `target + dir * distance`,
// animated over half a second unless `animate` is false.
function moveCamera(view, target, position, animate) {
  const { camera, controls } = view;
  const from = { t: controls.target.clone(), p: camera.position.clone() };
  const start = performance.now(), ms = animate ? 500 : 0;
  const step = () => {
    const k = ms ? Math.min(1, (performance.now() - start) / ms) : 1;
    const e = k * k * (3 - 2 * k);
    controls.target.lerpVectors(from.t, target, e);
    camera.position.lerpVectors(from.p, position, e);
    controls.update();
    view.anim = k < 1 ? requestAnimationFrame(step) : null;
    changed(view);
  };
  if (view.anim) cancelAnimationFrame(view.anim);
  step();
}

function setView(view, name, animate = true) {
  const dir = new THREE.Vector3(...VIEWS[name]).normalize();
  const distance = view.radius / Math.sin(THREE.MathUtils.degToRad(35 / 2)) * 1.05;
  moveCamera(view, new THREE.Vector3(), dir.multiplyScalar(distance), animate);
  state.views += 1;
}

function flyToDefect(view, id) {
  const m = view.defects.find((x) => String(x.defect.id) === String(id));
  if (!m) return;
  const dir = view.camera.position.clone().sub(view.controls.target).normalize();
  const distance = Math.max(8 * m.r, view.radius / 10);
  moveCamera(view, m.at.clone(), m.at.clone().add(dir.multiplyScalar(distance)), true);
  document.querySelectorAll('tr.defect').forEach((tr) =>
    tr.classList.toggle('selected', tr.dataset.defect === String(id)));
}

// The deviation under the pointer (nearest shown point along the ray).
function pick(view, event) {
  const rect = view.renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
    -((event.clientY - rect.top) / rect.height) * 2 + 1);
  const ray = new THREE.Raycaster();
  ray.params.Points.threshold = 2 * view.points.userData.spacing;
  ray.setFromCamera(ndc, view.camera);
  const hit = ray.intersectObject(view.points)[0];
  const box = document.getElementById('hover');
  if (!hit) { box.hidden = true; return; }
  const q = view.points.userData.deviations[hit.index];
  const p = hit.point.toArray().map((v, a) => (v + view.centre[a]).toFixed(2));
  box.hidden = false;
  box.textContent = q === -32768 ? `unmatched at (${p.join(', ')}) mm`
    : `deviation ${(q * data.points.deviation_step_mm).toFixed(4)} mm at (${p.join(', ')}) mm`;
  state.picks += 1;
}

// Orbit, pan and zoom, the standard views, and `pick` on hover and click.
function wireCamera(view, onPick) {
  view.controls.addEventListener('start', () => { view.dragging = true; });
  view.controls.addEventListener('end', () => { view.dragging = false; changed(view); });
  view.controls.addEventListener('change', () => { if (!view.anim) changed(view); });
  document.querySelectorAll('#toolbar button[data-view]').forEach((b) =>
    b.addEventListener('click', () => setView(view, b.dataset.view)));
  let pending = null, last = null;
  const canvas = view.renderer.domElement;
  canvas.addEventListener('pointermove', (e) => {
    if (e.buttons) return;
    last = e;
    if (!pending) pending = requestAnimationFrame(() => { pending = null; onPick(last); });
  });
  canvas.addEventListener('click', (e) => onPick(e));
}

// report.html's switches and its defect rows.
function wireReport(view, mesh, unseen) {
  const meshToggle = document.getElementById('mesh-toggle');
  meshToggle.disabled = !mesh;
  meshToggle.addEventListener('change', () => { if (mesh) mesh.visible = meshToggle.checked; changed(view); });
  const unseenToggle = document.getElementById('unseen-toggle');
  if (unseenToggle) {
    unseenToggle.disabled = !unseen;
    unseenToggle.addEventListener('change', () => { if (unseen) unseen.visible = unseenToggle.checked; changed(view); });
  }
  const defectToggle = document.getElementById('defect-toggle');
  defectToggle.addEventListener('change', () => {
    for (const m of view.defects) m.ring.visible = defectToggle.checked;
    changed(view);
  });
  document.querySelectorAll('tr.defect').forEach((tr) => {
    tr.addEventListener('click', () => flyToDefect(view, tr.dataset.defect));
    tr.addEventListener('keydown', (e) => { if (e.key === 'Enter') flyToDefect(view, tr.dataset.defect); });
  });
}

// --- trend.html: the process trend map on the CAD mesh ---

// The mesh without shared corners, so that each triangle has its own
// colour: one colour attribute per mode ('mean', 'sigma'), from the palette
// indices per triangle.
function buildTrendMesh(bytes, centre) {
  const M = data.mesh, T = data.trend;
  const v = dequantise(typed(bytes, M.positions, Uint16Array), M.min, M.step, centre);
  const index = typed(bytes, M.indices, Uint32Array);
  const n = M.triangles;
  const position = new Float32Array(9 * n);
  for (let c = 0; c < 3 * n; ++c)
    for (let a = 0; a < 3; ++a) position[3 * c + a] = v[3 * index[c] + a];
  const colours = {};
  for (const mode of ['mean', 'sigma']) {
    const idx = typed(bytes, T[mode + '_index'], Uint8Array);
    const rgb = new Uint8Array(9 * n);
    for (let t = 0; t < n; ++t)
      for (let k = 0; k < 3; ++k)
        for (let a = 0; a < 3; ++a) rgb[9 * t + 3 * k + a] = data.palette[3 * idx[t] + a];
    colours[mode] = new THREE.BufferAttribute(rgb, 3, true);
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(position, 3));
  geometry.setAttribute('color', colours.mean);
  geometry.computeBoundingSphere();
  const mesh = new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({ vertexColors: true, side: THREE.DoubleSide }));
  mesh.userData = {
    colours, mean: typed(bytes, T.mean_mm, Float32Array), sigma: typed(bytes, T.sigma_mm, Float32Array),
    parts: typed(bytes, T.parts_per_triangle, Uint32Array),
  };
  return mesh;
}

function trendScale(mode) {
  const T = data.trend;
  return mode === 'mean'
    ? { tol: T.mean_band_mm, range: T.mean_range_mm, signed: true, title: 'mean deviation', none: 'no points' }
    : { tol: T.sigma_band_mm, range: T.sigma_range_mm, signed: false, title: 'sigma over parts', none: 'under 2 parts' };
}

function pickTriangle(view, mesh, event) {
  const rect = view.renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
    -((event.clientY - rect.top) / rect.height) * 2 + 1);
  const ray = new THREE.Raycaster();
  ray.setFromCamera(ndc, view.camera);
  const hit = ray.intersectObject(mesh)[0];
  const box = document.getElementById('hover');
  if (!hit) { box.hidden = true; return; }
  const t = hit.faceIndex, u = mesh.userData, fmt = (x) => (Number.isNaN(x) ? 'n/a' : `${x.toFixed(4)} mm`);
  box.hidden = false;
  box.textContent = u.parts[t] === 0 ? `triangle ${t}: no points in any part`
    : `triangle ${t}: mean ${fmt(u.mean[t])}, sigma ${fmt(u.sigma[t])} over ${u.parts[t]} parts`;
  state.picks += 1;
}

function trendMain() {
  const T = data.trend, M = data.mesh;
  document.getElementById('viewer-note').textContent =
    `Per CAD triangle, the mean (or sigma) over ${T.parts} parts of its per-part mean deviation; ` +
    `${T.triangles_with_points.toLocaleString('en')} of ${M.triangles.toLocaleString('en')} triangles have points.`;
  const legend = document.getElementById('legend');
  drawLegend(legend, trendScale('mean'));
  const bytes = decodeBase64(document.getElementById('si-payload').textContent);
  mark('decoded');
  const centre = [0, 1, 2].map((a) => M.min[a] + M.step[a] * 32767.5);
  const mesh = buildTrendMesh(bytes, centre);
  mark('built');
  // Unlit colours are exact but flat: the crease edges (over 30 degrees)
  // give the part its shape.
  const edges = new THREE.LineSegments(new THREE.EdgesGeometry(mesh.geometry, 30),
    new THREE.LineBasicMaterial({ color: 0x101418, transparent: true, opacity: 0.45 }));
  const view = createView(mesh.geometry.boundingSphere.radius || 1, centre);
  view.scene.add(mesh, edges);
  wireCamera(view, (e) => pickTriangle(view, mesh, e));
  document.querySelectorAll('input[name="trend-mode"]').forEach((r) => r.addEventListener('change', () => {
    mesh.geometry.setAttribute('color', mesh.userData.colours[r.value]);
    drawLegend(legend, trendScale(r.value));
    state.mode = r.value;
    changed(view);
  }));
  state.mode = 'mean';
  state.shown = M.triangles;
  showView(view);
}

try {
  if (data.kind === 'trend_map') trendMain();
  else reportMain();
} catch (e) {
  state.errors.push(String(e));
  document.getElementById('viewer-note').textContent = `3D view unavailable: ${e.message}`;
  throw e;
}
