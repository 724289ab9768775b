// Sweep files (sweep/sweep_file.hpp): parsing, errors that name the file, the
// JSON path, the value and what was expected; the grid of runs and its fixed
// order; the overrides as the scenario parser sees them; result rows.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <utility>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/scenario/runner.hpp"
#include "crowdrecon/sweep/results.hpp"
#include "crowdrecon/sweep/sweep_file.hpp"
#include "crowdrecon/sweep/sweep_runner.hpp"
#include "scratch.hpp"

namespace crowdrecon::sweep {
namespace {

const std::filesystem::path kSweepDir = std::filesystem::path(CROWDRECON_SOURCE_DIR) / "tests/data/sweeps";

SweepSpec Parse(const std::string& text) { return ParseSweep(text, "test.json", kSweepDir); }

// The error message of parsing `text` ("" if it parses).
std::string ErrorOf(const std::string& text) {
  try {
    Parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const std::string kHead = R"("format": "crowdrecon-sweep", "version": 1, "scenario": "../scenarios/sweep-tiny.json")";

TEST(SweepFile, GridOrderIdsAndValues) {
  const SweepSpec s = Parse("{" + kHead + R"(,
    "axes": [{"path": "population.density_per_m2", "from": 3, "to": 7, "count": 9},
             {"path": "population.counter_flow_fraction", "values": [0, 0.25, 0.5]}],
    "seeds": {"first": 4, "count": 3},
    "variants": [{"name": "thorax", "set": {"population.body.mode": "paper"}},
                 {"name": "circle", "set": {"population.body.mode": "circle"}}]})");
  ASSERT_EQ(s.axes.size(), 2u);
  ASSERT_EQ(s.axes[0].numbers.size(), 9u);
  EXPECT_EQ(s.axes[0].numbers.front(), 3.0);
  EXPECT_EQ(s.axes[0].numbers[1], 3.5);
  EXPECT_EQ(s.axes[0].numbers.back(), 7.0);  // the end exactly as given
  EXPECT_EQ(s.seeds, (std::vector<std::uint64_t>{4, 5, 6}));
  EXPECT_EQ(s.diagram_x, "population.density_per_m2");  // default: the first two axes
  EXPECT_EQ(s.diagram_y, "population.counter_flow_fraction");
  EXPECT_EQ(s.RunCount(), 2u * 9u * 3u * 3u);

  const std::vector<RunPlan> runs = ExpandRuns(s);
  ASSERT_EQ(runs.size(), s.RunCount());
  for (std::size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(runs[i].index, i);
  // Variants outermost, then the first axis, the second, seeds innermost.
  EXPECT_EQ(runs[0].id, "0000-thorax-density_per_m2=3-counter_flow_fraction=0-seed4");
  EXPECT_EQ(runs[1].seed, 5u);
  EXPECT_EQ(runs[3].axis_value, (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(runs[9].axis_value, (std::vector<std::size_t>{1, 0}));
  EXPECT_EQ(runs[81].variant, 1u);
  EXPECT_EQ(runs[81].id, "0081-circle-density_per_m2=3-counter_flow_fraction=0-seed4");
  EXPECT_EQ(runs.back().id, "0161-circle-density_per_m2=7-counter_flow_fraction=0.5-seed6");
  EXPECT_EQ(runs[3].description,
            "variant thorax, population.density_per_m2 = 3, population.counter_flow_fraction = 0.25, seed 4");
  // The same file always gives the same runs.
  const std::vector<RunPlan> again = ExpandRuns(Parse("{" + kHead + R"(,
    "axes": [{"path": "population.density_per_m2", "from": 3, "to": 7, "count": 9},
             {"path": "population.counter_flow_fraction", "values": [0, 0.25, 0.5]}],
    "seeds": {"first": 4, "count": 3},
    "variants": [{"name": "thorax", "set": {"population.body.mode": "paper"}},
                 {"name": "circle", "set": {"population.body.mode": "circle"}}]})"));
  for (std::size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(again[i].id, runs[i].id);
}

// A sweep file named without a folder ("sweep.json", in the working folder)
// has an empty parent path: its scenario resolves against the working folder
// (this used to stop with an internal error from fs::absolute("")).
TEST(SweepFile, AFileInTheWorkingFolderResolvesItsScenarioThere) {
  const std::filesystem::path here = std::filesystem::current_path();
  std::filesystem::current_path(kSweepDir);
  SweepSpec s;
  EXPECT_NO_THROW(s = ParseSweep("{" + kHead + "}", "test.json", ""));
  std::filesystem::current_path(here);
  EXPECT_EQ(s.scenario_file, (kSweepDir / "../scenarios/sweep-tiny.json").lexically_normal());
}

TEST(SweepFile, DefaultsWithoutAxesVariantsOrSeeds) {
  const SweepSpec s = Parse("{" + kHead + "}");
  EXPECT_EQ(s.variants.size(), 1u);
  EXPECT_EQ(s.variants[0].name, "base");
  EXPECT_EQ(s.seeds, (std::vector<std::uint64_t>{1}));  // the scenario's own seed
  EXPECT_EQ(s.RunCount(), 1u);
  EXPECT_EQ(ExpandRuns(s).size(), 1u);
  EXPECT_EQ(s.diagram_x, "");
}

TEST(SweepFile, IntegerRangesStayIntegers) {
  const SweepSpec s = Parse("{" + kHead + R"(, "axes": [{"path": "population.count", "from": 10, "to": 30, "count": 3}]})");
  EXPECT_EQ(s.axes[0].values, (std::vector<std::string>{"10", "20", "30"}));
}

TEST(SweepFile, OverridesAppliedInOrderAndReadByTheScenarioParser) {
  const SweepSpec s = Parse("{" + kHead + R"(,
    "set": {"run.duration_s": 2, "model.back_force_gamma": 0.6},
    "axes": [{"path": "model.back_force_gamma", "values": [2.4]}],
    "variants": [{"name": "v", "set": {"model.back_force_gamma": 1.0, "model.torsion_stiffness_lambda": 13.5,
                                       "population.body": {"mode": "circle"}}}],
    "seeds": [7]})");
  const RunPlan run = ExpandRuns(s).at(0);
  const scenario::Scenario sc = RunScenarioOf(s, run);
  EXPECT_EQ(sc.model.back_force_gamma, 2.4);  // the axis wins over the variant and "set"
  EXPECT_EQ(sc.model.torsion_stiffness_lambda, 13.5);
  EXPECT_EQ(sc.run.duration_s, 2.0);
  EXPECT_EQ(sc.population.seed, 7u);
  EXPECT_EQ(sc.population.body_mode, geometry::PopulationMode::kCircle);
  // Relative paths of the base scenario still resolve against its folder.
  EXPECT_TRUE(std::filesystem::exists(sc.venue_file)) << sc.venue_file;
  EXPECT_EQ(sc.file, s.scenario_file);
}

TEST(SweepFile, FilePathsInOverridesAreRelativeToTheSweepFile) {
  const SweepSpec s = Parse("{" + kHead + R"(,
    "set": {"population.body": {"mode": "paper", "reference": "../../../venues/bodies/thorax-18.json"}}})");
  const scenario::Scenario sc = RunScenarioOf(s, ExpandRuns(s).at(0));
  EXPECT_TRUE(std::filesystem::exists(sc.population.reference_body)) << sc.population.reference_body;
  EXPECT_EQ(sc.population.reference_body.filename(), "thorax-18.json");
}

TEST(SweepFile, UnknownScenarioPathNamesTheRun) {
  const SweepSpec s = Parse("{" + kHead + R"(, "axes": [{"path": "population.densty", "values": [1, 2]}]})");
  const std::vector<RunPlan> runs = ExpandRuns(s);
  try {
    ValidateRuns(s, runs);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("test.json: run 0 (variant base, population.densty = 1, seed 1)"), std::string::npos) << m;
    EXPECT_NE(m.find("sweep-tiny.json: /population: unknown key(s) \"densty\""), std::string::npos) << m;
  }
}

TEST(SweepFile, OverrideOutOfRangeNamesTheRunAndTheRange) {
  const SweepSpec s = Parse("{" + kHead + R"(, "axes": [{"path": "population.counter_flow_fraction", "values": [0.5, 1.5]}]})");
  try {
    ValidateRuns(s, ExpandRuns(s));
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("run 1 (variant base, population.counter_flow_fraction = 1.5, seed 1)"), std::string::npos) << m;
    EXPECT_NE(m.find("/population/counter_flow_fraction: value 1.5 is out of range"), std::string::npos) << m;
  }
}

// The error of a sweep file (the members after the head) when parsed and
// its first run's scenario written ("" if none).
std::string OverrideError(const std::string& members) {
  try {
    const SweepSpec s = Parse("{" + kHead + ", " + members + "}");
    (void)RunScenarioJson(s, ExpandRuns(s).at(0));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SweepFile, OverrideThroughANonObject) {
  const std::string m = OverrideError(R"("set": {"population.seed.x": 1}, "seeds": [1])");
  EXPECT_NE(m.find("test.json: run 0 (variant base, seed 1): cannot set \"population.seed.x\": "
                   "\"population.seed\" is 1 in the scenario, not an object"),
            std::string::npos)
      << m;
}

// A part of a path that is a number names an element of a list: an axis over
// one inflow's cap ("timeline.inflows.0.max_rate_per_s"); an index beyond the
// list is refused with the list's size.
TEST(SweepFile, ANumberInAPathNamesAListsElement) {
  const SweepSpec s = Parse("{" + kHead + R"(,
    "set": {"timeline": {"inflows": [{"entry": "a", "rate_per_s": 1}, {"entry": "b", "rate_per_s": 2}]}},
    "axes": [{"path": "timeline.inflows.1.max_rate_per_s", "values": [0.5, 1.5]}]})");
  const std::vector<RunPlan> runs = ExpandRuns(s);
  const nlohmann::json doc = nlohmann::json::parse(RunScenarioJson(s, runs.at(1)));
  EXPECT_EQ(doc["timeline"]["inflows"][1]["max_rate_per_s"], 1.5);
  EXPECT_EQ(doc["timeline"]["inflows"][1]["rate_per_s"], 2);
  EXPECT_FALSE(doc["timeline"]["inflows"][0].contains("max_rate_per_s"));
  const std::string m = OverrideError(
      R"("set": {"timeline": {"inflows": [{"entry": "a", "rate_per_s": 1}]}, "timeline.inflows.2.rate_scale": 2})");
  EXPECT_NE(m.find("cannot set \"timeline.inflows.2.rate_scale\": \"timeline.inflows\" is a list of 1 in the "
                   "scenario; expected an index 0..0, not \"2\""),
            std::string::npos)
      << m;
}

// Runs the sweep DIR/sweep.json into DIR/out, one run at a time.
SweepSummary RunSweepIn(const std::filesystem::path& dir) {
  SweepOptions options;
  options.sweep_file = dir / "sweep.json";
  options.output_dir = dir / "out";
  options.jobs = 1;
  return RunSweep(options);
}

// The header and first row of DIR/out/results.csv.
std::pair<std::string, std::string> FirstResultRow(const std::filesystem::path& dir) {
  std::ifstream csv(dir / "out" / "results.csv");
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  return {header, row};
}

// A scenario with a third group (an inflow's own: the Itaewon envelope's
// people walking along the food street) runs in a sweep; the table keeps the
// first two groups' columns (it stopped the sweep with an internal error).
TEST(SweepRunner, AThirdGroupsMetricsStayOutOfTheTable) {
  const std::filesystem::path dir = crowdrecon::testing::ScratchFile("sweep-three-groups");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string source = CROWDRECON_SOURCE_DIR;
  {
    std::ofstream f(dir / "scenario.json");
    f << R"({"format": "crowdrecon-scenario", "version": 1, "venue": ")" << source
      << R"(/venues/madrid-arena/hallway-open.json",
      "population": {"count": 12, "counter_flow_fraction": 0.5, "target": "to_exit", "counter_target": "to_court",
                     "body": {"mode": "circle"}, "seed": 4},
      "run": {"duration_s": 2, "output_fps": 10, "checkpoint_interval_s": 0, "contacts": false},
      "timeline": {"inflows": [{"entry": "from_court", "group": "along", "target": "to_exit", "rate_per_s": 2}]}})";
  }
  {
    std::ofstream f(dir / "sweep.json");
    f << R"({"format": "crowdrecon-sweep", "version": 1, "scenario": "scenario.json", "seeds": [1]})";
  }
  const SweepSummary summary = RunSweepIn(dir);
  EXPECT_EQ(summary.failed, 0u);
  const auto [header, row] = FirstResultRow(dir);
  EXPECT_NE(header.find("mean_speed_g1_m_per_s"), std::string::npos);
  EXPECT_EQ(header.find("_g2"), std::string::npos) << header;
  EXPECT_NE(row.find("complete"), std::string::npos) << row;
}

