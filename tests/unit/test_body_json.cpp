// Body JSON: written, read back, validated.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "scratch.hpp"

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/body.hpp"

namespace crowdrecon::geometry {
namespace {

using crowdrecon::testing::ScratchFile;

Body SquareBody() {
  Outline outline;
  outline.source = "square";
  outline.points = {{0, 0}, {0.3, 0}, {0.3, 0.3}, {0, 0.3}};
  BodyOptions options;
  options.vertex_count = 4;
  return BuildBody(outline, options);
}

std::string ReadText(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void WriteText(const std::filesystem::path& file, const std::string& text) { std::ofstream(file) << text; }

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

std::string ErrorReading(const std::filesystem::path& file) {
  try {
    ReadBodyJson(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(BodyJson, RoundTrips) {
  const Body body = SquareBody();
  const auto file = ScratchFile("square.json");
  WriteBodyJson(body, file);
  const Body back = ReadBodyJson(file);
  ASSERT_EQ(back.shape.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(back.shape.vertices()[i], body.shape.vertices()[i]);
  EXPECT_EQ(back.shape.radius(), body.shape.radius());
  EXPECT_DOUBLE_EQ(back.shape.area(), body.shape.area());
  EXPECT_EQ(back.scale_rule, "none");
  EXPECT_EQ(back.source, "square");
  EXPECT_EQ(back.source_front, "+y");
  EXPECT_DOUBLE_EQ(back.hausdorff_m, body.hausdorff_m);
  EXPECT_EQ(back.outline_m.size(), body.outline_m.size());
}

TEST(BodyJson, RejectsUnknownKeysAndInconsistentFigures) {
  const auto file = ScratchFile("square.json");
  WriteBodyJson(SquareBody(), file);
  const std::string text = ReadText(file);

  const auto unknown = ScratchFile("unknown.json");
  WriteText(unknown, Replace(text, "\"format\"", "\"colour\": \"red\",\n \"format\""));
  const std::string e1 = ErrorReading(unknown);
  EXPECT_NE(e1.find("unknown.json"), std::string::npos) << e1;
  EXPECT_NE(e1.find("colour"), std::string::npos) << e1;

  const auto area = ScratchFile("area.json");
  WriteText(area, Replace(text, "\"area_m2\": 0.", "\"area_m2\": 0.9"));
  const std::string e2 = ErrorReading(area);
  EXPECT_NE(e2.find("area.json: /area_m2: stored value"), std::string::npos) << e2;
  EXPECT_NE(e2.find("does not match the shape"), std::string::npos) << e2;

  const auto front = ScratchFile("front.json");
  WriteText(front, Replace(text, "\"front_axis\": \"+x\"", "\"front_axis\": \"+y\""));
  EXPECT_NE(ErrorReading(front).find("/front_axis"), std::string::npos);

  const auto radius = ScratchFile("radius.json");
  WriteText(radius, Replace(text, "\"radius_m\": 0.05", "\"radius_m\": -0.05"));
  EXPECT_NE(ErrorReading(radius).find("/radius_m"), std::string::npos);
}

}  // namespace
}  // namespace crowdrecon::geometry
