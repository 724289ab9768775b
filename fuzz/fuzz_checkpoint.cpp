// Engine checkpoints (engine::Simulation::LoadState, the state `crowdrecon
// simulate --resume` restores from RUN.sqlite.checkpoint), then a few steps
// of the restored world. A state ends with an FNV-1a checksum of the bytes
// before it, which would reject nearly every mutated input at once; so the
// fuzzer's input is a state WITHOUT its last 8 bytes, and the harness
// appends the right checksum (the checksum test itself is a unit test). The
// world is the seed of fuzz_world_file (2 x 2 people, a wall, a grid target),
// read once; the seed state is that world's after 40 steps with the people
// drawn together (positions 0.7 times as far from their centre, moving
// towards it at 4 m/s per metre: 5 contacts, walls included). Whatever the
// state holds, LoadState either refuses it (InputError) or the world it
// leaves steps without a fault: a SimulationError (a state that goes
// numerically wrong, stopped with a message) is the engine doing its job too.
#include "crowdrecon/common/fnv.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/engine/world_file.hpp"
#include "fuzz_harness.hpp"

namespace {

const crowdrecon::engine::WorldDef& World() {
  static const crowdrecon::engine::WorldDef world = [] {
    std::string bytes = crowdrecon::ReadInputFile(
        crowdrecon::fuzz::SourceDir() / "fuzz/corpus/fuzz_world_file/gas-2x2-wall-grid.world-nochecksum", "world");
    const std::uint64_t checksum = crowdrecon::Fnv1a(bytes.data(), bytes.size());
    bytes.append(reinterpret_cast<const char*>(&checksum), sizeof(checksum));
    return crowdrecon::engine::LoadWorld(bytes, "fuzz.world");
  }();
  return world;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  std::string state = fuzz::Text(data, size);
  const std::uint64_t checksum = Fnv1a(state.data(), state.size());
  state.append(reinterpret_cast<const char*>(&checksum), sizeof(checksum));
  return fuzz::Parse([&] {
    engine::Simulation sim(World());
    sim.LoadState(state);
    try {
      for (int step = 0; step < 3; ++step) sim.Step();
    } catch (const engine::SimulationError&) {
    }
  });
}
