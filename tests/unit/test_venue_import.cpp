// Importers: the same venue given as JSON, WKT, DXF and a raster image gives
// the same walkable area; curves, units, layers and bad inputs.
#include <gtest/gtest.h>

#include "scratch.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "crowdrecon/media/media.hpp"  // imread/imwrite/video through the codecs module (tests start without it)

#include "test_util.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/outline.hpp"
#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::geometry {
namespace {

using testing_util::ErrorOf;

const std::filesystem::path kImportData = std::filesystem::path(CROWDRECON_SOURCE_DIR) / "tests/data/venues";

std::filesystem::path TempFile(const std::string& name) { return crowdrecon::testing::ScratchFile(name); }

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
  const Shape json = ShapeOf(LoadVenue(kImportData / "room.json"));
  const Shape wkt = ShapeOf(ImportWkt(kImportData / "room.wkt"));
  const Shape dxf = ShapeOf(ImportDxf(kImportData / "room.dxf"));  // millimetres, $INSUNITS = 4
  RasterImportOptions raster;
  raster.pixels_per_metre = 50;
  const Shape image = ShapeOf(ImportRasterPlan(kImportData / "room-50ppm.png", raster));

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
  const Venue v = ImportWkt(kImportData / "room.wkt");
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
  const Venue two = ImportWkt(kImportData / "two-rooms.wkt");
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
  std::string m = ErrorOf([] { ImportWkt(kImportData / "bad-syntax.wkt"); });
  EXPECT_NE(m.find("bad-syntax.wkt:2:33: invalid WKT: expected a number but found 'x'"), std::string::npos) << m;
  m = ErrorOf([] { ImportWkt(kImportData / "bad-unclosed.wkt"); });
  EXPECT_NE(m.find("bad-unclosed.wkt:1:10: invalid WKT: ring is not closed"), std::string::npos) << m;
  m = ErrorOf([] { ImportWkt(kImportData / "bad-hole-crosses.wkt"); });
  EXPECT_NE(m.find("/obstacles/0/polygon: obstacle \"obstacle-1\" meets the boundary"), std::string::npos) << m;
  m = ErrorOf([] { ParseWkt("LINESTRING (0 0, 1 1)", "line.wkt"); });
  EXPECT_NE(m.find("line.wkt:1:1: invalid WKT: unsupported geometry type \"LINESTRING\""), std::string::npos) << m;
  m = ErrorOf([] { ParseWkt("POLYGON EMPTY", "empty.wkt"); });
  EXPECT_NE(m.find("empty.wkt: the WKT geometry is EMPTY"), std::string::npos) << m;
  m = ErrorOf([] { ParseWkt("POLYGON ((0 0, 1 0, 1 1, 0 0)) trailing", "t.wkt"); });
  EXPECT_NE(m.find("t.wkt:1:32: invalid WKT: unexpected text after the end"), std::string::npos) << m;
  m = ErrorOf([] { ImportWkt(kImportData / "no-such.wkt"); });
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
  std::string m = ErrorOf([] { ImportDxf(kImportData / "bad-open.dxf"); });
  EXPECT_NE(m.find("bad-open.dxf: no closed region found (3 open polyline(s)"), std::string::npos) << m;
  m = ErrorOf([] { ImportDxf(kImportData / "no-such.dxf"); });
  EXPECT_NE(m.find("no-such.dxf: cannot open"), std::string::npos) << m;
  ImportOptions options;
  options.dxf_layer = "nothing-here";
  m = ErrorOf([&] { ImportDxf(kImportData / "room.dxf", options); });
  EXPECT_NE(m.find("no closed region found on layer \"nothing-here\""), std::string::npos) << m;
}

