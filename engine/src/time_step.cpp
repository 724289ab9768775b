// The time step: the stability limit from every stiffness and rate of the
// model, and the accuracy the integrator gives at a step (docs/model.md,
// "ERRATA 12: time step").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>
#include <string>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/simulation.hpp"

namespace crowdrecon::engine {

TimeStepEstimate EstimateTimeStep(const WorldDef& def) {
  // The stiffest contact mode: a contact at the farthest point of the
  // lightest, most elongated body, against an equal body. Along the normal
  // the effective inverse mass of one body is 1/m + l^2/I (translation plus
  // the rotation that the lever arm l allows); two such bodies add. Two flat
  // faces touch at up to four points (two vertices of each against the
  // other's face), multiplying the stiffness by four. A contact point's
  // stiffness is k_n along the normal and k_t across it (eqs. 8-9), at most
  // max(k_n, k_t) in any direction. Hence
  //   omega_contact^2 = 4 max(k_n, k_t) * 2 max_i (1/m_i + l_i^2 / I_i).
  // A wall is one body of infinite mass with the same law: half of that.
  const ModelParameters& mp = def.parameters;
  double w_max = 0.0, mw_max = 1.0;
  for (const PersonDef& p : def.people) {
    const BodyShape& s = def.shapes[p.shape];
    double l = 0.0;
    for (const Vec2& v : s.vertices) l = std::max(l, Length(v));
    l += s.radius_m;
    const double w = 1.0 / p.mass_kg + (p.inertia_kg_m2 > 0 ? l * l / p.inertia_kg_m2 : 0.0);
    w_max = std::max(w_max, w);
    mw_max = std::max(mw_max, p.mass_kg * w);
  }
  TimeStepEstimate e;
  // A world with no one in it: the step of the lightest person the paper
  // draws (40 kg, a point mass), so that the estimate stays finite.
  if (w_max == 0.0) w_max = 1.0 / 40.0;
  const double k = std::max(mp.normal_stiffness_n_per_m, mp.tangential_stiffness_n_per_m);
  e.omega_max_rad_per_s = std::sqrt(4.0 * k * 2.0 * w_max);
  e.limited_by = mp.tangential_stiffness_n_per_m > mp.normal_stiffness_n_per_m ? "tangential_stiffness_n_per_m"
                                                                               : "normal_stiffness_n_per_m";
  // The other rates of the model, each as the frequency it imposes on an
  // explicit step (a spring omega, or a dashpot rate gamma: both need
  // h < 2 / rate with velocity Verlet). Taken one at a time, the largest
  // sets the limit; they are far apart for the paper's values (contacts
  // ~300 rad/s, torsion 7.8, relaxation 1.5), and the step the engine
  // chooses stays a fraction time_step_safety of it.
  const auto consider = [&](double rate, const char* name) {
    if (rate > e.omega_max_rad_per_s) {
      e.omega_max_rad_per_s = rate;
      e.limited_by = name;
    }
  };
  if (mp.ground_reaction) {
    consider(std::sqrt(mp.torsion_stiffness_lambda) / mp.relaxation_time_s, "torsion_stiffness_lambda");  // eq. (16)
    consider(1.0 / mp.relaxation_time_s, "relaxation_time_s");                                             // eq. (3)
    consider(1.0 / mp.rotation_relaxation_time_s, "rotation_relaxation_time_s");                           // eq. (17)
  }
  if (mp.tangential_damping == TangentialDamping::kFixed)  // eq. (12): m_ij gamma_t on both bodies, lever arms
    consider(2.0 * mp.tangential_damping_rate_per_s * mw_max, "tangential_damping_rate_per_s");
  // Velocity Verlet is stable for omega dt < 2; the fifth-order Gear
  // predictor-corrector only below about 0.2 for these damping ratios (ERRATA 12).
  const double bound = mp.integrator == Integrator::kVelocityVerlet ? 2.0 : 0.2;
  e.stability_limit_s = bound / e.omega_max_rad_per_s;
  e.accurate_s = mp.time_step_safety * e.stability_limit_s;
  e.chosen_s = mp.time_step_s > 0.0 ? mp.time_step_s : e.accurate_s;
  return e;
}

double RestitutionErrorAtStep(const WorldDef& def, double time_step_s) {
  // Two flat bodies (rectangular cores) meet face to face at four points,
  // the stiffest mode of EstimateTimeStep, with inertias so large that the
  // lever arms do not count: their contact frequency sqrt(4 k 2 / m) is made
  // the world's omega_max by the choice of m. The error depends on omega h,
  // epsilon and where within a step the contact begins; ten such phases, as
  // in EnginePhysics.HeadOnCollisionsHaveTheConfiguredRestitution.
  const TimeStepEstimate world = EstimateTimeStep(def);
  WorldDef scene;
  scene.parameters = def.parameters;
  scene.parameters.ground_reaction = false;
  scene.parameters.time_step_mode = TimeStepMode::kFixed;  // (measured at this one step)
  scene.parameters.time_step_s = std::min(time_step_s, world.stability_limit_s);
  scene.targets.push_back(geometry::NavigationField::Constant({1.0, 0.0}));
  BodyShape face;
  face.radius_m = 0.05;
  face.vertices = {{-0.1, -0.15}, {0.1, -0.15}, {0.1, 0.15}, {-0.1, 0.15}};
  scene.shapes = {face};
  // (Head on, only k_n acts: the scene's k_t is set to it so that its own
  // estimate is its normal frequency.)
  const double k = def.parameters.normal_stiffness_n_per_m;
  scene.parameters.tangential_stiffness_n_per_m = k;
  const double mass = 8.0 * k / (world.omega_max_rad_per_s * world.omega_max_rad_per_s) * (1.0 + 1e-9);
  const double approach_m_per_s = 1.0;
  double worst = 0.0;
  for (int phase = 0; phase < 10; ++phase) {
    const double gap = 0.01 + approach_m_per_s * scene.parameters.time_step_s * phase / 10.0;
    PersonDef a, b;
    a.mass_kg = b.mass_kg = mass;
    a.inertia_kg_m2 = b.inertia_kg_m2 = mass * 1e9;
    a.position_m = {-(0.1 + 0.05 + gap / 2), 0.0};
    b.position_m = {0.1 + 0.05 + gap / 2, 0.0};
    a.velocity_m_per_s = {approach_m_per_s / 2, 0.0};
    b.velocity_m_per_s = {-approach_m_per_s / 2, 0.0};
    scene.people = {a, b};
    Simulation sim(scene);
    bool touched = false;
    for (int step = 0; step < 1000000; ++step) {
      sim.Step();
      touched = touched || !sim.contacts().empty();
      if (touched && sim.contacts().empty()) break;
    }
    const auto& v = sim.bodies().velocity_m_per_s;
    const double restitution = (v[1].x - v[0].x) / approach_m_per_s;
    worst = std::max(worst, std::abs(restitution / def.parameters.restitution - 1.0));
  }
  return worst;
}

int AdaptiveStepLevels(const ModelParameters& p) {
  if (p.time_step_mode != TimeStepMode::kAdaptive) return 0;
  int levels = 0;
  while (levels + 1 < kMaxStepLevels && std::ldexp(p.time_step_safety, levels + 1) <= p.adaptive_max_safety * (1.0 + 1e-12))
    ++levels;
  return levels;
}

std::vector<double> AdaptiveLevelSpeeds(const WorldDef& def, double tick_s, int levels, double reference_speed_m_per_s) {
  std::vector<double> speeds(static_cast<std::size_t>(levels) + 1, std::numeric_limits<double>::infinity());
  if (levels == 0) return speeds;
  const double error_at_tick = RestitutionErrorAtStep(def, tick_s);
  for (int l = 1; l <= levels; ++l) {
    const double error = RestitutionErrorAtStep(def, std::ldexp(tick_s, l));
    speeds[static_cast<std::size_t>(l)] = error > 0.0 ? reference_speed_m_per_s * error_at_tick / error
                                                      : std::numeric_limits<double>::infinity();
  }
  return speeds;
}

std::string StepLevelHistogram(const Profile& profile, double tick_s) {
  std::uint64_t steps = 0, ticks = 0;
  for (std::size_t l = 0; l < profile.steps_at_level.size(); ++l) {
    steps += profile.steps_at_level[l];
    ticks += profile.steps_at_level[l] << l;
  }
  if (steps == profile.steps_at_level[0]) return "";
  std::string text;
  for (std::size_t l = 0; l < profile.steps_at_level.size(); ++l) {
    if (profile.steps_at_level[l] == 0) continue;
    char part[96];
    std::snprintf(part, sizeof part, "%s%llu h: %llu steps (%.1f %%)", text.empty() ? "" : ", ", 1ull << l,
                  static_cast<unsigned long long>(profile.steps_at_level[l]),
                  100.0 * static_cast<double>(profile.steps_at_level[l]) / static_cast<double>(steps));
    text += part;
  }
  const double mean = static_cast<double>(ticks) / static_cast<double>(steps);
  char tail[96];
  std::snprintf(tail, sizeof tail, "; mean step %.2f h = %.3g s", mean, mean * tick_s);
  return text + tail;
}

std::string TimeStepAboveLimit(double time_step_s, Integrator integrator, const TimeStepEstimate& estimate) {
  if (!(time_step_s > estimate.stability_limit_s)) return "";
  return FormatNumber(time_step_s) + " s is above the stability limit of the " + ToString(integrator) +
         " integrator for these bodies, " + FormatNumber(estimate.stability_limit_s) + " s (omega_max = " +
         FormatNumber(estimate.omega_max_rad_per_s) + " rad/s, set by " + estimate.limited_by +
         "); give a smaller step, or 0 to let the engine choose";
}

}  // namespace crowdrecon::engine
