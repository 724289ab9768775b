// Simulation: Newton-Euler dynamics of spheropolygon pedestrians (paper,
// eqs. 1-19). One Step() runs the named stages of stages.hpp (update_pairs,
// place_shapes, collide, gather, drive, integrate, check), each in a file of
// its own (engine/src/stage_*.cpp) and each timed into the Profile, in the
// manner of Box2D v3.
//
// Forces read only the current state and every sum runs in a fixed order, so
// results are identical whatever the number of threads. With
// WorldDef::device = kCuda, the collide stage for person pairs and their part
// of gather run on a CUDA device, with the same results
// (engine/src/cuda_collide.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "crowdrecon/engine/contact.hpp"
#include "crowdrecon/engine/stages.hpp"
#include "crowdrecon/engine/world.hpp"

namespace crowdrecon::engine {

// Hot state, one entry per person (structure of arrays).
struct BodyState {
  std::vector<Vec2> position_m;
  std::vector<double> angle_rad;
  std::vector<Vec2> velocity_m_per_s;
  std::vector<double> angular_velocity_rad_per_s;
  std::vector<Vec2> force_n;         // total force of the last evaluation
  std::vector<double> torque_n_m;    // total torque of the last evaluation
  std::vector<Vec2> contact_force_n;  // sum of contact forces (eq. 2, third term)
  std::vector<double> contact_torque_n_m;  // sum of contact torques (eq. 18, last term)
  std::vector<Vec2> external_force_n;  // see Simulation::SetExternalForce
  std::vector<double> mass_kg;
  std::vector<double> inertia_kg_m2;
  std::vector<std::uint32_t> shape;
  std::vector<double> desired_speed_m_per_s;
  std::vector<std::uint32_t> target;
  std::vector<std::uint32_t> group;
  std::vector<PersonState> state;
  // Who is in each slot: the person's index in the run (its run-file id - 1).
  // i at the start; Simulation::Spawn puts another person into a free slot,
  // so that an open venue's people come and go through a fixed set of slots.
  std::vector<std::uint32_t> id;
  std::size_t size() const { return position_m.size(); }
};

// Profile (seconds per stage, counters): stages.hpp.

// Time-step limits derived from every stiffness and rate of the model and
// the smallest body (see docs/model.md, "ERRATA 12: time step").
struct TimeStepEstimate {
  double omega_max_rad_per_s = 0.0;  // highest frequency (contact, torsion, or a damping rate)
  std::string limited_by;            // the parameter that sets omega_max
  double stability_limit_s = 0.0;    // integrator's stability bound
  double accurate_s = 0.0;           // time_step_safety * limit: the engine's own choice
  double chosen_s = 0.0;             // accurate_s, or the user's value
};

// A run that went numerically wrong. The message names the people (by id =
// index + 1, as in run files) and the time.
class SimulationError : public std::runtime_error {
 public:
  SimulationError(const std::string& message, std::int64_t person, std::int64_t other, double time_s)
      : std::runtime_error(message), person_(person), other_(other), time_s_(time_s) {}
  std::int64_t person() const { return person_; }  // engine index, -1 if none
  std::int64_t other() const { return other_; }    // engine index of the other person, -1 if none or a wall
  double time_s() const { return time_s_; }

 private:
  std::int64_t person_, other_;
  double time_s_;
};

namespace detail {
class PairCollider;  // engine/src/stage_collide.cpp
}  // namespace detail

// Whether the engine may use the processor's wide (AVX2) instructions where
// it has them (default: yes; the anticipation's pick of collision courses,
// the gait jitter's cosines).
// The results are the same either way, bit for bit: a switch for tests and
// benchmarks. WideInstructions: allowed, and the processor has them.
void UseWideInstructions(bool use);
bool WideInstructions();

// Whether the anticipation (time to collision, evaluated at every step)
// visits each pair once, from its lower index, and gives the partner the
// opposite force (default: yes), or each person's whole list. The results
// are the same either way, bit for bit (each person's sum is still taken
// over their partners in increasing index, each term the same number):
// a switch for tests and benchmarks.
void UseHalfPairs(bool use);

class Simulation {
 public:
  // Validates the definition; throws InputError with a precise message.
  explicit Simulation(WorldDef def);
  ~Simulation();
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;

  void Step();
  // Steps until time() >= end_time_s.
  void AdvanceTo(double end_time_s);

