// A statistic's values pooled over runs and the numbers taken from them:
// what the criteria judge (judge.cpp) and the report draws
// (validation_report.cpp), one definition for both. Internal to validate/.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "crowdrecon/validate/measures.hpp"
#include "crowdrecon/validate/validation_test.hpp"

namespace crowdrecon::validate {

// The finite values, sorted.
inline std::vector<double> Finite(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  std::sort(v.begin(), v.end());
  return v;
}

// Linear interpolation between order statistics (q in [0, 1]).
inline double Quantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return std::numeric_limits<double>::quiet_NaN();
  const double at = q * double(sorted.size() - 1);
  const std::size_t i = std::size_t(std::floor(at));
  if (i + 1 >= sorted.size()) return sorted.back();
  return sorted[i] + (at - double(i)) * (sorted[i + 1] - sorted[i]);
}

inline double AggregateOf(const std::vector<double>& sorted, Aggregate a) {
  if (sorted.empty()) return std::numeric_limits<double>::quiet_NaN();
  switch (a) {
    case Aggregate::kEvery:  // (judged value by value; the median stands for it)
    case Aggregate::kMedian: return Quantile(sorted, 0.5);
    case Aggregate::kMean: {
      double s = 0;
      for (double v : sorted) s += v;
      return s / double(sorted.size());
    }
    case Aggregate::kMin: return sorted.front();
    case Aggregate::kMax: return sorted.back();
    case Aggregate::kP95: return Quantile(sorted, 0.95);
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// Every value of a statistic over a case's runs (runs that failed give none).
inline std::vector<double> Pooled(const std::vector<Statistics>& runs, const std::string& statistic) {
  std::vector<double> all;
  for (const Statistics& s : runs) {
    const auto it = s.find(statistic);
    if (it != s.end()) all.insert(all.end(), it->second.begin(), it->second.end());
  }
  return Finite(all);
}

}  // namespace crowdrecon::validate
