#pragma once
// The kinetic-sorting experiment's error meter (internal to the experiments; tested on its own).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "kinetic/core/motion_table.hpp"
#include "kinetic/core/predicates.hpp"

namespace kinetic::experiment::detail {

/// err(t) = max_k |y_k(t) - z_k(t)| (Abam, Agarwal, de Berg, Yu, Section 6): y the maintained
/// order's values, z the same values sorted, both in floating point, as the paper computes them.
/// With w_k the value of the k-th key of the maintained order, z = sort(w), and z_k = w_k outside
/// the *blocks*: the shortest runs [l, r] of positions around w's descents (w_k > w_k+1) such that
/// everything before a block is at most its smallest value and everything after it at least its
/// largest. Sorting each block alone therefore gives sort(w) there, and err is the largest
/// |w_k - z_k| over the blocks: the same doubles as sorting all n values.
///
/// A descent whose pair is in order exactly (nearly equal values rounded the other way) is
/// rounding, not error: when every descent is one, err is 0. A pair whose values round to the
/// same double adds 0 to err whichever its exact order, and is not decided.
///
/// One pass evaluates every value (Horner on a flat copy of the motions, the same arithmetic as
/// MotionPolynomial::evaluate) and one more reads w and finds the descents. A robust run's order is
/// sorted but at the few pairs that crossed since their events were processed: its blocks are short
/// and cost their own size. A classic run's order drifts far from sorted and its blocks span nearly
/// everything: then the sorted order of the previous sample is re-sorted by insertion, O(n +
/// crossings since).
class ErrorMeter {
 public:
  explicit ErrorMeter(const MotionTable& motions) : motions_(motions) {}

  double error(std::span<const std::uint32_t> order, Time t) {
    copy_motions();
    evaluate_all(t);
    const std::size_t n = order.size();
    w_.resize(n);
    not_below_.resize(n);
    descents_.resize(n);
    std::size_t not_below = 0, descents = 0;
    {
      // Local pointers: the stores below would otherwise reload every vector's data each time.
      const double* values = values_.data();
      double* w = w_.data();
      std::size_t* nb = not_below_.data();
      std::size_t* de = descents_.data();
      double prev = n > 0 ? values[order[0]] : 0.0;
      if (n > 0) w[0] = prev;
      for (std::size_t k = 1; k < n; ++k) {
        const double v = values[order[k]];
        w[k] = v;
        // Branch-free: ties are many (GRIDS) and come in no pattern.
        nb[not_below] = k - 1;
        de[descents] = k - 1;
        not_below += static_cast<std::size_t>(!(prev < v));
        descents += static_cast<std::size_t>(prev > v);
        prev = v;
      }
    }
    not_below_.resize(not_below);
    descents_.resize(descents);
    if (descents_.empty()) {  // w sorted: z = w
      true_order_fresh_ = false;
      return 0.0;
    }
    double err = 0.0;
    const std::vector<Block>& blocks = find_blocks();
    std::size_t covered = 0;
    for (const Block& b : blocks) covered += b.r - b.l + 1;
    if (covered * 8 <= n) {
      for (const Block& b : blocks) {
        block_.assign(w_.begin() + static_cast<std::ptrdiff_t>(b.l),
                      w_.begin() + static_cast<std::ptrdiff_t>(b.r) + 1);
        std::sort(block_.begin(), block_.end());
        for (std::size_t k = b.l; k <= b.r; ++k) {
          err = std::max(err, std::fabs(w_[k] - block_[k - b.l]));
        }
      }
      true_order_fresh_ = false;
    } else {
      err = error_by_insertion(order);
    }
    if (err > 0.0 && descents_are_rounding(order, t)) err = 0.0;
    return err;
  }

  /// The positions k of the last error()'s order whose values are not strictly increasing
  /// (w_k >= w_k+1), ascending: every other adjacent pair is certainly in order.
  [[nodiscard]] std::span<const std::size_t> not_below() const { return not_below_; }

 private:
  struct Block {
    std::size_t l, r;
    double lo, hi;  ///< the smallest and largest value in w[l..r]
  };

  /// The motions along the sorting axis, flat: stride max_degree + 1 coefficients per index.
  void copy_motions() {
    if (copied_version_ == motions_.version() && !origin_.empty()) return;
    copied_version_ = motions_.version();
    const std::size_t cap = motions_.capacity();
    const std::size_t terms = static_cast<std::size_t>(motions_.max_degree()) + 1;
    coef_.assign(cap * terms, 0.0);
    origin_.assign(cap, 0.0);
    degree_.assign(cap, 0);
    values_.assign(cap, 0.0);
    uniform_degree_ = -2;  // none seen yet
    for (const std::uint32_t i : motions_.alive_indices()) {
      const MotionPolynomial& p = motions_.motion(i, 0);
      origin_[i] = p.origin;
      degree_[i] = p.degree;
      for (int j = 0; j <= p.degree; ++j) coef_[static_cast<std::size_t>(j) * cap + i] = p.c[j];
      uniform_degree_ = uniform_degree_ == -2 || uniform_degree_ == p.degree ? p.degree : -1;
    }
    // A free index evaluates to 0 (its coefficients are 0) and is never read; the per-index
    // loop handles mixed degrees.
    if (uniform_degree_ < 0 || uniform_degree_ > 2) uniform_degree_ = -1;
    true_order_.clear();
    true_order_fresh_ = false;
  }

