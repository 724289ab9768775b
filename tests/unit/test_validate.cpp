// The validation suite (issue 62): its measures on trajectories whose answers
// are known, its judging of every kind of criterion, and its files' errors.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/scenario/runner.hpp"
#include "crowdrecon/scenario/scenario.hpp"
#include "crowdrecon/validate/measures.hpp"
#include "crowdrecon/validate/validate.hpp"
#include "crowdrecon/validate/validation_test.hpp"

namespace crowdrecon::validate {
namespace {

namespace fs = std::filesystem;

// A person walking from `from` with velocity `v` for frames [f0, f1] at `fps`.
void Walk(observe::Trajectories* t, std::uint32_t id, Vec2 from, Vec2 v, std::int64_t f0, std::int64_t f1) {
  for (std::int64_t f = f0; f <= f1; ++f)
    t->points.push_back({id, f, from + (double(f - f0) / t->fps) * v, 0.0});
  t->first_frame = std::min(t->first_frame, f0);
  t->last_frame = std::max(t->last_frame, f1);
}

observe::Trajectories Empty(double fps) {
  observe::Trajectories t;
  t.source = "synthetic";
  t.format = "petrack";
  t.fps = fps;
  t.first_frame = 1'000'000;
  t.last_frame = 0;
  return t;
}

observe::Line LineAt(double x, double y0, double y1) {
  observe::Line l;
  l.a_m = {x, y0};
  l.b_m = {x, y1};
  return l;
}

// Every statistic a measure gives is one StatisticNames declares (the list a
// test's criteria are checked against when read).
void ExpectDeclared(const Statistics& s, MeasureKind kind) {
  for (const auto& [name, values] : s) EXPECT_EQ(UnknownStatistic(kind, name), "") << name;
}

TEST(ValidationMeasures, TravelTimeIsTheTimeBetweenTheTwoLines) {
  observe::Trajectories t = Empty(10.0);
  Walk(&t, 1, {-1.0, 1.0}, {1.25, 0.0}, 0, 400);  // 1.25 m/s: 40 m in 32 s
  t.people = 1;
  MeasureSpec m;
  m.kind = MeasureKind::kTravel;
  m.from_line = LineAt(0, 0, 2);
  m.to_line = LineAt(40, 0, 2);
  const Statistics s = MeasureTrajectories(t, m);
  ExpectDeclared(s, m.kind);
  ASSERT_EQ(s.at("travel_time_s").size(), 1u);
  EXPECT_NEAR(s.at("travel_time_s")[0], 32.0, 1e-9);
  EXPECT_NEAR(s.at("speed_m_per_s")[0], 1.25, 1e-9);
  EXPECT_DOUBLE_EQ(s.at("arrived_share")[0], 1.0);
}

TEST(ValidationMeasures, PassagesGiveFlowLapsesAndTheOpenLapseOfAClog) {
  // Five people cross x = 0 going +x at 1, 2, 3, 5 and 10 s (frame times at
  // 10 fps, so crossings fall exactly between frames: interpolated); a sixth
  // never crosses. The file runs 0-20 s.
  observe::Trajectories t = Empty(10.0);
  const double crossings[] = {1.0, 2.0, 3.0, 5.0, 10.0};
  for (int i = 0; i < 5; ++i) Walk(&t, std::uint32_t(i + 1), {-crossings[i] * 0.5, 0.5}, {0.5, 0.0}, 0, 200);
  Walk(&t, 6, {-3.0, 0.5}, {0.0, 0.0}, 0, 200);
  MeasureSpec m;
  m.kind = MeasureKind::kPassages;
  m.line = LineAt(0, 0, 1);
  m.direction = {1, 0};
  Statistics s = MeasureTrajectories(t, m);
  ExpectDeclared(s, m.kind);
  EXPECT_DOUBLE_EQ(s.at("passed")[0], 5.0);
  EXPECT_NEAR(s.at("passed_share")[0], 5.0 / 6.0, 1e-12);
  EXPECT_NEAR(s.at("flow_per_s")[0], 4.0 / 9.0, 1e-9);
  EXPECT_NEAR(s.at("sustained_flow_per_s")[0], 4.0 / 19.0, 1e-9);  // the clog to the end (20 s) counts
  EXPECT_NEAR(s.at("max_lapse_s")[0], 5.0, 1e-9);
  EXPECT_NEAR(s.at("median_lapse_s")[0], 1.5, 1e-9);
  EXPECT_NEAR(s.at("open_lapse_s")[0], 10.0, 1e-9);  // from the last passage to the end: a clog
  EXPECT_TRUE(std::isnan(s.at("time_to_all_s")[0]));
  // Going the other way counts nothing.
  m.direction = {-1, 0};
  s = MeasureTrajectories(t, m);
  EXPECT_DOUBLE_EQ(s.at("passed")[0], 0.0);
}

TEST(ValidationMeasures, PassageTimesCountFromTheFilesFirstFrame) {
  // An experiment's frames start anywhere (the Jülich files at 94 or 98).
  observe::Trajectories t = Empty(25.0);
  Walk(&t, 1, {-1.0, 0.5}, {1.0, 0.0}, 100, 200);  // crosses 1 s after frame 100
  Walk(&t, 2, {-2.0, 0.5}, {1.0, 0.0}, 100, 200);  // 2 s after
  MeasureSpec m;
  m.kind = MeasureKind::kPassages;
  m.line = LineAt(0, 0, 1);
  m.direction = {1, 0};
  const Statistics s = MeasureTrajectories(t, m);
  ExpectDeclared(s, m.kind);
  EXPECT_NEAR(s.at("time_to_all_s")[0], 2.0, 1e-9);
  EXPECT_NEAR(s.at("open_lapse_s")[0], 0.0, 1e-12);
}

TEST(ValidationMeasures, ClearanceCountsTracksThatEndBeforeTheFile) {
  observe::Trajectories t = Empty(10.0);
  Walk(&t, 1, {0, 0}, {1, 0}, 0, 50);   // leaves at 5 s
  Walk(&t, 2, {0, 1}, {1, 0}, 0, 120);  // at 12 s
  Walk(&t, 3, {0, 2}, {0, 0}, 0, 300);  // still there at the end
  MeasureSpec m;
  m.kind = MeasureKind::kClearance;
  Statistics s = MeasureTrajectories(t, m);
  ExpectDeclared(s, m.kind);
  EXPECT_NEAR(s.at("left_share")[0], 2.0 / 3.0, 1e-12);
  EXPECT_TRUE(std::isnan(s.at("time_to_all_s")[0]));
  t.points.erase(std::remove_if(t.points.begin(), t.points.end(), [](const auto& p) { return p.id == 3; }), t.points.end());
  t.last_frame = 200;
  s = MeasureTrajectories(t, m);
  EXPECT_NEAR(s.at("time_to_all_s")[0], 12.0, 1e-12);
}

TEST(ValidationMeasures, HeadwayIsTheDistanceToThePersonAheadInTheSameFile) {
  // A file of two walkers 1.0 m apart, and a third beside them (0.8 m off
  // the line: not ahead of anyone).
  observe::Trajectories t = Empty(10.0);
  Walk(&t, 1, {0.0, 1.0}, {1.0, 0.0}, 0, 100);
  Walk(&t, 2, {1.0, 1.0}, {1.0, 0.0}, 0, 100);
  Walk(&t, 3, {0.5, 1.8}, {1.0, 0.0}, 0, 100);
  MeasureSpec m;
  m.kind = MeasureKind::kHeadway;
  m.has_area = true;
  m.area.polygon_m = {{-10, 0}, {30, 0}, {30, 3}, {-10, 3}};
  const Statistics s = MeasureTrajectories(t, m);
  ExpectDeclared(s, m.kind);
  const auto& h = s.at("headway_m");
  ASSERT_FALSE(h.empty());
  for (double v : h) EXPECT_NEAR(v, 1.0, 1e-9);
  // One headway per sampled frame (person 1's only): frames 0, 5, ..., 100.
  EXPECT_EQ(h.size(), 21u);
}

TEST(ValidationMeasures, WalkingSpeedIsDistanceOverTimeInTheAreaByGroup) {
  observe::Trajectories t = Empty(10.0);
  Walk(&t, 1, {0.0, 1.0}, {1.2, 0.0}, 0, 300);
  Walk(&t, 2, {0.0, 2.0}, {0.6, 0.8}, 0, 300);  // 1.0 m/s diagonally
  // A walker at 0.9 m/s who sways 4 cm across the way every frame: the
  // sway is not distance (its path is 0.1 m per frame, 1.0 m/s).
  Walk(&t, 3, {0.0, 4.0}, {0.9, 0.0}, 0, 300);
  for (auto& p : t.points)
    if (p.id == 3 && p.frame % 2 == 1) p.position_m.y += 0.04;
  t.groups = {{1, 0}, {2, 1}, {3, 0}};
  MeasureSpec m;
  m.kind = MeasureKind::kWalkingSpeed;
  m.has_area = true;
  m.area.polygon_m = {{5, 0}, {15, 0}, {15, 50}, {5, 50}};
  const Statistics s = MeasureTrajectories(t, m);
  ExpectDeclared(s, m.kind);
  EXPECT_NEAR(s.at("speed_m_per_s@group0")[0], 1.2, 1e-9);
  ASSERT_EQ(s.at("speed_m_per_s@group0").size(), 2u);
  EXPECT_NEAR(s.at("speed_m_per_s@group0")[1], 0.9, 1e-3);  // (the last frame inside may be a swayed one)
  EXPECT_NEAR(s.at("speed_m_per_s@group1")[0], 1.0, 1e-9);
  // The group filter keeps one group's people.
  m.group = "group1";
  const Statistics g = MeasureTrajectories(t, m);
  ExpectDeclared(g, m.kind);
  EXPECT_EQ(g.at("speed_m_per_s").size(), 1u);
}

TEST(ValidationMeasures, FundamentalDiagramGivesTheAreasDensityAndSpeed) {
  observe::Trajectories t = Empty(10.0);
  // Eight people walking +x at 1.1 m/s through a 4 m x 2 m area, side by
  // side in two rows: 8 / 8 m2 = 1 person/m2 while all are inside.
  for (int i = 0; i < 8; ++i) Walk(&t, std::uint32_t(i + 1), {0.3 + 0.5 * (i % 4), 0.5 + 1.0 * (i / 4)}, {1.1, 0.0}, 0, 10);
  MeasureSpec m;
  m.kind = MeasureKind::kFundamentalDiagram;
  m.has_area = true;
  m.area.polygon_m = {{0, 0}, {4, 0}, {4, 2}, {0, 2}};
  m.frame_step = 1;
  const Statistics s = MeasureTrajectories(t, m);
  ExpectDeclared(s, m.kind);
  EXPECT_NEAR(s.at("density_per_m2")[0], 1.0, 1e-9);
  EXPECT_NEAR(s.at("speed_m_per_s")[0], 1.1, 1e-9);
  EXPECT_NEAR(s.at("specific_flow_per_m_s")[0], 1.1, 1e-9);
}

TEST(ValidationMeasures, LanesThatMixAreCountedAsBroken) {
  // Twenty walkers each way, 1 m apart, in a periodic box 20 m long: in two
  // lanes (y = 1 and y = 3) for 10 s, then all in one file (y = 1, each
  // seeing as many walkers the other way as its own within 1.5 m) for 10 s,
  // then in lanes again.
  observe::Trajectories t = Empty(5.0);
  for (std::int64_t f = 0; f <= 150; ++f) {
    const bool mixed = f > 50 && f <= 100;
    for (std::uint32_t id = 1; id <= 40; ++id) {
      const bool east = id <= 20;
      const double x0 = double((id - 1) % 20) + (east ? 0.0 : 0.5);
      const double x = x0 + (east ? 1.0 : -1.0) * double(f) / 5.0;
      const double y = mixed ? 1.0 : (east ? 1.0 : 3.0);
      t.points.push_back({id, f, {std::fmod(x + 1000.0, 20.0), y}, 0.0});
    }
  }
  t.first_frame = 0;
  t.last_frame = 150;
  t.box.x = true;
  t.box.min_m = {0, 0};
  t.box.max_m = {20, 4};
  MeasureSpec m;
  m.kind = MeasureKind::kLanes;
  m.has_area = true;
  m.area.polygon_m = {{0, 0}, {20, 0}, {20, 4}, {0, 4}};
  m.direction = {1, 0};
  m.frame_step = 1;
  const Statistics s = MeasureTrajectories(t, m);
  ExpectDeclared(s, m.kind);
  EXPECT_DOUBLE_EQ(s.at("lane_breaks")[0], 1.0);
  EXPECT_DOUBLE_EQ(s.at("lane_reformations")[0], 1.0);
  EXPECT_DOUBLE_EQ(s.at("organized_at_end")[0], 1.0);
  EXPECT_GT(s.at("organized_share")[0], 0.6);
  EXPECT_LT(s.at("organized_share")[0], 0.72);
  EXPECT_NEAR(s.at("longest_organized_s")[0], 10.0, 0.5);
}

// A run that ends once everyone has left writes a last frame without people:
// the last to leave has left too (RiMEA 15's clearance), and every start event
// counts in the pre-movement sample (NIST Verif.1.1).
TEST(ValidationMeasures, ARunsClearanceAndStartsCountEveryone) {
  const fs::path dir = fs::temp_directory_path() / "crowdrecon-validate-run";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path venue = fs::path(CROWDRECON_SOURCE_DIR) / "venues/validation/venues/corner.json";
  const std::string text = R"({"format": "crowdrecon-scenario", "version": 1, "name": "t", "venue": ")" + venue.string() +
                           R"(", "population": {"count": 4, "target": "leave", "placement": {"region": "entries"},
      "desired_speed_m_per_s": [1.2, 1.4], "seed": 3},
      "run": {"duration_s": 60, "output_fps": 5, "checkpoint_interval_s": 0, "contacts": false},
      "timeline": {"stop_when_left_fraction": 1, "premovement": {"uniform_s": [0.5, 2]}}})";
  const scenario::Scenario sc = scenario::ParseScenario(text, (dir / "t.json").string(), dir);
  scenario::RunOptions options;
  options.output = dir / "run.sqlite";
  ASSERT_EQ(scenario::RunScenario(sc, options).status, "complete");
  MeasureSpec clearance;
  clearance.kind = MeasureKind::kClearance;
  const Statistics c = MeasureRun(options.output, clearance);
  ExpectDeclared(c, clearance.kind);
  EXPECT_EQ(c.at("left_share")[0], 1.0);
  EXPECT_TRUE(std::isfinite(c.at("time_to_all_s")[0]));
  EXPECT_LT(c.at("time_to_all_s")[0], 60.0);
  MeasureSpec starts;
  starts.kind = MeasureKind::kStartTimes;
  const Statistics st = MeasureRun(options.output, starts);
  ExpectDeclared(st, starts.kind);
  EXPECT_EQ(st.at("premovement_s").size(), 4u);
  EXPECT_EQ(st.at("started_people")[0], 4.0);
  for (double t : st.at("premovement_s")) {
    EXPECT_GE(t, 0.5);
    EXPECT_LT(t, 2.05);
  }
  fs::remove_all(dir);
}

