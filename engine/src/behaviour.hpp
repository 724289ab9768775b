// Behaviour terms: the parts of the drive stage (issue 63). Each behaviour of
// a walking person — the paper's own eqs. 3 and 15-17, the floor slope, and
// each extension of round three — is a term in a file of its own under
// engine/src/terms/, with its own parameters (read from ModelParameters), its
// own per-person state (its own checkpoint section and version), its own
// update after each step, and its own tests. They are registered in one list
// (engine/src/terms/term_list.cpp); the drive stage (stage_drive.cpp) asks the
// active terms of the run for their contributions and knows none by name.
//
// The drive evaluates people in blocks of kDriveBlock, in phases; within a
// phase the terms take their turn in the list's order, each over the whole
// block:
//
//   phase      what a term may change            terms (list order)
//   direction  e_i, where the person wants to go   giving_way
//   steer      the heading eq. 3 drives along      headway
//              (e_i unless a term steers)
//   desire     the desired speed (pace) and the   yielding, reaction_time, floor_slope (held), headway (its cap)
//              velocity eq. 3 relaxes from
//   facing     where the body turns, eq. 16's gain motive_torque, shoulder_turn
//   (the drive: theta_D - theta of every facing)
//   force      the force and torque on the person  desired_velocity, gait_jitter, back_force,
//                                                  motive_torque, rotational_damping, floor_slope,
//                                                  social_force, centrifugal, anticipation
//
// so each sum is added in the same order as the single loop it replaced
// (forces: contacts, eq. 3, jitter, back force, slope; torques: contacts,
// eq. 16, eq. 17): the results are the same, bit for bit
// (bench/reference/checksums.txt). A term's block hooks are const and write
// only into the block (the blocks run on several threads); its per-person
// state changes only in AfterStep and the person hooks, which run serially.
//
// Private to the engine, like simulation_internals.hpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "binary_io.hpp"
#include "crowdrecon/engine/contact.hpp"
#include "crowdrecon/engine/simulation.hpp"
#include "crowdrecon/engine/world.hpp"
#include "minimum_image.hpp"

