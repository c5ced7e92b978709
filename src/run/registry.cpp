#include "registry.hpp"

#include <algorithm>

#include "kinetic/structures.hpp"

namespace kinetic::run::detail {

Json AnswerContext::sorted_ids(const std::vector<std::uint32_t>& indices) const {
  std::vector<ObjectId> ids;
  ids.reserve(indices.size());
  for (const std::uint32_t i : indices) {
    if (i != kNoIndex) ids.push_back(motions.id(i));  // (an empty slot of a gapped order)
  }
  std::sort(ids.begin(), ids.end());
  return Json(ids);
}

Json AnswerContext::ids_in_order(std::span<const std::uint32_t> indices) const {
  Json ids = Json::array();
  for (const std::uint32_t i : indices) {
    if (i != kNoIndex) ids.push_back(motions.id(i));  // (an empty slot of a gapped order)
  }
  return ids;
}

const std::vector<StructureDescriptor>& registry() {
  static const std::vector<StructureDescriptor> table = [] {
    std::vector<StructureDescriptor> out;
    Structures::for_each([&]<class S>() { out.push_back(descriptor<S>()); });
    return out;
  }();
  return table;
}

const StructureDescriptor* find(const std::string& name) {
  for (const StructureDescriptor& d : registry()) {
    if (d.info.name == name) return &d;
  }
  return nullptr;
}

}  // namespace kinetic::run::detail

namespace kinetic::run {

const std::vector<StructureInfo>& structures() {
  static const std::vector<StructureInfo> infos = [] {
    std::vector<StructureInfo> out;
    for (const detail::StructureDescriptor& d : detail::registry()) out.push_back(d.info);
    return out;
  }();
  return infos;
}

}  // namespace kinetic::run