TEST(VenueImport, TruncatedDxfIsAnError) {
  // The room cut short after its outline (its obstacle's lines and the end-of-file
  // group lost): refused, not imported in part. With the last group present
  // (blank lines and CR after it allowed) the same text imports.
  std::ifstream in(kImportData / "room.dxf");
  std::stringstream whole;
  whole << in.rdbuf();
  const std::string text = whole.str();
  const std::size_t cut = text.find("\nLINE");
  ASSERT_NE(cut, std::string::npos);
  std::string m = ErrorOf([&] { ImportDxf(WriteText("cut.dxf", text.substr(0, cut))); });
  EXPECT_NE(m.find("cut.dxf: the file ends at line "), std::string::npos) << m;
  EXPECT_NE(m.find("without the end-of-file group (0 / EOF)"), std::string::npos) << m;
  std::string crlf;
  for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  EXPECT_NEAR(WalkableArea_m2(ImportDxf(WriteText("crlf.dxf", crlf + "\r\n\n"))), 39.0, 1e-6);
}

// A DXF file with a BLOCKS section before the entities.
std::string DxfFileWithBlocks(const std::string& blocks, const std::string& entities) {
  return "0\nSECTION\n2\nHEADER\n9\n$INSUNITS\n70\n6\n0\nENDSEC\n0\nSECTION\n2\nBLOCKS\n" + blocks +
         "0\nENDSEC\n0\nSECTION\n2\nENTITIES\n" + entities + "0\nENDSEC\n0\nEOF\n";
}

std::string DxfBlock(const std::string& name, Vec2 base, const std::string& entities) {
  return "0\nBLOCK\n8\n0\n2\n" + name + "\n70\n0\n10\n" + Num(base.x) + "\n20\n" + Num(base.y) + "\n30\n0\n" +
         entities + "0\nENDBLK\n8\n0\n";
}

struct DxfPlacement {
  Vec2 at;
  double scale_x = 1.0, scale_y = 1.0, angle_deg = 0.0;
  int columns = 1, rows = 1;
  double column_spacing = 0.0, row_spacing = 0.0;
};

std::string DxfInsert(const std::string& block, const DxfPlacement& p, const std::string& layer = "0") {
  return "0\nINSERT\n8\n" + layer + "\n2\n" + block + "\n10\n" + Num(p.at.x) + "\n20\n" + Num(p.at.y) + "\n41\n" +
         Num(p.scale_x) + "\n42\n" + Num(p.scale_y) + "\n50\n" + Num(p.angle_deg) + "\n70\n" +
         std::to_string(p.columns) + "\n71\n" + std::to_string(p.rows) + "\n44\n" + Num(p.column_spacing) +
         "\n45\n" + Num(p.row_spacing) + "\n";
}

// The obstacle whose polygon contains p (by its bounding box), or null.
const Obstacle* ObstacleAt(const Venue& v, Vec2 p) {
  for (const Obstacle& o : v.obstacles) {
    Vec2 lo = o.polygon[0], hi = o.polygon[0];
    for (Vec2 q : o.polygon) {
      lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
      hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
    }
    if (p.x > lo.x && p.x < hi.x && p.y > lo.y && p.y < hi.y) return &o;
  }
  return nullptr;
}

double ExtentX(const Obstacle& o) {
  double lo = o.polygon[0].x, hi = lo;
  for (Vec2 q : o.polygon) lo = std::min(lo, q.x), hi = std::max(hi, q.x);
  return hi - lo;
}