  double time_s() const { return time_s_; }
  std::uint64_t step_count() const { return step_count_; }
  // The step the next Step() takes. With TimeStepMode::kAdaptive it is
  // tick_s() times a power of two that changes between steps; with the fixed
  // step it is tick_s() throughout.
  double time_step_s() const { return dt_s_; }
  // The time counts in ticks of the fixed step: time_s() = tick_count() *
  // tick_s() (with the fixed step one tick per step, so this is step_count()
  // * time_step_s() as it always was). A step of level l advances 2^l ticks
  // and starts at a multiple of 2^l ticks, so that a run whose frames are a
  // multiple of 2^max_step_level() ticks apart lands on every frame exactly.
  double tick_s() const { return tick_s_; }
  std::uint64_t tick_count() const { return tick_count_; }
  int step_level() const { return level_; }          // of the next step
  int max_step_level() const { return max_level_; }  // 0 with the fixed step
  // The length of the step just taken (before the first, time_step_s()).
  double last_step_s() const { return last_step_ticks_ == 0 ? dt_s_ : tick_s_ * static_cast<double>(last_step_ticks_); }
  // True when the step just taken reached or passed a multiple of `every`
  // ticks: "every k steps" of the fixed step, whatever the steps' lengths.
  bool LastStepReached(std::uint64_t every) const {
    return every != 0 && last_step_ticks_ != 0 && (tick_count_ - last_step_ticks_) / every != tick_count_ / every;
  }
  // The largest approach speed the adaptive step allows at each level
  // (level 0: infinite); one entry with the fixed step.
  const std::vector<double>& step_level_speeds() const { return level_speed_; }
  const TimeStepEstimate& time_step_estimate() const { return dt_estimate_; }
  const WorldDef& definition() const { return def_; }
  // Changes the number of worker threads from the next step on (1..1024).
  // Results do not depend on it, so it may change between any two steps
  // (ThreadGovernor does so on a busy machine).
  void SetThreads(int threads);
  const BodyState& bodies() const { return bodies_; }
  // Contacts of the last force evaluation, in a fixed order.
  const std::vector<Contact>& contacts() const { return contacts_; }
  const Profile& profile() const { return profile_; }
  // With ComputeDevice::kCuda: empty while the device computes; once it has
  // failed (a lost GPU, a driver error), why and when, and the processor
  // computes from then on, with the same results.
  const std::string& device_fallback() const { return device_fallback_; }

  // Sets every velocity and angular velocity to zero and forgets the
  // integrator's history (used to relax an initial placement).
  void Quench();

  // A constant external force on a person (N), added to eq. (2) until changed;
  // used by verification scenes and crash tests (pushing, pressing).
  void SetExternalForce(std::uint32_t person, Vec2 force_n);

  // Changes a person's state (a fall makes them an obstacle; removal takes them
  // out, with their contacts of the last evaluation).
  void SetPersonState(std::uint32_t person, PersonState state);

  // The incident timeline's changes between two steps (scenario/timeline.hpp).
  // Results stay independent of the thread count, and checkpoints keep all of it.
  //
  // Puts `person` (every field of PersonDef; its shape one of the world's
  // shapes) into `slot`, which must be empty (kRemoved), as run person `id`:
  // walking, with no history (no integrator derivatives, no contacts).
  void Spawn(std::uint32_t slot, const PersonDef& person, std::uint32_t id);
  // True if a body of world shape `shape` at `position_m`, facing
  // `angle_rad`, touches no wall and no one in the venue (walking or fallen),
  // and keeps at least `clearance_m` from each (as far as the narrow phase's
  // lower bound on the gap shows: a place a little farther may be refused).
  bool IsFree(std::uint32_t shape, Vec2 position_m, double angle_rad, double clearance_m = 0.0) const;
  void SetTarget(std::uint32_t person, std::uint32_t target);
  void SetDesiredSpeed(std::uint32_t person, double speed_m_per_s);
  // Replaces the model parameters (a timed change of the back force, the
  // torsion stiffness, the restitution, ...). Throws InputError if they are
  // invalid or need a shorter time step than the run's (the runner chooses the
  // step for every parameter set of the timeline, so that never happens there).
  // The per-group values of SetGroupDrive stay where set.
  void SetParameters(const ModelParameters& parameters);
  // Switches wall `wall` off (an open door: no contacts, not in the wall
  // check) or on again (a closed door). Before the first step the forces of
  // t = 0 are evaluated again, as the constructor did.
  void SetWallEnabled(std::uint32_t wall, bool enabled);
  bool WallEnabled(std::uint32_t wall) const {
    return wall_enabled_.empty() || wall >= wall_enabled_.size() || wall_enabled_[wall] != 0;
  }
  // Group `group`'s own back force Gamma and torsion stiffness lambda (eqs.
  // 15-16), in place of the model's; NaN: the model's value again.
  void SetGroupDrive(std::uint32_t group, double back_force_gamma, double torsion_stiffness_lambda);

