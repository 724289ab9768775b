// Footage (issue 22): a floor texture sliding at a known speed, seen through
// a tilted camera's homography, is observed at that speed everywhere in the
// picture (the flow carried to the floor through the homography's Jacobian);
// dark, cut and frozen frames are flagged and left out; homographies from
// pairs reproduce their pairs and refuse degenerate ones.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "crowdrecon/media/media.hpp"  // imread/imwrite/video through the codecs module (tests start without it)

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/observe/footage.hpp"
#include "crowdrecon/observe/homography.hpp"
#include "scratch.hpp"

namespace crowdrecon::observe {
namespace {

using crowdrecon::testing::ScratchFile;

// A camera over the floor window [0, 10] x [0, 5] m, near edge at the bottom
// of a 480 x 320 picture, far edge 0.6 of its width.
Homography Camera() {
  return HomographyFromPairs({{{10, 310}, {0, 0}}, {{470, 310}, {10, 0}}, {{378, 10}, {10, 5}}, {{102, 10}, {0, 5}}},
                             "test camera");
}

// Frames of a random texture on the floor sliding along +x at `speed`.
// `dark`, `cut`, `frozen`: frame indices drawn black, from another texture,
// or as a copy of the previous frame.
std::filesystem::path SlidingFloor(double speed, int frames, const std::vector<int>& dark, int cut,
                                   const std::vector<int>& frozen) {
  const double ppm = 40, fps = 25;
  cv::Mat texture(5 * 40, 40 * 40, CV_8UC1), other(texture.size(), CV_8UC1);
  cv::RNG rng(7);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 255);
  rng.fill(other, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.5);
  cv::GaussianBlur(other, other, cv::Size(0, 0), 1.5);
  const Homography h = Camera();
  const auto file = ScratchFile("sliding.avi");
  const std::unique_ptr<media::VideoWriter> writer = media::MakeVideoWriter();
  writer->Open(file.string(), cv::CAP_OPENCV_MJPEG, media::FourCc('M', 'J', 'P', 'G'), fps, cv::Size(480, 320), true);
  writer->Set(cv::VIDEOWRITER_PROP_QUALITY, 98);
  cv::Mat picture, previous;
  for (int k = 0; k < frames; ++k) {
    // Floor drawing pixel (u, v) shows floor point (u / ppm - 20 + speed t, 5 - v / ppm).
    const double shift = speed * k / fps;
    const cv::Mat drawing_to_floor = (cv::Mat_<double>(3, 3) << 1 / ppm, 0, -20 + shift, 0, -1 / ppm, 5, 0, 0, 1);
    const cv::Mat cam = (cv::Mat_<double>(3, 3) << h.h[0], h.h[1], h.h[2], h.h[3], h.h[4], h.h[5], h.h[6], h.h[7], h.h[8]);
    cv::warpPerspective(k == cut ? other : texture, picture, cam * drawing_to_floor, cv::Size(480, 320), cv::INTER_LINEAR);
    if (std::find(dark.begin(), dark.end(), k) != dark.end()) picture = cv::Mat::zeros(picture.size(), CV_8UC1);
    if (std::find(frozen.begin(), frozen.end(), k) != frozen.end()) picture = previous.clone();
    cv::Mat colour;
    cv::cvtColor(picture, colour, cv::COLOR_GRAY2BGR);
    writer->Write(colour);
    previous = picture.clone();
  }
  return file;
}

ObservationSpec FloorSpec() {
  ObservationSpec spec;
  spec.regions.push_back({"floor", {{1, 0.5}, {9, 0.5}, {9, 4.5}, {1, 4.5}}});
  spec.bin_s = 0.4;
  return spec;
}

TEST(Footage, ASlidingFloorIsSeenAtItsSpeedThroughATiltedCamera) {
  const auto video = SlidingFloor(0.6, 50, {}, -1, {});
  FootageSummary summary;
  const Observation obs = ObserveFootage(video, Camera(), FloorSpec(), FootageOptions{}, &summary);
  EXPECT_EQ(summary.frames_read, 50u);
  EXPECT_EQ(summary.dark + summary.flat + summary.cut + summary.frozen, 0u);
  EXPECT_EQ(summary.span_frames, 5);
  const Series* speed = obs.Find("speed", "floor", "forward");
  const Series* share = obs.Find("share_moving", "floor", "forward");
  ASSERT_TRUE(speed && share);
  int bins = 0;
  for (std::size_t k = 0; k < obs.bins; ++k) {
    if (std::isnan(speed->points[k].value)) continue;
    ++bins;
    // The far floor is seen at 0.6 of the near floor's scale: only the
    // Jacobian makes both read the same speed.
    EXPECT_NEAR(speed->points[k].value, 0.6, 0.03) << "bin " << k;
    EXPECT_GT(share->points[k].value, 0.95) << "bin " << k;
  }
  EXPECT_GE(bins, 4);
}

TEST(Footage, DarkCutAndFrozenFramesAreFlaggedAndLeftOut) {
  const auto video = SlidingFloor(0.6, 60, {20, 21, 22}, 40, {50, 51});
  FootageSummary summary;
  const Observation obs = ObserveFootage(video, Camera(), FloorSpec(), FootageOptions{}, &summary);
  EXPECT_EQ(summary.dark, 3u);
  // Frames 50 and 51 repeat their predecessors, and so do the dark frames
  // 21 and 22 (black after black).
  EXPECT_EQ(summary.frozen, 4u);
  // Into the other texture and out of it; into, through (a uniform black
  // frame correlates with nothing) and out of the dark frames.
  EXPECT_EQ(summary.cut, 6u);
  // Every velocity spanning a flagged frame is left out: of the 55 spans of
  // 5 frames, those touching frames 20-22, 40 and 50-51.
  EXPECT_LT(summary.flows, 40u);
  EXPECT_GT(summary.flows, 15u);
  for (const SeriesPoint& p : obs.Find("speed", "floor", "forward")->points)
    if (!std::isnan(p.value)) {
      EXPECT_NEAR(p.value, 0.6, 0.03);
    }
  bool noted = false;
  for (const std::string& n : obs.notes) noted = noted || n.find("3 dark") != std::string::npos;
  EXPECT_TRUE(noted);
}

// A start past the video's end is refused (before: an all-NaN observation
// with exit 0), and a video cut short says so (before: 16 of 31 frames were
// observed as if complete).
TEST(Footage, AStartPastTheEndIsRefusedAndACutVideoIsSaidToBeCut) {
  const auto video = SlidingFloor(0.6, 30, {}, -1, {});
  FootageOptions late;
  late.from_s = 100.0;
  try {
    ObserveFootage(video, Camera(), FloorSpec(), late, nullptr);
    ADD_FAILURE() << "a start past the end was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--from 100 s is past the video's last frame at 1.16 s"), std::string::npos)
        << e.what();
  }
  FootageSummary whole;
  const Observation complete = ObserveFootage(video, Camera(), FloorSpec(), FootageOptions{}, &whole);
  for (const std::string& n : complete.notes) EXPECT_EQ(n.find("truncated"), std::string::npos) << n;
  // The same file cut at 60 % of its bytes (the end of a copy that stopped).
  const auto cut = ScratchFile("cut.avi");
  std::filesystem::copy_file(video, cut, std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(cut, std::filesystem::file_size(video) * 6 / 10);
  FootageSummary summary;
  const Observation obs = ObserveFootage(cut, Camera(), FloorSpec(), FootageOptions{}, &summary);
  EXPECT_LT(summary.frames_read, 30u);
  bool said = false;
  for (const std::string& n : obs.notes)
    said = said || (n.find("the video states 30 frames but only " + std::to_string(summary.frames_read) +
                           " could be decoded") != std::string::npos &&
                    n.find("may be truncated") != std::string::npos);
  EXPECT_TRUE(said) << "frames read: " << summary.frames_read;
}

