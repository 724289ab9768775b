#include "crowdrecon/calibrate/calibration_file.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/json_reader.hpp"
#include "crowdrecon/common/sha256.hpp"
#include "crowdrecon/engine/parameter_table.hpp"
#include "crowdrecon/scenario/scenario.hpp"
#include "crowdrecon/scenario/timeline.hpp"
#include "crowdrecon/sweep/results.hpp"

namespace crowdrecon::calibrate {

namespace fs = std::filesystem;
using nlohmann::json;

const char* ToString(Approach a) { return a == Approach::kGradient ? "gradient" : "surrogate"; }

namespace {

const json& Raw(const json& document, const JsonReader& reader) {
  return document.at(json::json_pointer(reader.path()));
}

// The value at a dotted path of a JSON document, or nullptr.
const json* AtPath(const json& doc, const std::string& path) {
  const json* node = &doc;
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = path.find('.', begin);
    const std::string part = path.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin);
    if (!node->is_object() || !node->contains(part)) return nullptr;
    node = &(*node)[part];
    if (dot == std::string::npos) return node;
    begin = dot + 1;
  }
}

// The parameter table's entry for "model.<name>", or nullptr for other paths.
const engine::ParameterInfo* ModelEntry(const std::string& path) {
  if (path.rfind("model.", 0) != 0) return nullptr;
  return engine::FindModelParameter(path.substr(6));
}

Parameter ReadParameter(const JsonReader& item, const json& base_scenario, const std::vector<Parameter>& before) {
  if (!item.IsObject()) item.Fail("expected a parameter {\"path\": ..., \"min\": ..., \"max\": ...}, found " + item.ValueText());
  Parameter p;
  const JsonReader path = item.At("path");
  p.path = path.AsString();
  if (p.path.empty() || p.path.front() == '.' || p.path.back() == '.' || p.path.find("..") != std::string::npos)
    path.Fail("\"" + p.path + "\" is not a scenario path; expected names separated by dots, e.g. \"model.back_force_gamma\"");
  for (const Parameter& other : before)
    if (other.path == p.path) path.Fail("parameter \"" + p.path + "\" is given twice");
  if (p.path == "population.seed") path.Fail("the seed is not a parameter; the seeds are given with \"seeds\"");
  p.name = p.path.substr(p.path.rfind('.') + 1);

  const engine::ParameterInfo* entry = ModelEntry(p.path);
  if (p.path.rfind("model.", 0) == 0) {
    if (!entry) path.Fail("\"" + p.path + "\" is not a model parameter (docs/model.md, the parameter table)");
    if (entry->kind != engine::ParameterInfo::Kind::kNumber)
      path.Fail("\"" + p.path + "\" is not a number (" + entry->Expected() + "); only numbers can be calibrated");
  }
  const double lo_allowed = entry ? entry->min : -1e300, hi_allowed = entry ? entry->max : 1e300;
  const auto bound = [&](const char* key, double table_value) {
    if (item.Has(key)) return item.Number(key, lo_allowed, hi_allowed);
    if (!entry) item.Fail(std::string("\"") + key + "\" is required for \"" + p.path +
                          "\" (only model parameters have bounds by default: the parameter table's range)");
    return table_value;
  };
  p.min = bound("min", entry ? entry->min : 0.0);
  p.max = bound("max", entry ? entry->max : 0.0);
  if (!(p.max > p.min))
    item.Fail("the bounds [" + FormatNumber(p.min) + ", " + FormatNumber(p.max) + "] are empty; expected min < max");

  const json* v = AtPath(base_scenario, p.path);
  const bool range = v && v->is_array() && v->size() == 2 && (*v)[0].is_number() && (*v)[1].is_number();
  if (entry && item.Has("width"))
    item.At("width").Fail("\"" + p.path + "\" is a number; \"width\" is for ranges [low, high] such as "
                          "population.desired_speed_m_per_s");
  if (item.Has("width") || range) {
    p.is_range = true;
    p.width = item.Number("width", range ? (*v)[1].get<double>() - (*v)[0].get<double>() : 0.0, 0.0, 1e300);
    if (v && !range) {
      item.At("width").Fail("\"" + p.path + "\" is not a range [low, high] in the scenario; \"width\" is for ranges");
    }
    if (p.min - p.width / 2 < lo_allowed || p.max + p.width / 2 > hi_allowed)
      item.Fail("the range's ends would leave the allowed values: [" + FormatNumber(p.min - p.width / 2) + ", " +
                FormatNumber(p.max + p.width / 2) + "]");
  }
  if (item.Has("start")) {
    p.start = item.Number("start", p.min, p.max);
  } else {
    if (range) {
      p.start = 0.5 * ((*v)[0].get<double>() + (*v)[1].get<double>());
    } else if (v && v->is_number()) {
      p.start = v->get<double>();
    } else if (entry) {
      p.start = engine::ModelParameters{}.*(entry->number);
    } else {
      item.Fail("no \"start\" given, and the scenario has no number at \"" + p.path + "\" to start from");
    }
    if (p.start < p.min || p.start > p.max)
      item.Fail("the start " + FormatNumber(p.start) + " (from the scenario) lies outside the bounds [" +
                FormatNumber(p.min) + ", " + FormatNumber(p.max) + "]; give \"start\" or other bounds");
  }
  item.Finish();
  return p;
}

