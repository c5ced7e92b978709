// Collision detection benchmark (plain timing program): the kinetic broad phases (fat-bvh, bvh,
// sweep-and-prune) against the per-frame broad phases users run today, on the same positions.
//
// For each scene and n in --sizes:
//  1. Kinetic: initialize, then the whole window with `colliding_pairs` asked F times per unit
//     time (F = --frames, 60 by default; --changes: `contact_changes`, the pairs that began and
//     ended since the last frame): events per unit time, CPU per event, CPU per query,
//     total CPU per unit time (events + F queries), heap bytes held. Each run has a CPU budget
//     (--budget); a run that spends it reports the rates of what it processed and is marked.
//  2. Per frame: at the same F frame times every box is evaluated in double (not timed: an
//     engine has its positions), then each peer updates its structure and finds the overlapping
//     pairs (timed): a brute-force sweep-and-prune (sort the low sides on the axis of largest
//     spread, sweep, test the other axes), FCL's DynamicAABBTreeCollisionManager (update() and
//     self collide()), Bullet's btDbvtBroadphase (setAabb per box, calculateOverlappingPairs(),
//     then the pair cache filtered by the boxes' own AABBs, as a dispatcher would before its
//     narrow phase) and Box2D's b2BroadPhase over its b2DynamicTree (2-D scenes only: MoveProxy
//     per box, UpdatePairs() into a persistent contact list, pairs whose fat boxes separated
//     dropped, as b2ContactManager does; Box2D computes in float). Peers are used when found at
//     build time. Every peer's pair count at every frame is checked against the brute force's.
//  3. Ratios against each peer measured in the same run: total cost per unit time (kinetic /
//     per-frame), the break-even frame rate F* = (kinetic event CPU per unit time) / (peer CPU per
//     frame - kinetic CPU per query), and for every contact interval the kinetic structure
//     reported, whether a frame fell inside it: contacts a per-frame broad phase at F frames per
//     unit time misses (tunnelling).
//  4. The three schedulers side by side (classic, robust, exact) for each kinetic structure, on
//     the first scene's motions at the first size (--no-schedulers: left out).
// Scenes: boxes-linear (3-D), boxes-ballistic (3-D), tunnelling (2-D), boxes-mixed (3-D),
// boxes-pile (3-D, at rest); a "-2d" or "-3d" suffix
// picks the dimension (boxes-linear-2d: the scene Box2D can take).
// Options: --sizes=1000,10000  --frames=F (60)  --budget=SECONDS (30)  --seed=S
//          --scenes=boxes-linear,boxes-ballistic,tunnelling
//          --structures=fat-bvh,bvh,sweep-and-prune
//          --peers=brute-sap,fcl,bullet,box2d  --no-rebuild (the BVH's quality policy off)
//          --fattening=2,0.05 (the fat BVH's lookahead and margin, in extents)
//          --changes (the kinetic query per frame is contact_changes)  --no-schedulers
//          --churn=K (K inserts, jumps and removes timed per structure at the scene's start)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <thread>
#include <unordered_set>
#include <utility>
#include <vector>

#if defined(KINETIC_BENCH_HAVE_FCL)
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/narrowphase/collision_object.h>
#endif
#if defined(KINETIC_BENCH_HAVE_BULLET)
#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionDispatch/btDefaultCollisionConfiguration.h>
#include <LinearMath/btAabbUtil2.h>
#endif
#if defined(KINETIC_BENCH_HAVE_BOX2D)
#include <box2d/b2_broad_phase.h>
#include <box2d/b2_collision.h>
#endif

#include "harness.hpp"
#include "kinetic/bvh/kinetic_bvh.hpp"
#include "kinetic/core/boxes.hpp"
#include "kinetic/fat_bvh/kinetic_fat_bvh.hpp"
#include "kinetic/run/timeline_driver.hpp"
#include "kinetic/scenario/generators.hpp"
#include "kinetic/sweep_and_prune/kinetic_sweep_and_prune.hpp"
#include "scheduler_table.hpp"

using kinetic::bench::out;

