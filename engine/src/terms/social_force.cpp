// Term social_force (ModelParameters::social_force = circular; issue 64, off
// by default): the social force's repulsion between people (Helbing and
// Molnar 1995; Helbing, Farkas and Vicsek, Nature 407:487, 2000; the circular
// specification with anisotropy, Johansson, Helbing and Shukla, Adv. Complex
// Syst. 10:271, 2007), a force beside the contact forces.
//
// Force phase, on each walking person i from every other person j in the
// venue (walking or fallen) within the neighbour radius:
//   A exp(min(0, r_ij - d_ij) / B) n_ij (lambda + (1 - lambda) (1 + cos phi_ij) / 2)
// d_ij the centre distance (minimum image), r_ij the sum of the two bodies'
// bounding radii (core radius + sphero-radius), n_ij the unit vector from j
// to i, cos phi_ij = -n_ij . e_i (1 for a person straight ahead). Once the
// bounding circles overlap the repulsion stays A: the body forces of the
// social force model are this model's contact forces, which carry the
// bodies, and the term adds no stiffness of its own to the time step (its
// largest, A / B at touching, 25,000 N/m at the defaults, is a quarter of
// the contact stiffness). The neighbour radius: twice the largest bounding
// radius plus 7 B (beyond it the force is below A / 1000). Summed in the
// neighbour list's order: the same on any thread count. No state.
#include <algorithm>
#include <cmath>

#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

class SocialForceTerm final : public BehaviourTerm {
 public:
  SocialForceTerm(const ModelParameters& p, const WorldDef& def) {
    bound_m_.reserve(def.shapes.size());
    double largest = 0.0;
    for (const BodyShape& s : def.shapes) {
      bound_m_.push_back(s.core_radius_m + s.radius_m);
      largest = std::max(largest, bound_m_.back());
    }
    radius_m_ = 2.0 * largest + 7.0 * p.social_force_range_m;
  }
  unsigned phases() const override { return kForce; }
  double neighbour_radius_m() const override { return radius_m_; }

  void Force(const DriveInputs& in, DriveBlock& b) const override {
    const ModelParameters& mp = in.def.parameters;
    const double a = mp.social_force_strength_n, inverse_range = 1.0 / mp.social_force_range_m;
    const double lambda = mp.social_force_anisotropy;
    const PeriodicBox& box = in.def.periodic;
    for (std::size_t k = 0; k < b.count; ++k) {
      if (!b.driven[k]) continue;
      const std::size_t i = b.first + k;
      const Vec2 xi = in.bodies.position_m[i], e = b.direction[k];
      const double ri = bound_m_[in.bodies.shape[i]];
      Vec2 push{};
      ForEachNeighbour(in.neighbours, in.bodies, i, [&](std::uint32_t j) {
        const Vec2 d = Separation(box, xi, in.bodies.position_m[j]);  // from j to i
        const double dij = Length(d);
        if (!(dij > 0.0) || dij > radius_m_) return;
        const Vec2 n = d * (1.0 / dij);
        const double cos_phi = -Dot(n, e);
        const double weight = lambda + (1.0 - lambda) * (1.0 + cos_phi) / 2.0;
        const double reach = std::min(0.0, ri + bound_m_[in.bodies.shape[j]] - dij);
        push += n * (a * std::exp(reach * inverse_range) * weight);
      });
      b.force[k] += push;
    }
  }

 private:
  std::vector<double> bound_m_;  // per shape of the world
  double radius_m_ = 0.0;
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeSocialForce(const ModelParameters& p, const WorldDef& def) {
  if (p.social_force != SocialForce::kCircular) return nullptr;
  return std::make_unique<SocialForceTerm>(p, def);
}

}  // namespace crowdrecon::engine::detail
