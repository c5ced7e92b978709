#include "kinetic/run/timeline_driver.hpp"

#include <algorithm>

#include "kinetic/core/boxes.hpp"

namespace kinetic::run {

std::vector<MotionPolynomial> to_polynomials(const scenario::Motion& m,
                                             const std::vector<double>& half_extents) {
  std::vector<MotionPolynomial> out;
  out.reserve(m.coordinates.size() + half_extents.size());
  for (const auto& c : m.coordinates) out.push_back(MotionPolynomial::from(c, m.origin));
  for (const double h : half_extents) out.push_back(MotionPolynomial::from({h}, m.origin));
  return out;
}

int table_dimension(const scenario::Scenario& s) {
  return s.objects_are == scenario::ObjectsAre::Boxes ? boxes_table_dimension(s.dimension)
                                                       : s.dimension;
}

std::vector<MotionPolynomial> updated_motion(const scenario::Scenario& s,
                                             const scenario::TimelineOp& op,
                                             const MotionTable& table, ObjectHandle h) {
  std::vector<MotionPolynomial> out = to_polynomials(op.motion, op.half_extents);
  if (s.objects_are == scenario::ObjectsAre::Boxes && op.half_extents.empty()) {
    for (int axis = 0; axis < s.dimension; ++axis) out.push_back(half_extent(table, h.index, axis));
  }
  return out;
}

int degree_of(const scenario::Motion& m) {
  int degree = 0;
  for (const auto& c : m.coordinates) {
    std::size_t n = c.size();
    while (n > 1 && c[n - 1] == 0.0) --n;
    degree = std::max(degree, static_cast<int>(n) - 1);
  }
  return degree;
}

ScenarioBounds bounds_of(const scenario::Scenario& s) {
  ScenarioBounds b;
  b.dimension = s.dimension;
  b.max_objects = s.objects.size();
  b.motion_changes = s.objects.size();
  auto note_degree = [&](const scenario::Motion& m) {
    b.max_degree = std::max(b.max_degree, degree_of(m));
  };
  for (const scenario::ObjectSpec& o : s.objects) note_degree(o.motion);
  for (const scenario::TimelineOp& op : s.timeline) {
    if (op.op == scenario::OpKind::Insert) ++b.max_objects;
    if (op.op == scenario::OpKind::Insert || op.op == scenario::OpKind::Update) {
      ++b.motion_changes;
      note_degree(op.motion);
    }
  }
  return b;
}

MotionTable table_of(const scenario::Scenario& s) {
  MotionTable table(table_dimension(s));
  for (const scenario::ObjectSpec& o : s.objects)
    table.insert(o.id, to_polynomials(o.motion, o.half_extents), s.start_time);
  return table;
}

SessionOptions session_options(const scenario::Scenario& s, SchedulerKind kind, double eps) {
  SessionOptions o;
  o.scheduler = kind;
  o.eps = eps;
  o.start = s.start_time;
  o.horizon = s.end_time.value_or(kTimeInfinity);
  return o;
}

Time end_of(const scenario::Scenario& s) {
  return s.end_time.value_or(s.timeline.empty() ? s.start_time : s.timeline.back().time);
}

}  // namespace kinetic::run