SeriesMatch ReadSeriesMatch(const JsonReader& item, const observe::Observation& obs) {
  if (!item.IsObject()) item.Fail("expected a series {\"quantity\": ..., \"where\": ..., \"direction\": ...}, found " + item.ValueText());
  SeriesMatch m;
  m.quantity = item.String("quantity");
  m.where = item.String("where");
  m.direction = item.String("direction");
  if (!obs.Find(m.quantity, m.where, m.direction)) {
    std::string list;
    std::set<std::string> seen;
    for (const observe::Series& s : obs.series) {
      const std::string n = s.quantity + " " + s.where + " " + s.direction;
      if (seen.insert(n).second) list += (list.empty() ? "" : ", ") + n;
    }
    item.Fail("the observation has no series " + m.quantity + " " + m.where + " " + m.direction +
              "; expected one of: " + list);
  }
  const double t_end = obs.t0_s + static_cast<double>(obs.bins) * obs.bin_s;
  m.from_s = item.Number("from_s", obs.t0_s, -1e9, 1e9);
  m.to_s = item.Number("to_s", t_end, -1e9, 1e9);
  if (!(m.to_s > m.from_s))
    item.Fail("the window [" + FormatNumber(m.from_s) + ", " + FormatNumber(m.to_s) + "] s is empty; expected from_s < to_s");
  m.window_s = item.Number("window_s", 0.0, 0.0, 1e9);
  if (m.window_s > 0 && m.window_s < obs.bin_s)
    item.At("window_s").Fail("windows shorter than the observation's bins (" + FormatNumber(obs.bin_s) +
                             " s) hold no whole bin; expected 0 (one window) or at least the bin");
  if (m.window_s > 0 && (m.to_s - m.from_s) / m.window_s > 10000)
    item.At("window_s").Fail("more than 10,000 windows; expected a longer window");
  m.relative_error = item.Number("relative_error", 0.0, 0.0, 10.0);
  m.take_max = item.Choice("reduce", "mean", {"mean", "max"}) == "max";
  if (item.Has("simulated_from_s") || item.Has("simulated_to_s")) {
    m.simulated_from_s = item.Number("simulated_from_s", -1e9, 1e9);
    m.simulated_to_s = item.Number("simulated_to_s", -1e9, 1e9);
    if (!(m.simulated_to_s > m.simulated_from_s))
      item.Fail("the simulated window [" + FormatNumber(m.simulated_from_s) + ", " + FormatNumber(m.simulated_to_s) +
                "] s is empty; expected simulated_from_s < simulated_to_s");
    if (m.window_s > 0 && m.window_s < m.to_s - m.from_s)
      item.At("window_s").Fail("a simulated window of its own goes with one observed window; expected window_s 0");
  }
  item.Finish();
  return m;
}

EventMatch ReadEventMatch(const JsonReader& item, const observe::Observation& obs) {
  if (!item.IsObject()) item.Fail("expected events {\"kind\": ..., \"where\": ..., \"direction\": ...}, found " + item.ValueText());
  EventMatch m;
  m.kind = item.Choice("kind", {"stop", "surge"});
  m.where = item.String("where");
  m.direction = item.Choice("direction", {"forward", "backward"});
  if (std::none_of(obs.spec.regions.begin(), obs.spec.regions.end(),
                   [&](const observe::Region& r) { return r.name == m.where; }))
    item.At("where").Fail("the observation has no region \"" + m.where + "\" (events are per region)");
  const double t_end = obs.t0_s + static_cast<double>(obs.bins) * obs.bin_s;
  m.from_s = item.Number("from_s", obs.t0_s, -1e9, 1e9);
  m.to_s = item.Number("to_s", t_end, -1e9, 1e9);
  if (!(m.to_s > m.from_s))
    item.Fail("the window [" + FormatNumber(m.from_s) + ", " + FormatNumber(m.to_s) + "] s is empty; expected from_s < to_s");
  item.Finish();
  return m;
}

