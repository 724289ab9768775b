// Checkpoints: Simulation::SaveState and LoadState, the complete dynamic state.
// (one of the stages of Simulation::Step; engine/include/crowdrecon/engine/stages.hpp)
#include "simulation_internals.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <utility>

#include "binary_io.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/engine/parameter_table.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace crowdrecon::engine {

using namespace detail;  // the stages' shared helpers (simulation_internals.hpp)

namespace {

// Version 2 adds what the incident timeline changes (who is in each slot,
// their body, group, the per-group drive, the model parameters); version 1 is
// still read (a run without a timeline changes none of it). Version 3: the
// model parameters of the shoulder's turn and giving way, and giving way's
// state; a version-2 state (whose parameter block is shorter) is refused as
// such rather than misread. Version 4: the time step's mode and the adaptive
// step's parameters, and with the adaptive step its ticks and level (the
// fixed step's time is written where the step was); version 3 is refused.
// Version 6: the behaviour terms' per-person states as sections, each with
// the term's name and the version of its state (behaviour.hpp); version 5,
// which wrote the same states bare in a fixed order, is still read.
constexpr char kStateMagic[8] = {'C', 'R', 'S', 'T', 'A', 'T', 'E', '6'};
constexpr char kStateMagicV5[8] = {'C', 'R', 'S', 'T', 'A', 'T', 'E', '5'};
constexpr char kStateMagicV4[8] = {'C', 'R', 'S', 'T', 'A', 'T', 'E', '4'};
constexpr char kStateMagicV3[8] = {'C', 'R', 'S', 'T', 'A', 'T', 'E', '3'};
constexpr char kStateMagicV2[8] = {'C', 'R', 'S', 'T', 'A', 'T', 'E', '2'};
constexpr char kStateMagicV1[8] = {'C', 'R', 'S', 'T', 'A', 'T', 'E', '1'};

// The checkpoint's writer and reader (binary_io.hpp, shared with world files).
class StateWriter : public detail::BinaryWriter {
 public:
  StateWriter() : BinaryWriter(kStateMagic) {}
};

class StateReader : public detail::BinaryReader {
 public:
  StateReader(const std::string& data, const char (&magic)[8]) : BinaryReader(data, magic, "checkpoint", "state") {}
};

// The terms' sections (version 6): the names of the terms with state, in
// the list's order, then per term the version of its state and what it saves.
void PutTermStates(StateWriter& w, const ActiveTerms& terms) {
  w.Put(static_cast<std::uint64_t>(terms.stateful.size()));
  for (const std::string name : terms.stateful_names) w.PutVector(std::vector<char>(name.begin(), name.end()));
  for (const BehaviourTerm* term : terms.stateful) {
    w.Put(term->state_version());
    term->Save(w);
  }
}

std::string Names(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return names.empty() ? "none" : text;
}

void GetTermStates(StateReader& r, const ActiveTerms& terms, std::size_t people) {
  const std::size_t count = r.GetCount(8);
  std::vector<std::string> theirs, ours(terms.stateful_names.begin(), terms.stateful_names.end());
  for (std::size_t t = 0; t < count; ++t) {
    std::vector<char> name;
    r.GetVector(name);
    theirs.emplace_back(name.begin(), name.end());
  }
  if (theirs != ours)
    throw InputError("checkpoint: holds the state of the behaviour terms " + Names(theirs) +
                     " where this run's parameters have " + Names(ours) + " (different model parameters?)");
  for (std::size_t t = 0; t < terms.stateful.size(); ++t) {
    BehaviourTerm* term = terms.stateful[t];
    const auto version = r.Get<std::uint32_t>();
    if (version != term->state_version())
      throw InputError("checkpoint: holds the state of the behaviour term " + ours[t] + " in version " +
                       std::to_string(version) + " where this build reads version " +
                       std::to_string(term->state_version()) +
                       "; resume the run with the version that wrote it, or start it again");
    term->Load(r, people);
  }
}

// Version 5: the states of the averaged back-force trigger, the reaction time
// and giving way, bare and in that order, where the run has them (each
// term's version-1 state).
void GetTermStatesV5(StateReader& r, const ActiveTerms& terms, std::size_t people) {
  for (const char* legacy : {"back_force", "reaction_time", "giving_way"})
    for (std::size_t t = 0; t < terms.stateful.size(); ++t)
      if (std::string(terms.stateful_names[t]) == legacy) terms.stateful[t]->Load(r, people);
}

// The model parameters, every entry of the parameter table in its order
// after their count (version 6; version 5 wrote the first
// kParametersOfVersion5 entries without it). A checkpoint with fewer entries
// than this build's table (new parameters are appended to the table) leaves
// the others at the run's values.
constexpr std::size_t kParametersOfVersion5 = 42;

void PutParameters(StateWriter& w, const ModelParameters& p) {
  w.Put(static_cast<std::uint64_t>(ModelParameterTable().size()));
  for (const ParameterInfo& info : ModelParameterTable()) {
    switch (info.kind) {
      case ParameterInfo::Kind::kNumber: w.Put(p.*info.number); break;
      case ParameterInfo::Kind::kFlag: w.Put(static_cast<std::uint8_t>(p.*info.flag)); break;
      case ParameterInfo::Kind::kChoice: w.Put(static_cast<std::uint8_t>(info.get_choice(p))); break;
    }
  }
}

ModelParameters GetParameters(StateReader& r, ModelParameters p, bool v5) {
  const std::size_t count = v5 ? kParametersOfVersion5 : r.Get<std::uint64_t>();
  if (count > ModelParameterTable().size())
    throw InputError("checkpoint: holds " + std::to_string(count) + " model parameters, this build knows " +
                     std::to_string(ModelParameterTable().size()) + " (written by a newer crowdrecon?)");
  for (const ParameterInfo& info : ModelParameterTable().first(count)) {
    switch (info.kind) {
      case ParameterInfo::Kind::kNumber: p.*info.number = r.Get<double>(); break;
      case ParameterInfo::Kind::kFlag: p.*info.flag = r.Get<std::uint8_t>() != 0; break;
      case ParameterInfo::Kind::kChoice: {
        const int c = r.Get<std::uint8_t>();
        if (c >= static_cast<int>(info.choice_count)) throw InputError("checkpoint: damaged model parameters");
        info.set_choice(p, c);
        break;
      }
    }
  }
  return p;
}

// What a step relies on in a restored state, checked before it steps: a
// checkpoint that passed its checksum yet holds values no run can reach (one
// written by another build, or made by hand) is refused with what is wrong,
// rather than stepped into out-of-range indices or non-numbers.
bool Finite(double x) { return std::isfinite(x); }
bool Finite(Vec2 v) { return std::isfinite(v.x) && std::isfinite(v.y); }
template <typename T, std::size_t N>
bool Finite(const std::array<T, N>& values) {
  return std::all_of(values.begin(), values.end(), [](const T& x) { return Finite(x); });
}

template <typename T>
void RequireFinite(const std::vector<T>& values, const char* what) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!Finite(values[i]))
      throw InputError(std::string("checkpoint: damaged state: ") + what + " of slot " + std::to_string(i) +
                       " is not a finite number");
}

