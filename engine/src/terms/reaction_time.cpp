// Term reaction_time (ModelParameters::drive_reaction = lagged; issue 39, off
// by default): eq. (3) relaxes from the velocity the person perceives, w_i, a
// first-order lag of their velocity with time constant drive_reaction_time_s
// (its mean delay): w_i <- w_i + (1 - exp(-h/T)) (v_i - w_i) after each step,
// the exact update of dw/dt = (v - w)/T for v constant over the step. People
// perceive the velocity they are placed with; people who stop walking (a
// fall, an exit) and a quenched crowd perceive that they stand.
#include <algorithm>
#include <cmath>

#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

class ReactionTime final : public BehaviourTerm {
 public:
  unsigned phases() const override { return kDesire | kAfterStep; }
  void Desire(const DriveInputs&, DriveBlock& b) const override {
    for (std::size_t k = 0; k < b.count; ++k)
      if (b.driven[k]) b.from[k] = perceived_[b.first + k];
  }
  void AfterStep(const StepInputs& in) override {
    const double a = -std::expm1(-in.step_s / in.def.parameters.drive_reaction_time_s);
    for (std::size_t i = 0; i < in.bodies.size(); ++i)
      if (in.bodies.state[i] == PersonState::kWalking) perceived_[i] += (in.bodies.velocity_m_per_s[i] - perceived_[i]) * a;
  }

  std::uint32_t state_version() const override { return 1; }
  void Start(const BodyState& bodies) override { perceived_ = bodies.velocity_m_per_s; }
  void Place(std::size_t slot, const BodyState& bodies) override { perceived_[slot] = bodies.velocity_m_per_s[slot]; }
  void Stop(std::size_t person) override { perceived_[person] = {}; }
  void Quench() override { std::fill(perceived_.begin(), perceived_.end(), Vec2{}); }
  void Save(BinaryWriter& w) const override { w.PutVector(perceived_); }
  void Load(BinaryReader& r, std::size_t people) override { GetTermVector(r, perceived_, people, "perceived velocity"); }

 private:
  std::vector<Vec2> perceived_;  // w_i
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeReactionTime(const ModelParameters& p, const WorldDef&) {
  if (p.drive_reaction != DriveReaction::kLagged) return nullptr;
  return std::make_unique<ReactionTime>();
}

}  // namespace crowdrecon::engine::detail