// --- Judging ----------------------------------------------------------------

ValidationTest TwoCaseTest() {
  ValidationTest t;
  t.id = "t";
  t.cases = {Case{"a", "a", 1.0, {}, {1.0, 1.2}}, Case{"b", "b", 2.0, {}, {2.0}}};
  return t;
}

Statistics RunOf(std::initializer_list<std::pair<const std::string, std::vector<double>>> values, bool completed = true) {
  Statistics s(values);
  s["completed"] = {completed ? 1.0 : 0.0};
  return s;
}

TEST(ValidationJudge, EveryValueMustLieInTheBand) {
  ValidationTest t = TwoCaseTest();
  Criterion c;
  c.statistic = "x";
  c.aggregate = Aggregate::kEvery;
  c.low = 1.0;
  c.high = 2.0;
  t.criteria = {c};
  TestResult r = Judge(t, "p", {{RunOf({{"x", {1.0, 1.5}}}), RunOf({{"x", {2.0}}})}, {RunOf({{"x", {1.9}}})}}, std::nullopt);
  EXPECT_EQ(r.verdict, Verdict::kPass);
  r = Judge(t, "p", {{RunOf({{"x", {1.0, 2.01}}})}, {RunOf({{"x", {1.9}}})}}, std::nullopt);
  EXPECT_EQ(r.verdict, Verdict::kFail);
  EXPECT_FALSE(r.criteria[0].cases[0].pass);
  EXPECT_TRUE(r.criteria[0].cases[1].pass);
  // A run that failed fails the criterion, whatever the others gave.
  r = Judge(t, "p", {{RunOf({{"x", {1.5}}}), RunOf({}, false)}, {RunOf({{"x", {1.9}}})}}, std::nullopt);
  EXPECT_EQ(r.verdict, Verdict::kFail);
  EXPECT_EQ(r.failures.size(), 1u);
}

