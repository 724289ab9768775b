#include "crowdrecon/scenario/profile.hpp"

#include <algorithm>
#include <cctype>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/json_reader.hpp"
#include "crowdrecon/engine/parameter_table.hpp"
#include "crowdrecon/scenario/scenario.hpp"

namespace crowdrecon::scenario {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

bool EndsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

fs::path ProfilesFolder() { return DataDirectory() / "venues" / "profiles"; }

}  // namespace

bool IsProfileName(const std::string& name_or_file) {
  return IsPlainName(name_or_file) && !EndsWith(name_or_file, ".json");
}

fs::path ProfilePath(const std::string& name_or_file, const fs::path& base_dir) {
  if (IsProfileName(name_or_file)) return ProfilesFolder() / (name_or_file + ".json");
  const fs::path p(name_or_file);
  return p.is_absolute() ? p : (base_dir / p).lexically_normal();
}

ModelProfile ParseModelProfile(const std::string& text, const std::string& origin, const fs::path& base_dir) {
  const JsonDocument doc = JsonDocument::Parse(text, origin);
  const JsonReader r = doc.Root();
  if (!r.IsObject()) r.Fail("expected a profile object");
  if (r.String("format") != "crowdrecon-profile") r.At("format").Fail("expected \"crowdrecon-profile\"");
  r.Integer("version", 1, 1);
  ModelProfile p;
  p.name = r.At("name").AsName();
  p.description = r.String("description", "");
  if (const auto model = r.Find("model")) {
    if (!model->IsObject()) model->Fail("expected the scenario's model block {\"key\": value, ...}");
    for (const std::string& key : model->Keys()) {
      // Checked here, against the parameter table, so that a bad key or value
      // is blamed on the profile (issue 65, K03, K10: it was blamed on every
      // scenario that uses it, which does not have it).
      const JsonReader value = model->At(key);
      const engine::ParameterInfo* info = engine::FindModelParameter(key);
      if (info == nullptr) value.Fail("unknown model parameter; expected one of the parameter table's (docs/model.md)");
      switch (info->kind) {
        case engine::ParameterInfo::Kind::kNumber: value.AsNumber(info->min, info->max); break;
        case engine::ParameterInfo::Kind::kFlag: (void)model->Bool(key, false); break;
        case engine::ParameterInfo::Kind::kChoice: {
          const std::vector<std::string> allowed(info->choices, info->choices + info->choice_count);
          if (std::find(allowed.begin(), allowed.end(), value.AsString()) == allowed.end())
            value.Fail("\"" + value.AsString() + "\"; expected " + info->Expected());
          break;
        }
      }
      p.model.emplace_back(key, value.Raw().dump());
    }
  }
  if (const auto body = r.Find("body")) {
    if (!body->IsObject()) body->Fail("expected the scenario's body block {\"mode\": ..., ...}");
    json b = body->Raw();
    // File paths resolve against the profile's folder.
    for (const char* key : {"reference", "anthropometry"})
      if (b.contains(key) && b[key].is_string())
        b[key] = fs::absolute(base_dir / b[key].get<std::string>()).lexically_normal().string();
    for (const std::string& key : body->Keys()) body->At(key);  // (checked by the scenario reader)
    p.body_json = b.dump();
  }
  if (const auto v0 = r.Find("desired_speed_m_per_s")) {
    const Vec2 range = v0->AsPoint();
    if (!(range.x >= 0.0 && range.x <= range.y && range.y <= 10.0))
      v0->Fail("expected [low, high] m/s with 0 <= low <= high <= 10");
    p.desired_speed_m_per_s = std::make_pair(range.x, range.y);
  }
  r.Finish();
  p.canonical_json = doc.Json().dump();
  return p;
}

ModelProfile LoadModelProfile(const fs::path& file) {
  ModelProfile p = ParseModelProfile(ReadInputFile(file, "profile"), file.string(), file.parent_path());
  p.file = fs::absolute(file).lexically_normal();
  return p;
}

std::vector<std::string> NamedProfiles() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(ProfilesFolder(), ec))
    if (e.is_regular_file() && e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace crowdrecon::scenario
