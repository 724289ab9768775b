#include "envelope.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/runfile/sqlite.hpp"
#include "crowdrecon/reports/svg.hpp"

namespace crowdrecon::reports {

namespace fs = std::filesystem;

bool IsSweepFolder(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir, ec) && fs::is_regular_file(dir / "results.sqlite", ec);
}

namespace {
std::string Quoted(const std::string& name) { return "\"" + name + "\""; }
}  // namespace

Envelope ReadEnvelope(const fs::path& dir, const std::string& metric, double level) {
  using sqlite::Database;
  using sqlite::Statement;
  Envelope e;
  e.results = dir / "results.sqlite";
  e.metric = metric;
  e.level = level;
  const Database db(e.results.string(), SQLITE_OPEN_READONLY);
  std::map<std::string, std::string> sweep;
  {
    Statement s(db, "SELECT key, value FROM sweep");
    while (s.Next()) sweep[s.Text(0)] = s.Text(1);
  }
  if (sweep["format"] != "crowdrecon-sweep-results")
    throw InputError(e.results.string() + ": not a crowdrecon sweep's results (table sweep, key format)");
  e.sweep_name = sweep["name"];
  e.sweep_file = sweep["sweep_file"];
  e.crowdrecon_version = sweep["crowdrecon_version"];
  e.x_axis = sweep["diagram_x"];
  e.y_axis = sweep["diagram_y"];
  std::set<std::string> columns;
  {
    Statement s(db, "SELECT * FROM runs LIMIT 0");
    for (int c = 0; c < s.ColumnCount(); ++c) columns.insert(s.ColumnName(c));
  }
  // A sweep of one axis (its diagram has no y): one row of cells.
  for (const std::string& c : {e.x_axis, e.y_axis})
    if (!(c.empty() && &c != &e.x_axis) && !columns.count(c))
      throw InputError(e.results.string() + ": table runs has no column \"" + c + "\" (the diagram's axis)");
  if (!columns.count(metric)) {
    // A sweep that records injury risk has people_danger: then the metric is
    // simply not one of its columns (issue 40: the age was blamed).
    if (columns.count("people_danger"))
      throw InputError("--envelope-metric " + metric + ": " + e.results.string() + " has no column \"" + metric +
                       "\"; expected a numeric column of its table runs (the header of results.csv lists them), "
                       "e.g. people_danger or max_chest_load_n");
    throw InputError(e.results.string() + ": table runs has no column \"" + metric +
                     "\"; the sweep was made before runs recorded injury risk (2026-11-26): run it again with this "
                     "crowdrecon into a new folder");
  }
  std::map<std::string, std::map<std::pair<double, double>, std::vector<double>>> cells;
  std::set<double> xs, ys;
  Statement s(db, "SELECT variant, " + Quoted(e.x_axis) + ", " + (e.y_axis.empty() ? "0" : Quoted(e.y_axis)) +
                      ", status, " + Quoted(metric) + " FROM runs ORDER BY run_index");
  while (s.Next()) {
    ++e.runs;
    const double x = s.Double(1), y = s.Double(2);
    xs.insert(x);
    ys.insert(y);
    auto& values = cells[s.Text(0)][{y, x}];
    if (s.Text(3) != "complete") {
      ++e.failed;
      continue;
    }
    if (s.Type(4) == SQLITE_NULL) {
      ++e.without_metric;
      continue;
    }
    values.push_back(s.Double(4));
  }
  e.xs.assign(xs.begin(), xs.end());
  e.ys.assign(ys.begin(), ys.end());
  for (auto& [variant, grid] : cells)
    for (auto& [yx, values] : grid) {
      EnvelopeCell c;
      c.y = yx.first;
      c.x = yx.second;
      c.values = values;
      if (!values.empty()) {
        std::vector<double> v = values;
        std::sort(v.begin(), v.end());
        c.low = v.front();
        c.high = v.back();
        c.median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
      } else {
        c.median = c.low = c.high = std::nan("");
      }
      e.variants[variant].push_back(c);
    }
  return e;
}