TEST(ValidationJudge, PublishedValuesDataAndCasesAreComparedAsDeclared) {
  ValidationTest t = TwoCaseTest();
  Criterion near;
  near.statistic = "flow";
  near.kind = CriterionKind::kNearReference;
  near.relative = 0.1;  // a: [0.9, 1.32]; b: [1.8, 2.2]
  Criterion rise;
  rise.statistic = "flow";
  rise.kind = CriterionKind::kIncreasing;
  Criterion ratio;
  ratio.statistic = "flow";
  ratio.kind = CriterionKind::kRatio;
  ratio.case_a = "a";
  ratio.case_b = "b";
  ratio.low = 1.5;
  ratio.high = 2.5;
  Criterion shown;
  shown.statistic = "flow";
  shown.kind = CriterionKind::kDocuments;
  t.criteria = {near, rise, ratio, shown};
  TestResult r = Judge(t, "p", {{RunOf({{"flow", {1.3}}})}, {RunOf({{"flow", {2.1}}})}}, std::nullopt);
  EXPECT_EQ(r.verdict, Verdict::kPass);
  EXPECT_FALSE(r.criteria[3].judged);
  r = Judge(t, "p", {{RunOf({{"flow", {1.4}}})}, {RunOf({{"flow", {2.1}}})}}, std::nullopt);  // 1.4 > 1.32
  EXPECT_EQ(r.verdict, Verdict::kFail);
  EXPECT_FALSE(r.criteria[0].pass);
  EXPECT_TRUE(r.criteria[1].pass);
  r = Judge(t, "p", {{RunOf({{"flow", {1.2}}})}, {RunOf({{"flow", {1.9}}})}}, std::nullopt);
  EXPECT_TRUE(r.criteria[1].pass);
  EXPECT_TRUE(r.criteria[2].pass);  // 1.9 / 1.2 = 1.58
  r = Judge(t, "p", {{RunOf({{"flow", {1.2}}})}, {RunOf({{"flow", {1.1}}})}}, std::nullopt);
  EXPECT_FALSE(r.criteria[1].pass);  // falls
  EXPECT_FALSE(r.criteria[2].pass);  // 0.92
}

