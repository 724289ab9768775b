#include "crowdrecon/viz/timeline_figure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/viz/canvas.hpp"
#include "crowdrecon/viz/chart.hpp"
#include "ticks.hpp"

namespace crowdrecon::viz {

namespace {

constexpr double kWidth = 1400, kLeft = 110, kRight = 1180, kTop = 112, kPanel = 150, kGap = 26;
const Color kInk = Color::Hex(0x222222), kGrid = Color::Hex(0xe3e3e3);
const Color kFatal = RecordedMarkStyleOf("fatal").color, kDetected = Color::Hex(0x6a3d9a);
const Color kSeries[] = {Color::Hex(0x2166ac), Color::Hex(0xd6604d), Color::Hex(0x1b7837), Color::Hex(0x762a83)};

// Pixels from the top-left corner on a canvas of one world unit per pixel.
struct Sheet {
  Canvas canvas;
  double height;
  Sheet(const std::filesystem::path& file, double h) : canvas(file, {0, 0}, {kWidth, h}, 1.0, 0.0), height(h) {}
  Vec2 P(double x, double y) const { return {x, height - y}; }
};

struct Panel {
  double top = 0, bottom = 0, lo = 0, hi = 1, t0 = 0, t1 = 1;
  double X(double t) const { return kLeft + (t - t0) / (t1 - t0) * (kRight - kLeft); }
  double Y(double v) const { return bottom - (std::clamp(v, lo, hi) - lo) / (hi - lo) * (bottom - top); }
};

// About four ticks per panel.
double NiceStep(double range) { return detail::NiceStep(range, 4.0); }

std::string Number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, std::abs(v - std::round(v)) < 1e-9 ? "%.0f" : "%.2g", v);
  return text;
}

// A duration in seconds as people read it: whole seconds from 10 s on, one
// decimal below (Number's two significant digits wrote 889.5 s as "8.9e+02").
std::string Seconds(double v) { return FormatFixed(v, std::abs(v) >= 10.0 ? 0 : 1); }

void DrawFrame(Sheet& s, const Panel& p, const std::string& label) {
  const double step = NiceStep(p.hi - p.lo);
  for (double v = std::ceil(p.lo / step) * step; v <= p.hi + 1e-9; v += step) {
    s.canvas.Line(s.P(kLeft, p.Y(v)), s.P(kRight, p.Y(v)), kGrid, 1.0);
    s.canvas.TextPxAligned(kLeft - 8, p.Y(v), Number(v), 12, 1.0, 0.5, kInk);
  }
  s.canvas.StrokePolygon({s.P(kLeft, p.top), s.P(kRight, p.top), s.P(kRight, p.bottom), s.P(kLeft, p.bottom)}, kInk, 1.0);
  s.canvas.TextPxAligned(kLeft - 64, 0.5 * (p.top + p.bottom), label, 12, 0.5, 1.0, kInk, 1.5707963267948966, false,
                         kPanel);
}

// A series as a polyline, broken where it is NaN.
void DrawSeries(Sheet& s, const Panel& p, const std::vector<double>& t, const std::vector<double>& v, Color c,
                double width, bool dashed = false) {
  std::vector<Vec2> run;
  const auto flush = [&] {
    if (run.size() >= 2) s.canvas.StrokePolyline(run, c, width, dashed);
    run.clear();
  };
  // At most ~2 points per pixel column.
  const std::size_t stride = std::max<std::size_t>(1, t.size() / static_cast<std::size_t>(2 * (kRight - kLeft)));
  for (std::size_t i = 0; i < t.size() && i < v.size(); i += stride) {
    if (std::isnan(v[i])) {
      flush();
      continue;
    }
    run.push_back(s.P(p.X(t[i]), p.Y(v[i])));
  }
  flush();
}

double Max(const std::vector<double>& v, double floor_value) {
  double m = floor_value;
  for (double x : v)
    if (!std::isnan(x)) m = std::max(m, x);
  return m;
}

}  // namespace

