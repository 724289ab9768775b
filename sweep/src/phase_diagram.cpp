#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/sweep/phase_diagram.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <regex>
#include <set>

#include <nlohmann/json.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/sweep/results.hpp"
#include "crowdrecon/viz/canvas.hpp"

namespace crowdrecon::sweep {

namespace fs = std::filesystem;
using viz::Color;

namespace {

constexpr double kPi = std::numbers::pi;

// --- regimes -----------------------------------------------------------------

enum Category { kLanes, kAvalanches, kClogging, kUnclassified, kFailed, kCategoryCount };

struct CategoryStyle {
  const char* legend;
  Color color;
};

// The paper's Figure 5 markers: lanes disks, avalanches crosses, clogging
// squares; then the two outcomes the paper does not have.
const std::array<CategoryStyle, kCategoryCount> kStyles = {{
    {"lanes", Color::Hex(0x1f77b4)},
    {"avalanches", Color::Hex(0xff7f0e)},
    {"clogging", Color::Hex(0xd62728)},
    {"unclassified", Color::Hex(0x8c8c8c)},
    {"run failed", Color::Hex(0x222222)},
}};

// The regime code of analysis::Regime (0 lanes, 1 avalanches, 2 clogging,
// 3 unclassified) as the text of the regime column.
ResultsTable::Cell RegimeTextOf(const ResultsTable::Cell& code) {
  ResultsTable::Cell c;
  c.null = code.null;
  if (!code.null) {
    const int k = static_cast<int>(code.number);
    c.text = k == 0 ? "lanes" : k == 1 ? "avalanches" : k == 2 ? "clogging" : "unclassified";
  }
  return c;
}

Category CategoryOf(const ResultsTable::Cell& status, const ResultsTable::Cell& regime) {
  if (status.text != "complete") return kFailed;
  if (regime.text == "lanes") return kLanes;
  if (regime.text == "avalanches") return kAvalanches;
  if (regime.text == "clogging") return kClogging;
  return kUnclassified;
}

// --- axes ----------------------------------------------------------------------

struct AxisLabel {
  std::string text;
  bool percent = false;  // values are fractions, shown in %
};

AxisLabel LabelOf(const std::string& path) {
  static const std::map<std::string, AxisLabel> known = {
      {"population.density_per_m2", {"density (persons/m\u00b2)", false}},
      {"population.counter_flow_fraction", {"counter-flow (% of people)", true}},
      {"population.count", {"people", false}},
      {"model.back_force_gamma", {"back force \u0393", false}},
      {"model.torsion_stiffness_lambda", {"torsion stiffness \u03bb", false}},
      {"model.restitution", {"restitution \u03b5", false}},
      {"model.friction_coefficient", {"friction coefficient \u03bc", false}},
  };
  if (const auto it = known.find(path); it != known.end()) return it->second;
  const bool fraction = path.size() > 9 && path.compare(path.size() - 9, 9, "_fraction") == 0;
  return {fraction ? path + " (%)" : path, fraction};
}

std::string Short(double v, int digits = 3) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
  return buffer;
}

struct PlotAxis {
  std::string path;
  AxisLabel label;
  bool numeric = true;
  std::vector<std::string> texts;  // distinct values, in plotting order
  std::vector<double> positions;   // their positions on the axis
  double lo = 0, hi = 1;           // drawn range
  std::vector<double> edges;       // cell edges (size + 1)

