// The timeline tests' scenes (test_timeline.cpp, test_timeline_runs.cpp): a
// scenario in the open hallway with a population, run and timeline spliced
// in, run into a scratch run file, with its census and events.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/analysis/timeline_series.hpp"
#include "crowdrecon/common/distribution.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/scenario/runner.hpp"
#include "crowdrecon/scenario/scenario.hpp"
#include "crowdrecon/scenario/timeline.hpp"
#include "scratch.hpp"

namespace crowdrecon::scenario::timeline_tests {

inline const std::filesystem::path kSource = CROWDRECON_SOURCE_DIR;

// A scenario in the open hallway (12 m x 3 m, exits "court" at x = 0 and
// "exit" at x = 12, entries 1.5 m deep at both ends) with `population`,
// `run` and `timeline` spliced in.
inline std::string Hallway(const std::string& population, const std::string& run, const std::string& timeline,
                    const std::string& venue = "venues/madrid-arena/hallway-open.json") {
  return R"({"format": "crowdrecon-scenario", "version": 1, "name": "timeline test",
    "venue": ")" + (kSource / venue).string() + R"(",
    "population": )" + population + R"(,
    "run": )" + run + R"(,
    "timeline": )" + timeline + "}";
}

struct TimelineRun {
  std::filesystem::path file;
  std::vector<runfile::CensusRow> census;
  std::vector<runfile::Event> events;
  std::string Value(const std::string& key) const { return runfile::RunFileReader(file).RunValue(key); }
  std::vector<runfile::Event> Kind(const std::string& kind) const {
    std::vector<runfile::Event> out;
    for (const runfile::Event& e : events)
      if (e.kind == kind) out.push_back(e);
    return out;
  }
};

inline TimelineRun Simulate(const std::string& json, const std::string& name, int threads = 1) {
  const Scenario s = ParseScenario(json, name + ".json", kSource);
  RunOptions options;
  options.output = crowdrecon::testing::ScratchFile(name + ".sqlite");
  std::filesystem::remove(options.output);
  options.threads = threads;
  RunScenario(s, options);
  TimelineRun run;
  run.file = options.output;
  const runfile::RunFileReader reader(run.file);
  run.census = reader.CensusRows();
  run.events = reader.Events();
  return run;
}

inline void ExpectConservation(const TimelineRun& run) {
  ASSERT_FALSE(run.census.empty());
  for (const runfile::CensusRow& r : run.census)
    ASSERT_EQ(r.census.entered, r.census.walking + r.census.fallen + r.census.removed) << "frame " << r.frame;
}

}  // namespace crowdrecon::scenario::timeline_tests
