#pragma once
// Exact event times, the ground the exact scheduler stands on (see docs/crop.md, "Exact times").
// A certificate function of polynomial motions is a polynomial with rational (indeed dyadic)
// coefficients: its roots are algebraic numbers. An ExactTime is one of them, kept as its
// square-free polynomial and an isolating interval with rational ends that is refined on demand
// (bisection, exact signs), or a rational point. Two times compare exactly: their intervals are
// refined until they separate, and equality (the degenerate case: crossings at one instant) is
// decided by the gcd of the two polynomials having a root where both intervals meet. Signs of
// another function at such a time, and just after it, are exact too. Everything is GMP rational
// arithmetic: correct first, and paid for only by the exact scheduler.

#include <gmpxx.h>

#include <array>
#include <atomic>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <vector>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/gmp_work.hpp"
#include "kinetic/core/incircle.hpp"
#include "kinetic/core/polynomial.hpp"

namespace kinetic {

/// Thrown by the exact arithmetic (root isolation, refinement, gcds, Sturm sequences) when the
/// interrupt flag of the current thread's ExactInterruptScope is raised: a decision on
/// polynomials of extreme magnitudes may take long, and a run must stop within a second of
/// SIGINT or SIGTERM whatever it computes. The structure it interrupted is left unusable; the
/// caller (the runner) stops the run there.
struct ExactInterrupted : std::runtime_error {
  ExactInterrupted() : std::runtime_error("interrupted during an exact decision") {}
};

/// While alive, the exact arithmetic of this thread polls `flag` (may be null: no polling).
class ExactInterruptScope {
 public:
  explicit ExactInterruptScope(const std::atomic<bool>* flag);
  ~ExactInterruptScope();
  ExactInterruptScope(const ExactInterruptScope&) = delete;
  ExactInterruptScope& operator=(const ExactInterruptScope&) = delete;

 private:
  const std::atomic<bool>* previous_;
};

/// Throws ExactInterrupted when the current scope's flag is raised.
void poll_exact_interrupt();

/// A polynomial in t (powers of t, not of t - origin) with rational coefficients, exact.
class ExactPolynomial {
 public:
  ExactPolynomial() = default;
  /// c[k] is the coefficient of t^k; trailing zeros are trimmed (the zero polynomial is empty).
  explicit ExactPolynomial(std::vector<mpq_class> c);
  /// x(t) of a motion, expanded exactly about t = 0.
  static ExactPolynomial of(const MotionPolynomial& m);
  /// upper(t) - lower(t), exactly.
  static ExactPolynomial difference(const MotionPolynomial& upper, const MotionPolynomial& lower);
  /// plus[0] + plus[1] - minus[0] - minus[1], exactly.
  static ExactPolynomial of(const MotionCombination& f);
  /// (P0 - P1)(P2 - P3) - (M0 - M1)(M2 - M3), exactly.
  static ExactPolynomial of(const ProductCombination& f);
  /// The in-circle determinant of four moving points, exactly (core/incircle.hpp).
  static ExactPolynomial of(const InCircle& f);
  /// The difference of two squared lengths, exactly (core/incircle.hpp).
  static ExactPolynomial of(const LengthComparison& f);

  /// -1 for the zero polynomial.
  [[nodiscard]] int degree() const { return static_cast<int>(c_.size()) - 1; }
  [[nodiscard]] bool is_zero() const { return c_.empty(); }
  [[nodiscard]] const std::vector<mpq_class>& coefficients() const { return c_; }
  /// Each coefficient enclosed by doubles [lo, hi] (equal when it is a double; the whole line
  /// beyond the doubles), computed once: the floating-point filters' view of the polynomial.
  /// When the largest coefficient is beyond 2^+-64, all are first scaled by one power of two
  /// that brings it near 1 (exact; the signs of the polynomial, all the filters read, unchanged).
  /// Not the polynomial's values, then: only its signs.
  [[nodiscard]] const std::vector<std::array<double, 2>>& enclosure() const;
  [[nodiscard]] mpq_class operator()(const mpq_class& t) const;
  [[nodiscard]] int sign_at(const mpq_class& t) const;
  [[nodiscard]] ExactPolynomial derivative() const;
  /// f(2^e s) as a polynomial in s, exactly (coefficient k times 2^(e k)): the same roots
  /// scaled by 2^-e, the same signs.
  [[nodiscard]] ExactPolynomial time_scaled(int e) const;
  /// The same roots, each simple: p / gcd(p, p') (times a positive rational: the same signs).
  /// The zero polynomial stays zero.
  [[nodiscard]] ExactPolynomial square_free() const;
  /// p times the positive rational that makes its coefficients coprime integers: the same roots
  /// and signs; its signs at dyadic times are computed with integers only (sign_at).
  [[nodiscard]] ExactPolynomial primitive_part() const;

