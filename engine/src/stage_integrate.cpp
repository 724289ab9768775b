// Stage integrate: velocity Verlet, or Gear's fifth-order predictor-corrector.
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
#include "simulation_internals.hpp"

#include <algorithm>
#include <cmath>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

namespace {

// Gear predictor for one coordinate (a Vec2 position or an angle): Pascal
// triangle on the Nordsieck vector (x, h v, r2..r5). Returns the predicted r2.
template <typename T>
T GearPredictOne(T& x, T& v, std::array<T, 4>& r, double h) {
  T r1 = v * h;
  x += r1 + r[0] + r[1] + r[2] + r[3];
  r1 += r[0] * 2.0 + r[1] * 3.0 + r[2] * 4.0 + r[3] * 5.0;
  r[0] += r[1] * 3.0 + r[2] * 6.0 + r[3] * 10.0;
  r[1] += r[2] * 4.0 + r[3] * 10.0;
  r[2] += r[3] * 5.0;
  v = r1 / h;
  return r[0];
}

// Gear corrector for one coordinate, `delta` = h^2/2 a(computed) - r2(predicted),
// with the coefficients for velocity-dependent forces (c0 = 3/16).
template <typename T>
void GearCorrectOne(T& x, T& v, std::array<T, 4>& r, T delta, double h) {
  static constexpr double c[6] = {3.0 / 16.0, 251.0 / 360.0, 1.0, 11.0 / 18.0, 1.0 / 6.0, 1.0 / 60.0};
  x += delta * c[0];
  v += delta * (c[1] / h);
  r[0] += delta * c[2];
  r[1] += delta * c[3];
  r[2] += delta * c[4];
  r[3] += delta * c[5];
}

}  // namespace

void Simulation::VerletKickDrift() {
  ScopedTimer timer(profile_.stage_s[Index(Stage::kIntegrate)]);
  const double h = dt_s_;
  const std::size_t n = bodies_.size();
  Internals& in = *in_;
  std::vector<Vec2>& v = bodies_.velocity_m_per_s;
  std::vector<double>& w = bodies_.angular_velocity_rad_per_s;
  in.v_half.resize(n);
  in.w_half.resize(n);
  // Half kick with the forces of the last evaluation and drift. The velocity-
  // dependent forces (dashpots, eqs. 11-12; eq. 3) at the new positions see the
  // predicted velocity v + h a(t). (A second-order Adams-Bashforth predictor was
  // tried: the restitution error is dominated by the timing of contact onset and
  // end within a step, which ContactLaw corrects, not by the predictor.)
  const std::int64_t count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (count >= kParallelBodies)
  for (std::int64_t ii = 0; ii < count; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    if (bodies_.state[i] != PersonState::kWalking || in.Asleep(i)) {  // (a sleeper stays: docs/model.md, "Sleeping")
      v[i] = {};
      w[i] = 0.0;
      in.v_half[i] = {};
      in.w_half[i] = 0.0;
      continue;
    }
    const Vec2 a = bodies_.force_n[i] / bodies_.mass_kg[i];
    const double alpha = bodies_.torque_n_m[i] / bodies_.inertia_kg_m2[i];
    in.v_half[i] = v[i] + (bodies_.force_n[i] + in.leading_force[i]) / bodies_.mass_kg[i] * (h / 2.0);
    in.w_half[i] = w[i] + (bodies_.torque_n_m[i] + in.leading_torque[i]) / bodies_.inertia_kg_m2[i] * (h / 2.0);
    bodies_.position_m[i] += in.v_half[i] * h;
    bodies_.angle_rad[i] += in.w_half[i] * h;
    detail::Wrap(def_.periodic, bodies_.position_m[i]);
    v[i] = in.v_half[i] + a * (h / 2.0);
    w[i] = in.w_half[i] + alpha * (h / 2.0);
  }
}

