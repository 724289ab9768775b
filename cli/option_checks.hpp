// What the commands check and say about their options and outputs before
// and after the work. Range checks of numeric option values: CLI::Range lets
// "nan" through (every comparison with NaN is false) and does not say what
// the value means; these reject NaN and infinity and name the range and unit.
// CLI11 reports a failed check as "--option: MESSAGE" and exits with status
// 105. Then picture names checked up front, pictures written atomically, and
// the note on an unfinished run.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace crowdrecon::cli {

// A finite number in [min, max]; `unit` ("s", "m") is named in the message.
CLI::Validator NumberIn(double min, double max, const std::string& unit = "");

// A whole number in [min, max] (decimal digits, optional sign).
CLI::Validator IntegerIn(long long min, long long max);

// Throws InputError naming the option unless `file` ends in .png, .svg or
// .pdf (the pictures viz::Canvas writes): checked before anything is written.
void CheckPictureName(const std::string& option, const std::string& file);

// Prints "note: RUN is unfinished (...)" when a run file's status is not
// "complete" (issue 40: what is drawn, exported or observed from a killed or
// interrupted run says so); nothing for a finished run or a file that is no run.
void SayIfUnfinished(const std::string& run_file);

// --log-every SECONDS of a long command (simulate, sweep): where stderr is
// not a terminal (a log, under nohup or a batch system), a progress line of
// its own this often; 0 never. Returns the interval the command uses: 0 with
// -q or on a terminal (which gets the line rewritten in place instead).
constexpr double kLogEveryDefaultS = 600.0;
void AddLogEveryOption(CLI::App* cmd, double* seconds);
double LogProgressEvery(double seconds, bool quiet);

}  // namespace crowdrecon::cli
