// Calibration files and their statistics (issue 23): statistics of an
// observation made in memory (window means, their standard errors, event
// counts, a time offset, windows beyond the runs, avalanches of any
// direction); calibration files read with their defaults and refused with
// the JSON path, the value and what was expected; the footage design against
// the analytic information of a correlated series. (The fit itself:
// test_calibrate.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "crowdrecon/analysis/timeline_series.hpp"
#include "crowdrecon/calibrate/calibration_file.hpp"
#include "crowdrecon/calibrate/statistics.hpp"
#include "crowdrecon/common/error.hpp"
#include "fit.hpp"
#include "footage.hpp"
#include "scratch.hpp"

namespace crowdrecon::calibrate {
namespace {

using crowdrecon::testing::ScratchFile;

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// An observation of 10 s in 0.2-s bins: speed forward 1.0 for t < 5 s and
// 0.5 after (uncertainty 0.1 per bin), and three stops.
observe::Observation MadeObservation() {
  observe::Observation o;
  o.spec.regions.push_back({"hallway", {{0, 0}, {8, 0}, {8, 3}, {0, 3}}});
  o.method = "trajectories";
  o.source_format = "crowdrecon-run";
  o.source_file = "made";
  o.t0_s = 0.0;
  o.bin_s = 0.2;
  o.bins = 50;
  observe::Series s{"speed", "hallway", "forward", "m/s", {}};
  for (std::size_t k = 0; k < o.bins; ++k) s.points.push_back({k < 25 ? 1.0 : 0.5, 0.1, 10.0});
  o.series.push_back(s);
  for (double t : {1.0, 4.0, 8.0}) {
    observe::Event e;
    e.kind = "stop";
    e.where = "hallway";
    e.direction = "forward";
    e.time_s = t;
    e.end_s = t + 0.5;
    o.events.push_back(e);
  }
  return o;
}

const std::string kScenario = std::string(CROWDRECON_SOURCE_DIR) + "/tests/data/scenarios/sweep-tiny.json";

std::string Calibration(const std::string& observation_file, const std::string& parameters, const std::string& more = "") {
  return R"({"format": "crowdrecon-calibration", "version": 1, "scenario": ")" + kScenario + R"(",
    "parameters": )" + parameters + R"(,
    "observations": [{"file": ")" + observation_file + R"(",
      "series": [{"quantity": "speed", "where": "hallway", "direction": "forward", "from_s": 0, "to_s": 10, "window_s": 5}],
      "events": [{"kind": "stop", "where": "hallway", "direction": "forward", "from_s": 2, "to_s": 10}]}],
    "set": {"run.duration_s": 12},
    "seeds": {"first": 1, "count": 3})" + more + "}";
}

