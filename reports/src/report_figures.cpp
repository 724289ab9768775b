// The injury-risk report's figures and numbers (report_parts.hpp).
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/reports/report.hpp"
#include "crowdrecon/reports/html_page.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <random>
#include <sstream>
#include <utility>

#include "crowdrecon/analysis/plausibility.hpp"
#include "crowdrecon/common/child_process.hpp"
#include "crowdrecon/common/csv.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/common/sha256.hpp"
#include "crowdrecon/common/staged_folder.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/viz/render_run.hpp"
#include "crowdrecon/sweep/version.hpp"
#include "envelope.hpp"
#include "report_parts.hpp"
#include "crowdrecon/reports/svg.hpp"

namespace crowdrecon::reports {

namespace detail {

namespace {

// Ids of an SVG written by Cairo (glyphs, clips) made unique within the page.
std::string PrefixSvgIds(std::string text, const std::string& prefix) {
  const auto replace_all = [&text](const std::string& from, const std::string& to) {
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
      text.replace(at, from.size(), to);
  };
  replace_all("id=\"", "id=\"" + prefix);
  replace_all("href=\"#", "href=\"#" + prefix);
  replace_all("url(#", "url(#" + prefix);
  const std::size_t start = text.find("<svg");
  return start == std::string::npos ? text : text.substr(start);
}


std::string Base64(const std::string& bytes) {
  static const char* kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t b0 = static_cast<unsigned char>(bytes[i]);
    const std::uint32_t b1 = i + 1 < bytes.size() ? static_cast<unsigned char>(bytes[i + 1]) : 0u;
    const std::uint32_t b2 = i + 2 < bytes.size() ? static_cast<unsigned char>(bytes[i + 2]) : 0u;
    const std::uint32_t v = (b0 << 16) | (b1 << 8) | b2;
    out += kDigits[(v >> 18) & 63];
    out += kDigits[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[v & 63] : '=';
  }
  return out;
}

}  // namespace

// Counts whole (a median of an even number of runs may end in .5); other
// values with `digits` significant digits.
std::string Value(double v, int digits) {
  if (std::abs(v) >= 1.0 && std::abs(v - std::round(v * 2.0) / 2.0) < 1e-9) {
    char buf[32];
    std::snprintf(buf, sizeof buf, v == std::round(v) ? "%.0f" : "%.1f", v);
    return buf;
  }
  return Short(v, digits);
}

std::string SpreadText(const Spread& s, int digits) {
  if (s.runs == 0) return "–";
  if (s.runs == 1 || s.low == s.high) return Value(s.median, digits);
  return Value(s.median, digits) + " <span class=\"range\">[" + Value(s.low, digits) + "–" + Value(s.high, digits) + "]</span>";
}

// Above this many people the force network goes into the page as a PNG
// (a data URI, still inside the one file) rather than SVG: the SVG of the
// 6,800-person evacuation's network is 24 MB, its PNG about 1 MB.
constexpr std::uint32_t kNetworkSvgPeople = 2000;

// The force network of `frame` of a run, drawn by viz (the paper's Figure 6
// a-b): the whole view, or with `window` (its lower-left and upper-right
// corners) that part of it; `summary` (may be null) receives the layout.
std::string ForceNetworkFigure(const fs::path& run, std::int64_t frame, std::uint32_t people, const std::string& id_prefix,
                               const std::optional<std::pair<Vec2, Vec2>>& window, viz::RenderSummary* summary,
                               const std::optional<std::pair<Vec2, Vec2>>& mark, int width_px) {
  std::mt19937_64 rng(std::random_device{}());
  const fs::path dir = fs::temp_directory_path() / ("crowdrecon-report-" + std::to_string(rng()));
  viz::RenderOptions o;
  o.output_dir = dir;
  o.frames = viz::ParseFrameSelection(std::to_string(frame));
  const bool as_svg = people <= kNetworkSvgPeople;
  o.svg = as_svg;
  o.width_px = width_px > 0 ? width_px : as_svg ? 1100 : 2000;
  if (mark) {
    o.has_mark = true;
    o.mark_min_m = mark->first;
    o.mark_max_m = mark->second;
  }
  if (window) {
    o.has_window = true;
    o.window_min_m = window->first;
    o.window_max_m = window->second;
  }
  std::string text;
  try {
    const viz::RenderSummary drawn = viz::RenderRun(run, o);
    if (summary) *summary = drawn;
    text = ReadInputFile(viz::FramePicturePath(dir, frame, as_svg ? ".svg" : ".png"), "rendered force network");
  } catch (...) {
    std::error_code ec;
    fs::remove_all(dir, ec);
    throw;
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
  if (!as_svg)
    return "<img class=\"network\" alt=\"force network\" src=\"data:image/png;base64," + Base64(text) + "\">";
  std::string svg = PrefixSvgIds(text, id_prefix);
  // Scale with the page (Cairo writes fixed sizes in pt).
  const std::size_t tag_end = svg.find('>');
  if (tag_end != std::string::npos) svg.insert(tag_end, " class=\"network\"");
  return svg;
}


std::string CdfChart(const std::string& title, const std::string& x_label,
                     const std::vector<std::pair<std::string, std::vector<double>>>& sets, const RiskOptions& o,
                     const std::vector<std::string>& colors) {
  // 1 - CDF of each sorted set (values in N), plotted against F / F0.
  svg::Chart c;
  c.title = title;
  c.x_label = x_label;
  c.y_label = "fraction above";
  c.log_x = c.log_y = true;
  c.x_min = 1e-2;
  c.x_max = 1e2;
  double smallest = 1.0;
  for (std::size_t k = 0; k < sets.size(); ++k) {
    svg::Series s;
    s.label = sets[k].first;
    s.color = colors[k % colors.size()];
    s.step = true;
    const auto& v = sets[k].second;
    for (std::size_t i = 0; i < v.size(); ++i) {
      s.x.push_back(v[i] / o.f0_n);
      s.y.push_back(double(v.size() - i) / double(v.size()));
    }
    if (!v.empty()) smallest = std::min(smallest, 1.0 / double(v.size()));
    c.series.push_back(std::move(s));
  }
  c.y_min = std::max(1e-5, std::pow(10.0, std::floor(std::log10(smallest))));
  c.y_max = 1.0;
  c.legend_left = c.legend_bottom = true;
  c.bands = {{1e-3, 1.0, kZoneColor[0], "safe"},
             {1.0, o.danger_n / o.f0_n, kZoneColor[1], "uncomfortable"},
             {o.danger_n / o.f0_n, 1e3, kZoneColor[2], "danger"}};
  return c.ToSvg();
}

}  // namespace detail

}  // namespace crowdrecon::reports
