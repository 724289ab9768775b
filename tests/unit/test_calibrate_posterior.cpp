// The calibration's posterior (issue 23): the sampler against the analytic
// posterior of a linear problem, its local surrogate, the seeds' surfaces,
// the likelihood with a known and an estimated covariance, and its quantiles.
// (The surrogate and the objective: test_calibrate.cpp.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "crowdrecon/analysis/timeline_series.hpp"
#include "crowdrecon/calibrate/calibration_file.hpp"
#include "crowdrecon/calibrate/statistics.hpp"
#include "crowdrecon/common/error.hpp"
#include "fit.hpp"
#include "footage.hpp"
#include "scratch.hpp"

namespace crowdrecon::calibrate {
namespace {

// The posterior's sampler against the analytic posterior: linear statistics
// m = A u with Gaussian errors give a Gaussian posterior of covariance
// (JᵀJ)⁻¹ about the least-squares solution (far inside the box, the flat
// prior's edges do not matter); a surrogate's variance shared by the
// statistics widens it as the generalised chi2 says; a coordinate nothing
// depends on comes out uniform over the box; the same seed, the same samples.
TEST(Posterior, MatchesTheAnalyticPosteriorOfALinearProblem) {
  const LinearProblem linear;
  const auto& a = linear.a;
  const auto& pts = linear.corners;
  const Quadratic& q = linear.q;
  const std::vector<double> truth{0.45, 0.55};
  std::vector<double> observed;
  for (const auto& row : a) observed.push_back(row[0] * truth[0] + row[1] * truth[1]);
  const double sd = 0.04;
  Objective o = ObjectiveObserving(observed, {sd, sd, sd});
  // Each coordinate's mean, standard deviation and central 68 % interval.
  struct Marginal {
    double mean, sd, lo68, hi68;
  };
  const auto marginals = [](const PosteriorSamples& ps) {
    std::vector<Marginal> out;
    for (std::size_t i = 0; i < 2; ++i) {
      std::vector<double> v;
      for (const auto& u : ps.u) v.push_back(u[i]);
      std::sort(v.begin(), v.end());
      double mean = 0.0, ss = 0.0;
      for (double x : v) mean += x / static_cast<double>(v.size());
      for (double x : v) ss += (x - mean) * (x - mean);
      out.push_back({mean, std::sqrt(ss / static_cast<double>(v.size() - 1)), Quantile(v, 0.15865), Quantile(v, 0.84135)});
    }
    return out;
  };
  const auto analytic_sd = [&](double var) {
    double jtj[2][2] = {{0, 0}, {0, 0}};
    for (const auto& row : a)
      for (int i = 0; i < 2; ++i)
        for (int k = 0; k < 2; ++k) jtj[i][k] += row[i] * row[k] / var;
    const double det = jtj[0][0] * jtj[1][1] - jtj[0][1] * jtj[1][0];
    return std::vector<double>{std::sqrt(jtj[1][1] / det), std::sqrt(jtj[0][0] / det)};
  };
  const std::vector<std::vector<double>> starts{{0.5, 0.5}, {0.2, 0.8}, {0.8, 0.3}, {0.3, 0.3}};
  const auto sample = [&](const Objective& obj, const Quadratic& mean, std::uint64_t seed) {
    const SurrogateLikelihood l(mean, obj);
    return SamplePosterior([&](const std::vector<double>& u) { return l(u); }, starts, 40000, seed);
  };
  const PosteriorSamples ps = sample(o, q, 7);
  ASSERT_EQ(ps.u.size(), 4u * 30000u);
  EXPECT_EQ(ps.chains, 4u);
  EXPECT_GT(ps.acceptance, 0.15);
  EXPECT_LT(ps.acceptance, 0.6);
  const std::vector<Marginal> m = marginals(ps);
  const std::vector<double> expected = analytic_sd(sd * sd);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_LT(ps.r_hat[i], 1.01);
    EXPECT_NEAR(m[i].mean, truth[i], 0.1 * expected[i]) << i;
    EXPECT_NEAR(m[i].sd, expected[i], 0.05 * expected[i]) << i;
    EXPECT_NEAR(m[i].lo68, truth[i] - expected[i], 0.1 * expected[i]) << i;
    EXPECT_NEAR(m[i].hi68, truth[i] + expected[i], 0.1 * expected[i]) << i;
  }
  // The same seed: the same samples.
  EXPECT_EQ(sample(o, q, 7).u, ps.u);

