// A kinetic kd-tree in the plane with orthogonal range queries, checked against brute force.
//
// 5,000 points move on straight lines in a 1000 x 1000 field. The rank-based kinetic kd-tree of
// Abam, de Berg and Speckmann answers "which points are in this box now?" at any time without
// being rebuilt. Every half time unit we ask 20 random boxes and compare with a brute-force scan
// of the positions; along the way some points change course (flight-plan updates), new points
// arrive and others leave. Exit status 0 iff every answer agrees.
#include <cstdio>
#include <random>
#include <vector>

#include <kinetic/kinetic.hpp>

namespace {

using kinetic::MotionPolynomial;
using kinetic::ObjectId;

std::mt19937_64 rng(7);

/// A straight-line motion through a random point of the field, valid from time `now`: the
/// coefficients are in powers of (t - now).
std::vector<MotionPolynomial> random_course(double now) {
  std::uniform_real_distribution<double> coord(0.0, 1000.0), speed(-10.0, 10.0);
  return {MotionPolynomial::from({coord(rng), speed(rng)}, now),
          MotionPolynomial::from({coord(rng), speed(rng)}, now)};
}

/// The ids inside the box, by scanning every point (ascending, as range() answers).
std::vector<ObjectId> brute_force(const kinetic::Session<kinetic::KineticKdTree>& s,
                                  const kinetic::Box& box) {
  std::vector<ObjectId> inside;
  for (const ObjectId id : s.ids()) {
    const std::vector<double> p = s.position(id);
    if (box[0][0] <= p[0] && p[0] <= box[0][1] && box[1][0] <= p[1] && p[1] <= box[1][1]) {
      inside.push_back(id);
    }
  }
  return inside;
}

}  // namespace

int main() {
  kinetic::Session<kinetic::KineticKdTree> session(/*dimension=*/2);
  ObjectId next_id = 0;
  for (; next_id < 5000; ++next_id) session.insert(next_id, random_course(0.0));

  std::uniform_real_distribution<double> corner(-50.0, 1000.0), side(10.0, 200.0);
  int queries = 0, agree = 0;
  std::size_t reported = 0;
  for (int step = 1; step <= 10; ++step) {
    session.advance(0.5 * step);
    for (int q = 0; q < 20; ++q) {
      const double x = corner(rng), y = corner(rng);
      const kinetic::Box box{{x, x + side(rng)}, {y, y + side(rng)}};
      const std::vector<ObjectId> got = session.range(box);
      ++queries;
      reported += got.size();
      if (got == brute_force(session, box)) ++agree;
    }
    // Changes at the current time: 50 points change course, 20 arrive, 20 leave.
    for (int k = 0; k < 50; ++k) {
      session.update(static_cast<ObjectId>(rng() % 5000), random_course(session.now()));
    }
    for (int k = 0; k < 20; ++k) session.insert(next_id++, random_course(session.now()));
    for (int k = 0; k < 20; ++k) {
      const ObjectId id = static_cast<ObjectId>(5000 + rng() % (next_id - 5000));
      if (session.contains(id)) session.remove(id);
    }
  }
  std::printf(
      "kd-tree over %zu moving points at t = %g: %llu events, %d range queries "
      "(%zu points reported), %d agree with brute force\n",
      session.size(), session.now(),
      static_cast<unsigned long long>(session.simulator().counters().events()), queries, reported,
      agree);
  const bool ok = agree == queries && session.validate();
  std::printf("%s\n", ok ? "every answer matches brute force" : "MISMATCH");
  return ok ? 0 : 1;
}