  std::size_t IndexOf(const ResultsTable::Cell& c) const {
    const std::string t = Key(c);
    return static_cast<std::size_t>(std::find(texts.begin(), texts.end(), t) - texts.begin());
  }
  static std::string Key(const ResultsTable::Cell& c) { return c.null ? std::string("null") : c.text; }
  std::string TickText(std::size_t i) const {
    if (!numeric) return texts[i];
    return label.percent ? Short(positions[i] * 100.0, 6) : Short(positions[i], 6);
  }
};

PlotAxis MakeAxis(const ResultsTable& t, const std::string& path) {
  PlotAxis a;
  a.path = path;
  a.label = LabelOf(path);
  const std::size_t col = t.Column(path);
  // Distinct values in order of first appearance (run order follows the
  // sweep file's order of values); numbers sorted.
  std::vector<std::pair<std::string, double>> values;
  std::set<std::string> seen;
  for (const auto& row : t.rows) {
    const ResultsTable::Cell& c = row[col];
    if (!c.numeric) a.numeric = false;
    if (seen.insert(PlotAxis::Key(c)).second) values.emplace_back(PlotAxis::Key(c), c.number);
  }
  if (a.numeric)
    std::sort(values.begin(), values.end(), [](const auto& p, const auto& q) { return p.second < q.second; });
  for (std::size_t i = 0; i < values.size(); ++i) {
    a.texts.push_back(values[i].first);
    a.positions.push_back(a.numeric ? values[i].second : static_cast<double>(i));
  }
  // Cells: edges halfway between neighbours; the outer cells as wide as
  // their inner half.
  const std::size_t n = a.positions.size();
  if (n == 0) {
    a.edges = {0.0, 1.0};
  } else if (n == 1) {
    const double half = a.numeric && a.positions[0] != 0.0 ? 0.1 * std::abs(a.positions[0]) : 0.5;
    a.edges = {a.positions[0] - half, a.positions[0] + half};
  } else {
    a.edges.push_back(a.positions[0] - 0.5 * (a.positions[1] - a.positions[0]));
    for (std::size_t i = 0; i + 1 < n; ++i) a.edges.push_back(0.5 * (a.positions[i] + a.positions[i + 1]));
    a.edges.push_back(a.positions[n - 1] + 0.5 * (a.positions[n - 1] - a.positions[n - 2]));
  }
  a.lo = a.edges.front();
  a.hi = a.edges.back();
  return a;
}

// --- the grid of one picture ---------------------------------------------------

struct Point {
  std::vector<Category> votes;  // one per run (seed), in run order
  std::vector<std::uint64_t> seeds;
  std::map<std::string, std::vector<double>> metrics;  // complete runs only
};

struct Panel {
  std::string variant;
  std::string slice;  // "model.restitution = 0.3, ..." for extra axes; "" if none
  std::string stem;   // file name stem
  std::map<std::pair<std::size_t, std::size_t>, Point> points;
  std::size_t runs = 0;
  // What the verdicts rest on: the runs' lengths and the classifiers that
  // judged them (1 where the table predates the column).
  double shortest_s = std::numeric_limits<double>::infinity(), longest_s = 0.0;
  std::set<int> classifiers;
  bool single_release = false;  // PhaseOptions::single_release_reading
};

// "120 runs of 30 s, classifier version 1" (or "of 21-240 s" when the runs
// stopped when settled or failed early).
std::string RunsText(const Panel& p) {
  char length[64];
  if (!(p.longest_s > 0.0)) std::snprintf(length, sizeof length, "of unknown length");
  else if (p.longest_s - p.shortest_s < 0.5) std::snprintf(length, sizeof length, "of %.0f s", p.longest_s);
  else std::snprintf(length, sizeof length, "of %.0f-%.0f s", p.shortest_s, p.longest_s);
  std::string versions;
  for (int v : p.classifiers) versions += (versions.empty() ? "" : " and ") + std::to_string(v);
  return std::to_string(p.runs) + " runs " + length + ", classifier version " + versions +
         (p.single_release ? ", read as a single release (a clog of at least 5 s released once)" : "");
}

// Page layout in device pixels (y down).
struct Layout {
  double width = 980, height = 760;
  double left = 110, right = 720, top = 96, bottom = 660;  // the plot area
  const PlotAxis* x = nullptr;
  const PlotAxis* y = nullptr;
  double PX(double v) const { return left + (v - x->lo) / (x->hi - x->lo) * (right - left); }
  double PY(double v) const { return bottom - (v - y->lo) / (y->hi - y->lo) * (bottom - top); }
};

// Pixel coordinates (from the top-left corner) to the canvas's world
// coordinates: the canvas is set up one world unit per pixel, y up.
struct Page {
  viz::Canvas canvas;
  double height;
  Page(const fs::path& file, double w, double h) : canvas(file, {0, 0}, {w, h}, 1.0, 0.0), height(h) {}
  Vec2 P(double x, double y) const { return {x, height - y}; }
  std::vector<Vec2> Poly(const std::vector<std::pair<double, double>>& pts) const {
    std::vector<Vec2> out;
    for (const auto& [x, y] : pts) out.push_back(P(x, y));
    return out;
  }
  void Rect(double x0, double y0, double x1, double y1, Color fill) {
    canvas.FillPolygon(Poly({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}), fill);
  }
  void RectOutline(double x0, double y0, double x1, double y1, Color stroke, double w) {
    canvas.StrokePolygon(Poly({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}), stroke, w);
  }
  void LinePx(double x0, double y0, double x1, double y1, Color c, double w) { canvas.Line(P(x0, y0), P(x1, y1), c, w); }
};

void DrawMarker(Page& page, Category c, double cx, double cy, double r) {
  const Color color = kStyles[c].color;
  const Color edge = Color::Hex(0x333333);
  switch (c) {
    case kLanes:
      page.canvas.Circle(page.P(cx, cy), r, color, edge, 1.0);
      break;
    case kAvalanches: {
      const double w = std::max(2.5, 0.42 * r), d = 0.85 * r;
      page.LinePx(cx - d, cy - d, cx + d, cy + d, color, w);
      page.LinePx(cx - d, cy + d, cx + d, cy - d, color, w);
      break;
    }
    case kClogging: {
      const double d = 0.85 * r;
      page.Rect(cx - d, cy - d, cx + d, cy + d, color);
      page.RectOutline(cx - d, cy - d, cx + d, cy + d, edge, 1.0);
      break;
    }
    case kUnclassified: {
      const double d = 0.95 * r;
      page.canvas.StrokePolygon(page.Poly({{cx, cy - d}, {cx + d, cy}, {cx, cy + d}, {cx - d, cy}}), color,
                                std::max(2.0, 0.25 * r));
      break;
    }
    case kFailed:
    case kCategoryCount: {
      const double d = 0.9 * r;
      page.canvas.FillPolygon(page.Poly({{cx, cy - d}, {cx + d, cy + 0.8 * d}, {cx - d, cy + 0.8 * d}}), color);
      break;
    }
  }
}

// One segment per vote, clockwise from the top, in the vote's colour.
void DrawVoteRing(Page& page, const std::vector<Category>& votes, double cx, double cy, double r_in, double r_out) {
  const std::size_t n = votes.size();
  if (n == 0) return;
  const double gap = n > 1 ? std::min(0.2, kPi / static_cast<double>(n)) : 0.0;  // radians left white between segments
  for (std::size_t i = 0; i < n; ++i) {
    const double a0 = kPi / 2 - 2 * kPi * static_cast<double>(i) / static_cast<double>(n) - gap / 2;
    const double a1 = kPi / 2 - 2 * kPi * static_cast<double>(i + 1) / static_cast<double>(n) + gap / 2;
    std::vector<std::pair<double, double>> pts;
    const int steps = 24;
    for (int k = 0; k <= steps; ++k) {
      const double a = a0 + (a1 - a0) * k / steps;
      pts.emplace_back(cx + r_out * std::cos(a), cy - r_out * std::sin(a));
    }
    for (int k = steps; k >= 0; --k) {
      const double a = a0 + (a1 - a0) * k / steps;
      pts.emplace_back(cx + r_in * std::cos(a), cy - r_in * std::sin(a));
    }
    page.canvas.FillPolygon(page.Poly(pts), kStyles[votes[i]].color);
  }
}

// The majority of the votes, or kCategoryCount for a tie.
Category Majority(const std::vector<Category>& votes) {
  std::array<int, kCategoryCount> count{};
  for (Category c : votes) ++count[c];
  const int best = *std::max_element(count.begin(), count.end());
  if (std::count(count.begin(), count.end(), best) > 1) return kCategoryCount;
  return static_cast<Category>(std::max_element(count.begin(), count.end()) - count.begin());
}

void DrawAxes(Page& page, const Layout& L, bool grid_lines) {
  const Color grid = Color::Hex(0xdddddd);
  const auto every = [](std::size_t n) { return n > 12 ? (n + 11) / 12 : std::size_t{1}; };
  for (std::size_t i = 0; i < L.x->positions.size(); ++i) {
    const double px = L.PX(L.x->positions[i]);
    if (grid_lines) page.LinePx(px, L.top, px, L.bottom, grid, 1.0);
    page.LinePx(px, L.bottom, px, L.bottom + 6, Color::Black(), 1.2);
    if (i % every(L.x->positions.size()) == 0)
      page.canvas.TextPxAligned(px, L.bottom + 10, L.x->TickText(i), 13, 0.5, 0.0);
  }
  for (std::size_t i = 0; i < L.y->positions.size(); ++i) {
    const double py = L.PY(L.y->positions[i]);
    if (grid_lines) page.LinePx(L.left, py, L.right, py, grid, 1.0);
    page.LinePx(L.left - 6, py, L.left, py, Color::Black(), 1.2);
    if (i % every(L.y->positions.size()) == 0)
      page.canvas.TextPxAligned(L.left - 10, py, L.y->TickText(i), 13, 1.0, 0.5);
  }
  page.RectOutline(L.left, L.top, L.right, L.bottom, Color::Black(), 1.2);
  page.canvas.TextPxAligned(0.5 * (L.left + L.right), L.bottom + 36, L.x->label.text, 15, 0.5, 0.0);
  page.canvas.TextPxAligned(L.left - 62, 0.5 * (L.top + L.bottom), L.y->label.text, 15, 0.5, 1.0, Color::Black(),
                            kPi / 2);
}

void DrawTitle(Page& page, const Layout& L, const std::string& title, const std::string& subtitle) {
  const double room = L.width - L.left - 12.0;  // long sweep names shrink to fit the page
  page.canvas.TextPxAligned(L.left, 30, title, 18, 0.0, 0.5, Color::Black(), 0.0, true, room);
  page.canvas.TextPxAligned(L.left, 58, subtitle, 14, 0.0, 0.5, Color::Hex(0x333333), 0.0, false, room);
}

std::string PanelTitle(const Panel& p) {
  return "variant " + p.variant + (p.slice.empty() ? "" : ", " + p.slice);
}

std::size_t SeedCount(const Panel& panel) {
  std::size_t n = 0;
  for (const auto& [cell, point] : panel.points) n = std::max(n, point.votes.size());
  return n;
}

// The run's path over the plot (PathOverlay), clamped to the plotted range.
void DrawPath(Page& page, const Layout& L, const PathOverlay& path) {
  if (path.points.size() < 2) return;
  const auto at = [&](std::size_t i) {
    const double x = std::clamp(path.points[i].first, L.x->lo, L.x->hi);
    const double y = std::clamp(path.points[i].second, L.y->lo, L.y->hi);
    return std::pair{L.PX(x), L.PY(y)};
  };
  std::vector<std::pair<double, double>> pts;
  for (std::size_t i = 0; i < path.points.size(); ++i) pts.push_back(at(i));
  const Color ink = Color::Hex(0x7a0177);
  page.canvas.StrokePolyline(page.Poly(pts), Color::White(), 6.0);
  page.canvas.StrokePolyline(page.Poly(pts), ink, 3.0);
  page.canvas.Arrow(page.P(pts[pts.size() - 2].first, pts[pts.size() - 2].second),
                    page.P(pts.back().first, pts.back().second), ink, 3.0);
  std::vector<std::pair<double, double>> labelled;  // a label per place: clamped points pile up at the edges
  for (const auto& [index, text] : path.labels) {
    if (index >= pts.size()) continue;
    const std::pair<double, double> spot = pts[index];  // (a structured binding is not captured before clang 16)
    const bool crowded = std::any_of(labelled.begin(), labelled.end(), [&](const std::pair<double, double>& q) {
      return std::abs(q.first - spot.first) < 40.0 && std::abs(q.second - spot.second) < 14.0;
    });
    if (crowded) continue;
    labelled.push_back(spot);
    page.canvas.Dot(page.P(spot.first, spot.second), 4.5, ink);
    page.canvas.TextPxAligned(spot.first + 7, spot.second - 7, text, 12, 0.0, 1.0, ink, 0.0, true);
  }
  const double room = L.width - L.left - 12.0;  // (long captions shrink to fit the page)
  if (!path.caption.empty())
    page.canvas.TextPxAligned(L.left, L.height - 32, path.caption, 12, 0.0, 0.0, ink, 0.0, false, room);
  if (!path.note.empty())
    page.canvas.TextPxAligned(L.left, 78, path.note, 13, 0.0, 0.5, Color::Hex(0xb2182b), 0.0, true, room);
}

void DrawPhase(const Panel& panel, const Layout& L, const std::string& sweep_name, const fs::path& file,
               const PathOverlay& path = {}) {
  Page page(file, L.width, L.height);
  DrawTitle(page, L, sweep_name,
            "Phase diagram, " + PanelTitle(panel) + ": regime of the majority of " +
                std::to_string(SeedCount(panel)) + " seeds");
  DrawAxes(page, L, true);
  const double cell_w = (L.right - L.left) / static_cast<double>(std::max<std::size_t>(1, L.x->positions.size()));
  const double cell_h = (L.bottom - L.top) / static_cast<double>(std::max<std::size_t>(1, L.y->positions.size()));
  const double r = std::clamp(0.26 * std::min(cell_w, cell_h), 4.0, 18.0);
  std::array<int, kCategoryCount + 1> majority_count{};
  std::array<bool, kCategoryCount> voted{};
  int disagreeing = 0;
  for (const auto& [cell, point] : panel.points) {
    if (point.votes.empty()) continue;
    for (Category c : point.votes) voted[c] = true;
    const double cx = L.PX(L.x->positions[cell.first]);
    const double cy = L.PY(L.y->positions[cell.second]);
    const Category m = Majority(point.votes);
    ++majority_count[m];
    const bool unanimous = std::all_of(point.votes.begin(), point.votes.end(), [&votes = point.votes](Category c) { return c == votes[0]; });
    if (!unanimous) {
      ++disagreeing;
      page.canvas.Circle(page.P(cx, cy), 1.75 * r, Color::White(), Color::Hex(0x999999), 0.8);
      DrawVoteRing(page, point.votes, cx, cy, 1.25 * r, 1.7 * r);
    }
    if (m == kCategoryCount) page.canvas.TextPxAligned(cx, cy, "?", 1.6 * r, 0.5, 0.5, Color::Black(), 0.0, true);
    else DrawMarker(page, m, cx, cy, r);
  }

  // Legend.
  double y = L.top + 8;
  const double lx = L.right + 34;
  page.canvas.TextPxAligned(lx - 10, y, "majority regime", 14, 0.0, 0.0, Color::Black(), 0.0, true);
  y += 30;
  for (int c = 0; c < kCategoryCount; ++c) {
    if (c >= kUnclassified && !voted[static_cast<std::size_t>(c)]) continue;
    DrawMarker(page, static_cast<Category>(c), lx + 4, y, 9);
    page.canvas.TextPxAligned(lx + 24, y, std::string(kStyles[static_cast<std::size_t>(c)].legend) + " (" +
                                              std::to_string(majority_count[static_cast<std::size_t>(c)]) + ")",
                              13, 0.0, 0.5);
    y += 28;
  }
  if (majority_count[kCategoryCount] > 0) {
    page.canvas.TextPxAligned(lx + 4, y, "?", 18, 0.5, 0.5, Color::Black(), 0.0, true);
    page.canvas.TextPxAligned(lx + 24, y, "no majority (" + std::to_string(majority_count[kCategoryCount]) + ")", 13,
                              0.0, 0.5);
    y += 28;
  }
  y += 14;
  page.canvas.TextPxAligned(lx - 10, y, "seeds disagree", 14, 0.0, 0.0, Color::Black(), 0.0, true);
  y += 40;
  page.canvas.Circle(page.P(lx + 8, y), 1.75 * 9, Color::White(), Color::Hex(0x999999), 0.8);
  DrawVoteRing(page, {kLanes, kLanes, kAvalanches}, lx + 8, y, 1.25 * 9, 1.7 * 9);
  DrawMarker(page, kLanes, lx + 8, y, 9);
  page.canvas.TextPxAligned(lx + 34, y - 8, "ring: one segment per", 12, 0.0, 0.5);
  page.canvas.TextPxAligned(lx + 34, y + 8, "seed, in its regime", 12, 0.0, 0.5);
  y += 36;
  page.canvas.TextPxAligned(lx - 10, y, std::to_string(disagreeing) + " of " + std::to_string(panel.points.size()) +
                                            " points disagree",
                            12, 0.0, 0.5, Color::Hex(0x333333));
  page.canvas.TextPxAligned(L.left, L.height - 14,
                            RunsText(panel) + "; regimes as defined in docs/analysis.md", 12, 0.0, 0.0,
                            Color::Hex(0x555555));
  DrawPath(page, L, path);
  page.canvas.Finish();
}

// --- heat maps -------------------------------------------------------------------

struct Metric {
  const char* name;  // column, or a derived value
  const char* title;
  const char* unit;  // for the colour bar ("" if none)
};

const std::vector<Metric> kMetrics = {
    {"mean_speed_m_per_s", "Mean speed along the desired direction", "m/s"},
    {"mean_stopped_fraction", "Fraction of people stopped (|v| < 0.1 m/s)", ""},
    {"stopped_time_fraction", "Fraction of the time the flow is stopped", ""},
    {"mean_lane_order", "Lane order parameter", ""},
    {"avalanche_rate_per_min", "Avalanches per minute of the stationary stage", "1/min"},
    {"max_load_n", "Largest load on a person", "N"},
    {"above_load_person_frames", "Fraction of person-frames above 400 N", ""},
    // Classifier version 2 (issue 19): per direction, and the field's measures
    // of clogs at the line; tables written before it lack them (not drawn).
    {"frozen_at_end_g1", "Counter-flow frozen at the end (mean over seeds)", ""},
    {"clogged_fraction_g0", "Main flow: fraction of the time clogged at the line (lapses > 2 s)", ""},
    {"clogged_fraction_g1", "Counter-flow: fraction of the time clogged at the line (lapses > 2 s)", ""},
    {"lapse_tail_exponent_g1", "Counter-flow: tail exponent of the lapses between passages", ""},
    {"avalanche_mean_rise_time_s", "Rise time of the avalanches' releases", "s"},
};

// The metrics a results table can show: derived ones, and those whose column it has.
std::vector<const Metric*> AvailableMetrics(const ResultsTable& t) {
  std::vector<const Metric*> available;
  for (const Metric& m : kMetrics)
    if (std::string(m.name) == "avalanche_rate_per_min" || t.FindColumn(m.name)) available.push_back(&m);
  return available;
}

Color Viridis(double t) {
  static const std::array<unsigned, 9> stops = {0x440154, 0x472c7a, 0x3b518b, 0x2c718e, 0x21908d,
                                                0x27ad81, 0x5cc863, 0xaadc32, 0xfde725};
  t = std::clamp(t, 0.0, 1.0) * 8.0;
  const auto i = static_cast<std::size_t>(std::min(7.0, std::floor(t)));
  const double f = t - static_cast<double>(i);
  const Color a = Color::Hex(stops[i]), b = Color::Hex(stops[i + 1]);
  return {a.r + (b.r - a.r) * f, a.g + (b.g - a.g) * f, a.b + (b.b - a.b) * f, 1.0};
}

double Mean(const std::vector<double>& v) {
  double sum = 0;
  std::size_t n = 0;
  for (double x : v)
    if (std::isfinite(x)) {
      sum += x;
      ++n;
    }
  return n ? sum / static_cast<double>(n) : std::numeric_limits<double>::quiet_NaN();
}

void DrawHeatMap(const Panel& panel, const Layout& L, const Metric& metric, const std::string& sweep_name,
                 const fs::path& file) {
  Page page(file, L.width, L.height);
  DrawTitle(page, L, std::string(metric.title) + (*metric.unit ? std::string(" (") + metric.unit + ")" : ""),
            sweep_name + ", " + PanelTitle(panel) + ": mean over " + std::to_string(SeedCount(panel)) + " seeds");
  std::map<std::pair<std::size_t, std::size_t>, double> value;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& [cell, point] : panel.points) {
    const auto it = point.metrics.find(metric.name);
    const double v = it == point.metrics.end() ? std::numeric_limits<double>::quiet_NaN() : Mean(it->second);
    value[cell] = v;
    if (std::isfinite(v)) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  const bool any = std::isfinite(lo);
  if (!any) lo = 0, hi = 1;
  if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) {
    lo -= 0.5 * std::max(1e-9, std::abs(lo));
    hi += 0.5 * std::max(1e-9, std::abs(hi));
  }
  for (std::size_t i = 0; i < L.x->positions.size(); ++i) {
    for (std::size_t j = 0; j < L.y->positions.size(); ++j) {
      const double x0 = L.PX(L.x->edges[i]), x1 = L.PX(L.x->edges[i + 1]);
      const double y0 = L.PY(L.y->edges[j + 1]), y1 = L.PY(L.y->edges[j]);
      const auto it = value.find({i, j});
      const double v = it == value.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
      const Color fill = std::isfinite(v) ? Viridis((v - lo) / (hi - lo)) : Color::Hex(0xe8e8e8);
      page.Rect(x0, y0, x1, y1, fill);
      page.RectOutline(x0, y0, x1, y1, Color::White(), 1.0);
      if (x1 - x0 >= 38 && y1 - y0 >= 16) {
        const double luminance = 0.299 * fill.r + 0.587 * fill.g + 0.114 * fill.b;
        const std::string text = std::isfinite(v) ? Short(v) : (it == value.end() ? "" : "n/a");
        page.canvas.TextPxAligned(0.5 * (x0 + x1), 0.5 * (y0 + y1), text, std::min(13.0, 0.3 * (x1 - x0)), 0.5, 0.5,
                                  luminance > 0.55 ? Color::Black() : Color::White());
      }
    }
  }
  DrawAxes(page, L, false);
  // Colour bar.
  const double bx0 = L.right + 40, bx1 = bx0 + 22;
  const int slices = 128;
  for (int k = 0; k < slices; ++k) {
    const double t0 = static_cast<double>(k) / slices, t1 = static_cast<double>(k + 1) / slices;
    page.Rect(bx0, L.bottom - t1 * (L.bottom - L.top) - 1.0, bx1, L.bottom - t0 * (L.bottom - L.top),
              Viridis(0.5 * (t0 + t1)));
  }
  page.RectOutline(bx0, L.top, bx1, L.bottom, Color::Black(), 1.0);
  for (int k = 0; k <= 4; ++k) {
    const double t = k / 4.0;
    const double py = L.bottom - t * (L.bottom - L.top);
    page.LinePx(bx1, py, bx1 + 5, py, Color::Black(), 1.0);
    page.canvas.TextPxAligned(bx1 + 9, py, any ? Short(lo + t * (hi - lo)) : "", 12, 0.0, 0.5);
  }
  if (*metric.unit) page.canvas.TextPxAligned(bx0, L.top - 10, metric.unit, 13, 0.0, 1.0);
  const std::string source = std::string(metric.name) == "avalanche_rate_per_min"
                                 ? "avalanche_count / (duration_s - stationary_start_s) in minutes"
                                 : std::string("column ") + metric.name;
  page.canvas.TextPxAligned(L.left, L.height - 14, source + " of results.sqlite; grey: no value", 12, 0.0, 0.0,
                            Color::Hex(0x555555));
  page.canvas.Finish();
}

