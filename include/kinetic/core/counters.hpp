#pragma once
// The KDS performance measures, counted (the KDS lecture notes: responsive, efficient, compact,
// local). Every structure fills these; the runner reports them in `--stats`.
//  - efficient:  events processed, split into external (the maintained attribute changed) and
//                internal ones;
//  - compact:    certificates alive, now and at most;
//  - local:      certificates per object, at most;
//  - responsive: time per event (wall time / events, measured by the caller).

#include <cstdint>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/predicates.hpp"

namespace kinetic {

/// The timeline's changes a structure took: the base of the structures' own counters.
struct ChangeCounters {
  std::uint64_t inserts = 0;
  std::uint64_t removes = 0;
  std::uint64_t updates = 0;  ///< flight-plan updates
};

struct Counters {
  std::uint64_t events_internal = 0;
  std::uint64_t events_external = 0;
  /// Events whose scheduled time lies before t_curr when processed (robust scheduling only).
  std::uint64_t events_in_past = 0;
  /// Exact scheduling: groups of two events or more at one exact time.
  std::uint64_t equal_time_groups = 0;
  /// Exact scheduling: comparisons of two event times whose double brackets overlapped (decided
  /// exactly), and halvings of exact times' isolating intervals (by the queue's comparisons and
  /// the scheduler's decisions at the exact current time).
  std::uint64_t exact_comparisons = 0;
  std::uint64_t exact_refinements = 0;
  /// Exact scheduling: certificate decisions (the sign just after now and the next failure),
  /// and how many of them and of the exact comparisons above reached GMP (core/gmp_work.hpp);
  /// the rest stayed in floating point (filters, expansions, brackets between doubles).
  std::uint64_t exact_decisions = 0;
  std::uint64_t exact_decisions_gmp = 0;
  std::uint64_t exact_comparisons_gmp = 0;
  /// Classic scheduling: certificates whose floating-point form could overflow (extreme
  /// coefficients or origins), decided on the exact polynomial instead.
  std::uint64_t classic_exact_fallbacks = 0;
  std::uint64_t certificates_alive = 0;
  std::uint64_t certificates_alive_max = 0;
  std::uint64_t certificates_per_object_max = 0;
  /// Failure-time computations (root isolations / root findings) of certificates.
  std::uint64_t root_isolation_calls = 0;
  /// Exact sign decisions of the structures: how many the floating-point filter took, how many
  /// needed GMP.
  PredicateStats predicates;
  /// Root isolation work of the robust scheduler (its own exact sign decisions included).
  CropStats crop;
  /// Event delays t_pr - t_ex (Abam, Agarwal, de Berg, Yu, Section 3), where measured (robust
  /// scheduling).
  std::uint64_t delays_measured = 0;
  double delay_max = 0.0;
  double delay_sum_squares = 0.0;

  /// Exact (GMP) fallbacks taken, by the structures and by CROP.
  [[nodiscard]] std::uint64_t exact_fallbacks() const {
    return predicates.exact + crop.predicates.exact + crop.exact_boxes;
  }
  void note_delay(double delay) {
    ++delays_measured;
    if (delay > delay_max) delay_max = delay;
    delay_sum_squares += delay * delay;
  }

  [[nodiscard]] std::uint64_t events() const { return events_internal + events_external; }
  void set_certificates_alive(std::uint64_t alive) {
    certificates_alive = alive;
    if (alive > certificates_alive_max) certificates_alive_max = alive;
  }
  void note_certificates_per_object(std::uint64_t count) {
    if (count > certificates_per_object_max) certificates_per_object_max = count;
  }
};

}  // namespace kinetic