TEST(VenueImport, DxfBlockInsertsAreExpanded) {
  // A 10 m x 6 m room; pillars drawn once, in block PILLAR (a 0.4 m square
  // around its base point (1, 1), on layer "0"), and placed by INSERTs: plain,
  // scaled by 2 and turned 45 degrees, mirrored, as a 2 x 2 array (MINSERT),
  // twice through a nested block PAIR, and once on another layer.
  const std::string pillar =
      DxfBlock("PILLAR", {1, 1}, DxfPolyline({{0.8, 0.8}, {1.2, 0.8}, {1.2, 1.2}, {0.8, 1.2}}, true));
  const std::string pair =
      DxfBlock("PAIR", {0, 0}, DxfInsert("PILLAR", {{0, 0}}) + DxfInsert("PILLAR", {{0.8, 0}}));
  DxfPlacement turned{{5, 3}};
  turned.scale_x = turned.scale_y = 2.0;
  turned.angle_deg = 45.0;
  DxfPlacement mirrored{{4, 1}};
  mirrored.scale_x = -1.0;
  DxfPlacement array{{7, 1.5}};
  array.columns = array.rows = 2;
  array.column_spacing = array.row_spacing = 1.0;
  const std::string entities = DxfPolyline({{0, 0}, {10, 0}, {10, 6}, {0, 6}}, true, "plan") +
                               DxfInsert("PILLAR", {{2, 3}}, "plan") + DxfInsert("PILLAR", turned, "plan") +
                               DxfInsert("PILLAR", mirrored, "plan") + DxfInsert("PILLAR", array, "plan") +
                               DxfInsert("PAIR", {{2, 5}}, "plan") + DxfInsert("PILLAR", {{8.5, 4.5}}, "furniture");
  const auto path = WriteText("blocks.dxf", DxfFileWithBlocks(pillar + pair, entities));
  ImportOptions options;
  options.dxf_layer = "plan";
  const Venue v = ImportDxf(path, options);
  // 1 + 1 + 1 + 4 + 2 pillars of 0.16 m2, the turned one 0.64 m2.
  EXPECT_EQ(v.obstacles.size(), 9u);
  EXPECT_NEAR(WalkableArea_m2(v), 60.0 - 8 * 0.16 - 0.64, 1e-9);
  for (Vec2 centre : {Vec2{2, 3}, Vec2{4, 1}, Vec2{7, 1.5}, Vec2{8, 1.5}, Vec2{7, 2.5}, Vec2{8, 2.5}, Vec2{2, 5},
                      Vec2{2.8, 5}}) {
    const Obstacle* o = ObstacleAt(v, centre);
    ASSERT_NE(o, nullptr) << centre.x << ", " << centre.y;
    EXPECT_NEAR(ExtentX(*o), 0.4, 1e-9) << centre.x << ", " << centre.y;
  }
  const Obstacle* turned_pillar = ObstacleAt(v, {5, 3});
  ASSERT_NE(turned_pillar, nullptr);
  EXPECT_NEAR(ExtentX(*turned_pillar), 0.8 * std::sqrt(2.0), 1e-9);  // a 0.8 m square turned 45 degrees
  EXPECT_EQ(ObstacleAt(v, {8.5, 4.5}), nullptr);                      // on layer "furniture"
  // All layers: the furniture's pillar too.
  EXPECT_EQ(ImportDxf(path).obstacles.size(), 10u);
}

