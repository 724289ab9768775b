// Calibration (issue 23): the quadratic surrogate fitted exactly to a known
// quadratic; Ceres finding a known minimum, inside the box and on its edge;
// Ceres' covariance equal to (JᵀJ)⁻¹ of a linear model, and a parameter no
// statistic depends on reported rank deficient; the objective and the
// profile's noise. (The posterior: test_calibrate_posterior.cpp; calibration
// files and their statistics: test_calibration_file.cpp.)
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

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Two statistics of two unit coordinates, known quadratics.
double F0(const std::vector<double>& u) { return 1.0 + 2.0 * u[0] - u[1] + 3.0 * u[0] * u[0] + 0.5 * u[0] * u[1]; }
double F1(const std::vector<double>& u) { return -0.5 + u[1] + 2.0 * u[1] * u[1] - u[0] * u[1]; }

TEST(Surrogate, AQuadraticIsFittedExactlyWithItsGradient) {
  std::vector<std::vector<double>> pts, vals;
  for (double a : {0.0, 0.5, 1.0})
    for (double b : {0.0, 0.5, 1.0}) {
      pts.push_back({a, b});
      vals.push_back({F0({a, b}), F1({a, b})});
    }
  Quadratic q;
  ASSERT_TRUE(q.Fit(pts, vals, {0.5, 0.5}, 0.5));
  EXPECT_EQ(q.form, "full quadratic");
  const std::vector<double> u{0.3, 0.8};
  EXPECT_NEAR(q.Value(0, u), F0(u), 1e-12);
  EXPECT_NEAR(q.Value(1, u), F1(u), 1e-12);
  const std::vector<double> g = q.Gradient(0, u);
  EXPECT_NEAR(g[0], 2.0 + 6.0 * u[0] + 0.5 * u[1], 1e-10);
  EXPECT_NEAR(g[1], -1.0 + 0.5 * u[0], 1e-10);
  EXPECT_LT(q.rms[0], 1e-12);
  // Fewer points: squares without cross terms, then linear.
  Quadratic few;
  ASSERT_TRUE(few.Fit({pts[0], pts[1], pts[2], pts[3], pts[4], pts[5]}, {vals[0], vals[1], vals[2], vals[3], vals[4], vals[5]},
                      {0.5, 0.5}, 0.5));
  EXPECT_EQ(few.form, "quadratic without cross terms");
  Quadratic line;
  ASSERT_TRUE(line.Fit({pts[0], pts[1], pts[3]}, {vals[0], vals[1], vals[3]}, {0.5, 0.5}, 0.5));
  EXPECT_EQ(line.form, "linear");
  EXPECT_FALSE(Quadratic().Fit({pts[0], pts[1]}, {vals[0], vals[1]}, {0.5, 0.5}, 0.5));
}

Objective ObjectiveObserving(const std::vector<double>& observed, const std::vector<double>& sigma) {
  Objective o;
  for (std::size_t j = 0; j < observed.size(); ++j) {
    Statistic s;
    s.name = "s" + std::to_string(j);
    s.observed = observed[j];
    s.observed_sigma = sigma[j];
    o.statistics.push_back(s);
  }
  o.Weigh({}, 1.0);  // no seed spread: sigma is the observed one
  return o;
}

