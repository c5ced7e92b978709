#include "kinetic/scenario/generators.hpp"

#include "box_datasets.hpp"
#include "random.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace kinetic::scenario {
namespace {

using detail::evaluate;
using detail::Rng;
using detail::root;
using detail::stream;
using detail::uniform;
using detail::uniform01;
using detail::uniform_index;

/// Uniform in the unit disk by rejection from the square (uniform in area, no trigonometry).
std::array<double, 2> disk_point(Rng& rng) {
  for (;;) {
    const double a = uniform(rng, -1.0, 1.0), b = uniform(rng, -1.0, 1.0);
    if (a * a + b * b <= 1.0) return {a, b};
  }
}

/// Uniform on the unit circle: a disk point (away from the centre) projected radially; the angle
/// is uniform because the disk point's is. |a^2 + b^2 - 1| is a few ulps.
std::array<double, 2> circle_point(Rng& rng) {
  for (;;) {
    const auto [a, b] = disk_point(rng);
    const double r2 = a * a + b * b;
    if (r2 >= 0x1p-10) {
      const double r = std::sqrt(r2);
      return {a / r, b / r};
    }
  }
}

enum class Kind { RandomLinear, RandomPoly, Grids, Parabola, RandDc, RandCr, Circle };

constexpr std::array<const char*, 7> kNames = {"random-linear", "random-poly", "grids", "parabola",
                                               "randdc",        "randcr",      "circle"};

// Paper datasets (Section 6): GRIDS and PARABOLA put integer-valued dual points / apexes on the
// odd integers -(k-1), -(k-3), ..., k-1 (spacing 2, centred on 0, exact); inserted objects use
// the even integers in between so they never duplicate an original trajectory.
constexpr double kParabolaA = 1.0;    // leading coefficient of every PARABOLA trajectory
constexpr double kRandWindow = 10.0;  // RANDDC / RANDCR window [-10, 10]: crossing times are
                                      // standard Cauchy, 2/pi atan(10) = 93.7% inside
// CIRCLE (2-D, for the convex hull): points on the unit circle breathing in and out and turning.
constexpr double kCircleWindow = 10.0;  // window [0, 10]
constexpr double kCircleBreath = 0.02;  // radius 1 - alpha at the point's own time tau
constexpr double kCircleTurn = 0.05;    // tangential speed (a linearised rotation)

class Generator {
 public:
  Generator(Kind kind, const GeneratorOptions& options) : kind_(kind), options_(options) {
    const auto n = static_cast<double>(options.n);
    side_ = root(n, options.dimension);
    k_ = 1;
    while (k_ * k_ < options.n) ++k_;
  }

  [[nodiscard]] std::array<double, 2> default_window() const {
    const auto k = static_cast<double>(k_);
    switch (kind_) {
      case Kind::RandomLinear:
      case Kind::RandomPoly:
        return {0.0, 10.0};
      case Kind::Grids:
        return {-k, k};  // all crossings lie in [-(k-1), k-1]
      case Kind::Parabola:
        return {-1.5 * k, 1.5 * k};  // all crossings in +-1.5(k-1)
      case Kind::RandDc:
      case Kind::RandCr:
        return {-kRandWindow, kRandWindow};
      case Kind::Circle:
        return {0.0, kCircleWindow};
    }
    return {0.0, 10.0};
  }

  [[nodiscard]] Motion initial(std::size_t index, Rng& rng) const {
    return scaled(initial_unscaled(index, rng));
  }

  /// Motion of an object inserted at time t.
  [[nodiscard]] Motion inserted(double t, Rng& rng) const {
    return scaled(inserted_unscaled(t, rng));
  }

  /// Flight-plan change at time t: continue from the current (rounded, already scaled) position
  /// with a fresh velocity / fresh higher coefficients of the dataset's kind, scaled.
  [[nodiscard]] Motion updated(const Motion& old, double t, Rng& rng) const {
    Motion motion = updated_unscaled(old, t, rng);
    for (auto& c : motion.coordinates) {
      for (std::size_t i = 1; i < c.size(); ++i) c[i] *= options_.scale;
    }
    return motion;
  }

 private:
  [[nodiscard]] Motion scaled(Motion motion) const {
    if (options_.scale != 1.0) {
      for (auto& c : motion.coordinates) {
        for (double& x : c) {
          x *= options_.scale;
          if (!std::isfinite(x)) {
            throw std::invalid_argument("scale " + std::to_string(options_.scale) +
                                        " makes a coefficient overflow");
          }
        }
      }
    }
    return motion;
  }

