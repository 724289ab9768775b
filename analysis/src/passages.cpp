#include "crowdrecon/analysis/passages.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::analysis {

bool PassageOptions::IsValid(std::string* error) const {
  if (!(clog_lapse_s > 0.0 && clog_lapse_s <= 3600.0)) {
    *error = "passages clog_lapse_s = " + FormatNumber(clog_lapse_s) + " s, expected (0, 3600]";
    return false;
  }
  if (!(tail_from_s > 0.0 && tail_from_s <= 3600.0)) {
    *error = "passages tail_from_s = " + FormatNumber(tail_from_s) + " s, expected (0, 3600]";
    return false;
  }
  if (min_tail_lapses < 2) {
    *error = "passages min_tail_lapses = " + std::to_string(min_tail_lapses) + ", expected at least 2";
    return false;
  }
  return true;
}

PassageStatistics AnalyzePassages(std::vector<double> times, double from_s, double to_s,
                                  const PassageOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  if (!(std::isfinite(from_s) && std::isfinite(to_s) && to_s >= from_s))
    throw InputError("AnalyzePassages: the window [" + FormatNumber(from_s) + ", " + FormatNumber(to_s) +
                     "] s is not an interval");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  times.erase(std::remove_if(times.begin(), times.end(),
                             [&](double t) { return !(t >= from_s && t <= to_s); }),
              times.end());
  std::sort(times.begin(), times.end());

  PassageStatistics s;
  s.passages = times.size();
  s.median_lapse_s = s.mean_lapse_s = s.max_lapse_s = nan;
  s.mean_burst_size = s.tail_exponent = s.tail_exponent_error = nan;
  s.open_lapse_s = to_s - (times.empty() ? from_s : times.back());
  for (std::size_t i = 1; i < times.size(); ++i) s.lapses_s.push_back(times[i] - times[i - 1]);

  // Clogs and the bursts between them. Burst k holds the passages after
  // clog k and up to the next clog; it counts only if a clog precedes it.
  double clogged_s = 0.0;
  bool after_clog = false;
  int burst = times.empty() ? 0 : 1;  // the first passage begins a (cut) burst
  for (double lapse : s.lapses_s) {
    if (lapse > options.clog_lapse_s) {
      ++s.clogs;
      clogged_s += lapse;
      if (after_clog) s.burst_sizes.push_back(burst);
      after_clog = true;
      burst = 1;
    } else {
      ++burst;
    }
  }
  if (s.open_lapse_s > options.clog_lapse_s) {
    ++s.clogs;
    clogged_s += s.open_lapse_s;
    if (after_clog && !times.empty()) s.burst_sizes.push_back(burst);
  }
  s.clogged_fraction = to_s > from_s ? clogged_s / (to_s - from_s) : 0.0;
  if (!s.burst_sizes.empty()) {
    double sum = 0.0;
    for (int b : s.burst_sizes) sum += b;
    s.mean_burst_size = sum / static_cast<double>(s.burst_sizes.size());
  }

  if (!s.lapses_s.empty()) {
    std::vector<double> sorted = s.lapses_s;
    std::sort(sorted.begin(), sorted.end());
    const std::size_t n = sorted.size();
    s.median_lapse_s = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
    double sum = 0.0;
    for (double l : sorted) sum += l;
    s.mean_lapse_s = sum / static_cast<double>(n);
    s.max_lapse_s = sorted.back();
  }

  double log_sum = 0.0;
  for (double lapse : s.lapses_s)
    if (lapse >= options.tail_from_s) {
      ++s.tail_lapses;
      log_sum += std::log(lapse / options.tail_from_s);
    }
  if (s.tail_lapses >= options.min_tail_lapses && log_sum > 0.0) {
    const double n = static_cast<double>(s.tail_lapses);
    s.tail_exponent = 1.0 + n / log_sum;
    s.tail_exponent_error = (s.tail_exponent - 1.0) / std::sqrt(n);
  }
  return s;
}

}  // namespace crowdrecon::analysis
