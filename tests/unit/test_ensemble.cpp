// Ensembles of an incident (issue 39, point 5; reports/ensemble.hpp): the
// score of runs against the recorded marks -- per recorded avalanche, the
// runs with an avalanche within the tolerance (each recorded mark on its
// own, so one avalanche may match two close marks); per run, its
// avalanches that match none, its clog for good against the fatal mark,
// its falls before it; medians and ranges; runs of another incident
// refused; the score files recognised as previous outputs.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/reports/ensemble.hpp"
#include "crowdrecon/reports/report.hpp"
#include "scratch.hpp"

namespace crowdrecon::reports {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<analysis::TimelineMark> Recorded() {
  return {{100.0, "avalanche A", "avalanche"}, {160.0, "avalanche B", "avalanche"}, {600.0, "avalanche C", "avalanche"},
          {900.0, "fatal clog", "fatal"}};
}

EnsembleRun MakeRun(std::string label, std::vector<double> avalanches, std::vector<double> falls, double clog,
                std::size_t danger, double density) {
  EnsembleRun r;
  r.run_file = label + ".sqlite";
  r.label = label;
  r.end_s = 1000.0;
  r.avalanche_s = std::move(avalanches);
  r.fall_s = std::move(falls);
  r.clog_for_good_s = clog;
  r.danger_peak = danger;
  r.loads_available = true;
  r.peak_density_per_m2 = density;
  r.peak_equivalent_density_per_m2 = density * 0.6;
  r.recorded = Recorded();
  for (std::size_t k = 0; k < r.avalanche_s.size(); ++k) r.rise_time_s.push_back(0.1 * static_cast<double>(k + 1));
  return r;
}

TEST(Ensemble, EachRecordedAvalancheCountsTheRunsWithOneWithinTheTolerance) {
  EnsembleOptions o;
  o.tolerance_s = 60.0;
  const EnsembleScore s = ScoreEnsemble(
      {MakeRun("seed 1", {130.0, 400.0}, {850.0, 950.0}, 880.0, 3, 12.0),  // 130 matches A and B; 400 matches none
       MakeRun("seed 2", {659.0}, {}, kNaN, 0, 8.0),                       // matches C (within 60 s)
       MakeRun("seed 3", {39.0, 661.0}, {}, 700.0, 7, 10.0)},              // 39 and 661: just outside A and C
      o);
  ASSERT_EQ(s.avalanches.size(), 3u);
  EXPECT_EQ(s.avalanches[0].runs_matching, 1u);
  EXPECT_EQ(s.avalanches[1].runs_matching, 1u);
  EXPECT_EQ(s.avalanches[2].runs_matching, 1u);
  EXPECT_EQ(s.avalanches[2].matched, (std::vector<bool>{false, true, false}));
  EXPECT_EQ(s.unmatched, (std::vector<std::size_t>{1, 0, 2}));
  ASSERT_EQ(s.fatal.size(), 1u);
  // Falls before the clog for good: 850 of seed 1 (950 came after it).
  EXPECT_EQ(s.falls_before_clog, (std::vector<std::size_t>{1, 0, 0}));
  EXPECT_EQ(s.runs_clogging_for_good, 2u);
  // Medians and ranges over the runs that have the figure.
  EXPECT_DOUBLE_EQ(s.clog_spread.median, 790.0);
  EXPECT_DOUBLE_EQ(s.clog_spread.low, 700.0);
  EXPECT_DOUBLE_EQ(s.clog_spread.high, 880.0);
  EXPECT_EQ(s.clog_spread.runs, 2u);
  EXPECT_DOUBLE_EQ(s.clog_minus_fatal_spread.median, -110.0);
  EXPECT_DOUBLE_EQ(s.danger_spread.median, 3.0);
  EXPECT_DOUBLE_EQ(s.density_spread.high, 12.0);
  EXPECT_DOUBLE_EQ(s.avalanche_count_spread.median, 2.0);
  // Rise times over every avalanche: 0.1, 0.2 (seed 1), 0.1 (seed 2), 0.1, 0.2 (seed 3).
  EXPECT_EQ(s.rise_time_spread.runs, 5u);
  EXPECT_DOUBLE_EQ(s.rise_time_spread.median, 0.1);
  EXPECT_DOUBLE_EQ(s.rise_time_spread.high, 0.2);
  // The table says it in words.
  const std::string md = s.Markdown();
  EXPECT_NE(md.find("| avalanche A | 100.0 s | 1 of 3 (33 %) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| runs whose venue clogs for good | 2 of 3 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| seed 2 | 1 (0) | 0 | never | 0 | 8.0 (4.8) |"), std::string::npos) << md;
  const std::string csv = s.Csv();
  EXPECT_NE(csv.find("seed 1.sqlite,seed 1,2,1,1,1,0,2,1,880.00,3,"), std::string::npos) << csv;
}

TEST(Ensemble, RunsOfAnotherIncidentAndBadOptionsAreRefused) {
  EnsembleRun other = MakeRun("seed 2", {}, {}, kNaN, 0, 8.0);
  other.recorded.pop_back();
  try {
    ScoreEnsemble({MakeRun("seed 1", {}, {}, kNaN, 0, 8.0), other}, EnsembleOptions{});
    ADD_FAILURE() << "runs with different recorded marks were scored together";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("seed 2.sqlite: its recorded marks or clock differ"), std::string::npos) << e.what();
  }
  EnsembleOptions bad;
  bad.tolerance_s = std::nan("");
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("tolerance_s"), std::string::npos);
  EXPECT_THROW(ScoreEnsemble({MakeRun("seed 1", {}, {}, kNaN, 0, 8.0)}, bad), InputError);
  EXPECT_THROW(ScoreEnsemble({}, EnsembleOptions{}), InputError);
}

