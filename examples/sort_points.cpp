// Kinetic sorting of 10,000 points moving on a line.
//
// Each point moves as x(t) = x0 + v t. A kinetic sort keeps them in sorted order: it holds one
// certificate per pair of neighbours ("a is left of b") and repairs the order only when one
// fails, at the crossing time. Here we advance to t = 1, 2, ..., 10, read the order, and check
// it against brute force (sorting the positions at t). Exit status 0 iff every order is right.
#include <cstdio>
#include <random>
#include <vector>

#include <kinetic/kinetic.hpp>

int main() {
  using kinetic::MotionPolynomial;
  using kinetic::ObjectId;

  // A session owns the motions, the clock, the (robust) scheduler and the structure. Objects
  // have 1 coordinate; the KineticSort sorts them along axis 0.
  kinetic::Session<kinetic::KineticSort> session(/*dimension=*/1, /*options=*/{}, /*axis=*/0);

  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> start(0.0, 10000.0), speed(-1.0, 1.0);
  const int n = 10000;
  for (ObjectId id = 0; id < n; ++id) {
    // Coefficients of x(t): {x0, v} means x0 + v t. Degrees up to 6 are allowed.
    session.insert(id, {MotionPolynomial::from({start(rng), speed(rng)})});
  }

  bool all_right = true;
  for (int step = 1; step <= 10; ++step) {
    session.advance(step);  // processes every swap up to t = step
    const std::vector<ObjectId> order = session.sorted();

    // Brute force: the positions at t must be non-decreasing along the order, and every
    // object must appear.
    bool right = order.size() == static_cast<std::size_t>(n);
    for (std::size_t k = 1; right && k < order.size(); ++k) {
      right = session.position(order[k - 1])[0] <= session.position(order[k])[0];
    }
    all_right = all_right && right;
    std::printf("t = %2d: %llu swaps so far, order %s\n", step,
                static_cast<unsigned long long>(session.simulator().counters().events()),
                right ? "matches brute force" : "WRONG");
  }
  std::printf("kinetic sorting of %d points: %s\n", n,
              all_right ? "every order matches brute force" : "MISMATCH");
  return all_right ? 0 : 1;
}
