// Body populations (see population.hpp for the three modes and ERRATA 7).
#include "crowdrecon/geometry/population.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <thread>
#include <fstream>
#include <map>
#include <numbers>
#include <random>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/geometry/population_table.hpp"

namespace crowdrecon::geometry {

std::string ToString(PopulationMode mode) {
  switch (mode) {
    case PopulationMode::kPaper: return "paper";
    case PopulationMode::kAnthropometric: return "anthropometric";
    case PopulationMode::kCircle: return "circle";
  }
  return "?";
}

PopulationMode PopulationModeFromString(const std::string& text, const std::string& what) {
  if (text == "paper") return PopulationMode::kPaper;
  if (text == "anthropometric") return PopulationMode::kAnthropometric;
  if (text == "circle") return PopulationMode::kCircle;
  throw InputError(what + ": unknown population mode \"" + text +
                   "\"; expected paper, anthropometric or circle");
}

bool PopulationOptions::IsValid(std::string* error) const {
  const std::string problem = [&]() -> std::string {
    // The options a scenario gives, against the population table.
    if (const PopulationKeyInfo& k = PopulationKey("count"); !k.Contains(static_cast<double>(count)))
      return "count (" + std::to_string(count) + ") out of range; expected " + k.Expected() + " (check the count)";
    if (!(mass_min_kg > 0.0 && mass_min_kg <= mass_max_kg && std::isfinite(mass_max_kg)))
      return "mass range [" + FormatNumber(mass_min_kg) + ", " + FormatNumber(mass_max_kg) +
             "] kg; expected 0 < min <= max";
    if (!(density_kg_m2 > 0.0 && std::isfinite(density_kg_m2)))
      return "density (" + FormatNumber(density_kg_m2) + " kg/m^2) must be positive";
    if (const PopulationKeyInfo& k = PopulationKey("body.female_fraction"); !k.Contains(female_fraction))
      return "female fraction (" + FormatNumber(female_fraction) + ") out of range; expected " + k.Expected();
    if (const PopulationKeyInfo& k = PopulationKey("body.vertices"); !k.Contains(static_cast<double>(vertex_count)))
      return "vertex count (" + std::to_string(vertex_count) + ") out of range; expected " + k.Expected();
    if (!(radius_m > 0.0 && std::isfinite(radius_m)))
      return "sphero-radius (" + FormatNumber(radius_m) + " m) must be positive";
    std::string thorax_error;
    return thorax.IsValid(&thorax_error) ? std::string() : thorax_error;
  }();
  if (!problem.empty() && error) *error = problem;
  return problem.empty();
}

Population MakePopulation(const PopulationOptions& options, const Spheropolygon& reference,
                          const std::vector<AnsurRecord>& records) {
  if (std::string error; !options.IsValid(&error)) throw InputError("population: " + error);
  Population population{options, {}, 0, 0};
  population.people.reserve(options.count);
  std::mt19937_64 rng(options.seed);
  const double rho = options.density_kg_m2;

  if (options.mode == PopulationMode::kPaper || options.mode == PopulationMode::kCircle) {
    if (Length(reference.centroid()) > 1e-6)
      throw InputError("population: the reference body is not in the body frame (centroid at (" +
                       FormatNumber(reference.centroid().x) + ", " +
                       FormatNumber(reference.centroid().y) + ")); expected the origin");
    for (std::size_t i = 0; i < options.count; ++i) {
      // One draw per person in both modes, so person i has the same mass in
      // the paper and circle populations of one seed.
      const double mass_kg = options.mass_min_kg +
                             (options.mass_max_kg - options.mass_min_kg) * UniformUnit(rng());
      const double area_m2 = mass_kg / rho;
      if (options.mode == PopulationMode::kPaper) {
        // Area scales with s^2: s = sqrt(A / A_ref); J with s^4.
        Spheropolygon shape = reference.Scaled(std::sqrt(area_m2 / reference.area()));
        const double inertia = rho * shape.polar_moment();
        population.people.push_back({std::move(shape), mass_kg, inertia, rho, std::nullopt, std::nullopt});
      } else {
        const double radius_m = std::sqrt(area_m2 / std::numbers::pi);
        Spheropolygon disk = Spheropolygon::Create({{0.0, 0.0}}, radius_m, "circle body");
        const double inertia = rho * disk.polar_moment();
        population.people.push_back({std::move(disk), mass_kg, inertia, rho, std::nullopt, std::nullopt});
      }
    }
    population.distinct_shapes = options.mode == PopulationMode::kPaper ? 1 : 0;
    return population;
  }

  // Anthropometric.
  std::vector<const AnsurRecord*> by_sex[2];
  for (const AnsurRecord& r : records) by_sex[r.sex == Sex::kFemale ? 0 : 1].push_back(&r);
  if (options.female_fraction > 0.0 && by_sex[0].empty())
    throw InputError("population: no female record in the anthropometric data but the female "
                     "fraction is " + FormatNumber(options.female_fraction));
  if (options.female_fraction < 1.0 && by_sex[1].empty())
    throw InputError("population: no male record in the anthropometric data but the female "
                     "fraction is " + FormatNumber(options.female_fraction));
  BodyOptions body_options;
  body_options.vertex_count = options.vertex_count;
  body_options.radius_m = options.radius_m;
  body_options.front = FrontAxis::kPlusX;  // ThoraxOutline is in the body frame
  body_options.scale = ScaleRule::None();  // and in metres
  body_options.hausdorff_spacing_m = 0.0;  // not needed per person; costly
  // 0.5 mm: invisible after the reduction to 18 vertices, and halves the
  // straight skeleton's work.
  body_options.presimplify_tolerance_m = 5e-4;
  body_options.shrink_radius_to_keep_one_piece = true;
  // Draw everyone first (the random sequence does not depend on how bodies are
  // built), then build each distinct record's body once: records drawn twice
  // (sampling is with replacement) share it. The builds are independent, so
  // they run on worker threads, each writing only its own slot: the result
  // does not depend on the thread count.
  std::vector<const AnsurRecord*> drawn;
  drawn.reserve(options.count);
  std::map<std::int64_t, std::size_t> slot_of;  // subject id -> index into `distinct`
  std::vector<const AnsurRecord*> distinct;
  for (std::size_t i = 0; i < options.count; ++i) {
    const bool female = UniformUnit(rng()) < options.female_fraction;
    const auto& pool = by_sex[female ? 0 : 1];
    const auto index = static_cast<std::size_t>(UniformUnit(rng()) * static_cast<double>(pool.size()));
    const AnsurRecord* record = pool[std::min(index, pool.size() - 1)];
    drawn.push_back(record);
    if (slot_of.emplace(record->subject_id, distinct.size()).second) distinct.push_back(record);
  }
  std::vector<std::optional<Spheropolygon>> shapes(distinct.size());
  // Each slot keeps its own failure as an exception_ptr (no allocation for a
  // std::bad_alloc): the first one in slot order is rethrown on this thread
  // unchanged, so an out-of-memory reaches the caller as std::bad_alloc and
  // a bad outline as its GeometryError, never std::terminate on a worker.
  std::vector<std::exception_ptr> errors(distinct.size());
  std::atomic<std::size_t> next{0};
  const auto worker = [&] {
    for (std::size_t k = next++; k < distinct.size(); k = next++) {
      try {
        Outline outline;
        outline.source = "ANSUR II subject " + std::to_string(distinct[k]->subject_id);
        outline.points = ThoraxOutline(distinct[k]->thorax, options.thorax);
        shapes[k] = BuildBody(outline, body_options).shape;
      } catch (...) {
        errors[k] = std::current_exception();
      }
    }
  };
  const std::size_t threads =
      std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1, std::max<std::size_t>(1, distinct.size() / 8));
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& error : errors) {
    if (!error) continue;
    try {
      std::rethrow_exception(error);
    } catch (const GeometryError& e) {
      throw GeometryError(std::string("population: ") + e.what());
    }
  }

  for (const AnsurRecord* record : drawn) {
    const Spheropolygon& shape = *shapes[slot_of.at(record->subject_id)];
    // rho_i = m_i / A_i, I_i = rho_i J_i (ERRATA 7: the person's own weight and shape).
    const double density = record->weight_kg / shape.area();
    population.people.push_back({shape, record->weight_kg, density * shape.polar_moment(), density,
                                 record->sex, record->subject_id});
  }
  for (const auto& shape : shapes)
    if (shape->radius() != options.radius_m) ++population.reduced_radius;
  population.distinct_shapes = distinct.size();
  return population;
}