// A sweep of one seed of a test scenario in a scratch folder DIR (its
// output DIR/out), its run simulated up to `stop_after_s` and interrupted,
// as a sweep stopped by a signal leaves it: the folder and the run file
// (with `stop_after_s` < 0: run to its end, as a sweep stopped while it
// analysed the run leaves it).
struct InterruptedRun {
  std::filesystem::path dir, file;
};
InterruptedRun InterruptedSweepRun(const std::string& name, const std::string& scenario_file, int seed,
                                   double stop_after_s) {
  const std::filesystem::path dir = crowdrecon::testing::ScratchFile(name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "out" / "runs");
  {
    std::ofstream f(dir / "sweep.json");
    f << R"({"format": "crowdrecon-sweep", "version": 1, "scenario": ")" << CROWDRECON_SOURCE_DIR
      << "/tests/data/scenarios/" << scenario_file << R"(", "seeds": [)" << seed << R"(], "keep_runs": true})";
  }
  const SweepSpec spec = LoadSweep(dir / "sweep.json");
  const std::vector<RunPlan> runs = ExpandRuns(spec);
  EXPECT_EQ(runs.size(), 1u);
  const std::filesystem::path file = dir / "out" / "runs" / (runs.at(0).id + ".sqlite");
  scenario::RunOptions stopped;
  stopped.output = file;
  stopped.stop_after_s = stop_after_s;
  EXPECT_EQ(scenario::RunScenario(RunScenarioOf(spec, runs.at(0)), stopped).status,
            stop_after_s < 0 ? "complete" : "interrupted");
  return {dir, file};
}

