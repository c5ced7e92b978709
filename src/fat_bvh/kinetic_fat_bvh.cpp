#include "kinetic/fat_bvh/kinetic_fat_bvh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "kinetic/core/crop.hpp"
#include "kinetic/core/error.hpp"
#include "kinetic/core/pair_set.hpp"

namespace kinetic {
namespace {

const MotionPolynomial kZero{};

/// The range of p over [t, t + T] in double (T finite >= 0): its ends, the vertex of a parabola,
/// and for higher degrees samples widened a little. Only how fat a box is rests on it: the
/// containment certificate is exact.
std::pair<double, double> range_over(const MotionPolynomial& p, Time t, Time T) {
  double lo = p.evaluate(t), hi = lo;
  if (p.degree == 0) return {lo, hi};
  const auto take = [&](double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  };
  take(p.evaluate(t + T));
  if (p.degree == 2 && p.c[2] != 0.0) {
    const Time vertex = p.origin - p.c[1] / (2.0 * p.c[2]);
    if (vertex > t && vertex < t + T) take(p.evaluate(vertex));
  } else if (p.degree > 2) {
    constexpr int kSamples = 32;
    for (int s = 1; s < kSamples; ++s) take(p.evaluate(t + T * s / kSamples));
    const double widen = 0.05 * (hi - lo);
    lo -= widen;
    hi += widen;
  }
  return {lo, hi};
}

/// A containment comparison: sign(fat high - box high) or sign(box low - fat low), > 0 inside.
struct InsideCombination {
  MotionPolynomial wall;
  MotionPolynomial negated_half;
  MotionCombination f;
  InsideCombination(const MotionTable& boxes, std::uint32_t box, int axis, bool high,
                    const ConstantBox& fat)
      : wall(MotionPolynomial::constant(high ? fat.hi[static_cast<std::size_t>(axis)]
                                             : fat.lo[static_cast<std::size_t>(axis)])),
        negated_half(half_extent(boxes, box, axis)) {
    negated_half.c[0] = -negated_half.c[0];  // exact
    const MotionPolynomial& c = center(boxes, box, axis);
    f = high ? MotionCombination{{&wall, &kZero}, {&c, &half_extent(boxes, box, axis)}}
             : MotionCombination{{&c, &negated_half}, {&wall, &kZero}};
  }
  InsideCombination(const InsideCombination&) = delete;
  InsideCombination& operator=(const InsideCombination&) = delete;
};

/// Whether failure a comes before failure b (exactly when both are exact times).
bool earlier(Scheduler::SignDecision& a, Scheduler::SignDecision& b) {
  if (a.exact && b.exact) return compare(*a.exact, *b.exact) < 0;
  return a.failure < b.failure;
}

}  // namespace

KineticFatBvh::KineticFatBvh(const MotionTable& boxes, Simulator& simulator,
                             const Scheduler& scheduler)
    : BoxContacts(boxes, simulator, "KineticFatBvh::colliding_pairs",
                  "KineticFatBvh::contact_changes"),
      scheduler_(scheduler),
      d_(box_dimension(boxes)),
      tree_(box_dimension(boxes)) {
  require_box_table(boxes, "KineticFatBvh");
  simulator.attach(scheduler);
  owners_ = simulator.reserve_owners(2);
  for (int axis = 0; axis < d_; ++axis) keys_.emplace_back(boxes, axis);
}

void KineticFatBvh::set_fattening(double lookahead, double margin) {
  if (!(lookahead >= 0.0 && std::isfinite(lookahead)) || !(margin > 0.0 && std::isfinite(margin)))
    throw PreconditionError(
        "KineticFatBvh::set_fattening: lookahead must be >= 0 and margin > 0,"
        " both finite");
  lookahead_ = lookahead;
  margin_ = margin;
}

NamedCounters KineticFatBvh::named_counters() const {
  return {{"refits", counters_.refits},
          {"containment_checks", counters_.containment_checks},
          {"pair_events", counters_.pair_events},
          {"pairs_made", counters_.pairs_made},
          {"pairs_dropped", counters_.pairs_dropped},
          {"pairs_apart_for_ever", counters_.pairs_apart_for_ever},
          {"contact_begins", counters_.contact_begins},
          {"contact_ends", counters_.contact_ends},
          {"instant_contacts", counters_.instant_contacts},
          {"tree_rotations", tree_.rotations()},
          {"inserts", counters_.inserts},
          {"removes", counters_.removes},
          {"updates", counters_.updates},
          {"queries", counters_.queries}};
}

void KineticFatBvh::grow(std::size_t capacity) {
  if (fat_.size() >= capacity) return;
  fat_.resize(capacity);
  fat_since_.resize(capacity, 0.0);
  leaf_.resize(capacity, kNoIndex);
  inside_.resize(capacity);
  pairs_of_.resize(capacity);
  mark_.resize(capacity, kNoIndex);
  piece_refits_.resize(capacity, 0);
}

Scheduler::SignDecision KineticFatBvh::decide_pair(std::uint32_t a, std::uint32_t b, int k) const {
  const int axis = k / 2;
  const std::uint32_t x = k % 2 == 0 ? a : b, y = k % 2 == 0 ? b : a;
  const Time window_lo = std::max(boxes_.valid_from(a), boxes_.valid_from(b));
  return keys_[static_cast<std::size_t>(axis)].decide(
      scheduler_, BoxEndpointKeys::key(y, BoxSide::Low), BoxEndpointKeys::key(x, BoxSide::High),
      sim_.now(), window_lo, sim_.counters());
}

Scheduler::SignDecision KineticFatBvh::decide_inside(std::uint32_t box, int k) const {
  const auto axis = static_cast<std::size_t>(k / 2);
  if (std::isinf(k % 2 == 1 ? fat_[box].hi[axis] : fat_[box].lo[axis]))
    return {1, kTimeInfinity, {}};  // no wall on this side
  const InsideCombination f(boxes_, box, k / 2, k % 2 == 1, fat_[box]);
  // A side that moves away from its wall (or stays), inside now: it never reaches the wall, and
  // every scheduler decides {+1, never} (the exact sign now, then the motion's slope): no root
  // isolation. Half the walls of a box in linear motion.
  const MotionPolynomial& c = center(boxes_, box, k / 2);
  if (c.degree <= 1) {
    const double velocity = c.degree == 1 ? c.c[1] : 0.0;
    const bool away = k % 2 == 1 ? velocity <= 0.0 : velocity >= 0.0;
    if (away && sign_at(f.f, sim_.now()) > 0) return {1, kTimeInfinity, {}};
  }
  const Time window_lo = std::max(boxes_.valid_from(box), fat_since_[box]);
  return scheduler_.decide(f.f, sim_.now(), window_lo, sim_.counters());
}

bool KineticFatBvh::schedule_inside(std::uint32_t box) {
  std::array<Scheduler::SignDecision, 6> ds;
  int first = -1;
  for (int k = 0; k < 2 * d_; ++k) {
    Scheduler::SignDecision& d = ds[static_cast<std::size_t>(k)];
    d = decide_inside(box, k);
    if (d.sign <= 0) return false;
    if (d.failure == kTimeInfinity) continue;
    if (first < 0 || earlier(d, ds[static_cast<std::size_t>(first)])) first = k;
  }
  if (first < 0) {
    sim_.cancel(inside_[box]);
    return true;
  }
  Scheduler::SignDecision& d = ds[static_cast<std::size_t>(first)];
  sim_.reschedule(inside_[box], d.failure, std::move(d.exact), owners_[0], box);
  return true;
}

void KineticFatBvh::fatten(std::uint32_t box) {
  const Time t = sim_.now();
  double extent = 0.0, speed = 0.0;
  bool moving = false;
  for (int k = 0; k < d_; ++k) {
    extent = std::max(extent, 2.0 * half_extent(boxes_, box, k).c[0]);
    const MotionPolynomial& c = center(boxes_, box, k);
    moving = moving || c.degree > 0;
    speed = std::max(speed, std::fabs(c.derivative(t)));
  }
  if (extent == 0.0) extent = unit_extent_;
  // The lookahead: the time to travel `lookahead` extents, halved while the path strays further
  // (an accelerating box), never below the floor.
  const double reach = lookahead_ * extent;
  Time lookahead = 0.0;
  Time floor = kMinLookahead;  // after kSteadyRefits refits of one motion, twice as far each
  if (moving) {
    lookahead = speed > 0.0 ? reach / speed : 1.0;
    if (!(lookahead > 0.0 && std::isfinite(lookahead))) lookahead = 1.0;
    const std::uint32_t refits = piece_refits_[box];
    if (refits > kSteadyRefits) {
      floor = std::ldexp(std::max(lookahead, kMinLookahead),
                         static_cast<int>(std::min<std::uint32_t>(refits - kSteadyRefits, 4096)));
    }
    lookahead = std::max(lookahead, floor);
  }
  ConstantBox fat;
  for (int halvings = 0;; ++halvings) {
    bool strays = false;
    for (int k = 0; k < d_; ++k) {
      const auto [lo, hi] = range_over(center(boxes_, box, k), t, lookahead);
      const auto i = static_cast<std::size_t>(k);
      const double h = half_extent(boxes_, box, k).c[0];
      fat.lo[i] = lo - h;
      fat.hi[i] = hi + h;
      strays = strays || hi - lo > 2.0 * reach;
    }
    if (!strays || halvings == 40 || lookahead <= floor) break;
    lookahead = std::max(lookahead / 2, floor);
  }
  fat_since_[box] = t;
  // The margin doubles until the box is inside just after now (at once, but for sides beyond
  // what a double holds: an infinite wall is no certificate, and the last try has only those).
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (double m = margin_ * extent;; m *= 2) {
    for (std::size_t i = 0; i < static_cast<std::size_t>(d_); ++i) {
      const double lo = std::nextafter(fat.lo[i] - m, -kInf);
      const double hi = std::nextafter(fat.hi[i] + m, kInf);
      fat_[box].lo[i] = lo > -kInf && std::isfinite(m) ? lo : -kInf;  // NaN too
      fat_[box].hi[i] = hi < kInf && std::isfinite(m) ? hi : kInf;
    }
    if (schedule_inside(box)) break;
  }
  if (building_) return;  // initialize() builds the tree over every fat box at once
  if (leaf_[box] != kNoIndex) tree_.remove(leaf_[box]);
  leaf_[box] = tree_.insert(fat_[box], box);
}

std::uint32_t KineticFatBvh::add_pair(std::uint32_t a, std::uint32_t b) {
  std::uint32_t p;
  if (!free_pairs_.empty()) {
    p = free_pairs_.back();
    free_pairs_.pop_back();
  } else {
    p = static_cast<std::uint32_t>(pairs_.size());
    pairs_.emplace_back();
  }
  Pair& r = pairs_[p];
  r = Pair{};
  r.box = {a, b};
  r.state = State::Separated;
  for (std::size_t e = 0; e < 2; ++e) {
    r.at[e] = static_cast<std::uint32_t>(pairs_of_[r.box[e]].size());
    pairs_of_[r.box[e]].push_back(p);
  }
  ++live_pairs_;
  ++counters_.pairs_made;
  return p;
}

void KineticFatBvh::drop_pair(std::uint32_t p) {
  Pair& r = pairs_[p];
  sim_.cancel(r.handle);
  for (std::size_t e = 0; e < 2; ++e) {
    std::vector<std::uint32_t>& list = pairs_of_[r.box[e]];
    const std::uint32_t moved = list.back();
    list[r.at[e]] = moved;
    Pair& m = pairs_[moved];
    m.at[m.box[0] == r.box[e] ? 0 : 1] = r.at[e];
    list.pop_back();
  }
  r = Pair{};
  free_pairs_.push_back(p);
  --live_pairs_;
  ++counters_.pairs_dropped;
}

void KineticFatBvh::set_contact(std::uint32_t p, bool contact, bool quiet) {
  const std::uint32_t a = pairs_[p].box[0], b = pairs_[p].box[1];
  if (contact) {
    begin_contact(a, b);
  } else {
    end_contact(a, b);
  }
  if (quiet) return;
  ++(contact ? counters_.contact_begins : counters_.contact_ends);
  log_contact(contact, a, b);
}

void KineticFatBvh::note_if_touching(std::uint32_t a, std::uint32_t b, int axis) {
  if (!boxes_overlap_at(boxes_, a, b, sim_.now(), axis)) return;
  ++counters_.instant_contacts;
  ended_.note_now(sim_, a, b);
}

int KineticFatBvh::apart_for_ever(std::uint32_t a, std::uint32_t b) const {
  for (int axis = 0; axis < d_; ++axis) {
    const MotionPolynomial& ca = center(boxes_, a, axis);
    const MotionPolynomial& cb = center(boxes_, b, axis);
    if (ca.degree > 1 || cb.degree > 1 || half_extent(boxes_, a, axis).degree > 0 ||
        half_extent(boxes_, b, axis).degree > 0)
      continue;
    const double va = ca.degree == 1 ? ca.c[1] : 0.0, vb = cb.degree == 1 ? cb.c[1] : 0.0;
    const auto& keys = keys_[static_cast<std::size_t>(axis)];
    for (int which = 0; which < 2; ++which) {
      // low(y) - high(x) moves at v_y - v_x: it never falls when y is no slower than x.
      const std::uint32_t x = which == 0 ? a : b, y = which == 0 ? b : a;
      if ((which == 0 ? vb < va : va < vb)) continue;
      if (keys.compare_at(BoxEndpointKeys::key(y, BoxSide::Low),
                          BoxEndpointKeys::key(x, BoxSide::High), sim_.now()) > 0)
        return 2 * axis + which;
    }
  }
  return -1;
}

bool KineticFatBvh::classify(std::uint32_t p, bool quiet, int axis) {
  const std::uint32_t a = pairs_[p].box[0], b = pairs_[p].box[1];
  if (const int k = apart_for_ever(a, b); k >= 0) {
    // Every scheduler decides {+1, never} for that side (the exact sign now, then the slope),
    // and nothing lasts longer: the pair is separated for good, with no root isolation. The
    // boxes are apart now on that axis, so they do not touch now either.
    Pair& r = pairs_[p];
    const bool was_contact = r.state == State::Contact;
    r.state = State::Separated;
    r.certified = static_cast<std::int8_t>(k);
    sim_.cancel(r.handle);
    ++counters_.pairs_apart_for_ever;
    if (!was_contact) return false;
    set_contact(p, false, quiet);
    return true;
  }
  std::array<Scheduler::SignDecision, 6> ds;
  int apart = -1;  // the separating decision that lasts longest
  int n = 0;
  for (int k = 0; k < 2 * d_; ++k, ++n) {
    Scheduler::SignDecision& d = ds[static_cast<std::size_t>(k)];
    if (k % 2 == 1 && ds[static_cast<std::size_t>(k - 1)].sign > 0) {
      // b above a on this axis: a is not above b (its low side is below b's high side), and
      // the pair is separated, which needs no other decision of this axis.
      d = Scheduler::SignDecision{-1, kTimeInfinity, {}};
      continue;
    }
    d = decide_pair(a, b, k);
    if (d.sign <= 0) continue;
    if (apart < 0 || earlier(ds[static_cast<std::size_t>(apart)], d)) apart = k;
    if (d.failure == kTimeInfinity) {
      ++n;
      break;  // apart for ever: nothing lasts longer
    }
  }
  Pair& r = pairs_[p];
  const bool was_contact = r.state == State::Contact;
  int scheduled = apart;
  if (apart >= 0) {
    r.state = State::Separated;
  } else {
    // In contact: every inequality low <= high holds just after now; the first to fail ends it.
    r.state = State::Contact;
    for (int k = 0; k < n; ++k) {
      Scheduler::SignDecision& d = ds[static_cast<std::size_t>(k)];
      if (d.failure == kTimeInfinity) continue;
      if (scheduled < 0 || earlier(d, ds[static_cast<std::size_t>(scheduled)])) scheduled = k;
    }
  }
  r.certified = static_cast<std::int8_t>(scheduled);
  if (scheduled < 0) {
    sim_.cancel(r.handle);
  } else {
    Scheduler::SignDecision& d = ds[static_cast<std::size_t>(scheduled)];
    sim_.reschedule(r.handle, d.failure, std::move(d.exact), owners_[1], p);
  }
  const bool contact = r.state == State::Contact;
  if (!contact) note_if_touching(a, b, axis);
  if (contact == was_contact) return false;
  set_contact(p, contact, quiet);
  return true;
}

bool KineticFatBvh::find_pairs(std::uint32_t box, bool quiet) {
  constexpr std::uint32_t kKept = kNoIndex - 1;
  std::vector<std::uint32_t>& mine = pairs_of_[box];
  for (const std::uint32_t p : mine) mark_[other(p, box)] = p;
  scratch_.clear();
  tree_.query(fat_[box], [&](std::uint32_t j) {
    if (j == box) return;
    if (mark_[j] == kNoIndex) {
      scratch_.push_back(j);
    } else {
      mark_[j] = kKept;
    }
  });
  // Pairs whose fat boxes parted leave, unless in contact (a contact pair stays until it
  // separates). Walked from the back: dropping moves the last pair into the dropped one's place.
  for (std::size_t i = mine.size(); i-- > 0;) {
    const std::uint32_t p = mine[i];
    const std::uint32_t j = other(p, box);
    const bool kept = mark_[j] == kKept;
    mark_[j] = kNoIndex;
    if (!kept && pairs_[p].state != State::Contact) drop_pair(p);
  }
  bool changed = false;
  for (const std::uint32_t j : scratch_) {
    const std::uint32_t p = add_pair(box, j);
    changed = classify(p, quiet, -1) || changed;
  }
  return changed;
}

void KineticFatBvh::initialize() {
  for (const std::uint32_t i : boxes_.alive_indices()) require_box(i, "KineticFatBvh::initialize");
  sync_.note();
  tree_.clear();
  for (Pair& r : pairs_) sim_.cancel(r.handle);
  for (EventHandle& h : inside_) sim_.cancel(h);
  pairs_.clear();
  free_pairs_.clear();
  live_pairs_ = 0;
  fat_.clear();
  fat_since_.clear();
  leaf_.clear();
  inside_.clear();
  pairs_of_.clear();
  mark_.clear();
  piece_refits_.clear();
  clear_contacts();
  grow(boxes_.capacity());
  const std::vector<std::uint32_t> alive = boxes_.alive_indices();
  double sum = 0.0;
  for (const std::uint32_t i : alive) {
    double e = 0.0;
    for (int k = 0; k < d_; ++k) e = std::max(e, 2.0 * half_extent(boxes_, i, k).c[0]);
    sum += e;
  }
  unit_extent_ = sum > 0.0 ? sum / static_cast<double>(alive.size()) : 1.0;
  for (BoxEndpointKeys& k : keys_) {
    for (const std::uint32_t i : alive) k.refresh(i);
  }
  building_ = true;
  for (const std::uint32_t i : alive) fatten(i);
  building_ = false;
  std::vector<ConstantBox> boxes;
  boxes.reserve(alive.size());
  for (const std::uint32_t i : alive) boxes.push_back(fat_[i]);
  const std::vector<std::uint32_t> leaves = tree_.build(boxes, alive);
  for (std::size_t k = 0; k < alive.size(); ++k) leaf_[alive[k]] = leaves[k];
  for (const std::uint32_t i : alive) {
    scratch_.clear();
    tree_.query(fat_[i], [&](std::uint32_t j) {
      if (j > i) scratch_.push_back(j);
    });
    for (const std::uint32_t j : scratch_) classify(add_pair(i, j), true, -1);
  }
}

EventKind KineticFatBvh::process(const Event& event) {
  if (event.owner == owners_[0]) {
    const std::uint32_t box = event.payload;
    if (schedule_inside(box)) {
      ++counters_.containment_checks;
      return EventKind::Internal;
    }
    ++counters_.refits;
    ++piece_refits_[box];
    fatten(box);
    return find_pairs(box, false) ? EventKind::External : EventKind::Internal;
  }
  const std::uint32_t p = event.payload;
  ++counters_.pair_events;
  const int axis = pairs_[p].certified / 2;
  const bool changed = classify(p, false, axis);
  const Pair& r = pairs_[p];
  if (r.state == State::Separated && !boxes_meet(fat_[r.box[0]], fat_[r.box[1]], d_)) drop_pair(p);
  return changed ? EventKind::External : EventKind::Internal;
}

void KineticFatBvh::insert(std::uint32_t index) {
  sync_.require_inserted("KineticFatBvh::insert", index);
  require_box(index, "KineticFatBvh::insert");
  ++counters_.inserts;
  grow(boxes_.capacity());
  for (BoxEndpointKeys& k : keys_) k.refresh(index);
  piece_refits_[index] = 0;
  fatten(index);
  find_pairs(index, true);
}

void KineticFatBvh::remove(std::uint32_t index) {
  sync_.require_removed("KineticFatBvh::remove", index);
  ++counters_.removes;
  std::vector<std::uint32_t>& mine = pairs_of_[index];
  while (!mine.empty()) {
    const std::uint32_t p = mine.back();
    if (pairs_[p].state == State::Contact) set_contact(p, false, true);
    drop_pair(p);
  }
  sim_.cancel(inside_[index]);
  tree_.remove(leaf_[index]);
  leaf_[index] = kNoIndex;
}

void KineticFatBvh::motion_changed(std::uint32_t index) {
  sync_.require_updated("KineticFatBvh::motion_changed", index);
  require_box(index, "KineticFatBvh::motion_changed");
  ++counters_.updates;
  for (BoxEndpointKeys& k : keys_) k.refresh(index);
  piece_refits_[index] = 0;
  fatten(index);
  // The pairs it has are decided on its new motion (quietly: a timeline change), then those its
  // new fat box meets are found.
  had_.assign(pairs_of_[index].begin(), pairs_of_[index].end());
  for (const std::uint32_t p : had_) classify(p, true, -1);
  find_pairs(index, true);
}

bool KineticFatBvh::audit(Time t) const {
  for (const std::uint32_t i : boxes_.alive_indices()) {
    for (int k = 0; k < 2 * d_; ++k) {
      const auto axis = static_cast<std::size_t>(k / 2);
      if (std::isinf(k % 2 == 1 ? fat_[i].hi[axis] : fat_[i].lo[axis])) continue;
      const InsideCombination f(boxes_, i, k / 2, k % 2 == 1, fat_[i]);
      if (sign_at(f.f, t) < 0) return false;
    }
  }
  for (const Pair& r : pairs_) {
    if (r.state == State::Free) continue;
    const auto apart_at = [&](int k) {  // sign(low(y) - high(x)) at t
      const auto axis = static_cast<std::size_t>(k / 2);
      const std::uint32_t x = k % 2 == 0 ? r.box[0] : r.box[1];
      const std::uint32_t y = k % 2 == 0 ? r.box[1] : r.box[0];
      return keys_[axis].compare_at(BoxEndpointKeys::key(y, BoxSide::Low),
                                    BoxEndpointKeys::key(x, BoxSide::High), t);
    };
    if (r.state == State::Separated) {
      if (r.certified < 0 || apart_at(r.certified) <= 0) return false;
    } else {
      for (int k = 0; k < 2 * d_; ++k) {
        if (apart_at(k) > 0) return false;
      }
    }
  }
  return true;
}

bool KineticFatBvh::validate() const {
  if (!sync_.current() || !tree_.validate()) return false;
  const std::vector<std::uint32_t> alive = boxes_.alive_indices();
  if (tree_.leaves() != alive.size()) return false;
  for (const std::uint32_t i : alive) {
    const std::uint32_t leaf = leaf_[i];
    if (leaf == kNoIndex || tree_.item(leaf) != i) return false;
    const ConstantBox& b = tree_.box(leaf);
    for (std::size_t k = 0; k < static_cast<std::size_t>(d_); ++k) {
      if (b.lo[k] != fat_[i].lo[k] || b.hi[k] != fat_[i].hi[k]) return false;
    }
    if (!inside_[i].is_null() && !sim_.queue().contains(inside_[i])) return false;
  }
  PairSet kept;
  std::size_t live = 0, contact = 0;
  for (std::uint32_t p = 0; p < pairs_.size(); ++p) {
    const Pair& r = pairs_[p];
    if (r.state == State::Free) continue;
    ++live;
    for (std::size_t e = 0; e < 2; ++e) {
      const std::uint32_t box = r.box[e];
      if (!boxes_.alive_index(box) || r.at[e] >= pairs_of_[box].size() ||
          pairs_of_[box][r.at[e]] != p)
        return false;
    }
    if (!kept.insert(r.box[0], r.box[1])) return false;  // one record per pair
    const bool meet = boxes_meet(fat_[r.box[0]], fat_[r.box[1]], d_);
    if (r.state == State::Contact) {
      ++contact;
      if (!contact_set().contains(r.box[0], r.box[1])) return false;
    } else if (!meet || contact_set().contains(r.box[0], r.box[1])) {
      return false;
    }
    if (!r.handle.is_null() && !sim_.queue().contains(r.handle)) return false;
  }
  if (live != live_pairs_ || contact != contact_set().size()) return false;
  for (const std::uint32_t i : alive) {
    bool complete = true;
    tree_.query(fat_[i], [&](std::uint32_t j) {
      if (j != i && !kept.contains(i, j)) complete = false;
    });
    if (!complete) return false;
  }
  return true;
}

std::size_t KineticFatBvh::certificates() const { return tree_.leaves() + live_pairs_; }

std::size_t KineticFatBvh::certificates_per_object_max() const {
  std::size_t most = 0;
  for (const std::vector<std::uint32_t>& list : pairs_of_) most = std::max(most, list.size());
  return tree_.leaves() == 0 ? 0 : 1 + most;
}

std::size_t KineticFatBvh::bytes() const {
  std::size_t lists = 0;
  for (const std::vector<std::uint32_t>& list : pairs_of_)
    lists += list.capacity() * sizeof(std::uint32_t) + sizeof(list);
  return tree_.bytes() + fat_.capacity() * sizeof(ConstantBox) +
         fat_since_.capacity() * sizeof(Time) + leaf_.capacity() * sizeof(std::uint32_t) +
         inside_.capacity() * sizeof(EventHandle) + pairs_.capacity() * sizeof(Pair) + lists +
         mark_.capacity() * sizeof(std::uint32_t) + contact_set().bytes();
}

namespace {

/// The loop guard's bounds: a pair's events are crossings of its sides (as the exact-box
/// tree's); a box refits at most once per instant and, per motion, kSteadyRefits times and then
/// once per doubling of its lookahead (a double's exponent range: about 2,100 more), each refit
/// with at most 2d containment checks before it.
LoopGuard fat_bvh_event_bounds(const RunBounds& b) {
  LoopGuard g = crossing_guard(16 * static_cast<std::uint64_t>(b.dimension), 2 * b.max_objects,
                               2 * b.motion_changes, b.max_degree);
  const std::uint64_t per_refit = 1 + 2 * static_cast<std::uint64_t>(std::max(1, b.dimension));
  const std::uint64_t refits = KineticFatBvh::kSteadyRefits + 2200;
  const auto add = [](std::uint64_t x, std::uint64_t y) {
    return x > std::numeric_limits<std::uint64_t>::max() - y
               ? std::numeric_limits<std::uint64_t>::max()
               : x + y;
  };
  g.max_events_per_instant =
      add(g.max_events_per_instant, saturating_product({per_refit, b.max_objects}));
  g.max_events_total =
      add(g.max_events_total,
          saturating_product({per_refit, refits, b.max_objects + b.motion_changes}));
  return g;
}

}  // namespace

StructureDescription KineticFatBvh::description() {
  return StructureDescription{
      "fat-bvh",
      "FatBvh",
      ObjectsAre::Boxes,
      {QueryType::CollidingPairs},
      {"contact_begin", "contact_end"},
      "The kinetic AABB tree over fat boxes (constant boxes refitted when a box leaves its own) "
      "over moving boxes (colliding_pairs()); centers (n, d, k) and half_extents (n, d).",
      "kinetic AABB tree over fat boxes (each box's path over a lookahead; refitted when the box "
      "leaves it) with the pairs of meeting fat boxes certified exactly: all pairs of boxes in "
      "contact"}
      .limit_dimensions(1, 3, "boxes in 1 to 3 dimensions")
      .bound_events(fat_bvh_event_bounds);
}

}  // namespace kinetic
