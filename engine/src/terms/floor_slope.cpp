// Term floor_slope: a sloping floor (WorldDef::slope; issue 43), on where the
// floor slopes (gradient > 0), on the whole floor or inside its region.
// ModelParameters::slope_response says how people meet it:
//   body_force  gravity's component along the floor, m g s / sqrt(1 + s^2)
//               downhill, pulls every walking person on it (force phase);
//   held        the legs hold that pull, and the desired speed follows the
//               grade along e_i by Tobler's hiking function
//               (SlopeWalkingFactor; desire phase, after yielding's share).
#include <cmath>

#include "../behaviour.hpp"
#include "crowdrecon/common/polygon.hpp"

namespace crowdrecon::engine::detail {
namespace {

class SlopeTerm final : public BehaviourTerm {
 public:
  explicit SlopeTerm(bool held) : held_(held) {}
  unsigned phases() const override { return held_ ? kDesire : kForce; }

  void Desire(const DriveInputs& in, DriveBlock& b) const override {
    const FloorSlope& slope = in.def.slope;
    for (std::size_t k = 0; k < b.count; ++k)
      if (b.driven[k] && OnSlope(slope, in.bodies.position_m[b.first + k]))
        b.pace[k] *= SlopeWalkingFactor(-slope.gradient * Dot(b.direction[k], slope.downhill));
  }

  void Force(const DriveInputs& in, DriveBlock& b) const override {
    const FloorSlope& slope = in.def.slope;
    const double pull_per_kg =
        in.def.parameters.gravity_m_per_s2 * slope.gradient / std::sqrt(1.0 + slope.gradient * slope.gradient);
    const Vec2 pull = slope.downhill * pull_per_kg;
    for (std::size_t k = 0; k < b.count; ++k)
      if (b.driven[k] && OnSlope(slope, in.bodies.position_m[b.first + k]))
        b.force[k] += pull * in.bodies.mass_kg[b.first + k];
  }

 private:
  // (An empty region: the whole floor.)
  static bool OnSlope(const FloorSlope& slope, Vec2 x) { return slope.region.empty() || PointInPolygon(slope.region, x); }
  bool held_;
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeFloorSlope(const ModelParameters& p, const WorldDef& def) {
  if (!(def.slope.gradient > 0.0)) return nullptr;
  return std::make_unique<SlopeTerm>(p.slope_response == SlopeResponse::kHeld);
}

}  // namespace crowdrecon::engine::detail
