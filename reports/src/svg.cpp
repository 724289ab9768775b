#include "crowdrecon/reports/svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace crowdrecon::reports::svg {

std::string Escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string Short(double v, int digits) {
  if (!std::isfinite(v)) return v > 0 ? "∞" : "–";
  char buf[64];
  // Large values whole (6800, not 6.8e+03); small ones with `digits` significant digits.
  if (std::abs(v) >= std::pow(10.0, digits) && std::abs(v) < 1e12)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

namespace {

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

}  // namespace

std::string Open(const std::string& css_class, double width, double height, const std::string& title, double title_x,
                 double title_y) {
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"" + css_class + "\" viewBox=\"0 0 " + Num(width) +
                  " " + Num(height) + "\" width=\"" + Num(width) + "\" height=\"" + Num(height) +
                  "\" font-family=\"sans-serif\" font-size=\"12\" role=\"img\" aria-label=\"" + Escape(title) + "\">\n";
  s += "<rect x=\"0\" y=\"0\" width=\"" + Num(width) + "\" height=\"" + Num(height) + "\" fill=\"white\"/>\n";
  s += "<text x=\"" + Num(title_x) + "\" y=\"" + Num(title_y) + "\" font-size=\"14\" font-weight=\"bold\">" +
       Escape(title) + "</text>\n";
  return s;
}

namespace {

// Ticks of a linear axis: about `count` round values in [lo, hi].
std::vector<double> LinearTicks(double lo, double hi, int count) {
  const double span = hi - lo;
  if (!(span > 0)) return {lo};
  const double raw = span / count, mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  std::vector<double> ticks;
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * span; t += step) ticks.push_back(std::abs(t) < 1e-12 * span ? 0.0 : t);
  return ticks;
}

}  // namespace

