// The ANSUR II thorax extract (geometry::ReadAnsurExtract, CSV), which
// scenarios name as population.body.anthropometry.
#include "crowdrecon/geometry/anthropometry.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const auto file = fuzz::WriteScratchFile(data, size, "csv");
  return fuzz::Parse([&] { (void)geometry::ReadAnsurExtract(file); });
}