TEST(Surrogate, CeresFindsTheParametersThatReproduceTheObservation) {
  std::vector<std::vector<double>> pts, vals;
  for (double a : {0.0, 0.5, 1.0})
    for (double b : {0.0, 0.5, 1.0}) {
      pts.push_back({a, b});
      vals.push_back({F0({a, b}), F1({a, b})});
    }
  Quadratic q;
  ASSERT_TRUE(q.Fit(pts, vals, {0.5, 0.5}, 0.5));
  const std::vector<double> truth{0.35, 0.7};
  const Objective o = ObjectiveObserving({F0(truth), F1(truth)}, {0.1, 0.1});
  for (const std::vector<double>& start : {std::vector<double>{0.9, 0.1}, std::vector<double>{0.1, 0.95}}) {
    const Minimum m = MinimiseSurrogate(q, o, start);
    EXPECT_NEAR(m.u[0], truth[0], 1e-6);
    EXPECT_NEAR(m.u[1], truth[1], 1e-6);
    EXPECT_LT(m.chi2, 1e-10);
  }
  // An observation the box cannot reach: the optimum lies on its edge.
  const Objective beyond = ObjectiveObserving({F0({1.0, 0.7}) + 5.0, F1({1.0, 0.7})}, {0.1, 0.1});
  EXPECT_NEAR(MinimiseSurrogate(q, beyond, {0.5, 0.5}).u[0], 1.0, 1e-9);
  // A coordinate held: the other is minimised alone.
  const Minimum held = MinimiseSurrogate(q, o, {0.6, 0.2}, 0);
  EXPECT_EQ(held.u[0], 0.6);
  EXPECT_GT(held.chi2, 0.0);
}

// The gradient approach's minimiser: residuals r = A (u - target) with
// Jacobians by the function itself. It finds a minimum inside the box and
// one beyond its edge (clamped onto the edge), and asks for a Jacobian only
// at the start and where a step was accepted, never at every trial point
// (each Jacobian is a stencil of 2p + 1 parameter sets).
TEST(GradientSearch, FindsMinimaInsideAndOnTheEdgeWithFewJacobians) {
  for (const std::vector<double>& target : {std::vector<double>{0.3, 0.7}, std::vector<double>{1.4, 0.2}}) {
    int jacobians = 0, evaluations = 0;
    const ResidualFunction f = [&](const std::vector<double>& u, std::vector<double>* r, std::vector<double>* j) {
      EXPECT_GE(u[0], 0.0);
      EXPECT_LE(u[0], 1.0);
      ++evaluations;
      const double a[3][2] = {{2.0, 0.5}, {0.0, 1.5}, {1.0, -1.0}};
      r->assign(3, 0.0);
      for (int k = 0; k < 3; ++k) (*r)[k] = a[k][0] * (u[0] - target[0]) + a[k][1] * (u[1] - target[1]);
      if (j) {
        ++jacobians;
        j->assign(6, 0.0);
        for (int k = 0; k < 3; ++k)
          for (int i = 0; i < 2; ++i) (*j)[static_cast<std::size_t>(k * 2 + i)] = a[k][i];
      }
      return true;
    };
    const Minimum m = MinimiseFunction(f, 3, {0.9, 0.1}, 20);
    const double expected0 = std::min(target[0], 1.0);
    EXPECT_NEAR(m.u[0], expected0, 1e-6) << m.termination;
    if (target[0] <= 1.0) {
      EXPECT_NEAR(m.u[1], target[1], 1e-6) << m.termination;
    } else {
      // u0 held at the edge: the best u1 minimises |A (u - target)| with u0 = 1.
      // d/du1: sum_k a_k1 (a_k0 (1 - t0) + a_k1 (u1 - t1)) = 0.
      const double d0 = 1.0 - target[0];
      const double num = -(2.0 * 0.5 * d0 + 0.0 + 1.0 * -1.0 * d0);
      const double den = 0.5 * 0.5 + 1.5 * 1.5 + 1.0;
      EXPECT_NEAR(m.u[1], target[1] + num / den, 1e-4) << m.termination;  // Ceres' function tolerance
    }
    EXPECT_LE(jacobians, m.iterations + 1) << evaluations << " evaluations";
  }
}

// Three statistics linear in two unit coordinates, m = A u, and their
// quadratic fitted at the box's corners (exact).
struct LinearProblem {
  const double a[3][2] = {{1.0, 0.5}, {-0.3, 2.0}, {0.7, 0.7}};
  std::vector<std::vector<double>> corners{{0.0, 0.0}, {0.0, 1.0}, {1.0, 0.0}, {1.0, 1.0}};
  Quadratic q;
  LinearProblem() {
    std::vector<std::vector<double>> vals;
    for (const auto& u : corners)
      vals.push_back({a[0][0] * u[0] + a[0][1] * u[1], a[1][0] * u[0] + a[1][1] * u[1], a[2][0] * u[0] + a[2][1] * u[1]});
    if (!q.Fit(corners, vals, {0.5, 0.5}, 0.5)) throw std::logic_error("the linear problem's fit");
  }
};