  friend ExactPolynomial operator+(const ExactPolynomial& a, const ExactPolynomial& b);
  friend ExactPolynomial operator-(const ExactPolynomial& a, const ExactPolynomial& b);
  friend ExactPolynomial operator*(const ExactPolynomial& a, const ExactPolynomial& b);
  /// The monic greatest common divisor (zero when both are zero).
  static ExactPolynomial gcd(ExactPolynomial a, ExactPolynomial b);
  /// The remainder of a divided by b times a positive rational, with coprime integer
  /// coefficients (the same signs as the remainder; computed with integers only); b non-zero.
  static ExactPolynomial positive_remainder(const ExactPolynomial& a, const ExactPolynomial& b);
  /// Quotient and remainder; b non-zero.
  static void divide(const ExactPolynomial& a, const ExactPolynomial& b, ExactPolynomial& q,
                     ExactPolynomial& r);

 private:
  void trim();
  /// Drops the views computed from the coefficients (after they changed in place).
  void forget_views();
  std::vector<mpq_class> c_;
  mutable std::vector<std::array<double, 2>> enclosure_;  // empty until asked
  /// Dyadic coefficients (denominators powers of two, as the motions' doubles make them) as
  /// integers over one common power of two, for signs at dyadic times without rational
  /// normalisation; computed on first use (dyadic_state_: 0 unknown, 1 dyadic, 2 not).
  mutable std::vector<mpz_class> dyadic_;
  mutable int dyadic_state_ = 0;
};

/// q when its denominator is a power of two (a dyadic rational, as every double is), else a
/// dyadic just below (above) it. Exact polynomials' signs at dyadic times are computed with
/// integers only (ExactPolynomial::sign_at), so searches over times start and end at such.
[[nodiscard]] mpq_class dyadic_at_or_below(const mpq_class& q);
[[nodiscard]] mpq_class dyadic_at_or_above(const mpq_class& q);

/// The Sturm sequence of a square-free polynomial: distinct real roots in (a, b] counted exactly.
class SturmSequence {
 public:
  /// Precondition: p non-zero and square-free.
  explicit SturmSequence(const ExactPolynomial& p);
  /// The number of roots of p in (a, b], a < b.
  [[nodiscard]] int count(const mpq_class& a, const mpq_class& b) const;

 private:
  [[nodiscard]] int variations(const mpq_class& x) const;
  std::vector<ExactPolynomial> seq_;
};

/// An exact time: a rational point, or the only root, simple, of a polynomial p in the open
/// interval (lo, hi), with p(lo) and p(hi) non-zero and of opposite signs.
class ExactTime {
 public:
  ExactTime() = default;
  /// The rational (e.g. a double) time t.
  static ExactTime point(const mpq_class& t);
  /// The root of p (square-free, or with one simple root in (lo, hi)) in (lo, hi); preconditions
  /// as above (checked by assertion).
  static ExactTime root(ExactPolynomial p, mpq_class lo, mpq_class hi);
  /// The same when the sign of p at lo is known (p(hi) has the other sign; checked by
  /// assertion): p needs only one root in (lo, hi), simple, not to be square-free.
  static ExactTime root_with_sign(ExactPolynomial p, mpq_class lo, mpq_class hi, int sign_lo);

