// `crowdrecon analyze`: time series, summary metrics and the regime (lanes /
// avalanches / clogging) of a run (analysis/run_analysis.hpp, docs/analysis.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/scenario/settle.hpp"

namespace crowdrecon::cli {

namespace {

struct AnalyzeArgs {
  std::string run_file;
  std::string json;
  std::string line;
  bool write = false;
  bool full = false;
  bool digest = false;
  bool force = false;
  bool settle_check = false;
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

// Replays the run's frames through the check of run.stop_when_settled
// (scenario/settle.hpp; the run's own options, else the defaults): when a run with it would have
// stopped, and the verdict of the run up to then against the whole run's.
// Checks the early-stop criteria on runs simulated to their full length.
void SettleCheck(const std::string& file, const analysis::RunAnalysis& whole,
                 const analysis::AnalysisOptions& options) {
  const runfile::RunFileReader run(file);
  const std::vector<runfile::Person> people = run.People();
  const std::size_t n = people.size();
  std::vector<std::uint32_t> group(n);
  for (std::size_t i = 0; i < n; ++i) group[i] = people[i].group;
  const scenario::SettleOptions settle =
      scenario::SettleOptionsOfScenario(run.RunValue("scenario"), file + ": run value scenario");
  scenario::SettleDetector detector(settle, group, whole.group_name, whole.box);
  std::vector<Vec2> position(n), velocity(n), direction(n);
  std::vector<double> load(n, 0.0);
  std::vector<char> present(n, 0);
  for (std::size_t i = 0; i < n; ++i) direction[i] = whole.group_direction[group[i]];
  const analysis::MetricSeries& series = whole.series;
  runfile::PersonFrameStream stream = run.PersonFrames(series.frame.back());
  runfile::PersonFrame rows;
  std::size_t k = 0;
  std::string reason;
  while (reason.empty() && stream.Next(&rows)) {
    while (k < series.frame.size() && series.frame[k] < rows.frame) ++k;
    if (k == series.frame.size() || series.frame[k] != rows.frame) continue;
    std::fill(present.begin(), present.end(), 0);
    for (std::size_t r = 0; r < rows.person.size(); ++r) {
      const std::size_t i = rows.person[r];
      if (i >= n) continue;
      present[i] = 1;
      position[i] = rows.position_m[r];
      velocity[i] = rows.velocity_m_per_s[r];
      load[i] = rows.load_n[r];
    }
    reason = detector.Add({series.time_s[k], &position, &velocity, &direction, &load, &present});
  }
  const std::string whole_verdict = std::string(analysis::ToString(whole.regime.regime)) + " (" +
                                    FormatNumber(whole.duration_s) + " s)";
  if (reason.empty()) {
    std::printf("settle check: does not settle; verdict of the whole run %s\n", whole_verdict.c_str());
    return;
  }
  // The verdict of the frames up to the stop, as the analysis of the
  // stopped run gives it.
  const std::size_t end = k + 1;
  const auto head = [end](const std::vector<double>& v) { return std::vector<double>(v.begin(), v.begin() + end); };
  std::vector<double> crowd = head(series.mean_speed_m_per_s);
  for (double& v : crowd)
    if (std::isnan(v)) v = 0.0;
  std::vector<analysis::DirectionSeries> directions;
  for (std::size_t g = 0; g < whole.groups; ++g)
    if (whole.group_people[g] > 0)
      directions.push_back({whole.group_name[g], whole.group_people[g], head(series.group_mean_speed_m_per_s[g])});
  const analysis::RegimeResult early = analysis::ClassifyByDirection(
      head(series.time_s), crowd, directions, head(series.lane_order), options.regime);
  std::printf("settle check: %s\nsettle check: verdict at the stop %s (%s s), of the whole run %s: %s\n",
              reason.c_str(), analysis::ToString(early.regime), FormatNumber(series.time_s[k] - series.time_s[0]).c_str(),
              whole_verdict.c_str(), early.regime == whole.regime.regime ? "same" : "DIFFERENT");
}

void RunAnalyze(const AnalyzeArgs& args) {
  if (args.digest) {
    // Only the digest: what "a resumed run is the same run" means, checkable.
    std::printf("tables digest (SHA-256 of every per-frame table, row by row): %s\n",
                runfile::RunFileReader(args.run_file).TablesDigest().c_str());
    return;
  }
  CheckOutputs({{"--json", args.json, analysis::AnalysisJsonOutput()}}, {{"the run file", args.run_file}}, args.force);
  analysis::AnalysisOptions options;
  if (args.transient_s >= 0.0) options.regime.transient_s = args.transient_s;
  if (!args.line.empty()) options.line = ParseLine(args.line);
  const analysis::RunAnalysis result = analysis::AnalyzeRun(args.run_file, options);
  std::printf("%s", args.full ? result.FullReport().c_str() : result.BriefReport().c_str());
  if (args.settle_check) SettleCheck(args.run_file, result, options);
  if (!args.json.empty()) {
    WriteFileAtomically(args.json, result.ToJson() + "\n");
    std::printf("json: %s\n", args.json.c_str());
  }
  if (args.write) {
    const runfile::RunFileLock lock(args.run_file);  // not into a run another process is writing
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
  CLI::Option* json = cmd->add_option("--json", args->json, "also write everything (summary, avalanches, series) as JSON to this file");
  CLI::Option* write = cmd->add_flag("--write", args->write,
                "store the results in the run file (tables metric_series, metric_summary, metric_avalanche, "
                "metric_load_histogram; run values regime, regime_reason)");
  AddForceFlag(cmd, &args->force);
  CLI::Option* full = cmd->add_flag("--full", args->full, "print the full report (set-up, every avalanche, load histogram)");
  CLI::Option* digest = cmd->add_flag("--digest", args->digest,
                "print only the SHA-256 of the run's per-frame tables: equal for a run and the same run resumed "
                "from a checkpoint, or run on another number of threads (the file's own bytes may differ); "
                "nothing else (it excludes the analysis's options)");
  CLI::Option* settle = cmd->add_flag("--settle-check", args->settle_check,
                "replay the run through the check of run.stop_when_settled: when it would have stopped, and "
                "whether the verdict then is the whole run's (docs/analysis.md)");
  CLI::Option* transient =
      cmd->add_option("--transient", args->transient_s, "start-up time left out of stationary averages, s (default 10)")
          ->check(NumberIn(0.0, 1e6, "s"));
  CLI::Option* line = cmd->add_option("--line", args->line,
                                      "measurement line X1,Y1,X2,Y2 in metres (default: the venue's first measurement line)");
  // --digest prints the digest alone: an analysis option beside it would be
  // dropped without a word (issue 65, the adversarial pass's P06, P11, P12).
  for (CLI::Option* option : {json, write, full, settle, transient, line}) digest->excludes(option);
  cmd->callback([args] { RunAnalyze(*args); });
}

}  // namespace crowdrecon::cli
