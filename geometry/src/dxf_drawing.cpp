// Reading a DXF floor plan's drawing via dxflib (dxf_drawing.hpp).
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <fstream>
#include <istream>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <dxflib/dl_creationadapter.h>
#include <dxflib/dl_dxf.h>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/input_limits.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "dxf_drawing.hpp"
#include "venue_internal.hpp"

namespace crowdrecon::geometry::internal {

namespace {

using Piece = DxfPiece;

// An INSERT: block `name` placed at `at`, scaled, rotated (degrees,
// counter-clockwise) and repeated in `columns` x `rows` (MINSERT spacing,
// along the rotated axes).
struct Insert {
  std::string name, layer;
  std::size_t line = 0;  // line of the file where the entity starts (0: unknown)
  Vec2 at;
  double scale_x = 1.0, scale_y = 1.0, angle_deg = 0.0;
  int columns = 1, rows = 1;
  double column_spacing = 0.0, row_spacing = 0.0;
};

// A block definition: its base point and what it draws, inserts included.
struct Block {
  Vec2 base;
  std::vector<Piece> pieces;
  std::vector<Insert> inserts;
};

// x' = m[0] x + m[1] y + m[4], y' = m[2] x + m[3] y + m[5].
struct Affine {
  double m[6] = {1.0, 0.0, 0.0, 1.0, 0.0, 0.0};
  Vec2 operator()(Vec2 p) const { return {m[0] * p.x + m[1] * p.y + m[4], m[2] * p.x + m[3] * p.y + m[5]}; }
  Affine Then(const Affine& outer) const {  // outer after this
    Affine r;
    r.m[0] = outer.m[0] * m[0] + outer.m[1] * m[2];
    r.m[1] = outer.m[0] * m[1] + outer.m[1] * m[3];
    r.m[2] = outer.m[2] * m[0] + outer.m[3] * m[2];
    r.m[3] = outer.m[2] * m[1] + outer.m[3] * m[3];
    r.m[4] = outer.m[0] * m[4] + outer.m[1] * m[5] + outer.m[4];
    r.m[5] = outer.m[2] * m[4] + outer.m[3] * m[5] + outer.m[5];
    return r;
  }
};

// Number of segments for an arc of radius r and sweep |angle| so that the
// chord's distance to the arc (r (1 - cos(step/2))) stays below `tolerance`.
std::size_t ArcSegments(double radius, double sweep_rad, double tolerance) {
  const double ratio = std::clamp(1.0 - tolerance / radius, -1.0, 1.0);
  const double max_step = std::max(2.0 * std::acos(ratio), 1e-3);
  const auto n = static_cast<std::size_t>(std::ceil(std::abs(sweep_rad) / max_step));
  return std::clamp<std::size_t>(n, 1, 10000);
}

// Points of an arc from start_rad sweeping sweep_rad (positive: counter-clockwise).
std::vector<Vec2> ArcPoints(Vec2 centre, double radius, double start_rad, double sweep_rad, double tolerance,
                            bool include_last) {
  const std::size_t n = ArcSegments(radius, sweep_rad, tolerance);
  std::vector<Vec2> points;
  for (std::size_t k = 0; k <= n; ++k) {
    if (k == n && !include_last) break;
    const double a = start_rad + sweep_rad * static_cast<double>(k) / static_cast<double>(n);
    points.push_back(centre + radius * Vec2{std::cos(a), std::sin(a)});
  }
  return points;
}

// Metres per unit for the DXF $INSUNITS codes a floor plan may use.
double MetresPerInsUnit(int code) {
  switch (code) {
    case 1: return 0.0254;   // inches
    case 2: return 0.3048;   // feet
    case 4: return 0.001;    // millimetres
    case 5: return 0.01;     // centimetres
    case 6: return 1.0;      // metres
    case 14: return 0.1;     // decimetres
    default: return 1.0;     // unitless or unusual: take metres
  }
}

class Collector : public DL_CreationAdapter {
 public:
  // The arc tolerance is in metres; the drawing unit is known once the header
  // ($INSUNITS) has been read, which in a DXF file precedes the entities.
  // Not copyable: dxflib's interface base owns a raw pointer.
  // `insert_lines`: the line of every INSERT entity of the file, in order
  // (dxflib does not say where an entity was read).
  Collector(std::string file, std::string layer, double tolerance_m, double scale_override,
            std::vector<std::size_t> insert_lines)
      : layer_(std::move(layer)),
        tolerance_m_(tolerance_m),
        scale_override_(scale_override),
        insert_lines_(std::move(insert_lines)),
        file_(std::move(file)) {}
  Collector(const Collector&) = delete;
  Collector& operator=(const Collector&) = delete;

