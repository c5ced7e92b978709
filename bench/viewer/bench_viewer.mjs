// Frame-time benchmark of the replay viewer (`kinetic view`) on large traces: the requirement
// "large traces (10^5 objects, 10^6 events) stay interactive". For each configuration it
// generates a scenario (random-linear unless --dataset), runs it with --trace, makes the replay
// page (always anew: it holds the viewer's code being measured), opens it in
// headless Chromium (puppeteer-core, viewport 1280x800) and measures:
//   - the sizes of the trace and of the page;
//   - load: from page.goto until window.kineticViewer.ready (page load + trace parse + first draw);
//   - step: gotoStep at evenly spread steps: the draw time (state().frameMs), the time of the whole
//     gotoStep call in the page (draw + event list + slider), and the round trip from node
//     (evaluate of gotoStep, then the next animation frame: the frame is on screen);
//   - scrub: the same for gotoTime at evenly spread times;
//   - play: playing for a few seconds: draw times (frameMs of each drawn frame) and the intervals
//     between the animation frames (what the user sees: 16.7 ms is 60 frames per second);
//   - step, new snapshot: those of the steps that show another structure snapshot than the
//     step before (what is cached per snapshot is rebuilt);
//   - pan / zoom: one redraw after a drag move and after a wheel step (events dispatched on the
//     canvas), draw time and the call's time; "settled": the draw 400 ms later when there is one
//     (a slow image is previewed during the gesture and drawn in full when it pauses);
//   - fit: the fit button's full redraw (the view changes: every cached image remade).
// It prints the configuration and a table of medians and 95th percentiles (ms per frame).
//
// Usage: node bench_viewer.mjs --kinetic PATH/TO/kinetic --work DIR
//          [--configs sort,kdtree] [--structure S --dimension D] [--n N] [--end T] [--seed S]
//          [--dataset random-linear] [--scheduler robust]
//          [--steps 200] [--scrub 100] [--play-seconds 3] [--pan 10] [--reuse]
//          [--chromium /usr/bin/chromium] [--json FILE]
// Defaults: "sort": 1-D sort of 10^5 points, --end 30 (about 10^6 events);
//           "kdtree": 2-D kd-tree of 10^5 points, --end 0.045 (about 10^6 events; the trace
//           keeps at most 10^6). --structure (with --dimension, --n, --end) runs one
//           configuration of your own instead; --n and --end also override the defaults.
// --reuse: keep the scenario, trace and page of an earlier run with the same configuration.
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
// puppeteer-core is installed for the browser tests (tests/viewer/node_modules); its ESM entry.
const puppeteerPath = path.join(here, "../../tests/viewer/node_modules/puppeteer-core/lib/esm/puppeteer/puppeteer-core.js");
const { default: puppeteer } = await import(puppeteerPath);

const args = {};
for (let i = 2; i < process.argv.length; ++i) {
  const a = process.argv[i];
  if (!a.startsWith("--")) continue;
  const next = process.argv[i + 1];
  if (next === undefined || next.startsWith("--")) args[a.slice(2)] = true;
  else { args[a.slice(2)] = next; ++i; }
}
const kinetic = args.kinetic;
const work = args.work;
if (!kinetic || !work) {
  console.error("usage: node bench_viewer.mjs --kinetic PATH --work DIR [--configs sort,kdtree] [--structure S --dimension D] [--n N] [--end T] ...");
  process.exit(2);
}
const chromium = args.chromium || "/usr/bin/chromium";
const stepCount = Number(args.steps || 200);
const scrubCount = Number(args.scrub || 100);
const playSeconds = Number(args["play-seconds"] || 3);
const panCount = Number(args.pan || 10);
const seed = String(args.seed || 1);
const dataset = String(args.dataset || "random-linear");
const scheduler = String(args.scheduler || "robust");
fs.mkdirSync(work, { recursive: true });

const DEFAULTS = {
  sort: { structure: "sort", dimension: 1, n: 100000, end: 30 },
  kdtree: { structure: "kdtree", dimension: 2, n: 100000, end: 0.045 },
};
let configs;
if (args.structure) {
  const oneD = ["sort", "tournament"].includes(args.structure);
  configs = [{ structure: args.structure, dimension: Number(args.dimension || (oneD ? 1 : 2)),
               n: Number(args.n || 100000), end: Number(args.end || (oneD ? 30 : 0.045)) }];
} else {
  configs = String(args.configs || "sort,kdtree").split(",").map((name) => {
    if (!DEFAULTS[name]) { console.error("unknown configuration " + name); process.exit(2); }
    const c = { ...DEFAULTS[name] };
    if (args.n) c.n = Number(args.n);
    if (args.end) c.end = Number(args.end);
    return c;
  });
}

