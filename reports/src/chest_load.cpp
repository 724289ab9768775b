#include "crowdrecon/reports/chest_load.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::reports {

double CompressionAlong(Vec2 u, std::span<const Vec2> branch, std::span<const Vec2> force) {
  double plus = 0.0, minus = 0.0;
  for (std::size_t c = 0; c < branch.size(); ++c) {
    const double side = Dot(branch[c], u), push = Dot(force[c], u);
    // The side a contact presses on: relative to the branch's length, so that
    // round-off in a contact point on the normal line does not pick a side.
    const double tolerance = 1e-9 * std::max(Length(branch[c]), 1e-12);
    if (side > tolerance) {
      plus += std::max(0.0, -push);
    } else if (side < -tolerance) {
      minus += std::max(0.0, push);
    } else {
      plus += 0.5 * std::max(0.0, -push);
      minus += 0.5 * std::max(0.0, push);
    }
  }
  return std::min(plus, minus);
}

MomentTensor MomentOf(std::span<const Vec2> branch, std::span<const Vec2> force) {
  MomentTensor m;
  for (std::size_t c = 0; c < branch.size(); ++c) {
    m.xx += branch[c].x * force[c].x;
    m.xy += branch[c].x * force[c].y;
    m.yx += branch[c].y * force[c].x;
    m.yy += branch[c].y * force[c].y;
  }
  return m;
}

std::vector<ChestLoad> ChestLoads(std::span<const Pose> poses, std::span<const LoadContact> contacts,
                                  const PeriodicBox& box) {
  // Each person's contacts (branch, force), gathered by person.
  std::vector<std::uint32_t> count(poses.size() + 1, 0);
  const auto check = [&](std::uint32_t person, std::size_t c) {
    if (person >= poses.size() || !poses[person].present)
      throw InputError("contact " + std::to_string(c + 1) + " of the frame names person " +
                       std::to_string(std::uint64_t{person} + 1) +
                       ", who is not in the frame; expected contacts between people present");
  };
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    check(contacts[c].a, c);
    ++count[contacts[c].a + 1];
    if (!contacts[c].wall) {
      check(contacts[c].b, c);
      ++count[contacts[c].b + 1];
    }
  }
  for (std::size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
  std::vector<Vec2> branch(count.back()), force(count.back());
  std::vector<std::uint32_t> fill(count.begin(), count.end() - 1);
  for (const LoadContact& c : contacts) {
    const std::uint32_t k = fill[c.a]++;
    branch[k] = box.MinimumImage(c.point_m - poses[c.a].position_m);
    force[k] = c.force_on_a_n;
    if (!c.wall) {
      const std::uint32_t kb = fill[c.b]++;
      branch[kb] = box.MinimumImage(c.point_m - poses[c.b].position_m);
      force[kb] = c.force_on_a_n * -1.0;
    }
  }
  std::vector<ChestLoad> loads(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const std::size_t begin = count[i], n = count[i + 1] - count[i];
    if (n < 2) continue;  // one contact cannot be balanced: no compression
    const std::span<const Vec2> l(branch.data() + begin, n), f(force.data() + begin, n);
    const Vec2 d{std::cos(poses[i].angle_rad), std::sin(poses[i].angle_rad)};
    loads[i].chest_n = CompressionAlong(d, l, f);
    loads[i].lateral_n = CompressionAlong(Perp(d), l, f);
  }
  return loads;
}

}  // namespace crowdrecon::reports