  // Metres per drawing unit.
  double Scale() const { return scale_override_ > 0.0 ? scale_override_ : MetresPerInsUnit(insunits_); }

  void setVariableInt(const std::string& key, int value, int /*code*/) override {
    if (key == "$INSUNITS") insunits_ = value;
  }
  // Block definitions are kept, and drawn where an INSERT places them
  // (Collect); what lies in a block is drawn only through its inserts.
  void addBlock(const DL_BlockData& d) override {
    FinishPending();
    block_ = &blocks_[d.name];
    *block_ = Block{};
    block_->base = {d.bpx, d.bpy};
  }
  void endBlock() override {
    FinishPending();
    block_ = nullptr;
  }
  void addInsert(const DL_InsertData& d) override {
    FinishPending();
    Insert insert;
    insert.name = d.name;
    insert.layer = getAttributes().getLayer();
    if (inserts_seen_ < insert_lines_.size()) insert.line = insert_lines_[inserts_seen_];
    ++inserts_seen_;
    insert.at = {d.ipx, d.ipy};
    insert.scale_x = d.sx;
    insert.scale_y = d.sy;
    insert.angle_deg = d.angle;
    insert.columns = std::max(1, d.cols);
    insert.rows = std::max(1, d.rows);
    insert.column_spacing = d.colSp;
    insert.row_spacing = d.rowSp;
    (block_ ? block_->inserts : inserts_).push_back(std::move(insert));
  }

  void addLine(const DL_LineData& d) override {
    FinishPending();
    Add({{d.x1, d.y1}, {d.x2, d.y2}}, false);
  }
  void addArc(const DL_ArcData& d) override {
    FinishPending();
    if (d.radius <= 0.0) return;
    double sweep_deg = std::fmod(d.angle2 - d.angle1, 360.0);
    if (sweep_deg <= 0.0) sweep_deg += 360.0;  // DXF arcs run counter-clockwise
    Add(ArcPoints({d.cx, d.cy}, d.radius, Radians(d.angle1), Radians(sweep_deg), Tolerance(), true), false);
  }
  void addCircle(const DL_CircleData& d) override {
    FinishPending();
    if (d.radius <= 0.0) return;
    std::vector<Vec2> ring = ArcPoints({d.cx, d.cy}, d.radius, 0.0, 2.0 * std::numbers::pi, Tolerance(), false);
    // A circle needs at least a few vertices to be a ring of the right area.
    if (ring.size() < 8) ring = ArcPoints({d.cx, d.cy}, d.radius, 0.0, 2.0 * std::numbers::pi, 0.0, false);
    Add(std::move(ring), true);
  }
  // An ellipse or elliptic arc: centre, major axis (end point relative to the
  // centre), ratio of the axes, and the range of the parameter (radians).
  void addEllipse(const DL_EllipseData& d) override {
    FinishPending();
    const Vec2 centre{d.cx, d.cy}, major{d.mx, d.my};
    const Vec2 minor = Perp(major) * d.ratio;
    const double radius = Length(major);
    if (radius <= 0.0 || d.ratio <= 0.0) return;
    double sweep = std::fmod(d.angle2 - d.angle1, 2.0 * std::numbers::pi);
    if (sweep <= 1e-12) sweep += 2.0 * std::numbers::pi;
    const bool closed = std::abs(sweep - 2.0 * std::numbers::pi) < 1e-9;
    // Segments as for a circle of the major radius (the chord deviation of
    // an ellipse is at most that of its major circle for the same parameter step).
    const std::size_t n = std::max<std::size_t>(ArcSegments(radius, sweep, Tolerance()), closed ? 8 : 1);
    std::vector<Vec2> points;
    for (std::size_t k = 0; k <= n; ++k) {
      if (k == n && closed) break;
      const double t = d.angle1 + sweep * static_cast<double>(k) / static_cast<double>(n);
      points.push_back(centre + major * std::cos(t) + minor * std::sin(t));
    }
    Add(std::move(points), closed);
  }
  // A spline (NURBS): degree, flags (1 closed, 4 rational), then its knots
  // and control points (with weights) as separate calls; flattened by
  // FinishSpline. A spline given by fit points only (no control points) is
  // first interpolated through them (InterpolateFitPoints).
  void addSpline(const DL_SplineData& d) override {
    FinishPending();
    spline_active_ = true;
    spline_layer_ = getAttributes().getLayer();
    spline_degree_ = d.degree;
    spline_closed_ = (d.flags & 1) != 0;
    start_tangent_ = {d.tangentStartX, d.tangentStartY};  // groups 12/22, 13/23 (zero: not given)
    end_tangent_ = {d.tangentEndX, d.tangentEndY};
    knots_.clear();
    control_.clear();
    weights_.clear();
    fit_.clear();
  }
  void addFitPoint(const DL_FitPointData& d) override {
    if (spline_active_) fit_.push_back({d.x, d.y});
  }
  void addKnot(const DL_KnotData& d) override {
    if (spline_active_) knots_.push_back(d.k);
  }
  void addControlPoint(const DL_ControlPointData& d) override {
    if (!spline_active_) return;
    control_.push_back({d.x, d.y});
    weights_.push_back(d.w > 0.0 ? d.w : 1.0);  // (absent weights read as 0 or 1: no weight)
  }

