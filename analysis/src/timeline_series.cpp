#include "crowdrecon/analysis/timeline_series.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <limits>

#include <nlohmann/json.hpp>

#include "crowdrecon/analysis/run_analysis.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/runfile/run_file.hpp"

namespace crowdrecon::analysis {

double ClogForGood(const TimelineSeries& s, double smooth_s, double stop_speed_m_per_s, double min_s) {
  std::vector<std::vector<double>> speeds;
  for (const std::vector<double>& g : s.group_speed_m_per_s) speeds.push_back(MovingMean(s.time_s, g, smooth_s));
  const auto clogged = [&](std::size_t i) {
    bool anyone = false;
    for (const std::vector<double>& g : speeds) {
      if (std::isnan(g[i])) continue;  // nobody of this direction present
      anyone = true;
      if (g[i] >= stop_speed_m_per_s) return false;
    }
    return anyone;
  };
  if (s.time_s.empty() || !clogged(s.time_s.size() - 1)) return std::numeric_limits<double>::quiet_NaN();
  std::size_t first = s.time_s.size() - 1;
  while (first > 0 && clogged(first - 1)) --first;
  if (s.time_s.back() - s.time_s[first] < min_s) return std::numeric_limits<double>::quiet_NaN();
  return s.time_s[first];
}

std::vector<double> MovingMean(const std::vector<double>& t, const std::vector<double>& v, double window_s) {
  std::vector<double> out(v.size(), std::numeric_limits<double>::quiet_NaN());
  std::size_t lo = 0, hi = 0, count = 0;
  double sum = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    while (hi < v.size() && t[hi] <= t[i] + 0.5 * window_s) {
      if (!std::isnan(v[hi])) sum += v[hi], ++count;
      ++hi;
    }
    while (lo < hi && t[lo] < t[i] - 0.5 * window_s) {
      if (!std::isnan(v[lo])) sum -= v[lo], --count;
      ++lo;
    }
    if (count > 0) out[i] = sum / static_cast<double>(count);
  }
  return out;
}