// The contacts of the last step (the tangential springs' history): each
// names people or a wall that exist, carries finite numbers, and the list is
// in the engine's order (by pair, then feature). Their `wall` flags are
// checked as bytes before any is read as a bool.
void RequireValidContacts(const std::vector<Contact>& contacts, std::size_t people, std::size_t walls) {
  const auto damaged = [](std::size_t k, const std::string& why) {
    return InputError("checkpoint: damaged contact " + std::to_string(k) + ": " + why);
  };
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    unsigned char flag;
    std::memcpy(&flag, reinterpret_cast<const unsigned char*>(&contacts[k]) + offsetof(Contact, wall), 1);
    if (flag > 1) throw damaged(k, "a flag of value " + std::to_string(flag));
  }
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const Contact& c = contacts[k];
    if (c.a >= people || c.b >= (c.wall ? walls : people))
      throw damaged(k, "names person " + std::to_string(c.a + 1) + " and " + (c.wall ? "wall " : "person ") +
                           std::to_string(c.b + 1) + ", which this run does not have");
    if (!Finite(c.point_m) || !Finite(c.normal) || !Finite(c.overlap_m) || !Finite(c.normal_force_n) ||
        !Finite(c.tangential_force_n) || !Finite(c.tangential_spring_m) || !Finite(c.viscous_normal_n) ||
        !Finite(c.viscous_tangential_n) || !Finite(c.trailing_fraction) || !Finite(c.leading_fraction))
      throw damaged(k, "a value is not a finite number");
    if (k > 0) {
      const Contact& p = contacts[k - 1];
      if (PairKey(c) < PairKey(p) || (PairKey(c) == PairKey(p) && c.feature <= p.feature))
        throw damaged(k, "out of order");
    }
  }
}

