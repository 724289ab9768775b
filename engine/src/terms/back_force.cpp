// Term back_force: the back force of eq. (15), Gamma m_i v0_i / tau (e_i +
// e_i x k) while the person is pushed backwards (Theta(x) = 1 for x > 0
// only, ERRATA 9), with a group's own Gamma where it has one
// (Simulation::SetGroupDrive). The paper's; always on.
//
// Its trigger (ModelParameters::back_force_trigger): the velocity along e_i
// now (the paper), or that velocity averaged over back_force_reaction_time_s,
// u_i, whose per-person state this term keeps: u_i <- u_i + (1 -
// exp(-h/T)) (e_i . v_i - u_i) after each step, the exact update of du/dt =
// (e.v - u)/T for e.v constant over the step; people are placed at rest
// (u_i = 0, no back force until pushed back).
#include <cmath>

#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

class BackForce final : public BehaviourTerm {
 public:
  explicit BackForce(bool averaged) : averaged_(averaged) {}
  unsigned phases() const override { return averaged_ ? kForce | kAfterStep : kForce; }

  void Force(const DriveInputs& in, DriveBlock& b) const override {
    const double inverse_tau = in.inverse_tau;
    const double back_factor = in.def.parameters.back_force_gamma * inverse_tau;  // Gamma / tau
    const Vec2* velocity = in.bodies.velocity_m_per_s.data() + b.first;
    const double* averaged = averaged_ ? averaged_along_.data() + b.first : nullptr;
    for (std::size_t k = 0; k < b.count; ++k) {
      if (!b.driven[k]) continue;
      const Vec2 e = b.direction[k];
      const double along = averaged != nullptr ? averaged[k] : Dot(e, velocity[k]);
      if (!(-along > 0.0)) continue;  // pushed backwards only
      const std::size_t i = b.first + k;
      double back = back_factor;
      if (const std::uint32_t g = in.bodies.group[i]; g < in.group_gamma.size() && !std::isnan(in.group_gamma[g]))
        back = in.group_gamma[g] * inverse_tau;
      // Along e plus e x k, which points to the person's right.
      b.force[k] += (e + Vec2{e.y, -e.x}) * (back * in.bodies.mass_kg[i] * in.bodies.desired_speed_m_per_s[i]);
    }
  }

  void AfterStep(const StepInputs& in) override {
    const double a = -std::expm1(-in.step_s / in.def.parameters.back_force_reaction_time_s);
    for (std::size_t i = 0; i < in.bodies.size(); ++i) {
      if (in.bodies.state[i] != PersonState::kWalking) continue;
      const Vec2 e = in.def.targets[in.bodies.target[i]].Direction(in.bodies.position_m[i], in.field_cache[i]);
      averaged_along_[i] += a * (Dot(e, in.bodies.velocity_m_per_s[i]) - averaged_along_[i]);
    }
  }

  std::uint32_t state_version() const override { return averaged_ ? 1 : 0; }
  void Start(const BodyState& bodies) override {
    if (averaged_) averaged_along_.assign(bodies.size(), 0.0);
  }
  void Place(std::size_t slot, const BodyState&) override { averaged_along_[slot] = 0.0; }
  void Save(BinaryWriter& w) const override { w.PutVector(averaged_along_); }
  void Load(BinaryReader& r, std::size_t people) override {
    GetTermVector(r, averaged_along_, people, "averaged velocity");
  }

 private:
  bool averaged_;
  std::vector<double> averaged_along_;  // u_i (with the averaged trigger)
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeBackForce(const ModelParameters& p, const WorldDef&) {
  return std::make_unique<BackForce>(p.back_force_trigger == BackForceTrigger::kAveragedVelocity);
}

}  // namespace crowdrecon::engine::detail