double ExitSpecificFlow(const TimelineSeries& s, std::size_t exit) {
  if (exit >= s.exit_left.size() || s.exit_left[exit].empty()) return std::numeric_limits<double>::quiet_NaN();
  const std::vector<double>& left = s.exit_left[exit];
  const double total = left.back();
  if (total < 10.0 || !(s.exit_width_m[exit] > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const auto when = [&](double count) {
    return s.time_s[static_cast<std::size_t>(std::lower_bound(left.begin(), left.end(), count) - left.begin())];
  };
  const double t10 = when(0.1 * total), t90 = when(0.9 * total);
  if (!(t90 > t10)) return std::numeric_limits<double>::quiet_NaN();
  return 0.8 * total / (t90 - t10) / s.exit_width_m[exit];
}

std::string RunClock::Text(double t_s) const {
  char text[40];
  // To the second: minutes alone where the time is a whole minute (issue 65:
  // with a scale of 10 a tick at 21:46:40 read "21:46", and two maps 50 s
  // apart were both "21:45").
  const long incident = std::lround(t_s * scale);
  const long minutes_in = incident >= 0 ? incident / 60 : -((-incident + 59) / 60);
  const long seconds = incident - 60 * minutes_in;
  if (start.size() != 5) {
    if (seconds == 0) std::snprintf(text, sizeof text, "%ld min", minutes_in);
    else std::snprintf(text, sizeof text, "%ld min %ld s", minutes_in, seconds);
    return text;
  }
  const long first = std::stol(start.substr(0, 2)) * 60 + std::stol(start.substr(3, 2));
  const long minutes = ((first + minutes_in) % (24 * 60) + 24 * 60) % (24 * 60);
  if (seconds == 0) std::snprintf(text, sizeof text, "%02ld:%02ld", minutes / 60, minutes % 60);
  else std::snprintf(text, sizeof text, "%02ld:%02ld:%02ld", minutes / 60, minutes % 60, seconds);
  return text;
}

std::string RunClock::TickText(double t_s, double tick_s) const {
  return tick_s * scale >= 60.0 ? Text(t_s) : FormatNumber(t_s) + " s";
}

std::string RunClock::AxisLabel() const {
  if (start.empty() && scale == 1.0) return "time of the run";
  if (start.empty())
    return "time of the incident since the run's start (a second of the run stands for " + FormatNumber(scale) + " s)";
  if (scale == 1.0) return "time of night (run time 0 = " + start + ")";
  return "time of night (run time 0 = " + start + "; a second of the run stands for " + FormatNumber(scale) + " s)";
}

std::string RunClock::MomentText(double t_s) const {
  if (!start.empty()) return Text(t_s);
  const std::string run = "t = " + FormatNumber(std::round(t_s * 10.0) / 10.0) + " s";
  return scale == 1.0 ? run : run + " (" + Text(t_s) + " of the incident)";
}

TimelineSeries ComputeTimeline(const std::filesystem::path& run_file, double smooth_s) {
  const runfile::RunFileReader reader(run_file);
  TimelineSeries s;
  s.run_file = run_file.string();
  s.smooth_s = smooth_s;
  s.clock.start = reader.RunValue("timeline_clock_start");
  if (const std::string scale = reader.RunValue("timeline_clock_scale"); !scale.empty()) {
    s.clock.scale = std::strtod(scale.c_str(), nullptr);
    if (!(s.clock.scale > 0.0) || !std::isfinite(s.clock.scale))
      throw InputError(run_file.string() + ": run value timeline_clock_scale \"" + scale +
                       "\" is not a positive number of the incident's seconds per run second");
  }
  const std::string venue = reader.venue_json();
  if (venue.empty()) throw InputError(run_file.string() + ": the run file holds no venue (written before format 2)");
  const geometry::Venue stored = geometry::ParseVenue(venue, run_file.string() + ": run value venue");
  s.area_m2 = geometry::WalkableArea_m2(stored);
  for (const geometry::MeasurementArea& m : stored.measurement_areas) {
    s.area_names.push_back(m.id);
    s.area_m2_each.push_back(std::abs(geometry::RingSignedArea_m2(m.polygon)));
  }
  for (const geometry::Exit& e : stored.exits) {
    s.exit_names.push_back(e.id);
    s.exit_width_m.push_back(stored.FreeWidth_m(e));  // between the jambs: flows per metre of opening
  }

  // People present and the counter-flow's share, frame by frame.
  const std::vector<runfile::FrameTime> times = reader.FrameTimes();
  if (times.empty()) throw InputError(run_file.string() + ": the run has no frames");
  const std::vector<std::uint32_t> group = reader.PersonGroups();
  auto stream = reader.PersonFrames(times.back().frame);
  runfile::PersonFrame frame;
  for (const runfile::FrameTime& ft : times) s.time_s.push_back(ft.time_s);
  s.density_per_m2.assign(times.size(), 0.0);  // a frame nobody is in has no rows
  s.area_density_per_m2.assign(s.area_names.size(), std::vector<double>(times.size(), 0.0));
  s.area_speed_m_per_s.assign(s.area_names.size(), std::vector<double>(times.size(), std::numeric_limits<double>::quiet_NaN()));
  s.counter_fraction.assign(times.size(), std::numeric_limits<double>::quiet_NaN());
  // Speeds and flows: the analysis of the run (its groups' desired directions
  // are the areas' too).
  const RunAnalysis a = AnalyzeRun(run_file);
  std::size_t k = 0;
  while (stream.Next(&frame)) {
    while (k < times.size() && times[k].frame < frame.frame) ++k;
    if (k == times.size()) break;
    std::size_t counter = 0;
    for (std::uint32_t p : frame.person)
      if (p < group.size() && group[p] == 1) ++counter;
    const std::size_t present = frame.person.size();
    s.density_per_m2[k] = static_cast<double>(present) / s.area_m2;
    for (std::size_t m = 0; m < s.area_names.size(); ++m) {
      std::size_t inside = 0, walking = 0;
      double along = 0.0;
      for (std::size_t r = 0; r < present; ++r) {
        if (!geometry::PointInRing(stored.measurement_areas[m].polygon, frame.position_m[r])) continue;
        ++inside;
        const std::uint32_t p = frame.person[r];
        if (frame.state[r] != runfile::PersonStatus::kWalking || p >= group.size() || group[p] >= a.group_direction.size())
          continue;
        along += Dot(frame.velocity_m_per_s[r], a.group_direction[group[p]]);
        ++walking;
      }
      if (s.area_m2_each[m] > 0.0) s.area_density_per_m2[m][k] = static_cast<double>(inside) / s.area_m2_each[m];
      if (walking > 0) s.area_speed_m_per_s[m][k] = along / static_cast<double>(walking);
    }
    if (present > 0) s.counter_fraction[k] = static_cast<double>(counter) / static_cast<double>(present);
  }
  s.queued.assign(s.time_s.size(), 0.0);
  for (const runfile::CensusRow& row : reader.CensusRows())
    if (row.frame >= 0 && static_cast<std::size_t>(row.frame) < s.queued.size())
      s.queued[static_cast<std::size_t>(row.frame)] = static_cast<double>(row.census.queued);

  s.group_names = a.group_name;
  s.validity = a.plausibility;
  const std::size_t n = std::min(s.time_s.size(), a.series.time_s.size());
  const auto fit = [n](std::vector<double> v) {
    v.resize(n, std::numeric_limits<double>::quiet_NaN());
    return v;
  };
  s.time_s.resize(n);
  s.density_per_m2.resize(n);
  for (std::vector<double>& area : s.area_density_per_m2) area.resize(n);
  for (std::vector<double>& area : s.area_speed_m_per_s) area.resize(n);
  s.counter_fraction.resize(n);
  s.queued.resize(n);
  for (const std::vector<double>& g : a.series.group_mean_speed_m_per_s) s.group_speed_m_per_s.push_back(fit(g));
  s.flow_forward_per_m_s = fit(a.series.flow_forward_per_m_s);
  s.flow_backward_per_m_s = fit(a.series.flow_backward_per_m_s);
  const std::string groups = reader.RunValue("groups");  // "main,counter,..." for a timeline
  if (!groups.empty()) {
    std::vector<std::string> names;
    std::size_t at = 0;
    while (at <= groups.size()) {
      const std::size_t comma = groups.find(',', at);
      names.push_back(groups.substr(at, comma == std::string::npos ? std::string::npos : comma - at));
      if (comma == std::string::npos) break;
      at = comma + 1;
    }
    for (std::size_t g = 0; g < s.group_names.size() && g < names.size(); ++g)
      s.group_names[g] = names[g] + " (" + s.group_names[g] + ")";
  }

  s.exit_left.assign(s.exit_names.size(), std::vector<double>(s.time_s.size(), 0.0));
  for (const runfile::Event& e : reader.Events()) {
    if (e.kind == "exit") {
      const auto x = std::find(s.exit_names.begin(), s.exit_names.end(), e.detail);
      if (x != s.exit_names.end()) {
        std::vector<double>& left = s.exit_left[static_cast<std::size_t>(x - s.exit_names.begin())];
        const auto from = std::lower_bound(s.time_s.begin(), s.time_s.end(), e.time_s - 1e-9);
        for (auto f = static_cast<std::size_t>(from - s.time_s.begin()); f < left.size(); ++f) left[f] += 1.0;
      }
    }
    if (e.kind == "avalanche") {
      TimelineMark m{e.time_s, e.detail, e.kind};
      // The detail's format is the avalanche system's (scenario/src/timeline_systems.cpp).
      if (const std::size_t at = e.detail.find("rise time "); at != std::string::npos)
        m.rise_time_s = std::strtod(e.detail.c_str() + at + 10, nullptr);
      s.avalanches.push_back(m);
    }
    if (e.kind == "fall") s.falls.push_back({e.time_s, e.detail, e.kind});
  }
  const std::string recorded = reader.RunValue("timeline_recorded");
  if (!recorded.empty()) {
    const nlohmann::json marks = nlohmann::json::parse(recorded, nullptr, false);
    if (!marks.is_array())
      throw InputError(run_file.string() + ": run value timeline_recorded is not a list of marks (damaged file)");
    for (const nlohmann::json& m : marks) {
      if (!m.is_object() || !m.contains("time_s") || !m["time_s"].is_number())
        throw InputError(run_file.string() + ": run value timeline_recorded holds a mark without a time (damaged file)");
      s.recorded.push_back({m["time_s"].get<double>(), m.value("label", ""), m.value("kind", "avalanche")});
    }
  }
  return s;
}

std::vector<TimelineMark> AreaAvalanches(const TimelineSeries& s, const RegimeOptions& options, double min_density_per_m2) {
  std::vector<TimelineMark> marks;
  for (std::size_t m = 0; m < s.area_speed_m_per_s.size(); ++m) {
    const std::vector<double>& v = s.area_speed_m_per_s[m];
    const std::vector<double>& rho = s.area_density_per_m2[m];
    // An empty area has no flow to stop, and a gap ends a stop.
    for (const Avalanche& a : FindAvalanchesBetweenGaps(s.time_s, v, options)) {
      // The stop it released: from stopped_before_s before its start to its start.
      double sum = 0.0;
      std::size_t count = 0;
      for (std::size_t k = 0; k < a.start_index; ++k)
        if (s.time_s[k] >= a.start_time_s - a.stopped_before_s - 1e-9) sum += rho[k], ++count;
      const double stop_density = count > 0 ? sum / static_cast<double>(count) : 0.0;
      if (stop_density < min_density_per_m2) continue;
      TimelineMark mark{a.start_time_s,
                        "area " + s.area_names[m] + ": released after a stop of " + FormatFixed(a.stopped_before_s, 1) +
                            " s at " + FormatFixed(stop_density, 1) + " /m2, rise time " + FormatFixed(a.rise_time_s, 2) +
                            " s, peak " + FormatFixed(a.peak_speed_m_per_s, 2) + " m/s",
                        "avalanche"};
      mark.rise_time_s = a.rise_time_s;
      marks.push_back(mark);
    }
  }
  std::stable_sort(marks.begin(), marks.end(), [](const TimelineMark& a, const TimelineMark& b) { return a.time_s < b.time_s; });
  return marks;
}

std::vector<TimelineMark> MergeAvalanches(std::vector<TimelineMark> marks, double within_s) {
  std::stable_sort(marks.begin(), marks.end(), [](const TimelineMark& a, const TimelineMark& b) { return a.time_s < b.time_s; });
  std::vector<TimelineMark> kept;
  for (TimelineMark& m : marks)
    if (kept.empty() || m.time_s > kept.back().time_s + within_s) kept.push_back(std::move(m));
  return kept;
}

std::vector<TimelineMark> AvalanchesWithAreas(const TimelineSeries& s) {
  std::vector<TimelineMark> all = s.avalanches;
  for (TimelineMark& m : AreaAvalanches(s, IncidentAvalancheOptions())) all.push_back(std::move(m));
  return MergeAvalanches(std::move(all), RegimeOptions{}.min_stop_duration_s);
}

}  // namespace crowdrecon::analysis
