// From an outline to a body: scale, canonical frame, inward offset by the
// sphero-radius, simplification to N vertices, exact mass properties.
//
// Why this order (docs/bodies.md has the measurements): the swept shape is
// core ⊕ disk(r), so the core we want is the outline eroded by r, and every
// error of the core passes one-to-one to the swept boundary. Offsetting the
// *dense* outline first and simplifying the *core* last therefore spends the N
// vertices where the core needs them, and the count comes out exact because the
// last step removes vertices one by one down to N. The other order (simplify
// the outline to N, then offset) loses vertices where offset edges vanish and
// rounds the corners of an already coarse polygon a second time.
#include "crowdrecon/geometry/body.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/json_reader.hpp"
#include "crowdrecon/geometry/input_limits.hpp"
#include "outline_cgal.hpp"

namespace crowdrecon::geometry {

namespace {

// Radius of the fans that replace reflex corners before the offset, m.
constexpr double kCornerRoundingM = 1e-3;

double RingArea(const std::vector<Vec2>& ring) {
  double twice = 0.0;
  for (std::size_t i = 0; i < ring.size(); ++i) twice += Cross(ring[i], ring[(i + 1) % ring.size()]);
  return twice / 2.0;
}

// Points along a closed ring at most `spacing` apart, every vertex included.
std::vector<Vec2> ResampleRing(const std::vector<Vec2>& ring, double spacing) {
  std::vector<Vec2> out;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Vec2 a = ring[i], b = ring[(i + 1) % ring.size()];
    const int steps = std::max(1, static_cast<int>(std::ceil(Length(b - a) / spacing)));
    for (int k = 0; k < steps; ++k) out.push_back(a + (b - a) * (static_cast<double>(k) / steps));
  }
  return out;
}

// The straight skeleton offsets every vertex with a miter. At convex vertices
// that is exactly the erosion by a disk, but at a reflex (concave) corner the
// erosion's boundary is an arc of radius r around the corner, while the miter
// cuts deeper, to r / cos(turn / 2): at the notch between an arm and the torso
// (a turn of about 100 degrees) that pinches the neck and splits the core where
// the true erosion is whole. So each sharp reflex corner (turn above 30 degrees;
// below that the miter is less than 3.5% deeper) is first filleted with
// a polygonal arc of radius `radius` (tangent to both edges, adding a sliver of
// at most that size to the region); the skeleton offsets the arc's short edges
// into a polygonal arc of radius r + `radius`, as the erosion would.
std::vector<Vec2> RoundReflexCorners(const std::vector<Vec2>& ring, double radius) {
  constexpr double kMinTurnRad = 30.0 * std::numbers::pi / 180.0;
  constexpr double kStepRad = 15.0 * std::numbers::pi / 180.0;
  std::vector<Vec2> out;
  out.reserve(ring.size());
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = ring[(i + n - 1) % n], v = ring[i], b = ring[(i + 1) % n];
    const Vec2 e1 = v - a, e2 = b - v;
    const double turn = std::atan2(Cross(e1, e2), Dot(e1, e2));  // < 0: reflex on a CCW ring
    // The tangent points must stay on the edges.
    const double half_wedge = (std::numbers::pi + turn) / 2.0;  // half the exterior angle
    const double tangent_distance = radius / std::tan(half_wedge);
    if (turn > -kMinTurnRad || turn < -std::numbers::pi + 1e-3 ||
        tangent_distance > 0.5 * std::min(Length(e1), Length(e2))) {
      out.push_back(v);
      continue;
    }
    const Vec2 bisector = Normalized(Normalized(e2) - Normalized(e1));
    const Vec2 centre = v + bisector * (radius / std::sin(half_wedge));
    const double from = std::atan2(-e1.x, e1.y);  // outward (right-hand) normal of e1
    const int steps = static_cast<int>(std::ceil(-turn / kStepRad));
    for (int k = 0; k <= steps; ++k) {
      const double phi = from + turn * k / steps;  // clockwise, towards e2's normal
      out.push_back(centre - Vec2{std::cos(phi), std::sin(phi)} * radius);
    }
  }
  return out;
}

