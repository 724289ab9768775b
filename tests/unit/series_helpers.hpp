// Synthetic time series for the regime tests (test_analysis.cpp,
// test_directions.cpp): sample times and a function sampled at them.
#pragma once

#include <cmath>
#include <vector>

namespace crowdrecon::analysis::test_series {

// Samples at 10 per second from 0 to duration_s.
inline std::vector<double> Times(double duration_s) {
  std::vector<double> t;
  for (int k = 0; k <= static_cast<int>(std::lround(duration_s * 10.0)); ++k) t.push_back(k / 10.0);
  return t;
}

template <typename F>
std::vector<double> Series(const std::vector<double>& t, F f) {
  std::vector<double> v;
  for (double ti : t) v.push_back(f(ti));
  return v;
}

}  // namespace crowdrecon::analysis::test_series
