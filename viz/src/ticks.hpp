// Internal: axis ticks shared by viz's figures (timeline_figure.cpp, chart.cpp).
#pragma once

#include <cmath>

namespace crowdrecon::viz::detail {

// A "nice" tick step (1, 2, 2.5 or 5 times a power of ten) giving about
// `ticks` steps over `range`.
inline double NiceStep(double range, double ticks) {
  const double raw = range / ticks, p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10.0 * p;
}

}  // namespace crowdrecon::viz::detail
