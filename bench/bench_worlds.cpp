#include "bench_worlds.hpp"

#include <algorithm>
#include <cstdlib>
#include <map>
#include <memory>
#include <thread>

namespace crowdrecon::bench {

std::filesystem::path BenchDirectory() {
  if (const char* dir = std::getenv("CROWDRECON_BENCH_DIR"); dir != nullptr && *dir != '\0') return dir;
  return CROWDRECON_BENCH_DIR;
}

std::filesystem::path ScenarioPath(const std::string& name) {
  if (std::filesystem::is_regular_file(name)) return name;
  return BenchDirectory() / "scenarios" / (name + ".json");
}

const scenario::BuiltWorld& CachedWorld(const std::string& name) {
  // unique_ptr: references handed out stay valid while the map grows.
  static std::map<std::string, std::unique_ptr<scenario::BuiltWorld>> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    const scenario::Scenario sc = scenario::LoadScenario(ScenarioPath(name));
    // The placement does not depend on the thread count; use every core to
    // build it quickly. Callers set WorldDef::threads for what they measure.
    const int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    auto built = std::make_unique<scenario::BuiltWorld>(scenario::BuildWorld(sc, threads));
    it = cache.emplace(name, std::move(built)).first;
  }
  return *it->second;
}

}  // namespace crowdrecon::bench
