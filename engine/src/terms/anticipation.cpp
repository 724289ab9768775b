// Term anticipation (ModelParameters::anticipation = time_to_collision; issue
// 64, off by default): anticipation by the time to collision (Karamouzas,
// Skinner and Guy, "Universal power law governing pedestrian interactions",
// Phys. Rev. Lett. 113:238701, 2014), a force beside the contact forces.
//
// Force phase, on each walking person i from every other person j in the
// venue (walking or fallen) within anticipation_radius_m: with x = x_i - x_j
// (minimum image), v = v_i - v_j and R = r_i + r_j the sum of the bounding
// radii, the time to collision tau is the smaller root of |x + v t| = R,
//   a t^2 + 2 b t + c = 0,  a = v.v, b = x.v, c = x.x - R^2,
// tau = c / (-b + sqrt(D)), D = b^2 - a c; there is none when the two move
// apart (b >= 0), miss each other (D <= 0) or their bounding circles
// already overlap (c <= 0: the contact forces act there). The energy
// E(tau) = k tau^-2 exp(-tau / tau0) per unit mass gives the force
//   F = -m_i dE/dtau d(tau)/dx = m_i k exp(-tau/tau0) tau^-2 (2/tau + 1/tau0) (x + v tau) / sqrt(D)
// (d(tau)/dx = (x + v tau) / sqrt(D), from differentiating the quadratic):
// along x + v tau, the direction from j to i at the moment they would touch.
// Its size is capped at m_i anticipation_max_acceleration_m_per_s2 per
// neighbour (tau -> 0 makes it diverge; the ceiling is ours, twice eq. 3's
// largest push at the venues' speeds, 1.2 m/s / 0.5 s). The neighbour radius: anticipation_radius_m (Karamouzas et al.
// looked 10 m; people closing at 2.6 m/s from 5 m meet in under 2 s, so
// half of it keeps the collisions that matter at a quarter of the cost).
// It acts on people who want to walk (desired speed > 0): the force is the
// change of a walker's chosen velocity (Karamouzas et al.'s agents choose a
// velocity toward a goal), and a person who stands by choice (desired speed
// 0: waiting for a pre-movement time, told to stand) chooses none; walkers
// avoid them all the same (their own force, with the standing person as j),
// and the contact forces act as ever (as the gait jitter, gait_jitter.cpp).
// Summed in the neighbour list's order: the same on any thread count.
// No state.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

class AnticipationTerm final : public BehaviourTerm {
 public:
  explicit AnticipationTerm(const ModelParameters& p, const WorldDef& def) : radius_m_(p.anticipation_radius_m) {
    bound_m_.reserve(def.shapes.size());
    for (const BodyShape& s : def.shapes) bound_m_.push_back(s.core_radius_m + s.radius_m);
  }
  unsigned phases() const override { return kForce; }
  double neighbour_radius_m() const override { return radius_m_; }

  // A candidate j of person i (at xi, moving at vi, bounding radius ri): the
  // quadratic's terms, and whether the two would touch (within the radius,
  // not yet touching, closing in, not missing each other).
  struct Approach {
    Vec2 x, v;
    double reach, bb, c, discriminant;
    bool collides;
  };
  Approach Approaching(const DriveInputs& in, Vec2 xi, Vec2 vi, double ri, std::uint32_t j) const {
    Approach p;
    p.x = Separation(in.def.periodic, xi, in.bodies.position_m[j]);  // x_i - x_j
    const double xx = Dot(p.x, p.x);
    p.v = vi - in.bodies.velocity_m_per_s[j];
    p.reach = ri + bound_m_[in.bodies.shape[j]];
    const double a = Dot(p.v, p.v);
    p.bb = Dot(p.x, p.v);
    p.c = xx - p.reach * p.reach;
    p.discriminant = p.bb * p.bb - a * p.c;
    p.collides = !(xx > radius_m_ * radius_m_) & (p.c > 0.0) & (p.bb < 0.0) & (p.discriminant > 0.0);
    return p;
  }

  void Force(const DriveInputs& in, DriveBlock& b) const override {
    const ModelParameters& mp = in.def.parameters;
    const double k = mp.anticipation_strength_m2, inverse_horizon = 1.0 / mp.anticipation_horizon_s;
    const double ceiling = mp.anticipation_max_acceleration_m_per_s2;
    const NeighbourList& list = in.neighbours;
    for (std::size_t n = 0; n < b.count; ++n) {
      const std::size_t i = b.first + n;
      if (!b.driven[n] || !WantsToWalk(in.bodies, i)) continue;
      const Vec2 xi = in.bodies.position_m[i], vi = in.bodies.velocity_m_per_s[i];
      const double ri = bound_m_[in.bodies.shape[i]];
      Vec2 push{};
      // In chunks of the list, in its order: step one picks the candidates
      // that would collide (most do not: they move apart, miss, or are out of
      // reach), without a branch per candidate (which way a candidate goes is
      // not predictable: the branches cost more than the arithmetic); step
      // two computes the force of each, in the list's order. The same
      // arithmetic as one loop over the candidates (Approach), so the same sums.
      for (std::uint32_t m = list.start[i], end = list.start[i + 1]; m < end;) {
        const std::uint32_t chunk_end = std::min<std::uint32_t>(end, m + kChunk);
        std::uint32_t hits[kChunk];
        std::uint32_t count = 0;
        for (; m < chunk_end; ++m) {
          const std::uint32_t j = list.items[m];
          const Approach p = Approaching(in, xi, vi, ri, j);
          hits[count] = j;
          count += static_cast<std::uint32_t>(p.collides & (in.bodies.state[j] != PersonState::kRemoved));
        }
        for (std::uint32_t h = 0; h < count; ++h) {
          const Approach p = Approaching(in, xi, vi, ri, hits[h]);
          const double root = std::sqrt(p.discriminant);
          const double tau = p.c / (root - p.bb);
          const double size = k * std::exp(-tau * inverse_horizon) / (tau * tau) * (2.0 / tau + inverse_horizon) / root;
          const Vec2 at_contact = p.x + p.v * tau;  // |at_contact| = reach
          const double acceleration = std::min(size * p.reach, ceiling);
          push += at_contact * (acceleration / p.reach);
        }
      }
      b.force[n] += push * in.bodies.mass_kg[i];
    }
  }

 private:
  static constexpr std::uint32_t kChunk = 128;
  std::vector<double> bound_m_;  // per shape of the world
  double radius_m_;
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeAnticipation(const ModelParameters& p, const WorldDef& def) {
  if (p.anticipation != Anticipation::kTimeToCollision) return nullptr;
  return std::make_unique<AnticipationTerm>(p, def);
}

}  // namespace crowdrecon::engine::detail
