// The run-loop systems' part of a checkpoint (RUN.sqlite.checkpoint after
// the engine state: each system's name and state: the timeline's queues,
// pending events, exits, fall filters and avalanche detector, the settle
// detector), as `crowdrecon simulate --resume` reads it, through
// scenario::RunScenario. Once per process the harness runs the open-hallway
// timeline of the tests (tests/data/scenarios/timeline-hallway.json) to 0.5 s
// and keeps its run file and the checkpoint's header and engine state; each
// input is then a systems part put behind them, and the run is resumed for
// 0.1 s. The input is refused (InputError), or the run resumes and stops
// cleanly. The seed is the systems part of that checkpoint itself. The
// engine state has its own harness (fuzz_checkpoint).
#include <cstring>

#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/output_path.hpp"

#include "crowdrecon/scenario/runner.hpp"
#include "crowdrecon/scenario/scenario.hpp"
#include "fuzz_harness.hpp"

namespace {

using crowdrecon::scenario::Scenario;

struct Saved {
  Scenario scenario;
  std::string run_file;    // the interrupted run's file, bytes
  std::string checkpoint;  // its checkpoint up to the end of the engine state
};

// The run file: the scratch file that WriteScratchFile writes for "sqlite".
const std::filesystem::path& RunFile() {
  static const std::filesystem::path file = crowdrecon::fuzz::ScratchDir() / "input.sqlite";
  return file;
}

const Saved& Interrupted() {
  static const Saved saved = [] {
    Saved s{crowdrecon::scenario::LoadScenario(crowdrecon::fuzz::SourceDir() /
                                               "tests/data/scenarios/timeline-hallway.json"),
            {}, {}};
    crowdrecon::scenario::RunOptions options;
    options.output = RunFile();
    options.stop_after_s = 0.5;
    crowdrecon::scenario::RunScenario(s.scenario, options);
    s.run_file = crowdrecon::ReadInputFile(RunFile(), "run file");
    const std::string checkpoint = crowdrecon::ReadInputFile(crowdrecon::scenario::CheckpointPath(RunFile()), "checkpoint");
    // magic, fingerprint, last frame, then the engine state as a length and bytes
    std::uint64_t length = 0;
    if (checkpoint.size() < 32) std::abort();
    std::memcpy(&length, checkpoint.data() + 24, sizeof length);
    if (length > checkpoint.size() - 32) std::abort();
    s.checkpoint = checkpoint.substr(0, 32 + length);
    return s;
  }();
  return saved;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const Saved& saved = Interrupted();
  // The interrupted run's file as it was, then its checkpoint with this input as the systems' part.
  fuzz::WriteScratchFile(reinterpret_cast<const std::uint8_t*>(saved.run_file.data()), saved.run_file.size(), "sqlite");
  WriteFileAtomically(scenario::CheckpointPath(RunFile()), saved.checkpoint + fuzz::Text(data, size));
  return fuzz::Parse([&] {
    scenario::RunOptions options;
    options.output = RunFile();
    options.resume = true;
    options.stop_after_s = 0.6;
    (void)scenario::RunScenario(saved.scenario, options);
  });
}
