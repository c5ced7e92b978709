// Fuzz harness (d): the kinetic Delaunay triangulation (exact, and robust at a fine and a coarse
// precision) and the kinetic closest pair over it (exact) against the brute-force oracle. The
// bytes choose the structure, a few points on degenerate motions (small integers, halves and
// quarters: points co-circular, collinear and coincident at many instants, identical motions,
// points passing through each other) and a timeline of advances, inserts, flight-plan updates,
// removes and queries (fuzz_play.hpp). After every step the structure must validate(); every query
// must equal the oracle's answer (exact at every time under the exact scheduler; under the robust
// one at the grid point at or before the query, its guarantee; points on lines): the
// triangles (co-circular ties by the lifting perturbation by ids), the closest pair and the
// exact nearest point. One input in eight has coefficients near the magnitude limit the two
// structures state (2^+-128). Preconditions are respected; a PreconditionError is a defect too.

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "fuzz_play.hpp"
#include "kinetic/kinetic.hpp"
#include "support/grid.hpp"

namespace {

using namespace kinetic;

struct Tally {
  std::uint64_t inputs = 0;
  fuzz::PlayTally play;
  ~Tally() {
    if (std::getenv("KINETIC_FUZZ_STATS") != nullptr) {
      std::fprintf(stderr, "fuzz_delaunay: %llu inputs, %llu steps, %llu queries checked\n",
                   static_cast<unsigned long long>(inputs),
                   static_cast<unsigned long long>(play.steps),
                   static_cast<unsigned long long>(play.queries_checked));
    }
  }
} tally;

/// The triangulation's answers at now against the oracle's at t (now, or the grid point before).
void check_triangulation(const MotionTable& m, KineticDelaunay& dt, fuzz::Input& in, Time now,
                         Time t) {
  std::vector<std::array<ObjectId, 3>> got, want;
  for (const auto& tri : dt.triangles()) got.push_back({m.id(tri[0]), m.id(tri[1]), m.id(tri[2])});
  for (const auto& tri : oracle::delaunay_at(m, t))
    want.push_back({m.id(tri[0]), m.id(tri[1]), m.id(tri[2])});
  if (got != want) fuzz::fail("delaunay: the triangles differ at t = " + std::to_string(t));
  const Point2 q{static_cast<double>(in.small(8)) / 2.0, static_cast<double>(in.small(8)) / 2.0};
  const std::optional<std::uint32_t> a = dt.nearest(q, 0.0, now);
  const std::optional<std::uint32_t> b = oracle::exact_nearest_at(m, {q[0], q[1]}, t);
  if (a.has_value() != b.has_value() || (a && m.id(*a) != m.id(*b)))
    fuzz::fail("delaunay: the nearest point differs at t = " + std::to_string(t));
  // The k nearest (copies and ties by id), exactly the oracle's at t.
  const std::size_t k = in.below(8);
  if (dt.k_nearest(q, k, 0.0, now) != oracle::k_nearest_at(m, q, k, t))
    fuzz::fail("delaunay: the k nearest differ at t = " + std::to_string(t));
}

template <class S>
void check_pair(const MotionTable& m, S& s, Time t, const char* what) {
  const auto got = s.closest_pair();
  const auto want = oracle::closest_pair_at(m, t);
  if (got.has_value() != want.has_value() ||
      (got && (m.id((*got)[0]) != m.id((*want)[0]) || m.id((*got)[1]) != m.id((*want)[1]))))
    fuzz::fail(std::string(what) + ": the closest pair differs at t = " + std::to_string(t));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  ++tally.inputs;
  SessionOptions options;
  options.scheduler = SchedulerKind::Exact;
  options.eps = fuzz::kEps;
  // The same bytes choose the structure as before (below(16) % 2 == below(2)); one input in
  // eight also puts coefficients near the structures' magnitude limit, 2^+-128, into its motions.
  // The Delaunay triangulation runs under the robust scheduler when pick / 2 is 1 (eps 1e-9)
  // or 5 (eps 0.3: many events in one cell, folds repaired), on points on lines.
  const std::uint32_t pick = in.below(16);
  const bool extremes = pick / 2 == 7;
  const int top = KineticDelaunay::kMagnitudeLog2;
  try {
    if (pick % 2 == 0) {
      const bool robust = pick / 2 == 1 || pick / 2 == 5;
      if (robust) {
        options.scheduler = SchedulerKind::Robust;
        options.eps = pick / 2 == 1 ? fuzz::kEps : 0.3;
      }
      Session<KineticDelaunay> s(2, options);
      const auto at = [&] {
        return robust ? test::grid_point_before(s.now(), options.eps) : s.now();
      };
      fuzz::points(
          in, s, 2,
          [&] {
            check_triangulation(s.motions(), s.structure(), in, s.now(), at());
            check_pair(s.motions(), s.structure(), at(), "delaunay");
          },
          tally.play, extremes, top, robust ? 1 : 2);
    } else {
      Session<KineticClosestPair> s(2, options);
      fuzz::points(
          in, s, 2,
          [&] {
            check_pair(s.motions(), s.structure(), s.now(), "closest-pair");
            check_triangulation(s.motions(), s.structure().triangulation(), in, s.now(), s.now());
          },
          tally.play, extremes, top);
    }
  } catch (const PreconditionError& e) {
    fuzz::fail(std::string("a precondition refused a correct use: ") + e.what());
  }
  return 0;
}
