// An inflow's rate schedule as CSV (scenario::ReadRateCsv), which scenarios
// name as timeline.inflows[].rate_csv.
#include "crowdrecon/scenario/timeline.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const auto file = fuzz::WriteScratchFile(data, size, "csv");
  return fuzz::Parse([&] {
    const scenario::RateSchedule rate = scenario::ReadRateCsv(file);
    (void)scenario::ArrivalsDue(rate, 1e6);
  });
}
