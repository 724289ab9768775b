#include "crowdrecon/analysis/regime.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <limits>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::analysis {

namespace {

// Frame times exceed their nominal times by less than a time step (the engine
// stops at the first step past the frame time); comparisons of times with
// window edges allow for it.
constexpr double kTimeTolerance_s = 1e-6;

bool CheckRange(double value, double lo, double hi, const char* name, const char* unit, std::string* error) {
  if (value >= lo && value <= hi) return true;
  *error = std::string("regime ") + name + " = " + FormatNumber(value) + (*unit ? " " : "") + unit +
           ", expected [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]";
  return false;
}

// Time at which the series rose through `level` on its way to sample i
// (speed[i] >= level): linear between samples i - 1 and i if the earlier one
// is below the level, else the time of sample i.
double UpwardCrossing(const std::vector<double>& time_s, const std::vector<double>& speed, std::size_t i,
                      double level) {
  if (i == 0 || !(speed[i - 1] < level) || !(speed[i] > speed[i - 1])) return time_s[i];
  return time_s[i - 1] + (level - speed[i - 1]) / (speed[i] - speed[i - 1]) * (time_s[i] - time_s[i - 1]);
}

}  // namespace

const char* ToString(Regime regime) {
  switch (regime) {
    case Regime::kLanes: return "lanes";
    case Regime::kAvalanches: return "avalanches";
    case Regime::kClogging: return "clogging";
    case Regime::kUnclassified: return "unclassified";
  }
  return "unclassified";
}

bool FromString(const std::string& text, Regime* regime) {
  for (Regime r : {Regime::kLanes, Regime::kAvalanches, Regime::kClogging, Regime::kUnclassified})
    if (text == ToString(r)) {
      *regime = r;
      return true;
    }
  return false;
}

bool RegimeOptions::IsValid(std::string* error) const {
  if (!CheckRange(stop_speed_m_per_s, 1e-4, 2.0, "stop_speed_m_per_s", "m/s", error)) return false;
  if (!CheckRange(burst_speed_m_per_s, 1e-4, 5.0, "burst_speed_m_per_s", "m/s", error)) return false;
  if (!(burst_speed_m_per_s > stop_speed_m_per_s)) {
    *error = "regime burst_speed_m_per_s (" + FormatNumber(burst_speed_m_per_s) +
             " m/s) must exceed stop_speed_m_per_s (" + FormatNumber(stop_speed_m_per_s) + " m/s)";
    return false;
  }
  if (!CheckRange(min_stop_duration_s, 0.0, 600.0, "min_stop_duration_s", "s", error)) return false;
  if (!CheckRange(frozen_speed_m_per_s, 0.0, 2.0, "frozen_speed_m_per_s", "m/s", error)) return false;
  if (!CheckRange(frozen_window_s, 0.1, 3600.0, "frozen_window_s", "s", error)) return false;
  if (!CheckRange(transient_s, 0.0, 3600.0, "transient_s", "s", error)) return false;
  if (!CheckRange(stationary_window_s, 1.0, 1e6, "stationary_window_s", "s", error)) return false;
  if (stationary_window_s < frozen_window_s) {
    *error = "regime stationary_window_s (" + FormatNumber(stationary_window_s) +
             " s) must be at least frozen_window_s (" + FormatNumber(frozen_window_s) + " s)";
    return false;
  }
  if (!(std::isfinite(min_released_stop_s) && min_released_stop_s >= 0.0)) {
    *error = "regime min_released_stop_s = " + FormatNumber(min_released_stop_s) + " s, expected at least 0 s";
    return false;
  }
  if (min_avalanches < 1) {
    *error = "regime min_avalanches = " + std::to_string(min_avalanches) + ", expected at least 1";
    return false;
  }
  if (!CheckRange(max_stopped_fraction_for_lanes, 0.0, 1.0, "max_stopped_fraction_for_lanes", "", error)) return false;
  if (!CheckRange(min_lane_order_for_lanes, 0.0, 1.0, "min_lane_order_for_lanes", "", error)) return false;
  return true;
}

// A Schmitt trigger with a dwell time on V(t): "stopped" is entered when V has
// stayed below the stop speed for min_stop_duration_s, "moving" when V exceeds
// the burst speed; every passage stopped -> moving is an avalanche. Sub-burst
// excursions between the two thresholds neither end a stop nor count as a
// release: they are creeping, not the "sudden release" of the paper.
double StationaryStart(double t_first, double t_last, const RegimeOptions& options) {
  return std::max(t_first + options.transient_s, t_last - options.stationary_window_s);
}

