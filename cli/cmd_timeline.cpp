// `crowdrecon timeline RUN`: the figure of an incident timeline's run
// (density, counter-flow, speeds per direction, flow, queues, the run's
// avalanches and falls, the incident's recorded marks) and the run's path
// through density x counter-flow over a sweep's phase diagrams (issue 20;
// analysis/timeline_series.hpp, viz/timeline_figure.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "crowdrecon/analysis/density_map.hpp"
#include "crowdrecon/analysis/plausibility.hpp"
#include "crowdrecon/analysis/timeline_series.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/reports/ensemble.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/scenario/profile.hpp"
#include "crowdrecon/sweep/phase_diagram.hpp"
#include "crowdrecon/sweep/results.hpp"
#include "crowdrecon/viz/density_figure.hpp"
#include "crowdrecon/viz/timeline_figure.hpp"
#include "option_checks.hpp"

namespace crowdrecon::cli {

namespace {

struct TimelineArgs {
  std::vector<std::string> runs;
  std::string run;  // the first
  std::vector<std::string> figures;
  std::string phase;
  std::string phase_output;
  double smooth_s = 10.0;
  double path_step_s = 60.0;
  std::vector<std::string> density_maps;
  std::vector<double> density_times_s;
  double density_cell_m = 0.5, density_sigma_m = 0.5;
  std::vector<std::string> scores;
  double tolerance_s = 120.0;
  bool area_avalanches = false;
  std::vector<std::string> compare;  // a second ensemble (of the same incident)
  std::string summaries;             // a folder for each run's summary (ensembles over several sessions)
  std::string label, compare_label;  // their names (default: their runs' profile)
  bool force = false;
};

// The run's path through the diagram's plane: means over path_step_s of
// the density and the counter-flow share, labelled every quarter of the run.
sweep::PathOverlay PathOf(const analysis::TimelineSeries& s, double step_s) {
  sweep::PathOverlay path;
  if (s.time_s.empty()) return path;
  const double t0 = s.time_s.front(), t1 = s.time_s.back();
  const double label_every = std::max(step_s, std::round((t1 - t0) / 6.0 / step_s) * step_s);
  for (double a = t0; a < t1; a += step_s) {
    double d = 0.0, c = 0.0;
    std::size_t nd = 0, nc = 0;
    for (std::size_t i = 0; i < s.time_s.size(); ++i) {
      if (s.time_s[i] < a || s.time_s[i] >= a + step_s) continue;
      d += s.density_per_m2[i], ++nd;
      if (!std::isnan(s.counter_fraction[i])) c += s.counter_fraction[i], ++nc;
    }
    if (nd == 0 || nc == 0) continue;
    path.points.emplace_back(d / static_cast<double>(nd), c / static_cast<double>(nc));
    if (std::fmod(a - t0 + 1e-9, label_every) < step_s * 0.5)
      path.labels.emplace_back(path.points.size() - 1, s.clock.Text(a));
  }
  path.caption = "path of " + s.run_file + ": density and counter-flow share, " + FormatNumber(step_s) +
                 "-s means (clamped to the diagram's range)";
  return path;
}

// Several runs of one incident (seeds): one row per run beside the recorded
// marks, and the score table (reports/ensemble.hpp).
void RunEnsemble(const TimelineArgs& args) {
  // (With one run, --scores made this an ensemble of one: the figures of one
  // run are another call's.)
  const std::string instead = args.runs.size() == 1
                                  ? "with --scores the run is scored as an ensemble (of one); draw it in a call without --scores"
                                  : "give one run file, not " + std::to_string(args.runs.size());
  if (!args.phase.empty()) throw InputError("--phase draws one run's path: " + instead);
  if (!args.density_maps.empty()) throw InputError("--density-maps draws one run's maps: " + instead);
  reports::EnsembleOptions options;
  options.tolerance_s = args.tolerance_s;
  options.smooth_s = args.smooth_s;
  options.area_avalanches = args.area_avalanches;
  if (std::string error; !options.IsValid(&error)) throw InputError("--tolerance / --smooth: " + error);
  std::vector<PlannedOutput> outputs;
  for (const std::string& f : args.figures) {
    CheckPictureName("-o", f);
    outputs.push_back({"-o", f, PictureOutputKind()});
  }
  for (const std::string& f : args.scores) {
    const std::string ext = std::filesystem::path(f).extension().string();
    if (ext != ".md" && ext != ".csv")
      throw InputError("--scores " + f + ": expected a file ending in .md (the score table) or .csv (one row per run)");
    outputs.push_back({"--scores", f, reports::EnsembleScoresOutput()});
  }
  std::vector<NamedInput> inputs;
  for (const std::string& r : args.runs) inputs.push_back({"a run file", r});
  for (const std::string& r : args.compare) inputs.push_back({"a run file (--compare)", r});
  // Each run's summary (reports/ensemble.hpp): DIR/<the run file's name>.json.
  std::map<std::string, std::filesystem::path> summary_of;
  if (!args.summaries.empty()) {
    std::vector<std::string> every_run(args.runs.begin(), args.runs.end());
    every_run.insert(every_run.end(), args.compare.begin(), args.compare.end());
    for (const std::string& r : every_run) {
      if (std::filesystem::path(r).extension() == ".json")
        throw InputError("--summaries: " + r + " is a summary already; give run files to summarise");
      const std::filesystem::path out =
          std::filesystem::path(args.summaries) / (std::filesystem::path(r).stem().string() + ".json");
      if (!summary_of.emplace(std::filesystem::absolute(out).lexically_normal().string(), r).second)
        throw InputError("--summaries: two runs have the name " + std::filesystem::path(r).stem().string() +
                         "; summarise them into different folders");
      outputs.push_back({"--summaries", out.string(), reports::EnsembleSummaryOutput()});
    }
  }
  CheckOutputs(outputs, inputs, args.force);
  std::vector<std::filesystem::path> every(args.runs.begin(), args.runs.end());
  every.insert(every.end(), args.compare.begin(), args.compare.end());
  RefuseRepeatedFiles(every, "each run counts once in an ensemble");
  reports::CheckSeedsOfOneScenario({args.runs.begin(), args.runs.end()}, "an ensemble",
                                   "give another scenario's runs with --compare");
  if (!args.compare.empty())
    reports::CheckSeedsOfOneScenario({args.compare.begin(), args.compare.end()}, "the --compare ensemble");
  const auto read = [&](const std::vector<std::string>& files) {
    std::vector<reports::EnsembleRun> runs;
    for (std::size_t k = 0; k < files.size(); ++k) {
      std::fprintf(stderr, "reading %s (%zu of %zu)\n", files[k].c_str(), k + 1, files.size());
      runs.push_back(reports::ReadEnsembleRun(files[k], options));
      if (!args.summaries.empty()) {
        const std::filesystem::path out =
            std::filesystem::path(args.summaries) / (std::filesystem::path(files[k]).stem().string() + ".json");
        WriteFileAtomically(out, reports::EnsembleSummaryJson(files[k], runs.back(), options));
        std::printf("wrote %s\n", out.string().c_str());
      }
    }
    return reports::ScoreEnsemble(std::move(runs), options);
  };
  const reports::EnsembleScore score = read(args.runs);
  const std::string name = reports::EnsembleRunScenarioName(args.runs.front());
  std::vector<reports::LabelledEnsemble> ensembles{{"", &score}};
  reports::EnsembleScore compared;
  // (The number of runs is in the figure's second line: a long scenario name
  // and a count ran off the sheet.)
  std::string title = name.empty() ? std::string("Ensemble") : name;
  if (!args.compare.empty()) {
    compared = read(args.compare);
    // Named by their runs' profiles unless told (the profile is what a comparison is usually of).
    const std::string profile_a = reports::EnsembleRunProfile(args.runs.front());
    const std::string profile_b = reports::EnsembleRunProfile(args.compare.front());
    const bool by_profile = !profile_a.empty() && !profile_b.empty() && profile_a != profile_b;
    ensembles.front().label = !args.label.empty() ? args.label : by_profile ? "profile " + profile_a : "runs";
    ensembles.push_back({!args.compare_label.empty() ? args.compare_label : by_profile ? "profile " + profile_b : "comparison",
                         &compared});
    if (ensembles[0].label == ensembles[1].label)
      throw InputError("--label and --compare-label: the two ensembles need different names (both \"" +
                       ensembles[0].label + "\")");
    reports::CheckComparable(ensembles);
    // (Which ensembles: the figure's second line and its legend; a long
    // scenario name with both labels ran off the sheet.)
    if (name.empty()) title = ensembles[0].label + " beside " + ensembles[1].label;
  }
  for (const std::string& f : args.figures) {
    // (Every picture replaces its file only when complete: viz::Canvas.)
    reports::DrawEnsemblesFigure(ensembles, title, f);
    std::printf("wrote %s\n", f.c_str());
  }
  const std::string markdown = reports::EnsemblesMarkdown(ensembles);
  for (const std::string& f : args.scores) {
    WriteFileAtomically(f, std::filesystem::path(f).extension() == ".csv" ? reports::EnsemblesCsv(ensembles) : markdown);
    std::printf("wrote %s\n", f.c_str());
  }
  std::printf("%s", markdown.c_str());
}

void RunTimeline(const TimelineArgs& args) {
  std::vector<PlannedOutput> outputs;
  for (const std::string& f : args.figures) outputs.push_back({"-o", f, PictureOutputKind()});
  for (const std::string& f : args.density_maps) outputs.push_back({"--density-maps", f, PictureOutputKind()});
  sweep::PhaseOptions phase;
  if (!args.phase.empty()) {
    phase.results = args.phase;
    phase.output_dir = args.phase_output;
    phase.heat_maps = false;
    outputs.push_back({"--phase-output", sweep::PhaseOutputFolder(phase), sweep::PhaseFolderOutput()});
  }
  CheckOutputs(outputs, {{"the run file", args.run}, {"the sweep results", args.phase}}, args.force);
  // Every option is checked before anything is written (issue 40).
  for (const std::string& f : args.figures) CheckPictureName("-o", f);
  for (const std::string& f : args.density_maps) CheckPictureName("--density-maps", f);
  analysis::DensityMapOptions density;
  density.times_s = args.density_times_s;
  density.cell_m = args.density_cell_m;
  density.sigma_m = args.density_sigma_m;
  if (std::string why; !args.density_maps.empty() && !density.IsValid(&why))
    throw InputError("--density-times / --density-cell / --density-sigma: " + why);
  if (!runfile::IsRunFile(args.run))
    throw InputError(args.run + ": " + runfile::DescribeNonRunFile(args.run) + ", not a crowdrecon run file");
  analysis::TimelineSeries s = analysis::ComputeTimeline(args.run, args.smooth_s);
  // The local reading needs the venue's measurement areas (issue 65, H09: on a
  // venue without any it changed nothing, without a word).
  if (args.area_avalanches && s.area_names.empty())
    throw InputError("--area-avalanches: the run's venue has no measurement areas (\"measurement_areas\" in its venue "
                     "file) to read avalanches in; leave the option out for the crowd's and the directions' reading");
  if (args.area_avalanches) s.avalanches = analysis::AvalanchesWithAreas(s);
  // What may still refuse the run (the maps' times, the sweep's folder) is
  // read or drawn before the run's own figures.
  const std::vector<analysis::DensityMap> maps =
      args.density_maps.empty() ? std::vector<analysis::DensityMap>{} : analysis::ComputeDensityMaps(args.run, density);
  if (!args.phase.empty()) {
    phase.path = PathOf(s, args.path_step_s);
    // A path over another model's regimes is said, on the figure and here.
    std::string run_profile = runfile::RunFileReader(args.run).RunValue("profile");
    if (run_profile.empty()) run_profile = scenario::kDefaultProfile;  // (a run from before profiles)
    const std::string diagram_profile = sweep::SweepProfile(sweep::ReadResults(args.phase));
    if (!diagram_profile.empty() && diagram_profile != run_profile) {
      const std::string note = "the run's model (profile " + run_profile + ") is not the diagrams' (profile " +
                               diagram_profile + "): the path crosses another model's regimes";
      phase.path.note = "Note: " + note;
      std::printf("note: %s\n", note.c_str());
    }
    const sweep::PhaseSummary summary = sweep::DrawPhaseDiagrams(phase);
    std::printf("%s", summary.BriefReport().c_str());
  }
  const std::string title = reports::EnsembleRunScenarioName(args.run);
  for (const std::string& f : args.figures) {
    viz::DrawTimelineFigure(s, title.empty() ? "Timeline of " + args.run : title, f);
    std::printf("wrote %s\n", f.c_str());
  }
  std::printf("%zu frames from %s to %s; %zu avalanches and %zu falls in the run; %zu recorded marks\n",
              s.time_s.size(), s.clock.Text(s.time_s.front()).c_str(),
              s.clock.Text(s.time_s.back()).c_str(), s.avalanches.size(), s.falls.size(),
              s.recorded.size());
  SayIfUnfinished(args.run);
  std::printf("validity: %s\n", s.validity.Statement(analysis::PlausibilityOptions{}).c_str());
  if (!args.density_maps.empty()) {
    const geometry::Venue venue =
        geometry::ParseVenue(runfile::RunFileReader(args.run).venue_json(), args.run + ": run value venue");
    for (const std::string& f : args.density_maps) {
      viz::DrawDensityMaps(maps, venue, "Density: " + (title.empty() ? args.run : title), s.clock, f);
      std::printf("wrote %s\n", f.c_str());
    }
    for (const analysis::DensityMap& m : maps)
      std::printf("density at %s: %zu people, densest %.2f persons/m2\n",
                  s.clock.MomentText(m.time_s).c_str(),
                  m.people, m.max_per_m2);
  }
}

}  // namespace

void RegisterTimelineCommand(CLI::App& app) {
  auto args = std::make_shared<TimelineArgs>();
  CLI::App* cmd = app.add_subcommand(
      "timeline",
      "Draw the figure of an incident timeline's run: density, counter-flow, speed per direction, flow, people waiting "
      "at the entries, the run's avalanches and falls and the incident's recorded marks over time; with --phase, the "
      "run's path over a sweep's phase diagrams");
  cmd->add_option("RUN", args->runs,
                  "Run file of a scenario with a timeline; several (seeds of one incident): the ensemble's figure, one "
                  "row per run, and its score against the recorded marks")
      ->required();
  cmd->add_option("-o,--output", args->figures, "Figure file(s): .png, .svg or .pdf (repeat for several)")->required();
  cmd->add_option("--phase", args->phase, "Sweep output folder whose phase diagrams the run's path is drawn over");
  cmd->add_option("--phase-output", args->phase_output, "Folder for those diagrams (default: the sweep's phase/)");
  cmd->add_option("--smooth", args->smooth_s, "Moving-mean window of the figure's lines (s)")
      ->check(NumberIn(0.0, 3600.0, "s"));
  cmd->add_option("--path-step", args->path_step_s, "Averaging step of the path's points (s)")
      ->check(NumberIn(1.0, 3600.0, "s"));
  cmd->add_option("--density-maps", args->density_maps,
                  "Figure of density maps (persons/m2 over the venue) at --density-times: .png, .svg or .pdf (repeat for several)");
  cmd->add_option("--density-times", args->density_times_s,
                  "Times of the density maps (s, comma-separated; default: the start and the quarters of the run)")
      ->delimiter(',');
  cmd->add_option("--density-cell", args->density_cell_m, "Cell of the density maps (m)")->check(NumberIn(0.05, 10.0, "m"));
  cmd->add_option("--density-sigma", args->density_sigma_m, "Width of each person's Gaussian in the density maps (m)")
      ->check(NumberIn(0.05, 10.0, "m"));
  cmd->add_option("--scores", args->scores,
                  "Score file(s) of the runs against the recorded marks: .md (the score table) or .csv (one row per "
                  "run); also with one run")
      ->allow_extra_args(false);
  cmd->add_option("--tolerance", args->tolerance_s,
                  "A run's avalanche matches a recorded one within this many seconds of run time (default 120; scale it "
                  "with a compressed scenario's marks)")
      ->check(NumberIn(0.001, 1e7, "s"));
  cmd->add_flag("--area-avalanches", args->area_avalanches,
                "The local reading of avalanches: a stop and release inside one of the venue's measurement areas, "
                "while it held at least 3.6 persons/m2, counts too (one release seen in several places once; "
                "docs/analysis.md, \"Local avalanches\")");
  cmd->add_option("--compare", args->compare,
                  "Run files of a second ensemble of the same incident (another profile, another calibration): drawn "
                  "and scored beside the first, one column per ensemble");
  cmd->add_option("--summaries", args->summaries,
                  "An existing folder for each run's summary (RUN's name with .json): what scoring and drawing need, small enough "
                  "to keep in a repository; give the summaries instead of the run files later (an ensemble run over "
                  "several sessions)");
  cmd->add_option("--label", args->label, "Name of the first ensemble with --compare (default: its runs' profile)");
  cmd->add_option("--compare-label", args->compare_label,
                  "Name of the --compare ensemble (default: its runs' profile)");
  AddForceFlag(cmd, &args->force);
  cmd->callback([args] {
    args->run = args->runs.front();
    if ((!args->label.empty() || !args->compare_label.empty()) && args->compare.empty())
      throw InputError("--label and --compare-label name the ensembles of --compare; give --compare RUN...");
    const bool summaries = std::any_of(args->runs.begin(), args->runs.end(), [](const std::string& r) {
      return std::filesystem::path(r).extension() == ".json";
    });
    if (args->runs.size() > 1 || !args->scores.empty() || !args->compare.empty() || !args->summaries.empty() ||
        summaries)
      RunEnsemble(*args);
    else
      RunTimeline(*args);
  });
}

}  // namespace crowdrecon::cli
