// Venue files: reading (through JsonReader, so every error names the JSON path
// and unknown keys are errors), writing, and the quantities derived from a venue
// (area, perimeter, point location, wall segments for the engine).
#include "crowdrecon/geometry/venue.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/polygon.hpp"
#include "crowdrecon/common/json_reader.hpp"
#include "venue_internal.hpp"

namespace crowdrecon::geometry {

// ---------------------------------------------------------------------------
// Rings
// ---------------------------------------------------------------------------

double RingSignedArea_m2(const Ring& ring) {
  // Shoelace formula, with coordinates taken relative to the first vertex so
  // that venues far from the origin (surveyed coordinates) keep their digits.
  if (ring.size() < 3) return 0.0;
  const Vec2 o = ring.front();
  double twice = 0.0;
  for (std::size_t i = 1; i + 1 < ring.size(); ++i) twice += Cross(ring[i] - o, ring[i + 1] - o);
  return 0.5 * twice;
}

double RingPerimeter_m(const Ring& ring) {
  double length = 0.0;
  for (std::size_t i = 0; i < ring.size(); ++i) length += Length(ring[(i + 1) % ring.size()] - ring[i]);
  return length;
}

bool PointInRing(const Ring& ring, Vec2 p) { return PointInPolygon(ring, p); }

double DistanceToRing(const Ring& ring, Vec2 p) {
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < ring.size(); ++i)
    d = std::min(d, DistanceToSegment(p, ring[i], ring[(i + 1) % ring.size()]));
  return d;
}

// ---------------------------------------------------------------------------
// Venue lookups and derived quantities
// ---------------------------------------------------------------------------

const Exit* Venue::FindExit(std::string_view id) const {
  for (const Exit& e : exits)
    if (e.id == id) return &e;
  return nullptr;
}

std::optional<Target> Venue::FindTarget(std::string_view id) const {
  for (const Target& t : targets)
    if (t.id == id) return t;
  if (const Exit* e = FindExit(id)) {
    Target t;
    t.id = e->id;
    t.kind = Target::Kind::kExit;
    t.exit_id = e->id;
    t.exit_ids = {e->id};
    return t;
  }
  return std::nullopt;
}

double WalkableArea_m2(const Venue& venue) {
  double area = 0.0;
  for (const Ring& r : venue.walkable_area) area += std::abs(RingSignedArea_m2(r));
  for (const Obstacle& o : venue.obstacles) area -= std::abs(RingSignedArea_m2(o.polygon));
  return area;
}

double WalkablePerimeter_m(const Venue& venue) {
  double length = 0.0;
  for (const Ring& r : venue.walkable_area) length += RingPerimeter_m(r);
  for (const Obstacle& o : venue.obstacles) length += RingPerimeter_m(o.polygon);
  return length;
}

bool IsWalkable(const Venue& venue, Vec2 p) {
  bool in_outer = false;
  for (const Ring& r : venue.walkable_area)
    if (PointInRing(r, p) || DistanceToRing(r, p) <= kVenueTolerance_m) {
      in_outer = true;
      break;
    }
  if (!in_outer) return false;
  for (const Obstacle& o : venue.obstacles)
    if (PointInRing(o.polygon, p) && DistanceToRing(o.polygon, p) > kVenueTolerance_m) return false;
  return true;
}

void WalkableBounds(const Venue& venue, Vec2* min, Vec2* max) {
  Vec2 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  Vec2 hi = -lo;
  for (const Ring& r : venue.walkable_area)
    for (Vec2 p : r) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    }
  if (venue.walkable_area.empty()) lo = hi = Vec2{};
  *min = lo;
  *max = hi;
}