std::vector<Avalanche> FindAvalanches(const std::vector<double>& time_s, const std::vector<double>& speed_m_per_s,
                                      const RegimeOptions& options) {
  if (time_s.size() != speed_m_per_s.size())
    throw InputError("FindAvalanches: the time and speed series differ in length");
  const std::size_t n = time_s.size();
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::vector<Avalanche> avalanches;
  if (n == 0) return avalanches;
  const double stationary_start_s = StationaryStart(time_s.front(), time_s.back(), options) - kTimeTolerance_s;
  bool armed = false;
  bool flowed = !options.require_flow_before_stop;  // the series has reached the burst speed
  std::size_t below_start = kNone;   // first sample of the current run below the stop speed
  std::size_t armed_stop_start = 0;  // first sample of the stop that armed the trigger
  std::size_t last_rise = 0;         // last sample that rose above the stop speed
  for (std::size_t i = 0; i < n; ++i) {
    const double v = speed_m_per_s[i];
    if (v < options.stop_speed_m_per_s) {
      if (below_start == kNone) below_start = i;
      // A run below the stop speed that includes the first sample is the
      // initial rest of a crowd placed standing, not a stop of a flow.
      if (!armed && flowed && below_start != 0 &&
          time_s[below_start] - time_s.front() >= options.first_stop_after_s - kTimeTolerance_s &&
          time_s[i] - time_s[below_start] >= options.min_stop_duration_s - kTimeTolerance_s) {
        armed = true;
        armed_stop_start = below_start;
      }
      continue;
    }
    if (below_start != kNone || i == 0) last_rise = i;
    below_start = kNone;
    if (!armed || v < options.burst_speed_m_per_s) {
      if (v >= options.burst_speed_m_per_s) flowed = true;
      continue;
    }
    // The burst: the avalanche began at the last rise and lasts until V falls
    // back below the stop speed.
    Avalanche a;
    a.start_index = last_rise;
    std::size_t end = i;
    while (end < n && speed_m_per_s[end] >= options.stop_speed_m_per_s) ++end;
    a.complete = end < n;
    a.end_index = a.complete ? end : n - 1;
    a.start_time_s = time_s[a.start_index];
    a.end_time_s = time_s[a.end_index];
    a.duration_s = a.end_time_s - a.start_time_s;
    a.stopped_before_s = a.start_time_s - time_s[armed_stop_start];
    a.rise_time_s = UpwardCrossing(time_s, speed_m_per_s, i, options.burst_speed_m_per_s) -
                    UpwardCrossing(time_s, speed_m_per_s, a.start_index, options.stop_speed_m_per_s);
    for (std::size_t k = a.start_index; k <= a.end_index; ++k) {
      a.peak_speed_m_per_s = std::max(a.peak_speed_m_per_s, speed_m_per_s[k]);
      if (k > a.start_index)
        a.distance_m += 0.5 * (speed_m_per_s[k] + speed_m_per_s[k - 1]) * (time_s[k] - time_s[k - 1]);
    }
    a.stationary = a.start_time_s >= stationary_start_s;
    avalanches.push_back(a);
    armed = false;
    if (!a.complete) break;
    // Continue at the sample that fell back below the stop speed: it may begin
    // the next stop.
    i = a.end_index - 1;
  }
  return avalanches;
}

std::vector<Avalanche> FindAvalanchesBetweenGaps(const std::vector<double>& time_s,
                                                 const std::vector<double>& speed_m_per_s,
                                                 const RegimeOptions& options) {
  if (time_s.size() != speed_m_per_s.size())
    throw InputError("FindAvalanchesBetweenGaps: the time and speed series differ in length");
  std::vector<Avalanche> all;
  const std::size_t n = speed_m_per_s.size();
  std::size_t from = 0;
  while (from < n) {
    while (from < n && std::isnan(speed_m_per_s[from])) ++from;
    std::size_t to = from;
    while (to < n && !std::isnan(speed_m_per_s[to])) ++to;
    if (to > from) {
      const auto at = [&](const std::vector<double>& v, std::size_t k) { return v.begin() + static_cast<std::ptrdiff_t>(k); };
      const std::vector<double> t(at(time_s, from), at(time_s, to)), v(at(speed_m_per_s, from), at(speed_m_per_s, to));
      for (Avalanche a : FindAvalanches(t, v, options)) {
        a.start_index += from;
        a.end_index += from;
        all.push_back(a);
      }
    }
    from = to;
  }
  return all;
}

