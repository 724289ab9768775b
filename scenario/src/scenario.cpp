#include "crowdrecon/scenario/scenario.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/json_reader.hpp"
#include "crowdrecon/engine/parameter_table.hpp"
#include "crowdrecon/geometry/population_table.hpp"
#include "crowdrecon/scenario/profile.hpp"
#include "timeline_systems.hpp"

namespace crowdrecon::scenario {

std::filesystem::path DataDirectory() {
  if (const char* dir = std::getenv("CROWDRECON_DATA_DIR"); dir && *dir) return dir;
  return CROWDRECON_SOURCE_DIR;
}

namespace {

std::filesystem::path Resolve(const std::filesystem::path& base, const std::string& path) {
  const std::filesystem::path p(path);
  return p.is_absolute() ? p : (base / p).lexically_normal();
}

// Reads every parameter of the table (engine/parameter_table.hpp) present in
// `model`, with the table's range; an absent one keeps its default, or takes
// the value of the parameter it defaults from (wall_restitution: restitution).
void ReadModel(const JsonReader& model, engine::ModelParameters& m) {
  for (const engine::ParameterInfo& info : engine::ModelParameterTable()) {
    switch (info.kind) {
      case engine::ParameterInfo::Kind::kNumber: {
        const double fallback =
            info.default_from ? m.*(engine::FindModelParameter(info.default_from)->number) : m.*info.number;
        m.*info.number = model.Number(info.name, fallback, info.min, info.max);
        break;
      }
      case engine::ParameterInfo::Kind::kFlag: m.*info.flag = model.Bool(info.name, m.*info.flag); break;
      case engine::ParameterInfo::Kind::kChoice: {
        const std::vector<std::string> allowed(info.choices, info.choices + info.choice_count);
        const std::string chosen = model.Choice(info.name, info.ValueText(m), allowed);
        info.set_choice(m, static_cast<int>(std::find(allowed.begin(), allowed.end(), chosen) - allowed.begin()));
        break;
      }
    }
  }
  model.Finish();
}

// A profile's values where the scenario gives none of its own (its model
// block's keys one by one, the population's body block and free speeds as
// wholes); body files by paths relative to the scenario's folder, as a
// scenario names them. Whether anything was added.
bool ApplyProfile(const ModelProfile& profile, const std::filesystem::path& base_dir, nlohmann::json& scenario) {
  bool changed = false;
  if (!profile.model.empty()) {
    nlohmann::json& model = scenario["model"];
    if (model.is_null()) model = nlohmann::json::object();
    if (model.is_object())
      for (const auto& [key, value] : profile.model)
        if (!model.contains(key)) {
          model[key] = nlohmann::json::parse(value);
          changed = true;
        }
  }
  const auto population = scenario.find("population");
  if (population == scenario.end() || !population->is_object()) return changed;  // (the reader says what is wrong)
  if (!profile.body_json.empty() && !population->contains("body")) {
    nlohmann::json body = nlohmann::json::parse(profile.body_json);
    if (!base_dir.empty())
      for (const char* key : {"reference", "anthropometry"})
        if (body.contains(key) && body[key].is_string())
          body[key] = std::filesystem::path(body[key].get<std::string>())
                          .lexically_relative(std::filesystem::absolute(base_dir).lexically_normal())
                          .string();
    (*population)["body"] = body;
    changed = true;
  }
  if (profile.desired_speed_m_per_s && !population->contains("desired_speed_m_per_s")) {
    (*population)["desired_speed_m_per_s"] = {profile.desired_speed_m_per_s->first, profile.desired_speed_m_per_s->second};
    changed = true;
  }
  return changed;
}

}  // namespace

Scenario ParseScenario(const std::string& json_text, const std::string& origin,
                       const std::filesystem::path& base_dir) {
  const JsonDocument doc = JsonDocument::Parse(json_text, origin);
  const JsonReader root = doc.Root();
  if (!root.IsObject()) root.Fail("expected a scenario object {...}");
  // The model profile (profile.hpp): its values are written into the
  // scenario where it gives none of its own, and the scenario is read from
  // that text, which the run file keeps (a later change of the profile's file
  // is then a change of the scenario: a resume refuses it).
  std::string profile_name = kDefaultProfile;
  if (auto named = root.Find("profile")) {
    const std::string given = named->AsString();
    ModelProfile profile;
    try {
      profile = LoadModelProfile(ProfilePath(given, base_dir));
    } catch (const InputError& e) {
      std::string names;
      for (const std::string& n : NamedProfiles()) names += (names.empty() ? "" : ", ") + n;
      named->Fail(std::string("cannot use the profile: ") + e.what() + "; expected one of the named profiles (" + names +
                  ") or a profile file");
    }
    nlohmann::json merged = doc.Json();
    if (ApplyProfile(profile, base_dir, merged)) return ParseScenario(merged.dump(2) + "\n", origin, base_dir);
    profile_name = profile.name;
  }
  Scenario s;
  s.json_text = json_text;
  s.file = origin;
  s.profile = profile_name;
  const std::string format = root.String("format", "crowdrecon-scenario");
  if (format != "crowdrecon-scenario")
    root.At("format").Fail("\"" + format + "\" is not a scenario; expected \"crowdrecon-scenario\"");
  root.Integer("version", 1, 1, 1);
  s.name = root.String("name", std::filesystem::path(origin).stem().string());
  if (auto notes = root.Find("notes")) {  // the scenario's assumptions and sources, one per entry
    if (!notes->IsArray()) notes->Fail("expected a list of notes [\"...\", ...]");
    for (std::size_t k = 0; k < notes->Size(); ++k) s.notes.push_back(notes->Element(k).AsString());
  }

  {
    const JsonReader venue = root.At("venue");
    s.venue_file = Resolve(base_dir, venue.AsString());
    try {
      s.venue = geometry::LoadVenue(s.venue_file);
    } catch (const InputError& e) {
      venue.Fail(std::string("cannot use the venue: ") + e.what());
    }
  }

  // "slope": the venue's floor slope with another gradient (or switched on
  // or off): a figure the sources disagree on is a parameter of the
  // scenario, while its direction and region stay the venue's.
  if (auto slope = root.Find("slope")) {
    if (!slope->IsObject()) slope->Fail("expected an object {\"gradient\": g, \"enabled\": true}, found " + slope->ValueText());
    if (!s.venue.slope)
      slope->Fail("the venue " + s.venue_file.string() + " has no slope (its direction and region come from the venue)");
    s.venue.slope->gradient = slope->Number("gradient", s.venue.slope->gradient, 0.0, 1.0);
    s.venue.slope->enabled = slope->Bool("enabled", s.venue.slope->enabled);
    slope->Finish();
  }

  {
    const JsonReader pop = root.At("population");
    PopulationSpec& p = s.population;
    // Every number with its range from the population table (geometry/population_table.hpp).
    const auto number = [](const JsonReader& section, std::string_view path, double fallback) {
      const geometry::PopulationKeyInfo& k = geometry::PopulationKey(path);
      return k.integer ? static_cast<double>(section.Integer(k.key, static_cast<long long>(fallback),
                                                             static_cast<long long>(k.min), static_cast<long long>(k.max)))
                       : section.Number(k.key, fallback, k.min, k.max);
    };
    if (pop.Has("count") == pop.Has("density_per_m2"))
      pop.Fail("give exactly one of \"count\" and \"density_per_m2\"");
    // 0 is allowed here for a venue that starts empty and fills by inflow
    // (checked against /timeline below); the population table's range is 1...
    if (pop.Has("count"))
      p.count = static_cast<std::size_t>(pop.Integer("count", 0, static_cast<long long>(geometry::PopulationKey("count").max)));
    if (pop.Has("density_per_m2")) p.density_per_m2 = number(pop, "density_per_m2", 0.0);
    p.counter_flow_fraction = number(pop, "counter_flow_fraction", p.counter_flow_fraction);
    p.target = pop.String("target");
    if (!s.venue.FindTarget(p.target))
      pop.At("target").Fail("the venue " + s.venue_file.string() + " has no target or exit \"" + p.target + "\"");
    p.counter_target = pop.String("counter_target", "");
    if (p.counter_flow_fraction > 0.0) {
      if (p.counter_target.empty()) pop.Fail("counter_flow_fraction > 0 needs a \"counter_target\"");
      if (!s.venue.FindTarget(p.counter_target))
        pop.At("counter_target").Fail("the venue has no target or exit \"" + p.counter_target + "\"");
    }
    if (auto body = pop.Find("body")) {
      p.body_mode = geometry::PopulationModeFromString(
          body->Choice("mode", "paper", {"paper", "anthropometric", "circle"}), body->Where() + "/mode");
      // The files are read when the world is built; one that cannot be opened
      // is reported here, against the key that names it.
      const auto readable = [&](const JsonReader& key, const std::string& expected) {
        const std::filesystem::path file = Resolve(base_dir, key.AsString());
        if (!std::ifstream(file)) key.Fail("cannot open \"" + file.string() + "\" for reading; expected " + expected);
        if (std::filesystem::is_directory(file)) key.Fail("\"" + file.string() + "\" is a directory; expected " + expected);
        return file;
      };
      if (auto ref = body->Find("reference")) p.reference_body = readable(*ref, "a body file (crowdrecon body JSON)");
      if (auto ansur = body->Find("anthropometry"))
        p.anthropometry = readable(*ansur, "an ANSUR II extract (CSV, docs/bodies.md)");
      p.female_fraction = number(*body, "body.female_fraction", p.female_fraction);
      p.vertex_count = static_cast<std::size_t>(number(*body, "body.vertices", static_cast<double>(p.vertex_count)));
      body->Finish();
    }
    if (p.reference_body.empty()) p.reference_body = DataDirectory() / "venues/bodies/thorax-18.json";
    if (p.anthropometry.empty()) p.anthropometry = DataDirectory() / "venues/bodies/ansur2-thorax.csv";
    if (auto speed = pop.Find("desired_speed_m_per_s")) {
      const geometry::PopulationKeyInfo& k = geometry::PopulationKey("desired_speed_m_per_s");
      if (speed->Size() != 2) speed->Fail(std::string("expected ") + k.Expected() + " " + k.unit);
      p.desired_speed_min_m_per_s = speed->Element(0).AsNumber(k.min, k.max);
      p.desired_speed_max_m_per_s = speed->Element(1).AsNumber(p.desired_speed_min_m_per_s, k.max);
    }
    if (auto placement = pop.Find("placement")) {
      p.placement_region = placement->Choice("region", "walkable", {"walkable", "entries"});
      p.max_initial_overlap_m = number(*placement, "placement.max_overlap_m", p.max_initial_overlap_m);
      placement->Finish();
    }
    if (p.placement_region == "entries" && s.venue.entries.empty())
      pop.At("placement").Fail("region \"entries\" but the venue has no entry zones");
    p.seed = static_cast<std::uint64_t>(pop.Integer("seed", static_cast<long long>(p.seed), 0,
                                                    static_cast<long long>(geometry::PopulationKey("seed").max)));
    pop.Finish();
  }

  // The gait jitter's seed (issue 39) follows the population's unless the model gives one.
  s.model.gait_jitter_seed = static_cast<double>(s.population.seed & ((std::uint64_t{1} << 52) - 1));
  if (auto model = root.Find("model")) ReadModel(*model, s.model);
  {
    std::string error;
    if (!s.model.IsValid(&error)) root.At("model").Fail(error);
  }
  // Settings that change nothing here (issue 65): an extension's numbers
  // while it is off, and a floor slope's settings while the floor is level.
  if (auto model = root.Find("model")) {
    s.settings_without_effect = engine::SettingsWithoutEffect(s.model, model->Keys());
    const bool sloping = s.venue.slope && s.venue.slope->enabled && s.venue.slope->gradient > 0.0;
    const std::string level =
        !s.venue.slope ? "the venue has no slope" : !s.venue.slope->enabled ? "the slope is off (slope.enabled false)"
                                                                          : "the slope's gradient is 0";
    for (const char* key : {"slope_response", "gravity_m_per_s2"})
      if (!sloping && model->Has(key))
        s.settings_without_effect.push_back(std::string("model.") + key + " changes nothing: the floor is level here: " +
                                            level);
  }
  if (auto slope = root.Find("slope"); slope && slope->Has("gradient") && s.venue.slope && !s.venue.slope->enabled)
    s.settings_without_effect.push_back("slope.gradient changes nothing: the slope is off (slope.enabled false; "
                                        "\"enabled\": true switches it on)");

  if (auto run = root.Find("run")) {
    s.run.duration_s = run->Number("duration_s", s.run.duration_s, 0.0, 1e6);
    s.run.output_fps = run->Number("output_fps", s.run.output_fps, 0.01, 1000.0);
    s.run.checkpoint_interval_s = run->Number("checkpoint_interval_s", s.run.checkpoint_interval_s, 0.0, 1e6);
    if (auto contacts = run->Find("contacts"); contacts && contacts->IsObject()) {
      s.run.lean_contacts = true;
      s.run.write_contacts = true;
      s.run.contacts_every_s = contacts->Number("every_s", s.run.contacts_every_s, 0.0, 1e6);
      s.run.contacts_worst = contacts->Bool("worst", s.run.contacts_worst);
      contacts->Finish();
    } else {
      s.run.write_contacts = run->Bool("contacts", s.run.write_contacts);
    }
    s.run.packed_frames = run->Choice("frames", s.run.packed_frames ? "packed" : "tables", {"tables", "packed"}) == "packed";
    if (auto settle = run->Find("stop_when_settled")) s.run.settle = ReadSettleOptions(*settle);
    run->Finish();
  }
  if (auto timeline = root.Find("timeline")) {
    s.timeline = ReadTimeline(*timeline, s.venue, base_dir, s.population.target, s.population.counter_target);
    if (s.run.settle.enabled && s.timeline.HasInflow())
      root.At("run").At("stop_when_settled").Fail(
          "a run with inflow never settles into a closed regime; drop run.stop_when_settled or the inflows");
    const auto due_by_end = [&](const InflowSpec& f) { return double(ArrivalsDue(f.rate, s.run.duration_s)); };
    double arrivals = 0.0;
    for (const InflowSpec& f : s.timeline.inflows) arrivals += due_by_end(f);
    // An event at or after the run's end would never happen (issue 40: it
    // was accepted without a word; issue 65: at the end itself, too: the
    // last step ends there, and an event acts before a step).
    for (const TimelineEvent& e : s.timeline.events)
      if (e.time_s >= s.run.duration_s)
        throw InputError(e.where + "/time_s: " + FormatNumber(e.time_s) + " s lies " +
                         (e.time_s == s.run.duration_s ? "at" : "after") + " the run's end (run.duration_s = " +
                         FormatNumber(s.run.duration_s) +
                         " s), so the event would never happen; expected a time before the run's end");
    // Every event's values as if applied, in time order (issue 65: a value
    // that leaves the parameters invalid, as a jitter band whose low end
    // passes its high one, failed only when it fired, leaving a run marked
    // running). Per-group values (Gamma, lambda, speeds) are range-checked
    // when read; the model's own are checked here together.
    {
      engine::ModelParameters p = s.model;
      for (const TimelineEvent& e : s.timeline.events) {
        if (e.kind != TimelineEvent::Kind::kSetParameters || !e.group.empty()) continue;
        detail::ApplyEventToModel(e, &p);
        std::string error;
        if (!p.IsValid(&error))
          throw InputError(e.where + "/set: the model as this event at " + FormatNumber(e.time_s) +
                           " s leaves it: " + error);
      }
    }
    if (arrivals > static_cast<double>(geometry::kMaxPeople))
      timeline->At("inflows").Fail("the inflows bring " + FormatNumber(arrivals) + " people in " +
                                   FormatNumber(s.run.duration_s) + " s; expected at most " +
                                   std::to_string(geometry::kMaxPeople) + " (check the rates' unit: persons per second)");
  }
  if (s.population.count && *s.population.count == 0 && !s.timeline.HasInflow())
    root.At("population").At("count").Fail("0 people and no inflow (/timeline/inflows): nothing to simulate");
  root.Finish();
  return s;
}

Scenario LoadScenario(const std::filesystem::path& file) {
  Scenario s = ParseScenario(ReadInputFile(file, "scenario file"), file.string(), file.parent_path());
  s.file = file;
  return s;
}

Scenario LoadScenario(const std::filesystem::path& file, const std::string& profile) {
  if (profile.empty()) return LoadScenario(file);
  const std::string text = ReadInputFile(file, "scenario file");
  nlohmann::json j = JsonDocument::Parse(text, file.string()).Json();
  if (!j.is_object()) return LoadScenario(file);  // (its own message)
  // A file named on the command line is the working folder's, not the
  // scenario's: made absolute before the scenario resolves it.
  j["profile"] = IsProfileName(profile) ? profile : ProfilePath(profile, std::filesystem::current_path()).string();
  Scenario s = ParseScenario(j.dump(2) + "\n", file.string() + " (with --profile " + profile + ")", file.parent_path());
  s.file = file;
  return s;
}

}  // namespace crowdrecon::scenario
