// A downstream consumer of the installed kinetic library: through the umbrella header, a session
// keeps 1,000 points moving on a line sorted while they cross, and the order is checked against
// brute force at t = 5. Exits with 0 iff the order is right.
#include <cstdio>
#include <vector>

#include <kinetic/kinetic.hpp>

int main() {
  using kinetic::MotionPolynomial;
  kinetic::Session<kinetic::KineticSort> session(1, {}, 0);  // 1-D, robust, sorted on axis 0
  for (int i = 0; i < 1000; ++i) {
    // x_i(t) = i - 0.37 i t mod 1: many crossings before t = 5.
    const std::vector<double> c{static_cast<double>(i), -0.37 * (i % 97)};
    session.insert(i, {MotionPolynomial::from(c)});
  }
  session.advance(5.0);
  const std::vector<kinetic::ObjectId> order = session.sorted();
  bool sorted = order.size() == 1000;
  for (std::size_t k = 1; sorted && k < order.size(); ++k) {
    const auto value = [&](kinetic::ObjectId id) {
      return session.motions().motion(session.motions().find(id)->index, 0).evaluate(5.0);
    };
    sorted = value(order[k - 1]) <= value(order[k]);
  }
  std::printf("%zu points, %llu events, sorted at t = 5: %s\n", order.size(),
              static_cast<unsigned long long>(session.simulator().counters().events()),
              sorted ? "yes" : "NO");
  return sorted ? 0 : 1;
}