RegimeResult ClassifyRegime(const std::vector<double>& time_s, const std::vector<double>& mean_speed_m_per_s,
                            const std::vector<double>& lane_order, const RegimeOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  if (time_s.size() != mean_speed_m_per_s.size() || (!lane_order.empty() && lane_order.size() != time_s.size()))
    throw InputError("ClassifyRegime: the time, speed and lane order series differ in length");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  RegimeResult r;
  r.mean_lane_order = nan;
  if (time_s.empty()) {
    r.reason = "no frames";
    return r;
  }
  const std::size_t n = time_s.size();
  const double t_first = time_s.front(), t_last = time_s.back();
  r.stationary_start_s = StationaryStart(t_first, t_last, options);
  r.long_enough = t_last - (t_first + options.transient_s) >= options.frozen_window_s - kTimeTolerance_s;

  // Stationary stage: fraction of samples stopped, mean lane order. A run
  // that ends before the transient does is averaged whole (and is too short
  // to classify anyway).
  const double from_s = t_last >= r.stationary_start_s - kTimeTolerance_s ? r.stationary_start_s : t_first;
  std::size_t stationary = 0, stopped = 0, lane_samples = 0;
  double lane_sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (time_s[i] < from_s - kTimeTolerance_s) continue;
    ++stationary;
    if (mean_speed_m_per_s[i] < options.stop_speed_m_per_s) ++stopped;
    if (!lane_order.empty() && std::isfinite(lane_order[i])) {
      lane_sum += lane_order[i];
      ++lane_samples;
    }
  }
  r.stopped_time_fraction = stationary > 0 ? static_cast<double>(stopped) / static_cast<double>(stationary) : 0.0;
  if (lane_samples > 0) r.mean_lane_order = lane_sum / static_cast<double>(lane_samples);

  // Final window: mean speed, frozen or not.
  std::size_t end_samples = 0;
  double end_sum = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    if (time_s[i] >= t_last - options.frozen_window_s - kTimeTolerance_s) {
      end_sum += mean_speed_m_per_s[i];
      ++end_samples;
    }
  r.end_mean_speed_m_per_s = end_sum / static_cast<double>(end_samples);
  r.frozen_at_end = r.end_mean_speed_m_per_s < options.frozen_speed_m_per_s;

  r.avalanches = FindAvalanches(time_s, mean_speed_m_per_s, options);
  for (const Avalanche& a : r.avalanches)
    r.stationary_avalanches += a.stationary && a.stopped_before_s >= options.min_released_stop_s ? 1 : 0;

  // The decision, in the order of regime.hpp.
  const std::string speed_text = "mean speed along the desired direction over the last " +
                                 FormatNumber(options.frozen_window_s) + " s " +
                                 FormatFixed(r.end_mean_speed_m_per_s, 3) + " m/s";
  if (!r.long_enough) {
    r.regime = Regime::kUnclassified;
    r.reason = "run too short: " + FormatFixed(t_last - t_first, 1) + " s, the classifier needs the transient (" +
               FormatNumber(options.transient_s) + " s) plus a final window of " +
               FormatNumber(options.frozen_window_s) + " s";
  } else if (r.frozen_at_end) {
    r.regime = Regime::kClogging;
    r.reason = "frozen at the end: " + speed_text + " < " + FormatNumber(options.frozen_speed_m_per_s) + " m/s";
  } else if (r.stationary_avalanches >= options.min_avalanches) {
    r.regime = Regime::kAvalanches;
    r.reason = std::to_string(r.stationary_avalanches) + " avalanches (stop >= " +
               FormatNumber(std::max(options.min_stop_duration_s, options.min_released_stop_s)) + " s below " + FormatNumber(options.stop_speed_m_per_s) +
               " m/s, then a burst above " + FormatNumber(options.burst_speed_m_per_s) +
               " m/s) in the stationary stage, at least " + std::to_string(options.min_avalanches) +
               ", and not frozen (" + speed_text + ")";
  } else if (r.stopped_time_fraction <= options.max_stopped_fraction_for_lanes &&
             (options.min_lane_order_for_lanes <= 0.0 ||
              (std::isfinite(r.mean_lane_order) && r.mean_lane_order >= options.min_lane_order_for_lanes))) {
    r.regime = Regime::kLanes;
    r.reason = "free flow: stopped " + FormatFixed(100.0 * r.stopped_time_fraction, 1) +
               " % of the stationary stage (at most " +
               FormatNumber(100.0 * options.max_stopped_fraction_for_lanes) + " %), " +
               std::to_string(r.stationary_avalanches) + " avalanche(s)";
    if (std::isfinite(r.mean_lane_order)) r.reason += ", mean lane order " + FormatFixed(r.mean_lane_order, 2);
  } else if (r.stopped_time_fraction <= options.max_stopped_fraction_for_lanes) {
    r.regime = Regime::kUnclassified;
    r.reason = "free flow without lanes: mean lane order " + FormatFixed(r.mean_lane_order, 2) + " below " +
               FormatNumber(options.min_lane_order_for_lanes);
  } else {
    r.regime = Regime::kUnclassified;
    r.reason = "intermittent: stopped " + FormatFixed(100.0 * r.stopped_time_fraction, 1) +
               " % of the stationary stage with " + std::to_string(r.stationary_avalanches) +
               " avalanche(s) (fewer than " + std::to_string(options.min_avalanches) + "), not frozen";
  }
  return r;
}

