// Reading outlines from images (OpenCV) and point lists (JSON, CSV).
#include "crowdrecon/geometry/outline.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/common/json_reader.hpp"
#include "crowdrecon/geometry/input_limits.hpp"
#include "box_pairs.hpp"
#include "image_file.hpp"
#include "outline_cgal.hpp"

namespace crowdrecon::geometry {

namespace {

std::string PointText(Vec2 p) { return "(" + FormatNumber(p.x) + ", " + FormatNumber(p.y) + ")"; }

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool SegmentsCross(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  const double d1 = Cross(b - a, c - a), d2 = Cross(b - a, d - a);
  const double d3 = Cross(d - c, a - c), d4 = Cross(d - c, b - c);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return true;
  // Touching or collinear overlap also makes the ring non-simple.
  const auto on = [](Vec2 p, Vec2 q, Vec2 r) {  // r on segment pq, given collinear
    return std::min(p.x, q.x) <= r.x && r.x <= std::max(p.x, q.x) && std::min(p.y, q.y) <= r.y &&
           r.y <= std::max(p.y, q.y);
  };
  return (d1 == 0 && on(a, b, c)) || (d2 == 0 && on(a, b, d)) || (d3 == 0 && on(c, d, a)) ||
         (d4 == 0 && on(c, d, b));
}

// Names the first pair of non-adjacent edges that cross (for the error message;
// only called once CGAL has said the ring is not simple; only edges whose
// bounding boxes overlap are compared, so a ring of 1e6 points takes no longer
// than its sorting).
std::string DescribeSelfIntersection(const std::vector<Vec2>& ring) {
  const std::size_t n = ring.size();
  for (const auto& [i, j] : detail::OverlappingPairs(detail::EdgeBoxes(ring))) {
    const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
    if (adjacent) continue;
    if (SegmentsCross(ring[i], ring[(i + 1) % n], ring[j], ring[(j + 1) % n]))
      return "edge " + std::to_string(i) + " " + PointText(ring[i]) + "-" + PointText(ring[(i + 1) % n]) +
             " crosses edge " + std::to_string(j) + " " + PointText(ring[j]) + "-" + PointText(ring[(j + 1) % n]);
  }
  return "an edge folds back onto its neighbour";
}

// Throws GeometryError, naming `where`, if a coordinate is not finite or is
// too large for a body outline in any unit (input_limits.hpp): beyond it the
// squared lengths the geometry is built on overflow or lose every digit.
void CheckOutlinePoint(Vec2 p, const std::string& where) {
  for (const double c : {p.x, p.y}) {
    if (!std::isfinite(c))
      throw GeometryError(where + ": coordinate " + FormatNumber(c) + " is not finite; expected finite x, y");
    if (std::abs(c) > kMaxOutlineCoordinate)
      throw GeometryError(where + ": coordinate " + FormatNumber(c) + " is beyond " +
                          FormatNumber(kMaxOutlineCoordinate) +
                          " in magnitude; expected a body outline a few thousand units across at most "
                          "(metres, millimetres or pixels): check the scale/units");
  }
}

// Points of a JSON array [[x, y], ...], each checked where it stands.
std::vector<Vec2> JsonOutlinePoints(const JsonReader& array) {
  std::vector<Vec2> points = array.AsPoints(0);
  for (std::size_t i = 0; i < points.size(); ++i) CheckOutlinePoint(points[i], array.Element(i).Where());
  return points;
}

// Drops the vertices that lie exactly on the straight line between their
// neighbours (a densely sampled straight edge): the polygon is the same, but
// the polyline simplification of BuildBody slows down with the cube of the
// number of collinear vertices (a 2.9 m square given every 0.15 mm: over a
// minute). Vertices where the ring turns back (spikes) stay, for the
// self-intersection check to name.
std::vector<Vec2> WithoutStraightRuns(std::vector<Vec2> ring) {
  const auto straight = [](Vec2 a, Vec2 b, Vec2 c) { return Cross(b - a, c - b) == 0.0 && Dot(b - a, c - b) > 0.0; };
  std::vector<Vec2> out;
  out.reserve(ring.size());
  for (const Vec2& p : ring) {
    while (out.size() >= 2 && straight(out[out.size() - 2], out.back(), p)) out.pop_back();
    out.push_back(p);
  }
  // Across the closing edge: the last and the first vertices.
  std::size_t first = 0;
  while (out.size() - first >= 4) {
    if (straight(out[out.size() - 2], out.back(), out[first])) {
      out.pop_back();
    } else if (straight(out.back(), out[first], out[first + 1])) {
      ++first;
    } else {
      break;
    }
  }
  return {out.begin() + static_cast<std::ptrdiff_t>(first), out.end()};
}

// Extracts {"points": ...} or a bare array.
Outline ParseJsonOutline(const std::filesystem::path& file) {
  const JsonDocument doc = JsonDocument::Load(file);
  const JsonReader root = doc.Root();
  Outline outline;
  outline.source = file.string();
  if (root.IsArray()) {
    outline.points = JsonOutlinePoints(root);
  } else if (root.IsObject()) {
    outline.points = JsonOutlinePoints(root.At("points"));
    if (root.Has("front")) {
      const JsonReader front = root.At("front");
      outline.front = FrontAxisFromString(front.AsString(), front.Where());
    }
    outline.description = root.String("description", "");
    root.Finish();
  } else {
    root.Fail("expected an outline: [[x, y], ...] or {\"points\": [[x, y], ...]}, found " +
              root.ValueText());
  }
  return outline;
}

Outline ParseCsvOutline(const std::filesystem::path& file) {
  CheckInputFile(file, "CSV outline file");
  std::ifstream in(file, std::ios::binary);
  Outline outline;
  outline.source = file.string();
  std::string line;
  std::size_t line_no = 0;
  bool seen_data = false, header_skipped = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto comma = line.find(',');
    const std::string where = file.string() + ":" + std::to_string(line_no);
    if (comma == std::string::npos)
      throw InputError(where + ": expected \"x,y\", found \"" + line + "\"");
    const std::string xs = line.substr(0, comma), ys = line.substr(comma + 1);
    char* end_x = nullptr;
    char* end_y = nullptr;
    const double x = std::strtod(xs.c_str(), &end_x);
    const double y = std::strtod(ys.c_str(), &end_y);
    const auto rest_blank = [](const char* p) {
      while (*p == ' ' || *p == '\t') ++p;
      return *p == '\0';
    };
    const bool numeric = end_x != xs.c_str() && end_y != ys.c_str() && rest_blank(end_x) &&
                         rest_blank(end_y);
    if (!numeric) {
      if (!seen_data && !header_skipped) {  // a header such as "x,y"
        header_skipped = true;
        continue;
      }
      throw InputError(where + ": expected two numbers \"x,y\", found \"" + line + "\"");
    }
    seen_data = true;
    CheckOutlinePoint({x, y}, where);
    outline.points.push_back({x, y});
  }
  return outline;
}

}  // namespace

