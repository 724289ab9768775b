// One line of milliseconds per step of each stage of Simulation::Step(),
// between two readings of Simulation::profile() `steps` steps apart
// (crowdrecon_step_world --profile, crowdrecon_bench_lammps --profile).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include "crowdrecon/engine/simulation.hpp"

namespace crowdrecon::bench {

inline std::string StageProfileText(const engine::Profile& before, const engine::Profile& after, std::uint64_t steps) {
  const double n = static_cast<double>(steps);
  std::string text = "ms/step by stage:";
  char value[64];
  for (const engine::StageInfo& stage : engine::kStages) {
    std::snprintf(value, sizeof value, " %s %.4f", stage.name, (after.seconds(stage.stage) - before.seconds(stage.stage)) * 1e3 / n);
    text += value;
  }
  std::snprintf(value, sizeof value, "  (pair rebuilds %llu, pairs measured per step %.1f)",
                static_cast<unsigned long long>(after.pair_rebuilds - before.pair_rebuilds),
                static_cast<double>(after.pairs_measured - before.pairs_measured) / n);
  return text + value;
}

}  // namespace crowdrecon::bench