TEST(Homography, PairsAreReproducedAndDegenerateOnesRefused) {
  const Homography h = Camera();
  EXPECT_LT(h.rms_error_px, 1e-6);
  for (const PointPair& p : h.pairs) {
    EXPECT_NEAR(Length(h.ToImage(p.floor_m) - p.image_px), 0.0, 1e-6);
    EXPECT_NEAR(Length(h.ToFloor(p.image_px) - p.floor_m), 0.0, 1e-9);
  }
  // The Jacobian against central differences of ToFloor (their error is
  // of the order of the third derivative times (0.5 px)^2).
  const Vec2 p{240, 160};
  const auto j = h.FloorJacobianAt(p);
  const Vec2 dx = (h.ToFloor(p + Vec2{0.5, 0}) - h.ToFloor(p - Vec2{0.5, 0})), dy = (h.ToFloor(p + Vec2{0, 0.5}) - h.ToFloor(p - Vec2{0, 0.5}));
  EXPECT_NEAR(j[0], dx.x, 1e-7);
  EXPECT_NEAR(j[2], dx.y, 1e-7);
  EXPECT_NEAR(j[1], dy.x, 1e-7);
  EXPECT_NEAR(j[3], dy.y, 1e-7);
  const auto error = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error([] { HomographyFromPairs({{{0, 0}, {0, 0}}, {{1, 0}, {1, 0}}, {{0, 1}, {0, 1}}}, "h"); }).find("at least 4"),
            std::string::npos);
  EXPECT_NE(error([] { HomographyFromPairs({{{0, 0}, {0, 0}}, {{1, 0}, {1, 0}}, {{2, 0}, {2, 0}}, {{3, 1}, {3, 0}}}, "h"); })
                .find("on one line"),
            std::string::npos);
  EXPECT_NE(error([] { HomographyFromPairs({{{0, 0}, {0, 0}}, {{0, 0}, {1, 0}}, {{2, 0}, {2, 1}}, {{3, 1}, {3, 0}}}, "h"); })
                .find("repeat a point"),
            std::string::npos);
  EXPECT_NE(error([] { HomographyFromMatrix({1, 2, 3, 2, 4, 6, 0, 0, 1}, "h"); }).find("singular"), std::string::npos);
  EXPECT_NE(error([] { ParseHomography(R"({"format": "crowdrecon-homography", "version": 1, "matrix": [[1, 0, 0], [0, 1, 0]]})", "h.json"); })
                .find("h.json: /matrix"),
            std::string::npos);
}

}  // namespace
}  // namespace crowdrecon::observe
