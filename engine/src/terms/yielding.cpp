// Term yielding (ModelParameters::yielding = when_blocked; issue 39, off by
// default): a person held up by the people ahead (the backward parts of
// their contact forces with them, DriveInputs::held_back_n, < 0) drives
// toward only a share of their desired speed, yielding_push_share of v0_i,
// instead of pushing with all of it.
#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

class YieldingTerm final : public BehaviourTerm {
 public:
  unsigned phases() const override { return kDesire; }
  bool needs_people_ahead() const override { return true; }
  void Desire(const DriveInputs& in, DriveBlock& b) const override {
    const double share = in.def.parameters.yielding_push_share;
    for (std::size_t k = 0; k < b.count; ++k) {
      const std::size_t i = b.first + k;
      if (b.driven[k] && in.held_back_n[i] < 0.0) b.pace[k] = in.bodies.desired_speed_m_per_s[i] * share;
    }
  }
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeYielding(const ModelParameters& p, const WorldDef&) {
  if (p.yielding != Yielding::kWhenBlocked) return nullptr;
  return std::make_unique<YieldingTerm>();
}

}  // namespace crowdrecon::engine::detail