// Moves every edge of a closed polygon along its outward normal by `delta`
// (negative: inward): each vertex goes to the intersection of its two moved
// edges, i.e. along the miter (n1 + n2) / (1 + n1 . n2).
std::vector<Vec2> ShiftEdgesOutward(const std::vector<Vec2>& ring, double delta) {
  const std::size_t n = ring.size();
  std::vector<Vec2> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = ring[(i + n - 1) % n], v = ring[i], b = ring[(i + 1) % n];
    const Vec2 e1 = Normalized(v - a), e2 = Normalized(b - v);
    const Vec2 n1{e1.y, -e1.x}, n2{e2.y, -e2.x};  // outward on a counter-clockwise ring
    // Spikes (turns near 180 degrees) would send the vertex far away; cap the miter at 4.
    const double denominator = std::max(1.0 + Dot(n1, n2), 0.125);
    out[i] = v + (n1 + n2) * (delta / denominator);
  }
  return out;
}

// Metres per unit of the outline's coordinates according to the rule. For
// traced images the contour runs through the centres of the border pixels,
// about half a pixel inside the region's edge on every side, so that allowance
// is added on both sides of measured lengths.
double MetresPerUnit(const Outline& outline, const ScaleRule& rule, Vec2 front,
                     const std::string& what) {
  const double edge_allowance = 2.0 * outline.edge_allowance_units;
  switch (rule.kind) {
    case ScaleRule::Kind::kNone:
      if (outline.from_image)
        throw InputError(what + ": an image outline is in pixels and needs a scale rule "
                                "(none given); expected sternum:DEPTH_M, shoulder:WIDTH_M or "
                                "ppm:PIXELS_PER_M");
      return 1.0;
    case ScaleRule::Kind::kSternum:
      return rule.value / (DepthAlongAxisThroughCentroid(outline.points, front) + edge_allowance);
    case ScaleRule::Kind::kShoulder:
      return rule.value / (ExtentAlongAxis(outline.points, Perp(front)) + edge_allowance);
    case ScaleRule::Kind::kPixelsPerMetre:
      return 1.0 / rule.value;
  }
  return 1.0;
}

// Refuses an outline far larger than a person (input_limits.hpp) before any
// work that grows with its size: an outline in the wrong units would sample
// millions of boundary points.
void CheckBodySize(const std::vector<Vec2>& ring_m, const Outline& outline, const ScaleRule& rule,
                   double metres_per_unit, const std::string& what) {
  const double across_m = std::max(ExtentAlongAxis(ring_m, {1.0, 0.0}), ExtentAlongAxis(ring_m, {0.0, 1.0}));
  if (across_m <= kMaxBodyExtentM) return;
  throw GeometryError(what + ": the outline is " + FormatNumber(across_m) + " m across (scale " + ToString(rule) +
                      ", " + FormatNumber(metres_per_unit) + " m per " + (outline.from_image ? "pixel" : "unit") +
                      "); a body is 0.2-1 m across and at most " + FormatNumber(kMaxBodyExtentM) +
                      " m is accepted: check the scale/units (--scale)");
}

std::string Join(const std::vector<std::string>& items, const std::string& sep) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? sep : "") + items[i];
  return out;
}

bool Close(double a, double b, double relative, double absolute) {
  return std::abs(a - b) <= std::max(absolute, relative * std::max(std::abs(a), std::abs(b)));
}

}  // namespace

// --- scale rules -----------------------------------------------------------

std::string ToString(const ScaleRule& rule) {
  switch (rule.kind) {
    case ScaleRule::Kind::kNone: return "none";
    case ScaleRule::Kind::kSternum: return "sternum:" + FormatNumber(rule.value);
    case ScaleRule::Kind::kShoulder: return "shoulder:" + FormatNumber(rule.value);
    case ScaleRule::Kind::kPixelsPerMetre: return "ppm:" + FormatNumber(rule.value);
  }
  return "?";
}

