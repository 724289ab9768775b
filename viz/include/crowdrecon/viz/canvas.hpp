// Canvas: draws plane figures in world coordinates (metres, y up) to a PNG, SVG
// or PDF file chosen by the file's extension. A thin layer over Cairo, kept out
// of every other module's headers.
//
//   viz::Canvas canvas("venue.png", {0, 0}, {12, 3}, /*pixels_per_metre=*/80);
//   canvas.FillPolygon(area, viz::Color::Hex(0xeeeeee));
//   canvas.StrokePolyline(wall, viz::Color::Black(), 2.0);
//   canvas.Finish();   // writes the file; throws InputError if it cannot
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::viz {

struct Color {
  double r = 0, g = 0, b = 0, a = 1;
  static Color Hex(unsigned rgb, double alpha = 1.0) {
    return {((rgb >> 16) & 0xff) / 255.0, ((rgb >> 8) & 0xff) / 255.0, (rgb & 0xff) / 255.0, alpha};
  }
  static Color Black() { return {0, 0, 0, 1}; }
  static Color White() { return {1, 1, 1, 1}; }
};

// "" if a Canvas can write `file` (by its extension: .png, .svg, .pdf), else
// what is wrong with it, for a message.
std::string PictureFormatProblem(const std::filesystem::path& file);

class Canvas {
 public:
  // World window [min, max] drawn at `pixels_per_metre`, with `margin_px` around.
  // Format from extension: .png, .svg or .pdf.
  Canvas(const std::filesystem::path& file, Vec2 world_min, Vec2 world_max,
         double pixels_per_metre, double margin_px = 40.0);
  ~Canvas();
  Canvas(const Canvas&) = delete;
  Canvas& operator=(const Canvas&) = delete;

  // Line widths are in pixels (device units), sizes of text in pixels.
  void FillPolygon(const std::vector<Vec2>& ring, Color fill);
  // Even-odd fill of several rings (a polygon with holes).
  void FillRings(const std::vector<std::vector<Vec2>>& rings, Color fill);
  void StrokePolygon(const std::vector<Vec2>& ring, Color stroke, double width_px);
  void StrokePolyline(const std::vector<Vec2>& points, Color stroke, double width_px,
                      bool dashed = false);
  void Line(Vec2 a, Vec2 b, Color stroke, double width_px);
  void Circle(Vec2 centre, double radius_m, Color fill, Color stroke, double width_px);
  void Dot(Vec2 centre, double radius_px, Color fill);
  void Arrow(Vec2 from, Vec2 to, Color stroke, double width_px);
  // Text anchored at a world point (left-baseline), size in pixels.
  void Text(Vec2 at, const std::string& text, double size_px, Color color = Color::Black());
  // Text at a device position (pixels from the top-left corner).
  void TextPx(double x_px, double y_px, const std::string& text, double size_px,
              Color color = Color::Black());
  // Text at a device position, anchored by fractions of its drawn extent:
  // align_x 0 = left edge at x_px, 0.5 = centred, 1 = right edge; align_y
  // 0 = top at y_px, 0.5 = centred, 1 = bottom. Turned counter-clockwise by
  // angle_rad about the anchor (pi/2: reads bottom to top, for y-axis labels).
  // max_width_px > 0: the font shrinks so that the text fits that width.
  void TextPxAligned(double x_px, double y_px, const std::string& text, double size_px, double align_x,
                     double align_y, Color color = Color::Black(), double angle_rad = 0.0, bool bold = false,
                     double max_width_px = 0.0);
  // Drawing from here on is clipped to the world window (the picture less its
  // margins), so that what lies outside a cropped window stays out of the
  // margins' legend; ResetClip() draws everywhere again.
  void ClipToWorld();
  void ResetClip();
  // A scale bar of `length_m` at the lower-left corner.
  void ScaleBar(double length_m);

  double width_px() const;
  double height_px() const;
  // Writes the file. Throws InputError naming the file if it cannot be written.
  void Finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crowdrecon::viz
