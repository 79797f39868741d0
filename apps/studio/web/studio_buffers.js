// vitri studio: what the page holds and draws, in WebGL buffers changed in place: the mesh as triangle
// slots (from the server's mesh deltas) and the constraint list (from its constraint deltas);
// docs/studio.md. Loaded after three.js, before studio.js.
'use strict';

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
    this.mesh.frustumCulled = this.wire.frustumCulled = false;
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
    const old = this.geometry.attributes.position.array;
    for (const id of removed) {
      const slot = this.slotOf.get(id);
      if (slot === undefined) continue;
      this.slotOf.delete(id);
      for (let i = 9 * slot; i < 9 * slot + 9; ++i) old[i] = 0;
      this.free.push(slot);
      if (slot < lo) lo = slot;
      if (slot > hi) hi = slot;
    }
    if (this.used + nAdded > this.capacity && this.free.length < nAdded) {
      this.grow(Math.max(2 * this.capacity, this.used + nAdded));
      lo = 0; hi = Math.max(hi, this.used - 1);
    }
    // Plain loops over the 9 floats of each triangle (no subarray objects: 10^4 triangles per delta).
    const positions = this.geometry.attributes.position.array, normals = this.geometry.attributes.normal.array;
    for (let k = 0; k < nAdded; ++k) {
      const slot = this.free.length ? this.free.pop() : this.used++;
      this.slotOf.set(added[k], slot);
      for (let i = 0, d = 9 * slot, o = 9 * k; i < 9; ++i) {
        positions[d + i] = pos[o + i];
        normals[d + i] = nrm[o + i];
      }
      if (slot < lo) lo = slot;
      if (slot > hi) hi = slot;
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
    // No bounding sphere per delta (a pass over the whole mesh): the mesh is never frustum-culled, clicks
    // use raycast() below, and framing the model computes the sphere.
    this.geometry.boundingSphere = null;
    this.version = version;
    this.triangles = this.slotOf.size;
    return nRemoved + nAdded;
  }

  // The nearest triangle the ray (THREE.Ray) crosses at t > 0, either side: { point, face: { normal },
  // distance } as three.js's raycast gives it (normal: (b - a) x (c - a), unit), or null. Moller-Trumbore
  // on the slots' float32 positions, zeroed slots skipped (det 0): several times faster than
  // Mesh.raycast's per-triangle objects (a click on 10^5 triangles).
  raycast(ray) {
    const P = this.geometry.attributes.position.array;
    const { x: ox, y: oy, z: oz } = ray.origin, { x: dx, y: dy, z: dz } = ray.direction;
    let best = Infinity, bestSlot = -1;
    for (let s = 0, o = 0; s < this.used; ++s, o += 9) {
      const ax = P[o], ay = P[o + 1], az = P[o + 2];
      const e1x = P[o + 3] - ax, e1y = P[o + 4] - ay, e1z = P[o + 5] - az;
      const e2x = P[o + 6] - ax, e2y = P[o + 7] - ay, e2z = P[o + 8] - az;
      const px = dy * e2z - dz * e2y, py = dz * e2x - dx * e2z, pz = dx * e2y - dy * e2x;
      const det = e1x * px + e1y * py + e1z * pz;
      if (det === 0) continue;
      const inv = 1 / det, tx = ox - ax, ty = oy - ay, tz = oz - az;
      const u = (tx * px + ty * py + tz * pz) * inv;
      if (!(u >= 0 && u <= 1)) continue;
      const qx = ty * e1z - tz * e1y, qy = tz * e1x - tx * e1z, qz = tx * e1y - ty * e1x;
      const v = (dx * qx + dy * qy + dz * qz) * inv;
      if (!(v >= 0 && u + v <= 1)) continue;
      const t = (e2x * qx + e2y * qy + e2z * qz) * inv;
      if (t > 0 && t < best) {
        best = t;
        bestSlot = s;
      }
    }
    if (bestSlot < 0) return null;
    const o = 9 * bestSlot, a = new THREE.Vector3(P[o], P[o + 1], P[o + 2]);
    const e1 = new THREE.Vector3(P[o + 3], P[o + 4], P[o + 5]).sub(a);
    const e2 = new THREE.Vector3(P[o + 6], P[o + 7], P[o + 8]).sub(a);
    return { point: ray.at(best, new THREE.Vector3()), face: { normal: e1.cross(e2).normalize() }, distance: best };
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
const SELECTED_COLOR = new THREE.Color(0xffffff);
const PLAIN_POINTS_ABOVE = 5000;
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

// The constraint list the page holds (version `version` of the server's): positions (float64, as sent),
// values and ids in typed arrays, drawn from a float32 copy. Changes from the server's constraint deltas
// (docs/studio.md) are applied in place; only the range of points that changed is uploaded.
class ConstraintPoints {
  constructor(scene) {
    this.count = 0;
    this.capacity = 0;
    this.version = 0;
    this.selected = -1;
    this.disc = discTexture();
    this.size = 11;  // CSS pixels (Studio.render() scales it to the drawing buffer)
    this.material = new THREE.PointsMaterial({ size: 11, vertexColors: THREE.VertexColors, map: this.disc,
                                               alphaTest: 0.5, sizeAttenuation: false });
    this.points = new THREE.Points(new THREE.BufferGeometry(), this.material);
    this.points.renderOrder = 1;
    this.points.frustumCulled = false;  // (no bounding sphere to keep up to date)
    scene.add(this.points);
    this.grow(256);
  }

  grow(capacity) {
    const old = this.capacity ? { xyz: this.xyz, values: this.values, ids: this.ids } : null;
    this.xyz = new Float64Array(3 * capacity);
    this.values = new Float64Array(capacity);
    this.ids = new Float64Array(capacity);
    if (old) { this.xyz.set(old.xyz); this.values.set(old.values); this.ids.set(old.ids); }
    const g = this.points.geometry;
    const pos = new Float32Array(3 * capacity), col = new Float32Array(3 * capacity);
    if (old) { pos.set(g.attributes.position.array); col.set(g.attributes.color.array); }
    for (const [name, array] of [['position', pos], ['color', col]]) {
      const attribute = new THREE.BufferAttribute(array, 3);
      attribute.setUsage(THREE.DynamicDrawUsage);
      g.setAttribute(name, attribute);
    }
    this.capacity = capacity;
    this.dirty = [0, this.count];
  }

  position(i) { return [this.xyz[3 * i], this.xyz[3 * i + 1], this.xyz[3 * i + 2]]; }
  value(i) { return this.values[i]; }

  // Constraint i's point and colour into the drawn buffers.
  write(i) {
    const pos = this.points.geometry.attributes.position.array, col = this.points.geometry.attributes.color.array;
    for (let k = 0; k < 3; ++k) pos[3 * i + k] = this.xyz[3 * i + k];
    const color = i === this.selected ? SELECTED_COLOR : KIND_COLORS[kindOf(this.values[i])];
    col[3 * i] = color.r; col[3 * i + 1] = color.g; col[3 * i + 2] = color.b;
    this.touch(i, i + 1);
  }

  touch(lo, hi) {
    this.dirty = this.dirty ? [Math.min(this.dirty[0], lo), Math.max(this.dirty[1], hi)] : [lo, hi];
  }

  // One change {op: add|remove|update, index, id, position, value}. Throws when it does not fit the
  // list held (the caller then asks for the whole list).
  change(c) {
    const i = c.index;
    if (c.op === 'add') {
      if (i !== this.count) throw new Error('constraint delta out of order');
      if (this.count === this.capacity) this.grow(2 * this.capacity);
      ++this.count;
    } else if (!(i >= 0 && i < this.count)) {
      throw new Error('constraint delta names index ' + i + ' of ' + this.count);
    }
    if (c.op === 'remove') {  // later constraints shift down by one, as on the server
      const g = this.points.geometry.attributes;
      this.xyz.copyWithin(3 * i, 3 * i + 3, 3 * this.count);
      g.position.array.copyWithin(3 * i, 3 * i + 3, 3 * this.count);
      g.color.array.copyWithin(3 * i, 3 * i + 3, 3 * this.count);
      this.values.copyWithin(i, i + 1, this.count);
      this.ids.copyWithin(i, i + 1, this.count);
      this.touch(i, this.count);
      --this.count;
      if (this.selected === i) this.selected = -1;
      else if (this.selected > i) --this.selected;
      return;
    }
    this.xyz.set(c.position, 3 * i);
    this.values[i] = c.value;
    this.ids[i] = c.id;
    this.write(i);
  }

  // A constraint delta {base, version, full, changes}. Returns false when it does not apply to the list
  // held (another base version): the caller asks for the changes since the version held.
  apply(delta) {
    if (!delta.full && delta.base !== this.version) return false;
    if (delta.full) { this.count = 0; this.selected = -1; }
    try {
      for (const c of delta.changes) this.change(c);
    } catch (e) {
      this.version = 0;  // out of step: the next sync takes the whole list
      return false;
    }
    this.version = delta.version;
    this.upload();
    return true;
  }

  // Uploads the range of points that changed.
  upload() {
    const g = this.points.geometry;
    if (this.dirty && this.dirty[1] > this.dirty[0]) {
      for (const name of ['position', 'color']) {
        const a = g.attributes[name];
        a.updateRange.offset = 3 * this.dirty[0];
        a.updateRange.count = 3 * (this.dirty[1] - this.dirty[0]);
        a.needsUpdate = true;
      }
    }
    this.dirty = null;
    g.setDrawRange(0, this.count);
    // Discs of 11 pixels for a few constraints, down to 5 for thousands (so that the surface shows).
    this.size = Math.max(5, Math.min(11, 60 / Math.sqrt(Math.max(this.count, 1))));
    // Many constraints: small plain squares. A textured disc is cut out per fragment (alpha test), which
    // a software rasterizer pays for dearly (about 1 s a frame for 10^5 constraints, docs/benchmarks.md).
    const plain = this.count > PLAIN_POINTS_ABOVE;
    if (plain !== (this.material.map === null)) {
      this.material.map = plain ? null : this.disc;
      this.material.alphaTest = plain ? 0 : 0.5;
      this.material.needsUpdate = true;
    }
    if (plain) this.size = 3;
  }

  select(index) {
    const old = this.selected;
    this.selected = index;
    if (old >= 0 && old < this.count) this.write(old);
    if (index >= 0) this.write(index);
    this.upload();
  }

  moveLocally(index, p) {
    this.xyz[3 * index] = p.x; this.xyz[3 * index + 1] = p.y; this.xyz[3 * index + 2] = p.z;
    this.write(index);
    this.upload();
  }
}
