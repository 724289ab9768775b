// Kernel benchmarks (Google Benchmark): the narrow phase of two thorax bodies,
// the neighbour-list rebuild and one whole Step() on dense crowds. What each
// measures and how to run them: bench/README.md.
//
//   crowdrecon_bench_kernels                                  all of them
//   crowdrecon_bench_kernels --benchmark_filter=NarrowPhase   only the narrow phase
//
// Items per second are agent-steps per second (people x steps) for Step, people
// per second for the rebuild, and shape pairs per second for the narrow phase.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "bench_worlds.hpp"
#include "step_benchmark.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/vec2.hpp"
#include "crowdrecon/engine/narrow_phase.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/engine/world_file.hpp"
#include "crowdrecon/geometry/body.hpp"
#include "crowdrecon/scenario/run_record.hpp"
#include "crowdrecon/scenario/runner.hpp"
#include "crowdrecon/scenario/scenario.hpp"

namespace crowdrecon::bench {

namespace {

constexpr double kPi = std::numbers::pi;

// ---------------------------------------------------------------------------
// Narrow phase

// The narrow phase's interface changes with the optimisation of issue 5: before
// it, a PlacedShape carries world-frame vertices (with centroid, core radius,
// body-frame box and rotation); after it, a pointer to the shape's geometry in
// its own frame and a pose. The benchmark places bodies for whichever
// interface the engine has, as engine/src/simulation.cpp's Collide() does, so
// that the same benchmark measures both.
template <typename Shape>
concept PoseShape = requires(Shape s) {
  s.geometry;
  s.position;
};

template <typename Shape>
struct GeometryOf {
  using type = int;  // world-vertex interface: no separate geometry
};
template <PoseShape Shape>
struct GeometryOf<Shape> {
  using type = std::remove_cvref_t<decltype(*std::declval<Shape>().geometry)>;
};

// A body placed in the world. Not copyable: `shape` points into the object.
template <typename Shape>
struct PlacedBodyOf {
  std::vector<Vec2> world;                   // world-vertex interface
  typename GeometryOf<Shape>::type geometry;  // pose interface
  Shape shape;

