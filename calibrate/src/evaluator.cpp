#include "evaluator.hpp"


#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "crowdrecon/analysis/timeline_series.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/sha256.hpp"
#include "crowdrecon/observe/trajectories.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/sweep/sweep_runner.hpp"

namespace crowdrecon::calibrate {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const std::string kRunEvents = ObservationMatch::kFromRunEvents;
const std::string kRunClog = ObservationMatch::kFromRunClog;

// The run's own events of the kinds a calibration can match (avalanches,
// detected during the run: docs/scenarios.md), as an observation's events:
// where "run", direction the group's name or "crowd".
observe::Observation RunEvents(const fs::path& run_file) {
  observe::Observation o;
  o.bin_s = 1.0;
  for (const runfile::Event& e : runfile::RunFileReader(run_file).Events()) {
    if (e.kind != "avalanche") continue;
    observe::Event ev;
    ev.kind = e.kind;
    ev.where = "run";
    const std::string who = e.detail.substr(0, e.detail.find(':'));
    ev.direction = who.rfind("direction ", 0) == 0 ? who.substr(10) : who;
    ev.time_s = e.time_s;
    o.events.push_back(ev);
  }
  return o;
}

// The time from which the run is clogged for good (analysis::ClogForGood,
// the ensemble score's defaults), as one event of kind "clog" (none if it
// never is).
observe::Observation RunClog(const fs::path& run_file) {
  observe::Observation o;
  o.bin_s = 1.0;
  const double t = analysis::ClogForGood(analysis::ComputeTimeline(run_file));
  if (std::isfinite(t)) {
    observe::Event ev;
    ev.kind = "clog";
    ev.where = "run";
    ev.direction = "crowd";
    ev.time_s = t;
    o.events.push_back(ev);
  }
  return o;
}

json Number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

// A simulated run's observation, as much of it as statistics need.
json CompactObservation(const observe::Observation& o) {
  json series = json::array();
  for (const observe::Series& s : o.series) {
    json values = json::array();
    for (const observe::SeriesPoint& p : s.points) values.push_back(Number(p.value));
    series.push_back({{"quantity", s.quantity}, {"where", s.where}, {"direction", s.direction}, {"unit", s.unit},
                      {"values", std::move(values)}});
  }
  json events = json::array();
  for (const observe::Event& e : o.events)
    events.push_back({{"kind", e.kind}, {"where", e.where}, {"direction", e.direction}, {"time_s", Number(e.time_s)},
                      {"censored", e.censored}});
  return {{"t0_s", o.t0_s}, {"bin_s", o.bin_s}, {"bins", o.bins}, {"series", std::move(series)}, {"events", std::move(events)}};
}

}  // namespace

observe::Observation ReadCachedObservation(const fs::path& file) {
  const json j = json::parse(ReadInputFile(file, "cached observation"), nullptr, false);
  if (j.is_discarded() || !j.is_object())
    throw InputError(file.string() + ": a damaged cache file; delete it (its set's runs are made again)");
  observe::Observation o;
  try {
    o.t0_s = j.at("t0_s").get<double>();
    o.bin_s = j.at("bin_s").get<double>();
    o.bins = j.at("bins").get<std::size_t>();
    for (const json& s : j.at("series")) {
      observe::Series series;
      series.quantity = s.at("quantity").get<std::string>();
      series.where = s.at("where").get<std::string>();
      series.direction = s.at("direction").get<std::string>();
      series.unit = s.at("unit").get<std::string>();
      for (const json& v : s.at("values")) series.points.push_back({v.is_null() ? kNaN : v.get<double>(), kNaN, 0.0});
      o.series.push_back(std::move(series));
    }
    for (const json& e : j.at("events")) {
      observe::Event event;
      event.kind = e.at("kind").get<std::string>();
      event.where = e.at("where").get<std::string>();
      event.direction = e.at("direction").get<std::string>();
      event.time_s = e.at("time_s").is_null() ? kNaN : e.at("time_s").get<double>();
      event.censored = e.at("censored").get<bool>();
      o.events.push_back(std::move(event));
    }
  } catch (const json::exception& e) {
    throw InputError(file.string() + ": a damaged cache file (" + e.what() + "); delete it (its set's runs are made again)");
  }
  return o;
}

