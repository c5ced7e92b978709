#pragma once
// The objects and their motions. Structures read motions through this table (a narrow, read-only
// view: `motion(index, axis)`); they never own them. Objects are addressed by dense indices on
// hot paths and by generation-counted handles at the API boundary, so a stale handle is caught.

#include <cassert>
#include <cstdint>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include "kinetic/core/huge_pages.hpp"
#include "kinetic/core/ids.hpp"
#include "kinetic/core/polynomial.hpp"

namespace kinetic {

/// Handle to an object in a MotionTable. Stale after the object is removed.
struct ObjectHandle {
  std::uint32_t index = kNoIndex;
  std::uint32_t generation = 0;
  friend bool operator==(const ObjectHandle&, const ObjectHandle&) = default;
};

/// Throws PreconditionError unless p is a motion the library accepts: degree in
/// [0, kMaxMotionDegree] with c[degree] != 0 (or the zero polynomial), zero coefficients above
/// the degree, every coefficient and the origin finite. `where` names the caller.
void check_motion(const MotionPolynomial& p, const char* where);

class MotionTable {
 public:
  explicit MotionTable(int dimension);

  [[nodiscard]] int dimension() const { return dimension_; }

  /// Adds an object whose motion holds from `valid_from` on. Throws PreconditionError when `id`
  /// is present, coordinates.size() != dimension(), or a coordinate is not a valid motion (see
  /// check_motion). `where` names the caller in the message.
  ObjectHandle insert(ObjectId id, std::span<const MotionPolynomial> coordinates,
                      Time valid_from = kTimeMinusInfinity,
                      const char* where = "MotionTable::insert");
  /// Removes an object; its index may be reused by a later insert. Throws PreconditionError
  /// unless alive(h). The structures over the table are told after (remove(index)), as for
  /// insert and update: the table changes first, then every structure over it is told.
  void remove(ObjectHandle h);
  /// Replaces the motion from `valid_from` on (a flight-plan update). Throws as insert does,
  /// or unless alive(h).
  void update(ObjectHandle h, std::span<const MotionPolynomial> coordinates,
              Time valid_from = kTimeMinusInfinity, const char* where = "MotionTable::update");

  /// Changes so far (inserts, removes, updates): a structure that noted this count when it last
  /// caught up knows whether it has been told of every change (TableSync).
  [[nodiscard]] std::uint64_t version() const { return version_; }

  [[nodiscard]] std::optional<ObjectHandle> find(ObjectId id) const;
  [[nodiscard]] bool alive(ObjectHandle h) const;
  [[nodiscard]] bool alive_index(std::uint32_t index) const {
    return index < alive_.size() && alive_[index] != 0;
  }
  [[nodiscard]] ObjectHandle handle(std::uint32_t index) const {
    return ObjectHandle{index, generations_[index]};
  }

  /// Coordinate `axis` of object `index`. Precondition: alive_index(index), 0 <= axis < dimension.
  [[nodiscard]] const MotionPolynomial& motion(std::uint32_t index, int axis) const {
    assert(alive_index(index) && axis >= 0 && axis < dimension_);  // debug builds only: hot path
    return coordinates_[static_cast<std::size_t>(index) * dimension_ + axis];
  }
  [[nodiscard]] ObjectId id(std::uint32_t index) const { return ids_[index]; }
  /// Since when the object's current motion holds (its insert or last update; -infinity when
  /// not given). Roots of a certificate before this time belong to an old motion.
  [[nodiscard]] Time valid_from(std::uint32_t index) const { return valid_from_[index]; }

  /// Number of live objects.
  [[nodiscard]] std::size_t size() const { return size_; }
  /// Every live index is < capacity(); structures size their per-object arrays with it.
  [[nodiscard]] std::size_t capacity() const { return ids_.size(); }
  /// Live indices, ascending.
  [[nodiscard]] std::vector<std::uint32_t> alive_indices() const;
  /// Inserts plus updates so far: each may create new crossings (used by loop-guard bounds).
  [[nodiscard]] std::uint64_t motion_changes() const { return motion_changes_; }
  /// Highest degree of any coordinate of any object ever inserted.
  [[nodiscard]] int max_degree() const { return max_degree_; }

 private:
  int dimension_;
  /// Large tables are offered huge pages: structures read motions at random places.
  HugeVector<MotionPolynomial> coordinates_;
  std::vector<ObjectId> ids_;
  std::vector<Time> valid_from_;
  std::vector<std::uint32_t> generations_;
  std::vector<std::uint8_t> alive_;
  std::vector<std::uint32_t> free_;
  std::unordered_map<ObjectId, std::uint32_t> index_of_;
  std::size_t size_ = 0;
  std::uint64_t motion_changes_ = 0;
  std::uint64_t version_ = 0;
  int max_degree_ = 0;
};

}  // namespace kinetic
