// An ensemble of an incident's runs scored against its recorded marks, and
// its figure (reports/ensemble.hpp; docs/reports.md, "Ensembles of an
// incident").
#include "crowdrecon/reports/ensemble.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "crowdrecon/analysis/plausibility.hpp"
#include "crowdrecon/common/csv.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/json_reader.hpp"
#include "crowdrecon/common/sha256.hpp"
#include "crowdrecon/reports/risk.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/viz/canvas.hpp"
#include "crowdrecon/viz/chart.hpp"
#include "crowdrecon/viz/timeline_figure.hpp"

namespace crowdrecon::reports {

bool EnsembleOptions::IsValid(std::string* error) const {
  const auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(tolerance_s)) return fail("tolerance_s must be a positive number of seconds");
  if (!positive(clog_speed_m_per_s)) return fail("clog_speed_m_per_s must be a positive speed");
  if (!positive(clog_min_s)) return fail("clog_min_s must be a positive number of seconds");
  if (!(std::isfinite(smooth_s) && smooth_s >= 0.0)) return fail("smooth_s must be at least 0 s");
  if (!positive(danger_n)) return fail("danger_n must be a positive force");
  return true;
}

namespace {

std::string LabelOf(const std::filesystem::path& file, const runfile::RunFileReader& reader) {
  const std::string seed = reader.RunValue("seed");
  return seed.empty() ? file.filename().string() : "seed " + seed;
}

std::string Clock(const analysis::RunClock& clock, double t) {
  if (std::isnan(t)) return "never";
  return clock.start.empty() ? FormatFixed(t, 1) + " s" : clock.Text(t);
}

std::string SpreadText(const Spread& s, int decimals, const std::string& unit = "") {
  if (s.runs == 0) return "none";
  const std::string u = unit.empty() ? "" : " " + unit;
  if (s.low == s.high) return FormatFixed(s.median, decimals) + u;
  return FormatFixed(s.median, decimals) + u + " (" + FormatFixed(s.low, decimals) + "–" + FormatFixed(s.high, decimals) + ")";
}

std::string Num(double v, int decimals) { return std::isnan(v) ? "" : FormatFixed(v, decimals); }

std::string Runs(std::size_t n) { return std::to_string(n) + (n == 1 ? " run" : " runs"); }

}  // namespace

namespace {

// A file named in a scenario by its name alone: the same scenario written
// with relative paths in one folder and absolute ones in another is the
// same (the venue itself is compared as the run stored it).
void FileNamesOnly(nlohmann::json& j) {
  if (j.is_object() || j.is_array()) {
    for (nlohmann::json& v : j) FileNamesOnly(v);
  } else if (j.is_string()) {
    const std::filesystem::path p(j.get<std::string>());
    const std::string ext = p.extension().string();
    if (ext == ".json" || ext == ".csv" || ext == ".txt") j = p.filename().string();
  }
}

}  // namespace

namespace {

// What makes runs the seeds of one scenario: the scenario as stored (its
// seed apart, file names only), the seed, the walkable area (by digest).
struct RunIdentity {
  nlohmann::json scenario;
  std::uint64_t seed = 0;
  std::string walkable_sha256;
};

bool IsSummaryFile(const std::filesystem::path& file) { return file.extension() == ".json"; }

EnsembleRunSummary ReadSummary(const std::filesystem::path& file) {
  return ParseEnsembleSummary(ReadInputFile(file, "ensemble run summary"), file.string());
}

RunIdentity IdentityOf(const std::filesystem::path& run) {
  RunIdentity id;
  if (IsSummaryFile(run)) {
    const EnsembleRunSummary summary = ReadSummary(run);
    id.scenario = nlohmann::json::parse(summary.scenario_json);
    id.seed = summary.seed;
    id.walkable_sha256 = summary.walkable_sha256;
    return id;
  }
  const runfile::RunFileReader reader(run);
  id.scenario = nlohmann::json::parse(reader.RunValue("scenario"), nullptr, false);
  if (!id.scenario.is_object())
    throw InputError(run.string() + ": the run holds no scenario of its own (run value \"scenario\"); "
                     "expected a run file written by crowdrecon simulate");
  if (id.scenario.contains("population") && id.scenario["population"].is_object()) {
    nlohmann::json& population = id.scenario["population"];
    if (population.contains("seed") && population["seed"].is_number_unsigned())
      id.seed = population["seed"].get<std::uint64_t>();
    population.erase("seed");
  }
  FileNamesOnly(id.scenario);
  id.walkable_sha256 = Sha256Hex(reader.walkable_wkt());
  return id;
}

}  // namespace

void CheckSeedsOfOneScenario(const std::vector<std::filesystem::path>& runs, const std::string& what,
                             const std::string& apart) {
  RunIdentity first;
  std::map<std::uint64_t, std::filesystem::path> seed_of;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    RunIdentity id = IdentityOf(runs[k]);
    if (k == 0) {
      first = id;
    } else if (id.walkable_sha256 != first.walkable_sha256) {
      throw InputError(runs[k].string() + ": not a seed of the scenario of " + runs[0].string() +
                       " (their walkable areas differ); " + what + " is the seeds of one scenario: " + apart);
    } else if (id.scenario != first.scenario) {
      const nlohmann::json patch = nlohmann::json::diff(first.scenario, id.scenario);
      const std::string path = patch.empty() ? "/" : patch[0].value("path", "/");
      throw InputError(runs[k].string() + ": not a seed of the scenario of " + runs[0].string() + " (they differ at " +
                       path + "); " + what + " is the seeds of one scenario: " + apart);
    }
    const auto [at, added] = seed_of.emplace(id.seed, runs[k]);
    if (!added)
      throw InputError(runs[k].string() + ": the same run as " + at->second.string() + " (seed " +
                       std::to_string(id.seed) + " of the same scenario): each run counts once in " + what);
  }
}

