#pragma once
// Exact dyadic arithmetic: numbers m * 2^e with an integer m (a GMP integer) and an exponent e.
// Every finite double is one, and sums, differences and products of dyadics are dyadic, so
// polynomials in doubles evaluate, Taylor-shift and compare exactly, without rationals (no gcd)
// and without rounding. Bound: none, every operation is exact. Domain: finite doubles; exponents
// are longs, and a double's lies in [-1074, 1023], so products of a few hundred factors are safe
// (the callers multiply at most a dozen).
//
// Two forms of the same numbers:
//  - Dyadic, a value type (mpz_class mantissa): CROP's exact fallbacks (crop.cpp: exact Taylor
//    coefficients, Bernstein signs, the discriminant), rare enough that allocation does not
//    matter;
//  - in-place operations on raw mpz_t (dyadic_add_small(), dyadic_difference_sign()): the exact
//    stage of the predicates (predicates.cpp), which reuses thread-local integers and so does not
//    allocate once their buffers have grown.
// Every result is only ever read through its sign or compared; mantissas are not normalised
// (a dyadic has many representations), except that dyadic_parts() strips trailing zero bits.

#include <gmpxx.h>

#include <cmath>
#include <cstdint>

namespace kinetic::numeric {

/// x == m * 2^e exactly with m odd, |m| < 2^53 (m == 0, e == 0 for x == 0). x finite (normal or
/// subnormal).
inline void dyadic_parts(double x, std::int64_t& m, long& e) {
  if (x == 0.0) {
    m = 0;
    e = 0;
    return;
  }
  int exponent = 0;
  const double f = std::frexp(x, &exponent);  // x = f 2^exponent, 0.5 <= |f| < 1 (subnormals too)
  m = static_cast<std::int64_t>(std::ldexp(f, 53));
  e = exponent - 53;
  const int tz = __builtin_ctzll(static_cast<unsigned long long>(m < 0 ? -m : m));
  m >>= tz;  // exact: the low tz bits are zero (arithmetic shift of a negative m too)
  e += tz;
}

/// m * 2^e, a value.
struct Dyadic {
  mpz_class m;
  long e = 0;
};

/// The double v (finite) as a Dyadic, exactly.
inline Dyadic dyadic(double v) {
  Dyadic d;
  std::int64_t m = 0;
  dyadic_parts(v, m, d.e);
  d.m = static_cast<long>(m);
  return d;
}

inline Dyadic operator+(const Dyadic& a, const Dyadic& b) {
  if (a.m == 0) return b;
  if (b.m == 0) return a;
  Dyadic r;
  if (a.e <= b.e) {
    mpz_class t;
    mpz_mul_2exp(t.get_mpz_t(), b.m.get_mpz_t(), static_cast<mp_bitcnt_t>(b.e - a.e));
    r.m = a.m + t;
    r.e = a.e;
  } else {
    mpz_class t;
    mpz_mul_2exp(t.get_mpz_t(), a.m.get_mpz_t(), static_cast<mp_bitcnt_t>(a.e - b.e));
    r.m = t + b.m;
    r.e = b.e;
  }
  return r;
}

inline Dyadic operator-(const Dyadic& a) {
  Dyadic r = a;
  r.m = -r.m;
  return r;
}

inline Dyadic operator*(const Dyadic& a, const Dyadic& b) {
  Dyadic r;
  r.m = a.m * b.m;
  r.e = a.e + b.e;
  return r;
}

/// z * 2^ez += m * 2^e exactly (m a small integer, as from dyadic_parts()). tmp is clobbered.
inline void dyadic_add_small(mpz_t z, long& ez, std::int64_t m, long e, mpz_t tmp) {
  if (m == 0) return;
  if (mpz_sgn(z) == 0) {
    mpz_set_si(z, static_cast<long>(m));
    ez = e;
    return;
  }
  if (e >= ez) {
    mpz_set_si(tmp, static_cast<long>(m));
    mpz_mul_2exp(tmp, tmp, static_cast<mp_bitcnt_t>(e - ez));
    mpz_add(z, z, tmp);
  } else {
    mpz_mul_2exp(z, z, static_cast<mp_bitcnt_t>(ez - e));
    ez = e;
    if (m > 0) {
      mpz_add_ui(z, z, static_cast<unsigned long>(m));
    } else {
      mpz_sub_ui(z, z, static_cast<unsigned long>(-m));
    }
  }
}

/// sign(x * 2^ex - y * 2^ey); x and y are clobbered.
inline int dyadic_difference_sign(mpz_t x, long ex, mpz_t y, long ey) {
  if (mpz_sgn(x) == 0) return -mpz_sgn(y);
  if (mpz_sgn(y) == 0) return mpz_sgn(x);
  if (ex > ey) {
    mpz_mul_2exp(x, x, static_cast<mp_bitcnt_t>(ex - ey));
  } else if (ey > ex) {
    mpz_mul_2exp(y, y, static_cast<mp_bitcnt_t>(ey - ex));
  }
  const int c = mpz_cmp(x, y);
  return (c > 0) - (c < 0);
}

}  // namespace kinetic::numeric
