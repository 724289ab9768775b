// The model's parameter table: every field of ModelParameters, defined once —
// its name (the key under "model" in a scenario, in world files, in the
// docs), unit, allowed range, source in the paper and meaning. Its default is
// the field's initialiser in parameters.hpp. Everything else is derived from
// this table: the scenario reader (scenario/src/scenario.cpp),
// ModelParameters::IsValid, the world file's parameter block
// (world_file.cpp), the parameter table of docs/model.md (checked by
// tests/unit/test_parameter_table.cpp), and next the calibration's bounds
// and the sweeps' axes.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "crowdrecon/engine/parameters.hpp"

namespace crowdrecon::engine {

struct ParameterInfo {
  enum class Kind { kNumber, kFlag, kChoice };
  Kind kind = Kind::kNumber;
  const char* name = "";
  const char* unit = "";     // "" for dimensionless numbers, flags and choices
  const char* source = "";   // where the value comes from: "Table 1", "text", "ERRATA 2" (docs/decisions.md), ...
  const char* meaning = "";  // one line

  // kNumber: the field and its allowed range [min, max] (both included).
  double ModelParameters::*number = nullptr;
  double min = 0.0, max = 0.0;
  // kNumber: in a scenario, a parameter absent from "model" takes the value of
  // this one (read before it), rather than its own default.
  const char* default_from = nullptr;

  // The setting under which it acts at all ("give_way = where_room": a
  // number of an extension, of an option), and the test of it; null: always.
  const char* applies_when = nullptr;
  bool (*applies)(const ModelParameters&) = nullptr;

  // kFlag.
  bool ModelParameters::*flag = nullptr;

  // kChoice: an enumeration whose values are 0..choice_count-1, named choices[k].
  const char* const* choices = nullptr;
  std::size_t choice_count = 0;
  int (*get_choice)(const ModelParameters&) = nullptr;
  void (*set_choice)(ModelParameters&, int) = nullptr;

  // The value of this parameter in `p`, as text ("100000", "true", "gear5").
  std::string ValueText(const ModelParameters& p) const;
  // "in [0.01, 1]", "true or false", "one of velocity, desired_direction".
  std::string Expected() const;
};

// The table, in a fixed order (that of the world file's parameter block).
std::span<const ParameterInfo> ModelParameterTable();
// The entry named `name`, or nullptr.
const ParameterInfo* FindModelParameter(const std::string& name);

// Of the parameters named in `given` (the keys a scenario's "model" sets),
// those that change nothing under `p`, each as one line: "model.give_way_blocked_s
// changes nothing: it acts only when give_way = where_room (here give_way is
// none)". Empty when every given setting acts.
std::vector<std::string> SettingsWithoutEffect(const ModelParameters& p, const std::vector<std::string>& given);

// The table as the Markdown of docs/model.md ("| name | unit | default |
// range | source | meaning |"), one row per parameter.
std::string ModelParameterTableMarkdown();

}  // namespace crowdrecon::engine
