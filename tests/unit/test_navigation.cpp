// Navigation fields (fast marching accuracy, walking around obstacles) and the
// triangulation used for random placement.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/navigation.hpp"
#include "crowdrecon/geometry/triangulation.hpp"
#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::geometry {
namespace {

const std::filesystem::path kNavigationData = std::filesystem::path(CROWDRECON_SOURCE_DIR) / "tests/data/venues";

Venue Parse(const std::string& json) { return ParseVenue(json, "test.json"); }

TEST(FastMarch, PlaneWaveIsExact) {
  // Sources along the column i = 0: the first-order scheme is exact for a
  // front parallel to a grid axis.
  MarchingGrid grid;
  grid.nx = 50;
  grid.ny = 20;
  grid.spacing_m = 0.1;
  grid.inside.assign(grid.nx * grid.ny, 1);
  std::vector<double> source(grid.nx * grid.ny, kUnreachable);
  for (std::size_t j = 0; j < grid.ny; ++j) source[j * grid.nx] = 0.0;
  const std::vector<double> t = FastMarch(grid, source);
  for (std::size_t j = 0; j < grid.ny; ++j)
    for (std::size_t i = 0; i < grid.nx; ++i) EXPECT_NEAR(t[j * grid.nx + i], 0.1 * static_cast<double>(i), 1e-12);
}

TEST(FastMarch, BlockedLinksStopTheFront) {
  MarchingGrid grid;
  grid.nx = 10;
  grid.ny = 1;
  grid.spacing_m = 1.0;
  grid.inside.assign(10, 1);
  grid.blocked_east.assign(10, 0);
  grid.blocked_north.assign(10, 0);
  grid.blocked_east[4] = 1;  // between nodes 4 and 5
  std::vector<double> source(10, kUnreachable);
  source[0] = 0.0;
  const std::vector<double> t = FastMarch(grid, source);
  EXPECT_DOUBLE_EQ(t[4], 4.0);
  EXPECT_TRUE(std::isinf(t[5]));
}

TEST(Navigation, SeveralExitsLeadToTheNearest) {
  // A 20 m x 4 m corridor with exits across both ends; the target "nearest"
  // names both: its distance is the smaller of the two, and people walk to
  // the nearer end.
  const Venue v = Parse(R"({"version": 1, "walkable_area": [[[0, 0], [20, 0], [20, 4], [0, 4]]],
    "walls": [{"id": "w", "polygon": [[0, 0], [20, 0], [20, 4], [0, 4]]}],
    "exits": [{"id": "west", "segment": [[0, 0], [0, 4]]}, {"id": "east", "segment": [[20, 0], [20, 4]]}],
    "targets": [{"id": "nearest", "exits": ["west", "east"]}]})");
  const NavigationField f = NavigationField::ForTarget(v, "nearest");
  EXPECT_NEAR(f.Distance({3.0, 2.0}), 3.0, 0.05);
  EXPECT_NEAR(f.Distance({16.0, 2.0}), 4.0, 0.05);
  EXPECT_LT(f.Direction({3.0, 2.0}).x, -0.99);
  EXPECT_GT(f.Direction({16.0, 2.0}).x, 0.99);
  // Written back as "exits" and read again the same.
  EXPECT_NE(VenueToJson(v).find("\"exits\": ["), std::string::npos);
  EXPECT_EQ(ParseVenue(VenueToJson(v), "again.json").targets.at(0).exit_ids, (std::vector<std::string>{"west", "east"}));
  // An unknown exit in the list is named with its path.
  try {
    Parse(R"({"version": 1, "walkable_area": [[[0, 0], [20, 0], [20, 4], [0, 4]]],
      "exits": [{"id": "west", "segment": [[0, 0], [0, 4]]}],
      "targets": [{"id": "nearest", "exits": ["west", "north"]}]})");
    ADD_FAILURE() << "an unknown exit was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/targets/0/exits/1"), std::string::npos) << e.what();
  }
}

