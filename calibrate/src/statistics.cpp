#include "crowdrecon/calibrate/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::calibrate {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct WindowMean {
  double mean = kNaN;
  double standard_error = kNaN;
};

// Mean of the bins of `series` whose centres lie in [from, to).
WindowMean MeanOver(const observe::Observation& obs, const observe::Series& series, double from, double to) {
  double sum = 0.0, sum_u2 = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < series.points.size(); ++k) {
    const double t = obs.t0_s + (static_cast<double>(k) + 0.5) * obs.bin_s;
    if (t < from || t >= to) continue;
    const observe::SeriesPoint& p = series.points[k];
    if (!std::isfinite(p.value)) continue;
    sum += p.value;
    sum_u2 += std::isfinite(p.uncertainty) ? p.uncertainty * p.uncertainty : 0.0;
    ++n;
  }
  WindowMean w;
  if (n == 0) return w;
  w.mean = sum / static_cast<double>(n);
  w.standard_error = std::sqrt(sum_u2) / static_cast<double>(n);
  return w;
}

// The largest bin of `series` whose centre lies in [from, to), with that
// bin's uncertainty.
WindowMean MaxOver(const observe::Observation& obs, const observe::Series& series, double from, double to) {
  WindowMean w;
  for (std::size_t k = 0; k < series.points.size(); ++k) {
    const double t = obs.t0_s + (static_cast<double>(k) + 0.5) * obs.bin_s;
    const observe::SeriesPoint& p = series.points[k];
    if (t < from || t >= to || !std::isfinite(p.value)) continue;
    if (std::isnan(w.mean) || p.value > w.mean) {
      w.mean = p.value;
      w.standard_error = std::isfinite(p.uncertainty) ? p.uncertainty : 0.0;
    }
  }
  return w;
}

WindowMean Reduce(bool take_max, const observe::Observation& obs, const observe::Series& series, double from, double to) {
  return take_max ? MaxOver(obs, series, from, to) : MeanOver(obs, series, from, to);
}

// Onsets of the events of a kind, region and direction ("any": every
// direction, merged), sorted (a censored stop, under way when the series
// began, has no observed onset).
std::vector<double> Onsets(const observe::Observation& obs, const std::string& kind, const std::string& where,
                           const std::string& direction) {
  std::vector<double> t;
  const bool any = direction == "any";
  for (const observe::Event& e : obs.events)
    if (e.kind == kind && e.where == where && (any || e.direction == direction) && !e.censored) t.push_back(e.time_s);
  std::sort(t.begin(), t.end());
  if (!any) return t;
  // Any direction: one surge seen in several directions (each group's and the
  // crowd's detector) within kSameEventS of the first counts once.
  constexpr double kSameEventS = 2.0;
  std::vector<double> merged;
  for (double x : t)
    if (merged.empty() || x - merged.back() > kSameEventS) merged.push_back(x);
  return merged;
}

std::string Window(double a, double b) { return "[" + FormatNumber(a) + ", " + FormatNumber(b) + ") s"; }

}  // namespace

namespace {

// A statistic compares the runs over [sim_from_s, sim_to_s]: a window that
// reaches beyond the runs would compare nothing (no simulated value, no
// chi-square) and is refused before anything runs, naming it.
void CheckWithinTheRuns(const CalibrationSpec& spec, const ObservationMatch& m, const Statistic& st) {
  const double end = spec.run_duration_s;
  if (end <= 0.0 || (st.sim_from_s >= -1e-9 && st.sim_to_s <= end + 1e-9 && st.sim_from_s < end)) return;
  throw InputError(spec.origin + ": " + m.file.string() + ": " + st.name + " is compared with the runs over " +
                   Window(st.sim_from_s, st.sim_to_s) + " (the observation's window" +
                   (m.time_offset_s != 0.0 ? " plus its time_offset_s of " + FormatNumber(m.time_offset_s) + " s" : "") +
                   "), beyond the runs, which last " + FormatNumber(end) +
                   " s (run.duration_s); expected windows within [0, " + FormatNumber(end) +
                   "] s: shorten the window, change time_offset_s or lengthen the runs");
}

}  // namespace

