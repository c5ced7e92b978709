#pragma once
// Helpers of the numeric layer's tests (test_numeric_*.cpp): random doubles over chosen binary
// exponent ranges and exact rational values of doubles and dyadics (GMP), the oracle every bound
// is checked against.

#include <gmpxx.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <sstream>
#include <string>

namespace kinetic::numeric_test {

/// A random finite double m * 2^e: random sign, e uniform in [emin, emax] (emax <= 1023), m in
/// [1, 2) with 53 random bits, or (one time in four) only its top 8 bits random, so that sums
/// and products can cancel exactly. Below 2^-1022 the result is subnormal (rounded).
inline double random_double(std::mt19937_64& rng, int emin, int emax) {
  const int e = std::uniform_int_distribution<int>(emin, emax)(rng);
  std::uint64_t bits = rng() >> 12;  // 52 random fraction bits
  if (rng() % 4 == 0) bits &= ~((std::uint64_t{1} << 44) - 1);
  const double m = 1.0 + std::ldexp(static_cast<double>(bits), -52);
  const double v = std::ldexp(m, e);
  return (rng() & 1) != 0 ? -v : v;
}

/// The exact value of a finite double.
inline mpq_class exact(double v) { return mpq_class(v); }

/// The exact value of m * 2^e.
inline mpq_class exact_dyadic(const mpz_class& m, long e) {
  mpq_class q(m);
  if (e >= 0) {
    mpq_mul_2exp(q.get_mpq_t(), q.get_mpq_t(), static_cast<mp_bitcnt_t>(e));
  } else {
    mpq_div_2exp(q.get_mpq_t(), q.get_mpq_t(), static_cast<mp_bitcnt_t>(-e));
  }
  return q;
}

/// Doubles in C99 hexadecimal notation, for failure messages that reproduce exactly.
inline std::string hex(double v) {
  std::ostringstream os;
  os << std::hexfloat << v;
  return os.str();
}

}  // namespace kinetic::numeric_test