namespace crowdrecon::engine::detail {

inline constexpr std::size_t kDriveBlock = 64;
// Below this many people the per-body stages (and a term's own loops over
// everyone) run on one thread (the results are the same either way; only the
// overhead differs).
inline constexpr std::int64_t kParallelBodies = 512;

// The minimum-image difference a - b under the periodic box (the stages and
// the terms that look at their neighbours).
inline Vec2 Separation(const PeriodicBox& box, Vec2 a, Vec2 b) {
  Vec2 d = a - b;
  if (box.x) d.x = MinimumImage(d.x, box.max_m.x - box.min_m.x);
  if (box.y) d.y = MinimumImage(d.y, box.max_m.y - box.min_m.y);
  return d;
}

// The people within a radius of each walking or fallen person (the neighbour
// stage, stage_neighbours.cpp), for terms that act at a distance: person i's
// candidates are items[start[i]] .. items[start[i + 1] - 1], in increasing
// index, every one within radius_m of i and possibly some farther (up to
// radius_m + the stage's skin): a term measures the distance itself. Empty
// (start empty) when no active term asks for neighbours.
// The near list (near_radius_m > 0, a term asked for one: BehaviourTerm::
// near_radius_m): the same for a shorter radius, near_start / near_items,
// every candidate within near_radius_m and possibly some farther (up to it +
// the skin), in increasing index: a subset of the list, built with it.
struct NeighbourList {
  double radius_m = 0.0;
  std::vector<std::uint32_t> start, items;
  // Where person i's candidates after i begin: items[later[i]] .. items[start[i + 1] - 1]
  // are those of index > i (the list's rows are in increasing index).
  std::vector<std::uint32_t> later;
  double near_radius_m = 0.0;
  std::vector<std::uint32_t> near_start, near_items;
  bool empty() const { return start.empty(); }
};

// Calls visit(j) for each of person i's candidates that is in the venue
// (walking or fallen: the list holds those in the venue at its build and
// those come back since; some may have left), in the
// list's order (so that sums are the same on any thread count).
template <class BodyStateT, class Visit>
void ForEachNeighbour(const NeighbourList& list, const BodyStateT& bodies, std::size_t i, Visit&& visit) {
  for (std::uint32_t m = list.start[i]; m < list.start[i + 1]; ++m) {
    const std::uint32_t j = list.items[m];
    if (bodies.state[j] != PersonState::kRemoved) visit(j);
  }
}

// Whether person i wants to walk (desired speed > 0): the gait and the
// choice of a velocity are a walker's; a person who stands by choice
// (waiting for a pre-movement time, told to stand) has neither.
template <class BodyStateT>
bool WantsToWalk(const BodyStateT& bodies, std::size_t i) {
  return bodies.desired_speed_m_per_s[i] > 0.0;
}

// What every term may read during one evaluation of the drive.
struct DriveInputs {
  const BodyState& bodies;
  const WorldDef& def;                // def.parameters: the run's current parameters
  double inverse_tau;                 // 1 / tau of eq. (3)
  double time_s;                      // when the forces are evaluated (gait jitter)
  const std::vector<double>& cos_angle;  // each body's orientation (place_shapes)
  const std::vector<double>& sin_angle;
  // Per person, the backward parts of their contact forces with people ahead
  // (<= 0; HeldBackByPeopleAhead), when a term needs_people_ahead(); else empty.
  const std::vector<double>& held_back_n;
  // A group's own Gamma and lambda (Simulation::SetGroupDrive; NaN: the
  // model's), empty when no group has its own.
  const std::vector<double>& group_gamma;
  const std::vector<double>& group_lambda;
  const NeighbourList& neighbours;
};

// One block of people, first .. first + count - 1: what the drive found and
// what the terms change, per person k = i - first.
struct DriveBlock {
  std::size_t first = 0, count = 0;
  bool driven[kDriveBlock];      // walking, with the ground reaction on: the terms act on these only
  Vec2 direction[kDriveBlock];   // e_i (the target's direction; the direction phase may change it)
  Vec2 heading[kDriveBlock];     // the direction eq. (3) drives along: e_i, unless the steer phase turns it
                                 // (e_i stays where the person wants to go: the back force and the facing read it)
  double pace[kDriveBlock];      // the desired speed of eq. (3) (v0_i; the desire phase may change it)
  Vec2 from[kDriveBlock];        // the velocity eq. (3) relaxes from (v_i; the desire phase may change it)
  Vec2 facing[kDriveBlock];      // where the body turns (only its direction matters; zero: nowhere)
  double gain[kDriveBlock];      // the share of eq. (16)'s torque
  bool turning[kDriveBlock];     // facing somewhere (set by the drive after the facing phase)
  double angle[kDriveBlock];     // theta_D - theta in (-pi, pi] (the same)
  Vec2 force[kDriveBlock];       // contacts + external force, then the terms' forces
  double torque[kDriveBlock];    // contact torque, then the terms' torques
};

// What a step hands the terms after it (serially).
struct StepInputs {
  const BodyState& bodies;
  const WorldDef& def;
  const std::vector<Contact>& contacts;  // of the step's last evaluation, in their order
  std::vector<geometry::NavigationField::CellCache>& field_cache;
  double step_s;  // the step just taken
};

class BehaviourTerm {
 public:
  enum Phase : unsigned {
    kDirection = 1u, kDesire = 2u, kFacing = 4u, kForce = 8u, kAfterStep = 16u, kSteer = 32u, kPrepare = 64u
  };
  virtual ~BehaviourTerm() = default;
  // The phases it takes part in (a sum of Phase).
  virtual unsigned phases() const = 0;
  // It reads DriveInputs::held_back_n.
  virtual bool needs_people_ahead() const { return false; }
  // The radius within which it needs each person's neighbours (0: none).
  virtual double neighbour_radius_m() const { return 0.0; }
  // A shorter radius within which it needs them at every step (the near
  // list; 0: none; at most neighbour_radius_m).
  virtual double near_radius_m() const { return 0.0; }

