// Browser tests of the replay viewer (`kinetic view`), in a real headless Chromium driven by
// puppeteer-core. For a small scenario of each structure: run it with --trace, make the replay
// page, open it from disk, step to given events and queries, and check from the page's state and
// from the pixels of screenshots that the objects are drawn where their motions put them at the
// displayed time and that the structure and the answers are drawn as the trace says. The
// screenshots are kept in the work directory as the test's artifacts.
//
// Usage: node test_viewer.mjs --kinetic PATH/TO/kinetic --work DIR [--chromium /usr/bin/chromium]
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import puppeteer from "puppeteer-core";

const args = Object.fromEntries(
  process.argv.slice(2).reduce((acc, a, i, all) => (a.startsWith("--") ? [...acc, [a.slice(2), all[i + 1]]] : acc), []));
const kinetic = args.kinetic;
const work = args.work;
const chromium = args.chromium || "/usr/bin/chromium";
if (!kinetic || !work) {
  console.error("usage: node test_viewer.mjs --kinetic PATH --work DIR [--chromium PATH]");
  process.exit(2);
}
fs.mkdirSync(work, { recursive: true });

let failures = 0;
function check(ok, what) {
  if (!ok) { failures += 1; console.log("  FAIL " + what); } else console.log("  ok   " + what);
}

function sh(...argv) { return execFileSync(kinetic, argv, { stdio: ["ignore", "pipe", "inherit"] }); }

/// The scenario file of a case: generated, or written from a JSON object.
function scenarioFile(name, spec) {
  const file = path.join(work, name + ".json");
  if (spec.generate) sh("generate", ...spec.generate, "--out", file);
  else fs.writeFileSync(file, JSON.stringify(spec.scenario));
  return file;
}

function intervals(n, seed) {
  let s = seed;
  const rnd = () => { s = (s * 1103515245 + 12345) % 2147483648; return s / 2147483648 * 2 - 1; };
  const objects = [];
  for (let i = 0; i < n; ++i) {
    const x = rnd(), v = rnd(), w = (rnd() + 1) * 0.3;
    objects.push({ id: i, motion: [[x, v], [x + w, v]] });
  }
  const timeline = [2, 4, 6, 8].map((t, k) => ({ time: t, op: "query", query: { type: "stab", x: 0.2 * k - 0.3 } }));
  return { format: "kinetic-scenario/1", dimension: 2, objects_are: "intervals", start_time: 0, end_time: 10, objects, timeline };
}

const CASES = [
  { name: "sort", structure: "sort", generate: ["random-linear", "--n", "12", "--seed", "3", "--queries", "3"] },
  { name: "tournament", structure: "tournament", generate: ["random-linear", "--n", "12", "--seed", "4", "--queries", "3", "--query-type", "max"] },
  { name: "extent", structure: "extent", generate: ["random-linear", "--n", "20", "--seed", "5", "--dimension", "2", "--queries", "3", "--query-type", "extent"] },
  { name: "kdtree", structure: "kdtree", generate: ["random-linear", "--n", "40", "--seed", "6", "--dimension", "2", "--queries", "4", "--query-type", "range"] },
  { name: "kdtree-k-nearest", structure: "kdtree", generate: ["random-linear", "--n", "40", "--seed", "16", "--dimension", "2", "--queries", "3", "--query-type", "k_nearest"] },
  { name: "range-tree", structure: "range-tree", generate: ["random-linear", "--n", "41", "--seed", "7", "--dimension", "2", "--queries", "4", "--query-type", "range"] },
  { name: "longest-side-kdtree", structure: "longest-side-kdtree", generate: ["random-linear", "--n", "30", "--seed", "8", "--dimension", "2", "--end", "0.2", "--queries", "3", "--query-type", "nearest"] },
  { name: "segment-tree", structure: "segment-tree", scenario: intervals(15, 9) },
  { name: "hull", structure: "hull", generate: ["circle", "--n", "24", "--seed", "10", "--queries", "4", "--query-type", "hull"] },
  { name: "delaunay", structure: "delaunay", scheduler: "exact", generate: ["random-linear", "--n", "14", "--seed", "11", "--dimension", "2", "--end", "2", "--queries", "3", "--query-type", "delaunay"] },
  { name: "closest-pair", structure: "closest-pair", scheduler: "exact", generate: ["random-linear", "--n", "14", "--seed", "12", "--dimension", "2", "--end", "2", "--queries", "3", "--query-type", "closest_pair"] },
  { name: "bvh", structure: "bvh", generate: ["boxes-linear", "--n", "20", "--seed", "13", "--dimension", "2", "--queries", "3", "--query-type", "colliding_pairs"] },
  { name: "fat-bvh", structure: "fat-bvh", generate: ["boxes-linear", "--n", "20", "--seed", "15", "--dimension", "2", "--queries", "3", "--query-type", "colliding_pairs"] },
  { name: "sweep-and-prune", structure: "sweep-and-prune", generate: ["boxes-linear", "--n", "20", "--seed", "14", "--dimension", "2", "--queries", "3", "--query-type", "colliding_pairs"] },
];