TEST(Surrogate, CovarianceIsTheInverseOfJtJAndAFreeParameterIsReported) {
  // Linear statistics m = A u + b with sigma 0.5: covariance (JᵀJ)⁻¹, J = A / 0.5.
  const LinearProblem linear;
  const auto& a = linear.a;
  const auto& pts = linear.corners;
  const Quadratic& q = linear.q;
  const Objective o = ObjectiveObserving({0.5, 0.5, 0.5}, {0.5, 0.5, 0.5});
  std::vector<double> cov;
  std::string reason;
  std::vector<int> without_effect;
  ASSERT_TRUE(SurrogateCovariance(q, o, {0.4, 0.6}, &cov, &reason, &without_effect)) << reason;
  EXPECT_TRUE(without_effect.empty());
  double jtj[2][2] = {{0, 0}, {0, 0}};
  for (const auto& row : a)
    for (int i = 0; i < 2; ++i)
      for (int k = 0; k < 2; ++k) jtj[i][k] += row[i] * row[k] / 0.25;
  const double det = jtj[0][0] * jtj[1][1] - jtj[0][1] * jtj[1][0];
  EXPECT_NEAR(cov[0], jtj[1][1] / det, 1e-9);
  EXPECT_NEAR(cov[1], -jtj[0][1] / det, 1e-9);
  EXPECT_NEAR(cov[3], jtj[0][0] / det, 1e-9);

  // Statistics that depend on u[0] only: u[1] is listed as without effect,
  // and u[0]'s variance is that of the problem without it.
  std::vector<std::vector<double>> flat;
  for (const auto& p : pts) flat.push_back({2.0 * p[0], -p[0]});
  Quadratic f;
  ASSERT_TRUE(f.Fit(pts, flat, {0.5, 0.5}, 0.5));
  ASSERT_TRUE(SurrogateCovariance(f, ObjectiveObserving({1.0, -0.5}, {0.1, 0.1}), {0.5, 0.5}, &cov, &reason, &without_effect));
  ASSERT_EQ(without_effect, std::vector<int>{1});
  EXPECT_NEAR(cov[0], 1.0 / (4.0 / 0.01 + 1.0 / 0.01), 1e-12);
  EXPECT_EQ(cov[3], 0.0);
  // Statistics that depend on u[0] + u[1] only: a combination is free, said so.
  std::vector<std::vector<double>> sum;
  for (const auto& p : pts) sum.push_back({p[0] + p[1], 2.0 * (p[0] + p[1])});
  Quadratic g;
  ASSERT_TRUE(g.Fit(pts, sum, {0.5, 0.5}, 0.5));
  EXPECT_FALSE(SurrogateCovariance(g, ObjectiveObserving({1.0, 2.0}, {0.1, 0.1}), {0.5, 0.5}, &cov, &reason, &without_effect));
  EXPECT_NE(reason.find("rank deficient"), std::string::npos) << reason;
}

