// The stages of one engine step, listed once. Simulation::Step runs them in
// this order (engine/src/simulation.cpp), each in a file of its own, and
// times each into Profile::stage_s; the command line's summary, the stage
// profile and the step benchmarks iterate this list (never their own copy).
//
//   stage          file                              what it does
//   update_pairs   engine/src/stage_update_pairs.cpp  Verlet neighbour lists (cells + skin), when people moved
//   place_shapes   engine/src/stage_place_shapes.cpp  body-frame vertices -> world frame (sin, cos of each angle)
//   neighbours     engine/src/stage_neighbours.cpp    people within the radius a behaviour term asks for (none: no cost)
//   collide        engine/src/stage_collide.cpp       narrow phase + contact forces per pair (eqs. 7-14, 19)
//   gather         engine/src/stage_gather.cpp        contact forces and torques onto bodies, fixed order (eq. 18)
//   drive          engine/src/stage_drive.cpp         the behaviour terms (engine/src/behaviour.hpp): eqs. 3, 15-17, slope, ...
//   integrate      engine/src/stage_integrate.cpp     velocity Verlet or Gear 5th-order predictor-corrector
//   check          engine/src/stage_check.cpp         non-finite state, cores interpenetrating -> SimulationError
//   choose_step    engine/src/stage_choose_step.cpp   the next step (TimeStepMode::kAdaptive only)
//   sleep          engine/src/stage_sleep.cpp         who falls asleep, who wakes (sleep_speed_m_per_s > 0 only)
//
// With the velocity Verlet integrator a step is: integrate (kick + drift),
// [choose_step,] then the force stages 1-6, then integrate (kick), then check[, then sleep]. With Gear:
// integrate (predict), force stages, integrate (correct), check.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace crowdrecon::engine {

enum class Stage : std::uint8_t {
  kUpdatePairs,
  kPlaceShapes,
  kNeighbours,
  kCollide,
  kGather,
  kDrive,
  kIntegrate,
  kCheck,
  kChooseStep,
  kSleep
};
inline constexpr std::size_t kStageCount = 10;

struct StageInfo {
  Stage stage;
  const char* name;     // as printed and in benchmark counters ("<name>_ms")
  const char* summary;  // one line
};

inline constexpr std::array<StageInfo, kStageCount> kStages{{
    {Stage::kUpdatePairs, "update_pairs", "Verlet neighbour lists (cells + skin), rebuilt when people moved"},
    {Stage::kPlaceShapes, "place_shapes", "body-frame vertices to the world frame"},
    {Stage::kNeighbours, "neighbours", "people within the radius a behaviour term asks for (none asks: no cost)"},
    {Stage::kCollide, "collide", "narrow phase and contact forces per pair (eqs. 7-14, 19)"},
    {Stage::kGather, "gather", "contact forces and torques onto bodies in a fixed order (eq. 18)"},
    {Stage::kDrive, "drive", "the behaviour terms: self-driven force (3), back force (15), torques (16-17), slope, ..."},
    {Stage::kIntegrate, "integrate", "velocity Verlet or Gear 5th-order predictor-corrector"},
    {Stage::kCheck, "check", "non-finite state or interpenetrating cores: SimulationError"},
    {Stage::kChooseStep, "choose_step", "the next step from the approach speeds of pairs that may touch (adaptive)"},
    {Stage::kSleep, "sleep", "who falls asleep and who wakes (sleeping only)"},
}};

// The adaptive step's levels: a step of level l is 2^l times the fixed step.
inline constexpr int kMaxStepLevels = 8;

constexpr std::size_t Index(Stage s) { return static_cast<std::size_t>(s); }

// Wall-clock seconds spent in each stage, and what the stages counted.
struct Profile {
  std::array<double, kStageCount> stage_s{};  // indexed by Index(Stage)
  std::uint64_t pair_rebuilds = 0;
  // Pairs (person-person and person-wall) given to the narrow phase; the
  // others were known to be still apart (pair clearances).
  std::uint64_t pairs_measured = 0;
  // With the CUDA force computation: of the collide stage's time, the seconds
  // spent copying to and from the device and in its kernels (its events).
  double device_copy_s = 0, device_kernels_s = 0;
  // Sleeping (stage sleep): over the steps, the walking people counted at
  // each, and of them those asleep after it.
  std::uint64_t walking_person_steps = 0, sleeping_person_steps = 0;
  // Steps taken at each level of the adaptive step (level 0 only, with the fixed step).
  std::array<std::uint64_t, kMaxStepLevels> steps_at_level{};

  double seconds(Stage s) const { return stage_s[Index(s)]; }
  double total_s() const {
    double total = 0;
    for (double s : stage_s) total += s;
    return total;
  }
};

// "1 h: 120 steps (12 %), 2 h: ..., 4 h: ...; mean step 3.1 h = 0.0017 s" for
// the steps of a profile at each level of the adaptive step (h the fixed
// step, tick_s); "" when every step was a fixed one (engine/src/time_step.cpp).
std::string StepLevelHistogram(const Profile& profile, double tick_s);

}  // namespace crowdrecon::engine