std::string Chart::ToSvg() const {
  constexpr double kLeft = 70, kRight = 20, kTop = 34, kBottom = 48;
  double x0 = x_min, x1 = x_max, y0 = y_min, y1 = y_max;
  if (!(x1 > x0) || !(y1 > y0)) {
    double ax = std::numeric_limits<double>::infinity(), bx = -ax, ay = ax, by = -ax;
    for (const Series& s : series)
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if ((log_x && !(s.x[i] > 0)) || (log_y && !(s.y[i] > 0)) || !std::isfinite(s.x[i]) || !std::isfinite(s.y[i]))
          continue;
        ax = std::min(ax, s.x[i]); bx = std::max(bx, s.x[i]);
        ay = std::min(ay, s.y[i]); by = std::max(by, s.y[i]);
      }
    if (!(x1 > x0)) {
      x0 = std::isfinite(ax) ? ax : 0.0;
      x1 = std::isfinite(bx) && bx > x0 ? bx : x0 + 1.0;
    }
    if (!(y1 > y0)) {
      y0 = log_y ? (std::isfinite(ay) ? ay : 1e-3) : std::min(0.0, std::isfinite(ay) ? ay : 0.0);
      y1 = std::isfinite(by) && by > y0 ? by * (log_y ? 1.5 : 1.08) : y0 + 1.0;
    }
  }
  const auto fx = [&](double v) { return log_x ? std::log10(v) : v; };
  const auto fy = [&](double v) { return log_y ? std::log10(v) : v; };
  const double pw = width - kLeft - kRight, ph = height - kTop - kBottom;
  const auto X = [&](double v) { return kLeft + (fx(v) - fx(x0)) / (fx(x1) - fx(x0)) * pw; };
  const auto Y = [&](double v) { return kTop + ph - (fy(v) - fy(y0)) / (fy(y1) - fy(y0)) * ph; };
  std::string s = Open("chart", width, height, title, kLeft, 20);
  for (const Band& b : bands) {
    const double a = X(std::max(b.from, x0)), e = X(std::min(b.to, x1));
    if (e <= a) continue;
    s += "<rect x=\"" + Num(a) + "\" y=\"" + Num(kTop) + "\" width=\"" + Num(e - a) + "\" height=\"" + Num(ph) +
         "\" fill=\"" + b.color + "\" fill-opacity=\"0.22\"/>\n";
    s += "<text x=\"" + Num((a + e) / 2) + "\" y=\"" + Num(kTop + 14) + "\" text-anchor=\"middle\" fill=\"#444\">" +
         Escape(b.label) + "</text>\n";
  }
  // Axes and ticks.
  std::vector<double> xt, yt;
  if (log_x) {
    for (double e = std::floor(std::log10(x0)); e <= std::ceil(std::log10(x1)); ++e)
      if (std::pow(10.0, e) >= x0 * 0.999 && std::pow(10.0, e) <= x1 * 1.001) xt.push_back(std::pow(10.0, e));
  } else {
    xt = LinearTicks(x0, x1, 8);
  }
  if (log_y) {
    for (double e = std::floor(std::log10(y0)); e <= std::ceil(std::log10(y1)); ++e)
      if (std::pow(10.0, e) >= y0 * 0.999 && std::pow(10.0, e) <= y1 * 1.001) yt.push_back(std::pow(10.0, e));
  } else {
    yt = LinearTicks(y0, y1, 6);
  }
  for (double t : xt) {
    s += "<line x1=\"" + Num(X(t)) + "\" y1=\"" + Num(kTop) + "\" x2=\"" + Num(X(t)) + "\" y2=\"" + Num(kTop + ph) +
         "\" stroke=\"#e4e4e4\"/>\n";
    s += "<text x=\"" + Num(X(t)) + "\" y=\"" + Num(kTop + ph + 16) + "\" text-anchor=\"middle\">" + Short(t) + "</text>\n";
  }
  for (double t : yt) {
    s += "<line x1=\"" + Num(kLeft) + "\" y1=\"" + Num(Y(t)) + "\" x2=\"" + Num(kLeft + pw) + "\" y2=\"" + Num(Y(t)) +
         "\" stroke=\"#e4e4e4\"/>\n";
    s += "<text x=\"" + Num(kLeft - 6) + "\" y=\"" + Num(Y(t) + 4) + "\" text-anchor=\"end\">" + Short(t) + "</text>\n";
  }
  s += "<rect x=\"" + Num(kLeft) + "\" y=\"" + Num(kTop) + "\" width=\"" + Num(pw) + "\" height=\"" + Num(ph) +
       "\" fill=\"none\" stroke=\"#333\"/>\n";
  s += "<text x=\"" + Num(kLeft + pw / 2) + "\" y=\"" + Num(height - 10) + "\" text-anchor=\"middle\">" + Escape(x_label) +
       "</text>\n";
  s += "<text transform=\"translate(16," + Num(kTop + ph / 2) + ") rotate(-90)\" text-anchor=\"middle\">" +
       Escape(y_label) + "</text>\n";
  for (const auto& [x, label] : x_marks) {
    if (!(x >= x0 && x <= x1)) continue;
    s += "<line x1=\"" + Num(X(x)) + "\" y1=\"" + Num(kTop) + "\" x2=\"" + Num(X(x)) + "\" y2=\"" + Num(kTop + ph) +
         "\" stroke=\"#b22\" stroke-dasharray=\"4 3\"/>\n";
    s += "<text x=\"" + Num(X(x) + 3) + "\" y=\"" + Num(kTop + 28) + "\" fill=\"#b22\">" + Escape(label) + "</text>\n";
  }
  // Series, clipped to the plot by clamping (a chart has few points outside).
  const auto cx = [&](double v) { return std::clamp(X(v), kLeft, kLeft + pw); };
  const auto cy = [&](double v) { return std::clamp(Y(v), kTop, kTop + ph); };
  const double labelled = double(std::count_if(series.begin(), series.end(), [](const Series& x) { return !x.label.empty(); }));
  double legend_y = legend_bottom ? kTop + ph - 10 - 16.0 * labelled + 16 : kTop + 30;
  const double legend_x = legend_left ? kLeft + 10 : kLeft + pw - 280;
  std::string legend;  // drawn last, on a light ground, over the lines
  for (const Series& ser : series) {
    std::string path;
    bool pen = false;
    double last_y = 0;
    for (std::size_t i = 0; i < ser.x.size(); ++i) {
      const bool ok = std::isfinite(ser.x[i]) && std::isfinite(ser.y[i]) && (!log_x || ser.x[i] > 0) && (!log_y || ser.y[i] > 0);
      if (!ok) {
        pen = false;
        continue;
      }
      const double px = cx(ser.x[i]), py = cy(ser.y[i]);
      if (!pen) {
        path += "M" + Num(px) + " " + Num(py);
        pen = true;
      } else {
        if (ser.step) path += "L" + Num(px) + " " + Num(last_y);
        path += "L" + Num(px) + " " + Num(py);
      }
      last_y = py;
    }
    if (ser.marker_radius > 0.0)
      for (std::size_t i = 0; i < ser.x.size(); ++i) {
        if (!std::isfinite(ser.x[i]) || !std::isfinite(ser.y[i]) || (log_x && ser.x[i] <= 0) || (log_y && ser.y[i] <= 0))
          continue;
        s += "<circle cx=\"" + Num(cx(ser.x[i])) + "\" cy=\"" + Num(cy(ser.y[i])) + "\" r=\"" + Num(ser.marker_radius) +
             "\" fill=\"" + ser.color + "\" fill-opacity=\"0.75\"/>\n";
      }
    if (!ser.line) path.clear();
    if (path.empty() && ser.marker_radius <= 0.0) continue;
    if (!path.empty())
      s += "<path d=\"" + path + "\" fill=\"none\" stroke=\"" + ser.color + "\" stroke-width=\"" + Num(ser.width) +
           "\"" + (ser.dashed ? " stroke-dasharray=\"6 4\"" : "") + "/>\n";
    if (!ser.label.empty()) {
      const double lx = legend_x;
      legend += "<line x1=\"" + Num(lx) + "\" y1=\"" + Num(legend_y) + "\" x2=\"" + Num(lx + 24) + "\" y2=\"" + Num(legend_y) +
           "\" stroke=\"" + ser.color + "\" stroke-width=\"" + Num(std::max(ser.width, 2.0)) + "\"" +
           (ser.dashed ? " stroke-dasharray=\"6 4\"" : "") + "/>\n";
      legend += "<text x=\"" + Num(lx + 30) + "\" y=\"" + Num(legend_y + 4) + "\">" + Escape(ser.label) + "</text>\n";
      legend_y += 16;
    }
  }
  if (!legend.empty())
    s += "<rect x=\"" + Num(legend_x - 6) + "\" y=\"" + Num(legend_y - 16.0 * labelled - 10) + "\" width=\"276\" height=\"" +
         Num(16.0 * labelled + 8) + "\" fill=\"white\" fill-opacity=\"0.85\"/>\n" + legend;
  s += "</svg>\n";
  return s;
}

