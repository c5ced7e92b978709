#pragma once
// A group of kinetic structures of one kind sharing a simulator, seen as one structure: one
// kinetic sort per axis, one tournament per (axis, extreme), ... Each member reserves one owner
// tag when it is built; the group's members are built one after the other, so their owners are
// consecutive and an event goes to member (owner - first owner) with no search. Timeline changes
// go to every member; certificates and counters are summed.

#include <algorithm>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "kinetic/core/structure.hpp"

namespace kinetic {

/// A range of references to the members of a StructureGroup (a plain iterator over the owning
/// pointers: no <ranges> adaptor, which some compilers cannot take from every standard library).
template <class M>
class Members {
  using Owner = std::unique_ptr<std::remove_const_t<M>>;

 public:
  Members(const Owner* first, std::size_t n) : first_(first), n_(n) {}
  class iterator {
   public:
    explicit iterator(const Owner* p) : p_(p) {}
    M& operator*() const { return **p_; }
    iterator& operator++() {
      ++p_;
      return *this;
    }
    bool operator==(const iterator&) const = default;

   private:
    const Owner* p_;
  };
  [[nodiscard]] iterator begin() const { return iterator(first_); }
  [[nodiscard]] iterator end() const { return iterator(first_ + n_); }
  [[nodiscard]] std::size_t size() const { return n_; }

 private:
  const Owner* first_;
  std::size_t n_;
};

template <KineticStructure Member>
class StructureGroup {
 public:
  StructureGroup() = default;

  /// Adds a member built just now (it reserved one owner, the next after the previous member's).
  /// Throws std::logic_error when its owner does not follow: something else reserved owners on
  /// the same simulator between two members.
  Member& add(std::unique_ptr<Member> member) {
    const OwnerRange r = member->owners();
    if (members_.empty()) first_owner_ = r.first;
    if (r.count != 1 || r.first != first_owner_ + static_cast<std::uint32_t>(members_.size())) {
      throw std::logic_error("StructureGroup: members must reserve consecutive owners");
    }
    members_.push_back(std::move(member));
    return *members_.back();
  }

  [[nodiscard]] std::size_t size() const { return members_.size(); }
  [[nodiscard]] Member& operator[](std::size_t k) { return *members_[k]; }
  [[nodiscard]] const Member& operator[](std::size_t k) const { return *members_[k]; }
  /// The members, in the order they were added (a range of Member&, for range-for).
  [[nodiscard]] auto members() { return Members<Member>{members_.data(), members_.size()}; }
  [[nodiscard]] auto members() const {
    return Members<const Member>{members_.data(), members_.size()};
  }
  /// The member an event of the group belongs to.
  [[nodiscard]] std::size_t member_of(const Event& event) const {
    return event.owner - first_owner_;
  }
  [[nodiscard]] OwnerRange owners() const {
    return OwnerRange{first_owner_, static_cast<std::uint32_t>(members_.size())};
  }

  void initialize() {
    for (auto& m : members_) m->initialize();
    initialized_ = true;
  }
  [[nodiscard]] bool initialized() const { return initialized_; }
  EventKind process(const Event& event) { return members_[member_of(event)]->process(event); }
  void insert(std::uint32_t index) {
    for (auto& m : members_) m->insert(index);
  }
  void remove(std::uint32_t index) {
    for (auto& m : members_) m->remove(index);
  }
  void motion_changed(std::uint32_t index) {
    for (auto& m : members_) m->motion_changed(index);
  }
  /// Robust scheduling: measure event delays, where the members can.
  void set_measure_delays(bool on) requires requires(Member& m) { m.set_measure_delays(on); }
  {
    for (auto& m : members_) m->set_measure_delays(on);
  }
  [[nodiscard]] bool validate() const {
    return std::all_of(members_.begin(), members_.end(),
                       [](const auto& m) { return m->validate(); });
  }
  [[nodiscard]] std::uint64_t certificates() const {
    std::uint64_t total = 0;
    for (const auto& m : members_) total += m->certificates();
    return total;
  }
  /// An object takes part in certificates of every member.
  [[nodiscard]] std::uint64_t certificates_per_object_max() const {
    std::uint64_t total = 0;
    for (const auto& m : members_) total += m->certificates_per_object_max();
    return total;
  }
  [[nodiscard]] NamedCounters named_counters() const {
    NamedCounters out;
    for (const auto& m : members_) accumulate(out, m->named_counters());
    return out;
  }

 private:
  std::vector<std::unique_ptr<Member>> members_;
  bool initialized_ = false;
  std::uint32_t first_owner_ = 0;
};

}  // namespace kinetic
