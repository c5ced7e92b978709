#pragma once
// The one exception type of the library's checked preconditions (see preconditions.hpp).

#include <stdexcept>
#include <string>

namespace kinetic {

/// A precondition of the public API does not hold: the message names the call and what is wrong.
class PreconditionError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Throws PreconditionError("<where>: <what>").
[[noreturn]] void precondition_failed(const char* where, const std::string& what);

/// A number for a message: shortest round-trip form ("10", "0.1", "1e+300", "inf").
[[nodiscard]] std::string format_number(double v);

}  // namespace kinetic
