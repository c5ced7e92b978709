// Fuzz harness (c): every structure of the library's list (kinetic::Structures) against the
// brute-force oracle, each by its Case<S> below: the generic case, read from the structure's
// description (its objects, dimensions and queries), or one of its own (the Delaunay
// triangulation has its own harness, fuzz_delaunay). The bytes choose a structure by its name
// (kChoices, then the list's other structures in its order; the closest pair from cones shares
// the longest-side kd-tree's byte, split by one more byte), a scheduler,
// a few objects on degenerate motions (small integers and quarters: equal trajectories, many
// crossings at one instant, tangencies) and a timeline of advances, inserts, flight-plan updates,
// removes and queries, played through the session API. After every step the structure must
// validate(); at every query whose time is safe (no two coordinates the structure sorts meet within
// 2 eps before it, so even a robust answer must be exact) the answer must equal the oracle's.
// Classic scheduling may miss events (the traditional KDS), so under it only validity and the
// absence of crashes are checked. Preconditions are respected (the harness never misuses the API);
// a PreconditionError is a defect too.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "fuzz_input.hpp"
#include "fuzz_play.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/kinetic.hpp"

namespace {

using namespace kinetic;

using fuzz::kEps;
using fuzz::motion;

/// What the inputs exercised (printed at exit when KINETIC_FUZZ_STATS is set).
struct Tally {
  std::uint64_t inputs = 0;
  fuzz::PlayTally play;
  ~Tally() {
    if (std::getenv("KINETIC_FUZZ_STATS") != nullptr) {
      std::fprintf(stderr,
                   "fuzz_structures: %llu inputs, %llu steps, %llu queries checked, %llu "
                   "skipped at unsafe times\n",
                   static_cast<unsigned long long>(inputs),
                   static_cast<unsigned long long>(play.steps),
                   static_cast<unsigned long long>(play.queries_checked),
                   static_cast<unsigned long long>(play.queries_unsafe));
    }
  }
} tally;

std::vector<ObjectId> ids_of(const MotionTable& m, const std::vector<std::uint32_t>& indices) {
  std::vector<ObjectId> ids;
  for (const std::uint32_t i : indices) ids.push_back(m.id(i));
  std::sort(ids.begin(), ids.end());
  return ids;
}

bool g_extremes = false;

template <class S>
void points(fuzz::Input& in, Session<S>& s, int d, auto&& query) {
  fuzz::points(in, s, d, query, tally.play, g_extremes);
}

/// Boxes: no two sides on one axis meet within [t - 2 eps, t] (a robust answer must then be
/// exact). Sides are compared exactly at the ends and the middle of the window; a pair whose
/// functions are identical (copies, or sides of boxes of equal motion) never crosses.
bool boxes_safe(const MotionTable& m, int d, Time t) {
  const std::vector<std::uint32_t> alive = m.alive_indices();
  for (int axis = 0; axis < d; ++axis) {
    BoxEndpointKeys keys(m, axis);
    for (const std::uint32_t i : alive) keys.refresh(i);
    for (std::size_t i = 0; i < alive.size(); ++i) {
      for (std::size_t j = i + 1; j < alive.size(); ++j) {
        for (const BoxSide u : {BoxSide::Low, BoxSide::High}) {
          for (const BoxSide v : {BoxSide::Low, BoxSide::High}) {
            const std::uint32_t a = BoxEndpointKeys::key(alive[i], u);
            const std::uint32_t b = BoxEndpointKeys::key(alive[j], v);
            if (keys.compare_after(a, b, t - 2 * kEps, nullptr) == 0 &&
                keys.compare_at(a, b, t - 2 * kEps) == 0)
              continue;  // the same function of t
            const int lo = keys.compare_at(a, b, t - 2 * kEps),
                      mid = keys.compare_at(a, b, t - kEps);
            const int hi = keys.compare_at(a, b, t);
            if (lo == 0 || mid == 0 || hi == 0 || lo != mid || mid != hi) return false;
          }
        }
      }
    }
  }
  return true;
}

/// The colliding pairs at now against the oracle (closed boxes): every answered pair overlaps
/// at now, and every overlapping pair is answered unless it touches only at now and is apart
/// just after: under robust or classic scheduling (events after their exact times), or sides of
/// curved motions touching without crossing (no event: docs/scheduling.md).
template <class S>
void check_collisions(Session<S>& s, int d, const char* what) {
  const MotionTable& m = s.motions();
  const Time t = s.now();
  std::vector<std::array<ObjectId, 2>> want;
  for (const auto& p : oracle::colliding_pairs_at(m, t)) {
    ObjectId a = m.id(p[0]), b = m.id(p[1]);
    if (a > b) std::swap(a, b);
    want.push_back({a, b});
  }
  std::sort(want.begin(), want.end());
  const std::vector<std::array<ObjectId, 2>> got = s.colliding_pairs();
  for (const auto& p : got) {
    if (!std::binary_search(want.begin(), want.end(), p))
      fuzz::fail(std::string(what) +
                 ": a pair answered that does not overlap at t = " + std::to_string(t));
  }
  for (const auto& p : want) {
    if (std::find(got.begin(), got.end(), p) != got.end()) continue;
    const std::uint32_t a = m.find(p[0])->index, b = m.find(p[1])->index;
    bool apart_after = false;
    for (int axis = 0; axis < d && !apart_after; ++axis) {
      BoxEndpointKeys keys(m, axis);
      keys.refresh(a);
      keys.refresh(b);
      apart_after = keys.compare_after(BoxEndpointKeys::key(a, BoxSide::Low),
                                       BoxEndpointKeys::key(b, BoxSide::High), t, nullptr) > 0 ||
                    keys.compare_after(BoxEndpointKeys::key(b, BoxSide::Low),
                                       BoxEndpointKeys::key(a, BoxSide::High), t, nullptr) > 0;
    }
    if (!apart_after)
      fuzz::fail(std::string(what) +
                 ": a contact lost (overlapping at and after t = " + std::to_string(t) + ")");
  }
}

/// Plays boxes on a session of S: centers on the harness's motions, half extents in halves.
template <class S>
void boxes(fuzz::Input& in, Session<S>& s, int d, bool extremes, const char* what) {
  const bool robust = s.scheduler().kind() == SchedulerKind::Robust;
  fuzz::play(
      in, s,
      [&](Time now) {
        std::vector<MotionPolynomial> m;
        for (int a = 0; a < d; ++a) m.push_back(fuzz::motion(in, now, extremes));
        for (int a = 0; a < d; ++a)
          m.push_back(MotionPolynomial::from({static_cast<double>(in.below(4)) / 2.0}));
        return m;
      },
      [&] {
        if (robust && !boxes_safe(s.motions(), d, s.now())) return;
        check_collisions(s, d, what);
      },
      false, tally.play);
}

Box random_box(fuzz::Input& in, int d) {
  Box box;
  for (int a = 0; a < d; ++a) {
    const double lo = static_cast<double>(in.small(8)) / 2.0;
    box.push_back({lo, lo + static_cast<double>(in.below(12)) / 2.0});
  }
  return box;
}

/// Safe for the closest pair from cones under robust scheduling: no two points meet along any of
/// its eight directions within [t - 2 eps, t] (its orders are then exact), and no pair's length
/// crosses the closest pair's in that window (the tournament's comparisons with it are then
/// exact): the answer must then be as close as the oracle's.
bool cones_safe(const MotionTable& m, Time t, std::uint32_t a, std::uint32_t b) {
  const std::vector<std::uint32_t> alive = m.alive_indices();
  const auto stable = [](int lo, int mid, int hi) { return lo != 0 && lo == mid && mid == hi; };
  for (int d = 0; d < 8; ++d) {
    DirectionKeys keys(m, d);
    for (const std::uint32_t i : alive) keys.refresh(i);
    for (std::size_t i = 0; i < alive.size(); ++i) {
      for (std::size_t j = i + 1; j < alive.size(); ++j) {
        const std::uint32_t u = alive[i], w = alive[j];
        if (keys.compare_after(u, w, t - 2 * kEps, nullptr) == 0) continue;  // equal for ever
        if (!stable(keys.compare_at(u, w, t - 2 * kEps), keys.compare_at(u, w, t - kEps),
                    keys.compare_at(u, w, t)))
          return false;
      }
    }
  }
  const MovingPoint2 pa = moving_point(m, a), pb = moving_point(m, b);
  for (std::size_t i = 0; i < alive.size(); ++i) {
    for (std::size_t j = i + 1; j < alive.size(); ++j) {
      const MovingPoint2 p = moving_point(m, alive[i]), q = moving_point(m, alive[j]);
      const auto at = [&](Time x) { return compare_squared_distances_at(p, q, pa, pb, x); };
      if (at(t - 2 * kEps) == 0 && at(t - kEps) == 0 && at(t) == 0) continue;  // tied
      if (!stable(at(t - 2 * kEps), at(t - kEps), at(t))) return false;
    }
  }
  return true;
}

/// The closest pair from cones: exact answers equal the oracle's; robust ones are as close at
/// the times cones_safe() allows. Coefficients stay below 2^1016 (it takes |c| < 2^1023).
void closest_pair(fuzz::Input& in, const SessionOptions& options, bool extremes) {
  Session<KineticConeClosestPair> s(2, options);
  fuzz::points(
      in, s, 2,
      [&] {
        const MotionTable& m = s.motions();
        const Time t = s.now();
        const auto got = s.closest_pair();
        const auto want = oracle::closest_pair_at(m, t);
        if (got.has_value() != want.has_value())
          fuzz::fail("closest pair: an answer where the oracle has none, or none where it has");
        if (!got) return;
        const std::uint32_t a = m.find((*got)[0])->index, b = m.find((*got)[1])->index;
        if (options.scheduler == SchedulerKind::Exact) {
          if ((*got)[0] != m.id((*want)[0]) || (*got)[1] != m.id((*want)[1]))
            fuzz::fail("closest pair: differs from the oracle at t = " + std::to_string(t));
          return;
        }
        if (!cones_safe(m, t, (*want)[0], (*want)[1])) return;
        if (compare_squared_distances_at(moving_point(m, a), moving_point(m, b),
                                         moving_point(m, (*want)[0]), moving_point(m, (*want)[1]),
                                         t) != 0)
          fuzz::fail("closest pair: farther than the oracle's at a safe time t = " +
                     std::to_string(t));
      },
      tally.play, extremes, extremes ? 1016 : 0);
}

/// A query of type q on points against the oracle (the types generic_check names).
template <class S>
void check_point_query(fuzz::Input& in, Session<S>& s, int d, QueryType q,
                       const std::string& what) {
  const MotionTable& m = s.motions();
  if (q == QueryType::Range) {
    if constexpr (requires { s.range(Box{}); }) {
      const Box box = random_box(in, d);
      if (s.range(box) != ids_of(m, oracle::in_box_at(m, box, s.now())))
        fuzz::fail(what + ": range differs at t = " + std::to_string(s.now()));
      return;
    }
  }
  if (q == QueryType::Extent) {
    if constexpr (requires { s.extent(); }) {
      // Per axis, the min and the max equal the oracle's values.
      const std::vector<std::array<ObjectId, 2>> box = s.extent();
      for (int axis = 0; axis < d; ++axis) {
        const auto& lohi = box[static_cast<std::size_t>(axis)];
        const std::uint32_t lo = oracle::min_at(m, axis, s.now());
        const std::uint32_t hi = oracle::max_at(m, axis, s.now());
        if (compare_at(m.motion(m.find(lohi[0])->index, axis), m.motion(lo, axis), s.now()) != 0 ||
            compare_at(m.motion(m.find(lohi[1])->index, axis), m.motion(hi, axis), s.now()) != 0)
          fuzz::fail(what + ": extent not the extremes at t = " + std::to_string(s.now()));
      }
      return;
    }
  }
  if (q == QueryType::Max || q == QueryType::Min) {
    if constexpr (requires { s.extent(); }) return;  // the extent's ends: checked with it
  }
  if (q == QueryType::KNearest || q == QueryType::Nearest) {
    if constexpr (requires { s.k_nearest(std::span<const double>{}, std::size_t{1}, 0.0); }) {
      // Exact for eps = 0: the ids by distance then id, as the oracle orders them; nearest is
      // its first.
      std::vector<double> p(static_cast<std::size_t>(d));
      for (double& x : p) x = static_cast<double>(in.small(8)) / 2.0;
      const std::size_t k = q == QueryType::Nearest ? 1 : in.below(6);
      std::vector<ObjectId> want;
      for (const std::uint32_t i : oracle::k_nearest_at(m, p, k, s.now())) want.push_back(m.id(i));
      if (q == QueryType::KNearest && s.k_nearest(p, k, 0.0) != want)
        fuzz::fail(what + ": k_nearest differs at t = " + std::to_string(s.now()));
      if constexpr (requires { s.nearest(std::span<const double>{}, 0.0); }) {
        if (q == QueryType::Nearest) {
          const std::optional<ObjectId> got = s.nearest(std::span<const double>(p), 0.0);
          if (got.has_value() != !want.empty() || (got && *got != want[0]))
            fuzz::fail(what + ": nearest differs at t = " + std::to_string(s.now()));
        }
      }
      return;
    }
  }
  fuzz::fail(what + ": the generic case cannot ask '" + to_string(q) + "' of its session");
}

/// Plays intervals [c(t) - w(t), c(t) + w(t)] with w(t) >= 0 from now on (rigid or growing) on a
/// session of S, its stabbing queries against the oracle.
template <class S>
void intervals(fuzz::Input& in, Session<S>& s, const std::string& what) {
  fuzz::play(
      in, s,
      [&](Time now) {
        const MotionPolynomial c = motion(in, now);
        const double w0 = static_cast<double>(in.below(5)) / 2.0;
        const double g = static_cast<double>(in.below(3)) / 2.0;
        std::array<double, 3> lo{}, hi{};
        for (int k = 0; k <= c.degree; ++k) lo[k] = hi[k] = c.c[k];
        // w is added in powers of (t - c.origin):
        // w(t) = w0 + g (t - now) = (w0 + g (o - now)) + g (t - o); w >= 0 for t >= now.
        const Time o = c.origin;
        const double w_at_o = w0 + g * (o - now);
        lo[0] -= w_at_o, hi[0] += w_at_o;
        lo[1] -= g, hi[1] += g;
        return std::vector<MotionPolynomial>{MotionPolynomial::from(lo, o),
                                             MotionPolynomial::from(hi, o)};
      },
      [&] {
        const double x = static_cast<double>(in.small(8)) / 2.0;
        if (s.stab(x) != ids_of(s.motions(), oracle::stab_at(s.motions(), x, s.now())))
          fuzz::fail(what + ": stab differs at t = " + std::to_string(s.now()));
      },
      true, tally.play);
}

/// The query types the generic case checks against the oracle, by the structure's objects.
bool generic_check(ObjectsAre objects, QueryType q) {
  switch (objects) {
    case ObjectsAre::Points:
      return q == QueryType::Range || q == QueryType::Extent || q == QueryType::KNearest ||
             q == QueryType::Nearest;
    case ObjectsAre::Boxes:
      return q == QueryType::CollidingPairs;
    case ObjectsAre::Intervals:
      return q == QueryType::Stab;
  }
  return false;
}

/// The generic case, read from S's description: a session of S on its objects (points, boxes or
/// intervals; points and boxes in one to three of the dimensions it takes, chosen by a byte)
/// against the oracle, every query type it answers at every query (generic_check: the harness
/// refuses to run a structure whose queries the generic case does not check; such a structure
/// gets a Case of its own).
template <class S>
struct GenericCase {
  static void play(fuzz::Input& in, const SessionOptions& options, bool extremes) {
    static const StructureDescription desc = S::description();
    // Points and boxes: the dimension from a byte, where the structure takes more than one.
    const int lo = desc.min_dimension, hi = std::min(desc.max_dimension, 3);
    const int d = desc.objects == ObjectsAre::Intervals || hi <= lo
                      ? lo
                      : lo + static_cast<int>(in.below(static_cast<std::uint32_t>(hi - lo + 1)));
    switch (desc.objects) {
      case ObjectsAre::Points: {
        Session<S> s(d, options);
        points(in, s, d, [&] {
          for (const QueryType q : desc.queries) check_point_query(in, s, d, q, desc.name);
        });
        return;
      }
      case ObjectsAre::Boxes:
        if constexpr (requires(Session<S> & s) { s.colliding_pairs(); }) {
          Session<S> s(boxes_table_dimension(d), options);
          boxes(in, s, d, extremes, desc.name.c_str());
          return;
        }
        break;
      case ObjectsAre::Intervals:
        if constexpr (requires(Session<S> & s) { s.stab(0.0); }) {
          Session<S> s(2, options);
          intervals(in, s, desc.name);
          return;
        }
        break;
    }
    fuzz::fail(desc.name + ": the generic case cannot ask its session its objects' queries");
  }
};

/// The fuzz case of each structure: Case<S>::play(in, options, extremes) plays a session of S
/// against its oracle; the generic one unless S has its own below.
template <class S>
struct Case : GenericCase<S> {};

template <>
struct Case<KineticSort> {
  static void play(fuzz::Input& in, const SessionOptions& options, bool /*extremes*/) {
    Session<KineticSort> s(1, options, 0);
    points(in, s, 1, [&] {
      std::vector<std::uint32_t> order;
      for (const ObjectId id : s.sorted()) order.push_back(s.motions().find(id)->index);
      if (order.size() != s.size() || !oracle::is_sorted_at(s.motions(), order, 0, s.now()))
        fuzz::fail("sort: the order is not sorted at t = " + std::to_string(s.now()));
    });
  }
};

template <>
struct Case<KineticTournament> {
  static void play(fuzz::Input& in, const SessionOptions& options, bool /*extremes*/) {
    const Extreme extreme = in.below(2) == 0 ? Extreme::Max : Extreme::Min;
    Session<KineticTournament> s(1, options, 0, extreme);
    points(in, s, 1, [&] {
      const std::optional<ObjectId> top = s.top();
      const std::uint32_t want = extreme == Extreme::Max ? oracle::max_at(s.motions(), 0, s.now())
                                                         : oracle::min_at(s.motions(), 0, s.now());
      if (!top || compare_at(s.motions().motion(s.motions().find(*top)->index, 0),
                             s.motions().motion(want, 0), s.now()) != 0)
        fuzz::fail("tournament: not the extreme at t = " + std::to_string(s.now()));
    });
  }
};

template <>
struct Case<LongestSideKdTree> {
  static void play(fuzz::Input& in, const SessionOptions& options, bool /*extremes*/) {
    Session<LongestSideKdTree> s(2, options);
    points(in, s, 2, [&] {
      const Box box = random_box(in, 2);
      if (s.range(box) != ids_of(s.motions(), oracle::in_box_at(s.motions(), box, s.now())))
        fuzz::fail("longest-side kd-tree: range differs at t = " + std::to_string(s.now()));
      const std::array<double, 2> q{static_cast<double>(in.small(8)) / 2.0,
                                    static_cast<double>(in.small(8)) / 2.0};
      const double eps = static_cast<double>(in.below(3)) / 4.0;
      const std::optional<ObjectId> got = s.nearest({q[0], q[1]}, eps);
      const double best = oracle::nearest_distance_at(s.motions(), q, s.now());
      const double d = oracle::distance_at(s.motions(), s.motions().find(*got)->index, q, s.now());
      if (std::isfinite(best) && std::isfinite(d) && !(d <= (1.0 + eps) * best * (1.0 + 0x1p-38)))
        fuzz::fail("longest-side kd-tree: nearest too far at t = " + std::to_string(s.now()));
      // k nearest, exact for eps = 0.
      const std::size_t k = in.below(6);
      std::vector<ObjectId> want;
      for (const std::uint32_t i : oracle::k_nearest_at(s.motions(), q, k, s.now()))
        want.push_back(s.motions().id(i));
      if (s.k_nearest(q, k, 0.0) != want)
        fuzz::fail("longest-side kd-tree: k_nearest differs at t = " + std::to_string(s.now()));
    });
  }
};

template <>
struct Case<KineticConeClosestPair> {
  static void play(fuzz::Input& in, const SessionOptions& options, bool extremes) {
    closest_pair(in, options, extremes);
  }
};

template <>
struct Case<KineticHull> {
  static void play(fuzz::Input& in, const SessionOptions& options, bool /*extremes*/) {
    // The hull: every answer is exactly the hull of the points it names (a convex polygon of
    // live points); when no certificate has a root within 2 eps of now it is the oracle's
    // (its vertices, exactly).
    Session<KineticHull> s(2, options);
    points(in, s, 2, [&] {
      const std::vector<ObjectId> got = s.hull();
      std::vector<std::uint32_t> named;
      for (const ObjectId id : got) named.push_back(s.motions().find(id)->index);
      if (oracle::hull_of_at(s.motions(), named, s.now()) != named)
        fuzz::fail("hull: the answer is not a convex polygon at t = " + std::to_string(s.now()));
      if (s.structure().audit_certificates(s.now(), 2 * kEps).wrong != 0) return;
      const std::vector<std::uint32_t> want = oracle::hull_at(s.motions(), s.now());
      // The oracle names the smallest id of coincident points; where two different motions
      // meet exactly at a vertex the structure may name the other one (docs/hull.md, "Known
      // gap"): a vertex is right when it is at the oracle's vertex exactly.
      bool same = named.size() == want.size();
      for (std::size_t k = 0; same && k < want.size(); ++k) {
        for (int axis = 0; axis < 2; ++axis) {
          same = same && compare_at(s.motions().motion(named[k], axis),
                                    s.motions().motion(want[k], axis), s.now()) == 0;
        }
      }
      if (!same) fuzz::fail("hull: differs from the oracle at t = " + std::to_string(s.now()));
    });
  }
};

/// The Delaunay triangulation is fuzzed by its own harness (fuzz_delaunay.cpp): exact
/// certificates, a triangulation to check against the oracle's circles.
template <>
struct Case<KineticDelaunay> {
  static constexpr const char* kOwnHarness = "fuzz_delaunay";
};

/// What the first byte chose before the generic case (the corpus's bytes keep their meaning):
/// the list's other structures follow in its order, so a new structure needs no edit here. Byte 5
/// is shared by the longest-side kd-tree and the closest pair from cones, split by one more byte.
constexpr std::array<std::string_view, 11> kChoices{
    "sort",         "tournament",   "kdtree", "range-tree", "longest-side-kdtree",
    "closest-pair", "segment-tree", "hull",   "extent",     "sweep-and-prune",
    "bvh"};
constexpr std::size_t kSharedChoice = 5;  // closest-pair or longest-side-kdtree

template <class S>
constexpr bool own_harness() {
  return requires { Case<S>::kOwnHarness; };
}

/// Whether the generic case checks every query the description lists (the extent's max and min
/// are its ends: checked with it).
bool generic_checks_all(const StructureDescription& d) {
  const auto answers = [&](QueryType q) {
    return std::find(d.queries.begin(), d.queries.end(), q) != d.queries.end();
  };
  for (const QueryType q : d.queries) {
    const bool extent_end = (q == QueryType::Max || q == QueryType::Min) &&
                            d.objects == ObjectsAre::Points && answers(QueryType::Extent);
    if (!extent_end && !generic_check(d.objects, q)) return false;
  }
  return true;
}

/// The list's structures' names in its order, and the first byte's choices: kChoices, then the
/// list's other structures but those with their own harness. Checked once: every choice names a
/// structure, none with its own harness is chosen, and the generic case checks every query of the
/// structures it plays.
struct Choices {
  std::vector<std::string> names;
  std::vector<std::string> bytes;
};
template <class... S>
Choices choices_checked(StructureList<S...> /*list*/) {
  Choices c{{S::description().name...}, {kChoices.begin(), kChoices.end()}};
  const std::array<bool, sizeof...(S)> own{own_harness<S>()...};
  const std::array<bool, sizeof...(S)> generic{std::is_base_of_v<GenericCase<S>, Case<S>>...};
  const std::array<bool, sizeof...(S)> checked{
      (!std::is_base_of_v<GenericCase<S>, Case<S>> || generic_checks_all(S::description()))...};
  for (std::size_t k = 0; k < c.names.size(); ++k) {
    const bool chosen = std::find(kChoices.begin(), kChoices.end(), c.names[k]) != kChoices.end();
    if (own[k] && chosen)
      fuzz::fail("fuzz_structures: structure '" + c.names[k] + "' has its own harness and a byte");
    if (!own[k] && !chosen) c.bytes.push_back(c.names[k]);
    if (generic[k] && !checked[k])
      fuzz::fail("fuzz_structures: structure '" + c.names[k] +
                 "' answers a query the generic case does not check: give it a Case of its own");
  }
  for (const std::string_view choice : kChoices) {
    if (std::find(c.names.begin(), c.names.end(), choice) == c.names.end())
      fuzz::fail("fuzz_structures: the choice '" + std::string(choice) +
                 "' names no structure of kinetic::Structures");
  }
  return c;
}

/// Plays the case of the structure named `name` (one of the list's).
template <class... S>
void play_named(const std::vector<std::string>& names, std::string_view name, fuzz::Input& in,
                const SessionOptions& options, bool extremes, StructureList<S...> /*list*/) {
  std::size_t k = 0;
  const auto try_one = [&]<class T>() {
    if constexpr (!own_harness<T>()) {
      if (names[k] == name) Case<T>::play(in, options, extremes);
    }
    ++k;
  };
  (try_one.template operator()<S>(), ...);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Choices choices = choices_checked(Structures{});
  fuzz::Input in(data, size);
  ++tally.inputs;
  const std::size_t which = in.below(static_cast<std::uint32_t>(choices.bytes.size()));
  SessionOptions options;
  const std::uint32_t scheduler = in.below(6);
  options.scheduler = scheduler == 0   ? SchedulerKind::Classic
                      : scheduler == 1 ? SchedulerKind::Exact
                                       : SchedulerKind::Robust;
  options.eps = kEps;
  // One input in eight puts coefficients near the limits of double into its motions.
  const bool extremes = in.below(8) == 0;
  g_extremes = extremes;
  std::string_view name = choices.bytes[which];
  if (which == kSharedChoice && in.below(2) != 0) name = "longest-side-kdtree";
  fuzz::context() = std::string(name) + ", " + to_string(options.scheduler) +
                    (extremes ? ", extreme magnitudes" : "");
  try {
    play_named(choices.names, name, in, options, extremes, Structures{});
  } catch (const PreconditionError& e) {
    fuzz::fail(std::string("a precondition refused a correct use: ") + e.what());
  } catch (const SessionError& e) {
    // The traditional classic KDS may loop on degenerate input: its loop guard stops it, as
    // documented (docs/scheduling.md); under robust and exact scheduling that is a defect.
    if (options.scheduler != SchedulerKind::Classic)
      fuzz::fail(std::string("the session stopped: ") + e.what());
  }
  return 0;
}