void DrawTimelineFigure(const analysis::TimelineSeries& ts, const std::string& title, const std::filesystem::path& file) {
  const int panels = 6;
  const double height = kTop + panels * (kPanel + kGap) + 50;
  Sheet s(file, height);
  s.canvas.FillPolygon({s.P(0, 0), s.P(kWidth, 0), s.P(kWidth, height), s.P(0, height)}, Color::White());
  s.canvas.TextPxAligned(kLeft, 28, title, 18, 0.0, 0.5, kInk, 0.0, true, kWidth - kLeft - 20);
  s.canvas.TextPxAligned(kLeft, 54,
                         "lines: centred " + Number(ts.smooth_s) + "-s moving means of the run's frames; " + ts.run_file,
                         12, 0.0, 0.5, Color::Hex(0x555555), 0.0, false, kWidth - kLeft - 20);
  // The run's validity on the figure itself (issue 65): whether its states
  // are ones a human crowd can reach, in one line.
  if (ts.validity.frames > 0) {
    const analysis::Plausibility& v = ts.validity;
    const std::string peak = Number(std::round(v.peak_equivalent_density_per_m2 * 10.0) / 10.0) + " real-size persons/m2";
    std::string line;
    Color colour = Color::Hex(0x555555);
    switch (v.verdict) {
      case analysis::PlausibilityVerdict::kWithin: line = "validity: within the range of human crowds (peak " + peak + ")"; break;
      case analysis::PlausibilityVerdict::kBeyondStatic:
        line = "validity: beyond Fruin's critical density of a static crowd (7.1 /m2) for " +
               Seconds(v.time_beyond_static_s) + " s, peak " + peak + ": within what crushes have reached";
        colour = Color::Hex(0xb35806);
        break;
      case analysis::PlausibilityVerdict::kBeyondMeasured:
        line = "validity: BEYOND what any human crowd has been measured to reach for " +
               Seconds(v.time_beyond_measured_s) + " s (peak " + peak +
               "): read its loads and counts as the model's in that state";
        colour = Color::Hex(0xb2182b);
        break;
    }
    s.canvas.TextPxAligned(kLeft, 73, line, 12, 0.0, 0.5, colour, 0.0, v.verdict != analysis::PlausibilityVerdict::kWithin,
                           kWidth - kLeft - 20);
  }
  const double t0 = ts.time_s.empty() ? 0.0 : ts.time_s.front();
  const double t1 = ts.time_s.empty() ? 1.0 : std::max(ts.time_s.back(), t0 + 1.0);
  const auto smooth = [&](const std::vector<double>& v) { return analysis::MovingMean(ts.time_s, v, ts.smooth_s); };
  std::vector<Panel> p(panels);
  for (int k = 0; k < panels; ++k) {
    p[k].top = kTop + k * (kPanel + kGap);
    p[k].bottom = p[k].top + kPanel;
    p[k].t0 = t0;
    p[k].t1 = t1;
  }
  // 1. density, 2. counter-flow share, 3. speeds, 4. flows, 5. waiting.
  const std::vector<double> density = smooth(ts.density_per_m2), share = smooth(ts.counter_fraction),
                            forward = smooth(ts.flow_forward_per_m_s), backward = smooth(ts.flow_backward_per_m_s),
                            queued = smooth(ts.queued);
  std::vector<std::vector<double>> area_density;  // the measurement areas' (dashed on the density panel)
  for (const auto& a : ts.area_density_per_m2) area_density.push_back(smooth(a));
  p[0].hi = std::ceil(Max(density, 1.0));
  for (const auto& a : area_density) p[0].hi = std::max(p[0].hi, std::ceil(Max(a, 1.0)));
  p[1].hi = 100.0;
  std::vector<std::vector<double>> speeds;
  double v_lo = 0.0, v_hi = 0.5;
  for (const auto& g : ts.group_speed_m_per_s) {
    speeds.push_back(smooth(g));
    for (double v : speeds.back())
      if (!std::isnan(v)) v_lo = std::min(v_lo, v), v_hi = std::max(v_hi, v);
  }
  p[2].lo = std::floor(v_lo * 4.0) / 4.0;
  p[2].hi = std::ceil(v_hi * 4.0) / 4.0;
  p[3].hi = std::max(0.5, std::ceil(std::max(Max(forward, 0.0), Max(backward, 0.0)) * 4.0) / 4.0);
  p[4].hi = std::max(5.0, std::ceil(Max(queued, 0.0) / 5.0) * 5.0);
  DrawFrame(s, p[0], "persons / m^2");
  DrawFrame(s, p[1], "counter-flow, % present");
  DrawFrame(s, p[2], "speed along desired dir., m/s");
  DrawFrame(s, p[3], "flow, persons/(m s)");
  DrawFrame(s, p[4], "waiting at entries");
  double left_max = 10.0;
  for (const auto& left : ts.exit_left) left_max = std::max(left_max, Max(left, 0.0));
  p[5].hi = NiceStep(left_max) * std::ceil(left_max / NiceStep(left_max));
  DrawFrame(s, p[5], "left, by exit (persons)");
  // Marks across every panel: what was recorded of the incident.
  for (const analysis::TimelineMark& m : ts.recorded) {
    if (m.time_s < t0 || m.time_s > t1) continue;
    const RecordedMarkStyle style = RecordedMarkStyleOf(m.kind);
    for (const Panel& q : p)
      s.canvas.StrokePolyline({s.P(q.X(m.time_s), q.top), s.P(q.X(m.time_s), q.bottom)}, style.color, style.width_px,
                              style.dashed);
  }
  std::vector<double> shares(share.size());
  for (std::size_t i = 0; i < share.size(); ++i) shares[i] = 100.0 * share[i];
  DrawSeries(s, p[0], ts.time_s, density, kSeries[0], 2.0);
  for (std::size_t a = 0; a < area_density.size(); ++a)
    DrawSeries(s, p[0], ts.time_s, area_density[a], AreaColor(a), 1.6, true);
  DrawSeries(s, p[1], ts.time_s, shares, kSeries[1], 2.0);
  s.canvas.Line(s.P(kLeft, p[2].Y(0.0)), s.P(kRight, p[2].Y(0.0)), kInk, 0.8);
  for (std::size_t g = 0; g < speeds.size(); ++g) DrawSeries(s, p[2], ts.time_s, speeds[g], kSeries[g % 4], 2.0);
  DrawSeries(s, p[3], ts.time_s, forward, kSeries[0], 2.0);
  DrawSeries(s, p[3], ts.time_s, backward, kSeries[1], 2.0);
  DrawSeries(s, p[4], ts.time_s, queued, kSeries[2], 2.0);
  for (std::size_t x = 0; x < ts.exit_left.size(); ++x) DrawSeries(s, p[5], ts.time_s, ts.exit_left[x], kSeries[(x + 2) % 4], 2.0);
  // What the run recorded: detected avalanches (triangles on the speed
  // panel), falls (crosses on the density panel).
  for (const analysis::TimelineMark& a : ts.avalanches) {
    const double x = p[2].X(a.time_s), y = p[2].top + 8;
    s.canvas.FillPolygon({s.P(x, y + 7), s.P(x - 6, y - 4), s.P(x + 6, y - 4)}, kDetected);
  }
  for (const analysis::TimelineMark& f : ts.falls) {
    const double x = p[0].X(f.time_s), y = p[0].top + 10;
    s.canvas.Line(s.P(x - 5, y - 5), s.P(x + 5, y + 5), kFatal, 2.0);
    s.canvas.Line(s.P(x - 5, y + 5), s.P(x + 5, y - 5), kFatal, 2.0);
  }
  // Time axis under the last panel, and labels of the marks over the first.
  const double span = t1 - t0;
  const double tick = detail::TimeAxisTick(span);
  for (double t = std::ceil(t0 / tick) * tick; t <= t1 + 1e-9; t += tick) {
    for (const Panel& q : p) s.canvas.Line(s.P(q.X(t), q.bottom), s.P(q.X(t), q.bottom + 4), kInk, 1.0);
    const std::string text = ts.clock.TickText(t, tick);
    s.canvas.TextPxAligned(p.back().X(t), p.back().bottom + 8, text, 12, 0.5, 0.0, kInk);
  }
  s.canvas.TextPxAligned(0.5 * (kLeft + kRight), p.back().bottom + 28,
                         ts.clock.AxisLabel(), 13, 0.5, 0.0, kInk);
  // Legend.
  double ly = kTop + 4;
  const double lx = kRight + 16;
  const auto entry = [&](Color c, const std::string& text, bool dashed) {
    s.canvas.StrokePolyline({s.P(lx, ly + 6), s.P(lx + 26, ly + 6)}, c, 2.5, dashed);
    s.canvas.TextPxAligned(lx + 32, ly + 6, text, 12, 0.0, 0.5, kInk, 0.0, false, kWidth - lx - 40);
    ly += 22;
  };
  entry(kSeries[0], "density over the venue", false);
  for (std::size_t a = 0; a < ts.area_names.size(); ++a)
    entry(AreaColor(a), "density in " + ts.area_names[a] + " (" + Number(std::round(ts.area_m2_each[a] * 10.0) / 10.0) + " m2)",
          true);
  ly += 8;
  for (std::size_t g = 0; g < ts.group_names.size() && g < speeds.size(); ++g) entry(kSeries[g % 4], ts.group_names[g], false);
  ly += 8;
  entry(kSeries[0], "flow along group 0's direction", false);
  entry(kSeries[1], "flow against it", false);
  ly += 8;
  for (std::size_t x = 0; x < ts.exit_names.size(); ++x) {
    const double flow = analysis::ExitSpecificFlow(ts, x);
    entry(kSeries[(x + 2) % 4],
          "exit " + ts.exit_names[x] + " (" + Number(ts.exit_width_m[x]) + " m)" +
              (std::isnan(flow) ? "" : ": " + Number(std::round(flow * 100.0) / 100.0) + " /(m s)"),
          false);
  }
  ly += 8;
  for (const std::string& kind : RecordedMarkKinds(ts.recorded, t0, t1)) {
    const RecordedMarkStyle style = RecordedMarkStyleOf(kind);
    entry(style.color, style.legend, style.dashed);
  }
  s.canvas.FillPolygon({s.P(lx + 13, ly + 13), s.P(lx + 7, ly + 2), s.P(lx + 19, ly + 2)}, kDetected);
  s.canvas.TextPxAligned(lx + 32, ly + 6, "avalanche in the run (" + std::to_string(ts.avalanches.size()) + ")", 12, 0.0,
                         0.5, kInk);
  ly += 22;
  s.canvas.Line(s.P(lx + 8, ly + 1), s.P(lx + 18, ly + 11), kFatal, 2.0);
  s.canvas.Line(s.P(lx + 8, ly + 11), s.P(lx + 18, ly + 1), kFatal, 2.0);
  s.canvas.TextPxAligned(lx + 32, ly + 6, "fall in the run (" + std::to_string(ts.falls.size()) + ")", 12, 0.0, 0.5, kInk);
  DrawRecordedMarkLabels(s.canvas, ts.recorded, t0, t1, [&](double t) { return p[0].X(t); }, p[0].top);
  s.canvas.Finish();
}

