// The run's validity (analysis/plausibility.hpp) read in the passes that
// read the run anyway -- the analysis's frame pass and the risk report's --
// is the validity ComputePlausibility reads on its own, field by field: the
// same peak, at the same person, place and time, the same time beyond the
// range and the same largest overlap, whether that comes from the contacts
// the risk pass streams or from the contact table.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "crowdrecon/analysis/plausibility.hpp"
#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/reports/risk.hpp"
#include "render_scene.hpp"

namespace crowdrecon::reports {
namespace {

void ExpectSame(const analysis::Plausibility& a, const analysis::Plausibility& b) {
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_EQ(a.peak_density_per_m2, b.peak_density_per_m2);
  EXPECT_EQ(a.peak_equivalent_density_per_m2, b.peak_equivalent_density_per_m2);
  EXPECT_EQ(a.peak_mean_body_area_m2, b.peak_mean_body_area_m2);
  EXPECT_EQ(a.peak_time_s, b.peak_time_s);
  EXPECT_EQ(a.peak_place_m.x, b.peak_place_m.x);
  EXPECT_EQ(a.peak_place_m.y, b.peak_place_m.y);
  EXPECT_EQ(a.peak_person, b.peak_person);
  EXPECT_EQ(a.time_beyond_static_s, b.time_beyond_static_s);
  EXPECT_EQ(a.time_beyond_measured_s, b.time_beyond_measured_s);
  EXPECT_EQ(a.contacts_available, b.contacts_available);
  EXPECT_EQ(a.max_overlap_m, b.max_overlap_m);
  EXPECT_EQ(a.max_overlap_time_s, b.max_overlap_time_s);
  EXPECT_EQ(a.max_overlap_with_wall, b.max_overlap_with_wall);
  EXPECT_EQ(a.verdict, b.verdict);
}

// 12 people in head-on counter-flow, 21 frames at 10 fps with contacts and
// chest loads.
std::filesystem::path CounterFlowRun(const std::string& name) {
  const std::filesystem::path file = std::filesystem::path(::testing::TempDir()) / name;
  std::filesystem::remove(file);
  const engine::testing::CorridorScene scene;
  engine::Simulation sim(engine::testing::CounterFlowCorridor(engine::testing::ThoraxLikeShape(), scene));
  engine::testing::WriteCorridorRun(file, sim, scene, 21, 10.0, /*record_periodic_box=*/true);
  return file;
}

TEST(ValidityPass, TheAnalysisAndTheRiskPassGiveWhatTheValidityAloneGives) {
  // 12 people in head-on counter-flow, 21 frames with contacts: the bodies
  // press into each other after the first frames, so the largest overlap and
  // the densest moment lie inside the run, not at its first frame.
  const std::filesystem::path file = CounterFlowRun("validity-pass.sqlite");

  const analysis::Plausibility alone = analysis::ComputePlausibility(file);
  ASSERT_EQ(alone.frames, 21u);
  ASSERT_TRUE(alone.contacts_available);
  ASSERT_GT(alone.max_overlap_m, 0.0);
  EXPECT_GT(alone.max_overlap_time_s, 0.0);

  ExpectSame(analysis::AnalyzeRun(file).plausibility, alone);

  RiskOptions options;
  EXPECT_FALSE(AnalyseRunRisk(file, options).validity.has_value());  // only when asked for
  options.validity = analysis::PlausibilityOptions{};
  const RunRisk risk = AnalyseRunRisk(file, options);
  ASSERT_TRUE(risk.validity.has_value());
  ExpectSame(*risk.validity, alone);

  // Other options reach the pass (a larger disc counts more people).
  analysis::PlausibilityOptions wide;
  wide.disc_area_m2 = 3.0;
  options.validity = wide;
  const analysis::Plausibility wide_alone = analysis::ComputePlausibility(file, wide);
  ExpectSame(*AnalyseRunRisk(file, options).validity, wide_alone);
  EXPECT_NE(wide_alone.peak_density_per_m2, alone.peak_density_per_m2);

  options.validity->disc_area_m2 = -1.0;
  std::string why;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("validity: disc_area_m2 = -1"), std::string::npos) << why;
}

// A caller that needs the loads alone (a sweep's risk columns, an
// ensemble's scores) skips the contact table, most of a long run's file:
// where the run records its chest loads, everyone's exposure is the same
// and the validity's largest overlap comes from the table instead.
TEST(ValidityPass, TheLoadsAloneNeedNoContactsWhereTheRunRecordsThem) {
  const std::filesystem::path file = CounterFlowRun("loads-alone.sqlite");

  RiskOptions options;
  options.validity = analysis::PlausibilityOptions{};
  const RunRisk all = AnalyseRunRisk(file, options);
  options.read_contacts = false;
  const RunRisk loads = AnalyseRunRisk(file, options);
  ASSERT_TRUE(all.loads_recorded);
  ASSERT_TRUE(all.has_contacts);
  EXPECT_GT(all.contact_rows, 0u);
  EXPECT_FALSE(loads.has_contacts);
  EXPECT_EQ(loads.contact_rows, 0u);
  ASSERT_EQ(loads.people.size(), all.people.size());
  for (std::size_t i = 0; i < all.people.size(); ++i) {
    EXPECT_EQ(loads.people[i].id, all.people[i].id);
    EXPECT_EQ(loads.people[i].max_load_n, all.people[i].max_load_n);
    EXPECT_EQ(loads.people[i].dose, all.people[i].dose);
    EXPECT_EQ(loads.people[i].longest_above_f0_s, all.people[i].longest_above_f0_s);
  }
  EXPECT_EQ(loads.counts, all.counts);
  EXPECT_EQ(loads.worst_frame, all.worst_frame);
  ASSERT_EQ(loads.frames.size(), all.frames.size());
  for (std::size_t k = 0; k < all.frames.size(); ++k) EXPECT_EQ(loads.frames[k].above_danger, all.frames[k].above_danger);
  ExpectSame(*loads.validity, *all.validity);
}

}  // namespace
}  // namespace crowdrecon::reports
