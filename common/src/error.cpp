#include "crowdrecon/common/error.hpp"

#include <cmath>
#include <cstdio>

namespace crowdrecon {

std::string FormatNumber(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds)) return "?";
  char buffer[32];
  const long total = std::lround(seconds);
  if (total >= 3600) std::snprintf(buffer, sizeof buffer, "%ldh%02ldm", total / 3600, (total / 60) % 60);
  else if (total >= 60) std::snprintf(buffer, sizeof buffer, "%ldm%02lds", total / 60, total % 60);
  else std::snprintf(buffer, sizeof buffer, "%lds", total);
  return buffer;
}

}  // namespace crowdrecon