  // The spline's point at parameter u in knot span s (knots_[s] <= u <
  // knots_[s + 1]), by de Boor's algorithm on homogeneous coordinates.
  Vec2 SplinePoint(std::size_t s, double u) const {
    const std::size_t p = spline_degree_;
    std::vector<Vec2> d(p + 1);
    std::vector<double> w(p + 1);
    for (std::size_t j = 0; j <= p; ++j) {
      w[j] = weights_[s - p + j];
      d[j] = control_[s - p + j] * w[j];
    }
    for (std::size_t r = 1; r <= p; ++r)
      for (std::size_t j = p; j >= r; --j) {
        const std::size_t i = s - p + j;
        const double span = knots_[i + p + 1 - r] - knots_[i];
        const double alpha = span > 0.0 ? (u - knots_[i]) / span : 0.0;
        d[j] = d[j - 1] * (1.0 - alpha) + d[j] * alpha;
        w[j] = w[j - 1] * (1.0 - alpha) + w[j] * alpha;
      }
    return d[p] / w[p];
  }

  // The non-zero B-spline basis functions N_{s-p..s, p}(u) of knot span s
  // (The NURBS Book, algorithm A2.2).
  static std::vector<double> BasisFunctions(const std::vector<double>& knots, std::size_t s, double u, std::size_t p) {
    std::vector<double> n(p + 1), left(p + 1), right(p + 1);
    n[0] = 1.0;
    for (std::size_t j = 1; j <= p; ++j) {
      left[j] = u - knots[s + 1 - j];
      right[j] = knots[s + j] - u;
      double saved = 0.0;
      for (std::size_t r = 0; r < j; ++r) {
        const double temp = n[r] / (right[r + 1] + left[j - r]);
        n[r] = saved + right[r + 1] * temp;
        saved = left[j - r] * temp;
      }
      n[j] = saved;
    }
    return n;
  }

