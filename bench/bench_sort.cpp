// Kinetic sorting against the baselines a user would write instead (docs/performance/sort.md).
//
// Input: the `random-linear` dataset (1-D): n points uniform in [0, n], velocities uniform in
// [-1, 1], fixed seed. Two such points cross during [0, T] with probability ~ E|v_i - v_j| T / n =
// (2/3) T / n (for T << n), so the expected number of crossings -- the kinetic events -- is about
// n T / 3. The horizon T = 3 * kEventsPerObject therefore gives about kEventsPerObject * n events
// for every n, a comparable and sizeable amount of work per object.
//
// Measured, for each n:
//  1. kinetic_sort: KineticSort with the classic scheduler, initialize() at t = 0 (timed
//     separately, reported as setup) and advance_to(T) (the benchmark's time);
//  2. std_sort_step: one query step of a user who re-sorts from scratch: evaluate x0 + v t for
//     every point, std::sort the (value, id) pairs; "warm" with the same input order at every
//     step, "cold" with the input order cycling through random permutations (see below);
//  3. insertion_step: one query step of a user who keeps the points in last step's order:
//     re-evaluate in place and insertion-sort, at two step sizes (dt = 0.01 and dt = 1, the time
//     sweeping back and forth over [0, T]) to separate the per-step scan from the per-inversion
//     work.
// After the runs, a summary gives events/s, ns/event and the break-even query rates: the number
// of query steps per unit time at which the baseline costs as much over [0, T] as the kinetic
// structure (all figures from this run).
//
// Then robust vs classic kinetic sorting (issue target: robust within 1.5x of classic events per
// second), the same KineticSort code under SchedulerKind::Classic and SchedulerKind::Robust
// (EVENTTIME over CROP, eps = 1e-9, horizon = the end of the window), objects inserted with
// valid-from = the window's start, on
//  4. random-linear (the input above) and random-poly of degree 2, at the --sizes;
//  5. the paper's GRIDS and PARABOLA datasets in their own windows, at the --paper-sizes.
// The exact scheduler runs beside them (n <= 10^5; one iteration, at most two repetitions), with
// its own table "Exact vs robust" (events per second, the ratio per event, equal-time groups,
// exact comparisons; docs/scheduling.md). The schedulers run back to back on the same input;
// the time is advance_to(end) as in 1. Per
// run, counted over advance_to(end) alone (initialize() is timed and counted apart): events, CROP
// calls (root_isolation_calls, fast path), exact (GMP) fallbacks, events in the past; and an
// exact audit of the final order at the end of the window (untimed).
//
// Options (besides the --benchmark_* ones): --sizes=1000,10000 (default 1e3,1e4,1e5,1e6),
// --paper-sizes=900,10000 (the default), --seed=S (default 1), --quick (sizes 1e3,1e4,1e5,
// paper size 900, fewer repetitions), --full (the comparison at n >= 10^6 over the whole
// windows instead of shorter ones: several minutes more).

#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <random>
#include <span>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "harness.hpp"
#include "kinetic/core/counters.hpp"
#include "kinetic/core/crop.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/scheduler.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/sort/kinetic_sort.hpp"

using kinetic::bench::out;

