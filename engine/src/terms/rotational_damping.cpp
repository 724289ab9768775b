// Term rotational_damping: the rotational damping of eq. (17), -I_i omega_i
// / tau_r, with its own relaxation time (ERRATA 8). The paper's; always on.
#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

class RotationalDamping final : public BehaviourTerm {
 public:
  unsigned phases() const override { return kForce; }
  void Force(const DriveInputs& in, DriveBlock& b) const override {
    const double rotation_damping = 1.0 / in.def.parameters.rotation_relaxation_time_s;
    const double* inertia = in.bodies.inertia_kg_m2.data() + b.first;
    const double* omega = in.bodies.angular_velocity_rad_per_s.data() + b.first;
    for (std::size_t k = 0; k < b.count; ++k)
      if (b.driven[k]) b.torque[k] -= inertia[k] * rotation_damping * omega[k];
  }
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeRotationalDamping(const ModelParameters&, const WorldDef&) { return std::make_unique<RotationalDamping>(); }

}  // namespace crowdrecon::engine::detail