TEST(ValidationJudge, TheDataBandComparesAtTheRunsDensity) {
  ValidationTest t;
  t.id = "fd";
  t.cases = {Case{"base", "", 0, {}, {}}};
  Criterion c;
  c.statistic = "speed_m_per_s";
  c.kind = CriterionKind::kDataBand;
  c.band_sd = 2.0;
  c.band_width_per_m2 = 0.2;
  t.criteria = {c};
  Statistics data;
  // 40 samples at 1.0 /m2 with speeds 1.0 +- 0.1 (sd 0.1013), 40 at 2 /m2 around 0.5.
  for (int i = 0; i < 40; ++i) {
    data["fd_density_per_m2"].push_back(1.0);
    data["fd_speed_m_per_s"].push_back(i % 2 ? 1.1 : 0.9);
    data["fd_density_per_m2"].push_back(2.0);
    data["fd_speed_m_per_s"].push_back(0.5);
  }
  auto judged = [&](double rho, double v) {
    return Judge(t, "p", {{RunOf({{"density_per_m2", {rho}}, {"speed_m_per_s", {v}}})}}, data).criteria[0].cases[0];
  };
  EXPECT_TRUE(judged(1.05, 1.15).pass);
  EXPECT_FALSE(judged(1.05, 1.25).pass);
  // No data at 3 /m2: not judged, said so.
  const CaseVerdict none = judged(3.0, 0.2);
  EXPECT_FALSE(none.judged);
  EXPECT_NE(none.expected.find("fewer than 10"), std::string::npos);
}

