// Term centrifugal (ModelParameters::centrifugal = generalized; issue 64, off
// by default): the generalized centrifugal force (Chraibi, Seyfried and
// Schadschneider, "Generalized centrifugal-force model for pedestrian
// dynamics", Phys. Rev. E 82:046111, 2010), a force beside the contact forces.
//
// Force phase, on each walking person i moving at v_i from every other person
// j in the venue (walking or fallen) within the neighbour radius, e_ij the
// unit vector from i to j (minimum image):
//   K_ij = max(0, v_i . e_ij) / |v_i|     (people behind, and anyone for a
//                                          person at rest: no push)
//   v_ij = max(0, (v_i - v_j) . e_ij)     (the speed at which i closes in)
//   f(s) = m_i K_ij (eta v0_i + v_ij)^2 / s
//   F    = -f(dist_ij) e_ij
// dist_ij = d_ij - r_i(e_ij) - r_j(-e_ij): the gap between the two people's
// ellipses along the line of centres, r(n) an ellipse's polar radius in the
// direction n; semi-axes a = a_min + tau_a |v| along the velocity (the body's
// facing when at rest) and b = b_max - (b_max - b_min) min(1, |v| / v0)
// across it. The paper's Fig. 7 interpolations, with JuPedSim's widths:
//   dist >= r_c:                 0
//   r_c - r_eps <= dist < r_c:   Hermite from f(r_c - r_eps) (its slope) to 0 (slope 0)
//   r_eps <= dist < r_c - r_eps: f(dist)
//   0 < dist < r_eps:            Hermite from f_m f(r_eps) (slope 0) at 0 to f(r_eps) (its slope)
//   dist <= 0 (ellipses overlap): f_m f(r_eps)
// (JuPedSim shifts the near interpolation by a fixed 0.5 m "for performance";
// here it starts at touching ellipses, as in the paper's figure.) The
// ellipses' own repulsion is all the term adds: where bodies touch, the
// contact forces carry them. The neighbour radius: r_c plus twice the
// largest semi-axis at 2.5 m/s (faster people's ellipses reach farther; the
// venues' crowds do not walk that fast). Summed in the neighbour list's
// order: the same on any thread count. No state.
#include <algorithm>
#include <cmath>

#include "../behaviour.hpp"

namespace crowdrecon::engine::detail {
namespace {

constexpr double kEllipseSpeedBound_m_per_s = 2.5;
constexpr double kAtRest_m_per_s = 1e-9;

// The cubic with values y0, y1 and slopes s0, s1 at x0, x1, at x.
double Hermite(double x, double x0, double x1, double y0, double y1, double s0, double s1) {
  const double h = x1 - x0, t = (x - x0) / h, t2 = t * t, t3 = t2 * t;
  return (2 * t3 - 3 * t2 + 1) * y0 + (t3 - 2 * t2 + t) * h * s0 + (-2 * t3 + 3 * t2) * y1 + (t3 - t2) * h * s1;
}

// An ellipse with semi-axis a along the unit vector u and b across it: its
// polar radius in the unit direction n.
double PolarRadius(double a, double b, Vec2 u, Vec2 n) {
  const double along = Dot(n, u), across = Cross(u, n);
  return a * b / std::sqrt(b * b * along * along + a * a * across * across);
}

class CentrifugalTerm final : public BehaviourTerm {
 public:
  explicit CentrifugalTerm(const ModelParameters& p)
      : radius_m_(p.centrifugal_cutoff_m +
                  2.0 * std::max({p.centrifugal_b_max_m, p.centrifugal_b_min_m,
                                  p.centrifugal_a_min_m + p.centrifugal_a_time_s * kEllipseSpeedBound_m_per_s})) {}
  unsigned phases() const override { return kForce; }
  double neighbour_radius_m() const override { return radius_m_; }

  void Force(const DriveInputs& in, DriveBlock& b) const override {
    const ModelParameters& mp = in.def.parameters;
    const double eta = mp.centrifugal_strength, cutoff = mp.centrifugal_cutoff_m;
    const double width = mp.centrifugal_interpolation_m, factor = mp.centrifugal_max_factor;
    for (std::size_t k = 0; k < b.count; ++k) {
      if (!b.driven[k]) continue;
      const std::size_t i = b.first + k;
      const Vec2 vi = in.bodies.velocity_m_per_s[i];
      const double speed = Length(vi);
      if (!(speed > kAtRest_m_per_s)) continue;  // K_ij = 0 for every j
      const Vec2 ui = vi * (1.0 / speed);
      const double ai = mp.centrifugal_a_min_m + mp.centrifugal_a_time_s * speed;
      const double bi = SemiAxisAcross(mp, speed, in.bodies.desired_speed_m_per_s[i]);
      const double numerator_speed = eta * in.bodies.desired_speed_m_per_s[i];
      const Vec2 xi = in.bodies.position_m[i];
      Vec2 push{};
      ForEachNeighbour(in.neighbours, in.bodies, i, [&](std::uint32_t j) {
        const Vec2 d = Separation(in.def.periodic, in.bodies.position_m[j], xi);  // x_j - x_i
        const double dij = Length(d);
        if (!(dij > 0.0) || dij > radius_m_) return;
        const Vec2 e = d * (1.0 / dij);
        const double kij = Dot(vi, e) / speed;
        if (!(kij > 0.0)) return;
        const Vec2 vj = in.bodies.velocity_m_per_s[j];
        const double vj_speed = Length(vj);
        const Vec2 uj = vj_speed > kAtRest_m_per_s ? vj * (1.0 / vj_speed) : Vec2{in.cos_angle[j], in.sin_angle[j]};
        const double aj = mp.centrifugal_a_min_m + mp.centrifugal_a_time_s * vj_speed;
        const double bj = SemiAxisAcross(mp, vj_speed, in.bodies.desired_speed_m_per_s[j]);
        const double gap = dij - PolarRadius(ai, bi, ui, e) - PolarRadius(aj, bj, uj, e * -1.0);
        if (gap >= cutoff) return;
        const double closing = std::max(0.0, Dot(vi - vj, e));
        const double scale = in.bodies.mass_kg[i] * kij * (numerator_speed + closing) * (numerator_speed + closing);
        double f;
        if (gap >= cutoff - width) {
          const double x0 = cutoff - width;
          f = Hermite(gap, x0, cutoff, scale / x0, 0.0, -scale / (x0 * x0), 0.0);
        } else if (gap >= width) {
          f = scale / gap;
        } else if (gap > 0.0) {
          f = Hermite(gap, 0.0, width, factor * scale / width, scale / width, 0.0, -scale / (width * width));
        } else {
          f = factor * scale / width;
        }
        push -= e * f;
      });
      b.force[k] += push;
    }
  }

 private:
  static double SemiAxisAcross(const ModelParameters& mp, double speed, double desired) {
    const double share = desired > 0.0 ? std::min(1.0, speed / desired) : 1.0;
    return mp.centrifugal_b_max_m - (mp.centrifugal_b_max_m - mp.centrifugal_b_min_m) * share;
  }

  double radius_m_;
};

}  // namespace

std::unique_ptr<BehaviourTerm> MakeCentrifugal(const ModelParameters& p, const WorldDef&) {
  if (p.centrifugal != Centrifugal::kGeneralized) return nullptr;
  return std::make_unique<CentrifugalTerm>(p);
}

}  // namespace crowdrecon::engine::detail
