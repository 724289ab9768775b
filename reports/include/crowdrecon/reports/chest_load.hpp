// Chest load: the force that compresses a person's thorax, from the person's
// contact forces (other people, walls, barriers and fallen people alike).
// docs/reports.md, "Chest load", gives the equations and why this measure
// and not the raw force moment tensor; docs/model.md maps them to the paper.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "crowdrecon/common/periodic_box.hpp"
#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::reports {

// One contact as the run file records it: the force acts on person `a`;
// person `b` (when not a wall) feels its opposite. `point_m` is the contact
// point (in a's periodic image).
struct LoadContact {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  bool wall = false;
  Vec2 point_m;
  Vec2 force_on_a_n;
};

// Where a person is and which way the chest faces (radians, +x = 0).
struct Pose {
  Vec2 position_m;
  double angle_rad = 0.0;
  bool present = false;  // false: no contact of this index is expected
};

// The compressive load across the chest (front to back, along the facing
// direction d) and across the shoulders (side to side, along Perp(d)). For an
// axis u, the contacts on the side u points to (branch vector l with l.u > 0)
// push the body back with P+ = sum max(0, -F.u), those on the other side
// push it on with P- = sum max(0, F.u); what both sides press together is
// min(P+, P-), the rest accelerates the body. A contact exactly on the axis'
// normal line counts half to each side.
struct ChestLoad {
  double chest_n = 0.0;    // across the depth, along d
  double lateral_n = 0.0;  // across the width, along Perp(d)
  // The load the tolerance data are compared with: the larger of the two
  // (either compresses the thorax; docs/reports.md).
  double load_n() const { return chest_n > lateral_n ? chest_n : lateral_n; }
};

// The load along unit axis u of a body whose contacts have branch vectors
// `branch` and forces (on the body) `force`: min(P+, P-) above.
double CompressionAlong(Vec2 u, std::span<const Vec2> branch, std::span<const Vec2> force);

// The chest loads of every person (index = person index, sized like `poses`)
// from one frame's contacts. Contacts naming a person that is not present
// are an error of the caller (InputError names the contact).
std::vector<ChestLoad> ChestLoads(std::span<const Pose> poses, std::span<const LoadContact> contacts,
                                  const PeriodicBox& box);

// The force moment tensor M = sum_c l_c (x) F_c of one body (row-major
// xx, xy, yx, yy), the standard measure of granular mechanics, for
// comparison in the docs and tests: for contacts on the two faces of a body
// of depth D along u, -u.M.u / D = (P+ + P-) / 2, which counts half of the
// net force that accelerates the body as load.
struct MomentTensor {
  double xx = 0.0, xy = 0.0, yx = 0.0, yy = 0.0;
  double Along(Vec2 u) const { return u.x * (xx * u.x + xy * u.y) + u.y * (yx * u.x + yy * u.y); }
};
MomentTensor MomentOf(std::span<const Vec2> branch, std::span<const Vec2> force);

}  // namespace crowdrecon::reports
