// Body populations: a shape and a mass per person, mutually consistent
// (ERRATA 7: mass, area and moment of inertia agree for every body).
//
//   paper          mass m ~ U[40, 70] kg; the reference body scaled uniformly
//                  (vertices and sphero-radius together, so the swept shape is
//                  geometrically similar) so that rho A = m with rho = 1000
//                  kg/m^2 (eq. 13); I = rho J.
//   anthropometric ANSUR II records drawn with a given fraction of women; each
//                  person's outline is built from their own chest breadth,
//                  chest depth and bideltoid breadth; mass = their weight; the
//                  surface density is their own, rho_i = m_i / A_i, so
//                  I_i = m_i J_i / A_i.
//   circle         the paper's masses, each body a disk of the same area as
//                  the paper-mode thorax of that mass (rho = 1000 kg/m^2).
//
// Deterministic given the seed: std::mt19937_64 with explicit transforms to
// uniform numbers (no std::*_distribution, whose algorithms the standard leaves
// to the library), so the same seed gives the same people on every platform.
// Anthropometric bodies are built once per distinct record, on worker threads
// that each fill only their own slot: the result does not depend on the
// thread count.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "crowdrecon/geometry/anthropometry.hpp"
#include "crowdrecon/geometry/body.hpp"
#include "crowdrecon/geometry/spheropolygon.hpp"

namespace crowdrecon::geometry {

enum class PopulationMode { kPaper, kAnthropometric, kCircle };
std::string ToString(PopulationMode mode);  // "paper", "anthropometric", "circle"
PopulationMode PopulationModeFromString(const std::string& text, const std::string& what = "mode");

// The most people one population (a scenario, `crowdrecon population --count`)
// may hold. Measured: a run's peak memory grows by about 3.4 kB per person
// (84 MB at 2,000 people, 111 MB at 10,000: bench/scenarios/box-*.json, 0.2 s,
// one thread), and the 1,000,000-person scenario of issue 17 reached 5.7 GB
// (about 6 kB per person) before std::bad_alloc; 200,000 people thus stay near
// 1 GB. The largest shipped scenarios hold 10,000 (benchmarks) and 6,800
// (evacuation); a larger count is almost always a typo or a venue drawn in the
// wrong unit.
inline constexpr std::size_t kMaxPeople = 200000;

struct PopulationOptions {
  PopulationMode mode = PopulationMode::kPaper;
  std::size_t count = 100;
  std::uint64_t seed = 1;
  double mass_min_kg = 40.0;   // paper, "Contact parameters": uniform in 40-70 kg
  double mass_max_kg = 70.0;
  double density_kg_m2 = kPaperDensityKgPerM2;  // rho of eq. 13 (paper, circle)
  double female_fraction = 0.5;  // anthropometric: probability that a person is female
  // Anthropometric bodies: core vertices and (maximum) sphero-radius; the radius
  // is reduced per person where a thin arm would otherwise be cut off (body.hpp).
  std::size_t vertex_count = 18;
  double radius_m = 0.05;
  ThoraxModel thorax;

  // Empty if valid, else a message naming the bad field and value.
  // false (and *error: what is wrong, what was expected) if a value is out of range.
  bool IsValid(std::string* error) const;
};

struct Person {
  Spheropolygon shape;               // body frame: centroid at the origin, chest to +x
  double mass_kg = 0.0;
  double moment_of_inertia_kgm2 = 0.0;  // about the centroid, I = rho J
  double density_kg_m2 = 0.0;        // m / A
  std::optional<Sex> sex;            // anthropometric mode only
  std::optional<std::int64_t> record_id;  // ANSUR II subjectid, anthropometric only
};

struct Population {
  PopulationOptions options;
  std::vector<Person> people;
  std::size_t distinct_shapes = 0;   // bodies actually built (the rest reused)
  std::size_t reduced_radius = 0;    // anthropometric bodies whose radius was reduced
};

// `reference` (body frame) is the thorax body of the paper and circle modes;
// `records` the ANSUR II extract for the anthropometric mode (may be empty
// otherwise). Throws InputError if what the mode needs is missing.
Population MakePopulation(const PopulationOptions& options, const Spheropolygon& reference,
                          const std::vector<AnsurRecord>& records);

// Population JSON (format "crowdrecon-population"): see docs/bodies.md.
void WritePopulationJson(const Population& population, const std::filesystem::path& file);
// A previous population JSON, which an output may replace.
OutputKind PopulationJsonOutput();

// Uniform double in [0, 1) from the top 53 bits of one draw (exact, portable).
inline double UniformUnit(std::uint64_t draw) {
  return static_cast<double>(draw >> 11) * 0x1.0p-53;
}

}  // namespace crowdrecon::geometry
