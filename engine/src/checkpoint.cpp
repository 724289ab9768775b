// Checkpoints: Simulation::SaveState and LoadState, the complete dynamic state.
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
#include "simulation_internals.hpp"

#include <cstring>

#include "binary_io.hpp"
#include "crowdrecon/common/error.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

namespace {

constexpr char kStateMagic[8] = {'C', 'R', 'S', 'T', 'A', 'T', 'E', '1'};

// The checkpoint's writer and reader (binary_io.hpp, shared with world files).
class StateWriter : public detail::BinaryWriter {
 public:
  StateWriter() : BinaryWriter(kStateMagic) {}
};

class StateReader : public detail::BinaryReader {
 public:
  explicit StateReader(const std::string& data) : BinaryReader(data, kStateMagic, "checkpoint", "state") {}
};

}  // namespace

std::string Simulation::SaveState() const {
  StateWriter w;
  w.Put(static_cast<std::uint64_t>(bodies_.size()));
  w.Put(step_count_);
  w.Put(time_s_);
  w.Put(dt_s_);
  w.Put(advance_springs_);
  w.PutVector(bodies_.position_m);
  w.PutVector(bodies_.angle_rad);
  w.PutVector(bodies_.velocity_m_per_s);
  w.PutVector(bodies_.angular_velocity_rad_per_s);
  w.PutVector(bodies_.force_n);
  w.PutVector(bodies_.torque_n_m);
  w.PutVector(bodies_.contact_force_n);
  w.PutVector(bodies_.contact_torque_n_m);
  w.PutVector(bodies_.external_force_n);
  w.PutVector(bodies_.state);
  w.PutVector(bodies_.target);
  w.PutVector(bodies_.desired_speed_m_per_s);
  w.PutVector(contacts_);
  w.PutVector(in_->leading_force);
  w.PutVector(in_->leading_torque);
  w.Put(in_->gear_initialised);
  w.PutVector(in_->gear_xy);
  w.PutVector(in_->gear_theta);
  // Only with BackForceTrigger::kAveragedVelocity (the definition, which the
  // checkpoint is restored into, says which).
  if (!in_->averaged_along.empty()) w.PutVector(in_->averaged_along);
  return w.Finish();
}

void Simulation::LoadState(const std::string& data) {
  StateReader r(data);
  const auto n = r.Get<std::uint64_t>();
  if (n != bodies_.size())
    throw InputError("checkpoint: holds " + std::to_string(n) + " people where this run has " +
                     std::to_string(bodies_.size()) + " (different scenario?)");
  step_count_ = r.Get<std::uint64_t>();
  time_s_ = r.Get<double>();
  const double dt = r.Get<double>();
  if (dt != dt_s_)
    throw InputError("checkpoint: time step " + FormatNumber(dt) + " s differs from this run's " +
                     FormatNumber(dt_s_) + " s (different scenario or parameters?)");
  advance_springs_ = r.Get<bool>();
  r.GetVector(bodies_.position_m, n);
  r.GetVector(bodies_.angle_rad, n);
  r.GetVector(bodies_.velocity_m_per_s, n);
  r.GetVector(bodies_.angular_velocity_rad_per_s, n);
  r.GetVector(bodies_.force_n, n);
  r.GetVector(bodies_.torque_n_m, n);
  r.GetVector(bodies_.contact_force_n, n);
  r.GetVector(bodies_.contact_torque_n_m, n);
  r.GetVector(bodies_.external_force_n, n);
  r.GetVector(bodies_.state, n);
  r.GetVector(bodies_.target, n);
  r.GetVector(bodies_.desired_speed_m_per_s, n);
  r.GetVector(contacts_);
  r.GetVector(in_->leading_force);
  r.GetVector(in_->leading_torque);
  in_->gear_initialised = r.Get<bool>();
  r.GetVector(in_->gear_xy);
  r.GetVector(in_->gear_theta);
  if (!in_->averaged_along.empty()) r.GetVector(in_->averaged_along, n);
  in_->pairs_valid = false;  // rebuilt on the next step; results do not depend on when
  in_->cuda_has_history = false;  // the device's last contacts are not these
  PlaceShapes();  // orientations of the restored angles (Drive reads them)
}

}  // namespace crowdrecon::engine