namespace {

using kinetic::bench::cpu_now;

struct Options {
  std::vector<std::size_t> sizes{1000, 10000};
  int frames = 60;
  double budget = 30.0;
  std::uint64_t seed = 1;
  std::vector<std::string> scenes{"boxes-linear", "boxes-ballistic", "tunnelling"};
  std::vector<std::string> structures{"fat-bvh", "bvh", "sweep-and-prune"};
  std::vector<std::string> peers{"brute-sap", "fcl", "bullet", "box2d"};
  bool rebuild_policy = true;  ///< the BVH's quality policy (--no-rebuild: off)
  /// The fat BVH's fattening (--fattening LOOKAHEAD,MARGIN; KineticFatBvh::set_fattening).
  std::vector<double> fattening{2.0, 0.05};
  bool schedulers = true;  ///< the schedulers side by side (--no-schedulers: left out)
  bool changes = false;    ///< the kinetic query per frame: contact_changes (--changes)
  int churn = 0;           ///< timeline changes timed per structure (--churn; 0: none)
};

/// What a kinetic structure is tuned with before its build, and asked per frame.
struct Tuning {
  bool rebuild_policy = true;
  std::vector<double> fattening;
  bool changes = false;  ///< contact_changes per frame instead of colliding_pairs
};

/// Contact intervals seen through the event log: per pair, begin and end times.
struct ContactLog {
  std::map<std::pair<kinetic::ObjectId, kinetic::ObjectId>, double> open;
  std::vector<std::pair<double, double>> intervals;
  static void record(void* context, kinetic::Time t, const char* kind,
                     std::span<const kinetic::ObjectId> ids, int /*axis*/) {
    auto& log = *static_cast<ContactLog*>(context);
    const std::pair key{ids[0], ids[1]};
    if (kind[8] == 'b') {  // contact_begin
      log.open[key] = t;
    } else if (const auto it = log.open.find(key); it != log.open.end()) {
      log.intervals.emplace_back(it->second, t);
      log.open.erase(it);
    }
  }
};

struct KineticResult {
  bool completed = true;
  double reached = 0.0;  ///< simulated time reached
  double init_cpu = 0.0, event_cpu = 0.0, query_cpu = 0.0;
  double first_query_cpu = 0.0;  ///< the first query's CPU (contact_changes: the whole set)
  std::uint64_t events = 0, queries = 0, answered_pairs = 0;
  std::size_t heap = 0;
  ContactLog contacts;
};

template <class S>
KineticResult run_kinetic(const kinetic::scenario::Scenario& s, int frames, double budget,
                          const Tuning& tuning) {
  KineticResult r;
  // The structure's heap: what its constructor takes (before the table is loaded) and what its
  // build adds.
  std::size_t heap_constructed = 0;
  kinetic::run::TimelineDriver<S> driver(
      s, kinetic::SchedulerKind::Robust, 1e-9,
      kinetic::build_with(
          [&](kinetic::MotionTable& m, kinetic::Simulator& sim, kinetic::Scheduler& scheduler) {
            const std::size_t before = kinetic::bench::heap_bytes();
            auto made = std::make_unique<S>(m, sim, scheduler);
            if constexpr (requires { made->set_rebuild_policy(tuning.rebuild_policy); })
              made->set_rebuild_policy(tuning.rebuild_policy);
            if constexpr (requires { made->set_fattening(1.0, 1.0); })
              made->set_fattening(tuning.fattening.at(0), tuning.fattening.at(1));
            heap_constructed = kinetic::bench::heap_bytes() - before;
            return made;
          }));
  driver.sim().set_event_log(&ContactLog::record, &r.contacts);
  const std::size_t heap0 = kinetic::bench::heap_bytes();
  double c0 = cpu_now();
  S& structure = driver.structure();  // built here
  r.init_cpu = cpu_now() - c0;
  r.heap = heap_constructed + (kinetic::bench::heap_bytes() - heap0);
  const double start = s.start_time, end = *s.end_time;
  const auto n_frames = static_cast<std::size_t>(std::llround((end - start) * frames));
  std::size_t op = 0;
  for (std::size_t f = 1; f <= n_frames; ++f) {
    const double t = start + (end - start) * static_cast<double>(f) / static_cast<double>(n_frames);
    c0 = cpu_now();
    // Timeline changes (the ballistic bounces) at their times, between the frames.
    while (op < s.timeline.size() && s.timeline[op].time <= t) {
      const auto& entry = s.timeline[op++];
      if (entry.op == kinetic::scenario::OpKind::Query) continue;
      (void)driver.advance_to(entry.time);
      driver.apply(entry);
    }
    (void)driver.advance_to(t);
    r.event_cpu += cpu_now() - c0;
    c0 = cpu_now();
    if (tuning.changes) {
      const kinetic::ContactChanges c = structure.contact_changes(t);
      r.answered_pairs += c.begun.size() + c.ended.size() + c.touched.size();
    } else {
      r.answered_pairs += structure.colliding_pairs(t).size();
    }
    if (r.queries == 0) r.first_query_cpu = cpu_now() - c0;
    r.query_cpu += cpu_now() - c0;
    ++r.queries;
    r.reached = t;
    if (r.event_cpu + r.query_cpu > budget) {
      r.completed = f == n_frames;
      break;
    }
  }
  r.events = driver.sim().counters().events();
  return r;
}

/// Timeline changes at the scene's start, one at a time, each timed (the table's change and the
/// structure's repair, through the timeline driver as a run applies them): `changes` inserts of
/// a new box (an object's size and velocity at another object's place), removes of a random box
/// and jumps of a random box to another object's place (a flight-plan update that moves it in
/// every order), interleaved.
struct ChurnResult {
  double insert_cpu = 0.0, remove_cpu = 0.0, jump_cpu = 0.0;
  std::size_t changes = 0;
};

template <class S>
ChurnResult run_churn(const kinetic::scenario::Scenario& s, std::size_t changes, std::uint64_t seed,
                      const Tuning& tuning) {
  kinetic::run::TimelineDriver<S> driver(
      s, kinetic::SchedulerKind::Robust, 1e-9,
      kinetic::build_with(
          [&](kinetic::MotionTable& m, kinetic::Simulator& sim, kinetic::Scheduler& scheduler) {
            auto made = std::make_unique<S>(m, sim, scheduler);
            if constexpr (requires { made->set_fattening(1.0, 1.0); })
              made->set_fattening(tuning.fattening.at(0), tuning.fattening.at(1));
            return made;
          }));
  (void)driver.structure();  // built here, not timed
  std::mt19937_64 rng(seed);
  std::vector<kinetic::ObjectId> alive;
  for (const auto& object : s.objects) alive.push_back(object.id);
  kinetic::ObjectId next_id = 0;
  for (const auto& object : s.objects) next_id = std::max(next_id, object.id + 1);
  // A motion like object a's, placed where object b is.
  const auto placed = [&](std::size_t a, std::size_t b) {
    kinetic::scenario::Motion m = s.objects[a].motion;
    for (std::size_t k = 0; k < m.coordinates.size(); ++k)
      m.coordinates[k][0] = s.objects[b].motion.coordinates[k][0];
    m.origin = s.start_time;
    return m;
  };
  ChurnResult r;
  const std::size_t n = s.objects.size();
  for (std::size_t k = 0; k < changes && n > 0; ++k) {
    kinetic::scenario::TimelineOp insert;
    insert.time = s.start_time;
    insert.op = kinetic::scenario::OpKind::Insert;
    insert.id = next_id++;
    const std::size_t a = rng() % n;
    insert.motion = placed(a, rng() % n);
    insert.half_extents = s.objects[a].half_extents;
    double c0 = cpu_now();
    driver.apply(insert);
    r.insert_cpu += cpu_now() - c0;
    alive.push_back(insert.id);

    kinetic::scenario::TimelineOp jump;
    jump.time = s.start_time;
    jump.op = kinetic::scenario::OpKind::Update;
    jump.id = alive[rng() % alive.size()];
    jump.motion = placed(rng() % n, rng() % n);
    c0 = cpu_now();
    driver.apply(jump);
    r.jump_cpu += cpu_now() - c0;

    kinetic::scenario::TimelineOp remove;
    remove.time = s.start_time;
    remove.op = kinetic::scenario::OpKind::Remove;
    const std::size_t victim = rng() % alive.size();
    remove.id = alive[victim];
    alive[victim] = alive.back();
    alive.pop_back();
    c0 = cpu_now();
    driver.apply(remove);
    r.remove_cpu += cpu_now() - c0;
    ++r.changes;
  }
  return r;
}

/// The boxes at one frame time, evaluated in double: what every per-frame broad phase is given.
struct Frame {
  int d = 0;
  std::vector<std::uint32_t> boxes;  ///< the alive table slots, in order
  std::vector<double> c, h, lo, hi;  ///< per slot: slot * d + axis