namespace {

using Clock = std::chrono::steady_clock;

constexpr double kEventsPerObject = 10.0;
constexpr double kHorizon = 3.0 * kEventsPerObject;  // expected events ~ n T / 3 = 10 n
constexpr double kFineStep = 0.01;
constexpr double kCoarseStep = 1.0;

std::uint64_t g_seed = 1;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

/// CPU time of this thread: compared with the wall time, it shows whether another process took
/// the core during a measurement (the figures are wall times).
double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// ------------------------------------------------------------------------------------------------
// Data: positions and velocities of the random-linear dataset, generated once per n.

struct Dataset {
  std::vector<kinetic::scenario::ObjectId> id;
  std::vector<double> x0;
  std::vector<double> v;
};

const Dataset& dataset(std::size_t n) {
  static std::map<std::size_t, std::unique_ptr<Dataset>> cache;
  auto& slot = cache[n];
  if (!slot) {
    kinetic::scenario::GeneratorOptions options;
    options.n = n;
    options.seed = g_seed;
    options.dimension = 1;
    const kinetic::scenario::Scenario s = kinetic::scenario::generate("random-linear", options);
    auto d = std::make_unique<Dataset>();
    d->id.reserve(n);
    d->x0.reserve(n);
    d->v.reserve(n);
    for (const auto& object : s.objects) {
      const auto& c = object.motion.coordinates.at(0);
      if (object.motion.origin != 0.0 || c.empty() || c.size() > 2) {
        std::fprintf(stderr, "bench_sort: random-linear object %lld is not x0 + v t\n",
                     static_cast<long long>(object.id));
        std::exit(1);
      }
      d->id.push_back(object.id);
      d->x0.push_back(c[0]);
      d->v.push_back(c.size() > 1 ? c[1] : 0.0);
    }
    slot = std::move(d);
  }
  return *slot;
}

// ------------------------------------------------------------------------------------------------
// 1. Kinetic sorting over [0, T].

void BM_kinetic_sort(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const Dataset& d = dataset(n);
  double setup = 0.0, advance_cpu = 0.0;
  double events = 0.0, swaps = 0.0, in_past = 0.0, exact = 0.0, filtered = 0.0;
  double audit_failures = 0.0;
  for (auto _ : state) {
    kinetic::MotionTable motions(1);
    for (std::size_t i = 0; i < n; ++i) {
      const std::array coordinates{
          kinetic::MotionPolynomial::from(std::array{d.x0[i], d.v[i]}, 0.0)};
      motions.insert(d.id[i], coordinates);
    }
    kinetic::Simulator sim(0.0);
    const kinetic::Scheduler scheduler(kinetic::SchedulerKind::Classic);
    kinetic::KineticSort sort(motions, sim, scheduler, 0);

    const auto t0 = Clock::now();
    sort.initialize();
    const auto t1 = Clock::now();
    const double cpu1 = thread_cpu_seconds();
    const kinetic::AdvanceOutcome outcome = sim.advance_to(kHorizon, sort);
    const double cpu2 = thread_cpu_seconds();
    const auto t2 = Clock::now();
    benchmark::DoNotOptimize(sort.order().data());
    state.SetIterationTime(seconds(t2 - t1));

    if (outcome != kinetic::AdvanceOutcome::Reached) {
      state.SkipWithError("advance_to did not reach the horizon");
      break;
    }
    setup += seconds(t1 - t0);
    advance_cpu += cpu2 - cpu1;
    const kinetic::Counters& c = sim.counters();
    events += static_cast<double>(c.events());
    swaps += static_cast<double>(sort.counters().swaps);
    in_past += static_cast<double>(c.events_in_past);
    exact += static_cast<double>(c.predicates.exact);
    filtered += static_cast<double>(c.predicates.filtered);
    if (!sort.audit(kHorizon).ok) audit_failures += 1.0;  // untimed correctness check
  }
  using benchmark::Counter;
  state.counters["n"] = static_cast<double>(n);
  state.counters["events"] = Counter(events, Counter::kAvgIterations);
  state.counters["setup_s"] = Counter(setup, Counter::kAvgIterations);
  state.counters["advance_cpu_s"] = Counter(advance_cpu, Counter::kAvgIterations);
  state.counters["swaps"] = Counter(swaps, Counter::kAvgIterations);
  state.counters["events_in_past"] = Counter(in_past, Counter::kAvgIterations);
  state.counters["exact_predicates"] = Counter(exact, Counter::kAvgIterations);
  state.counters["filtered_predicates"] = Counter(filtered, Counter::kAvgIterations);
  state.counters["audit_failures"] = Counter(audit_failures);
}

// ------------------------------------------------------------------------------------------------
// 2. Re-sorting from scratch at each query step: evaluate in id order, sort (value, id) pairs.
//    Warm (range(1) == 0): the input order is the same at every step, so the comparisons of one
//    step repeat those of the last (the order changes only at crossings) and, for small n, the
//    branch predictor learns them. Cold (range(1) == 1): the input order cycles through 8 random
//    permutations (pre-permuted copies, so no extra gather), as when other work runs between
//    steps. The break-even uses the warm figure: the cheaper baseline.

struct Permuted {
  std::vector<double> x0, v;
};

void BM_std_sort_step(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const bool cold = state.range(1) != 0;
  const Dataset& d = dataset(n);
  std::vector<Permuted> inputs(cold ? 8 : 1);
  std::vector<std::uint32_t> permutation(n);
  std::mt19937_64 rng(g_seed);
  for (std::size_t p = 0; p < inputs.size(); ++p) {
    for (std::size_t i = 0; i < n; ++i) permutation[i] = static_cast<std::uint32_t>(i);
    if (cold) std::shuffle(permutation.begin(), permutation.end(), rng);
    inputs[p].x0.resize(n);
    inputs[p].v.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      inputs[p].x0[i] = d.x0[permutation[i]];
      inputs[p].v[i] = d.v[permutation[i]];
    }
  }
  std::vector<std::pair<double, std::uint32_t>> values(n);
  double t = 0.0;
  std::size_t p = 0;
  for (auto _ : state) {
    const Permuted& in = inputs[p];
    for (std::size_t i = 0; i < n; ++i)
      values[i] = {in.x0[i] + in.v[i] * t, static_cast<std::uint32_t>(i)};
    std::sort(values.begin(), values.end());
    benchmark::DoNotOptimize(values.data());
    benchmark::ClobberMemory();
    t += kFineStep;
    if (t > kHorizon) t = 0.0;
    if (++p == inputs.size()) p = 0;
  }
  state.counters["n"] = static_cast<double>(n);
  state.counters["cold"] = cold ? 1.0 : 0.0;
}

// ------------------------------------------------------------------------------------------------
// 3. Insertion sort from the last step's order. The points themselves are kept in that order
//    (an array of records, scanned sequentially): the fastest way a user would write it.

struct Record {
  double key;
  double x0;
  double v;
  std::uint32_t id;
};

bool less(const Record& a, const Record& b) {
  return a.key < b.key || (a.key == b.key && a.id < b.id);
}

void BM_insertion_step(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const double dt = state.range(1) == 0 ? kFineStep : kCoarseStep;
  const Dataset& d = dataset(n);
  std::vector<Record> records(n);
  for (std::size_t i = 0; i < n; ++i)
    records[i] = {d.x0[i], d.x0[i], d.v[i], static_cast<std::uint32_t>(i)};
  std::sort(records.begin(), records.end(), less);  // the order at t = 0
  double t = 0.0;
  double direction = 1.0;
  std::uint64_t shifts = 0;
  for (auto _ : state) {
    // Sweep [0, T] back and forth so that every step sees the crossings of a window of length dt.
    double next = t + direction * dt;
    if (next > kHorizon || next < 0.0) {
      direction = -direction;
      next = t + direction * dt;
    }
    t = next;
    for (Record& r : records) r.key = r.x0 + r.v * t;
    for (std::size_t i = 1; i < n; ++i) {
      const Record r = records[i];
      std::size_t j = i;
      while (j > 0 && less(r, records[j - 1])) {
        records[j] = records[j - 1];
        --j;
      }
      records[j] = r;
      shifts += i - j;
    }
    benchmark::DoNotOptimize(records.data());
    benchmark::ClobberMemory();
  }
  state.counters["n"] = static_cast<double>(n);
  state.counters["dt"] = dt;
  state.counters["shifts_per_step"] =
      benchmark::Counter(static_cast<double>(shifts), benchmark::Counter::kAvgIterations);
}

