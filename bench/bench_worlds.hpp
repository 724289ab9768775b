// Worlds for the benchmarks: the scenarios under bench/scenarios/, loaded and
// built through the scenario library exactly as `crowdrecon simulate` builds
// them (population, placement, relaxation), once per process.
#pragma once

#include <filesystem>
#include <string>

#include "crowdrecon/scenario/scenario.hpp"
#include "crowdrecon/scenario/world_builder.hpp"

namespace crowdrecon::bench {

// bench/ of the source tree (CROWDRECON_BENCH_DIR in the environment, or the
// folder the program was built from).
std::filesystem::path BenchDirectory();

// bench/scenarios/<name>.json, or `name` itself if it names an existing file.
std::filesystem::path ScenarioPath(const std::string& name);

// The world of a scenario, built on first use and kept for the life of the
// process (building 10,000 people takes seconds). Not thread-safe; the
// benchmarks call it from the main thread.
const scenario::BuiltWorld& CachedWorld(const std::string& name);

}  // namespace crowdrecon::bench
