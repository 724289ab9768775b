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

// The colour of a recorded mark in every timeline figure (the fatal clog's,
// or an avalanche's and the others').
inline Color RecordedMarkColor(bool fatal) { return Color::Hex(fatal ? 0xb2182b : 0xe6550d); }

// The labels of the recorded marks within [t0, t1] above a panel whose top
// is at top_px, each at x_px(its time), in rows where they would overlap
// (LabelRows), in the marks' colours. For the run's and the ensemble's figure.
void DrawRecordedMarkLabels(Canvas& canvas, const std::vector<analysis::TimelineMark>& marks, double t0, double t1,
                            const std::function<double(double)>& x_px, double top_px);

}  // namespace crowdrecon::viz