  // Checkpoints: the complete dynamic state (bodies, contacts with their
  // tangential springs, integrator history, time), so that a run restored from
  // it continues bit for bit as if it had never stopped. The definition (world)
  // is not included: restore into a Simulation built from the same WorldDef.
  // LoadState throws InputError if the data is damaged or does not match.
  std::string SaveState() const;
  void LoadState(const std::string& data);

  // Rebuilds the neighbour (Verlet) list now; normally the engine decides.
  // Results do not depend on when it is rebuilt. For benchmarks and tests.
  void RebuildNeighbourList();
  std::size_t neighbour_pair_count() const;  // person-person pairs in the list
  // The names of the run's behaviour terms, the parts of the drive stage
  // its parameters switch on, in the order the drive asks them
  // (engine/src/behaviour.hpp; "desired_velocity", "back_force", ...).
  std::vector<std::string> BehaviourTermNames() const;
  // The neighbour stage (stages.hpp), for tests and benchmarks: asks it for
  // everyone's neighbours within `radius_m` (0..1000 m) from now on, as a
  // behaviour term would (0: only what the run's terms ask for), and the
  // people within `radius_m` (at most the radius asked for) of `person` at
  // the last evaluation, every slot whatever its state, in increasing index.
  void RequestNeighbours(double radius_m);
  std::vector<std::uint32_t> NeighboursWithin(std::uint32_t person, double radius_m) const;
  // With false, the narrow phase forgets what it knows of pairs and vertices
  // still apart (temporal coherence) and measures every pair of the list at
  // every evaluation. The results are the same, bit for bit; for tests.
  void SetPairMemory(bool enabled);

  // Sleeping (ModelParameters::sleep_speed_m_per_s > 0; docs/model.md,
  // "Sleeping"): how many people sleep now (0 with it off), and whether
  // slot `person` does.
  std::size_t asleep_count() const;
  bool asleep(std::uint32_t person) const;

  // Diagnostics for tests and reports.
  Vec2 LinearMomentum() const;
  double AngularMomentum() const;  // about the origin (z component)
  double KineticEnergy() const;    // translational + rotational
  double ElasticEnergy() const;    // kn delta^2/2 + kt delta_t^2/2 over the contacts

  // Minimum-image difference a - b under the periodic box.
  Vec2 Separation(Vec2 a, Vec2 b) const;

 private:
  struct Internals;
  // The constructor's steps, in order (after validating the world): the
  // bodies' state, the shape families the narrow phase uses, the walls.
  void LoadBodies();
  void LoadPerson(std::size_t i, const PersonDef& person, std::uint32_t id);
  WorldDef ProbeWorld(const ModelParameters& parameters) const;
  void BuildShapeFamilies();
  void BuildWalls();
  void UpdatePairs();
  void PlaceShapes();
  void Collide();
  // The collide stage's other two ways: person pairs on the CUDA device, and
  // several threads with work stealing (stage_collide.cpp).
  bool CollideOnDevice(const detail::PairCollider& collider);
  void CollideOnThreads(const detail::PairCollider& collider);
  friend class detail::PairCollider;
  void Gather();
  void Drive();
  void UpdateBehaviourTerms();  // after each step (stage_drive.cpp)
  void Neighbours();
  void ListComebacks();  // empty slots filled since the neighbour list's build (stage_neighbours.cpp)
  void ComputeForces();
  void VerletKickDrift();
  void VerletKick();
  void GearPredict();
  void GearCorrect();
  void Check();
  // Stage sleep (stage_sleep.cpp): who falls asleep and who wakes, after
  // each step; the sleeping state made or dropped when the parameters say,
  // and a sleeper woken by a change that concerns them.
  void Sleep();
  void SetUpSleeping();
  void Wake(std::uint32_t person);
  void WakeAll();
  // The adaptive step: its levels and the approach speed each allows (at
  // construction and when the parameters change), and the next step's level
  // (stage choose_step, after the drift: positions at the step's end).
  void SetUpAdaptiveStep();
  void ChooseStep(std::uint64_t ticks_after);
  double LargestStep() const { return tick_s_ * static_cast<double>(std::uint64_t{1} << max_level_); }