function sh(...argv) { return execFileSync(kinetic, argv, { stdio: ["ignore", "pipe", "inherit"], maxBuffer: 1 << 26 }); }
function mb(bytes) { return (bytes / 1048576).toFixed(1) + " MB"; }
function pct(values, p) {
  if (values.length === 0) return NaN;
  const s = values.slice().sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.max(0, Math.ceil(p / 100 * s.length) - 1))];
}
function lastLine(file) {
  const fd = fs.openSync(file, "r");
  const size = fs.fstatSync(fd).size;
  const len = Math.min(size, 4096);
  const buf = Buffer.alloc(len);
  fs.readSync(fd, buf, 0, len, size - len);
  fs.closeSync(fd);
  const lines = buf.toString("utf8").trim().split("\n");
  return JSON.parse(lines[lines.length - 1]);
}

const browser = await puppeteer.launch({
  executablePath: chromium, headless: true, protocolTimeout: 600000,
  args: ["--no-sandbox", "--disable-gpu", "--allow-file-access-from-files", "--force-device-scale-factor=1"],
});
const browserVersion = await browser.version();

const results = [];
for (const c of configs) {
  const name = `${c.structure}-${dataset === "random-linear" ? "" : dataset + "-"}${scheduler === "robust" ? "" : scheduler + "-"}d${c.dimension}-n${c.n}-end${c.end}-seed${seed}`;
  const scenario = path.join(work, name + ".json");
  const trace = path.join(work, name + ".trace");
  const html = path.join(work, name + ".html");
  const timings = {};
  let t = Date.now();
  if (!(args.reuse && fs.existsSync(scenario))) {
    const dim = ["random-linear", "random-poly"].includes(dataset) || dataset.startsWith("boxes") ? ["--dimension", String(c.dimension)] : [];
    sh("generate", dataset, "--n", String(c.n), ...dim, "--end", String(c.end), "--seed", seed, "--out", scenario);
  }
  timings.generate = (Date.now() - t) / 1000;
  t = Date.now();
  if (!(args.reuse && fs.existsSync(trace))) {
    sh("run", scenario, "--structure", c.structure, "--scheduler", scheduler, "--out", "/dev/null", "--trace", trace);
  }
  timings.run = (Date.now() - t) / 1000;
  t = Date.now();
  // The page is always remade: it holds the viewer's code being measured.
  sh("view", trace, "--out", html);
  timings.view = (Date.now() - t) / 1000;
  const end = lastLine(trace);
  const traceBytes = fs.statSync(trace).size, pageBytes = fs.statSync(html).size;

  console.log(`\n== ${c.structure} (${scheduler}): ${c.n} objects of ${dataset} in dimension ${c.dimension}, window [0, ${c.end}], seed ${seed}`);
  console.log(`   events processed ${end.events.processed}, in the trace ${end.events.written}; snapshots ${end.snapshots.written}`);
  console.log(`   trace ${mb(traceBytes)}, page ${mb(pageBytes)}; generate ${timings.generate.toFixed(1)} s, run ${timings.run.toFixed(1)} s, view ${timings.view.toFixed(1)} s`);

  const page = await browser.newPage();
  await page.setViewport({ width: 1280, height: 800, deviceScaleFactor: 1 });
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  t = performance.now();
  await page.goto("file://" + path.resolve(html), { timeout: 0, waitUntil: "load" });
  await page.waitForFunction(() => window.kineticViewer && window.kineticViewer.ready, { timeout: 0, polling: 50 });
  const loadMs = performance.now() - t;
  const info = await page.evaluate(() => {
    const v = window.kineticViewer;
    const sc = v.header.scenario;
    return { steps: v.steps.length, objects: sc.objects.length, t0: sc.start_time, t1: sc.end_time,
             heapMB: performance.memory ? performance.memory.usedJSHeapSize / 1048576 : null };
  });
  console.log(`   page: ${info.steps} steps, ${info.objects} objects; ready after ${(loadMs / 1000).toFixed(2)} s; JS heap ${info.heapMB ? info.heapMB.toFixed(0) + " MB" : "?"}`);

  // In the page: one action, its draw time, the call's time; node: the round trip until the next
  // animation frame (the frame is painted).
  async function measure(fn, arg) {
    const t = performance.now();
    const r = await page.evaluate(async (fn, arg) => {
      const v = window.kineticViewer;
      const a = performance.now();
      if (fn === "step") v.gotoStep(arg);
      else if (fn === "time") v.gotoTime(arg);
      else if (fn === "pan" || fn === "zoom") {
        const canvas = document.getElementById("canvas");
        const box = canvas.getBoundingClientRect();
        const x = box.left + box.width / 2, y = box.top + box.height / 2;
        if (fn === "pan") {
          canvas.dispatchEvent(new MouseEvent("mousedown", { clientX: x, clientY: y, bubbles: true }));
          const b = performance.now();
          canvas.dispatchEvent(new MouseEvent("mousemove", { clientX: x + arg, clientY: y + arg / 2, bubbles: true }));
          const call = performance.now() - b;
          window.dispatchEvent(new MouseEvent("mouseup", { clientX: x + arg, clientY: y, bubbles: true }));
          await new Promise((res) => requestAnimationFrame(() => res()));
          window.__benchState = v.state();
          return { frameMs: v.state().frameMs, callMs: call };
        }
        canvas.dispatchEvent(new WheelEvent("wheel", { clientX: x + 40, clientY: y - 30, deltaY: arg, bubbles: true, cancelable: true }));
      } else if (fn === "fit") v.fit();
      const call = performance.now() - a;
      await new Promise((res) => requestAnimationFrame(() => res()));
      const st = v.state();
      window.__benchState = st;
      return { frameMs: st.frameMs, callMs: call, snapshotStep: st.snapshotStep };
    }, fn, arg);
    const wallMs = performance.now() - t;
    if (fn === "pan" || fn === "zoom") {
      // A pan or zoom may be previewed (the last image moved) and drawn in full when the gesture
      // pauses: the draw after 400 ms of quiet, if there is one, else the same draw.
      r.settleMs = await page.evaluate(async () => {
        await new Promise((res) => setTimeout(res, 400));
        const after = window.kineticViewer.state();
        return after !== window.__benchState ? after.frameMs : window.__benchState.frameMs;
      });
    }
    return { ...r, wallMs };
  }
  const table = [];
  function row(what, samples, fields) {
    const r = { what, count: samples.length };
    for (const f of fields) r[f] = { median: pct(samples.map((s) => s[f]), 50), p95: pct(samples.map((s) => s[f]), 95) };
    table.push(r);
  }

  // Stepping: stepCount steps spread over the run (a warm-up step first).
  await measure("step", 0);
  const stepSamples = [];
  for (let k = 0; k < stepCount; ++k) {
    const i = Math.floor((k + 0.5) * info.steps / stepCount);
    stepSamples.push(await measure("step", i));
  }
  row("gotoStep", stepSamples, ["frameMs", "callMs", "wallMs"]);
  // Those of them that show another snapshot than the step before (structure drawings rebuilt).
  const newSnapshot = stepSamples.filter((s, k) => k > 0 && s.snapshotStep !== stepSamples[k - 1].snapshotStep);
  if (newSnapshot.length > 0) row("  new snapshot", newSnapshot, ["frameMs", "callMs", "wallMs"]);
  // Neighbouring steps (the arrow keys): 50 consecutive steps from the middle.
  const nextSamples = [];
  const mid = Math.floor(info.steps / 2);
  for (let k = 0; k < 50; ++k) nextSamples.push(await measure("step", mid + k));
  row("gotoStep +1", nextSamples, ["frameMs", "callMs", "wallMs"]);
  // Scrubbing.
  const scrubSamples = [];
  for (let k = 0; k < scrubCount; ++k) {
    const tt = info.t0 + (info.t1 - info.t0) * (k + 0.5) / scrubCount;
    scrubSamples.push(await measure("time", tt));
  }
  row("gotoTime", scrubSamples, ["frameMs", "callMs", "wallMs"]);
  // Pan and zoom at the middle of the window.
  await measure("time", (info.t0 + info.t1) / 2);
  const panSamples = [], zoomSamples = [];
  for (let k = 0; k < panCount; ++k) panSamples.push(await measure("pan", k % 2 ? -15 : 15));
  for (let k = 0; k < panCount; ++k) zoomSamples.push(await measure("zoom", k % 2 ? 60 : -60));
  row("pan (drag move)", panSamples, ["frameMs", "callMs", "wallMs"]);
  row("  settled", panSamples.map((s) => ({ frameMs: s.settleMs })), ["frameMs"]);
  row("zoom (wheel)", zoomSamples, ["frameMs", "callMs", "wallMs"]);
  row("  settled", zoomSamples.map((s) => ({ frameMs: s.settleMs })), ["frameMs"]);
  // Zoom to fit: the whole drawing remade (1-D: the trajectories' image).
  const fitSamples = [];
  for (let k = 0; k < 3; ++k) fitSamples.push(await measure("fit"));
  row("fit (full)", fitSamples, ["frameMs", "callMs", "wallMs"]);

  // Playing: from the start, at a speed that does not reach the window's end in playSeconds.
  const play = await page.evaluate(async (seconds) => {
    const v = window.kineticViewer;
    const sc = v.header.scenario;
    const sel = document.getElementById("speed");
    const speeds = Array.from(sel.options).map((o) => Number(o.value)).sort((a, b) => a - b);
    const want = (sc.end_time - sc.start_time) / (seconds * 1.5);
    let speed = speeds[0];
    for (const s of speeds) if (s <= want) speed = s;
    sel.value = String(speed);
    sel.dispatchEvent(new Event("change"));
    v.gotoTime(sc.start_time);
    const draws = [], intervals = [];
    let last = v.state(), lastFrame = 0, stop = false;
    const watch = (now) => {
      if (lastFrame) intervals.push(now - lastFrame);
      lastFrame = now;
      const s = v.state();
      if (s !== last) { draws.push(s.frameMs); last = s; }
      if (!stop) requestAnimationFrame(watch);
    };
    const startTime = v.state().time;
    v.play();
    requestAnimationFrame(watch);
    await new Promise((res) => setTimeout(res, seconds * 1000));
    v.pause();
    stop = true;
    const endTime = v.state().time;
    sel.value = "1";
    sel.dispatchEvent(new Event("change"));
    return { speed, draws, intervals, startTime, endTime, ring: v.frameTimes().length };
  }, playSeconds);
  const pr = { what: "play", count: play.draws.length,
               frameMs: { median: pct(play.draws, 50), p95: pct(play.draws, 95) },
               intervalMs: { median: pct(play.intervals, 50), p95: pct(play.intervals, 95) } };
  table.push(pr);

  // The page's own ring of frame times (the last up to 240 draws).
  const ring = await page.evaluate(() => window.kineticViewer.frameTimes());
  const heapAfter = await page.evaluate(() => (performance.memory ? performance.memory.usedJSHeapSize / 1048576 : null));
  await page.close();

  console.log(`   play: speed ${play.speed} time units/s for ${playSeconds} s, t ${play.startTime.toPrecision(4)} -> ${play.endTime.toPrecision(4)}, ${play.draws.length} frames drawn (${(play.draws.length / playSeconds).toFixed(1)} per second)`);
  console.log(`   frameTimes() ring: ${ring.length} draws, median ${pct(ring, 50).toFixed(2)} ms, p95 ${pct(ring, 95).toFixed(2)} ms; JS heap after ${heapAfter ? heapAfter.toFixed(0) + " MB" : "?"}`);
  if (errors.length) console.log("   PAGE ERRORS: " + errors.join("; "));
  const f = (x) => (x === undefined || Number.isNaN(x) ? "-" : x.toFixed(2));
  console.log("");
  console.log("   " + ["action", "n", "draw med", "draw p95", "call med", "call p95", "wall med", "wall p95"].map((h, k) => (k === 0 ? h.padEnd(16) : h.padStart(9))).join(" "));
  console.log("   " + ["load (ready)", "1", "", "", "", "", f(loadMs), f(loadMs)].map((h, k) => (k === 0 ? h.padEnd(16) : h.padStart(9))).join(" "));
  for (const r of table) {
    const cells = r.what === "play"
      ? [r.what, String(r.count), f(r.frameMs.median), f(r.frameMs.p95), "", "", f(r.intervalMs.median), f(r.intervalMs.p95)]
      : [r.what, String(r.count), f(r.frameMs.median), f(r.frameMs.p95), f(r.callMs && r.callMs.median), f(r.callMs && r.callMs.p95), f(r.wallMs && r.wallMs.median), f(r.wallMs && r.wallMs.p95)];
    console.log("   " + cells.map((h, k) => (k === 0 ? h.padEnd(16) : h.padStart(9))).join(" "));
  }
  console.log("   (ms; draw = state().frameMs, the draw function; call = the whole call in the page;");
  console.log("    wall = node's round trip to the next animation frame; play: wall = interval between animation frames;");
  console.log("    settled = the draw 400 ms after a pan / zoom (the full drawing when the gesture's frame was a preview))");
  results.push({ config: c, seed, events: end.events, snapshots: end.snapshots, traceBytes, pageBytes, timings,
                 loadMs, steps: info.steps, play: { speed: play.speed, frames: play.draws.length, seconds: playSeconds },
                 table, errors });
}
await browser.close();

console.log(`\nmachine: ${(await import("node:os")).cpus().length} cores (${(await import("node:os")).cpus()[0].model}), node ${process.version}, ${browserVersion} (${chromium}, headless, --disable-gpu)`);
if (args.json) fs.writeFileSync(args.json, JSON.stringify({ browser: browserVersion, results }, null, 1));
process.exit(results.some((r) => r.errors.length) ? 1 : 0);