TEST(CalibrationStatistics, WindowMeansCountsAndAnOffset) {
  const auto file = ScratchFile("made.observation.json");
  observe::WriteObservation(MadeObservation(), file);
  const CalibrationSpec spec =
      ParseCalibration(Calibration(file.string(), R"([{"path": "model.back_force_gamma"}])"), "cal.json", "");
  const std::vector<Statistic> st = ObservedStatistics(spec);
  // Two windows of the series, then the counts after each stop from 2 s on (4 s, 8 s) and at the end.
  ASSERT_EQ(st.size(), 5u);
  EXPECT_DOUBLE_EQ(st[0].observed, 1.0);
  EXPECT_DOUBLE_EQ(st[1].observed, 0.5);
  EXPECT_NEAR(st[0].observed_sigma, 0.1 / std::sqrt(25.0), 1e-12);  // 25 bins of 0.1 each
  EXPECT_EQ(st[2].to_s, 4.0);
  EXPECT_EQ(st[2].observed, 1.0);
  EXPECT_EQ(st[3].observed, 2.0);
  EXPECT_EQ(st[4].to_s, 10.0);
  EXPECT_EQ(st[4].observed, 2.0);
  // A simulated observation equal to the observed one reads the same values ...
  std::vector<double> values;
  SimulatedStatistics(0, MadeObservation(), st, &values);
  for (std::size_t j = 0; j < st.size(); ++j) EXPECT_DOUBLE_EQ(values[j], st[j].observed) << st[j].name;
  // ... and one whose clock runs 1 s later, with the offset, too.
  observe::Observation later = MadeObservation();
  later.t0_s = 1.0;
  for (observe::Event& e : later.events) e.time_s += 1.0;
  CalibrationSpec shifted = spec;
  shifted.observations[0].time_offset_s = 1.0;
  SimulatedStatistics(0, later, ObservedStatistics(shifted), &values);
  for (std::size_t j = 0; j < st.size(); ++j) EXPECT_DOUBLE_EQ(values[j], st[j].observed) << st[j].name;
  // A simulated window of its own: the observed [5, 10) against the run's [0, 5).
  std::string text = Calibration(file.string(), R"([{"path": "model.back_force_gamma"}])");
  const std::string windows = "\"from_s\": 0, \"to_s\": 10, \"window_s\": 5";
  text.replace(text.find(windows), windows.size(),
               "\"from_s\": 5, \"to_s\": 10, \"simulated_from_s\": 0, \"simulated_to_s\": 5");
  const CalibrationSpec own = ParseCalibration(text, "cal.json", "");
  const std::vector<Statistic> ost = ObservedStatistics(own);
  EXPECT_DOUBLE_EQ(ost[0].observed, 0.5);
  SimulatedStatistics(0, MadeObservation(), ost, &values);
  EXPECT_DOUBLE_EQ(values[0], 1.0);
}

// Issue 40: an observation compared beyond the runs' end (an offset of 100 s
// with 12-s runs; before, the pooled seed covariance of no values crashed
// the calibration) is refused before anything runs, naming the statistic,
// the window and the runs' length; so is a window partly beyond them.
TEST(CalibrationStatistics, WindowsBeyondTheRunsAreRefusedUpFront) {
  const auto file = ScratchFile("made.observation.json");
  observe::WriteObservation(MadeObservation(), file);
  CalibrationSpec spec = ParseCalibration(Calibration(file.string(), R"([{"path": "model.back_force_gamma"}])"), "cal.json", "");
  ASSERT_EQ(spec.run_duration_s, 12.0);
  EXPECT_NO_THROW(ObservedStatistics(spec));
  spec.observations[0].time_offset_s = 100.0;
  std::string e = ErrorOf([&] { ObservedStatistics(spec); });
  EXPECT_NE(e.find("cal.json: " + file.string() + ": obs0 speed hallway forward [0, 5) s is compared with the runs over [100, 105) s "
                   "(the observation's window plus its time_offset_s of 100 s), beyond the runs, which last 12 s"),
            std::string::npos) << e;
  spec.observations[0].time_offset_s = 3.0;  // the second window, [5, 10) s, runs to 13 s
  e = ErrorOf([&] { ObservedStatistics(spec); });
  EXPECT_NE(e.find("is compared with the runs over [8, 13) s"), std::string::npos) << e;
  spec.observations[0].time_offset_s = -1.0;  // before the runs begin
  e = ErrorOf([&] { ObservedStatistics(spec); });
  EXPECT_NE(e.find("is compared with the runs over [-1, 4) s"), std::string::npos) << e;
}

// The run's avalanches in "any" direction: one surge seen by two detectors
// within 2 s counts once.
TEST(CalibrationStatistics, AvalanchesOfAnyDirectionCountOnce) {
  observe::Observation run;
  for (const auto& [t, who] : std::vector<std::pair<double, std::string>>{{10.0, "counter"}, {11.5, "crowd"}, {30.0, "leaving"}}) {
    observe::Event e;
    e.kind = "avalanche";
    e.where = "run";
    e.direction = who;
    e.time_s = t;
    run.events.push_back(e);
  }
  Statistic st;
  st.is_count = true;
  st.quantity = "avalanche";
  st.where = "run";
  st.direction = "any";
  st.sim_from_s = 0.0;
  st.sim_to_s = 100.0;
  std::vector<double> values;
  SimulatedStatistics(0, run, {st}, &values);
  EXPECT_EQ(values[0], 2.0);
  st.direction = "crowd";
  SimulatedStatistics(0, run, {st}, &values);
  EXPECT_EQ(values[0], 1.0);
}