ScaleRule ScaleRuleFromString(const std::string& text, const std::string& what) {
  const std::string expected =
      "expected sternum:DEPTH_M (e.g. sternum:0.20), shoulder:WIDTH_M (e.g. shoulder:0.45), "
      "ppm:PIXELS_PER_METRE (e.g. ppm:1000) or none";
  if (text == "none") return ScaleRule::None();
  const auto colon = text.find(':');
  if (colon == std::string::npos)
    throw InputError(what + ": unknown scale rule \"" + text + "\"; " + expected);
  const std::string name = text.substr(0, colon), number = text.substr(colon + 1);
  ScaleRule rule;
  if (name == "sternum") rule.kind = ScaleRule::Kind::kSternum;
  else if (name == "shoulder") rule.kind = ScaleRule::Kind::kShoulder;
  else if (name == "ppm") rule.kind = ScaleRule::Kind::kPixelsPerMetre;
  else throw InputError(what + ": unknown scale rule \"" + name + "\" in \"" + text + "\"; " + expected);
  char* end = nullptr;
  rule.value = std::strtod(number.c_str(), &end);
  if (number.empty() || *end != '\0' || !std::isfinite(rule.value) || rule.value <= 0.0)
    throw InputError(what + ": scale value \"" + number + "\" in \"" + text +
                     "\" is not a positive number; " + expected);
  return rule;
}

double DepthAlongAxisThroughCentroid(const std::vector<Vec2>& ring, Vec2 front) {
  const Vec2 c = RingCentroid(ring);
  double t_min = std::numeric_limits<double>::infinity(), t_max = -t_min;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Vec2 p = ring[i] - c, q = ring[(i + 1) % ring.size()] - c;
    const double sp = Cross(front, p), sq = Cross(front, q);  // signed distances to the line
    if ((sp > 0.0) == (sq > 0.0)) continue;
    const Vec2 x = p + (q - p) * (sp / (sp - sq));
    t_min = std::min(t_min, Dot(front, x));
    t_max = std::max(t_max, Dot(front, x));
  }
  return t_max > t_min ? t_max - t_min : 0.0;
}

double ExtentAlongAxis(const std::vector<Vec2>& ring, Vec2 axis) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Vec2& p : ring) {
    lo = std::min(lo, Dot(p, axis));
    hi = std::max(hi, Dot(p, axis));
  }
  return hi - lo;
}

bool BodyOptions::IsValid(std::string* error) const {
  const std::string problem = [&]() -> std::string {
    if (vertex_count < 3)
      return "vertex count (" + std::to_string(vertex_count) + ") is too small; expected at least 3";
    if (vertex_count > 1000)
      return "vertex count (" + std::to_string(vertex_count) + ") is too large; expected at most 1000";
    if (!std::isfinite(radius_m) || radius_m <= 0.0)
      return "sphero-radius (" + FormatNumber(radius_m) + " m) must be positive; expected e.g. 0.05";
    if (!std::isfinite(presimplify_tolerance_m) || presimplify_tolerance_m < 0.0)
      return "pre-simplification tolerance (" + FormatNumber(presimplify_tolerance_m) +
             " m) must be >= 0";
    if (!std::isfinite(hausdorff_spacing_m) || hausdorff_spacing_m < 0.0)
      return "Hausdorff sampling spacing (" + FormatNumber(hausdorff_spacing_m) + " m) must be >= 0";
    if (scale.kind != ScaleRule::Kind::kNone && !(std::isfinite(scale.value) && scale.value > 0.0))
      return "scale value (" + FormatNumber(scale.value) + ") must be positive";
    return "";
  }();
  if (!problem.empty() && error) *error = problem;
  return problem.empty();
}

// --- the pipeline ------------------------------------------------------------