// A run that goes numerically wrong after it resumed is recorded as failed
// with its files kept, not started over (it would fail again, identically,
// hours later for a long run, and its message and saved state were deleted).
// The run is interrupted before its failure (20 people sprinting into a wall
// go through it at 0.35 s), marked, and the sweep resumes it: the mark stays.
TEST(SweepRunner, ARunThatFailsAfterResumingIsRecordedFailedNotStartedOver) {
  const auto [dir, file] = InterruptedSweepRun("sweep-fails-after-resume", "bad-sprint-into-wall.json", 3, 0.1);
  ASSERT_TRUE(std::filesystem::exists(scenario::CheckpointPath(file)));
  {
    runfile::RunFileWriter writer = runfile::RunFileWriter::Resume(file, 1);
    writer.SetRunValue("test_mark", "the file of the first attempt");
  }
  const SweepSummary summary = RunSweepIn(dir);
  EXPECT_EQ(summary.failed, 1u);
  EXPECT_TRUE(std::filesystem::exists(file.string() + ".failed-state"));
  const runfile::RunFileReader reader(file);
  EXPECT_EQ(reader.RunValue("test_mark"), "the file of the first attempt") << "the run was started over";
  EXPECT_EQ(reader.RunValue("status").rfind("failed: ", 0), 0u) << reader.RunValue("status");
  const std::string row = FirstResultRow(dir).second;
  EXPECT_NE(row.find("went through wall"), std::string::npos) << row;
}

