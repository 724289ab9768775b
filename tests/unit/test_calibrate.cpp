// Calibration (issue 23): the quadratic surrogate fitted exactly to a known
// quadratic; Ceres finding a known minimum, inside the box and on its edge;
// Ceres' covariance equal to (JᵀJ)⁻¹ of a linear model, and a parameter no
// statistic depends on reported rank deficient; statistics of an observation
// made in memory (window means, their standard errors, event counts, a time
// offset); calibration files read with their defaults and refused with the
// JSON path, the value and what was expected.
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

using crowdrecon::testing::ScratchFile;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

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

// An observation of 10 s in 0.2-s bins: speed forward 1.0 for t < 5 s and
// 0.5 after (uncertainty 0.1 per bin), and three stops.
observe::Observation MadeObservation() {
  observe::Observation o;
  o.spec.regions.push_back({"hallway", {{0, 0}, {8, 0}, {8, 3}, {0, 3}}});
  o.method = "trajectories";
  o.source_format = "crowdrecon-run";
  o.source_file = "made";
  o.t0_s = 0.0;
  o.bin_s = 0.2;
  o.bins = 50;
  observe::Series s{"speed", "hallway", "forward", "m/s", {}};
  for (std::size_t k = 0; k < o.bins; ++k) s.points.push_back({k < 25 ? 1.0 : 0.5, 0.1, 10.0});
  o.series.push_back(s);
  for (double t : {1.0, 4.0, 8.0}) {
    observe::Event e;
    e.kind = "stop";
    e.where = "hallway";
    e.direction = "forward";
    e.time_s = t;
    e.end_s = t + 0.5;
    o.events.push_back(e);
  }
  return o;
}

const std::string kScenario = std::string(CROWDRECON_SOURCE_DIR) + "/tests/data/scenarios/sweep-tiny.json";

std::string Calibration(const std::string& observation_file, const std::string& parameters, const std::string& more = "") {
  return R"({"format": "crowdrecon-calibration", "version": 1, "scenario": ")" + kScenario + R"(",
    "parameters": )" + parameters + R"(,
    "observations": [{"file": ")" + observation_file + R"(",
      "series": [{"quantity": "speed", "where": "hallway", "direction": "forward", "from_s": 0, "to_s": 10, "window_s": 5}],
      "events": [{"kind": "stop", "where": "hallway", "direction": "forward", "from_s": 2, "to_s": 10}]}],
    "set": {"run.duration_s": 12},
    "seeds": {"first": 1, "count": 3})" + more + "}";
}

TEST(CalibrationStatistics, WindowMeansCountsAndAnOffset) {
  const auto file = ScratchFile("made.observation.json");
  observe::WriteObservation(MadeObservation(), file);
  const CalibrationSpec spec =
      ParseCalibration(Calibration(file.string(), R"([{"path": "model.back_force_gamma"}])"), "cal.json", "");
  const std::vector<Statistic> st = ObservedStatistics(spec);
  // Two windows of the series, then the counts after each stop from 2 s on (4 s, 8 s) and at the end.
  ASSERT_EQ(st.size(), 5u);
  EXPECT_DOUBLE_EQ(st[0].observed, 1.0);
  EXPECT_DOUBLE_EQ(st[1].observed, 0.5);
  EXPECT_NEAR(st[0].observed_sigma, 0.1 / std::sqrt(25.0), 1e-12);  // 25 bins of 0.1 each
  EXPECT_EQ(st[2].to_s, 4.0);
  EXPECT_EQ(st[2].observed, 1.0);
  EXPECT_EQ(st[3].observed, 2.0);
  EXPECT_EQ(st[4].to_s, 10.0);
  EXPECT_EQ(st[4].observed, 2.0);
  // A simulated observation equal to the observed one reads the same values ...
  std::vector<double> values;
  SimulatedStatistics(0, MadeObservation(), st, &values);
  for (std::size_t j = 0; j < st.size(); ++j) EXPECT_DOUBLE_EQ(values[j], st[j].observed) << st[j].name;
  // ... and one whose clock runs 1 s later, with the offset, too.
  observe::Observation later = MadeObservation();
  later.t0_s = 1.0;
  for (observe::Event& e : later.events) e.time_s += 1.0;
  CalibrationSpec shifted = spec;
  shifted.observations[0].time_offset_s = 1.0;
  SimulatedStatistics(0, later, ObservedStatistics(shifted), &values);
  for (std::size_t j = 0; j < st.size(); ++j) EXPECT_DOUBLE_EQ(values[j], st[j].observed) << st[j].name;
  // A simulated window of its own: the observed [5, 10) against the run's [0, 5).
  std::string text = Calibration(file.string(), R"([{"path": "model.back_force_gamma"}])");
  const std::string windows = "\"from_s\": 0, \"to_s\": 10, \"window_s\": 5";
  text.replace(text.find(windows), windows.size(),
               "\"from_s\": 5, \"to_s\": 10, \"simulated_from_s\": 0, \"simulated_to_s\": 5");
  const CalibrationSpec own = ParseCalibration(text, "cal.json", "");
  const std::vector<Statistic> ost = ObservedStatistics(own);
  EXPECT_DOUBLE_EQ(ost[0].observed, 0.5);
  SimulatedStatistics(0, MadeObservation(), ost, &values);
  EXPECT_DOUBLE_EQ(values[0], 1.0);
}

