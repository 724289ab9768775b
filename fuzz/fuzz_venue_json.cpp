// Venue JSON files (geometry::ParseVenue: syntax, keys, ranges, geometry), from memory.
#include "crowdrecon/geometry/venue.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  return fuzz::Parse([&] { (void)geometry::ParseVenue(fuzz::Text(data, size), "fuzz-venue.json"); });
}
