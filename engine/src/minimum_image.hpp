// The minimum-image difference along one periodic axis (Simulation::Separation),
// shared as source with the CUDA force computation, which places each pair's
// second body in the first one's periodic image the same way.
#pragma once

#include <cmath>

#include "host_device.hpp"

namespace crowdrecon::engine::detail {

// d, a difference of coordinates along an axis of period `period`, brought
// within half a period. Rounding (a library call without SSE4.1) only when
// the difference is longer than half a period: the same result, far fewer
// calls.
CROWDRECON_HOST_DEVICE CROWDRECON_INLINE double MinimumImage(double d, double period) {
  return std::abs(d) > period / 2.0 ? d - period * std::nearbyint(d / period) : d;
}

}  // namespace crowdrecon::engine::detail
