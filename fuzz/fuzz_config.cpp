// libFuzzer target: the configuration reader (src/config/scenario_reader.cpp): TOML text -> Scenario, with
// the reader's validation (types, ranges, unknown keys). A clean refusal (gyrocal::Error) is fine; anything
// else escaping, a crash, a leak or undefined behaviour is a finding. A configuration that is accepted must
// also survive the writer: scenario_to_toml's text parses back without error to the same text
// (config_io.hpp promises a bit-exact round trip for any scenario that parse_scenario returned).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "gyrocal/config/config_io.hpp"
#include "gyrocal/core/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  gyrocal::Scenario scenario;
  try {
    scenario = gyrocal::parse_scenario(text, "fuzz.toml");
  } catch (const gyrocal::Error&) {
    return 0;  // a clean refusal
  }
  // Accepted: the writer's text must read back (an Error escaping from here is a finding) to itself.
  const std::string written = gyrocal::scenario_to_toml(scenario);
  const gyrocal::Scenario again = gyrocal::parse_scenario(written, "written.toml");
  if (gyrocal::scenario_to_toml(again) != written) std::abort();
  return 0;
}