function hex(c) { return [1, 3, 5].map((k) => parseInt(c.slice(k, k + 2), 16)); }
/// A colour, or its blend with the white background (a thin line's antialiased pixels).
function tinted(rgb, c, tol = 24) {
  const [r, g, b] = hex(c);
  for (let alpha = 0.3; alpha <= 1.0001; alpha += 0.05) {
    const w = [r, g, b].map((v) => alpha * v + (1 - alpha) * 255);
    if (Math.abs(rgb[0] - w[0]) <= tol && Math.abs(rgb[1] - w[1]) <= tol && Math.abs(rgb[2] - w[2]) <= tol) return true;
  }
  return false;
}
function near(rgb, c, tol = 40) { const [r, g, b] = hex(c); return Math.abs(rgb[0] - r) <= tol && Math.abs(rgb[1] - g) <= tol && Math.abs(rgb[2] - b) <= tol; }

function evaluate(piece, axis, t) {
  const c = piece.motion[axis];
  const dt = t - (piece.origin || 0);
  let v = 0;
  for (let j = c.length - 1; j >= 0; --j) v = v * dt + c[j];
  return v;
}

// Chromium can take more than puppeteer's default 30 s to start while the rest of the suite
// runs on both cores (CTest -j2): wait up to two minutes for it.
const browser = await puppeteer.launch({
  executablePath: chromium, headless: true, timeout: 120000,
  args: ["--no-sandbox", "--disable-gpu", "--allow-file-access-from-files", "--force-device-scale-factor=1"],
});

/// Pixels of a screenshot: the PNG decoded by the page into an image data array (RGBA).
async function screenshotPixels(page, file) {
  const png = await page.screenshot({ encoding: "base64" });
  fs.writeFileSync(file, Buffer.from(png, "base64"));
  return page.evaluate(async (data) => {
    const img = new Image();
    img.src = "data:image/png;base64," + data;
    await img.decode();
    const c = document.createElement("canvas");
    c.width = img.width; c.height = img.height;
    const g = c.getContext("2d");
    g.drawImage(img, 0, 0);
    window.__shot = g.getImageData(0, 0, c.width, c.height);
    return [c.width, c.height];
  }, png);
}
/// The colours around (x, y) in the last screenshot, in page pixels (canvas offset added).
async function pixelsAround(page, x, y, r = 1) {
  return page.evaluate((x, y, r) => {
    const box = document.getElementById("canvas").getBoundingClientRect();
    const out = [];
    for (let dy = -r; dy <= r; ++dy) for (let dx = -r; dx <= r; ++dx) {
      const px = Math.round(box.left + x + dx), py = Math.round(box.top + y + dy);
      const k = 4 * (py * window.__shot.width + px);
      out.push([window.__shot.data[k], window.__shot.data[k + 1], window.__shot.data[k + 2]]);
    }
    return out;
  }, x, y, r);
}

