// A run's summary for an ensemble (reports::ParseEnsembleSummary: what
// `timeline --summaries` writes and `timeline SUMMARY.json ...` reads), from
// memory, then scored as an ensemble of one.
#include "crowdrecon/reports/ensemble.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const std::string text = fuzz::Text(data, size);
  return fuzz::Parse([&] {
    const reports::EnsembleRunSummary s = reports::ParseEnsembleSummary(text, "fuzz-summary.json");
    const reports::EnsembleScore score = reports::ScoreEnsemble({s.run}, s.options);
    (void)score.Markdown();
    (void)score.Csv();
  });
}