// "reduce": "max": the window's largest bin and that bin's uncertainty.
TEST(CalibrationStatistics, AWindowsLargestBinWithItsUncertainty) {
  const auto file = ScratchFile("made.observation.json");
  observe::Observation made = MadeObservation();
  made.series[0].points[30] = {1.7, 0.25, 10.0};
  observe::WriteObservation(made, file);
  std::string text = Calibration(file.string(), R"([{"path": "model.back_force_gamma"}])");
  const std::string window = "\"window_s\": 5";
  text.replace(text.find(window), window.size(), window + ", \"reduce\": \"max\"");
  const std::vector<Statistic> st = ObservedStatistics(ParseCalibration(text, "cal.json", ""));
  ASSERT_EQ(st.size(), 5u);
  EXPECT_TRUE(st[0].is_max);
  EXPECT_DOUBLE_EQ(st[0].observed, 1.0);  // [0, 5): every bin 1.0
  EXPECT_DOUBLE_EQ(st[0].observed_sigma, 0.1);
  EXPECT_DOUBLE_EQ(st[1].observed, 1.7);  // [5, 10): bin 30 (6.1 s)
  EXPECT_DOUBLE_EQ(st[1].observed_sigma, 0.25);
  EXPECT_NE(st[1].name.find("speed hallway forward max [5, 10) s"), std::string::npos) << st[1].name;
  std::vector<double> values;
  SimulatedStatistics(0, made, st, &values);
  EXPECT_DOUBLE_EQ(values[1], 1.7);
  EXPECT_DOUBLE_EQ(values[0], 1.0);
  EXPECT_NE(ErrorOf([&] {
              std::string bad = text;
              bad.replace(bad.find("\"max\""), 5, "\"median\"");
              ParseCalibration(bad, "cal.json", "");
            }).find("/observations/0/series/0/reduce"),
            std::string::npos);
}