std::string ToString(ImageRegion region) { return region == ImageRegion::kDark ? "dark" : "light"; }

ImageRegion ImageRegionFromString(const std::string& text, const std::string& what) {
  if (text == "dark") return ImageRegion::kDark;
  if (text == "light") return ImageRegion::kLight;
  throw InputError(what + ": unknown region \"" + text + "\"; expected dark or light");
}

std::string ToString(FrontAxis front) {
  switch (front) {
    case FrontAxis::kPlusX: return "+x";
    case FrontAxis::kMinusX: return "-x";
    case FrontAxis::kPlusY: return "+y";
    case FrontAxis::kMinusY: return "-y";
  }
  return "?";
}

FrontAxis FrontAxisFromString(const std::string& text, const std::string& what) {
  if (text == "+x" || text == "x") return FrontAxis::kPlusX;
  if (text == "-x") return FrontAxis::kMinusX;
  if (text == "+y" || text == "y") return FrontAxis::kPlusY;
  if (text == "-y") return FrontAxis::kMinusY;
  throw InputError(what + ": unknown front axis \"" + text + "\"; expected +x, -x, +y or -y");
}

Vec2 FrontVector(FrontAxis front) {
  switch (front) {
    case FrontAxis::kPlusX: return {1, 0};
    case FrontAxis::kMinusX: return {-1, 0};
    case FrontAxis::kPlusY: return {0, 1};
    case FrontAxis::kMinusY: return {0, -1};
  }
  return {1, 0};
}

