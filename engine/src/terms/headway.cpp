// Term headway (ModelParameters::headway = time_gap; issue 64, off by
// default): keeping a distance from the people ahead, the two rules of the
// collision-free speed model (Tordeux, Chraibi and Seyfried, "Collision-free
// speed model for pedestrian dynamics", Traffic and Granular Flow '15, 2016;
// JuPedSim's default operational model), as a behaviour term of a force-based
// model: eq. (3) relaxes toward the velocity these rules choose, and the
// contact forces still act when people touch.
//
// Steer phase: the heading h_i = (e_i + sum_j a exp((l - d_ij) / D) n_ji) normalised,
// n_ji the unit vector from j to i at centre distance d_ij (minimum image),
// over every other person in the venue within the neighbour radius (walking
// or fallen); a = headway_repulsion_strength, D = headway_repulsion_range_m,
// l = headway_length_m.
// Desire phase: the desired speed capped at max(0, (s_i - l) / T), s_i the
// smallest centre distance to a person j ahead (h_i . (x_j - x_i) > 0) whose
// centre lies within l of the line through x_i along h_i; T =
// headway_time_gap_s. No one ahead within the neighbour radius: no cap.
// e_i itself stays where the person wants to go: turned back by the people
// just ahead, a person steps back (the model's rule) without being "pushed
// backwards" in the sense of eq. (15), whose trigger and facing read e_i.
//
// The neighbour radius: l + 2.5 m/s x T (beyond it the cap exceeds 2.5 m/s,
// above the desired speeds of the venues' crowds; a person wanting to run
// faster meets the cap only within that radius) and at least l + 12 D (where
// the turning has fallen below a e^-11). No state.
#include <algorithm>
#include <cmath>

#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

constexpr double kHeadwayRadiusSpeed_m_per_s = 2.5;

class HeadwayTerm final : public BehaviourTerm {
 public:
  explicit HeadwayTerm(const ModelParameters& p)
      : radius_m_(std::max(p.headway_length_m + kHeadwayRadiusSpeed_m_per_s * p.headway_time_gap_s,
                           p.headway_length_m + 12.0 * p.headway_repulsion_range_m)) {}
  unsigned phases() const override { return kSteer | kDesire; }
  double neighbour_radius_m() const override { return radius_m_; }

  void Steer(const DriveInputs& in, DriveBlock& b) const override {
    const ModelParameters& mp = in.def.parameters;
    const double a = mp.headway_repulsion_strength, range = mp.headway_repulsion_range_m, l = mp.headway_length_m;
    for (std::size_t k = 0; k < b.count; ++k) {
      if (!b.driven[k]) continue;
      const std::size_t i = b.first + k;
      const Vec2 xi = in.bodies.position_m[i];
      Vec2 turned = b.heading[k];
      ForEachNeighbour(in.neighbours, in.bodies, i, [&](std::uint32_t j) {
        const Vec2 d = Separation(in.def.periodic, in.bodies.position_m[j], xi);  // x_j - x_i
        const double dij = Length(d);
        if (!(dij > 0.0) || dij > radius_m_) return;
        turned -= d * (a * std::exp((l - dij) / range) / dij);
      });
      const double norm = Length(turned);
      if (norm > 0.0) b.heading[k] = turned * (1.0 / norm);
    }
  }

  void Desire(const DriveInputs& in, DriveBlock& b) const override {
    const ModelParameters& mp = in.def.parameters;
    const double l = mp.headway_length_m, inverse_gap = 1.0 / mp.headway_time_gap_s;
    for (std::size_t k = 0; k < b.count; ++k) {
      if (!b.driven[k]) continue;
      const std::size_t i = b.first + k;
      const Vec2 xi = in.bodies.position_m[i], e = b.heading[k];
      double headway = radius_m_ + 1.0;  // (no one ahead: no cap)
      ForEachNeighbour(in.neighbours, in.bodies, i, [&](std::uint32_t j) {
        const Vec2 d = Separation(in.def.periodic, in.bodies.position_m[j], xi);  // x_j - x_i
        const double along = Dot(d, e);
        if (!(along > 0.0) || std::abs(Cross(e, d)) >= l) return;
        headway = std::min(headway, Length(d));
      });
      if (headway <= radius_m_) b.pace[k] = std::min(b.pace[k], std::max(0.0, (headway - l) * inverse_gap));
    }
  }

 private:
  double radius_m_;
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeHeadway(const ModelParameters& p, const WorldDef&) {
  if (p.headway != Headway::kTimeGap) return nullptr;
  return std::make_unique<HeadwayTerm>(p);
}

}  // namespace crowdrecon::engine::detail