Evaluator::Evaluator(const CalibrationSpec& spec, const std::vector<Statistic>& statistics, fs::path dir, int jobs,
                     bool show_progress)
    : spec_(spec), statistics_(statistics), dir_(std::move(dir)), jobs_(jobs), show_progress_(show_progress) {
  for (const ObservationMatch& m : spec_.observations) {
    // The scenario's recorded events compare with the run's event table, its
    // recorded fatal clog with the run's clog for good: one file per run of
    // each, whatever the spec.
    const std::string j = m.SimulatedFrom();
    std::size_t k = 0;
    while (k < spec_json_.size() && spec_json_[k] != j) ++k;
    if (k == spec_json_.size()) {
      spec_json_.push_back(j);
      const std::string from_run = j == kRunEvents ? "events" : j == kRunClog ? "clog" : "";
      specs_.push_back(from_run.empty() ? m.observation.spec : observe::ObservationSpec{});
      spec_tag_.push_back(from_run.empty() ? Sha256Hex(j).substr(0, 12) : from_run);
    }
    spec_of_observation_.push_back(k);
  }
}

std::vector<double> Evaluator::ToUnit(const std::vector<double>& values) const {
  std::vector<double> u(values.size());
  for (std::size_t k = 0; k < values.size(); ++k)
    u[k] = (values[k] - spec_.parameters[k].min) / spec_.parameters[k].Range();
  return u;
}

std::vector<double> Evaluator::FromUnit(const std::vector<double>& unit) const {
  std::vector<double> v(unit.size());
  for (std::size_t k = 0; k < unit.size(); ++k) {
    const Parameter& p = spec_.parameters[k];
    v[k] = std::clamp(p.min + unit[k] * p.Range(), p.min, p.max);
  }
  return v;
}

std::string Evaluator::KeyOf(const std::vector<double>& values) const {
  std::string text = spec_.fingerprint;
  for (double v : values) text += " " + sweep::ExactNumber(v);
  return Sha256Hex(text).substr(0, 16);
}

bool Evaluator::Cached(const std::string& key) const {
  const fs::path d = dir_ / "cache" / key;
  for (std::uint64_t seed : spec_.base.seeds) {
    if (fs::exists(d / ("seed" + std::to_string(seed) + ".failed"))) continue;
    for (const std::string& tag : spec_tag_)
      if (!fs::exists(d / ("seed" + std::to_string(seed) + "-" + tag + ".json"))) return false;
  }
  return true;
}

SetResult Evaluator::Load(const std::vector<double>& values, const std::string& key) const {
  SetResult r;
  r.values = values;
  r.key = key;
  const fs::path d = dir_ / "cache" / key;
  const std::size_t n = statistics_.size();
  for (std::uint64_t seed : spec_.base.seeds) {
    const std::string stem = "seed" + std::to_string(seed);
    std::vector<double> row(n, kNaN);
    if (fs::exists(d / (stem + ".failed"))) {
      r.failures.push_back("seed " + std::to_string(seed) + ": " + ReadInputFile(d / (stem + ".failed"), "failure note"));
    } else {
      std::vector<observe::Observation> simulated;
      for (const std::string& tag : spec_tag_) simulated.push_back(ReadCachedObservation(d / (stem + "-" + tag + ".json")));
      for (std::size_t i = 0; i < spec_.observations.size(); ++i) {
        std::vector<double> part;
        SimulatedStatistics(i, simulated[spec_of_observation_[i]], statistics_, &part);
        for (std::size_t j = 0; j < n; ++j)
          if (statistics_[j].observation == i) row[j] = part[j];
      }
    }
    r.per_seed.push_back(std::move(row));
  }
  r.mean.assign(n, kNaN);
  r.sd.assign(n, kNaN);
  for (std::size_t j = 0; j < n; ++j) {
    double sum = 0.0, sum2 = 0.0, count = 0.0;
    for (const auto& row : r.per_seed)
      if (std::isfinite(row[j])) {
        sum += row[j];
        count += 1.0;
      }
    if (count == 0) continue;
    r.mean[j] = sum / count;
    for (const auto& row : r.per_seed)
      if (std::isfinite(row[j])) sum2 += (row[j] - r.mean[j]) * (row[j] - r.mean[j]);
    r.sd[j] = count > 1 ? std::sqrt(sum2 / (count - 1.0)) : 0.0;
  }
  return r;
}

