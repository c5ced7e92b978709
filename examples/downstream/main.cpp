// A downstream consumer of the installed kinetic library: builds the motion x(t) = 1 + 2t and
// evaluates it at t = 3. Exits with 0 iff the value is 7.
#include <array>
#include <cstdio>

#include <kinetic/core/polynomial.hpp>

int main() {
  const std::array<double, 2> coefficients{1.0, 2.0};  // ascending powers of t
  const kinetic::MotionPolynomial x = kinetic::MotionPolynomial::from(coefficients);
  const double value = x.evaluate(3.0);
  std::printf("x(3) = %g\n", value);
  return value == 7.0 ? 0 : 1;
}
