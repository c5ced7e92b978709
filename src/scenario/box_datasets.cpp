#include "box_datasets.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "kinetic/core/polynomial.hpp"
#include "kinetic/core/predicates.hpp"
#include "random.hpp"

namespace kinetic::scenario::detail {
namespace {

[[noreturn]] void fail(const std::string& message) { throw std::invalid_argument(message); }

// boxes-linear: half extents in [0.25, 0.75] (sizes 0.5 to 1.5, 1 on average), centers uniform
// in a cube of side kLinearSpacing n^(1/d), velocities uniform in [-1, 1] per axis: a box
// travels about its own size per unit time.
constexpr double kLinearSpacing = 3.0;
constexpr double kHalfMin = 0.25, kHalfMax = 0.75;
constexpr double kLinearWindow = 10.0;

// boxes-ballistic: the last axis is vertical, the floor is at 0. Gravity g = 2 (the center's
// height is z0 + v (t - t0) - (t - t0)^2); a box bounces when its low side reaches the floor,
// leaving with kRestitution times its impact speed, and comes to rest (constant motion: a pile
// on the floor) when that speed would be below kRestSpeed.
constexpr double kGravityHalf = 1.0;  // g / 2
constexpr double kRestitution = 0.75;
constexpr double kRestSpeed = 0.3;
constexpr double kDropHeight = 5.0;  // initial low sides in [0, 5] above the floor
constexpr double kBallisticWindow = 10.0;

// tunnelling: thin static walls across axis 0 and small fast boxes flying along it. A bullet
// moves 20 to 40 per unit time, i.e. 0.33 to 0.67 per frame at 60 frames per unit time, while
// it overlaps a wall over 2 (kWallHalf + kBulletHalf) = 0.06 of its path: a per-frame test sees
// about one crossing in ten.
constexpr double kWallHalf = 0.005;
constexpr double kWallSpan = 10.0;  // walls cover [0, 10] on the other axes
constexpr double kWallSpacing = 2.0;
constexpr double kBulletHalf = 0.025;
constexpr double kBulletSpeedMin = 20.0, kBulletSpeedMax = 40.0;
constexpr double kTunnellingWindow = 1.0;

// boxes-mixed: mixed sizes and speeds on lines, at boxes-linear's density: 1 % of the boxes
// (at least one) small and fast (half extents in [0.1, 0.25], up to 10 per unit time per axis,
// ten times boxes-linear's), 4 % large and slow (half extents in [1.5, 3], up to 0.05), the rest
// boxes-linear's sizes at a tenth of its speed (up to 0.1): a few fast objects among many slow
// ones, as in a game or a robot's world.
struct BoxClass {
  double half_min, half_max;  // half extents uniform in [half_min, half_max] per axis
  double speed;               // velocity uniform in [-speed, speed] per axis
};
constexpr BoxClass kLinearClass{kHalfMin, kHalfMax, 1.0};
constexpr BoxClass kFastClass{0.1, 0.25, 10.0};
constexpr BoxClass kLargeClass{1.5, 3.0, 0.05};
constexpr BoxClass kSlowClass{kHalfMin, kHalfMax, 0.1};
constexpr double kFastShare = 0.01, kLargeShare = 0.04;

// boxes-pile: a pile at rest. Columns on the unit grid of the first d - 1 axes (half extents
// 0.5 there: neighbouring columns touch face to face; d = 1: one column), each a stack along
// the last axis of about kPileLevels boxes of heights in {0.5, 0.625, ..., 1.5} (multiples of 1/8:
// every side a double, exactly), the lowest on the floor at 0. Nothing moves: every contact holds
// for the whole window, and a kinetic structure has no event to process.
constexpr std::size_t kPileLevels = 8;
constexpr double kPileWindow = 10.0;

enum class BoxKind { Linear, Ballistic, Tunnelling, Mixed, Pile };

const std::vector<std::string> kBoxNames = {"boxes-linear", "boxes-ballistic", "tunnelling",
                                            "boxes-mixed", "boxes-pile"};

std::vector<double> half_extents(Rng& rng, int d, const BoxClass& c = kLinearClass) {
  std::vector<double> h;
  for (int k = 0; k < d; ++k) h.push_back(uniform(rng, c.half_min, c.half_max));
  return h;
}

/// A box on a line at time t (origin t): center uniform in [0, side]^d, its class's velocity
/// and half extents (boxes-linear's by default).
ObjectSpec linear_box(ObjectId id, Rng& rng, int d, double side, double t,
                      const BoxClass& c = kLinearClass) {
  Motion m{{}, t};
  for (int k = 0; k < d; ++k)
    m.coordinates.push_back({uniform(rng, 0.0, side), uniform(rng, -c.speed, c.speed)});
  return {id, m, half_extents(rng, d, c)};
}

/// The class of the i-th of n initial boxes-mixed boxes: the first 1 % (at least one) fast, the
/// next 4 % large, the rest slow.
const BoxClass& mixed_class(std::size_t i, std::size_t n) {
  const auto fast =
      std::max<std::size_t>(1, static_cast<std::size_t>(kFastShare * static_cast<double>(n)));
  const auto large = static_cast<std::size_t>(kLargeShare * static_cast<double>(n));
  return i < fast ? kFastClass : i < fast + large ? kLargeClass : kSlowClass;
}

/// The ballistic flights of one box from its initial motion: the bounce updates in the window.
void ballistic_bounces(const ObjectSpec& box, double end, std::vector<TimelineOp>& out) {
  const auto d = box.motion.coordinates.size();
  const double h = box.half_extents[d - 1];
  Motion m = box.motion;
  for (;;) {
    const auto& z = m.coordinates[d - 1];
    if (z.size() < 3) return;  // at rest
    // z0 + v tau - tau^2 = h: tau = (v + sqrt(v^2 + 4 (z0 - h))) / 2, the later root.
    const double z0 = z[0], v = z[1];
    const double tau0 = (v + std::sqrt(v * v + 4.0 * std::max(0.0, z0 - h))) / 2.0;
    // The bounce at the last double where the low side is still >= 0, exactly: the box never
    // dips below the floor (a dip of one rounding would pass every box resting there).
    Time t = m.origin + tau0;
    const MotionPolynomial height = MotionPolynomial::from(z, m.origin);
    for (int k = 0; k < 64 && compare_at_value(height, h, t) < 0; ++k)
      t = std::nextafter(t, m.origin);
    const double tau = t - m.origin;
    if (!(t < end) || !(tau > 0.0)) return;
    const double speed = kRestitution * (2.0 * kGravityHalf * tau - v);  // e |impact velocity|
    Motion next{{}, t};
    const bool rest = speed < kRestSpeed;
    for (std::size_t k = 0; k + 1 < d; ++k) {
      const auto& c = m.coordinates[k];
      const double x = evaluate(c, m.origin, t);
      if (rest) {
        next.coordinates.push_back({x});
      } else {
        next.coordinates.push_back({x, c[1]});
      }
    }
    if (rest) {
      next.coordinates.push_back({h});  // resting on the floor: the low side is 0, exactly
    } else {
      next.coordinates.push_back({h, speed, -kGravityHalf});
    }
    TimelineOp op;
    op.time = t;
    op.op = OpKind::Update;
    op.id = box.id;
    op.motion = next;
    out.push_back(op);
    m = next;
  }
}

}  // namespace

const std::vector<std::string>& box_dataset_names() { return kBoxNames; }

bool is_box_dataset(const std::string& name) {
  return std::find(kBoxNames.begin(), kBoxNames.end(), name) != kBoxNames.end();
}

Scenario generate_boxes(const std::string& name, const GeneratorOptions& requested) {
  const auto kind =
      static_cast<BoxKind>(std::find(kBoxNames.begin(), kBoxNames.end(), name) - kBoxNames.begin());
  GeneratorOptions options = requested;
  const bool on_lines = kind == BoxKind::Linear || kind == BoxKind::Mixed;
  const int lowest = on_lines || kind == BoxKind::Pile ? 1 : 2;
  if (options.dimension == 0) options.dimension = kind == BoxKind::Tunnelling ? 2 : 3;
  if (options.dimension < lowest || options.dimension > 3) {
    fail("dataset '" + name + "' needs dimension " + std::to_string(lowest) + " to 3, got " +
         std::to_string(options.dimension));
  }
  if (options.scale != 1.0) fail("dataset '" + name + "' takes no scale");
  if (options.query_type != QueryType::Sorted && options.query_type != QueryType::CollidingPairs) {
    fail("dataset '" + name + "' asks colliding_pairs queries, got " +
         to_string(options.query_type));
  }
  const std::size_t changes = options.updates + options.inserts + options.removes;
  if (!on_lines && changes > 0) {
    fail("dataset '" + name + "' makes its own timeline (" +
         (kind == BoxKind::Ballistic ? std::string("the bounces are its updates")
          : kind == BoxKind::Pile    ? std::string("a pile at rest")
                                     : std::string("static walls and straight flights")) +
         "); it takes no --updates, --inserts or --removes");
  }
  if (options.removes > options.n || (options.updates > 0 && options.removes >= options.n))
    fail("removes must be <= n (and < n when there are updates)");
  const int d = options.dimension;
  const double window = on_lines                     ? kLinearWindow
                        : kind == BoxKind::Ballistic ? kBallisticWindow
                        : kind == BoxKind::Pile      ? kPileWindow
                                                     : kTunnellingWindow;
  Scenario s;
  s.dimension = d;
  s.objects_are = ObjectsAre::Boxes;
  s.start_time = options.start_time.value_or(0.0);
  const double end = options.end_time.value_or(window);
  s.end_time = end;
  const double start = s.start_time;
  if (!std::isfinite(start) || !std::isfinite(end) || !(start < end)) {
    fail("the time window must be finite with start < end, got [" + std::to_string(start) + ", " +
         std::to_string(end) + "]");
  }
  Rng rng = stream(options.seed, 0), query_rng = stream(options.seed, 1),
      change_rng = stream(options.seed, 2);
  (void)query_rng;
  const auto n = static_cast<double>(options.n);
  std::vector<TimelineOp> timeline;

  if (on_lines) {
    const double side = kLinearSpacing * root(std::max(1.0, n), d);
    // Each box's class, by id (boxes-linear: all one class).
    std::vector<const BoxClass*> classes;
    for (std::size_t i = 0; i < options.n; ++i) {
      classes.push_back(kind == BoxKind::Mixed ? &mixed_class(i, options.n) : &kLinearClass);
      s.objects.push_back(
          linear_box(static_cast<ObjectId>(i), rng, d, side, start, *classes.back()));
    }
    // Changes at random times: a new velocity from the current position, a new box, a removal.
    const auto planned =
        plan_changes(change_rng, start, end, options.updates, options.inserts, options.removes);
    std::vector<Motion> current;
    std::vector<ObjectId> alive;
    for (const ObjectSpec& o : s.objects) {
      current.push_back(o.motion);
      alive.push_back(o.id);
    }
    auto next_id = static_cast<ObjectId>(options.n);
    for (const auto& [t, op] : planned) {
      TimelineOp entry;
      entry.time = t;
      entry.op = op;
      if (op == OpKind::Insert) {
        const BoxClass* c = &kLinearClass;
        if (kind == BoxKind::Mixed) {
          const double u = uniform01(change_rng);
          c = u < kFastShare                 ? &kFastClass
              : u < kFastShare + kLargeShare ? &kLargeClass
                                             : &kSlowClass;
        }
        classes.push_back(c);
        ObjectSpec box = linear_box(next_id++, change_rng, d, side, t, *c);
        entry.id = box.id;
        entry.motion = box.motion;
        entry.half_extents = box.half_extents;
        current.push_back(box.motion);
        alive.push_back(box.id);
      } else {
        const std::size_t slot = uniform_index(change_rng, alive.size());
        entry.id = alive[slot];
        if (op == OpKind::Update) {
          Motion& m = current[static_cast<std::size_t>(entry.id)];
          Motion next{{}, t};
          const double speed = classes[static_cast<std::size_t>(entry.id)]->speed;
          for (const auto& c : m.coordinates)
            next.coordinates.push_back(
                {evaluate(c, m.origin, t), uniform(change_rng, -speed, speed)});
          m = next;
          entry.motion = next;
        } else {
          alive[slot] = alive.back();
          alive.pop_back();
        }
      }
      timeline.push_back(std::move(entry));
    }
  } else if (kind == BoxKind::Ballistic) {
    const double side = kLinearSpacing * root(std::max(1.0, n), d - 1);
    for (std::size_t i = 0; i < options.n; ++i) {
      Motion m{{}, start};
      for (int k = 0; k + 1 < d; ++k)
        m.coordinates.push_back({uniform(rng, 0.0, side), uniform(rng, -0.5, 0.5)});
      std::vector<double> h = half_extents(rng, d);
      const double z0 = h.back() + uniform(rng, 0.0, kDropHeight);
      m.coordinates.push_back({z0, uniform(rng, -2.0, 2.0), -kGravityHalf});
      s.objects.emplace_back(static_cast<ObjectId>(i), m, h);
      ballistic_bounces(s.objects.back(), end, timeline);
    }
    std::stable_sort(timeline.begin(), timeline.end(),
                     [](const TimelineOp& a, const TimelineOp& b) { return a.time < b.time; });
  } else if (kind == BoxKind::Pile) {
    const std::size_t columns =  // d = 1: one column, the boxes end to end
        d == 1 ? 1 : std::max<std::size_t>(1, (options.n + kPileLevels - 1) / kPileLevels);
    const auto across = static_cast<std::size_t>(
        d == 1 ? 1.0 : std::ceil(root(static_cast<double>(columns), d - 1) - 1e-9));
    std::vector<double> top(columns, 0.0);  // each column's height so far
    for (std::size_t i = 0; i < options.n; ++i) {
      const std::size_t column = i % columns;
      Motion m{{}, start};
      std::vector<double> h;
      std::size_t cell = column;
      for (int k = 0; k + 1 < d; ++k) {  // the column's cell on the unit grid
        m.coordinates.push_back({static_cast<double>(cell % across) + 0.5});
        h.push_back(0.5);
        cell /= across;
      }
      const double height = 0.5 + 0.125 * static_cast<double>(uniform_index(rng, 9));
      m.coordinates.push_back({top[column] + height / 2});
      h.push_back(height / 2);
      top[column] += height;
      s.objects.emplace_back(static_cast<ObjectId>(i), m, h);
    }
  } else {  // tunnelling
    const std::size_t walls = std::max<std::size_t>(1, options.n / 20);
    const double corridor = kWallSpacing * static_cast<double>(walls);
    for (std::size_t i = 0; i < options.n; ++i) {
      Motion m{{}, start};
      std::vector<double> h;
      if (i < walls) {
        m.coordinates.push_back({kWallSpacing * (static_cast<double>(i) + 0.5)});
        h.push_back(kWallHalf);
        for (int k = 1; k < d; ++k) {
          m.coordinates.push_back({kWallSpan / 2});
          h.push_back(kWallSpan / 2);
        }
      } else {
        const double speed = uniform(rng, kBulletSpeedMin, kBulletSpeedMax);
        m.coordinates.push_back(
            {uniform(rng, 0.0, corridor), uniform01(rng) < 0.5 ? -speed : speed});
        h.push_back(kBulletHalf);
        for (int k = 1; k < d; ++k) {
          m.coordinates.push_back({uniform(rng, 0.5, kWallSpan - 0.5), uniform(rng, -1.0, 1.0)});
          h.push_back(kBulletHalf);
        }
      }
      s.objects.emplace_back(static_cast<ObjectId>(i), m, h);
    }
  }

  for (std::size_t i = 0; i < options.queries; ++i) {
    TimelineOp entry;
    entry.time = i + 1 == options.queries ? end
                                          : start + static_cast<double>(i + 1) * (end - start) /
                                                        static_cast<double>(options.queries);
    entry.query.type = QueryType::CollidingPairs;
    timeline.push_back(std::move(entry));
  }
  // Changes precede queries at equal times, so a query sees a change made at its own time.
  std::stable_sort(timeline.begin(), timeline.end(),
                   [](const TimelineOp& a, const TimelineOp& b) { return a.time < b.time; });
  for (std::size_t i = 0; i < timeline.size(); ++i) timeline[i].file_index = i;
  s.timeline = std::move(timeline);
  return s;
}

}  // namespace kinetic::scenario::detail
