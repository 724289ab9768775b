// `crowdrecon report RUN... [--compare RUN...] -o DIR`: the injury-risk report
// of one run or an ensemble of seeds (issue 21; reports/report.hpp,
// docs/reports.md): report.html (self-contained), report.pdf and people.csv.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "crowdrecon/reports/report.hpp"
#include "crowdrecon/validate/validate.hpp"

namespace crowdrecon::cli {

namespace {

struct ReportArgs {
  std::vector<std::string> inputs, compare;
  std::string output;
  std::string label = "runs", compare_label = "comparison";
  reports::RiskOptions risk;
  bool no_pdf = false;
  std::string chromium;
  std::size_t table_rows = 40;
  double close_up_m = 12.0;
  std::string envelope_metric = "people_danger";
  double envelope_level = 0.0;
  std::string validation;  // a validation's results.json
  bool force = false, quiet = false;
};

void RunReport(const ReportArgs& args) {
  reports::ReportOptions o;
  for (const std::string& s : args.inputs) o.inputs.emplace_back(s);
  for (const std::string& s : args.compare) o.compare.emplace_back(s);
  o.label = args.label;
  o.compare_label = args.compare_label;
  o.output_dir = args.output;
  o.risk = args.risk;
  o.pdf = !args.no_pdf;
  o.chromium = args.chromium;
  o.table_rows = args.table_rows;
  o.close_up_m = args.close_up_m;
  o.envelope_metric = args.envelope_metric;
  o.envelope_level = args.envelope_level;
  o.force = args.force;
  if (!args.validation.empty()) {
    const validate::ValidationSummary v = validate::LoadValidationSummary(args.validation);
    o.validation_source = args.validation + ", judged by crowdrecon " + v.build;
    for (const validate::ProfileVerdicts& p : v.profiles)
      o.validation.push_back({p.name, p.tests, p.passed, p.failed});
  }
  o.command_line = CommandLine();
  if (!args.quiet) o.progress = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  const reports::ReportSummary summary = reports::WriteReport(o);
  std::printf("%s", summary.BriefReport().c_str());
}

}  // namespace

void RegisterReportCommand(CLI::App& app) {
  auto args = std::make_shared<ReportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "Injury-risk report of runs: each person's chest load from the contact forces, exposure against tolerance, the "
      "paper's safe / uncomfortable / danger zones with intervals over seeds, the force network at the worst moment, "
      "a comparison with a second set of runs; writes DIR/report.html, DIR/report.pdf and DIR/people.csv "
      "(docs/reports.md)");
  cmd->add_option("RUN", args->inputs,
                  "Run files, or folders of run files: one ensemble of seeds; or a sweep's folder alone: its "
                  "venue-design envelope")
      ->required();
  cmd->add_option("--compare", args->compare, "Run files or folders of a second ensemble to compare with");
  cmd->add_option("-o,--output", args->output, "Folder of the report")->required();
  cmd->add_option("--label", args->label, "Name of the first ensemble in the report");
  cmd->add_option("--validation", args->validation,
                  "A validation's results.json (crowdrecon validate): the methods page says which tests the runs' "
                  "profiles pass and fail");
  cmd->add_option("--compare-label", args->compare_label, "Name of the second ensemble");
  cmd->add_option("--f0", args->risk.f0_n, "F0 (N): the load above which a person is at risk (paper: 400 N)");
  cmd->add_option("--danger", args->risk.danger_n, "Lower edge of the danger zone (N; Hopkins et al.: 1112 N)");
  cmd->add_option("--tolerance-short", args->risk.lethal_short_n, "Tolerance point 1: load (N), with --tolerance-short-time");
  cmd->add_option("--tolerance-short-time", args->risk.lethal_short_s, "Tolerance point 1: time (s)");
  cmd->add_option("--tolerance-long", args->risk.lethal_long_n, "Tolerance point 2: load (N), with --tolerance-long-time");
  cmd->add_option("--tolerance-long-time", args->risk.lethal_long_s, "Tolerance point 2: time (s)");
  cmd->add_option("--smoothing", args->risk.smoothing_s, "Moving mean of the chest load (s)");
  cmd->add_option("--table-rows", args->table_rows, "People listed in the HTML table (all are in people.csv)")
      ->check(IntegerIn(0, 1000000));
  cmd->add_option("--close-up", args->close_up_m,
                  "Side (m) of the force network's close-up around the most loaded person at the worst moment, drawn "
                  "when the whole view is more than three times as large (default 12; 0: none)")
      ->check(NumberIn(0.0, 1e4, "m"));
  cmd->add_option("--envelope-metric", args->envelope_metric,
                  "For a sweep's folder: the risk column of its results the design envelope bounds (people_danger, "
                  "people_uncomfortable, people_beyond_tolerance, ...)");
  cmd->add_option("--envelope-level", args->envelope_level,
                  "For a sweep's folder: the envelope holds the cells whose median over seeds is at most this")
      ->check(NumberIn(0.0, 1e12));
  cmd->add_flag("--no-pdf", args->no_pdf, "Write no report.pdf (no Chromium needed)");
  cmd->add_option("--chromium", args->chromium, "The browser that prints report.pdf (default: chromium on PATH)");
  cmd->add_flag("-q,--quiet", args->quiet, "No progress lines");
  AddForceFlag(cmd, &args->force);
  cmd->callback([args] { RunReport(*args); });
}

}  // namespace crowdrecon::cli