  // A spline given by fit points only: the non-rational B-spline of its
  // degree (3 if none is given, less if there are too few points) through
  // them, by global interpolation (The NURBS Book, 9.2.1): parameters by
  // chord length, knots by averaging them, control points from the linear
  // system N P = Q (banded; sparse LU). Repeated points are dropped; a closed
  // spline's first point is repeated at its end (the curve closes there with
  // a corner of at most the points' turning angle).
  // An open spline whose start and end tangents are both given (groups 12,
  // 13) is interpolated with them (9.2.2): two more control points, knots
  // averaged over p parameters from the first (9.22), and the two equations
  // C'(0) = D0, C'(1) = Dn. The file gives their directions; their length is
  // taken as the total chord length, the speed of a curve whose parameter
  // runs over [0, 1] by chord length. Without tangents, CAD programs choose
  // their own: the ends may then differ from the drawing program's curve by
  // a little, never at the fit points themselves.
  // Returns false (and leaves the spline as it was) if it cannot be done.
  bool InterpolateFitPoints() {
    std::vector<Vec2> q;
    for (const Vec2& f : fit_)
      if (q.empty() || Length(f - q.back()) > 0.0) q.push_back(f);
    if (spline_closed_ && q.size() >= 3 && Length(q.front() - q.back()) > 0.0) q.push_back(q.front());
    if (q.size() < 2) return false;
    const std::size_t n = q.size() - 1;
    const bool tangents = !spline_closed_ && Length(start_tangent_) > 0.0 && Length(end_tangent_) > 0.0;
    const std::size_t extra = tangents ? 2 : 0;  // control points beyond the fit points
    const std::size_t p = std::min<std::size_t>(spline_degree_ >= 1 ? spline_degree_ : 3, n + extra);
    std::vector<double> u(n + 1, 0.0);
    double total = 0.0;
    for (std::size_t k = 1; k <= n; ++k) total += Length(q[k] - q[k - 1]);
    for (std::size_t k = 1; k < n; ++k) u[k] = u[k - 1] + Length(q[k] - q[k - 1]) / total;
    u[n] = 1.0;
    const std::size_t controls = n + 1 + extra;
    std::vector<double> knots(controls + p + 1, 0.0);
    for (std::size_t k = controls; k < knots.size(); ++k) knots[k] = 1.0;
    // Interior knots knots[p + 1 .. controls - 1], each the mean of p parameters:
    // from u[1] on without tangents (9.8), from u[0] on with them (9.22).
    for (std::size_t j = p + 1; j < controls; ++j) {
      const std::size_t from = tangents ? j - p - 1 : j - p;
      double sum = 0.0;
      for (std::size_t i = from; i < from + p; ++i) sum += u[i];
      knots[j] = sum / static_cast<double>(p);
    }
    std::vector<Eigen::Triplet<double>> entries;
    std::size_t s = p;  // the span of u[k]: knots[s] <= u < knots[s + 1], the last for u = 1 (u increases with k)
    for (std::size_t k = 0; k <= n; ++k) {
      while (s + 1 < controls && knots[s + 1] <= u[k]) ++s;
      const std::vector<double> basis = BasisFunctions(knots, s, u[k], p);
      for (std::size_t j = 0; j <= p; ++j)
        if (basis[j] != 0.0)
          entries.emplace_back(static_cast<int>(k), static_cast<int>(s - p + j), basis[j]);
    }
    const int size = static_cast<int>(controls);
    Eigen::MatrixX2d rhs(size, 2);
    for (std::size_t k = 0; k <= n; ++k) rhs.row(static_cast<int>(k)) << q[k].x, q[k].y;
    if (tangents) {
      // C'(0) = p / knots[p + 1] (P1 - P0), C'(1) = p / (1 - knots[controls - 1]) (P_last - P_last-1).
      const double a0 = static_cast<double>(p) / knots[p + 1];
      const double a1 = static_cast<double>(p) / (1.0 - knots[controls - 1]);
      const int r0 = static_cast<int>(n + 1), r1 = static_cast<int>(n + 2), last = size - 1;
      entries.emplace_back(r0, 0, -a0);
      entries.emplace_back(r0, 1, a0);
      entries.emplace_back(r1, last - 1, -a1);
      entries.emplace_back(r1, last, a1);
      const Vec2 d0 = start_tangent_ / Length(start_tangent_) * total, d1 = end_tangent_ / Length(end_tangent_) * total;
      rhs.row(r0) << d0.x, d0.y;
      rhs.row(r1) << d1.x, d1.y;
    }
    Eigen::SparseMatrix<double> a(size, size);
    a.setFromTriplets(entries.begin(), entries.end());
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
    lu.compute(a);
    if (lu.info() != Eigen::Success) return false;
    const Eigen::MatrixX2d solution = lu.solve(rhs);
    if (lu.info() != Eigen::Success || !solution.allFinite()) return false;
    control_.clear();
    for (int k = 0; k < size; ++k) control_.push_back({solution(k, 0), solution(k, 1)});
    weights_.assign(control_.size(), 1.0);
    knots_ = std::move(knots);
    spline_degree_ = p;
    return true;
  }

