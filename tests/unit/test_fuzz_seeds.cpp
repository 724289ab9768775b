// The engine's fuzz seeds (fuzz/corpus/fuzz_world_file, fuzz_checkpoint)
// must be in the current formats: a seed the reader refuses at its magic
// gives the fuzzer no coverage, and fuzz_checkpoint reads its world from the
// world seed (a world file from before CRWORLD5 made every input a refusal
// without anyone noticing). Both seeds are stored without their checksum.
// To write them again after a format change, run
//   crowdrecon_engine_tests --gtest_also_run_disabled_tests
//     --gtest_filter=FuzzSeeds.DISABLED_WriteTheCheckpointSeedFromTheWorldSeed
// after converting the world seed (or writing a new one with SaveWorld).
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/fnv.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/engine/world_file.hpp"

namespace crowdrecon::engine {
namespace {

const std::string kWorldSeed = std::string(CROWDRECON_SOURCE_DIR) + "/fuzz/corpus/fuzz_world_file/gas-2x2-wall-grid.world-nochecksum";
const std::string kStateSeed =
    std::string(CROWDRECON_SOURCE_DIR) + "/fuzz/corpus/fuzz_checkpoint/gas-2x2-colliding-after-40-steps.state-nochecksum";

std::string Read(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string WithChecksum(std::string bytes) {
  const std::uint64_t checksum = Fnv1a(bytes.data(), bytes.size());
  bytes.append(reinterpret_cast<const char*>(&checksum), sizeof(checksum));
  return bytes;
}

TEST(FuzzSeeds, TheWorldAndCheckpointSeedsAreInTheCurrentFormats) {
  const WorldDef world = LoadWorld(WithChecksum(Read(kWorldSeed)), kWorldSeed);
  EXPECT_EQ(world.people.size(), 4u);
  Simulation sim(world);
  sim.LoadState(WithChecksum(Read(kStateSeed)));
  EXPECT_GT(sim.contacts().size(), 0u) << "the seed state has people in contact";
  for (int step = 0; step < 3; ++step) sim.Step();
}

// A state written before this format (CRSTATE2: a shorter parameter block)
// is refused as such, with what to do, rather than read as truncated.
TEST(FuzzSeeds, AStateOfTheFormerFormatIsRefusedAsSuch) {
  const WorldDef world = LoadWorld(WithChecksum(Read(kWorldSeed)), kWorldSeed);
  std::string state = Read(kStateSeed);
  ASSERT_EQ(state.substr(0, 8), "CRSTATE6");
  state[7] = '2';
  Simulation sim(world);
  try {
    sim.LoadState(WithChecksum(state));
    ADD_FAILURE() << "a version-2 state was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("written by an older crowdrecon (state format 2"), std::string::npos) << e.what();
  }
}

// A checkpoint of format 5 (before the behaviour terms' sections and the
// parameters' count; tests/data/checkpoints/, the seed as the build of
// 7df3dee wrote it) is still read, and holds the same state as the seed of
// format 6 written from the same world by this build: a run checkpointed
// before the change resumes after it.
TEST(FuzzSeeds, ACheckpointOfFormat5IsStillRead) {
  const WorldDef world = LoadWorld(WithChecksum(Read(kWorldSeed)), kWorldSeed);
  const std::string v5 = Read(std::string(CROWDRECON_SOURCE_DIR) +
                              "/tests/data/checkpoints/gas-2x2-colliding-after-40-steps.v5.state-nochecksum");
  ASSERT_EQ(v5.substr(0, 8), "CRSTATE5");
  Simulation old_format(world), new_format(world);
  old_format.LoadState(WithChecksum(v5));
  new_format.LoadState(WithChecksum(Read(kStateSeed)));
  for (int step = 0; step < 3; ++step) {
    old_format.Step();
    new_format.Step();
  }
  EXPECT_EQ(old_format.SaveState(), new_format.SaveState());
}

// A checkpoint writes contacts as they lie in memory: the bytes between their
// fields are named and zero, after a load of an older file (which may hold
// anything there) and after steps, so that one state always gives the same
// bytes (the test above compared unequal now and then before).
TEST(FuzzSeeds, ContactsCarryNoStrayBytesIntoCheckpoints) {
  const WorldDef world = LoadWorld(WithChecksum(Read(kWorldSeed)), kWorldSeed);
  Simulation sim(world);
  sim.LoadState(WithChecksum(Read(std::string(CROWDRECON_SOURCE_DIR) +
                                  "/tests/data/checkpoints/gas-2x2-colliding-after-40-steps.v5.state-nochecksum")));
  const auto all_zero = [](const Simulation& s) {
    for (const Contact& c : s.contacts())
      for (const std::uint8_t byte : c.padding_)
        if (byte != 0) return false;
    return true;
  };
  ASSERT_FALSE(sim.contacts().empty());
  EXPECT_TRUE(all_zero(sim));
  for (int step = 0; step < 3; ++step) sim.Step();
  ASSERT_FALSE(sim.contacts().empty());
  EXPECT_TRUE(all_zero(sim));
}

// The checkpoint seed: the world seed's people drawn together (positions 0.7
// times as far from their centre, moving towards it at 4 m/s per metre of
// distance) and stepped 40 times, saved without its checksum.
TEST(FuzzSeeds, DISABLED_WriteTheCheckpointSeedFromTheWorldSeed) {
  WorldDef world = LoadWorld(WithChecksum(Read(kWorldSeed)), kWorldSeed);
  Vec2 centre{};
  for (const PersonDef& p : world.people) centre += p.position_m * (1.0 / static_cast<double>(world.people.size()));
  for (PersonDef& p : world.people) {
    p.position_m = centre + (p.position_m - centre) * 0.7;
    p.velocity_m_per_s = (centre - p.position_m) * 4.0;
  }
  Simulation sim(world);
  for (int step = 0; step < 40; ++step) sim.Step();
  std::string state = sim.SaveState();
  state.resize(state.size() - sizeof(std::uint64_t));
  std::ofstream(kStateSeed, std::ios::binary | std::ios::trunc) << state;
}

}  // namespace
}  // namespace crowdrecon::engine
