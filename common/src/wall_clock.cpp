#include "crowdrecon/common/wall_clock.hpp"

#include <ctime>

namespace crowdrecon {

std::string WallClockNow() {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char buffer[16];
  std::strftime(buffer, sizeof buffer, "%H:%M:%S", &local);
  return buffer;
}

}  // namespace crowdrecon
