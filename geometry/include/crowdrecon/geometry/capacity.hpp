// Capacity of a venue at the density landmarks of crowd safety (persons per
// m^2 of walkable area), one source for every part of the tool that quotes
// them (venue check today; risk reports next). Sources: docs/venues.md and
// docs/decisions.md, "Facts from other sources".
#pragma once

#include <cmath>

#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::geometry {

// UK guidance after Hillsborough: the maximum for standing terraces.
inline constexpr double kGuidanceDensity_per_m2 = 4.7;
// Just beyond Fruin's 5.6 /m^2, where a moving crowd's forces become dangerous.
inline constexpr double kDangerDensity_per_m2 = 6.0;

struct Capacity {
  double area_m2 = 0.0;
  double at_guidance = 0.0;  // persons at kGuidanceDensity_per_m2 (whole persons)
  double at_danger = 0.0;    // persons at kDangerDensity_per_m2
};

inline Capacity VenueCapacity(const Venue& venue) {
  Capacity c;
  c.area_m2 = WalkableArea_m2(venue);
  c.at_guidance = std::floor(c.area_m2 * kGuidanceDensity_per_m2);
  c.at_danger = std::floor(c.area_m2 * kDangerDensity_per_m2);
  return c;
}

}  // namespace crowdrecon::geometry