TEST(Navigation, CorridorDistanceIsExact) {
  const Venue v = Parse(R"({"walkable_area": [[[0, 0], [20, 0], [20, 4], [0, 4]]],
                           "exits": [{"id": "end", "segment": [[20, 0], [20, 4]]}]})");
  const NavigationField f = NavigationField::ToExit(v, "end");
  for (double x : {0.5, 3.0, 10.0, 17.3})
    for (double y : {0.3, 2.0, 3.7}) {
      EXPECT_NEAR(f.Distance({x, y}), 20.0 - x, 1e-9) << x << ", " << y;
      const Vec2 d = f.Direction({x, y});
      EXPECT_NEAR(d.x, 1.0, 1e-9);
      EXPECT_NEAR(d.y, 0.0, 1e-9);
    }
}

TEST(Navigation, SmallDoorDistanceWithinFewPercent) {
  // A 0.2 m door in the middle of the east wall of a 20 m x 20 m hall: the
  // front is round, the hardest case for a first-order scheme.
  const Venue v = Parse(R"({"walkable_area": [[[0, 0], [20, 0], [20, 20], [0, 20]]],
                           "exits": [{"id": "door", "segment": [[20, 9.9], [20, 10.1]]}]})");
  const NavigationField f = NavigationField::ToExit(v, "door");
  double worst = 0.0;
  for (double x = 0.5; x < 18.0; x += 1.1)
    for (double y = 0.5; y < 20.0; y += 1.3) {
      const double exact = DistanceToSegment({x, y}, {20, 9.9}, {20, 10.1});
      worst = std::max(worst, std::abs(f.Distance({x, y}) - exact) / exact);
      const Vec2 d = f.Direction({x, y});
      const Vec2 to_door = Normalized(Vec2{20, std::clamp(y, 9.9, 10.1)} - Vec2{x, y});
      EXPECT_GT(Dot(d, to_door), std::cos(0.1)) << x << ", " << y;  // within about 6 degrees
    }
  EXPECT_LT(worst, 0.03);
}

TEST(Navigation, LShapedCorridorGoesRoundTheCorner) {
  // An L: a 10 m x 2 m arm along x, and a 2 m x 10 m arm up from its east end;
  // the exit is at the top of the vertical arm. From the west end of the
  // horizontal arm the shortest path bends round the inner corner (8, 2).
  const Venue v = Parse(R"({"walkable_area": [[[0, 0], [10, 0], [10, 10], [8, 10], [8, 2], [0, 2]]],
                           "walls": [{"id": "outline", "polygon": [[0, 0], [10, 0], [10, 10], [8, 10], [8, 2], [0, 2]]}],
                           "exits": [{"id": "top", "segment": [[8, 10], [10, 10]]}]})");
  const NavigationField f = NavigationField::ToExit(v, "top");
  const Vec2 corner{8, 2};
  for (Vec2 p : {Vec2{1, 1}, Vec2{3, 0.5}, Vec2{5, 1.5}}) {
    const double exact = Length(corner - p) + 8.0;  // corner to the exit line y = 10
    EXPECT_NEAR(f.Distance(p), exact, 0.03 * exact) << p.x << ", " << p.y;
    // The direction points at the corner, not at the exit through the wall.
    const Vec2 d = f.Direction(p);
    EXPECT_GT(Dot(d, Normalized(corner - p)), std::cos(0.15)) << p.x << ", " << p.y;
  }
  // In the vertical arm people walk straight up.
  EXPECT_NEAR(f.Direction({9, 6}).y, 1.0, 1e-6);
}

