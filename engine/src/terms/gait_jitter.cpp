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
#include <numbers>

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

Vec2 JitterVelocity(std::uint64_t seed, std::uint32_t id, double t_s, const ModelParameters& mp) {
  const double amplitude = mp.gait_jitter_velocity_m_per_s * std::sqrt(2.0 / kJitterComponents);
  const double f_low = mp.gait_jitter_band_low_hz, f_span = mp.gait_jitter_band_high_hz - mp.gait_jitter_band_low_hz;
  std::uint64_t h = Mix(seed ^ Mix(std::uint64_t{id} + 1));
  double axis_sum[2];
  for (double& sum : axis_sum) {
    sum = 0.0;
    for (int k = 0; k < kJitterComponents; ++k) {
      h = Mix(h);
      const double frequency = f_low + f_span * UnitInterval(h);
      h = Mix(h);
      const double cycles = frequency * t_s + UnitInterval(h);
      double sine, cosine;
      SinCos(2.0 * std::numbers::pi * (cycles - std::floor(cycles)), sine, cosine);
      sum += cosine;
    }
  }
  return Vec2{axis_sum[0], axis_sum[1]} * amplitude;
}

class GaitJitterTerm final : public BehaviourTerm {
 public:
  unsigned phases() const override { return kForce; }
  void Force(const DriveInputs& in, DriveBlock& b) const override {
    const ModelParameters& mp = in.def.parameters;
    const auto seed = static_cast<std::uint64_t>(mp.gait_jitter_seed);
    for (std::size_t k = 0; k < b.count; ++k) {
      const std::size_t i = b.first + k;
      if (!b.driven[k] || !WantsToWalk(in.bodies, i)) continue;
      b.force[k] += JitterVelocity(seed, in.bodies.id[i], in.time_s, mp) * (in.bodies.mass_kg[i] * in.inverse_tau);
    }
  }
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeGaitJitter(const ModelParameters& p, const WorldDef&) {
  if (p.gait_jitter != GaitJitter::kIsotropic || !(p.gait_jitter_velocity_m_per_s > 0.0))
    return nullptr;
  return std::make_unique<GaitJitterTerm>();
}

}  // namespace crowdrecon::engine::detail
