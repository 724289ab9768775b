// Importers: the same venue given as JSON, WKT, DXF and a raster image gives
// the same walkable area; curves, units, layers and bad inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "test_util.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::geometry {
namespace {

using testing_util::ErrorOf;

const std::filesystem::path kData = std::filesystem::path(CROWDRECON_SOURCE_DIR) / "tests/data/venues";

std::filesystem::path TempFile(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "crowdrecon_test_venue_import";
  std::filesystem::create_directories(dir);
  return dir / name;
}

// --- DXF text ------------------------------------------------------------

std::string DxfFile(const std::string& entities, int insunits = 6) {
  return "0\nSECTION\n2\nHEADER\n9\n$INSUNITS\n70\n" + std::to_string(insunits) +
         "\n0\nENDSEC\n0\nSECTION\n2\nENTITIES\n" + entities + "0\nENDSEC\n0\nEOF\n";
}

std::string Num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

std::string DxfPolyline(const std::vector<Vec2>& points, bool closed, const std::string& layer = "0",
                        const std::vector<double>& bulges = {}) {
  std::string e = "0\nLWPOLYLINE\n8\n" + layer + "\n90\n" + std::to_string(points.size()) + "\n70\n" +
                  (closed ? "1" : "0") + "\n";
  for (std::size_t i = 0; i < points.size(); ++i) {
    e += "10\n" + Num(points[i].x) + "\n20\n" + Num(points[i].y) + "\n";
    if (i < bulges.size() && bulges[i] != 0.0) e += "42\n" + Num(bulges[i]) + "\n";
  }
  return e;
}

std::string DxfLine(Vec2 a, Vec2 b, const std::string& layer = "0") {
  return "0\nLINE\n8\n" + layer + "\n10\n" + Num(a.x) + "\n20\n" + Num(a.y) + "\n11\n" + Num(b.x) + "\n21\n" +
         Num(b.y) + "\n";
}

std::string DxfCircle(Vec2 c, double r, const std::string& layer = "0") {
  return "0\nCIRCLE\n8\n" + layer + "\n10\n" + Num(c.x) + "\n20\n" + Num(c.y) + "\n40\n" + Num(r) + "\n";
}

std::string DxfArc(Vec2 c, double r, double from_deg, double to_deg, const std::string& layer = "0") {
  return "0\nARC\n8\n" + layer + "\n10\n" + Num(c.x) + "\n20\n" + Num(c.y) + "\n40\n" + Num(r) + "\n50\n" +
         Num(from_deg) + "\n51\n" + Num(to_deg) + "\n";
}

std::filesystem::path WriteText(const std::string& name, const std::string& text) {
  const auto path = TempFile(name);
  std::ofstream(path) << text;
  return path;
}

struct Shape {
  double area_m2, perimeter_m;
  std::size_t parts, holes;
};

Shape ShapeOf(const Venue& v) {
  return {WalkableArea_m2(v), WalkablePerimeter_m(v), v.walkable_area.size(), v.obstacles.size()};
}

// --- the same room in four formats -------------------------------------------

TEST(VenueImport, JsonWktDxfAndImageAgree) {
  const Shape json = ShapeOf(LoadVenue(kData / "room.json"));
  const Shape wkt = ShapeOf(ImportWkt(kData / "room.wkt"));
  const Shape dxf = ShapeOf(ImportDxf(kData / "room.dxf"));  // millimetres, $INSUNITS = 4
  RasterImportOptions raster;
  raster.pixels_per_metre = 50;
  const Shape image = ShapeOf(ImportRasterPlan(kData / "room-50ppm.png", raster));

  EXPECT_DOUBLE_EQ(json.area_m2, 39.0);
  EXPECT_DOUBLE_EQ(json.perimeter_m, 32.0);
  for (const Shape& s : {wkt, dxf}) {
    EXPECT_NEAR(s.area_m2, json.area_m2, 1e-9);
    EXPECT_NEAR(s.perimeter_m, json.perimeter_m, 1e-9);
    EXPECT_EQ(s.parts, 1u);
    EXPECT_EQ(s.holes, 1u);
  }
  EXPECT_NEAR(image.area_m2, json.area_m2, 0.01 * json.area_m2);
  EXPECT_NEAR(image.perimeter_m, json.perimeter_m, 0.02 * json.perimeter_m);
  EXPECT_EQ(image.holes, 1u);
}

TEST(VenueImport, ImportedVenueRoundTripsThroughJson) {
  const Venue v = ImportWkt(kData / "room.wkt");
  const auto path = TempFile("room-from-wkt.json");
  WriteVenueJson(v, path);
  const Venue w = LoadVenue(path);
  EXPECT_EQ(w.walkable_area, v.walkable_area);
  EXPECT_EQ(w.obstacles.size(), 1u);
  EXPECT_EQ(w.walls.size(), 1u);  // the outline as a closed wall
  EXPECT_EQ(w.metadata.name, "room");
}

// --- WKT --------------------------------------------------------------------

TEST(VenueImport, WktMultipolygonAndJuelichStyle) {
  const Venue two = ImportWkt(kData / "two-rooms.wkt");
  EXPECT_EQ(two.walkable_area.size(), 2u);
  EXPECT_EQ(two.obstacles.size(), 1u);
  EXPECT_NEAR(WalkableArea_m2(two), 12.0 + 9.0 - 1.0, 1e-12);
  // The bottleneck walkable area of the Jülich/Wuppertal experiment as PedPy
  // writes it (transcribed), with lower-case keyword and extra spaces.
  const Venue bottleneck = ParseWkt(
      "polygon  ((3.5 -2, 3.5 8, -3.5 8, -3.5 -2, 3.5 -2), (-0.7 -1.1, -0.25 -1.1, -0.25 -0.15, -0.4 0, -2.8 0, "
      "-2.8 6.7, -3.05 6.7, -3.05 -0.3, -0.7 -0.3, -0.7 -1, -0.7 -1.1), (0.25 -1.1, 0.7 -1.1, 0.7 -0.3, 3.05 -0.3, "
      "3.05 6.7, 2.8 6.7, 2.8 0, 0.4 0, 0.25 -0.15, 0.25 -1.1))",
      "bottleneck.wkt");
  EXPECT_EQ(bottleneck.obstacles.size(), 2u);
  EXPECT_GT(WalkableArea_m2(bottleneck), 60.0);
  EXPECT_LT(WalkableArea_m2(bottleneck), 70.0);
}

TEST(VenueImport, WktErrorsGiveLineAndColumn) {
  std::string m = ErrorOf([] { ImportWkt(kData / "bad-syntax.wkt"); });
  EXPECT_NE(m.find("bad-syntax.wkt:2:33: invalid WKT: expected a number but found 'x'"), std::string::npos) << m;
  m = ErrorOf([] { ImportWkt(kData / "bad-unclosed.wkt"); });
  EXPECT_NE(m.find("bad-unclosed.wkt:1:10: invalid WKT: ring is not closed"), std::string::npos) << m;
  m = ErrorOf([] { ImportWkt(kData / "bad-hole-crosses.wkt"); });
  EXPECT_NE(m.find("/obstacles/0/polygon: obstacle \"obstacle-1\" meets the boundary"), std::string::npos) << m;
  m = ErrorOf([] { ParseWkt("LINESTRING (0 0, 1 1)", "line.wkt"); });
  EXPECT_NE(m.find("line.wkt:1:1: invalid WKT: unsupported geometry type \"LINESTRING\""), std::string::npos) << m;
  m = ErrorOf([] { ParseWkt("POLYGON EMPTY", "empty.wkt"); });
  EXPECT_NE(m.find("empty.wkt: the WKT geometry is EMPTY"), std::string::npos) << m;
  m = ErrorOf([] { ParseWkt("POLYGON ((0 0, 1 0, 1 1, 0 0)) trailing", "t.wkt"); });
  EXPECT_NE(m.find("t.wkt:1:32: invalid WKT: unexpected text after the end"), std::string::npos) << m;
  m = ErrorOf([] { ImportWkt(kData / "no-such.wkt"); });
  EXPECT_NE(m.find("no-such.wkt: cannot open"), std::string::npos) << m;
}

// --- DXF --------------------------------------------------------------------

TEST(VenueImport, DxfCurvesAreFlattened) {
  // A 10 m x 4 m room with rounded ends (LWPOLYLINE bulges of 1 = half
  // circles of radius 2) and a round pillar (CIRCLE r = 0.5).
  const std::vector<Vec2> stadium{{0, 0}, {10, 0}, {10, 4}, {0, 4}};
  const std::string text =
      DxfFile(DxfPolyline(stadium, true, "plan", {0.0, 1.0, 0.0, 1.0}) + DxfCircle({5, 2}, 0.5, "plan"));
  ImportOptions options;
  options.dxf_arc_tolerance_m = 0.001;
  const Venue v = ImportDxf(WriteText("stadium.dxf", text), options);
  const double exact = 40.0 + std::numbers::pi * 4.0 - std::numbers::pi * 0.25;
  EXPECT_NEAR(WalkableArea_m2(v), exact, 0.002 * exact);
  EXPECT_EQ(v.obstacles.size(), 1u);
  // Polygons inscribed in the arcs: a little less area, never more.
  EXPECT_LT(WalkableArea_m2(v), 40.0 + std::numbers::pi * 4.0);
}

TEST(VenueImport, DxfArcsAndLinesChainIntoARing) {
  // A 6 m x 4 m room whose east side is an ARC bulging outward, drawn as
  // separate LINE and ARC entities in no particular order or direction.
  const std::string text = DxfFile(DxfLine({0, 0}, {6, 0}) + DxfLine({0, 4}, {0, 0}) + DxfArc({6, 2}, 2, -90, 90) +
                                   DxfLine({6, 4}, {0, 4}));
  const Venue v = ImportDxf(WriteText("arc-room.dxf", text));
  // The arc is flattened with chords within 0.01 m of it (the default), so
  // the area falls short by less than that times the arc's length.
  const double exact = 24.0 + 0.5 * std::numbers::pi * 4.0;
  EXPECT_LT(WalkableArea_m2(v), exact);
  EXPECT_GT(WalkableArea_m2(v), exact - 0.01 * std::numbers::pi * 2.0);
}

TEST(VenueImport, DxfLayerAndUnits) {
  // Centimetres; the furniture layer must be ignored when a layer is chosen.
  const std::string text = DxfFile(DxfPolyline({{0, 0}, {1000, 0}, {1000, 400}, {0, 400}}, true, "walkable") +
                                       DxfPolyline({{200, 100}, {300, 100}, {300, 200}, {200, 200}}, true, "furniture"),
                                   5);
  const auto path = WriteText("layers.dxf", text);
  ImportOptions options;
  options.dxf_layer = "walkable";
  EXPECT_NEAR(WalkableArea_m2(ImportDxf(path, options)), 40.0, 1e-9);
  EXPECT_NEAR(WalkableArea_m2(ImportDxf(path)), 39.0, 1e-9);  // all layers: the table is an obstacle
  options.dxf_layer.clear();
  options.scale_m_per_unit = 0.001;  // an explicit scale overrides $INSUNITS
  EXPECT_NEAR(WalkableArea_m2(ImportDxf(path, options)), 0.39, 1e-9);
}

TEST(VenueImport, DxfWithoutClosedRegionIsAnError) {
  std::string m = ErrorOf([] { ImportDxf(kData / "bad-open.dxf"); });
  EXPECT_NE(m.find("bad-open.dxf: no closed region found (3 open polyline(s)"), std::string::npos) << m;
  m = ErrorOf([] { ImportDxf(kData / "no-such.dxf"); });
  EXPECT_NE(m.find("no-such.dxf: cannot open"), std::string::npos) << m;
  ImportOptions options;
  options.dxf_layer = "nothing-here";
  m = ErrorOf([&] { ImportDxf(kData / "room.dxf", options); });
  EXPECT_NE(m.find("no closed region found on layer \"nothing-here\""), std::string::npos) << m;
}

// --- raster -------------------------------------------------------------------

// Draws a plan at `ppm` pixels per metre: black everywhere, a white 10 m x 4 m
// room whose lower-left corner is at (1, 1) m, with a black disc pillar of
// radius 0.5 m at (5, 3) and a black slanted wall triangle at its east end.
std::filesystem::path DrawPlan(double ppm) {
  const int width = static_cast<int>(12 * ppm), height = static_cast<int>(6 * ppm);
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(255));
  auto px = [&](Vec2 m) { return cv::Point(static_cast<int>(std::lround(m.x * ppm)), height - static_cast<int>(std::lround(m.y * ppm))); };
  cv::rectangle(image, cv::Point(0, 0), cv::Point(width - 1, height - 1), cv::Scalar(0), cv::FILLED);
  cv::rectangle(image, px({1, 5}), px({11, 1}) - cv::Point(1, 1), cv::Scalar(255), cv::FILLED);
  cv::circle(image, px({5, 3}), static_cast<int>(std::lround(0.5 * ppm)), cv::Scalar(0), cv::FILLED, cv::LINE_8);
  std::vector<cv::Point> corner{px({9, 1}), px({11, 1}), px({11, 3})};
  cv::fillConvexPoly(image, corner, cv::Scalar(0), cv::LINE_8);
  const auto path = TempFile("plan-" + std::to_string(static_cast<int>(ppm)) + ".png");
  cv::imwrite(path.string(), image);
  return path;
}