// Recordings of one simulated value share its error (seed_sd^2 / K): their
// residuals are whitened so that chi2 is the generalised one, within-group
// scatter plus (m - weighted mean)^2 / (1/W + seed_sd^2/K), and the
// parameter's variance stops shrinking at (seed_sd^2 / K) / slope^2 however
// many recordings there are.
TEST(Objective, RecordingsOfOneSimulatedValueShareItsError) {
  const auto statistic = [](double observed, double from, std::size_t recording) {
    Statistic s;
    s.observation = recording;
    s.simulated_from = "spec";
    s.quantity = "speed";
    s.sim_from_s = from;
    s.sim_to_s = from + 5.0;
    s.observed = observed;
    s.observed_sigma = 0.1;
    return s;
  };
  Objective o;
  o.statistics = {statistic(1.0, 0.0, 0), statistic(2.0, 0.0, 1), statistic(3.0, 5.0, 0)};
  o.Weigh({0.5, 0.5, 0.5}, 4.0);
  EXPECT_EQ(o.lead, (std::vector<std::size_t>{0, 0, 2}));
  const double d = 0.01 + 0.25, w = 2.0 / d, a = 0.25 / 4.0;
  const double grouped = 2 * 0.25 / d + (1.7 - 1.5) * (1.7 - 1.5) / (1.0 / w + a);
  const double alone = (2.6 - 3.0) * (2.6 - 3.0) / (0.01 + 0.25 * (1.0 + 1.0 / 4.0));
  EXPECT_NEAR(o.Chi2({1.7, 1.7, 2.6}), grouped + alone, 1e-12);
  EXPECT_NEAR(o.sigma[1], std::sqrt(0.01 + 0.25 * 1.25), 1e-12);  // shown per statistic, alone

  // A linear statistic m(u) = 2u observed N times: var(u) = (s^2/N + s^2/K) / 4.
  std::vector<std::vector<double>> pts, vals;
  for (double u : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    pts.push_back({u});
    vals.push_back(std::vector<double>(16, 2.0 * u));
  }
  for (std::size_t n : {1u, 16u}) {
    Objective many;
    for (std::size_t i = 0; i < n; ++i) many.statistics.push_back(statistic(1.0, 0.0, i));
    for (Statistic& st : many.statistics) st.observed_sigma = 0.0;
    many.Weigh(std::vector<double>(n, 0.4), 8.0);
    std::vector<std::vector<double>> v;
    for (const auto& row : vals) v.push_back(std::vector<double>(row.begin(), row.begin() + static_cast<long>(n)));
    Quadratic q;
    ASSERT_TRUE(q.Fit(pts, v, {0.5}, 0.5));
    std::vector<double> cov;
    std::string reason;
    std::vector<int> without;
    ASSERT_TRUE(SurrogateCovariance(q, many, {0.5}, &cov, &reason, &without)) << reason;
    EXPECT_NEAR(cov[0], (0.16 / static_cast<double>(n) + 0.16 / 8.0) / 4.0, 1e-9) << n << " recordings";
  }
}

// Statistics of one recording that the seeds move together (a share moving
// and a share still: r = -1; one window and the next) are one piece of
// evidence, not two: m1 = 2u and m2 = -2u with seed covariance
// s^2 [[1, -1], [-1, 1]] give var(u) = s^2 (1 + 1/K) / 4, as m1 alone does
// (weighted as independent, half of it), and the same statistics
// uncorrelated do halve it.
TEST(Objective, StatisticsTheSeedsMoveTogetherCountOnce) {
  const double s2 = 0.16, k = 8.0;
  std::vector<std::vector<double>> pts, vals;
  for (double u : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    pts.push_back({u});
    vals.push_back({2.0 * u, -2.0 * u});
  }
  Quadratic q;
  ASSERT_TRUE(q.Fit(pts, vals, {0.5}, 0.5));
  const auto variance = [&](double correlation) {
    Objective o;
    o.statistics.resize(2);
    o.statistics[0].observed = 1.0;
    o.statistics[1].observed = -1.0;
    o.WeighCovariance({s2, correlation * s2, correlation * s2, s2}, k);
    std::vector<double> cov;
    std::string reason;
    std::vector<int> without;
    EXPECT_TRUE(SurrogateCovariance(q, o, {0.5}, &cov, &reason, &without)) << reason;
    return cov.empty() ? kNaN : cov[0];
  };
  const double one = s2 * (1.0 + 1.0 / k) / 4.0;
  EXPECT_NEAR(variance(-0.999999), one, 1e-6 * one);
  EXPECT_NEAR(variance(0.0), one / 2.0, 1e-12);

  // chi2 is the generalised one: (m - o)^T C^-1 (m - o).
  Objective o;
  o.statistics.resize(2);
  o.statistics[0].observed = 1.0;
  o.statistics[1].observed = 0.5;
  o.statistics[1].observed_sigma = 0.3;
  o.WeighCovariance({0.25, 0.1, 0.1, 0.2}, 4.0);
  const double c00 = 0.25 * 1.25, c01 = 0.1 * 1.25, c11 = 0.2 * 1.25 + 0.09;
  const double d0 = 1.4 - 1.0, d1 = 0.2 - 0.5, det = c00 * c11 - c01 * c01;
  EXPECT_NEAR(o.Chi2({1.4, 0.2}), (c11 * d0 * d0 - 2.0 * c01 * d0 * d1 + c00 * d1 * d1) / det, 1e-12);
  // Without a simulated value for one, the other is weighed alone.
  EXPECT_TRUE(std::isinf(o.Chi2({1.4, kNaN})));
  const std::vector<double> r = o.Residuals({1.4, kNaN});
  EXPECT_NEAR(r[0], d0 / std::sqrt(c00), 1e-12);
  EXPECT_TRUE(std::isnan(r[1]));
  // The bootstrap's redraw of one recording: its statistics scatter with
  // C's own part (S + observed sigma^2), correlated as the seeds are.
  const std::vector<double> e = o.ObservationNoise({1.0, 0.0});
  EXPECT_NEAR(e[0], 0.5, 1e-12);
  EXPECT_NEAR(e[1], 0.1 / 0.5, 1e-12);
  // Weighed again with other spreads: the new weights, not the last ones.
  o.Weigh({0.5, 0.0}, 4.0);
  EXPECT_NEAR(o.Chi2({1.4, 0.2}), d0 * d0 / (0.25 * 1.25) + d1 * d1 / 0.09, 1e-12);
}

