// JuPedSim SQLite trajectory files, versions 1-3 (observe::ReadJuPedSim).
#include "crowdrecon/observe/trajectories.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const auto file = fuzz::WriteScratchFile(data, size, "sqlite");
  return fuzz::Parse([&] { (void)observe::ReadTrajectories(file); });
}
