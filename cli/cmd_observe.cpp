// `crowdrecon observe`: observations from trajectories (PeTrack, JuPedSim,
// crowdrecon runs) and from footage, in one format (observe/observation.hpp,
// docs/observations.md).
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/observe/fundamental_diagram.hpp"
#include "crowdrecon/observe/observation.hpp"
#include "crowdrecon/observe/trajectories.hpp"
#include "crowdrecon/viz/chart.hpp"

namespace crowdrecon::cli {

namespace {

struct TrajectoryArgs {
  std::string file;
  std::string spec;
  std::string output;
  double fps = 0.0;
  bool quiet = false;
  bool force = false;
};

// The series averaged over the bins (weighted by their samples), for a summary.
// Counts (flows) are averaged over the bins, other quantities weighted by
// their samples.
double Average(const observe::Series* s) {
  if (!s) return std::nan("");
  double sum = 0.0, weight = 0.0;
  const bool per_bin = s->quantity == "flow";
  for (const observe::SeriesPoint& p : s->points)
    if (std::isfinite(p.value) && (per_bin || p.samples > 0)) {
      sum += p.value * (per_bin ? 1.0 : p.samples);
      weight += per_bin ? 1.0 : p.samples;
    }
  return weight > 0 ? sum / weight : std::nan("");
}

void PrintSummary(const observe::Observation& obs) {
  std::printf("observation of %s (%s, by %s): %zu bins of %s s from %s s\n", obs.source_file.c_str(),
              obs.source_format.c_str(), obs.method.c_str(), obs.bins, FormatNumber(obs.bin_s).c_str(),
              FormatNumber(obs.t0_s).c_str());
  for (const observe::Region& r : obs.spec.regions) {
    std::printf("  region %s (%s m2): speed forward %s m/s, backward %s m/s; moving forward %s, backward %s, still %s; "
                "counter-flow share %s",
                r.name.c_str(), FormatNumber(r.Area_m2()).c_str(),
                FormatNumber(Average(obs.Find("speed", r.name, "forward"))).c_str(),
                FormatNumber(Average(obs.Find("speed", r.name, "backward"))).c_str(),
                FormatNumber(Average(obs.Find("share_moving", r.name, "forward"))).c_str(),
                FormatNumber(Average(obs.Find("share_moving", r.name, "backward"))).c_str(),
                FormatNumber(Average(obs.Find("share_still", r.name, "all"))).c_str(),
                FormatNumber(Average(obs.Find("counterflow_share", r.name, "all"))).c_str());
    if (const observe::Series* d = obs.Find("density", r.name, "all"))
      std::printf("; density %s /m2", FormatNumber(Average(d)).c_str());
    std::printf("\n");
  }
  for (const observe::Line& l : obs.spec.lines) {
    const observe::Series* f = obs.Find("flow", l.name, "forward");
    const observe::Series* b = obs.Find("flow", l.name, "backward");
    if (f && b)
      std::printf("  line %s: flow forward %s, backward %s /(m s)\n", l.name.c_str(), FormatNumber(Average(f)).c_str(),
                  FormatNumber(Average(b)).c_str());
  }
  std::size_t stops = 0, surges = 0;
  for (const observe::Event& e : obs.events) (e.kind == "stop" ? stops : surges) += 1;
  std::printf("  events: %zu stops, %zu surges\n", stops, surges);
  for (const observe::Event& e : obs.events)
    if (e.kind == "surge")
      std::printf("    surge in %s (%s) at %s +- %s s, peak %s m/s, rise %s s\n", e.where.c_str(), e.direction.c_str(),
                  FormatNumber(e.time_s).c_str(), FormatNumber(e.uncertainty_s).c_str(),
                  FormatNumber(e.peak_speed_m_per_s).c_str(), FormatNumber(e.rise_time_s).c_str());
  for (const std::string& n : obs.notes) std::printf("  note: %s\n", n.c_str());
}

void CheckObservationOutputs(const std::string& output, const std::vector<NamedInput>& inputs, bool force) {
  if (std::filesystem::path(output).extension() != ".json")
    throw InputError("-o " + output + ": expected a file name ending in .json (the series go beside it, in .csv)");
  CheckOutputs({{"-o", output, observe::ObservationJsonOutput()},
                {"-o (its series)", observe::ObservationCsvPath(output), observe::ObservationCsvOutput()}},
               inputs, force);
}

void RunTrajectories(const TrajectoryArgs& args) {
  CheckObservationOutputs(args.output, {{"the trajectories", args.file}, {"the spec", args.spec}}, args.force);
  const observe::ObservationSpec spec = observe::ReadObservationSpec(args.spec);
  const observe::Trajectories t = observe::ReadTrajectories(args.file, args.fps);
  const observe::Observation obs = observe::ObserveTrajectories(t, spec);
  observe::WriteObservation(obs, args.output);
  if (!args.quiet) {
    std::printf("%zu people, frames %lld-%lld at %s fps\n", t.people, static_cast<long long>(t.first_frame),
                static_cast<long long>(t.last_frame), FormatNumber(t.fps).c_str());
    PrintSummary(obs);
  }
  std::printf("observation: %s and %s\n", args.output.c_str(), observe::ObservationCsvPath(args.output).string().c_str());
}

struct FdArgs {
  std::vector<std::string> files;
  std::vector<std::string> specs;
  std::vector<std::string> pictures;
  std::string csv;
  int frame_step = 5;
  bool force = false;
};

void RunFundamentalDiagram(const FdArgs& args) {
  if (args.specs.size() != 1 && args.specs.size() != args.files.size())
    throw InputError("--spec: " + std::to_string(args.specs.size()) + " given for " + std::to_string(args.files.size()) +
                     " files; expected one for all or one per file");
  std::vector<PlannedOutput> outputs;
  for (const std::string& p : args.pictures) outputs.push_back({"-o", p, PictureOutputKind()});
  outputs.push_back({"--csv", args.csv,
                     OutputKind{"a fundamental diagram's points (CSV)", false, [](const std::filesystem::path& f) {
                                  return FileStartsWith(f, "source,area,time_s,density_per_m2,speed_m_per_s,people");
                                }}});
  std::vector<NamedInput> inputs;
  for (const std::string& f : args.files) inputs.push_back({"a trajectory file", f});
  for (const std::string& f : args.specs) inputs.push_back({"a spec", f});
  CheckOutputs(outputs, inputs, args.force);
  const observe::WeidmannRelation weidmann;
  std::vector<observe::FundamentalDiagram> diagrams;
  double rho_hi = 2.0;
  std::string csv = "source,area,time_s,density_per_m2,speed_m_per_s,people\n";
  for (std::size_t i = 0; i < args.files.size(); ++i) {
    const observe::ObservationSpec spec = observe::ReadObservationSpec(args.specs.size() == 1 ? args.specs[0] : args.specs[i]);
    const observe::Trajectories t = observe::ReadTrajectories(args.files[i]);
    diagrams.push_back(observe::ComputeFundamentalDiagram(t, spec.regions.front(), spec.velocity_span_s, args.frame_step));
    const observe::FundamentalDiagram& fd = diagrams.back();
    std::printf("%s, area %s (%s m2): %zu frames; density %s", t.source.c_str(), fd.area.c_str(),
                FormatNumber(spec.regions.front().Area_m2()).c_str(), fd.points.size(), "");
    double lo = 1e9, hi = 0, mean_v = 0;
    std::size_t n = 0;
    for (const observe::FundamentalDiagramPoint& p : fd.points) {
      lo = std::min(lo, p.density_per_m2);
      hi = std::max(hi, p.density_per_m2);
      if (std::isfinite(p.speed_m_per_s)) mean_v += p.speed_m_per_s, ++n;
      csv += std::filesystem::path(t.source).filename().string() + "," + fd.area + "," + FormatNumber(p.time_s) + "," +
             FormatNumber(p.density_per_m2) + "," + (std::isfinite(p.speed_m_per_s) ? FormatNumber(p.speed_m_per_s) : "") +
             "," + std::to_string(p.people) + "\n";
    }
    rho_hi = std::max(rho_hi, hi);
    std::printf("%s-%s /m2, mean speed %s m/s; class means from Weidmann: rms %s m/s\n", FormatNumber(lo).c_str(),
                FormatNumber(hi).c_str(), FormatNumber(n ? mean_v / static_cast<double>(n) : std::nan("")).c_str(),
                FormatNumber(fd.rms_from_weidmann_m_per_s).c_str());
    for (const observe::DensityClass& c : fd.classes)
      if (c.frames >= 25)
        std::printf("  %s-%s /m2: %zu frames, speed %s +- %s m/s (Weidmann %s)\n", FormatNumber(c.density_from).c_str(),
                    FormatNumber(c.density_to).c_str(), c.frames, FormatNumber(c.mean_speed_m_per_s).c_str(),
                    FormatNumber(c.sd_speed_m_per_s).c_str(),
                    FormatNumber(weidmann.SpeedAt(0.5 * (c.density_from + c.density_to))).c_str());
  }
  rho_hi = std::ceil(rho_hi * 1.1 * 2.0) / 2.0;
  for (const std::string& picture : args.pictures) {
    viz::ChartSheet sheet(picture, 1000, "Fundamental diagram: mean speed against classic density in the measurement area",
                          "points: frames (every " + std::to_string(args.frame_step) +
                              "th); dots with bars: means and standard deviations in classes of 0.25 /m2; black: Weidmann (1993)");
    viz::ChartPanel& p = sheet.AddPanel("classic density, persons/m2", "mean speed in the area, m/s", 0, rho_hi, 0, 2.2, 520);
    for (std::size_t i = 0; i < diagrams.size(); ++i) {
      std::vector<double> x, y, cx, cy, ce;
      for (const auto& q : diagrams[i].points) x.push_back(q.density_per_m2), y.push_back(q.speed_m_per_s);
      for (const auto& c : diagrams[i].classes)
        if (c.frames >= 25)
          cx.push_back(0.5 * (c.density_from + c.density_to)), cy.push_back(c.mean_speed_m_per_s),
              ce.push_back(c.sd_speed_m_per_s);
      viz::Color light = viz::ChartColor(static_cast<int>(i));
      light.a = 0.25;
      p.Points(x, y, light, 1.6);
      p.Points(cx, cy, viz::ChartColor(static_cast<int>(i)), 4.5,
               std::filesystem::path(diagrams[i].source).filename().string(), &ce);
    }
    std::vector<double> wx, wy;
    for (double r = 0.05; r <= rho_hi; r += 0.02) wx.push_back(r), wy.push_back(weidmann.SpeedAt(r));
    p.Line(wx, wy, viz::Color::Black(), 2.0, "Weidmann (1993)");
    sheet.Finish();
    std::printf("picture: %s\n", picture.c_str());
  }
  if (!args.csv.empty()) {
    WriteFileAtomically(args.csv, csv);
    std::printf("points: %s\n", args.csv.c_str());
  }
}

}  // namespace

void RegisterObserveCommands(CLI::App& app) {
  CLI::App* observe = app.add_subcommand(
      "observe", "Observations (speeds and shares per direction, density, flows, stops and surges) from trajectories "
                 "or footage, in one format (docs/observations.md)");
  observe->require_subcommand(1);

  auto targs = std::make_shared<TrajectoryArgs>();
  CLI::App* traj = observe->add_subcommand(
      "trajectories", "Observe trajectories: a PeTrack text file, a JuPedSim SQLite file (version 1-3) or a crowdrecon run");
  traj->add_option("FILE", targs->file, "trajectory file")->required();
  traj->add_option("--spec", targs->spec, "observation spec (JSON: axis, regions, lines, bins; docs/observations.md)")
      ->required();
  traj->add_option("-o,--output", targs->output, "observation file (.json; its series go to the same name .csv)")
      ->required();
  traj->add_option("--fps", targs->fps, "frame rate, replacing the file's (a PeTrack file without one needs it)")
      ->check(CLI::Range(0.001, 10000.0));
  traj->add_flag("-q,--quiet", targs->quiet, "print only the output's name");
  AddForceFlag(traj, &targs->force);
  traj->callback([targs] { RunTrajectories(*targs); });

  auto fargs = std::make_shared<FdArgs>();
  CLI::App* fd = observe->add_subcommand(
      "fd", "Fundamental diagram (mean speed against classic density in each spec's first region, frame by frame) of "
            "trajectory files, with Weidmann's relation");
  fd->add_option("FILES", fargs->files, "trajectory files (PeTrack, JuPedSim, crowdrecon runs)")->required();
  fd->add_option("--spec", fargs->specs, "observation spec: one for every file, or one per file in order")->required();
  fd->add_option("-o,--picture", fargs->pictures, "picture (.png, .svg or .pdf; repeat for several)")->required();
  fd->add_option("--csv", fargs->csv, "also write every point (source, time, density, speed, people) as CSV");
  fd->add_option("--frame-step", fargs->frame_step, "use every N-th frame (default 5)")->check(CLI::Range(1, 10000));
  AddForceFlag(fd, &fargs->force);
  fd->callback([fargs] { RunFundamentalDiagram(*fargs); });
}

}  // namespace crowdrecon::cli