// The seeds' covariance pooled over sets: each set's seeds about their own
// mean (a set's offset is not spread), the correlation recovered, the
// correlations of noise shrunk away, a simulated value read by two
// statistics expanded to both.
TEST(Objective, TheSeedsCovarianceIsPooledAndShrunk) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<std::vector<std::vector<double>>> sets(40);
  for (std::size_t s = 0; s < sets.size(); ++s)
    for (int seed = 0; seed < 8; ++seed) {
      const double a = normal(rng), b = 0.8 * a + 0.6 * normal(rng), c = normal(rng);
      // values: a (sd 2, set offset s), b (sd 1), c (sd 0.5), and a again (another recording's statistic)
      sets[s].push_back({10.0 * static_cast<double>(s) + 2.0 * a, b, 0.5 * c, 10.0 * static_cast<double>(s) + 2.0 * a});
    }
  std::vector<const std::vector<std::vector<double>>*> ptr;
  for (const auto& s : sets) ptr.push_back(&s);
  const SeedCovariance c = PooledSeedCovariance(ptr, {0, 1, 2, 0});
  ASSERT_EQ(c.covariance.size(), 16u);
  EXPECT_EQ(c.values, 3u);
  EXPECT_NEAR(c.sd[0], 2.0, 0.2);
  EXPECT_NEAR(c.sd[1], 1.0, 0.1);
  EXPECT_NEAR(c.sd[2], 0.5, 0.05);
  EXPECT_EQ(c.sd[3], c.sd[0]);
  const auto corr = [&](std::size_t j, std::size_t i) {
    return c.covariance[j * 4 + i] / std::sqrt(c.covariance[j * 4 + j] * c.covariance[i * 4 + i]);
  };
  EXPECT_NEAR(corr(0, 1), 0.8, 0.08);
  EXPECT_LT(std::abs(corr(0, 2)), 0.1);
  EXPECT_EQ(corr(0, 3), 1.0);
  EXPECT_EQ(c.covariance[1 * 4 + 3], c.covariance[1 * 4 + 0]);
  EXPECT_GT(c.shrinkage, 0.0);
  EXPECT_LT(c.shrinkage, 0.2);
  EXPECT_GT(c.effective_values, 1.5);
  EXPECT_LT(c.effective_values, 3.0);
  // Pure noise: the sample correlations are mostly shrunk away.
  std::vector<std::vector<std::vector<double>>> few(2);
  for (auto& s : few)
    for (int seed = 0; seed < 4; ++seed) s.push_back({normal(rng), normal(rng), normal(rng), normal(rng), normal(rng)});
  const SeedCovariance noise = PooledSeedCovariance({&few[0], &few[1]}, {0, 1, 2, 3, 4});
  EXPECT_GT(noise.shrinkage, 0.5);
  // Issue 65: no value varies over the seeds (a recorded fatal clog that no
  // run reaches, every seed at the window's end): no covariance, no crash.
  std::vector<std::vector<std::vector<double>>> still(2, std::vector<std::vector<double>>(3, {30.0, 30.0}));
  const SeedCovariance none = PooledSeedCovariance({&still[0], &still[1]}, {0, 1});
  EXPECT_EQ(none.values, 0u);
  EXPECT_EQ(none.effective_values, 0.0);
  for (double v : none.covariance) EXPECT_EQ(v, 0.0);
  Objective o;
  o.statistics.resize(5);
  o.WeighCovariance(noise.covariance, 4.0);  // positive definite: whitened
  EXPECT_TRUE(std::isfinite(o.Chi2({0.1, 0.2, 0.3, 0.4, 0.5})));
}