std::string EnvelopeSvg(const Envelope& e, const std::string& variant) {
  const std::vector<EnvelopeCell>& cells = e.variants.at(variant);
  const std::size_t nx = e.xs.size(), ny = e.ys.size();
  constexpr double kLeft = 80, kTop = 40, kCell = 62, kRightPad = 220, kBottom = 60;
  const double width = std::max(kLeft + double(nx) * kCell + kRightPad, 640.0), height = kTop + double(ny) * kCell + kBottom;
  const auto cell_at = [&](std::size_t ix, std::size_t iy) -> const EnvelopeCell* {
    for (const EnvelopeCell& c : cells)
      if (c.x == e.xs[ix] && c.y == e.ys[iy]) return &c;
    return nullptr;
  };
  double top = 1.0;
  for (const EnvelopeCell& c : cells)
    if (std::isfinite(c.median)) top = std::max(top, c.median);
  const auto colour = [&](double v) {
    // White at zero, through yellow and orange to dark red at the largest median (square-root scale).
    const double f = std::sqrt(std::clamp(v / top, 0.0, 1.0));
    const int r = static_cast<int>(255 - 60 * f), g = static_cast<int>(250 - 220 * f), b = static_cast<int>(235 - 215 * f);
    char buf[16];
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", r, g, b);
    return std::string(buf);
  };
  const auto X = [&](std::size_t ix) { return kLeft + double(ix) * kCell; };
  const auto Y = [&](std::size_t iy) { return kTop + double(ny - 1 - iy) * kCell; };  // y up
  std::string s = svg::Open("chart", width, height, variant + ": " + e.metric + ", median over seeds [range]", kLeft, 22);
  for (std::size_t iy = 0; iy < ny; ++iy)
    for (std::size_t ix = 0; ix < nx; ++ix) {
      const EnvelopeCell* c = cell_at(ix, iy);
      const bool have = c && std::isfinite(c->median);
      s += "<rect x=\"" + svg::Short(X(ix), 6) + "\" y=\"" + svg::Short(Y(iy), 6) + "\" width=\"" + svg::Short(kCell, 6) +
           "\" height=\"" + svg::Short(kCell, 6) + "\" fill=\"" + (have ? colour(c->median) : "#dddddd") +
           "\" stroke=\"#ffffff\"><title>" +
           svg::Escape(e.x_axis + " " + svg::Short(e.xs[ix]) +
                       (e.y_axis.empty() ? std::string() : ", " + e.y_axis + " " + svg::Short(e.ys[iy])) +
                       (have ? ": median " + svg::Short(c->median) + ", range " + svg::Short(c->low) + "–" +
                                   svg::Short(c->high) + " over " + std::to_string(c->values.size()) + " seeds"
                             : ": no complete run")) +
           "</title></rect>\n";
      if (!have) continue;
      const bool dark = std::sqrt(std::clamp(c->median / top, 0.0, 1.0)) > 0.7;  // white text on dark cells
      s += "<text x=\"" + svg::Short(X(ix) + kCell / 2, 6) + "\" y=\"" + svg::Short(Y(iy) + kCell / 2 - 2, 6) +
           "\" text-anchor=\"middle\" font-size=\"13\" font-weight=\"bold\" fill=\"" + (dark ? "#ffffff" : "#111111") +
           "\">" + svg::Short(c->median) + "</text>\n";
      if (c->low != c->high)
        s += "<text x=\"" + svg::Short(X(ix) + kCell / 2, 6) + "\" y=\"" + svg::Short(Y(iy) + kCell / 2 + 13, 6) +
             "\" text-anchor=\"middle\" font-size=\"10\" fill=\"" + (dark ? "#f4f4f4" : "#444444") + "\">[" +
             svg::Short(c->low) + "–" + svg::Short(c->high) + "]</text>\n";
      // Seeds on both sides of the level: the envelope's edge is uncertain here.
      if (c->low <= e.level && c->high > e.level)
        s += "<rect x=\"" + svg::Short(X(ix) + 3, 6) + "\" y=\"" + svg::Short(Y(iy) + 3, 6) + "\" width=\"" +
             svg::Short(kCell - 6, 6) + "\" height=\"" + svg::Short(kCell - 6, 6) +
             "\" fill=\"none\" stroke=\"#555\" stroke-dasharray=\"3 3\"/>\n";
    }
  // The envelope's edge: between a cell within it (median <= level) and one
  // outside it or off the grid's inner side.
  const auto inside = [&](long ix, long iy) {
    if (ix < 0 || iy < 0 || ix >= long(nx) || iy >= long(ny)) return false;
    const EnvelopeCell* c = cell_at(std::size_t(ix), std::size_t(iy));
    return c && std::isfinite(c->median) && c->median <= e.level;
  };
  std::string edge;
  for (long iy = 0; iy < long(ny); ++iy)
    for (long ix = 0; ix < long(nx); ++ix) {
      if (!inside(ix, iy)) continue;
      const double x0 = X(std::size_t(ix)), y0 = Y(std::size_t(iy)), x1 = x0 + kCell, y1 = y0 + kCell;
      if (!inside(ix + 1, iy) && ix + 1 < long(nx)) edge += "M" + svg::Short(x1, 6) + " " + svg::Short(y0, 6) + "V" + svg::Short(y1, 6);
      if (!inside(ix - 1, iy) && ix > 0) edge += "M" + svg::Short(x0, 6) + " " + svg::Short(y0, 6) + "V" + svg::Short(y1, 6);
      if (!inside(ix, iy + 1) && iy + 1 < long(ny)) edge += "M" + svg::Short(x0, 6) + " " + svg::Short(y0, 6) + "H" + svg::Short(x1, 6);
      if (!inside(ix, iy - 1) && iy > 0) edge += "M" + svg::Short(x0, 6) + " " + svg::Short(y1, 6) + "H" + svg::Short(x1, 6);
    }
  if (!edge.empty()) s += "<path d=\"" + edge + "\" stroke=\"#1a5fb4\" stroke-width=\"4\" fill=\"none\"/>\n";
  for (std::size_t ix = 0; ix < nx; ++ix)
    s += "<text x=\"" + svg::Short(X(ix) + kCell / 2, 6) + "\" y=\"" + svg::Short(kTop + double(ny) * kCell + 16, 6) +
         "\" text-anchor=\"middle\">" + svg::Short(e.xs[ix]) + "</text>\n";
  for (std::size_t iy = 0; iy < ny && !e.y_axis.empty(); ++iy)
    s += "<text x=\"" + svg::Short(kLeft - 6, 6) + "\" y=\"" + svg::Short(Y(iy) + kCell / 2 + 4, 6) +
         "\" text-anchor=\"end\">" + svg::Short(e.ys[iy]) + "</text>\n";
  s += "<text x=\"" + svg::Short(kLeft + double(nx) * kCell / 2, 6) + "\" y=\"" + svg::Short(height - 14, 6) +
       "\" text-anchor=\"middle\">" + svg::Escape(e.x_axis) + "</text>\n";
  s += "<text transform=\"translate(16," + svg::Short(kTop + double(ny) * kCell / 2, 6) +
       ") rotate(-90)\" text-anchor=\"middle\">" + svg::Escape(e.y_axis) + "</text>\n";
  const double lx = kLeft + double(nx) * kCell + 16;
  s += "<path d=\"M" + svg::Short(lx, 6) + " " + svg::Short(kTop + 10, 6) + "H" + svg::Short(lx + 30, 6) +
       "\" stroke=\"#1a5fb4\" stroke-width=\"4\"/><text x=\"" + svg::Short(lx + 36, 6) + "\" y=\"" + svg::Short(kTop + 14, 6) +
       "\">edge of the envelope</text>\n";
  s += "<text x=\"" + svg::Short(lx, 6) + "\" y=\"" + svg::Short(kTop + 32, 6) + "\">(median ≤ " + svg::Short(e.level) +
       " inside)</text>\n";
  s += "<rect x=\"" + svg::Short(lx, 6) + "\" y=\"" + svg::Short(kTop + 46, 6) +
       "\" width=\"30\" height=\"20\" fill=\"none\" stroke=\"#555\" stroke-dasharray=\"3 3\"/><text x=\"" +
       svg::Short(lx + 36, 6) + "\" y=\"" + svg::Short(kTop + 60, 6) + "\">seeds on both sides</text>\n";
  s += "</svg>\n";
  return s;
}

}  // namespace crowdrecon::reports