TEST(VenueImport, DxfBlockErrorsAndEllipses) {
  const std::string room = DxfPolyline({{0, 0}, {10, 0}, {10, 6}, {0, 6}}, true);
  // An INSERT of a block the file does not define.
  std::string m = ErrorOf([&] { ImportDxf(WriteText("no-block.dxf", DxfFileWithBlocks("", room + DxfInsert("GHOST", {{1, 1}})))); });
  EXPECT_NE(m.find("no-block.dxf: an INSERT places block \"GHOST\", which the file does not define"),
            std::string::npos) << m;
  // A block that inserts itself.
  const std::string loop = DxfBlock("LOOP", {0, 0}, DxfInsert("LOOP", {{0.1, 0}}));
  m = ErrorOf([&] { ImportDxf(WriteText("loop.dxf", DxfFileWithBlocks(loop, room + DxfInsert("LOOP", {{1, 1}})))); });
  EXPECT_NE(m.find("loop.dxf: block \"LOOP\" is inserted more than 32 levels deep"), std::string::npos) << m;
  // A spline whose knots do not fit its control points is refused, naming it;
  // on a layer that is not imported it is left out.
  const std::string bad_spline = "0\nSPLINE\n8\ncurves\n70\n8\n71\n3\n72\n5\n73\n4\n40\n0\n40\n0\n40\n0\n40\n1\n40\n1\n"
                                 "10\n1\n20\n1\n10\n2\n20\n2\n10\n3\n20\n1\n10\n4\n20\n2\n";
  const auto spline_path =
      WriteText("spline.dxf", DxfFile(DxfPolyline({{0, 0}, {10, 0}, {10, 6}, {0, 6}}, true, "plan") + bad_spline));
  m = ErrorOf([&] { ImportDxf(spline_path); });
  EXPECT_NE(m.find("spline.dxf: a SPLINE of degree 3 with 4 control points and 5 knots (expected degree + control "
                   "points + 1) on layer \"curves\" cannot be read"),
            std::string::npos) << m;
  ImportOptions options;
  options.dxf_layer = "plan";
  EXPECT_NEAR(WalkableArea_m2(ImportDxf(spline_path, options)), 60.0, 1e-9);
  // A full ellipse (semi-axes 1 and 0.5, turned 30 degrees) as a pillar: its area within the flattening.
  const double c = std::cos(std::numbers::pi / 6.0), s = std::sin(std::numbers::pi / 6.0);
  const std::string ellipse = "0\nELLIPSE\n8\n0\n10\n5\n20\n3\n30\n0\n11\n" + Num(c) + "\n21\n" + Num(s) +
                              "\n31\n0\n40\n0.5\n41\n0\n42\n" + Num(2.0 * std::numbers::pi) + "\n";
  options.dxf_layer.clear();
  options.dxf_arc_tolerance_m = 1e-4;
  const Venue v = ImportDxf(WriteText("ellipse.dxf", DxfFile(room + ellipse)), options);
  ASSERT_EQ(v.obstacles.size(), 1u);
  EXPECT_NEAR(WalkableArea_m2(v), 60.0 - std::numbers::pi * 0.5, 2e-3);
  EXPECT_NEAR(ExtentX(v.obstacles[0]), 2.0 * std::sqrt(c * c + 0.25 * s * s), 1e-3);
}

// A SPLINE entity: degree, knots, control points and (if given) weights.
std::string DxfSpline(int degree, const std::vector<double>& knots, const std::vector<Vec2>& control,
                      const std::vector<double>& weights = {}, bool closed = false) {
  std::string e = "0\nSPLINE\n8\n0\n70\n" + std::to_string(8 + (closed ? 1 : 0) + (weights.empty() ? 0 : 4)) +
                  "\n71\n" + std::to_string(degree) + "\n72\n" + std::to_string(knots.size()) + "\n73\n" +
                  std::to_string(control.size()) + "\n74\n0\n";
  for (double k : knots) e += "40\n" + Num(k) + "\n";
  for (std::size_t i = 0; i < control.size(); ++i) {
    e += "10\n" + Num(control[i].x) + "\n20\n" + Num(control[i].y) + "\n30\n0\n";
    if (!weights.empty()) e += "41\n" + Num(weights[i]) + "\n";
  }
  return e;
}

TEST(VenueImport, DxfSplinesAreFlattened) {
  const std::string room = DxfPolyline({{0, 0}, {10, 0}, {10, 6}, {0, 6}}, true);
  ImportOptions options;
  options.dxf_arc_tolerance_m = 1e-5;
  // A cubic Bezier (one clamped span) closed by a line: the region between
  // them, by Green's theorem over the Bernstein form, is the pillar's area.
  const std::vector<Vec2> c{{2, 2}, {2, 3.5}, {5, 3.5}, {5, 2}};
  const auto bezier = [&](double t) {
    const double s = 1.0 - t;
    return c[0] * (s * s * s) + c[1] * (3 * s * s * t) + c[2] * (3 * s * t * t) + c[3] * (t * t * t);
  };
  double area = 0.0;
  const int steps = 200000;
  for (int k = 0; k < steps; ++k) area += Cross(bezier(double(k) / steps), bezier(double(k + 1) / steps)) / 2.0;
  area += Cross(c[3], c[0]) / 2.0;  // the closing line
  const Venue v = ImportDxf(
      WriteText("bezier.dxf", DxfFile(room + DxfSpline(3, {0, 0, 0, 0, 1, 1, 1, 1}, c) + DxfLine({5, 2}, {2, 2}))),
      options);
  ASSERT_EQ(v.obstacles.size(), 1u);
  EXPECT_NEAR(60.0 - WalkableArea_m2(v), std::abs(area), 1e-4);
  // A circle of radius 1 around (7, 3) as a rational quadratic NURBS (nine
  // control points on a square, weights 1 and 1/sqrt(2)): area pi within the flattening.
  const double h = std::sqrt(0.5);
  const std::vector<Vec2> square{{8, 3}, {8, 4}, {7, 4}, {6, 4}, {6, 3}, {6, 2}, {7, 2}, {8, 2}, {8, 3}};
  const std::string circle =
      DxfSpline(2, {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1}, square, {1, h, 1, h, 1, h, 1, h, 1}, true);
  const Venue round = ImportDxf(WriteText("nurbs-circle.dxf", DxfFile(room + circle)), options);
  ASSERT_EQ(round.obstacles.size(), 1u);
  EXPECT_NEAR(60.0 - WalkableArea_m2(round), std::numbers::pi, 1e-3);
  EXPECT_NEAR(ExtentX(round.obstacles[0]), 2.0, 1e-6);
}

