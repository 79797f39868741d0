// vitri studio: the page. Draws the mesh and the constraints with three.js, sends edits to the server's
// HTTP/JSON API and applies the mesh deltas it answers with (docs/studio.md). No build step, no modules:
// three.min.js and OrbitControls.js (Debian libjs-three) are loaded before this file.
'use strict';

// ------------------------------------------------------------------------------------------- server
const api = {
  async request(method, path, body) {
    const init = { method, headers: {} };
    if (method === 'POST') {
      init.body = body === undefined ? '{}' : body;
      if (typeof init.body === 'string') init.headers['Content-Type'] = 'application/json';
    }
    const r = await fetch(path, init);
    if (!r.ok) {
      let what = r.status + ' ' + r.statusText;
      try { what = (await r.json()).error; } catch (e) { /* not JSON */ }
      throw new Error(what);
    }
    return r;
  },
  async json(method, path, body) {
    return (await this.request(method, path, body === undefined ? undefined : JSON.stringify(body))).json();
  },
};

// ------------------------------------------------------------------------------ mesh held as slots
// Each triangle the server sent has an id; it lives in a slot (9 floats of positions and normals) of
// one growing, non-indexed BufferGeometry. A removed triangle's slot is zeroed (degenerate, invisible)
// and reused by the next added one; only the range of slots that changed is uploaded.
class MeshSlots {
  constructor(scene) {
    this.geometry = new THREE.BufferGeometry();
    this.capacity = 0;
    this.used = 0;          // slots ever used (draw range)
    this.slotOf = new Map(); // triangle id -> slot
    this.free = [];
    this.version = 0;
    this.triangles = 0;
    this.grow(1024);
    const shaded = new THREE.MeshPhongMaterial({ color: 0xb9c4d6, specular: 0x222222, shininess: 30,
                                                 side: THREE.DoubleSide, polygonOffset: true,
                                                 polygonOffsetFactor: 1, polygonOffsetUnits: 1 });
    this.mesh = new THREE.Mesh(this.geometry, shaded);
    this.wire = new THREE.Mesh(this.geometry, new THREE.MeshBasicMaterial({ color: 0x20242c, wireframe: true }));
    this.wire.visible = false;
    scene.add(this.mesh, this.wire);
  }

  grow(capacity) {
    const positions = new Float32Array(capacity * 9), normals = new Float32Array(capacity * 9);
    if (this.capacity) {
      positions.set(this.geometry.attributes.position.array);
      normals.set(this.geometry.attributes.normal.array);
    }
    for (const [name, array] of [['position', positions], ['normal', normals]]) {
      const attribute = new THREE.BufferAttribute(array, 3);
      attribute.setUsage(THREE.DynamicDrawUsage);
      this.geometry.setAttribute(name, attribute);
    }
    this.capacity = capacity;
  }

  // Applies one binary delta (format in docs/studio.md). Returns the number of triangles changed.
  apply(buffer) {
    const words = new Uint32Array(buffer, 0, 6);
    if (words[0] !== 0x44525456) throw new Error('not a vitri mesh delta');
    const full = words[1] & 1, version = words[2], nRemoved = words[4], nAdded = words[5];
    const removed = new Uint32Array(buffer, 24, nRemoved);
    const added = new Uint32Array(buffer, 24 + 4 * nRemoved, nAdded);
    const floats = 24 + 4 * (nRemoved + nAdded);
    const pos = new Float32Array(buffer, floats, 9 * nAdded);
    const nrm = new Float32Array(buffer, floats + 36 * nAdded, 9 * nAdded);
    if (full) this.clear();
    let lo = Infinity, hi = -1;
    const P = () => this.geometry.attributes.position.array;
    for (const id of removed) {
      const slot = this.slotOf.get(id);
      if (slot === undefined) continue;
      this.slotOf.delete(id);
      P().fill(0, 9 * slot, 9 * slot + 9);
      this.free.push(slot);
      lo = Math.min(lo, slot); hi = Math.max(hi, slot);
    }
    if (this.used + nAdded > this.capacity && this.free.length < nAdded) {
      this.grow(Math.max(2 * this.capacity, this.used + nAdded));
      lo = 0; hi = Math.max(hi, this.used - 1);
    }
    const positions = P(), normals = this.geometry.attributes.normal.array;
    for (let k = 0; k < nAdded; ++k) {
      const slot = this.free.length ? this.free.pop() : this.used++;
      this.slotOf.set(added[k], slot);
      positions.set(pos.subarray(9 * k, 9 * k + 9), 9 * slot);
      normals.set(nrm.subarray(9 * k, 9 * k + 9), 9 * slot);
      lo = Math.min(lo, slot); hi = Math.max(hi, slot);
    }
    if (hi >= lo) {
      for (const name of ['position', 'normal']) {
        const a = this.geometry.attributes[name];
        a.updateRange.offset = 9 * lo;
        a.updateRange.count = 9 * (hi - lo + 1);
        a.needsUpdate = true;
      }
    }
    this.geometry.setDrawRange(0, 3 * this.used);
    this.geometry.computeBoundingSphere();
    this.version = version;
    this.triangles = this.slotOf.size;
    return nRemoved + nAdded;
  }