// A run that completed but has no row (the sweep was stopped or killed while
// analysing it: for a long run, its hours were spent) is analysed, not
// simulated again: the run file is the one that was there, and the row
// takes its wall time.
TEST(SweepRunner, ACompletedRunWithoutARowIsAnalysedNotSimulatedAgain) {
  const auto [dir, file] = InterruptedSweepRun("sweep-completed-no-row", "sweep-tiny.json", 2, -1.0);
  ASSERT_FALSE(std::filesystem::exists(scenario::CheckpointPath(file)));
  {
    runfile::RunFileWriter writer = runfile::RunFileWriter::Resume(file, 10);  // (marks it running)
    writer.SetRunValue("test_mark", "the file of the first attempt");
    writer.SetRunValue("wall_s", "5000");
    writer.SetStatus("complete");
  }
  const SweepSummary summary = RunSweepIn(dir);
  EXPECT_EQ(summary.completed, 1u);
  EXPECT_EQ(summary.failed, 0u);
  const runfile::RunFileReader reader(file);
  EXPECT_EQ(reader.RunValue("test_mark"), "the file of the first attempt") << "the run was simulated again";
  EXPECT_EQ(reader.RunValue("status"), "complete");
  const ResultsTable table = ReadResults(dir / "out");
  ASSERT_EQ(table.rows.size(), 1u);
  EXPECT_EQ(table.rows[0][table.Column("status")].text, "complete");
  EXPECT_GE(table.rows[0][table.Column("wall_s")].number, 5000.0);
  EXPECT_FALSE(table.rows[0][table.Column("mean_speed_m_per_s")].null);
}