// A speed read from the footage at a recorded mark (the Madrid night's
// "up to 3 m/s" at the fifth avalanche), against the run's fastest person at
// the exit end between the marks before and after it; refused with the path
// where it cannot be matched.
TEST(CalibrationFile, ASpeedRecordedOfTheIncident) {
  const std::string src = CROWDRECON_SOURCE_DIR;
  const auto calibration = [&](const std::string& scenario, const std::string& set, const std::string& recorded) {
    return R"({"format": "crowdrecon-calibration", "version": 1, "scenario": ")" + src + scenario + R"(",
      "set": )" + set + R"(, "parameters": [{"path": "model.back_force_gamma"}],
      "observations": [{"recorded": {"kind": "max_speed", "spec": ")" + src +
           R"(/venues/madrid-arena/observations/hallway-night.json", )" + recorded + R"(}}],
      "seeds": {"first": 1, "count": 2}})";
  };
  const std::string night = "/venues/madrid-arena/scenarios/madrid-night-demo.json";
  const std::string fast = R"({"run.output_fps": 10})";
  const CalibrationSpec spec = ParseCalibration(calibration(night, fast, R"("where": "exit end")"), "cal.json", "");
  const std::vector<Statistic> st = ObservedStatistics(spec);
  ASSERT_EQ(st.size(), 1u);
  EXPECT_TRUE(st[0].is_max);
  EXPECT_EQ(st[0].quantity, "max_speed");
  EXPECT_EQ(st[0].where, "exit end");
  EXPECT_DOUBLE_EQ(st[0].observed, 3.0);
  EXPECT_DOUBLE_EQ(st[0].observed_sigma, 0.5);
  EXPECT_DOUBLE_EQ(st[0].sim_from_s, 177.0);  // the demo's marks (/20): 02:59 ...
  EXPECT_DOUBLE_EQ(st[0].sim_to_s, 279.0);    // ... and the fatal clog, around 03:29 (267 s)
  // The run's observation: the fastest bin inside the window counts, not one outside.
  observe::Observation run;
  run.bin_s = 0.2;
  run.bins = 1500;
  observe::Series m{"max_speed", "exit end", "all", "m/s", {}};
  for (std::size_t k = 0; k < run.bins; ++k) m.points.push_back({k == 1000 ? 2.6 : (k == 1400 ? 4.0 : 1.0), 0.1, 5.0});
  run.series.push_back(m);
  std::vector<double> values;
  SimulatedStatistics(0, run, st, &values);
  EXPECT_DOUBLE_EQ(values[0], 2.6);  // bin 1000 (200.1 s); bin 1400 (280.1 s) lies after the window
  // A window of one's own.
  const std::vector<Statistic> own =
      ObservedStatistics(ParseCalibration(calibration(night, fast, R"("where": "exit end", "from_s": 260, "to_s": 285)"), "cal.json", ""));
  SimulatedStatistics(0, run, own, &values);
  EXPECT_DOUBLE_EQ(values[0], 4.0);
  // One reaching past the runs' 285 s is refused (issue 40).
  const std::string beyond = ErrorOf([&] {
    ObservedStatistics(ParseCalibration(calibration(night, fast, R"("where": "exit end", "from_s": 260, "to_s": 300)"), "cal.json", ""));
  });
  EXPECT_NE(beyond.find("is compared with the runs over [260, 300) s (the observation's window), beyond the runs, which last 285 s"),
            std::string::npos) << beyond;
  const auto expect = [&](const std::string& text, const std::string& part) {
    const std::string e = ErrorOf([&] { ParseCalibration(text, "cal.json", ""); });
    EXPECT_NE(e.find(part), std::string::npos) << "error: " << e << "\nexpected: " << part;
  };
  expect(calibration(night, "{}", R"("where": "exit end")"),
         "/observations/0/recorded: the runs write 5 frames/s, so their velocities would span 0.4 s against the "
         "observation's 0.2 s; expected run.output_fps of at least 10");
  expect(calibration(night, fast, R"("where": "exit")"),
         "/observations/0/recorded/where: the spec has no region \"exit\"; expected one of \"hallway\", \"exit end\"");
  expect(calibration(night, fast, R"("where": "exit end", "from_s": 0, "to_s": 100)"), "leaves out the mark");
  expect(calibration("/tests/data/scenarios/sweep-tiny.json", fast, R"("where": "exit end")"),
         "the scenario records no speed in timeline.recorded");
}

