#include "kinetic/oracle/oracle.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

#include "core/numeric/interval.hpp"
#include "kinetic/core/boxes.hpp"
#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/incircle.hpp"
#include "kinetic/core/k_nearest.hpp"
#include "kinetic/core/predicates.hpp"

namespace kinetic::oracle {

std::vector<std::uint32_t> sorted_at(const MotionTable& motions, int axis, Time t) {
  std::vector<std::uint32_t> order = motions.alive_indices();
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const int s = compare_after(motions.motion(a, axis), motions.motion(b, axis), t);
    if (s != 0) return s < 0;
    return motions.id(a) < motions.id(b);
  });
  return order;
}

bool is_sorted_at(const MotionTable& motions, std::span<const std::uint32_t> order, int axis,
                  Time t) {
  if (order.size() != motions.size()) return false;
  for (std::size_t j = 0; j + 1 < order.size(); ++j) {
    if (compare_at(motions.motion(order[j], axis), motions.motion(order[j + 1], axis), t) > 0) {
      return false;
    }
  }
  return true;
}

namespace {
std::uint32_t extreme_at(const MotionTable& motions, int axis, Time t, int want) {
  const std::vector<std::uint32_t> alive = motions.alive_indices();
  assert(!alive.empty());
  std::uint32_t best = alive.front();
  for (std::uint32_t i : alive) {
    const int s = compare_at(motions.motion(i, axis), motions.motion(best, axis), t);
    if (s == want || (s == 0 && motions.id(i) < motions.id(best))) best = i;
  }
  return best;
}
}  // namespace

std::uint32_t max_at(const MotionTable& motions, int axis, Time t) {
  return extreme_at(motions, axis, t, 1);
}
std::uint32_t min_at(const MotionTable& motions, int axis, Time t) {
  return extreme_at(motions, axis, t, -1);
}

double sorting_error(const MotionTable& motions, std::span<const std::uint32_t> order, int axis,
                     Time t) {
  const std::vector<std::uint32_t> truth = sorted_at(motions, axis, t);
  assert(truth.size() == order.size());
  double err = 0.0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (order[i] == truth[i]) continue;
    const double d = std::fabs(value_at(motions.motion(order[i], axis), t) -
                               value_at(motions.motion(truth[i], axis), t));
    err = std::max(err, d);
  }
  return err;
}