// ------------------------------------------------------------------------------------------------
// 4-5. Robust vs classic kinetic sorting. One benchmark per (input, n, scheduler); each call of
//      the function (one repetition) appends its figures to g_compare for the comparison table.

constexpr double kEps = 1e-9;
// random-poly, degree 2: c0 uniform in [0, n], c1 uniform in [-1, 1], c2 uniform in
// [-1/2, 1/2]. Over [0, T] the number of crossings grows about as T^2 (measured, seed 1:
// 4.5 n at T = 5, 17 n at T = 10); T = 7.5 gives about 10 n, as the linear input's T = 30.
constexpr double kQuadraticHorizon = 7.5;
// At n >= kShortFrom the comparison runs over a shorter window, about n events instead of 10 n,
// unless --full: robust sorting of 10^6 points over the whole window takes a minute per input
// (measured: 61 s linear, 60 s quadratic, against 13 s and 14 s classic). Linear: [0, T / 10];
// quadratic: [0, 2.5] (crossings grow as T^2 there: measured 1.4 n).
constexpr std::size_t kShortFrom = 1000000;
constexpr double kLinearShortHorizon = kHorizon / 10.0;
constexpr double kQuadraticShortHorizon = 2.5;

bool g_full = false;
bool g_quick = false;

enum class Input : int { Linear = 0, Quadratic = 1, Grids = 2, Parabola = 3 };

const char* input_tag(Input input) {
  switch (input) {
    case Input::Linear:
      return "linear";
    case Input::Quadratic:
      return "quadratic";
    case Input::Grids:
      return "grids";
    case Input::Parabola:
      return "parabola";
  }
  return "?";
}

const char* input_dataset(Input input) {
  switch (input) {
    case Input::Linear:
      return "random-linear";
    case Input::Quadratic:
      return "random-poly, degree 2";
    case Input::Grids:
      return "grids";
    case Input::Parabola:
      return "parabola";
  }
  return "?";
}

/// The end of the compared window for the random inputs (they start at 0).
double compare_horizon(Input input, std::size_t n) {
  if (n >= kShortFrom && !g_full)
    return input == Input::Linear ? kLinearShortHorizon : kQuadraticShortHorizon;
  return input == Input::Linear ? kHorizon : kQuadraticHorizon;
}

struct Workload {
  kinetic::Time start = 0.0;
  kinetic::Time end = 0.0;
  int degree = 0;
  std::vector<kinetic::ObjectId> id;
  std::vector<kinetic::MotionPolynomial> motion;  // axis 0
};

const Workload& workload(Input input, std::size_t n) {
  static std::map<std::pair<int, std::size_t>, std::unique_ptr<Workload>> cache;
  auto& slot = cache[{static_cast<int>(input), n}];
  if (slot) return *slot;
  auto w = std::make_unique<Workload>();
  w->id.reserve(n);
  w->motion.reserve(n);
  if (input == Input::Linear) {
    const Dataset& d = dataset(n);  // exactly the input of 1-3
    for (std::size_t i = 0; i < n; ++i) {
      w->id.push_back(d.id[i]);
      w->motion.push_back(kinetic::MotionPolynomial::from(std::array{d.x0[i], d.v[i]}, 0.0));
    }
    w->start = 0.0;
    w->end = compare_horizon(input, n);
  } else {
    kinetic::scenario::GeneratorOptions options;
    options.n = n;
    options.seed = g_seed;
    options.dimension = 1;
    options.degree = 2;
    if (input == Input::Quadratic) {
      options.start_time = 0.0;
      options.end_time = compare_horizon(input, n);
    }
    const char* name = input == Input::Quadratic ? "random-poly"
                       : input == Input::Grids   ? "grids"
                                                 : "parabola";
    const kinetic::scenario::Scenario s = kinetic::scenario::generate(name, options);
    for (const auto& object : s.objects) {
      w->id.push_back(object.id);
      w->motion.push_back(
          kinetic::MotionPolynomial::from(object.motion.coordinates.at(0), object.motion.origin));
    }
    w->start = s.start_time;
    w->end = s.end_time.value_or(s.start_time);
  }
  for (const kinetic::MotionPolynomial& p : w->motion) w->degree = std::max(w->degree, p.degree);
  if (!kinetic::crop_precision_supported(kEps, w->start, w->end)) {
    std::fprintf(stderr, "bench_sort: eps %g is not supported on [%g, %g]\n", kEps, w->start,
                 w->end);
    std::exit(1);
  }
  slot = std::move(w);
  return *slot;
}

/// The figures of one repetition (averages over its iterations; the counts are the same in
/// every iteration).
struct CompareRecord {
  double advance_s = 0.0;  // advance_to(end), wall
  double advance_cpu_s = 0.0;
  double setup_s = 0.0;  // initialize()
  double events = 0.0;
  double root_calls = 0.0;  // failure-time computations (CROP calls when robust)
  double crop_calls = 0.0;
  double crop_fast = 0.0;
  double crop_boxes = 0.0;
  double crop_exact_boxes = 0.0;
  double crop_filtered = 0.0;    // CROP's exact sign decisions taken by the filter
  double crop_exact = 0.0;       // ... and by GMP
  double structure_exact = 0.0;  // the structure's own predicates that needed GMP
  double exact_fallbacks = 0.0;  // Counters::exact_fallbacks()
  double in_past = 0.0;
  double equal_time_groups = 0.0;  // exact: groups of events at one exact time
  double exact_comparisons = 0.0;  // exact: event times compared exactly (brackets overlapped)
  double audits = 0.0;             // runs whose final order was audited (one per iteration)
  double audit_failures = 0.0;     // ... and failed the exact audit
  std::string stopped;             // non-empty when the loop guard stopped the run
};