  // A surrogate's variance, shared by the three statistics (one simulated
  // value each here, so it adds to each diagonal): sd² + v.
  o.surrogate_variance.assign(3, 0.03 * 0.03);
  o.Reobserve();
  const std::vector<Marginal> wider = marginals(sample(o, q, 7));
  const std::vector<double> expected_wider = analytic_sd(sd * sd + 0.03 * 0.03);
  for (std::size_t i = 0; i < 2; ++i) EXPECT_NEAR(wider[i].sd, expected_wider[i], 0.05 * expected_wider[i]) << i;

  // Statistics of u[0] alone: u[1] is uniform over the box.
  std::vector<std::vector<double>> flat;
  for (const auto& p : pts) flat.push_back({2.0 * p[0], -p[0]});
  Quadratic f;
  ASSERT_TRUE(f.Fit(pts, flat, {0.5, 0.5}, 0.5));
  const PosteriorSamples free = sample(ObjectiveObserving({1.0, -0.5}, {0.1, 0.1}), f, 8);
  std::vector<double> v;
  for (const auto& u : free.u) v.push_back(u[1]);
  std::sort(v.begin(), v.end());
  EXPECT_NEAR(Quantile(v, 0.025), 0.025, 0.02);
  EXPECT_NEAR(Quantile(v, 0.5), 0.5, 0.03);
  EXPECT_NEAR(Quantile(v, 0.975), 0.975, 0.02);
  // Nothing to sample: no start.
  EXPECT_TRUE(SamplePosterior([](const std::vector<double>&) { return 0.0; }, {}, 40000, 8).u.empty());
}

// The posterior's local surrogate: with an infinite bandwidth it is the
// quadratic over the whole box; a statistic steep at one end and flat at the
// other (1 - exp(-u / 0.1), as the restitution acts) is followed by a
// quadratic fitted around each point where the global one cannot, the
// leave-one-out error says so, and the bandwidth chosen is finite; for a
// quadratic statistic the global fit is exact and chosen.
TEST(Posterior, ALocalQuadraticFollowsWhatAGlobalOneCannot) {
  std::vector<std::vector<double>> pts;
  for (int i = 0; i <= 6; ++i)
    for (int k = 0; k <= 6; ++k) pts.push_back({i / 6.0, k / 6.0});
  const auto steep = [](const std::vector<double>& u) { return 1.0 - std::exp(-u[0] / 0.1) + 0.3 * u[1]; };
  const auto quad = [](const std::vector<double>& u) { return 0.5 + u[0] - 0.7 * u[0] * u[1] + 0.2 * u[1] * u[1]; };
  std::vector<std::vector<double>> values;
  for (const auto& u : pts) values.push_back({steep(u), quad(u)});
  Quadratic global;
  ASSERT_TRUE(global.Fit(pts, values, {0.5, 0.5}, 0.5));
  const LocalQuadratic whole(pts, values, std::numeric_limits<double>::infinity());
  for (const std::vector<double>& u : {std::vector<double>{0.1, 0.3}, std::vector<double>{0.77, 0.9}}) {
    const std::vector<double> a = whole.Values(u), b = global.Values(u);
    EXPECT_NEAR(a[0], b[0], 1e-9);
    EXPECT_NEAR(a[1], b[1], 1e-9);
  }
  const LocalQuadratic near(pts, values, 0.15);
  double global_error = 0.0, local_error = 0.0;
  for (double x = 0.02; x < 1.0; x += 0.05) {
    const std::vector<double> u{x, 0.4};
    global_error = std::max(global_error, std::abs(whole.Values(u)[0] - steep(u)));
    local_error = std::max(local_error, std::abs(near.Values(u)[0] - steep(u)));
    EXPECT_NEAR(near.Values(u)[1], quad(u), 1e-9);  // a quadratic is exact at any bandwidth
  }
  EXPECT_GT(global_error, 0.05);
  EXPECT_LT(local_error, 0.5 * global_error);
  std::vector<double> scores;
  const double h = ChooseBandwidth(pts, values, {1e-4, 1e-4}, {0.15, 0.4, std::numeric_limits<double>::infinity()}, &scores);
  ASSERT_EQ(scores.size(), 3u);
  EXPECT_TRUE(std::isfinite(h)) << h;
  EXPECT_LT(scores[0], scores[2]);
  // The quadratic statistic alone: every bandwidth is exact; the first of
  // the best is kept, and its leave-one-out error is round-off.
  std::vector<std::vector<double>> only;
  for (const auto& v : values) only.push_back({v[1]});
  double score = 1.0;
  const std::vector<double> loo = LocalQuadratic(pts, only, 0.4).LeaveOneOutVariance({1e-4}, &score);
  EXPECT_LT(loo[0], 1e-20);
  EXPECT_LT(score, 1e-14);
  // Left out: the point's own value does not enter its prediction.
  std::vector<std::vector<double>> bumped = values;
  bumped[24][0] += 10.0;
  EXPECT_NEAR(LocalQuadratic(pts, bumped, 0.15).Values(pts[24], 24)[0], near.Values(pts[24], 24)[0], 1e-9);
  EXPECT_GT(std::abs(LocalQuadratic(pts, bumped, 0.15).Values(pts[24])[0] - near.Values(pts[24])[0]), 0.1);
}

// The seeds' mean as an uncertain function: K seeds whose surfaces differ
// in slope (common random numbers: smooth, zero difference at the anchor)
// give the means an error that grows away from the anchor; sampled with the
// parameters (weights w = Phi^-1(z)), the posterior of u is the marginal one,
// y ~ N(a u, sigma^2 + v (u - anchor)^2), computed here on a grid.
TEST(Posterior, TheSeedsSurfacesWidenItAsTheirSlopesDiffer) {
  EXPECT_NEAR(NormalQuantile(0.5), 0.0, 1e-14);
  EXPECT_NEAR(NormalQuantile(0.975), 1.959963984540054, 1e-12);
  EXPECT_NEAR(NormalQuantile(1e-10), -6.361340902404056, 1e-9);
  EXPECT_NEAR(NormalQuantile(0.3) + NormalQuantile(0.7), 0.0, 1e-14);
  EXPECT_TRUE(std::isinf(NormalQuantile(0.0)) && std::isinf(NormalQuantile(1.0)));

  const std::vector<double> slopes{-0.3, -0.1, 0.1, 0.3};  // per seed, about the anchor 0.5
  std::vector<std::vector<double>> pts;
  std::vector<std::vector<std::vector<double>>> per_set_seed;
  std::vector<std::vector<double>> means;
  for (int i = 0; i <= 10; ++i) {
    const double u = i / 10.0;
    pts.push_back({u});
    means.push_back({u});
    std::vector<std::vector<double>> seeds;
    for (double c : slopes) seeds.push_back({u + c * (u - 0.5)});
    per_set_seed.push_back(seeds);
  }
  SeedSurfaces surfaces;
  ASSERT_TRUE(surfaces.Fit(pts, per_set_seed, {0.5}));
  EXPECT_EQ(surfaces.seeds(), 4u);
  EXPECT_NEAR(surfaces.Offset({0.5}, {1.0, -2.0, 0.5, 3.0})[0], 0.0, 1e-12);  // nothing at the anchor
  const double v = (0.09 + 0.01 + 0.01 + 0.09) / 3.0 / 4.0;                 // the slopes' sample variance / K
  // The offset is linear in w: its variance over w ~ N(0, I) is the sum of its squared coefficients.
  double var = 0.0;
  for (std::size_t s = 0; s < 4; ++s) {
    std::vector<double> w(4, 0.0);
    w[s] = 1.0;
    const double o = surfaces.Offset({0.9}, w)[0];
    var += o * o;
  }
  EXPECT_NEAR(var, v * 0.16, 1e-12);

  Quadratic q;
  ASSERT_TRUE(q.Fit(pts, means, {0.5}, 0.5));
  const double sigma = 0.05, truth = 0.8;
  const Objective o = ObjectiveObserving({truth}, {sigma});
  const SurrogateLikelihood l(q, o);
  const auto sample = [&](bool with_seeds) {
    std::vector<std::vector<double>> starts{{0.5}, {0.3}, {0.7}, {0.9}};
    if (with_seeds)
      for (auto& x : starts) x.resize(5, 0.5);
    const PosteriorSamples ps = SamplePosterior(
        [&](const std::vector<double>& x) {
          if (!with_seeds) return l(x);
          std::vector<double> w;
          for (std::size_t s = 1; s < 5; ++s) w.push_back(NormalQuantile(x[s]));
          return l.WithOffset({x[0]}, surfaces.Offset({x[0]}, w));
        },
        starts, 60000, 11);
    std::vector<double> u;
    for (const auto& x : ps.u) u.push_back(x[0]);
    return SampleSd(u);
  };
  const auto grid_sd = [&](double slope_var) {
    double z = 0.0, m1 = 0.0, m2 = 0.0;
    for (double u = 0.00005; u < 1.0; u += 0.0001) {
      const double s2 = sigma * sigma + slope_var * (u - 0.5) * (u - 0.5);
      const double d = std::exp(-0.5 * (truth - u) * (truth - u) / s2) / std::sqrt(s2);
      z += d;
      m1 += d * u;
      m2 += d * u * u;
    }
    return std::sqrt(m2 / z - (m1 / z) * (m1 / z));
  };
  const double plain = sample(false), wider = sample(true);
  EXPECT_NEAR(plain, grid_sd(0.0), 0.05 * grid_sd(0.0));
  EXPECT_NEAR(wider, grid_sd(v), 0.05 * grid_sd(v));
  EXPECT_GT(grid_sd(v), 1.1 * grid_sd(0.0));
}

// The likelihood: -chi2 / 2 of the generalised chi2, divided by the
// overdispersion scale.
TEST(Posterior, TheLikelihoodIsTheScaledChi2) {
  Objective o = ObjectiveObserving({0.5}, {0.1});
  o.WeighCovariance({0.04}, 3.0);
  Quadratic mean;
  ASSERT_TRUE(mean.Fit({{0.0}, {1.0}}, {{0.0}, {1.0}}, {0.5}, 0.5));
  const SurrogateLikelihood plain(mean, o), wider(mean, o, 2.5);
  const double c = 0.01 + 0.04 * (1.0 + 1.0 / 3.0);
  for (double u : {0.2, 0.5, 0.9}) {
    EXPECT_NEAR(plain({u}), -0.5 * (u - 0.5) * (u - 0.5) / c, 1e-12) << u;
    EXPECT_NEAR(wider({u}), -0.5 * (u - 0.5) * (u - 0.5) / c / 2.5, 1e-12) << u;
  }
}

// With an estimated covariance the likelihood's argument leaves out the
// scatter between recordings, the part of chi2 no simulated means can
// remove (issue 41, point 3: at K = 6 it widened the intervals beyond their
// level). Two recordings of one simulated value, 0.4 and 0.6, and three of
// another, 1.0, 1.2, 1.1: at the means that match the recordings' means the
// likelihood is at its top, log 1 = 0, and elsewhere the argument is chi2
// less its value there.
TEST(Posterior, TheEstimatedCovariancesLikelihoodLeavesOutTheScatterBetweenRecordings) {
  Objective o;
  const std::vector<std::pair<std::string, double>> recorded = {{"a", 0.4}, {"a", 0.6}, {"b", 1.0}, {"b", 1.2}, {"b", 1.1}};
  for (std::size_t j = 0; j < recorded.size(); ++j) {
    Statistic st;
    st.name = recorded[j].first + std::to_string(j);
    st.simulated_from = recorded[j].first;
    st.observation = j;  // each its own recording
    st.observed = recorded[j].second;
    st.observed_sigma = 0.05;
    o.statistics.push_back(st);
  }
  const std::size_t n = recorded.size();
  std::vector<double> s(n * n, 0.0);
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t i = 0; i < n; ++i)
      if (recorded[j].first == recorded[i].first) s[j * n + i] = 0.01;
  o.WeighCovariance(s, 6.0);
  ASSERT_EQ(o.lead, (std::vector<std::size_t>{0, 0, 2, 2, 2}));
  // The simulated means: a = u, b = u + 0.6 (one parameter).
  std::vector<std::vector<double>> pts, vals;
  for (double u : {0.0, 0.5, 1.0}) {
    pts.push_back({u});
    vals.push_back({u, u, u + 0.6, u + 0.6, u + 0.6});
  }
  Quadratic mean;
  ASSERT_TRUE(mean.Fit(pts, vals, {0.5}, 0.5));
  const EstimatedCovariance estimated{30.0, 2.0, 1.0};
  const SurrogateLikelihood l(mean, o, 1.0, nullptr, estimated);
  const auto chi2 = [&](double u) { return o.Chi2({u, u, u + 0.6, u + 0.6, u + 0.6}); };
  // The best u: a's recordings say 0.5, b's 0.5 as well.
  const double scatter = chi2(0.5);
  EXPECT_GT(scatter, 1.0);  // (0.1^2 + 0.1^2 + 0.1^2 + 0.1^2) / (0.05^2 + 0.01) = 3.2 without correlations
  EXPECT_NEAR(l({0.5}), 0.0, 1e-12);
  for (double u : {0.3, 0.45, 0.7})
    EXPECT_NEAR(l({u}), -0.5 * estimated.Power() * std::log1p((chi2(u) - scatter) / estimated.freedom), 1e-9) << u;
  // Known sigmas (no estimated covariance): the Gaussian of the whole chi2.
  const SurrogateLikelihood gaussian(mean, o);
  EXPECT_NEAR(gaussian({0.7}), -0.5 * chi2(0.7), 1e-9);
}