EnsembleRun ReadEnsembleRun(const std::filesystem::path& run_file, const EnsembleOptions& options) {
  if (IsSummaryFile(run_file)) {
    EnsembleRunSummary summary = ReadSummary(run_file);
    const EnsembleOptions& o = summary.options;
    if (o.smooth_s != options.smooth_s || o.area_avalanches != options.area_avalanches ||
        o.danger_n != options.danger_n || o.clog_speed_m_per_s != options.clog_speed_m_per_s ||
        o.clog_min_s != options.clog_min_s)
      throw InputError(run_file.string() + ": summarised with smoothing " + FormatNumber(o.smooth_s) + " s" +
                       (o.area_avalanches ? ", the local reading of avalanches" : "") + ", danger " +
                       FormatNumber(o.danger_n) + " N; this ensemble is read with smoothing " +
                       FormatNumber(options.smooth_s) + " s" + (options.area_avalanches ? ", the local reading" : "") +
                       ", danger " + FormatNumber(options.danger_n) +
                       " N: give the same options, or the run file itself");
    summary.run.run_file = run_file.string();
    return summary.run;
  }
  if (!runfile::IsRunFile(run_file)) throw InputError(run_file.string() + ": not a crowdrecon run file");
  EnsembleRun r;
  r.run_file = run_file.string();
  {
    const runfile::RunFileReader reader(run_file);
    const std::string status = reader.RunValue("status");
    if (status != "complete")
      throw InputError(run_file.string() + ": the run's status is \"" + status +
                       "\"; an ensemble scores finished runs (resume it with crowdrecon simulate --resume)");
    r.label = LabelOf(run_file, reader);
  }
  const analysis::TimelineSeries s = analysis::ComputeTimeline(run_file, options.smooth_s);
  r.clock = s.clock;
  r.end_s = s.time_s.empty() ? 0.0 : s.time_s.back();
  for (const analysis::TimelineMark& a : options.area_avalanches ? analysis::AvalanchesWithAreas(s) : s.avalanches) {
    r.avalanche_s.push_back(a.time_s);
    r.rise_time_s.push_back(a.rise_time_s);
  }
  for (const analysis::TimelineMark& f : s.falls) r.fall_s.push_back(f.time_s);
  r.time_s = s.time_s;
  r.density_per_m2 = analysis::MovingMean(s.time_s, s.density_per_m2, options.smooth_s);
  r.area_names = s.area_names;
  for (const std::vector<double>& a : s.area_density_per_m2)
    r.area_density_per_m2.push_back(analysis::MovingMean(s.time_s, a, options.smooth_s));
  r.recorded = s.recorded;
  r.clog_for_good_s = analysis::ClogForGood(s, options.smooth_s, options.clog_speed_m_per_s, options.clog_min_s);
  RiskOptions risk;
  risk.danger_n = options.danger_n;
  risk.read_contacts = false;  // the loads suffice
  const RunRisk rr = AnalyseRunRisk(run_file, risk);
  r.loads_available = rr.loads_recorded || rr.has_contacts;
  for (const FrameRisk& f : rr.frames)
    if (std::isnan(r.danger_peak_time_s) || f.above_danger > r.danger_peak) {
      r.danger_peak = f.above_danger;
      r.danger_peak_time_s = f.time_s;
    }
  r.peak_density_per_m2 = s.validity.peak_density_per_m2;
  r.peak_equivalent_density_per_m2 = s.validity.peak_equivalent_density_per_m2;
  return r;
}

// ---------------------------------------------------------------------------
// A run's summary (ensembles over several sessions).

namespace {

constexpr const char* kSummaryFormat = "crowdrecon-ensemble-run";

nlohmann::json Nullable(double v) { return std::isnan(v) ? nlohmann::json(nullptr) : nlohmann::json(v); }

// Every `stride`-th value and the last; `digits` > 0 rounds them to that
// many decimals (a figure's series), 0 keeps them exact (scores).
nlohmann::json Numbers(const std::vector<double>& values, std::size_t stride, int digits = 0) {
  const double scale = std::pow(10.0, digits);
  const auto value = [&](double v) { return Nullable(digits > 0 ? std::round(v * scale) / scale : v); };
  nlohmann::json a = nlohmann::json::array();
  for (std::size_t i = 0; i < values.size(); i += stride) a.push_back(value(values[i]));
  if (!values.empty() && (values.size() - 1) % stride != 0) a.push_back(value(values.back()));
  return a;
}

}  // namespace

