#include "option_checks.hpp"

#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/viz/canvas.hpp"

namespace crowdrecon::cli {

CLI::Validator NumberIn(double min, double max, const std::string& unit) {
  const std::string range = "[" + FormatNumber(min) + ", " + FormatNumber(max) + "]" + (unit.empty() ? "" : " " + unit);
  return CLI::Validator(
      [min, max, range](std::string& input) -> std::string {
        const char* begin = input.c_str();
        char* end = nullptr;
        const double v = std::strtod(begin, &end);
        if (input.empty() || end != begin + input.size())
          return "\"" + ShortText(input) + "\" is not a number; expected a number in " + range;
        if (!std::isfinite(v)) return "value " + ShortText(input) + " is not finite; expected a number in " + range;
        if (v < min || v > max) return "value " + ShortText(input) + " is out of range; expected a number in " + range;
        return "";
      },
      "NUMBER in " + range);
}

CLI::Validator IntegerIn(long long min, long long max) {
  const std::string range = "[" + std::to_string(min) + ", " + std::to_string(max) + "]";
  return CLI::Validator(
      [min, max, range](std::string& input) -> std::string {
        long long v = 0;
        const char* begin = input.data() + (input.starts_with('+') ? 1 : 0);
        const auto [end, error] = std::from_chars(begin, input.data() + input.size(), v);
        if (error == std::errc::result_out_of_range)
          return "value " + ShortText(input) + " is out of range; expected a whole number in " + range;
        if (error != std::errc{} || end != input.data() + input.size())
          return "\"" + ShortText(input) + "\" is not a whole number; expected a whole number in " + range;
        if (v < min || v > max) return "value " + input + " is out of range; expected a whole number in " + range;
        return "";
      },
      "INTEGER in " + range);
}

void CheckPictureName(const std::string& option, const std::string& file) {
  if (const std::string problem = viz::PictureFormatProblem(file); !problem.empty())
    throw InputError(option + " " + file + ": " + problem);
}

void SayIfUnfinished(const std::string& run_file) {
  if (!runfile::IsRunFile(run_file)) return;
  const std::string note = runfile::RunFileReader(run_file).UnfinishedNote();
  if (!note.empty()) std::printf("note: %s\n", note.c_str());
}

void AddLogEveryOption(CLI::App* cmd, double* seconds) {
  cmd->add_option("--log-every", *seconds,
                  "Where stderr is not a terminal (a log): a progress line this often, in wall seconds (0: never)")
      ->check(NumberIn(0.0, 1e7, "s"))
      ->capture_default_str();
}

double LogProgressEvery(double seconds, bool quiet) { return quiet || isatty(STDERR_FILENO) ? 0.0 : seconds; }

}  // namespace crowdrecon::cli