Body BuildBody(const Outline& outline, const BodyOptions& options) {
  const std::string what = outline.source.empty() ? std::string("outline") : outline.source;
  if (std::string error; !options.IsValid(&error)) throw InputError(what + ": " + error);
  const std::vector<Vec2> points = ValidateOutlineRing(outline.points, what);
  std::vector<std::string> notes = outline.notes;

  // 1-2. Metres, centred on the outline's centroid (keeps pixel coordinates
  // small), rotated so that the front faces +x.
  const Vec2 front = FrontVector(options.front);
  const double metres_per_unit = MetresPerUnit(outline, options.scale, front, what);
  const double to_body_frame_rad = -std::atan2(front.y, front.x);
  const Vec2 centre = RingCentroid(points);
  std::vector<Vec2> dense_m;
  dense_m.reserve(points.size());
  for (const Vec2& p : points) dense_m.push_back(Rotated((p - centre) * metres_per_unit, to_body_frame_rad));
  CheckBodySize(dense_m, outline, options.scale, metres_per_unit, what);

  // 3. Light pre-simplification: removes a raster's staircase and points that
  // carry no shape, so that the straight skeleton (superlinear in the vertex
  // count) runs on a few hundred vertices at most.
  const double pixel_m = outline.from_image ? metres_per_unit : 0.0;
  const double tolerance_m = std::max(options.presimplify_tolerance_m, 0.5 * pixel_m);
  const std::vector<Vec2> outline_m =
      tolerance_m > 0.0 ? detail::SimplifyRingToTolerance(dense_m, tolerance_m) : dense_m;

  // 4. Inward offset by the sphero-radius. A traced contour lies about half a
  // pixel inside the region's edge, so it is offset by that much less.
  const double edge_m = outline.edge_allowance_units * metres_per_unit;
  double radius_m = options.radius_m;
  std::vector<std::vector<Vec2>> pieces;
  for (;;) {
    const double offset_m = radius_m - edge_m;
    if (offset_m <= 0.0)
      throw GeometryError(what + ": sphero-radius (" + FormatNumber(radius_m) +
                          " m) is smaller than half a pixel (" + FormatNumber(edge_m) +
                          " m); expected a larger radius or a finer image");
    pieces = detail::InwardOffsetPieces(RoundReflexCorners(outline_m, kCornerRoundingM), offset_m);
    const bool retry = options.shrink_radius_to_keep_one_piece && pieces.size() > 1 &&
                       radius_m * 0.9 >= 0.5 * options.radius_m - 1e-12;
    if (!retry) break;
    radius_m *= 0.9;
  }
  if (pieces.empty())
    throw GeometryError(what + ": outline too thin for the sphero-radius (" + FormatNumber(radius_m) +
                        " m): the inward offset vanishes, i.e. no part of the outline is " +
                        FormatNumber(2 * radius_m) +
                        " m thick; expected a smaller --radius or a larger outline (check the scale)");
  if (radius_m != options.radius_m)
    notes.push_back("sphero-radius reduced from " + FormatNumber(options.radius_m) + " m to " +
                    FormatNumber(radius_m) + " m so that the core stays in one piece");
  if (pieces.size() > 1) {
    std::vector<std::string> areas;
    for (const auto& piece : pieces) areas.push_back(FormatNumber(RingArea(piece)));
    notes.push_back("the inward offset by the sphero-radius split into " +
                    std::to_string(pieces.size()) + " pieces (core areas " + Join(areas, ", ") +
                    " m^2); kept the largest, parts narrower than " + FormatNumber(2 * radius_m) +
                    " m are lost");
  }

  // 5. Exactly N vertices (fewer only if the core has fewer corners).
  std::vector<Vec2> core = detail::SimplifyRingToCount(pieces.front(), options.vertex_count);
  if (core.size() != options.vertex_count)
    notes.push_back("the core polygon has " + std::to_string(core.size()) + " vertices, not the " +
                    std::to_string(options.vertex_count) + " asked for (" +
                    (core.size() < options.vertex_count
                         ? "the offset outline has no more corners"
                         : "removing more would make it self-intersect") +
                    ")");

  // 6. The swept shape and its exact mass properties.
  Spheropolygon placed = Spheropolygon::Create(core, radius_m, what + ": core polygon");

  // 6b. Area matching. The simplified core's edges are chords of the dense
  // core, so the swept shape lies inside the outline wherever the outline is
  // convex and comes out too small (1.5% for an 18-vertex ellipse): a bias, not
  // noise, and one that would pass into the mass (m = rho A). Shifting every
  // core edge outward by the same distance delta = (A_outline - A_swept) / P
  // (P the swept perimeter, ~ the rate dA/d delta) centres the error on the
  // outline instead; two rounds make the areas agree to ~1e-6. Skipped when the
  // offset split (the outline's area then includes parts the body has lost).
  if (pieces.size() == 1 && core.size() >= 3) {
    // Area enclosed by the outline; for a traced image, the region's pixel count.
    const double target_m2 = outline.region_area_units2 > 0.0
                                 ? outline.region_area_units2 * metres_per_unit * metres_per_unit
                                 : RingArea(dense_m);
    for (int round = 0; round < 2; ++round) {
      const double swept_perimeter_m =
          placed.CorePerimeter() + 2.0 * std::numbers::pi * placed.radius();
      const double delta_m = (target_m2 - placed.area()) / swept_perimeter_m;
      std::vector<Vec2> shifted = ShiftEdgesOutward(placed.vertices(), delta_m);
      try {
        placed = Spheropolygon::Create(std::move(shifted), radius_m, what + ": core polygon");
      } catch (const GeometryError&) {
        break;  // the shift would fold the core (never seen); keep the chords
      }
    }
  }
  // Centroid to the origin.
  const Vec2 centroid = placed.centroid();
  Body body{placed.Centered(), {}, what, ToString(options.front), ToString(options.scale),
            metres_per_unit, -1.0, pieces.size(), notes};
  body.outline_m.reserve(outline_m.size());
  for (const Vec2& p : outline_m) body.outline_m.push_back(p - centroid);

  // 7. Fidelity against the dense outline (not the pre-simplified one).
  if (options.hausdorff_spacing_m > 0.0) {
    std::vector<Vec2> dense_body = dense_m;
    for (Vec2& p : dense_body) p -= centroid;
    body.hausdorff_m = HausdorffDistance(ResampleRing(dense_body, options.hausdorff_spacing_m),
                                         body.shape.SampleBoundary(options.hausdorff_spacing_m));
  }
  return body;
}

