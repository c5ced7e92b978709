#pragma once
// The project's one spelling of object identity: the user's id of an object, and the "no index"
// sentinel of every index-based array (absent object, node, slot or event).

#include <cstdint>

namespace kinetic {

/// The user's id of an object (the scenario's `id`). Structures work with dense table indices
/// (`std::uint32_t`); ids appear only at the API boundary.
using ObjectId = std::int64_t;

/// "No index": an absent object, node, slot or link in any index-based array.
inline constexpr std::uint32_t kNoIndex = UINT32_MAX;

}  // namespace kinetic