// Issue 40: an observation compared beyond the runs' end (an offset of 100 s
// with 12-s runs; before, the pooled seed covariance of no values crashed
// the calibration) is refused before anything runs, naming the statistic,
// the window and the runs' length; so is a window partly beyond them.
TEST(CalibrationStatistics, WindowsBeyondTheRunsAreRefusedUpFront) {
  const auto file = ScratchFile("made.observation.json");
  observe::WriteObservation(MadeObservation(), file);
  CalibrationSpec spec = ParseCalibration(Calibration(file.string(), R"([{"path": "model.back_force_gamma"}])"), "cal.json", "");
  ASSERT_EQ(spec.run_duration_s, 12.0);
  EXPECT_NO_THROW(ObservedStatistics(spec));
  spec.observations[0].time_offset_s = 100.0;
  std::string e = ErrorOf([&] { ObservedStatistics(spec); });
  EXPECT_NE(e.find("cal.json: " + file.string() + ": obs0 speed hallway forward [0, 5) s is compared with the runs over [100, 105) s "
                   "(the observation's window plus its time_offset_s of 100 s), beyond the runs, which last 12 s"),
            std::string::npos) << e;
  spec.observations[0].time_offset_s = 3.0;  // the second window, [5, 10) s, runs to 13 s
  e = ErrorOf([&] { ObservedStatistics(spec); });
  EXPECT_NE(e.find("is compared with the runs over [8, 13) s"), std::string::npos) << e;
  spec.observations[0].time_offset_s = -1.0;  // before the runs begin
  e = ErrorOf([&] { ObservedStatistics(spec); });
  EXPECT_NE(e.find("is compared with the runs over [-1, 4) s"), std::string::npos) << e;
}

// The run's avalanches in "any" direction: one surge seen by two detectors
// within 2 s counts once.
TEST(CalibrationStatistics, AvalanchesOfAnyDirectionCountOnce) {
  observe::Observation run;
  for (const auto& [t, who] : std::vector<std::pair<double, std::string>>{{10.0, "counter"}, {11.5, "crowd"}, {30.0, "leaving"}}) {
    observe::Event e;
    e.kind = "avalanche";
    e.where = "run";
    e.direction = who;
    e.time_s = t;
    run.events.push_back(e);
  }
  Statistic st;
  st.is_count = true;
  st.quantity = "avalanche";
  st.where = "run";
  st.direction = "any";
  st.sim_from_s = 0.0;
  st.sim_to_s = 100.0;
  std::vector<double> values;
  SimulatedStatistics(0, run, {st}, &values);
  EXPECT_EQ(values[0], 2.0);
  st.direction = "crowd";
  SimulatedStatistics(0, run, {st}, &values);
  EXPECT_EQ(values[0], 1.0);
}

