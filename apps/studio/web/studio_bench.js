// vitri studio: measurements in the page (docs/benchmarks.md, tests/apps/studio_browser.py --bench).
// Pointer events are synthesized on the canvas, so that a latency runs from the event through the
// page's own handlers (picking, raycast, request, delta, constraint changes) to the frame drawn after
// the update (Studio.present(): the animation frame after applying, with a pixel read back so that the
// drawing is finished). Loaded after studio.js; nothing here runs unless a script calls it.
'use strict';

function summary(values) {
  const v = values.filter((x) => Number.isFinite(x)).sort((a, b) => a - b);
  if (!v.length) return { count: 0 };
  const at = (q) => v[Math.min(v.length - 1, Math.floor(q * v.length))];
  const r = (x) => Math.round(x * 100) / 100;
  return { count: v.length, p50: r(at(0.5)), p90: r(at(0.9)), max: r(v[v.length - 1]) };
}

// The begin times of every animation frame while a benchmark runs (a loop of empty rAF callbacks), so
// that an update can be checked against the frames that began between its event and the frame that drew
// it: none means it was drawn in the first frame after the event, the soonest a display shows it.
// Only with hardware WebGL: with a software rasterizer every extra frame costs CPU time that the server
// and the page share (frames_missed then has count 0).
function frameClock(studio) {
  return studio.software ? null : new FrameClock();
}