namespace {

// Appends the parts of [a, b] not covered by any exit collinear with it.
void AppendUncoveredParts(Vec2 a, Vec2 b, double radius_m, const std::vector<Exit>& exits,
                          std::vector<WallSegment>* out) {
  const Vec2 ab = b - a;
  const double length = Length(ab);
  if (length <= 0.0) return;
  const Vec2 u = ab / length;
  // Covered parameter intervals [s0, s1] in metres along the edge.
  std::vector<std::pair<double, double>> covered;
  for (const Exit& e : exits) {
    // Collinear: both exit endpoints within tolerance of the edge's line.
    if (std::abs(Cross(u, e.a - a)) > kVenueTolerance_m ||
        std::abs(Cross(u, e.b - a)) > kVenueTolerance_m)
      continue;
    double s0 = Dot(e.a - a, u), s1 = Dot(e.b - a, u);
    if (s0 > s1) std::swap(s0, s1);
    s0 = std::max(s0, 0.0);
    s1 = std::min(s1, length);
    if (s1 - s0 > kVenueTolerance_m) covered.emplace_back(s0, s1);
  }
  std::sort(covered.begin(), covered.end());
  double s = 0.0;
  for (const auto& [c0, c1] : covered) {
    if (c0 - s > kVenueTolerance_m) out->push_back({a + u * s, a + u * c0, radius_m});
    s = std::max(s, c1);
  }
  if (length - s > kVenueTolerance_m) out->push_back({a + u * s, b, radius_m});
}

}  // namespace

std::vector<WallSegment> WallSegments(const Venue& venue) {
  std::vector<WallSegment> segments;
  for (const Wall& w : venue.walls) {
    const std::size_t n = w.points.size();
    const std::size_t edges = w.closed ? n : (n > 0 ? n - 1 : 0);
    for (std::size_t i = 0; i < edges; ++i)
      AppendUncoveredParts(w.points[i], w.points[(i + 1) % n], w.radius_m, venue.exits, &segments);
  }
  for (const Obstacle& o : venue.obstacles) {
    const std::size_t n = o.polygon.size();
    for (std::size_t i = 0; i < n; ++i)
      AppendUncoveredParts(o.polygon[i], o.polygon[(i + 1) % n], o.radius_m, venue.exits, &segments);
  }
  return segments;
}

double Venue::FreeWidth_m(const Exit& exit) const {
  double jamb_a = 0.0, jamb_b = 0.0;
  for (const WallSegment& w : WallSegments(*this))
    for (Vec2 end : {w.a, w.b}) {
      if (Length(end - exit.a) <= kVenueTolerance_m) jamb_a = std::max(jamb_a, w.radius_m);
      if (Length(end - exit.b) <= kVenueTolerance_m) jamb_b = std::max(jamb_b, w.radius_m);
    }
  return std::max(0.0, exit.width_m() - jamb_a - jamb_b);
}

// ---------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------

namespace {

// Drops a closing vertex equal to the first (WKT and GeoJSON style rings).
Ring OpenRing(std::vector<Vec2> points) {
  if (points.size() >= 2 && points.front() == points.back()) points.pop_back();
  return points;
}

class VenueReader {
 public:
  explicit VenueReader(const JsonReader& root) : root_(root) {}