  // Before the blocks of an evaluation, once, serially: what the blocks
  // share (a copy of the people's state laid out for the term's loops).
  virtual void Prepare(const DriveInputs&) const {}
  virtual void Direction(const DriveInputs&, DriveBlock&) const {}
  virtual void Steer(const DriveInputs&, DriveBlock&) const {}
  virtual void Desire(const DriveInputs&, DriveBlock&) const {}
  virtual void Facing(const DriveInputs&, DriveBlock&) const {}
  virtual void Force(const DriveInputs&, DriveBlock&) const {}
  virtual void AfterStep(const StepInputs&) {}

  // A term with state is kept through a change of the model's parameters
  // (Simulation::SetParameters): it takes the new ones here.
  virtual void Retune(const ModelParameters&) {}

  // Per-person state. state_version() 0: the term keeps none (then nothing
  // below is called but Start). Start: the run's people as placed; Place: a
  // newcomer in `slot`; Stop: `person` no longer walks; Quench: everyone at rest.
  virtual std::uint32_t state_version() const { return 0; }
  virtual void Start(const BodyState&) {}
  virtual void Place(std::size_t /*slot*/, const BodyState&) {}
  virtual void Stop(std::size_t /*person*/) {}
  virtual void Quench() {}
  // Its checkpoint section (after the name and version the checkpoint writes);
  // Load reads what Save wrote for `people` slots, and refuses damaged values
  // (InputError naming the term and the slot).
  virtual void Save(BinaryWriter&) const {}
  virtual void Load(BinaryReader&, std::size_t /*people*/) {}
};

// One entry of the list of terms.
struct TermEntry {
  const char* name;     // in checkpoints and messages ("back_force")
  const char* summary;  // one line: what it adds (docs/model.md)
  // The term for these parameters of a run of this world, or null when it is off.
  std::unique_ptr<BehaviourTerm> (*make)(const ModelParameters&, const WorldDef&);
};

// Every term, in the list's order (engine/src/terms/term_list.cpp).
const std::vector<TermEntry>& BehaviourTermList();

// A run's terms: those the parameters switch on, in the list's order, and
// per phase the ones that take part.
struct ActiveTerms {
  struct Active {
    const TermEntry* entry;
    std::unique_ptr<BehaviourTerm> term;
  };
  std::vector<Active> terms;
  std::vector<const BehaviourTerm*> prepare, direction, steer, desire, facing, force;
  std::vector<BehaviourTerm*> after_step, stateful;
  std::vector<const char*> stateful_names;
  bool people_ahead = false;
  double neighbour_radius_m = 0.0;
  double near_radius_m = 0.0;

  // The terms of `parameters` in `def` (every entry's make); `previous` (may be null) hands
  // over the terms it has that are still on, with their state. Throws
  // InputError if a term with per-person state would be switched on or off
  // (its state starts with the run).
  static ActiveTerms For(const ModelParameters& parameters, const WorldDef& def, ActiveTerms* previous);
};

// Each walking person's desired direction e_i (zero for the others).
void DesiredDirections(const BodyState& bodies, const WorldDef& def,
                       std::vector<geometry::NavigationField::CellCache>& field_cache, std::vector<Vec2>& desired);

// A per-person vector of a term's state, checked as read: `people` entries,
// each finite (else InputError "checkpoint: damaged state: <what> of slot N
// is not a finite number").
void GetTermVector(BinaryReader& r, std::vector<double>& values, std::size_t people, const char* what);
void GetTermVector(BinaryReader& r, std::vector<Vec2>& values, std::size_t people, const char* what);

}  // namespace crowdrecon::engine::detail
