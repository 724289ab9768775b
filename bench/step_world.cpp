// crowdrecon_step_world: a fixed number of steps of a saved world, for
// instruction counts (callgrind) and for interleaved timings of two builds
// with nothing else in the process (bench/README.md, "Steps of a saved world").
//
//   crowdrecon_step_world WORLD STATE [--steps=N] [--warm-up=N] [--threads=T] [--profile]
//
// WORLD and STATE are the files that `crowdrecon_bench_kernels
// --dump_worlds=DIR` writes (engine/world_file.hpp, Simulation::SaveState).
// After loading the state it takes --warm-up steps (20 by default: the first
// steps after a load measure every pair afresh), then --steps steps (100)
// inside MeasuredSteps(), the function to give callgrind:
//
//   valgrind --tool=callgrind --toggle-collect='*MeasuredSteps*'
//       build/release/bench/crowdrecon_step_world W.world W.state --steps=10
//   (one command)
//
// It prints one line: the wall time per measured step, the contact count
// after them and a checksum of the bodies' positions (two builds that give
// the same line did the same work). --profile adds a second line: the
// milliseconds per measured step of each stage (Simulation::profile()).
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <sstream>
#include <string>

#include "crowdrecon/common/fnv.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/engine/world_file.hpp"
#include "stage_profile.hpp"

namespace {

using crowdrecon::engine::Simulation;

// Kept out of line so that callgrind can collect exactly these steps.
__attribute__((noinline)) void MeasuredSteps(Simulation& simulation, int steps) {
  for (int i = 0; i < steps; ++i) simulation.Step();
}

int ParseCount(const char* arg, const char* flag) {
  const std::size_t n = std::strlen(flag);
  const std::string value(arg + n);
  std::size_t used = 0;
  int parsed = -1;
  try {
    parsed = std::stoi(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != value.size() || parsed < 0) {
    std::fprintf(stderr, "crowdrecon_step_world: %s'%s': expected a whole number >= 0\n", flag, value.c_str());
    std::exit(2);
  }
  return parsed;
}

}  // namespace

int main(int argc, char** argv) {
  const char* usage = "usage: crowdrecon_step_world WORLD STATE [--steps=N] [--warm-up=N] [--threads=T] [--profile]\n";
  std::string world_path, state_path;
  int steps = 100, warm_up = 20, threads = 1;
  bool profile = false;
  for (int i = 1; i < argc; ++i) {
    const char* arg = argv[i];
    if (std::strncmp(arg, "--steps=", 8) == 0) {
      steps = ParseCount(arg, "--steps=");
    } else if (std::strncmp(arg, "--warm-up=", 10) == 0) {
      warm_up = ParseCount(arg, "--warm-up=");
    } else if (std::strncmp(arg, "--threads=", 10) == 0) {
      threads = ParseCount(arg, "--threads=");
    } else if (std::strcmp(arg, "--profile") == 0) {
      profile = true;
    } else if (arg[0] == '-') {
      std::fprintf(stderr, "crowdrecon_step_world: unknown option '%s'\n%s", arg, usage);
      return 2;
    } else if (world_path.empty()) {
      world_path = arg;
    } else if (state_path.empty()) {
      state_path = arg;
    } else {
      std::fprintf(stderr, "crowdrecon_step_world: unexpected argument '%s'\n%s", arg, usage);
      return 2;
    }
  }
  if (state_path.empty() || threads < 1) {
    std::fprintf(stderr, "%s", usage);
    return 2;
  }
  try {
    crowdrecon::engine::WorldDef def = crowdrecon::engine::LoadWorldFile(world_path);
    def.threads = threads;
    std::ifstream in(state_path, std::ios::binary);
    if (!in) {
      std::fprintf(stderr, "crowdrecon_step_world: %s: cannot open the state file\n", state_path.c_str());
      return 1;
    }
    std::ostringstream state;
    state << in.rdbuf();
    Simulation simulation(std::move(def));
    simulation.LoadState(state.str());
    for (int i = 0; i < warm_up; ++i) simulation.Step();
    const crowdrecon::engine::Profile before = simulation.profile();
    const auto start = std::chrono::steady_clock::now();
    MeasuredSteps(simulation, steps);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    // A checksum of the positions' bytes: equal lines, equal work.
    const auto& positions = simulation.bodies().position_m;
    const std::uint64_t hash = crowdrecon::Fnv1a(positions.data(), positions.size() * sizeof(positions[0]));
    std::printf("%.4f ms/step  %d steps  %zu contacts  positions %016llx\n", steps > 0 ? ms / steps : 0.0, steps,
                simulation.contacts().size(), static_cast<unsigned long long>(hash));
    if (profile && steps > 0)
      std::printf("%s\n", crowdrecon::bench::StageProfileText(before, simulation.profile(),
                                                                static_cast<std::uint64_t>(steps))
                               .c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crowdrecon_step_world: %s\n", e.what());
    return 1;
  }
  return 0;
}