  clear() {
    this.geometry.attributes.position.array.fill(0);
    this.slotOf.clear();
    this.free = [];
    this.used = 0;
  }
}

// ------------------------------------------------------------------------------------- constraints
const KIND_COLORS = { on: new THREE.Color(0xf2c94c), in: new THREE.Color(0x4c9bf2), out: new THREE.Color(0xf2584c) };
const kindOf = (value) => (value === 0 ? 'on' : value < 0 ? 'in' : 'out');

function discTexture() {
  const c = document.createElement('canvas');
  c.width = c.height = 64;
  const g = c.getContext('2d');
  g.beginPath(); g.arc(32, 32, 28, 0, 2 * Math.PI);
  g.fillStyle = '#fff'; g.fill();
  g.lineWidth = 5; g.strokeStyle = '#000'; g.stroke();
  return new THREE.CanvasTexture(c);
}

class ConstraintPoints {
  constructor(scene) {
    this.list = [];
    this.selected = -1;
    this.material = new THREE.PointsMaterial({ size: 11 * window.devicePixelRatio, vertexColors: THREE.VertexColors,
                                               map: discTexture(), alphaTest: 0.5, sizeAttenuation: false });
    this.points = new THREE.Points(new THREE.BufferGeometry(), this.material);
    this.points.renderOrder = 1;
    scene.add(this.points);
  }

  set(list) {
    this.list = list;
    const n = list.length, pos = new Float32Array(3 * n), col = new Float32Array(3 * n);
    list.forEach((c, i) => {
      pos.set(c.position, 3 * i);
      const color = i === this.selected ? new THREE.Color(0xffffff) : KIND_COLORS[kindOf(c.value)];
      col.set([color.r, color.g, color.b], 3 * i);
    });
    const g = this.points.geometry;
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    g.setAttribute('color', new THREE.BufferAttribute(col, 3));
    g.computeBoundingSphere();
    // Discs of 11 pixels for a few constraints, down to 5 for thousands (so that the surface shows).
    this.material.size = Math.max(5, Math.min(11, 60 / Math.sqrt(Math.max(n, 1)))) * window.devicePixelRatio;
  }

  moveLocally(index, p) {
    const a = this.points.geometry.attributes.position;
    a.setXYZ(index, p.x, p.y, p.z);
    a.needsUpdate = true;
    this.list[index].position = [p.x, p.y, p.z];
  }
}

