#include "crowdrecon/viz/canvas.hpp"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>

#include <cmath>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/remove_on_interrupt.hpp"

namespace crowdrecon::viz {

namespace {
enum class Format { kPng, kSvg, kPdf };

Format FormatOf(const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".png") return Format::kPng;
  if (ext == ".svg") return Format::kSvg;
  if (ext == ".pdf") return Format::kPdf;
  throw InputError(file.string() + ": " + PictureFormatProblem(file));
}
}  // namespace

std::string PictureFormatProblem(const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".png" || ext == ".svg" || ext == ".pdf") return "";
  return "unknown picture format \"" + ext + "\"; expected .png, .svg or .pdf";
}

struct Canvas::Impl {
  std::filesystem::path file;
  // Every picture is drawn into a hidden partial file beside `file` and
  // renamed over it when complete: a kill or a full disk never leaves a
  // truncated picture under the final name, nor empties the previous one.
  std::filesystem::path partial;
  std::unique_ptr<RemoveOnInterrupt> remove_on_interrupt;  // the partial file goes on Ctrl-C
  bool written = false;
  Format format = Format::kPng;
  Vec2 world_min, world_max;
  double scale = 1.0;  // pixels per metre
  double margin = 0.0;
  double width = 0.0, height = 0.0;
  cairo_surface_t* surface = nullptr;
  cairo_t* cr = nullptr;
  bool finished = false;

  double X(double x) const { return margin + (x - world_min.x) * scale; }
  double Y(double y) const { return margin + (world_max.y - y) * scale; }
  void MoveTo(Vec2 p) const { cairo_move_to(cr, X(p.x), Y(p.y)); }
  void LineTo(Vec2 p) const { cairo_line_to(cr, X(p.x), Y(p.y)); }
  void SetColor(Color c) const { cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a); }
  void Ring(const std::vector<Vec2>& ring) const {
    if (ring.empty()) return;
    MoveTo(ring.front());
    for (std::size_t i = 1; i < ring.size(); ++i) LineTo(ring[i]);
    cairo_close_path(cr);
  }
};