  // Flattens the pending spline: each knot span is split until the middle
  // of every chord's arc lies within the tolerance of the chord.
  void FinishSpline() {
    if (!spline_active_) return;
    spline_active_ = false;
    if (control_.empty() && !fit_.empty() && !InterpolateFitPoints()) {
      Piece marker{{}, false, spline_layer_,
                   "SPLINE with " + std::to_string(fit_.size()) +
                       " fit points and no control points, through which no curve could be interpolated "
                       "(expected at least 2 distinct points)"};
      Push(std::move(marker));
      return;
    }
    const std::size_t p = spline_degree_, n = control_.size();
    if (p < 1 || n < p + 1 || knots_.size() != n + p + 1 ||
        !std::is_sorted(knots_.begin(), knots_.end())) {
      Piece marker{{}, false, spline_layer_,
                   "SPLINE of degree " + std::to_string(p) + " with " + std::to_string(n) + " control points and " +
                       std::to_string(knots_.size()) + " knots (expected degree + control points + 1)"};
      Push(std::move(marker));
      return;
    }
    const double tolerance = Tolerance();
    std::vector<Vec2> points;
    const auto refine = [&](auto&& self, std::size_t s, double u0, Vec2 a, double u1, Vec2 b, int depth) -> void {
      const double um = 0.5 * (u0 + u1);
      const Vec2 m = SplinePoint(s, um);
      const Vec2 chord = b - a;
      const double length = Length(chord);
      const double off = length > 0.0 ? std::abs(Cross(chord, m - a)) / length : Length(m - a);
      if (depth < 16 && (off > tolerance || depth < 2)) {
        self(self, s, u0, a, um, m, depth + 1);
        self(self, s, um, m, u1, b, depth + 1);
      } else {
        points.push_back(b);
      }
    };
    for (std::size_t s = p; s < n; ++s) {
      if (!(knots_[s + 1] > knots_[s])) continue;
      // The end of the span is evaluated in it, as its limit.
      const double u0 = knots_[s], u1 = knots_[s + 1];
      const Vec2 a = SplinePoint(s, u0), b = SplinePoint(s, u1);
      if (points.empty()) points.push_back(a);
      refine(refine, s, u0, a, u1, b, 0);
    }
    if (points.size() < 2) return;
    const bool closed = spline_closed_ || Length(points.front() - points.back()) <= tolerance * 1e-3;
    if (closed && Length(points.front() - points.back()) <= tolerance) points.pop_back();
    Piece piece{std::move(points), closed, spline_layer_, {}};
    Push(std::move(piece));
  }
  void addPolyline(const DL_PolylineData& d) override {
    FinishPending();
    polyline_active_ = true;
    polyline_layer_ = getAttributes().getLayer();
    polyline_closed_ = (d.flags & 1) != 0;
    vertices_.clear();
    bulges_.clear();
  }
  void addVertex(const DL_VertexData& d) override {
    if (!polyline_active_) return;
    vertices_.push_back({d.x, d.y});
    bulges_.push_back(d.bulge);
  }
  void endSequence() override { FinishPending(); }

  // Completes a pending polyline or spline (their vertices, control points
  // and knots come as separate calls; LWPOLYLINE has no end marker).
  void FinishPending() {
    FinishSpline();
    FinishPolylineNow();
  }

