// Every structure at scale (docs/performance/scale.md): n objects (default 10^6) of a random
// linear scenario of the kind the structure takes (points on a line or in the plane, intervals,
// boxes), a short window and three queries, run through the library's runner (kinetic::run::run,
// what `kinetic run` does, without reading a JSON file). One structure per process, since the
// memory figure is the process's peak:
//
//   bench_scale --structure NAME [--n N] [--end T] [--scheduler classic|robust|exact] [--seed S]
//
// Prints one line of key=value pairs: the structure, n, the window, the outcome, the events
// processed, the run's wall time (setup included), the resident memory before the run (the
// scenario in memory) and the peak during it, and (peak - before) / n bytes per object: what
// the structure, its motion table and its event queue took.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "harness.hpp"
#include "kinetic/run/runner.hpp"
#include "kinetic/scenario/generators.hpp"

using kinetic::bench::out;

namespace {

using kinetic::scenario::QueryType;

double resident_mib() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / 1048576.0;
}
double peak_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // kilobytes on Linux
}

/// Intervals [x, x + w] moving at one velocity v: x uniform in [0, n], w in [0, 20], v in [-1, 1].
kinetic::scenario::Scenario intervals(std::size_t n, std::uint64_t seed, double end) {
  kinetic::scenario::Scenario s;
  s.dimension = 2;
  s.objects_are = kinetic::scenario::ObjectsAre::Intervals;
  s.end_time = end;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> x(0.0, static_cast<double>(n)), w(0.0, 20.0), v(-1, 1);
  s.objects.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double a = x(rng), width = w(rng), speed = v(rng);
    kinetic::scenario::Motion m;
    m.coordinates = {{a, speed}, {a + width, speed}};
    s.objects.emplace_back(static_cast<kinetic::ObjectId>(i), std::move(m));
  }
  for (int k = 1; k <= 3; ++k) {
    kinetic::scenario::TimelineOp op;
    op.time = end * k / 4.0;
    op.query.type = QueryType::Stab;
    op.query.x = static_cast<double>(n) * k / 4.0;
    op.file_index = static_cast<std::size_t>(k - 1);
    s.timeline.push_back(op);
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  std::string structure, scheduler = "robust";
  std::size_t n = 1000000;
  double end = 0.3;
  std::uint64_t seed = 1;
  kinetic::bench::Harness harness("bench_scale",
                                  "one structure at scale through the runner (kinetic run's code "
                                  "path): wall time and memory per object");
  harness.option("--structure", structure, "the structure (kinetic run --structure NAME)");
  harness.option("--n", n, "objects");
  harness.option("--end", end, "the window's end (it starts at 0)");
  harness.option("--scheduler", scheduler, "robust, classic or exact");
  harness.seed(seed);
  harness.parse(argc, argv);
  if (scheduler != "robust" && scheduler != "classic" && scheduler != "exact") {
    std::fprintf(stderr, "bench_scale: --scheduler %s (robust, classic or exact)\n",
                 scheduler.c_str());
    return 2;
  }
  harness.configured();
  // The scenario each structure takes, and the query it answers.
  struct Kind {
    const char* name;
    const char* dataset;  // nullptr: intervals
    int dimension;
    QueryType query;
  };
  const Kind kinds[] = {
      {"sort", "random-linear", 1, QueryType::Sorted},
      {"tournament", "random-linear", 1, QueryType::Max},
      {"extent", "random-linear", 2, QueryType::Extent},
      {"kdtree", "random-linear", 2, QueryType::Range},
      {"range-tree", "random-linear", 2, QueryType::Range},
      {"longest-side-kdtree", "random-linear", 2, QueryType::Nearest},
      {"segment-tree", nullptr, 2, QueryType::Stab},
      {"hull", "random-linear", 2, QueryType::Hull},
      {"delaunay", "random-linear", 2, QueryType::Delaunay},
      {"closest-pair", "random-linear", 2, QueryType::ClosestPair},
      {"bvh", "boxes-linear", 2, QueryType::CollidingPairs},
      {"sweep-and-prune", "boxes-linear", 2, QueryType::CollidingPairs},
  };
  const Kind* kind = nullptr;
  for (const Kind& k : kinds) {
    if (structure == k.name) kind = &k;
  }
  // A structure not in the table: its objects' dataset in the plane (or its one dimension),
  // its first query type, as the registry describes it.
  Kind described{};
  for (const kinetic::run::StructureInfo& info : kinetic::run::structures()) {
    if (kind != nullptr || info.name != structure || info.queries.empty()) continue;
    described.name = info.name.c_str();
    described.dataset = info.objects == kinetic::scenario::ObjectsAre::Intervals ? nullptr
                        : info.objects == kinetic::scenario::ObjectsAre::Boxes   ? "boxes-linear"
                                                                                 : "random-linear";
    described.dimension = std::clamp(2, info.min_dimension, info.max_dimension);
    described.query = info.queries.front();
    kind = &described;
  }
  if (kind == nullptr || n < 2 || !(end > 0.0)) {
    std::fprintf(stderr,
                 "bench_scale: --structure names a structure, --n >= 2, --end > 0 (--help lists "
                 "the options)\n");
    return 2;
  }
  kinetic::scenario::Scenario s;
  if (kind->dataset == nullptr) {
    s = intervals(n, seed, end);
  } else {
    kinetic::scenario::GeneratorOptions o;
    o.n = n;
    o.seed = seed;
    o.dimension = kind->dimension;
    o.start_time = 0.0;
    o.end_time = end;
    o.queries = 3;
    o.query_type = kind->query;
    s = kinetic::scenario::generate(kind->dataset, o);
  }
  kinetic::run::RunOptions options;
  options.structure = structure;
  options.scheduler = scheduler == "classic" ? kinetic::SchedulerKind::Classic
                      : scheduler == "exact" ? kinetic::SchedulerKind::Exact
                                             : kinetic::SchedulerKind::Robust;
  kinetic::run::check_runnable(s, options, "bench_scale");
  const double before = resident_mib(), peak_before = peak_mib();
  std::ostringstream answers;
  const auto t0 = std::chrono::steady_clock::now();
  const kinetic::run::RunResult r = kinetic::run::run(s, options, answers);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double peak = peak_mib();
  out("| structure | scheduler | n | window | outcome | events | wall s | RSS before MiB | peak "
      "MiB | bytes per object |\n|---|---|---:|---|---|---:|---:|---:|---:|---:|\n");
  out("| %s | %s | %zu | [0, %g] | %s | %llu | %.3f | %.1f | %.1f%s | %.0f |\n", structure.c_str(),
      scheduler.c_str(), n, end,
      r.outcome == kinetic::run::RunOutcome::Completed ? "completed" : r.message.c_str(),
      static_cast<unsigned long long>(r.stats.counters.events()), wall, before, peak,
      peak <= peak_before ? " (peak before the run: a lower bound)" : "",
      (peak - before) * 1048576.0 / static_cast<double>(n));
  return r.outcome == kinetic::run::RunOutcome::Completed ? 0 : 1;
}
