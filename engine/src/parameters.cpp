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

const char* ToString(TimeStepMode m) { return m == TimeStepMode::kFixed ? "fixed" : "adaptive"; }

const char* ToString(ComputeDevice d) { return d == ComputeDevice::kCpu ? "cpu" : "cuda"; }
bool FromString(const std::string& s, ComputeDevice* d) {
  if (s == "cpu") *d = ComputeDevice::kCpu;
  else if (s == "cuda") *d = ComputeDevice::kCuda;
  else return false;
  return true;
}

// ModelParameters::IsValid is defined with the table (parameter_table.cpp).

double RestitutionDampingFactor(double restitution) {
  const double l = -std::log(restitution);
  return 2.0 * l / std::sqrt(std::numbers::pi * std::numbers::pi + l * l);
}

double DampingRateFromRestitution(double restitution, double stiffness_n_per_m, double mass_kg) {
  return RestitutionDampingFactor(restitution) * std::sqrt(stiffness_n_per_m / mass_kg);
}

double RestitutionFromDampingRate(double gamma_per_s, double stiffness_n_per_m, double mass_kg) {
  const double omega2 = stiffness_n_per_m / mass_kg - gamma_per_s * gamma_per_s / 4.0;
  if (omega2 <= 0.0) return 0.0;  // overdamped: no rebound
  return std::exp(-std::numbers::pi * gamma_per_s / 2.0 / std::sqrt(omega2));
}

}  // namespace crowdrecon::engine