std::string EnsembleSummaryJson(const std::filesystem::path& run_file, const EnsembleRun& run,
                                const EnsembleOptions& options) {
  const RunIdentity id = IdentityOf(run_file);
  nlohmann::json j = {{"format", kSummaryFormat}, {"version", 1}};
  j["run_file"] = run_file.filename().string();
  j["profile"] = EnsembleRunProfile(run_file);
  j["run_sha256"] = Sha256OfFile(run_file);
  j["label"] = run.label;
  j["seed"] = id.seed;
  j["scenario"] = id.scenario;
  j["walkable_sha256"] = id.walkable_sha256;
  j["options"] = {{"smooth_s", options.smooth_s},
                  {"area_avalanches", options.area_avalanches},
                  {"danger_n", options.danger_n},
                  {"clog_speed_m_per_s", options.clog_speed_m_per_s},
                  {"clog_min_s", options.clog_min_s}};
  j["clock"] = {{"start", run.clock.start}, {"scale", run.clock.scale}};
  j["end_s"] = run.end_s;
  j["avalanche_s"] = Numbers(run.avalanche_s, 1);
  j["rise_time_s"] = Numbers(run.rise_time_s, 1);
  j["fall_s"] = Numbers(run.fall_s, 1);
  j["clog_for_good_s"] = Nullable(run.clog_for_good_s);
  j["danger_peak"] = run.danger_peak;
  j["danger_peak_time_s"] = Nullable(run.danger_peak_time_s);
  j["loads_available"] = run.loads_available;
  j["peak_density_per_m2"] = run.peak_density_per_m2;
  j["peak_equivalent_density_per_m2"] = run.peak_equivalent_density_per_m2;
  j["recorded"] = nlohmann::json::array();
  for (const analysis::TimelineMark& m : run.recorded)
    j["recorded"].push_back({{"time_s", m.time_s}, {"label", m.label}, {"kind", m.kind}});
  const std::size_t stride = std::max<std::size_t>(1, (run.time_s.size() + kSummaryPoints - 1) / kSummaryPoints);
  j["series"] = {{"time_s", Numbers(run.time_s, stride, 3)}, {"density_per_m2", Numbers(run.density_per_m2, stride, 4)}};
  j["series"]["areas"] = nlohmann::json::array();
  for (std::size_t a = 0; a < run.area_names.size(); ++a)
    j["series"]["areas"].push_back({{"name", run.area_names[a]},
                                    {"density_per_m2", Numbers(run.area_density_per_m2[a], stride, 4)}});
  return j.dump(1) + "\n";
}

EnsembleRunSummary ParseEnsembleSummary(const std::string& text, const std::string& origin) {
  const JsonDocument doc = JsonDocument::Parse(text, origin);
  const JsonReader root = doc.Root();
  if (!root.IsObject()) root.Fail("expected a run's summary for an ensemble (an object), found " + root.ValueText());
  if (root.String("format") != kSummaryFormat)
    root.At("format").Fail(std::string("expected \"") + kSummaryFormat + "\" (timeline --summaries), found " +
                           root.At("format").ValueText());
  (void)root.Integer("version", 1, 1);
  const auto number = [](const JsonReader& r) { return r.AsNumber(-1e12, 1e12); };
  const auto nullable = [&](const JsonReader& r) {
    return r.IsNull() ? std::numeric_limits<double>::quiet_NaN() : number(r);
  };
  const auto list = [&](const JsonReader& r, bool nulls) {
    if (!r.IsArray()) r.Fail("expected a list of numbers, found " + r.ValueText());
    std::vector<double> v;
    for (std::size_t k = 0; k < r.Size(); ++k) {
      const JsonReader e = r.Element(k);
      if (e.IsNull() && !nulls) e.Fail("expected a number, found null");
      v.push_back(nullable(e));
    }
    return v;
  };
  EnsembleRunSummary s;
  EnsembleRun& r = s.run;
  (void)root.String("run_file");
  s.profile = root.String("profile");
  s.run_sha256 = root.String("run_sha256");
  r.label = root.String("label");
  s.seed = static_cast<std::uint64_t>(root.Integer("seed", 0, std::numeric_limits<long long>::max()));
  const JsonReader scenario = root.At("scenario");
  if (!scenario.IsObject()) scenario.Fail("expected the run's scenario (an object), found " + scenario.ValueText());
  s.scenario_json = scenario.Raw().dump();
  s.walkable_sha256 = root.String("walkable_sha256");
  const JsonReader o = root.At("options");
  s.options.smooth_s = o.Number("smooth_s", 0.0, 3600.0);
  s.options.area_avalanches = o.Bool("area_avalanches", false);
  s.options.danger_n = o.Number("danger_n", 1e-9, 1e9);
  s.options.clog_speed_m_per_s = o.Number("clog_speed_m_per_s", 0.0, 100.0);
  s.options.clog_min_s = o.Number("clog_min_s", 0.0, 1e9);
  o.Finish();
  const JsonReader clock = root.At("clock");
  r.clock.start = clock.String("start");
  r.clock.scale = clock.Number("scale", 1e-6, 1e6);
  clock.Finish();
  r.end_s = number(root.At("end_s"));
  r.avalanche_s = list(root.At("avalanche_s"), false);
  r.rise_time_s = list(root.At("rise_time_s"), true);
  if (r.rise_time_s.size() != r.avalanche_s.size())
    root.At("rise_time_s").Fail("expected one rise time (or null) per avalanche (" + std::to_string(r.avalanche_s.size()) + ")");
  r.fall_s = list(root.At("fall_s"), false);
  r.clog_for_good_s = nullable(root.At("clog_for_good_s"));
  r.danger_peak = static_cast<std::size_t>(root.Integer("danger_peak", 0, 1000000000));
  r.danger_peak_time_s = nullable(root.At("danger_peak_time_s"));
  r.loads_available = root.Bool("loads_available", false);
  r.peak_density_per_m2 = root.Number("peak_density_per_m2", 0.0, 1e6);
  r.peak_equivalent_density_per_m2 = root.Number("peak_equivalent_density_per_m2", 0.0, 1e6);
  const JsonReader recorded = root.At("recorded");
  if (!recorded.IsArray()) recorded.Fail("expected a list of recorded marks, found " + recorded.ValueText());
  for (std::size_t k = 0; k < recorded.Size(); ++k) {
    const JsonReader m = recorded.Element(k);
    analysis::TimelineMark mark;
    mark.time_s = m.Number("time_s", -1e12, 1e12);
    mark.label = m.String("label");
    mark.kind = m.String("kind");
    m.Finish();
    r.recorded.push_back(mark);
  }
  const JsonReader series = root.At("series");
  r.time_s = list(series.At("time_s"), false);
  r.density_per_m2 = list(series.At("density_per_m2"), true);
  if (r.density_per_m2.size() != r.time_s.size())
    series.At("density_per_m2").Fail("expected one value per time (" + std::to_string(r.time_s.size()) + ")");
  const JsonReader areas = series.At("areas");
  if (!areas.IsArray()) areas.Fail("expected a list of areas, found " + areas.ValueText());
  for (std::size_t a = 0; a < areas.Size(); ++a) {
    const JsonReader area = areas.Element(a);
    r.area_names.push_back(area.String("name"));
    r.area_density_per_m2.push_back(list(area.At("density_per_m2"), true));
    if (r.area_density_per_m2.back().size() != r.time_s.size())
      area.At("density_per_m2").Fail("expected one value per time (" + std::to_string(r.time_s.size()) + ")");
    area.Finish();
  }
  series.Finish();
  root.Finish();
  return s;
}

