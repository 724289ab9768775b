#include "crowdrecon/viz/density_figure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "crowdrecon/analysis/timeline_series.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/viz/canvas.hpp"

namespace crowdrecon::viz {

namespace {

// A perceptual scale from light yellow through orange and red to dark purple
// (low density pale, so that walls and exits stay visible).
Color Scale(double f) {
  static const Color stops[] = {Color::Hex(0xffffe5), Color::Hex(0xfee391), Color::Hex(0xfec44f), Color::Hex(0xfe9929),
                                Color::Hex(0xec7014), Color::Hex(0xcc4c02), Color::Hex(0x8c2d04), Color::Hex(0x4a1486)};
  constexpr int n = sizeof(stops) / sizeof(stops[0]);
  f = std::clamp(f, 0.0, 1.0) * (n - 1);
  const int k = std::min(static_cast<int>(f), n - 2);
  const double w = f - k;
  return {stops[k].r + w * (stops[k + 1].r - stops[k].r), stops[k].g + w * (stops[k + 1].g - stops[k].g),
          stops[k].b + w * (stops[k + 1].b - stops[k].b), 1.0};
}

}  // namespace

void DrawDensityMaps(const std::vector<analysis::DensityMap>& maps, const geometry::Venue& venue,
                     const std::string& title, const analysis::RunClock& clock, const std::filesystem::path& file) {
  if (maps.empty()) throw InputError(file.string() + ": no density map to draw");
  const analysis::DensityMap& first = maps.front();
  const double w = double(first.nx) * first.cell_m, h = double(first.ny) * first.cell_m;
  const int columns = maps.size() == 1 ? 1 : 2;
  const int rows = static_cast<int>((maps.size() + 1) / static_cast<std::size_t>(columns));
  const double gap = 0.12 * w, title_m = 0.16 * h, legend_m = 0.22 * h;
  const double sheet_w = columns * w + (columns - 1) * gap;
  const double ppm = 1300.0 / sheet_w;
  // The title on one line where it fits the sheet (about 0.56 of the font
  // size per character), else on two, broken at a space; its band at the
  // top in pixels (a long, low venue leaves too little of its height for
  // two lines: the second once ran into the first map's label).
  const std::size_t fits = static_cast<std::size_t>(1300.0 / (0.56 * 20.0));
  const bool one_line = title.size() <= fits;
  const double top_m = std::max(title_m, (one_line ? 44.0 : 66.0) / ppm);
  const Vec2 sheet_min{0.0, 0.0};
  const Vec2 sheet_max{sheet_w, rows * (h + title_m) + legend_m + top_m};
  Canvas c(file, sheet_min, sheet_max, ppm, 20.0);
  // The scale: 0 to the largest density of any map, rounded up to a whole number.
  double top = 1.0;
  for (const auto& m : maps) top = std::max(top, m.max_per_m2);
  top = std::ceil(top / 4.0) * 4.0;  // whole ticks at its quarters
  if (one_line) {
    c.TextPx(20, 30, title, 20);
  } else {
    std::size_t cut = title.rfind(' ', fits);
    if (cut == std::string::npos || cut < fits / 2) cut = fits;
    c.TextPx(20, 28, title.substr(0, cut), 18);
    c.TextPx(20, 52, title.substr(cut + (title[cut] == ' ' ? 1 : 0)), 18);
  }
  for (std::size_t k = 0; k < maps.size(); ++k) {
    const analysis::DensityMap& m = maps[k];
    const double ox = double(k % columns) * (w + gap);
    const double oy = sheet_max.y - top_m - double(k / columns + 1) * (h + title_m) + title_m * 0.2;
    const Vec2 shift{ox - m.origin_m.x, oy - m.origin_m.y};
    for (std::size_t iy = 0; iy < m.ny; ++iy)
      for (std::size_t ix = 0; ix < m.nx; ++ix) {
        const double d = m.At(ix, iy);
        if (d < 0.05) continue;
        const double x = ox + double(ix) * m.cell_m, y = oy + double(iy) * m.cell_m;
        const double e = m.cell_m * 1.03;  // a hair wider: no seams between cells in antialiased pictures
        c.FillPolygon({{x, y}, {x + e, y}, {x + e, y + e}, {x, y + e}}, Scale(d / top));
      }
    for (const geometry::WallSegment& s : geometry::WallSegments(venue))
      c.Line(s.a + shift, s.b + shift, Color::Hex(0x222222), std::max(1.5, 2.0 * s.radius_m * ppm));
    for (const geometry::Exit& e : venue.exits) c.Line(e.a + shift, e.b + shift, Color::Hex(0x1a9850), 4.0);
    char label[160];
    const std::string when = clock.MomentText(m.time_s);
    std::snprintf(label, sizeof label, "%s: %zu people, densest %.1f /m2", when.c_str(), m.people, m.max_per_m2);
    c.Text({ox, oy + h + 0.25 * title_m}, label, 15);
  }
  // Colour bar.
  const double bar_y = legend_m * 0.45, bar_w = std::min(sheet_max.x * 0.5, 40.0 * (sheet_max.x / 100.0));
  for (int i = 0; i < 100; ++i) {
    const double x = double(i) / 100.0 * bar_w;
    c.FillPolygon({{x, bar_y}, {x + bar_w / 100.0 * 1.01, bar_y}, {x + bar_w / 100.0 * 1.01, bar_y + legend_m * 0.25},
                   {x, bar_y + legend_m * 0.25}},
                  Scale(i / 99.0));
  }
  for (int t = 0; t <= 4; ++t) {
    const double v = top * t / 4.0;
    c.Text({bar_w * t / 4.0, bar_y - legend_m * 0.3}, FormatNumber(std::round(v * 10.0) / 10.0), 12);
  }
  c.Text({bar_w + 0.02 * sheet_max.x, bar_y}, "persons per m2 (Gaussian kernel; walls black, exits green)", 13);
  c.Finish();
}

}  // namespace crowdrecon::viz
