// crowdrecon simulate SCENARIO -o RUN.sqlite [--profile NAME] [--threads N] [--device cpu|cuda] [--resume | --branch-from RUN | --continue-from RUN]
#include <unistd.h>

#include <cstdio>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/scenario/runner.hpp"

namespace crowdrecon::cli {

namespace {

struct SimulateArgs {
  std::string scenario;
  std::string output;
  std::string profile;  // --profile: another model profile than the scenario's
  int threads = 0;
  std::string device = "cpu";
  bool resume = false;
  std::string branch_from;
  std::string continue_from;
  bool force = false;
  bool quiet = false;
  double log_every_s = kLogEveryDefaultS;  // --log-every
  bool fixed_threads = false;
  double stop_after_s = -1.0;
};

int RunSimulate(const SimulateArgs& args) {
  const scenario::Scenario sc = scenario::LoadScenario(args.scenario, args.profile);
  // A resume of what is no run (a run file cut short, another program's
  // file) is said as such, not offered --force (issue 65, R07).
  if (std::error_code ec; args.resume && std::filesystem::exists(args.output, ec) && !runfile::IsRunFile(args.output))
    throw InputError(args.output + ": nothing to resume: it is " + runfile::DescribeNonRunFile(args.output) +
                     ", not a crowdrecon run file; run the scenario again without --resume (--force replaces the file)");
  CheckOutputs({{"-o", args.output, runfile::RunFileOutput()}},
               {{"the scenario", sc.file},
                {"the venue", sc.venue_file},
                {"the reference body", sc.population.reference_body},
                {"the anthropometry extract", sc.population.anthropometry},
                {"the run to branch from", args.branch_from},
                {"the segment to continue", args.continue_from}},
               args.force);
  if (!args.branch_from.empty()) {
    // CheckOutputs allowed replacing -o: a branch starts it anew.
    const double t_s = scenario::BranchRun(sc, args.branch_from, args.output);
    std::fprintf(stderr, "crowdrecon: branched from %s at t = %.3f s\n", args.branch_from.c_str(), t_s);
  }
  if (!args.continue_from.empty()) {
    const double t_s = scenario::ContinueRun(sc, args.continue_from, args.output);
    std::fprintf(stderr, "crowdrecon: continuing %s from t = %.3f s into %s\n", args.continue_from.c_str(), t_s,
                 args.output.c_str());
  }
  scenario::RunOptions options;
  options.output = args.output;
  options.threads = args.threads > 0 ? args.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (!engine::FromString(args.device, &options.device))
    throw InputError("--device: \"" + args.device + "\", expected \"cpu\" or \"cuda\"");
  options.adapt_threads = !args.fixed_threads;
  options.resume = args.resume || !args.branch_from.empty() || !args.continue_from.empty();
  options.show_progress = !args.quiet && isatty(STDERR_FILENO);
  options.log_progress_every_s = LogProgressEvery(args.log_every_s, args.quiet);
  options.stop_after_s = args.stop_after_s;
  for (const std::string& line : sc.settings_without_effect) std::printf("note: %s\n", line.c_str());
  scenario::InstallInterruptHandlers();
  const scenario::RunSummary s = scenario::RunScenario(sc, options);
  std::printf("scenario: %s\n", sc.name.c_str());
  std::printf("profile: %s\n", sc.profile.c_str());
  if (s.slots > 0)
    std::printf("timeline: %zu people at the start, room in the engine for %zu at once\n", s.people, s.slots);
  // A max_present the engine could not keep is said (issue 40: it was raised without a word).
  if (const std::size_t asked = sc.timeline.max_present; asked > 0 && s.slots > 0 && asked != s.slots)
    std::printf("note: timeline.max_present %zu %s: the engine holds %zu at once\n", asked,
                asked < s.slots ? ("is below the " + std::to_string(s.people) + " people of the start").c_str()
                                : "is more than the start and every arrival together",
                s.slots);
  std::printf("people: %zu, time step %.6g s, %d thread(s)%s\n", s.people, s.time_step_s, options.threads,
              options.device != engine::ComputeDevice::kCuda ? ""
              : s.device_fallback.empty()                      ? ", person-pair forces on CUDA"
                                                               : ", person-pair forces on CUDA until it failed (see the note)");
  if (!s.threads_report.empty()) std::printf("threads: %s\n", s.threads_report.c_str());
  if (!s.systems_report.empty()) std::printf("run loop: %s\n", s.systems_report.c_str());
  if (s.started_at_s > 0.0)  // resumed (or branched): this part, then the whole
    std::printf("simulated: from %.3f to %.3f s in %.2f s wall (real-time factor %.3f); the run so far %.2f s wall\n",
                s.started_at_s, s.simulated_s, s.wall_s, s.real_time_factor, s.total_wall_s);
  else
    std::printf("simulated: %.3f s in %.2f s wall (real-time factor %.3f)\n", s.simulated_s, s.wall_s, s.real_time_factor);
  std::printf("run file: %s (%lld frames), status %s\n", args.output.c_str(), static_cast<long long>(s.frames),
              s.status.c_str());
  const engine::Profile& p = s.profile;
  const double total = p.total_s();
  if (total > 0) {
    std::string stages;
    for (const engine::StageInfo& stage : engine::kStages) {
      char share[64];
      std::snprintf(share, sizeof share, "%s%s %.0f %%", stages.empty() ? "" : ", ", stage.name,
                    100.0 * p.seconds(stage.stage) / total);
      stages += share;
      if (stage.stage == engine::Stage::kUpdatePairs)
        stages += " (" + std::to_string(p.pair_rebuilds) + " rebuilds)";
    }
    std::printf("engine time %.2f s: %s\n", total, stages.c_str());
  }
  if (const std::string steps = engine::StepLevelHistogram(p, s.time_step_s); !steps.empty())
    std::printf("adaptive step: %s\n", steps.c_str());
  if (p.walking_person_steps > 0)  // (model.sleep_speed_m_per_s > 0)
    std::printf("sleeping: %.1f %% of the walking people's steps asleep\n",
                100.0 * static_cast<double>(p.sleeping_person_steps) / static_cast<double>(p.walking_person_steps));
  if (s.status != "complete") {
    std::fprintf(stderr, "crowdrecon: run interrupted at t = %.3f s; continue it with: crowdrecon simulate %s%s -o %s --resume\n",
                 s.simulated_s, args.scenario.c_str(), args.profile.empty() ? "" : (" --profile " + args.profile).c_str(),
                 args.output.c_str());
    return scenario::InterruptedExitStatus();
  }
  return 0;
}

}  // namespace

void RegisterSimulateCommand(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand("simulate", "Run a scenario and write its run file (SQLite, JuPedSim format)");
  cmd->add_option("scenario", args->scenario, "Scenario file (JSON)")->required();
  cmd->add_option("-o,--output", args->output, "Run file to write (.sqlite)")->required();
  cmd->add_option("--profile", args->profile,
                  "Run under this model profile instead of the scenario's own \"profile\": a name (venues/profiles/: "
                  "paper, validated) or a profile file; the scenario's own single values still win. A resume takes "
                  "the same --profile");
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores); results do not depend on it")
      ->check(IntegerIn(0, 1024));
  cmd->add_option("--device", args->device,
                  "Where person-pair forces are computed: cpu (default) or cuda (a build with CUDA and a GPU); "
                  "results do not depend on it");
  cmd->add_flag("--fixed-threads", args->fixed_threads,
                "Keep exactly --threads threads, even while fewer are faster (another program busy on a core); "
                "for benchmarks. By default the count adapts; results do not depend on it");
  auto* resume = cmd->add_flag("--resume", args->resume, "Continue an interrupted run from its checkpoint");
  cmd->add_option("--branch-from", args->branch_from,
                  "Start the run as the given unfinished run stood at its checkpoint and continue it under this "
                  "scenario, which may differ from that run's only in its name, notes and timeline events from the "
                  "checkpoint's time on (a what-if from a moment of a long run)")
      ->excludes(resume);
  cmd->add_option("--continue-from", args->continue_from,
                  "Continue a stopped run (status interrupted, e.g. by --stop-after) from its checkpoint into -o, a new "
                  "file: the next segment of the run, which every command reads with the segments before it as one "
                  "run (a long run over several machines or days; docs/scenarios.md, \"Runs in segments\")")
      ->excludes(resume)
      ->excludes("--branch-from");
  AddForceFlag(cmd, &args->force);
  cmd->add_flag("-q,--quiet", args->quiet, "No progress line");
  AddLogEveryOption(cmd, &args->log_every_s);
  cmd->add_option("--stop-after", args->stop_after_s, "Stop as if interrupted at this simulated time (s), for testing resumption")
      ->check(NumberIn(0.0, 1e9, "s"));
  cmd->callback([args] {
    const int rc = RunSimulate(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace crowdrecon::cli