// The recorded fatal clog (the Madrid night's 03:33) as a time: observed the
// mark's time with the stated uncertainty, simulated the first "clog" event
// (the time from which the run is clogged for good) in the window, or the
// window's end where the run never clogs for good; refused with the path
// where the scenario records none or the window leaves it out.
TEST(CalibrationFile, TheRecordedFatalClogAsATime) {
  const std::string src = CROWDRECON_SOURCE_DIR;
  const auto calibration = [&](const std::string& scenario, const std::string& recorded) {
    return R"({"format": "crowdrecon-calibration", "version": 1, "scenario": ")" + src + scenario + R"(",
      "parameters": [{"path": "model.back_force_gamma"}],
      "observations": [{"recorded": {"kind": "fatal")" + recorded + R"(}}],
      "seeds": {"first": 1, "count": 2}})";
  };
  const std::string night = "/venues/madrid-arena/scenarios/madrid-night-demo.json";
  const std::vector<Statistic> st = ObservedStatistics(ParseCalibration(calibration(night, ""), "cal.json", ""));
  ASSERT_EQ(st.size(), 1u);
  EXPECT_TRUE(st[0].is_time);
  EXPECT_FALSE(st[0].is_count);
  EXPECT_EQ(st[0].quantity, "clog");
  EXPECT_EQ(st[0].simulated_from, "run clog");
  EXPECT_DOUBLE_EQ(st[0].observed, 279.0);  // the demo's 03:33 (5,580 s / 20)
  EXPECT_DOUBLE_EQ(st[0].observed_sigma, 60.0);
  EXPECT_DOUBLE_EQ(st[0].sim_from_s, 0.0);
  EXPECT_DOUBLE_EQ(st[0].sim_to_s, 285.0);  // the runs' end
  EXPECT_DOUBLE_EQ(ObservedStatistics(ParseCalibration(calibration(night, R"(, "uncertainty_s": 5)"), "cal.json", ""))[0].observed_sigma, 5.0);

  observe::Observation run;
  std::vector<double> values;
  SimulatedStatistics(0, run, st, &values);
  EXPECT_DOUBLE_EQ(values[0], 285.0);  // never clogged for good: censored at the window's end
  observe::Event clog;
  clog.kind = "clog";
  clog.where = "run";
  clog.direction = "crowd";
  clog.time_s = 212.5;
  run.events.push_back(clog);
  SimulatedStatistics(0, run, st, &values);
  EXPECT_DOUBLE_EQ(values[0], 212.5);

  const auto expect = [&](const std::string& text, const std::string& part) {
    const std::string e = ErrorOf([&] { ParseCalibration(text, "cal.json", ""); });
    EXPECT_NE(e.find(part), std::string::npos) << "error: " << e << "\nexpected: " << part;
  };
  expect(calibration("/tests/data/scenarios/sweep-tiny.json", ""), "/observations/0/recorded: the scenario records no \"fatal\" mark");
  expect(calibration(night, R"(, "from_s": 0, "to_s": 200)"), "leaves out the fatal clog at 279 s");
  expect(calibration(night, R"(, "uncertainty_s": 0)"), "/observations/0/recorded/uncertainty_s");
}

// The time from which a run is clogged for good (the function the ensemble's
// score and the recorded fatal clog share), on made directions' speeds: the
// start of the last stretch in which every direction present is still.
TEST(CalibrationFile, AClogForGoodIsTheStartOfTheLastStillStretch) {
  analysis::TimelineSeries s;
  for (int k = 0; k <= 100; ++k) s.time_s.push_back(k);
  s.group_speed_m_per_s = {std::vector<double>(101, 1.0), std::vector<double>(101, std::numeric_limits<double>::quiet_NaN())};
  for (int k = 60; k <= 100; ++k) s.group_speed_m_per_s[0][k] = 0.0;
  EXPECT_DOUBLE_EQ(analysis::ClogForGood(s, 0.0), 60.0);
  EXPECT_TRUE(std::isnan(analysis::ClogForGood(s, 0.0, 0.1, 50.0)));  // 40 s still: shorter than 50
  s.group_speed_m_per_s[1].assign(101, 0.5);                           // the other direction still walks
  EXPECT_TRUE(std::isnan(analysis::ClogForGood(s, 0.0)));
  s.group_speed_m_per_s[1].assign(101, 0.0);
  s.group_speed_m_per_s[1][80] = 0.3;                                   // ... until 80 s
  EXPECT_DOUBLE_EQ(analysis::ClogForGood(s, 0.0), 81.0);
}

// Every calibration the repository ships is read and its observed statistics
// computed (a change to the format or the checks that refused one would
// show here first, not in a documented command an hour in).
TEST(CalibrationFile, EveryShippedCalibrationIsValid) {
  int files = 0;
  for (const auto& venue : std::filesystem::directory_iterator(std::string(CROWDRECON_SOURCE_DIR) + "/venues")) {
    const std::filesystem::path dir = venue.path() / "calibrations";
    if (!std::filesystem::is_directory(dir)) continue;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
      if (entry.path().extension() != ".json") continue;
      std::ifstream in(entry.path());
      const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (text.find("\"crowdrecon-calibration\"") == std::string::npos) continue;  // a sweep of recordings
      SCOPED_TRACE(entry.path().string());
      EXPECT_EQ(ErrorOf([&] { EXPECT_FALSE(ObservedStatistics(LoadCalibration(entry.path())).empty()); }), "");
      ++files;
    }
  }
  EXPECT_GE(files, 5);  // the Madrid Arena's three, the Jülich corridors' two
}

