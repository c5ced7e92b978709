#pragma once
// The box datasets (private to the scenario layer; generate() dispatches to them): moving boxes
// for the collision structures. Parameters and formulas are in docs/datasets.md.

#include <string>
#include <vector>

#include "kinetic/scenario/generators.hpp"

namespace kinetic::scenario::detail {

/// boxes-linear, boxes-ballistic, tunnelling, boxes-mixed, boxes-pile.
[[nodiscard]] const std::vector<std::string>& box_dataset_names();
[[nodiscard]] bool is_box_dataset(const std::string& name);
/// Throws std::invalid_argument for options the dataset cannot honour.
[[nodiscard]] Scenario generate_boxes(const std::string& name, const GeneratorOptions& options);

}  // namespace kinetic::scenario::detail
