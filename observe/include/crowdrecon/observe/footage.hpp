// Observations from footage (issue 22): a video of a crowd seen by a camera
// whose image relates to the floor by a homography (homography.hpp).
//
//   observe::FootageOptions options;
//   observe::FootageSummary summary;
//   observe::Observation obs = observe::ObserveFootage("hallway.avi", observe::ReadHomography("h.json"),
//                                                      spec, options, &summary);
//
// Named steps, for each frame read (one pass, bounded memory: the last
// n + 1 frames, n = the frames in the spec's velocity span):
//   1. Check the picture in the regions: too dark (mean grey level), too flat
//      (contrast: occluded, covered or out of focus), cut (the grey-level
//      histogram jumps from the previous frame: another scene or camera) or
//      frozen (identical to the previous frame: a recorder repeating frames).
//      A flagged frame is left out, and so is every velocity spanning it.
//   2. Enhance contrast (CLAHE), so that a semi-dark picture keeps texture.
//   3. Dense optical flow (DIS or Farneback) from the frame n back to this one.
//   4. At the floor grid points of every region: the image displacement u at
//      the point's pixel, carried to the floor through the local Jacobian of
//      the homography, d = J u, and v = d / (n / fps), at the span's middle.
//   5. Into the series (observation.hpp) exactly as trajectories go: samples
//      moving forward, backward or still along the axis. Footage cannot count
//      people: shares are of the region's floor (people and floor), density
//      and flows are not given; speeds and the counter-flow share are of the
//      moving samples and so compare with trajectories.
// OpenCV stays inside the .cpp files.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "crowdrecon/observe/homography.hpp"
#include "crowdrecon/observe/observation.hpp"

namespace crowdrecon::observe {

struct FootageProgress {
  std::size_t frames_done = 0;
  std::size_t frames_total = 0;  // as the container says (0: unknown)
  double video_time_s = 0.0;
  double elapsed_s = 0.0;
};

struct FootageOptions {
  // "dis-medium" (DIS, medium preset: flow at full resolution), "dis-fast"
  // (DIS, fast preset: about three times faster, speeds lower on small
  // bodies) or "farneback". The synthetic-footage study measures each
  // (docs/observations.md).
  std::string flow = "dis-medium";
  // Spacing of the floor grid sampled in every region (m): a tenth of a
  // metre, a third of a body's depth, so that a person covers several points.
  double grid_spacing_m = 0.1;
  bool enhance = true;               // CLAHE before the flow (step 2)
  // Step 1's thresholds, on 8-bit grey levels in the regions: a mean below
  // min_brightness is too dark; a standard deviation below min_contrast is
  // too flat; a correlation with the previous frame (at an eighth of the
  // size, in the regions) below min_correlation is a cut.
  double min_brightness = 8.0;
  double min_contrast = 3.0;
  double min_correlation = 0.5;
  // Part of the video (s from its start).
  double from_s = 0.0;
  double to_s = std::numeric_limits<double>::infinity();
  // Diagnostic pictures: the flow field on the frames nearest these times,
  // written into picture_dir as flow_<time>s.png.
  std::vector<double> picture_times_s;
  std::filesystem::path picture_dir;
  std::function<void(const FootageProgress&)> progress;  // every 25 frames (may be empty)

  bool IsValid(std::string* error) const;
};

struct FootageSummary {
  std::string video;
  int width = 0, height = 0;
  double fps = 0.0;
  int span_frames = 0;
  std::size_t frames_read = 0;
  std::size_t flows = 0;            // velocity fields used
  std::size_t dark = 0, flat = 0, cut = 0, frozen = 0;  // frames flagged
  std::size_t grid_points = 0;      // floor points sampled in all regions
  double elapsed_s = 0.0;
  double processing_fps = 0.0;      // frames read per second of processing
  std::vector<std::filesystem::path> pictures;
  std::vector<std::string> notes;
  std::string BriefReport() const;
};

// Throws InputError for a video that cannot be opened or read, options out
// of range, a homography whose stated image size differs from the video's,
// or regions that fall outside the picture.
Observation ObserveFootage(const std::filesystem::path& video, const Homography& homography,
                           const ObservationSpec& spec, const FootageOptions& options, FootageSummary* summary);

}  // namespace crowdrecon::observe