Canvas::Canvas(const std::filesystem::path& file, Vec2 world_min, Vec2 world_max,
               double pixels_per_metre, double margin_px)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.file = file;
  m.partial = PartialPath(file);
  m.remove_on_interrupt = std::make_unique<RemoveOnInterrupt>(m.partial);
  m.format = FormatOf(file);
  m.world_min = world_min;
  m.world_max = world_max;
  m.scale = pixels_per_metre;
  m.margin = margin_px;
  m.width = std::ceil((world_max.x - world_min.x) * pixels_per_metre + 2 * margin_px);
  m.height = std::ceil((world_max.y - world_min.y) * pixels_per_metre + 2 * margin_px);
  if (!(m.width > 0 && m.height > 0 && m.width < 20000 && m.height < 20000))
    throw InputError(file.string() + ": picture size " + FormatNumber(m.width) + " x " +
                     FormatNumber(m.height) + " px is out of range (1..20000)");
  switch (m.format) {
    case Format::kPng:
      m.surface = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, static_cast<int>(m.width),
                                             static_cast<int>(m.height));
      break;
    case Format::kSvg:
      m.surface = cairo_svg_surface_create(m.partial.c_str(), m.width, m.height);
      break;
    case Format::kPdf:
      m.surface = cairo_pdf_surface_create(m.partial.c_str(), m.width, m.height);
      break;
  }
  if (cairo_surface_status(m.surface) != CAIRO_STATUS_SUCCESS)
    throw InputError(file.string() + ": cannot create picture: " +
                     cairo_status_to_string(cairo_surface_status(m.surface)));
  m.cr = cairo_create(m.surface);
  cairo_set_line_join(m.cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(m.cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_source_rgb(m.cr, 1, 1, 1);
  cairo_paint(m.cr);
}

Canvas::~Canvas() {
  if (impl_->cr) cairo_destroy(impl_->cr);
  if (impl_->surface) cairo_surface_destroy(impl_->surface);
  if (!impl_->written) {
    std::error_code ignored;
    std::filesystem::remove(impl_->partial, ignored);
  }
}

void Canvas::ClipToWorld() {
  const Impl& m = *impl_;
  cairo_reset_clip(m.cr);
  cairo_new_path(m.cr);
  cairo_rectangle(m.cr, m.X(m.world_min.x), m.Y(m.world_max.y), (m.world_max.x - m.world_min.x) * m.scale,
                  (m.world_max.y - m.world_min.y) * m.scale);
  cairo_clip(m.cr);
}

void Canvas::ResetClip() { cairo_reset_clip(impl_->cr); }

double Canvas::width_px() const { return impl_->width; }
double Canvas::height_px() const { return impl_->height; }

void Canvas::FillPolygon(const std::vector<Vec2>& ring, Color fill) {
  impl_->Ring(ring);
  impl_->SetColor(fill);
  cairo_fill(impl_->cr);
}

void Canvas::FillRings(const std::vector<std::vector<Vec2>>& rings, Color fill) {
  cairo_set_fill_rule(impl_->cr, CAIRO_FILL_RULE_EVEN_ODD);
  for (const auto& ring : rings) impl_->Ring(ring);
  impl_->SetColor(fill);
  cairo_fill(impl_->cr);
  cairo_set_fill_rule(impl_->cr, CAIRO_FILL_RULE_WINDING);
}

void Canvas::StrokePolygon(const std::vector<Vec2>& ring, Color stroke, double width_px) {
  impl_->Ring(ring);
  impl_->SetColor(stroke);
  cairo_set_line_width(impl_->cr, width_px);
  cairo_stroke(impl_->cr);
}

void Canvas::StrokePolyline(const std::vector<Vec2>& points, Color stroke, double width_px,
                            bool dashed) {
  if (points.size() < 2) return;
  impl_->MoveTo(points.front());
  for (std::size_t i = 1; i < points.size(); ++i) impl_->LineTo(points[i]);
  impl_->SetColor(stroke);
  cairo_set_line_width(impl_->cr, width_px);
  if (dashed) {
    const double dashes[] = {3.0 * width_px, 2.0 * width_px};
    cairo_set_dash(impl_->cr, dashes, 2, 0);
  }
  cairo_stroke(impl_->cr);
  cairo_set_dash(impl_->cr, nullptr, 0, 0);
}

void Canvas::Line(Vec2 a, Vec2 b, Color stroke, double width_px) {
  StrokePolyline({a, b}, stroke, width_px);
}

void Canvas::Circle(Vec2 centre, double radius_m, Color fill, Color stroke, double width_px) {
  cairo_t* cr = impl_->cr;
  cairo_new_path(cr);
  cairo_arc(cr, impl_->X(centre.x), impl_->Y(centre.y), radius_m * impl_->scale, 0, 2 * M_PI);
  impl_->SetColor(fill);
  cairo_fill_preserve(cr);
  impl_->SetColor(stroke);
  cairo_set_line_width(cr, width_px);
  cairo_stroke(cr);
}

void Canvas::Dot(Vec2 centre, double radius_px, Color fill) {
  cairo_t* cr = impl_->cr;
  cairo_new_path(cr);
  cairo_arc(cr, impl_->X(centre.x), impl_->Y(centre.y), radius_px, 0, 2 * M_PI);
  impl_->SetColor(fill);
  cairo_fill(cr);
}

void Canvas::Arrow(Vec2 from, Vec2 to, Color stroke, double width_px) {
  Line(from, to, stroke, width_px);
  const double dx = impl_->X(to.x) - impl_->X(from.x), dy = impl_->Y(to.y) - impl_->Y(from.y);
  const double len = std::hypot(dx, dy);
  if (len <= 0) return;
  const double ux = dx / len, uy = dy / len, head = 4.0 * width_px + 4.0;
  cairo_t* cr = impl_->cr;
  const double tx = impl_->X(to.x), ty = impl_->Y(to.y);
  cairo_move_to(cr, tx, ty);
  cairo_line_to(cr, tx - head * ux + 0.5 * head * uy, ty - head * uy - 0.5 * head * ux);
  cairo_line_to(cr, tx - head * ux - 0.5 * head * uy, ty - head * uy + 0.5 * head * ux);
  cairo_close_path(cr);
  impl_->SetColor(stroke);
  cairo_fill(cr);
}

void Canvas::Text(Vec2 at, const std::string& text, double size_px, Color color) {
  TextPx(impl_->X(at.x), impl_->Y(at.y), text, size_px, color);
}

void Canvas::TextPx(double x_px, double y_px, const std::string& text, double size_px,
                    Color color) {
  cairo_t* cr = impl_->cr;
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size_px);
  impl_->SetColor(color);
  cairo_move_to(cr, x_px, y_px);
  cairo_show_text(cr, text.c_str());
  cairo_new_path(cr);
}

