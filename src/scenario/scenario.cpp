#include "kinetic/scenario/scenario.hpp"

namespace kinetic::scenario {

const char* to_string(OpKind op) {
  switch (op) {
    case OpKind::Query:
      return "query";
    case OpKind::Update:
      return "update";
    case OpKind::Insert:
      return "insert";
    case OpKind::Remove:
      return "remove";
  }
  return "unknown";
}

}  // namespace kinetic::scenario
