#include "crowdrecon/scenario/world_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <random>
#include <tuple>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/narrow_phase.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/geometry/anthropometry.hpp"
#include "crowdrecon/geometry/body.hpp"
#include "crowdrecon/geometry/navigation.hpp"
#include "crowdrecon/geometry/triangulation.hpp"

namespace crowdrecon::scenario {

namespace {

constexpr double kPi = std::numbers::pi;

double Uniform(std::mt19937_64& rng) { return geometry::UniformUnit(rng()); }

std::string RingWkt(const geometry::Ring& ring, bool ccw) {
  geometry::Ring r = ring;
  if ((geometry::RingSignedArea_m2(r) > 0) != ccw) std::reverse(r.begin(), r.end());
  std::string s = "(";
  char buffer[64];
  for (std::size_t i = 0; i <= r.size(); ++i) {
    const Vec2 p = r[i % r.size()];
    std::snprintf(buffer, sizeof buffer, "%s%.17g %.17g", i ? ", " : "", p.x, p.y);
    s += buffer;
  }
  return s + ")";
}

engine::BodyShape ToBodyShape(const geometry::Spheropolygon& shape, double scale) {
  engine::BodyShape b;
  for (const Vec2& v : shape.vertices()) b.vertices.push_back(v * scale);
  b.radius_m = shape.radius() * scale;
  return b;
}

double MaxOverlap(const engine::Simulation& sim) {
  double worst = 0.0;
  for (const engine::Contact& c : sim.contacts()) worst = std::max(worst, c.overlap_m);
  return worst;
}

}  // namespace

std::vector<engine::Wall> VenueWalls(const geometry::Venue& venue) {
  std::vector<engine::Wall> walls;
  for (const geometry::WallSegment& s : geometry::WallSegments(venue)) {
    if (!walls.empty()) {
      engine::Wall& last = walls.back();
      if (last.radius_m == s.radius_m && Length(last.points.back() - s.a) < 1e-12) {
        if (Length(last.points.front() - s.b) < 1e-12 && last.points.size() >= 3) {
          last.closed = true;  // the chain came back to its start
        } else {
          last.points.push_back(s.b);
        }
        continue;
      }
    }
    walls.push_back({{s.a, s.b}, false, s.radius_m});
  }
  return walls;
}

// Position of the cell (x, y) along a Hilbert curve filling a 2^16 x 2^16
// grid: cells close along the curve are close in the plane.
std::uint64_t HilbertIndex(std::uint32_t x, std::uint32_t y) {
  std::uint64_t d = 0;
  for (std::uint32_t s = 1u << 15; s > 0; s /= 2) {
    const std::uint32_t rx = (x & s) ? 1 : 0, ry = (y & s) ? 1 : 0;
    d += std::uint64_t{s} * s * ((3 * rx) ^ ry);
    if (ry == 0) {  // rotate the quadrant
      if (rx == 1) {
        x = s - 1 - (x & (s - 1));
        y = s - 1 - (y & (s - 1));
      }
      std::swap(x, y);
    }
  }
  return d;
}

// The order of people along a Hilbert curve through their positions in the
// box [lo, hi] (ties by the original order).
std::vector<std::size_t> SpatialOrder(const std::vector<Vec2>& position, Vec2 lo, Vec2 hi) {
  const double extent = std::max({hi.x - lo.x, hi.y - lo.y, 1e-9});
  const auto cell = [&](double u) {
    return static_cast<std::uint32_t>(std::clamp(u / extent * 65536.0, 0.0, 65535.0));
  };
  std::vector<std::pair<std::uint64_t, std::size_t>> keyed(position.size());
  for (std::size_t i = 0; i < position.size(); ++i)
    keyed[i] = {HilbertIndex(cell(position[i].x - lo.x), cell(position[i].y - lo.y)), i};
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::size_t> order(position.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = keyed[i].second;
  return order;
}

std::string WalkableAreaWkt(const geometry::Venue& venue) {
  std::vector<std::string> polygons;
  for (const geometry::Ring& outer : venue.walkable_area) {
    std::string p = "(" + RingWkt(outer, true);
    for (const geometry::Obstacle& o : venue.obstacles)
      if (!o.polygon.empty() && geometry::PointInRing(outer, o.polygon.front())) p += ", " + RingWkt(o.polygon, false);
    polygons.push_back(p + ")");
  }
  if (polygons.size() == 1) return "POLYGON " + polygons.front();
  std::string wkt = "MULTIPOLYGON (";
  for (std::size_t i = 0; i < polygons.size(); ++i) wkt += (i ? ", " : "") + polygons[i];
  return wkt + ")";
}

Placement PlaceSequentially(const engine::WorldDef& def, const std::vector<geometry::AreaTriangulation>& regions,
                            double area_m2, double scale, double max_bound, Vec2 lo, Vec2 hi, std::mt19937_64& rng,
                            const std::string& origin) {
  const std::size_t count = def.people.size();
  // Random sequential placement at the reduced size, checked with the engine's
  // narrow phase against people already placed (cell grid) and walls.
  std::vector<Vec2> world;
  Placement placed;
  std::vector<Vec2>& position = placed.position;
  std::vector<double>& angle = placed.angle;
  position.resize(count);
  angle.resize(count);
  const double cell = 2.0 * max_bound * scale + 1e-9;
  std::vector<std::vector<std::uint32_t>> grid;
  Vec2 grid_lo = lo - Vec2{cell, cell};
  const auto gx = static_cast<std::size_t>(std::ceil((hi.x - lo.x) / cell)) + 3;
  const auto gy = static_cast<std::size_t>(std::ceil((hi.y - lo.y) / cell)) + 3;
  grid.assign(gx * gy, {});
  const auto cell_of = [&](Vec2 p) {
    const auto cx = static_cast<std::size_t>(std::clamp((p.x - grid_lo.x) / cell, 0.0, double(gx - 1)));
    const auto cy = static_cast<std::size_t>(std::clamp((p.y - grid_lo.y) / cell, 0.0, double(gy - 1)));
    return std::pair{cx, cy};
  };
  // Shapes at this growth stage's scale, and the walls, in their own frames.
  std::vector<engine::ShapeGeometry> scaled_shapes;
  for (const engine::BodyShape& s : def.shapes) {
    std::vector<Vec2> vertices;
    for (const Vec2& v : s.vertices) vertices.push_back(v * scale);
    scaled_shapes.push_back(engine::ShapeGeometry::Make(std::move(vertices), s.vertices.size() >= 3, s.radius_m * scale));
  }
  std::vector<engine::ShapeGeometry> wall_shapes;
  std::vector<Vec2> wall_origins(def.walls.size());
  for (std::size_t w = 0; w < def.walls.size(); ++w)
    wall_shapes.push_back(engine::ShapeGeometry::FromWorld(def.walls[w].points, def.walls[w].closed,
                                                           def.walls[w].radius_m, wall_origins[w]));
  const auto placed_shape = [&](std::size_t i, Vec2 at, double theta) {
    engine::PlacedShape p;
    p.geometry = &scaled_shapes[def.people[i].shape];
    p.position = at;
    p.cos_angle = std::cos(theta);
    p.sin_angle = std::sin(theta);
    return p;
  };
  std::vector<engine::ContactPoint> hits;
  const auto periodic_image = [&](Vec2 d) {
    if (def.periodic.x) d.x -= (def.periodic.max_m.x - def.periodic.min_m.x) * std::nearbyint(d.x / (def.periodic.max_m.x - def.periodic.min_m.x));
    if (def.periodic.y) d.y -= (def.periodic.max_m.y - def.periodic.min_m.y) * std::nearbyint(d.y / (def.periodic.max_m.y - def.periodic.min_m.y));
    return d;
  };
  for (std::size_t i = 0; i < count; ++i) {
    bool done = false;
    int attempts = 0, wall_blocked = 0;  // why places were refused, for the message
    for (int attempt = 0; attempt < 4000 && !done; ++attempt) {
      ++attempts;
      // Region chosen in proportion to its area.
      double u = Uniform(rng) * area_m2;
      std::size_t r = 0;
      while (r + 1 < regions.size() && u > regions[r].area_m2()) u -= regions[r++].area_m2();
      const Vec2 at = regions[r].Sample(rng);
      const Vec2 e = def.targets[def.people[i].target].Direction(at);
      const double theta = (e.x != 0.0 || e.y != 0.0 ? std::atan2(e.y, e.x) : 2.0 * kPi * Uniform(rng)) +
                           0.3 * (Uniform(rng) - 0.5);
      const engine::PlacedShape me = placed_shape(i, at, theta);
      bool free = true;
      for (std::size_t w = 0; w < def.walls.size(); ++w) {
        engine::PlacedShape ws;
        ws.geometry = &wall_shapes[w];
        ws.position = wall_origins[w];
        hits.clear();
        engine::CollideShapes(me, ws, hits);
        if (!hits.empty()) { free = false; break; }
      }
      if (!free) ++wall_blocked;
      const auto [cx, cy] = cell_of(at);
      for (std::size_t dy = 0; dy < 3 && free; ++dy)
        for (std::size_t dx = 0; dx < 3 && free; ++dx) {
          const std::size_t x = cx + dx - 1, y = cy + dy - 1;
          if (x >= gx || y >= gy) continue;
          for (std::uint32_t j : grid[y * gx + x]) {
            hits.clear();
            engine::CollideShapes(me, placed_shape(j, position[j], angle[j]), hits);
            if (!hits.empty()) { free = false; break; }
          }
        }
      // Across a periodic seam, compare with the nearest images too (only a
      // person within reach of a seam can meet someone's image).
      const double seam_reach = 2.0 * max_bound * scale;
      const bool near_seam =
          (def.periodic.x && std::min(at.x - def.periodic.min_m.x, def.periodic.max_m.x - at.x) < seam_reach) ||
          (def.periodic.y && std::min(at.y - def.periodic.min_m.y, def.periodic.max_m.y - at.y) < seam_reach);
      if (free && near_seam)
        for (std::size_t j = 0; j < i && free; ++j) {
          const Vec2 d = periodic_image(position[j] - at);
          if (Length(d) > 2.0 * max_bound * scale || Length(position[j] - at - d) < 1e-9) continue;
          hits.clear();
          engine::CollideShapes(me, placed_shape(j, at + d, angle[j]), hits);
          if (!hits.empty()) free = false;
        }
      if (!free) continue;
      position[i] = at;
      angle[i] = theta;
      grid[cy * gx + cx].push_back(static_cast<std::uint32_t>(i));
      done = true;
    }
    if (!done && wall_blocked == attempts)
      throw InputError(origin + ": /population: cannot place person " + std::to_string(i + 1) +
                       " of " + std::to_string(count) + ": each of the " + std::to_string(attempts) +
                       " places tried in the placement region (" + FormatNumber(area_m2) +
                       " m^2) touches a wall, even at " + FormatNumber(scale) +
                       " of full size; expected a region wider than a body inside the walls (check the venue's walls)");
    if (!done)
      throw InputError(origin + ": /population: cannot place person " + std::to_string(i + 1) +
                       " of " + std::to_string(count) + " in " + FormatNumber(area_m2) +
                       " m^2 even at " + FormatNumber(scale) + " of full size; the density is too high");
  }

  return placed;
}

void NumberAlongCurve(engine::WorldDef& def, Placement& placement, Vec2 lo, Vec2 hi) {
  // Number the people along a space-filling curve through their places, so
  // that people close in the crowd are close in the engine's arrays: the
  // narrow phase of neighbours then reads memory that is close too (the
  // placement's random order scattered every neighbour's data). The crowd is
  // the same; only who is person 1, 2, ... changes.
  {
    std::vector<Vec2>& position = placement.position;
    std::vector<double>& angle = placement.angle;
    const std::size_t count = def.people.size();
    const std::vector<std::size_t> order = SpatialOrder(position, lo, hi);
    std::vector<engine::PersonDef> people(count);
    std::vector<engine::BodyShape> shapes(count);  // one shape per person, in the same order
    std::vector<Vec2> placed_position(count);
    std::vector<double> placed_angle(count);
    for (std::size_t k = 0; k < count; ++k) {
      people[k] = def.people[order[k]];
      shapes[k] = def.shapes[people[k].shape];
      people[k].shape = static_cast<std::uint32_t>(k);
      placed_position[k] = position[order[k]];
      placed_angle[k] = angle[order[k]];
    }
    def.people = std::move(people);
    def.shapes = std::move(shapes);
    position = std::move(placed_position);
    angle = std::move(placed_angle);
  }

}

Relaxation GrowAndRelax(const engine::WorldDef& def, Placement& placement, double initial_scale, double tolerance,
                        const std::string& origin, const std::function<void(const std::string&)>& say) {
  // Grow to full size in stages with a passive, quenched relaxation after each.
  const int stages = initial_scale < 1.0 ? 8 : 1;
  Relaxation result;
  double& residual = result.residual;
  std::vector<Vec2>& position = placement.position;
  std::vector<double>& angle = placement.angle;
  const std::size_t count = def.people.size();
  for (int stage = 1; stage <= stages; ++stage) {
    const double scale = stages == 1 ? 1.0 : initial_scale + (1.0 - initial_scale) * stage / stages;
    engine::WorldDef relax = def;
    relax.parameters.ground_reaction = false;
    relax.parameters.restitution = relax.parameters.wall_restitution = 0.05;
    relax.parameters.time_step_s = 0.0;
    // The placement is not part of the dynamics: relax with velocity Verlet
    // whatever the run's integrator (Gear's step is ten times shorter).
    relax.parameters.integrator = engine::Integrator::kVelocityVerlet;
    relax.parameters.time_step_mode = engine::TimeStepMode::kFixed;  // (the same placement with either step)
    for (engine::BodyShape& s : relax.shapes) {
      for (Vec2& v : s.vertices) v *= scale;
      s.radius_m *= scale;
    }
    for (std::size_t i = 0; i < count; ++i) {
      relax.people[i].position_m = position[i];
      relax.people[i].angle_rad = angle[i];
    }
    std::optional<engine::Simulation> relaxing;
    try {
      relaxing.emplace(relax);
    } catch (const engine::SimulationError& e) {
      throw InputError(origin + ": /population: placement failed while relaxing: " + e.what());
    }
    engine::Simulation& sim = *relaxing;
    const bool last = stage == stages;
    const double goal = last ? tolerance : std::max(tolerance, 0.02 * scale);
    // Budgets in simulated time, so that the placement does not depend on
    // the step the engine chooses: quench every 5 ms, judge progress every
    // 0.25 s, at most 5 s for the full size (0.8 s for a growing stage).
    const double h = sim.time_step_s();
    const int quench_steps = std::max(1, static_cast<int>(std::lround(0.005 / h)));
    const int window_quenches = std::max(1, static_cast<int>(std::lround(0.25 / (quench_steps * h))));
    const int budget_quenches = static_cast<int>(std::lround((last ? 5.0 : 0.8) / (quench_steps * h)));
    int steps = 0;
    residual = MaxOverlap(sim);
    // Quenched relaxation; give up early once the largest overlap stops
    // falling (a jammed packing), judged over the windows.
    double window_start = residual;
    for (int quench = 1; residual > goal && quench <= budget_quenches; ++quench) {
      try {
        for (int k = 0; k < quench_steps; ++k) sim.Step();
      } catch (const engine::SimulationError& e) {
        throw InputError(origin + ": /population: placement failed while relaxing (the density may be too high): " +
                         e.what());
      }
      steps += quench_steps;
      sim.Quench();
      residual = MaxOverlap(sim);
      if (quench % window_quenches == 0) {
        if (residual > 0.95 * window_start) break;
        window_start = residual;
      }
    }
    result.steps += static_cast<std::size_t>(steps);
    for (std::size_t i = 0; i < count; ++i) {
      position[i] = sim.bodies().position_m[i];
      angle[i] = sim.bodies().angle_rad[i];
    }
    say("placement stage " + std::to_string(stage) + "/" + std::to_string(stages) + ": size x" +
        FormatNumber(scale) + ", largest overlap " + FormatNumber(residual) + " m after " + std::to_string(steps) +
        " relaxation steps");
  }
  return result;
}

namespace {

// The engine index of venue target `name`, added to the world if new.
std::uint32_t TargetIndex(const geometry::Venue& venue, BuiltWorld& built, const std::string& name) {
  const auto known = std::find(built.target_names.begin(), built.target_names.end(), name);
  if (known != built.target_names.end()) return static_cast<std::uint32_t>(known - built.target_names.begin());
  built.target_names.push_back(name);
  built.world.targets.push_back(geometry::NavigationField::ForTarget(venue, name));
  return static_cast<std::uint32_t>(built.target_names.size() - 1);
}

// The arrivals' run ids (BuiltTimeline::arrival_id): after the initial
// people, by the time each is due, then by inflow, then in the inflow's order.
void NumberArrivals(const TimelineSpec& timeline, BuiltTimeline& out) {
  struct Due {
    double time_s;
    std::size_t inflow, k;
  };
  std::vector<Due> due;
  out.arrival_id.assign(out.arrivals.size(), {});
  for (std::size_t f = 0; f < out.arrivals.size(); ++f) {
    out.arrival_id[f].resize(out.arrivals[f].size());
    for (std::size_t k = 0; k < out.arrivals[f].size(); ++k)
      due.push_back({ArrivalDueTime(timeline.inflows[f].rate, k + 1), f, k});
  }
  std::sort(due.begin(), due.end(), [](const Due& a, const Due& b) {
    return std::tie(a.time_s, a.inflow, a.k) < std::tie(b.time_s, b.inflow, b.k);
  });
  for (std::size_t n = 0; n < due.size(); ++n)
    out.arrival_id[due[n].inflow][due[n].k] = static_cast<std::uint32_t>(out.initial_people + n);
}

// The timeline's people to come (issue 20): per inflow, every arrival the
// schedule can bring within the run (its rate integrated over the whole run,
// as if always on), drawn from the population's rules with a seed of the
// inflow's own, so that the k-th arrival of an inflow is the same person
// whatever else the scenario holds; their shapes join the world's. Then the
// empty slots that arrivals fill (engine::Simulation::Spawn), and the targets
// every group and every event may name.
void AddArrivals(const Scenario& scenario, const geometry::Body& reference,
                 const std::vector<geometry::AnsurRecord>& records, BuiltWorld& built,
                 const std::function<void(const std::string&)>& say) {
  const TimelineSpec& timeline = scenario.timeline;
  const PopulationSpec& spec = scenario.population;
  const geometry::Venue& venue = scenario.venue;
  engine::WorldDef& def = built.world;
  BuiltTimeline& out = built.timeline;
  out.initial_people = def.people.size();
  const std::size_t first_shape = def.shapes.size();  // the arrivals' shapes follow the world's
  std::size_t total = 0;
  double smallest = 1e300;  // the smallest arriving body's area (m^2)
  for (std::size_t j = 0; j < timeline.inflows.size(); ++j) {
    const InflowSpec& inflow = timeline.inflows[j];
    const std::size_t count = ArrivalsDue(inflow.rate, scenario.run.duration_s);
    out.arrivals.emplace_back();
    if (count == 0) continue;
    // A seed per inflow (splitmix64 of the population's seed and the index).
    std::uint64_t z = spec.seed + 0x9e3779b97f4a7c15ull * (j + 1);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    geometry::PopulationOptions options;
    options.mode = spec.body_mode;
    options.count = count;
    options.seed = z;
    options.female_fraction = spec.female_fraction;
    options.vertex_count = spec.vertex_count;
    say("building " + std::to_string(count) + " " + geometry::ToString(spec.body_mode) + " bodies for inflow \"" +
        inflow.id + "\"");
    const geometry::Population population = geometry::MakePopulation(options, reference.shape, records);
    std::mt19937_64 rng(z ^ 0x9e3779b97f4a7c15ull);
    const auto [v_lo, v_hi] = inflow.desired_speed_m_per_s.value_or(
        std::pair{spec.desired_speed_min_m_per_s, spec.desired_speed_max_m_per_s});
    const std::uint32_t group = static_cast<std::uint32_t>(
        std::find(timeline.groups.begin(), timeline.groups.end(), inflow.group) - timeline.groups.begin());
    const std::uint32_t target = TargetIndex(venue, built, inflow.target);
    for (const geometry::Person& person : population.people) {
      engine::PersonDef p;
      p.shape = static_cast<std::uint32_t>(def.shapes.size());
      def.shapes.push_back(ToBodyShape(person.shape, 1.0));
      smallest = std::min(smallest, person.shape.area());
      p.mass_kg = person.mass_kg;
      p.inertia_kg_m2 = person.moment_of_inertia_kgm2;
      p.desired_speed_m_per_s = v_lo + (v_hi - v_lo) * Uniform(rng);
      p.group = group;
      p.target = target;
      out.arrivals.back().push_back(p);
    }
    total += count;
  }
  NumberArrivals(timeline, out);
  // Each arrival's shape at the place of its id, so that the shape table, as
  // the person table, does not depend on how long the run is.
  const std::vector<engine::BodyShape> drawn(def.shapes.begin() + static_cast<std::ptrdiff_t>(first_shape), def.shapes.end());
  for (std::size_t f = 0; f < out.arrivals.size(); ++f)
    for (std::size_t k = 0; k < out.arrivals[f].size(); ++k) {
      engine::PersonDef& p = out.arrivals[f][k];
      const std::size_t to = first_shape + (out.arrival_id[f][k] - out.initial_people);
      def.shapes[to] = drawn[p.shape - first_shape];
      p.shape = static_cast<std::uint32_t>(to);
    }
  // Every target an event may give.
  for (const TimelineEvent& e : timeline.events)
    if (e.kind == TimelineEvent::Kind::kTarget) TargetIndex(venue, built, e.name);
  // Empty slots: as many as the venue can hold at once (its walkable area over
  // the smallest arriving body's area: a crowd packed without gaps), or the
  // scenario's max_present; never more than the arrivals.
  std::size_t slots = 0;
  if (total > 0) {
    const double capacity = std::ceil(geometry::WalkableArea_m2(venue) / smallest);
    slots = timeline.max_present > 0
                ? (timeline.max_present > out.initial_people ? timeline.max_present - out.initial_people : 0)
                : static_cast<std::size_t>(std::min(capacity, double(total)));
    slots = std::min(slots, total);
  }
  Vec2 lo, hi;
  geometry::WalkableBounds(venue, &lo, &hi);
  for (std::size_t k = 0; k < slots; ++k) {
    engine::PersonDef empty;
    for (const auto& list : out.arrivals)
      if (!list.empty()) {
        empty = list.front();
        break;
      }
    empty.position_m = lo;
    empty.state = engine::PersonState::kRemoved;
    def.people.push_back(empty);
  }
  say("timeline: " + std::to_string(total) + " arrivals scheduled, " + std::to_string(out.initial_people) +
      " people at the start, " + std::to_string(def.people.size()) + " places in the engine");
}

}  // namespace

BuiltWorld BuildWorld(const Scenario& scenario, int threads,
                      const std::function<void(const std::string&)>& progress) {
  const auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };
  const geometry::Venue& venue = scenario.venue;
  const PopulationSpec& spec = scenario.population;
  BuiltWorld built;
  engine::WorldDef& def = built.world;
  def.parameters = scenario.model;
  def.threads = threads;

  // Placement region and head count.
  std::vector<geometry::AreaTriangulation> regions;
  if (spec.placement_region == "entries") {
    for (std::size_t e = 0; e < venue.entries.size(); ++e)
      regions.push_back(geometry::AreaTriangulation::OfEntryZone(venue, e));
  } else {
    regions.push_back(geometry::AreaTriangulation::OfWalkableArea(venue));
  }
  for (const auto& r : regions) built.placement_area_m2 += r.area_m2();
  const double wanted = spec.count ? static_cast<double>(*spec.count) : *spec.density_per_m2 * built.placement_area_m2;
  if (!spec.count && !(wanted <= static_cast<double>(geometry::kMaxPeople)))  // before any allocation; NaN too
    throw InputError(scenario.file.string() + ": /population/density_per_m2: " + FormatNumber(*spec.density_per_m2) +
                     " /m^2 over " + FormatNumber(built.placement_area_m2) + " m^2 gives " + FormatNumber(wanted) +
                     " people; expected at most " + std::to_string(geometry::kMaxPeople) +
                     " (check the venue's scale: is it drawn in metres?)");
  const std::size_t count = spec.count ? *spec.count : static_cast<std::size_t>(std::llround(wanted));
  if (count == 0 && !scenario.timeline.HasInflow())
    throw InputError(scenario.file.string() + ": /population: the density gives 0 people in " +
                     FormatNumber(built.placement_area_m2) + " m^2");

  // Targets: the main flow first, the counter-flow second (then those only
  // the timeline names: TargetIndex).
  built.target_names.push_back(spec.target);
  def.targets.push_back(geometry::NavigationField::ForTarget(venue, spec.target));
  if (spec.counter_flow_fraction > 0.0) {
    built.target_names.push_back(spec.counter_target);
    def.targets.push_back(geometry::NavigationField::ForTarget(venue, spec.counter_target));
  }

  // Bodies.
  say("building " + std::to_string(count) + " " + geometry::ToString(spec.body_mode) + " bodies");
  geometry::PopulationOptions options;
  options.mode = spec.body_mode;
  options.count = count;
  options.seed = spec.seed;
  options.female_fraction = spec.female_fraction;
  options.vertex_count = spec.vertex_count;
  const geometry::Body reference = geometry::ReadBodyJson(spec.reference_body);
  std::vector<geometry::AnsurRecord> records;
  if (spec.body_mode == geometry::PopulationMode::kAnthropometric) records = geometry::ReadAnsurExtract(spec.anthropometry);
  const geometry::Population population =
      count > 0 ? geometry::MakePopulation(options, reference.shape, records) : geometry::Population{};

  // Groups, desired speeds: a second generator stream so that they do not
  // depend on how many draws the body modes consumed.
  std::mt19937_64 rng(spec.seed ^ 0x9e3779b97f4a7c15ull);
  const std::size_t counter = static_cast<std::size_t>(std::llround(spec.counter_flow_fraction * double(count)));
  std::vector<std::uint32_t> group(count, 0);
  for (std::size_t i = 0; i < counter; ++i) group[i] = 1;
  for (std::size_t i = count - 1; count > 0 && i > 0; --i) {  // Fisher-Yates with explicit draws
    const std::size_t j = static_cast<std::size_t>(Uniform(rng) * double(i + 1));
    std::swap(group[i], group[std::min(j, i)]);
  }
  for (std::size_t i = 0; i < count; ++i) {
    const geometry::Person& person = population.people[i];
    engine::PersonDef p;
    p.shape = static_cast<std::uint32_t>(def.shapes.size());
    def.shapes.push_back(ToBodyShape(person.shape, 1.0));
    p.mass_kg = person.mass_kg;
    p.inertia_kg_m2 = person.moment_of_inertia_kgm2;
    p.desired_speed_m_per_s =
        spec.desired_speed_min_m_per_s + (spec.desired_speed_max_m_per_s - spec.desired_speed_min_m_per_s) * Uniform(rng);
    p.group = group[i];
    p.target = group[i];
    def.people.push_back(p);
  }

  // Walls, periodic box, slope.
  def.walls = VenueWalls(venue);
  Vec2 lo, hi;
  geometry::WalkableBounds(venue, &lo, &hi);
  for (const geometry::PeriodicDirection& d : venue.periodic) {
    if (std::abs(std::abs(d.direction.x) - 1.0) < 1e-9) {
      def.periodic.x = true;
      def.periodic.min_m.x = lo.x;
      def.periodic.max_m.x = lo.x + d.period_m;
    } else if (std::abs(std::abs(d.direction.y) - 1.0) < 1e-9) {
      def.periodic.y = true;
      def.periodic.min_m.y = lo.y;
      def.periodic.max_m.y = lo.y + d.period_m;
    } else {
      throw InputError(venue.origin + ": periodic direction (" + FormatNumber(d.direction.x) + ", " +
                       FormatNumber(d.direction.y) + ") is not along x or y; the engine supports axis-aligned periods");
    }
  }
  if (venue.slope && venue.slope->enabled) def.slope = {venue.slope->direction, venue.slope->gradient, venue.slope->region};
  built.walkable_wkt = WalkableAreaWkt(venue);
  // A timeline's doors: a wall across every exit, switched off while the
  // exit is open (engine::Simulation::SetWallEnabled).
  if (scenario.timeline.enabled)
    for (const geometry::Exit& e : venue.exits) {
      built.timeline.exit_wall.push_back(static_cast<std::uint32_t>(def.walls.size()));
      def.walls.push_back({{e.a, e.b}, false, 0.0});
    }
  if (count == 0) {
    AddArrivals(scenario, reference, records, built, say);
    return built;
  }

  // --- Placement --------------------------------------------------------
  double body_area = 0.0, max_bound = 0.0;
  for (const geometry::Person& person : population.people) {
    body_area += person.shape.area();
    double bound = 0.0;
    for (const Vec2& v : person.shape.vertices()) bound = std::max(bound, Length(v));
    max_bound = std::max(max_bound, bound + person.shape.radius());
  }
  const double fraction = body_area / built.placement_area_m2;
  const double scale = std::min(1.0, std::sqrt(0.25 / fraction));
  say("placing at area fraction " + FormatNumber(fraction) + ", initial size x" + FormatNumber(scale));

  Placement placement = PlaceSequentially(def, regions, built.placement_area_m2, scale, max_bound, lo, hi, rng,
                                          scenario.file.string());
  NumberAlongCurve(def, placement, lo, hi);
  const double tolerance = spec.max_initial_overlap_m;
  const Relaxation relaxed = GrowAndRelax(def, placement, scale, tolerance, scenario.file.string(), say);
  const double residual = relaxed.residual;
  built.relaxation_steps += relaxed.steps;
  const std::vector<Vec2>& position = placement.position;
  const std::vector<double>& angle = placement.angle;
  if (residual > tolerance)
    throw InputError(scenario.file.string() + ": /population: " + std::to_string(count) + " people (" +
                     FormatNumber(double(count) / built.placement_area_m2) + " /m^2) cannot be placed: after relaxation the largest overlap is " +
                     FormatNumber(residual) + " m, above the tolerance " + FormatNumber(tolerance) +
                     " m (/population/placement/max_overlap_m); the crowd is jammed at this density");
  for (std::size_t i = 0; i < count; ++i) {
    def.people[i].position_m = position[i];
    def.people[i].angle_rad = angle[i];
    if (!def.periodic.x && !def.periodic.y && !geometry::IsWalkable(venue, position[i]))
      throw InputError(scenario.file.string() + ": /population: person " + std::to_string(i + 1) +
                       " was pushed out of the walkable area while relaxing the placement; lower the density");
  }
  built.max_initial_overlap_m = residual;
  if (scenario.timeline.enabled) AddArrivals(scenario, reference, records, built, say);
  return built;
}

}  // namespace crowdrecon::scenario