std::string EnsembleRunProfile(const std::filesystem::path& run_or_summary) {
  if (IsSummaryFile(run_or_summary)) return ReadSummary(run_or_summary).profile;
  return runfile::RunFileReader(run_or_summary).RunValue("profile");
}

std::string EnsembleRunScenarioName(const std::filesystem::path& run_or_summary) {
  const nlohmann::json scenario =
      IsSummaryFile(run_or_summary)
          ? nlohmann::json::parse(ReadSummary(run_or_summary).scenario_json)
          : nlohmann::json::parse(runfile::RunFileReader(run_or_summary).RunValue("scenario"), nullptr, false);
  return scenario.is_object() && scenario.contains("name") && scenario["name"].is_string()
             ? scenario["name"].get<std::string>()
             : "";
}

OutputKind EnsembleSummaryOutput() {
  return {"ensemble run summary", false, [](const std::filesystem::path& f) {
            try {
              const nlohmann::json j = nlohmann::json::parse(ReadInputFile(f, "ensemble run summary"));
              return j.is_object() && j.value("format", "") == kSummaryFormat;
            } catch (...) {
              return false;
            }
          }};
}

EnsembleScore ScoreEnsemble(std::vector<EnsembleRun> runs, const EnsembleOptions& options) {
  if (std::string error; !options.IsValid(&error)) throw InputError("ensemble options: " + error);
  if (runs.empty()) throw InputError("an ensemble needs at least one run");
  // Runs of one seed under different settings (a sweep's variants) are told
  // apart by their files' names.
  std::map<std::string, int> uses;
  for (const EnsembleRun& r : runs) ++uses[r.label];
  for (EnsembleRun& r : runs)
    if (uses[r.label] > 1) r.label = std::filesystem::path(r.run_file).stem().string();
  const auto same_marks = [](const std::vector<analysis::TimelineMark>& a, const std::vector<analysis::TimelineMark>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t k = 0; k < a.size(); ++k)
      if (a[k].time_s != b[k].time_s || a[k].kind != b[k].kind || a[k].label != b[k].label) return false;
    return true;
  };
  for (const EnsembleRun& r : runs)
    if (!same_marks(r.recorded, runs.front().recorded) || r.clock != runs.front().clock)
      throw InputError(r.run_file + ": its recorded marks or clock differ from those of " + runs.front().run_file +
                       "; an ensemble is runs of one incident's scenario");
  EnsembleScore s;
  s.options = options;
  s.runs = std::move(runs);
  for (const analysis::TimelineMark& m : s.runs.front().recorded) {
    if (m.kind == "avalanche") s.avalanches.push_back({m, 0, {}});
    if (m.kind == "fatal") s.fatal.push_back(m);
  }
  std::sort(s.avalanches.begin(), s.avalanches.end(),
            [](const RecordedScore& a, const RecordedScore& b) { return a.mark.time_s < b.mark.time_s; });
  const auto near = [&](double a, double b) { return std::abs(a - b) <= options.tolerance_s; };
  std::vector<double> unmatched, clog, clog_minus_fatal, falls_before, danger, density, equivalent, count, rise;
  for (const EnsembleRun& r : s.runs) {
    for (RecordedScore& rec : s.avalanches) {
      const bool hit = std::any_of(r.avalanche_s.begin(), r.avalanche_s.end(), [&](double t) { return near(t, rec.mark.time_s); });
      rec.matched.push_back(hit);
      rec.runs_matching += hit;
    }
    std::size_t none = 0;
    for (double t : r.avalanche_s)
      none += std::none_of(s.avalanches.begin(), s.avalanches.end(), [&](const RecordedScore& rec) { return near(t, rec.mark.time_s); });
    s.unmatched.push_back(none);
    std::size_t before = 0;
    for (double t : r.fall_s) before += std::isnan(r.clog_for_good_s) || t <= r.clog_for_good_s;
    s.falls_before_clog.push_back(before);
    s.runs_clogging_for_good += !std::isnan(r.clog_for_good_s);
    unmatched.push_back(static_cast<double>(none));
    clog.push_back(r.clog_for_good_s);
    clog_minus_fatal.push_back(s.fatal.empty() ? std::numeric_limits<double>::quiet_NaN() : r.clog_for_good_s - s.fatal.front().time_s);
    falls_before.push_back(static_cast<double>(before));
    danger.push_back(r.loads_available ? static_cast<double>(r.danger_peak) : std::numeric_limits<double>::quiet_NaN());
    density.push_back(r.peak_density_per_m2);
    equivalent.push_back(r.peak_equivalent_density_per_m2);
    count.push_back(static_cast<double>(r.avalanche_s.size()));
    rise.insert(rise.end(), r.rise_time_s.begin(), r.rise_time_s.end());
  }
  s.rise_time_spread = SpreadOf(rise);
  s.unmatched_spread = SpreadOf(unmatched);
  s.clog_spread = SpreadOf(clog);
  s.clog_minus_fatal_spread = SpreadOf(clog_minus_fatal);
  s.falls_before_clog_spread = SpreadOf(falls_before);
  s.danger_spread = SpreadOf(danger);
  s.density_spread = SpreadOf(density);
  s.equivalent_density_spread = SpreadOf(equivalent);
  s.avalanche_count_spread = SpreadOf(count);
  return s;
}

