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
  const auto per_step = [&](double a, double b) { return (a - b) * 1e3 / n; };
  char text[512];
  std::snprintf(text, sizeof text,
                "ms/step by stage: pairs %.4f  place %.4f  collide %.4f  gather %.4f  drive %.4f  integrate %.4f"
                "  check %.4f  (pair rebuilds %llu, pairs measured per step %.1f)",
                per_step(after.update_pairs_s, before.update_pairs_s),
                per_step(after.place_shapes_s, before.place_shapes_s), per_step(after.collide_s, before.collide_s),
                per_step(after.gather_s, before.gather_s), per_step(after.drive_s, before.drive_s),
                per_step(after.integrate_s, before.integrate_s), per_step(after.check_s, before.check_s),
                static_cast<unsigned long long>(after.pair_rebuilds - before.pair_rebuilds),
                static_cast<double>(after.pairs_measured - before.pairs_measured) / n);
  return text;
}

}  // namespace crowdrecon::bench