  [[nodiscard]] bool is_point() const { return point_; }
  /// Bounds: lo() <= the time <= hi() (equal for a point).
  [[nodiscard]] const mpq_class& lo() const { return lo_; }
  [[nodiscard]] const mpq_class& hi() const { return hi_; }
  /// Doubles below and above the time (the nearest that are, rounded outwards).
  [[nodiscard]] double lower() const;
  [[nodiscard]] double upper() const;
  /// Halves the interval (a point stays); a root found at the midpoint becomes a point.
  void refine();
  /// Refines until lower() and upper() are the same or adjacent doubles: a floating-point guess
  /// of the root (bisection on p's coefficients rounded to doubles) checked by exact signs at
  /// the guess and its two neighbours, bisection when the guess misses.
  void tighten();
  /// Refinements made so far (for the counters).
  [[nodiscard]] std::size_t refinements() const { return refinements_; }

  /// sign(a - b), exactly: refines both until they separate; equal roots of different
  /// polynomials are recognised by the gcd. `equal_by_gcd`, when given, is set when equality
  /// needed the gcd test.
  friend int compare(ExactTime& a, ExactTime& b, bool* equal_by_gcd);
  friend int compare(ExactTime& a, ExactTime& b) { return compare(a, b, nullptr); }

  /// The exact sign of f at this time (refines).
  [[nodiscard]] int sign_of(const ExactPolynomial& f);
  /// The sign of f just after this time: sign_of(f), or when that is 0 the sign of the first
  /// derivative of f that is not 0 here. 0 only for the zero polynomial.
  [[nodiscard]] int sign_after(const ExactPolynomial& f);

 private:
  /// Splits at a rational m inside (lo, hi): keeps the half with the root, or becomes m.
  void split_at(const mpq_class& m);

  bool point_ = true;
  mpq_class lo_, hi_;
  ExactPolynomial
      p_;  // one simple root in (lo, hi) (square-free, or a root isolated alone); empty for a point
  int sign_lo_ = 0;  // sign of p at lo (a root: non-zero)
  std::size_t refinements_ = 0;
};

/// The magnitude (e in 2^e <= |c| < 2^(e+1)) of a coefficient of x(t), expanded exactly about
/// t = 0, outside 2^-log2 <= |c| < 2^log2 (the farthest from 1 when several), or nothing when
/// every coefficient is within or 0. An origin far from 0 counts through the expansion. The cost
/// of exact certificates of high degree grows with these magnitudes: structures that use them
/// bound them (KineticDelaunay::kMagnitudeLog2).
[[nodiscard]] std::optional<long> magnitude_beyond(const MotionPolynomial& m, int log2);

/// Every real root of f (non-zero) in (lo, hi], ascending, each an ExactTime of f's square-free
/// part. lo < hi.
[[nodiscard]] std::vector<ExactTime> isolate_roots(const ExactPolynomial& f, const mpq_class& lo,
                                                   const mpq_class& hi);

/// The exact scheduler's decision on a certificate function f at the exact time `now`: the sign
/// of f just after now (0: f is the zero polynomial), and the first time after now when f takes
/// the other sign (a root of odd multiplicity: a touching root does not fail the certificate),
/// when there is one in (now, horizon].
struct ExactDecision {
  int sign = 0;
  bool fails = false;
  ExactTime failure;
};
[[nodiscard]] ExactDecision decide_exact(const ExactPolynomial& f, ExactTime& now,
                                         const mpq_class& horizon);

/// An exact time that is cheap until it must be exact (the exact scheduler's event times and
/// clock): a double; a root of a certificate of degree <= 2 (two motions of degree <= 2: lines,
/// parabolas) strictly between two adjacent doubles, found by exact signs at doubles in
/// floating-point expansions (no GMP); or a general ExactTime. Comparisons look at the double
/// brackets first; two low-degree roots whose brackets overlap are compared without GMP when
/// they can be (two linear roots by a 2 x 2 determinant; two roots of the same quadratic by
/// their order); only otherwise are the times made exact (exact(): the ExactTime, built once
/// and kept) and compared exactly.
struct LowDegreeDecision;

class LazyTime {
 public:
  LazyTime() = default;  ///< the double 0
  LazyTime(const LazyTime& other);
  LazyTime& operator=(const LazyTime& other);
  /// Moves copy only the root's components in use (the queue moves times: a linear root's
  /// touch two cache lines of the 152 bytes).
  LazyTime(LazyTime&& other) noexcept
      : exact_(std::move(other.exact_)), deferred_(std::move(other.deferred_)) {
    copy_plain(other);
  }
  LazyTime& operator=(LazyTime&& other) noexcept {
    exact_ = std::move(other.exact_);
    deferred_ = std::move(other.deferred_);
    copy_plain(other);
    return *this;
  }
  ~LazyTime() = default;
  /// The double t, exactly.
  static LazyTime point(double t);
  /// A general exact time (its bracket one double wide after ExactTime::tighten()).
  static LazyTime of(ExactTime t);
  /// The coefficients (in powers of t, at most kMax of them) of a polynomial as floating-point
  /// expansions, in one block: coefficient k is the exact sum of (*this)[k], non-overlapping
  /// components.
  class ExpansionCoefficients {
   public:
    static constexpr std::size_t kMax = 9;  ///< degree <= 8: the in-circle of parabolas
    /// Appends the coefficient of the next power of t.
    void push_back(std::span<const double> components) {
      assert(count_ < kMax);
      for (const double x : components) components_.push_back(x);
      start_[++count_] = static_cast<std::uint32_t>(components_.size());
    }
    [[nodiscard]] std::size_t size() const { return count_; }
    [[nodiscard]] std::span<const double> operator[](std::size_t k) const {
      return {components_.data() + start_[k], start_[k + 1] - start_[k]};
    }

