// The analysis as tables, text reports and JSON, and written into the run file.
#include <cmath>
#include <cstdio>
#include <limits>

#include <nlohmann/json.hpp>

#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/runfile/sqlite.hpp"

namespace crowdrecon::analysis {

namespace {

using sqlite::Database;
using sqlite::Statement;

std::string Printf(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

// JSON has no NaN: null says "no value".
nlohmann::json Number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json Array(const std::vector<double>& values) {
  nlohmann::json a = nlohmann::json::array();
  for (double v : values) a.push_back(Number(v));
  return a;
}

// Adding +0 turns a negative zero (from negating a normal) into "0".
std::string Point(Vec2 p) { return "(" + FormatNumber(p.x + 0.0) + ", " + FormatNumber(p.y + 0.0) + ")"; }

}  // namespace

std::vector<SummaryValue> RunAnalysis::SummaryTable() const {
  std::vector<SummaryValue> t = {
      {"duration_s", duration_s, "s"},
      {"frames", static_cast<double>(frames), ""},
      {"people", static_cast<double>(people), ""},
      {"stationary_start_s", regime.stationary_start_s, "s"},
      {"mean_speed_m_per_s", mean_speed_m_per_s, "m/s"},
  };
  for (std::size_t g = 0; g < group_mean_speed_m_per_s.size(); ++g)
    t.push_back({"mean_speed_g" + std::to_string(g) + "_m_per_s", group_mean_speed_m_per_s[g], "m/s"});
  const std::vector<SummaryValue> rest = {
      {"flow_forward_per_m_s", flow_forward_per_m_s, "1/(m s)"},
      {"flow_backward_per_m_s", flow_backward_per_m_s, "1/(m s)"},
      {"crossings_forward", static_cast<double>(crossings_forward), ""},
      {"crossings_backward", static_cast<double>(crossings_backward), ""},
      {"stopped_time_fraction", regime.stopped_time_fraction, ""},
      {"mean_stopped_fraction", mean_stopped_fraction, ""},
      {"avalanche_count", static_cast<double>(regime.stationary_avalanches), ""},
      {"avalanche_count_all", static_cast<double>(regime.avalanches.size()), ""},
      {"avalanche_mean_duration_s", avalanche_mean_duration_s, "s"},
      {"avalanche_max_duration_s", avalanche_max_duration_s, "s"},
      {"avalanche_mean_distance_m", avalanche_mean_distance_m, "m"},
      {"avalanche_mean_people", avalanche_mean_people, ""},
      {"frozen_at_end", regime.frozen_at_end ? 1.0 : 0.0, ""},
      {"end_mean_speed_m_per_s", regime.end_mean_speed_m_per_s, "m/s"},
      {"mean_lane_order", mean_lane_order, ""},
      {"max_load_n", max_load_n, "N"},
      {"max_load_person", static_cast<double>(max_load_person), ""},
      {"max_load_time_s", max_load_time_s, "s"},
      {"mean_load_n", mean_load_n, "N"},
      {"load_p50_n", load_p50_n, "N"},
      {"load_p90_n", load_p90_n, "N"},
      {"load_p99_n", load_p99_n, "N"},
      {"above_load_person_frames", above_load_person_frames, ""},
      {"max_above_load_fraction", max_above_load_fraction, ""},
      {"people_ever_above_load", static_cast<double>(people_ever_above_load), ""},
      {"longest_above_load_s", longest_above_load_s, "s"},
      {"regime_code", static_cast<double>(static_cast<int>(regime.regime)), ""},
      {"regime_classifier_version", static_cast<double>(kRegimeClassifierVersion), ""},
      {"regime_code_single_release", static_cast<double>(static_cast<int>(regime_single_release.regime)), ""},
      {"avalanche_mean_rise_time_s", avalanche_mean_rise_time_s, "s"},
      {"peak_density_per_m2", plausibility.peak_density_per_m2, "1/m^2"},
      {"peak_equivalent_density_per_m2", plausibility.peak_equivalent_density_per_m2, "1/m^2"},
      {"time_beyond_static_critical_s", plausibility.time_beyond_static_s, "s"},
      {"time_beyond_measured_s", plausibility.time_beyond_measured_s, "s"},
      {"max_overlap_m", plausibility.contacts_available ? plausibility.max_overlap_m : std::numeric_limits<double>::quiet_NaN(), "m"},
      {"plausibility_code", static_cast<double>(static_cast<int>(plausibility.verdict)), ""},
  };
  t.insert(t.end(), rest.begin(), rest.end());
  // Per direction of travel (group): its own verdict and its passages.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::size_t next_direction = 0;
  for (std::size_t g = 0; g < group_mean_speed_m_per_s.size(); ++g) {
    const DirectionRegime* d = nullptr;
    if (g < group_people.size() && group_people[g] > 0 && next_direction < regime.directions.size())
      d = &regime.directions[next_direction++];
    const PassageStatistics* p = g < passages.size() ? &passages[g] : nullptr;
    const std::string k = "_g" + std::to_string(g);
    const auto of = [&](double value) { return d ? value : nan; };
    const auto op = [&](double value) { return p ? value : nan; };
    const std::vector<SummaryValue> direction = {
        {"regime_code" + k, of(d ? static_cast<double>(static_cast<int>(d->result.regime)) : 0.0), ""},
        {"stopped_time_fraction" + k, of(d ? d->result.stopped_time_fraction : 0.0), ""},
        {"frozen_at_end" + k, of(d && d->result.frozen_at_end ? 1.0 : 0.0), ""},
        {"end_mean_speed" + k + "_m_per_s", of(d ? d->result.end_mean_speed_m_per_s : 0.0), "m/s"},
        {"avalanche_count" + k, of(d ? d->result.stationary_avalanches : 0.0), ""},
        {"passages" + k, op(p ? static_cast<double>(p->passages) : 0.0), ""},
        {"lapse_median" + k + "_s", op(p ? p->median_lapse_s : 0.0), "s"},
        {"lapse_max" + k + "_s", op(p ? p->max_lapse_s : 0.0), "s"},
        {"lapse_open" + k + "_s", op(p ? p->open_lapse_s : 0.0), "s"},
        {"clogs" + k, op(p ? p->clogs : 0.0), ""},
        {"clogged_fraction" + k, op(p ? p->clogged_fraction : 0.0), ""},
        {"burst_mean_size" + k, op(p ? p->mean_burst_size : 0.0), ""},
        {"lapse_tail_lapses" + k, op(p ? static_cast<double>(p->tail_lapses) : 0.0), ""},
        {"lapse_tail_exponent" + k, op(p ? p->tail_exponent : 0.0), ""},
        {"lapse_tail_exponent_error" + k, op(p ? p->tail_exponent_error : 0.0), ""},
    };
    t.insert(t.end(), direction.begin(), direction.end());
  }
  return t;
}

std::string RunAnalysis::BriefReport() const {
  std::string r;
  r += "run: " + run_file + " (" + (status.empty() ? "no status" : status) + "), " + std::to_string(people) +
       " people in " + std::to_string(groups) + " group(s), " + std::to_string(frames) + " frames, " +
       Printf("%.1f s", duration_s) + "\n";
  r += std::string("regime: ") + ToString(regime.regime) + " (" + regime.reason + ")\n";
  for (const DirectionRegime& d : regime.directions)
    r += "  direction " + d.name + " (" + std::to_string(d.people) + " people): " + ToString(d.result.regime) + " (" +
         d.result.reason + ")\n";
  if (regime_single_release.regime != regime.regime)
    r += std::string("regime, read as a single release (a clog of at least 5 s released once is enough): ") +
         ToString(regime_single_release.regime) + " (" + regime_single_release.reason + ")\n";
  for (std::size_t g = 0; g < passages.size() && g < group_name.size(); ++g) {
    const PassageStatistics& p = passages[g];
    if (g < group_people.size() && group_people[g] == 0) continue;
    r += "  passages of " + group_name[g] + ": " + std::to_string(p.passages) +
         Printf(", median lapse %.2f s", p.median_lapse_s) + Printf(", longest %.2f s", p.max_lapse_s) +
         Printf(", open at the end %.2f s", p.open_lapse_s) + ", " + std::to_string(p.clogs) + " clog(s)" +
         Printf(" (%.0f %% of the time)", 100.0 * p.clogged_fraction) + ", " +
         std::to_string(p.burst_sizes.size()) + " bounded burst(s)" +
         (p.burst_sizes.empty() ? "" : Printf(" of %.1f passages on average", p.mean_burst_size)) +
         (std::isfinite(p.tail_exponent)
              ? Printf("; lapse tail exponent %.2f", p.tail_exponent) + Printf(" +- %.2f", p.tail_exponent_error) +
                    " (" + std::to_string(p.tail_lapses) + " lapses)"
              : "; too few long lapses for a tail exponent (" + std::to_string(p.tail_lapses) + ")") +
         "\n";
  }
  r += "mean speed along the desired direction: " + Printf("%.3f m/s", mean_speed_m_per_s);
  for (std::size_t g = 0; g < group_mean_speed_m_per_s.size(); ++g)
    r += (g == 0 ? " (group " : ", group ") + std::to_string(g) + " " + Printf("%.3f", group_mean_speed_m_per_s[g]);
  r += group_mean_speed_m_per_s.empty() ? "\n" : ")\n";
  r += "stopped: " + Printf("%.1f %% of the time", 100.0 * regime.stopped_time_fraction) + ", " +
       Printf("%.1f %% of people on average", 100.0 * mean_stopped_fraction) + "; frozen at the end: " +
       (regime.frozen_at_end ? "yes" : "no") + Printf(" (%.3f m/s over the final window)", regime.end_mean_speed_m_per_s) +
       "\n";
  r += "flow through " + line_source + Printf(" (%.2f m): ", line.length_m()) +
       Printf("forward %.3f", flow_forward_per_m_s) + Printf(", backward %.3f persons/(m s)", flow_backward_per_m_s) +
       " (" + std::to_string(crossings_forward) + " / " + std::to_string(crossings_backward) + " crossings in all)\n";
  r += "lane order: " + (std::isfinite(mean_lane_order) ? Printf("%.3f", mean_lane_order) : std::string("n/a")) + "\n";
  r += "avalanches: " + std::to_string(regime.stationary_avalanches) + " in the stationary stage (" +
       std::to_string(regime.avalanches.size()) + " in all)";
  if (regime.stationary_avalanches > 0)
    r += Printf(", mean duration %.1f s", avalanche_mean_duration_s) + Printf(" (max %.1f s)", avalanche_max_duration_s) +
         Printf(", mean distance %.2f m", avalanche_mean_distance_m) +
         Printf(", %.1f people moved on average", avalanche_mean_people) +
         Printf(", rise time %.2f s on average", avalanche_mean_rise_time_s);
  r += "\n";
  r += std::string(chest_loads ? "chest load" : "load (sum of contact forces; the run records no chest loads)") +
       ": max " + Printf("%.0f N", max_load_n) + " (person " + std::to_string(max_load_person) +
       Printf(" at %.1f s)", max_load_time_s) + Printf("; mean %.1f N", mean_load_n) +
       Printf(", p50 %.1f", load_p50_n) + Printf(", p90 %.1f", load_p90_n) + Printf(", p99 %.1f N", load_p99_n) +
       Printf("; above threshold: %.2f %% of person-frames", 100.0 * above_load_person_frames) + ", " +
       std::to_string(people_ever_above_load) + " people ever" +
       Printf(", longest %.1f s", longest_above_load_s) + "\n";
  r += "validity: " + plausibility.Statement(PlausibilityOptions{}) + "\n";
  for (const std::string& note : notes) r += "note: " + note + "\n";
  return r;
}

std::string RunAnalysis::FullReport() const {
  std::string r = BriefReport();
  r += "desired directions: " + direction_source + ":";
  for (std::size_t g = 0; g < group_direction.size(); ++g)
    r += " group " + std::to_string(g) + " " + Point(group_direction[g]);
  r += "\n";
  r += "measurement line: " + line_source + " " + Point(line.a_m) + " - " + Point(line.b_m) + ", forward " +
       Point(forward) + "\n";
  r += "periodic: ";
  if (!box.any()) r += "no\n";
  else
    r += std::string(box.x ? "x " : "") + (box.y ? "y " : "") + "box " + Point(box.min_m) + " - " + Point(box.max_m) +
         "\n";
  r += "stationary stage from " + Printf("%.2f s", regime.stationary_start_s) + "\n";
  for (std::size_t i = 0; i < regime.avalanches.size(); ++i) {
    const Avalanche& a = regime.avalanches[i];
    r += "avalanche " + std::to_string(i + 1) + Printf(": %.2f", a.start_time_s) + Printf(" - %.2f s", a.end_time_s) +
         Printf(" (%.2f s", a.duration_s) + (a.complete ? "" : ", until the end of the run") +
         Printf(") after a stop of %.2f s", a.stopped_before_s) + Printf(", peak %.3f m/s", a.peak_speed_m_per_s) +
         Printf(", distance %.3f m", a.distance_m) + ", " + std::to_string(a.people_moved) + " people moved" +
         Printf(", rise %.2f s", a.rise_time_s) +
         (a.stationary ? "" : " [transient]") + "\n";
  }
  r += "load histogram (stationary person-frames):";
  for (std::size_t b = 0; b < load_histogram.size(); ++b) {
    const double lo = static_cast<double>(b) * load_histogram_bin_n;
    r += b + 1 < load_histogram.size() ? " [" + FormatNumber(lo) + "," + FormatNumber(lo + load_histogram_bin_n) + ")"
                                       : " >=" + FormatNumber(lo);
    r += ":" + std::to_string(load_histogram[b]);
  }
  r += "\n";
  return r;
}

std::string RunAnalysis::ToJson() const {
  nlohmann::json j;
  j["run_file"] = run_file;
  j["status"] = status;
  j["regime"] = ToString(regime.regime);
  j["regime_reason"] = regime.reason;
  nlohmann::json summary = nlohmann::json::object(), units = nlohmann::json::object();
  for (const SummaryValue& v : SummaryTable()) {
    summary[v.name] = Number(v.value);
    units[v.name] = v.unit;
  }
  j["summary"] = summary;
  j["units"] = units;
  nlohmann::json setup;
  setup["direction_source"] = direction_source;
  setup["group_direction"] = nlohmann::json::array();
  for (Vec2 d : group_direction) setup["group_direction"].push_back({d.x, d.y});
  setup["line_source"] = line_source;
  setup["line"] = {{line.a_m.x, line.a_m.y}, {line.b_m.x, line.b_m.y}};
  setup["forward"] = {forward.x, forward.y};
  setup["periodic"] = {{"x", box.x}, {"y", box.y}, {"min_m", {box.min_m.x, box.min_m.y}}, {"max_m", {box.max_m.x, box.max_m.y}}};
  j["setup"] = setup;
  j["avalanches"] = nlohmann::json::array();
  for (const Avalanche& a : regime.avalanches)
    j["avalanches"].push_back({{"start_frame", series.frame[a.start_index]},
                               {"end_frame", series.frame[a.end_index]},
                               {"start_time_s", a.start_time_s},
                               {"end_time_s", a.end_time_s},
                               {"duration_s", a.duration_s},
                               {"stopped_before_s", a.stopped_before_s},
                               {"peak_speed_m_per_s", a.peak_speed_m_per_s},
                               {"distance_m", a.distance_m},
                               {"people_moved", a.people_moved},
                               {"rise_time_s", a.rise_time_s},
                               {"complete", a.complete},
                               {"stationary", a.stationary}});
  j["load_histogram"] = {{"bin_n", load_histogram_bin_n}, {"counts", load_histogram}};
  j["regime_classifier_version"] = kRegimeClassifierVersion;
  j["directions"] = nlohmann::json::array();
  for (std::size_t g = 0; g < group_name.size(); ++g) {
    nlohmann::json d = {{"group", g}, {"name", group_name[g]},
                        {"people", g < group_people.size() ? group_people[g] : 0}};
    for (const DirectionRegime& r : regime.directions)
      if (r.name == group_name[g]) {
        d["regime"] = ToString(r.result.regime);
        d["regime_reason"] = r.result.reason;
      }
    if (g < passages.size()) {
      const PassageStatistics& p = passages[g];
      d["passages"] = p.passages;
      d["lapses_s"] = p.lapses_s;
      d["open_lapse_s"] = p.open_lapse_s;
      d["burst_sizes"] = p.burst_sizes;
      d["lapse_tail_exponent"] = Number(p.tail_exponent);
      d["lapse_tail_exponent_error"] = Number(p.tail_exponent_error);
    }
    j["directions"].push_back(d);
  }
  nlohmann::json s;
  s["frame"] = series.frame;
  s["time_s"] = series.time_s;
  for (const MetricSeries::Column& c : series.Columns()) s[c.name] = Array(*c.values);
  j["series"] = s;
  j["notes"] = notes;
  return j.dump(1);
}

std::string OptionsToJson(const AnalysisOptions& o) {
  const RegimeOptions& r = o.regime;
  nlohmann::json j = {
      {"regime",
       {{"stop_speed_m_per_s", r.stop_speed_m_per_s},
        {"burst_speed_m_per_s", r.burst_speed_m_per_s},
        {"min_stop_duration_s", r.min_stop_duration_s},
        {"frozen_speed_m_per_s", r.frozen_speed_m_per_s},
        {"frozen_window_s", r.frozen_window_s},
        {"transient_s", r.transient_s},
        {"stationary_window_s", r.stationary_window_s},
        {"min_avalanches", r.min_avalanches},
        {"max_stopped_fraction_for_lanes", r.max_stopped_fraction_for_lanes},
        {"min_lane_order_for_lanes", r.min_lane_order_for_lanes}}},
      {"passages",
       {{"clog_lapse_s", o.passages.clog_lapse_s},
        {"tail_from_s", o.passages.tail_from_s},
        {"min_tail_lapses", o.passages.min_tail_lapses}}},
      {"lanes", {{"band_half_width_m", o.lanes.band_half_width_m}, {"band_half_length_m", o.lanes.band_half_length_m}}},
      {"stopped_person_speed_m_per_s", o.stopped_person_speed_m_per_s},
      {"flow_window_s", o.flow_window_s},
      {"load_threshold_n", o.load_threshold_n},
      {"load_histogram_bin_n", o.load_histogram_bin_n},
      {"load_histogram_max_n", o.load_histogram_max_n},
      {"avalanche_move_m", o.avalanche_move_m},
  };
  if (o.line) j["line"] = {{o.line->a_m.x, o.line->a_m.y}, {o.line->b_m.x, o.line->b_m.y}};
  return j.dump();
}

void WriteAnalysis(const std::filesystem::path& run_file, const RunAnalysis& a, const AnalysisOptions& options) {
  const std::string file = run_file.string();
  if (a.status == "running")
    throw InputError(file + ": the run is still being written (status \"running\"); analyse it without --write, or "
                            "write the analysis once it is complete");
  Database db(file, SQLITE_OPEN_READWRITE);
  db.Exec("BEGIN IMMEDIATE");
  try {
    // An earlier analysis is replaced as a whole.
    db.Exec("DROP TABLE IF EXISTS metric_series");
    db.Exec("DROP TABLE IF EXISTS metric_summary");
    db.Exec("DROP TABLE IF EXISTS metric_avalanche");
    db.Exec("DROP TABLE IF EXISTS metric_load_histogram");
    db.Exec("CREATE TABLE metric_series(frame INTEGER NOT NULL, name TEXT NOT NULL, value REAL)");
    db.Exec("CREATE INDEX metric_series_idx ON metric_series(name, frame)");
    db.Exec("CREATE TABLE metric_summary(name TEXT NOT NULL PRIMARY KEY, value REAL, unit TEXT NOT NULL)");
    db.Exec(
        "CREATE TABLE metric_avalanche(idx INTEGER PRIMARY KEY, start_frame INTEGER NOT NULL, end_frame INTEGER NOT "
        "NULL, start_time_s REAL NOT NULL, end_time_s REAL NOT NULL, duration_s REAL NOT NULL, stopped_before_s REAL "
        "NOT NULL, peak_speed_m_per_s REAL NOT NULL, distance_m REAL NOT NULL, people_moved INTEGER NOT NULL, "
        "complete INTEGER NOT NULL, stationary INTEGER NOT NULL, rise_time_s REAL NOT NULL)");
    db.Exec("CREATE TABLE metric_load_histogram(lower_n REAL NOT NULL, upper_n REAL, count INTEGER NOT NULL)");
    {
      Statement insert(db, "INSERT INTO metric_series VALUES(?, ?, ?)");
      for (const MetricSeries::Column& c : a.series.Columns())
        for (std::size_t k = 0; k < a.series.frame.size(); ++k)
          insert.Bind(1, a.series.frame[k]).Bind(2, c.name).Bind(3, (*c.values)[k]).Run();
    }
    {
      Statement insert(db, "INSERT INTO metric_summary VALUES(?, ?, ?)");
      for (const SummaryValue& v : a.SummaryTable()) insert.Bind(1, v.name).Bind(2, v.value).Bind(3, v.unit).Run();
    }
    {
      Statement insert(db, "INSERT INTO metric_avalanche VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
      for (std::size_t i = 0; i < a.regime.avalanches.size(); ++i) {
        const Avalanche& v = a.regime.avalanches[i];
        insert.Bind(1, static_cast<std::int64_t>(i + 1))
            .Bind(2, a.series.frame[v.start_index])
            .Bind(3, a.series.frame[v.end_index])
            .Bind(4, v.start_time_s)
            .Bind(5, v.end_time_s)
            .Bind(6, v.duration_s)
            .Bind(7, v.stopped_before_s)
            .Bind(8, v.peak_speed_m_per_s)
            .Bind(9, v.distance_m)
            .Bind(10, static_cast<std::int64_t>(v.people_moved))
            .Bind(11, static_cast<std::int64_t>(v.complete))
            .Bind(12, static_cast<std::int64_t>(v.stationary))
            .Bind(13, v.rise_time_s)
            .Run();
      }
    }
    {
      Statement insert(db, "INSERT INTO metric_load_histogram VALUES(?, ?, ?)");
      for (std::size_t b = 0; b < a.load_histogram.size(); ++b) {
        const double lo = static_cast<double>(b) * a.load_histogram_bin_n;
        insert.Bind(1, lo);
        if (b + 1 < a.load_histogram.size()) insert.Bind(2, lo + a.load_histogram_bin_n);
        else insert.BindNull(2);
        insert.Bind(3, a.load_histogram[b]).Run();
      }
    }
    {
      Statement put(db, "INSERT OR REPLACE INTO run VALUES(?, ?)");
      put.Bind(1, std::string("regime")).Bind(2, std::string(ToString(a.regime.regime))).Run();
      put.Bind(1, std::string("regime_reason")).Bind(2, a.regime.reason).Run();
      put.Bind(1, std::string("regime_classifier")).Bind(2, std::to_string(kRegimeClassifierVersion)).Run();
      put.Bind(1, std::string("analysis_options")).Bind(2, OptionsToJson(options)).Run();
      // Derived from the frames: a resumed run drops them with the metric_*
      // tables (runfile::RunFileWriter::Resume).
      put.Bind(1, std::string("derived_keys"))
          .Bind(2, std::string(R"(["regime", "regime_reason", "regime_classifier", "analysis_options"])"))
          .Run();
    }
    db.Exec("COMMIT");
  } catch (...) {
    sqlite3_exec(db.get(), "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

OutputKind AnalysisJsonOutput() {
  return JsonOutputKind("an analysis JSON (run_file, regime, summary)", [](const nlohmann::json& j) {
    return j.contains("run_file") && j.contains("regime") && j.contains("summary");
  });
}

}  // namespace crowdrecon::analysis