// "reduce": "max": the window's largest bin and that bin's uncertainty.
TEST(CalibrationStatistics, AWindowsLargestBinWithItsUncertainty) {
  const auto file = ScratchFile("made.observation.json");
  observe::Observation made = MadeObservation();
  made.series[0].points[30] = {1.7, 0.25, 10.0};
  observe::WriteObservation(made, file);
  std::string text = Calibration(file.string(), R"([{"path": "model.back_force_gamma"}])");
  const std::string window = "\"window_s\": 5";
  text.replace(text.find(window), window.size(), window + ", \"reduce\": \"max\"");
  const std::vector<Statistic> st = ObservedStatistics(ParseCalibration(text, "cal.json", ""));
  ASSERT_EQ(st.size(), 5u);
  EXPECT_TRUE(st[0].is_max);
  EXPECT_DOUBLE_EQ(st[0].observed, 1.0);  // [0, 5): every bin 1.0
  EXPECT_DOUBLE_EQ(st[0].observed_sigma, 0.1);
  EXPECT_DOUBLE_EQ(st[1].observed, 1.7);  // [5, 10): bin 30 (6.1 s)
  EXPECT_DOUBLE_EQ(st[1].observed_sigma, 0.25);
  EXPECT_NE(st[1].name.find("speed hallway forward max [5, 10) s"), std::string::npos) << st[1].name;
  std::vector<double> values;
  SimulatedStatistics(0, made, st, &values);
  EXPECT_DOUBLE_EQ(values[1], 1.7);
  EXPECT_DOUBLE_EQ(values[0], 1.0);
  EXPECT_NE(ErrorOf([&] {
              std::string bad = text;
              bad.replace(bad.find("\"max\""), 5, "\"median\"");
              ParseCalibration(bad, "cal.json", "");
            }).find("/observations/0/series/0/reduce"),
            std::string::npos);
}