// A run resumed by the sweep records the wall time of all its parts (the run
// file's wall_s, here as if its first part had taken 1,000 s), not the last
// part's alone: the hours of a long incident run interrupted by the end of a
// working day stay in the results.
TEST(SweepRunner, AResumedRunsWallTimeCountsItsEarlierParts) {
  const auto [dir, file] = InterruptedSweepRun("sweep-wall-time", "sweep-tiny.json", 2, 0.5);
  {
    runfile::RunFileWriter writer = runfile::RunFileWriter::Resume(file, 5);
    writer.SetRunValue("wall_s", "1000");
  }
  const SweepSummary summary = RunSweepIn(dir);
  EXPECT_EQ(summary.failed, 0u);
  const ResultsTable table = ReadResults(dir / "out");
  ASSERT_EQ(table.rows.size(), 1u);
  const double wall_s = table.rows[0][table.Column("wall_s")].number;
  EXPECT_GE(wall_s, 1000.0);
  EXPECT_LT(wall_s, 1600.0);
  EXPECT_GE(scenario::RecordedWallSeconds(file), 1000.0);
}

// A scratch folder DIR holding DIR/sweep.json: the test scenario
// sweep-tiny.json with `rest` (the sweep's other keys).
std::filesystem::path TinySweepIn(const std::string& name, const std::string& rest) {
  const std::filesystem::path dir = crowdrecon::testing::ScratchFile(name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream f(dir / "sweep.json");
  f << R"({"format": "crowdrecon-sweep", "version": 1, "scenario": ")" << CROWDRECON_SOURCE_DIR
    << "/tests/data/scenarios/sweep-tiny.json\", " << rest << "}";
  return dir;
}

// The sweep's last run (handed out when no other is left to start) may take
// the cores the runs before it free: with two at a time, the first two of
// three runs get one engine thread, the third up to two (the governor's
// account is in its run file); a sweep of one at a time gives every run one.
TEST(SweepRunner, TheLastRunMayTakeTheCoresTheOthersFree) {
  const std::filesystem::path dir =
      TinySweepIn("sweep-last-run-threads", R"("seeds": {"first": 1, "count": 3}, "keep_runs": true)");
  const std::vector<RunPlan> runs = ExpandRuns(LoadSweep(dir / "sweep.json"));
  ASSERT_EQ(runs.size(), 3u);
  const auto threads_account = [&](const std::string& out, std::size_t i) {
    const runfile::RunFileReader reader(dir / out / "runs" / (runs[i].id + ".sqlite"));
    EXPECT_EQ(reader.RunValue("status"), "complete");
    return reader.RunValue("engine_threads");  // "" when one thread was asked for
  };
  SweepOptions options;
  options.sweep_file = dir / "sweep.json";
  options.output_dir = dir / "two";
  options.jobs = 2;
  EXPECT_EQ(RunSweep(options).failed, 0u);
  EXPECT_EQ(threads_account("two", 0), "");
  EXPECT_EQ(threads_account("two", 1), "");
  const std::string last = threads_account("two", 2);
  if (std::thread::hardware_concurrency() >= 2) {
    EXPECT_TRUE(last.rfind("1 thread now", 0) == 0 || last.rfind("2 threads now", 0) == 0) << last;
    EXPECT_NE(last.find("steps at "), std::string::npos) << last;
  } else {
    EXPECT_EQ(last, "");  // one core: nothing to take
  }
  options.output_dir = dir / "one";
  options.jobs = 1;
  EXPECT_EQ(RunSweep(options).failed, 0u);
  for (std::size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(threads_account("one", i), "") << i;
  // The same results either way (every column but the wall time).
  const ResultsTable two = ReadResults(dir / "two"), one = ReadResults(dir / "one");
  ASSERT_EQ(two.rows.size(), 3u);
  ASSERT_EQ(one.rows.size(), 3u);
  const std::size_t wall = two.Column("wall_s");
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < two.rows[r].size(); ++c)
      if (c != wall) {
        EXPECT_EQ(two.rows[r][c].null, one.rows[r][c].null) << "run " << r << ", column " << two.columns[c];
        EXPECT_EQ(two.rows[r][c].text, one.rows[r][c].text) << "run " << r << ", column " << two.columns[c];
      }
}

