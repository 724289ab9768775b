// The model's parameter table (engine/parameter_table.hpp): one definition of
// every parameter, from which validation, the scenario reader, the world file
// and the table in docs/model.md are derived.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "crowdrecon/engine/parameter_table.hpp"
#include "generated_docs.hpp"

namespace crowdrecon::engine {
namespace {

TEST(ParameterTable, NamesAreUniqueAndDefaultsAreValid) {
  std::set<std::string> names;
  for (const ParameterInfo& info : ModelParameterTable()) {
    EXPECT_TRUE(names.insert(info.name).second) << info.name;
    EXPECT_NE(std::string(info.meaning), "") << info.name;
    EXPECT_NE(std::string(info.source), "") << info.name;
    if (info.default_from) {
      EXPECT_NE(FindModelParameter(info.default_from), nullptr) << info.name;
    }
  }
  std::string error;
  EXPECT_TRUE(ModelParameters{}.IsValid(&error)) << error;
}

TEST(ParameterTable, EveryFieldOfModelParametersIsInTheTable) {
  // Changing each entry's field changes that parameter's value (each entry
  // reaches its own field).
  for (const ParameterInfo& info : ModelParameterTable()) {
    ModelParameters p;
    switch (info.kind) {
      case ParameterInfo::Kind::kNumber: p.*info.number = p.*info.number == info.max ? info.min : info.max; break;
      case ParameterInfo::Kind::kFlag: p.*info.flag = !(p.*info.flag); break;
      case ParameterInfo::Kind::kChoice:
        info.set_choice(p, (info.get_choice(p) + 1) % static_cast<int>(info.choice_count));
        break;
    }
    EXPECT_NE(info.ValueText(p), info.ValueText(ModelParameters{})) << info.name;
  }
  // A new field changes the size: add it to the table (the world file asserts the same).
  EXPECT_EQ(sizeof(ModelParameters), 544u) << "ModelParameters changed: update the parameter table";
}

TEST(ParameterTable, IsValidUsesTheTableRanges) {
  for (const ParameterInfo& info : ModelParameterTable()) {
    if (info.kind != ParameterInfo::Kind::kNumber) continue;
    for (double bad : {info.min - 1e-9 * (1.0 + std::abs(info.min)), info.max * (1 + 1e-9) + 1e-12}) {
      ModelParameters p;
      p.*info.number = bad;
      std::string error;
      EXPECT_FALSE(p.IsValid(&error)) << info.name << " = " << bad;
      EXPECT_NE(error.find(info.name), std::string::npos) << error;
      EXPECT_NE(error.find(info.Expected()), std::string::npos) << error;
    }
    ModelParameters p;
    p.*info.number = info.min;
    // The jitter's band has a second rule (high >= low), checked apart.
    p.gait_jitter_band_low_hz = std::min(p.gait_jitter_band_low_hz, p.gait_jitter_band_high_hz);
    std::string error;
    EXPECT_TRUE(p.IsValid(&error)) << error;
  }
}

// With CROWDRECON_UPDATE_DOCS=1 in the environment, the test writes the
// table into docs/model.md instead of failing (then review the diff).
TEST(ParameterTable, DocsMatchTheTable) {
  crowdrecon::testing::ExpectGeneratedSection("docs/model.md", "parameter-table", "engine::ModelParameterTableMarkdown()",
                                  ModelParameterTableMarkdown());
}

}  // namespace
}  // namespace crowdrecon::engine