void Canvas::TextPxAligned(double x_px, double y_px, const std::string& text, double size_px, double align_x,
                           double align_y, Color color, double angle_rad, bool bold, double max_width_px) {
  cairo_t* cr = impl_->cr;
  cairo_save(cr);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size_px);
  cairo_text_extents_t e;
  cairo_text_extents(cr, text.c_str(), &e);
  if (max_width_px > 0.0 && e.x_advance > max_width_px) {
    cairo_set_font_size(cr, size_px * max_width_px / e.x_advance);
    cairo_text_extents(cr, text.c_str(), &e);
  }
  cairo_translate(cr, x_px, y_px);
  cairo_rotate(cr, -angle_rad);  // device y points down: counter-clockwise on the page
  impl_->SetColor(color);
  cairo_move_to(cr, -(e.x_bearing + e.width * align_x), -(e.y_bearing + e.height * align_y));
  cairo_show_text(cr, text.c_str());
  cairo_new_path(cr);
  cairo_restore(cr);
}

void Canvas::ScaleBar(double length_m) {
  const double x0 = impl_->margin, y0 = impl_->height - impl_->margin * 0.35;
  cairo_t* cr = impl_->cr;
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 2.0);
  cairo_move_to(cr, x0, y0);
  cairo_line_to(cr, x0 + length_m * impl_->scale, y0);
  cairo_stroke(cr);
  TextPx(x0 + length_m * impl_->scale + 6, y0 + 4, FormatNumber(length_m) + " m", 12);
}

namespace {
// Cairo's reason, with the likely cause of a failed write.
std::string Why(cairo_status_t status) {
  return std::string(cairo_status_to_string(status)) +
         (status == CAIRO_STATUS_WRITE_ERROR ? " (disk full, or no permission to write there?)" : "");
}
}  // namespace

void Canvas::Finish() {
  Impl& m = *impl_;
  if (m.finished) return;
  m.finished = true;
  cairo_show_page(m.cr);
  cairo_surface_flush(m.surface);
  if (m.format == Format::kPng) {
    const cairo_status_t status = cairo_surface_write_to_png(m.surface, m.partial.c_str());
    if (status != CAIRO_STATUS_SUCCESS) throw InputError(m.file.string() + ": cannot write picture: " + Why(status));
  }
  cairo_surface_finish(m.surface);
  if (cairo_surface_status(m.surface) != CAIRO_STATUS_SUCCESS)
    throw InputError(m.file.string() + ": cannot write picture: " + Why(cairo_surface_status(m.surface)));
  std::error_code ec;
  std::filesystem::rename(m.partial, m.file, ec);
  if (ec) throw InputError(m.file.string() + ": cannot write picture: " + ec.message());
  m.written = true;
}

}  // namespace crowdrecon::viz