std::map<std::tuple<int, std::size_t, int>, std::vector<CompareRecord>> g_compare;

void BM_compare(benchmark::State& state, Input input, kinetic::SchedulerKind kind) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const Workload& w = workload(input, n);
  // The guard of the runner (src/run): at one instant each pair swaps at most once; over the
  // run two degree-s motions cross at most s times.
  const auto pairs = static_cast<std::uint64_t>(n) * (n - 1) / 2;
  kinetic::LoopGuard guard;
  guard.max_events_per_instant = pairs + 16;
  guard.max_events_total =
      static_cast<std::uint64_t>(std::max(1, w.degree)) * (pairs + std::uint64_t{n} * n) + 16;

  CompareRecord r;
  std::uint64_t iterations = 0;
  for (auto _ : state) {
    kinetic::MotionTable motions(1);
    for (std::size_t i = 0; i < n; ++i)
      motions.insert(w.id[i], std::span(&w.motion[i], 1), w.start);
    kinetic::Simulator sim(w.start);
    sim.set_guard(guard);
    const kinetic::Scheduler scheduler(kind, kEps, w.end);
    kinetic::KineticSort sort(motions, sim, scheduler, 0);

    const auto t0 = Clock::now();
    sort.initialize();
    const kinetic::Counters before = sim.counters();  // the counts of initialize()
    const auto t1 = Clock::now();
    const double cpu1 = thread_cpu_seconds();
    const kinetic::AdvanceOutcome outcome = sim.advance_to(w.end, sort);
    const double cpu2 = thread_cpu_seconds();
    const auto t2 = Clock::now();
    benchmark::DoNotOptimize(sort.order().data());
    state.SetIterationTime(seconds(t2 - t1));
    ++iterations;

    r.setup_s += seconds(t1 - t0);
    r.advance_s += seconds(t2 - t1);
    r.advance_cpu_s += cpu2 - cpu1;
    // Counts of the timed part, advance_to(end): initialize()'s n - 1 failure-time computations
    // are left out.
    const kinetic::Counters& c = sim.counters();
    const auto delta = [](std::uint64_t after, std::uint64_t at_start) {
      return static_cast<double>(after - at_start);
    };
    r.events += delta(c.events(), before.events());
    r.root_calls += delta(c.root_isolation_calls, before.root_isolation_calls);
    r.crop_calls += delta(c.crop.calls, before.crop.calls);
    r.crop_fast += delta(c.crop.fast_path, before.crop.fast_path);
    r.crop_boxes += delta(c.crop.bernstein_boxes, before.crop.bernstein_boxes);
    r.crop_exact_boxes += delta(c.crop.exact_boxes, before.crop.exact_boxes);
    r.crop_filtered += delta(c.crop.predicates.filtered, before.crop.predicates.filtered);
    r.crop_exact += delta(c.crop.predicates.exact, before.crop.predicates.exact);
    r.structure_exact += delta(c.predicates.exact, before.predicates.exact);
    r.exact_fallbacks += delta(c.exact_fallbacks(), before.exact_fallbacks());
    r.in_past += delta(c.events_in_past, before.events_in_past);
    r.equal_time_groups += delta(c.equal_time_groups, before.equal_time_groups);
    r.exact_comparisons += delta(c.exact_comparisons, before.exact_comparisons);
    if (outcome != kinetic::AdvanceOutcome::Reached) {
      const kinetic::GuardReport& g = sim.guard_report();
      char text[160];
      std::snprintf(text, sizeof text, "%s at t = %.17g after %llu events",
                    outcome == kinetic::AdvanceOutcome::LoopGuard ? "loop guard" : "event guard",
                    g.time, static_cast<unsigned long long>(g.events_total));
      r.stopped = text;
      state.SkipWithError(text);
      break;
    }
    r.audits += 1.0;
    if (!sort.audit(w.end).ok) r.audit_failures += 1.0;  // untimed, exact
  }
  if (iterations == 0) return;
  const double k = static_cast<double>(iterations);
  for (double* field : {&r.advance_s, &r.advance_cpu_s, &r.setup_s, &r.events, &r.root_calls,
                        &r.crop_calls, &r.crop_fast, &r.crop_boxes, &r.crop_exact_boxes,
                        &r.crop_filtered, &r.crop_exact, &r.structure_exact, &r.exact_fallbacks,
                        &r.in_past, &r.equal_time_groups, &r.exact_comparisons})
    *field /= k;
  state.counters["n"] = static_cast<double>(n);
  state.counters["end"] = w.end;
  state.counters["events"] = r.events;
  state.counters["crop_calls"] = r.crop_calls;
  state.counters["exact_fallbacks"] = r.exact_fallbacks;
  state.counters["events_in_past"] = r.in_past;
  state.counters["audit_failures"] = r.audit_failures;
  g_compare[{static_cast<int>(input), n, static_cast<int>(kind)}].push_back(std::move(r));
}

// ------------------------------------------------------------------------------------------------
// Collecting the figures of this run for the summary.

struct Sample {
  double time_s = 0.0;  // per iteration (manual time for kinetic_sort)
  double cpu_s = 0.0;   // per iteration, process CPU time (whole iteration)
  benchmark::UserCounters counters;
};