TEST(Navigation, WalksAroundTheObstacle) {
  const Venue v = LoadVenue(kNavigationData / "room.json");
  const NavigationField f = NavigationField::ToExit(v, "door");
  // Just west of the pillar the direction turns to pass it, not into it.
  const Vec2 west_of_pillar = f.Direction({4.2, 2.2});
  EXPECT_GT(west_of_pillar.y, 0.5);
  const Vec2 below = f.Direction({4.2, 1.8});
  EXPECT_LT(below.y, -0.5);
  // Geodesic from (1, 2): round a corner of the pillar, then straight on.
  const double exact = std::hypot(3.5, 0.5) + 1.0 + 4.5;
  EXPECT_NEAR(f.Distance({1, 2}), exact, 0.03 * exact);
  EXPECT_GT(f.Distance({1, 2}), 9.0);  // longer than the straight 9 m
}

TEST(Navigation, ThinWallsBlock) {
  // A barrier from the floor to y = 3 at x = 5 in a 10 m x 4 m room: from
  // (4, 0.5) people must go round its tip at (5, 3).
  const Venue v = Parse(R"({"walkable_area": [[[0, 0], [10, 0], [10, 4], [0, 4]]],
                           "walls": [{"id": "barrier", "polyline": [[5, 0], [5, 3]]}],
                           "exits": [{"id": "east", "segment": [[10, 0], [10, 4]]}]})");
  const NavigationField f = NavigationField::ToExit(v, "east");
  const double exact = std::hypot(1.0, 2.5) + 5.0;
  EXPECT_NEAR(f.Distance({4, 0.5}), exact, 0.03 * exact);
  EXPECT_GT(f.Direction({4, 0.5}).y, 0.5);
}

TEST(Navigation, UnreachablePartsAndTargets) {
  const Venue v = ImportWkt(kNavigationData / "two-rooms.wkt");
  Venue with_exit = v;
  with_exit.exits.push_back({"door", {4, 1}, {4, 2}});
  ValidateVenue(with_exit);
  const NavigationField f = NavigationField::ToExit(with_exit, "door");
  EXPECT_TRUE(std::isfinite(f.Distance({2, 1.5})));
  EXPECT_TRUE(std::isinf(f.Distance({6.5, 1.5})));  // the other room
  EXPECT_EQ(f.Direction({6.5, 1.5}), Vec2(0, 0));

  const Venue room = LoadVenue(kNavigationData / "room.json");
  const NavigationField east = NavigationField::ForTarget(room, "east");
  EXPECT_TRUE(east.is_constant());
  EXPECT_EQ(east.Direction({3, 3}), Vec2(1, 0));
  EXPECT_FALSE(NavigationField::ForTarget(room, "leave").is_constant());
  const std::string message = [&] {
    try {
      NavigationField::ForTarget(room, "nowhere");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  }();
  EXPECT_NE(message.find("no target or exit named \"nowhere\"; expected one of \"leave\", \"east\", \"door\""),
            std::string::npos)
      << message;
  NavigationOptions bad;
  bad.grid_spacing_m = 0.0;
  EXPECT_THROW(NavigationField::ToExit(room, "door", bad), InputError);
}

TEST(Triangulation, AreaAndUniformSamples) {
  const Venue v = LoadVenue(kNavigationData / "room.json");
  const AreaTriangulation tri = AreaTriangulation::OfWalkableArea(v);
  EXPECT_NEAR(tri.area_m2(), WalkableArea_m2(v), 1e-9);
  double sum = 0.0;
  for (const Triangle& t : tri.triangles()) {
    EXPECT_GT(t.area_m2(), 0.0);
    sum += t.area_m2();
  }
  EXPECT_NEAR(sum, 39.0, 1e-9);

  std::mt19937_64 rng(42);
  const int n = 20000;
  int in_middle = 0;
  for (int k = 0; k < n; ++k) {
    const Vec2 p = tri.Sample(rng);
    ASSERT_TRUE(IsWalkable(v, p)) << p.x << ", " << p.y;
    if (p.x >= 3 && p.x <= 7) ++in_middle;
  }
  // The strip 3 <= x <= 7 holds 16 - 1 = 15 of the 39 m^2.
  const double expected = 15.0 / 39.0;
  const double sigma = std::sqrt(expected * (1 - expected) / n);
  EXPECT_NEAR(static_cast<double>(in_middle) / n, expected, 4 * sigma);

  // Same seed, same points (the mapping to [0, 1) is our own).
  std::mt19937_64 a(7), b(7);
  for (int k = 0; k < 10; ++k) EXPECT_EQ(tri.Sample(a), tri.Sample(b));
  // The unit cube's corners map into the region.
  EXPECT_TRUE(IsWalkable(v, tri.Sample(0.0, 0.0, 0.0)));
  EXPECT_TRUE(IsWalkable(v, tri.Sample(0.999999, 0.999999, 0.999999)));
}

TEST(Triangulation, EntryZoneExcludesObstaclesInside) {
  const Venue v = Parse(R"({"walkable_area": [[[0, 0], [10, 0], [10, 4], [0, 4]]],
                           "obstacles": [{"id": "p", "polygon": [[1, 1], [2, 1], [2, 2], [1, 2]]}],
                           "entries": [{"id": "west", "polygon": [[0, 0], [3, 0], [3, 4], [0, 4]]},
                                       {"id": "east", "polygon": [[7, 0], [10, 0], [10, 4], [7, 4]]}]})");
  EXPECT_NEAR(AreaTriangulation::OfEntryZone(v, 0).area_m2(), 11.0, 1e-9);
  EXPECT_NEAR(AreaTriangulation::OfEntryZone(v, 1).area_m2(), 12.0, 1e-9);
  const AreaTriangulation west = AreaTriangulation::OfEntryZone(v, 0);
  std::mt19937_64 rng(1);
  for (int k = 0; k < 1000; ++k) {
    const Vec2 p = west.Sample(rng);
    EXPECT_TRUE(IsWalkable(v, p));
    EXPECT_LE(p.x, 3.0);
  }
}

