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

// The step of a timeline's time axis over `span_s` seconds of the run: whole
// minutes and their multiples for long runs (at most 12 ticks), 10 s or 60 s
// below ten minutes, and below a minute a nice step of about six ticks
// (issue 65, T08: a 6 s run had one tick, "0 s").
inline double TimeAxisTick(double span_s) {
  double tick = 60.0;
  for (double c : {60.0, 300.0, 600.0, 900.0, 1800.0, 3600.0})
    if (span_s / c <= 12.0) {
      tick = c;
      break;
    }
  if (span_s < 600.0) tick = span_s / 6.0 > 30.0 ? 60.0 : 10.0;
  if (span_s < 60.0 && span_s > 0.0) tick = NiceStep(span_s, 6.0);
  return tick;
}

}  // namespace crowdrecon::viz::detail