  [[nodiscard]] Motion initial_unscaled(std::size_t index, Rng& rng) const {
    switch (kind_) {
      case Kind::RandomLinear:
      case Kind::RandomPoly:
        return fresh(0.0, rng);
      case Kind::Grids:  // row-major: row = slope, column = intercept
        return {{{grid(index % k_), grid(index / k_)}}, 0.0};
      case Kind::Parabola:  // row = apex time, column = apex position
        return {{{grid(index % k_), 0.0, kParabolaA}}, grid(index / k_)};
      case Kind::RandDc:
      case Kind::RandCr:
        return fresh(0.0, rng);
      case Kind::Circle:
        return circle_motion(rng);
    }
    return {};
  }

  [[nodiscard]] Motion inserted_unscaled(double t, Rng& rng) const {
    switch (kind_) {
      case Kind::Grids: {
        const double a = grid(uniform_index(rng, k_)) + 1.0, b = grid(uniform_index(rng, k_)) + 1.0;
        return {{{b, a}}, 0.0};
      }
      case Kind::Parabola: {
        const double apex_t = grid(uniform_index(rng, k_)) + 1.0;
        const double apex_x = grid(uniform_index(rng, k_)) + 1.0;
        return {{{apex_x, 0.0, kParabolaA}}, apex_t};
      }
      case Kind::Circle:
        return circle_motion(rng);
      default:
        return fresh(t, rng);
    }
  }

  /// The new motion's constant term is the current position (scaled already); the others are
  /// unscaled here.
  [[nodiscard]] Motion updated_unscaled(const Motion& old, double t, Rng& rng) const {
    Motion motion{{}, t};
    if (kind_ == Kind::Circle) {
      // From the current position on, the velocity and acceleration a fresh point has at t.
      const Motion fresh_point = circle_motion(rng);
      for (std::size_t axis = 0; axis < 2; ++axis) {
        const auto& f = fresh_point.coordinates[axis];
        motion.coordinates.push_back(
            {evaluate(old.coordinates[axis], old.origin, t), f[1] + 2.0 * f[2] * t, f[2]});
      }
      return motion;
    }
    for (const auto& c : old.coordinates) {
      const double value = evaluate(c, old.origin, t);
      switch (kind_) {
        case Kind::RandomLinear:
          motion.coordinates.push_back({value, uniform(rng, -1.0, 1.0)});
          break;
        case Kind::RandomPoly:
          motion.coordinates.push_back(poly(value, rng));
          break;
        case Kind::Grids:
          motion.coordinates.push_back({value, grid(uniform_index(rng, k_))});
          break;
        case Kind::Parabola: {  // congruent parabola through the current point, apex time on grid
          const double slope = 2.0 * kParabolaA * (t - grid(uniform_index(rng, k_)));
          motion.coordinates.push_back({value, slope, kParabolaA});
          break;
        }
        case Kind::RandDc:
          motion.coordinates.push_back({value, disk_point(rng)[0]});
          break;
        case Kind::RandCr:
          motion.coordinates.push_back({value, circle_point(rng)[0]});
          break;
        case Kind::Circle:  // handled above
          break;
      }
    }
    return motion;
  }

  /// The i-th of k values -(k-1), -(k-3), ..., k-1 (exact integers).
  [[nodiscard]] double grid(std::size_t i) const {
    return static_cast<double>(2 * i) - static_cast<double>(k_ - 1);
  }

  [[nodiscard]] std::vector<double> poly(double c0, Rng& rng) const {
    std::vector<double> c{c0};
    double factorial = 1.0;
    for (int power = 1; power <= options_.degree; ++power) {
      factorial *= power;
      c.push_back(uniform(rng, -1.0, 1.0) / factorial);
    }
    return c;
  }

  /// CIRCLE: a point u uniform on the unit circle, a time tau uniform in [0, W]; radius
  /// r(t) = 1 - alpha + alpha ((t - tau) / W)^2 (the point dips in to 1 - alpha at tau and comes
  /// back out), turned by a tangential velocity omega: p(t) = r(t) u + omega t u^perp. Degree 2,
  /// origin 0.
  [[nodiscard]] static Motion circle_motion(Rng& rng) {
    const auto [ux, uy] = circle_point(rng);
    const double tau = uniform(rng, 0.0, kCircleWindow);
    const double w2 = kCircleWindow * kCircleWindow;
    const double r0 = 1.0 - kCircleBreath + kCircleBreath * tau * tau / w2;
    const double r1 = -2.0 * kCircleBreath * tau / w2;
    const double r2 = kCircleBreath / w2;
    return {{{ux * r0, ux * r1 - kCircleTurn * uy, ux * r2},
             {uy * r0, uy * r1 + kCircleTurn * ux, uy * r2}},
            0.0};
  }

