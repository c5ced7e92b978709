#include "kinetic/core/motion_table.hpp"

#include <algorithm>
#include <cassert>

namespace kinetic {

MotionTable::MotionTable(int dimension) : dimension_(dimension) { assert(dimension >= 1); }

ObjectHandle MotionTable::insert(ObjectId id, std::span<const MotionPolynomial> coordinates,
                                 Time valid_from) {
  assert(coordinates.size() == static_cast<std::size_t>(dimension_));
  assert(!index_of_.contains(id));
  std::uint32_t index;
  if (!free_.empty()) {
    index = free_.back();
    free_.pop_back();
  } else {
    index = static_cast<std::uint32_t>(ids_.size());
    ids_.push_back(0);
    valid_from_.push_back(kTimeMinusInfinity);
    generations_.push_back(0);
    alive_.push_back(0);
    coordinates_.resize(coordinates_.size() + dimension_);
  }
  ids_[index] = id;
  valid_from_[index] = valid_from;
  alive_[index] = 1;
  index_of_.emplace(id, index);
  ++size_;
  ++motion_changes_;
  const ObjectHandle h{index, generations_[index]};
  for (int k = 0; k < dimension_; ++k) {
    coordinates_[static_cast<std::size_t>(index) * dimension_ + k] = coordinates[k];
    max_degree_ = std::max(max_degree_, coordinates[k].degree);
  }
  return h;
}

void MotionTable::remove(ObjectHandle h) {
  assert(alive(h));
  alive_[h.index] = 0;
  ++generations_[h.index];
  index_of_.erase(ids_[h.index]);
  free_.push_back(h.index);
  --size_;
}

void MotionTable::update(ObjectHandle h, std::span<const MotionPolynomial> coordinates,
                         Time valid_from) {
  assert(alive(h));
  valid_from_[h.index] = valid_from;
  assert(coordinates.size() == static_cast<std::size_t>(dimension_));
  ++motion_changes_;
  for (int k = 0; k < dimension_; ++k) {
    coordinates_[static_cast<std::size_t>(h.index) * dimension_ + k] = coordinates[k];
    max_degree_ = std::max(max_degree_, coordinates[k].degree);
  }
}

std::optional<ObjectHandle> MotionTable::find(ObjectId id) const {
  const auto it = index_of_.find(id);
  if (it == index_of_.end()) return std::nullopt;
  return ObjectHandle{it->second, generations_[it->second]};
}

bool MotionTable::alive(ObjectHandle h) const {
  return h.index < ids_.size() && alive_[h.index] != 0 && generations_[h.index] == h.generation;
}

std::vector<std::uint32_t> MotionTable::alive_indices() const {
  std::vector<std::uint32_t> out;
  out.reserve(size_);
  for (std::uint32_t i = 0; i < ids_.size(); ++i) {
    if (alive_[i]) out.push_back(i);
  }
  return out;
}

}  // namespace kinetic
