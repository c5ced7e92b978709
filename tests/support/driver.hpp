#pragma once
// Test support: drives a KineticSort (one per axis) or a kinetic structure through a scenario's
// timeline the way the runner does, with hooks for oracle checks between events. Header-only,
// tests only.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "kinetic/core/float_roots.hpp"
#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/predicates.hpp"
#include "kinetic/core/simulator.hpp"
#include "kinetic/scenario/scenario.hpp"
#include "kinetic/sort/kinetic_sort.hpp"

namespace kinetic::testing {

inline std::vector<MotionPolynomial> polynomials(const scenario::Motion& m) {
  std::vector<MotionPolynomial> out;
  for (const auto& c : m.coordinates) out.push_back(MotionPolynomial::from(c, m.origin));
  return out;
}

/// True when a and b cross or touch somewhere in [lo, hi] (up to the rounding of floating-point
/// roots, widened by a tiny pad): exact signs at the ends, floating-point sign-change roots of
/// a - b inside, and the exact sign at the floating-point critical points (touches).
inline bool cross_within(const MotionPolynomial& a, const MotionPolynomial& b, Time lo, Time hi) {
  const int s_lo = compare_at(a, b, lo), s_hi = compare_at(a, b, hi);
  if (s_lo == 0 || s_hi == 0 || s_lo != s_hi) return true;
  std::array<double, kMaxMotionDegree + 1> d{};
  const int degree = float_difference(a, b, d);
  if (degree == 0) return false;
  std::array<FloatRoot, kMaxMotionDegree> roots{};
  const double pad = 1e-9 * (1.0 + std::abs(lo) + std::abs(hi));
  if (float_sign_change_roots(d, degree, lo - b.origin - pad, hi - b.origin + pad, roots) > 0)
    return true;
  if (degree < 2) return false;
  std::array<double, kMaxMotionDegree> deriv{};
  for (int i = 1; i <= degree; ++i) deriv[i - 1] = i * d[i];
  const int m = float_sign_change_roots(std::span<const double>(deriv.data(), degree), degree - 1,
                                        lo - b.origin, hi - b.origin, roots);
  for (int i = 0; i < m; ++i) {
    if (compare_at(a, b, b.origin + roots[i].at) != s_lo) return true;
  }
  return false;
}

/// A random closed box (per axis [lo, hi]) inside the points' bounding box at t: sometimes a
/// degenerate slab, sometimes everything, sometimes ending exactly on a point's coordinate.
inline std::vector<std::array<double, 2>> random_box(const MotionTable& motions, Time t,
                                                     std::mt19937_64& rng) {
  const int d = motions.dimension();
  std::vector<std::array<double, 2>> box(static_cast<std::size_t>(d));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto idx = motions.alive_indices();
  for (int a = 0; a < d; ++a) {
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const std::uint32_t i : idx) {
      const double x = motions.motion(i, a).evaluate(t);
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    if (!(lo <= hi)) lo = hi = 0.0;
    double x = lo + (hi - lo) * u(rng), y = lo + (hi - lo) * u(rng);
    if (x > y) std::swap(x, y);
    const int kind = static_cast<int>(rng() % 8);
    if (kind == 0) y = x;                       // a degenerate slab
    if (kind == 1) x = lo - 1.0, y = hi + 1.0;  // everything
    if (kind == 2 && !idx.empty()) {            // ends exactly on a point's coordinate
      x = motions.motion(idx[rng() % idx.size()], a).evaluate(t);
      y = std::max(x, y);
    }
    box[static_cast<std::size_t>(a)] = {x, y};
  }
  return box;
}

/// One kinetic structure over a motion table built from a scenario: the structure owns its
/// sorts and events (its constructor takes the table, the simulator and the scheduler) and
/// follows the timeline's inserts, removes and flight-plan updates as the runner does.
template <class Tree>
struct TreeHarness {
  TreeHarness(const scenario::Scenario& s, SchedulerKind kind, double eps)
      : motions(s.dimension),
        sim(s.start_time),
        scheduler(kind, eps, s.end_time.value_or(kTimeInfinity)) {
    for (const auto& o : s.objects) motions.insert(o.id, polynomials(o.motion), s.start_time);
    tree = std::make_unique<Tree>(motions, sim, scheduler);
    tree->initialize();
  }
  EventKind process(const Event& e) { return tree->process(e); }
  void apply(const scenario::TimelineOp& op) {
    switch (op.op) {
      case scenario::OpKind::Insert:
        tree->insert(motions.insert(op.id, polynomials(op.motion), op.time).index);
        break;
      case scenario::OpKind::Remove: {
        const ObjectHandle h = *motions.find(op.id);
        tree->remove(h.index);
        motions.remove(h);
        break;
      }
      case scenario::OpKind::Update: {
        const ObjectHandle h = *motions.find(op.id);
        motions.update(h, polynomials(op.motion), op.time);
        tree->motion_changed(h.index);
        break;
      }
      case scenario::OpKind::Query:
        break;
    }
    sim.note_external_change();
  }
  MotionTable motions;
  Simulator sim;
  Scheduler scheduler;
  std::unique_ptr<Tree> tree;
};

/// One kinetic sort per axis over a motion table built from a scenario.
struct SortHarness {
  explicit SortHarness(const scenario::Scenario& s, SchedulerKind kind = SchedulerKind::Classic,
                       double eps = 1e-9)
      : scenario(s),
        motions(s.dimension),
        sim(s.start_time),
        scheduler(kind, eps, s.end_time.value_or(kTimeInfinity)) {
    for (const auto& o : s.objects) motions.insert(o.id, polynomials(o.motion), s.start_time);
    for (int axis = 0; axis < s.dimension; ++axis) {
      sorts.push_back(std::make_unique<KineticSort>(motions, sim, scheduler, axis,
                                                    static_cast<std::uint32_t>(axis)));
    }
    for (auto& k : sorts) k->initialize();
  }
  EventKind process(const Event& e) { return sorts[e.owner]->process(e); }