  /// Every value at t by MotionPolynomial::evaluate's Horner, operation for operation, by
  /// index: one pass over the coefficients, without a branch when all degrees are equal.
  void evaluate_all(Time t) {
    const std::size_t cap = origin_.size();
    const double* o = origin_.data();
    const double* c = coef_.data();
    double* out = values_.data();
    switch (uniform_degree_) {
      case 0:
        for (std::size_t i = 0; i < cap; ++i) out[i] = c[i];
        break;
      case 1:
        for (std::size_t i = 0; i < cap; ++i) out[i] = c[cap + i] * (t - o[i]) + c[i];
        break;
      case 2:
        for (std::size_t i = 0; i < cap; ++i) {
          const double u = t - o[i];
          out[i] = (c[2 * cap + i] * u + c[cap + i]) * u + c[i];
        }
        break;
      default:
        for (std::size_t i = 0; i < cap; ++i) {
          const double u = t - o[i];
          double v = c[static_cast<std::size_t>(degree_[i]) * cap + i];
          for (int j = degree_[i] - 1; j >= 0; --j)
            v = v * u + c[static_cast<std::size_t>(j) * cap + i];
          out[i] = v;
        }
    }
  }

  /// err from the whole sorted order: the previous sample's when it was kept (nearly sorted
  /// still), else the maintained order's, re-sorted by insertion.
  double error_by_insertion(std::span<const std::uint32_t> order) {
    const std::size_t n = order.size();
    if (!true_order_fresh_ || true_order_.size() != n)
      true_order_.assign(order.begin(), order.end());
    for (std::size_t k = 1; k < n; ++k) {
      const std::uint32_t x = true_order_[k];
      const double v = values_[x];
      std::size_t j = k;
      while (j > 0 && values_[true_order_[j - 1]] > v) {
        true_order_[j] = true_order_[j - 1];
        --j;
      }
      true_order_[j] = x;
    }
    true_order_fresh_ = true;
    return largest_difference(w_.data(), values_.data(), true_order_.data(), n);
  }

  /// max_k |w[k] - values[z[k]]|, two running maxima (max is exact: the same double).
  static double largest_difference(const double* w, const double* values, const std::uint32_t* z,
                                   std::size_t n) {
    double e0 = 0.0, e1 = 0.0;
    std::size_t k = 0;
    for (; k + 1 < n; k += 2) {
      e0 = std::max(e0, std::fabs(w[k] - values[z[k]]));
      e1 = std::max(e1, std::fabs(w[k + 1] - values[z[k + 1]]));
    }
    if (k < n) e0 = std::max(e0, std::fabs(w[k] - values[z[k]]));
    return std::max(e0, e1);
  }

  /// The blocks of w around its descents, left to right (see the class comment).
  const std::vector<Block>& find_blocks() {
    blocks_.clear();
    const std::size_t n = w_.size();
    for (const std::size_t d : descents_) {
      if (!blocks_.empty() && d <= blocks_.back().r) continue;  // already inside the last block
      Block b{d, d + 1, std::min(w_[d], w_[d + 1]), std::max(w_[d], w_[d + 1])};
      for (bool grew = true; grew;) {
        grew = false;
        // Left: what comes before is at most lo (the previous block's largest value when it
        // ends right before; otherwise w is non-decreasing up to l - 1).
        while (b.l > 0) {
          if (!blocks_.empty() && blocks_.back().r == b.l - 1) {
            const Block p = blocks_.back();
            if (!(p.hi > b.lo)) break;
            blocks_.pop_back();
            b = {p.l, b.r, std::min(p.lo, b.lo), std::max(p.hi, b.hi)};
            grew = true;
          } else if (w_[b.l - 1] > b.lo) {
            --b.l;
            b.hi = std::max(b.hi, w_[b.l]);
            grew = true;
          } else {
            break;
          }
        }
        // Right: what comes after is at least hi (later descents make blocks that merge back).
        while (b.r + 1 < n && w_[b.r + 1] < b.hi) {
          ++b.r;
          b.lo = std::min(b.lo, w_[b.r]);
          grew = true;
        }
      }
      blocks_.push_back(b);
    }
    return blocks_;
  }

  /// Every descent of w is a pair in order at t exactly (see the class comment).
  [[nodiscard]] bool descents_are_rounding(std::span<const std::uint32_t> order, Time t) const {
    for (const std::size_t k : descents_) {
      if (compare_at(motions_.motion(order[k], 0), motions_.motion(order[k + 1], 0), t) > 0)
        return false;
    }
    return true;
  }

  const MotionTable& motions_;
  std::uint64_t copied_version_ = 0;
  std::vector<double> coef_;  ///< coefficient j of index i at j * capacity + i
  std::vector<double> origin_;
  std::vector<int> degree_;
  int uniform_degree_ = -1;     ///< every live motion's degree when they agree and it is <= 2
  std::vector<double> values_;  ///< by index, at the last error()'s time
  std::vector<std::uint32_t> true_order_;
  bool true_order_fresh_ = false;  ///< true_order_ is the previous sample's sorted order
  std::vector<double> w_, block_;
  std::vector<std::size_t> not_below_, descents_;
  std::vector<Block> blocks_;
};

}  // namespace kinetic::experiment::detail
