#include "crowdrecon/sweep/sweep_file.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/json_reader.hpp"

namespace crowdrecon::sweep {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Scenario keys that hold file paths. A relative path given in an override is
// relative to the sweep file (where the user wrote it), not to the scenario.
const std::vector<std::string> kFileKeys = {"venue", "population.body.reference", "population.body.anthropometry"};

std::vector<std::string> SplitPath(const std::string& path) {
  std::vector<std::string> parts;
  std::string part;
  for (char c : path) {
    if (c == '.') {
      parts.push_back(part);
      part.clear();
    } else {
      part += c;
    }
  }
  parts.push_back(part);
  return parts;
}


// The raw JSON value a reader stands for (JsonReader keeps it private; its
// path is an RFC 6901 pointer into the same document).
const json& Raw(const json& document, const JsonReader& reader) {
  return document.at(json::json_pointer(reader.path()));
}

// A dotted scenario path: non-empty names separated by dots.
std::string DottedPath(const JsonReader& reader) {
  const std::string path = reader.AsString();
  for (const std::string& part : SplitPath(path))
    if (part.empty())
      reader.Fail("\"" + path + "\" is not a scenario path; expected names separated by dots, e.g. "
                  "\"population.density_per_m2\"");
  return path;
}

std::vector<Override> ReadOverrides(const json& document, const JsonReader& set) {
  if (!set.IsObject()) set.Fail("expected an object {\"scenario.path\": value, ...}, found " + set.ValueText());
  std::vector<Override> overrides;
  for (const std::string& key : set.Keys()) {
    const JsonReader value = set.At(key);
    for (const std::string& part : SplitPath(key))
      if (part.empty())
        value.Fail("\"" + key + "\" is not a scenario path; expected names separated by dots, e.g. "
                   "\"model.back_force_gamma\"");
    overrides.push_back({key, Raw(document, value).dump()});
  }
  return overrides;
}

Axis ReadAxis(const json& document, const JsonReader& item) {
  if (!item.IsObject()) item.Fail("expected an axis {\"path\": ..., \"values\": [...]}, found " + item.ValueText());
  Axis axis;
  axis.path = DottedPath(item.At("path"));
  const bool listed = item.Has("values");
  const bool ranged = item.Has("from") || item.Has("to") || item.Has("count");
  if (listed == ranged)
    item.Fail("give either \"values\": [...] or \"from\", \"to\" and \"count\"");
  if (listed) {
    const JsonReader values = item.At("values");
    const std::size_t n = values.Size();
    if (n == 0) values.Fail("expected at least one value");
    bool numeric = true;
    for (std::size_t i = 0; i < n; ++i) {
      const json& v = Raw(document, values.Element(i));
      axis.values.push_back(v.dump());
      if (v.is_number()) axis.numbers.push_back(v.get<double>());
      else numeric = false;
    }
    if (!numeric) axis.numbers.clear();
  } else {
    const double from = item.Number("from", -1e300, 1e300);
    const double to = item.Number("to", -1e300, 1e300);
    const auto count = static_cast<std::size_t>(item.Integer("count", 1, 100000));
    if (count == 1 && from != to)
      item.At("count").Fail("count 1 with from (" + FormatNumber(from) + ") != to (" + FormatNumber(to) +
                            "); expected count >= 2, or from == to");
    // Whole numbers stay whole (JSON integers) where both ends are integers:
    // "population.count" takes integers only.
    const bool integers = Raw(document, item.At("from")).is_number_integer() &&
                          Raw(document, item.At("to")).is_number_integer();
    for (std::size_t i = 0; i < count; ++i) {
      // The ends exactly as given; between them evenly spaced.
      const double v = i + 1 == count ? to : from + (to - from) * static_cast<double>(i) / static_cast<double>(count - 1);
      axis.numbers.push_back(v);
      axis.values.push_back(integers && v == std::floor(v) ? json(static_cast<long long>(v)).dump() : json(v).dump());
    }
  }
  std::set<std::string> seen;
  for (std::size_t i = 0; i < axis.values.size(); ++i)
    if (!seen.insert(axis.values[i]).second)
      item.Fail("value " + axis.values[i] + " appears twice on axis \"" + axis.path + "\"");
  item.Finish();
  return axis;
}

std::vector<std::uint64_t> ReadSeeds(const json& document, const JsonReader& seeds) {
  constexpr long long kMaxSeed = std::int64_t{1} << 62;  // as the scenario format allows
  std::vector<std::uint64_t> out;
  if (seeds.IsArray()) {
    const std::size_t n = seeds.Size();
    if (n == 0) seeds.Fail("expected at least one seed");
    for (std::size_t i = 0; i < n; ++i) {
      const JsonReader s = seeds.Element(i);
      const json& v = Raw(document, s);
      if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() > kMaxSeed)
        s.Fail("expected a whole number in [0, 2^62], found " + s.ValueText());
      out.push_back(v.get<std::uint64_t>());
    }
  } else if (seeds.IsObject()) {
    const long long first = seeds.Integer("first", 1, 0, kMaxSeed);
    const long long count = seeds.Integer("count", 1, 100000);
    if (first + count - 1 > kMaxSeed) seeds.At("count").Fail("the last seed is beyond 2^62");
    for (long long i = 0; i < count; ++i) out.push_back(static_cast<std::uint64_t>(first + i));
    seeds.Finish();
  } else {
    seeds.Fail("expected a list of seeds [1, 2, 3] or {\"first\": 1, \"count\": 3}, found " + seeds.ValueText());
  }
  std::set<std::uint64_t> seen;
  for (std::uint64_t s : out)
    if (!seen.insert(s).second) seeds.Fail("seed " + std::to_string(s) + " appears twice");
  return out;
}