  /// A random motion with the given origin (random-linear, random-poly, randdc, randcr).
  [[nodiscard]] Motion fresh(double origin, Rng& rng) const {
    Motion motion{{}, origin};
    switch (kind_) {
      case Kind::RandomLinear:
        for (int axis = 0; axis < options_.dimension; ++axis) {
          const double position = uniform(rng, 0.0, side_);
          motion.coordinates.push_back({position, uniform(rng, -1.0, 1.0)});
        }
        break;
      case Kind::RandomPoly:
        for (int axis = 0; axis < options_.dimension; ++axis)
          motion.coordinates.push_back(poly(uniform(rng, 0.0, side_), rng));
        break;
      case Kind::RandDc:
      case Kind::RandCr: {  // dual point (a, b) is the line x = a t + b
        const auto [a, b] = kind_ == Kind::RandDc ? disk_point(rng) : circle_point(rng);
        motion.coordinates.push_back({b, a});
        break;
      }
      default:
        break;
    }
    return motion;
  }

  Kind kind_;
  const GeneratorOptions& options_;
  double side_ = 0.0;  ///< L = n^(1/d)
  std::size_t k_ = 1;  ///< grid side ceil(sqrt(n)), at least 1
};

[[noreturn]] void fail(const std::string& message) { throw std::invalid_argument(message); }

/// A query of the requested type; geometric parameters are drawn inside the bounding box of the
/// initial objects at that time, so that answers are neither always empty nor always everything.
QuerySpec make_query(const GeneratorOptions& options, const std::vector<ObjectSpec>& objects,
                     double t, Rng& rng) {
  QuerySpec query;
  query.type = options.query_type;
  const auto d = static_cast<std::size_t>(options.dimension);
  std::vector<std::array<double, 2>> bounds(d, {0.0, 0.0});
  switch (query.type) {
    case QueryType::Range:
    case QueryType::Nearest:
    case QueryType::KNearest:
    case QueryType::Farthest:
    case QueryType::ApproxRange:
    case QueryType::Stab:
    case QueryType::CollidingPairs:
      for (std::size_t axis = 0; axis < d; ++axis) {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const auto& object : objects) {
          const double x = evaluate(object.motion.coordinates[axis], object.motion.origin, t);
          lo = std::min(lo, x);
          hi = std::max(hi, x);
        }
        if (lo <= hi) bounds[axis] = {lo, hi};
      }
      break;
    default:
      break;
  }
  auto inside = [&](std::size_t axis) { return uniform(rng, bounds[axis][0], bounds[axis][1]); };
  switch (query.type) {
    case QueryType::Range:
      for (std::size_t axis = 0; axis < d; ++axis) {
        const double a = inside(axis), b = inside(axis);
        query.box.push_back({std::min(a, b), std::max(a, b)});
      }
      break;
    case QueryType::Nearest:
    case QueryType::Farthest:
      for (std::size_t axis = 0; axis < d; ++axis) query.point.push_back(inside(axis));
      query.eps = 0.1;
      break;
    case QueryType::KNearest:  // exact (eps 0), ten of them: what a k-nearest user asks most
      for (std::size_t axis = 0; axis < d; ++axis) query.point.push_back(inside(axis));
      query.k = 10;
      break;
    case QueryType::ApproxRange: {
      query.shape.kind = Shape::Kind::Disk;
      double width = std::numeric_limits<double>::infinity();
      for (std::size_t axis = 0; axis < d; ++axis) {
        query.shape.disk.center.push_back(inside(axis));
        width = std::min(width, bounds[axis][1] - bounds[axis][0]);
      }
      query.shape.disk.radius = width / 4;
      query.eps = 0.1;
      break;
    }
    case QueryType::Stab:
      query.x = inside(0);
      break;
    default:
      break;
  }
  return query;
}

}  // namespace

const std::vector<std::string>& dataset_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all(kNames.begin(), kNames.end());
    for (const std::string& b : detail::box_dataset_names()) all.push_back(b);
    return all;
  }();
  return names;
}

double unit_scale(const std::string& dataset, std::size_t n) {
  if (detail::is_box_dataset(dataset)) return 1.0;
  if (std::find(kNames.begin(), kNames.end(), dataset) == kNames.end())
    fail("unknown dataset '" + dataset + "'");
  if (dataset != "grids" && dataset != "parabola") return 1.0;
  std::size_t k = 1;
  while (k * k < n) ++k;
  return k > 1 ? 1.0 / static_cast<double>(k - 1) : 1.0;
}

