// The engine's sine, cosine and atan2 (common/fast_math.hpp) against libm:
// within 2 units in the last place over the ranges the engine uses, exact at
// the quadrant and octant boundaries, and the fall-backs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>

#include "crowdrecon/common/fast_math.hpp"

namespace crowdrecon {
namespace {

// |a - b| in units of the last place of the larger magnitude (at least the
// smallest normal's, so that results near zero are compared absolutely).
double Ulps(double a, double b) {
  const double scale = std::max({std::abs(a), std::abs(b), 1e-300});
  int exponent = 0;
  std::frexp(scale, &exponent);
  return std::abs(a - b) / std::ldexp(1.0, exponent - 53);
}

// Absolute error in units of 2^-53 (sin and cos of large arguments are
// compared absolutely: near a root the relative error of any reduction grows).
double AbsoluteUlps(double a, double b) { return std::abs(a - b) / std::ldexp(1.0, -53); }

TEST(FastMath, SinCosMatchLibmWithinTwoUlps) {
  std::mt19937_64 rng(20261122);
  double worst_small = 0.0, worst_large = 0.0;
  for (const double range : {1.0, 4.0, 100.0, 1e4, 1e6}) {
    std::uniform_real_distribution<double> angle(-range, range);
    for (int k = 0; k < 400000; ++k) {
      const double x = angle(rng);
      double s = 0.0, c = 0.0;
      SinCos(x, s, c);
      if (range <= 4.0) {
        worst_small = std::max({worst_small, Ulps(s, std::sin(x)), Ulps(c, std::cos(x))});
      } else {
        // Beyond a few turns: the reduction's own error is |k| ulp(pi/2 lo part), absolute.
        worst_large = std::max({worst_large, AbsoluteUlps(s, std::sin(x)), AbsoluteUlps(c, std::cos(x))});
      }
    }
  }
  EXPECT_LE(worst_small, 2.0);
  EXPECT_LE(worst_large, 2.0);
}

TEST(FastMath, SinCosAtQuadrantBoundariesAndFallBacks) {
  for (int q = -8; q <= 8; ++q) {
    const double x = q * std::numbers::pi / 2.0;
    for (const double dx : {-1e-9, 0.0, 1e-9}) {
      double s = 0.0, c = 0.0;
      SinCos(x + dx, s, c);
      EXPECT_LE(AbsoluteUlps(s, std::sin(x + dx)), 2.0) << x + dx;
      EXPECT_LE(AbsoluteUlps(c, std::cos(x + dx)), 2.0) << x + dx;
    }
  }
  double s = 0.0, c = 0.0;
  SinCos(0.0, s, c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  SinCos(3e7, s, c);  // beyond the reduction's range: libm
  EXPECT_EQ(s, std::sin(3e7));
  EXPECT_EQ(c, std::cos(3e7));
  SinCos(std::numeric_limits<double>::quiet_NaN(), s, c);
  EXPECT_TRUE(std::isnan(s) && std::isnan(c));
}

TEST(FastMath, Atan2MatchesLibmWithinTwoUlps) {
  std::mt19937_64 rng(2012);
  double worst = 0.0;
  // Unit vectors (the engine's use: orientation against facing), and
  // arbitrary magnitudes and ratios.
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  std::uniform_real_distribution<double> exponent(-30.0, 30.0);
  for (int k = 0; k < 1000000; ++k) {
    const double t = angle(rng);
    double y = std::sin(t), x = std::cos(t);
    if (k % 2 == 1) {
      y *= std::exp2(exponent(rng));
      x *= std::exp2(exponent(rng));
    }
    worst = std::max(worst, Ulps(Atan2(y, x), std::atan2(y, x)));
  }
  EXPECT_LE(worst, 2.0);
}

TEST(FastMath, Atan2AtOctantBoundaries) {
  const double tan_pi_8 = std::tan(std::numbers::pi / 8.0);
  for (const double sx : {1.0, -1.0})
    for (const double sy : {1.0, -1.0})
      for (const auto& [y, x] : {std::pair{0.0, 1.0}, std::pair{1.0, 1.0}, std::pair{1.0, 0.0}, std::pair{tan_pi_8, 1.0},
                                 std::pair{1.0, tan_pi_8}, std::pair{1e-300, 1.0}, std::pair{1.0, 1e-300}}) {
        const double a = Atan2(sy * y, sx * x), b = std::atan2(sy * y, sx * x);
        if (y == 0.0) {
          EXPECT_EQ(std::abs(a), std::abs(b));  // signed zeros are not distinguished
        } else {
          EXPECT_LE(Ulps(a, b), 2.0) << sy * y << ", " << sx * x;
        }
      }
  EXPECT_EQ(Atan2(0.0, 0.0), 0.0);
}

}  // namespace
}  // namespace crowdrecon
