#include <limits>

#include <gtest/gtest.h>

#include "test_util.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/json_reader.hpp"

namespace crowdrecon {
namespace {

using testing_util::ErrorOf;

TEST(JsonReader, SyntaxErrorNamesLineAndColumn) {
  const std::string msg = ErrorOf([] { JsonDocument::Parse("{\n  \"a\": 1,\n  \"b\": ]\n}", "x.json"); });
  EXPECT_NE(msg.find("x.json:3:"), std::string::npos) << msg;
}

TEST(JsonReader, OutOfRangeNamesPathValueAndRange) {
  const auto doc = JsonDocument::Parse(R"({"model": {"kn": -5}})", "s.json");
  const std::string msg = ErrorOf([&] { doc.Root().At("model").Number("kn", 1.0, 1e9); });
  EXPECT_NE(msg.find("s.json: /model/kn"), std::string::npos) << msg;
  EXPECT_NE(msg.find("-5"), std::string::npos) << msg;
  EXPECT_NE(msg.find("[1, 1000000000]"), std::string::npos) << msg;
}

TEST(JsonReader, UnknownKeysAreReported) {
  const auto doc = JsonDocument::Parse(R"({"width": 3, "lenght": 12})", "v.json");
  const JsonReader root = doc.Root();
  EXPECT_EQ(root.Number("width", 0, 10), 3.0);
  const std::string msg = ErrorOf([&] { root.Finish(); });
  EXPECT_NE(msg.find("\"lenght\""), std::string::npos) << msg;
  EXPECT_EQ(msg.find("\"width\""), std::string::npos) << msg;
}

TEST(JsonReader, PointsAndChoices) {
  const auto doc = JsonDocument::Parse(R"({"p": [[0, 1], [2, "x"]], "mode": "circle"})", "b.json");
  const JsonReader root = doc.Root();
  const std::string msg = ErrorOf([&] { root.At("p").AsPoints(2); });
  EXPECT_NE(msg.find("/p/1"), std::string::npos) << msg;
  EXPECT_EQ(root.Choice("mode", {"paper", "circle"}), "circle");
  const std::string msg2 = ErrorOf([&] { root.Choice("mode", {"paper"}); });
  EXPECT_NE(msg2.find("expected one of \"paper\""), std::string::npos) << msg2;
}

TEST(JsonReader, MissingFileIsAnError) {
  const std::string msg = ErrorOf([] { JsonDocument::Load("/nonexistent/venue.json"); });
  EXPECT_NE(msg.find("/nonexistent/venue.json: cannot open"), std::string::npos) << msg;
}

}  // namespace
}  // namespace crowdrecon

TEST(Format, NumbersAndDurations) {
  EXPECT_EQ(crowdrecon::FormatNumber(0.05), "0.05");
  EXPECT_EQ(crowdrecon::FormatNumber(1e5), "100000");
  EXPECT_EQ(crowdrecon::FormatDuration(42.4), "42s");
  EXPECT_EQ(crowdrecon::FormatDuration(187.0), "3m07s");
  EXPECT_EQ(crowdrecon::FormatDuration(3900.0), "1h05m");
  EXPECT_EQ(crowdrecon::FormatDuration(std::numeric_limits<double>::infinity()), "?");
}