std::string Plan::ToSvg() const {
  constexpr double kMargin = 16, kTitle = 26, kLegend = 26;
  const double span_x = std::max(max_m.x - min_m.x, 1e-6), span_y = std::max(max_m.y - min_m.y, 1e-6);
  const double scale = (width - 2 * kMargin) / span_x;
  const double height = kTitle + kLegend + 2 * kMargin + span_y * scale;
  const auto P = [&](Vec2 p) {
    return Num(kMargin + (p.x - min_m.x) * scale) + "," + Num(kTitle + kMargin + (max_m.y - p.y) * scale);
  };
  std::string s = Open("plan", width, height, title, kMargin, 18);
  for (const auto& ring : area) {
    std::string pts;
    for (Vec2 p : ring) pts += P(p) + " ";
    s += "<polygon points=\"" + pts + "\" fill=\"#f2f2ee\" stroke=\"none\"/>\n";
  }
  for (const auto& wall : walls) {
    std::string pts;
    for (Vec2 p : wall) pts += P(p) + " ";
    s += "<polyline points=\"" + pts + "\" fill=\"none\" stroke=\"#222\" stroke-width=\"2\"/>\n";
  }
  for (const Dot& d : dots) {
    const std::string at = P(d.at);
    const std::size_t comma = at.find(',');
    s += "<circle cx=\"" + at.substr(0, comma) + "\" cy=\"" + at.substr(comma + 1) + "\" r=\"" +
         Num(std::max(1.2, d.radius_m * scale)) + "\" fill=\"" + d.color + "\" fill-opacity=\"0.85\">";
    if (!d.tip.empty()) s += "<title>" + Escape(d.tip) + "</title>";
    s += "</circle>\n";
  }
  double lx = kMargin;
  const double ly = height - 10;
  for (const auto& [color, label] : legend) {
    s += "<circle cx=\"" + Num(lx + 6) + "\" cy=\"" + Num(ly - 4) + "\" r=\"5\" fill=\"" + color + "\"/>\n";
    s += "<text x=\"" + Num(lx + 16) + "\" y=\"" + Num(ly) + "\">" + Escape(label) + "</text>\n";
    lx += 22 + 7.0 * static_cast<double>(label.size());
  }
  s += "</svg>\n";
  return s;
}

}  // namespace crowdrecon::reports::svg