std::string EnsembleScore::Markdown() const { return EnsemblesMarkdown({{"", this}}); }
std::string EnsembleScore::Csv() const { return EnsemblesCsv({{"", this}}); }

void CheckComparable(const std::vector<LabelledEnsemble>& ensembles) {
  if (ensembles.empty()) throw InputError("no ensemble to score");
  const EnsembleRun& first = ensembles.front().score->runs.front();
  for (const LabelledEnsemble& e : ensembles) {
    const EnsembleRun& r = e.score->runs.front();
    bool same = r.recorded.size() == first.recorded.size() && r.clock == first.clock &&
                e.score->options.tolerance_s == ensembles.front().score->options.tolerance_s;
    for (std::size_t k = 0; same && k < r.recorded.size(); ++k)
      same = r.recorded[k].time_s == first.recorded[k].time_s && r.recorded[k].kind == first.recorded[k].kind &&
             r.recorded[k].label == first.recorded[k].label;
    if (!same)
      throw InputError(r.run_file + " (" + e.label + "): its recorded marks, clock or tolerance differ from those of " +
                       first.run_file + " (" + ensembles.front().label +
                       "); ensembles compared side by side are runs of one incident, scored with one tolerance");
  }
}

std::string EnsemblesMarkdown(const std::vector<LabelledEnsemble>& ensembles) {
  CheckComparable(ensembles);
  std::ostringstream o;
  const EnsembleScore& head = *ensembles.front().score;
  const analysis::RunClock clock = head.runs.front().clock;
  const bool several = ensembles.size() > 1;
  // One column per ensemble (one ensemble: the table of before, unlabelled).
  const auto row = [&](const std::string& what, const std::function<std::string(const EnsembleScore&)>& cell) {
    o << "| " << what << " |";
    for (const LabelledEnsemble& e : ensembles) o << ' ' << cell(*e.score) << " |";
    o << '\n';
  };
  const auto rule = [&](int leading) {
    o << '|';
    for (int k = 0; k < leading; ++k) o << " --- |";
    for (std::size_t k = 0; k < ensembles.size(); ++k) o << " --- |";
    o << '\n';
  };
  o << "| recorded | at | runs with an avalanche within ±" << FormatNumber(head.options.tolerance_s) << " s";
  if (several) {
    o << ": " << ensembles.front().label;
    for (std::size_t k = 1; k < ensembles.size(); ++k) o << " | " << ensembles[k].label;
  }
  o << " |\n";
  rule(2);
  for (std::size_t a = 0; a < head.avalanches.size(); ++a) {
    o << "| " << head.avalanches[a].mark.label << " | " << Clock(clock, head.avalanches[a].mark.time_s) << " |";
    for (const LabelledEnsemble& e : ensembles) {
      const std::size_t n = e.score->runs.size(), hits = e.score->avalanches[a].runs_matching;
      o << ' ' << hits << " of " << n << " ("
        << FormatFixed(100.0 * static_cast<double>(hits) / static_cast<double>(n), 0) << " %) |";
    }
    o << '\n';
  }
  if (several) {
    o << "\n| over the runs |";
    for (const LabelledEnsemble& e : ensembles)
      o << ' ' << e.label << " (" << Runs(e.score->runs.size()) << "): median (range) |";
    o << '\n';
  } else {
    o << "\n| over the " << Runs(head.runs.size()) << " | median (range) |\n";
  }
  rule(1);
  row("avalanches in the run", [](const EnsembleScore& s) { return SpreadText(s.avalanche_count_spread, 1); });
  row("of them matching no recorded avalanche", [](const EnsembleScore& s) { return SpreadText(s.unmatched_spread, 1); });
  row("rise time of the avalanches (all runs' together; a free start takes 0.17 s)", [](const EnsembleScore& s) {
    return SpreadText(s.rise_time_spread, 2, "s") +
           (s.rise_time_spread.runs > 0 ? " over " + std::to_string(s.rise_time_spread.runs) + " avalanches" : "");
  });
  row("runs whose venue clogs for good", [](const EnsembleScore& s) {
    return std::to_string(s.runs_clogging_for_good) + " of " + std::to_string(s.runs.size());
  });
  const bool any_clog = std::any_of(ensembles.begin(), ensembles.end(),
                                    [](const LabelledEnsemble& e) { return e.score->clog_spread.runs > 0; });
  if (any_clog) {
    row("it clogs for good at", [&](const EnsembleScore& s) {
      if (s.clog_spread.runs == 0) return std::string("never");
      std::string text = Clock(clock, s.clog_spread.median) + " (" + Clock(clock, s.clog_spread.low) + "–" +
                         Clock(clock, s.clog_spread.high) + ")";
      if (!s.fatal.empty()) text += "; recorded fatal clog " + Clock(clock, s.fatal.front().time_s);
      return text;
    });
    if (!head.fatal.empty())
      row("clog for good minus the recorded fatal clog", [](const EnsembleScore& s) {
        return s.clog_spread.runs == 0 ? std::string("never") : SpreadText(s.clog_minus_fatal_spread, 0, "s");
      });
  }
  row("falls before the clog for good (all falls where none)",
      [](const EnsembleScore& s) { return SpreadText(s.falls_before_clog_spread, 1); });
  row("people in the danger zone (chest load above " + FormatNumber(head.options.danger_n) +
          " N, 1-s mean) at the worst moment",
      [](const EnsembleScore& s) { return SpreadText(s.danger_spread, 1); });
  row("peak local density, model persons/m² (~1 m²)", [](const EnsembleScore& s) { return SpreadText(s.density_spread, 1); });
  row("the same floor covered by real-size persons/m²",
      [](const EnsembleScore& s) { return SpreadText(s.equivalent_density_spread, 1); });
  for (const LabelledEnsemble& e : ensembles) {
    const EnsembleScore& s = *e.score;
    if (several) o << "\n**" << e.label << "** (" << Runs(s.runs.size()) << ")\n";
    o << "\n| run | avalanches (matching none) | falls | clogs for good | danger peak | peak density (real-size) |\n";
    o << "| --- | --- | --- | --- | --- | --- |\n";
    for (std::size_t k = 0; k < s.runs.size(); ++k) {
      const EnsembleRun& r = s.runs[k];
      o << "| " << r.label << " | " << r.avalanche_s.size() << " (" << s.unmatched[k] << ") | " << r.fall_s.size()
        << " | " << Clock(clock, r.clog_for_good_s) << " | "
        << (r.loads_available ? std::to_string(r.danger_peak) : "no loads") << " | "
        << FormatFixed(r.peak_density_per_m2, 1) << " (" << FormatFixed(r.peak_equivalent_density_per_m2, 1) << ") |\n";
    }
  }
  return o.str();
}