  WorldDef def_;
  BodyState bodies_;
  std::vector<Contact> contacts_;
  std::unique_ptr<Internals> in_;
  Profile profile_;
  TimeStepEstimate dt_estimate_;
  double dt_s_ = 0.0;       // the next step
  double next_dt_s_ = 0.0;  // the step after it, decided during the next (the contact law's leading fractions)
  double tick_s_ = 0.0;
  double time_s_ = 0.0;
  std::uint64_t step_count_ = 0;
  std::uint64_t tick_count_ = 0;
  std::uint64_t last_step_ticks_ = 0;
  int level_ = 0, next_level_ = 0, max_level_ = 0;
  std::vector<double> level_speed_;
  double reference_speed_m_per_s_ = 0.0;
  // The fastest approach of the recent past, held for collision_s_ (the
  // longest collision) and then decaying over it: a collision keeps its
  // impact speed's step until it is over, though its relative speed passes
  // through zero at the turning point. Its age, since it was seen.
  double approach_memory_m_per_s_ = 0.0;
  double approach_age_s_ = 0.0;
  double collision_s_ = 0.0;
  bool advance_springs_ = false;
  std::string device_fallback_;
  // Per wall: 0 while switched off (SetWallEnabled); empty while all are on.
  std::vector<std::uint8_t> wall_enabled_;
};

// True when this build has the CUDA force computation (ComputeDevice::kCuda)
// and a CUDA device is present; otherwise false with the reason in *why.
bool CudaAvailable(std::string* why = nullptr);

// Time-step estimate for a world (used by the constructor; exposed for tests).
TimeStepEstimate EstimateTimeStep(const WorldDef& def);
// The number of doublings of the fixed step the adaptive step may use:
// the largest L (at most kMaxStepLevels - 1) with 2^L time_step_safety <=
// adaptive_max_safety; 0 with the fixed step. A runner that lands on frames
// makes them a multiple of 2^L ticks apart.
int AdaptiveStepLevels(const ModelParameters& parameters);
// The largest approach speed each level 0..levels of the adaptive step allows
// (level 0: infinite): reference_speed * err(tick) / err(2^l tick), err the
// restitution error RestitutionErrorAtStep measures at that step.
std::vector<double> AdaptiveLevelSpeeds(const WorldDef& def, double tick_s, int levels, double reference_speed_m_per_s);
// "" if `time_step_s` is within the integrator's stability limit, else why
// not ("0.02 s is above the stability limit of the velocity_verlet
// integrator ...; give a smaller step, or 0 ..."): the one message of the
// engine and of the scenario runner, which prefix it with where the step was given.
std::string TimeStepAboveLimit(double time_step_s, Integrator integrator, const TimeStepEstimate& estimate);

// The error of the restitution that the integrator gives, at `time_step_s`,
// to a collision in the stiffest contact mode of `def` (|eps_measured / eps
// - 1|, worst over ten phases of the collision within a step), measured by
// running a two-body head-on scene whose contact frequency is def's
// omega_max (engine/src/time_step.cpp). About 0.02 at the engine's own step.
double RestitutionErrorAtStep(const WorldDef& def, double time_step_s);

// The walking speed on a grade s (rise over run along the walking direction,
// uphill positive) relative to the level's: Tobler's hiking function
// exp(-3.5 |s + 0.05|) / exp(-3.5 x 0.05) (0.61 at +0.14, 0.87 at -0.14).
// The desired speed of SlopeResponse::kHeld.
double SlopeWalkingFactor(double grade);

// Throws SimulationError if the straight path of a person's centre from
// `centres_before` (positions at an earlier time) to now crosses a wall's
// core line: a safety net behind the contact check (a core vertex crossing a
// wall line), for the run loop once per output frame (walls x people
// segment tests; engine/src/wall_passage.cpp).
void CheckCentresStayInsideWalls(const Simulation& sim, const std::vector<Vec2>& centres_before);

// True when the path p -> q crosses the segment [a, b]: it starts on one
// side of the segment's line and ends on it or beyond, and the segment's
// ends lie on either side of the path's line (or on it). (The wall check
// above; a timeline's exits.)
bool PathCrossesSegment(Vec2 p, Vec2 q, Vec2 a, Vec2 b);

}  // namespace crowdrecon::engine
