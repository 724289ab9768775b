// Run files (SQLite): everything scenario::RunFileReader reads (what
// `render` uses), then analysis::AnalyzeRun (what `analyze` and sweeps use).
#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/scenario/run_file.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const auto file = fuzz::WriteScratchFile(data, size, "sqlite");
  fuzz::Parse([&] {
    const scenario::RunFileReader reader(file);
    (void)reader.RunValue("status");
    (void)reader.fps();
    (void)reader.walkable_wkt();
    (void)reader.Shapes();
    (void)reader.PersonShapes();
    (void)reader.PersonGroups();
    (void)reader.Walls();
    for (const std::int64_t frame : reader.Frames()) (void)reader.Frame(frame);
  });
  return fuzz::Parse([&] { (void)analysis::AnalyzeRun(file); });
}
