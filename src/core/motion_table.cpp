#include "kinetic/core/motion_table.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "kinetic/core/preconditions.hpp"

namespace kinetic {

void check_motion(const MotionPolynomial& p, const char* where) {
  if (p.degree < 0 || p.degree > kMaxMotionDegree) {
    precondition_failed(where, "a motion of degree " + std::to_string(p.degree) +
                                   " (the degree is at most " + std::to_string(kMaxMotionDegree) +
                                   ")");
  }
  if (!std::isfinite(p.origin)) precondition_failed(where, "a motion's origin is not finite");
  for (int i = 0; i <= kMaxMotionDegree; ++i) {
    if (!std::isfinite(p.c[static_cast<std::size_t>(i)])) {
      precondition_failed(where, "a motion's coefficient c" + std::to_string(i) + " is not finite");
    }
    if (i > p.degree && p.c[static_cast<std::size_t>(i)] != 0.0) {
      precondition_failed(where, "a motion's coefficient c" + std::to_string(i) +
                                     " is not zero above its degree " + std::to_string(p.degree) +
                                     " (build motions with MotionPolynomial::from)");
    }
  }
  if (p.degree > 0 && p.c[static_cast<std::size_t>(p.degree)] == 0.0) {
    precondition_failed(where, "a motion's leading coefficient c" + std::to_string(p.degree) +
                                   " is zero (build motions with MotionPolynomial::from)");
  }
}

namespace {

void check_coordinates(std::span<const MotionPolynomial> coordinates, int dimension,
                       const char* where) {
  if (coordinates.size() != static_cast<std::size_t>(dimension)) {
    precondition_failed(where, std::to_string(coordinates.size()) + " coordinates for a table of "
                                   "dimension " + std::to_string(dimension));
  }
  for (const MotionPolynomial& p : coordinates) check_motion(p, where);
}

}  // namespace

MotionTable::MotionTable(int dimension) : dimension_(dimension) {
  if (dimension < 1) {
    precondition_failed("MotionTable", "dimension " + std::to_string(dimension) + " (at least 1)");
  }
}

ObjectHandle MotionTable::insert(ObjectId id, std::span<const MotionPolynomial> coordinates,
                                 Time valid_from, const char* where) {
  check_coordinates(coordinates, dimension_, where);
  if (index_of_.contains(id)) {
    precondition_failed(where, "id " + std::to_string(id) + " is present already");
  }
  if (std::isnan(valid_from)) precondition_failed(where, "valid_from is NaN");
  ++version_;
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
  if (!alive(h)) precondition_failed("MotionTable::remove", "the handle is not alive");
  ++version_;
  alive_[h.index] = 0;
  ++generations_[h.index];
  index_of_.erase(ids_[h.index]);
  free_.push_back(h.index);
  --size_;
}

void MotionTable::update(ObjectHandle h, std::span<const MotionPolynomial> coordinates,
                         Time valid_from, const char* where) {
  if (!alive(h)) precondition_failed(where, "the handle is not alive");
  check_coordinates(coordinates, dimension_, where);
  if (std::isnan(valid_from)) precondition_failed(where, "valid_from is NaN");
  ++version_;
  valid_from_[h.index] = valid_from;
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