bool ValidName(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
           c == '-';
  });
}

// Puts `value` at dotted `path` in `doc`, creating objects on the way.
// The element a path's part names in a list: a decimal index below its size
// ("timeline.inflows.0.max_rate_per_s" is the first inflow's cap).
json& Element(json& list, const std::string& part, const std::string& prefix, const std::string& path,
              const std::string& where) {
  const bool digits = !part.empty() && part.size() <= 6 &&
                      std::all_of(part.begin(), part.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!digits || std::stoul(part) >= list.size())
    throw InputError(where + ": cannot set \"" + path + "\": \"" + prefix + "\" is a list of " +
                     std::to_string(list.size()) + " in the scenario; expected an index 0.." +
                     (list.empty() ? std::string("(none)") : std::to_string(list.size() - 1)) + ", not \"" + part + "\"");
  return list[std::stoul(part)];
}

void Apply(json& doc, const std::string& path, json value, const std::string& where) {
  const std::vector<std::string> parts = SplitPath(path);
  json* node = &doc;
  std::string prefix;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    json& next = node->is_array() ? Element(*node, parts[i], prefix, path, where) : (*node)[parts[i]];
    prefix += (i ? "." : "") + parts[i];
    if (next.is_null()) next = json::object();
    if (!next.is_object() && !next.is_array())
      throw InputError(where + ": cannot set \"" + path + "\": \"" + prefix + "\" is " + next.dump() +
                       " in the scenario, not an object or a list");
    node = &next;
  }
  if (node->is_array())
    Element(*node, parts.back(), prefix, path, where) = std::move(value);
  else
    (*node)[parts.back()] = std::move(value);
}

// Makes relative file paths inside an override value relative to `dir`
// (absolute), for the scenario keys that hold files.
void RebaseFilePaths(const std::string& path, json& value, const fs::path& dir) {
  for (const std::string& key : kFileKeys) {
    json* target = nullptr;
    if (key == path) {
      target = &value;
    } else if (key.rfind(path + ".", 0) == 0) {
      target = &value;
      for (const std::string& part : SplitPath(key.substr(path.size() + 1))) {
        if (!target->is_object() || !target->contains(part)) {
          target = nullptr;
          break;
        }
        target = &(*target)[part];
      }
    }
    if (target && target->is_string()) {
      const fs::path p = target->get<std::string>();
      if (p.is_relative()) *target = (dir / p).lexically_normal().string();
    }
  }
}