TEST(CalibrationFile, DefaultsFromTheParameterTableAndTheScenario) {
  const auto file = ScratchFile("made.observation.json");
  observe::WriteObservation(MadeObservation(), file);
  const CalibrationSpec spec = ParseCalibration(
      Calibration(file.string(),
                  R"([{"path": "model.back_force_gamma"}, {"path": "model.restitution", "min": 0.1, "max": 0.8, "start": 0.3},
                      {"path": "population.desired_speed_m_per_s", "min": 0.6, "max": 1.8, "width": 0.4, "start": 1.0}])",
                  R"(, "starts": [{"model.restitution": 0.7}])"),
      "cal.json", "");
  ASSERT_EQ(spec.parameters.size(), 3u);
  EXPECT_EQ(spec.parameters[0].min, 0.0);    // the table's range
  EXPECT_EQ(spec.parameters[0].max, 100.0);
  EXPECT_EQ(spec.parameters[0].start, 1.2);  // the table's default (the scenario has no model block)
  EXPECT_EQ(spec.parameters[1].start, 0.3);
  // A range: its centre is the parameter, its width kept.
  EXPECT_TRUE(spec.parameters[2].is_range);
  EXPECT_DOUBLE_EQ(spec.parameters[2].start, 1.0);
  EXPECT_DOUBLE_EQ(spec.parameters[2].width, 0.4);
  EXPECT_EQ(spec.parameters[2].JsonOf(1.5), "[1.3,1.7]");
  ASSERT_EQ(spec.starts.size(), 2u);
  EXPECT_EQ(spec.starts[1][1], 0.7);
  EXPECT_EQ(spec.starts[1][0], 1.2);
  EXPECT_EQ(spec.base.seeds.size(), 3u);
}

TEST(CalibrationFile, BadFilesAreRefusedWithThePathAndTheValue) {
  const auto file = ScratchFile("made.observation.json");
  observe::WriteObservation(MadeObservation(), file);
  const std::string obs = file.string();
  const auto error = [&](const std::string& text) { return ErrorOf([&] { ParseCalibration(text, "cal.json", ""); }); };
  const auto expect = [&](const std::string& text, const std::string& part) {
    const std::string e = error(text);
    EXPECT_NE(e.find(part), std::string::npos) << "error: " << e << "\nexpected: " << part;
  };
  expect(Calibration(obs, R"([{"path": "model.back_force_gama"}])"),
         "cal.json: /parameters/0/path: \"model.back_force_gama\" is not a model parameter");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma", "max": 200}])"), "/parameters/0/max");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma", "min": 2, "max": 1}])"), "are empty; expected min < max");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma", "min": 2, "max": 3}])"),
         "the start 1.2 (from the scenario) lies outside the bounds [2, 3]");
  expect(Calibration(obs, R"([{"path": "population.density_per_m2"}])"),
         "\"min\" is required for \"population.density_per_m2\"");
  expect(Calibration(obs, R"([{"path": "model.integrator"}])"), "is not a number");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}, {"path": "model.back_force_gamma"}])"), "given twice");
  expect(Calibration(obs, R"([{"path": "population.seed", "min": 1, "max": 9}])"), "the seed is not a parameter");
  expect(Calibration(obs, R"([])"), "/parameters: expected at least one parameter");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}])", R"(, "approach": "newton")"),
         "/approach");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}])", R"(, "starts": [{"model.restitution": 0.3}])"),
         "/starts/0/model.restitution: \"model.restitution\" is not one of the parameters to fit");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}])", R"(, "options": {"profile_points": 1})"),
         "/options/profile_points");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}])", R"(, "options": {"posterior_steps": 500})"),
         "/options/posterior_steps: expected 0 (no posterior) or at least 1000 steps per chain");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}])", R"(, "options": {"posterior_steps": -1})"),
         "/options/posterior_steps");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}])", R"(, "extra": 1)"), "unknown key");
  // Issue 65: one seed has no spread to weigh the statistics by (it crashed the calibration).
  {
    std::string one = Calibration(obs, R"([{"path": "model.back_force_gamma"}])");
    one.replace(one.find("\"count\": 3"), 10, "\"count\": 1");
    expect(one, "cal.json: /seeds: 1 seed; expected at least 2");
  }
  expect(Calibration("/nonexistent/obs.json", R"([{"path": "model.back_force_gamma"}])"),
         "/observations/0/file: cannot use the observation");
  // A series the observation does not have: the ones it has are listed.
  std::string text = Calibration(obs, R"([{"path": "model.back_force_gamma"}])");
  text.replace(text.find("\"direction\": \"forward\", \"from_s\": 0"), 22, "\"direction\": \"backward\"");
  expect(text, "the observation has no series speed hallway backward; expected one of: speed hallway forward");
  // An override that makes the scenario invalid at a bound: refused before any run.
  expect(Calibration(obs, R"([{"path": "population.density_per_m2", "min": 0.5, "max": 400, "start": 1}])"),
         "(variant max-density_per_m2, seed 1): the scenario with this run's overrides is not valid");
  // "width" for a value that is not a range.
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma", "width": 0.2}])"), "\"width\" is for ranges");
}