namespace {

std::string DirectionText(const DirectionRegime& d) {
  return d.name + " (" + std::to_string(d.people) + " people) " + FormatFixed(d.result.end_mean_speed_m_per_s, 3) +
         " m/s";
}

}  // namespace

RegimeResult ClassifyByDirection(const std::vector<double>& time_s, const std::vector<double>& crowd_speed_m_per_s,
                                 const std::vector<DirectionSeries>& directions,
                                 const std::vector<double>& lane_order, const RegimeOptions& options) {
  RegimeResult r = ClassifyRegime(time_s, crowd_speed_m_per_s, lane_order, options);
  for (const DirectionSeries& d : directions) {
    if (d.speed_m_per_s.size() != time_s.size())
      throw InputError("ClassifyByDirection: the series of direction " + d.name + " differs in length");
    std::vector<double> t, v;
    for (std::size_t i = 0; i < time_s.size(); ++i)
      if (std::isfinite(d.speed_m_per_s[i])) {
        t.push_back(time_s[i]);
        v.push_back(d.speed_m_per_s[i]);
      }
    if (t.empty()) continue;
    r.directions.push_back({d.name, d.people, ClassifyRegime(t, v, {}, options)});
  }
  if (!r.long_enough || r.directions.empty()) return r;

  // The combination, worst first.
  const std::string last_window = "mean speed along the desired direction over the last " +
                                  FormatNumber(options.frozen_window_s) + " s: ";
  std::string frozen, moving;
  for (const DirectionRegime& d : r.directions) {
    std::string& list = d.result.frozen_at_end ? frozen : moving;
    list += (list.empty() ? "" : ", ") + DirectionText(d);
  }
  if (!frozen.empty()) {
    const bool all = moving.empty();
    r.regime = Regime::kClogging;
    r.reason = std::string(all ? "every direction frozen at the end" : "a direction frozen at the end") + " (" +
               last_window + frozen + " < " + FormatNumber(options.frozen_speed_m_per_s) + " m/s" +
               (all ? "" : "; still moving: " + moving) + ")";
    return r;
  }
  int most = r.stationary_avalanches;
  std::string where = most >= options.min_avalanches ? "the crowd" : "";
  for (const DirectionRegime& d : r.directions)
    if (d.result.stationary_avalanches >= options.min_avalanches) {
      where += (where.empty() ? "" : ", ") + d.name;
      most = std::max(most, d.result.stationary_avalanches);
    }
  if (!where.empty()) {
    r.regime = Regime::kAvalanches;
    r.reason = std::to_string(most) + " avalanches (stop >= " + FormatNumber(options.min_stop_duration_s) +
               " s below " + FormatNumber(options.stop_speed_m_per_s) + " m/s, then a burst above " +
               FormatNumber(options.burst_speed_m_per_s) + " m/s) in the stationary stage of " + where +
               ", at least " + std::to_string(options.min_avalanches) + ", no direction frozen (" + last_window +
               moving + ")";
    return r;
  }
  for (const DirectionRegime& d : r.directions)
    if (d.result.regime != Regime::kLanes) {
      r.regime = Regime::kUnclassified;
      r.reason = "direction " + d.name + " is not free flow: " + d.result.reason;
      return r;
    }
  if (r.regime == Regime::kLanes) {
    std::string speeds;
    for (const DirectionRegime& d : r.directions)
      speeds += (speeds.empty() ? "" : ", ") + d.name + " stopped " +
                FormatFixed(100.0 * d.result.stopped_time_fraction, 1) + " %";
    r.reason += "; every direction free (" + speeds + ")";
  }
  return r;
}

RegimeOptions IncidentAvalancheOptions() {
  RegimeOptions options;
  options.require_flow_before_stop = true;
  options.first_stop_after_s = options.transient_s;
  return options;
}

RegimeOptions SingleReleaseReading(RegimeOptions options) {
  options.min_avalanches = 1;
  options.min_released_stop_s = 5.0;
  return options;
}

}  // namespace crowdrecon::analysis
