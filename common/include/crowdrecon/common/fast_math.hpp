// Sine, cosine and atan2 for the engine's per-person, per-step work.
//
// Why not libm: at 10,000 people glibc's sincos (placing each body) and atan2
// (the motive torque's angle, eq. 16) took 13 % of a step, as calls that the
// compiler cannot inline or overlap. These are branch-free polynomials that
// inline into the loops: within 2 units in the last place of the correctly
// rounded result over the engine's range (tests/unit/test_fast_math.cpp checks
// them against libm on millions of arguments), and, like every other
// arithmetic of the engine, the same bits for the same input on any thread.
//
// How. SinCos: x = k pi/2 + r with |r| <= pi/4 (Cody-Waite: pi/2 split in
// three parts, the first two with 30-bit mantissas so that k * part is exact
// for |k| < 2^23), then the Taylor series of sin to r^17 and of cos to r^16,
// whose truncation errors (< 1e-19 and < 3e-18) are far below the rounding;
// |x| > 1e6 rad goes to libm. Atan2: the octant is folded to 0 <= u <= tan(pi/8)
// by |y|/|x| or (|y| - |x|)/(|y| + |x|) (one division), then atan(u) = u P(u^2)
// with P the degree-11 Chebyshev fit of atan(sqrt(s))/sqrt(s) on
// [0, tan^2(pi/8)] (relative error 1.3e-18, computed with mpmath at 60 digits).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace crowdrecon {

namespace fast_math_detail {

inline constexpr double kTwoOverPi = 0x1.45f306dc9c883p-1;
inline constexpr double kPiOver2Hi = 0x1.921fb54000000p+0;  // 30-bit mantissa
inline constexpr double kPiOver2Mid = 0x1.10b4611800000p-30;  // 30-bit mantissa
inline constexpr double kPiOver2Lo = 0x1.313198a2e0370p-61;
inline constexpr double kPiOver4 = 0x1.921fb54442d18p-1;
inline constexpr double kPiOver2 = 0x1.921fb54442d18p+0;
inline constexpr double kPi = 0x1.921fb54442d18p+1;
inline constexpr double kTanPiOver8 = 0x1.a827999fcef32p-2;
inline constexpr double kReduceLimit = 1e6;
// Adding and subtracting 1.5 * 2^52 rounds a double of magnitude < 2^51 to
// the nearest integer (ties to even) in the default rounding mode.
inline constexpr double kRoundMagic = 0x1.8p52;

// The Taylor series of SinCos, highest power first (Horner): sin r = r (1 +
// s P(s)), P = -1/3! + s/5! - ... + s^7/17!; cos r = 1 + s Q(s), Q = -1/2! +
// s/4! - ... + s^7/16!; s = r^2. (Also read by the engine's four-lane copy
// of SinCos, engine/src/terms/gait_jitter.cpp.)
inline constexpr int kSeriesTerms = 8;
inline constexpr double kSinSeries[kSeriesTerms] = {
    2.8114572543455207632e-15,   // 1/17!
    -7.6471637318198164759e-13,  // -1/15!
    1.6059043836821614599e-10,   // 1/13!
    -2.5052108385441718775e-08,  // -1/11!
    2.7557319223985890653e-06,   // 1/9!
    -1.9841269841269841270e-04,  // -1/7!
    8.3333333333333333333e-03,   // 1/5!
    -1.6666666666666666667e-01,  // -1/3!
};
inline constexpr double kCosSeries[kSeriesTerms] = {
    4.7794773323873852974e-14,   // 1/16!
    -1.1470745597729724714e-11,  // -1/14!
    2.0876756987868098979e-09,   // 1/12!
    -2.7557319223985890653e-07,  // -1/10!
    2.4801587301587301587e-05,   // 1/8!
    -1.3888888888888888889e-03,  // -1/6!
    4.1666666666666666667e-02,   // 1/4!
    -0.5,                        // -1/2!
};

// Branch-free selection (the engine's arguments fall in any quadrant or
// octant, so branches would be mispredicted half of the time): with f = 0 or
// 1, f a + (1 - f) b and the like are exact, and stay in the floating-point
// unit.
inline double AsDouble(bool b) { return static_cast<double>(b); }

}  // namespace fast_math_detail