  void FinishPolylineNow() {
    if (!polyline_active_) return;
    polyline_active_ = false;
    if (vertices_.size() < 2) return;
    std::vector<Vec2> points;
    const std::size_t n = vertices_.size();
    const std::size_t edges = polyline_closed_ ? n : n - 1;
    for (std::size_t i = 0; i < edges; ++i) {
      const Vec2 p0 = vertices_[i], p1 = vertices_[(i + 1) % n];
      points.push_back(p0);
      const double bulge = bulges_[i];
      const double chord = Length(p1 - p0);
      if (std::abs(bulge) > 1e-12 && chord > 0.0) {
        // Bulge = tan(theta / 4), theta the signed included angle of the arc
        // from p0 to p1; the centre is off the chord's midpoint by
        // (c / 2) cot(theta / 2) to the left of the chord.
        const double theta = 4.0 * std::atan(bulge);
        const Vec2 mid = 0.5 * (p0 + p1);
        const Vec2 left = Perp(p1 - p0) / chord;
        const Vec2 centre = mid + left * (0.5 * chord / std::tan(0.5 * theta));
        const double radius = Length(p0 - centre);
        const double start = std::atan2(p0.y - centre.y, p0.x - centre.x);
        std::vector<Vec2> arc = ArcPoints(centre, radius, start, theta, Tolerance(), false);
        points.insert(points.end(), arc.begin() + 1, arc.end());
      }
    }
    if (!polyline_closed_) points.push_back(vertices_.back());
    Piece piece{std::move(points), polyline_closed_, polyline_layer_, {}};
    Push(std::move(piece));
  }

  // The drawing's pieces on the wanted layer (all layers if none was named),
  // with every INSERT expanded, in drawing units. Entities in a block on
  // layer "0" take the layer of the INSERT that places them (DXF's rule).
  std::vector<Piece> Collect(const std::string& file) {
    CheckLoad(file);
    std::vector<Piece> out;
    for (const Piece& p : pieces_) Keep(p, p.layer, Affine{}, "", file, out);
    for (const Insert& insert : inserts_) Expand(insert, Affine{}, insert.layer, 0, file, out);
    return out;
  }

  std::size_t skipped_layers() const { return skipped_; }

 private:
  static double Radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

  // The pieces of the block being defined, or of the drawing.
  std::vector<Piece>& Current() { return block_ ? block_->pieces : pieces_; }

  // Into the current block or the drawing. The points read so far are
  // counted here, so that a drawing of many finely flattened curves is
  // refused while it is read rather than once it fills the memory.
  void Push(Piece piece) {
    points_read_ += piece.points.size();
    if (points_read_ > kMaxDxfPoints)
      throw InputError(file_ + ": the drawing holds more than " + std::to_string(kMaxDxfPoints) +
                       " points once its curves are flattened (" + std::to_string(blocks_.size()) +
                       " blocks read so far); at most that many are accepted: check the drawing's unit ($INSUNITS, "
                       "--scale), or import one layer (--layer)");
    Current().push_back(std::move(piece));
  }

  // Into the current block or the drawing, with the entity's layer.
  void Add(std::vector<Vec2> points, bool closed, std::string unsupported = {}) {
    Piece piece{std::move(points), closed, getAttributes().getLayer(), std::move(unsupported)};
    Push(std::move(piece));
  }

  // Piece p (drawn with `layer`) placed by `to`, if on the wanted layer.
  void Keep(const Piece& p, const std::string& layer, const Affine& to, const std::string& block,
            const std::string& file, std::vector<Piece>& out) {
    if (!layer_.empty() && layer != layer_) {
      ++skipped_;
      return;
    }
    if (!p.unsupported.empty())
      throw InputError(file + ": a " + p.unsupported + " on layer \"" + layer + "\"" +
                       (block.empty() ? "" : " (in block \"" + block + "\")") +
                       " cannot be read (convert it to a polyline, or leave its layer out with --layer)");
    Piece placed{{}, p.closed, layer, {}};
    placed.points.reserve(p.points.size());
    for (Vec2 q : p.points) placed.points.push_back(to(q));
    out.push_back(std::move(placed));
  }