class FrameClock {
  constructor() {
    this.begins = [];
    this.running = true;
    const tick = (t) => {
      this.begins.push(t);
      if (this.running) requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  }
  stop() { this.running = false; }
  missed(t) { return this.begins.filter((b) => b > t.event && b < t.vsync).length; }
}

// Where the time of updates went: input (event to request sent: handlers, raycast, queue), server (its
// Server-Timing: edit + delta), transfer (request to delta received, less the server: HTTP or socket,
// JSON parse), apply (mesh delta and constraint changes into the buffers), wait (to the animation frame),
// draw (render + read back), total (event to drawn); frames_missed (with a FrameClock: frames that began
// after the event, before the one that drew the update).
function breakdown(timings, clock) {
  const of = (f) => summary(timings.map(f));
  return {
    frames_missed: clock ? of((t) => clock.missed(t)) : { count: 0 },
    total: of((t) => t.drawn - t.event), input: of((t) => t.sent - t.event), server: of((t) => t.server),
    transfer: of((t) => t.received - t.sent - t.server), apply: of((t) => t.applied - t.received),
    wait: of((t) => t.frame - t.applied), draw: of((t) => t.drawn - t.frame),
    delta_kb: of((t) => t.bytes / 1024), triangles_changed: of((t) => t.changed),
  };
}

Studio.prototype.pointer = function (type, x, y) {
  const target = type === 'pointerdown' ? this.renderer.domElement : window;
  target.dispatchEvent(new PointerEvent(type, { clientX: x, clientY: y, button: 0, buttons: type === 'pointerup' ? 0 : 1,
                                                bubbles: true, pointerType: 'mouse', isPrimary: true }));
};

// Resolves when every queued request is done and its frame drawn.
Studio.prototype.settled = async function () {
  for (;;) {
    const busy = this.busy;
    await busy;
    if (this.frame) await this.frame;
    if (busy === this.busy && !this.frame) return;
  }
};

// Window points where a click hits the surface: a grid over the middle of the view.
Studio.prototype.surfacePixels = function (count) {
  const r = this.renderer.domElement.getBoundingClientRect(), found = [];
  for (let k = 0; k < 400 && found.length < count; ++k) {
    const x = r.left + r.width * (0.3 + 0.4 * (((k * 0.618034) % 1))), y = r.top + r.height * (0.3 + 0.4 * ((k * 0.41421) % 1));
    if (this.pickSurface({ clientX: x, clientY: y })) found.push({ x, y });
  }
  return found;
};

// Clicks the surface `count` times (on-surface constraints; the constraint discs are hidden, as with the
// "constraints" box, so that the click adds instead of selecting), each followed by an undo (Ctrl+Z path).
Studio.prototype.benchAdd = async function ({ count = 12 } = {}) {
  await this.settled();
  const shown = this.constraints.points.visible;
  this.constraints.points.visible = false;
  this.syncDraw = this.holdIdle = true;
  const adds = [], undos = [], target = [], clock = frameClock(this);
  for (const p of this.surfacePixels(count)) {
    this.timings = [];
    const before = this.constraints.count;
    const clicked = performance.now();
    this.pointer('pointerdown', p.x, p.y);
    this.pointer('pointerup', p.x, p.y);
    await this.settled();
    if (this.constraints.count !== before + 1) throw new Error('the click did not add a constraint');
    adds.push(...this.timings);
    // An add shown on the server's coarser preview (docs/studio.md): the target mesh follows, as the idle
    // step brings it (without its 30 ms delay); timed from the click to that mesh drawn.
    if (this.stats.preview) {
      await this.benchTarget();
      target.push(performance.now() - clicked);
    }
    this.timings = [];
    await this.command('/api/undo', performance.now());
    await this.settled();
    undos.push(...this.timings);
    if (this.stats.preview) await this.benchTarget();  // the next click starts from the target mesh
  }
  if (clock) clock.stop();
  this.syncDraw = this.holdIdle = false;
  this.constraints.points.visible = shown;
  return { add: breakdown(adds, clock), undo: breakdown(undos, clock), target_after_add: summary(target),
           triangles: this.slots.triangles };
};

// The idle step's work at once: refinement requests until the target is reached, its mesh pulled and drawn.
Studio.prototype.benchTarget = async function () {
  await this.queue(async () => {
    let s;
    do s = await api.json('POST', '/api/refine'); while (!s.refined);
    await this.pull();
    this.present();
    this.showStats(s);
  });
  await this.settled();
};

// The on-surface constraint nearest to the middle of the view that the pointer picks at its own place on
// screen (the front-most there: with dense oriented points an outside constraint usually lies in front
// of its sample, and dragging it barely moves the surface), and where it is on screen.
Studio.prototype.draggable = function () {
  const r = this.renderer.domElement.getBoundingClientRect(), cx = r.left + r.width / 2, cy = r.top + r.height / 2;
  const near = [];
  for (let i = 0; i < this.constraints.count; ++i) {
    if (this.constraints.value(i) !== 0) continue;
    const s = this.screenOf(i, r);
    if (s.z < 1) near.push({ i, d: Math.hypot(s.x - cx, s.y - cy) });
  }
  near.sort((a, b) => a.d - b.d);
  for (const { i } of near.slice(0, 200)) {
    const s = this.screenOf(i, r);
    if (this.pickConstraint({ clientX: s.x, clientY: s.y }) === i) return Object.assign(s, { index: i });
  }
  return null;
};

// Drags a constraint along a circle of `radius` pixels with synthesized pointer events, then releases
// it and undoes the drag. `live` false: each move waits until the previous one is drawn (latency of one
// update, frames read back). `live` true: one move per animation frame for `moves` frames whatever the
// server's pace, as a user's hand (the page sends the latest position when the previous update is done);
// drag updates per second = updates drawn / time.
Studio.prototype.benchDrag = async function ({ moves = 60, radius = 12, live = false } = {}) {
  await this.settled();
  const start = this.draggable();
  if (!start) throw new Error('no on-surface constraint to drag in view');
  this.syncDraw = !live;
  this.holdIdle = true;
  this.timings = [];
  const clock = frameClock(this);
  this.pointer('pointerdown', start.x, start.y);
  if (!this.drag || this.drag.index !== start.index) throw new Error('the pointer did not pick the constraint');
  const t0 = performance.now();
  for (let k = 1; k <= moves; ++k) {
    const a = (2 * Math.PI * k) / moves;
    this.pointer('pointermove', start.x + radius * Math.sin(a), start.y - radius * (1 - Math.cos(a)));
    if (live) await new Promise((resolve) => requestAnimationFrame(resolve));
    else await this.settled();
  }
  const end = performance.now(), seconds = (end - t0) / 1000;
  this.pointer('pointerup', start.x, start.y);
  await this.settled();
  const timings = this.timings.filter((t) => !live || t.drawn <= end);  // live: those drawn while moving
  if (clock) clock.stop();
  this.syncDraw = this.holdIdle = false;
  await this.command('/api/undo');
  await this.settled();
  return Object.assign(breakdown(timings, clock), { index: start.index, moves, updates: timings.length,
                                             updates_per_second: timings.length / seconds,
                                             triangles: this.slots.triangles });
};
