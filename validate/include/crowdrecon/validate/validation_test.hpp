// The validation suite's inputs: tests, profiles and the suite (docs/validation.md).
//
// A test is data: one JSON file under venues/validation/tests/ with its
// source (the standard or the experiment, cited), its setup (a scenario,
// overrides, seeds, cases), what is measured (measures.hpp) and its criteria
// with their tolerances and why. A profile is the model and body blocks a
// scenario would carry ("paper", "circle", a user's own): the suite is run
// on a profile by applying it to every test's scenario.
//
//   {
//     "format": "crowdrecon-validation-test", "version": 1,
//     "id": "rimea-01", "title": "Walking speed in a corridor",
//     "standard": "RiMEA 4.1.1, test 1", "role": "verification",
//     "source": "RiMEA guideline 4.1.1 (2022), Annex 1, test 1 ...",
//     "setup": "one person walks 40 m of a 2 m wide corridor at 1.33 m/s",
//     "scenario": "../scenarios/rimea-01.json",
//     "seeds": {"first": 1, "count": 1},
//     "cases": [{"name": "base"}],
//     "measure": {"kind": "travel", "from": [[0, 0], [0, 2]], "to": [[40, 0], [40, 2]]},
//     "criteria": [{"statistic": "travel_time_s", "aggregate": "every", "within": [26, 34],
//                   "why": "the guideline's own band"}],
//     "quick": true
//   }
//
// Unknown keys and bad values are errors naming the file, the JSON path, the
// value and what was expected.
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "crowdrecon/common/distribution.hpp"
#include "crowdrecon/sweep/sweep_file.hpp"
#include "crowdrecon/validate/measures.hpp"

namespace crowdrecon::validate {

// What a test is for, decided before any profile is fitted (docs/validation.md,
// "Fitted and held out"): a standard's verification test (the model must
// pass it whatever it was fitted to), an experiment used to fit a profile, or
// an experiment held out to test it.
enum class Role { kVerification, kFit, kHeldOut };
std::string ToString(Role role);
bool FromString(const std::string& name, Role* role);

// How a statistic's values (per run, person or sample; pooled over the seeds
// of a case) become the one number a criterion judges.
enum class Aggregate { kEvery, kMedian, kMean, kMin, kMax, kP95 };
std::string ToString(Aggregate aggregate);
bool FromString(const std::string& name, Aggregate* aggregate);

enum class CriterionKind {
  kWithin,         // the aggregate (every value, for "every") in [low, high]
  kNearReference,  // within `relative` of the case's published values' range
  kWithinData,     // in the data's [quantile_low, quantile_high] of the same statistic
  kNearData,       // within `relative` of the data's aggregate of the same statistic
  kDataBand,       // fundamental diagram: the speed within band_sd standard deviations of the data's
                   // speeds at the run's density (+- band_width / 2)
  kIncreasing,     // the aggregate rises from case to case, in the cases' order
  kRatio,          // aggregate(case_b) / aggregate(case_a) in [low, high]
  kDocuments,      // no verdict: the standard documents behaviour only; shown
  kFollows,        // the pooled values follow a distribution: a Kolmogorov-Smirnov test at `alpha`
};
std::string ToString(CriterionKind kind);

struct Criterion {
  std::string statistic;
  Aggregate aggregate = Aggregate::kMedian;
  CriterionKind kind = CriterionKind::kWithin;
  double low = -std::numeric_limits<double>::infinity();
  double high = std::numeric_limits<double>::infinity();
  double relative = 0.0;
  double quantile_low = 0.25, quantile_high = 0.75;
  double band_sd = 2.0, band_width_per_m2 = 0.5;
  std::string case_a, case_b;       // ratio
  Distribution distribution;        // follows
  double alpha = 0.05;              // follows: the test's level
  std::vector<std::string> cases;   // the cases judged (empty: every case)
  std::string why;                  // the tolerance and its reason
  // One line: "travel_time_s (every) in [26, 34]".
  std::string Describe() const;
  // Whether the criterion judges the case of this name (`cases`, or every case).
  bool AppliesTo(const std::string& case_name) const {
    return cases.empty() || std::find(cases.begin(), cases.end(), case_name) != cases.end();
  }
};

// One case of a test: a named set of overrides (a width, a density, a share
// of counter-flow), with the published values it is compared with.
struct Case {
  std::string name;  // letters, digits, '.', '_', '-' (a sweep variant's name)
  std::string label;
  double x = std::numeric_limits<double>::quiet_NaN();  // where the case stands in the figure
  std::vector<sweep::Override> set;
  std::vector<double> reference;  // published values (near_reference: [min, max] of them)
};

// An experiment's trajectories measured with the test's measure in the
// experiment's own coordinates.
struct DataReference {
  std::filesystem::path trajectories;  // absolute
  std::string label;
  std::string unit;    // PeTrack unit ("" for the file's own)
  MeasureSpec measure;
};

// The test's figure in the report: by default a fundamental diagram for that
// measure, the first criterion's statistic against the cases' x where every
// case has one, or else the distribution of its values.
struct FigureSpec {
  enum class Kind { kDefault, kDistribution, kCumulative };
  Kind kind = Kind::kDefault;
  std::string statistic;  // distribution: this statistic ("" = the first criterion's)
  bool log = false;       // distribution: log axes (lapses, the tail of Zuriguel et al.)
};

struct ValidationTest {
  std::filesystem::path file;
  std::string id, title, standard, source, setup;
  std::vector<std::string> notes;
  Role role = Role::kVerification;
  std::filesystem::path scenario;      // absolute
  std::vector<sweep::Override> set;    // applied to every run, before the profile
  std::vector<std::uint64_t> seeds;
  std::vector<Case> cases;             // at least one ("base")
  std::string x_label;                 // the cases' axis in the figure ("" without one)
  MeasureSpec measure;
  std::string measure_json;            // as read, compact (what a run's stored measures depend on)
  std::optional<DataReference> data;
  std::vector<Criterion> criteria;     // none: the test only documents
  FigureSpec figure;
  bool quick = false;                  // in the quick subset (make test)
};

ValidationTest LoadValidationTest(const std::filesystem::path& file);
ValidationTest ParseValidationTest(const std::string& text, const std::string& origin,
                                   const std::filesystem::path& base_dir);

// A model profile: overrides of the scenario's model block (by key), its
// body block (as a whole) and the crowd's free speeds, applied after a test's
// own overrides and before its cases' (a case that prescribes speeds, as
// RiMEA's corridor does, keeps them).
//
//   {"format": "crowdrecon-profile", "version": 1, "name": "paper",
//    "description": "...", "model": {"restitution": 0.4}, "body": {"mode": "paper",
//    "reference": "../../bodies/thorax-18.json"}, "desired_speed_m_per_s": [0.8, 1.2]}
struct Profile {
  std::filesystem::path file;
  std::string name, description;
  std::vector<sweep::Override> set;  // model.KEY ..., population.body (paths made absolute)
  std::string canonical_json;        // as read, compact (the report's record)
};

Profile LoadProfile(const std::filesystem::path& file);
Profile ParseProfile(const std::string& text, const std::string& origin, const std::filesystem::path& base_dir);

// The tests of a suite: a folder's tests/*.json (the suite folder,
// venues/validation) or one test file, in the order of their ids.
std::vector<ValidationTest> LoadSuite(const std::filesystem::path& suite);

}  // namespace crowdrecon::validate