// A sweep's variants share seeds: their rows are told apart by the files'
// names; distinct seeds keep their "seed N".
TEST(Ensemble, RunsOfOneSeedAreLabelledByTheirFiles) {
  EnsembleRun a = MakeRun("seed 1", {}, {}, kNaN, 0, 8.0), b = MakeRun("seed 1", {}, {}, kNaN, 0, 8.0);
  a.run_file = "runs/0000-foot-count=4-seed1.sqlite";
  b.run_file = "runs/0002-foot-count=8-seed1.sqlite";
  const EnsembleScore s = ScoreEnsemble({a, b, MakeRun("seed 2", {}, {}, kNaN, 0, 8.0)}, EnsembleOptions{});
  EXPECT_EQ(s.runs[0].label, "0000-foot-count=4-seed1");
  EXPECT_EQ(s.runs[1].label, "0002-foot-count=8-seed1");
  EXPECT_EQ(s.runs[2].label, "seed 2");
  const EnsembleScore distinct =
      ScoreEnsemble({MakeRun("seed 1", {}, {}, kNaN, 0, 8.0), MakeRun("seed 2", {}, {}, kNaN, 0, 8.0)}, EnsembleOptions{});
  EXPECT_EQ(distinct.runs[0].label, "seed 1");
}

// Two ensembles of one incident side by side (timeline --compare): a column
// each in the score table, each one's runs under its name, an `ensemble`
// column in the CSV; the score files known as previous outputs; ensembles
// of other incidents or with another tolerance refused. One ensemble: the
// table of before.
TEST(Ensemble, TwoEnsemblesAreScoredSideBySide) {
  EnsembleOptions o;
  o.tolerance_s = 60.0;
  const EnsembleScore a = ScoreEnsemble({MakeRun("seed 1", {130.0}, {}, 880.0, 3, 12.0),
                                         MakeRun("seed 2", {659.0}, {}, kNaN, 0, 8.0)}, o);
  const EnsembleScore b = ScoreEnsemble({MakeRun("seed 1", {}, {}, kNaN, 1, 4.0), MakeRun("seed 2", {}, {}, kNaN, 0, 3.0),
                                         MakeRun("seed 3", {605.0}, {}, kNaN, 0, 5.0)}, o);
  const std::vector<LabelledEnsemble> both{{"paper", &a}, {"validated", &b}};
  const std::string md = EnsemblesMarkdown(both);
  EXPECT_EQ(md.rfind("| recorded | at | runs with an avalanche within ±60 s: paper | validated |\n| --- | --- | --- | --- |\n", 0), 0u) << md;
  EXPECT_NE(md.find("| avalanche A | 100.0 s | 1 of 2 (50 %) | 0 of 3 (0 %) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| avalanche C | 600.0 s | 1 of 2 (50 %) | 1 of 3 (33 %) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| over the runs | paper (2 runs): median (range) | validated (3 runs): median (range) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| runs whose venue clogs for good | 1 of 2 | 0 of 3 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| clog for good minus the recorded fatal clog | -20 s | never |"), std::string::npos) << md;
  EXPECT_NE(md.find("**validated** (3 runs)\n\n| run |"), std::string::npos) << md;
  EXPECT_NE(md.find("| seed 3 | 1 (0) | 0 | never | 0 | 5.0 (3.0) |"), std::string::npos) << md;
  const std::string csv = EnsemblesCsv(both);
  EXPECT_NE(csv.find(",end_s,ensemble\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("seed 3.sqlite,seed 3,1,0,0,0,1,"), std::string::npos) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 6);
  const std::filesystem::path figure = crowdrecon::testing::ScratchFile("two-ensembles.png");
  DrawEnsemblesFigure(both, "Two ensembles", figure);
  EXPECT_GT(std::filesystem::file_size(figure), 1000u);
  const OutputKind kind = EnsembleScoresOutput();
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"both.md", md}, {"both.csv", csv}}) {
    const std::filesystem::path f = crowdrecon::testing::ScratchFile(name);
    std::ofstream(f) << text;
    EXPECT_TRUE(kind.is_previous(f)) << name;
  }
  EXPECT_EQ(EnsemblesMarkdown({{"", &a}}), a.Markdown());
  // Another incident's runs, or another tolerance, are not compared.
  EnsembleRun other = MakeRun("seed 9", {}, {}, kNaN, 0, 8.0);
  other.recorded.pop_back();
  const EnsembleScore c = ScoreEnsemble({other}, o);
  try {
    CheckComparable({{"paper", &a}, {"elsewhere", &c}});
    ADD_FAILURE() << "ensembles of two incidents were compared";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("seed 9.sqlite (elsewhere): its recorded marks, clock or tolerance differ from those of seed 1.sqlite (paper)"),
              std::string::npos) << e.what();
  }
  EnsembleOptions wider = o;
  wider.tolerance_s = 120.0;
  const EnsembleScore d = ScoreEnsemble({MakeRun("seed 1", {}, {}, kNaN, 0, 8.0)}, wider);
  EXPECT_THROW(EnsemblesMarkdown({{"paper", &a}, {"wider", &d}}), InputError);
}

