// The replay viewer of kinetic traces (kinetic-trace/2 or /1, docs/trace-format.md; docs/viewer.md).
// Plain JavaScript, no library: it reads the trace embedded in the page, evaluates every
// object's motion at the displayed time (the scenario's polynomials, updates and inserts and
// removes of the timeline), and draws the objects and the structure's latest snapshot on a
// canvas. window.kineticViewer is the page's state and controls, for the tests.
"use strict";
(function () {
  const COLORS = {
    point: "#1f77b4", highlight: "#ff8000", hull: "#2ca02c", cell: "#9a9a9a", triangle: "#b8b8b8",
    pair: "#d62728", query: "#0a58ca", now: "#d62728", event: "#444444", box: "#1f77b4",
    node: "#8c564b", front: "#9467bd", split: "#7f7f7f", axis: "#444444",
    trajectory: "rgba(31,119,180,0.55)",
  };

  // ---- The trace ------------------------------------------------------------------------------
  const raw = document.getElementById("kinetic-trace").textContent;
  const lines = raw.split("\n").filter((l) => l.trim().length > 0);
  const info = document.getElementById("info");
  if (lines.length === 0) { info.textContent = "no trace in this page"; return; }
  const header = JSON.parse(lines[0]);
  if (header.format !== "kinetic-trace/2" && header.format !== "kinetic-trace/1") {
    info.textContent = "not a kinetic-trace/2 (or /1) trace: " + header.format;
    return;
  }
  const sc = header.scenario;
  const objectsAre = sc.objects_are || "points";
  const dim = sc.dimension;
  const steps = [];      // events, internal events, ops and queries, in trace order
  const snapshots = [];  // each with .step: the step it follows (-1: before the first)
  let endLine = null;
  // kinetic-trace/2: events come in lines of columns ("events": each event's time the one before
  // plus dt * 2^q, its type a place in the header's kinds), made here the steps of /1's lines;
  // a snapshot line without "t" is at the line before's time; a patch applies to the snapshot
  // before with the swap events since it applied.
  const types = header.kinds || [];
  let lastT = sc.start_time, swaps = [];
  for (let i = 1; i < lines.length; ++i) {
    const o = JSON.parse(lines[i]);
    if (o.k === "events") {
      const unit = Math.pow(2, o.q);
      let t = o.t !== undefined ? o.t : lastT;
      for (let e = 0; e < o.dt.length; ++e) {
        t = t + o.dt[e] * unit;
        const type = types[o.kind[e]];
        const s = type[0] === "internal" ? { t: t, k: "internal" }
                : { t: t, k: "event", kind: type[0], ids: o.ids[e] };
        if (type.length > 1) { s.axis = type[1]; if (type[0] === "swap") swaps.push([type[1], s.ids[0], s.ids[1]]); }
        s.index_in_steps = steps.length;
        steps.push(s);
      }
      lastT = t;
      continue;
    }
    if (o.t === undefined) o.t = lastT;
    lastT = o.t;
    if (o.k === "snapshot") { o.step = steps.length - 1; o.swaps = swaps; swaps = []; snapshots.push(o); patchedLine(o, snapshots.length - 1); }
    else if (o.k === "end") endLine = o;
    else { o.index_in_steps = steps.length; steps.push(o); }
  }
  // A snapshot line holds the whole structure ("snapshot") or its changes against the line before
  // ("patch": [path, value] pairs, docs/trace-format.md): a patched one is rebuilt when asked for,
  // from the last whole one before it (or the last one rebuilt, when it lies between), as a new
  // object, and only the last one rebuilt is kept (a long trace's would not fit in memory).
  let rebuilt = null;  // { k, snapshot }
  function patchedLine(o, k) {
    if (o.snapshot !== undefined) return;
    Object.defineProperty(o, "snapshot", { get: () => snapshotAt(k) });
  }
  /// The place of each id in an order's ids: a table by id when the ids are small, else a Map.
  function placesOf(ids) {
    let max = -1, small = true;
    for (const id of ids) { if (!(Number.isInteger(id) && id >= 0)) small = false; else if (id > max) max = id; }
    if (small && max < 4 * ids.length + 1024) {
      const table = new Int32Array(max + 1).fill(-1);
      ids.forEach((id, p) => { table[id] = p; });
      return { get: (id) => table[id], set: (id, p) => { table[id] = p; } };
    }
    const map = new Map();
    ids.forEach((id, p) => map.set(id, p));
    return { get: (id) => map.get(id), set: (id, p) => map.set(id, p) };
  }
  /// Applies swap events ([axis, a, b]: a and b exchange their places in the order of the axis)
  /// to a snapshot; `places` (per axis, made when first needed) lasts across calls while no patch
  /// changes the orders.
  function applySwaps(s, list, places) {
    for (const [axis, a, b] of list) {
      const ids = s.orders[axis].ids;
      if (!places[axis]) places[axis] = placesOf(ids);
      const at = places[axis];
      const pa = at.get(a), pb = at.get(b);
      ids[pa] = b; ids[pb] = a; at.set(a, pb); at.set(b, pa);
    }
  }
  function snapshotAt(k) {
    if (rebuilt && rebuilt.k === k) return rebuilt.snapshot;
    let from = k;
    while (from > 0 && snapshots[from].patch) --from;
    const start = rebuilt && rebuilt.k > from && rebuilt.k < k ? rebuilt.k : from;
    let s = structuredClone(start === from ? snapshots[from].snapshot : rebuilt.snapshot);
    let places = [];
    for (let i = start + 1; i <= k; ++i) {
      applySwaps(s, snapshots[i].swaps, places);
      if (snapshots[i].patch.length > 0) places = [];  // the orders may have changed
      for (const [path, value] of snapshots[i].patch) {
        if (path.length === 0) { s = structuredClone(value); continue; }
        let at = s;
        for (let j = 0; j + 1 < path.length; ++j) at = at[path[j]];
        at[path[path.length - 1]] = structuredClone(value);
      }
    }
    rebuilt = { k: k, snapshot: s };
    return s;
  }
  const t0 = sc.start_time;
  let t1 = sc.end_time !== undefined && sc.end_time !== null ? sc.end_time
         : (endLine ? endLine.t : (steps.length ? steps[steps.length - 1].t : t0 + 1));
  if (!(t1 > t0)) t1 = t0 + 1;
  const opsUpTo = new Int32Array(steps.length);  // the ops among steps 0..i
  for (let i = 0, n = 0; i < steps.length; ++i) { if (steps[i].k === "op") ++n; opsUpTo[i] = n; }

  // ---- Motions: per object, its pieces [from, to) with coefficients, origin, half extents. ----
  const objects = new Map();  // id -> {id, pieces: [...]}
  function piece(from, motion, origin, half) {
    return { from: from, to: Infinity, c: motion, o: origin || 0, h: half || null };
  }
  for (const ob of sc.objects) {
    objects.set(ob.id, { id: ob.id, pieces: [piece(t0, ob.motion, ob.origin, ob.half_extents)] });
  }
  for (const s of steps) {
    if (s.k !== "op") continue;
    const op = sc.timeline[s.index];
    const o = objects.get(op.id);
    if (op.op === "insert") {
      objects.set(op.id, { id: op.id, pieces: [piece(s.t, op.motion, op.origin, op.half_extents)] });
    } else if (op.op === "update" && o) {
      const last = o.pieces[o.pieces.length - 1];
      last.to = s.t;
      o.pieces.push(piece(s.t, op.motion, op.origin, op.half_extents || last.h));
    } else if (op.op === "remove" && o) {
      o.pieces[o.pieces.length - 1].to = s.t;
    }
  }
  const objectList = Array.from(objects.values());
  function pieceAt(o, t) {
    for (let k = o.pieces.length - 1; k >= 0; --k) {
      const p = o.pieces[k];
      if (p.from <= t) return t < p.to || (p.to === Infinity) ? p : null;
    }
    return null;
  }
  function evalCoord(p, a, t) {
    const c = p.c[a];
    const dt = t - p.o;
    let v = 0;
    for (let j = c.length - 1; j >= 0; --j) v = v * dt + c[j];
    return v;
  }
  // Positions at t (2-D: coordinates 0 and 1; 1-D: [t, x]; intervals: [lo, hi]), for every object
  // at once in typed arrays over the objects' dense indexes (objectList's order): no Map of 10^5
  // entries and arrays per frame. get(id) gives [x, y, piece] (undefined when not alive at t),
  // has(id), size (the objects alive), and x, y, piece by dense index for the loops over all.
  const N = objectList.length;
  const objectIds = objectList.map((o) => o.id);
  const denseIndex = new Map();
  objectList.forEach((o, k) => denseIndex.set(o.id, k));
  // The same as a table when the ids are small integers (a lookup 10^5 times a snapshot).
  const idTable = objectIds.every((id) => Number.isInteger(id) && id >= 0 && id < 4 * N + 1024)
    ? new Int32Array(4 * N + 1024).fill(-1) : null;
  if (idTable) objectIds.forEach((id, k) => { idTable[id] = k; });
  function denseOf(id) {  // the dense index of an id, -1 for none
    if (idTable) return Number.isInteger(id) && id >= 0 && id < idTable.length ? idTable[id] : -1;
    const k = denseIndex.get(id);
    return k === undefined ? -1 : k;
  }
  function Positions() {
    this.t = NaN; this.size = 0;
    this.x = new Float64Array(N); this.y = new Float64Array(N); this.piece = new Array(N).fill(null);
  }
  Positions.prototype.get = function (id) {
    const k = denseIndex.get(id);
    if (k === undefined || !this.piece[k]) return undefined;
    return [this.x[k], this.y[k], this.piece[k]];
  };
  Positions.prototype.has = function (id) {
    const k = denseIndex.get(id);
    return k !== undefined && this.piece[k] !== null;
  };
  Positions.prototype.entries = function* () {  // [id, [x, y, piece]] of the alive, in order
    for (let k = 0; k < N; ++k) if (this.piece[k] !== null) yield [objectIds[k], [this.x[k], this.y[k], this.piece[k]]];
  };
  function positionsAt(t, into) {
    const out = into || new Positions();
    out.t = t; out.size = 0;
    const X = out.x, Y = out.y, P = out.piece;
    for (let k = 0; k < N; ++k) {
      const p = pieceAt(objectList[k], t);
      P[k] = p;
      if (!p) continue;
      ++out.size;
      X[k] = evalCoord(p, 0, t);
      Y[k] = p.c.length > 1 ? evalCoord(p, 1, t) : 0;
    }
    return out;
  }
  // The displayed time's positions, computed once per time (a pan, a zoom or a redraw reuse them).
  const shown = new Positions();
  function shownPositions(t) { return shown.t === t ? shown : positionsAt(t, shown); }

  // ---- The view ------------------------------------------------------------------------------
  const oneD = dim === 1 || objectsAre === "intervals";
  // In 1-D the view is the trajectories over the whole window: nothing to follow, no follow box.
  if (oneD) document.getElementById("follow").closest("label").hidden = true;
  const canvas = document.getElementById("canvas");
  const ctx = canvas.getContext("2d");
  let W = 0, H = 0;
  const view = { cx: 0, cy: 0, sx: 1, sy: 1 };  // world (cx, cy) at the centre; pixels per unit
  function toScreen(x, y) { return [(x - view.cx) * view.sx + W / 2, H / 2 - (y - view.cy) * view.sy]; }
  function toWorld(px, py) { return [(px - W / 2) / view.sx + view.cx, view.cy - (py - H / 2) / view.sy]; }

  let T = t0;           // displayed time
  let current = -1;     // the last step at or before T (-1: none yet)
  let playing = false;
  let speed = 1;
  let showInternal = false;
  let treeLevels = 4;  // how deep the snapshots' trees are drawn
  const frameTimes = [];

  function stepAtOrBefore(t) {
    let lo = -1, hi = steps.length - 1;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (steps[mid].t <= t) lo = mid; else hi = mid - 1;
    }
    return lo;
  }
  function snapshotFor(step) {
    let lo = -1, hi = snapshots.length - 1;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (snapshots[mid].step <= step) lo = mid; else hi = mid - 1;
    }
    return lo >= 0 ? snapshots[lo] : null;
  }

  // The room of the axes' labels (left, bottom) and of the 1-D view's panels (a tournament's tree
  // at the top, the canonical sets at the right), in CSS pixels: the fitted view covers none.
  const AXIS_LEFT = 60, AXIS_BOTTOM = 32;
  function panelRoom() {
    const s0 = snapshots.length ? snapshots[0].snapshot : {};
    let top = 0, right = 0;
    if (oneD && s0.tops) top = s0.tops.slice(0, 2).reduce((acc, tp) => acc + (tp.levels ? tournamentPanelHeight(tp) + 8 : 0), 0);
    if (oneD && s0.endpoints && s0.nodes) right = canonicalPanelWidth() + 8;
    return [top, right];
  }
  // The view fitted to the objects. In the plane it follows them: each frame is fitted to where
  // they are at the displayed time, until a drag or the wheel takes the view over ("fit" gives it
  // back). In 1-D the view is their trajectories over the whole window (time runs along x).
  let follow = true;
  let addressNote = "";  // an address the page could not follow, said in the status line
  function fitTo([xmin, xmax, ymin, ymax]) {
    const [top, right] = panelRoom();
    const w = W - right - AXIS_LEFT, h = H - top - AXIS_BOTTOM;
    view.sx = (w * 0.92) / (xmax - xmin); view.sy = (h * 0.92) / (ymax - ymin);
    if (!oneD) { view.sx = view.sy = Math.min(view.sx, view.sy); }
    view.cx = (xmin + xmax) / 2 - (AXIS_LEFT - right) / (2 * view.sx);
    view.cy = (ymin + ymax) / 2 + (top - AXIS_BOTTOM) / (2 * view.sy);
  }
  function fit() {
    setFollow(true);
    fitTo(oneD ? windowExtent() : extentOf(shownPositions(T)));
    trajectories = null;
  }
  function setFollow(on) {
    follow = on;
    const box = document.getElementById("follow");
    if (box) box.checked = on;
  }
  /// [xmin, xmax, ymin, ymax] of a range grown by points; a flat or empty one widened.
  function Extent() { this.e = [Infinity, -Infinity, Infinity, -Infinity]; }
  Extent.prototype.grow = function (x, y) {
    if (!isFinite(x) || !isFinite(y)) return;
    const e = this.e;
    if (x < e[0]) e[0] = x; if (x > e[1]) e[1] = x; if (y < e[2]) e[2] = y; if (y > e[3]) e[3] = y;
  };
  Extent.prototype.done = function () {
    let [xmin, xmax, ymin, ymax] = this.e;
    if (!isFinite(xmin)) { xmin = -1; xmax = 1; ymin = -1; ymax = 1; }
    // A flat extent (one object, objects at one place) is widened: relative to its magnitude,
    // so that the axes' ticks stay apart in doubles.
    const flat = (lo, hi) => hi - lo < 1e-9 * Math.max(1, Math.abs(lo), Math.abs(hi));
    if (flat(xmin, xmax)) { const w = Math.max(1, Math.abs(xmin)) * 1e-3; xmin -= w; xmax += w; }
    if (flat(ymin, ymax)) { const w = Math.max(1, Math.abs(ymin)) * 1e-3; ymin -= w; ymax += w; }
    return [xmin, xmax, ymin, ymax];
  };
  /// The plane's objects' extent at the positions `p` (boxes with their half extents).
  function extentOf(p) {
    const e = new Extent();
    for (let j = 0; j < N; ++j) {
      if (!p.piece[j]) continue;
      const h = p.piece[j].h, hx = h ? h[0] : 0, hy = h && h.length > 1 ? h[1] : 0;
      e.grow(p.x[j] - hx, p.y[j] - hy);
      e.grow(p.x[j] + hx, p.y[j] + hy);
    }
    return e.done();
  }
  /// The 1-D view's extent: the trajectories (time, position) over the window.
  function windowExtent() {
    const e = new Extent(), p = new Positions(), samples = 24;
    for (let k = 0; k <= samples; ++k) {
      const t = t0 + (t1 - t0) * k / samples;
      positionsAt(t, p);
      for (let j = 0; j < N; ++j) {
        if (!p.piece[j]) continue;
        e.grow(t, p.x[j]);
        if (objectsAre === "intervals") e.grow(t, p.y[j]);
      }
    }
    return e.done();
  }

  // ---- Many marks at once: pixels written into a layer, then one drawImage. ------------------
  // (10^5 fillRect calls cost 80-200 ms a frame in Chromium's software canvas; writing the
  // pixels and one drawImage about 3 ms.) Used from LARGE objects on; below, the canvas calls.
  const LARGE = 20000;
  const littleEndian = new Uint8Array(new Uint32Array([0x01020304]).buffer)[0] === 4;
  function pixel32(hex, alpha) {
    const r = parseInt(hex.slice(1, 3), 16), g = parseInt(hex.slice(3, 5), 16), b = parseInt(hex.slice(5, 7), 16);
    const a = alpha === undefined ? 255 : alpha;
    return (littleEndian ? ((a << 24) | (b << 16) | (g << 8) | r) : ((r << 24) | (g << 16) | (b << 8) | a)) >>> 0;
  }
  let layer = null;
  function pixelLayer() {  // cleared, the canvas's size in device pixels
    const w = canvas.width, h = canvas.height;
    if (!layer || layer.w !== w || layer.h !== h) {
      const c = document.createElement("canvas");
      c.width = Math.max(1, w); c.height = Math.max(1, h);
      const g = c.getContext("2d");
      const img = g.createImageData(c.width, c.height);
      layer = { w: w, h: h, canvas: c, g: g, img: img, px: new Uint32Array(img.data.buffer) };
    } else layer.px.fill(0);
    layer.d = devicePixelRatio;  // read once: a getter of the window, slow 10^5 times a frame
    return layer;
  }
  function layerSquare(L, x, y, r, colour) {  // (x, y) and r in CSS pixels
    const d = L.d;
    let xa = Math.round((x - r) * d), xb = Math.round((x + r) * d);
    let ya = Math.round((y - r) * d), yb = Math.round((y + r) * d);
    if (!(xa < L.w && ya < L.h && xb > 0 && yb > 0)) return;  // off the canvas (or NaN)
    if (xa < 0) xa = 0; if (ya < 0) ya = 0; if (xb > L.w) xb = L.w; if (yb > L.h) yb = L.h;
    const px = L.px, w = L.w;
    for (let j = ya; j < yb; ++j) for (let i = j * w + xa, e = j * w + xb; i < e; ++i) px[i] = colour;
  }
  function layerLine(L, x0, y0, x1, y1, colour) {  // device pixels, clipped to the layer
    const w = L.w, h = L.h;
    let ax = x0, ay = y0, bx = x1, by = y1;
    if (!(x0 >= 0 && x0 < w && y0 >= 0 && y0 < h && x1 >= 0 && x1 < w && y1 >= 0 && y1 < h)) {
      // Liang-Barsky: the part of the segment inside [0, w) x [0, h) (none when not finite).
      let u0 = 0, u1 = 1;
      const dx = x1 - x0, dy = y1 - y0;
      const ps = [-dx, dx, -dy, dy], qs = [x0, w - 1e-9 - x0, y0, h - 1e-9 - y0];
      for (let k = 0; k < 4; ++k) {
        const p = ps[k], q = qs[k];
        if (p === 0) { if (q >= 0) continue; return; }
        const r = q / p;
        if (p < 0) { if (r > u1) return; if (r > u0) u0 = r; } else { if (r < u0) return; if (r < u1) u1 = r; }
      }
      if (!(u0 <= u1)) return;
      ax = x0 + u0 * dx; ay = y0 + u0 * dy; bx = x0 + u1 * dx; by = y0 + u1 * dy;
    }
    const n = Math.ceil(Math.max(Math.abs(bx - ax), Math.abs(by - ay)));
    if (!(n >= 0)) return;  // not finite
    const sx = n ? (bx - ax) / n : 0, sy = n ? (by - ay) / n : 0;
    const px = L.px;
    for (let i = 0; i <= n; ++i) {
      const x = (ax + sx * i) | 0, y = (ay + sy * i) | 0;
      px[y * w + x] = colour;
    }
  }
  function drawLayer(L, g) {
    L.g.putImageData(L.img, 0, 0);
    g.save(); g.setTransform(1, 0, 0, 1, 0, 0); g.drawImage(L.canvas, 0, 0); g.restore();
  }

  // ---- 1-D: trajectories in the (t, x) plane, cached while the view does not change. ----------
  let trajectories = null;
  let eventMarks = null;  // the external events with ids, found once
  let settle = null;      // the full drawing after a pan or zoom of a slow trajectory image
  const SLOW = 40;        // ms: a trajectory image slower than this is previewed while panning
  function drawTrajectories(gesture) {
    const key = [W, H, view.cx, view.cy, view.sx, view.sy].join(",");
    if (trajectories && trajectories.key === key) { ctx.drawImage(trajectories.canvas, 0, 0, W, H); return; }
    if (gesture && trajectories && trajectories.ms > SLOW && trajectories.w === canvas.width && trajectories.h === canvas.height) {
      // A pan or zoom of a large trace: the last image moved and scaled to the new view at once,
      // the new image drawn when the gesture pauses.
      const v0 = trajectories.view, d = devicePixelRatio;
      const kx = view.sx / v0.sx, ky = view.sy / v0.sy;
      ctx.save();
      ctx.setTransform(d * kx, 0, 0, d * ky, d * (W / 2 - kx * W / 2 + (v0.cx - view.cx) * view.sx),
                       d * (H / 2 - ky * H / 2 - (v0.cy - view.cy) * view.sy));
      ctx.drawImage(trajectories.canvas, 0, 0, W, H);
      ctx.restore();
      clearTimeout(settle);
      settle = setTimeout(() => { settle = null; draw(); }, 150);
      return;
    }
    const started = performance.now();
    const off = document.createElement("canvas");
    off.width = canvas.width; off.height = canvas.height;
    const g = off.getContext("2d");
    g.setTransform(devicePixelRatio, 0, 0, devicePixelRatio, 0, 0);
    const coords = objectsAre === "intervals" ? [0, 1] : [0];
    if (N > RASTER) rasterTrajectories(g, off, coords);
    else {
      const n = Math.max(1, objectList.length);
      const samples = Math.max(8, Math.min(400, Math.floor(2e6 / n)));
      g.lineWidth = 1;
      g.strokeStyle = COLORS.trajectory;
      g.beginPath();
      for (const o of objectList) {
        for (const p of o.pieces) {
          const a = Math.max(p.from, t0), b = Math.min(p.to, t1);
          if (!(b > a)) continue;
          for (const axis of coords) {
            for (let k = 0; k <= samples; ++k) {
              const t = a + (b - a) * k / samples;
              const [x, y] = toScreen(t, evalCoord(p, axis, t));
              if (k === 0) g.moveTo(x, y); else g.lineTo(x, y);
            }
          }
        }
      }
      g.stroke();
    }
    // Event marks (external events with ids), at most 20000 drawn, evenly chosen.
    if (!eventMarks) eventMarks = steps.filter((s) => s.k === "event" && s.ids && s.ids.length > 0);
    const marks = eventMarks;
    const every = Math.max(1, Math.ceil(marks.length / 20000));
    g.strokeStyle = COLORS.event;
    const batch = marks.length > 2000;  // one path: the same squares, faster
    if (batch) g.beginPath();
    for (let k = 0; k < marks.length; k += every) {
      const s = marks[k];
      const o = objects.get(s.ids[0]);
      const p = o && pieceAt(o, s.t);
      if (!p) continue;
      const [x, y] = toScreen(s.t, evalCoord(p, 0, s.t));
      if (batch) g.rect(x - 2.5, y - 2.5, 5, 5); else g.strokeRect(x - 2.5, y - 2.5, 5, 5);
    }
    if (batch) g.stroke();
    trajectories = { key: key, canvas: off, view: Object.assign({}, view), w: off.width, h: off.height,
                     ms: performance.now() - started };
    ctx.drawImage(off, 0, 0, W, H);
  }
  // Many trajectories (from RASTER objects on; a canvas path of 10^5 lines takes 1-2 s to
  // stroke): each piece's curve rasterized by pixel column (column c covers the rows between the
  // values at its edges), the pixels' counts turned into the lines' colour with the opacity of
  // that many lines of opacity 0.55 over each other. A straight piece is filled by runs of
  // columns a row, a curved one evaluated at every column. At most RASTER_BUDGET columns in all:
  // beyond, every k-th visible piece is drawn and counted k times (at 10^5 objects on a screen of
  // 800 rows the image is saturated anyway; zoomed in, the pieces off the canvas do not count
  // and every visible one is drawn).
  const RASTER = 2000;
  const RASTER_BUDGET = 2e7;
  function rasterTrajectories(g, off, coords) {
    const d = devicePixelRatio, w = off.width, h = off.height;
    if (w === 0 || h === 0) return;
    const sx = view.sx, sy = view.sy, cx = view.cx, cy = view.cy, w2 = W / 2, h2 = H / 2;
    const tOf = (X) => (X / d - w2) / sx + cx;  // the time at device column edge X
    const yOf = (p, axis, t) => (h2 - (evalCoord(p, axis, t) - cy) * sy) * d;
    // The visible runs: a piece's coordinate over its columns on the canvas.
    const runPiece = [], runAxis = [], runFrom = [], runTo = [];
    let columns = 0;
    for (const o of objectList) {
      for (const p of o.pieces) {
        const a = Math.max(p.from, t0), b = Math.min(p.to, t1);
        if (!(b > a)) continue;
        const xa = ((a - cx) * sx + w2) * d, xb = ((b - cx) * sx + w2) * d;
        const c0 = Math.max(0, Math.floor(xa)), c1 = Math.min(w - 1, Math.ceil(xb) - 1);
        if (!(c1 >= c0)) continue;
        for (const axis of coords) {
          if (p.c[axis].length <= 2) {  // a straight line: not when above or below the canvas
            const ya = yOf(p, axis, Math.max(a, tOf(c0))), yb = yOf(p, axis, Math.min(b, tOf(c1 + 1)));
            if ((ya < 0 && yb < 0) || (ya >= h && yb >= h) || !(ya === ya && yb === yb)) continue;
          }
          runPiece.push(p); runAxis.push(axis); runFrom.push(c0); runTo.push(c1);
          columns += c1 - c0 + 1;
        }
      }
    }
    const every = Math.max(1, Math.ceil(columns / RASTER_BUDGET));
    const count = new Uint32Array(w * h);
    for (let k = 0; k < runPiece.length; k += every) {
      const p = runPiece[k], axis = runAxis[k], c0 = runFrom[k], c1 = runTo[k];
      const a = Math.max(p.from, t0), b = Math.min(p.to, t1);
      if (p.c[axis].length <= 2) {
        // A straight line, y = base + slope (X - c0) at column edge X; column c covers the rows
        // from y(c) to y(c + 1): row by row, the run of columns that cover it.
        const slope = -(p.c[axis].length > 1 ? p.c[axis][1] : 0) * sy / sx;
        const base = yOf(p, axis, tOf(c0)), end = base + slope * (c1 + 1 - c0);
        const r0 = Math.max(0, Math.floor(Math.min(base, end))), r1 = Math.min(h - 1, Math.floor(Math.max(base, end)));
        for (let r = r0; r <= r1; ++r) {
          let ca = c0, cb = c1;
          if (slope > 0) { ca = Math.ceil(c0 - 1 + (r - base) / slope); cb = Math.ceil(c0 + (r + 1 - base) / slope) - 1; }
          else if (slope < 0) { ca = Math.floor(c0 - 1 + (r + 1 - base) / slope) + 1; cb = Math.floor(c0 + (r - base) / slope); }
          if (ca < c0) ca = c0;
          if (cb > c1) cb = c1;
          for (let i = r * w + ca, e = r * w + cb; i <= e; ++i) count[i] += every;
        }
        continue;
      }
      let yPrev = yOf(p, axis, Math.max(a, tOf(c0)));
      for (let c = c0; c <= c1; ++c) {
        const yNext = yOf(p, axis, Math.min(b, tOf(c + 1)));
        let lo = yPrev, hi = yNext;
        if (hi < lo) { lo = yNext; hi = yPrev; }
        yPrev = yNext;
        if (!(hi >= 0 && lo < h)) continue;  // off the canvas, or not finite
        const e = (hi >= h ? h - 1 : hi | 0) * w + c;
        let i = (lo < 0 ? 0 : lo | 0) * w + c;
        do { count[i] += every; i += w; } while (i <= e);
      }
    }
    const img = g.createImageData(w, h);
    const px = new Uint32Array(img.data.buffer);
    const shade = [];
    for (let k = 0; k < 64; ++k) shade.push(pixel32("#1f77b4", Math.round(255 * (1 - Math.pow(0.45, k)))));
    for (let k = 0; k < count.length; ++k) { const c = count[k]; if (c) px[k] = shade[c < 63 ? c : 63]; }
    g.putImageData(img, 0, 0);
  }

  // ---- The structure's snapshot ---------------------------------------------------------------
  /// The left child's share of a node of `size` objects: the rank-based kd-tree's median rank
  /// lo + (hi - lo + 1) / 2 begins the right child (floor(size / 2) on the left); the range
  /// tree's node [s, e] over dense ranks (a trace without slots) has the left child
  /// [s, s + (e - s) / 2] (ceil(size / 2)).
  function leftSize(size, rangeTree) { return rangeTree ? (size + 1) >> 1 : size >> 1; }
  function kdCellsBySorting(orders, pos, maxDepth, primaryOnly) {
    // The rank-based kd-tree's cells from the maintained orders: median splits by rank, axes in
    // turn (primaryOnly: the range tree's splits of axis 0 at every level, over dense ranks, as
    // written before the range tree's traces carried slots). (The reference;
    // kdCells below gives the same segments, in the same order, from a tree cached per snapshot.)
    const rank = orders.map((o) => { const m = new Map(); o.ids.forEach((id, r) => m.set(id, r)); return m; });
    const d = orders.length;
    const segs = [];
    const all = orders[0].ids.filter((id) => pos.has(id));
    function rec(ids, depth, box) {
      if (ids.length < 2 || depth >= maxDepth) return;
      const axis = primaryOnly ? 0 : depth % d;
      ids.sort((a, b) => rank[axis].get(a) - rank[axis].get(b));
      const m = leftSize(ids.length, primaryOnly);
      const left = ids.slice(0, m), right = ids.slice(m);
      if (axis < 2) {
        const v = (pos.get(left[left.length - 1])[axis] + pos.get(right[0])[axis]) / 2;
        if (axis === 0) segs.push([v, box[2], v, box[3]]); else segs.push([box[0], v, box[1], v]);
        const lb = box.slice(), rb = box.slice();
        if (axis === 0) { lb[1] = v; rb[0] = v; } else { lb[3] = v; rb[2] = v; }
        rec(left, depth + 1, primaryOnly ? [box[0], v, box[2], box[3]] : lb);
        rec(right, depth + 1, primaryOnly ? [v, box[1], box[2], box[3]] : rb);
      } else {
        rec(left, depth + 1, box); rec(right, depth + 1, box);
      }
    }
    const [x0, y1] = toWorld(0, 0), [x1, y0] = toWorld(W, H);
    rec(all, 0, [x0, x1, y0, y1]);
    return segs;
  }

  // The tree of the splits depends only on the snapshot's orders and on which objects are alive
  // (the ops applied by the displayed time): it is built once for them, by partitioning the
  // orders (no sorting; O(n d) a level), and only the splits' values (from the two objects at
  // each median) are evaluated per frame.
  let kdCache = null;
  function kdTree(orders, pos, maxDepth, primaryOnly) {
    const d = orders.length;
    const axes = primaryOnly ? 1 : Math.min(d, maxDepth);  // the orders the splits use
    const rank = [];
    for (let a = 0; a < axes; ++a) {
      const r = new Int32Array(N).fill(-1), ids = orders[a].ids;
      for (let k = 0; k < ids.length; ++k) { const j = denseOf(ids[k]); if (j >= 0) r[j] = k; }
      rank.push(r);
    }
    const inAll = new Uint8Array(N);
    const all = [];
    for (const id of orders[0].ids) {
      const j = denseOf(id);
      if (j < 0 || pos.piece[j] === null) continue;
      if (inAll[j]) return null;  // an id twice: the reference decides
      inAll[j] = 1;
      all.push(j);
    }
    const n = all.length;
    // Per axis a buffer of the n objects for the even levels and one for the odd: a node holds
    // its objects at [lo, hi) of each, in that axis's order (each object at its rank, as sorting
    // by rank). A node's children write into the other buffers within [lo, hi), after which the
    // node does not read its own; the left subtree stays within [lo, mid).
    const buf = [[], []];
    for (let a = 0; a < axes; ++a) { buf[0].push(new Int32Array(n)); buf[1].push(new Int32Array(n)); }
    for (let a = 0; a < axes; ++a) {
      const byRank = new Int32Array(orders[a].ids.length).fill(-1);
      for (const j of all) { if (rank[a][j] < 0) return null; byRank[rank[a][j]] = j; }
      const list = buf[0][a];
      let m = 0;
      for (let k = 0; k < byRank.length; ++k) if (byRank[k] >= 0) list[m++] = byRank[k];
    }
    const mark = new Uint8Array(N);
    function rec(depth, lo, hi) {
      const size = hi - lo;
      if (size < 2 || depth >= maxDepth) return null;
      const axis = primaryOnly ? 0 : depth % d;
      const ls = buf[depth & 1], sorted = ls[axis], m = leftSize(size, primaryOnly), mid = lo + m;
      const node = { axis: axis, a: sorted[mid - 1], b: sorted[mid], left: null, right: null };
      if (depth + 1 >= maxDepth) return node;  // its children would stop at once
      const next = buf[(depth + 1) & 1];
      for (let j = lo; j < mid; ++j) mark[sorted[j]] = 1;
      for (let a = 0; a < axes; ++a) {
        const l = ls[a], out = next[a];
        if (a === axis) { out.set(l.subarray(lo, hi), lo); continue; }
        let nl = lo, nr = mid;
        for (let k = lo; k < hi; ++k) { const j = l[k]; if (mark[j]) out[nl++] = j; else out[nr++] = j; }
      }
      for (let j = lo; j < mid; ++j) mark[sorted[j]] = 0;
      node.left = rec(depth + 1, lo, mid);
      node.right = rec(depth + 1, mid, hi);
      return node;
    }
    return { root: rec(0, 0, n) };
  }
  /// One order of a snapshot with its keys' slots (a gapped sort's labels: `slots` strictly
  /// increasing, each below U = `slot_count`, a power of two): log2 U (rounded up), the label of
  /// every alive object by dense index (-1: not in the order or not alive), and the alive keys in
  /// slot order (dense indexes) with their slots; null when the slots are missing or not usable
  /// (not increasing, not below U, an id twice).
  function slottedOrder(o, pos) {
    const count = o.ids.length;
    if (!Array.isArray(o.slots) || o.slots.length !== count || !(o.slot_count >= 1)) return null;
    let l = 0;
    while (2 ** l < o.slot_count) ++l;
    if (l > 31) return null;
    const r = new Int32Array(N).fill(-1), ids = new Int32Array(count), slots = new Float64Array(count);
    let m = 0, prev = -1;
    for (let k = 0; k < count; ++k) {
      const slot = o.slots[k];
      if (!Number.isInteger(slot) || !(slot > prev) || slot >= 2 ** l) return null;  // increasing, < U
      prev = slot;
      const j = denseOf(o.ids[k]);
      if (j < 0 || pos.piece[j] === null) continue;
      if (r[j] >= 0) return null;  // an id twice
      r[j] = slot; ids[m] = j; slots[m++] = slot;
    }
    return { log: l, label: r, ids: ids.subarray(0, m), slots: slots.subarray(0, m) };
  }
  // The range tree's primary tree (docs/range-tree.md), when the snapshot's A_0 carries its keys'
  // slots and its number of slots U (a power of two): the node over the slots [s, e] (the root
  // [0, U - 1]) holds the points whose slot in A_0 lies in [s, e], and has the children
  // [s, s + (e - s)/2] and [s + (e - s)/2 + 1, e] (exact dyadic halves). A node whose two
  // children both hold points splits between the left child's last point (its largest slot) and
  // the right child's first: a node of kdTree's form (axis 0, a, b), drawn by kdCells halfway
  // between their x. A node with an empty child splits nothing visible: nothing is drawn there
  // and the drawing goes on into the other child at the same depth, so `maxDepth` counts the
  // levels of splits drawn, as over dense ranks (where every node of two points or more splits):
  // the gaps of the layout (U is 2n to 4n, a level or two more than log2 n) do not use up the
  // levels the view draws. Null when A_0's slots are not usable (the dense drawing then).
  function rangeSlotTree(orders, pos, maxDepth) {
    const o = slottedOrder(orders[0], pos);
    if (!o) return null;
    const ids = o.ids, slots = o.slots;
    function firstAfter(lo, hi, m) {  // the first of ids[lo, hi) at a slot > m
      while (lo < hi) { const mid = (lo + hi) >> 1; if (slots[mid] <= m) lo = mid + 1; else hi = mid; }
      return lo;
    }
    function rec(lo, hi, s, e, depth) {  // ids[lo, hi): the node's points, those of slots [s, e]
      for (;;) {  // each turn halves [s, e]: a range of one slot holds at most one point
        if (hi - lo < 2 || depth >= maxDepth) return null;
        const m = s + Math.floor((e - s) / 2), k = firstAfter(lo, hi, m);
        if (k > lo && k < hi) {
          const node = { axis: 0, a: ids[k - 1], b: ids[k], slots: [s, e], left: null, right: null };
          node.left = rec(lo, k, s, m, depth + 1);
          node.right = rec(k, hi, m + 1, e, depth + 1);
          return node;
        }
        if (k === hi) e = m; else s = m + 1;  // one child empty: on into the other
      }
    }
    return { root: rec(0, ids.length, 0, 2 ** o.log - 1, 0), slotCount: 2 ** o.log, points: ids.length };
  }
  /// The range tree's primary tree over slots for the page's state: U, the points, and the first
  /// node drawn (the root when both halves of [0, U - 1] hold points) with its slot range and the
  /// ids of the two points its split lies between.
  function rangeSlotSummary(t) {
    const r = t.root;
    return { labels: true, primary: true, slot_count: t.slotCount, points: t.points,
             root: r ? { slots: r.slots, left: objectIds[r.a], right: objectIds[r.b] } : null };
  }
  // The library's kd-tree (docs/kdtree.md), when the snapshot's orders carry their keys' slots
  // (labels) and each sort's number of slots U_i (a power of two): an x_i-node at skeleton depth
  // s (i = s mod d, level l = floor(s / d) of axis i) halves the label range of its x_i-parent
  // ([0, U_i - 1] at the first x_i-node), so the side a point takes there is bit l of its label
  // from the top (0 once the range is one label); its split passes through the first point of
  // A_i at a label >= the range's median m (the first label of its upper half), or +infinity
  // when there is none; labels < m go left. T(P): the active nodes (both sides non-empty; a
  // point alone is a leaf right below), each with its chain: of the degree-one skeleton nodes
  // between it and its active parent (from depth 0 above the root), the lowest one per axis and
  // side, top-down, as the library keeps them. Built once per snapshot and alive set, active
  // nodes down to `maxLevels` trie levels (the whole tree when that is Infinity); null when the
  // slots are not usable (the dense drawing then).
  function kdLabelTree(orders, pos, maxLevels) {
    const d = orders.length;
    const label = [], log = [], splitIds = [], splitSlots = [];
    let maxLog = 0;
    for (let a = 0; a < d; ++a) {
      const o = slottedOrder(orders[a], pos);
      if (!o) return null;
      log.push(o.log); maxLog = Math.max(maxLog, o.log);
      label.push(o.label); splitIds.push(o.ids); splitSlots.push(o.slots);
    }
    const n = splitIds[0].length;
    for (let a = 1; a < d; ++a) {  // the same objects in every order
      if (splitIds[a].length !== n) return null;
      for (const j of splitIds[0]) if (label[a][j] < 0) return null;
    }
    // Skeleton depth s: axis s mod d, level floor(s / d) of that axis; the side a label takes
    // there is its bit log - 1 - level (none once the range is one label: every point left).
    const axisOf = (s) => s % d;
    const shiftOf = (s) => { const a = s % d; return log[a] - 1 - (s - a) / d; };
    function median(j, s) {  // the first label of the upper half of j's range at depth s
      const a = s % d, r = label[a][j], shift = shiftOf(s);
      if (shift < 0) return r;
      const width = 2 ** (shift + 1);
      return r - (r % width) + width / 2;
    }
    function splitAt(a, m) {  // the first point of A_a at a label >= m: its dense index, -1 for none
      const sl = splitSlots[a];
      let lo = 0, hi = sl.length;
      while (lo < hi) { const mid = (lo + hi) >> 1; if (sl[mid] < m) lo = mid + 1; else hi = mid; }
      return lo < sl.length ? splitIds[a][lo] : -1;
    }
    const pts = Int32Array.from(splitIds[0]), tmp = new Int32Array(n), seen = new Uint8Array(2 * d);
    const out = { root: null, active: 0, chained: 0, points: n, depth: 0, complete: true };
    const limit = d * maxLog;  // below it any two points have taken different sides
    function build(lo, hi, depth, level) {  // pts[lo, hi), two points or more, from skeleton depth `depth`
      let s = depth;
      for (;; ++s) {
        if (s >= limit) throw new Error("kd-tree labels: two points with the same labels");
        const shift = shiftOf(s);
        if (shift < 0) continue;
        const L = label[axisOf(s)], b0 = (L[pts[lo]] >>> shift) & 1;
        let k = lo + 1;
        while (k < hi && ((L[pts[k]] >>> shift) & 1) === b0) ++k;
        if (k < hi) break;
      }
      const rep = pts[lo], chain = [];
      seen.fill(0);
      for (let u = s - 1; u >= depth; --u) {  // bottom-up: the first one seen is the lowest
        const a = axisOf(u), shift = shiftOf(u), side = shift < 0 ? 0 : (label[a][rep] >>> shift) & 1;
        if (seen[2 * a + side]) continue;
        seen[2 * a + side] = 1;
        const m = median(rep, u);
        chain.push({ depth: u, axis: a, side: side, median: m, split: splitAt(a, m) });
      }
      chain.reverse();
      const axis = axisOf(s), m = median(rep, s);
      const node = { depth: s, axis: axis, median: m, split: splitAt(axis, m), chain: chain,
                     size: hi - lo, left: null, right: null };
      ++out.active; out.chained += chain.length;
      // Stable partition: the labels below the median (bit 0) to the left.
      const L = label[axis], shift = shiftOf(s);
      let mid = lo, nr = 0;
      for (let k = lo; k < hi; ++k) { const j = pts[k]; if (((L[j] >>> shift) & 1) === 0) pts[mid++] = j; else tmp[nr++] = j; }
      pts.set(tmp.subarray(0, nr), mid);
      for (const [a, b, side] of [[lo, mid, "left"], [mid, hi, "right"]]) {
        if (b - a === 1) out.depth = Math.max(out.depth, s + 1);  // a leaf right below
        else if (level + 1 < maxLevels) node[side] = build(a, b, s + 1, level + 1);
        else out.complete = false;
      }
      return node;
    }
    try {
      if (n >= 2) out.root = build(0, n, 0, 0);
    } catch (e) {
      return null;
    }
    // Nodes of T(P) as the library counts them (KineticKdTree::node_count(): trie nodes and
    // chain nodes), when the whole tree was built.
    out.nodes = out.complete ? out.active + out.chained + n : null;
    return out;
  }
  /// The library's tree as plain data for the page's state (ids, not dense indexes): the root, and
  /// every node in preorder for small trees.
  function kdLabelSummary(t) {
    const id = (j) => (j >= 0 ? objectIds[j] : null);
    const plain = (v) => ({ depth: v.depth, axis: v.axis, median: v.median, split: id(v.split), size: v.size,
                            chain: v.chain.map((e) => ({ depth: e.depth, axis: e.axis, side: e.side, median: e.median, split: id(e.split) })) });
    const nodes = [];
    if (t.active <= 256) (function walk(v) { if (!v) return; nodes.push(plain(v)); walk(v.left); walk(v.right); })(t.root);
    return { labels: true, nodes: t.nodes, active: t.active, chained: t.chained, points: t.points, depth: t.depth,
             complete: t.complete, root: t.root ? plain(t.root) : null, preorder: nodes };
  }
  /// The cells of the library's tree: at each active node, its chain's splits (each bounds the
  /// region on its side: drawn where it cuts the region; +infinity bounds nothing), then its own
  /// split through its split point, left child below it, right child above.
  function kdLabelCells(t, pos) {
    const segs = [];
    const coord = (j, axis) => (axis === 0 ? pos.x[j] : pos.y[j]);
    function line(axis, v, box) {
      if (axis === 0) segs.push([v, box[2], v, box[3]]); else segs.push([box[0], v, box[1], v]);
    }
    function rec(node, box) {
      if (!node) return;
      for (const e of node.chain) {
        if (e.axis >= 2 || e.split < 0 || pos.piece[e.split] === null) continue;
        const v = coord(e.split, e.axis), lo = 2 * e.axis, hi = lo + 1;
        if (!(v > box[lo] && v < box[hi])) continue;  // no cut (or off the view)
        line(e.axis, v, box);
        box = box.slice();
        box[e.side === 0 ? hi : lo] = v;
      }
      const axis = node.axis;
      if (axis < 2 && node.split >= 0 && pos.piece[node.split] !== null) {
        const v = coord(node.split, axis);
        line(axis, v, box);
        const lb = box.slice(), rb = box.slice();
        if (axis === 0) { lb[1] = v; rb[0] = v; } else { lb[3] = v; rb[2] = v; }
        rec(node.left, lb); rec(node.right, rb);
      } else {
        rec(node.left, box); rec(node.right, box);
      }
    }
    const [x0, y1] = toWorld(0, 0), [x1, y0] = toWorld(W, H);
    rec(t.root, [x0, x1, y0, y1]);
    return segs;
  }
  function kdCells(orders, pos, maxDepth, primaryOnly, snap, alive) {
    if (!kdCache || kdCache.snap !== snap || kdCache.alive !== alive || kdCache.depth !== maxDepth ||
        kdCache.primaryOnly !== primaryOnly) {
      kdCache = { snap: snap, alive: alive, depth: maxDepth, primaryOnly: primaryOnly, labels: null, tree: null, summary: null };
      // The library's tree when the orders carry slots (the kd-tree's trace): whole up to 4096
      // points, else its top twelve levels of active nodes. The range tree's primary tree over
      // A_0's slots when A_0 carries them (its trace), down to maxDepth levels of splits.
      if (!primaryOnly && orders.every((o) => o.slots !== undefined)) {
        kdCache.labels = kdLabelTree(orders, pos, pos.size <= 4096 ? Infinity : 12);
        if (kdCache.labels) kdCache.summary = kdLabelSummary(kdCache.labels);
      } else if (primaryOnly && orders[0].slots !== undefined) {
        kdCache.tree = rangeSlotTree(orders, pos, maxDepth);
        if (kdCache.tree) kdCache.summary = rangeSlotSummary(kdCache.tree);
      }
      if (!kdCache.labels && !kdCache.tree) kdCache.tree = kdTree(orders, pos, maxDepth, primaryOnly);
    }
    if (kdCache.labels) return kdLabelCells(kdCache.labels, pos);
    if (!kdCache.tree) return kdCellsBySorting(orders, pos, maxDepth, primaryOnly);
    const segs = [];
    const coord = (j, axis) => (axis === 0 ? pos.x[j] : pos.y[j]);
    function rec(node, box) {
      if (!node) return;
      const axis = node.axis;
      if (axis < 2) {
        const v = (coord(node.a, axis) + coord(node.b, axis)) / 2;
        if (axis === 0) segs.push([v, box[2], v, box[3]]); else segs.push([box[0], v, box[1], v]);
        const lb = box.slice(), rb = box.slice();
        if (axis === 0) { lb[1] = v; rb[0] = v; } else { lb[3] = v; rb[2] = v; }
        rec(node.left, primaryOnly ? [box[0], v, box[2], box[3]] : lb);
        rec(node.right, primaryOnly ? [v, box[1], box[2], box[3]] : rb);
      } else {
        rec(node.left, box); rec(node.right, box);
      }
    }
    const [x0, y1] = toWorld(0, 0), [x1, y0] = toWorld(W, H);
    rec(kdCache.tree.root, [x0, x1, y0, y1]);
    return segs;
  }

  let screenBuffer = null;
  function screenPoints(pos, d) {  // the objects' device pixel positions, interleaved
    if (!screenBuffer) screenBuffer = new Float64Array(2 * N);
    const q = screenBuffer, cx = view.cx, cy = view.cy, sx = view.sx, sy = view.sy, w2 = W / 2, h2 = H / 2;
    for (let j = 0; j < N; ++j) {
      if (pos.piece[j] === null) { q[2 * j] = NaN; continue; }
      q[2 * j] = ((pos.x[j] - cx) * sx + w2) * d; q[2 * j + 1] = (h2 - (pos.y[j] - cy) * sy) * d;
    }
    return q;
  }
  let triangleCache = null;  // a snapshot's triangles as dense indexes (-1: an unknown id)
  function trianglesOf(snapshot) {
    if (triangleCache && triangleCache.snapshot === snapshot) return triangleCache.tri;
    const tri = new Int32Array(3 * snapshot.delaunay.length);
    snapshot.delaunay.forEach((t, k) => {
      for (let j = 0; j < 3; ++j) tri[3 * k + j] = denseOf(t[j]);
    });
    triangleCache = { snapshot: snapshot, tri: tri };
    return tri;
  }

  function idsOf(result) {
    // The ids a query's answer names (flattened), for highlighting.
    const out = [];
    const walk = (v) => { if (Array.isArray(v)) v.forEach(walk); else if (typeof v === "number") out.push(v); };
    walk(result);
    return out;
  }

  // ---- The snapshots' trees: tournament levels, canonical sets, BVH nodes, longest-side cells --
  // `treeLevels` (the "tree levels" control) bounds how deep each is drawn.

  function tournamentPanelHeight(top) { return 28 * Math.min(top.levels.length, treeLevels) + 8; }
  function canonicalDepths() { return Math.min(treeLevels + 4, 8); }
  function canonicalPanelWidth() { return 16 * canonicalDepths() + 12; }

  /// A tournament's top levels as a tree in a panel at the top right (the lecture notes' picture:
  /// every node holds the winner of its subtree; the winner's path from the root is drawn thick).
  function drawTournamentPanel(top, slot, state) {
    const levels = top.levels.slice(0, Math.min(top.levels.length, treeLevels));
    const panelW = Math.min(440, W * 0.45), rowH = 28, panelH = tournamentPanelHeight(top);
    const x0 = W - panelW - 8, y0 = 8 + slot * (panelH + 8);
    ctx.fillStyle = "rgba(255,255,255,0.9)"; ctx.fillRect(x0, y0, panelW, panelH);
    ctx.strokeStyle = COLORS.cell; ctx.lineWidth = 1; ctx.strokeRect(x0, y0, panelW, panelH);
    const place = (k, j) => [x0 + panelW * (j + 0.5) / (1 << k), y0 + 4 + rowH * k + rowH / 2];
    for (let k = 1; k < levels.length; ++k) {
      levels[k].forEach((id, j) => {
        if (id === null) return;
        const [px, py] = place(k - 1, j >> 1), [x, y] = place(k, j);
        const onPath = levels[k - 1][j >> 1] === id;  // this child's winner won above
        ctx.strokeStyle = onPath ? COLORS.hull : COLORS.cell; ctx.lineWidth = onPath ? 2 : 1;
        ctx.beginPath(); ctx.moveTo(px, py); ctx.lineTo(x, y); ctx.stroke();
      });
    }
    ctx.lineWidth = 1; ctx.textAlign = "center"; ctx.textBaseline = "middle";
    levels.forEach((row, k) => {
      const r = Math.max(3, Math.min(10, panelW / (1 << k) / 2 - 2));
      ctx.font = Math.round(Math.min(11, r + 2)) + "px sans-serif";
      row.forEach((id, j) => {
        if (id === null) return;
        const [x, y] = place(k, j);
        ctx.fillStyle = "#ffffff"; ctx.strokeStyle = id === top.id ? COLORS.hull : COLORS.node;
        ctx.lineWidth = 2; ctx.beginPath(); ctx.arc(x, y, r, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
        if (r >= 7) { ctx.fillStyle = COLORS.event; ctx.fillText(String(id), x, y); }
        state.tree.push({ top: slot, level: k, index: j, id: id, x: x, y: y, r: r });
      });
    });
    ctx.lineWidth = 1;
  }

  /// The segment tree's canonical sets: one column per level at the right edge, a node as a bar
  /// over its span [R[first], R[last + 1]] at the displayed time, its set's size beside it. On a
  /// stab query the nodes whose span holds the query point are highlighted: the answer is the
  /// union of their sets (and of the deeper levels' below the drawn ones).
  function drawCanonicalSets(s, pos, stabX, state) {
    const R = s.endpoints, depths = canonicalDepths();
    const end = (r) => {
      const e = R[Math.min(r, R.length - 1)];
      const p = e && pos.get(e[0]);
      return p ? (e[1] === 0 ? p[0] : p[1]) : NaN;
    };
    const colW = 16, x0 = W - colW * depths - 8;
    ctx.fillStyle = "rgba(255,255,255,0.85)"; ctx.fillRect(x0 - 4, 0, colW * depths + 12, H);
    ctx.strokeStyle = COLORS.cell; ctx.strokeRect(x0 - 4, 0, colW * depths + 12, H);
    ctx.textAlign = "left"; ctx.textBaseline = "top"; ctx.font = "10px sans-serif";
    ctx.fillStyle = COLORS.event; ctx.fillText("S(v) by level", x0, 4);
    ctx.textBaseline = "middle"; ctx.font = "9px sans-serif";
    for (const node of s.nodes) {
      if (node.depth >= depths) continue;
      const first = node.leaves[0], last = node.leaves[1];
      if (first >= R.length) continue;  // padding leaves
      const a = end(first), b = end(last + 1);
      if (a !== a || b !== b) continue;
      const [, ya] = toScreen(T, a), [, yb] = toScreen(T, b);
      const x = x0 + colW * node.depth + 4;
      const onPath = stabX !== null && a <= stabX && stabX <= b;
      ctx.strokeStyle = onPath ? COLORS.highlight : COLORS.node; ctx.lineWidth = 3;
      ctx.beginPath(); ctx.moveTo(x, ya); ctx.lineTo(x, yb); ctx.stroke();
      ctx.fillStyle = COLORS.event; ctx.fillText(String(node.ids.length), x + 3, (ya + yb) / 2);
      state.canonical.push({ depth: node.depth, leaves: [first, last], ids: node.ids, x: x,
                             y: [ya, yb], onPath: onPath });
    }
    ctx.lineWidth = 1;
  }

  /// The BVH's node boxes down to treeLevels (deeper ones fainter), and its separation list's
  /// front among them: each separated pair as a dashed segment between the two boxes' centres.
  function drawBvhNodes(s, pos, state) {
    const rects = [];
    s.nodes.forEach((node, k) => {
      const b = [];
      for (let a = 0; a < 2; ++a) {
        const lo = node.sides[a] ? pos.get(node.sides[a][0]) : null, hi = node.sides[a] ? pos.get(node.sides[a][1]) : null;
        if (!lo || !hi) { b.push(null); continue; }
        const hl = lo[2].h ? lo[2].h[a] : 0, hh = hi[2].h ? hi[2].h[a] : 0;
        b.push([lo[a] - hl, hi[a] + hh]);
      }
      if (dim < 2) b[1] = [0, 0];
      if (!b[0] || !b[1] || node.depth >= treeLevels) { rects[k] = null; return; }
      const [xa, ya] = toScreen(b[0][0], b[1][1]), [xb, yb] = toScreen(b[0][1], b[1][0]);
      rects[k] = [xa, ya, xb, yb];
      ctx.strokeStyle = COLORS.node; ctx.globalAlpha = Math.max(0.3, 1 - 0.18 * node.depth);
      ctx.lineWidth = node.depth === 0 ? 2 : 1;
      ctx.strokeRect(xa, ya, xb - xa, yb - ya);
      state.bvh.push({ index: k, depth: node.depth, rect: [xa, ya, xb, yb], world: b });
    });
    ctx.globalAlpha = 1; ctx.lineWidth = 1;
    if (!s.pairs) return;
    ctx.strokeStyle = COLORS.front; ctx.setLineDash([4, 3]); ctx.beginPath();
    for (const [a, b, st] of s.pairs) {
      if (st !== "separated" || !rects[a] || !rects[b]) continue;
      const ca = [(rects[a][0] + rects[a][2]) / 2, (rects[a][1] + rects[a][3]) / 2];
      const cb = [(rects[b][0] + rects[b][2]) / 2, (rects[b][1] + rects[b][3]) / 2];
      ctx.moveTo(ca[0], ca[1]); ctx.lineTo(cb[0], cb[1]);
      state.front.push([a, b]);
    }
    ctx.stroke(); ctx.setLineDash([]);
  }

  /// The longest-side kd-tree's own cells: each active node's split, orthogonal to its longest
  /// side through its split point, across its region (both from the points that bound them).
  function drawLongestSideCells(s, pos, state) {
    ctx.strokeStyle = COLORS.cell; ctx.lineWidth = 1; ctx.beginPath();
    const maxDepth = treeLevels + 6;
    for (const c of s.cells) {
      if (c.depth >= maxDepth) continue;
      const lo = [pos.get(c.lo[0]), pos.get(c.lo[1])], top = [pos.get(c.top[0]), pos.get(c.top[1])];
      const sp = pos.get(c.split);
      if (!lo[0] || !lo[1] || !top[0] || !top[1] || !sp) continue;
      if (c.depth === 0) {  // the root's region: the bounding box
        const [xa, ya] = toScreen(lo[0][0], top[1][1]), [xb, yb] = toScreen(top[0][0], lo[1][1]);
        ctx.rect(xa, ya, xb - xa, yb - ya);
      }
      const other = 1 - c.axis, at = sp[c.axis];
      const from = lo[other][other], to = top[other][other];
      const w = c.axis === 0 ? [[at, from], [at, to]] : [[from, at], [to, at]];
      const [p, q] = toScreen(w[0][0], w[0][1]), [u, v] = toScreen(w[1][0], w[1][1]);
      ctx.moveTo(p, q); ctx.lineTo(u, v);
      if (state.cells.length < 5000) state.cells.push({ depth: c.depth, axis: c.axis, from: [p, q], to: [u, v] });
    }
    ctx.stroke();
  }

  let lastState = {};
  // ---- Axes and legend ------------------------------------------------------------------------
  /// A round tick spacing (1, 2 or 5 times a power of ten) giving about `count` ticks on `span`.
  function niceStep(span, count) {
    const raw = span / Math.max(1, count);
    const p = Math.pow(10, Math.floor(Math.log10(raw)));
    const m = raw / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
  }
  function tickLabel(v, step) {
    if (Math.abs(v) < step / 2) return "0";
    const decimals = Math.max(0, Math.ceil(-Math.log10(step) - 1e-9));
    if (decimals > 6 || Math.abs(v) >= 1e6) return v.toExponential(Math.min(6, Math.max(1, Math.round(Math.log10(Math.abs(v) / step)))));
    return v.toFixed(decimals);
  }
  /// The axes with their scale: x along the bottom, y along the left (in 1-D: time and
  /// position), ticks at round values, their positions kept in state.axes.
  function drawAxes(state) {
    const [top, right] = panelRoom();
    const xa = AXIS_LEFT, xb = W - right, ya = top, yb = H - AXIS_BOTTOM;
    ctx.fillStyle = "#ffffff";
    ctx.fillRect(0, 0, AXIS_LEFT, H); ctx.fillRect(0, yb, xb, AXIS_BOTTOM);
    ctx.strokeStyle = COLORS.axis; ctx.fillStyle = COLORS.axis; ctx.lineWidth = 1;
    ctx.beginPath(); ctx.moveTo(xa, ya); ctx.lineTo(xa, yb); ctx.lineTo(xb, yb); ctx.stroke();
    ctx.font = "11px system-ui, sans-serif";
    const axes = { x: { title: oneD ? "time" : "x", ticks: [] }, y: { title: oneD ? "position" : "y", ticks: [] } };
    const [wx0] = toWorld(xa, 0), [wx1] = toWorld(xb, 0);
    const stepX = niceStep(wx1 - wx0, (xb - xa) / 90);
    ctx.textAlign = "center"; ctx.textBaseline = "top";
    // (At most 100 ticks, and none once k + 1 no longer differs from k in doubles: a view zoomed
    // far in at a large coordinate.)
    for (let k = Math.ceil(wx0 / stepX), n = 0; k * stepX <= wx1 && n < 100 && k + 1 !== k; ++k, ++n) {
      const v = k * stepX, [px] = toScreen(v, 0);
      ctx.beginPath(); ctx.moveTo(px, yb); ctx.lineTo(px, yb + 5); ctx.stroke();
      ctx.fillText(tickLabel(v, stepX), px, yb + 7);
      axes.x.ticks.push([v, px]);
    }
    ctx.textAlign = "right"; ctx.fillText(axes.x.title, xb - 2, yb + 19);
    const [, wy0] = toWorld(0, yb), [, wy1] = toWorld(0, ya);
    const stepY = niceStep(wy1 - wy0, (yb - ya) / 60);
    ctx.textBaseline = "middle";
    for (let k = Math.ceil(wy0 / stepY), n = 0; k * stepY <= wy1 && n < 100 && k + 1 !== k; ++k, ++n) {
      const v = k * stepY, [, py] = toScreen(0, v);
      ctx.beginPath(); ctx.moveTo(xa - 5, py); ctx.lineTo(xa, py); ctx.stroke();
      ctx.fillText(tickLabel(v, stepY), xa - 7, py);
      axes.y.ticks.push([v, py]);
    }
    ctx.textAlign = "left"; ctx.textBaseline = "top"; ctx.fillText(axes.y.title, 4, ya + 2);
    state.axes = axes;
  }
  /// What each colour and mark of the picture means (the entries drawn this frame), in the side
  /// panel above the step list (never over the picture); the labels kept in state.legend.
  let legendKey = null;
  function drawLegend(entries, state) {
    const seen = new Set(), rows = entries.filter((e) => !seen.has(e.label) && seen.add(e.label));
    state.legend = rows.map((e) => e.label);
    const key = JSON.stringify(rows);
    if (key === legendKey) return;  // (the DOM changes only when the entries do)
    legendKey = key;
    const box = document.getElementById("legend");
    box.innerHTML = "";
    for (const e of rows) {
      const row = document.createElement("div");
      const mark = document.createElement("span");
      mark.className = "mark " + e.mark;
      mark.style.setProperty("--c", e.colour);
      if (e.mark === "cross") mark.textContent = "\u00d7";
      row.appendChild(mark);
      row.appendChild(document.createTextNode(e.label));
      box.appendChild(row);
    }
  }
  /// The part of an axis-parallel segment [xa, ya, xb, yb] inside the box [x0, x1, y0, y1], or null.
  function clipSegment(q, box) {
    const xa = Math.max(Math.min(q[0], q[2]), box[0]), xb = Math.min(Math.max(q[0], q[2]), box[1]);
    const ya = Math.max(Math.min(q[1], q[3]), box[2]), yb = Math.min(Math.max(q[1], q[3]), box[3]);
    if (xa > xb || ya > yb) return null;
    return q[0] === q[2] ? [q[0], ya, q[0], yb] : [xa, q[1], xb, q[1]];
  }

  function draw(gesture) {
    const started = performance.now();
    if (settle && !gesture) { clearTimeout(settle); settle = null; }
    ctx.setTransform(devicePixelRatio, 0, 0, devicePixelRatio, 0, 0);
    ctx.clearRect(0, 0, W, H);
    const pos = shownPositions(T);
    const objectsBox = oneD ? null : extentOf(pos);
    if (follow && !oneD) fitTo(objectsBox);
    const snap = snapshotFor(current);
    const s = snap ? snap.snapshot : {};
    const step = current >= 0 ? steps[current] : null;
    const query = step && step.k === "query" && step.t === T ? step : null;
    const highlighted = new Set(query ? idsOf(query.result) : []);
    const state = { time: T, step: current, stepCount: steps.length, view: oneD ? "1d" : "2d",
                    snapshotStep: snap ? snap.step : null, highlighted: Array.from(highlighted),
                    positions: {}, marks: [], hull: null, pair: null,
                    tree: [], canonical: [], bvh: [], front: [], cells: [], rootSplit: null, kd: null, kdSegments: null, kNearest: null,
                    query: query ? query.type : null, axes: null, legend: [] };
    const legend = [];  // what this frame draws: {colour, label, mark}
    const note = (colour, label, mark) => legend.push({ colour, label, mark });

    if (oneD) {
      drawTrajectories(gesture === true);
      note(COLORS.trajectory, "an object's position over time", "line");
      note(COLORS.now, "the time shown", "line");
      note(COLORS.point, objectsAre === "intervals" ? "an interval's ends now" : "an object now", "square");
      const [xn] = toScreen(T, 0);
      ctx.strokeStyle = COLORS.now; ctx.lineWidth = 1;
      ctx.beginPath(); ctx.moveTo(xn, 0); ctx.lineTo(xn, H); ctx.stroke();
      if (query && query.type === "stab") {
        const q = sc.timeline[query.index].query;
        const [, ys] = toScreen(T, q.x);
        const [, right] = panelRoom();
        ctx.strokeStyle = COLORS.query; ctx.beginPath(); ctx.moveTo(AXIS_LEFT, ys); ctx.lineTo(W - right, ys); ctx.stroke();
        note(COLORS.query, "the stabbing query's position", "line");
      }
      if (query && query.type === "range") {
        const b = sc.timeline[query.index].query.box[0];
        const [, ya] = toScreen(T, b[0]), [, yb] = toScreen(T, b[1]);
        const [, right] = panelRoom();
        ctx.fillStyle = "rgba(10,88,202,0.12)"; ctx.fillRect(AXIS_LEFT, yb, W - right - AXIS_LEFT, ya - yb);
        note(COLORS.query, "the range query's interval", "square");
      }
      // The objects in objectList's order, the answer's after the others (on top). From LARGE
      // objects on, the others' squares (all on the time line, one column) are drawn as the runs
      // of pixel rows that they cover; state.positions keeps the first 5000 of them (all below
      // that) and every highlighted one.
      const d = devicePixelRatio, ch = canvas.height;
      const rows = pos.size > LARGE ? new Int32Array(ch + 1) : null;  // +1 at a square's top row, -1 below its bottom
      let barColumn = 0, recorded = 0;
      const px = (T - view.cx) * view.sx + W / 2;  // the time line
      for (const hi of [false, true]) {
        if (hi && highlighted.size === 0) break;
        for (let k = 0; k < N; ++k) {
          if (pos.piece[k] === null) continue;
          const id = objectIds[k];
          if (highlighted.size > 0 && highlighted.has(id) !== hi) continue;
          for (let e = 0; e < (objectsAre === "intervals" ? 2 : 1); ++e) {
            const py = H / 2 - ((e === 0 ? pos.x[k] : pos.y[k]) - view.cy) * view.sy;
            const r = hi ? 5 : 3;
            if (rows && !hi) {
              const ya = Math.max(0, Math.round((py - r) * d)), yb = Math.min(ch, Math.round((py + r) * d));
              if (ya < yb) { ++rows[ya]; --rows[yb]; }
            } else {
              ctx.fillStyle = hi ? COLORS.highlight : COLORS.point;
              ctx.fillRect(px - r, py - r, 2 * r, 2 * r);
            }
            if (!state.positions[id] && (hi || recorded < 5000)) { state.positions[id] = [px, py]; if (!hi) ++recorded; }
            if (state.marks.length < 5000) state.marks.push([px, py]);
          }
          if (objectsAre === "intervals" && hi) {
            // An interval of the answer: a bar beside the time line, one column per interval.
            const [xt, pa] = toScreen(T, pos.x[k]), [, pb] = toScreen(T, pos.y[k]);
            const x = xt + 8 + 4 * (barColumn++);
            ctx.strokeStyle = COLORS.highlight; ctx.lineWidth = 2;
            ctx.beginPath(); ctx.moveTo(x, pa); ctx.lineTo(x, pb); ctx.stroke(); ctx.lineWidth = 1;
          }
        }
        if (rows && !hi) {
          const xa = Math.round((px - 3) * d), xb = Math.round((px + 3) * d);
          ctx.save(); ctx.setTransform(1, 0, 0, 1, 0, 0); ctx.fillStyle = COLORS.point;
          for (let y = 0, depth = 0, from = -1; y <= ch; ++y) {
            depth += rows[y];
            if (depth > 0 && from < 0) from = y;
            else if (depth <= 0 && from >= 0) { ctx.fillRect(xa, from, xb - xa, y - from); from = -1; }
          }
          ctx.restore();
        }
      }
      if (s.nodes && s.endpoints) {
        const stabX = query && query.type === "stab" ? sc.timeline[query.index].query.x : null;
        drawCanonicalSets(s, pos, stabX, state);
        note(COLORS.node, "a node's canonical set (right panel)", "thick");
      }
      if (s.tops) {
        s.tops.slice(0, 2).forEach((top, k) => { if (top.levels) drawTournamentPanel(top, k, state); });
        for (const top of s.tops) {
          const p = pos.get(top.id);
          if (!p) continue;
          const [px, py] = toScreen(T, p[0]);
          ctx.strokeStyle = COLORS.hull; ctx.lineWidth = 2;
          ctx.beginPath(); ctx.arc(px, py, 8, 0, 2 * Math.PI); ctx.stroke(); ctx.lineWidth = 1;
          note(COLORS.hull, "a tournament's winner (the " + top.extreme + ")", "circle");
        }
      }
    } else {
      // Structure first, objects over it.
      if (s.cells) { drawLongestSideCells(s, pos, state); note(COLORS.cell, "a cell's split (longest-side kd-tree)", "line"); }
      if (s.nodes && s.nodes.length && s.nodes[0].sides) {
        drawBvhNodes(s, pos, state);
        note(COLORS.node, "a BVH node's box", "box");
        note(COLORS.front, "the separation list's front", "dashed");
      }
      if (s.orders && !s.cells && s.orders.length >= 2) {
        const primaryOnly = header.structure === "range-tree";
        const depth = Math.min(primaryOnly ? 6 : 12, Math.ceil(Math.log2(Math.max(2, pos.size))));
        ctx.strokeStyle = COLORS.cell; ctx.lineWidth = 1; ctx.beginPath();
        const at = stepAtOrBefore(T), alive = at >= 0 ? opsUpTo[at] : 0;  // the ops applied
        // The cells' lines, clipped to the objects' extent now (a root cell is unbounded).
        const [ex0, ex1, ey0, ey1] = objectsBox;
        const segs = kdCells(s.orders, pos, depth, primaryOnly, snap, alive)
          .map((q) => clipSegment(q, [ex0, ex1, ey0, ey1])).filter((q) => q !== null);
        note(COLORS.cell, primaryOnly ? "a primary tree's split (range tree)" : "a kd-tree split", "line");
        if (segs.length) state.rootSplit = segs[0];
        state.kd = kdCache.summary || { labels: false };  // { labels: false }: over dense ranks
        if (segs.length <= 256) state.kdSegments = segs;  // world coordinates [x, y, x, y]
        for (const [xa, ya, xb, yb] of segs) {
          const [p, q] = toScreen(xa, ya), [u, v] = toScreen(xb, yb);
          ctx.moveTo(p, q); ctx.lineTo(u, v);
        }
        ctx.stroke();
      }
      if (s.delaunay && s.delaunay.length > 1000) {
        // Many triangles: their edges through a pixel layer. (A canvas path of many closed
        // triangles takes quadratic time to build in Chromium: 16000 cost 0.6 s, 2x10^5 minutes.)
        const tri = trianglesOf(s);
        const L = pixelLayer(), colour = pixel32(COLORS.triangle);
        const q = screenPoints(pos, L.d);  // x, y interleaved (one cache line a vertex); NaN: not alive
        for (let k = 0; k < tri.length; k += 3) {
          const a = 2 * tri[k], b = 2 * tri[k + 1], c = 2 * tri[k + 2];
          if (a < 0 || b < 0 || c < 0) continue;
          const xa = q[a], ya = q[a + 1], xb = q[b], yb = q[b + 1], xc = q[c], yc = q[c + 1];
          if (xa !== xa || xb !== xb || xc !== xc) continue;
          layerLine(L, xa, ya, xb, yb, colour); layerLine(L, xb, yb, xc, yc, colour); layerLine(L, xc, yc, xa, ya, colour);
        }
        drawLayer(L, ctx);
        note(COLORS.triangle, "a Delaunay edge", "line");
      } else if (s.delaunay) {
        note(COLORS.triangle, "a Delaunay edge", "line");
        ctx.strokeStyle = COLORS.triangle; ctx.beginPath();
        for (const tri of s.delaunay) {
          const ps = tri.map((id) => pos.get(id));
          if (ps.some((p) => !p)) continue;
          const sp = ps.map((p) => toScreen(p[0], p[1]));
          ctx.moveTo(sp[0][0], sp[0][1]); ctx.lineTo(sp[1][0], sp[1][1]); ctx.lineTo(sp[2][0], sp[2][1]); ctx.closePath();
        }
        ctx.stroke();
      }
      if (s.hull && s.hull.length > 0) {
        const sp = s.hull.map((id) => pos.get(id)).filter((p) => p).map((p) => toScreen(p[0], p[1]));
        ctx.strokeStyle = COLORS.hull; ctx.lineWidth = 2; ctx.beginPath();
        sp.forEach(([x, y], k) => (k === 0 ? ctx.moveTo(x, y) : ctx.lineTo(x, y)));
        ctx.closePath(); ctx.stroke(); ctx.lineWidth = 1;
        state.hull = sp;
        note(COLORS.hull, "the convex hull", "thick");
      }
      if (s.colliding_pairs) {
        if (s.colliding_pairs.length) note(COLORS.pair, "two boxes in contact (centres joined)", "line");
        ctx.strokeStyle = COLORS.pair; ctx.beginPath();
        for (const [a, b] of s.colliding_pairs) {
          const p = pos.get(a), q = pos.get(b);
          if (!p || !q) continue;
          const [x1, y1] = toScreen(p[0], p[1]), [x2, y2] = toScreen(q[0], q[1]);
          ctx.moveTo(x1, y1); ctx.lineTo(x2, y2);
        }
        ctx.stroke();
      }
      if (s.tops && dim >= 2) {
        // The kinetic bounding box: per axis the min and max tournaments' winners.
        const ext = {};
        for (const top of s.tops) { const p = pos.get(top.id); if (p && top.axis < 2) ext[top.extreme + top.axis] = p[top.axis]; }
        if (ext.min0 !== undefined && ext.max0 !== undefined && ext.min1 !== undefined && ext.max1 !== undefined) {
          const [xa, ya] = toScreen(ext.min0, ext.max1), [xb, yb] = toScreen(ext.max0, ext.min1);
          ctx.strokeStyle = COLORS.hull; ctx.lineWidth = 2; ctx.strokeRect(xa, ya, xb - xa, yb - ya); ctx.lineWidth = 1;
          note(COLORS.hull, "the bounding box (min and max tournaments)", "box");
        }
      }
      if (query) {
        const q = sc.timeline[query.index].query;
        ctx.strokeStyle = COLORS.query; ctx.lineWidth = 2;
        if (q.box) {
          const [xa, ya] = toScreen(q.box[0][0], q.box[1][1]), [xb, yb] = toScreen(q.box[0][1], q.box[1][0]);
          ctx.strokeRect(xa, ya, xb - xa, yb - ya);
          note(COLORS.query, "the query's box", "box");
        }
        if (q.shape) note(COLORS.query, "the query's " + (q.shape.disk ? "disk" : "polygon"), "line");
        if (q.point) note(COLORS.query, "the query's point", "cross");
        if (q.shape && q.shape.disk) {
          const [cx, cy] = toScreen(q.shape.disk.center[0], q.shape.disk.center[1]);
          ctx.beginPath(); ctx.arc(cx, cy, q.shape.disk.radius * view.sx, 0, 2 * Math.PI); ctx.stroke();
        }
        if (q.shape && q.shape.polygon) {
          ctx.beginPath();
          q.shape.polygon.forEach((v, k) => { const [x, y] = toScreen(v[0], v[1]); if (k === 0) ctx.moveTo(x, y); else ctx.lineTo(x, y); });
          ctx.closePath(); ctx.stroke();
        }
        if (q.point) {
          const [x, y] = toScreen(q.point[0], q.point[1]);
          ctx.beginPath(); ctx.moveTo(x - 6, y - 6); ctx.lineTo(x + 6, y + 6); ctx.moveTo(x - 6, y + 6); ctx.lineTo(x + 6, y - 6); ctx.stroke();
        }
        ctx.lineWidth = 1;
      }
      note(objectsAre === "boxes" ? COLORS.box : COLORS.point, objectsAre === "boxes" ? "a box (its centre marked)" : "an object", objectsAre === "boxes" ? "box" : "square");
      const small = pos.size > LARGE;  // many objects: small squares, no boxes
      let recorded = 0;
      if (small) {
        // Through a pixel layer (the same 2x2 squares, snapped to pixels), in objectList's order.
        const L = pixelLayer(), colour = pixel32(COLORS.point);
        const cx = view.cx, cy = view.cy, sx = view.sx, sy = view.sy, w2 = W / 2, h2 = H / 2;
        for (let k = 0; k < N; ++k) {
          if (pos.piece[k] === null) continue;
          const id = objectIds[k];
          if (highlighted.size > 0 && highlighted.has(id)) continue;
          const px = (pos.x[k] - cx) * sx + w2, py = h2 - (pos.y[k] - cy) * sy;
          layerSquare(L, px, py, 1, colour);
          if (recorded < 5000) { state.positions[id] = [px, py]; ++recorded; }
        }
        drawLayer(L, ctx);
      }
      if (!small) for (const [id, p] of pos.entries()) {
        const [px, py] = toScreen(p[0], p[1]);
        if (objectsAre === "boxes" && p[2].h) {
          const h = p[2].h;
          ctx.strokeStyle = highlighted.has(id) ? COLORS.highlight : COLORS.box;
          ctx.strokeRect(px - h[0] * view.sx, py - (h.length > 1 ? h[1] : 0) * view.sy,
                         2 * h[0] * view.sx, 2 * (h.length > 1 ? h[1] : 0) * view.sy);
        }
        if (highlighted.has(id)) continue;
        const r = small ? 1 : 3;
        ctx.fillStyle = COLORS.point;
        ctx.fillRect(px - r, py - r, 2 * r, 2 * r);
        if (recorded < 5000) { state.positions[id] = [px, py]; ++recorded; }
      }
      for (const id of highlighted) {  // the answer's objects last, on top
        const p = pos.get(id);
        if (!p) continue;
        const [px, py] = toScreen(p[0], p[1]);
        ctx.fillStyle = COLORS.highlight;
        ctx.fillRect(px - 5, py - 5, 10, 10);
        state.positions[id] = [px, py];
      }
      if (query && query.type === "k_nearest" && Array.isArray(query.result) && query.result.length > 0 && sc.dimension === 2) {
        // The circle about the query point through the k-th nearest (every answer inside or on
        // it, every other object on or outside), and each answer's rank beside it.
        const q = sc.timeline[query.index].query;
        const last = pos.get(query.result[query.result.length - 1]);
        if (last) {
          const [cx, cy] = toScreen(q.point[0], q.point[1]);
          const radius = Math.hypot(last[0] - q.point[0], last[1] - q.point[1]) * view.sx;
          ctx.strokeStyle = COLORS.query; ctx.lineWidth = 1; ctx.setLineDash([5, 4]);
          ctx.beginPath(); ctx.arc(cx, cy, radius, 0, 2 * Math.PI); ctx.stroke(); ctx.setLineDash([]);
          note(COLORS.query, "the circle through the k-th nearest", "line");
          state.kNearest = { center: [cx, cy], radius, ranks: [] };
          ctx.fillStyle = "#000"; ctx.font = "11px sans-serif";
          query.result.forEach((id, r) => {
            const p = pos.get(id);
            if (!p) return;
            const [px, py] = toScreen(p[0], p[1]);
            state.kNearest.ranks.push([id, r + 1]);
            if (query.result.length <= 20) ctx.fillText(String(r + 1), px + 7, py - 7);
          });
        }
      }
      if (s.closest_pair && s.closest_pair.length === 2) {
        const p = pos.get(s.closest_pair[0]), q = pos.get(s.closest_pair[1]);
        if (p && q) {
          const [x1, y1] = toScreen(p[0], p[1]), [x2, y2] = toScreen(q[0], q[1]);
          ctx.strokeStyle = COLORS.pair; ctx.lineWidth = 3;
          ctx.beginPath(); ctx.moveTo(x1, y1); ctx.lineTo(x2, y2); ctx.stroke(); ctx.lineWidth = 1;
          state.pair = [[x1, y1], [x2, y2]];
          note(COLORS.pair, "the closest pair", "thick");
        }
      }
    }
    if (highlighted.size > 0) note(COLORS.highlight, "the query's answer", "square");
    drawAxes(state);
    drawLegend(legend, state);
    const ms = performance.now() - started;
    frameTimes.push(ms);
    if (frameTimes.length > 240) frameTimes.shift();
    state.frameMs = ms;
    lastState = state;
    updateSide(step, snap);
  }

  // ---- The side: info and the step list (virtual: only the visible rows exist). ---------------
  const list = document.getElementById("list");
  const ROW = 18;
  let visibleSteps = [];
  function rebuildList() {
    visibleSteps = [];
    for (let i = 0; i < steps.length; ++i) if (showInternal || steps[i].k !== "internal") visibleSteps.push(i);
    list.innerHTML = "";
    const spacer = document.createElement("div");
    spacer.style.height = (visibleSteps.length * ROW) + "px";
    list.appendChild(spacer);
    renderRows();
  }
  /// An event in words, with its ids (the README's --events table says what each kind's ids are).
  function eventWords(s) {
    const ids = s.ids || [], a = ids[0], b = ids[1], list = ids.join(", ");
    const axis = s.axis !== undefined ? " on axis " + s.axis : "";
    switch (s.kind) {
      case "swap": return "swap" + axis + ": " + a + " up past " + b;
      case "max_change": return "the max" + axis + " passes from " + a + " to " + b;
      case "min_change": return "the min" + axis + " passes from " + a + " to " + b;
      case "longest_side": return "a cell's longest side changes (points " + list + ")";
      case "endpoint_swap": return a === b ? "interval " + a + "'s two ends meet" : "ends of intervals " + a + " and " + b + " swap";
      case "hull_change": return "the hull changes (points " + list + ")";
      case "contact_begin": return "boxes " + a + " and " + b + " touch";
      case "contact_end": return "boxes " + a + " and " + b + " part";
      case "flip": return "Delaunay flip (points " + list + ")";
      case "inversion": return "triangle " + list + " turned clockwise (repaired)";
      case "pair_change": return "the closest pair becomes " + a + ", " + b;
      case "external": return "an event that changed an answer";
      default: return s.kind + (ids.length ? " " + list : "") + axis;
    }
  }
  /// A query's answer in words: its ids (the first few), or how many pairs or triangles.
  function answerWords(r) {
    if (r === null || r === undefined) return "none";
    if (!Array.isArray(r)) return "object " + r;
    if (r.length === 0) return "nothing";
    if (Array.isArray(r[0])) return r.length + (r[0].length === 3 ? " triangles" : r[0].length === 2 && typeof r[0][0] === "number" ? " pairs" : " entries");
    const shown = r.slice(0, 8).join(", ") + (r.length > 8 ? ", ..." : "");
    return r.length + (r.length === 1 ? " object: " : " objects: ") + shown;
  }
  function describe(s) {
    const t = "t=" + s.t.toPrecision(7) + "  ";
    if (s.k === "event") return t + eventWords(s);
    if (s.k === "internal") return t + "an internal event (no answer changed)";
    if (s.k === "op") {
      return t + "object " + s.id + (s.op === "insert" ? " inserted" : s.op === "remove" ? " removed" : " changes course");
    }
    if (s.k === "query" && s.type === "extent" && Array.isArray(s.result))
      return t + "query extent: " + s.result.map((r, a) => "axis " + a + " from " + r[0] + " to " + r[1]).join(", ");
    if (s.k === "query") return t + "query " + s.type + ": " + answerWords(s.result);
    return t + s.k;
  }
  function renderRows() {
    for (const r of Array.from(list.querySelectorAll(".row"))) r.remove();
    const first = Math.max(0, Math.floor(list.scrollTop / ROW) - 5);
    const last = Math.min(visibleSteps.length, first + Math.ceil(list.clientHeight / ROW) + 10);
    for (let k = first; k < last; ++k) {
      const i = visibleSteps[k];
      const s = steps[i];
      const row = document.createElement("div");
      row.className = "row " + s.k + (i === current ? " current" : "");
      row.style.top = (k * ROW) + "px";
      row.textContent = (i + 1) + ".  " + describe(s);
      row.dataset.step = i;
      row.onclick = () => gotoStep(i);
      list.appendChild(row);
    }
  }
  list.addEventListener("scroll", renderRows);
  function scrollToCurrent() {
    let lo = 0, hi = visibleSteps.length - 1;  // visibleSteps ascends: a binary search
    while (lo < hi) { const mid = (lo + hi) >> 1; if (visibleSteps[mid] < current) lo = mid + 1; else hi = mid; }
    const k = visibleSteps.length > 0 && visibleSteps[lo] === current ? lo : -1;
    if (k < 0) return;
    const top = k * ROW;
    if (top < list.scrollTop || top > list.scrollTop + list.clientHeight - ROW) list.scrollTop = top - list.clientHeight / 2;
  }
  function updateSide(step, snap) {
    const left = endLine ? endLine.events.left_out : 0;
    info.textContent =
      header.structure + ", " + header.scheduler + (header.eps ? " eps " + header.eps : "") + "\n" +
      objectList.length + " objects (" + objectsAre + ", dimension " + dim + "), window [" + t0 + ", " + t1 + "]\n" +
      "t = " + T.toPrecision(12) + "\n" +
      (current < 0 ? "the start (before step 1 of " + steps.length + ")"
                   : "step " + (current + 1) + " of " + steps.length + ": " + describe(step)) + "\n" +
      "structure as " + (snap ? (snap.step < 0 ? "at the start" : "after step " + (snap.step + 1)) + " (t = " + snap.t.toPrecision(8) + ")" : "unknown") +
      (left ? "\n" + left + " events beyond the trace's limit are not listed" : "");
    document.getElementById("status").textContent = addressNote +
      "frame " + (frameTimes.length ? frameTimes[frameTimes.length - 1].toFixed(1) : "-") + " ms; " +
      "drag to pan, wheel to zoom, arrows to step, space to play";
  }

  // ---- Controls ------------------------------------------------------------------------------
  const slider = document.getElementById("time");
  function setTime(t, fromStep) {
    T = Math.min(Math.max(t, t0), Math.max(t1, t0));
    if (fromStep === undefined) current = stepAtOrBefore(T);
    else current = fromStep;
    slider.value = String(Math.round((T - t0) / (t1 - t0) * 1e6));
    draw();
    renderRows();
    scrollToCurrent();
    noteAddress();
  }
  // The page's address names what it shows (#step=N counted from 1, #time=T between steps), so
  // that a link opens it there; written at most every quarter second (browsers limit the rate of
  // history changes), and read at the start and when the address is edited: #step=N (0: the
  // start), #time=T, #query=K (the K-th query, from 1).
  let addressTimer = null, shownAddress = "";
  function noteAddress() {
    if (addressTimer !== null) return;
    addressTimer = setTimeout(() => {
      addressTimer = null;
      const at = current >= 0 && steps[current].t === T ? "#step=" + (current + 1)
               : current < 0 && T === t0 ? "#step=0" : "#time=" + T;
      if (at !== location.hash) { shownAddress = at; history.replaceState(null, "", at); }
    }, 250);
  }
  /// Opens the page where its address says; false when it says nothing the page understands.
  function openAddress(hash) {
    const m = /^#(step|time|query)=([-+0-9.eE]+)$/.exec(hash || "");
    if (!m) return false;
    const v = Number(m[2]);
    if (!isFinite(v)) return false;
    if (m[1] === "time") { setTime(v); return true; }
    if (m[1] === "step") {
      if (!Number.isInteger(v) || v < 0 || v > steps.length) return false;
      if (v === 0) setTime(t0, -1); else gotoStep(v - 1);
      return true;
    }
    const queries = [];
    steps.forEach((st, i) => { if (st.k === "query") queries.push(i); });
    if (!Number.isInteger(v) || v < 1 || v > queries.length) return false;
    gotoStep(queries[v - 1]);
    return true;
  }
  window.addEventListener("hashchange", () => {
    if (location.hash === shownAddress) return;
    addressNote = openAddress(location.hash) ? "" : "the address " + location.hash + " names no step, time or query of this run; ";
    draw();
  });
  function gotoStep(i) {
    if (steps.length === 0) return;
    i = Math.max(0, Math.min(steps.length - 1, i));
    setTime(steps[i].t, i);
  }
  function nextStep(dir) {
    let i = current + dir;
    while (i >= 0 && i < steps.length && !showInternal && steps[i].k === "internal") i += dir;
    if (i < 0) { current = -1; setTime(t0, -1); return; }
    gotoStep(i);
  }
  slider.addEventListener("input", () => setTime(t0 + (t1 - t0) * Number(slider.value) / 1e6));
  document.getElementById("first").onclick = () => setTime(t0, -1);
  document.getElementById("last").onclick = () => gotoStep(steps.length - 1);
  document.getElementById("back").onclick = () => nextStep(-1);
  document.getElementById("fwd").onclick = () => nextStep(1);
  const playButton = document.getElementById("play");
  let lastFrame = 0;
  function tick(now) {
    if (!playing) return;
    const dt = lastFrame ? (now - lastFrame) / 1000 : 0;
    lastFrame = now;
    setTime(T + speed * dt);
    if (T >= t1) { setPlaying(false); return; }
    requestAnimationFrame(tick);
  }
  function setPlaying(on) {
    playing = on;
    playButton.textContent = on ? "pause" : "play";
    lastFrame = 0;
    if (on) requestAnimationFrame(tick);
  }
  playButton.onclick = () => setPlaying(!playing);
  document.getElementById("speed").onchange = (e) => { speed = Number(e.target.value); };
  document.getElementById("levels").onchange = (e) => { treeLevels = Number(e.target.value); draw(); };
  document.getElementById("internal").onchange = (e) => { showInternal = e.target.checked; rebuildList(); };
  document.getElementById("fit").onclick = () => { fit(); draw(); };
  document.getElementById("follow").onchange = (e) => { if (e.target.checked) fit(); else setFollow(false); draw(); };
  document.addEventListener("keydown", (e) => {
    if (e.key === "ArrowRight") nextStep(1);
    else if (e.key === "ArrowLeft") nextStep(-1);
    else if (e.key === " ") { setPlaying(!playing); e.preventDefault(); }
  });
  let drag = null;
  canvas.addEventListener("mousedown", (e) => { drag = [e.offsetX, e.offsetY, view.cx, view.cy]; canvas.style.cursor = "grabbing"; });
  window.addEventListener("mouseup", () => { drag = null; canvas.style.cursor = "grab"; });
  canvas.addEventListener("mousemove", (e) => {
    if (!drag) return;
    setFollow(false);
    view.cx = drag[2] - (e.offsetX - drag[0]) / view.sx;
    view.cy = drag[3] + (e.offsetY - drag[1]) / view.sy;
    draw(true);
  });
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    setFollow(false);
    const f = Math.exp(-e.deltaY * 0.0015);
    const [wx, wy] = toWorld(e.offsetX, e.offsetY);
    // (Not so far in that a pixel is below the doubles' resolution at the view's centre.)
    const limit = 1 / (4e-15 * Math.max(1, Math.abs(view.cx), Math.abs(view.cy)));
    if (f > 1 && Math.max(view.sx, view.sy) * f > limit) return;
    view.sx *= f; view.sy *= f;
    const [nx, ny] = toWorld(e.offsetX, e.offsetY);
    view.cx += wx - nx; view.cy += wy - ny;
    draw(true);
  }, { passive: false });

  function resize() {
    const box = document.getElementById("canvas-box");
    W = box.clientWidth; H = box.clientHeight;
    canvas.width = Math.round(W * devicePixelRatio); canvas.height = Math.round(H * devicePixelRatio);
    trajectories = null;
  }
  // The canvas follows its box (a window resize, or the bars' heights changing).
  new ResizeObserver(() => { resize(); if (steps) draw(); }).observe(document.getElementById("canvas-box"));

  resize();
  fit();
  rebuildList();
  setTime(t0, -1);
  if (location.hash && !openAddress(location.hash)) {
    addressNote = "the address " + location.hash + " names no step, time or query of this run; ";
    draw();
  }

  window.kineticViewer = {
    ready: true,
    header: header,
    steps: steps,
    snapshots: snapshots,
    colors: COLORS,
    gotoStep: gotoStep,
    gotoTime: (t) => setTime(t),
    openAddress: openAddress,
    play: () => setPlaying(true),
    pause: () => setPlaying(false),
    fit: () => { fit(); draw(); },
    toScreen: toScreen,
    state: () => lastState,
    frameTimes: () => frameTimes.slice(),
    redraw: () => draw(),
  };
})();
