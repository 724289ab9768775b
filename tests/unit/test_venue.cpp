// Venue files: parsing, writing, derived quantities and validation errors.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <filesystem>
#include <limits>
#include <numbers>
#include <ostream>
#include <string>

#include "test_util.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::geometry {
namespace {

using testing_util::ErrorOf;

const std::filesystem::path kData = std::filesystem::path(CROWDRECON_SOURCE_DIR) / "tests/data/venues";
const std::filesystem::path kVenues = std::filesystem::path(CROWDRECON_SOURCE_DIR) / "venues/madrid-arena";

constexpr const char* kRoom = R"("walkable_area": [[[0, 0], [10, 0], [10, 4], [0, 4]]])";

std::string ParseError(const std::string& body) {
  return ErrorOf([&] { ParseVenue("{" + body + "}", "test.json"); });
}

TEST(Venue, LoadsTheTestRoom) {
  const Venue v = LoadVenue(kData / "room.json");
  EXPECT_EQ(v.metadata.name, "test room");
  EXPECT_DOUBLE_EQ(WalkableArea_m2(v), 39.0);
  EXPECT_DOUBLE_EQ(WalkablePerimeter_m(v), 32.0);
  ASSERT_EQ(v.exits.size(), 1u);
  EXPECT_DOUBLE_EQ(v.exits[0].width_m(), 1.0);
  ASSERT_EQ(v.targets.size(), 2u);
  EXPECT_EQ(v.targets[0].kind, Target::Kind::kExit);
  EXPECT_EQ(v.targets[1].kind, Target::Kind::kDirection);
  ASSERT_TRUE(v.slope.has_value());
  EXPECT_TRUE(v.slope->enabled);
  EXPECT_DOUBLE_EQ(v.slope->gradient, 0.02);
  EXPECT_TRUE(IsWalkable(v, {1, 1}));
  EXPECT_FALSE(IsWalkable(v, {5, 2}));   // inside the pillar
  EXPECT_TRUE(IsWalkable(v, {4.5, 2}));  // on the pillar's face
  EXPECT_FALSE(IsWalkable(v, {11, 2}));
  // Every exit is also a target of its own name.
  ASSERT_TRUE(v.FindTarget("door").has_value());
  EXPECT_EQ(v.FindTarget("door")->kind, Target::Kind::kExit);
  EXPECT_FALSE(v.FindTarget("nowhere").has_value());
}

TEST(Venue, WallSegmentsHaveExitOpenings) {
  const Venue v = LoadVenue(kData / "room.json");
  // The outline polygon crosses the door at x = 10, y in [1.5, 2.5]: that part
  // is cut out; the pillar adds its four edges.
  double length = 0.0;
  for (const WallSegment& s : WallSegments(v)) {
    length += Length(s.b - s.a);
    const bool on_door = std::abs(s.a.x - 10) < 1e-12 && std::abs(s.b.x - 10) < 1e-12 &&
                         std::min(s.a.y, s.b.y) < 2.5 - 1e-9 && std::max(s.a.y, s.b.y) > 1.5 + 1e-9;
    EXPECT_FALSE(on_door) << "wall segment across the door";
  }
  EXPECT_NEAR(length, 28.0 - 1.0 + 4.0, 1e-12);
}

TEST(Venue, JsonRoundTrip) {
  const Venue v = LoadVenue(kData / "room.json");
  const Venue w = ParseVenue(VenueToJson(v), "roundtrip.json");
  EXPECT_EQ(VenueToJson(w), VenueToJson(v));
  EXPECT_EQ(w.walkable_area, v.walkable_area);
  EXPECT_EQ(w.obstacles[0].polygon, v.obstacles[0].polygon);
  EXPECT_EQ(w.targets[1].direction, v.targets[1].direction);
}

TEST(Venue, ScaleAndClosingVertex) {
  // Centimetres, with the ring closed WKT-style (first vertex repeated).
  const Venue v = ParseVenue(R"({"metadata": {"name": "cm", "scale_m_per_unit": 0.01},
      "walkable_area": [[[0, 0], [300, 0], [300, 1200], [0, 1200], [0, 0]]],
      "periodic": [{"direction": [0, 2], "period_m": 12}]})",
                             "cm.json");
  EXPECT_EQ(v.walkable_area[0].size(), 4u);
  EXPECT_NEAR(WalkableArea_m2(v), 36.0, 1e-9);
  EXPECT_EQ(v.periodic[0].direction, Vec2(0, 1));  // normalised
}