// A speed read from the footage at a recorded mark (the Madrid night's
// "up to 3 m/s" at the fifth avalanche), against the run's fastest person at
// the exit end between the marks before and after it; refused with the path
// where it cannot be matched.
TEST(CalibrationFile, ASpeedRecordedOfTheIncident) {
  const std::string src = CROWDRECON_SOURCE_DIR;
  const auto calibration = [&](const std::string& scenario, const std::string& set, const std::string& recorded) {
    return R"({"format": "crowdrecon-calibration", "version": 1, "scenario": ")" + src + scenario + R"(",
      "set": )" + set + R"(, "parameters": [{"path": "model.back_force_gamma"}],
      "observations": [{"recorded": {"kind": "max_speed", "spec": ")" + src +
           R"(/venues/madrid-arena/observations/hallway-night.json", )" + recorded + R"(}}],
      "seeds": {"first": 1, "count": 2}})";
  };
  const std::string night = "/venues/madrid-arena/scenarios/madrid-night-demo.json";
  const std::string fast = R"({"run.output_fps": 10})";
  const CalibrationSpec spec = ParseCalibration(calibration(night, fast, R"("where": "exit end")"), "cal.json", "");
  const std::vector<Statistic> st = ObservedStatistics(spec);
  ASSERT_EQ(st.size(), 1u);
  EXPECT_TRUE(st[0].is_max);
  EXPECT_EQ(st[0].quantity, "max_speed");
  EXPECT_EQ(st[0].where, "exit end");
  EXPECT_DOUBLE_EQ(st[0].observed, 3.0);
  EXPECT_DOUBLE_EQ(st[0].observed_sigma, 0.5);
  EXPECT_DOUBLE_EQ(st[0].sim_from_s, 177.0);  // the demo's marks (/20): 02:59 ...
  EXPECT_DOUBLE_EQ(st[0].sim_to_s, 279.0);    // ... and the fatal clog, around 03:29 (267 s)
  // The run's observation: the fastest bin inside the window counts, not one outside.
  observe::Observation run;
  run.bin_s = 0.2;
  run.bins = 1500;
  observe::Series m{"max_speed", "exit end", "all", "m/s", {}};
  for (std::size_t k = 0; k < run.bins; ++k) m.points.push_back({k == 1000 ? 2.6 : (k == 1400 ? 4.0 : 1.0), 0.1, 5.0});
  run.series.push_back(m);
  std::vector<double> values;
  SimulatedStatistics(0, run, st, &values);
  EXPECT_DOUBLE_EQ(values[0], 2.6);  // bin 1000 (200.1 s); bin 1400 (280.1 s) lies after the window
  // A window of one's own.
  const std::vector<Statistic> own =
      ObservedStatistics(ParseCalibration(calibration(night, fast, R"("where": "exit end", "from_s": 260, "to_s": 285)"), "cal.json", ""));
  SimulatedStatistics(0, run, own, &values);
  EXPECT_DOUBLE_EQ(values[0], 4.0);
  // One reaching past the runs' 285 s is refused (issue 40).
  const std::string beyond = ErrorOf([&] {
    ObservedStatistics(ParseCalibration(calibration(night, fast, R"("where": "exit end", "from_s": 260, "to_s": 300)"), "cal.json", ""));
  });
  EXPECT_NE(beyond.find("is compared with the runs over [260, 300) s (the observation's window), beyond the runs, which last 285 s"),
            std::string::npos) << beyond;
  const auto expect = [&](const std::string& text, const std::string& part) {
    const std::string e = ErrorOf([&] { ParseCalibration(text, "cal.json", ""); });
    EXPECT_NE(e.find(part), std::string::npos) << "error: " << e << "\nexpected: " << part;
  };
  expect(calibration(night, "{}", R"("where": "exit end")"),
         "/observations/0/recorded: the runs write 5 frames/s, so their velocities would span 0.4 s against the "
         "observation's 0.2 s; expected run.output_fps of at least 10");
  expect(calibration(night, fast, R"("where": "exit")"),
         "/observations/0/recorded/where: the spec has no region \"exit\"; expected one of \"hallway\", \"exit end\"");
  expect(calibration(night, fast, R"("where": "exit end", "from_s": 0, "to_s": 100)"), "leaves out the mark");
  expect(calibration("/tests/data/scenarios/sweep-tiny.json", fast, R"("where": "exit end")"),
         "the scenario records no speed in timeline.recorded");
}