std::string Sanitized(const std::string& text, std::size_t max_size) {
  std::string out;
  for (char c : text) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                    c == '_' || c == '-' || c == '+' || c == '=';
    out += ok ? c : '_';
  }
  return out.size() > max_size ? out.substr(0, max_size) : out;
}

// Advances `point` over the axis grid, the last axis fastest; false after the
// last point (and always without axes: the grid is then one point).
bool NextGridPoint(const SweepSpec& spec, std::vector<std::size_t>& point) {
  for (std::size_t a = spec.axes.size(); a-- > 0;) {
    if (++point[a] < spec.axes[a].values.size()) return true;
    point[a] = 0;
  }
  return false;
}

}  // namespace

std::string ExactNumber(double value) {
  if (std::isnan(value)) return "";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

std::string AxisValueText(const Axis& axis, std::size_t index) {
  if (axis.numeric()) return ExactNumber(axis.numbers[index]);
  const json v = json::parse(axis.values[index]);
  return v.is_string() ? v.get<std::string>() : v.dump();
}

std::size_t SweepSpec::RunCount() const {
  std::size_t n = variants.size();
  const auto times = [&n](std::size_t k) {
    n = k != 0 && n > std::numeric_limits<std::size_t>::max() / k ? std::numeric_limits<std::size_t>::max() : n * k;
  };
  times(seeds.size());
  for (const Axis& a : axes) times(a.values.size());
  return n;
}

SweepSpec ParseSweep(const std::string& json_text, const std::string& origin, const fs::path& base_dir) {
  const JsonDocument doc = JsonDocument::Parse(json_text, origin);
  const json document = json::parse(json_text);  // the same text, for raw override values
  const JsonReader root = doc.Root();
  if (!root.IsObject()) root.Fail("expected a sweep object {...}");
  SweepSpec s;
  s.origin = origin;
  s.canonical_json = document.dump();
  const std::string format = root.String("format", "crowdrecon-sweep");
  if (format != "crowdrecon-sweep")
    root.At("format").Fail("\"" + format + "\" is not a sweep; expected \"crowdrecon-sweep\"");
  root.Integer("version", 1, 1, 1);
  s.name = root.String("name", fs::path(origin).stem().string());
  // A file in the working folder has an empty parent path, which fs::absolute refuses.
  const fs::path sweep_dir = fs::absolute(base_dir.empty() ? fs::path(".") : base_dir).lexically_normal();

  {
    const JsonReader scenario = root.At("scenario");
    const fs::path given = scenario.AsString();
    s.scenario_file = (given.is_absolute() ? given : sweep_dir / given).lexically_normal();
    try {
      s.scenario_text = ReadInputFile(s.scenario_file, "scenario file");
    } catch (const InputError& e) {
      scenario.Fail("cannot open the scenario file " + s.scenario_file.string() + " (" + e.what() + ")");
    }
    // Parsed with the readers' checks (syntax, nesting, duplicate keys), which name the line and column.
    const json base = JsonDocument::Parse(s.scenario_text, s.scenario_file.string()).Json();
    if (!base.is_object()) scenario.Fail("the scenario " + s.scenario_file.string() + " is not a JSON object");
    s.scenario_canonical_json = base.dump();
  }

  if (auto set = root.Find("set")) s.set = ReadOverrides(document, *set);
  for (Override& o : s.set) {
    json v = json::parse(o.json);
    RebaseFilePaths(o.path, v, sweep_dir);
    o.json = v.dump();
  }

  if (auto axes = root.Find("axes")) {
    const std::size_t n = axes->Size();
    for (std::size_t i = 0; i < n; ++i) {
      Axis axis = ReadAxis(document, axes->Element(i));
      for (const Axis& other : s.axes)
        if (other.path == axis.path) axes->Element(i).At("path").Fail("axis \"" + axis.path + "\" is given twice");
      if (axis.path == "population.seed")
        axes->Element(i).At("path").Fail("the seed is not an axis; give the seeds with \"seeds\"");
      // Only an axis that is, or holds, a file key can name files (the other
      // values are left as read: an axis may hold 100,000 numbers).
      const bool may_name_files = std::any_of(kFileKeys.begin(), kFileKeys.end(), [&](const std::string& key) {
        return key == axis.path || key.rfind(axis.path + ".", 0) == 0;
      });
      if (may_name_files)
        for (std::string& v : axis.values) {
          json value = json::parse(v);
          RebaseFilePaths(axis.path, value, sweep_dir);
          v = value.dump();
        }
      s.axes.push_back(std::move(axis));
    }
  }

  if (auto seeds = root.Find("seeds")) {
    s.seeds = ReadSeeds(document, *seeds);
  } else {
    // The base scenario's own seed (after "set"), so that a sweep without
    // seeds runs the scenario as written.
    json base = json::parse(s.scenario_text);
    for (const Override& o : s.set) Apply(base, o.path, json::parse(o.json), origin + ": /set");
    const json* seed = base.contains("population") && base["population"].is_object() &&
                               base["population"].contains("seed")
                           ? &base["population"]["seed"]
                           : nullptr;
    s.seeds = {seed && seed->is_number_unsigned() ? seed->get<std::uint64_t>() : std::uint64_t{1}};
  }

  if (auto variants = root.Find("variants")) {
    const std::size_t n = variants->Size();
    if (n == 0) variants->Fail("expected at least one variant (or leave \"variants\" out)");
    for (std::size_t i = 0; i < n; ++i) {
      const JsonReader item = variants->Element(i);
      if (!item.IsObject()) item.Fail("expected a variant {\"name\": ..., \"set\": {...}}, found " + item.ValueText());
      Variant v;
      const JsonReader name = item.At("name");
      v.name = name.AsString();
      if (!ValidName(v.name))
        name.Fail("\"" + v.name + "\" is not a variant name; expected 1 to 64 letters, digits, '.', '_' or '-'");
      for (const Variant& other : s.variants)
        if (other.name == v.name) name.Fail("variant \"" + v.name + "\" is given twice");
      if (auto set = item.Find("set")) v.set = ReadOverrides(document, *set);
      for (Override& o : v.set) {
        json value = json::parse(o.json);
        RebaseFilePaths(o.path, value, sweep_dir);
        o.json = value.dump();
      }
      item.Finish();
      s.variants.push_back(std::move(v));
    }
  } else {
    s.variants.push_back({"base", {}});
  }

  if (s.axes.size() >= 1) s.diagram_x = s.axes[0].path;
  if (s.axes.size() >= 2) s.diagram_y = s.axes[1].path;
  if (auto diagram = root.Find("diagram")) {
    const auto axis_path = [&](const char* key) {
      const JsonReader r = diagram->At(key);
      const std::string path = r.AsString();
      if (std::none_of(s.axes.begin(), s.axes.end(), [&](const Axis& a) { return a.path == path; })) {
        std::string list;
        for (const Axis& a : s.axes) list += (list.empty() ? "\"" : ", \"") + a.path + "\"";
        r.Fail("\"" + path + "\" is not an axis of this sweep; expected one of " + (list.empty() ? "(none)" : list));
      }
      return path;
    };
    s.diagram_x = axis_path("x");
    s.diagram_y = axis_path("y");
    if (s.diagram_x == s.diagram_y) diagram->At("y").Fail("x and y are the same axis \"" + s.diagram_x + "\"");
    diagram->Finish();
  }
  s.keep_runs = root.Bool("keep_runs", false);
  s.ensemble_summaries = root.Bool("ensemble_summaries", false);
  root.Finish();
  if (s.RunCount() > kMaxSweepRuns) {
    std::string sizes = std::to_string(s.variants.size()) + " variant(s) x ";
    for (const Axis& a : s.axes) sizes += std::to_string(a.values.size()) + " (" + a.path + ") x ";
    root.Fail("the sweep has " + (s.RunCount() == std::numeric_limits<std::size_t>::max() ? std::string("more than 10^19")
                                                                                         : std::to_string(s.RunCount())) +
              " runs (" + sizes + std::to_string(s.seeds.size()) + " seed(s)); expected at most " +
              std::to_string(kMaxSweepRuns) + ": check the axes' counts, or split the study into several sweeps");
  }
  return s;
}

SweepSpec LoadSweep(const fs::path& file) {
  SweepSpec s = ParseSweep(ReadInputFile(file, "sweep file"), file.string(), file.parent_path());
  s.file = file;
  return s;
}

std::vector<RunPlan> ExpandRuns(const SweepSpec& spec) {
  std::vector<RunPlan> runs;
  const std::size_t total = spec.RunCount();
  runs.reserve(total);
  const int width = std::max<int>(4, static_cast<int>(std::to_string(total > 0 ? total - 1 : 0).size()));
  std::vector<std::size_t> point(spec.axes.size(), 0);
  for (std::size_t v = 0; v < spec.variants.size(); ++v) {
    std::fill(point.begin(), point.end(), 0);
    do {
      for (std::uint64_t seed : spec.seeds) {
        RunPlan r;
        r.index = runs.size();
        r.variant = v;
        r.axis_value = point;
        r.seed = seed;
        std::string index = std::to_string(r.index);
        r.id = std::string(static_cast<std::size_t>(width) - std::min(index.size(), static_cast<std::size_t>(width)), '0') +
               index + "-" + spec.variants[v].name;
        r.description = "variant " + spec.variants[v].name;
        for (std::size_t a = 0; a < spec.axes.size(); ++a) {
          const Axis& axis = spec.axes[a];
          const std::string value = AxisValueText(axis, point[a]);
          r.id += "-" + Sanitized(SplitPath(axis.path).back() + "=" + value, 48);
          r.description += ", " + axis.path + " = " + value;
        }
        r.id += "-seed" + std::to_string(seed);
        r.description += ", seed " + std::to_string(seed);
        runs.push_back(std::move(r));
      }
    } while (NextGridPoint(spec, point));
  }
  return runs;
}

std::string RunScenarioJson(const SweepSpec& spec, const RunPlan& run) {
  json doc = json::parse(spec.scenario_text);
  const std::string where = spec.origin + ": run " + std::to_string(run.index) + " (" + run.description + ")";
  for (const Override& o : spec.set) Apply(doc, o.path, json::parse(o.json), where);
  for (const Override& o : spec.variants[run.variant].set) Apply(doc, o.path, json::parse(o.json), where);
  for (std::size_t a = 0; a < spec.axes.size(); ++a)
    Apply(doc, spec.axes[a].path, json::parse(spec.axes[a].values[run.axis_value[a]]), where);
  Apply(doc, "population.seed", json(run.seed), where);
  return doc.dump(2);
}

scenario::Scenario RunScenarioOf(const SweepSpec& spec, const RunPlan& run) {
  const std::string text = RunScenarioJson(spec, run);
  try {
    scenario::Scenario s = scenario::ParseScenario(text, spec.scenario_file.string(), spec.scenario_file.parent_path());
    s.file = spec.scenario_file;
    return s;
  } catch (const InputError& e) {
    throw InputError(spec.origin + ": run " + std::to_string(run.index) + " (" + run.description +
                     "): the scenario with this run's overrides is not valid: " + e.what());
  }
}

std::vector<std::string> ValidateRuns(const SweepSpec& spec, const std::vector<RunPlan>& runs) {
  std::vector<std::pair<std::string, std::size_t>> seen;  // in the order first met
  for (const RunPlan& r : runs)
    for (const std::string& line : RunScenarioOf(spec, r).settings_without_effect) {
      auto it = std::find_if(seen.begin(), seen.end(), [&](const auto& x) { return x.first == line; });
      if (it == seen.end())
        seen.emplace_back(line, 1);
      else
        ++it->second;
    }
  std::vector<std::string> notes;
  for (const auto& [line, count] : seen)
    notes.push_back(line + " (in " + std::to_string(count) + " of " + std::to_string(runs.size()) + " runs)");
  return notes;
}

}  // namespace crowdrecon::sweep
