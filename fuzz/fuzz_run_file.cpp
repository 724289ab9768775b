// Run files (SQLite): everything runfile::RunFileReader reads (what `render`,
// reports and calibration use), then analysis::AnalyzeRun (what `analyze` and
// sweeps use).
#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const auto file = fuzz::WriteScratchFile(data, size, "sqlite");
  fuzz::Parse([&] {
    const runfile::RunFileReader reader(file);
    (void)reader.RunValue("status");
    (void)reader.fps();
    (void)reader.walkable_wkt();
    (void)reader.Shapes();
    (void)reader.PersonShapes();
    (void)reader.PersonGroups();
    (void)reader.Walls();
    (void)reader.People();
    (void)reader.periodic_box();
    (void)reader.venue_json();
    (void)reader.Events();
    (void)reader.GroupVelocitySums();
    (void)reader.FrameTimes();
    for (const std::int64_t frame : reader.Frames()) (void)reader.Frame(frame);
    runfile::PersonFrameStream stream = reader.PersonFrames(runfile::run_limits::kFrame);
    runfile::PersonFrame rows;
    while (stream.Next(&rows)) {
    }
  });
  return fuzz::Parse([&] { (void)analysis::AnalyzeRun(file); });
}
