// Stage update_pairs: Verlet neighbour lists of person pairs and person-wall pairs.
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
#include "simulation_internals.hpp"

#include <algorithm>
#include <cmath>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

void Simulation::UpdatePairs() {
  ScopedTimer timer(profile_.stage_s[Index(Stage::kUpdatePairs)]);
  Internals& in = *in_;
  const std::size_t n = bodies_.size();
  if (in.pairs_valid) {
    // Rebuild only when someone moved more than half the skin since the last
    // build (bounding circles are rotation invariant, so rotation never forces one).
    const double limit2 = in.skin_m * in.skin_m / 4.0;
    const std::int64_t count = static_cast<std::int64_t>(n);
    bool rebuild = false;
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (count >= kParallelBodies) reduction(|| : rebuild)
    for (std::int64_t i = 0; i < count; ++i)
      rebuild = rebuild || LengthSquared(detail::Separation(def_.periodic, bodies_.position_m[static_cast<std::size_t>(i)],
                                                    in.position_at_build[static_cast<std::size_t>(i)])) > limit2;
    if (!rebuild) return;
  }
  ++profile_.pair_rebuilds;
  in.pairs_valid = true;
  in.position_at_build = bodies_.position_m;
  in.pairs.clear();
  in.wall_pairs.clear();

  std::vector<std::uint32_t> active;
  double bound_max = 0.0;
  Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
  for (std::uint32_t i = 0; i < n; ++i) {
    if (bodies_.state[i] == PersonState::kRemoved) continue;
    active.push_back(i);
    bound_max = std::max(bound_max, in.bound_m[i]);
    const Vec2 p = bodies_.position_m[i];
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  }
  if (active.empty()) return;
  const double cutoff = 2.0 * bound_max + in.skin_m;
  const PeriodicBox& box = def_.periodic;
  if (box.x) { lo.x = box.min_m.x; hi.x = box.max_m.x; }
  if (box.y) { lo.y = box.min_m.y; hi.y = box.max_m.y; }
  if ((box.x && box.max_m.x - box.min_m.x < 2.0 * cutoff) ||
      (box.y && box.max_m.y - box.min_m.y < 2.0 * cutoff))
    throw InputError("periodic box is shorter than twice the interaction range " +
                     FormatNumber(cutoff) + " m; make it longer");
  const auto cells_along = [&](double extent) {
    return static_cast<std::int64_t>(std::clamp(std::floor(extent / cutoff), 1.0, 1e6));
  };
  std::int64_t ncx = cells_along(hi.x - lo.x + (box.x ? 0.0 : 1e-9));
  std::int64_t ncy = cells_along(hi.y - lo.y + (box.y ? 0.0 : 1e-9));
  // People spread over an absurd extent (a state far beyond any venue: a 1 km
  // square at the usual range is 1.6 million cells, under the cap) would ask
  // for more cells than memory holds; coarser cells then find the same pairs.
  const double max_cells = std::max(double(1 << 22), 64.0 * double(active.size()));
  while (double(ncx) * double(ncy) > max_cells) {
    if (ncx >= ncy) ncx = (ncx + 1) / 2;
    else ncy = (ncy + 1) / 2;
  }
  const double cell_w = box.x ? (hi.x - lo.x) / double(ncx) : std::max(cutoff, (hi.x - lo.x) / double(ncx));
  const double cell_h = box.y ? (hi.y - lo.y) / double(ncy) : std::max(cutoff, (hi.y - lo.y) / double(ncy));
  const auto cell_of = [&](Vec2 p) {
    // Clamped before the conversion (a value beyond the range of the integer
    // would be undefined); the same cells as clamping the integers.
    const auto clamped = [](double f, std::int64_t count) {
      return !(f > 0.0) ? std::int64_t{0} : static_cast<std::int64_t>(std::min(f, double(count - 1)));
    };
    return std::pair{clamped(std::floor((p.x - lo.x) / cell_w), ncx), clamped(std::floor((p.y - lo.y) / cell_h), ncy)};
  };
  // Counting sort of bodies into cells.
  const std::size_t ncells = static_cast<std::size_t>(ncx * ncy);
  std::vector<std::uint32_t> cell_start(ncells + 1, 0), cell_items(active.size());
  std::vector<std::size_t> body_cell(active.size());
  for (std::size_t k = 0; k < active.size(); ++k) {
    const auto [cx, cy] = cell_of(bodies_.position_m[active[k]]);
    body_cell[k] = static_cast<std::size_t>(cy * ncx + cx);
    ++cell_start[body_cell[k] + 1];
  }
  for (std::size_t c = 0; c < ncells; ++c) cell_start[c + 1] += cell_start[c];
  {
    std::vector<std::uint32_t> fill(cell_start.begin(), cell_start.end() - 1);
    for (std::size_t k = 0; k < active.size(); ++k) cell_items[fill[body_cell[k]]++] = active[k];
  }
  // The pairs of each person with the later people of its own and the eight
  // neighbouring cells, and with the walls. People are taken in index order
  // and each one's partners in increasing order, so the lists come out sorted;
  // with many people, in as many contiguous parts as there are threads, each
  // into a list of its own, joined in order: the same lists either way.
  const std::size_t parts =
      static_cast<std::int64_t>(active.size()) >= kParallelBodies ? static_cast<std::size_t>(def_.threads) : 1;
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> part_pairs(parts), part_wall_pairs(parts);
  const std::int64_t part_count = static_cast<std::int64_t>(parts);
#pragma omp parallel for schedule(static, 1) num_threads(def_.threads) if (part_count > 1)
  for (std::int64_t part = 0; part < part_count; ++part) {
    const std::size_t q = static_cast<std::size_t>(part);
    std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs = part_pairs[q];
    std::vector<std::pair<std::uint32_t, std::uint32_t>>& wall_pairs = part_wall_pairs[q];
    std::vector<std::uint32_t> candidates;
    std::vector<std::size_t> neighbour_cells;
    const Part people = PartOf(active.size(), q, parts);
    for (std::size_t k = people.begin; k < people.end; ++k) {
      const std::uint32_t i = active[k];
      const Vec2 pi = bodies_.position_m[i];
      const std::int64_t cx = static_cast<std::int64_t>(body_cell[k] % static_cast<std::size_t>(ncx));
      const std::int64_t cy = static_cast<std::int64_t>(body_cell[k] / static_cast<std::size_t>(ncx));
      neighbour_cells.clear();
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          std::int64_t x = cx + dx, y = cy + dy;
          if (box.x) x = (x + ncx) % ncx;
          if (box.y) y = (y + ncy) % ncy;
          if (x < 0 || x >= ncx || y < 0 || y >= ncy) continue;
          neighbour_cells.push_back(static_cast<std::size_t>(y * ncx + x));
        }
      std::sort(neighbour_cells.begin(), neighbour_cells.end());
      neighbour_cells.erase(std::unique(neighbour_cells.begin(), neighbour_cells.end()), neighbour_cells.end());
      candidates.clear();
      for (std::size_t c : neighbour_cells)
        for (std::uint32_t s = cell_start[c]; s < cell_start[c + 1]; ++s) {
          const std::uint32_t j = cell_items[s];
          if (j <= i) continue;
          const double range = in.bound_m[i] + in.bound_m[j] + in.skin_m;
          if (LengthSquared(detail::Separation(def_.periodic, pi, bodies_.position_m[j])) < range * range) candidates.push_back(j);
        }
      std::sort(candidates.begin(), candidates.end());
      for (std::uint32_t j : candidates) pairs.emplace_back(i, j);
      for (std::uint32_t w = 0; w < def_.walls.size(); ++w) {
        if (!WallEnabled(w)) continue;  // an open door (SetWallEnabled)
        const Wall& wall = def_.walls[w];
        const double range = in.bound_m[i] + wall.radius_m + in.skin_m;
        if (Length(pi - in.wall_origin[w]) > in.wall_geometry[w].core_radius_m + range) continue;
        const std::size_t segments = wall.closed ? wall.points.size() : wall.points.size() - 1;
        for (std::size_t seg = 0; seg < segments; ++seg)
          if (DistanceToSegment(pi, wall.points[seg], wall.points[(seg + 1) % wall.points.size()]) < range) {
            wall_pairs.emplace_back(i, w);
            break;
          }
      }
    }
  }
  for (std::size_t q = 0; q < parts; ++q) {
    in.pairs.insert(in.pairs.end(), part_pairs[q].begin(), part_pairs[q].end());
    in.wall_pairs.insert(in.wall_pairs.end(), part_wall_pairs[q].begin(), part_wall_pairs[q].end());
  }
  assert(std::is_sorted(in.pairs.begin(), in.pairs.end()));
  const auto vertices_of = [&](std::uint32_t i) {
    return std::size_t{in.family_geometry[in.shape_family[bodies_.shape[i]]].count()};
  };
  in.pair_clear.Reset(
      in.pairs.size(), [&](std::size_t k) { return vertices_of(in.pairs[k].first) + vertices_of(in.pairs[k].second); },
      def_.threads);
  in.pair_motion.assign(in.pairs.size(), Internals::PairMotion{});  // (the first visit measures every vertex)
  in.wall_pair_clear.Reset(
      in.wall_pairs.size(),
      [&](std::size_t k) { return vertices_of(in.wall_pairs[k].first) + in.wall_geometry[in.wall_pairs[k].second].count(); },
      def_.threads);
}

void Simulation::RebuildNeighbourList() {
  in_->pairs_valid = false;
  UpdatePairs();
}

std::size_t Simulation::neighbour_pair_count() const { return in_->pairs.size(); }

void Simulation::SetPairMemory(bool enabled) {
  if (enabled && !in_->pair_memory) in_->pairs_valid = false;  // what was remembered is stale: start afresh
  in_->pair_memory = enabled;
}

}  // namespace crowdrecon::engine
