// Range checks of numeric option values. CLI::Range lets "nan" through (every
// comparison with NaN is false) and does not say what the value means; these
// reject NaN and infinity and name the range and unit. CLI11 reports a failed
// check as "--option: MESSAGE" and exits with status 105.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace crowdrecon::cli {

// A finite number in [min, max]; `unit` ("s", "m") is named in the message.
CLI::Validator NumberIn(double min, double max, const std::string& unit = "");

// A whole number in [min, max] (decimal digits, optional sign).
CLI::Validator IntegerIn(long long min, long long max);

}  // namespace crowdrecon::cli
