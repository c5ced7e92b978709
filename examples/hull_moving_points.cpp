// A kinetic convex hull: which moving points are on the hull, at any time?
//
// 3,000 points move in the plane with random linear motions. The kinetic hull keeps the upper and
// lower hulls as a tree of merged chains, certified by orientation tests that fail only when the
// hull's structure changes; between events a hull query reads the root chains (O(h)). At twenty
// times we compare it with Andrew's monotone chain computed from scratch on the positions.
// Exit status 0 iff every answer agrees.
#include <algorithm>
#include <array>
#include <cstdio>
#include <random>
#include <vector>

#include <kinetic/kinetic.hpp>

namespace {

using Point = std::array<double, 3>;  // x, y, id

double cross(const Point& o, const Point& a, const Point& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

/// Andrew's monotone chain: ids counter-clockwise from the lowest-then-leftmost point.
std::vector<kinetic::ObjectId> brute_force_hull(std::vector<Point> p) {
  std::sort(p.begin(), p.end());
  std::vector<Point> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {  // lower hull
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {  // upper hull
    while (k >= lower && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  const auto lowest = std::min_element(h.begin(), h.end(), [](const Point& a, const Point& b) {
    return a[1] != b[1] ? a[1] < b[1] : a[0] < b[0];
  });
  std::rotate(h.begin(), lowest, h.end());
  std::vector<kinetic::ObjectId> ids;
  for (const Point& q : h) ids.push_back(static_cast<kinetic::ObjectId>(q[2]));
  return ids;
}

}  // namespace

int main() {
  using kinetic::MotionPolynomial;
  using kinetic::ObjectId;

  kinetic::Session<kinetic::KineticHull> session(/*dimension=*/2);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> position(-100.0, 100.0), velocity(-10.0, 10.0);
  const int n = 3000;
  for (ObjectId id = 0; id < n; ++id) {
    session.insert(id, {MotionPolynomial::from({position(rng), velocity(rng)}),
                        MotionPolynomial::from({position(rng), velocity(rng)})});
  }

  int queries = 0, agree = 0;
  std::size_t vertices = 0;
  for (int step = 1; step <= 20; ++step) {
    session.advance(0.5 * step);
    const std::vector<ObjectId> got = session.hull();
    std::vector<Point> points;
    for (const ObjectId id : session.ids()) {
      const std::vector<double> p = session.position(id);
      points.push_back({p[0], p[1], static_cast<double>(id)});
    }
    ++queries;
    vertices += got.size();
    if (got == brute_force_hull(points)) ++agree;
  }
  std::printf(
      "kinetic hull of %d moving points to t = %g: %llu events, %d hull queries "
      "(%zu vertices reported), %d agree with brute force\n",
      n, session.now(), static_cast<unsigned long long>(session.simulator().counters().events()),
      queries, vertices, agree);
  const bool ok = agree == queries && session.validate();
  std::printf("%s\n", ok ? "every answer matches brute force" : "MISMATCH");
  return ok ? 0 : 1;
}