std::string Sanitized(const std::string& text) {
  std::string out;
  for (char c : text) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                    c == '_' || c == '-' || c == '=';
    out += ok ? c : '_';
  }
  return out;
}

std::string Html(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

}  // namespace

std::string PhaseSummary::BriefReport() const {
  std::string r = "read " + std::to_string(runs) + " runs; drew " + std::to_string(diagrams) + " phase diagram(s) and " +
                  std::to_string(heat_maps) + " heat map(s), " +
                  (heat_maps == 0 || heat_map_svg ? "PNG and SVG\n" : "PNG and SVG (heat maps PNG only)\n");
  for (const std::string& n : notes) r += "note: " + n + "\n";
  r += "index: " + index.string() + "\n";
  return r;
}

fs::path PhaseOutputFolder(const PhaseOptions& options) {
  const fs::path dir = options.results.extension() == ".sqlite" ? options.results.parent_path() : options.results;
  return options.output_dir.empty() ? dir / "phase" : options.output_dir;
}

OutputKind PhaseFolderOutput() {
  return {"a phase folder (phase-*, heat-* pictures and index.html only)", true, [](const fs::path& dir) {
    const std::regex picture(R"((phase|heat)-.*\.(png|svg)|index\.html)");
    return FolderHoldsOnly(dir, [&](const fs::directory_entry& e) {
      std::error_code ec;
      return e.is_regular_file(ec) && std::regex_match(e.path().filename().string(), picture);
    });
  }};
}

