// The wall clock's time of day, for progress lines in a log (a long run or
// sweep whose stderr is a file: which line was written when).
#pragma once

#include <string>

namespace crowdrecon {

// The local time of day, "HH:MM:SS".
std::string WallClockNow();

}  // namespace crowdrecon