// ------------------------------------------------------------------------------------------ studio
class Studio {
  constructor() {
    this.view = document.getElementById('view');
    this.renderer = new THREE.WebGLRenderer({ antialias: !/[?&]aa=0/.test(location.search) });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    this.renderer.setClearColor(0x2b2f37);
    this.view.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.01, 1000);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 0.55));
    const light = new THREE.DirectionalLight(0xffffff, 0.65);
    light.position.set(0.5, 1, 2);
    this.camera.add(light);
    this.scene.add(this.camera);
    this.controls = new THREE.OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.render());
    this.slots = new MeshSlots(this.scene);
    this.constraints = new ConstraintPoints(this.scene);
    this.raycaster = new THREE.Raycaster();
    this.stats = null;
    this.latency = null;     // ms from sending the last edit to its picture on screen
    this.latencies = [];
    this.drawTimes = [];
    this.busy = Promise.resolve();  // edits run one after the other
    this.drag = null;
    this.pixel = new Uint8Array(4);
    // Benchmarks wait for each frame to be drawn, so that a latency includes the drawing; otherwise the
    // next request goes out while the GPU draws.
    this.syncDraw = false;
    this.idleTimer = 0;
    this.ready = false;
    window.addEventListener('resize', () => this.resize());
    this.resize();
  }

  resize() {
    const w = this.view.clientWidth, h = this.view.clientHeight;
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  render() { this.renderer.render(this.scene, this.camera); }

  // Blocks until the last frame is drawn: reading a pixel back waits for the GPU (gl.finish() may not).
  waitForDraw() {
    const gl = this.renderer.getContext();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, this.pixel);
  }

  // Runs fn after every earlier edit (edits must reach the server in order).
  queue(fn) {
    const run = this.busy.then(fn);
    this.busy = run.catch((e) => this.showError(e));
    return run;
  }

  showError(e) {
    const box = document.getElementById('error');
    box.textContent = String(e.message || e);
    box.hidden = false;
    clearTimeout(this.errorTimer);
    this.errorTimer = setTimeout(() => { box.hidden = true; }, 6000);
  }

  // Fetches the mesh delta since the version held, applies it and draws. `t0`: when the edit was sent.
  // `approximate`: during a drag, triangles that moved less than the drag tolerance are not resent.
  async pull(t0, approximate) {
    const r = await api.request('GET', '/api/mesh?since=' + this.slots.version + (approximate ? '&exact=0' : ''));
    const buffer = await r.arrayBuffer(), t1 = performance.now();
    this.slots.apply(buffer);
    this.render();
    if (this.syncDraw) this.waitForDraw();
    if (t0 !== undefined) {
      const t2 = performance.now();
      this.latency = t2 - t0;
      this.latencies.push(this.latency);
      this.drawTimes.push(t2 - t1);  // of which: applying the delta and drawing (when syncDraw)
    }
  }

  async refreshState() {
    const s = await api.json('GET', '/api/state');
    this.constraints.set(s.constraint_list);
    delete s.constraint_list;
    this.showStats(s);
  }

  showStats(s) {
    this.stats = s;
    document.getElementById('model-name').textContent = s.name;
    document.getElementById('undo').disabled = s.undo === 0;
    document.getElementById('redo').disabled = s.redo === 0;
    document.getElementById('precision-value').textContent = s.target_precision.toPrecision(3);
    document.getElementById('precision').value = precisionToSlider(s.target_precision);
    document.getElementById('refine-state').textContent = s.refined
      ? 'refined to the target'
      : 'refining while idle: at ' + (s.precision === null ? '-' : s.precision.toPrecision(3));
    const lat = this.latency === null ? '-' : this.latency.toFixed(1) + ' ms';
    document.getElementById('stats').textContent =
      'update (edit to screen) ' + lat + '\n' +
      'server: edit ' + s.edit_ms.toFixed(1) + ' ms, extract ' + s.extract_ms.toFixed(1) + ' ms\n' +
      s.triangles + ' triangles, ' + s.vertices + ' vertices\n' +
      s.constraints + ' constraints, ' + s.delaunay_vertices + ' Delaunay vertices';
    this.updateSelection();
  }

  // One edit: POST it, then bring the mesh up to date (approximately while `dragging`), and the
  // constraint list unless `dragging` (the page moved the dragged point itself).
  edit(body, dragging) {
    return this.queue(async () => {
      const t0 = performance.now();
      const s = await api.json('POST', '/api/edit', body);
      await this.pull(t0, dragging);
      if (dragging) this.showStats(s); else await this.refreshState();
      this.scheduleRefine();
      return s;
    });
  }

  command(path) {
    return this.queue(async () => {
      const t0 = performance.now();
      await api.json('POST', path);
      this.select(-1);
      await this.pull(t0);
      await this.refreshState();
      this.scheduleRefine();
    });
  }

  // Progressive refinement: while the user is idle, ask the server for the next level.
  scheduleRefine(delay = 300) {
    clearTimeout(this.idleTimer);
    if (this.stats && this.stats.refined) return;
    this.idleTimer = setTimeout(() => {
      if (this.drag) return this.scheduleRefine();
      this.queue(async () => {
        const s = await api.json('POST', '/api/refine');
        await this.pull();
        this.showStats(s);
        this.scheduleRefine(50);
      });
    }, delay);
  }

  setPrecision(p) {
    clearTimeout(this.idleTimer);
    return this.queue(async () => {
      const s = await api.json('POST', '/api/refine', { precision: p });
      await this.pull();
      this.showStats(s);
      this.scheduleRefine(50);
    });
  }

  async load(file) {
    const bytes = await file.arrayBuffer();
    await this.queue(async () => {
      await api.request('POST', '/api/load?name=' + encodeURIComponent(file.name), bytes);
      this.select(-1);
      await this.pull();
      await this.refreshState();
      this.frame();
      this.scheduleRefine();
    });
  }

  frame() {
    const sphere = this.slots.geometry.boundingSphere;
    const r = sphere && sphere.radius > 0 ? sphere.radius : 1;
    const c = sphere ? sphere.center : new THREE.Vector3();
    this.controls.target.copy(c);
    const d = r / Math.sin((this.camera.fov * Math.PI) / 360) * 1.15;
    this.camera.position.set(c.x + 0.35 * d, c.y + 0.25 * d, c.z + 0.9 * d);
    this.camera.near = d / 100;
    this.camera.far = d * 100;
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.render();
  }

  select(index) {
    this.constraints.selected = index;
    this.constraints.set(this.constraints.list);
    this.updateSelection();
    this.render();
  }

  updateSelection() {
    const i = this.constraints.selected, c = this.constraints.list[i];
    document.getElementById('selection').hidden = !c;
    document.getElementById('delete').disabled = !c;
    if (!c) return;
    document.getElementById('sel-index').textContent = i;
    document.getElementById('sel-kind').textContent = { on: 'on-surface', in: 'inside', out: 'outside' }[kindOf(c.value)];
    const input = document.getElementById('sel-value');
    if (document.activeElement !== input) input.value = c.value;
  }

  depth() {
    return (document.getElementById('depth').value / 100) * 0.05 * (this.stats ? this.stats.unit : 1);
  }
}

