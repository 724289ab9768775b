// `crowdrecon observe`: observations from trajectories (PeTrack, JuPedSim,
// crowdrecon runs) and from footage, in one format (observe/observation.hpp,
// docs/observations.md).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "crowdrecon/common/csv.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/observe/footage.hpp"
#include "crowdrecon/observe/fundamental_diagram.hpp"
#include "crowdrecon/observe/homography.hpp"
#include "crowdrecon/observe/observation.hpp"
#include "crowdrecon/observe/synthetic_footage.hpp"
#include "crowdrecon/observe/trajectories.hpp"
#include "crowdrecon/viz/chart.hpp"

namespace crowdrecon::cli {

namespace {

struct TrajectoryArgs {
  std::string file;
  std::string figure;
  std::string spec;
  std::string output;
  double fps = 0.0;
  std::string unit;
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

// What the summary's numbers are, stated where they are printed: the
// velocities' window as used (a span rounded to whole frames), and how the
// means over bins treat stopped directions.
std::string Definitions(const observe::Observation& obs) {
  const nlohmann::json o = nlohmann::json::parse(obs.method_options_json, nullptr, false);
  std::string window;
  if (o.is_object() && o.contains("velocity_half_span_frames") && o.contains("velocity_span_s"))
    window = "velocities are centred differences over +-" + o["velocity_half_span_frames"].dump() + " frames (" +
             FormatNumber(o["velocity_span_s"].get<double>()) + " s; one-sided at a track's ends)";
  else if (o.is_object() && o.contains("span_frames") && o.contains("fps"))
    window = "velocities are image motion over " + o["span_frames"].dump() + " frames (" +
             FormatNumber(o["span_frames"].get<double>() / o["fps"].get<double>()) + " s)";
  return "  definitions: " + (window.empty() ? std::string() : window + "; ") +
         "speeds, shares and density are means over the bins, weighted by their samples; a direction stopped in "
         "a bin counts with speed 0; flows are means over the bins\n";
}

// Writes the observation and says which leftovers of killed writers of it went.
void WriteObservationSayingLeftovers(const observe::Observation& obs, const std::string& output) {
  for (const std::filesystem::path& p : observe::WriteObservation(obs, output))
    std::printf("note: removed %s, left by an observe that was killed\n", p.c_str());
}

void PrintSummary(const observe::Observation& obs) {
  std::printf("observation of %s (%s, by %s): %zu bins of %s s from %s s\n", obs.source_file.c_str(),
              obs.source_format.c_str(), obs.method.c_str(), obs.bins, FormatNumber(obs.bin_s).c_str(),
              FormatNumber(obs.t0_s).c_str());
  std::printf("%s", Definitions(obs).c_str());
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

// An observation read as an input: its JSON and the series file it names,
// neither of which an output may replace (not even with --force).
void AddObservationInputs(const std::string& what, const std::string& json_file, std::vector<NamedInput>* inputs) {
  if (json_file.empty()) return;
  inputs->push_back({what, json_file});
  inputs->push_back({what + "'s series", observe::ObservationSeriesPath(json_file)});
}

void CheckObservationOutputs(const std::string& output, const std::vector<NamedInput>& inputs, bool force) {
  if (std::filesystem::path(output).extension() != ".json")
    throw InputError("-o " + output + ": expected a file name ending in .json (the series go beside it, in .csv)");
  CheckOutputs({{"-o", output, observe::ObservationJsonOutput()},
                {"-o (its series)", observe::ObservationCsvPath(output), observe::ObservationCsvOutput()}},
               inputs, force);
}

void DrawObservationFigure(const observe::Observation& obs, const observe::Observation* reference,
                           const std::filesystem::path& file);

void RunTrajectories(const TrajectoryArgs& args) {
  // The figure's format before any output (issue 65, Q09: a .txt figure failed
  // after the observation's JSON and CSV were written).
  if (!args.figure.empty()) CheckPictureName("--figure", args.figure);
  CheckObservationOutputs(args.output, {{"the trajectories", args.file}, {"the spec", args.spec}}, args.force);
  CheckOutputs({{"--figure", args.figure, PictureOutputKind()}}, {{"the trajectories", args.file}}, args.force);
  const observe::ObservationSpec spec = observe::ReadObservationSpec(args.spec);
  const observe::Trajectories t = observe::ReadTrajectories(args.file, args.fps, args.unit);
  const observe::Observation obs = observe::ObserveTrajectories(t, spec);
  WriteObservationSayingLeftovers(obs, args.output);
  if (!args.figure.empty()) DrawObservationFigure(obs, nullptr, args.figure);
  SayIfUnfinished(args.file);  // (a run file's; issue 65, Q08)
  // A region nobody ever enters gives empty series (issue 65, Q06: a region
  // beside the venue gave "speed nan, density 0" without a word).
  for (const observe::Region& region : spec.regions) {
    bool entered = false;
    for (const observe::TrajectoryPoint& p : t.points)
      if (region.Contains(p.position_m)) {
        entered = true;
        break;
      }
    if (!entered && !t.points.empty())
      std::printf("note: nobody is ever inside the region \"%s\" (check its coordinates against the trajectories'); "
                  "its series are empty\n",
                  region.name.c_str());
  }
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
  std::string unit;
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
    const observe::Trajectories t = observe::ReadTrajectories(args.files[i], 0.0, args.unit);
    diagrams.push_back(observe::ComputeFundamentalDiagram(t, spec.regions.front(), spec.velocity_span_s, args.frame_step));
    const observe::FundamentalDiagram& fd = diagrams.back();
    if (fd.points.empty())
      throw InputError(args.files[i] + ": no frame (of every " + std::to_string(args.frame_step) +
                       ") has anyone in the measurement area " + fd.area +
                       "; expected trajectories that pass through the spec's first region");
    std::printf("%s, area %s (%s m2): %zu frames with someone in the area (the others are left out); density %s", t.source.c_str(), fd.area.c_str(),
                FormatNumber(spec.regions.front().Area_m2()).c_str(), fd.points.size(), "");
    double lo = 1e9, hi = 0, mean_v = 0;
    std::size_t n = 0;
    for (const observe::FundamentalDiagramPoint& p : fd.points) {
      lo = std::min(lo, p.density_per_m2);
      hi = std::max(hi, p.density_per_m2);
      if (std::isfinite(p.speed_m_per_s)) mean_v += p.speed_m_per_s, ++n;
      csv += CsvField(std::filesystem::path(t.source).filename().string()) + "," + CsvField(fd.area) + "," + FormatNumber(p.time_s) + "," +
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

// The figure of an observation: per region, the speed of each direction with
// its uncertainty and the shares moving, with the detected events; a second
// observation (the reference, e.g. a run's own trajectories) drawn beside it.
void DrawObservationFigure(const observe::Observation& obs, const observe::Observation* reference,
                           const std::filesystem::path& file) {
  const std::vector<double> t = obs.BinTimes();
  const double t0 = obs.t0_s, t1 = obs.t0_s + obs.bin_s * static_cast<double>(obs.bins);
  viz::ChartSheet sheet(file, 1200, "Observation of " + std::filesystem::path(obs.source_file).filename().string() + " (" + obs.method + ")",
                        reference ? "dots with bars: this observation; lines: " +
                                        std::filesystem::path(reference->source_file).filename().string() + " (" + reference->method +
                                        "); marks: surges (solid) and stops (dashed)"
                                  : "dots with bars: values and uncertainties per bin; marks: surges (solid) and stops (dashed)");
  const auto values = [](const observe::Series* s, bool error) {
    std::vector<double> v;
    if (s)
      for (const observe::SeriesPoint& p : s->points) v.push_back(error ? p.uncertainty : p.value);
    return v;
  };
  for (const observe::Region& region : obs.spec.regions) {
    double v_hi = 0.5;
    for (const char* d : {"forward", "backward"})
      for (double v : values(obs.Find("speed", region.name, d), false))
        if (std::isfinite(v)) v_hi = std::max(v_hi, v);
    viz::ChartPanel& speed = sheet.AddPanel("time, s", region.name + ": speed of the movers, m/s", t0, t1, 0,
                                            std::ceil(v_hi * 1.15 * 4) / 4, 300);
    viz::ChartPanel& share = sheet.AddPanel("time, s", region.name + ": share moving", t0, t1, 0, 1, 200);
    int colour = 0;
    for (const char* d : {"forward", "backward"}) {
      const std::vector<double> err = values(obs.Find("speed", region.name, d), true);
      speed.Points(t, values(obs.Find("speed", region.name, d), false), viz::ChartColor(colour), 2.2, std::string(d), &err);
      share.Points(t, values(obs.Find("share_moving", region.name, d), false), viz::ChartColor(colour), 2.0, std::string(d));
      if (reference && reference->Find("speed", region.name, d)) {
        const std::vector<double> rt = reference->BinTimes();
        speed.Line(rt, values(reference->Find("speed", region.name, d), false), viz::ChartColor(colour), 1.5,
                   std::string(d) + ", reference");
        share.Line(rt, values(reference->Find("share_moving", region.name, d), false), viz::ChartColor(colour), 1.5);
      }
      ++colour;
    }
    share.Line(t, values(obs.Find("counterflow_share", region.name, "all"), false), viz::ChartColor(3), 1.5,
               "counter-flow share of the movers");
    for (const observe::Event& e : obs.events) {
      if (e.where != region.name || e.direction == "all" || e.censored) continue;
      const viz::Color c = viz::ChartColor(e.direction == "forward" ? 0 : 1);
      speed.Mark(e.time_s, c, e.kind == "surge" ? "surge" : "stop", e.kind != "surge");
    }
  }
  sheet.Finish();
}

struct FootageArgs {
  std::string video, homography, spec, output, picture_dir, figure, reference, flow = "dis-medium";
  std::vector<double> picture_at;
  double grid_m = 0.1, from_s = 0.0, to_s = -1.0;
  observe::FootageOptions defaults;
  bool no_enhance = false, quiet = false, force = false;
};

void RunFootage(const FootageArgs& args) {
  if (!args.figure.empty()) CheckPictureName("--figure", args.figure);
  std::vector<PlannedOutput> outputs = {{"--figure", args.figure, PictureOutputKind()}};
  std::vector<NamedInput> inputs = {{"the video", args.video}, {"the homography", args.homography}, {"the spec", args.spec}};
  AddObservationInputs("the reference", args.reference, &inputs);
  CheckObservationOutputs(args.output, inputs, args.force);
  CheckOutputs(outputs, inputs, args.force);
  observe::FootageOptions options;
  options.flow = args.flow;
  options.grid_spacing_m = args.grid_m;
  options.min_brightness = args.defaults.min_brightness;
  options.min_contrast = args.defaults.min_contrast;
  options.min_correlation = args.defaults.min_correlation;
  options.enhance = !args.no_enhance;
  options.from_s = args.from_s;
  if (args.to_s >= 0) options.to_s = args.to_s;
  if (!args.picture_at.empty()) {
    if (args.picture_dir.empty()) throw InputError("--picture-at needs --pictures FOLDER");
    options.picture_times_s = args.picture_at;
    options.picture_dir = args.picture_dir;
  }
  if (!args.quiet && isatty(fileno(stderr)) != 0)
    options.progress = [](const observe::FootageProgress& p) {
      std::fprintf(stderr, "\rfootage: frame %zu%s (video %.1f s), %.0f frames/s   ", p.frames_done,
                   p.frames_total ? (" of " + std::to_string(p.frames_total)).c_str() : "", p.video_time_s,
                   p.elapsed_s > 0 ? static_cast<double>(p.frames_done) / p.elapsed_s : 0.0);
      std::fflush(stderr);
    };
  const observe::ObservationSpec spec = observe::ReadObservationSpec(args.spec);
  const observe::Homography h = observe::ReadHomography(args.homography);
  std::unique_ptr<observe::Observation> reference;
  if (!args.reference.empty()) reference = std::make_unique<observe::Observation>(observe::ReadObservation(args.reference));
  observe::FootageSummary summary;
  const observe::Observation obs = observe::ObserveFootage(args.video, h, spec, options, &summary);
  if (options.progress) std::fprintf(stderr, "\n");
  WriteObservationSayingLeftovers(obs, args.output);
  if (!args.figure.empty()) DrawObservationFigure(obs, reference.get(), args.figure);
  if (!args.quiet) {
    if (!h.pairs.empty())
      std::printf("homography: %zu point pairs, rms %s px\n", h.pairs.size(), FormatNumber(h.rms_error_px).c_str());
    std::printf("%s", summary.BriefReport().c_str());
    PrintSummary(obs);
    for (const auto& p : summary.pictures) std::printf("picture: %s\n", p.string().c_str());
    if (!args.figure.empty()) std::printf("figure: %s\n", args.figure.c_str());
  }
  std::printf("observation: %s and %s\n", args.output.c_str(), observe::ObservationCsvPath(args.output).string().c_str());
}

struct SynthesizeArgs {
  std::string run, video, homography;
  observe::SyntheticFootageOptions options;
  bool force = false;
};

void RunSynthesize(const SynthesizeArgs& args) {
  if (std::filesystem::path(args.video).extension() != ".avi")
    throw InputError("-o " + args.video + ": expected a file name ending in .avi (Motion-JPEG)");
  CheckOutputs({{"-o", args.video, VideoOutputKind()},
                {"--homography-out", args.homography,
                 JsonOutputKind("a homography (format crowdrecon-homography)",
                                [](const nlohmann::json& j) { return j.contains("format") && j["format"] == "crowdrecon-homography"; })}},
               {{"the run file", args.run}}, args.force);
  observe::SyntheticFootageOptions options = args.options;
  if (isatty(fileno(stderr)) != 0)
    options.progress = [](std::size_t done, std::size_t total) {
      if (done % 25 == 0 || done == total) std::fprintf(stderr, "\rsynthesize: frame %zu of %zu   ", done, total);
      std::fflush(stderr);
    };
  const observe::SyntheticFootageSummary s = observe::RenderSyntheticFootage(args.run, options, args.video, args.homography);
  for (const std::filesystem::path& p : s.removed_partials)
    std::printf("removed %s: the unfinished video of a synthesize that was killed\n", p.c_str());
  if (options.progress) std::fprintf(stderr, "\n");
  std::printf("video: %s (%zu frames at %s fps, from run time %s s; %dx%d; darkness %s, blur %s px, noise %s, JPEG quality %d)\n",
              args.video.c_str(), s.frames, FormatNumber(s.fps).c_str(), FormatNumber(s.first_time_s).c_str(),
              options.width_px, options.height_px, FormatNumber(options.darkness).c_str(),
              FormatNumber(options.blur_sigma_px).c_str(), FormatNumber(options.noise_sigma).c_str(), options.jpeg_quality);
  std::printf("homography: %s\n", args.homography.c_str());
  SayIfUnfinished(args.run);
}

// Compares an observation with a reference (e.g. footage with the run's own
// trajectories): per region and direction, the mean speed over the bins both
// define; the counter-flow share; and each reference surge/stop matched to
// the nearest one of the same kind within 3 s. Shares of the moving and
// still, and the mean velocity, are left out: footage counts floor, not
// people (footage.hpp).
struct CompareArgs {
  std::string reference, test, csv;
  double match_s = 3.0;
  bool force = false;
};

void RunCompare(const CompareArgs& args) {
  CheckOutputs({{"--csv", args.csv, OutputKind{"a comparison (CSV)", false, [](const std::filesystem::path& f) {
                                                return FileStartsWith(f, "where,quantity,direction,reference,observed");
                                              }}}},
               [&] {
                 std::vector<NamedInput> inputs;
                 AddObservationInputs("the reference", args.reference, &inputs);
                 AddObservationInputs("the observation", args.test, &inputs);
                 return inputs;
               }(),
               args.force);
  const observe::Observation ref = observe::ReadObservation(args.reference);
  const observe::Observation obs = observe::ReadObservation(args.test);
  std::string csv = "where,quantity,direction,reference,observed,error,error_percent,bins\n";
  const std::vector<double> rt = ref.BinTimes(), ot = obs.BinTimes();
  // The observed value at a reference bin's time (the bin that holds it).
  const auto at = [&](const observe::Series& s, double time) {
    const double k = std::floor((time - obs.t0_s) / obs.bin_s);
    return k >= 0 && k < static_cast<double>(s.points.size()) ? s.points[static_cast<std::size_t>(k)].value : std::nan("");
  };
  std::printf("%-10s %-18s %-9s %10s %10s %10s %8s %6s\n", "where", "quantity", "direction", "reference", "observed", "error",
              "error %", "bins");
  for (const observe::Region& region : ref.spec.regions)
    for (const auto& [quantity, direction] : std::vector<std::pair<std::string, std::string>>{
             {"speed", "forward"}, {"speed", "backward"}, {"counterflow_share", "all"}}) {
      const observe::Series* r = ref.Find(quantity, region.name, direction);
      const observe::Series* o = obs.Find(quantity, region.name, direction);
      if (!r || !o) continue;
      double sr = 0, so = 0;
      std::size_t n = 0;
      for (std::size_t k = 0; k < r->points.size(); ++k) {
        const double a = r->points[k].value, b = at(*o, rt[k]);
        // Speeds: bins where the reference has movers that way.
        if (!std::isfinite(a) || !std::isfinite(b) || (quantity == "speed" && a <= 0)) continue;
        sr += a, so += b, ++n;
      }
      if (n == 0) continue;
      const double mr = sr / static_cast<double>(n), mo = so / static_cast<double>(n), e = mo - mr;
      std::printf("%-10s %-18s %-9s %10.4f %10.4f %+10.4f %+8.1f %6zu\n", region.name.c_str(), quantity.c_str(),
                  direction.c_str(), mr, mo, e, mr != 0 ? 100 * e / std::abs(mr) : std::nan(""), n);
      csv += CsvField(region.name) + "," + quantity + "," + direction + "," + FormatNumber(mr) + "," + FormatNumber(mo) + "," +
             FormatNumber(e) + "," + (mr != 0 ? FormatNumber(100 * e / std::abs(mr)) : "") + "," + std::to_string(n) + "\n";
    }
  for (const observe::Event& e : ref.events) {
    if (e.censored || e.direction == "all") continue;
    const observe::Event* best = nullptr;
    for (const observe::Event& f : obs.events)
      if (f.kind == e.kind && f.where == e.where && f.direction == e.direction && !f.censored &&
          std::abs(f.time_s - e.time_s) <= args.match_s && (!best || std::abs(f.time_s - e.time_s) < std::abs(best->time_s - e.time_s)))
        best = &f;
    if (best) {
      std::printf("%-10s %-18s %-9s %10.2f %10.2f %+10.2f %8s %6s\n", e.where.c_str(), (e.kind + " onset").c_str(),
                  e.direction.c_str(), e.time_s, best->time_s, best->time_s - e.time_s, "", "");
      csv += CsvField(e.where) + "," + e.kind + "_onset_s," + e.direction + "," + FormatNumber(e.time_s) + "," +
             FormatNumber(best->time_s) + "," + FormatNumber(best->time_s - e.time_s) + ",,\n";
    } else {
      std::printf("%-10s %-18s %-9s %10.2f %10s\n", e.where.c_str(), (e.kind + " onset").c_str(), e.direction.c_str(), e.time_s,
                  "missed");
      csv += CsvField(e.where) + "," + e.kind + "_onset_s," + e.direction + "," + FormatNumber(e.time_s) + ",,,,\n";
    }
  }
  std::size_t extra = 0;
  for (const observe::Event& f : obs.events) {
    if (f.censored || f.direction == "all") continue;
    bool matched = false;
    for (const observe::Event& e : ref.events)
      matched = matched || (e.kind == f.kind && e.where == f.where && e.direction == f.direction &&
                            std::abs(f.time_s - e.time_s) <= args.match_s);
    extra += !matched;
  }
  std::printf("events in the observation with no reference event within %s s: %zu\n", FormatNumber(args.match_s).c_str(), extra);
  csv += "all,unmatched_events,all,0," + std::to_string(extra) + ",,,\n";
  if (!args.csv.empty()) {
    WriteFileAtomically(args.csv, csv);
    std::printf("comparison: %s\n", args.csv.c_str());
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
      ->check(NumberIn(0.001, 10000.0, "frames/s"));
  traj->add_option("--unit", targs->unit, "unit of a PeTrack file's coordinates, replacing its header's (m, cm or mm)")
      ->check(CLI::IsMember({"m", "cm", "mm"}));
  traj->add_option("--figure", targs->figure, "picture of the series with the detected events (.png, .svg, .pdf)");
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
  fd->add_option("--frame-step", fargs->frame_step, "use every N-th frame (default 5)")->check(IntegerIn(1, 10000));
  fd->add_option("--unit", fargs->unit, "unit of a PeTrack file's coordinates, replacing its header's (m, cm or mm)")
      ->check(CLI::IsMember({"m", "cm", "mm"}));
  AddForceFlag(fd, &fargs->force);
  fd->callback([fargs] { RunFundamentalDiagram(*fargs); });

  auto vargs = std::make_shared<FootageArgs>();
  CLI::App* footage = observe->add_subcommand(
      "footage", "Observe a video: dense optical flow carried to the floor through a homography, per direction of travel, "
                 "with unusable frames flagged (docs/observations.md)");
  footage->add_option("VIDEO", vargs->video, "video file (AVI, MP4, ...)")->required();
  footage->add_option("--homography", vargs->homography, "homography (JSON: >= 4 image <-> floor point pairs, or a matrix)")
      ->required();
  footage->add_option("--spec", vargs->spec, "observation spec (axis, regions, bins)")->required();
  footage->add_option("-o,--output", vargs->output, "observation file (.json; its series go to the same name .csv)")->required();
  footage->add_option("--flow", vargs->flow, "optical flow: dis-medium (DIS, medium preset; default), dis-fast (DIS, fast preset: about three times faster, speeds lower; docs/observations.md) or farneback")->check(CLI::IsMember({"dis-fast", "dis-medium", "farneback"}));
  footage->add_option("--grid", vargs->grid_m, "spacing of the floor points sampled (m, default 0.1)")->check(NumberIn(0.01, 2.0, "m"));
  footage->add_option("--from", vargs->from_s, "start at this time of the video (s)")->check(NumberIn(0.0, 1e7, "s"));
  footage->add_option("--to", vargs->to_s, "stop at this time of the video (s)")->check(NumberIn(0.0, 1e7, "s"));
  footage->add_option("--pictures", vargs->picture_dir, "folder for the flow-field pictures (with --picture-at)");
  footage->add_option("--picture-at", vargs->picture_at, "times (s) of the flow-field pictures, e.g. 2,10.5")
      ->delimiter(',')
      ->check(NumberIn(0.0, 1e7, "s"));
  footage->add_option("--figure", vargs->figure, "picture of the series with the detected events (.png, .svg, .pdf)");
  footage->add_option("--reference", vargs->reference, "an observation to draw beside it in --figure (e.g. the trajectories')");
  footage->add_option("--min-brightness", vargs->defaults.min_brightness,
                      "a frame darker than this mean grey level (of 255) in the regions is flagged dark (default 8)")
      ->check(NumberIn(0.0, 255.0, "grey levels"));
  footage->add_option("--min-contrast", vargs->defaults.min_contrast,
                      "a frame whose grey levels in the regions vary less than this (standard deviation) is flagged flat "
                      "(default 3; 0 lets every frame through)")
      ->check(NumberIn(0.0, 128.0, "grey levels"));
  footage->add_option("--min-correlation", vargs->defaults.min_correlation,
                      "a frame correlated less than this with the previous one is flagged as a cut (default 0.5)")
      ->check(NumberIn(-1.0, 1.0));
  footage->add_flag("--no-enhance", vargs->no_enhance, "no contrast enhancement (CLAHE) before the flow");
  footage->add_flag("-q,--quiet", vargs->quiet, "no progress, print only the output's name");
  AddForceFlag(footage, &vargs->force);
  footage->callback([vargs] { RunFootage(*vargs); });

  auto sargs = std::make_shared<SynthesizeArgs>();
  CLI::App* synth = observe->add_subcommand(
      "synthesize", "Synthetic footage of a run: bodies seen by a tilted camera (known homography), darkened, blurred, noisy, "
                    "compressed; for checking footage analysis against the run's trajectories");
  synth->add_option("RUN", sargs->run, "run file (.sqlite)")->required();
  synth->add_option("-o,--output", sargs->video, "video (.avi, Motion-JPEG)")->required();
  synth->add_option("--homography-out", sargs->homography, "where to write the camera's homography (JSON)")->required();
  synth->add_option("--width", sargs->options.width_px, "picture width (px, default 960)");
  synth->add_option("--height", sargs->options.height_px, "picture height (px, default 480)");
  synth->add_option("--far-width", sargs->options.far_width, "far edge of the floor as a share of the near edge (default 0.6)");
  synth->add_option("--darkness", sargs->options.darkness, "grey levels scaled by 1 - darkness (0 to <1, default 0)");
  synth->add_option("--blur", sargs->options.blur_sigma_px, "Gaussian blur (sigma, px)");
  synth->add_option("--noise", sargs->options.noise_sigma, "sensor noise (sigma, grey levels)");
  synth->add_option("--quality", sargs->options.jpeg_quality, "Motion-JPEG quality (1-100, default 95)");
  synth->add_option("--frame-step", sargs->options.frame_step, "every N-th frame of the run (a lower frame rate)");
  synth->add_option("--seed", sargs->options.seed, "seed of the textures and the noise")
      ->check(IntegerIn(0, 4611686018427387904LL));
  AddForceFlag(synth, &sargs->force);
  synth->callback([sargs] { RunSynthesize(*sargs); });

  auto cargs = std::make_shared<CompareArgs>();
  CLI::App* compare = observe->add_subcommand(
      "compare", "Errors of an observation against a reference observation: mean speeds per direction, the counter-flow "
                 "share, event onsets");
  compare->add_option("REFERENCE", cargs->reference, "reference observation (.json)")->required();
  compare->add_option("OBSERVATION", cargs->test, "observation to check (.json)")->required();
  compare->add_option("--csv", cargs->csv, "also write the table as CSV");
  compare->add_option("--match", cargs->match_s, "events match within this time (s, default 3)")->check(NumberIn(0.0, 60.0, "s"));
  AddForceFlag(compare, &cargs->force);
  compare->callback([cargs] { RunCompare(*cargs); });
}

}  // namespace crowdrecon::cli
