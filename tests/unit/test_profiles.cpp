// Model profiles (issue 64, point 4): a scenario names its profile and may
// override single values; the profile's values are written into the
// scenario's text (kept in the run file); a scenario without one runs
// "paper", unchanged; bad names and bad profiles are errors that name them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/parameter_table.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/scenario/profile.hpp"
#include "crowdrecon/scenario/runner.hpp"
#include "crowdrecon/scenario/scenario.hpp"

namespace crowdrecon::scenario {
namespace {

namespace fs = std::filesystem;

const std::string kDir = std::string(CROWDRECON_SOURCE_DIR) + "/venues/itaewon/scenarios";
const std::string kHead = R"({"format": "crowdrecon-scenario", "version": 1, "venue": "../alley.json",
    "population": {"count": 20, "target": "to_station"}, "run": {"duration_s": 1})";

// Every parameter of the table, as the table writes it.
std::string ModelText(const engine::ModelParameters& m) {
  std::string text;
  for (const engine::ParameterInfo& info : engine::ModelParameterTable()) text += info.name + ("=" + info.ValueText(m)) + "\n";
  return text;
}

std::string ErrorOfParsing(const std::string& text, const std::string& dir = kDir) {
  try {
    ParseScenario(text, "s.json", dir);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// A profile file in a fresh folder under the test's temporary folder.
fs::path WriteProfile(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / ("crowdrecon-profiles-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  fs::create_directories(dir);
  const fs::path file = dir / name;
  std::ofstream(file) << text;
  return file;
}

TEST(ModelProfiles, AScenarioWithoutAProfileRunsPaperUnchanged) {
  const std::string text = kHead + "}";
  const Scenario s = ParseScenario(text, "s.json", kDir);
  EXPECT_EQ(s.profile, "paper");
  EXPECT_EQ(s.json_text, text);  // not rewritten: its run files stay as they were
  EXPECT_EQ(s.model.tangential_spring, engine::ModelParameters{}.tangential_spring);
}

TEST(ModelProfiles, TheNamedPaperProfileIsTheEnginesDefaults) {
  const Scenario named = ParseScenario(kHead + R"(, "profile": "paper"})", "s.json", kDir);
  const Scenario none = ParseScenario(kHead + "}", "s.json", kDir);
  EXPECT_EQ(named.profile, "paper");
  EXPECT_EQ(ModelText(named.model), ModelText(none.model));
  EXPECT_EQ(named.population.body_mode, none.population.body_mode);
  EXPECT_EQ(named.population.desired_speed_min_m_per_s, 0.8);
  EXPECT_EQ(named.population.desired_speed_max_m_per_s, 1.2);
  EXPECT_NE(named.json_text.find("\"profile\": \"paper\""), std::string::npos) << named.json_text;
  const std::vector<std::string> names = NamedProfiles();
  EXPECT_NE(std::find(names.begin(), names.end(), "paper"), names.end());
}

TEST(ModelProfiles, TheScenariosOwnValuesWinOverTheProfilesAndTheTextSaysAll) {
  const fs::path file = WriteProfile("doors.profile.json", R"({"format": "crowdrecon-profile", "version": 1,
    "name": "doors", "model": {"tangential_spring": "none", "yielding": "when_blocked", "yielding_push_share": 0.2,
    "restitution": 0.3}, "desired_speed_m_per_s": [1.0, 1.8], "body": {"mode": "circle"}})");
  const Scenario s = ParseScenario(kHead.substr(0, kHead.size()) + R"(, "profile": ")" + file.string() +
                                       R"(", "model": {"restitution": 0.5}})",
                                   "s.json", kDir);
  EXPECT_EQ(s.profile, "doors");
  EXPECT_EQ(s.model.tangential_spring, engine::TangentialSpring::kNone);
  EXPECT_EQ(s.model.yielding, engine::Yielding::kWhenBlocked);
  EXPECT_EQ(s.model.yielding_push_share, 0.2);
  EXPECT_EQ(s.model.restitution, 0.5);        // the scenario's own
  EXPECT_EQ(s.model.wall_restitution, 0.5);   // follows it, as without a profile
  EXPECT_EQ(s.population.desired_speed_min_m_per_s, 1.0);
  EXPECT_EQ(s.population.desired_speed_max_m_per_s, 1.8);
  EXPECT_EQ(s.population.body_mode, geometry::PopulationMode::kCircle);
  // The text the run file keeps carries every value that made the run.
  const Scenario again = ParseScenario(s.json_text, "again.json", kDir);
  EXPECT_EQ(ModelText(again.model), ModelText(s.model));
  EXPECT_EQ(again.json_text, s.json_text);
  EXPECT_NE(s.json_text.find("\"yielding_push_share\": 0.2"), std::string::npos) << s.json_text;
}

