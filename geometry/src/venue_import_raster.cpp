// Raster floor plans: dark pixels are walls, the chosen free region is the
// walkable area.
//
// Steps: threshold (OpenCV) -> 4-connected free components -> choose one (seed
// or largest enclosed) -> trace its boundary along pixel edges -> simplify all
// rings together with CGAL Polyline_simplification_2 -> venue.
//
// The boundary is traced along pixel *edges* (cracks) rather than through
// pixel centres (cv::findContours): the polygon through the crack midpoints
// encloses the component's pixels less 1/8 px^2 per convex corner, so the
// area is right to the pixel, whereas centre contours lose half a pixel all
// around (about 1 % for a 10 m x 4 m room at 50 px/m).
// GCC's -Wnull-dereference fires inside CGAL's inlined triangulation and
// container code after optimisation, where the system-header exemption no
// longer applies (CGAL's own sentinels); silence it for this file only.
#pragma GCC diagnostic ignored "-Wnull-dereference"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_plus_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polyline_simplification_2/simplify.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "image_file.hpp"
#include "venue_internal.hpp"

namespace crowdrecon::geometry {

namespace {

namespace PS = CGAL::Polyline_simplification_2;
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = PS::Vertex_base_2<Kernel>;
using Fb = CGAL::Constrained_triangulation_face_base_2<Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;
using Ct = CGAL::Constrained_triangulation_plus_2<Cdt>;

// Loops of pixel edges around the pixels of `mask` (value 1), in pixel units
// with y down. Every loop keeps the region on its right (clockwise on screen
// for outer boundaries, counter-clockwise for holes).
std::vector<std::vector<Vec2>> TraceCracks(const cv::Mat& mask) {
  const int rows = mask.rows, cols = mask.cols;
  auto in = [&](int r, int c) { return r >= 0 && c >= 0 && r < rows && c < cols && mask.at<std::uint8_t>(r, c) != 0; };
  const auto vertex = [&](int x, int y) { return static_cast<std::size_t>(y) * static_cast<std::size_t>(cols + 1) + static_cast<std::size_t>(x); };
  struct Edge {
    int x0, y0, dx, dy;
    bool used = false;
  };
  std::vector<Edge> edges;
  // Outgoing edges per vertex (at most two, at a saddle), for boundary
  // vertices only: a dense array over the image would cost 16 bytes a pixel.
  std::unordered_map<std::size_t, std::array<std::int64_t, 2>> out;
  auto add = [&](int x0, int y0, int dx, int dy) {
    auto [it, inserted] = out.try_emplace(vertex(x0, y0), std::array<std::int64_t, 2>{-1, -1});
    auto& slots = it->second;
    (slots[0] < 0 ? slots[0] : slots[1]) = static_cast<std::int64_t>(edges.size());
    edges.push_back({x0, y0, dx, dy});
  };
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      if (!in(r, c)) continue;
      if (!in(r - 1, c)) add(c, r, 1, 0);           // top, left to right
      if (!in(r, c + 1)) add(c + 1, r, 0, 1);       // right, downward
      if (!in(r + 1, c)) add(c + 1, r + 1, -1, 0);  // bottom, right to left
      if (!in(r, c - 1)) add(c, r + 1, 0, -1);      // left, upward
    }
  std::vector<std::vector<Vec2>> loops;
  for (std::size_t start = 0; start < edges.size(); ++start) {
    if (edges[start].used) continue;
    // The loop's vertices are the midpoints of its pixel edges: a staircase
    // of a slanted wall then has its vertices on the wall's line (so that the
    // simplification can remove them), and at a saddle the two loops cut the
    // corners of different pixels instead of touching. Where two straight
    // runs of at least two edges meet (a drawn corner, not a stair step), the
    // pixel corner itself is kept, so that rectangles come out exact.
    std::vector<std::size_t> chain;
    std::size_t e = start;
    while (!edges[e].used) {
      edges[e].used = true;
      chain.push_back(e);
      const Edge& cur = edges[e];
      const auto& slots = out.at(vertex(cur.x0 + cur.dx, cur.y0 + cur.dy));
      std::size_t next = static_cast<std::size_t>(slots[0]);
      if (slots[1] >= 0) {
        // Two region pixels meet diagonally here. Turning right keeps hugging
        // the same pixel, i.e. treats the region as 4-connected, as the
        // component labelling did.
        const Edge& a = edges[static_cast<std::size_t>(slots[0])];
        const bool a_is_right = a.dx == -cur.dy && a.dy == cur.dx;
        next = static_cast<std::size_t>(a_is_right ? slots[0] : slots[1]);
      }
      e = next;
    }
    const std::size_t m = chain.size();
    auto same = [&](std::size_t i, std::size_t j) {
      const Edge& p = edges[chain[i % m]];
      const Edge& q = edges[chain[j % m]];
      return p.dx == q.dx && p.dy == q.dy;
    };
    std::vector<Vec2> loop;
    for (std::size_t i = 0; i < m; ++i) {
      const Edge& cur = edges[chain[i]];
      loop.push_back({cur.x0 + 0.5 * cur.dx, cur.y0 + 0.5 * cur.dy});
      const std::size_t j = i + 1;
      const int cx = cur.x0 + cur.dx, cy = cur.y0 + cur.dy;
      const bool saddle = out.at(vertex(cx, cy))[1] >= 0;  // keep cutting there: rings must not touch
      if (!same(i, j) && m >= 4 && same(i + m - 1, i) && same(j, j + 1) && !saddle) loop.push_back(Vec2(cx, cy));
    }
    // Straight runs keep only their ends (coordinates are half-integers, so
    // the collinearity test is exact).
    std::vector<Vec2> corners;
    const std::size_t n = loop.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2 prev = loop[(i + n - 1) % n], here = loop[i], next = loop[(i + 1) % n];
      if (Cross(here - prev, next - here) != 0.0) corners.push_back(here);
    }
    loops.push_back(std::move(corners));
  }
  return loops;
}