// The lines of `text` that contain `what`.
std::vector<std::string> LinesWith(const std::string& text, const std::string& what) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (line.find(what) != std::string::npos) lines.push_back(line);
  return lines;
}

// A long run whose stderr is a log (RunOptions::log_progress_every_s) gets
// progress lines of their own (no carriage returns), none at the end, and a
// caller's counter follows the simulated time (a sweep reports from it).
TEST(Progress, ARunsLogGetsLinesOfTheirOwnAndTheCallerTheSimulatedTime) {
  const SweepSpec spec = Parse("{" + kHead + R"(, "seeds": [1]})");
  scenario::RunOptions options;
  options.output = crowdrecon::testing::ScratchFile("progress-log.sqlite");
  std::filesystem::remove(options.output);
  options.log_progress_every_s = 1e-9;  // every frame but the last
  std::atomic<double> simulated_s{-1.0};
  options.simulated_s = &simulated_s;
  ::testing::internal::CaptureStderr();
  const scenario::RunSummary summary = scenario::RunScenario(RunScenarioOf(spec, ExpandRuns(spec).at(0)), options);
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(summary.status, "complete");
  EXPECT_EQ(log.find('\r'), std::string::npos) << log;
  const std::vector<std::string> lines = LinesWith(log, "real-time factor");
  ASSERT_GE(lines.size(), 5u) << log;   // 1 s at 10 frames a second
  EXPECT_LE(lines.size(), 10u) << log;  // not at the last frame
  EXPECT_NE(lines.front().find("t = 0.1 / 1.0 s, real-time factor "), std::string::npos) << lines.front();
  EXPECT_NE(lines.front().find(", time left "), std::string::npos) << lines.front();
  EXPECT_EQ(simulated_s.load(), summary.simulated_s);
  EXPECT_NEAR(simulated_s.load(), 1.0, 1e-9);

  // Without the option (and without a progress line) nothing is said.
  options.log_progress_every_s = 0;
  std::filesystem::remove(options.output);
  ::testing::internal::CaptureStderr();
  scenario::RunScenario(RunScenarioOf(spec, ExpandRuns(spec).at(0)), options);
  EXPECT_EQ(LinesWith(::testing::internal::GetCapturedStderr(), "real-time factor").size(), 0u);
}

// A sweep whose stderr is a log says now and then how many runs are done and
// how far each running run has got.
TEST(Progress, ASweepsLogSaysHowFarEachRunningRunHasGot) {
  const std::filesystem::path dir =
      TinySweepIn("sweep-progress-log", R"("seeds": {"first": 1, "count": 2}, "set": {"run.duration_s": 150})");
  SweepOptions options;
  options.sweep_file = dir / "sweep.json";
  options.output_dir = dir / "out";
  options.jobs = 1;
  // At every look of the coordinator (every 200 ms at most; a run takes a
  // second or more of wall time even on a fast idle core, so that each is
  // seen running: 10 simulated s took 0.15 s and were missed).
  options.log_progress_every_s = 1e-9;
  ::testing::internal::CaptureStderr();
  const SweepSummary summary = RunSweep(options);
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(summary.failed, 0u);
  EXPECT_EQ(log.find('\r'), std::string::npos) << log;
  const std::vector<std::string> first = LinesWith(log, "sweep: 0 / 2 runs (0 failed), 1 running, ");
  const std::vector<std::string> second = LinesWith(log, "sweep: 1 / 2 runs (0 failed), 1 running, ");
  ASSERT_FALSE(first.empty()) << log;
  ASSERT_FALSE(second.empty()) << log;
  const std::vector<RunPlan> runs = ExpandRuns(LoadSweep(dir / "sweep.json"));
  EXPECT_FALSE(LinesWith(log, "; " + runs[0].id + " at ").empty()) << log;
  EXPECT_FALSE(LinesWith(log, "; " + runs[1].id + " at ").empty()) << log;
  EXPECT_NE(first.back().find(" / 150 s"), std::string::npos) << first.back();
}

