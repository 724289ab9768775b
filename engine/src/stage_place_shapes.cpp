// Stage place_shapes: each body's orientation (cos, sin) and travel since the last evaluation.
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
#include "simulation_internals.hpp"

#include <cmath>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

void Simulation::PlaceShapes() {
  ScopedTimer timer(profile_.stage_s[Index(Stage::kPlaceShapes)]);
  Internals& in = *in_;
  const std::int64_t n = static_cast<std::int64_t>(bodies_.size());
#pragma omp parallel for schedule(static) num_threads(def_.threads) if (n >= kParallelBodies)
  for (std::int64_t ii = 0; ii < n; ++ii) {
    const std::size_t i = static_cast<std::size_t>(ii);
    if (bodies_.state[i] == PersonState::kRemoved) continue;  // an empty slot (Spawn places it afresh)
    SinCos(bodies_.angle_rad[i], in.sin_angle[i], in.cos_angle[i]);  // common/fast_math.hpp
    // Travel since the last evaluation: a core point at distance r <= arm
    // from the centre moves by at most |translation| + r |rotation|.
    const Vec2 x = bodies_.position_m[i];
    const double angle = bodies_.angle_rad[i];
    in.travel_m[i] += Length(detail::Separation(def_.periodic, x, in.travel_position[i])) +
                      in.rotation_arm_m[i] * std::abs(angle - in.travel_angle[i]);
    in.travel_position[i] = x;
    in.travel_angle[i] = angle;
  }
}

}  // namespace crowdrecon::engine
