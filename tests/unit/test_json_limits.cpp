// The limits and checks of JSON parsing (common/src/json_parse.cpp): nesting,
// duplicate keys, numbers beyond a double, huge integers, long keys and
// values echoed in messages, directories given as files.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "test_util.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/json_reader.hpp"

namespace crowdrecon {
namespace {

using testing_util::ErrorOf;

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::string Nested(std::size_t depth) { return std::string(depth, '[') + std::string(depth, ']'); }

TEST(JsonLimits, DeepNestingIsRefusedWithPosition) {
  const std::string msg = ErrorOf([] { JsonDocument::Parse("{\"a\": " + Nested(100000) + "}", "deep.json"); });
  EXPECT_TRUE(Contains(msg, "deep.json:1:")) << msg;
  EXPECT_TRUE(Contains(msg, "nested more than 100 levels")) << msg;
  EXPECT_LT(msg.size(), 400u) << msg;
}

TEST(JsonLimits, NestingUpToTheLimitIsAccepted) {
  const JsonDocument doc = JsonDocument::Parse(Nested(100), "ok.json");
  EXPECT_EQ(doc.Root().Size(), 1u);
  EXPECT_NE(ErrorOf([] { JsonDocument::Parse(Nested(101), "x.json"); }), "(no error)");
}

TEST(JsonLimits, ValueTextIsShortOnDeepAndWideValues) {
  const JsonDocument doc =
      JsonDocument::Parse("{\"a\": " + Nested(99) + ", \"b\": [\"" + std::string(1'000'000, 'x') + "\"]}", "v.json");
  EXPECT_LE(doc.Root().At("a").ValueText().size(), 60u);
  const std::string msg = ErrorOf([&] { doc.Root().At("a").AsString(); });
  EXPECT_TRUE(Contains(msg, "v.json: /a: expected a string, found [[[[")) << msg;
  EXPECT_LE(doc.Root().At("b").ValueText().size(), 60u);
}

TEST(JsonLimits, DuplicateKeyNamesPathBothValuesAndLines) {
  const std::string msg = ErrorOf([] {
    JsonDocument::Parse("{\n \"run\": {\n  \"duration_s\": 0.5,\n  \"duration_s\": 0.2\n }\n}", "dup.json");
  });
  EXPECT_TRUE(Contains(msg, "dup.json:4:")) << msg;
  EXPECT_TRUE(Contains(msg, "/run/duration_s: key given twice")) << msg;
  EXPECT_TRUE(Contains(msg, "line 3 with value 0.5")) << msg;
  EXPECT_TRUE(Contains(msg, "line 4 with value 0.2")) << msg;
}

TEST(JsonLimits, DuplicateKeyWithObjectValues) {
  const std::string msg =
      ErrorOf([] { JsonDocument::Parse(R"({"a": {"x": 1}, "b": 2, "a": {"y": [1, 2]}})", "dup2.json"); });
  EXPECT_TRUE(Contains(msg, "/a: key given twice")) << msg;
  EXPECT_TRUE(Contains(msg, "{\"x\": 1}")) << msg;
  EXPECT_TRUE(Contains(msg, "{\"y\": [1, 2]}")) << msg;
}

TEST(JsonLimits, SameKeyInDifferentObjectsIsFine) {
  const JsonDocument doc = JsonDocument::Parse(R"({"a": {"x": 1}, "b": {"x": 2}, "c": [{"x": 3}, {"x": 4}]})", "ok.json");
  EXPECT_EQ(doc.Root().At("b").Number("x", 0, 10), 2.0);
  EXPECT_EQ(doc.Root().At("c").Element(1).Number("x", 0, 10), 4.0);
}

TEST(JsonLimits, NumberBeyondDoubleIsAnInputErrorWithPosition) {
  const std::string msg = ErrorOf([] { JsonDocument::Parse("{\n  \"x\": 1e400\n}", "big.json"); });
  EXPECT_TRUE(Contains(msg, "big.json:2:")) << msg;
  EXPECT_TRUE(Contains(msg, "1e400")) << msg;
  EXPECT_TRUE(Contains(msg, "expected a finite number")) << msg;
}

TEST(JsonLimits, HugeUnsignedIntegerIsReportedAsWritten) {
  const JsonDocument doc = JsonDocument::Parse(R"({"count": 18446744073709551615})", "n.json");
  const std::string msg = ErrorOf([&] { doc.Root().Integer("count", 1, 200000); });
  EXPECT_TRUE(Contains(msg, "value 18446744073709551615 is out of range")) << msg;
  EXPECT_TRUE(Contains(msg, "[1, 200000]")) << msg;
  EXPECT_FALSE(Contains(msg, "-1")) << msg;
}

TEST(JsonLimits, LongUnknownKeyIsShortened) {
  const std::string key(10'000'000, 'k');
  const JsonDocument doc = JsonDocument::Parse("{\"" + key + "\": 1}", "k.json");
  const std::string msg = ErrorOf([&] { doc.Root().Finish(); });
  EXPECT_TRUE(Contains(msg, "unknown key(s) \"kkkk")) << msg.substr(0, 200);
  EXPECT_LT(msg.size(), 200u);
}

TEST(JsonLimits, LongChoiceValueIsShortened) {
  const JsonDocument doc = JsonDocument::Parse("{\"mode\": \"" + std::string(100000, 'x') + "\"}", "c.json");
  const std::string msg = ErrorOf([&] { doc.Root().Choice("mode", {"paper"}); });
  EXPECT_TRUE(Contains(msg, "...\"; expected one of \"paper\"")) << msg.substr(0, 200);
  EXPECT_LT(msg.size(), 200u);
}

TEST(JsonLimits, SyntaxErrorsStillNameLineAndColumn) {
  const std::string msg = ErrorOf([] { JsonDocument::Parse("{\n  \"a\": tru\n}", "s.json"); });
  EXPECT_TRUE(Contains(msg, "s.json:2:")) << msg;
  EXPECT_TRUE(Contains(msg, "invalid JSON")) << msg;
}

TEST(JsonLimits, ShortTextKeepsUtf8Whole) {
  const std::string text = std::string(56, 'a') + "\xc3\xa9\xc3\xa9\xc3\xa9";  // 56 + 3 two-byte letters
  const std::string s = ShortText(text, 60);
  EXPECT_EQ(s, std::string(56, 'a') + "...");
  EXPECT_EQ(ShortText("short", 60), "short");
}

TEST(InputFile, DirectoryIsNamedAsSuch) {
  const auto dir = std::filesystem::temp_directory_path();
  const std::string msg = ErrorOf([&] { JsonDocument::Load(dir); });
  EXPECT_TRUE(Contains(msg, dir.string() + ": is a directory; expected a JSON file")) << msg;
  EXPECT_TRUE(Contains(ErrorOf([&] { ReadInputFile(dir, "WKT file"); }), "is a directory; expected a WKT file"));
  // A description with its own article keeps it (issue 65: "expected a the test's scenario").
  EXPECT_TRUE(Contains(ErrorOf([&] { ReadInputFile(dir, "the test's scenario"); }), "is a directory; expected the test's scenario"));
}

TEST(InputFile, MissingFileNamesTheReason) {
  const std::string msg = ErrorOf([] { ReadInputFile("/nonexistent/x.wkt", "WKT file"); });
  EXPECT_TRUE(Contains(msg, "/nonexistent/x.wkt: cannot open WKT file for reading (No such file or directory)")) << msg;
}

}  // namespace
}  // namespace crowdrecon
