// Sweep files (sweep::ParseSweep), from memory, then the list of runs. The
// scenario path resolves against tests/data/sweeps/, as for the seeds copied
// from there.
#include "crowdrecon/sweep/sweep_file.hpp"
#include "fuzz_harness.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  return fuzz::Parse([&] {
    const sweep::SweepSpec spec =
        sweep::ParseSweep(fuzz::Text(data, size), "fuzz-sweep.json", fuzz::SourceDir() / "tests/data/sweeps");
    (void)sweep::ExpandRuns(spec);
  });
}