// A run's summary (timeline --summaries) read back: the fuzz seed is a
// real night's summary cut short; each inconsistency is refused naming the
// JSON path; a summary made with other options is not mixed in.
TEST(Ensemble, ARunsSummaryIsReadBackOrRefusedNamingThePlace) {
  const std::filesystem::path seed =
      std::filesystem::path(CROWDRECON_SOURCE_DIR) / "fuzz/corpus/fuzz_ensemble_summary/night-seed1-short.json";
  std::ifstream in(seed);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const EnsembleRunSummary s = ParseEnsembleSummary(text, "s.json");
  EXPECT_EQ(s.run.label, "seed 1");
  EXPECT_EQ(s.seed, 1u);
  EXPECT_EQ(s.profile, "validated");
  EXPECT_EQ(s.run.avalanche_s, (std::vector<double>{1100.5, 2000.0}));
  ASSERT_EQ(s.run.rise_time_s.size(), 2u);
  EXPECT_TRUE(std::isnan(s.run.rise_time_s[1]));
  EXPECT_EQ(s.run.clog_for_good_s, 4000.0);
  EXPECT_EQ(s.run.time_s.size(), 5u);
  EXPECT_EQ(s.run.area_names.size(), 3u);
  EXPECT_EQ(s.run.recorded.size(), 6u);
  EXPECT_EQ(s.options.smooth_s, 10.0);
  const auto refused = [&](const std::string& from, const std::string& to, const std::string& where) {
    std::string changed = text;
    const std::size_t at = changed.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    changed.replace(at, from.size(), to);
    try {
      (void)ParseEnsembleSummary(changed, "s.json");
      ADD_FAILURE() << "accepted with " << to;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
    }
  };
  refused("\"crowdrecon-ensemble-run\"", "\"crowdrecon-scenario\"", "s.json: /format");
  refused("\"rise_time_s\": [\n  0.4,\n  null\n ]", "\"rise_time_s\": [0.4]", "s.json: /rise_time_s");
  refused("\"avalanche_s\": [\n  1100.5,", "\"avalanche_s\": [\n  null,", "s.json: /avalanche_s/0");
  refused("\"smooth_s\": 10.0", "\"smooth_s\": -1", "s.json: /options/smooth_s");
  refused("\"scale\": 1.0", "\"scale\": 1.0, \"extra\": 1", "s.json: /clock");
  // Read as a run of an ensemble with other options: refused, naming them.
  const std::filesystem::path file = crowdrecon::testing::ScratchFile("seed1.json");
  std::ofstream(file) << text;
  EnsembleOptions wider;
  wider.smooth_s = 5.0;
  try {
    (void)ReadEnsembleRun(file, wider);
    ADD_FAILURE() << "a summary made with 10-s smoothing was read with 5 s";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("summarised with smoothing 10 s"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ReadEnsembleRun(file, EnsembleOptions{}).clog_for_good_s, 4000.0);
  EXPECT_TRUE(EnsembleSummaryOutput().is_previous(file));
  EXPECT_FALSE(EnsembleSummaryOutput().is_previous(seed.parent_path() / "missing.json"));
}

TEST(Ensemble, ItsScoreFilesAreKnownAsPreviousOutputs) {
  const EnsembleScore s = ScoreEnsemble({MakeRun("seed 1", {130.0}, {}, kNaN, 0, 8.0)}, EnsembleOptions{});
  const OutputKind kind = EnsembleScoresOutput();
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"scores.md", s.Markdown()}, {"scores.csv", s.Csv()},
                                   {"other.md", "# notes\n"}}) {
    const std::filesystem::path f = crowdrecon::testing::ScratchFile(name);
    std::ofstream(f) << text;
    EXPECT_EQ(kind.is_previous(f), name != "other.md") << name;
  }
}

}  // namespace
}  // namespace crowdrecon::reports

