// Validation tests and profiles (validate::ParseValidationTest, ParseProfile),
// measures' statistics files and a validation's results as other outputs
// read them (ParseValidationSummary), from memory. Paths resolve against
// venues/validation/tests/, as for the seeds copied from there. The input
// is tried as each of the four.
#include "crowdrecon/validate/validate.hpp"
#include "crowdrecon/validate/validation_test.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const std::string text = fuzz::Text(data, size);
  const auto dir = fuzz::SourceDir() / "venues/validation/tests";
  fuzz::Parse([&] {
    const validate::ValidationTest t = validate::ParseValidationTest(text, "fuzz-test.json", dir);
    for (const validate::Criterion& c : t.criteria) (void)c.Describe();
  });
  fuzz::Parse([&] { (void)validate::ParseProfile(text, "fuzz-profile.json", dir); });
  fuzz::Parse([&] { (void)validate::StatisticsFromJson(text, "fuzz-statistics.json"); });
  return fuzz::Parse([&] { (void)validate::ParseValidationSummary(text, "fuzz-results.json"); });
}
