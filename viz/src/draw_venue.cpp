#include "crowdrecon/viz/draw_venue.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/viz/canvas.hpp"

namespace crowdrecon::viz {

namespace {

// Palette: one colour per kind of element, as in the legend.
const Color kFloor = Color::Hex(0xe9e6df);
const Color kObstacle = Color::Hex(0x8a8a8a);
const Color kWall = Color::Hex(0x202020);
const Color kExit = Color::Hex(0x1a9a3a);
const Color kEntry = Color::Hex(0x2b6cd4);
const Color kMeasure = Color::Hex(0xe07b00);
const Color kArrow = Color::Hex(0x8b1a5a);

// A round length (1, 2 or 5 times a power of ten) near a fifth of `extent_m`.
double NiceLength(double extent_m) {
  const double target = extent_m / 5.0;
  const double power = std::pow(10.0, std::floor(std::log10(target)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * power <= target) return m * power;
  return power;
}

}  // namespace

void DrawVenue(const geometry::Venue& venue, const std::filesystem::path& file,
               const VenuePictureOptions& options) {
  using geometry::Ring;
  // World window: the walkable area and every wall, with a little room.
  Vec2 lo, hi;
  geometry::WalkableBounds(venue, &lo, &hi);
  for (const geometry::Wall& w : venue.walls)
    for (Vec2 p : w.points) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    }
  const double extent = std::max(hi.x - lo.x, hi.y - lo.y);
  const double pad = 0.03 * extent;
  lo -= Vec2{pad, pad};
  hi += Vec2{pad, pad};
  const double ppm = options.max_size_px / std::max(hi.x - lo.x, hi.y - lo.y);
  // Margins hold the title (top) and the scale bar and legend (bottom).
  Canvas canvas(file, lo, hi, ppm, 56.0);
  auto px = [&](double metres) { return metres * ppm; };

  // Floor: outer rings with the obstacles cut out (even-odd fill).
  std::vector<Ring> rings = venue.walkable_area;
  for (const geometry::Obstacle& o : venue.obstacles) rings.push_back(o.polygon);
  canvas.FillRings(rings, kFloor);

  // The floor slope's region (issue 43): tinted brown, an arrow downhill at
  // its centre (a slope over the whole floor: the subtitle says it).
  if (venue.slope && !venue.slope->region.empty()) {
    const Color brown = Color::Hex(0x8c510a);
    canvas.FillPolygon(venue.slope->region, Color::Hex(0x8c510a, 0.10));
    Vec2 c;
    for (Vec2 q : venue.slope->region) c += q;
    c = c / static_cast<double>(venue.slope->region.size());
    const Vec2 d = venue.slope->direction * (0.06 * extent);
    canvas.Arrow(c - d, c + d, brown, 2.5);
    canvas.Text(c + d + Vec2{0.01 * extent, 0.0}, "downhill", 12, brown);
  }
  for (const geometry::MeasurementArea& m : venue.measurement_areas) {
    canvas.FillPolygon(m.polygon, Color{kMeasure.r, kMeasure.g, kMeasure.b, 0.12});
    std::vector<Vec2> closed = m.polygon;
    closed.push_back(m.polygon.front());
    canvas.StrokePolyline(closed, kMeasure, 2.0, /*dashed=*/true);
  }
  for (const geometry::EntryZone& e : venue.entries) {
    canvas.FillPolygon(e.polygon, Color{kEntry.r, kEntry.g, kEntry.b, 0.25});
    canvas.StrokePolygon(e.polygon, kEntry, 1.5);
  }

  // Navigation arrows on a coarse grid (about 24 across the longer side).
  if (options.field) {
    const double step = extent / 24.0;
    for (double y = lo.y + 0.5 * step; y < hi.y; y += step)
      for (double x = lo.x + 0.5 * step; x < hi.x; x += step) {
        const Vec2 p{x, y};
        if (!geometry::IsWalkable(venue, p)) continue;
        const Vec2 d = options.field->Direction(p);
        if (Length(d) < 0.5) continue;
        canvas.Arrow(p - 0.3 * step * d, p + 0.3 * step * d, Color{kArrow.r, kArrow.g, kArrow.b, 0.75}, 1.3);
      }
  }

  for (const geometry::Obstacle& o : venue.obstacles) canvas.FillPolygon(o.polygon, kObstacle);
  // Walls as the engine sees them (exit openings cut out), at least 3 px wide
  // and as wide as their sphero-diameter.
  for (const geometry::WallSegment& w : geometry::WallSegments(venue))
    canvas.Line(w.a, w.b, kWall, std::max(3.0, px(2.0 * w.radius_m)));