bool HasMagic(const std::string& data, const char* magic) {
  return data.size() >= sizeof kStateMagic && std::memcmp(data.data(), magic, sizeof kStateMagic) == 0;
}

}  // namespace

std::string Simulation::SaveState() const {
  StateWriter w;
  w.Put(static_cast<std::uint64_t>(bodies_.size()));
  w.Put(step_count_);
  w.Put(time_s_);
  w.Put(tick_s_);  // (the fixed step; with it, the step)
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
  // The behaviour terms' states (the definition, which the checkpoint is
  // restored into, says which terms the run has).
  PutTermStates(w, in_->terms);
  w.PutVector(bodies_.id);
  w.PutVector(bodies_.shape);
  w.PutVector(bodies_.mass_kg);
  w.PutVector(bodies_.inertia_kg_m2);
  w.PutVector(bodies_.group);
  w.PutVector(in_->group_gamma);
  w.PutVector(in_->group_lambda);
  PutParameters(w, def_.parameters);
  w.PutVector(wall_enabled_);
  // Only with the adaptive step (the definition says which): the time in
  // ticks and the next step's level.
  if (max_level_ > 0) {
    w.Put(tick_count_);
    w.Put(static_cast<std::uint8_t>(level_));
    w.Put(approach_memory_m_per_s_);
    w.Put(approach_age_s_);
  }
  // Only with sleeping (the parameters above say): who sleeps, how long the
  // others have been still, the sleepers' frozen drive.
  if (!in_->asleep.empty()) {
    w.PutVector(in_->asleep);
    w.PutVector(in_->still_s);
    w.PutVector(in_->sleep_drive_force);
    w.PutVector(in_->sleep_drive_torque);
    w.PutVector(in_->sleep_anchor);
    w.PutVector(in_->sleep_anchor_angle);
  }
  return w.Finish();
}

