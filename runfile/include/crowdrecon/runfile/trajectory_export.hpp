// ExportTrajectories: a run's trajectories as a plain JuPedSim trajectory
// file (version 2), for tools that know nothing of periodic boxes (PedPy,
// JuPedSim's own viewers, a spreadsheet).
//
// A periodic run stores positions wrapped into its box (the hallway repeats
// every 12 m along x): a person walking through the seam at x = 12 reappears
// at x = 0 in the next frame. A tool unaware of that sees a 12 m jump in one
// frame, i.e. a speed of 120 m/s at 10 frames/s and a crossing of every line
// in between. The export therefore cuts each person's trajectory where a step
// crosses a seam (its raw displacement differs from its minimum image,
// PeriodicBox::MinimumImage) and gives every piece an id of its own, so that
// no id ever jumps. Within a piece the positions are the run's, unchanged:
// finite differences give the run's own speeds, and crossings of a line away
// from the seams are the ones `crowdrecon analyze` counts.
//
// The file written:
//   trajectory_data(frame, id, pos_x, pos_y, ori_x, ori_y)   one row per row of the run's
//   metadata(key, value)   version = 2, fps, xmin, xmax, ymin, ymax (JuPedSim), and
//                          crowdrecon_export = 1 (this format), crowdrecon_source (the
//                          run file's name), crowdrecon_periodic (the run's periodic box
//                          as JSON; only for a periodic run), crowdrecon_split_at_seams
//                          (the number of cuts), crowdrecon_people, crowdrecon_tracks
//   geometry(hash, wkt)    the run's walkable area
//   frame_data(frame, geometry_hash)   every frame of the run
//   crowdrecon_track(id INTEGER PRIMARY KEY, person, part, first_frame, last_frame)
//                          each id's person (the run's 1-based id) and piece (0, 1, ...)
// Ids: a person's first piece keeps the person's id; each later piece gets the
// next id above the run's largest person id, in the order the pieces begin.
// A run that is not periodic is copied with its ids (every person one piece).
// Version 2, as the run file: PedPy rejects the walkable area of version-3 files.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/runfile/run_file.hpp"

namespace crowdrecon::runfile {

struct ExportSummary {
  std::int64_t frames = 0;
  std::int64_t rows = 0;     // trajectory rows written (= the run's)
  std::int64_t people = 0;   // people with at least one row
  std::int64_t tracks = 0;   // ids written (people + splits)
  std::int64_t splits = 0;   // steps across a seam of the periodic box
  PeriodicBox box;           // the run's
  // Stale "-journal", "-wal" or "-shm" files of a killed writer that were
  // beside `file` and were removed (they would have been applied to it).
  std::vector<std::string> removed_sidecars;
  std::vector<std::string> removed_partials;  // of exports to this file that were killed
};

// Writes the export of `run` to `file`: into a temporary file beside it
// (common/output_path.hpp, PartialPath) renamed over `file` when complete, so
// that an error or a kill never leaves a partial file under the final name.
// The caller has checked `file` (CheckOutputs). The run is read frame by
// frame (RunFileReader::PersonFrames): memory holds one frame and a few
// numbers per person, whatever the run's length.
ExportSummary ExportTrajectories(const RunFileReader& run, const std::filesystem::path& file);

// A previous export (a SQLite file whose metadata has crowdrecon_export),
// which `export -o` may replace.
OutputKind TrajectoryExportOutput();

}  // namespace crowdrecon::runfile
