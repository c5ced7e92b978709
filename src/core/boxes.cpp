#include "kinetic/core/boxes.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "core/numeric/linear_filter.hpp"
#include "kinetic/core/crop.hpp"
#include "kinetic/core/preconditions.hpp"

namespace kinetic {

int compare_sides_at(const MotionTable& boxes, std::uint32_t a, BoxSide s, std::uint32_t b,
                     BoxSide u, int axis, Time t) {
  // side(a) - side(b) = c_a + sa h_a - c_b - sb h_b with sa, sb = -1 (low) or +1 (high): the
  // half extents enter with their signs as constant polynomials (negation is exact).
  const MotionPolynomial& ha = half_extent(boxes, a, axis);
  const MotionPolynomial& hb = half_extent(boxes, b, axis);
  // First the floating-point filter: the centers within their rigorous bounds, the half extents
  // (constants, require_box_motion) exact with their signs. Most sides are far apart.
  const int filtered =
      numeric::sum_sign(numeric::filtered_value(center(boxes, a, axis), t),
                        FilteredValue{s == BoxSide::High ? ha.c[0] : -ha.c[0], 0.0},
                        numeric::filtered_value(center(boxes, b, axis), t),
                        FilteredValue{u == BoxSide::High ? hb.c[0] : -hb.c[0], 0.0});
  if (filtered != 0) return filtered;
  MotionPolynomial neg_ha = ha, neg_hb = hb;
  neg_ha.c[0] = -ha.c[0];
  neg_hb.c[0] = -hb.c[0];
  // plus: c_a and (+h_a or -h_a); minus: c_b and (+h_b or -h_b), i.e. - (sb h_b).
  const MotionCombination f{{&center(boxes, a, axis), s == BoxSide::High ? &ha : &neg_ha},
                            {&center(boxes, b, axis), u == BoxSide::High ? &hb : &neg_hb}};
  return sign_at(f, t);
}

void require_box_motion(std::span<const MotionPolynomial> motion, ObjectId id, const char* where) {
  if (motion.size() % 2 != 0) {
    precondition_failed(where, "box " + std::to_string(id) + ": " + std::to_string(motion.size()) +
                                   " coordinates; a box has 2d (its center's motions, then its "
                                   "half extents)");
  }
  const std::size_t d = motion.size() / 2;
  for (std::size_t k = 0; k < d; ++k) {
    const MotionPolynomial& h = motion[d + k];
    if (h.degree != 0 || !(h.c[0] >= 0.0)) {
      precondition_failed(where, "box " + std::to_string(id) + ": the half extent on axis " +
                                     std::to_string(k) + " (coordinate " + std::to_string(d + k) +
                                     ") must be a constant >= 0");
    }
  }
}

void require_box_row(const MotionTable& boxes, std::uint32_t index, const char* where) {
  std::array<MotionPolynomial, 6> row;
  const auto n = static_cast<std::size_t>(boxes.dimension());
  for (std::size_t k = 0; k < n && k < row.size(); ++k)
    row[k] = boxes.motion(index, static_cast<int>(k));
  require_box_motion(std::span<const MotionPolynomial>(row.data(), std::min(n, row.size())),
                     boxes.id(index), where);
}

namespace {
void sort_by_ids(const MotionTable& boxes, std::vector<IndexPair>& out) {
  for (IndexPair& p : out) {
    if (boxes.id(p.first) > boxes.id(p.second)) std::swap(p.first, p.second);
  }
  std::sort(out.begin(), out.end(), [&](const IndexPair& x, const IndexPair& y) {
    const ObjectId x0 = boxes.id(x.first), y0 = boxes.id(y.first);
    if (x0 != y0) return x0 < y0;
    return boxes.id(x.second) < boxes.id(y.second);
  });
}
}  // namespace

std::vector<IndexPair> pairs_by_ids(const MotionTable& boxes, const PairSet& pairs) {
  std::vector<IndexPair> out;
  out.reserve(pairs.size());
  for (const std::uint64_t k : pairs.keys())
    out.emplace_back(PairSet::first(k), PairSet::second(k));
  sort_by_ids(boxes, out);
  return out;
}

std::vector<IndexPair> EndedContacts::touching_only(const MotionTable& boxes,
                                                    const PairSet& contacts,
                                                    const Simulator& sim) const {
  std::vector<IndexPair> out;
  if (sim.instant() != instant_) return out;
  for (const IndexPair& p : pairs_) {
    if (boxes.alive_index(p.first) && boxes.alive_index(p.second) &&
        !contacts.contains(p.first, p.second)) {
      out.push_back(p);
    }
  }
  sort_by_ids(boxes, out);
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<IndexPair> EndedContacts::answer(const MotionTable& boxes, const PairSet& contacts,
                                             const Simulator& sim) const {
  if (pairs_.empty() || sim.instant() != instant_) return pairs_by_ids(boxes, contacts);
  std::vector<IndexPair> out = touching_only(boxes, contacts, sim);
  for (const std::uint64_t k : contacts.keys())
    out.emplace_back(PairSet::first(k), PairSet::second(k));
  sort_by_ids(boxes, out);
  return out;
}

BoxEndpointKeys::BoxEndpointKeys(const MotionTable& boxes, int axis) : boxes_(boxes), axis_(axis) {
  if (boxes.dimension() % 2 != 0) {
    precondition_failed("BoxEndpointKeys",
                        "a table of boxes has an even dimension (centers, then "
                        "half extents), not " +
                            std::to_string(boxes.dimension()));
  }
  require_axis("BoxEndpointKeys", axis, box_dimension(boxes));
}

void BoxEndpointKeys::refresh(std::uint32_t box) {
  if (negated_extent_.size() < boxes_.capacity()) negated_extent_.resize(boxes_.capacity());
  MotionPolynomial& n = negated_extent_[box];
  n = half_extent(boxes_, box, axis_);
  n.c[0] = -n.c[0];  // exact
}

void EndedContacts::note(const Simulator& sim, const MotionTable& boxes, std::uint32_t a,
                         std::uint32_t b) {
  if (sim.queue().exact_order() || boxes_overlap_at(boxes, a, b, sim.now())) note_now(sim, a, b);
}

std::vector<IndexPair> touching_only_at(const MotionTable& boxes, const PairSet& contacts, Time t) {
  std::vector<IndexPair> out;
  if (box_dimension(boxes) == 0) return out;
  // A sweep along axis 0 at t with closed boxes: the boxes by their low side at t (exact
  // comparisons), a box active until a low side strictly above its high side comes.
  std::vector<std::uint32_t> order = boxes.alive_indices();
  const auto low_before = [&](std::uint32_t a, std::uint32_t b) {
    const int c = compare_sides_at(boxes, a, BoxSide::Low, b, BoxSide::Low, 0, t);
    return c != 0 ? c < 0 : a < b;
  };
  std::sort(order.begin(), order.end(), low_before);
  const auto high_after = [&](std::uint32_t a, std::uint32_t b) {  // a min-heap by high side
    const int c = compare_sides_at(boxes, a, BoxSide::High, b, BoxSide::High, 0, t);
    return c != 0 ? c > 0 : a > b;
  };
  std::vector<std::uint32_t> heap;
  std::vector<std::uint32_t> active;
  std::vector<char> is_active(boxes.capacity(), 0);
  for (const std::uint32_t b : order) {
    while (!heap.empty() &&
           compare_sides_at(boxes, heap.front(), BoxSide::High, b, BoxSide::Low, 0, t) < 0) {
      is_active[heap.front()] = 0;
      std::pop_heap(heap.begin(), heap.end(), high_after);
      heap.pop_back();
    }
    std::erase_if(active, [&](std::uint32_t a) { return is_active[a] == 0; });
    for (const std::uint32_t a : active) {
      if (!contacts.contains(a, b) && boxes_overlap_at(boxes, a, b, t)) {
        out.emplace_back(boxes.id(a) < boxes.id(b) ? IndexPair{a, b} : IndexPair{b, a});
      }
    }
    active.push_back(b);
    is_active[b] = 1;
    heap.push_back(b);
    std::push_heap(heap.begin(), heap.end(), high_after);
  }
  return out;
}

bool boxes_overlap_at(const MotionTable& boxes, std::uint32_t a, std::uint32_t b, Time t,
                      int last_axis) {
  const int d = box_dimension(boxes);
  for (int i = 0; i < d; ++i) {
    const int axis = last_axis >= 0 && last_axis < d ? (last_axis + 1 + i) % d : i;
    if (compare_sides_at(boxes, a, BoxSide::Low, b, BoxSide::High, axis, t) > 0) return false;
    if (compare_sides_at(boxes, b, BoxSide::Low, a, BoxSide::High, axis, t) > 0) return false;
  }
  return true;
}

}  // namespace kinetic
