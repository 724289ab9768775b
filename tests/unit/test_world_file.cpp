// World files (engine/include/crowdrecon/engine/world_file.hpp): a world with
// every kind of content survives a round trip byte for byte, runs bit for bit
// like the original, and damaged data is refused with the file's name.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/world_file.hpp"
#include "engine_scenes.hpp"

namespace crowdrecon::engine {
namespace {

using geometry::NavigationField;
using testing::DiskShape;
using testing::RandomGas;
using testing::SetMassFromShape;

// A navigation grid toward the line x = 3 m over [-1, 3.75] x [-1, 2.75]:
// distances 3 - x, directions +x, with a block of unreachable nodes
// (+infinity, no direction) in one corner.
NavigationField GridTowardLine() {
  const Vec2 origin{-1.0, -1.0};
  const double h = 0.25;
  const std::size_t nx = 20, ny = 16;
  std::vector<double> distance(nx * ny);
  std::vector<Vec2> direction(nx * ny);
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i) {
      const std::size_t k = j * nx + i;
      const double x = origin.x + static_cast<double>(i) * h;
      if (i < 2 && j < 2) {
        distance[k] = geometry::kUnreachable;
      } else {
        distance[k] = std::abs(3.0 - x);
        direction[k] = Normalized(Vec2{3.0 - x, 0.1});
      }
    }
  return NavigationField::FromGrid(origin, h, nx, ny, std::move(distance), std::move(direction));
}

// A world with every kind of content: two shapes, people in every state with
// varied masses, speeds, targets and groups, two walls, a constant target (in
// a direction whose normalisation is not exact) and a grid target, a box
// periodic in x, a slope, and parameters and enums away from their defaults.
WorldDef EveryKindOfWorld() {
  WorldDef def = RandomGas(5, 0.45, 3, true);
  const double side = 5 * 0.45;
  def.periodic.y = false;
  def.shapes.push_back(DiskShape(0.18));
  for (std::size_t i = 0; i < def.people.size(); ++i) {
    PersonDef& p = def.people[i];
    if (i % 7 == 3) {
      p.shape = 1;
      SetMassFromShape(def.shapes[1], 1000.0, p);
    }
    p.desired_speed_m_per_s = 0.8 + 0.02 * static_cast<double>(i);
    p.target = static_cast<std::uint32_t>(i % 2);
    p.group = static_cast<std::uint32_t>(i % 3);
  }
  def.people[4].state = PersonState::kFallen;
  def.people[9].state = PersonState::kRemoved;
  // A floor and a ceiling that the lowest and the highest person already
  // touch (2 mm and 1 mm deep), so that there are wall contacts from the start.
  double lowest = side, highest = 0.0;
  for (const PersonDef& p : def.people)
    for (const Vec2& v : def.shapes[p.shape].vertices) {
      const double y = (p.position_m + Rotated(v, p.angle_rad)).y;
      lowest = std::min(lowest, y - def.shapes[p.shape].radius_m);
      highest = std::max(highest, y + def.shapes[p.shape].radius_m);
    }
  Wall floor;
  floor.points = {{-1.0, lowest - 0.018}, {1.0, lowest - 0.018}, {side + 1.0, lowest - 0.018}};
  floor.radius_m = 0.02;
  Wall ceiling;
  ceiling.points = {{-1.0, highest - 0.001}, {side + 1.0, highest - 0.001}};
  ceiling.radius_m = 0.0;
  def.walls = {floor, ceiling};
  def.targets = {NavigationField::Constant({1.0, 1.0}), GridTowardLine()};
  def.slope.downhill = Normalized(Vec2{1.0, 0.3});
  def.slope.gradient = 0.025;
  def.slope.region = {{0.5, 0.0}, {3.0, 0.0}, {3.0, 2.0}, {0.5, 2.0}};
  def.threads = 2;

  ModelParameters& m = def.parameters;
  m.ground_reaction = true;
  m.friction_coefficient = 0.5;
  m.restitution = 0.35;
  m.wall_restitution = 0.3;
  m.tangential_damping = TangentialDamping::kFixed;
  m.tangential_damping_rate_per_s = 3.0;
  m.allow_tensile_normal_force = false;
  m.relaxation_time_s = 0.5;
  m.back_force_gamma = 1.1;
  m.torsion_stiffness_lambda = 20.0;
  m.rotation_relaxation_time_s = 0.4;
  m.facing_target = FacingTarget::kDesiredDirection;
  m.integrator = Integrator::kGear5;
  m.time_step_safety = 0.07;
  return def;
}

template <typename T>
bool SameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool SameBits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }
bool SameBits(Vec2 a, Vec2 b) { return SameBits(a.x, b.x) && SameBits(a.y, b.y); }

