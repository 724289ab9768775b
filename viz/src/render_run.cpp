// Rendering a run (render_run.hpp): the scene, the layout, the drawing of
// each frame, the video. The options are render_options.cpp.
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/remove_on_interrupt.hpp"
#include "crowdrecon/viz/render_run.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <regex>
#include <system_error>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/viz/canvas.hpp"
#include "crowdrecon/media/media.hpp"

namespace crowdrecon::viz {

namespace {

// --- the scene: what does not change from frame to frame ---------------------

struct ShapeInfo {
  std::vector<Vec2> vertices;  // body frame, chest toward +x
  double radius_m = 0.0;
  double reach_m = 0.0;  // farthest point of the swept shape from the centroid
  double front_m = 0.0;  // farthest point along +x (the chest)
};

struct WallPiece {
  Vec2 a, b;
  double radius_m = 0.0;
};

struct Scene {
  std::vector<std::vector<Vec2>> floor_rings;  // outer rings and holes, filled even-odd
  std::vector<WallPiece> walls;  // wall segments as drawn (see ClipToPeriodicBox)
  std::vector<ShapeInfo> shapes;
  std::vector<std::uint32_t> person_shape;  // by engine index (id - 1)
  std::vector<std::uint32_t> person_group;
  std::optional<PeriodicBox> periodic;
  std::string floor_note;  // why the walkable area is not drawn, if it is not
  // When each person fell (event `fall`; NaN: never): from then on they are
  // drawn as lying obstacles (grey, a cross).
  std::vector<double> fell_at_s;

  bool FallenAt(std::size_t person, double t_s) const {
    return person < fell_at_s.size() && fell_at_s[person] <= t_s + 1e-9;
  }

  const ShapeInfo& ShapeOf(std::size_t person) const {
    const std::uint32_t s = person < person_shape.size() ? person_shape[person] : 0;
    return shapes[s < shapes.size() ? s : 0];
  }
  std::uint32_t GroupOf(std::size_t person) const {
    return person < person_group.size() ? person_group[person] : 0;
  }
  // Minimum-image form of a difference under the periodic box (identity without one).
  Vec2 MinimumImage(Vec2 d) const { return periodic ? periodic->MinimumImage(d) : d; }
};

// Clips the segment [a, b] to the periodic box widened by `margin_m` along its
// periodic axes (Liang-Barsky); false if nothing is left.
bool ClipToPeriodicBox(const PeriodicBox& box, double margin_m, Vec2* a, Vec2* b) {
  double t0 = 0.0, t1 = 1.0;
  const Vec2 d = *b - *a;
  const auto clip = [&](double p, double q) {  // keeps the part where p t <= q
    if (p == 0.0) return q >= 0.0;
    const double t = q / p;
    if (p < 0.0) t0 = std::max(t0, t); else t1 = std::min(t1, t);
    return t0 <= t1;
  };
  if (box.x && !(clip(-d.x, a->x - (box.min_m.x - margin_m)) && clip(d.x, box.max_m.x + margin_m - a->x)))
    return false;
  if (box.y && !(clip(-d.y, a->y - (box.min_m.y - margin_m)) && clip(d.y, box.max_m.y + margin_m - a->y)))
    return false;
  const Vec2 start = *a + d * t0, end = *a + d * t1;
  *a = start;
  *b = end;
  return true;
}

Scene LoadScene(const runfile::RunFileReader& run, const std::string& file) {
  Scene scene;
  for (const runfile::Shape& s : run.Shapes()) {
    ShapeInfo info;
    info.vertices = s.vertices;
    info.radius_m = s.radius_m;
    info.front_m = -std::numeric_limits<double>::infinity();
    for (Vec2 v : s.vertices) {
      info.reach_m = std::max(info.reach_m, Length(v) + s.radius_m);
      info.front_m = std::max(info.front_m, v.x + s.radius_m);
    }
    if (s.vertices.empty()) throw InputError(file + ": run file has a body shape without vertices");
    scene.shapes.push_back(std::move(info));
  }
  if (scene.shapes.empty()) throw InputError(file + ": run file has no body shapes (table shape is empty)");
  scene.person_shape = run.PersonShapes();
  scene.person_group = run.PersonGroups();
  for (const runfile::Event& e : run.Events()) {
    if (e.kind != "fall" || e.person < 0) continue;
    const auto person = static_cast<std::size_t>(e.person);
    if (person >= scene.fell_at_s.size()) scene.fell_at_s.resize(person + 1, std::numeric_limits<double>::quiet_NaN());
    if (!(scene.fell_at_s[person] <= e.time_s)) scene.fell_at_s[person] = e.time_s;
  }
  // Run files need not record a periodic box: without one, seams are handled
  // by leaving out contact lines that would span the box (see DrawForceNetwork).
  if (const PeriodicBox box = run.periodic_box(); box.any()) scene.periodic = box;
  // The engine extends walls that cross a periodic seam beyond it (so that a
  // body straddling the seam meets a straight wall) and the run stores them so;
  // drawn, they are cut back to the box and the bodies' images across the seam.
  double max_reach_m = 0.0;
  for (const ShapeInfo& shape : scene.shapes) max_reach_m = std::max(max_reach_m, shape.reach_m);
  for (const runfile::Wall& w : run.Walls()) {
    const std::size_t n = w.points.size();
    for (std::size_t k = 0; k + 1 < n + (w.closed ? 1 : 0); ++k) {
      WallPiece piece{w.points[k], w.points[(k + 1) % n], w.radius_m};
      if (scene.periodic && !ClipToPeriodicBox(*scene.periodic, max_reach_m, &piece.a, &piece.b)) continue;
      scene.walls.push_back(piece);
    }
  }

  // The walkable area as drawn by PedPy: outer rings with the obstacles as holes.
  // A WKT the venue importer refuses only costs the floor, not the picture.
  const std::string wkt = run.walkable_wkt();
  if (!wkt.empty()) {
    try {
      const geometry::Venue area = geometry::ParseWkt(wkt, file + " (geometry)");
      scene.floor_rings = area.walkable_area;
      for (const geometry::Obstacle& o : area.obstacles) scene.floor_rings.push_back(o.polygon);
    } catch (const InputError& e) {
      scene.floor_note = std::string("walkable area not drawn: ") + e.what();
    }
  }
  return scene;
}

// --- layout: world window and pixel scale, the same for every frame -----------

// Canvas margin: holds the legend (top) and the scales (bottom).
constexpr double kMargin_px = 52.0;
// Width of the thickest force line when the scale is chosen automatically (m):
// a quarter of a chest depth, thick enough to rank forces by eye, thin enough
// not to hide two bodies pressed chest to chest (centroids ~0.3 m apart).
constexpr double kAutoMaxLineWidth_m = 0.06;

struct Layout {
  Vec2 lo, hi;        // world window (m)
  double ppm = 1.0;   // pixels per metre
  int width_px = 0, height_px = 0;
  bool cropped = false;  // RenderOptions::has_window: drawing is clipped to the window
  bool marked = false;   // RenderOptions::has_mark: the rectangle drawn over the picture
  Vec2 mark_lo, mark_hi;

