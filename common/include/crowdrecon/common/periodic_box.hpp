// PeriodicBox: the box of a periodic run (the paper's hallway is periodic
// along its length). The engine wraps positions into [min_m, max_m) along
// each periodic axis; run files record the box (run value periodic_box), and
// analysis and drawing take differences of positions as minimum images.
#pragma once

#include <cmath>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon {

struct PeriodicBox {
  bool x = false, y = false;
  Vec2 min_m, max_m;  // only the periodic axes need an extent

  bool any() const { return x || y; }
  // The minimum-image representative of a difference of two positions. (The
  // engine's force computation has its own, faster form of the same rule:
  // engine/src/minimum_image.hpp.)
  Vec2 MinimumImage(Vec2 d_m) const {
    if (x) {
      const double l = max_m.x - min_m.x;
      d_m.x -= l * std::round(d_m.x / l);
    }
    if (y) {
      const double l = max_m.y - min_m.y;
      d_m.y -= l * std::round(d_m.y / l);
    }
    return d_m;
  }
};

}  // namespace crowdrecon