OutputKind PopulationJsonOutput() {
  return JsonOutputKind("a population JSON (format crowdrecon-population)", [](const nlohmann::json& j) {
    return j.contains("format") && j["format"] == "crowdrecon-population";
  });
}

void WritePopulationJson(const Population& population, const std::filesystem::path& file) {
  const PopulationOptions& o = population.options;
  nlohmann::ordered_json j;
  j["format"] = "crowdrecon-population";
  j["version"] = 1;
  j["mode"] = ToString(o.mode);
  j["count"] = o.count;
  j["seed"] = o.seed;
  if (o.mode == PopulationMode::kAnthropometric) {
    j["female_fraction"] = o.female_fraction;
    j["source"] = "ANSUR II (Gordon et al. 2014), venues/bodies/ansur2-thorax.csv";
  } else {
    j["mass_range_kg"] = {o.mass_min_kg, o.mass_max_kg};
    j["density_kg_m2"] = o.density_kg_m2;
  }
  nlohmann::ordered_json people = nlohmann::ordered_json::array();
  for (const Person& p : population.people) {
    nlohmann::ordered_json q;
    if (p.record_id) q["record_id"] = *p.record_id;
    if (p.sex) q["sex"] = ToString(*p.sex);
    q["mass_kg"] = p.mass_kg;
    q["moment_of_inertia_kgm2"] = p.moment_of_inertia_kgm2;
    q["density_kg_m2"] = p.density_kg_m2;
    q["radius_m"] = p.shape.radius();
    nlohmann::ordered_json vertices = nlohmann::ordered_json::array();
    for (const Vec2& v : p.shape.vertices()) vertices.push_back({v.x, v.y});
    q["vertices_m"] = vertices;
    q["area_m2"] = p.shape.area();
    q["polar_moment_m4"] = p.shape.polar_moment();
    people.push_back(q);
  }
  j["people"] = people;
  WriteFileAtomically(file, j.dump(1) + '\n');
}

}  // namespace crowdrecon::geometry
