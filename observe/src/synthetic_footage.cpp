#include "crowdrecon/observe/synthetic_footage.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/remove_on_interrupt.hpp"
#include "crowdrecon/runfile/run_file.hpp"
#include "crowdrecon/media/media.hpp"

namespace crowdrecon::observe {

bool SyntheticFootageOptions::IsValid(std::string* error) const {
  const auto bad = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (width_px < 64 || width_px > 8192 || height_px < 64 || height_px > 8192)
    return bad("picture size " + std::to_string(width_px) + "x" + std::to_string(height_px) + ", expected 64 to 8192 px each way");
  if (!(far_width > 0.05 && far_width <= 1.0)) return bad("far width " + FormatNumber(far_width) + ", expected (0.05, 1]");
  if (!(pixels_per_metre >= 10 && pixels_per_metre <= 1000))
    return bad("floor drawing scale " + FormatNumber(pixels_per_metre) + " px/m, expected [10, 1000]");
  if (!(darkness >= 0.0 && darkness < 1.0)) return bad("darkness " + FormatNumber(darkness) + ", expected [0, 1)");
  if (!(blur_sigma_px >= 0.0 && blur_sigma_px <= 50.0)) return bad("blur " + FormatNumber(blur_sigma_px) + " px, expected [0, 50]");
  if (!(noise_sigma >= 0.0 && noise_sigma <= 128.0)) return bad("noise " + FormatNumber(noise_sigma) + ", expected [0, 128] grey levels");
  if (frame_step < 1 || frame_step > 1000) return bad("frame step " + std::to_string(frame_step) + ", expected 1 to 1000");
  if (jpeg_quality < 1 || jpeg_quality > 100) return bad("JPEG quality " + std::to_string(jpeg_quality) + ", expected 1 to 100");
  return true;
}

namespace {

// A small deterministic generator (SplitMix64) for textures: the same run and
// seed draw the same picture on every machine.
struct SplitMix {
  std::uint64_t state;
  std::uint64_t Next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
};

struct Spot {
  Vec2 at;        // body frame (m)
  double radius;  // m
  cv::Scalar colour;
};

struct Look {
  cv::Scalar body;
  std::vector<Spot> spots;
  std::vector<Vec2> outline;  // body frame: the spheropolygon's boundary
};

// The boundary of a convex polygon swept by a disc: arcs at the vertices.
std::vector<Vec2> Outline(const runfile::Shape& shape) {
  const std::vector<Vec2>& v = shape.vertices;
  std::vector<Vec2> out;
  if (v.size() == 1) {
    for (int k = 0; k < 24; ++k)
      out.push_back(v[0] + Vec2{std::cos(k * M_PI / 12), std::sin(k * M_PI / 12)} * shape.radius_m);
    return out;
  }
  // Counter-clockwise order for the outward normals.
  double area = 0;
  for (std::size_t i = 0; i < v.size(); ++i) area += Cross(v[i], v[(i + 1) % v.size()]);
  std::vector<Vec2> p = v;
  if (area < 0) std::reverse(p.begin(), p.end());
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 in = p[i] - p[(i + n - 1) % n], outd = p[(i + 1) % n] - p[i];
    const double a0 = std::atan2(-in.x, in.y), a1 = std::atan2(-outd.x, outd.y);  // outward normals
    double sweep = a1 - a0;
    while (sweep < 0) sweep += 2 * M_PI;
    const int steps = std::max(1, static_cast<int>(std::ceil(sweep / (M_PI / 12))));
    for (int k = 0; k <= steps; ++k) {
      const double a = a0 + sweep * k / steps;
      out.push_back(p[i] + Vec2{std::cos(a), std::sin(a)} * shape.radius_m);
    }
  }
  return out;
}

Look LookOf(std::uint32_t person, const runfile::Shape& shape, std::uint64_t seed) {
  SplitMix rng{seed * 1000003ull + person};
  Look look;
  const double base = 60 + 150 * rng.Uniform();
  look.body = cv::Scalar(base * (0.7 + 0.6 * rng.Uniform()), base * (0.7 + 0.6 * rng.Uniform()), base * (0.7 + 0.6 * rng.Uniform()));
  look.outline = Outline(shape);
  Vec2 lo = look.outline.front(), hi = lo;
  for (Vec2 q : look.outline) lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)}, hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
  for (int k = 0; k < 14; ++k) {
    Spot s;
    s.at = {lo.x + (hi.x - lo.x) * (0.15 + 0.7 * rng.Uniform()), lo.y + (hi.y - lo.y) * (0.15 + 0.7 * rng.Uniform())};
    s.radius = 0.015 + 0.03 * rng.Uniform();
    const double shade = rng.Uniform() < 0.5 ? 0.35 : 1.6;
    s.colour = cv::Scalar(std::min(255.0, look.body[0] * shade + 20 * rng.Uniform()),
                          std::min(255.0, look.body[1] * shade + 20 * rng.Uniform()),
                          std::min(255.0, look.body[2] * shade + 20 * rng.Uniform()));
    look.spots.push_back(s);
  }
  return look;
}

}  // namespace