std::string BodyReport(const Body& body) {
  std::ostringstream out;
  const Spheropolygon& s = body.shape;
  const double rho = kPaperDensityKgPerM2;
  out << "vertices: " << s.size() << ", sphero-radius " << FormatNumber(s.radius()) << " m\n";
  out << "area: " << FormatNumber(s.area()) << " m^2 (mass " << FormatNumber(rho * s.area())
      << " kg at rho = 1000 kg/m^2)\n";
  out << "polar moment J: " << FormatNumber(s.polar_moment()) << " m^4 (I = rho J = "
      << FormatNumber(rho * s.polar_moment()) << " kg m^2 at rho = 1000 kg/m^2)\n";
  out << "extent: depth (x, front) " << FormatNumber(s.BoundsMax().x - s.BoundsMin().x)
      << " m, width (y, shoulders) " << FormatNumber(s.BoundsMax().y - s.BoundsMin().y) << " m\n";
  if (body.hausdorff_m >= 0.0)
    out << "Hausdorff distance outline - swept shape: " << FormatNumber(body.hausdorff_m) << " m\n";
  out << "scale: " << body.scale_rule << " (" << FormatNumber(body.metres_per_unit)
      << " m per outline unit), source front " << body.source_front << " -> body +x\n";
  for (const std::string& note : body.notes) out << "note: " << note << "\n";
  return out.str();
}

// --- JSON --------------------------------------------------------------------

namespace {
nlohmann::ordered_json PointsJson(const std::vector<Vec2>& points) {
  nlohmann::ordered_json a = nlohmann::ordered_json::array();
  for (const Vec2& p : points) a.push_back({p.x, p.y});
  return a;
}
}  // namespace

void WriteBodyJson(const Body& body, const std::filesystem::path& file) {
  nlohmann::ordered_json j;
  j["format"] = "crowdrecon-body";
  j["version"] = 1;
  j["front_axis"] = "+x";  // the body frame: centroid at the origin, chest facing +x
  j["radius_m"] = body.shape.radius();
  j["vertices_m"] = PointsJson(body.shape.vertices());
  j["area_m2"] = body.shape.area();
  j["centroid_m"] = {body.shape.centroid().x, body.shape.centroid().y};
  j["polar_moment_m4"] = body.shape.polar_moment();
  j["hausdorff_m"] = body.hausdorff_m;
  nlohmann::ordered_json source;
  source["outline"] = body.source;
  source["front"] = body.source_front;
  source["scale_rule"] = body.scale_rule;
  source["metres_per_unit"] = body.metres_per_unit;
  source["offset_pieces"] = body.offset_pieces;
  source["notes"] = body.notes;
  source["outline_m"] = PointsJson(body.outline_m);
  j["source"] = source;
  WriteFileAtomically(file, j.dump(1) + '\n');
}