TEST(SweepFile, ErrorsNameFilePathValueAndExpectation) {
  const struct {
    std::string body;
    std::string expected;
  } cases[] = {
      {R"("axs": [])", "test.json: /: unknown key(s) \"axs\""},
      // A key given twice is an error (the head already gives format and version).
      {R"("format": "crowdrecon-scenario")", "test.json:1:97: /format: key given twice"},
      {R"("version": 2)", "test.json:1:98: /version: key given twice (first at line 1 with value 1, again at line 1 with value 2)"},
      {R"("axes": [{"path": "population.density_per_m2"}])",
       "test.json: /axes/0: give either \"values\": [...] or \"from\", \"to\" and \"count\""},
      {R"("axes": [{"path": "population.density_per_m2", "values": [1], "from": 1}])", "/axes/0: give either"},
      {R"("axes": [{"path": "population.density_per_m2", "from": 1, "to": 2, "count": 0}])",
       "/axes/0/count: value 0 is out of range; expected an integer in [1, 100000]"},
      {R"("axes": [{"path": "population.density_per_m2", "values": []}])",
       "/axes/0/values: expected at least one value"},
      {R"("axes": [{"path": "population.density_per_m2", "values": [1, 1]}])", "value 1 appears twice"},
      {R"("axes": [{"path": "population..seed", "values": [1]}])",
       "/axes/0/path: \"population..seed\" is not a scenario path"},
      {R"("axes": [{"path": "population.seed", "values": [1]}])",
       "/axes/0/path: the seed is not an axis; give the seeds with \"seeds\""},
      {R"("axes": [{"path": "model.restitution", "values": [0.3]}, {"path": "model.restitution", "values": [0.4]}])",
       "/axes/1/path: axis \"model.restitution\" is given twice"},
      {R"("axes": [{"path": "model.restitution", "values": [0.3], "step": 1}])", "/axes/0: unknown key(s) \"step\""},
      {R"("seeds": [1, 2, 1])", "/seeds: seed 1 appears twice"},
      {R"("seeds": [1.5])", "/seeds/0: expected a whole number in [0, 2^62], found 1.5"},
      {R"("seeds": [-1])", "/seeds/0: expected a whole number in [0, 2^62], found -1"},
      {R"("seeds": {"count": 3, "last": 4})", "/seeds: unknown key(s) \"last\""},
      {R"("seeds": "three")", "/seeds: expected a list of seeds"},
      {R"("variants": [])", "/variants: expected at least one variant"},
      {R"("variants": [{"name": "a b"}])", "/variants/0/name: \"a b\" is not a variant name"},
      {R"("variants": [{"name": "a"}, {"name": "a"}])", "/variants/1/name: variant \"a\" is given twice"},
      {R"("variants": [{"name": "a", "sett": {}}])", "/variants/0: unknown key(s) \"sett\""},
      {R"("set": [1])", "/set: expected an object"},
      {R"("set": {".x": 1})", "/set/.x: \".x\" is not a scenario path"},
      {R"("axes": [{"path": "model.restitution", "values": [0.3]}], "diagram": {"x": "model.restitution", "y": "population.density_per_m2"})",
       "/diagram/y: \"population.density_per_m2\" is not an axis of this sweep; expected one of \"model.restitution\""},
      {R"("keep_runs": "yes")", "/keep_runs: expected true or false, found \"yes\""},
  };
  for (const auto& c : cases) {
    const std::string m = ErrorOf("{" + kHead + ", " + c.body + "}");
    EXPECT_NE(m.find(c.expected), std::string::npos) << c.body << "\n  gave: " << m;
  }
  const std::string scenario = R"("scenario": "../scenarios/sweep-tiny.json")";
  EXPECT_NE(ErrorOf(R"({"format": "crowdrecon-scenario", )" + scenario + "}")
                .find("test.json: /format: \"crowdrecon-scenario\" is not a sweep"),
            std::string::npos);
  EXPECT_NE(ErrorOf(R"({"version": 2, )" + scenario + "}")
                .find("test.json: /version: value 2 is out of range; expected an integer in [1, 1]"),
            std::string::npos);
  EXPECT_NE(ErrorOf(R"({"format": "crowdrecon-sweep", "scenario": "nope.json"})")
                .find("test.json: /scenario: cannot open the scenario file"),
            std::string::npos);
  EXPECT_NE(ErrorOf(R"({"format": "crowdrecon-sweep", )").find("test.json:1:"), std::string::npos);
  EXPECT_NE(ErrorOf(R"({"format": "crowdrecon-sweep"})").find("test.json: /: missing required key \"scenario\""),
            std::string::npos);
}