// Precision slider: logarithmic, 0.1 (left) to 0.0025 (right).
const precisionToSlider = (p) => Math.round((100 * Math.log(0.1 / p)) / Math.log(40));
const sliderToPrecision = (v) => 0.1 / Math.pow(40, v / 100);

// --------------------------------------------------------------------------------------- pointer
Studio.prototype.ray = function (event) {
  const r = this.renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(((event.clientX - r.left) / r.width) * 2 - 1, -((event.clientY - r.top) / r.height) * 2 + 1);
  this.raycaster.setFromCamera(ndc, this.camera);
  return this.raycaster;
};

// The constraint drawn nearest to the pointer (within 8 pixels), the front-most when several are.
Studio.prototype.pickConstraint = function (event) {
  if (!this.constraints.points.visible) return -1;
  const r = this.renderer.domElement.getBoundingClientRect(), v = new THREE.Vector3();
  let best = -1, bestDepth = Infinity;
  this.constraints.list.forEach((c, i) => {
    v.fromArray(c.position).project(this.camera);
    const x = r.left + ((v.x + 1) / 2) * r.width, y = r.top + ((1 - v.y) / 2) * r.height;
    if (v.z < 1 && Math.hypot(x - event.clientX, y - event.clientY) <= 8 && v.z < bestDepth) {
      best = i;
      bestDepth = v.z;
    }
  });
  return best;
};

Studio.prototype.pickSurface = function (event) {
  const hits = this.ray(event).intersectObject(this.slots.mesh);
  return hits.length ? hits[0] : null;
};

Studio.prototype.onPointerDown = function (event) {
  if (event.button !== 0) return;
  this.down = { x: event.clientX, y: event.clientY };
  const index = this.pickConstraint(event);
  if (index < 0) return;
  this.controls.enabled = false;  // this drag moves a constraint, not the camera
  this.select(index);
  const p = new THREE.Vector3().fromArray(this.constraints.list[index].position);
  const normal = this.camera.getWorldDirection(new THREE.Vector3());
  this.drag = { index, plane: new THREE.Plane().setFromNormalAndCoplanarPoint(normal, p), pending: null,
                inFlight: false, first: true, ended: false };
};

