// Fuzz harness (a): the scenario reader. Any bytes: parse_scenario either returns a scenario or
// throws ScenarioError with one line of bounded length; nothing else (no crash, no other
// exception, no hang). A scenario it accepts is written back and read again to the same value.

#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input.hpp"
#include "kinetic/scenario/scenario_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace kinetic::scenario;
  const std::string text(reinterpret_cast<const char*>(data), size);
  Scenario s;
  try {
    s = parse_scenario(text, "fuzz.json");
  } catch (const ScenarioError& e) {
    const std::string m = e.what();
    if (m.find('\n') != std::string::npos) kinetic::fuzz::fail("a message of two lines: " + m);
    if (m.size() > 600) kinetic::fuzz::fail("a message of " + std::to_string(m.size()) + " bytes");
    if (m.rfind("fuzz.json: $", 0) != 0) kinetic::fuzz::fail("a message without its path: " + m);
    return 0;
  }
  // Round trip: write_scenario's contract holds for a time-sorted timeline in file order.
  for (std::size_t i = 0; i < s.timeline.size(); ++i) {
    if (s.timeline[i].file_index != i) return 0;
  }
  const std::string written = write_scenario(s);
  Scenario again;
  try {
    again = parse_scenario(written, "written.json");
  } catch (const ScenarioError& e) {
    kinetic::fuzz::fail(std::string("a written scenario is refused: ") + e.what());
  }
  if (!(again == s)) kinetic::fuzz::fail("the round trip changed the scenario");
  return 0;
}
