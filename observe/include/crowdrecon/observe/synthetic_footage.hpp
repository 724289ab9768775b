// Synthetic footage of a simulated run, for checking what footage analysis
// recovers against the run's own trajectories (issue 22). Named steps, per
// video frame:
//   1. Draw the floor from above: tiles with a fixed texture (a real floor
//      is never blank), the walls, and every person's body filled, with
//      spots of clothing fixed to the body so that it has texture to follow;
//      no force lines. Periodic runs are drawn with their images across seams.
//   2. Warp it with a known perspective homography, as a ceiling camera at an
//      angle sees the floor: the near edge of the floor window spans the
//      picture's width, the far edge `far_width` of it.
//   3. Degrade: darkness (grey levels scaled by 1 - darkness, like the
//      semi-dark hallway), Gaussian blur, sensor noise (Gaussian, seeded),
//      a lower frame rate (every k-th frame of the run), and lossy
//      compression (Motion-JPEG at a stated quality).
//   4. Encode (AVI, Motion-JPEG) and write the homography (floor <-> image
//      pairs at the window's corners) beside it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "crowdrecon/observe/homography.hpp"

namespace crowdrecon::observe {

struct SyntheticFootageOptions {
  int width_px = 960, height_px = 480;
  // Width of the far edge of the floor window in the picture, as a share of
  // the near edge's (1: seen straight from above).
  double far_width = 0.6;
  // Floor window drawn (m); empty (x1 <= x0): the run's periodic box, else
  // the bounding box of its walls.
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  double pixels_per_metre = 100;  // of the floor drawing before the warp
  // Step 3.
  double darkness = 0.0;          // [0, 1)
  double blur_sigma_px = 0.0;
  double noise_sigma = 0.0;       // grey levels (of 255)
  int frame_step = 1;             // every k-th frame of the run
  int jpeg_quality = 95;          // 1-100
  std::uint64_t seed = 1;
  std::function<void(std::size_t done, std::size_t total)> progress;  // may be empty

  bool IsValid(std::string* error) const;
};

struct SyntheticFootageSummary {
  std::size_t frames = 0;
  double fps = 0.0;
  double first_time_s = 0.0;  // run time of the video's first frame
  Homography homography;      // floor -> picture
  std::vector<std::filesystem::path> removed_partials;  // unfinished videos of killed runs of synthesize
};

// Writes `video` (.avi) and `homography_file` (JSON). Throws InputError for
// a file that is no run, options out of range, or outputs that cannot be written.
SyntheticFootageSummary RenderSyntheticFootage(const std::filesystem::path& run_file,
                                               const SyntheticFootageOptions& options,
                                               const std::filesystem::path& video,
                                               const std::filesystem::path& homography_file);

}  // namespace crowdrecon::observe