// The recorded fatal clog (the Madrid night's 03:33) as a time: observed the
// mark's time with the stated uncertainty, simulated the first "clog" event
// (the time from which the run is clogged for good) in the window, or the
// window's end where the run never clogs for good; refused with the path
// where the scenario records none or the window leaves it out.
TEST(CalibrationFile, TheRecordedFatalClogAsATime) {
  const std::string src = CROWDRECON_SOURCE_DIR;
  const auto calibration = [&](const std::string& scenario, const std::string& recorded) {
    return R"({"format": "crowdrecon-calibration", "version": 1, "scenario": ")" + src + scenario + R"(",
      "parameters": [{"path": "model.back_force_gamma"}],
      "observations": [{"recorded": {"kind": "fatal")" + recorded + R"(}}],
      "seeds": {"first": 1, "count": 2}})";
  };
  const std::string night = "/venues/madrid-arena/scenarios/madrid-night-demo.json";
  const std::vector<Statistic> st = ObservedStatistics(ParseCalibration(calibration(night, ""), "cal.json", ""));
  ASSERT_EQ(st.size(), 1u);
  EXPECT_TRUE(st[0].is_time);
  EXPECT_FALSE(st[0].is_count);
  EXPECT_EQ(st[0].quantity, "clog");
  EXPECT_EQ(st[0].simulated_from, "run clog");
  EXPECT_DOUBLE_EQ(st[0].observed, 279.0);  // the demo's 03:33 (5,580 s / 20)
  EXPECT_DOUBLE_EQ(st[0].observed_sigma, 60.0);
  EXPECT_DOUBLE_EQ(st[0].sim_from_s, 0.0);
  EXPECT_DOUBLE_EQ(st[0].sim_to_s, 285.0);  // the runs' end
  EXPECT_DOUBLE_EQ(ObservedStatistics(ParseCalibration(calibration(night, R"(, "uncertainty_s": 5)"), "cal.json", ""))[0].observed_sigma, 5.0);

  observe::Observation run;
  std::vector<double> values;
  SimulatedStatistics(0, run, st, &values);
  EXPECT_DOUBLE_EQ(values[0], 285.0);  // never clogged for good: censored at the window's end
  observe::Event clog;
  clog.kind = "clog";
  clog.where = "run";
  clog.direction = "crowd";
  clog.time_s = 212.5;
  run.events.push_back(clog);
  SimulatedStatistics(0, run, st, &values);
  EXPECT_DOUBLE_EQ(values[0], 212.5);

  const auto expect = [&](const std::string& text, const std::string& part) {
    const std::string e = ErrorOf([&] { ParseCalibration(text, "cal.json", ""); });
    EXPECT_NE(e.find(part), std::string::npos) << "error: " << e << "\nexpected: " << part;
  };
  expect(calibration("/tests/data/scenarios/sweep-tiny.json", ""), "/observations/0/recorded: the scenario records no \"fatal\" mark");
  expect(calibration(night, R"(, "from_s": 0, "to_s": 200)"), "leaves out the fatal clog at 279 s");
  expect(calibration(night, R"(, "uncertainty_s": 0)"), "/observations/0/recorded/uncertainty_s");
}

// The time from which a run is clogged for good (the function the ensemble's
// score and the recorded fatal clog share), on made directions' speeds: the
// start of the last stretch in which every direction present is still.
TEST(CalibrationFile, AClogForGoodIsTheStartOfTheLastStillStretch) {
  analysis::TimelineSeries s;
  for (int k = 0; k <= 100; ++k) s.time_s.push_back(k);
  s.group_speed_m_per_s = {std::vector<double>(101, 1.0), std::vector<double>(101, std::numeric_limits<double>::quiet_NaN())};
  for (int k = 60; k <= 100; ++k) s.group_speed_m_per_s[0][k] = 0.0;
  EXPECT_DOUBLE_EQ(analysis::ClogForGood(s, 0.0), 60.0);
  EXPECT_TRUE(std::isnan(analysis::ClogForGood(s, 0.0, 0.1, 50.0)));  // 40 s still: shorter than 50
  s.group_speed_m_per_s[1].assign(101, 0.5);                           // the other direction still walks
  EXPECT_TRUE(std::isnan(analysis::ClogForGood(s, 0.0)));
  s.group_speed_m_per_s[1].assign(101, 0.0);
  s.group_speed_m_per_s[1][80] = 0.3;                                   // ... until 80 s
  EXPECT_DOUBLE_EQ(analysis::ClogForGood(s, 0.0), 81.0);
}

// Every calibration the repository ships is read and its observed statistics
// computed (a change to the format or the checks that refused one would
// show here first, not in a documented command an hour in).
TEST(CalibrationFile, EveryShippedCalibrationIsValid) {
  int files = 0;
  for (const auto& venue : std::filesystem::directory_iterator(std::string(CROWDRECON_SOURCE_DIR) + "/venues")) {
    const std::filesystem::path dir = venue.path() / "calibrations";
    if (!std::filesystem::is_directory(dir)) continue;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
      if (entry.path().extension() != ".json") continue;
      std::ifstream in(entry.path());
      const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (text.find("\"crowdrecon-calibration\"") == std::string::npos) continue;  // a sweep of recordings
      SCOPED_TRACE(entry.path().string());
      EXPECT_EQ(ErrorOf([&] { EXPECT_FALSE(ObservedStatistics(LoadCalibration(entry.path())).empty()); }), "");
      ++files;
    }
  }
  EXPECT_GE(files, 5);  // the Madrid Arena's three, the Jülich corridors' two
}

