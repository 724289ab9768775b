// The population's table: every number a scenario's "population" section
// gives, defined once -- its key, unit, default, allowed range, source and
// meaning. Derived from it: scenario::PopulationSpec's defaults, the scenario
// reader's ranges (scenario/src/scenario.cpp), the `population` subcommand's,
// PopulationOptions::IsValid for the options the scenario fills (count,
// female fraction, vertex count), and the population table of
// docs/scenarios.md (checked by tests/unit/test_world_builder.cpp). The model's
// parameters have their own table (engine/parameter_table.hpp).
#pragma once

#include <span>
#include <string>
#include <string_view>

namespace crowdrecon::geometry {

struct PopulationKeyInfo {
  const char* section = "";  // "" (population itself), "body" or "placement"
  const char* key = "";
  const char* unit = "";     // "" for counts and fractions
  double min = 0.0, max = 0.0;  // allowed range, both included
  bool integer = false;
  bool pair = false;            // [low, high], each in the range, low <= high
  double default_value = 0.0;   // (pairs: the low end)
  double default_high = 0.0;    // pairs: the high end
  const char* default_note = nullptr;  // instead of a default ("give this or ...")
  const char* source = "";      // "paper", "ANSUR II", "crowdrecon"
  const char* meaning = "";

  // "population.body.vertices"
  std::string Path() const;
  // "in [3, 200]", "a whole number in [1, 200000]", "[low, high] in [0, 10]"
  std::string Expected() const;
  bool Contains(double value) const;
  // "0.5", "[0.8, 1.2]", or the note.
  std::string DefaultText() const;
};

// The table, in the order of docs/scenarios.md.
std::span<const PopulationKeyInfo> PopulationKeyTable();
// The table as the Markdown of docs/scenarios.md ("| key | unit | default |
// range | source | meaning |"), one row per key.
std::string PopulationKeyTableMarkdown();
// The entry of `path` ("count", "body.vertices", "placement.max_overlap_m");
// throws std::logic_error if there is none (a programming error).
const PopulationKeyInfo& PopulationKey(std::string_view path);

}  // namespace crowdrecon::geometry
