#pragma once
// "Did you mean": the closest of a list of names to a word that is not one of them, for the
// messages that refuse a misspelt name (a structure, an option, a query type).

#include <cstddef>
#include <span>
#include <string>

namespace kinetic {

/// Edit distance between a and b: insertions, deletions, substitutions and transpositions of
/// neighbours (optimal string alignment).
[[nodiscard]] std::size_t edit_distance(const std::string& a, const std::string& b);

/// The name of `names` closest to `word` when it is close enough to be a likely misspelling
/// (within a third of the word's length, at least 2 edits), or one that `word` begins; "" when
/// none is.
[[nodiscard]] std::string closest_name(const std::string& word, std::span<const std::string> names);

}  // namespace kinetic