void Simulation::LoadState(const std::string& data) {
  for (const auto& [magic, format] :
       {std::pair{kStateMagicV2, "2"}, std::pair{kStateMagicV3, "3"}, std::pair{kStateMagicV4, "4"}})
    if (HasMagic(data, magic))
      throw InputError(std::string("checkpoint: written by an older crowdrecon (state format ") + format +
                       ", before the model parameters of November 2026); resume the run with the version that "
                       "wrote it, or start it again");
  const bool v1 = HasMagic(data, kStateMagicV1), v5 = HasMagic(data, kStateMagicV5);
  StateReader r(data, v1 ? kStateMagicV1 : v5 ? kStateMagicV5 : kStateMagic);
  const auto n = r.Get<std::uint64_t>();
  if (n != bodies_.size())
    throw InputError("checkpoint: holds " + std::to_string(n) + " people where this run has " +
                     std::to_string(bodies_.size()) + " (different scenario?)");
  step_count_ = r.Get<std::uint64_t>();
  time_s_ = r.Get<double>();
  in_->drive_time_s = time_s_;
  const double dt = r.Get<double>();
  if (dt != tick_s_)
    throw InputError("checkpoint: time step " + FormatNumber(dt) + " s differs from this run's " +
                     FormatNumber(tick_s_) + " s (different scenario or parameters?)");
  tick_count_ = step_count_;  // (the fixed step; the adaptive one's ticks follow below)
  level_ = next_level_ = 0;
  last_step_ticks_ = 0;
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
  for (Contact& c : contacts_) std::fill(std::begin(c.padding_), std::end(c.padding_), std::uint8_t{0});  // (older files: whatever was there)
  r.GetVector(in_->leading_force);
  r.GetVector(in_->leading_torque);
  in_->gear_initialised = r.Get<bool>();
  r.GetVector(in_->gear_xy);
  r.GetVector(in_->gear_theta);
  if (v1 || v5)
    GetTermStatesV5(r, in_->terms, n);
  else
    GetTermStates(r, in_->terms, n);
  if (!v1) {
    r.GetVector(bodies_.id, n);
    r.GetVector(bodies_.shape, n);
    r.GetVector(bodies_.mass_kg, n);
    r.GetVector(bodies_.inertia_kg_m2, n);
    r.GetVector(bodies_.group, n);
    r.GetVector(in_->group_gamma);
    r.GetVector(in_->group_lambda);
    if (in_->group_gamma.size() != in_->group_lambda.size() || in_->group_gamma.size() > 1024)
      throw InputError("checkpoint: damaged per-group drive");
    const ModelParameters p = GetParameters(r, def_.parameters, v5);
    std::string error;
    if (!p.IsValid(&error)) throw InputError("checkpoint: damaged model parameters: " + error);
    def_.parameters = p;
    r.GetVector(wall_enabled_);
    if (!wall_enabled_.empty() && wall_enabled_.size() != def_.walls.size())
      throw InputError("checkpoint: damaged wall switches");
    if (max_level_ > 0) {
      tick_count_ = r.Get<std::uint64_t>();
      const int level = r.Get<std::uint8_t>();
      approach_memory_m_per_s_ = r.Get<double>();
      approach_age_s_ = r.Get<double>();
      for (double x : {approach_memory_m_per_s_, approach_age_s_})
        if (!(x >= 0.0 && std::isfinite(x)))
          throw InputError("checkpoint: damaged adaptive step (a remembered approach of " + FormatNumber(x) + ")");
      if (level > max_level_ || tick_count_ % (std::uint64_t{1} << level) != 0 || tick_count_ < step_count_ ||
          static_cast<double>(tick_count_) * tick_s_ != time_s_)
        throw InputError("checkpoint: damaged adaptive step (level " + std::to_string(level) + " at tick " +
                         std::to_string(tick_count_) + ")");
      level_ = next_level_ = level;
    }
    // Sleeping as the restored parameters say (off: nothing saved). A
    // checkpoint from before sleeping existed ends here: everyone awake.
    SetUpSleeping();
    if (!in_->asleep.empty() && r.remaining() > 0) {
      r.GetVector(in_->asleep, n);
      r.GetVector(in_->still_s, n);
      r.GetVector(in_->sleep_drive_force, n);
      r.GetVector(in_->sleep_drive_torque, n);
      r.GetVector(in_->sleep_anchor, n);
      r.GetVector(in_->sleep_anchor_angle, n);
      for (std::size_t i = 0; i < n; ++i)
        if (in_->asleep[i] > 1 || !(in_->still_s[i] >= 0.0))
          throw InputError("checkpoint: damaged sleeping state of slot " + std::to_string(i));
      RequireFinite(in_->still_s, "time still");
      RequireFinite(in_->sleep_drive_force, "frozen drive");
      RequireFinite(in_->sleep_drive_torque, "frozen drive torque");
      RequireFinite(in_->sleep_anchor, "still spell's place");
      RequireFinite(in_->sleep_anchor_angle, "still spell's angle");
    }
    in_->restitution_factor = RestitutionDampingFactor(p.restitution);
    in_->wall_restitution_factor = RestitutionDampingFactor(p.wall_restitution);
    for (std::size_t i = 0; i < n; ++i) {
      if (bodies_.shape[i] >= def_.shapes.size() || !(bodies_.mass_kg[i] > 0) || !(bodies_.inertia_kg_m2[i] > 0))
        throw InputError("checkpoint: damaged body of slot " + std::to_string(i));
      const std::uint32_t s = bodies_.shape[i];
      in_->bound_m[i] = def_.shapes[s].core_radius_m + def_.shapes[s].radius_m;
      in_->rotation_arm_m[i] =
          in_->family_geometry[in_->shape_family[s]].core_radius_m * in_->shape_scale[s] * (1.0 + 1e-12);
    }
  }
  dt_s_ = next_dt_s_ = std::ldexp(tick_s_, level_);
  // What the steps rely on (the body arrays' lengths were checked as read).
  if (!std::isfinite(time_s_)) throw InputError("checkpoint: damaged state: the time is not a finite number");
  RequireFinite(bodies_.position_m, "position");
  RequireFinite(bodies_.angle_rad, "angle");
  RequireFinite(bodies_.velocity_m_per_s, "velocity");
  RequireFinite(bodies_.angular_velocity_rad_per_s, "angular velocity");
  RequireFinite(bodies_.force_n, "force");
  RequireFinite(bodies_.torque_n_m, "torque");
  RequireFinite(bodies_.contact_force_n, "contact force");
  RequireFinite(bodies_.contact_torque_n_m, "contact torque");
  RequireFinite(bodies_.external_force_n, "external force");
  RequireFinite(bodies_.desired_speed_m_per_s, "desired speed");
  RequireFinite(bodies_.mass_kg, "mass");
  RequireFinite(bodies_.inertia_kg_m2, "moment of inertia");
  for (std::size_t i = 0; i < n; ++i) {
    if (static_cast<std::uint8_t>(bodies_.state[i]) > static_cast<std::uint8_t>(PersonState::kRemoved))
      throw InputError("checkpoint: damaged state: slot " + std::to_string(i) + " has no valid state");
    if (bodies_.target[i] >= def_.targets.size())
      throw InputError("checkpoint: damaged state: slot " + std::to_string(i) + " heads for target " +
                       std::to_string(bodies_.target[i]) + " of " + std::to_string(def_.targets.size()));
  }
  if (in_->leading_force.size() != n || in_->leading_torque.size() != n)
    throw InputError("checkpoint: damaged state: the last step's forces are not one per slot");
  RequireFinite(in_->leading_force, "last step's force");
  RequireFinite(in_->leading_torque, "last step's torque");
  if (in_->gear_initialised && (in_->gear_xy.size() != n || in_->gear_theta.size() != n))
    throw InputError("checkpoint: damaged state: the Gear predictor's history is not one per slot");
  RequireFinite(in_->gear_xy, "Gear history");
  RequireFinite(in_->gear_theta, "Gear history");
  for (std::size_t g = 0; g < in_->group_gamma.size(); ++g)  // NaN: the group has no value of its own
    if (std::isinf(in_->group_gamma[g]) || std::isinf(in_->group_lambda[g]))
      throw InputError("checkpoint: damaged per-group drive");
  RequireValidContacts(contacts_, n, def_.walls.size());

  in_->pairs_valid = false;  // rebuilt on the next step; results do not depend on when
  in_->cuda_has_history = false;  // the device's last contacts are not these
  PlaceShapes();  // orientations of the restored angles (Drive reads them)
  ListComebacks();  // the people in slots that were empty at the neighbour list's build
}

}  // namespace crowdrecon::engine