  void Expand(const Insert& insert, const Affine& outer, const std::string& layer, int depth, const std::string& file,
              std::vector<Piece>& out) {
    const auto found = blocks_.find(insert.name);
    if (found == blocks_.end())
      throw InputError(file + ": an INSERT places block \"" + insert.name + "\", which the file does not define");
    if (depth >= kMaxBlockDepth)
      throw InputError(file + ": block \"" + insert.name + "\" is inserted more than " +
                       std::to_string(kMaxBlockDepth) + " levels deep (does a block insert itself?)");
    const Block& block = found->second;
    const double a = Radians(insert.angle_deg), c = std::cos(a), s = std::sin(a);
    for (int row = 0; row < insert.rows; ++row)
      for (int column = 0; column < insert.columns; ++column) {
        // Block point q: u = scale (q - base) + array offset; placed at `at` + R(angle) u.
        Affine local;
        local.m[0] = c * insert.scale_x;
        local.m[1] = -s * insert.scale_y;
        local.m[2] = s * insert.scale_x;
        local.m[3] = c * insert.scale_y;
        const Vec2 offset{column * insert.column_spacing - insert.scale_x * block.base.x,
                          row * insert.row_spacing - insert.scale_y * block.base.y};
        local.m[4] = insert.at.x + c * offset.x - s * offset.y;
        local.m[5] = insert.at.y + s * offset.x + c * offset.y;
        const Affine to = local.Then(outer);
        for (const Piece& p : block.pieces) Keep(p, p.layer == "0" ? layer : p.layer, to, insert.name, file, out);
        for (const Insert& inner : block.inserts)
          Expand(inner, to, inner.layer == "0" ? layer : inner.layer, depth + 1, file, out);
      }
  }

  // What a drawing or block expands to: entities and their points, every
  // INSERT and MINSERT array multiplied out (in double: 1e5 x 1e5 copies of
  // a nested array overflow any integer, and only the order matters).
  struct Load {
    double entities = 0.0, points = 0.0;
    Load& operator+=(const Load& o) {
      entities += o.entities;
      points += o.points;
      return *this;
    }
  };

  Load PiecesLoad(const std::vector<Piece>& pieces) const {
    Load load;
    for (const Piece& p : pieces) load += {1.0, static_cast<double>(p.points.size())};
    return load;
  }

  // One INSERT with its copies. Blocks are memoised, so that a chain of
  // blocks each inserting the next twice costs no more than its length.
  Load InsertLoad(const Insert& insert, int depth, const std::string& file, std::map<std::string, Load>& memo) const {
    const auto found = blocks_.find(insert.name);
    if (found == blocks_.end()) return {};  // reported by Expand
    if (depth >= kMaxBlockDepth)
      throw InputError(file + ": block \"" + insert.name + "\" is inserted more than " +
                       std::to_string(kMaxBlockDepth) + " levels deep (does a block insert itself?)");
    auto known = memo.find(insert.name);
    if (known == memo.end()) {
      Load block = PiecesLoad(found->second.pieces);
      for (const Insert& inner : found->second.inserts) block += InsertLoad(inner, depth + 1, file, memo);
      known = memo.emplace(insert.name, block).first;
    }
    const double copies = static_cast<double>(insert.columns) * static_cast<double>(insert.rows);
    return {copies * known->second.entities, copies * known->second.points};
  }

  // Refuses a drawing whose expansion exceeds kMaxDxfEntities or
  // kMaxDxfPoints (input_limits.hpp) before anything is expanded, naming the
  // INSERT that contributes most.
  void CheckLoad(const std::string& file) const {
    std::map<std::string, Load> memo;
    Load total = PiecesLoad(pieces_);
    const Insert* worst = nullptr;
    Load worst_load;
    for (const Insert& insert : inserts_) {
      const Load load = InsertLoad(insert, 0, file, memo);
      total += load;
      if (!worst || load.entities > worst_load.entities) {
        worst = &insert;
        worst_load = load;
      }
    }
    const double max_entities = static_cast<double>(kMaxDxfEntities);
    const double max_points = static_cast<double>(kMaxDxfPoints);
    if (total.entities <= max_entities && total.points <= max_points) return;
    std::string message = file;
    if (worst && worst_load.entities > 0.5 * total.entities)
      message += ":" + std::to_string(worst->line) + ": the INSERT of block \"" + worst->name + "\" (" +
                 std::to_string(worst->columns) + " x " + std::to_string(worst->rows) + " copies) expands to " +
                 FormatNumber(worst_load.entities) + " entities with " + FormatNumber(worst_load.points) +
                 " points; the drawing";
    else
      message += ": the drawing";
    throw InputError(message + " has " + FormatNumber(total.entities) + " entities with " +
                     FormatNumber(total.points) + " points once blocks are expanded; at most " +
                     std::to_string(kMaxDxfEntities) + " entities and " + std::to_string(kMaxDxfPoints) +
                     " points are accepted: check the MINSERT column and row counts and the curve tolerance, "
                     "or import one layer (--layer)");
  }