Vec2 RingCentroid(const std::vector<Vec2>& ring) {
  // Relative to the first vertex, so that far-from-origin pixel coordinates do
  // not lose digits.
  const Vec2 o = ring.front();
  double twice_area = 0.0;
  Vec2 sum;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Vec2 p = ring[i] - o, q = ring[(i + 1) % ring.size()] - o;
    const double c = Cross(p, q);
    twice_area += c;
    sum += (p + q) * c;
  }
  return o + sum / (3.0 * twice_area);
}

std::vector<Vec2> ValidateOutlineRing(std::vector<Vec2> points, const std::string& what) {
  for (std::size_t i = 0; i < points.size(); ++i) CheckOutlinePoint(points[i], what + ": point " + std::to_string(i));
  // Drop consecutive repeats and an explicit closing point.
  std::vector<Vec2> ring;
  ring.reserve(points.size());
  for (const Vec2& p : points)
    if (ring.empty() || !(ring.back() == p)) ring.push_back(p);
  while (ring.size() > 1 && ring.back() == ring.front()) ring.pop_back();
  ring = WithoutStraightRuns(std::move(ring));
  if (ring.size() < 3)
    throw GeometryError(what + ": too few points (" + std::to_string(ring.size()) +
                        " distinct); expected at least 3 forming a closed outline");
  if (!detail::IsSimpleRing(ring))
    throw GeometryError(what + ": the outline intersects itself (" + DescribeSelfIntersection(ring) +
                        "); expected a simple closed outline");
  double twice_area = 0.0;
  for (std::size_t i = 0; i < ring.size(); ++i) twice_area += Cross(ring[i], ring[(i + 1) % ring.size()]);
  if (twice_area == 0.0)
    throw GeometryError(what + ": the outline has zero area; expected a closed outline");
  if (twice_area < 0.0) std::reverse(ring.begin(), ring.end());
  return ring;
}