int ChooseComponent(const cv::Mat& labels, const cv::Mat& stats, int count, const RasterImportOptions& options,
                    const std::string& origin) {
  const int rows = labels.rows, cols = labels.cols;
  if (options.seed_m) {
    const Vec2 s = *options.seed_m;
    const double col = std::floor(s.x * options.pixels_per_metre);
    const double row = static_cast<double>(rows) - 1.0 - std::floor(s.y * options.pixels_per_metre);
    if (col < 0 || row < 0 || col >= cols || row >= rows)
      throw InputError(origin + ": seed point (" + FormatNumber(s.x) + ", " + FormatNumber(s.y) +
                       ") m is outside the image, which spans (0, 0) to (" +
                       FormatNumber(cols / options.pixels_per_metre) + ", " +
                       FormatNumber(rows / options.pixels_per_metre) + ") m");
    const int label = labels.at<int>(static_cast<int>(row), static_cast<int>(col));
    if (label == 0)
      throw InputError(origin + ": seed point (" + FormatNumber(s.x) + ", " + FormatNumber(s.y) +
                       ") m falls on a dark (wall) pixel; expected a point in the free region");
    return label;
  }
  int best = 0;
  for (int label = 1; label < count; ++label) {
    const int left = stats.at<int>(label, cv::CC_STAT_LEFT), top = stats.at<int>(label, cv::CC_STAT_TOP);
    const int width = stats.at<int>(label, cv::CC_STAT_WIDTH), height = stats.at<int>(label, cv::CC_STAT_HEIGHT);
    if (left == 0 || top == 0 || left + width == cols || top + height == rows) continue;  // outside the building
    if (best == 0 || stats.at<int>(label, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) best = label;
  }
  if (best == 0)
    throw GeometryError(origin + ": no enclosed free region: every region of light pixels touches the image "
                                 "border (is the outline closed? is --dark-threshold right?); expected walls "
                                 "enclosing the walkable area, or give a seed point");
  return best;
}

// Simplifies all rings together so that they cannot cross each other
// (Constrained_triangulation_plus_2 keeps the constraints' topology).
std::vector<Ring> Simplify(const std::vector<Ring>& rings, double tolerance_m) {
  Ct ct;
  std::vector<Ct::Constraint_id> ids;
  for (const Ring& ring : rings) {
    std::vector<Kernel::Point_2> points;
    for (Vec2 p : ring) points.emplace_back(p.x, p.y);
    ids.push_back(ct.insert_constraint(points.begin(), points.end(), /*close=*/true));
  }
  if (tolerance_m > 0.0)
    PS::simplify(ct, PS::Squared_distance_cost(), PS::Stop_above_cost_threshold(tolerance_m * tolerance_m));
  std::vector<Ring> out;
  for (const auto& id : ids) {
    Ring ring;
    for (auto it = ct.points_in_constraint_begin(id); it != ct.points_in_constraint_end(id); ++it)
      ring.push_back({it->x(), it->y()});
    if (ring.size() >= 2 && ring.front() == ring.back()) ring.pop_back();
    out.push_back(std::move(ring));
  }
  return out;
}

}  // namespace

