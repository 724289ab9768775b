// Helpers shared by the venue importers (not part of the public API).
#pragma once

#include <string>
#include <vector>

#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::geometry::internal {

// One connected part of a walkable area as found in an input file.
struct ImportedRegion {
  Ring outer;
  std::vector<Ring> holes;
};

// Builds a venue from imported regions: outer rings become the walkable area
// and closed walls ("boundary-N"), holes obstacles ("obstacle-N", whose edges
// are walls anyway). Then validates it, so that an import never writes a venue
// that `venue check` would reject.
Venue VenueFromRegions(std::vector<ImportedRegion> regions, const std::string& name,
                       const std::string& source, const std::string& origin);

}  // namespace crowdrecon::geometry::internal