TEST(CalibrationFile, DefaultsFromTheParameterTableAndTheScenario) {
  const auto file = ScratchFile("made.observation.json");
  observe::WriteObservation(MadeObservation(), file);
  const CalibrationSpec spec = ParseCalibration(
      Calibration(file.string(),
                  R"([{"path": "model.back_force_gamma"}, {"path": "model.restitution", "min": 0.1, "max": 0.8, "start": 0.3},
                      {"path": "population.desired_speed_m_per_s", "min": 0.6, "max": 1.8, "width": 0.4, "start": 1.0}])",
                  R"(, "starts": [{"model.restitution": 0.7}])"),
      "cal.json", "");
  ASSERT_EQ(spec.parameters.size(), 3u);
  EXPECT_EQ(spec.parameters[0].min, 0.0);    // the table's range
  EXPECT_EQ(spec.parameters[0].max, 100.0);
  EXPECT_EQ(spec.parameters[0].start, 1.2);  // the table's default (the scenario has no model block)
  EXPECT_EQ(spec.parameters[1].start, 0.3);
  // A range: its centre is the parameter, its width kept.
  EXPECT_TRUE(spec.parameters[2].is_range);
  EXPECT_DOUBLE_EQ(spec.parameters[2].start, 1.0);
  EXPECT_DOUBLE_EQ(spec.parameters[2].width, 0.4);
  EXPECT_EQ(spec.parameters[2].JsonOf(1.5), "[1.3,1.7]");
  ASSERT_EQ(spec.starts.size(), 2u);
  EXPECT_EQ(spec.starts[1][1], 0.7);
  EXPECT_EQ(spec.starts[1][0], 1.2);
  EXPECT_EQ(spec.base.seeds.size(), 3u);
}

TEST(CalibrationFile, BadFilesAreRefusedWithThePathAndTheValue) {
  const auto file = ScratchFile("made.observation.json");
  observe::WriteObservation(MadeObservation(), file);
  const std::string obs = file.string();
  const auto error = [&](const std::string& text) { return ErrorOf([&] { ParseCalibration(text, "cal.json", ""); }); };
  const auto expect = [&](const std::string& text, const std::string& part) {
    const std::string e = error(text);
    EXPECT_NE(e.find(part), std::string::npos) << "error: " << e << "\nexpected: " << part;
  };
  expect(Calibration(obs, R"([{"path": "model.back_force_gama"}])"),
         "cal.json: /parameters/0/path: \"model.back_force_gama\" is not a model parameter");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma", "max": 200}])"), "/parameters/0/max");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma", "min": 2, "max": 1}])"), "are empty; expected min < max");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma", "min": 2, "max": 3}])"),
         "the start 1.2 (from the scenario) lies outside the bounds [2, 3]");
  expect(Calibration(obs, R"([{"path": "population.density_per_m2"}])"),
         "\"min\" is required for \"population.density_per_m2\"");
  expect(Calibration(obs, R"([{"path": "model.integrator"}])"), "is not a number");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}, {"path": "model.back_force_gamma"}])"), "given twice");
  expect(Calibration(obs, R"([{"path": "population.seed", "min": 1, "max": 9}])"), "the seed is not a parameter");
  expect(Calibration(obs, R"([])"), "/parameters: expected at least one parameter");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}])", R"(, "approach": "newton")"),
         "/approach");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}])", R"(, "starts": [{"model.restitution": 0.3}])"),
         "/starts/0/model.restitution: \"model.restitution\" is not one of the parameters to fit");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}])", R"(, "options": {"profile_points": 1})"),
         "/options/profile_points");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}])", R"(, "options": {"posterior_steps": 500})"),
         "/options/posterior_steps: expected 0 (no posterior) or at least 1000 steps per chain");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}])", R"(, "options": {"posterior_steps": -1})"),
         "/options/posterior_steps");
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma"}])", R"(, "extra": 1)"), "unknown key");
  // Issue 65: one seed has no spread to weigh the statistics by (it crashed the calibration).
  {
    std::string one = Calibration(obs, R"([{"path": "model.back_force_gamma"}])");
    one.replace(one.find("\"count\": 3"), 10, "\"count\": 1");
    expect(one, "cal.json: /seeds: 1 seed; expected at least 2");
  }
  expect(Calibration("/nonexistent/obs.json", R"([{"path": "model.back_force_gamma"}])"),
         "/observations/0/file: cannot use the observation");
  // A series the observation does not have: the ones it has are listed.
  std::string text = Calibration(obs, R"([{"path": "model.back_force_gamma"}])");
  text.replace(text.find("\"direction\": \"forward\", \"from_s\": 0"), 22, "\"direction\": \"backward\"");
  expect(text, "the observation has no series speed hallway backward; expected one of: speed hallway forward");
  // An override that makes the scenario invalid at a bound: refused before any run.
  expect(Calibration(obs, R"([{"path": "population.density_per_m2", "min": 0.5, "max": 400, "start": 1}])"),
         "(variant max-density_per_m2, seed 1): the scenario with this run's overrides is not valid");
  // "width" for a value that is not a range.
  expect(Calibration(obs, R"([{"path": "model.back_force_gamma", "width": 0.2}])"), "\"width\" is for ranges");
}