// {"recorded": {"kind": "avalanche", "direction", "from_s", "to_s"}}: events
// recorded of the incident, observed times from the scenario's
// timeline.recorded marks, simulated ones from the run's event table.
void ReadRecordedAvalanches(const JsonReader& recorded, const scenario::Scenario& sc, ObservationMatch* m) {
  EventMatch e;
  e.kind = m->recorded_kind;
  e.where = "run";
  e.direction = recorded.String("direction", "crowd");
  double last = 0.0;
  for (const scenario::RecordedMark& mark : sc.timeline.recorded)
    if (mark.kind == m->recorded_kind) {
      observe::Event ev;
      ev.kind = e.kind;
      ev.where = e.where;
      ev.direction = e.direction;
      ev.time_s = mark.time_s;
      m->observation.events.push_back(ev);
      last = std::max(last, mark.time_s);
    }
  if (m->observation.events.empty())
    recorded.Fail("the scenario records no \"" + m->recorded_kind + "\" in timeline.recorded; expected the times of "
                  "the incident's events there (docs/scenarios.md)");
  e.from_s = recorded.Number("from_s", 0.0, -1e9, 1e9);
  e.to_s = recorded.Number("to_s", std::max(sc.run.duration_s, last), -1e9, 1e9);
  if (!(e.to_s > e.from_s)) recorded.Fail("the window is empty; expected from_s < to_s");
  m->events.push_back(e);
}

// {"recorded": {"kind": "fatal", "uncertainty_s", "from_s", "to_s"}}: the
// scenario's recorded fatal clog (its one mark of kind "fatal") as a time,
// against the time from which the run is clogged for good (the window's end
// if it never is: a censored value, the run's last word).
void ReadRecordedFatal(const JsonReader& recorded, const scenario::Scenario& sc, ObservationMatch* m) {
  EventMatch e;
  e.kind = "clog";
  e.where = "run";
  e.direction = "crowd";
  e.first_time = true;
  std::size_t marks = 0;
  for (const scenario::RecordedMark& mark : sc.timeline.recorded)
    if (mark.kind == "fatal") {
      e.recorded_time_s = mark.time_s;
      ++marks;
    }
  if (marks == 0)
    recorded.Fail("the scenario records no \"fatal\" mark in timeline.recorded; expected the time of the incident's "
                  "fatal clog there (docs/scenarios.md)");
  if (marks > 1)
    recorded.Fail("the scenario records " + std::to_string(marks) + " \"fatal\" marks; expected one (the clog that "
                  "lasted is one time)");
  e.recorded_sigma_s = recorded.Number("uncertainty_s", 60.0, 1e-3, 1e6);
  e.from_s = recorded.Number("from_s", 0.0, -1e9, 1e9);
  e.to_s = recorded.Number("to_s", sc.run.duration_s, -1e9, 1e9);
  if (!(e.to_s > e.from_s)) recorded.Fail("the window is empty; expected from_s < to_s");
  if (e.recorded_time_s < e.from_s || e.recorded_time_s > e.to_s)
    recorded.Fail("the window [" + FormatNumber(e.from_s) + ", " + FormatNumber(e.to_s) + "] s leaves out the fatal clog at " +
                  FormatNumber(e.recorded_time_s) + " s; expected a window around it");
  m->events.push_back(e);
}

// The regions of a spec, listed for a message.
std::string RegionNames(const observe::ObservationSpec& spec) {
  std::string list;
  for (const observe::Region& r : spec.regions) list += (list.empty() ? "\"" : ", \"") + r.name + "\"";
  return list;
}