  // Drawing units. Curves in blocks are flattened 16 times finer, since an
  // INSERT may scale them up.
  double Tolerance() const { return tolerance_m_ / Scale() / (block_ ? 16.0 : 1.0); }

  static constexpr int kMaxBlockDepth = 32;
  std::string layer_;
  double tolerance_m_;
  double scale_override_;
  int insunits_ = 0;
  bool spline_active_ = false;
  bool spline_closed_ = false;
  std::size_t spline_degree_ = 0;
  std::string spline_layer_;
  std::vector<double> knots_;
  std::vector<Vec2> control_;
  std::vector<double> weights_;
  std::vector<Vec2> fit_;
  Vec2 start_tangent_, end_tangent_;
  bool polyline_active_ = false;
  bool polyline_closed_ = false;
  std::string polyline_layer_;
  std::vector<Vec2> vertices_;
  std::vector<double> bulges_;
  std::vector<Piece> pieces_;
  std::vector<Insert> inserts_;
  std::map<std::string, Block> blocks_;
  Block* block_ = nullptr;  // the block being defined, or null
  std::vector<std::size_t> insert_lines_;
  std::size_t inserts_seen_ = 0;
  std::string file_;
  std::size_t points_read_ = 0;
  std::size_t skipped_ = 0;
};

// What a first pass over the file finds: its number of lines, whether it
// ends with the group "0" / "EOF" that closes every DXF file (dxflib reads a
// file that stops short, an interrupted copy or download, without complaint,
// as far as it goes: such a file is refused rather than imported in part),
// and the line of every INSERT entity (group 0 / INSERT), for messages.
struct DxfScan {
  std::size_t lines = 0;
  bool ends_with_eof = false;
  std::vector<std::size_t> insert_lines;
};

DxfScan ScanDxf(std::istream& in) {
  DxfScan scan;
  std::string line, last, before;
  while (std::getline(in, line)) {
    ++scan.lines;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    const auto end = line.find_last_not_of(" \t\r");
    before = std::move(last);
    last = line.substr(first, end - first + 1);
    if (before == "0" && last == "INSERT") scan.insert_lines.push_back(scan.lines - 1);
  }
  scan.ends_with_eof = before == "0" && last == "EOF";
  return scan;
}

}  // namespace

DxfDrawing ReadDxfDrawing(const std::filesystem::path& file, const ImportOptions& options) {
  CheckInputFile(file, "DXF file");
  DxfScan scan;
  {
    std::ifstream in(file);
    if (!in) throw InputError(file.string() + ": cannot open DXF file for reading");
    scan = ScanDxf(in);
    if (!scan.ends_with_eof)
      throw InputError(file.string() + ": the file ends at line " + std::to_string(scan.lines) +
                       " without the end-of-file group (0 / EOF) that closes every DXF file: it looks cut short; "
                       "expected a complete ASCII DXF file");
  }
  Collector collector(file.string(), options.dxf_layer, options.dxf_arc_tolerance_m, options.scale_m_per_unit,
                      std::move(scan.insert_lines));
  DL_Dxf dxf;
  if (!dxf.in(file.string(), &collector)) throw InputError(file.string() + ": cannot read the file as DXF");
  collector.FinishPending();
  DxfDrawing drawing;
  drawing.scale_m_per_unit = collector.Scale();
  drawing.pieces = collector.Collect(file.string());
  drawing.skipped_layers = collector.skipped_layers();
  return drawing;
}

}  // namespace crowdrecon::geometry::internal
