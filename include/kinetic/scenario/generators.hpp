#pragma once
// Synthetic datasets: the four inputs of the seed paper's experiments (Section 6, "Input data":
// GRIDS, PARABOLA, RANDDC, RANDCR), random linear and polynomial motions in any dimension, and
// CIRCLE (points in the plane on a breathing, turning circle, for the convex hull), and moving boxes
// for collision detection (boxes-linear, boxes-ballistic with floor bounces, tunnelling,
// boxes-mixed with a few fast boxes among many slow ones).
// Every dataset is a pure function of (name, options): std::mt19937_64 and only correctly rounded
// IEEE operations (+, -, *, /, sqrt), so the same seed gives the same scenario bit for bit on any
// platform. Parameters, formulas and windows are documented in docs/datasets.md.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "kinetic/scenario/scenario.hpp"

namespace kinetic::scenario {

struct GeneratorOptions {
  std::size_t n = 1000;  ///< number of objects (ids 0..n-1)
  std::uint64_t seed = 1;
  /// 0: the dataset's own (1; circle 2). random-linear, random-poly take any d >= 1; the paper's
  /// datasets are 1-D only, circle 2-D only.
  int dimension = 0;
  int degree = 2;                              ///< random-poly (1..6)
  std::optional<double> start_time, end_time;  ///< override the dataset's default window
  std::size_t queries = 0;  ///< query ops at start + (i+1)(end-start)/queries, i < queries
  QueryType query_type = QueryType::Sorted;  ///< axis 0; geometric parameters drawn at random
  /// Random timeline changes at random times in (start, end). Requires removes <= n, and
  /// removes < n when updates > 0, so an alive object always exists when one is needed.
  std::size_t updates = 0, inserts = 0, removes = 0;
  /// Every position is multiplied by `scale` (each coefficient rounded to double; times are not
  /// scaled). Crossing times are those of the unscaled dataset up to that rounding, but the
  /// arithmetic on the coefficients is no longer exact (docs/datasets.md, "Scale"). Finite, > 0.
  double scale = 1.0;
};

/// The scale that maps the dataset's dual points into [-1, 1]^2 (as RANDDC's unit disk and the
/// paper's Figure 5): 1 / (k - 1) with k = ceil(sqrt(n)) for grids and parabola (1 when k = 1),
/// 1 for the other datasets. Throws std::invalid_argument for an unknown name.
[[nodiscard]] double unit_scale(const std::string& dataset, std::size_t n);

/// Builds the named dataset. Throws std::invalid_argument for an unknown name (the message lists
/// the known ones) or options the dataset cannot honour.
[[nodiscard]] Scenario generate(const std::string& dataset, const GeneratorOptions& options);

/// Known dataset names: random-linear, random-poly, grids, parabola, randdc, randcr, circle, and
/// the moving boxes boxes-linear, boxes-ballistic, tunnelling, boxes-mixed.
[[nodiscard]] const std::vector<std::string>& dataset_names();

}  // namespace kinetic::scenario
