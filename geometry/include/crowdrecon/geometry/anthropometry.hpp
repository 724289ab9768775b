// Anthropometry: ANSUR II thorax dimensions and the thorax-with-arms outline
// built from them (docs/bodies.md, "Reference outline").
//
// The project ships an extract of ANSUR II (Gordon et al. 2014, NATICK/TR-15/007,
// public U.S. Government data) in venues/bodies/ansur2-thorax.csv, made by
// scripts/make-ansur-extract.py; nothing here reads ../shared at run time.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::geometry {

enum class Sex { kFemale, kMale };
std::string ToString(Sex sex);  // "female", "male"

// Horizontal dimensions of the upper body, metres (ANSUR II definitions).
struct ThoraxDimensions {
  double chest_breadth_m = 0.0;       // across the chest at nipple level (arms excluded)
  double chest_depth_m = 0.0;         // sternum/nipple level to the back
  double biacromial_breadth_m = 0.0;  // between the acromion points (shoulder bones)
  double bideltoid_breadth_m = 0.0;   // across the deltoid muscles: the widest point

  // Empty if usable for ThoraxOutline, else a message naming the bad value.
  // false (and *error: what is wrong, what was expected) if a value is out of range.
  bool IsValid(std::string* error) const;
};

struct AnsurRecord {
  std::int64_t subject_id = 0;  // ANSUR II `subjectid`
  Sex sex = Sex::kMale;
  ThoraxDimensions thorax;
  double weight_kg = 0.0;
  double stature_m = 0.0;
};

// Default location of the extract, relative to the project root.
inline constexpr const char* kAnsurExtractPath = "venues/bodies/ansur2-thorax.csv";

// Reads the extract (header subjectid,sex,chestbreadth,chestdepth,
// biacromialbreadth,bideltoidbreadth,weightkg,stature; mm and 0.1 kg as in
// ANSUR II). Errors name the file, line and column.
std::vector<AnsurRecord> ReadAnsurExtract(const std::filesystem::path& file);

// Per-dimension medians of a population in which a fraction `female_fraction`
// of people are female: each record is weighted by female_fraction / n_female or
// (1 - female_fraction) / n_male, and the weighted median is taken (the lower
// one at an exact half). This is the median of the mixed distribution, not of
// the raw sample (ANSUR II is one-third female).
ThoraxDimensions MedianThoraxDimensions(const std::vector<AnsurRecord>& records,
                                        double female_fraction);

// The construction of the outline (docs/bodies.md):
//   torso: superellipse |x/(D/2)|^n + |y/(B/2)|^n = 1 (D chest depth along the
//          front axis x, B chest breadth along y);
//   arms:  two ellipses, outer edge at y = +-W/2 (W bideltoid breadth), reaching
//          `arm_overlap_m` into the torso (pressed against the chest wall), with
//          front-to-back depth `arm_depth_fraction` * D, centred at x = 0.
// The outline is the boundary of the union: total width W, depth D.
struct ThoraxModel {
  double superellipse_exponent = 3.0;  // 2 = ellipse; larger = boxier
  double arm_overlap_m = 0.04;         // arm/torso overlap across y, m
  double arm_depth_fraction = 0.6;     // arm depth / chest depth
  std::size_t samples_per_shape = 240; // boundary points per piece (1.5 degree steps)

  // false (and *error: what is wrong, what was expected) if a value is out of range.
  bool IsValid(std::string* error) const;
};

// Boundary of the union, counter-clockwise, body frame (front +x, centred on
// the torso, which is the centroid by symmetry). Throws GeometryError if the
// dimensions are invalid.
std::vector<Vec2> ThoraxOutline(const ThoraxDimensions& dimensions, const ThoraxModel& model = {});

}  // namespace crowdrecon::geometry