// FNV-1a over everything but the last 8 bytes, written there: damaged data
// that still passes the checksum, to reach the checks behind it.
std::string Resealed(std::string data) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i + 8 < data.size(); ++i) h = (h ^ static_cast<unsigned char>(data[i])) * 1099511628211ull;
  std::memcpy(data.data() + data.size() - 8, &h, 8);
  return data;
}

// The message of the InputError that LoadWorld throws ("" if none).
std::string LoadError(const std::string& data, const std::string& origin) {
  try {
    LoadWorld(data, origin);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(WorldFile, RoundTripGivesTheSameBytes) {
  const WorldDef def = EveryKindOfWorld();
  const std::string bytes = SaveWorld(def);
  ASSERT_EQ(bytes.substr(0, 8), "CRWORLDF");
  const WorldDef loaded = LoadWorld(bytes, "memory");
  EXPECT_EQ(SaveWorld(loaded), bytes);

  // And the contents are those of the original (spot checks of each part).
  EXPECT_EQ(loaded.parameters.integrator, Integrator::kGear5);
  EXPECT_EQ(loaded.parameters.facing_target, FacingTarget::kDesiredDirection);
  EXPECT_EQ(loaded.parameters.tangential_damping, TangentialDamping::kFixed);
  EXPECT_FALSE(loaded.parameters.allow_tensile_normal_force);
  EXPECT_TRUE(SameBits(loaded.parameters.time_step_safety, 0.07));
  ASSERT_EQ(loaded.shapes.size(), 2u);
  EXPECT_TRUE(SameBits(loaded.shapes[0].vertices, def.shapes[0].vertices));
  ASSERT_EQ(loaded.people.size(), def.people.size());
  EXPECT_EQ(loaded.people[4].state, PersonState::kFallen);
  EXPECT_EQ(loaded.people[9].state, PersonState::kRemoved);
  EXPECT_EQ(loaded.people[3].shape, 1u);
  EXPECT_EQ(loaded.people[5].group, 2u);
  EXPECT_TRUE(SameBits(loaded.people[7].position_m, def.people[7].position_m));
  ASSERT_EQ(loaded.walls.size(), 2u);
  EXPECT_TRUE(SameBits(loaded.walls[0].points, def.walls[0].points));
  EXPECT_TRUE(SameBits(loaded.walls[0].radius_m, 0.02));
  ASSERT_EQ(loaded.targets.size(), 2u);
  EXPECT_TRUE(loaded.targets[0].is_constant());
  EXPECT_TRUE(SameBits(loaded.targets[0].constant_direction(), def.targets[0].constant_direction()));
  EXPECT_FALSE(loaded.targets[1].is_constant());
  EXPECT_EQ(loaded.targets[1].nx(), 20u);
  EXPECT_EQ(loaded.targets[1].ny(), 16u);
  EXPECT_TRUE(SameBits(loaded.targets[1].distance_m(), def.targets[1].distance_m()));
  EXPECT_TRUE(SameBits(loaded.targets[1].direction(), def.targets[1].direction()));
  EXPECT_TRUE(std::isinf(loaded.targets[1].distance_m()[0]));
  EXPECT_TRUE(loaded.periodic.x);
  EXPECT_FALSE(loaded.periodic.y);
  EXPECT_TRUE(SameBits(loaded.periodic.max_m, def.periodic.max_m));
  EXPECT_TRUE(SameBits(loaded.slope.downhill, def.slope.downhill));
  ASSERT_EQ(loaded.slope.region.size(), def.slope.region.size());
  for (std::size_t k = 0; k < def.slope.region.size(); ++k) EXPECT_TRUE(SameBits(loaded.slope.region[k], def.slope.region[k]));
  EXPECT_EQ(loaded.threads, 2);
  EXPECT_EQ(loaded.device, ComputeDevice::kCpu);
  WorldDef on_cuda = def;
  on_cuda.device = ComputeDevice::kCuda;
  EXPECT_EQ(LoadWorld(SaveWorld(on_cuda), "memory").device, ComputeDevice::kCuda);

  // An empty world too.
  EXPECT_EQ(SaveWorld(LoadWorld(SaveWorld(WorldDef{}), "memory")), SaveWorld(WorldDef{}));
}

TEST(WorldFile, SimulationOfTheLoadedWorldIsBitIdentical) {
  const WorldDef def = EveryKindOfWorld();
  Simulation original(def);
  Simulation loaded(LoadWorld(SaveWorld(def), "memory"));
  ASSERT_TRUE(SameBits(original.time_step_s(), loaded.time_step_s()));
  std::size_t wall_contacts = 0;
  for (int step = 0; step < 200; ++step) {
    original.Step();
    loaded.Step();
    for (const Contact& c : original.contacts()) wall_contacts += c.wall ? 1 : 0;
  }
  const BodyState& a = original.bodies();
  const BodyState& b = loaded.bodies();
  EXPECT_TRUE(SameBits(a.position_m, b.position_m));
  EXPECT_TRUE(SameBits(a.angle_rad, b.angle_rad));
  EXPECT_TRUE(SameBits(a.velocity_m_per_s, b.velocity_m_per_s));
  EXPECT_TRUE(SameBits(a.angular_velocity_rad_per_s, b.angular_velocity_rad_per_s));
  EXPECT_TRUE(SameBits(a.force_n, b.force_n));
  // Contacts field by field (the struct has padding, whose bytes mean nothing).
  const auto& ca = original.contacts();
  const auto& cb = loaded.contacts();
  ASSERT_EQ(ca.size(), cb.size());
  EXPECT_GT(ca.size(), 0u);
  for (std::size_t k = 0; k < ca.size(); ++k) {
    SCOPED_TRACE("contact " + std::to_string(k));
    EXPECT_EQ(ca[k].a, cb[k].a);
    EXPECT_EQ(ca[k].b, cb[k].b);
    EXPECT_EQ(ca[k].wall, cb[k].wall);
    EXPECT_EQ(ca[k].feature, cb[k].feature);
    EXPECT_TRUE(SameBits(ca[k].point_m, cb[k].point_m));
    EXPECT_TRUE(SameBits(ca[k].normal, cb[k].normal));
    EXPECT_TRUE(SameBits(ca[k].overlap_m, cb[k].overlap_m));
    EXPECT_TRUE(SameBits(ca[k].normal_force_n, cb[k].normal_force_n));
    EXPECT_TRUE(SameBits(ca[k].tangential_force_n, cb[k].tangential_force_n));
    EXPECT_TRUE(SameBits(ca[k].tangential_spring_m, cb[k].tangential_spring_m));
  }
  // The scene does what it is for: people pressed against the walls too.
  EXPECT_GT(wall_contacts, 0u);
}

TEST(WorldFile, FileRoundTripLeavesNoPartialFile) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "crowdrecon-test-world-file";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / "world.crworld";
  const WorldDef def = EveryKindOfWorld();
  SaveWorldFile(def, path);
  SaveWorldFile(def, path);  // over an existing file
  EXPECT_EQ(SaveWorld(LoadWorldFile(path)), SaveWorld(def));
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1u);

  // A file that is missing, or a place that cannot be written, is named.
  try {
    LoadWorldFile(dir / "nope.crworld");
    ADD_FAILURE() << "no error for a missing file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nope.crworld: cannot open world file"), std::string::npos) << e.what();
  }
  try {
    SaveWorldFile(def, dir / "no-such-dir" / "w.crworld");
    ADD_FAILURE() << "no error for an unwritable path";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("w.crworld: cannot write world file"), std::string::npos) << e.what();
  }
  // A damaged file's errors begin with its name.
  {
    std::string bytes = SaveWorld(def);
    bytes[bytes.size() / 2] ^= 0x10;
    std::ofstream(dir / "damaged.crworld", std::ios::binary) << bytes;
  }
  try {
    LoadWorldFile(dir / "damaged.crworld");
    ADD_FAILURE() << "no error for a damaged file";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind((dir / "damaged.crworld").string() + ": world file: checksum mismatch", 0), 0u)
        << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(WorldFile, DamagedDataIsRefusedWithItsOrigin) {
  const std::string good = SaveWorld(EveryKindOfWorld());
  const std::string origin = "runs/w17.crworld";
  auto refused = [&](const std::string& data, const std::string& expected) {
    const std::string message = LoadError(data, origin);
    EXPECT_EQ(message.rfind(origin + ": world file: ", 0), 0u) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  };

  // A flipped bit anywhere: the checksum.
  for (std::size_t at : {std::size_t{9}, good.size() / 3, good.size() - 9, good.size() - 1}) {
    std::string flipped = good;
    flipped[at] ^= 0x04;
    refused(flipped, "checksum mismatch");
  }
  // Cut short: the checksum too, or the magic when too little is left.
  refused(good.substr(0, good.size() - 100), "checksum mismatch");
  refused(good.substr(0, 10), "bad magic");
  refused("", "bad magic");
  // Another file: wrong magic (a checkpoint is not a world).
  std::string other = good;
  other[2] = 'X';
  refused(other, "not a crowdrecon engine world (bad magic)");
  Simulation simulation(EveryKindOfWorld());
  refused(simulation.SaveState(), "bad magic");

  // Cut short with a valid checksum (a writer that stopped early): truncation.
  refused(Resealed(good.substr(0, good.size() / 2) + std::string(8, '\0')), "truncated world");
  // Bytes after the world.
  refused(Resealed(good.substr(0, good.size() - 8) + std::string(3, '\0') + std::string(8, '\0')),
          "3 bytes after the world");

  // Offsets in the format (world_file.hpp): the magic (8), then the
  // parameters (the parameter table's order): 5 doubles, tangential_damping,
  // a double, tangential_spring, 2 flags, 2 doubles (tau, Gamma),
  // back_force_trigger, 3 doubles, facing_target, a double (g),
  // slope_response, integrator, 2 doubles, time_step_mode, 2 doubles,
  // gait_jitter, 4 doubles, yielding, 2 doubles, shoulder_turn, a double,
  // give_way, 4 doubles, drive_reaction, a double, headway, 4 doubles,
  // social_force, 3 doubles, centrifugal, 8 doubles, anticipation, 6
  // doubles, 3 doubles (sleeping), 1 double (side preference), its gate (a choice); then the shape count.
  const std::size_t integrator_at = 8 + 5 * 8 + 1 + 8 + 1 + 2 + 2 * 8 + 1 + 3 * 8 + 1 + 1 * 8 + 1;
  const std::size_t shape_count_at =
      integrator_at + 1 + 2 * 8 + 1 + 2 * 8 + 1 + 4 * 8 + 1 + 2 * 8 + 1 + 8 + 1 + 4 * 8 + 1 + 8 + 1 + 4 * 8 + 1 + 3 * 8 + 1 + 8 * 8 + 1 + 6 * 8 + 3 * 8 + 8 + 1;
  ASSERT_EQ(static_cast<unsigned char>(good[integrator_at]), static_cast<unsigned>(Integrator::kGear5));
  std::string bad_enum = good;
  bad_enum[integrator_at] = 7;
  refused(Resealed(bad_enum), "parameters: integrator = 7; expected 0 to 1");

  // An absurd count is refused before anything is allocated.
  std::string huge = good;
  const std::uint64_t count = std::uint64_t{1} << 60;
  std::memcpy(huge.data() + shape_count_at, &count, 8);
  refused(Resealed(huge), "truncated world");
  std::string most = good;
  const std::uint64_t all = std::numeric_limits<std::uint64_t>::max();
  std::memcpy(most.data() + shape_count_at, &all, 8);
  refused(Resealed(most), "truncated world");
}