TEST(Venue, MadridArenaVenuesLoad) {
  const Venue periodic = LoadVenue(kVenues / "hallway-periodic.json");
  EXPECT_DOUBLE_EQ(WalkableArea_m2(periodic), 36.0);
  ASSERT_EQ(periodic.periodic.size(), 1u);
  EXPECT_DOUBLE_EQ(periodic.periodic[0].period_m, 12.0);
  ASSERT_TRUE(periodic.slope.has_value());
  EXPECT_FALSE(periodic.slope->enabled);
  EXPECT_DOUBLE_EQ(periodic.slope->gradient * 12.0, 0.30);  // 30 cm over 12 m
  EXPECT_TRUE(periodic.FindTarget("to_exit").has_value());
  EXPECT_TRUE(periodic.FindTarget("to_court").has_value());

  const Venue open = LoadVenue(kVenues / "hallway-open.json");
  EXPECT_EQ(open.exits.size(), 2u);
  EXPECT_EQ(open.entries.size(), 2u);
  EXPECT_TRUE(open.periodic.empty());

  const Venue floor = LoadVenue(kVenues / "ground-floor.json");
  EXPECT_DOUBLE_EQ(WalkableArea_m2(floor), 55.0 * 35.0);
  // The paper's 7,700 people on the ground floor at "four people per m2".
  EXPECT_NEAR(7700.0 / WalkableArea_m2(floor), 4.0, 1e-12);
  ASSERT_NE(floor.FindExit("hallway"), nullptr);
  // The hallway entrance: 3 m between the faces of its 0.15 m jambs.
  EXPECT_NEAR(floor.FindExit("hallway")->width_m(), 3.3, 1e-12);
  EXPECT_NEAR(floor.FreeWidth_m(*floor.FindExit("hallway")), 3.0, 1e-12);
}

// --- invalid inputs: each error names the file, the JSON path and the problem.

struct BadFile {
  const char* file;
  const char* expected;  // substrings, '|' separated
};

// Test names and failure messages show the file, not the struct's bytes.
void PrintTo(const BadFile& bad, std::ostream* os) { *os << bad.file; }

class InvalidVenueFile : public ::testing::TestWithParam<BadFile> {};

