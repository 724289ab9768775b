#include "crowdrecon/engine/parameters.hpp"

#include <cmath>
#include <numbers>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/world.hpp"

namespace crowdrecon::engine {

const char* ToString(FacingTarget t) {
  return t == FacingTarget::kVelocity ? "velocity" : "desired_direction";
}
bool FromString(const std::string& s, FacingTarget* t) {
  if (s == "velocity") *t = FacingTarget::kVelocity;
  else if (s == "desired_direction") *t = FacingTarget::kDesiredDirection;
  else return false;
  return true;
}

const char* ToString(TangentialDamping t) {
  switch (t) {
    case TangentialDamping::kFromRestitution: return "from_restitution";
    case TangentialDamping::kEqualToNormal: return "equal_to_normal";
    case TangentialDamping::kFixed: return "fixed";
  }
  return "?";
}
bool FromString(const std::string& s, TangentialDamping* t) {
  if (s == "from_restitution") *t = TangentialDamping::kFromRestitution;
  else if (s == "equal_to_normal") *t = TangentialDamping::kEqualToNormal;
  else if (s == "fixed") *t = TangentialDamping::kFixed;
  else return false;
  return true;
}

const char* ToString(Integrator t) { return t == Integrator::kVelocityVerlet ? "velocity_verlet" : "gear5"; }
bool FromString(const std::string& s, Integrator* t) {
  if (s == "velocity_verlet") *t = Integrator::kVelocityVerlet;
  else if (s == "gear5") *t = Integrator::kGear5;
  else return false;
  return true;
}

const char* ToString(ComputeDevice d) { return d == ComputeDevice::kCpu ? "cpu" : "cuda"; }
bool FromString(const std::string& s, ComputeDevice* d) {
  if (s == "cpu") *d = ComputeDevice::kCpu;
  else if (s == "cuda") *d = ComputeDevice::kCuda;
  else return false;
  return true;
}

namespace {
bool Check(bool ok, const char* name, double value, const char* expected, std::string* error) {
  if (!ok && error) *error = std::string(name) + " = " + FormatNumber(value) + ", expected " + expected;
  return ok;
}
}  // namespace

bool ModelParameters::IsValid(std::string* error) const {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  const auto non_negative = [](double v) { return std::isfinite(v) && v >= 0.0; };
  return Check(positive(normal_stiffness_n_per_m), "normal_stiffness_n_per_m", normal_stiffness_n_per_m, "> 0", error) &&
         Check(positive(tangential_stiffness_n_per_m), "tangential_stiffness_n_per_m", tangential_stiffness_n_per_m, "> 0", error) &&
         Check(non_negative(friction_coefficient) && friction_coefficient <= 5.0, "friction_coefficient", friction_coefficient, "in [0, 5]", error) &&
         Check(restitution > 0.0 && restitution <= 1.0, "restitution", restitution, "in (0, 1]", error) &&
         Check(wall_restitution > 0.0 && wall_restitution <= 1.0, "wall_restitution", wall_restitution, "in (0, 1]", error) &&
         Check(non_negative(tangential_damping_rate_per_s), "tangential_damping_rate_per_s", tangential_damping_rate_per_s, ">= 0", error) &&
         Check(positive(relaxation_time_s), "relaxation_time_s", relaxation_time_s, "> 0", error) &&
         Check(non_negative(desired_speed_min_m_per_s), "desired_speed_min_m_per_s", desired_speed_min_m_per_s, ">= 0", error) &&
         Check(std::isfinite(desired_speed_max_m_per_s) && desired_speed_max_m_per_s >= desired_speed_min_m_per_s && desired_speed_max_m_per_s <= 10.0,
               "desired_speed_max_m_per_s", desired_speed_max_m_per_s, ">= desired_speed_min_m_per_s and <= 10", error) &&
         Check(non_negative(back_force_gamma) && back_force_gamma <= 100.0, "back_force_gamma", back_force_gamma, "in [0, 100]", error) &&
         Check(non_negative(torsion_stiffness_lambda) && torsion_stiffness_lambda <= 1e4, "torsion_stiffness_lambda", torsion_stiffness_lambda, "in [0, 10000]", error) &&
         Check(positive(rotation_relaxation_time_s), "rotation_relaxation_time_s", rotation_relaxation_time_s, "> 0", error) &&
         Check(positive(surface_density_kg_per_m2), "surface_density_kg_per_m2", surface_density_kg_per_m2, "> 0", error) &&
         Check(positive(mass_min_kg), "mass_min_kg", mass_min_kg, "> 0", error) &&
         Check(std::isfinite(mass_max_kg) && mass_max_kg >= mass_min_kg, "mass_max_kg", mass_max_kg, ">= mass_min_kg", error) &&
         Check(non_negative(gravity_m_per_s2), "gravity_m_per_s2", gravity_m_per_s2, ">= 0", error) &&
         Check(non_negative(time_step_s) && time_step_s < 1.0, "time_step_s", time_step_s, "in [0, 1) (0 = automatic)", error) &&
         Check(time_step_safety > 0.0 && time_step_safety <= 1.0, "time_step_safety", time_step_safety, "in (0, 1]", error);
}

double DampingRateFromRestitution(double restitution, double stiffness_n_per_m, double mass_kg) {
  const double l = -std::log(restitution);
  return 2.0 * l * std::sqrt(stiffness_n_per_m / mass_kg) / std::sqrt(std::numbers::pi * std::numbers::pi + l * l);
}

double RestitutionFromDampingRate(double gamma_per_s, double stiffness_n_per_m, double mass_kg) {
  const double omega2 = stiffness_n_per_m / mass_kg - gamma_per_s * gamma_per_s / 4.0;
  if (omega2 <= 0.0) return 0.0;  // overdamped: no rebound
  return std::exp(-std::numbers::pi * gamma_per_s / 2.0 / std::sqrt(omega2));
}

}  // namespace crowdrecon::engine