// sin(x) and cos(x).
inline void SinCos(double x, double& sin_x, double& cos_x) {
  using namespace fast_math_detail;
  if (!(std::abs(x) <= kReduceLimit)) [[unlikely]] {  // also NaN
    sin_x = std::sin(x);
    cos_x = std::cos(x);
    return;
  }
  const double k = (x * kTwoOverPi + kRoundMagic) - kRoundMagic;
  const double r = ((x - k * kPiOver2Hi) - k * kPiOver2Mid) - k * kPiOver2Lo;
  const double s = r * r;
  double ps = kSinSeries[0];
  for (int term = 1; term < kSeriesTerms; ++term) ps = ps * s + kSinSeries[term];
  const double sin_r = r + r * s * ps;
  double pc = kCosSeries[0];
  for (int term = 1; term < kSeriesTerms; ++term) pc = pc * s + kCosSeries[term];
  const double cos_r = 1.0 + s * pc;
  // Quadrant q = k mod 4: (sin, cos) = (s, c), (c, -s), (-s, -c), (-c, s).
  const auto q = static_cast<std::uint64_t>(static_cast<std::int64_t>(k));
  const double odd = AsDouble((q & 1u) != 0);
  const double a = odd * cos_r + (1.0 - odd) * sin_r, b = odd * sin_r + (1.0 - odd) * cos_r;
  sin_x = (1.0 - 2.0 * AsDouble((q & 2u) != 0)) * a;
  cos_x = (1.0 - 2.0 * AsDouble(((q + 1u) & 2u) != 0)) * b;
}

// atan2(y, x) in [-pi, pi]; 0 for (0, 0). (Signed zeros and infinities are
// not all distinguished as libm does: the engine never passes them.)
inline double Atan2(double y, double x) {
  using namespace fast_math_detail;
  const double ax = std::abs(x), ay = std::abs(y);
  const double hi = std::max(ax, ay), lo = std::min(ax, ay);
  // atan(lo / hi) in [0, pi/4]: directly below tan(pi/8), else pi/4 + atan(u)
  // with u = (lo/hi - 1) / (lo/hi + 1) = (lo - hi) / (lo + hi) in (-tan(pi/8), 0].
  // (0, 0) gives 0 / 1 and the angle 0.
  const double upper = AsDouble(lo > kTanPiOver8 * hi);
  const double den = hi + upper * lo;
  const double u = (lo - upper * hi) / (den + AsDouble(den == 0.0));
  const double s = u * u, s2 = s * s;
  // P(s) - 1 = s (c1 + c2 s + ... + c11 s^10), evaluated as even + s odd
  // powers of s (two independent chains: half the latency of one).
  double even = -0x1.23b93fac21dacp-6;  // c11
  even = even * s2 - 0x1.9c79c07a989c6p-5;  // c9
  even = even * s2 - 0x1.10ea1d157f6ffp-4;  // c7
  even = even * s2 - 0x1.745cf64dcc6bdp-4;  // c5
  even = even * s2 - 0x1.2492492259b3ep-3;  // c3
  even = even * s2 - 0x1.555555555552fp-2;  // c1
  double odd = 0x1.3702ea64c11f2p-5;        // c10
  odd = odd * s2 + 0x1.def9ecd6a20f2p-5;    // c8
  odd = odd * s2 + 0x1.3b10f0f5b1224p-4;    // c6
  odd = odd * s2 + 0x1.c71c70cb775cep-4;    // c4
  odd = odd * s2 + 0x1.999999999466ap-3;    // c2
  double angle = u + u * s * (even + s * odd);  // the fit's constant term is 1 exactly
  angle += upper * kPiOver4;
  const double steep = AsDouble(ay > ax), left = AsDouble(x < 0.0);
  angle = steep * kPiOver2 + (1.0 - 2.0 * steep) * angle;
  angle = left * kPi + (1.0 - 2.0 * left) * angle;
  return std::copysign(angle, y);
}

}  // namespace crowdrecon