class Collector : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.run_type != Run::RT_Iteration || run.error_occurred || run.iterations == 0) continue;
      const auto n_it = run.counters.find("n");
      if (n_it == run.counters.end()) continue;
      std::string name = run.run_name.function_name;
      const auto dt_it = run.counters.find("dt");
      if (dt_it != run.counters.end())
        name += dt_it->second.value == kFineStep ? "_fine" : "_coarse";
      const auto cold_it = run.counters.find("cold");
      if (cold_it != run.counters.end() && cold_it->second.value != 0.0) name += "_cold";
      samples_[{name, static_cast<std::size_t>(n_it->second.value)}].push_back(
          Sample{run.real_accumulated_time / static_cast<double>(run.iterations),
                 run.cpu_accumulated_time / static_cast<double>(run.iterations), run.counters});
    }
    ConsoleReporter::ReportRuns(runs);
  }

  [[nodiscard]] const std::vector<Sample>* find(const std::string& name, std::size_t n) const {
    const auto it = samples_.find({name, n});
    return it == samples_.end() ? nullptr : &it->second;
  }

 private:
  std::map<std::pair<std::string, std::size_t>, std::vector<Sample>> samples_;
};

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t m = values.size() / 2;
  return values.size() % 2 == 1 ? values[m] : 0.5 * (values[m - 1] + values[m]);
}

double median_time(const std::vector<Sample>& samples) {
  std::vector<double> v;
  for (const Sample& s : samples) v.push_back(s.time_s);
  return median(v);
}

double median_counter(const std::vector<Sample>& samples, const char* name) {
  std::vector<double> v;
  for (const Sample& s : samples) {
    const auto it = s.counters.find(name);
    if (it != s.counters.end()) v.push_back(it->second.value);
  }
  return v.empty() ? 0.0 : median(v);
}

std::string format_time(double s) {
  char buffer[64];
  if (s >= 1.0) {
    std::snprintf(buffer, sizeof buffer, "%.2f s", s);
  } else if (s >= 1e-3) {
    std::snprintf(buffer, sizeof buffer, "%.2f ms", s * 1e3);
  } else {
    std::snprintf(buffer, sizeof buffer, "%.1f us", s * 1e6);
  }
  return buffer;
}

double median_cpu(const std::vector<Sample>& samples) {
  std::vector<double> v;
  for (const Sample& s : samples) v.push_back(s.cpu_s);
  return median(v);
}

void print_summary(const Collector& collector, const std::vector<std::size_t>& sizes) {
  out("\n== Summary (medians over repetitions; T = %g; all figures from this run) ==\n\n",
      kHorizon);
  out("| n | events | setup (initialize) | kinetic over [0, T] | events/s | ns/event | std::sort "
      "per step, warm (cold) | insertion sort per step (dt = %g) | break-even vs std::sort "
      "(steps per unit time) | break-even vs insertion sort (steps per unit time) |\n",
      kFineStep);
  out("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::vector<std::string> details;
  for (const std::size_t n : sizes) {
    const auto* kin = collector.find("BM_kinetic_sort", n);
    const auto* warm = collector.find("BM_std_sort_step", n);
    const auto* cold = collector.find("BM_std_sort_step_cold", n);
    const auto* fine = collector.find("BM_insertion_step_fine", n);
    const auto* coarse = collector.find("BM_insertion_step_coarse", n);
    if (kin == nullptr || warm == nullptr || cold == nullptr || fine == nullptr ||
        coarse == nullptr) {
      out("| %zu | (not run) | | | | | | | | |\n", n);
      continue;
    }
    const double kinetic = median_time(*kin);
    const double kinetic_cpu = median_counter(*kin, "advance_cpu_s");
    const double events = median_counter(*kin, "events");
    const double setup = median_counter(*kin, "setup_s");
    const double per_sort = median_time(*warm);
    const double per_sort_cold = median_time(*cold);
    const double c_fine = median_time(*fine);
    const double c_coarse = median_time(*coarse);
    // Insertion sort per step as a function of the step: c(dt) = a + b dt (a: evaluating and
    // scanning n records; b dt: the ~ n dt / 3 inversions of a window dt). Over [0, T] at k
    // steps per unit time it costs T k a + T b; it equals the kinetic cost K at
    // k = (K - T b) / (T a).
    const double b = std::max(0.0, (c_coarse - c_fine) / (kCoarseStep - kFineStep));
    const double a = c_fine - b * kFineStep;
    const double break_sort = kinetic / (per_sort * kHorizon);
    const double break_ins = (kinetic - kHorizon * b) / (kHorizon * a);
    char ins_text[64];
    if (break_ins > 0.0) {
      std::snprintf(ins_text, sizeof ins_text, "%.3g", break_ins);
    } else {
      std::snprintf(ins_text, sizeof ins_text, "none (kinetic cheaper)");
    }
    out("| %zu | %.0f | %s | %s | %.3g | %.0f | %s (%s) | %s | %.3g | %s |\n", n, events,
        format_time(setup).c_str(), format_time(kinetic).c_str(), events / kinetic,
        kinetic / events * 1e9, format_time(per_sort).c_str(), format_time(per_sort_cold).c_str(),
        format_time(c_fine).c_str(), break_sort, ins_text);

    char line[1024];
    std::snprintf(
        line, sizeof line,
        "  n = %zu:\n"
        "    std::sort re-sorts costing as much as the kinetic run over [0, T]: %.0f warm, %.0f "
        "cold"
        " (break-even %.3g steps per unit time against cold);\n"
        "    insertion sort c(dt) = %s + %s * dt (shifts per step: %.0f at dt = %g, %.0f at dt = "
        "%g);\n"
        "    kinetic: swaps %.0f, events in the past %.0f, predicates filtered %.0f / exact %.0f,"
        " audit failures at T %.0f;\n"
        "    wall / CPU time (1.00 = the core was ours): kinetic %.2f, std::sort %.2f / %.2f,"
        " insertion %.2f / %.2f\n",
        n, kinetic / per_sort, kinetic / per_sort_cold, kinetic / (per_sort_cold * kHorizon),
        format_time(a).c_str(), format_time(b).c_str(), median_counter(*fine, "shifts_per_step"),
        kFineStep, median_counter(*coarse, "shifts_per_step"), kCoarseStep,
        median_counter(*kin, "swaps"), median_counter(*kin, "events_in_past"),
        median_counter(*kin, "filtered_predicates"), median_counter(*kin, "exact_predicates"),
        median_counter(*kin, "audit_failures"), kinetic / kinetic_cpu, per_sort / median_cpu(*warm),
        per_sort_cold / median_cpu(*cold), c_fine / median_cpu(*fine),
        c_coarse / median_cpu(*coarse));
    details.emplace_back(line);
  }
  out("\nDetails:\n");
  for (const std::string& d : details) out("%s", d.c_str());
}

// ------------------------------------------------------------------------------------------------
// Robust vs classic: the comparison table.

std::string format_count(double v) {
  // 12345678 -> "12,345,678"
  char digits[32];
  std::snprintf(digits, sizeof digits, "%.0f", v);
  std::string s = digits, out;
  const std::size_t lead = s.size() % 3 == 0 ? 3 : s.size() % 3;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (i >= lead && (i - lead) % 3 == 0 && i > 0) out += ',';
    out += s[i];
  }
  return out;
}

