// Running the validation suite on one or two model profiles
// (`crowdrecon validate`, docs/validation.md).
//
// Every test of the suite (validation_test.hpp) is a sweep (sweep/): its
// scenario with the test's overrides, then the profile's, its cases as the
// sweep's variants and its seeds; the runs go through the sweep machinery
// (parallel over cores, resumable: run again on the same folder and the runs
// that have rows are not run again). Each run is measured (measures.hpp) as
// soon as it ends, before its file is removed; an experiment's trajectories
// are measured with the same code. The criteria are then judged over the
// seeds, and the report (report.html, report.pdf, results.json, results.csv)
// written.
//
// Folder:
//   DIR/validation.json                 what this folder is (the suite, the profiles)
//   DIR/report.html, report.pdf          the report (validation_report.hpp)
//   DIR/results.json, results.csv        every criterion's value and verdict
//   DIR/runs/PROFILE/TEST-HASH/          the test's sweep (sweep.json, results.*, measures/RUN.json)
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/validate/measures.hpp"
#include "crowdrecon/validate/validation_test.hpp"

namespace crowdrecon::validate {

struct ValidateOptions {
  std::filesystem::path suite;                   // the suite folder (venues/validation) or one test file
  std::vector<std::filesystem::path> profiles;   // one or two profile files
  std::filesystem::path output_dir;
  std::vector<std::string> only;                 // test ids (empty: every test)
  bool quick = false;                            // only the tests marked quick
  int seeds = 0;                                 // > 0: at most this many seeds per test (a trial)
  int jobs = 0;                                  // runs at a time (0: the cores)
  bool pdf = true;
  std::string chromium;                          // "" : found on PATH
  bool show_progress = false;                    // the sweeps' progress lines
  std::function<void(const std::string&)> progress;  // a line per test started and ended

  bool IsValid(std::string* error) const;
};

// One criterion judged on one case.
struct CaseVerdict {
  std::string case_name;
  double value = 0.0;     // the aggregate (NaN where it does not exist)
  std::string text;       // "28.6 s", "26.1-31.9 (every value of 10 seeds)", ...
  std::string expected;   // "[26, 34]", "0.98-1.22 (data)", ...
  bool judged = false;    // false: documents, or nothing to judge
  bool pass = false;
};

struct CriterionVerdict {
  Criterion criterion;
  std::vector<CaseVerdict> cases;  // one for a ratio or a rise over cases
  bool judged = false;
  bool pass = false;
};

enum class Verdict { kPass, kFail, kDocuments, kError };
std::string ToString(Verdict verdict);

// What one test gave on one profile.
struct TestResult {
  std::string test_id, profile;
  Verdict verdict = Verdict::kDocuments;
  std::string error;                          // kError: why
  std::vector<CriterionVerdict> criteria;
  // The statistics of each case's runs, in seed order ([case][seed]); a
  // failed run has completed = 0 and its message in failures.
  std::vector<std::vector<Statistics>> runs;
  std::vector<std::string> failures;          // "seed 3: failed: ..." per failed run
  std::optional<Statistics> data;             // the experiment, measured alike
  // The setup of the first run: its walls and where people stood at the start.
  std::vector<std::vector<Vec2>> walls;
  std::vector<Vec2> start_positions;
  double wall_s = 0.0;                        // the runs' wall time, summed
};

// Judges a test's criteria on statistics already measured (exposed for tests).
TestResult Judge(const ValidationTest& test, const std::string& profile, std::vector<std::vector<Statistics>> runs,
                 std::optional<Statistics> data);

struct ValidateSummary {
  std::vector<Profile> profiles;
  std::vector<ValidationTest> tests;
  std::vector<std::vector<TestResult>> results;  // [profile][test]
  bool interrupted = false;
  double wall_s = 0.0;
  std::filesystem::path html, pdf, json, csv;
  std::vector<std::string> notes;

  int Count(Verdict verdict) const;
  std::string BriefReport() const;
  // 0: every judged criterion passed; 1: some failed (or a test could not
  // run); 130: interrupted.
  int ExitStatus() const;
};

ValidateSummary RunValidation(const ValidateOptions& options);

// A validation folder (validation.json and what it lists), which a new
// validation may write into (docs/validation.md).
OutputKind ValidationFolderOutput();

// What a validation's results.json (ResultsJson: `crowdrecon validate`
// writes it) says of each profile, for other outputs to cite (the injury-risk
// report's methods page, `report --validation`): per profile, how many
// tests it passes and which it fails, with their roles. The file's other
// contents (criteria, values) are not read here.
struct ProfileVerdicts {
  std::string name;
  std::size_t tests = 0, passed = 0;
  std::vector<std::string> failed;  // "test-id (role)", in the suite's order; errors too
};
struct ValidationSummary {
  std::string origin;          // the file
  std::string build, sources;  // the build that judged (its version and source fingerprint)
  std::vector<ProfileVerdicts> profiles;
  const ProfileVerdicts* Find(const std::string& profile) const;  // null: not in it
};
// Throws InputError naming the file and JSON path where the text is not a
// validation's results (format "crowdrecon-validation-results", version 1).
ValidationSummary ParseValidationSummary(const std::string& text, const std::string& origin);
ValidationSummary LoadValidationSummary(const std::filesystem::path& results_json);

// Statistics to and from JSON (NaN as null): the measures' files.
std::string StatisticsToJson(const Statistics& statistics);
Statistics StatisticsFromJson(const std::string& text, const std::string& origin);

}  // namespace crowdrecon::validate