std::vector<std::uint32_t> in_box_at(const MotionTable& motions,
                                     std::span<const std::array<double, 2>> box, Time t) {
  std::vector<std::uint32_t> out;
  // sign(p(t) - side): a side at -infinity or +infinity is compared as such (a finite
  // coordinate is above the one, below the other), not as a constant motion, whose value at t
  // would not be a number.
  const auto versus = [t](const MotionPolynomial& p, double side) {
    if (std::isinf(side)) return side < 0.0 ? 1 : -1;
    return compare_at(p, MotionPolynomial::constant(side), t);
  };
  for (const std::uint32_t i : motions.alive_indices()) {
    bool inside = true;
    for (int a = 0; a < motions.dimension() && inside; ++a) {
      const MotionPolynomial& p = motions.motion(i, a);
      const auto& b = box[static_cast<std::size_t>(a)];
      inside = versus(p, b[0]) >= 0 && versus(p, b[1]) <= 0;
    }
    if (inside) out.push_back(i);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::uint32_t> stab_at(const MotionTable& intervals, double x, Time t) {
  const MotionPolynomial q = MotionPolynomial::constant(x);
  std::vector<std::uint32_t> out;
  for (const std::uint32_t i : intervals.alive_indices()) {
    if (compare_at(intervals.motion(i, 0), q, t) <= 0 &&
        compare_at(intervals.motion(i, 1), q, t) >= 0)
      out.push_back(i);
  }
  return out;  // alive_indices() is ascending
}

namespace {

/// The exact sign of high(y) - low(x) on `axis` at t (>= 0: x's low side is not above y's high).
int gap_sign(const MotionTable& boxes, std::uint32_t x, std::uint32_t y, int axis, Time t) {
  return -compare_sides_at(boxes, x, BoxSide::Low, y, BoxSide::High, axis, t);
}

/// Brackets of the sign changes of high(y) - low(x) on `axis` in (from, to).
void side_crossings(const MotionTable& boxes, std::uint32_t x, std::uint32_t y, int axis, Time from,
                    Time to, double tolerance, std::vector<TimeBracket>& out) {
  std::array<double, kMaxMotionDegree + 1> d{};
  const MotionPolynomial& cy = center(boxes, y, axis);
  int degree = float_difference(cy, center(boxes, x, axis), d);
  d[0] += half_extent(boxes, x, axis).c[0] + half_extent(boxes, y, axis).c[0];  // a guess only
  while (degree > 0 && d[static_cast<std::size_t>(degree)] == 0.0) --degree;
  if (degree == 0) return;
  const Time origin = center(boxes, x, axis).origin;
  std::array<FloatRoot, kMaxMotionDegree> roots{};
  const int m = float_sign_change_roots(d, degree, from - origin, to - origin, roots);
  for (int i = 0; i < m; ++i) {
    const Time r = origin + roots[static_cast<std::size_t>(i)].at;
    // Widen until the exact signs at the two ends differ (a guessed root is near an exact one).
    double w = 1e-12 * (1.0 + std::abs(r));
    Time lo = r, hi = r;
    int s_lo = 0, s_hi = 0;
    for (; w < 1e-3 * (1.0 + std::abs(r)); w *= 4) {
      lo = std::max(from, r - w);
      hi = std::min(to, r + w);
      s_lo = gap_sign(boxes, x, y, axis, lo);
      s_hi = gap_sign(boxes, x, y, axis, hi);
      if (s_lo != 0 && s_hi != 0 && s_lo != s_hi) break;
    }
    if (s_lo == 0 || s_hi == 0 || s_lo == s_hi) continue;  // a touch, not a crossing
    while (hi - lo > tolerance) {
      const Time mid = lo + (hi - lo) / 2;
      if (mid <= lo || mid >= hi) break;
      const int s = gap_sign(boxes, x, y, axis, mid);
      if (s == 0) {
        lo = hi = mid;  // the exact root
      } else if (s == s_lo) {
        lo = mid;
      } else {
        hi = mid;
      }
    }
    out.push_back({lo, hi});
  }
}

}  // namespace

std::vector<ContactInterval> contact_intervals(const MotionTable& boxes, std::uint32_t a,
                                               std::uint32_t b, Time from, Time to,
                                               double tolerance) {
  std::vector<TimeBracket> crossings;
  for (int axis = 0; axis < box_dimension(boxes); ++axis) {
    side_crossings(boxes, a, b, axis, from, to, tolerance, crossings);
    side_crossings(boxes, b, a, axis, from, to, tolerance, crossings);
  }
  std::sort(crossings.begin(), crossings.end(),
            [](const TimeBracket& x, const TimeBracket& y) { return x.lo < y.lo; });
  std::vector<TimeBracket> merged;  // overlapping brackets as one
  for (const TimeBracket& c : crossings) {
    if (!merged.empty() && c.lo <= merged.back().hi) {
      merged.back().hi = std::max(merged.back().hi, c.hi);
    } else {
      merged.push_back(c);
    }
  }
  // The open sections between crossings have a constant contact status: test it at one time.
  std::vector<ContactInterval> out;
  bool open = false;
  TimeBracket begin{from, from};
  Time section_lo = from;
  for (std::size_t k = 0; k <= merged.size(); ++k) {
    const Time section_hi = k < merged.size() ? merged[k].lo : to;
    if (section_lo < section_hi) {
      const bool in_contact =
          boxes_overlap_at(boxes, a, b, section_lo + (section_hi - section_lo) / 2);
      if (in_contact && !open) {
        begin = k == 0 ? TimeBracket{from, from} : merged[k - 1];
        open = true;
      } else if (!in_contact && open) {
        out.push_back({begin, merged[k - 1]});
        open = false;
      }
    }
    if (k < merged.size()) section_lo = merged[k].hi;
  }
  if (open) out.push_back({begin, {to, to}});
  return out;
}

std::vector<double> position_at(const MotionTable& motions, std::uint32_t index, Time t) {
  std::vector<double> x;
  for (int a = 0; a < motions.dimension(); ++a) x.push_back(value_at(motions.motion(index, a), t));
  return x;
}

double distance_at(const MotionTable& motions, std::uint32_t index, std::span<const double> q,
                   Time t) {
  std::vector<const MotionPolynomial*> point;
  for (int a = 0; a < motions.dimension(); ++a) point.push_back(&motions.motion(index, a));
  return point_distance_at(point, q, t);
}

namespace {

/// The smallest (nearest) or largest (farthest) distance_at() over the live objects. Each
/// object's squared distance is first enclosed in an interval (filtered evaluation, outward
/// rounding); only the objects whose interval can hold the extreme are evaluated exactly. The
/// object at the exact extreme is always among them, and distance_at() is the exact distance
/// rounded toward zero, a non-decreasing function of the squared distance: the result is the
/// same double as evaluating every object exactly.
double extreme_distance_at(const MotionTable& motions, std::span<const double> q, Time t,
                           bool nearest) {
  assert(motions.size() > 0);
  const std::vector<std::uint32_t> idx = motions.alive_indices();
  std::vector<numeric::Interval> squared(idx.size());
  // nearest: the smallest upper end bounds the smallest squared distance from above; farthest:
  // the largest lower end bounds the largest from below (a NaN end is skipped by min / max).
  double bound = nearest ? HUGE_VAL : 0.0;
  for (std::size_t k = 0; k < idx.size(); ++k) {
    numeric::Interval s = numeric::Interval::point(0.0);
    for (int a = 0; a < motions.dimension(); ++a) {
      const FilteredValue v = evaluate_filtered(motions.motion(idx[k], a), t);
      const numeric::Interval d = numeric::around(v.value, v.error) -
                                  numeric::Interval::point(q[static_cast<std::size_t>(a)]);
      numeric::Interval d2 = d * d;
      d2.lo = std::max(d2.lo, 0.0);  // a square is >= 0
      s = s + d2;
    }
    squared[k] = s;
    bound = nearest ? std::min(bound, s.hi) : std::max(bound, s.lo);
  }
  double best = nearest ? HUGE_VAL : 0.0;
  for (std::size_t k = 0; k < idx.size(); ++k) {
    // Written so that an interval with a NaN end stays a candidate.
    const bool candidate = nearest ? !(squared[k].lo > bound) : !(squared[k].hi < bound);
    if (!candidate) continue;
    const double d = distance_at(motions, idx[k], q, t);
    best = nearest ? std::min(best, d) : std::max(best, d);
  }
  return best;
}

}  // namespace

double nearest_distance_at(const MotionTable& motions, std::span<const double> q, Time t) {
  return extreme_distance_at(motions, q, t, true);
}

double farthest_distance_at(const MotionTable& motions, std::span<const double> q, Time t) {
  return extreme_distance_at(motions, q, t, false);
}

double signed_distance_to_disk(std::array<double, 2> x, std::array<double, 2> center,
                               double radius) {
  return std::hypot(x[0] - center[0], x[1] - center[1]) - radius;
}

double signed_distance_to_polygon(std::array<double, 2> x,
                                  std::span<const std::array<double, 2>> polygon) {
  // Distance to the boundary (closest point on each edge), negative when x is inside by the
  // even-odd rule.
  double best = HUGE_VAL;
  bool inside = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const auto& a = polygon[j];
    const auto& b = polygon[i];
    if ((a[1] > x[1]) != (b[1] > x[1])) {
      const double cross = a[0] + (x[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
      if (x[0] < cross) inside = !inside;
    }
    const double ex = b[0] - a[0], ey = b[1] - a[1];
    const double len2 = ex * ex + ey * ey;
    const double u =
        len2 > 0.0 ? std::clamp(((x[0] - a[0]) * ex + (x[1] - a[1]) * ey) / len2, 0.0, 1.0) : 0.0;
    best = std::min(best, std::hypot(x[0] - (a[0] + u * ex), x[1] - (a[1] + u * ey)));
  }
  return inside ? -best : best;
}

namespace {
/// The exact value of p(t) as a rational.
mpq_class exact_value(const MotionPolynomial& p, Time t) {
  const mpq_class s = mpq_class(t) - mpq_class(p.origin);
  mpq_class v = p.c[static_cast<std::size_t>(p.degree)];
  for (int i = p.degree - 1; i >= 0; --i) v = v * s + mpq_class(p.c[static_cast<std::size_t>(i)]);
  return v;
}
}  // namespace

std::vector<std::uint32_t> hull_of_at(const MotionTable& points,
                                      std::span<const std::uint32_t> subset, Time t) {
  struct P {
    mpq_class x, y;
    std::uint32_t index;
    ObjectId id;
  };
  std::vector<P> p;
  p.reserve(subset.size());
  for (const std::uint32_t i : subset)
    p.push_back({exact_value(points.motion(i, 0), t), exact_value(points.motion(i, 1), t), i,
                 points.id(i)});
  std::sort(p.begin(), p.end(), [](const P& a, const P& b) {
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    return a.id < b.id;
  });
  // Coincident points: the smallest id stays (the first of its group).
  std::vector<P> u;
  for (P& q : p) {
    if (!u.empty() && u.back().x == q.x && u.back().y == q.y) continue;
    u.push_back(std::move(q));
  }
  if (u.size() <= 2) {
    std::vector<std::uint32_t> out;
    for (const P& q : u) out.push_back(q.index);
    // Counter-clockwise from the lowest-then-leftmost.
    if (out.size() == 2 && (u[1].y < u[0].y)) std::swap(out[0], out[1]);
    return out;
  }
  auto cross = [](const P& o, const P& a, const P& b) {
    return sgn(mpq_class((a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)));
  };
  // Andrew's monotone chain: lower hull left to right, then upper hull right to left; a turn
  // that is not strictly counter-clockwise pops (collinear points are not vertices).
  std::vector<std::size_t> h(2 * u.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < u.size(); ++i) {
    while (k >= 2 && cross(u[h[k - 2]], u[h[k - 1]], u[i]) <= 0) --k;
    h[k++] = i;
  }
  for (std::size_t i = u.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(u[h[k - 2]], u[h[k - 1]], u[i]) <= 0) --k;
    h[k++] = i;
  }
  --k;  // the first point is repeated at the end
  std::vector<std::uint32_t> out;
  std::size_t start = 0;
  for (std::size_t j = 1; j < k; ++j) {
    const P& a = u[h[j]];
    const P& b = u[h[start]];
    if (a.y < b.y || (a.y == b.y && a.x < b.x)) start = j;
  }
  for (std::size_t j = 0; j < k; ++j) out.push_back(u[h[(start + j) % k]].index);
  return out;
}

std::vector<std::uint32_t> hull_at(const MotionTable& points, Time t) {
  const std::vector<std::uint32_t> all = points.alive_indices();
  return hull_of_at(points, all, t);
}

std::vector<std::array<std::uint32_t, 2>> colliding_pairs_at(const MotionTable& boxes, Time t) {
  const int d = box_dimension(boxes);
  std::vector<std::uint32_t> alive = boxes.alive_indices();
  std::sort(alive.begin(), alive.end(),
            [&](std::uint32_t a, std::uint32_t b) { return boxes.id(a) < boxes.id(b); });
  // Exact centers and half extents at t, per box and axis.
  std::vector<mpq_class> c(alive.size() * static_cast<std::size_t>(d));
  std::vector<mpq_class> h(c.size());
  for (std::size_t i = 0; i < alive.size(); ++i) {
    for (int k = 0; k < d; ++k) {
      const std::size_t at = i * static_cast<std::size_t>(d) + static_cast<std::size_t>(k);
      c[at] = exact_value(center(boxes, alive[i], k), t);
      h[at] = exact_value(half_extent(boxes, alive[i], k), t);
    }
  }
  std::vector<std::array<std::uint32_t, 2>> out;
  mpq_class gap;
  for (std::size_t i = 0; i < alive.size(); ++i) {
    for (std::size_t j = i + 1; j < alive.size(); ++j) {
      bool overlap = true;
      for (int k = 0; k < d && overlap; ++k) {
        const std::size_t a = i * static_cast<std::size_t>(d) + static_cast<std::size_t>(k);
        const std::size_t b = j * static_cast<std::size_t>(d) + static_cast<std::size_t>(k);
        gap = abs(c[a] - c[b]) - h[a] - h[b];
        overlap = sgn(gap) <= 0;
      }
      if (overlap) out.push_back({alive[i], alive[j]});
    }
  }
  return out;
}

namespace {

int orient_after(const MotionTable& m, std::uint32_t a, std::uint32_t b, std::uint32_t c, Time t) {
  return sign_after(orientation(m, a, b, c), t);
}

bool identical(const MotionTable& m, std::uint32_t a, std::uint32_t b, Time t) {
  return compare_after(m.motion(a, 0), m.motion(b, 0), t) == 0 &&
         compare_after(m.motion(a, 1), m.motion(b, 1), t) == 0;
}

}  // namespace

std::vector<std::array<std::uint32_t, 3>> delaunay_at(const MotionTable& points, Time t) {
  // The points taking part: of identical motions, the smallest id.
  std::vector<std::uint32_t> all = points.alive_indices();
  std::sort(all.begin(), all.end(),
            [&](std::uint32_t a, std::uint32_t b) { return points.id(a) < points.id(b); });
  std::vector<std::uint32_t> p;
  for (const std::uint32_t i : all) {
    bool copy = false;
    for (const std::uint32_t j : p) copy = copy || identical(points, i, j, t);
    if (!copy) p.push_back(i);
  }
  std::vector<std::array<std::uint32_t, 3>> out;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      for (std::size_t k = j + 1; k < n; ++k) {
        std::uint32_t a = p[i], b = p[j], c = p[k];  // a has the smallest id
        const int o = orient_after(points, a, b, c, t);
        if (o == 0) continue;
        if (o < 0) std::swap(b, c);
        bool empty = true;
        for (std::size_t l = 0; l < n && empty; ++l) {
          const std::uint32_t d = p[l];
          if (d == a || d == b || d == c) continue;
          const InCircle f{{moving_point(points, a), moving_point(points, b),
                            moving_point(points, c), moving_point(points, d)}};
          empty = perturbed_sign_after(f, {points.id(a), points.id(b), points.id(c), points.id(d)},
                                       t) < 0;
        }
        if (empty) out.push_back({a, b, c});
      }
    }
  }
  std::sort(out.begin(), out.end(), [&](const auto& x, const auto& y) {
    for (int i = 0; i < 3; ++i) {
      if (x[i] != y[i]) return points.id(x[i]) < points.id(y[i]);
    }
    return false;
  });
  return out;
}