  [[nodiscard]] std::size_t at(std::uint32_t slot, int axis) const {
    return slot * static_cast<std::size_t>(d) + static_cast<std::size_t>(axis);
  }
  /// Returns whether the set of boxes changed since the last frame.
  bool evaluate(const kinetic::MotionTable& table, double t) {
    const std::size_t n = table.capacity() * static_cast<std::size_t>(d);
    c.resize(n), h.resize(n), lo.resize(n), hi.resize(n);
    std::vector<std::uint32_t> alive = table.alive_indices();
    const bool changed = alive != boxes;
    boxes = std::move(alive);
    for (const std::uint32_t i : boxes) {
      for (int k = 0; k < d; ++k) {
        const std::size_t x = at(i, k);
        c[x] = kinetic::center(table, i, k).evaluate(t);
        h[x] = kinetic::half_extent(table, i, k).c[0];
        lo[x] = c[x] - h[x];
        hi[x] = c[x] + h[x];
      }
    }
    return changed;
  }
};

/// A per-frame broad phase: built on the first frame's boxes (again when the set of boxes
/// changes), then updated at every frame to the frame's boxes, answering how many pairs overlap.
class Peer {
 public:
  virtual ~Peer() = default;
  [[nodiscard]] virtual const char* name() const = 0;
  [[nodiscard]] virtual bool supports(int d) const { return d >= 1 && d <= 3; }
  virtual void build(const Frame& f) = 0;
  [[nodiscard]] virtual std::size_t pairs(const Frame& f) = 0;
};

/// Brute-force sweep-and-prune: sort on the axis of largest spread of the low sides, sweep.
class BruteSap final : public Peer {
 public:
  [[nodiscard]] const char* name() const override { return "brute-sap"; }
  void build(const Frame&) override {}
  [[nodiscard]] std::size_t pairs(const Frame& f) override {
    order_ = f.boxes;
    int axis = 0;
    double best = -1.0;
    for (int k = 0; k < f.d; ++k) {
      double a = HUGE_VAL, b = -HUGE_VAL;
      for (const std::uint32_t i : order_) {
        a = std::min(a, f.lo[f.at(i, k)]);
        b = std::max(b, f.lo[f.at(i, k)]);
      }
      if (b - a > best) best = b - a, axis = k;
    }
    std::sort(order_.begin(), order_.end(), [&](std::uint32_t a, std::uint32_t b) {
      return f.lo[f.at(a, axis)] < f.lo[f.at(b, axis)];
    });
    std::size_t found = 0;
    for (std::size_t x = 0; x < order_.size(); ++x) {
      const std::uint32_t a = order_[x];
      for (std::size_t y = x + 1; y < order_.size(); ++y) {
        const std::uint32_t b = order_[y];
        if (f.lo[f.at(b, axis)] > f.hi[f.at(a, axis)]) break;
        bool overlap = true;
        for (int k = 0; k < f.d && overlap; ++k)
          overlap = f.lo[f.at(a, k)] <= f.hi[f.at(b, k)] && f.lo[f.at(b, k)] <= f.hi[f.at(a, k)];
        found += overlap ? 1 : 0;
      }
    }
    return found;
  }