TEST(Navigation, MadridArenaGroundFloor) {
  const Venue v = LoadVenue(std::filesystem::path(CROWDRECON_SOURCE_DIR) / "venues/madrid-arena/ground-floor.json");
  const NavigationField f = NavigationField::ToExit(v, "main_exit");
  // From the far north-east corner to the main exit's east end (30, 0).
  const double exact = DistanceToSegment({54.9, 34.9}, {25, 0}, {30, 0});
  EXPECT_NEAR(f.Distance({54.9, 34.9}), exact, 0.02 * exact);
}

TEST(Navigation, CachedDirectionIsDirectionBitForBit) {
  // Walks that stay in a cell, cross cells, pass beside the pillar (cells
  // with unreachable nodes), leave the grid and switch between two fields
  // with one cache: the cached direction is the direction, bit for bit.
  const Venue v = LoadVenue(kNavigationData / "room.json");
  NavigationOptions coarse;
  coarse.grid_spacing_m = 0.15;
  const NavigationField fields[2] = {NavigationField::ToExit(v, "door"), NavigationField::ToExit(v, "door", coarse)};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> start(-0.5, 10.5), step(-0.03, 0.03);
  NavigationField::CellCache cache;
  for (int walk = 0; walk < 200; ++walk) {
    Vec2 p{start(rng), start(rng) * 0.5};
    for (int k = 0; k < 50; ++k) {
      const NavigationField& f = fields[(walk + k / 25) % 2];
      const Vec2 plain = f.Direction(p), cached = f.Direction(p, cache);
      ASSERT_EQ(plain.x, cached.x) << p.x << ", " << p.y;
      ASSERT_EQ(plain.y, cached.y) << p.x << ", " << p.y;
      p += Vec2{step(rng), step(rng)};
    }
  }
  EXPECT_TRUE(cache.field == &fields[0] || cache.field == &fields[1]);
}

}  // namespace
}  // namespace crowdrecon::geometry
