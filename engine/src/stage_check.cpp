// Stage check: non-finite states and interpenetrating cores end the run (SimulationError).
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
#include "simulation_internals.hpp"

#include <cmath>

#include "crowdrecon/common/error.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

void Simulation::Check() {
  ScopedTimer timer(profile_.stage_s[Index(Stage::kCheck)]);
  // Look for a bad body in parallel (Collide already looked at the contacts);
  // if there is one, report the first as the serial scan below would.
  const std::int64_t n = static_cast<std::int64_t>(bodies_.size());
  bool bad_body = false;
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (n >= kParallelBodies) reduction(|| : bad_body)
  for (std::int64_t ii = 0; ii < n; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    const Vec2 x = bodies_.position_m[i], v = bodies_.velocity_m_per_s[i];
    bad_body = !std::isfinite(x.x + x.y + v.x + v.y + bodies_.angle_rad[i] + bodies_.angular_velocity_rad_per_s[i]) || bad_body;
  }
  if (!bad_body && !in_->overlap_beyond) return;
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    const Vec2 x = bodies_.position_m[i], v = bodies_.velocity_m_per_s[i];
    if (!std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(v.x) || !std::isfinite(v.y) ||
        !std::isfinite(bodies_.angle_rad[i]) || !std::isfinite(bodies_.angular_velocity_rad_per_s[i]))
      throw SimulationError("non-finite state of " + PersonText(bodies_, i) + " at t = " + FormatNumber(time_s_) +
                            " s (position " + FormatNumber(x.x) + ", " + FormatNumber(x.y) + "; velocity " +
                            FormatNumber(v.x) + ", " + FormatNumber(v.y) + ")",
                            i, -1, time_s_);
  }
  PreviousContacts previous(in_->previous_contacts);
  for (const Contact& c : contacts_) {
    const double ra = def_.shapes[bodies_.shape[c.a]].radius_m;
    const double rb = c.wall ? def_.walls[c.b].radius_m : def_.shapes[bodies_.shape[c.b]].radius_m;
    const Contact* before = c.wall ? previous.Find(PairKey(c), c.feature) : nullptr;
    const auto separation = [this](Vec2 x, Vec2 y) { return detail::Separation(def_.periodic, x, y); };
    if (before && WentThroughWall(c, *before, rb, ra + rb, separation)) {
      const Vec2 x = bodies_.position_m[c.a];
      throw SimulationError(PersonText(bodies_, c.a) + " went through wall " + std::to_string(c.b) + " at t = " +
                            FormatNumber(time_s_) + " s near (" + FormatNumber(c.point_m.x) + ", " +
                            FormatNumber(c.point_m.y) + "), centre at (" + FormatNumber(x.x) + ", " +
                            FormatNumber(x.y) + "): the core crossed the wall line, a load beyond k_n (r_person + r_wall) = " +
                            FormatNumber(def_.parameters.normal_stiffness_n_per_m * (ra + rb)) +
                            " N on one point or too fast for the step (desired speed, time step)",
                            c.a, -1, time_s_);
    }
    if (!(c.overlap_m <= ra + rb)) {
      const std::string other = c.wall ? "wall " + std::to_string(c.b) : PersonText(bodies_, c.b);
      throw SimulationError("overlap of " + PersonText(bodies_, c.a) + " and " + other + " is " +
                            FormatNumber(c.overlap_m) + " m at t = " + FormatNumber(time_s_) +
                            " s, beyond the sum of their sphero-radii " + FormatNumber(ra + rb) +
                            " m: the cores interpenetrate (time step too large or forces too strong)",
                            c.a, c.wall ? -1 : std::int64_t{c.b}, time_s_);
    }
  }
}

}  // namespace crowdrecon::engine
