#include "box_pairs.hpp"

#include <algorithm>
#include <numeric>

namespace crowdrecon::geometry::detail {

Box BoundsOf(const std::vector<Vec2>& points) {
  Box b{points.front(), points.front()};
  for (const Vec2 p : points) {
    b.lo = {std::min(b.lo.x, p.x), std::min(b.lo.y, p.y)};
    b.hi = {std::max(b.hi.x, p.x), std::max(b.hi.y, p.y)};
  }
  return b;
}

std::vector<Box> EdgeBoxes(const std::vector<Vec2>& ring) {
  std::vector<Box> boxes;
  boxes.reserve(ring.size());
  for (std::size_t i = 0; i < ring.size(); ++i) boxes.push_back(BoundsOf({ring[i], ring[(i + 1) % ring.size()]}));
  return boxes;
}

std::vector<std::pair<std::size_t, std::size_t>> OverlappingPairs(const std::vector<Box>& boxes) {
  std::vector<std::size_t> order(boxes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return boxes[a].lo.x < boxes[b].lo.x; });
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t k = 0; k < order.size(); ++k)
    for (std::size_t m = k + 1; m < order.size() && boxes[order[m]].lo.x <= boxes[order[k]].hi.x; ++m)
      if (boxes[order[k]].Overlaps(boxes[order[m]]))
        pairs.emplace_back(std::min(order[k], order[m]), std::max(order[k], order[m]));
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace crowdrecon::geometry::detail
