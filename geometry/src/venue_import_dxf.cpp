// DXF floor plans: the drawing read by dxf_drawing.cpp (curves flattened,
// block inserts expanded), pieces whose endpoints meet chained into rings,
// and the nesting of the rings deciding what is walkable (even depth) and
// what is an obstacle (odd depth), which is how a plan drawn as "outline plus
// pillars" reads.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <fstream>
#include <istream>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>


#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/input_limits.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "dxf_drawing.hpp"
#include "venue_internal.hpp"

namespace crowdrecon::geometry {

namespace {

using Piece = internal::DxfPiece;

std::vector<Vec2> WithoutRepeats(const std::vector<Vec2>& points, double tolerance) {
  std::vector<Vec2> out;
  for (Vec2 p : points)
    if (out.empty() || Length(p - out.back()) > tolerance) out.push_back(p);
  return out;
}

// Points hashed into square cells of side `tolerance`, so that the points
// within the tolerance of a query are found in the 3 x 3 cells around it.
// Cells are keyed by the bits of their (floored) coordinates, so that
// infinite or huge coordinates share a cell rather than overflow an integer.
class NodeGrid {
 public:
  explicit NodeGrid(double tolerance) : tolerance_(tolerance > 0.0 ? tolerance : 1e-300) {}

  // The lowest-numbered node within the tolerance of p, or nodes.size().
  std::size_t Find(Vec2 p, const std::vector<Vec2>& nodes) const {
    std::size_t best = nodes.size();
    const double cx = std::floor(p.x / tolerance_), cy = std::floor(p.y / tolerance_);
    for (double dx = -1.0; dx <= 1.0; dx += 1.0)
      for (double dy = -1.0; dy <= 1.0; dy += 1.0) {
        const auto cell = cells_.find(Key(cx + dx, cy + dy));
        if (cell == cells_.end()) continue;
        for (const std::size_t k : cell->second)
          if (k < best && Length(nodes[k] - p) <= tolerance_) best = k;
      }
    return best;
  }

  void Add(Vec2 p, std::size_t id) {
    cells_[Key(std::floor(p.x / tolerance_), std::floor(p.y / tolerance_))].push_back(id);
  }

 private:
  static std::pair<std::uint64_t, std::uint64_t> Key(double x, double y) {
    // (+ 0.0 turns -0.0 into 0.0, whose bits differ.)
    return {std::bit_cast<std::uint64_t>(x + 0.0), std::bit_cast<std::uint64_t>(y + 0.0)};
  }

