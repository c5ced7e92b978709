// A kinetic segment tree: which moving intervals contain a point? (stabbing queries)
//
// 2,000 intervals slide along a line, some stretching as they go: interval i is [l(t), r(t)]
// with l and r linear in t and l <= r throughout. The kinetic segment tree keeps each interval
// in its canonical nodes over the sorted endpoints and repairs itself locally when two endpoints
// swap. At ten times we stab it at 50 random points and compare with a brute-force scan.
// Exit status 0 iff every answer agrees.
#include <cstdio>
#include <random>
#include <vector>

#include <kinetic/kinetic.hpp>

int main() {
  using kinetic::MotionPolynomial;
  using kinetic::ObjectId;

  // An interval is an object with two coordinates: coordinate 0 is its left end, 1 its right.
  kinetic::Session<kinetic::KineticSegmentTree> session(/*dimension=*/2);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> centre(0.0, 1000.0), speed(-20.0, 20.0),
      half_width(1.0, 30.0), stretch(0.0, 2.0);
  const int n = 2000;
  for (ObjectId id = 0; id < n; ++id) {
    const double c = centre(rng), v = speed(rng), w = half_width(rng), g = stretch(rng);
    // Left end c - w moving at v - g, right end c + w at v + g: the interval grows at 2g.
    session.insert(
        id, {MotionPolynomial::from({c - w, v - g}), MotionPolynomial::from({c + w, v + g})});
  }

  std::uniform_real_distribution<double> where(-100.0, 1100.0);
  int queries = 0, agree = 0;
  std::size_t reported = 0;
  for (int step = 1; step <= 10; ++step) {
    session.advance(step);
    for (int q = 0; q < 50; ++q) {
      const double x = where(rng);
      const std::vector<ObjectId> got = session.stab(x);  // ids ascending
      std::vector<ObjectId> want;
      for (const ObjectId id : session.ids()) {
        const std::vector<double> ends = session.position(id);
        if (ends[0] <= x && x <= ends[1]) want.push_back(id);
      }
      ++queries;
      reported += got.size();
      if (got == want) ++agree;
    }
  }
  std::printf(
      "segment tree over %d moving intervals to t = %g: %llu events, %d stabbing "
      "queries (%zu intervals reported), %d agree with brute force\n",
      n, session.now(), static_cast<unsigned long long>(session.simulator().counters().events()),
      queries, reported, agree);
  const bool ok = agree == queries && session.validate();
  std::printf("%s\n", ok ? "every answer matches brute force" : "MISMATCH");
  return ok ? 0 : 1;
}