   private:
    std::vector<double> components_;
    std::array<std::uint32_t, kMax + 1> start_{};
    std::size_t count_ = 0;
  };
  /// A deferred root's polynomial: given as expansion coefficients, or as the certificate whose
  /// root it is (the eight motions, of degree <= 2, copied compactly: an in-circle's four points
  /// or a product combination), whose expansions and exact polynomial are built only when
  /// asked: most deferred roots are ordered by their brackets alone and never need them.
  class DeferredPolynomial {
   public:
    enum class Certificate : std::uint8_t { Given, InCircle, Product };
    explicit DeferredPolynomial(ExpansionCoefficients coefficients)
        : certificate_(Certificate::Given),
          expansions_(std::make_unique<ExpansionCoefficients>(std::move(coefficients))),
          built_(true) {}
    /// Precondition (asserted): every motion of degree <= 2.
    explicit DeferredPolynomial(const InCircle& f);
    explicit DeferredPolynomial(const ProductCombination& f);
    [[nodiscard]] Certificate certificate() const { return certificate_; }
    /// The certificate's motion k (InCircle: p0.x, p0.y, ..., p3.x, p3.y; Product: plus[0..3],
    /// minus[0..3]); meaningless when Given.
    [[nodiscard]] MotionPolynomial motion(std::size_t k) const;
    /// True when motion k is m (the same origin, degree and coefficients).
    [[nodiscard]] bool same_motion(std::size_t k, const MotionPolynomial& m) const;
    /// The coefficients as expansions (built on first use), or null when they leave the
    /// expansions' domain or capacity.
    [[nodiscard]] const ExpansionCoefficients* expansions() const;
    /// The polynomial exactly (GMP).
    [[nodiscard]] ExactPolynomial exact() const;

