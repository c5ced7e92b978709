#include "kinetic/core/description.hpp"

#include <array>
#include <utility>

namespace kinetic {
namespace {

// One table so that the two directions cannot drift apart.
constexpr std::array<std::pair<QueryType, const char*>, 14> kQueryTypeNames{{
    {QueryType::Sorted, "sorted"},
    {QueryType::Max, "max"},
    {QueryType::Min, "min"},
    {QueryType::Extent, "extent"},
    {QueryType::Range, "range"},
    {QueryType::Nearest, "nearest"},
    {QueryType::KNearest, "k_nearest"},
    {QueryType::Farthest, "farthest"},
    {QueryType::ApproxRange, "approx_range"},
    {QueryType::Stab, "stab"},
    {QueryType::Hull, "hull"},
    {QueryType::ClosestPair, "closest_pair"},
    {QueryType::CollidingPairs, "colliding_pairs"},
    {QueryType::Delaunay, "delaunay"},
}};

}  // namespace

const char* to_string(ObjectsAre objects_are) {
  switch (objects_are) {
    case ObjectsAre::Intervals:
      return "intervals";
    case ObjectsAre::Boxes:
      return "boxes";
    case ObjectsAre::Points:
      break;
  }
  return "points";
}

const char* to_string(QueryType type) {
  for (const auto& [value, name] : kQueryTypeNames) {
    if (value == type) return name;
  }
  return "unknown";
}

std::vector<const char*> query_type_names() {
  std::vector<const char*> names;
  for (const auto& entry : kQueryTypeNames) names.push_back(entry.second);
  return names;
}

std::optional<QueryType> query_type_from_string(const std::string& name) {
  for (const auto& [value, spelling] : kQueryTypeNames) {
    if (name == spelling) return value;
  }
  return std::nullopt;
}

}  // namespace kinetic
