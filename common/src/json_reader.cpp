#include "crowdrecon/common/json_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "json_parse.hpp"

namespace crowdrecon {

JsonDocument JsonDocument::Load(const std::filesystem::path& file) {
  return Parse(ReadInputFile(file, "JSON file"), file.string());
}

JsonDocument JsonDocument::Parse(std::string_view text, std::string origin) {
  JsonDocument doc;
  doc.origin_ = std::move(origin);
  doc.json_ = std::make_shared<const nlohmann::json>(detail::ParseJsonText(text, doc.origin_));
  return doc;
}

JsonReader JsonDocument::Root() const { return JsonReader(json_, json_.get(), origin_, ""); }

JsonReader::JsonReader(std::shared_ptr<const nlohmann::json> root, const nlohmann::json* value,
                       std::string origin, std::string path)
    : root_(std::move(root)),
      value_(value),
      origin_(std::move(origin)),
      path_(std::move(path)),
      used_(std::make_shared<std::set<std::string, std::less<>>>()) {}

std::string JsonReader::Where() const { return origin_ + ": " + (path_.empty() ? "/" : path_); }

void JsonReader::Fail(const std::string& message) const { throw InputError(Where() + ": " + message); }

std::string JsonReader::ValueText() const {
  return detail::SketchJson(*value_);
}

bool JsonReader::IsObject() const { return value_->is_object(); }
bool JsonReader::IsArray() const { return value_->is_array(); }
bool JsonReader::IsNumber() const { return value_->is_number(); }
bool JsonReader::IsString() const { return value_->is_string(); }
bool JsonReader::IsNull() const { return value_->is_null(); }

JsonReader JsonReader::Child(std::string_view key, const nlohmann::json* value) const {
  return JsonReader(root_, value, origin_, path_ + "/" + detail::EscapeToken(key));
}

void JsonReader::MarkUsed(std::string_view key) const { used_->emplace(key); }

bool JsonReader::Has(std::string_view key) const {
  return value_->is_object() && value_->contains(key);
}

std::optional<JsonReader> JsonReader::Find(std::string_view key) const {
  if (!value_->is_object()) Fail("expected an object, found " + ValueText());
  const auto it = value_->find(key);
  if (it == value_->end()) return std::nullopt;
  MarkUsed(key);
  return Child(key, &*it);
}

JsonReader JsonReader::At(std::string_view key) const {
  auto child = Find(key);
  if (!child) Fail("missing required key \"" + std::string(key) + "\"");
  return *child;
}

double JsonReader::AsNumber(double min, double max) const {
  if (!value_->is_number())
    Fail("expected a number in [" + FormatNumber(min) + ", " + FormatNumber(max) + "], found " +
         ValueText());
  const double v = value_->get<double>();
  if (!std::isfinite(v) || v < min || v > max)
    Fail("value " + FormatNumber(v) + " is out of range; expected a number in [" +
         FormatNumber(min) + ", " + FormatNumber(max) + "]");
  return v;
}

double JsonReader::Number(std::string_view key, double min, double max) const {
  return At(key).AsNumber(min, max);
}

double JsonReader::Number(std::string_view key, double fallback, double min, double max) const {
  auto child = Find(key);
  return child ? child->AsNumber(min, max) : fallback;
}

long long JsonReader::Integer(std::string_view key, long long min, long long max) const {
  const JsonReader child = At(key);
  const std::string expected = "expected an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  if (!child.value_->is_number_integer()) child.Fail(expected + ", found " + child.ValueText());
  // An unsigned value above the range of long long (18446744073709551615) is
  // reported as written, not wrapped to a negative number.
  if (child.value_->is_number_unsigned() &&
      child.value_->get<unsigned long long>() > static_cast<unsigned long long>(max))
    child.Fail("value " + std::to_string(child.value_->get<unsigned long long>()) + " is out of range; " + expected);
  const long long v = child.value_->get<long long>();
  if (v < min || v > max) child.Fail("value " + std::to_string(v) + " is out of range; " + expected);
  return v;
}

long long JsonReader::Integer(std::string_view key, long long fallback, long long min,
                              long long max) const {
  return Has(key) ? Integer(key, min, max) : fallback;
}

std::string JsonReader::AsString() const {
  if (!value_->is_string()) Fail("expected a string, found " + ValueText());
  return value_->get<std::string>();
}

bool IsPlainName(std::string_view name) {
  return !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '_' || ch == '-';
  });
}

std::string JsonReader::AsName() const {
  std::string name = AsString();
  if (!IsPlainName(name)) Fail("expected letters, digits, '.', '_' or '-' (at most 64)");
  return name;
}

std::string JsonReader::String(std::string_view key) const { return At(key).AsString(); }

std::string JsonReader::String(std::string_view key, std::string fallback) const {
  auto child = Find(key);
  return child ? child->AsString() : fallback;
}

std::string JsonReader::Choice(std::string_view key, const std::vector<std::string>& allowed) const {
  const JsonReader child = At(key);
  const std::string v = child.AsString();
  if (std::find(allowed.begin(), allowed.end(), v) == allowed.end()) {
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "\"" : ", \"") + a + "\"";
    child.Fail("unknown value \"" + ShortText(v) + "\"; expected one of " + list);
  }
  return v;
}

std::string JsonReader::Choice(std::string_view key, std::string fallback,
                               const std::vector<std::string>& allowed) const {
  return Has(key) ? Choice(key, allowed) : fallback;
}

bool JsonReader::Bool(std::string_view key, bool fallback) const {
  auto child = Find(key);
  if (!child) return fallback;
  if (!child->value_->is_boolean()) child->Fail("expected true or false, found " + child->ValueText());
  return child->value_->get<bool>();
}

std::vector<std::string> JsonReader::Keys() const {
  std::vector<std::string> keys;
  if (value_->is_object())
    for (auto it = value_->begin(); it != value_->end(); ++it) keys.push_back(it.key());
  return keys;
}

void JsonReader::Finish() const {
  if (!value_->is_object()) return;
  std::string unknown;
  for (const auto& key : Keys())
    if (!used_->contains(key)) unknown += (unknown.empty() ? "\"" : ", \"") + ShortText(key) + "\"";
  if (!unknown.empty()) Fail("unknown key(s) " + unknown + " (misspelt or not supported here)");
}

std::size_t JsonReader::Size() const {
  if (!value_->is_array()) Fail("expected an array, found " + ValueText());
  return value_->size();
}

JsonReader JsonReader::Element(std::size_t index) const {
  if (!value_->is_array()) Fail("expected an array, found " + ValueText());
  if (index >= value_->size()) Fail("index " + std::to_string(index) + " out of range");
  return JsonReader(root_, &(*value_)[index], origin_, path_ + "/" + std::to_string(index));
}

Vec2 JsonReader::AsPoint() const {
  if (!value_->is_array() || value_->size() != 2 || !(*value_)[0].is_number() ||
      !(*value_)[1].is_number())
    Fail("expected a point [x, y] of two numbers, found " + ValueText());
  const Vec2 p{(*value_)[0].get<double>(), (*value_)[1].get<double>()};
  if (!std::isfinite(p.x) || !std::isfinite(p.y)) Fail("point coordinates must be finite");
  return p;
}

std::vector<Vec2> JsonReader::AsPoints(std::size_t min_count) const {
  const std::size_t n = Size();
  if (n < min_count)
    Fail("expected at least " + std::to_string(min_count) + " points [[x, y], ...], found " +
         std::to_string(n));
  std::vector<Vec2> points;
  points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) points.push_back(Element(i).AsPoint());
  return points;
}

}  // namespace crowdrecon
