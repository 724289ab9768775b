// Term motive_torque: the motive torque of eq. (16), lambda I_i / tau^2
// g_i (theta_D - theta), with the restoring sign (ERRATA 4) and a group's own
// lambda where it has one (Simulation::SetGroupDrive). The paper's; always on.
//
// In the facing phase it says where the body turns: toward the velocity
// (FacingTarget::kVelocity, the paper's reading) or toward e_i, with the gain
// g_i = 1 - exp(-|v_i| / v0_i) (1 for a person who wants to stand). Terms
// after it in the list may turn the facing elsewhere (shoulder_turn). The
// drive then computes theta_D - theta; in the force phase this term adds the
// torque.
#include <cmath>

#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

class MotiveTorque final : public BehaviourTerm {
 public:
  unsigned phases() const override { return kFacing | kForce; }

  void Facing(const DriveInputs& in, DriveBlock& b) const override {
    const bool face_velocity = in.def.parameters.facing_target == FacingTarget::kVelocity;
    const Vec2* velocity = in.bodies.velocity_m_per_s.data() + b.first;
    const double* desired_speed = in.bodies.desired_speed_m_per_s.data() + b.first;
    for (std::size_t k = 0; k < b.count; ++k) {
      if (!b.driven[k]) continue;
      const Vec2 v = velocity[k];
      // Only the direction of the facing matters to the angle (atan2 of two
      // products with it), so the velocity needs no normalising.
      b.facing[k] = face_velocity ? v : b.direction[k];
      const double v0 = desired_speed[k];
      b.gain[k] = v0 > 0.0 ? 1.0 - std::exp(-Length(v) / v0) : 1.0;
    }
  }

  void Force(const DriveInputs& in, DriveBlock& b) const override {
    const double inverse_tau = in.inverse_tau;
    const double torsion_factor = in.def.parameters.torsion_stiffness_lambda * inverse_tau * inverse_tau;  // lambda / tau^2
    const double* inertia = in.bodies.inertia_kg_m2.data() + b.first;
    const bool groups = !in.group_lambda.empty();
    for (std::size_t k = 0; k < b.count; ++k) {
      if (!b.driven[k] || !b.turning[k]) continue;
      double torsion = torsion_factor;
      if (groups)
        if (const std::uint32_t g = in.bodies.group[b.first + k]; g < in.group_lambda.size() && !std::isnan(in.group_lambda[g]))
          torsion = in.group_lambda[g] * inverse_tau * inverse_tau;
      b.torque[k] += torsion * inertia[k] * b.gain[k] * b.angle[k];
    }
  }
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeMotiveTorque(const ModelParameters&, const WorldDef&) { return std::make_unique<MotiveTorque>(); }

}  // namespace crowdrecon::engine::detail
