// Engine world files (engine::LoadWorld: magic, counts, enums, navigation
// grids), from memory. A world file ends with an FNV-1a checksum of the bytes
// before it, which would reject nearly every mutated input at once; so the
// fuzzer's input is a world file WITHOUT its last 8 bytes, and the harness
// appends the right checksum (the seeds in fuzz/corpus/fuzz_world_file/ are
// stored that way). The checksum test itself is covered by the unit tests.
#include <cstring>

#include "crowdrecon/common/fnv.hpp"
#include "crowdrecon/engine/world_file.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  std::string world = fuzz::Text(data, size);
  const std::uint64_t checksum = Fnv1a(world.data(), world.size());
  world.append(reinterpret_cast<const char*>(&checksum), sizeof(checksum));
  return fuzz::Parse([&] { (void)engine::LoadWorld(world, "fuzz.world"); });
}