Venue ImportRasterPlan(const std::filesystem::path& file, const RasterImportOptions& options) {
  const std::string origin = file.string();
  if (!(options.pixels_per_metre > 0.0) || !std::isfinite(options.pixels_per_metre))
    throw InputError(origin + ": pixels per metre is " + FormatNumber(options.pixels_per_metre) +
                     "; expected a positive scale (--pixels-per-metre)");
  if (options.dark_threshold < 1 || options.dark_threshold > 255)
    throw InputError(origin + ": dark threshold " + std::to_string(options.dark_threshold) +
                     " is out of range; expected a grey level in [1, 255]");
  const cv::Mat grey = detail::ReadImage(file, cv::IMREAD_GRAYSCALE);
  if (grey.empty()) throw InputError(origin + ": cannot read the file as an image (PNG, JPEG, BMP, TIFF, ...)");

  // 1. Free pixels and their 4-connected components.
  cv::Mat free_mask;
  cv::threshold(grey, free_mask, options.dark_threshold - 1, 1, cv::THRESH_BINARY);  // >= threshold -> 1
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(free_mask, labels, stats, centroids, 4, CV_32S);
  const int chosen = ChooseComponent(labels, stats, count, options, origin);
  const cv::Mat region = (labels == chosen) / 255;  // 0/1

  // 2. Crack boundary in metres, y up from the image's lower-left corner.
  const double ppm = options.pixels_per_metre;
  const double rows = static_cast<double>(grey.rows);
  std::vector<Ring> rings;
  for (const auto& loop : TraceCracks(region)) {
    Ring ring;
    ring.reserve(loop.size());
    for (Vec2 p : loop) ring.push_back({p.x / ppm, (rows - p.y) / ppm});
    rings.push_back(std::move(ring));
  }
  // The outer boundary is the loop of largest area (the component is
  // connected, so there is exactly one); the others are holes, of which
  // specks below the size limit are dropped (filled in as walkable).
  std::size_t outer = 0;
  for (std::size_t i = 1; i < rings.size(); ++i)
    if (std::abs(RingSignedArea_m2(rings[i])) > std::abs(RingSignedArea_m2(rings[outer]))) outer = i;
  std::vector<Ring> kept{rings[outer]};
  for (std::size_t i = 0; i < rings.size(); ++i)
    if (i != outer && std::abs(RingSignedArea_m2(rings[i])) >= options.min_obstacle_area_m2) kept.push_back(rings[i]);

  // 3. Simplification, all rings at once.
  std::vector<Ring> simple = Simplify(kept, options.simplify_tolerance_px / ppm);
  internal::ImportedRegion region_rings;
  region_rings.outer = simple[0];
  for (std::size_t i = 1; i < simple.size(); ++i)
    if (simple[i].size() >= 3) region_rings.holes.push_back(simple[i]);

  const std::string name = options.name.empty() ? file.stem().string() : options.name;
  Venue venue = internal::VenueFromRegions({region_rings}, name,
                                           "imported from " + file.filename().string() + " (raster plan, " +
                                               FormatNumber(ppm) + " px/m, dark below " +
                                               std::to_string(options.dark_threshold) + ")",
                                           origin);
  return venue;
}

}  // namespace crowdrecon::geometry
