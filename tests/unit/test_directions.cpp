// Regimes per direction of travel (classifier version 2) and the field's
// avalanche measures (issue 19): per-direction verdicts on synthetic series
// (one group stalled while the other walks; both stalled; stop-and-go in one
// direction only), the rise time of a release, and the statistics of lapses
// between passages (Zuriguel et al. 2014) on synthetic passage times with a
// known power-law tail and known bursts.
#include <cmath>
#include <limits>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "crowdrecon/analysis/passages.hpp"
#include "crowdrecon/analysis/regime.hpp"
#include "crowdrecon/common/error.hpp"
#include "series_helpers.hpp"

namespace crowdrecon::analysis {

void PrintTo(Regime regime, std::ostream* os);  // test_analysis.cpp

// Named, not anonymous: the tests are compiled as one unity source with
// test_analysis.cpp, whose helpers have the same names.
namespace direction_tests {

using test_series::Series;
using test_series::Times;

// The crowd's mean speed from two directions of `a` and `b` people.
std::vector<double> Crowd(const DirectionSeries& a, const DirectionSeries& b) {
  std::vector<double> v;
  const double na = static_cast<double>(a.people), nb = static_cast<double>(b.people);
  for (std::size_t i = 0; i < a.speed_m_per_s.size(); ++i)
    v.push_back((na * a.speed_m_per_s[i] + nb * b.speed_m_per_s[i]) / (na + nb));
  return v;
}

// Moving at 0.6 m/s until 12 s, then every 8 s: 4 s at 0.02 m/s, 2 s at
// 0.8 m/s, 2 s at 0.02 m/s (six bursts, 16 .. 56 s).
double StopAndGo(double x) {
  if (x < 12.0 - 1e-9) return 0.6;
  const double phase = std::fmod(x - 12.0 + 1e-9, 8.0);
  return phase >= 4.0 && phase < 6.0 ? 0.8 : 0.02;
}

TEST(RegimeByDirection, OneDirectionStalledWhileTheOtherWalksIsClogging) {
  const std::vector<double> t = Times(60.0);
  const DirectionSeries exit{"to_exit", 126, Series(t, [](double) { return 0.85; })};
  // The counter-flow walks for 8 s, then stands (0.002 m/s) to the end.
  const DirectionSeries court{"to_court", 54, Series(t, [](double x) { return x < 8.0 ? 0.4 : 0.002; })};
  const std::vector<double> crowd = Crowd(exit, court);
  // The crowd alone looks free: 0.6 m/s, never below the stop speed.
  EXPECT_EQ(ClassifyRegime(t, crowd, {}, RegimeOptions{}).regime, Regime::kLanes);

  const RegimeResult r = ClassifyByDirection(t, crowd, {exit, court}, {}, RegimeOptions{});
  EXPECT_EQ(r.regime, Regime::kClogging) << r.reason;
  ASSERT_EQ(r.directions.size(), 2u);
  EXPECT_EQ(r.directions[0].name, "to_exit");
  EXPECT_EQ(r.directions[0].result.regime, Regime::kLanes) << r.directions[0].result.reason;
  EXPECT_EQ(r.directions[1].result.regime, Regime::kClogging) << r.directions[1].result.reason;
  EXPECT_TRUE(r.directions[1].result.frozen_at_end);
  EXPECT_NE(r.reason.find("a direction frozen at the end"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("to_court (54 people) 0.002 m/s"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("still moving: to_exit"), std::string::npos) << r.reason;
  // The crowd's own measurements are kept.
  EXPECT_DOUBLE_EQ(r.stopped_time_fraction, 0.0);
  EXPECT_FALSE(r.frozen_at_end);
}

TEST(RegimeByDirection, BothDirectionsStalledIsClogging) {
  const std::vector<double> t = Times(60.0);
  const DirectionSeries exit{"to_exit", 90, Series(t, [](double x) { return 0.8 * std::exp(-x / 6.0); })};
  const DirectionSeries court{"to_court", 90, Series(t, [](double x) { return 0.5 * std::exp(-x / 4.0); })};
  const RegimeResult r = ClassifyByDirection(t, Crowd(exit, court), {exit, court}, {}, RegimeOptions{});
  EXPECT_EQ(r.regime, Regime::kClogging) << r.reason;
  EXPECT_NE(r.reason.find("every direction frozen at the end"), std::string::npos) << r.reason;
  for (const DirectionRegime& d : r.directions) EXPECT_EQ(d.result.regime, Regime::kClogging);
}

TEST(RegimeByDirection, StopAndGoInOneDirectionOnlyIsAvalanches) {
  const std::vector<double> t = Times(60.0);
  const DirectionSeries exit{"to_exit", 150, Series(t, [](double) { return 0.9; })};
  const DirectionSeries court{"to_court", 30, Series(t, StopAndGo)};
  const std::vector<double> crowd = Crowd(exit, court);
  // Diluted in the crowd's mean (>= 0.75 m/s) the stops do not show.
  const RegimeResult whole = ClassifyRegime(t, crowd, {}, RegimeOptions{});
  EXPECT_EQ(whole.regime, Regime::kLanes);
  EXPECT_TRUE(whole.avalanches.empty());

  const RegimeResult r = ClassifyByDirection(t, crowd, {exit, court}, {}, RegimeOptions{});
  EXPECT_EQ(r.regime, Regime::kAvalanches) << r.reason;
  EXPECT_NE(r.reason.find("6 avalanches"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("of to_court"), std::string::npos) << r.reason;
  EXPECT_EQ(r.directions[0].result.regime, Regime::kLanes);
  EXPECT_EQ(r.directions[1].result.regime, Regime::kAvalanches);
  EXPECT_EQ(r.directions[1].result.stationary_avalanches, 6);
}

TEST(RegimeByDirection, EveryDirectionFreeIsLanesAndAnEmptiedDirectionIsSkippedSamples) {
  const std::vector<double> t = Times(40.0);
  const DirectionSeries exit{"to_exit", 100, Series(t, [](double) { return 0.9; })};
  // An open venue: the counter-flow has left after 25 s (no one present).
  const DirectionSeries court{"to_court", 20, Series(t, [](double x) {
                                return x < 25.0 ? 0.7 : std::numeric_limits<double>::quiet_NaN();
                              })};
  std::vector<double> crowd = exit.speed_m_per_s;
  const RegimeResult r = ClassifyByDirection(t, crowd, {exit, court}, {}, RegimeOptions{});
  EXPECT_EQ(r.regime, Regime::kLanes) << r.reason;
  EXPECT_NE(r.reason.find("every direction free"), std::string::npos) << r.reason;
  ASSERT_EQ(r.directions.size(), 2u);
  EXPECT_FALSE(r.directions[1].result.frozen_at_end);  // judged on the samples with people
  EXPECT_NEAR(r.directions[1].result.end_mean_speed_m_per_s, 0.7, 1e-12);
  // A series of the wrong length is refused.
  const DirectionSeries bad{"x", 1, {0.1, 0.2}};
  EXPECT_THROW(ClassifyByDirection(t, crowd, {bad}, {}, RegimeOptions{}), InputError);
}

TEST(RegimeByDirection, RiseTimeOfARelease) {
  // Stopped from 12 s to 20 s, then V rises linearly at 1 m/s^2 to 0.8 m/s:
  // from the stop speed (0.1) to the burst speed (0.3) takes 0.2 s.
  const std::vector<double> t = Times(40.0);
  const auto v = Series(t, [](double x) {
    if (x < 12.0 - 1e-9) return 0.6;
    if (x < 20.0 - 1e-9) return 0.0;
    return std::min(0.8, 0.05 + (x - 20.0));
  });
  const std::vector<Avalanche> a = FindAvalanches(t, v, RegimeOptions{});
  ASSERT_EQ(a.size(), 1u);
  EXPECT_NEAR(a[0].rise_time_s, 0.2, 1e-9);
  // A step from 0.02 to 0.8 m/s between two samples rises within one 0.1 s
  // interval: (0.3 - 0.1) / 0.78 of it.
  const std::vector<Avalanche> b = FindAvalanches(t, Series(t, StopAndGo), RegimeOptions{});
  ASSERT_FALSE(b.empty());
  EXPECT_NEAR(b[0].rise_time_s, 0.1 * 0.2 / 0.78, 1e-9);
}

// --- lapses between passages --------------------------------------------------

// Passage times whose lapses are drawn from p(t) = (alpha - 1)/t_min (t/t_min)^-alpha.
std::vector<double> ParetoPassages(double alpha, double t_min, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> times{0.0};
  for (std::size_t i = 0; i < n; ++i) times.push_back(times.back() + t_min * std::pow(1.0 - u(rng), -1.0 / (alpha - 1.0)));
  return times;
}

TEST(Passages, TailExponentOfAKnownPowerLaw) {
  PassageOptions options;
  options.tail_from_s = 0.5;
  for (double alpha : {1.6, 2.0, 2.5, 3.5}) {
    const std::vector<double> times = ParetoPassages(alpha, 0.5, 4000, 7);
    const PassageStatistics s = AnalyzePassages(times, 0.0, times.back(), options);
    EXPECT_EQ(s.passages, 4001u);
    EXPECT_EQ(s.tail_lapses, 4000u);
    // The estimator's standard error is (alpha - 1)/sqrt(n): 1-2.5 % here.
    EXPECT_NEAR(s.tail_exponent, alpha, 3.0 * s.tail_exponent_error) << alpha;
    EXPECT_NEAR(s.tail_exponent_error, (s.tail_exponent - 1.0) / std::sqrt(4000.0), 1e-12);
  }
  // Only the lapses from tail_from_s on enter the fit: power-law lapses from
  // 1 s on, each followed by three lapses of 0.2 s (a dense stream).
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> mixed{0.0};
  for (int i = 0; i < 3000; ++i) {
    mixed.push_back(mixed.back() + std::pow(1.0 - u(rng), -1.0 / 1.5));  // alpha = 2.5, t_min = 1 s
    for (int k = 0; k < 3; ++k) mixed.push_back(mixed.back() + 0.2);
  }
  options.tail_from_s = 1.0;
  const PassageStatistics m = AnalyzePassages(mixed, 0.0, mixed.back(), options);
  EXPECT_EQ(m.tail_lapses, 3000u);
  EXPECT_NEAR(m.tail_exponent, 2.5, 3.0 * m.tail_exponent_error);
  options.tail_from_s = 0.1;  // the stream's lapses now dominate the fit
  const PassageStatistics all = AnalyzePassages(mixed, 0.0, mixed.back(), options);
  EXPECT_EQ(all.tail_lapses, 12000u);
  EXPECT_LT(all.tail_exponent, 2.0);
}

TEST(Passages, SteadyStreamHasNoClogsAndNoTail) {
  std::vector<double> times;
  for (int i = 0; i < 200; ++i) times.push_back(10.0 + 0.4 * i);  // 10.0 .. 89.6 s
  const PassageStatistics s = AnalyzePassages(times, 10.0, 90.0, PassageOptions{});
  EXPECT_EQ(s.passages, 200u);
  EXPECT_EQ(s.lapses_s.size(), 199u);
  EXPECT_NEAR(s.median_lapse_s, 0.4, 1e-9);
  EXPECT_NEAR(s.mean_lapse_s, 0.4, 1e-9);
  EXPECT_NEAR(s.open_lapse_s, 0.4, 1e-9);
  EXPECT_EQ(s.clogs, 0);
  EXPECT_DOUBLE_EQ(s.clogged_fraction, 0.0);
  EXPECT_TRUE(s.burst_sizes.empty());
  EXPECT_TRUE(std::isnan(s.mean_burst_size));
  EXPECT_EQ(s.tail_lapses, 0u);
  EXPECT_TRUE(std::isnan(s.tail_exponent));
}

TEST(Passages, ClogsAndBurstsBetweenThem) {
  // Burst A (4 passages, cut by the window's start), clog of 5 s, burst B
  // (6 passages), clog of 3 s, burst C (3 passages), then nothing until the
  // end: an open lapse of 10 s, a clog that bounds C.
  std::vector<double> times;
  double t = 0.5;
  const auto burst = [&](int n) {
    for (int i = 0; i < n; ++i) times.push_back(t += (i == 0 ? 0.0 : 0.5));
  };
  burst(4);
  t += 5.0;
  burst(6);
  t += 3.0;
  burst(3);
  const double end = t + 10.0;
  times.push_back(-1.0);  // outside the window: ignored
  const PassageStatistics s = AnalyzePassages(times, 0.0, end, PassageOptions{});
  EXPECT_EQ(s.passages, 13u);
  EXPECT_EQ(s.clogs, 3);  // 5 s, 3 s and the open 10 s
  EXPECT_NEAR(s.open_lapse_s, 10.0, 1e-9);
  ASSERT_EQ(s.burst_sizes.size(), 2u);  // A is cut by the start
  EXPECT_EQ(s.burst_sizes[0], 6);
  EXPECT_EQ(s.burst_sizes[1], 3);
  EXPECT_NEAR(s.mean_burst_size, 4.5, 1e-12);
  EXPECT_NEAR(s.clogged_fraction, 18.0 / end, 1e-12);
  EXPECT_NEAR(s.max_lapse_s, 5.0, 1e-9);
  // Without passages the whole window is one open lapse.
  const PassageStatistics none = AnalyzePassages({}, 10.0, 40.0, PassageOptions{});
  EXPECT_EQ(none.passages, 0u);
  EXPECT_NEAR(none.open_lapse_s, 30.0, 1e-12);
  EXPECT_EQ(none.clogs, 1);
  EXPECT_TRUE(none.burst_sizes.empty());
  EXPECT_TRUE(std::isnan(none.median_lapse_s));
}

TEST(Passages, OptionsAndWindowAreChecked) {
  PassageOptions bad;
  bad.clog_lapse_s = 0.0;
  std::string error;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_EQ(error, "passages clog_lapse_s = 0 s, expected (0, 3600]");
  EXPECT_THROW(AnalyzePassages({1.0}, 0.0, 10.0, bad), InputError);
  EXPECT_THROW(AnalyzePassages({1.0}, 5.0, 1.0, PassageOptions{}), InputError);
}

}  // namespace direction_tests
}  // namespace crowdrecon::analysis