TEST(ValidationJudge, QuantilesOfTheDataBoundTheAggregate) {
  ValidationTest t;
  t.id = "h";
  t.cases = {Case{"base", "", 0, {}, {}}};
  Criterion c;
  c.statistic = "headway_m";
  c.kind = CriterionKind::kWithinData;
  c.quantile_low = 0.25;
  c.quantile_high = 0.75;
  t.criteria = {c};
  Statistics data;
  data["headway_m"] = {0.5, 1.0, 1.5, 2.0, 2.5};  // quartiles 1.0 and 2.0
  EXPECT_TRUE(Judge(t, "p", {{RunOf({{"headway_m", {1.4, 1.6}}})}}, data).criteria[0].pass);
  EXPECT_FALSE(Judge(t, "p", {{RunOf({{"headway_m", {0.6, 0.8}}})}}, data).criteria[0].pass);
}

TEST(ValidationJudge, FollowsIsAKolmogorovSmirnovTestOfThePooledValues) {
  ValidationTest t;
  t.id = "pre";
  t.cases = {Case{"base", "", 0, {}, {}}};
  Criterion c;
  c.statistic = "premovement_s";
  c.kind = CriterionKind::kFollows;
  c.distribution.kind = Distribution::Kind::kWeibull;
  c.distribution.a = 1.195;
  c.distribution.b = 139.285;
  t.criteria = {c};
  // 100 values at the distribution's quantiles, split over two seeds: D is
  // at most 1/100, far below the critical value (about 0.134).
  std::vector<double> a, b;
  for (int i = 0; i < 100; ++i) (i % 2 ? a : b).push_back(c.distribution.Quantile((i + 0.5) / 100.0));
  TestResult r = Judge(t, "p", {{RunOf({{"premovement_s", a}}), RunOf({{"premovement_s", b}})}}, std::nullopt);
  EXPECT_TRUE(r.criteria[0].pass) << r.criteria[0].cases[0].text;
  EXPECT_LE(r.criteria[0].cases[0].value, 0.0101);
  // The same values half as late again: rejected (the CDFs differ by up to 0.18).
  for (double& x : a) x *= 1.5;
  for (double& x : b) x *= 1.5;
  r = Judge(t, "p", {{RunOf({{"premovement_s", a}}), RunOf({{"premovement_s", b}})}}, std::nullopt);
  EXPECT_FALSE(r.criteria[0].pass);
  EXPECT_GT(r.criteria[0].cases[0].value, 0.134);
  EXPECT_NE(r.criteria[0].cases[0].expected.find("Weibull"), std::string::npos);
  // Uniform values judged against the gamma distribution of NIST's case: rejected.
  t.criteria[0].distribution = Distribution{Distribution::Kind::kGamma, 1.291, 103.901};
  std::vector<double> u;
  for (int i = 0; i < 100; ++i) u.push_back(10.0 + 90.0 * (i + 0.5) / 100.0);
  EXPECT_FALSE(Judge(t, "p", {{RunOf({{"premovement_s", u}})}}, std::nullopt).criteria[0].pass);
}