PhaseSummary DrawPhaseDiagrams(const PhaseOptions& options) {
  const ResultsTable t = ReadResults(options.results);
  const fs::path out = PhaseOutputFolder(options);
  const std::string x_path = t.sweep.count("diagram_x") ? t.sweep.at("diagram_x") : "";
  const std::string y_path = t.sweep.count("diagram_y") ? t.sweep.at("diagram_y") : "";
  if (x_path.empty() || y_path.empty())
    throw InputError(t.file.string() + ": the sweep has fewer than two axes; a phase diagram needs two (its x and y)");
  const std::string sweep_name = t.sweep.count("name") ? t.sweep.at("name") : "sweep";
  std::vector<std::string> axes, variants;
  try {
    for (const auto& a : nlohmann::json::parse(t.sweep.at("axes"))) axes.push_back(a.get<std::string>());
    for (const auto& v : nlohmann::json::parse(t.sweep.at("variants"))) variants.push_back(v.get<std::string>());
  } catch (const std::exception&) {
    throw InputError(t.file.string() + ": the sweep table's axes or variants are not readable");
  }

  if (options.single_release_reading && !t.FindColumn("regime_code_single_release"))
    throw InputError(t.file.string() + ": the runs table has no column \"regime_code_single_release\": the sweep was "
                     "analysed before the single-release reading existed (2026-11-27); run it again into a new folder "
                     "for --single-release");
  PlotAxis x = MakeAxis(t, x_path), y = MakeAxis(t, y_path);
  const std::size_t c_variant = t.Column("variant"), c_seed = t.Column("seed"), c_status = t.Column("status"),
                    c_regime = t.Column(options.single_release_reading ? "regime_code_single_release" : "regime"),
                    c_x = t.Column(x_path), c_y = t.Column(y_path);
  std::vector<std::size_t> c_other;
  for (const std::string& a : axes)
    if (a != x_path && a != y_path) c_other.push_back(t.Column(a));
  const std::size_t c_count = t.Column("avalanche_count"), c_duration = t.Column("duration_s"),
                    c_stationary = t.Column("stationary_start_s");
  const std::optional<std::size_t> c_classifier = t.FindColumn("regime_classifier_version");
  const std::vector<const Metric*> metrics = AvailableMetrics(t);

  // Panels in variant order, then in order of first appearance of the other
  // axes' values.
  std::vector<Panel> panels;
  std::map<std::string, std::size_t> panel_of;
  std::size_t failed = 0;
  for (const std::string& variant : variants) {
    for (const auto& row : t.rows) {
      if (row[c_variant].text != variant) continue;
      std::string slice, stem = "phase-" + Sanitized(variant);
      for (std::size_t c : c_other) {
        const std::string value = row[c].null ? "null" : row[c].text;
        slice += (slice.empty() ? "" : ", ") + t.columns[c] + " = " + value;
        const std::string& name = t.columns[c];
        stem += "-" + Sanitized(name.substr(name.rfind('.') == std::string::npos ? 0 : name.rfind('.') + 1) + "=" + value);
      }
      const std::string key = variant + "\n" + slice;
      if (!panel_of.count(key)) {
        panel_of[key] = panels.size();
        panels.push_back({variant, slice, stem, {}, 0, std::numeric_limits<double>::infinity(), 0.0, {}});
      }
      Panel& p = panels[panel_of[key]];
      p.single_release = options.single_release_reading;
      ++p.runs;
      if (!row[c_duration].null) {
        p.shortest_s = std::min(p.shortest_s, row[c_duration].number);
        p.longest_s = std::max(p.longest_s, row[c_duration].number);
      }
      if (c_classifier && !row[*c_classifier].null) p.classifiers.insert(static_cast<int>(row[*c_classifier].number));
      else if (!c_classifier) p.classifiers.insert(1);
      Point& point = p.points[{x.IndexOf(row[c_x]), y.IndexOf(row[c_y])}];
      const Category category =
          CategoryOf(row[c_status], options.single_release_reading ? RegimeTextOf(row[c_regime]) : row[c_regime]);
      if (category == kFailed) ++failed;
      point.votes.push_back(category);
      point.seeds.push_back(static_cast<std::uint64_t>(row[c_seed].number));
      if (category == kFailed) continue;
      for (const Metric* metric : metrics) {
        const Metric& m = *metric;
        double v = std::numeric_limits<double>::quiet_NaN();
        if (std::string(m.name) == "avalanche_rate_per_min") {
          const double stationary_s = row[c_duration].number - row[c_stationary].number;
          if (!row[c_count].null && !row[c_duration].null && !row[c_stationary].null && stationary_s > 0)
            v = row[c_count].number / (stationary_s / 60.0);
        } else {
          const ResultsTable::Cell& cell = row[t.Column(m.name)];
          if (!cell.null) v = cell.number;
        }
        point.metrics[m.name].push_back(v);
      }
    }
  }
  if (panels.empty()) throw InputError(t.file.string() + ": no runs have results yet; nothing to draw");

  CreateOutputFolder(out);

  PhaseSummary summary;
  summary.runs = t.rows.size();
  summary.heat_map_svg = options.heat_map_svg;
  if (failed) summary.notes.push_back(std::to_string(failed) + " run(s) failed (drawn as triangles)");
  const std::size_t expected = x.positions.size() * y.positions.size();
  for (const Panel& p : panels)
    if (p.points.size() < expected)
      summary.notes.push_back(PanelTitle(p) + ": " + std::to_string(expected - p.points.size()) + " of " +
                              std::to_string(expected) + " points have no results yet");

  Layout layout;
  layout.x = &x;
  layout.y = &y;
  std::string html = "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>" + Html(sweep_name) +
                     "</title>\n<style>body{font-family:sans-serif;margin:2em}img{width:100%}"
                     ".grid{display:grid;grid-template-columns:1fr 1fr;gap:1em}"
                     "figure{margin:0}</style></head><body>\n<h1>" +
                     Html(sweep_name) + "</h1>\n<p>" + std::to_string(t.rows.size()) + " runs from <code>" +
                     Html(t.file.string()) +
                     "</code>. Markers as in the paper's Figure 5: lanes (disks), avalanches (crosses), clogging "
                     "(squares); a ring shows each seed's regime where the seeds disagree. Click a picture for its " +
                     std::string(options.heat_map_svg ? "SVG" : "full size (SVG for the phase diagrams)") + ".</p>\n";
  html += "<h2>Phase diagrams</h2>\n<div class=\"grid\">\n";
  for (const Panel& p : panels) {
    const fs::path png = out / (p.stem + ".png"), svg = out / (p.stem + ".svg");
    DrawPhase(p, layout, sweep_name, png, options.path);
    DrawPhase(p, layout, sweep_name, svg, options.path);
    summary.pictures.push_back(png);
    summary.pictures.push_back(svg);
    ++summary.diagrams;
    html += "<figure><a href=\"" + Html(svg.filename().string()) + "\"><img src=\"" + Html(png.filename().string()) +
            "\"></a><figcaption>" + Html(PanelTitle(p) + "; " + RunsText(p)) + "</figcaption></figure>\n";
  }
  html += "</div>\n";
  if (options.heat_maps) {
    for (const Panel& p : panels) {
      html += "<h2>Metrics, " + Html(PanelTitle(p)) + "</h2>\n<div class=\"grid\">\n";
      for (const Metric* metric : metrics) {
        const Metric& m = *metric;
        const std::string stem = "heat-" + p.stem.substr(6) + "-" + m.name;
        const fs::path png = out / (stem + ".png"), svg = out / (stem + ".svg");
        DrawHeatMap(p, layout, m, sweep_name, png);
        summary.pictures.push_back(png);
        if (options.heat_map_svg) {
          DrawHeatMap(p, layout, m, sweep_name, svg);
          summary.pictures.push_back(svg);
        }
        ++summary.heat_maps;
        const fs::path& link = options.heat_map_svg ? svg : png;
        html += "<figure><a href=\"" + Html(link.filename().string()) + "\"><img src=\"" +
                Html(png.filename().string()) + "\"></a><figcaption>" + Html(m.title) + "</figcaption></figure>\n";
      }
      html += "</div>\n";
    }
  }
  html += "</body></html>\n";
  summary.index = out / "index.html";
  WriteFileAtomically(summary.index, html);
  return summary;
}

}  // namespace crowdrecon::sweep