OutputKind BodyJsonOutput() {
  return JsonOutputKind("a body JSON (format crowdrecon-body)",
                        [](const nlohmann::json& j) { return j.contains("format") && j["format"] == "crowdrecon-body"; });
}

Body ReadBodyJson(const std::filesystem::path& file) {
  const JsonDocument doc = JsonDocument::Load(file);
  const JsonReader root = doc.Root();
  if (!root.IsObject()) root.Fail("expected a body object {\"format\": \"crowdrecon-body\", ...}");
  root.Choice("format", {"crowdrecon-body"});
  root.Integer("version", 1, 1);
  root.Choice("front_axis", {"+x"});
  const JsonReader vertices_json = root.At("vertices_m");
  const std::vector<Vec2> vertices = vertices_json.AsPoints(1);
  for (std::size_t i = 0; i < vertices.size(); ++i)
    for (const double c : {vertices[i].x, vertices[i].y})
      if (!(std::abs(c) <= kMaxBodyExtentM))
        vertices_json.Element(i).Fail("coordinate " + FormatNumber(c) + " m is beyond " +
                                      FormatNumber(kMaxBodyExtentM) +
                                      " m from the centroid; expected a body 0.2-1 m across, in metres: check the units");
  const double radius_m = root.Number("radius_m", 1e-9, 10.0);
  const double area_m2 = root.Number("area_m2", 0.0, 1e3);
  const Vec2 centroid_m = root.At("centroid_m").AsPoint();
  const double polar_moment_m4 = root.Number("polar_moment_m4", 0.0, 1e3);
  const double hausdorff_m = root.Number("hausdorff_m", -1.0, -1.0, 10.0);

  const JsonReader source = root.At("source");
  const std::string outline = source.String("outline");
  const std::string front = source.Choice("front", {"+x", "-x", "+y", "-y"});
  const JsonReader scale_json = source.At("scale_rule");
  const std::string scale_text = scale_json.AsString();
  (void)ScaleRuleFromString(scale_text, scale_json.Where());  // validates
  const double metres_per_unit = source.Number("metres_per_unit", 1e-12, 1e12);
  const auto pieces = static_cast<std::size_t>(source.Integer("offset_pieces", 1, 1, 1000000));
  std::vector<std::string> notes;
  if (const auto notes_json = source.Find("notes")) {
    for (std::size_t i = 0; i < notes_json->Size(); ++i) notes.push_back(notes_json->Element(i).AsString());
  }
  std::vector<Vec2> outline_m;
  if (const auto outline_json = source.Find("outline_m")) outline_m = outline_json->AsPoints(0);
  source.Finish();
  root.Finish();

  Spheropolygon shape = Spheropolygon::Create(vertices, radius_m, vertices_json.Where());
  const auto mismatch = [&](const std::string& key, const std::string& stored, const std::string& computed) {
    root.At(key).Fail("stored value " + stored + " does not match the shape (" + computed +
                      "); expected the value computed from vertices_m and radius_m");
  };
  if (!Close(area_m2, shape.area(), 1e-6, 1e-12))
    mismatch("area_m2", FormatNumber(area_m2), FormatNumber(shape.area()));
  if (!Close(polar_moment_m4, shape.polar_moment(), 1e-6, 1e-15))
    mismatch("polar_moment_m4", FormatNumber(polar_moment_m4), FormatNumber(shape.polar_moment()));
  if (Length(centroid_m - shape.centroid()) > 1e-6)
    mismatch("centroid_m", "[" + FormatNumber(centroid_m.x) + ", " + FormatNumber(centroid_m.y) + "]",
             "[" + FormatNumber(shape.centroid().x) + ", " + FormatNumber(shape.centroid().y) + "]");
  if (Length(shape.centroid()) > 1e-6)
    root.At("vertices_m").Fail("the shape's centroid is at (" + FormatNumber(shape.centroid().x) + ", " +
                               FormatNumber(shape.centroid().y) +
                               "); expected the body frame, centroid at the origin");
  return Body{std::move(shape), std::move(outline_m), outline, front, scale_text, metres_per_unit,
              hausdorff_m, pieces, std::move(notes)};
}

}  // namespace crowdrecon::geometry