   private:
    void keep(std::size_t k, const MotionPolynomial& m);
    Certificate certificate_;
    std::array<std::uint8_t, 8> degree_{};
    std::array<std::array<double, 4>, 8> motion_{};  // origin, c0, c1, c2
    mutable std::unique_ptr<ExpansionCoefficients> expansions_;
    mutable bool built_ = false;
  };
  /// The only root, simple, strictly between the adjacent doubles lo < hi of the polynomial f
  /// given by `polynomial`, where f goes from sign_lo to -sign_lo (exactly): a deferred root,
  /// whose exact time (GMP) is built only when a comparison needs it.
  static LazyTime deferred_root(std::shared_ptr<const DeferredPolynomial> polynomial, double lo,
                                double hi, int sign_lo);
  /// Doubles at or below / at or above the time: the same or adjacent doubles, always (a bracket
  /// only narrows).
  [[nodiscard]] double lower() const { return lo_; }
  [[nodiscard]] double upper() const { return hi_; }
  /// A deferred root's polynomial and its sign at lower() (else null and 0).
  [[nodiscard]] const DeferredPolynomial* deferred_polynomial() const {
    return kind_ == Kind::Deferred ? deferred_.get() : nullptr;
  }
  [[nodiscard]] int deferred_sign_lo() const { return deferred_sign_lo_; }
  /// True when the time is the double lower() == upper() (a point).
  [[nodiscard]] bool is_double() const { return kind_ == Kind::Double; }
  /// The degree (1 or 2) of the certificate whose root this is, kept as such; 0 otherwise.
  [[nodiscard]] int root_degree() const { return kind_ == Kind::Root ? degree_ : 0; }
  /// The exact time (built on first use).
  [[nodiscard]] ExactTime& exact();
  [[nodiscard]] bool is_exact_built() const { return exact_ != nullptr; }
  /// Refinements of the exact time so far (0 while it was not needed).
  [[nodiscard]] std::size_t refinements() const {
    return exact_ ? exact_->refinements() : std::size_t{0};
  }

  /// sign(a - b), exactly: without GMP when compare_without_gmp() decides, otherwise by the
  /// exact times (exact()).
  friend int compare(LazyTime& a, LazyTime& b);
  /// sign(a - b) when it is decided without GMP (the brackets; equal doubles; two linear roots,
  /// by the determinant; two roots of the same quadratic), else nullopt. Never builds an exact
  /// time.
  friend std::optional<int> compare_without_gmp(const LazyTime& a, const LazyTime& b);
  /// sign(a - b) when the brackets decide it, else 0 (never builds an exact time).
  friend int order_by_brackets(const LazyTime& a, const LazyTime& b);
  friend struct LowDegreeRoots;  // lazy_time.cpp: builds and compares low-degree roots

  /// Components of each coefficient kept inline for a low-degree root.
  static constexpr std::size_t kTerms = 4;

 private:
  enum class Kind : std::uint8_t { Double, Root, General, Deferred };
  explicit LazyTime(Kind kind) : kind_(kind) {}
  /// Refreshes lo_ and hi_ from the exact time (after it was refined).
  void sync();

  /// Every member but the two pointers from `other`, and of a_ only the root's components in
  /// use (the others are never read).
  void copy_plain(const LazyTime& other) {
    kind_ = other.kind_;
    degree_ = other.degree_;
    index_ = other.index_;
    n_ = other.n_;
    deferred_sign_lo_ = other.deferred_sign_lo_;
    lo_ = other.lo_;
    hi_ = other.hi_;
    o_ = other.o_;
    if (kind_ != Kind::Root) return;
    for (std::size_t k = 0; k < 3; ++k)
      for (std::size_t i = 0; i < n_[k]; ++i) a_[k][i] = other.a_[k][i];
  }