// The ratio of the fractions in danger between two ensembles: the pairs
// whose main run had nobody in danger are counted and said, not dropped (a
// report once gave "1055" over the 6 of 24 pairs with a finite ratio while
// the other 18 had none).
TEST(Report, TheRatioOfTheFractionsInDangerSaysThePairsWithoutAFiniteRatio) {
  using crowdrecon::reports::DangerRatioOf;
  using crowdrecon::reports::DangerRatioText;
  // main: 1 of 100 in danger, 0 of 100, 0 of 100; other: 10 of 100, 0 of 100
  const auto r = DangerRatioOf({{1, 100}, {0, 100}, {0, 100}}, {{10, 100}, {0, 100}});
  EXPECT_EQ(r.finite.runs, 2u);
  EXPECT_DOUBLE_EQ(r.finite.low, 0.0);
  EXPECT_DOUBLE_EQ(r.finite.high, 10.0);
  EXPECT_EQ(r.main_none, 2u);
  EXPECT_EQ(r.neither, 2u);
  EXPECT_EQ(r.Pairs(), 6u);
  const std::string text = DangerRatioText(r, "validated <crowd>", "paper", true);
  EXPECT_NE(text.find("over the 2 of 6 pairs of runs in which validated &lt;crowd&gt; had someone in danger"),
            std::string::npos) << text;
  EXPECT_NE(text.find("in 2 more validated &lt;crowd&gt; had nobody in danger and paper had someone: no finite ratio"),
            std::string::npos) << text;
  EXPECT_NE(text.find("in 2 nobody was in danger in either run"), std::string::npos) << text;

  const auto none = DangerRatioOf({{0, 100}}, {{3, 100}, {5, 100}});
  EXPECT_EQ(none.finite.runs, 0u);
  EXPECT_EQ(DangerRatioText(none, "a", "b", false),
            "No finite ratio of the fractions in danger: nobody reached the danger zone in a, and someone did in b "
            "(in 2 of 2 pairs of runs).");
  EXPECT_EQ(DangerRatioText(DangerRatioOf({{0, 10}}, {{0, 10}}), "a", "b", false),
            "No ratio of the fractions in danger: nobody reached the danger zone in a or b.");
  EXPECT_EQ(DangerRatioText(DangerRatioOf({}, {}), "a", "b", false), "");
}