TEST(WorldFile, InvalidNavigationGridIsRefused) {
  // A grid field read back is validated like one made by FromGrid, and the
  // message says which target.
  WorldDef def;
  def.targets = {NavigationField::Constant({0.0, 1.0}), GridTowardLine()};
  std::string bytes = SaveWorld(def);
  // The spacing of the grid (0.25) is the only double of that value after the
  // parameters (whose last are anticipation's six numbers): make it negative.
  const double last_parameters[6] = {1.5, 3.0, 5.0, 5.0, 0.0, 0.0};
  const std::size_t parameters_end = bytes.find(std::string(reinterpret_cast<const char*>(last_parameters), 48));
  ASSERT_NE(parameters_end, std::string::npos);
  const double spacing = 0.25;
  const std::size_t at = bytes.find(std::string(reinterpret_cast<const char*>(&spacing), 8), parameters_end + 48);
  ASSERT_NE(at, std::string::npos);
  const double negative = -0.25;
  std::memcpy(bytes.data() + at, &negative, 8);
  const std::string message = LoadError(Resealed(bytes), "w.crworld");
  EXPECT_EQ(message.rfind("w.crworld: world file: target 1: navigation field: grid spacing -0.25 m", 0), 0u) << message;
}

TEST(NavigationFieldFromGrid, SamplesTheGridItWasGiven) {
  const NavigationField f = GridTowardLine();
  EXPECT_FALSE(f.is_constant());
  const Vec2 d = f.Direction({1.0, 1.0});
  EXPECT_NEAR(d.x, Normalized(Vec2{2.0, 0.1}).x, 1e-3);
  EXPECT_NEAR(f.Distance({1.0, 1.0}), 2.0, 1e-12);
  // Unreachable corner.
  EXPECT_TRUE(std::isinf(f.Distance({-0.9, -0.9})));
}

