// Fuzz harness (c): every structure against the brute-force oracle. The bytes choose a
// structure, a scheduler, a few objects on degenerate motions (small integers and quarters:
// equal trajectories, many crossings at one instant, tangencies) and a timeline of advances,
// inserts, flight-plan updates, removes and queries, played through the session API. After
// every step the structure must validate(); at every query whose time is safe (no two
// coordinates the structure sorts meet within 2 eps before it, so even a robust answer must be
// exact) the answer must equal the oracle's. Classic scheduling may miss events (the
// traditional KDS), so under it only validity and the absence of crashes are checked.
// Preconditions are respected (the harness never misuses the API); a PreconditionError is a
// defect too.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/kinetic.hpp"
#include "support/crossing.hpp"

namespace {

using namespace kinetic;

constexpr double kEps = 1e-9;

/// What the inputs exercised (printed at exit when KINETIC_FUZZ_STATS is set).
struct Tally {
  std::uint64_t inputs = 0, steps = 0, queries_checked = 0, queries_unsafe = 0;
  ~Tally() {
    if (std::getenv("KINETIC_FUZZ_STATS") != nullptr) {
      std::fprintf(stderr,
                   "fuzz_structures: %llu inputs, %llu steps, %llu queries checked, %llu "
                   "skipped at unsafe times\n",
                   static_cast<unsigned long long>(inputs), static_cast<unsigned long long>(steps),
                   static_cast<unsigned long long>(queries_checked),
                   static_cast<unsigned long long>(queries_unsafe));
    }
  }
} tally;

/// A motion of degree <= 2 with small coefficients, valid from `now` (its origin).
MotionPolynomial motion(fuzz::Input& in, Time now) {
  std::array<double, 3> c{static_cast<double>(in.small(4)), static_cast<double>(in.small(3)) / 2.0,
                          in.below(3) == 0 ? static_cast<double>(in.small(2)) / 4.0 : 0.0};
  return MotionPolynomial::from(c, in.below(2) == 0 ? now : 0.0);
}

/// Safe: no two of the coordinates the structure sorts meet within [t - 2 eps, t] (`cross_axes`:
/// the segment tree sorts both ends of all intervals together).
bool safe(const MotionTable& m, Time t, bool cross_axes) {
  const std::vector<std::uint32_t> alive = m.alive_indices();
  const int d = m.dimension();
  for (std::size_t i = 0; i < alive.size(); ++i) {
    for (std::size_t j = 0; j < alive.size(); ++j) {
      for (int a = 0; a < d; ++a) {
        for (int b = 0; b < d; ++b) {
          if (a != b && !cross_axes) continue;
          if (i == j && a == b) continue;
          if (test::cross_within(m.motion(alive[i], a), m.motion(alive[j], b), t - 2 * kEps, t))
            return false;
        }
      }
    }
  }
  return true;
}

std::vector<ObjectId> ids_of(const MotionTable& m, const std::vector<std::uint32_t>& indices) {
  std::vector<ObjectId> ids;
  for (const std::uint32_t i : indices) ids.push_back(m.id(i));
  std::sort(ids.begin(), ids.end());
  return ids;
}

Box random_box(fuzz::Input& in, int d) {
  Box box;
  for (int a = 0; a < d; ++a) {
    const double lo = static_cast<double>(in.small(8)) / 2.0;
    box.push_back({lo, lo + static_cast<double>(in.below(12)) / 2.0});
  }
  return box;
}

/// Plays the bytes on a session of S; `query` checks one query at a safe time.
template <class S, class MakeMotion, class Query>
void play(fuzz::Input& in, Session<S>& s, MakeMotion&& make, Query&& query, bool cross_axes) {
  const bool exact_answers = s.scheduler().kind() == SchedulerKind::Robust;
  const int n = 1 + static_cast<int>(in.below(7));
  ObjectId next = 0;
  for (; next < n; ++next) s.insert(next, make(s.now()));
  for (int step = 0; step < 24 && !in.done(); ++step) {
    s.advance(s.now() + static_cast<double>(in.below(9)) / 4.0);
    const std::vector<ObjectId> ids = s.ids();
    switch (in.below(5)) {
      case 0:
        s.insert(next++, make(s.now()));
        break;
      case 1:
        if (!ids.empty())
          s.update(ids[in.below(static_cast<std::uint32_t>(ids.size()))], make(s.now()));
        break;
      case 2:
        if (ids.size() > 1) s.remove(ids[in.below(static_cast<std::uint32_t>(ids.size()))]);
        break;
      default:
        if (!exact_answers) break;
        if (safe(s.motions(), s.now(), cross_axes)) {
          query();
          ++tally.queries_checked;
        } else {
          ++tally.queries_unsafe;
        }
        break;
    }
    ++tally.steps;
    if (!s.validate()) fuzz::fail("validate() failed at t = " + std::to_string(s.now()));
  }
}

template <class S>
void points(fuzz::Input& in, Session<S>& s, int d, auto&& query) {
  play(
      in, s,
      [&](Time now) {
        std::vector<MotionPolynomial> m;
        for (int a = 0; a < d; ++a) m.push_back(motion(in, now));
        return m;
      },
      query, false);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  ++tally.inputs;
  const int which = static_cast<int>(in.below(8));
  SessionOptions options;
  options.scheduler = in.below(4) == 0 ? SchedulerKind::Classic : SchedulerKind::Robust;
  options.eps = kEps;
  try {
    switch (which) {
      case 0: {
        Session<KineticSort> s(1, options, 0);
        points(in, s, 1, [&] {
          std::vector<std::uint32_t> order;
          for (const ObjectId id : s.sorted()) order.push_back(s.motions().find(id)->index);
          if (order.size() != s.size() || !oracle::is_sorted_at(s.motions(), order, 0, s.now()))
            fuzz::fail("sort: the order is not sorted at t = " + std::to_string(s.now()));
        });
        break;
      }
      case 1: {
        const Extreme extreme = in.below(2) == 0 ? Extreme::Max : Extreme::Min;
        Session<KineticTournament> s(1, options, 0, extreme);
        points(in, s, 1, [&] {
          const std::optional<ObjectId> top = s.top();
          const std::uint32_t want = extreme == Extreme::Max
                                         ? oracle::max_at(s.motions(), 0, s.now())
                                         : oracle::min_at(s.motions(), 0, s.now());
          if (!top || compare_at(s.motions().motion(s.motions().find(*top)->index, 0),
                                 s.motions().motion(want, 0), s.now()) != 0)
            fuzz::fail("tournament: not the extreme at t = " + std::to_string(s.now()));
        });
        break;
      }
      case 2:
      case 3: {
        const int d = 1 + static_cast<int>(in.below(3));
        if (which == 2) {
          Session<KineticKdTree> s(d, options);
          points(in, s, d, [&] {
            const Box box = random_box(in, d);
            if (s.range(box) != ids_of(s.motions(), oracle::in_box_at(s.motions(), box, s.now())))
              fuzz::fail("kd-tree: range differs at t = " + std::to_string(s.now()));
          });
        } else {
          Session<KineticRangeTree> s(d, options);
          points(in, s, d, [&] {
            const Box box = random_box(in, d);
            if (s.range(box) != ids_of(s.motions(), oracle::in_box_at(s.motions(), box, s.now())))
              fuzz::fail("range tree: range differs at t = " + std::to_string(s.now()));
          });
        }
        break;
      }
      case 4:
      case 5: {
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
          const double d =
              oracle::distance_at(s.motions(), s.motions().find(*got)->index, q, s.now());
          if (!(d <= (1.0 + eps) * best * (1.0 + 0x1p-38)))
            fuzz::fail("longest-side kd-tree: nearest too far at t = " + std::to_string(s.now()));
        });
        break;
      }
      case 7: {
        // The hull: every answer is exactly the hull of the points it names (a convex polygon of
        // live points); when no certificate has a root within 2 eps of now it is the oracle's.
        Session<KineticHull> s(2, options);
        points(in, s, 2, [&] {
          const std::vector<ObjectId> got = s.hull();
          std::vector<std::uint32_t> named;
          for (const ObjectId id : got) named.push_back(s.motions().find(id)->index);
          if (oracle::hull_of_at(s.motions(), named, s.now()) != named)
            fuzz::fail("hull: the answer is not a convex polygon at t = " +
                       std::to_string(s.now()));
          if (s.structure().audit_certificates(s.now(), 2 * kEps).wrong != 0) return;
          std::vector<ObjectId> want;
          for (const std::uint32_t i : oracle::hull_at(s.motions(), s.now()))
            want.push_back(s.motions().id(i));
          if (got != want)
            fuzz::fail("hull: differs from the oracle at t = " + std::to_string(s.now()));
        });
        break;
      }
      default: {
        Session<KineticSegmentTree> s(2, options);
        // Intervals [c(t) - w(t), c(t) + w(t)] with w(t) >= 0 from now on: rigid or growing.
        play(
            in, s,
            [&](Time now) {
              const MotionPolynomial c = motion(in, now);
              const double w0 = static_cast<double>(in.below(5)) / 2.0;
              const double g = static_cast<double>(in.below(3)) / 2.0;
              std::array<double, 3> lo{}, hi{};
              for (int k = 0; k <= c.degree; ++k) lo[k] = hi[k] = c.c[k];
              // Shift c to origin `now` is not needed: w is added in powers of (t - c.origin).
              const Time o = c.origin;
              // w(t) = w0 + g (t - now) = (w0 + g (o - now)) + g (t - o); keep w >= 0 for t >= now.
              const double w_at_o = w0 + g * (o - now);
              lo[0] -= w_at_o, hi[0] += w_at_o;
              lo[1] -= g, hi[1] += g;
              return std::vector<MotionPolynomial>{MotionPolynomial::from(lo, o),
                                                   MotionPolynomial::from(hi, o)};
            },
            [&] {
              const double x = static_cast<double>(in.small(8)) / 2.0;
              if (s.stab(x) != ids_of(s.motions(), oracle::stab_at(s.motions(), x, s.now())))
                fuzz::fail("segment tree: stab differs at t = " + std::to_string(s.now()));
            },
            true);
        break;
      }
    }
  } catch (const PreconditionError& e) {
    fuzz::fail(std::string("a precondition refused a correct use: ") + e.what());
  }
  return 0;
}