TEST_P(InvalidVenueFile, ErrorNamesFilePathAndProblem) {
  const BadFile& bad = GetParam();
  const std::string message = ErrorOf([&] { LoadVenue(kData / bad.file); });
  ASSERT_FALSE(message.empty()) << bad.file << " was accepted";
  EXPECT_NE(message.find(bad.file), std::string::npos) << message;
  std::string expected = bad.expected;
  std::size_t start = 0;
  while (start <= expected.size()) {
    const std::size_t bar = expected.find('|', start);
    const std::string part = expected.substr(start, bar == std::string::npos ? std::string::npos : bar - start);
    EXPECT_NE(message.find(part), std::string::npos) << "expected \"" << part << "\" in: " << message;
    if (bar == std::string::npos) break;
    start = bar + 1;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Venue, InvalidVenueFile,
    ::testing::Values(
        BadFile{"bad-self-intersecting.json", "/walkable_area/0: outer ring is self-intersecting|cross at (2, 2)"},
        BadFile{"bad-obstacle-outside.json", "/obstacles/0/polygon: obstacle \"kiosk\"|lies outside the walkable area"},
        BadFile{"bad-overlapping-obstacles.json", "/obstacles/1/polygon|\"bar\"|\"stage\"|overlap"},
        BadFile{"bad-obstacle-crosses-boundary.json", "/obstacles/0/polygon|meets the boundary|(10, 1)"},
        BadFile{"bad-exit-outside.json", "/exits/1/segment: exit point (30, 0) is 20 m outside the walkable area"},
        BadFile{"bad-unknown-key.json", "unknown key(s) \"exitz\""},
        BadFile{"bad-wrong-type.json", "/periodic/0/period_m: expected a number|found \"ten\""},
        BadFile{"bad-gradient.json", "/slope/gradient: value -0.025 is out of range; expected a number in [0, 1]"},
        BadFile{"bad-empty-area.json", "/walkable_area: the walkable area is empty"},
        BadFile{"bad-syntax.json", "bad-syntax.json:3:|invalid JSON"},
        BadFile{"bad-target.json", "/targets/0/exit|exit \"main\", which does not exist|\"door\""},
        BadFile{"bad-period.json", "/periodic/0/period_m: period 12 m differs|10 m"},
        BadFile{"bad-duplicate-id.json", "/exits/1/id: id \"door\" is used twice"},
        BadFile{"bad-zero-direction.json", "/targets/0/direction|zero length"}),
    [](const ::testing::TestParamInfo<BadFile>& param_info) {
      std::string name = std::filesystem::path(param_info.param.file).stem().string();
      for (char& c : name)
        if (c == '-') c = '_';
      return name;
    });

// The Itaewon alley (issue 43): its floor slopes inside the alley only (a
// region), 8 degrees down toward the station; the region survives a round
// trip; a region of two points is refused by its JSON path.
TEST(Venue, TheItaewonAlleySlopesInsideItsRegion) {
  const Venue v = LoadVenue(std::filesystem::path(CROWDRECON_SOURCE_DIR) / "venues/itaewon/alley.json");
  ASSERT_TRUE(v.slope.has_value());
  EXPECT_TRUE(v.slope->enabled);
  EXPECT_NEAR(std::atan(v.slope->gradient) * 180.0 / std::numbers::pi, 8.0, 0.01);
  EXPECT_EQ(v.slope->direction, (Vec2{0.0, -1.0}));
  ASSERT_EQ(v.slope->region.size(), 4u);
  const Venue w = ParseVenue(VenueToJson(v), "roundtrip.json");
  ASSERT_TRUE(w.slope.has_value());
  EXPECT_EQ(w.slope->region, v.slope->region);
  EXPECT_NE(ParseError(std::string(kRoom) + R"(, "slope": {"direction": [1, 0], "gradient": 0.1, "region": [[0, 0], [1, 0]]})")
                .find("/slope/region"),
            std::string::npos);
  // A direction whose length overflows or underflows is still its direction
  // (issue 65: [1e308, 1e308] was read as (0, 0), a slope that pulled nowhere).
  for (const auto& [text, expected] : {std::pair{"[1e308, 1e308]", Vec2{std::sqrt(0.5), std::sqrt(0.5)}},
                                       std::pair{"[1e200, -1e200]", Vec2{std::sqrt(0.5), -std::sqrt(0.5)}},
                                       std::pair{"[0, 1e-300]", Vec2{0.0, 1.0}}}) {
    const Venue t = ParseVenue("{" + std::string(kRoom) + R"(, "slope": {"direction": )" + text + R"(, "gradient": 0.1}})",
                               "tilted.json");
    EXPECT_NEAR(t.slope->direction.x, expected.x, 1e-15) << text;
    EXPECT_NEAR(t.slope->direction.y, expected.y, 1e-15) << text;
  }
}

// The Itaewon alley's building fronts are walls with a thickness drawn outside
// the walkable area (issue 43: a line of radius 0 let a body's core through at
// 4.3 kN): every wall's face lies on the walkable edge, so the free widths are
// the drawn ones. Points along the edge (exits excepted) are one radius from
// the nearest wall line (near the buildings' corners, no nearer and at most
// the rounded corner's gap further); no walkable point is nearer than that.
TEST(Venue, TheItaewonWallFacesLieOnTheWalkableEdge) {
  const Venue v = LoadVenue(std::filesystem::path(CROWDRECON_SOURCE_DIR) / "venues/itaewon/alley.json");
  const std::vector<WallSegment> walls = WallSegments(v);
  ASSERT_FALSE(walls.empty());
  const auto clearance = [&](Vec2 p) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const WallSegment& w : walls) nearest = std::min(nearest, DistanceToSegment(p, w.a, w.b) - w.radius_m);
    return nearest;
  };
  const auto on_exit = [&](Vec2 p) {
    for (const Exit& e : v.exits)
      if (DistanceToSegment(p, e.a, e.b) < 1e-6) return true;
    return false;
  };
  for (const WallSegment& w : walls) EXPECT_DOUBLE_EQ(w.radius_m, 0.15);
  const Ring& edge = v.walkable_area.at(0);
  int checked = 0;
  for (std::size_t i = 0; i < edge.size(); ++i) {
    const Vec2 a = edge[i], b = edge[(i + 1) % edge.size()];
    for (int k = 0; k <= 200; ++k) {
      const Vec2 p = a + (b - a) * (k / 200.0);
      if (on_exit(p)) continue;
      // Within two radii of a corner of the buildings, the thick walls'
      // rounded mitre leaves the corner itself up to r (1 / sin(angle / 2) - 1)
      // free; the buildings' corners are no sharper than 85 degrees.
      const double corner = std::min(Length(p - a), Length(p - b));
      const double slack = corner < 0.3 ? 0.15 * (1.0 / std::sin(85.0 / 2.0 * std::numbers::pi / 180.0) - 1.0) : 0.0;
      EXPECT_GE(clearance(p), -2e-4) << "edge " << i << " at (" << p.x << ", " << p.y << ")";
      EXPECT_LE(clearance(p), slack + 2e-4) << "edge " << i << " at (" << p.x << ", " << p.y << ")";
      ++checked;
    }
  }
  EXPECT_GT(checked, 1500);
  Vec2 lo, hi;
  WalkableBounds(v, &lo, &hi);
  for (double x = lo.x; x <= hi.x; x += 0.05)
    for (double y = lo.y; y <= hi.y; y += 0.05) {
      if (!IsWalkable(v, {x, y}) || DistanceToRing(edge, {x, y}) < kVenueTolerance_m) continue;
      ASSERT_GE(clearance({x, y}), -2e-4) << "(" << x << ", " << y << ")";
    }
}

