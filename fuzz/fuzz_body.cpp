// Body files (geometry::ReadBodyJson: format, ranges, a valid spheropolygon
// whose stored mass properties match the recomputed ones).
#include "crowdrecon/geometry/body.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const auto file = fuzz::WriteScratchFile(data, size, "json");
  return fuzz::Parse([&] { (void)geometry::ReadBodyJson(file); });
}
