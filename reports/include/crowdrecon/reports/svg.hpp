// Small SVG figures for the report, written as text to inline in its HTML
// (no external files): line charts with log or linear axes and shaded bands,
// and plan maps in metres. Used by the reports and the validation report.
#pragma once

#include <string>
#include <vector>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::reports::svg {

std::string Escape(const std::string& text);
// A number with few digits, for ticks and tables.
std::string Short(double v, int digits = 3);
// The opening of a figure: <svg> of that size and class, a white ground and
// the title in bold at (title_x, title_y).
std::string Open(const std::string& css_class, double width, double height, const std::string& title, double title_x,
                 double title_y);

struct Series {
  std::vector<double> x, y;
  std::string color = "#1f4e79";
  double width = 1.8;
  bool dashed = false;
  bool step = false;  // a staircase (CDFs, counts per frame)
  std::string label;  // legend entry ("" = none)
  double marker_radius = 0.0;  // > 0: a dot of this radius (px) at every point
  bool line = true;            // false: the dots alone (a scatter)
};

struct Band {
  double from = 0.0, to = 0.0;  // along x
  std::string color;            // fill, drawn light
  std::string label;
};

struct Chart {
  std::string title;
  std::string x_label, y_label;
  double width = 760, height = 360;
  bool log_x = false, log_y = false;
  // Axis ranges; min >= max: from the data.
  double x_min = 0, x_max = 0, y_min = 0, y_max = 0;
  std::vector<Band> bands;
  std::vector<Series> series;
  std::vector<std::pair<double, std::string>> x_marks;  // vertical lines with a label
  bool legend_left = false, legend_bottom = false;  // where the legend goes (default: top right)
  std::string ToSvg() const;
};

// A plan: walls, the walkable area and dots, in metres (y up).
struct Plan {
  std::string title;
  double width = 760;
  Vec2 min_m, max_m;
  std::vector<std::vector<Vec2>> area;   // walkable rings (light fill)
  std::vector<std::vector<Vec2>> walls;  // polylines
  struct Dot {
    Vec2 at;
    std::string color;
    double radius_m = 0.2;
    std::string tip;  // hover text
  };
  std::vector<Dot> dots;
  std::vector<std::pair<std::string, std::string>> legend;  // color, label
  std::string ToSvg() const;
};

}  // namespace crowdrecon::reports::svg