Studio.prototype.onPointerMove = function (event) {
  const d = this.drag;
  if (!d || d.ended) return;
  const p = this.ray(event).ray.intersectPlane(d.plane, new THREE.Vector3());
  if (!p) return;
  this.constraints.moveLocally(d.index, p);
  d.pending = p;
  this.pumpDrag();
};

// Sends the latest drag position when no move is in flight (positions in between are skipped).
Studio.prototype.pumpDrag = function () {
  const d = this.drag;
  if (!d || d.inFlight) return;
  if (!d.pending) {
    if (d.ended) this.endDrag();
    return;
  }
  const p = d.pending;
  d.pending = null;
  d.inFlight = true;
  this.edit({ op: 'move', index: d.index, position: [p.x, p.y, p.z], merge: !d.first }, true).finally(() => {
    d.first = false;
    d.inFlight = false;
    this.pumpDrag();
  });
};

Studio.prototype.endDrag = function () {
  this.drag = null;
  this.queue(async () => {
    await this.pull();  // exact again
    await this.refreshState();
  });
};

Studio.prototype.onPointerUp = function (event) {
  if (event.button !== 0 || !this.down) return;
  const moved = Math.hypot(event.clientX - this.down.x, event.clientY - this.down.y) > 4;
  this.down = null;
  this.controls.enabled = true;
  if (this.drag) {
    this.drag.ended = true;
    this.pumpDrag();
    return;
  }
  if (moved) return;  // the camera was orbited
  const hit = this.pickSurface(event);
  if (!hit) return this.select(-1);
  const n = hit.face.normal.clone().normalize(), depth = this.depth();
  let p = hit.point, value = 0;
  if (event.shiftKey) { p = p.clone().addScaledVector(n, depth); value = depth; }
  else if (event.altKey || event.ctrlKey) { p = p.clone().addScaledVector(n, -depth); value = -depth; }
  this.edit({ op: 'add', position: [p.x, p.y, p.z], value }).then((s) => s && this.select(s.index));
};

// ------------------------------------------------------------------------------- measurements
function summary(values) {
  const v = values.slice().sort((a, b) => a - b);
  const at = (q) => v[Math.min(v.length - 1, Math.floor(q * v.length))];
  return { count: v.length, median: at(0.5), p90: at(0.9), max: v[v.length - 1] };
}

// Drags constraint `index` (default: the first on-surface one) along a small circle: `moves` updates one
// after the other, as a user's drag when the server keeps up; then undoes the drag. Latency = edit sent
// -> picture drawn when `sync` (each frame waited for), else -> frame submitted (the page's normal mode,
// which gives the drag rate a user sees).
Studio.prototype.benchDrag = async function ({ index = -1, moves = 40, radius = 0.01, sync = true } = {}) {
  if (index < 0) index = this.constraints.list.findIndex((c) => c.value === 0);  // an on-surface one
  const c = this.constraints.list[index].position.slice(), r = radius * this.stats.unit;
  this.latencies = [];
  this.drawTimes = [];
  this.syncDraw = sync;
  const t0 = performance.now();
  for (let k = 1; k <= moves; ++k) {
    const a = (2 * Math.PI * k) / moves;
    await this.edit({ op: 'move', index, position: [c[0] + r * Math.sin(a), c[1] + r * (1 - Math.cos(a)), c[2]],
                      merge: k > 1 }, true);
  }
  const seconds = (performance.now() - t0) / 1000;
  this.syncDraw = false;
  await this.queue(() => this.pull());
  const result = Object.assign(summary(this.latencies), { updates_per_second: moves / seconds,
                                                          draw_median: summary(this.drawTimes).median,
                                                          triangles: this.stats.triangles });
  await this.command('/api/undo');
  return result;
};