  /// Advances to t; with `validate`, one event at a time with validate() after each.
  AdvanceOutcome advance_to(Time t, bool validate = false) {
    if (!validate) return sim.advance_to(t, *this);
    while (!sim.queue().empty() && sim.queue().top().time <= t) {
      const AdvanceOutcome o = sim.process_next(*this);
      if (o != AdvanceOutcome::Reached) return o;
      for (auto& k : sorts) EXPECT_TRUE(k->validate()) << "after an event at t=" << sim.now();
    }
    return sim.advance_to(t, *this);
  }

  void apply(const scenario::TimelineOp& op) {
    switch (op.op) {
      case scenario::OpKind::Insert: {
        const ObjectHandle h = motions.insert(op.id, polynomials(op.motion), op.time);
        for (auto& k : sorts) k->insert(h.index);
        last_change = op.time;
        break;
      }
      case scenario::OpKind::Remove: {
        const ObjectHandle h = *motions.find(op.id);
        for (auto& k : sorts) k->remove(h.index);
        motions.remove(h);
        break;
      }
      case scenario::OpKind::Update: {
        const ObjectHandle h = *motions.find(op.id);
        motions.update(h, polynomials(op.motion), op.time);
        for (auto& k : sorts) k->motion_changed(h.index);
        last_change = op.time;
        break;
      }
      case scenario::OpKind::Query:
        break;
    }
    sim.note_external_change();
  }

  /// Every adjacent pair that is out of order at t must cross within [t - delta, t + delta]
  /// (a time away from every crossing therefore has the exact sorted order).
  ::testing::AssertionResult order_ok_at(Time t, double delta) const {
    for (const auto& k : sorts) {
      const auto order = k->order();
      if (order.size() != motions.size()) return ::testing::AssertionFailure() << "size mismatch";
      for (std::size_t j = 0; j + 1 < order.size(); ++j) {
        const auto& a = motions.motion(order[j], k->axis());
        const auto& b = motions.motion(order[j + 1], k->axis());
        if (compare_at(a, b, t) <= 0) continue;
        if (cross_within(a, b, t - delta, t + delta)) continue;
        return ::testing::AssertionFailure()
               << "axis " << k->axis() << ": ids " << motions.id(order[j]) << " > "
               << motions.id(order[j + 1]) << " at position " << j << ", t=" << t
               << " and they do not cross within " << delta;
      }
    }
    return ::testing::AssertionSuccess();
  }

  const scenario::Scenario& scenario;
  MotionTable motions;
  Simulator sim;
  Scheduler scheduler;
  std::vector<std::unique_ptr<KineticSort>> sorts;
  Time last_change = kTimeMinusInfinity;
};

}  // namespace kinetic::testing
