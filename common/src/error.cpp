#include "crowdrecon/common/error.hpp"

#include <cstdio>

namespace crowdrecon {

std::string FormatNumber(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

}  // namespace crowdrecon