  for (const geometry::MeasurementLine& m : venue.measurement_lines) {
    canvas.StrokePolyline({m.a, m.b}, kMeasure, 2.5, /*dashed=*/true);
    canvas.Text(m.b + Vec2{0.01 * extent, 0.0}, m.id, 12, kMeasure);
  }
  for (const geometry::Exit& e : venue.exits) {
    canvas.Line(e.a, e.b, kExit, 6.0);
    // Label on the walkable side of the exit, so that exits on the right or
    // top edge do not push their label off the picture.
    const Vec2 mid = 0.5 * (e.a + e.b);
    Vec2 normal = Length(e.b - e.a) > 0.0 ? Normalized(Perp(e.b - e.a)) : Vec2{1, 0};
    if (!geometry::IsWalkable(venue, mid + 0.01 * extent * normal)) normal = -normal;
    const std::string label = e.id + " (" + FormatFixed(venue.FreeWidth_m(e), 2) + " m)";
    const double text_m = 0.55 * 13.0 * static_cast<double>(label.size()) / ppm;  // rough text width
    Vec2 at = mid + 0.025 * extent * normal;
    if (normal.x < -0.5) at.x -= text_m;
    if (std::abs(normal.x) <= 0.5) at.x -= 0.5 * text_m;
    if (normal.y < -0.5) at.y -= 12.0 / ppm;
    canvas.Text(at, label, 13, kExit);
  }
  // Periodic ends: the boundary edges at the two extremes along a periodic
  // direction are not walls but seams; dashed grey.
  for (const geometry::PeriodicDirection& p : venue.periodic)
    for (const Ring& ring : venue.walkable_area) {
      double d_lo = std::numeric_limits<double>::infinity(), d_hi = -d_lo;
      for (Vec2 q : ring) {
        d_lo = std::min(d_lo, Dot(q, p.direction));
        d_hi = std::max(d_hi, Dot(q, p.direction));
      }
      for (std::size_t i = 0; i < ring.size(); ++i) {
        const Vec2 a = ring[i], b = ring[(i + 1) % ring.size()];
        for (double end : {d_lo, d_hi})
          if (std::abs(Dot(a, p.direction) - end) < 1e-6 && std::abs(Dot(b, p.direction) - end) < 1e-6)
            canvas.StrokePolyline({a, b}, Color::Hex(0x777777), 2.0, /*dashed=*/true);
      }
    }
  for (const geometry::EntryZone& e : venue.entries) {
    Vec2 c;
    for (Vec2 p : e.polygon) c += p;
    c = c / static_cast<double>(e.polygon.size());
    canvas.Text(c - Vec2{0.0, 0.05 * extent}, e.id, 12, kEntry);  // below the centre, clear of exit labels
  }

  // Title, scale bar and legend.
  const std::string title = options.title.empty() ? venue.metadata.name : options.title;
  canvas.TextPx(56.0, 24.0, title, 17);
  std::string subtitle = FormatFixed(geometry::WalkableArea_m2(venue), 1) + " m2 walkable";
  for (const geometry::PeriodicDirection& p : venue.periodic)
    subtitle += "; periodic along (" + FormatNumber(p.direction.x) + ", " + FormatNumber(p.direction.y) + "), " +
                FormatNumber(p.period_m) + " m";
  if (venue.slope)
    subtitle += "; slope " + FormatFixed(100.0 * venue.slope->gradient, 1) + " % toward (" +
                FormatNumber(venue.slope->direction.x) + ", " + FormatNumber(venue.slope->direction.y) + ")" +
                (venue.slope->region.empty() ? "" : " in the tinted region") + (venue.slope->enabled ? "" : " (disabled)");
  canvas.TextPx(56.0, 44.0, subtitle, 12, Color::Hex(0x444444));
  canvas.ScaleBar(NiceLength(hi.x - lo.x));
  std::string legend = "walls: black   exits: green   entries: blue   obstacles: grey";
  if (!venue.measurement_areas.empty() || !venue.measurement_lines.empty()) legend += "   measurement: orange";
  if (options.field) legend += "   arrows: " + options.field_label;
  canvas.TextPx(56.0 + px(NiceLength(hi.x - lo.x)) + 70.0, canvas.height_px() - 56.0 * 0.35 + 4.0, legend, 12,
                Color::Hex(0x444444));
  canvas.Finish();
}

}  // namespace crowdrecon::viz