TEST(VenueImport, RasterPlanWithCurvedAndSlantedWalls) {
  const double exact = 40.0 - std::numbers::pi * 0.25 - 2.0;  // room - pillar - corner triangle
  RasterImportOptions options;
  options.pixels_per_metre = 50;
  const Venue v = ImportRasterPlan(DrawPlan(50), options);
  EXPECT_NEAR(WalkableArea_m2(v), exact, 0.015 * exact);
  EXPECT_EQ(v.obstacles.size(), 1u);
  // The simplification leaves a few dozen vertices, not the pixel staircase.
  EXPECT_LT(v.walkable_area[0].size(), 40u);
  EXPECT_LT(v.obstacles[0].polygon.size(), 60u);
  // Coordinates are metres from the image's lower-left corner.
  EXPECT_TRUE(IsWalkable(v, {2, 2}));
  EXPECT_FALSE(IsWalkable(v, {5, 3}));
  EXPECT_FALSE(IsWalkable(v, {0.5, 0.5}));
}

TEST(VenueImport, RasterSeedAndErrors) {
  const auto path = DrawPlan(20);
  RasterImportOptions options;
  options.pixels_per_metre = 20;
  options.seed_m = Vec2{2, 2};
  EXPECT_NO_THROW(ImportRasterPlan(path, options));
  options.seed_m = Vec2{5, 3};  // on the pillar
  std::string m = ErrorOf([&] { ImportRasterPlan(path, options); });
  EXPECT_NE(m.find("falls on a dark (wall) pixel"), std::string::npos) << m;
  options.seed_m = Vec2{50, 3};
  m = ErrorOf([&] { ImportRasterPlan(path, options); });
  EXPECT_NE(m.find("is outside the image"), std::string::npos) << m;

  // A plan whose free space touches the border everywhere: nothing enclosed.
  cv::Mat open(100, 100, CV_8UC1, cv::Scalar(255));
  cv::line(open, {10, 50}, {90, 50}, cv::Scalar(0), 3);
  const auto open_path = TempFile("open.png");
  cv::imwrite(open_path.string(), open);
  RasterImportOptions plain;
  plain.pixels_per_metre = 10;
  m = ErrorOf([&] { ImportRasterPlan(open_path, plain); });
  EXPECT_NE(m.find("no enclosed free region"), std::string::npos) << m;

  m = ErrorOf([&] { ImportRasterPlan(kData / "room.wkt", plain); });
  EXPECT_NE(m.find("cannot read the file as an image"), std::string::npos) << m;
  plain.pixels_per_metre = 0;
  m = ErrorOf([&] { ImportRasterPlan(path, plain); });
  EXPECT_NE(m.find("expected a positive scale"), std::string::npos) << m;
}

}  // namespace
}  // namespace crowdrecon::geometry