// A recording's statistics for the footage design: `windows` windows of
// `window_s` of one series (speed) whose seeds' values correlate as AR(1)
// from window to window (variance s2, correlation rho^lag) and move with the
// parameters by `slope` (one row per parameter), plus, optionally, a count.
Objective FootageObjective(std::size_t windows, double window_s, double s2, double rho, std::vector<double> slope,
                           std::vector<double>* jacobian, bool with_count = false, double count_var = 4.0,
                           std::vector<double> count_slope = {}) {
  Objective o;
  const std::size_t p = slope.size();
  for (std::size_t w = 0; w < windows; ++w) {
    Statistic st;
    st.name = "speed " + std::to_string(w);
    st.quantity = "speed";
    st.where = "hallway";
    st.direction = "forward";
    st.sim_from_s = static_cast<double>(w) * window_s;
    st.sim_to_s = st.sim_from_s + window_s;
    o.statistics.push_back(st);
    jacobian->insert(jacobian->end(), slope.begin(), slope.end());
  }
  if (with_count) {
    Statistic st;
    st.name = "stops";
    st.quantity = "stop";
    st.where = "hallway";
    st.direction = "forward";
    st.is_count = true;
    st.sim_to_s = static_cast<double>(windows) * window_s;
    o.statistics.push_back(st);
    jacobian->insert(jacobian->end(), count_slope.begin(), count_slope.end());
  }
  const std::size_t n = o.statistics.size();
  o.seed_covariance.assign(n * n, 0.0);
  for (std::size_t a = 0; a < windows; ++a)
    for (std::size_t b = 0; b < windows; ++b)
      o.seed_covariance[a * n + b] = s2 * std::pow(rho, std::abs(static_cast<double>(a) - static_cast<double>(b)));
  if (with_count) o.seed_covariance[n * n - 1] = count_var;
  (void)p;
  return o;
}

