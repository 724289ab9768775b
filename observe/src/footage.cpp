#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/observe/footage.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <opencv2/videoio.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/sha256.hpp"
#include "crowdrecon/media/media.hpp"
#include "series_builder.hpp"

namespace crowdrecon::observe {

bool FootageOptions::IsValid(std::string* error) const {
  const auto bad = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (flow != "dis-fast" && flow != "dis-medium" && flow != "farneback")
    return bad("flow: \"" + flow + "\", expected dis-fast, dis-medium or farneback");
  if (!(grid_spacing_m >= 0.01 && grid_spacing_m <= 2.0))
    return bad("grid spacing: " + FormatNumber(grid_spacing_m) + " m, expected [0.01, 2] m");
  if (!(min_brightness >= 0.0 && min_brightness <= 255.0))
    return bad("minimum brightness: " + FormatNumber(min_brightness) + ", expected a grey level in [0, 255]");
  if (!(min_contrast >= 0.0 && min_contrast <= 128.0))
    return bad("minimum contrast: " + FormatNumber(min_contrast) + ", expected a grey level in [0, 128]");
  if (!(min_correlation >= -1.0 && min_correlation <= 1.0))
    return bad("minimum correlation: " + FormatNumber(min_correlation) + ", expected [-1, 1]");
  if (!(from_s >= 0.0) || !(to_s > from_s))
    return bad("time window: from " + FormatNumber(from_s) + " s to " + FormatNumber(to_s) + " s, expected 0 <= from < to");
  for (double t : picture_times_s)
    if (!std::isfinite(t) || t < 0) return bad("picture time " + FormatNumber(t) + " s, expected a time >= 0");
  return true;
}

std::string FootageSummary::BriefReport() const {
  char text[512];
  std::snprintf(text, sizeof text,
                "%s: %dx%d at %s fps; %zu frames read, %zu velocity fields (span %d frames); flagged: %zu dark, %zu flat, "
                "%zu cut, %zu frozen; %zu floor points; %s s, %s frames/s\n",
                video.c_str(), width, height, FormatNumber(fps).c_str(), frames_read, flows, span_frames, dark, flat, cut,
                frozen, grid_points, FormatNumber(std::round(elapsed_s * 10) / 10).c_str(),
                FormatNumber(std::round(processing_fps * 10) / 10).c_str());
  return text;
}

namespace {

struct Sample {
  std::size_t region;
  cv::Point pixel;
  std::array<double, 4> jacobian;  // floor per image pixel
  int ix, iy;                      // place in the region's floor grid
};

// A region's floor grid, for step 4's averaging over a body's size.
struct Grid {
  int nx = 0, ny = 0;
  std::vector<int> sample;  // index into the samples, -1 where none
};

// Step 4's averaging window (m): about a body's depth and half its breadth
// (the paper's thorax: 0.24 m x 0.5 m).
constexpr double kBodyWindow_m = 0.5;

// Step 4: an image displacement (px) carried to the floor (m).
Vec2 FloorDisplacement(const Sample& s, cv::Point2f u_px) {
  const double ux = static_cast<double>(u_px.x), uy = static_cast<double>(u_px.y);
  return {s.jacobian[0] * ux + s.jacobian[1] * uy, s.jacobian[2] * ux + s.jacobian[3] * uy};
}

// The standard deviation of a frame's noise, by J. Immerkaer's estimator
// ("Fast noise variance estimation", Comput. Vis. Image Underst. 64:300,
// 1996): the mean absolute response to the Laplacian difference mask
// [1 -2 1; -2 4 -2; 1 -2 1], which cancels smooth image content, times
// sqrt(pi/2)/6. From one frame, so it does not depend on how much of the
// picture moves (a packed crowd walking changes nearly every pixel).
double NoiseSigma(const cv::Mat& grey, const cv::Mat& mask) {
  static const cv::Mat kernel = (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::Mat response;
  cv::filter2D(grey, response, CV_32F, kernel);
  response = cv::abs(response);
  return std::sqrt(M_PI / 2.0) / 6.0 * cv::mean(response, mask)[0];
}

// Pixels (in `mask`) whose grey level changed between two frames by more
// than the noise allows: both frames smoothed (sigma 1 px, which leaves
// about 0.28 of the noise), their difference (sqrt 2 of one frame's) against
// four times its noise, never below 3 grey levels; the changed pixels
// dilated by 2 px (a moving body's interior may be uniform, its spots and
// edges are not).
void ChangeMask(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask, cv::Mat* changed) {
  cv::Mat sa, sb, diff;
  cv::GaussianBlur(a, sa, cv::Size(0, 0), 1.0);
  cv::GaussianBlur(b, sb, cv::Size(0, 0), 1.0);
  cv::absdiff(sa, sb, diff);
  const double sigma = 0.5 * (NoiseSigma(a, mask) + NoiseSigma(b, mask));
  const double diff_sigma = std::sqrt(2.0) * 0.28 * sigma;
  cv::threshold(diff, *changed, std::max(3.0, 4.0 * diff_sigma), 255, cv::THRESH_BINARY);
  cv::dilate(*changed, *changed, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));
}

// Normalised cross-correlation of two frames in the mask, at an eighth of
// their size: consecutive frames of one scene stay correlated however the
// crowd moves at that scale; another scene (a cut) is not. 0 when either is
// uniform.
double FrameCorrelation(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  const cv::Size small(std::max(1, a.cols / 8), std::max(1, a.rows / 8));
  cv::Mat sa, sb, sm;
  cv::resize(a, sa, small, 0, 0, cv::INTER_AREA);
  cv::resize(b, sb, small, 0, 0, cv::INTER_AREA);
  cv::resize(mask, sm, small, 0, 0, cv::INTER_NEAREST);
  cv::Scalar ma, da, mb, db;
  cv::meanStdDev(sa, ma, da, sm);
  cv::meanStdDev(sb, mb, db, sm);
  if (da[0] < 1e-6 || db[0] < 1e-6) return 0.0;
  cv::Mat fa, fb;
  sa.convertTo(fa, CV_64F, 1.0, -ma[0]);
  sb.convertTo(fb, CV_64F, 1.0, -mb[0]);
  return cv::mean(fa.mul(fb), sm)[0] / (da[0] * db[0]);
}

// What step 1 found in one frame.
enum Flag : unsigned { kDark = 1, kFlat = 2, kCut = 4, kFrozen = 8 };

struct Held {
  cv::Mat grey;      // enhanced, for the flow
  cv::Mat raw;       // as decoded (grey), for the frozen check
  unsigned flags = 0;
  std::size_t index = 0;
};

// The flow field as measured: at every second floor point, an arrow along
// the image motion over the span (three times longer) coloured by the
// velocity that went into the series (step 4: blue forward, red backward),
// or a grey dot where the point was still.
void DrawFlowPicture(const cv::Mat& frame, const cv::Mat& flow, const std::vector<Sample>& samples,
                     const std::vector<double>& used_velocity, const std::vector<std::vector<cv::Point>>& outlines,
                     double still, const std::filesystem::path& file) {
  cv::Mat out;
  if (frame.channels() == 1) cv::cvtColor(frame, out, cv::COLOR_GRAY2BGR);
  else out = frame.clone();
  cv::polylines(out, outlines, true, cv::Scalar(0, 200, 255), 2, cv::LINE_AA);
  for (std::size_t i = 0; i < samples.size(); i += 2) {
    const Sample& s = samples[i];
    const cv::Point2f u = flow.at<cv::Point2f>(s.pixel);
    const double v = used_velocity[i];
    const cv::Scalar colour = v > still ? cv::Scalar(200, 90, 30) : v < -still ? cv::Scalar(40, 40, 220) : cv::Scalar(150, 150, 150);
    // Arrows show the image motion over the span, drawn three times longer.
    const cv::Point tip(static_cast<int>(std::lround(s.pixel.x + 3.0 * static_cast<double>(u.x))), static_cast<int>(std::lround(s.pixel.y + 3.0 * static_cast<double>(u.y))));
    if (std::abs(v) > still) cv::arrowedLine(out, s.pixel, tip, colour, 1, cv::LINE_AA, 0, 0.3);
    else cv::circle(out, s.pixel, 1, colour, -1);
  }
  if (!media::WriteImage(file.string(), out)) throw InputError(file.string() + ": cannot write the flow picture");
}

}  // namespace

Observation ObserveFootage(const std::filesystem::path& video, const Homography& homography,
                           const ObservationSpec& spec, const FootageOptions& options, FootageSummary* summary) {
  std::string error;
  if (!spec.IsValid(&error)) throw InputError("observation spec: " + error);
  if (!options.IsValid(&error)) throw InputError("footage options: " + error);
  if (!std::filesystem::is_regular_file(video)) throw InputError(video.string() + ": no such video file");
  const auto started = std::chrono::steady_clock::now();
  const std::unique_ptr<media::VideoReader> reader = media::MakeVideoReader();
  media::VideoReader& capture = *reader;
  if (!capture.Open(video.string(), cv::CAP_FFMPEG)) capture.Open(video.string(), cv::CAP_ANY);
  if (!capture.IsOpened())
    throw InputError(video.string() + ": cannot be read as a video (expected a file FFmpeg or OpenCV can decode: AVI, MP4, MKV, ...)");
  FootageSummary s;
  s.video = video.string();
  s.fps = capture.Get(cv::CAP_PROP_FPS);
  s.width = static_cast<int>(capture.Get(cv::CAP_PROP_FRAME_WIDTH));
  s.height = static_cast<int>(capture.Get(cv::CAP_PROP_FRAME_HEIGHT));
  if (!(s.fps > 0.0 && s.fps <= 1000.0))
    throw InputError(video.string() + ": the video states no frame rate (" + FormatNumber(s.fps) + "); expected (0, 1000] fps");
  if (s.width <= 0 || s.height <= 0) throw InputError(video.string() + ": the video states no picture size");
  if (homography.image_width > 0 && (homography.image_width != s.width || homography.image_height != s.height))
    throw InputError(video.string() + ": the picture is " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                     " but the homography was made for " + std::to_string(homography.image_width) + "x" +
                     std::to_string(homography.image_height));
  const double total_frames = capture.Get(cv::CAP_PROP_FRAME_COUNT);
  const int span = std::max(1, static_cast<int>(std::lround(spec.velocity_span_s * s.fps)));
  s.span_frames = span;
  const Vec2 axis = spec.axis * (1.0 / Length(spec.axis));

  // The floor grid of every region, seen in the picture.
  std::vector<Sample> samples;
  std::vector<Grid> grids;
  std::vector<std::vector<cv::Point>> outlines;
  cv::Mat mask = cv::Mat::zeros(s.height, s.width, CV_8U);
  for (std::size_t r = 0; r < spec.regions.size(); ++r) {
    const Region& region = spec.regions[r];
    Vec2 lo = region.polygon_m.front(), hi = lo;
    for (Vec2 p : region.polygon_m) lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)}, hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    std::size_t inside = 0, seen = 0;
    Grid grid;
    grid.nx = static_cast<int>(std::ceil((hi.x - lo.x) / options.grid_spacing_m));
    grid.ny = static_cast<int>(std::ceil((hi.y - lo.y) / options.grid_spacing_m));
    grid.sample.assign(static_cast<std::size_t>(grid.nx) * grid.ny, -1);
    for (int iy = 0; iy < grid.ny; ++iy)
      for (int ix = 0; ix < grid.nx; ++ix) {
        const double x = lo.x + (ix + 0.5) * options.grid_spacing_m, y = lo.y + (iy + 0.5) * options.grid_spacing_m;
        if (!region.Contains({x, y})) continue;
        ++inside;
        if (!homography.InFront({x, y})) continue;
        const Vec2 p = homography.ToImage({x, y});
        const cv::Point px(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)));
        if (px.x < 0 || px.y < 0 || px.x >= s.width || px.y >= s.height) continue;
        ++seen;
        grid.sample[static_cast<std::size_t>(iy) * grid.nx + ix] = static_cast<int>(samples.size());
        samples.push_back({r, px, homography.FloorJacobianAt({static_cast<double>(px.x), static_cast<double>(px.y)}), ix, iy});
      }
    grids.push_back(std::move(grid));
    if (seen == 0)
      throw InputError("region " + region.name + ": none of its floor lies in the picture (" + std::to_string(s.width) + "x" +
                       std::to_string(s.height) + ") through this homography; expected regions the camera sees");
    if (seen < inside)
      s.notes.push_back("region " + region.name + ": " + std::to_string(inside - seen) + " of " + std::to_string(inside) +
                        " floor points lie outside the picture and are not observed");
    std::vector<cv::Point> outline;
    for (Vec2 p : region.polygon_m) {
      const Vec2 q = homography.ToImage(p);
      outline.emplace_back(static_cast<int>(std::lround(q.x)), static_cast<int>(std::lround(q.y)));
    }
    outlines.push_back(outline);
    cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{outline}, cv::Scalar(255));
  }
  s.grid_points = samples.size();
  std::vector<char> moved(samples.size(), 0);
  std::vector<double> along(samples.size(), 0.0), used(samples.size(), 0.0);
  const int reach = std::max(0, static_cast<int>(std::lround(0.5 * kBodyWindow_m / options.grid_spacing_m - 0.5)));

  Observation obs;
  obs.source_file = video.string();
  obs.source_sha256 = Sha256OfFile(video);
  obs.source_format = "video";
  obs.method = "footage";
  obs.spec = spec;
  obs.spec.axis = axis;
  nlohmann::json method = {{"flow", options.flow},
                           {"grid_spacing_m", options.grid_spacing_m},
                           {"enhance", options.enhance},
                           {"min_brightness", options.min_brightness},
                           {"min_contrast", options.min_contrast},
                           {"min_correlation", options.min_correlation},
                           {"from_s", options.from_s},
                           {"fps", s.fps},
                           {"span_frames", span},
                           {"homography", nlohmann::json::parse(HomographyToJson(homography))}};
  if (std::isfinite(options.to_s)) method["to_s"] = options.to_s;
  obs.method_options_json = method.dump();
  detail::SeriesBuilder builder(obs.spec, options.from_s, 0, options.grid_spacing_m * options.grid_spacing_m);

  cv::Ptr<cv::DISOpticalFlow> dis;
  if (options.flow == "dis-fast") dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_FAST);
  if (options.flow == "dis-medium") dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);
  cv::Ptr<cv::CLAHE> clahe = cv::createCLAHE(2.0, cv::Size(8, 8));
  std::deque<Held> held;  // the last span + 1 frames
  std::vector<double> pictures_left = options.picture_times_s;
  std::sort(pictures_left.begin(), pictures_left.end());
  if (!pictures_left.empty()) CreateOutputFolder(options.picture_dir);
  cv::Mat frame, flow, change;
  std::size_t index = 0;
  bool window_ended = false;  // the loop stopped at --to, not at the video's last readable frame
  for (;; ++index) {
    if (!capture.Read(frame) || frame.empty()) break;
    const double t = static_cast<double>(index) / s.fps;
    if (t > options.to_s) {
      window_ended = true;
      break;
    }
    ++s.frames_read;
    if (t + static_cast<double>(span) / s.fps < options.from_s) continue;
    // 1. Is the picture usable?
    Held h;
    h.index = index;
    if (frame.channels() == 3) cv::cvtColor(frame, h.raw, cv::COLOR_BGR2GRAY);
    else h.raw = frame.clone();
    cv::Scalar mean, sd;
    cv::meanStdDev(h.raw, mean, sd, mask);
    if (mean[0] < options.min_brightness) h.flags |= kDark;
    if (sd[0] < options.min_contrast) h.flags |= kFlat;
    if (!held.empty() && held.back().index + 1 == index) {
      if (FrameCorrelation(held.back().raw, h.raw, mask) < options.min_correlation) h.flags |= kCut;
      if (cv::norm(held.back().raw, h.raw, cv::NORM_L1) == 0.0) h.flags |= kFrozen;
    }
    s.dark += (h.flags & kDark) != 0;
    s.flat += (h.flags & kFlat) != 0;
    s.cut += (h.flags & kCut) != 0;
    s.frozen += (h.flags & kFrozen) != 0;
    // 2. Contrast.
    if (options.enhance) clahe->apply(h.raw, h.grey);
    else h.grey = h.raw;
    held.push_back(std::move(h));
    if (held.size() > static_cast<std::size_t>(span) + 1) held.pop_front();
    if (held.size() != static_cast<std::size_t>(span) + 1) continue;
    // A velocity spanning a flagged frame is left out (a cut at the first
    // frame of the span is the scene before it: the span does not cross it).
    bool usable = (held.front().flags & (kDark | kFlat | kFrozen)) == 0;
    for (std::size_t k = 1; k < held.size(); ++k) usable = usable && held[k].flags == 0;
    const double t_mid = (static_cast<double>(index) - 0.5 * span) / s.fps;
    if (!usable || t_mid < options.from_s) continue;
    // 3. Dense optical flow over the span.
    if (dis) dis->calc(held.front().grey, held.back().grey, flow);
    else cv::calcOpticalFlowFarneback(held.front().grey, held.back().grey, flow, 0.5, 3, 15, 3, 5, 1.2, 0);
    ++s.flows;
    // 4. Floor velocities where the picture changed over the span: the
    // flow of a textured floor next to a moving body is smeared from the
    // body (the flow field is smooth), but the floor itself does not change;
    // a pixel whose grey level changed by less than the noise allows is
    // still (velocity 0). The velocity of a changed point is the mean over
    // the changed points within a body's size around it (a square of
    // kBodyWindow_m on the floor): a body turning in place moves its two
    // shoulders opposite ways, which cancel, as they do in the trajectory of
    // its centre; occlusion errors at its edges are averaged with its inside.
    ChangeMask(held.front().raw, held.back().raw, mask, &change);
    const double per_second = s.fps / span;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      moved[i] = change.at<unsigned char>(samples[i].pixel) != 0;
      along[i] = moved[i] ? Dot(FloorDisplacement(samples[i], flow.at<cv::Point2f>(samples[i].pixel)), axis) * per_second : 0.0;
    }
    // 5. Into the series.
    const std::size_t b = builder.Bin(t_mid);
    if (b == detail::SeriesBuilder::kNoBin) continue;
    builder.AddFrame(b, nullptr);
    for (const Sample& sample : samples) {
      double& v = used[&sample - samples.data()];
      v = 0.0;
      if (moved[&sample - samples.data()]) {
        const Grid& g = grids[sample.region];
        double sum = 0.0;
        int n = 0;
        for (int dy = -reach; dy <= reach; ++dy)
          for (int dx = -reach; dx <= reach; ++dx) {
            const int x = sample.ix + dx, y = sample.iy + dy;
            if (x < 0 || y < 0 || x >= g.nx || y >= g.ny) continue;
            const int j = g.sample[static_cast<std::size_t>(y) * g.nx + x];
            if (j >= 0 && moved[static_cast<std::size_t>(j)]) sum += along[static_cast<std::size_t>(j)], ++n;
          }
        // The window's mean tells which way (and whether) the body moves;
        // the point's own velocity, the speed (the mean is lowered by a
        // body's slower edges), where it agrees in sign.
        const double local = sum / n, own = along[&sample - samples.data()];
        v = (std::abs(local) > spec.still_speed_m_per_s && own * local > 0) ? own : local;
      }
      builder.AddSample(sample.region, b, v);
    }
    while (!pictures_left.empty() && pictures_left.front() <= t_mid + 0.5 / s.fps) {
      char name[64];
      std::snprintf(name, sizeof name, "flow_%08.2fs.png", t_mid);
      const std::filesystem::path file = options.picture_dir / name;
      DrawFlowPicture(frame, flow, samples, used, outlines, spec.still_speed_m_per_s, file);
      s.pictures.push_back(file);
      pictures_left.erase(pictures_left.begin());
    }
    if (options.progress && s.frames_read % 25 == 0) {
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      options.progress({s.frames_read, total_frames > 0 ? static_cast<std::size_t>(total_frames) : 0, t, elapsed});
    }
  }
  if (s.frames_read == 0) throw InputError(video.string() + ": no frame could be decoded; expected a readable video");
  const double last_frame_s = static_cast<double>(index - 1) / s.fps;
  if (options.from_s > last_frame_s)
    throw InputError(video.string() + ": --from " + FormatNumber(options.from_s) + " s is past the video's last frame at " +
                     FormatNumber(last_frame_s) + " s; expected a start within the video");
  // A container states its frame count; fewer decoded frames mean a cut file
  // (one frame fewer is within what containers misstate).
  if (!window_ended && total_frames > 0 && static_cast<double>(index) + 1.0 < total_frames)
    s.notes.push_back("the video states " + FormatNumber(total_frames) + " frames but only " + std::to_string(index) +
                      " could be decoded (up to " + FormatNumber(last_frame_s) +
                      " s): the file may be truncated; the observation ends there");
  if (s.flows == 0)
    s.notes.push_back("no usable velocity field: every span of " + std::to_string(span) +
                      " frames held a flagged frame, or the video is shorter than the span");
  if (builder.bins() == 0) builder.AddFrame(0, nullptr);  // an empty, all-NaN series of one bin
  // An onset lies within its bin; the velocities smear it by half their span.
  builder.Finish(&obs, false, false, spec.bin_s + 0.5 * span / s.fps);
  s.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  s.processing_fps = s.elapsed_s > 0 ? static_cast<double>(s.frames_read) / s.elapsed_s : 0.0;
  for (const std::string& n : s.notes) obs.notes.push_back(n);
  if (s.dark + s.flat + s.cut + s.frozen > 0)
    obs.notes.push_back("frames flagged and left out: " + std::to_string(s.dark) + " dark, " + std::to_string(s.flat) +
                        " flat, " + std::to_string(s.cut) + " cut, " + std::to_string(s.frozen) + " frozen");
  if (summary) *summary = s;
  return obs;
}

}  // namespace crowdrecon::observe
