// vitri studio: the page. Draws the mesh and the constraints with three.js, sends edits to the server's
// API (over its WebSocket, else HTTP) and applies the mesh deltas it answers with (docs/studio.md). No build step, no modules:
// three.min.js and OrbitControls.js (Debian libjs-three), then studio_buffers.js (the mesh and the
// constraints held in WebGL buffers) are loaded before this file.
'use strict';

// ------------------------------------------------------------------------------------------- server
// An answer that came over the socket, with the parts of a fetch Response the page reads.
class SocketAnswer {
  constructor(status, type, serverMs, body) {
    this.status = status;
    this.ok = status >= 200 && status < 300;
    this.statusText = '';
    this.body = body;
    const h = { 'content-type': type, 'server-timing': serverMs >= 0 ? 'app;dur=' + serverMs : '' };
    this.headers = { get: (name) => h[name.toLowerCase()] || null };
  }
  async arrayBuffer() { return this.body; }
  async text() { return new TextDecoder().decode(this.body); }
  async json() { return JSON.parse(await this.text()); }
}

// Requests go over the server's WebSocket when it is open (a fetch costs the page 2-4 ms more per
// update; docs/studio.md, "Socket"), else over HTTP; uploads (binary bodies) always over HTTP.
const api = {
  socket: null,
  pending: new Map(),  // request id -> {resolve, reject}
  nextId: 1,
  counts: { socket: {}, http: {} },  // requests sent per transport and API path (the tests read them)

  // Opens the socket on `port` of this host (null or ?socket=0: HTTP only). Resolves either way, within
  // 2 s (a port that a firewall drops would otherwise hold the page's start for the TCP timeout).
  connect(port) {
    if (!port || /[?&]socket=0/.test(location.search)) return Promise.resolve(false);
    return new Promise((resolve) => {
      const ws = new WebSocket('ws://' + location.hostname + ':' + port + '/api/socket');
      ws.binaryType = 'arraybuffer';
      const timer = setTimeout(() => { if (this.socket !== ws) { ws.close(); resolve(false); } }, 2000);
      ws.onopen = () => { clearTimeout(timer); this.socket = ws; resolve(true); };
      ws.onmessage = (e) => this.receive(e.data);
      ws.onclose = () => {
        if (this.socket === ws) this.socket = null;  // later requests over HTTP
        for (const p of this.pending.values()) p.reject(new Error('the connection to the studio closed'));
        this.pending.clear();
        resolve(false);
      };
    });
  },

  // An answer: uint32 id, uint32 status, float32 server ms, uint32 L, L bytes of content type, body.
  receive(buffer) {
    const v = new DataView(buffer);
    const id = v.getUint32(0, true), n = v.getUint32(12, true);
    const type = new TextDecoder().decode(new Uint8Array(buffer, 16, n)).trim();
    const answer = new SocketAnswer(v.getUint32(4, true), type, v.getFloat32(8, true), buffer.slice(16 + n));
    const p = this.pending.get(id);
    if (!p) return;
    this.pending.delete(id);
    p.resolve(answer);
  },

  send(method, path, body) {
    const id = this.nextId++;
    return new Promise((resolve, reject) => {
      this.pending.set(id, { resolve, reject });
      this.socket.send(id + ' ' + method + ' ' + path + '\n' + (body === undefined ? '' : body));
    });
  },

  async request(method, path, body) {
    if (method === 'POST' && body === undefined) body = '{}';
    let r;
    const socket = this.socket && (body === undefined || typeof body === 'string');
    const count = this.counts[socket ? 'socket' : 'http'], route = path.split('?')[0];
    count[route] = (count[route] || 0) + 1;
    if (socket) {
      r = await this.send(method, path, body);
    } else {
      const init = { method, headers: {} };
      if (method === 'POST') {
        init.body = body;
        if (typeof init.body === 'string') init.headers['Content-Type'] = 'application/json';
      }
      r = await fetch(path, init);
    }
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

// ------------------------------------------------------------------------------------------ studio
// Milliseconds the server spent on a response (its Server-Timing header; 0 when absent).
function serverMs(response) {
  const m = /dur=([0-9.]+)/.exec(response.headers.get('Server-Timing') || '');
  return m ? parseFloat(m[1]) : 0;
}

// True when WebGL is drawn by a software rasterizer (SwiftShader, llvmpipe): a probe context's renderer.
function softwareWebGL() {
  const gl = document.createElement('canvas').getContext('webgl');
  if (!gl) return false;
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  const lose = gl.getExtension('WEBGL_lose_context');
  if (lose) lose.loseContext();
  return /swiftshader|llvmpipe|softpipe|software/i.test(name);
}

class Studio {
  constructor() {
    this.view = document.getElementById('view');
    // A software rasterizer (no GPU) pays for every pixel on the CPU; multisampling doubles the cost of a
    // frame there (docs/benchmarks.md), so it is off unless asked for (?aa=1); ?aa=0 turns it off anywhere.
    this.software = softwareWebGL();
    const aa = /[?&]aa=([01])/.exec(location.search);
    this.renderer = new THREE.WebGLRenderer({ antialias: aa ? aa[1] === '1' : !this.software });
    this.lowResInteraction = this.software && !/[?&]lowres=0/.test(location.search);
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
    this.controls.addEventListener('change', () => this.present());
    this.slots = new MeshSlots(this.scene);
    this.constraints = new ConstraintPoints(this.scene);
    this.raycaster = new THREE.Raycaster();
    this.stats = null;
    this.latency = null;  // ms from the last edit's pointer event to its frame
    // Timing of every edit (see present()); benchmarks read and clear it.
    this.timings = [];
    this.waiting = [];    // timings of updates applied, waiting for their frame
    this.frame = null;    // promise of the next frame, while one is requested
    this.busy = Promise.resolve();  // edits run one after the other
    this.drag = null;
    this.pixel = new Uint8Array(4);
    // Benchmarks wait for each frame to be drawn (a pixel read back), so that the draw time is the GPU's
    // (here the software rasterizer's), not only the submission of the commands.
    this.syncDraw = false;
    this.idleTimer = 0;
    this.holdIdle = false;  // benchmarks: no idle work between the updates they time
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

  // Draws the scene. `interactive`: a frame for an edit or a drag; a software rasterizer draws those at
  // half resolution (a quarter of the pixels; ?lowres=0 turns it off), the next other frame (the exact
  // mesh when idle, orbiting, selecting) at full resolution again.
  render(interactive = false) {
    const ratio = window.devicePixelRatio * (interactive && this.lowResInteraction ? 0.5 : 1);
    if (this.renderer.getPixelRatio() !== ratio) this.renderer.setPixelRatio(ratio);
    this.constraints.material.size = this.constraints.size * ratio;
    this.renderer.render(this.scene, this.camera);
  }

  // Draws in the next animation frame (several updates within one frame are drawn once). `timing`: an
  // edit's record, completed when its frame is drawn: {event, sent, server, received, applied, frame,
  // drawn} (performance.now() ms; server: ms the server spent on the edit and its delta). Returns a
  // promise resolved after the frame.
  present(timing) {
    if (timing) {
      timing.applied = performance.now();
      this.waiting.push(timing);
    }
    if (!this.frame) {
      this.frame = new Promise((resolve) => requestAnimationFrame((vsync) => {
        const t = performance.now();
        this.render(this.waiting.length > 0 || this.drag !== null);
        if (this.syncDraw) this.waitForDraw();
        const drawn = performance.now();
        for (const w of this.waiting) {
          Object.assign(w, { frame: t, drawn, vsync });  // vsync: the frame's begin time (rAF's argument)
          this.latency = drawn - w.event;
          this.timings.push(w);
        }
        this.waiting = [];
        this.frame = null;
        resolve();
      }));
    }
    return this.frame;
  }

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

  // Fetches the mesh delta since the version held and applies it (not drawn yet: present()).
  // `approximate`: during a drag, triangles that moved less than the drag tolerance are not resent.
  async pull(timing, approximate) {
    const r = await api.request('GET', '/api/mesh?since=' + this.slots.version + (approximate ? '&exact=0' : ''));
    const buffer = await r.arrayBuffer();
    if (timing) timing.server += serverMs(r);
    this.applyMesh(buffer, timing, approximate);
  }

  // Applies a binary mesh delta (not drawn yet: present()).
  applyMesh(buffer, timing, approximate) {
    if (timing) {
      timing.received = performance.now();
      timing.bytes = buffer.byteLength;
    }
    const changed = this.slots.apply(buffer);
    this.slots.approximate = !!approximate;
    if (timing) timing.changed = changed;
  }

  // Brings the constraint list up to date: `delta` (from an edit's answer) when it follows the version
  // held, else the changes since that version (the whole list after a load or when too far behind).
  async syncConstraints(delta) {
    if (delta && this.constraints.apply(delta)) return;
    const r = await api.request('GET', '/api/constraints?since=' + this.constraints.version);
    if (!this.constraints.apply(await r.json())) throw new Error('constraint list out of step with the server');
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
      : s.preview
        ? 'preview at ' + s.precision.toPrecision(3) + ': the target follows'
        : 'refining while idle: at ' + (s.precision === null ? '-' : s.precision.toPrecision(3));
    const lat = this.latency === null ? '-' : this.latency.toFixed(1) + ' ms';
    document.getElementById('stats').textContent =
      'update (edit to screen) ' + lat + '\n' +
      'server: edit ' + s.edit_ms.toFixed(1) + ' ms, extract ' + s.extract_ms.toFixed(1) + ' ms\n' +
      s.triangles + ' triangles, ' + s.vertices + ' vertices\n' +
      s.constraints + ' constraints, ' + s.delaunay_vertices + ' Delaunay vertices' +
      (s.certify ? '\n' + (s.uncertified === 0 ? 'topology certified'
                                                : 'NOT certified: ' + s.uncertified + ' tetrahedra' +
                                                  (s.certify_budget_reached ? ' (insertion budget spent)' : '')) : '');
    this.updateSelection();
  }

  // Sends a POST (an edit, undo or redo), applies the mesh delta and the constraint changes it brought,
  // and draws. `event`: the time of the pointer or key event that caused it (the latency's start). The
  // mesh delta is approximate (vertices that moved less than the drag tolerance are not resent: with the
  // global function an edit moves every root a little); the exact mesh follows when the user is idle.
  // `select(answer)`: the constraint to select after it (-1: none).
  update(path, body, { event, approximate = true, select } = {}) {
    return this.queue(async () => {
      const timing = { event: event === undefined ? performance.now() : event, sent: performance.now(), server: 0 };
      // One round trip: the answer carries the mesh delta from the version held (docs/studio.md).
      const query = '?mesh=' + this.slots.version + (approximate ? '&exact=0' : '');
      const r = await api.request('POST', path + query, body === undefined ? undefined : JSON.stringify(body));
      timing.server += serverMs(r);
      const buffer = await r.arrayBuffer();
      const n = new DataView(buffer).getUint32(0, true);
      const s = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, n)));
      this.applyMesh(buffer.slice(4 + n), timing, approximate);
      await this.syncConstraints(s.constraint_delta);
      if (select !== undefined) this.select(select(s), false);  // in the same frame
      this.present(timing);
      this.showStats(s);
      // An edit shown on the server's coarser preview (docs/studio.md): the target mesh follows at once.
      this.scheduleRefine(s.preview ? 30 : 300);
      return s;
    });
  }

  // One edit (docs/studio.md); an added constraint is selected.
  edit(body, event) {
    return this.update('/api/edit', body, { event, select: body.op === 'add' ? (s) => s.index : undefined });
  }

  command(path, event) {
    return this.update(path, undefined, { event, select: () => -1 });
  }

  // While the user is idle: the exact mesh after approximate updates, then progressive refinement (the
  // server's next level, one request at a time).
  scheduleRefine(delay = 300) {
    clearTimeout(this.idleTimer);
    if (this.stats && this.stats.refined && !this.slots.approximate) return;
    this.idleTimer = setTimeout(() => {
      if (this.drag || this.holdIdle) return this.scheduleRefine();
      this.queue(async () => {
        if (this.slots.approximate) {
          await this.pull();
          this.present();
        }
        if (!this.stats.refined) {
          const s = await api.json('POST', '/api/refine');
          await this.pull();
          this.present();
          this.showStats(s);
        }
        this.scheduleRefine(50);
      });
    }, delay);
  }

  setPrecision(p) {
    clearTimeout(this.idleTimer);
    return this.queue(async () => {
      const s = await api.json('POST', '/api/refine', { precision: p });
      await this.pull();
      this.present();
      this.showStats(s);
      this.scheduleRefine(50);
    });
  }

  // The whole state after a start or a load: the mesh from nothing, the whole constraint list.
  async reload() {
    this.select(-1);
    await this.pull();
    await this.syncConstraints();
    this.showStats(await api.json('GET', '/api/stats'));
  }

  async load(file) {
    const bytes = await file.arrayBuffer();
    await this.queue(async () => {
      const loaded = await (await api.request('POST', '/api/load?name=' + encodeURIComponent(file.name), bytes)).json();
      // Points are read as a scan: what was set aside and how the normals were oriented.
      document.getElementById('scan-note').textContent = loaded.scan || '';
      await this.reload();
      this.frameModel();
      this.scheduleRefine();
    });
  }

  frameModel() {
    this.slots.geometry.computeBoundingSphere();
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

  select(index, draw = true) {
    this.constraints.select(index);
    this.updateSelection();
    if (draw) this.present();
  }

  updateSelection() {
    const i = this.constraints.selected, has = i >= 0 && i < this.constraints.count;
    document.getElementById('selection').hidden = !has;
    document.getElementById('delete').disabled = !has;
    if (!has) return;
    const value = this.constraints.value(i);
    document.getElementById('sel-index').textContent = i;
    document.getElementById('sel-kind').textContent = { on: 'on-surface', in: 'inside', out: 'outside' }[kindOf(value)];
    const input = document.getElementById('sel-value');
    if (document.activeElement !== input) input.value = value;
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

// Window coordinates and depth (NDC z) of constraint i.
Studio.prototype.screenOf = function (i, rect = this.renderer.domElement.getBoundingClientRect()) {
  const p = new THREE.Vector3().fromArray(this.constraints.position(i)).project(this.camera);
  return { x: rect.left + ((p.x + 1) / 2) * rect.width, y: rect.top + ((1 - p.y) / 2) * rect.height, z: p.z };
};

// The constraint the pointer picks: of those drawn within 8 pixels of it, the nearest to the pointer
// among the ones at most kPickDepthBand x the load diagonal behind the front-most of them (ties: the one
// in front). So a sample stays reachable beside the outside constraint drawn just in front of it (dense
// oriented points), and the far side of the model is not picked through the near one. One projection
// per constraint (a few ms for 10^5), with the camera's matrices applied by hand.
const kPickDepthBand = 0.02;
Studio.prototype.pickConstraint = function (event) {
  if (!this.constraints.points.visible) return -1;
  const r = this.renderer.domElement.getBoundingClientRect();
  const m = new THREE.Matrix4().multiplyMatrices(this.camera.projectionMatrix, this.camera.matrixWorldInverse).elements;
  const v = this.camera.matrixWorldInverse.elements;  // view depth: -(row 3 of the view matrix) . p
  const xyz = this.constraints.xyz, px = event.clientX, py = event.clientY;
  const near = [];  // [index, view depth, pixels from the pointer]
  let front = Infinity;
  for (let i = 0; i < this.constraints.count; ++i) {
    const x = xyz[3 * i], y = xyz[3 * i + 1], z = xyz[3 * i + 2];
    const w = m[3] * x + m[7] * y + m[11] * z + m[15];
    if (!(w > 0)) continue;
    if ((m[2] * x + m[6] * y + m[10] * z + m[14]) / w >= 1) continue;  // beyond the far plane
    const sx = r.left + (((m[0] * x + m[4] * y + m[8] * z + m[12]) / w + 1) / 2) * r.width;
    const sy = r.top + ((1 - (m[1] * x + m[5] * y + m[9] * z + m[13]) / w) / 2) * r.height;
    const d = Math.hypot(sx - px, sy - py);
    if (d > 8) continue;
    const depth = -(v[2] * x + v[6] * y + v[10] * z + v[14]);
    near.push([i, depth, d]);
    front = Math.min(front, depth);
  }
  const band = kPickDepthBand * (this.stats ? this.stats.unit : 1);
  let best = -1, bestD = Infinity, bestDepth = Infinity;
  for (const [i, depth, d] of near)
    if (depth <= front + band && (d < bestD || (d === bestD && depth < bestDepth))) {
      best = i;
      bestD = d;
      bestDepth = depth;
    }
  return best;
};

Studio.prototype.pickSurface = function (event) {
  return this.slots.raycast(this.ray(event).ray);
};

Studio.prototype.onPointerDown = function (event) {
  if (event.button !== 0) return;
  this.down = { x: event.clientX, y: event.clientY };
  const index = this.pickConstraint(event);
  if (index < 0) return;
  this.controls.enabled = false;  // this drag moves a constraint, not the camera
  this.select(index);
  const p = new THREE.Vector3().fromArray(this.constraints.position(index));
  const normal = this.camera.getWorldDirection(new THREE.Vector3());
  this.drag = { index, plane: new THREE.Plane().setFromNormalAndCoplanarPoint(normal, p), pending: null,
                event: 0, inFlight: false, first: true, ended: false };
};

Studio.prototype.onPointerMove = function (event) {
  const d = this.drag;
  if (!d || d.ended) return;
  const p = this.ray(event).ray.intersectPlane(d.plane, new THREE.Vector3());
  if (!p) return;
  this.constraints.moveLocally(d.index, p);
  if (!d.pending) d.event = event.timeStamp;  // the oldest move not sent yet: the latency's start
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
  this.edit({ op: 'move', index: d.index, position: [p.x, p.y, p.z], merge: !d.first }, d.event).finally(() => {
    d.first = false;
    d.inFlight = false;
    this.pumpDrag();
  });
};

Studio.prototype.endDrag = function () {
  this.drag = null;
  this.scheduleRefine(0);  // the exact mesh again
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
  this.edit({ op: 'add', position: [p.x, p.y, p.z], value }, event.timeStamp);
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
  const deleteSelected = (e) => {
    const i = studio.constraints.selected;
    if (i < 0) return;
    studio.select(-1);
    studio.edit({ op: 'remove', index: i }, e ? e.timeStamp : undefined);
  };
  byId('undo').onclick = (e) => studio.command('/api/undo', e.timeStamp);
  byId('redo').onclick = (e) => studio.command('/api/redo', e.timeStamp);
  byId('delete').onclick = deleteSelected;
  byId('wireframe').onchange = (e) => { studio.slots.wire.visible = e.target.checked; studio.present(); };
  byId('show-constraints').onchange = (e) => { studio.constraints.points.visible = e.target.checked; studio.present(); };
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
    if (mod && key === 'z' && !e.shiftKey) studio.command('/api/undo', e.timeStamp);
    else if (mod && (key === 'y' || (key === 'z' && e.shiftKey))) studio.command('/api/redo', e.timeStamp);
    else if (key === 'delete' || key === 'backspace') deleteSelected(e);
    else if (key === 'w' && !mod) { byId('wireframe').click(); }
    else return;
    e.preventDefault();
  });
  await api.connect((await api.json('GET', '/api/stats')).socket_port);
  await studio.queue(() => studio.reload());
  studio.frameModel();
  studio.ready = true;
  studio.scheduleRefine();
}

main().catch((e) => {
  document.getElementById('error').textContent = 'vitri studio could not start: ' + (e.message || e);
  document.getElementById('error').hidden = false;
});