// Adds `count` on-surface constraints at mesh triangle centers (each undone after); edit-to-screen latency.
Studio.prototype.benchAdd = async function ({ count = 10 } = {}) {
  const lat = [];
  this.drawTimes = [];
  this.syncDraw = true;
  for (let k = 0; k < count; ++k) {
    const P = this.slots.geometry.attributes.position.array, slots = Array.from(this.slots.slotOf.values());
    const s = slots[Math.floor(((k + 0.5) / count) * slots.length)];
    const p = [0, 1, 2].map((j) => (P[9 * s + j] + P[9 * s + 3 + j] + P[9 * s + 6 + j]) / 3);
    await this.edit({ op: 'add', position: p, value: 0 });
    lat.push(this.latency);
    await this.command('/api/undo');
  }
  this.syncDraw = false;
  return Object.assign(summary(lat), { draw_median: summary(this.drawTimes.filter((_, k) => k % 2 === 0)).median,
                                       triangles: this.stats.triangles });
};

// Window coordinates of constraint i (for the browser test).
Studio.prototype.screenOf = function (i) {
  const p = new THREE.Vector3().fromArray(this.constraints.list[i].position).project(this.camera);
  const r = this.renderer.domElement.getBoundingClientRect();
  return { x: r.left + ((p.x + 1) / 2) * r.width, y: r.top + ((1 - p.y) / 2) * r.height };
};

// ------------------------------------------------------------------------------------------ wiring
function download(format) {
  const a = document.createElement('a');
  a.href = '/api/export?format=' + format;
  a.download = '';
  document.body.appendChild(a);
  a.click();
  a.remove();
}

async function main() {
  const studio = new Studio();
  window.studio = studio;
  const canvas = studio.renderer.domElement;
  canvas.addEventListener('pointerdown', (e) => studio.onPointerDown(e));
  window.addEventListener('pointermove', (e) => studio.onPointerMove(e));
  window.addEventListener('pointerup', (e) => studio.onPointerUp(e));
  const byId = (id) => document.getElementById(id);
  const deleteSelected = () => {
    const i = studio.constraints.selected;
    if (i < 0) return;
    studio.select(-1);
    studio.edit({ op: 'remove', index: i });
  };
  byId('undo').onclick = () => studio.command('/api/undo');
  byId('redo').onclick = () => studio.command('/api/redo');
  byId('delete').onclick = deleteSelected;
  byId('wireframe').onchange = (e) => { studio.slots.wire.visible = e.target.checked; studio.render(); };
  byId('show-constraints').onchange = (e) => { studio.constraints.points.visible = e.target.checked; studio.render(); };
  byId('precision').oninput = (e) => { byId('precision-value').textContent = sliderToPrecision(+e.target.value).toPrecision(3); };
  byId('precision').onchange = (e) => studio.setPrecision(sliderToPrecision(+e.target.value));
  const showDepth = () => { byId('depth-value').textContent = (byId('depth').value / 100 * 0.05).toPrecision(2) + ' x diagonal'; };
  byId('depth').oninput = showDepth;
  showDepth();
  const applyValue = () => {
    const v = parseFloat(byId('sel-value').value), i = studio.constraints.selected;
    if (i >= 0 && Number.isFinite(v)) studio.edit({ op: 'value', index: i, value: v });
  };
  byId('sel-apply').onclick = applyValue;
  byId('sel-value').onkeydown = (e) => { if (e.key === 'Enter') applyValue(); };
  byId('open').onchange = (e) => { if (e.target.files[0]) studio.load(e.target.files[0]).catch((x) => studio.showError(x)); e.target.value = ''; };
  byId('save-xyzv').onclick = () => download('xyzv');
  for (const b of document.querySelectorAll('[data-export]')) b.onclick = () => download(b.dataset.export);
  window.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'INPUT' && e.target.type !== 'checkbox' && e.target.type !== 'range') return;
    const key = e.key.toLowerCase(), mod = e.ctrlKey || e.metaKey;
    if (mod && key === 'z' && !e.shiftKey) studio.command('/api/undo');
    else if (mod && (key === 'y' || (key === 'z' && e.shiftKey))) studio.command('/api/redo');
    else if (key === 'delete' || key === 'backspace') deleteSelected();
    else if (key === 'w' && !mod) { byId('wireframe').click(); }
    else return;
    e.preventDefault();
  });
  await studio.queue(async () => {
    await studio.pull();
    await studio.refreshState();
  });
  studio.frame();
  studio.ready = true;
  studio.scheduleRefine();
}

main().catch((e) => {
  document.getElementById('error').textContent = 'vitri studio could not start: ' + (e.message || e);
  document.getElementById('error').hidden = false;
});
