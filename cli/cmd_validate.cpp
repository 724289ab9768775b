// `crowdrecon validate [SUITE] --profile P [--profile Q] -o DIR`: the
// validation suite on one or two model profiles (validate/, docs/validation.md).
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/validate/validate.hpp"

namespace crowdrecon::cli {

namespace {

// The suite and the profile of the project's reconstructions, found from
// the program's own tree when run from a checkout (the defaults).
constexpr const char* kDefaultSuite = "venues/validation";
constexpr const char* kDefaultProfile = "venues/profiles/validated.json";

struct ValidateArgs {
  std::string suite = kDefaultSuite;
  std::vector<std::string> profiles;
  std::string output;
  std::vector<std::string> tests;
  bool quick = false;
  int seeds = 0;
  int jobs = 0;
  bool no_pdf = false;
  std::string chromium;
  bool quiet = false;
  bool force = false;
};

int RunValidateCommand(const ValidateArgs& args) {
  validate::ValidateOptions o;
  o.suite = args.suite;
  for (const std::string& p : args.profiles.empty() ? std::vector<std::string>{kDefaultProfile} : args.profiles)
    o.profiles.push_back(p);
  o.output_dir = args.output;
  o.only = args.tests;
  o.quick = args.quick;
  o.seeds = args.seeds;
  o.jobs = args.jobs;
  o.pdf = !args.no_pdf;
  o.chromium = args.chromium;
  o.show_progress = !args.quiet && isatty(STDERR_FILENO);
  if (!args.quiet) o.progress = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  std::vector<NamedInput> inputs = {{"the suite", o.suite}};
  for (const auto& p : o.profiles) inputs.push_back({"the profile", p});
  if (std::string why; !o.IsValid(&why)) throw InputError(why);
  CheckOutputs({{"-o", o.output_dir, validate::ValidationFolderOutput()}}, inputs, args.force);
  const validate::ValidateSummary s = validate::RunValidation(o);
  std::printf("%s", s.BriefReport().c_str());
  return s.ExitStatus();
}

}  // namespace

void RegisterValidateCommand(CLI::App& app) {
  auto args = std::make_shared<ValidateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "validate",
      "Run the validation suite (the standards' verification tests and the experiments, venues/validation) on one or "
      "two model profiles and write its report (report.html, report.pdf, results.json, results.csv) into DIR; runs "
      "again on the same DIR reuse the runs done; exit 1 when a judged criterion fails (docs/validation.md)");
  cmd->add_option("SUITE", args->suite, "The suite folder (default venues/validation) or one test file");
  cmd->add_option("--profile", args->profiles,
                  "A profile file (model and body blocks; default venues/profiles/validated.json, the reconstructions' crowd); give two "
                  "to see them side by side")
      ->allow_extra_args(false);
  cmd->add_option("-o,--output", args->output, "The validation's folder DIR")->required();
  cmd->add_option("--test", args->tests, "Only this test (by id; may be repeated)")->allow_extra_args(false);
  cmd->add_flag("--quick", args->quick, "Only the tests marked quick (the subset make test runs)");
  cmd->add_option("--seeds", args->seeds,
                  "At most this many seeds per test (a trial; the report says how many ran); 0: each test's own")
      ->check(IntegerIn(0, 1000));
  cmd->add_option("--jobs", args->jobs, "Runs at a time (default: all cores); results do not depend on it")
      ->check(IntegerIn(0, 4096));
  cmd->add_flag("--no-pdf", args->no_pdf, "No report.pdf (no browser needed)");
  cmd->add_option("--chromium", args->chromium, "The browser that prints report.pdf (default: chromium on PATH)");
  AddForceFlag(cmd, &args->force);
  cmd->add_flag("-q,--quiet", args->quiet, "No progress lines");
  cmd->callback([args] {
    const int rc = RunValidateCommand(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace crowdrecon::cli