  Venue Read() {
    Venue v;
    v.origin = root_.origin();
    root_.Integer("version", 1, 1, 1);
    if (auto meta = root_.Find("metadata")) ReadMetadata(*meta, &v.metadata);
    scale_ = metadata_scale_;
    default_radius_m_ = root_.Number("wall_radius_m", 0.0, 0.0, 10.0);

    const JsonReader area = root_.At("walkable_area");
    if (area.Size() == 0)
      area.Fail("the walkable area is empty; expected at least one outer ring [[x, y], ...]");
    for (std::size_t i = 0; i < area.Size(); ++i) v.walkable_area.push_back(ReadRing(area.Element(i)));

    ForEachObject("obstacles", [&](const JsonReader& o, std::size_t i) {
      Obstacle obstacle;
      obstacle.id = o.String("id", "obstacle-" + std::to_string(i + 1));
      obstacle.polygon = ReadRing(o.At("polygon"));
      obstacle.radius_m = o.Number("radius_m", default_radius_m_, 0.0, 10.0);
      v.obstacles.push_back(std::move(obstacle));
    });
    ForEachObject("walls", [&](const JsonReader& w, std::size_t i) {
      Wall wall;
      wall.id = w.String("id", "wall-" + std::to_string(i + 1));
      const bool has_line = w.Has("polyline"), has_polygon = w.Has("polygon");
      if (has_line == has_polygon)
        w.Fail("a wall needs exactly one of \"polyline\" (open) or \"polygon\" (closed)");
      if (has_line) {
        wall.points = Scaled(w.At("polyline").AsPoints(2));
      } else {
        wall.points = ReadRing(w.At("polygon"));
        wall.closed = true;
      }
      wall.radius_m = w.Number("radius_m", default_radius_m_, 0.0, 10.0);
      v.walls.push_back(std::move(wall));
    });
    ForEachObject("exits", [&](const JsonReader& e, std::size_t) {
      Exit exit;
      exit.id = ReadId(e);
      ReadSegment(e.At("segment"), &exit.a, &exit.b);
      v.exits.push_back(std::move(exit));
    });
    ForEachObject("entries", [&](const JsonReader& e, std::size_t) {
      v.entries.push_back({ReadId(e), ReadRing(e.At("polygon"))});
    });
    ForEachObject("measurement_areas", [&](const JsonReader& e, std::size_t) {
      v.measurement_areas.push_back({ReadId(e), ReadRing(e.At("polygon"))});
    });
    ForEachObject("measurement_lines", [&](const JsonReader& e, std::size_t) {
      MeasurementLine line;
      line.id = ReadId(e);
      ReadSegment(e.At("segment"), &line.a, &line.b);
      v.measurement_lines.push_back(std::move(line));
    });
    ForEachObject("periodic", [&](const JsonReader& p, std::size_t) {
      PeriodicDirection periodic;
      periodic.direction = ReadDirection(p.At("direction"));
      periodic.period_m = p.Number("period_m", 1e-3, kVenueMaxCoordinate_m);
      v.periodic.push_back(periodic);
    });
    ForEachObject("targets", [&](const JsonReader& t, std::size_t) {
      Target target;
      target.id = ReadId(t);
      const bool has_exit = t.Has("exit"), has_exits = t.Has("exits"), has_direction = t.Has("direction");
      if (int(has_exit) + int(has_exits) + int(has_direction) != 1)
        t.Fail("a target needs exactly one of \"exit\" (an exit id), \"exits\" (a list of exit ids: the nearest) "
               "or \"direction\" ([x, y])");
      if (has_exit) {
        target.kind = Target::Kind::kExit;
        target.exit_id = t.String("exit");
        target.exit_ids = {target.exit_id};
      } else if (has_exits) {
        const JsonReader list = t.At("exits");
        if (!list.IsArray() || list.Size() == 0) list.Fail("expected a non-empty list of exit ids");
        target.kind = Target::Kind::kExit;
        for (std::size_t k = 0; k < list.Size(); ++k) target.exit_ids.push_back(list.Element(k).AsString());
        target.exit_id = target.exit_ids.front();
      } else {
        target.kind = Target::Kind::kDirection;
        target.direction = ReadDirection(t.At("direction"));
      }
      v.targets.push_back(std::move(target));
    });
    if (auto s = root_.Find("slope")) {
      if (!s->IsObject()) s->Fail("expected an object {\"direction\": [x, y], \"gradient\": g}, found " + s->ValueText());
      Slope slope;
      slope.direction = ReadDirection(s->At("direction"));
      // Gradient: rise over run. 1 is 45 degrees, far beyond any walkable ramp
      // (building codes allow about 0.08), so larger values are input errors.
      slope.gradient = s->Number("gradient", 0.0, 1.0);
      slope.enabled = s->Bool("enabled", true);
      // A region: the floor slopes there only (an alley between level
      // streets); elsewhere it is level.
      if (auto region = s->Find("region")) slope.region = ReadRing(*region);
      s->Finish();
      v.slope = slope;
    }
    root_.Finish();
    return v;
  }

