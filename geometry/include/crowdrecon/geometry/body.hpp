// Bodies: a pedestrian's cross-section as a spheropolygon in the canonical body
// frame, built from an outline (outline.hpp). See docs/bodies.md for the
// pipeline, the order of operations and the decisions taken where the paper is
// ambiguous.
//
//   Outline outline = ReadOutline("thorax.png");
//   BodyOptions options;                     // 18 vertices, r = 0.05 m, sternum 0.20 m
//   Body body = BuildBody(outline, options);
//   WriteBodyJson(body, "thorax-18.json");
//
// Body frame: the centroid of the swept shape is the origin and the chest faces
// +x (ERRATA 6: the body's orientation angle theta is the direction the chest
// faces, perpendicular to the shoulder line, which lies along y).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/vec2.hpp"
#include "crowdrecon/geometry/outline.hpp"
#include "crowdrecon/geometry/spheropolygon.hpp"

namespace crowdrecon::geometry {

// How an outline's units become metres.
struct ScaleRule {
  enum class Kind {
    // Coordinates are metres already.
    kNone,
    // The outline's depth along its front axis, measured on the line through its
    // area centroid (frontmost minus rearmost crossing of that line), becomes
    // `value` metres. The paper's "sternum width of 200 mm" can only be this
    // front-to-back depth (a sternum is ~4 cm wide; 200 mm is a chest depth).
    kSternum,
    // The outline's full extent across the shoulder axis (perpendicular to the
    // front axis) becomes `value` metres.
    kShoulder,
    // `value` outline units (pixels) per metre.
    kPixelsPerMetre,
  };
  Kind kind = Kind::kNone;
  double value = 1.0;

  static ScaleRule None() { return {Kind::kNone, 1.0}; }
  static ScaleRule Sternum(double depth_m) { return {Kind::kSternum, depth_m}; }
  static ScaleRule Shoulder(double width_m) { return {Kind::kShoulder, width_m}; }
  static ScaleRule PixelsPerMetre(double ppm) { return {Kind::kPixelsPerMetre, ppm}; }
};
// "none", "sternum:0.2", "shoulder:0.45", "ppm:1000".
std::string ToString(const ScaleRule& rule);
// Parses the forms above; throws InputError naming `what` (e.g. "--scale").
ScaleRule ScaleRuleFromString(const std::string& text, const std::string& what = "scale");

// Depth of a ring along unit direction `front` on the line through its area
// centroid (same units as the ring).
double DepthAlongAxisThroughCentroid(const std::vector<Vec2>& ring, Vec2 front);
// Extent of a ring's projection onto unit direction `axis`.
double ExtentAlongAxis(const std::vector<Vec2>& ring, Vec2 axis);

struct BodyOptions {
  std::size_t vertex_count = 18;  // vertices of the core polygon (paper: 18)
  double radius_m = 0.05;         // sphero-radius, m (paper: 0.05)
  ScaleRule scale = ScaleRule::None();
  FrontAxis front = FrontAxis::kPlusY;  // where the chest faces in the outline
  // Tolerance of the light pre-simplification of the dense outline, m. Pixel
  // outlines use at least half a pixel (the staircase of a traced raster edge).
  double presimplify_tolerance_m = 2e-4;
  // Spacing of the boundary samples for the Hausdorff distance, m; 0 skips it.
  double hausdorff_spacing_m = 5e-4;
  // If the inward offset splits (a narrow neck, e.g. a thin arm), retry with a
  // sphero-radius reduced in steps of 10% down to half of radius_m, and keep the
  // first radius whose core is one piece. Off for `crowdrecon shape` (the
  // radius asked for is kept and the largest piece used, with a note); on for
  // anthropometric populations so that thin-armed people keep their arms.
  bool shrink_radius_to_keep_one_piece = false;

  // Empty if valid, else a message naming the bad field and value.
  // false (and *error: what is wrong, what was expected) if a value is out of range.
  bool IsValid(std::string* error) const;
};

struct Body {
  Spheropolygon shape;            // body frame, centroid at the origin, chest to +x
  std::vector<Vec2> outline_m;    // the input outline in the body frame, metres
  std::string source;             // outline file (or generator) it came from
  std::string source_front;       // front axis of the source, "+y" etc.
  std::string scale_rule;         // ToString(ScaleRule)
  double metres_per_unit = 1.0;   // scale applied to the source's coordinates
  double hausdorff_m = -1.0;      // outline vs swept boundary; < 0 if not computed
  std::size_t offset_pieces = 1;  // pieces of the inward offset (1 unless it split)
  std::vector<std::string> notes; // things the user should know (split offset, ...)

  double area_m2() const { return shape.area(); }
  double polar_moment_m4() const { return shape.polar_moment(); }
};

// Builds a body from an outline. Order of operations (docs/bodies.md):
//   1. scale to metres by the rule (measured on the outline in its own frame);
//   2. rotate so the front faces +x;
//   3. light pre-simplification of the dense outline (tolerance above);
//   4. inward offset by the sphero-radius (straight skeleton), largest piece;
//   5. simplification of that core to exactly `vertex_count` vertices;
//   6. Spheropolygon::Create, then translate the swept centroid to the origin;
//   7. Hausdorff distance between the outline and the swept boundary.
// Throws InputError/GeometryError with the outline's file in the message.
Body BuildBody(const Outline& outline, const BodyOptions& options);

// Surface density used by the paper, kg/m^2 (m = rho A, eq. 13).
inline constexpr double kPaperDensityKgPerM2 = 1000.0;

// Body JSON (format "crowdrecon-body", version 1): see docs/bodies.md.
void WriteBodyJson(const Body& body, const std::filesystem::path& file);
// A previous body JSON, which an output may replace (common/output_path.hpp).
OutputKind BodyJsonOutput();
// Reads and validates a body file (unknown keys, ranges, a valid spheropolygon
// whose stored area/centroid/polar moment match the recomputed ones).
Body ReadBodyJson(const std::filesystem::path& file);

// Multi-line human-readable summary (vertex count, area, J, I at rho = 1000
// kg/m^2, Hausdorff distance, notes).
std::string BodyReport(const Body& body);

}  // namespace crowdrecon::geometry
