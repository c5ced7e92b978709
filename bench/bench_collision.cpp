// Collision detection benchmark (plain timing program): the kinetic broad phases (bvh,
// sweep-and-prune) against a per-frame broad phase on the same positions.
//
// For each scene (boxes-linear 3-D, boxes-ballistic 3-D, tunnelling 2-D) and n in --sizes:
//  1. Kinetic: initialize, then the whole window with `colliding_pairs` asked F times per unit
//     time (F = --frames, 60 by default): events per unit time, CPU per event, CPU per query,
//     total CPU per unit time (events + F queries), heap bytes held. Each run has a CPU budget
//     (--budget); a run that spends it reports the rates of what it processed and is marked.
//  2. Per frame: at the same F frame times, evaluate every box at the frame in double and run a
//     brute-force sweep-and-prune (sort the low sides on the axis of largest spread, sweep, test
//     the other axes): CPU per frame, total per unit time. (FCL, Bullet and Box2D broad phases
//     are the next baselines; not built yet.)
//  3. Ratios against the per-frame baseline measured in the same run: total cost per unit time
//     (kinetic / per-frame), the break-even frame rate F* = (kinetic event CPU per unit time) /
//     (per-frame CPU per frame - kinetic CPU per query), and for every contact interval the
//     kinetic structure reported, whether a frame fell inside it: contacts a per-frame broad
//     phase at F frames per unit time misses (tunnelling).
// Options: --sizes=1000,10000  --frames=F (60)  --budget=SECONDS (30)  --seed=S
//          --scenes=boxes-linear,boxes-ballistic,tunnelling  --structures=bvh,sweep-and-prune
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "bench_config.hpp"
#include "kinetic/bvh/kinetic_bvh.hpp"
#include "kinetic/core/boxes.hpp"
#include "kinetic/run/timeline_driver.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/sweep_and_prune/kinetic_sweep_and_prune.hpp"

namespace {

using kinetic::bench::cpu_now;

struct Options {
  std::vector<std::size_t> sizes{1000, 10000};
  int frames = 60;
  double budget = 30.0;
  std::uint64_t seed = 1;
  std::vector<std::string> scenes{"boxes-linear", "boxes-ballistic", "tunnelling"};
  std::vector<std::string> structures{"bvh", "sweep-and-prune"};
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while (pos <= s.size()) {
    const std::size_t comma = s.find(',', pos);
    out.push_back(s.substr(pos, comma - pos));
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return out;
}

/// Contact intervals seen through the event log: per pair, begin and end times.
struct ContactLog {
  std::map<std::pair<kinetic::ObjectId, kinetic::ObjectId>, double> open;
  std::vector<std::pair<double, double>> intervals;
  static void record(void* context, kinetic::Time t, const char* kind,
                     std::span<const kinetic::ObjectId> ids) {
    auto& log = *static_cast<ContactLog*>(context);
    const std::pair key{ids[0], ids[1]};
    if (kind[8] == 'b') {  // contact_begin
      log.open[key] = t;
    } else if (const auto it = log.open.find(key); it != log.open.end()) {
      log.intervals.emplace_back(it->second, t);
      log.open.erase(it);
    }
  }
};

struct KineticResult {
  bool completed = true;
  double reached = 0.0;  ///< simulated time reached
  double init_cpu = 0.0, event_cpu = 0.0, query_cpu = 0.0;
  std::uint64_t events = 0, queries = 0, answered_pairs = 0;
  std::size_t heap = 0;
  ContactLog contacts;
};

template <class S>
KineticResult run_kinetic(const kinetic::scenario::Scenario& s, int frames, double budget) {
  KineticResult r;
  kinetic::run::TimelineDriver driver(s, kinetic::SchedulerKind::Robust, 1e-9);
  const std::size_t heap0 = kinetic::bench::heap_bytes();
  S structure(driver.motions(), driver.sim(), driver.scheduler());
  driver.sim().set_event_log(&ContactLog::record, &r.contacts);
  double c0 = cpu_now();
  structure.initialize();
  r.init_cpu = cpu_now() - c0;
  r.heap = kinetic::bench::heap_bytes() - heap0;
  const double start = s.start_time, end = *s.end_time;
  const auto n_frames = static_cast<std::size_t>(std::llround((end - start) * frames));
  std::size_t op = 0;
  for (std::size_t f = 1; f <= n_frames; ++f) {
    const double t = start + (end - start) * static_cast<double>(f) / static_cast<double>(n_frames);
    c0 = cpu_now();
    // Timeline changes (the ballistic bounces) at their times, between the frames.
    while (op < s.timeline.size() && s.timeline[op].time <= t) {
      const auto& entry = s.timeline[op++];
      if (entry.op == kinetic::scenario::OpKind::Query) continue;
      (void)driver.advance_to(entry.time, structure);
      driver.apply(entry, structure);
    }
    (void)driver.advance_to(t, structure);
    r.event_cpu += cpu_now() - c0;
    c0 = cpu_now();
    r.answered_pairs += structure.colliding_pairs(t).size();
    r.query_cpu += cpu_now() - c0;
    ++r.queries;
    r.reached = t;
    if (r.event_cpu + r.query_cpu > budget) {
      r.completed = f == n_frames;
      break;
    }
  }
  r.events = driver.sim().counters().events();
  return r;
}

/// Brute-force sweep-and-prune on positions in double at one time: the per-frame baseline.
struct PerFrame {
  int d = 0;
  std::vector<double> lo, hi;  // box * d + axis
  std::vector<std::uint32_t> order;
  std::vector<std::uint32_t> active;