std::string EnsemblesCsv(const std::vector<LabelledEnsemble>& ensembles) {
  CheckComparable(ensembles);
  std::ostringstream o;
  const bool several = ensembles.size() > 1;
  o << "run_file,label,avalanches,avalanches_matching_none";
  for (std::size_t a = 0; a < ensembles.front().score->avalanches.size(); ++a) o << ",matches_recorded_" << (a + 1);
  o << ",falls,falls_before_clog,clog_for_good_s,danger_peak,danger_peak_time_s,peak_density_per_m2,"
       "peak_equivalent_density_per_m2,end_s"
    << (several ? ",ensemble" : "") << "\n";
  for (const LabelledEnsemble& e : ensembles) {
    const EnsembleScore& s = *e.score;
    for (std::size_t k = 0; k < s.runs.size(); ++k) {
      const EnsembleRun& r = s.runs[k];
      o << CsvField(r.run_file) << ',' << CsvField(r.label) << ',' << r.avalanche_s.size() << ',' << s.unmatched[k];
      for (const RecordedScore& rec : s.avalanches) o << ',' << (rec.matched[k] ? 1 : 0);
      o << ',' << r.fall_s.size() << ',' << s.falls_before_clog[k] << ',' << Num(r.clog_for_good_s, 2) << ','
        << (r.loads_available ? std::to_string(r.danger_peak) : "") << ',' << Num(r.danger_peak_time_s, 2) << ','
        << Num(r.peak_density_per_m2, 3) << ',' << Num(r.peak_equivalent_density_per_m2, 3) << ',' << Num(r.end_s, 2);
      if (several) o << ',' << CsvField(e.label);
      o << '\n';
    }
  }
  return o.str();
}

OutputKind EnsembleScoresOutput() {
  return {"ensemble score file", false, [](const std::filesystem::path& f) {
            return FileStartsWith(f, "| recorded | at | runs with an avalanche within") ||
                   FileStartsWith(f, "run_file,label,avalanches,avalanches_matching_none");
          }};
}

// ---------------------------------------------------------------------------
// The figure.

namespace {

constexpr double kWidth = 1400, kLeft = 150, kRight = 1130, kTop = 96, kDensity = 170, kRow = 34;
const viz::Color kInk = viz::Color::Hex(0x222222), kGrid = viz::Color::Hex(0xe3e3e3);
const viz::Color kFatal = viz::RecordedMarkStyleOf("fatal").color, kDetected = viz::Color::Hex(0x6a3d9a),
                 kClog = viz::Color::Hex(0x525252);

// Each ensemble's colour in a figure of several (one ensemble: the blue of before).
viz::Color EnsembleColor(std::size_t k) {
  static const std::uint32_t kColors[] = {0x2166ac, 0xd95f02, 0x1b9e77, 0x7570b3};
  return viz::Color::Hex(kColors[k % 4], 0.55);
}

}  // namespace

void DrawEnsembleFigure(const EnsembleScore& score, const std::string& title, const std::filesystem::path& file) {
  DrawEnsemblesFigure({{"", &score}}, title, file);
}