// A recording's statistics for the footage design: `windows` windows of
// `window_s` of one series (speed) whose seeds' values correlate as AR(1)
// from window to window (variance s2, correlation rho^lag) and move with the
// parameters by `slope` (one row per parameter), plus, optionally, a count.
Objective FootageObjective(std::size_t windows, double window_s, double s2, double rho, std::vector<double> slope,
                           std::vector<double>* jacobian, bool with_count = false, double count_var = 4.0,
                           std::vector<double> count_slope = {}) {
  Objective o;
  const std::size_t p = slope.size();
  for (std::size_t w = 0; w < windows; ++w) {
    Statistic st;
    st.name = "speed " + std::to_string(w);
    st.quantity = "speed";
    st.where = "hallway";
    st.direction = "forward";
    st.sim_from_s = static_cast<double>(w) * window_s;
    st.sim_to_s = st.sim_from_s + window_s;
    o.statistics.push_back(st);
    jacobian->insert(jacobian->end(), slope.begin(), slope.end());
  }
  if (with_count) {
    Statistic st;
    st.name = "stops";
    st.quantity = "stop";
    st.where = "hallway";
    st.direction = "forward";
    st.is_count = true;
    st.sim_to_s = static_cast<double>(windows) * window_s;
    o.statistics.push_back(st);
    jacobian->insert(jacobian->end(), count_slope.begin(), count_slope.end());
  }
  const std::size_t n = o.statistics.size();
  o.seed_covariance.assign(n * n, 0.0);
  for (std::size_t a = 0; a < windows; ++a)
    for (std::size_t b = 0; b < windows; ++b)
      o.seed_covariance[a * n + b] = s2 * std::pow(rho, std::abs(static_cast<double>(a) - static_cast<double>(b)));
  if (with_count) o.seed_covariance[n * n - 1] = count_var;
  (void)p;
  return o;
}