Outline ReadOutlineImage(const std::filesystem::path& file, const ImageOutlineOptions& options) {
  const std::string name = file.string();
  cv::Mat image = detail::ReadImage(file, cv::IMREAD_UNCHANGED);
  if (image.empty())
    throw InputError(name + ": not a readable image (empty or unknown format); expected a PNG, "
                            "JPEG, BMP or TIFF picture");
  // Grey levels; transparent pixels count as white (the usual background of a
  // drawn outline), whatever colour their RGB channels hold.
  cv::Mat grey;
  if (image.channels() == 4) {
    std::vector<cv::Mat> channels;
    cv::split(image, channels);
    cv::Mat bgr;
    cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    cv::Mat alpha = channels[3];
    if (image.depth() != CV_8U) throw InputError(name + ": expected an 8-bit image");
    grey.setTo(255, alpha < 128);
  } else if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = image;
  }
  if (grey.depth() != CV_8U) grey.convertTo(grey, CV_8U, grey.depth() == CV_16U ? 1.0 / 257.0 : 1.0);

  cv::Mat mask;
  const auto threshold = static_cast<double>(options.threshold);
  if (options.region == ImageRegion::kDark)
    cv::threshold(grey, mask, threshold - 0.5, 255, cv::THRESH_BINARY_INV);
  else
    cv::threshold(grey, mask, threshold - 0.5, 255, cv::THRESH_BINARY);
  // A 3x3 opening removes one-pixel spurs and necks, whose traced border would
  // run back over itself and not be a simple polygon. It moves smooth borders
  // by less than a pixel.
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));

  // Straight runs of the border (horizontal, vertical, diagonal) keep only
  // their ends: the same polygon, but the polyline simplification of
  // BuildBody slows down with the cube of the number of collinear vertices
  // (a 2000 x 2000 dark square: 31 s with every border pixel kept).
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  const std::string region = ToString(options.region);
  if (contours.empty())
    throw GeometryError(name + ": no " + region + " region (grey level " +
                        (options.region == ImageRegion::kDark ? "below " : "at or above ") +
                        std::to_string(options.threshold) + ") wider than 2 pixels in the " +
                        std::to_string(grey.cols) + " x " + std::to_string(grey.rows) +
                        " image; expected a body drawn " + region + " on a " +
                        (options.region == ImageRegion::kDark ? "light" : "dark") +
                        " background (see --region)");
  std::size_t best = 0;
  double best_area = -1.0;
  for (std::size_t i = 0; i < contours.size(); ++i) {
    const double a = cv::contourArea(contours[i]);
    if (a > best_area) { best_area = a; best = i; }
  }
  Outline outline;
  outline.source = name;
  outline.from_image = true;
  outline.region = region;
  // Pixel centres, y up: the contour runs through the centres of the region's
  // border pixels (BuildBody accounts for the half pixel between them and the edge).
  const auto rows = static_cast<double>(grey.rows);
  for (const cv::Point& p : contours[best])
    outline.points.push_back({static_cast<double>(p.x), rows - 1.0 - static_cast<double>(p.y)});
  bool touches_border = false;
  for (const cv::Point& p : contours[best])
    if (p.x == 0 || p.y == 0 || p.x == grey.cols - 1 || p.y == grey.rows - 1) touches_border = true;
  if (touches_border)
    outline.notes.push_back("the " + region + " region touches the image border; it may be cut off");
  outline.points = ValidateOutlineRing(std::move(outline.points), name + ": " + region + " region");
  // The region's own area (holes filled: the body is its outer border).
  cv::Mat filled = cv::Mat::zeros(mask.size(), CV_8UC1);
  cv::drawContours(filled, contours, static_cast<int>(best), cv::Scalar(255), cv::FILLED);
  outline.region_area_units2 = static_cast<double>(cv::countNonZero(filled));
  const double contour_length = cv::arcLength(contours[best], /*closed=*/true);
  outline.edge_allowance_units =
      std::clamp((outline.region_area_units2 - best_area) / contour_length, 0.0, 1.0);
  return outline;
}

Outline ReadOutlinePoints(const std::filesystem::path& file) {
  const std::string ext = Lower(file.extension().string());
  if (!std::filesystem::exists(file)) throw InputError(file.string() + ": cannot open file (it does not exist)");
  CheckInputFile(file, ext == ".csv" ? "point list (CSV)" : "point list (JSON)");
  Outline outline = ext == ".csv" ? ParseCsvOutline(file) : ParseJsonOutline(file);
  outline.points = ValidateOutlineRing(std::move(outline.points), file.string());
  return outline;
}

Outline ReadOutline(const std::filesystem::path& file, const ImageOutlineOptions& options) {
  const std::string ext = Lower(file.extension().string());
  if (ext == ".json" || ext == ".csv") return ReadOutlinePoints(file);
  return ReadOutlineImage(file, options);
}

OutputKind OutlineJsonOutput() {
  return JsonOutputKind("an outline JSON (points)", [](const nlohmann::json& j) {
    if (!j.contains("points")) return false;
    for (const auto& [key, value] : j.items())
      if (key != "points" && key != "description" && key != "front") return false;
    return true;
  });
}

void WriteOutlineJson(const Outline& outline, const std::filesystem::path& file) {
  nlohmann::ordered_json j;
  if (!outline.description.empty()) j["description"] = outline.description;
  if (outline.front) j["front"] = ToString(*outline.front);
  nlohmann::ordered_json points = nlohmann::ordered_json::array();
  for (const Vec2& p : outline.points) {
    // 0.1 micrometre resolution is plenty for outlines in metres and keeps files small.
    points.push_back({std::round(p.x * 1e7) / 1e7, std::round(p.y * 1e7) / 1e7});
  }
  j["points"] = points;
  WriteFileAtomically(file, j.dump(1) + '\n');
}

}  // namespace crowdrecon::geometry