// The design against the analytic information of an AR(1) series: m
// windows of unit-variance correlation rho^|a-b| carry 1ᵀR⁻¹1 =
// (m(1 - rho) + 2 rho) / (1 + rho) windows' worth; beyond the recording each
// window adds (1 - rho) / (1 + rho) (the long-run variance, up to the
// Bartlett weights' bias); N recordings divide the variance by N, K seeds
// add 1/K; a count's information grows with the length; a statistic that
// moves with one parameter only informs that one.
TEST(FootageDesign, MatchesTheInformationOfACorrelatedSeries) {
  const double rho = 0.5, s2 = 0.04, g = 0.8;
  std::vector<double> jac;
  const Objective o = FootageObjective(40, 5.0, s2, rho, {g}, &jac);
  const auto var = [&](int n, double m, double k) { return FootageCovariance(o, jac, 1, n, m, k)[0]; };
  const auto analytic = [&](double m) { return s2 / (g * g) * (1.0 + rho) / (m * (1.0 - rho) + 2.0 * rho); };
  for (double m : {1.0, 2.0, 10.0, 40.0}) EXPECT_NEAR(var(1, m, 0.0), analytic(m), 1e-9 * analytic(m)) << m;
  for (double m : {80.0, 160.0, 1000.0}) EXPECT_NEAR(var(1, m, 0.0), analytic(m), 0.05 * analytic(m)) << m;
  EXPECT_NEAR(var(4, 10.0, 0.0), analytic(10.0) / 4.0, 1e-9);
  EXPECT_NEAR(var(4, 10.0, 8.0), analytic(10.0) * (1.0 / 4.0 + 1.0 / 8.0), 1e-9);

  // The design's table and the footage it asks for.
  FootageOptions options;
  options.recordings = {1, 4};
  options.targets = {0.2};
  const FootageDesign d = DesignFootage(o, jac, {1.0}, options);
  ASSERT_TRUE(d.note.empty()) << d.note;
  EXPECT_EQ(d.windows, 40u);
  EXPECT_DOUBLE_EQ(d.recording_s, 200.0);
  ASSERT_EQ(d.rows.size(), 2u * 7u);
  EXPECT_NEAR(d.rows[1].sd[0], std::sqrt(analytic(40.0)), 1e-9);  // one recording, its own length
  EXPECT_NEAR(d.rows[7 + 1].sd[0], std::sqrt(analytic(40.0) / 4.0), 1e-9);
  // 95 % half-width 0.2: sd 0.2 / 1.96; analytic windows m, in seconds, within a window.
  const double want = 0.2 / 1.96;
  const double m = ((1.0 + rho) * s2 / (g * g) / (want * want) - 2.0 * rho) / (1.0 - rho);
  EXPECT_NEAR(d.one_recording_s[0][0], m * 5.0, 0.05 * m * 5.0 + 5.0);
  EXPECT_DOUBLE_EQ(d.recordings_needed[0][0], std::ceil(analytic(40.0) / (want * want)));
  ASSERT_EQ(d.share_lost.size(), 1u);
  EXPECT_DOUBLE_EQ(d.share_lost[0][0], 1.0);  // without its only statistic, undetermined

  // A count informs the second parameter alone, the series the first: each
  // kind carries all of its parameter's information.
  std::vector<double> jac2;
  const Objective two = FootageObjective(10, 5.0, s2, rho, {g, 0.0}, &jac2, true, 4.0, {0.0, 3.0});
  const FootageDesign d2 = DesignFootage(two, jac2, {1.0, 2.0}, options);
  ASSERT_EQ(d2.kinds.size(), 2u);
  EXPECT_EQ(d2.kinds[1], "stop hallway forward (count)");
  EXPECT_NEAR(d2.share_lost[0][0], 1.0, 1e-12);
  EXPECT_NEAR(d2.share_lost[0][1], 0.0, 1e-12);
  EXPECT_NEAR(d2.share_lost[1][1], 1.0, 1e-12);
  EXPECT_NEAR(d2.information_share[1][1], 1.0, 1e-12);
  // The count over f times the recording: mean slope f * 3, variance f * 4
  // (and the observed count's own 0.25, not grown).
  const auto count_var = [&](double f) { return (4.0 * f) / (9.0 * f * f); };
  for (double f : {0.5, 1.0, 3.0}) {
    const std::vector<double> c = FootageCovariance(two, jac2, 2, 1, 10.0 * f, 0.0);
    EXPECT_NEAR(c[3], count_var(f), 1e-9 * count_var(f)) << f;
  }
}

}  // namespace
}  // namespace crowdrecon::calibrate
