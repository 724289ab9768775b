// The figure of an incident timeline (issue 20): stacked panels over the
// run's time (clock time where the scenario gives one) of the density, the
// counter-flow's share, each direction's mean speed, the flow through the
// measurement line and the people waiting at the entries, with the
// avalanches and falls the run recorded and the marks of the real incident
// (the five avalanches and the fatal clog of the Madrid night) drawn across.
// PNG, SVG or PDF by the file's extension.
#pragma once

#include <filesystem>
#include <functional>
#include <vector>

#include "crowdrecon/analysis/timeline_series.hpp"
#include "crowdrecon/viz/canvas.hpp"

namespace crowdrecon::viz {

void DrawTimelineFigure(const analysis::TimelineSeries& series, const std::string& title,
                        const std::filesystem::path& file);

// How a recorded mark of a kind ("avalanche", "fatal", "other": the
// scenario's timeline.recorded[].kind) is drawn in every timeline figure,
// and what the legend calls it. Each kind its own, so that a mark that is
// not an avalanche (a police call, a rescue team) is not read as one.
struct RecordedMarkStyle {
  Color color;
  double width_px = 1.6;
  bool dashed = true;
  std::string legend;  // "recorded avalanche", ...
};
RecordedMarkStyle RecordedMarkStyleOf(const std::string& kind);
// The kinds of the marks within [t0, t1] (those a figure of that time
// shows), each once, in the legend's order (avalanche, fatal, other).
std::vector<std::string> RecordedMarkKinds(const std::vector<analysis::TimelineMark>& marks, double t0, double t1);

// The labels of the recorded marks within [t0, t1] above a panel whose top
// is at top_px, each at x_px(its time), in rows where they would overlap
// (LabelRows), in the marks' colours. For the run's and the ensemble's figure.
void DrawRecordedMarkLabels(Canvas& canvas, const std::vector<analysis::TimelineMark>& marks, double t0, double t1,
                            const std::function<double(double)>& x_px, double top_px);

}  // namespace crowdrecon::viz
