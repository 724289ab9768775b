// Picture of a venue: walkable area, walls, obstacles, exits, entries,
// measurement areas and lines, a few arrows of a navigation field, a scale bar
// and a title. Used by `crowdrecon venue check --picture`.
#pragma once

#include <filesystem>
#include <string>

#include "crowdrecon/geometry/navigation.hpp"
#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::viz {

struct VenuePictureOptions {
  // Length of the longer side of the venue in the picture (pixels).
  double max_size_px = 1400.0;
  std::string title;  // empty: the venue's name
  // Arrows of this field on a coarse grid over the walkable area (none if null),
  // with `field_label` in the legend (e.g. "direction to exit \"main\"").
  const geometry::NavigationField* field = nullptr;
  std::string field_label;
};

// Writes the picture; the format follows the extension (.png, .svg, .pdf).
// Throws InputError if the file cannot be written.
void DrawVenue(const geometry::Venue& venue, const std::filesystem::path& file,
               const VenuePictureOptions& options = {});

}  // namespace crowdrecon::viz
