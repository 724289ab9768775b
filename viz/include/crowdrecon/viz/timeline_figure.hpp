// The figure of an incident timeline (issue 20): stacked panels over the
// run's time (clock time where the scenario gives one) of the density, the
// counter-flow's share, each direction's mean speed, the flow through the
// measurement line and the people waiting at the entries, with the
// avalanches and falls the run recorded and the marks of the real incident
// (the five avalanches and the fatal clog of the Madrid night) drawn across.
// PNG, SVG or PDF by the file's extension.
#pragma once

#include <filesystem>

#include "crowdrecon/analysis/timeline_series.hpp"

namespace crowdrecon::viz {

void DrawTimelineFigure(const analysis::TimelineSeries& series, const std::string& title,
                        const std::filesystem::path& file);

}  // namespace crowdrecon::viz