 private:
  void ReadMetadata(const JsonReader& meta, VenueMetadata* m) {
    if (!meta.IsObject()) meta.Fail("expected an object, found " + meta.ValueText());
    m->name = meta.String("name", "");
    m->source = meta.String("source", "");
    m->description = meta.String("description", "");
    if (auto notes = meta.Find("notes"))
      for (std::size_t i = 0; i < notes->Size(); ++i) m->notes.push_back(notes->Element(i).AsString());
    metadata_scale_ = meta.Number("scale_m_per_unit", 1.0, 1e-9, 1e6);
    meta.Finish();
  }

  template <typename F>
  void ForEachObject(std::string_view key, F&& read_one) {
    auto list = root_.Find(key);
    if (!list) return;
    for (std::size_t i = 0; i < list->Size(); ++i) {
      const JsonReader item = list->Element(i);
      if (!item.IsObject()) item.Fail("expected an object, found " + item.ValueText());
      read_one(item, i);
      item.Finish();
    }
  }

  static std::string ReadId(const JsonReader& item) {
    const JsonReader id = item.At("id");
    std::string text = id.AsString();
    if (text.empty()) id.Fail("the id is empty; expected a name such as \"main\"");
    return text;
  }

  std::vector<Vec2> Scaled(std::vector<Vec2> points) const {
    for (Vec2& p : points) p *= scale_;
    return points;
  }

  Ring ReadRing(const JsonReader& ring) const {
    // (Coordinates beyond kVenueMaxCoordinate_m are reported by ValidateVenue.)
    return OpenRing(Scaled(ring.AsPoints(3)));
  }

  void ReadSegment(const JsonReader& segment, Vec2* a, Vec2* b) const {
    const std::vector<Vec2> points = Scaled(segment.AsPoints(2));
    if (points.size() != 2)
      segment.Fail("expected a segment [[x1, y1], [x2, y2]] of two points, found " +
                   std::to_string(points.size()) + " points");
    *a = points[0];
    *b = points[1];
  }

  static Vec2 ReadDirection(const JsonReader& direction) {
    const Vec2 d = direction.AsPoint();
    const double largest = std::max(std::abs(d.x), std::abs(d.y));
    if (!(largest > 0.0))
      direction.Fail("the direction " + direction.ValueText() + " has zero length; expected a non-zero vector [x, y]");
    // A length that overflows or underflows (components of 1e308, or 1e-200)
    // is taken of the vector scaled by its largest component: the same
    // direction (issue 65: [1e308, 1e308] became (0, 0), a slope that pulled nowhere).
    const double length = Length(d);
    return std::isfinite(length) && length >= 1e-12 ? Normalized(d) : Normalized(Vec2{d.x / largest, d.y / largest});
  }

  JsonReader root_;
  double metadata_scale_ = 1.0;
  double scale_ = 1.0;
  double default_radius_m_ = 0.0;
};

}  // namespace

Venue ParseVenue(std::string_view json_text, const std::string& origin) {
  const JsonDocument doc = JsonDocument::Parse(json_text, origin);
  const JsonReader root = doc.Root();
  if (!root.IsObject()) root.Fail("expected a venue object {\"walkable_area\": ...}, found " + root.ValueText());
  Venue venue = VenueReader(root).Read();
  ValidateVenue(venue);
  return venue;
}

Venue LoadVenue(const std::filesystem::path& file) {
  return ParseVenue(ReadInputFile(file, "venue file"), file.string());
}

// ---------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------

