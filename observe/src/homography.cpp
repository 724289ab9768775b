#include "crowdrecon/observe/homography.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/json_reader.hpp"

namespace crowdrecon::observe {

namespace {

Vec2 Apply(const std::array<double, 9>& m, Vec2 p) {
  const double w = m[6] * p.x + m[7] * p.y + m[8];
  return {(m[0] * p.x + m[1] * p.y + m[2]) / w, (m[3] * p.x + m[4] * p.y + m[5]) / w};
}

bool Invert(const std::array<double, 9>& m, std::array<double, 9>* out) {
  const double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                     m[2] * (m[3] * m[7] - m[4] * m[6]);
  double scale = 0.0;
  for (double v : m) scale = std::max(scale, std::abs(v));
  if (!(std::abs(det) > 1e-12 * scale * scale * scale) || !std::isfinite(det)) return false;
  const double k = 1.0 / det;
  *out = {(m[4] * m[8] - m[5] * m[7]) * k, (m[2] * m[7] - m[1] * m[8]) * k, (m[1] * m[5] - m[2] * m[4]) * k,
          (m[5] * m[6] - m[3] * m[8]) * k, (m[0] * m[8] - m[2] * m[6]) * k, (m[2] * m[3] - m[0] * m[5]) * k,
          (m[3] * m[7] - m[4] * m[6]) * k, (m[1] * m[6] - m[0] * m[7]) * k, (m[0] * m[4] - m[1] * m[3]) * k};
  return true;
}

}  // namespace

Vec2 Homography::ToImage(Vec2 floor_m) const { return Apply(h, floor_m); }
Vec2 Homography::ToFloor(Vec2 image_px) const { return Apply(inverse, image_px); }

bool Homography::InFront(Vec2 floor_m) const {
  // The matrix is scaled so that w > 0 in front of the camera (at the
  // pairs' centre, or at the floor's origin for a given matrix).
  const double w = h[6] * floor_m.x + h[7] * floor_m.y + h[8];
  return w > 0.0;
}

std::array<double, 4> Homography::FloorJacobianAt(Vec2 p) const {
  const std::array<double, 9>& g = inverse;
  const double a = g[0] * p.x + g[1] * p.y + g[2], b = g[3] * p.x + g[4] * p.y + g[5], c = g[6] * p.x + g[7] * p.y + g[8];
  const double c2 = c * c;
  return {(g[0] * c - a * g[6]) / c2, (g[1] * c - a * g[7]) / c2, (g[3] * c - b * g[6]) / c2, (g[4] * c - b * g[7]) / c2};
}

Homography HomographyFromMatrix(const std::array<double, 9>& m, const std::string& source) {
  Homography out;
  for (double v : m)
    if (!std::isfinite(v)) throw InputError(source + ": the homography matrix holds a value that is not a finite number");
  // Scaled so that w > 0 in front of the camera: a matrix and its negative
  // are the same homography; the one with h22 >= 0 is kept (the floor's
  // origin, usually in view, then maps with w > 0).
  out.h = m;
  if (m[8] < 0)
    for (double& v : out.h) v = -v;
  if (!Invert(out.h, &out.inverse))
    throw InputError(source + ": the homography matrix is singular; expected an invertible 3x3 matrix (floor -> image)");
  return out;
}

Homography HomographyFromPairs(const std::vector<PointPair>& pairs, const std::string& source) {
  if (pairs.size() < 4)
    throw InputError(source + ": " + std::to_string(pairs.size()) +
                     " point pairs; expected at least 4 image <-> floor pairs (no three floor points on a line)");
  std::vector<cv::Point2d> floor, image;
  for (const PointPair& p : pairs) {
    floor.emplace_back(p.floor_m.x, p.floor_m.y);
    image.emplace_back(p.image_px.x, p.image_px.y);
  }
  // Degenerate layouts: repeated points or every triple of floor points on a line.
  for (std::size_t i = 0; i < pairs.size(); ++i)
    for (std::size_t j = i + 1; j < pairs.size(); ++j)
      if (Length(pairs[i].floor_m - pairs[j].floor_m) < 1e-9 || Length(pairs[i].image_px - pairs[j].image_px) < 1e-9)
        throw InputError(source + ": pairs " + std::to_string(i + 1) + " and " + std::to_string(j + 1) +
                         " repeat a point; expected distinct points");
  double spread = 0.0;  // the largest triangle of floor points
  for (std::size_t i = 0; i < pairs.size(); ++i)
    for (std::size_t j = i + 1; j < pairs.size(); ++j)
      for (std::size_t k = j + 1; k < pairs.size(); ++k)
        spread = std::max(spread, std::abs(Cross(pairs[j].floor_m - pairs[i].floor_m, pairs[k].floor_m - pairs[i].floor_m)));
  if (!(spread > 1e-6)) throw InputError(source + ": the floor points lie on one line; expected points spanning an area");
  const cv::Mat m = cv::findHomography(floor, image, 0);
  if (m.empty() || m.rows != 3 || m.cols != 3)
    throw InputError(source + ": no homography fits these point pairs (are they in the same order on the floor and in the image?)");
  std::array<double, 9> a{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a[static_cast<std::size_t>(r * 3 + c)] = m.at<double>(r, c);
  Homography out = HomographyFromMatrix(a, source);
  // The sign that puts the pairs in front of the camera (w > 0 at their centre).
  Vec2 centre;
  for (const PointPair& p : pairs) centre += p.floor_m * (1.0 / static_cast<double>(pairs.size()));
  if (!out.InFront(centre)) {
    for (double& v : out.h) v = -v;
    for (double& v : out.inverse) v = -v;
  }
  out.pairs = pairs;
  double sum = 0.0;
  for (const PointPair& p : pairs) {
    if (!out.InFront(p.floor_m))
      throw InputError(source + ": the fitted homography puts floor point [" + FormatNumber(p.floor_m.x) + ", " +
                       FormatNumber(p.floor_m.y) + "] behind the camera; check the order of the pairs");
    sum += LengthSquared(out.ToImage(p.floor_m) - p.image_px);
  }
  out.rms_error_px = std::sqrt(sum / static_cast<double>(pairs.size()));
  return out;
}

Homography ParseHomography(const std::string& text, const std::string& source) {
  const JsonDocument doc = JsonDocument::Parse(text, source);
  const JsonReader root = doc.Root();
  if (!root.IsObject()) root.Fail("expected a homography (docs/observations.md)");
  if (root.String("format") != "crowdrecon-homography") root.At("format").Fail("expected \"crowdrecon-homography\"");
  root.Integer("version", 1, 1);
  const bool has_pairs = root.Has("pairs"), has_matrix = root.Has("matrix");
  if (has_pairs == has_matrix) root.Fail("expected exactly one of \"pairs\" and \"matrix\"");
  Homography h;
  if (has_pairs) {
    const JsonReader list = root.At("pairs");
    if (!list.IsArray()) list.Fail("expected a list of {\"image\": [u, v], \"floor\": [x, y]}");
    std::vector<PointPair> pairs;
    for (std::size_t i = 0; i < list.Size(); ++i) {
      const JsonReader p = list.Element(i);
      PointPair pair{p.At("image").AsPoint(), p.At("floor").AsPoint()};
      if (std::abs(pair.image_px.x) > 1e6 || std::abs(pair.image_px.y) > 1e6) p.At("image").Fail("a pixel beyond 1e6");
      if (std::abs(pair.floor_m.x) > 1e5 || std::abs(pair.floor_m.y) > 1e5) p.At("floor").Fail("a point beyond 1e5 m");
      p.Finish();
      pairs.push_back(pair);
    }
    h = HomographyFromPairs(pairs, source);
  } else {
    const JsonReader m = root.At("matrix");
    if (!m.IsArray() || m.Size() != 3) m.Fail("expected 3 rows of 3 numbers");
    std::array<double, 9> a{};
    for (std::size_t r = 0; r < 3; ++r) {
      const JsonReader row = m.Element(r);
      if (!row.IsArray() || row.Size() != 3) row.Fail("expected 3 numbers");
      for (std::size_t c = 0; c < 3; ++c) a[r * 3 + c] = row.Element(c).AsNumber(-1e12, 1e12);
    }
    h = HomographyFromMatrix(a, source);
  }
  if (const auto size = root.Find("image_size")) {
    const Vec2 s = size->AsPoint();
    if (!(s.x >= 1 && s.x <= 100000 && s.y >= 1 && s.y <= 100000 && s.x == std::floor(s.x) && s.y == std::floor(s.y)))
      size->Fail("expected [width, height] in whole pixels, 1 to 100000");
    h.image_width = static_cast<int>(s.x);
    h.image_height = static_cast<int>(s.y);
  }
  if (const auto notes = root.Find("notes")) (void)notes->Size();
  root.Finish();
  return h;
}

Homography ReadHomography(const std::filesystem::path& file) {
  return ParseHomography(ReadInputFile(file, "homography"), file.string());
}

std::string HomographyToJson(const Homography& h) {
  nlohmann::json j;
  j["format"] = "crowdrecon-homography";
  j["version"] = 1;
  if (!h.pairs.empty()) {
    j["pairs"] = nlohmann::json::array();
    for (const PointPair& p : h.pairs)
      j["pairs"].push_back({{"image", {p.image_px.x, p.image_px.y}}, {"floor", {p.floor_m.x, p.floor_m.y}}});
  } else {
    j["matrix"] = {{h.h[0], h.h[1], h.h[2]}, {h.h[3], h.h[4], h.h[5]}, {h.h[6], h.h[7], h.h[8]}};
  }
  if (h.image_width > 0) j["image_size"] = {h.image_width, h.image_height};
  return j.dump(2) + "\n";
}

}  // namespace crowdrecon::observe