 private:
  std::vector<std::uint32_t> order_;
};

#if defined(KINETIC_BENCH_HAVE_FCL) || defined(KINETIC_BENCH_HAVE_BULLET)
/// The frame's box of a slot in 3-D (a 2-D box gets the extent [-0.5, 0.5] on the third axis).
struct Box3 {
  std::array<double, 3> c{0.0, 0.0, 0.0}, h{0.5, 0.5, 0.5};
};
Box3 box3(const Frame& f, std::uint32_t slot) {
  Box3 b;
  for (int k = 0; k < f.d; ++k) {
    b.c[static_cast<std::size_t>(k)] = f.c[f.at(slot, k)];
    b.h[static_cast<std::size_t>(k)] = f.h[f.at(slot, k)];
  }
  return b;
}
#endif

#if defined(KINETIC_BENCH_HAVE_FCL)
/// FCL's dynamic AABB tree broad phase: translations set, AABBs recomputed, update() (refit and
/// FCL's own rebalancing), then the self collide() counting the leaf pairs it reports.
class FclPeer final : public Peer {
 public:
  [[nodiscard]] const char* name() const override { return "fcl"; }
  void build(const Frame& f) override {
    manager_ = std::make_unique<fcl::DynamicAABBTreeCollisionManagerd>();
    objects_.clear();
    slots_ = f.boxes;
    std::vector<fcl::CollisionObjectd*> raw;
    for (const std::uint32_t slot : slots_) {
      const Box3 b = box3(f, slot);
      auto shape = std::make_shared<fcl::Boxd>(2.0 * b.h[0], 2.0 * b.h[1], 2.0 * b.h[2]);
      fcl::Transform3d tf = fcl::Transform3d::Identity();
      tf.translation() = fcl::Vector3d(b.c[0], b.c[1], b.c[2]);
      objects_.push_back(std::make_unique<fcl::CollisionObjectd>(shape, tf));
      raw.push_back(objects_.back().get());
    }
    manager_->registerObjects(raw);
    manager_->setup();
  }
  [[nodiscard]] std::size_t pairs(const Frame& f) override {
    for (std::size_t k = 0; k < slots_.size(); ++k) {
      const Box3 b = box3(f, slots_[k]);
      objects_[k]->setTranslation(fcl::Vector3d(b.c[0], b.c[1], b.c[2]));
      objects_[k]->computeAABB();
    }
    manager_->update();
    std::size_t found = 0;
    manager_->collide(&found, [](fcl::CollisionObjectd*, fcl::CollisionObjectd*, void* data) {
      ++*static_cast<std::size_t*>(data);
      return false;  // not done: every pair
    });
    return found;
  }

 private:
  std::unique_ptr<fcl::DynamicAABBTreeCollisionManagerd> manager_;
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects_;
  std::vector<std::uint32_t> slots_;
};
#endif

#if defined(KINETIC_BENCH_HAVE_BULLET)
/// Bullet's dynamic AABB tree broad phase (btDbvtBroadphase, double precision): setAabb per box,
/// calculateOverlappingPairs(), then the pair cache's pairs whose boxes overlap (the cache keeps
/// pairs of the fattened tree leaves and removes stale ones incrementally; a dispatcher filters
/// them by the proxies' AABBs before its narrow phase, as here).
class BulletPeer final : public Peer {
 public:
  ~BulletPeer() override { clear(); }
  [[nodiscard]] const char* name() const override { return "bullet"; }
  void build(const Frame& f) override {
    clear();
    broadphase_ = std::make_unique<btDbvtBroadphase>();
    slots_ = f.boxes;
    for (const std::uint32_t slot : slots_) {
      const auto [lo, hi] = aabb(f, slot);
      proxies_.push_back(
          broadphase_->createProxy(lo, hi, BOX_SHAPE_PROXYTYPE, nullptr, 1, -1, &dispatcher_));
    }
    broadphase_->calculateOverlappingPairs(&dispatcher_);
  }
  [[nodiscard]] std::size_t pairs(const Frame& f) override {
    for (std::size_t k = 0; k < slots_.size(); ++k) {
      const auto [lo, hi] = aabb(f, slots_[k]);
      broadphase_->setAabb(proxies_[k], lo, hi, &dispatcher_);
    }
    broadphase_->calculateOverlappingPairs(&dispatcher_);
    const btBroadphasePairArray& cache =
        broadphase_->getOverlappingPairCache()->getOverlappingPairArray();
    std::size_t found = 0;
    for (int k = 0; k < cache.size(); ++k) {
      const btBroadphaseProxy* a = cache[k].m_pProxy0;
      const btBroadphaseProxy* b = cache[k].m_pProxy1;
      found += TestAabbAgainstAabb2(a->m_aabbMin, a->m_aabbMax, b->m_aabbMin, b->m_aabbMax) ? 1 : 0;
    }
    return found;
  }