namespace {

using Json = nlohmann::ordered_json;

Json PointJson(Vec2 p) { return Json::array({p.x, p.y}); }

Json PointsJson(const std::vector<Vec2>& points) {
  Json a = Json::array();
  for (Vec2 p : points) a.push_back(PointJson(p));
  return a;
}

bool IsNumberArray(const Json& j) {
  if (!j.is_array() || j.empty()) return false;
  return std::all_of(j.begin(), j.end(), [](const Json& e) { return e.is_number(); });
}

// Pretty printer that keeps points on one line and packs point lists several
// to a line, so that a venue file stays readable by eye (nlohmann's dump(2)
// puts every coordinate on its own line).
void Emit(const Json& j, int indent, std::string* out) {
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  const std::string inner(static_cast<std::size_t>(indent + 2), ' ');
  if (j.is_object()) {
    if (j.empty()) { *out += "{}"; return; }
    *out += "{\n";
    bool first = true;
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (!first) *out += ",\n";
      first = false;
      *out += inner + Json(it.key()).dump() + ": ";
      Emit(it.value(), indent + 2, out);
    }
    *out += "\n" + pad + "}";
  } else if (j.is_array()) {
    if (j.empty()) { *out += "[]"; return; }
    if (IsNumberArray(j)) {
      *out += "[";
      for (std::size_t i = 0; i < j.size(); ++i) *out += (i ? ", " : "") + j[i].dump();
      *out += "]";
      return;
    }
    const bool points = std::all_of(j.begin(), j.end(), [](const Json& e) { return IsNumberArray(e); });
    if (points) {
      // Points, packed up to ~96 characters per line.
      std::string line;
      std::string text = "[";
      bool first_line = true;
      for (std::size_t i = 0; i < j.size(); ++i) {
        std::string p = "[" + j[i][0].dump() + ", " + j[i][1].dump() + "]";
        if (i + 1 < j.size()) p += ", ";
        if (!line.empty() && line.size() + p.size() > 96) {
          text += (first_line ? "" : inner) + line + "\n";
          first_line = false;
          line.clear();
        }
        line += p;
      }
      text += (first_line ? "" : inner) + line + "]";
      *out += text;
      return;
    }
    *out += "[\n";
    for (std::size_t i = 0; i < j.size(); ++i) {
      *out += inner;
      Emit(j[i], indent + 2, out);
      *out += i + 1 < j.size() ? ",\n" : "\n";
    }
    *out += pad + "]";
  } else {
    *out += j.dump();
  }
}

Json IdRing(const std::string& id, const Ring& ring) {
  Json j;
  j["id"] = id;
  j["polygon"] = PointsJson(ring);
  return j;
}

}  // namespace

