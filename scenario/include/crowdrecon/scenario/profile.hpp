// Model profiles (issue 64): the model a scenario runs, in one documented
// place. A profile is the scenario's model block (by key), its population's
// body block and the crowd's free speeds; a scenario names one ("profile":
// "paper", or a profile file's path) and may still set single values of its
// own, which win. The named profiles live in venues/profiles/NAME.json
// (DataDirectory()); "paper" is the paper's model as the engine's defaults
// give it (Table 1, the paper's thorax bodies, desired speeds U(0.8, 1.2)
// m/s), and a scenario without a "profile" runs it.
//
//   {"format": "crowdrecon-profile", "version": 1, "name": "paper",
//    "description": "...", "model": {"restitution": 0.4}, "body": {"mode": "paper",
//    "reference": "../bodies/thorax-18.json"}, "desired_speed_m_per_s": [0.8, 1.2]}
//
// The validation suite (crowdrecon validate --profile FILE) reads the same files.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace crowdrecon::scenario {

struct ModelProfile {
  std::string name, description;
  std::filesystem::path file;  // where it was read ("" from text)
  // The model block's keys and their values (JSON text), each checked
  // against the parameter table; the body block (JSON text, its file paths
  // absolute); the free speeds [low, high] m/s.
  std::vector<std::pair<std::string, std::string>> model;
  std::string body_json;
  std::optional<std::pair<double, double>> desired_speed_m_per_s;
  std::string canonical_json;  // as read, compact (a report's record)
};

// The profile a scenario names with `name_or_file`: a name (letters, digits,
// '.', '_', '-', without ".json") is venues/profiles/NAME.json of
// DataDirectory(); anything else is a file, relative to `base_dir`.
std::filesystem::path ProfilePath(const std::string& name_or_file, const std::filesystem::path& base_dir);
// Whether `name_or_file` is a name (of venues/profiles/), not a file.
bool IsProfileName(const std::string& name_or_file);
ModelProfile LoadModelProfile(const std::filesystem::path& file);
ModelProfile ParseModelProfile(const std::string& text, const std::string& origin, const std::filesystem::path& base_dir);
// The names of venues/profiles/*.json, sorted.
std::vector<std::string> NamedProfiles();

// The name a scenario without "profile" runs under.
inline constexpr const char* kDefaultProfile = "paper";

}  // namespace crowdrecon::scenario
