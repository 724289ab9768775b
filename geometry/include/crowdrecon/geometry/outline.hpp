// Outlines: the closed boundary of a body's cross-section as it comes from the
// user, before it becomes a spheropolygon (see body.hpp and docs/bodies.md).
//
// Two sources:
//   * an image (PNG, JPEG, BMP, TIFF): the largest dark (or light) region,
//     found by thresholding at mid-grey and tracing the region's outer border
//     with OpenCV; coordinates are pixels with the image's y axis flipped so
//     that y points up (row 0 is the top of the picture).
//   * a list of points: JSON `[[x, y], ...]` or `{"points": [[x, y], ...],
//     "front": "+y", "description": "..."}` ("front" and "description" are
//     optional), or CSV with one "x,y" pair a line ('#' comments, blank lines and
//     a non-numeric header line are skipped). Units are whatever the file uses
//     (metres for the outlines shipped in venues/bodies/).
//
// Every reader validates: at least 3 distinct points, finite, a simple polygon
// (no self-intersection) of non-zero area. The ring is returned counter-clockwise
// without a repeated closing point.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::geometry {

// Which region of an image is the body.
enum class ImageRegion { kDark, kLight };
std::string ToString(ImageRegion region);
// "dark" | "light"; throws InputError naming `what` otherwise.
ImageRegion ImageRegionFromString(const std::string& text, const std::string& what = "region");

// A body's front direction in the outline's own coordinates (ERRATA 6: the
// direction the chest faces, perpendicular to the shoulder line).
enum class FrontAxis { kPlusX, kMinusX, kPlusY, kMinusY };
std::string ToString(FrontAxis front);                // "+x", "-x", "+y", "-y"
FrontAxis FrontAxisFromString(const std::string& text, const std::string& what = "front");
Vec2 FrontVector(FrontAxis front);                    // unit vector

struct Outline {
  std::vector<Vec2> points;      // counter-clockwise ring, no closing repeat
  std::string source;            // file it came from (for messages and provenance)
  bool from_image = false;       // true: units are pixels of a traced raster border
  // For a traced image: the region's area (its pixel count, units^2) and the
  // mean distance from the traced contour (through border-pixel centres) out to
  // the region's edge, (area - contour area) / contour length, about half a
  // pixel. Zero for point lists, whose points are the edge itself.
  double region_area_units2 = 0.0;
  double edge_allowance_units = 0.0;
  std::string region;            // "dark"/"light" for images, empty otherwise
  std::optional<FrontAxis> front;  // front given by the file itself, if any
  std::string description;       // free text from the file, if any
  std::vector<std::string> notes;  // warnings found while reading (region cut by the border)
};

struct ImageOutlineOptions {
  ImageRegion region = ImageRegion::kDark;
  // Grey level (0..255) separating dark from light. 128 puts the border at
  // half coverage of anti-aliased edges, i.e. where the drawn edge really is.
  int threshold = 128;
};

// Reads the largest region of an image. Throws InputError on a missing or
// unreadable file, an image with no such region, or a region too small to trace.
Outline ReadOutlineImage(const std::filesystem::path& file, const ImageOutlineOptions& options = {});
// Reads a point list (.json or .csv).
Outline ReadOutlinePoints(const std::filesystem::path& file);
// Chooses by extension: .json/.csv are point lists, anything else an image.
Outline ReadOutline(const std::filesystem::path& file, const ImageOutlineOptions& options = {});

// Validates a ring and returns it counter-clockwise without consecutive
// duplicates or a closing repeat. `what` names it in messages.
std::vector<Vec2> ValidateOutlineRing(std::vector<Vec2> points, const std::string& what);

// Writes a point-list outline as JSON ({"description", "front", "points"}).
void WriteOutlineJson(const Outline& outline, const std::filesystem::path& file);
// A previous outline JSON (keys description, front, points and no others).
OutputKind OutlineJsonOutput();

// Area centroid of a ring (use SignedArea of spheropolygon.hpp for its area).
Vec2 RingCentroid(const std::vector<Vec2>& ring);

}  // namespace crowdrecon::geometry
