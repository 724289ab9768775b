// Outline -> body: the image and point-list paths against a known ellipse,
// scaling rules, the canonical frame and every invalid-outline error.
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "scratch.hpp"
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "crowdrecon/media/media.hpp"  // imread/imwrite/video through the codecs module (tests start without it)

#include "test_util.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/body.hpp"
#include "crowdrecon/geometry/outline.hpp"

namespace crowdrecon::geometry {
namespace {

using testing_util::ErrorOf;

const std::string kBodyData = std::string(CROWDRECON_SOURCE_DIR) + "/tests/data/bodies/";
constexpr double kA = 0.25, kB = 0.15;  // semi-axes, m: across the shoulders, front-back
const double kEllipseArea = std::numbers::pi * kA * kB;

using crowdrecon::testing::ScratchFile;

// The ellipse drawn dark on white at 1000 px/m, front (+y, semi-axis kB) up,
// with 1/16 px precision. Not anti-aliased: OpenCV draws a filled LINE_AA
// ellipse with an extra half-pixel fringe (0.6% too much area here).
std::filesystem::path EllipseImage() {
  const auto file = ScratchFile("ellipse.png");
  cv::Mat image(500, 700, CV_8UC1, cv::Scalar(255));
  cv::ellipse(image, cv::Point(350 * 16, 250 * 16), cv::Size(250 * 16, 150 * 16), 0, 0, 360,
              cv::Scalar(0), cv::FILLED, cv::LINE_8, 4);
  EXPECT_TRUE(media::WriteImage(file.string(), image));
  return file;
}

Outline EllipsePoints(double a = kA, double b = kB, int n = 720) {
  Outline outline;
  outline.source = "ellipse";
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * std::numbers::pi * i / n;
    outline.points.push_back({a * std::cos(t), b * std::sin(t)});
  }
  return outline;
}

TEST(Outline, ImageOfEllipseBecomesFaithfulBody) {
  const Outline outline = ReadOutline(EllipseImage());
  EXPECT_TRUE(outline.from_image);
  BodyOptions options;
  options.scale = ScaleRule::PixelsPerMetre(1000);
  const Body body = BuildBody(outline, options);
  EXPECT_EQ(body.shape.size(), 18u);
  EXPECT_DOUBLE_EQ(body.shape.radius(), 0.05);
  EXPECT_NEAR(body.shape.area(), kEllipseArea, 0.01 * kEllipseArea);
  EXPECT_GE(body.hausdorff_m, 0.0);
  EXPECT_LT(body.hausdorff_m, 0.01);
  // Canonical frame: centroid at the origin, front (image up) along +x.
  EXPECT_NEAR(Length(body.shape.centroid()), 0.0, 1e-9);
  EXPECT_NEAR(body.shape.BoundsMax().x - body.shape.BoundsMin().x, 2 * kB, 0.01);
  EXPECT_NEAR(body.shape.BoundsMax().y - body.shape.BoundsMin().y, 2 * kA, 0.01);
}

TEST(Outline, PointListGivesTheSameBodyAsTheImage) {
  BodyOptions options;
  const Body from_points = BuildBody(EllipsePoints(), options);
  EXPECT_EQ(from_points.shape.size(), 18u);
  EXPECT_NEAR(from_points.shape.area(), kEllipseArea, 0.01 * kEllipseArea);
  EXPECT_LT(from_points.hausdorff_m, 0.01);
  options.scale = ScaleRule::PixelsPerMetre(1000);
  const Body from_image = BuildBody(ReadOutline(EllipseImage()), options);
  EXPECT_NEAR(from_image.shape.area(), from_points.shape.area(), 0.01 * kEllipseArea);
  EXPECT_NEAR(from_image.shape.polar_moment(), from_points.shape.polar_moment(),
              0.01 * from_points.shape.polar_moment());
}

TEST(Outline, CsvAndJsonPointListsAreRead) {
  const auto csv = ScratchFile("square.csv");
  {
    std::FILE* f = std::fopen(csv.c_str(), "w");
    std::fputs("x,y\n# a square\n0,0\n0.4,0\n\n0.4,0.4\n0,0.4\n0,0\n", f);
    std::fclose(f);
  }
  const Outline from_csv = ReadOutline(csv);
  EXPECT_EQ(from_csv.points.size(), 4u);  // closing repeat dropped
  const auto json = ScratchFile("square.json");
  {
    std::FILE* f = std::fopen(json.c_str(), "w");
    std::fputs("{\"front\": \"-x\", \"points\": [[0,0],[0,0.4],[0.4,0.4],[0.4,0]]}", f);
    std::fclose(f);
  }
  const Outline from_json = ReadOutline(json);
  ASSERT_EQ(from_json.points.size(), 4u);
  EXPECT_GT(SignedArea(from_json.points), 0.0);  // clockwise input made counter-clockwise
  ASSERT_TRUE(from_json.front.has_value());
  EXPECT_EQ(*from_json.front, FrontAxis::kMinusX);
}

TEST(Outline, ScalingRulesGiveTheStatedSize) {
  BodyOptions options;
  options.scale = ScaleRule::Sternum(0.20);
  const Body sternum = BuildBody(EllipsePoints(), options);
  EXPECT_NEAR(sternum.metres_per_unit, 0.20 / (2 * kB), 1e-9);
  EXPECT_NEAR(DepthAlongAxisThroughCentroid(sternum.outline_m, {1, 0}), 0.20, 5e-4);
  options.scale = ScaleRule::Shoulder(0.45);
  const Body shoulder = BuildBody(EllipsePoints(), options);
  EXPECT_NEAR(ExtentAlongAxis(shoulder.outline_m, {0, 1}), 0.45, 5e-4);
  EXPECT_NEAR(shoulder.shape.BoundsMax().y - shoulder.shape.BoundsMin().y, 0.45, 0.01);
  options.scale = ScaleRule::PixelsPerMetre(1000);
  const Body ppm = BuildBody(EllipsePoints(250, 150), options);
  EXPECT_NEAR(ppm.shape.area(), kEllipseArea, 0.01 * kEllipseArea);
}

TEST(Outline, ScaleRuleTextRoundTrips) {
  EXPECT_EQ(ToString(ScaleRuleFromString("sternum:0.2")), "sternum:0.2");
  EXPECT_EQ(ToString(ScaleRuleFromString("shoulder:0.45")), "shoulder:0.45");
  EXPECT_EQ(ToString(ScaleRuleFromString("ppm:1000")), "ppm:1000");
  EXPECT_EQ(ToString(ScaleRuleFromString("none")), "none");
}

TEST(Outline, FrontAxisBecomesPlusX) {
  // A house: the roof's apex (0, 0.25) is the front (+y).
  Outline house;
  house.source = "house";
  house.points = {{-0.2, -0.15}, {0.2, -0.15}, {0.2, 0.1}, {0, 0.25}, {-0.2, 0.1}};
  for (const auto& [front, apex] : std::vector<std::pair<FrontAxis, Vec2>>{
           {FrontAxis::kPlusY, {0, 0.25}}, {FrontAxis::kMinusY, {0, -0.25}},
           {FrontAxis::kPlusX, {0.25, 0}}, {FrontAxis::kMinusX, {-0.25, 0}}}) {
    Outline o = house;
    // Rotate the house so its apex lies along `apex`, and say so.
    const double angle = std::atan2(apex.y, apex.x) - std::numbers::pi / 2;
    for (Vec2& p : o.points) p = Rotated(p, angle);
    BodyOptions options;
    options.radius_m = 0.02;
    options.front = front;
    const Body body = BuildBody(o, options);
    Vec2 frontmost = body.outline_m.front();
    for (const Vec2& p : body.outline_m)
      if (p.x > frontmost.x) frontmost = p;
    EXPECT_NEAR(frontmost.y, 0.0, 1e-9) << ToString(front);
    EXPECT_GT(frontmost.x, -body.shape.BoundsMin().x - 0.05) << ToString(front);
    EXPECT_NEAR(Length(body.shape.centroid()), 0.0, 1e-9);
  }
}

TEST(Outline, InvalidOutlinesGiveClearErrors) {
  EXPECT_NE(ErrorOf([] { ReadOutline(kBodyData + "empty.png"); }).find("not a readable image"),
            std::string::npos);
  const std::string no_region = ErrorOf([] { ReadOutline(kBodyData + "blank.png"); });
  EXPECT_NE(no_region.find("blank.png: no dark region"), std::string::npos) << no_region;
  EXPECT_NE(ErrorOf([] { ReadOutline(kBodyData + "two-points.csv"); }).find("too few points (2 distinct)"),
            std::string::npos);
  const std::string bowtie = ErrorOf([] { ReadOutline(kBodyData + "bowtie.json"); });
  EXPECT_NE(bowtie.find("bowtie.json: the outline intersects itself (edge 0"), std::string::npos) << bowtie;
  const std::string thin =
      ErrorOf([] { BuildBody(ReadOutline(kBodyData + "thin-strip.json"), BodyOptions{}); });
  EXPECT_NE(thin.find("thin-strip.json: outline too thin for the sphero-radius (0.05 m)"),
            std::string::npos) << thin;
  BodyOptions two_vertices;
  two_vertices.vertex_count = 2;
  EXPECT_NE(ErrorOf([&] { BuildBody(EllipsePoints(), two_vertices); })
                .find("ellipse: vertex count (2) is too small; expected at least 3"),
            std::string::npos);
  BodyOptions negative;
  negative.radius_m = -0.05;
  EXPECT_NE(ErrorOf([&] { BuildBody(EllipsePoints(), negative); })
                .find("sphero-radius (-0.05 m) must be positive"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { ScaleRuleFromString("width:0.3", "--scale"); })
                .find("--scale: unknown scale rule \"width\""),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { ScaleRuleFromString("sternum:-1", "--scale"); }).find("not a positive number"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { ReadOutline(kBodyData + "missing.json"); }).find("missing.json: cannot open file"),
            std::string::npos);
  const std::string bad_json = ErrorOf([] { ReadOutline(kBodyData + "bad-syntax.json"); });
  EXPECT_NE(bad_json.find("bad-syntax.json:2:1: invalid JSON"), std::string::npos) << bad_json;
  BodyOptions no_scale;  // an image in pixels needs a rule
  EXPECT_NE(ErrorOf([&] { BuildBody(ReadOutline(EllipseImage()), no_scale); }).find("needs a scale rule"),
            std::string::npos);
}

}  // namespace
}  // namespace crowdrecon::geometry
