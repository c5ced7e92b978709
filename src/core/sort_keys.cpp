#include "kinetic/core/sort_keys.hpp"

#include <cassert>
#include <cmath>
#include <cstdlib>
#include <string>

#include "kinetic/core/error.hpp"

namespace kinetic {

namespace {
const MotionPolynomial kZeroMotion{};  // the zero polynomial
}  // namespace

DirectionKeys::DirectionKeys(const MotionTable& table, int direction)
    : table_(table), direction_(direction), ascending_ids_(true) {
  if (table.dimension() != 2) {
    precondition_failed("DirectionKeys", "directions a x + b y are keys of points in the plane "
                                         "(a table of dimension 2), not of dimension " +
                                             std::to_string(table.dimension()));
  }
  if (direction < 0 || direction >= static_cast<int>(kDirections.size())) {
    precondition_failed("DirectionKeys", "direction " + std::to_string(direction) +
                                             " is not one of the 8 (0 to 7)");
  }
  const Direction d = kDirections[static_cast<std::size_t>(direction)];
  ascending_ids_ = d.a > 0 || (d.a == 0 && d.b > 0);
}

void DirectionKeys::refresh(std::uint32_t object) {
  const Direction d = direction();
  for (int axis = 0; axis < 2; ++axis) {
    if (std::abs(axis == 0 ? d.a : d.b) != 2) continue;
    std::vector<MotionPolynomial>& copies = doubled_[static_cast<std::size_t>(axis)];
    if (copies.size() < table_.capacity()) copies.resize(table_.capacity());
    MotionPolynomial m = table_.motion(object, axis);
    for (int k = 0; k <= m.degree; ++k) {
      double& c = m.c[static_cast<std::size_t>(k)];
      c *= 2.0;  // exact unless it overflows
      if (!std::isfinite(c)) {
        precondition_failed("DirectionKeys",
                            "object " + std::to_string(table_.id(object)) + ": twice its " +
                                (axis == 0 ? "x" : "y") +
                                " coefficient overflows the doubles (|c| >= 2^1023)");
      }
    }
    copies[object] = m;
  }
}

const MotionPolynomial& DirectionKeys::scaled(std::uint32_t object, int axis,
                                              int coefficient) const {
  switch (std::abs(coefficient)) {
    case 0:
      return kZeroMotion;
    case 1:
      return table_.motion(object, axis);
    default:
      assert(object < doubled_[static_cast<std::size_t>(axis)].size());  // refresh()ed
      return doubled_[static_cast<std::size_t>(axis)][object];
  }
}

MotionCombination DirectionKeys::difference(std::uint32_t u, std::uint32_t w) const {
  // a x_u + b y_u - a x_w - b y_w: each axis gives one term of u and one of w, of opposite
  // signs, so two terms are added and two subtracted.
  const Direction d = direction();
  MotionCombination f;
  std::size_t plus = 0, minus = 0;
  // The axis with a zero coefficient (directions x and y) last: CROP takes its frame at the
  // origin of the first motion, which should be a motion of the points.
  const int first = d.a != 0 ? 0 : 1;
  for (const int axis : {first, 1 - first}) {
    const int c = axis == 0 ? d.a : d.b;
    const MotionPolynomial& mu = scaled(u, axis, c);
    const MotionPolynomial& mw = scaled(w, axis, c);
    if (c >= 0) {
      f.plus[plus++] = &mu;
      f.minus[minus++] = &mw;
    } else {
      f.plus[plus++] = &mw;
      f.minus[minus++] = &mu;
    }
  }
  return f;
}

double DirectionKeys::value_at(std::uint32_t object, Time t) const {
  const Direction d = direction();
  return d.a * table_.motion(object, 0).evaluate(t) + d.b * table_.motion(object, 1).evaluate(t);
}

}  // namespace kinetic