// A SPLINE given by fit points only (group 11), as some CAD exporters write them.
// With `tangents` (start, end), also groups 12/22/32 and 13/23/33.
std::string DxfFitSpline(int degree, const std::vector<Vec2>& fit, bool closed,
                         std::optional<std::pair<Vec2, Vec2>> tangents = std::nullopt) {
  std::string e = "0\nSPLINE\n8\n0\n70\n" + std::to_string(8 + (closed ? 1 : 0)) + "\n71\n" + std::to_string(degree) +
                  "\n72\n0\n73\n0\n74\n" + std::to_string(fit.size()) + "\n";
  if (tangents) {
    e += "12\n" + Num(tangents->first.x) + "\n22\n" + Num(tangents->first.y) + "\n32\n0\n";
    e += "13\n" + Num(tangents->second.x) + "\n23\n" + Num(tangents->second.y) + "\n33\n0\n";
  }
  for (const Vec2& f : fit) e += "11\n" + Num(f.x) + "\n21\n" + Num(f.y) + "\n31\n0\n";
  return e;
}

// Least distance from p to the closed polygon `ring`.
double DistanceToRing(Vec2 p, const std::vector<Vec2>& ring) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Vec2 a = ring[i], b = ring[(i + 1) % ring.size()];
    const double t = std::clamp(Dot(p - a, b - a) / LengthSquared(b - a), 0.0, 1.0);
    best = std::min(best, Length(p - (a + (b - a) * t)));
  }
  return best;
}

