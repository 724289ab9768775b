// Term gait_jitter (ModelParameters::gait_jitter = isotropic with a velocity
// > 0; issue 39, off by default): eq. (3)'s desired velocity plus u_i(t), a
// person's own stationary random velocity of standard deviation
// gait_jitter_velocity_m_per_s per axis, flat in the band gait_jitter_band_*
// (the sway of the gait, measured from the Juelich trajectories:
// studies/wuppertal-bottleneck/gait-jitter-from-data.py), so the force m u_i(t) / tau.
//
// u_i(t) per axis is sigma sqrt(2/K) sum_k cos(2 pi (f_k t + phi_k)), f_k
// uniform in the band and phi_k uniform in [0, 1), drawn from the seed and
// the person's id: the spectral representation of a stationary random
// process (Shinozuka and Deodatis, Appl. Mech. Rev. 44:191, 1991), whose
// variance is sigma^2 and whose expected spectrum is flat in the band. A
// function of time alone: no state to save, the same on any thread count and
// after a resume.
//
// It is the gait's: it acts on people who want to walk (desired speed > 0),
// blocked or not (the Wuppertal crowd it was measured on pressed toward the
// door, stepping in place), and not on people who stand by choice (desired
// speed 0: waiting for their pre-movement time, or told to stand), who have
// no gait. Before issue 64 it swayed them too, by about 5 cm at 0.3 m/s,
// which RiMEA test 5 read as setting off before their time.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define CROWDRECON_WIDE_JITTER 1
#endif

#include "../behaviour.hpp"
#include "crowdrecon/common/fast_math.hpp"