TEST(ModelProfiles, AnUnknownNameOrABadProfileIsAnErrorThatNamesIt) {
  const std::string unknown = ErrorOfParsing(kHead + R"(, "profile": "polite"})");
  EXPECT_NE(unknown.find("s.json: /profile: cannot use the profile:"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("venues/profiles/polite.json"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("expected one of the named profiles (paper"), std::string::npos) << unknown;
  const fs::path bad = WriteProfile("bad.profile.json", R"({"format": "crowdrecon-profile", "version": 1,
    "name": "bad", "model": {"yielding_push_share": 2}})");
  const std::string value = ErrorOfParsing(kHead + R"(, "profile": ")" + bad.string() + "\"}");
  EXPECT_NE(value.find(bad.string() + ": /model/yielding_push_share"), std::string::npos) << value;
  const fs::path key = WriteProfile("key.profile.json", R"({"format": "crowdrecon-profile", "version": 1,
    "name": "key", "model": {"politeness": 2}})");
  const std::string unknown_key = ErrorOfParsing(kHead + R"(, "profile": ")" + key.string() + "\"}");
  EXPECT_NE(unknown_key.find("/model/politeness: unknown model parameter"), std::string::npos) << unknown_key;
  const std::string not_text = ErrorOfParsing(kHead + R"(, "profile": 3})");
  EXPECT_NE(not_text.find("s.json: /profile"), std::string::npos) << not_text;
}

// The run file says which profile made it (run value "profile"), and keeps
// the scenario's text with the profile's values in it.
TEST(ModelProfiles, TheRunFileSaysWhichProfileMadeIt) {
  const fs::path file = WriteProfile("polite.profile.json", R"({"format": "crowdrecon-profile", "version": 1,
    "name": "polite", "model": {"yielding": "when_blocked"}})");
  const Scenario s = ParseScenario(kHead + R"(, "profile": ")" +
                                       file.string() + "\"}",
                                   "s.json", kDir);
  RunOptions options;
  options.output = file.parent_path() / "polite.sqlite";
  fs::remove(options.output);
  RunScenario(s, options);
  const runfile::RunFileReader run(options.output);
  EXPECT_EQ(run.RunValue("profile"), "polite");
  EXPECT_NE(run.RunValue("scenario").find("\"yielding\": \"when_blocked\""), std::string::npos);
}

// Every shipped named profile is read and applies to a scenario that names
// it; "validated" is issue 64's crowd (its evidence: docs/decisions.md).
TEST(ModelProfiles, EveryNamedProfileIsReadAndApplies) {
  const std::vector<std::string> names = NamedProfiles();
  ASSERT_GE(names.size(), 2u);
  for (const std::string& name : names) {
    const Scenario s = ParseScenario(kHead + R"(, "profile": ")" + name + "\"}", "s.json", kDir);
    EXPECT_EQ(s.profile, name);
  }
  const Scenario v = ParseScenario(kHead + R"(, "profile": "validated"})", "s.json", kDir);
  EXPECT_EQ(v.model.anticipation, engine::Anticipation::kTimeToCollision);
  EXPECT_EQ(v.model.tangential_spring, engine::TangentialSpring::kNone);
  EXPECT_EQ(v.model.headway, engine::Headway::kNone);
  EXPECT_EQ(v.population.desired_speed_min_m_per_s, 1.0);
  EXPECT_EQ(v.population.body_mode, geometry::PopulationMode::kPaper);
}


// `simulate --profile`: a scenario run under another profile than its own
// key without editing it (the paper's model one option away from a
// reconstruction's validated crowd); its own single values still win; a
// file is the working folder's; an unknown name is the same clear error.
TEST(ModelProfiles, AScenarioRunsUnderAnotherProfileWithoutEditingIt) {
  const fs::path night = fs::path(CROWDRECON_SOURCE_DIR) / "venues/madrid-arena/scenarios/madrid-night.json";
  const Scenario own = LoadScenario(night);
  EXPECT_EQ(own.profile, "validated");
  const Scenario paper = LoadScenario(night, "paper");
  EXPECT_EQ(paper.profile, "paper");
  EXPECT_EQ(paper.model.anticipation, engine::Anticipation::kNone);
  EXPECT_EQ(paper.model.back_force_gamma, own.model.back_force_gamma);  // the night's own Gamma
  EXPECT_EQ(LoadScenario(night, "").json_text, own.json_text);
  const fs::path file = WriteProfile("polite.profile.json", R"({"format": "crowdrecon-profile", "version": 1,
    "name": "polite", "model": {"yielding": "when_blocked"}})");
  const fs::path cwd = fs::current_path();
  fs::current_path(file.parent_path());
  const Scenario polite = LoadScenario(night, file.filename().string());
  fs::current_path(cwd);
  EXPECT_EQ(polite.profile, "polite");
  EXPECT_EQ(polite.model.yielding, engine::Yielding::kWhenBlocked);
  try {
    LoadScenario(night, "polit");
    ADD_FAILURE() << "an unknown profile was accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("madrid-night.json (with --profile polit): /profile: cannot use the profile"), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace crowdrecon::scenario