bool Evaluator::RunBatch(const std::vector<std::vector<double>>& sets, const std::vector<std::string>& keys,
                         int attempt) {
  json sweep = {{"format", "crowdrecon-sweep"},
                {"version", 1},
                {"name", spec_.name + ": " + std::to_string(sets.size()) + " parameter set(s)"},
                {"scenario", spec_.base.scenario_file.string()},
                {"keep_runs", false}};
  json set = json::object();
  for (const sweep::Override& o : spec_.base.set) set[o.path] = json::parse(o.json);
  sweep["set"] = set;
  sweep["seeds"] = spec_.base.seeds;
  json variants = json::array();
  for (std::size_t s = 0; s < sets.size(); ++s) {
    json v = json::object();
    for (std::size_t k = 0; k < sets[s].size(); ++k) v[spec_.parameters[k].path] = json::parse(spec_.parameters[k].JsonOf(sets[s][k]));
    variants.push_back({{"name", keys[s]}, {"set", v}});
  }
  sweep["variants"] = variants;
  // The batch's folder: named by the build (the fingerprint holds its
  // version: a batch folder is one build's) and the whole sweep, seeds
  // included (named by the sets alone, a rerun with other seeds found the
  // earlier seeds' batch and was refused as "a different sweep").
  const std::string sweep_text = sweep.dump(1);
  std::string joined = spec_.fingerprint + sweep_text;
  if (attempt > 0) joined += "attempt " + std::to_string(attempt);
  const std::string batch = Sha256Hex(joined).substr(0, 16);
  const fs::path batches = dir_ / "batches";
  CreateOutputFolder(batches);
  const fs::path sweep_file = batches / (batch + ".json");
  // Every rank writes the same text; the file is read by every rank.
  if (!fs::exists(sweep_file) || ReadInputFile(sweep_file, "batch") != sweep_text) WriteFileAtomically(sweep_file, sweep_text);

  sweep::SweepOptions options;
  options.sweep_file = sweep_file;
  options.output_dir = batches / batch;
  options.jobs = jobs_;
  options.show_progress = show_progress_;
  options.after_run = [this](const sweep::RunPlan& run, const fs::path& run_file, const std::string& status) {
    const std::string key = run.id.substr(run.id.find('-') + 1, 16);
    const fs::path d = dir_ / "cache" / key;
    CreateOutputFolder(d);
    const std::string stem = "seed" + std::to_string(run.seed);
    if (status != "complete") {
      WriteFileAtomically(d / (stem + ".failed"), status);
      return;
    }
    std::optional<observe::Trajectories> t;
    for (std::size_t k = 0; k < spec_json_.size(); ++k) {
      observe::Observation o;
      if (spec_json_[k] == kRunEvents) {
        o = RunEvents(run_file);
      } else if (spec_json_[k] == kRunClog) {
        o = RunClog(run_file);
      } else {
        if (!t) t = observe::ReadTrajectories(run_file);
        o = observe::ObserveTrajectories(*t, specs_[k]);
      }
      WriteFileAtomically(d / (stem + "-" + spec_tag_[k] + ".json"), CompactObservation(o).dump());
    }
  };
  const sweep::SweepSummary s = sweep::RunSweep(options);
  coordinator_ = s.coordinator;
  if (s.exit_code != 0) throw InputError("an MPI rank could not take part in the calibration's sweep");
  runs_simulated_ += s.completed;
  if (s.interrupted) return false;
  std::vector<std::vector<double>> stale;
  std::vector<std::string> stale_keys;
  for (std::size_t k = 0; k < keys.size(); ++k)
    if (!Cached(keys[k])) {
      stale.push_back(sets[k]);
      stale_keys.push_back(keys[k]);
    }
  if (stale.empty()) return true;
  if (attempt == 0) return RunBatch(stale, stale_keys, 1);
  throw InputError(sweep_file.string() + ": the runs of parameter set " + stale_keys.front() +
                   " completed, but their observations are missing from " +
                   (dir_ / "cache" / stale_keys.front()).string());
}

bool Evaluator::Evaluate(const std::vector<std::vector<double>>& sets, const std::string& stage,
                         std::vector<SetResult>* out) {
  std::vector<std::vector<double>> missing;
  std::vector<std::string> missing_keys;
  std::set<std::string> seen;
  for (const auto& values : sets) {
    const std::string key = KeyOf(values);
    if (known_.contains(key) || Cached(key) || !seen.insert(key).second) continue;
    missing.push_back(values);
    missing_keys.push_back(key);
  }
  if (!missing.empty()) {
    if (show_progress_ && coordinator_)
      std::fprintf(stderr, "calibrate: %s: %zu parameter set(s) x %zu seed(s) to run\n", stage.c_str(), missing.size(),
                   spec_.base.seeds.size());
    if (!RunBatch(missing, missing_keys)) return false;
  }
  out->clear();
  for (const auto& values : sets) {
    const std::string key = KeyOf(values);
    auto it = known_.find(key);
    if (it == known_.end()) {
      SetResult r = Load(values, key);
      r.order = known_.size();
      r.stage = stage;
      it = known_.emplace(key, std::move(r)).first;
    }
    out->push_back(it->second);
  }
  return true;
}

std::vector<const SetResult*> Evaluator::All() const {
  std::vector<const SetResult*> all(known_.size(), nullptr);
  for (const auto& [key, r] : known_) all[r.order] = &r;
  return all;
}

}  // namespace crowdrecon::calibrate
