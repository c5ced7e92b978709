#pragma once
// How often the exact arithmetic leaves floating point: a count, per thread, of the work done
// in GMP (rationals made from doubles, exact polynomials and exact times built and refined,
// exact predicate fallbacks). Its changes around a decision or a comparison tell whether that
// one reached GMP (Counters::exact_decisions_gmp, exact_comparisons_gmp).

#include <cstdint>

namespace kinetic {

/// Work done in GMP on this thread, counted. Only its changes mean something: the scheduler
/// reads it around each exact decision and the queue around each comparison of two close event
/// times.
inline thread_local std::uint64_t g_gmp_work = 0;
[[nodiscard]] inline std::uint64_t gmp_work() { return g_gmp_work; }
inline void note_gmp_work() { ++g_gmp_work; }

}  // namespace kinetic
