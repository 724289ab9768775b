// Term shoulder_turn (ModelParameters::shoulder_turn = when_blocked; issue
// 39, off by default): a person held up by the people ahead
// (DriveInputs::held_back_n < 0) turns a shoulder into the way, on purpose:
// the body faces e_i turned by shoulder_turn_angle_deg to whichever side is
// nearer its present orientation, with the full gain of eq. (16) (not its
// share of the speed). After motive_torque in the facing phase.
#include <cmath>
#include <numbers>

#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

// e rotated by the turn (cos, sin) to whichever side is nearer `orientation`.
Vec2 ShoulderFacing(Vec2 e, Vec2 turn, Vec2 orientation) {
  const Vec2 left{e.x * turn.x - e.y * turn.y, e.x * turn.y + e.y * turn.x};
  const Vec2 right{e.x * turn.x + e.y * turn.y, -e.x * turn.y + e.y * turn.x};
  return Dot(orientation, left) >= Dot(orientation, right) ? left : right;
}

class ShoulderTurnTerm final : public BehaviourTerm {
 public:
  unsigned phases() const override { return kFacing; }
  bool needs_people_ahead() const override { return true; }
  void Facing(const DriveInputs& in, DriveBlock& b) const override {
    const double turn_rad = in.def.parameters.shoulder_turn_angle_deg * (std::numbers::pi / 180.0);
    const Vec2 turn{std::cos(turn_rad), std::sin(turn_rad)};
    for (std::size_t k = 0; k < b.count; ++k) {
      const std::size_t i = b.first + k;
      if (!b.driven[k] || !(in.held_back_n[i] < 0.0)) continue;
      b.facing[k] = ShoulderFacing(b.direction[k], turn, Vec2{in.cos_angle[i], in.sin_angle[i]});
      b.gain[k] = 1.0;
    }
  }
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeShoulderTurn(const ModelParameters& p, const WorldDef&) {
  if (p.shoulder_turn != ShoulderTurn::kWhenBlocked) return nullptr;
  return std::make_unique<ShoulderTurnTerm>();
}

}  // namespace crowdrecon::engine::detail
