#include "crowdrecon/analysis/metrics.hpp"

#include <cmath>
#include <limits>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::analysis {

int CrossingDirection(const MeasurementLine& line, Vec2 forward, Vec2 from_m, Vec2 to_m, const PeriodicBox& box,
                      double* fraction) {
  const Vec2 along = line.b_m - line.a_m;
  const double along2 = LengthSquared(along);
  if (!(along2 > 0.0)) return 0;
  Vec2 normal = Perp(along);
  if (Dot(normal, forward) < 0.0) normal = -normal;
  const Vec2 step = box.MinimumImage(to_m - from_m);
  const Vec2 period{box.x ? box.max_m.x - box.min_m.x : 0.0, box.y ? box.max_m.y - box.min_m.y : 0.0};
  const int kx = box.x ? 1 : 0, ky = box.y ? 1 : 0;
  int net = 0;
  for (int i = -kx; i <= kx; ++i)
    for (int j = -ky; j <= ky; ++j) {
      const Vec2 a = line.a_m + Vec2{i * period.x, j * period.y};
      // Signed distances (times |along|) of the step's ends from the line.
      const double s0 = Dot(from_m - a, normal);
      const double s1 = s0 + Dot(step, normal);
      int direction = 0;
      if (s0 < 0.0 && s1 >= 0.0) direction = +1;
      else if (s0 >= 0.0 && s1 < 0.0) direction = -1;
      if (direction == 0) continue;
      // Where the step meets the infinite line; it must lie on the segment.
      const double t = s0 / (s0 - s1);
      const Vec2 hit = from_m + step * t;
      const double u = Dot(hit - a, along) / along2;
      if (u < 0.0 || u > 1.0) continue;
      net += direction;
      if (fraction) *fraction = t;
    }
  return net;
}

bool LaneOrderOptions::IsValid(std::string* error) const {
  if (!(band_half_width_m > 0.0 && band_half_width_m <= 5.0)) {
    *error = "lane band_half_width_m = " + FormatNumber(band_half_width_m) + " m, expected (0, 5]";
    return false;
  }
  if (!(band_half_length_m > 0.0 && band_half_length_m <= 50.0)) {
    *error = "lane band_half_length_m = " + FormatNumber(band_half_length_m) + " m, expected (0, 50]";
    return false;
  }
  return true;
}

LaneOrderResult LaneOrder(const std::vector<Vec2>& position_m, const std::vector<std::uint32_t>& group,
                          Vec2 flow_axis, const LaneOrderOptions& options, const PeriodicBox& box,
                          std::vector<double>* per_person) {
  const std::size_t n = position_m.size();
  if (group.size() != n) throw InputError("LaneOrder: positions and groups differ in number");
  const double axis_length = Length(flow_axis);
  if (!(axis_length > 0.0)) throw InputError("LaneOrder: the flow axis has zero length");
  const Vec2 e = flow_axis / axis_length;
  const Vec2 across = Perp(e);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (per_person) per_person->assign(n, nan);
  LaneOrderResult result;
  double sum = 0.0;
  // All pairs: a few hundred people per frame make a cell list not worth it.
  for (std::size_t j = 0; j < n; ++j) {
    std::size_t same = 0, other = 0;
    for (std::size_t k = 0; k < n; ++k) {
      if (k == j) continue;
      const Vec2 d = box.MinimumImage(position_m[k] - position_m[j]);
      if (std::abs(Dot(d, across)) > options.band_half_width_m) continue;
      if (std::abs(Dot(d, e)) > options.band_half_length_m) continue;
      (group[k] == group[j] ? same : other) += 1;
    }
    if (same + other == 0) continue;
    const double ratio = (static_cast<double>(same) - static_cast<double>(other)) / static_cast<double>(same + other);
    const double phi = ratio * ratio;
    if (per_person) (*per_person)[j] = phi;
    sum += phi;
    ++result.people_counted;
  }
  result.order = result.people_counted > 0 ? sum / static_cast<double>(result.people_counted) : nan;
  return result;
}

}  // namespace crowdrecon::analysis
