#include "kinetic/core/box_contacts.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "kinetic/core/error.hpp"

namespace kinetic {

std::vector<IndexPair> BoxContacts::colliding_pairs(Time t) {
  sync_.require_current(query_where_);
  require_query_time(query_where_, t, sim_.now());
  count_query();
  return ended_.answer(boxes_, contacts_, sim_);
}

bool BoxContacts::begin_contact(std::uint32_t a, std::uint32_t b) {
  if (!contacts_.insert(a, b)) return false;
  if (tracking_) journal(a, b, true);
  return true;
}

bool BoxContacts::end_contact(std::uint32_t a, std::uint32_t b) {
  if (!contacts_.erase(a, b)) return false;
  if (tracking_) journal(a, b, false);
  return true;
}

void BoxContacts::clear_contacts() {
  if (tracking_) {
    for (const std::uint64_t k : contacts_.keys())
      journal(PairSet::first(k), PairSet::second(k), false);
  }
  contacts_.clear();
}

void BoxContacts::log_contact(bool begins, std::uint32_t a, std::uint32_t b) {
  if (!begins) ended_.note(sim_, boxes_, a, b);
  if (!sim_.logging_events()) return;
  std::array<ObjectId, 2> ids{boxes_.id(a), boxes_.id(b)};
  if (ids[0] > ids[1]) std::swap(ids[0], ids[1]);
  sim_.log_event(begins ? "contact_begin" : "contact_end", ids);
}

void BoxContacts::journal(std::uint32_t a, std::uint32_t b, bool begins) {
  ObjectId x = boxes_.id(a), y = boxes_.id(b);
  if (x > y) std::swap(x, y);
  journal_.push_back(Journaled{x, y, sim_.now(), begins});
}

std::vector<BoxContacts::IdPair> BoxContacts::touching_only_now() const {
  std::vector<IdPair> out;
  for (const auto& [a, b] : ended_.touching_only(boxes_, contacts_, sim_))
    out.emplace_back(boxes_.id(a), boxes_.id(b));  // touching_only: the smaller id first, sorted
  return out;
}

ContactChanges BoxContacts::contact_changes(Time t) {
  sync_.require_current(changes_where_);
  require_query_time(changes_where_, t, sim_.now());
  count_query();
  ContactChanges out;
  std::vector<IdPair> touching_now = touching_only_now();
  if (!tracking_) {
    tracking_ = true;
    for (const auto& [a, b] : ended_.answer(boxes_, contacts_, sim_))
      out.begun.push_back(ContactChange{boxes_.id(a), boxes_.id(b), t});
  } else {
    // A pair's membership in the previous answer: in the contact set then (its first change
    // since is an end) or touching only then; in the answer now: in the contact set now (its
    // last change is a begin) or touching only now. Pairs neither changed nor touching only at
    // either call kept their membership.
    std::stable_sort(journal_.begin(), journal_.end(), [](const Journaled& x, const Journaled& y) {
      return x.a != y.a ? x.a < y.a : x.b < y.b;
    });
    std::vector<IdPair> keys;
    keys.reserve(journal_.size() + touching_before_.size() + touching_now.size());
    for (const Journaled& j : journal_) {
      if (keys.empty() || keys.back() != IdPair{j.a, j.b}) keys.emplace_back(j.a, j.b);
    }
    keys.insert(keys.end(), touching_before_.begin(), touching_before_.end());
    keys.insert(keys.end(), touching_now.begin(), touching_now.end());
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    const auto in = [](const std::vector<IdPair>& sorted, const IdPair& k) {
      return std::binary_search(sorted.begin(), sorted.end(), k);
    };
    for (const IdPair& k : keys) {
      const auto [lo, hi] = std::equal_range(journal_.begin(), journal_.end(),
                                             Journaled{k.first, k.second, 0.0, false},
                                             [](const Journaled& x, const Journaled& y) {
                                               return x.a != y.a ? x.a < y.a : x.b < y.b;
                                             });
      const bool changed = lo != hi;
      const bool was = (changed && !lo->begins) || in(touching_before_, k);
      const bool is = (changed && std::prev(hi)->begins) || in(touching_now, k);
      if (is && !was) {
        Time when = t;  // touching only now, with no contact since the previous call
        for (auto j = lo; j != hi; ++j) {
          if (j->begins) when = j->time;
        }
        out.begun.push_back(ContactChange{k.first, k.second, when});
      } else if (was && !is) {
        Time when = last_call_;  // touching only at the previous call, not since
        for (auto j = lo; j != hi; ++j) {
          if (!j->begins) when = j->time;
        }
        out.ended.push_back(ContactChange{k.first, k.second, when});
      } else if (!was && !is) {
        const auto first_begin = std::find_if(lo, hi, [](const Journaled& j) { return j.begins; });
        if (first_begin != hi)
          out.touched.push_back(ContactChange{k.first, k.second, first_begin->time});
      }
    }
  }
  journal_.clear();
  touching_before_ = std::move(touching_now);
  last_call_ = t;
  return out;
}

void BoxContacts::require_box_table(const MotionTable& boxes, const char* structure) {
  if (boxes.dimension() % 2 != 0) {
    precondition_failed(structure,
                        "the table does not hold boxes (an even dimension: centers, then half "
                        "extents), it has dimension " +
                            std::to_string(boxes.dimension()));
  }
  require_dimension(structure, box_dimension(boxes), 1, 3, "boxes in 1 to 3 dimensions");
}

}  // namespace kinetic
