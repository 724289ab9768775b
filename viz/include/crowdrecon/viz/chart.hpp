// Chart: x-y panels (lines, points with error bars, vertical marks, legends)
// stacked on one sheet, drawn with Canvas to PNG, SVG or PDF. For the figures
// of observations and fundamental diagrams (issue 22):
//
//   viz::ChartSheet sheet("fd.png", 1000, "Fundamental diagram", "subtitle");
//   viz::ChartPanel& p = sheet.AddPanel("density, 1/m2", "speed, m/s", 0, 6, 0, 2, 420);
//   p.Points(x, y, viz::ChartColor(0), 2.0, "bi_corr_400_b_03");
//   p.Line(x, y, viz::Color::Black(), 2.0, "Weidmann (1993)");
//   sheet.Finish();
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "crowdrecon/viz/canvas.hpp"

namespace crowdrecon::viz {

// A palette of distinguishable colours (index wraps).
Color ChartColor(int index);
// The colour of a venue's measurement area `index` in the timeline figures
// (its own density, dashed: brown, teal, orange, grey, then again).
Color AreaColor(std::size_t index);

// Rows (0, 1, ...) for labels drawn left-aligned from x_px, so that no two
// in one row overlap (a label's width taken as 0.56 of the font size per
// character, plus a gap): each in the first row where it fits, at most
// `rows` rows (where none is free, the row whose last label ends first).
// For the recorded marks' labels over the timeline figures.
std::vector<int> LabelRows(const std::vector<double>& x_px, const std::vector<std::string>& labels, double size_px,
                           int rows);

class ChartPanel {
 public:
  void Line(const std::vector<double>& x, const std::vector<double>& y, Color color, double width_px,
            const std::string& legend = "", bool dashed = false);
  // Points (radius in px); `error` (optional, same size) draws vertical bars.
  void Points(const std::vector<double>& x, const std::vector<double>& y, Color color, double radius_px,
              const std::string& legend = "", const std::vector<double>* error = nullptr);
  // A band between lo and hi along x (filled, translucent).
  void Band(const std::vector<double>& x, const std::vector<double>& lo, const std::vector<double>& hi, Color color);
  // A vertical line at x with a short label at its top.
  void Mark(double x, Color color, const std::string& label = "", bool dashed = true);

 private:
  friend class ChartSheet;
  struct Item;
  std::string x_label_, y_label_;
  double x0_ = 0, x1_ = 1, y0_ = 0, y1_ = 1, height_ = 300;
  std::vector<std::shared_ptr<Item>> items_;
};

class ChartSheet {
 public:
  ChartSheet(std::filesystem::path file, double width_px, std::string title, std::string subtitle = "");
  ChartPanel& AddPanel(std::string x_label, std::string y_label, double x0, double x1, double y0, double y1,
                       double height_px = 300);
  // Draws every panel and writes the file (InputError if it cannot).
  void Finish();

 private:
  std::filesystem::path file_;
  double width_;
  std::string title_, subtitle_;
  std::vector<std::unique_ptr<ChartPanel>> panels_;
};

}  // namespace crowdrecon::viz
