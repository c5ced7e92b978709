#pragma once
// The k nearest points to a query point q, exactly, from enclosures of their distances: the part
// of every k_nearest query that does not depend on the structure (the kinetic kd-tree, the
// longest-side kd-tree, the Delaunay triangulation). A structure walks its regions, offers each
// point it meets with an enclosure [lo, hi] of the point's distance to q (floating point, a
// rigorous bound), and skips a region whose lower bound on the distance to q is above
// prune_above(); finish() then orders the candidates by (distance, id) with exact comparisons
// where the enclosures overlap, and keeps k.
//
// Why the answer is exact (eps = 0). W, the k-th smallest upper bound offered so far, only
// decreases, and is at least the true k-th nearest distance r_k (k offered points are within
// W). A point of the answer is at distance <= r_k <= W: its region's lower bound is <= W (so it
// is not skipped) and its own lower bound too (so it is kept). Ties at r_k are kept as well (both
// comparisons are strict), and finish() breaks them by id.
// With eps > 0 a region is skipped when (1 + eps) times its lower bound exceeds W (Arya and
// Mount's approximate search): a true i-th nearest point skipped that way is farther than
// W / (1 + eps) >= r'_k / (1 + eps) >= r'_i / (1 + eps), r'_i the i-th reported distance, so
// every reported distance is within (1 + eps) of the true one of its rank.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "kinetic/core/motion_table.hpp"

namespace kinetic {

class NearestCandidates {
 public:
  /// A new query for the k nearest with the approximation factor 1 + eps (eps >= 0, finite).
  void reset(std::size_t k, double eps) {
    k_ = k;
    stretch_ = 1.0 + eps;
    worst_.clear();
    candidates_.clear();
    limit_ = k == 0 ? -1.0 : kInf;
  }
  /// A region whose points are all at distance >= lower from q holds none of the answer when
  /// lower > prune_above() (eps = 0: W itself; +infinity until k points are offered; below 0
  /// for k = 0).
  [[nodiscard]] double prune_above() const { return limit_; }
  /// The same test on squared distances: a region holds none of the answer when its squared
  /// lower bound (a sum of squares rounded to nearest, at most 2^-40 relatively above the true
  /// one) is above this.
  [[nodiscard]] double prune_above_squared() const {
    return limit_ < 0.0 ? -1.0 : limit_ * limit_ * (1.0 + 0x1p-38);
  }
  /// Point `point` is at a distance in [lo, hi] from q.
  void offer(std::uint32_t point, double lo, double hi) {
    if (k_ == 0) return;
    if (worst_.size() < k_) {
      worst_.push_back(hi);
      std::push_heap(worst_.begin(), worst_.end());
    } else if (hi < worst_.front()) {
      std::pop_heap(worst_.begin(), worst_.end());
      worst_.back() = hi;
      std::push_heap(worst_.begin(), worst_.end());
    }
    const double w = worst_.size() < k_ ? kInf : worst_.front();
    if (lo <= w) candidates_.push_back(Candidate{lo, hi, point});
    // (1 + eps) * lower > W  <=>  lower > W / (1 + eps); the quotient rounded down stays
    // conservative for the strict test only when eps = 0, where it is W itself.
    limit_ = stretch_ == 1.0 ? w : w / stretch_ * (1.0 - 0x1p-52);
  }
  /// The k nearest candidates (all when fewer), by increasing distance, equal distances by id,
  /// into `out`. `compare(a, b)` is sign(|a - q| - |b - q|), exactly; `id(a)` is a's id.
  template <class Compare, class Id>
  void finish(const Compare& compare, const Id& id, std::vector<std::uint32_t>& out) {
    out.clear();
    if (k_ == 0) return;
    const double w = worst_.size() < k_ ? kInf : worst_.front();
    std::erase_if(candidates_, [&](const Candidate& c) { return !(c.lo <= w); });
    std::sort(candidates_.begin(), candidates_.end(), [&](const Candidate& a, const Candidate& b) {
      if (a.hi < b.lo) return true;
      if (b.hi < a.lo) return false;
      if (a.point == b.point) return false;
      const int s = compare(a.point, b.point);
      return s < 0 || (s == 0 && id(a.point) < id(b.point));
    });
    const std::size_t count = std::min(k_, candidates_.size());
    out.reserve(count);
    for (std::size_t j = 0; j < count; ++j) out.push_back(candidates_[j].point);
  }
  /// finish() for objects of a table, by their exact distances to q at t
  /// (compare_object_distances) and their ids.
  void finish(const MotionTable& table, std::span<const double> q, Time t,
              std::vector<std::uint32_t>& out) {
    finish([&](std::uint32_t a,
               std::uint32_t b) { return compare_object_distances(table, a, b, q, t); },
           [&](std::uint32_t a) { return table.id(a); }, out);
  }
  /// sign(|a(t) - q| - |b(t) - q|) for the table's objects a and b (indices), exactly:
  /// compare_distances_at() over their coordinates. q has the table's dimension.
  [[nodiscard]] static int compare_object_distances(const MotionTable& table, std::uint32_t a,
                                                    std::uint32_t b, std::span<const double> q,
                                                    Time t);
  /// Candidates kept so far (for counters).
  [[nodiscard]] std::size_t candidates() const { return candidates_.size(); }

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  struct Candidate {
    double lo, hi;
    std::uint32_t point;
  };
  std::size_t k_ = 0;
  double stretch_ = 1.0;
  double limit_ = kInf;
  std::vector<double> worst_;  // max-heap of the k smallest upper bounds
  std::vector<Candidate> candidates_;
};

}  // namespace kinetic