std::string format_rate(double events_per_s) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f M", events_per_s * 1e-6);
  return buffer;
}

double median_field(const std::vector<CompareRecord>& records, double CompareRecord::*field) {
  std::vector<double> v;
  for (const CompareRecord& r : records) v.push_back(r.*field);
  return median(v);
}

void print_compare(const std::vector<std::pair<Input, std::size_t>>& rows) {
  out("\n== Robust vs classic kinetic sorting (eps = %g; medians over repetitions; all figures "
      "from this run) ==\n\n",
      kEps);
  out("| input | n | window | events classic / robust | classic events/s | robust events/s | "
      "robust/classic time | CROP calls (per event) | CROP fast path | exact fallbacks (per "
      "event) | events in the past | audit at end (robust) |\n");
  out("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
  std::vector<std::string> details;
  for (const auto& [input, n] : rows) {
    const auto c_it = g_compare.find(
        {static_cast<int>(input), n, static_cast<int>(kinetic::SchedulerKind::Classic)});
    const auto r_it = g_compare.find(
        {static_cast<int>(input), n, static_cast<int>(kinetic::SchedulerKind::Robust)});
    const Workload& w = workload(input, n);
    char window[64];
    std::snprintf(window, sizeof window, "[%g, %g]", w.start, w.end);
    if (c_it == g_compare.end() || r_it == g_compare.end()) {
      out("| %s | %zu | %s | (not run) | | | | | | | | |\n", input_tag(input), n, window);
      continue;
    }
    const std::vector<CompareRecord>& cls = c_it->second;
    const std::vector<CompareRecord>& rob = r_it->second;
    if (!cls.back().stopped.empty() || !rob.back().stopped.empty()) {
      out("| %s | %zu | %s | stopped: classic %s, robust %s | | | | | | | | |\n", input_tag(input),
          n, window, cls.back().stopped.empty() ? "reached the end" : cls.back().stopped.c_str(),
          rob.back().stopped.empty() ? "reached the end" : rob.back().stopped.c_str());
      continue;
    }
    const CompareRecord& c0 = cls.back();  // counts: identical in every repetition
    const CompareRecord& r0 = rob.back();
    const double tc = median_field(cls, &CompareRecord::advance_s);
    const double tr = median_field(rob, &CompareRecord::advance_s);
    // Audits of every run (all iterations of all repetitions): "ok (passed/audited)".
    const auto audit_text = [](const std::vector<CompareRecord>& records) {
      double audits = 0.0, failures = 0.0;
      for (const CompareRecord& r : records) {
        audits += r.audits;
        failures += r.audit_failures;
      }
      char text[64];
      std::snprintf(text, sizeof text, "%s (%.0f/%.0f)", failures == 0.0 ? "ok" : "FAILED",
                    audits - failures, audits);
      return std::string(text);
    };
    out("| %s | %zu | %s | %s / %s | %s | %s | %.2f | %s (%.2f) | %.1f %% | %s (%.3f) | %s | %s "
        "|\n",
        input_tag(input), n, window, format_count(c0.events).c_str(),
        format_count(r0.events).c_str(), format_rate(c0.events / tc).c_str(),
        format_rate(r0.events / tr).c_str(), tr / tc, format_count(r0.crop_calls).c_str(),
        r0.crop_calls / r0.events, 100.0 * r0.crop_fast / std::max(1.0, r0.crop_calls),
        format_count(r0.exact_fallbacks).c_str(), r0.exact_fallbacks / r0.events,
        format_count(r0.in_past).c_str(), audit_text(rob).c_str());

    char line[1024];
    std::snprintf(
        line, sizeof line,
        "  %s, n = %zu (%s, window [%g, %g]; %zu / %zu repetitions):\n"
        "    time over the window: classic %s, robust %s; initialize(): classic %s, robust %s;\n"
        "    ns/event: classic %.0f, robust %.0f; robust - classic per event: %.0f ns;\n"
        "    CROP: %s calls, %s on the fast path, %s Bernstein boxes (%s needing GMP), exact signs"
        " %s filtered / %s GMP;\n"
        "    GMP fallbacks: structure %s (classic %s), CROP %s; per event: robust %.3f, classic "
        "%.3f;\n"
        "    audits at the end: robust %s, classic %s; wall / CPU time (1.00 = the core was "
        "ours): classic %.2f, robust %.2f\n",
        input_tag(input), n, input_dataset(input), w.start, w.end, cls.size(), rob.size(),
        format_time(tc).c_str(), format_time(tr).c_str(),
        format_time(median_field(cls, &CompareRecord::setup_s)).c_str(),
        format_time(median_field(rob, &CompareRecord::setup_s)).c_str(), tc / c0.events * 1e9,
        tr / r0.events * 1e9, (tr / r0.events - tc / c0.events) * 1e9,
        format_count(r0.crop_calls).c_str(), format_count(r0.crop_fast).c_str(),
        format_count(r0.crop_boxes).c_str(), format_count(r0.crop_exact_boxes).c_str(),
        format_count(r0.crop_filtered).c_str(), format_count(r0.crop_exact).c_str(),
        format_count(r0.structure_exact).c_str(), format_count(c0.structure_exact).c_str(),
        format_count(r0.crop_exact + r0.crop_exact_boxes).c_str(), r0.exact_fallbacks / r0.events,
        c0.exact_fallbacks / c0.events, audit_text(rob).c_str(), audit_text(cls).c_str(),
        tc / median_field(cls, &CompareRecord::advance_cpu_s),
        tr / median_field(rob, &CompareRecord::advance_cpu_s));
    details.emplace_back(line);
  }
  out("\nDetails:\n");
  for (const std::string& d : details) out("%s", d.c_str());
  // The exact scheduler beside the robust one (same inputs, same run).
  out("\n== Exact vs robust kinetic sorting (medians over repetitions; all figures from this run; "
      "goals: exact / robust per event <= 2 on random input at n = 10^5, <= 5 on GRIDS and "
      "PARABOLA at n = 900) ==\n\n");
  out("| input | n | events exact / robust | exact events/s | robust events/s | exact/robust "
      "time per event | equal-time groups | exact comparisons | events in the past | audit at "
      "end (exact) |\n");
  out("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
  for (const auto& [input, n] : rows) {
    const auto e_it = g_compare.find(
        {static_cast<int>(input), n, static_cast<int>(kinetic::SchedulerKind::Exact)});
    const auto r_it = g_compare.find(
        {static_cast<int>(input), n, static_cast<int>(kinetic::SchedulerKind::Robust)});
    if (e_it == g_compare.end() || r_it == g_compare.end() || !e_it->second.back().stopped.empty())
      continue;
    const CompareRecord& e0 = e_it->second.back();
    const CompareRecord& r0 = r_it->second.back();
    const double te = median_field(e_it->second, &CompareRecord::advance_s);
    const double tr = median_field(r_it->second, &CompareRecord::advance_s);
    double audits = 0.0, failures = 0.0;
    for (const CompareRecord& r : e_it->second) {
      audits += r.audits;
      failures += r.audit_failures;
    }
    out("| %s | %zu | %s / %s | %s | %s | %.2f | %s | %s | %s | %s (%.0f/%.0f) |\n",
        input_tag(input), n, format_count(e0.events).c_str(), format_count(r0.events).c_str(),
        format_rate(e0.events / te).c_str(), format_rate(r0.events / tr).c_str(),
        (te / e0.events) / (tr / r0.events), format_count(e0.equal_time_groups).c_str(),
        format_count(e0.exact_comparisons).c_str(), format_count(e0.in_past).c_str(),
        failures == 0.0 ? "ok" : "FAILED", audits - failures, audits);
  }
}

// ------------------------------------------------------------------------------------------------

std::vector<std::size_t> parse_sizes(const std::string& text, const char* flag) {
  std::vector<std::size_t> sizes;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);  // accepts 1e5
    if (item.empty() || *end != '\0' || value < 2.0 || value > 1e8) {
      std::fprintf(stderr, "bench_sort: bad %s item '%s'\n", flag, item.c_str());
      std::exit(2);
    }
    sizes.push_back(static_cast<std::size_t>(value));
    start = comma + 1;
  }
  return sizes;
}

