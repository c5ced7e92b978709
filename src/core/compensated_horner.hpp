#pragma once
// Compensated Horner (Graillat, Langlois, Louvet) with its rigorous error bound: private to the
// core. Defined in polynomial.cpp, which states the algorithm and the analysis; used there by the
// motions' evaluations and by the floating-point decisions' exact signs (incircle.cpp).

#include "kinetic/core/polynomial.hpp"

namespace kinetic {

/// P(x) = sum_{i <= n} (c_i + cl_i) x^i at the exact point x = s + e (|e| <= u |s|; cl may be
/// null, else |cl_i| <= u |c_i|), n <= 8 (the analysis holds while 2 n u stays far below
/// 2^-40; the motions use n <= 6, the in-circle of parabolas 8): hi + lo and a rigorous bound on
/// its error (error +infinity when no bound can be given).
[[nodiscard]] CompensatedValue compensated_horner(const double* c, const double* cl, int n,
                                                  double s, double e);

}  // namespace kinetic