// --- Files ------------------------------------------------------------------

std::string TestText(const std::string& extra, const std::string& criteria = "") {
  return R"({"format": "crowdrecon-validation-test", "version": 1, "id": "x", "title": "t", "standard": "s",
             "role": "verification", "source": "s", "setup": "s",
             "scenario": "../scenarios/corridor-40m.json",
             "measure": {"kind": "travel", "from": [[0, 0], [0, 2]], "to": [[40, 0], [40, 2]]})" +
         extra + R"(, "criteria": [)" + criteria + "]}";
}

std::string ErrorOf(const std::string& text) {
  const fs::path dir = fs::path(CROWDRECON_SOURCE_DIR) / "venues/validation/tests";
  try {
    ParseValidationTest(text, "x.json", dir);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ValidationFiles, BadTestsAreRefusedWithTheirJsonPath) {
  const std::string ok = R"({"statistic": "travel_time_s", "within": [26, 34], "why": "w"})";
  EXPECT_EQ(ErrorOf(TestText("", ok)), "");
  EXPECT_NE(ErrorOf(TestText(R"(, "seeds": {"count": 0})", ok)).find("/seeds/count"), std::string::npos);
  EXPECT_NE(ErrorOf(TestText(R"(, "colour": 1)", ok)).find("colour"), std::string::npos);
  EXPECT_NE(ErrorOf(TestText("", R"({"statistic": "s", "within": [2, 1], "why": "w"})")).find("/criteria/0/within"),
            std::string::npos);
  EXPECT_NE(ErrorOf(TestText("", R"({"statistic": "s", "within": [1, 2], "documents": true, "why": "w"})"))
                .find("exactly one of"),
            std::string::npos);
  EXPECT_NE(ErrorOf(TestText("", R"({"statistic": "s", "within": [1, 2]})")).find("why"), std::string::npos);
  EXPECT_NE(ErrorOf(TestText("", R"({"statistic": "s", "near_data": 0.2, "why": "w"})")).find("no \"data\""),
            std::string::npos);
  EXPECT_NE(ErrorOf(TestText("", R"({"statistic": "travel_time_s", "near_reference": 0.2, "why": "w"})")).find("reference"),
            std::string::npos);
  EXPECT_NE(ErrorOf(TestText("", R"({"statistic": "s", "ratio": {"of": "a", "to": "base", "within": [1, 2]}, "why": "w"})"))
                .find("\"a\" is not a case"),
            std::string::npos);
  EXPECT_NE(ErrorOf(TestText(R"(, "cases": [{"name": "a b"}])", ok)).find("/cases/0/name"), std::string::npos);
  EXPECT_EQ(ErrorOf(TestText("", R"({"statistic": "travel_time_s", "follows": {"gamma": {"shape": 1.3, "scale_s": 104}}, "alpha": 0.05, "why": "w"})")), "");
  EXPECT_EQ(ErrorOf(TestText("", R"({"statistic": "travel_time_s", "within": [1, null], "why": "w"})")), "");
  // A statistic the measure does not give (issue 65, K19).
  EXPECT_NE(ErrorOf(TestText("", R"({"statistic": "travel_tme_s", "within": [1, 2], "why": "w"})"))
                .find("/criteria/0/statistic: \"travel_tme_s\" is not a statistic of the measure travel; expected one of "
                      "travel_time_s, speed_m_per_s, arrived_share, completed"),
            std::string::npos)
      << ErrorOf(TestText("", R"({"statistic": "travel_tme_s", "within": [1, 2], "why": "w"})"));
  EXPECT_NE(ErrorOf(TestText("", R"({"statistic": "s", "within_data": [null, 0.5], "why": "w"})")).find("quantiles"),
            std::string::npos);
  EXPECT_NE(ErrorOf(TestText("", R"({"statistic": "s", "follows": {"gamma": {"shape": -1, "scale_s": 104}}, "why": "w"})"))
                .find("/criteria/0/follows/gamma/shape"),
            std::string::npos);
  EXPECT_NE(ErrorOf(TestText("", R"({"statistic": "s", "follows": {"beta": {}}, "why": "w"})")).find("exactly one distribution"),
            std::string::npos);
  EXPECT_NE(ErrorOf(TestText("", R"({"statistic": "s", "within": [1, 2], "alpha": 0.1, "why": "w"})")).find("/criteria/0/alpha"),
            std::string::npos);
  const std::string bad_measure = R"({"format": "crowdrecon-validation-test", "version": 1, "id": "x", "title": "t",
      "standard": "s", "role": "fit", "source": "s", "setup": "s", "scenario": "../scenarios/corridor-40m.json",
      "measure": {"kind": "teleport"}})";
  EXPECT_NE(ErrorOf(bad_measure).find("/measure/kind"), std::string::npos);
  EXPECT_NE(ErrorOf(TestText(R"(, "set": {"venue": "no-such-venue.json"})", ok)).find("no-such-venue.json"),
            std::string::npos);
  EXPECT_NE(ErrorOf(TestText("", "")).find("/criteria: expected at least one criterion"), std::string::npos)
      << ErrorOf(TestText("", ""));  // (K17: an empty list ran its seeds for nothing)
}