using kinetic::bench::build_type;
using kinetic::bench::compiler;

}  // namespace

int main(int argc, char** argv) {
  // Google Benchmark takes its --benchmark_* flags first (its own --help is not shown: the
  // harness's is).
  bool help = false;
  for (int i = 1; i < argc; ++i) help = help || std::string(argv[i]) == "--help";
  if (!help) benchmark::Initialize(&argc, argv);
  std::vector<std::size_t> sizes{1000, 10000, 100000, 1000000};
  std::vector<std::size_t> paper_sizes{900, 10000};
  std::string paper_text = "900,10000";
  kinetic::bench::Harness harness("bench_sort",
                                  "kinetic sorting against re-sorting (random-linear, 1-D), robust "
                                  "against classic, and the paper's grids and parabola (Google "
                                  "Benchmark's --benchmark_* flags are taken too)");
  harness.sizes(sizes);
  harness.option("--paper-sizes", paper_text, "n of the grids and parabola runs, comma-separated");
  harness.seed(g_seed);
  harness.quick(g_quick, "sizes 10^3 to 10^5, paper size 900, fewer repetitions");
  harness.flag("--full", g_full, "the whole windows at large n");
  harness.parse(argc, argv);
  paper_sizes = parse_sizes(paper_text, "--paper-sizes");
  for (const std::size_t n : sizes) {
    if (n < 2 || n > 100000000) {
      std::fprintf(stderr, "bench_sort: --sizes: %zu is not in [2, 1e8]\n", n);
      return 2;
    }
  }
  if (g_quick && !harness.given("--sizes")) sizes = {1000, 10000, 100000};
  if (g_quick && !harness.given("--paper-sizes")) paper_sizes = {900};
  paper_text.clear();
  for (const std::size_t n : paper_sizes)
    paper_text += (paper_text.empty() ? "" : ",") + std::to_string(n);
  harness.configured();

  // Repetitions: fewer at large n (and with --quick) to keep the whole run within a few minutes.
  const auto baseline_repetitions = [](std::size_t n) {
    return g_quick ? 3 : n >= 1000000 ? 3 : 5;
  };
  const auto compare_repetitions = [](std::size_t n) {
    if (g_quick) return n >= 100000 ? 1 : 3;
    return n >= 1000000 ? 1 : n >= 100000 ? 3 : 5;
  };
  const auto paper_repetitions = [](std::size_t n) {
    if (g_quick) return n >= 10000 ? 1 : 3;
    return n >= 10000 ? 1 : 5;
  };

  out("  n values:        ");
  for (const std::size_t n : sizes) out("%zu ", n);
  out("\n  dataset:         random-linear, x0 uniform in [0, n], v uniform in [-1, 1], seed %llu\n",
      static_cast<unsigned long long>(g_seed));
  out("  horizon:         [0, %g] (expected events ~ n T / 3 = %g n)\n", kHorizon, kHorizon / 3.0);
  out("  scheduler:       classic\n");
  out("  repetitions:     %s; statistics are medians\n", g_quick ? "3" : "5 (3 at n >= 10^6)");
  out("  baseline steps:  std::sort from scratch; insertion sort from last order, dt = %g and %g\n",
      kFineStep, kCoarseStep);
  out("  robust vs classic, same run, eps = %g, objects valid from the window's start:\n", kEps);
  out("    random-linear (above), window [0, %g]; random-poly degree 2 (c0 in [0, n],"
      " c1 in [-1, 1], c2 in [-1/2, 1/2]), window [0, %g] (~10 n events); at the same n\n",
      kHorizon, kQuadraticHorizon);
  if (!g_full) {
    out("    at n >= %zu over shorter windows, ~n events: [0, %g] and [0, %g] (--full:"
        " the whole windows)\n",
        kShortFrom, kLinearShortHorizon, kQuadraticShortHorizon);
  }
  out("    grids, parabola (their own windows [-k, k], [-1.5 k, 1.5 k], k = ceil(sqrt n))"
      " at n = ");
  for (const std::size_t n : paper_sizes) out("%zu ", n);
  out("\n    repetitions: %s (random), %s (grids, parabola)\n",
      g_quick ? "3, 1 at n >= 10^5" : "5, 3 at n >= 10^5, 1 at n >= 10^6",
      g_quick ? "3, 1 at n >= 10^4" : "5, 1 at n >= 10^4");
  out("\n");
  std::fflush(stdout);

  for (const std::size_t n : sizes) {
    const auto arg = static_cast<std::int64_t>(n);
    const int repetitions = baseline_repetitions(n);
    // Kinetic: one iteration = a whole run over [0, T]; several per repetition at small n.
    const auto iterations =
        static_cast<benchmark::IterationCount>(std::max<std::size_t>(1, 100000 / n));
    benchmark::RegisterBenchmark("BM_kinetic_sort", BM_kinetic_sort)
        ->Arg(arg)
        ->UseManualTime()
        ->Iterations(iterations)
        ->Repetitions(repetitions)
        ->Unit(benchmark::kMillisecond);
    for (const std::int64_t cold : {0, 1}) {
      benchmark::RegisterBenchmark("BM_std_sort_step", BM_std_sort_step)
          ->Args({arg, cold})
          ->UseRealTime()
          ->MinTime(0.2)
          ->Repetitions(repetitions)
          ->Unit(benchmark::kMicrosecond);
    }
    for (const std::int64_t coarse : {0, 1}) {
      benchmark::RegisterBenchmark("BM_insertion_step", BM_insertion_step)
          ->Args({arg, coarse})
          ->UseRealTime()
          ->MinTime(0.2)
          ->Repetitions(repetitions)
          ->Unit(benchmark::kMicrosecond);
    }
  }

  // Robust vs classic: classic and robust back to back for each (input, n).
  std::vector<std::pair<Input, std::size_t>> compare_rows;
  const auto register_compare = [&](Input input, std::size_t n, int repetitions,
                                    benchmark::IterationCount iterations) {
    compare_rows.emplace_back(input, n);
    for (const kinetic::SchedulerKind kind :
         {kinetic::SchedulerKind::Classic, kinetic::SchedulerKind::Robust,
          kinetic::SchedulerKind::Exact}) {
      // The exact scheduler up to n = 10^5 (its goals' sizes; GMP per certificate beyond).
      if (kind == kinetic::SchedulerKind::Exact && n > 100000) continue;
      const std::string name =
          std::string("BM_") + kinetic::to_string(kind) + "_sort_" + input_tag(input);
      // (Exact: one iteration, at most two repetitions: general certificates cost GMP.)
      const bool exact = kind == kinetic::SchedulerKind::Exact;
      benchmark::RegisterBenchmark(name.c_str(), BM_compare, input, kind)
          ->Arg(static_cast<std::int64_t>(n))
          ->UseManualTime()
          ->Iterations(exact ? 1 : iterations)
          ->Repetitions(exact ? std::min(repetitions, 2) : repetitions)
          ->Unit(benchmark::kMillisecond);
    }
  };
  for (const std::size_t n : sizes) {
    const auto iterations =
        static_cast<benchmark::IterationCount>(std::max<std::size_t>(1, 100000 / n));
    for (const Input input : {Input::Linear, Input::Quadratic})
      register_compare(input, n, compare_repetitions(n), iterations);
  }
  for (const std::size_t n : paper_sizes) {
    for (const Input input : {Input::Grids, Input::Parabola})
      register_compare(input, n, paper_repetitions(n), 1);
  }

  Collector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  print_summary(collector, sizes);
  print_compare(compare_rows);
  benchmark::Shutdown();
  return 0;
}
