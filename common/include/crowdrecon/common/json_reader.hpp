// JsonReader: reads configuration files (venues, bodies, scenarios) so that
// every error names the file, the JSON path (RFC 6901 pointer), the value found
// and what was expected, and so that keys nobody read are reported as errors
// (in the manner of pbrt's ParameterDictionary).
//
//   JsonDocument doc = JsonDocument::Load("venue.json");
//   JsonReader root = doc.Root();
//   double w = root.Number("width_m", 0.1, 1000.0);   // required, range-checked
//   root.Finish();                                     // unknown keys -> error
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon {

class JsonReader;

// A name safe in file and folder names: 1 to 64 letters, digits, '.', '_' or '-'.
bool IsPlainName(std::string_view name);

// A parsed JSON file (or string) that owns its data.
class JsonDocument {
 public:
  // Parses a file; a syntax error names the file, line and column.
  static JsonDocument Load(const std::filesystem::path& file);
  // Parses text; `origin` stands in for the file name in messages.
  static JsonDocument Parse(std::string_view text, std::string origin);

  JsonReader Root() const;
  const std::string& origin() const { return origin_; }
  // The parsed value itself, for code that copies or edits raw JSON (sweeps).
  const nlohmann::json& Json() const { return *json_; }

 private:
  std::shared_ptr<const nlohmann::json> json_;
  std::string origin_;
};

// A read-only view of one JSON value, with the place it came from.
class JsonReader {
 public:
  JsonReader(std::shared_ptr<const nlohmann::json> root, const nlohmann::json* value,
             std::string origin, std::string path);

  const std::string& path() const { return path_; }
  const std::string& origin() const { return origin_; }
  // "file: /json/path" for messages.
  std::string Where() const;
  // Throws InputError "file: /path: message".
  [[noreturn]] void Fail(const std::string& message) const;
  // Short rendering of the value for messages (truncated).
  std::string ValueText() const;

  bool IsObject() const;
  bool IsArray() const;
  bool IsNumber() const;
  bool IsString() const;
  bool IsNull() const;

  // --- objects ---------------------------------------------------------
  bool Has(std::string_view key) const;
  // Required member (error if absent). Marks the key as read.
  JsonReader At(std::string_view key) const;
  std::optional<JsonReader> Find(std::string_view key) const;
  // Required number within [min, max].
  double Number(std::string_view key, double min, double max) const;
  // Optional number with default, within [min, max].
  double Number(std::string_view key, double fallback, double min, double max) const;
  // Required integer within [min, max].
  long long Integer(std::string_view key, long long min, long long max) const;
  long long Integer(std::string_view key, long long fallback, long long min, long long max) const;
  std::string String(std::string_view key) const;
  std::string String(std::string_view key, std::string fallback) const;
  // A string that must be one of `allowed`.
  std::string Choice(std::string_view key, const std::vector<std::string>& allowed) const;
  std::string Choice(std::string_view key, std::string fallback,
                     const std::vector<std::string>& allowed) const;
  bool Bool(std::string_view key, bool fallback) const;
  // Error naming every key of this object that was never read.
  void Finish() const;
  // Keys of this object, in file order.
  std::vector<std::string> Keys() const;

  // --- arrays ----------------------------------------------------------
  std::size_t Size() const;
  JsonReader Element(std::size_t index) const;

  // --- this value ------------------------------------------------------
  double AsNumber(double min, double max) const;
  std::string AsString() const;
  // A string that IsPlainName (a profile's, a validation test's, a case's name).
  std::string AsName() const;
  // The value as parsed, for code that copies raw JSON on (overrides, profiles).
  const nlohmann::json& Raw() const { return *value_; }
  // [x, y]
  Vec2 AsPoint() const;
  // [[x, y], ...] with at least `min_count` points.
  std::vector<Vec2> AsPoints(std::size_t min_count) const;

 private:
  JsonReader Child(std::string_view key, const nlohmann::json* value) const;
  void MarkUsed(std::string_view key) const;

  std::shared_ptr<const nlohmann::json> root_;
  const nlohmann::json* value_;
  std::string origin_;
  std::string path_;
  std::shared_ptr<std::set<std::string, std::less<>>> used_;
};

}  // namespace crowdrecon