// The design against the analytic information of an AR(1) series: m
// windows of unit-variance correlation rho^|a-b| carry 1ᵀR⁻¹1 =
// (m(1 - rho) + 2 rho) / (1 + rho) windows' worth; beyond the recording each
// window adds (1 - rho) / (1 + rho) (the long-run variance, up to the
// Bartlett weights' bias); N recordings divide the variance by N, K seeds
// add 1/K; a count's information grows with the length; a statistic that
// moves with one parameter only informs that one.
TEST(FootageDesign, MatchesTheInformationOfACorrelatedSeries) {
  const double rho = 0.5, s2 = 0.04, g = 0.8;
  std::vector<double> jac;
  const Objective o = FootageObjective(40, 5.0, s2, rho, {g}, &jac);
  const auto var = [&](int n, double m, double k) { return FootageCovariance(o, jac, 1, n, m, k)[0]; };
  const auto analytic = [&](double m) { return s2 / (g * g) * (1.0 + rho) / (m * (1.0 - rho) + 2.0 * rho); };
  for (double m : {1.0, 2.0, 10.0, 40.0}) EXPECT_NEAR(var(1, m, 0.0), analytic(m), 1e-9 * analytic(m)) << m;
  for (double m : {80.0, 160.0, 1000.0}) EXPECT_NEAR(var(1, m, 0.0), analytic(m), 0.05 * analytic(m)) << m;
  EXPECT_NEAR(var(4, 10.0, 0.0), analytic(10.0) / 4.0, 1e-9);
  EXPECT_NEAR(var(4, 10.0, 8.0), analytic(10.0) * (1.0 / 4.0 + 1.0 / 8.0), 1e-9);

  // The design's table and the footage it asks for.
  FootageOptions options;
  options.recordings = {1, 4};
  options.targets = {0.2};
  const FootageDesign d = DesignFootage(o, jac, {1.0}, options);
  ASSERT_TRUE(d.note.empty()) << d.note;
  EXPECT_EQ(d.windows, 40u);
  EXPECT_DOUBLE_EQ(d.recording_s, 200.0);
  ASSERT_EQ(d.rows.size(), 2u * 7u);
  EXPECT_NEAR(d.rows[1].sd[0], std::sqrt(analytic(40.0)), 1e-9);  // one recording, its own length
  EXPECT_NEAR(d.rows[7 + 1].sd[0], std::sqrt(analytic(40.0) / 4.0), 1e-9);
  // 95 % half-width 0.2: sd 0.2 / 1.96; analytic windows m, in seconds, within a window.
  const double want = 0.2 / 1.96;
  const double m = ((1.0 + rho) * s2 / (g * g) / (want * want) - 2.0 * rho) / (1.0 - rho);
  EXPECT_NEAR(d.one_recording_s[0][0], m * 5.0, 0.05 * m * 5.0 + 5.0);
  EXPECT_DOUBLE_EQ(d.recordings_needed[0][0], std::ceil(analytic(40.0) / (want * want)));
  ASSERT_EQ(d.share_lost.size(), 1u);
  EXPECT_DOUBLE_EQ(d.share_lost[0][0], 1.0);  // without its only statistic, undetermined

  // A count informs the second parameter alone, the series the first: each
  // kind carries all of its parameter's information.
  std::vector<double> jac2;
  const Objective two = FootageObjective(10, 5.0, s2, rho, {g, 0.0}, &jac2, true, 4.0, {0.0, 3.0});
  const FootageDesign d2 = DesignFootage(two, jac2, {1.0, 2.0}, options);
  ASSERT_EQ(d2.kinds.size(), 2u);
  EXPECT_EQ(d2.kinds[1], "stop hallway forward (count)");
  EXPECT_NEAR(d2.share_lost[0][0], 1.0, 1e-12);
  EXPECT_NEAR(d2.share_lost[0][1], 0.0, 1e-12);
  EXPECT_NEAR(d2.share_lost[1][1], 1.0, 1e-12);
  EXPECT_NEAR(d2.information_share[1][1], 1.0, 1e-12);
  // The count over f times the recording: mean slope f * 3, variance f * 4
  // (and the observed count's own 0.25, not grown).
  const auto count_var = [&](double f) { return (4.0 * f) / (9.0 * f * f); };
  for (double f : {0.5, 1.0, 3.0}) {
    const std::vector<double> c = FootageCovariance(two, jac2, 2, 1, 10.0 * f, 0.0);
    EXPECT_NEAR(c[3], count_var(f), 1e-9 * count_var(f)) << f;
  }
}

}  // namespace
}  // namespace crowdrecon::calibrate