void DrawRecordedMarkLabels(Canvas& canvas, const std::vector<analysis::TimelineMark>& marks, double t0, double t1,
                            const std::function<double(double)>& x_px, double top_px) {
  std::vector<const analysis::TimelineMark*> shown;
  std::vector<double> at;
  std::vector<std::string> text;
  for (const analysis::TimelineMark& m : marks)
    if (m.time_s >= t0 && m.time_s <= t1) {
      shown.push_back(&m);
      at.push_back(x_px(m.time_s) + 3);
      text.push_back(m.label);
    }
  const std::vector<int> rows = LabelRows(at, text, 10, 3);
  for (std::size_t k = 0; k < shown.size(); ++k)
    canvas.TextPxAligned(at[k], top_px - 4 - 11.0 * rows[k], text[k], 10, 0.0, 1.0,
                         RecordedMarkStyleOf(shown[k]->kind).color);
}

RecordedMarkStyle RecordedMarkStyleOf(const std::string& kind) {
  if (kind == "fatal") return {Color::Hex(0xb2182b), 2.5, false, "recorded fatal event"};
  if (kind == "avalanche") return {Color::Hex(0xe6550d), 1.6, true, "recorded avalanche"};
  return {Color::Hex(0x999999), 1.2, true, "recorded, other"};
}

std::vector<std::string> RecordedMarkKinds(const std::vector<analysis::TimelineMark>& marks, double t0, double t1) {
  std::vector<std::string> kinds;
  for (const char* kind : {"avalanche", "fatal", "other"})
    if (std::any_of(marks.begin(), marks.end(), [&](const analysis::TimelineMark& m) {
          return m.kind == kind && m.time_s >= t0 && m.time_s <= t1;
        }))
      kinds.push_back(kind);
  return kinds;
}

}  // namespace crowdrecon::viz
