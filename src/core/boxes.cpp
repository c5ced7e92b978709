#include "kinetic/core/boxes.hpp"

#include "kinetic/core/crop.hpp"

namespace kinetic {

int compare_sides_at(const MotionTable& boxes, std::uint32_t a, BoxSide s, std::uint32_t b,
                     BoxSide u, int axis, Time t) {
  // side(a) - side(b) = c_a + sa h_a - c_b - sb h_b with sa, sb = -1 (low) or +1 (high): the
  // half extents enter with their signs as constant polynomials (negation is exact).
  const MotionPolynomial& ha = half_extent(boxes, a, axis);
  const MotionPolynomial& hb = half_extent(boxes, b, axis);
  MotionPolynomial neg_ha = ha, neg_hb = hb;
  neg_ha.c[0] = -ha.c[0];
  neg_hb.c[0] = -hb.c[0];
  // plus: c_a and (+h_a or -h_a); minus: c_b and (+h_b or -h_b), i.e. - (sb h_b).
  const MotionCombination f{{&center(boxes, a, axis), s == BoxSide::High ? &ha : &neg_ha},
                            {&center(boxes, b, axis), u == BoxSide::High ? &hb : &neg_hb}};
  return sign_at(f, t);
}

bool boxes_overlap_at(const MotionTable& boxes, std::uint32_t a, std::uint32_t b, Time t) {
  for (int axis = 0; axis < box_dimension(boxes); ++axis) {
    if (compare_sides_at(boxes, a, BoxSide::Low, b, BoxSide::High, axis, t) > 0) return false;
    if (compare_sides_at(boxes, b, BoxSide::Low, a, BoxSide::High, axis, t) > 0) return false;
  }
  return true;
}

}  // namespace kinetic
