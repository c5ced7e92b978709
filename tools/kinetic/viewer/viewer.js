// The replay viewer of kinetic traces (kinetic-trace/1, docs/trace-format.md; docs/viewer.md).
// Plain JavaScript, no library: it reads the trace embedded in the page, evaluates every
// object's motion at the displayed time (the scenario's polynomials, updates and inserts and
// removes of the timeline), and draws the objects and the structure's latest snapshot on a
// canvas. window.kineticViewer is the page's state and controls, for the tests.
"use strict";
(function () {
  const COLORS = {
    point: "#1f77b4", highlight: "#ff8000", hull: "#2ca02c", cell: "#9a9a9a", triangle: "#b8b8b8",
    pair: "#d62728", query: "#0a58ca", now: "#d62728", event: "#444444", box: "#1f77b4",
  };

  // ---- The trace ------------------------------------------------------------------------------
  const raw = document.getElementById("kinetic-trace").textContent;
  const lines = raw.split("\n").filter((l) => l.trim().length > 0);
  const info = document.getElementById("info");
  if (lines.length === 0) { info.textContent = "no trace in this page"; return; }
  const header = JSON.parse(lines[0]);
  if (header.format !== "kinetic-trace/1") {
    info.textContent = "not a kinetic-trace/1 trace: " + header.format;
    return;
  }
  const sc = header.scenario;
  const objectsAre = sc.objects_are || "points";
  const dim = sc.dimension;
  const steps = [];      // events, internal events, ops and queries, in trace order
  const snapshots = [];  // each with .step: the step it follows (-1: before the first)
  let endLine = null;
  for (let i = 1; i < lines.length; ++i) {
    const o = JSON.parse(lines[i]);
    if (o.k === "snapshot") { o.step = steps.length - 1; snapshots.push(o); }
    else if (o.k === "end") endLine = o;
    else { o.index_in_steps = steps.length; steps.push(o); }
  }
  const t0 = sc.start_time;
  let t1 = sc.end_time !== undefined && sc.end_time !== null ? sc.end_time
         : (endLine ? endLine.t : (steps.length ? steps[steps.length - 1].t : t0 + 1));
  if (!(t1 > t0)) t1 = t0 + 1;

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
  // Positions at t: id -> [x, y] (2-D: coordinates 0 and 1; 1-D: [t, x]; intervals: [lo, hi]).
  function positionsAt(t) {
    const out = new Map();
    for (const o of objectList) {
      const p = pieceAt(o, t);
      if (!p) continue;
      const x = evalCoord(p, 0, t);
      const y = p.c.length > 1 ? evalCoord(p, 1, t) : 0;
      out.set(o.id, [x, y, p]);
    }
    return out;
  }

  // ---- The view ------------------------------------------------------------------------------
  const oneD = dim === 1 || objectsAre === "intervals";
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

  function fit() {
    let xmin = Infinity, xmax = -Infinity, ymin = Infinity, ymax = -Infinity;
    const grow = (x, y) => {
      if (!isFinite(x) || !isFinite(y)) return;
      xmin = Math.min(xmin, x); xmax = Math.max(xmax, x); ymin = Math.min(ymin, y); ymax = Math.max(ymax, y);
    };
    const samples = oneD ? 24 : 3;
    for (let k = 0; k <= samples; ++k) {
      const t = t0 + (t1 - t0) * k / samples;
      for (const [, p] of positionsAt(t)) {
        if (oneD) { grow(t, p[0]); if (objectsAre === "intervals") grow(t, p[1]); }
        else {
          const h = p[2].h;
          grow(p[0] - (h ? h[0] : 0), p[1] - (h && h.length > 1 ? h[1] : 0));
          grow(p[0] + (h ? h[0] : 0), p[1] + (h && h.length > 1 ? h[1] : 0));
        }
      }
    }
    if (!isFinite(xmin)) { xmin = -1; xmax = 1; ymin = -1; ymax = 1; }
    if (xmax - xmin < 1e-12) { xmin -= 1; xmax += 1; }
    if (ymax - ymin < 1e-12) { ymin -= 1; ymax += 1; }
    view.cx = (xmin + xmax) / 2; view.cy = (ymin + ymax) / 2;
    view.sx = (W * 0.9) / (xmax - xmin); view.sy = (H * 0.9) / (ymax - ymin);
    if (!oneD) { view.sx = view.sy = Math.min(view.sx, view.sy); }
    trajectories = null;
  }

  // ---- 1-D: trajectories in the (t, x) plane, cached while the view does not change. ----------
  let trajectories = null;
  function drawTrajectories() {
    const key = [W, H, view.cx, view.cy, view.sx, view.sy].join(",");
    if (trajectories && trajectories.key === key) { ctx.drawImage(trajectories.canvas, 0, 0); return; }
    const off = document.createElement("canvas");
    off.width = canvas.width; off.height = canvas.height;
    const g = off.getContext("2d");
    g.setTransform(devicePixelRatio, 0, 0, devicePixelRatio, 0, 0);
    const n = Math.max(1, objectList.length);
    const samples = Math.max(8, Math.min(400, Math.floor(2e6 / n)));
    g.lineWidth = 1;
    g.strokeStyle = "rgba(31,119,180,0.55)";
    g.beginPath();
    const coords = objectsAre === "intervals" ? [0, 1] : [0];
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
    // Event marks (external events with ids), at most 20000 drawn, evenly chosen.
    const marks = steps.filter((s) => s.k === "event" && s.ids && s.ids.length > 0);
    const every = Math.max(1, Math.ceil(marks.length / 20000));
    g.strokeStyle = COLORS.event;
    for (let k = 0; k < marks.length; k += every) {
      const s = marks[k];
      const o = objects.get(s.ids[0]);
      const p = o && pieceAt(o, s.t);
      if (!p) continue;
      const [x, y] = toScreen(s.t, evalCoord(p, 0, s.t));
      g.strokeRect(x - 2.5, y - 2.5, 5, 5);
    }
    trajectories = { key: key, canvas: off };
    ctx.drawImage(off, 0, 0);
  }

  // ---- The structure's snapshot ---------------------------------------------------------------
  function kdCells(orders, pos, maxDepth, primaryOnly) {
    // The rank-based kd-tree's cells from the maintained orders: median splits by rank, axes in
    // turn (primaryOnly: the range tree's splits of axis 0 at every level).
    const rank = orders.map((o) => { const m = new Map(); o.ids.forEach((id, r) => m.set(id, r)); return m; });
    const d = orders.length;
    const segs = [];
    const all = orders[0].ids.filter((id) => pos.has(id));
    function rec(ids, depth, box) {
      if (ids.length < 2 || depth >= maxDepth) return;
      const axis = primaryOnly ? 0 : depth % d;
      ids.sort((a, b) => rank[axis].get(a) - rank[axis].get(b));
      const m = ids.length >> 1;
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

  function idsOf(result) {
    // The ids a query's answer names (flattened), for highlighting.
    const out = [];
    const walk = (v) => { if (Array.isArray(v)) v.forEach(walk); else if (typeof v === "number") out.push(v); };
    walk(result);
    return out;
  }

  let lastState = {};
  function draw() {
    const started = performance.now();
    ctx.setTransform(devicePixelRatio, 0, 0, devicePixelRatio, 0, 0);
    ctx.clearRect(0, 0, W, H);
    const pos = positionsAt(T);
    const snap = snapshotFor(current);
    const s = snap ? snap.snapshot : {};
    const step = current >= 0 ? steps[current] : null;
    const query = step && step.k === "query" && step.t === T ? step : null;
    const highlighted = new Set(query ? idsOf(query.result) : []);
    const state = { time: T, step: current, stepCount: steps.length, view: oneD ? "1d" : "2d",
                    snapshotStep: snap ? snap.step : null, highlighted: Array.from(highlighted),
                    positions: {}, marks: [], hull: null, pair: null,
                    query: query ? query.type : null };

    if (oneD) {
      drawTrajectories();
      const [xn] = toScreen(T, 0);
      ctx.strokeStyle = COLORS.now; ctx.lineWidth = 1;
      ctx.beginPath(); ctx.moveTo(xn, 0); ctx.lineTo(xn, H); ctx.stroke();
      if (query && query.type === "stab") {
        const q = sc.timeline[query.index].query;
        const [, ys] = toScreen(T, q.x);
        ctx.strokeStyle = COLORS.query; ctx.beginPath(); ctx.moveTo(0, ys); ctx.lineTo(W, ys); ctx.stroke();
      }
      if (query && query.type === "range") {
        const b = sc.timeline[query.index].query.box[0];
        const [, ya] = toScreen(T, b[0]), [, yb] = toScreen(T, b[1]);
        ctx.fillStyle = "rgba(10,88,202,0.12)"; ctx.fillRect(0, yb, W, ya - yb);
      }
      const order = Array.from(pos.keys()).filter((id) => !highlighted.has(id))
        .concat(Array.from(pos.keys()).filter((id) => highlighted.has(id)));  // the answer on top
      let barColumn = 0;
      for (const id of order) {
        const p = pos.get(id);
        const ends = objectsAre === "intervals" ? [p[0], p[1]] : [p[0]];
        const hi = highlighted.has(id);
        for (const x of ends) {
          const [px, py] = toScreen(T, x);
          ctx.fillStyle = hi ? COLORS.highlight : COLORS.point;
          const r = hi ? 5 : 3;
          ctx.fillRect(px - r, py - r, 2 * r, 2 * r);
          if (!state.positions[id]) state.positions[id] = [px, py];
          if (state.marks.length < 5000) state.marks.push([px, py]);
        }
        if (objectsAre === "intervals" && hi) {
          // An interval of the answer: a bar beside the time line, one column per interval.
          const [px, pa] = toScreen(T, p[0]), [, pb] = toScreen(T, p[1]);
          const x = px + 8 + 4 * (barColumn++);
          ctx.strokeStyle = COLORS.highlight; ctx.lineWidth = 2;
          ctx.beginPath(); ctx.moveTo(x, pa); ctx.lineTo(x, pb); ctx.stroke(); ctx.lineWidth = 1;
        }
      }
      if (s.tops) {
        for (const top of s.tops) {
          const p = pos.get(top.id);
          if (!p) continue;
          const [px, py] = toScreen(T, p[0]);
          ctx.strokeStyle = COLORS.hull; ctx.lineWidth = 2;
          ctx.beginPath(); ctx.arc(px, py, 8, 0, 2 * Math.PI); ctx.stroke(); ctx.lineWidth = 1;
        }
      }
    } else {
      // Structure first, objects over it.
      if (s.orders && header.structure !== "longest-side-kdtree" && s.orders.length >= 2) {
        const primaryOnly = header.structure === "range-tree";
        const depth = Math.min(primaryOnly ? 6 : 12, Math.ceil(Math.log2(Math.max(2, pos.size))));
        ctx.strokeStyle = COLORS.cell; ctx.lineWidth = 1; ctx.beginPath();
        for (const [xa, ya, xb, yb] of kdCells(s.orders, pos, depth, primaryOnly)) {
          const [p, q] = toScreen(xa, ya), [u, v] = toScreen(xb, yb);
          ctx.moveTo(p, q); ctx.lineTo(u, v);
        }
        ctx.stroke();
      }
      if (s.delaunay) {
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
      }
      if (s.colliding_pairs) {
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
        }
      }
      if (query) {
        const q = sc.timeline[query.index].query;
        ctx.strokeStyle = COLORS.query; ctx.lineWidth = 2;
        if (q.box) {
          const [xa, ya] = toScreen(q.box[0][0], q.box[1][1]), [xb, yb] = toScreen(q.box[0][1], q.box[1][0]);
          ctx.strokeRect(xa, ya, xb - xa, yb - ya);
        }
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
      const small = pos.size > 20000;
      let recorded = 0;
      for (const [id, p] of pos) {
        const [px, py] = toScreen(p[0], p[1]);
        if (objectsAre === "boxes" && p[2].h && !small) {
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
      if (s.closest_pair && s.closest_pair.length === 2) {
        const p = pos.get(s.closest_pair[0]), q = pos.get(s.closest_pair[1]);
        if (p && q) {
          const [x1, y1] = toScreen(p[0], p[1]), [x2, y2] = toScreen(q[0], q[1]);
          ctx.strokeStyle = COLORS.pair; ctx.lineWidth = 3;
          ctx.beginPath(); ctx.moveTo(x1, y1); ctx.lineTo(x2, y2); ctx.stroke(); ctx.lineWidth = 1;
          state.pair = [[x1, y1], [x2, y2]];
        }
      }
    }
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
    visibleSteps = showInternal ? steps.map((s, i) => i) : steps.map((s, i) => i).filter((i) => steps[i].k !== "internal");
    list.innerHTML = "";
    const spacer = document.createElement("div");
    spacer.style.height = (visibleSteps.length * ROW) + "px";
    list.appendChild(spacer);
    renderRows();
  }
  function describe(s) {
    const t = s.t.toPrecision(10);
    if (s.k === "event") return t + "  " + s.kind + (s.ids.length ? " " + s.ids.join(",") : "") + (s.axis !== undefined ? " axis " + s.axis : "");
    if (s.k === "internal") return t + "  internal";
    if (s.k === "op") return t + "  " + s.op + " " + s.id;
    if (s.k === "query") return t + "  query " + s.type + " -> " + JSON.stringify(s.result).slice(0, 60);
    return t + " " + s.k;
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
      row.textContent = "#" + i + "  " + describe(s);
      row.dataset.step = i;
      row.onclick = () => gotoStep(i);
      list.appendChild(row);
    }
  }
  list.addEventListener("scroll", renderRows);
  function scrollToCurrent() {
    const k = visibleSteps.indexOf(current);
    if (k < 0) return;
    const top = k * ROW;
    if (top < list.scrollTop || top > list.scrollTop + list.clientHeight - ROW) list.scrollTop = top - list.clientHeight / 2;
  }
  function updateSide(step, snap) {
    const left = endLine ? endLine.events.left_out : 0;
    info.textContent =
      header.structure + ", " + header.scheduler + (header.eps ? " eps " + header.eps : "") + "\n" +
      objectList.length + " objects (" + objectsAre + ", dimension " + dim + "), window [" + t0 + ", " + t1 + "]\n" +
      "t = " + T.toPrecision(12) + "\nstep " + current + " of " + steps.length +
      (step ? ": " + describe(step) : "") + "\n" +
      "snapshot " + (snap ? "after step " + snap.step + " (t = " + snap.t.toPrecision(8) + ")" : "none") +
      (left ? "\n" + left + " events beyond the trace's limit are not listed" : "");
    document.getElementById("status").textContent =
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
  }
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
  document.getElementById("internal").onchange = (e) => { showInternal = e.target.checked; rebuildList(); };
  document.getElementById("fit").onclick = () => { fit(); draw(); };
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
    view.cx = drag[2] - (e.offsetX - drag[0]) / view.sx;
    view.cy = drag[3] + (e.offsetY - drag[1]) / view.sy;
    draw();
  });
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    const f = Math.exp(-e.deltaY * 0.0015);
    const [wx, wy] = toWorld(e.offsetX, e.offsetY);
    view.sx *= f; view.sy *= f;
    const [nx, ny] = toWorld(e.offsetX, e.offsetY);
    view.cx += wx - nx; view.cy += wy - ny;
    draw();
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

  window.kineticViewer = {
    ready: true,
    header: header,
    steps: steps,
    snapshots: snapshots,
    colors: COLORS,
    gotoStep: gotoStep,
    gotoTime: (t) => setTime(t),
    play: () => setPlaying(true),
    pause: () => setPlaying(false),
    fit: () => { fit(); draw(); },
    toScreen: toScreen,
    state: () => lastState,
    frameTimes: () => frameTimes.slice(),
    redraw: draw,
  };
})();
