#include "crowdrecon/observe/events.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::observe {

bool EventOptions::IsValid(std::string* error) const {
  const auto bad = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (!(reference_speed_m_per_s > 0.0 && reference_speed_m_per_s <= 5.0))
    return bad("events.reference_speed_m_per_s: " + FormatNumber(reference_speed_m_per_s) + ", expected a speed in (0, 5] m/s");
  if (!(threshold_m > 0.0 && threshold_m <= 100.0))
    return bad("events.threshold_m: " + FormatNumber(threshold_m) + ", expected a distance in (0, 100] m");
  if (!(min_stop_s >= 0.0 && min_stop_s <= 3600.0))
    return bad("events.min_stop_s: " + FormatNumber(min_stop_s) + ", expected a time in [0, 3600] s");
  return true;
}

std::vector<Event> DetectEvents(const std::vector<double>& time_s, const std::vector<double>& speed, double bin_s,
                                double time_uncertainty_s, const EventOptions& options, const std::string& where,
                                const std::string& direction) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // The state's changes: (bin index of the onset, new state is moving).
  struct Change {
    std::size_t bin;
    bool moving;
  };
  std::vector<Change> changes;
  std::size_t first = 0;
  while (first < speed.size() && std::isnan(speed[first])) ++first;
  if (first == speed.size()) return {};
  const double ref = options.reference_speed_m_per_s;
  bool moving = speed[first] > ref;
  changes.push_back({first, moving});
  double g = 0.0;
  std::size_t start = first;  // first bin of the current excursion
  for (std::size_t i = first; i < speed.size(); ++i) {
    if (std::isnan(speed[i])) continue;
    const double step = (moving ? ref - speed[i] : speed[i] - ref) * bin_s;
    if (g == 0.0 && step > 0.0) start = i;
    g = std::max(0.0, g + step);
    if (g > options.threshold_m) {
      moving = !moving;
      changes.push_back({start, moving});
      g = 0.0;
      start = i + 1;
    }
  }
  // Drop stops shorter than min_stop_s (not the censored first one when it
  // lasts to the end: it is all there is).
  const double end_time = time_s.back() + bin_s;
  const auto time_of = [&](std::size_t k) { return k < changes.size() ? time_s[changes[k].bin] : end_time; };
  std::vector<Change> kept;
  for (std::size_t k = 0; k < changes.size(); ++k) {
    if (!changes[k].moving && k > 0 && time_of(k + 1) - time_of(k) < options.min_stop_s && k + 1 < changes.size()) {
      ++k;  // skip the stop and the motion that ends it (the motion goes on)
      continue;
    }
    if (!kept.empty() && kept.back().moving == changes[k].moving) continue;
    kept.push_back(changes[k]);
  }
  std::vector<Event> events;
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const double onset = time_s[kept[k].bin];
    const double next = k + 1 < kept.size() ? time_s[kept[k + 1].bin] : nan;
    Event e;
    e.kind = kept[k].moving ? "surge" : "stop";
    e.where = where;
    e.direction = direction;
    e.time_s = onset;
    e.uncertainty_s = time_uncertainty_s;
    e.end_s = next;
    if (!kept[k].moving) {
      e.censored = k == 0;
      events.push_back(e);
      continue;
    }
    if (k == 0) continue;  // motion from the start: no onset seen
    const std::size_t last = k + 1 < kept.size() ? kept[k + 1].bin : speed.size();
    double peak = 0.0;
    for (std::size_t i = kept[k].bin; i < last; ++i)
      if (!std::isnan(speed[i])) peak = std::max(peak, speed[i]);
    e.peak_speed_m_per_s = peak;
    e.rise_time_s = nan;
    for (std::size_t i = kept[k].bin; i < last; ++i)
      if (!std::isnan(speed[i]) && speed[i] >= 0.9 * peak) {
        e.rise_time_s = time_s[i] + bin_s - onset;
        break;
      }
    events.push_back(e);
  }
  return events;
}

}  // namespace crowdrecon::observe