TEST(VenueImport, DxfFitPointSplinesAreInterpolated) {
  const std::string room = DxfPolyline({{0, 0}, {10, 0}, {10, 6}, {0, 6}}, true);
  ImportOptions options;
  options.dxf_arc_tolerance_m = 1e-5;
  // 24 fit points on a circle of radius 1 around (7, 3), closed: the curve
  // passes through every one of them, and encloses pi to the interpolation's
  // accuracy (a cubic through points 15 degrees apart).
  std::vector<Vec2> fit;
  for (int k = 0; k < 24; ++k) {
    const double t = 2.0 * std::numbers::pi * k / 24.0;
    fit.push_back({7.0 + std::cos(t), 3.0 + std::sin(t)});
  }
  const Venue v = ImportDxf(WriteText("fit-circle.dxf", DxfFile(room + DxfFitSpline(3, fit, true))), options);
  ASSERT_EQ(v.obstacles.size(), 1u);
  for (const Vec2& f : fit) EXPECT_LT(DistanceToRing(f, v.obstacles[0].polygon), 2e-5) << f.x << " " << f.y;
  EXPECT_NEAR(60.0 - WalkableArea_m2(v), std::numbers::pi, 2e-4);
  // Between the fit points the curve bulges out like the circle, not along
  // the chords: the polygon through the fit points alone has 3.106 m^2.
  EXPECT_GT(60.0 - WalkableArea_m2(v), 3.13);
  // An open fit spline (an arc of a pillar) closed by a line, and a
  // degree-1 one (a polyline through its points).
  const std::vector<Vec2> arc{{2, 2}, {2.5, 3}, {3.5, 3.4}, {4.5, 3}, {5, 2}};
  const Venue open = ImportDxf(
      WriteText("fit-arc.dxf", DxfFile(room + DxfFitSpline(3, arc, false) + DxfLine({5, 2}, {2, 2}))), options);
  ASSERT_EQ(open.obstacles.size(), 1u);
  for (const Vec2& f : arc) EXPECT_LT(DistanceToRing(f, open.obstacles[0].polygon), 2e-5);
  const Venue linear = ImportDxf(
      WriteText("fit-linear.dxf", DxfFile(room + DxfFitSpline(1, arc, false) + DxfLine({5, 2}, {2, 2}))), options);
  ASSERT_EQ(linear.obstacles.size(), 1u);
  double polygon_area = 0.0;
  for (std::size_t i = 0; i < arc.size(); ++i) polygon_area += Cross(arc[i], arc[(i + 1) % arc.size()]) / 2.0;
  EXPECT_NEAR(60.0 - WalkableArea_m2(linear), std::abs(polygon_area), 1e-9);
  // One distinct fit point: an error that says so.
  const std::string m = ErrorOf([&] {
    ImportDxf(WriteText("fit-one.dxf", DxfFile(room + DxfFitSpline(3, {{1, 1}, {1, 1}}, false))), options);
  });
  EXPECT_NE(m.find("2 fit points and no control points"), std::string::npos) << m;
}

TEST(VenueImport, DxfFitPointSplinesFollowTheirEndTangents) {
  // A pillar shaped as a quarter disc of radius 1 around (7, 3): its arc is a
  // fit spline through 4 points, its straight sides two lines. With the
  // arc's own end tangents (of any length: the file gives directions) the
  // curve hugs the circle much more closely than with the ends left free.
  const std::string room = DxfPolyline({{0, 0}, {10, 0}, {10, 6}, {0, 6}}, true);
  ImportOptions options;
  options.dxf_arc_tolerance_m = 1e-5;
  const Vec2 centre{7, 3};
  std::vector<Vec2> fit;
  for (int k = 0; k < 4; ++k) {
    const double t = std::numbers::pi / 2.0 * k / 3.0;
    fit.push_back(centre + Vec2{std::cos(t), std::sin(t)});
  }
  const std::string sides = DxfLine(fit.back(), centre) + DxfLine(centre, fit.front());
  // Largest distance of the pillar's outline from the circle, its straight
  // sides and their ends left out.
  const auto deviation = [&](const Venue& v) {
    double worst = 0.0;
    for (const Vec2& p : v.obstacles.at(0).polygon)
      if (p.x > centre.x + 1e-6 && p.y > centre.y + 1e-6) worst = std::max(worst, std::abs(Length(p - centre) - 1.0));
    return worst;
  };
  const Venue free = ImportDxf(WriteText("quarter-free.dxf", DxfFile(room + DxfFitSpline(3, fit, false) + sides)), options);
  const Venue tangent = ImportDxf(
      WriteText("quarter-tangent.dxf",
                DxfFile(room + DxfFitSpline(3, fit, false, std::pair{Vec2{0, 3}, Vec2{-0.5, 0}}) + sides)),
      options);
  ASSERT_EQ(free.obstacles.size(), 1u);
  ASSERT_EQ(tangent.obstacles.size(), 1u);
  for (const Vec2& f : fit) EXPECT_LT(DistanceToRing(f, tangent.obstacles[0].polygon), 2e-5);
  const double free_deviation = deviation(free), tangent_deviation = deviation(tangent);
  EXPECT_LT(tangent_deviation, 1e-3) << free_deviation;
  EXPECT_LT(tangent_deviation, 0.25 * free_deviation) << free_deviation;
  EXPECT_NEAR(60.0 - WalkableArea_m2(tangent), std::numbers::pi / 4.0, 2e-3);
  // Two fit points and both tangents: a cubic (Hermite) arc, which a degree
  // clamped to the point count alone would make a straight line.
  const Venue two = ImportDxf(
      WriteText("quarter-two.dxf", DxfFile(room + DxfFitSpline(3, {fit.front(), fit.back()}, false,
                                                                 std::pair{Vec2{0, 1}, Vec2{-1, 0}}) +
                                            sides)),
      options);
  ASSERT_EQ(two.obstacles.size(), 1u);
  EXPECT_GT(60.0 - WalkableArea_m2(two), 0.7) << "chord triangle: 0.5 m^2, quarter disc: 0.785 m^2";
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
  media::WriteImage(path.string(), image);
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
  media::WriteImage(open_path.string(), open);
  RasterImportOptions plain;
  plain.pixels_per_metre = 10;
  m = ErrorOf([&] { ImportRasterPlan(open_path, plain); });
  EXPECT_NE(m.find("no enclosed free region"), std::string::npos) << m;

  m = ErrorOf([&] { ImportRasterPlan(kImportData / "room.wkt", plain); });
  EXPECT_NE(m.find("cannot read the file as an image"), std::string::npos) << m;
  plain.pixels_per_metre = 0;
  m = ErrorOf([&] { ImportRasterPlan(path, plain); });
  EXPECT_NE(m.find("expected a positive scale"), std::string::npos) << m;
}

