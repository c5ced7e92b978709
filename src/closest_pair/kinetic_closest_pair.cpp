#include "kinetic/closest_pair/kinetic_closest_pair.hpp"

#include <algorithm>
#include <cassert>
#include <stdexcept>
#include <string>

#include "kinetic/core/exact_time.hpp"
#include "kinetic/core/free_list.hpp"
#include "kinetic/core/incircle.hpp"
#include "kinetic/core/preconditions.hpp"

namespace kinetic {

namespace {
const Scheduler& require_exact(const Scheduler& scheduler) {
  if (scheduler.kind() != SchedulerKind::Exact) {
    precondition_failed("KineticClosestPair",
                        std::string("the closest pair over the kinetic Delaunay triangulation "
                                    "needs the exact scheduler (its tournament compares the "
                                    "lengths of the triangulation's edges now, which the robust "
                                    "triangulation keeps for its last grid point); the closest "
                                    "pair from cones (KineticConeClosestPair) takes every "
                                    "scheduler; got the ") +
                            to_string(scheduler.kind()) + " scheduler");
  }
  return scheduler;
}
}  // namespace

KineticClosestPair::KineticClosestPair(const MotionTable& points, Simulator& simulator,
                                       const Scheduler& scheduler)
    : points_(points),
      sim_(simulator),
      scheduler_(require_exact(scheduler)),
      dt_(points, simulator, scheduler),
      tournament_(points, simulator, scheduler) {}

ClosestPairCounters KineticClosestPair::counters() const {
  ClosestPairCounters c = counters_;
  c.nodes_redecided = tournament_.counters().nodes_redecided;
  c.tie_visits = tournament_.counters().tie_visits;
  return c;
}

NamedCounters KineticClosestPair::named_counters() const {
  const ClosestPairCounters c = counters();
  NamedCounters out = dt_.named_counters();
  for (NamedCounter& n : out) {
    if (n.name == "events") n.name = "flip_events";
    if (n.name == "rebuilds") n.name = "triangulation_rebuilds";
    if (n.name == "queries") n.name = "triangulation_queries";
  }
  out.insert(out.begin(), {{"events", dt_.counters().events + c.events},
                           {"tournament_events", c.events},
                           {"edge_inserts", c.edge_inserts},
                           {"edge_removes", c.edge_removes},
                           {"rebuilds", c.rebuilds},
                           {"nodes_redecided", c.nodes_redecided},
                           {"queries", c.queries},
                           {"tie_visits", c.tie_visits}});
  return out;
}

KineticClosestPair::Pair KineticClosestPair::ends(std::uint32_t record) const {
  return {PairSet::first(key_[record]), PairSet::second(key_[record])};
}

void KineticClosestPair::lay_out() {
  tournament_.reset(key_.size());
  for (std::uint32_t r = 0; r < key_.size(); ++r) {
    if (held_[r] > 0) tournament_.set(r, ends(r)[0], ends(r)[1]);
  }
  tournament_.decide_all();
}

void KineticClosestPair::reread_edges() {
  ++counters_.rebuilds;
  edges_.clear();
  record_of_.clear();
  key_.clear();
  held_.clear();
  free_records_.clear();
  freed_records_.clear();
  grow_ = false;
  dt_.edges(scratch_edges_);
  for (const Pair& e : scratch_edges_) {
    edges_.insert(e[0], e[1]);
    record_of_.push_back(static_cast<std::uint32_t>(key_.size()));
    key_.push_back(PairSet::key(e[0], e[1]));
    held_.push_back(2);  // every edge has two triangles (the vertex at infinity closes the hull)
  }
  lay_out();
  dt_.clear_edge_changes();
}

void KineticClosestPair::add_edge(std::uint32_t a, std::uint32_t b) {
  const std::uint32_t r = take_record(key_, free_records_);
  if (held_.size() < key_.size()) held_.resize(key_.size(), 0);
  key_[r] = PairSet::key(a, b);
  held_[r] = 1;
  edges_.insert(a, b);
  record_of_.push_back(r);
  ++counters_.edge_inserts;
  // Full: the tree is laid out again for more leaves once the batch is taken (deciding now could
  // read edges of the batch that are gone, their points with them).
  if (r >= tournament_.leaves()) grow_ = true;
  if (grow_) return;
  tournament_.set(r, ends(r)[0], ends(r)[1]);
}

void KineticClosestPair::remove_edge(std::size_t position) {
  const std::uint32_t r = record_of_[position];
  const Pair e = ends(r);
  edges_.erase(e[0], e[1]);  // the last position takes this one's place
  record_of_[position] = record_of_.back();
  record_of_.pop_back();
  freed_records_.push_back(r);  // reused after this batch: a record names one edge per batch
  held_[r] = 0;
  ++counters_.edge_removes;
  if (grow_) return;  // laid out again at the end of the batch
  tournament_.clear(r);
}

void KineticClosestPair::take_edge_changes() {
  if (dt_.edges_rebuilt()) {
    reread_edges();
    return;
  }
  for (const KineticDelaunay::EdgeChange& c : dt_.edge_changes()) {
    const std::size_t pos = edges_.position(c.a, c.b);
    if (c.delta > 0) {
      if (pos == PairSet::npos) {
        add_edge(c.a, c.b);
      } else {
        ++held_[record_of_[pos]];
      }
    } else {
      if (pos == PairSet::npos || held_[record_of_[pos]] == 0) {
        throw std::logic_error(
            "KineticClosestPair: the triangulation reported a missing edge leaving (an internal "
            "failure; please report the scenario)");
      }
      if (--held_[record_of_[pos]] == 0) remove_edge(pos);
    }
  }
  dt_.clear_edge_changes();
  if (grow_) {
    // Every record gets a leaf (the leaves double until they suffice) and every node is decided
    // on the batch's final edges (amortized O(1) decisions per edge).
    grow_ = false;
    lay_out();
  } else {
    tournament_.update();
  }
  free_records_.insert(free_records_.end(), freed_records_.begin(), freed_records_.end());
  freed_records_.clear();
}

void KineticClosestPair::initialize() {
  dt_.record_edge_changes(true);
  dt_.initialize();
  reread_edges();
  --counters_.rebuilds;  // the first build is not a rebuild
}

EventKind KineticClosestPair::process(const Event& event) {
  const std::uint32_t top_before = tournament_.winner();
  const std::uint64_t key_before = top_before == kNoIndex ? 0 : key_[top_before];
  if (event.owner == tournament_.owner()) {
    ++counters_.events;
    tournament_.process(event);
  } else {
    (void)dt_.process(event);
    take_edge_changes();
  }
  const std::uint32_t top = tournament_.winner();
  if (top == top_before && (top == kNoIndex || key_[top] == key_before)) return EventKind::Internal;
  if (sim_.logging_events() && top != kNoIndex) {
    const Pair e = ends(top);
    std::array<ObjectId, 2> ids{points_.id(e[0]), points_.id(e[1])};
    std::sort(ids.begin(), ids.end());
    sim_.log_event("pair_change", ids);
  }
  return EventKind::External;
}

void KineticClosestPair::insert(std::uint32_t index) {
  dt_.insert(index);
  take_edge_changes();
}

void KineticClosestPair::remove(std::uint32_t index) {
  dt_.remove(index);
  take_edge_changes();
}

void KineticClosestPair::motion_changed(std::uint32_t index) {
  dt_.motion_changed(index);
  take_edge_changes();
  // The edges at the point keep their records, but their lengths follow another motion now.
  if (!dt_.flat()) {
    for (std::size_t pos = 0; pos < record_of_.size(); ++pos) {
      const std::uint32_t r = record_of_[pos];
      const Pair e = ends(r);
      if (e[0] == index || e[1] == index) tournament_.set(r, e[0], e[1]);
    }
    tournament_.update();
  }
}

std::optional<std::array<std::uint32_t, 2>> KineticClosestPair::closest_pair() {
  ++counters_.queries;
  if (dt_.flat()) return dt_.closest_pair();
  // Every edge as short as the winner now: a subtree whose winner is longer now holds none (its
  // winner is the shortest of the subtree just after now, hence now too).
  scratch_edges_.clear();
  tournament_.ties(scratch_edges_);
  return dt_.closest_pair_among(scratch_edges_);
}

std::size_t KineticClosestPair::certificates() const {
  return dt_.certificates() + tournament_.certificates();
}

std::size_t KineticClosestPair::certificates_per_object_max() const {
  std::vector<std::uint32_t> count(points_.capacity(), 0);
  tournament_.count_certificates(count);
  const std::uint32_t best = count.empty() ? 0 : *std::max_element(count.begin(), count.end());
  return dt_.certificates_per_object_max() + best;
}

bool KineticClosestPair::validate() const {
  if (!dt_.validate()) return false;
  if (!dt_.edge_changes().empty() || dt_.edges_rebuilt()) return false;  // all taken
  // The same edges as the triangulation, each held twice.
  std::vector<Pair> current;
  dt_.edges(current);
  if (current.size() != edges_.size()) return false;
  for (const Pair& e : current) {
    const std::size_t pos = edges_.position(e[0], e[1]);
    if (pos == PairSet::npos || held_[record_of_[pos]] != 2) return false;
  }
  if (record_of_.size() != edges_.size()) return false;
  for (std::size_t pos = 0; pos < record_of_.size(); ++pos) {
    const std::uint32_t r = record_of_[pos];
    if (r >= key_.size() || key_[r] != edges_.keys()[pos] || r >= tournament_.leaves())
      return false;
    const std::optional<Pair> leaf = tournament_.pair(r);
    if (!leaf || (*leaf)[0] != ends(r)[0] || (*leaf)[1] != ends(r)[1]) return false;
  }
  std::size_t leaves = 0;
  for (std::uint32_t l = 0; l < tournament_.leaves(); ++l) leaves += tournament_.pair(l) ? 1 : 0;
  if (leaves != edges_.size()) return false;
  return tournament_.validate();
}

}  // namespace kinetic