TEST(SweepFile, ExactNumbers) {
  EXPECT_EQ(ExactNumber(0.1), "0.1");
  EXPECT_EQ(ExactNumber(3.0), "3");
  EXPECT_EQ(ExactNumber(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(ExactNumber(std::numeric_limits<double>::quiet_NaN()), "");
  EXPECT_EQ(std::stod(ExactNumber(1.0 / 3.0)), 1.0 / 3.0);
}

// The profile a sweep's runs ran (issue 64; timeline --phase says when a
// run's path crosses another model's diagram): the sweep's set, else the
// scenario's key, else "paper"; variants' own named too; "" for old tables.
TEST(SweepResults, TheProfileOfASweepsRuns) {
  ResultsTable t;
  EXPECT_EQ(SweepProfile(t), "");
  t.sweep["scenario"] = R"({"format": "crowdrecon-scenario", "name": "s"})";
  t.sweep["sweep"] = R"({"set": {"run.duration_s": 60}})";
  EXPECT_EQ(SweepProfile(t), "paper");
  t.sweep["scenario"] = R"({"format": "crowdrecon-scenario", "profile": "validated"})";
  EXPECT_EQ(SweepProfile(t), "validated");
  t.sweep["sweep"] = R"({"set": {"profile": "paper"}, "variants": [{"name": "a", "set": {}},
                         {"name": "b", "set": {"profile": "validated"}}]})";
  EXPECT_EQ(SweepProfile(t), "paper, validated");
  // A profile file is named by its name, read beside the scenario.
  t.sweep["scenario_file"] = std::string(CROWDRECON_SOURCE_DIR) + "/studies/keeping-distance/x.json";
  t.sweep["sweep"] = R"({"set": {"profile": "radius/validated-radius2.5.profile.json"}})";
  EXPECT_EQ(SweepProfile(t), "validated-radius2.5");
  t.sweep["sweep"] = R"({"set": {"profile": "radius/gone.profile.json"}})";
  EXPECT_EQ(SweepProfile(t), "radius/gone.profile.json");
}

TEST(SweepResults, ColumnsAndRowRoundTrip) {
  const std::vector<std::string>& c = MetricColumns();
  EXPECT_EQ(c.front(), "duration_s");
  EXPECT_NE(std::find(c.begin(), c.end(), "mean_speed_g0_m_per_s"), c.end());
  EXPECT_NE(std::find(c.begin(), c.end(), "mean_speed_g1_m_per_s"), c.end());
  EXPECT_NE(std::find(c.begin(), c.end(), "regime_code"), c.end());
  // Per direction (classifier version 2), for both groups.
  EXPECT_NE(std::find(c.begin(), c.end(), "regime_code_g1"), c.end());
  EXPECT_NE(std::find(c.begin(), c.end(), "lapse_tail_exponent_g0"), c.end());
  // The analysis' columns, then the injury-risk columns (issue 21).
  EXPECT_NE(std::find(c.begin(), c.end(), "lapse_tail_exponent_error_g1"), c.end());
  EXPECT_EQ(std::vector<std::string>(c.end() - static_cast<std::ptrdiff_t>(RiskColumns().size()), c.end()), RiskColumns());
  EXPECT_EQ(c.back(), "longest_above_f0_s");

  ResultRow row;
  row.run_index = 42;
  row.status = "complete";
  row.regime = "avalanches";
  row.regime_reason = "3 avalanches, \"stop-and-go\"";
  row.metrics = {1.0 / 3.0, std::numeric_limits<double>::quiet_NaN(), -0.0, 1e300};
  row.wall_s = 12.5;
  const ResultRow back = DeserializeRow(SerializeRow(row));
  EXPECT_EQ(back.run_index, 42u);
  EXPECT_EQ(back.status, row.status);
  EXPECT_EQ(back.regime, row.regime);
  EXPECT_EQ(back.regime_reason, row.regime_reason);
  ASSERT_EQ(back.metrics.size(), 4u);
  EXPECT_EQ(back.metrics[0], 1.0 / 3.0);
  EXPECT_TRUE(std::isnan(back.metrics[1]));
  EXPECT_TRUE(std::signbit(back.metrics[2]));
  EXPECT_EQ(back.metrics[3], 1e300);
  EXPECT_EQ(back.wall_s, 12.5);
}

}  // namespace
}  // namespace crowdrecon::sweep