  std::size_t pairs_at(const kinetic::MotionTable& boxes, double t) {
    const std::size_t n = boxes.capacity();
    lo.resize(n * static_cast<std::size_t>(d));
    hi.resize(lo.size());
    order.clear();
    for (const std::uint32_t i : boxes.alive_indices()) {
      for (int k = 0; k < d; ++k) {
        const double c = kinetic::center(boxes, i, k).evaluate(t);
        const double h = kinetic::half_extent(boxes, i, k).c[0];
        lo[i * static_cast<std::size_t>(d) + static_cast<std::size_t>(k)] = c - h;
        hi[i * static_cast<std::size_t>(d) + static_cast<std::size_t>(k)] = c + h;
      }
      order.push_back(i);
    }
    // The axis of largest spread of the low sides.
    int axis = 0;
    double best = -1.0;
    for (int k = 0; k < d; ++k) {
      double a = HUGE_VAL, b = -HUGE_VAL;
      for (const std::uint32_t i : order) {
        a = std::min(a, lo[i * static_cast<std::size_t>(d) + static_cast<std::size_t>(k)]);
        b = std::max(b, lo[i * static_cast<std::size_t>(d) + static_cast<std::size_t>(k)]);
      }
      if (b - a > best) best = b - a, axis = k;
    }
    const auto at = [&](std::uint32_t i, int k) {
      return i * static_cast<std::size_t>(d) + static_cast<std::size_t>(k);
    };
    std::sort(order.begin(), order.end(),
              [&](std::uint32_t a, std::uint32_t b) { return lo[at(a, axis)] < lo[at(b, axis)]; });
    std::size_t found = 0;
    for (std::size_t x = 0; x < order.size(); ++x) {
      const std::uint32_t a = order[x];
      for (std::size_t y = x + 1; y < order.size(); ++y) {
        const std::uint32_t b = order[y];
        if (lo[at(b, axis)] > hi[at(a, axis)]) break;
        bool overlap = true;
        for (int k = 0; k < d && overlap; ++k)
          overlap = lo[at(a, k)] <= hi[at(b, k)] && lo[at(b, k)] <= hi[at(a, k)];
        found += overlap ? 1 : 0;
      }
    }
    return found;
  }
};

struct FrameResult {
  double cpu = 0.0;
  std::uint64_t frames = 0, pairs = 0;
};

FrameResult run_per_frame(const kinetic::scenario::Scenario& s, int frames, double until) {
  FrameResult r;
  kinetic::run::TimelineDriver driver(s, kinetic::SchedulerKind::Robust, 1e-9);
  PerFrame pf;
  pf.d = s.dimension;
  struct Null {  // the table follows the timeline; nothing kinetic is maintained
    void initialize() {}
    kinetic::EventKind process(const kinetic::Event&) { return kinetic::EventKind::Internal; }
    void insert(std::uint32_t) {}
    void remove(std::uint32_t) {}
    void motion_changed(std::uint32_t) {}
    [[nodiscard]] bool initialized() const { return true; }
    [[nodiscard]] bool validate() const { return true; }
    [[nodiscard]] std::uint64_t certificates() const { return 0; }
    [[nodiscard]] std::uint64_t certificates_per_object_max() const { return 0; }
    [[nodiscard]] kinetic::NamedCounters named_counters() const { return {}; }
  } null;
  const double start = s.start_time, end = *s.end_time;
  const auto n_frames = static_cast<std::size_t>(std::llround((end - start) * frames));
  std::size_t op = 0;
  for (std::size_t f = 1; f <= n_frames; ++f) {
    const double t = start + (end - start) * static_cast<double>(f) / static_cast<double>(n_frames);
    if (t > until) break;
    while (op < s.timeline.size() && s.timeline[op].time <= t) {
      const auto& entry = s.timeline[op++];
      if (entry.op == kinetic::scenario::OpKind::Query) continue;
      (void)driver.advance_to(entry.time, null);
      driver.apply(entry, null);
    }
    const double c0 = cpu_now();
    r.pairs += pf.pairs_at(driver.motions(), t);
    r.cpu += cpu_now() - c0;
    ++r.frames;
  }
  return r;
}

double per(double a, double b) { return b > 0.0 ? a / b : 0.0; }

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&](const char* name) -> const char* {
      const std::size_t len = std::string(name).size();
      return a.compare(0, len, name) == 0 ? a.c_str() + len : nullptr;
    };
    if (const char* v = value("--sizes=")) {
      o.sizes = kinetic::bench::parse_sizes(v);
    } else if (const char* v2 = value("--frames=")) {
      o.frames = std::atoi(v2);
    } else if (const char* v3 = value("--budget=")) {
      o.budget = std::atof(v3);
    } else if (const char* v4 = value("--seed=")) {
      o.seed = std::strtoull(v4, nullptr, 10);
    } else if (const char* v5 = value("--scenes=")) {
      o.scenes = split(v5);
    } else if (const char* v6 = value("--structures=")) {
      o.structures = split(v6);
    } else {
      std::fprintf(stderr, "bench_collision: unknown option %s\n", a.c_str());
      return 2;
    }
  }
  std::printf(
      "bench_collision: %s, %s, %u hardware threads; robust scheduling (eps 1e-9); "
      "%d frames per unit time; CPU budget %.0f s per run; seed %llu\n",
      kinetic::bench::build_type(), kinetic::bench::compiler(), std::thread::hardware_concurrency(),
      o.frames, o.budget, static_cast<unsigned long long>(o.seed));
  std::printf(
      "baseline: per-frame brute-force sweep-and-prune on positions evaluated in double "
      "(FCL, Bullet, Box2D: not built yet)\n\n");
  std::printf("%-16s %7s %-16s %9s %11s %9s %9s %12s %12s %9s %10s %8s %9s %9s\n", "scene", "n",
              "structure", "reached", "events/ut", "us/event", "us/query", "kinetic s/ut",
              "frame s/ut", "ratio", "F*", "missed", "contacts", "heap MB");
  for (const std::string& scene : o.scenes) {
    for (const std::size_t n : o.sizes) {
      kinetic::scenario::GeneratorOptions g;
      g.n = n;
      g.seed = o.seed;
      const kinetic::scenario::Scenario s = kinetic::scenario::generate(scene, g);
      const double span = *s.end_time - s.start_time;
      for (const std::string& structure : o.structures) {
        const KineticResult k =
            structure == "bvh" ? run_kinetic<kinetic::KineticBvh>(s, o.frames, o.budget)
                               : run_kinetic<kinetic::KineticSweepAndPrune>(s, o.frames, o.budget);
        const double simulated = k.reached - s.start_time;
        const FrameResult f = run_per_frame(s, o.frames, k.reached);
        const double per_query = per(k.query_cpu, static_cast<double>(k.queries));
        const double per_frame = per(f.cpu, static_cast<double>(f.frames));
        const double kinetic_per_ut = per(k.event_cpu + k.query_cpu, simulated);
        const double frame_per_ut = per(f.cpu, simulated);
        const double event_per_ut = per(k.event_cpu, simulated);
        const double break_even =
            per_frame > per_query ? event_per_ut / (per_frame - per_query) : HUGE_VAL;
        std::size_t missed = 0;
        for (const auto& [b, e] : k.contacts.intervals) {
          // A frame time start + j / F lies in [b, e] unless floor(e F) < ceil(b F).
          const double fb = std::ceil((b - s.start_time) * o.frames);
          const double fe = std::floor((e - s.start_time) * o.frames);
          missed += fe < fb ? 1 : 0;
        }
        std::printf(
            "%-16s %7zu %-16s %8.2f%s %11.0f %9.2f %9.1f %12.4f %12.4f %9.3f %10.1f "
            "%8zu %9zu %9.1f\n",
            scene.c_str(), n, structure.c_str(), simulated, k.completed ? " " : "*",
            per(static_cast<double>(k.events), simulated),
            1e6 * per(k.event_cpu, static_cast<double>(k.events)), 1e6 * per_query, kinetic_per_ut,
            frame_per_ut, per(kinetic_per_ut, frame_per_ut), break_even, missed,
            k.contacts.intervals.size(), static_cast<double>(k.heap) / 1e6);
        std::fflush(stdout);
        (void)span;
      }
    }
  }
  std::printf(
      "\nreached: simulated time processed (* the CPU budget ran out first); ut: unit of "
      "simulated time; ratio: kinetic / per-frame total CPU per unit time (< 1: the "
      "kinetic structure is cheaper); F*: the frame rate above which the kinetic "
      "structure is cheaper; contacts: contact intervals that began and ended in the processed "
      "time; missed: those "
      "with no frame inside, i.e. contacts a per-frame broad "
      "phase at this frame rate never sees\n");
  return 0;
}
