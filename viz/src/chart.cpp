#include "crowdrecon/viz/chart.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "ticks.hpp"

namespace crowdrecon::viz {

struct ChartPanel::Item {
  enum class Kind { kLine, kPoints, kBand, kMark } kind;
  std::vector<double> x, y, lo, hi, error;
  Color color;
  double size = 1.0;
  std::string legend;
  bool dashed = false;
};

Color ChartColor(int index) {
  static const unsigned kPalette[] = {0x2166ac, 0xd6604d, 0x1b7837, 0x762a83, 0xe08214, 0x35978f, 0x8c510a, 0x4d4d4d};
  return Color::Hex(kPalette[static_cast<unsigned>(index) % 8]);
}

Color AreaColor(std::size_t index) {
  static const unsigned kPalette[] = {0x8c510a, 0x35978f, 0xe08214, 0x4d4d4d};
  return Color::Hex(kPalette[index % 4]);
}

void ChartPanel::Line(const std::vector<double>& x, const std::vector<double>& y, Color color, double width_px,
                      const std::string& legend, bool dashed) {
  items_.push_back(std::make_shared<Item>(Item{Item::Kind::kLine, x, y, {}, {}, {}, color, width_px, legend, dashed}));
}

void ChartPanel::Points(const std::vector<double>& x, const std::vector<double>& y, Color color, double radius_px,
                        const std::string& legend, const std::vector<double>* error) {
  items_.push_back(std::make_shared<Item>(
      Item{Item::Kind::kPoints, x, y, {}, {}, error ? *error : std::vector<double>{}, color, radius_px, legend, false}));
}

void ChartPanel::Band(const std::vector<double>& x, const std::vector<double>& lo, const std::vector<double>& hi,
                      Color color) {
  items_.push_back(std::make_shared<Item>(Item{Item::Kind::kBand, x, {}, lo, hi, {}, color, 1.0, "", false}));
}

std::vector<int> LabelRows(const std::vector<double>& x_px, const std::vector<std::string>& labels, double size_px,
                           int rows) {
  std::vector<double> end(static_cast<std::size_t>(std::max(rows, 1)), -1e300);
  std::vector<int> out;
  for (std::size_t k = 0; k < x_px.size() && k < labels.size(); ++k) {
    std::size_t row = 0;
    while (row < end.size() && end[row] > x_px[k]) ++row;
    if (row == end.size()) row = static_cast<std::size_t>(std::min_element(end.begin(), end.end()) - end.begin());
    end[row] = x_px[k] + 0.56 * size_px * static_cast<double>(labels[k].size()) + 6.0;
    out.push_back(static_cast<int>(row));
  }
  return out;
}

void ChartPanel::Mark(double x, Color color, const std::string& label, bool dashed) {
  items_.push_back(std::make_shared<Item>(Item{Item::Kind::kMark, {x}, {}, {}, {}, {}, color, 1.4, label, dashed}));
}

ChartSheet::ChartSheet(std::filesystem::path file, double width_px, std::string title, std::string subtitle)
    : file_(std::move(file)), width_(width_px), title_(std::move(title)), subtitle_(std::move(subtitle)) {}

ChartPanel& ChartSheet::AddPanel(std::string x_label, std::string y_label, double x0, double x1, double y0, double y1,
                                 double height_px) {
  auto p = std::make_unique<ChartPanel>();
  p->x_label_ = std::move(x_label);
  p->y_label_ = std::move(y_label);
  p->x0_ = x0;
  p->x1_ = x1 > x0 ? x1 : x0 + 1;
  p->y0_ = y0;
  p->y1_ = y1 > y0 ? y1 : y0 + 1;
  p->height_ = height_px;
  panels_.push_back(std::move(p));
  return *panels_.back();
}

namespace {

constexpr double kLeft = 90, kRight = 40, kTop = 76, kGap = 64;
const Color kInk = Color::Hex(0x222222), kGrid = Color::Hex(0xe3e3e3);

// About five ticks per axis.
double NiceStep(double range) { return detail::NiceStep(range, 5.0); }

std::string Tick(double v, double step) {
  char text[32];
  // As many decimals as the step needs (2.5 -> 1, 0.25 -> 2, 5 -> 0).
  int digits = 0;
  while (digits < 6 && std::abs(step * std::pow(10.0, digits) - std::round(step * std::pow(10.0, digits))) > 1e-6) ++digits;
  std::snprintf(text, sizeof text, "%.*f", std::min(digits, 6), std::abs(v) < step * 1e-6 ? 0.0 : v);
  return text;
}

}  // namespace

void ChartSheet::Finish() {
  double height = kTop;
  for (const auto& p : panels_) height += p->height_ + kGap;
  height += 10;
  // One world unit per pixel, y up: P() turns pixels from the top into world points.
  Canvas canvas(file_, {0, 0}, {width_, height}, 1.0, 0.0);
  const auto P = [&](double x, double y) { return Vec2{x, height - y}; };
  canvas.FillPolygon({P(0, 0), P(width_, 0), P(width_, height), P(0, height)}, Color::White());
  canvas.TextPxAligned(kLeft, 26, title_, 18, 0.0, 0.5, kInk, 0.0, true, width_ - kLeft - 20);
  if (!subtitle_.empty())
    canvas.TextPxAligned(kLeft, 50, subtitle_, 12, 0.0, 0.5, Color::Hex(0x555555), 0.0, false, width_ - kLeft - 20);
  double top = kTop;
  const double right = width_ - kRight;
  for (const auto& panel : panels_) {
    const ChartPanel& p = *panel;
    const double bottom = top + p.height_;
    const auto X = [&](double x) { return kLeft + (x - p.x0_) / (p.x1_ - p.x0_) * (right - kLeft); };
    const auto Y = [&](double y) { return bottom - (std::clamp(y, p.y0_, p.y1_) - p.y0_) / (p.y1_ - p.y0_) * p.height_; };
    const auto inside_x = [&](double x) { return x >= p.x0_ && x <= p.x1_; };
    const double ys = NiceStep(p.y1_ - p.y0_), xs = NiceStep(p.x1_ - p.x0_);
    for (double v = std::ceil(p.y0_ / ys - 1e-9) * ys; v <= p.y1_ + 1e-9 * ys; v += ys) {
      canvas.Line(P(kLeft, Y(v)), P(right, Y(v)), kGrid, 1.0);
      canvas.TextPxAligned(kLeft - 8, Y(v), Tick(v, ys), 12, 1.0, 0.5, kInk);
    }
    for (double v = std::ceil(p.x0_ / xs - 1e-9) * xs; v <= p.x1_ + 1e-9 * xs; v += xs) {
      canvas.Line(P(X(v), top), P(X(v), bottom), kGrid, 1.0);
      canvas.TextPxAligned(X(v), bottom + 6, Tick(v, xs), 12, 0.5, 0.0, kInk);
    }
    canvas.TextPxAligned(0.5 * (kLeft + right), bottom + 24, p.x_label_, 13, 0.5, 0.0, kInk);
    canvas.TextPxAligned(kLeft - 58, 0.5 * (top + bottom), p.y_label_, 13, 0.5, 1.0, kInk, 1.5707963267948966, false,
                         p.height_);
    std::vector<const ChartPanel::Item*> legends;
    for (const auto& item : p.items_) {
      const ChartPanel::Item& it = *item;
      if (!it.legend.empty() && it.kind != ChartPanel::Item::Kind::kMark) legends.push_back(&it);
      switch (it.kind) {
        case ChartPanel::Item::Kind::kLine: {
          std::vector<Vec2> run;
          const auto flush = [&] {
            if (run.size() >= 2) canvas.StrokePolyline(run, it.color, it.size, it.dashed);
            run.clear();
          };
          for (std::size_t i = 0; i < it.x.size() && i < it.y.size(); ++i) {
            if (!std::isfinite(it.y[i]) || !inside_x(it.x[i])) {
              flush();
              continue;
            }
            run.push_back(P(X(it.x[i]), Y(it.y[i])));
          }
          flush();
          break;
        }
        case ChartPanel::Item::Kind::kPoints:
          for (std::size_t i = 0; i < it.x.size() && i < it.y.size(); ++i) {
            if (!std::isfinite(it.y[i]) || !inside_x(it.x[i])) continue;
            if (i < it.error.size() && std::isfinite(it.error[i]))
              canvas.Line(P(X(it.x[i]), Y(it.y[i] - it.error[i])), P(X(it.x[i]), Y(it.y[i] + it.error[i])), it.color,
                          1.0);
            canvas.Dot(P(X(it.x[i]), Y(it.y[i])), it.size, it.color);
          }
          break;
        case ChartPanel::Item::Kind::kBand: {
          std::vector<Vec2> ring;
          for (std::size_t i = 0; i < it.x.size(); ++i)
            if (std::isfinite(it.hi[i]) && inside_x(it.x[i])) ring.push_back(P(X(it.x[i]), Y(it.hi[i])));
          for (std::size_t i = it.x.size(); i-- > 0;)
            if (std::isfinite(it.lo[i]) && inside_x(it.x[i])) ring.push_back(P(X(it.x[i]), Y(it.lo[i])));
          Color c = it.color;
          c.a = 0.18;
          if (ring.size() >= 3) canvas.FillPolygon(ring, c);
          break;
        }
        case ChartPanel::Item::Kind::kMark:
          if (!inside_x(it.x[0])) break;
          canvas.StrokePolyline({P(X(it.x[0]), top), P(X(it.x[0]), bottom)}, it.color, it.size, it.dashed);
          if (!it.legend.empty()) canvas.TextPxAligned(X(it.x[0]) + 3, top + 4, it.legend, 10, 0.0, 0.0, it.color);
          break;
      }
    }
    canvas.StrokePolygon({P(kLeft, top), P(right, top), P(right, bottom), P(kLeft, bottom)}, kInk, 1.0);
    // Legend: top-right inside the panel.
    double ly = top + 14;
    for (const ChartPanel::Item* it : legends) {
      const double lx = right - 250;
      if (it->kind == ChartPanel::Item::Kind::kPoints) canvas.Dot(P(lx + 10, ly), std::max(3.0, it->size), it->color);
      else canvas.StrokePolyline({P(lx, ly), P(lx + 20, ly)}, it->color, std::max(2.0, it->size), it->dashed);
      canvas.TextPxAligned(lx + 28, ly, it->legend, 12, 0.0, 0.5, kInk, 0.0, false, 220);
      ly += 18;
    }
    top = bottom + kGap;
  }
  canvas.Finish();
}

}  // namespace crowdrecon::viz
