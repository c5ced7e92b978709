#pragma once
// The geometric vocabulary shared by the scenario, the oracle and the structures: one Box, one
// Disk, one Polygon, one query Shape. Plain data; every number is taken as exact.

#include <array>
#include <vector>

namespace kinetic {

/// What a Shape is.
enum class ShapeKind { None, Disk, Polygon };

/// A closed interval [lo, hi] (lo <= hi for a non-empty one).
using Interval = std::array<double, 2>;

/// A closed axis-aligned box: per axis a closed interval [lo, hi].
using Box = std::vector<Interval>;

/// A point of the plane.
using Point2 = std::array<double, 2>;

/// A simple polygon (convex or not, vertices in either orientation, at least 3).
using Polygon = std::vector<Point2>;

/// A closed disk (a ball in the scenario's dimension).
struct Disk {
  std::vector<double> center;
  double radius = 0.0;

  friend bool operator==(const Disk&, const Disk&) = default;
};

/// The region of an approximate range query: a closed disk or a simple polygon.
struct Shape {
  using Kind = ShapeKind;
  Kind kind = Kind::None;
  Disk disk;
  Polygon polygon;

  friend bool operator==(const Shape&, const Shape&) = default;
};

}  // namespace kinetic