SyntheticFootageSummary RenderSyntheticFootage(const std::filesystem::path& run_file,
                                               const SyntheticFootageOptions& options,
                                               const std::filesystem::path& video,
                                               const std::filesystem::path& homography_file) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("synthetic footage: " + error);
  const runfile::RunFileReader run(run_file);
  const PeriodicBox box = run.periodic_box();
  // The floor window.
  double x0 = options.x0, y0 = options.y0, x1 = options.x1, y1 = options.y1;
  const std::vector<runfile::Wall> walls = run.Walls();
  if (!(x1 > x0 && y1 > y0)) {
    bool first = true;
    for (const runfile::Wall& w : walls)
      for (Vec2 p : w.points) {
        x0 = first ? p.x : std::min(x0, p.x), x1 = first ? p.x : std::max(x1, p.x);
        y0 = first ? p.y : std::min(y0, p.y), y1 = first ? p.y : std::max(y1, p.y);
        first = false;
      }
    if (box.x) x0 = box.min_m.x, x1 = box.max_m.x;
    if (box.y) y0 = box.min_m.y, y1 = box.max_m.y;
    if (first || !(x1 > x0 && y1 > y0))
      throw InputError(run_file.string() + ": the run has no walls or periodic box to frame; give the floor window");
  }
  const double ppm = options.pixels_per_metre;
  const int fw = static_cast<int>(std::ceil((x1 - x0) * ppm)), fh = static_cast<int>(std::ceil((y1 - y0) * ppm));
  if (static_cast<double>(fw) * fh > 64e6) throw InputError("synthetic footage: the floor drawing would exceed 64 Mpx; lower its scale");
  const auto floor_px = [&](Vec2 p) { return cv::Point2d((p.x - x0) * ppm, (y1 - p.y) * ppm); };

  // 2. The camera: floor window corners to a trapezoid.
  const double m = 16, W = options.width_px, H = options.height_px;
  const double inset = 0.5 * (1.0 - options.far_width) * (W - 2 * m);
  std::vector<PointPair> pairs = {{{m, H - m}, {x0, y0}}, {{W - m, H - m}, {x1, y0}},
                                  {{W - m - inset, m}, {x1, y1}}, {{m + inset, m}, {x0, y1}}};
  SyntheticFootageSummary summary;
  summary.homography = HomographyFromPairs(pairs, "synthetic camera");
  summary.homography.image_width = options.width_px;
  summary.homography.image_height = options.height_px;
  // Floor drawing pixels -> picture: H_cam * (floor drawing -> floor).
  const std::array<double, 9>& hc = summary.homography.h;
  const cv::Mat cam = (cv::Mat_<double>(3, 3) << hc[0], hc[1], hc[2], hc[3], hc[4], hc[5], hc[6], hc[7], hc[8]);
  const cv::Mat to_floor = (cv::Mat_<double>(3, 3) << 1 / ppm, 0, x0, 0, -1 / ppm, y1, 0, 0, 1);
  const cv::Mat warp = cam * to_floor;

  // 1. The static floor: 0.5 m tiles of slightly different greys with grain.
  cv::Mat floor(fh, fw, CV_8UC3);
  {
    SplitMix rng{options.seed * 7919ull + 17};
    cv::Mat grain(fh, fw, CV_8UC1);
    for (int r = 0; r < fh; ++r)
      for (int c = 0; c < fw; ++c) grain.at<unsigned char>(r, c) = static_cast<unsigned char>(rng.Next() % 24);
    cv::GaussianBlur(grain, grain, cv::Size(0, 0), 1.2);
    for (int r = 0; r < fh; ++r)
      for (int c = 0; c < fw; ++c) {
        const int tile = static_cast<int>(std::floor(c / (0.5 * ppm))) * 31 + static_cast<int>(std::floor(r / (0.5 * ppm))) * 17;
        const int g = 120 + (tile * 7919 % 23) + grain.at<unsigned char>(r, c);
        floor.at<cv::Vec3b>(r, c) = cv::Vec3b(static_cast<unsigned char>(g), static_cast<unsigned char>(g + 4),
                                              static_cast<unsigned char>(g + 10));
      }
    for (const runfile::Wall& w : walls) {
      std::vector<cv::Point> line;
      for (Vec2 p : w.points) line.emplace_back(floor_px(p));
      const int thick = std::max(2, static_cast<int>(std::lround(2 * w.radius_m * ppm)));
      cv::polylines(floor, std::vector<std::vector<cv::Point>>{line}, w.closed, cv::Scalar(40, 40, 45), thick, cv::LINE_AA);
    }
  }
  const std::vector<runfile::Shape> shapes = run.Shapes();
  const std::vector<std::uint32_t> person_shape = run.PersonShapes();
  std::vector<Look> looks(person_shape.size());
  for (std::size_t i = 0; i < person_shape.size(); ++i)
    looks[i] = LookOf(static_cast<std::uint32_t>(i), shapes.at(person_shape[i]), options.seed);

  const std::vector<runfile::FrameTime> times = run.FrameTimes();
  if (times.size() < 2) throw InputError(run_file.string() + ": the run has fewer than two frames");
  summary.fps = run.fps() / options.frame_step;
  summary.first_time_s = times.front().time_s;
  summary.removed_partials = RemoveStalePartialsOf(video);
  const std::filesystem::path partial = PartialPath(video);
  const RemoveOnInterrupt remove_on_interrupt(partial);
  const std::unique_ptr<media::VideoWriter> writer = media::MakeVideoWriter();
  writer->Open(partial.string(), cv::CAP_OPENCV_MJPEG, media::FourCc('M', 'J', 'P', 'G'), summary.fps,
               cv::Size(options.width_px, options.height_px), true);
  if (!writer->IsOpened()) throw InputError(video.string() + ": cannot write a Motion-JPEG video there");
  writer->Set(cv::VIDEOWRITER_PROP_QUALITY, options.jpeg_quality);
  const double image_offsets[3] = {0.0, box.x ? box.max_m.x - box.min_m.x : 0.0, box.x ? -(box.max_m.x - box.min_m.x) : 0.0};
  runfile::PersonFrameStream stream = run.PersonFrames(times.back().frame);
  runfile::PersonFrame rows;
  std::size_t k = 0;
  cv::Mat drawing, picture, noise;
  const std::size_t total = (times.size() + options.frame_step - 1) / options.frame_step;
  while (stream.Next(&rows)) {
    if (k++ % static_cast<std::size_t>(options.frame_step) != 0) continue;
    floor.copyTo(drawing);
    for (std::size_t r = 0; r < rows.person.size(); ++r) {
      if (rows.state[r] == runfile::PersonStatus::kRemoved) continue;
      const Look& look = looks.at(rows.person[r]);
      for (double dx : image_offsets) {
        if (dx != 0.0 && std::abs(rows.position_m[r].x + dx - 0.5 * (x0 + x1)) > 0.5 * (x1 - x0) + 1.0) continue;
        const Vec2 at = rows.position_m[r] + Vec2{dx, 0.0};
        std::vector<cv::Point> body;
        for (Vec2 q : look.outline) {
          const cv::Point2d p = floor_px(at + Rotated(q, rows.angle_rad[r]));
          body.emplace_back(static_cast<int>(std::lround(p.x * 4)), static_cast<int>(std::lround(p.y * 4)));
        }
        cv::fillPoly(drawing, std::vector<std::vector<cv::Point>>{body}, look.body, cv::LINE_AA, 2);
        cv::polylines(drawing, std::vector<std::vector<cv::Point>>{body}, true, look.body * 0.5, 1, cv::LINE_AA, 2);
        for (const Spot& s : look.spots) {
          const cv::Point2d p = floor_px(at + Rotated(s.at, rows.angle_rad[r]));
          cv::circle(drawing, cv::Point(static_cast<int>(std::lround(p.x * 4)), static_cast<int>(std::lround(p.y * 4))),
                     static_cast<int>(std::lround(s.radius * ppm * 4)), s.colour, -1, cv::LINE_AA, 2);
        }
      }
    }
    cv::warpPerspective(drawing, picture, warp, cv::Size(options.width_px, options.height_px), cv::INTER_AREA,
                        cv::BORDER_CONSTANT, cv::Scalar(20, 20, 20));
    // 3. Degrade.
    if (options.darkness > 0) picture.convertTo(picture, -1, 1.0 - options.darkness, 0.0);
    if (options.blur_sigma_px > 0) cv::GaussianBlur(picture, picture, cv::Size(0, 0), options.blur_sigma_px);
    if (options.noise_sigma > 0) {
      cv::RNG rng(options.seed * 1000003ull + k);
      noise.create(picture.size(), CV_16SC3);
      rng.fill(noise, cv::RNG::NORMAL, cv::Scalar::all(0), cv::Scalar::all(options.noise_sigma));
      cv::Mat wide;
      picture.convertTo(wide, CV_16SC3);
      wide += noise;
      wide.convertTo(picture, CV_8UC3);
    }
    writer->Write(picture);
    ++summary.frames;
    if (options.progress) options.progress(summary.frames, total);
  }
  writer->Release();
  try {
    media::RequireCompleteVideo(partial.string(), video.string());
  } catch (const InputError&) {
    std::error_code ignored;
    std::filesystem::remove(partial, ignored);
    throw;
  }
  std::filesystem::rename(partial, video);
  WriteFileAtomically(homography_file, HomographyToJson(summary.homography));
  return summary;
}

}  // namespace crowdrecon::observe
