// Raster floor plans (geometry::ImportRasterPlan: OpenCV decodes the image,
// the project traces and simplifies it), at 50 pixels per metre like the
// seed tests/data/venues/room-50ppm.png.
#include "crowdrecon/geometry/venue.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const auto file = fuzz::WriteScratchFile(data, size, "png");
  geometry::RasterImportOptions options;
  options.pixels_per_metre = 50.0;
  return fuzz::Parse([&] { (void)geometry::ImportRasterPlan(file, options); });
}
