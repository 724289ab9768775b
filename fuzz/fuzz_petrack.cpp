// PeTrack trajectory text files (observe::ReadPeTrack), the Jülich format of
// ../shared/data.
#include "crowdrecon/observe/petrack.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const auto file = fuzz::WriteScratchFile(data, size, "txt");
  return fuzz::Parse([&] { (void)observe::ReadPeTrack(file); });
}
