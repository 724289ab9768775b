// Stage neighbours: the people within the radius a behaviour term asks for
// (BehaviourTerm::neighbour_radius_m; the largest any active term asks for),
// for interactions at a distance, which the contact stage's Verlet lists do
// not reach (they hold pairs within their bounding radii plus a skin, about
// 0.6 m apart; keeping a distance looks 2-3 m ahead). When no term asks, the
// stage returns at once: no cost, no list.
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
//
// The list is a Verlet list of its own: candidates within radius + skin of
// each person, found with a grid of cells of that size (minimum image in a
// periodic box), and kept until someone has moved half the skin since it
// was built; a term measures the distance itself. Every slot has a list;
// its candidates are the slots in the venue at the build (a term reads their
// state: someone may have left since), not the empty ones, which the
// scenarios park together by the hundred (listing them cost most of a
// night's engine time). A slot filled between builds (Spawn, a state set
// back, a checkpoint loaded) is listed at once where it would have been as
// a candidate at the build's positions (ListComebacks): the drive evaluated
// at a placement, before the next build, sees the same candidates as when
// every slot was listed, so the runs are those of then, bit for bit. A
// newcomer's slot moves far, which rebuilds the list at the next step.
// Candidates are a superset of the people within the radius whenever the
// list is used by a step, so when it is rebuilt changes no result; the list
// is built in a fixed order, the same on any thread count (each chunk of
// people's rows on a thread, the chunks put end to end in their order), and
// is not in the checkpoint. When a term asks for a near list (a shorter
// radius it needs at every step), the list's
// candidates within the near radius + skin are kept as a second list, built
// and kept valid with the first.
#include "simulation_internals.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

