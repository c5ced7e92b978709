// Soak: a long kinetic-sorting run with flight-plan updates, inserts and removes mixed in
// (docs/reliability.md). n points move on lines in [0, L]; each unit of time, the points that
// left [0, L] get a flight plan back inwards (a bounce), a few random points change course, one
// point leaves and one arrives. The run goes on until --events events; the resident set size is
// sampled every million events, and the program reports whether it stays flat after the first
// tenth of the run. At the end the maintained order is audited exactly against the oracle.
//   soak_sort [--events=100000000] [--n=2000] [--seed=1] [--eps=1e-9]
// Exit status 0 iff the audit passes and the memory stays flat (within 5 % or 4 MB).

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "harness.hpp"
#include "kinetic/kinetic.hpp"

using kinetic::bench::out;

namespace {

/// Resident set size in bytes (/proc/self/statm).
std::size_t rss_bytes() {
  std::ifstream f("/proc/self/statm");
  std::size_t pages = 0, resident = 0;
  f >> pages >> resident;
  return resident * 4096;
}

}  // namespace

int main(int argc, char** argv) {
  std::uint64_t target = 100000000, seed = 1;
  std::size_t n = 2000;
  double eps = 1e-9;
  kinetic::bench::Harness harness(
      "soak_sort",
      "a long run of kinetic sorting with bounces, course changes, inserts "
      "and removes, checked as it goes");
  harness.option("--events", target, "events to process");
  harness.option("--n", n, "points");
  harness.seed(seed);
  harness.option("--eps", eps, "the robust scheduler's precision");
  harness.parse(argc, argv);
  harness.configured();
  using kinetic::MotionPolynomial;
  using kinetic::ObjectId;
  const double width = static_cast<double>(n) / 20.0;  // L: 20 points per unit of length
  out("soak_sort: kinetic sorting, robust eps %g, n = %zu points in [0, %g], speeds in "
      "[-5, 5], seed %llu, until %llu events\n",
      eps, n, width, static_cast<unsigned long long>(seed),
      static_cast<unsigned long long>(target));
  out("  each unit of time: bounces (flight-plan updates) of the points outside [0, L], "
      "5 random course changes, 1 remove, 1 insert\n");

  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> where(0.0, width), speed(-5.0, 5.0);
  kinetic::Session<kinetic::KineticSort> s(1, {kinetic::SchedulerKind::Robust, eps}, 0);
  ObjectId next = 0;
  for (; next < static_cast<ObjectId>(n); ++next) {
    s.insert(next, {MotionPolynomial::from({where(rng), speed(rng)})});
  }
  const auto events = [&] { return s.simulator().counters().events(); };
  std::uint64_t updates = 0, inserts = 0, removes = 0, next_sample = 1000000;
  std::vector<std::size_t> rss;
  const double wall_start = kinetic::bench::wall_now();
  while (events() < target) {
    s.advance(s.now() + 1.0);
    const double t = s.now();
    for (const ObjectId id : s.ids()) {
      const double x = s.position(id)[0];
      if (x < 0.0 || x > width) {  // bounce back inwards, from where it is now
        const double v =
            (x < 0.0 ? 1.0 : -1.0) * (0.5 + 4.5 * std::generate_canonical<double, 53>(rng));
        s.update(id, {MotionPolynomial::from({x, v}, t)});
        ++updates;
      }
    }
    const std::vector<ObjectId> ids = s.ids();
    for (int k = 0; k < 5; ++k) {
      const ObjectId id = ids[rng() % ids.size()];
      s.update(id, {MotionPolynomial::from({s.position(id)[0], speed(rng)}, t)});
      ++updates;
    }
    s.remove(ids[rng() % ids.size()]);
    ++removes;
    s.insert(next++, {MotionPolynomial::from({where(rng), speed(rng)}, t)});
    ++inserts;
    while (events() >= next_sample) {
      rss.push_back(rss_bytes());
      next_sample += 1000000;
    }
  }
  const double seconds = kinetic::bench::wall_now() - wall_start;

  // The exact audit of the final order.
  std::vector<std::uint32_t> order;
  for (const ObjectId id : s.sorted()) order.push_back(s.motions().find(id)->index);
  const bool sorted = order.size() == s.size() &&
                      kinetic::oracle::is_sorted_at(s.motions(), order, 0, s.now()) && s.validate();

  std::size_t lo = SIZE_MAX, hi = 0;
  for (std::size_t k = rss.size() / 10; k < rss.size(); ++k) {
    lo = std::min(lo, rss[k]);
    hi = std::max(hi, rss[k]);
  }
  const bool flat = rss.empty() || hi - lo <= std::max<std::size_t>(lo / 20, 4u << 20);
  out("events %llu (in the past: %llu) over %.0f units of time in %.1f s: %.0f events/s\n",
      static_cast<unsigned long long>(events()),
      static_cast<unsigned long long>(s.simulator().counters().events_in_past), s.now(), seconds,
      static_cast<double>(events()) / seconds);
  out("changes: %llu flight-plan updates, %llu inserts, %llu removes\n",
      static_cast<unsigned long long>(updates), static_cast<unsigned long long>(inserts),
      static_cast<unsigned long long>(removes));
  if (!rss.empty()) {
    out("resident set: %.1f MB at 1e6 events, %.1f to %.1f MB after the first tenth "
        "(%zu samples): %s\n",
        static_cast<double>(rss.front()) / 1e6, static_cast<double>(lo) / 1e6,
        static_cast<double>(hi) / 1e6, rss.size(), flat ? "flat" : "GROWING");
  }
  out("final order of %zu points at t = %g audited exactly: %s\n", s.size(), s.now(),
      sorted ? "sorted" : "NOT SORTED");
  return sorted && flat ? 0 : 1;
}