std::optional<std::array<std::uint32_t, 2>> closest_pair_at(const MotionTable& points, Time t) {
  std::vector<std::uint32_t> p = points.alive_indices();
  std::sort(p.begin(), p.end(),
            [&](std::uint32_t a, std::uint32_t b) { return points.id(a) < points.id(b); });
  std::optional<std::array<std::uint32_t, 2>> best;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      // Pairs come in ascending (id, id) order: a tie keeps the first.
      if (!best || compare_squared_distances_at(
                       moving_point(points, p[i]), moving_point(points, p[j]),
                       moving_point(points, (*best)[0]), moving_point(points, (*best)[1]), t) < 0)
        best = std::array<std::uint32_t, 2>{p[i], p[j]};
    }
  }
  return best;
}

std::optional<std::uint32_t> exact_nearest_at(const MotionTable& points, std::array<double, 2> q,
                                              Time t) {
  const MotionPolynomial qx = MotionPolynomial::from({q[0]}), qy = MotionPolynomial::from({q[1]});
  const MovingPoint2 at{&qx, &qy};
  std::optional<std::uint32_t> best;
  for (const std::uint32_t i : points.alive_indices()) {
    if (!best) {
      best = i;
      continue;
    }
    const int s = compare_squared_distances_at(moving_point(points, i), at,
                                               moving_point(points, *best), at, t);
    if (s < 0 || (s == 0 && points.id(i) < points.id(*best))) best = i;
  }
  return best;
}

std::vector<std::uint32_t> k_nearest_at(const MotionTable& points, std::span<const double> q,
                                        std::size_t k, Time t) {
  std::vector<std::uint32_t> all = points.alive_indices();
  std::sort(all.begin(), all.end(), [&](std::uint32_t a, std::uint32_t b) {
    if (a == b) return false;
    const int s = NearestCandidates::compare_object_distances(points, a, b, q, t);
    return s < 0 || (s == 0 && points.id(a) < points.id(b));
  });
  if (all.size() > k) all.resize(k);
  return all;
}

}  // namespace kinetic::oracle
