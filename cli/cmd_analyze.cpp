// `crowdrecon analyze`: time series, summary metrics and the regime (lanes /
// avalanches / clogging) of a run (analysis/run_analysis.hpp, docs/analysis.md).
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"

namespace crowdrecon::cli {

namespace {

struct AnalyzeArgs {
  std::string run_file;
  std::string json;
  std::string line;
  bool write = false;
  bool full = false;
  bool force = false;
  double transient_s = -1.0;
};

// "X1,Y1,X2,Y2" in metres.
analysis::MeasurementLine ParseLine(const std::string& text) {
  std::istringstream in(text);
  double v[4];
  char comma = 0;
  for (int i = 0; i < 4; ++i) {
    if (!(in >> v[i])) throw InputError("--line \"" + text + "\": expected four numbers X1,Y1,X2,Y2 (m)");
    if (i < 3 && !(in >> comma && comma == ','))
      throw InputError("--line \"" + text + "\": expected four numbers X1,Y1,X2,Y2 (m)");
  }
  if (in >> comma) throw InputError("--line \"" + text + "\": expected four numbers X1,Y1,X2,Y2 (m)");
  return {{v[0], v[1]}, {v[2], v[3]}};
}

void RunAnalyze(const AnalyzeArgs& args) {
  CheckOutputs({{"--json", args.json, analysis::AnalysisJsonOutput()}}, {{"the run file", args.run_file}}, args.force);
  analysis::AnalysisOptions options;
  if (args.transient_s >= 0.0) options.regime.transient_s = args.transient_s;
  if (!args.line.empty()) options.line = ParseLine(args.line);
  const analysis::RunAnalysis result = analysis::AnalyzeRun(args.run_file, options);
  std::printf("%s", args.full ? result.FullReport().c_str() : result.BriefReport().c_str());
  if (!args.json.empty()) {
    WriteFileAtomically(args.json, result.ToJson() + "\n");
    std::printf("json: %s\n", args.json.c_str());
  }
  if (args.write) {
    analysis::WriteAnalysis(args.run_file, result, options);
    std::printf("wrote metric_series, metric_summary, metric_avalanche, metric_load_histogram and run.regime into %s\n",
                args.run_file.c_str());
  }
}

}  // namespace

void RegisterAnalyzeCommand(CLI::App& app) {
  auto args = std::make_shared<AnalyzeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "analyze", "Metrics of a run (flow, speed, lanes, stops, avalanches, loads) and its regime: lanes, avalanches "
                 "or clogging (docs/analysis.md)");
  cmd->add_option("RUN", args->run_file, "run file (.sqlite) written by `crowdrecon simulate`")->required();
  cmd->add_option("--json", args->json, "also write everything (summary, avalanches, series) as JSON to this file");
  cmd->add_flag("--write", args->write,
                "store the results in the run file (tables metric_series, metric_summary, metric_avalanche, "
                "metric_load_histogram; run values regime, regime_reason)");
  AddForceFlag(cmd, &args->force);
  cmd->add_flag("--full", args->full, "print the full report (set-up, every avalanche, load histogram)");
  cmd->add_option("--transient", args->transient_s, "start-up time left out of stationary averages, s (default 10)")
      ->check(NumberIn(0.0, 1e6, "s"));
  cmd->add_option("--line", args->line,
                  "measurement line X1,Y1,X2,Y2 in metres (default: the venue's first measurement line)");
  cmd->callback([args] { RunAnalyze(*args); });
}

}  // namespace crowdrecon::cli
