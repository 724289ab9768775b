// Scenario files (scenario::ParseScenario), from memory. Relative paths
// (venue, body reference) resolve against tests/data/scenarios/, so the seeds
// copied from there find their venues and bodies.
#include "crowdrecon/scenario/scenario.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  return fuzz::Parse([&] {
    (void)scenario::ParseScenario(fuzz::Text(data, size), "fuzz-scenario.json",
                                  fuzz::SourceDir() / "tests/data/scenarios");
  });
}
