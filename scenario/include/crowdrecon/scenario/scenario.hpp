// Scenario: what to simulate, read from a JSON file (docs/scenarios.md).
//
//   {
//     "format": "crowdrecon-scenario", "version": 1,
//     "name": "Madrid Arena hallway, 5 /m2, 30 % counter-flow",
//     "venue": "../venues/madrid-arena/hallway-periodic.json",   (relative to this file)
//     "population": {
//       "density_per_m2": 5.0,            (or "count": 180)
//       "counter_flow_fraction": 0.3,
//       "target": "to_exit", "counter_target": "to_court",
//       "body": {"mode": "paper", "reference": "../venues/bodies/thorax-18.json"},
//       "desired_speed_m_per_s": [0.8, 1.2],
//       "placement": {"region": "walkable", "max_overlap_m": 0.003},
//       "seed": 2012
//     },
//     "profile": "paper",              (a named model profile or a profile file: profile.hpp)
//     "model": { "restitution": 0.4, "back_force_gamma": 1.2, ... },   (engine::ModelParameters; wins over the profile)
//     "run": {"duration_s": 60, "output_fps": 10, "checkpoint_interval_s": 10, "contacts": true},
//     "timeline": { "inflows": [...], "events": [...], "falls": {...} }   (optional: timeline.hpp)
//   }
//
// Unknown keys and out-of-range values are errors naming the file, the JSON
// path and the allowed range.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "crowdrecon/engine/parameters.hpp"
#include "crowdrecon/geometry/population.hpp"
#include "crowdrecon/geometry/population_table.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/scenario/settle.hpp"
#include "crowdrecon/scenario/timeline.hpp"

namespace crowdrecon::scenario {

struct PopulationSpec {
  std::optional<std::size_t> count;       // exactly one of count and density
  std::optional<double> density_per_m2;   // persons per m^2 of the placement region
  // Numbers' defaults (and ranges) from the population table (geometry/population_table.hpp).
  double counter_flow_fraction = Default("counter_flow_fraction");  // share of people walking to counter_target
  std::string target;                     // venue target of the main flow
  std::string counter_target;             // venue target of the counter-flow
  geometry::PopulationMode body_mode = geometry::PopulationMode::kPaper;
  std::filesystem::path reference_body;   // body JSON (paper and circle modes)
  std::filesystem::path anthropometry;    // ANSUR II extract (anthropometric mode)
  double female_fraction = Default("body.female_fraction");
  std::size_t vertex_count = static_cast<std::size_t>(Default("body.vertices"));  // anthropometric bodies
  double desired_speed_min_m_per_s = Default("desired_speed_m_per_s");  // v0 ~ U(min, max), paper
  double desired_speed_max_m_per_s = geometry::PopulationKey("desired_speed_m_per_s").default_high;
  std::string placement_region = "walkable";  // "walkable" or "entries"
  double max_initial_overlap_m = Default("placement.max_overlap_m");  // after relaxation of the placement
  std::uint64_t seed = static_cast<std::uint64_t>(Default("seed"));

  static double Default(std::string_view path) { return geometry::PopulationKey(path).default_value; }
};

struct RunSpec {
  double duration_s = 60.0;
  double output_fps = 10.0;
  double checkpoint_interval_s = 10.0;  // 0 = none
  bool write_contacts = true;  // run.contacts true: every frame's contacts; false: none
  // run.contacts as an object (issue 66): the contacts of some frames only --
  // every `contacts_every_s` seconds (0: none at a rate) and, with
  // `contacts_worst`, those of the report's worst moment (F0 and smoothing
  // of reports::RiskOptions' defaults; worst_moment.hpp); every frame's
  // contact forces in the report's histogram (table contact_forces).
  bool lean_contacts = false;
  double contacts_every_s = 0.0;
  bool contacts_worst = true;
  // run.frames: "tables" (rows of trajectory_data, person_state and
  // person_load: PedPy reads the run file itself) or "packed" (table
  // frame_pack, without loss, about a tenth of the bytes: crowdrecon reads
  // it as the tables, PedPy reads `crowdrecon export`'s file; issue 66).
  bool packed_frames = false;
  // Stop once the regime has settled (run.stop_when_settled: an object,
  // possibly empty, of SettleOptions; absent = run the whole duration).
  SettleOptions settle;
};

struct Scenario {
  std::string name;
  std::vector<std::string> notes;  // "notes": assumptions and their sources (free text)
  // Settings the file gives that change nothing here, each as one line that
  // says why ("model.give_way_blocked_s changes nothing: it acts only when
  // give_way = where_room (here give_way is none)"; a slope's gradient while
  // the slope is off): the commands print them as notes.
  std::vector<std::string> settings_without_effect;
  std::filesystem::path file;  // where it was read from ("" if from text)
  // As given, with its profile's values written in where it gives none of
  // its own (kept in the run file).
  std::string json_text;
  // The model profile it runs ("profile", scenario/profile.hpp; "paper"
  // without one: the engine's defaults are the paper's model).
  std::string profile;
  std::filesystem::path venue_file;
  geometry::Venue venue;
  PopulationSpec population;
  engine::ModelParameters model;
  RunSpec run;
  TimelineSpec timeline;  // "timeline": inflow, exits, timed events, falls (timeline.hpp)
};

Scenario LoadScenario(const std::filesystem::path& file);
// The scenario under another model profile than its own "profile" (a name
// of venues/profiles/ or a profile file, relative to the working folder):
// the file read as if its "profile" said `profile` (its own single values
// still win). For comparing profiles without editing the scenario
// (`crowdrecon simulate --profile`); empty: LoadScenario(file).
Scenario LoadScenario(const std::filesystem::path& file, const std::string& profile);
// `base_dir` resolves relative paths; `origin` names the text in messages.
Scenario ParseScenario(const std::string& json_text, const std::string& origin,
                       const std::filesystem::path& base_dir);

// The project's root (where venues/ lives) for default reference files: the
// CROWDRECON_DATA_DIR environment variable, or the source tree the program was
// built from.
std::filesystem::path DataDirectory();

}  // namespace crowdrecon::scenario
