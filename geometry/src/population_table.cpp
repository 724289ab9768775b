#include "crowdrecon/geometry/population_table.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/population.hpp"

namespace crowdrecon::geometry {

namespace {

PopulationKeyInfo Number(const char* section, const char* key, const char* unit, double fallback, double min,
                         double max, const char* source, const char* meaning) {
  PopulationKeyInfo info;
  info.section = section;
  info.key = key;
  info.unit = unit;
  info.default_value = fallback;
  info.min = min;
  info.max = max;
  info.source = source;
  info.meaning = meaning;
  return info;
}

PopulationKeyInfo Integer(const char* section, const char* key, double fallback, double min, double max,
                          const char* source, const char* meaning) {
  PopulationKeyInfo info = Number(section, key, "", fallback, min, max, source, meaning);
  info.integer = true;
  return info;
}

PopulationKeyInfo OneOf(PopulationKeyInfo info) {
  info.default_note = "give count or density_per_m2";
  return info;
}

const auto& Table() {
  static const std::array table{
      OneOf(Integer("", "count", 0, 1, static_cast<double>(kMaxPeople), "crowdrecon",
                    "head count; at most geometry::kMaxPeople")),
      OneOf(Number("", "density_per_m2", "m^-2", 0, 0.01, 12.0, "paper (densities 3-7 /m^2)",
                   "persons per m^2 of the placement region; refused if it gives more than the largest head count")),
      Number("", "counter_flow_fraction", "", 0.0, 0.0, 1.0, "paper (0-0.5)",
             "share of people walking to counter_target (group 1)"),
      [] {
        PopulationKeyInfo info = Number("", "desired_speed_m_per_s", "m/s", 0.8, 0.0, 10.0, "paper",
                                        "v0 uniform in [low, high]");
        info.pair = true;
        info.default_high = 1.2;
        return info;
      }(),
      Number("body", "female_fraction", "", 0.5, 0.0, 1.0, "ANSUR II (both sexes)",
             "anthropometric mode: probability that a person is female"),
      Integer("body", "vertices", 18, 3, 200, "crowdrecon (docs/bodies.md)", "anthropometric bodies: core vertices"),
      Number("placement", "max_overlap_m", "m", 0.003, 1e-5, 0.05, "crowdrecon",
             "largest overlap accepted after the placement relaxation"),
      Integer("", "seed", 1, 0, 4611686018427387904.0 /* 2^62 */, "crowdrecon",
              "everything random (bodies, groups, speeds, placement) follows from it"),
  };
  return table;
}

}  // namespace

std::string PopulationKeyInfo::Path() const {
  return std::string("population.") + (*section ? std::string(section) + "." : std::string()) + key;
}

std::string PopulationKeyInfo::Expected() const {
  const std::string range = "[" + FormatNumber(min) + ", " + FormatNumber(max) + "]";
  if (pair) return "[low, high] with low <= high, each in " + range;
  return (integer ? "a whole number in " : "a number in ") + range;
}

bool PopulationKeyInfo::Contains(double value) const {
  return value >= min && value <= max && (!integer || std::floor(value) == value);
}

std::string PopulationKeyInfo::DefaultText() const {
  if (default_note) return default_note;
  if (pair) return "[" + FormatNumber(default_value) + ", " + FormatNumber(default_high) + "]";
  return FormatNumber(default_value);
}

std::span<const PopulationKeyInfo> PopulationKeyTable() { return Table(); }

std::string PopulationKeyTableMarkdown() {
  std::string md = "| key | unit | default | range | source | meaning |\n|---|---|---|---|---|---|\n";
  for (const PopulationKeyInfo& k : Table())
    md += "| `" + k.Path() + "` | " + k.unit + " | " + k.DefaultText() + " | " +
          (k.integer ? "whole, " : "") + "[" + FormatNumber(k.min) + ", " + FormatNumber(k.max) + "]" +
          (k.pair ? " each, low <= high" : "") + " | " + k.source + " | " + k.meaning + " |\n";
  return md;
}

const PopulationKeyInfo& PopulationKey(std::string_view path) {
  for (const PopulationKeyInfo& info : Table()) {
    const std::string full = info.Path();
    if (full == path || full.substr(std::string_view("population.").size()) == path) return info;
  }
  throw std::logic_error("no population key \"" + std::string(path) + "\" in the population table");
}

}  // namespace crowdrecon::geometry