 private:
  static std::pair<btVector3, btVector3> aabb(const Frame& f, std::uint32_t slot) {
    const Box3 b = box3(f, slot);
    return {btVector3(b.c[0] - b.h[0], b.c[1] - b.h[1], b.c[2] - b.h[2]),
            btVector3(b.c[0] + b.h[0], b.c[1] + b.h[1], b.c[2] + b.h[2])};
  }
  void clear() {
    if (broadphase_)
      for (btBroadphaseProxy* p : proxies_) broadphase_->destroyProxy(p, &dispatcher_);
    proxies_.clear();
    broadphase_.reset();
  }
  btDefaultCollisionConfiguration configuration_;
  btCollisionDispatcher dispatcher_{&configuration_};
  std::unique_ptr<btDbvtBroadphase> broadphase_;
  std::vector<btBroadphaseProxy*> proxies_;
  std::vector<std::uint32_t> slots_;
};
#endif

#if defined(KINETIC_BENCH_HAVE_BOX2D)
/// Box2D's broad phase (b2BroadPhase over b2DynamicTree, float, 2-D): MoveProxy per box with its
/// displacement since the last frame, UpdatePairs() adding new candidate pairs to a persistent
/// contact list, then, as b2ContactManager::Collide does, pairs whose fat boxes no longer overlap
/// dropped and those whose boxes overlap counted.
class Box2dPeer final : public Peer {
 public:
  [[nodiscard]] const char* name() const override { return "box2d"; }
  [[nodiscard]] bool supports(int d) const override { return d == 2; }
  void build(const Frame& f) override {
    broadphase_ = std::make_unique<b2BroadPhase>();
    slots_ = f.boxes;
    index_.resize(slots_.size());
    proxies_.clear();
    boxes_.assign(slots_.size(), b2AABB{});
    last_.assign(slots_.size(), b2Vec2{});
    contacts_.clear();
    known_.clear();
    for (std::size_t k = 0; k < slots_.size(); ++k) {
      index_[k] = static_cast<std::uint32_t>(k);
      set(f, k);
      proxies_.push_back(broadphase_->CreateProxy(boxes_[k], &index_[k]));
    }
    broadphase_->UpdatePairs(this);
  }
  [[nodiscard]] std::size_t pairs(const Frame& f) override {
    for (std::size_t k = 0; k < slots_.size(); ++k) {
      const b2Vec2 before = last_[k];
      set(f, k);
      broadphase_->MoveProxy(proxies_[k], boxes_[k], last_[k] - before);
    }
    broadphase_->UpdatePairs(this);
    std::size_t found = 0;
    for (std::size_t k = 0; k < contacts_.size();) {
      const auto [a, b] = contacts_[k];
      if (!broadphase_->TestOverlap(proxies_[a], proxies_[b])) {
        known_.erase(key(a, b));
        contacts_[k] = contacts_.back();
        contacts_.pop_back();
        continue;
      }
      found += b2TestOverlap(boxes_[a], boxes_[b]) ? 1 : 0;
      ++k;
    }
    return found;
  }
  /// b2BroadPhase::UpdatePairs' callback: a candidate pair (possibly one already in the list).
  void AddPair(void* a, void* b) {
    std::uint32_t x = *static_cast<std::uint32_t*>(a), y = *static_cast<std::uint32_t*>(b);
    if (x > y) std::swap(x, y);
    if (known_.insert(key(x, y)).second) contacts_.emplace_back(x, y);
  }