// A profile's chi2 differences and the seeds' noise in them: one statistic
// observed 0 with sigma 1 (chi2 = mean^2), K = 8 seeds.
TEST(Profile, AnEndIsExcludedOnlyBeyondTheSeedsNoise) {
  Statistic st;
  st.observed = 0.0;
  st.observed_sigma = 1.0;
  Objective o;
  o.statistics = {st};
  o.Weigh({0.0}, 8.0);
  const auto seeds = [](std::vector<double> v) {
    std::vector<std::vector<double>> per_seed;
    for (double x : v) per_seed.push_back({x});
    return per_seed;
  };
  const auto best = seeds({0.1, -0.1, 0.05, -0.05, 0.0, 0.1, -0.1, 0.0});
  const auto steady = seeds({2.9, 3.1, 3.0, 3.0, 2.95, 3.05, 3.0, 3.0});     // chi2 9, little noise
  const auto noisy = seeds({-2.0, 6.4, -2.0, 6.4, -2.0, 6.4, -2.0, 6.4});   // chi2 4.84 by its mean, mostly noise
  const auto same = best;                                                  // the best's own runs
  const ProfileNoise n = ProfileDifferences(o, {&steady, &noisy, &same}, best, 400, 7);
  ASSERT_EQ(n.delta.size(), 3u);
  EXPECT_NEAR(n.delta[0], 9.0, 1e-9);
  EXPECT_NEAR(n.delta[1], 2.2 * 2.2, 1e-9);
  EXPECT_NEAR(n.delta[2], 0.0, 1e-12);
  // The steady end stays beyond 3.84 in 97.5 % of the redraws: excluded.
  EXPECT_GT(n.lo95[0], 3.84);
  EXPECT_LT(n.lo95[0], 9.0);
  // The noisy one is beyond 3.84 by its mean only: the redraws reach 0.
  EXPECT_GT(n.delta[1], 3.84);
  EXPECT_LT(n.lo95[1], 3.84);
  EXPECT_GT(n.hi95[1], 9.0);
  // Common random numbers: a set with the best's own per-seed values
  // differs from it by nothing in any redraw (independent redraws would not).
  EXPECT_EQ(n.lo95[2], 0.0);
  EXPECT_EQ(n.hi95[2], 0.0);
  // No redraws: the point estimate only.
  const ProfileNoise none = ProfileDifferences(o, {&steady}, best, 0, 7);
  EXPECT_TRUE(std::isnan(none.lo95[0]));
  EXPECT_NEAR(none.delta[0], 9.0, 1e-9);
  // A redrawn mean with repeats, and NaN where no drawn seed has a value.
  EXPECT_NEAR(RedrawnMean(seeds({1.0, 2.0, 4.0}), {2, 2, 0})[0], 3.0, 1e-12);
  EXPECT_TRUE(std::isnan(RedrawnMean(seeds({std::nan(""), 2.0}), {0, 0})[0]));
}

}  // namespace
}  // namespace crowdrecon::calibrate
