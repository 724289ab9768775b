// Geometry inputs never crash, hang or explode in memory (issue 17): the
// limits of crowdrecon/geometry/input_limits.hpp, the near-linear Hausdorff
// distance, and the messages for non-finite, huge and self-intersecting input.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "scratch.hpp"
#include <opencv2/imgcodecs.hpp>

#include "crowdrecon/media/media.hpp"  // imread/imwrite/video through the codecs module (tests start without it)

#include "test_util.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/body.hpp"
#include "crowdrecon/geometry/input_limits.hpp"
#include "crowdrecon/geometry/outline.hpp"
#include "crowdrecon/geometry/spheropolygon.hpp"
#include "crowdrecon/geometry/venue.hpp"

namespace crowdrecon::geometry {
namespace {

using testing_util::ErrorOf;

bool Has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

using crowdrecon::testing::ScratchFile;

double BruteForceHausdorff(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  const auto directed = [](const std::vector<Vec2>& from, const std::vector<Vec2>& to) {
    double worst = 0.0;
    for (const Vec2& p : from) {
      double best = INFINITY;
      for (const Vec2& q : to) best = std::min(best, Length(p - q));
      worst = std::max(worst, best);
    }
    return worst;
  };
  return std::max(directed(a, b), directed(b, a));
}

std::vector<Vec2> RandomPoints(std::mt19937& rng, std::size_t n, double spread) {
  std::uniform_real_distribution<double> u(-spread, spread);
  std::vector<Vec2> points(n);
  for (Vec2& p : points) p = {u(rng), u(rng)};
  return points;
}

TEST(GeometryLimits, HausdorffMatchesBruteForce) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 20; ++trial) {
    const auto a = RandomPoints(rng, 50 + static_cast<std::size_t>(trial) * 7, 1.0);
    const auto b = RandomPoints(rng, 80, 1.0 + 0.1 * trial);
    EXPECT_DOUBLE_EQ(HausdorffDistance(a, b), BruteForceHausdorff(a, b));
  }
  EXPECT_TRUE(std::isinf(HausdorffDistance({}, {{0, 0}})));
}

// 200000 points a side: 4e10 pairs by brute force (minutes); well under a
// second through the k-d tree.
TEST(GeometryLimits, HausdorffIsNearLinear) {
  std::vector<Vec2> a, b;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * M_PI * i / n;
    a.push_back({std::cos(t), std::sin(t)});
    b.push_back({1.001 * std::cos(t + 1e-6), 1.001 * std::sin(t + 1e-6)});
  }
  const auto start = std::chrono::steady_clock::now();
  EXPECT_NEAR(HausdorffDistance(a, b), 0.001, 1e-5);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
}

TEST(GeometryLimits, OutlineCoordinatesBeyondTheLimitAreRefused) {
  const std::string m = ErrorOf([] { ValidateOutlineRing({{0, 0}, {1e154, 0}, {1e154, 1e154}, {0, 1e154}}, "o"); });
  EXPECT_TRUE(Has(m, "o: point 1: coordinate 1e+154 is beyond 1000000000")) << m;
  EXPECT_TRUE(Has(m, "check the scale/units")) << m;
  const std::string n = ErrorOf([] { ValidateOutlineRing({{0, 0}, {NAN, 0}, {1, 1}}, "o"); });
  EXPECT_TRUE(Has(n, "o: point 1: coordinate nan is not finite")) << n;
  // At the limit itself: still an outline.
  EXPECT_EQ(ValidateOutlineRing({{0, 0}, {kMaxOutlineCoordinate, 0}, {0, kMaxOutlineCoordinate}}, "o").size(), 3u);
}

Outline Square(double side_m) {
  Outline outline;
  outline.source = "square";
  outline.points = {{0, 0}, {side_m, 0}, {side_m, side_m}, {0, side_m}};
  return outline;
}

TEST(GeometryLimits, BodyFarLargerThanAPersonIsRefused) {
  for (const double side : {10.0, 1e4, 1e6}) {
    const std::string m = ErrorOf([&] { BuildBody(Square(side), {}); });
    EXPECT_TRUE(Has(m, "square: the outline is " + FormatNumber(side) + " m across")) << m;
    EXPECT_TRUE(Has(m, "check the scale/units")) << m;
  }
  const Body body = BuildBody(Square(0.9 * kMaxBodyExtentM), {});
  EXPECT_GT(body.hausdorff_m, 0.0);
}