void Simulation::VerletKick() {
  ScopedTimer timer(profile_.stage_s[Index(Stage::kIntegrate)]);
  const double h = dt_s_;
  Internals& in = *in_;
  const std::int64_t count = static_cast<std::int64_t>(bodies_.size());
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (count >= kParallelBodies)
  for (std::int64_t ii = 0; ii < count; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    if (bodies_.state[i] != PersonState::kWalking || in.Asleep(i)) continue;
    bodies_.velocity_m_per_s[i] =
        in.v_half[i] + (bodies_.force_n[i] + in.trailing_force[i]) / bodies_.mass_kg[i] * (h / 2.0);
    bodies_.angular_velocity_rad_per_s[i] =
        in.w_half[i] + (bodies_.torque_n_m[i] + in.trailing_torque[i]) / bodies_.inertia_kg_m2[i] * (h / 2.0);
  }
}

void Simulation::GearPredict() {
  ScopedTimer timer(profile_.stage_s[Index(Stage::kIntegrate)]);
  // Fifth-order Gear predictor-corrector for second-order equations, in
  // Nordsieck form r_k = h^k/k! d^k x/dt^k (Allen & Tildesley, Appendix E),
  // with the corrector coefficients for velocity-dependent forces (c0 = 3/16).
  const double h = dt_s_;
  const std::size_t n = bodies_.size();
  Internals& in = *in_;
  if (!in.gear_initialised) {
    in.gear_xy.assign(n, {});
    in.gear_theta.assign(n, {});
    for (std::size_t i = 0; i < n; ++i) {
      if (bodies_.state[i] != PersonState::kWalking) continue;
      in.gear_xy[i][0] = bodies_.force_n[i] / bodies_.mass_kg[i] * (h * h / 2.0);
      in.gear_theta[i][0] = bodies_.torque_n_m[i] / bodies_.inertia_kg_m2[i] * (h * h / 2.0);
    }
    in.gear_initialised = true;
  }
  std::vector<Vec2>& predicted_r2 = in.v_half;
  std::vector<double>& predicted_t2 = in.w_half;
  predicted_r2.resize(n);
  predicted_t2.resize(n);
  const std::int64_t count = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (count >= kParallelBodies)
  for (std::int64_t ii = 0; ii < count; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    if (bodies_.state[i] != PersonState::kWalking) {
      bodies_.velocity_m_per_s[i] = {};
      bodies_.angular_velocity_rad_per_s[i] = 0.0;
      in.gear_xy[i] = {};
      in.gear_theta[i] = {};
      continue;
    }
    predicted_r2[i] = GearPredictOne(bodies_.position_m[i], bodies_.velocity_m_per_s[i], in.gear_xy[i], h);
    predicted_t2[i] = GearPredictOne(bodies_.angle_rad[i], bodies_.angular_velocity_rad_per_s[i], in.gear_theta[i], h);
    detail::Wrap(def_.periodic, bodies_.position_m[i]);
  }
}

void Simulation::GearCorrect() {
  ScopedTimer timer(profile_.stage_s[Index(Stage::kIntegrate)]);
  const double h = dt_s_;
  Internals& in = *in_;
  const std::vector<Vec2>& predicted_r2 = in.v_half;
  const std::vector<double>& predicted_t2 = in.w_half;
  const std::int64_t count = static_cast<std::int64_t>(bodies_.size());
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (count >= kParallelBodies)
  for (std::int64_t ii = 0; ii < count; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    if (bodies_.state[i] != PersonState::kWalking) continue;
    GearCorrectOne(bodies_.position_m[i], bodies_.velocity_m_per_s[i], in.gear_xy[i],
                   bodies_.force_n[i] / bodies_.mass_kg[i] * (h * h / 2.0) - predicted_r2[i], h);
    detail::Wrap(def_.periodic, bodies_.position_m[i]);
    GearCorrectOne(bodies_.angle_rad[i], bodies_.angular_velocity_rad_per_s[i], in.gear_theta[i],
                   bodies_.torque_n_m[i] / bodies_.inertia_kg_m2[i] * (h * h / 2.0) - predicted_t2[i], h);
  }
}

}  // namespace crowdrecon::engine
