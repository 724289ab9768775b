// Term desired_velocity: the self-driven force of eq. (3),
// m_i (v0_i e_i - v_i) / tau, from the block's pace (v0_i, or what the desire
// phase made of it), its heading (e_i, or where the steer phase turned it)
// and the velocity it relaxes from (v_i, or the perceived velocity of
// reaction_time). The paper's; always on.
#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

class DesiredVelocity final : public BehaviourTerm {
 public:
  unsigned phases() const override { return kForce; }
  void Force(const DriveInputs& in, DriveBlock& b) const override {
    const double inverse_tau = in.inverse_tau;
    const double* mass = in.bodies.mass_kg.data() + b.first;
    for (std::size_t k = 0; k < b.count; ++k)
      if (b.driven[k]) b.force[k] += (b.heading[k] * b.pace[k] - b.from[k]) * (mass[k] * inverse_tau);  // eq. (3)
  }
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeDesiredVelocity(const ModelParameters&, const WorldDef&) { return std::make_unique<DesiredVelocity>(); }

}  // namespace crowdrecon::engine::detail