  double tolerance_;
  std::map<std::pair<std::uint64_t, std::uint64_t>, std::vector<std::size_t>> cells_;
};

// Joins open pieces whose endpoints meet into rings. Endpoints within
// `tolerance` are one node; a connected set of pieces in which every node has
// exactly two piece ends is a cycle and becomes a ring. Pieces of other sets
// (T-junctions, dangling lines) stay open.
void ChainPieces(std::vector<Piece>* pieces, double tolerance) {
  std::vector<Piece> open, done;
  for (Piece& p : *pieces) (p.closed ? done : open).push_back(std::move(p));
  // Cluster endpoints: node id per end (2 per piece); an end joins the first
  // node within the tolerance, found through a grid of tolerance-sized cells.
  const std::size_t ends = 2 * open.size();
  std::vector<Vec2> end_point(ends);
  for (std::size_t i = 0; i < open.size(); ++i) {
    end_point[2 * i] = open[i].points.front();
    end_point[2 * i + 1] = open[i].points.back();
  }
  std::vector<std::size_t> node(ends);
  std::vector<Vec2> node_point;
  NodeGrid grid(tolerance);
  for (std::size_t e = 0; e < ends; ++e) {
    std::size_t found = grid.Find(end_point[e], node_point);
    if (found == node_point.size()) {
      grid.Add(end_point[e], found);
      node_point.push_back(end_point[e]);
    }
    node[e] = found;
  }
  std::vector<std::vector<std::size_t>> ends_at(node_point.size());
  for (std::size_t e = 0; e < ends; ++e) ends_at[node[e]].push_back(e);

  std::vector<bool> used(open.size(), false);
  for (std::size_t start = 0; start < open.size(); ++start) {
    if (used[start]) continue;
    // Collect the connected set of pieces.
    std::vector<std::size_t> set{start}, stack{start};
    std::vector<bool> seen(open.size(), false);
    seen[start] = true;
    while (!stack.empty()) {
      const std::size_t piece = stack.back();
      stack.pop_back();
      for (std::size_t side = 0; side < 2; ++side)
        for (std::size_t e : ends_at[node[2 * piece + side]])
          if (!seen[e / 2]) { seen[e / 2] = true; set.push_back(e / 2); stack.push_back(e / 2); }
    }
    for (std::size_t piece : set) used[piece] = true;
    const bool cycle = std::all_of(set.begin(), set.end(), [&](std::size_t piece) {
      return ends_at[node[2 * piece]].size() == 2 && ends_at[node[2 * piece + 1]].size() == 2;
    });
    if (!cycle) {
      for (std::size_t piece : set) done.push_back(std::move(open[piece]));
      continue;
    }
    // Walk the cycle, appending each piece in the direction of travel.
    Piece ring;
    ring.closed = true;
    std::size_t piece = start, entry_end = 2 * start;  // enter at its front
    std::vector<bool> walked(open.size(), false);
    while (!walked[piece]) {
      walked[piece] = true;
      std::vector<Vec2> pts = open[piece].points;
      if (entry_end % 2 == 1) std::reverse(pts.begin(), pts.end());
      ring.points.insert(ring.points.end(), pts.begin(), pts.end() - 1);  // the last point starts the next piece
      const std::size_t exit_end = entry_end ^ 1u;
      const auto& at = ends_at[node[exit_end]];
      const std::size_t next_end = at[0] == exit_end ? at[1] : at[0];
      piece = next_end / 2;
      entry_end = next_end;
    }
    done.push_back(std::move(ring));
  }
  *pieces = std::move(done);
}

}  // namespace

Venue ImportDxf(const std::filesystem::path& file, const ImportOptions& options) {
  internal::DxfDrawing drawing = internal::ReadDxfDrawing(file, options);
  const double scale = drawing.scale_m_per_unit;
  std::vector<Piece>& pieces = drawing.pieces;
  const double join_units = options.dxf_join_tolerance_m / scale;
  for (Piece& p : pieces) p.points = WithoutRepeats(p.points, join_units * 1e-3);
  pieces.erase(std::remove_if(pieces.begin(), pieces.end(),
                              [](const Piece& p) { return p.points.size() < (p.closed ? 3u : 2u); }),
               pieces.end());
  ChainPieces(&pieces, join_units);

  std::vector<Ring> rings;
  std::vector<std::vector<Vec2>> open_lines;
  for (Piece& p : pieces) {
    for (Vec2& q : p.points) q *= scale;
    if (p.closed) rings.push_back(std::move(p.points));
    else open_lines.push_back(std::move(p.points));
  }
  if (rings.empty()) {
    std::string what = file.string() + ": no closed region found";
    what += options.dxf_layer.empty() ? "" : " on layer \"" + options.dxf_layer + "\"";
    what += " (" + std::to_string(open_lines.size()) + " open polyline(s) that do not close";
    if (drawing.skipped_layers > 0)
      what += ", " + std::to_string(drawing.skipped_layers) + " entities on other layers skipped";
    what += "); expected the outline of the walkable area as a closed polyline, a circle, or lines whose "
            "endpoints meet within " + FormatNumber(options.dxf_join_tolerance_m) + " m";
    throw GeometryError(what);
  }

  // Nesting depth: the number of other rings containing a ring (tested at a
  // vertex; rings of a valid plan do not touch, and validation reports it if
  // they do). The innermost container of an odd ring is its outer ring.
  const std::size_t n = rings.size();
  std::vector<std::size_t> depth(n, 0);
  std::vector<std::size_t> parent(n, n);
  std::vector<double> area(n);
  std::vector<std::pair<Vec2, Vec2>> bounds(n);  // a cheap test before the point-in-ring one
  for (std::size_t i = 0; i < n; ++i) {
    area[i] = std::abs(RingSignedArea_m2(rings[i]));
    Vec2 lo = rings[i][0], hi = rings[i][0];
    for (const Vec2 p : rings[i]) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    }
    bounds[i] = {lo, hi};
  }
  const auto in_bounds = [&](std::size_t j, Vec2 p) {
    return bounds[j].first.x <= p.x && p.x <= bounds[j].second.x && bounds[j].first.y <= p.y &&
           p.y <= bounds[j].second.y;
  };
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      if (i != j && area[j] > area[i] && in_bounds(j, rings[i][0]) && PointInRing(rings[j], rings[i][0])) {
        ++depth[i];
        if (parent[i] == n || area[j] < area[parent[i]]) parent[i] = j;
      }
  std::vector<internal::ImportedRegion> regions;
  std::map<std::size_t, std::size_t> region_of_ring;
  for (std::size_t i = 0; i < n; ++i)
    if (depth[i] % 2 == 0) {
      region_of_ring[i] = regions.size();
      regions.push_back({rings[i], {}});
    }
  for (std::size_t i = 0; i < n; ++i)
    if (depth[i] % 2 == 1) regions[region_of_ring.at(parent[i])].holes.push_back(rings[i]);

  const std::string name = options.name.empty() ? file.stem().string() : options.name;
  Venue venue = internal::VenueFromRegions(std::move(regions), name,
                                           "imported from " + file.filename().string() + " (DXF)", file.string());
  for (std::size_t i = 0; i < open_lines.size(); ++i) {
    Wall wall;
    wall.id = "line-" + std::to_string(i + 1);
    wall.points = std::move(open_lines[i]);
    venue.walls.push_back(std::move(wall));
  }
  ValidateVenue(venue);
  return venue;
}

}  // namespace crowdrecon::geometry
