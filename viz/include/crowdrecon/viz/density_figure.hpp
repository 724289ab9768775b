// Density maps of a run (analysis/density_map.hpp) as one figure: a panel per
// time, persons per square metre in colour over the venue's walls and exits,
// one colour scale for every panel. PNG, SVG or PDF by the file's extension.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "crowdrecon/analysis/density_map.hpp"
#include "crowdrecon/analysis/timeline_series.hpp"
#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::viz {

// Times are written as the incident's clock times when the clock has a start.
// Throws InputError if the file cannot be written or there is no map.
void DrawDensityMaps(const std::vector<analysis::DensityMap>& maps, const geometry::Venue& venue,
                     const std::string& title, const analysis::RunClock& clock, const std::filesystem::path& file);

}  // namespace crowdrecon::viz