  // World point at a device position (pixels from the top-left corner).
  Vec2 World(double x_px, double y_px) const {
    return {lo.x + (x_px - kMargin_px) / ppm, hi.y - (y_px - kMargin_px) / ppm};
  }
};

// A round force (1, 2 or 5 times a power of ten) not above `force_n`.
double NiceFloor(double force_n) {
  const double power = std::pow(10.0, std::floor(std::log10(force_n)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * power <= force_n * (1.0 + 1e-9)) return m * power;
  return power;
}

// A round length near a fifth of `extent_m`, for the scale bar.
double NiceLength(double extent_m) { return NiceFloor(extent_m / 5.0); }

// --- drawing ------------------------------------------------------------------

// Group colours: group 0 (toward the exit) blue, group 1 (counter-flow)
// orange, more groups from a qualitative palette (Tableau 10).
Color GroupColor(std::uint32_t group) {
  static const unsigned kPalette[] = {0x4e79a7, 0xf28e2b, 0x59a14f, 0xb07aa1, 0xe15759, 0x76b7b2, 0xedc948};
  return Color::Hex(kPalette[group % (sizeof kPalette / sizeof kPalette[0])]);
}
Color Lighter(Color c, double toward_white) {
  return {c.r + (1 - c.r) * toward_white, c.g + (1 - c.g) * toward_white, c.b + (1 - c.b) * toward_white, c.a};
}
Color Darker(Color c, double factor) { return {c.r * factor, c.g * factor, c.b * factor, c.a}; }

const Color kFloor = Color::Hex(0xeeebe4);
const Color kWall = Color::Hex(0x303030);
const Color kForce = Color{0.55, 0.05, 0.05, 0.85};
const Color kText = Color::Hex(0x202020);
const Color kSubtleText = Color::Hex(0x505050);
const Color kFallenBody = Color::Hex(0x3a3a3a);

// Offsets of the periodic images of a body at `p` that reach into the box:
// {0} plus one per seam the body straddles (and the corner image).
std::vector<Vec2> ImageOffsets(const Scene& scene, Vec2 p, double reach_m) {
  std::vector<Vec2> offsets{{0.0, 0.0}};
  if (!scene.periodic) return offsets;
  const PeriodicBox& box = *scene.periodic;
  std::vector<double> dx{0.0}, dy{0.0};
  if (box.x) {
    const double l = box.max_m.x - box.min_m.x;
    if (p.x - reach_m < box.min_m.x) dx.push_back(l);
    if (p.x + reach_m > box.max_m.x) dx.push_back(-l);
  }
  if (box.y) {
    const double l = box.max_m.y - box.min_m.y;
    if (p.y - reach_m < box.min_m.y) dy.push_back(l);
    if (p.y + reach_m > box.max_m.y) dy.push_back(-l);
  }
  for (double x : dx)
    for (double y : dy)
      if (x != 0.0 || y != 0.0) offsets.push_back({x, y});
  return offsets;
}

// One body: the swept outline (core polygon dilated by the sphero-radius) is
// drawn as the core polygon stroked 2r wide with round joins, on top of a
// slightly wider stroke in a darker colour that becomes its outline; then a
// triangle on the chest shows where the person faces.
void DrawBody(Canvas& canvas, const Layout& layout, const ShapeInfo& shape, Vec2 position, Vec2 facing,
              Color color) {
  const double angle = std::atan2(facing.y, facing.x);
  const Color fill = Lighter(color, 0.45), outline = Darker(color, 0.6);
  const double outline_px = std::clamp(0.012 * layout.ppm, 0.8, 2.0);
  if (shape.vertices.size() == 1) {  // a disk: Cairo draws nothing for a closed one-point path
    canvas.Circle(position + Rotated(shape.vertices[0], angle), shape.radius_m, fill, outline, outline_px);
  } else {
    std::vector<Vec2> core;
    core.reserve(shape.vertices.size());
    for (Vec2 v : shape.vertices) core.push_back(position + Rotated(v, angle));
    const double sweep_px = 2.0 * shape.radius_m * layout.ppm;
    canvas.StrokePolygon(core, outline, sweep_px + 2.0 * outline_px);
    canvas.FillPolygon(core, fill);
    canvas.StrokePolygon(core, fill, sweep_px);
  }
  // Chest mark: a triangle just inside the front of the body, sized to it.
  const Vec2 ahead = Rotated(Vec2{1.0, 0.0}, angle), side = Perp(ahead);
  const Vec2 tip = position + ahead * (0.9 * shape.front_m);
  const Vec2 base = position + ahead * (0.9 * shape.front_m - 0.4 * shape.front_m);
  const double half_width_m = 0.22 * shape.front_m;
  canvas.FillPolygon({tip, base + side * half_width_m, base - side * half_width_m}, outline);
}

// A fallen person (an obstacle lying on the floor): a cross over the body,
// as wide as its front.
void DrawFallenCross(Canvas& canvas, Vec2 position, const ShapeInfo& shape) {
  const double h = 0.7 * shape.front_m;
  const Color ink = Color::Hex(0x101010);
  canvas.Line(position + Vec2{-h, -h}, position + Vec2{h, h}, ink, 1.5);
  canvas.Line(position + Vec2{-h, h}, position + Vec2{h, -h}, ink, 1.5);
}

// A force line: a band of `width_px` from a to b with square ends (a stroked
// line would get Canvas's round caps, which pile up into blobs at a centroid
// with several contacts).
void ForceLine(Canvas& canvas, const Layout& layout, Vec2 a, Vec2 b, double width_px) {
  const double length = Length(b - a);
  if (length <= 0.0) return;
  const Vec2 half = Perp(b - a) * (0.5 * width_px / layout.ppm / length);
  canvas.FillPolygon({a + half, b + half, b - half, a - half}, kForce);
}

struct FrameStats {
  std::size_t contacts = 0, wall_contacts = 0;
  double max_force_n = 0.0;
  std::size_t branches_left_out = 0;
};

// Figure 6's contact network: for each contact, a line from the centroid of
// each person in it to the contact point, as wide as the force is strong
// (|F| = |fn n + ft Perp(n)|, the force on a; b feels the opposite).
// The contact point lies in a's periodic image, so across a seam it may be
// far from b's stored (wrapped) position: with a known periodic box the branch
// is unwrapped to the nearest image and drawn at both sides of the seam;
// without one, a branch longer than the body could reach is left out.
void DrawForceNetwork(Canvas& canvas, const Layout& layout, const Scene& scene, const runfile::RunFrame& frame,
                      const std::vector<std::int64_t>& slot_of_person, double force_n_per_px,
                      FrameStats* stats) {
  const auto branch = [&](std::size_t person, Vec2 point, double width_px) {
    const std::int64_t slot = person < slot_of_person.size() ? slot_of_person[person] : -1;
    if (slot < 0) {  // person not in this frame (removed): nothing to attach to
      ++stats->branches_left_out;
      return;
    }
    const Vec2 centre = frame.position_m[static_cast<std::size_t>(slot)];
    const Vec2 d = scene.MinimumImage(point - centre);
    // 1.5 x the reach: contact points lie on the swept surface, overlapped a little.
    if (Length(d) > 1.5 * scene.ShapeOf(person).reach_m) {
      ++stats->branches_left_out;
      return;
    }
    // Drawn from every image of the body that is drawn, and from the image
    // next to the point (which lies in a's image, maybe across the seam from
    // this body's stored position).
    std::vector<Vec2> offsets = ImageOffsets(scene, centre, scene.ShapeOf(person).reach_m);
    const Vec2 to_point_image = point - d - centre;
    if (std::none_of(offsets.begin(), offsets.end(), [&](Vec2 o) { return Length(o - to_point_image) < 1e-6; }))
      offsets.push_back(to_point_image);
    for (Vec2 o : offsets) ForceLine(canvas, layout, centre + o, centre + o + d, width_px);
  };
  for (const runfile::Contact& c : frame.contacts) {
    const double force_n = Length(c.Force());
    stats->max_force_n = std::max(stats->max_force_n, force_n);
    ++stats->contacts;
    if (c.wall) ++stats->wall_contacts;
    const double width_px = std::max(force_n / force_n_per_px, kMinForceLineWidth_px);
    branch(c.a, c.point_m, width_px);
    if (!c.wall) branch(c.b, c.point_m, width_px);
  }
}

struct FrameLegend {
  std::int64_t frame = 0;
  double time_s = 0.0;
  std::size_t people = 0;
  std::size_t fallen = 0;
  std::vector<std::uint32_t> groups_present;
};

void DrawLegend(Canvas& canvas, const Layout& layout, const FrameLegend& legend, const FrameStats& stats,
                double force_n_per_px, double max_force_all_n) {
  const double w = canvas.width_px(), h = canvas.height_px();
  const std::string line1 = "t = " + FormatFixed(legend.time_s, 2) + " s    frame " + std::to_string(legend.frame) +
                            "    people " + std::to_string(legend.people) + "    contacts " +
                            std::to_string(stats.contacts) + " (" + std::to_string(stats.wall_contacts) +
                            " with walls)    max contact force " + FormatFixed(stats.max_force_n, 0) + " N";
  // Both lines shrink to the picture's width rather than run off its edge (a
  // narrow picture, a tall window).
  canvas.TextPxAligned(kMargin_px, 26.0, line1, 15, 0.0, 1.0, kText, 0.0, false, w - 2.0 * kMargin_px);

  // Groups: a swatch and a name each.
  double x = kMargin_px;
  const auto swatch = [&](Color c, const std::string& name) {
    const Vec2 a = layout.World(x, 32.0), b = layout.World(x + 11.0, 43.0);
    canvas.FillPolygon({a, {b.x, a.y}, b, {a.x, b.y}}, Lighter(c, 0.45));
    canvas.StrokePolygon({a, {b.x, a.y}, b, {a.x, b.y}}, Darker(c, 0.6), 1.0);
    canvas.TextPx(x + 16.0, 42.0, name, 12, kSubtleText);
    x += 16.0 + 7.0 * static_cast<double>(name.size()) + 18.0;
  };
  for (std::uint32_t g : legend.groups_present)
    swatch(GroupColor(g), "group " + std::to_string(g) + (g == 1 ? " (counter-flow)" : ""));
  if (legend.fallen > 0) swatch(kFallenBody, "fallen: " + std::to_string(legend.fallen) + " (a cross)");
  canvas.TextPxAligned(x, 45.0, "triangle: chest    lines: contact forces (centroid to contact point)", 12, 0.0, 1.0,
                       kSubtleText, 0.0, false, std::max(w - kMargin_px - x, 1.0));

  // Scale bar (lower left) and force scale (lower right): sample lines of
  // round forces up to the largest force of the selected frames.
  canvas.ScaleBar(NiceLength(layout.hi.x - layout.lo.x));
  const double y = h - 0.35 * kMargin_px;
  std::vector<double> samples;
  if (max_force_all_n > 0.0) {
    const double top = NiceFloor(max_force_all_n);
    for (double f : {top / 5.0, top / 2.0, top})
      if (f / force_n_per_px >= kMinForceLineWidth_px) samples.push_back(f);
  }
  const std::string title = "force scale " + FormatNumber(std::round(force_n_per_px * 100.0) / 100.0) + " N/px:";
  double right = w - kMargin_px;
  std::vector<std::pair<double, std::string>> items;  // x of each sample, label
  double needed = 0.0;
  for (double f : samples) needed += 30.0 + 8.0 + 7.0 * static_cast<double>(FormatNumber(f).size() + 2) + 14.0;
  double sx = right - needed;
  canvas.TextPx(sx - 6.5 * static_cast<double>(title.size()) - 6.0, y + 4.0, title, 12, kSubtleText);
  for (double f : samples) {
    const std::string label = FormatNumber(f) + " N";
    ForceLine(canvas, layout, layout.World(sx, y), layout.World(sx + 30.0, y), f / force_n_per_px);
    canvas.TextPx(sx + 38.0, y + 4.0, label, 12, kSubtleText);
    sx += 30.0 + 8.0 + 7.0 * static_cast<double>(label.size()) + 14.0;
  }
}

// --- video --------------------------------------------------------------------

// OpenCV's writer, chosen by the video's extension. Debian's OpenCV writes
// Motion-JPEG AVI with its built-in encoder (no FFmpeg needed); MPEG-4 part 2
// ("mp4v") in .mp4 needs its FFmpeg backend, so that one may fall back to AVI.
// The video is written under a hidden partial name (same extension) and
// renamed when Close succeeds; given up, the partial file is removed.
class VideoOut {
 public:
  VideoOut(const std::filesystem::path& requested, double fps, int width_px, int height_px,
           RenderSummary* summary)
      : size_(width_px + width_px % 2, height_px + height_px % 2) {  // even sizes: codecs want them
    std::string ext = requested.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    std::filesystem::path path = requested;
    std::string codec = ext == ".mp4" ? "mp4v" : "MJPG";
    Open(path, codec, fps);
    if (!writer_->IsOpened() && ext == ".mp4") {
      const std::filesystem::path fallback = std::filesystem::path(requested).replace_extension(".avi");
      summary->notes.push_back(requested.string() + ": OpenCV cannot write MPEG-4 (mp4v) here; wrote " +
                            fallback.string() + " (Motion-JPEG) instead");
      path = fallback;
      codec = "MJPG";
      Open(path, codec, fps);
    }
    if (!writer_->IsOpened())
      throw InputError(path.string() + ": cannot write video (" + codec + " at " + FormatNumber(fps) +
                       " fps); check that the folder exists and is writable");
    final_ = path;
    remove_on_interrupt_ = std::make_unique<RemoveOnInterrupt>(PartialPath(path));
    summary->video_written = path;
    summary->video_codec = codec;
    summary->video_fps = fps;
  }

  // Appends a PNG written for this frame. Frames are padded with white to the
  // video's size (all frames share one layout, so this only adds the odd row).
  void Append(const std::filesystem::path& png) {
    cv::Mat image = media::ReadImage(png.string(), cv::IMREAD_COLOR);
    if (image.empty()) throw InputError(png.string() + ": cannot read back the frame for the video");
    if (image.cols > size_.width || image.rows > size_.height) {
      cv::resize(image, image, size_, 0, 0, cv::INTER_AREA);
    } else if (image.cols != size_.width || image.rows != size_.height) {
      cv::copyMakeBorder(image, image, 0, size_.height - image.rows, 0, size_.width - image.cols,
                         cv::BORDER_CONSTANT, cv::Scalar(255, 255, 255));
    }
    writer_->Write(image);
  }
  void Close() {
    writer_->Release();
    media::RequireCompleteVideo(PartialPath(final_).string(), final_.string());  // (~VideoOut removes the partial)
    std::error_code ec;
    std::filesystem::rename(PartialPath(final_), final_, ec);
    if (ec) throw InputError(final_.string() + ": cannot write video: " + ec.message());
    closed_ = true;
  }
  VideoOut(VideoOut&& other) noexcept
      : writer_(std::move(other.writer_)),
        size_(other.size_),
        final_(std::move(other.final_)),
        remove_on_interrupt_(std::move(other.remove_on_interrupt_)),
        closed_(other.closed_) {
    other.closed_ = true;  // the moved-from object owns no file
  }
  VideoOut& operator=(VideoOut&&) = delete;
  ~VideoOut() {
    if (closed_) return;
    if (writer_) writer_->Release();
    std::error_code ignored;
    if (!final_.empty()) std::filesystem::remove(PartialPath(final_), ignored);
  }

 private:
  void Open(const std::filesystem::path& path, const std::string& codec, double fps) {
    // OpenCV may print backend warnings on failure; the fallback above reports the outcome.
    writer_->Open(PartialPath(path).string(), -1, media::FourCc(codec[0], codec[1], codec[2], codec[3]), fps, size_,
                  true);
    if (!writer_->IsOpened()) {
      std::error_code ignored;
      std::filesystem::remove(PartialPath(path), ignored);
    }
  }
  std::unique_ptr<media::VideoWriter> writer_ = media::MakeVideoWriter();
  cv::Size size_;
  std::filesystem::path final_;
  std::unique_ptr<RemoveOnInterrupt> remove_on_interrupt_;
  bool closed_ = false;
};

}  // namespace

std::string RenderSummary::BriefReport() const {
  std::string s = "rendered " + std::to_string(frames_written) + " frame(s), " + std::to_string(first_frame) +
                  " to " + std::to_string(last_frame) + ", " + std::to_string(width_px) + " x " +
                  std::to_string(height_px) + " px\n";
  if (cropped)
    s += "window: (" + FormatNumber(world_min_m.x) + ", " + FormatNumber(world_min_m.y) + ") to (" +
         FormatNumber(world_max_m.x) + ", " + FormatNumber(world_max_m.y) + ") m\n";
  s += "contact force" + std::string(cropped ? " inside the window" : "") + ": max " +
       FormatFixed(max_contact_force_n, 1) + " N, drawn at " +
       FormatNumber(std::round(force_n_per_px * 1000.0) / 1000.0) + " N per px of line width\n";
  if (most_fallen > 0)
    s += "fallen: up to " + std::to_string(most_fallen) + " in a frame, drawn grey with a cross\n";
  if (branches_left_out > 0)
    s += "note: " + std::to_string(branches_left_out) +
         " contact line(s) across a periodic seam left out (the run file records no periodic box)\n";
  for (const std::string& note : notes) s += "note: " + note + "\n";
  if (!video_written.empty())
    s += "video: " + video_written.string() + " (" + video_codec + ", " + FormatNumber(video_fps) + " fps)\n";
  return s;
}

namespace {

// 2. The layout every frame shares: a first pass over the selected frames finds
//    the region people occupy and the largest force (one force scale).
Layout ChooseLayout(const runfile::RunFileReader& run, const std::vector<std::int64_t>& frames, const Scene& scene,
                    const RenderOptions& options, RenderSummary* summary) {
  const std::string& file = run.file();
  Vec2 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  Vec2 hi = -lo;
  const auto include = [&](Vec2 p, double pad) {
    lo = {std::min(lo.x, p.x - pad), std::min(lo.y, p.y - pad)};
    hi = {std::max(hi.x, p.x + pad), std::max(hi.y, p.y + pad)};
  };
  for (const auto& ring : scene.floor_rings)
    for (Vec2 p : ring) include(p, 0.0);
  for (const WallPiece& w : scene.walls) {
    include(w.a, w.radius_m);
    include(w.b, w.radius_m);
  }
  if (scene.periodic) {
    include(scene.periodic->min_m, 0.0);
    include(scene.periodic->max_m, 0.0);
  }
  for (std::int64_t f : frames) {
    const runfile::RunFrame frame = run.Frame(f);
    // Ids are 1-based (PedPy's convention); anything else would index out of range below.
    for (std::int64_t id : frame.ids)
      if (id < 1 || id > (std::int64_t{1} << 31))
        throw InputError(file + ": frame " + std::to_string(f) + " has person id " + std::to_string(id) +
                         "; expected ids from 1 (trajectory_data.id)");
    for (std::size_t i = 0; i < frame.position_m.size(); ++i)
      include(frame.position_m[i], scene.ShapeOf(static_cast<std::size_t>(frame.ids[i] - 1)).reach_m);
    for (const runfile::Contact& c : frame.contacts) {
      const bool shown = !options.has_window || (c.point_m.x >= options.window_min_m.x && c.point_m.x <= options.window_max_m.x &&
                                                 c.point_m.y >= options.window_min_m.y && c.point_m.y <= options.window_max_m.y);
      if (shown) summary->max_contact_force_n = std::max(summary->max_contact_force_n, Length(c.Force()));
    }
  }
  if (options.has_window) {  // a crop: exactly the window
    // A window beside everything drawn would be a blank picture (issue 65, O05).
    if (lo.x <= hi.x && (options.window_max_m.x < lo.x || options.window_min_m.x > hi.x ||
                         options.window_max_m.y < lo.y || options.window_min_m.y > hi.y))
      throw InputError("--window " + FormatNumber(options.window_min_m.x) + "," + FormatNumber(options.window_min_m.y) +
                       "," + FormatNumber(options.window_max_m.x) + "," + FormatNumber(options.window_max_m.y) +
                       ": holds nothing of the run; its venue and people lie within (" + FormatNumber(std::round(lo.x * 100) / 100) +
                       ", " + FormatNumber(std::round(lo.y * 100) / 100) + ") to (" + FormatNumber(std::round(hi.x * 100) / 100) +
                       ", " + FormatNumber(std::round(hi.y * 100) / 100) + ") m");
    lo = options.window_min_m;
    hi = options.window_max_m;
  } else {
    if (!(lo.x < hi.x && lo.y < hi.y)) {  // a lone person and no venue: a square around them
      lo -= Vec2{1.0, 1.0};
      hi += Vec2{1.0, 1.0};
    }
    const double pad_m = 0.02 * std::max(hi.x - lo.x, hi.y - lo.y);
    lo -= Vec2{pad_m, pad_m};
    hi += Vec2{pad_m, pad_m};
  }
  Layout layout;
  layout.lo = lo;
  layout.hi = hi;
  layout.cropped = options.has_window;
  layout.marked = options.has_mark;
  layout.mark_lo = options.mark_min_m;
  layout.mark_hi = options.mark_max_m;
  // A hair below the exact scale, so that Canvas's ceil() lands on width_px.
  layout.ppm = (options.width_px - 2.0 * kMargin_px) / (hi.x - lo.x) * (1.0 - 1e-9);
  layout.width_px = static_cast<int>(std::ceil((hi.x - lo.x) * layout.ppm + 2.0 * kMargin_px));
  layout.height_px = static_cast<int>(std::ceil((hi.y - lo.y) * layout.ppm + 2.0 * kMargin_px));
  if (layout.height_px > 20000)
    throw InputError(file + ": the drawn region is " + FormatFixed(hi.x - lo.x, 1) + " m x " + FormatFixed(hi.y - lo.y, 1) +
                     " m; at --width " + std::to_string(options.width_px) + " the pictures would be " +
                     std::to_string(layout.height_px) + " px tall (at most 20000): give a smaller --width" +
                     (options.has_window ? " or a wider --window" : ""));
  summary->cropped = layout.cropped;
  summary->world_min_m = layout.lo;
  summary->world_max_m = layout.hi;
  summary->pixels_per_metre = layout.ppm;
  summary->margin_px = kMargin_px;
  summary->force_n_per_px =
      options.force_n_per_px > 0.0 ? options.force_n_per_px
      : summary->max_contact_force_n > 0.0
          ? summary->max_contact_force_n / std::max(4.0, kAutoMaxLineWidth_m * layout.ppm)
          : 100.0;  // no contact anywhere: any scale will do; 100 N/px puts the paper's 400 N at 4 px
  return layout;
}

// 3. The output folder, made only once every selected frame has been read and
//    checked (ChooseLayout), so that a damaged run file leaves nothing behind.
void MakeOutputFolder(const std::filesystem::path& dir, RenderSummary* summary) {
  CreateOutputFolder(dir);
  for (const std::filesystem::path& left : RemoveLeftovers(dir))
    summary->notes.push_back("removed " + left.string() + ", left by a render that was killed");
}

// 4. The video, opened before any drawing so that a bad path fails early; its
//    rate is the run's frame rate over the stride, unless given.
std::optional<VideoOut> OpenVideo(const runfile::RunFileReader& run, const RenderOptions& options, const Layout& layout,
                                  RenderSummary* summary) {
  std::optional<VideoOut> video;
  if (options.video.empty()) return video;
  double fps = options.video_fps;
  if (fps <= 0.0) {
    double run_fps = 10.0;
    try {
      run_fps = run.fps();
    } catch (const InputError&) {
      // A run without metadata.fps: 10 frames per second, JuPedSim's default.
    }
    const double stride =
        options.frames.kind == FrameSelection::Kind::kEvery ? static_cast<double>(options.frames.stride) : 1.0;
    fps = std::max(run_fps / stride, 1.0);
  }
  video.emplace(options.video, fps, layout.width_px, layout.height_px, summary);
  return video;
}

// The legend's counts of a frame, and each person's slot in it (-1: absent).
FrameLegend LegendOf(const runfile::RunFrame& frame, const Scene& scene, std::vector<std::int64_t>* slot_of_person) {
  slot_of_person->assign(scene.person_shape.size(), -1);
  FrameLegend legend;
  legend.frame = frame.frame;
  legend.time_s = frame.time_s;
  legend.people = frame.ids.size();
  for (std::size_t i = 0; i < frame.ids.size(); ++i) {
    const auto person = static_cast<std::size_t>(frame.ids[i] - 1);
    if (person >= slot_of_person->size()) slot_of_person->resize(person + 1, -1);
    (*slot_of_person)[person] = static_cast<std::int64_t>(i);
    if (scene.FallenAt(person, frame.time_s)) {
      ++legend.fallen;
      continue;
    }
    const std::uint32_t g = scene.GroupOf(person);
    if (std::find(legend.groups_present.begin(), legend.groups_present.end(), g) == legend.groups_present.end())
      legend.groups_present.push_back(g);
  }
  std::sort(legend.groups_present.begin(), legend.groups_present.end());
  return legend;
}

// 5. One frame into one picture: floor, walls, periodic seams, bodies (and
//    their images across seams), force network on top, legend in the margins.
//    Returns the picture's size in pixels.
std::pair<double, double> DrawFrame(const std::filesystem::path& path, const runfile::RunFrame& frame,
                                    const Scene& scene, const Layout& layout, const FrameLegend& legend,
                                    const std::vector<std::int64_t>& slot_of_person, const RenderSummary& summary,
                                    FrameStats* stats) {
  Canvas canvas(path, layout.lo, layout.hi, layout.ppm, kMargin_px);
  if (layout.cropped) canvas.ClipToWorld();
  if (!scene.floor_rings.empty()) canvas.FillRings(scene.floor_rings, kFloor);
  for (const WallPiece& w : scene.walls) canvas.Line(w.a, w.b, kWall, std::max(3.0, 2.0 * w.radius_m * layout.ppm));
  if (scene.periodic) {  // dashed grey lines across the box where it wraps
    const PeriodicBox& box = *scene.periodic;
    const Color seam = Color::Hex(0x777777);
    if (box.x)
      for (double x : {box.min_m.x, box.max_m.x})
        canvas.StrokePolyline({{x, layout.lo.y}, {x, layout.hi.y}}, seam, 1.5, /*dashed=*/true);
    if (box.y)
      for (double y : {box.min_m.y, box.max_m.y})
        canvas.StrokePolyline({{layout.lo.x, y}, {layout.hi.x, y}}, seam, 1.5, /*dashed=*/true);
  }
  for (std::size_t i = 0; i < frame.ids.size(); ++i) {
    const auto person = static_cast<std::size_t>(frame.ids[i] - 1);
    const ShapeInfo& shape = scene.ShapeOf(person);
    const bool fallen = scene.FallenAt(person, frame.time_s);
    for (Vec2 offset : ImageOffsets(scene, frame.position_m[i], shape.reach_m)) {
      DrawBody(canvas, layout, shape, frame.position_m[i] + offset, frame.orientation[i],
               fallen ? kFallenBody : GroupColor(scene.GroupOf(person)));
      if (fallen) DrawFallenCross(canvas, frame.position_m[i] + offset, shape);
    }
  }
  *stats = FrameStats{};
  DrawForceNetwork(canvas, layout, scene, frame, slot_of_person, summary.force_n_per_px, stats);
  for (Vec2 p : frame.position_m) canvas.Dot(p, std::clamp(0.02 * layout.ppm, 1.0, 2.5), kForce);
  if (layout.marked) {
    const Vec2 a = layout.mark_lo, b = layout.mark_hi;
    canvas.StrokePolyline({a, {b.x, a.y}, b, {a.x, b.y}, a}, Color::Hex(0xd62728), 3.0, /*dashed=*/false);
  }
  canvas.ResetClip();
  DrawLegend(canvas, layout, legend, *stats, summary.force_n_per_px, summary.max_contact_force_n);
  canvas.Finish();
  return {canvas.width_px(), canvas.height_px()};
}

}  // namespace

RenderSummary RenderRun(const std::filesystem::path& run_file, const RenderOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  const std::string file = run_file.string();

  // 1. Open the run (RunFileReader names missing, foreign and non-run files)
  //    and select its frames.
  const runfile::RunFileReader run(run_file);
  const std::vector<std::int64_t> all_frames = run.Frames();
  if (all_frames.empty()) {
    const std::string status = run.RunValue("status");
    throw InputError(file + ": the run has no frames to draw" + (status.empty() ? "" : " (status: " + status + ")"));
  }
  // Frame times exceed their nominal times by less than one time step.
  const double time_step_s = run.RunNumber("time_step_s", 0.0, 0.0, 1.0);  // absent: exact times assumed
  const std::vector<std::int64_t> frames =
      SelectFrames(options.frames, all_frames, [&](std::int64_t f) { return run.Frame(f).time_s; },
                   std::max(1e-6, std::isfinite(time_step_s) ? time_step_s : 0.0));
  const Scene scene = LoadScene(run, file);
  RenderSummary summary;
  if (!scene.floor_note.empty()) summary.notes.push_back(scene.floor_note);

  const Layout layout = ChooseLayout(run, frames, scene, options, &summary);
  MakeOutputFolder(options.output_dir, &summary);
  std::optional<VideoOut> video = OpenVideo(run, options, layout, &summary);

  std::vector<std::int64_t> slot_of_person;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const runfile::RunFrame frame = run.Frame(frames[k]);
    const FrameLegend legend = LegendOf(frame, scene, &slot_of_person);
    FrameStats stats;
    const std::filesystem::path png = FramePicturePath(options.output_dir, frame.frame, ".png");
    const auto [w, h] = DrawFrame(png, frame, scene, layout, legend, slot_of_person, summary, &stats);
    if (options.svg)
      DrawFrame(FramePicturePath(options.output_dir, frame.frame, ".svg"), frame, scene, layout, legend, slot_of_person,
                summary, &stats);
    if (video) video->Append(png);
    if (k == 0) {
      summary.first_picture = png;
      summary.first_frame = frame.frame;
      summary.width_px = static_cast<int>(w);
      summary.height_px = static_cast<int>(h);
    }
    summary.last_frame = frame.frame;
    summary.branches_left_out += stats.branches_left_out;
    summary.most_fallen = std::max(summary.most_fallen, legend.fallen);
    ++summary.frames_written;
    if (options.progress) options.progress({k + 1, frames.size(), frame.frame, frame.time_s});
  }
  if (video) video->Close();
  return summary;
}

}  // namespace crowdrecon::viz