void DrawEnsemblesFigure(const std::vector<LabelledEnsemble>& ensembles, const std::string& title,
                         const std::filesystem::path& file) {
  CheckComparable(ensembles);
  const bool several = ensembles.size() > 1;
  const EnsembleScore& head = *ensembles.front().score;
  const EnsembleRun& first = head.runs.front();
  // Rows: each ensemble's runs, under a row with its name when there are several.
  struct Row {
    const EnsembleScore* score = nullptr;
    std::size_t run = 0;  // in score->runs
    std::string heading;  // a heading row (no run)
  };
  std::vector<Row> rows;
  for (const LabelledEnsemble& e : ensembles) {
    if (several) rows.push_back({nullptr, 0, e.label + " (" + Runs(e.score->runs.size()) + ")"});
    for (std::size_t k = 0; k < e.score->runs.size(); ++k) rows.push_back({e.score, k, ""});
  }
  const std::size_t n = rows.size();
  // The density panel grows with the legend's lines for measurement areas and ensembles.
  const double density_h = kDensity + (several ? 22.0 * static_cast<double>(ensembles.size() - 1)
                                               : 22.0 * static_cast<double>(first.area_names.size()));
  const double rows_top = kTop + density_h + 30;
  const double height = rows_top + static_cast<double>(n) * kRow + 70;
  viz::Canvas canvas(file, {0, 0}, {kWidth, height}, 1.0, 0.0);
  const auto P = [&](double x, double y) { return Vec2{x, height - y}; };
  const analysis::RunClock clock = first.clock;
  double t1 = 1.0;
  for (const LabelledEnsemble& e : ensembles)
    for (const EnsembleRun& r : e.score->runs) t1 = std::max(t1, r.end_s);
  const double t0 = 0.0;
  const auto X = [&](double t) { return kLeft + (std::clamp(t, t0, t1) - t0) / (t1 - t0) * (kRight - kLeft); };
  canvas.FillPolygon({P(0, 0), P(kWidth, 0), P(kWidth, height), P(0, height)}, viz::Color::White());
  canvas.TextPxAligned(kLeft, 26, title, 18, 0.0, 0.5, kInk, 0.0, true, kWidth - kLeft - 20);
  std::string counted;
  for (const LabelledEnsemble& e : ensembles)
    counted += (counted.empty() ? "" : ", ") + Runs(e.score->runs.size()) +
               (several ? " " + e.label : "");
  canvas.TextPxAligned(kLeft, 52,
                       counted + "; a run's avalanche matches a recorded one within ±" +
                           FormatNumber(head.options.tolerance_s) + " s (shaded); density: centred " +
                           FormatNumber(head.options.smooth_s) + "-s means",
                       12, 0.0, 0.5, viz::Color::Hex(0x555555), 0.0, false, kWidth - kLeft - 20);
  // Density panel.
  double d_hi = 1.0;
  for (const LabelledEnsemble& e : ensembles)
    for (const EnsembleRun& r : e.score->runs) {
      for (double d : r.density_per_m2)
        if (!std::isnan(d)) d_hi = std::max(d_hi, d);
      for (const std::vector<double>& area : r.area_density_per_m2)
        for (double d : area)
          if (!std::isnan(d)) d_hi = std::max(d_hi, d);
    }
  d_hi = std::ceil(d_hi / 2.0) * 2.0;
  const double top = kTop, bottom = kTop + density_h;
  const auto Y = [&](double v) { return bottom - std::clamp(v / d_hi, 0.0, 1.0) * (bottom - top); };
  const double d_step = d_hi <= 6 ? 1.0 : d_hi <= 12 ? 2.0 : d_hi <= 30 ? 5.0 : 10.0;
  for (double v = 0.0; v <= d_hi + 1e-9; v += d_step) {
    canvas.Line(P(kLeft, Y(v)), P(kRight, Y(v)), kGrid, 1.0);
    canvas.TextPxAligned(kLeft - 8, Y(v), FormatNumber(v), 12, 1.0, 0.5, kInk);
  }
  canvas.TextPxAligned(kLeft - 56, 0.5 * (top + bottom), "persons / m^2", 12, 0.5, 1.0, kInk, 1.5707963267948966);
  // Recorded marks and tolerance bands across the density panel and every row.
  const double rows_bottom = rows_top + static_cast<double>(n) * kRow;
  for (const RecordedScore& r : head.avalanches) {
    const double a = X(r.mark.time_s - head.options.tolerance_s), b = X(r.mark.time_s + head.options.tolerance_s);
    canvas.FillPolygon({P(a, rows_top), P(b, rows_top), P(b, rows_bottom), P(a, rows_bottom)},
                       viz::Color::Hex(0xfdd0a2, 0.45));
  }
  for (const analysis::TimelineMark& m : first.recorded) {
    if (m.time_s < t0 || m.time_s > t1) continue;
    const viz::RecordedMarkStyle style = viz::RecordedMarkStyleOf(m.kind);
    for (auto [y0, y1] : {std::pair{top, bottom}, std::pair{rows_top, rows_bottom}})
      canvas.StrokePolyline({P(X(m.time_s), y0), P(X(m.time_s), y1)}, style.color, style.width_px, style.dashed);
  }
  for (std::size_t g = 0; g < ensembles.size(); ++g)
    for (const EnsembleRun& r : ensembles[g].score->runs) {
      std::vector<Vec2> line;
      for (std::size_t i = 0; i < r.time_s.size(); ++i)
        if (!std::isnan(r.density_per_m2[i])) line.push_back(P(X(r.time_s[i]), Y(r.density_per_m2[i])));
      if (line.size() >= 2) canvas.StrokePolyline(line, EnsembleColor(g), 1.4);
      // Each measurement area's own density (dashed, one colour per area;
      // one ensemble only: with several, which ensemble a dashed line is of
      // could not be told).
      for (std::size_t a = 0; !several && a < r.area_density_per_m2.size(); ++a) {
        std::vector<Vec2> dashed;
        for (std::size_t i = 0; i < r.time_s.size() && i < r.area_density_per_m2[a].size(); ++i)
          if (!std::isnan(r.area_density_per_m2[a][i])) dashed.push_back(P(X(r.time_s[i]), Y(r.area_density_per_m2[a][i])));
        if (dashed.size() >= 2) canvas.StrokePolyline(dashed, viz::AreaColor(a), 1.2, true);
      }
    }
  canvas.StrokePolygon({P(kLeft, top), P(kRight, top), P(kRight, bottom), P(kLeft, bottom)}, kInk, 1.0);
  // Recorded marks' labels over the density panel.
  viz::DrawRecordedMarkLabels(canvas, first.recorded, t0, t1, X, top);
  // One row per run (and a heading row per ensemble when there are several).
  std::size_t shade = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double y0 = rows_top + static_cast<double>(k) * kRow, yc = y0 + 0.5 * kRow;
    if (rows[k].score == nullptr) {
      canvas.FillPolygon({P(0, y0), P(kWidth, y0), P(kWidth, y0 + kRow), P(0, y0 + kRow)}, viz::Color::White());
      canvas.TextPxAligned(12, yc, rows[k].heading, 13, 0.0, 0.5, kInk, 0.0, true, kWidth - 24);
      canvas.Line(P(kLeft, y0 + kRow), P(kRight, y0 + kRow), kInk, 1.0);
      shade = 0;
      continue;
    }
    const EnsembleScore& score = *rows[k].score;
    const std::size_t run = rows[k].run;
    const EnsembleRun& r = score.runs[run];
    if (shade++ % 2 == 1)
      canvas.FillPolygon({P(kLeft, y0), P(kRight, y0), P(kRight, y0 + kRow), P(kLeft, y0 + kRow)},
                         viz::Color::Hex(0x000000, 0.04));
    canvas.TextPxAligned(kLeft - 8, yc, r.label, 12, 1.0, 0.5, kInk, 0.0, false, kLeft - 16);
    canvas.Line(P(kLeft, yc), P(X(r.end_s), yc), kGrid, 1.0);
    if (!std::isnan(r.clog_for_good_s))
      canvas.FillPolygon({P(X(r.clog_for_good_s), yc - 4), P(X(r.end_s), yc - 4), P(X(r.end_s), yc + 4),
                          P(X(r.clog_for_good_s), yc + 4)},
                         kClog);
    for (double t : r.avalanche_s) {
      const double x = X(t);
      canvas.FillPolygon({P(x, yc + 8), P(x - 7, yc - 6), P(x + 7, yc - 6)}, kDetected);
    }
    for (double t : r.fall_s) {
      const double x = X(t);
      canvas.Line(P(x - 5, yc - 5), P(x + 5, yc + 5), kFatal, 2.0);
      canvas.Line(P(x - 5, yc + 5), P(x + 5, yc - 5), kFatal, 2.0);
    }
    const std::size_t matched = static_cast<std::size_t>(std::count_if(
        score.avalanches.begin(), score.avalanches.end(), [&](const RecordedScore& rec) { return rec.matched[run]; }));
    canvas.TextPxAligned(kRight + 10, yc,
                         std::to_string(r.avalanche_s.size()) + " aval., " + std::to_string(matched) + "/" +
                             std::to_string(score.avalanches.size()) + " matched, " + std::to_string(r.fall_s.size()) +
                             (r.fall_s.size() == 1 ? " fall" : " falls"),
                         11, 0.0, 0.5, kInk, 0.0, false, kWidth - kRight - 16);
  }
  canvas.StrokePolygon({P(kLeft, rows_top), P(kRight, rows_top), P(kRight, rows_bottom), P(kLeft, rows_bottom)}, kInk, 1.0);
  // Time axis.
  const double span = t1 - t0;
  double tick = 600.0;
  for (double c : {5.0, 10.0, 30.0, 60.0, 300.0, 600.0, 900.0, 1800.0, 3600.0})
    if (span / c <= 12.0) {
      tick = c;
      break;
    }
  for (double t = 0.0; t <= t1 + 1e-9; t += tick) {
    canvas.Line(P(X(t), rows_bottom), P(X(t), rows_bottom + 4), kInk, 1.0);
    canvas.Line(P(X(t), bottom), P(X(t), bottom + 4), kInk, 1.0);
    canvas.TextPxAligned(X(t), rows_bottom + 8, clock.TickText(t, tick), 12, 0.5, 0.0, kInk);
  }
  canvas.TextPxAligned(0.5 * (kLeft + kRight), rows_bottom + 30,
                       clock.AxisLabel(), 13, 0.5, 0.0, kInk);
  // Legend, right of the density panel.
  double ly = top + 4;
  const double lx = kRight + 12;
  const auto text = [&](const std::string& t) {
    canvas.TextPxAligned(lx + 30, ly + 6, t, 12, 0.0, 0.5, kInk, 0.0, false, kWidth - lx - 36);
    ly += 22;
  };
  for (std::size_t g = 0; g < ensembles.size(); ++g) {
    canvas.StrokePolyline({P(lx, ly + 6), P(lx + 24, ly + 6)}, EnsembleColor(g), 2.0);
    text(several ? "density: " + ensembles[g].label : "density, one line per run");
  }
  for (std::size_t a = 0; !several && a < first.area_names.size(); ++a) {
    canvas.StrokePolyline({P(lx, ly + 6), P(lx + 24, ly + 6)}, viz::AreaColor(a), 2.0, true);
    text("density in " + first.area_names[a]);
  }
  for (const std::string& kind : viz::RecordedMarkKinds(first.recorded, t0, t1)) {
    const viz::RecordedMarkStyle style = viz::RecordedMarkStyleOf(kind);
    canvas.StrokePolyline({P(lx, ly + 6), P(lx + 24, ly + 6)}, style.color, std::max(2.0, style.width_px), style.dashed);
    text(style.legend);
  }
  canvas.FillPolygon({P(lx + 12, ly + 13), P(lx + 5, ly + 1), P(lx + 19, ly + 1)}, kDetected);
  text("avalanche in a run");
  canvas.Line(P(lx + 7, ly + 1), P(lx + 17, ly + 11), kFatal, 2.0);
  canvas.Line(P(lx + 7, ly + 11), P(lx + 17, ly + 1), kFatal, 2.0);
  text("fall in a run");
  canvas.FillPolygon({P(lx, ly + 2), P(lx + 24, ly + 2), P(lx + 24, ly + 10), P(lx, ly + 10)}, kClog);
  text("clogged for good");
  canvas.Finish();
}

}  // namespace crowdrecon::reports