// A seeds' covariance estimated from few runs: the Gaussian likelihood
// that takes it as known gives "95 %" intervals that cover far less; the
// likelihood for an estimated covariance (Percival et al. 2022) covers as
// it claims. 8 statistics that each read the parameter, one recording with
// a correlated error, S the sample covariance of 16 runs (15 degrees of
// freedom) drawn afresh for each of 500 replicates.
TEST(Posterior, AnEstimatedCovariancesLikelihoodCoversAsItClaims) {
  constexpr std::size_t kStats = 8, kRuns = 16, kReplicates = 500;
  std::vector<std::vector<double>> pts, vals;
  for (double u : {0.0, 0.5, 1.0}) {
    pts.push_back({u});
    vals.push_back(std::vector<double>(kStats, u));
  }
  Quadratic mean;
  ASSERT_TRUE(mean.Fit(pts, vals, {0.5}, 0.5));
  // The true covariance: sd 0.04-0.07, correlations 0.5^|j-k|.
  std::vector<double> sd(kStats), chol(kStats * kStats, 0.0), sigma(kStats * kStats);
  for (std::size_t j = 0; j < kStats; ++j) sd[j] = 0.04 + 0.03 * static_cast<double>(j) / (kStats - 1);
  for (std::size_t j = 0; j < kStats; ++j)
    for (std::size_t k = 0; k < kStats; ++k)
      sigma[j * kStats + k] = sd[j] * sd[k] * std::pow(0.5, std::abs(static_cast<double>(j) - static_cast<double>(k)));
  for (std::size_t j = 0; j < kStats; ++j)  // Cholesky, lower
    for (std::size_t k = 0; k <= j; ++k) {
      double v = sigma[j * kStats + k];
      for (std::size_t i = 0; i < k; ++i) v -= chol[j * kStats + i] * chol[k * kStats + i];
      chol[j * kStats + k] = j == k ? std::sqrt(v) : v / chol[k * kStats + k];
    }
  std::mt19937_64 rng(20121031);
  std::normal_distribution<double> normal;
  const auto draw = [&] {
    std::vector<double> z(kStats), x(kStats, 0.0);
    for (double& v : z) v = normal(rng);
    for (std::size_t j = 0; j < kStats; ++j)
      for (std::size_t k = 0; k <= j; ++k) x[j] += chol[j * kStats + k] * z[k];
    return x;
  };
  const double truth = 0.5;
  const EstimatedCovariance estimated{kRuns - 1.0, static_cast<double>(kStats), 1.0};
  std::size_t inside_known = 0, inside_estimated = 0;
  for (std::size_t rep = 0; rep < kReplicates; ++rep) {
    std::vector<double> observed = draw();
    for (double& v : observed) v += truth;
    std::vector<std::vector<double>> runs;
    std::vector<double> m(kStats, 0.0), s(kStats * kStats, 0.0);
    for (std::size_t r = 0; r < kRuns; ++r) {
      runs.push_back(draw());
      for (std::size_t j = 0; j < kStats; ++j) m[j] += runs.back()[j] / kRuns;
    }
    for (const auto& x : runs)
      for (std::size_t j = 0; j < kStats; ++j)
        for (std::size_t k = 0; k < kStats; ++k) s[j * kStats + k] += (x[j] - m[j]) * (x[k] - m[k]) / (kRuns - 1.0);
    Objective o = ObjectiveObserving(observed, std::vector<double>(kStats, 0.0));
    o.WeighCovariance(s, 1e12);  // the simulated mean exact: C = S
    const SurrogateLikelihood known(mean, o), with_estimate(mean, o, 1.0, nullptr, estimated);
    const auto covers = [&](const SurrogateLikelihood& l) {
      std::vector<double> u, logp;
      for (double x = 0.0; x <= 1.0; x += 0.0005) {
        u.push_back(x);
        logp.push_back(l({x}));
      }
      const double top = *std::max_element(logp.begin(), logp.end());
      std::vector<double> cdf;
      double sum = 0.0;
      for (double v : logp) cdf.push_back(sum += std::exp(v - top));
      const auto at = [&](double q) { return u[std::lower_bound(cdf.begin(), cdf.end(), q * sum) - cdf.begin()]; };
      return at(0.025) <= truth && truth <= at(0.975);
    };
    inside_known += covers(known);
    inside_estimated += covers(with_estimate);
  }
  const double known_share = static_cast<double>(inside_known) / kReplicates;
  const double estimated_share = static_cast<double>(inside_estimated) / kReplicates;
  // 500 replicates: a share's standard error is about 0.01 at 0.95.
  EXPECT_NEAR(estimated_share, 0.95, 0.025) << "known " << known_share;
  EXPECT_LT(known_share, 0.8);
  // The power: Percival et al.'s formula, its few-runs limit, and the
  // Gaussian as the runs grow (the likelihood's curvature at chi2 = 0 is
  // power / freedom: 1 in the limit).
  EXPECT_NEAR(estimated.Power(), 9.6, 1e-12);  // B = 6 / (7 x 4), B (8 - 1) = 1.5: 1 + 2 + 16.5 / 2.5
  EXPECT_EQ((EstimatedCovariance{10.0, 8.0, 2.0}.Power()), 5.0);
  const EstimatedCovariance many{1e6, 8.0, 1.0};
  EXPECT_NEAR(many.Power() / many.freedom, 1.0, 1e-4);
  EXPECT_TRUE(EstimatedCovariance{}.known());
}

TEST(Posterior, QuantilesInterpolateBetweenOrderStatistics) {
  const std::vector<double> v{0.0, 1.0, 2.0, 3.0};
  EXPECT_EQ(Quantile(v, 0.0), 0.0);
  EXPECT_EQ(Quantile(v, 1.0), 3.0);
  EXPECT_DOUBLE_EQ(Quantile(v, 0.5), 1.5);
  EXPECT_DOUBLE_EQ(Quantile(v, 0.25), 0.75);
  EXPECT_EQ(Quantile({4.0}, 0.3), 4.0);
}

}  // namespace
}  // namespace crowdrecon::calibrate