  // The members a move always touches first (one cache line with a_[0]'s first component),
  // the root's coefficients last.
  std::unique_ptr<ExactTime> exact_;  // General, or Root / Double once needed (kept out of
                                      // line: rarely built, and the queue moves times)
  std::shared_ptr<const DeferredPolynomial> deferred_;  // Deferred: its polynomial
  Kind kind_ = Kind::Double;
  std::uint8_t degree_ = 0;          // Root: of g below, 1 or 2
  std::uint8_t index_ = 0;           // Root: which root of g, ascending (0 or 1)
  std::array<std::uint8_t, 3> n_{};  // Root: components of a_[k] in use
  std::int8_t deferred_sign_lo_ = 0;  // Deferred: the sign at lo
  double lo_ = 0.0, hi_ = 0.0;
  double o_ = 0.0;  // Root: of g(t) = a0 + a1 (t - o) + a2 (t - o)^2, its leading coefficient
                    // > 0; each a_k an expansion (non-overlapping, increasing magnitude) of
                    // n_[k] components: only those are written and read (a_ is otherwise
                    // uninitialised: not zeroed at every construction)
  std::array<std::array<double, kTerms>, 3> a_;
};

/// The exact decision on a certificate f = upper - lower of degree <= 2 at an exact time now:
/// the sign of f just after now (0: f == 0), and the first root after now where f changes sign
/// (a touching double root is none), without GMP.
struct LowDegreeDecision {
  int sign = 0;
  bool fails = false;
  LazyTime failure;  ///< when fails: a double, or a low-degree root
};
/// The decision above: f's roots bracketed between adjacent doubles by exact signs
/// (floating-point expansions) and placed against now by compare_without_gmp(). nullopt when
/// that cannot decide: motions of degree > 2, coefficients beyond the expansions' domain
/// (2^+-480) or longer than LazyTime::kTerms components, two roots within a double or two of
/// each other, a root whose bracket meets now's (unless both are linear roots, or roots of
/// the same quadratic). The caller then decides exactly with GMP.
[[nodiscard]] std::optional<LowDegreeDecision> decide_low_degree(const MotionPolynomial& upper,
                                                                 const MotionPolynomial& lower,
                                                                 const LazyTime& now);
/// The same for a combination plus[0] + plus[1] - minus[0] - minus[1] of motions of degree <= 2
/// (the sides of moving boxes: a centre plus or minus a half extent).
[[nodiscard]] std::optional<LowDegreeDecision> decide_low_degree(const MotionCombination& f,
                                                                 const LazyTime& now);
/// The same for a product combination (P0 - P1)(P2 - P3) - (M0 - M1)(M2 - M3) of motions of
/// degree <= 1 (orientations of moving points on lines: degree <= 2 in t).
[[nodiscard]] std::optional<LowDegreeDecision> decide_low_degree(const ProductCombination& f,
                                                                 const LazyTime& now);
/// The same for the difference of two squared lengths of moving points on lines (degree <= 2 in
/// t; core/incircle.hpp).
[[nodiscard]] std::optional<LowDegreeDecision> decide_low_degree(const LengthComparison& f,
                                                                 const LazyTime& now);

/// Under the exact scheduler, the exact time of a failure the scheduler computed (empty under the
/// others, and when nothing is to be scheduled). A value (no allocation per decision);
/// Simulator::schedule() takes it to the event queue.
using ExactFailure = std::optional<LazyTime>;

/// The sign part of a LowDegreeDecision.
struct LowDegreeSign {
  int sign = 0;
  bool fails = false;
};
/// decide_low_degree() with the failure root built in place in `failure` (set when the
/// decision fails f, reset otherwise and on nullopt): the scheduler's form, which moves no
/// LazyTime on the way to the event queue.
[[nodiscard]] std::optional<LowDegreeSign> decide_low_degree_into(const MotionPolynomial& upper,
                                                                  const MotionPolynomial& lower,
                                                                  const LazyTime& now,
                                                                  ExactFailure& failure);
[[nodiscard]] std::optional<LowDegreeSign> decide_low_degree_into(const MotionCombination& f,
                                                                  const LazyTime& now,
                                                                  ExactFailure& failure);

/// Signs just after an exact time (the exact scheduler's clock, e.g. Simulator::exact_now()):
/// the filtered predicates when `now` is a double, exact arithmetic on the exact time otherwise.
/// 0 only for the zero polynomial (identical motions, points collinear or co-circular for ever).
[[nodiscard]] int sign_after(const ProductCombination& f, LazyTime& now);
[[nodiscard]] int sign_after(const InCircle& f, LazyTime& now);
[[nodiscard]] int sign_after(const LengthComparison& f, LazyTime& now);
[[nodiscard]] int compare_after(const MotionPolynomial& a, const MotionPolynomial& b,
                                LazyTime& now);

/// The in-circle polynomial of points on lines and parabolas computed in floating-point
/// expansions (no GMP but for one rational per coefficient): what ExactPolynomial::of(InCircle)
/// uses first; nullopt when a motion's degree exceeds 2 or the expansions leave their domain or
/// capacity (then of() computes in rationals).
[[nodiscard]] std::optional<ExactPolynomial> incircle_polynomial_in_expansions(const InCircle& f);

/// A double as an exact rational.
[[nodiscard]] inline mpq_class rational(double x) {
  note_gmp_work();
  return mpq_class(x);
}

}  // namespace kinetic