// {"recorded": {"kind": "max_speed", "spec": FILE, "where": REGION, "from_s", "to_s"}}:
// each speed the scenario's timeline.recorded reads from the footage becomes
// a statistic: the largest bin of the run's max_speed series in REGION
// (observed with the spec) within a window around its mark -- by default
// from the mark before it to the mark after it (the part of the incident the
// footage of that moment belongs to: the simulated night need not place its
// avalanches at the recorded times, and the avalanche times are matched
// separately), else the given one.
void ReadRecordedMaxSpeed(const JsonReader& recorded, const scenario::Scenario& sc, const fs::path& dir,
                          ObservationMatch* m) {
  const JsonReader spec_file = recorded.At("spec");
  fs::path file = fs::path(spec_file.AsString());
  if (file.is_relative()) file = (dir / file).lexically_normal();
  try {
    m->observation.spec = observe::ReadObservationSpec(file);
  } catch (const InputError& e) {
    spec_file.Fail(std::string("cannot use the observation spec: ") + e.what());
  }
  const std::string where = recorded.String("where");
  const auto& regions = m->observation.spec.regions;
  if (std::none_of(regions.begin(), regions.end(), [&](const observe::Region& r) { return r.name == where; }))
    recorded.At("where").Fail("the spec has no region \"" + where + "\"; expected one of " + RegionNames(m->observation.spec));
  m->observation.t0_s = 0.0;
  m->observation.bin_s = m->observation.spec.bin_s;
  std::vector<scenario::RecordedMark> marks = sc.timeline.recorded;
  std::stable_sort(marks.begin(), marks.end(), [](const auto& a, const auto& b) { return a.time_s < b.time_s; });
  const bool has_from = recorded.Has("from_s"), has_to = recorded.Has("to_s");
  const double from = recorded.Number("from_s", 0.0, -1e9, 1e9);
  const double to = recorded.Number("to_s", 0.0, -1e9, 1e9);
  for (std::size_t k = 0; k < marks.size(); ++k) {
    if (!marks[k].HasMaxSpeed()) continue;
    SeriesMatch s;
    s.quantity = "max_speed";
    s.where = where;
    s.direction = "all";
    s.take_max = true;
    s.from_s = has_from ? from : (k > 0 ? marks[k - 1].time_s : 0.0);
    s.to_s = has_to ? to : (k + 1 < marks.size() ? marks[k + 1].time_s : std::max(sc.run.duration_s, marks[k].time_s));
    if (!(s.to_s > s.from_s))
      recorded.Fail("the window [" + FormatNumber(s.from_s) + ", " + FormatNumber(s.to_s) + "] s around the mark \"" +
                    marks[k].label + "\" is empty; expected from_s < to_s");
    if (marks[k].time_s < s.from_s || marks[k].time_s > s.to_s)
      recorded.Fail("the window [" + FormatNumber(s.from_s) + ", " + FormatNumber(s.to_s) + "] s leaves out the mark \"" +
                    marks[k].label + "\" at " + FormatNumber(marks[k].time_s) + " s; expected a window around it");
    s.recorded_value = marks[k].max_speed_m_per_s;
    s.recorded_sigma = marks[k].max_speed_uncertainty_m_per_s;
    m->series.push_back(s);
  }
  if (m->series.empty())
    recorded.Fail("the scenario records no speed in timeline.recorded; expected a mark with \"max_speed_m_per_s\" "
                  "and \"max_speed_uncertainty_m_per_s\" (docs/scenarios.md)");
}

// Velocities over the spec's span need frames that close: a run written at
// too few frames per second would measure them over a longer span (slower
// peaks, smoother speeds) than the observation did.
void CheckFramesForVelocities(const JsonReader& item, const observe::ObservationSpec& spec, double output_fps) {
  const int half_span = std::max(1, static_cast<int>(std::lround(spec.velocity_span_s * output_fps / 2.0)));
  const double span = 2.0 * half_span / output_fps;
  if (span > 1.5 * spec.velocity_span_s)
    item.Fail("the runs write " + FormatNumber(output_fps) + " frames/s, so their velocities would span " +
              FormatNumber(span) + " s against the observation's " + FormatNumber(spec.velocity_span_s) +
              " s; expected run.output_fps of at least " + FormatNumber(2.0 / spec.velocity_span_s) + " (in \"set\")");
}

}  // namespace

std::string Parameter::JsonOf(double value) const {
  if (is_range)
    return json::array({value - width / 2, value + width / 2}).dump();
  return json(value).dump();
}