Scenario generate(const std::string& dataset, const GeneratorOptions& requested) {
  if (detail::is_box_dataset(dataset)) return detail::generate_boxes(dataset, requested);
  const auto found = std::find(kNames.begin(), kNames.end(), dataset);
  if (found == kNames.end()) {
    std::string known;
    for (const std::string& name : dataset_names()) known += (known.empty() ? "" : ", ") + name;
    fail("unknown dataset '" + dataset + "'; known datasets: " + known);
  }
  const auto kind = static_cast<Kind>(found - kNames.begin());
  const bool any_dimension = kind == Kind::RandomLinear || kind == Kind::RandomPoly;
  const int fixed_dimension = kind == Kind::Circle ? 2 : 1;
  GeneratorOptions options = requested;
  if (options.dimension == 0) options.dimension = fixed_dimension;  // the dataset's own
  if (options.dimension < 1 || (!any_dimension && options.dimension != fixed_dimension))
    fail("dataset '" + dataset + "' needs dimension " +
         (any_dimension ? ">= 1" : std::to_string(fixed_dimension)) + ", got " +
         std::to_string(options.dimension));
  if (kind == Kind::RandomPoly && (options.degree < 1 || options.degree > 6))
    fail("dataset 'random-poly' needs degree 1..6, got " + std::to_string(options.degree));
  if (!(options.scale > 0.0) || !std::isfinite(options.scale))
    fail("scale must be a finite number > 0, got " + std::to_string(options.scale));
  if (options.removes > options.n || (options.updates > 0 && options.removes >= options.n))
    fail(
        "removes must be <= n (and < n when there are updates), so that an object is alive "
        "whenever one is updated or removed");

  const Generator generator(kind, options);
  Scenario scenario;
  scenario.dimension = options.dimension;
  const auto window = generator.default_window();
  scenario.start_time = options.start_time.value_or(window[0]);
  const double end = options.end_time.value_or(window[1]);
  scenario.end_time = end;
  const double start = scenario.start_time;
  if (!std::isfinite(start) || !std::isfinite(end) || !(start < end))
    fail("the time window must be finite with start < end, got [" + std::to_string(start) + ", " +
         std::to_string(end) + "]");
  const std::size_t changes = options.updates + options.inserts + options.removes;
  if (changes > 0 && std::nextafter(start, end) >= end)
    fail("the time window has no time strictly inside it for timeline changes");

  Rng object_rng = stream(options.seed, 0), query_rng = stream(options.seed, 1),
      change_rng = stream(options.seed, 2);
  for (std::size_t i = 0; i < options.n; ++i)
    scenario.objects.push_back({static_cast<ObjectId>(i), generator.initial(i, object_rng)});

  // Changes: draw the times, sort them, then replay so that ids are chosen among the alive ones.
  const auto planned = detail::plan_changes(change_rng, start, end, options.updates,
                                            options.inserts, options.removes);

  std::vector<Motion> current(options.n + options.inserts);
  std::vector<ObjectId> alive;
  for (const auto& object : scenario.objects) {
    current[static_cast<std::size_t>(object.id)] = object.motion;
    alive.push_back(object.id);
  }
  auto next_id = static_cast<ObjectId>(options.n);
  std::vector<TimelineOp> timeline;
  for (const auto& [t, op] : planned) {
    TimelineOp entry;
    entry.time = t;
    entry.op = op;
    if (op == OpKind::Insert) {
      entry.id = next_id++;
      entry.motion = generator.inserted(t, change_rng);
      alive.push_back(entry.id);
    } else {
      const std::size_t slot = uniform_index(change_rng, alive.size());
      entry.id = alive[slot];
      if (op == OpKind::Update) {
        entry.motion =
            generator.updated(current[static_cast<std::size_t>(entry.id)], t, change_rng);
      } else {
        alive[slot] = alive.back();
        alive.pop_back();
      }
    }
    if (op != OpKind::Remove) current[static_cast<std::size_t>(entry.id)] = entry.motion;
    timeline.push_back(std::move(entry));
  }

  for (std::size_t i = 0; i < options.queries; ++i) {
    TimelineOp entry;
    entry.time = i + 1 == options.queries ? end
                                          : start + static_cast<double>(i + 1) * (end - start) /
                                                        static_cast<double>(options.queries);
    entry.query = make_query(options, scenario.objects, entry.time, query_rng);
    timeline.push_back(std::move(entry));
  }
  // Changes precede queries at equal times, so a query sees a change made at its own time.
  std::stable_sort(timeline.begin(), timeline.end(),
                   [](const TimelineOp& a, const TimelineOp& b) { return a.time < b.time; });
  for (std::size_t i = 0; i < timeline.size(); ++i) timeline[i].file_index = i;
  scenario.timeline = std::move(timeline);
  return scenario;
}

}  // namespace kinetic::scenario