TEST(NavigationFieldFromGrid, WrongGridsThrow) {
  const Vec2 o{0.0, 0.0};
  auto grid = [](std::size_t n) { return std::vector<double>(n, 1.0); };
  auto dirs = [](std::size_t n) { return std::vector<Vec2>(n, Vec2{1.0, 0.0}); };
  EXPECT_NO_THROW(NavigationField::FromGrid(o, 0.1, 3, 2, grid(6), dirs(6)));
  // Sizes that do not match nx * ny.
  EXPECT_THROW(NavigationField::FromGrid(o, 0.1, 3, 2, grid(5), dirs(6)), InputError);
  EXPECT_THROW(NavigationField::FromGrid(o, 0.1, 3, 2, grid(6), dirs(7)), InputError);
  // Too few nodes to interpolate in a cell.
  EXPECT_THROW(NavigationField::FromGrid(o, 0.1, 1, 6, grid(6), dirs(6)), InputError);
  EXPECT_THROW(NavigationField::FromGrid(o, 0.1, 0, 0, grid(0), dirs(0)), InputError);
  // nx * ny overflows.
  const std::size_t big = std::size_t{1} << 40;
  EXPECT_THROW(NavigationField::FromGrid(o, 0.1, big, big, grid(6), dirs(6)), InputError);
  // Spacing, origin and values.
  EXPECT_THROW(NavigationField::FromGrid(o, 0.0, 3, 2, grid(6), dirs(6)), InputError);
  EXPECT_THROW(NavigationField::FromGrid(o, std::nan(""), 3, 2, grid(6), dirs(6)), InputError);
  EXPECT_THROW(NavigationField::FromGrid({std::nan(""), 0.0}, 0.1, 3, 2, grid(6), dirs(6)), InputError);
  auto with = [&](double value) {
    auto g = grid(6);
    g[4] = value;
    return g;
  };
  EXPECT_THROW(NavigationField::FromGrid(o, 0.1, 3, 2, with(std::nan("")), dirs(6)), InputError);
  EXPECT_THROW(NavigationField::FromGrid(o, 0.1, 3, 2, with(-1.0), dirs(6)), InputError);
  EXPECT_NO_THROW(NavigationField::FromGrid(o, 0.1, 3, 2, with(geometry::kUnreachable), dirs(6)));
  try {
    NavigationField::FromGrid(o, 0.1, 3, 2, grid(5), dirs(6));
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "navigation field: grid of 3 x 2 nodes has 5 distances and 6 directions; expected 6 of each");
  }
  // A constant direction kept exactly must be a direction.
  EXPECT_THROW(NavigationField::ConstantExact({2.0, 0.0}), InputError);
  EXPECT_NO_THROW(NavigationField::ConstantExact({0.0, 0.0}));
  const Vec2 unit = Normalized(Vec2{1.0, 1.0});
  EXPECT_TRUE(SameBits(NavigationField::ConstantExact(unit).Direction({5.0, 5.0}), unit));
}

}  // namespace
}  // namespace crowdrecon::engine