CalibrationSpec ParseCalibration(const std::string& json_text, const std::string& origin, const fs::path& base_dir) {
  const JsonDocument doc = JsonDocument::Parse(json_text, origin);
  const json& document = doc.Json();
  const JsonReader root = doc.Root();
  if (!root.IsObject()) root.Fail("expected a calibration object {\"format\": \"crowdrecon-calibration\", ...}");
  root.Choice("format", {"crowdrecon-calibration"});
  root.Integer("version", 1, 1);
  CalibrationSpec c;
  c.origin = origin;
  c.name = root.String("name", fs::path(origin).stem().string());
  const fs::path dir = fs::absolute(base_dir.empty() ? fs::path(".") : base_dir).lexically_normal();

  // 1. The scenario, "set" and "seeds": a sweep without axes or variants, read
  //    by the sweep's own parser (the JSON paths stay those of this file).
  {
    json sweep = {{"format", "crowdrecon-sweep"}, {"version", 1}, {"name", c.name}};
    for (const char* key : {"scenario", "set", "seeds"})
      if (auto r = root.Find(key)) sweep[key] = Raw(document, *r);
    if (!sweep.contains("scenario")) root.At("scenario");  // the error names the missing key
    c.base = sweep::ParseSweep(sweep.dump(), origin, dir);
    // The objective weighs each statistic by the seeds' spread of it (the
    // seeds' covariance, docs/calibration.md "The objective"): one seed has
    // none (issue 65: it crashed the calibration).
    if (c.base.seeds.size() < 2)
      throw InputError(origin + ": /seeds: " + std::to_string(c.base.seeds.size()) +
                       " seed; expected at least 2 (the objective weighs each statistic by its spread over the "
                       "seeds; 8 or more give its correlations to about +-0.13)");
  }
  json base_scenario = json::parse(sweep::RunScenarioJson(c.base, sweep::RunPlan{0, "base", 0, {}, c.base.seeds[0], ""}));

  // 2. The parameters.
  const JsonReader params = root.At("parameters");
  if (params.Size() == 0) params.Fail("expected at least one parameter to fit");
  if (params.Size() > 8) params.Fail("expected at most 8 parameters (each costs a design's worth of runs)");
  for (std::size_t i = 0; i < params.Size(); ++i) c.parameters.push_back(ReadParameter(params.Element(i), base_scenario, c.parameters));

  // 3. The observations and what to match in each.
  const JsonReader observations = root.At("observations");
  if (observations.Size() == 0) observations.Fail("expected at least one observation file");
  const scenario::Scenario sc = sweep::RunScenarioOf(c.base, sweep::RunPlan{0, "base", 0, {}, c.base.seeds[0], ""});
  c.run_duration_s = sc.run.duration_s;
  for (std::size_t i = 0; i < observations.Size(); ++i) {
    const JsonReader item = observations.Element(i);
    if (!item.IsObject()) item.Fail("expected {\"file\": ..., \"series\": [...]}, found " + item.ValueText());
    ObservationMatch m;
    if (auto recorded = item.Find("recorded")) {
      m.recorded_kind = recorded->Choice("kind", {"avalanche", "max_speed", "fatal"});
      m.observation.method = "recorded";
      m.observation.source_file = c.base.scenario_file.string();
      if (m.recorded_kind == "max_speed") {
        ReadRecordedMaxSpeed(*recorded, sc, dir, &m);
        CheckFramesForVelocities(*recorded, m.observation.spec, sc.run.output_fps);
      } else if (m.recorded_kind == "fatal") {
        ReadRecordedFatal(*recorded, sc, &m);
      } else {
        ReadRecordedAvalanches(*recorded, sc, &m);
      }
      recorded->Finish();
      if (item.Has("file") || item.Has("series") || item.Has("events"))
        item.Fail("\"recorded\" stands alone: an observation is either a file or the scenario's recorded events");
      item.Finish();
      c.observations.push_back(std::move(m));
      continue;
    }
    const JsonReader file = item.At("file");
    m.file = fs::path(file.AsString());
    if (m.file.is_relative()) m.file = (dir / m.file).lexically_normal();
    try {
      m.observation = observe::ReadObservation(m.file);
    } catch (const InputError& e) {
      file.Fail(std::string("cannot use the observation: ") + e.what());
    }
    CheckFramesForVelocities(item, m.observation.spec, sc.run.output_fps);
    m.time_offset_s = item.Number("time_offset_s", 0.0, -1e9, 1e9);
    if (auto series = item.Find("series"))
      for (std::size_t k = 0; k < series->Size(); ++k) m.series.push_back(ReadSeriesMatch(series->Element(k), m.observation));
    if (auto events = item.Find("events"))
      for (std::size_t k = 0; k < events->Size(); ++k) m.events.push_back(ReadEventMatch(events->Element(k), m.observation));
    if (m.series.empty() && m.events.empty()) item.Fail("nothing to match: give \"series\" or \"events\"");
    item.Finish();
    c.observations.push_back(std::move(m));
  }

  // 4. The approach, the starts and the options.
  c.approach = root.Choice("approach", "surrogate", {"surrogate", "gradient"}) == "gradient" ? Approach::kGradient
                                                                                            : Approach::kSurrogate;
  std::vector<double> first;
  for (const Parameter& p : c.parameters) first.push_back(p.start);
  c.starts.push_back(first);
  if (auto starts = root.Find("starts")) {
    for (std::size_t i = 0; i < starts->Size(); ++i) {
      const JsonReader item = starts->Element(i);
      if (!item.IsObject()) item.Fail("expected a starting point {\"parameter.path\": value, ...}, found " + item.ValueText());
      std::vector<double> start = first;
      for (const std::string& key : item.Keys()) {
        const auto it = std::find_if(c.parameters.begin(), c.parameters.end(), [&](const Parameter& p) { return p.path == key; });
        if (it == c.parameters.end()) item.At(key).Fail("\"" + key + "\" is not one of the parameters to fit");
        start[static_cast<std::size_t>(it - c.parameters.begin())] = item.Number(key, it->min, it->max);
      }
      c.starts.push_back(start);
    }
  }
  if (auto o = root.Find("options")) {
    CalibrationOptions& x = c.options;
    x.refinements = static_cast<int>(o->Integer("refinements", x.refinements, 0, 10));
    x.shrink = o->Number("shrink", x.shrink, 0.05, 0.95);
    x.gradient_step = o->Number("gradient_step", x.gradient_step, 1e-4, 0.5);
    x.max_iterations = static_cast<int>(o->Integer("max_iterations", x.max_iterations, 1, 100));
    x.bootstrap = static_cast<int>(o->Integer("bootstrap", x.bootstrap, 0, 100000));
    x.profile_points = static_cast<int>(o->Integer("profile_points", x.profile_points, 0, 101));
    if (x.profile_points == 1) o->At("profile_points").Fail("1 point is no profile; expected 0 (none) or at least 2");
    x.measure_noise = o->Bool("measure_noise", x.measure_noise);
    x.noise_step = o->Number("noise_step", x.noise_step, 1e-6, 0.2);
    x.posterior_steps = static_cast<int>(o->Integer("posterior_steps", x.posterior_steps, 0, 10000000));
    if (x.posterior_steps > 0 && x.posterior_steps < 1000)
      o->At("posterior_steps").Fail("expected 0 (no posterior) or at least 1000 steps per chain");
    o->Finish();
  }
  root.Finish();

  // Every parameter at its bounds and every start must give a valid scenario:
  // checked now, so that a bad path or range never stops a calibration half-way.
  {
    sweep::SweepSpec check = c.base;
    check.seeds = {c.base.seeds[0]};
    check.variants.clear();
    const auto variant = [&](const std::string& name, const std::vector<double>& values) {
      sweep::Variant v{name, {}};
      for (std::size_t k = 0; k < values.size(); ++k) v.set.push_back({c.parameters[k].path, c.parameters[k].JsonOf(values[k])});
      check.variants.push_back(std::move(v));
    };
    for (std::size_t s = 0; s < c.starts.size(); ++s) variant("start" + std::to_string(s), c.starts[s]);
    for (std::size_t k = 0; k < c.parameters.size(); ++k) {
      std::vector<double> lo = c.starts[0], hi = c.starts[0];
      lo[k] = c.parameters[k].min;
      hi[k] = c.parameters[k].max;
      variant("min-" + c.parameters[k].name, lo);
      variant("max-" + c.parameters[k].name, hi);
    }
    sweep::ValidateRuns(check, sweep::ExpandRuns(check));
  }

  // The fingerprint: what a run's outputs depend on besides the values and
  // the seed (the observation specs key the cache's files themselves).
  // The build's sources count too: runs of different sources are never
  // mixed (as in sweeps: sweep::SourceFingerprint).
  std::string f = "crowdrecon sources " + sweep::SourceFingerprint() + "\n" + c.base.scenario_canonical_json + "\n";
  for (const sweep::Override& o : c.base.set) f += o.path + "=" + o.json + "\n";
  for (const Parameter& p : c.parameters)
    f += "param " + p.path + (p.is_range ? " range of width " + FormatNumber(p.width) : std::string()) + "\n";
  c.fingerprint = Sha256Hex(f);
  return c;
}

CalibrationSpec LoadCalibration(const fs::path& file) {
  CalibrationSpec c = ParseCalibration(ReadInputFile(file, "calibration file"), file.string(), file.parent_path());
  c.file = fs::absolute(file);
  return c;
}

}  // namespace crowdrecon::calibrate