// Reads a file's bytes, or writes them.
std::string Bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream all;
  all << in.rdbuf();
  return all.str();
}
std::filesystem::path WriteBytes(const std::string& name, const std::string& bytes) {
  const auto path = TempFile(name);
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

TEST(VenueImport, PicturesCutShortAreErrors) {
  // OpenCV decodes a JPEG that stops short (grey rows where data is missing)
  // with only a warning from libjpeg; a PNG that stops short it refuses, with
  // a message that does not say why. Both are refused, saying so.
  RasterImportOptions options;
  options.pixels_per_metre = 20;
  const std::string png = Bytes(DrawPlan(20));
  const cv::Mat plan = media::ReadImage(DrawPlan(20).string(), cv::IMREAD_GRAYSCALE);
  const auto jpeg_path = TempFile("plan-20.jpg");
  media::WriteImage(jpeg_path.string(), plan);  // OpenCV's JPEG quality is 95 by default
  const std::string jpeg = Bytes(jpeg_path);
  const double exact = WalkableArea_m2(ImportRasterPlan(jpeg_path, options));
  EXPECT_GT(exact, 35.0);
  // Bytes after the end-of-image marker (some cameras append data) are fine.
  EXPECT_NEAR(WalkableArea_m2(ImportRasterPlan(WriteBytes("tail.jpg", jpeg + std::string(64, '\x17')), options)), exact,
              1e-12);
  const std::string cut_jpeg = jpeg.substr(0, jpeg.size() * 2 / 3);
  const auto cut_path = WriteBytes("cut.jpg", cut_jpeg);
  ASSERT_FALSE(media::ReadImage(cut_path.string(), cv::IMREAD_GRAYSCALE).empty()) << "OpenCV decodes it, as said above";
  std::string m = ErrorOf([&] { ImportRasterPlan(cut_path, options); });
  EXPECT_NE(m.find("cut.jpg: JPEG whose image data stops without the end-of-image marker"), std::string::npos) << m;
  EXPECT_NE(m.find("cut short"), std::string::npos) << m;
  m = ErrorOf([&] { ImportRasterPlan(WriteBytes("cut.png", png.substr(0, png.size() - 20)), options); });
  EXPECT_NE(m.find("cut.png: PNG without its closing IEND chunk"), std::string::npos) << m;
  // Body outlines are read through the same check.
  m = ErrorOf([&] { ReadOutlineImage(cut_path, ImageOutlineOptions{}); });
  EXPECT_NE(m.find("cut.jpg: JPEG whose image data stops"), std::string::npos) << m;
}

}  // namespace
}  // namespace crowdrecon::geometry