namespace crowdrecon::engine::detail {
namespace {

// SplitMix64's finaliser (Steele, Lea and Flood, OOPSLA 2014): a 64-bit
// hash whose outputs pass statistical tests as random numbers.
std::uint64_t Mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
double UnitInterval(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }  // [0, 1)

// Cosines per axis: four give a nearly Gaussian sum (its kurtosis is 3 -
// 3/(2K) = 2.63 instead of 3) at 8 cosines a person.
constexpr int kJitterComponents = 4;

// A person's draws: per axis and cosine, the unit numbers that give its
// frequency and phase (a function of the seed and the person's id alone;
// the hashes are a long chain of dependent multiplications, so they are
// drawn once per person and kept: the same numbers, so the same sums).
struct Draws {
  std::uint64_t seed = 0;
  std::uint32_t id = 0;
  bool drawn = false;
  double frequency_unit[2][kJitterComponents], phase[2][kJitterComponents];
};

void Draw(std::uint64_t seed, std::uint32_t id, Draws& d) {
  std::uint64_t h = Mix(seed ^ Mix(std::uint64_t{id} + 1));
  for (int axis = 0; axis < 2; ++axis)
    for (int k = 0; k < kJitterComponents; ++k) {
      h = Mix(h);
      d.frequency_unit[axis][k] = UnitInterval(h);
      h = Mix(h);
      d.phase[axis][k] = UnitInterval(h);
    }
  d.seed = seed;
  d.id = id;
  d.drawn = true;
}

#ifdef CROWDRECON_WIDE_JITTER
// The four cosines of one axis, four at a time (AVX2): SinCos's cosine
// (common/fast_math.hpp) of 2 pi (cycles - floor(cycles)), with the same
// IEEE operations in the same order (no fused multiply-add), so the same
// numbers bit for bit; the quadrant's two low bits read from the rounding
// sum x 2/pi + 1.5 2^52, whose low mantissa bits are k (mod 4 also for
// negative k). Returns them added in order, as the scalar loop does.
__attribute__((target("avx2"), always_inline)) inline __m256d HornerStep(__m256d p, __m256d s, double c) {
  return _mm256_add_pd(_mm256_mul_pd(p, s), _mm256_set1_pd(c));
}
__attribute__((target("avx2"))) double AxisCosinesWide(const double* frequency_unit, const double* phase,
                                                       double f_low, double f_span, double t_s) {
  using namespace fast_math_detail;
  const __m256d frequency =
      _mm256_add_pd(_mm256_set1_pd(f_low), _mm256_mul_pd(_mm256_set1_pd(f_span), _mm256_loadu_pd(frequency_unit)));
  const __m256d cycles = _mm256_add_pd(_mm256_mul_pd(frequency, _mm256_set1_pd(t_s)), _mm256_loadu_pd(phase));
  const __m256d x = _mm256_mul_pd(_mm256_set1_pd(2.0 * std::numbers::pi),
                                  _mm256_sub_pd(cycles, _mm256_floor_pd(cycles)));
  const __m256d magic = _mm256_set1_pd(kRoundMagic);
  const __m256d rounding = _mm256_add_pd(_mm256_mul_pd(x, _mm256_set1_pd(kTwoOverPi)), magic);
  const __m256d k = _mm256_sub_pd(rounding, magic);
  const __m256d r = _mm256_sub_pd(_mm256_sub_pd(_mm256_sub_pd(x, _mm256_mul_pd(k, _mm256_set1_pd(kPiOver2Hi))),
                                                _mm256_mul_pd(k, _mm256_set1_pd(kPiOver2Mid))),
                                  _mm256_mul_pd(k, _mm256_set1_pd(kPiOver2Lo)));
  const __m256d s = _mm256_mul_pd(r, r);
  __m256d ps = _mm256_set1_pd(kSinSeries[0]);
  for (int term = 1; term < kSeriesTerms; ++term) ps = HornerStep(ps, s, kSinSeries[term]);
  const __m256d sin_r = _mm256_add_pd(r, _mm256_mul_pd(_mm256_mul_pd(r, s), ps));
  __m256d pc = _mm256_set1_pd(kCosSeries[0]);
  for (int term = 1; term < kSeriesTerms; ++term) pc = HornerStep(pc, s, kCosSeries[term]);
  const __m256d cos_r = _mm256_add_pd(_mm256_set1_pd(1.0), _mm256_mul_pd(s, pc));
  const __m256i q = _mm256_castpd_si256(rounding);
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256d odd = _mm256_and_pd(
      _mm256_castsi256_pd(_mm256_cmpeq_epi64(_mm256_and_si256(q, _mm256_set1_epi64x(1)), _mm256_set1_epi64x(1))), one);
  const __m256i q1 = _mm256_add_epi64(q, _mm256_set1_epi64x(1));
  const __m256d negative = _mm256_and_pd(
      _mm256_castsi256_pd(_mm256_cmpeq_epi64(_mm256_and_si256(q1, _mm256_set1_epi64x(2)), _mm256_set1_epi64x(2))), one);
  const __m256d b = _mm256_add_pd(_mm256_mul_pd(odd, sin_r), _mm256_mul_pd(_mm256_sub_pd(one, odd), cos_r));
  const __m256d cosine = _mm256_mul_pd(_mm256_sub_pd(one, _mm256_mul_pd(_mm256_set1_pd(2.0), negative)), b);
  alignas(32) double c[4];
  _mm256_store_pd(c, cosine);
  double sum = 0.0;
  for (const double v : c) sum += v;
  return sum;
}
#endif

Vec2 JitterVelocity(const Draws& d, double t_s, const ModelParameters& mp, bool wide) {
  const double amplitude = mp.gait_jitter_velocity_m_per_s * std::sqrt(2.0 / kJitterComponents);
  const double f_low = mp.gait_jitter_band_low_hz, f_span = mp.gait_jitter_band_high_hz - mp.gait_jitter_band_low_hz;
  double axis_sum[2];
#ifdef CROWDRECON_WIDE_JITTER
  static_assert(kJitterComponents == 4, "AxisCosinesWide takes an axis's cosines four at a time");
  if (wide) {
    for (int axis = 0; axis < 2; ++axis)
      axis_sum[axis] = AxisCosinesWide(d.frequency_unit[axis], d.phase[axis], f_low, f_span, t_s);
    return Vec2{axis_sum[0], axis_sum[1]} * amplitude;
  }
#endif
  for (int axis = 0; axis < 2; ++axis) {
    double& sum = axis_sum[axis];
    sum = 0.0;
    for (int k = 0; k < kJitterComponents; ++k) {
      const double frequency = f_low + f_span * d.frequency_unit[axis][k];
      const double cycles = frequency * t_s + d.phase[axis][k];
      double sine, cosine;
      SinCos(2.0 * std::numbers::pi * (cycles - std::floor(cycles)), sine, cosine);
      sum += cosine;
    }
  }
  return Vec2{axis_sum[0], axis_sum[1]} * amplitude;
}

class GaitJitterTerm final : public BehaviourTerm {
 public:
  unsigned phases() const override { return kForce | kPrepare; }
  // Room for every slot's draws (a slot's are drawn when first needed, and
  // again when the slot holds another person or the seed changed; each
  // block writes its own people's).
  void Prepare(const DriveInputs& in) const override {
    if (draws_.size() != in.bodies.size()) draws_.resize(in.bodies.size());
  }
  void Force(const DriveInputs& in, DriveBlock& b) const override {
    const ModelParameters& mp = in.def.parameters;
    const auto seed = static_cast<std::uint64_t>(mp.gait_jitter_seed);
    const bool wide = WideInstructions();
    for (std::size_t k = 0; k < b.count; ++k) {
      const std::size_t i = b.first + k;
      if (!b.driven[k] || !WantsToWalk(in.bodies, i)) continue;
      Draws& d = draws_[i];
      if (!d.drawn || d.seed != seed || d.id != in.bodies.id[i]) Draw(seed, in.bodies.id[i], d);
      b.force[k] += JitterVelocity(d, in.time_s, mp, wide) * (in.bodies.mass_kg[i] * in.inverse_tau);
    }
  }

 private:
  mutable std::vector<Draws> draws_;  // per slot (not state: a function of the seed and the id)
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeGaitJitter(const ModelParameters& p, const WorldDef&) {
  if (p.gait_jitter != GaitJitter::kIsotropic || !(p.gait_jitter_velocity_m_per_s > 0.0))
    return nullptr;
  return std::make_unique<GaitJitterTerm>();
}

}  // namespace crowdrecon::engine::detail
