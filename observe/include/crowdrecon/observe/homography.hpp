// The homography between a camera's image and the floor: a 3x3 matrix H with
//   image ~ H (x, y, 1)^T     (floor metres to image pixels, up to scale),
// given as a matrix or fitted to at least four image <-> floor point pairs
// (least squares over all pairs, OpenCV's findHomography without outlier
// rejection: the user's pairs are trusted and their fit reported).
//
// File (JSON, docs/observations.md):
//   {"format": "crowdrecon-homography", "version": 1,
//    "pairs": [{"image": [u, v], "floor": [x, y]}, ...]}      at least 4
//   or "matrix": [[h00, h01, h02], [h10, h11, h12], [h20, h21, h22]]
//   optional "image_size": [width, height] (checked against the video)
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "crowdrecon/common/vec2.hpp"

namespace crowdrecon::observe {

struct PointPair {
  Vec2 image_px;
  Vec2 floor_m;
};

struct Homography {
  std::array<double, 9> h{1, 0, 0, 0, 1, 0, 0, 0, 1};  // row major, floor -> image
  std::array<double, 9> inverse{1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::vector<PointPair> pairs;  // as given (empty for a matrix)
  double rms_error_px = 0.0;     // of the pairs mapped by h (0 for a matrix)
  int image_width = 0, image_height = 0;  // 0: not stated

  Vec2 ToImage(Vec2 floor_m) const;
  Vec2 ToFloor(Vec2 image_px) const;
  // d(floor)/d(image) at an image point, row major [dx/du, dx/dv, dy/du, dy/dv]
  // (metres per pixel): carries an image displacement to the floor.
  std::array<double, 4> FloorJacobianAt(Vec2 image_px) const;
  // Whether a floor point lies in front of the camera (positive depth).
  bool InFront(Vec2 floor_m) const;
};

// From a matrix (floor -> image); throws InputError if it is singular.
Homography HomographyFromMatrix(const std::array<double, 9>& h, const std::string& source);
// Fitted to pairs; throws InputError (naming `source`) for fewer than four
// pairs, repeated or collinear points, or a fit that fails.
Homography HomographyFromPairs(const std::vector<PointPair>& pairs, const std::string& source);
Homography ReadHomography(const std::filesystem::path& file);
Homography ParseHomography(const std::string& text, const std::string& source);
std::string HomographyToJson(const Homography& h);

}  // namespace crowdrecon::observe