std::string VenueToJson(const Venue& v) {
  Json root;
  root["version"] = 1;
  Json meta;
  meta["name"] = v.metadata.name;
  if (!v.metadata.source.empty()) meta["source"] = v.metadata.source;
  if (!v.metadata.description.empty()) meta["description"] = v.metadata.description;
  if (!v.metadata.notes.empty()) meta["notes"] = v.metadata.notes;
  root["metadata"] = meta;
  Json area = Json::array();
  for (const Ring& r : v.walkable_area) area.push_back(PointsJson(r));
  root["walkable_area"] = area;
  if (!v.obstacles.empty()) {
    Json list = Json::array();
    for (const Obstacle& o : v.obstacles) {
      Json j = IdRing(o.id, o.polygon);
      if (o.radius_m != 0.0) j["radius_m"] = o.radius_m;
      list.push_back(j);
    }
    root["obstacles"] = list;
  }
  if (!v.walls.empty()) {
    Json list = Json::array();
    for (const Wall& w : v.walls) {
      Json j;
      j["id"] = w.id;
      j[w.closed ? "polygon" : "polyline"] = PointsJson(w.points);
      if (w.radius_m != 0.0) j["radius_m"] = w.radius_m;
      list.push_back(j);
    }
    root["walls"] = list;
  }
  auto segments = [&](const char* key, const auto& items) {
    if (items.empty()) return;
    Json list = Json::array();
    for (const auto& item : items) {
      Json j;
      j["id"] = item.id;
      j["segment"] = Json::array({PointJson(item.a), PointJson(item.b)});
      list.push_back(j);
    }
    root[key] = list;
  };
  auto polygons = [&](const char* key, const auto& items) {
    if (items.empty()) return;
    Json list = Json::array();
    for (const auto& item : items) list.push_back(IdRing(item.id, item.polygon));
    root[key] = list;
  };
  segments("exits", v.exits);
  polygons("entries", v.entries);
  polygons("measurement_areas", v.measurement_areas);
  segments("measurement_lines", v.measurement_lines);
  if (!v.periodic.empty()) {
    Json list = Json::array();
    for (const PeriodicDirection& p : v.periodic)
      list.push_back(Json{{"direction", PointJson(p.direction)}, {"period_m", p.period_m}});
    root["periodic"] = list;
  }
  if (!v.targets.empty()) {
    Json list = Json::array();
    for (const Target& t : v.targets) {
      Json j;
      j["id"] = t.id;
      if (t.kind == Target::Kind::kExit && t.exit_ids.size() > 1) j["exits"] = t.exit_ids;
      else if (t.kind == Target::Kind::kExit) j["exit"] = t.exit_id;
      else j["direction"] = PointJson(t.direction);
      list.push_back(j);
    }
    root["targets"] = list;
  }
  if (v.slope) {
    root["slope"] = Json{{"direction", PointJson(v.slope->direction)},
                         {"gradient", v.slope->gradient},
                         {"enabled", v.slope->enabled}};
    if (!v.slope->region.empty()) root["slope"]["region"] = PointsJson(v.slope->region);
  }
  std::string out;
  Emit(root, 0, &out);
  out += "\n";
  return out;
}

OutputKind VenueJsonOutput() {
  return JsonOutputKind("a venue JSON (version, walkable_area)", [](const nlohmann::json& j) {
    return j.contains("version") && j.contains("walkable_area");
  });
}

void WriteVenueJson(const Venue& venue, const std::filesystem::path& file) {
  WriteFileAtomically(file, VenueToJson(venue));
}

}  // namespace crowdrecon::geometry

// ---------------------------------------------------------------------------
// Shared by the importers
// ---------------------------------------------------------------------------

namespace crowdrecon::geometry::internal {

Venue VenueFromRegions(std::vector<ImportedRegion> regions, const std::string& name,
                       const std::string& source, const std::string& origin) {
  Venue v;
  v.origin = origin;
  v.metadata.name = name;
  v.metadata.source = source;
  std::size_t obstacle_count = 0;
  for (std::size_t i = 0; i < regions.size(); ++i) {
    Wall wall;
    wall.id = "boundary-" + std::to_string(i + 1);
    wall.points = regions[i].outer;
    wall.closed = true;
    v.walls.push_back(std::move(wall));
    v.walkable_area.push_back(std::move(regions[i].outer));
    for (Ring& hole : regions[i].holes) {
      Obstacle o;
      o.id = "obstacle-" + std::to_string(++obstacle_count);
      o.polygon = std::move(hole);
      v.obstacles.push_back(std::move(o));
    }
  }
  if (v.walkable_area.empty())
    throw GeometryError(origin + ": the walkable area is empty; expected at least one polygon");
  try {
    ValidateVenue(v);
  } catch (const GeometryError& e) {
    // The checker names venue JSON paths; say how they map to the input.
    throw GeometryError(std::string(e.what()) +
                        "\n(paths name the venue being imported: /walkable_area/N is the outer ring of the "
                        "input's polygon N+1, /obstacles/K its (K+1)-th hole, counted over all polygons)");
  }
  return v;
}

}  // namespace crowdrecon::geometry::internal