std::vector<Statistic> ObservedStatistics(const CalibrationSpec& spec) {
  std::vector<Statistic> out;
  for (std::size_t i = 0; i < spec.observations.size(); ++i) {
    const ObservationMatch& m = spec.observations[i];
    const std::string tag = "obs" + std::to_string(i) + " ";
    const std::string simulated_from = m.SimulatedFrom();
    for (const SeriesMatch& s : m.series) {
      const observe::Series* series = m.observation.Find(s.quantity, s.where, s.direction);
      const double width = s.window_s > 0 ? s.window_s : s.to_s - s.from_s;
      for (double a = s.from_s; a < s.to_s - 1e-9; a += width) {
        const double b = std::min(a + width, s.to_s);
        // A value recorded of the incident stands for the observation's series.
        const bool recorded = std::isfinite(s.recorded_value);
        const WindowMean w = recorded ? WindowMean{s.recorded_value, s.recorded_sigma}
                                      : Reduce(s.take_max, m.observation, *series, a, b);
        if (!std::isfinite(w.mean))
          throw InputError(spec.origin + ": " + m.file.string() + ": series " + s.quantity + " " + s.where + " " +
                           s.direction + " has no value in the window " + Window(a, b) +
                           "; expected a window where the observation has data (see its CSV)");
        Statistic st;
        st.name = tag + s.quantity + " " + s.where + " " + s.direction + (s.take_max ? " max " : " ") + Window(a, b);
        st.unit = recorded ? "m/s" : series->unit;
        st.is_max = s.take_max;
        st.simulated_from = simulated_from;
        st.observation = i;
        st.quantity = s.quantity;
        st.where = s.where;
        st.direction = s.direction;
        st.from_s = a;
        st.to_s = b;
        st.sim_from_s = std::isnan(s.simulated_from_s) ? a + m.time_offset_s : s.simulated_from_s;
        st.sim_to_s = std::isnan(s.simulated_to_s) ? b + m.time_offset_s : s.simulated_to_s;
        st.observed = w.mean;
        const double systematic = s.relative_error * std::abs(w.mean);
        st.observed_sigma = std::sqrt(w.standard_error * w.standard_error + systematic * systematic);
        CheckWithinTheRuns(spec, m, st);
        out.push_back(st);
      }
    }
    for (const EventMatch& e : m.events) {
      // A statistic of the events over [from_s, to]: where, when, what it is read from.
      const auto of_events = [&](double to) {
        Statistic st;
        st.simulated_from = simulated_from;
        st.observation = i;
        st.quantity = e.kind;
        st.where = e.where;
        st.direction = e.direction;
        st.from_s = e.from_s;
        st.to_s = to;
        st.sim_from_s = e.from_s + m.time_offset_s;
        st.sim_to_s = to + m.time_offset_s;
        return st;
      };
      if (e.first_time) {
        Statistic st = of_events(e.to_s);
        st.is_time = true;
        st.name = tag + e.kind + " " + e.where + " " + e.direction + ": first in " + Window(e.from_s, e.to_s);
        st.unit = "s";
        st.observed = e.recorded_time_s;
        st.observed_sigma = e.recorded_sigma_s;
        CheckWithinTheRuns(spec, m, st);
        out.push_back(st);
        continue;
      }
      const std::vector<double> all = Onsets(m.observation, e.kind, e.where, e.direction);
      std::vector<double> checkpoints;
      for (double t : all)
        if (t >= e.from_s && t < e.to_s) checkpoints.push_back(t);
      checkpoints.push_back(e.to_s);
      for (std::size_t k = 0; k < checkpoints.size(); ++k) {
        Statistic st = of_events(checkpoints[k]);
        st.is_count = true;
        st.name = tag + e.kind + "s " + e.where + " " + e.direction + " by " + FormatNumber(checkpoints[k]) + " s";
        st.unit = "events";
        // Onsets at the checkpoint count (a count just after the event).
        st.observed = static_cast<double>(std::min(k + 1, checkpoints.size() - 1));
        st.observed_sigma = 0.5;
        CheckWithinTheRuns(spec, m, st);
        out.push_back(st);
      }
    }
  }
  return out;
}

void SimulatedStatistics(std::size_t index, const observe::Observation& simulated,
                         const std::vector<Statistic>& statistics, std::vector<double>* values) {
  values->assign(statistics.size(), kNaN);
  for (std::size_t j = 0; j < statistics.size(); ++j) {
    const Statistic& st = statistics[j];
    if (st.observation != index) continue;
    if (st.is_time) {
      double first = st.sim_to_s;  // never in the window: censored at its end
      for (double t : Onsets(simulated, st.quantity, st.where, st.direction))
        if (t >= st.sim_from_s && t <= st.sim_to_s) {
          first = t;
          break;
        }
      (*values)[j] = first;
    } else if (st.is_count) {
      double n = 0;
      for (double t : Onsets(simulated, st.quantity, st.where, st.direction))
        if (t >= st.sim_from_s && t <= st.sim_to_s) ++n;
      (*values)[j] = n;
    } else {
      const observe::Series* series = simulated.Find(st.quantity, st.where, st.direction);
      if (series) (*values)[j] = Reduce(st.is_max, simulated, *series, st.sim_from_s, st.sim_to_s).mean;
    }
  }
}

}  // namespace crowdrecon::calibrate