TEST(Venue, MissingFileIsAnError) {
  const std::string message = ErrorOf([] { LoadVenue(kData / "no-such-venue.json"); });
  EXPECT_NE(message.find("no-such-venue.json: cannot open"), std::string::npos) << message;
}

TEST(Venue, InlineErrors) {
  EXPECT_NE(ParseError(R"("walkable_area": [[[0, 0], [1, 0], [1, 1], [0, 1]]], "walls": [{"id": "w"}])")
                .find("/walls/0: a wall needs exactly one of \"polyline\""),
            std::string::npos);
  EXPECT_NE(ParseError(std::string(kRoom) + R"(, "exits": [{"id": "x", "segment": [[0, 0], [0, 1], [0, 2]]}])")
                .find("/exits/0/segment: expected a segment [[x1, y1], [x2, y2]] of two points, found 3"),
            std::string::npos);
  EXPECT_NE(ParseError(std::string(kRoom) + R"(, "exits": [{"id": "", "segment": [[0, 0], [0, 1]]}])")
                .find("/exits/0/id: the id is empty"),
            std::string::npos);
  EXPECT_NE(ParseError(std::string(kRoom) + R"(, "slope": {"direction": [1, 0], "gradient": 0.1, "tilt": 1})")
                .find("/slope: unknown key(s) \"tilt\""),
            std::string::npos);
  EXPECT_NE(ParseError(R"("walkable_area": [[[0, 0], [1, 0], [2, 0]]])").find("/walkable_area/0: outer ring has zero area"),
            std::string::npos);
  EXPECT_NE(ParseError(R"("walkable_area": [[[0, 0], [1, 0], [1, 1], [1, 0], [0, 1]]])").find("repeats a vertex"),
            std::string::npos);
  EXPECT_NE(ParseError(std::string(kRoom) + R"(, "entries": [{"id": "e", "polygon": [[8, 1], [12, 1], [12, 2], [8, 2]]}])")
                .find("/entries/0/polygon: entry zone vertex 1 (12, 1) is 2 m outside"),
            std::string::npos);
  EXPECT_NE(ParseError(R"("walkable_area": [[[0, 0], [1, 0], [1, 1], [0, 1]], [[0.5, 0.5], [3, 0.5], [3, 3], [0.5, 3]]])")
                .find("/walkable_area/1: outer ring meets outer ring /walkable_area/0"),
            std::string::npos);
}

// Issue 65: a slope's region was never checked ("venue OK" for any of these).
TEST(Venue, ASlopeRegionIsChecked) {
  const auto slope = [](const std::string& region) {
    return ParseError(std::string(kRoom) + R"(, "slope": {"direction": [1, 0], "gradient": 0.1, "region": )" + region + "}");
  };
  EXPECT_EQ(slope("[[2, 0], [6, 0], [6, 4], [2, 4]]"), "(no error)");
  EXPECT_EQ(slope("[[8, -2], [14, -2], [14, 6], [8, 6]]"), "(no error)");  // reaching beyond the area is fine
  EXPECT_EQ(slope("[[-5, -5], [20, -5], [20, 20], [-5, 20]]"), "(no error)");  // around it all
  EXPECT_NE(slope("[[2, 0], [6, 4], [6, 0], [2, 4]]").find("/slope/region: slope region is self-intersecting"),
            std::string::npos);
  EXPECT_NE(slope("[[20, 0], [30, 0], [30, 4], [20, 4]]").find("/slope/region: the slope region lies wholly outside"),
            std::string::npos);
  EXPECT_NE(slope("[[2, 1], [4, 1], [6, 1]]").find("/slope/region: slope region has zero area"), std::string::npos);
  EXPECT_NE(slope("[[0, 0], [1e30, 0], [1e30, 4], [0, 4]]").find("/slope/region/1: coordinate"), std::string::npos);
}

TEST(Venue, AllProblemsAreReportedTogether) {
  const std::string message = ParseError(std::string(kRoom) + R"(,
      "obstacles": [{"id": "far", "polygon": [[20, 20], [21, 20], [21, 21], [20, 21]]}],
      "exits": [{"id": "far", "segment": [[30, 0], [31, 0]]}])");
  EXPECT_NE(message.find("/obstacles/0/polygon"), std::string::npos) << message;
  EXPECT_NE(message.find("/exits/0/segment"), std::string::npos) << message;
}

}  // namespace
}  // namespace crowdrecon::geometry