/// What a newcomer sees when the page opens: steps counted from the start, axes with a scale, a
/// legend of what is drawn (in the side panel, as the state says), the view fitted to the objects
/// (in the plane: spanning most of the plot, none outside it), the kd-tree's lines inside the
/// objects' extent, and events described in words with their ids.
async function checkFirstLook(page, c, steps) {
  const look = await page.evaluate(() => {
    const v = window.kineticViewer, st = v.state();
    const canvas = document.getElementById("canvas").getBoundingClientRect();
    return { st, info: document.getElementById("info").textContent, w: canvas.width, h: canvas.height,
             legend: Array.from(document.querySelectorAll("#legend div")).map((d) => d.textContent),
             rows: Array.from(document.querySelectorAll("#list .row")).slice(0, 3).map((r) => r.textContent) };
  });
  const st = look.st;
  check(st.step === -1 && look.info.includes(`the start (before step 1 of ${steps.length})`), "opens at the start, steps counted from 1: " + look.info.split("\n")[3]);
  for (const a of ["x", "y"]) {
    const ticks = st.axes ? st.axes[a].ticks : [];
    const ascending = ticks.every((t, k) => k === 0 || t[0] > ticks[k - 1][0]);
    const placed = await page.evaluate((ticks, a) => ticks.every(([v, p]) => {
      const q = a === "x" ? window.kineticViewer.toScreen(v, 0)[0] : window.kineticViewer.toScreen(0, v)[1];
      return Math.abs(q - p) < 1e-6;
    }), ticks, a);
    check(ticks.length >= 3 && ascending && placed, `the ${a} axis: ${ticks.length} ticks at round values, each where its value is (${st.axes && st.axes[a].title})`);
  }
  check(st.legend.length >= 2 && JSON.stringify(look.legend) === JSON.stringify(st.legend), "a legend in the side panel: " + look.legend.join("; "));
  const objects = c.structure.includes("sweep") || c.structure.includes("bvh") ? "a box (its centre marked)" : "an object";
  const oneD = st.view === "1d";
  check(st.legend.includes(oneD ? (c.structure === "segment-tree" ? "an interval's ends now" : "an object now") : objects), "the legend names the objects' mark");
  if (!oneD) {
    // Fitted: every object inside the plot (left of the right edge, above the x axis, right of
    // the y axis), and the objects spanning at least 80 % of it along one axis.
    const ps = Object.values(st.positions);
    const xs = ps.map((p) => p[0]), ys = ps.map((p) => p[1]);
    const inside = ps.every(([x, y]) => x >= 60 && x <= look.w && y >= 0 && y <= look.h - 32);
    const span = Math.max((Math.max(...xs) - Math.min(...xs)) / (look.w - 60), (Math.max(...ys) - Math.min(...ys)) / (look.h - 32));
    check(inside && span >= 0.8, `the view fitted to the objects: all inside the plot, spanning ${(100 * span).toFixed(0)} % of it`);
  }
  if (st.kdSegments) {
    const ext = await page.evaluate(() => {
      const v = window.kineticViewer, sc = v.header.scenario, t = v.state().time;
      const at = (ob, a) => ob.motion[a].reduce((acc, c, k) => acc + c * Math.pow(t - (ob.origin || 0), k), 0);
      const xs = sc.objects.map((ob) => at(ob, 0)), ys = sc.objects.map((ob) => at(ob, 1));
      return [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
    });
    const within = st.kdSegments.every((q) => q[0] >= ext[0] - 1e-9 && q[2] <= ext[1] + 1e-9 && Math.min(q[1], q[3]) >= ext[2] - 1e-9 && Math.max(q[1], q[3]) <= ext[3] + 1e-9);
    check(st.kdSegments.length > 0 && within, `the ${st.kdSegments.length} split lines clipped to the objects' extent`);
  }
  if (c.structure === "sort") {
    check(/^1\.  t=\S+  swap on axis 0: \d+ up past \d+$/.test(look.rows[0] || ""), "events in words, with their ids: " + look.rows[0]);
  }
}

/// A new page on the viewer's html, once the viewer is ready; the page's errors are collected.
async function openViewer(html, address = "") {
  const page = await browser.newPage();
  await page.setViewport({ width: 1100, height: 700, deviceScaleFactor: 1 });
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  await page.goto("file://" + path.resolve(html) + address);
  await page.waitForFunction(() => window.kineticViewer && window.kineticViewer.ready, { timeout: 20000 });
  return { page, errors };
}

for (const c of CASES) {
  console.log("== " + c.name);
  const file = scenarioFile(c.name, c);
  const trace = path.join(work, c.name + ".trace");
  const html = path.join(work, c.name + ".html");
  const statsFile = path.join(work, c.name + ".stats");
  const eventsFile = path.join(work, c.name + ".events");
  sh("run", file, "--structure", c.structure, "--scheduler", c.scheduler || "robust", "--out", path.join(work, c.name + ".answers"), "--stats", statsFile, "--events", eventsFile, "--trace", trace);
  sh("view", trace, "--out", html);
  const { page, errors } = await openViewer(html);
  const header = await page.evaluate(() => window.kineticViewer.header);
  const steps = await page.evaluate(() => window.kineticViewer.steps.map((s) => ({ k: s.k, t: s.t, ids: s.ids, type: s.type, result: s.result, index: s.index })));
  const colors = await page.evaluate(() => window.kineticViewer.colors);
  check(errors.length === 0, "the page loads without errors " + errors.join("; "));
  check(header.structure === c.structure && steps.length > 0, "the trace is read: " + steps.length + " steps");
  await checkFirstLook(page, c, steps);
  // The compact trace read back (kinetic-trace/2: events in lines of columns, times as exact
  // steps): a step for every event, op and query, and the logged events' kinds, ids and times
  // those --events wrote, bit for bit.
  const endLine = JSON.parse(fs.readFileSync(trace, "utf8").trimEnd().split("\n").pop());
  check(header.format === "kinetic-trace/2" && steps.length === endLine.events.written + (header.scenario.timeline || []).length,
        `every event, op and query a step: ${steps.length}`);
  const logged = fs.readFileSync(eventsFile, "utf8").split("\n").filter((l) => l).map((l) => JSON.parse(l));
  const stepEvents = await page.evaluate(() => window.kineticViewer.steps.filter((s) => s.k === "event" && s.kind !== "external").map((s) => ({ t: s.t, kind: s.kind, ids: s.ids, axis: s.axis })));
  check(stepEvents.length === logged.length && stepEvents.every((e, i) => e.t === logged[i].time && e.kind === logged[i].kind && JSON.stringify(e.ids) === JSON.stringify(logged[i].ids) && (e.axis === undefined ? logged[i].axis === undefined : e.axis === logged[i].axis)),
        `the ${logged.length} logged events as --events wrote them (times bit for bit)`);
  // The follow box: in the plane it follows the objects; in 1-D the view is the whole window's
  // trajectories (nothing to follow), and the box is not shown.
  const followShown = await page.evaluate(() => { const l = document.getElementById("follow").closest("label"); return !l.hidden && getComputedStyle(l).display !== "none"; });
  const flat = header.scenario.dimension === 1 || header.scenario.objects_are === "intervals";
  check(followShown === !flat, `the follow box ${flat ? "hidden in 1-D" : "shown in the plane"}`);

  // Objects at their motions' positions: at an event and at each query, every object drawn at
  // its motion's place at the displayed time (pixel of the point's colour, or of the answer's).
  const sc = header.scenario;
  const oneD = sc.dimension === 1 || sc.objects_are === "intervals";
  const targets = [];
  const firstEvent = steps.findIndex((s) => s.k === "event" && s.ids && s.ids.length === 2);
  if (firstEvent >= 0) targets.push(firstEvent);
  steps.forEach((s, i) => { if (s.k === "query") targets.push(i); });
  let shot = 0, checkedObjects = 0;
  for (const i of targets) {
    await page.evaluate((i) => window.kineticViewer.gotoStep(i), i);
    const state = await page.evaluate(() => window.kineticViewer.state());
    check(state.step === i && state.time === steps[i].t, `step ${i} (${steps[i].k}) shown at t = ${steps[i].t}`);
    const png = path.join(work, `${c.name}-step${i}.png`);
    await screenshotPixels(page, png);
    ++shot;
    // Every object of the scenario (no timeline changes here) where its motion is at t.
    let placed = 0, total = 0;
    const highlighted = new Set(state.highlighted);
    const drawnAt = state.marks.length ? state.marks : Object.values(state.positions);  // every mark drawn
    const alone = (p) => drawnAt.filter((q) => Math.hypot(q[0] - p[0], q[1] - p[1]) < 8).length === 1;
    for (const ob of sc.objects) {
      const piece = ob;
      const world = oneD ? [state.time, evaluate(piece, 0, state.time)] : [evaluate(piece, 0, state.time), evaluate(piece, 1, state.time)];
      const [x, y] = await page.evaluate((w) => window.kineticViewer.toScreen(w[0], w[1]), world);
      const drawn = state.positions[ob.id];
      if (!drawn || !alone(drawn)) continue;  // overlapping objects: one pixel cannot tell
      ++total;
      if (Math.abs(drawn[0] - x) < 0.5 && Math.abs(drawn[1] - y) < 0.5) {
        const px = await pixelsAround(page, x, y, 1);
        const want = highlighted.has(ob.id) ? colors.highlight : colors.point;
        if (px.some((p) => near(p, want))) ++placed;
      }
    }
    check(placed === total, `objects drawn at their motions' positions: ${placed}/${total}`);
    checkedObjects += total;
    if (steps[i].k === "query" && steps[i].type === "k_nearest") {
      // The circle through the k-th nearest: the answer inside or on it, the others on or
      // outside; the ranks in the answer's order.
      const kn = state.kNearest;
      const d = (p) => Math.hypot(p[0] - kn.center[0], p[1] - kn.center[1]);
      const inside = kn && steps[i].result.every((id) => !state.positions[id] || d(state.positions[id]) <= kn.radius + 0.5);
      const outside = kn && Object.entries(state.positions).every(([id, p]) => highlighted.has(Number(id)) || d(p) >= kn.radius - 0.5);
      const ranked = kn && kn.ranks.every(([id, r]) => steps[i].result[r - 1] === id);
      check(kn && inside && outside && ranked && kn.radius > 0, `k_nearest: the circle through the k-th nearest (radius ${kn && kn.radius.toFixed(1)} px) holds the ${steps[i].result.length} answers, no other object inside, ranks in order`);
    }
    if (steps[i].k === "query") {
      const want = new Set((function flat(v, out = []) { if (Array.isArray(v)) v.forEach((u) => flat(u, out)); else if (typeof v === "number") out.push(v); return out; })(steps[i].result));
      check(want.size === highlighted.size && [...want].every((id) => highlighted.has(id)), `query ${steps[i].type}: the answer's ${want.size} ids highlighted`);
      let lit = 0;
      for (const id of want) {
        const p = state.positions[id];
        if (p && (await pixelsAround(page, p[0], p[1], 3)).some((q) => near(q, colors.highlight))) ++lit;
      }
      if (want.size > 0 && c.structure !== "sort") check(lit === want.size, `answer's objects in the highlight colour: ${lit}/${want.size}`);
    }
    if (c.structure === "sort" && i === firstEvent) {
      const [a, b] = steps[i].ids;
      const pa = state.positions[a], pb = state.positions[b];
      check(pa && pb && Math.abs(pa[1] - pb[1]) < 1, `swap ${a},${b}: the two points meet at the event's time (y ${pa && pa[1].toFixed(2)} vs ${pb && pb[1].toFixed(2)})`);
    }
    if (c.structure === "hull" && state.hull) {
      const snapHull = await page.evaluate(() => {
        const v = window.kineticViewer; const st = v.state();
        const snaps = v.snapshots.filter((s) => s.step <= st.step); return snaps.length ? snaps[snaps.length - 1].snapshot.hull : null;
      });
      check(snapHull && state.hull.length === snapHull.length, `hull polygon of ${state.hull.length} vertices as the snapshot's ${snapHull && snapHull.length}`);
      let edges = 0;
      let long = 0;
      for (let k = 0; k < state.hull.length; ++k) {
        const p = state.hull[k], q = state.hull[(k + 1) % state.hull.length];
        if (Math.hypot(p[0] - q[0], p[1] - q[1]) < 16) continue;  // under the vertices' marks
        ++long;
        const px = await pixelsAround(page, (p[0] + q[0]) / 2, (p[1] + q[1]) / 2, 1);
        if (px.some((z) => near(z, colors.hull))) ++edges;
      }
      check(long > 0 && edges === long, `hull edges drawn in the hull colour: ${edges}/${long}`);
      if (steps[i].k === "query") {
        const hullIds = steps[i].result;
        check(JSON.stringify(hullIds) === JSON.stringify(snapHull), "the query's hull is the snapshot's hull");
      }
    }
    const snapNow = await page.evaluate(() => {
      const v = window.kineticViewer; const st = v.state();
      const snaps = v.snapshots.filter((s) => s.step <= st.step); return snaps.length ? snaps[snaps.length - 1].snapshot : null;
    });
    if (c.structure === "tournament") {
      // The tree panel: each node shows its level's winner from the snapshot; the root is the top.
      const top = snapNow.tops[0];
      const agree = state.tree.filter((n) => top.levels[n.level][n.index] === n.id).length;
      check(state.tree.length > 0 && agree === state.tree.length, `tournament tree panel: ${agree}/${state.tree.length} nodes show the snapshot's winners`);
      const root = state.tree.find((n) => n.level === 0);
      check(root && root.id === top.id, "the panel's root is the tournament's top");
      if (root) check((await pixelsAround(page, root.x + root.r, root.y, 1)).some((q) => near(q, colors.hull)), "the root's ring drawn in the winner colour");
    }
    if (c.structure === "segment-tree" && steps[i].k === "query") {
      // The canonical sets: the nodes on the query's path are highlighted; the snapshot lists the
      // whole tree here, so the union of their sets is the answer (the segment tree's query).
      const path = state.canonical.filter((n) => n.onPath);
      const union = new Set(path.flatMap((n) => n.ids));
      const answer = new Set(state.highlighted);
      const whole = snapNow.nodes.every((n) => n.depth < 8) && state.canonical.length === snapNow.nodes.filter((n) => n.leaves[0] < snapNow.endpoints.length).length;
      check(whole, `every canonical set drawn: ${state.canonical.length} nodes`);
      check(union.size === answer.size && [...union].every((id) => answer.has(id)), `the highlighted nodes' sets (${union.size} ids) are the stab answer (${answer.size})`);
      let lit = 0, tall = 0;
      for (const n of state.canonical) {
        if (Math.abs(n.y[1] - n.y[0]) < 6) continue;
        ++tall;
        const px = await pixelsAround(page, n.x, (n.y[0] + n.y[1]) / 2, 1);
        if (px.some((q) => near(q, n.onPath ? colors.highlight : colors.node))) ++lit;
      }
      check(tall > 0 && lit === tall, `canonical-set bars drawn in their colours: ${lit}/${tall}`);
    }
    if (c.structure === "bvh") {
      // The root node's box is the bounding box of all boxes at t; its edge is drawn.
      const root = state.bvh.find((b) => b.depth === 0);
      let lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
      for (const ob of sc.objects) for (let a = 0; a < 2; ++a) {
        const x = evaluate(ob, a, state.time);
        lo[a] = Math.min(lo[a], x - ob.half_extents[a]); hi[a] = Math.max(hi[a], x + ob.half_extents[a]);
      }
      const [xa, ya] = await page.evaluate((x, y) => window.kineticViewer.toScreen(x, y), lo[0], hi[1]);
      const [xb, yb] = await page.evaluate((x, y) => window.kineticViewer.toScreen(x, y), hi[0], lo[1]);
      check(root && [xa, ya, xb, yb].every((v, k) => Math.abs(v - root.rect[k]) < 0.5), "the BVH root box is the bounding box of the boxes at t");
      if (root) check((await pixelsAround(page, (root.rect[0] + root.rect[2]) / 2, root.rect[1], 1)).some((q) => near(q, colors.node)), "the root box's edge drawn");
      const separated = new Set(snapNow.pairs.filter((p) => p[2] === "separated").map((p) => p[0] + "," + p[1]));
      check(state.front.every(([a, b]) => separated.has(a + "," + b)), `the separation list's front drawn: ${state.front.length} separated pairs`);
    }
    if (c.structure === "range-tree") {
      // The primary tree halves A_0's slots [0, U - 1] (docs/range-tree.md): the snapshot
      // carries them, and the root's split line (the first drawn, when both halves of the
      // slots hold points) leaves on its left exactly the points of A_0 at a slot < U / 2.
      const o = snapNow.orders[0], u = o.slot_count, kd = state.kd;
      const ok = Array.isArray(o.slots) && o.slots.length === o.ids.length && Number.isInteger(u) && u >= o.ids.length && (u & (u - 1)) === 0;
      check(ok, `range tree: the snapshot's A_0 has slots and slot_count (U = ${u}, a power of two)`);
      check(snapNow.orders.every((q) => Array.isArray(q.slots) && q.slot_count >= 1), "range tree: every order has slots and slot_count");
      check(kd && kd.labels && kd.primary && kd.slot_count === u && kd.points === sc.objects.length, "range tree drawn over A_0's slots");
      const low = new Set(o.ids.filter((id, k) => o.slots[k] < u / 2));
      if (ok && low.size > 0 && low.size < o.ids.length) {
        const x = state.rootSplit ? state.rootSplit[0] : NaN;
        const left = new Set(sc.objects.filter((ob) => evaluate(ob, 0, state.time) < x).map((ob) => ob.id));
        check(kd.root && kd.root.slots[0] === 0 && kd.root.slots[1] === u - 1, "the first line drawn is the root's split, node [0, U - 1]");
        check(left.size === low.size && [...low].every((id) => left.has(id)),
              `range tree root split at x = ${x}: the ${left.size} points on its left are those at a slot < U/2 = ${u / 2} (${low.size})`);
      } else {
        console.log(`  (range tree: one half of [0, ${u - 1}] empty, no root split to check)`);
      }
    }
    if (c.structure === "kdtree") {
      // The library's tree from the snapshot's slots (docs/kdtree.md): the root (the first
      // skeleton depth where the points take both sides) splits through the first point of its
      // axis's order at a label >= its median; the points of lower labels lie on its left.
      const kd = state.kd, n = sc.objects.length;
      check(kd && kd.labels && kd.complete && kd.points === n, "kd-tree drawn over the orders' slots, whole");
      const root = kd && kd.root;
      const order = root ? snapNow.orders[root.axis] : null;
      const first = order ? order.slots.findIndex((slot) => slot >= root.median) : -1;
      check(first >= 0 && order.ids[first] === root.split, `kd-tree root: split through the first point of axis ${root && root.axis} at a label >= ${root && root.median}`);
      if (first >= 0) {
        const at = evaluate(sc.objects.find((ob) => ob.id === root.split), root.axis, state.time);
        const left = sc.objects.filter((ob) => evaluate(ob, root.axis, state.time) < at).length;
        check(first > 0 && first < n && left === first, `kd-tree root split leaves ${left} points on the left (${first}: the labels below the median)`);
        const drawn = state.rootSplit && (root.axis === 0 ? state.rootSplit[0] === state.rootSplit[2] && state.rootSplit[0] === at
                                                          : state.rootSplit[1] === state.rootSplit[3] && state.rootSplit[1] === at);
        if (root.chain.every((e) => e.split === null)) check(drawn, "the first cell line drawn is the root's split");
      }
    }
    if (c.structure === "longest-side-kdtree") {
      check(state.cells.length === snapNow.cells.length && state.cells.length > 0, `longest-side cells: ${state.cells.length} splits for ${snapNow.cells.length} cells`);
      const clear = state.cells.filter((k) => {
        const m = [(k.from[0] + k.to[0]) / 2, (k.from[1] + k.to[1]) / 2];
        return Math.hypot(k.to[0] - k.from[0], k.to[1] - k.from[1]) > 12 && state.marks.concat(Object.values(state.positions)).every((q) => Math.hypot(q[0] - m[0], q[1] - m[1]) > 8);
      });
      let drawn = 0;
      for (const k of clear) if ((await pixelsAround(page, (k.from[0] + k.to[0]) / 2, (k.from[1] + k.to[1]) / 2, 1)).some((q) => tinted(q, colors.cell))) ++drawn;
      check(clear.length > 0 && drawn === clear.length, `split segments drawn: ${drawn}/${clear.length}`);
    }
    if (c.structure === "closest-pair" && state.pair) {
      const [p, q] = state.pair;
      const px = await pixelsAround(page, (p[0] + q[0]) / 2, (p[1] + q[1]) / 2, 1);
      check(px.some((z) => near(z, colors.pair)), "the closest pair's segment drawn");
    }
  }
  if (c.structure === "kdtree") {
    // At the end of the run the viewer's tree (from the last snapshot) has as many nodes as the
    // library's T(P) (--stats tree_nodes: active nodes, leaves and chain nodes).
    await page.evaluate(() => { const v = window.kineticViewer; v.gotoStep(v.steps.length - 1); });
    const end = await page.evaluate(() => { const v = window.kineticViewer; return { state: v.state(), last: v.snapshots[v.snapshots.length - 1].step }; });
    const nodes = JSON.parse(fs.readFileSync(statsFile, "utf8")).structure_counters.tree_nodes;
    check(end.last === steps.length - 1 && end.state.snapshotStep === end.last, "the last snapshot holds the run's final tree");
    check(end.state.kd && end.state.kd.nodes === nodes, `the viewer's kd-tree has the library's ${nodes} nodes (${end.state.kd && end.state.kd.nodes})`);
  }
  check(shot > 0, `${shot} screenshots kept in ${work}`);
  check(checkedObjects > 0, `${checkedObjects} object placements checked in all`);
  // Stepping backwards and scrubbing work from any place.
  await page.evaluate(() => { const v = window.kineticViewer; v.gotoStep(v.steps.length - 1); });
  await page.keyboard.press("ArrowLeft");
  const back = await page.evaluate(() => window.kineticViewer.state());
  check(back.step < steps.length - 1, "the left arrow steps back");
  await page.evaluate(() => window.kineticViewer.gotoTime(window.kineticViewer.header.scenario.start_time));
  const first = await page.evaluate(() => window.kineticViewer.state());
  check(first.step === -1 || steps[first.step].t <= first.time, "scrubbing to the start");
  // A click on a row of the event list jumps to it.
  const target = await page.evaluate(() => {
    const rows = Array.from(document.querySelectorAll("#list .row"));
    const row = rows[Math.min(3, rows.length - 1)];
    if (!row) return null;
    row.click();
    return Number(row.dataset.step);
  });
  if (target !== null) {
    const clicked = await page.evaluate(() => window.kineticViewer.state());
    check(clicked.step === target, "a click on the event list jumps to that step");
  }
  await page.close();
}
// The page's address: #step=N (from 1; 0 the start), #time=T and #query=K (from 1) open the page
// there, and stepping writes the step into the address (a link to share).
{
  console.log("== address parameters");
  const html = path.join(work, "sort.html");
  const steps = await (async () => {
    const { page } = await openViewer(html);
    const out = await page.evaluate(() => window.kineticViewer.steps.map((s) => ({ k: s.k, t: s.t })));
    await page.close();
    return out;
  })();
  const queries = steps.map((s, i) => (s.k === "query" ? i : -1)).filter((i) => i >= 0);
  // A time strictly between two steps (the first two of different times after step 1).
  let between = 1;
  while (between + 1 < steps.length && !(steps[between].t < steps[between + 1].t)) ++between;
  const t = (steps[between].t + steps[between + 1].t) / 2;
  for (const [address, step, time] of [["#step=3", 2, steps[2].t], ["#step=0", -1, undefined],
                                       ["#time=" + t, between, t], ["#query=2", queries[1], steps[queries[1]].t]]) {
    const { page, errors } = await openViewer(html, address);
    const st = await page.evaluate(() => window.kineticViewer.state());
    check(errors.length === 0 && st.step === step && (time === undefined || st.time === time),
          `${address} opens the page at step ${step} (t = ${st.time})`);
    await page.close();
  }
  const { page } = await openViewer(html);
  await page.evaluate(() => window.kineticViewer.gotoStep(4));
  await new Promise((r) => setTimeout(r, 600));
  check(await page.evaluate(() => location.hash) === "#step=5", "stepping writes #step=5 into the address");
  // An edited address naming a query the page is not at moves it there.
  const k = queries[0] === 4 ? 2 : 1;
  await page.evaluate((k) => { location.hash = "#query=" + k; }, k);
  await new Promise((r) => setTimeout(r, 300));
  check(await page.evaluate(() => window.kineticViewer.state().step) === queries[k - 1], `an edited address (#query=${k}) moves the page there`);
  // One that names nothing of the run is said so in the status line.
  await page.evaluate(() => { location.hash = "#step=99999"; });
  await new Promise((r) => setTimeout(r, 300));
  check((await page.evaluate(() => document.getElementById("status").textContent)).includes("names no step, time or query"), "an address naming nothing is said so");
  await page.close();
}
/// A hand-made trace of one snapshot of `structure` over the fixed `objects` (at t = 0 and 0.5,
/// a range query over all of them at 0.5; a whole trace, as `kinetic view` checks: the header's
/// limits, the end line with its counts), made a page and opened at the first snapshot: the
/// page, its state, and whether the cell colour is drawn around a world point (last screenshot).
async function openHandMade(name, structure, objects, snapshot) {
  const scenario = { format: "kinetic-scenario/1", dimension: 2, objects_are: "points", start_time: 0, end_time: 1, objects,
                     timeline: [{ time: 0.5, op: "query", query: { type: "range", box: [[-1, 5], [-1, 5]] } }] };
  const limits = { max_events: 1000000, max_snapshots: 2000, max_snapshot_bytes: 67108864 };
  const lines = [{ format: "kinetic-trace/1", structure, scheduler: "robust", eps: 1e-9, limits, scenario },
                 { t: 0, k: "snapshot", event: 0, snapshot },
                 { t: 0.5, k: "query", index: 0, type: "range", result: objects.map((ob) => ob.id) },
                 { t: 0.5, k: "snapshot", event: 0, snapshot },
                 { t: 1, k: "end", outcome: "completed", message: "", events: { processed: 0, written: 0, left_out: 0 }, snapshots: { written: 2, left_out: 0 } }];
  const trace = path.join(work, name + ".trace"), html = path.join(work, name + ".html");
  fs.writeFileSync(trace, lines.map((l) => JSON.stringify(l)).join("\n") + "\n");
  sh("view", trace, "--out", html);
  const { page, errors } = await openViewer(html);
  await page.evaluate(() => window.kineticViewer.gotoStep(0));
  const state = await page.evaluate(() => window.kineticViewer.state());
  check(errors.length === 0, "the page loads without errors " + errors.join("; "));
  await screenshotPixels(page, path.join(work, name + ".png"));
  const colors = await page.evaluate(() => window.kineticViewer.colors);
  const lit = async (x, y) => {
    const [px, py] = await page.evaluate((x, y) => window.kineticViewer.toScreen(x, y), x, y);
    return (await pixelsAround(page, px, py, 1)).some((q) => tinted(q, colors.cell));
  };
  return { page, state, lit };
}

// The kd-tree's cells from a hand-made trace: five fixed points whose slots (labels) leave gaps,
// U = 32 on x and 16 on y. The library's tree (docs/kdtree.md), computed by hand: the root, at
// skeleton depth 0, halves x's labels [0, 31] at 16 and splits through id 13 (x = 3): {10, 11,
// 12} | {13, 14}. The left part takes the same sides at depths 1 and 2 (degree-one nodes: y
// below label 8, no point there, +infinity; x below 8, split at id 13) and splits at depth 3,
// y labels [0, 7] at 4 (id 12, y = 4); {10, 11} then goes left of x label 4 at depth 4 (split
// id 13, the first point at a label >= 4 although not in that part) and splits at depth 5,
// y labels [0, 3] at 2 (id 14, y = 2). {13, 14} goes below y label 8 (+infinity), left of x
// label 24 (+infinity), below y label 4 (id 12), left of x label 20 (+infinity) and splits at
// depth 5 at y label 2 (id 14). The chains keep the lowest degree-one node per axis and side.
// Over dense ranks the same points split at x = 1.5 first ({10, 11} | {12, 13, 14}).
{
  const objects = [[0, 3], [1, 0], [2, 4], [3, 1], [4, 2]].map(([x, y], k) => ({ id: 10 + k, motion: [[x], [y]] }));
  const orders = [{ axis: 0, ids: [10, 11, 12, 13, 14], slots: [0, 1, 2, 16, 17], slot_count: 32 },
                  { axis: 1, ids: [11, 13, 14, 10, 12], slots: [0, 1, 2, 3, 4], slot_count: 16 }];
  const chain = (depth, axis, median, split) => ({ depth, axis, side: 0, median, split });
  const want = [
    { depth: 0, axis: 0, median: 16, split: 13, size: 5, chain: [] },
    { depth: 3, axis: 1, median: 4, split: 12, size: 3, chain: [chain(1, 1, 8, null), chain(2, 0, 8, 13)] },
    { depth: 5, axis: 1, median: 2, split: 14, size: 2, chain: [chain(4, 0, 4, 13)] },
    { depth: 5, axis: 1, median: 2, split: 14, size: 2, chain: [chain(3, 1, 4, 12), chain(4, 0, 20, null)] },
  ];
  for (const labels of [true, false]) {
    const name = labels ? "kdtree-labels" : "kdtree-dense";
    console.log("== " + name + " (hand-made trace" + (labels ? ")" : ", no slots: an older trace)"));
    const snapshot = { orders: labels ? orders : orders.map((o) => ({ axis: o.axis, ids: o.ids })) };
    const { page, state, lit } = await openHandMade(name, "kdtree", objects, snapshot);
    if (labels) {
      const kd = state.kd;
      check(kd && kd.labels && kd.complete, "drawn over the slots");
      check(kd && JSON.stringify(kd.preorder) === JSON.stringify(want), "the library's tree, node by node: " + JSON.stringify(kd && kd.preorder));
      check(kd && kd.nodes === 14 && kd.depth === 6, `T(P): ${kd && kd.nodes} nodes (4 active, 5 chain nodes, 5 leaves), leaves down to skeleton depth ${kd && kd.depth}`);
      // The segments drawn: x = 3 (the root), then y = 4 and y = 2 on each side of it (the
      // left part's own splits; the right part's chain node at id 12's y and its split); the
      // chain nodes on x = 3 coincide with the root's line and +infinity bounds nothing.
      const segs = state.kdSegments || [];
      const vertical = segs.filter((q) => q[0] === q[2]).map((q) => q[0]);
      const horizontal = segs.filter((q) => q[1] === q[3]).map((q) => [q[1], q[0] < 3 ? "left" : "right"]).sort();
      check(JSON.stringify(vertical) === "[3]" && JSON.stringify(horizontal) === JSON.stringify([[2, "left"], [2, "right"], [4, "left"], [4, "right"]]),
            "cell lines x = 3 | y = 4, 2 on each side: " + JSON.stringify(segs));
      check(await lit(3, 0.5), "the root's line x = 3 drawn");
      check(!(await lit(1.5, 3.5)), "no line at the dense ranks' median x = 1.5");
    } else {
      check(state.kd && state.kd.labels === false, "no slots: drawn over dense ranks");
      check(state.rootSplit && state.rootSplit[0] === 1.5, "the dense root split at x = 1.5");
      check(await lit(1.5, 3.5), "the dense root's line x = 1.5 drawn");
    }
    await page.close();
  }
}
// The range tree's primary splits from a hand-made trace: the same five points, A_0's slots
// [0, 8, 9, 10, 24] of U = 32 (ids 10 to 14, x = 0 to 4). Depth limit min(6, ceil(log2 5)) = 3
// levels of splits. The root [0, 31] splits {10, 11, 12, 13} | {14} (slots < 16 | >= 16) at
// x = 3.5; its left child [0, 15] splits {10} | {11, 12, 13} (< 8 | >= 8) at x = 0.5; then
// [8, 15] holds them all in [8, 11] (its right child [12, 15] empty: nothing drawn, no level
// used) and [8, 11] splits {11, 12} | {13} (< 10 | >= 10) at x = 2.5, the third level: [8, 9]'s
// split at x = 1.5 is below the limit. Over dense ranks (no slots, an older trace) the root
// [0, 4] leaves ceil(5/2) = 3 points on its left: x = 2.5 first, and every split (1.5, 0.5, 3.5)
// drawn.
{
  const objects = [[0, 3], [1, 0], [2, 4], [3, 1], [4, 2]].map(([x, y], k) => ({ id: 10 + k, motion: [[x], [y]] }));
  const orders = [{ axis: 0, ids: [10, 11, 12, 13, 14], slots: [0, 8, 9, 10, 24], slot_count: 32 },
                  { axis: 1, ids: [11, 13, 14, 10, 12], slots: [1, 5, 9, 13, 17], slot_count: 32 }];
  for (const labels of [true, false]) {
    const name = labels ? "range-tree-slots" : "range-tree-dense";
    console.log("== " + name + " (hand-made trace" + (labels ? ")" : ", no slots: an older trace)"));
    const snapshot = { orders: labels ? orders : orders.map((o) => ({ axis: o.axis, ids: o.ids })) };
    const { page, state, lit } = await openHandMade(name, "range-tree", objects, snapshot);
    const xs = (state.kdSegments || []).map((q) => (q[0] === q[2] ? q[0] : null));
    if (labels) {
      const kd = state.kd;
      check(kd && kd.labels && kd.primary && kd.slot_count === 32 && kd.points === 5, "drawn over A_0's slots");
      check(kd && kd.root && JSON.stringify(kd.root) === JSON.stringify({ slots: [0, 31], left: 13, right: 14 }), "the root [0, 31] splits between ids 13 and 14: " + JSON.stringify(kd && kd.root));
      check(JSON.stringify(xs) === "[3.5,0.5,2.5]", "primary splits x = 3.5, 0.5, 2.5 in preorder: " + JSON.stringify(xs));
      check(await lit(3.5, 3.5) && await lit(0.5, 3.5) && await lit(2.5, 3.5), "the three lines drawn");
      check(!(await lit(1.5, 3.5)), "no line at x = 1.5 (a fourth level of splits)");
    } else {
      check(state.kd && state.kd.labels === false, "no slots: drawn over dense ranks");
      check(JSON.stringify(xs) === "[2.5,1.5,0.5,3.5]", "dense primary splits x = 2.5, 1.5, 0.5, 3.5 in preorder: " + JSON.stringify(xs));
      check(await lit(2.5, 3.5) && await lit(1.5, 3.5), "the dense root's line x = 2.5 and x = 1.5 drawn");
    }
    await page.close();
  }
}

await browser.close();
console.log(failures === 0 ? "all viewer checks passed" : failures + " viewer checks failed");
process.exit(failures === 0 ? 0 : 1);