namespace {

// The skin: a person walking at 2 m/s crosses half of it in 0.1 s, some
// hundred steps.
constexpr double kNeighbourSkin_m = 0.4;

// One axis of the grid: `count` cells of `size` from `origin`; along a
// periodic axis they tile the period (and fewer than three cells are all
// searched, so no candidate is missed or listed twice).
struct GridAxis {
  double origin = 0.0, size = 1.0;
  std::int64_t count = 1;
  bool periodic = false;
  std::int64_t Cell(double x) const {
    const auto c = static_cast<std::int64_t>(std::floor((x - origin) / size));
    return periodic ? ((c % count) + count) % count : std::clamp<std::int64_t>(c, 0, count - 1);
  }
  // The cells next to c (c - 1, c, c + 1), each once.
  int Around(std::int64_t c, std::int64_t out[3]) const {
    if (periodic && count < 3) {
      for (std::int64_t k = 0; k < count; ++k) out[k] = k;
      return static_cast<int>(count);
    }
    int m = 0;
    for (std::int64_t d = -1; d <= 1; ++d) {
      std::int64_t k = c + d;
      if (periodic) k = (k + count) % count;
      if (k >= 0 && k < count) out[m++] = k;
    }
    return m;
  }
};

// Cells of at least `cell` (the reach), at most `most` of them along the
// axis (so that people spread over a wide world need no more cells than
// there are people: a cell then holds more than the reach).
GridAxis Axis(bool periodic, double box_min, double box_max, double low, double high, double cell, std::int64_t most) {
  GridAxis a;
  a.periodic = periodic;
  const double extent = periodic ? box_max - box_min : high - low;
  const double fit = std::floor(extent / cell);
  a.count = std::clamp<std::int64_t>(fit < static_cast<double>(most) ? static_cast<std::int64_t>(fit) : most, 1, most);
  a.origin = periodic ? box_min : low;
  if (!periodic) ++a.count;  // (the last person's cell, at `high`)
  a.size = periodic ? extent / static_cast<double>(a.count) : std::max(cell, extent / static_cast<double>(a.count - 1));
  return a;
}

// People per chunk of the build (each chunk's rows made on one thread, the
// chunks then put end to end in their order: the same list on any thread
// count).
constexpr std::size_t kBuildChunk = 256;

// The list of every slot's candidates: the slots `eligible` within `radius`
// + the skin of it at the positions `at` (each slot has a list, eligible or
// not; the candidates of each in increasing index), and the near list; the
// rows on `threads` threads, in `chunks` and `near_chunks` (work space).
void BuildNeighbourList(const PeriodicBox& box, const std::vector<Vec2>& at, const std::vector<std::uint8_t>& eligible,
                        double radius, double near_radius, int threads, std::vector<std::vector<std::uint32_t>>& chunks,
                        std::vector<std::vector<std::uint32_t>>& near_chunks, NeighbourList& list) {
  const std::size_t n = at.size();
  const double reach = radius + kNeighbourSkin_m;
  Vec2 low{0.0, 0.0}, high{0.0, 0.0};
  if (n > 0) low = high = at[0];
  for (const Vec2& x : at) {
    low = {std::min(low.x, x.x), std::min(low.y, x.y)};
    high = {std::max(high.x, x.x), std::max(high.y, x.y)};
  }
  const auto most = static_cast<std::int64_t>(std::sqrt(4.0 * static_cast<double>(n))) + 1;
  const GridAxis ax = Axis(box.x, box.min_m.x, box.max_m.x, low.x, high.x, reach, most);
  const GridAxis ay = Axis(box.y, box.min_m.y, box.max_m.y, low.y, high.y, reach, most);
  // The eligible slots by cell (counting sort: within a cell in increasing
  // index); every slot's cell, for its own list.
  std::vector<std::uint32_t> cell_start(static_cast<std::size_t>(ax.count * ay.count) + 1, 0), cell_items;
  std::vector<std::uint32_t> cell_of(n);
  for (std::size_t i = 0; i < n; ++i) {
    cell_of[i] = static_cast<std::uint32_t>(ay.Cell(at[i].y) * ax.count + ax.Cell(at[i].x));
    if (eligible[i]) ++cell_start[cell_of[i] + 1];
  }
  for (std::size_t c = 1; c < cell_start.size(); ++c) cell_start[c] += cell_start[c - 1];
  cell_items.resize(cell_start.back());
  {
    std::vector<std::uint32_t> fill(cell_start.begin(), cell_start.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      if (eligible[i]) cell_items[fill[cell_of[i]]++] = static_cast<std::uint32_t>(i);
  }
  list.radius_m = radius;
  list.start.assign(n + 1, 0);
  list.items.clear();
  list.later.assign(n, 0);
  list.near_radius_m = near_radius;
  list.near_start.assign(near_radius > 0.0 ? n + 1 : 0, 0);
  list.near_items.clear();
  const double reach2 = reach * reach;
  const double near_reach2 = (near_radius + kNeighbourSkin_m) * (near_radius + kNeighbourSkin_m);
  const bool near = near_radius > 0.0;
  // Each chunk's rows: its people's candidates end to end, and each one's
  // count in start[i + 1] (near_start) until the counts are summed below.
  const auto chunk_count = static_cast<std::int64_t>((n + kBuildChunk - 1) / kBuildChunk);
  if (chunks.size() < static_cast<std::size_t>(chunk_count)) chunks.resize(static_cast<std::size_t>(chunk_count));
  if (near && near_chunks.size() < static_cast<std::size_t>(chunk_count))
    near_chunks.resize(static_cast<std::size_t>(chunk_count));
#pragma omp parallel for schedule(dynamic) num_threads(threads) if (static_cast<std::int64_t>(n) >= kParallelBodies)
  for (std::int64_t chunk = 0; chunk < chunk_count; ++chunk) {
    std::vector<std::uint32_t>& rows = chunks[static_cast<std::size_t>(chunk)];
    rows.clear();
    if (near) near_chunks[static_cast<std::size_t>(chunk)].clear();
    std::vector<std::uint32_t> mine;
    const std::size_t first = static_cast<std::size_t>(chunk) * kBuildChunk, last = std::min(n, first + kBuildChunk);
    for (std::size_t i = first; i < last; ++i) {
      const Vec2 x = at[i];
      std::int64_t cx[3], cy[3];
      const int mx = ax.Around(ax.Cell(x.x), cx), my = ay.Around(ay.Cell(x.y), cy);
      mine.clear();
      for (int a = 0; a < my; ++a)
        for (int b = 0; b < mx; ++b) {
          const auto c = static_cast<std::size_t>(cy[a] * ax.count + cx[b]);
          for (std::uint32_t k = cell_start[c]; k < cell_start[c + 1]; ++k) {
            const std::uint32_t j = cell_items[k];
            if (j == i) continue;
            const Vec2 d = detail::Separation(box, x, at[j]);
            if (Dot(d, d) <= reach2) mine.push_back(j);
          }
        }
      std::sort(mine.begin(), mine.end());
      rows.insert(rows.end(), mine.begin(), mine.end());
      list.start[i + 1] = static_cast<std::uint32_t>(mine.size());
      // (how many come before i: made an index below)
      list.later[i] = static_cast<std::uint32_t>(std::upper_bound(mine.begin(), mine.end(), i) - mine.begin());
      if (near) {
        std::vector<std::uint32_t>& near_rows = near_chunks[static_cast<std::size_t>(chunk)];
        const std::size_t before = near_rows.size();
        for (const std::uint32_t j : mine) {
          const Vec2 d = detail::Separation(box, x, at[j]);
          if (Dot(d, d) <= near_reach2) near_rows.push_back(j);
        }
        list.near_start[i + 1] = static_cast<std::uint32_t>(near_rows.size() - before);
      }
    }
  }
  // The counts summed into starts, the chunks put end to end.
  for (std::size_t i = 0; i < n; ++i) {
    list.start[i + 1] += list.start[i];
    list.later[i] += list.start[i];
  }
  list.items.resize(list.start[n]);
  if (near) {
    for (std::size_t i = 0; i < n; ++i) list.near_start[i + 1] += list.near_start[i];
    list.near_items.resize(list.near_start[n]);
  }
#pragma omp parallel for schedule(static) num_threads(threads) if (static_cast<std::int64_t>(n) >= kParallelBodies)
  for (std::int64_t chunk = 0; chunk < chunk_count; ++chunk) {
    const std::size_t first = static_cast<std::size_t>(chunk) * kBuildChunk;
    const std::vector<std::uint32_t>& rows = chunks[static_cast<std::size_t>(chunk)];
    std::copy(rows.begin(), rows.end(), list.items.begin() + list.start[first]);
    if (near) {
      const std::vector<std::uint32_t>& near_rows = near_chunks[static_cast<std::size_t>(chunk)];
      std::copy(near_rows.begin(), near_rows.end(), list.near_items.begin() + list.near_start[first]);
    }
  }
}

}  // namespace

void Simulation::Neighbours() {
  Internals& in = *in_;
  const double radius = std::max(in.terms.neighbour_radius_m, in.requested_neighbour_radius_m);
  const double near_radius = std::min(in.terms.near_radius_m, radius);
  if (!(radius > 0.0)) {
    if (!in.neighbours.empty()) in.neighbours = NeighbourList{};
    return;
  }
  ScopedTimer timer(profile_.stage_s[Index(Stage::kNeighbours)]);
  const std::size_t n = bodies_.size();
  // Still valid: built for this radius, and nobody has moved half the skin since.
  if (!in.neighbours.empty() && in.neighbours.radius_m == radius && in.neighbours.near_radius_m == near_radius &&
      in.neighbours_position_at_build.size() == n) {
    // (Well within half the skin by the square, without a square root; near
    // it, the length itself: the same decision, so the same builds.)
    const double half_skin = kNeighbourSkin_m / 2.0, surely_within2 = (half_skin * 0.999) * (half_skin * 0.999);
    bool valid = true;
    for (std::size_t i = 0; i < n && valid; ++i) {
      const Vec2 moved = detail::Separation(def_.periodic, bodies_.position_m[i], in.neighbours_position_at_build[i]);
      valid = Dot(moved, moved) <= surely_within2 || Length(moved) <= half_skin;
    }
    if (valid) return;
  }
  in.neighbours_listed.resize(n);
  for (std::size_t i = 0; i < n; ++i) in.neighbours_listed[i] = bodies_.state[i] != PersonState::kRemoved;
  BuildNeighbourList(def_.periodic, bodies_.position_m, in.neighbours_listed, radius, near_radius, def_.threads,
                     in.neighbour_chunks, in.near_chunks, in.neighbours);
  in.neighbours_position_at_build = bodies_.position_m;
}

void Simulation::ListComebacks() {
  Internals& in = *in_;
  const std::size_t n = bodies_.size();
  if (in.neighbours.empty() || in.neighbours_position_at_build.size() != n || in.neighbours_listed.size() != n) return;
  bool any = false;
  for (std::size_t i = 0; i < n; ++i)
    if (!in.neighbours_listed[i] && bodies_.state[i] != PersonState::kRemoved) {
      in.neighbours_listed[i] = 1;
      any = true;
    }
  if (!any) return;
  ScopedTimer timer(profile_.stage_s[Index(Stage::kNeighbours)]);
  BuildNeighbourList(def_.periodic, in.neighbours_position_at_build, in.neighbours_listed, in.neighbours.radius_m,
                     in.neighbours.near_radius_m, def_.threads, in.neighbour_chunks, in.near_chunks, in.neighbours);
}

void Simulation::RequestNeighbours(double radius_m) {
  if (!(radius_m >= 0.0 && radius_m <= 1e3))
    throw InputError("neighbour radius " + FormatNumber(radius_m) + " m, expected 0..1000 m");
  in_->requested_neighbour_radius_m = radius_m;
  in_->neighbours = NeighbourList{};
  Neighbours();
}

std::vector<std::uint32_t> Simulation::NeighboursWithin(std::uint32_t person, double radius_m) const {
  const NeighbourList& list = in_->neighbours;
  if (person >= bodies_.size()) throw InputError("person index " + std::to_string(person) + " out of range");
  if (list.empty() || radius_m > list.radius_m)
    throw InputError("the neighbour stage holds no list of radius " + FormatNumber(radius_m) + " m");
  std::vector<std::uint32_t> within;
  for (std::uint32_t k = list.start[person]; k < list.start[person + 1]; ++k) {
    const std::uint32_t j = list.items[k];
    if (Length(Separation(bodies_.position_m[person], bodies_.position_m[j])) <= radius_m) within.push_back(j);
  }
  return within;
}

}  // namespace crowdrecon::engine
