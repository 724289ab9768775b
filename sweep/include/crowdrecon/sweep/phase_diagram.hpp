// Phase diagrams of a sweep, like the paper's Figure 5 ("Phase diagram of the
// simulations of counter-flow in the corridor ... lane formation (disks),
// avalanches (crosses) and clogging (squares)"), and heat maps of the run
// metrics, drawn from DIR/results.sqlite (results.hpp).
//
// One diagram per variant (and per value of any axis besides the diagram's
// two): x and y are the sweep's "diagram" axes (density and counter-flow
// fraction for the hallway). At each grid point the marker is the regime of
// the majority of the seeds; where the seeds disagree a ring around it shows
// every seed's regime, one segment per seed; where no regime has a majority
// (a tie) the ring is drawn with a "?" in place of the marker.
//
// Heat maps (mean over the seeds of each point, failed runs left out): mean
// speed along the desired direction, fraction of people stopped, fraction of
// the time the flow is stopped, lane order, avalanches per minute of the
// stationary stage, maximum load, fraction of person-frames above 400 N.
//
// Every picture is written as PNG and SVG; FIGDIR/index.html shows them all.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "crowdrecon/common/output_path.hpp"

namespace crowdrecon::sweep {

// A run's path through the diagram's plane (the Madrid night's density and
// counter-flow over time, like the arrow of the paper's Figure 5), drawn over
// every phase diagram as a line ending in an arrow, with labelled points.
struct PathOverlay {
  std::vector<std::pair<double, double>> points;  // (x, y) in the diagram's units, in time order
  std::vector<std::pair<std::size_t, std::string>> labels;  // index into points, text ("02:30")
  std::string caption;  // one line under the diagram ("path of madrid-night.sqlite, 5-s means")
  std::string note;     // a warning over the diagram (the run's model is not the diagram's), or ""
};

struct PhaseOptions {
  std::filesystem::path results;     // DIR, or DIR/results.sqlite
  std::filesystem::path output_dir;  // FIGDIR; "" = DIR/phase
  bool heat_maps = true;
  bool heat_map_svg = true;  // false: heat maps as PNG only (each ~200 kB as SVG), linked to their PNG
  PathOverlay path;          // drawn over the phase diagrams when it has points
  // Issue 39, candidate (d): each run's regime read as a single release
  // (results column regime_code_single_release: a clog of at least 5 s
  // released once is enough for avalanches; analysis/regime.hpp,
  // SingleReleaseReading) instead of the recurring reading (column regime).
  bool single_release_reading = false;
};

struct PhaseSummary {
  std::vector<std::filesystem::path> pictures;  // PNG and SVG files written
  std::filesystem::path index;                  // FIGDIR/index.html
  std::size_t diagrams = 0;                     // phase diagrams (PNG + SVG each)
  std::size_t heat_maps = 0;
  bool heat_map_svg = true;                     // heat maps written as SVG too
  std::size_t runs = 0;                         // rows read
  std::vector<std::string> notes;               // e.g. runs that failed, points without runs
  std::string BriefReport() const;
};

// Throws InputError if the results are missing or not a sweep's, or the sweep
// has fewer than two axes (no diagram).
PhaseSummary DrawPhaseDiagrams(const PhaseOptions& options);

// The folder the pictures go to: options.output_dir, or DIR/phase.
std::filesystem::path PhaseOutputFolder(const PhaseOptions& options);

// A previous phase folder: only phase-*.png/.svg, heat-*.png/.svg and
// index.html, which `phase -o` writes into (common/output_path.hpp).
OutputKind PhaseFolderOutput();

}  // namespace crowdrecon::sweep
