// Sweep files: a grid of runs over scenario parameters (docs/sweeps.md).
//
//   {
//     "format": "crowdrecon-sweep", "version": 1,
//     "name": "Madrid Arena hallway: thorax and circle bodies",
//     "scenario": "../scenarios/hallway-5pm2-30cf.json",        (relative to this file)
//     "set": {"run.duration_s": 40, "run.contacts": false},     (every run)
//     "axes": [
//       {"path": "population.density_per_m2", "from": 3, "to": 7, "count": 9},
//       {"path": "population.counter_flow_fraction", "values": [0, 0.25, 0.5]}
//     ],
//     "seeds": {"first": 1, "count": 3},                         (or [1, 2, 3]; sets population.seed)
//     "variants": [
//       {"name": "thorax", "set": {"population.body.mode": "paper"}},
//       {"name": "circle", "set": {"population.body.mode": "circle"}}
//     ],
//     "diagram": {"x": "population.density_per_m2", "y": "population.counter_flow_fraction"},
//     "keep_runs": false
//   }
//
// Overrides ("set", variants, axes, seeds) address the scenario JSON by dotted
// path ("model.back_force_gamma"); missing objects on the way are created.
// Each run's scenario is the base scenario with, in this order, "set", its
// variant's "set", its axis values and its seed applied, then read by the
// normal scenario parser (scenario::ParseScenario), so a path the scenario
// format does not know is an error like any unknown key. Relative paths in
// the base scenario resolve against the scenario's folder, as always; file
// paths given in overrides (venue, population.body.reference,
// population.body.anthropometry) resolve against the sweep file's folder.
//
// Runs = variants x axis grid x seeds, in that nesting order (variants
// outermost, the first axis next, seeds innermost): run i is always the same
// run of a given sweep file.
//
// Unknown keys and bad values are errors naming the file, the JSON path, the
// value and what was expected.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "crowdrecon/scenario/scenario.hpp"

namespace crowdrecon::sweep {

// One override: a dotted path into the scenario JSON and the value to put
// there, as JSON text (numbers, strings, objects, ...).
struct Override {
  std::string path;
  std::string json;
};

struct Axis {
  std::string path;                 // dotted scenario path
  std::vector<std::string> values;  // JSON text of each value, in order
  // The values as numbers when every value is a number (empty otherwise).
  std::vector<double> numbers;
  bool numeric() const { return !numbers.empty(); }
};

struct Variant {
  std::string name;  // letters, digits, '.', '_', '-'
  std::vector<Override> set;
};

struct SweepSpec {
  std::filesystem::path file;  // the sweep file ("" if parsed from text)
  std::string origin;          // names the sweep in messages
  std::string canonical_json;  // the sweep, parsed and re-written compactly (compared on resume)
  std::string name;
  std::filesystem::path scenario_file;  // absolute
  std::string scenario_text;            // the base scenario as read
  std::string scenario_canonical_json;  // and compact
  std::vector<Override> set;            // applied to every run
  std::vector<Axis> axes;
  std::vector<std::uint64_t> seeds;     // at least one
  std::vector<Variant> variants;        // at least one ("base" if none given)
  std::string diagram_x, diagram_y;     // axis paths ("" if the sweep has fewer axes)
  bool keep_runs = false;               // keep each run's file in DIR/runs/
  // Write each finished run's summary for an ensemble (reports/ensemble.hpp,
  // timeline's default options) to DIR/summaries/RUN_ID.json: the part of a
  // long ensemble to keep in a repository while its runs go on elsewhere.
  bool ensemble_summaries = false;

  // variants x axis values x seeds, saturating at SIZE_MAX (never wraps).
  std::size_t RunCount() const;
};

// The most runs a sweep file may ask for. Every run's scenario is built and
// checked before the first run starts (about 1 ms each), so this keeps the
// start under a couple of minutes; a larger study is several sweep files.
inline constexpr std::size_t kMaxSweepRuns = 100000;

// One run of a sweep.
struct RunPlan {
  std::size_t index = 0;               // 0-based, in the fixed order
  std::string id;                      // "0007-thorax-density_per_m2=3.5-counter_flow_fraction=0.125-seed1"
  std::size_t variant = 0;             // index into SweepSpec::variants
  std::vector<std::size_t> axis_value; // per axis, index into Axis::values
  std::uint64_t seed = 0;
  // e.g. "variant thorax, population.density_per_m2 = 3.5, population.counter_flow_fraction = 0.125, seed 1"
  std::string description;
};

SweepSpec LoadSweep(const std::filesystem::path& file);
// `base_dir` resolves the scenario path; `origin` names the text in messages.
SweepSpec ParseSweep(const std::string& json_text, const std::string& origin,
                     const std::filesystem::path& base_dir);

// Every run of the sweep, in run-index order.
std::vector<RunPlan> ExpandRuns(const SweepSpec& spec);

// The run's scenario JSON: the base scenario with every override applied.
// Throws InputError naming the sweep file and the run if an override cannot
// be applied (a path through a value that is not an object).
std::string RunScenarioJson(const SweepSpec& spec, const RunPlan& run);

// The run's scenario, read by the normal scenario parser. Its `file` is the
// base scenario's (relative paths and the analysis's venue lookup go through
// it). Throws InputError "SWEEP: run 7 (variant thorax, ...): SCENARIO: /path: ..."
// for a scenario the overrides made invalid.
scenario::Scenario RunScenarioOf(const SweepSpec& spec, const RunPlan& run);

// Reads every run's scenario once, so that a bad override fails before any
// run starts. Throws the first run's InputError. Returns the settings that
// change nothing (Scenario::settings_without_effect), each once, with the
// number of runs it concerns ("... (in 6 of 6 runs)").
std::vector<std::string> ValidateRuns(const SweepSpec& spec, const std::vector<RunPlan>& runs);

// Value `index` of `axis` as shown in tables and pictures: numbers in their
// shortest exact form, strings as they are, anything else as compact JSON.
std::string AxisValueText(const Axis& axis, std::size_t index);

// Shortest decimal text that reads back as exactly `value` ("0.1", "3",
// "1e-07"); "" for NaN. Used wherever results must compare exactly.
std::string ExactNumber(double value);

}  // namespace crowdrecon::sweep