// A profile's bad model key or value is blamed on the profile, by its JSON
// path (issue 65, K03, K10: it was blamed on every test's scenario).
TEST(ValidationFiles, AProfilesBadModelIsRefusedInTheProfile) {
  const auto error = [](const std::string& model) {
    try {
      ParseProfile(R"({"format": "crowdrecon-profile", "version": 1, "name": "p", "model": )" + model + "}", "p.json",
                   fs::path(CROWDRECON_SOURCE_DIR));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error(R"({"gait_jitter": "isotropic", "gait_jitter_velocity_m_per_s": 0.3})"), "");
  EXPECT_NE(error(R"({"gait_jiter": 0.3})").find("p.json: /model/gait_jiter: unknown model parameter"), std::string::npos)
      << error(R"({"gait_jiter": 0.3})");
  EXPECT_NE(error(R"({"gait_jitter_velocity_m_per_s": 7})").find("p.json: /model/gait_jitter_velocity_m_per_s"),
            std::string::npos);
  EXPECT_NE(error(R"({"headway": "far"})").find("p.json: /model/headway: \"far\"; expected one of none, time_gap"),
            std::string::npos)
      << error(R"({"headway": "far"})");
}

TEST(ValidationFiles, EveryShippedTestAndProfileReads) {
  const fs::path suite = fs::path(CROWDRECON_SOURCE_DIR) / "venues/validation";
  const std::vector<ValidationTest> tests = LoadSuite(suite);
  EXPECT_GE(tests.size(), 10u);
  bool quick = false;
  for (const ValidationTest& t : tests) {
    EXPECT_FALSE(t.source.empty()) << t.id;
    EXPECT_FALSE(t.criteria.empty()) << t.id;
    quick = quick || t.quick;
  }
  EXPECT_TRUE(quick);
  for (const char* p : {"paper.json", "paper-circle.json"}) {
    const Profile profile = LoadProfile(suite / "profiles" / p);
    EXPECT_FALSE(profile.set.empty()) << p;
  }
}

TEST(ValidationFiles, StatisticsSurviveTheirJson) {
  Statistics s;
  s["a"] = {1.5, std::nan(""), -2.0};
  s["b"] = {};
  const Statistics back = StatisticsFromJson(StatisticsToJson(s), "x");
  ASSERT_EQ(back.at("a").size(), 3u);
  EXPECT_EQ(back.at("a")[0], 1.5);
  EXPECT_TRUE(std::isnan(back.at("a")[1]));
  EXPECT_TRUE(back.at("b").empty());
  EXPECT_THROW(StatisticsFromJson("{\"a\": [\"x\"]}", "x"), InputError);
}

// A validation's results.json read for other outputs (report --validation):
// per profile the tests passed and those failed, in the suite's order, with
// their roles; a file that is not one is refused naming the place.
TEST(ValidationFiles, TheResultsSummaryCountsEachProfilesVerdicts) {
  const std::string ok = R"({"format": "crowdrecon-validation-results", "version": 1, "build": "abc", "sources": "f00",
    "profiles": [{"name": "validated", "description": "d"}, {"name": "paper"}],
    "tests": [{"id": "t-one", "role": "fit", "results": {"validated": {"verdict": "pass"}, "paper": {"verdict": "fail"}}},
              {"id": "t-two", "role": "held-out", "results": {"validated": {"verdict": "fail"}, "paper": {"verdict": "error"}}},
              {"id": "t-three", "role": "verification", "results": {"validated": {"verdict": "documents"}, "paper": {"verdict": "pass"}}}]})";
  const ValidationSummary v = ParseValidationSummary(ok, "results.json");
  EXPECT_EQ(v.build, "abc");
  ASSERT_EQ(v.profiles.size(), 2u);
  const ProfileVerdicts* validated = v.Find("validated");
  ASSERT_NE(validated, nullptr);
  EXPECT_EQ(validated->tests, 3u);
  EXPECT_EQ(validated->passed, 1u);
  EXPECT_EQ(validated->failed, (std::vector<std::string>{"t-two (held-out)"}));
  EXPECT_EQ(v.Find("paper")->failed, (std::vector<std::string>{"t-one (fit)", "t-two (held-out, an error)"}));
  EXPECT_EQ(v.Find("polite"), nullptr);
  const auto refused = [](const std::string& text, const std::string& where) {
    try {
      (void)ParseValidationSummary(text, "r.json");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
    }
  };
  refused("[1]", "r.json");
  refused(R"({"format": "crowdrecon-scenario", "version": 1})", "r.json: /format");
  const std::string head = R"({"format": "crowdrecon-validation-results", "version": 1, "build": "b", "sources": "s", )";
  refused(head + R"("profiles": [], "tests": []})", "r.json: /profiles");
  refused(head + R"("profiles": [{"name": "a"}, {"name": "a"}], "tests": []})", "r.json: /profiles/1/name");
  refused(head + R"("profiles": [{"name": "a"}], "tests": [{"id": "t", "role": "fit", "results": {}}]})",
          "r.json: /tests/0/results");
  refused(head + R"("profiles": [{"name": "a"}], "tests": [{"id": "t", "role": "fit", "results": {"a": {"verdict": "maybe"}}}]})",
          "r.json: /tests/0/results/a/verdict");
}

}  // namespace
}  // namespace crowdrecon::validate
