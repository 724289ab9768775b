// DXF floor plans (geometry::ImportDxf through dxflib, which reads a path).
#include "crowdrecon/geometry/venue.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const auto file = fuzz::WriteScratchFile(data, size, "dxf");
  return fuzz::Parse([&] { (void)geometry::ImportDxf(file); });
}