TEST(GeometryLimits, BowTieIsASelfIntersectionNotCollinear) {
  const std::string m = ErrorOf([] { Spheropolygon::Create({{-0.2, -0.15}, {0.2, 0.15}, {0.2, -0.15}, {-0.2, 0.15}}, 0.05, "b"); });
  EXPECT_TRUE(Has(m, "b: edges 0 ")) << m;
  EXPECT_TRUE(Has(m, "intersect; the polygon must be simple")) << m;
  const std::string c = ErrorOf([] { Spheropolygon::Create({{0, 0}, {1, 0}, {2, 0}}, 0.05, "c"); });
  EXPECT_TRUE(Has(c, "c: the polygon has zero area (all vertices collinear)")) << c;
}

TEST(GeometryLimits, WktNonFiniteNumbersNameLineAndColumn) {
  std::string m = ErrorOf([] { ParseWkt("POLYGON ((0 0, 10 0,\n 10 nan, 0 10, 0 0))", "w"); });
  EXPECT_TRUE(Has(m, "w:2:5: invalid WKT: the number nan is not finite")) << m;
  m = ErrorOf([] { ParseWkt("POLYGON ((0 0, -inf 0, 10 10, 0 0))", "w"); });
  EXPECT_TRUE(Has(m, "w:1:16: invalid WKT: the number -inf is not finite")) << m;
  m = ErrorOf([] { ParseWkt("POLYGON ((0 0, 1e400 0, 10 10, 0 0))", "w"); });
  EXPECT_TRUE(Has(m, "w:1:16: invalid WKT: the number 1e400 is out of range")) << m;
}

TEST(GeometryLimits, VenueProblemsIncludeHugeCoordinates) {
  Venue v;
  v.origin = "v";
  v.walkable_area = {{{0, 0}, {1e300, 0}, {1e300, 1e300}, {0, 1e300}}};
  const auto problems = FindVenueProblems(v);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_TRUE(Has(problems[0], "v: /walkable_area/0/1: coordinate (1e+300, 0) is beyond 10000000 m")) << problems[0];
  // The importers validate the same way: nothing that `venue check` rejects is returned.
  const std::string m = ErrorOf([] { ParseWkt("POLYGON ((0 0, 1e300 0, 1e300 1e300, 0 0))", "w"); });
  EXPECT_TRUE(Has(m, "w: /walkable_area/0/1: coordinate (1e+300, 0) is beyond 10000000 m")) << m;
}

TEST(GeometryLimits, FoldersAreNamedAsFolders) {
  const auto dir = ScratchFile("folder.png");
  std::filesystem::create_directories(dir);
  EXPECT_TRUE(Has(ErrorOf([&] { ReadOutline(dir); }), "folder.png: is a directory; expected a picture file"));
  RasterImportOptions raster;
  raster.pixels_per_metre = 50;
  EXPECT_TRUE(Has(ErrorOf([&] { ImportRasterPlan(dir, raster); }), "folder.png: is a directory"));
  EXPECT_TRUE(Has(ErrorOf([&] { ImportWkt(dir); }), "folder.png: is a directory; expected a WKT file"));
  EXPECT_TRUE(Has(ErrorOf([&] { ImportDxf(dir); }), "folder.png: is a directory; expected a DXF file"));
  const auto csv = ScratchFile("folder.csv");
  std::filesystem::create_directories(csv);
  EXPECT_TRUE(Has(ErrorOf([&] { ReadOutline(csv); }), "folder.csv: is a directory; expected a point list (CSV)"));
}

TEST(GeometryLimits, PictureAbovePixelLimitIsRefusedFromItsHeader) {
  // A real 11000 x 10000 picture (110 megapixels, mostly one colour so small
  // on disk): refused before it is decoded.
  const auto file = ScratchFile("large.png");
  cv::Mat image(10000, 11000, CV_8UC1, cv::Scalar(255));
  ASSERT_TRUE(media::WriteImage(file.string(), image));
  const std::string m = ErrorOf([&] { ReadOutline(file); });
  EXPECT_TRUE(Has(m, "large.png: the picture is 11000 x 10000 pixels (110 megapixels); at most 100 megapixels")) << m;
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace crowdrecon::geometry