  PlacedBodyOf(const geometry::Spheropolygon& body, Vec2 at, double angle_rad, double extra_radius_m) {
    const double c = std::cos(angle_rad), s = std::sin(angle_rad);
    if constexpr (PoseShape<Shape>) {
      geometry = decltype(geometry)::Make(body.vertices(), body.vertices().size() >= 3, body.radius() + extra_radius_m);
      shape.geometry = &geometry;
      shape.position = at;
    } else {
      shape.box_min = shape.box_max = body.vertices().front();
      for (const Vec2& v : body.vertices()) {
        world.push_back({at.x + c * v.x - s * v.y, at.y + s * v.x + c * v.y});
        shape.core_radius_m = std::max(shape.core_radius_m, Length(v));
        shape.box_min = {std::min(shape.box_min.x, v.x), std::min(shape.box_min.y, v.y)};
        shape.box_max = {std::max(shape.box_max.x, v.x), std::max(shape.box_max.y, v.y)};
      }
      shape.vertices = world.data();
      shape.count = static_cast<std::uint32_t>(world.size());
      shape.closed = world.size() >= 3;
      shape.radius_m = body.radius() + extra_radius_m;
      shape.centre = at;
    }
    shape.cos_angle = c;
    shape.sin_angle = s;
  }
  PlacedBodyOf(const PlacedBodyOf&) = delete;
  PlacedBodyOf& operator=(const PlacedBodyOf&) = delete;
};
using PlacedBody = PlacedBodyOf<engine::PlacedShape>;

// Largest overlap of A (at the origin, angle_a) and B (at distance `d` along
// `direction`, angle_b), with both sphero-radii grown by `extra_m`; -infinity
// when they do not touch.
double MaxOverlap(const geometry::Spheropolygon& body, double angle_a, Vec2 direction, double d, double angle_b,
                  double extra_m) {
  const PlacedBody a(body, {0.0, 0.0}, angle_a, extra_m);
  const PlacedBody b(body, direction * d, angle_b, extra_m);
  std::vector<engine::ContactPoint> points;
  engine::CollideShapes(a.shape, b.shape, points);
  double worst = -std::numeric_limits<double>::infinity();
  for (const engine::ContactPoint& p : points) worst = std::max(worst, p.overlap_m);
  return worst;
}

// Centre distance along `direction` at which the largest overlap (radii grown
// by extra_m) equals `overlap_m`: bisection between coincident centres and the
// sum of the bounding radii, where they cannot touch.
double DistanceForOverlap(const geometry::Spheropolygon& body, double angle_a, Vec2 direction, double angle_b,
                          double overlap_m, double extra_m) {
  double bound = 0.0;
  for (const Vec2& v : body.vertices()) bound = std::max(bound, Length(v));
  double lo = 0.0, hi = 2.0 * (bound + body.radius() + extra_m);
  for (int k = 0; k < 80; ++k) {
    const double mid = 0.5 * (lo + hi);
    (MaxOverlap(body, angle_a, direction, mid, angle_b, extra_m) > overlap_m ? lo : hi) = mid;
  }
  return hi;
}

struct NarrowPhaseCase {
  std::string name;
  double angle_a, angle_b;  // rad; 0 = chest toward +x (shoulders along y)
  Vec2 direction;           // from A's centre to B's
  enum Kind { kTouching, kNear, kFar } kind;
};

const geometry::Spheropolygon& ReferenceThorax() {
  static const geometry::Body body =
      geometry::ReadBodyJson(scenario::DataDirectory() / "venues/bodies/thorax-18.json");
  return body.shape;
}

void NarrowPhase(benchmark::State& state, const NarrowPhaseCase& c) {
  const geometry::Spheropolygon& body = ReferenceThorax();
  double bound = 0.0;
  for (const Vec2& v : body.vertices()) bound = std::max(bound, Length(v));
  bound += body.radius();
  double d = 0.0;
  switch (c.kind) {
    case NarrowPhaseCase::kTouching:  // overlapping by 1 cm
      d = DistanceForOverlap(body, c.angle_a, c.direction, c.angle_b, 0.01, 0.0);
      break;
    case NarrowPhaseCase::kNear:  // 2 cm apart: grown by 1 cm each, they would just touch
      d = DistanceForOverlap(body, c.angle_a, c.direction, c.angle_b, 0.0, 0.01);
      break;
    case NarrowPhaseCase::kFar:  // bounding circles apart, within the list's reach (skin 0.1 m)
      d = 2.0 * bound + 0.05;
      break;
  }
  const PlacedBody a(body, {0.0, 0.0}, c.angle_a, 0.0);
  const PlacedBody b(body, c.direction * d, c.angle_b, 0.0);
  std::vector<engine::ContactPoint> points;
  points.reserve(64);
  engine::CollideShapes(a.shape, b.shape, points);
  const double contacts = static_cast<double>(points.size());
  if ((c.kind == NarrowPhaseCase::kTouching) != (contacts > 0)) {
    state.SkipWithError("the configuration does not touch as intended");
    return;
  }
  if ((c.kind == NarrowPhaseCase::kFar) != (d >= 2.0 * bound)) {
    state.SkipWithError("the bounding circles overlap where they should not, or the other way round");
    return;
  }
  for (auto _ : state) {
    points.clear();
    engine::CollideShapes(a.shape, b.shape, points);
    benchmark::DoNotOptimize(points.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["contacts"] = contacts;
  state.counters["centre_distance_m"] = d;
}

// ---------------------------------------------------------------------------
// Neighbour list and whole steps on the benchmark scenarios
//
// A placement relaxes into a crowd at rest whose contacts first fade, then
// build up again as people walk. So that every run measures the same work
// whatever the speed of the engine (Google Benchmark chooses the number of
// iterations from the time they take), the crowd first walks kWarmUpSeconds,
// its state is saved, and the timed steps are always the kWindowSteps steps
// that follow it: every kWindowSteps iterations the state is restored, with
// the timer paused. (A restore makes the next step rebuild the neighbour
// list, once per window: a run at 1 m/s rebuilds about as often.)

constexpr double kWarmUpSeconds = 0.25;  // simulated
constexpr double kDevelopedSeconds = 5.0;  // simulated; see RegisterAll

engine::Simulation MakeSimulation(const std::string& world, int threads) {
  engine::WorldDef def = CachedWorld(world).world;
  def.threads = threads;
  return engine::Simulation(std::move(def));
}

// The state after the warm-up, once per world (results do not depend on the
// thread count, so it serves every thread count).
const std::string& WarmState(const std::string& world, double warm_up_s = kWarmUpSeconds) {
  static std::map<std::pair<std::string, double>, std::string> cache;
  auto it = cache.find({world, warm_up_s});
  if (it == cache.end()) {
    engine::Simulation sim =
        MakeSimulation(world, static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
    while (sim.time_s() < warm_up_s) sim.Step();
    it = cache.emplace(std::pair{world, warm_up_s}, sim.SaveState()).first;
  }
  return it->second;
}

void NeighbourRebuild(benchmark::State& state, const std::string& world, int threads) {
  engine::Simulation sim = MakeSimulation(world, threads);
  sim.LoadState(WarmState(world));
  const auto people = static_cast<std::int64_t>(sim.bodies().size());
  for (auto _ : state) sim.RebuildNeighbourList();
  state.SetItemsProcessed(state.iterations() * people);
  state.counters["people"] = static_cast<double>(people);
  state.counters["pairs"] = static_cast<double>(sim.neighbour_pair_count());
}

void Step(benchmark::State& state, const std::string& world, int threads, double warm_up_s = kWarmUpSeconds) {
  const std::string& warm = WarmState(world, warm_up_s);
  engine::Simulation sim = MakeSimulation(world, threads);
  sim.LoadState(warm);
  TimeSteps(state, sim, warm);
  state.counters["warm_up_s"] = warm_up_s;
}

// Writing one frame of the run file (trajectories, states and every contact,
// one SQLite transaction), as `crowdrecon simulate` does 10 times a simulated
// second; the frames go to a temporary file, one per benchmark.
void FrameWrite(benchmark::State& state, const std::string& world) {
  engine::Simulation sim = MakeSimulation(world, 1);
  sim.LoadState(WarmState(world));
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("crowdrecon-bench-frames-" + world + ".sqlite");
  runfile::RunHeader header;
  header.scenario_json = "{}";
  header.walkable_wkt = CachedWorld(world).walkable_wkt;
  header.time_step_s = sim.time_step_s();
  std::int64_t frame = 0;
  {
    runfile::RunFileWriter writer = scenario::CreateRunFile(file, header, sim, {});
    runfile::FrameSnapshot snapshot;
    scenario::TakeSnapshot(sim, 0, {}, true, &snapshot);
    for (auto _ : state) {
      snapshot.frame = frame++;
      writer.WriteFrame(snapshot);
    }
  }
  std::error_code ec;
  std::filesystem::remove(file, ec);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(sim.bodies().size()));
  state.counters["people"] = static_cast<double>(sim.bodies().size());
  state.counters["contacts"] = static_cast<double>(sim.contacts().size());
}

void RegisterAll() {
  const Vec2 along_x{1.0, 0.0}, along_y{0.0, 1.0};
  const Vec2 diagonal{std::sqrt(0.5), std::sqrt(0.5)};
  const Vec2 staggered{0.5, std::sqrt(0.75)};
  const std::vector<NarrowPhaseCase> cases = {
      // Both facing +x, B beside A: shoulder against shoulder.
      {"touching_side_by_side", 0.0, 0.0, along_y, NarrowPhaseCase::kTouching},
      // Both facing +x, B in front of A: A's chest against B's back.
      {"touching_chest_to_back", 0.0, 0.0, along_x, NarrowPhaseCase::kTouching},
      // Near: 2 cm apart, bounding circles overlapping (so the pair passes the
      // bounding-circle test). Exactly side by side the shoulders are the
      // points farthest from the centres, and 2 cm apart the circles would be
      // too; so B stands beside A half a step ahead (centres along 60 degrees).
      {"near_side_by_side_staggered", 0.0, 0.0, staggered, NarrowPhaseCase::kNear},
      {"near_chest_to_back", 0.0, 0.0, along_x, NarrowPhaseCase::kNear},
      // Turned against each other along a diagonal: rejected by the bounding circles.
      {"far", 0.3, kPi - 0.5, diagonal, NarrowPhaseCase::kFar},
  };
  for (const NarrowPhaseCase& c : cases)
    benchmark::RegisterBenchmark(("NarrowPhase/" + c.name).c_str(), [c](benchmark::State& s) { NarrowPhase(s, c); })
        ->UseRealTime();

  const std::vector<std::string> worlds = {"hallway-400", "box-2000", "box-10000"};
  for (const std::string& w : worlds)
    for (int threads : {1, 2})
      benchmark::RegisterBenchmark(("NeighbourRebuild/" + w + "/threads:" + std::to_string(threads)).c_str(),
                                   [w, threads](benchmark::State& s) { NeighbourRebuild(s, w, threads); })
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  for (const std::string& w : worlds)
    benchmark::RegisterBenchmark(("FrameWrite/" + w).c_str(), [w](benchmark::State& s) { FrameWrite(s, w); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  for (const std::string& w : worlds)
    for (int threads : {1, 2})
      benchmark::RegisterBenchmark(("Step/" + w + "/threads:" + std::to_string(threads)).c_str(),
                                   [w, threads](benchmark::State& s) { Step(s, w, threads); })
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  // A developed crowd: after kDevelopedSeconds of walking, contacts have built
  // up (box-10000: from 1,400 after the placement to about 11,700), and a
  // step costs two to three times as much as just after the placement.
  for (const std::string& w : {std::string("box-2000"), std::string("box-10000")})
    for (int threads : {1, 2})
      benchmark::RegisterBenchmark(("Step/" + w + "/developed/threads:" + std::to_string(threads)).c_str(),
                                   [w, threads](benchmark::State& s) { Step(s, w, threads, kDevelopedSeconds); })
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  // The validated crowd at 5 /m2 (issue 66): its anticipation visiting each
  // pair once against each person's whole list (the same run, bit for bit).
  for (const bool once : {false, true})
    for (int threads : {1, 2})
      benchmark::RegisterBenchmark(("Step/box-2000-validated/pairs:" + std::string(once ? "once" : "whole") +
                                    "/threads:" + std::to_string(threads))
                                       .c_str(),
                                   [once, threads](benchmark::State& s) {
                                     engine::UseHalfPairs(once);
                                     Step(s, "box-2000-validated", threads);
                                     engine::UseHalfPairs(true);
                                   })
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
}

// Writes the worlds of the Step benchmarks, and their states after the
// warm-up, as DIR/<name>.world and DIR/<name>.state, for bench_device on
// machines that cannot build worlds from scenarios (a GPU machine).
void DumpWorlds(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const auto dump = [&](const std::string& world, const std::string& name, double warm_up_s) {
    engine::SaveWorldFile(CachedWorld(world).world, dir / (name + ".world"));
    const std::filesystem::path file = dir / (name + ".state");
    WriteFileAtomically(file, WarmState(world, warm_up_s));
    std::printf("wrote %s and %s\n", (dir / (name + ".world")).c_str(), file.c_str());
  };
  dump("hallway-400", "hallway-400", kWarmUpSeconds);
  dump("box-2000", "box-2000-developed", kDevelopedSeconds);
  dump("box-10000", "box-10000-developed", kDevelopedSeconds);
}

// Writes DIR/<name>.world and DIR/<name>.state from an interrupted run of a
// scenario (its checkpoint: scenario::ReadEngineAtCheckpoint), so that
// bench_device can time a dense moment of a real run, e.g. the evacuation at
// 30 s (`crowdrecon simulate ... --stop-after 30`).
void DumpCheckpoint(const std::filesystem::path& dir, const std::string& spec) {
  const std::size_t a = spec.find(',');
  const std::size_t b = a == std::string::npos ? a : spec.find(',', a + 1);
  if (b == std::string::npos)
    throw std::runtime_error("--dump_run=\"" + spec + "\": expected SCENARIO,RUN.sqlite,NAME");
  const scenario::Scenario sc = scenario::LoadScenario(spec.substr(0, a));
  const scenario::EngineAtCheckpoint saved = scenario::ReadEngineAtCheckpoint(sc, spec.substr(a + 1, b - a - 1), 1);
  const std::string name = spec.substr(b + 1);
  std::filesystem::create_directories(dir);
  engine::SaveWorldFile(saved.world, dir / (name + ".world"));
  const std::filesystem::path file = dir / (name + ".state");
  WriteFileAtomically(file, saved.state);
  std::printf("wrote %s and %s (t = %.3f s, %zu bodies)\n", (dir / (name + ".world")).c_str(), file.c_str(),
              saved.time_s, saved.world.people.size());
}

}  // namespace

}  // namespace crowdrecon::bench

int main(int argc, char** argv) {
  // --dump_worlds=DIR: write the worlds and states (see DumpWorlds), run
  // nothing; with --dump_run=SCENARIO,RUN.sqlite,NAME, that run's checkpoint
  // instead (see DumpCheckpoint).
  std::string dump_run;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]).rfind("--dump_run=", 0) == 0) dump_run = std::string(argv[i]).substr(11);
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]).rfind("--dump_worlds=", 0) == 0) {
      try {
        if (dump_run.empty()) crowdrecon::bench::DumpWorlds(std::string(argv[i]).substr(14));
        else crowdrecon::bench::DumpCheckpoint(std::string(argv[i]).substr(14), dump_run);
        return 0;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "crowdrecon_bench_kernels: %s\n", e.what());
        return 1;
      }
    }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  try {
    crowdrecon::bench::RegisterAll();
    benchmark::RunSpecifiedBenchmarks();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crowdrecon_bench_kernels: %s\n", e.what());
    return 1;
  }
  benchmark::Shutdown();
  return 0;
}
