// WriteRunTables: a run as one run file with tables (run.frames "tables"),
// whatever its storage: its people's packed frames unpacked into
// trajectory_data, person_state and person_load, a run in segments joined,
// rows of contacts a later segment dropped left out. For scripts that read
// the tables themselves (the studies' Python, PedPy on a run file): the file
// is the run written with tables in one go, row for row (`analyze --digest`
// gives the same digest).
#pragma once

#include <cstdint>
#include <filesystem>

#include "crowdrecon/runfile/run_file.hpp"

namespace crowdrecon::runfile {

struct TablesExportSummary {
  std::int64_t segments = 0;
  std::int64_t frames = 0;  // frames unpacked
  std::int64_t rows = 0;    // people's rows unpacked
};

// Writes `run` to `file` (through a partial file renamed when whole; the
// caller has checked that `file` may be written: CheckOutputs).
TablesExportSummary WriteRunTables(const RunFileReader& run, const std::filesystem::path& file);

// A segment's head (issue 66: a long run carried to another machine): the
// run file `segment` (a segment stopped at its checkpoint) with its header
// (scenario, venue, shapes, people, walls, storage, run values) and only its
// last frame's time, every per-frame row left out, marked with the run
// value segment_head: what `simulate --continue-from` needs beside the
// checkpoint to write the next segment anywhere, small enough to keep in a
// repository. No tool reads a head as a run (RunFileReader refuses it: its
// frames are not there); put the whole segment in its place to read the
// chain. Written through a partial file renamed when whole (the caller has
// checked that `file` may be written).
void WriteSegmentHead(const std::filesystem::path& segment, const std::filesystem::path& file);

}  // namespace crowdrecon::runfile
