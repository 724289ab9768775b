// Venue: the floor plan a scenario runs in. A plain value (rings of Vec2, ids,
// segments) read from a JSON file (docs/venues.md) or imported from a WKT
// walkable area, a DXF floor plan or a raster image of a plan.
//
// The model of a venue:
//   * walkable_area  outer rings of the region people may occupy (one per
//                    connected part, as the polygons of a WKT MULTIPOLYGON);
//   * obstacles      solid polygons inside it (pillars, bars, a stage): they are
//                    the holes of the walkable area and their edges are walls;
//   * walls          the building's walls as polylines or polygons, usually along
//                    the boundary of the walkable area. Walls are explicit because
//                    some boundary edges are open (exits, periodic ends);
//   * exits          segments on the boundary (or across the area) where people
//                    leave; wall parts that coincide with an exit are openings;
//   * entries        polygons where people are placed when they enter;
//   * measurement areas and lines (as in PedPy), periodic directions, targets
//     (an exit or a fixed direction), an optional floor slope and metadata.
//
// Every coordinate is in metres once loaded (a file may declare another unit
// with metadata.scale_m_per_unit). Errors are InputError (bad file) or
// GeometryError (geometry that is not a valid venue), with messages of the form
// "file: /json/path: what is wrong (value); expected ...".
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::geometry {

// A closed polygon given by its vertices (the closing edge from the last vertex
// back to the first is implied; a repeated first vertex at the end is dropped on
// input). Either orientation is accepted.
using Ring = std::vector<Vec2>;

struct VenueMetadata {
  std::string name;         // short title shown in pictures and summaries
  std::string source;       // where the geometry comes from (plan, paper, import)
  std::string description;  // free text
  // Free-text notes, e.g. one per assumption taken while drawing the venue.
  std::vector<std::string> notes;
};

// A solid object inside the walkable area; a hole of the walkable area whose
// edges are walls of radius `radius_m`.
struct Obstacle {
  std::string id;
  Ring polygon;
  double radius_m = 0.0;  // sphero-radius of its edges as walls (m)
};

// A wall of the building: an open polyline or a closed polygon. The engine sees
// each of its edges as a segment swept by a disk of radius `radius_m`, so the
// wall's surface lies radius_m from the line.
struct Wall {
  std::string id;
  std::vector<Vec2> points;
  bool closed = false;    // true: polygon (closing edge implied)
  double radius_m = 0.0;  // sphero-radius (m)
};

// A segment where people leave the venue (an opening in the walls).
struct Exit {
  std::string id;
  Vec2 a, b;
  // The segment's length; the opening people pass through is narrower by
  // the jambs' thickness: Venue::FreeWidth_m.
  double width_m() const { return Length(b - a); }
};

// A zone where entering people are placed.
struct EntryZone {
  std::string id;
  Ring polygon;
};

struct MeasurementArea {
  std::string id;
  Ring polygon;
};

struct MeasurementLine {
  std::string id;
  Vec2 a, b;
};

// Periodic boundary: a person leaving the area at one end along `direction`
// re-enters at the other, `period_m` away (the extent of the walkable area
// along the direction).
struct PeriodicDirection {
  Vec2 direction;  // unit vector
  double period_m = 0.0;
};

// Where a group of people wants to go: toward an exit (desired direction from
// the navigation field) or in a fixed direction (periodic corridors).
struct Target {
  enum class Kind { kExit, kDirection };
  std::string id;
  Kind kind = Kind::kDirection;
  std::string exit_id;  // for kExit: the (first) exit
  // For kExit: every exit of the target, the first being exit_id; with
  // several ("exits": [...]) people walk to the nearest by walking distance.
  std::vector<std::string> exit_ids;
  Vec2 direction;       // for kDirection: unit vector
};

// An inclined floor. The floor descends along `direction` by `gradient` metres
// per metre (rise over run); gravity then pulls with m g sin(atan(gradient)).
struct Slope {
  Vec2 direction;         // downhill, unit vector
  double gradient = 0.0;  // dimensionless, in [0, 1]
  bool enabled = true;    // a slope may be documented but switched off
  Ring region;            // where the floor slopes (empty: the whole floor)
};

struct Venue {
  VenueMetadata metadata;
  std::vector<Ring> walkable_area;  // outer rings, at least one
  std::vector<Obstacle> obstacles;
  std::vector<Wall> walls;
  std::vector<Exit> exits;
  std::vector<EntryZone> entries;
  std::vector<MeasurementArea> measurement_areas;
  std::vector<MeasurementLine> measurement_lines;
  std::vector<PeriodicDirection> periodic;
  std::vector<Target> targets;
  std::optional<Slope> slope;
  // Where the venue came from ("venues/x.json"), for messages. Not written.
  std::string origin;

  const Exit* FindExit(std::string_view id) const;
  // The free width of an exit: its segment's length less the sphero-radius
  // of the wall that ends at each of its ends (a door's jambs), the width
  // people pass through and flows per metre are measured against.
  double FreeWidth_m(const Exit& exit) const;
  // A target by id: first the declared targets, then an exit of that id (every
  // exit is implicitly a target). nullopt if there is neither.
  std::optional<Target> FindTarget(std::string_view id) const;
};

// --- JSON ------------------------------------------------------------------

// Reads and validates a venue file. Throws InputError for syntax, unknown keys,
// wrong types or ranges, and GeometryError (listing every problem found) for
// geometry that is not a valid venue.
Venue LoadVenue(const std::filesystem::path& file);
// The same from text; `origin` names the text in messages.
Venue ParseVenue(std::string_view json_text, const std::string& origin);
// The venue as JSON text (coordinates in metres), readable by ParseVenue.
std::string VenueToJson(const Venue& venue);
// Writes VenueToJson to a file; throws InputError if it cannot.
void WriteVenueJson(const Venue& venue, const std::filesystem::path& file);
// A previous venue JSON (version and walkable_area), which an output may replace.
OutputKind VenueJsonOutput();

// --- validation --------------------------------------------------------------

// Every problem of the venue's geometry, one message each ("origin: /path: ...").
// Checks: finite coordinates within kVenueMaxCoordinate_m, rings with at least 3 distinct vertices and non-zero area, simple (no
// self-intersection, no repeated vertex), obstacles strictly inside one outer
// ring and disjoint from each other, outer rings disjoint, a walkable area of
// positive area, exits, entries, measurement areas and lines inside the
// walkable area or on its boundary (within kVenueTolerance_m), unique ids,
// targets naming existing exits, periodic periods matching the area's extent.
std::vector<std::string> FindVenueProblems(const Venue& venue);
// Throws GeometryError with every problem (one per line) if there is any.
void ValidateVenue(const Venue& venue);

// Largest magnitude of a venue coordinate (m): beyond it a unit is surely
// wrong, and squared lengths lose the digits the geometry needs. Checked by
// FindVenueProblems, so by `venue check` and by every importer alike.
inline constexpr double kVenueMaxCoordinate_m = 1e7;

// Distance (m) within which a point counts as on the boundary of the walkable
// area, and an exit's endpoints may lie outside it (drawing rounding).
inline constexpr double kVenueTolerance_m = 1e-3;

// --- derived quantities -------------------------------------------------------

// Walkable area: outer rings minus obstacles (m^2).
double WalkableArea_m2(const Venue& venue);
// Length of the boundary of the walkable area, outer rings and obstacles (m).
double WalkablePerimeter_m(const Venue& venue);
// True if p is in the walkable area (inside an outer ring, outside every
// obstacle); points on the boundary count as inside.
bool IsWalkable(const Venue& venue, Vec2 p);
// Axis-aligned bounds of the walkable area.
void WalkableBounds(const Venue& venue, Vec2* min, Vec2* max);

// A wall segment for the engine: the segment [a, b] swept by a disk of
// radius radius_m.
struct WallSegment {
  Vec2 a, b;
  double radius_m = 0.0;
};
// Every wall edge and obstacle edge as a segment, with the parts that coincide
// with an exit (collinear and overlapping within kVenueTolerance_m) cut out, so
// that exits are openings even when a wall polygon is drawn across them.
std::vector<WallSegment> WallSegments(const Venue& venue);

// Signed area of a ring (positive when counter-clockwise), its perimeter, and
// an even-odd point-in-ring test (boundary points may go either way).
double RingSignedArea_m2(const Ring& ring);
double RingPerimeter_m(const Ring& ring);
bool PointInRing(const Ring& ring, Vec2 p);
// Distance from p to the edges of a ring.
double DistanceToRing(const Ring& ring, Vec2 p);

// --- importers ----------------------------------------------------------------

struct ImportOptions {
  std::string name;  // metadata.name; empty: the file's stem
  // Metres per coordinate unit of the input (WKT, DXF); <= 0: DXF takes it from
  // the file's $INSUNITS (metres if absent), WKT uses metres.
  double scale_m_per_unit = 0.0;
  // DXF only: import entities of this layer only (empty: every layer).
  std::string dxf_layer;
  // DXF only: arcs and circles are flattened into segments whose distance to
  // the arc is at most this (m).
  double dxf_arc_tolerance_m = 0.01;
  // DXF only: endpoints closer than this (m) are joined when chaining lines into rings.
  double dxf_join_tolerance_m = 1e-3;
};

// WKT POLYGON or MULTIPOLYGON (as JuPedSim and PedPy write walkable areas):
// outer rings become the walkable area, holes obstacles, every ring a closed
// wall. Syntax errors name the line and column. The result is validated.
Venue ImportWkt(const std::filesystem::path& file, const ImportOptions& options = {});
Venue ParseWkt(std::string_view text, const std::string& origin, const ImportOptions& options = {});

// DXF floor plan (via dxflib): LINE, LWPOLYLINE and POLYLINE (bulges as arcs),
// ARC and CIRCLE flattened to segments. Closed polylines, circles and chains of
// segments whose endpoints meet form rings; rings nested at even depth (0, 2,
// ...) are walkable outer rings, at odd depth obstacles. Open chains become
// walls only. Throws GeometryError if no closed region is found.
Venue ImportDxf(const std::filesystem::path& file, const ImportOptions& options = {});

struct RasterImportOptions {
  std::string name;               // metadata.name; empty: the file's stem
  double pixels_per_metre = 0.0;  // required, > 0
  // Pixels darker than this grey level (0..255) are walls.
  int dark_threshold = 128;
  // A point (m, origin at the lower-left corner of the image, y up) inside the
  // wanted free region; without it, the largest free region that does not touch
  // the image border is taken.
  std::optional<Vec2> seed_m;
  // Douglas-Peucker-like tolerance (pixels) of the CGAL polyline simplification
  // of the pixel-edge contours; 0.75 px removes the staircase of slanted walls.
  double simplify_tolerance_px = 0.75;
  // Holes smaller than this (m^2) are dropped as noise (specks in the image).
  double min_obstacle_area_m2 = 0.01;
};

// Raster floor plan (PNG, JPEG, ...): dark pixels are walls; the boundary of the
// chosen free region, traced along pixel edges and simplified with CGAL
// Polyline_simplification_2 (topology preserved), becomes the walkable area;
// enclosed dark islands become obstacles. Coordinates: x to the right, y up, in
// metres from the lower-left corner of the image.
Venue ImportRasterPlan(const std::filesystem::path& file, const RasterImportOptions& options);

}  // namespace crowdrecon::geometry
