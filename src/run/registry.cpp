#include "registry.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

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

namespace {

/// Every structure of the list, each by its own binding (src/run/structures/) where it has one,
/// else played on its description. A description without its loop guard's bounds, a structure
/// the session cannot build from motions alone without a binding, or a binding of a structure
/// not in the list is a defect of the build: logic_error.
std::vector<StructureDescriptor> build_registry() {
  OwnDescriptors own;
#define KINETIC_RUN_BINDING(stem) bind_##stem(own);
#include "run_bindings.inc"
#undef KINETIC_RUN_BINDING
  std::vector<StructureDescriptor> out;
  Structures::for_each([&]<class S>() {
    StructureDescriptor d = default_descriptor<S>();
    if (d.info.event_bounds == nullptr) {
      throw std::logic_error("structure '" + d.info.name +
                             "': its description has no loop-guard bounds (bound_events)");
    }
    for (const StructureDescriptor& o : own) {
      if (o.info.name == d.info.name) d.make = o.make;
    }
    if (d.make == nullptr) {
      throw std::logic_error("structure '" + d.info.name +
                             "' takes constructor arguments besides its motions: it needs a "
                             "binding of its own (src/run/structures/)");
    }
    out.push_back(std::move(d));
  });
  for (const StructureDescriptor& o : own) {
    if (std::none_of(out.begin(), out.end(),
                     [&](const StructureDescriptor& d) { return d.info.name == o.info.name; })) {
      throw std::logic_error("src/run/structures/ binds '" + o.info.name +
                             "', which is not a structure of kinetic::Structures");
    }
  }
  return out;
}

}  // namespace

const std::vector<StructureDescriptor>& registry() {
  static const std::vector<StructureDescriptor> table = build_registry();
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