 private:
  static std::uint64_t key(std::uint32_t a, std::uint32_t b) {
    return (static_cast<std::uint64_t>(a) << 32) | b;
  }
  void set(const Frame& f, std::size_t k) {
    const std::uint32_t slot = slots_[k];
    const double cx = f.c[f.at(slot, 0)], cy = f.c[f.at(slot, 1)];
    const double hx = f.h[f.at(slot, 0)], hy = f.h[f.at(slot, 1)];
    boxes_[k].lowerBound.Set(static_cast<float>(cx - hx), static_cast<float>(cy - hy));
    boxes_[k].upperBound.Set(static_cast<float>(cx + hx), static_cast<float>(cy + hy));
    last_[k].Set(static_cast<float>(cx), static_cast<float>(cy));
  }
  std::unique_ptr<b2BroadPhase> broadphase_;
  std::vector<std::uint32_t> slots_, index_;
  std::vector<std::int32_t> proxies_;
  std::vector<b2AABB> boxes_;
  std::vector<b2Vec2> last_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> contacts_;
  std::unordered_set<std::uint64_t> known_;
};
#endif

std::unique_ptr<Peer> make_peer(const std::string& name) {
  if (name == "brute-sap") return std::make_unique<BruteSap>();
#if defined(KINETIC_BENCH_HAVE_FCL)
  if (name == "fcl") return std::make_unique<FclPeer>();
#endif
#if defined(KINETIC_BENCH_HAVE_BULLET)
  if (name == "bullet") return std::make_unique<BulletPeer>();
#endif
#if defined(KINETIC_BENCH_HAVE_BOX2D)
  if (name == "box2d") return std::make_unique<Box2dPeer>();
#endif
  return nullptr;
}

struct PeerResult {
  std::string name;
  double init_cpu = 0.0, cpu = 0.0, reached = 0.0;
  std::uint64_t frames = 0, pairs = 0, pair_mismatches = 0;
  std::size_t heap = 0;
  bool completed = true;
};

/// Runs the peers over the frames up to `until`, all on the same frames; the first peer (the
/// brute force) is the reference count of every frame. A peer that spends `budget` stops there.
std::vector<PeerResult> run_per_frame(const kinetic::scenario::Scenario& s, int frames,
                                      double until, double budget,
                                      std::vector<std::unique_ptr<Peer>>& peers) {
  std::vector<PeerResult> results(peers.size());
  for (std::size_t p = 0; p < peers.size(); ++p) results[p].name = peers[p]->name();
  Frame frame;
  frame.d = s.dimension;
  struct Null {  // the table follows the timeline; nothing kinetic is maintained
    bool built = false;
    void initialize() { built = true; }
    kinetic::EventKind process(const kinetic::Event&) { return kinetic::EventKind::Internal; }
    void insert(std::uint32_t) {}
    void remove(std::uint32_t) {}
    void motion_changed(std::uint32_t) {}
    [[nodiscard]] bool initialized() const { return built; }
    [[nodiscard]] bool validate() const { return true; }
    [[nodiscard]] std::uint64_t certificates() const { return 0; }
    [[nodiscard]] std::uint64_t certificates_per_object_max() const { return 0; }
    [[nodiscard]] kinetic::NamedCounters named_counters() const { return {}; }
  };
  kinetic::run::TimelineDriver<Null> driver(
      s, kinetic::SchedulerKind::Robust, 1e-9,
      kinetic::build_with([](kinetic::MotionTable&, kinetic::Simulator&, kinetic::Scheduler&) {
        return std::make_unique<Null>();
      }));
  const double start = s.start_time, end = *s.end_time;
  const auto n_frames = static_cast<std::size_t>(std::llround((end - start) * frames));
  std::size_t op = 0;
  for (std::size_t f = 1; f <= n_frames; ++f) {
    const double t = start + (end - start) * static_cast<double>(f) / static_cast<double>(n_frames);
    if (t > until) break;
    while (op < s.timeline.size() && s.timeline[op].time <= t) {
      const auto& entry = s.timeline[op++];
      if (entry.op == kinetic::scenario::OpKind::Query) continue;
      (void)driver.advance_to(entry.time);
      driver.apply(entry);
    }
    const bool changed = frame.evaluate(driver.motions(), t);
    std::optional<std::uint64_t> reference;
    for (std::size_t p = 0; p < peers.size(); ++p) {
      PeerResult& r = results[p];
      if (!r.completed) continue;
      if (changed || f == 1) {
        const std::size_t heap0 = kinetic::bench::heap_bytes();
        const double c0 = cpu_now();
        peers[p]->build(frame);
        r.init_cpu += cpu_now() - c0;
        r.heap = kinetic::bench::heap_bytes() - heap0;
      }
      const double c0 = cpu_now();
      const std::size_t found = peers[p]->pairs(frame);
      r.cpu += cpu_now() - c0;
      r.pairs += found;
      if (!reference) reference = found;
      r.pair_mismatches += found != *reference ? 1 : 0;
      ++r.frames;
      r.reached = t;
      if (r.cpu > budget) r.completed = f == n_frames;
    }
  }
  return results;
}

double per(double a, double b) { return b > 0.0 ? a / b : 0.0; }

/// "boxes-linear-2d" -> ("boxes-linear", 2); no suffix -> the dataset's own dimension (0).
std::pair<std::string, int> scene_of(const std::string& name) {
  for (const auto& [suffix, d] : {std::pair{"-2d", 2}, std::pair{"-3d", 3}}) {
    const std::size_t len = 3;
    if (name.size() > len && name.compare(name.size() - len, len, suffix) == 0)
      return {name.substr(0, name.size() - len), d};
  }
  return {name, 0};
}

/// The scene of `kinetic generate` named `name` (a "-2d" or "-3d" suffix picks the dimension)
/// with n boxes.
kinetic::scenario::Scenario scene_scenario(const std::string& name, std::size_t n,
                                           std::uint64_t seed) {
  const auto [scene, dimension] = scene_of(name);
  kinetic::scenario::GeneratorOptions g;
  g.n = n;
  g.seed = seed;
  g.dimension = dimension;
  return kinetic::scenario::generate(scene, g);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  bool no_rebuild = false;
  kinetic::bench::Harness harness(
      "bench_collision",
      "the kinetic BVHs (over fat boxes and exact boxes) and sweep-and-prune (robust scheduling, "
      "eps 1e-9) against per-frame broad "
      "phases (brute-force sort and sweep, FCL, Bullet, Box2D) on moving boxes, CPU per unit of "
      "simulated time at F frames per unit time");
  harness.sizes(o.sizes);
  harness.option("--frames", o.frames, "frames (queries) per unit of simulated time, F");
  harness.budget(o.budget, "CPU seconds per run at most");
  harness.seed(o.seed);
  harness.list("--scenes", o.scenes, "the scenes (datasets of kinetic generate)");
  harness.list("--structures", o.structures,
               "the kinetic structures (fat-bvh, bvh, sweep-and-prune)");
  harness.list("--peers", o.peers, "the per-frame peers (brute-sap, fcl, bullet, box2d)");
  harness.flag("--no-rebuild", no_rebuild, "the BVH's quality policy off (no rebuilds)");
  bool no_schedulers = false;
  harness.flag("--no-schedulers", no_schedulers,
               "leave out the three schedulers side by side (section 4)");
  harness.flag("--changes", o.changes,
               "the kinetic query per frame is contact_changes (the pairs begun and ended since "
               "the last frame), not colliding_pairs");
  harness.option("--churn", o.churn,
                 "inserts, jumps and removes (each) timed per structure at the scene's start, "
                 "after the runs (0: none)");
  std::vector<std::string> fattening{"2", "0.05"};
  harness.list("--fattening", fattening,
               "the fat BVH's fattening: lookahead (extents travelled), margin (extents)");
  harness.parse(argc, argv);
  o.rebuild_policy = !no_rebuild;
  o.schedulers = !no_schedulers;
  o.fattening.clear();
  for (const std::string& v : fattening) o.fattening.push_back(std::strtod(v.c_str(), nullptr));
  if (o.fattening.size() != 2 || !(o.fattening[0] >= 0.0) || !(o.fattening[1] > 0.0)) {
    std::fprintf(stderr, "bench_collision: --fattening takes LOOKAHEAD,MARGIN (>= 0, > 0)\n");
    return 2;
  }
  if (o.frames < 1) {
    std::fprintf(stderr, "bench_collision: --frames must be at least 1\n");
    return 2;
  }
  if (o.scenes.empty() || o.structures.empty()) {
    std::fprintf(stderr, "bench_collision: --scenes and --structures name one at least\n");
    return 2;
  }
  harness.configured();
  out("per-frame peers:");
  for (const std::string& p : o.peers)
    out(" %s%s", p.c_str(), make_peer(p) ? "" : " (not available)");
  out("\n\n");
  out("| scene | n | method | reached | init ms | events/ut | us/event | us/query | CPU s/ut | "
      "heap MB | missed/contacts |\n|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const std::string& scene_name : o.scenes) {
    for (const std::size_t n : o.sizes) {
      const kinetic::scenario::Scenario s = scene_scenario(scene_name, n, o.seed);
      struct Row {
        std::string name;
        double event_per_ut, per_query, total_per_ut;
      };
      std::vector<Row> kinetic_rows;
      double reached = s.start_time;
      for (const std::string& structure : o.structures) {
        const Tuning tuning{o.rebuild_policy, o.fattening, o.changes};
        const KineticResult k =
            structure == "bvh" ? run_kinetic<kinetic::KineticBvh>(s, o.frames, o.budget, tuning)
            : structure == "fat-bvh"
                ? run_kinetic<kinetic::KineticFatBvh>(s, o.frames, o.budget, tuning)
                : run_kinetic<kinetic::KineticSweepAndPrune>(s, o.frames, o.budget, tuning);
        const double simulated = k.reached - s.start_time;
        reached = std::max(reached, k.reached);
        const double per_query = per(k.query_cpu, static_cast<double>(k.queries));
        const double total_per_ut = per(k.event_cpu + k.query_cpu, simulated);
        std::size_t missed = 0;
        for (const auto& [b, e] : k.contacts.intervals) {
          // A frame time start + j / F lies in [b, e] unless floor(e F) < ceil(b F).
          const double fb = std::ceil((b - s.start_time) * o.frames);
          const double fe = std::floor((e - s.start_time) * o.frames);
          missed += fe < fb ? 1 : 0;
        }
        char contacts[48];
        std::snprintf(contacts, sizeof contacts, "%zu/%zu", missed, k.contacts.intervals.size());
        out("| %s | %zu | %s | %.2f%s | %.1f | %.0f | %.2f | %.1f | %.4f | %.1f | %s |\n",
            scene_name.c_str(), n, structure.c_str(), simulated, k.completed ? "" : "*",
            1e3 * k.init_cpu, per(static_cast<double>(k.events), simulated),
            1e6 * per(k.event_cpu, static_cast<double>(k.events)), 1e6 * per_query, total_per_ut,
            static_cast<double>(k.heap) / 1e6, contacts);
        if (o.changes && k.queries > 1) {
          const double later =
              per(k.query_cpu - k.first_query_cpu, static_cast<double>(k.queries - 1));
          out("|  |  | (%s: the first contact_changes %.2f ms, each later one %.2f us; CPU per "
              "frame after the first %.2f us) |  |  |  |  |  |  |  |  |\n",
              structure.c_str(), 1e3 * k.first_query_cpu, 1e6 * later,
              1e6 * per(k.event_cpu + k.query_cpu - k.first_query_cpu,
                        static_cast<double>(k.queries - 1)));
        }
        std::fflush(stdout);
        kinetic_rows.push_back({structure, per(k.event_cpu, simulated), per_query, total_per_ut});
      }
      std::vector<std::unique_ptr<Peer>> peers;
      peers.push_back(std::make_unique<BruteSap>());  // the reference count, always first
      for (const std::string& p : o.peers) {
        if (p == "brute-sap") continue;
        if (auto peer = make_peer(p); peer && peer->supports(s.dimension))
          peers.push_back(std::move(peer));
      }
      const std::vector<PeerResult> frames = run_per_frame(s, o.frames, reached, o.budget, peers);
      for (const PeerResult& r : frames) {
        const double simulated = r.reached - s.start_time;
        char check[48];
        std::snprintf(check, sizeof check, "%s", r.pair_mismatches == 0 ? "pairs =" : "");
        if (r.pair_mismatches != 0)
          std::snprintf(check, sizeof check, "pairs differ x%llu",
                        static_cast<unsigned long long>(r.pair_mismatches));
        char method[48];
        std::snprintf(method, sizeof method, "frame %s", r.name.c_str());
        out("| %s | %zu | %s | %.2f%s | %.1f | %s | %s | %.1f | %.4f | %.1f | %s |\n",
            scene_name.c_str(), n, method, simulated, r.completed ? "" : "*", 1e3 * r.init_cpu, "-",
            "-", 1e6 * per(r.cpu, static_cast<double>(r.frames)), per(r.cpu, simulated),
            static_cast<double>(r.heap) / 1e6, check);
      }
      for (const Row& k : kinetic_rows) {
        out("%-18s %7zu   %s against each peer: ratio (F*)", scene_name.c_str(), n, k.name.c_str());
        for (const PeerResult& r : frames) {
          const double per_frame = per(r.cpu, static_cast<double>(r.frames));
          const double frame_per_ut = per(r.cpu, r.reached - s.start_time);
          const double break_even =
              per_frame > k.per_query ? k.event_per_ut / (per_frame - k.per_query) : HUGE_VAL;
          out("  %s %.3f (%.0f)", r.name.c_str(), per(k.total_per_ut, frame_per_ut), break_even);
        }
        out("\n");
      }
      std::fflush(stdout);
    }
  }
  out("\nreached: simulated time processed (* the CPU budget ran out first: rates are those of "
      "what was processed); ut: unit of simulated time; us/query: CPU per colliding_pairs "
      "(kinetic; with --changes per contact_changes) or per frame (update + pairs, peers); CPU "
      "s/ut: events + F queries (kinetic) or "
      "F frames (peers) per unit time; contacts: contact intervals the kinetic structure reported "
      "(begun and ended in the processed time); init ms: CPU to build before the first frame "
      "(peers: "
      "every build); missed: those with no frame inside, contacts a "
      "per-frame broad phase at F frames per unit time never sees; pairs =: the peer's pair count "
      "equals the brute force's at every frame; ratio: kinetic / peer CPU per unit time (< 1: "
      "the kinetic structure is cheaper); F*: the frame rate above which it is cheaper\n");

  // 5 (first, when asked). Inserts, removes and jumps, each timed.
  if (o.churn > 0) {
    out("\ntimeline changes at the start (--churn=%d of each; robust scheduling):\n\n"
        "| scene | n | structure | us per insert | us per jump | us per remove |\n"
        "|---|---:|---|---:|---:|---:|\n",
        o.churn);
    for (const std::string& scene_name : o.scenes) {
      for (const std::size_t n : o.sizes) {
        const kinetic::scenario::Scenario s = scene_scenario(scene_name, n, o.seed);
        const Tuning tuning{o.rebuild_policy, o.fattening, o.changes};
        const auto changes = static_cast<std::size_t>(o.churn);
        for (const std::string& structure : o.structures) {
          const ChurnResult c =
              structure == "bvh" ? run_churn<kinetic::KineticBvh>(s, changes, o.seed, tuning)
              : structure == "fat-bvh"
                  ? run_churn<kinetic::KineticFatBvh>(s, changes, o.seed, tuning)
                  : run_churn<kinetic::KineticSweepAndPrune>(s, changes, o.seed, tuning);
          const auto count = static_cast<double>(c.changes);
          out("| %s | %zu | %s | %.2f | %.2f | %.2f |\n", scene_name.c_str(), n, structure.c_str(),
              1e6 * per(c.insert_cpu, count), 1e6 * per(c.jump_cpu, count),
              1e6 * per(c.remove_cpu, count));
        }
      }
    }
  }

  // 4. The three schedulers side by side (exact beside robust and classic) for each structure:
  // the first scene's motions (its timeline, e.g. the ballistic bounces, left out), the smallest
  // size (--no-schedulers: left out).
  if (o.schedulers) {
    const kinetic::scenario::Scenario s = scene_scenario(o.scenes.front(), o.sizes.front(), o.seed);
    const kinetic::MotionTable table = kinetic::run::table_of(s);
    const double end = kinetic::run::end_of(s);
    for (const std::string& structure : o.structures) {
      if (structure == "fat-bvh") {
        kinetic::bench::print_scheduler_table<kinetic::KineticFatBvh>(
            "fat-bvh", o.scenes.front().c_str(), table, s.start_time, end, 1e-9, o.budget);
      } else if (structure == "bvh") {
        kinetic::bench::print_scheduler_table<kinetic::KineticBvh>(
            "bvh", o.scenes.front().c_str(), table, s.start_time, end, 1e-9, o.budget);
      } else {
        kinetic::bench::print_scheduler_table<kinetic::KineticSweepAndPrune>(
            "sweep-and-prune", o.scenes.front().c_str(), table, s.start_time, end, 1e-9, o.budget);
      }
    }
  }
  return 0;
}
